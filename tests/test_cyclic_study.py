"""The cyclic stage of a study end to end through the CLI, on a coarse parametric sector (``[geometry] kind =
"sector"``, 6 blades): ``cyclic.csv`` checked against the whole disk assembled as one ordinary mesh (the sector
written to ``mesh.vtu`` turned 6 times by scipy, nodes merged: the union of the nodal diameters' frequencies, each
double for 0 < k < 3, equals its lowest frequencies to 1e-8), the annulus VTK series checked as a forward travelling
wave (a phase step of ``kα`` shows each sector what the previous one showed, turned by ``+α``), the Campbell diagram
per nodal diameter, and the errors of bad keys (exit 2, nothing published)."""

from __future__ import annotations

import csv
import json
import math

import meshio
import numpy as np
import pytest
from _cyclic_util import annulus
from scipy.spatial import cKDTree

from bladecase.cli import main
from bladecase.fe import assemble, load_mesh, natural_frequencies
from bladecase.fe.cyclic import rotation_matrix
from bladecase.post.vtk import read_time_series

N, RIM = 6, 0.2
GEOMETRY = (f'geometry = {{kind = "sector", sectors = {N}, hub_radius = 0.1, rim_radius = {RIM}, '
            'disk_thickness = 0.03, span = 0.1, root_chord = 0.03, thickness = 0.005, size = 0.03}')


def _write(tmp_path, extra: str = "", formats: str = '["vtu", "png"]') -> str:
    path = tmp_path / "disk.toml"
    path.write_text(f'study = {{name = "disk"}}\n{GEOMETRY}\nfem = {{order = 1, mass = "consistent"}}\n'
                    f'output = {{formats = {formats}, frames = {N}}}\n{extra}\n')
    return str(path)


