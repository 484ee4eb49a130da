"""The held-out check of a worn profile's lobes against the tip's vibration frequency
(bladecase.nsm.massless.wear_lobes, bladecase.nsm.massless.wear.harmonic_lobes): the lobes of the coating worn over
the same last revolutions as the frequency is read on, a profile's lobe count, and the "undefined" verdicts."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.nodes import NodalSystem
from bladecase.nsm.massless.wear import Abradable, WearProfile, harmonic_lobes, pass_tip
from bladecase.nsm.massless.wear_lobes import dominant_ratio, lobe_check
from bladecase.nsm.massless.wear_rub import wear_rub

CELLS, PER_TURN = 90, 400
THETA = (np.arange(CELLS) + 0.5) * 2 * np.pi / CELLS


def _worn(paths) -> tuple[np.ndarray, np.ndarray]:
    """A rigid tip passed over a 90-cell coating once a revolution along ``r(θ) = Σ a cos(kθ + p)`` for each
    revolution's ``[(a, k, p), …]`` (its vibration at k × the rotation frequency seen round the casing): the profile
    after each revolution and the tip's displacement over each revolution (the same path, over time)."""
    c = Abradable(thickness=1e-3, yield_pressure=1e6, stiffness=np.inf, cells=CELLS, radius=0.3, width=0.01)
    p = WearProfile.new(c)
    t = np.arange(PER_TURN) / PER_TURN                       # a revolution, in revolutions
    depths, tip = [], []
    for rev, terms in enumerate(paths):
        r = sum(a * np.cos(2 * np.pi * k * (rev + t) + ph) for a, k, ph in terms)
        p, _ = pass_tip(p, 2 * np.pi * t, r)
        depths.append(p.depth.copy())
        tip.append(r)
    return np.array(depths), np.array(tip)


def test_the_lobe_count_is_the_strongest_harmonic_not_a_weaker_neighbour():
    """Harmonics 10 (1), 11 (0.84) and 9 (0.70): the profile has 10 lobes, and 11 is its rival (no one lobe count).
    Taking the lowest harmonic within half of the strongest read 9: a neighbour, not a fundamental."""
    d = 1.0 + np.cos(10 * THETA) + 0.84 * np.cos(11 * THETA + 0.3) + 0.70 * np.cos(9 * THETA + 1.1)
    assert harmonic_lobes(d) == (10, 11)
    c = Abradable(1e-3, 1e6, np.inf, cells=CELLS, radius=0.3, width=0.01)
    assert WearProfile(c, 1e-5 * d).lobes() == 10
    # one clear count: 10, with its rivals below half of it
    assert harmonic_lobes(1.0 + np.cos(10 * THETA) + 0.45 * np.cos(11 * THETA)) == (10, 0)


def test_peaked_lobes_and_wear_on_part_of_the_casing_keep_their_count():
    """Lobes worn only at their tips (overtones 2N, 3N …) are N lobes; 9 lobes worn deeper on one side of the casing
    (a strong harmonic 1: the envelope) are 9 lobes, not 1."""
    peaked = np.maximum(np.cos(6 * THETA) - 0.8, 0.0)
    amp = np.abs(np.fft.rfft(peaked - peaked.mean()))
    assert amp[12] > 0.5 * amp[6]                                   # the overtone is strong: the test can fail
    assert harmonic_lobes(peaked) == (6, 0)
    side = (1 + np.cos(9 * THETA)) * (1 + 0.8 * np.cos(THETA))
    amp = np.abs(np.fft.rfft(side - side.mean()))
    assert amp[1] > 0.5 * amp[9]                                    # the envelope is strong
    assert harmonic_lobes(side) == (9, 0)
    overtone = 1.0 + 0.6 * np.cos(6 * THETA) + np.cos(12 * THETA)     # the overtone the strongest: still 6 lobes
    assert harmonic_lobes(overtone) == (6, 0) and harmonic_lobes(1.0 + 0.4 * np.cos(6 * THETA) + np.cos(12 * THETA)) \
        == (12, 0)
    assert harmonic_lobes(np.zeros(CELLS)) == (0, 0) and harmonic_lobes(np.full(CELLS, 3e-6)) == (0, 0)


def test_the_lobes_are_read_on_the_wear_of_the_same_revolutions_as_the_frequency():
    """A transient at 10 × f_rot (three revolutions, its peaks 20 µm into the coating), then the tip vibrates at
    8 × f_rot, its peaks reaching 5 to 17 µm: the profile since rest has 10 lobes, the coating removed over the last
    four revolutions 8, as the frequency read over them. Read on the whole profile the check would say they
    differ."""
    paths = [[(80e-6, 10, 0.0), (-60e-6, 0, 0.0)]] * 3 + [[(65e-6 + 1.5e-6 * k, 8, 0.4), (-60e-6, 0, 0.0)]
                                                          for k in range(9)]
    depths, tip = _worn(paths)
    assert depths[2].max() == pytest.approx(20e-6) and depths[-1].max() == pytest.approx(20e-6)
    assert harmonic_lobes(depths[-1])[0] == 10                       # the whole profile: the transient's lobes
    c = lobe_check(depths, tip, PER_TURN)
    assert (c.verdict, c.window, c.lobes, c.expected) == ("agree", 4, 8, 8)
    assert c.ratio == pytest.approx(8.0, abs=1e-3) and c.reason == ""
    # the same check over the whole run reads the transient: they differ
    assert lobe_check(depths, tip, PER_TURN, window=12).lobes == 10


