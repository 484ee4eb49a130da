"""Seed paper, Fig. 3: periodic trajectories with two impacts per period along a nonsmooth mode.

System: the 2-dof chain of the paper's Sec. 1.4 (``bladecase.chain(2, k=1,
m=1/2, gap=1)``; T₂ = 2π/ω₂ = 2.7459).  The 2-ipp families are followed with
``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``; the one whose
admissible arc ends closest to ``T = 5T₂`` is the paper's red curve of Fig. 2,
between ① (T ≈ 13.33: a 1-ipp orbit of period T/2 seen with two impacts,
``t₁ = T/2``) and ② (T → 5T₂ ≈ 13.73: the impulses vanish and the motion
tends to the fifth harmonic of the second linear mode, touching the obstacle
five times per period).  In between are genuine 2-ipp motions.

The figure shows the contact mass ``x₂(t)`` (and ``x₁(t)``) over one period,
time normalised by ``T``, for orbits evenly spaced in ``T`` along that arc;
the obstacle ``x₂ = d`` is reached exactly at the two impacts ``t = t₁`` and
``t = T`` and never crossed (admissibility is certified by ``bladecase``).

Run: ``python examples/fig3_trajectories.py [--out DIR] [--low]``.
"""

from __future__ import annotations

import argparse
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402


def two_dof() -> bladecase.LinearSystem:
    """The paper's Sec. 1.4 system: k₁ = k₂ = 1, m₁ = m₂ = 1/2, d = 1."""
    return bladecase.chain(2, k=1.0, m=0.5, gap=1.0)


def paper_family(system: bladecase.LinearSystem | None = None) -> tuple[bladecase.Family, bladecase.Arc]:
    """The 2-ipp family (and its admissible arc) whose arc ends closest to ``T = 5T₂``."""
    system = two_dof() if system is None else system
    T2 = 2 * np.pi / system.spectrum.omega[1]
    families = bladecase.nonsmooth_mode(system, 2, (3.0, 14.5), scan=24)
    pairs = [(f, a) for f in families for a in f.arcs]
    if not pairs:
        raise RuntimeError("no admissible 2-ipp arc found")
    return min(pairs, key=lambda fa: abs(fa[1].T_hi - 5 * T2))


def grazing_extension(system: bladecase.LinearSystem, last: bladecase.PeriodicOrbit, T_end: float,
                      fractions=(0.2, 0.4, 0.6, 0.8, 0.9, 0.96)) -> list[bladecase.PeriodicOrbit]:
    """Admissible orbits of the same branch beyond ``last``, towards ``T_end`` (excluded).

    Work-around: the continuation of ``nonsmooth_mode`` stops at T ≈ 13.7227,
    short of the end ② of the branch at the resonant period 5T₂ = 13.7293,
    although admissible 2-ipp orbits of the branch exist up to 5T₂ (their
    impulses vanish there).  They are found directly with
    ``bladecase.orbits_kipp(system, T, 2)`` at periods ``last.T + f·(T_end -
    last.T)``, keeping the admissible, non-repeated solution whose ``t₁/T`` is
    closest to the previous orbit's.
    """
    out, prev = [], last
    for f in fractions:
        T = last.T + f * (T_end - last.T)
        cands = [o for o in bladecase.orbits_kipp(system, T, 2) if o.admissible and o.repeats == 1]
        phase = prev.impact_times[0] / prev.T
        cands = [o for o in cands if abs(o.impact_times[0] / o.T - phase) < 0.01]
        if not cands:
            break
        prev = min(cands, key=lambda o: abs(o.impact_times[0] / o.T - phase))
        out.append(prev)
    return out


def mode_orbits(family: bladecase.Family, arc: bladecase.Arc,
                system: bladecase.LinearSystem | None = None) -> list[bladecase.PeriodicOrbit]:
    """The orbits of the paper's mode: the admissible arc of ``family`` (sorted by
    ``T``) followed by its :func:`grazing_extension` towards ``5T₂``."""
    system = family.system if system is None else system
    T2 = 2 * np.pi / system.spectrum.omega[1]
    orbits = sorted(family.orbits[arc.start: arc.stop + 1], key=lambda o: o.T)
    return orbits + grazing_extension(system, orbits[-1], 5 * T2)


