"""Periodic orbits with one impact per period (theory §3–4).

* 1-dof oscillator against its closed form;
* the orbit is a periodic motion of the impacting system, checked with an
  independent exact flight (expm): position/velocity periodicity and Moreau jump;
* resonant periods are errors;
* non-admissible orbits leave the orbit when simulated;
* admissibility is certified, not sampled (narrow violations, brute-force grids).
"""

from __future__ import annotations

import numpy as np
import pytest
from _util import dense, flow, stacked, two_dof_exact
from scipy.optimize import fsolve

import bladecase as bc

# ---------------------------------------------------------------------------
# 1-dof oscillator: closed form (theory §4 with one mode)
#   ω = √(k/m), φ = b = 1/√m, g(0) = cot(ωT/2)/(2mω), Λ = -d/g(0) = -2mωd tan(ωT/2),
#   x(t) = -Λ G(t) = d cos(ω(t - T/2)) / cos(ωT/2)   (t ∈ [0, T)),
#   amplitude A = d/|cos(ωT/2)|, energy E = ½ k A² = ½ m ω² A².
# Λ >= 0 and x <= d for all t  <=>  ωT/2 ∈ (π/2, π)  <=>  T ∈ (π/ω, 2π/ω).
# Outside: T < π/ω or T ∈ (3π/ω, 4π/ω): x(T/2) = A > d;  T ∈ (2π/ω, 3π/ω): Λ < 0 and
# x = A at ω(t - T/2) = ±π.  In all three cases max(x - d) = A - d.
# ---------------------------------------------------------------------------

K1, M1, D1 = 8.0, 2.0, 0.5
W1 = np.sqrt(K1 / M1)  # ω = 2


@pytest.fixture(scope="module")
def one_dof():
    return bc.chain(1, k=K1, m=M1, gap=D1)


def _closed_form(T, t):
    A = D1 / abs(np.cos(W1 * T / 2))
    lam = -2 * M1 * W1 * D1 * np.tan(W1 * T / 2)
    x = D1 * np.cos(W1 * (t - T / 2)) / np.cos(W1 * T / 2)
    v = -D1 * W1 * np.sin(W1 * (t - T / 2)) / np.cos(W1 * T / 2)
    return A, lam, 0.5 * K1 * A**2, x, v


@pytest.mark.parametrize("f", [1.05, 1.2, 1.5, 1.7, 1.9, 1.99])
def test_one_dof_admissible_matches_closed_form(one_dof, f):
    T = f * np.pi / W1  # inside (π/ω, 2π/ω)
    o = bc.orbit_1ipp(one_dof, T)
    t = np.linspace(0, T, 101)[:-1]
    A, lam, E, x_ref, v_ref = _closed_form(T, t)
    assert o.admissible
    assert 0.0 <= o.max_violation <= 1e-9 * D1
    assert o.T == T and o.k == 1
    assert o.impact_times[-1] == T
    assert o.impulses[0] > 0
    assert o.impulses[0] == pytest.approx(lam, rel=1e-12)
    assert o.energy == pytest.approx(E, rel=1e-12)  # E = ½ k A² = ½ m ω² A²
    assert o.energy == pytest.approx(0.5 * M1 * W1**2 * A**2, rel=1e-12)
    x, v = o.state(t)
    assert x.shape == (1, t.size) and v.shape == (1, t.size)
    np.testing.assert_allclose(x[0], x_ref, rtol=0, atol=1e-12 * A)
    np.testing.assert_allclose(v[0], v_ref, rtol=0, atol=1e-12 * A * W1)
    # amplitude: max|x| = d/|cos(ωT/2)|, reached at t = T/2 (rel 1e-12)
    xm, _ = o.state([T / 2])
    assert abs(xm[0, 0]) == pytest.approx(A, rel=1e-12)
    assert np.abs(x).max() <= A * (1 + 1e-12)
    # at the obstacle at t = 0, leaving it (post-impact)
    x0, v0 = o.state(0.0)
    assert x0[0, 0] == pytest.approx(D1, rel=1e-13)
    assert v0[0, 0] < 0
    # impulse = momentum jump: M(v⁺ - v⁻) = -Λ with v⁻ = -v⁺ (elastic)
    assert -2 * M1 * v0[0, 0] == pytest.approx(lam, rel=1e-12)


