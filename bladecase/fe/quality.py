"""Geometric checks of mesh cells: signed measures, Jacobian determinants of quadratic cells, orientation."""

from __future__ import annotations

import numpy as np

from .cells import CORNER_FRAMES, KINDS

#: Element whose ``|volume|`` (area in 2-D) is at most ``DEGENERATE_RTOL`` times the
#: mean ``|volume|`` of the mesh is degenerate.
DEGENERATE_RTOL = 1e-12


def signed_measures(points: np.ndarray, cells: np.ndarray, dim: int) -> np.ndarray:
    """Signed volumes (3-D) or signed ``xy`` areas (2-D) of the straight simplices through the corner nodes.

    Positive for the gmsh/meshio orientation (counter-clockwise triangles seen
    from ``+z``; tetrahedra with ``(p1-p0)×(p2-p0)·(p3-p0) > 0``).
    """
    p = points[cells[:, : dim + 1]]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    if dim == 3:
        return np.einsum("ij,ij->i", np.cross(a, b), p[:, 3] - p[:, 0]) / 6.0
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


#: Edges of the midside nodes of order-2 simplices (meshio/VTK ordering).
_P2_EDGES = {2: [(0, 1), (1, 2), (0, 2)], 3: [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]}


def jacobian_dets(points: np.ndarray, cells: np.ndarray, dim: int, bary: np.ndarray) -> np.ndarray:
    """Jacobian determinants of order-1 or order-2 simplices at barycentric points.

    Parameters
    ----------
    points : (n, 3) ndarray
    cells : (m, dim+1) or (m, (dim+1)(dim+2)/2) int ndarray
        ``triangle``/``tetra`` or ``triangle6``/``tetra10`` connectivity.
    dim : {2, 3}
    bary : (q, dim+1) ndarray
        Barycentric coordinates of the evaluation points.

    Returns
    -------
    (m, q) ndarray
        ``det(∂x/∂ξ)`` (reference simplex ``ξ_i >= 0, Σξ_i <= 1``); in 2-D
        the ``xy`` determinant.
    """
    bary = np.atleast_2d(np.asarray(bary, dtype=float))
    dl = np.vstack([-np.ones(dim), np.eye(dim)])  # ∇λ_a in reference coordinates
    if cells.shape[1] == dim + 1:
        grads = np.broadcast_to(dl, (len(bary), dim + 1, dim))
    else:
        grads = np.empty((len(bary), cells.shape[1], dim))
        for a in range(dim + 1):
            grads[:, a] = (4 * bary[:, a] - 1)[:, None] * dl[a]
        for k, (a, b) in enumerate(_P2_EDGES[dim]):
            grads[:, dim + 1 + k] = 4 * (bary[:, b, None] * dl[a] + bary[:, a, None] * dl[b])
    x = points[cells][:, :, :dim]  # (m, nodes, dim)
    J = np.einsum("mai,qaj->mqij", x, grads)
    return np.linalg.det(J)


#: Node permutation that reverses a triangle's orientation (meshio ordering).
_FLIP = {"triangle": [0, 2, 1], "triangle6": [0, 2, 1, 5, 4, 3]}


def corner_jacobians(points: np.ndarray, cells: np.ndarray, cell_type: str, curved: bool = False) -> np.ndarray:
    """Jacobian determinants of cells at their corner nodes, in the cell's own corner frames.

    At corner ``a`` with neighbours ``b, c, d`` (:data:`~bladecase.fe.cells.CORNER_FRAMES`, right-handed for
    a positively oriented cell), the straight cell's Jacobian is ``det[x_b - x_a, x_c - x_a, x_d - x_a]``
    (the ``xy`` cross product in 2-D): the trilinear hexahedron's, the prism's and the bilinear
    quadrilateral's exactly, up to the reference cell's scale.  With ``curved=True`` each edge vector is the
    derivative of the quadratic edge through its midside node ``m``, ``4 x_m - 3 x_a - x_b`` (the edge's
    restriction of every second-order Lagrange or serendipity cell), so a midside node pulled past a corner
    shows as a negative value.

    Parameters
    ----------
    points : (n, 3) ndarray
    cells : (m, nodes) int ndarray
        Connectivity of ``cell_type`` in meshio order.
    cell_type : str
        A meshio type of :data:`~bladecase.fe.cells.KINDS`.
    curved : bool
        Use the midside nodes (second-order cells only).

    Returns
    -------
    (m, corners) ndarray

    Examples
    --------
    A unit cube (VTK order: the bottom face counter-clockwise seen from above, then the top face), and the
    same cube with its midside node of edge ``(0, 1)`` moved beyond corner 1:

    >>> cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.]])
    >>> corner_jacobians(cube, np.arange(8)[None], "hexahedron").tolist()
    [[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]]
    >>> from bladecase.fe.cells import KINDS
    >>> mids = np.array([(cube[a] + cube[b]) / 2 for a, b in KINDS["hexahedron20"].parents[8:]])
    >>> mids[0] = [1.5, 0, 0]
    >>> J = corner_jacobians(np.vstack([cube, mids]), np.arange(20)[None], "hexahedron20", curved=True)
    >>> np.round(J, 12).tolist()
    [[5.0, -3.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]]
    """
    kind = KINDS[cell_type]
    dim = kind.dim
    x = points[:, :dim][cells]  # (m, nodes, dim)
    frames = np.array(CORNER_FRAMES[kind.family])  # (corners, dim)
    a = np.arange(kind.corners)[:, None]
    edges = x[:, frames] - x[:, a]  # (m, corners, dim, dim): edge k from corner a, coordinates
    if curved and kind.order == 2:
        mid = np.array([[kind.edge_node[int(i), int(j)] for j in row] for i, row in enumerate(frames)])
        edges = 4 * x[:, mid] - 3 * x[:, a] - x[:, frames]
    return np.linalg.det(edges)


