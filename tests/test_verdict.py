"""The three-line verdict at the top of every report and in ``summary.json["verdict"]``
(:mod:`bladecase.post.verdict`): what was found, whether to trust it and why, what to do next — each sentence and
reason code on a study built to trigger it.

Real runs (each a second or two): the demo (a mode found and checked), massless plates whose search range leaves
out the first linear period, whose one family has no admissible orbit, whose contact face sits on the node line of
its first modes, and whose rigid casing keeps the mode next to grazing; a Newton plate whose orbits fail the
reference check. The other reasons use copies of those summaries with fields changed (each test says which).
"""

from __future__ import annotations

import copy
import json
import re

import pytest
from _studies import PLATE, absolute, as_raw

from bladecase.post.report import report
from bladecase.post.verdict import REASONS, verdict
from bladecase.study.demo import demo_study
from bladecase.study.run import run
from bladecase.study.schema import loads, validate

OUTPUT = "\n[output]\nformats = []\nframes = 4\nanimate = 1\n"

#: The plate with the massless contact model (4 modes + the attachment) against a rigid casing, near T1.
MASSLESS_PLATE = absolute(PLATE).replace("[contact]\n", '[contact]\nmodel = "massless"\n').replace(
    'method = "modal"\nsize = 10', 'method = "massless"\nsize = 4').replace(
    "periods = [0.5, 0.9999]", "periods = [0.8, 1.001]") + OUTPUT

#: Sentences that would advise the other contact model.
OTHER_MODEL = re.compile(r"\[contact\] model|impact law|massless contact model", re.IGNORECASE)


def _run(text: str, out) -> tuple[dict, str]:
    result = run(loads(text), out=out, progress=False)
    summary = json.loads((result.directory / "summary.json").read_text())
    return summary, (result.directory / "report.md").read_text()


def _top(report_text: str) -> list[str]:
    """The report's lines between its title and ``## Model``."""
    lines = report_text.splitlines()
    return lines[1:lines.index("## Model")]


