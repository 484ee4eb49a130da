"""Curved (isoparametric) second-order cells: the assembly maps each cell through all its nodes.

Rings and hollow cylinders whose midside (face-centre, centre) nodes lie on the circles — the curved cells a
mesher makes — against closed forms, and the same meshes with those nodes moved to the middle of the straight
edges ("straight": the cells bladecase assembled before).  Measured (annulus r = 0.9, R = 1, one cell across,
``n`` cells around; steel, plane stress):

* area vs π(R² − r²): straight −9.97e-2 / −2.55e-2 / −6.41e-3 for n = 8 / 16 / 32 (O(h²): the polygon),
  curved −7.78e-4 / −4.93e-5 / −3.09e-6 (O(h⁴)), the same for triangle6, quad8, quad9;
* the breathing (n = 0 extensional) mode of the free ring vs the exact plane-stress annulus (Bessel functions,
  846.48 Hz; the thin-ring ``sqrt(E/ρR²)`` gives 845.62 Hz): triangle6 straight +5.95e-2 / +1.34e-2 / +3.24e-3,
  curved +4.13e-4 / +2.60e-5 / +2.26e-6; quad8 and quad9 straight +5.65e-2 / +1.32e-2 / +3.23e-3, curved
  +3.95e-4 / +2.54e-5 / +2.24e-6;
* 3-D, volume of a hollow cylinder (r = 0.8, R = 1, H = 0.5) meshed by gmsh in tetra10 (``setOrder(2)``:
  midside nodes on the CAD surfaces), size 0.2: curved +2.7e-6, straight −5.5e-4; its outer lateral area by a
  curved ``FacetBasis``: −1.1e-6 (straight −1.25e-3); the extruded annuli of hexahedron20/27 and wedge15/18
  (n = 16) have the area's errors;
* the demo blade meshed with ``mesh_order = 2`` (gmsh tetra10, 10 mm / 5 mm at the tip): curved cells raise
  f1–f4 by +5.8, +5.6, +2.5, +4.0 % over the straightened mesh; against 4 mm meshes the curved errors are
  +2.1, +2.0, +1.0, +0.2 %, the straight ones −3.5, −3.4, −1.5, −3.6 %; the volume goes from −7.7 % to
  −1.1 % of the CAD's.  The demo itself (``mesh_order = 1``: no midside node) is unchanged.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as sla
from scipy.optimize import brentq
from scipy.special import jv, yv
from test_fe_elements import KUHN, WEDGES, box

import bladecase as bc
from bladecase.fe import Mesh, assemble, isoparametric, node_operator
from bladecase.fe.cells import KINDS

STEEL = bc.Material.preset("steel")
R_IN, R_OUT = 0.9, 1.0
QUADRATIC = ("tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18", "triangle6", "quad8", "quad9")


# ----------------------------------------------------------------------------- meshes


def parameter_mesh(btype: str, n: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``(points, cells)`` of ``btype`` cells on the unit square/cube (``n`` cells per side), extra nodes at the
    centres of the straight edges and faces (meshio/VTK order)."""
    kind = KINDS[btype]
    base = {"triangle": "quad", "tetra": "hexahedron", "wedge": "hexahedron"}.get(kind.family, kind.family)
    m = box((1.0,) * len(n), n, base)
    pts, cells = m.points, m.cells[0].data
    if kind.family == "triangle":
        cells = np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
    elif kind.family in ("wedge", "tetra"):
        cells = np.vstack([cells[:, list(p)] for p in (WEDGES if kind.family == "wedge" else KUHN)])
        if kind.family == "tetra":
            x = pts[cells]
            neg = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0]) < 0
            cells[neg] = cells[neg][:, [0, 2, 1, 3]]
    # the extra nodes: one per entity (its sorted corner set), at the corners' mean
    extra = kind.parents[kind.corners:]
    keys = np.full((len(cells), len(extra), 8), -1)
    for j, p in enumerate(extra):
        keys[:, j, : len(p)] = np.sort(cells[:, list(p)], axis=1)
    uniq, inv = np.unique(keys.reshape(-1, 8), axis=0, return_inverse=True)
    mask = uniq >= 0
    centres = (pts[np.where(mask, uniq, 0)] * mask[..., None]).sum(axis=1) / mask.sum(axis=1)[:, None]
    return np.vstack([pts, centres]), np.hstack([cells, len(pts) + inv.reshape(len(cells), -1)])


