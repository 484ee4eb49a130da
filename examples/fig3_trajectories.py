"""Seed paper, Fig. 3: periodic trajectories with two impacts per period along a nonsmooth mode.

System: the 2-dof chain of the paper's Sec. 1.4 (``bladecase.chain(2, k=1,
m=1/2, gap=1)``; T₂ = 2π/ω₂ = 2.7459).  The 2-ipp families are followed with
``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``; the admissible
arc that ends closest to ``T = 5T₂`` (``_paper.paper_mode``) is the paper's
red curve of Fig. 2, between ① (T ≈ 13.33: a 1-ipp orbit of period T/2
seen with two impacts, ``t₁ = T/2``) and ② (T → 5T₂ ≈ 13.73: the impulses
vanish and the motion tends to the fifth harmonic of the second linear mode,
touching the obstacle five times per period).  In between are genuine 2-ipp motions.

The figure shows the contact mass ``x₂(t)`` (and ``x₁(t)``) over one period,
time normalised by ``T``, for orbits evenly spaced in ``T`` along that arc;
the obstacle ``x₂ = d`` is reached exactly at the two impacts ``t = t₁`` and
``t = T`` and never crossed (admissibility is certified by ``bladecase``).

Run: ``python examples/fig3_trajectories.py [--out DIR] [--low]``.
"""

from __future__ import annotations

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402


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
    system = paper.two_dof()
    d = system.gap
    T5 = paper.five_T2(system)
    mode = paper.paper_mode(system)
    arc = mode.arcs[0]
    orbits = arc_orbits(mode.orbits, 6)
    print(f"arc: T in [{arc.T_lo:.6f}, {arc.T_hi:.6f}] (5 T2 = {T5:.6f})")

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
            "    linear mode 2 (five contacts per period)",
            transform=ax.transAxes, fontsize=8.5, va="top", ha="left")
    ax.set_ylim(-1.55, d + 0.35)
    ax.set_xlim(0, 1)
    ax.set_ylabel(r"contact mass $x_2(t)$")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, framealpha=0.95,
              title="orbits along the admissible arc\n(▼ = impacts, Λ = impulse)", title_fontsize=9)
    ax.set_title(f"2-ipp periodic orbits along the nonsmooth mode ① → ②, "
                 f"T ∈ [{arc.T_lo:.4f}, {arc.T_hi:.4f}]  (5T₂ = {T5:.4f})", fontsize=10.5)
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
    paper.run(main, __doc__)