@pytest.mark.parametrize("f", [0.3, 0.6, 0.9, 2.1, 2.5, 2.9, 3.2, 3.5, 3.9])
def test_one_dof_non_admissible_outside_interval(one_dof, f):
    T = f * np.pi / W1
    o = bc.orbit_1ipp(one_dof, T)
    A, lam, E, _, _ = _closed_form(T, 0.0)
    assert not o.admissible
    assert o.impulses[0] == pytest.approx(lam, rel=1e-12)
    assert o.energy == pytest.approx(E, rel=1e-12)
    # Λ = -2mωd tan(ωT/2) < 0 exactly when ωT/2 ∈ (0, π/2) ∪ (π, 3π/2), i.e. f < 1 or 2 < f < 3
    assert (o.impulses[0] < 0) == (f < 1 or 2 < f < 3)
    # the largest violation is A - d (closed form above), found to 1e-10 relative of A
    assert o.max_violation == pytest.approx(A - D1, rel=0, abs=1e-10 * A)


def test_one_dof_backbone_interval_is_pi_over_omega_to_two_pi_over_omega(one_dof):
    bb = bc.backbone(one_dof, np.linspace(0.5 * np.pi / W1, 4.5 * np.pi / W1, 50))
    assert len(bb.intervals) == 1
    iv = bb.intervals[0]
    assert iv.refined_lo and iv.refined_hi
    # ends refined to BISECTION_RTOL = 1e-9: allow 2e-9 relative
    assert iv.T_lo == pytest.approx(np.pi / W1, rel=2e-9)
    assert iv.T_hi == pytest.approx(2 * np.pi / W1, rel=2e-9)
    assert np.pi / W1 < iv.T_lo < iv.T_hi < 2 * np.pi / W1


