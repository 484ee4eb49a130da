"""Frequency–energy plot of the nonsmooth modes of the paper's 2-dof chain (cf. seed paper Fig. 9).

System: ``bladecase.chain(2, k=1, m=1/2, gap=1)`` (Sec. 1.4 of the paper;
ω = 0.874, 2.288, linear frequencies ω/2π = 0.139, 0.364).  Energy
``E = ½vᵀMv + ½xᵀKx`` (constant along an orbit) against the frequency ``1/T`` of

* the 1-ipp backbone, ``bladecase.backbone(sys, np.linspace(1, 14.5, N))``;
* the 2-ipp families, ``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``,

drawn together with ``bladecase.plot.frequency_energy([backbone, *families])``
(admissible orbits solid, non-admissible faint dots, one colour per number of
impacts per period).  The energy of non-admissible orbits diverges at the
resonances ``T = 2πj/ω_i``, and the admissible 1-ipp branches also end at
infinite energy where ``g(0) = 0`` (the impulse ``Λ = -d/g(0)`` blows up,
e.g. T = 2.5049, 3.7459), so the energy axis is clipped.  The right panel
zooms on the low frequencies, where the 2-ipp modes live; the paper's mode of
Figs. 2–4 (① T ≈ 13.33, where it branches off the 1-ipp orbit of period T/2,
to ② T → 5T₂ ≈ 13.73) is marked; its continuation stops at T ≈ 13.7227
(E ≈ 3.77), and the admissible orbits of the branch beyond it, found with
``bladecase.orbits_kipp`` (dashed), reach E = 4.69 at T = 13.7290, on the way
to the energy of linear mode 2 grazing the obstacle, ½(ω₂d/|b₂|)² = 4.736.

Run: ``python examples/frequency_energy.py [--out DIR] [--low]``.
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
from bladecase.plot import frequency_energy  # noqa: E402

E_LIM = (0.1, 3e3)  # clipped energy axis (admissible branches end at E = ∞)
ZOOM_F = (0.066, 0.205)
ZOOM_E = (0.06, 60.0)


def two_dof() -> bladecase.LinearSystem:
    """The paper's Sec. 1.4 system: k₁ = k₂ = 1, m₁ = m₂ = 1/2, d = 1."""
    return bladecase.chain(2, k=1.0, m=0.5, gap=1.0)


def compute(system: bladecase.LinearSystem | None = None, n_periods: int = 1351):
    """``(backbone, families)``: the 1-ipp backbone on ``n_periods`` periods in
    [1, 14.5] and the 2-ipp families followed in [3, 14.5]."""
    system = two_dof() if system is None else system
    bb = bladecase.backbone(system, np.linspace(1.0, 14.5, n_periods))
    families = bladecase.nonsmooth_mode(system, 2, (3.0, 14.5), scan=24)
    return bb, families


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


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the frequency–energy plot; return the PNG paths written."""
    low = resolution == "low"
    out = pathlib.Path(out_dir)
    system = two_dof()
    T2 = 2 * np.pi / system.spectrum.omega[1]
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
        a.axvline(1 / (5 * T2), color="tab:blue", ls="--", lw=0.9, alpha=0.7)
        a.set_xlabel(r"frequency $1/T$")
        a.set_ylabel(r"energy $E = \frac{1}{2}\dot x^T M \dot x + \frac{1}{2}x^T K x$")
    az.text(1 / (5 * T2) + 0.001, ZOOM_E[1] * 0.7, r"$T = 5T_2$", color="tab:blue", fontsize=9, rotation=90,
            va="top")
    lf = bb.linear_frequencies
    for n, fj in enumerate(lf, start=1):
        ax.text(fj + 0.006, E_LIM[1] * 0.55, rf"$\omega_{n}/2\pi$", fontsize=9, va="top")
    # the paper's mode (Figs. 2-4): arc ending closest to 5 T2
    fam, arc = min(((f, a) for f in families for a in f.arcs), key=lambda fa: abs(fa[1].T_hi - 5 * T2))
    last = max(fam.orbits[arc.start: arc.stop + 1], key=lambda o: o.T)
    ext = [last] + grazing_extension(system, last, 5 * T2)  # continuation stops short of ②
    az.plot([1 / o.T for o in ext], [o.energy for o in ext], color="C1", lw=1.8, ls=(0, (2, 1)), zorder=4)
    o1, o2 = fam.orbits[arc.start], ext[-1]
    E_graze = 0.5 * (system.spectrum.omega[1] * system.gap / abs(system.spectrum.contact_modes[1][1])) ** 2
    for o, label, dx in ((o1, "①", 0.004), (o2, "②", -0.004)):
        az.plot(1 / o.T, o.energy, "o", ms=6, mfc="white", mec="C1", mew=1.6, zorder=5)
        az.text(1 / o.T + dx, o.energy, label, fontsize=14, color="C1", ha="center", va="center")
    print(f"paper's mode: ① T = {o1.T:.6f} E = {o1.energy:.6f};  continuation end T = {last.T:.6f} "
          f"E = {last.energy:.4f};  ② (orbits_kipp) T = {o2.T:.6f} E = {o2.energy:.4f};  "
          f"grazing mode-2 energy at 5T2: {E_graze:.4f}")
    az.annotate(f"① T = {o1.T:.4f}, E = {o1.energy:.4f}\n    (= 1-ipp orbit of period T/2)\n"
                f"② T = {o2.T:.4f}, E = {o2.energy:.3f}\n    (→ {E_graze:.3f}: mode 2 grazing d)\n"
                f"dashed: orbits_kipp beyond the\ncontinuation's end T = {last.T:.4f}",
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
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/examples", help="output directory (default: %(default)s)")
    parser.add_argument("--low", action="store_true", help="low resolution (fast)")
    args = parser.parse_args()
    t0 = time.perf_counter()
    paths = main(args.out, "low" if args.low else "full")
    print("wrote", *paths, f"({time.perf_counter() - t0:.1f} s)")
