"""The wear of an abradable coating by a rubbing blade: the worn profile unrolled over the casing's angle after each
revolution, at the speed of most wear, and — over several speeds — the removed volume against speed, each speed
marked with its lobes against round(f_vib / f_rot).

>>> section = {"speed_unit": "rpm", "rows": [{"speed": 1650.0}],
...            "wear": {"most_wear": 1650.0, "speeds": [{"speed": 1650.0, "removed_mm3": 2.0, "lobes": 8}]}}
>>> theta = (np.arange(90) + 0.5) * 4.0
>>> hist = [list(k * 1e-6 * (1 + np.cos(np.radians(8 * theta)))) for k in (1, 2, 3)]
>>> fig = wear_plot(section, [{"wear": {"history_m": hist}}])
>>> [ax.get_xlabel() for ax in fig.axes][:1]
['angle round the casing (deg)']
"""

from __future__ import annotations

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from ..plots import new_figure

__all__ = ["wear_plot"]


def wear_plot(section: dict, points: list[dict], title: str | None = None) -> Figure:
    """The figure of a ``[rub]`` section with wear (:func:`bladecase.study.rub.wear.wear_section`): the profile after
    each revolution at the speed of most wear (one line per revolution, light to dark), and, with several speeds,
    the removed volume against speed with each speed's lobe count."""
    wear = section["wear"]
    per = wear["speeds"]
    many = len(per) > 1
    fig = new_figure(figsize=(9.0, 6.5 if many else 4.0))
    ax = fig.add_subplot(2 if many else 1, 1, 1)
    top = next(i for i, r in enumerate(per) if r["speed"] == wear["most_wear"])
    history = np.asarray(points[top]["wear"]["history_m"]) * 1e6
    cells = history.shape[1]
    edges = np.arange(cells + 1) * 360.0 / cells
    cmap = colormaps["viridis"]
    for k, d in enumerate(history):
        ax.stairs(d, edges, color=cmap(0.15 + 0.8 * k / max(1, history.shape[0] - 1)), lw=1.0,
                label=f"revolution {k + 1}" if k in (0, history.shape[0] - 1) else None)
    ax.set_xlim(0.0, 360.0)
    ax.set_xlabel("angle round the casing (deg)")
    ax.set_ylabel("worn depth (µm)")
    ax.set_title(f"at {per[top]['speed']:.6g} {section['speed_unit']}: {per[top]['lobes']} lobes after "
                 f"{history.shape[0]} revolutions", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    if many:
        bx = fig.add_subplot(2, 1, 2)
        speed = np.array([r["speed"] for r in per])
        volume = np.array([r["removed_mm3"] for r in per])
        bx.plot(speed, volume, "o-", color="C3")
        for s, v, r in zip(speed, volume, per):
            bx.annotate(_lobe_label(r), (s, v), textcoords="offset points", xytext=(0, 6), ha="center", fontsize=8)
        bx.set_xlabel(f"speed ({section['speed_unit']})")
        bx.set_ylabel("removed volume (mm³)")
        bx.set_title("coating removed at each speed; lobes removed over the last wearing revolutions = or ≠ "
                     "round(f_vib / f_rot)\n(?: no lobe count to compare)", fontsize=9)
        bx.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def _lobe_label(r: dict) -> str:
    """A speed's lobes against round(f_vib / f_rot) over the last revolutions that wore the coating (its final
    profile's lobes without the check)."""
    c = r.get("lobe_check")
    if not c:
        return f"{r['lobes']}"
    if c["verdict"] == "undefined":
        return "?"
    return f"{c['lobes']}{'=' if c['verdict'] == 'agree' else '≠'}{c['expected']}"
