"""The distribution of a mistuned disk's amplification factor: a histogram with the tuned disk (1) and Whitehead's
bound ``½(1 + √N)`` marked.  A matplotlib :class:`~matplotlib.figure.Figure`, no pyplot.

>>> import numpy as np
>>> from bladecase.reduction.mistuning_stats import MistuningStatistics
>>> stats = MistuningStatistics(np.zeros((3, 4)), np.array([1.1, 1.3, 1.2]), np.zeros(3, int), np.ones(3), 1.0,
...                             1.5)
>>> fig = amplification_figure(stats, bins=4)
>>> ax = fig.axes[0]
>>> len(ax.patches), [line.get_label() for line in ax.lines]
(4, ['tuned', 'Whitehead bound 1.500', 'largest 1.300'])
"""

from __future__ import annotations

from matplotlib.figure import Figure

from ...reduction.mistuning_stats import MistuningStatistics
from ..plots import new_figure

__all__ = ["amplification_figure"]


def amplification_figure(stats: MistuningStatistics, bins: int = 40) -> Figure:
    """The histogram of ``stats.factors`` with the tuned value, Whitehead's bound and the largest sample marked
    (doctest in the module's docstring)."""
    fig = new_figure(figsize=(6.4, 4.0))
    ax = fig.add_subplot(1, 1, 1)
    ax.hist(stats.factors, bins=bins, color="tab:blue", alpha=0.8)
    ax.axvline(1.0, color="k", linestyle=":", label="tuned")
    ax.axvline(stats.bound, color="tab:red", linestyle="--", label=f"Whitehead bound {stats.bound:.3f}")
    ax.axvline(float(stats.factors.max()), color="tab:orange", label=f"largest {stats.factors.max():.3f}")
    ax.set_xlabel("amplification factor (largest blade amplitude ÷ tuned)")
    ax.set_ylabel("samples")
    ax.set_title(f"{stats.factors.size} mistuned samples, {stats.deltas.shape[1]} blades")
    ax.legend(loc="center right")
    return fig
