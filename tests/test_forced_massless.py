"""Forced, damped simulation of the massless contact model (bladecase.nsm.massless.forced, issue 13)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bladecase.nsm import Damping, bar, condense, simulate_massless
from bladecase.nsm.massless.forced import (
    ExpSignal,
    MasslessForcedFlight,
    _ModalPhase,
    _StatePhase,
    simulate_forced_massless,
)
from bladecase.nsm.sweep import forced_point, forced_sweep


def two_dof():
    """Two masses in a chain, a massless contact dof behind the second one (spring 3)."""
    K = np.array([[3.0, -1.0, 0.0], [-1.0, 4.0, -3.0], [0.0, -3.0, 3.0]])
    return condense(np.diag([1.0, 0.5, 0.0]), K, np.array([0.0, 0.0, 1.0]), gap=0.2)


SYSTEMS = {"bar6": lambda: bar(6, 0.05, contact="massless"), "two_dof": two_dof}
DAMPINGS = {"rayleigh": Damping(alpha=0.03, beta=0.01), "ratio": Damping(zeta=0.04), "mass": Damping(beta=0.05),
            "none": None}


def damping_matrix(s, damping):
    if damping is None:
        return np.zeros_like(s.M)
    if damping.zeta is None:
        return damping.alpha * s.S + damping.beta * s.M
    o = s.open
    MP = s.M @ o.phi
    return MP @ np.diag(2 * damping.rates(o.omega)) @ MP.T


def reference(s, damping, period, amplitude, load, g, x0, v0, t_span, phase=None, t_eval=None):
    """``solve_ivp`` (DOP853, rtol 1e-12) of the interior equations: one phase (``"open"``/``"closed"``, the
    multiplier's formula taken without its max) or the nonsmooth model (``phase=None``)."""
    Om, Minv = 2 * np.pi / period, np.linalg.inv(s.M)
    # a = M⁻¹(F₀cos(Ωt) f - Cv - Sx - wλ), with the products by M⁻¹ formed once (solve_ivp calls rhs ~10⁴ times)
    MC, MS, Mw, Mf = (Minv @ a for a in (damping_matrix(s, damping), s.S, s.w, amplitude * np.asarray(load)))
    law = {"open": lambda y: 0.0, "closed": lambda y: s.kc * (y - s.gap), None: lambda y: s.kc * max(0.0, y - s.gap)}
    multiplier = law[phase]

    def rhs(t, z):
        x, v = z[:s.n], z[s.n:]
        c = np.cos(Om * t)
        lam = multiplier(s.w @ x + g * amplitude * c)
        return np.concatenate([v, c * Mf - MC @ v - MS @ x - lam * Mw])

    sol = solve_ivp(rhs, t_span, np.concatenate([x0, v0]), method="DOP853", rtol=1e-12, atol=1e-14,
                    t_eval=t_eval, dense_output=t_eval is None)
    return sol


@pytest.mark.parametrize("name", sorted(SYSTEMS))
@pytest.mark.parametrize("dname", sorted(DAMPINGS))
@pytest.mark.parametrize("which", ["open", "closed"])
def test_phase_flight_matches_solve_ivp(name, dname, which):
    s, damping = SYSTEMS[name](), DAMPINGS[dname]
    rng = np.random.default_rng(3)
    load, g = rng.normal(size=s.n), 0.004
    fl = MasslessForcedFlight(s, period=2.7, amplitude=0.3, damping=damping, load=load, contact_load=g)
    ph = getattr(fl, which)
    if which == "closed":  # the closed phase's flight: state-space unless C is undamped or mass-proportional
        assert isinstance(ph, _StatePhase if dname in ("rayleigh", "ratio") else _ModalPhase)
    x0, v0 = 0.05 * rng.normal(size=s.n), 0.05 * rng.normal(size=s.n)
    t0, taus = 1.3, np.linspace(0.0, 6.0, 13)
    q, p = ph.advance(*np.broadcast_arrays(*[a[:, None] for a in fl.encode(x0, v0)]), np.full(13, t0), taus)
    x, v = fl.decode(q, p)
    sol = reference(s, damping, 2.7, 0.3, load, g, x0, v0, (t0, t0 + 6.0), which, t0 + taus)
    scale = np.abs(sol.y).max()
    assert np.abs(np.vstack([x, v]) - sol.y).max() <= 1e-10 * scale
    # the switching signal (y - d open, d - y closed) of the same flight
    sig = ph.signal(*fl.encode(x0, v0), t0, 10.0)
    y = s.w @ sol.y[:s.n] + g * 0.3 * np.cos(2 * np.pi / 2.7 * (t0 + taus))
    dy = s.w @ sol.y[s.n:] - g * 0.3 * 2 * np.pi / 2.7 * np.sin(2 * np.pi / 2.7 * (t0 + taus))
    sign = 1.0 if which == "open" else -1.0
    f, df = sig(taus)
    assert np.abs(f - sign * (y - s.gap)).max() <= 1e-10 * scale
    assert np.abs(df - sign * dy).max() <= 1e-10 * scale


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_curvature_bound_holds(name):
    """The certified bound B₂ of the closed phase's state-space signal dominates |f''| (finite differences)."""
    s = SYSTEMS[name]()
    fl = MasslessForcedFlight(s, period=2.1, amplitude=0.4, damping=DAMPINGS["rayleigh"], contact_load=0.01)
    rng = np.random.default_rng(5)
    sig = fl.closed.signal(*fl.encode(0.1 * rng.normal(size=s.n), rng.normal(size=s.n)), 0.7, 50.0)
    assert isinstance(sig, ExpSignal)
    tau = np.linspace(0, 50, 20001)
    _, df = sig(tau)
    curv = np.abs(np.diff(df) / np.diff(tau)).max()
    assert 0.3 * sig.curvature_bound < curv <= sig.curvature_bound


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_undamped_unforced_matches_simulate_massless(name):
    s = SYSTEMS[name]()
    rng = np.random.default_rng(11)
    x0 = 0.3 * s.gap * rng.normal(size=s.n) / max(abs(s.w).max(), 1e-300)
    v0 = rng.normal(size=s.n)
    ref = simulate_massless(s, x0, v0, 30.0)
    tr = simulate_forced_massless(s, x0, v0, 30.0)
    assert ref.switch_times.size >= 6 and tr.phases == ref.phases
    assert np.abs(tr.switch_times - ref.switch_times).max() <= 1e-9
    assert np.abs(tr.x_end - ref.x_end).max() <= 1e-9 * np.abs(ref.x_end).max()


@pytest.mark.parametrize("name", sorted(SYSTEMS))
@pytest.mark.parametrize("dname", sorted(DAMPINGS))
def test_trajectory_matches_solve_ivp_and_balances_energy(name, dname):
    """The whole forced run (several contact phases) against solve_ivp of the nonsmooth equations, and its
    energy budget."""
    s, damping = SYSTEMS[name](), DAMPINGS[dname]
    load, g, T, F0 = np.ones(s.n), 0.002, 3.1, 0.5 if name == "two_dof" else 0.04
    tr = simulate_forced_massless(s, np.zeros(s.n), np.zeros(s.n), 25.0, period=T, amplitude=F0, damping=damping,
                                  load=load, contact_load=g)
    assert tr.complete and tr.contact_times.size >= 2
    t = np.linspace(0, 25.0, 51)
    sol = reference(s, damping, T, F0, load, g, np.zeros(s.n), np.zeros(s.n), (0, 25.0), None, t)
    x, v = tr.state(t)
    assert np.abs(np.vstack([x, v]) - sol.y).max() <= 1e-8 * np.abs(sol.y).max()  # solve_ivp: C⁰ kinks
    b = tr.energy_balance()
    assert abs(b.residual) <= 1e-8 * max(abs(b.work), b.dissipated, b.final)
    # switches at y = d, λ >= 0 exactly where closed, ≈ 0 where open
    y = s.w @ tr.x + g * F0 * np.cos(2 * np.pi / T * tr.switch_times)
    assert np.abs(y - s.gap).max() <= 1e-12 * s.gap * 1e3
    mid = 0.5 * (np.append(tr.switch_times, 25.0) + np.concatenate([[0.0], tr.switch_times]))
    lam = tr.multiplier_at(mid)
    assert np.array_equal(lam > 0, tr._closed)
    assert np.all(tr.impulses > 0) and tr.impulses.size == tr.contact_times.size


def test_linear_forced_matches_harmonic_closed_form():
    """No contact (large gap): from the steady state, the run stays on ``Re(X e^{iΩt})``, X = (S - Ω²M + iΩC)⁻¹f."""
    s = bar(8, 50.0, contact="massless")
    damping, T, F0 = Damping(alpha=0.02, beta=0.03), 5.0, 0.7
    f = np.linspace(1.0, 2.0, s.n)
    Om = 2 * np.pi / T
    X = np.linalg.solve(s.S - Om**2 * s.M + 1j * Om * damping_matrix(s, damping), F0 * f)
    tr = simulate_forced_massless(s, X.real, (1j * Om * X).real, 40.0, period=T, amplitude=F0, damping=damping,
                                  load=f)
    assert tr.switch_times.size == 0
    t = np.linspace(0, 40.0, 81)
    x, v = tr.state(t)
    E = np.exp(1j * Om * t)
    assert np.abs(x - np.outer(X, E).real).max() <= 1e-12 * np.abs(X).max()
    assert np.abs(v - np.outer(1j * Om * X, E).real).max() <= 1e-12 * Om * np.abs(X).max()


def test_bad_input():
    s = two_dof()
    with pytest.raises(ValueError, match="MasslessSystem"):
        simulate_forced_massless(bar(5, 0.1, contact="newton"), np.zeros(5), np.zeros(5), 1.0)
    with pytest.raises(ValueError, match="period is needed"):
        simulate_forced_massless(s, np.zeros(2), np.zeros(2), 1.0, amplitude=1.0)
    with pytest.raises(ValueError, match="2 interior dofs"):
        simulate_forced_massless(s, np.zeros(3), np.zeros(2), 1.0)
    with pytest.raises(ValueError, match="t_end"):
        simulate_forced_massless(s, np.zeros(2), np.zeros(2), -1.0)
    with pytest.raises(ValueError, match="load must be"):
        simulate_forced_massless(s, np.zeros(2), np.zeros(2), 1.0, period=1.0, amplitude=1.0, load=[1.0])
    with pytest.raises(ValueError, match="zeta has 3 ratios"):
        MasslessForcedFlight(s, period=2.0, amplitude=1.0, damping=Damping(zeta=[0.1, 0.1, 0.1]))
    tr = simulate_forced_massless(s, [0.3, 0.5], np.zeros(2), 50.0, max_switches=3)
    assert not tr.complete and tr.switch_times.size == 3 and tr.t_end == tr.switch_times[-1]


def test_load_on_the_contact_dof_matches_the_full_model():
    """A load on the massless contact dof (condensed load + contact_load g) against solve_ivp of the FULL
    3-dof model, whose massless contact dof is solved statically at every instant (free, or held at d)."""
    K = np.array([[3.0, -1.0, 0.0], [-1.0, 4.0, -3.0], [0.0, -3.0, 3.0]])
    f_full, d, T, F0 = np.array([0.3, -0.2, 1.0]), 0.2, 3.1, 0.4
    s = two_dof()
    f_r = f_full[:2] - K[:2, 2] * f_full[2] / K[2, 2]
    g = f_full[2] / K[2, 2]  # w_cᵀK_cc⁻¹f_c
    damping = Damping(alpha=0.03, beta=0.01)
    C, Om, Minv = damping_matrix(s, damping), 2 * np.pi / T, np.diag([1.0, 2.0])

    def rhs(t, z):
        x, v = z[:2], z[2:]
        F = F0 * np.cos(Om * t)
        xc = min((F * f_full[2] - K[2, :2] @ x) / K[2, 2], d)  # free contact dof, or held by the casing at d
        a = Minv @ (F * f_full[:2] - K[:2, :2] @ x - K[:2, 2] * xc - C @ v)
        return np.concatenate([v, a])

    tr = simulate_forced_massless(s, np.zeros(2), np.zeros(2), 25.0, period=T, amplitude=F0, damping=damping,
                                  load=f_r, contact_load=g)
    assert tr.contact_times.size >= 3
    t = np.linspace(0, 25.0, 51)
    sol = solve_ivp(rhs, (0, 25.0), np.zeros(4), method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t)
    assert np.abs(np.vstack(tr.state(t)) - sol.y).max() <= 1e-8 * np.abs(sol.y).max()


def test_forced_massless_bar_sweep_is_periodic_and_resimulates_to_itself():
    """A massless bar (20 elements) swept near its first mode: periodic steady states with contact phases, each
    re-simulated over its p forcing periods from its end state back to itself."""
    s = bar(20, 0.01, contact="massless")
    f, damping, F0 = np.ones(s.n) / s.n, Damping(zeta=0.02), 0.02
    # 100 periods settle every point to a stroboscopic residual <= 5e-12 (measured; 150 gave <= 1.3e-12): the
    # 1e-9 below keeps a margin of 200 (80 periods: 9e-10, too close)
    pts = forced_sweep(s, [3.2, 3.8, 4.3], damping=damping, amplitude=F0, load=f, n_periods=100)
    assert [pt.T for pt in pts] == [4.3, 3.8, 3.2]  # "up" in frequency
    assert [pt.label for pt in pts] == ["1/1", "2/1", "1/1"]
    for pt in pts:
        assert pt.residual <= 1e-9 and pt.impulses.size == pt.k and np.all(pt.impulses > 0)
        tr = simulate_forced_massless(s, pt.x_end, pt.v_end, pt.p * pt.T, period=pt.T, amplitude=F0,
                                      damping=damping, load=f)
        z0, z1 = np.concatenate([pt.x_end, pt.v_end]), np.concatenate([tr.x_end, tr.v_end])
        assert np.linalg.norm(z1 - z0) <= 1e-8 * np.linalg.norm(z0)
        assert tr.contact_times.size == pt.k
        assert np.allclose(np.sort(np.mod(tr.contact_times / pt.T, 1.0)), np.sort(np.mod(pt.impact_phases, 1.0)),
                           atol=1e-8)
        e = tr.energy_at(np.linspace(0, pt.T, 400))
        assert e.max() <= pt.energy * (1 + 1e-12) and e.max() >= pt.energy * (1 - 1e-3)
    with pytest.raises(ValueError, match="restitution applies to Newton"):
        forced_point(s, 4.0, damping=damping, amplitude=F0, load=f, n_periods=20, restitution=0.9)
    with pytest.raises(ValueError, match="massless contact model only"):
        forced_point(bar(5, 0.1, contact="newton"), 4.0, n_periods=20, contact_load=0.1)