def straighten(points: np.ndarray, cells: np.ndarray, btype: str) -> np.ndarray:
    """``points`` with every extra node of the cells moved to its corners' mean (straight edges and faces)."""
    kind, out = KINDS[btype], points.copy()
    for j in range(kind.corners, kind.n_nodes):
        out[cells[:, j]] = points[cells[:, list(kind.parents[j])]].mean(axis=1)
    return out


def annulus(btype: str, n_theta: int, n_r: int = 1, curved: bool = True, angle: float = 2 * np.pi,
            height: float = 0.1, n_z: int = 1, distort: float = 0.0) -> Mesh:
    """An annulus ``R_IN ≤ r ≤ R_OUT`` (2-D types) or a hollow cylinder of ``height`` (3-D types) over ``angle``:
    the polar image of :func:`parameter_mesh`.  ``curved``: every node mapped (midside nodes on the circles);
    else the corners only, the extra nodes at their means.  ``distort`` moves the corners at random (a
    fraction of the radial cell size) first."""
    dim = KINDS[btype].dim
    pts, cells = parameter_mesh(btype, (n_r, n_theta) + ((n_z,) if dim == 3 else ()))
    r = R_IN + (R_OUT - R_IN) * pts[:, 0]
    xyz = np.zeros((len(pts), 3))
    xyz[:, 0], xyz[:, 1] = r * np.cos(angle * pts[:, 1]), r * np.sin(angle * pts[:, 1])
    if dim == 3:
        xyz[:, 2] = height * pts[:, 2]
    if distort:
        corners = np.unique(cells[:, : KINDS[btype].corners])
        shift = np.random.default_rng(7).uniform(-1, 1, (corners.size, dim))
        xyz[corners, :dim] += distort * (R_OUT - R_IN) / n_r * shift
    if not curved:
        xyz = straighten(xyz, cells, btype)
    # the nodes at θ = 0 and θ = 2π are the same: merge them
    key = np.round(xyz / (R_OUT * 1e-9)).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return Mesh(xyz[first], {btype: inv.ravel()[cells]}, dim=dim, source=f"annulus {btype}")


def straight_copy(mesh: Mesh) -> Mesh:
    return Mesh(straighten(mesh.points, mesh.cells[mesh.body_type], mesh.body_type), mesh.cells, dim=mesh.dim,
                groups=mesh.groups, source=f"{mesh.source} (straightened)")


def breathing_frequency(mat=STEEL, a=R_IN, b=R_OUT) -> float:
    """The first axisymmetric extensional frequency (Hz) of a free plane-stress annulus: ``u_r = A J1(kr) +
    B Y1(kr)``, ``k = ω / c``, ``c² = (λ* + 2μ)/ρ``, ``σ_rr = (λ* + 2μ) k Z0(kr) − 2μ Z1(kr)/r = 0`` at ``a, b``."""
    lam, mu = mat.lame("stress")
    c = np.sqrt((lam + 2 * mu) / mat.rho)

    def det(w):
        def s(Z, r):
            return (lam + 2 * mu) * (w / c) * Z(0, w / c * r) - 2 * mu * Z(1, w / c * r) / r
        return s(jv, a) * s(yv, b) - s(yv, a) * s(jv, b)

    w0 = np.sqrt(mat.E / (mat.rho * ((a + b) / 2) ** 2))  # the thin ring
    w = np.linspace(0.8 * w0, 1.2 * w0, 400)
    v = np.array([det(x) for x in w])
    i = np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))[0]
    return brentq(det, w[i], w[i + 1]) / (2 * np.pi)


def fe_breathing(model, guess: float) -> float:
    """The FE mode near ``guess`` (Hz) with the most uniform radial displacement."""
    lam, V = sla.eigsh(model.K.tocsc(), 8, model.M.tocsc(), sigma=(2 * np.pi * guess) ** 2)
    x, d = model.dofs.coords, model.dofs.direction
    er = np.where(d == 0, x[:, 0], x[:, 1]) / np.hypot(x[:, 0], x[:, 1])
    score = np.abs(er @ (model.M @ V)) / np.sqrt(np.einsum("ij,ij->j", V, model.M @ V))
    return float(np.sqrt(lam[np.argmax(score)]) / (2 * np.pi))