def _check(v: dict) -> None:
    assert set(v) == {"found", "trust", "next", "reasons"}
    assert all(isinstance(v[k], str) and v[k] for k in ("found", "trust", "next"))
    assert v["reasons"] and set(v["reasons"]) <= set(REASONS), set(v["reasons"]) - set(REASONS)


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The demo study (its tip face against a 1e6 N/m casing, massless model), one orbit animated and checked in
    the reference model, no pictures."""
    c = copy.deepcopy(demo_study().config)
    c["output"].update(formats=[], frames=4, animate=1)
    result = run(validate(as_raw(c), source="<demo>"), out=tmp_path_factory.mktemp("demo") / "out", progress=False)
    return json.loads((result.directory / "summary.json").read_text()), (result.directory / "report.md").read_text()


@pytest.fixture(scope="module")
def rigid(tmp_path_factory):
    """The massless plate against a rigid casing: narrow arcs next to grazing."""
    return _run(MASSLESS_PLATE, tmp_path_factory.mktemp("rigid") / "out")


@pytest.fixture(scope="module")
def newton(tmp_path_factory):
    """The Newton plate (modal, 10 modes) with the reference check: its 1-ipp orbits do not survive there."""
    return _run(absolute(PLATE) + OUTPUT, tmp_path_factory.mktemp("newton") / "out")


def test_demo_finds_a_stiffening_mode_and_trusts_it_with_care(demo):
    """(a) The demo: a stiffening mode of mode 1 with its frequencies, tip amplitude, contact force and stable share;
    its animated orbit re-simulates and survives in the reference model, but tip nodes pass the clearance far beyond
    the face mean: trusted with care; the verdict at the top of the report, right under the title."""
    summary, text = demo
    v = summary["verdict"]
    _check(v)
    assert v["reasons"][:5] == ["mode_found", "band_to_tongue", "verified", "reference_survived",
                                "reduced_model_matches_fe"]
    assert not {"verification_failed", "reference_failed", "not_animated", "no_reference_check"} & set(v["reasons"])
    arc = summary["families"][0]["admissible_arcs"][0]
    f1 = summary["reduction"]["frequencies_hz"][0]
    # the band is quoted up to the 8:1 tongue of mode 3 (its place moves with the mesh), the arc's top beyond it
    t = arc["tongue"]
    assert (t["mode"], round(t["ratio"]), t["own_mode"]) == (3, 8, 1) and t["own_share"] < 0.9
    assert arc["backbone_f_lo"] == arc["f_lo"] and arc["backbone_f_hi"] < t["frequency_hz"] < arc["f_hi"]
    assert v["found"].startswith(f"A stiffening nonsmooth mode of mode 1 (one contact phase per period): "
                                 f"{arc['f_lo']:.1f} → {arc['backbone_f_hi']:.1f} Hz (from grazing to ")
    assert "up to the tongue of the internal resonance 8:1 with mode 3" in v["found"]
    assert "band_to_tongue" in v["reasons"]
    assert f"**Family 0 enters a resonance tongue at {t['frequency_hz']:.2f} Hz**" in text
    assert f"above the linear frequency of mode 1, {f1:.1f} Hz" in v["found"]
    lo, hi = arc["tip_amplitude_range_mm"]
    assert f"tip amplitude {lo:.3g}–{hi:.3g} mm" in v["found"]
    assert f"contact force up to {arc['contact_force_range_n'][1]:.3g} N" in v["found"]
    assert "linearly stable over 100 % of its admissible orbits" in v["found"]
    a = summary["files"]["animations"][0]
    # trusted with care: the face mean is not the tip — its node 3 passes the clearance by 92 % of it
    assert v["trust"].startswith("Trust it with care: the animated orbit re-simulates event-driven back to itself to "
                                 f"{a['verification']['return_error']:.1e}")
    assert "the face mean's contact is not the tip's: a node passes the clearance by" in v["trust"]
    assert f"survives in the reference model {a['reference_check']['reference']}" in v["trust"]
    # the face's nodes beyond the clearance are a limit of the contact model, named with their numbers
    assert "tip_not_resolved" in v["reasons"] and "Limit: the contact is the mean of the face 'tip'" in v["trust"]
    assert f"{a['tip_excursion']['nodes_beyond']} of its 26 nodes pass the clearance" in v["trust"]
    assert "internal_resonance" in v["reasons"] and "Read the backbone below" in v["next"]
    assert _top(text) == ["", f"- **Found:** {v['found']}", f"- **Trust:** {v['trust']}", f"- **Next:** {v['next']}",
                          "", text.splitlines()[6], ""]
    assert text.splitlines()[6].startswith("Study file:")
    assert not OTHER_MODEL.search(" ".join(v[k] for k in ("found", "trust", "next")))


def test_no_family_when_the_range_leaves_out_the_first_linear_period(tmp_path):
    """(b) Periods [0.5, 0.6] × T1 on the massless plate: no family, and the verdict names the first linear period
    and says to widen the range to it; the report has no empty family table and no advice about artefacts or the
    other contact model."""
    summary, text = _run(MASSLESS_PLATE.replace("periods = [0.8, 1.001]", "periods = [0.5, 0.6]"), tmp_path / "o")
    v = summary["verdict"]
    _check(v)
    assert summary["families"] == []
    assert v["reasons"][0] == "no_family_in_range" and "grazing_outside_range" in v["reasons"]
    assert "contact_on_node_line" not in v["reasons"] and "mode_found" not in v["reasons"]
    T1 = summary["search"]["period_unit_s"]
    assert v["found"].startswith(f"No nonsmooth mode in the searched periods [0.5, 0.6] × T1 (= [{0.5 * T1:.6g}, "
                                 f"{0.6 * T1:.6g}] s): the search found no family")
    assert f"mode 1's ({T1:.6g} s, " in v["next"] and "1.0 T1) lies above the searched periods" in v["next"]
    assert "their upper end is 0.6 T1" in v["next"]
    assert "Widen `[search] periods` to include 1.0 T1 (e.g. [0.5, 1.001] × T1)" in v["next"]
    assert v["trust"].startswith("Nothing to verify (no admissible orbit)")
    assert "| family | contact phases / period |" not in text and "artefacts" not in text
    assert "**No orbit animated:** no family has an admissible arc in the search range" in text
    assert not OTHER_MODEL.search(re.sub(r"- Contact model: .*", "", text))


def test_families_without_an_admissible_orbit_say_why(tmp_path):
    """(c) Periods [0.8, 0.85] × T1 on the massless plate: one family of one-phase orbits, none admissible — the
    verdict says where the family lies against f1, why its orbits are not admissible (modes.json: the casing would
    pull, orbits cross it) and that the range stops short of grazing at 1.0 T1."""
    summary, text = _run(MASSLESS_PLATE.replace("periods = [0.8, 1.001]", "periods = [0.8, 0.85]"), tmp_path / "o")
    v = summary["verdict"]
    _check(v)
    fam, = summary["families"]
    assert fam["admissible_arcs"] == [] and fam["admissible_orbits"] == 0
    assert v["reasons"][0] == "no_admissible_orbit"
    assert {"casing_would_pull", "grazing_outside_range"} <= set(v["reasons"])
    lo, hi = fam["frequency_range_hz"]
    assert (f"1 family of orbits with one contact phase per period at {lo:.1f}–{hi:.1f} Hz" in v["found"]
            and "% above the linear frequency of mode 1" in v["found"])
    assert f"none of its {fam['orbits']} orbits admissible: all {fam['orbits']} need a pulling casing" in v["found"]
    assert "their upper end is 0.85 T1" in v["next"] and "include 1.0 T1" in v["next"]
    assert "| family | contact phases / period |" not in text and "artefacts of the reduced model" not in text


def test_a_contact_on_the_node_line_of_the_first_modes(tmp_path):
    """(d) The plate's tip face as the contact (massless): its mean barely moves in modes 1 and 2 — the contact's
    share of mode 1's stiffness is far below what any grazing orbit can resolve, so no branch grows from it (the log
    says why; a family of another mode's orbits was found here before) — and the verdict says the contact group is
    on their node line, with the b² values, instead of a range advice."""
    summary, _ = _run(MASSLESS_PLATE.replace("[contact]\n", '[contact]\nface = "tip"\n'), tmp_path / "o")
    v = summary["verdict"]
    _check(v)
    b2 = summary["reduction"]["contact_weights_b2"]
    assert b2[0] < 1e-3 * b2[2] and b2[1] < 1e-3 * b2[2]
    assert v["reasons"][0] == "no_family_in_range" and summary["families"] == []
    assert "massless branch of open mode 1 skipped: no grazing orbit found from open-phase mode 1" in \
        (tmp_path / "o" / "run.log").read_text()
    assert "contact_on_node_line" in v["reasons"]
    assert "grazing_outside_range" not in v["reasons"] and "no_reason_in_data" not in v["reasons"]
    assert "the contact group is on a node line of modes 1–2" in v["next"]
    assert f"b² = {b2[0]:.2g}" in v["next"] and "grazing energy ½ω²(d/b)² = " in v["next"]
    assert "the first mode it sees well is mode 3" in v["next"]


def test_narrow_arcs_against_a_rigid_casing_name_the_contact_stiffness(rigid):
    """(d) The massless plate against a rigid casing: narrow arcs within a fraction of a percent of f1; the verdict
    and the report's "Narrow" paragraph say where they lie, and the verdict names the contact stiffness k_c."""
    summary, text = rigid
    v = summary["verdict"]
    _check(v)
    assert {"mode_found", "narrow_arc", "stiff_casing"} <= set(v["reasons"])
    kc = summary["contact"]["contact_stiffness_n_per_m"]
    assert ("Against a rigid casing the closed contact is as stiff as the blade's own contact stiffness "
            f"k_c = {kc:.3g}") in v["next"]
    assert "`[contact] casing_stiffness`" in v["next"]
    narrow = next(line for line in text.splitlines() if line.startswith("**Narrow:**"))
    assert "above the linear frequency of mode 1" in narrow and "contact splits" not in narrow
    assert narrow[len("**Narrow:** "):-1] in v["next"][0].lower() + v["next"][1:]


