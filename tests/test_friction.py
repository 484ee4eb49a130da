"""Coulomb friction with rotation-dominated sliding (bladecase.nsm.massless.friction): friction off is bit for bit
the model without it; closed forms on a 1-dof and a 2-dof tip; an independent integrator; the energy balance."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from test_nodes import V0, X0, chain

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction, FrictionFlight, lemke, simulate_friction, sliding_check
from bladecase.nsm.massless.friction_energy import energy_balance, stored_energy
from bladecase.nsm.massless.friction_rub import friction_rub
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, Rub, simulate_nodes


def two_nodes() -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[4.0, 4.0])


def chain_friction(mu: float = 0.15) -> Friction:
    """Tangential couplings of the chain's two contacts, and a small normal–tangential compliance of their own."""
    T = np.array([[0.2, 0.0], [0.5, 0.1], [0.0, 0.6]])
    return Friction(mu, T=T, C_nt=[[0.02, 0.005], [0.0, 0.03]], C_tt=[[0.1, 0.01], [0.01, 0.08]])


# ----------------------------------------------------------------------------- friction off: bit for bit


def test_friction_off_is_bit_for_bit():
    s, d, rub = chain(12.0), Damping(zeta=0.02), Rub(3, 0.3, 0.7, (0.0, 0.4))
    plain = simulate_nodes(s, X0, V0, 40.0, damping=d, rub=rub)
    off = simulate_friction(s, chain_friction(0.0), X0, V0, 40.0, damping=d, rub=rub)
    assert type(off.flight) is NodalFlight
    for name in ("starts", "active", "q", "p", "amplitudes"):
        assert np.array_equal(getattr(plain, name), getattr(off, name)), name
    assert plain.switch_times.size > 10
    # the rub with friction off: the same trajectory again, and no friction work
    r0 = friction_rub(two_nodes(), Friction(0.0, T=np.eye(2)), 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), 3)
    ref = simulate_nodes(two_nodes(), np.zeros(2), np.zeros(2), 3 * 2 * np.pi / 0.4, Damping(zeta=0.05),
                         Rub(3, 1.2, 0.4, (0.0, 0.3)))
    assert np.array_equal(r0.trajectory.starts, ref.starts) and np.array_equal(r0.trajectory.q, ref.q)
    assert all(e.friction == 0.0 for e in r0.energy) and r0.worst_relative < 1e-10


def test_friction_flight_with_no_tangential_coupling_matches_the_model_without():
    """μ > 0 with T = 0 and no compliance coupling: another path (non-symmetric eigen-solution, Lemke), the same
    motion within round-off."""
    s, d, rub = chain(12.0), Damping(zeta=0.02), Rub(3, 0.3, 0.7, (0.0, 0.4))
    plain = simulate_nodes(s, X0, V0, 30.0, damping=d, rub=rub)
    fr = simulate_friction(s, Friction(0.3, T=np.zeros((3, 2))), X0, V0, 30.0, damping=d, rub=rub)
    assert isinstance(fr.flight, FrictionFlight)
    assert fr.switch_times.size == plain.switch_times.size > 10
    assert np.max(np.abs(fr.switch_times - plain.switch_times)) < 1e-10
    assert np.max(np.abs(fr.x_end - plain.x_end)) < 1e-9


# ----------------------------------------------------------------------------- closed forms


