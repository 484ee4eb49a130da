"""The stick–slip rub (bladecase.nsm.massless.friction_coulomb_rub): its energy balance closes through sticking and
sliding, and at a sliding speed too fast to stick it is the rotation model's rub, figure for figure."""

from __future__ import annotations

import numpy as np
import pytest
from test_nodes import V0, X0, chain

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.friction_coulomb import simulate_coulomb
from bladecase.nsm.massless.friction_coulomb_rub import coulomb_energy, coulomb_rub_response, stick_share
from bladecase.nsm.massless.nodes import NodalSystem, Rub
from bladecase.nsm.massless.rub import rub_response

KW = dict(T=np.array([[0.2, 0.0], [0.5, 0.1], [0.0, 0.6]]), C_nt=[[0.02, 0.005], [0.0, 0.03]],
          C_tt=[[0.1, 0.01], [0.01, 0.08]])


@pytest.mark.parametrize("V", [0.1, 0.0])
def test_energy_balance_closes_through_stick_and_slip(V):
    """Two coupled contacts sticking and sliding on a slow casing and on one at rest, damped, the casing out of
    round: over each span of 10 s the stored energy's change equals casing + friction − damping to 1e-10 relative,
    and the two quadratures agree."""
    tr = simulate_coulomb(chain(12.0), Friction(0.15, model="coulomb", **KW), X0, V0, 40.0,
                          damping=Damping(zeta=0.02), rub=Rub(3, 0.3, 0.7, (0.0, 0.4)), sliding=[V, V])
    assert np.all(stick_share(tr, 0.0, 40.0) > 0.05)
    for t0 in (0.0, 10.0, 20.0, 30.0):
        e = coulomb_energy(tr, t0, t0 + 10.0)
        assert abs(e.relative) < 1e-10 and e.friction != 0 and e.damping > 0
        assert e.quadrature_error < 1e-9 * max(abs(e.casing), abs(e.friction), e.damping)


def test_fast_casing_rub_is_the_rotation_models():
    """At a sliding speed far above the vibration's the stick–slip rub is the rotation model's: the same peaks,
    contact fractions and energy of the last revolution, and no stick."""
    s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]), gap=[1.0, 1.0],
                    casing=[4.0, 4.0])
    kw = dict(T=np.array([[0.3, 0.1], [-0.1, 0.4]]), C_tt=np.diag([0.2, 0.2]), radius=[1e4, 1e4])
    d = Damping(zeta=0.05)
    rot = rub_response(s, 0.4, 3, 1.2, [0.0, 0.3], d, revolutions=4, window=2, max_revolutions=4,
                       friction=Friction(0.15, **kw))
    cou = coulomb_rub_response(s, Friction(0.15, model="coulomb", **kw), 0.4, 3, 1.2, [0.0, 0.3], d, revolutions=4,
                               window=2)
    assert cou.friction["stick_share_max"] == 0.0
    for name in ("peak_displacement", "peak_force", "contact_fraction", "force_at_peak"):
        assert np.allclose(getattr(cou, name), getattr(rot, name), rtol=1e-9, atol=0), name
    for key in ("casing_j", "friction_j", "damping_j", "stored_change_j"):
        assert cou.friction[key] == pytest.approx(rot.friction[key], rel=1e-9), key
    assert cou.switches == rot.switches and cou.settled == rot.settled


def test_rub_input_is_checked():
    s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.5]], gap=[1.0])
    with pytest.raises(ValueError, match="needs each node's radius"):
        coulomb_rub_response(s, Friction(0.1, T=[[0.3]], C_tt=[[0.1]], model="coulomb"), 1.0, 3, 0.1, [0.0])
    with pytest.raises(ValueError, match="window must be an integer"):
        coulomb_rub_response(s, Friction(0.1, T=[[0.3]], C_tt=[[0.1]], radius=[1.0], model="coulomb"), 1.0, 3,
                             0.1, [0.0], revolutions=4, window=3)