def straight_assembly(monkeypatch, *args, **kwargs):
    """:func:`assemble` as before curved cells: the geometry through the corners only."""
    with monkeypatch.context() as m:
        m.setattr(isoparametric, "curved_geometry", lambda *a, **k: None)
        return assemble(*args, **kwargs)


# ----------------------------------------------------------------------------- closed forms


@pytest.mark.parametrize("btype", ["triangle6", "quad8", "quad9"])
def test_ring_area_and_breathing_mode_converge_as_h4_on_curved_cells(btype):
    """Curved cells: area and breathing frequency O(h⁴) (errors ÷ ≥ 12 when n doubles); straight: O(h²) (÷ ~4)."""
    exact_area, exact_f = np.pi * (R_OUT**2 - R_IN**2), breathing_frequency()
    err = {}
    for curved in (False, True):
        for n in (8, 16):
            model = assemble(annulus(btype, n, curved=curved), STEEL, order=2, clamp=None, thickness=0.01)
            err[curved, n] = (model.volume / exact_area - 1, fe_breathing(model, exact_f) / exact_f - 1)
    print(f"\n{btype} area / breathing errors: straight {err[False, 8]}, {err[False, 16]}; "
          f"curved {err[True, 8]}, {err[True, 16]}", end="")
    (a8, f8), (a16, f16) = err[True, 8], err[True, 16]
    assert abs(a16) < 6e-5 and abs(f16) < 3e-5  # measured 4.93e-5, 2.6e-5
    assert abs(a8 / a16) > 12 and abs(f8 / f16) > 12
    (s8, g8), (s16, g16) = err[False, 8], err[False, 16]
    assert abs(s16) > 2e-2 and abs(g16) > 1e-2  # the polygon: 2.55e-2, 1.3e-2
    assert 3 < s8 / s16 < 5 and 3 < g8 / g16 < 5
    assert abs(f16) < 0.01 * abs(g16)


@pytest.mark.parametrize("btype", ["tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18"])
def test_hollow_cylinder_volume_in_3d(btype):
    """Extruded annulus (n = 16 around): the volume has the area's error, curved −4.93e-5, straight −2.55e-2."""
    exact = np.pi * (R_OUT**2 - R_IN**2) * 0.1
    curved = assemble(annulus(btype, 16), STEEL, order=2, clamp=None).volume / exact - 1
    straight = assemble(annulus(btype, 16, curved=False), STEEL, order=2, clamp=None).volume / exact - 1
    assert curved == pytest.approx(-4.93e-5, rel=0.01)
    assert straight == pytest.approx(-2.55e-2, rel=0.01)


