"""Hexahedra, wedges and quadrilaterals (issue 15): node orderings, checks, frequencies against beam theory.

Cantilevers of square section clamped at ``x = 0`` (steel), meshed here with numpy in meshio (VTK) node order:

* slender, L/h = 20: first bending frequency vs Euler–Bernoulli ``f = 1.8751² / 2π · sqrt(EI / ρAL⁴)``;
* stubby, L/h = 5: vs Timoshenko (Cowper's κ = 10(1+ν)/(12+11ν)), the exact root of the frequency equation.

Figures (``OPENBLAS_NUM_THREADS=1 .venv/bin/python -m pytest -q tests/test_fe_elements.py``), relative errors:
hex8 (1st order) 20×2×2: +19.8 %, 40×4×4: +5.4 %; hex20 10×1×1: +1.02 %; hex27 10×1×1: +0.61 %;
hex8 mesh with serendipity order 2, 20×2×2: +0.30 % (vs Euler–Bernoulli, whose own shear/rotary-inertia
error here is −0.20 %); stubby hex20 10×2×2: +1.37 % vs Timoshenko (+1.02 % at 20×4×4: the 3-D root,
which blocks the Poisson contraction, stiffens it), −1.65 % vs Euler–Bernoulli; wedges (2 per hexahedron,
order 1) 20×2×2: +19.5 %, 40×4×4: +5.5 % (order 2, 15-node
serendipity: +0.32 % at 20×2×2, tests/test_wedge2.py); P2 tetrahedra (6 per hexahedron) 20×2×2: +0.36 % (hex +0.30 %);
plane-stress strip: quad 20×2: +18.7 %, 80×8: +1.16 %; quad8 10×1: +0.39 %; quad9 10×1: +0.10 %.
"""

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq

from bladecase import log
from bladecase.fe import Material, assemble, load_mesh, natural_frequencies, node_operator, save_mesh
from bladecase.fe.cells import GMSH_WEDGE18, KINDS, element_name
from bladecase.fe.mesh import from_meshio
from bladecase.fe.quality import corner_jacobians

STEEL = Material.preset("steel")
ROOT = {"plane": [0, 0, 0, 1, 0, 0]}
_CUBE = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])


def box(sizes, n, btype):
    """A structured box [0, sizes[0]] × … of ``btype`` cells (``n`` cells per side), meshio node order."""
    q = KINDS[btype].order
    unit = _CUBE if len(n) == 3 else _CUBE[:4, :2]
    axes = [np.linspace(0, s, q * k + 1) for s, k in zip(sizes, n)]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(n))
    idx = np.arange(len(pts)).reshape([q * k + 1 for k in n])
    start = [q * a.ravel() for a in np.meshgrid(*[np.arange(k) for k in n], indexing="ij")]
    offsets = [(q * unit[list(p)].mean(axis=0)).astype(int) for p in KINDS[btype].parents]
    cells = np.stack([idx[tuple(s + o for s, o in zip(start, off))] for off in offsets], axis=1)
    used, cells = np.unique(cells, return_inverse=True)
    return meshio.Mesh(pts[used], [(btype, cells.reshape(-1, len(offsets)))])


def hex_beam(L, h, n, btype="hexahedron"):
    return box((L, h, h), n, btype)


def split(m, parts):
    """Each hexahedron of ``m`` cut into cells given by corner lists (tetrahedra are oriented positively)."""
    hexa = m.cells_dict["hexahedron"]
    cells = np.vstack([hexa[:, list(p)] for p in parts])
    if cells.shape[1] == 4:
        x = m.points[cells]
        neg = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0]) < 0
        cells[neg] = cells[neg][:, [0, 2, 1, 3]]
    return meshio.Mesh(m.points, [("tetra" if cells.shape[1] == 4 else "wedge", cells)])


WEDGES = [(0, 1, 2, 4, 5, 6), (0, 2, 3, 4, 6, 7)]
KUHN = [(0, 1, 2, 6), (0, 1, 5, 6), (0, 3, 2, 6), (0, 3, 7, 6), (0, 4, 5, 6), (0, 4, 7, 6)]


def euler_bernoulli(L, h, mat=STEEL):
    return 1.875104068711961**2 / (2 * np.pi) * np.sqrt(mat.E * h**4 / 12 / (mat.rho * h * h * L**4))


