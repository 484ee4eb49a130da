"""Every node of a quadratic mesh in every frame: ``fe_grid`` / ``nodal_field`` on meshes of quadratic cells, the
VTK time series and the off-screen animation of them (``bladecase.post.grid``, ``post.vtk``, ``post.animation``).

References: VTK's own cells — the parametric coordinates VTK gives each node of its cell types
(``vtkCell.GetParametricCoords``) against bladecase's node tables (each extra node at the mean of its parent corners),
VTK's interpolation functions (``vtkCell.EvaluateLocation``) reproducing a quadratic field from the nodes, the
outward faces VTK extracts —; ``mesh.vtu`` as :func:`bladecase.save_mesh` writes it (its point count, cell types and
cells, node for node); closed-form fields (a rigid translation: exact everywhere at either order; a quadratic field:
exact at every node for an order-2 model; at order 1 the midside value is the mean of the edge's ends).

Meshes: a CalculiX deck of ``C3D15`` wedges and of ``C3D20R`` hexahedra in millimetres (tests/test_decks.py's
cantilever, 20 × 2 × 2 cells), and structured boxes of every quadratic type (tests/test_fe_elements.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_decks import write_deck
from test_fe_elements import STEEL, WEDGES, box, hex_beam, split
from test_wedge2 import quadratic

from bladecase.fe import Mesh, assemble, load_mesh, natural_frequencies, save_mesh
from bladecase.fe.cells import KINDS
from bladecase.fe.mesh import from_meshio
from bladecase.post.grid import VTK_CELL_TYPES, fe_grid, grid_index, nodal_field, vtk_cells
from bladecase.post.vtk import read_time_series, write_time_series

pv = pytest.importorskip("pyvista")

QUADRATIC_3D = ["tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18"]
QUADRATIC_2D = ["triangle6", "quad8", "quad9"]
L = 0.2  # the boxes' length (m)


def quadratic_box(btype: str) -> Mesh:
    """A straight-sided box of ``btype`` cells, 0.2 × 0.02 (× 0.02) m, 4 × 1 (× 1) cells (wedges: each hexahedron
    cut in two; tetrahedra: in six), with the groups ``root`` (x = 0) and ``contact`` (the tip corner)."""
    kind = KINDS[btype]
    if kind.family == "wedge":
        m = quadratic(split(hex_beam(L, 0.02, (4, 1, 1)), WEDGES), btype)
    elif kind.family == "tetra":
        from test_fe_elements import KUHN

        m = from_meshio(split(hex_beam(L, 0.02, (4, 1, 1)), KUHN))
        m = _tetra10(m)
    else:
        m = box((L, 0.02, 0.02) if kind.dim == 3 else (L, 0.02), (4, 1, 1) if kind.dim == 3 else (4, 1), btype)
    mesh = m if isinstance(m, Mesh) else from_meshio(m, source=btype)
    tip = int(np.argmax(mesh.points @ np.array([1.0, 0.1, 0.01])))
    return Mesh(mesh.points, mesh.cells, mesh.dim, {"root": np.flatnonzero(mesh.points[:, 0] == 0),
                                                    "contact": np.array([tip])}, btype)


def _tetra10(m: Mesh) -> Mesh:
    """``m``'s tetrahedra with a midside node at the middle of each edge (one node per edge)."""
    cells = m.cells["tetra"]
    edges = np.sort(np.stack([cells[:, [a, b]] for a, b in KINDS["tetra10"].parents[4:]], axis=1), axis=2)
    uniq, inv = np.unique(edges.reshape(-1, 2), axis=0, return_inverse=True)
    points = np.vstack([m.points, m.points[uniq].mean(axis=1)])
    return Mesh(points, {"tetra10": np.hstack([cells, len(m.points) + inv.reshape(len(cells), 6)])}, 3)


def deck_mesh(folder: Path, btype: str) -> Mesh:
    """tests/test_decks.py's CalculiX cantilever (mm) of ``C3D15`` wedges or ``C3D20R`` hexahedra, as read."""
    write_deck(folder, btype, {"wedge15": "C3D15", "hexahedron20": "C3D20R"}[btype])
    return load_mesh(folder / "beam.inp", unit="mm")


# ----------------------------------------------------------------------------- VTK's node orders


#: Corners of bladecase's reference cells (positively oriented), by family.
REFERENCE = {"tetra": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], "triangle": [(0, 0, 0), (1, 0, 0), (0, 1, 0)],
             "hexahedron": [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
             "quad": [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
             "wedge": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)]}