def test_gmsh_curved_tetra10_cylinder_volume_and_surface(tmp_path):
    """gmsh's tetra10 (``setOrder(2)``: midside nodes on the cylinders) of a hollow cylinder r = 0.8, R = 1,
    H = 0.5, size 0.2: volume within 1e-5 curved (measured +2.7e-6), −5.5e-4 straight; the outer lateral area
    2πRH by a curved ``FacetBasis`` within 1e-5 (−1.1e-6; straight −1.25e-3), its normals radial within 2e-4."""
    from skfem import ElementTetP2, FacetBasis

    from bladecase.fe.assembly import _basis
    from bladecase.fe.cad import gmsh_model

    r, R, H = 0.8, 1.0, 0.5
    path = tmp_path / "cylinder.msh"
    with gmsh_model("cylinder", {"Mesh.MeshSizeMax": 0.2, "Mesh.MeshSizeMin": 0.2, "General.NumThreads": 1,
                                 "Mesh.Binary": 1}) as gmsh:
        occ = gmsh.model.occ
        occ.cut([(3, occ.addCylinder(0, 0, 0, 0, 0, H, R))], [(3, occ.addCylinder(0, 0, 0, 0, 0, H, r))])
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [e[1] for e in gmsh.model.getEntities(3)], name="body")
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(2)
        gmsh.write(str(path))
    mesh = bc.load_mesh(path)
    assert mesh.body_type == "tetra10"
    exact = np.pi * (R**2 - r**2) * H
    curved = assemble(mesh, STEEL, clamp=None).volume / exact - 1
    straight = assemble(straight_copy(mesh), STEEL, clamp=None).volume / exact - 1
    print(f"\ngmsh tetra10 cylinder volume: curved {curved:.3g}, straight {straight:.3g}", end="")
    assert abs(curved) < 1e-5 and straight < -2e-4

    basis, fe_mesh, _ = _basis(mesh, mesh.points, 3, 2)
    mapping = isoparametric.MappingCurved(basis.mapping.mesh)  # facets mapped by ElementTriP2
    facets = fe_mesh.boundary_facets()
    mid = fe_mesh.p[:, fe_mesh.facets[:, facets]].mean(axis=1)
    outer = facets[(np.hypot(mid[0], mid[1]) > (r + R) / 2) & (mid[2] > 1e-9) & (mid[2] < H - 1e-9)]
    lateral = FacetBasis(fe_mesh, ElementTetP2(), facets=outer, mapping=mapping)
    area = lateral.dx.sum() / (2 * np.pi * R * H) - 1
    flat = FacetBasis(fe_mesh, ElementTetP2(), facets=outer).dx.sum() / (2 * np.pi * R * H) - 1
    assert abs(area) < 1e-5 and flat < -5e-4
    x, n = np.asarray(lateral.global_coordinates()), lateral.normals
    assert np.abs(n[:2] - x[:2] / np.hypot(x[0], x[1])).max() < 2e-4


# ----------------------------------------------------------------------------- straight cells: unchanged


@pytest.mark.parametrize("btype", QUADRATIC)
def test_straight_quadratic_cells_give_the_straight_matrices(btype, monkeypatch):
    """Midside nodes at the edge midpoints (corners distorted at random): K, M (consistent and lumped), the dof
    locations and the volume equal those of the straight-cell assembly to round-off (≤ 1e-12 relative)."""
    mesh = annulus(btype, 6, n_r=2, curved=False, distort=0.2)
    extra = {} if KINDS[btype].dim == 3 else {"thickness": 0.01}
    for mass in ("consistent", "lumped"):
        curved = assemble(mesh, STEEL, order=2, mass=mass, clamp=None, **extra)
        straight = straight_assembly(monkeypatch, mesh, STEEL, order=2, mass=mass, clamp=None, **extra)
        for name in ("K", "M"):
            a, b = getattr(curved, name), getattr(straight, name)
            assert abs(a - b).max() <= 1e-12 * abs(b).max(), (name, mass)
        assert np.abs(curved.dofs.coords - straight.dofs.coords).max() <= 1e-12 * R_OUT
        assert curved.volume == pytest.approx(straight.volume, rel=1e-12)


@pytest.mark.parametrize("btype", ["tetra", "hexahedron", "wedge", "triangle", "quad"])
def test_meshes_without_midside_nodes_are_unchanged(btype, monkeypatch):
    mesh = annulus(btype, 6, n_r=2, distort=0.2)
    extra = {} if KINDS[btype].dim == 3 else {"thickness": 0.01}
    a = assemble(mesh, STEEL, order=2, clamp=None, **extra)
    b = straight_assembly(monkeypatch, mesh, STEEL, order=2, clamp=None, **extra)
    assert (a.K != b.K).nnz == 0 and (a.M != b.M).nnz == 0


def test_order_one_keeps_straight_cells_on_a_curved_mesh(monkeypatch):
    """Order 1 on a curved mesh: the straight cells through the corners (a curved map with a linear field would
    give a free ring's rigid rotation a frequency: 87 Hz on 32 × 2 curved triangle6, above the ring's first
    flexural mode at 69 Hz).  The rigid rotation costs no energy."""
    mesh = annulus("triangle6", 16)
    a = assemble(mesh, STEEL, order=1, clamp=None, thickness=0.01)
    b = straight_assembly(monkeypatch, mesh, STEEL, order=1, clamp=None, thickness=0.01)
    assert (a.K != b.K).nnz == 0 and (a.M != b.M).nnz == 0
    x, d = a.dofs.coords, a.dofs.direction
    rotation = np.where(d == 0, -x[:, 1], x[:, 0])
    assert rotation @ (a.K @ rotation) <= 1e-12 * abs(a.K).max() * rotation @ rotation


