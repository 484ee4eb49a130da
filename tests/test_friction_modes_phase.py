"""A mode with stick–slip friction read off a forced steady state by the phase of its fundamental harmonic
(the single nonlinear mode), against the mode itself at the same fundamental amplitude."""

import numpy as np
import pytest
from test_friction_damping import LOAD, jenkins

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction_modes_coulomb import coulomb_mode
from bladecase.nsm.massless.friction_modes_forced import forced_point
from bladecase.nsm.massless.friction_modes_phase import fundamental, kinetic_factor, phase_mode


def test_a_flank_point_gives_the_modes_frequency_and_ratio_at_its_amplitude():
    """The Jenkins oscillator (ζ ≈ 8 %) driven 1 % below its frequency at amplitude 4 by the force that puts its
    phase resonance there: the point's ω and ζκ against the mode's at the point's own fundamental amplitude
    (measured −5.6e-5 and +0.80 %; at the peak −3e-5 and −0.01 %, 3 % off it ±3 %: first order in ζ)."""
    s, f = jenkins()
    d = Damping(zeta=0.02)
    m = coulomb_mode(s, f, 4.0, load=LOAD, damping=d)
    a1, kappa = kinetic_factor(m)
    force = 2 * m.zeta * kappa * m.frequency**2 * a1
    shape = 1j * force * (s.M @ s.modes[1][:, 0])
    p = forced_point(s, f, shape, 0.99 * m.frequency, d, LOAD, rtol=1e-10, max_periods=4000,
                     state=(m.x0, m.v0, m.codes, m.anchors))
    w, zk, b1 = phase_mode(p, shape)
    assert 0.95 < b1 / a1 < 1.0  # on the flank, below the peak
    mm = coulomb_mode(s, f, 4.0 * b1 / a1, load=LOAD, damping=d, guess=m)
    mm = coulomb_mode(s, f, 4.0 * b1 / a1 * b1 / kinetic_factor(mm)[0], load=LOAD, damping=d, guess=mm)
    c1, ck = kinetic_factor(mm)
    assert c1 == pytest.approx(b1, rel=1e-5)
    assert w == pytest.approx(mm.frequency, rel=1e-4)
    assert zk == pytest.approx(mm.zeta * ck, rel=0.015)


def test_the_fundamental_of_a_shifted_cosine_and_a_period_refused():
    s, f = jenkins()
    from bladecase.nsm.massless.friction_coulomb import CoulombFlight

    far = type(s)(s.M, s.S, s.W, s.flexibility, np.array([10.0]))
    tr = CoulombFlight(far, f, None, sliding=0.0).simulate(np.array([0.3, 0.0]), np.array([0.3, 0.0]), 2 * np.pi)
    c = fundamental(tr, 0.0, 2 * np.pi)                  # q = 0.3 cos t + 0.3 sin t = Re(0.3(1 − i) e^{it})
    assert c == pytest.approx(0.3 - 0.3j, abs=1e-9)
    with pytest.raises(ValueError, match="period"):
        fundamental(tr, 0.0, 0.0)
