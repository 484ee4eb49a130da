"""What an engineer reads in a run's results: the words, the units and the numbers of summary.json, report.md,
run.log, modes.json and forced.csv.

* modes.json: every orbit says whether it is linearly stable (Floquet) — a verdict for every admissible orbit, a
  reason for every orbit without one — and agrees with the summary's stable fractions;
* the massless contact model's words (contact phases, contact force) in the report, the log, the summary and the
  figures; Newton's (impacts, impulses) kept for Newton studies;
* forced.csv: one unit per column, as the name's suffix (the convention of comparison.csv and summary.json);
* a face contact is named as a face in the log and the report;
* tip amplitude |u| (mm), contact force (N) or impulses (N·s), contact fraction and casing penetration per animated
  orbit and per admissible arc, and the contact stiffnesses — each checked against an independent computation.
"""

from __future__ import annotations

import copy
import csv
import json
import re

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from _studies import PLATE, absolute, as_raw

import bladecase as bc
from bladecase.nsm import chain
from bladecase.nsm.floquet import floquet
from bladecase.reduction import reduce
from bladecase.study.demo import demo_study
from bladecase.study.run import run
from bladecase.study.schema import loads, validate


def _small(contact_model: str):
    """The demo study (massless: its tip face against a 1e6 N/m casing; newton: the seed paper's tip node on a
    coarser mesh), one orbit animated, no pictures."""
    c = copy.deepcopy(demo_study(contact_model).config)
    if contact_model == "newton":
        c["geometry"].update(size=0.01, tip_size=0.005)
        c["reduction"]["size"] = 6
        c["search"]["scan"] = 4
    c["output"].update(formats=[], frames=4, animate=1, reference=False)
    return validate(as_raw(c), source=f"<small {contact_model} demo>")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    return run(_small("massless"), out=tmp_path_factory.mktemp("massless") / "out", progress=False)


@pytest.fixture(scope="module")
def newton(tmp_path_factory):
    return run(_small("newton"), out=tmp_path_factory.mktemp("newton") / "out", progress=False)


def _texts(result) -> tuple[str, str, dict]:
    d = result.directory
    return (d / "report.md").read_text(), (d / "run.log").read_text(), json.loads((d / "summary.json").read_text())


def _animated(result):
    """The animated orbit (the first one chosen) and the main reduced model."""
    from bladecase.study.choose import choose_orbits
    from bladecase.study.stages import period_unit

    reduced = next(iter(result.models.values())).reduced
    study = _small("massless" if "massless" in reduced.method else "newton")
    unit, _ = period_unit(study, reduced.system)
    (choice,) = choose_orbits(study, result.families, unit)[:1]
    entry = result.summary["files"]["animations"][0]
    assert choice.orbit.T == pytest.approx(entry["T"], rel=1e-14)
    return choice.orbit, reduced, entry


# ----------------------------------------------------------------------------- 1. stability in modes.json


def test_every_orbit_of_the_modes_file_has_its_stability(demo):
    """Every admissible orbit carries its Floquet verdict (the same as floquet() on the orbit), every other one a
    reason; the summary's stable fraction of each arc is the share of its verdicts that are stable."""
    doc = json.loads((demo.directory / "modes.json").read_text())
    for fam, raw in zip(demo.families, doc["families"]):
        assert len(raw["orbits"]) == len(fam.orbits)
        for o, rec in zip(fam.orbits, raw["orbits"]):
            assert isinstance(rec["stability"], str) and rec["stability"]
            if o.admissible:
                fl = floquet(o)
                assert rec["stable"] is fl.stable and rec["stability"] == fl.verdict
                assert len(rec["multipliers"]) == 2 * fam.system.n
            else:
                assert rec["stable"] is None and rec["stability"].startswith("not computed: the orbit is not admiss")
        for arc, summary in zip(fam.arcs, demo.summary["families"][0]["admissible_arcs"]):
            verdicts = [raw["orbits"][j]["stable"] for j in range(arc.start, arc.stop + 1)]
            assert None not in verdicts and summary["stable_fraction"] == pytest.approx(np.mean(verdicts))
    entry = demo.summary["files"]["animations"][0]
    assert entry["stable"] is True and entry["stability"].startswith("linearly stable")


