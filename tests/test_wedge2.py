"""Second-order wedges (issue 15): bladecase.fe.wedge_element's 15-node serendipity and 18-node Lagrange prisms.

The basis on the reference prism (partition of unity, Kronecker property, exact gradients, the polynomials each
space reproduces, conforming traces), the dof numbering of the 18-node element, its assembly against
scikit-fem's own assembler, the patch test on distorted prisms, and steel cantilevers of square section
(L/h = 20, clamped at x = 0) against Euler–Bernoulli ``f = 1.8751² / 2π · sqrt(EI / ρAL⁴)``.

Figures (``OPENBLAS_NUM_THREADS=1 .venv/bin/python -m pytest -q tests/test_wedge2.py``), first bending frequency,
relative to Euler–Bernoulli (whose own shear/rotary-inertia error here is about −0.2 %):

* prisms along the span (a triangulated section extruded, the blade-mesh case; 8 triangles in the section):
  order 1, 10 / 20 / 40 layers: +61.7 % / +20.6 % / +7.7 %; order 2 (15 nodes): +0.74 % / +0.31 % / +0.14 %;
  18 nodes: +0.58 % / +0.23 % / +0.11 %;
* prisms across (each hexahedron of a 20×2×2 grid cut in two): order 1 +19.5 %; order 2: 15 nodes +0.32 %,
  18 nodes +0.26 %; on the same grid hex20 +0.30 %, tet10 (6 per hexahedron) +0.36 %; 10×1×1: 15 nodes
  +1.07 %, 18 nodes +0.68 %, hex20 +1.02 %.
"""

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
from skfem import BilinearForm, CellBasis, ElementVector, MeshWedge1
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters, linear_elasticity
from skfem.quadrature import get_quadrature_line, get_quadrature_tri
from test_fe_elements import KUHN, ROOT, STEEL, WEDGES, euler_bernoulli, first_frequency, hex_beam, split

from bladecase.fe import assemble, load_mesh, natural_frequencies, node_operator, save_mesh
from bladecase.fe.cells import KINDS, element_name
from bladecase.fe.mesh import _register_types, from_meshio
from bladecase.fe.wedge_element import ElementWedge2, ElementWedgeS2, WedgeFaceDofs

ELEMENTS = {"serendipity": (ElementWedgeS2(), 15), "lagrange": (ElementWedge2(), 18)}
L_BEAM, H_BEAM = 0.1, 0.005


def _points(n, seed=0):
    """``n`` random points of the reference prism (3, n)."""
    rng = np.random.default_rng(seed)
    xy = rng.random((2, n))
    flip = xy.sum(axis=0) > 1
    xy[:, flip] = 1 - xy[:, flip]
    return np.vstack([xy, rng.random(n)])


def _values(element, n, X):
    """Values (n, q) and gradients (n, 3, q) of all basis functions at ``X``."""
    out = [element.lbasis(X, i) for i in range(n)]
    return np.array([v for v, _ in out]), np.array([g for _, g in out])


def _product_rule(degree):
    """Triangle × line quadrature of ``degree`` in each (as bladecase.fe.assembly builds for wedges)."""
    X, W = get_quadrature_tri(degree)
    Z, V = get_quadrature_line(degree)
    return np.vstack([np.tile(X, Z.shape[1]), np.repeat(Z, X.shape[1], axis=1)]), np.outer(V, W).ravel()


# ----------------------------------------------------------------------------- the reference element


@pytest.mark.parametrize("name", ELEMENTS)
def test_partition_of_unity_kronecker_and_gradients(name):
    element, n = ELEMENTS[name]
    assert element.doflocs.shape == (n, 3)
    V, _ = _values(element, n, element.doflocs.T)
    np.testing.assert_allclose(V, np.eye(n), atol=1e-15)  # Kronecker at the dof locations
    X = _points(200)
    V, G = _values(element, n, X)
    np.testing.assert_allclose(V.sum(axis=0), 1.0, atol=1e-14)
    np.testing.assert_allclose(G.sum(axis=0), 0.0, atol=1e-13)
    eps = 1e-6  # central differences (the functions have degree <= 4: error ~ eps², round-off ~ 1e-16/eps)
    for d in range(3):
        step = np.zeros((3, 1))
        step[d] = eps
        fd = (_values(element, n, X + step)[0] - _values(element, n, X - step)[0]) / (2 * eps)
        np.testing.assert_allclose(G[:, d], fd, atol=1e-8)
    assert np.abs(G).max() > 1  # not trivially zero