def test_one_dof_closed_form():
    """One mode (ω = 1) moving along the normal and the tangent (T = τ): the drag μλτ is a stiffness change in
    contact, ``q'' + q + (1 − μτ)k_c(q − g) = 0``. From ``q = g`` at speed ``v``: the penetration ``δ`` solves
    ``(1 + (1 − μτ)k_c)δ² + 2gδ − v² = 0``; friction gives ``μτk_cδ²/2`` on the way in and takes it back on the
    way out (one cycle loses nothing); the contact lasts ``2φ/ω_c``."""
    kc, g, v, mu, tau = 30.0, 1.0, 1.5, 0.2, 0.7
    s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[1.0 / kc]], gap=[g])
    f = Friction(mu, T=[[tau]])
    tr = simulate_friction(s, f, [g], [v], 12.0)
    k_in = 1 + (1 - mu * tau) * kc
    delta = (-2 * g + np.sqrt(4 * g * g + 4 * k_in * v * v)) / (2 * k_in)
    wc, xe = np.sqrt(k_in), (1 - mu * tau) * kc * g / k_in
    t_c = 2 * np.arctan2(v / wc, g - xe) / wc
    A = np.hypot(g, v)
    t_f = (2 * np.pi - 2 * np.arccos(g / A))
    assert tr.switch_times[:4] == pytest.approx([t_c, t_c + t_f, 2 * t_c + t_f, 2 * (t_c + t_f)], rel=1e-12)
    E0 = 0.5 * v * v + 0.5 * g * g
    t_peak = 0.5 * t_c
    gain = mu * tau * kc * delta**2 / 2
    e_in = energy_balance(tr, 0.0, t_peak)
    e_out = energy_balance(tr, t_peak, t_c)
    assert e_in.friction == pytest.approx(gain, rel=1e-10)
    assert e_out.friction == pytest.approx(-gain, rel=1e-10)
    assert stored_energy(tr, [t_peak])[0] == pytest.approx(E0 + gain, rel=1e-10)
    cycle = energy_balance(tr, 0.0, t_c + t_f)
    assert abs(cycle.friction) < 1e-10 * gain and abs(cycle.relative) < 1e-12


def tip_closed_form(wx, wz, kc, g, v0, z0, dz0, mu, cycles):
    """The 2-dof tip (normal ``x``, tangential ``z``): ``x'' + ωx²x = −λ``, ``z'' + ωz²z = μλ``,
    ``λ = k_c(x − g)⁺``. ``x`` repeats each cycle (contact ``t_c``, flight ``t_f``); ``ζ = z' + iω_z z`` obeys
    ``ζ' = iω_zζ + μλ``: ``ζ_{k+1} = e^{iω_z(t_c+t_f)}(ζ_k + μI)``, ``I = ∫₀^{t_c} e^{−iω_z s}λ(s) ds`` in closed form.
    Returns the cycle's length and the energy at the start of each cycle."""
    wc = np.sqrt(wx * wx + kc)
    xe = kc * g / wc**2
    R, phi = np.hypot(g - xe, v0 / wc), np.arctan2(v0 / wc, g - xe)
    t_c = 2 * phi / wc

    def ex(a):  # ∫₀^{t_c} e^{ias} ds
        return (np.exp(1j * a * t_c) - 1) / (1j * a) if a != 0 else t_c

    cos_part = 0.5 * (np.exp(-1j * phi) * ex(wc - wz) + np.exp(1j * phi) * ex(-(wc + wz)))
    integral = kc * R * (cos_part - np.cos(phi) * ex(-wz))
    A = np.hypot(g, v0 / wx)
    t_f = (2 * np.pi - 2 * np.arccos(g / A)) / wx
    zeta = dz0 + 1j * wz * z0
    Ex = 0.5 * v0 * v0 + 0.5 * wx * wx * g * g
    energies = []
    for _ in range(cycles + 1):
        energies.append(Ex + 0.5 * abs(zeta) ** 2)
        zeta = np.exp(1j * wz * (t_c + t_f)) * (zeta + mu * integral)
    return t_c + t_f, np.array(energies)


def test_tip_energy_per_cycle_closed_form():
    """The energy lost (or gained) per cycle by the drag μλ on a tangential oscillator, closed form against the
    simulator to 1e-10."""
    wx, wz, kc, g, v0, z0, dz0, mu = 1.0, 1.7, 25.0, 0.8, 1.2, 0.3, -0.4, 0.15
    s = NodalSystem(np.eye(2), np.diag([wx**2, wz**2]), np.array([[1.0], [0.0]]), [[1.0 / kc]], gap=[g])
    f = Friction(mu, T=np.array([[0.0], [1.0]]))
    period, E = tip_closed_form(wx, wz, kc, g, v0, z0, dz0, mu, 4)
    tr = simulate_friction(s, f, [g, z0], [v0, dz0], 4 * period * (1 + 1e-9))
    assert tr.switch_times[1] == pytest.approx(period, rel=1e-12)
    loss = -np.diff(E)
    assert np.abs(loss).min() > 1e-3 * E[0]  # the drag does work every cycle
    sim = stored_energy(tr, period * np.arange(5))
    assert np.abs(-np.diff(sim) - loss).max() < 1e-10 * np.abs(loss).max()
    work = [energy_balance(tr, k * period, (k + 1) * period).friction for k in range(4)]
    assert np.abs(np.array(work) + loss).max() < 1e-10 * np.abs(loss).max()


