"""Seed paper, Fig. 10: two forced damped responses and the corresponding nonsmooth mode.

System and method as ``fig9_forced_response.py`` (n = 5 chain ``bladecase.chain(5, k=1, m=0.2, gap=1)``,
``C = αK``, ``F₀ cos(2πt/T)`` on every mass, ``e = 1``, 500 forcing periods per ``T``, swept up in
frequency from ``T = 10`` to 1.4), for the paper's two other settings: ``F₀ = 0.3, α = 0.003`` and
``F₀ = 1, α = 0.03``.

Left: energies (maximum of ``½vᵀMv + ½xᵀKx`` over the steady cycle) of the periodic states, against
the 1-ipp nonsmooth mode ``bladecase.backbone`` and the admissible 2-ipp modes
``bladecase.nonsmooth_mode(system, 2, (1.4, 10))``.  Right: for each setting, the contact mass
``x₅(t)`` over one cycle of its most energetic periodic state with one impact per forcing period,
next to the 1-ipp orbit of the nonsmooth mode at the same period (``bladecase.orbit_1ipp``), both with
the impact at ``t = 0``.

Run: ``python examples/fig10_forced_response.py [--out DIR] [--low]``.
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
from bladecase.nsm.damping import Damping  # noqa: E402
from bladecase.nsm.newton.forced import simulate_forced  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for the sibling scripts, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402
import fig9_forced_response as fig9  # noqa: E402

CASES = [(0.3, 0.003), (1.0, 0.03)]  # (F₀, α) of the paper's Fig. 10
COLORS = ("C2", "C1")


def response_cycle(s: bladecase.LinearSystem, point, F0: float, alpha: float, n_t: int = 2000):
    """``(θ, x₅)`` over one cycle of the periodic ``point``, the first impact of the cycle at ``θ = 0``
    (``θ = t/T``)."""
    T, p = point.T, point.p
    tr = simulate_forced(s, point.x_end, point.v_end, 2 * p * T, period=T, amplitude=F0,
                         damping=Damping(alpha=alpha))
    t0 = tr.impact_times[0]
    t = t0 + np.linspace(0.0, p * T, n_t)
    x, _ = tr.state(t)
    return (t - t0) / T, x[-1]


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Run the sweeps, draw Fig. 10; return the PNG paths written."""
    low = resolution == "low"
    cfg = fig9.RESOLUTION["low" if low else "full"]
    out = pathlib.Path(out_dir)
    s = fig9.system()
    bb, families = fig9.nonsmooth_modes(s, cfg["T_range"], cfg["backbone"], cfg["scan"])
    results, timing = fig9.sweeps(s, CASES, cfg["periods"], cfg["n_periods"], progress=not low)

    fig, (ax, ar) = plt.subplots(1, 2, figsize=(15.0, 6.2), width_ratios=[1.35, 1], layout="constrained")
    fig9.draw_modes(ax, bb, families)
    for (F0, alpha), color in zip(CASES, COLORS):
        pts = results[F0, alpha]
        print(f"F0 = {F0}, alpha = {alpha}: {fig9.summary(pts)}; {timing[F0, alpha]:.2f} s per forcing period")
        fig9.draw_sweep(ax, pts, color, f"F₀ = {F0:g}, α = {alpha:g}")
        ones = [p for p in pts if p.periodic and p.k == 1 and p.p == 1]
        if not ones:
            continue
        best = max(ones, key=lambda p: p.energy)
        theta, x5 = response_cycle(s, best, F0, alpha)
        ar.plot(theta, x5, color=color, lw=1.6, label=f"forced, F₀ = {F0:g}, α = {alpha:g}: T = {best.T:.2f}, "
                                                       f"E = {best.energy:.3g}")
        orbit = bladecase.orbit_1ipp(s, best.T)
        th = np.linspace(0.0, 1.0, 1000)
        xo, _ = orbit.state(th * orbit.T)
        ar.plot(th, xo[-1], color=color, ls="--", lw=1.2,
                label=f"1-ipp orbit at T = {best.T:.2f}: E = {orbit.energy:.3g}"
                      + ("" if orbit.admissible else " (not admissible)"))
        print(f"    most energetic 1/1 state: T = {best.T:.3f}, E = {best.energy:.4f}; 1-ipp orbit there: "
              f"E = {orbit.energy:.4f}, admissible = {orbit.admissible}")
    ax.set_yscale("log")
    ax.set_ylim(*fig9.E_LIM)
    ax.set_xlim(*cfg["T_range"])
    ax.set_xlabel("period $T$ (forcing period for the forced responses)")
    ax.set_ylabel(r"energy $\frac{1}{2}\dot x^T M \dot x + \frac{1}{2}x^T K x$ (max over the cycle)")
    ax.grid(alpha=0.25, which="both")
    ax.legend(loc="upper left", fontsize=7.5, ncol=2, framealpha=0.95)
    ax.set_title(f"energies: forced periodic states vs nonsmooth modes ({cfg['n_periods']} periods per T)",
                 fontsize=10)
    ar.axhline(s.gap, color="k", lw=2.0)
    ar.set_xlabel(r"$t/T$ (impact at 0)")
    ar.set_ylabel(r"contact mass $x_5(t)$")
    ar.grid(alpha=0.3)
    if ar.lines[1:]:
        ar.legend(loc="lower center", fontsize=7.8, framealpha=0.95)
    else:
        ar.text(0.5, 0.5, "no periodic state with one impact per period", ha="center", transform=ar.transAxes)
    ar.set_title("steady cycle of the most energetic 1-impact-per-period state", fontsize=10)
    fig.suptitle("Seed paper Fig. 10 — two forced damped responses and the nonsmooth mode, n = 5 chain, C = αK",
                 fontsize=12.5)
    path = out / "fig10_forced_response.png"
    save_figure(fig, path, dpi=110 if low else 160)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
