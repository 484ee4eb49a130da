"""The first mode with friction against its amplitude: frequency (over the open mode's) and damping ratio, one line
per ``[rub]`` speed, the free decay's ratios as open circles on the concept's line.

>>> section = {"speed_unit": "rpm", "speeds": [{"speed": 1650.0, "open_hz": 200.0, "structural_zeta": 0.005,
...            "points": [{"amplitude_ratio": r, "frequency_hz": 200.0 + r, "zeta": 0.005 - 1e-5 * r,
...                        "decay_zeta": 0.005 - 1e-5 * r} for r in (1.5, 2.0, 3.0)]}]}
>>> fig = friction_modes_plot(section)
>>> [ax.get_ylabel() for ax in fig.axes]
['frequency / open first mode', 'damping ratio (%)']
"""

from __future__ import annotations

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from ..plots import new_figure

__all__ = ["friction_modes_plot"]

#: At most this many speeds are drawn (evenly picked over the sweep, its ends among them).
MAX_LINES = 9


def friction_modes_plot(section: dict, title: str | None = None) -> Figure:
    """The figure of ``rub.friction.modes`` (:func:`bladecase.study.rub.friction_modes.modes_section`, with the
    rub's ``speed_unit``): the frequency over the open mode's and the damping ratio (%) against the amplitude (×
    grazing), a line per speed, the structural ratio dashed."""
    per = [s for s in section["speeds"] if any("error" not in q for q in s["points"])]
    if len(per) > MAX_LINES:
        per = [per[i] for i in np.unique(np.linspace(0, len(per) - 1, MAX_LINES).round().astype(int))]
    unit = section.get("speed_unit", "")
    fig = new_figure(figsize=(9.0, 4.0))
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    cmap = colormaps["viridis"]
    for i, s in enumerate(per):
        good = [q for q in s["points"] if "error" not in q]
        r = np.array([q["amplitude_ratio"] for q in good])
        color = cmap(0.1 + 0.8 * i / max(1, len(per) - 1))
        ax.plot(r, [q["frequency_hz"] / s["open_hz"] for q in good], "o-", color=color, ms=4,
                label=f"{s['speed']:.6g} {unit}")
        bx.plot(r, [100 * q["zeta"] for q in good], "o-", color=color, ms=4)
        bx.plot(r, [100 * q["decay_zeta"] for q in good], "o", mfc="none", mec="k", ms=7)
        bx.axhline(100 * s["structural_zeta"], color=color, ls="--", lw=0.8)
    ax.set_xlabel("amplitude (× grazing)")
    ax.set_ylabel("frequency / open first mode")
    ax.legend(fontsize=7, loc="best")
    bx.set_xlabel("amplitude (× grazing)")
    bx.set_ylabel("damping ratio (%)")
    bx.set_title("line: the mode; circles: its free decay; dashed: structural", fontsize=8)
    for a in (ax, bx):
        a.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
