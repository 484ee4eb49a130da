"""The whole disk's rub over speeds (``summary["cyclic"]["rub"]``, :mod:`bladecase.study.disk.rub`): each blade's
peak contact force against speed, and the share of the blade tips' oscillation on each nodal diameter; and the
report's words for it. A matplotlib :class:`~matplotlib.figure.Figure`, no pyplot.

>>> section = {"sectors": 4, "lobes": 3, "speed_unit": "rpm", "expected_nd": 1, "contacts": 4, "modes": 8,
...            "amplitude_m": 1e-4, "speeds": [
...     {"speed": s, "peak_force": [f, f, f, f], "contact_share": [0.1] * 4, "nd_share": [0.02, 0.98, 0.0],
...      "dominant": 1, "response": "settled"} for s, f in ((1000.0, 2.0), (2000.0, 3.0))]}
>>> fig = disk_rub_figure(section)
>>> len(fig.axes), [line.get_label() for line in fig.axes[0].lines][:2]
(3, ['blade 0', 'blade 1'])
>>> rub_lines(section)[1]
'## The whole disk in the out-of-round casing'
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..plots import new_figure

__all__ = ["disk_rub_figure", "rub_lines"]


def disk_rub_figure(section: dict, title: str | None = None) -> Figure:
    """Each blade's peak force against speed (left) and the nodal-diameter content of the tips' oscillation per
    speed (right, a share from 0 to 1), the diameter the lobes force marked (doctest in the module's docstring)."""
    speeds = np.array([p["speed"] for p in section["speeds"]])
    force = np.array([p["peak_force"] for p in section["speeds"]])  # (speeds, blades)
    share = np.array([p["nd_share"] for p in section["speeds"]])  # (speeds, diameters)
    fig = new_figure(figsize=(10.0, 4.0))
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    for j in range(force.shape[1]):
        ax.plot(speeds, force[:, j], marker="o", ms=3, lw=1, label=f"blade {j}")
    ax.set_xlabel(f"speed ({section['speed_unit']})")
    ax.set_ylabel("peak contact force (N)")
    ax.ticklabel_format(axis="y", useOffset=False)
    if force.shape[1] <= 8:
        ax.legend(fontsize=7)
    image = bx.imshow(share.T, origin="lower", aspect="auto", vmin=0, vmax=1, cmap="viridis",
                      extent=(-0.5, speeds.size - 0.5, -0.5, share.shape[1] - 0.5))
    bx.axhline(section["expected_nd"], color="w", ls=":", lw=1)
    bx.set_xticks(range(speeds.size), [f"{s:.6g}" for s in speeds], rotation=45, fontsize=7)
    bx.set_xlabel(f"speed ({section['speed_unit']})")
    bx.set_ylabel("nodal diameter")
    bx.set_title(f"tips' oscillation by nodal diameter (the {section['lobes']} lobes force "
                 f"{section['expected_nd']})", fontsize=9)
    fig.colorbar(image, ax=bx, label="share")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def rub_lines(section: dict | None) -> list[str]:
    """The report's section on the disk's rub (empty without one): a table of speeds (doctest in the module's
    docstring)."""
    if not section:
        return []
    lines = ["", "## The whole disk in the out-of-round casing", "",
             f"Every one of the {section['sectors']} blades turns inside a casing of {section['lobes']} lobes of "
             f"{section['amplitude_m'] * 1e3:.4g} mm, each seeing the lobes at its own angle ({section['contacts']} "
             f"contacts, {section['modes']} modes, simulated exactly from rest until settled). A tuned disk is forced "
             f"on nodal diameter {section['expected_nd']} (the lobes modulo the blades, folded).", "",
             f"| speed ({section['speed_unit']}) | response | peak force (N), least–largest blade | contact share | "
             "dominant ND (share) |", "|---|---|---|---|---|"]
    for p in section["speeds"]:
        f, d = p["peak_force"], p["dominant"]
        lines.append(f"| {p['speed']:.6g} | {p['response']} | {min(f):.4g}–{max(f):.4g} | "
                     f"{max(p['contact_share']):.3g} | {d} ({p['nd_share'][d]:.2f}) |")
    return lines