def timoshenko(L, h, mat=STEEL):
    """First bending frequency of a Timoshenko cantilever of square section (exact root, Cowper's κ)."""
    E, nu, rho = mat.E, mat.nu, mat.rho
    A, I = h * h, h**4 / 12
    kGA = 10 * (1 + nu) / (12 + 11 * nu) * E / (2 * (1 + nu)) * A

    def det(w):  # w = cosh, sinh (α) and cos, sin (β) terms; BCs w = ψ = 0 at 0, ψ' = w' - ψ = 0 at L
        a2, a1, a0 = E * I * kGA, (kGA * rho * I + rho * A * E * I) * w**2, rho * A * w**2 * (rho * I * w**2 - kGA)
        r = np.sqrt(a1**2 - 4 * a2 * a0)
        al, be = np.sqrt((r - a1) / (2 * a2)), np.sqrt((a1 + r) / (2 * a2))
        c, d = (kGA * al**2 + rho * A * w**2) / (kGA * al), (rho * A * w**2 - kGA * be**2) / (kGA * be)
        ch, sh, co, si = np.cosh(al * L), np.sinh(al * L), np.cos(be * L), np.sin(be * L)
        return np.linalg.det([[1, 0, 1, 0], [0, c, 0, -d], [c * al * ch, c * al * sh, d * be * co, d * be * si],
                              [(al - c) * sh, (al - c) * ch, -(be + d) * si, (be + d) * co]])

    w = 2 * np.pi * euler_bernoulli(L, h, mat) * np.linspace(0.5, 1.05, 200)
    v = np.array([det(x) for x in w])
    i = np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))[0]
    return brentq(det, w[i], w[i + 1]) / (2 * np.pi)


def first_frequency(m, order, source="beam"):
    return natural_frequencies(assemble(from_meshio(m, source=source), STEEL, order=order, clamp=ROOT), 1)[0]


# ----------------------------------------------------------------------------- orderings


@pytest.mark.parametrize("order", [1, 2])
def test_hex_ordering_gives_scikit_fem_own_matrices(order):
    """meshio order → skfem order: our K, M equal scikit-fem's on its own MeshHex (through skfem.io.meshio)."""
    from skfem import Basis, BilinearForm, ElementHex1, ElementHexS2, ElementVector, MeshHex, condense
    from skfem.helpers import dot
    from skfem.io.meshio import to_meshio
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    sk = MeshHex.init_tensor(np.linspace(0, 0.03, 4), np.linspace(0, 0.01, 3), np.linspace(0, 0.005, 2))
    bend = 0.001 * np.sin(7 * sk.p[[1, 2, 0]] / 0.01) * sk.p[0] / 0.03  # distorted (x = 0 kept): no symmetry
    sk = type(sk)(sk.p + bend, sk.t)
    model = assemble(from_meshio(to_meshio(sk)), STEEL, order=order, clamp=ROOT)
    basis = Basis(sk, ElementVector((ElementHex1 if order == 1 else ElementHexS2)()), intorder=2 * order + 1)
    K = linear_elasticity(*lame_parameters(STEEL.E, STEEL.nu)).assemble(basis)
    M = BilinearForm(lambda u, v, w: STEEL.rho * dot(u, v)).assemble(basis)
    D = basis.get_dofs(lambda x: x[0] < 1e-12).all()
    K, M = condense(K, M, D=D, expand=False)
    f_ours = natural_frequencies(model, 4)
    lam = np.sort(np.real(sp.linalg.eigsh(K, 4, M, sigma=0)[0]))
    np.testing.assert_allclose(f_ours, np.sqrt(lam) / (2 * np.pi), rtol=1e-9)
    assert model.n_dofs == K.shape[0]


