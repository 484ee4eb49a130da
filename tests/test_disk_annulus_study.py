"""``[cyclic] nonsmooth`` end to end through the CLI: a coarse hexahedral sector of 12 blades (a mesh file), each
blade's tip face its massless contact on a compliant casing; the travelling family, its check in the whole disk
without the symmetry (10 periods), the annulus' VTK frames and GIF, the summary and the report; and the keys'
errors (exit 2, nothing published)."""

from __future__ import annotations

import csv
import json

import meshio
import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.cli import main
from bladecase.fe import save_mesh
from bladecase.post.vtk import read_time_series

N = 12
TIP = 'contact = {face = "tip", normal = [0, 0, 1], clearance = 1e-4, model = "massless", casing_stiffness = 5e6}\n'
CONTACT = TIP + 'reduction = {method = "massless"}\nsearch = {ipp = [1]}\n'


def _study(tmp_path, nonsmooth: str = "{diameter = 2, modes = 2, growth = [1.1, 1.5]}", contact: str = CONTACT,
           formats: str = '["vtu", "gif"]') -> str:
    save_mesh(hex_sector(N, nt=3, band=(1, 2), nr=1, nb=3, nx=1), tmp_path / "sector.vtu")
    path = tmp_path / "s.toml"
    path.write_text('mesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\n'
                    'fem = {order = 1, clamp = "hub", mass = "lumped"}\n'
                    f'output = {{formats = {formats}, frames = 8, '
                    'window = [240, 180]}\nrotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n'
                    f"{contact}[cyclic]\nsectors = {N}\nmodes = 2\ndiameters = [2]\nnonsmooth = {nonsmooth}\n")
    return str(path)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("disk_nonsmooth")
    assert main(["run", _study(tmp), "--out", str(tmp / "out"), "--quiet"]) == 0
    return tmp / "out"


def test_the_travelling_family_comes_back_in_the_whole_disk(run):
    s = json.loads((run / "summary.json").read_text())
    n = s["cyclic"]["nonsmooth"]
    assert n["diameter"] == 2 and n["direction"] == "forward" and n["contacts"] == N and n["fraction"] == 6
    rows = list(csv.DictReader(open(run / "disk_modes.csv")))
    assert len(rows) == len(n["orbits"]) == 2 and all(r["touching"] == "True" for r in rows)
    assert all(float(r["return_error_1T"]) < 1e-9 for r in rows)
    assert n["check"]["periods"] == 10 and n["check"]["return_error"] < 1e-3  # the bar; measured ~1e-13
    assert float(rows[-1]["max_force_n"]) > float(rows[0]["max_force_n"]) > 0
    assert "travelling wave of mode" in s["verdict"]["found"]
    assert "## The whole disk against the casing" in (run / "report.md").read_text()


def test_the_annulus_frames_show_the_summarys_penetration(run):
    a = json.loads((run / "summary.json").read_text())["cyclic"]["nonsmooth"]["animated"]
    assert (run / a["gif"]).stat().st_size > 0
    times, files = read_time_series(run / a["pvd"])
    assert len(files) == 8
    deepest = max(float(np.nanmax(-meshio.read(f).point_data["normal_gap"])) for f in files)
    assert a["max_penetration_mm"] > 0
    assert abs(deepest * 1e3 - a["max_penetration_mm"]) <= 1e-6 * a["max_penetration_mm"]


@pytest.mark.parametrize("nonsmooth, contact, words", [
    ("{diameter = 6}", CONTACT, "diameter = 6 of a disk of 12 sectors is a standing wave"),
    ("{diameter = 2}", TIP.replace('model = "massless", casing_stiffness = 5e6', 'model = "newton"'),
     "[contact] model: the whole disk's nonsmooth mode uses the massless contact model"),
    ("{diameter = 2}", "", "[cyclic] nonsmooth: the whole disk's nonsmooth mode needs a casing"),
    ("{diameter = 2, growth = [1.5, 1.1]}", CONTACT, "growth must be an increasing list"),
])
def test_bad_nonsmooth_keys_exit_2(tmp_path, capsys, nonsmooth, contact, words):
    study = _study(tmp_path, nonsmooth, contact, formats="[]")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err and not (tmp_path / "out").exists(), err