@pytest.fixture(scope="module")
def disk(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("disk")
    study = _write(tmp, "[cyclic]\nmodes = 3\nengine_orders = [1, 5, 7]")
    assert main(["run", study, "--out", str(tmp / "out"), "--quiet"]) == 0
    return tmp / "out"


def test_outputs_and_summary(disk):
    names = {p.name for p in disk.iterdir()}
    assert {"cyclic.csv", "safe.png", "summary.json", "report.md", "run.log", "vtk", "mesh.vtu"} <= names
    s = json.loads((disk / "summary.json").read_text())
    c = s["cyclic"]
    assert c["sectors"] == N and [d["nd"] for d in c["diameters"]] == [0, 1, 2, 3]
    assert [d["multiplicity"] for d in c["diameters"]] == [1, 2, 2, 1]
    assert [(r["order"], r["diameter"]) for r in c["engine_orders"]] == [(1, 1), (5, 1), (7, 1)]
    assert c["speed_rad_s"] is None and c["expanded"]["wave"] == "forward" and c["expanded"]["diameter"] == 1
    report = (disk / "report.md").read_text()
    assert "| 5 | 1 |" in report and "at rest" in s["verdict"]["found"]


def test_frequencies_equal_the_whole_disk_as_one_mesh(disk):
    rows = list(csv.DictReader(open(disk / "cyclic.csv")))
    assert [r["nd"] for r in rows] == [str(k) for k in (0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3)]
    f = np.sort(np.concatenate([[float(r["frequency_hz"])] * int(r["multiplicity"]) for r in rows]))
    sector = load_mesh(disk / "mesh.vtu")
    whole = annulus(sector, N, origin=(0.0, 0.0, -RIM), tol=1e-7)
    model = assemble(whole, "Ti-6Al-4V", order=1, clamp="hub")
    ref = natural_frequencies(model, 12)
    top = min(float(r["frequency_hz"]) for r in rows if r["mode"] == "3")   # below it the union is complete
    n = int(np.sum(f < top))
    assert n >= 9 and np.max(np.abs(f[:n] / ref[:n] - 1)) < 1e-8


def test_the_annulus_series_is_a_forward_wave(disk):
    times, files = read_time_series(disk / "vtk" / "annulus_nd1_mode1_forward.pvd")
    assert len(files) == N + 1
    a, b = (meshio.read(disk / "vtk" / p) for p in files[:2])
    u0, u1 = a.point_data["displacement"], b.point_data["displacement"]
    o, alpha = np.array([0.0, 0.0, -RIM]), 2 * math.pi / N
    R = rotation_matrix((1.0, 0.0, 0.0), alpha)
    back = (a.points - o) @ R + o                      # each node turned by -α: where it was one sector before
    d, j = cKDTree(a.points).query(back)
    assert d.max() < 1e-9
    # one phase step kα = α later, each node shows its predecessor's displacement turned by +α: a forward wave
    assert np.abs(u1 - u0[j] @ R.T).max() < 1e-9 * np.abs(u0).max()
    assert np.abs(u1 - u0[j]).max() > 0.1 * np.abs(u0).max()   # not trivially so


def test_campbell_per_nodal_diameter(tmp_path):
    study = _write(tmp_path, '[cyclic]\nmodes = 1\ndiameters = [0, 3]\n[rotation]\nspeeds = [0, 20000]\n'
                   f'axis = {{origin = [0, 0, {-RIM}], direction = [1, 0, 0]}}\nengine_orders = [3]', '["png"]')
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    c = json.loads((tmp_path / "out" / "summary.json").read_text())["cyclic"]
    assert (tmp_path / "out" / "campbell_nd.png").is_file() and (tmp_path / "out" / "safe.png").is_file()
    table = c["campbell"]["frequencies_hz"]
    assert sorted(table) == ["0", "3"] and c["speed_rpm"] == pytest.approx(20000)
    for d in c["diameters"]:   # the SAFE speed is the top Campbell speed: the same frequencies
        assert table[str(d["nd"])][-1][0] == pytest.approx(d["frequencies_hz"][0], rel=1e-9)
    assert table["0"][1][0] > table["0"][0][0]          # the disk stiffens with speed


@pytest.mark.parametrize("extra, words", [
    ("[cyclic]\ndiameters = [4]", "[cyclic] diameters: 4 is not a nodal diameter of a disk of 6 sectors (0 … 3)"),
    ('[cyclic]\nexpand = {diameter = 3, wave = "forward"}', "has standing waves only (k = 0 or N/2)"),
    ("[cyclic]\nsectors = 7", "[cyclic] sectors: the sector geometry has [geometry] sectors = 6, got 7"),
    ("[cyclic]\nexpand = {diameter = 1, mode = 5}", "[cyclic] expand: mode = 5, but [cyclic] modes = 4"),
    ("[contact]\nclearance = 1e-4", "[contact]: a cyclic study"),
])
def test_bad_keys_exit_2(tmp_path, capsys, extra, words):
    study = _write(tmp_path, extra)
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err and not (tmp_path / "out").exists(), err


def test_too_few_sectors_for_a_sector_geometry(tmp_path, capsys):
    path = tmp_path / "disk.toml"
    path.write_text(GEOMETRY.replace(f"sectors = {N}", "sectors = 2") + "\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "[geometry] sectors: must be" in capsys.readouterr().err


def _vtu_study(tmp_path, cyclic: str) -> str:
    from _cyclic_util import hex_sector

    from bladecase.fe import save_mesh

    save_mesh(hex_sector(8), tmp_path / "sector.vtu")
    path = tmp_path / "s.toml"
    path.write_text('mesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\nfem = {order = 1, clamp = "hub"}\n'
                    'output = {formats = []}\nrotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n'
                    f"[cyclic]\n{cyclic}\n")
    return str(path)


def test_a_sector_mesh_file_with_faces_found_by_angle(tmp_path):
    from _cyclic_util import hex_sector

    assert main(["run", _vtu_study(tmp_path, "sectors = 8\nmodes = 2"), "--out", str(tmp_path / "out"),
                 "--quiet"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "out" / "cyclic.csv")))
    f = np.sort(np.concatenate([[float(r["frequency_hz"])] * int(r["multiplicity"]) for r in rows]))
    whole = assemble(annulus(hex_sector(8), 8), "steel", order=1, clamp="hub")
    ref = natural_frequencies(whole, 8)
    n = int(np.sum(f < min(float(r["frequency_hz"]) for r in rows if r["mode"] == "2")))
    assert n >= 8 and np.max(np.abs(f[:n] / ref[:n] - 1)) < 1e-8
    s = json.loads((tmp_path / "out" / "summary.json").read_text())["cyclic"]
    assert s["faces"]["from"] == "sector angle" and s["expanded"] is None


@pytest.mark.parametrize("cyclic, words", [
    ("sectors = 7", "the sector spans 45° about the axis, but 7 sectors need 51.4286°"),
    ("modes = 2", "[cyclic] sectors: required for a sector mesh without *CYCLIC SYMMETRY MODEL"),
])
def test_a_sector_mesh_file_errors(tmp_path, capsys, cyclic, words):
    assert main(["run", _vtu_study(tmp_path, cyclic), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert words in capsys.readouterr().err


def test_a_file_of_the_users_with_a_cyclic_result_name_stops_the_run(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "safe.png").write_text("my own figure")
    assert main(["run", _write(tmp_path, "[cyclic]\nmodes = 1"), "--out", str(out), "--quiet"]) == 2
    assert "safe.png" in capsys.readouterr().err and (out / "safe.png").read_text() == "my own figure"


def test_bladecase_mesh_meshes_a_sector(tmp_path):
    """`bladecase mesh` on a sector study writes the sector's mesh with its cyclic faces and hub as groups."""
    study = _write(tmp_path, "[cyclic]\nmodes = 3")
    assert main(["mesh", study, "-o", str(tmp_path / "sector.vtu"), "--quiet"]) == 0
    mesh = load_mesh(tmp_path / "sector.vtu")
    assert {"hub", "left", "right", "tip"} <= set(mesh.groups)