def test_gmsh_orderings_of_second_order_cells_match_the_tables():
    """Every extra node of gmsh's hexahedron20/27 and wedge15/18 (read by meshio) sits at its parents' mean."""
    gmsh = pytest.importorskip("gmsh")
    import tempfile

    for incomplete, btype, wtype in [(1, "hexahedron20", "wedge15"), (0, "hexahedron27", "wedge18")]:
        gmsh.initialize(["", "-v", "0"], readConfigFiles=False, interruptible=False)  # keeps SIGINT
        try:
            gmsh.model.add("box")
            r = gmsh.model.occ.addRectangle(0, 0, 0, 1.0, 0.2)
            s = gmsh.model.occ.addRectangle(1, 0, 0, 0.2, 0.2)
            gmsh.model.occ.synchronize()
            gmsh.model.mesh.setTransfiniteSurface(r)
            gmsh.model.mesh.setRecombine(2, r)
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1)
            gmsh.model.occ.extrude([(2, r)], 0, 0, 0.1, numElements=[2], recombine=True)
            gmsh.model.occ.extrude([(2, s)], 0, 0, 0.1, numElements=[2], recombine=True)
            gmsh.model.occ.synchronize()
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", incomplete)
            gmsh.model.mesh.generate(3)
            gmsh.model.mesh.setOrder(2)
            with tempfile.TemporaryDirectory() as folder:
                gmsh.write(f"{folder}/m.msh")
                from bladecase.fe.mesh import _register_types
                _register_types()
                m = meshio.read(f"{folder}/m.msh")
        finally:
            gmsh.finalize()
        for t in (btype, wtype):
            cells = m.cells_dict[t]
            if t == "wedge18":
                cells = cells[:, list(GMSH_WEDGE18)]  # meshio 5.3 leaves gmsh's order
            mids = np.stack([m.points[cells[:, list(p)]].mean(axis=1) for p in KINDS[t].parents], axis=1)
            np.testing.assert_allclose(m.points[cells], mids, atol=1e-12)
            if t == "wedge18":  # from_meshio recognises gmsh's order and converts it
                read = from_meshio(meshio.Mesh(m.points, [(t, m.cells_dict[t])]), source="w18").cells[t]
                np.testing.assert_array_equal(read, cells)


# ----------------------------------------------------------------------------- frequencies


def test_slender_hex_cantilever_against_euler_bernoulli():
    L, h = 0.1, 0.005
    f_eb = euler_bernoulli(L, h)
    err = {key: first_frequency(hex_beam(L, h, n, t), order) / f_eb - 1 for key, (t, order, n) in {
        "hex8 coarse": ("hexahedron", 1, (20, 2, 2)), "hex8 fine": ("hexahedron", 1, (40, 4, 4)),
        "hex20": ("hexahedron20", 2, (10, 1, 1)), "hex27": ("hexahedron27", 2, (10, 1, 1)),
        "hex8 mesh, order 2": ("hexahedron", 2, (20, 2, 2))}.items()}
    assert 0.15 < err["hex8 coarse"] < 0.25 and 0 < err["hex8 fine"] < 0.06  # first order: locks, converges (h²)
    assert err["hex8 fine"] < err["hex8 coarse"] / 3
    assert 0 < err["hex20"] < 0.0125 and 0 < err["hex27"] < 0.008  # one element through the thickness
    assert abs(err["hex8 mesh, order 2"]) < 0.004


def test_stubby_hex_cantilever_against_timoshenko():
    L, h = 0.05, 0.01
    f = first_frequency(hex_beam(L, h, (10, 2, 2), "hexahedron20"), 2)
    assert f / timoshenko(L, h) - 1 == pytest.approx(0.0137, abs=0.003)  # 3-D root: slightly stiffer
    assert f / euler_bernoulli(L, h) - 1 < -0.012  # shear flexibility: below Euler-Bernoulli


def test_timoshenko_reference_tends_to_euler_bernoulli():
    assert timoshenko(1.0, 0.001) / euler_bernoulli(1.0, 0.001) == pytest.approx(1, abs=1e-5)


def test_wedge_cantilever_converges_and_hex_tet_agree():
    L, h = 0.1, 0.005
    f_eb = euler_bernoulli(L, h)
    coarse = first_frequency(split(hex_beam(L, h, (20, 2, 2)), WEDGES), 1) / f_eb - 1
    fine = first_frequency(split(hex_beam(L, h, (40, 4, 4)), WEDGES), 1) / f_eb - 1
    assert 0 < fine < coarse / 3 and fine < 0.08
    f_hex = first_frequency(hex_beam(L, h, (20, 2, 2)), 2)
    f_tet = first_frequency(split(hex_beam(L, h, (20, 2, 2)), KUHN), 2)
    assert f_tet / f_hex - 1 == pytest.approx(0, abs=0.01)
    assert f_hex / f_eb - 1 == pytest.approx(0, abs=0.004)


