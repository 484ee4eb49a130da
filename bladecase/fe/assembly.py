"""Finite-element assembly: stiffness and mass of a clamped linear-elastic body from a :class:`~bladecase.fe.mesh.Mesh`.

:func:`assemble` turns a mesh (tetrahedra, hexahedra or wedges in 3-D; triangles or
quadrilaterals in 2-D plane stress or plane strain) and a :class:`~bladecase.fe.material.Material`
into an :class:`~bladecase.fe.model.FEModel`: the sparse stiffness and mass
matrices of linear elasticity with the clamped degrees of freedom removed
(:func:`~bladecase.fe.eigen.natural_frequencies` then gives its lowest
eigenfrequencies).

The discretisation is scikit-fem's: the mesh's vertices make a
``skfem.MeshTet``/``MeshTri``/``MeshHex``/``MeshWedge1``/``MeshQuad`` (the cells' topology),
the scalar element of :data:`~bladecase.fe.cells.SKFEM_ELEMENTS` (``ElementTetP1/P2``,
``ElementTriP1/P2``, ``ElementHex1``, ``ElementHexS2`` — ``ElementHex2`` on 27-node
meshes —, ``ElementWedge1``, ``ElementWedgeS2`` — ``ElementWedge2`` on 18-node meshes —,
``ElementQuad1``, ``ElementQuadS2`` — ``ElementQuad2`` on 9-node meshes) gives the basis
functions (the second-order wedges are :mod:`~bladecase.fe.wedge_element`'s: scikit-fem has
none), ``skfem.models.elasticity.lame_parameters`` the Lamé constants.  The geometry: at order
2 on a second-order mesh, each cell is mapped through all its nodes by its own quadratic
element (isoparametric, curved cells: :mod:`~bladecase.fe.isoparametric`), and every scalar dof
sits at a mesh node — a vertex, or the midside, face-centre or centre node of its edge, face or
cell (``DofMap.coords``, where :func:`~bladecase.fe.node_operator` finds it); otherwise (a
first-order mesh, or order 1) the cells are straight-sided, trilinear or prismatic through
their corners and the dofs sit at the vertices, edge midpoints and face (cell) centres of the
straight cells.  Straight-sided second-order cells give the same matrices either way, to
round-off.  Simplices use scikit-fem's default quadrature; hexahedra and
quadrilaterals the ``(p+1)``-point Gauss rule per direction (exact mass and stiffness
on parallelepipeds), wedges a triangle × line product rule of degree ``2p+1`` in each
built here (exact on right prisms; scikit-fem 12.0's wedge rule does not integrate the
reference prism: weights summing to 1/4, not 1/2); curved cells keep the same rules (their
integrands are no longer polynomials: the quadrature error is of the discretisation's order).
The weak forms are those of ``skfem.models.elasticity.linear_elasticity``
(``σ(u):ε(v)``) and of the mass ``ρ u·v`` on
``ElementVector(ElementTetP1/P2)``; they are integrated here by one batched
product over all cells instead of skfem's loop over the local basis pairs
(about 20 times faster for P2 tetrahedra; the tests check that both give the
same matrices).

This module also re-exports, for the old import paths, the names that moved to
:mod:`~bladecase.fe.material`, :mod:`~bladecase.fe.model`,
:mod:`~bladecase.fe.eigen` and :mod:`~bladecase.fe.storage`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import scipy.sparse as sp
import skfem
from scipy.sparse.csgraph import connected_components
from skfem import CellBasis, ElementTetP1, ElementTetP2, ElementTriP1, ElementTriP2
from skfem.quadrature import get_quadrature_line, get_quadrature_tri

from ..checks import positive
from . import isoparametric, wedge_element
from .cells import KINDS, SKFEM_MESHES, element_name
from .eigen import natural_frequencies
from .material import AL6061T6, ALUMINIUM, INCONEL718, PLANE_KINDS, PRESETS, STEEL, TI6AL4V, Material
from .mesh import Mesh, check_extent
from .model import MASS_KINDS, ORDERS, DofMap, FEModel
from .quality import corner_jacobians
from .select import select_nodes
from .storage import (
    MODEL_FORMAT,
    load_model,
    model_from_arrays,
    model_to_arrays,
    save_model,
    sparse_from_arrays,
    sparse_to_arrays,
)

__all__ = [
    "CHUNK_CELLS", "DEGENERATE_RTOL", "MASS_KINDS", "ORDERS", "Clamp", "assemble",
    # moved (old import paths of bladecase.fe.assembly)
    "AL6061T6", "ALUMINIUM", "INCONEL718", "MODEL_FORMAT", "PLANE_KINDS", "PRESETS", "STEEL", "TI6AL4V",
    "DofMap", "FEModel", "Material", "load_model", "model_from_arrays", "model_to_arrays", "natural_frequencies",
    "save_model", "sparse_from_arrays", "sparse_to_arrays",
]

#: Cells per batch of the element integration (bounds the temporaries).
CHUNK_CELLS = 4096

#: A cell whose volume is below this fraction of the largest one is degenerate.
DEGENERATE_RTOL = 1e-12

Clamp = str | dict | Sequence[int] | np.ndarray | Callable[[np.ndarray], np.ndarray] | None

#: The simplex elements by (dim, order) (all elements: :data:`bladecase.fe.cells.SKFEM_ELEMENTS`).
_ELEMENTS = {
    (3, 1): ElementTetP1, (3, 2): ElementTetP2,
    (2, 1): ElementTriP1, (2, 2): ElementTriP2,
}


def assemble(
    mesh: Mesh,
    material: Material | str,
    order: int = 2,
    mass: str = "consistent",
    clamp: Clamp = "root",
    thickness: float | None = None,
    plane: str = "stress",
) -> FEModel:
    """Stiffness and mass matrices of a clamped linear-elastic body.

    Parameters
    ----------
    mesh : Mesh
        Tetrahedra, hexahedra or wedges (``dim == 3``), triangles or
        quadrilaterals in the xy-plane (``dim == 2``).  Second-order cells
        (``tetra10``, ``hexahedron20``, …) are curved through their midside
        (face-centre, centre) nodes at ``order=2`` (isoparametric cells); at
        ``order=1`` they are straight through their corners.
    material : Material or str
        The material, or the name of a preset (:meth:`Material.preset`).
    order : {1, 2}
        Element order: 2 (default; P2, serendipity or full quadratic
        hexahedra and quadrilaterals, accurate in bending) or 1 (P1,
        trilinear, bilinear, prismatic: they lock in bending and need fine
        meshes).  Wedges: 15-node serendipity at order 2 (18-node Lagrange
        on ``wedge18`` meshes).
    mass : {"consistent", "lumped"}
        Consistent mass, or lumped: row sum for P1, HRZ (diagonal scaled to
        the element mass, Hinton–Rock–Zienkiewicz 1976) for P2.  Both keep the
        total mass exactly.
    clamp : str, dict, sequence of int, callable or None
        Nodes whose displacements are fixed: a group name of ``mesh``
        (default ``"root"``), a selection by coordinates (a dict of
        :func:`~bladecase.fe.select.select_nodes`, e.g. ``{"plane": [0, 0,
        0, 1, 0, 0]}``), mesh node indices (or a boolean mask over the
        nodes), or a function of the node coordinates ``(n, 3) -> (n,) bool``.
        For order 2, an edge (face) dof is clamped when all the vertices of
        its edge (face) are.  ``None`` gives the unclamped (free-free) model.
    thickness : float
        Out-of-plane thickness of a 2-D model (required, > 0); must be
        ``None`` in 3-D.
    plane : {"stress", "strain"}
        2-D hypothesis (ignored in 3-D).  Plane stress uses the Lamé constant
        ``λ* = 2λμ/(λ + 2μ)``.

    Returns
    -------
    FEModel
        ``K`` and ``M`` (CSR) on the free dofs, the dof map, and the data above.

    Raises
    ------
    ValueError
        Bad argument (the message names it and what is valid), a clamp that
        selects no node of the body, degenerate cells, curved cells folded
        over (the Jacobian changing sign inside).

    Examples
    --------
    A steel plate 100 × 20 × 2 mm in plane stress, clamped along ``x = 0`` (its ``root`` group):

    >>> import numpy as np
    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 11), np.linspace(0, 0.02, 3))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> plate = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    >>> model = assemble(plate, "steel", order=2, thickness=0.002)
    >>> model
    FEModel(2-D, P2, 200 free dofs, consistent mass, steel, thickness=0.002, plane stress, 3 clamped nodes)
    >>> model.K.shape, round(model.total_mass, 6)  # ρ · area · thickness (kg)
    ((200, 200), 0.0314)
    """
    if not isinstance(mesh, Mesh):
        raise ValueError(f"mesh must be a bladecase.Mesh, got {type(mesh).__name__}")
    if mesh.dim not in (2, 3):
        raise ValueError(f"mesh.dim must be 2 or 3, got {mesh.dim!r}")
    dim = mesh.dim
    if isinstance(material, str):
        material = Material.preset(material)
    if not isinstance(material, Material):
        raise ValueError(f"material must be a Material or a preset name, got {type(material).__name__}")
    if isinstance(order, bool) or order not in ORDERS:
        raise ValueError(f"order must be 1 or 2, got {order!r}")
    if mass not in MASS_KINDS:
        raise ValueError(f"mass must be one of {MASS_KINDS}, got {mass!r}")
    if plane not in PLANE_KINDS:
        raise ValueError(f"plane must be one of {PLANE_KINDS}, got {plane!r}")
    if dim == 2:
        if thickness is None:
            raise ValueError("a 2-D model needs a thickness (> 0, same length unit as the mesh)")
        thickness = positive("thickness", thickness)
    elif thickness is not None:
        raise ValueError(f"thickness applies to 2-D models only; this mesh is 3-D (got thickness={thickness!r})")

    points = np.asarray(mesh.points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise ValueError(f"mesh.points must be a finite (n, 3) array, got shape {points.shape}")
    check_extent(points, mesh.source or "(in memory)")  # 1e±150 m: K, M over/underflow; 0: a degenerate mesh
    clamped = _clamp_nodes(mesh, points, clamp)

    basis, fe_mesh, used = _basis(mesh, points, dim, order)
    cell_volume = basis.dx.sum(axis=1)
    volume = float(cell_volume.sum())
    depth = thickness if dim == 2 else 1.0

    lam, mu = material.lame(plane if dim == 2 else None)
    K = _stiffness(basis, dim, lam, mu) * depth
    Ms = _scalar_mass(basis, mass, order) * (material.rho * depth)
    M = sp.kron(Ms, sp.eye_array(dim), format="csr") if sp.issparse(Ms) else None

    # Scalar dofs: their mesh node (vertices) and whether they are clamped.
    n_scalar = basis.N
    node_of = np.full(n_scalar, -1, dtype=np.int64)
    node_of[basis.nodal_dofs[0]] = used
    is_clamped = np.zeros(points.shape[0], dtype=bool)
    is_clamped[clamped] = True
    vertex_clamped = is_clamped[used]
    if clamp is not None and not vertex_clamped.any():
        raise ValueError(f"clamp {_describe(clamp)} selects no vertex of the body cells of mesh {mesh.source or ''}")
    scalar_clamped = _clamped_dofs(basis, fe_mesh, vertex_clamped)

    free = np.flatnonzero(~np.repeat(scalar_clamped, dim))
    scalar = free // dim
    coords = np.zeros((free.size, 3))
    coords[:, :dim] = basis.doflocs[:, scalar].T
    dofs = DofMap(node=node_of[scalar], direction=free % dim, coords=coords, fe_index=free, n_total=dim * n_scalar)

    K = sp.csr_array(K[free][:, free])
    if M is None:  # lumped: a diagonal
        M = sp.diags_array(np.repeat(Ms, dim)[free], format="csr")
    else:
        M = sp.csr_array(M[free][:, free])
    return FEModel(
        K=K, M=M, dofs=dofs, mesh=mesh, material=material, order=order, mass=mass,
        thickness=thickness, plane=plane if dim == 2 else None,
        clamped=used[vertex_clamped], volume=volume,
        rigid_modes=_free_motions(fe_mesh, vertex_clamped),
    )


def _basis(mesh: Mesh, points: np.ndarray, dim: int, order: int):
    """``(basis, fe_mesh, used)``: scikit-fem's basis on the body cells, the mesh of their corners, and the mesh
    node of each of its vertices.

    At order 2, cells with extra nodes are curved: the basis maps them through all their nodes
    (:class:`~bladecase.fe.isoparametric.MappingCurved`) and its ``doflocs`` are the mesh's nodes.  At order 1
    they stay straight through their corners (a curved map with a linear field would not hold the rigid
    rotations: see :mod:`~bladecase.fe.isoparametric`).
    """
    body_type = mesh.body_type
    kind = KINDS[body_type]
    used, local = _body_cells(mesh, points, dim)
    corners = local if kind.family in ("tetra", "triangle") else local[:, list(kind.skfem_corners)]
    fe_mesh = getattr(skfem, SKFEM_MESHES[kind.family])(np.ascontiguousarray(points[used, :dim].T),
                                                       np.ascontiguousarray(corners.T))
    geometry = isoparametric.curved_geometry(mesh, used, fe_mesh) if order == 2 else None
    if kind.family in ("tetra", "triangle"):  # scikit-fem's elements and default quadrature
        element, options = _ELEMENTS[dim, order](), {}
    elif kind.family == "wedge":
        element = isoparametric.element(element_name(body_type, order))
        X, W = get_quadrature_tri(2 * order + 1)
        Z, V = get_quadrature_line(2 * order + 1)
        options = {"quadrature": (np.vstack([np.tile(X, Z.shape[1]), np.repeat(Z, X.shape[1], axis=1)]),
                                  np.outer(V, W).ravel())}
        if isinstance(element, wedge_element.ElementWedge2):
            options["dofs"] = wedge_element.WedgeFaceDofs(fe_mesh, element)
    else:
        element, options = isoparametric.element(element_name(body_type, order)), {"intorder": 2 * order + 1}
    if geometry is None:
        return CellBasis(fe_mesh, element, **options), fe_mesh, used
    options["dofs"] = geometry.dofs  # the field's element is the geometry's: the same dofs, at the mesh's nodes
    basis = CellBasis(fe_mesh, element, mapping=isoparametric.MappingCurved(geometry), disable_doflocs=True,
                      **options)
    basis.doflocs = geometry.doflocs
    folded = isoparametric.folded_cells(basis.mapping.detDF(basis.X))
    if folded.size:
        i = int(folded[0])
        raise ValueError(f"mesh {mesh.source or ''} has {folded.size} folded curved {body_type} cell(s) (the Jacobian "
                         f"changes sign inside), e.g. cell {i} with nodes {mesh.cells[body_type][i].tolist()}")
    return basis, fe_mesh, used


def _clamped_dofs(basis: CellBasis, fe_mesh, vertex_clamped: np.ndarray) -> np.ndarray:
    """Scalar dofs fixed by the clamped vertices: a vertex's, and an edge's (face's) when all its vertices are."""
    clamped = np.zeros(basis.N, dtype=bool)
    clamped[basis.nodal_dofs[0]] = vertex_clamped
    elem = basis.elem
    entities = [("facet_dofs", fe_mesh.facets[:, getattr(basis.dofs, "facet_index", slice(None))])]
    if fe_mesh.dim() == 3:
        entities.insert(0, ("edge_dofs", fe_mesh.edges))
    for name, ends in entities:
        if getattr(elem, name, 0):
            clamped[getattr(basis, name)[0]] = vertex_clamped[ends].all(axis=0)
    return clamped


def _body_cells(mesh: Mesh, points: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """``(used, local)``: the mesh nodes of the body cells (sorted) and the cells' corners numbered among them.

    Raises ``ValueError`` for cells referring to missing nodes, a 2-D mesh off
    the xy-plane, degenerate (zero-volume) cells.
    """
    kind = KINDS[mesh.body_type]
    cells = np.asarray(mesh.cells[mesh.body_type])[:, : kind.corners].astype(np.int64)
    if cells.min() < 0 or cells.max() >= points.shape[0]:
        raise ValueError(f"mesh cells refer to nodes outside 0..{points.shape[0] - 1}")
    used, local = np.unique(cells, return_inverse=True)
    if dim == 2:
        scale = np.abs(points[used, :2]).max()
        if np.abs(points[used, 2]).max() > 1e-12 * max(scale, 1e-300):
            raise ValueError("a 2-D mesh must lie in the xy-plane (z = 0)")
    if kind.family in ("tetra", "triangle"):
        corners = points[cells, :dim]
        cell_volume = np.abs(np.linalg.det(corners[:, 1:] - corners[:, :1])) / math.factorial(dim)
    else:  # the largest corner Jacobian: zero for a cell collapsed to a point, a segment or a plane
        cell_volume = np.abs(corner_jacobians(points, cells, kind.family)).max(axis=1)
    flat = cell_volume <= DEGENERATE_RTOL * cell_volume.max()
    if flat.any():
        i = int(np.flatnonzero(flat)[0])
        raise ValueError(
            f"mesh has {int(flat.sum())} degenerate cell(s) (zero volume), e.g. cell {i} with nodes {cells[i].tolist()}"
        )
    return used, local.reshape(cells.shape)


def _describe(clamp) -> str:
    if isinstance(clamp, (str, dict)):
        return repr(clamp)
    if callable(clamp):
        return f"function {getattr(clamp, '__name__', repr(clamp))}"
    return "node list"


def _clamp_nodes(mesh: Mesh, points: np.ndarray, clamp: Clamp) -> np.ndarray:
    """Sorted mesh node indices selected by ``clamp`` (see :func:`assemble`)."""
    n = points.shape[0]
    if clamp is None:
        return np.zeros(0, dtype=np.int64)
    if isinstance(clamp, str):
        nodes = np.asarray(mesh.group(clamp))
        if nodes.size == 0:
            raise ValueError(f"clamp group {clamp!r} of mesh {mesh.source or ''} is empty")
    elif isinstance(clamp, dict):
        nodes = select_nodes(mesh, clamp, what="clamp", allow_all=False)
    elif callable(clamp):
        mask = np.asarray(clamp(points.copy()))
        if mask.size != n:
            raise ValueError(
                f"clamp function must return one boolean per node ({n}), got an array of shape {mask.shape}"
            )
        nodes = np.flatnonzero(mask.reshape(n).astype(bool))
        if nodes.size == 0:
            raise ValueError(f"clamp {_describe(clamp)} selects no node (it returned False for all {n} nodes)")
    else:
        nodes = np.asarray(clamp)
        if nodes.dtype == bool:
            if nodes.shape != (n,):
                raise ValueError(f"a boolean clamp mask needs one entry per node ({n}), got shape {nodes.shape}")
            nodes = np.flatnonzero(nodes)
        elif nodes.size and nodes.dtype.kind not in "iu":
            raise ValueError(
                "clamp must be a group name, node indices (integers), a boolean mask, a function of "
                f"the coordinates or None; got an array of dtype {nodes.dtype}"
            )
        nodes = nodes.astype(np.int64).ravel()
        if nodes.size == 0:
            raise ValueError("clamp selects no node (empty node list)")
    nodes = nodes.astype(np.int64).ravel()
    if nodes.min() < 0 or nodes.max() >= n:
        bad = nodes[(nodes < 0) | (nodes >= n)][0]
        raise ValueError(f"clamp node {bad} is out of range (mesh nodes 0..{n - 1})")
    return np.unique(nodes)


def _free_motions(fe_mesh, vertex_clamped: np.ndarray) -> int:
    """Rigid-body motions left free by the clamp, summed over the face-connected parts of the mesh.

    Cells sharing a facet (a triangle in 3-D, an edge in 2-D) belong to the
    same part; a part is fixed when its clamped vertices suppress every rigid
    motion (3 non-collinear points in 3-D, 2 distinct points in 2-D).  Parts
    joined to the rest only at vertices or edges count as free bodies (an
    upper bound: they are hinged); a face-connected body gets an exact count.
    """
    f2t = fe_mesh.f2t
    inner = f2t[1] >= 0
    nel = fe_mesh.t.shape[1]
    graph = sp.coo_array((np.ones(int(inner.sum())), (f2t[0, inner], f2t[1, inner])), shape=(nel, nel))
    n_parts, part = connected_components(graph, directed=False)
    p = fe_mesh.p.T
    if n_parts == 1:
        return _rigid_modes(p[vertex_clamped])
    total = 0
    for k in range(n_parts):
        verts = np.unique(fe_mesh.t[:, part == k])
        total += _rigid_modes(p[verts[vertex_clamped[verts]]])
    return total


def _rigid_modes(x: np.ndarray) -> int:
    """Number of rigid-body motions that do not vanish at all the points ``x`` (n, dim)."""
    dim = x.shape[1]
    n_rb = 6 if dim == 3 else 3
    if x.shape[0] == 0:
        return n_rb
    x = x - x.mean(axis=0)
    x = x / max(np.abs(x).max(), 1e-300)
    n = x.shape[0]
    R = np.zeros((n, dim, n_rb))
    for c in range(dim):
        R[:, c, c] = 1.0
    if dim == 2:
        R[:, 0, 2], R[:, 1, 2] = -x[:, 1], x[:, 0]
    else:
        for k, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):  # rotation about axis k: u_i = -x_j, u_j = x_i
            R[:, i, 3 + k], R[:, j, 3 + k] = -x[:, j], x[:, i]
    s = np.linalg.svd(R.reshape(n * dim, n_rb), compute_uv=False)
    return int(n_rb - np.sum(s > 1e-8 * s[0]))


def _gradients(basis: CellBasis, cells: slice) -> np.ndarray:
    """Basis gradients ``(cells, nb, dim, nq)`` of a batch of cells."""
    return np.stack([b[0].grad[:, cells] for b in basis.basis], axis=0).transpose(2, 0, 1, 3)


def _stiffness(basis: CellBasis, dim: int, lam: float, mu: float) -> sp.csr_array:
    """``∫ σ(u):ε(v)`` on ``ElementVector(basis.elem)``, numbered ``dim * s + c``.

    For ``u = φ_b e_j``, ``v = φ_a e_i``:
    ``K[(a,i),(b,j)] = λ ∂_iφ_a ∂_jφ_b + μ (δ_ij ∇φ_a·∇φ_b + ∂_jφ_a ∂_iφ_b)``.
    """
    nb, nel = basis.Nbfun, basis.nelems
    nloc = nb * dim
    data = np.empty((nel, nloc, nloc))
    for start in range(0, nel, CHUNK_CELLS):
        cells = slice(start, min(start + CHUNK_CELLS, nel))
        G = _gradients(basis, cells)  # (e, a, i, q)
        ne, nq = G.shape[0], G.shape[3]
        Gw = (G * basis.dx[cells, None, None, :]).reshape(ne, nloc, nq)
        S = np.matmul(Gw, G.reshape(ne, nloc, nq).transpose(0, 2, 1)).reshape(ne, nb, dim, nb, dim)
        Ke = lam * S + mu * S.transpose(0, 1, 4, 3, 2)  # S[e,a,i,b,j] and S[e,a,j,b,i]
        lap = np.einsum("eakbk->eab", S)
        for i in range(dim):
            Ke[:, :, i, :, i] += mu * lap
        Ke = Ke.reshape(ne, nloc, nloc)
        data[cells] = 0.5 * (Ke + Ke.transpose(0, 2, 1))
    n = dim * basis.N
    vdofs = (dim * basis.element_dofs.T[:, :, None] + np.arange(dim)).reshape(nel, nloc).astype(_index_type(n))
    rows = np.broadcast_to(vdofs[:, :, None], data.shape).ravel()
    cols = np.broadcast_to(vdofs[:, None, :], data.shape).ravel()
    return sp.csr_array(sp.coo_array((data.ravel(), (rows, cols)), shape=(n, n)))


def _index_type(n: int):
    return np.int32 if n < np.iinfo(np.int32).max else np.int64


def _scalar_mass(basis: CellBasis, mass: str, order: int):
    """Scalar mass ``∫ φ_a φ_b`` (CSR) if consistent; the lumped diagonal (ndarray) otherwise."""
    phi = np.stack([np.asarray(b[0]) for b in basis.basis], axis=1)  # (e, a, q)
    dx = basis.dx
    n = basis.N
    ed = basis.element_dofs.astype(_index_type(n))  # (a, e)
    if mass == "lumped" and order == 2:  # HRZ: diagonal scaled to the element mass
        diag = np.einsum("eaq,eaq,eq->ea", phi, phi, dx)
        lumped = dx.sum(axis=1)[:, None] * diag / diag.sum(axis=1, keepdims=True)
        return np.bincount(ed.T.ravel(), weights=lumped.ravel(), minlength=n)
    Me = np.matmul(phi * dx[:, None, :], phi.transpose(0, 2, 1))  # (e, a, b)
    Me = 0.5 * (Me + Me.transpose(0, 2, 1))
    rows = np.broadcast_to(ed.T[:, :, None], Me.shape).ravel()
    cols = np.broadcast_to(ed.T[:, None, :], Me.shape).ravel()
    Ms = sp.csr_array(sp.coo_array((Me.ravel(), (rows, cols)), shape=(n, n)))
    if mass == "lumped":  # P1: row sum
        return np.asarray(Ms.sum(axis=1)).ravel()
    return Ms

