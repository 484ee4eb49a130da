"""The casing-stiffness sensitivity as one figure: the nonsmooth mode's admissible backbone (energy against frequency)
for each casing stiffness of a ``[contact] casing_stiffness = [...]`` list, one colour per stiffness.

>>> import numpy as np
>>> from bladecase.nsm import backbone, chain
>>> soft = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(2.0, 8.0, 25))
>>> fig = casing_figure([1e5, 1e6], [[soft], []])
>>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
['casing 1e+05 N/m', 'casing 1e+06 N/m: no admissible arc']
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from .plots import new_figure

__all__ = ["casing_figure"]


def casing_figure(stiffnesses: Sequence[float], branches: Sequence[Sequence], title: str | None = None) -> Figure:
    """Energy (J, log) against frequency (Hz) of the admissible orbits of every family found with each casing
    stiffness (N/m), one colour per stiffness; a stiffness with no admissible arc is named in the legend."""
    fig = new_figure(figsize=(7.0, 4.8), layout="constrained")
    ax = fig.add_subplot()
    for i, (k, fams) in enumerate(zip(stiffnesses, branches)):
        color = f"C{i % 10}"
        drawn = False
        for f in fams:
            fr, en = np.asarray(f.frequencies, dtype=float), np.asarray(f.energy, dtype=float)
            for a in f.arcs:
                sel = slice(a.start, a.stop + 1)
                ok = np.asarray(f.admissible)[sel]
                x, y = fr[sel][ok], en[sel][ok]
                if x.size:
                    ax.plot(x, y, "-" if x.size > 1 else "o", color=color,
                            label=None if drawn else f"casing {k:.3g} N/m")
                    drawn = True
        if not drawn:
            ax.plot([], [], "-", color=color, label=f"casing {k:.3g} N/m: no admissible arc")
    ax.set_yscale("log")
    ax.set_xlabel("frequency 1/T (Hz)")
    ax.set_ylabel("energy (J)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or "the nonsmooth mode's admissible backbone for each casing stiffness")
    return fig
