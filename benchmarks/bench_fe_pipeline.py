"""FE front end, stage by stage, SuperLU against the faster factorisation backend.

For each blade size (twisted, tapered NACA 0012 blade of ``bench_fem.py``; mesh sizes 5.5 / 2.5 / 1.4 mm give
5 490 / 26 316 / 110 424 P2 dofs) and each backend (``superlu`` and the best available, e.g. ``cholmod``),
one fresh process (so that its peak memory is its own) runs, timed with ``time.perf_counter``:

(a) ``bladecase.blade_mesh``;  (b) ``bladecase.assemble`` (Ti-6Al-4V, P2, consistent mass, root clamped);
(c) ``bladecase.fe.stiffness_factor`` — the ONE factorisation of K, reused by (d) and (e);
(d) ``bladecase.natural_frequencies(model, 20, factor=...)`` (ARPACK, or block Lanczos on CHOLMOD);
(e) ``bladecase.reduce(model, contact, "lanczos-si", 50, factor=...)``, contact at the tip node farthest
    along the span.

After each stage the process's peak resident memory (``ru_maxrss``) is recorded.  The table gives the stage
times per backend, the ratio SuperLU / new, and the performance target at the largest size: mesh to reduced
model and 20 frequencies in at most 30 s and 1.5 GB (1.5e9 bytes = 1431 MiB).  Single-threaded BLAS
(``OPENBLAS_NUM_THREADS=1`` is set for the children unless already set).  Exit status 0 whatever the times;
``--json FILE`` writes every figure.

Run::

    cd /work/main && OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_fe_pipeline.py
        [--skip-110k] [--sizes 0.0055,0.0025,0.0014] [--backends superlu,cholmod] [--count 20] [--steps 50]
        [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

from bench_core import in_child, line, machine, verdict

#: Mesh sizes (m) of the three blades: ~5k, ~26k, ~110k P2 dofs.
SIZES = (0.0055, 0.0025, 0.0014)
#: The performance target at the largest size: seconds from mesh to reduced model, and peak memory (MiB).
TARGET_SECONDS, TARGET_MIB = 30.0, 1.5e9 / 2**20
STAGES = ("mesh", "assemble", "factor", "frequencies", "reduce")


def peak_mib() -> float:
    """Peak resident memory of this process so far (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run_one(size: float, count: int, steps: int) -> dict:
    """The five stages on one blade in this process (backend from ``$BLADECASE_FACTOR``)."""
    from bench_fem import blade

    import bladecase
    from bladecase.fe import stiffness_factor

    out: dict = {"size": size, "seconds": {}, "peak_MiB": {}}

    def stage(name, fn):
        t0 = time.perf_counter()
        result = fn()
        out["seconds"][name] = time.perf_counter() - t0
        out["peak_MiB"][name] = peak_mib()
        return result

    mesh = stage("mesh", lambda: blade(size))
    model = stage("assemble", lambda: bladecase.assemble(mesh, "Ti-6Al-4V", order=2, clamp="root"))
    factor = stage("factor", lambda: stiffness_factor(model))
    freqs = stage("frequencies", lambda: bladecase.natural_frequencies(model, count, factor=factor))
    contact = bladecase.Contact.farthest(model, [0.0, 0.0, 1.0], None, 1e-4, group="tip")
    reduced = stage("reduce", lambda: bladecase.reduce(model, contact, "lanczos-si", steps, factor=factor))
    out.update(dofs=model.n_dofs, backend=factor.backend, frequencies_Hz=freqs.tolist(),
               reduced_size=int(reduced.size),
               total_seconds=sum(out["seconds"].values()), total_peak_MiB=peak_mib())
    return out


def child(size: float, backend: str, count: int, steps: int) -> dict:
    """:func:`run_one` in a fresh interpreter with ``BLADECASE_FACTOR=backend``."""
    out = in_child("bench_fe_pipeline", f"b.run_one({size!r}, {count!r}, {steps!r})", {"BLADECASE_FACTOR": backend})
    return {"size": size, "backend": backend, **out} if "error" in out else out


def cell(run: dict | None, stage: str, key: str) -> float | None:
    """``run[key][stage]`` (``key`` ``"seconds"`` or ``"peak_MiB"``; stage ``"total"``: the run's total)."""
    if run is None or "error" in run:
        return None
    if stage == "total":
        return run["total_seconds" if key == "seconds" else "total_peak_MiB"]
    return run[key].get(stage)


def table(results: dict[float, dict[str, dict]], backends: list[str]) -> None:
    ref, new = backends[0], backends[-1]
    head = f"{'dofs':>8} {'stage':<12}" + "".join(f"{b + ' s':>12}" for b in backends)
    print("\n" + head + (f"{'ratio':>8}" if len(backends) > 1 else "") + "   peak MiB " + " / ".join(backends))
    for runs in results.values():
        ok = [r for r in runs.values() if "error" not in r]
        if not ok:
            continue
        for stage in (*STAGES, "total"):
            secs = [cell(runs.get(b), stage, "seconds") for b in backends]
            peaks = [cell(runs.get(b), stage, "peak_MiB") for b in backends]
            cells = "".join(f"{s:12.2f}" if s is not None else f"{'-':>12}" for s in secs)
            ratio = f"{secs[0] / secs[-1]:8.1f}" if len(backends) > 1 and None not in (secs[0], secs[-1]) else ""
            mem = " / ".join(f"{p:.0f}" if p is not None else "-" for p in peaks)
            print(f"{ok[0]['dofs']:>8} {stage:<12}{cells}{ratio}   {mem}")
    largest = results[min(results)]  # the finest mesh: the most dofs
    if new in largest and "error" not in largest[new]:
        r = largest[new]
        print()
        line(f"target at {r['dofs']} dofs ({new})", f"{r['total_seconds']:.1f} s <= {TARGET_SECONDS:g} s: "
             f"{verdict(r['total_seconds'] <= TARGET_SECONDS)};  peak {r['total_peak_MiB']:.0f} MiB <= "
             f"{TARGET_MIB:.0f} MiB: {verdict(r['total_peak_MiB'] <= TARGET_MIB)}")
    if ref in largest and new in largest and ref != new and "error" not in largest[ref] and "error" not in largest[new]:
        f_ref, f_new = largest[ref]["frequencies_Hz"], largest[new]["frequencies_Hz"]
        line("max relative frequency difference", f"{max(abs(a / b - 1) for a, b in zip(f_new, f_ref)):.1e}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)), help="mesh sizes in m, comma-separated")
    parser.add_argument("--skip-110k", action="store_true", help="leave out the 1.4 mm (110k-dof) blade")
    parser.add_argument("--backends", default=None,
                        help="comma-separated backends (default: superlu and the best available)")
    parser.add_argument("--count", type=int, default=20, help="natural frequencies (default 20)")
    parser.add_argument("--steps", type=int, default=50, help="lanczos-si steps of the reduction (default 50)")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    args = parser.parse_args(argv)

    from bladecase.linalg import available_backends

    sizes = [float(s) for s in args.sizes.split(",") if not (args.skip_110k and float(s) <= 0.0014)]
    backends = args.backends.split(",") if args.backends else list(dict.fromkeys(["superlu", available_backends()[0]]))
    print("bladecase FE pipeline benchmark: mesh, assemble, factorise, frequencies, reduce")
    info = {"machine": machine(), "backends": backends, "runs": []}
    results: dict[float, dict[str, dict]] = {}
    for size in sizes:
        for backend in backends:
            r = child(size, backend, args.count, args.steps)
            results.setdefault(size, {})[backend] = r
            info["runs"].append(r)
            print(f"  size {size:g} m, {backend}: " + (r["error"] if "error" in r else
                  f"{r['dofs']} dofs, {r['total_seconds']:.2f} s, peak {r['total_peak_MiB']:.0f} MiB"), flush=True)
    table(results, backends)
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
