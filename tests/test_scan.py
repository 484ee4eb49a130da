"""Backbones: admissible intervals of T, frequency–energy data, table / dict / plot."""

from __future__ import annotations

import json

import matplotlib.figure
import matplotlib.pyplot as plt
import numpy as np
import pytest
from _util import two_dof_exact
from scipy.optimize import brentq, fsolve

import bladecase as bc


def _two_dof_references():
    """Independent ends of the 2-dof admissible intervals (closed-form spectrum only).

    * lower ends of the first two intervals: zeros of g(0) = Σ b_j² cot(ω_j T/2)/(2ω_j)
      (Λ = -d/g(0) -> +∞ there);
    * upper ends: resonances 2π/ω₂, 2·2π/ω₂, 2π/ω₁ (Λ -> 0⁺, grazing linear modes);
    * lower end of the third interval: interior tangency of wᵀx(t) with d.
    """
    omega, b2 = two_dof_exact()

    def g0(T):
        return np.sum(b2 / np.tan(omega * T / 2) / (2 * omega))

    def g(t, T):
        return np.sum(b2 * np.cos(omega * (t - T / 2)) / (2 * omega * np.sin(omega * T / 2)))

    def dg(t, T):
        return -np.sum(b2 * np.sin(omega * (t - T / 2)) / (2 * np.sin(omega * T / 2)))

    lo1 = brentq(g0, 2.4, 2.6, xtol=1e-15, rtol=1e-15)
    lo2 = brentq(g0, 3.6, 3.9, xtol=1e-15, rtol=1e-15)
    sol = fsolve(lambda z: [g(z[0], z[1]) / g(0.0, z[1]) - 1, dg(z[0], z[1])], [0.19 * 5.65, 5.65], xtol=1e-14)
    lo3 = sol[1]
    P1, P2 = 2 * np.pi / omega
    return [(lo1, P2), (lo2, 2 * P2), (lo3, P1)]


def test_two_dof_intervals_match_references(two_dof_backbone):
    bb = two_dof_backbone
    ref = _two_dof_references()
    # the values quoted for the paper's example (rounded to 2-3 decimals)
    rough = [(2.505, 2.746), (3.746, 5.49), (5.65, 7.189)]
    assert len(bb.intervals) == 3
    for iv, (lo, hi), (rlo, rhi) in zip(bb.intervals, ref, rough):
        assert iv.refined_lo and iv.refined_hi
        assert iv.T_lo == pytest.approx(rlo, abs=2e-3) and iv.T_hi == pytest.approx(rhi, abs=2e-3)
        # ends refined by bisection to 1e-9 relative; the reference is exact to ~1e-15
        assert iv.T_lo == pytest.approx(lo, rel=1e-8)
        assert iv.T_hi == pytest.approx(hi, rel=1e-8)
        assert iv.T_lo < iv.T_hi
    # hard-coded values (to 1e-6) for the record
    np.testing.assert_allclose(
        [(iv.T_lo, iv.T_hi) for iv in bb.intervals],
        [(2.5048741, 2.7458527), (3.7458951, 5.4917053), (5.6501485, 7.1887356)],
        rtol=0, atol=1e-6,
    )


def test_two_dof_last_interval_ends_at_first_linear_period(two_dof, two_dof_backbone):
    P1 = 2 * np.pi / two_dof.spectrum.omega[0]
    assert two_dof_backbone.intervals[-1].T_hi == pytest.approx(P1, rel=1e-8)
    assert two_dof_backbone.intervals[-1].T_hi <= P1  # the resonant period itself is excluded


def test_backbone_orbits_and_intervals_are_consistent(two_dof_backbone):
    bb = two_dof_backbone
    assert bb.ipp == 1
    assert bb.periods.size == 111 and np.all(np.diff(bb.periods) > 0)
    np.testing.assert_allclose(bb.frequencies, 1 / bb.periods, rtol=1e-15)
    adm = bb.admissible
    assert adm.dtype == bool and adm.shape == (111,)
    for T, o, a in zip(bb.periods, bb.orbits, adm):
        inside = any(iv.T_lo <= T <= iv.T_hi for iv in bb.intervals)
        assert inside == a, T
        assert o is not None and o.T == T
    # energies: constant of each orbit; impulses positive on admissible orbits
    assert np.all(np.isfinite(bb.energy)) and np.all(bb.energy > 0)
    assert np.all(bb.impulses[adm] > 0)
    assert bb.impulses.shape == (111, 1)
    assert np.all(bb.max_violation[adm] <= 1e-9)
    np.testing.assert_allclose(bb.linear_frequencies, np.sort(bb.system.spectrum.frequencies), rtol=1e-15)