def test_a_stiff_compliant_casing_and_a_newton_narrow_arc(rigid):
    """(d) Synthetic, from the rigid-casing plate's summary: (1) a compliant casing of 1e12 N/m (casing and series
    stiffness changed) — the casing stiffness is named against k_c; (2) the same summary as a Newton study whose
    arc is narrow and 4–4.05 % above f1 (contact model, arcs and animations changed) — the "Narrow" words say where
    the arc is, not "grazing", and nothing about the casing."""
    summary = copy.deepcopy(rigid[0])
    summary.pop("verdict")
    kc = summary["contact"]["contact_stiffness_n_per_m"]
    summary["contact"].update(casing_stiffness_n_per_m=1e12, series_stiffness_n_per_m=1 / (1 / kc + 1e-12))
    v = verdict(summary)
    assert "stiff_casing" in v["reasons"]
    assert f"The casing (k = 1e+12 N/m) is {1e12 / kc:.3g} × the blade's own contact stiffness k_c = {kc:.3g}" \
           in v["next"]

    newton = copy.deepcopy(rigid[0])
    newton.pop("verdict")
    newton["contact"].update(model="newton", casing_stiffness_n_per_m=None)
    for key in ("contact_stiffness_n_per_m", "series_stiffness_n_per_m"):
        newton["contact"].pop(key)
    newton["files"]["animations"] = []  # its animated orbit was a massless one
    f1 = newton["reduction"]["frequencies_hz"][0]
    fam = newton["families"][0]
    fam["admissible_arcs"] = [dict(fam["admissible_arcs"][0], f_lo=1.04 * f1, f_hi=1.0405 * f1,
                                   T_lo=1 / (1.0405 * f1), T_hi=1 / (1.04 * f1))]
    v = verdict(newton)
    assert "narrow_arc" in v["reasons"] and "stiff_casing" not in v["reasons"]
    assert "The widest admissible arc spans 4.8e-04 of its frequency, 4–4.05 % above the linear frequency of mode 1" \
           in v["next"]
    assert "grazing" not in v["next"] and "one impact per period" in v["found"]
    narrow = next(line for line in report(newton).splitlines() if line.startswith("**Narrow:**"))
    assert "4–4.05 % above the linear frequency of mode 1" in narrow and "grazing" not in narrow


