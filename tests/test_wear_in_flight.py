"""The abradable coating yielding during the flight (:mod:`bladecase.nsm.massless.coating_flight`, ``wear_rub``'s
``coupling="in_flight"``): the force capped at the yield, the removed depth against the closed form, an
independent fixed-step integrator of the same Jenkins law, the energy balance, the elastic flight recovered with
a yield never reached, the removed volume against the profile."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.coating_flight import PLASTIC, CoatingFlight, simulate_coating
from bladecase.nsm.massless.friction import Friction, simulate_friction
from bladecase.nsm.massless.nodes import NodalSystem, Profile, Rub, simulate_nodes
from bladecase.nsm.massless.wear import Abradable
from bladecase.nsm.massless.wear_rub import wear_rub

K_COAT = np.array([100.0, 80.0])
YIELD = np.array([6.0, 5.0])


def _two() -> NodalSystem:
    """Two interior dofs, two contact nodes coupled through their own flexibility, a compliant coating."""
    return NodalSystem(np.diag([1.0, 1.5]), np.array([[2.0, -1.0], [-1.0, 2.5]]), np.array([[1.0, 0.2], [0.3, 1.0]]),
                       [[0.02, 0.005], [0.005, 0.03]], gap=[1.0, 0.8], casing=K_COAT)


def _energy(s: NodalSystem, x, v, lam) -> np.ndarray:
    return 0.5 * np.einsum("ik,ij,jk->k", v, s.M, v) + 0.5 * np.einsum("ik,ij,jk->k", x, s.S, x) + 0.5 * np.einsum(
        "ik,ij,jk->k", lam, s.H, lam)


def test_one_node_closed_form():
    """One node pressed by a mass–spring: the force caps at λ_y to round-off and the depth removed is the closed
    form from the energy: ½K x² + ½Hλ_y² + λ_y(x − g − Hλ_y) = ½v₀², removed = x − g − Hλ_y."""
    h, k, g, ly, v0 = 0.01, 100.0, 1.0, 10.0, 10.0
    s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[h]], gap=[g], casing=[k])
    tr = simulate_coating(s, [ly], [0.0], [v0], 3.0)
    H = h + 1 / k
    x_max = -ly + np.sqrt(ly**2 + 2 * ly * (g + H * ly) - H * ly**2 + v0**2)
    removed = x_max - g - H * ly
    assert abs(tr.removed()[0] - removed) < 1e-10 * removed
    x, _, lam, y = tr.sample(np.linspace(0.0, 3.0, 6001))
    assert lam.max() <= ly * (1 + 1e-12) and lam.max() >= ly * (1 - 1e-12)
    assert abs(x.max() - x_max) < 1e-6 * x_max  # the sampled peak (the grid's resolution)
    assert tr.codes[:, 0].tolist() == [0, 1, 2, 1, 0]
    # the node left its last surface where it stopped: the last elastic phase's surface is the removed depth
    assert abs(tr.surfaces[-2, 0] - removed) < 1e-10 * removed


def _jenkins_forces(s: NodalSystem, b: np.ndarray, ly: np.ndarray, H=None) -> tuple[np.ndarray, np.ndarray]:
    """The Jenkins law's forces and the excess removed, by enumerating every node's state (open, elastic, plastic)
    and keeping the one that satisfies its conditions (``H``: the flexibility the forces see, ``s.H`` by default)."""
    H, m = (s.H if H is None else H), b.size
    for codes in itertools.product((0, 1, 2), repeat=m):
        c = np.array(codes)
        A, P = np.flatnonzero(c == 1), np.flatnonzero(c == 2)
        lam = np.zeros(m)
        lam[P] = ly[P]
        if A.size:
            lam[A] = np.linalg.solve(H[np.ix_(A, A)], b[A] - H[np.ix_(A, P)] @ ly[P])
        slack = -b + H @ lam
        if (np.all(lam[A] >= -1e-13) and np.all(lam[A] <= ly[A] + 1e-13) and np.all(slack[c == 0] >= -1e-13)
                and np.all(slack[P] <= 1e-13)):
            return lam, np.where(c == 2, np.maximum(-slack, 0.0), 0.0)
    raise AssertionError("no state satisfies the Jenkins law")


def _verlet(s: NodalSystem, ly, x, v, t_end: float, dt: float, friction: Friction | None = None):
    """Velocity Verlet with the Jenkins law's return mapping at every force evaluation; with the rotation model's
    ``friction``, the interior driven by ``W − μT`` and the forces seeing ``H − μC_nt``."""
    Minv = np.linalg.inv(s.M)
    w = np.zeros(s.m)
    drive = s.W if friction is None else s.W - friction.mu * friction.T
    H = s.H if friction is None else friction.H(s)

    def accel(x, w):
        lam, dw = _jenkins_forces(s, s.W.T @ x - s.gap - w, ly, H)
        return Minv @ (-s.S @ x - drive @ lam), w + dw

    a, w = accel(x, w)
    for _ in range(int(round(t_end / dt))):
        v = v + 0.5 * dt * a
        x = x + dt * v
        a, w = accel(x, w)
        v = v + 0.5 * dt * a
    return x, v, w


def test_against_fixed_step_integrator():
    """Two coupled nodes yielding and springing back: the exact flight against velocity Verlet with the Jenkins
    law's return mapping: they agree to 2e-5 and the gap closes as the step halves."""
    s, T = _two(), 2.5
    x0, v0 = np.zeros(2), np.array([3.0, 2.0])
    tr = simulate_coating(s, YIELD, x0, v0, T)
    assert (tr.codes == PLASTIC).any(axis=0).all()  # both nodes yield
    x_ex = tr.x_end
    errs = []
    for dt in (2e-3, 1e-3):
        x, _, w = _verlet(s, YIELD, x0, v0, T, dt)
        errs.append((np.abs(x - x_ex).max() / np.abs(x_ex).max(), np.abs(w - tr.removed()).max()
                     / tr.removed().max()))
    assert errs[1][0] < 2e-5 and errs[1][1] < 2e-5
    assert errs[1][0] < 0.7 * errs[0][0]  # it converges to the exact flight