def test_planar_quads_against_euler_bernoulli():
    L, h, t = 0.1, 0.005, 0.002
    f_eb = euler_bernoulli(L, h)  # in-plane bending of a plane-stress strip: EI = E t h³/12, ρA = ρ t h

    err = {}
    for btype, order, n in [("quad", 1, (20, 2)), ("quad", 1, (80, 8)), ("quad8", 2, (10, 1)), ("quad9", 2, (10, 1))]:
        mesh = from_meshio(box((L, h), n, btype), source=btype)
        model = assemble(mesh, STEEL, order=order, clamp={"plane": [0, 0, 1, 0]}, thickness=t)
        err[btype, n] = natural_frequencies(model, 1)[0] / f_eb - 1
    assert err["quad", (80, 8)] < err["quad", (20, 2)] / 10 and 0 < err["quad", (80, 8)] < 0.015  # h²
    assert abs(err["quad8", (10, 1)]) < 0.01 and abs(err["quad9", (10, 1)]) < 0.01


def test_node_operator_on_extra_nodes_of_hexahedra():
    """A linear displacement field is reproduced at every node of hex20/hex27 meshes, orders 1 and 2."""
    for btype in ("hexahedron20", "hexahedron27"):
        mesh = from_meshio(hex_beam(0.04, 0.01, (4, 2, 1), btype))
        for order in (1, 2):
            model = assemble(mesh, STEEL, order=order, clamp=ROOT)
            u = _linear(model.dofs.coords)[np.arange(model.n_dofs), model.dofs.direction]
            nodal = (node_operator(model) @ u).reshape(-1, 3)
            np.testing.assert_allclose(nodal, _linear(mesh.points), atol=1e-15)


def _linear(x):
    """A linear displacement field vanishing on x = 0."""
    return np.c_[0.1 * x[:, 0], -0.2 * x[:, 0], 0.05 * x[:, 0] + 0.3 * x[:, 0] * 0]


# ----------------------------------------------------------------------------- checks


def _one_hex(points, btype="hexahedron"):
    n = KINDS[btype].n_nodes
    return meshio.Mesh(points, [(btype, np.arange(n)[None])])


def test_hexahedron_checks():
    cube = _CUBE.astype(float)
    assert from_meshio(_one_hex(cube)).body_type == "hexahedron"
    with pytest.raises(ValueError, match=r"1 inverted hexahedron .*negative Jacobian at every corner.*opposite node"):
        from_meshio(_one_hex(cube[[0, 3, 2, 1, 4, 7, 6, 5]]), source="mirror")
    with pytest.raises(ValueError, match=r"1 twisted or collapsed hexahedron .*first: element 0, nodes \[0, 1, 2, 3"):
        from_meshio(_one_hex(cube[[0, 1, 3, 2, 4, 5, 6, 7]]), source="twisted")  # two corners swapped
    flat = cube.copy()
    flat[4:, 2] = 0.0
    with pytest.raises(ValueError, match=r"1 degenerate hexahedron"):
        from_meshio(meshio.Mesh(np.vstack([cube + [2, 0, 0], flat]),
                                [("hexahedron", np.array([np.arange(8), np.arange(8, 16)]))]))
    mids = np.array([cube[list(p)].mean(axis=0) for p in KINDS["hexahedron20"].parents[8:]])
    mids[0] = [1.5, 0, 0]  # midside node of edge (0, 1) beyond corner 1
    with pytest.raises(ValueError, match=r"1 inverted curved hexahedron20 .*corner Jacobians \[5, -3, 1"):
        from_meshio(_one_hex(np.vstack([cube, mids]), "hexahedron20"))