# ----------------------------------------------------------------------------- curved cells: consistency


@pytest.mark.parametrize("btype", ["tetra10", "hexahedron20", "wedge18", "quad9"])
def test_curved_cells_pass_the_patch_test_and_keep_rigid_motions(btype):
    """Isoparametric cells reproduce linear fields: ``uᵀKu = σ:ε · volume`` (1e-10) and the rigid motions cost
    no energy (``|K r| ≤ 1e-10 |K| |r|``); the mass of a translation is ρ · volume."""
    mesh = annulus(btype, 8, n_r=2, angle=np.pi)
    dim = mesh.dim
    extra = {} if dim == 3 else {"thickness": 1.0}
    model = assemble(mesh, STEEL, order=2, clamp=None, mass="consistent", **extra)
    x, d = model.dofs.coords[:, :dim], model.dofs.direction
    A = np.array([[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.25, 0.0, 0.7]])[:dim, :dim] * 1e-3
    u = (x @ A.T)[np.arange(model.n_dofs), d]
    eps = 0.5 * (A + A.T)
    lam, mu = STEEL.lame(None if dim == 3 else "stress")
    sigma = lam * np.trace(eps) * np.eye(dim) + 2 * mu * eps
    assert u @ (model.K @ u) == pytest.approx(np.sum(sigma * eps) * model.volume, rel=1e-10)
    rotations = [(0, 1)] if dim == 2 else [(1, 2), (2, 0), (0, 1)]
    rigid = [np.where(d == c, 1.0, 0.0) for c in range(dim)]
    for i, j in rotations:
        rigid.append(np.where(d == i, -x[:, j], 0.0) + np.where(d == j, x[:, i], 0.0))
    for r in rigid:
        assert np.linalg.norm(model.K @ r) <= 1e-10 * abs(model.K).max() * np.linalg.norm(r)
    assert rigid[0] @ (model.M @ rigid[0]) == pytest.approx(STEEL.rho * model.volume, rel=1e-12)


@pytest.mark.parametrize("btype", ["hexahedron27", "wedge15", "triangle6"])
def test_mapping_equals_scikit_fem_isoparametric_mapping(btype):
    """:class:`MappingCurved`'s vectorised Jacobians equal ``skfem.MappingIsoparametric`` on the same nodes."""
    from skfem.mapping import MappingIsoparametric

    from bladecase.fe.assembly import _basis

    mesh = annulus(btype, 6, n_r=2, angle=np.pi)
    basis, _, _ = _basis(mesh, mesh.points, mesh.dim, 2)
    geometry = basis.mapping.mesh
    ref = MappingIsoparametric(geometry, geometry.element)
    X = basis.X
    np.testing.assert_allclose(basis.mapping.detDF(X), ref.detDF(X), rtol=1e-12)
    np.testing.assert_allclose(basis.mapping.invDF(X), ref.invDF(X), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(basis.mapping.F(X), ref.F(X), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("btype", ["tetra10", "hexahedron27", "wedge15", "quad8"])
def test_dofs_sit_at_the_mesh_nodes_and_node_operator_finds_them(btype):
    """On curved cells the order-2 dofs are at the mesh's own nodes (``DofMap.coords``), and ``node_operator``
    carries the field ``u = x`` (which the isoparametric cells hold exactly) to every mesh node."""
    mesh = annulus(btype, 8, angle=np.pi)
    dim = mesh.dim
    model = assemble(mesh, STEEL, order=2, clamp=None, **({} if dim == 3 else {"thickness": 0.01}))
    pts = mesh.points[:, :dim]
    tree_dist = np.min(np.linalg.norm(model.dofs.coords[:, None, :dim] - pts[None], axis=2), axis=1)
    assert tree_dist.max() == 0.0
    u = model.dofs.coords[np.arange(model.n_dofs), model.dofs.direction]
    nodal = (node_operator(model) @ u).reshape(-1, dim)
    np.testing.assert_allclose(nodal, pts, rtol=0, atol=1e-14)


def test_centrifugal_load_uses_the_curved_positions():
    """The spin load ``f₁ = M r⊥`` of a curved half ring about z: its resultant is ρ t ∫ r⊥ dA, the curved
    geometry's own first moment (to round-off) and within 1e-4 of the exact half ring's 2/3 (R³ − r³)."""
    from bladecase.fe.rotation import RotationAxis, _Operators

    model = assemble(annulus("quad8", 16, angle=np.pi), STEEL, order=2, clamp=None, thickness=0.01)
    ops = _Operators(model, RotationAxis())
    fy = ops.f1[model.dofs.direction == 1].sum()
    basis = ops.basis
    moment = float((np.asarray(basis.global_coordinates())[1] * basis.dx).sum())
    assert fy == pytest.approx(STEEL.rho * 0.01 * moment, rel=1e-12)
    assert fy == pytest.approx(STEEL.rho * 0.01 * 2 / 3 * (R_OUT**3 - R_IN**3), rel=1e-4)


def test_folded_curved_cell_is_refused():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0.8, 0], [0.5, 0.5, 0], [0, 0.5, 0]])  # edge 01 bent past 2
    mesh = Mesh(p, {"triangle6": np.array([[0, 1, 2, 3, 4, 5]])}, dim=2, source="folded")
    with pytest.raises(ValueError, match=r"1 folded curved triangle6 cell\(s\).*cell 0"):
        assemble(mesh, STEEL, clamp=None, thickness=0.01)


