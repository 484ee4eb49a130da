"""Forced, damped event-driven simulation and the forcing-period sweep (bladecase.nsm.newton.forced, .sweep).

* the exact flight against scipy's solve_ivp (1e-9 relative) for under-, critically and over-damped modes,
  exactly and nearly resonant forcing of undamped modes, Rayleigh damping and a non-diagonal mass matrix;
* the certified curvature bound of the contact signal against finite differences;
* no damping and no forcing reproduces ``bladecase.simulate`` (impact times to 1e-10);
* a response that never reaches the obstacle converges to the analytic linear steady state;
* energy balance (work of the forcing - viscous dissipation - impact losses = energy change) to 1e-8;
* pre-impact states; no missed grazing contact (dense-sampled check);
* the sweep classifies a 1-impact-per-period steady state and a non-periodic one (2-dof chain).
"""

from __future__ import annotations

import numpy as np
import pytest
from _util import dense
from scipy.integrate import solve_ivp

import bladecase as bc
from bladecase.nsm.damped_signals import DampedModes, DampedSignal
from bladecase.nsm.damping import Damping
from bladecase.nsm.newton.forced import ForcedFlight, simulate_forced
from bladecase.nsm.sweep import forced_point, forced_sweep
from bladecase.study.executor import SerialExecutor


def _reference(system, damping, F0, T, load, x0, v0, t0, times):
    """``M x'' + C x' + K x = F₀ cos(2πt/T) f`` by DOP853 (numpy/scipy only)."""
    M, K, C = dense(system.M), dense(system.K), damping.matrix(system)
    n, W, f = system.n, 2 * np.pi / T, F0 * np.asarray(load, float)
    Minv = np.linalg.inv(M)

    def rhs(t, z):
        return np.concatenate([z[n:], Minv @ (f * np.cos(W * t) - C @ z[n:] - K @ z[:n])])

    sol = solve_ivp(rhs, (t0, times[-1]), np.concatenate([x0, v0]), method="DOP853", rtol=1e-13, atol=1e-15,
                    t_eval=times)
    return sol.y


CHAIN3 = bc.chain(3, k=1.0, m=0.5, gap=1.0)
W3 = CHAIN3.spectrum.omega
FLIGHT_CASES = {
    "under-critical-over": (CHAIN3, Damping(zeta=[0.1, 1.0, 2.5]), 1.3),
    "exact resonance of an undamped mode": (CHAIN3, Damping(zeta=[0.0, 0.05, 0.0]), 2 * np.pi / W3[0]),
    "near resonance, undamped": (CHAIN3, None, 2 * np.pi / (W3[2] * (1 + 1e-9))),
    "resonance, damped": (CHAIN3, Damping(alpha=0.02, beta=0.01), 2 * np.pi / W3[1]),
}


@pytest.mark.parametrize("case", list(FLIGHT_CASES))
def test_flight_matches_solve_ivp(case):
    system, damping, T = FLIGHT_CASES[case]
    damping = Damping() if damping is None else damping
    load = [1.0, -0.5, 2.0]
    fl = ForcedFlight(system, period=T, amplitude=0.7, damping=damping, load=load)
    if case == "under-critical-over":  # the three regimes really are exercised
        wd, g = fl.modes._rates
        assert fl.modes.overdamped.tolist() == [False, False, True] and wd[0] > 0 and wd[1] == 0 and g[2] > 0
    rng = np.random.default_rng(3)
    x0, v0 = rng.standard_normal(3), rng.standard_normal(3)
    t0 = 3.7
    tau = np.linspace(0.0, 30.0, 13)
    ref = _reference(system, damping, 0.7, T, load, x0, v0, t0, t0 + tau)
    q0, p0 = fl.encode(x0, v0)
    q, p = fl.advance(np.repeat(q0[:, None], tau.size, 1), np.repeat(p0[:, None], tau.size, 1), tau, t0)
    z = np.vstack(fl.decode(q, p))
    assert np.abs(z - ref).max() <= 1e-9 * np.abs(ref).max()
    # one state, scalar flight time: the same numbers
    qs, ps = fl.advance(q0, p0, tau[-1], t0)
    np.testing.assert_allclose(np.concatenate(fl.decode(qs, ps)), z[:, -1], rtol=0, atol=1e-12 * np.abs(z).max())


