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
    from bladecase.study.rub import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB, **contact), source="<friction>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), figures=False)


@pytest.fixture(scope="module")
def with_friction(blade, tmp_path_factory):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub import rub_stage
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
    from bladecase.post.rub_report import rub_report

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
    ('{mu = 0.15, model = "coulomb"}', RUB, r"stick–slip\) is not available yet; what is: model = \"rotation\""),
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