def test_orbits_rejected_by_the_reference_model(newton):
    """The Newton plate with the reference check: arcs, but every orbit tried fails the check — "Do not trust it
    yet", naming the orbits tried and their drifts (from summary.json's reference.rejected), and the report's
    "No orbit animated" paragraph (only because the family table is not empty) with no advice about the other
    contact model, which the study's data do not call for."""
    summary, text = newton
    v = summary["verdict"]
    _check(v)
    assert summary["files"]["animations"] == [] and any(f["admissible_arcs"] for f in summary["families"])
    assert {"mode_found", "not_animated", "reference_failed"} <= set(v["reasons"])
    assert "switch_contact_model" not in v["reasons"]
    tried = summary["reference"]["rejected"]
    assert v["trust"].startswith("Do not trust it yet:") and f"{len(tried)} orbits tried, none survives" in v["trust"]
    assert f"reference model {summary['reference']['method']} ({summary['reference']['reduced_dofs']} dofs)" \
           in v["trust"]
    assert f"T = {tried[0]['T']:.8g} s" in v["trust"] and f"drifts by {tried[0]['drift']:.1e}" in v["trust"]
    assert "one impact per period" in v["found"] and "impulses up to" in v["found"]
    assert "No orbit animated" in text and "artefacts of the reduced model" in text
    assert "| family | ipp |" in text
    assert not OTHER_MODEL.search(re.sub(r"- Contact model: .*", "", text))


def test_newton_reference_failure_and_scattered_energies_advise_the_massless_model(newton, demo):
    """Synthetic: the Newton plate's summary with a comparison grid whose energies at 0.95 T1 scatter 3×, whose
    largest sizes disagree and one of whose models found no admissible arc (comparison rows added) — then, and
    only then, the verdict advises the massless contact model; the demo's (massless) summary with the same rows
    and its orbit failing the reference check (reference_check changed) gets no such advice."""
    rows = [{"model": "fe", "method": "fe", "size": None},
            {"model": "modal-10", "method": "modal", "size": 10, "energy_0.95T1": 1.0e-3,
             "convergence": "not converged (Δ = 67 %)"},
            {"model": "modal-20", "method": "modal", "size": 20, "energy_0.95T1": 3.0e-3,
             "convergence": "not converged (Δ = 67 %)"},
            {"model": "lanczos-si-6", "method": "lanczos-si", "size": 6, "admissible_arcs": 0}]
    summary = copy.deepcopy(newton[0])
    summary.pop("verdict")
    summary["comparison"] = {"rows": rows, "diagnostics": [], "figures": {}}
    v = verdict(summary)
    assert {"energies_scatter", "comparison_not_converged", "switch_contact_model"} <= set(v["reasons"])
    assert "the energies at 0.95 T1 range from 0.001 to 0.003 J" in v["next"]
    assert "the massless contact model ([contact] model = \"massless\"" in v["next"]
    assert "not converged (Δ = 67 %) between sizes 10 and 20" in v["trust"]
    assert "models_disagree" in v["reasons"]
    assert "of the 2 compared models, lanczos-si-6 found no admissible arc in the same periods" in v["trust"]

    massless = copy.deepcopy(demo[0])
    massless.pop("verdict")
    massless["comparison"] = {"rows": rows, "diagnostics": [], "figures": {}}
    massless["files"]["animations"][0]["reference_check"].update(survives=False, drift=0.4, contacts=2)
    v = verdict(massless)
    assert "energies_scatter" in v["reasons"] and "switch_contact_model" not in v["reasons"]
    assert not OTHER_MODEL.search(v["next"])