# ----------------------------------------------------------------------------- the demo blade


def test_demo_blade(monkeypatch):
    """The demo (gmsh ``mesh_order = 1``: tetra, no midside node) is unchanged.  Its blade meshed with
    ``mesh_order = 2`` (10 mm, 5 mm at the tip): curved tetra10 raise f1–f4 by +5.8, +5.6, +2.5, +4.0 % over
    the straightened mesh; against 4 mm meshes (the mean of curved and straight) the curved errors are +2.1,
    +2.0, +1.0, +0.2 %, the straight ones −3.5, −3.4, −1.5, −3.6 %; the volume is −1.1 % off the CAD's
    curved, −7.7 % straight."""
    from bladecase.fe.geometry import cad_volume
    from bladecase.study.demo import demo_study

    geometry = demo_study().geometry()
    kwargs = {"order": 2, "mass": "lumped", "clamp": "root"}
    mesh = bc.blade_mesh(geometry, size=0.01, tip_size=0.005, order=1)
    assert mesh.body_type == "tetra"
    demo, before = assemble(mesh, "Ti-6Al-4V", **kwargs), straight_assembly(monkeypatch, mesh, "Ti-6Al-4V", **kwargs)
    assert (demo.K != before.K).nnz == 0 and (demo.M != before.M).nnz == 0
    np.testing.assert_array_equal(bc.natural_frequencies(demo, 4), bc.natural_frequencies(before, 4))

    f, volume = {}, {}
    for size in (0.01, 0.004):
        mesh = bc.blade_mesh(geometry, size=size, tip_size=size / 2, order=2)
        for curved, m in ((True, mesh), (False, straight_copy(mesh))):
            model = assemble(m, "Ti-6Al-4V", **kwargs)
            f[size, curved], volume[size, curved] = bc.natural_frequencies(model, 4), model.volume
    reference = 0.5 * (f[0.004, True] + f[0.004, False])
    err_c, err_s = f[0.01, True] / reference - 1, f[0.01, False] / reference - 1
    cad = cad_volume(geometry)
    moved = np.round(100 * (f[0.01, True] / f[0.01, False] - 1), 2)
    print(f"\ndemo blade mesh_order 2, 10 mm: curved / straight - 1 = {moved} %; "
          f"vs 4 mm: curved {np.round(100 * err_c, 2)} %, straight {np.round(100 * err_s, 2)} %; volume vs CAD "
          f"curved {volume[0.01, True] / cad - 1:.3g}, straight {volume[0.01, False] / cad - 1:.3g}", end="")
    assert np.all(np.abs(err_c) < 0.7 * np.abs(err_s))
    assert abs(volume[0.01, True] / cad - 1) < 0.2 * abs(volume[0.01, False] / cad - 1)
