"""Finite-element model of a structure: stiffness and mass from a :class:`~bladecase.fe.mesh.Mesh`.

:func:`assemble` turns a simplex mesh (tetrahedra in 3-D, triangles in 2-D
plane stress or plane strain) and a :class:`Material` into the sparse
stiffness and mass matrices of linear elasticity, with the clamped degrees of
freedom removed; :func:`natural_frequencies` gives the lowest eigenfrequencies
by a sparse shift-invert eigen-solution.

The discretisation is scikit-fem's: the mesh's vertices make a
``skfem.MeshTet``/``MeshTri`` (straight-sided cells; the extra nodes of
``tetra10``/``triangle6`` cells are not used), the scalar Lagrange element
``ElementTetP1/P2``/``ElementTriP1/P2`` gives the basis functions and the
quadrature, ``skfem.models.elasticity.lame_parameters`` the Lamé constants.
The weak forms are those of ``skfem.models.elasticity.linear_elasticity``
(``σ(u):ε(v)``) and of the mass ``ρ u·v`` on
``ElementVector(ElementTetP1/P2)``; they are integrated here by one batched
product over all cells instead of skfem's loop over the local basis pairs
(about 20 times faster for P2 tetrahedra; the tests check that both give the
same matrices).

Degree-of-freedom numbering: the scalar dofs of skfem's basis, each carrying
``dim`` displacement components, component ``c`` of scalar dof ``s`` being
unclamped dof ``dim * s + c``.  A :class:`DofMap` says for each free dof its
location, its direction and its mesh node (``-1`` for the edge dofs of
quadratic elements).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components
from skfem import CellBasis, ElementTetP1, ElementTetP2, ElementTriP1, ElementTriP2, MeshTet, MeshTri
from skfem.models.elasticity import lame_parameters

from .mesh import Mesh

#: Accepted values of ``mass``.
MASS_KINDS = ("consistent", "lumped")
#: Accepted values of ``plane`` (2-D models).
PLANE_KINDS = ("stress", "strain")
#: Accepted values of ``order``.
ORDERS = (1, 2)

#: Cells per batch of the element integration (bounds the temporaries).
CHUNK_CELLS = 4096

#: A cell whose volume is below this fraction of the largest one is degenerate.
DEGENERATE_RTOL = 1e-12

Clamp = str | Sequence[int] | np.ndarray | Callable[[np.ndarray], np.ndarray] | None

_ELEMENTS = {
    (3, 1): ElementTetP1, (3, 2): ElementTetP2,
    (2, 1): ElementTriP1, (2, 2): ElementTriP2,
}
_DIRECTIONS = {"x": 0, "y": 1, "z": 2}


def _positive(name: str, value, what: str = "> 0", noun: str = "number") -> float:
    """``float(value)`` if it is a finite number > 0, else ``ValueError``
    ("``name`` must be a [finite] ``noun`` ``what``, got …")."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number {what}, got {value!r}") from None
    if isinstance(value, bool) or not math.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be a finite {noun} {what}, got {value!r}")
    return x


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic material (SI units).

    Parameters
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio, ``-1 < nu < 0.5``.
    rho : float
        Density (kg/m³), > 0.
    name : str
        Label for messages and reports.

    Presets (:meth:`preset`, and the module constants :data:`TI6AL4V`,
    :data:`STEEL`, :data:`INCONEL718`, :data:`AL6061T6`) hold typical
    room-temperature handbook values (ASM Aerospace Specification Metals /
    MatWeb data sheets, consistent with MMPDS typical values):

    ============  =========  =====  =========  ===========================================
    preset        E (GPa)    ν      ρ (kg/m³)  source
    ============  =========  =====  =========  ===========================================
    Ti-6Al-4V     113.8      0.342  4430       ASM data sheet, Ti-6Al-4V (Grade 5), annealed
    steel         200        0.30   7850       typical carbon/structural steel handbook value
    Inconel 718   200        0.294  8190       Special Metals INCONEL 718 data (ASM/MatWeb);
                                               Special Metals' own table lists ≈ 204.9 GPa
    Al 6061-T6    68.9       0.33   2700       ASM data sheet, aluminium 6061-T6
    ============  =========  =====  =========  ===========================================

    Raises
    ------
    ValueError
        A value that is not a finite number in its valid range.
    """

    E: float
    nu: float
    rho: float
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "E", _positive("Young's modulus E", self.E, "> 0 (Pa)"))
        object.__setattr__(self, "rho", _positive("density rho", self.rho, "> 0 (kg/m³)"))
        try:
            nu = float(self.nu)
        except (TypeError, ValueError):
            raise ValueError(f"Poisson's ratio nu must be a number in (-1, 0.5), got {self.nu!r}") from None
        if isinstance(self.nu, bool) or not -1.0 < nu < 0.5:
            raise ValueError(f"Poisson's ratio nu must be in (-1, 0.5) (open interval), got {self.nu!r}")
        object.__setattr__(self, "nu", nu)

    @classmethod
    def preset(cls, name: str) -> Material:
        """A preset by name, case and punctuation ignored.

        Names: ``"Ti-6Al-4V"`` (also ``"titanium"``), ``"steel"``,
        ``"Inconel 718"`` (also ``"IN718"``, ``"inconel"``),
        ``"aluminium"`` (also ``"aluminum"``, ``"Al 6061-T6"``, ``"6061-T6"``).
        """
        key = re.sub(r"[^a-z0-9]", "", str(name).lower())
        if key not in _PRESET_KEYS:
            raise ValueError(f"unknown material preset {name!r} (presets: {', '.join(PRESETS)})")
        return PRESETS[_PRESET_KEYS[key]]

    def lame(self, plane: str | None = None) -> tuple[float, float]:
        """Lamé constants ``(λ, μ)``; ``plane="stress"`` gives ``λ* = 2λμ/(λ + 2μ) = Eν/(1 - ν²)``.

        ``plane=None`` (3-D) and ``plane="strain"`` give the 3-D constants.
        """
        lam, mu = lame_parameters(self.E, self.nu)
        if plane == "stress":
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)
        elif plane not in (None, "strain"):
            raise ValueError(f"plane must be one of {PLANE_KINDS} or None, got {plane!r}")
        return lam, mu


#: Ti-6Al-4V (Grade 5), annealed: ASM data sheet.
TI6AL4V = Material(113.8e9, 0.342, 4430.0, "Ti-6Al-4V")
#: Carbon/structural steel, typical handbook value.
STEEL = Material(200e9, 0.30, 7850.0, "steel")
#: Inconel 718 (ASM/MatWeb; Special Metals lists ≈ 204.9 GPa).
INCONEL718 = Material(200e9, 0.294, 8190.0, "Inconel 718")
#: Aluminium 6061-T6: ASM data sheet.
AL6061T6 = Material(68.9e9, 0.33, 2700.0, "Al 6061-T6")
#: Alias of :data:`AL6061T6`.
ALUMINIUM = AL6061T6

#: Presets by display name.
PRESETS = {m.name: m for m in (TI6AL4V, STEEL, INCONEL718, AL6061T6)}
_PRESET_KEYS = {
    "ti6al4v": "Ti-6Al-4V", "titanium": "Ti-6Al-4V", "tc4": "Ti-6Al-4V",
    "steel": "steel",
    "inconel718": "Inconel 718", "inconel": "Inconel 718", "in718": "Inconel 718",
    "al6061t6": "Al 6061-T6", "6061t6": "Al 6061-T6", "aluminium": "Al 6061-T6",
    "aluminum": "Al 6061-T6", "aluminium6061t6": "Al 6061-T6", "aluminum6061t6": "Al 6061-T6",
}


@dataclass(frozen=True, eq=False)
class DofMap:
    """Where each free degree of freedom of an :class:`FEModel` lives.

    Attributes
    ----------
    node : (n,) int ndarray
        Mesh node (index into ``mesh.points``) of a vertex dof; ``-1`` for a
        dof that is not at a mesh node (edge dofs of quadratic elements).
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
        extra = f", thickness={self.thickness:g}, plane {self.plane}" if self.dim == 2 else ""
        return (
            f"FEModel({self.dim}-D, P{self.order}, {self.n_dofs} free dofs, {self.mass} mass, "
            f"{self.material.name or 'material'}{extra}, {self.clamped.size} clamped nodes)"
        )