@pytest.mark.parametrize("btype", list(VTK_CELL_TYPES))
def test_node_orders_are_vtks(btype):
    """Each node of a bladecase cell is the node VTK's cell type puts at the mean of its parent corners (VTK's
    parametric coordinates), and the faces VTK extracts from a positively oriented cell, as written
    (:func:`vtk_cells`), point outwards. (VTK's linear wedge alone is self-contradictory: its parametric
    coordinates follow gmsh's orientation — bladecase's —, its faces the other one, which meshio and so
    ``mesh.vtu`` write; the frames write it as ``mesh.vtu`` does.)"""
    kind = KINDS[btype]
    name = VTK_CELL_TYPES[btype]
    cell = pv.UnstructuredGrid({pv.CellType[name]: np.arange(kind.n_nodes)[None]},
                               np.zeros((kind.n_nodes, 3))).GetCell(0)
    assert cell.GetNumberOfPoints() == kind.n_nodes
    pc = np.array([cell.GetParametricCoords()[i] for i in range(3 * kind.n_nodes)]).reshape(-1, 3)
    for j, parents in enumerate(kind.parents):
        np.testing.assert_allclose(pc[j], pc[list(parents)].mean(axis=0), atol=1e-15, err_msg=f"node {j}")
    if kind.dim == 2:
        return
    corners = np.array(REFERENCE[kind.family], dtype=float)
    points = np.array([corners[list(p)].mean(axis=0) for p in kind.parents])
    name, conn = vtk_cells(btype, np.arange(kind.n_nodes)[None])
    surf = pv.UnstructuredGrid({pv.CellType[name]: conn}, points).extract_surface(
        algorithm="dataset_surface", nonlinear_subdivision=0)
    assert surf.n_cells == {"tetra": 4, "hexahedron": 6, "wedge": 5}[kind.family]
    for face in surf.irregular_faces:
        q = surf.points[list(face)]
        assert np.cross(q[1] - q[0], q[2] - q[0]) @ (q.mean(axis=0) - points.mean(axis=0)) > 0, face


@pytest.mark.parametrize("btype", QUADRATIC_3D + QUADRATIC_2D)
def test_vtk_interpolates_a_quadratic_field_from_the_grid_nodes(btype):
    """VTK's shape functions of the written cells reproduce a quadratic field from its values at the grid's nodes:
    the midside, face and centre nodes are where VTK's node order says they are."""
    mesh = quadratic_box(btype)
    grid = fe_grid(assemble(mesh, STEEL, order=2, clamp="root", thickness=0.002 if mesh.dim == 2 else None))
    name, conn = vtk_cells(grid.body_type, grid.cells[grid.body_type])
    ug = pv.UnstructuredGrid({pv.CellType[name]: conn}, grid.points)
    from vtkmodules.vtkCommonCore import reference

    rng = np.random.default_rng(3)
    f = _quadratic(grid.points)
    for c in range(ug.n_cells):
        cell = ug.GetCell(c)
        for xi in rng.random((5, 3)):
            if KINDS[btype].family in ("tetra", "triangle", "wedge"):
                xi[:2] *= 0.5  # inside the triangle
            xi[2] = xi[2] if mesh.dim == 3 else 0.0
            x, w = [0.0, 0.0, 0.0], [0.0] * cell.GetNumberOfPoints()
            cell.EvaluateLocation(reference(0), xi, x, w)
            ids = [cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())]
            np.testing.assert_allclose(np.asarray(w) @ f[ids], _quadratic(np.array([x]))[0], rtol=0, atol=1e-12)


def _quadratic(x: np.ndarray) -> np.ndarray:
    """A full quadratic field of ``x / L`` (3 components)."""
    y = x / L
    X, Y, Z = y[:, 0], y[:, 1], y[:, 2]
    return np.column_stack([0.3 + X - 2 * Y + X * Y + 0.5 * Y**2 + Z**2, -0.7 + X**2 + 0.2 * X * Y - Y * Z,
                            1.1 - Z + X * Z + Y**2])