FRICTION = Friction(0.15, T=np.array([[0.3, 0.0], [0.1, 0.5]]), C_nt=np.array([[0.004, 0.001], [0.0, 0.003]]),
                    C_tt=0.01 * np.eye(2))


def test_friction_against_fixed_step_integrator_and_without_yield():
    """With friction (the rotation model): against velocity Verlet with the same law (to 2e-5); with a yield never
    reached, the flight of the elastic casing with friction (``simulate_friction``) to 1e-12."""
    s, T = _two(), 2.5
    x0, v0 = np.zeros(2), np.array([3.0, 2.0])
    tr = simulate_coating(s, YIELD, x0, v0, T, friction=FRICTION)
    assert (tr.codes == PLASTIC).any(axis=0).all()
    x, _, w = _verlet(s, YIELD, x0, v0, T, 1e-3, FRICTION)
    assert np.abs(x - tr.x_end).max() < 2e-5 * np.abs(tr.x_end).max()
    assert np.abs(w - tr.removed()).max() < 2e-5 * tr.removed().max()
    rub, d = Rub(3, 0.7, 0.7, [0.0, 0.4]), Damping(zeta=0.01)
    x0 = np.array([0.5, 0.0])
    ref = simulate_friction(s, FRICTION, x0, v0, 20.0, damping=d, rub=rub)
    tr = simulate_coating(s, [1e9, 1e9], x0, v0, 20.0, damping=d, rub=rub, friction=FRICTION)
    assert ref.switch_times.size > 8 and np.allclose(tr.switch_times, ref.switch_times, rtol=0, atol=1e-12)
    t = np.linspace(0.0, 20.0, 101)
    xr, _, lr = ref.sample(t)
    x, _, lam, _ = tr.sample(t)
    assert np.abs(x - xr).max() < 1e-12 * np.abs(xr).max() and np.abs(lam - lr).max() < 1e-12 * np.abs(lr).max()


