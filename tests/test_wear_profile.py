"""A general clearance profile round the casing in the exact nodal simulator: its steps are event times known in
advance, where the flight is cut (bladecase.nsm.massless.nodes, Profile)."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction, simulate_friction
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, Profile, Rub, simulate_nodes

SPEED = 0.4                      # rad/s: a revolution of 15.7 s
ANGLES = [0.0, 0.3]


def _system(**kw) -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[4.0, 4.0], **kw)


def _restarted(system, rub, damping, profile, x0, v0, t_end):
    """The reference: the simulation without a profile restarted at each of the profile's steps, each piece on a
    system whose clearances are widened by that piece's offset (no shifted phases, a fresh complementarity
    problem at every restart)."""
    b = np.r_[0.0, profile.breaks(0.0, t_end), t_end]
    x, v = np.asarray(x0, float), np.asarray(v0, float)
    for t0, t1 in zip(b[:-1], b[1:]):
        off = profile.offset(0.5 * (t0 + t1))
        s = NodalSystem(system.M, system.S, system.W, system.flexibility, gap=system.gap + off, casing=system.casing)
        # the same casing seen from t0: the lobes' phase moved on by Ωt0
        shifted = Rub(rub.lobes, rub.amplitude, rub.speed, [a + rub.speed * t0 for a in rub.angles])
        tr = simulate_nodes(s, x, v, t1 - t0, damping=damping, rub=shifted)
        x, v = tr.x_end, tr.v_end
    return x, v


def test_a_stepped_profile_against_the_simulation_restarted_at_each_step():
    """A worn profile of 24 cells (depths up to 0.4 of the clearance, 20 steps round the casing: 79 steps seen by
    the two nodes over two revolutions), damped, in a three-lobe casing: the final state matches the restarted
    simulation to 1e-9 relative."""
    rng = np.random.default_rng(3)
    depth = np.where(rng.random(24) < 0.5, 0.4 * rng.random(24), 0.0)
    s, damping = _system(), Damping(zeta=0.05)
    rub = Rub(3, 1.2, SPEED, ANGLES)
    profile = Profile(depth, SPEED, ANGLES)
    t_end = 2 * 2 * np.pi / SPEED
    tr = simulate_nodes(s, [0.5, 0.0], [0.0, 0.2], t_end, damping=damping, rub=rub, profile=profile)
    x, v = _restarted(s, rub, damping, profile, [0.5, 0.0], [0.0, 0.2], t_end)
    scale = np.abs(np.r_[x, v]).max()
    assert np.abs(np.r_[tr.x_end - x, tr.v_end - v]).max() < 1e-9 * scale
    assert tr.active.any() and profile.breaks(0.0, t_end).size == 79
    # between two steps the clearances are the piece's own: the forces obey the complementarity problem there
    t = np.linspace(0.1, t_end - 0.1, 57)
    x_t, _, lam = tr.sample(t)
    g = tr.flight.gap(t)
    for k in range(t.size):
        np.testing.assert_allclose(lam[:, k], s.forces(x_t[:, k], g[:, k]), atol=1e-9)


def test_a_uniform_profile_is_a_wider_clearance_and_zero_is_none_bit_for_bit():
    s = _system()
    rub, damping = Rub(3, 1.2, SPEED, ANGLES), Damping(zeta=0.05)
    t_end = 2 * np.pi / SPEED
    plain = simulate_nodes(s, [0.5, 0.0], [0.0, 0.0], t_end, damping=damping, rub=rub)
    zero = simulate_nodes(s, [0.5, 0.0], [0.0, 0.0], t_end, damping=damping, rub=rub,
                          profile=Profile(np.zeros(36), SPEED, ANGLES))
    assert np.array_equal(plain.starts, zero.starts) and np.array_equal(plain.q, zero.q)
    wide = NodalSystem(s.M, s.S, s.W, s.flexibility, gap=s.gap + 0.1, casing=s.casing)
    ref = simulate_nodes(wide, [0.5, 0.0], [0.0, 0.0], t_end, damping=damping, rub=rub)
    even = simulate_nodes(s, [0.5, 0.0], [0.0, 0.0], t_end, damping=damping, rub=rub,
                          profile=Profile(np.full(36, 0.1), SPEED, ANGLES))
    np.testing.assert_allclose(even.switch_times, ref.switch_times, rtol=1e-11)
    np.testing.assert_allclose(np.r_[even.x_end, even.v_end], np.r_[ref.x_end, ref.v_end], rtol=1e-9, atol=1e-12)


def test_a_profile_with_friction_against_the_restarted_friction_simulation():
    """The friction flight's phases shift with the profile as the plain ones do."""
    s = _system()
    fr = Friction(0.15, T=np.array([[0.3, 0.1], [-0.1, 0.4]]), radius=[30.0, 30.0])
    profile = Profile(np.r_[np.zeros(6), 0.3 * np.ones(6)], SPEED, ANGLES)
    t_end = 2 * np.pi / SPEED
    rub, damping = Rub(3, 1.2, SPEED, ANGLES), Damping(zeta=0.05)
    tr = simulate_friction(s, fr, [0.5, 0.0], [0.0, 0.0], t_end, damping=damping, rub=rub, profile=profile)
    b = np.r_[0.0, profile.breaks(0.0, t_end), t_end]
    x, v = np.array([0.5, 0.0]), np.zeros(2)
    for t0, t1 in zip(b[:-1], b[1:]):
        piece = NodalSystem(s.M, s.S, s.W, s.flexibility, gap=s.gap + profile.offset(0.5 * (t0 + t1)),
                            casing=s.casing)
        seg = simulate_friction(piece, fr, x, v, t1 - t0, damping=damping,
                                rub=Rub(3, 1.2, SPEED, [a + SPEED * t0 for a in ANGLES]))
        x, v = seg.x_end, seg.v_end
    np.testing.assert_allclose(np.r_[tr.x_end, tr.v_end], np.r_[x, v], rtol=1e-9, atol=1e-10)


def test_profile_input_errors():
    with pytest.raises(ValueError, match="one angle per contact node"):
        NodalFlight(_system(), profile=Profile(np.zeros(4), SPEED, [0.0]))
    with pytest.raises(ValueError, match="speed must be a finite number > 0"):
        Profile(np.zeros(4), 0.0, ANGLES)