def test_reversed_wedges_and_quads_are_reoriented_mixed_are_not():
    m = split(hex_beam(0.02, 0.01, (2, 1, 1)), WEDGES)
    reversed_ = m.cells[0].data[:, [0, 2, 1, 3, 5, 4]]
    mesh = from_meshio(meshio.Mesh(m.points, [("wedge", reversed_)]))
    assert (corner_jacobians(mesh.points, mesh.cells["wedge"], "wedge") > 0).all()
    mixed = reversed_.copy()
    mixed[0] = m.cells[0].data[0]
    with pytest.raises(ValueError, match=r"3 inverted wedge .*first: element 1"):
        from_meshio(meshio.Mesh(m.points, [("wedge", mixed)]))
    quad8 = meshio.Mesh(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [.5, 0], [1, .5], [.5, 1], [0, .5]]),
                        [("quad8", np.array([[0, 3, 2, 1, 7, 6, 5, 4]]))])
    np.testing.assert_array_equal(from_meshio(quad8).cells["quad8"][0], np.arange(8))


def test_mixed_body_types_are_refused_with_counts():
    hexa = hex_beam(0.02, 0.01, (2, 1, 1))
    wedges = split(hex_beam(0.02, 0.01, (2, 1, 1)), WEDGES)
    both = meshio.Mesh(hexa.points, [hexa.cells[0], ("wedge", wedges.cells[0].data[:1])])
    with pytest.raises(ValueError, match=r"mixes 3-D cell types \(2 hexahedron, 1 wedge cells\).*one body cell type"
                                         r".*valid bodies: tetra or tetra10; hexahedron or hexahedron20 or "
                                         r"hexahedron27; wedge"):
        from_meshio(both, source="both")
    tets = split(hexa, KUHN)
    with pytest.raises(ValueError, match=r"non-simplex 3-D cells \(wedge\) beside tetra cells \(12 tetra, 1 wedge"):
        from_meshio(meshio.Mesh(hexa.points, [tets.cells[0], ("wedge", wedges.cells[0].data[:1])]))
    with pytest.raises(ValueError, match=r"pyramid cells have no scikit-fem element"):
        from_meshio(meshio.Mesh(hexa.points, [hexa.cells[0], ("pyramid", np.array([[0, 1, 2, 3, 4]]))]))


def test_wedges_take_order_two_and_dropped_cells_are_logged():
    """Wedges were order 1 only (scikit-fem has no quadratic wedge); bladecase's ElementWedgeS2 now gives order 2:
    3 dofs per vertex and per edge (tests/test_wedge2.py checks it)."""
    mesh = from_meshio(split(hex_beam(0.02, 0.01, (2, 1, 1)), WEDGES))
    p1, p2 = (assemble(mesh, STEEL, order=o, clamp=ROOT) for o in (1, 2))
    assert p1.n_dofs == 3 * 8 and p2.n_dofs == 3 * (8 + 20)  # free: 8 vertices, 20 of the 24 edges (4 on the root)
    with pytest.raises(ValueError, match=r"order 3 is not available for wedge cells.*valid: order=1 or 2"):
        element_name("wedge", 3)
    hexa = hex_beam(0.02, 0.01, (2, 1, 1))
    with log.transcript() as lines:
        from_meshio(meshio.Mesh(hexa.points, [hexa.cells[0], ("polygon", np.array([[0, 1, 2, 3, 4]]))]), source="p")
    assert any("1 polygon cell(s) dropped" in line for line in lines)


# ----------------------------------------------------------------------------- files


@pytest.mark.parametrize("suffix", [".vtu", ".inp"])
@pytest.mark.parametrize("btype", ["hexahedron", "hexahedron20", "wedge", "quad8"])
def test_round_trip_with_groups(tmp_path, suffix, btype):
    if btype == "wedge":
        m = split(hex_beam(0.03, 0.01, (3, 1, 1)), WEDGES)
    elif btype == "quad8":
        m = meshio.Mesh(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [.5, 0], [1, .5], [.5, 1], [0, .5]]),
                        [("quad8", np.arange(8)[None])])
    else:
        m = hex_beam(0.03, 0.01, (3, 1, 1), btype)
    mesh = from_meshio(m, source=btype)
    mesh.groups.update(root=np.flatnonzero(mesh.points[:, 0] == 0), tip=np.array([1, 2]))
    save_mesh(mesh, tmp_path / f"m{suffix}")
    back = load_mesh(tmp_path / f"m{suffix}", require=("root", "tip"))
    assert back.body_type == btype and back.dim == mesh.dim
    np.testing.assert_array_equal(back.cells[btype], mesh.cells[btype])
    np.testing.assert_allclose(back.points, mesh.points)
    for name in ("root", "tip"):
        np.testing.assert_array_equal(back.group(name), mesh.group(name))


