"""Event-driven simulation (theory §5) and re-simulation of computed orbits.

* every admissible orbit, started from its post-impact state, comes back to it
  after one period (1e-8 relative) with one impact at T (rel 1e-9);
* after 50 periods as well, for linearly stable orbits (|Floquet multipliers| ≈ 1);
  unstable admissible orbits exist (theory §6) and amplify round-off by |μ|^k:
  for those the finite-difference monodromy is checked to be unstable instead;
* energy conservation over 1000 impacts, Moreau's law at every impact, dissipation with e < 1,
  no missed contact between impacts, and the free flight against an independent expm.
"""

from __future__ import annotations

import numpy as np
import pytest
from _util import dense, floquet_multipliers, flow, resimulate, stacked

import bladecase as bc


def _in_some_interval(bb, T):
    return any(iv.T_lo <= T <= iv.T_hi for iv in bb.intervals)


#: Orbits whose post-impact state exceeds this multiple of the gap (near the ends of
#: intervals where g(0) -> 0 and Λ -> ∞) are left to test_large_amplitude_orbits_can_be_resimulated.
MODERATE_AMPLITUDE = 1e3


def _moderate(system, T):
    x0, _ = bc.orbit_1ipp(system, T).state(0.0)
    return np.abs(x0).max() * np.abs(system.w).max() <= MODERATE_AMPLITUDE * system.gap


def _check_return(system, T, periods):
    o = bc.orbit_1ipp(system, T)
    assert o.admissible, T
    tr, z0, err = resimulate(system, o, periods)
    assert tr.complete
    # exactly one impact per period, at k·T (rel 1e-9)
    assert tr.impact_times.size == periods, (T, tr.impact_times / T)
    k = np.arange(1, periods + 1)
    np.testing.assert_allclose(tr.impact_times, k * T, rtol=1e-9, atol=0)
    # back to the post-impact state after 1 and after `periods` periods (relative 1e-8)
    assert err[0] <= 1e-8, (T, err[0])
    assert err[periods - 1] <= 1e-8, (T, err[periods - 1])
    # impulses equal the orbit's (1e-8 relative to the momentum scale: Λ -> 0 at grazing ends)
    p_scale = np.abs(dense(system.M)).max() * np.linalg.norm(z0) / np.linalg.norm(system.w)
    np.testing.assert_allclose(tr.impulses, o.impulses[0], rtol=1e-8, atol=1e-8 * p_scale)
    return o, tr


# --- the paper's 2-dof example ---------------------------------------------

# Linearly stable admissible orbits: finite-difference Floquet multipliers all of modulus
# 1 ± 1e-4 (checked for these T). The whole first interval [2.505, 2.746], the ends of the
# others and narrow windows (e.g. T ≈ 4.066, 6.51: |μ| ≈ 1.1) are unstable, so round-off grows
# like |μ|^k there; see test_unstable_admissible_orbits_are_unstable.
TWO_DOF_STABLE = [3.9, 4.2, 4.55, 4.85, 5.0, 6.0, 6.17, 6.68, 6.85, 7.0]


@pytest.mark.parametrize("T", TWO_DOF_STABLE)
def test_two_dof_orbit_returns_after_1_and_50_periods(two_dof, two_dof_backbone, T):
    assert _in_some_interval(two_dof_backbone, T)
    _check_return(two_dof, T, 50)


def test_every_admissible_two_dof_orbit_returns_after_one_period(two_dof, two_dof_backbone):
    bb = two_dof_backbone
    periods = [o.T for o in bb.orbits if o is not None and o.admissible]
    # plus points close to (1e-6 relative inside) every refined interval end
    for iv in bb.intervals:
        periods += [iv.T_lo * (1 + 1e-6), iv.T_hi * (1 - 1e-6), 0.5 * (iv.T_lo + iv.T_hi)]
    periods = [T for T in periods if _moderate(two_dof, T)]
    assert len(periods) > 40
    for T in periods:
        _check_return(two_dof, T, 1)


