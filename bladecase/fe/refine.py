"""A user's mesh refined by splitting its cells: every edge cut into ``n`` equal parts (in the cell's reference
coordinates), each cell into ``n^dim`` cells of its own type.

The new nodes are placed by the cell's own isoparametric map ``x(ξ) = Σ_a x_a N_a(ξ)`` (the element the assembly
maps it with, :func:`bladecase.fe.isoparametric.element`): a curved second-order cell (``tetra10``,
``hexahedron20``, …) gives curved sub-cells on the same curved surface, not cells on straight chords; a straight
cell gives straight sub-cells that fill it exactly. Hexahedra, quadrilaterals and the layers of a wedge are cut on
their reference grid, simplices (and a wedge's triangle) by the Freudenthal–Kuhn subdivision of the reference
simplex. The original nodes keep their coordinates and numbers, first (a second-order cell's midside, face-centre and
centre nodes included: they are nodes of its sub-cells for every ``n``); the new nodes are numbered after them.

A new node shared by cells — on an edge or face of the original mesh — is made once: it is identified by the
original corners of the smallest edge or face it lies on and its weights on them (exact rationals), so neighbours
agree whatever their orientation. Named node groups follow the refinement: a new node belongs to a group when
every corner of the edge, face or cell it was made on is in the group and, for an edge or face, that edge or face
lies on the body's surface within a face of the group, or inside a cell of the group (a group without any face or
cell — a line of nodes — takes the new nodes on its edges).

>>> import numpy as np
>>> from bladecase.fe import Mesh
>>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> tet = Mesh(p, {"tetra": np.array([[0, 1, 2, 3]])}, dim=3, groups={"base": np.array([0, 1, 2])}, source="tet")
>>> fine = refine_mesh(tet, 2)
>>> len(fine.points), len(fine.cells["tetra"]), fine.groups["base"].tolist()   # the base face: 3 + 3 midpoints
(10, 8, [0, 1, 2, 4, 5, 7])
>>> splits_for(0.5), splits_for(0.33), splits_for(0.7)
(2, 3, 1)
"""

from __future__ import annotations

import dataclasses
import itertools
from functools import cache

import numpy as np

from .cells import EDGES, KINDS, element_name
from .isoparametric import element
from .mesh import Mesh

__all__ = ["refine_mesh", "splits_for"]

#: Most edge splits (each cell becomes ``n^dim`` cells).
MAX_SPLITS = 6

#: The facets (faces in 3-D, edges in 2-D) of each family, corner indices (meshio order).
FACETS = {
    "tetra": ((0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)),
    "hexahedron": ((0, 3, 7, 4), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7)),
    "wedge": ((0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)),
    "triangle": EDGES["triangle"],
    "quad": EDGES["quad"],
}


def splits_for(factor: float) -> int:
    """The number of parts each edge is split into for an element-size ``factor``: the nearest ``n`` with size
    ratio ``1/n`` (``0.5`` → 2: each edge halved; ``0.33`` → 3; ``0.7`` → 1, the mesh itself).

    >>> [splits_for(f) for f in (1, 0.7, 0.5, 0.4, 0.25)]
    [1, 1, 2, 2, 4]
    """
    if not 0 < factor <= 1:
        raise ValueError(f"element-size factor must be in (0, 1], got {factor!r}")
    return max(1, int(round(1.0 / factor)))


# ----------------------------------------------------------------------------- the reference sub-cells

def _reference_corners(name: str) -> np.ndarray:
    """Reference coordinates of the corners (meshio order) of the linear element of family ``name``."""
    kind = KINDS[name]
    lin = element(element_name(kind.family, 1))
    loc = np.asarray(lin.doflocs, dtype=float)
    out = np.empty((kind.corners, kind.dim))
    out[list(kind.skfem_corners)] = loc
    return out


def _kuhn(d: int, n: int) -> np.ndarray:
    """The ``n^d`` simplices of the Freudenthal–Kuhn subdivision of ``{n >= y1 >= … >= yd >= 0}``: ``(S, d+1, d)``
    vertices, integers."""
    out = []
    for z in itertools.product(range(n), repeat=d):
        for perm in itertools.permutations(range(d)):
            v = [np.array(z, dtype=float)]
            for axis in perm:
                v.append(v[-1] + np.eye(d)[axis])
            c = np.mean(v, axis=0)
            if c[0] <= n and all(c[i] >= c[i + 1] for i in range(d - 1)) and c[-1] >= 0:
                out.append(v)
    return np.array(out)


def _simplices(R: np.ndarray, n: int) -> np.ndarray:
    """The simplex with corners ``R`` (d+1, d) cut into ``n^d``, each ordered with ``R``'s orientation."""
    d = R.shape[1]
    y = _kuhn(d, n) / n
    steps = np.diff(R, axis=0)  # R_j - R_{j-1}
    sub = R[0] + np.einsum("svj,ji->svi", y, steps)
    sign = np.sign(np.linalg.det(sub[:, 1:] - sub[:, :1]))
    flip = sign != np.sign(np.linalg.det(R[1:] - R[:1]))
    sub[flip, 1], sub[flip, 2] = sub[flip, 2].copy(), sub[flip, 1].copy()
    return sub


