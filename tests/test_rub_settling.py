"""A rub speed that has not settled runs on, the same simulation continued, up to [rub] max_revolutions; one that
never settles is characterised (periodic over another period, transient, quasi-periodic, irregular); each speed is
also given over the crossing speed of mode 1 with the casing's lobes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from bladecase.nsm import Damping
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, Rub, simulate_nodes
from bladecase.nsm.massless.rub import _peaks, rub_response
from bladecase.post.rub.report import rub_report
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


def characterise(*args, **kwargs):
    from bladecase.nsm.massless.rub import characterise

    return characterise(*args, **kwargs)


def crossing_speed(*args, **kwargs):
    from bladecase.study.rub.stage import crossing_speed

    return crossing_speed(*args, **kwargs)


def two_nodes() -> NodalSystem:
    """The 2-dof, 2-contact system of ``bladecase.nsm.massless.rub``'s example."""
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[4.0, 4.0])


def one_node() -> NodalSystem:
    """One mode (1 rad/s) and one stiff contact (20 N/m) 1 m from its casing."""
    return NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[0.05]]), gap=[1.0], casing=[1e9])


# ----------------------------------------------------------------------------- (a) runs on until it settles


def test_a_speed_that_settles_late_runs_on_from_where_it_stopped():
    s, damping, speed = two_nodes(), Damping(zeta=0.02), 0.5
    args = (s, speed, 3, 1.2, [0.0, 0.3], damping)
    short = rub_response(*args, revolutions=6, window=3, max_revolutions=6)          # today's behaviour: no run-on
    assert not short.settled and short.revolutions_run == 6 and short.response != "settled"
    r = rub_response(*args, revolutions=6, window=3, max_revolutions=60)
    assert r.settled and r.response == "settled" and r.period == 1
    assert 6 < r.revolutions_run <= 60 and (r.revolutions_run - 6) % 3 == 0 and r.change <= 0.02
    assert r.read_revolutions == 3 and r.max_revolutions == 60
    # the same simulation continued, not restarted: one run from rest over as many turns gives the same figures
    fl = NodalFlight(s, damping, Rub(3, 1.2, speed, [0.0, 0.3]))
    turn = 2 * np.pi / speed
    whole = simulate_nodes(s, np.zeros(2), np.zeros(2), r.revolutions_run * turn, flight=fl)
    end = whole.t_end
    samples = 3 * 3 * int(np.ceil(max(24 * 3, int(np.ceil(24 * s.modes[0][0] / speed)) * 4) / 3)) + 1
    u, lam, _, _ = _peaks(whole, fl, end - 3 * turn, end, samples)
    np.testing.assert_allclose(r.peak_displacement, u, rtol=1e-8)
    np.testing.assert_allclose(r.peak_force, lam, rtol=1e-8)
    np.testing.assert_allclose(r.contact_fraction, whole.contact_time(end - 3 * turn, end) / (3 * turn), atol=1e-9)
    assert r.switches == whole.switch_times.size


def test_the_report_says_which_speeds_ran_on():
    r = rub_response(two_nodes(), 0.5, 3, 1.2, [0.0, 0.3], Damping(zeta=0.02), revolutions=6, window=3,
                     max_revolutions=60)
    row = {"speed": 4.77, "speed_rad_s": 0.5, "speed_ratio": None,
           "tip_normal_displacement_mm": 1e3 * r.tip_displacement,
           "max_pressure_mpa": 1.0, "total_force_n": r.total_force, "loaded_area_mm2": 1.0,
           "peak_loaded_area_mm2": 1.0, "load_centre": 0.5, "load_location": "mid-chord",
           "max_node_force_n": float(r.peak_force.max()), "contact_fraction": float(r.contact_fraction.max()),
           "penetration_mm": 0.0, "nodes_touching": len(r.touching), "switches": r.switches, "settled": r.settled,
           "response": r.response, "revolutions_run": r.revolutions_run}
    section = {"speed_unit": "rpm", "lobes": 3, "amplitude_m": 1.2, "revolutions": 6, "window": 3,
               "max_revolutions": 60, "damping": {"ratio": 0.02}, "nodes": [0, 1], "rows": [row],
               "worst": {**row, "touching_nodes": [0, 1], "touching_along_tip": None}, "unsettled_speeds": [],
               "characterised": [{"speed": 4.77, "response": r.response, "settled": r.settled,
                                  "revolutions_run": r.revolutions_run, "read_revolutions": r.read_revolutions,
                                  "change": r.change}],
               "model": {}}
    text = "\n".join(rub_report(section))
    assert (f"1 of 1 speeds had not settled after 6 revolutions and ran on until they did ({r.revolutions_run}–"
            f"{r.revolutions_run} revolutions, of at most 60)") in text
    assert "Not settled" not in text


