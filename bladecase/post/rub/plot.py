"""The interaction diagram of a rub sweep: peak tip normal displacement, peak total contact force and peak contact
pressure against speed, with the speeds where the casing's lobes excite a linear mode (``n·Ω = ω_k``, dashed) and
where they excite a nonsmooth mode's frequency band (shaded); on top, the ratio of the speed to the crossing speed
of mode 1. Each point says what the response is: settled, periodic over another period (a sub-harmonic), or not
settled.

>>> section = {"speed_unit": "rpm", "lobes": 3, "rows": [
...     {"speed": s, "tip_normal_displacement_mm": d, "total_force_n": f, "max_pressure_mpa": f / 20, "settled": True}
...     for s, d, f in [(3000, 0.05, 1.0), (4000, 0.4, 9.0), (5000, 0.1, 2.0)]],
...     "resonances": [{"mode": 1, "speed": 4100.0}], "nonsmooth_bands_hz": [(210.0, 216.0)]}
>>> fig = interaction_plot(section)
>>> [ax.get_ylabel() for ax in fig.axes]
['peak tip normal displacement (mm)', 'peak total contact force (N)', 'peak contact pressure (MPa)']
>>> section["crossing"] = {"mode": 1, "speed": 4100.0}
>>> section["rows"][1]["response"] = "periodic-6"
>>> interaction_plot(section).axes[0].child_axes[0].get_xlabel()
'speed / crossing speed of mode 1'
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from ...fe.rotation import SPEED_UNITS
from ..plots import new_figure

__all__ = ["interaction_plot"]


def interaction_plot(section: dict, title: str | None = None) -> Figure:
    """The figure of a ``[rub]`` summary section (:func:`bladecase.study.rub.stage.rub_stage`): hollow markers where the
    response had not settled."""
    rows = section["rows"]
    unit = section["speed_unit"]
    scale = SPEED_UNITS[unit.lower()]
    speed = np.array([r["speed"] for r in rows])
    settled = np.array([r["settled"] for r in rows], dtype=bool)
    periodic = np.array([str(r.get("response", "")).startswith("periodic-") for r in rows], dtype=bool)
    campbell = bool(section.get("open_hz"))
    series = [("tip_normal_displacement_mm", "peak tip normal displacement (mm)"),
              ("total_force_n", "peak total contact force (N)"), ("max_pressure_mpa", "peak contact pressure (MPa)")]
    if all(r.get("max_pressure_mpa") is None for r in rows):  # a line of contact nodes: no area, no pressure
        series = series[:2]
    fig = new_figure(figsize=(7.0, 9.6 if campbell else 7.4), layout="constrained")
    axes = fig.subplots(len(series) + int(campbell), 1, sharex=True)
    lobes = section["lobes"]
    for ax, (key, label) in zip(axes, series):
        y = np.array([r[key] for r in rows], dtype=float)
        ax.plot(speed, y, "-", color="C0", lw=1.2)
        plain = settled & ~periodic
        ax.plot(speed[plain], y[plain], "o", color="C0", ms=4, label="settled")
        if periodic.any():
            ax.plot(speed[periodic], y[periodic], "s", color="C2", ms=5, label="periodic over another period")
        if (~settled).any():
            ax.plot(speed[~settled], y[~settled], "o", mfc="none", color="C3", ms=5, label="not settled")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        for k, (lo, hi) in enumerate(section.get("nonsmooth_bands_hz") or []):
            a, b = (2 * math.pi * f / lobes / scale for f in (lo, hi))
            label = f"nonsmooth-mode band ({section.get('bands_at', 'at rest')})" if k == 0 else None
            ax.axvspan(a, b, color="C1", alpha=0.2, lw=0, label=label)
        for res in section.get("resonances") or []:
            ax.axvline(res["speed"], ls="--", color="0.4", lw=0.9)
            if key == series[0][0]:
                ax.annotate(f"mode {res['mode']}", (res["speed"], 1.0), xycoords=("data", "axes fraction"),
                            rotation=90, va="top", ha="right", fontsize=8, color="0.3")
    if campbell:  # the Campbell diagram on the same speed axis: the modes at each speed, the lobes' order line
        ax = axes[len(series)]
        f = np.asarray(section["open_hz"], dtype=float)
        excite = lobes * speed * scale / (2 * math.pi)
        lo = 0.9 * min(float(excite.min()), float(f[:, 0].min()))
        top = 1.1 * max(float(excite.max()), float(f[:, 0].max()))
        for k in range(f.shape[1]):
            if f[:, k].min() <= top:
                ax.plot(speed, f[:, k], "-", color=f"C{k + 2}", lw=1.2, label=f"mode {k + 1} (linear, at speed)")
        ax.plot(speed, excite, "--", color="0.3", lw=1.0, label=f"EO {lobes} (the lobes)")
        for k, (lo, hi) in enumerate(section.get("nonsmooth_bands_hz") or []):
            ax.axhspan(lo, hi, color="C1", alpha=0.2, lw=0, label="nonsmooth-mode band" if k == 0 else None)
        ax.set_ylim(lo, top)
        ax.set_ylabel("frequency (Hz)")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    axes[0].legend(loc="upper left", fontsize=8)
    crossing = (section.get("crossing") or {}).get("speed")
    if crossing:  # the speed over the crossing speed: the axis to compare meshes on
        top = axes[0].secondary_xaxis("top", functions=(lambda s: s / crossing, lambda r: r * crossing))
        top.set_xlabel(f"speed / crossing speed of mode {section['crossing'].get('mode', 1)}")
    axes[-1].set_xlabel(f"speed ({unit}); casing with {lobes} lobes: excitation at {lobes} × the speed")
    if title:
        fig.suptitle(title)
    return fig
