"""The small-displacement limit on the every-node family (``[contact] points = "nodes"``).

Checked on the massless plate strip with every tip node a contact (5 nodes, span 100.5 mm), its family followed
with no face-mean energy to stop at (as when the face mean has no admissible arc: the family then runs on to a
frequency ratio of 1/0.95), a contact node's amplitude growing 0.100 → 0.161 mm: with ``amplitude_limit = 0.0012``
(0.1206 mm) the family's figures stop at the last orbit within the limit — every orbit kept is within it and the
first dropped is beyond, by an independent measure (the orbit expanded onto the FE model's free dofs, the normal
displacement of each contact node sampled at 1024 instants) —; ``nodal_modes.csv``, ``summary.json`` and the report
say where and why, and how far the continuation went on; the sampled amplitude agrees with 2048 samples to 1e-6;
the default limit (5 %, 5 mm) leaves the family whole; a tongue reaching past the cut is marked ``cut``.
"""

from __future__ import annotations

import csv
import dataclasses

import numpy as np
import pytest
from test_convergence import STRIP

from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.post.nodal.report import nodal_report
from bladecase.reduction.nodes import nodal_model
from bladecase.study.nodal.stage import nodal_stage, node_amplitude
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model
from bladecase.study.validity import blade_span, cut_family, first_beyond

LIMIT = 0.0012


def fe_amplitude(nodal, orbit, samples: int = 1024) -> float:
    """The largest |normal displacement| of a contact node over the orbit, on the FE model's free dofs."""
    x, _ = orbit.state(np.linspace(0.0, orbit.T, samples, endpoint=False))
    return float(np.abs(nodal.normal_map @ nodal.free_dofs(x)).max())


@pytest.fixture(scope="module")
def strip(tmp_path_factory):
    text = STRIP.replace('model = "massless"', 'model = "massless"\npoints = "nodes"')
    study = loads(text.replace("scan = 8}", f"scan = 8, amplitude_limit = {LIMIT}}}"))
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    out = tmp_path_factory.mktemp("limit")
    section = nodal_stage(study, model, contact, [], None, folder=out, figures=False)
    nodal = nodal_model(model, contact, 8, residual=True)
    family = nodal_family(nodal.system, 0, through_resonances=True, freq_ratio=1 / 0.95)  # the same, uncut
    return section, out, model, nodal, family


def test_the_family_stops_at_the_limit(strip):
    section, out, model, nodal, family = strip
    v = section["validity"]
    assert v["span_m"] == pytest.approx(blade_span(model)) and v["limit_m"] == pytest.approx(LIMIT * v["span_m"])
    k = v["cut"]["index"]
    assert 2 <= k < len(family.orbits) and section["orbits"] == k == len(section["rows"])
    assert [r["frequency_hz"] for r in section["rows"]] == pytest.approx([o.frequency for o in family.orbits[:k]],
                                                                        rel=1e-9)
    fe = [fe_amplitude(nodal, o) for o in family.orbits[:k + 1]]
    assert max(fe[:k]) <= v["limit_m"] < fe[k]  # independently: every kept orbit within, the first dropped beyond
    assert v["cut"]["tip_amplitude_beyond_mm"] == pytest.approx(fe[k] * 1e3, rel=1e-4)
    assert section["energy_range_j"][1] == pytest.approx(family.orbits[k - 1].energy, rel=1e-9)
    assert section["energy_range_j"][1] < v["cut"]["energy_beyond_j"] <= v["cut"]["continuation_top_energy_j"]
    assert section["end"]["kind"] == "amplitude_limit" and "small-displacement limit" in section["stop"]
    # the continuation stops at the first orbit beyond the limit: nothing past it is computed
    assert v["cut"]["continuation_stop"] == "beyond the small-displacement limit" and v["cut"]["orbits_beyond"] == 1
    assert v["cut"]["continuation_top_energy_j"] == v["cut"]["energy_beyond_j"]
    rows = list(csv.DictReader(open(out / "nodal_modes.csv")))
    assert len(rows) == k


def test_the_report_says_where_and_why(strip):
    section = strip[0]
    c = section["validity"]["cut"]
    text = "\n".join(nodal_report(section))
    assert "**The family is cut at the small-displacement limit**" in text
    assert f"at {c['frequency_beyond_hz']:.5g} Hz" in text and "`[search] amplitude_limit`" in text
    assert "The continuation stops at that orbit: nothing beyond the limit is computed." in text


def test_the_amplitude_and_the_default_limit(strip):
    _, _, model, nodal, family = strip
    top = family.orbits[-1]
    assert node_amplitude(nodal, top) == pytest.approx(node_amplitude(nodal, top, 2048), rel=1e-6)
    assert node_amplitude(nodal, top) >= top.max_tip
    assert first_beyond(family.orbits, lambda o: node_amplitude(nodal, o), 0.05 * blade_span(model))[0] is None


def test_a_tongue_past_the_cut_is_marked(strip):
    family = strip[4]
    fake = dataclasses.replace(family, tongues=({"start": 2, "stop": 5, "left": "crossed", "landing": 6,
                                                 "to_frequency_hz": 1.0}, {"start": 7, "stop": 7, "left": "open"}))
    cut = cut_family(fake, 4, "cut", {"kind": "amplitude_limit"})
    assert len(cut.orbits) == 4 and cut.tongues == ({"start": 2, "stop": 3, "left": "cut"},)
    assert cut.on_backbone.tolist() == [True, True, False, False]
