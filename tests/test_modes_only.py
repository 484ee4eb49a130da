"""A study without a contact: ``[rotation] speeds`` and no ``[contact]`` gives the linear modes and the Campbell
diagram through ``bladecase run`` (exit 0, all-or-nothing), says in words that there are no nonsmooth modes and how
to add a contact, and speaks the study's speed unit; its frequencies are the assembled model's (at rest) and the
contact study's (at each speed)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from _studies import PLATE, absolute

from bladecase.cli import main
from bladecase.fe import natural_frequencies
from bladecase.study.schema import loads
from bladecase.study.stages import build_mesh, build_model

NO_CONTACT = absolute(PLATE).replace("[contact]\nclearance = 1e-4\n", "")
ROTATION = """
[rotation]
speeds = [0, 400, 800, 1200]
speed_unit = "rad/s"
axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}
engine_orders = [13]
modes = 3
[output]
formats = ["png"]
"""


def _run(tmp_path, text: str, capsys) -> tuple[int, str]:
    path = tmp_path / "s.toml"
    path.write_text(text)
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet", "--no-progress"])
    return code, capsys.readouterr().err


@pytest.fixture(scope="module")
def modes_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("modes")
    path = folder / "s.toml"
    path.write_text(NO_CONTACT + ROTATION)
    assert main(["run", str(path), "--out", str(folder / "out"), "--quiet", "--no-progress"]) == 0
    return folder / "out"


def test_modes_and_campbell_without_a_contact(modes_run):
    assert "[contact]" not in NO_CONTACT
    names = {p.name for p in modes_run.iterdir()}
    assert {"summary.json", "report.md", "run.log", "campbell.png", "mesh.vtu"} <= names
    assert not any(n.startswith(".staging") for n in names)
    s = json.loads((modes_run / "summary.json").read_text())
    c = s["campbell"]
    assert s["contact"] is None and s["families"] == [] and c["bands"] == [None] * 4
    assert c["speed_unit"] == "rad/s" and c["speeds"] == pytest.approx([0, 400, 800, 1200])
    assert c["running_clearance_m"] is None
    # independent: at rest, the assembled model's own eigen-solve; at the operating speed, the summary's model
    model = build_model(loads(NO_CONTACT + ROTATION), build_mesh(loads(NO_CONTACT + ROTATION)))
    f0 = natural_frequencies(model, 3)
    assert np.array(c["frequencies_hz"][0]) == pytest.approx(f0, rel=1e-8)
    assert c["frequencies_hz"][-1] == pytest.approx(s["model"]["linear_frequencies_hz"][:3], rel=1e-8)
    assert c["frequencies_hz"][-1][0] > 1.02 * c["frequencies_hz"][0][0]  # stress stiffening
    assert (modes_run / "campbell.png").stat().st_size > 10_000
    report = (modes_run / "report.md").read_text()
    assert "No nonsmooth modes: the study has no [contact]" in report
    assert "without a contact there are no nonsmooth modes" in report and "add a [contact] section" in report
    assert "| speed (rad/s) | (rpm) |" in report and "Operating speed 1200 rad/s (11459.2 rpm)" in report
    assert "EO 13 × mode 1 at " in report and " rad/s (" in report.split("EO 13 × mode 1 at ")[1][:40]


def test_the_same_plate_with_a_contact_gives_the_same_campbell_frequencies(modes_run, tmp_path):
    from bladecase.study import run

    text = (absolute(PLATE) + ROTATION.replace("[0, 400, 800, 1200]", "[0, 1200]")
            .replace("modes = 3\n", "modes = 3\nbands = false\nspeed = 800\n")
            .replace('formats = ["png"]', "formats = []\nreference = false\nanimate = 0"))
    with_contact = run(loads(text), tmp_path / "c", progress=False).summary["campbell"]
    alone = json.loads((modes_run / "summary.json").read_text())["campbell"]
    assert with_contact["frequencies_hz"][0] == pytest.approx(alone["frequencies_hz"][0], rel=1e-10)
    assert with_contact["frequencies_hz"][-1] == pytest.approx(alone["frequencies_hz"][-1], rel=1e-10)


def test_rpm_study_speaks_rpm_first(tmp_path, capsys):
    text = NO_CONTACT + ROTATION.replace("[0, 400, 800, 1200]", "[0, 6000]").replace('"rad/s"', '"rpm"')
    code, _ = _run(tmp_path, text.replace('formats = ["png"]', "formats = []"), capsys)
    assert code == 0
    report = (tmp_path / "out" / "report.md").read_text()
    assert "| speed (rpm) | (rad/s) |" in report and "Operating speed 6000 rpm (628.319 rad/s)" in report


@pytest.mark.parametrize("extra, words", [
    ("[forcing]\namplitude = 1.0\n", "[forcing] amplitude: the forced response follows the nonsmooth modes, which "
                                     "needs a contact: add a [contact] section"),
])
def test_a_stage_that_needs_a_contact_is_refused_and_nothing_is_written(tmp_path, capsys, extra, words):
    code, err = _run(tmp_path, NO_CONTACT + ROTATION + extra, capsys)
    assert code == 2 and words in err
    assert not (tmp_path / "out").exists()


def test_without_speeds_a_contact_is_still_required():
    with pytest.raises(Exception, match=r"\[contact\] clearance: required"):
        loads(NO_CONTACT)


def test_reduce_without_a_contact_says_what_is_missing(tmp_path, capsys):
    """`bladecase reduce` of a study without [contact]: exit 2, the message names the missing section and what the
    study can give instead (not a 'gap is required' from deep inside)."""
    path = tmp_path / "s.toml"
    path.write_text(NO_CONTACT + ROTATION)
    assert main(["assemble", str(path), "--quiet", "-o", str(tmp_path / "m.npz")]) == 0
    capsys.readouterr()
    args = ["--model", str(tmp_path / "m.npz"), "--quiet", "-o", str(tmp_path / "r.npz")]
    assert main(["reduce", str(path), *args]) == 2
    err = capsys.readouterr().err
    assert "[contact]: this study has none" in err and "'bladecase run' gives the linear modes" in err, err
    assert not (tmp_path / "r.npz").exists()