@pytest.mark.parametrize("T, mu_min", [(2.52, 2.0), (2.6, 2.0), (2.7, 5.0), (5.3, 2.0), (5.7, 2.0)])
def test_unstable_admissible_orbits_are_unstable(two_dof, T, mu_min):
    """Admissible but unstable: a Floquet multiplier |μ| > mu_min (theory §6), so the
    simulation drifts away from the orbit after many periods — physics, not a solver error."""
    o = bc.orbit_1ipp(two_dof, T)
    assert o.admissible
    mu = floquet_multipliers(two_dof, o)
    # a double multiplier 1 (flow direction and the family)
    assert np.sum(np.abs(mu - 1) < 1e-3) == 2
    assert np.abs(mu).max() > mu_min
    _, _, err = resimulate(two_dof, o, 50)
    assert err[0] <= 1e-8  # one period is fine
    assert err.max() > 1e-3  # many periods are not


@pytest.mark.parametrize("T", [3.9, 6.0, 7.0])
def test_stable_orbits_have_unit_multipliers(two_dof, T):
    mu = floquet_multipliers(two_dof, bc.orbit_1ipp(two_dof, T))
    np.testing.assert_allclose(np.abs(mu), 1.0, atol=1e-4)


# --- 10-dof chain (paper's Sec. 2: k = 1, m = 1/n, d = 1) -------------------

# admissible periods taken from the backbone's intervals [6.5906, 6.6159], [6.6900, 6.7762],
# [10.1094, 10.3965]; max |μ| = 1.00, 1.00, 1.03 (most chain-10 orbits are unstable)
CHAIN10_STABLE = [6.59694, 6.71152, 10.32471]


@pytest.mark.parametrize("T", CHAIN10_STABLE)
def test_chain10_orbit_returns_after_1_and_50_periods(chain10, chain10_backbone, T):
    assert _in_some_interval(chain10_backbone, T)
    _check_return(chain10, T, 50)


def test_chain10_every_admissible_orbit_returns_after_one_period(chain10, chain10_backbone):
    bb = chain10_backbone
    periods = [o.T for o in bb.orbits if o is not None and o.admissible]
    for iv in bb.intervals:  # 1e-6 (relative) inside each refined end
        periods += [iv.T_lo * (1 + 1e-6), iv.T_hi * (1 - 1e-6)]
    periods = [T for T in periods if _moderate(chain10, T)]
    assert len(periods) > 100
    for T in periods:
        _check_return(chain10, T, 1)


# --- random non-diagonal SPD M, K with a generic w ------------------------

# from the intervals [1.0647, 1.3636], [1.5253, 2.0375], [3.4818, 4.0749] (x2), [4.3979, 4.4912];
# max |μ| = 1.08, 1.00, 1.00, 1.07, 1.13: growth <= 1.13^50 ≈ 500 of round-off, far below 1e-8
RANDOM_STABLE = [1.28891, 1.65337, 3.63009, 3.77836, 4.46785]


@pytest.mark.parametrize("T", RANDOM_STABLE)
def test_random_system_orbit_returns_after_1_and_50_periods(random_sys, random_backbone, T):
    assert _in_some_interval(random_backbone, T)
    _check_return(random_sys, T, 50)


def test_random_system_every_admissible_orbit_returns_after_one_period(random_sys, random_backbone):
    bb = random_backbone
    periods = [o.T for o in bb.orbits if o is not None and o.admissible]
    for iv in bb.intervals:  # 1e-6 (relative) inside each refined end
        periods += [iv.T_lo * (1 + 1e-6), iv.T_hi * (1 - 1e-6)]
    periods = [T for T in periods if _moderate(random_sys, T)]
    assert len(periods) > 100
    for T in periods:
        _check_return(random_sys, T, 1)


