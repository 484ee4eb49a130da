"""Seed paper, Fig. 2: where two impacts per period are possible, in the (t₁, T) plane.

System: the 2-dof spring–mass chain of the paper's Sec. 1.4
(``bladecase.chain(2, k=1, m=1/2, gap=1)``, ω = 0.874, 2.288, linear periods
T₁ = 7.1887, T₂ = 2.7459), impacts at ``t₁`` and ``t₂ = T``.

A 2-ipp periodic orbit needs ``s(t₁) = wᵀG'(t₁) = 0`` at period ``T`` (the
paper's Eq. 15, ``Q_T(T - 2t₁) = 0``; theory §3–4).  ``s`` has poles at the
resonant periods ``sin(ω_j T/2) = 0``, so the figure draws the zero set of the
pole-free numerator

    N(t₁, T) = s(t₁) · Π_j sin(ω_j T/2)
             = -Σ_j (b_j²/2) sin(ω_j (t₁ - T/2)) Π_{i≠j} sin(ω_i T/2)

(``b_j = wᵀφ_j``).  ``s`` is odd about ``T/2``, so the diagonal ``t₁ = T/2``
(a 1-ipp orbit of period ``T/2`` counted twice) always belongs to the zero
set, and the map is symmetric under ``t₁ → T - t₁`` (the same orbit, shifted
in time).  Only parts of the zero set are periodic motions: the orbit must
also have non-negative impulses and stay behind the obstacle for all ``t``.
Those admissible arcs, followed by continuation
(``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``), are drawn in
red; the one between ① (on the diagonal, T ≈ 13.33) and ② (T → 5T₂ ≈ 13.73)
is the paper's red curve, the nonsmooth mode of Figs. 3 and 4
(``_paper.paper_mode``: its upper end is refined to 5T₂ = 13.72926331).

Run: ``python examples/fig2_impact_time_map.py [--out DIR] [--low]``.
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

T_RANGE = (1.0, 14.5)  # periods shown in the map
ZOOM_T = (13.22, 13.82)  # right panel: the paper's red arc
ZOOM_T1 = (5.25, 7.05)


def numerator(system: bladecase.LinearSystem, t1, T) -> np.ndarray:
    """Pole-free numerator ``N(t₁, T) = s(t₁)·Π_j sin(ω_j T/2)`` (broadcasts ``t1`` and ``T``).

    Equals ``bladecase.nsm.ModalKernel.of(system, T).g_s(t1)[1] * prod(sin(ω T/2))``
    wherever ``T`` is not resonant, and stays finite (and continuous) across
    the resonant periods.
    """
    omega, b, _ = system.spectrum.contact_modes
    t1, T = np.broadcast_arrays(np.asarray(t1, dtype=float), np.asarray(T, dtype=float))
    half = np.sin(np.multiply.outer(T, omega) / 2)  # (..., m)
    osc = np.sin(np.multiply.outer(t1 - T / 2, omega))  # (..., m)
    out = np.zeros(t1.shape)
    for j in range(omega.size):
        others = np.prod(np.delete(half, j, axis=-1), axis=-1)
        out -= 0.5 * b[j] ** 2 * osc[..., j] * others
    return out


def resonant_periods(system: bladecase.LinearSystem, T_range=T_RANGE) -> list[tuple[float, int, int]]:
    """``(2πj/ω_i, i, j)`` for the contact modes ``i`` (1-based) inside ``T_range``."""
    omega = system.spectrum.contact_modes[0]
    out = []
    for i, w in enumerate(omega, start=1):
        j = 1
        while 2 * np.pi * j / w <= T_range[1]:
            if 2 * np.pi * j / w >= T_range[0]:
                out.append((2 * np.pi * j / w, i, j))
            j += 1
    return sorted(out)


def admissible_arcs(families) -> list[dict]:
    """The admissible stretches of the families, as curves in the (t₁, T) plane.

    Each item: ``family`` (index), ``arc`` (:class:`bladecase.nsm.Arc`), ``T``
    and ``t1`` (arrays along the arc, in continuation order), ``T_lo``, ``T_hi``.
    """
    out = []
    for n, fam in enumerate(families):
        T, t1 = fam.T, fam.impact_times[:, 0]
        for arc in fam.arcs:
            sl = slice(arc.start, arc.stop + 1)
            out.append({"family": n, "arc": arc, "T": T[sl], "t1": t1[sl], "T_lo": arc.T_lo, "T_hi": arc.T_hi})
    return out


def _map(ax, system, t1_lim, T_lim, n_grid):
    t1 = np.linspace(*t1_lim, n_grid)
    T = np.linspace(*T_lim, n_grid)
    t1g, Tg = np.meshgrid(t1, T)
    N = np.ma.masked_where(t1g >= Tg, numerator(system, t1g, Tg))
    return ax.contour(t1g, Tg, N, levels=[0.0], colors="0.15", linewidths=0.9, zorder=1)


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the Fig. 2 map; return the PNG paths written."""
    low = resolution == "low"
    n_grid, n_zoom = (60, 60) if low else (400, 300)
    out = pathlib.Path(out_dir)
    system = paper.two_dof()
    T5 = paper.five_T2(system)
    arcs = admissible_arcs(paper.two_ipp_families(system))
    mode = paper.paper_mode(system)  # the paper's arc from ① to ②, sorted by T
    mode_t1, mode_T = mode.impact_times[:, 0], mode.T
    _, main_arc = paper.paper_arc(system)
    for a in arcs:
        print(f"admissible 2-ipp arc (family {a['family']}): T in [{a['T_lo']:.6f}, {a['T_hi']:.6f}]")

    fig, (ax, az) = plt.subplots(1, 2, figsize=(12.5, 6.6), width_ratios=[1.45, 1], layout="constrained")
    _map(ax, system, (0.0, T_RANGE[1]), T_RANGE, n_grid)
    _map(az, system, ZOOM_T1, ZOOM_T, n_zoom)
    for a in (ax, az):
        lo, hi = a.get_xlim()
        for Tr, _i, _j in resonant_periods(system):
            if abs(Tr - T5) > 1e-9:
                a.axhline(Tr, color="0.55", ls=(0, (3, 3)), lw=0.6, zorder=0)
        a.axhline(T5, color="tab:blue", ls="--", lw=1.3, zorder=1)
        d = np.array(T_RANGE)
        a.plot(d / 2, d, color="tab:orange", lw=1.4, ls="-.", zorder=2)
        for arc in arcs:
            if arc["arc"] is not main_arc:
                a.plot(arc["t1"], arc["T"], color="red", lw=2.4, solid_capstyle="round", zorder=3)
        a.plot(mode_t1, mode_T, color="red", lw=3.2, solid_capstyle="round", zorder=3)
        a.set_xlabel(r"first impact time $t_1$")
        a.set_ylabel(r"period $T$ ($t_2 = T$)")
    # left panel: whole map
    ax.fill_between([0, T_RANGE[1]], [0, T_RANGE[1]], 0, color="0.93", zorder=0, lw=0)  # t1 >= T: outside
    ax.set_xlim(0, T_RANGE[1])
    ax.set_ylim(*T_RANGE)
    ax.text(11.6, 7.2, r"$t_1 \geq T$" "\n(excluded)", color="0.45", ha="center", fontsize=9)
    ax.text(0.25, T5 + 0.12, r"$T = 5T_2$", color="tab:blue", fontsize=9)
    ax.annotate(r"$t_1 = T/2$: 1-ipp orbit of period $T/2$" "\ncounted twice", xy=(4.25, 8.5), xytext=(5.2, 6.4),
                fontsize=8.5, color="tab:orange", arrowprops=dict(arrowstyle="->", color="tab:orange", lw=0.8))
    for Tr, i, j in resonant_periods(system):
        tag = f"{j}T$_{i}$" if j > 1 else f"T$_{i}$"
        ax.text(1.006, Tr, tag, fontsize=7.5, color="0.4", ha="left", va="center",
                transform=ax.get_yaxis_transform())
    ax.add_patch(plt.Rectangle((ZOOM_T1[0], ZOOM_T[0]), ZOOM_T1[1] - ZOOM_T1[0], ZOOM_T[1] - ZOOM_T[0],
                               fill=False, ec="red", lw=0.9, ls=":"))
    ax.set_title(r"zero set of $N(t_1,T) = s(t_1)\,\Pi_j \sin(\omega_j T/2)$ in the $(t_1, T)$ plane")
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], color="0.15", lw=0.9, label=r"$N = 0$ (paper's Eq. 15, $Q_T(T-2t_1)=0$)"),
        Line2D([], [], color="red", lw=2.4, label="admissible 2-ipp orbits (nonsmooth modes)"),
        Line2D([], [], color="tab:orange", ls="-.", lw=1.4, label=r"$t_1 = T/2$"),
        Line2D([], [], color="tab:blue", ls="--", lw=1.3, label=rf"$T = 5T_2 = {T5:.4f}$"),
        Line2D([], [], color="0.55", ls=(0, (3, 3)), lw=0.6, label=r"resonant $T = 2\pi j/\omega_i$ (excluded)"),
    ]
    ax.legend(handles=handles, loc="lower right", fontsize=8.5, framealpha=0.95)
    # right panel: zoom on the paper's arc
    az.set_xlim(*ZOOM_T1)
    az.set_ylim(*ZOOM_T)
    ends = ((mode_t1[0], mode_T[0]), (mode_t1[-1], mode_T[-1]))
    for (t1p, Tp), label, dx, dy in zip(ends, ("①", "②"), (-0.17, -0.09), (0.0, -0.022)):
        az.plot(t1p, Tp, "o", ms=6, mfc="white", mec="red", mew=1.6, zorder=4)
        az.text(t1p + dx, Tp + dy, label, fontsize=15, color="red", ha="center", va="center")
    az.text(ZOOM_T1[0] + 0.05, T5 + 0.006, r"$T = 5T_2$", color="tab:blue", fontsize=9)
    az.text(0.03, 0.04,
            f"① T = {mode_T[0]:.4f}, t₁ = T/2 (1-ipp orbit of period T/2)\n"
            f"② T → 5T₂ = {T5:.4f}, t₁ → 2T₂ (5th harmonic of linear mode 2)",
            transform=az.transAxes, fontsize=8.5, va="bottom", bbox=dict(fc="white", ec="0.7", alpha=0.95))
    az.set_title("zoom: the paper's red arc from ① to ②")
    fig.suptitle("Seed paper Fig. 2 — roots of the 2-ipp condition $s(t_1)=0$, 2-dof chain "
                 r"($k=1$, $m=1/2$, $d=1$)", fontsize=12.5)
    path = out / "fig2_impact_time_map.png"
    save_figure(fig, path, dpi=110 if low else 160)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
