"""Curved (isoparametric) geometry of second-order cells: the map of each cell through all its nodes.

A second-order mesh cell (``tetra10``, ``hexahedron20``/``27``, ``wedge15``/``18``, ``triangle6``,
``quad8``/``9``) is the image of the reference cell under the map ``x(ξ) = Σ_a x_a N_a(ξ)`` of its own
quadratic element (``ElementTetP2``, ``ElementHexS2``/``ElementHex2``, ``ElementWedgeS2``/``ElementWedge2``,
``ElementTriP2``, ``ElementQuadS2``/``ElementQuad2``), the ``x_a`` being its corner, midside, face-centre and
centre nodes where the mesh puts them (on the curved surface, for a mesher's second-order mesh).
:class:`CurvedGeometry` holds these coordinates in that element's scikit-fem dof numbering on the mesh of the
corners (``doflocs``, ``dofs.element_dofs``: what ``skfem.MappingIsoparametric`` reads); :class:`MappingCurved`
is that mapping with the Jacobians of all cells at all quadrature points computed in one product over the cells
and kept for every basis function.

:func:`bladecase.fe.assemble` uses it at order 2 (the field's element is the geometry's: isoparametric cells,
which hold the linear fields and the rigid motions exactly).  When the extra nodes sit at the centres of their
straight edges and faces the map is the cell's linear, bilinear, trilinear or prismatic one and the matrices are
those of straight cells, to round-off.  At order 1 the cells stay straight through their corners: a quadratic
map under a linear field (superparametric cells) no longer holds the rigid rotations — on a free ring of 32 × 2
curved triangle6 its rotation has a frequency of 87 Hz, above the ring's first flexural mode (69 Hz).

Two triangle6 through the unit half circle: their area is the half disc's but for the two parabolic segments'
deficit, ``1 + (4/3)(1 − 1/√2)√2 = 1.5523`` (π/2 = 1.5708; the straight triangles: 1):

>>> import numpy as np, skfem
>>> from bladecase.fe import Mesh
>>> s = 2 ** -0.5
>>> p = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, 0, 0], [s, s, 0], [-s, s, 0], [-.5, 0, 0], [.5, 0, 0],
...               [0, .5, 0]])
>>> half_disc = Mesh(p, {"triangle6": np.array([[0, 1, 3, 4, 8, 7], [1, 2, 3, 5, 6, 8]])}, dim=2)
>>> corners = skfem.MeshTri1(p[:4, :2].T.copy(), np.array([[0, 1, 3], [1, 2, 3]]).T.copy())
>>> mapping = MappingCurved(curved_geometry(half_disc, np.arange(4), corners))
>>> round(float(skfem.CellBasis(corners, skfem.ElementTriP2(), mapping=mapping).dx.sum()), 4)
1.5523
"""

from __future__ import annotations

import numpy as np
import skfem
from skfem.assembly import Dofs
from skfem.mapping import MappingIsoparametric

from . import wedge_element
from .cells import KINDS, element_name
from .mesh import Mesh

__all__ = ["CurvedGeometry", "MappingCurved", "boundary_element", "curved_geometry", "element", "folded_cells"]


def element(name: str) -> skfem.element.Element:
    """An instance of the element called ``name``: bladecase's wedges, else scikit-fem's.

    >>> type(element("ElementWedgeS2")).__module__, type(element("ElementTetP2")).__name__
    ('bladecase.fe.wedge_element', 'ElementTetP2')
    """
    return (getattr(wedge_element, name, None) or getattr(skfem, name))()


