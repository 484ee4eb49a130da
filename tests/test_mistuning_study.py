"""``[mistuning]`` in a cyclic study, end to end through the CLI on a coarse parametric sector of 6 blades: the
summary's amplification of a given pattern equals the library's (:func:`bladecase.reduction.mistuning.amplification`
on the model rebuilt here from the run's ``mesh.vtu``, the blade chosen by radius) to 1e-12, the tuned pattern gives
1 to 1e-9, random samples equal :func:`~bladecase.reduction.mistuning_stats.mistuning_statistics` with the same seed;
a sector mesh file whose blade is a node group; and the errors of bad keys (exit 2, nothing published)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from bladecase.cli import main
from bladecase.fe import assemble, fe_sector, load_mesh
from bladecase.fe.cyclic import sector_angles
from bladecase.fe.rotation import RotationAxis
from bladecase.reduction.mistuning import amplification, family_band, fmm_model, mistuning_model
from bladecase.reduction.mistuning_fe import blade_stiffness
from bladecase.reduction.mistuning_stats import mistuning_statistics

N, RIM, SPAN = 6, 0.2, 0.1
AXIS = RotationAxis((0.0, 0.0, -RIM), (1.0, 0.0, 0.0))  # the parametric sector's engine axis
GEOMETRY = (f'geometry = {{kind = "sector", sectors = {N}, hub_radius = 0.1, rim_radius = {RIM}, '
            f'disk_thickness = 0.03, span = {SPAN}, root_chord = 0.03, thickness = 0.005, size = 0.03}}')
PATTERN = [0.03, -0.02, 0.0, 0.025, -0.03, 0.01]


def _write(tmp_path, mistuning: str, formats: str = "[]") -> str:
    path = tmp_path / "disk.toml"
    path.write_text(f'study = {{name = "disk"}}\n{GEOMETRY}\nfem = {{order = 1, mass = "consistent"}}\n'
                    f"output = {{formats = {formats}}}\ncyclic = {{modes = 1}}\n[mistuning]\n{mistuning}\n")
    return str(path)


def _run(tmp_path, mistuning: str, formats: str = "[]"):
    out = tmp_path / "out"
    assert main(["run", _write(tmp_path, mistuning, formats), "--out", str(out), "--quiet"]) == 0
    return out, json.loads((out / "summary.json").read_text())["mistuning"]


def _library_model(out):
    """The SNM model from the run's own sector mesh, assembled here; the blade: the cells beyond the rim radius."""
    mesh = load_mesh(out / "mesh.vtu")
    fe = assemble(mesh, "Ti-6Al-4V", order=1, mass="consistent", clamp="hub")
    sector = fe_sector(fe, N, AXIS, left="left", right="right")
    kb = blade_stiffness(fe, lambda c: sector_angles(c, AXIS)[0] > RIM)
    return mistuning_model(sector, kb, families=[0])


