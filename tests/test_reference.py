"""Verification in a richer model (bladecase.study.reference): an orbit of a reduced model is expanded to the
FE model, projected onto a reference model (another method, 4 × the size) and simulated there for one period."""

from __future__ import annotations

import numpy as np
import pytest
from _studies import PLATE, ROOT

from bladecase.study import run, stages
from bladecase.study.choose import choose_orbits
from bladecase.study.reference import REFERENCE_FACTOR, SURVIVAL_RTOL, check_in_reference, reference_model
from bladecase.study.schema import loads


@pytest.fixture(scope="module")
def plate():
    st = loads(PLATE, base=ROOT)
    model = stages.build_model(st, stages.build_mesh(st))
    contact = stages.build_contact(st, model)
    reduced = stages.build_reduced(st, model, contact)
    unit, _ = stages.period_unit(st, reduced.system)
    chosen = choose_orbits(st, stages.search(st, reduced.system), unit)
    return st, model, contact, reduced, [c.orbit for c in chosen]


def test_reference_is_the_krylov_extension_or_another_method_four_times_larger(plate):
    _, model, contact, reduced, _ = plate
    ref = reference_model(model, contact, reduced)
    assert reduced.method == "modal" and ref.method == "modal+krylov" and ref.n == REFERENCE_FACTOR * reduced.n
    ref = reference_model(model, contact, reduced, basis="independent")
    assert ref.method != "modal" and ref.size == REFERENCE_FACTOR * reduced.size
    with pytest.raises(ValueError, match="basis must be one of 'krylov', 'independent'"):
        reference_model(model, contact, reduced, basis="arnoldi")


def test_an_orbit_survives_in_its_own_model(plate):
    """The check can pass: with the reduced model as its own reference, the orbit comes back to 1e-9."""
    *_, reduced, orbits = plate
    assert orbits
    for orbit in orbits:
        check = check_in_reference(orbit, reduced, reduced)
        assert check["survives"] and check["drift"] < 1e-9 and check["contacts"] == orbit.k


@pytest.mark.parametrize("basis", ["krylov", "independent"])
def test_newton_orbits_of_a_modal_model_do_not_survive_in_the_reference(plate, basis):
    """The seed formulation's limitation, measured: the 1-ipp orbits of the 10-mode model of the plate drift by
    more than SURVIVAL_RTOL in the 40-dof references, the Krylov extension and Craig–Bampton (or start beyond
    their casing)."""
    _, model, contact, reduced, orbits = plate
    ref = reference_model(model, contact, reduced, basis=basis)
    for orbit in orbits:
        check = check_in_reference(orbit, reduced, ref)
        assert not check["survives"]
        assert check["drift"] > SURVIVAL_RTOL or check["contacts"] != orbit.k


def test_run_animates_no_orbit_that_fails_and_says_why(tmp_path):
    st = loads(PLATE.replace("periods = [0.5, 0.9999]", "periods = [0.5, 0.9999]\n[output]\nformats = [\"vtu\"]\n"
                                                                 "frames = 4\nmanifold = false"), base=ROOT)
    result = run(st, out=tmp_path / "out", progress=False)
    s = result.summary
    assert s["files"]["animations"] == [] and s["reference"]["method"] != s["reduction"]["method"]
    report = (result.directory / "report.md").read_text()
    assert "No orbit animated" in report and "artefacts of the reduced model" in report
    tried = s["reference"]["rejected"]  # every orbit tried, with the figures of its failed check
    assert tried and all(not c["survives"] and (c["drift"] is None or c["drift"] > SURVIVAL_RTOL) for c in tried)
    assert f"T = {tried[0]['T']:.8g} s" in report and "unless `[output] animate = 0`" not in report
    assert "unless `[output] animate = 0`" not in " ".join(v for v in s["verdict"].values() if isinstance(v, str))
    log = (result.directory / "run.log").read_text()
    assert "do not survive in the reference model" in log
    assert not np.isnan(s["reference"]["reduced_dofs"])


MASSLESS_PLATE = PLATE.replace("[contact]\n", '[contact]\nmodel = "massless"\n').replace(
    'method = "modal"', 'method = "massless"').replace("periods = [0.5, 0.9999]", "periods = [0.8, 1.001]") + """
[output]
formats = ["vtu"]
frames = 6
manifold = false
"""


def test_massless_study_animates_orbits_that_survive_in_the_reference(tmp_path):
    """The massless contact model end to end on the plate: its animated orbits re-simulate in their own model
    (1e-10) and survive in the 4 × larger massless reference, the model's Krylov extension (drift <
    SURVIVAL_RTOL, one contact phase)."""
    result = run(loads(MASSLESS_PLATE, base=ROOT), out=tmp_path / "out", progress=False)
    anims = result.summary["files"]["animations"]
    assert anims and result.summary["reference"]["method"] == "massless+krylov"
    for a in anims:
        assert a["verification"]["ok"] and a["verification"]["return_error"] < 1e-10
        check = a["reference_check"]
        assert check["survives"] and check["drift"] < SURVIVAL_RTOL and check["contacts"] == 1
        assert 0 < a["contact_time"] < a["T"]
        assert a["contact_intervals"] == [[0.0, a["contact_time"]]]
        assert a["modal_energy"]["top_modes"][0]["mode"] == 1  # near grazing the first mode holds the energy
        assert a["stability"].startswith(("linearly stable", "unstable"))  # the Floquet verdict in words
    fractions = [arc["stable_fraction"] for f in result.summary["families"] for arc in f["admissible_arcs"]]
    assert fractions and all(x is None or 0.0 <= x <= 1.0 for x in fractions)
    report = (result.directory / "report.md").read_text()
    assert "in contact for t/T in [0.0000, " in report and "Energy: " in report and "Doubtful" not in report
    assert "Stability (Floquet multipliers" in report and "linearly stable (Floquet)" in report
    ref = result.summary["reference"]
    assert (f"- Reference model of the orbit check: massless+krylov, {ref['reduced_dofs']} dofs — the reduced model's "
            "basis extended by the Krylov sequence of its own factorisation (no second eigen-solve); its lowest "
            f"{len(ref['relative_error_vs_fe'])} frequencies agree with the FE model's to "
            f"{max(ref['relative_error_vs_fe']):.1e}.") in report


def test_massless_study_keys_go_together():
    from bladecase.study.schema import StudyError

    with pytest.raises(StudyError, match=r"\[reduction\] method: the massless contact model needs"):
        loads(PLATE.replace("[contact]\n", '[contact]\nmodel = "massless"\n'), base=ROOT)
    with pytest.raises(StudyError, match=r"\[reduction\] method: 'massless' is a reduction of the massless"):
        loads(PLATE.replace('method = "modal"', 'method = "massless"'), base=ROOT)
    with pytest.raises(StudyError, match=r"\[contact\] model"):
        loads(PLATE.replace("[contact]\n", '[contact]\nmodel = "penalty"\n'), base=ROOT)


def test_no_orbit_tried_is_said_as_such(tmp_path):
    """With `[output] animate = 0` nothing is checked: the report and the verdict say no orbit was tried, not that
    the orbits tried failed."""
    st = loads(MASSLESS_PLATE.replace("frames = 6", "frames = 6\nanimate = 0"), base=ROOT)
    s = run(st, out=tmp_path / "out", progress=False).summary
    assert s["files"]["animations"] == [] and s["reference"]["rejected"] == []
    report = (tmp_path / "out" / "report.md").read_text()
    assert "**No orbit animated:** no orbit was tried (`[output] animate = 0`" in report
    assert "artefacts" not in report.split("## Files")[0]