#: Monomials x^a y^b z^c of each space (serendipity: P2(x, y) ⊗ P1(z) ⊕ P1(x, y) ⊗ {z²}; Lagrange: P2 ⊗ P2).
_P2XY = [(a, b) for a in range(3) for b in range(3) if a + b <= 2]
SPACES = {"serendipity": [(a, b, c) for a, b in _P2XY for c in (0, 1)] + [(a, b, 2) for a, b in _P2XY if a + b <= 1],
          "lagrange": [(a, b, c) for a, b in _P2XY for c in (0, 1, 2)]}


@pytest.mark.parametrize("name", ELEMENTS)
def test_interpolation_reproduces_its_polynomials_and_no_more(name):
    element, n = ELEMENTS[name]
    assert len(SPACES[name]) == n
    X = _points(50, seed=1)
    V, G = _values(element, n, X)
    P = element.doflocs.T
    for a, b, c in SPACES[name]:
        coef = P[0] ** a * P[1] ** b * P[2] ** c
        np.testing.assert_allclose(coef @ V, X[0] ** a * X[1] ** b * X[2] ** c, atol=1e-14)
        dz = c * X[0] ** a * X[1] ** b * X[2] ** max(c - 1, 0)
        np.testing.assert_allclose(np.einsum("i,iq->q", coef, G[:, 2]), dz, atol=1e-13)
    for a, b, c in [(1, 1, 2), (3, 0, 0), (0, 0, 3)] if name == "serendipity" else [(3, 0, 0), (0, 0, 3)]:
        coef = P[0] ** a * P[1] ** b * P[2] ** c
        assert np.abs(coef @ V - X[0] ** a * X[1] ** b * X[2] ** c).max() > 1e-3  # outside the space


@pytest.mark.parametrize("name", ELEMENTS)
def test_traces_on_each_face_depend_on_its_own_dofs_only(name):
    """Conformity: on each face of the prism, the functions of the dofs off that face vanish."""
    element, n = ELEMENTS[name]
    t = np.random.default_rng(2).random((2, 30))
    faces = {  # a parametrisation of the face, and the test for a dof location on it
        "y=0": (np.vstack([t[0], 0 * t[0], t[1]]), lambda p: p[1] == 0),
        "x+y=1": (np.vstack([t[0], 1 - t[0], t[1]]), lambda p: np.isclose(p[0] + p[1], 1)),
        "x=0": (np.vstack([0 * t[0], t[0], t[1]]), lambda p: p[0] == 0),
        "z=0": (np.vstack([t[0] * (1 - t[1]), t[1], 0 * t[0]]), lambda p: p[2] == 0),
        "z=1": (np.vstack([t[0] * (1 - t[1]), t[1], 1 + 0 * t[0]]), lambda p: p[2] == 1),
    }
    for face, (X, on) in faces.items():
        own = on(element.doflocs.T)
        assert own.sum() == (6 if face.startswith("z") else (8 if name == "serendipity" else 9)), face
        V, _ = _values(element, n, X)
        assert np.abs(V[~own]).max() < 1e-15, face
        np.testing.assert_allclose(V[own].sum(axis=0), 1.0, atol=1e-14)


def test_face_dofs_of_the_lagrange_prism():
    """One dof per vertex, edge and quadrilateral facet; neighbours share their face's dof; scikit-fem's own numbering
    (facet dofs on the triangles too) is refused with the way out."""
    prisms = split(hex_beam(1.0, 1.0, (2, 2, 1)), WEDGES)
    m = MeshWedge1(prisms.points.T.copy(), prisms.cells_dict["wedge"].T.copy())
    dofs = WedgeFaceDofs(m)
    quad = np.all(np.diff(np.sort(m.facets, axis=0), axis=0) > 0, axis=0)  # triangles repeat a vertex
    assert dofs.N == m.nvertices + m.nedges + quad.sum()
    np.testing.assert_array_equal(dofs.facet_index, np.flatnonzero(quad))
    basis = CellBasis(m, ElementWedge2(), dofs=dofs)
    centres = m.p[:, m.facets[:, dofs.facet_index]].mean(axis=1)
    np.testing.assert_allclose(basis.doflocs[:, dofs.facet_dofs[0]], centres, atol=1e-15)
    inner = dofs.facet_index[m.f2t[1, dofs.facet_index] >= 0]
    assert inner.size > 0
    for f in inner:  # both cells sharing an inner quadrilateral facet hold its dof
        k = np.searchsorted(dofs.facet_index, f)
        cells = m.f2t[:, f]
        assert all(dofs.facet_dofs[0, k] in basis.element_dofs[15:, c] for c in cells)
    with pytest.raises(ValueError, match=r"ElementWedge2 has 18 basis functions.*dofs=WedgeFaceDofs\(mesh\)"):
        CellBasis(m, ElementWedge2())


