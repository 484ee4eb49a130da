"""Cyclic symmetry: the modes of a bladed disk by nodal diameter, from one sector.

A disk of ``N`` identical sectors is sector 0 rotated ``j`` times by ``α = 2π/N`` about the engine axis (a point
``o`` and a unit direction ``a``, :class:`~bladecase.fe.rotation.RotationAxis`; angles are right-handed about
``a``).  Sector 0 has two cyclic faces: the **left** face and the **right** face, the left face rotated by ``+α``
(the right face of sector ``j`` is the left face of sector ``j + 1``).  A mode of nodal diameter ``k``
(``0 <= k <= N/2``) has, in each sector's own frame, the complex amplitude of sector 0 times ``e^{ijkα}``; the
sector's displacements then satisfy, in the global frame,

    ``u_right = e^{ikα} R_α u_left``        (``R_α``: the rotation by ``α`` about ``a``)

so ``u = T_k q`` on the sector's dofs without its right face, ``T_k = E + e^{ikα} C``, and the modes of nodal
diameter ``k`` are those of ``T_kᴴ K T_k``, ``T_kᴴ M T_k`` (Hermitian).  For ``k = 0`` and ``k = N/2``
(``N`` even) ``e^{ikα} = ±1`` and the problem is real.  For ``0 < k < N/2`` it is solved as its real equivalent
of twice the size — the cosine and sine parts ``q = a + i b`` of the sector —, a real symmetric problem whose
every eigenvalue is double (``(a, b)`` and ``(−b, a)``); each pair gives one complex sector mode, i.e. two
standing waves of the disk (the double frequencies of a tuned disk).  One factorisation per ``k``
(:func:`bladecase.linalg.spd_factor`, :func:`bladecase.linalg.lowest_modes`), never a dense ``n × n`` matrix.

:func:`fe_sector` makes a :class:`CyclicSector` from a clamped sector :class:`~bladecase.fe.model.FEModel`: the two
faces from named node groups or found by the sector angle, their nodes matched by the rotation (to ``tol`` in the
mesh's unit; unmatched nodes are an error naming them).  :func:`cyclic_modes` solves one nodal diameter,
:func:`cyclic_spectrum` all of them; :mod:`bladecase.fe.cyclic_waves` expands a sector mode to the annulus as a
standing or a travelling wave.

>>> import scipy.sparse as sp
>>> N = 8                                    # a ring of 8 unit masses, unit springs between neighbours
>>> s = CyclicSector(sp.csr_array([[1.0 + 1e-3, -1.0], [-1.0, 1.0]]), sp.csr_array(np.diag([1.0, 0.0])), N,
...                  left=[0], right=[1])   # dof 1 is the next sector's mass; a weak spring 1e-3 to the ground
>>> [round(float(cyclic_modes(s, k, 1).lam[0]), 6) for k in nodal_diameters(N)]    # 1e-3 + 2 - 2 cos(kα)
[0.001, 0.586786, 2.001, 3.415214, 4.001]
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..checks import integer, symmetric
from ..linalg import DENSE_LIMIT, lowest_modes, spd_factor
from .mesh_checks import LENGTH_UNITS
from .model import FEModel
from .rotation import RotationAxis

__all__ = ["CyclicModes", "CyclicSector", "cyclic_basis", "cyclic_modes", "cyclic_spectrum", "engine_order_diameter",
           "fe_sector", "nodal_diameters", "rotation_matrix", "sector_angles"]

#: Default matching tolerance of the cyclic faces, as a fraction of the sector's largest radius.
FACE_RTOL = 1e-6

#: Eigenvalues of the real ``2n`` form closer than this (relative) are treated as one cluster.
CLUSTER_RTOL = 1e-6


def rotation_matrix(direction, angle: float) -> np.ndarray:
    """The 3 × 3 right-handed rotation by ``angle`` (rad) about the unit vector ``direction`` (Rodrigues).

    >>> rotation_matrix((1, 0, 0), np.pi / 2).round(12) @ np.array([0.0, 0.0, 1.0])
    array([ 0., -1.,  0.])
    """
    a = np.asarray(direction, dtype=float)
    a = a / np.linalg.norm(a)
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * W + (1.0 - math.cos(angle)) * (W @ W)


def nodal_diameters(sectors: int) -> list[int]:
    """The nodal diameters ``0 … ⌊N/2⌋`` of a disk of ``sectors`` sectors.

    >>> nodal_diameters(7), nodal_diameters(8)
    ([0, 1, 2, 3], [0, 1, 2, 3, 4])
    """
    return list(range(integer("sectors", sectors, 2) // 2 + 1))


def engine_order_diameter(order: int, sectors: int) -> int:
    """The nodal diameter an engine order excites: ``k ≡ ±e (mod N)``, folded into ``0 … ⌊N/2⌋``.

    >>> [engine_order_diameter(e, 12) for e in (1, 6, 7, 11, 12, 13, 25)]
    [1, 6, 5, 1, 0, 1, 1]
    """
    n = integer("sectors", sectors, 2)
    k = integer("engine order", order, 0) % n
    return min(k, n - k)


@dataclass(frozen=True, eq=False)
class CyclicSector:
    """A sector of a cyclic structure: its matrices and how its right face follows its left face.

    Attributes
    ----------
    K, M : (n, n) scipy sparse
        The sector's stiffness and mass (symmetric; ``K`` positive definite once the cyclic constraint holds).
    sectors : int
        ``N >= 2``, the number of sectors of the whole structure.
    left, right : (p,) int arrays
        Dofs of the left and right faces (disjoint); ``u_right = e^{ikα} link @ u_left``.
    link : (p, p) scipy sparse or None
        The map from left to right face dofs: the rotation ``R_α`` of each face node's displacement
        (:func:`fe_sector`); ``None``: the identity (scalar dofs, e.g. a lumped model).
    triples : (q, 3) int array or None
        The ``x, y, z`` dofs of each location with three free dofs (rotating a field to another sector);
        ``None`` for scalar dofs that a rotation leaves as they are.
    axis : RotationAxis or None
        The engine axis (``None`` for a lumped model).
    pairs : (m, 2) int array or None
        The matched ``(left, right)`` mesh nodes with free dofs (:func:`fe_sector`; the edge and face dofs of an
        order-2 model on first-order cells, which sit at no mesh node, are matched too but not listed here).
    """

    K: object
    M: object
    sectors: int
    left: np.ndarray
    right: np.ndarray
    link: object = None
    triples: np.ndarray | None = None
    axis: RotationAxis | None = None
    pairs: np.ndarray | None = None

    def __post_init__(self):
        n = self.K.shape[0]
        if self.K.shape != (n, n) or self.M.shape != (n, n):
            raise ValueError(f"K {self.K.shape} and M {self.M.shape} must be square matrices of one size")
        object.__setattr__(self, "sectors", integer("sectors", self.sectors, 2))
        for name in ("K", "M"):
            a = sp.csr_array(getattr(self, name), dtype=float)
            symmetric(name, a)
            object.__setattr__(self, name, a)
        left, right = (np.asarray(v, dtype=np.int64).ravel() for v in (self.left, self.right))
        if left.size != right.size or left.size == 0:
            raise ValueError(f"the cyclic faces must have the same number (>= 1) of dofs: left {left.size}, "
                             f"right {right.size}")
        both = np.concatenate([left, right])
        if both.min() < 0 or both.max() >= n or np.unique(both).size != both.size:
            raise ValueError(f"the cyclic face dofs must be distinct dofs in 0..{n - 1} (left and right disjoint)")
        link = sp.eye_array(left.size, format="csr") if self.link is None else sp.csr_array(self.link)
        if link.shape != (left.size, left.size):
            raise ValueError(f"link must be {left.size} × {left.size} (left to right face dofs), got {link.shape}")
        object.__setattr__(self, "left", left)
        object.__setattr__(self, "right", right)
        object.__setattr__(self, "link", link)

    @property
    def n_dofs(self) -> int:
        """Dofs of the sector (both faces included)."""
        return self.K.shape[0]

    @property
    def alpha(self) -> float:
        """The sector angle ``2π/N`` (rad)."""
        return 2.0 * math.pi / self.sectors

    def kept(self) -> np.ndarray:
        """The sector's dofs without its right face: the unknowns ``q`` of the cyclic problem."""
        mask = np.ones(self.n_dofs, dtype=bool)
        mask[self.right] = False
        return np.flatnonzero(mask)