def test_large_amplitude_orbits_can_be_resimulated(two_dof, two_dof_backbone):
    """Admissible orbits near the lower ends of [2.505, 2.746] and [3.746, 5.49], where
    g(0) -> 0 and Λ grows like 1/(T - T_lo) (amplitudes 1e4..1e7 d)."""
    failures = []
    for T0 in (two_dof_backbone.intervals[0].T_lo, two_dof_backbone.intervals[1].T_lo):
        for r in np.logspace(-8, -5, 16):
            o = bc.orbit_1ipp(two_dof, T0 * (1 + r))
            assert o.admissible
            try:
                _, _, err = resimulate(two_dof, o, 1)
                if not err[0] <= 1e-8:
                    failures.append((o.T, f"error {err[0]:.2e}"))
            except ValueError as exc:
                failures.append((o.T, str(exc)))
    assert not failures, failures


# ---------------------------------------------------------------------------
# Energy, impact law, dissipation
# ---------------------------------------------------------------------------


def _generic_state(system, seed=7):
    rng = np.random.default_rng(seed)
    x0 = rng.standard_normal(system.n)
    v0 = rng.standard_normal(system.n)
    x0 *= 0.5 * system.gap / abs(system.w @ x0)
    if system.w @ x0 > 0:
        x0 = -x0  # wᵀx0 = -d/2: admissible, away from the obstacle
    return x0, 3.0 * v0  # enough energy to reach the obstacle


def _impacts_until(system, x0, v0, count, e=1.0):
    """Simulate long enough for at least ``count`` impacts."""
    t_end = 50.0
    while True:
        tr = bc.simulate(system, x0, v0, t_end, restitution=e)
        if tr.impact_times.size >= count:
            return tr
        t_end *= 1.5 * count / max(tr.impact_times.size, 1)


@pytest.mark.parametrize("sysname", ["two_dof", "random_sys"])
def test_energy_conserved_over_1000_impacts(request, sysname):
    s = request.getfixturevalue(sysname)
    x0, v0 = _generic_state(s)
    tr = _impacts_until(s, x0, v0, 1000)
    assert tr.complete
    E0 = s.energy(x0, v0)
    assert tr.impact_times.size >= 1000
    np.testing.assert_allclose(tr.energy(), E0, rtol=1e-10)
    np.testing.assert_allclose(s.energy(tr.x, tr.v), E0, rtol=1e-10)
    np.testing.assert_allclose(s.energy(tr.x_end, tr.v_end), E0, rtol=1e-10)
    # every post-impact state is at the obstacle, leaving it
    np.testing.assert_allclose(s.w @ tr.x, s.gap, rtol=1e-12)
    assert np.all(s.w @ tr.v < 0)
    assert np.all(np.diff(tr.impact_times) > 0)