def test_failed_checks_say_so_with_their_numbers(demo):
    """Synthetic, from the demo's summary: the animated orbit's re-simulation misses it (verification changed), it
    did not survive in the reference model (reference_check changed), reduced mode 1 is 5 % off FE mode 1
    (fe_match changed), no reference model ran (reference and reference_check removed)."""
    base = copy.deepcopy(demo[0])
    base.pop("verdict")
    a = base["files"]["animations"][0]

    s = copy.deepcopy(base)
    s["files"]["animations"][0]["verification"].update(ok=False, return_error=1e-3)
    v = verdict(s)
    assert "verification_failed" in v["reasons"] and "verified" not in v["reasons"]
    assert v["trust"].startswith("Do not trust it yet:")
    assert f"the event-driven re-simulation of the orbit at T = {a['T']:.8g} s does not return to it (error 0.001)" \
           in v["trust"]

    s = copy.deepcopy(base)
    s["files"]["animations"][0]["reference_check"].update(survives=False, drift=0.4, contacts=2)
    v = verdict(s)
    assert "reference_failed" in v["reasons"] and v["trust"].startswith("Do not trust it yet:")
    assert a["reference_check"]["reference"] == "massless+krylov (36 dofs)"  # 4 × the 9 dofs of the massless 8 model
    assert (f"the orbit at T = {a['T']:.8g} s did not survive in the reference model massless+krylov (36 dofs): it "
            "drifts by 40% in one period (energy norm), with 2 contact(s) for 1") in v["trust"]
    assert f"Treat the orbit at T = {a['T']:.8g} s as an artefact of the massless 8 model" in v["next"]
    assert "`[reduction] sizes = [8, 32]`" in v["next"] and not OTHER_MODEL.search(v["next"])

    s = copy.deepcopy(base)
    s["reduction"]["fe_match"][0]["relative_error"] = 0.05
    v = verdict(s)
    assert "reduced_model_off_fe" in v["reasons"] and v["trust"].startswith("Trust it with care:")
    assert "reduced mode 1 is 5.0% off its FE counterpart (FE mode 1)" in v["trust"]
    assert "Enlarge `[reduction] size`" in v["next"]

    s = copy.deepcopy(base)
    s["reference"] = None
    s["files"]["animations"][0].pop("reference_check")
    v = verdict(s)
    assert "no_reference_check" in v["reasons"] and "no reference-model check ran" in v["trust"]
    assert "`[output] reference = true`" in v["next"]


def test_nothing_found_for_no_reason_in_the_data_says_so(rigid):
    """Synthetic, from the rigid-casing plate's summary: its families removed — the searched periods hold T1, the
    contact sees mode 1, and the summary holds no reason: the verdict says so rather than guess."""
    s = copy.deepcopy(rigid[0])
    s.pop("verdict")
    s["families"], s["files"]["animations"] = [], []
    v = verdict(s)
    assert v["reasons"][0] == "no_family_in_range" and "no_reason_in_data" in v["reasons"]
    assert "grazing_outside_range" not in v["reasons"] and "stiff_casing" not in v["reasons"]
    assert "which the contact sees (b² = 0.97), yet the search found no family there; nothing in summary.json says " \
           "why" in v["next"]
    text = report(s)
    assert text.splitlines()[2] == f"- **Found:** {v['found']}"