def test_newton_modes_file_stability_and_resonant_periods(tmp_path):
    """Newton's orbits too (saltation matrices); a resonant scan period says it has no orbit; the file reads back
    with the verdicts."""
    from bladecase.study.documents import families_document, load_families

    s = chain(2, k=1.0, m=0.5, gap=1.0)
    branch = bc.backbone(s, [6.6, 7.0, 7.05, 2 * np.pi / np.sqrt(3 - np.sqrt(5))])  # the last one is resonant
    orbits = families_document([branch], s)["families"][0]["orbits"]
    assert [o.get("stable") for o in orbits] == [False, True, True, None]
    assert orbits[0]["stability"] == "unstable: a multiplier -1.15 (flip) leaves the unit circle"
    assert orbits[3]["stability"] == "no orbit (resonant period)"
    path = tmp_path / "modes.json"
    path.write_text(json.dumps(families_document([branch], s)))
    back = load_families(path, s)[0]
    assert [o.stable if o is not None else None for o in back.orbits] == [False, True, True, None]


def test_large_systems_sample_the_stability_and_say_so(monkeypatch, bar10_massless_mode):
    """Above STABILITY_DOFS dofs the multipliers are computed for STABILITY_SAMPLES orbits per arc (ends included);
    every other admissible orbit says why it has no verdict."""
    from bladecase.study import documents

    branch = bar10_massless_mode  # conftest's: massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))
    system = branch.system
    arc = max(branch.arcs, key=lambda a: a.stop - a.start)
    assert arc.stop - arc.start >= 4
    monkeypatch.setattr(documents, "STABILITY_DOFS", 0)
    monkeypatch.setattr(documents, "STABILITY_SAMPLES", 3)
    records = documents.stability_records(branch)
    on_arc = records[arc.start:arc.stop + 1]
    judged = [r for r in on_arc if r["stable"] is not None]
    assert len(judged) == 3 and on_arc[0]["stable"] is not None and on_arc[-1]["stable"] is not None
    assert all(r["stability"].startswith(f"not computed: on a system of {system.n} dofs") for r in on_arc
               if r["stable"] is None)


# ----------------------------------------------------------------------------- 2. the contact model's words

#: Newton's words, which a massless run must not use (file names aside: their stem is ``mode00_1ipp_…``).
NEWTON_WORDS = re.compile(r"impact|impuls|\d-ipp|\bipp\b", re.IGNORECASE)


