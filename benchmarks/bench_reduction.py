"""Performance benchmark of the reduction layer on the ~100k-dof blade of ``bench_fem.py``.

The twisted, tapered NACA 0012 blade of ``bench_fem.py`` (span 100 mm, chord
40 → 30 mm, twist 30°, stagger 10°, ``--size`` 1.4 mm, P2 elements: ~110k
free dofs; Ti-6Al-4V, root clamped) with one contact: the tip node of
smallest ``x`` (``Contact.farthest(model, (-1, 0, 0))``, the leading-edge tip
corner), radial normal ``+z``, clearance 0.1 mm.  It is reduced by

* ``reduce(model, contact, "lanczos", 50)``     — 50 Lanczos steps;
* ``reduce(model, contact, "lanczos-si", 50)``  — 50 shift-invert Lanczos steps;
* ``reduce(model, contact, "modal", 50)``       — the 50 lowest modes;
* ``reduce(model, contact, "craig-bampton", 50)`` — contact-node dofs + 50 fixed-interface modes;

each in its own process (``--worker``), so that the peak resident memory
(``ru_maxrss``) is per method: the peak after meshing and assembly (the
baseline, the same for all) and after the reduction are both reported.  A
last process computes the reference: ``natural_frequencies(model, --count)``
of the full model (shift-invert, sparse).  Printed: the time of ``reduce``
alone, the peaks, the lowest frequencies of each reduced model (its
``system.spectrum``) against the reference with their relative errors.

Target: each reduction under 30 s on a 2-core machine (reported MET / NOT
MET; the script exits 0 whatever the times).  ``--json FILE`` writes every
figure.

Run (about 3 minutes; each process meshes and assembles the blade again)::

    cd /work/main && .venv/bin/python benchmarks/bench_reduction.py [--size 0.0014] [--steps 50]
        [--methods lanczos lanczos-si modal craig-bampton] [--count 10] [--no-reference] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_core import fmt_time, line, machine, verdict

import bladecase
from bladecase.reduction import METHODS, Contact, reduce

#: Target: each reduction in under this many seconds (2-core machine).
TARGET_SECONDS = 30.0
#: Contact clearance (m).
GAP = 1e-4
#: Worker time-out (s).
WORKER_TIMEOUT = 1800


def peak_mb() -> float:
    """Peak resident memory of this process so far (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def blade(size: float, path: Path) -> bladecase.Mesh:
    geometry = bladecase.BladeGeometry(span=0.1, root_chord=0.04, tip_chord=0.03, naca="0012",
                                       twist_deg=30.0, stagger_deg=10.0)
    return bladecase.blade_mesh(geometry, size=size, order=1, path=path)


def setup(mesh_path: Path, order: int) -> tuple[bladecase.FEModel, Contact]:
    """The model and its contact, as every worker builds them."""
    mesh = bladecase.load_mesh(mesh_path)
    model = bladecase.assemble(mesh, "Ti-6Al-4V", order=order, clamp="root")
    return model, Contact.farthest(model, (-1.0, 0.0, 0.0), gap=GAP)


def worker(args) -> int:
    """One measurement in this process; the figures go to ``args.out`` (JSON)."""
    t0 = time.perf_counter()
    model, contact = setup(args.mesh, args.order)
    out = {"method": args.worker, "dofs": model.n_dofs, "setup_seconds": time.perf_counter() - t0,
           "baseline_MiB": peak_mb(), "contact_node": contact.node,
           "contact_point": model.mesh.points[contact.node].tolist()}
    t0 = time.perf_counter()
    if args.worker == "reference":
        f = bladecase.natural_frequencies(model, args.count)
        out["seconds"] = time.perf_counter() - t0
        out["frequencies_Hz"] = f.tolist()
    else:
        reduced = reduce(model, contact, args.worker, args.steps)
        out["seconds"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        spectrum = reduced.system.spectrum
        out["spectrum_seconds"] = time.perf_counter() - t0
        out["reduced_dofs"] = reduced.n
        out["frequencies_Hz"] = spectrum.frequencies[: args.count].tolist()
        if reduced.chain is not None:
            out["breakdown"] = bool(reduced.chain.breakdown)
    out["peak_MiB"] = peak_mb()
    args.out.write_text(json.dumps(out))
    return 0


def run_worker(script: Path, what: str, mesh: Path, args, scratch: Path) -> dict:
    out = scratch / f"{what}.json"
    cmd = [sys.executable, str(script), "--worker", what, "--mesh", str(mesh), "--out", str(out),
           "--order", str(args.order), "--steps", str(args.steps), "--count", str(args.count)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=WORKER_TIMEOUT)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        tail = "\n".join((proc.stderr or proc.stdout).strip().splitlines()[-5:])
        return {"method": what, "error": f"worker exited with status {proc.returncode}: {tail}", "wall": wall}
    result = json.loads(out.read_text())
    result["wall"] = wall
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=float, default=0.0014, help="blade mesh size in m (default 0.0014)")
    parser.add_argument("--order", type=int, choices=(1, 2), default=2, help="element order (default 2)")
    parser.add_argument("--steps", type=int, default=50, help="modes / Lanczos steps of every method (default 50)")
    parser.add_argument("--methods", nargs="+", default=["lanczos", "lanczos-si", "modal", "craig-bampton"],
                        choices=[m for m in METHODS if m != "full"])
    parser.add_argument("--count", type=int, default=10, help="frequencies compared (default 10)")
    parser.add_argument("--no-reference", action="store_true", help="skip the full-model reference frequencies")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--mesh", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(args)

    print("bladecase reduction benchmark: a ~100k-dof blade reduced by Lanczos, modal and Craig–Bampton")
    info = {"machine": machine(), "target_seconds": TARGET_SECONDS, "steps": args.steps}
    script = Path(__file__).resolve()
    with tempfile.TemporaryDirectory(prefix="bench_reduction_") as tmp:
        scratch = Path(tmp)
        mesh_path = scratch / "blade.msh"
        print("\n(a) mesh, model and contact")
        t0 = time.perf_counter()
        mesh = blade(args.size, mesh_path)
        line("mesh", f"blade_mesh(NACA 0012 blade, size={args.size:g} m): {mesh.points.shape[0]} nodes, "
                     f"{len(mesh.cells[mesh.body_type])} {mesh.body_type} ({fmt_time(time.perf_counter() - t0)})")
        del mesh

        results = {}
        for what in args.methods + ([] if args.no_reference else ["reference"]):
            label = "natural_frequencies (reference)" if what == "reference" else f"reduce({what!r}, {args.steps})"
            print(f"\n({'b' if what != 'reference' else 'c'}) {label}  [own process]", flush=True)
            r = run_worker(script, what, mesh_path, args, scratch)
            results[what] = r
            if "error" in r:
                line("FAILED", r["error"])
                continue
            line("model", f"P{args.order}, {r['dofs']} free dofs, contact node {r['contact_node']} at "
                          f"({', '.join(f'{c * 1e3:.2f}' for c in r['contact_point'])}) mm, normal +z, gap {GAP:g} m")
            line("setup (load mesh + assemble)", f"{fmt_time(r['setup_seconds'])}, peak {r['baseline_MiB']:.0f} MiB")
            if what == "reference":
                line("time", fmt_time(r["seconds"]))
            else:
                extra = f", breakdown {r['breakdown']}" if "breakdown" in r else ""
                line("reduced dofs", f"{r['reduced_dofs']}{extra}")
                line("time of reduce()", f"{fmt_time(r['seconds'])}  (target < {TARGET_SECONDS:g} s: "
                                         f"{verdict(r['seconds'] < TARGET_SECONDS)})")
                line("reduced spectrum (dense, cached)", fmt_time(r["spectrum_seconds"]))
            line("peak memory after", f"{r['peak_MiB']:.0f} MiB  (+{r['peak_MiB'] - r['baseline_MiB']:.0f} MiB "
                                      "over the assembled model)")
    info["results"] = results

    ref = results.get("reference", {}).get("frequencies_Hz")
    print(f"\n(d) lowest frequencies (Hz){' and relative error vs the full model' if ref else ''}")
    methods = [m for m in args.methods if "error" not in results[m]]
    header = f"  {'mode':>4}  " + (f"{'full':>12}" if ref else "") + "".join(f"  {m:>24}" for m in methods)
    print(header)
    for j in range(args.count):
        row = f"  {j + 1:>4}  " + (f"{ref[j]:12.2f}" if ref else "")
        for m in methods:
            f = results[m]["frequencies_Hz"]
            if j >= len(f):
                row += f"  {'-':>24}"
            elif ref:
                row += f"  {f[j]:12.2f} ({f[j] / ref[j] - 1:+9.1e})"
            else:
                row += f"  {f[j]:24.2f}"
        print(row)

    print("\nSummary")
    for m in args.methods:
        r = results[m]
        if "error" in r:
            line(m, "FAILED")
            continue
        err = ""
        if ref:
            k = min(5, len(r["frequencies_Hz"]))
            e = np.abs(np.array(r["frequencies_Hz"][:k]) / np.array(ref[:k]) - 1).max()
            err = f", max rel. error of the lowest {k} frequencies {e:.1e}"
        line(m, f"{fmt_time(r['seconds'])} ({verdict(r['seconds'] < TARGET_SECONDS)}), "
                f"peak {r['peak_MiB']:.0f} MiB{err}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