def test_flight_non_diagonal_mass(random_sys):
    damping = Damping(alpha=0.01, beta=0.05)
    load = np.linspace(1.0, -1.0, random_sys.n)
    fl = ForcedFlight(random_sys, period=1.7, amplitude=2.0, damping=damping, load=load)
    rng = np.random.default_rng(5)
    x0, v0 = 0.1 * rng.standard_normal(random_sys.n), rng.standard_normal(random_sys.n)
    tau = np.linspace(0.0, 12.0, 7)
    ref = _reference(random_sys, damping, 2.0, 1.7, load, x0, v0, 1.1, 1.1 + tau)
    q0, p0 = fl.encode(x0, v0)
    q, p = fl.advance(np.repeat(q0[:, None], 7, 1), np.repeat(p0[:, None], 7, 1), tau, 1.1)
    assert np.abs(np.vstack(fl.decode(q, p)) - ref).max() <= 1e-9 * np.abs(ref).max()
    # modal damping matrix: Φᵀ C Φ = diag(2ζω)
    sp = random_sys.spectrum
    C = Damping(zeta=0.03).matrix(random_sys)
    np.testing.assert_allclose(sp.phi.T @ C @ sp.phi, np.diag(0.06 * sp.omega), atol=1e-12)


@pytest.mark.parametrize("case", list(FLIGHT_CASES))
def test_curvature_bound_is_an_upper_bound(case):
    system, damping, T = FLIGHT_CASES[case]
    fl = ForcedFlight(system, period=T, amplitude=1.5, damping=damping, horizon=40.0)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q0, p0 = rng.standard_normal(3), 2 * rng.standard_normal(3)
        f = fl.contact_signal(q0, p0, t0=rng.uniform(0, 10))
        tau = np.linspace(0.0, 40.0, 200_001)
        _, d = f(tau)
        curv = np.abs(np.diff(d)) / (tau[1] - tau[0])        # mean |f''| on each sub-interval
        assert curv.max() <= f.curvature_bound
        assert curv.max() >= 0.05 * f.curvature_bound       # and not absurdly loose


def test_exact_resonance_needs_a_horizon():
    modes = DampedModes(np.array([1.0]), np.array([0.0]), np.array([1.0]), Omega=1.0)
    f = DampedSignal(modes, np.array([1.0]), np.zeros(1), np.zeros(1), 0.0, -1.0)   # horizon = inf
    with pytest.raises(ValueError, match="finite horizon"):
        _ = f.curvature_bound
    # with a horizon the secular growth reaches the obstacle: τ sin(τ)/2 = 1 first near τ = 2.47...
    f = DampedSignal(modes, np.array([1.0]), np.zeros(1), np.zeros(1), 0.0, -1.0, horizon=50.0)
    from bladecase.nsm.signals import first_upcrossing

    tau = first_upcrossing(f, 0.0, 50.0)
    assert abs(tau * np.sin(tau) / 2 - 1) < 1e-14 and tau > 0
    t = np.linspace(1e-6, tau, 100_000)[:-1]
    assert np.all(t * np.sin(t) / 2 < 1)                     # it is the FIRST crossing


@pytest.mark.parametrize("name", ["chain10", "random_sys"])
def test_unforced_undamped_reproduces_simulate(request, name):
    system = request.getfixturevalue(name)
    rng = np.random.default_rng(7)
    x0 = 0.3 * system.gap * rng.standard_normal(system.n) / np.abs(system.w).max()
    x0 -= max(0.0, system.w @ x0 - 0.5 * system.gap) * system.w / (system.w @ system.w)
    v0 = 3 * rng.standard_normal(system.n)
    t_end = 60.0
    a = bc.simulate(system, x0, v0, t_end)
    b = simulate_forced(system, x0, v0, t_end)
    assert a.impact_times.size == b.impact_times.size >= 12
    np.testing.assert_allclose(b.impact_times, a.impact_times, rtol=0, atol=1e-10)
    np.testing.assert_allclose(b.impulses, a.impulses, rtol=1e-9)


