"""The every-node family through internal resonances (``nodal_family(..., through_resonances=True)``).

The system: ``tests/test_nodes.py``'s 3-mass chain (masses 1, 1.5, 0.7; two coupled massless contacts at clearances
0.2 and 0.3, rigid casing). Its first mode's backbone (f₁ = 0.2110 Hz) hardens into a 3:1 internal resonance with
the third open-phase mode (0.7909 Hz) at 0.2659 Hz, 26 % above f₁: there the family turns into that mode for good
(its energy climbs at an almost constant frequency while the third mode takes the modal energy) and the family of
before stopped. The backbone goes on beyond it on a separate branch; the new family crosses to it. With masses
(2, 1.5, 0.7) the backbone meets a 2:1 resonance with the second mode at 0.2454 Hz beyond which no orbit carries
90 % of its energy in the first mode (the motion stays shared between the two): the family genuinely ends there.

The references are independent of the crossing: the exact event-driven simulator (``simulate_nodes``) for one
period, the complementarity of the contact forces sampled along the orbit, and the energy-stepped and
arclength families meeting on the same backbone beyond the tongue.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from bladecase.nsm.massless.nodal_modes import BACKBONE_SHARE, backbone_trend, nodal_family, resonance_ratio
from bladecase.nsm.massless.nodes import NodalSystem, simulate_nodes
from bladecase.post.nodal.report import backbone_rows, nodal_report


def chain(masses=(1.0, 1.5, 0.7)) -> NodalSystem:
    from test_nodes import chain as nodes_chain

    return nodes_chain(np.inf, masses)


def energy_norm(s: NodalSystem, x, v) -> float:
    return float(np.sqrt(v @ s.M @ v + x @ s.S @ x))


@pytest.fixture(scope="module")
def crossed():
    """The energy-stepped family through the 3:1 resonance, to 1.35 f₁ (measured 26 orbits, 0.5 s)."""
    s = chain()
    return s, nodal_family(s, 0, freq_ratio=1.35, through_resonances=True)


def test_without_crossing_the_family_ends_at_the_resonance_in_words_and_fields():
    """The behaviour of before (``through_resonances=False``, the default): the family stops in the 3:1 tongue, and
    says so — the mode, the ratio, that the place depends on the mesh, the backbone's trend below it."""
    fam = nodal_family(chain(), 0, freq_ratio=1.35)
    end = fam.end
    assert end["kind"] == "internal_resonance" and end["mode"] == 2 and end["ratio"] == "3:1"
    assert end["mode_frequency_hz"] == pytest.approx(0.790873, rel=1e-5)
    assert end["frequency_hz"] == pytest.approx(0.265923, rel=1e-4)          # measured 0.2659225
    assert end["mesh_dependent"] and end["crossing"] == "not crossed (through_resonances=False)"
    assert fam.frequency.max() < 0.266 and fam.frequency.max() / fam.linear_frequency < 1.35
    # the backbone's trend below the tongue, fitted on orbits at least 98 % in the first mode
    trend = end["trend"]
    assert trend["orbits"] == 3 and trend["frequency_hz"] < end["frequency_hz"]
    assert trend["df_dlnE_hz"] > 0 and trend["hz_per_doubling"] == pytest.approx(trend["df_dlnE_hz"] * np.log(2))
    assert trend["dE_df_j_per_hz"] == pytest.approx(trend["energy_j"] / trend["df_dlnE_hz"])
    for words in ("internal resonance at T = ", "open-phase mode 2", "3:1", "depends on the mesh",
                  "per doubling of the energy"):
        assert words in fam.stop
    assert fam.tongues[-1]["left"] == "end" and fam.tongues[-1]["ratio"] == "3:1"


def test_the_family_crosses_the_resonance_and_goes_on_along_the_backbone(crossed):
    s, fam = crossed
    (t,) = fam.tongues
    assert (t["mode"], t["ratio"], t["left"]) == (2, "3:1", "crossed")
    assert t["frequency_hz"] == pytest.approx(0.265923, rel=1e-4)
    assert t["least_share"] < 0.5 and t["to_frequency_hz"] > t["frequency_hz"]
    assert fam.landings == [t["landing"]] == [t["stop"] + 1]
    # the old family's end is now inside the tongue; beyond it the backbone, to the frequency asked for
    assert fam.end["kind"] == "frequency_ratio" and fam.frequency[-1] / fam.linear_frequency >= 1.35
    beyond = fam.orbits[t["landing"]:]
    assert len(beyond) >= 5                                            # measured 8, 0.2790 to 0.2854 Hz
    assert all(o.frequency > t["frequency_hz"] for o in beyond)
    assert all(o.modal_energy_share[0] >= BACKBONE_SHARE for o in beyond)
    assert np.all(np.diff([o.energy for o in beyond]) > 0)            # the energy grows along it again
    # the flags: on the backbone exactly outside the tongue
    on = fam.on_backbone
    assert not on[t["start"]:t["stop"] + 1].any() and on[:t["start"]].all() and on[t["landing"]:].all()
    assert np.array_equal(on, fam.shares >= BACKBONE_SHARE)
    # every orbit closes (the exact flow's fixed point)
    assert max(o.residual for o in fam.orbits) < 1e-12                # measured 7.3e-15


