"""``[contact] points = "nodes"``: the demo's nonsmooth mode with every tip node a contact, beside the face mean."""

from __future__ import annotations

import csv

import pytest

from bladecase.study import run
from bladecase.study.demo import demo_text
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


def _text(points: str = "nodes", model: str = "massless") -> str:
    text = demo_text().replace('model = "massless"', f'model = "{model}"\npoints = "{points}"')
    return text.replace('formats = ["gif", "mp4", "vtu", "png"]', 'formats = ["png"]').replace("animate = 2",
                                                                                                 "animate = 0")


@pytest.fixture(scope="module")
def nodal_run(tmp_path_factory):
    """The demo with every tip node a contact and the nodal orbits checked in the reference: one run, two tests."""
    out = tmp_path_factory.mktemp("nodes")
    text = _text().replace("animate = 0", "animate = 1\nreference = true").replace('formats = ["png"]',
                                                                                  'formats = ["png", "vtu"]')
    return run(loads(text, source="<nodes>"), out, progress=False), out


def test_every_tip_node_a_contact(nodal_run):
    res, tmp_path = nodal_run
    s = res.summary["nodal_modes"]
    # measured: from grazing at 210.4996 Hz through the 8:1 tongue of mode 3 (215.5 Hz) and the 4:1 tongue of
    # mode 2 (216 Hz), both crossed onto the backbone, to 227.8 Hz at the face mean's top energy (70 mJ); closing
    # residuals ~1e-14
    assert s["contact_nodes"] == 26 and s["orbits"] >= 10
    assert s["frequency_range_hz"][0] == pytest.approx(210.4996, abs=1e-3)
    assert 225.0 < s["frequency_range_hz"][1] < 230.0
    assert [(t["mode"] + 1, t["ratio"], t["left"]) for t in s["tongues"]][:2] == [(3, "8:1", "crossed"),
                                                                                  (2, "4:1", "crossed")]
    assert s["energy_range_j"][1] >= max(a["energy_range_j"][1] for a in res.summary["families"][0]["admissible_arcs"])
    assert 10 <= s["most_nodes_touching"] <= 26 and s["first_touch_nodes"]
    assert max(r["residual"] for r in s["rows"]) < 1e-10
    energies = [r["energy_j"] for r in s["rows"] if r["on_backbone"]]
    assert energies[:10] == sorted(energies[:10])
    # the face mean touches only once its mean reaches the clearance: later (in energy) than the first node
    assert min(s["face_mean"]["energy_j"]) > 2 * s["energy_range_j"][0]
    rows = list(csv.DictReader(open(tmp_path / "nodal_modes.csv")))
    assert len(rows) == s["orbits"] and "max_penetration_mm" in rows[0]
    assert (tmp_path / "nodal_modes.png").is_file()
    assert "## Every face node a contact" in (tmp_path / "report.md").read_text()


def test_the_nodal_mode_reports_pressure_total_force_and_loaded_area(nodal_run):
    """The casing's load on the tip in the figures that converge under tip-mesh refinement (per-node forces fall
    like the nodes' areas): peak pressure, total force, loaded area and where it sits along the chord — in the
    summary, the CSV and the report's sentence (which no longer quotes a node's force)."""
    res, tmp_path = nodal_run
    s = res.summary["nodal_modes"]
    assert s["face_area_mm2"] == pytest.approx(103.2, abs=0.1)              # the tip section's meshed area
    top = max(s["rows"], key=lambda r: r["energy_j"])
    # measured at the top of the demo's family: see docs/massless.md
    assert top["total_force_n"] > 0 and 0 < top["loaded_area_mm2"] <= top["peak_loaded_area_mm2"]
    assert top["peak_loaded_area_mm2"] <= s["face_area_mm2"] * (1 + 1e-12)
    assert top["max_pressure_mpa"] * top["loaded_area_mm2"] >= top["total_force_n"] * (1 - 1e-9)  # mean <= peak
    assert top["load_location"] in ("leading edge", "mid-chord", "trailing edge") and 0 <= top["load_centre"] <= 1
    assert s["rows"][0]["total_force_n"] == 0 and s["rows"][0]["load_location"] is None    # grazing: no load
    rows = list(csv.DictReader(open(tmp_path / "nodal_modes.csv")))
    assert {"max_pressure_mpa", "total_force_n", "loaded_area_mm2", "load_location"} <= set(rows[0])
    assert "max_force_n" not in rows[0]
    assert float(rows[-1]["total_force_n"]) == pytest.approx(s["rows"][-1]["total_force_n"], rel=1e-8)
    text = (tmp_path / "report.md").read_text()
    assert f"the contact pressure peaks at {top['max_pressure_mpa']:.3g} MPa" in text
    assert f"the total contact force at {top['total_force_n']:.3g} N" in text and "node carries" not in text