@pytest.fixture(scope="module")
def given(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("given")
    return _run(tmp, f"deviations = {PATTERN}\nengine_order = 2\ndamping = 0.005", '["png"]')


def test_a_given_pattern_equals_the_library(given):
    out, m = given
    names = {p.name for p in out.iterdir()}
    assert {"mistuning.csv", "mistuning.png", "cyclic.csv", "summary.json", "report.md"} <= names
    model = _library_model(out)
    dof = m["tip"]["dof"]
    ref = amplification(model, PATTERN, 2, family_band(model), zeta=0.005, force=dof, response=dof)
    assert m["samples"] == 1 and m["deviations"] == PATTERN and m["diameter"] == 2 and m["model"] == "snm"
    assert abs(m["largest"] - ref) <= 1e-12 * ref and ref > 1.01      # mistuned: amplified
    assert m["whitehead_bound"] == pytest.approx(0.5 * (1 + 6**0.5), rel=1e-15) and m["above_bound"] == 0
    assert m["tip"]["position_m"][2] == pytest.approx(SPAN, abs=1e-9)   # the blade's tip
    rows = list(csv.DictReader(open(out / "mistuning.csv")))
    assert len(rows) == 1 and float(rows[0]["amplification"]) == m["largest"]
    assert int(rows[0]["blade"]) == m["largest_blade"]
    report = (out / "report.md").read_text()
    assert "## Mistuning" in report and "subset of nominal modes" in report and "Whitehead's bound" in report
    assert f"blade {m['largest_blade']}" in report


def test_the_tuned_pattern_amplifies_one(tmp_path):
    _, m = _run(tmp_path, f"deviations = {[0.0] * N}\nengine_order = 5")
    assert abs(m["largest"] - 1.0) <= 1e-9 and m["diameter"] == 1


def test_the_fundamental_mistuning_model(tmp_path, given):
    _, m = _run(tmp_path, f'deviations = {PATTERN}\nengine_order = 2\ndamping = 0.005\nmodel = "fmm"')
    sector = fe_sector(assemble(load_mesh(given[0] / "mesh.vtu"), "Ti-6Al-4V", order=1, mass="consistent",
                                clamp="hub"), N, AXIS, left="left", right="right")
    model, dof = fmm_model(sector), m["tip"]["dof"]
    ref = amplification(model, PATTERN, 2, family_band(model), zeta=0.005, force=dof, response=dof)
    assert m["model"] == "fmm" and abs(m["largest"] - ref) <= 1e-12 * ref
    assert m["largest"] == pytest.approx(given[1]["largest"], rel=0.01)   # FMM ≈ SNM (0.27 % here)


def test_random_samples_equal_the_library_statistics(tmp_path, given):
    out, m = _run(tmp_path, "std = 0.02\nsamples = 6\nseed = 11\nengine_order = 2\ndamping = 0.005")
    model = _library_model(given[0])
    dof = m["tip"]["dof"]
    ref = mistuning_statistics(model, 2, std=0.02, samples=6, seed=11, zeta=0.005, force=dof, response=dof)
    factors = [float(r["amplification"]) for r in csv.DictReader(open(out / "mistuning.csv"))]
    assert np.max(np.abs(np.array(factors) / ref.factors - 1)) <= 1e-12
    assert m["percentiles"]["p50"] == pytest.approx(ref.percentiles()[50.0], rel=1e-12)
    assert m["largest_sample"] == ref.worst and m["largest_blade"] == int(ref.blades[ref.worst])


def _vtu_study(tmp_path, extra: str) -> str:
    from _cyclic_util import hex_sector

    from bladecase.fe import save_mesh

    mesh = hex_sector(8)
    radius = np.hypot(mesh.points[:, 1], mesh.points[:, 2])
    mesh.groups["blade"] = np.flatnonzero(radius >= 0.16 - 1e-9)          # the blade: beyond r_rim = 0.16
    save_mesh(mesh, tmp_path / "sector.vtu")
    path = tmp_path / "s.toml"
    path.write_text('mesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\nfem = {order = 1, clamp = "hub"}\n'
                    'output = {formats = []}\nrotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n'
                    f"{extra}\n")
    return str(path)


def test_a_sector_mesh_file_with_its_blade_group(tmp_path):
    pattern = [0.02, -0.01, 0.0, 0.015, -0.02, 0.005, 0.01, -0.015]
    study = _vtu_study(tmp_path, f'cyclic = {{sectors = 8, modes = 1}}\n[mistuning]\nblade = "blade"\n'
                                 f"deviations = {pattern}\nengine_order = 3")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    m = json.loads((tmp_path / "out" / "summary.json").read_text())["mistuning"]
    mesh = load_mesh(tmp_path / "sector.vtu")
    fe = assemble(mesh, "steel", order=1, clamp="hub")
    axis = RotationAxis((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    model = mistuning_model(fe_sector(fe, 8, axis), blade_stiffness(fe, lambda c: np.hypot(c[:, 1], c[:, 2]) > 0.16))
    dof = m["tip"]["dof"]
    ref = amplification(model, pattern, 3, family_band(model), zeta=0.002, force=dof, response=dof)
    assert abs(m["largest"] - ref) <= 1e-12 * ref and m["blade_cells"] == 16 and m["tip"]["radius_m"] == 0.26


@pytest.mark.parametrize("mistuning, words", [
    ("std = -0.1", "[mistuning] std: must be a standard deviation > 0 and < 0.3"),
    ("std = 0.01\nsamples = 0", "[mistuning] samples: must be an integer with 1 <= value <= 100000"),
    ("deviations = [0.0, 0.01]", "[mistuning] deviations: 2 values, but the disk has 6 blades"),
    ("std = 0.01\nengine_order = 0", "[mistuning] engine_order: must be an integer with 1 <= value <= 1000"),
    ("deviations = [0, 0, 0, 0, 0, 0.5]", "[mistuning] deviations: must be a list of one relative stiffness"),
    ("deviations = [0, 0, 0, 0, 0, 0]\nstd = 0.01", "[mistuning] std: give either 'deviations'"),
    ("samples = 10", "[mistuning] std: required for random samples"),
    ('std = 0.01\nmodel = "lumped"', "[mistuning] model: must be one of 'snm', 'fmm'"),
    ('std = 0.01\nblade = "b"', "[mistuning] blade: only for a sector mesh file"),
])
def test_bad_keys_exit_2(tmp_path, capsys, mistuning, words):
    assert main(["run", _write(tmp_path, mistuning), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err and not (tmp_path / "out").exists(), err


def test_not_a_bladed_disk_exit_2(tmp_path, capsys):
    path = tmp_path / "blade.toml"
    path.write_text('geometry = {kind = "blade", span = 0.1, root_chord = 0.03, thickness = 0.005}\n'
                    "mistuning = {std = 0.01}\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "[mistuning]: mistuning is that of a bladed disk" in capsys.readouterr().err
    assert main(["run", _vtu_study(tmp_path, '[mistuning]\nblade = "blade"\nstd = 0.01'), "--out",
                 str(tmp_path / "out"), "--quiet"]) == 2
    assert "is not a sector (no *CYCLIC SYMMETRY MODEL)" in capsys.readouterr().err
    assert main(["run", _vtu_study(tmp_path, "cyclic = {sectors = 8}\nmistuning = {std = 0.01}"), "--out",
                 str(tmp_path / "out"), "--quiet"]) == 2
    assert "[mistuning] blade: required for a sector mesh file" in capsys.readouterr().err
    assert main(["run", _vtu_study(tmp_path, 'cyclic = {sectors = 8}\nmistuning = {std = 0.01, blade = "tip"}'),
                 "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "[mistuning] blade: 0 of the sector's" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
