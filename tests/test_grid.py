"""The full nodal grid of an FE model (``bladecase.post.grid``): every FE node, quadratic cells, fields on it.

References: the model's own dof map (``DofMap.coords``, ``fe_index``),
scikit-fem's P2 basis (dof locations and element dofs, built independently
here; through the curved isoparametric map for a mesh with midside nodes), the
straight-edge midpoints computed from the corners, the mesh's own midside nodes,
closed-form polynomial displacements (a quadratic field is exact in P2 on
straight cells, a linear one on curved cells), VTK's own quadratic-cell
interpolation and cell sizes (pyvista), the model's volume, and the volume of
the tessellation of each quadratic cell into straight sub-cells at its nodes.

Three order-2 meshes: the plate (triangles: no midside nodes, the edge nodes at
the edge midpoints), a gmsh blade in curved tetra10 (``mesh_order = 2``: its
midside nodes are on the CAD surfaces, and the model's cells are curved through
them, so the edge nodes are the mesh's midside nodes) and the same tetra10 with
its midside nodes moved to the edge midpoints (``blade2_straight``: both).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from skfem import CellBasis, ElementTetP2, ElementTriP2, MeshTet, MeshTri
from test_isoparametric import straight_copy

import bladecase as bc
from bladecase.fe import MappingCurved, curved_geometry
from bladecase.post.grid import VTK_EDGES, fe_grid, grid_index, nodal_field

MESHES = Path(__file__).resolve().parents[1] / "meshes"

#: A small gmsh blade (curved tetra10 from gmsh: its midside nodes, off the straight edges, are the P2 edge dofs).
BLADE = bc.BladeGeometry(span=0.06, root_chord=0.03, tip_chord=0.02, naca="2412", stagger_deg=20, twist_deg=30,
                         sweep=0.004, lean=0.002)


@pytest.fixture(scope="module")
def plate2() -> bc.FEModel:
    return bc.assemble(bc.load_mesh(MESHES / "plate.vtu"), "steel", order=2, thickness=0.002)


@pytest.fixture(scope="module")
def blade_mesh() -> bc.Mesh:
    return bc.blade_mesh(BLADE, size=0.006, order=2)


@pytest.fixture(scope="module")
def blade2(blade_mesh) -> bc.FEModel:
    return bc.assemble(blade_mesh, "Ti-6Al-4V", order=2)


@pytest.fixture(scope="module")
def blade2_straight(blade_mesh) -> bc.FEModel:
    """The blade's tetra10 with every midside node at its edge's midpoint: straight cells."""
    return bc.assemble(straight_copy(blade_mesh), "Ti-6Al-4V", order=2)


@pytest.fixture(scope="module")
def blade1(blade_mesh) -> bc.FEModel:
    return bc.assemble(blade_mesh, "Ti-6Al-4V", order=1)


MODELS = ["plate2", "blade2", "blade1"]
QUADRATIC = ["plate2", "blade2", "blade2_straight"]

#: Tessellation of the quadratic cells into straight sub-cells through their nodes (VTK node order): the 4
#: corner tetrahedra of a tetra10 and the 4 of its central octahedron (cut along the diagonal 6–8; the
#: octahedron's volume does not depend on the diagonal); the 4 triangles of a triangle6.
SUB_CELLS = {3: ((0, 4, 6, 7), (4, 1, 5, 8), (6, 5, 2, 9), (7, 8, 9, 3), (4, 5, 6, 8), (4, 6, 7, 8), (6, 5, 9, 8),
                 (6, 9, 7, 8)),
             2: ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))}


def _curved(model: bc.FEModel) -> bool:
    """The mesh has midside nodes off the straight edges (the model's cells are curved)."""
    mesh = model.mesh
    if mesh.order == 1:
        return False
    straight = straight_copy(mesh)
    return bool(np.abs(straight.points - mesh.points).max() > 1e-9 * _size(model))


def _tessellation_sizes(points: np.ndarray, cells: np.ndarray, dim: int) -> np.ndarray:
    """Volume (area) of each quadratic cell's straight sub-cells through its nodes, summed per cell."""
    total = np.zeros(len(cells))
    for sub in SUB_CELLS[dim]:
        x = points[cells[:, list(sub)]]
        e = x[:, 1:] - x[:, :1]
        total += (np.einsum("ij,ij->i", np.cross(e[:, 0], e[:, 1]), e[:, 2]) / 6 if dim == 3
                  else np.cross(e[:, 0], e[:, 1])[:, 2] / 2)
    return total


def _poly(x: np.ndarray, dim: int, L: float) -> np.ndarray:
    """A full quadratic displacement field (n, dim) of the coordinates ``x / L`` (exact in P2)."""
    x = x / L
    X, Y, Z = x[:, 0], x[:, 1], x[:, 2]
    cols = [0.3 + X - 2 * Y + X * Y + 0.5 * Y**2, -0.7 + 0.4 * X + Y - X**2 + 0.2 * X * Y, 1.1 - Z + X * Z + Y * Z]
    return np.column_stack(cols[:dim])


def _linear(x: np.ndarray, dim: int, L: float) -> np.ndarray:
    x = x / L
    A = np.array([[1.0, -2.0, 0.5], [0.3, 1.0, -1.0], [-0.5, 0.2, 1.0]])
    return 0.1 + x @ A.T[:, :dim]


def _size(model: bc.FEModel) -> float:
    return float(np.abs(model.mesh.points).max())


def _model_field(model: bc.FEModel, field) -> np.ndarray:
    """Free-dof vector of ``field`` evaluated at the dof locations."""
    d = model.dofs
    return field(d.coords, model.dim, _size(model))[np.arange(len(d)), d.direction]


@pytest.mark.parametrize("which", ["plate2", "blade2"])
def test_points_are_the_fe_nodes(which, request):
    model = request.getfixturevalue(which)
    grid, dim = fe_grid(model), model.dim
    d = model.dofs
    assert grid.dim == dim and grid.points.shape == (d.n_total // dim, 3)
    assert grid.body_type == {3: "tetra10", 2: "triangle6"}[dim]
    # every free dof sits on the point its fe_index names, and every point but the clamped ones has dofs
    np.testing.assert_allclose(grid.points[d.fe_index // dim], d.coords, rtol=0, atol=1e-12)
    has_dof = np.zeros(len(grid.points), bool)
    has_dof[d.fe_index // dim] = True
    assert set(np.flatnonzero(~has_dof)) == set(grid.groups["root"])  # the clamped root, nothing else
    assert len(np.unique(grid.points.round(12), axis=0)) == len(grid.points)  # no point twice
    # the vertices are the mesh's body-cell vertices, in mesh-node order
    mesh = model.mesh
    used = np.unique(np.asarray(mesh.cells[mesh.body_type])[:, : dim + 1])
    np.testing.assert_array_equal(grid.points[: used.size], mesh.points[used])
    cells = grid.cells[grid.body_type]
    assert set(np.unique(cells)) == set(range(len(grid.points)))  # every point belongs to a cell


@pytest.mark.parametrize("which", QUADRATIC)
def test_same_nodes_and_elements_as_scikit_fem(which, request):
    """An independent P2 basis: its dof locations are the grid points, its element dofs the cells' nodes.

    With midside nodes (tetra10) the basis maps the cells through all their nodes, as the assembly does
    (``MappingCurved(curved_geometry(...))``); scikit-fem places the dofs by that map at the element's reference
    dof locations, so the edge dofs land on the mesh's midside nodes.  Without them (triangles): straight cells.
    """
    model = request.getfixturevalue(which)
    grid, dim, mesh = fe_grid(model), model.dim, model.mesh
    corners = np.asarray(mesh.cells[mesh.body_type])[:, : dim + 1]
    used, local = np.unique(corners, return_inverse=True)
    fe_mesh = (MeshTet if dim == 3 else MeshTri)(mesh.points[used, :dim].T.copy(),
                                                 local.reshape(corners.shape).T.copy())
    geometry = curved_geometry(mesh, used, fe_mesh)
    assert (geometry is None) == (mesh.order == 1)
    mapping = MappingCurved(geometry) if geometry is not None else None
    basis = CellBasis(fe_mesh, (ElementTetP2 if dim == 3 else ElementTriP2)(), mapping=mapping)
    np.testing.assert_allclose(grid.points[:, :dim], basis.doflocs.T, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(np.sort(grid.cells[grid.body_type], axis=1), np.sort(basis.element_dofs.T, axis=1))
    straight = CellBasis(fe_mesh, (ElementTetP2 if dim == 3 else ElementTriP2)())  # the corners' affine map
    if _curved(model):  # the curved map moves the edge dofs off the straight edges
        assert np.abs(straight.doflocs.T - grid.points[:, :dim]).max() > 1e-6
    else:  # straight cells: the same dof locations as the affine map
        np.testing.assert_allclose(grid.points[:, :dim], straight.doflocs.T, rtol=0, atol=1e-15)


@pytest.mark.parametrize("which", QUADRATIC)
def test_midside_nodes_at_edge_midpoints(which, request):
    """The edge nodes: the mesh's own midside nodes when it has them (curved or not), else the edge midpoints."""
    model = request.getfixturevalue(which)
    grid, dim, mesh = fe_grid(model), model.dim, model.mesh
    cells = grid.cells[grid.body_type]
    assert cells.shape[1] == (dim + 1) * (dim + 2) // 2
    p = grid.points
    midpoints = np.stack([0.5 * (p[cells[:, a]] + p[cells[:, b]]) for a, b in VTK_EDGES[dim]], axis=1)
    assert _curved(model) == (which == "blade2")
    if mesh.order == 2:  # tetra10: the grid's cells are the mesh's cells, node for node (VTK order both)
        mesh_cells = np.asarray(mesh.cells[mesh.body_type])
        np.testing.assert_array_equal(grid.points[cells], mesh.points[mesh_cells])
    if which == "blade2":  # gmsh's curved midside nodes, hence the edge nodes: off the straight edges
        assert np.abs(midpoints - p[cells[:, dim + 1:]]).max() > 1e-6
    else:  # no midside nodes (plate2), or at the midpoints already (blade2_straight)
        np.testing.assert_allclose(p[cells[:, dim + 1:]], midpoints, rtol=0, atol=1e-15)


@pytest.mark.parametrize("which", MODELS)
@pytest.mark.parametrize("field", [_linear, _poly], ids=["linear", "quadratic"])
def test_nodal_field_reproduces_a_smooth_displacement(which, field, request):
    model = request.getfixturevalue(which)
    if field is _poly and model.order == 1:
        field = _linear  # P1 reproduces linear fields only; the placement test is the same
    grid, dim = fe_grid(model), model.dim
    x = _model_field(model, field)
    u = nodal_field(model, x)
    expected = field(grid.points, dim, _size(model))
    if model.order == 1 and model.mesh.order == 2:  # P1 on straight cells: at a curved midside node, the mean of
        cells = grid.cells[grid.body_type]           # the edge's ends (the straight edge's middle)
        expected[grid.groups["root"]] = 0.0  # a clamped end counts zero
        for k, (a, b) in enumerate(VTK_EDGES[dim]):
            expected[cells[:, dim + 1 + k]] = 0.5 * (expected[cells[:, a]] + expected[cells[:, b]])
    expected[grid.groups["root"]] = 0.0  # clamped
    assert u.shape == (len(grid.points), dim)
    np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12)
    # several states at once, (n_dofs, F) -> (n_points, dim, F)
    uF = nodal_field(model, np.column_stack([x, -2 * x, 0 * x]))
    assert uF.shape == (len(grid.points), dim, 3)
    np.testing.assert_array_equal(uF[:, :, 0], u)
    np.testing.assert_array_equal(uF[:, :, 1], -2 * u)
    np.testing.assert_array_equal(uF[:, :, 2], 0 * u)


@pytest.mark.parametrize("which", QUADRATIC)
def test_vtk_reads_quadratic_cells(which, request):
    """VTK's quadratic cells (its node order) interpolate a quadratic field exactly on straight cells (a linear
    one on curved cells) and have positive volume."""
    pv = pytest.importorskip("pyvista")
    model = request.getfixturevalue(which)
    grid, dim = fe_grid(model), model.dim
    curved = _curved(model)
    ctype = pv.CellType.QUADRATIC_TETRA if dim == 3 else pv.CellType.QUADRATIC_TRIANGLE
    conn = grid.cells[grid.body_type]
    ug = pv.UnstructuredGrid({ctype: conn}, grid.points)
    assert set(np.asarray(ug.celltypes)) == {int(ctype)}
    sizes = np.asarray(ug.compute_cell_sizes(length=False, area=dim == 2, volume=dim == 3)
                       .cell_data["Volume" if dim == 3 else "Area"])
    assert sizes.min() > 0
    # VTK measures a quadratic cell by its straight sub-cells through the nodes: on straight cells that is the
    # cell, and the total is the model's volume; on curved cells it is the polyhedron through the corners and
    # midside nodes, not the curved cells (the blade: -1.64 % of the model's volume, measured; its midside nodes
    # are up to 0.48 mm off the straight edges of a 60 mm blade), so the total is only near the model's volume
    np.testing.assert_allclose(sizes, _tessellation_sizes(grid.points, conn, dim), rtol=1e-10, atol=0)
    if curved:
        assert sizes.sum() == pytest.approx(model.volume, rel=0.03)
    else:
        assert sizes.sum() == pytest.approx(model.volume, rel=1e-10)
    # A quadratic field placed on the nodes, interpolated with VTK's own shape functions of the cell type
    # (its node order) at parametric points inside the cells: exact only if every midside node is where
    # VTK's ordering says it is.  On curved cells the interpolated point x(ξ) is itself a quadratic of ξ, and a
    # quadratic field of x is then quartic in ξ: a linear field (linear in x, so quadratic in ξ like x(ξ)) is
    # the one reproduced exactly.
    field = _linear if curved else _poly
    from vtkmodules.vtkCommonDataModel import vtkQuadraticTetra, vtkQuadraticTriangle

    cell = vtkQuadraticTetra() if dim == 3 else vtkQuadraticTriangle()
    n_nodes = (dim + 1) * (dim + 2) // 2
    rng = np.random.default_rng(7)
    W = []
    for w in rng.dirichlet(np.ones(dim + 1), size=20):
        weights = [0.0] * n_nodes
        cell.InterpolateFunctions((*w[1:], *[0.0] * (3 - dim)), weights)
        W.append(weights)
    W = np.array(W)  # (q, n_nodes)
    L = _size(model)
    values = field(grid.points, dim, L)
    x = np.einsum("qk,ckj->cqj", W, grid.points[conn])
    got = np.einsum("qk,ckj->cqj", W, values[conn])
    np.testing.assert_allclose(got.reshape(-1, dim), field(x.reshape(-1, 3), dim, L), rtol=0, atol=1e-12)
    if curved:  # the quadratic field is not reproduced (measured error 2.0e-4 on values of order 1; the linear
        # field: 4e-16), so the curved cells do bend the map and the linear field is the exact check
        poly = np.einsum("qk,ckj->cqj", W, _poly(grid.points, dim, L)[conn])
        assert np.abs(poly.reshape(-1, dim) - _poly(x.reshape(-1, 3), dim, L)).max() > 1e-6


def test_linear_model_grid(blade1, blade2):
    """P1 on the tetra10 mesh: every node of the mesh, its cells node for node (as mesh.vtu), the vertices first."""
    g1, g2 = fe_grid(blade1), fe_grid(blade2)
    mesh = blade1.mesh
    assert g1.body_type == "tetra10" and len(g1.points) == len(g2.points) == len(mesh.points)
    np.testing.assert_array_equal(g1.points[g1.cells["tetra10"]], mesh.points[mesh.cells["tetra10"]])
    n_v = len(np.unique(mesh.cells["tetra10"][:, :4]))
    np.testing.assert_array_equal(g1.points[:n_v], g2.points[:n_v])  # the same vertices first
    np.testing.assert_array_equal(g1.cells["tetra10"][:, :4], g2.cells["tetra10"][:, :4])


@pytest.mark.parametrize("which", ["plate2", "blade2"])
def test_groups_and_grid_index(which, request):
    model = request.getfixturevalue(which)
    grid, mesh, dim = fe_grid(model), model.mesh, model.dim
    assert set(grid.groups) == set(mesh.groups)
    for name, nodes in mesh.groups.items():
        vertices = np.intersect1d(nodes, np.unique(mesh.cells[mesh.body_type][:, : dim + 1]))
        at = grid_index(model, vertices)
        np.testing.assert_array_equal(grid.points[at], mesh.points[vertices])
        assert set(at) <= set(grid.groups[name])
        # plus the edge nodes whose two ends are in the group, and nothing else
        cells = grid.cells[grid.body_type]
        expected = set(at.tolist())
        for k, (a, b) in enumerate(VTK_EDGES[dim]):
            both = np.isin(cells[:, a], at) & np.isin(cells[:, b], at)
            expected |= set(cells[both, dim + 1 + k].tolist())
        assert set(grid.groups[name].tolist()) == expected
    if "contact" in mesh.groups:
        c = int(mesh.group("contact")[0])
        assert grid_index(model, c) == int(grid.groups["contact"][0])
        assert isinstance(grid_index(model, c), int)


def test_bad_inputs(plate2, blade_mesh):
    n = plate2.n_dofs
    for bad in (np.zeros(n + 1), np.zeros((n, 2, 2)), np.zeros((3, n))):
        with pytest.raises(ValueError, match=r"x_free .*\(n_dofs,\)"):
            nodal_field(plate2, bad)
    with pytest.raises(ValueError, match="x_free must be real"):
        nodal_field(plate2, np.array(["a"] * n))
    with pytest.raises(ValueError, match="model must be an FEModel"):
        fe_grid(blade_mesh)
    with pytest.raises(ValueError, match="out of range"):
        grid_index(plate2, len(plate2.mesh.points))
    with pytest.raises(ValueError, match="integer"):
        grid_index(plate2, 1.5)
    # a tetra10 mesh's own midside node is not a vertex: grid_index maps the body cells' vertices only
    model = bc.assemble(blade_mesh, "steel", order=2)
    with pytest.raises(ValueError, match="not a vertex"):
        grid_index(model, int(blade_mesh.cells["tetra10"][0, 5]))