@cache
def _sub_cells(name: str, n: int) -> np.ndarray:
    """Reference coordinates of the nodes (meshio order) of the ``n^dim`` sub-cells of a ``name`` cell:
    ``(S, nodes, dim)``."""
    kind = KINDS[name]
    R = _reference_corners(name)
    if kind.family in ("tetra", "triangle"):
        corners = _simplices(R, n)
    elif kind.family in ("hexahedron", "quad"):  # reference cell [0, 1]^dim: the grid
        offsets = np.array(list(itertools.product(range(n), repeat=kind.dim)), dtype=float)
        corners = (R[None] + offsets[:, None]) / n
    else:  # wedge: the triangle's subdivision × n layers
        tri = _simplices(R[:3, :2], n)
        layers = []
        for k in range(n):
            lo = np.concatenate([tri, np.full(tri.shape[:2] + (1,), k / n)], axis=2)
            hi = np.concatenate([tri, np.full(tri.shape[:2] + (1,), (k + 1) / n)], axis=2)
            layers.append(np.concatenate([lo, hi], axis=1))
        corners = np.concatenate(layers)
    nodes = [corners[:, list(p)].mean(axis=1) for p in kind.parents]
    return np.stack(nodes, axis=1)


def _basis(name: str, order: int, X: np.ndarray) -> np.ndarray:
    """Values ``(Q, nodes)`` at reference points ``X (Q, dim)`` of the shape functions of ``name``'s element of
    ``order`` (1: the corner functions), nodes in meshio order."""
    kind = KINDS[name]
    elem = element(element_name(name if order == kind.order else kind.family, order))
    parents = kind.parents if order == kind.order else kind.parents[:kind.corners]
    R = _reference_corners(name)
    loc = np.asarray(elem.doflocs, dtype=float)
    where = [int(np.argmin(np.abs(loc - R[list(p)].mean(axis=0)).sum(axis=1))) for p in parents]
    return np.stack([elem.lbasis(X.T.copy(), a)[0] for a in where], axis=1)


# ----------------------------------------------------------------------------- the refined mesh

