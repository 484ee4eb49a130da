"""``[contact] friction`` ``mode_amplitudes`` in a rub study: the first mode with friction at each speed (its
frequency and damping ratio against the amplitude), checked by its free decay, written to friction_modes.csv and
friction_modes.png and told in the report; the stick–slip model, always sliding at engine speed, gives the rotation
model's mode; the key's checks."""

from __future__ import annotations

import csv

import pytest
from test_friction_study import RUB
from test_rub_study import _study

from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


@pytest.fixture(scope="module")
def blade():
    from bladecase.study.stages import build_mesh, build_model

    study = loads(_study(rub=RUB), source="<friction modes>")
    return build_model(study, build_mesh(study))


def _stage(blade, friction: str, folder=None):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB, friction=friction), source="<friction modes>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), folder=folder,
                     figures=folder is not None)


@pytest.fixture(scope="module")
def rotation(blade, tmp_path_factory):
    out = tmp_path_factory.mktemp("friction_modes")
    return _stage(blade, "{mu = 0.15, mode_amplitudes = [3, 1.5]}", out), out


def test_the_mode_with_friction_is_computed_checked_and_written(rotation):
    """The demo blade at 1650 rpm, μ = 0.15, all 26 tip nodes: at 1.5 and 3 × grazing the mode stiffens with the
    amplitude (measured +0.06 % and +0.61 % over the open mode) and friction sliding at ΩR barely moves its damping
    ratio (0.4996 and 0.4960 % against the structural 0.5 %); the free decay from each orbit gives the same ratio
    within 1e-3 (measured 6e-6 and 3.7e-4)."""
    section, folder = rotation
    m = section["friction"]["modes"]
    (s,) = m["speeds"]
    assert [q["amplitude_ratio"] for q in s["points"]] == [1.5, 3.0]  # sorted
    assert all(q["converged"] and q["residual"] < 1e-7 for q in s["points"])
    f = [q["frequency_hz"] / s["open_hz"] for q in s["points"]]
    assert 1.0 < f[0] < f[1] < 1.02
    assert all(abs(q["zeta"] / s["structural_zeta"] - 1) < 0.02 for q in s["points"])
    assert abs(m["worst_decay_error"]) < 1e-3
    # the blade's second mode near four times the first: at 3 × grazing it answers the orbit's 4th harmonic ~77-fold
    # and holds ~0.5 % of its energy (at 1.5 × under 0.1 %): said as an internal resonance, the only doubt
    lo, hi = s["points"]
    assert lo["internal"] is None and lo["mode_share"] > 0.999
    assert hi["internal"]["mode"] == 2 and hi["internal"]["harmonic"] == 4 and hi["internal"]["gain"] > 10
    assert 1e-3 < hi["internal"]["share"] < 0.02
    (doubt,) = m["doubts"]
    assert doubt.startswith("at 1650 rpm from 3 × grazing: mode 2") and "internal resonance" in doubt
    assert section["files"]["friction_modes_csv"] == "friction_modes.csv"
    with open(folder / "friction_modes.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["amplitude_ratio"]) for r in rows] == [1.5, 3.0]
    assert abs(float(rows[1]["frequency_hz"]) - s["points"][1]["frequency_hz"]) < 1e-6
    assert rows[0]["internal_mode"] == "" and rows[1]["internal_mode"] == "2"
    assert (folder / "friction_modes.png").stat().st_size > 10_000


def test_the_report_tells_the_mode_and_its_check(rotation):
    from bladecase.post.rub.report import _friction_lines

    text = "\n".join(_friction_lines(rotation[0]["friction"], "rpm"))
    assert "The first mode with friction" in text and "from 1.5 to 3 × its grazing amplitude" in text
    assert "Checked by the free decay" in text and "mesh error is not measured" in text
    assert "**The mode with friction is doubtful** at 1650 rpm from 3 × grazing: mode 2" in text


def test_stick_slip_sliding_at_engine_speed_is_the_rotation_model(blade, rotation):
    """Another solver (stick–slip, each node's casing sliding at ΩR): every node slides, so the same mode to 1e-7."""
    other = _stage(blade, "{mu = 0.15, model = \"coulomb\", mode_amplitudes = [1.5]}")["friction"]["modes"]
    (q,) = other["speeds"][0]["points"]
    ref = rotation[0]["friction"]["modes"]["speeds"][0]["points"][0]
    assert abs(q["frequency_hz"] / ref["frequency_hz"] - 1) < 1e-7
    assert abs(q["zeta"] / ref["zeta"] - 1) < 1e-5


@pytest.mark.parametrize("given, match", [
    ("{mu = 0.15, mode_amplitudes = [0.8]}", r"mode_amplitudes must be a list of 1 to 20 numbers in \(1, 100\]"),
    ("{mu = 0.15, mode_amplitudes = 2}", r"got 2\b"),
    ("{mu = 0.15, mode_amplitudes = []}", r"got \[\]"),
    ("{mu = 0.15, modes = [2]}", r"unknown key 'modes' \(valid: mu, model, mode_amplitudes\)"),
])
def test_mode_amplitudes_errors(given, match):
    with pytest.raises(StudyError, match=match):
        loads(_study(rub=RUB, friction=given), source="<friction modes>")


def test_a_users_file_named_as_a_rub_result_is_refused_before_the_run(rotation, tmp_path):
    """Every file the rub stage writes is a name a run owns: a user's file of that name in the output folder is
    refused before any work (not found at the end, the results left unpublished)."""
    from bladecase.study.comparison.stage import FIGURES
    from bladecase.study.publish import RUN_RESULTS, check_ownership

    written = set(rotation[0]["files"].values()) | {"wear.csv", "wear_profile.csv", "wear.png", "wear.vtu"}
    assert written <= set(RUN_RESULTS) and {"comparison.csv", *FIGURES.values()} <= set(RUN_RESULTS)
    (tmp_path / "friction_modes.csv").write_text("mine\n")
    with pytest.raises(ValueError, match="friction_modes.csv"):
        check_ownership(tmp_path)
