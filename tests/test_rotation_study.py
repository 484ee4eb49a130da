"""A rotating plate study end to end: the running clearance against a hand computation, the operating speed in
every stage, the Campbell diagram with its nonsmooth-mode bands and engine-order risks, a clearance that closes,
and a study at rest unchanged by a zero speed."""

from __future__ import annotations

import json
import math

import pytest
from _studies import PLATE, ROOT

from bladecase.cli import main
from bladecase.study import run
from bladecase.study.schema import loads

HUB = 0.3  # the plate (radial along +y from y = 0) on a 0.3 m hub, spinning about z in its own plane
ROTATION = """
[rotation]
speeds = [0, 4000, 8000, 12000]
speed = 8000
axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}
engine_orders = [4, 13]
modes = 3
[output]
formats = ["png"]
reference = false
animate = 0
"""


def _study(extra: str = ROTATION, text: str = PLATE):
    return loads(text.replace("size = 10", "size = 4") + extra, base=ROOT)


@pytest.fixture(scope="module")
def spun(tmp_path_factory):
    return run(_study(), tmp_path_factory.mktemp("rot") / "out", progress=False)


def test_running_clearance_is_the_cold_one_less_the_centrifugal_growth(spun):
    """The tip of a bar from radius R to R + L grows by ρΩ²(R L²/2 + L³/3)/E (plane stress E: the strip's
    Poisson contraction and the spin softening of the static solve make the last 1 %)."""
    r = spun.summary["rotation"]
    m = spun.summary["model"]["material"]
    omega = 8000 * 2 * math.pi / 60
    L = 0.1
    growth = m["rho"] * omega**2 * (HUB * L * L / 2 + L**3 / 3) / m["E"]
    assert r["closure_m"] == pytest.approx(growth, rel=2e-2)
    assert r["clearance_running_m"] == pytest.approx(1e-4 - r["closure_m"], rel=1e-12)
    assert spun.summary["contact"]["clearance_m"] == pytest.approx(r["clearance_running_m"], rel=1e-12)


def test_every_stage_works_at_the_operating_speed(spun):
    c = spun.summary["campbell"]
    f_fe = spun.summary["model"]["linear_frequencies_hz"][0]
    at_8000 = [round(w) for w in c["speeds_rpm"]].index(8000)
    assert f_fe == pytest.approx(c["frequencies_hz"][at_8000][0], rel=1e-6)  # the FE model is K(Ω) at 8000 rpm
    assert f_fe > c["frequencies_hz"][0][0] * 1.01  # stiffer than at rest


def test_campbell_section_bands_and_risks(spun, tmp_path):
    c = spun.summary["campbell"]
    assert c["speeds_rpm"] == pytest.approx([0, 4000, 8000, 12000])
    assert all(row == sorted(row) for row in c["frequencies_hz"])
    assert c["running_clearance_m"][-1] < 0 and c["bands"][-1] is None  # closed at 12000 rpm
    assert "clearance closed" in c["band_notes"][-1]
    for s in range(3):  # a band at every speed where the clearance is open, starting at grazing
        band = c["bands"][s]
        assert band["mode"] == 0
        assert band["low_hz"] == pytest.approx(c["frequencies_hz"][s][0], rel=1e-3)
        assert band["high_hz"] > band["low_hz"]
    # engine order 13 (1733 Hz at 8000 rpm) enters the band of mode 1 (1637 -> 1819 Hz there) below 8000 rpm
    risks = [r for r in c["risks"] if r["engine_order"] == 13]
    step = 12000 / 2000  # band_risks samples the speed range at 2001 points
    assert risks and 4000 < risks[0]["from_rpm"] < 8000 and risks[0]["to_rpm"] == pytest.approx(8000, abs=step)
    assert not [r for r in c["risks"] if r["engine_order"] == 4]
    report = (spun.directory / "report.md").read_text()
    assert "## Campbell diagram" in report and "Contact-induced interaction risk" in report
    assert "engine order 13 lies inside the nonsmooth-mode band" in report
    assert (spun.directory / "campbell.png").stat().st_size > 10_000
    saved = json.loads((spun.directory / "summary.json").read_text())
    assert saved["campbell"]["risks"] == c["risks"]