def cyclic_basis(sector: CyclicSector, k: int) -> tuple[sp.csr_array, sp.csr_array]:
    """``(T_r, T_i)``: the real and imaginary parts of ``T_k`` (``n × m``), ``u = T_k q`` on the sector's dofs,
    ``q`` on :meth:`CyclicSector.kept` (module docstring).

    >>> import scipy.sparse as sp
    >>> s = CyclicSector(sp.eye_array(2), sp.eye_array(2), 4, left=[0], right=[1])
    >>> [t.toarray().round(12).tolist() for t in cyclic_basis(s, 1)]
    [[[1.0], [0.0]], [[0.0], [1.0]]]
    """
    k = integer("nodal diameter k", k, 0, sector.sectors // 2)
    kept = sector.kept()
    n, m = sector.n_dofs, kept.size
    col = np.full(n, -1, dtype=np.int64)
    col[kept] = np.arange(m)
    E = sp.csr_array((np.ones(m), (kept, np.arange(m))), shape=(n, m))
    link = sp.coo_array(sector.link)
    C = sp.csr_array((link.data, (sector.right[link.row], col[sector.left[link.col]])), shape=(n, m))
    c, s = math.cos(k * sector.alpha), math.sin(k * sector.alpha)
    if k == 0 or 2 * k == sector.sectors:
        s = 0.0
        c = 1.0 if k == 0 else -1.0
    return sp.csr_array(E + c * C), sp.csr_array(s * C)


@dataclass(frozen=True, eq=False)
class CyclicModes:
    """The modes of one nodal diameter of a cyclic sector (:func:`cyclic_modes`).

    Attributes
    ----------
    k : int
        The nodal diameter.
    sectors : int
        ``N``.
    lam : (c,) ndarray
        Eigenvalues ``ω²`` (rad²/s²), ascending.
    shapes : (n, c) complex ndarray
        The sector's complex modes on all its dofs, ``φᴴ M φ = 1``, each with its largest entry real and positive;
        the real part is the cosine standing wave, the imaginary part the sine one (real for ``k = 0`` and
        ``k = N/2``).
    size : int
        Unknowns of the solved real problem (``m``, or ``2m`` for ``0 < k < N/2``).
    seconds : float
        Wall time of the assembly, factorisation and eigen-solution.
    """

    k: int
    sectors: int
    lam: np.ndarray
    shapes: np.ndarray
    size: int
    seconds: float

    @property
    def frequencies(self) -> np.ndarray:
        """Natural frequencies (Hz)."""
        return np.sqrt(self.lam) / (2.0 * math.pi)

    @property
    def multiplicity(self) -> int:
        """How many times each frequency appears in the whole disk's spectrum: 1 for ``k = 0`` and ``k = N/2``,
        else 2 (a cosine and a sine standing wave, or a forward and a backward travelling wave)."""
        return 1 if self.k == 0 or 2 * self.k == self.sectors else 2


def _complex_modes(sector: CyclicSector, Tr, Ti, lam: np.ndarray, V: np.ndarray, real: bool,
                   count: int) -> tuple[np.ndarray, np.ndarray]:
    """The distinct complex sector modes of the eigenpairs ``(lam, V)`` of the real form: eigenvalues clustered,
    each cluster's complex vectors ``M``-orthonormalised (a pair ``(a, b)``, ``(−b, a)`` gives one mode)."""
    m = Tr.shape[1]
    Z = V.astype(complex) if real else V[:m] + 1j * V[m:]
    Phi = Tr @ Z + 1j * (Ti @ Z)
    out_lam, out = [], []
    start = 0
    while start < lam.size:
        stop = start + 1
        while stop < lam.size and lam[stop] - lam[start] <= CLUSTER_RTOL * lam[start]:
            stop += 1
        basis: list[np.ndarray] = []
        for j in range(start, stop):
            v = Phi[:, j].copy()
            norm0 = math.sqrt(max(float(np.real(np.vdot(v, sector.M @ v))), 0.0))
            for _ in range(2):
                for b in basis:
                    v = v - b * np.vdot(b, sector.M @ v)
            norm = math.sqrt(max(float(np.real(np.vdot(v, sector.M @ v))), 0.0))
            if norm > 0.3 * norm0:
                basis.append(v / norm)
        for b in basis:
            Kb = sector.K @ b
            out_lam.append(float(np.real(np.vdot(b, Kb))))
            out.append(b)
        start = stop
    order = np.argsort(out_lam)[:count]
    shapes = np.column_stack(out)[:, order]
    top = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(shapes.shape[1])]
    return np.asarray(out_lam)[order], shapes * (np.abs(top) / top)[None, :]  # largest entry real and positive


