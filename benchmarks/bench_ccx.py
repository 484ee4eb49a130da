"""CalculiX (``ccx``) against bladecase on the same CalculiX deck: 20 natural frequencies of a quadratic blade.

The twisted, tapered NACA 0012 blade of ``bench_fem.py`` is meshed by gmsh with second-order tetrahedra
(``bladecase.blade_mesh(order=2)``: midside nodes on the curved surface; mesh size ``--size``, default 1.75 mm:
61 704 free dofs) and written as ONE CalculiX deck, ``blade.inp``, in millimetres (N, mm, t, s; Ti-6Al-4V):
``*NODE``, ``*ELEMENT, TYPE=C3D10``, the root as ``*NSET, NSET=ROOT`` clamped by ``*BOUNDARY`` ``ROOT, 1, 3``,
``*STEP`` / ``*FREQUENCY`` with 20 eigenfrequencies.  Then, each in its own process (its peak memory its own:
GNU ``time``'s ``%M``), with ``--repeat`` runs interleaved and medians reported:

(a) ``ccx -i blade`` (SPOOLES + ARPACK shift-invert on Debian's build): wall time of the ``ccx`` process, with
    ``OMP_NUM_THREADS`` = ``CCX_NPROC_EQUATION_SOLVER`` = ``CCX_NPROC_STIFFNESS`` = ``--threads`` (default: the
    usable cores); the frequencies read from ``blade.dat``;
(b) bladecase on the same deck, in a fresh interpreter with the same thread variables (and
    ``OPENBLAS_NUM_THREADS``): ``bladecase.fe.load_mesh(deck, unit="mm")`` (:mod:`bladecase.fe.abaqus`),
    ``bladecase.assemble(order=2, clamp="boundary")`` (curved isoparametric P2 cells, the deck's
    ``*BOUNDARY``), ``bladecase.fe.stiffness_factor`` (the backend of ``bladecase.linalg.factor_backend``;
    ``BLADECASE_FACTOR`` or ``--backends`` forces one) and ``natural_frequencies(model, 20, factor=...)``, each
    phase timed (``time.perf_counter``) with the peak memory after it; the process wall time (interpreter start
    and imports included) is the figure compared with ``ccx``'s.

Printed: dofs, element type, both times, both peak memories, the ratio bladecase / ccx, the goal
"bladecase <= 0.5 x ccx time" as MET / NOT MET, the largest relative difference of the 20 frequencies, and the
bladecase phases.  Skipped (exit 0) where ``ccx`` is not installed.  Exit status 0 whatever the times.

Other jobs on the machine distort both sides (measured on 2 cores: ccx 13.5 s quiet, 17 to 90 s beside another
job; bladecase's eigen-solve 2.3 s quiet, 6 to 8 s beside one), so the CPU time every other process used during
each run is measured (``/proc/stat``) and a run where it exceeds 5 % of a core is flagged BUSY and left out of
the medians when a quiet run exists; ``--wait-idle SECONDS`` waits for the machine to go idle before each run.

Agreement: ccx integrates C3D10 stiffness and mass with 4 Gauss points (degree 2), bladecase with
scikit-fem's default P2 rule (degree 4); on curved cells (and for the mass on any cell) that is a difference of
discretisation, 4e-5 at 61 704 dofs and 7e-4 at 6 603.  ``--same-rule`` re-solves (untimed) with the 4-point
rule in bladecase: it then agrees with ccx to the 7 digits ccx prints.

The deck is written by :func:`bladecase.fe.calculix.write_calculix` from the model assembled on the gmsh mesh
(untimed); each side then starts from that file.

Run::

    cd /work/main && .venv/bin/python benchmarks/bench_ccx.py [--size 0.00175] [--repeat 3] [--keep DIR]
        [--threads N] [--backends cvxopt,superlu] [--method auto|arpack|block] [--count 20] [--wait-idle 600]
        [--same-rule] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Default mesh size (m): 61 704 free P2 dofs on the blade of ``bench_fem.py``.
SIZE = 0.00175
COUNT = 20
#: The goal: bladecase's wall time at most this fraction of ccx's.
GOAL_RATIO = 0.5
#: The deck's material, Ti-6Al-4V (bladecase's preset) in the deck's units: MPa (N/mm²) and t/mm³.
E_PA, NU, RHO_SI = 113.8e9, 0.342, 4430.0
#: Phases of the bladecase process, in order.
PHASES = ("import", "read", "assemble", "factor", "eigen")
#: A run during which other processes used more than this fraction of one core is flagged as busy.
BUSY_FRACTION = 0.05
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_STIFFNESS")


def cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


# ----------------------------------------------------------------------------- the deck


def blade_mesh(size: float):
    """The blade of ``bench_fem.py`` meshed by gmsh with second-order tetrahedra (``tetra10``, curved)."""
    import bladecase

    geometry = bladecase.BladeGeometry(span=0.1, root_chord=0.04, tip_chord=0.03, naca="0012",
                                       twist_deg=30.0, stagger_deg=10.0)
    return bladecase.blade_mesh(geometry, size=size, order=2)


def write_deck(mesh, path: Path, count: int = COUNT) -> dict:
    """Write the model of ``mesh`` (``tetra10`` cells, a ``root`` group; Ti-6Al-4V, P2) as a CalculiX deck in mm
    (:func:`bladecase.fe.calculix.write_calculix`). Returns what was written (nodes, elements, clamped nodes)."""
    import bladecase
    from bladecase.fe import Material
    from bladecase.fe.calculix import write_calculix
    from bladecase.fe.select import held_nodes

    model = bladecase.assemble(mesh, Material(E_PA, NU, RHO_SI, "Ti-6Al-4V"), order=2, clamp="root")
    write_calculix(model, path, count, unit="mm")
    return {"nodes": len(mesh.points), "elements": len(mesh.cells[mesh.body_type]), "element": "C3D10",
            "root_nodes": int(held_nodes(mesh, model.clamped).size), "bytes": path.stat().st_size}


# ----------------------------------------------------------------------------- one process, measured


#: GNU time, for the peak memory of one process: ``os.wait4``'s ``ru_maxrss`` of a child forked from this
#: (large) Python process counts this process's resident memory before the child's ``exec``.
GNU_TIME = "/usr/bin/time"


def busy_cpu_seconds() -> float | None:
    """CPU seconds the whole machine has been busy (Linux ``/proc/stat``), ``None`` elsewhere."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]
        user, nice, system, idle, iowait, irq, softirq, steal = (int(x) for x in fields[:8])
    except (OSError, ValueError):
        return None
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def run_measured(cmd: list[str], cwd: Path, env: dict, log: Path) -> dict:
    """Run ``cmd``: its wall time and its own peak resident memory (MiB) and CPU time.

    Through GNU ``time`` (``%M``) where installed, so that the peak is the process's own; else ``os.wait4``'s
    ``ru_maxrss``, an upper bound (``exact_peak`` False).
    """
    timed = os.access(GNU_TIME, os.X_OK)
    stats = log.with_suffix(".time")
    full = [GNU_TIME, "-f", "%e %M %U %S", "-o", str(stats), *cmd] if timed else cmd
    with open(log, "w") as out:
        busy = busy_cpu_seconds()
        t0 = time.perf_counter()
        proc = subprocess.Popen(full, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        busy = None if busy is None else busy_cpu_seconds() - busy
    proc.returncode = os.waitstatus_to_exitcode(status)
    out = {"seconds": seconds, "peak_MiB": usage.ru_maxrss / 1024, "returncode": proc.returncode,
           "cpu_seconds": usage.ru_utime + usage.ru_stime, "exact_peak": False}
    if timed and stats.exists():
        fields = stats.read_text().split()[-4:]  # after "Command exited with non-zero status N", if any
        try:
            out.update(peak_MiB=int(fields[1]) / 1024, cpu_seconds=float(fields[2]) + float(fields[3]),
                       exact_peak=True)
        except (ValueError, IndexError):
            pass
    # the CPU time of every other process meanwhile: another job on the machine makes the times unreliable
    out["other_cpu_seconds"] = None if busy is None else max(busy - out["cpu_seconds"], 0.0)
    return out


def is_busy(r: dict) -> bool:
    """Other processes took more than 5 % of a core during the run (its times are then unreliable)."""
    other = r.get("other_cpu_seconds")
    return bool(other and other > BUSY_FRACTION * r["seconds"])


def other_load(r: dict) -> str:
    return f"  [other processes used {r['other_cpu_seconds']:.1f} cpu-s: BUSY MACHINE]" if is_busy(r) else ""


def quiet_runs(runs: list[dict]) -> tuple[list[dict], int]:
    """The successful runs on a quiet machine (all successful runs if none was quiet), and how many busy ones
    were left out."""
    ok = [r for r in runs if "error" not in r]
    quiet = [r for r in ok if not is_busy(r)]
    return (quiet, len(ok) - len(quiet)) if quiet else (ok, 0)


def wait_idle(limit: float) -> bool:
    """Wait (at most ``limit`` s) until other processes use under 3 % of a core over 5 s; True if they did."""
    start = time.perf_counter()
    while time.perf_counter() - start < limit:
        before = busy_cpu_seconds()
        if before is None:
            return False
        time.sleep(5.0)
        if busy_cpu_seconds() - before < 0.15:
            return True
    return False


def thread_env(threads: int, backend: str | None = None) -> dict:
    env = dict(os.environ, **{k: str(threads) for k in THREAD_VARS})
    if backend:
        env["BLADECASE_FACTOR"] = backend
    return env


def ccx_frequencies(dat: Path, count: int) -> list[float]:
    """The frequencies (cycles/time) of the last eigenvalue table of a CalculiX ``.dat``."""
    table = dat.read_text().split("E I G E N V A L U E   O U T P U T")[-1]
    rows = re.findall(r"^\s*\d+\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)", table, re.M)
    return [float(r[2]) for r in rows[:count]]


def run_ccx(ccx: str, folder: Path, threads: int, count: int, k: int) -> dict:
    for suffix in (".dat", ".frd", ".sta", ".cvg", ".12d"):
        (folder / f"blade{suffix}").unlink(missing_ok=True)
    log = folder / f"ccx_{k}.log"
    r = run_measured([ccx, "-i", "blade"], folder, thread_env(threads), log)
    text = log.read_text(errors="replace")
    r["cpu_lines"] = [s.strip() for s in text.splitlines() if "cpu" in s.lower()]
    if r["returncode"] or not (folder / "blade.dat").exists():
        r["error"] = f"ccx exit status {r['returncode']}: " + " | ".join(text.strip().splitlines()[-3:])
        return r
    r["frequencies_Hz"] = ccx_frequencies(folder / "blade.dat", count)
    if len(r["frequencies_Hz"]) < count:
        r["error"] = f"ccx gave {len(r['frequencies_Hz'])} frequencies, {count} asked for"
    return r


def bladecase_child(t_start: float, deck: str, count: int, method: str, intorder: int | None = None) -> dict:
    """The bladecase side, in this (fresh) process: read the deck, assemble, factorise, 20 frequencies.

    ``t_start``: ``time.perf_counter()`` before bladecase was imported.  ``intorder``: a diagnostic, the
    quadrature degree of the tetrahedra instead of scikit-fem's default (4 for P2); 2 is CalculiX's 4-point rule
    of C3D10, for stiffness and mass alike.
    """
    import resource

    import bladecase
    from bladecase import linalg
    from bladecase.fe import Material, load_mesh, natural_frequencies, stiffness_factor

    if intorder is not None:  # diagnostic only (--same-rule): the tetrahedra's quadrature as CalculiX's
        from bladecase.fe import assembly

        basis = assembly.CellBasis

        def with_rule(*a, **k):
            if "quadrature" not in k:
                k.setdefault("intorder", intorder)
            return basis(*a, **k)

        assembly.CellBasis = with_rule

    out: dict = {"phase_seconds": {"import": time.perf_counter() - t_start}, "phase_peak_MiB": {}}

    def peak() -> float:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    out["phase_peak_MiB"]["import"] = peak()

    def phase(name, fn):
        t0 = time.perf_counter()
        result = fn()
        out["phase_seconds"][name] = time.perf_counter() - t0
        out["phase_peak_MiB"][name] = peak()
        return result

    mesh = phase("read", lambda: load_mesh(deck, unit="mm"))
    material = Material(E_PA, NU, RHO_SI, "Ti-6Al-4V (deck)")
    model = phase("assemble", lambda: bladecase.assemble(mesh, material, order=2, clamp="boundary"))
    factor = phase("factor", lambda: stiffness_factor(model))
    freqs = phase("eigen", lambda: natural_frequencies(model, count, factor=factor, method=method))
    out.update(dofs=int(model.n_dofs), body_type=mesh.body_type, nodes=int(len(mesh.points)),
               clamped_nodes=int(len(mesh.group("boundary"))), backend=factor.backend,
               eigen_method=linalg._eigen_method(method, factor, model.n_dofs),
               nnz_K=int(model.K.nnz), frequencies_Hz=[float(f) for f in freqs],
               deck_to_frequencies=sum(out["phase_seconds"][p] for p in PHASES[1:]))
    return out


def run_bladecase(deck: Path, threads: int, count: int, backend: str | None, method: str, k: int,
                  intorder: int | None = None) -> dict:
    here = str(Path(__file__).resolve().parent)
    code = ("import time; t = time.perf_counter(); import json, sys; "
            f"sys.path.insert(0, {here!r}); import bench_ccx as b; "
            f"print('RESULT' + json.dumps(b.bladecase_child(t, {str(deck)!r}, {count!r}, {method!r}, {intorder!r})))")
    log = deck.parent / f"bladecase_{backend or 'default'}_{k}{'' if intorder is None else '_rule'}.log"
    r = run_measured([sys.executable, "-W", "ignore", "-c", code], deck.parent, thread_env(threads, backend), log)
    text = log.read_text(errors="replace")
    rows = [s for s in text.splitlines() if s.startswith("RESULT")]
    if r["returncode"] or not rows:
        r["error"] = f"exit status {r['returncode']}: " + ((text.strip().splitlines() or ["?"])[-1])
        return r
    r.update(json.loads(rows[-1][len("RESULT"):]))
    return r


# ----------------------------------------------------------------------------- report


def median(runs: list[dict], *keys: str) -> float:
    values = []
    for r in runs:
        v = r
        for key in keys:
            v = v[key]
        values.append(v)
    return statistics.median(values)


def spread(runs: list[dict], busy: int, key: str = "seconds") -> str:
    left = f"; {busy} run(s) on a busy machine left out" if busy else ""
    if len(runs) < 2:
        return f" ({left[2:]})" if left else ""
    return f" (range {min(r[key] for r in runs):.2f}-{max(r[key] for r in runs):.2f}, median of {len(runs)}{left})"


def row(label: str, value: str) -> None:
    print(f"  {label:<44} {value}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=float, default=SIZE, help=f"blade mesh size in m (default {SIZE:g})")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each side, interleaved (medians shown)")
    parser.add_argument("--keep", metavar="DIR", type=Path, help="write the deck and the outputs to DIR and keep them")
    parser.add_argument("--threads", type=int, default=cores(), help="threads of both sides (default: usable cores)")
    parser.add_argument("--backends", default=None,
                        help="bladecase factor backends, comma-separated (default: $BLADECASE_FACTOR or the "
                             "automatic choice); the first is compared with ccx")
    parser.add_argument("--method", default="auto", choices=("auto", "arpack", "block"),
                        help="bladecase eigen-solver (lowest_modes' method)")
    parser.add_argument("--count", type=int, default=COUNT, help=f"frequencies (default {COUNT})")
    parser.add_argument("--wait-idle", type=float, default=0.0, metavar="SECONDS",
                        help="before each run, wait up to SECONDS for other processes to go idle (default 0)")
    parser.add_argument("--same-rule", action="store_true",
                        help="diagnostic: also solve (untimed) with CalculiX's 4-point C3D10 rule in bladecase")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write every figure to FILE (JSON)")
    args = parser.parse_args(argv)

    print("CalculiX (ccx) vs bladecase: 20 natural frequencies of a quadratic blade from one CalculiX deck")
    ccx = shutil.which("ccx")
    if ccx is None:
        print("  SKIPPED: CalculiX is not installed (no 'ccx' on PATH; Debian: apt-get install calculix-ccx)")
        return 0

    from bench_core import machine

    from bladecase.linalg import available_backends, factor_backend

    info: dict = {"machine": machine(), "ccx": ccx, "threads": args.threads}
    backends = args.backends.split(",") if args.backends else [factor_backend()]
    row("ccx", f"{ccx}  ({_ccx_version(ccx)}; linked solvers: {_ccx_solvers(ccx)})")
    row("bladecase factor backend(s)", f"{', '.join(backends)}  (available: {', '.join(available_backends())}"
        f"{'; BLADECASE_FACTOR=' + os.environ['BLADECASE_FACTOR'] if os.environ.get('BLADECASE_FACTOR') else ''})")
    row("threads, both sides", ", ".join(f"{k}={args.threads}" for k in THREAD_VARS)
        + f"  ({cores()} usable cores)")

    folder = args.keep or Path(tempfile.mkdtemp(prefix="bench_ccx_"))
    folder.mkdir(parents=True, exist_ok=True)
    try:
        t0 = time.perf_counter()
        mesh = blade_mesh(args.size)
        t_mesh = time.perf_counter() - t0
        deck = folder / "blade.inp"
        t0 = time.perf_counter()
        written = write_deck(mesh, deck, args.count)
        t_write = time.perf_counter() - t0
        del mesh
        info["deck"] = dict(written, size=args.size, path=str(deck))
        row("deck", f"{deck}  ({written['bytes'] / 2**20:.1f} MiB; gmsh {t_mesh:.1f} s, written {t_write:.1f} s)")
        row("mesh", f"size {args.size:g} m: {written['nodes']} nodes, {written['elements']} {written['element']}, "
            f"root set {written['root_nodes']} nodes")

        ccx_runs: list[dict] = []
        bc_runs: dict[str, list[dict]] = {b: [] for b in backends}
        for k in range(max(args.repeat, 1)):
            if args.wait_idle > 0:
                wait_idle(args.wait_idle)
            r = run_ccx(ccx, folder, args.threads, args.count, k)
            print(f"  run {k + 1}: ccx {r['seconds']:.2f} s, {r['peak_MiB']:.0f} MiB, cpu {r['cpu_seconds']:.1f} s"
                  + other_load(r) + (f"  ERROR {r['error']}" if "error" in r else ""), flush=True)
            ccx_runs.append(r)
            for b in backends:
                if args.wait_idle > 0:
                    wait_idle(args.wait_idle)
                r = run_bladecase(deck, args.threads, args.count, b, args.method, k)
                print(f"  run {k + 1}: bladecase ({b}) {r['seconds']:.2f} s, {r['peak_MiB']:.0f} MiB, cpu "
                      f"{r['cpu_seconds']:.1f} s" + other_load(r) + (f"  ERROR {r['error']}" if "error" in r else ""),
                      flush=True)
                bc_runs[b].append(r)
        info["ccx_runs"], info["bladecase_runs"] = ccx_runs, bc_runs
        report(ccx_runs, bc_runs, backends, args, info)
        if args.same_rule:
            same_rule(ccx_runs, deck, args, backends[0], info)
        if args.json:
            args.json.parent.mkdir(parents=True, exist_ok=True)
            args.json.write_text(json.dumps(info, indent=2))
    finally:
        if args.keep is None:
            shutil.rmtree(folder, ignore_errors=True)
    return 0


def report(ccx_runs: list[dict], bc_runs: dict[str, list[dict]], backends: list[str], args, info: dict) -> None:
    ccx_ok, ccx_busy = quiet_runs(ccx_runs)
    if not ccx_ok:
        print(f"\n  ccx failed: {ccx_runs[-1]['error']}")
        return
    if ccx_ok[0]["cpu_lines"]:
        row("ccx says", " | ".join(dict.fromkeys(ccx_ok[0]["cpu_lines"])))
    if not all(r["exact_peak"] for r in ccx_runs + [r for rs in bc_runs.values() for r in rs]):
        row("NOTE", f"no {GNU_TIME}: peak memories are os.wait4's ru_maxrss, which includes the launching "
            "Python's memory (an upper bound)")
    t_ccx, m_ccx = median(ccx_ok, "seconds"), median(ccx_ok, "peak_MiB")
    f_ccx = ccx_ok[0]["frequencies_Hz"]
    print(f"\n  {'':<30}{'wall s':>10}{'peak MiB':>10}{'cpu s':>9}")
    print(f"  {'ccx (C3D10)':<30}{t_ccx:10.2f}{m_ccx:10.0f}{median(ccx_ok, 'cpu_seconds'):9.1f}"
          + spread(ccx_ok, ccx_busy))
    summary = {"ccx_seconds": t_ccx, "ccx_peak_MiB": m_ccx, "bladecase": {}}
    for b in backends:
        ok, busy = quiet_runs(bc_runs[b])
        if not ok:
            print(f"  bladecase ({b}) failed: {bc_runs[b][-1]['error']}")
            continue
        r0 = ok[0]
        t_bc, m_bc = median(ok, "seconds"), median(ok, "peak_MiB")
        label = f"bladecase ({r0['backend']}, {r0['eigen_method']})"
        print(f"  {label:<30}{t_bc:10.2f}{m_bc:10.0f}{median(ok, 'cpu_seconds'):9.1f}{spread(ok, busy)}")
        d2f = median(ok, "deck_to_frequencies")
        print(f"    {'phase':<28}{'s':>10}{'peak MiB':>10}   (in-process; medians)")
        for p in PHASES:
            print(f"    {p:<28}{median(ok, 'phase_seconds', p):10.2f}{median(ok, 'phase_peak_MiB', p):10.0f}")
        print(f"    {'deck to frequencies':<28}{d2f:10.2f}")
        print(f"    {'interpreter start, exit':<28}{t_bc - median(ok, 'phase_seconds', 'import') - d2f:10.2f}")
        diff = max(abs(a / c - 1) for a, c in zip(r0["frequencies_Hz"], f_ccx))
        ratio, ratio_in = t_bc / t_ccx, d2f / t_ccx
        summary["bladecase"][b] = {"seconds": t_bc, "peak_MiB": m_bc, "deck_to_frequencies": d2f,
                                   "ratio": ratio, "max_rel_freq_diff": diff, "dofs": r0["dofs"]}
        print()
        row("dofs (free) / element", f"{r0['dofs']} / C3D10 = bladecase {r0['body_type']} at order 2 (curved), "
            f"{r0['clamped_nodes']} clamped nodes")
        row("bladecase factor backend / eigen-solver", f"{r0['backend']} / {r0['eigen_method']}  (nnz K "
            f"{r0['nnz_K']:,})")
        row("time ccx / bladecase", f"{t_ccx:.2f} s / {t_bc:.2f} s (process; deck to frequencies {d2f:.2f} s)")
        row("peak memory ccx / bladecase", f"{m_ccx:.0f} MiB / {m_bc:.0f} MiB  (ratio {m_bc / m_ccx:.2f})")
        row("ratio bladecase / ccx (time)", f"{ratio:.2f}  (deck to frequencies only: {ratio_in:.2f})")
        met = "MET" if ratio <= GOAL_RATIO else "NOT MET"
        row(f"goal bladecase <= {GOAL_RATIO:g} x ccx time", f"{met}  ({t_bc:.2f} s vs {GOAL_RATIO * t_ccx:.2f} s)")
        row(f"max relative difference of the {len(f_ccx)} frequencies", f"{diff:.1e}  "
            f"({'agree' if diff <= 1e-3 else 'DO NOT AGREE'} to 1e-3; ccx integrates C3D10 stiffness and mass with 4 "
            "points, bladecase with scikit-fem's P2 rule: --same-rule checks)")
        row("f1 ... f20 (Hz), ccx", " ".join(f"{f:.6g}" for f in f_ccx))
        row("f1 ... f20 (Hz), bladecase", " ".join(f"{f:.6g}" for f in r0["frequencies_Hz"]))
    info["summary"] = summary


def same_rule(ccx_runs: list[dict], deck: Path, args, backend: str, info: dict) -> None:
    """The diagnostic of ``--same-rule``: bladecase with CalculiX's 4-point rule on C3D10, against ccx."""
    ok = [r for r in ccx_runs if "error" not in r]
    r = run_bladecase(deck, args.threads, args.count, backend, args.method, 0, intorder=2)
    if not ok or "error" in r:
        print(f"\n  --same-rule: failed ({r.get('error', 'ccx failed')})")
        return
    diff = max(abs(a / c - 1) for a, c in zip(r["frequencies_Hz"], ok[0]["frequencies_Hz"]))
    info["same_rule_max_rel_freq_diff"] = diff
    row("--same-rule: bladecase with ccx's 4-point rule", f"max relative difference from ccx {diff:.1e} (ccx "
        "prints 7 digits)")


def _ccx_version(ccx: str) -> str:
    try:
        text = subprocess.run([ccx, "-v"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return "version unknown"
    m = re.search(r"Version\s+(\S+)", text)
    return f"version {m.group(1)}" if m else "version unknown"


def _ccx_solvers(ccx: str) -> str:
    """The sparse solver libraries ``ccx`` is linked with (from ``ldd``), e.g. ``spooles, arpack``."""
    try:
        text = subprocess.run(["ldd", ccx], capture_output=True, text=True, timeout=30).stdout.lower()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    names = [n for n in ("spooles", "pardiso", "mkl", "pastix", "arpack", "openblas", "gomp") if n in text]
    return ", ".join(names) or "none found"


if __name__ == "__main__":
    sys.exit(main())
