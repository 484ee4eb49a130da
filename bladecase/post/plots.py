"""Matplotlib figures: frequency–energy plots of nonsmooth-mode backbones.

Figures are made with :class:`matplotlib.figure.Figure` directly, never
through pyplot: no global figure registry, no backend switch.  Save them with
``fig.savefig(path)`` (or :func:`bladecase.io.save_figure`); a notebook shows
them as PNG images.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

#: Colours by number of impacts (massless model: contact phases) per period (cycled).
COLORS = ("C0", "C1", "C2", "C3", "C4", "C5")


def is_massless(item) -> bool:
    """Whether ``item`` — a system, a branch, an orbit (or anything with a ``system``) — is of the massless contact
    model (contact phases of finite duration), not Newton's (impacts)."""
    if getattr(item, "contact_model", None) == "massless":
        return True
    if getattr(getattr(item, "system", None), "contact_model", None) == "massless":
        return True
    return any(getattr(o, "contact_model", None) == "massless" for o in (getattr(item, "orbits", None) or [])[:1])


def per_period(k: int, massless: bool) -> str:
    """How many contacts a period holds, in the contact model's words: impacts (``"1 ipp"``) for Newton's law,
    contact phases for the massless model.

    >>> per_period(1, False), per_period(1, True), per_period(2, True)
    ('1 ipp', '1 contact phase / period', '2 contact phases / period')
    """
    if not massless:
        return f"{k} ipp"
    return f"{k} contact phase{'' if k == 1 else 's'} / period"


class NotebookFigure(Figure):
    """A :class:`~matplotlib.figure.Figure` that a notebook displays as a PNG even when pyplot was never
    imported (IPython's matplotlib formatter, when registered, takes precedence)."""

    def _repr_png_(self) -> bytes:
        buf = io.BytesIO()
        self.savefig(buf, format="png", dpi=100)
        return buf.getvalue()


def new_figure(**kwargs) -> Figure:
    """A pyplot-free figure (``figsize``, ``layout``, … as :class:`~matplotlib.figure.Figure`)."""
    return NotebookFigure(**kwargs)


def axis_labels(time_unit: str | None = None, energy_unit: str | None = None) -> tuple[str, str]:
    """``(x label, y label)`` of a frequency–energy plot.

    ``time_unit=None`` (dimensionless chains) gives ``"frequency 1/T"``; ``"s"``
    gives ``"frequency 1/T (Hz)"``, any other unit ``"frequency 1/T (1/unit)"``.

    >>> axis_labels("s", "J")
    ('frequency 1/T (Hz)', 'energy E (J)')
    >>> axis_labels()
    ('frequency 1/T', 'energy E')
    """
    for name, unit in (("time_unit", time_unit), ("energy_unit", energy_unit)):
        if unit is not None and (not isinstance(unit, str) or not unit.strip()):
            raise ValueError(f"{name} must be a non-empty string (e.g. 's', 'J') or None (dimensionless), got {unit!r}")
    freq = "" if time_unit is None else " (Hz)" if time_unit == "s" else f" (1/{time_unit})"
    energy = "" if energy_unit is None else f" ({energy_unit})"
    return f"frequency 1/T{freq}", f"energy E{energy}"