def test_a_clearance_closed_at_the_operating_speed_stops_the_run(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text((PLATE + ROTATION).replace("meshes/plate.vtu", str(ROOT / "meshes" / "plate.vtu"))
                    .replace("speed = 8000", "speed = 12000"))
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert "at 12000 rpm (1256.64 rad/s) the blade's centrifugal growth along the contact normal" in err
    touch = float(err.split("from about ")[1].split(" rpm")[0])
    assert 11000 < touch < 12000  # the growth goes as Ω²: sqrt(gap / growth) × 12000
    assert not (tmp_path / "out" / "summary.json").exists()


def test_a_study_at_zero_speed_is_the_study_at_rest(tmp_path):
    extra = ("[rotation]\nspeed = 0\naxis = {direction = [0, 0, 1]}\n"
             "[output]\nformats = []\nreference = false\nanimate = 0\n")
    at_zero = run(_study(extra), tmp_path / "zero", progress=False).summary
    at_rest = run(_study("[output]\nformats = []\nreference = false\nanimate = 0\n"), tmp_path / "rest",
                  progress=False).summary
    assert at_zero["model"]["linear_frequencies_hz"] == at_rest["model"]["linear_frequencies_hz"]
    assert [f["admissible_arcs"] for f in at_zero["families"]] == [f["admissible_arcs"] for f in at_rest["families"]]
    assert at_zero["rotation"]["closure_m"] == 0.0 and at_rest["rotation"] is None


@pytest.mark.parametrize("extra, words", [
    ("[rotation]\nspeeds = [0, 1000]\n", "[rotation] axis: required with speeds or speed"),
    ("[rotation]\nspeeds = [0, -1]\naxis = {direction = [0, 0, 1]}\n", "[rotation] speeds: must be a list of"),
    ("[rotation]\nengine_orders = [2]\n", "[rotation] engine_orders: drawn on the Campbell diagram, which needs"),
    ("[rotation]\nspeed = 1\nspeed_unit = 'rps'\naxis = {direction = [0, 0, 1]}\n", "[rotation] speed_unit"),
    ("[contact]\nclearance_at = 'hot'\n", "[contact] clearance_at: must be one of 'cold', 'speed'"),
])
def test_bad_rotation_keys(extra, words):
    text = PLATE.replace("[contact]\nclearance = 1e-4\n", "") if "[contact]" in extra else PLATE
    if "[contact]" in extra:
        extra = extra.replace("[contact]\n", "[contact]\nclearance = 1e-4\n")
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        loads(text + extra, base=ROOT)


def test_a_running_clearance_given_at_speed(spun, tmp_path):
    """clearance_at = "speed": the clearance is the running one at the operating speed; the Campbell speeds see the
    cold clearance it implies (running + closure there), so the same blade gives the same bands as with cold."""
    cold = spun.summary  # run(_study()): the cold-clearance study, run once for the module
    running = cold["rotation"]["clearance_running_m"]
    hot = run(_study(ROTATION.replace('formats = ["png"]', "formats = []"),  # the numbers only (figures: spun's)
                     PLATE.replace("clearance = 1e-4", f"clearance = {running!r}\nclearance_at = 'speed'")),
              tmp_path / "hot", progress=False).summary
    assert hot["rotation"]["clearance_running_m"] == pytest.approx(running, rel=1e-12)
    assert hot["rotation"]["clearance_cold_m"] == pytest.approx(1e-4, rel=1e-9)
    assert hot["campbell"]["running_clearance_m"] == pytest.approx(cold["campbell"]["running_clearance_m"], rel=1e-9)


def test_a_large_model_tracks_its_modes_on_a_sample_of_dofs(monkeypatch, tmp_path):
    """Beyond MAC_DOFS dofs, each speed sends back its mode shapes on a sample of dofs only (a 1M-dof sweep's
    results stay small): on the plate (1084 dofs) with a 150-dof sample, the same modes are followed, the links'
    MACs within 0.02 of the exact ones, and each speed's shapes have 150 rows."""
    from bladecase.fe import campbell as fc
    from bladecase.study.executor import make_executor
    from bladecase.study.rotation import stage as rs
    from bladecase.study.stages import build_contact, build_mesh, build_model

    study = _study(ROTATION.replace("modes = 3", "modes = 4\nbands = false"))
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    exact, _ = rs.campbell_stage(study, model, contact, make_executor("serial"))
    sent = []
    point = rs._speed_point

    def recording(*args, **kwargs):
        out = point(*args, **kwargs)
        sent.append(out["shapes"].shape)
        return out
    monkeypatch.setattr(rs, "_speed_point", recording)
    monkeypatch.setattr(fc, "MAC_DOFS", 150)
    sampled, _ = rs.campbell_stage(study, model, contact, make_executor("serial"))
    assert model.n_dofs > 150 and sent and all(rows == 150 for rows, _ in sent)
    assert (sampled.rank == exact.rank).all()
    assert abs(sampled.link_mac - exact.link_mac).max() < 0.02
    assert sampled.frequencies == pytest.approx(exact.frequencies, rel=1e-12)


def test_a_clearance_closed_at_speed_names_both_ways_out():
    """The blade's centrifugal growth closes a 1 µm cold clearance at 8000 rpm: the message gives the touch speed,
    and says how to give a clearance measured at speed."""
    from bladecase.fe import stiffness_factor
    from bladecase.study.rotation.stage import operating_point
    from bladecase.study.schema import StudyError
    from bladecase.study.stages import build_contact, build_mesh, build_model

    study = _study(text=PLATE.replace("clearance = 1e-4", "clearance = 1e-6"))
    model = build_model(study, build_mesh(study))
    with pytest.raises(StudyError, match=r"touches its casing statically from about .* rpm; lower the speed or widen "
                                         r"\[contact\] clearance \(a clearance measured at speed, not cold: set "
                                         r"\[contact\] clearance_at = \"speed\"\)"):
        operating_point(study, model, build_contact(study, model), stiffness_factor(model))
