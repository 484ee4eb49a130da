"""Benchmark of the k-impacts-per-period solver (``orbits_kipp``, ``nonsmooth_mode``).

(a) The seed paper's Fig. 2 on its 2-dof example (``chain(2, k=1, m=1/2, gap=1)``):
    * the (t₁, T) map of Eq. 15 on a ``--grid`` × ``--grid`` grid (default 400 × 400,
      ``t₁ ∈ [0, 14.5]``, ``T ∈ [1, 14.5]``, points with ``t₁ >= T`` masked), evaluated with
      the pole-free numerator ``N(t₁; T) = s(t₁; T) · Π_j sin(ω_j T/2)``, fully vectorised
      (numpy only); number of grid cells crossed by its zero set;
    * ``nonsmooth_mode(system, 2, (1, 14.5))`` (default ``scan = 24``): families, points,
      admissible arcs;
    * the continuation's exact Jacobian (``KippCurve.jacobian``) against the central differences
      it replaced, per evaluation, at a 3-ipp point of ``chain(200)``.
(b) k = 2 families of a long chain (default ``chain(200, k=1, m=1/200, gap=1)``) over a
    period range covering its first three linear modes, ``T ∈ [0.9·2π/ω₃, 2π/ω₁]``:
    * the start scan (``orbits_kipp`` at the ``--scan`` periods nonsmooth_mode uses);
    * the whole ``nonsmooth_mode`` run (continuation = total − scan);
    * families, points, single-point families, admissible arcs, family lengths in T;
    * the density of resonant periods ``m·2π/ω_j`` and an extrapolation of the scan needed
      to start every family (scan spacing = the median family length in T);
    * a cProfile of ``nonsmooth_mode`` on the sub-range ``--profile-range`` (top functions
      by own time and by cumulative time).

Times are wall-clock (``time.perf_counter``), best of ``--repeat`` for the cheap items,
one run for the expensive ones.  Nothing is asserted; exit status 0.

Run::

    cd /work/main && .venv/bin/python benchmarks/bench_kipp.py [--grid 400] [--n 200]
        [--scan 24] [--repeat 3] [--T-range LO HI] [--profile-range 33 34] [--profile-scan 4] [--skip-b]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import platform
import pstats
import time

import numpy as np
import scipy

import bladecase as bc


def best_of(repeat, fn):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), times, out


def line(label, value):
    print(f"  {label:<58} {value}")


def family_stats(families):
    pts = sum(len(f.orbits) for f in families)
    single = sum(len(f.orbits) == 1 for f in families)
    arcs = [a for f in families for a in f.arcs]
    lengths = np.array([f.T.max() - f.T.min() for f in families]) if families else np.zeros(0)
    adm_pts = sum(int(f.admissible.sum()) for f in families)
    return pts, single, arcs, lengths, adm_pts


# ---------------------------------------------------------------------------
# (a) Fig. 2


def fig2_numerator(omega, b, t1, T):
    """``N = s · Π_j sin(ω_j T/2)`` on the grid (t₁ rows × T columns broadcast)."""
    sh = np.sin(np.multiply.outer(T, omega) / 2)  # (nT, m)
    m = omega.size
    # Π_{l≠j} sin(ω_l T/2) for every j, without dividing (no poles)
    others = np.stack([np.prod(np.delete(sh, j, axis=-1), axis=-1) for j in range(m)], axis=-1)  # (nT, m)
    ph = np.multiply.outer(t1[:, None] - T[None, :] / 2, omega)  # (nt1, nT, m)
    return -(np.sin(ph) * (b**2 / 2) * others[None, :, :]).sum(axis=-1)


def bench_fig2(grid, repeat):
    system = bc.chain(2, k=1.0, m=0.5, gap=1.0)
    omega, b, _ = system.spectrum.contact_modes
    t1 = np.linspace(0.0, 14.5, grid)
    T = np.linspace(1.0, 14.5, grid)
    t_map, runs, N = best_of(repeat, lambda: fig2_numerator(omega, b, t1, T))
    N = np.where(t1[:, None] < T[None, :], N, np.nan)
    sgn = np.sign(N)
    cells = int(np.nansum((sgn[:-1, :] * sgn[1:, :]) < 0) + np.nansum((sgn[:, :-1] * sgn[:, 1:]) < 0))
    print(f"\n(a) Seed Fig. 2, 2-dof example (ω = {omega.round(6).tolist()}), k = 2")
    line(f"Eq. 15 numerator on {grid}×{grid} grid (vectorised numpy)", f"{t_map * 1e3:.2f} ms  (best of {repeat}; "
         f"{t_map / grid**2 * 1e9:.1f} ns per point)")
    line("grid edges crossed by the zero set (t₁ < T)", str(cells))
    t_nsm, runs, fams = best_of(repeat, lambda: bc.nonsmooth_mode(system, 2, (1.0, 14.5)))
    pts, single, arcs, lengths, adm = family_stats(fams)
    line("nonsmooth_mode(sys, 2, (1, 14.5)), scan = 24", f"{t_nsm:.3f} s  (best of {repeat}; runs "
         + ", ".join(f"{r:.2f}" for r in runs) + ")")
    line("families / points / admissible points", f"{len(fams)} / {pts} / {adm}")
    line("admissible arcs", str(len(arcs)))
    for a in sorted(arcs, key=lambda a: a.T_lo):
        line("", f"T ∈ [{a.T_lo:.8f}, {a.T_hi:.8f}]")
    print(f"  (5·T₂ = {5 * 2 * np.pi / omega[1]:.6f}: the paper's red arc ends there)")
    bench_jacobian(repeat)


def bench_jacobian(repeat, n=200, k=3):
    """The continuation's Jacobian (``KippCurve.jacobian``, exact) against the central differences the
    driver used before (2 residual evaluations per unknown), at a k-ipp point of ``chain(n)``."""
    from bladecase.nsm import KippCurve

    system = bc.chain(n, k=1.0, m=1.0 / n, gap=1.0)
    T = 0.9 * 2 * np.pi / system.spectrum.omega[0]
    curve = KippCurve(system, k, T, 1.0)
    z = np.append(np.arange(1, k) / k + 0.013, 1.0)

    def central(h=1e-7):
        return np.column_stack([(curve.residual(z + h * e) - curve.residual(z - h * e)) / (2 * h) for e in np.eye(k)])

    t_exact, _, J = best_of(max(repeat, 5), lambda: curve.jacobian(z))
    t_fd, _, F = best_of(max(repeat, 5), central)
    err = np.abs(F - J).max() / np.abs(J).max()
    line(f"Jacobian, chain({n}), k = {k}: exact / central differences",
         f"{t_exact * 1e3:.3f} ms / {t_fd * 1e3:.3f} ms  (the differences are off by {err:.1e})")


# ---------------------------------------------------------------------------
# (b) long chain


def bench_chain(n, scan, repeat, profile_range, profile_scan, top, T_range=None):
    system = bc.chain(n, k=1.0, m=1.0 / n, gap=1.0)
    t0 = time.perf_counter()
    sp = system.spectrum
    t_spec = time.perf_counter() - t0
    omega = sp.omega
    T_lo, T_hi = 0.9 * 2 * np.pi / omega[2], 2 * np.pi / omega[0]
    if T_range is not None:
        T_lo, T_hi = T_range
    what = "T ∈ [0.9·2π/ω₃, 2π/ω₁]" if T_range is None else "sub-range T"
    print(f"\n(b) k = 2 families of chain({n}, k=1, m=1/{n}, gap=1), {what} = [{T_lo:.6g}, {T_hi:.6g}]")
    line("spectrum", f"{t_spec * 1e3:.1f} ms; {sp.active.sum()} modes see the contact, "
         f"ω₁..ω₃ = {omega[0]:.5g}, {omega[1]:.5g}, {omega[2]:.5g}, ω_max = {omega[-1]:.5g}")
    # resonances m·2π/ω_j inside the range
    n_res = int(sum(np.floor(T_hi * w / (2 * np.pi)) - np.floor(T_lo * w / (2 * np.pi)) for w in omega[sp.active]))
    density = n_res / (T_hi - T_lo)
    line("resonant periods m·2π/ω_j in the range", f"{n_res}  ({density:.0f} per unit T, mean gap "
         f"{1 / density:.2e})")

    periods = np.linspace(T_lo, T_hi, scan)

    def scan_run():
        found = 0
        for T in periods:
            try:
                found += len(bc.orbits_kipp(system, T, 2))
            except ValueError:
                pass
        return found

    t_scan, runs, n_starts = best_of(repeat, scan_run)
    line(f"start scan: orbits_kipp(·, T, 2) at {scan} periods", f"{t_scan:.3f} s  ({t_scan / scan * 1e3:.1f} ms per "
         f"period, {n_starts / scan:.1f} orbits per period; best of {repeat})")

    t0 = time.perf_counter()
    fams = bc.nonsmooth_mode(system, 2, (T_lo, T_hi), scan=scan)
    t_nsm = time.perf_counter() - t0
    pts, single, arcs, lengths, adm = family_stats(fams)
    line(f"nonsmooth_mode(sys, 2, range, scan={scan})", f"{t_nsm:.2f} s  (one run)")
    line("  of which start scan / continuation + certification", f"{t_scan:.2f} s / {t_nsm - t_scan:.2f} s")
    line("families / points / admissible points", f"{len(fams)} / {pts} / {adm}")
    line("single-point families (continuation stopped at once)", f"{single}")
    line("admissible arcs", f"{len(arcs)}")
    if len(fams):
        multi = lengths[lengths > 0]
        line("family length in T: median (multi-point) / max",
             f"{np.median(multi) if multi.size else 0:.3g} / {lengths.max():.3g}")
        line("time per family / per point", f"{t_nsm / len(fams) * 1e3:.1f} ms / {t_nsm / max(pts, 1) * 1e3:.2f} ms")
    # Extrapolation: a start period on every family (scan spacing ~ the median family length)
    multi = lengths[lengths > 0] if len(fams) else np.zeros(0)
    if multi.size:
        med = float(np.median(multi))
        need = int(np.ceil((T_hi - T_lo) / med))
        line("EXTRAPOLATED scan with spacing = median family length",
             f"{need} periods ≈ {need * t_scan / scan / 60:.1f} min of start scan, "
             f"≈ {need * n_starts / scan:.0f} start orbits")
        line("  (one start per resonance gap instead)", f"{n_res} periods ≈ {n_res * t_scan / scan / 60:.1f} min")
        line("EXTRAPOLATED continuation (families ∝ scan, lower bound)",
             f"≈ {t_nsm - t_scan:.0f} s × {need / scan:.0f} = {(t_nsm - t_scan) * need / scan / 3600:.1f} h, "
             "plus the start-coverage test (_passes), O(families × starts)")

    # Profile a sub-range
    lo, hi = profile_range
    pr = cProfile.Profile()
    t0 = time.perf_counter()
    pr.enable()
    sub = bc.nonsmooth_mode(system, 2, (lo, hi), scan=profile_scan)
    pr.disable()
    t_sub = time.perf_counter() - t0
    pts, single, arcs, _, _ = family_stats(sub)
    print(f"\n  cProfile: nonsmooth_mode(sys, 2, ({lo}, {hi}), scan={profile_scan}): {t_sub:.2f} s under the "
          f"profiler, {len(sub)} families, {pts} points, {single} single-point, {len(arcs)} arcs")
    for key in ("tottime", "cumulative"):
        s = io.StringIO()
        pstats.Stats(pr, stream=s).strip_dirs().sort_stats(key).print_stats(top)
        text = s.getvalue()
        body = text[text.index("ncalls"):] if "ncalls" in text else text
        print(f"\n  top {top} by {key}:")
        for row in body.rstrip().splitlines():
            print("    " + row)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--grid", type=int, default=400, help="Fig. 2 grid size per axis (400)")
    ap.add_argument("--n", type=int, default=200, help="dofs of the chain in (b) (200)")
    ap.add_argument("--scan", type=int, default=24, help="start periods of nonsmooth_mode in (b) (24)")
    ap.add_argument("--repeat", type=int, default=3, help="repeats of the cheap timings (3)")
    ap.add_argument("--profile-range", type=float, nargs=2, default=(33.0, 34.0), help="T sub-range profiled in (b)")
    ap.add_argument("--profile-scan", type=int, default=4, help="scan of the profiled sub-range (4)")
    ap.add_argument("--top", type=int, default=15, help="functions listed per profile (15)")
    ap.add_argument("--T-range", type=float, nargs=2, default=None,
                    help="period range of (b) (default: 0.9·2π/ω₃ to 2π/ω₁, about 6 min)")
    ap.add_argument("--skip-b", action="store_true", help="only (a)")
    args = ap.parse_args(argv)
    print("Machine")
    line("platform / python", f"{platform.platform()} / {platform.python_version()}")
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    line("CPUs (logical / usable)", f"{os.cpu_count()} / {usable}")
    line("numpy / scipy / bladecase", f"{np.__version__} / {scipy.__version__} / {bc.__version__}")
    if hasattr(os, "getloadavg"):
        line("load average (1, 5, 15 min)", " ".join(f"{x:.2f}" for x in os.getloadavg()))
    bench_fig2(args.grid, args.repeat)
    if not args.skip_b:
        bench_chain(args.n, args.scan, args.repeat, tuple(args.profile_range), args.profile_scan, args.top,
                    None if args.T_range is None else tuple(args.T_range))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