def _check_cells(points, body, btype, source) -> np.ndarray:
    """Non-simplex cells: reject degenerate, inverted, twisted elements (Jacobians at the corners); return
    ``body``, reoriented when every cell of a quadrilateral or wedge mesh is reversed (the other usual node
    order for these; an all-reversed hexahedron mesh is an error, as for tetrahedra)."""
    kind = KINDS[btype]
    J = corner_jacobians(points, body, btype)
    typical = float(np.mean(np.abs(J)))
    degenerate = np.abs(J).max(axis=1) <= DEGENERATE_RTOL * typical
    _refuse(degenerate, f"degenerate {btype}", f"(all corner Jacobians <= {DEGENERATE_RTOL:g} x mean "
            f"{typical:.3g})", body, J, source)
    if kind.family in ("quad", "wedge") and (J < 0).all():
        body = body[:, list(kind.flip)]
        J = corner_jacobians(points, body, btype)
    inverted = (J < 0).all(axis=1)
    hint = " (all of them: the file may use the opposite node ordering)" if inverted.all() else ""
    _refuse(inverted, f"inverted {btype}", f"(negative Jacobian at every corner){hint}", body, J, source)
    _refuse((J <= 0).any(axis=1), f"twisted or collapsed {btype}", "(Jacobian <= 0 at some corners: a corner "
            "folded over or an edge collapsed)", body, J, source)
    if kind.order == 2:
        Jc = corner_jacobians(points, body, btype, curved=True)
        _refuse((Jc <= 0).any(axis=1), f"inverted curved {btype}", "(Jacobian <= 0 at a corner node: a midside "
                "node beyond its edge's ends)", body, Jc, source)
    return body


def _refuse(bad: np.ndarray, what: str, why: str, body, J, source) -> None:
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        shown = ", ".join(f"{d:.3g}" for d in J[i])
        raise ValueError(f"mesh {source} has {int(bad.sum())} {what} element(s) {why}; first: element {i}, "
                         f"nodes {body[i].tolist()}, corner Jacobians [{shown}]")


def _check_orientation(points, body, btype, dim, source) -> np.ndarray:
    """Reject degenerate and inverted elements; return ``body`` (reoriented if all planar ones are clockwise)."""
    if btype not in ("tetra", "tetra10", "triangle", "triangle6"):
        return _check_cells(points, body, btype, source)
    vol = signed_measures(points, body, dim)
    what = "volume" if dim == 3 else "area"
    typical = float(np.mean(np.abs(vol)))
    degenerate = np.abs(vol) <= DEGENERATE_RTOL * typical
    if degenerate.any():
        i = int(np.flatnonzero(degenerate)[0])
        raise ValueError(
            f"mesh {source} has {int(degenerate.sum())} degenerate {btype} element(s) "
            f"(|{what}| <= {DEGENERATE_RTOL:g} x mean {typical:.3g}); first: element {i}, "
            f"nodes {body[i].tolist()}, {what} {vol[i]:.3g}"
        )
    negative = vol < 0
    if dim == 2 and negative.all():
        body, negative = body[:, _FLIP[btype]], ~negative  # clockwise file: reorient every triangle
    if negative.any():
        i = int(np.flatnonzero(negative)[0])
        hint = " (all of them: the file may use the opposite node ordering)" if negative.all() else ""
        raise ValueError(
            f"mesh {source} has {int(negative.sum())} inverted {btype} element(s) (negative {what}){hint}; "
            f"first: element {i}, nodes {body[i].tolist()}, {what} {vol[i]:.3g}"
        )
    if body.shape[1] > dim + 1:  # curved elements: the Jacobian must stay positive at the corners
        dets = jacobian_dets(points, body, dim, np.eye(dim + 1))
        bad = (dets <= 0).any(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            shown = ", ".join(f"{d:.3g}" for d in dets[i])
            raise ValueError(
                f"mesh {source} has {int(bad.sum())} inverted curved {btype} element(s) (Jacobian <= 0 at a "
                f"corner node); first: element {i}, nodes {body[i].tolist()}, corner Jacobians [{shown}]"
            )
    return body

