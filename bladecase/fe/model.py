"""A clamped finite-element model and its dof map (:class:`FEModel`, :class:`DofMap`), as :func:`assemble` makes it.

Degree-of-freedom numbering: the scalar dofs of skfem's basis, each carrying
``dim`` displacement components, component ``c`` of scalar dof ``s`` being
unclamped dof ``dim * s + c``.  A :class:`DofMap` says for each free dof its
location (on a second-order mesh at order 2, the edge, face and cell dofs are at the mesh's own midside,
face-centre and centre nodes: the cells are curved through them), its direction and its mesh node (``-1``
for the edge dofs of quadratic elements); :func:`node_operator` maps free-dof vectors to per-node
displacements.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .cells import KINDS
from .material import Material
from .mesh import Mesh

#: Accepted values of ``mass`` (:func:`bladecase.fe.assemble`).
MASS_KINDS = ("consistent", "lumped")
#: Accepted values of ``order``.
ORDERS = (1, 2)

_DIRECTIONS = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True, eq=False)
class DofMap:
    """Where each free degree of freedom of an :class:`FEModel` lives.

    Attributes
    ----------
    node : (n,) int ndarray
        Mesh node (index into ``mesh.points``) of a vertex dof; ``-1`` for the
        other dofs of quadratic elements (edge, face and cell dofs; on a
        second-order mesh they sit at its midside, face-centre and centre
        nodes, see :func:`node_operator`).
    direction : (n,) int ndarray
        Displacement component: 0 = x, 1 = y, 2 = z.
    coords : (n, 3) float ndarray
        Location of the dof (``z = 0`` in 2-D).
    fe_index : (n,) int ndarray
        Index in the unclamped numbering (``dim * scalar dof + direction``).
    n_total : int
        Number of dofs before the clamped ones were removed.
    """

    node: np.ndarray
    direction: np.ndarray
    coords: np.ndarray
    fe_index: np.ndarray
    n_total: int

    def __len__(self) -> int:
        return self.node.size


@dataclass(frozen=True, eq=False)
class FEModel:
    """A clamped linear-elastic finite-element model (free dofs only).

    Attributes
    ----------
    K, M : scipy.sparse.csr_array
        Stiffness and mass matrices on the free dofs (``M`` diagonal if ``mass == "lumped"``).
    dofs : DofMap
        Location, direction and mesh node of each free dof.
    mesh : Mesh
        The mesh the model was built from.
    material : Material
    order : int
        Polynomial order of the elements (1 or 2).
    mass : str
        ``"consistent"`` or ``"lumped"`` (row sum for P1, HRZ for P2).
    thickness : float or None
        Out-of-plane thickness of a 2-D model (``None`` in 3-D).
    plane : str or None
        ``"stress"`` or ``"strain"`` for a 2-D model, ``None`` in 3-D.
    clamped : ndarray
        Mesh nodes whose displacements are fixed (sorted).
    volume : float
        Volume (3-D) or area (2-D) of the mesh.
    rigid_modes : int
        Rigid-body motions the clamp leaves free, summed over the
        face-connected parts of the mesh (0 for a properly clamped model; 6
        in 3-D, 3 in 2-D for an unclamped one-piece body).
    """

    K: sp.csr_array
    M: sp.csr_array
    dofs: DofMap
    mesh: Mesh
    material: Material
    order: int
    mass: str
    thickness: float | None
    plane: str | None
    clamped: np.ndarray
    volume: float
    rigid_modes: int

    def __post_init__(self):
        if self.K.shape[0] == 0:
            n = len(self.mesh.points)
            raise ValueError(f"the clamp fixes {self.clamped.size} of the mesh's {n} nodes: no degree of freedom "
                             "is left free; clamp a face (e.g. the root), not the whole body")
        n = self.K.shape[0]
        if self.K.shape != (n, n) or getattr(self.M, "shape", None) != (n, n):
            raise ValueError(f"FE model of mesh {self.mesh.source or ''}: K ({self.K.shape}) and M "
                             f"({getattr(self.M, 'shape', None)}) must be square matrices of the same size")
        sizes = {name: len(getattr(self.dofs, name)) for name in ("node", "direction", "coords", "fe_index")}
        if set(sizes.values()) != {n}:
            raise ValueError(f"FE model of mesh {self.mesh.source or ''}: its dof map has "
                             f"{', '.join(f'{v} {k}' for k, v in sizes.items())} entries for {n} dofs")
        n_nodes = len(self.mesh.points)
        clamped = np.asarray(self.clamped)
        if clamped.size and (clamped.min() < 0 or clamped.max() >= n_nodes):
            raise ValueError(f"FE model of mesh {self.mesh.source or ''}: clamped nodes outside 0..{n_nodes - 1}")

    @property
    def dim(self) -> int:
        """Spatial dimension (2 or 3)."""
        return self.mesh.dim

    @property
    def n_dofs(self) -> int:
        """Number of free degrees of freedom."""
        return self.K.shape[0]

    @property
    def total_mass(self) -> float:
        """``ρ · volume`` in 3-D, ``ρ · area · thickness`` in 2-D (kg)."""
        return self.material.rho * self.volume * (self.thickness if self.thickness is not None else 1.0)

    @cached_property
    def _node_dof(self) -> np.ndarray:
        table = np.full((self.mesh.points.shape[0], self.dim), -1, dtype=np.int64)
        vertex = self.dofs.node >= 0
        table[self.dofs.node[vertex], self.dofs.direction[vertex]] = np.flatnonzero(vertex)
        return table

    def dof_of(self, node, direction) -> int | np.ndarray:
        """Free dof index of mesh ``node`` in ``direction`` (0/1/2 or ``"x"``/``"y"``/``"z"``).

        ``node`` and ``direction`` may be arrays (broadcast together).

        Raises
        ------
        ValueError
            A node out of range, clamped, or not a vertex of the body cells; a bad direction.
        """
        n_nodes = self.mesh.points.shape[0]
        nodes = np.asarray(node)
        if nodes.dtype.kind not in "iu":
            raise ValueError(f"node must be an integer mesh node index, got {node!r}")
        if nodes.size and (nodes.min() < 0 or nodes.max() >= n_nodes):
            bad = nodes[(nodes < 0) | (nodes >= n_nodes)].ravel()[0]
            raise ValueError(f"node {bad} is out of range (mesh nodes 0..{n_nodes - 1})")
        dirs = np.vectorize(lambda d: _direction(d, self.dim), otypes=[np.int64])(direction)
        out = self._node_dof[nodes, dirs]
        if np.any(out < 0):
            bad = np.broadcast_to(nodes, out.shape)[out < 0].ravel()[0]
            why = "is clamped" if np.isin(bad, self.clamped) else "is not a vertex of the body cells"
            raise ValueError(f"node {bad} has no free dof: it {why}")
        return int(out) if out.ndim == 0 else out

    def __repr__(self) -> str:
        from .select import held_nodes

        extra = f", thickness={self.thickness:g}, plane {self.plane}" if self.dim == 2 else ""
        held = held_nodes(self.mesh, self.clamped).size  # midside nodes of clamped edges included, as in a deck
        return (
            f"FEModel({self.dim}-D, P{self.order}, {self.n_dofs} free dofs, {self.mass} mass, "
            f"{self.material.name or 'material'}{extra}, {held} clamped nodes)"
        )


def _direction(d, dim: int) -> int:
    if isinstance(d, str) and d.lower() in _DIRECTIONS:
        d = _DIRECTIONS[d.lower()]
    if isinstance(d, (bool, np.bool_)) or not isinstance(d, (int, np.integer)) or not 0 <= d < dim:
        valid = "0, 1, 2 or 'x', 'y', 'z'" if dim == 3 else "0, 1 or 'x', 'y'"
        raise ValueError(f"direction must be {valid} in {dim}-D, got {d!r}")
    return int(d)


def node_operator(model: FEModel) -> sp.csr_array:
    """Sparse map from free-dof vectors to per-node displacements, flattened ``(n_nodes·dim, n_free)``.

    Row ``dim·p + c`` gives component ``c`` at mesh node ``p``: the vertex dof
    of ``p`` when it has one; for the midside nodes of quadratic mesh cells,
    the FE field there (order 2: the edge dof, located at the node itself, the
    cells being curved through it; order 1: the mean of the two end vertices,
    the value at the edge's middle), and likewise for the face and cell
    centres of 27-node hexahedra, 18-node wedges and 9-node quadrilaterals
    (the face or cell dof, or the mean of the corners); zero for clamped nodes
    and nodes outside the body cells.  (A stored model whose edge dofs sit at
    the straight edges' midpoints — built by a bladecase that did not curve
    second-order cells — is matched there.)
    """
    dofs, dim = model.dofs, model.dim
    n_nodes = model.mesh.points.shape[0]
    vertex = np.flatnonzero(dofs.node >= 0)
    rows = [dim * dofs.node[vertex] + dofs.direction[vertex]]
    cols = [vertex]
    vals = [np.ones(vertex.size)]
    kind = KINDS[model.mesh.body_type]
    cells = np.asarray(model.mesh.cells[model.mesh.body_type])
    edge = np.flatnonzero((dofs.node < 0) & (dofs.direction == 0))  # the dim dofs of a location: consecutive
    tree = cKDTree(dofs.coords[edge]) if model.order == 2 and edge.size else None
    table = np.full((n_nodes, dim), -1, dtype=np.int64)  # free dof of (node, direction), -1 if none
    table[dofs.node[vertex], dofs.direction[vertex]] = vertex
    for mids, parents in _extra_nodes(kind, cells):  # the extra nodes of quadratic mesh cells
        if model.order == 2:  # the FE node there (an edge, face or cell dof), where the node is
            if tree is None:
                continue
            tol = 1e-9 * np.abs(model.mesh.points).max()
            dist, k = tree.query(model.mesh.points[mids])
            ok = dist <= tol  # else: a clamped edge, or a model whose dofs sit at the straight centres
            if not ok.all():
                dist2, k2 = tree.query(model.mesh.points[parents].mean(axis=1))
                k = np.where(ok, k, k2)
                ok |= dist2 <= tol
            for c in range(dim):
                rows.append(dim * mids[ok] + c)
                cols.append(edge[k[ok]] + c)
                vals.append(np.ones(int(ok.sum())))
        else:  # order 1: the mean of the corners (the bilinear/trilinear field at the centre)
            for end in range(parents.shape[1]):
                for c in range(dim):
                    d = table[parents[:, end], c]
                    ok = d >= 0
                    rows.append(dim * mids[ok] + c)
                    cols.append(d[ok])
                    vals.append(np.full(int(ok.sum()), 1.0 / parents.shape[1]))
    return sp.csr_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_nodes * dim, model.n_dofs),
    )


def _extra_nodes(kind, cells: np.ndarray):
    """``(nodes, parents)`` per count of parents (2: edge midpoints, 4: face centres, 8: cell centres): the mesh
    nodes beyond the corners (each once) and the corner nodes they sit between."""
    extra = range(kind.corners, kind.n_nodes)
    for size in sorted({len(kind.parents[j]) for j in extra}):
        idx = [j for j in extra if len(kind.parents[j]) == size]
        mids = cells[:, idx].reshape(-1)
        parents = np.stack([cells[:, list(kind.parents[j])] for j in idx], axis=1).reshape(-1, size)
        mids, first = np.unique(mids, return_index=True)
        yield mids, parents[first]