def test_several_frequencies_of_the_tip_leave_the_lobes_undefined():
    """The tip at 8 × f_rot and 10.5 × f_rot (0.7 of it): no one frequency to compare, whatever the profile; at 0.3
    of it the frequency is 8."""
    n = 12 * PER_TURN
    t = np.arange(n) / PER_TURN
    depths, _ = _worn([[(10e-6 * (k + 1), 8, 0.0)] for k in range(12)])
    for share, verdict in ((0.7, "undefined"), (0.3, "agree")):
        tip = (np.cos(2 * np.pi * 8 * t) + share * np.cos(2 * np.pi * 10.5 * t)).reshape(12, PER_TURN)
        c = lobe_check(depths, tip, PER_TURN)
        assert c.verdict == verdict and c.second_share == pytest.approx(share, abs=0.05)
    assert "several frequencies" in c.reason or c.reason == ""
    assert c.second == pytest.approx(10.5, abs=0.01)


def test_a_vibration_far_from_an_engine_order_smears_the_wear():
    """At 8.3 × f_rot the lobes drift by 1.2 lobe lengths over four revolutions: undefined, the coating worn over
    them smeared (its 8-lobe harmonic a fraction of a locked vibration's); at 8.1 × f_rot (0.4 lobe length) the
    check holds."""
    locked = _worn([[(10e-6 * (k + 1), 8.0, 0.0)] for k in range(12)])[0]
    for ratio, verdict in ((8.3, "undefined"), (8.1, "agree")):
        depths, tip = _worn([[(10e-6 * (k + 1), ratio, 0.0)] for k in range(12)])
        c = lobe_check(depths, tip, PER_TURN)
        assert c.verdict == verdict and c.ratio == pytest.approx(ratio, abs=0.02)
    assert "drift by 1.2 lobe lengths" in lobe_check(*_worn([[(1e-5 * (k + 1), 8.3, 0)] for k in range(12)]),
                                                     PER_TURN).reason
    # the smearing, measured on the profiles: the 8-lobe harmonic of the last four revolutions' wear
    smeared = _worn([[(10e-6 * (k + 1), 8.3, 0.0)] for k in range(12)])[0]
    h8 = [np.abs(np.fft.rfft(d[-1] - d[-5]))[8] for d in (locked, smeared)]
    assert h8[1] < 0.5 * h8[0]


def test_no_wear_in_the_window_and_bad_input():
    depths, tip = _worn([[(30e-6, 8, 0.0)]] + [[(10e-6, 8, 0.0)]] * 5)         # worn once, then never deeper
    c = lobe_check(depths, tip, PER_TURN)  # read on the revolution that wore it: the vibration that made the lobes
    assert (c.verdict, c.last, c.window, c.lobes, c.expected) == ("agree", 1, 1, 8, 8)
    c = lobe_check(np.zeros_like(depths), tip, PER_TURN)
    assert c.verdict == "undefined" and c.reason == "no coating removed in any revolution" and c.last == 0
    grown = _worn([[(30e-6, 8, 0.0)]] + [[(10e-6, 8, 0.0)]] * 2 + [[(40e-6, 8, 0.0)]] + [[(1e-6, 8, 0.0)]] * 2)
    assert lobe_check(*grown, PER_TURN).last == 4  # the window ends with the last revolution that wore
    with pytest.raises(ValueError, match="window must be an integer >= 1"):
        lobe_check(depths, tip, PER_TURN, window=0)
    with pytest.raises(ValueError, match=r"one row per revolution and tip 400 samples a row, got \(6, 90\) and"):
        lobe_check(depths, tip[:, :300], PER_TURN)


def test_the_frequency_ignores_the_drift_of_the_tips_mean_position():
    """A tip opening the coating drifts outwards by 20 times its vibration's amplitude over four revolutions: the
    frequency is the vibration's, to 5e-3 of the rotation frequency between its bins (a bin is a quarter of it;
    Hann window, parabola through the peak: 4.0e-3 measured at worst over 6 to 12), and no other line shows."""
    t = np.arange(4 * PER_TURN) / PER_TURN
    for f in np.linspace(6.0, 12.0, 25):
        r, second, share = dominant_ratio(20.0 * t / 4 + np.cos(2 * np.pi * f * t + 0.3), PER_TURN)
        assert r == pytest.approx(f, abs=5e-3) and share < 0.05


def test_the_coupled_wear_carries_the_check_of_its_last_revolutions():
    """A two-node system in a three-lobe casing: its check is the one recomputed from its profiles and its tip
    displacement, and they agree (3 lobes)."""
    s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]), gap=[1.0, 1.0],
                    casing=[4.0, 4.0])
    coating = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=0.7)
    w = wear_rub(s, coating, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=6, areas=[1.0, 1.0],
                 coupling="staggered")
    assert w.tip.shape == (6, w.samples_per_turn)
    again = lobe_check(w.depths, w.tip, w.samples_per_turn)
    assert w.check == again and (w.check.verdict, w.check.lobes, w.check.expected) == ("agree", 3, 3)