@pytest.mark.parametrize("past", [0, 1], ids=["landing", "next"])
def test_an_orbit_past_the_tongue_is_a_periodic_orbit_of_the_exact_simulator(crossed, past):
    """The orbit the crossing lands on and the next one, re-simulated for one period by ``simulate_nodes``; the
    contact forces sampled over the period solve the complementarity problem (admissible: no pull, no
    penetration of an open node)."""
    s, fam = crossed
    o = fam.orbits[fam.landings[0] + past]
    tr = simulate_nodes(s, o.x0, o.v0, o.T)
    error = energy_norm(s, tr.x_end - o.x0, tr.v_end - o.v0) / energy_norm(s, o.x0, o.v0)
    assert error < 1e-10                                               # measured 8.1e-16, 6.0e-16
    t = np.linspace(0.0, o.T, 2001)
    x, _ = tr.state(t)
    lam = s.forces(x)
    slack = s.gap[:, None] - s.W.T @ x + s.flexibility @ lam           # each node's gap (0 while it touches)
    scale = float(np.abs(s.gap).max())
    assert lam.min() >= 0 and slack.min() > -1e-12 * scale
    assert np.abs(lam * slack).max() < 1e-12 * scale * max(lam.max(), 1.0)
    assert lam.max() > 0 and o.touching.all()                          # both nodes touch beyond the tongue


def test_both_ways_along_cross_to_the_same_backbone(crossed):
    """Pseudo-arclength crosses too — first the thin 3:1 tongue of the second mode 0.9 % above f₁, where the
    arclength family of before stopped, then the third mode's — and meets the energy-stepped family beyond."""
    s, fam = crossed
    arc = nodal_family(s, 0, method="arclength", freq_ratio=1.35, through_resonances=True)
    assert [(t["mode"], t["ratio"], t["left"]) for t in arc.tongues] == [(1, "3:1", "crossed"), (2, "3:1", "crossed")]
    assert arc.tongues[0]["frequency_hz"] == pytest.approx(0.21303, rel=1e-4)   # 0.94 % above f₁
    assert max(o.residual for o in arc.orbits) < 1e-12                          # measured 2.9e-14
    lo = max(fam.frequency[fam.landings[-1]], arc.frequency[arc.landings[-1]])
    f = 0.5 * (lo + min(fam.frequency[-1], arc.frequency[-1]))                   # a period on both, beyond
    (a,) = fam.at_period(1 / f, backbone=True)
    (b,) = arc.at_period(1 / f, backbone=True)
    assert a.energy == pytest.approx(b.energy, rel=1e-8)                         # measured 1.4e-14


def test_a_resonance_that_cannot_be_crossed_ends_the_family_with_its_mode_and_ratio():
    fam = nodal_family(chain((2.0, 1.5, 0.7)), 0, freq_ratio=1.5, through_resonances=True)
    end = fam.end
    assert end["kind"] == "internal_resonance" and (end["mode"], end["ratio"]) == (1, "2:1")
    assert end["frequency_hz"] == pytest.approx(0.24543, rel=1e-4)              # measured 0.245429 Hz
    assert end["crossing"].startswith("not crossed: no orbit on the backbone")
    assert end["trend"]["df_dlnE_hz"] > 0 and end["trend"]["frequency_hz"] < end["frequency_hz"]
    assert fam.tongues[-1]["left"] == "end" and not fam.landings
    assert "2:1" in fam.stop and "depends on the mesh" in fam.stop
    assert fam.frequency.max() / fam.linear_frequency < 1.5