@pytest.mark.parametrize("rub, match", [
    ("max_revolutions = 7", r"\[rub\] max_revolutions: at least revolutions = 8"),
    ("max_revolutions = 0", r"\[rub\] max_revolutions"),
])
def test_the_cap_is_checked(rub, match):
    from test_rub_study import CASING, RUB, _study

    with pytest.raises(StudyError, match=match):
        loads(_study(CASING, RUB.replace("max_revolutions = 8", rub)), source="<rub>")


def test_the_cap_defaults_to_ten_times_the_revolutions():
    from test_rub_study import CASING, RUB, _study

    from bladecase.study.rub.stage import max_revolutions

    study = loads(_study(CASING, RUB.replace("max_revolutions = 8\n", "")), source="<rub>")
    assert study["rub"]["max_revolutions"] is None and max_revolutions(study["rub"]) == 80


# ----------------------------------------------------------------------------- (b) what a response is


K = np.arange(360)


def test_a_period_three_return_map_is_periodic_3():
    rng = np.random.default_rng(3)
    pattern = rng.standard_normal((3, 4))
    c = characterise(pattern[K % 3] + 1e-5 * rng.standard_normal((K.size, 4)))
    assert (c.kind, c.period, c.label) == ("periodic", 3, "periodic-3") and c.error < 1e-3


def test_a_two_tone_signal_is_quasi_periodic():
    """A two-tone signal, once per period of the first tone: the second (√2 times faster) turns the sampled state
    by √2 − 1 of a cycle per sample, for ever without repeating."""
    t = K.astype(float)
    x = np.cos(2 * np.pi * t) + 0.4 * np.cos(2 * np.pi * np.sqrt(2) * t + 0.3)
    v = -np.sin(2 * np.pi * t) - 0.4 * np.sqrt(2) * np.sin(2 * np.pi * np.sqrt(2) * t + 0.3)
    c = characterise(np.c_[x, v])
    assert c.label == "quasi-periodic" and c.period is None and abs(c.k) < 0.2
    assert c.rotation == pytest.approx(np.sqrt(2) - 1, abs=2 / K.size)


def test_a_random_signal_is_irregular():
    c = characterise(np.random.default_rng(7).standard_normal((K.size, 3)))
    assert c.label == "irregular" and c.k > 0.8


def test_a_chaotic_map_is_irregular_and_a_decaying_one_transient():
    x = np.empty(K.size)
    x[0] = 0.3
    for i in range(1, K.size):        # the logistic map at r = 3.9: chaotic
        x[i] = 3.9 * x[i - 1] * (1 - x[i - 1])
    assert characterise(np.c_[x[1:], x[:-1]]).label == "irregular"
    c = characterise(np.c_[1 + 0.5 * np.exp(-K / 60) * np.cos(0.9 * K), 0.5 * np.exp(-K / 60) * np.sin(0.9 * K)],
                     lag=30)
    assert c.label == "transient" and c.decay == pytest.approx(np.exp(-30 / 60), rel=0.05)


def test_a_sub_harmonic_rub_is_periodic_over_three_revolutions():
    """One mode touched by a casing with one lobe turning at 5.1 rad/s: the blade meets the lobe once every 3
    revolutions. The response is read over a whole number of its periods (3 revolutions: the window is 5)."""
    s, damping, speed = one_node(), Damping(zeta=0.05), 5.1
    r = rub_response(s, speed, 1, 1.5, [0.0], damping, revolutions=20, window=5, max_revolutions=100)
    assert (r.response, r.period, r.settled) == ("periodic-3", 3, True)
    assert r.read_revolutions == 3 and r.revolutions_run <= 100
    # independently: a long run from rest, sampled once per revolution, repeats every 3 revolutions and not every 1
    from bladecase.nsm.massless.rub import _strobe

    fl = NodalFlight(s, damping, Rub(1, 1.5, speed, [0.0]))
    turn = 2 * np.pi / speed
    tr = simulate_nodes(s, [0.0], [0.0], 150 * turn, flight=fl)
    y = _strobe(tr, fl, turn, 150)[-30:]
    size = np.linalg.norm(y, axis=1).max()
    assert np.linalg.norm(y[3:] - y[:-3], axis=1).max() < 1e-3 * size < np.linalg.norm(y[1:] - y[:-1], axis=1).min()
    # its figures are the peaks over a period: those of the long run's last 3 revolutions
    x, _, lam = tr.sample(np.linspace(tr.t_end - 3 * turn, tr.t_end, 6001))
    assert r.peak_force.max() == pytest.approx(lam.max(), rel=0.02)
    assert r.tip_displacement == pytest.approx((x - s.flexibility @ lam).max(), rel=0.02)
    section = {"lobes": 1, "window": 5}
    from bladecase.post.rub.report import _verdict

    words = _verdict({"speed": 48.7, "response": r.response, "read_revolutions": r.read_revolutions,
                      "change": r.change}, section, "rpm")
    assert words == ["- At 48.7 rpm the response is periodic over 3 revolutions (3 lobe passings: a sub-harmonic, at "
                     "1/3 of the lobes' frequency); its figures are the peaks over that period."]