# ----------------------------------------------------------------------------- meshes


def distorted_wedges(n=3, amplitude=0.15, seed=3):
    """A unit cube of n³ hexahedra cut into prisms, its interior nodes moved at random (``amplitude`` × spacing):
    prisms with skewed, non-parallel sides."""
    m = hex_beam(1.0, 1.0, (n, n, n))
    pts = m.points.copy()
    inner = np.all((pts > 1e-9) & (pts < 1 - 1e-9), axis=1)
    pts[inner] += amplitude / n * np.random.default_rng(seed).uniform(-1, 1, (inner.sum(), 3))
    return split(meshio.Mesh(pts, m.cells), WEDGES)


def quadratic(m, btype):
    """The wedge mesh ``m`` with the extra nodes of ``btype`` (wedge15 or wedge18) at the straight entities'
    centres, each shared node once (meshio/VTK order)."""
    _register_types()  # meshio 5.3 lacks the dimension of the 15/18-node wedges
    cells = m.cells_dict["wedge"]
    extra = KINDS[btype].parents[6:]
    ent = np.full((len(cells), len(extra), 4), -1)
    for j, p in enumerate(extra):
        ent[:, j, : len(p)] = np.sort(cells[:, list(p)], axis=1)
    uniq, inv = np.unique(ent.reshape(-1, 4), axis=0, return_inverse=True)
    mask = uniq >= 0
    centres = (m.points[np.where(mask, uniq, 0)] * mask[..., None]).sum(axis=1) / mask.sum(axis=1)[:, None]
    body = np.hstack([cells, len(m.points) + inv.reshape(len(cells), -1)])
    return meshio.Mesh(np.vstack([m.points, centres]), [(btype, body)])