def _direction(d, dim: int) -> int:
    if isinstance(d, str) and d.lower() in _DIRECTIONS:
        d = _DIRECTIONS[d.lower()]
    if isinstance(d, (bool, np.bool_)) or not isinstance(d, (int, np.integer)) or not 0 <= d < dim:
        valid = "0, 1, 2 or 'x', 'y', 'z'" if dim == 3 else "0, 1 or 'x', 'y'"
        raise ValueError(f"direction must be {valid} in {dim}-D, got {d!r}")
    return int(d)


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
        Tetrahedra (``dim == 3``) or triangles in the xy-plane (``dim == 2``);
        quadratic cells (``tetra10``, ``triangle6``) contribute their vertices
        only (straight-sided cells).
    material : Material or str
        The material, or the name of a preset (:meth:`Material.preset`).
    order : {1, 2}
        Lagrange element order: 2 (default; P2, accurate in bending) or 1
        (P1, which locks in bending and needs fine meshes).
    mass : {"consistent", "lumped"}
        Consistent mass, or lumped: row sum for P1, HRZ (diagonal scaled to
        the element mass, Hinton–Rock–Zienkiewicz 1976) for P2.  Both keep the
        total mass exactly.
    clamp : str, sequence of int, callable or None
        Nodes whose displacements are fixed: a group name of ``mesh``
        (default ``"root"``), mesh node indices (or a boolean mask over the
        nodes), or a function of the node coordinates ``(n, 3) -> (n,) bool``.
        For P2, an edge dof is clamped when both end vertices are.  ``None``
        gives the unclamped (free-free) model.
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
        selects no node of the body, degenerate cells.
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
        thickness = _positive("thickness", thickness)
    elif thickness is not None:
        raise ValueError(f"thickness applies to 2-D models only; this mesh is 3-D (got thickness={thickness!r})")

    points = np.asarray(mesh.points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise ValueError(f"mesh.points must be a finite (n, 3) array, got shape {points.shape}")
    clamped = _clamp_nodes(mesh, points, clamp)

    cells = np.asarray(mesh.cells[mesh.body_type])[:, : dim + 1].astype(np.int64)
    if cells.min() < 0 or cells.max() >= points.shape[0]:
        raise ValueError(f"mesh cells refer to nodes outside 0..{points.shape[0] - 1}")
    used, local = np.unique(cells, return_inverse=True)
    local = local.reshape(cells.shape)
    if dim == 2:
        scale = np.abs(points[used, :2]).max()
        if np.abs(points[used, 2]).max() > 1e-12 * max(scale, 1e-300):
            raise ValueError("a 2-D mesh must lie in the xy-plane (z = 0)")
    corners = points[cells, :dim]
    cell_volume = np.abs(np.linalg.det(corners[:, 1:] - corners[:, :1])) / math.factorial(dim)
    flat = cell_volume <= DEGENERATE_RTOL * cell_volume.max()
    if flat.any():
        i = int(np.flatnonzero(flat)[0])
        raise ValueError(
            f"mesh has {int(flat.sum())} degenerate cell(s) (zero volume), e.g. cell {i} with nodes {cells[i].tolist()}"
        )
    p = points[used, :dim].T
    fe_mesh = (MeshTet if dim == 3 else MeshTri)(np.ascontiguousarray(p), np.ascontiguousarray(local.T))
    basis = CellBasis(fe_mesh, _ELEMENTS[dim, order]())
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
    scalar_clamped = np.zeros(n_scalar, dtype=bool)
    scalar_clamped[basis.nodal_dofs[0]] = vertex_clamped
    if order == 2:
        dofs2, ends = (basis.edge_dofs, fe_mesh.edges) if dim == 3 else (basis.facet_dofs, fe_mesh.facets)
        scalar_clamped[dofs2[0]] = vertex_clamped[ends].all(axis=0)

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


def _describe(clamp) -> str:
    if isinstance(clamp, str):
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


def natural_frequencies(model: FEModel, count: int, return_modes: bool = False):
    """The ``count`` lowest natural frequencies (Hz) of a clamped model.

    Shift-invert Lanczos (ARPACK ``eigsh``) about 0 with a sparse LDLᵀ of
    ``K`` (SuperLU, symmetric mode, minimum-degree ordering on ``K``'s
    pattern); no dense matrix is formed.

    Parameters
    ----------
    model : FEModel
    count : int
        Number of frequencies, ``1 <= count < model.n_dofs``.
    return_modes : bool
        Also return the mode shapes.

    Returns
    -------
    f : (count,) ndarray
        Frequencies ``√λ / 2π`` in Hz, ascending.
    phi : (n_dofs, count) ndarray
        M-normalised mode shapes (``φᵀMφ = I``), only if ``return_modes``.

    Raises
    ------
    ValueError
        ``count`` out of range; a model with rigid-body modes (no clamp, or a
        clamp that leaves a rotation free) or otherwise singular ``K``.
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    n = model.n_dofs
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or not 1 <= count < n:
        raise ValueError(f"count must be an integer with 1 <= count < {n} (the number of free dofs), got {count!r}")
    if model.rigid_modes:
        if model.clamped.size == 0:
            why = "the model is not clamped (no clamp?)"
        else:
            why = (f"the clamp ({model.clamped.size} node(s)) leaves {model.rigid_modes} rigid-body motion(s) free: "
                   "no clamp on some part of the mesh, or clamped nodes on one point or one line")
        raise ValueError(f"K is singular: {why}; clamp a face of every part")
    K = sp.csc_array(model.K)
    try:
        lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise ValueError(f"K is singular ({exc}): no clamp? a part of the mesh not connected to the clamp?") from None
    op = spla.LinearOperator(K.shape, matvec=lu.solve, dtype=float)
    lam, phi = spla.eigsh(model.K, k=int(count), M=model.M, sigma=0.0, which="LM", OPinv=op)
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    if not np.all(np.isfinite(lam)) or lam[0] <= 0:
        raise ValueError(
            f"K is not positive definite: eigenvalue {lam[0]:.3g} (a mechanism? degenerate cells?)"
        )
    f = np.sqrt(lam) / (2 * np.pi)
    return (f, phi) if return_modes else f


# ----------------------------------------------------------------------------- stage files

#: Format tag of the ``.npz`` files written by :func:`save_model`.
MODEL_FORMAT = "bladecase-femodel-1"


def sparse_to_arrays(name: str, A) -> dict[str, np.ndarray]:
    """A sparse matrix as CSR arrays ``name/data``, ``name/indices``, ``name/indptr``, ``name/shape``."""
    A = sp.csr_array(A)
    return {f"{name}/data": A.data, f"{name}/indices": A.indices, f"{name}/indptr": A.indptr,
            f"{name}/shape": np.array(A.shape)}


def sparse_from_arrays(data, name: str) -> sp.csr_array:
    """Inverse of :func:`sparse_to_arrays`."""
    return sp.csr_array((data[f"{name}/data"], data[f"{name}/indices"], data[f"{name}/indptr"]),
                        shape=tuple(int(s) for s in data[f"{name}/shape"]))


def model_to_arrays(model: FEModel, prefix: str = "") -> dict[str, np.ndarray]:
    """Everything of an :class:`FEModel` as named arrays (see :func:`save_model`)."""
    from .mesh import mesh_to_arrays

    out = {f"{prefix}format": np.array(MODEL_FORMAT)}
    out.update(sparse_to_arrays(f"{prefix}K", model.K))
    out.update(sparse_to_arrays(f"{prefix}M", model.M))
    d = model.dofs
    out.update({f"{prefix}dofs/node": d.node, f"{prefix}dofs/direction": d.direction,
                f"{prefix}dofs/coords": d.coords, f"{prefix}dofs/fe_index": d.fe_index,
                f"{prefix}dofs/n_total": np.array(d.n_total)})
    m = model.material
    out.update({f"{prefix}material": np.array([m.E, m.nu, m.rho]), f"{prefix}material_name": np.array(m.name),
                f"{prefix}order": np.array(model.order), f"{prefix}mass": np.array(model.mass),
                f"{prefix}thickness": np.array(np.nan if model.thickness is None else model.thickness),
                f"{prefix}plane": np.array(model.plane or ""), f"{prefix}clamped": model.clamped,
                f"{prefix}volume": np.array(model.volume), f"{prefix}rigid_modes": np.array(model.rigid_modes)})
    out.update(mesh_to_arrays(model.mesh, f"{prefix}mesh/"))
    return out


def model_from_arrays(data, prefix: str = "", source: str = "") -> FEModel:
    """Inverse of :func:`model_to_arrays`; ``ValueError`` if ``data`` is not a saved model."""
    from .mesh import mesh_from_arrays

    key = f"{prefix}format"
    if key not in data or str(data[key]) != MODEL_FORMAT:
        raise ValueError(f"{source or 'data'} is not a bladecase FE model file (expected format {MODEL_FORMAT!r}; "
                         "write one with 'bladecase assemble' or bladecase.fe.assembly.save_model)")
    E, nu, rho = (float(x) for x in data[f"{prefix}material"])
    thickness = float(data[f"{prefix}thickness"])
    dofs = DofMap(node=np.asarray(data[f"{prefix}dofs/node"]), direction=np.asarray(data[f"{prefix}dofs/direction"]),
                  coords=np.asarray(data[f"{prefix}dofs/coords"]), fe_index=np.asarray(data[f"{prefix}dofs/fe_index"]),
                  n_total=int(data[f"{prefix}dofs/n_total"]))
    return FEModel(
        K=sparse_from_arrays(data, f"{prefix}K"), M=sparse_from_arrays(data, f"{prefix}M"), dofs=dofs,
        mesh=mesh_from_arrays(data, f"{prefix}mesh/"),
        material=Material(E, nu, rho, str(data[f"{prefix}material_name"])),
        order=int(data[f"{prefix}order"]), mass=str(data[f"{prefix}mass"]),
        thickness=None if math.isnan(thickness) else thickness, plane=str(data[f"{prefix}plane"]) or None,
        clamped=np.asarray(data[f"{prefix}clamped"]), volume=float(data[f"{prefix}volume"]),
        rigid_modes=int(data[f"{prefix}rigid_modes"]),
    )


def save_model(model: FEModel, path) -> None:
    """Write an :class:`FEModel` (matrices, dof map, mesh, material) to a ``.npz`` file, atomically."""
    from ..io import atomic_path

    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **model_to_arrays(model))


def load_model(path) -> FEModel:
    """Read an :class:`FEModel` written by :func:`save_model`."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return model_from_arrays(data, source=str(path))
    except (OSError, EOFError, KeyError) as exc:
        raise ValueError(f"cannot read FE model file {str(path)!r}: {exc}") from None