def _steady_state(system, damping, F0, T, load):
    """Complex amplitude ``X`` of the linear steady state ``x = Re(X e^{iΩt})`` and its max energy."""
    M, K, C = dense(system.M), dense(system.K), damping.matrix(system)
    W = 2 * np.pi / T
    X = np.linalg.solve(K - W**2 * M + 1j * W * C, F0 * np.asarray(load, float))
    E0 = 0.25 * np.real(X.conj() @ K @ X + W**2 * X.conj() @ M @ X)
    E2 = 0.25 * (X @ K @ X - W**2 * X @ M @ X)
    return X, W, E0 + abs(E2), E0


def test_linear_response_converges_to_the_steady_state():
    system = bc.chain(2, k=1.0, m=0.5, gap=1e6)          # the obstacle is never reached
    damping, F0, T, load = Damping(zeta=0.05), 0.7, 4.0, [1.0, -0.3]
    X, W, Emax, Emean = _steady_state(system, damping, F0, T, load)
    tr = simulate_forced(system, np.zeros(2), np.zeros(2), 150 * T, period=T, amplitude=F0, damping=damping,
                         load=load)
    assert tr.impact_times.size == 0 and tr.complete
    t = np.linspace(149 * T, 150 * T, 50)
    x, v = tr.state(t)
    e = np.exp(1j * W * t)
    np.testing.assert_allclose(x, np.real(X[:, None] * e), rtol=0, atol=1e-9 * np.abs(X).max())
    np.testing.assert_allclose(v, np.real(1j * W * X[:, None] * e), rtol=0, atol=1e-9 * W * np.abs(X).max())
    # the sweep's view: a periodic state with no impact, of the analytic maximum (and mean) energy
    pt = forced_point(system, T, damping=damping, amplitude=F0, load=load, n_periods=150)
    assert (pt.label, pt.p, pt.k) == ("0/1", 1, 0) and pt.residual < 1e-9 and pt.linear
    assert pt.energy == pytest.approx(Emax, rel=1e-9)
    assert pt.mean_energy == pytest.approx(Emean, rel=1e-9)


def test_slow_linear_transient_is_certified_linear():
    """The paper's C = αK barely damps the lowest mode: at T = 2.5 the n = 5 chain stops impacting but is
    not periodic to 1e-6 after 500 periods; it is proved never to impact again (label "linear")."""
    system = bc.chain(5, k=1.0, m=0.2, gap=1.0)
    pt = forced_point(system, 2.5, damping=Damping(alpha=0.01), amplitude=1.0, n_periods=500)
    assert pt.label == "linear" and not pt.periodic and 1e-6 < pt.residual < 0.1 and pt.impact_phases.size == 0
    more = simulate_forced(system, pt.x_end, pt.v_end, 2000 * 2.5, period=2.5, amplitude=1.0,
                           damping=Damping(alpha=0.01))
    assert more.impact_times.size == 0
    x, _ = more.state(np.linspace(0, more.t_end, 200_001))
    assert x[-1].max() < system.gap


def test_no_spurious_period_without_impacts():
    """A free oscillation at ω₁ = π/T (barely damped) returns after 2 forcing periods; without impacts the
    motion is linear, its steady state T-periodic: not "0 impacts per 2 periods"."""
    system = bc.chain(2, k=1.0, m=0.5, gap=1e6)
    T = np.pi / system.spectrum.omega[0]
    pt = forced_point(system, T, damping=Damping(zeta=[1e-9, 0.05]), amplitude=0.5, n_periods=100)
    assert pt.label == "linear" and not pt.periodic and pt.residual > 1e-2


@pytest.mark.parametrize("e", [1.0, 0.8])
def test_energy_balance_with_impacts(e):
    system = bc.chain(5, k=1.0, m=0.2, gap=1.0)
    tr = simulate_forced(system, np.zeros(5), np.zeros(5), 40 * 5.0, period=5.0, amplitude=1.0,
                         damping=Damping(alpha=0.005), restitution=e)
    assert tr.complete and tr.impact_times.size >= 40
    b = tr.energy_balance()
    scale = max(b.work, b.dissipated, b.final)
    assert abs(b.residual) <= 1e-8 * scale
    assert b.work > 0 and b.dissipated > 0
    # Moreau's law: kinetic energy kept at e = 1, lost at e < 1
    fl = tr.flight
    E_pre = fl.energy(*fl.encode(tr.x_pre, tr.v_pre))
    E_post = tr.energy()
    if e == 1.0:
        assert b.impact_loss == pytest.approx(0.0, abs=1e-12 * scale)
        np.testing.assert_allclose(E_post, E_pre, rtol=1e-12)
    else:
        assert np.all(E_post < E_pre) and b.impact_loss > 0.01 * scale


