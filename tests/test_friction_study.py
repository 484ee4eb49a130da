"""``[contact] friction`` in a study: the rub stage with friction (the energy balance of each speed's last
revolution, the sliding check, rub.csv, the summary and the report), friction μ = 0 against none bit for bit, and
the keys' checks."""

from __future__ import annotations

import numpy as np
import pytest
from test_rub_study import _study

from bladecase.study.keys import StudyError
from bladecase.study.schema import loads

RUB = """
[rub]
speeds = [1650]
ratio = 0.005
revolutions = 2
window = 1
max_revolutions = 2

[rotation]
axis = {origin = [-0.000167, 0.030778, -0.3], direction = [-0.350089, -0.936717, 0.0]}
static = "linear"
"""


@pytest.fixture(scope="module")
def blade():
    from bladecase.study.stages import build_mesh, build_model

    study = loads(_study(rub=RUB), source="<friction>")
    return build_model(study, build_mesh(study))


def _stage(blade, **contact):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB, **contact), source="<friction>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), figures=False)


@pytest.fixture(scope="module")
def with_friction(blade, tmp_path_factory):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    out = tmp_path_factory.mktemp("friction")
    study = loads(_study(rub=RUB, friction="{mu = 0.15}"), source="<friction>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), folder=out,
                     figures=False), out


def test_friction_energy_balance_closes_and_is_written(with_friction):
    """The demo blade at 1650 rpm (1.01 × the crossing speed) with μ = 0.15: the last revolution's balance closes
    to 1e-9 (the goal; measured 2e-13), friction takes energy from the vibration, and the sliding is dominated by the
    rotation (max |z'| / ΩR about 0.025)."""
    section, out = with_friction
    f = section["friction"]
    assert f["mu"] == 0.15 and f["model"] == "rotation" and "ΩR" in f["assumption"]
    row = f["speeds"][0]
    assert abs(row["balance_residual"]) < 1e-9
    assert row["stored_change_j"] == pytest.approx(row["casing_input_j"] + row["friction_work_j"] - row["damping_j"],
                                                   abs=1e-9 * abs(row["casing_input_j"]))
    assert row["casing_input_j"] > 0 and row["friction_work_j"] < 0 < row["damping_j"]
    assert row["rotation_dominated"] is True and 0 < row["sliding_ratio"] < 0.1
    assert f["not_rotation_dominated"] == []
    header, line = (out / "rub.csv").read_text().splitlines()[:2]
    cells = dict(zip(header.split(","), line.split(",")))
    assert float(cells["friction_work_j"]) == pytest.approx(row["friction_work_j"], rel=1e-8)
    assert cells["rotation_dominated"] == "true"
    from bladecase.post.rub.report import rub_report

    text = "\n".join(rub_report(section))
    assert "the sliding dominated by the rotation" in text and "the balance closes to" in text
    assert "The sliding is dominated by the rotation at every speed" in text


@pytest.fixture(scope="module")
def plain(blade):
    return _stage(blade)


def test_friction_zero_is_the_rub_without_friction_bit_for_bit(blade, plain, with_friction):
    """μ = 0 flies the simulation without friction: every figure of rub.csv's own columns is identical, and the
    study without friction writes no friction column."""
    zero = _stage(blade, friction="{mu = 0.0}")
    assert "friction" not in plain and zero["friction"]["speeds"][0]["casing_input_j"] is None
    assert "casing_input_j" not in plain["rows"][0] and "casing_input_j" in zero["rows"][0]
    for a, b in zip(plain["rows"], zero["rows"]):
        assert {k: a[k] for k in a} == {k: b[k] for k in a}
    rubbed = with_friction[0]["rows"][0]
    assert rubbed["tip_normal_displacement_mm"] != plain["rows"][0]["tip_normal_displacement_mm"]