def extruded_beam(L, h, nx, ns):
    """Prisms along x: the square section [0, h]² cut into 2 ns² triangles, extruded in ``nx`` layers."""
    y = np.linspace(0, h, ns + 1)
    section = np.stack(np.meshgrid(y, y, indexing="ij"), axis=-1).reshape(-1, 2)
    idx = np.arange(len(section)).reshape(ns + 1, ns + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tri = np.r_[np.c_[a, b, c], np.c_[a, c, d]]  # counter-clockwise in (y, z): positive prisms along +x
    k = len(section)
    points = np.c_[np.repeat(np.linspace(0, L, nx + 1), k), np.tile(section, (nx + 1, 1))]
    cells = (np.c_[tri, tri + k][None] + k * np.arange(nx)[:, None, None]).reshape(-1, 6)
    return meshio.Mesh(points, [("wedge", cells)])


# ----------------------------------------------------------------------------- assembly


def test_serendipity_assembly_equals_scikit_fem_own():
    """Our batched K, M on ElementWedgeS2 equal scikit-fem's BilinearForm assembly on ElementVector(ElementWedgeS2)
    (same product quadrature), on skewed prisms."""
    mesh = from_meshio(distorted_wedges(2))
    model = assemble(mesh, STEEL, order=2, clamp=None)
    sk = MeshWedge1(mesh.points.T.copy(), mesh.cells["wedge"].T.copy())
    quadrature = _product_rule(5)
    basis = CellBasis(sk, ElementVector(ElementWedgeS2()), quadrature=quadrature)
    K = linear_elasticity(*lame_parameters(STEEL.E, STEEL.nu)).assemble(basis)
    M = BilinearForm(lambda u, v, w: STEEL.rho * dot(u, v)).assemble(basis)
    assert model.n_dofs == K.shape[0] == 3 * (sk.nvertices + sk.nedges)
    assert sp.linalg.norm(model.K - K) < 1e-10 * sp.linalg.norm(K)
    assert sp.linalg.norm(model.M - M) < 1e-12 * sp.linalg.norm(M)


def test_lagrange_assembly_equals_scikit_fem_own_on_face_dofs():
    """The 18-node model on a wedge18 mesh: its x-x block of K and its scalar mass equal scikit-fem's assembly on
    the scalar basis with WedgeFaceDofs (dofs numbered alike)."""
    mesh = from_meshio(quadratic(distorted_wedges(2), "wedge18"))
    model = assemble(mesh, STEEL, order=2, clamp=None)
    sk = MeshWedge1(mesh.points[:mesh.cells["wedge18"].max() + 1].T.copy(), mesh.cells["wedge18"][:, :6].T.copy())
    quadrature = _product_rule(5)
    basis = CellBasis(sk, ElementWedge2(), quadrature=quadrature, dofs=WedgeFaceDofs(sk))
    lam, mu = lame_parameters(STEEL.E, STEEL.nu)
    Kxx = BilinearForm(lambda u, v, w: (lam + 2 * mu) * u.grad[0] * v.grad[0]
                       + mu * (u.grad[1] * v.grad[1] + u.grad[2] * v.grad[2])).assemble(basis)
    Ms = BilinearForm(lambda u, v, w: STEEL.rho * u * v).assemble(basis)
    assert model.n_dofs == 3 * basis.N == 3 * (sk.nvertices + sk.nedges + WedgeFaceDofs(sk).facet_index.size)
    assert sp.linalg.norm(model.K[0::3, 0::3] - Kxx) < 1e-10 * sp.linalg.norm(Kxx)
    assert sp.linalg.norm(model.M[0::3, 0::3] - Ms) < 1e-12 * sp.linalg.norm(Ms)


@pytest.mark.parametrize("btype", ["wedge15", "wedge18"])
def test_quadrature_is_exact_on_right_prisms(btype):
    """On right prisms (constant Jacobian) the degree-5 triangle × line rule of order 2 integrates mass and stiffness
    exactly: the same matrices as a degree-11 rule."""
    mesh = from_meshio(quadratic(extruded_beam(0.02, 0.004, 3, 2), btype))
    model = assemble(mesh, STEEL, order=2, clamp=None)
    n = int(mesh.cells[btype][:, :6].max()) + 1
    sk = MeshWedge1(mesh.points[:n].T.copy(), mesh.cells[btype][:, :6].T.copy())
    element = ElementWedge2() if btype == "wedge18" else ElementWedgeS2()
    dofs = WedgeFaceDofs(sk) if btype == "wedge18" else None
    basis = CellBasis(sk, element, quadrature=_product_rule(11), dofs=dofs)
    lam, mu = lame_parameters(STEEL.E, STEEL.nu)
    Kzz = BilinearForm(lambda u, v, w: (lam + 2 * mu) * u.grad[2] * v.grad[2]
                       + mu * (u.grad[0] * v.grad[0] + u.grad[1] * v.grad[1])).assemble(basis)
    Ms = BilinearForm(lambda u, v, w: STEEL.rho * u * v).assemble(basis)
    assert sp.linalg.norm(model.K[2::3, 2::3] - Kzz) < 1e-12 * sp.linalg.norm(Kzz)
    assert sp.linalg.norm(model.M[2::3, 2::3] - Ms) < 1e-13 * sp.linalg.norm(Ms)
    coarse = CellBasis(sk, element, quadrature=_product_rule(3), dofs=dofs)  # too low for P2 × P2 products
    assert sp.linalg.norm(BilinearForm(lambda u, v, w: STEEL.rho * u * v).assemble(coarse) - Ms) \
        > 1e-6 * sp.linalg.norm(Ms)


@pytest.mark.parametrize("btype, order", [("wedge", 1), ("wedge", 2), ("wedge18", 2)])
def test_patch_test_and_rigid_motions_on_skewed_prisms(btype, order):
    """A linear displacement imposed on the boundary of a cube of skewed prisms is reproduced exactly inside, with
    the exact strain energy; the six rigid motions cost no energy (K r ≈ 0) and the mass is exact."""
    m = distorted_wedges(3)
    mesh = from_meshio(m if btype == "wedge" else quadratic(m, btype))
    model = assemble(mesh, STEEL, order=order, clamp=None, mass="consistent")
    assert model.rigid_modes == 6
    x = model.dofs.coords
    A = np.array([[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.25, 0.0, 0.7]]) * 1e-3
    u_exact = (x @ A.T + [1e-4, -2e-4, 3e-4])[np.arange(model.n_dofs), model.dofs.direction]
    boundary = np.any((x < 1e-12) | (x > 1 - 1e-12), axis=1)
    inner = ~boundary
    assert inner.sum() > 0
    K = model.K.tocsc()
    rhs = -K[inner][:, boundary] @ u_exact[boundary]
    u_inner = sp.linalg.spsolve(K[inner][:, inner], rhs)
    np.testing.assert_allclose(u_inner, u_exact[inner], rtol=0, atol=1e-12 * np.abs(u_exact).max())
    eps = 0.5 * (A + A.T)
    lam, mu = STEEL.lame(None)
    sigma = lam * np.trace(eps) * np.eye(3) + 2 * mu * eps
    energy = u_exact @ (model.K @ u_exact)
    assert energy == pytest.approx(np.sum(sigma * eps) * 1.0, rel=1e-11)  # volume of the unit cube
    rigid = np.zeros((model.n_dofs, 6))
    d = model.dofs.direction
    for c in range(3):
        rigid[d == c, c] = 1.0
    for k, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):  # rotation about axis k: u_i = -x_j, u_j = x_i
        rigid[d == i, 3 + k] = -x[d == i, j]
        rigid[d == j, 3 + k] = x[d == j, i]
    scale = sp.linalg.norm(model.K) * np.linalg.norm(rigid, axis=0)
    assert np.all(np.linalg.norm(model.K @ rigid, axis=0) < 1e-12 * scale)
    assert rigid[:, 0] @ (model.M @ rigid[:, 0]) == pytest.approx(STEEL.rho * 1.0, rel=1e-12)
    lumped = assemble(mesh, STEEL, order=order, clamp=None, mass="lumped")
    assert lumped.M.diagonal().min() > 0 and lumped.M.diagonal()[d == 0].sum() == pytest.approx(STEEL.rho, rel=1e-12)


