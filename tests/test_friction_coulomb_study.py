"""``[contact] friction = {model = "coulomb"}`` in a study: the keys, and the rub stage of the demo blade with the
stick–slip model — at an engine speed it is the rotation model's rub, figure for figure, and the log, summary,
rub.csv and report say the assumption and each speed's share of contact time in stick."""

from __future__ import annotations

import logging

import pytest
from test_friction_study import RUB, _wear_study
from test_rub_study import _study

from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


@pytest.fixture(scope="module")
def blade():
    from bladecase.study.stages import build_mesh, build_model

    study = loads(_study(rub=RUB), source="<coulomb>")
    return build_model(study, build_mesh(study))


def _stage(blade, folder=None, **contact):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB, **contact), source="<coulomb>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), folder=folder,
                     figures=False)


def test_coulomb_keys():
    study = loads(_study(rub=RUB, friction='{mu = 0.15, model = "coulomb"}'), source="<coulomb>")
    assert study["contact"]["friction"] == {"mu": 0.15, "model": "coulomb"}
    with pytest.raises(StudyError, match="model must be 'rotation' or 'coulomb', got 'stick'"):
        loads(_study(rub=RUB, friction='{mu = 0.15, model = "stick"}'), source="<coulomb>")
    with pytest.raises(StudyError, match=r'model = "coulomb" \(stick–slip\) is not run with a \[casing\] abradable'):
        loads(_wear_study(friction='{mu = 0.15, model = "coulomb"}'), source="<coulomb>")


def test_coulomb_at_engine_speed_is_the_rotation_model(blade, tmp_path, caplog):
    """The demo blade at 1650 rpm, μ = 0.15: the tip slides at ΩR ≈ 78 m/s, 40 times its fastest tangential
    vibration; the stick–slip rub never sticks and gives the rotation model's figures to 1e-9 (the energy of the last
    revolution, the peaks, the switches); the log, the summary, rub.csv and the report say the model and the share of
    contact time in stick."""
    rotation = _stage(blade, friction='{mu = 0.15, model = "rotation"}')
    with caplog.at_level(logging.INFO, logger="bladecase"):
        coulomb = _stage(blade, folder=tmp_path, friction='{mu = 0.15, model = "coulomb"}')
    r, c = rotation["friction"]["speeds"][0], coulomb["friction"]["speeds"][0]
    for key in ("casing_input_j", "friction_work_j", "damping_j", "stored_change_j"):
        assert c[key] == pytest.approx(r[key], rel=1e-9), key
    assert c["sliding_ratio"] == pytest.approx(r["sliding_ratio"], rel=5e-3)   # sampled maxima, on other grids
    assert abs(c["balance_residual"]) < 1e-9 and c["stick_share"] == 0.0 and r["stick_share"] is None
    for key in ("tip_normal_displacement_mm", "max_node_force_n", "contact_fraction", "switches"):
        assert coulomb["rows"][0][key] == pytest.approx(rotation["rows"][0][key], rel=1e-9), key
    f = coulomb["friction"]
    assert f["model"] == "coulomb" and "stick–slip" in f["assumption"] and f["sticking"] == []
    assert any("stick–slip (model 'coulomb')" in m for m in caplog.messages)
    assert any("of its contact time sticking" in m for m in caplog.messages)
    header, line = (tmp_path / "rub.csv").read_text().splitlines()[:2]
    cells = dict(zip(header.split(","), line.split(",")))
    assert float(cells["stick_share"]) == 0.0
    from bladecase.post.rub.report import rub_report

    text = "\n".join(rub_report(coulomb))
    assert "stick–slip (model 'coulomb')" in text and "share of contact time a node spends sticking" in text
    assert "The sliding is dominated by the rotation" not in text