# ----------------------------------------------------------------------------- the grid and the field on it


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("btype", QUADRATIC_3D + QUADRATIC_2D)
def test_grid_is_the_mesh_node_for_node(btype, order):
    """Every node and cell of the quadratic mesh (the cells node for node), at either order; the vertices first;
    ``grid_index`` of every node."""
    mesh = quadratic_box(btype)
    model = assemble(mesh, STEEL, order=order, clamp="root", thickness=0.002 if mesh.dim == 2 else None)
    grid = fe_grid(model)
    cells = grid.cells[btype]
    assert grid.body_type == btype and len(grid.points) == len(mesh.points)
    np.testing.assert_array_equal(grid.points[cells], mesh.points[mesh.cells[btype]])
    if order == 1 or KINDS[btype].family not in ("tetra", "triangle"):  # a grid of the mesh's nodes: each has one
        np.testing.assert_array_equal(grid.points[grid_index(model, np.arange(len(mesh.points)))], mesh.points)
    corners = np.unique(mesh.cells[btype][:, : KINDS[btype].corners])
    np.testing.assert_array_equal(grid.points[: corners.size], mesh.points[corners])
    # the root group: its nodes, midside ones included (the face x = 0)
    assert set(np.flatnonzero(grid.points[:, 0] == 0)) == set(grid.groups["root"].tolist())


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("btype", QUADRATIC_3D + QUADRATIC_2D)
def test_rigid_translation_is_exact_at_every_node(btype, order):
    mesh = quadratic_box(btype)
    model = assemble(mesh, STEEL, order=order, clamp=None, thickness=0.002 if mesh.dim == 2 else None)
    shift = np.array([1e-4, -2e-4, 3e-4])[: mesh.dim]
    u = nodal_field(model, shift[model.dofs.direction])
    grid = fe_grid(model)
    assert u.shape == (len(grid.points), mesh.dim)
    np.testing.assert_allclose(u, np.broadcast_to(shift, u.shape), rtol=0, atol=1e-18)