# ---------------------------------------------------------------------------
# PeriodicOrbit basics, checked with an independent exact flight (expm)
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "sysname, T",
    [("two_dof", 2.6), ("two_dof", 4.5), ("two_dof", 6.5), ("random_sys", 1.65337), ("random_sys", 3.63009),
     ("chain10", 6.6)],
)
def test_orbit_is_a_periodic_motion_with_moreau_jump(request, sysname, T):
    s = request.getfixturevalue(sysname)
    o = bc.orbit_1ipp(s, T)
    assert o.admissible
    x0, v0 = o.state(0.0)
    x0, v0 = x0[:, 0], v0[:, 0]
    scale = np.linalg.norm(stacked(x0, v0))
    # at the obstacle, moving away
    assert s.w @ x0 == pytest.approx(s.gap, rel=1e-12)
    assert s.w @ v0 < 0
    # exact free flight over T returns to x0 (position continuous at the impact) ...
    xT, vT = flow(s, x0, v0, T)
    np.testing.assert_allclose(xT, x0, rtol=0, atol=1e-10 * scale)
    # ... with pre-impact velocity vT: M(v⁺ - v⁻) = -w Λ and wᵀv⁺ = -wᵀv⁻ (e = 1)
    M = dense(s.M)
    lam = o.impulses[0]
    np.testing.assert_allclose(M @ (v0 - vT), -s.w * lam, rtol=0, atol=1e-10 * scale * np.abs(M).max())
    assert s.w @ v0 == pytest.approx(-(s.w @ vT), rel=1e-9)
    # state(t) agrees with the exact flight inside the period
    t = np.linspace(0, T, 7)[1:-1]
    X, V = o.state(t)
    for i, ti in enumerate(t):
        xr, vr = flow(s, x0, v0, ti)
        np.testing.assert_allclose(stacked(X[:, i], V[:, i]), stacked(xr, vr), rtol=0, atol=1e-10 * scale)
    # energy is constant along the orbit and equals the reported one (rel 1e-12)
    tt = np.linspace(0, T, 50)
    E = s.energy(*o.state(tt))
    np.testing.assert_allclose(E, o.energy, rtol=1e-12)
    # periodic in t, post-impact value at impact instants
    Xa, Va = o.state(t + 3 * T)
    np.testing.assert_allclose(Xa, X, rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(Va, V, rtol=0, atol=1e-11 * scale)
    xT2, vT2 = o.state(T)
    np.testing.assert_allclose(stacked(xT2, vT2), stacked(x0, v0), rtol=0, atol=1e-12 * scale)
    # contact(t) = wᵀx(t)
    np.testing.assert_allclose(o.contact(tt), s.w @ o.state(tt)[0], rtol=0, atol=1e-12 * scale)
    d = o.to_dict()
    assert d["T"] == T and d["ipp"] == 1 and d["admissible"] is True
    assert d["impulses"] == [lam] and d["impact_times"] == [T]


# ---------------------------------------------------------------------------
# Errors: resonant and invalid periods
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("j", [0, 1])
@pytest.mark.parametrize("multiple", [1, 2])
def test_resonant_period_is_an_error(two_dof, j, multiple):
    T = multiple * 2 * np.pi / two_dof.spectrum.omega[j]
    with pytest.raises(ValueError, match=rf"resonant: ω_{j + 1} T = 2π·{multiple}"):
        bc.orbit_1ipp(two_dof, T)


def test_resonant_period_from_closed_form_is_an_error(two_dof):
    omega, _ = two_dof_exact()
    with pytest.raises(ValueError, match="resonant"):
        bc.orbit_1ipp(two_dof, 2 * np.pi / omega[0])
    with pytest.raises(ValueError, match="resonant"):
        bc.orbit_1ipp(two_dof, 4 * np.pi / omega[1])
    # slightly off resonance is fine (relative 1e-9)
    bc.orbit_1ipp(two_dof, 2 * np.pi / omega[0] * (1 + 1e-9))


@pytest.mark.parametrize("T, match", [(0.0, "finite and > 0"), (-1.0, "finite and > 0"), (np.nan, "finite and > 0"),
                                      (np.inf, "finite and > 0"), ("abc", "must be a number")])
def test_invalid_period_is_an_error(two_dof, T, match):
    with pytest.raises(ValueError, match=match):
        bc.orbit_1ipp(two_dof, T)


# ---------------------------------------------------------------------------
# Non-admissible orbits: classified so, and the simulation leaves them
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("T", [1.5, 2.0, 3.0, 3.5, 5.55, 5.6, 5.64, 8.0, 9.0, 12.0])
def test_non_admissible_orbit_is_left_by_simulation(two_dof, T):
    s = two_dof
    o = bc.orbit_1ipp(s, T)
    assert not o.admissible
    assert o.max_violation > 1e-3  # a clear violation
    # the reported violation is real: wᵀx - d at max_violation_time (rel 1e-9)
    assert o.contact(o.max_violation_time)[0] - s.gap == pytest.approx(o.max_violation, rel=1e-9)
    x0, v0 = o.state(0.0)
    x0, v0 = x0[:, 0], v0[:, 0]
    z0 = stacked(x0, v0)
    tr = bc.simulate(s, x0, v0, 1.5 * T)
    assert tr.impact_times.size >= 1
    if o.impulses[0] < 0:
        # wᵀv(0⁺) > 0: moving into the obstacle, the simulation impacts at once
        assert s.w @ v0 > 0
        assert tr.impact_times[0] == 0.0
    else:
        # Λ >= 0 but wᵀx crosses d inside the period: the first impact is that crossing
        t_cross = tr.impact_times[0]
        assert t_cross < (1 - 1e-3) * T
        assert o.contact(t_cross)[0] == pytest.approx(s.gap, rel=1e-9)
        tt = np.linspace(0, t_cross, 2001)[1:-1]
        assert np.all(o.contact(tt) < s.gap)
    x1, v1 = tr.state(T)
    assert np.linalg.norm(stacked(x1, v1) - z0) > 1e-3 * np.linalg.norm(z0)  # >> 1e-8


# ---------------------------------------------------------------------------
# Admissibility is certified, not sampled
# ---------------------------------------------------------------------------


def _two_dof_tangency():
    """Independent reference: the left end of the 2-dof interval [5.65, 7.19].

    There, ``wᵀx(t)/d = g(t)/g(0)`` touches 1 at an interior time (t ≈ 0.19 T):
    solve ``g(t)/g(0) = 1``, ``g'(t) = 0`` for ``(t, T)`` with the closed-form spectrum.
    """
    omega, b2 = two_dof_exact()

    def g(t, T):
        return np.sum(b2 * np.cos(omega * (t - T / 2)) / (2 * omega * np.sin(omega * T / 2)))

    def dg(t, T):
        return -np.sum(b2 * np.sin(omega * (t - T / 2)) / (2 * np.sin(omega * T / 2)))

    sol, info, ier, msg = fsolve(lambda z: [g(z[0], z[1]) / g(0.0, z[1]) - 1, dg(z[0], z[1])],
                                 [0.19 * 5.65, 5.65], xtol=1e-14, full_output=True)
    assert ier == 1, msg
    return sol[1], sol[0]


def test_narrow_violation_is_found_where_sampling_misses_it(two_dof):
    s = two_dof
    T_star, t_star = _two_dof_tangency()
    assert T_star == pytest.approx(5.6501485, rel=1e-7)

    # just outside (T < T*): a violation of ~1e-6 d, over ~0.05 % of the period around t*
    T_out = T_star * (1 - 1e-8)
    o = bc.orbit_1ipp(s, T_out)
    assert o.impulses[0] > 0  # the impulse is fine: only the interior violation disqualifies
    t_fine = np.linspace(0, T_out, 200_001)
    brute = float(np.max(o.contact(t_fine) - s.gap))
    assert 1e-9 < brute < 1e-5
    # a coarse uniform sample (1001 points) sees nothing
    t_coarse = np.linspace(0, T_out, 1001)
    assert np.max(o.contact(t_coarse) - s.gap) < 1e-9
    # the certified check does
    assert not o.admissible
    assert o.max_violation >= brute - 1e-12
    assert o.max_violation == pytest.approx(brute, rel=1e-3)
    tv = o.max_violation_time
    assert min(abs(tv - t_star), abs(tv - (T_out - t_star))) < 1e-3 * T_out  # where (symmetric pair)
    assert o.contact(tv)[0] - s.gap == pytest.approx(o.max_violation, rel=1e-9)

    # just inside: admissible, and the brute-force grid agrees
    T_in = T_star * (1 + 1e-8)
    o = bc.orbit_1ipp(s, T_in)
    assert o.admissible
    brute = float(np.max(o.contact(np.linspace(0, T_in, 200_001)) - s.gap))
    assert brute <= 1e-9
    assert o.max_violation <= 1e-9


def _certification_agrees_with_brute_force(s, periods, points=200_001):
    checked = 0
    for T in periods:
        try:
            o = bc.orbit_1ipp(s, T)
        except ValueError:
            continue
        t = np.linspace(0, T, points)
        brute = float(np.max(o.contact(t) - s.gap))
        if o.admissible:
            # tolerance of the admissibility check: 1e-9 d (orbits of moderate amplitude here)
            assert brute <= 1e-9 * s.gap + 1e-12 * np.abs(o.impulses).max(), T
        else:
            if o.impulses.min() >= 0:
                assert o.max_violation >= brute - 1e-12, T
                assert o.max_violation > 1e-9 * s.gap, T  # a genuine violation, not round-off
        if brute > 1e-9 * s.gap:
            assert not o.admissible, T
        checked += 1
    return checked


def test_certification_vs_brute_force_two_dof(two_dof, two_dof_backbone):
    # scan points plus points just inside / outside every refined interval end
    ends = [e for iv in two_dof_backbone.intervals for e in (iv.T_lo, iv.T_hi)]
    near = [e * (1 + r) for e in ends for r in (-1e-7, 1e-7, -1e-5, 1e-5)]
    periods = np.r_[np.linspace(1.0, 12.0, 45), near]
    assert _certification_agrees_with_brute_force(two_dof, periods) > 60


def test_certification_vs_brute_force_many_modes(chain10, chain10_backbone, random_sys, random_backbone):
    for s, bb in ((chain10, chain10_backbone), (random_sys, random_backbone)):
        ends = [e for iv in bb.intervals[:6] for e in (iv.T_lo, iv.T_hi) if iv.refined_lo and iv.refined_hi]
        periods = np.r_[[e * (1 + r) for e in ends for r in (-1e-6, 1e-6)], np.linspace(1.0, 4.5, 12)]
        assert _certification_agrees_with_brute_force(s, periods, points=100_001) > 20


# ---------------------------------------------------------------------------
# Orbits are light records: they pickle without the system and re-bind to it
# ---------------------------------------------------------------------------


def test_orbit_pickles_small_without_the_system():
    import pickle

    big = bc.chain(500, k=1.0, m=1.0 / 500, gap=1.0)
    T = 0.97 * 2 * np.pi / big.spectrum.omega[0]
    o = bc.orbit_1ipp(big, T)
    o.state(0.0)  # caches the modal kernel (500 x 500 modes): it must not be shipped either
    data = pickle.dumps(o)
    assert len(data) < 10_000, len(data)
    back = pickle.loads(data)
    assert back.system is None
    for name in ("T", "energy", "admissible", "max_violation", "max_violation_time", "repeats", "stable"):
        assert getattr(back, name) == getattr(o, name), name
    np.testing.assert_array_equal(back.impact_times, o.impact_times)
    np.testing.assert_array_equal(back.impulses, o.impulses)
    with pytest.raises(ValueError, match="not bound to a system"):
        back.state(0.0)
    bound = back.bind(big)
    t = np.linspace(0, T, 7)
    for a, b in zip(bound.state(t), o.state(t)):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="LinearSystem"):
        back.bind("not a system")


def test_orbit_dict_round_trip(two_dof):
    o = bc.orbit_1ipp(two_dof, 4.5)
    back = bc.PeriodicOrbit.from_dict(two_dof, o.to_dict())
    assert back.to_dict() == o.to_dict()
    assert back.stable is None and back.multipliers is None
    np.testing.assert_array_equal(back.state(1.0)[0], o.state(1.0)[0])