@pytest.mark.parametrize("friction, rub, match", [
    ("{mu = -0.1}", RUB, r"mu must be a finite number in \[0, 2\]"),
    ("{model = \"rotation\"}", RUB, r"needs mu"),
    ("{mu = 0.1, law = 1}", RUB, r"unknown key 'law'"),
    ("{mu = 0.1}", "", r"\[contact\] friction: it acts in the rub response: give \[rub\] speeds"),
])
def test_friction_key_errors(friction, rub, match):
    with pytest.raises(StudyError, match=match):
        loads(_study(rub=rub, friction=friction), source="<friction>")


def test_friction_key_defaults_its_model():
    study = loads(_study(rub=RUB, friction="{mu = 0.2}"), source="<friction>")
    assert study["contact"]["friction"] == {"mu": 0.2, "model": "rotation"}
    assert np.isclose(study["contact"]["friction"]["mu"], 0.2)


WEAR_CASING = """
[casing]
radius = 0.4505
axis = {origin = [-0.000167, 0.030778, -0.3], direction = [-0.350089, -0.936717, 0.0]}
lobes = 8
amplitude = 3e-4
abradable = ABRADABLE
"""

COATING = "{thickness = 1e-3, yield = 2e5, stiffness = 2e11, cells = 24}"


def _wear_study(coating: str = COATING, rub: str = RUB, **contact) -> str:
    text = _study(casing=WEAR_CASING.replace("ABRADABLE", coating), rub=rub, **contact)
    return text.replace("casing_stiffness = 1e6      # N/m: a thin casing's local radial stiffness; the modes "
                        "converge (docs/massless.md)\n", "")


@pytest.mark.parametrize("coating, rub, contact, match", [
    ("{thickness = 1e-3, stiffness = 2e11}", RUB, {}, r"needs yield \(Pa: the contact pressure at which"),
    ("{thickness = 1e-3, yield = 2e5, stiffness = 2e11, cells = 2}", RUB, {}, r"cells must be an integer in \[3"),
    ("{thickness = -1e-3, yield = 2e5, stiffness = 2e11}", RUB, {}, r"thickness must be a finite number > 0"),
    (COATING, "", {}, r"\[casing\] abradable: the coating is worn by the rub response: give \[rub\] speeds"),
    (COATING, RUB, {"casing_stiffness": "1e6"}, r"\[contact\] casing_stiffness: with a \[casing\] abradable"),
])
def test_abradable_key_errors(coating, rub, contact, match):
    with pytest.raises(StudyError, match=match):
        loads(_wear_study(coating, rub, **contact), source="<wear>")


