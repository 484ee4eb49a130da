"""``[mistuning] clearance`` end to end through the CLI on a coarse parametric sector of 6 blades: who rubs first in
each random sample (``mistuning_rub.csv``, the summary, the report) equals the library's
:func:`~bladecase.reduction.mistuning_rub.sample_rub` on the model rebuilt here from the run's ``mesh.vtu`` with
the same seed; a clearance per blade moves the first rub; bad clearances exit 2."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from bladecase.cli import main
from bladecase.fe import assemble, fe_sector, load_mesh
from bladecase.fe.cyclic import sector_angles
from bladecase.fe.rotation import RotationAxis
from bladecase.reduction.mistuning import family_band, mistuning_model
from bladecase.reduction.mistuning_fe import blade_stiffness
from bladecase.reduction.mistuning_rub import sample_rub
from bladecase.reduction.mistuning_stats import random_mistuning
from bladecase.study.disk.mistuning import radial_response

N, RIM = 6, 0.2
AXIS = RotationAxis((0.0, 0.0, -RIM), (1.0, 0.0, 0.0))  # the parametric sector's engine axis
GEOMETRY = (f'geometry = {{kind = "sector", sectors = {N}, hub_radius = 0.1, rim_radius = {RIM}, '
            'disk_thickness = 0.03, span = 0.1, root_chord = 0.03, thickness = 0.005, size = 0.03}')
MISTUNING = "std = 0.03\nsamples = 6\nseed = 4\nengine_order = 2\ndamping = 0.003\n"


def _run(tmp_path, extra: str):
    path = tmp_path / "disk.toml"
    path.write_text(f'study = {{name = "disk"}}\n{GEOMETRY}\nfem = {{order = 1, mass = "consistent"}}\n'
                    f"output = {{formats = []}}\ncyclic = {{modes = 1}}\n[mistuning]\n{MISTUNING}{extra}\n")
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "--quiet"])
    return code, out


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    code, out = _run(tmp_path_factory.mktemp("rub"), "clearance = 1e-4")
    assert code == 0
    return out


def test_the_first_rub_of_each_sample_equals_the_librarys(run):
    s = json.loads((run / "summary.json").read_text())["mistuning"]
    rows = list(csv.DictReader(open(run / "mistuning_rub.csv")))
    assert len(rows) == 6
    mesh = load_mesh(run / "mesh.vtu")
    fe = assemble(mesh, "Ti-6Al-4V", order=1, mass="consistent", clamp="hub")
    sector = fe_sector(fe, N, AXIS, left="left", right="right")
    model = mistuning_model(sector, blade_stiffness(fe, lambda c: sector_angles(c, AXIS)[0] > RIM), families=[0])
    kw = {"model": model, "order": 2, "frequencies": family_band(model), "zeta": 0.003, "force": s["tip"]["dof"],
          "response": radial_response(fe, AXIS, s["tip"]["node"]), "clearance": 1e-4}
    for row, delta in zip(rows, random_mistuning(N, 6, 0.03, 4)):
        r = sample_rub(delta, **kw)
        assert int(row["first_blade"]) == r["blade"]
        assert float(row["level_n"]) == pytest.approx(r["level"], rel=1e-9)
        assert float(row["tuned_ratio"]) == pytest.approx(r["tuned_ratio"], rel=1e-9)
    rub = s["rub"]
    ratios = np.array([float(r["tuned_ratio"]) for r in rows])
    assert rub["tuned_ratio"]["min"] == pytest.approx(ratios.min(), rel=1e-12) and ratios.min() < 1
    assert sum(rub["first_blade_counts"]) == 6
    assert "First rub (tip clearance 100 µm)" in (run / "report.md").read_text()


def test_a_clearance_per_blade_moves_the_first_rub(tmp_path, run):
    rows = list(csv.DictReader(open(run / "mistuning_rub.csv")))
    first = int(rows[0]["first_blade"])
    c = [1e-4] * N
    c[first] = 3e-4  # its clearance tripled: another blade rubs first in sample 0
    code, out = _run(tmp_path, f"clearance = {c}")
    assert code == 0
    moved = list(csv.DictReader(open(out / "mistuning_rub.csv")))
    assert int(moved[0]["first_blade"]) != first


@pytest.mark.parametrize("value, words", [("-1e-4", "[mistuning] clearance: must be the casing clearance"),
                                          ("[1e-4, 1e-4]", "[mistuning] clearance: 2 values, but the disk has 6")])
def test_bad_clearance_exit_2(tmp_path, capsys, value, words):
    code, out = _run(tmp_path, f"clearance = {value}")
    assert code == 2 and words in capsys.readouterr().err and not out.exists()