def _strings(value, key=""):
    """Every string of a JSON document with its key, file names left out."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _strings(v, k)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v, key)
    elif isinstance(value, str) and key not in ("gif", "mp4", "pvd", "manifold", "source"):
        yield key, value


def test_massless_run_speaks_of_contact_phases(demo):
    report, log, summary = _texts(demo)
    prose = re.sub(r"`[^`]*`|\([^)]*\.(gif|png)\)", "", report)  # file names
    assert not NEWTON_WORDS.search(prose), NEWTON_WORDS.search(prose)
    assert "orbit with one contact phase per period, T = " in report
    assert "Search: contact phases per period [1]" in report and "| family | contact phases / period |" in report
    assert "Contact model: massless" in report and "no saltation matrices" in report
    # the search stage's own count line (bladecase/study/stages.py, not this change) still says "1-ipp"
    own = [line for line in log.splitlines() if not re.search(r"INFO massless \d+ \(\d+ dofs\): 1-ipp:", line)]
    assert not any(NEWTON_WORDS.search(line) for line in own), [x for x in own if NEWTON_WORDS.search(x)]
    assert "animated orbit with one contact phase per period T = " in log
    words = [(k, s) for k, s in _strings(summary) if NEWTON_WORDS.search(s)]
    assert not words, words
    entry = summary["files"]["animations"][0]
    assert "impulses" not in entry and "impact_times" not in entry
    assert entry["contact_momentum_ns"] and entry["verification"]["contact_phases"] == 1
    assert "impacts" not in entry["verification"]


def test_newton_run_keeps_its_words(newton):
    report, log, summary = _texts(newton)
    k = summary["files"]["animations"][0]["ipp"]
    assert f"{k}-ipp orbit, T = " in report and "impacts at t/T = " in report
    assert "Contact model: Newton's impact law" in report and "with saltation matrices" in report
    assert f"animated {k}-ipp orbit T = " in log and "impulses up to" in log
    assert summary["files"]["animations"][0]["verification"]["impacts"] == k


def test_figures_follow_the_contact_model(demo):
    from bladecase.post.forcing.plots import forced_response_plot
    from bladecase.post.plots import frequency_energy

    labels = frequency_energy(demo.families).axes[0].get_legend_handles_labels()[1]
    assert "1 contact phase / period (admissible)" in labels and not any("ipp" in x for x in labels)
    newton = bc.backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(6.0, 7.1, 12))
    assert "1 ipp (admissible)" in frequency_energy([newton]).axes[0].get_legend_handles_labels()[1]
    fig = forced_response_plot([1.0, 2.0], [1.0, 2.0], ["1/1", "2/1"], backbones=demo.families)
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert labels == ["nonsmooth mode, 1 contact phase / period (admissible arcs)", "1 contact phase / 1 period",
                      "2 contact phases / 1 period"]
    newton_labels = forced_response_plot([1.0], [1.0], ["2/1"]).axes[0].get_legend_handles_labels()[1]
    assert newton_labels == ["2 impacts / 1 period"]


#: The plate study with the massless contact model (4 modes), compared with 8 modes; its tip node against the casing.
MASSLESS_PLATE = absolute(PLATE).replace("[contact]\n", '[contact]\nmodel = "massless"\n').replace(
    'method = "modal"\nsize = 10', 'method = "massless"\nsize = 4').replace(
    "periods = [0.5, 0.9999]", "periods = [0.8, 1.001]") + "\n[output]\nformats = []\nframes = 4\nanimate = 1\n"


def test_massless_comparison_and_empty_search_speak_of_contact_phases(tmp_path):
    """A comparison of massless models has no impact mass to show; a massless search with nothing admissible does
    not advise Newton's remedies."""
    compared = run(loads(MASSLESS_PLATE.replace("size = 4", 'size = 4\ncompare = [{method = "massless", size = 8}]')
                         + "reference = false\n"), out=tmp_path / "compare", progress=False)
    report, log, summary = _texts(compared)
    assert "## Model comparison" in report and "| model | dofs | modes matched / checked | artefact modes | static " \
        "compliance kept |" in report
    prose = re.sub(r"`[^`]*`", "", report)
    assert not NEWTON_WORDS.search(prose), NEWTON_WORDS.search(prose)
    # the tip face of the plate barely moves along the casing normal in its first mode: nothing near T1
    face = run(loads(MASSLESS_PLATE.replace("[contact]\n", '[contact]\nface = "tip"\n')), out=tmp_path / "face",
               progress=False)
    report, log, _ = _texts(face)
    assert "**No orbit animated:** no family has an admissible arc in the search range" in report
    assert not NEWTON_WORDS.search(re.sub(r"`[^`]*`", "", report))
    assert "no admissible orbit to animate that survives in the reference model: widen [search] periods\n" in log


@pytest.fixture(scope="module")
def plate():
    """The plate study's Newton model (modal, 4 modes) and its massless counterpart."""
    from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced

    study = loads(absolute(PLATE).replace("size = 10", "size = 4"))
    model = build_model(study, build_mesh(study))
    reduced = build_reduced(study, model, build_contact(study, model))
    return reduced, reduce(reduced.model, reduced.contact, "massless", 4)


def test_massless_forcing_speaks_of_contact_phases(plate, tmp_path):
    from bladecase.post.report import forcing_report
    from bladecase.study.forcing.stage import forced_response

    _, massless = plate
    out = forced_response(massless, [], {"ratio": 0.03, "amplitude": 900.0, "frequencies": [0.96, 1.04],
                                         "points": 2, "periods": 100}, folder=tmp_path)
    out.pop("orbits")
    assert out["contact_model"] == "massless" and out["points"]["label"][0] == "1/1"
    lines = forcing_report(out, [{"label": "1/1", "frequency_hz": out["points"]["frequency_hz"][0], "sweep": "up",
                                  "return_error": 1e-9}])
    text = "\n".join(lines)
    assert "(contact phases/forcing periods)" in text and not NEWTON_WORDS.search(text), text


# ----------------------------------------------------------------------------- 3. forced.csv: one unit per column