def test_grazing_energy_tends_to_linear_mode_with_amplitude_d(two_dof):
    """Theory §4: as T -> 2π/ω₁ from below the orbit tends to mode 1 with wᵀφ amplitude d,
    so E -> ½ ω₁² (d/b₁)²."""
    spc = two_dof.spectrum
    P1 = 2 * np.pi / spc.omega[0]
    o = bc.orbit_1ipp(two_dof, P1 * (1 - 1e-7))
    E_lin = 0.5 * spc.omega[0] ** 2 * (two_dof.gap / spc.b[0]) ** 2
    assert o.admissible
    assert o.energy == pytest.approx(E_lin, rel=1e-5)


def test_backbone_with_resonant_scan_points(two_dof):
    P = 2 * np.pi / two_dof.spectrum.omega
    bb = bc.backbone(two_dof, [P[1], 4.0, 4.5, 5.0, 2 * P[1]])
    assert bb.orbits[0] is None and bb.orbits[-1] is None  # resonant: no orbit, no error
    assert all(o is not None and o.admissible for o in bb.orbits[1:-1])
    assert "resonant" in bb.table()
    d = bb.to_dict()
    assert d["orbits"][0]["resonant"] is True and d["orbits"][-1]["resonant"] is True
    assert np.isnan(bb.energy[0]) and not bb.admissible[0]
    # one interval, refined against the resonant neighbours: [3.7459, 2·2π/ω₂]
    (iv,) = bb.intervals
    assert iv.refined_lo and iv.refined_hi
    assert iv.T_lo == pytest.approx(_two_dof_references()[1][0], rel=1e-8)
    assert iv.T_hi == pytest.approx(2 * P[1], rel=1e-8) and iv.T_hi < 2 * P[1]


def test_backbone_argument_errors(two_dof):
    with pytest.raises(ValueError, match="periods is empty"):
        bc.backbone(two_dof, [])
    with pytest.raises(ValueError, match="finite and > 0"):
        bc.backbone(two_dof, [1.0, -2.0])
    with pytest.raises(ValueError, match="finite and > 0"):
        bc.backbone(two_dof, [1.0, np.nan])
    with pytest.raises(ValueError, match="ipp = 2"):
        bc.backbone(two_dof, [1.0, 2.0], ipp=2)


def test_unrefined_ends_at_the_scan_limits(two_dof):
    bb = bc.backbone(two_dof, np.linspace(4.0, 6.5, 26))
    assert bb.intervals[0].T_lo == 4.0 and not bb.intervals[0].refined_lo
    assert bb.intervals[-1].T_hi == 6.5 and not bb.intervals[-1].refined_hi
    assert bb.intervals[0].refined_hi and bb.intervals[-1].refined_lo


def test_table_and_to_dict_contain_the_intervals(two_dof_backbone):
    bb = two_dof_backbone
    table = bb.table()
    assert "admissible intervals of T" in table
    for iv in bb.intervals:
        assert f"{iv.T_lo:.12g}" in table and f"{iv.T_hi:.12g}" in table
    assert len(table.splitlines()) >= 111 + 1 + 3
    d = bb.to_dict()
    assert set(d) >= {"ipp", "system", "linear_frequencies", "linear_periods", "orbits", "intervals"}
    assert d["system"] == {"n": 2, "gap": 1.0}
    assert len(d["orbits"]) == 111
    assert d["intervals"] == [
        {"T_lo": iv.T_lo, "T_hi": iv.T_hi, "refined_lo": iv.refined_lo, "refined_hi": iv.refined_hi}
        for iv in bb.intervals
    ]
    json.loads(json.dumps(d))  # JSON-ready
    o = d["orbits"][50]
    assert set(o) >= {"T", "frequency", "ipp", "impact_times", "impulses", "energy", "admissible", "max_violation"}


def test_plot_returns_a_figure(two_dof_backbone):
    fig = two_dof_backbone.plot()
    try:
        assert isinstance(fig, matplotlib.figure.Figure)
        ax = fig.axes[0]
        assert ax.get_yscale() == "log"
        assert ax.get_xlabel() == "frequency 1/T"
    finally:
        plt.close(fig)
    fig, ax = plt.subplots()
    try:
        assert two_dof_backbone.plot(ax=ax) is fig
    finally:
        plt.close(fig)


# ---------------------------------------------------------------------------
# Intervals must not straddle a resonance (Λ changes sign through every resonance of an
# active mode: Λ = -d/g(0) and g(0) ~ b_j² cot(ω_j T/2)/(2ω_j) changes sign through ±∞).
# ---------------------------------------------------------------------------


