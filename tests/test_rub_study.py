"""The [rub] stage: the rub response of the demo blade turning in an out-of-round casing, from a study file to
rub.csv, rub_nodes.csv, rub.png, the summary and the report; its input checks."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from bladecase.study import run
from bladecase.study.demo import demo_text
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads

#: The demo blade under a cylindrical casing whose axis runs along the tip's chord (the tip is an arc of it, so
#: every tip node sits 0.5 mm from the casing cold), with 8 lobes of 0.3 mm.
CASING = """
[casing]
radius = 0.4505
axis = {origin = [-0.000167, 0.030778, -0.3], direction = [-0.350089, -0.936717, 0.0]}
lobes = 8
amplitude = 3e-4
"""

RUB = """
[rub]
speeds = [1450, 1650]
ratio = 0.005
revolutions = 8
window = 3
max_revolutions = 8
"""


def _study(casing: str = CASING, rub: str = RUB, **contact) -> str:
    text = demo_text().replace("clearance = 1e-4            # 0.1 mm tip clearance; normal: radial (+z)\n", "")
    text = text.replace('formats = ["gif", "mp4", "vtu", "png"]', 'formats = ["png", "vtu"]\nreference = false')
    text = text.replace("animate = 2", "animate = 0")
    for key, value in contact.items():
        text = text.replace("[contact]\n", f"[contact]\n{key} = {value}\n")
    return text + casing + rub


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("rub")
    study = loads(_study(), source="<rub>")
    return run(study, out, progress=False), out


@pytest.fixture(scope="module")
def blade():
    """The demo blade's FE model at rest, built once for the tests that call the stage itself (the [casing] and [rub]
    keys they change are not the mesh's or the model's)."""
    from bladecase.study.stages import build_mesh, build_model

    study = loads(_study(), source="<rub>")
    return build_model(study, build_mesh(study))


def test_rub_outputs(result, blade):
    res, out = result
    for name in ("rub.csv", "rub_nodes.csv", "rub.png", "rub.vtu"):
        assert (out / name).is_file()
    import meshio

    vtu = meshio.read(out / "rub.vtu")
    force = vtu.point_data["rub_peak_force_n"]
    assert (force > 0).sum() == res.summary["rub"]["rows"][1]["nodes_touching"]       # the touching nodes, 1650 rpm
    assert vtu.point_data["rub_contact_node"].sum() == 26 and force.max() == pytest.approx(
        res.summary["rub"]["rows"][1]["max_node_force_n"], rel=1e-12)
    pressure = vtu.point_data["contact_pressure"]                                      # Pa, at the hardest speed
    assert ((pressure > 0) == (force > 0)).all() and pressure.max() == pytest.approx(
        res.summary["rub"]["rows"][1]["max_pressure_mpa"] * 1e6, rel=1e-12)
    rows = list(csv.DictReader(open(out / "rub.csv")))
    assert [float(r["speed"]) for r in rows] == [1450.0, 1650.0]
    assert {"total_force_n", "max_pressure_mpa", "loaded_area_mm2", "load_location"} <= set(rows[0])
    nodes = list(csv.DictReader(open(out / "rub_nodes.csv")))
    assert len(nodes) == 2 * 26
    s = res.summary["rub"]
    slow, fast = s["rows"]
    # each node's pressure is its peak force over its tributary area; their largest, the row's
    from bladecase.reduction.contact import tributary_areas
    from bladecase.study.stages import build_contact

    contact = build_contact(loads(_study(), source="<rub>"), blade)
    area = tributary_areas(blade, contact.nodes)
    fast_nodes = nodes[26:]
    np.testing.assert_allclose([float(r["contact_pressure_mpa"]) for r in fast_nodes],
                               [float(r["peak_force_n"]) / a * 1e-6 for r, a in zip(fast_nodes, area)], rtol=1e-8)
    assert max(float(r["contact_pressure_mpa"]) for r in fast_nodes) == pytest.approx(fast["max_pressure_mpa"],
                                                                                        rel=1e-8)
    # past the linear resonance of mode 1 with 8 lobes (about 1626 rpm, f1 216.8 Hz at speed) the rub is far
    # harder: measured (8 revolutions) 0.017 mm, 0.78 MPa, 10.6 N over 35 mm² at 1450 rpm and 0.74 mm, 3.4 MPa,
    # 55.9 N over 41 mm² at 1650 rpm, both centred at the trailing edge
    assert fast["tip_normal_displacement_mm"] > 10 * slow["tip_normal_displacement_mm"] > 0
    assert fast["total_force_n"] > 2 * slow["total_force_n"] > 0
    assert fast["max_pressure_mpa"] > 2 * slow["max_pressure_mpa"] > 0
    for row in (slow, fast):   # the total is one instant's sum: at least the hardest node's peak, at most all peaks
        assert row["max_node_force_n"] <= row["total_force_n"]
        assert 0 < row["loaded_area_mm2"] <= row["peak_loaded_area_mm2"] * (1 + 1e-12)
        assert row["peak_loaded_area_mm2"] <= s["model"]["face_area_mm2"]
        assert row["load_location"] == "trailing edge"
    assert 0 < slow["contact_fraction"] < fast["contact_fraction"] < 1
    assert s["worst"]["speed"] == 1650 and len(s["worst"]["touching_nodes"]) == fast["nodes_touching"] > 0
    assert all(0 <= x <= 1 for x in s["worst"]["touching_along_tip"])
    assert [r["mode"] for r in s["resonances"]] == [1]
    assert 1600 < s["resonances"][0]["speed"] < 1650
    # the casing's yield is the force over each node's share of the 1e6 N/m casing
    assert s["model"]["casing_n_per_m"] == pytest.approx(1e6, rel=1e-9)
    # each speed over the crossing speed of mode 1 (8 lobes: 8Ω/2π = f1(Ω)), found here on f1 at the two speeds
    from scipy.optimize import brentq

    w, f1 = [r["speed_rad_s"] for r in s["rows"]], [hz[0] for hz in s["open_hz"]]
    crossing = brentq(lambda x: 8 * x / (2 * np.pi) - np.interp(x, w, f1), w[0], w[1])
    assert s["crossing"]["speed_rad_s"] == pytest.approx(crossing, rel=1e-4)
    assert s["crossing"]["speed"] == pytest.approx(s["resonances"][0]["speed"], rel=1e-12)
    for row, line in zip(s["rows"], rows):
        assert float(line["speed_ratio"]) == pytest.approx(row["speed_rad_s"] / crossing, rel=1e-4)
        assert line["response"] == row["response"] and int(line["revolutions_run"]) == 8   # max_revolutions = 8
    assert s["rows"][0]["speed_ratio"] < 1 < s["rows"][1]["speed_ratio"]
    text = (out / "report.md").read_text()
    assert "## Rub response" in text and "The hardest rub is at 1650 rpm" in text
    assert f"1650 rpm ({fast['speed_ratio']:.3g} × the crossing speed of mode 1)" in text
    assert "lobes excite linear mode 1" in text
    assert f"the contact pressure peaks at {fast['max_pressure_mpa']:.3g} MPa and the total contact force at " \
           f"{fast['total_force_n']:.3g} N, over {fast['loaded_area_mm2']:.3g} mm² of the tip's 103 mm², centred at " \
           "the trailing edge" in text


@pytest.mark.parametrize("casing, rub, contact, match", [
    (CASING.replace("lobes = 8\n", ""), RUB, {}, r"\[casing\] lobes: an out-of-round casing needs lobes and amplitude"),
    ("\n[casing]\nradius = 0.4505\naxis = {origin = [0, 0.03, -0.3], direction = [-0.35, -0.94, 0]}\n", RUB, {},
     r"\[rub\] speeds: the rub response needs an out-of-round casing"),
    (CASING, RUB.replace("window = 3", "window = 5"), {}, r"\[rub\] window: at most revolutions / 2 = 4"),
    (CASING, RUB.replace("ratio = 0.005\n", ""), {}, r"\[rub\] rayleigh / ratio: give exactly one damping"),
    (CASING, RUB.replace("speeds = [1450, 1650]", "speeds = [0, 1650]"), {}, r"\[rub\] speeds: must all be > 0"),
    (CASING, "\n[rub]\nratio = 0.01\n", {}, r"\[rub\] speeds: required to run the rub response"),
    (CASING, RUB, {"casing_stiffness_per_area": "1e9"}, r"casing_stiffness_per_area: give it or casing_stiffness"),
])
def test_rub_input_errors(casing, rub, contact, match):
    with pytest.raises(StudyError, match=match):
        loads(_study(casing, rub, **contact), source="<rub>")


def test_a_speed_whose_growth_closes_a_clearance_is_named(blade):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB.replace("speeds = [1450, 1650]", "speeds = [1450, 3000]")), source="<rub>")
    model = blade
    with pytest.raises(StudyError, match=r"rpm\) the blade's centrifugal growth .* closes the clearance of contact "
                                         r"node \d+ \(0.5 mm cold\)"):
        rub_stage(study, model, build_contact(study, model), executor=SerialExecutor())


def test_stiffness_per_area_gives_each_node_its_share(blade):
    from bladecase.study.rub.stage import _node_stiffness
    from bladecase.study.stages import build_contact

    text = _study().replace("casing_stiffness = 1e6      # N/m: a thin casing's local radial stiffness; the modes "
                            "converge (docs/massless.md)\n", "casing_stiffness_per_area = 2e9\n")
    study = loads(text, source="<rub>")
    model = blade
    contact = build_contact(study, model)
    from bladecase.reduction.contact import tributary_areas

    area = tributary_areas(model, contact.nodes)
    np.testing.assert_allclose(_node_stiffness(study, model, contact), 2e9 * area, rtol=1e-12)
    assert contact.casing == pytest.approx(2e9 * area.sum(), rel=1e-12)   # the face mean's spring: all in parallel
    # the tip section's area: a NACA 4-digit profile of thickness t and chord c has about 0.685 t c² (2412, 35 mm:
    # 100.7 mm²); the meshed tip face gives 103.2 mm²
    assert area.sum() == pytest.approx(0.685 * 0.12 * 0.035**2, rel=0.05)


def test_a_speed_the_simulation_refuses_is_reported_and_the_others_go_on(blade, monkeypatch):
    """A ValueError of the simulation at one speed (e.g. a grazing switch) is that speed's result, not the end of
    the sweep: the other speeds are computed, the failed one is listed with its reason."""
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub import stage
    from bladecase.study.stages import build_contact

    real = stage.rub_response

    def flaky(system, speed, *args, **kwargs):
        if abs(speed * 60 / (2 * np.pi) - 1450) < 1e-6:
            raise ValueError("grazing switch: a contact signal does not leave its switching surface")
        return real(system, speed, *args, **kwargs)

    monkeypatch.setattr(stage, "rub_response", flaky)
    # two revolutions a speed: what is checked is which speeds have a row, not their figures
    rub = RUB.replace("speeds = [1450, 1650]", "speeds = [1450, 1650, 1660]")
    rub = rub.replace("revolutions = 8", "revolutions = 2").replace("window = 3", "window = 1")
    study = loads(_study(rub=rub), source="<rub>")
    model = blade
    s = stage.rub_stage(study, model, build_contact(study, model), executor=SerialExecutor())
    assert [r["speed"] for r in s["rows"]] == [1650.0, 1660.0]
    assert s["failed_speeds"] == [{"speed": 1450.0, "reason": "grazing switch: a contact signal does not leave its "
                                                              "switching surface"}]
    from bladecase.post.rub.report import rub_report

    assert any("No result at 1450 rpm" in line for line in rub_report(s))
