"""The small-displacement limit: admissible arcs are cut where the tip moves more than ``[search] amplitude_limit``
× the span, and the report and verdict say where and why.

Checked on the massless plate strip (span 0.1 m, its backbone's tip amplitude 0.10 → 0.16 mm): the span; a limit
inside the arc cuts it at the last orbit within it (every orbit left on the arc is within the limit, re-measured
independently on the mesh); a limit below grazing leaves no arc, and the verdict says the orbits exist but beyond
the limit, not that none is admissible; the default limit (5 %) leaves the arc whole.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_convergence import STRIP

from bladecase.post.report import report
from bladecase.study import run
from bladecase.study.render import tip_amplitude
from bladecase.study.schema import StudyError, loads
from bladecase.study.stages import build_mesh, build_model
from bladecase.study.validity import blade_span


def _study(limit: float | None):
    extra = "" if limit is None else f", amplitude_limit = {limit}"
    return loads(STRIP.replace("scan = 8}", f"scan = 8{extra}}}"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("validity")
    return {lim: run(_study(lim), out / str(lim), progress=False) for lim in (None, 0.0012, 0.0005)}


def test_the_span_is_root_to_farthest_node():
    study = _study(None)
    model = build_model(study, build_mesh(study))
    assert blade_span(model) == pytest.approx(np.hypot(0.1, 0.01), rel=1e-12)  # root centre to a tip corner


def test_a_limit_inside_the_arc_cuts_it_there(runs):
    whole, cut = runs[None], runs[0.0012]
    assert whole.summary["validity"]["cuts"] == [] and whole.summary["validity"]["limit_m"] == pytest.approx(
        0.05 * np.hypot(0.1, 0.01))
    (a_whole,) = whole.summary["families"][0]["admissible_arcs"]
    (a_cut,) = cut.summary["families"][0]["admissible_arcs"]
    v = cut.summary["validity"]
    assert v["limit_m"] == pytest.approx(0.0012 * np.hypot(0.1, 0.01)) and len(v["cuts"]) == 1
    c = v["cuts"][0]
    assert c["tip_amplitude_cut"] <= v["limit_m"] < c["tip_amplitude_beyond"]
    assert a_cut["f_lo"] == pytest.approx(a_whole["f_lo"]) and a_cut["f_hi"] < a_whole["f_hi"]
    assert a_cut["f_hi"] == pytest.approx(1 / c["T_cut"], rel=1e-12)
    # every orbit left on the arc is within the limit, measured again on the mesh
    fam = cut.families[0]
    reduced = next(iter(cut.models.values())).reduced
    arc = fam.arcs[0]
    amps = [tip_amplitude(reduced, fam.orbits[j]) for j in range(arc.start, arc.stop + 1) if fam.orbits[j].admissible]
    assert max(amps) <= v["limit_m"] and len(amps) >= 2
    text = report(cut.summary)
    assert "**Cut at the small-displacement limit:**" in text and f"{1 / c['T_cut']:.6g} Hz" in text
    assert "cut_at_amplitude_limit" in cut.summary["verdict"]["reasons"]
    assert "The arcs end where the tip moves more than" in cut.summary["verdict"]["trust"]


def test_a_limit_below_grazing_leaves_no_arc_and_says_why(runs):
    s = runs[0.0005].summary
    assert all(not f["admissible_arcs"] for f in s["families"])
    v = s["verdict"]
    assert v["found"].startswith("No admissible nonsmooth mode within the small-displacement limit")
    assert "none of its" not in v["found"]  # the orbits are admissible, only beyond the limit
    assert "no_reason_in_data" not in v["reasons"] and "Every admissible orbit found moves the tip" in v["next"]


def test_the_limit_is_a_fraction_of_the_span():
    for bad in (0, -0.1, 1.5):
        with pytest.raises(StudyError, match=r"\[search\] amplitude_limit: must be in \(0, 1\]"):
            _study(bad)