def _interval_problems(system, bb, dense=801, mmax=40):
    spc = system.spectrum
    res = np.sort(np.concatenate([m * 2 * np.pi / spc.omega[spc.active] for m in range(1, mmax)]))
    problems = []
    for iv in bb.intervals:
        inside = res[(res > iv.T_lo) & (res < iv.T_hi)]
        if inside.size:
            problems.append((iv.T_lo, iv.T_hi, "contains resonances", inside.tolist()))
        for T in np.linspace(iv.T_lo, iv.T_hi, dense):
            try:
                o = bc.orbit_1ipp(system, T)
            except ValueError:
                problems.append((iv.T_lo, iv.T_hi, "resonant", T))
                break
            if not o.admissible:
                problems.append((iv.T_lo, iv.T_hi, "non-admissible", T, o.impulses[0], o.max_violation))
                break
    return problems


def test_fine_scan_intervals_are_admissible_throughout(two_dof_backbone, random_sys, random_backbone):
    assert _interval_problems(two_dof_backbone.system, two_dof_backbone) == []
    assert _interval_problems(random_sys, random_backbone, dense=201) == []


def test_coarse_scan_does_not_bridge_a_resonance_two_dof(two_dof):
    # scan points 5 and 6 are both admissible; 2·2π/ω₂ = 5.4917 lies between them, and
    # (5.4917, 5.6501) is not admissible (e.g. T = 5.55: Λ = -1.17, max_violation = 2.59 d)
    bb = bc.backbone(two_dof, np.linspace(1.0, 30.0, 30))
    o = bc.orbit_1ipp(two_dof, 5.55)
    assert not o.admissible and o.impulses[0] < 0
    assert not any(iv.T_lo <= 5.55 <= iv.T_hi for iv in bb.intervals), bb.intervals


def test_chain10_intervals_are_admissible_throughout(chain10, chain10_backbone):
    # e.g. the reported [4.1291, 4.4646] contains 4·2π/ω₉ = 4.15859 and 3·2π/ω₈ = 4.41062;
    # T = 4.1626 in it has Λ = -1.96 and max_violation = 12 d
    assert _interval_problems(chain10, chain10_backbone, dense=201) == []


# ---------------------------------------------------------------------------
# One branch type: the backbone is a Branch (source "scan"), serialised in one place
# ---------------------------------------------------------------------------


def test_backbone_is_a_branch_with_scan_source(two_dof_backbone):
    from bladecase.nsm import Branch

    bb = two_dof_backbone
    assert isinstance(bb, Branch) and bc.Backbone is Branch and bc.Family is Branch and bc.Interval is bc.Arc
    assert bb.source == "scan" and bb.k == bb.ipp == 1
    assert bb.intervals is bb.arcs
    np.testing.assert_array_equal(bb.T, bb.periods)
    for a in bb.arcs:  # arcs carry the scan indices of their admissible points
        assert bb.admissible[a.start: a.stop + 1].all()
        assert a.T_lo <= bb.periods[a.start] and bb.periods[a.stop] <= a.T_hi


def test_backbone_dict_round_trip(two_dof):
    P = 2 * np.pi / two_dof.spectrum.omega
    bb = bc.backbone(two_dof, [P[1], 4.0, 4.5, 5.0, 2 * P[1], 6.0, 7.0])
    d = bb.to_dict()
    back = bc.Backbone.from_dict(two_dof, json.loads(json.dumps(d)))
    assert back.source == "scan" and back.orbits[0] is None and back.orbits[4] is None
    assert back.to_dict() == d
    assert back.table() == bb.table()
    # a document written before the merge: intervals only (no arcs), orbits without the new keys
    old = {key: d[key] for key in ("ipp", "system", "linear_frequencies", "linear_periods", "intervals")}
    old["orbits"] = [{k: v for k, v in o.items() if k not in ("max_violation_time", "stable", "multipliers")}
                     for o in d["orbits"]]
    legacy = bc.Backbone.from_dict(two_dof, old)
    assert [(a.start, a.stop, a.T_lo, a.T_hi) for a in legacy.arcs] == [(a.start, a.stop, a.T_lo, a.T_hi)
                                                                     for a in bb.arcs]
    np.testing.assert_array_equal(legacy.energy, bb.energy)
    with pytest.raises(ValueError, match="system of 2 dofs, this one has 3"):
        bc.Backbone.from_dict(bc.chain(3, gap=1.0), d)
    with pytest.raises(ValueError, match="not a branch document"):
        bc.Backbone.from_dict(two_dof, {"ipp": 1})


def test_branch_pickles_without_the_system(two_dof_backbone):
    import pickle

    back = pickle.loads(pickle.dumps(two_dof_backbone))
    assert back.system is None and all(o is None or o.system is None for o in back.orbits)
    with pytest.raises(ValueError, match="not bound"):
        _ = back.linear_frequencies
    bound = back.bind(two_dof_backbone.system)
    assert bound.to_dict() == two_dof_backbone.to_dict()
