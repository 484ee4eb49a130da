"""Second-order wedge (triangular prism) elements for scikit-fem, which has only the 6-node ``ElementWedge1``.

Both live on scikit-fem's reference prism ``RefWedge`` (triangle ``x, y ≥ 0, x + y ≤ 1`` × ``0 ≤ z ≤ 1``;
vertices 0–2 at ``z = 0``, 3–5 above them at ``z = 1``) and number their dofs as scikit-fem does: the six
vertices, then the nine edges of ``RefWedge.edges`` (``01, 12, 02`` below, ``34, 45, 35`` above, then the
vertical ``03, 14, 25``: their midpoints), then (18 nodes) the centres of the three quadrilateral faces
``RefWedge.facets[:3]`` (``0143, 1254, 0253``).  This is meshio's (VTK's) ``wedge15`` / ``wedge18`` order.

* :class:`ElementWedge2` — the 18-node Lagrange prism, P2 triangle × P2 line: ``T_k(x, y) · l_m(z)``.
* :class:`ElementWedgeS2` — the 15-node serendipity prism (no face nodes): the Lagrange functions with the
  face-centre values eliminated, ``N_i = L_i + Σ_f L_i^S(c_f) L_f`` where the serendipity values at a face centre
  are ``-1/4`` (the face's corners) and ``+1/2`` (its edges).  Its space contains P2 and ``P2(x, y) · P1(z)``.

Everything is closed form (values and gradients), no matrix is inverted.  scikit-fem numbers facet dofs
uniformly over all five facets (its wedge facets include the two triangles), so the face dofs of
:class:`ElementWedge2` need the dof numbering :class:`WedgeFaceDofs` (``CellBasis(mesh, ElementWedge2(),
dofs=WedgeFaceDofs(mesh))``); :class:`ElementWedgeS2` uses scikit-fem's own.  Integrate with a triangle × line
rule (scikit-fem 12.0's wedge quadrature is wrong, see :func:`bladecase.fe.assembly.assemble`): the functions
have degree 2 in ``(x, y)`` and 2 in ``z``.

>>> import numpy as np
>>> X = np.array([[0.2], [0.3], [0.6]])
>>> round(float(sum(ElementWedge2().lbasis(X, i)[0][0] for i in range(18))), 12)
1.0
>>> [round(float(v), 12) for v in ElementWedgeS2().lbasis(ElementWedgeS2.doflocs[7][:, None], 7)[0]]
[1.0]
"""

from __future__ import annotations

import numpy as np
from skfem.assembly import Dofs
from skfem.element import ElementH1
from skfem.mesh import MeshWedge1
from skfem.refdom import RefWedge

__all__ = ["ElementWedge2", "ElementWedgeS2", "WedgeFaceDofs"]

#: Barycentric coordinates of the triangle and their (constant) gradients in (x, y).
_GRAD_L = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
#: Triangle P2 functions: a vertex ``(k,)`` or an edge ``(a, b)``.
_TRI = ((0,), (1,), (2,), (0, 1), (1, 2), (0, 2))
#: The 18 Lagrange functions as (triangle function, line function): line 0 at z = 0, 1 at z = 1/2, 2 at z = 1.
_PRODUCT = (
    (0, 0), (1, 0), (2, 0), (0, 2), (1, 2), (2, 2),  # vertices
    (3, 0), (4, 0), (5, 0), (3, 2), (4, 2), (5, 2),  # edges 01, 12, 02 (z = 0), 34, 45, 35 (z = 1)
    (0, 1), (1, 1), (2, 1),  # vertical edges 03, 14, 25
    (3, 1), (4, 1), (5, 1),  # quadrilateral faces 0143, 1254, 0253
)
_DOFLOCS = np.array([
    [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1],
    [.5, 0, 0], [.5, .5, 0], [0, .5, 0], [.5, 0, 1], [.5, .5, 1], [0, .5, 1],
    [0, 0, .5], [1, 0, .5], [0, 1, .5],
    [.5, 0, .5], [.5, .5, .5], [0, .5, .5],
])


def _serendipity_weights() -> np.ndarray:
    """``W[i, f]``: value of serendipity function ``i`` (15) at the centre of quadrilateral face ``f`` (3):
    ``-1/4`` at the face's four corners, ``+1/2`` at its four edge midpoints, 0 elsewhere."""
    W = np.zeros((15, 3))
    for f, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):
        W[[a, b, a + 3, b + 3], f] = -0.25
        W[[6 + f, 9 + f, 12 + a, 12 + b], f] = 0.5
    return W


_SERENDIPITY = _serendipity_weights()


