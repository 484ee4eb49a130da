"""The massless contact model (theory §8): exact dynamics, simulator, one-phase orbits, the bar and its continuum.

Tolerances: closed-form flight vs solve_ivp 1e-9 (relative, per phase); energy over 1000 contact phases 1e-10;
bilinear oscillator period–energy relation 1e-10; orbit return after one period 1e-8; continuum Signorini
conditions to round-off.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bladecase.nsm.massless.bar import bar, bar_continuum_energy, bar_continuum_field
from bladecase.nsm.massless.model import condense, redistribute_mass, simulate_massless
from bladecase.nsm.massless.orbits import follow_from_grazing


def bilinear(m=1.0, k1=1.0, k2=3.0, d=1.0):
    """Mass m on spring k1 to the wall, spring k2 to a massless contact point at gap d."""
    return condense(np.diag([m, 0.0]), np.array([[k1 + k2, -k2], [-k2, k2]]), np.array([0.0, 1.0]), d)


def bilinear_period(E, m=1.0, k1=1.0, k2=3.0, d=1.0):
    """Closed form: open flight from the turning point -A₁ to x = d, closed flight about x_eq to the turning point."""
    w1, w2, x_eq = np.sqrt(k1 / m), np.sqrt((k1 + k2) / m), k2 * d / (k1 + k2)
    A1 = np.sqrt(2 * E / k1)
    A2 = np.hypot(d - x_eq, w1 * np.sqrt(A1**2 - d**2) / w2)
    return 2 * (np.arccos(-d / A1) / w1 + np.arccos((d - x_eq) / A2) / w2)


def test_condensation_of_the_bilinear_oscillator():
    s = bilinear()
    assert s.S.tolist() == [[1.0]] and s.w.tolist() == [1.0] and s.kc == 3.0


@pytest.mark.parametrize("k2", [3.0, 1.0, 0.5])
def test_bilinear_branch_matches_the_closed_form_period_energy_relation(k2):
    """Also with k2 <= k1, where a plain Newton step for the first point jumped over the residual's pole."""
    s = bilinear(k2=k2)
    T_inf = np.pi + np.pi / np.sqrt(1 + k2)  # the high-energy limit: half a period in each phase
    orbits = follow_from_grazing(s, T_min=T_inf + 0.03 * (2 * np.pi - T_inf), ds=0.02)
    assert len(orbits) > 20
    assert orbits[0].T == pytest.approx(2 * np.pi, rel=1e-6)  # grazing: the free linear mode
    for o in orbits[1:]:
        assert o.admissible
        assert o.T == pytest.approx(bilinear_period(o.energy, k2=k2), rel=1e-10)
    assert orbits[-1].T < T_inf + 0.1 * (2 * np.pi - T_inf)  # stiffening: frequency rises with energy


def random_system(seed=1, n=5, gap=0.3):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    M = np.diag(np.r_[rng.uniform(0.5, 2.0, n - 1), 0.0])
    w = np.zeros(n)
    w[-1] = 1.0
    return condense(M, A @ A.T + n * np.eye(n), w, gap), rng