class CurvedGeometry:
    """The nodes of second-order cells in their quadratic element's scikit-fem numbering, on the mesh of the corners.

    What ``skfem.MappingIsoparametric`` (and :class:`MappingCurved`) read from a mesh: ``doflocs`` ``(dim, N)``,
    the coordinates of each geometric dof (a mesh node); ``dofs``, the element's dof numbering (``element_dofs``
    ``(n_local, n_cells)``); plus the corner mesh's ``facets``, ``f2e``, ``t2f`` and ``elem`` for facet maps.
    Build it with :func:`curved_geometry`.

    Attributes
    ----------
    element : skfem Element
        The quadratic element of the cells (``ElementTetP2``, ``ElementHexS2``, …).
    dofs : skfem Dofs
        Its dof numbering on ``fe_mesh`` (:class:`~bladecase.fe.wedge_element.WedgeFaceDofs` for 18-node wedges).
    doflocs : (dim, N) ndarray
        Coordinates of every geometric dof: the corner, midside, face-centre or centre node of the mesh.
    fe_mesh : skfem Mesh
        The mesh of the cells' corners the dofs are numbered on.
    node : (N,) int ndarray
        The mesh node at each geometric dof (``-1`` where the mesh has none: the straight centre is used).
    """

    def __init__(self, element, dofs, doflocs: np.ndarray, fe_mesh, node: np.ndarray):
        self.element, self.dofs, self.doflocs, self.fe_mesh, self.node = element, dofs, doflocs, fe_mesh, node

    def dim(self) -> int:
        return self.fe_mesh.dim()

    @property
    def nelements(self) -> int:
        return self.fe_mesh.nelements

    @property
    def facets(self):
        return self.fe_mesh.facets

    @property
    def f2e(self):
        return self.fe_mesh.f2e

    @property
    def t2f(self):
        return self.fe_mesh.t2f

    @property
    def elem(self):
        return type(self.element)

    def __repr__(self) -> str:
        return (f"CurvedGeometry({type(self.element).__name__}, {self.nelements} cells, "
                f"{self.doflocs.shape[1]} nodes)")


def curved_geometry(mesh: Mesh, used: np.ndarray, fe_mesh) -> CurvedGeometry | None:
    """The curved geometry of ``mesh``'s body cells, or ``None`` when they have no extra nodes (``tetra``, …).

    ``fe_mesh`` is the scikit-fem mesh of the body cells' corners (its cells in the order of the mesh's body
    cells, its vertex ``v`` being mesh node ``used[v]``), as :func:`bladecase.fe.assemble` builds it.  Every
    geometric dof of the quadratic element is matched to the mesh node sitting between the same corners (by
    node numbers, not positions): vertex dofs to the corners, edge dofs to the midside nodes, face and
    interior dofs to the face-centre and centre nodes.

    >>> import numpy as np, skfem
    >>> from bladecase.fe import Mesh
    >>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [.5, -.1, 0], [.5, .5, 0], [0, .5, 0]])
    >>> m = Mesh(p, {"triangle6": np.array([[0, 1, 2, 3, 4, 5]])}, dim=2)
    >>> g = curved_geometry(m, np.arange(3), skfem.MeshTri1(p[:3, :2].T.copy(), np.array([[0], [1], [2]])))
    >>> g, g.doflocs[:, 3].tolist(), g.node.tolist()  # facet 0 of skfem's triangle: nodes 0, 1
    (CurvedGeometry(ElementTriP2, 1 cells, 6 nodes), [0.5, -0.1], [0, 1, 2, 3, 5, 4])
    """
    kind = KINDS[mesh.body_type]
    if kind.order == 1:
        return None
    elem = element(element_name(mesh.body_type, 2))
    dofs = wedge_element.WedgeFaceDofs(fe_mesh, elem) if isinstance(elem, wedge_element.ElementWedge2) \
        else Dofs(fe_mesh, elem)
    dim = fe_mesh.dim()
    points = np.asarray(mesh.points, dtype=float)[:, :dim]
    cells = np.asarray(mesh.cells[mesh.body_type]).astype(np.int64)
    node = np.full(dofs.N, -1, dtype=np.int64)
    doflocs = np.zeros((dim, dofs.N))
    node[dofs.nodal_dofs[0]] = used
    entities = []  # (geometric dofs, their entity's vertices (k, n) in fe_mesh numbering)
    if dofs.edge_dofs.size:
        entities.append((dofs.edge_dofs[0], fe_mesh.edges))
    if dofs.facet_dofs.size:
        index = getattr(dofs, "facet_index", slice(None))
        entities.append((dofs.facet_dofs[0], fe_mesh.facets[:, index]))
    if dofs.interior_dofs.size:
        entities.append((dofs.interior_dofs[0], fe_mesh.t))
    tables = _extra_node_tables(kind, cells)
    for geo, vertices in entities:
        corners = used[vertices]
        doflocs[:, geo] = points[corners].mean(axis=0).T  # the straight centre, unless the mesh has the node
        keys = np.sort(corners, axis=0).T
        table = tables.get(keys.shape[1])
        if table is not None:
            node[geo] = _lookup(*table, keys)
    found = node >= 0
    doflocs[:, found] = points[node[found]].T
    return CurvedGeometry(elem, dofs, doflocs, fe_mesh, node)