def _triangle(X: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """P2 triangle function ``k`` of :data:`_TRI` and its gradient (2, ...) at ``X[:2]``."""
    L = (1.0 - X[0] - X[1], X[0], X[1])
    ent = _TRI[k]
    if len(ent) == 1:
        a = ent[0]
        return L[a] * (2.0 * L[a] - 1.0), np.multiply.outer(_GRAD_L[a], 4.0 * L[a] - 1.0)
    a, b = ent
    return 4.0 * L[a] * L[b], 4.0 * (np.multiply.outer(_GRAD_L[a], L[b]) + np.multiply.outer(_GRAD_L[b], L[a]))


def _line(z: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """P2 Lagrange function ``m`` on [0, 1] (nodes 0, 1/2, 1 for m = 0, 1, 2) and its derivative."""
    if m == 0:
        return (1.0 - z) * (1.0 - 2.0 * z), 4.0 * z - 3.0
    if m == 1:
        return 4.0 * z * (1.0 - z), 4.0 - 8.0 * z
    return z * (2.0 * z - 1.0), 4.0 * z - 1.0


def _lagrange(X: np.ndarray, i: int) -> tuple[np.ndarray, np.ndarray]:
    """18-node Lagrange function ``i`` and its gradient (3, ...)."""
    t, m = _PRODUCT[i]
    T, dT = _triangle(X, t)
    ell, dell = _line(X[2], m)
    return T * ell, np.concatenate([dT * ell, (T * dell)[None]])


class ElementWedge2(ElementH1):
    """The 18-node Lagrange prism (P2 triangle × P2 line): vertices, edge midpoints, quadrilateral-face centres.

    Its face dofs sit on the three quadrilateral faces only: build bases with ``dofs=WedgeFaceDofs(mesh)``
    (scikit-fem's default numbering would add dofs on the triangular faces, which this element has not).
    """

    nodal_dofs = 1
    edge_dofs = 1
    facet_dofs = 1
    maxdeg = 4
    dofnames = ["u", "u", "u"]
    doflocs = _DOFLOCS
    refdom = RefWedge

    def lbasis(self, X, i):
        if not 0 <= i < 18:
            raise ValueError(f"ElementWedge2 has 18 basis functions, got index {i}: build the basis with "
                             "dofs=WedgeFaceDofs(mesh) (face dofs on the quadrilateral faces only)")
        return _lagrange(X, i)


class ElementWedgeS2(ElementH1):
    """The 15-node serendipity prism: vertices and edge midpoints (scikit-fem's own dof numbering)."""

    nodal_dofs = 1
    edge_dofs = 1
    maxdeg = 4
    dofnames = ["u", "u"]
    doflocs = _DOFLOCS[:15]
    refdom = RefWedge

    def lbasis(self, X, i):
        if not 0 <= i < 15:
            self._index_error()
        phi, dphi = _lagrange(X, i)
        for f in np.flatnonzero(_SERENDIPITY[i]):
            face, dface = _lagrange(X, 15 + f)
            phi = phi + _SERENDIPITY[i, f] * face
            dphi = dphi + _SERENDIPITY[i, f] * dface
        return phi, dphi


class WedgeFaceDofs(Dofs):
    """scikit-fem's dof numbering for :class:`ElementWedge2`: one dof per vertex, per edge and per
    quadrilateral facet (none on the triangles), in that order.

    ``facet_dofs[0, k]`` is the dof of facet ``facet_index[k]`` of the mesh (``mesh.facets``); local dofs of a
    cell: ``t`` (6), ``t2e`` (9), the quadrilateral facets ``t2f[:3]`` (3).

    >>> from skfem import CellBasis
    >>> m = MeshWedge1()  # a cube cut into two prisms: 8 vertices, 14 edges, 5 of 9 facets quadrilateral
    >>> basis = CellBasis(m, ElementWedge2(), dofs=WedgeFaceDofs(m))
    >>> basis.N, basis.element_dofs.shape, WedgeFaceDofs(m).facet_index.size
    (27, (18, 2), 5)
    """

    def __init__(self, topo: MeshWedge1, element: ElementWedge2 | None = None, offset: int = 0):
        self.topo = topo
        self.element = element if element is not None else ElementWedge2()
        nv, ne = topo.nvertices, topo.nedges
        quad_of_cell = topo.t2f[:3]
        self.facet_index = np.unique(quad_of_cell)
        number = np.full(topo.nfacets, -1, dtype=np.int64)
        number[self.facet_index] = np.arange(self.facet_index.size)
        self.nodal_dofs = (offset + np.arange(nv, dtype=np.int32))[None]
        self.edge_dofs = (offset + nv + np.arange(ne, dtype=np.int32))[None]
        self.facet_dofs = (offset + nv + ne + np.arange(self.facet_index.size, dtype=np.int32))[None]
        self.interior_dofs = np.zeros((0, topo.nelements), dtype=np.int32)
        self.element_dofs = np.vstack([self.nodal_dofs[0][topo.t], self.edge_dofs[0][topo.t2e],
                                       self.facet_dofs[0][number[quad_of_cell]]]).astype(np.int32)
        self.N = int(self.element_dofs.max()) + 1
