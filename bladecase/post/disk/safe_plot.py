"""The SAFE (ZZENF: zig-zag excitation, nodal diameter, frequency) diagram of a bladed disk.

Natural frequency against nodal diameter ``k = 0 … ⌊N/2⌋``, one line per mode family (the ``j``-th frequency of
every diameter), and the engine orders at one speed ``Ω`` as a zig-zag: engine order ``e`` is at the frequency
``eΩ/2π`` and excites the nodal diameter ``k ≡ ±e (mod N)`` folded into ``0 … ⌊N/2⌋``
(:func:`~bladecase.fe.cyclic.engine_order_diameter`), so consecutive orders climb ``0, 1, …, N/2`` then fold back
``… 1, 0``.  Where the zig-zag meets a family at a diameter, that engine order resonates with that mode: a point of
the Campbell diagram of that diameter.  A matplotlib :class:`~matplotlib.figure.Figure`, no pyplot.

>>> fig = safe_figure({0: [100.0, 400.0], 1: [120.0, 420.0], 2: [150.0, 430.0]}, 4, speed=200.0)
>>> ax = fig.axes[0]
>>> [line.get_label() for line in ax.lines]
['family 1', 'family 2', 'engine orders at 1910 rpm']
>>> ax.lines[-1].get_xdata().tolist()                # EO 0, 1, …: nodal diameters 0 1 2 1 0 1 2 …
[0, 1, 2, 1, 0, 1, 2, 1, 0, 1, 2, 1, 0, 1, 2, 1]
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from ...fe.cyclic import engine_order_diameter
from ..plots import new_figure

__all__ = ["campbell_nd_figure", "engine_order_zigzag", "safe_figure"]


def engine_order_zigzag(sectors: int, speed: float, top: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(orders, diameters, frequencies)``: the engine orders ``e = 0, 1, …`` at ``speed`` (rad/s) up to the
    first above ``top`` (Hz), the nodal diameter each excites and its frequency ``eΩ/2π`` (Hz).

    >>> e, k, f = engine_order_zigzag(6, 2 * np.pi * 10, 45.0)
    >>> e.tolist(), k.tolist(), f.tolist()
    ([0, 1, 2, 3, 4, 5], [0, 1, 2, 3, 2, 1], [0.0, 10.0, 20.0, 30.0, 40.0, 50.0])
    """
    speed = float(speed)
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    per = speed / (2.0 * math.pi)
    last = int(math.ceil(float(top) / per)) if math.isfinite(top) and top > 0 else 1
    if last > 10_000:
        raise ValueError(f"{last} engine orders below {top:g} Hz at {speed:g} rad/s: too many to draw (a speed in "
                         "rpm given as rad/s?)")
    orders = np.arange(last + 1)
    return orders, np.array([engine_order_diameter(e, sectors) for e in orders]), orders * per


def _frequencies(spectrum) -> dict[int, np.ndarray]:
    out = {}
    for k, v in dict(spectrum).items():
        f = np.asarray(getattr(v, "frequencies", v), dtype=float).ravel()
        out[int(k)] = f
    if not out:
        raise ValueError("the spectrum is empty: give {nodal diameter: frequencies (Hz)}")
    return dict(sorted(out.items()))


def safe_figure(spectrum, sectors: int, *, speed: float | None = None, title: str | None = None,
                ax=None) -> Figure:
    """The SAFE diagram (module docstring) of ``spectrum`` — ``{k: frequencies (Hz)}`` or ``{k: CyclicModes}``
    (:func:`~bladecase.fe.cyclic.cyclic_spectrum`) — of a disk of ``sectors`` blades, with the engine-order
    zig-zag at ``speed`` (rad/s; ``None``: none).

    Raises
    ------
    ValueError
        A nodal diameter outside ``0 … ⌊N/2⌋``, an empty spectrum, a bad ``speed``.
    """
    freq = _frequencies(spectrum)
    bad = [k for k in freq if not 0 <= k <= sectors // 2]
    if bad:
        raise ValueError(f"nodal diameters {bad} are outside 0..{sectors // 2} (a disk of {sectors} sectors)")
    fig = ax.figure if ax is not None else new_figure(figsize=(7.0, 4.8), layout="constrained")
    ax = ax if ax is not None else fig.add_subplot()
    ks = np.array(list(freq))
    families = max(f.size for f in freq.values())
    for j in range(families):
        y = np.array([f[j] if j < f.size else np.nan for f in freq.values()])
        ax.plot(ks, y, "o-", ms=4, lw=1.2, label=f"family {j + 1}")
    top = float(np.nanmax(np.concatenate(list(freq.values())))) * 1.05
    if speed is not None:
        orders, k_e, f_e = engine_order_zigzag(sectors, speed, top)
        rpm = speed * 60.0 / (2.0 * math.pi)
        ax.plot(k_e, f_e, "--", color="0.35", lw=1.0, label=f"engine orders at {rpm:.0f} rpm")
        for e, k, f in zip(orders[1:], k_e[1:], f_e[1:]):
            if f <= top:
                ax.annotate(f"EO {e}", (k, f), textcoords="offset points", xytext=(3, -9), fontsize=7, color="0.35")
    ax.set_xlim(-0.3, sectors // 2 + 0.3)
    ax.set_ylim(0.0, top)
    ax.set_xticks(range(sectors // 2 + 1))
    ax.set_xlabel("nodal diameter")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(title or f"SAFE diagram, {sectors} sectors")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return fig


def campbell_nd_figure(speeds, table: dict, sectors: int, *, orders=(), title: str | None = None) -> Figure:
    """The Campbell diagram of every nodal diameter: ``table`` ``{k: (len(speeds), families) frequencies (Hz)}``
    (:func:`~bladecase.fe.cyclic_spin.cyclic_campbell`) against ``speeds`` (rad/s, drawn in rpm), one colour per
    nodal diameter, and the engine-order lines ``eΩ/2π`` of ``orders`` labelled with the diameter each excites.

    >>> import numpy as np
    >>> fig = campbell_nd_figure(np.array([0.0, 1000.0]), {0: np.array([[100.0], [110.0]]),
    ...                          1: np.array([[120.0], [125.0]])}, 4, orders=[1])
    >>> [line.get_label() for line in fig.axes[0].lines]
    ['ND 0', 'ND 1', 'EO 1 (ND 1)']
    """
    w = np.asarray(speeds, dtype=float)
    if w.ndim != 1 or w.size < 1 or not np.all(np.isfinite(w)):
        raise ValueError(f"speeds must be a list of finite speeds (rad/s), got {speeds!r}")
    rpm = w * 60.0 / (2.0 * math.pi)
    fig = new_figure(figsize=(7.0, 4.8), layout="constrained")
    ax = fig.add_subplot()
    colours = [f"C{i % 10}" for i in range(len(table))]
    top = 0.0
    for c, (k, f) in zip(colours, sorted(table.items())):
        f = np.asarray(f, dtype=float).reshape(w.size, -1)
        top = max(top, float(np.nanmax(f)))
        for j in range(f.shape[1]):
            ax.plot(rpm, f[:, j], "o-", color=c, ms=3, lw=1.1, label=f"ND {k}" if j == 0 else "_")
    for e in orders:
        ax.plot(rpm, e * w / (2.0 * math.pi), "--", color="0.4", lw=0.9,
                label=f"EO {e} (ND {engine_order_diameter(e, sectors)})")
    ax.set_ylim(0.0, 1.05 * top if top > 0 else 1.0)
    ax.set_xlabel("speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(title or f"Campbell diagram per nodal diameter, {sectors} sectors")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    return fig
