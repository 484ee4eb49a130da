"""The forced response of a blade drawn over the nonsmooth modes of the same model (pyplot-free figures).

:func:`forced_response_plot` draws, against the forcing frequency, the steady states of a forcing sweep
(:mod:`bladecase.nsm.sweep`) coloured by their class "k impacts per p forcing periods" ("k contact phases" for the
massless contact model), the non-periodic ones
and those without contact marked apart, over the admissible arcs of the nonsmooth modes (energy constant
along each orbit) as curves.  The quantity is the energy (the maximum over the steady cycle of
``½vᵀMv + ½xᵀKx``, the backbones' own energy measure) or the contact-node displacement along the casing
normal (the clearance is drawn: a state that touches the casing reaches it).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from ..plots import COLORS, _once, is_massless, new_figure, per_period

__all__ = ["CLASS_COLORS", "forced_response_plot"]

#: Colours of the steady-state classes ``k/p`` (in order of first appearance, sorted by ``p`` then ``k``).
CLASS_COLORS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4")

_QUANTITIES = {"energy": "energy E (J)", "contact": "contact displacement (m)"}


def _class_key(label: str) -> tuple[int, int]:
    k, p = (int(x) for x in label.split("/"))
    return p, k


def _backbone_arcs(ax, backbones: Sequence, labelled: set) -> list[float]:
    """The admissible arcs of every branch as curves (one colour per number of impacts or contact phases per
    period); returns their energies."""
    energies: list[float] = []
    for bb in backbones:
        c = COLORS[(bb.ipp - 1) % len(COLORS)]
        f, E = bb.frequencies, bb.energy
        for arc in bb.arcs:
            sl = slice(arc.start, arc.stop + 1)
            ok = np.isfinite(E[sl]) & (E[sl] > 0)
            if not ok.any():
                continue
            energies.extend(E[sl][ok].tolist())
            ax.plot(f[sl][ok], E[sl][ok], "-" if ok.sum() > 1 else "o", color=c, lw=1.6, ms=4, alpha=0.85,
                    label=_once(labelled, _mode_label(bb)))
    return energies


def _mode_label(bb) -> str:
    """The legend of a branch's arcs: ``"1-ipp nonsmooth mode …"`` (Newton), ``"nonsmooth mode, 1 contact phase /
    period …"`` (massless)."""
    if is_massless(bb):
        return f"nonsmooth mode, {per_period(bb.ipp, True)} (admissible arcs)"
    return f"{bb.ipp}-ipp nonsmooth mode (admissible arcs)"


def _class_words(k: str, p: str, massless: bool) -> str:
    """The legend of a steady-state class ``k/p``: impacts (Newton) or contact phases (massless) per ``p`` forcing
    periods."""
    if k == "0":
        return f"periodic, no contact{'' if p == '1' else f' ({p} periods)'}"
    event = "contact phase" if massless else "impact"
    return f"{k} {event}{'s' if k != '1' else ''} / {p} period{'s' if p != '1' else ''}"