def test_hex27_cannot_be_written_for_abaqus(tmp_path):
    mesh = from_meshio(hex_beam(0.02, 0.01, (2, 1, 1), "hexahedron27"))
    with pytest.raises(ValueError, match=r"cannot write hexahedron27 cells to Abaqus .*valid: .*C3D20.*\.vtu"):
        save_mesh(mesh, tmp_path / "m.inp")
    save_mesh(mesh, tmp_path / "m.vtu")
    assert load_mesh(tmp_path / "m.vtu").body_type == "hexahedron27"


# ----------------------------------------------------------------------------- results on the mesh


@pytest.mark.parametrize("btype, order, parts", [("hexahedron", 1, None), ("hexahedron20", 2, None),
                                                 ("wedge", 1, WEDGES), ("wedge", 2, WEDGES)])
def test_hex_and_wedge_models_are_drawn_on_their_corner_nodes(tmp_path, btype, order, parts):
    """fe_grid/nodal_field draw first-order hexahedra and wedges on their vertices (the vertex dofs come first), a
    mesh of hexahedron20 on all its nodes; a mode shape written to VTK reads back with the cell type and the field of
    the model."""
    from bladecase.post.grid import fe_grid, nodal_field

    m = hex_beam(0.2, 0.02, (4, 1, 1), "hexahedron" if parts else btype)
    if parts:
        m = split(m, parts)
    model = assemble(from_meshio(m, source="beam"), STEEL, order=order, clamp=ROOT)
    grid = fe_grid(model)
    family = KINDS[btype].family
    n = len(model.mesh.points)  # 5 × 2 × 2 vertices, and the 36 midside nodes of the hexahedron20
    assert grid.body_type == (btype if parts is None else family) and grid.points.shape == (n, 3) and n in (20, 56)
    f, phi = natural_frequencies(model, 1, return_modes=True)
    u = nodal_field(model, phi[:, 0])
    assert u.shape == (n, 3)
    root = grid.points[:, 0] < 1e-12
    assert np.abs(u[root]).max() == 0 and np.abs(u[~root]).max() > 0  # clamped root, moving tip
    tip = grid.points[:, 0] > 0.2 - 1e-12
    # the first bending mode (y and z bending share a frequency: any mix): the tip's transverse motion dominates
    # its axial motion (the section's rotation; 11–13 × on this coarse beam)
    assert np.linalg.norm(u[tip][:, 1:], axis=1).min() > 5 * np.abs(u[tip][:, 0]).max()
    pv = pytest.importorskip("pyvista")
    from bladecase.post.grid import VTK_CELL_TYPES

    cells = grid.cells[grid.body_type]
    ug = pv.UnstructuredGrid({pv.CellType[VTK_CELL_TYPES[grid.body_type]]: cells}, grid.points)
    ug.point_data["u"] = u
    assert ug.volume == pytest.approx(0.2 * 0.02 * 0.02, rel=1e-12)  # positive volume: VTK node order right


@pytest.mark.parametrize("parts", [None, WEDGES])
def test_area_weights_of_a_hexahedron_or_wedge_face(parts):
    """Contact.face(weights='area') integrates over the real facets: on a 2 × 2 quad face each corner of a quad
    gets a quarter of it (corner 1/16, edge 2/16, centre 4/16); wedges have the same quads on their x-faces."""
    from bladecase.fe import Mesh
    from bladecase.reduction.tributary import area_weights

    m = hex_beam(0.2, 0.02, (4, 2, 2), "hexahedron")
    if parts:
        m = split(m, parts)
    tip = np.flatnonzero(np.isclose(m.points[:, 0], 0.2))
    mesh = Mesh(m.points, {k: v for k, v in m.cells_dict.items()}, dim=3, groups={"tip": tip}, source="beam")
    model = assemble(mesh, STEEL, order=1, clamp=ROOT)
    w = area_weights(model, "tip", tip)
    y, z = m.points[tip, 1], m.points[tip, 2]
    interior = lambda c: (c > 1e-9) & (c < 0.02 - 1e-9)  # noqa: E731
    expected = (1 + interior(y)) * (1 + interior(z)) / 16
    assert np.allclose(w, expected, atol=1e-14) and w.sum() == pytest.approx(1.0, abs=1e-14)
