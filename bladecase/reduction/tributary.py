"""The share of a contact face or line each node carries: tributary areas (the boundary facets whose corners all
lie in the contact's nodes, each facet's measure shared by its corners) and, for a line of nodes along the tip,
tributary lengths. A casing stiffness per unit area is shared by these; a face-mean contact is weighted by them."""

from __future__ import annotations

import numpy as np

from ..fe import FEModel


def group_members(model: FEModel, group) -> tuple[np.ndarray, str]:
    """The mesh nodes of ``group`` (a group name, or 0-based node indices) and how messages name them."""
    if isinstance(group, str):
        return np.asarray(model.mesh.group(group)), f"group {group!r}"
    nodes = np.unique(np.asarray(group, dtype=np.int64).ravel())
    n = model.mesh.points.shape[0]
    if nodes.size == 0 or nodes[0] < 0 or nodes[-1] >= n:
        raise ValueError(f"face nodes must be mesh node indices 0..{n - 1}, got {np.asarray(group).tolist()[:8]!r}")
    return nodes, f"the {nodes.size} face nodes"


#: Boundary facets of each cell family (corner indices, cyclic order), grouped by their number of corners.
_FACETS = {
    "triangle": [((0, 1), (1, 2), (2, 0))],
    "quad": [((0, 1), (1, 2), (2, 3), (3, 0))],
    "tetra": [((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))],
    "hexahedron": [((0, 3, 7, 4), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7))],
    "wedge": [((0, 1, 2), (3, 4, 5)), ((0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5))],
}


def _facet_measure(P: np.ndarray, face: np.ndarray) -> np.ndarray:
    """Length (2 corners), area of a triangle (3) or of a planar quadrilateral (4, by its diagonals)."""
    if face.shape[1] == 2:
        return np.linalg.norm(P[face[:, 1]] - P[face[:, 0]], axis=1)
    if face.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(P[face[:, 1]] - P[face[:, 0]], P[face[:, 2]] - P[face[:, 0]]), axis=1)
    return 0.5 * np.linalg.norm(np.cross(P[face[:, 2]] - P[face[:, 0]], P[face[:, 3]] - P[face[:, 1]]), axis=1)


def area_weights(model: FEModel, group, nodes: np.ndarray) -> np.ndarray:
    """Tributary weights of ``nodes``: each boundary facet of the body cells whose corners all lie in ``group`` (a
    name or node indices) gives ``|f|/c`` to each of its ``c`` corners; divided by the face's total measure (see
    :meth:`Contact.face`). A set of nodes that holds no facet — a line of nodes along the tip, as a published
    benchmark lists them — is weighted by each node's tributary length along the line (:func:`tributary_lengths`),
    and the log says so."""
    try:
        share, total = _tributary(model, group)
    except ValueError:
        members = group_members(model, group)[0]
        if members.size < 2:
            raise
        from .. import log

        lengths = tributary_lengths(model.mesh.points[nodes])
        log.info("contact: the %d contact nodes hold no facet of the body (a line of nodes): each is weighted by its "
                 "tributary length along the line (%.4g to %.4g mm of %.4g mm)", len(nodes), lengths.min() * 1e3,
                 lengths.max() * 1e3, lengths.sum() * 1e3)
        return lengths / lengths.sum()
    return share[nodes] / total


def tributary_lengths(points) -> np.ndarray:
    """Each point's tributary length along the line through ``points`` (ordered along their first principal
    direction): half the distance to each neighbour — the ends take half a segment.

    >>> tributary_lengths([[0.0, 0, 0], [2.0, 0, 0], [1.0, 0, 0], [4.0, 0, 0]]).tolist()
    [0.5, 1.5, 1.0, 1.0]
    """
    P = np.asarray(points, dtype=float)
    if P.shape[0] < 2:
        return np.ones(P.shape[0])
    C = P - P.mean(axis=0)
    order = np.argsort(C @ np.linalg.svd(C, full_matrices=False)[2][0])
    seg = np.linalg.norm(np.diff(P[order], axis=0), axis=1)
    out = np.empty(P.shape[0])
    out[order] = 0.5 * (np.r_[0.0, seg] + np.r_[seg, 0.0])
    return out


def tributary_areas(model: FEModel, nodes) -> np.ndarray:
    """Each node's share of the boundary facets whose corners all lie in ``nodes`` (m²; in 2-D a length, times the
    model's thickness when it has one): what a casing stiffness per unit area gives each node.

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> (tributary_areas(model, np.flatnonzero(p[:, 0] == 0.1)) * 1e6).round(6).tolist()   # mm²: 5 mm × 2 mm
    [5.0, 10.0, 10.0, 10.0, 5.0]
    """
    nodes = np.asarray(nodes, dtype=int)
    share, _ = _tributary(model, nodes)
    thickness = getattr(model, "thickness", None) if model.dim == 2 else None
    return share[nodes] * (float(thickness) if thickness else 1.0)


def _tributary(model: FEModel, group) -> tuple[np.ndarray, float]:
    """``(share, total)``: every mesh node's tributary measure of the face ``group`` and the face's measure."""
    from ..fe.cells import KINDS

    mesh, dim = model.mesh, model.dim
    cells = mesh.cells[mesh.body_type]  # meshio order: the corner vertices first
    inside = np.zeros(mesh.points.shape[0], dtype=bool)
    inside[group_members(model, group)[0]] = True
    P = np.zeros((mesh.points.shape[0], 3))
    P[:, :dim] = mesh.points[:, :dim]
    share, total = np.zeros(mesh.points.shape[0]), 0.0
    for kind in _FACETS[KINDS[mesh.body_type].family]:
        facets = np.vstack([cells[:, list(f)] for f in kind])
        _, first, count = np.unique(np.sort(facets, axis=1), axis=0, return_index=True, return_counts=True)
        face = facets[first[count == 1]]
        face = face[inside[face].all(axis=1)]
        size = _facet_measure(P, face)
        np.add.at(share, face.ravel(), np.repeat(size / face.shape[1], face.shape[1]))
        total += size.sum()
    if total == 0:
        what = group_members(model, group)[1]
        raise ValueError(f"{what} {'holds' if what.startswith('group') else 'hold'} no boundary facet of the body "
                         "cells (a line of nodes, or scattered nodes): they have no area — give the casing's "
                         "stiffness as casing_stiffness (N/m, shared by the nodes' tributary lengths along the line), "
                         "not per unit area")
    return share, total
