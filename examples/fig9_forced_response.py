"""Seed paper, Fig. 9: energies of the forced, damped n = 5 chain against its nonsmooth modes.

System: the paper's Sec. 2 chain with n = 5 (``bladecase.chain(5, k=1, m=0.2, gap=1)``; linear periods
9.872, 3.382, 2.145, 1.670, 1.464), damping ``C = αK`` (``Damping(alpha=α)``), force
``F₀ cos(2πt/T)`` on every mass (load ``f = (1, …, 1)``), Newton's law with ``e = 1``.  As in the
paper: ``F₀ = 1``, ``α = 0.005`` and ``0.01``, 500 forcing periods at each forcing period ``T``.
The sweep (``bladecase.nsm.sweep.forced_sweep``) goes up in forcing frequency (``T`` from 10 down to 1.4,
step 0.05), each run starting from the end state of the previous one.

Each run is classified at its end: periodic steady state "k impacts per p forcing periods" when the
stroboscopic map returns to itself within 1e-6 (relative, energy norm) after ``p = 1..4`` periods;
"linear" when it no longer impacts and provably never will (it converges to the linear steady state,
too slowly for the tolerance: ``C = αK`` damps the lowest mode at only ``σ₁ = αω₁²/2 ≈ 0.001–0.002``);
"non-periodic" otherwise.  The energy of a periodic state is the maximum over its cycle of
``½vᵀMv + ½xᵀKx`` (the paper does not define its measure).

Nonsmooth modes (energy constant along each orbit): the 1-ipp backbone
``bladecase.backbone(system, np.linspace(1.4, 10, 1721))`` (admissible solid, non-admissible faint) and the
admissible arcs of the 2-ipp modes ``bladecase.nonsmooth_mode(system, 2, (1.4, 10), scan=24)`` (dotted).

Run: ``python examples/fig9_forced_response.py [--out DIR] [--low]`` (``--low``: a handful of periods,
40 forcing periods each, for the tests).
"""

from __future__ import annotations

import pathlib
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402
from bladecase.nsm.damping import Damping  # noqa: E402
from bladecase.nsm.sweep import SweepPoint, forced_sweep  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402

T_RANGE = (1.4, 10.0)
E_LIM = (0.05, 1e5)
CASES = [(1.0, 0.005), (1.0, 0.01)]  # (F₀, α) of the paper's Fig. 9
RESOLUTION = {
    "full": dict(periods=np.round(np.arange(T_RANGE[1], T_RANGE[0] - 1e-9, -0.05), 10), n_periods=500,
                 backbone=1721, scan=24, T_range=T_RANGE),
    "low": dict(periods=np.array([5.4, 4.8, 4.6]), n_periods=40, backbone=200, scan=3, T_range=(4.4, 5.6)),
}
MARKERS = {"1/1": "o", "2/1": "s", "2/2": "D", "1/2": "v", "3/2": "^", "1/3": "<"}


def system() -> bladecase.LinearSystem:
    """The paper's n = 5 chain (``k = 1``, ``m = 1/n``, ``d = 1``)."""
    return bladecase.chain(5, k=1.0, m=0.2, gap=1.0)


def nonsmooth_modes(s: bladecase.LinearSystem, T_range, n_backbone: int, scan: int):
    """``(backbone, 2-ipp families)`` of ``s`` over ``T_range``."""
    bb = bladecase.backbone(s, np.linspace(*T_range, n_backbone))
    return bb, bladecase.nonsmooth_mode(s, 2, T_range, scan=scan)


def sweeps(s: bladecase.LinearSystem, cases, periods, n_periods: int, progress: bool = True):
    """``{(F₀, α): [SweepPoint, …]}`` and the wall time per forcing period of each sweep."""
    out, timing = {}, {}
    for F0, alpha in cases:
        t0 = time.perf_counter()
        out[F0, alpha] = forced_sweep(s, periods, damping=Damping(alpha=alpha), amplitude=F0,
                                      n_periods=n_periods, direction="up", progress=progress)
        timing[F0, alpha] = (time.perf_counter() - t0) / len(periods)
    return out, timing


def draw_modes(ax, bb, families) -> None:
    """The 1-ipp backbone (admissible solid, the rest faint) and the admissible 2-ipp arcs (dotted)."""
    T, E, ok = bb.T, bb.energy, bb.admissible
    ax.plot(T, np.where(ok, np.nan, E), color="0.75", lw=0.6, zorder=1, label="1 ipp, not admissible")
    ax.plot(T, np.where(ok, E, np.nan), color="k", lw=1.6, zorder=2, label="nonsmooth mode, 1 ipp")
    first = True
    for f in families:
        for a in f.arcs:
            orbits = f.orbits[a.start: a.stop + 1]
            ax.plot([o.T for o in orbits], [o.energy for o in orbits], ls=":", color="k", lw=1.6, zorder=2,
                    label="nonsmooth modes, 2 ipp" if first else None)
            first = False


