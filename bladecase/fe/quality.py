"""Geometric checks of mesh cells: signed measures, Jacobian determinants of quadratic cells, orientation."""

from __future__ import annotations

import numpy as np

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


def _check_orientation(points, body, btype, dim, source) -> np.ndarray:
    """Reject degenerate and inverted elements; return ``body`` (reoriented if all planar ones are clockwise)."""
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


# ----------------------------------------------------------------------------- writing

#: Abaqus element keywords written by :func:`save_mesh` (plane stress in 2-D).
