"""The Campbell diagram: a rotating blade's natural frequencies against its speed, each mode followed by its
shape, and where they meet the engine orders.

At every speed the model is linearised about its centrifugal state (:func:`~bladecase.fe.rotation.spin`,
one factorisation per speed) and its lowest modes are computed; a mode is followed from one speed to the
next by its shape — the mass-weighted modal assurance criterion (MAC) between the modes of neighbouring
speeds, matched one to one (``scipy.optimize.linear_sum_assignment``) — not by its rank, so that two modes
that veer or cross keep their identity (ranking by frequency would swap them and draw false crossings).
An engine order ``N`` excites ``f = N Ω / 2π``; its crossings with each tracked mode are located by linear
interpolation between speeds.

>>> import numpy as np
>>> hit = crossings(np.array([0.0, 100.0]), np.array([[10.0], [12.0]]), [1])   # f = Ω/2π meets 10 → 12 Hz
>>> [(x["mode"], x["engine_order"], round(x["speed_rad_s"], 2), round(x["frequency_hz"], 2)) for x in hit]
[(0, 1, 71.86, 11.44)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..checks import integer
from ..linalg import lowest_modes
from .model import FEModel
from .rotation import RotationAxis, spin

__all__ = ["EXTRA_MODES", "MAC_DOFS", "Campbell", "campbell", "crossings", "from_modes", "mac", "mac_sample",
           "modes_at_speed", "track"]

#: Candidate modes computed beyond those tracked, so that a mode entering from above is followed by its shape.
EXTRA_MODES = 4

#: A link between two speeds whose MAC is below this is reported as uncertain (the speeds are too far apart).
MAC_WARN = 0.8

#: Largest number of dofs a speed's mode shapes keep for the tracking (:func:`mac_sample`): beyond, every k-th
#: dof, so that a sweep's results stay small (a 1M-dof blade: 80 MB of shapes per speed otherwise).
MAC_DOFS = 20_000


def mac_sample(model: FEModel, limit: int | None = None) -> tuple[np.ndarray | None, object]:
    """``(dofs, M)`` for tracking modes by MAC on a sample of ``model``'s dofs: ``(None, model.M)`` — every dof,
    the exact mass-weighted MAC — for at most ``limit`` (:data:`MAC_DOFS`) dofs; else every k-th dof (``limit``
    of them, evenly spread over the numbering) with the diagonal of ``M`` as weights (the lumped mass: exact for
    a lumped model, the row-sum lumping of a consistent one), as a test–analysis correlation does on its sensors.

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> strip = Mesh(np.c_[t.p.T, np.zeros(t.p.shape[1])], {"triangle": t.t.T}, dim=2,
    ...              groups={"root": np.flatnonzero(t.p[0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> mac_sample(model)[0] is None, mac_sample(model, 50)[0].size
    (True, 50)
    """
    import scipy.sparse as sp

    limit = MAC_DOFS if limit is None else integer("limit", limit, 1)
    n = model.n_dofs
    if n <= limit:
        return None, model.M
    dofs = np.unique(np.linspace(0, n - 1, limit).round().astype(np.int64))
    weights = np.asarray(model.M.sum(axis=1)).ravel()[dofs]  # row sums: the lumped mass of each sampled dof
    return dofs, sp.diags_array(weights)


def mac(a: np.ndarray, b: np.ndarray, M=None) -> np.ndarray:
    """The MAC matrix ``(φ_aᵢᵀ M φ_bⱼ)² / ((φ_aᵢᵀ M φ_aᵢ)(φ_bⱼᵀ M φ_bⱼ))`` of the columns of ``a`` and ``b``.

    >>> mac(np.eye(2), np.array([[1.0, 1.0], [0.0, 1.0]])).round(2).tolist()
    [[1.0, 0.5], [0.0, 0.5]]
    """
    Mb = b if M is None else M @ b
    Ma = a if M is None else M @ a
    cross = a.T @ Mb
    na = np.einsum("ij,ij->j", a, Ma)
    nb = np.einsum("ij,ij->j", b, Mb)
    return cross**2 / np.outer(na, nb)


def track(shapes: list[np.ndarray], M=None, count: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(index, link_mac)``: ``index[s, j]`` is the column of ``shapes[s]`` that continues mode ``j`` (the
    ``count`` lowest at the first speed), matched one to one with the previous speed by MAC; ``link_mac[s,
    j]`` is the MAC of that link (1 at the first speed)."""
    count = shapes[0].shape[1] if count is None else count
    index = np.zeros((len(shapes), count), dtype=int)
    link = np.ones((len(shapes), count))
    index[0] = np.arange(count)
    for s in range(1, len(shapes)):
        previous = shapes[s - 1][:, index[s - 1]]
        m = mac(previous, shapes[s], M)
        rows, cols = linear_sum_assignment(-m)
        index[s, rows] = cols
        link[s, rows] = m[rows, cols]
    return index, link


def crossings(speeds: np.ndarray, frequencies: np.ndarray, engine_orders) -> list[dict]:
    """Where each tracked mode (columns of ``frequencies``, Hz, one row per speed in rad/s) meets each engine
    order line ``f = N Ω / 2π`` (linear interpolation between speeds), in order of mode, engine order, speed."""
    out = []
    speeds = np.asarray(speeds, dtype=float)
    for j in range(frequencies.shape[1]):
        for n in engine_orders:
            g = frequencies[:, j] - n * speeds / (2 * math.pi)
            for s in np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0):
                t = g[s] / (g[s] - g[s + 1])
                w = speeds[s] + t * (speeds[s + 1] - speeds[s])
                out.append({"mode": j, "engine_order": int(n), "speed_rad_s": float(w),
                            "frequency_hz": float(n * w / (2 * math.pi))})
    return out


@dataclass
class Campbell:
    """Natural frequencies against speed, each mode tracked by shape.

    Attributes
    ----------
    speeds : ndarray
        Rotation speeds (rad/s), ascending.
    frequencies : ndarray
        ``(speeds, modes)``: tracked mode ``j``'s frequency (Hz) at each speed.
    rank : ndarray
        ``(speeds, modes)``: its rank among the frequencies at that speed (0 = lowest).
    link_mac : ndarray
        ``(speeds, modes)``: the MAC between its shapes at this speed and the previous one.
    engine_orders : list of int
    crossings : list of dict
        ``mode``, ``engine_order``, ``speed_rad_s``, ``frequency_hz`` of every crossing.
    running_displacement : list of ndarray
        The static centrifugal displacement (free dofs) at each speed.
    """

    speeds: np.ndarray
    frequencies: np.ndarray
    rank: np.ndarray
    link_mac: np.ndarray
    engine_orders: list[int] = field(default_factory=list)
    crossings: list[dict] = field(default_factory=list)
    running_displacement: list = field(default_factory=list, repr=False)

    @property
    def uncertain_links(self) -> list[tuple[int, int]]:
        """``(speed index, mode)`` of every link with a MAC below :data:`MAC_WARN`."""
        s, j = np.nonzero(self.link_mac < MAC_WARN)
        return list(zip(s.tolist(), j.tolist()))

    def to_dict(self) -> dict:
        """The summary's ``"campbell"`` section: SI speeds, one ascending frequency list per speed, the tracked
        mode of each, the engine orders and their crossings."""
        order = np.argsort(self.frequencies, axis=1)
        return {
            "speeds_rad_s": self.speeds.tolist(),
            "speeds_rpm": (self.speeds * 60 / (2 * math.pi)).tolist(),
            "frequencies_hz": np.take_along_axis(self.frequencies, order, axis=1).tolist(),
            "tracked_mode": order.tolist(),
            "tracked_frequencies_hz": self.frequencies.T.tolist(),
            "link_mac": self.link_mac.T.round(4).tolist(),
            "engine_orders": list(self.engine_orders),
            "crossings": self.crossings,
        }


def campbell(model: FEModel, speeds, axis: RotationAxis | None = None, count: int = 6, engine_orders=(),
             extra: int = EXTRA_MODES, progress: bool = False) -> Campbell:
    """The Campbell diagram of ``model`` at ``speeds`` (rad/s, sorted here): the ``count`` lowest modes at the
    first speed, followed by shape through ``count + extra`` candidates at every speed.

    Examples
    --------
    A 200 mm steel strip, 4 mm thick, spun about z (its flapwise motion is along z): the first mode stiffens
    from 83.5 to 120.5 Hz up to 500 rad/s, and meets the engine orders 4 and 2 on the way:

    >>> import numpy as np
    >>> from skfem import MeshTet
    >>> from bladecase.fe import Mesh, assemble
    >>> m = MeshTet.init_tensor(np.linspace(0, 0.2, 11), np.linspace(-0.01, 0.01, 2), np.linspace(-0.002, 0.002, 2))
    >>> mesh = Mesh(m.p.T.copy(), {"tetra": m.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(m.p[0] == 0)})
    >>> c = campbell(assemble(mesh, "steel"), np.linspace(0, 500, 6), count=2, engine_orders=[2, 4])
    >>> c.frequencies[[0, -1], 0].round(1).tolist()      # the first mode, Hz, at 0 and 500 rad/s
    [83.5, 120.5]
    >>> [(x["mode"], x["engine_order"], round(x["speed_rad_s"]), round(x["frequency_hz"], 1)) for x in c.crossings]
    [(0, 2, 314, 100.0), (0, 4, 137, 87.2)]
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be a bladecase FEModel, got {type(model).__name__}")
    speeds = np.sort(np.asarray(speeds, dtype=float).ravel())
    if speeds.size == 0 or not np.all(np.isfinite(speeds)) or speeds[0] < 0:
        raise ValueError(f"speeds must be finite numbers >= 0 (rad/s), got {speeds.tolist()}")
    count = integer("count", count, 1, model.n_dofs - 1)
    n = min(count + integer("extra", extra, 0), model.n_dofs - 1)
    from ..progress import progress_bar

    shapes, values, displacements = [], [], []
    for w in progress_bar(speeds, "Campbell", enabled=progress, unit="speed"):
        state, phi, f = modes_at_speed(model, float(w), axis, n)
        shapes.append(phi)
        values.append(f)
        displacements.append(state.displacement)
    out = from_modes(speeds, shapes, values, model.M, count, engine_orders)
    out.running_displacement = displacements
    return out


def modes_at_speed(model: FEModel, speed: float, axis: RotationAxis | None, count: int, static: str = "linear"):
    """``(state, Φ, f)``: the model spun at ``speed`` (:func:`~bladecase.fe.rotation.spin`), its ``count`` lowest
    mode shapes (free dofs × count) and frequencies (Hz) about that state — one speed of a Campbell diagram."""
    state = spin(model, speed, axis, static=static)
    lam, phi = lowest_modes(state.model.K, state.model.M, count, factor=state.factor)
    return state, phi, np.sqrt(np.maximum(lam, 0.0)) / (2 * math.pi)


def from_modes(speeds, shapes: list[np.ndarray], frequencies: list[np.ndarray], M, count: int,
               engine_orders=()) -> Campbell:
    """The Campbell diagram of modes computed elsewhere (e.g. by an executor, one speed per task):
    ``shapes[s]`` (dofs × candidates) and ``frequencies[s]`` (Hz) at ``speeds[s]`` (rad/s, ascending)."""
    speeds = np.asarray(speeds, dtype=float)
    index, link = track(list(shapes), M, count)
    freqs = np.array([np.asarray(frequencies[s])[index[s]] for s in range(len(speeds))])
    orders = [integer("engine order", e, 1) for e in engine_orders]
    return Campbell(speeds, freqs, index, link, orders, crossings(speeds, freqs, orders))