@pytest.mark.parametrize("btype", QUADRATIC_3D + QUADRATIC_2D)
def test_quadratic_field_at_the_midside_nodes(btype):
    """Order 2: the field at each midside (face, centre) node is the model's dof there, exact for a quadratic field.
    Order 1: the straight cell's linear field, the mean of the edge's two ends."""
    mesh = quadratic_box(btype)
    kind, dim = KINDS[btype], mesh.dim
    thickness = 0.002 if dim == 2 else None
    model = assemble(mesh, STEEL, order=2, clamp="root", thickness=thickness)
    d = model.dofs
    x = _quadratic(d.coords)[np.arange(len(d)), d.direction]
    grid = fe_grid(model)
    u = nodal_field(model, np.column_stack([x, 2 * x]))
    expected = _quadratic(grid.points)[:, :dim]
    expected[grid.groups["root"]] = 0.0  # clamped
    np.testing.assert_allclose(u[:, :, 0], expected, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(u[:, :, 1], 2 * u[:, :, 0])
    # order 1: a midside node gets the mean of its edge's ends (a face or cell centre: of its corners)
    model = assemble(mesh, STEEL, order=1, clamp="root", thickness=thickness)
    d = model.dofs
    u = nodal_field(model, _quadratic(d.coords)[np.arange(len(d)), d.direction])
    grid = fe_grid(model)
    cells = grid.cells[btype]
    for k in range(kind.corners, kind.n_nodes):
        mean = u[cells[:, list(kind.parents[k])]].mean(axis=1)
        np.testing.assert_allclose(u[cells[:, k]], mean, rtol=0, atol=1e-15)
    free = ~np.isin(np.arange(len(grid.points)), grid.groups["root"])
    assert np.abs(u[free] - _quadratic(grid.points)[free, :dim]).max() > 1e-3  # not the quadratic field


# ----------------------------------------------------------------------------- frames of a deck


def _orbit(model, frames: int = 5):
    """A mode shape times cos(2π t / T) over one period (the free dofs, frames as columns) and the times."""
    f, phi = natural_frequencies(model, 1, return_modes=True)
    times = np.arange(frames) / (frames * f[0])
    return phi[:, :1] * np.cos(2 * np.pi * f[0] * times), times


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("btype", ["wedge15", "hexahedron20"])
def test_time_series_frames_hold_the_points_and_cells_of_mesh_vtu(tmp_path, btype, order):
    mesh = deck_mesh(tmp_path, btype)
    save_mesh(mesh, tmp_path / "mesh.vtu")
    vtu = pv.read(tmp_path / "mesh.vtu")
    model = assemble(mesh, STEEL, order=order, clamp="boundary")
    grid = fe_grid(model)
    x, times = _orbit(model)
    u, v = nodal_field(model, x), nodal_field(model, -x)
    pvd = write_time_series(tmp_path, "orbit", grid, times, u, v, field_data={"period": 1.0})
    _, files = read_time_series(pvd)
    assert len(files) == len(times)
    corners = np.unique(mesh.cells[btype][:, : KINDS[btype].corners]).size
    assert vtu.n_points == len(mesh.points) > corners  # 189 corners of 621 nodes (hexahedra), of 741 (wedges)
    moved = []
    for j, f in enumerate(files):
        frame = pv.read(f)
        assert frame.n_points == vtu.n_points and frame.n_cells == vtu.n_cells
        assert set(np.unique(frame.celltypes)) == set(np.unique(vtu.celltypes)) == {
            int(pv.CellType[VTK_CELL_TYPES[btype]])}
        # the same cells, node for node: the same coordinates at each node of each cell
        np.testing.assert_array_equal(frame.points[frame.cell_connectivity], vtu.points[vtu.cell_connectivity])
        np.testing.assert_array_equal(frame.cell_offsets, vtu.cell_offsets)
        np.testing.assert_allclose(frame.point_data["displacement"], u[:, :, j], rtol=0, atol=0)
        moved.append(np.abs(frame.point_data["displacement"]).max())
    assert min(moved) > 0
    # the clamped root, midside nodes included, does not move; a midside node of the tip does
    frame = pv.read(files[0])
    root = np.flatnonzero(grid.points[:, 0] == 0)
    assert root.size == 21 and np.abs(frame.point_data["displacement"][root]).max() == 0.0
    tip_mid = np.setdiff1d(np.flatnonzero(np.isclose(grid.points[:, 0], 0.2)), np.arange(corners))
    assert tip_mid.size and np.abs(frame.point_data["displacement"][tip_mid]).min() > 0


def test_linear_wedges_are_written_as_mesh_vtu_writes_them(tmp_path):
    """Linear wedges: the frames hold meshio's VTK order, as ``mesh.vtu`` does (VTK's faces outward)."""
    mesh = from_meshio(split(hex_beam(L, 0.02, (4, 1, 1)), WEDGES), source="wedges")
    mesh = Mesh(mesh.points, mesh.cells, 3, {"root": np.flatnonzero(mesh.points[:, 0] == 0)}, "wedges")
    save_mesh(mesh, tmp_path / "mesh.vtu")
    model = assemble(mesh, STEEL, order=1)
    x, times = _orbit(model, 2)
    u = nodal_field(model, x)
    pvd = write_time_series(tmp_path, "orbit", fe_grid(model), times, u, u)
    vtu, frame = pv.read(tmp_path / "mesh.vtu"), pv.read(read_time_series(pvd)[1][0])
    np.testing.assert_array_equal(frame.points[frame.cell_connectivity], vtu.points[vtu.cell_connectivity])


# ----------------------------------------------------------------------------- the animation


@pytest.mark.parametrize("btype", ["wedge15", "hexahedron20", "hexahedron27", "wedge18"])
def test_drawn_surface_interpolates_the_field_of_the_quadratic_cells(btype):
    from scipy.spatial import cKDTree

    from bladecase.post import animation as viz

    grid = fe_grid(assemble(quadratic_box(btype), STEEL, order=2, clamp="root"))
    u = _quadratic(grid.points) * 1e-4
    u3 = np.stack([u, -u], axis=2)
    _, surf, ref, su = viz._surface(grid.points, grid, 3, u3)
    np.testing.assert_allclose(su[:, :, 0], _quadratic(ref) * 1e-4, rtol=0, atol=1e-16)
    np.testing.assert_allclose(su[:, :, 1], -su[:, :, 0], rtol=0, atol=0)
    boundary = grid.points[(grid.points[:, 0] == 0) | np.isclose(grid.points[:, 0], L)]
    assert cKDTree(ref).query(boundary)[0].max() < 1e-12  # every node of the end faces, midside ones included


@pytest.mark.parametrize("btype", ["wedge15", "hexahedron20"])
def test_animation_of_a_deck_renders_off_screen(tmp_path, btype):
    imageio = pytest.importorskip("imageio.v3")
    from bladecase.post import animation as viz

    mesh = deck_mesh(tmp_path, btype)
    model = assemble(mesh, STEEL, order=2, clamp="boundary")
    grid = fe_grid(model)
    x, times = _orbit(model, 4)
    u = nodal_field(model, x)
    tip = int(np.argmax(grid.points @ np.array([1.0, 0.1, 0.01])))
    written = viz.animate(grid, u, times, period=4 * times[1], impact_frames=np.arange(4) == 0, contact_node=tip,
                          normal=[0, 0, 1.0], gap=1e-5, scale=viz.auto_scale(grid, u), gif=tmp_path / "orbit.gif",
                          window_size=(240, 180))
    frames = imageio.imread(written["gif"], index=None)[..., :3]
    assert frames.shape[:3] == (4, 180, 240)
    assert all(img.std() > 10.0 for img in frames)
    assert min(np.abs(frames[i].astype(int) - frames[0]).max() for i in range(1, 4)) > 0