# ----------------------------------------------------------------------------- (c) the speed over the crossing speed


def test_the_crossing_speed_meets_the_lobes_excitation():
    """f1² linear in Ω² (stress stiffening, spin softening): the crossing of ``lobes·Ω/2π`` with f1 is exact whether
    it lies between the speeds, beyond them or with one speed of a constant f1; and, for a curved f1(Ω), it agrees
    with a root found independently on the frequencies."""
    lobes, f0, b = 3, 400.0, 1.5
    exact = f0 / np.sqrt((lobes / (2 * np.pi)) ** 2 - b / (4 * np.pi**2))   # rad/s
    f1 = lambda w: np.sqrt(f0**2 + b * (w / (2 * np.pi)) ** 2)                    # noqa: E731
    for w, how in ((np.linspace(0.8, 1.2, 5) * exact, "interpolated"), (np.linspace(0.5, 0.9, 4) * exact,
                                                                          "extrapolated"),
                   (np.linspace(1.1, 1.3, 3) * exact, "extrapolated")):
        c = crossing_speed(w, f1(w), lobes)
        assert c["how"] == how and c["speed_rad_s"] == pytest.approx(exact, rel=1e-12)
        assert c["frequency_hz"] == pytest.approx(f1(exact), rel=1e-12)
    one = crossing_speed([900.0], [410.0], lobes)
    assert one["how"] == "one speed" and one["speed_rad_s"] == pytest.approx(2 * np.pi * 410 / lobes)
    assert crossing_speed([100.0, 200.0], [100.0, 300.0], 1) is None                # f1 outruns the excitation
    # a curved f1 (not Southwell's law), the speeds close around the crossing: the root of lobes·Ω/2π − f1(Ω) on
    # the frequencies interpolated linearly in Ω
    g = lambda w: 500.0 - 0.02 * w + 3e-5 * w**2                                   # noqa: E731
    w = np.linspace(1040.0, 1110.0, 8)
    root = brentq(lambda x: lobes * x / (2 * np.pi) - np.interp(x, w, g(w)), w[0], w[-1])
    assert crossing_speed(w, g(w), lobes)["speed_rad_s"] == pytest.approx(root, rel=1e-5)


def test_the_report_quotes_the_hardest_rub_against_the_crossing_speed():
    row = {"speed": 8100.0, "speed_rad_s": 848.2, "speed_ratio": 1.0213, "tip_normal_displacement_mm": 0.5,
           "max_pressure_mpa": 2.0, "total_force_n": 30.0, "loaded_area_mm2": 20.0, "peak_loaded_area_mm2": 25.0,
           "load_centre": 0.8, "load_location": "trailing edge", "max_node_force_n": 3.0, "contact_fraction": 0.2,
           "penetration_mm": 0.01, "nodes_touching": 12, "switches": 900, "settled": True, "response": "periodic-9",
           "revolutions_run": 120}
    section = {"speed_unit": "rpm", "lobes": 3, "amplitude_m": 1e-4, "revolutions": 40, "window": 10,
               "max_revolutions": 400, "damping": {"ratio": 0.005}, "nodes": list(range(134)), "rows": [row],
               "worst": {**row, "touching_nodes": [1, 2], "touching_along_tip": [0.8, 0.9]}, "unsettled_speeds": [],
               "resonances": [{"mode": 1, "speed": 7931.0, "frequency_hz": 396.6}],
               "crossing": {"mode": 1, "speed": 7931.0, "speed_rad_s": 830.5, "frequency_hz": 396.6,
                            "how": "interpolated"},
               "characterised": [{"speed": 8100.0, "response": "periodic-9", "settled": True, "revolutions_run": 120,
                                  "read_revolutions": 9.0, "change": 0.004}],
               "model": {"face_area_mm2": 300.0}}
    text = "\n".join(rub_report(section))
    assert "The hardest rub is at 8100 rpm (1.02 × the crossing speed of mode 1): the tip reaches" in text
    assert "at about 7931 rpm — the crossing speed: `speed_ratio` in `rub.csv` is each speed over it" in text
    assert ("At 8100 rpm the response is periodic over 3 revolutions (9 lobe passings: a sub-harmonic, at 1/9 of the "
            "lobes' frequency); its figures are the peaks over 3 of those periods (9 revolutions).") in text