def test_order_two_clamp_fixes_every_dof_of_the_root_face():
    """Edge and quadrilateral-face dofs whose vertices are all clamped are clamped: every dof on x = 0, no other."""
    for btype in ("wedge15", "wedge18"):
        mesh = from_meshio(quadratic(split(hex_beam(0.04, 0.01, (4, 2, 2)), WEDGES), btype))
        free = assemble(mesh, STEEL, order=2, clamp=None)
        clamped = assemble(mesh, STEEL, order=2, clamp=ROOT)
        assert clamped.dofs.coords[:, 0].min() > 0
        assert free.n_dofs - clamped.n_dofs == np.sum(free.dofs.coords[:, 0] == 0) > 3 * 9


# ----------------------------------------------------------------------------- cantilevers


def test_extruded_section_cantilever_converges_at_order_two():
    """Prisms along the span: order 2 within 1 % of Euler–Bernoulli on 10 layers, < 0.5 % on 20; order 1 locks."""
    f_eb = euler_bernoulli(L_BEAM, H_BEAM)
    err = {(nx, order, btype): first_frequency(quadratic(m, btype) if btype != "wedge" else m, order) / f_eb - 1
           for nx in (10, 20, 40) for m in [extruded_beam(L_BEAM, H_BEAM, nx, 2)]
           for order, btype in ((1, "wedge"), (2, "wedge"), (2, "wedge18"))}
    for nx in (10, 20, 40):
        assert err[nx, 1, "wedge"] > 20 * err[nx, 2, "wedge"] > 0  # +61.7 / +20.6 / +7.7 % vs +0.74 / +0.31 / +0.14 %
        assert 0 < err[nx, 2, "wedge18"] < err[nx, 2, "wedge"]  # 18 nodes: richer space, lower (Rayleigh-Ritz)
    assert err[10, 2, "wedge"] < 0.01 and err[20, 2, "wedge"] < 0.005 and err[40, 2, "wedge"] < 0.002
    assert err[10, 2, "wedge"] > 2 * err[20, 2, "wedge"] and err[20, 2, "wedge"] > 2 * err[40, 2, "wedge"]
    assert err[10, 1, "wedge"] > 2.5 * err[20, 1, "wedge"] and err[20, 1, "wedge"] > 2.5 * err[40, 1, "wedge"]  # h²


