"""The damping ratio of a mode with stick–slip friction (extended periodic motion concept) against the closed form
of a Jenkins element, the free decay, and a forced response's resonance."""

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.friction_coulomb_rub import coulomb_energy
from bladecase.nsm.massless.friction_modes_coulomb import (
    coulomb_decay_ratio,
    coulomb_mode,
    equivalent_ratio,
    jenkins_dissipation,
    orbit_kinetic,
)
from bladecase.nsm.massless.friction_modes_forced import forced_point, forced_sweep, resonance
from bladecase.nsm.massless.nodes import NodalSystem

# a tangential dof (k = 1, m = 1) with a Jenkins contact (k_t = 2, slip force μN = 0.4) held at a constant normal
# load N = 1 by a preloaded normal dof (k = 4, contact compliance 1e-3, clearance 0.1)
K_T, MU, N = 2.0, 0.4, 1.0
LOAD = [0.0, 4 * (0.1 + 1e-3 * N) + N]


def jenkins():
    s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    return s, Friction(MU, T=[[1.0], [0.0]], C_tt=[[1 / K_T]], model="coulomb")


@pytest.mark.parametrize("a", [1.0, 10.0, 30.0])
def test_mode_dissipates_the_jenkins_loop(a):
    s, f = jenkins()
    m = coulomb_mode(s, f, a, load=LOAD)
    assert m.converged and m.residual < 1e-9
    e = coulomb_energy(m.orbit, 0.0, m.period)
    wd = float(jenkins_dissipation(a, MU * N, K_T))
    # the orbit's friction work is the loop area 4μN(a − μN/k_t), to round-off, and ξ∫x'ᵀMx' puts it back
    assert abs(-e.friction / wd - 1) < 1e-9
    assert abs(m.xi * orbit_kinetic(m.orbit, 0.0, m.period) / wd - 1) < 1e-9
    # the harmonic closed form ζ = W_d / (4π E_max), E_max = ½ω²a²: the orbit is not harmonic, so within 5 %
    assert abs(equivalent_ratio(wd, a, m.frequency) / m.zeta - 1) < 0.05
    # the free decay (certified simulator, no term) read at the start's amplitude from its first two periods:
    # 0.080ζ and 0.022ζ apart at a = 10 and 30 (each period's own ratio, half a period lower, was 3.2ζ apart); at
    # a = 1 the decay sticks within two periods (ζ = 0.16): the first period's own ratio, within 4ζ
    z = coulomb_decay_ratio(s, f, m, load=LOAD)
    assert abs(z / m.zeta - 1) < (4 if a < 10 else 0.15) * m.zeta


def test_forced_resonance_matches_the_mode_ratio():
    s, f = jenkins()
    damping, a = Damping(zeta=0.02), 4.0
    m = coulomb_mode(s, f, a, load=LOAD, damping=damping)
    force = 2 * m.zeta * m.frequency**2 * a  # the phase resonance of the nonlinear mode at amplitude a
    shape = s.M @ s.modes[1][:, 0] * force
    pts = forced_sweep(s, f, shape, m.frequency * np.linspace(0.985, 1.015, 5), damping, LOAD, rtol=1e-5)
    r = resonance(pts, force)
    assert abs(r.amplitude / a - 1) < 0.05
    m_peak = coulomb_mode(s, f, r.amplitude, load=LOAD, damping=damping, guess=m)
    assert abs(r.zeta_phase / m_peak.zeta - 1) < 0.05
    assert abs(r.frequency / m_peak.frequency - 1) < 0.01


def test_bad_input_is_named():
    s, f = jenkins()
    with pytest.raises(ValueError, match="amplitude"):
        coulomb_mode(s, f, -1.0, load=LOAD)
    with pytest.raises(ValueError, match="frequency"):
        forced_point(s, f, [1.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="contact_stiffness"):
        jenkins_dissipation(1.0, 0.1, 0.0)