def test_pre_impact_states():
    system = bc.chain(5, k=1.0, m=0.2, gap=1.0)
    e = 0.7
    tr = simulate_forced(system, np.zeros(5), np.zeros(5), 60.0, period=5.0, amplitude=1.0,
                         damping=Damping(alpha=0.01), restitution=e)
    w = system.w
    assert tr.impact_times.size >= 8
    np.testing.assert_allclose(w @ tr.x_pre, system.gap, atol=1e-12)
    assert np.all(w @ tr.v_pre > 0)
    np.testing.assert_allclose(w @ tr.v, -e * (w @ tr.v_pre), rtol=1e-12)
    # the pre-impact velocity is the limit of the flight before the impact
    _, v_before = tr.state(np.nextafter(tr.impact_times, 0))
    np.testing.assert_allclose(v_before, tr.v_pre, rtol=0, atol=1e-10 * np.abs(tr.v_pre).max())
    # only the contact dof's velocity jumps (diagonal M, w = e_n)
    np.testing.assert_allclose(tr.v_pre[:-1], tr.v[:-1], rtol=0, atol=1e-13 * np.abs(tr.v).max())


def test_no_missed_grazing_contact():
    """Started on the linear steady state of a 3-dof chain with the obstacle 1e-8 (relative) below its
    peak: a contact lasting ~3e-4 of a period, invisible to a grid of a quarter of the shortest period."""
    base = bc.chain(3, k=1.0, m=0.5, gap=1.0)
    damping, F0, T = Damping(alpha=0.01), 0.4, 2.0
    X, W, _, _ = _steady_state(base, damping, F0, T, np.ones(3))
    cX = base.w @ X
    a = abs(cX)
    system = bc.chain(3, k=1.0, m=0.5, gap=a * (1 - 1e-8))
    x0, v0 = np.real(X), np.real(1j * W * X)
    t_peak = np.mod(-np.angle(cX) / W, T)
    coarse = np.arange(0, T, 2 * np.pi / (4 * system.spectrum.omega.max()))
    assert np.real(cX * np.exp(1j * W * coarse)).max() < system.gap          # a coarse grid sees nothing
    tr = simulate_forced(system, x0, v0, 6 * T, period=T, amplitude=F0, damping=damping)
    assert tr.impact_times.size >= 1
    assert abs(tr.impact_times[0] - t_peak) < 1e-3 * T                        # found at the peak
    t = np.linspace(0, 6 * T, 600_001)
    x, _ = tr.state(t)
    assert (system.w @ x).max() - system.gap <= 1e-12                         # never inside the obstacle
    # the same motion without the obstacle does enter it
    t1 = np.linspace(t_peak - 1e-3, t_peak + 1e-3, 10_001)
    assert np.real(cX * np.exp(1j * W * t1)).max() > system.gap


# --- the sweep -----------------------------------------------------------------------

TWO_DOF = bc.chain(2, k=1.0, m=0.5, gap=1.0)
SWEEP = dict(damping=Damping(alpha=0.05), amplitude=0.6, n_periods=300)


@pytest.fixture(scope="module")
def sweep_points():
    return forced_sweep(TWO_DOF, [4.5, 5.0], continuation=False, progress=False, **SWEEP)


