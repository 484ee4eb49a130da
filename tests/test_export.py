"""VTK export for ParaView: the .pvd time series of an orbit on the mesh and the manifold quad surface.

References are the inputs themselves: synthetic fields on the real meshes
(``u = A (s/span)² cos(2πt/T)`` along ``x`` plus a smaller ``sin`` part along
the second axis, ``v = ∂u/∂t`` in closed form), read back with meshio and with
pyvista's PVD reader (what ParaView users open), and an explicit loop-built
quad connectivity for the manifold.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest

import bladecase as bc
from bladecase.post.vtk import read_time_series, write_manifold, write_time_series

MESHES = Path(__file__).resolve().parents[1] / "meshes"
T = 2.37e-3
F = 7
AMP = 1.3e-3


@pytest.fixture(scope="module")
def blade() -> bc.Mesh:
    return bc.load_mesh(MESHES / "twisted_blade.msh")


@pytest.fixture(scope="module")
def plate() -> bc.Mesh:
    return bc.load_mesh(MESHES / "plate.msh")


def orbit_fields(mesh: bc.Mesh, n_frames: int = F):
    """Times and synthetic (u, v) of shape (n_nodes, dim, n_frames); span along z (3-D) or y (2-D)."""
    times = np.arange(n_frames) * T / n_frames
    axis = 2 if mesh.dim == 3 else 1
    s = mesh.points[:, axis]
    shape = (s / s.max()) ** 2
    w = 2 * np.pi / T
    u = np.zeros((len(s), mesh.dim, n_frames))
    v = np.zeros_like(u)
    u[:, 0] = AMP * shape[:, None] * np.cos(w * times)
    v[:, 0] = -AMP * w * shape[:, None] * np.sin(w * times)
    u[:, 1] = 0.2 * AMP * shape[:, None] * np.sin(w * times)
    v[:, 1] = 0.2 * AMP * w * shape[:, None] * np.cos(w * times)
    return times, u, v, shape


def pad3(a: np.ndarray) -> np.ndarray:
    """(n, dim) -> (n, 3), zero z in 2-D."""
    return np.column_stack([a, np.zeros((len(a), 3 - a.shape[1]))])


def close(actual, expected, rtol=1e-12):
    """Agreement to ``rtol`` relative to the largest magnitude of ``expected``."""
    expected = np.asarray(expected, dtype=float)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * max(np.abs(expected).max(), 1e-300))


@pytest.mark.parametrize("which", ["blade", "plate"])
def test_time_series_round_trip(which, tmp_path, request):
    mesh = request.getfixturevalue(which)
    times, u, v, shape = orbit_fields(mesh)
    out = tmp_path / "results"  # created by the writer
    pvd = write_time_series(
        out, "orbit", mesh, times, u, v,
        point_data={"shape": shape, "shape3": np.column_stack([shape, 2 * shape, 3 * shape])},
        field_data={"period": T, "energy": 0.125},
    )
    assert pvd == out / "orbit.pvd" and pvd.is_file()
    assert sorted(os.listdir(out)) == ["orbit", "orbit.pvd"]  # no temporary folders left

    # The .pvd is a standard ParaView collection with relative file paths.
    root = ET.parse(pvd).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    items = root.find("Collection").findall("DataSet")
    assert [d.get("file") for d in items] == [f"orbit/orbit_{j:04d}.vtu" for j in range(F)]
    assert all(d.get("part") == "0" for d in items)

    t_read, files = read_time_series(pvd)
    np.testing.assert_allclose(t_read, times, rtol=1e-15, atol=0)
    assert len(files) == F and all(f.is_file() for f in files)
    assert files == [(out / "orbit" / f"orbit_{j:04d}.vtu").resolve() for j in range(F)]
    assert sorted(os.listdir(out / "orbit")) == [f"orbit_{j:04d}.vtu" for j in range(F)]

    body = mesh.body_type
    for j, f in enumerate(files):
        m = meshio.read(f)
        np.testing.assert_array_equal(m.points, mesh.points)
        assert [c.type for c in m.cells] == [body]
        np.testing.assert_array_equal(m.cells[0].data, mesh.cells[body])
        disp, vel = m.point_data["displacement"], m.point_data["velocity"]
        assert disp.shape == vel.shape == (len(mesh.points), 3)
        close(disp, pad3(u[:, :, j]))
        close(vel, pad3(v[:, :, j]))
        close(m.point_data["displacement_magnitude"], np.linalg.norm(u[:, :, j], axis=1))
        close(m.point_data["shape"], shape)
        close(m.point_data["shape3"], np.column_stack([shape, 2 * shape, 3 * shape]))
        for name, nodes in mesh.groups.items():
            mask = m.point_data[f"group:{name}"]
            assert mask.dtype == np.uint8
            np.testing.assert_array_equal(np.flatnonzero(mask), nodes)
        np.testing.assert_allclose(m.field_data["time"], [times[j]], rtol=1e-15, atol=0)
        np.testing.assert_allclose(m.field_data["period"], [T], rtol=1e-15, atol=0)
        np.testing.assert_allclose(m.field_data["energy"], [0.125], rtol=1e-15, atol=0)
    if mesh.dim == 2:
        assert np.all(meshio.read(files[1]).point_data["displacement"][:, 2] == 0)


@pytest.mark.parametrize("which", ["blade", "plate"])
def test_time_series_opens_in_pyvista(which, tmp_path, request):
    pv = pytest.importorskip("pyvista")
    mesh = request.getfixturevalue(which)
    times, u, v, _ = orbit_fields(mesh)
    pvd = write_time_series(tmp_path, "orbit", mesh, times, u, v, field_data={"period": T})
    reader = pv.get_reader(str(pvd))
    assert type(reader).__name__ == "PVDReader"
    np.testing.assert_allclose(reader.time_values, times, rtol=1e-15, atol=0)
    for j, t in enumerate(reader.time_values):
        reader.set_active_time_value(t)
        data = reader.read()
        block = data[0] if isinstance(data, pv.MultiBlock) else data
        assert block.n_points == len(mesh.points)
        assert block.n_cells == len(mesh.cells[mesh.body_type])
        close(block.point_data["displacement"], pad3(u[:, :, j]))
        close(block.point_data["velocity"], pad3(v[:, :, j]))
        # VTK reads the field data.
        np.testing.assert_allclose(block.field_data["time"], [times[j]], rtol=1e-15, atol=0)
        np.testing.assert_allclose(block.field_data["period"], [T], rtol=1e-15, atol=0)


def test_rewrite_replaces_old_frames(blade, tmp_path):
    times, u, v, _ = orbit_fields(blade)
    write_time_series(tmp_path, "orbit", blade, times, u, v)
    times3, u3, v3, _ = orbit_fields(blade, 3)
    pvd = write_time_series(tmp_path, "orbit", blade, times3, 2 * u3, v3)
    assert sorted(os.listdir(tmp_path)) == ["orbit", "orbit.pvd"]
    assert sorted(os.listdir(tmp_path / "orbit")) == [f"orbit_{j:04d}.vtu" for j in range(3)]
    t_read, files = read_time_series(pvd)
    np.testing.assert_allclose(t_read, times3, rtol=1e-15, atol=0)
    close(meshio.read(files[2]).point_data["displacement"], 2 * u3[:, :, 2])
    # Another stem in the same folder is independent.
    write_time_series(tmp_path, "other", blade, times3[:1], u3[:, :, :1], v3[:, :, :1])
    assert sorted(os.listdir(tmp_path)) == ["orbit", "orbit.pvd", "other", "other.pvd"]
    assert len(read_time_series(tmp_path / "orbit.pvd")[1]) == 3


def _fail_after(monkeypatch, n_ok: int):
    """The frame writer (VTK's, through ``pyvista.UnstructuredGrid.save``) fails after ``n_ok`` frames."""
    import pyvista as pv

    real = pv.UnstructuredGrid.save
    calls = {"n": 0}

    def failing(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > n_ok:
            raise OSError("disk full (simulated)")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(pv.UnstructuredGrid, "save", failing)
    return calls


def test_failed_write_leaves_nothing(blade, tmp_path, monkeypatch):
    times, u, v, _ = orbit_fields(blade)
    calls = _fail_after(monkeypatch, 3)
    with pytest.raises(OSError, match="simulated"):
        write_time_series(tmp_path / "out", "orbit", blade, times, u, v)
    assert calls["n"] == 4
    assert os.listdir(tmp_path / "out") == []  # no .pvd, no stem folder, no temporary folder


def test_failed_write_keeps_previous_result(blade, tmp_path, monkeypatch):
    times, u, v, _ = orbit_fields(blade)
    pvd = write_time_series(tmp_path, "orbit", blade, times, u, v)
    before = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    _fail_after(monkeypatch, 3)
    times5, u5, v5, _ = orbit_fields(blade, 5)
    with pytest.raises(OSError, match="simulated"):
        write_time_series(tmp_path, "orbit", blade, times5, u5, v5)
    after = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert after == before
    assert sorted(os.listdir(tmp_path)) == ["orbit", "orbit.pvd"]
    np.testing.assert_allclose(read_time_series(pvd)[0], times, rtol=1e-15, atol=0)


def _bad_stem(times, u, v):
    return dict(stem="a/b")


def _bad_u(times, u, v):
    return dict(u=u[:, :, :-1])


def _nan_v(times, u, v):
    v = v.copy()
    v[10, 0, 3] = np.nan
    return dict(v=v)


def _decreasing_times(times, u, v):
    return dict(times=times[::-1].copy())


@pytest.mark.parametrize(
    "bad, name",
    [
        (_bad_stem, "stem"),
        (lambda t, u, v: dict(stem=""), "stem"),
        (_bad_u, "u"),
        (lambda t, u, v: dict(u=u[:, :2].copy(), v=v[:, :2].copy()), "u"),  # 2 components on a 3-D mesh
        (_nan_v, "v"),
        (_decreasing_times, "times"),
        (lambda t, u, v: dict(times=t[:, None]), "times"),
        (lambda t, u, v: dict(point_data={"shape": np.ones(5)}), "point_data"),
        (lambda t, u, v: dict(point_data={"displacement": np.ones(len(u))}), "point_data"),
        (lambda t, u, v: dict(field_data={"period": np.nan}), "field_data"),
    ],
)
def test_bad_inputs(blade, tmp_path, bad, name):
    times, u, v, _ = orbit_fields(blade)
    args = dict(stem="orbit", times=times, u=u, v=v)
    args.update(bad(times, u, v))
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        write_time_series(tmp_path, args.pop("stem"), blade, args.pop("times"), args.pop("u"), args.pop("v"), **args)
    assert os.listdir(tmp_path) == []


def test_read_time_series_rejects_non_collection(tmp_path):
    p = tmp_path / "x.pvd"
    p.write_text('<?xml version="1.0"?><VTKFile type="UnstructuredGrid"><UnstructuredGrid/></VTKFile>')
    with pytest.raises(ValueError, match="Collection"):
        read_time_series(p)


# ----------------------------------------------------------------------------- manifold


def manifold_samples(n_orbits=5, n_times=12):
    """A family of ellipses of growing size (closed in phase): coordinates and point data."""
    a = np.linspace(1.0, 2.0, n_orbits)[:, None]
    phi = 2 * np.pi * np.arange(n_times)[None, :] / n_times
    coords = np.stack(np.broadcast_arrays(a * np.cos(phi), 0.5 * a * np.sin(phi), 0.1 * a + 0 * phi), axis=-1)
    energy = np.broadcast_to(a**2, (n_orbits, n_times)).copy()
    vel = np.stack([-np.sin(phi) * a, np.cos(phi) * a + 0 * a], axis=-1)
    return coords, {"energy": energy, "velocity2": vel}


@pytest.mark.parametrize("closed", [True, False])
def test_manifold_round_trip(tmp_path, closed):
    n_orbits, n_times = 5, 12
    coords, data = manifold_samples(n_orbits, n_times)
    path = write_manifold(tmp_path / "sub" / "manifold.vtu", coords, point_data=data, closed=closed)
    assert path == tmp_path / "sub" / "manifold.vtu"
    assert os.listdir(tmp_path / "sub") == ["manifold.vtu"]
    m = meshio.read(path)
    assert len(m.points) == n_orbits * n_times
    np.testing.assert_array_equal(m.points, coords.reshape(-1, 3))
    assert [c.type for c in m.cells] == ["quad"]
    quads = m.cells[0].data
    assert len(quads) == (n_orbits - 1) * (n_times if closed else n_times - 1)
    expected = [
        [i * n_times + j, (i + 1) * n_times + j, (i + 1) * n_times + (j + 1) % n_times, i * n_times + (j + 1) % n_times]
        for i in range(n_orbits - 1)
        for j in range(n_times if closed else n_times - 1)
    ]
    np.testing.assert_array_equal(quads, expected)
    np.testing.assert_array_equal(m.point_data["energy"], data["energy"].ravel())
    np.testing.assert_array_equal(m.point_data["velocity2"], data["velocity2"].reshape(-1, 2))
    np.testing.assert_array_equal(m.point_data["orbit"], np.repeat(np.arange(n_orbits), n_times))
    np.testing.assert_array_equal(m.point_data["phase_index"], np.tile(np.arange(n_times), n_orbits))


def test_manifold_opens_in_pyvista(tmp_path):
    pv = pytest.importorskip("pyvista")
    coords, data = manifold_samples()
    grid = pv.read(write_manifold(tmp_path / "manifold.vtu", coords, point_data=data))
    assert grid.n_points == coords.shape[0] * coords.shape[1]
    assert grid.n_cells == (coords.shape[0] - 1) * coords.shape[1]
    # Projected on xy, the quads tile the ring between the inscribed n-gons of the ellipses with
    # semi-axes (1, 1/2) and (2, 1): area (n/4) sin(2π/n) (2² - 1²).
    n = coords.shape[1]
    area_xy = 0.5 * n * np.sin(2 * np.pi / n) * 0.5 * (2.0**2 - 1.0**2)
    pts = np.array(grid.points)
    pts[:, 2] = 0.0
    grid.points = pts
    areas = grid.compute_cell_sizes(length=False, area=True, volume=False).cell_data["Area"]
    assert areas.sum() == pytest.approx(area_xy, rel=1e-12)


@pytest.mark.parametrize(
    "coords, kwargs, name",
    [
        (np.zeros((1, 5, 3)), {}, "coords"),
        (np.zeros((3, 1, 3)), {}, "coords"),
        (np.zeros((3, 5, 2)), {}, "coords"),
        (np.full((3, 5, 3), np.nan), {}, "coords"),
        (np.zeros((3, 5, 3)), {"point_data": {"e": np.zeros((3, 4))}}, "point_data"),
        (np.zeros((3, 5, 3)), {"point_data": {"orbit": np.zeros((3, 5))}}, "point_data"),
    ],
)
def test_manifold_bad_inputs(tmp_path, coords, kwargs, name):
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        write_manifold(tmp_path / "m.vtu", coords, **kwargs)
    assert os.listdir(tmp_path) == []


def test_manifold_rejects_other_suffix(tmp_path):
    coords, _ = manifold_samples()
    with pytest.raises(ValueError, match=r"\.vtu"):
        write_manifold(tmp_path / "m.vtk", coords)


# ----------------------------------------------------------------------------- P2 models: every FE node


@pytest.fixture(scope="module", params=["plate", "blade"])
def p2_model(request) -> bc.FEModel:
    if request.param == "plate":
        return bc.assemble(bc.load_mesh(MESHES / "plate.vtu"), "steel", order=2, thickness=0.002)
    return request.getfixturevalue("twisted_blade_p2")  # conftest's: shared with tests/test_viz.py


def test_p2_series_has_all_nodes_and_quadratic_cells(p2_model, tmp_path):
    """A P2 field written on ``fe_grid``: all FE nodes (vertices and edge midpoints) and quadratic cells,
    read back with meshio and with pyvista's PVD reader; the field at every node is the model's dof value."""
    pv = pytest.importorskip("pyvista")
    from bladecase.post.grid import fe_grid, nodal_field

    model, dim = p2_model, p2_model.dim
    grid = fe_grid(model)
    n_vertices = len(np.unique(model.mesh.cells[model.mesh.body_type][:, : dim + 1]))
    assert len(grid.points) == model.dofs.n_total // dim > n_vertices
    # u at the dofs: the synthetic orbit, evaluated at each dof's location
    times = np.arange(F) * T / F
    d = model.dofs
    s = d.coords[:, dim - 1] / d.coords[:, dim - 1].max()
    amp = np.where(d.direction == 0, AMP, 0.2 * AMP) * s**2
    x = amp[:, None] * np.cos(2 * np.pi * times / T + 0.3 * d.direction[:, None])
    u, v = nodal_field(model, x), nodal_field(model, -x)
    pvd = write_time_series(tmp_path, "p2", grid, times, u, v, field_data={"period": T})

    body = grid.body_type
    assert body == ("tetra10" if dim == 3 else "triangle6")
    expected = np.zeros((len(grid.points), dim, F))
    expected[d.fe_index // dim, d.direction] = x
    _, files = read_time_series(pvd)
    for j, f in enumerate(files):
        m = meshio.read(f)
        np.testing.assert_array_equal(m.points, grid.points)
        assert [c.type for c in m.cells] == [body]
        np.testing.assert_array_equal(m.cells[0].data, grid.cells[body])
        close(m.point_data["displacement"], pad3(expected[:, :, j]))
        close(m.point_data["velocity"], pad3(-expected[:, :, j]))
        np.testing.assert_allclose(m.field_data["time"], [times[j]], rtol=1e-15, atol=0)
    reader = pv.get_reader(str(pvd))
    quadratic = pv.CellType.QUADRATIC_TETRA if dim == 3 else pv.CellType.QUADRATIC_TRIANGLE
    for j, t in enumerate(reader.time_values):
        reader.set_active_time_value(t)
        data = reader.read()
        block = data[0] if isinstance(data, pv.MultiBlock) else data
        assert block.n_points == len(grid.points)
        assert set(np.asarray(block.celltypes)) == {int(quadratic)}
        close(block.point_data["displacement"], pad3(expected[:, :, j]))
        np.testing.assert_allclose(block.field_data["period"], [T], rtol=1e-15, atol=0)
        size = block.compute_cell_sizes(length=False, area=dim == 2, volume=dim == 3)
        assert np.asarray(size.cell_data["Volume" if dim == 3 else "Area"]).min() > 0