def test_forced_csv_header_carries_each_unit_once(plate, tmp_path):
    from bladecase.study.forcing.stage import COLUMNS, forced_response

    newton, _ = plate
    out = forced_response(newton, [], {"ratio": 0.05, "amplitude": 5.0, "frequencies": [0.9, 1.1], "points": 2,
                                       "periods": 100}, folder=tmp_path)
    with open(tmp_path / "forced.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    header = rows[0]
    assert header == [name for name, _ in COLUMNS] == list(out["points"])
    assert not any("(" in h or " " in h for h in header), header
    for name, unit in COLUMNS:  # a quantity with a unit carries it once, as the name's suffix
        assert (unit == "") or name.endswith("_" + unit.lower()), (name, unit)
    assert "resimulated_contacts" in header and "frequency_hz" in header
    assert float(rows[2][header.index("frequency_hz")]) == pytest.approx(out["points"]["frequency_hz"][1],
                                                                         rel=1e-11)


# ----------------------------------------------------------------------------- 4. a face contact is a face


def test_face_contact_is_named_as_a_face(demo, newton):
    report, log, summary = _texts(demo)
    c = summary["contact"]
    n, centre = len(c["face_nodes"]), c["node_id"]
    assert c["face"] == "tip" and n > 1
    assert (f"contact: face 'tip' of {n} nodes (area-weighted mean of their normal displacements), centre node "
            f"{centre} at [") in log
    assert f"contact: node {centre} at" not in log
    assert f"- Face 'tip' of {n} nodes (area-weighted mean of their normal displacements), centre node {centre}" \
        in report
    _, newton_log, newton_summary = _texts(newton)
    assert f"contact: node {newton_summary['contact']['node_id']} at [" in newton_log
    assert "face" not in newton_summary["contact"]


# ----------------------------------------------------------------------------- 5. engineering quantities


def test_tip_and_contact_force_of_the_animated_orbit(demo):
    """Tip displacement against the reduced model's own expansion at 4000 instants, the contact force against
    λ = k_s (ŵᵀq − d) at 20000 instants of the contact phase, the casing's give λ/k against the face mean's
    excursion beyond the clearance, the contact fraction and momentum against the orbit's phases."""
    orbit, reduced, entry = _animated(demo)
    t = np.linspace(0.0, orbit.T, 4000, endpoint=False)
    u, _ = reduced.expand(orbit, t)  # (nodes, dim, t)
    size = np.linalg.norm(u[list(reduced.contact.nodes)], axis=1)
    assert entry["tip_amplitude_mm"] == pytest.approx(size.max() * 1e3, rel=1e-4)
    (c0, c1), = orbit.contact_intervals
    x, _ = orbit.state(np.linspace(c0, c1, 20000))
    s = reduced.system
    lam = s.kc * np.maximum(s.w @ x - s.gap, 0.0)
    assert entry["contact_force_n"] == pytest.approx(lam.max(), rel=1e-8)
    assert entry["casing_penetration_m"] == pytest.approx(lam.max() / 1e6, rel=1e-12)
    assert entry["casing_penetration_m"] == pytest.approx(entry["tip_excursion"]["mean_max_m"], rel=1e-3)
    assert entry["contact_fraction"] == pytest.approx((c1 - c0) / orbit.T, rel=1e-12)
    (momentum,) = entry["contact_momentum_ns"]
    assert 2 / np.pi * 0.9 * entry["contact_force_n"] * (c1 - c0) < momentum < entry["contact_force_n"] * (c1 - c0)
    report, log, _ = _texts(demo)
    words = (f"tip amplitude |u| up to {entry['tip_amplitude_mm']:.4g} mm (node {entry['tip_amplitude_node_id']}, "
             f"t/T = {entry['tip_amplitude_t_over_T']:.3f}); contact force up to {entry['contact_force_n']:.4g} N, "
             f"in contact {100 * entry['contact_fraction']:.3g} % of the period; the casing yields up to "
             f"{entry['casing_penetration_m'] * 1e6:.4g} µm (λ/k)")
    assert f"  - Tip and casing: {words}." in report and words in log


def test_engineering_ranges_of_the_admissible_arcs(demo):
    """Each arc's ranges are those of its orbits (ends included), computed the same way as an animated orbit's;
    the report's table prints them."""
    from bladecase.study.render import orbit_engineering

    _, reduced, _ = _animated(demo)
    fam, summary = demo.families[0], demo.summary["families"][0]
    report, _, _ = _texts(demo)
    for arc, a in zip(fam.arcs, summary["admissible_arcs"]):
        assert 2 <= a["engineering_orbits"] <= 16
        # read on the backbone: up to the last orbit below the resonance tongue (the demo's 8:1 with mode 3)
        below = [j for j in range(arc.start, arc.stop + 1) if 1 / fam.orbits[j].T <= a.get("backbone_f_hi", np.inf)]
        ends = [orbit_engineering(reduced, fam.orbits[j]) for j in (min(below), max(below))]
        for key, ranged in (("tip_amplitude_mm", "tip_amplitude_range_mm"),
                            ("contact_force_n", "contact_force_range_n"),
                            ("contact_fraction", "contact_fraction_range"),
                            ("casing_penetration_m", "casing_penetration_range_m")):
            lo, hi = a[ranged]
            assert lo <= hi and all(lo <= e[key] <= hi for e in ends), (key, lo, hi, ends)
        assert a["contact_fraction_range"][1] < 1 and a["contact_force_range_n"][1] > 0
        band = (f"{a['f_lo']:.4f} – {a['f_hi']:.4f}" if "tongue" not in a else
                f"{a['backbone_f_lo']:.4f} – {a['backbone_f_hi']:.4f} (backbone; to {a['f_hi']:.4f} in a tongue)")
        cells = (f"| 0 | {band} | {a['engineering_orbits']} | "
                 f"{a['tip_amplitude_range_mm'][0]:.4g} – "
                 f"{a['tip_amplitude_range_mm'][1]:.4g} | {a['contact_force_range_n'][0]:.4g} – "
                 f"{a['contact_force_range_n'][1]:.4g} |")
        assert cells in report
    assert "| family | admissible arc f (Hz) | orbits used | tip amplitude |u| (mm) | peak contact force (N) | in " \
           "contact (% of the period) | casing penetration (µm) |" in report
    assert json.dumps(demo.summary, allow_nan=False)


def test_contact_stiffnesses(demo):
    """k_c = 1/(w_cᵀK_cc⁻¹w_c) and its series value with the casing, and the blade's static stiffness
    1/(wᵀK⁻¹w), computed here from the FE model's K: in the summary, the log and the report."""
    _, reduced, _ = _animated(demo)
    model, contact = reduced.model, reduced.contact
    w = contact.w(model)
    c = np.flatnonzero(w)
    K = model.K.tocsc()
    kc = 1.0 / float(w[c] @ np.linalg.solve(K[c][:, c].toarray(), w[c]))
    ks = kc * 1e6 / (kc + 1e6)
    static = 1.0 / float(w @ spla.spsolve(K, w))
    s = demo.summary["contact"]
    assert s["model"] == "massless"
    assert s["contact_stiffness_n_per_m"] == pytest.approx(kc, rel=1e-9)
    assert s["series_stiffness_n_per_m"] == pytest.approx(ks, rel=1e-9)
    assert s["static_stiffness_n_per_m"] == pytest.approx(static, rel=1e-6)
    report, log, _ = _texts(demo)
    assert (f"contact stiffness: k_c = {kc:.4g} N/m (the contact dofs with the interior held, 1/(w_cᵀK_cc⁻¹w_c)); "
            f"casing 1e+06 N/m in series: k_s = {ks:.4g} N/m; the blade's static stiffness at the contact "
            f"1/(wᵀK⁻¹w) = {static:.4g} N/m") in log
    assert f"k = 1e+06 N/m in series with the contact's own stiffness k_c = {kc:.4g} N/m" in report
    assert f"the closed contact's stiffness is k_s = {ks:.4g} N/m" in report
    assert f"1/(wᵀK⁻¹w) = {static:.4g} N/m" in report


def test_newton_orbit_has_impulses_not_forces(newton):
    orbit, _, entry = _animated(newton)
    assert entry["contact_force_n"] is None and entry["contact_fraction"] == 0.0
    assert entry["contact_impulse_ns"] == max(orbit.impulses) > 0
    assert "casing_penetration_m" not in entry
    arcs = [a for f in newton.summary["families"] for a in f["admissible_arcs"]]
    assert arcs and all("contact_impulse_range_ns" in a and "contact_force_range_n" not in a for a in arcs)
    report, _, summary = _texts(newton)
    assert "largest impulse (N·s)" in report and "peak contact force" not in report
    assert f"impulses up to {entry['contact_impulse_ns']:.4g} N·s per impact" in report
    assert summary["contact"]["static_stiffness_n_per_m"] > 0 and "contact_stiffness_n_per_m" not in summary["contact"]
