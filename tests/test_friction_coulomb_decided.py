"""A sliding node whose relative velocity crosses zero fast, its signal left a round-off above 0 (1.4e-17 of its
size) after the nodes on the cone were decided together: the decision must not keep it sliding (its signal falls at
once and the same switch would repeat forever). Stored from the extended periodic motion concept's first flight on a
fine mesh of the demo blade (60k dofs, 112 tip nodes, μ = 0.15 stick–slip, 1.5 × grazing), which ran 2341 such
switches in 300 s without advancing."""

from pathlib import Path

import numpy as np

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.friction_coulomb import CODES
from bladecase.nsm.massless.friction_modes_coulomb import _EPMCFlight, _flow
from bladecase.nsm.massless.nodes import NodalSystem

DATA = Path(__file__).parent / "data" / "fine_tip_decided_slip.npz"


def _state():
    d = dict(np.load(DATA))
    s = NodalSystem(d["M"], d["S"], d["W"], d["flexibility"], d["gap"], d["casing"], nodes=tuple(d["nodes"].tolist()))
    f = Friction(float(d["mu"]), T=d["T"], C_nt=d["C_nt"], C_tt=d["C_tt"], radius=d["radius"], model="coulomb")
    fl = _EPMCFlight(s, f, Damping(zeta=float(d["zeta"])), 0.0, None, float(d["xi"]))
    return fl, d


def test_a_slide_decided_at_a_round_off_above_zero_and_falling_is_not_kept():
    fl, d = _state()
    codes, anchors, q, p, t, k = d["codes"], d["anchors"], d["q"], d["p"], float(d["t"]), int(d["k"])
    ph = fl.phase(codes)
    sig = ph.signals(fl, ph.amplitudes(q, p, t, anchors), t, anchors, 1.0)
    f0, d0 = (v[0] for v in sig.values(0.0))
    node, kind = ph.meta[k]
    assert kind == "slip" and codes[node] == CODES["slip-"]
    assert 0 < f0[k] < 1e-15 * sig.magnitude[k] and d0[k] < -100.0  # a round-off above 0, falling fast
    new, _ = fl._switch(ph, k, codes, anchors, q, p, t)
    assert new[node] == CODES["stick"]  # it was kept sliding, and the switch found again at once, for ever
    assert np.array_equal(np.delete(new, node), np.delete(codes, node))


def test_the_flight_goes_on_from_there():
    fl, d = _state()
    tr = _flow(fl, d["q"], d["p"], d["codes"], d["anchors"], 2e-5)
    assert tr.starts.size < 50 and tr.t_end == 2e-5