# ----------------------------------------------------------------------------- an independent integrator


def reference(s: NodalSystem, f: Friction, x0, v0, t_end, damping, rub):
    """solve_ivp (DOP853, rtol 1e-12) on ``M x'' + C x' + S x + (W − μT)λ = 0``, λ from the non-symmetric
    complementarity problem solved by enumerating its supports, restarted at every switch."""
    fl = NodalFlight(s, damping, rub)
    Minv = np.linalg.inv(s.M)
    C = s.M @ fl.phi @ fl.Cq @ fl.phi.T @ s.M
    H = s.H - f.mu * f.C_nt
    drive = s.W - f.mu * f.T
    supports = [np.array(a, dtype=bool) for a in itertools.product([False, True], repeat=s.m)]

    def lam(t, x):
        q = fl.gap(t) - s.W.T @ x
        for A in supports:  # the support whose forces are >= 0 and slacks >= 0
            z = np.zeros(s.m)
            if A.any():
                z[A] = np.linalg.solve(H[np.ix_(A, A)], -q[A])
            w = q + H @ z
            if np.all(z >= -1e-14) and np.all(w[~A] >= -1e-14):
                return np.maximum(z, 0.0)
        raise AssertionError("no support")

    def rhs(t, y):
        x, v = y[: s.n], y[s.n:]
        return np.concatenate((v, Minv @ (-s.S @ x - C @ v - drive @ lam(t, x))))

    def event(j):
        def fn(t, y):
            x = y[: s.n]
            mu = lam(t, x)
            return mu[j] - (fl.gap(t) - s.W.T @ x + H @ mu)[j]
        fn.terminal = True
        return fn

    events = [event(j) for j in range(s.m)]
    t, y, times = 0.0, np.r_[x0, v0], []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-14, events=events)
        y = sol.y[:, -1]
        if sol.status != 1:
            break
        t = min(e[0] for e in sol.t_events if e.size)
        times.append(t)
        step = solve_ivp(rhs, (t, t + 1e-9), y, method="DOP853", rtol=1e-12, atol=1e-14)
        y, t = step.y[:, -1], t + 1e-9
    return np.array(times), y


@pytest.mark.parametrize("casing", [np.inf, 12.0], ids=["rigid", "compliant"])
def test_against_an_independent_integrator(casing):
    s, f, d, rub = chain(casing), chain_friction(0.2), Damping(zeta=0.02), Rub(3, 0.3, 0.7, (0.0, 0.4))
    t_end = 12.0
    tr = simulate_friction(s, f, X0, V0, t_end, damping=d, rub=rub)
    times, y = reference(s, f, X0, V0, t_end, d, rub)
    assert tr.switch_times.size == times.size >= 6
    assert np.max(np.abs(tr.switch_times - times)) < 1e-8  # the reference steps 1e-9 s off each surface
    assert np.max(np.abs(tr.x_end - y[: s.n])) < 1e-8 * np.abs(y[: s.n]).max()


# ----------------------------------------------------------------------------- energy balance, checks


def test_energy_balance_of_a_rub_with_friction_closes():
    s = two_nodes()
    f = Friction(0.15, T=np.array([[0.3, 0.1], [-0.1, 0.4]]), C_nt=[[0.05, 0.01], [0.0, 0.04]],
                 C_tt=[[0.2, 0.02], [0.02, 0.3]], radius=[30.0, 30.0])
    r = friction_rub(s, f, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=4)
    last = r.energy[-1]
    assert r.worst_relative < 1e-10
    assert abs(last.friction) > 1e-3 * abs(last.casing) and last.damping > 0 and last.quadrature_error < 1e-10
    assert r.sliding.ok and r.friction_per_revolution == last.friction
    # the balance must be able to fail: drop the friction work and it does not close
    assert abs(last.stored_change - (last.casing - last.damping)) > 1e3 * abs(last.residual)