def test_records_and_the_family_across_a_jump(crossed):
    _, fam = crossed
    data = json.loads(json.dumps(fam.to_dict()))
    assert data["end"]["kind"] == "frequency_ratio" and data["tongues"][0]["ratio"] == "3:1"
    assert data["on_backbone"] == fam.on_backbone.tolist() and data["backbone_share"] == BACKBONE_SHARE
    assert "1 tongue(s), 1 crossed" in repr(fam)
    # an energy met inside the tongue and again beyond it: never interpolated across the jump
    i = fam.landings[0]
    E = 0.5 * (fam.energy[i] + fam.energy[i - 1])
    assert len(fam.at_energy(E)) == 2                                 # one in the tongue, one beyond
    (o,) = fam.at_energy(E, backbone=True)
    assert o.modal_energy_share[0] >= BACKBONE_SHARE and o.frequency > fam.tongues[0]["frequency_hz"]
    # the trend at the family's end is its last stretch, beyond the tongue; the cleanest (>= 98 % in the first
    # mode) stretch of the whole family is the one below it
    t = fam.tongues[0]
    trend = fam.end["trend"]
    assert trend["frequency_hz"] == fam.frequency[-1] and trend["frequency_range_hz"][0] > t["to_frequency_hz"] - 1e-12
    below = backbone_trend(fam.orbits, fam.shares)
    assert below["frequency_hz"] < t["frequency_hz"] and below["df_dlnE_hz"] > 0


def test_resonance_ratios():
    assert resonance_ratio(7.9924) == (8, 1) and resonance_ratio(3.9997) == (4, 1)
    assert resonance_ratio(11.999) == (12, 1) and resonance_ratio(7.49) == (15, 2)


def _row(energy, on=None):
    row = {"energy_j": energy, "max_pressure_mpa": 0.5 + energy, "total_force_n": 10.0 * energy, "loaded_area_mm2": 5.0,
           "peak_loaded_area_mm2": 6.0, "load_centre": 0.5, "load_location": "mid-chord", "max_penetration_mm": 0.01,
           "max_contact_fraction": 0.2, "nodes_touching": 3}
    return row if on is None else dict(row, on_backbone=on)


def test_the_report_says_where_the_family_ends_what_it_crossed_and_reads_the_backbone_only():
    end = {"kind": "internal_resonance", "frequency_hz": 216.5053, "energy_j": 0.033, "mode": 4,
           "mode_frequency_hz": 2597.85, "ratio": "12:1", "ratio_value": 11.999, "share": 0.44, "other_share": 0.55,
           "crossing": "not crossed: …", "mesh_dependent": True,
           "trend": {"frequency_hz": 214.0, "energy_j": 0.0101, "df_dlnE_hz": 5.4, "hz_per_doubling": 3.74,
                     "frequency_range_hz": [211.27, 214.0]}}
    tongues = [{"start": 2, "stop": 3, "mode": 1, "mode_frequency_hz": 863.53, "ratio": "4:1", "frequency_hz": 215.898,
                "left": "crossed", "to_frequency_hz": 216.476}, {"start": 5, "stop": 5, "mode": 4,
                "mode_frequency_hz": 2597.85, "ratio": "12:1", "frequency_hz": 216.505, "left": "end"}]
    section = {"contact_nodes": 39, "reduced_dofs": 8, "size": 8, "stop": "internal resonance …",
               "frequency_range_hz": [210.17, 216.5], "stable_fraction": 1.0, "first_touch_nodes": ["3"],
               "most_nodes_touching": 30, "face_area_mm2": 103.0, "end": end, "tongues": tongues,
               "rows": [_row(0.003), _row(0.01), _row(0.02), _row(0.035), _row(0.015), _row(0.033)]}
    for with_flags in (False, True):
        if with_flags:   # a row's own flag wins over the tongue ranges
            section["rows"] = [dict(r, on_backbone=i not in (2, 3, 5)) for i, r in enumerate(section["rows"])]
        assert [r["energy_j"] for r in backbone_rows(section)] == [0.003, 0.01, 0.015]
        text = "\n".join(nodal_report(section))
        assert "at the top (0.015 J)" in text                                  # not the tongue's 0.035 J
        assert ("The family ends in an internal resonance at 216.51 Hz: its motion turns into the 5th mode of the "
                "blade with the contacts open (2598 Hz, 12:1") in text
        assert "depends on the mesh" in text and "rises 3.7 Hz per doubling of the energy" in text
        assert ("On the way it passes 1 internal resonance: with the 2nd open-contact mode (863.5 Hz) at 4:1 near "
                "215.9 Hz, crossed to the backbone at 216.48 Hz") in text
    # a family that ends otherwise: its stop, as before
    plain = dict(section, end={"kind": "energy_max"}, tongues=[], stop="energy 0.07 J reached")
    assert "- The family ends: energy 0.07 J reached." in nodal_report(plain)