def test_simulator_matches_solve_ivp_phase_by_phase():
    s, rng = random_system()
    x0, v0 = rng.standard_normal(s.n), 2 * rng.standard_normal(s.n)
    tr = simulate_massless(s, x0, v0, 5.0)
    assert len(tr.switch_times) >= 4

    def rhs(t, z, closed):
        x, v = z[: s.n], z[s.n:]
        f = -s.S @ x - (s.kc * s.w * (s.w @ x - s.gap) if closed else 0.0)
        return np.r_[v, np.linalg.solve(s.M, f)]

    z, t, closed = np.r_[x0, v0], 0.0, bool(s.w @ x0 > s.gap)
    for k, tk in enumerate(tr.switch_times):
        ref = solve_ivp(rhs, (t, tk), z, args=(closed,), method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
        exact = np.r_[tr.x[:, k], tr.v[:, k]]
        assert np.abs(ref - exact).max() <= 1e-9 * np.abs(exact).max()
        assert s.w @ tr.x[:, k] == pytest.approx(s.gap, rel=1e-12)  # every switch is on y = d
        z, t, closed = exact, tk, tr.phases[k] == "closed"


def test_energy_is_conserved_over_1000_contact_phases():
    s, rng = random_system(seed=2)
    x0, v0 = rng.standard_normal(s.n), 2 * rng.standard_normal(s.n)
    tr = simulate_massless(s, x0, v0, 1e9, max_switches=2000)
    assert len(tr.switch_times) == 2000 and not tr.complete
    E0 = s.energy(x0, v0)
    E = [s.energy(tr.x[:, k], tr.v[:, k]) for k in range(0, 2000, 97)]
    assert np.abs(np.array(E) - E0).max() <= 1e-10 * E0


@pytest.mark.parametrize("n", [25, 100])
def test_admissible_bar_orbits_come_back_in_the_simulator(n):
    s = bar(n, 0.5, contact="massless")
    orbits = follow_from_grazing(s, T_min=3.9, ds=1e-3, max_points=60)
    checked = 0
    for o in orbits[1::6]:
        if not o.admissible:
            continue
        x, v = o.closing_state()
        tr = simulate_massless(s, x, v, o.T)
        # from the closing state: closed for 2β, then open; the next closing is at T (the horizon), within round-off
        assert tr.phases[0] == "open" and tr.switch_times[0] == pytest.approx(2 * o.beta, rel=1e-8)
        assert len(tr.switch_times) == 1 or tr.switch_times[1] == pytest.approx(o.T, rel=1e-9)
        scale = np.abs(x).max()
        assert np.abs(tr.x_end - x).max() <= 1e-8 * scale
        assert np.abs(tr.v_end - v).max() <= 1e-8 * np.abs(v).max()
        checked += 1
    assert checked >= 2


def test_non_admissible_orbits_are_told_apart():
    s = bar(50, 0.5, contact="massless")
    # max_points only stops the continuation: the first 40 points are those of a longer run, and the first
    # non-admissible one is point 12 (measured)
    orbits = follow_from_grazing(s, T_min=3.8, ds=1e-3, max_points=40)
    flags = [o.admissible for o in orbits]
    assert flags[1] and not all(flags)  # admissible near grazing, λ < 0 inside the contact further on
    bad = orbits[flags.index(False)]
    _, closed = bad.proofs
    assert not closed.certified and closed.value > 0  # d - y > 0 somewhere in the contact phase: λ < 0


def test_bar_models_and_mass_redistribution():
    s = bar(10, 0.5, contact="massless")
    assert np.trace(s.M) == pytest.approx(0.95, rel=1e-14)  # total free mass ρA(L - h/2) kept
    x = np.arange(1, 10) / 10
    full_moment = (np.r_[np.full(9, 0.1), 0.05] * np.arange(1, 11) / 10).sum()
    assert np.diag(s.M) @ x == pytest.approx(full_moment, rel=1e-14)  # centre of mass kept
    assert s.kc == pytest.approx(10.0)
    newton = bar(10, 0.5, contact="newton")
    assert newton.n == 10 and newton.gap == 0.5
    with pytest.raises(ValueError, match="contact must be one of newton, massless"):
        bar(10, 0.5, contact="penalty")
    with pytest.raises(ValueError, match="n \\(elements\\) must be an integer >= 3"):
        bar(2, 0.5)
    with pytest.raises(ValueError, match="would make a mass non-positive"):
        redistribute_mass(np.array([0.1, 0.1, 1.0]), np.array([0.0, 1.0, 2.0]), 2, np.array([0, 1]))
    with pytest.raises(ValueError, match="carry mass"):
        condense(np.eye(2), np.array([[2.0, -1.0], [-1.0, 1.0]]), np.array([0.0, 1.0]), 1.0)
    with pytest.raises(ValueError, match="cannot keep both the total mass and the centre of mass"):
        redistribute_mass(np.array([1.0, 1.0, 1.0]), np.array([0.0, 1.0, 2.0]), 2, np.array([0]))


@pytest.mark.parametrize("T", [3.35, 3.45, 3.55])
def test_continuum_solution_satisfies_signorini_and_its_energy(T):
    d = 0.5
    u, u_t, u_x = bar_continuum_field(T, d)
    t = np.linspace(0.0, T, 40001)[:-1] + 1e-9
    tip, stress = u(1.0, t), u_x(1.0, t)
    closed = np.abs(tip - d) <= 1e-12
    assert tip.max() <= d + 1e-12                                  # never beyond the casing
    assert np.abs(stress[~closed]).max() == 0.0                    # free end while open
    assert stress[closed].max() < 0                                # compression while closed
    assert closed.mean() * T == pytest.approx(4 - T, abs=2 * T / t.size)  # contact lasts 4 - T
    assert np.abs(u(0.0, t)).max() == 0.0                          # fixed end
    assert np.abs(u(0.37, t + T) - u(0.37, t)).max() <= 1e-12      # T-periodic
    x = np.linspace(0, 1, 2001)
    for tk in (0.3, 1.7, 2.9):  # energy by quadrature (exact for the piecewise-constant fields)
        e = 0.5 * (u_t(x, tk) ** 2 + u_x(x, tk) ** 2)
        assert np.trapezoid(e, x) == pytest.approx(float(bar_continuum_energy(T, d)), rel=2e-3)


def test_band_limited_energy_of_the_bar_mode_converges_to_the_continuum():
    """The measure that converges (docs/massless.md): at T = 3.45, the smoothest one-phase orbit's energy in the
    lowest 10 modes approaches the continuum's with an observed order >= 1.5 and is within 1 % at n = 200, while
    the total energy stays > 10 % off (mesh-scale modes)."""
    from bladecase.nsm.massless.bar import bar_continuum_band_energy
    from bladecase.nsm.massless.orbits import orbits_at_period, smoothest

    T, d, K = 3.45, 0.5, 10
    ref = bar_continuum_band_energy(T, d, K)
    errors, totals = [], []
    for n in (50, 100, 200):
        o = smoothest(orbits_at_period(bar(n, d), T, samples=3 * n), K)
        assert o.contact_time == pytest.approx(4 - T, abs=0.06)
        errors.append(abs(o.band_energy(K) / ref - 1))
        totals.append(o.energy / float(bar_continuum_energy(T, d)) - 1)
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert orders.min() >= 1.5, (errors, orders)
    assert errors[-1] <= 0.01
    assert min(totals) > 0.10  # the total energy does not converge: say so, do not hide it


def test_nonsmooth_mode_api_on_the_massless_bar():
    """The API contract: ``nonsmooth_mode(bar(...), k=1, T_range)`` gives the branch type whose ``orbit_at(T)``
    returns orbits with ``.T``, ``.energy``, ``.admissible``, ``.state(t)``; records and pickles are light."""
    import pickle

    import bladecase as bc

    s = bc.bar(20, 0.5, contact="massless")
    (branch,) = bc.nonsmooth_mode(s, k=1, T_range=(3.8, 4.1))
    assert isinstance(branch, bc.Branch) and branch.k == 1 and len(branch.arcs) >= 1
    arc = branch.arcs[0]
    assert arc.T_hi == pytest.approx(4.0, abs=0.01) and not arc.refined_hi  # starts at grazing: T_hi = T₁
    assert arc.refined_lo  # where admissibility is lost, refined by bisection along the curve
    (orbit,) = [o for o in branch.orbit_at(3.95) if o.admissible]
    assert orbit.T == 3.95 and orbit.state(np.array([0.0, 1.0]))[0].shape == (s.n, 2)
    # within 10 % of the continuum (the discrete branch's energy is not the converging measure: docs/massless.md)
    assert orbit.energy == pytest.approx(bc.nsm.bar_continuum_energy(3.95, 0.5), rel=0.1)
    assert bc.verify(orbit)["ok"]
    back = bc.Branch.from_dict(s, branch.to_dict())
    assert back.arcs == branch.arcs and np.allclose(back.energy, branch.energy, rtol=1e-12)
    assert len(pickle.dumps(orbit)) < 4000 and pickle.loads(pickle.dumps(orbit)).system is None
    with pytest.raises(ValueError, match="one contact phase per period"):
        bc.nonsmooth_mode(s, k=2, T_range=(3.8, 4.1))