def frequency_energy(
    backbones: Sequence,
    ax=None,
    linear: bool = True,
    title: str | None = None,
    *,
    time_unit: str | None = None,
    energy_unit: str | None = None,
    stability: bool = False,
    nonadmissible: bool = True,
) -> Figure:
    r"""Energy ``E`` against frequency ``1/T`` for one or several backbones.

    ``backbones`` are :class:`bladecase.Backbone` (1 ipp) or
    :class:`bladecase.Family` (k ipp) objects, one colour per number of
    impacts per period (contact phases per period for the massless contact
    model, and so labelled: :func:`per_period`).  Admissible orbits are drawn as solid curves,
    non-admissible ones as faint dots; the ends of the admissible intervals
    are dotted vertical lines, and the linear frequencies ``ω_j/2π`` in range
    dashed black ones.  Every kind of mark has a legend entry (labels are on
    the drawn artists, so a later ``ax.legend()`` keeps them).

    Parameters
    ----------
    backbones : sequence of Backbone or Family
    ax : matplotlib Axes, optional
        Draw into it; by default a new pyplot-free figure is made.
    linear : bool
        Draw the linear frequencies of the first backbone.
    title : str, optional
    time_unit, energy_unit : str, optional
        Units of the periods and energies, for the axis labels
        (:func:`axis_labels`): ``None`` (default) for dimensionless chains;
        ``time_unit="s", energy_unit="J"`` for FE models in SI units.
    stability : bool
        Style the admissible curves by their Floquet verdict (:meth:`~bladecase.nsm.Branch.stability`):
        solid where linearly stable, dashed where unstable.
    nonadmissible : bool
        Draw the non-admissible orbits (faint dots).

    Admissible arcs narrower than a pixel are drawn as a marker at their middle (else they would vanish), and the
    linear frequencies are labelled with their mode number.

    Returns
    -------
    matplotlib.figure.Figure
        The figure of ``ax`` (or the new figure); ``fig.savefig(path)``
        writes it.

    Examples
    --------
    >>> import numpy as np
    >>> from bladecase.nsm import backbone, chain
    >>> bb = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(2.0, 8.0, 25))
    >>> fig = frequency_energy([bb])
    >>> ax = fig.axes[0]
    >>> ax.get_xlabel(), ax.get_ylabel()
    ('frequency 1/T', 'energy E')
    >>> print(*ax.get_legend_handles_labels()[1], sep=" | ")
    non-admissible orbits | 1 ipp (admissible) | ends of admissible arcs | linear frequencies $\omega_j/2\pi$
    >>> frequency_energy([bb], time_unit="s", energy_unit="J").axes[0].get_xlabel()
    'frequency 1/T (Hz)'
    """
    xlabel, ylabel = axis_labels(time_unit, energy_unit)
    if ax is None:
        fig = new_figure(figsize=(7.5, 4.8), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    fmin, fmax = np.inf, -np.inf
    labelled: set = set()
    for bb in backbones:
        c = COLORS[(bb.ipp - 1) % len(COLORS)]
        f, E, adm = bb.frequencies, bb.energy, bb.admissible
        fmin, fmax = min(fmin, f.min()), max(fmax, f.max())
        ok = np.isfinite(E) & (E > 0)
        bad = ok & ~adm
        if nonadmissible:
            ax.plot(f[bad], E[bad], ".", ms=2, color=c, alpha=0.2,
                    label=_once(labelled, "non-admissible orbits", bad.any()))
        if stability:
            _stability_curves(ax, bb, f, E, adm, c, labelled)
        else:
            Ea = np.where(adm, E, np.nan)  # NaN breaks the curve between admissible arcs
            label = _once(labelled, f"{per_period(bb.ipp, is_massless(bb))} (admissible)", adm.any())
            ax.plot(f, Ea, "-", lw=1.8, color=c, label=label)
        for iv in bb.intervals:
            for T, refined in ((iv.T_lo, iv.refined_lo), (iv.T_hi, iv.refined_hi)):
                if refined:
                    ax.axvline(1 / T, color=c, lw=0.5, ls=":", alpha=0.6,
                               label=_once(labelled, "ends of admissible arcs"))
    _narrow_arcs(ax, backbones, fmin, fmax, labelled)
    if linear and backbones:
        lf = backbones[0].linear_frequencies
        for j in np.flatnonzero((lf >= fmin) & (lf <= fmax)):
            label = _once(labelled, r"linear frequencies $\omega_j/2\pi$")
            ax.axvline(lf[j], color="k", ls="--", lw=0.8, label=label)
            ax.annotate(f"{j + 1}", (lf[j], 1.0), xycoords=("data", "axes fraction"), xytext=(2, -10),
                        textcoords="offset points", fontsize="small")
    ax.set_yscale("log")
    # Non-admissible energies diverge at resonances: frame the admissible curves.
    adm_E = np.concatenate([bb.energy[bb.admissible] for bb in backbones]) if backbones else np.array([])
    adm_E = adm_E[np.isfinite(adm_E) & (adm_E > 0)]
    if adm_E.size:
        ax.set_ylim(adm_E.min() / 3, adm_E.max() * 3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title or "Nonsmooth modes: frequency–energy")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small", markerscale=3)
    return fig


def _narrow_arcs(ax, backbones, fmin: float, fmax: float, labelled: set) -> None:
    """A marker at the middle of every admissible arc narrower than a pixel (a curve that thin is invisible)."""
    width_px = ax.get_position().width * ax.figure.get_figwidth() * ax.figure.dpi
    span = max(fmax - fmin, np.finfo(float).tiny)
    for bb in backbones:
        c = COLORS[(bb.ipp - 1) % len(COLORS)]
        f, E = bb.frequencies, bb.energy
        for arc in bb.arcs:
            if (1 / arc.T_lo - 1 / arc.T_hi) / span * width_px >= 1:
                continue
            i = (arc.start + arc.stop) // 2
            ax.plot([f[i]], [E[i]], "o", ms=5, mfc="none", color=c,
                    label=_once(labelled, f"{per_period(bb.ipp, is_massless(bb))} (admissible arc narrower than a "
                                             "pixel)"))


def _stability_curves(ax, bb, f, E, adm, c, labelled: set) -> None:
    """Admissible points split by their Floquet verdict; each run keeps its neighbour so the curve is unbroken."""
    st = bb.stability(where=adm)
    stable = adm & ~np.ma.getmaskarray(st) & np.ma.filled(st, False).astype(bool)
    unstable = adm & ~stable
    for mask, ls, word in ((stable, "-", "stable"), (unstable, "--", "unstable")):
        grown = mask | (np.r_[mask[1:], False] & adm) | (np.r_[False, mask[:-1]] & adm)
        ax.plot(f, np.where(grown, E, np.nan), ls, lw=1.8, color=c,
                label=_once(labelled, f"{per_period(bb.ipp, is_massless(bb))}, admissible, {word} (Floquet)",
                                   mask.any()))


def _once(labelled: set, label: str, drawn: bool = True) -> str | None:
    """``label`` the first time it is asked for something drawn, ``None`` afterwards (one legend entry)."""
    if not drawn or label in labelled:
        return None
    labelled.add(label)
    return label