def test_worn_profile_against_fixed_step_integrator():
    """A worn profile of 12 cells seen by two nodes over a revolution in a three-lobe casing: nodes yield, spring
    back and, entering a cell less worn than their surface, are pressed beyond their yield and remove the excess at
    once. Against velocity Verlet with the same law (each node on its cell's depth as it enters it, or on its own
    surface while yielding): final state and removed depths to the integrator's first order at the steps."""
    s, speed, phi = _two(), 2.0, np.array([0.0, 0.3])
    rub = Rub(3, 0.5, speed, phi)
    depth = np.array([0.026, 0.071, 0.24, 0.175, 0.028, 0.13, 0.144, 0.048, 0.22, 0.034, 0.117, 0.155])
    turn, x0, v0 = 2 * np.pi / speed, np.zeros(2), np.array([2.0, 1.5])
    tr = simulate_coating(s, YIELD, x0, v0, turn, rub=rub, profile=Profile(depth, speed, phi))
    assert (tr.jumps > 0.1).any() and (tr.codes == PLASTIC).any(axis=0).all()
    h, dt = 2 * np.pi / depth.size, 2e-3

    def accel(x, t, w, cell, plastic):
        c = np.floor((speed * t + phi) / h).astype(int)
        enter = depth[c % depth.size]
        w = np.where(c != cell, np.where(plastic, np.maximum(w, enter), enter), w)
        g = s.gap + (rub.D * np.exp(1j * rub.nu * t)).real
        lam, dw = _jenkins_forces(s, s.W.T @ x - g - w, YIELD)
        return np.linalg.solve(s.M, -s.S @ x - s.W @ lam), w + dw, c, dw > 0, dw

    x, v = x0.copy(), v0.copy()
    a, w, cell, plastic, removed = accel(x, 0.0, np.full(2, depth[0]), np.zeros(2, int), np.zeros(2, bool))
    for k in range(int(round(turn / dt))):
        v = v + 0.5 * dt * a
        x = x + dt * v
        a, w, cell, plastic, dw = accel(x, (k + 1) * dt, w, cell, plastic)
        removed = removed + dw
        v = v + 0.5 * dt * a
    assert np.abs(x - tr.x_end).max() < 3e-3 * np.abs(tr.x_end).max()
    assert np.abs(removed - tr.removed()).max() < 3e-3 * tr.removed().max()


def test_energy_balance():
    """No damping, a round casing: the energy plus the plastic work λ_y × removed depth of each node is conserved."""
    s = _two()
    x0, v0 = np.zeros(2), np.array([3.0, 2.0])
    tr = simulate_coating(s, YIELD, x0, v0, 6.0)
    t = np.linspace(0.0, 6.0, 7)
    x, v, lam, _ = tr.sample(t)
    e0 = _energy(s, x0[:, None], v0[:, None], np.zeros((2, 1)))[0]
    e_end = _energy(s, x[:, -1:], v[:, -1:], lam[:, -1:])[0]
    work = float(YIELD @ tr.removed())
    assert work > 0.1 * e0
    assert abs(e_end + work - e0) < 1e-10 * e0
    assert lam.max() <= YIELD.max() * (1 + 1e-12)