def _extra_node_tables(kind, cells: np.ndarray) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """``{k: (parents, nodes)}``: the extra nodes of the cells with ``k`` parent corners (sorted rows of mesh
    node numbers)."""
    tables: dict[int, list] = {}
    for j in range(kind.corners, kind.n_nodes):
        parents = kind.parents[j]
        rows = np.sort(cells[:, list(parents)], axis=1)
        tables.setdefault(len(parents), []).append((rows, cells[:, j]))
    return {k: (np.vstack([r for r, _ in v]), np.concatenate([n for _, n in v])) for k, v in tables.items()}


def _lookup(table: np.ndarray, values: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """``values`` of the rows of ``table`` equal to each row of ``keys`` (``-1`` where none is)."""
    def void(a):
        a = np.ascontiguousarray(a, dtype=np.int64)
        return a.view(np.dtype((np.void, 8 * a.shape[1]))).ravel()

    t, k = void(table), void(keys)
    order = np.argsort(t, kind="stable")
    pos = np.clip(np.searchsorted(t[order], k), 0, t.size - 1)
    hit = t[order][pos] == k
    return np.where(hit, values[order][pos], -1)


def boundary_element(elem: skfem.element.Element) -> skfem.element.Element | None:
    """The facet element of a quadratic simplex (``ElementTriP2`` for ``ElementTetP2``, ``ElementLineP2`` for
    ``ElementTriP2``): what a ``FacetBasis`` on curved cells maps facets with; ``None`` for the other elements.

    >>> type(boundary_element(skfem.ElementTetP2())).__name__, boundary_element(skfem.ElementHexS2())
    ('ElementTriP2', None)
    """
    facet = {skfem.ElementTetP2: skfem.ElementTriP2, skfem.ElementTriP2: skfem.ElementLineP2}.get(type(elem))
    return facet() if facet is not None else None


class MappingCurved(MappingIsoparametric):
    """scikit-fem's isoparametric mapping through the nodes of a :class:`CurvedGeometry`, vectorised.

    ``DF``, ``detDF`` and ``invDF`` at a set of reference points are computed for all cells in one product
    ``J[i, j, e, q] = Σ_a x_i[a, e] ∂_j N_a(X_q)`` and kept (the last few point sets), so that every basis
    function of a ``CellBasis`` reuses them.  ``F`` likewise.  The facet maps (``G``, ``detDG``, normals of a
    ``FacetBasis``: pressure on a curved surface) are scikit-fem's, through the boundary element ``bndelem``
    (default :func:`boundary_element`: tetra10 and triangle6 cells only).

    >>> import numpy as np, skfem
    >>> from bladecase.fe import Mesh
    >>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [.5, -.1, 0], [.5, .5, 0], [0, .5, 0]])
    >>> m = Mesh(p, {"triangle6": np.array([[0, 1, 2, 3, 4, 5]])}, dim=2)
    >>> fe = skfem.MeshTri1(p[:3, :2].T.copy(), np.array([[0], [1], [2]]))
    >>> mapping = MappingCurved(curved_geometry(m, np.arange(3), fe))
    >>> mapping.F(np.array([[0.5], [0.0]])).ravel().tolist()  # the midside node
    [0.5, -0.1]
    >>> round(float(skfem.CellBasis(fe, skfem.ElementTriP2(), mapping=mapping).dx.sum()), 12)  # 1/2 + 2/3 · 0.1
    0.566666666667
    """

    #: Point sets whose Jacobians are kept.
    CACHE_SIZE = 4

    def __init__(self, geometry: CurvedGeometry, bndelem=None):
        super().__init__(geometry, geometry.element, boundary_element(geometry.element) if bndelem is None else bndelem)
        self._kept: dict = {}

    def _local(self, X: np.ndarray, derivative: bool) -> np.ndarray:
        """Values ``(a, ...)`` or gradients ``(a, j, ...)`` of the geometric element's functions at ``X``."""
        return np.stack([self.elem.lbasis(X, a)[1 if derivative else 0] for a in range(self.elem_dofs.shape[0])])

    @property
    def elem_dofs(self) -> np.ndarray:
        return self.mesh.dofs.element_dofs

    def _nodes(self, tind) -> np.ndarray:
        """Coordinates ``(i, a, e)`` of the nodes of cells ``tind`` (all if ``None``)."""
        t = self.elem_dofs if tind is None else self.elem_dofs[:, tind]
        return self.mesh.doflocs[:, t]

    def _jacobians(self, X: np.ndarray, tind=None) -> dict:
        key = (X.shape, X.tobytes(), None if tind is None else np.asarray(tind).tobytes())
        hit = self._kept.get(key)
        if hit is not None:
            return hit
        x = self._nodes(tind)
        dN = self._local(X, True)  # (a, j, q) or (a, j, e, q)
        J = np.einsum("iae,ajq->ijeq", x, dN) if X.ndim == 2 else np.einsum("iae,ajeq->ijeq", x, dN)
        det, inv = _det_inv(J)
        if len(self._kept) >= self.CACHE_SIZE:
            self._kept.pop(next(iter(self._kept)))
        hit = self._kept[key] = {"J": J, "det": det, "inv": inv}
        return hit

    def F(self, X, tind=None):
        phi = self._local(X, False)  # (a, q) or (a, e, q)
        x = self._nodes(tind)
        return np.einsum("iae,aq->ieq", x, phi) if X.ndim == 2 else np.einsum("iae,aeq->ieq", x, phi)

    def J(self, i, j, X, tind=None):
        return self._jacobians(X, tind)["J"][i, j]

    def DF(self, X, tind=None, J=None):
        return self._jacobians(X, tind)["J"] if J is None else np.array(J)

    def detDF(self, X, tind=None, J=None):
        if J is not None:
            return _det_inv(np.array(J))[0]
        return self._jacobians(X, tind)["det"]

    def invDF(self, X, tind=None):
        return self._jacobians(X, tind)["inv"]


def _det_inv(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Determinant ``(e, q)`` and inverse ``(i, j, e, q)`` of the Jacobians ``J (i, j, e, q)`` (2×2 or 3×3, by
    cofactors as scikit-fem does)."""
    if J.shape[0] == 2:
        det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
        cof = np.array([[J[1, 1], -J[0, 1]], [-J[1, 0], J[0, 0]]])
    else:
        cof = np.empty_like(J)
        for i in range(3):
            for j in range(3):  # inverse[i, j] = cofactor of J[j, i]
                r, c = [k for k in range(3) if k != j], [k for k in range(3) if k != i]
                sign = -1.0 if (i + j) % 2 else 1.0
                cof[i, j] = sign * (J[r[0], c[0]] * J[r[1], c[1]] - J[r[0], c[1]] * J[r[1], c[0]])
        det = J[0, 0] * cof[0, 0] + J[0, 1] * cof[1, 0] + J[0, 2] * cof[2, 0]
    if np.any(det == 0):
        raise ValueError("a curved cell has a zero Jacobian determinant at a quadrature point (a degenerate cell)")
    return det, cof / det


def folded_cells(det: np.ndarray) -> np.ndarray:
    """Cells whose Jacobian determinant ``det (cells, points)`` changes sign (or vanishes) inside: folded cells.

    >>> folded_cells(np.array([[1.0, 2.0], [1.0, -0.5], [-1.0, -2.0]])).tolist()
    [1]
    """
    return np.flatnonzero((det.min(axis=1) <= 0) & (det.max(axis=1) >= 0))
