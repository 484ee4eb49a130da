"""Frequency–energy plot of the nonsmooth modes of the paper's 2-dof chain (cf. seed paper Fig. 9).

System: ``bladecase.chain(2, k=1, m=1/2, gap=1)`` (Sec. 1.4 of the paper;
ω = 0.874, 2.288, linear frequencies ω/2π = 0.139, 0.364).  Energy
``E = ½vᵀMv + ½xᵀKx`` (constant along an orbit) against the frequency ``1/T`` of

* the 1-ipp backbone, ``bladecase.backbone(sys, np.linspace(1, 14.5, N))``;
* the 2-ipp families, ``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``,

drawn together with ``bladecase.post.plots.frequency_energy([backbone, *families])``
(admissible orbits solid, non-admissible faint dots, one colour per number of
impacts per period).  The energy of non-admissible orbits diverges at the
resonances ``T = 2πj/ω_i``, and the admissible 1-ipp branches also end at
infinite energy where ``g(0) = 0`` (the impulse ``Λ = -d/g(0)`` blows up,
e.g. T = 2.5049, 3.7459), so the energy axis is clipped.  The right panel
zooms on the low frequencies, where the 2-ipp modes live; the paper's mode of
Figs. 2–4 (① T ≈ 13.33, where it branches off the 1-ipp orbit of period T/2,
to ② T → 5T₂ ≈ 13.73) is marked; towards ② its energy rises steeply to that
of linear mode 2 grazing the obstacle, ½(ω₂d/|b₂|)² = 4.736.

Run: ``python examples/frequency_energy.py [--out DIR] [--low]``.
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
from bladecase.post.plots import frequency_energy  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402

E_LIM = (0.1, 3e3)  # clipped energy axis (admissible branches end at E = ∞)
ZOOM_F = (0.066, 0.205)
ZOOM_E = (0.06, 60.0)


def compute(system: bladecase.LinearSystem | None = None, n_periods: int = 1351):
    """``(backbone, families)``: the 1-ipp backbone on ``n_periods`` periods in
    [1, 14.5] and the 2-ipp families followed in [3, 14.5]."""
    system = paper.two_dof() if system is None else system
    bb = bladecase.backbone(system, np.linspace(1.0, 14.5, n_periods))
    return bb, paper.two_ipp_families(system)


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the frequency–energy plot; return the PNG paths written."""
    low = resolution == "low"
    out = pathlib.Path(out_dir)
    system = paper.two_dof()
    T5 = paper.five_T2(system)
    bb, families = compute(system, 200 if low else 1351)
    print(bb.table().split("\n\n")[-1])
    for f in families:
        if f.arcs:
            print(f.table())

    fig, (ax, az) = plt.subplots(1, 2, figsize=(14.0, 5.8), width_ratios=[1.25, 1], layout="constrained")
    for a, title in ((ax, "1-ipp backbone and 2-ipp nonsmooth modes"), (az, "zoom: low frequencies (2-ipp modes)")):
        frequency_energy([bb, *families], ax=a, title=title)
    ax.set_ylim(*E_LIM)
    ax.set_xlim(1 / 14.5 - 0.01, 1.0)
    ax.add_patch(plt.Rectangle((ZOOM_F[0], ZOOM_E[0]), ZOOM_F[1] - ZOOM_F[0], ZOOM_E[1] - ZOOM_E[0],
                               fill=False, ec="0.3", ls=":", lw=1.0))
    az.set_xlim(*ZOOM_F)
    az.set_ylim(*ZOOM_E)
    for a in (ax, az):
        a.axvline(1 / T5, color="tab:blue", ls="--", lw=0.9, alpha=0.7)
        a.set_xlabel(r"frequency $1/T$")
        a.set_ylabel(r"energy $E = \frac{1}{2}\dot x^T M \dot x + \frac{1}{2}x^T K x$")
    az.text(1 / T5 + 0.001, ZOOM_E[1] * 0.7, r"$T = 5T_2$", color="tab:blue", fontsize=9, rotation=90,
            va="top")
    lf = bb.linear_frequencies
    for n, fj in enumerate(lf, start=1):
        ax.text(fj + 0.006, E_LIM[1] * 0.55, rf"$\omega_{n}/2\pi$", fontsize=9, va="top")
    # the paper's mode (Figs. 2-4), from ① to ②
    mode = paper.paper_mode(system)
    az.plot(mode.frequencies, mode.energy, color="C1", lw=1.8, zorder=4)
    o1, o2 = mode.orbits[0], mode.orbits[-1]
    E_graze = 0.5 * (system.spectrum.omega[1] * system.gap / abs(system.spectrum.contact_modes[1][1])) ** 2
    for o, label, dx in ((o1, "①", 0.004), (o2, "②", -0.004)):
        az.plot(1 / o.T, o.energy, "o", ms=6, mfc="white", mec="C1", mew=1.6, zorder=5)
        az.text(1 / o.T + dx, o.energy, label, fontsize=14, color="C1", ha="center", va="center")
    print(f"paper's mode: ① T = {o1.T:.6f} E = {o1.energy:.6f};  ② T = {o2.T:.8f} E = {o2.energy:.6f};  "
          f"grazing mode-2 energy at 5T2: {E_graze:.6f}")
    az.annotate(f"① T = {o1.T:.4f}, E = {o1.energy:.4f}\n    (= 1-ipp orbit of period T/2)\n"
                f"② T → 5T₂ = {T5:.4f}, E → {E_graze:.3f}\n    (linear mode 2 grazing d)",
                xy=(0.47, 0.97), xycoords="axes fraction", va="top", fontsize=7.8,
                bbox=dict(fc="white", ec="0.7", alpha=0.95))
    from matplotlib.lines import Line2D

    for a in (ax, az):  # explain the library's markers in the legend
        handles, _ = a.get_legend_handles_labels()
        handles += [Line2D([], [], ls="", marker=".", color="0.5", alpha=0.5, label="non-admissible orbits"),
                    Line2D([], [], ls=":", lw=0.8, color="0.4", label="ends of admissible arcs")]
        a.legend(handles=handles, loc="lower right", fontsize=8.5, framealpha=0.95)
    top = az.secondary_xaxis("top", functions=(lambda f: 1 / np.maximum(f, 1e-9), lambda T: 1 / np.maximum(T, 1e-9)))
    top.set_xlabel("period $T$")
    fig.suptitle("Frequency–energy plot of the nonsmooth modes, 2-dof chain ($k=1$, $m=1/2$, $d=1$) "
                 "— cf. seed paper Fig. 9 (1 ipp and 2 ipp)", fontsize=12.5)
    path = out / "frequency_energy.png"
    save_figure(fig, path, dpi=110 if low else 160)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
