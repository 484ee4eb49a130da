"""A yielding node whose yield signal starts flat a hair below its surface, with a cell's edge 1.2 ns ahead: the
flight to the edge is flown (the state stored from the demo blade's wear rub with friction at 1657.1 rpm, which
stopped there, "a node that stopped yielding does not leave its yield force", when that speed came after 1651 rpm
in a sweep)."""

from pathlib import Path

import numpy as np

from bladecase.nsm import Damping
from bladecase.nsm.massless.coating_flight import ADMISSIBLE_RTOL, LEAVE_POINTS, CoatingFlight, _start
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.nodal_switches import leave_flat
from bladecase.nsm.massless.nodes import NodalSystem, Rub

DATA = Path(__file__).parent / "data" / "demo_tip_coating_graze.npz"


def _flight():
    d = dict(np.load(DATA))
    s = NodalSystem(d["M"], d["S"], d["W"], d["flexibility"], d["gap"], d["casing"], nodes=tuple(d["nodes"].tolist()))
    f = Friction(float(d["mu"]), T=d["T"], C_nt=d["C_nt"], C_tt=d["C_tt"], model="rotation")
    rub = Rub(int(d["lobes"]), float(d["amplitude"]), float(d["speed"]), d["angles"])
    fl = CoatingFlight(s, d["yield_force"], Damping(zeta=float(d["zeta"])), rub, f)
    t = float(d["t"])
    ph = fl.phase(d["codes"], d["w"])
    return fl, ph, ph.amplitudes(d["q"], d["p"], t), t, float(d["horizon"])


def test_flat_start_below_its_surface_flies_to_the_edge():
    fl, ph, a, t, horizon = _flight()
    sig, f0, _, scale, on, flat = _start(ph, a, t)
    (k,) = np.flatnonzero(flat)
    assert ph.meta[k] == (4, "yield")  # an elastic node at its yield force, its rate zero
    assert -ADMISSIBLE_RTOL < f0[k] / scale[k] < -1e-15  # admitted, a hair below its surface
    # it curves up: positive after 1 ns, but not yet at the edge's 16th
    row = sig.row(k)
    assert -row(1e-9)[0] > 0 > -row(horizon / LEAVE_POINTS)[0]
    # without the band the flight stops for good (the old rule: a switch now, back and forth)
    assert leave_flat(row, horizon, sig.step, 0.0, LEAVE_POINTS) is None
    hit, span = fl._fly(ph, a, t, horizon)
    assert span == horizon and hit is None


def test_flight_past_the_edge_stays_admissible():
    """Flown to the edge, the node's force is still at its yield force to the band that admitted it."""
    fl, ph, a, t, horizon = _flight()
    q, p = ph.advance(a, t, horizon)
    lam = fl.positions(ph, q, t + horizon)[1][:, 0]
    assert abs(lam[4] - fl.yield_force[4]) <= ADMISSIBLE_RTOL * fl.yield_force[4]
    assert np.all(lam >= -1e-9 * fl.yield_force) and np.all(lam <= fl.yield_force * (1 + 1e-9))