def test_nodes_need_the_massless_model():
    text = _text(model="newton").replace("casing_stiffness = 1e6 ", "# casing_stiffness = 1e6 ")
    with pytest.raises(StudyError, match=r"\[contact\] points: 'nodes'"):
        loads(text, source="<nodes>")


def test_nodal_orbits_are_checked_in_the_krylov_reference(nodal_run):
    """Five orbits of the demo's every-node family, ends included, re-simulated for one period in the nodal model's
    Krylov extension (32 dofs): measured drifts 4e-11 (grazing) to 4e-4 — they survive, and the report says so."""
    from bladecase.study.reference import SURVIVAL_RTOL

    res, tmp_path = nodal_run
    s = res.summary["nodal_modes"]
    ref = s["reference"]
    assert ref["model"] == "massless-nodes+krylov (32 dofs)" and ref["checked"] == 5 == ref["survived"]
    drifts = [r["reference_drift"] for r in s["rows"] if r["reference_drift"] is not None]
    assert len(drifts) == 5 and s["rows"][0]["reference_drift"] is not None and max(drifts) < SURVIVAL_RTOL
    assert s["rows"][0]["reference_drift"] < 1e-8  # at grazing: the linear mode, in both models
    csv_rows = list(csv.DictReader(open(tmp_path / "nodal_modes.csv")))
    assert sum(bool(r["reference_drift"]) for r in csv_rows) == 5
    assert "in the reference model massless-nodes+krylov (32 dofs)" in (tmp_path / "report.md").read_text()


def test_the_every_node_orbit_is_animated_checked_and_its_frames_show_the_casing(nodal_run, caplog):
    """With points = "nodes" the every-node orbit is animated: it re-simulates to its start with the exact
    simulator, survives in the reference, its VTK frames carry each contact node's gap, pressure and casing yield,
    and the largest penetration the frames show is the summary's within 5 % (one frame sits on the peak)."""
    import numpy as np
    import pyvista as pv

    from bladecase.post.vtk import read_time_series

    res, out = nodal_run
    (a,) = res.summary["files"]["nodal_animations"]
    assert a["model"] == "every node a contact" and a["verification"]["ok"]
    assert a["verification"]["return_error"] < 1e-8 and a["reference_check"]["survives"]
    face = res.summary["files"]["animations"][0]["energy_j"]
    assert abs(np.log(a["energy_j"] / face)) <= max(abs(np.log(r["energy_j"] / face))
                                                     for r in res.summary["nodal_modes"]["rows"])
    _, frames = read_time_series(out / a["pvd"])
    yields = [float(np.nanmax(pv.read(f)["casing_yield"])) for f in frames]
    gaps = [float(np.nanmin(pv.read(f)["normal_gap"])) for f in frames]
    assert max(yields) * 1e3 == pytest.approx(a["max_penetration_mm"], rel=0.05)
    assert min(gaps) == pytest.approx(-max(yields), rel=1e-9)  # a pressed node's gap is minus the casing's yield
    g = pv.read(frames[0])
    assert int(g["contact_node"].sum()) == res.summary["nodal_modes"]["contact_nodes"]
    assert np.isnan(g["normal_gap"][g["contact_node"] == 0]).all()
    text = (out / "report.md").read_text()
    assert "- every face node a contact, T = " in text and "`casing_yield`" in text
    assert "the animated every-node orbit" in res.summary["verdict"]["trust"]
    log = (out / "run.log").read_text()
    assert 'points = "nodes" makes every node a contact' not in log
    # what each node's casing is: the face's 1e6 N/m shared by area, i.e. a stiffness per unit area
    assert "the casing's 1e+06 N/m shared by the nodes' tributary areas (the face's 103.2 mm²) is 9.689e+09 N/m³" in log


def test_the_every_node_orbit_is_checked_in_a_reference_converged_in_size(nodal_run):
    """The FE model's drift of the animated every-node orbit, from nested Krylov extensions of 4, 8, 16 × the nodal
    model's dofs: the estimate has settled (its change is a small part of it) and is well inside survival."""
    res, out = nodal_run
    (a,) = res.summary["files"]["nodal_animations"]
    full = a["full_model_check"]
    assert full["dofs"] == sorted(full["dofs"]) and len(full["dofs"]) == 3
    assert full["drift"] < 5e-3 and full["bound"] < 0.1 * full["drift"]
    assert "In the FE model (a reference converged in size" in (out / "report.md").read_text()
