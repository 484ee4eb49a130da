"""Rotor 37's front end side by side with CalculiX: both started together on the same machine, each the other's load.

The NASA Rotor 37 deck of ``bench_rotor37.py`` (C3D15 wedges, 61 098 free dofs, mm): 20 natural frequencies at
rest.  Each run starts two processes at the same instant and waits for both:

(a) ``ccx -i r37`` on the deck's model part with a ``*FREQUENCY`` step of 20 modes (``OMP_NUM_THREADS`` =
    ``CCX_NPROC_EQUATION_SOLVER`` = ``CCX_NPROC_STIFFNESS`` = ``--threads``);
(b) a fresh Python process: ``bladecase.fe.load_mesh(deck, unit="mm")``, ``assemble(order=2,
    clamp="boundary")`` with the deck's material, ``stiffness_factor`` and ``natural_frequencies(model, 20)``
    (``OPENBLAS_NUM_THREADS`` and the same thread variables = ``--threads``), each phase timed.

Printed per run: both wall times (process start to exit, imports included), the ratio bladecase / ccx against
the goal 0.5, bladecase's phases, and the largest relative difference of f1–f20; then medians.
``--backends`` / ``BLADECASE_FACTOR`` and ``--ordering amd`` (CHOLMOD's own ordering instead of METIS's) compare
the factorisation's options.  Exit status 0 whatever the times; skipped where ``ccx`` is missing.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_rotor37_fe.py DATA/blade.inp [--threads 2]
        [--repeat 3] [--ordering metis|amd]

Figures (2 cores, 2026-11-29, helpers' jobs also running: load average 6–10): see ``benchmarks/README.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_rotor37 import ccx_deck, dat_frequencies  # noqa: E402

COUNT, GOAL = 20, 0.5
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "CCX_NPROC_EQUATION_SOLVER",
               "CCX_NPROC_STIFFNESS")

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
from bladecase.fe import assemble, load_mesh, natural_frequencies, stiffness_factor
from bladecase.fe.material import mesh_material
if sys.argv[3] == "amd":
    import bladecase.ordering as o
    o.MIN_SIZE = 10**12
phases = {"import": time.perf_counter() - t0}
def phase(name, fn):
    t = time.perf_counter(); r = fn(); phases[name] = time.perf_counter() - t; return r
mesh = phase("read", lambda: load_mesh(sys.argv[1], unit="mm"))
model = phase("assemble", lambda: assemble(mesh, mesh_material(mesh), order=2, clamp="boundary"))
factor = phase("factor", lambda: stiffness_factor(model))
f = phase("eigen", lambda: natural_frequencies(model, int(sys.argv[2]), factor=factor))
json.dump({"phases": phases, "dofs": int(model.n_dofs), "backend": factor.backend,
           "frequencies": [float(x) for x in f]}, sys.stdout)
"""


def side_by_side(deck: Path, folder: Path, threads: int, ordering: str) -> dict:
    env = dict(os.environ, **{k: str(threads) for k in THREAD_VARS})
    for suffix in (".dat", ".frd", ".sta", ".cvg", ".12d"):
        (folder / f"r37{suffix}").unlink(missing_ok=True)
    t0 = time.perf_counter()
    with open(folder / "ccx.log", "w") as log:
        ccx = subprocess.Popen(["ccx", "-i", "r37"], cwd=folder, env=env, stdout=log, stderr=subprocess.STDOUT)
        ours = subprocess.Popen([sys.executable, "-c", CHILD, str(deck), str(COUNT), ordering], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        ends = {}
        while len(ends) < 2:
            for name, proc in (("ccx", ccx), ("bladecase", ours)):
                if name not in ends and proc.poll() is not None:
                    ends[name] = time.perf_counter() - t0
            time.sleep(0.02)
    out, err = ours.communicate()
    if ours.returncode or ccx.returncode:
        raise RuntimeError(f"ccx {ccx.returncode}, bladecase {ours.returncode}: {err[-2000:]}")
    result = json.loads(out)
    result.update(ccx_seconds=ends["ccx"], bladecase_seconds=ends["bladecase"],
                  ccx_frequencies=[float(x) for x in dat_frequencies(folder / "r37.dat", COUNT)])
    return result


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("deck", type=Path)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--ordering", choices=("metis", "amd"), default="metis")
    args = ap.parse_args()
    if shutil.which("ccx") is None:
        print("ccx not installed: skipped")
        return 0
    ratios = []
    with tempfile.TemporaryDirectory(prefix="r37fe_") as tmp:
        folder = Path(tmp)
        (folder / "r37.inp").write_text(ccx_deck(args.deck.resolve(), 0.0, COUNT))
        for k in range(args.repeat):
            load = os.getloadavg()[0]
            r = side_by_side(args.deck.resolve(), folder, args.threads, args.ordering)
            ratio = r["bladecase_seconds"] / r["ccx_seconds"]
            ratios.append(ratio)
            rel = [abs(a / b - 1) for a, b in zip(r["frequencies"], r["ccx_frequencies"])]
            phases = " ".join(f"{n} {s:.1f}" for n, s in r["phases"].items())
            print(f"run {k + 1} ({args.threads} threads each, {args.ordering}, load {load:.1f} before): bladecase "
                  f"{r['bladecase_seconds']:.1f} s, ccx {r['ccx_seconds']:.1f} s, ratio {ratio:.2f} "
                  f"({'MET' if ratio <= GOAL else 'NOT MET'}: goal {GOAL}); {r['dofs']} dofs, {r['backend']}; "
                  f"phases {phases} s; f1-f4 vs ccx {max(rel[:4]):.1e}, f1-f20 {max(rel):.1e}", flush=True)
    print(f"median ratio {statistics.median(ratios):.2f} over {len(ratios)} run(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
