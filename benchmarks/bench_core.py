"""Performance benchmark of the bladecase core on the seed paper's spring–mass chain.

Reference: the seed paper (Thorin & Legrand 2016) reports about 2 ms per
state-space coordinate for a 2000-dof chain (Mathematica).  This script times
the same kind of work on ``bladecase.chain(n, k=1.0, m=1.0/n, gap=1.0)``
(default ``n = 2000``) and prints a report of figures and ratios:

(a) spectral data — ``system.spectrum`` (a cached property) on a freshly
    built system at every repeat; the build itself is timed separately.
(b) one periodic orbit with one impact per period at ``T = 0.97·T₁``
    (``T₁ = 2π/ω₁``; ``--t-ratio`` changes the factor):
    * orbit construction ``bladecase.orbit_1ipp(system, T)``, which includes
      the certified admissibility check; the same call with
      ``certify=False`` gives the share of the certification;
    * ``orbit.state(np.linspace(0, T, instants))``, i.e. all ``n`` positions
      and ``n`` velocities at every instant.  Per-coordinate time =
      state time / (2n · instants), compared with the paper's 2 ms.
      Target: at least 10,000x faster.
(c) a certified 1-ipp backbone ``bladecase.backbone(system, periods)`` with
    ``periods = np.linspace(0.8·T₁, 0.999·T₁, --periods)`` (the spectrum is
    already cached here; it is timed in (a)).  Reported: total time, number
    of admissible intervals, and a split between the scan (one
    ``orbit_1ipp`` call per period, timed on its own) and the refinement of
    the interval ends by bisection (total minus scan).
    Target: under 10 s on a 2-core machine.

Every time is the best of ``--repeat`` runs (``time.perf_counter``).  The
machine (platform, CPU count, numpy/scipy versions, BLAS) and the peak
resident memory of the process (``ru_maxrss``) are printed too.

Targets are reported as met / not met; the script never fails on a time and
exits 0.  ``--json FILE`` also writes every figure to ``FILE``.

Run::

    cd /work/main && .venv/bin/python benchmarks/bench_core.py [--n 2000]
        [--periods 200] [--instants 1000] [--repeat 3] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import scipy

import bladecase

#: Seed paper (Thorin & Legrand 2016): seconds per state-space coordinate at 2000 dofs.
PAPER_SECONDS_PER_COORDINATE = 2e-3
#: Target (b): per-coordinate time at least this many times below the paper's.
TARGET_SPEEDUP = 1e4
#: Target (c): certified backbone in under this many seconds (2-core machine).
TARGET_BACKBONE_SECONDS = 10.0
#: Machine on which target (c) is defined.
TARGET_CORES = 2


def best_of(repeat: int, run: Callable[..., Any], setup: Callable[[], tuple] = tuple) -> tuple[float, list[float], Any]:
    """Time ``run(*setup())`` ``repeat`` times (``setup`` untimed).

    Returns ``(best time, all times, result of the best run)``.
    """
    times, best = [], None
    for _ in range(repeat):
        args = setup()
        start = time.perf_counter()
        result = run(*args)
        times.append(time.perf_counter() - start)
        if times[-1] == min(times):
            best = result
    return min(times), times, best


def in_child(module: str, call: str, env: dict | None = None) -> dict:
    """``call`` (an expression on the benchmark module ``module``, imported as ``b``) in a fresh interpreter, so
    that its peak memory is its own; its JSON result (printed after ``RESULT``), or ``{"error": last line}``.
    One BLAS thread unless ``env`` or the caller's environment says otherwise."""
    import subprocess

    env = dict(os.environ, **(env or {}))
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    code = (f"import json, sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import {module} as b; "
            f"print('RESULT' + json.dumps({call}))")
    proc = subprocess.run([sys.executable, "-W", "ignore", "-c", code], env=env, capture_output=True, text=True)
    rows = [r for r in proc.stdout.splitlines() if r.startswith("RESULT")]
    if proc.returncode or not rows:
        return {"error": (proc.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(rows[-1][len("RESULT"):])


def fmt_time(seconds: float) -> str:
    """A duration with a readable unit."""
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if abs(seconds) >= scale:
            return f"{seconds / scale:.3f} {unit}"
    return f"{seconds / 1e-9:.3f} ns"


def verdict(met: bool) -> str:
    return "MET" if met else "NOT MET"


def line(label: str, value: str) -> None:
    print(f"  {label:<48} {value}")


# ---------------------------------------------------------------------------
# Machine


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for row in fh:
                if row.startswith("model name"):
                    return row.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def blas_info() -> str:
    """Name and version of numpy's BLAS from its build configuration (cheap; may be unavailable)."""
    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
        return f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:  # older numpy, or a build without this information
        return "unknown"


def machine() -> dict:
    info = {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu": cpu_model(),
        "cpu_count": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "bladecase": bladecase.__version__,
        "blas": blas_info(),
        "thread_env": {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
                       if k in os.environ},
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }
    print("Machine")
    line("platform", info["platform"])
    line("python", info["python"])
    line("CPU", f"{info['cpu']}  ({info['cpu_count']} logical CPUs, {info['cpus_usable']} usable)")
    line("numpy / scipy / bladecase", f"{info['numpy']} / {info['scipy']} / {info['bladecase']}")
    line("BLAS (numpy)", info["blas"])
    line("thread variables", ", ".join(f"{k}={v}" for k, v in info["thread_env"].items()) or "none set")
    if info["load_average"] is not None:
        load = info["load_average"]
        note = "  (machine recently busy: times may be inflated)" if load[0] > 0.5 else ""
        line("load average at start (1, 5, 15 min)", " ".join(f"{x:.2f}" for x in load) + note)
    return info


# ---------------------------------------------------------------------------
# (a) spectral data


def bench_spectrum(n: int, repeat: int) -> tuple[dict, bladecase.LinearSystem]:
    def build():
        return bladecase.chain(n, k=1.0, m=1.0 / n, gap=1.0)

    t_build, build_times, system = best_of(repeat, build)
    t_spec, spec_times, spectrum = best_of(repeat, lambda s: s.spectrum, lambda: (build(),))
    omega = spectrum.omega
    res = {
        "build_s": t_build, "build_runs_s": build_times,
        "spectrum_s": t_spec, "spectrum_runs_s": spec_times,
        "modes": int(omega.size), "active_modes": int(spectrum.active.sum()),
        "omega_1": float(omega[0]), "omega_max": float(omega[-1]), "T1": float(2 * np.pi / omega[0]),
    }
    print(f"\n(a) Spectral data: system.spectrum on a fresh chain, n = {n}")
    line("system construction (chain, checks)", fmt_time(t_build))
    line("spectrum (eigen-solution, all modes)", fmt_time(t_spec))
    line("modes / modes seeing the contact", f"{res['modes']} / {res['active_modes']}")
    line("ω₁ / ω_max", f"{res['omega_1']:.6g} / {res['omega_max']:.6g} rad per time unit")
    line("T₁ = 2π/ω₁", f"{res['T1']:.6g}")
    _ = system.spectrum  # (b) and (c) use this system with its spectrum already cached
    return res, system


# ---------------------------------------------------------------------------
# (b) one orbit


def bench_orbit(system: bladecase.LinearSystem, t_ratio: float, instants: int, repeat: int) -> dict:
    n = system.n
    T1 = float(2 * np.pi / system.spectrum.omega[0])
    T = t_ratio * T1
    t_orbit, orbit_times, orbit = best_of(repeat, lambda: bladecase.orbit_1ipp(system, T))
    t_bare, bare_times, _ = best_of(repeat, lambda: bladecase.orbit_1ipp(system, T, certify=False))
    t = np.linspace(0.0, T, instants)
    t_state, state_times, (x, v) = best_of(repeat, orbit.state, lambda: (t,))
    if x.shape != (n, instants) or v.shape != (n, instants):
        raise RuntimeError(f"state returned shapes {x.shape}, {v.shape}; expected ({n}, {instants})")
    coords = 2 * n * instants
    per_coord = t_state / coords
    speedup = PAPER_SECONDS_PER_COORDINATE / per_coord
    per_coord_all = (t_state + t_orbit) / coords
    res = {
        "T": T, "T_over_T1": t_ratio, "admissible": bool(orbit.admissible),
        "max_violation": float(orbit.max_violation), "impulse": float(orbit.impulses[0]),
        "orbit_s": t_orbit, "orbit_runs_s": orbit_times,
        "orbit_uncertified_s": t_bare, "orbit_uncertified_runs_s": bare_times,
        "certification_s": t_orbit - t_bare,
        "instants": instants, "coordinates": coords,
        "state_s": t_state, "state_runs_s": state_times,
        "per_coordinate_s": per_coord,
        "speedup_vs_paper": speedup,
        "per_coordinate_with_orbit_s": per_coord_all,
        "speedup_vs_paper_with_orbit": PAPER_SECONDS_PER_COORDINATE / per_coord_all,
        "target_speedup": TARGET_SPEEDUP,
        "target_met": bool(speedup >= TARGET_SPEEDUP),
    }
    print(f"\n(b) One 1-ipp orbit at T = {t_ratio:g}·T₁ = {T:.6g}, all {n} dofs at {instants} instants")
    line("orbit admissible (certified)", f"{'yes' if orbit.admissible else 'no'}"
         f"  (max wᵀx - d = {orbit.max_violation:.3g}, Λ = {orbit.impulses[0]:.6g})")
    line("orbit construction, orbit_1ipp", fmt_time(t_orbit))
    line("  of which certified admissibility check", f"{fmt_time(t_orbit - t_bare)}"
         f"  (certify=False: {fmt_time(t_bare)})")
    line("state(t): x, v each (n, instants)", fmt_time(t_state))
    line("per state-space coordinate (/ 2n·instants)", f"{fmt_time(per_coord)}  ({coords:,} coordinates)")
    line("paper: 2 ms per coordinate -> speed-up", f"{speedup:,.0f}x")
    line("  same, counting orbit construction too", f"{res['speedup_vs_paper_with_orbit']:,.0f}x"
         f"  ({fmt_time(per_coord_all)} per coordinate)")
    line(f"target: >= {TARGET_SPEEDUP:,.0f}x faster than the paper", verdict(res["target_met"]))
    return res


# ---------------------------------------------------------------------------
# (c) certified backbone


def scan(system: bladecase.LinearSystem, periods: np.ndarray) -> list:
    """The scan part of ``backbone``: one ``orbit_1ipp`` per period, each timed; ``(orbit or None, seconds)``."""
    out = []
    for T in periods:
        start = time.perf_counter()
        try:
            orbit = bladecase.orbit_1ipp(system, T)
        except ValueError:  # resonant period: no orbit, as in backbone
            orbit = None
        out.append((orbit, time.perf_counter() - start))
    return out


def bench_backbone(system: bladecase.LinearSystem, count: int, repeat: int, spectrum_s: float) -> dict:
    T1 = float(2 * np.pi / system.spectrum.omega[0])
    periods = np.linspace(0.8 * T1, 0.999 * T1, count)
    t_total, total_times, bb = best_of(repeat, lambda: bladecase.backbone(system, periods))
    t_scan, scan_times, scanned = best_of(repeat, lambda: scan(system, np.unique(periods)))
    t_refine = t_total - t_scan
    ends = sum(iv.refined_lo + iv.refined_hi for iv in bb.intervals)
    adm_t = [s for o, s in scanned if o is not None and o.admissible]
    rej_t = [s for o, s in scanned if o is not None and not o.admissible]
    resonant = sum(o is None for o, _ in scanned)
    res = {
        "periods": int(bb.periods.size), "T_range": [float(periods[0]), float(periods[-1])],
        "total_s": t_total, "total_runs_s": total_times,
        "scan_s": t_scan, "scan_runs_s": scan_times,
        "refinement_s": t_refine,
        "intervals": len(bb.intervals), "refined_ends": int(ends),
        "admissible_scan_points": int(bb.admissible.sum()), "resonant_scan_points": int(resonant),
        "scan_orbit_mean_s": t_scan / max(1, len(scanned)),
        "scan_orbit_admissible_mean_s": float(np.mean(adm_t)) if adm_t else None,
        "scan_orbit_rejected_mean_s": float(np.mean(rej_t)) if rej_t else None,
        "refinement_per_end_s": t_refine / ends if ends else None,
        "total_with_spectrum_s": t_total + spectrum_s,
        "target_s": TARGET_BACKBONE_SECONDS, "target_cores": TARGET_CORES,
        "target_met": bool(t_total < TARGET_BACKBONE_SECONDS),
        "intervals_T": [[iv.T_lo, iv.T_hi] for iv in bb.intervals],
    }
    print(f"\n(c) Certified 1-ipp backbone, {res['periods']} periods in "
          f"[0.8·T₁, 0.999·T₁] = [{periods[0]:.6g}, {periods[-1]:.6g}] (spectrum cached)")
    line("total, backbone()", fmt_time(t_total))
    line("  scan: one orbit_1ipp per period", f"{fmt_time(t_scan)}  ({100 * t_scan / t_total:.0f}%)")
    line("  interval-end refinement (total - scan)", f"{fmt_time(t_refine)}  ({100 * t_refine / t_total:.0f}%)")
    line("admissible intervals / refined ends", f"{res['intervals']} / {ends}")
    line("admissible / resonant scan points", f"{res['admissible_scan_points']} / {resonant} of {res['periods']}")
    per = f"{fmt_time(res['scan_orbit_mean_s'])} mean"
    if adm_t and rej_t:
        per += f" (admissible {fmt_time(np.mean(adm_t))}, rejected {fmt_time(np.mean(rej_t))})"
    line("scan, per orbit", per)
    if ends:
        line("refinement, per refined end", fmt_time(t_refine / ends))
    line("total including the spectrum of (a)", fmt_time(res["total_with_spectrum_s"]))
    line(f"target: < {TARGET_BACKBONE_SECONDS:g} s on a {TARGET_CORES}-core machine",
         f"{verdict(res['target_met'])}  ({t_total / TARGET_BACKBONE_SECONDS:.2f} of the budget)")
    return res


# ---------------------------------------------------------------------------


def peak_memory_mib() -> float:
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 2**20 if sys.platform == "darwin" else rss / 2**10  # bytes on macOS, KiB elsewhere


def positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=positive_int, default=2000, help="dofs of the chain (default 2000)")
    parser.add_argument("--periods", type=positive_int, default=200, help="periods of the backbone scan (default 200)")
    parser.add_argument("--instants", type=positive_int, default=1000, help="instants for orbit.state (default 1000)")
    parser.add_argument("--repeat", type=positive_int, default=3, help="runs per measurement, best kept (default 3)")
    parser.add_argument("--t-ratio", type=float, default=0.97, help="period of the orbit in (b), as a multiple "
                        "of T1 = 2π/ω₁ (default 0.97)")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    args = parser.parse_args(argv)

    print(f"bladecase core benchmark: chain(n={args.n}, k=1, m=1/n, gap=1), best of {args.repeat} run(s)")
    if (args.n, args.periods, args.instants) != (2000, 200, 1000):
        print("note: the targets are defined for --n 2000 --periods 200 --instants 1000")
    print()
    report: dict = {"arguments": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}}
    report["machine"] = machine()
    report["spectrum"], system = bench_spectrum(args.n, args.repeat)
    report["orbit"] = bench_orbit(system, args.t_ratio, args.instants, args.repeat)
    report["backbone"] = bench_backbone(system, args.periods, args.repeat, report["spectrum"]["spectrum_s"])
    report["peak_memory_mib"] = peak_memory_mib()

    print("\nSummary")
    o, b = report["orbit"], report["backbone"]
    line(f"(b) >= {TARGET_SPEEDUP:,.0f}x faster per coordinate than 2 ms",
         f"{verdict(o['target_met'])}  ({o['speedup_vs_paper']:,.0f}x)")
    line(f"(c) backbone < {TARGET_BACKBONE_SECONDS:g} s ({TARGET_CORES} cores)",
         f"{verdict(b['target_met'])}  ({b['total_s']:.2f} s on {report['machine']['cpus_usable']} usable CPUs)")
    line("peak resident memory (ru_maxrss)", f"{report['peak_memory_mib']:.0f} MiB")

    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(report, indent=2) + "\n")
        print(f"\nfigures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