def refine_mesh(mesh: Mesh, n: int) -> Mesh:
    """``mesh`` with every body cell split into ``n^dim`` cells of its type, every edge in ``n`` (module docstring);
    its named groups carried to the new nodes; boundary cells dropped. ``n = 1`` returns ``mesh``.

    >>> import numpy as np
    >>> from bladecase.fe import Mesh
    >>> sq = Mesh(np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]]), {"quad": np.array([[0, 1, 2, 3]])}, dim=2,
    ...           groups={"left": np.array([0, 3])}, source="square")
    >>> fine = refine_mesh(sq, 3)
    >>> len(fine.points), len(fine.cells["quad"]), sorted(fine.points[fine.groups["left"], 1].round(3).tolist())
    (16, 9, [0.0, 0.333, 0.667, 1.0])
    >>> refine_mesh(sq, 0)
    Traceback (most recent call last):
        ...
    ValueError: refine_mesh: n (parts per edge) must be an integer from 1 to 6, got 0
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_SPLITS:
        raise ValueError(f"refine_mesh: n (parts per edge) must be an integer from 1 to {MAX_SPLITS}, got {n!r}")
    name = mesh.body_type
    if name not in KINDS:
        raise ValueError(f"refine_mesh: {name} cells cannot be split (supported: {', '.join(KINDS)})")
    if n == 1:
        return mesh
    kind = KINDS[name]
    cells = np.asarray(mesh.cells[name], dtype=np.int64)
    sub = _sub_cells(name, n)  # (S, A, dim)
    U, local = np.unique(sub.reshape(-1, kind.dim).round(12), axis=0, return_inverse=True)
    local = local.reshape(sub.shape[:2])
    W = _basis(name, 1, U)  # corner weights (Q, corners)
    scale = float((2 * n) ** kind.dim)
    Wi = np.rint(W * scale).astype(np.int64)
    assert np.abs(W * scale - Wi).max() < 1e-6, "reference points off the refinement lattice"
    nodemap, new_points, keys = _number_nodes(mesh, kind, cells, U, Wi)
    points = np.concatenate([np.asarray(mesh.points, dtype=float), new_points])
    refined = nodemap[:, local].reshape(-1, kind.n_nodes)
    groups = _groups(mesh, kind, cells, Wi, nodemap, keys, len(points))
    return _compact(mesh, name, points, refined, groups, n)


def _number_nodes(mesh: Mesh, kind, cells: np.ndarray, U: np.ndarray, Wi: np.ndarray):
    """The node of every reference point ``U`` of every cell: ``(C, Q)`` indices (the original node where it is one,
    else a new node numbered from ``len(mesh.points)``), the new nodes' coordinates and, per new node, the first
    cell and point it was made at."""
    C, Q = len(cells), len(U)
    nz = Wi > 0
    count = nz.sum(axis=1)
    nodemap = np.full((C, Q), -1, dtype=np.int64)
    # an original node: equal weights on exactly the corners of one of the kind's parents
    for k, p in enumerate(kind.parents):
        pattern = np.zeros(kind.corners, dtype=bool)
        pattern[list(p)] = True
        hit = (nz == pattern).all(axis=1) & (Wi[:, list(p)] == Wi[:, [p[0]]]).all(axis=1)
        nodemap[:, hit] = cells[:, [k]]
    todo = np.flatnonzero(nodemap[0] < 0)
    interior = todo[count[todo] == kind.corners]
    shared = todo[count[todo] < kind.corners]
    start = len(mesh.points)
    # nodes inside a cell: one per (cell, point)
    nodemap[:, interior] = start + np.arange(C * len(interior)).reshape(C, len(interior))
    first = [np.repeat(np.arange(C), len(interior)), np.tile(interior, C)]
    start += C * len(interior)
    # nodes on an original edge or face: keyed by its corners (sorted) and their weights, one table per corner count
    for k in np.unique(count[shared]):
        qs = shared[count[shared] == k]
        corners = np.array([np.flatnonzero(nz[q]) for q in qs])  # (nq, k)
        ids = cells[:, corners].astype(np.int32)  # (C, nq, k)
        order = np.argsort(ids, axis=2)
        w = np.take_along_axis(np.broadcast_to(Wi[qs[:, None], corners].astype(np.int32), ids.shape), order, axis=2)
        rows = np.concatenate([np.take_along_axis(ids, order, axis=2), w[..., :-1]], axis=2).reshape(C * qs.size, -1)
        _, index, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        nodemap[:, qs] = start + inverse.reshape(C, qs.size)
        first = [np.concatenate([first[0], index // qs.size]), np.concatenate([first[1], qs[index % qs.size]])]
        start += index.size
    first_cell, first_point = first
    phi = _basis(kind.name, kind.order, U)  # (Q, A)
    x = np.asarray(mesh.points, dtype=float)[cells[first_cell]]  # (N, A, 3)
    new_points = np.einsum("na,nai->ni", phi[first_point], x)
    return nodemap, new_points, (first_cell, first_point)


def _groups(mesh: Mesh, kind, cells: np.ndarray, Wi: np.ndarray, nodemap: np.ndarray, keys, n_points: int
            ) -> dict:
    """Every named group of ``mesh`` with the new nodes that belong to it (module docstring)."""
    facets = FACETS[kind.family]
    width = max(len(f) for f in facets)
    rows = np.full((len(cells), len(facets), width), -1, dtype=np.int64)
    for j, f in enumerate(facets):
        rows[:, j, :len(f)] = np.sort(cells[:, list(f)], axis=1)
    flat = rows.reshape(-1, width)
    _, inverse, counts = np.unique(flat, axis=0, return_inverse=True, return_counts=True)
    boundary = (counts[inverse] == 1).reshape(len(cells), len(facets))  # (C, F)
    nz = Wi > 0  # (Q, corners)
    inside = np.array([[not nz[q, [c for c in range(kind.corners) if c not in f]].any() for f in facets]
                       for q in range(len(Wi))])  # (Q, F): point q lies on facet f
    corners = cells[:, :kind.corners]
    start = len(mesh.points)
    out = {}
    for name, nodes in mesh.groups.items():
        member = np.zeros(n_points, dtype=bool)
        member[np.asarray(nodes, dtype=np.int64)] = True
        in_corner = member[corners]  # (C, corners)
        whole_cell = in_corner.all(axis=1)
        whole_facet = boundary & np.stack([in_corner[:, list(f)].all(axis=1) for f in facets], axis=1)
        has_area = bool(whole_cell.any() or whole_facet.any())
        # each (cell, point): every corner of its entity in the group, and the entity on a group facet or cell
        every = ((~in_corner).astype(np.int32) @ nz.T.astype(np.int32)) == 0  # (C, Q)
        on_facet = (whole_facet.astype(np.int32) @ inside.T.astype(np.int32)) > 0  # (C, Q)
        ok = every & (on_facet | whole_cell[:, None]) if has_area else every
        new = nodemap >= start
        member[nodemap[ok & new]] = True
        out[name] = np.flatnonzero(member)
    return out


def _compact(mesh: Mesh, name: str, points: np.ndarray, cells: np.ndarray, groups: dict, n: int) -> Mesh:
    """The refined mesh without any original node no cell uses (one the input's cells did not use either)."""
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    renumber = np.cumsum(used) - 1
    old = len(mesh.points)
    ids = np.concatenate([mesh.node_ids, mesh.node_ids.max(initial=-1) + 1 + np.arange(len(points) - old)])
    keep = {g: renumber[v[used[v]]] for g, v in groups.items()}
    return dataclasses.replace(mesh, points=points[used], cells={name: renumber[cells]}, groups=keep,
                               node_ids=ids[used], source=f"{mesh.source} (each edge split in {n})")