def forced_response_plot(
    frequency,
    value,
    labels: Sequence[str],
    *,
    sweep: Sequence[str] | None = None,
    backbones: Sequence = (),
    quantity: str = "energy",
    gap: float | None = None,
    engine_order: int | None = None,
    title: str | None = None,
    ax=None,
    massless: bool | None = None,
) -> Figure:
    """Steady states of a forced sweep against the forcing frequency, over the nonsmooth-mode arcs.

    Parameters
    ----------
    frequency, value : (n,) array_like
        Forcing frequency (Hz) and the plotted quantity of each steady state (J, or m for ``"contact"``).
    labels : sequence of str
        :attr:`~bladecase.nsm.sweep.SweepPoint.label` of each state: ``"k/p"``, ``"linear"`` (never touches
        the casing again), ``"non-periodic"``, ``"incomplete"``.
    sweep : sequence of {"up", "down"}, optional
        Sweep direction of each state (marker ``^`` up, ``v`` down).
    backbones : sequence of Branch
        Nonsmooth modes of the same model, drawn for ``quantity="energy"`` (their admissible arcs).
    quantity : {"energy", "contact"}
    gap : float, optional
        Clearance (m), drawn as a horizontal line for ``quantity="contact"``.
    engine_order : int, optional
        Adds the rotation speed ``60 f / EO`` (rpm) as a top axis.
    massless : bool, optional
        The states are of the massless contact model: their classes count contact phases, not impacts. Not set:
        as the ``backbones`` (Newton's impacts without any).

    Examples
    --------
    >>> fig = forced_response_plot([100.0, 110.0, 120.0], [1e-3, 5e-3, 2e-3], ["linear", "1/1", "non-periodic"],
    ...                            engine_order=4)
    >>> ax = fig.axes[0]
    >>> ax.get_xlabel(), ax.get_ylabel(), ax.get_legend_handles_labels()[1]
    ('forcing frequency (Hz)', 'energy E (J)', ['1 impact / 1 period', 'no contact (linear)', 'non-periodic'])
    >>> ax.child_axes[0].get_xlabel()
    'rotation speed (rpm), engine order 4'
    """
    if quantity not in _QUANTITIES:
        raise ValueError(f"quantity must be one of {', '.join(map(repr, _QUANTITIES))}, got {quantity!r}")
    f = np.asarray(frequency, dtype=float).reshape(-1)
    y = np.asarray(value, dtype=float).reshape(-1)
    labels = [str(s) for s in labels]
    if y.shape != f.shape or len(labels) != f.size:
        raise ValueError(f"frequency, value and labels must have one entry per state, got {f.size}, {y.size}, "
                         f"{len(labels)}")
    sweep = ["up"] * f.size if sweep is None else [str(s) for s in sweep]
    if len(sweep) != f.size or set(sweep) - {"up", "down"}:
        raise ValueError(f"sweep must give 'up' or 'down' for each of the {f.size} states, got {sweep!r}")
    if ax is None:
        fig = new_figure(figsize=(7.5, 4.8), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    if massless is None:
        massless = any(is_massless(bb) for bb in backbones)
    labelled: set = set()
    drawn_E = _backbone_arcs(ax, backbones, labelled) if quantity == "energy" else []
    up = np.array([s == "up" for s in sweep])
    lab = np.array(labels, dtype=object)
    classes = sorted({s for s in labels if "/" in s}, key=_class_key)
    for i, cls in enumerate(classes):
        text = _class_words(*cls.split("/"), massless)
        for mask, marker in ((up, "^" if not up.all() else "o"), (~up, "v")):
            m = (lab == cls) & mask
            if m.any():
                ax.plot(f[m], y[m], marker, ls="none", ms=6, color=CLASS_COLORS[i % len(CLASS_COLORS)],
                        mec="k", mew=0.4, label=_once(labelled, text))
    for word, marker, style in (("linear", ".", dict(color="0.45", ms=6)),
                                ("non-periodic", "x", dict(color="red", ms=7, mew=1.5)),
                                ("incomplete", "+", dict(color="k", ms=8, mew=1.2))):
        m = (lab == word) & np.isfinite(y)
        if m.any():
            text = "no contact (linear)" if word == "linear" else word
            ax.plot(f[m], y[m], marker, ls="none", label=_once(labelled, text), **style)
    if quantity == "contact" and gap is not None:
        ax.axhline(gap, color="k", ls="--", lw=0.9, label=_once(labelled, "clearance d"))
    if quantity == "energy":
        ax.set_yscale("log")
        shown = np.concatenate([y[np.isfinite(y) & (y > 0)], np.asarray(drawn_E, dtype=float)])
        if shown.size:
            ax.set_ylim(shown.min() / 3, shown.max() * 3)
    if f.size:
        pad = 0.02 * max(float(np.ptp(f)), 1e-12 * max(abs(float(f.max())), 1.0))
        ax.set_xlim(f.min() - pad, f.max() + pad)
    ax.set_xlabel("forcing frequency (Hz)")
    ax.set_ylabel(_QUANTITIES[quantity])
    ax.set_title(title or "Forced response over the nonsmooth modes")
    ax.grid(True, which="both", alpha=0.3)
    if engine_order is not None:
        eo = float(engine_order)
        top = ax.secondary_xaxis("top", functions=(lambda x: 60.0 * x / eo, lambda s: eo * s / 60.0))
        top.set_xlabel(f"rotation speed (rpm), engine order {engine_order}")
    if (not up.all()) and up.any():
        ax.plot([], [], "^", color="0.3", label="sweep up")
        ax.plot([], [], "v", color="0.3", label="sweep down")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small")
    return fig