def test_wedges_hex20_and_tet10_agree_on_the_same_beam():
    """A 20×2×2 grid of hexahedra: hex20, each cut in two prisms (15 and 18 nodes), in six P2 tetrahedra."""
    f_eb = euler_bernoulli(L_BEAM, H_BEAM)
    grid = (20, 2, 2)
    prisms = split(hex_beam(L_BEAM, H_BEAM, grid), WEDGES)
    f = {"hex20": first_frequency(hex_beam(L_BEAM, H_BEAM, grid, "hexahedron20"), 2),
         "tet10": first_frequency(split(hex_beam(L_BEAM, H_BEAM, grid), KUHN), 2),
         "wedge15": first_frequency(quadratic(prisms, "wedge15"), 2),
         "wedge18": first_frequency(quadratic(prisms, "wedge18"), 2),
         "wedge order 1": first_frequency(prisms, 1)}
    assert f["wedge15"] / f["hex20"] - 1 == pytest.approx(0, abs=0.001)  # +0.32 % vs +0.30 %
    assert f["wedge18"] / f["hex20"] - 1 == pytest.approx(0, abs=0.001)  # +0.26 %
    assert f["tet10"] / f["wedge15"] - 1 == pytest.approx(0, abs=0.001)  # +0.36 %
    assert f["wedge18"] < f["wedge15"]
    assert abs(f["wedge15"] / f_eb - 1) < 0.005 and f["wedge order 1"] / f_eb - 1 > 0.15


@pytest.mark.parametrize("btype, suffix", [("wedge15", ".vtu"), ("wedge15", ".inp"), ("wedge18", ".vtu")])
def test_quadratic_wedge_file_loads_and_runs_at_order_two(tmp_path, btype, suffix):
    """A wedge15 (wedge18) mesh file: its model at order 2 uses ElementWedgeS2 (ElementWedge2) on the straight
    cells, the same as the 6-node mesh's (ElementWedgeS2: same frequencies); every mesh node, midside and face
    centres included, gets the FE field (a quadratic field exactly at order 2, a linear one at order 1)."""
    prisms = split(hex_beam(0.04, 0.01, (8, 2, 1)), WEDGES)
    meshio.write(tmp_path / f"m{suffix}", quadratic(prisms, btype))
    mesh = load_mesh(tmp_path / f"m{suffix}")
    assert mesh.body_type == btype and element_name(btype, 2) == ("ElementWedgeS2" if btype == "wedge15"
                                                                  else "ElementWedge2")
    model = assemble(mesh, STEEL, order=2, clamp=ROOT)
    f = natural_frequencies(model, 3)
    f6 = natural_frequencies(assemble(from_meshio(prisms), STEEL, order=2, clamp=ROOT), 3)
    if btype == "wedge15":
        np.testing.assert_allclose(f, f6, rtol=1e-9)
    else:  # the 18-node space contains the 15-node one: every frequency lower
        assert np.all(f < f6) and np.all(f > 0.99 * f6)

    def field(x):  # quadratic in (x, y); vanishes at x = 0
        return np.c_[0.1 * x[:, 0], -0.2 * x[:, 0] + 3 * x[:, 0] * x[:, 1], 0.05 * x[:, 0] + 7 * x[:, 0] ** 2]

    u = field(model.dofs.coords)[np.arange(model.n_dofs), model.dofs.direction]
    nodal = (node_operator(model) @ u).reshape(-1, 3)
    np.testing.assert_allclose(nodal, field(mesh.points), atol=1e-15)
    linear = assemble(mesh, STEEL, order=1, clamp=ROOT)
    x = linear.dofs.coords
    u1 = (np.c_[0.1 * x[:, 0], -0.2 * x[:, 0], 0.3 * x[:, 0]])[np.arange(linear.n_dofs), linear.dofs.direction]
    np.testing.assert_allclose((node_operator(linear) @ u1).reshape(-1, 3),
                               np.c_[0.1, -0.2, 0.3] * mesh.points[:, :1], atol=1e-15)
    save_mesh(mesh, tmp_path / "again.vtu")
    assert load_mesh(tmp_path / "again.vtu").body_type == btype