def test_huge_yield_is_the_elastic_flight():
    """A yield never reached: the flight of the elastic casing (``simulate_nodes``), damped, out-of-round."""
    s, rub, d = _two(), Rub(3, 0.7, 0.7, [0.0, 0.4]), Damping(zeta=0.01)
    x0, v0 = np.array([0.5, 0.0]), np.array([3.0, 2.0])
    ref = simulate_nodes(s, x0, v0, 20.0, damping=d, rub=rub)
    tr = simulate_coating(s, [1e9, 1e9], x0, v0, 20.0, damping=d, rub=rub)
    assert ref.switch_times.size > 8 and np.allclose(tr.switch_times, ref.switch_times, rtol=0, atol=1e-12)
    t = np.linspace(0.0, 20.0, 101)
    xr, _, lr = ref.sample(t)
    x, _, lam, _ = tr.sample(t)
    assert np.abs(x - xr).max() < 1e-12 * np.abs(xr).max() and np.abs(lam - lr).max() < 1e-12 * np.abs(lr).max()
    assert float(np.abs(tr.removed()).max()) == 0.0


def _rub_system() -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[4.0, 4.0])


def test_wear_rub_in_flight():
    """The coupled wear with the coating yielding in flight: the pressure never beyond the yield, the removed volume
    equal to the profile's missing area × width; a yield never reached removes nothing, as the staggered coupling."""
    c = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=1.0)
    args = (_rub_system(), c, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05))
    w = wear_rub(*args, revolutions=4, areas=[1.0, 1.0], coupling="in_flight")
    assert w.peak_pressure.max() <= c.yield_pressure * (1 + 1e-12)
    assert w.profile.removed > 0 and abs(w.profile.removed / w.profile.missing_volume - 1) < 1e-6
    assert w.profile.lobes() == 3
    f = Friction(0.1, T=np.array([[0.3, 0.0], [0.1, 0.5]]), C_nt=0.01 * np.eye(2), C_tt=0.1 * np.eye(2))
    wf = wear_rub(*args, revolutions=3, areas=[1.0, 1.0], friction=f)  # the default: in flight, with friction
    assert wf.coupling == "in_flight" and wf.peak_pressure.max() <= c.yield_pressure * (1 + 1e-12)
    assert abs(wf.profile.removed / wf.profile.missing_volume - 1) < 1e-6 and wf.profile.removed != w.profile.removed
    stag = wear_rub(*args, revolutions=4, areas=[1.0, 1.0], coupling="staggered")
    assert stag.peak_pressure.max() > 1.2 * c.yield_pressure  # the elastic revolution overshoots the yield
    hard = Abradable(thickness=1.0, yield_pressure=1e9, stiffness=4.0, cells=60, radius=30.0, width=1.0)
    a = wear_rub(args[0], hard, *args[2:], revolutions=2, areas=[1.0, 1.0], coupling="in_flight")
    b = wear_rub(args[0], hard, *args[2:], revolutions=2, areas=[1.0, 1.0], coupling="staggered")
    assert a.profile.removed == 0.0 == b.profile.removed
    assert np.abs(a.tip - b.tip).max() < 1e-12 * np.abs(b.tip).max()
    assert np.allclose(a.peak_pressure, b.peak_pressure, rtol=1e-12, atol=0)


def test_bad_input():
    s = _rub_system()
    with pytest.raises(ValueError, match=r"yield_force must be finite and > 0 .* got \[-1.0, 1.0\]"):
        CoatingFlight(s, [-1.0, 1.0])
    c = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=1.0)
    with pytest.raises(ValueError, match="coupling must be one of"):
        wear_rub(s, c, 0.4, 3, 1.2, [0.0, 0.3], coupling="later")
    with pytest.raises(ValueError, match=r"coating's stiffness × the node's area, \[4.0, 8.0\] N/m, got \[4.0, 4.0\]"):
        wear_rub(s, c, 0.4, 3, 1.2, [0.0, 0.3], areas=[1.0, 2.0])
    f = Friction(0.1, T=np.eye(2), C_tt=0.1 * np.eye(2), model="coulomb")
    with pytest.raises(ValueError, match="flies the friction model 'rotation', got 'coulomb'"):
        wear_rub(s, c, 0.4, 3, 1.2, [0.0, 0.3], friction=f, coupling="in_flight")