@pytest.mark.parametrize("sysname", ["two_dof", "random_sys", "chain10"])
@pytest.mark.parametrize("e", [1.0, 0.7])
def test_moreau_impact_law_against_independent_flight(request, sysname, e):
    """Pre-impact states from an independent exact flight (expm) of the previous post-impact state:
    x continuous, wᵀx⁻ = d, M(v⁺ - v⁻) = -wΛ, wᵀv⁺ = -e wᵀv⁻, Λ = (1+e) wᵀv⁻/(wᵀM⁻¹w)."""
    s = request.getfixturevalue(sysname)
    M = dense(s.M)
    wMw = s.w @ np.linalg.solve(M, s.w)
    x0, v0 = _generic_state(s, seed=11)
    tr = bc.simulate(s, x0, v0, 30.0, restitution=e)
    assert tr.complete
    n_imp = tr.impact_times.size
    assert n_imp >= 5
    xp, vp, tp = x0, v0, 0.0
    scale = np.linalg.norm(stacked(x0, v0))
    for i in range(n_imp):
        xm, vm = flow(s, xp, vp, tr.impact_times[i] - tp)
        assert s.w @ xm == pytest.approx(s.gap, abs=1e-10 * scale)
        np.testing.assert_allclose(tr.x[:, i], xm, rtol=0, atol=1e-10 * scale)
        wvm = s.w @ vm
        assert wvm > 0  # arriving
        assert s.w @ tr.v[:, i] == pytest.approx(-e * wvm, rel=1e-9)
        lam = tr.impulses[i]
        assert lam == pytest.approx((1 + e) * wvm / wMw, rel=1e-9)
        np.testing.assert_allclose(M @ (tr.v[:, i] - vm), -s.w * lam, rtol=0, atol=1e-9 * abs(lam) * np.abs(M).max())
        xp, vp, tp = tr.x[:, i], tr.v[:, i], tr.impact_times[i]
        # restart the reference from the simulator's state (errors don't accumulate)
    # final state by exact flight from the last impact
    xe, ve = flow(s, xp, vp, tr.t_end - tp)
    np.testing.assert_allclose(stacked(tr.x_end, tr.v_end), stacked(xe, ve), rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("sysname", ["two_dof", "random_sys"])
def test_restitution_below_one_dissipates(request, sysname):
    s = request.getfixturevalue(sysname)
    e = 0.8
    M = dense(s.M)
    wMw = s.w @ np.linalg.solve(M, s.w)
    x0, v0 = _generic_state(s, seed=3)
    E0 = s.energy(x0, v0)
    tr = bc.simulate(s, x0, v0, 200.0, restitution=e)
    assert tr.complete
    E = tr.energy()
    assert E.size >= 3
    Eprev = np.r_[E0, E[:-1]]
    assert np.all(np.diff(np.r_[E0, E]) < 0)  # strictly decreasing after each impact
    # loss per impact: ΔE = -½(1 - e²)(wᵀv⁻)²/(wᵀM⁻¹w), with wᵀv⁻ = -wᵀv⁺/e
    wvm = -(s.w @ tr.v) / e
    np.testing.assert_allclose(Eprev - E, 0.5 * (1 - e**2) * wvm**2 / wMw, rtol=1e-8)
    # no dissipation in free flight after the last impact
    assert s.energy(tr.x_end, tr.v_end) == pytest.approx(E[-1], rel=1e-10)


def test_no_missed_contact_between_impacts(random_sys):
    s = random_sys
    x0, v0 = _generic_state(s, seed=5)
    tr = bc.simulate(s, x0, v0, 40.0)
    t = np.linspace(0, tr.t_end, 400_001)
    x, _ = tr.state(t)
    assert np.max(s.w @ x) <= s.gap * (1 + 1e-12)


def test_trajectory_state_against_independent_flight(random_sys):
    s = random_sys
    x0, v0 = _generic_state(s, seed=9)
    tr = bc.simulate(s, x0, v0, 10.0)
    assert tr.impact_times.size >= 2
    scale = np.linalg.norm(stacked(x0, v0))
    # before the first impact
    t1 = 0.5 * tr.impact_times[0]
    x, v = tr.state([t1])
    np.testing.assert_allclose(stacked(x, v), stacked(*flow(s, x0, v0, t1)), rtol=0, atol=1e-11 * scale)
    # at an impact instant: the post-impact state
    x, v = tr.state([tr.impact_times[1]])
    np.testing.assert_allclose(stacked(x, v), stacked(tr.x[:, 1], tr.v[:, 1]), rtol=0, atol=1e-13 * scale)
    # initial state and bounds
    x, v = tr.state([0.0])
    np.testing.assert_allclose(stacked(x, v), stacked(x0, v0), rtol=0, atol=1e-13 * scale)
    with pytest.raises(ValueError, match="times must lie in"):
        tr.state([tr.t_end + 1.0])


def test_state_at_obstacle_moving_in_impacts_at_once(two_dof):
    tr = bc.simulate(two_dof, [0.0, 1.0], [0.0, 1.0], 1.0)
    assert tr.impact_times[0] == 0.0
    assert tr.v[1, 0] == pytest.approx(-1.0, rel=1e-14)  # v_c⁺ = -v_c⁻ (diagonal M, paper's law)
    assert tr.v[0, 0] == pytest.approx(0.0, abs=1e-15)  # other velocities continuous


def test_no_impact_below_the_obstacle(two_dof):
    tr = bc.simulate(two_dof, [0.0, 0.1], [0.0, 0.0], 50.0)  # amplitude << d
    assert tr.impact_times.size == 0 and tr.complete
    assert tr.energy().size == 0


@pytest.mark.parametrize(
    "x0, v0, t_end, e, match",
    [
        ([0.0, 1.5], [0.0, 0.0], 1.0, 1.0, r"initial state violates the constraint"),
        ([0.0, 1.0 + 1e-6], [0.0, -1.0], 1.0, 1.0, r"initial state violates the constraint"),
        ([0.0], [0.0, 0.0], 1.0, 1.0, r"x0 has 1 entries, expected 2"),
        ([0.0, 0.0], [np.nan, 0.0], 1.0, 1.0, r"v0 contains non-finite"),
        ([0.0, 0.0], [0.0, 0.0], -1.0, 1.0, r"t_end must be finite and > 0"),
        ([0.0, 0.0], [0.0, 0.0], 1.0, 0.0, r"restitution must be in \(0, 1\]"),
        ([0.0, 0.0], [0.0, 0.0], 1.0, 1.5, r"restitution must be in \(0, 1\]"),
    ],
)
def test_simulate_errors(two_dof, x0, v0, t_end, e, match):
    with pytest.raises(ValueError, match=match):
        bc.simulate(two_dof, x0, v0, t_end, restitution=e)


# ---------------------------------------------------------------------------
# The simulator is made of swappable pieces: a flight propagator and an impact law
# ---------------------------------------------------------------------------


def test_event_loop_with_explicit_pieces_is_simulate(random_sys):
    from bladecase.nsm import ModalFlight, NewtonImpact, integrate

    x0, v0 = _generic_state(random_sys, seed=5)
    ref = bc.simulate(random_sys, x0, v0, 40.0, restitution=0.8)
    tr = integrate(ModalFlight(random_sys), NewtonImpact(0.8), x0, v0, 40.0)
    assert tr.impact_times.size > 5
    for name in ("impact_times", "impulses", "x", "v", "x_end", "v_end"):
        np.testing.assert_array_equal(getattr(tr, name), getattr(ref, name), err_msg=name)
    t = np.linspace(0, 40.0, 333)
    np.testing.assert_array_equal(tr.state(t)[0], ref.state(t)[0])


def test_event_loop_uses_the_pieces_it_is_given(two_dof):
    """A propagator and an impact law of one's own plug into the loop: here the modal flight with a
    counter on the contact-signal requests, and a perfectly plastic-like law that keeps a tenth of the
    normal velocity (the loop only asks for ``apply``)."""
    from bladecase.nsm import ModalFlight, integrate

    class CountingFlight(ModalFlight):
        calls = 0

        def contact_signal(self, q, p, t0=0.0):
            CountingFlight.calls += 1
            return super().contact_signal(q, p, t0)

    class TenthRebound:
        def apply(self, flight, q, p):
            direction, mobility = flight.normal_direction
            lam = 1.1 * flight.normal_velocity(q, p) / mobility
            return p - lam * direction, lam

    o = bc.orbit_1ipp(two_dof, 4.5)
    x0, v0 = o.state(o.T / 2)
    tr = integrate(CountingFlight(two_dof), TenthRebound(), x0[:, 0], v0[:, 0], 3 * o.T)
    assert tr.impact_times.size >= 1 and CountingFlight.calls >= tr.impact_times.size
    ref = bc.simulate(two_dof, x0[:, 0], v0[:, 0], 3 * o.T, restitution=0.1)
    np.testing.assert_allclose(tr.impact_times, ref.impact_times, rtol=1e-13)
    np.testing.assert_allclose(tr.impulses, ref.impulses, rtol=1e-12)