def test_sliding_check_flags_slow_speeds():
    s = two_nodes()
    f = Friction(0.15, T=0.3 * np.eye(2), radius=[0.3, 0.3])
    r = friction_rub(s, f, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=2)
    assert not r.sliding.ok and "not dominated by the rotation" in r.sliding.message
    assert np.all(r.sliding.ratio > 0.1)
    fast = sliding_check(r.trajectory, 1e4)
    assert fast.ok and fast.ratio.max() < 1e-3


def test_flutter_is_refused():
    """Friction makes a contact phase's stiffness ``D + k_c(w − μT)wᵀ`` non-symmetric; with ``w = (1, 1)``,
    ``w − μT = (1, −1)`` its eigenvalues solve ``λ² − 2.2λ + 1.2 + 0.2k_c = 0``: complex for ``k_c > 0.05``, one
    phase mode grows (flutter). Refused, in words; with μT halved the phase is stable and flown."""
    s = NodalSystem(np.eye(2), np.diag([1.0, 1.2]), np.array([[1.0], [1.0]]), [[0.01]], gap=[0.5])
    ok = simulate_friction(s, Friction(0.25, T=np.array([[0.0], [4.0]])), [0.6, 0.0], [0.0, 0.0], 5.0)
    assert ok.complete and ok.active[0].tolist() == [True]
    f = Friction(0.5, T=np.array([[0.0], [4.0]]))
    with pytest.raises(ValueError, match="friction-induced flutter"):
        simulate_friction(s, f, [0.6, 0.0], [0.0, 0.0], 5.0)


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="mu must be a finite number >= 0, got nan"):
        Friction(float("nan"), T=np.eye(2))
    with pytest.raises(ValueError, match="valid: rotation"):
        Friction(0.1, T=np.eye(2), model="stick")
    with pytest.raises(ValueError, match=r"C_nt must be a finite \(2, 2\) array"):
        Friction(0.1, T=np.eye(2), C_nt=np.eye(3))
    with pytest.raises(ValueError, match=r"does not match the system's \(n, m\) = \(2, 2\)"):
        simulate_friction(two_nodes(), Friction(0.1, T=np.ones((3, 2))), [0, 0], [0, 0], 1.0)
    with pytest.raises(ValueError, match="radius must be finite and > 0"):
        Friction(0.1, T=np.eye(2), radius=[1.0, -1.0])


def test_lemke_against_enumeration():
    rng = np.random.default_rng(3)
    for _ in range(30):
        m = int(rng.integers(1, 6))
        B = rng.normal(size=(m, m))
        H = B @ B.T + m * np.eye(m) + 0.3 * rng.normal(size=(m, m))  # a P-matrix (positive definite part)
        q = rng.normal(size=m)
        z = lemke(q, H)
        w = q + H @ z
        assert np.all(z >= 0) and np.all(w >= -1e-12) and abs(z @ w) < 1e-12


def test_rub_response_with_friction():
    """The rub figures with friction: ``μ = 0`` gives those without, bit for bit; ``μ = 0.15`` moves them; the
    sweep carries the friction to every speed."""
    from bladecase.nsm.massless.rub import rub_response, rub_sweep

    s, d = two_nodes(), Damping(zeta=0.05)
    args = (s, 0.4, 3, 1.2, [0.0, 0.3], d)
    plain = rub_response(*args, revolutions=6, window=3).as_dict()
    off = rub_response(*args, revolutions=6, window=3, friction=Friction(0.0, T=0.3 * np.eye(2))).as_dict()
    assert off == plain
    f = Friction(0.15, T=np.array([[0.3, 0.1], [-0.1, 0.4]]))
    on = rub_response(*args, revolutions=6, window=3, friction=f)
    assert abs(on.peak_force.max() - max(plain["peak_force"])) > 1e-3 * max(plain["peak_force"])
    swept = rub_sweep(s, [0.4], 3, 1.2, [0.0, 0.3], d, revolutions=6, window=3, friction=f)
    assert swept[0].as_dict() == on.as_dict()


def test_lemke_is_scale_free():
    """Flexibilities of a blade's tip nodes are ~1e-8 m/N: the same answer at any scale."""
    H = np.array([[2.0, 0.3, 0.1], [0.7, 1.0, 0.2], [0.0, 0.4, 1.5]])
    q = np.array([-1.0, 0.5, -0.2])
    z = lemke(q, H)
    for s in (1e-9, 1e6):
        assert np.allclose(lemke(q * s, H * s), z, rtol=1e-12, atol=0)