def test_sweep_finds_a_one_impact_per_period_state(sweep_points):
    pt = {p.T: p for p in sweep_points}[4.5]
    assert pt.complete and pt.periodic and (pt.k, pt.p, pt.label) == (1, 1, "1/1") and pt.residual < 1e-10
    # independent check: from the end state, one impact per period at the same phase, back after T
    T = 4.5
    tr = simulate_forced(TWO_DOF, pt.x_end, pt.v_end, 3 * T, period=T, amplitude=0.6, damping=Damping(alpha=0.05))
    assert tr.impact_times.size == 3
    np.testing.assert_allclose(np.mod(tr.impact_times / T, 1.0), pt.impact_phases[0], atol=1e-9)
    np.testing.assert_allclose(tr.impulses, pt.impulses[0], rtol=1e-9)
    x, v = tr.state([T])
    z0, z1 = np.concatenate([pt.x_end, pt.v_end]), np.concatenate([x[:, 0], v[:, 0]])
    assert np.linalg.norm(z1 - z0) <= 1e-8 * np.linalg.norm(z0)
    # its energy is the maximum of E(t) over the period: here at the impact (a corner of E)
    E = tr.energy_at(np.linspace(0, T, 20_001))
    assert E.max() <= pt.energy * (1 + 1e-12) and E.max() >= pt.energy * (1 - 1e-4)
    assert pt.energy == pytest.approx(tr.energy()[0], rel=1e-10)


def test_sweep_reports_a_non_periodic_state(sweep_points):
    pt = {p.T: p for p in sweep_points}[5.0]
    assert pt.complete and not pt.periodic and pt.label == "non-periodic" and pt.p is None and pt.k is None
    assert pt.residual > 1e-2
    # not a longer period either (up to 8 forcing periods), nor a slow transient (damping time 1/σ₁ ≈ 52)
    again = forced_point(TWO_DOF, 5.0, x0=pt.x_end, v0=pt.v_end, max_p=8, **{**SWEEP, "n_periods": 100})
    assert not again.periodic and again.residual > 1e-2


def test_sweep_order_continuation_and_executor(sweep_points):
    assert [p.T for p in sweep_points] == [5.0, 4.5]                 # "up": increasing forcing frequency
    mapped = forced_sweep(TWO_DOF, [5.0, 4.5], continuation=False, executor=SerialExecutor(), progress=False,
                          **SWEEP)
    assert [(p.T, p.label, p.energy) for p in mapped] == [(p.T, p.label, p.energy) for p in sweep_points]
    down = forced_sweep(TWO_DOF, [4.5, 4.6], direction="down", progress=False, **{**SWEEP, "n_periods": 60})
    assert [p.T for p in down] == [4.5, 4.6]
    # continuation: the second run starts from the first one's end state
    follow = forced_point(TWO_DOF, 4.6, x0=down[0].x_end, v0=down[0].v_end, **{**SWEEP, "n_periods": 60})
    assert follow.energy == down[1].energy


def test_chattering_stops_the_run():
    """e < 1 with a slow push into the obstacle: impacts accumulate, the run is reported incomplete."""
    pt = forced_point(TWO_DOF, 40.0, damping=Damping(alpha=0.01), amplitude=2.0, restitution=0.5, n_periods=9)
    assert not pt.complete and pt.label == "incomplete" and np.isnan(pt.energy)


def test_bad_input():
    with pytest.raises(ValueError, match="alpha"):
        Damping(alpha=-0.1)
    with pytest.raises(ValueError, match="not both"):
        Damping(alpha=0.1, zeta=0.02)
    with pytest.raises(ValueError, match="zeta has 3 ratios"):
        Damping(zeta=[0.1, 0.2, 0.3]).ratios(np.ones(2))
    with pytest.raises(ValueError, match="forcing period"):
        simulate_forced(TWO_DOF, np.zeros(2), np.zeros(2), 1.0, amplitude=1.0)
    with pytest.raises(ValueError, match="restitution"):
        simulate_forced(TWO_DOF, np.zeros(2), np.zeros(2), 1.0, period=2.0, amplitude=1.0, restitution=0.0)
    with pytest.raises(ValueError, match="load"):
        simulate_forced(TWO_DOF, np.zeros(2), np.zeros(2), 1.0, period=2.0, amplitude=1.0, load=[1.0])
    with pytest.raises(ValueError, match="damping must be a Damping"):
        simulate_forced(TWO_DOF, np.zeros(2), np.zeros(2), 1.0, period=2.0, damping=0.01)
    with pytest.raises(ValueError, match="direction"):
        forced_sweep(TWO_DOF, [3.0], direction="sideways")
    with pytest.raises(ValueError, match="n_periods"):
        forced_point(TWO_DOF, 3.0, n_periods=5, max_p=4)
    with pytest.raises(ValueError, match="forcing period T"):
        forced_point(TWO_DOF, -1.0)