def arc_orbits(orbits: list[bladecase.PeriodicOrbit], n: int = 6) -> list[bladecase.PeriodicOrbit]:
    """``n`` of ``orbits`` evenly spaced in ``T`` (the ones nearest to ``n`` equally
    spaced periods; both ends included), sorted by ``T``."""
    T = np.array([o.T for o in orbits])
    targets = np.linspace(T.min(), T.max(), n)
    pick = sorted({int(np.argmin(np.abs(T - Tt))) for Tt in targets}, key=lambda i: T[i])
    return [orbits[i] for i in pick]


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the Fig. 3 trajectories; return the PNG paths written."""
    low = resolution == "low"
    n_t = 400 if low else 2000
    out = pathlib.Path(out_dir)
    system = two_dof()
    d = system.gap
    T2 = 2 * np.pi / system.spectrum.omega[1]
    family, arc = paper_family(system)
    every = mode_orbits(family, arc, system)
    orbits = arc_orbits(every, 6)
    T_top = every[-1].T
    print(f"arc: T in [{arc.T_lo:.6f}, {arc.T_hi:.6f}], extended with orbits_kipp to {T_top:.6f} "
          f"(5 T2 = {5 * T2:.6f})")

    fig, (ax, ax1) = plt.subplots(2, 1, figsize=(12.8, 7.0), height_ratios=[2.1, 1], sharex=True,
                                  layout="constrained")
    cmap = plt.get_cmap("viridis")
    theta = np.linspace(0.0, 1.0, n_t)
    for n, o in enumerate(orbits):
        c = cmap(n / max(len(orbits) - 1, 1) * 0.92)
        x, _ = o.state(theta * o.T)
        t1 = o.impact_times[0]
        tag = ""
        if n == 0:
            tag = "  ① (t₁ = T/2)"
        elif n == len(orbits) - 1:
            tag = "  ② (→ 5T₂)"
        label = f"T = {o.T:.4f}, t₁/T = {t1 / o.T:.3f}, Λ = {o.impulses[0]:.3f}{tag}"
        ax.plot(theta, x[1], color=c, lw=1.6, label=label)
        ax1.plot(theta, x[0], color=c, lw=1.2)
        ax.plot([t1 / o.T, 1.0], [d, d], "v", color=c, ms=7, mec="k", mew=0.5, zorder=4)
        if n == 0:
            ax.plot([0.0], [d], "v", color=c, ms=7, mec="k", mew=0.5, zorder=4)
        print(f"  T = {o.T:.6f}  t1 = {t1:.6f}  impulses = {o.impulses.round(6).tolist()}  "
              f"energy = {o.energy:.5f}  max x2 - d = {x[1].max() - d:.2e}")
    ax.axhline(d, color="k", lw=2.2, zorder=3)
    ax.fill_between([0, 1], d, d + 0.35, color="0.82", lw=0, zorder=2)
    ax.text(0.5, d + 0.17, "obstacle  $x_2 = d$", ha="center", va="center", fontsize=10,
            bbox=dict(fc="white", ec="none", pad=1.5), zorder=3)
    ax.text(1.01, 0.55,
            "① a 1-ipp orbit of period T/2 seen with\n    two impacts per period (t₁ = T/2)\n"
            "② as T → 5T₂ the impulses vanish and the\n    motion tends to the 5th harmonic of\n"
            "    linear mode 2 (five contacts per period)\n\n"
            f"continuation (nonsmooth_mode) stops at\nT = {arc.T_hi:.4f}; orbits beyond it: orbits_kipp",
            transform=ax.transAxes, fontsize=8.5, va="top", ha="left")
    ax.set_ylim(-1.55, d + 0.35)
    ax.set_xlim(0, 1)
    ax.set_ylabel(r"contact mass $x_2(t)$")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, framealpha=0.95,
              title="orbits along the admissible arc\n(▼ = impacts, Λ = impulse)", title_fontsize=9)
    ax.set_title(f"2-ipp periodic orbits along the nonsmooth mode ① → ②, "
                 f"T ∈ [{arc.T_lo:.4f}, {T_top:.4f}]  (5T₂ = {5 * T2:.4f})", fontsize=10.5)
    ax1.set_ylabel(r"$x_1(t)$")
    ax1.set_xlabel(r"normalised time $t/T$")
    for a in (ax, ax1):
        a.grid(alpha=0.3)
    fig.suptitle("Seed paper Fig. 3 — periodic trajectories with two impacts per period, 2-dof chain",
                 fontsize=12.5)
    path = out / "fig3_trajectories.png"
    save_figure(fig, path, dpi=110 if low else 160)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/examples", help="output directory (default: %(default)s)")
    parser.add_argument("--low", action="store_true", help="low resolution (fast)")
    args = parser.parse_args()
    t0 = time.perf_counter()
    paths = main(args.out, "low" if args.low else "full")
    print("wrote", *paths, f"({time.perf_counter() - t0:.1f} s)")
