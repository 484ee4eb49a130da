"""Matplotlib figures: frequency–energy plots of nonsmooth-mode backbones."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def frequency_energy(backbones: Sequence, ax=None, linear: bool = True, title: str | None = None):
    """Energy ``E`` against frequency ``1/T`` for one or several backbones.

    ``backbones`` are :class:`bladecase.Backbone` (1 ipp) or
    :class:`bladecase.Family` (k ipp) objects, one colour per number of
    impacts per period.  Admissible orbits are drawn as solid curves,
    non-admissible ones as faint dots; the ends of the admissible intervals
    are marked, and the linear frequencies ``ω_j/2π`` in range are drawn as
    dashed vertical lines.

    Returns the matplotlib ``Figure``.
    """
    if ax is None:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    else:
        fig = ax.figure
    colors = ["C0", "C1", "C2", "C3", "C4", "C5"]
    fmin, fmax = np.inf, -np.inf
    labelled = set()
    for bb in backbones:
        c = colors[(bb.ipp - 1) % len(colors)]
        f, E, adm = bb.frequencies, bb.energy, bb.admissible
        fmin, fmax = min(fmin, f.min()), max(fmax, f.max())
        ok = np.isfinite(E) & (E > 0)
        ax.plot(f[ok & ~adm], E[ok & ~adm], ".", ms=2, color=c, alpha=0.2)
        Ea = np.where(adm, E, np.nan)  # NaN breaks the curve between admissible arcs
        label = None if bb.ipp in labelled or not adm.any() else f"{bb.ipp} ipp (admissible)"
        if label:
            labelled.add(bb.ipp)
        ax.plot(f, Ea, "-", lw=1.8, color=c, label=label)
        for iv in bb.intervals:
            for T, refined in ((iv.T_lo, iv.refined_lo), (iv.T_hi, iv.refined_hi)):
                if refined:
                    ax.axvline(1 / T, color=c, lw=0.5, ls=":", alpha=0.6)
    if linear and backbones:
        lf = backbones[0].linear_frequencies
        first = True
        for fj in lf[(lf >= fmin) & (lf <= fmax)]:
            ax.axvline(fj, color="k", ls="--", lw=0.8, label="linear frequencies" if first else None)
            first = False
    ax.set_yscale("log")
    # Non-admissible energies diverge at resonances: frame the admissible curves.
    adm_E = np.concatenate([bb.energy[bb.admissible] for bb in backbones]) if backbones else np.array([])
    adm_E = adm_E[np.isfinite(adm_E) & (adm_E > 0)]
    if adm_E.size:
        ax.set_ylim(adm_E.min() / 3, adm_E.max() * 3)
    ax.set_xlabel("frequency 1/T")
    ax.set_ylabel("energy E")
    ax.set_title(title or "Nonsmooth modes: frequency–energy")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small")
    return fig
