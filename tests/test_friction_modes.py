"""A mode with friction by the extended periodic motion concept (bladecase.nsm.massless.friction_modes): the orbit
closes, its damping ratio against the free decay simulated by the certified simulator, and the rotation-dominated
friction's own damping of a free mode (none: the orbits are reversible)."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.friction_modes import decay_ratio, friction_mode
from bladecase.nsm.massless.nodes import NodalSystem


def tip() -> NodalSystem:
    """Two coupled modes, one contact node whose normal and tangent both move them."""
    return NodalSystem(np.eye(2), np.array([[1.0, 0.2], [0.2, 2.5]]), np.array([[1.0], [0.3]]), [[0.02]], gap=[1.0])


FRICTION = Friction(0.15, T=np.array([[0.2], [1.0]]))


def test_below_contact_the_mode_is_the_linear_one():
    s, d = tip(), Damping(zeta=0.01)
    m = friction_mode(s, FRICTION, amplitude=0.9, damping=d)   # the tip stays 0.1 short of the casing
    assert m.converged and m.frequency == pytest.approx(s.modes[0][0], rel=1e-12)
    assert m.zeta == pytest.approx(0.01, rel=1e-10)


def test_rotation_dominated_friction_does_not_damp_a_free_mode():
    """The drag μλ depends on the position only: the motion is reversible, its symmetric orbits close with ξ = 0
    (to round-off), friction or not; the frequency still moves with friction (a non-symmetric stiffness)."""
    s = tip()
    with_friction = friction_mode(s, FRICTION, amplitude=1.6)
    without = friction_mode(s, Friction(0.0, T=FRICTION.T), amplitude=1.6)
    assert with_friction.converged and without.converged
    assert abs(with_friction.zeta) < 1e-12 and abs(without.zeta) < 1e-12
    assert with_friction.frequency / without.frequency - 1 > 1e-3


@pytest.mark.parametrize("mu, rtol", [(0.0, 5e-3), (0.15, 0.05)])
def test_damping_ratio_against_the_free_decay(mu, rtol):
    """ζ of the extended concept against the energy lost over one period of the free decay (certified
    simulator): 0.2 % without friction (first order in ζ); within 5 % with it (measured 2.4 %: the decaying orbit
    is not reversible, and friction works on it)."""
    s, d = tip(), Damping(zeta=0.01)
    f = Friction(mu, T=FRICTION.T)
    m = friction_mode(s, f, amplitude=1.3, damping=d)
    assert m.converged and m.residual < 1e-9
    z = decay_ratio(s, f, m, d)
    assert abs(z / m.zeta - 1) < rtol
    assert abs(m.zeta - 0.01) > 0.1 * 0.01  # the contact changes the ratio: the check can fail


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="amplitude must be a finite number > 0"):
        friction_mode(tip(), FRICTION, amplitude=-1.0)
    with pytest.raises(ValueError, match=r"mode must be an integer in 0\.\.1, got 5"):
        friction_mode(tip(), FRICTION, amplitude=1.0, mode=5)
