"""The Campbell diagram as a figure: tracked natural frequencies against speed (in the study's unit, the other
common one on the top axis), engine-order lines, their crossings, and the nonsmooth-mode bands — from grazing to
the end of each mode's admissible arc — where the blade touches its casing.

>>> import numpy as np
>>> from bladecase.fe.campbell import Campbell, crossings
>>> speeds = np.linspace(0, 1000, 5)
>>> f = np.c_[80 + 0.02 * speeds, 400 + 0.001 * speeds]
>>> c = Campbell(speeds, f, np.tile([0, 1], (5, 1)), np.ones((5, 2)), [2, 4], crossings(speeds, f, [2, 4]))
>>> fig = campbell_figure(c, bands={0: (speeds, f[:, 0], f[:, 0] * 1.02)})
>>> [t.get_text() for t in fig.axes[0].texts]
['EO 2', 'EO 4']
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from ..plots import new_figure

__all__ = ["campbell_figure"]


#: A nonsmooth-mode band narrower than this fraction of the frequency axis is drawn this wide (its true width in
#: the legend): a band of a few tenths of a percent would not show at the figure's scale.
MIN_BAND = 0.012


def _band(ax, band, j: int, color: str, top: float, per: float) -> None:
    """One mode's band, at least :data:`MIN_BAND` of the axis wide, hatched where widened, its width labelled
    (``per``: rad/s per unit of the speed axis)."""
    w, lo, hi = (np.asarray(x, dtype=float) for x in band)
    ok = np.isfinite(lo) & np.isfinite(hi)
    if not ok.any():
        return
    w, lo, hi = w[ok] / per, lo[ok], hi[ok]
    widest = float(np.max((hi - lo) / lo))
    drawn = np.maximum(hi, lo + MIN_BAND * top)
    widened = bool(np.any(drawn > hi))
    label = f"mode {j + 1}: nonsmooth mode, up to +{100 * widest:.2g} %" + (" (drawn wider)" if widened else "")
    ax.fill_between(w, lo, drawn, color=color, alpha=0.3, lw=0, hatch="///" if widened else None, label=label)


def campbell_figure(campbell, bands: dict | None = None, title: str | None = None, ax=None,
                    speed_unit: str = "rpm") -> Figure:
    """Frequencies (Hz) of the tracked modes against speed (in ``speed_unit``: the study's, ``"rpm"``, ``"rad/s"``
    or ``"Hz"``; on the top axis rad/s for rpm, else rpm), engine orders (dashed, labelled ``EO n``), their crossings
    (circles), and ``bands`` (mode → ``(speeds rad/s, low Hz, high Hz)``) shaded: the frequencies a nonsmooth mode
    of that linear mode spans at each speed.  An engine order entering a band is the contact-induced interaction
    risk."""
    from ...fe.rotation import SPEED_UNITS

    fig = ax.figure if ax is not None else new_figure(figsize=(7.0, 4.8), layout="constrained")
    ax = ax if ax is not None else fig.add_subplot()
    per = SPEED_UNITS[speed_unit.lower()]  # rad/s per unit of the axis
    rpm = campbell.speeds / per  # (the speed axis, in speed_unit)
    top = float(np.nanmax(campbell.frequencies)) * 1.08 if campbell.frequencies.size else 1.0
    for j in (bands or {}):
        hi = np.asarray(bands[j][2], dtype=float)
        if np.isfinite(hi).any():
            top = max(top, float(np.nanmax(hi)) * 1.05)
    for j in range(campbell.frequencies.shape[1]):
        color = f"C{j % 10}"
        ax.plot(rpm, campbell.frequencies[:, j], "-", color=color, lw=1.6, label=f"mode {j + 1}")
        if bands and j in bands:
            _band(ax, bands[j], j, color, top, per)
    x_end = float(rpm[-1]) if rpm.size else 1.0
    for n in campbell.engine_orders:
        y = n * campbell.speeds / (2 * math.pi)
        ax.plot(rpm, y, "--", color="0.45", lw=0.9)
        x_lab = min(x_end, 2 * math.pi * top / n / per)  # where f = n Ω / 2π leaves the plot (top or right edge)
        ax.text(x_lab, n * x_lab * per / (2 * math.pi), f"EO {n}", fontsize=8, color="0.3", ha="right", va="bottom")
    for x in campbell.crossings:
        ax.plot(x["speed_rad_s"] / per, x["frequency_hz"], "o", mfc="none", color="k", ms=6)
    ax.set_xlim(float(rpm[0]) if rpm.size else 0.0, x_end if x_end > 0 else 1.0)
    ax.set_ylim(0.0, top)
    unit = {"hz": "Hz"}.get(speed_unit.lower(), speed_unit.lower())
    ax.set_xlabel(f"rotation speed ({unit})")
    other = "rad/s" if unit == "rpm" else "rpm"  # the other unit in brackets, on top
    scale = per / SPEED_UNITS[other]
    ax.secondary_xaxis("top", functions=(lambda x: x * scale, lambda r: r / scale)).set_xlabel(f"({other})")
    ax.set_ylabel("frequency (Hz)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title or "Campbell diagram")
    return fig