def _real_form(sector: CyclicSector, k: int):
    """``(K_k, M_k, T_r, T_i, real)``: the real symmetric problem of nodal diameter ``k`` (size ``m`` or ``2m``)."""
    Tr, Ti = cyclic_basis(sector, k)
    real = k == 0 or 2 * k == sector.sectors
    K, M = sp.csr_array(sector.K), sp.csr_array(sector.M)
    if real:
        Kk, Mk = Tr.T @ K @ Tr, Tr.T @ M @ Tr
    else:
        T = sp.block_array([[Tr, -Ti], [Ti, Tr]], format="csr")
        Kk, Mk = T.T @ sp.block_diag([K, K]) @ T, T.T @ sp.block_diag([M, M]) @ T
    sym = lambda A: sp.csr_array(0.5 * (A + A.T))  # noqa: E731  (round-off asymmetry of the products)
    return sym(Kk), sym(Mk), Tr, Ti, real


def cyclic_modes(sector: CyclicSector, k: int, count: int = 10) -> CyclicModes:
    """The ``count`` lowest modes of nodal diameter ``k`` of a cyclic ``sector`` (module docstring).

    One factorisation of the reduced stiffness of diameter ``k`` (``K_k``: ``m`` unknowns, or ``2m`` for
    ``0 < k < N/2``, real); the eigen-solver is :func:`~bladecase.linalg.lowest_modes` (its block Lanczos for the
    double eigenvalues of ``0 < k < N/2``).

    Raises
    ------
    ValueError
        ``k`` outside ``0 … ⌊N/2⌋``, a bad ``count``, or ``K_k`` not positive definite (a sector that is not
        clamped: a free disk has rigid-body modes at nodal diameters 0 and 1).

    >>> import scipy.sparse as sp
    >>> s = CyclicSector(sp.csr_array([[2.0, -1.0], [-1.0, 1.0]]), sp.csr_array(np.diag([1.0, 0.0])), 6,
    ...                  left=[0], right=[1])
    >>> m = cyclic_modes(s, 1, 1)
    >>> round(float(m.lam[0]), 12), m.multiplicity, m.shapes.shape   # 1 + 2 - 2 cos(60°)
    (2.0, 2, (2, 1))
    """
    start = time.perf_counter()
    k = integer("nodal diameter k", k, 0, sector.sectors // 2, note=f" (a disk of {sector.sectors} sectors)")
    count = integer("count", count, 1)
    Kk, Mk, Tr, Ti, real = _real_form(sector, k)
    size = Kk.shape[0]
    factor = spd_factor(Kk, f"K of nodal diameter {k}",
                        hint="is the sector clamped (e.g. at its hub)? A free disk has rigid-body modes at nodal "
                             "diameters 0 and 1")
    wanted = min(count if real else 2 * count + 4, size)
    if wanted > size - 2 and size > DENSE_LIMIT:
        wanted = size - 2
    dense = wanted >= size - 1 or None
    lam, V = lowest_modes(Kk, Mk, wanted, factor=factor if not dense else None, dense=dense,
                          name=f"K of nodal diameter {k}", method="auto" if real else "block")
    lam, shapes = _complex_modes(sector, Tr, Ti, lam, V, real, count)
    return CyclicModes(k, sector.sectors, lam, shapes, size, time.perf_counter() - start)


def cyclic_spectrum(sector: CyclicSector, count: int = 10, diameters=None) -> dict[int, CyclicModes]:
    """:func:`cyclic_modes` for every nodal diameter (``diameters``: a subset of ``0 … ⌊N/2⌋``).

    >>> import scipy.sparse as sp
    >>> s = CyclicSector(sp.csr_array([[2.0, -1.0], [-1.0, 1.0]]), sp.csr_array(np.diag([1.0, 0.0])), 4,
    ...                  left=[0], right=[1])
    >>> {k: round(float(m.lam[0]), 9) for k, m in cyclic_spectrum(s, 1).items()}
    {0: 1.0, 1: 3.0, 2: 5.0}
    """
    ks = nodal_diameters(sector.sectors) if diameters is None else list(diameters)
    return {int(k): cyclic_modes(sector, k, count) for k in ks}


# ----------------------------------------------------------------------------- FE sectors


def sector_angles(points: np.ndarray, axis: RotationAxis) -> tuple[np.ndarray, np.ndarray]:
    """``(r, θ)`` of ``points`` about ``axis``: radius and right-handed angle (rad) from the mean radial direction
    of the points (so a sector of less than a half-turn has ``θ`` within ``(−π/2, π/2)``).

    >>> ax = RotationAxis((0, 0, 0), (1, 0, 0))
    >>> r, t = sector_angles(np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 1.0], [0.0, 1.0, 1.0]]), ax)
    >>> np.degrees(t).round(6).tolist()
    [0.0, 45.0, -45.0]
    """
    x = np.asarray(points, dtype=float) - axis.origin
    a = axis.direction
    radial = x - np.outer(x @ a, a)
    r = np.linalg.norm(radial, axis=1)
    mean = radial[r > 0].sum(axis=0) if np.any(r > 0) else np.zeros(3)
    if np.linalg.norm(mean) == 0:
        raise ValueError("the sector's nodes have no mean radial direction about the axis (a full disk?)")
    e1 = mean / np.linalg.norm(mean)
    e2 = np.cross(a, e1)
    return r, np.arctan2(radial @ e2, radial @ e1)


def _locations(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """``(points, triples)``: each dof location with its ``x, y, z`` free dofs (``-1`` where one is not free)."""
    pts, inverse = np.unique(model.dofs.coords, axis=0, return_inverse=True)
    triples = np.full((len(pts), 3), -1, dtype=np.int64)
    triples[inverse.ravel(), model.dofs.direction] = np.arange(model.n_dofs)
    return pts, triples


def _group_points(model: FEModel, group) -> np.ndarray:
    """Where the dofs of a face given as a node group may sit: its nodes, and the midpoints of any two of its nodes
    in one cell (the edge and face dofs of an order-2 model on first-order cells)."""
    mesh = model.mesh
    nodes = mesh.group(group) if isinstance(group, str) else np.asarray(group, dtype=np.int64)
    pts = [mesh.points[nodes]]
    inside = np.zeros(len(mesh.points), dtype=bool)
    inside[nodes] = True
    cells = np.asarray(mesh.cells[mesh.body_type])
    cells = cells[inside[cells].sum(axis=1) >= 2]
    for a in range(cells.shape[1]):
        for b in range(a + 1, cells.shape[1]):
            ok = inside[cells[:, a]] & inside[cells[:, b]]
            pts.append(0.5 * (mesh.points[cells[ok, a]] + mesh.points[cells[ok, b]]))
    return np.vstack(pts)


def _name_nodes(model: FEModel, points: np.ndarray) -> str:
    """The mesh nodes at ``points`` (their file numbers) and coordinates, for messages (first five)."""
    tree = cKDTree(model.mesh.points)
    _, idx = tree.query(points[:5])
    ids = model.mesh.node_ids if model.mesh.node_ids is not None else np.arange(len(model.mesh.points))
    words = [f"node {int(ids[i])} at ({', '.join(f'{c:.6g}' for c in p)})" for i, p in zip(idx, points[:5])]
    more = f" and {len(points) - 5} more" if len(points) > 5 else ""
    return "; ".join(words) + more


def _faces(model, pts, triples, axis, sectors, left, right, tol):
    """Indices (into ``pts``) of the left and right face locations."""
    if (left is None) != (right is None):
        raise ValueError("give both cyclic faces (left and right node groups) or neither (found by the sector angle)")
    if left is not None:
        out = []
        for name, group in (("left", left), ("right", right)):
            d, _ = cKDTree(_group_points(model, group)).query(pts)
            on = np.flatnonzero(d <= 1e-9 * max(1.0, float(np.abs(pts).max())))
            if on.size == 0:
                raise ValueError(f"the {name} cyclic face {group!r} holds no free node of the model")
            out.append(on)
        return out
    r, theta = sector_angles(pts, axis)
    if np.any(r <= tol):
        raise ValueError(f"free nodes lie on the engine axis (within tol = {tol:g}): "
                         f"{_name_nodes(model, pts[r <= tol])}; a cyclic sector needs them clamped or off the axis")
    lo, hi = theta.min(), theta.max()
    alpha = 2.0 * math.pi / sectors
    if abs((hi - lo) - alpha) * r.max() > tol * 10 + 1e-12:
        raise ValueError(f"the sector spans {math.degrees(hi - lo):.6g}° about the axis, but {sectors} sectors need "
                         f"{360.0 / sectors:.6g}°: wrong number of sectors or axis, or give the cyclic faces as node "
                         "groups (left, right)")
    return np.flatnonzero(r * np.abs(theta - lo) <= tol), np.flatnonzero(r * np.abs(theta - hi) <= tol)


def fe_sector(model: FEModel, sectors: int, axis: RotationAxis, *, left=None, right=None,
              tol: float | None = None) -> CyclicSector:
    """The cyclic sector of a clamped 3-D FE model of one sector.

    Parameters
    ----------
    model : FEModel
        The sector (clamped, e.g. at its hub: the cyclic problem of nodal diameters 0 and 1 is singular otherwise).
    sectors : int
        ``N``: the sector spans ``360°/N`` about ``axis``.
    axis : RotationAxis
        The engine axis.  The right face is the left face rotated by ``+360°/N`` (right-handed about the axis
        direction).
    left, right : str, int array or None
        The cyclic faces as node groups of the mesh (names or node indices); ``None`` (both): found by the sector
        angle — the nodes at its least and greatest angle about the axis (within ``tol``).
    tol : float or None
        Matching tolerance in the mesh file's length unit (``mesh.unit``, e.g. millimetres for a deck read with
        ``unit="mm"``; ``None``: ``1e-6`` × the sector's largest radius).  The mesh's points, the axis and the
        coordinates in messages are in metres, as everywhere in bladecase.

    Raises
    ------
    ValueError
        A 2-D model; faces not found; the sector's angle not ``360°/N``; a face node whose rotation meets no node
        of the other face (named with its coordinates); a face node with some but not all directions clamped.
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    if model.dim != 3:
        raise ValueError(f"a cyclic sector is a 3-D model, got a {model.dim}-D one")
    sectors = integer("sectors", sectors, 2)
    if not isinstance(axis, RotationAxis):
        raise ValueError(f"axis must be a RotationAxis (the engine axis), got {axis!r}")
    pts, triples = _locations(model)
    radius = float(sector_angles(pts, axis)[0].max())
    unit = model.mesh.unit if model.mesh.unit in LENGTH_UNITS else "m"
    if tol is None:
        tol = FACE_RTOL * radius
    else:
        given = float(tol) if isinstance(tol, (int, float, np.integer, np.floating)) else float("nan")
        if isinstance(tol, bool) or not (math.isfinite(given) and given > 0):
            raise ValueError(f"tol must be a finite length > 0 (in the mesh's unit, {unit}), got {tol!r}")
        tol = given * LENGTH_UNITS[unit]  # the points are in metres
    li, ri = _faces(model, pts, triples, axis, sectors, left, right, tol)
    for name, idx in (("left", li), ("right", ri)):
        partial = idx[(triples[idx] < 0).any(axis=1)]
        if partial.size:
            raise ValueError(f"{partial.size} node(s) of the {name} cyclic face have some but not all directions "
                             f"fixed: {_name_nodes(model, pts[partial])}; clamp all three or none")
    R = rotation_matrix(axis.direction, 2.0 * math.pi / sectors)
    moved = (pts[li] - axis.origin) @ R.T + axis.origin
    dist, j = cKDTree(pts[ri]).query(moved)
    bad = dist > tol
    if bad.any():
        raise ValueError(f"{int(bad.sum())} node(s) of the left cyclic face, rotated by 360°/{sectors} about the axis, "
                         f"meet no free node of the right face within tol = {tol / LENGTH_UNITS[unit]:g} {unit}: "
                         f"{_name_nodes(model, pts[li[bad]])}"
                         f" (nearest at {dist[bad].min():.3g}; right = left rotated by +360°/N about the axis "
                         "direction: swapped faces, a wrong axis, or a non-conforming mesh?)")
    if np.unique(j).size != li.size or li.size != ri.size:
        spare = np.setdiff1d(np.arange(ri.size), j)
        raise ValueError(f"the cyclic faces do not match one to one: {li.size} left and {ri.size} right nodes"
                         + (f"; right-face nodes met by no left node: {_name_nodes(model, pts[ri[spare]])}"
                            if spare.size else ""))
    L, Rt = triples[li], triples[ri[j]]
    link = sp.block_diag([sp.csr_array(R)] * li.size, format="csr")
    full = triples[(triples >= 0).all(axis=1)]
    tree = cKDTree(model.mesh.points)
    (dl, node_l), (dr, node_r) = tree.query(pts[li]), tree.query(pts[ri[j]])
    at_nodes = (dl <= 1e-9 * radius) & (dr <= 1e-9 * radius)  # not the edge dofs of P2 on first-order cells
    node_l, node_r = node_l[at_nodes], node_r[at_nodes]
    return CyclicSector(model.K, model.M, sectors, L.ravel(), Rt.ravel(), link, full, axis,
                        np.column_stack([node_l, node_r]))
