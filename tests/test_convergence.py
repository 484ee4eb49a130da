"""``[convergence] meshes``: the mesh error of a study's headline figures, measured by the tool.

Checked: the observed order and the Richardson extrapolation recover ``f = f₀ + C hᵖ`` exactly for unequal
refinement ratios; a sequence that oscillates has no order and a conservative error; the figures of each mesh are
those of the study run on that mesh by itself (f1 to 1e-9); the extrapolation from three meshes lands nearer a
fourth, finer mesh than the finest of the three does; the schema refuses what cannot be measured; the report and
the verdict say the errors, or that the mesh error is unknown.
"""

from __future__ import annotations

import pytest

from bladecase.fe import natural_frequencies
from bladecase.study import run
from bladecase.study.convergence.stage import FLAG, SAFETY, SAFETY_UNESTABLISHED, richardson, scaled_study
from bladecase.study.schema import StudyError, loads
from bladecase.study.stages import build_mesh, build_model

STRIP = """
study = {name = "strip"}
geometry = {kind = "plate", span = 0.1, chord = 0.02, size = 0.005}
material = {preset = "steel"}
fem = {order = 1, thickness = 0.002, mass = "lumped"}
reduction = {method = "massless", size = 8}
search = {ipp = [1], periods = [0.95, 1.0], scan = 8}
output = {animate = 1, frames = 4, formats = [], reference = false}
[contact]
clearance = 1e-4
model = "massless"
casing_stiffness = 1e6
face = "tip"
weights = "area"
normal = [1.0, 0.0]
"""


@pytest.mark.parametrize("p", [1.0, 2.0, 3.5])
def test_richardson_recovers_a_power_law_on_unequal_ratios(p):
    h = [1.0, 0.7, 0.45]
    f = [4.0 + 3.0 * x ** p for x in h]
    r = richardson(h, f)
    assert r["order"] == pytest.approx(p, rel=1e-8) and r["extrapolated"] == pytest.approx(4.0, rel=1e-10)
    assert r["error"] == pytest.approx(SAFETY * 3.0 / 4.0, rel=1e-8) and r["monotone"] and r["flag"]
    assert richardson(h, f, study_h=0.45)["error"] == pytest.approx(SAFETY * 3.0 * 0.45 ** p / 4.0, rel=1e-8)


def test_an_oscillating_figure_has_no_order_and_a_conservative_error():
    r = richardson([1.0, 0.7, 0.5], [10.0, 10.4, 10.1])
    assert r["order"] is None and r["extrapolated"] is None and r["monotone"] is False
    assert r["error"] == pytest.approx(SAFETY_UNESTABLISHED * 0.4 / 10.1) and r["flag"] == (r["error"] > FLAG)
    assert richardson([1.0, 0.7], [1.0, 2.0])["error"] is None  # two meshes: no estimate
    assert richardson([1.0, 0.7, 0.5], [1.0, None, 2.0])["error"] is None


@pytest.mark.parametrize("meshes, words", [
    ("[0.7, 0.5, 0.35]", "must include 1"),
    ("[1, 0.5]", "needs 3 to 6 different factors"),
    ("[1, 1, 0.5]", "needs 3 to 6 different factors"),
    ("[1, 0.7, 0.05]", "factors must be in [0.1, 1]"),
    ("[1, 0.7, 'x']", "must be a list of numbers"),
])
def test_the_schema_refuses_meshes_it_cannot_measure(meshes, words):
    with pytest.raises(StudyError, match=r"\[convergence\] meshes: " + words.replace("[", r"\[").replace("]", r"\]")):
        loads(STRIP + f"[convergence]\nmeshes = {meshes}\n")


def test_a_mesh_file_study_is_told_which_splits_its_factors_make(tmp_path):
    from _studies import PLATE, absolute

    with pytest.raises(StudyError, match=r"\[convergence\] meshes: with a \[mesh\] file the finer meshes split every "
                       r"cell edge in n parts .*: 1 → n = 1, 0.7 → n = 1, 0.5 → n = 2; give factors that make 3 "
                       r"different n, e\.g\. \[1, 0\.5, 0\.33\]"):
        loads(absolute(PLATE) + "[convergence]\nmeshes = [1, 0.7, 0.5]\n")
    assert loads(absolute(PLATE) + "[convergence]\nmeshes = [1, 0.5, 0.33]\n")["convergence"]["meshes"]


@pytest.fixture(scope="module")
def converged(tmp_path_factory):
    study = loads(STRIP + "[convergence]\nmeshes = [1, 0.7, 0.5]\n")
    return study, run(study, tmp_path_factory.mktemp("conv"), progress=False)


def test_each_mesh_is_the_study_on_that_mesh(converged):
    study, result = converged
    c = result.summary["convergence"]
    assert c["meshes"] == [1.0, 0.7, 0.5] and c["dofs"][0] == result.summary["model"]["dofs"]
    assert c["dofs"][0] < c["dofs"][1] < c["dofs"][2]
    alone = scaled_study(study, 0.5)
    model = build_model(alone, build_mesh(alone))
    assert model.n_dofs == c["dofs"][2]
    assert c["figures"]["f1_hz"]["values"][2] == pytest.approx(natural_frequencies(model, 1)[0], rel=1e-9)
    assert c["figures"]["f1_hz"]["values"][0] == pytest.approx(result.summary["model"]["linear_frequencies_hz"][0],
                                                               rel=1e-9)
    # the orbit's figures are read at the animated orbit's T/T1
    a = result.summary["files"]["animations"][0]
    assert c["ratio"] == pytest.approx(a["T"] / result.summary["search"]["period_unit_s"], rel=1e-12)
    assert c["figures"]["energy_j"]["values"][0] == pytest.approx(a["energy_j"], rel=1e-3)


def test_the_extrapolation_lands_nearer_a_finer_mesh(converged):
    """f1 from ×1, ×0.7, ×0.5 extrapolated: nearer the ×0.35 mesh's f1 than the ×0.5 mesh is, and the study's
    error estimate covers the ×0.35 mesh."""
    study, result = converged
    f = result.summary["convergence"]["figures"]["f1_hz"]
    fine = scaled_study(study, 0.35)
    f35 = natural_frequencies(build_model(fine, build_mesh(fine)), 1)[0]
    assert abs(f["extrapolated"] - f35) < abs(f["values"][2] - f35)
    assert abs(f["values"][0] - f35) <= f["error"] * f["extrapolated"]


def test_report_and_verdict_say_the_mesh_error(converged, tmp_path):
    from bladecase.post.report import report

    _, result = converged
    text = report(result.summary)
    assert "## Mesh convergence" in text and "| first natural frequency (Hz) |" in text
    v = result.summary["verdict"]
    assert ("mesh_error_large" in v["reasons"]) == bool(result.summary["convergence"]["flagged"])
    assert "Richardson over meshes ×1, ×0.7, ×0.5" in v["trust"] or "the study's mesh is off" in v["trust"]
    plain = run(loads(STRIP), tmp_path / "plain", progress=False)
    assert "**Mesh error: unknown.**" in report(plain.summary)
    assert "mesh_error_unknown" in plain.summary["verdict"]["reasons"]