def test_friction_and_wear_end_to_end_through_the_cli(tmp_path):
    """``bladecase run`` on the demo blade at 1650 rpm with μ = 0.15 and a 12-cell abradable coating, two
    revolutions: rub.csv with the friction's columns, wear.csv per revolution whose removed volume is the
    profile's missing volume to 1e-6 and whose energy balance closes to 1e-9, wear_profile.csv, wear.png, the worn
    casing's ring in wear.vtu, the summary and the report's words."""
    import csv
    import json

    import meshio

    from bladecase.cli import main

    study = tmp_path / "wear.toml"
    text = _wear_study(COATING.replace("cells = 24", "cells = 12"), friction="{mu = 0.15}")
    text = text.replace("[rub]\n", "[rub]\nsize = 4\n").replace("scan = 6", "scan = 2")   # quick: the rub's test
    study.write_text(text.replace("periods = [0.95, 1.0001]", "periods = [0.99, 1.0001]"), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["run", str(study), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())["rub"]
    assert summary["friction"]["worst_residual"] < 1e-9
    rows = list(csv.DictReader(open(out / "wear.csv")))
    assert [int(r["revolution"]) for r in rows] == [1, 2]
    for r in rows:
        assert float(r["removed_volume_mm3"]) == pytest.approx(float(r["missing_volume_mm3"]), rel=1e-6)
    assert float(rows[-1]["removed_volume_mm3"]) > 0
    # each revolution's energy balance with the coating yielding in flight closes (measured ~1e-13), the coating's
    # removal takes energy, friction dissipates
    for r in rows:
        assert abs(float(r["balance_residual"])) < 1e-9
    assert float(rows[-1]["removal_work_j"]) > 0 and float(rows[-1]["friction_work_j"]) < 0
    assert summary["wear"]["worst_balance_residual"] < 1e-9
    wear = summary["wear"]["speeds"][0]
    assert wear["volume_mismatch"] < 1e-6 and wear["lobes"] == int(rows[-1]["lobes"])
    ring = meshio.read(out / "wear.vtu")
    assert ring.cells_dict["quad"].shape == (12, 4)
    assert ring.point_data["worn_depth_mm"].max() == pytest.approx(float(rows[-1]["max_depth_um"]) * 1e-3, rel=1e-8)
    radius = np.linalg.norm(np.cross(ring.points - [-0.000167, 0.030778, -0.3], [-0.350089, -0.936717, 0.0]),
                            axis=1) / np.linalg.norm([-0.350089, -0.936717, 0.0])
    np.testing.assert_allclose(radius, 0.4505 + ring.point_data["worn_depth_mm"] * 1e-3, rtol=1e-6)
    profile = list(csv.DictReader(open(out / "wear_profile.csv")))
    assert len(profile) == 12
    assert (out / "wear.png").is_file() and (out / "rub.png").is_file()
    report = (out / "report.md").read_text()
    assert "Abradable coating: 1 mm thick" in report and "the sliding dominated by the rotation" in report
    assert "round(f_vib / f_rot)" in report and "removing the coating" in report
    log = (out / "run.log").read_text()
    assert "the sliding dominated by the rotation" in log and "the sliding is dominated by the rotation at every" in log
    assert "the coating is worn to" in log and "the last wearing revolution's energy" in log


def test_a_coating_on_a_line_of_nodes_is_refused_before_any_factorisation():
    """The coating's pressure needs each node's area: a line of tip nodes (no facet of the body) is refused."""
    from test_rub_line import LINE

    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    text = _wear_study().replace('face = "tip"                # the whole tip face rubs: its mean normal '
                                 'displacement meets the casing\n', f"nodes = {LINE}\n")
    text = text.replace('weights = "area"            # nodes weighted by their share of the face (converges under '
                        'mesh refinement)\n', "")
    study = loads(text, source="<wear>")
    from bladecase.study.stages import build_mesh, build_model

    blade = build_model(study, build_mesh(study))
    with pytest.raises(StudyError, match=r"\[casing\] abradable: the coating's pressure needs each contact node's "
                                         r"area: give a contact face"):
        rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor())


def test_a_speed_whose_worn_casing_flutters_is_reported_and_the_others_go_on(blade, monkeypatch, tmp_path):
    """The coupled wear run refused at one speed (friction-induced flutter once the coating is worn) is that speed's
    result, named with its reason, not the end of the sweep."""
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub import stage
    from bladecase.study.stages import build_contact

    real = stage.wear_rub

    def flutters(system, coating, speed, *args, **kwargs):
        if abs(speed * 60 / (2 * np.pi) - 1650) < 1e-6:
            raise ValueError("a contact phase with friction (nodes [4] closed, mu = 0.15) is unstable: it grows at "
                             "531 1/s (friction-induced flutter)")
        return real(system, coating, speed, *args, **kwargs)

    monkeypatch.setattr(stage, "wear_rub", flutters)
    study = loads(_wear_study(rub=RUB.replace("speeds = [1650]", "speeds = [1640, 1650]"), friction="{mu = 0.15}"),
                  source="<wear>")
    s = stage.rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), folder=tmp_path,
                        figures=False)
    assert [r["speed"] for r in s["rows"]] == [1640.0]
    assert (tmp_path / "wear.csv").exists() and "1650" not in (tmp_path / "wear.csv").read_text().split("\n", 1)[1]
    assert s["failed_speeds"][0]["speed"] == 1650.0 and "friction-induced flutter" in s["failed_speeds"][0]["reason"]