def draw_sweep(ax, points: list[SweepPoint], color, name: str) -> None:
    """Periodic states as markers (shape: impacts per forcing periods), joined when adjacent; non-periodic
    ones as faint crosses, certified-linear ones as faint dots (at their maximum energy)."""
    pts = sorted(points, key=lambda p: p.T)
    T = np.array([p.T for p in pts])
    E = np.array([p.energy for p in pts])
    per = np.array([p.periodic and p.k > 0 for p in pts])
    ax.plot(T, np.where(per, E, np.nan), color=color, lw=1.0, alpha=0.8, zorder=3)
    for lab in sorted({p.label for p in pts if p.periodic and p.k > 0}):
        sel = [p for p in pts if p.label == lab]
        ax.plot([p.T for p in sel], [p.energy for p in sel], ls="", marker=MARKERS.get(lab, "P"), ms=5,
                color=color, mec="k", mew=0.4, zorder=4, label=f"{name}: periodic, {lab} (impacts/periods)")
    non = [p for p in pts if p.complete and not p.periodic and not p.linear]
    if non:
        ax.plot([p.T for p in non], [p.energy for p in non], ls="", marker="x", ms=3.5, color=color, alpha=0.45,
                zorder=3, label=f"{name}: non-periodic after the run (max E)")
    lin = [p for p in pts if p.linear or (p.periodic and p.k == 0)]
    if lin:
        ax.plot([p.T for p in lin], [p.energy for p in lin], ls="", marker=".", ms=3, color=color, alpha=0.35,
                zorder=3, label=f"{name}: no more impacts (linear)")


def summary(points: list[SweepPoint]) -> str:
    counts: dict[str, int] = {}
    for p in points:
        counts[p.label] = counts.get(p.label, 0) + 1
    return ", ".join(f"{k}: {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1]))


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Run the sweeps, draw Fig. 9; return the PNG paths written."""
    cfg = RESOLUTION["low" if resolution == "low" else "full"]
    low = resolution == "low"
    out = pathlib.Path(out_dir)
    s = system()
    bb, families = nonsmooth_modes(s, cfg["T_range"], cfg["backbone"], cfg["scan"])
    results, timing = sweeps(s, CASES, cfg["periods"], cfg["n_periods"], progress=not low)
    for (F0, alpha), pts in results.items():
        print(f"F0 = {F0}, alpha = {alpha}: {summary(pts)}; {timing[F0, alpha]:.2f} s per forcing period "
              f"({cfg['n_periods']} periods each)")
        for p in sorted(pts, key=lambda p: p.T):
            if p.periodic and p.k > 0:
                print(f"    T = {p.T:.3f}  {p.label:>5}  E = {p.energy:10.4f}  residual {p.residual:.1e}")

    fig, ax = plt.subplots(figsize=(12.5, 6.6), layout="constrained")
    draw_modes(ax, bb, families)
    for (F0, alpha), color in zip(results, ("C3", "C0")):
        draw_sweep(ax, results[F0, alpha], color, f"F₀ = {F0:g}, α = {alpha:g}")
    for Tj in s.spectrum.periods:
        if cfg["T_range"][0] <= Tj <= cfg["T_range"][1]:
            ax.axvline(Tj, color="0.5", ls="--", lw=0.7, zorder=0)
    ax.set_yscale("log")
    ax.set_ylim(*E_LIM)
    ax.set_xlim(*cfg["T_range"])
    ax.set_xlabel("period $T$ (forcing period $2\\pi/\\Omega$ for the forced responses)")
    ax.set_ylabel(r"energy $\frac{1}{2}\dot x^T M \dot x + \frac{1}{2}x^T K x$ (max over the cycle)")
    ax.grid(alpha=0.25, which="both")
    ax.legend(loc="upper left", fontsize=7.8, ncol=2, framealpha=0.95)
    n_per = cfg["n_periods"]
    ax.set_title(f"n = 5 chain (k = 1, m = 0.2, d = 1), C = αK, F₀cos(2πt/T) on every mass, e = 1, "
                 f"{n_per} periods per T; dashed: linear periods", fontsize=10)
    fig.suptitle("Seed paper Fig. 9 — energies of the forced periodic responses and of the nonsmooth modes",
                 fontsize=12.5)
    path = out / "fig9_forced_response.png"
    save_figure(fig, path, dpi=110 if low else 160)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
