"""The closed contacts after a switch that puts several contacts on their surfaces at once: the contacts the
switch found there are decided at the rate level, whatever their force's round-off — without friction and with it
(the same code, the flexibility non-symmetric with friction)."""

from __future__ import annotations

import numpy as np

from bladecase.nsm.massless.friction import Friction, friction_flight
from bladecase.nsm.massless.nodes import SURFACE_RTOL, NodalFlight, NodalSystem


def _two_nodes() -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]), gap=[1.0, 1.0])


def _closed_by_round_off(fl):
    """Both contacts touch (zero clearance left) and separate (the velocity pulls them off): node 0 with a force ten
    times the position-level problem's tolerance (a switch's own signal tolerance can call it zero), node 1 with
    none. Returns (without ``on``, with ``on``)."""
    s = fl.system
    lam = np.array([10 * SURFACE_RTOL * float(np.abs(fl.gap(0.0)).max()) / float(np.abs(s.H).max()), 0.0])
    y = fl.gap(0.0) + s.H @ lam  # the contacts' displacement that leaves exactly that force
    x = np.linalg.lstsq(fl.Wq.T, y, rcond=None)[0]
    p = -np.linalg.lstsq(fl.Wq.T, np.ones(2), rcond=None)[0]  # moving off the casing: both should open
    on = np.array([True, True])
    return fl.active_set(x, p, 0.0), fl.active_set(x, p, 0.0, on)


def test_contacts_on_their_surfaces_are_decided_together():
    plain, decided = _closed_by_round_off(NodalFlight(_two_nodes()))
    assert decided.tolist() == [False, False]  # both leave: decided at the rate level
    assert plain.tolist() == [True, False]     # by the force's sign alone, round-off kept node 0 closed


def test_the_same_with_friction():
    f = Friction(0.2, T=np.eye(2), C_nt=[[0.02, 0.005], [0.0, 0.03]], C_tt=[[0.1, 0.01], [0.01, 0.08]])
    plain, decided = _closed_by_round_off(friction_flight(_two_nodes(), f))
    assert decided.tolist() == [False, False]
