"""The energy balance of the coating yielding in flight (:mod:`bladecase.nsm.massless.coating_energy`): the plastic
work against the closed form and the depth removed, the balance closing with damping, lobes, friction and a worn
profile's steps (each term needed), the force continuous at every switch, one balance for two simulators (the
elastic flight with friction), the demo blade's 26 tip nodes and the wear rub's revolutions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.coating_energy import (
    _fields,
    coating_balance,
    per_revolution,
    surface_steps,
)
from bladecase.nsm.massless.coating_flight import PLASTIC, CoatingFlight, simulate_coating
from bladecase.nsm.massless.friction import Friction, simulate_friction
from bladecase.nsm.massless.friction_energy import energy_balance
from bladecase.nsm.massless.nodes import NodalSystem, Profile, Rub
from bladecase.nsm.massless.wear import Abradable
from bladecase.nsm.massless.wear_rub import wear_rub

DATA = Path(__file__).parent / "data" / "demo_tip_coating_graze.npz"
YIELD = np.array([6.0, 5.0])


def _three() -> NodalSystem:
    """Three interior dofs, two contact nodes coupled through their own flexibility, a compliant coating."""
    S = np.array([[2.0, -1.0, 0.0], [-1.0, 2.5, -0.8], [0.0, -0.8, 3.0]])
    W = np.array([[1.0, 0.2], [0.3, 1.0], [0.1, 0.4]])
    return NodalSystem(np.diag([1.0, 1.5, 0.8]), S, W, [[0.02, 0.005], [0.005, 0.03]], gap=[1.0, 0.8],
                       casing=[100.0, 80.0])


def _friction() -> Friction:
    return Friction(0.15, T=np.array([[0.3, 0.0], [0.1, 0.5], [0.0, 0.2]]), C_nt=np.array([[0.004, 0.001],
                    [0.0, 0.003]]), C_tt=np.array([[0.03, 0.002], [0.002, 0.02]]), model="rotation")


def test_one_dof_plastic_work_closed_form():
    """One dof into a yielding coating, no damping, a round casing: the stored energy lost is the plastic work, and
    that is λ_y × the depth removed, the closed form ½v₀² − ½x_max² − ½Hλ_y² at the turning point."""
    h, k, g, ly, v0 = 0.01, 100.0, 1.0, 10.0, 10.0
    s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[h]], gap=[g], casing=[k])
    tr = simulate_coating(s, [ly], [0.0], [v0], 3.0)
    assert tr.codes[:, 0].tolist() == [0, 1, 2, 1, 0]
    e = coating_balance(tr, 0.0, 3.0)
    assert e.casing == 0.0 and e.friction == 0.0 and e.damping == 0.0 and e.steps == 0.0
    assert abs(e.stored_change + e.plastic) < 1e-12 * e.plastic
    assert abs(e.plastic - ly * tr.removed()[0]) < 1e-12 * e.plastic
    H = h + 1 / k
    x_max = -ly + np.sqrt(ly**2 + 2 * ly * (g + H * ly) - H * ly**2 + v0**2)
    assert abs(e.plastic - ly * (x_max - g - H * ly)) < 1e-10 * e.plastic
    # the plastic phase alone: all of it there
    i = int(np.flatnonzero(tr.codes[:, 0] == PLASTIC)[0])
    part = coating_balance(tr, tr.starts[i], tr.starts[i + 1])
    assert abs(part.plastic - e.plastic) < 1e-12 * e.plastic and abs(part.relative) < 1e-12


def _worn(revolutions: int = 2):
    """Two nodes over a worn profile of 12 cells in a three-lobe casing, damped, with friction: they yield, spring
    back and, entering a cell less worn than their surface, remove the excess at once."""
    s, speed, phi = _three(), 2.0, np.array([0.0, 0.3])
    depth = np.array([0.026, 0.071, 0.24, 0.175, 0.028, 0.13, 0.144, 0.048, 0.22, 0.034, 0.117, 0.155])
    fl = CoatingFlight(s, YIELD, Damping(zeta=0.02), Rub(3, 0.5, speed, phi), _friction())
    tr = fl.simulate(np.zeros(3), np.array([2.0, 1.5, 0.5]), revolutions * 2 * np.pi / speed,
                     profile=Profile(depth, speed, phi))
    return tr, speed


def test_worn_profile_with_friction_closes_every_revolution():
    """Damping, lobes, friction μ = 0.15 and a worn profile's steps: each revolution closes to 1e-9, every term at
    work; without the steps' term it does not close; the plastic work is λ_y × the depth removed in flight."""
    tr, speed = _worn()
    assert tr.complete and (tr.jumps > 0.01).any() and (tr.codes == PLASTIC).any(axis=0).all()
    revs = per_revolution(tr, speed)
    assert len(revs) == 2
    for e in revs:
        assert abs(e.relative) < 1e-9 and e.quadrature_error < 1e-9 * abs(e.casing)
        assert e.damping > 0 and e.plastic > 0 and e.friction != 0 and e.casing != 0 and e.steps != 0
        scale = abs(e.residual / e.relative)
        assert abs(e.residual - e.steps) > 1e-3 * scale  # without the steps' term: off by far more than 1e-9
    whole = coating_balance(tr, 0.0, tr.t_end)
    in_flight = tr.removed() - tr.jumps.sum(axis=0)
    assert abs(whole.plastic - YIELD @ in_flight) < 1e-9 * whole.plastic
    assert abs(sum(e.plastic for e in revs) - whole.plastic) < 1e-12 * whole.plastic
    # a span cut inside phases, across a step
    t0, t1 = 0.37 * tr.t_end, 0.61 * tr.t_end
    part = coating_balance(tr, t0, t1)
    assert abs(part.relative) < 1e-9 and part.steps != 0


def test_force_continuous_but_at_the_surfaces_steps():
    """x, x' continuous at every start; λ too, except where the surfaces jump, and it does jump at some of those."""
    tr, _ = _worn()
    i = np.arange(1, tr.starts.size)
    t = tr.starts[i]
    Qb, Pb, lb, *_ = _fields(tr, i - 1, t)
    Qa, Pa, la, *_ = _fields(tr, i, t)
    assert np.abs(Qa - Qb).max() < 1e-12 * np.abs(Qa).max() and np.abs(Pa - Pb).max() < 1e-12 * np.abs(Pa).max()
    steps = np.isin(i, surface_steps(tr))
    jump = np.abs(la - lb).max(axis=0)
    assert steps.sum() >= 5 and (~steps).sum() >= 5
    assert jump[~steps].max() < 1e-9 * YIELD.max()
    assert jump[steps].max() > 0.1 * YIELD.max()


def test_no_yield_no_profile_is_the_friction_balance():
    """A yield never reached and no profile: the coating's balance of its flight equals the friction balance of the
    same rub flown by the elastic flight with friction (two simulators, one balance)."""
    s, speed, phi = _three(), 0.7, [0.0, 0.4]
    d, rub, f = Damping(zeta=0.01), Rub(3, 0.7, speed, phi), _friction()
    x0, v0 = np.array([0.5, 0.0, 0.1]), np.array([3.0, 2.0, 1.0])
    ref = simulate_friction(s, f, x0, v0, 20.0, damping=d, rub=rub)
    tr = CoatingFlight(s, [1e9, 1e9], d, rub, f).simulate(x0, v0, 20.0)
    assert ref.switch_times.size > 8 and not (tr.codes == PLASTIC).any()
    for t0, t1 in [(0.0, 20.0), (3.3, 11.9)]:
        a, b = coating_balance(tr, t0, t1), energy_balance(ref, t0, t1)
        scale = max(abs(b.casing), abs(b.friction), abs(b.damping), abs(b.stored_change))
        for name in ("casing", "friction", "damping", "stored_change"):
            assert abs(getattr(a, name) - getattr(b, name)) < 1e-9 * scale, name
        assert a.plastic == 0.0 and a.steps == 0.0 and abs(a.relative) < 1e-12
        assert a.friction != 0 and a.damping > 0 and a.casing != 0


def _demo():
    d = dict(np.load(DATA))
    s = NodalSystem(d["M"], d["S"], d["W"], d["flexibility"], d["gap"], d["casing"], nodes=tuple(d["nodes"].tolist()))
    f = Friction(float(d["mu"]), T=d["T"], C_nt=d["C_nt"], C_tt=d["C_tt"], model="rotation")
    speed = float(d["speed"])
    rub = Rub(int(d["lobes"]), float(d["amplitude"]), speed, d["angles"])
    return d, CoatingFlight(s, d["yield_force"], Damping(zeta=float(d["zeta"])), rub, f)


def test_demo_blade_tip_nodes():
    """The demo blade's 26 tip nodes, friction 0.15 and 8 lobes, from the state stored mid-rub over a worn profile
    of 120 cells (a tenth of a revolution): the balance closes to 1e-9 with every term at work, the plastic work is
    λ_y × the depth removed in flight, the forces continuous at every switch."""
    d, fl = _demo()
    speed = float(d["speed"])
    cells = np.arange(120)
    depth = 2e-5 * (1 + np.cos(8 * 2 * np.pi * cells / cells.size)) + 1e-6 * ((cells * 7919) % 13) / 13
    prof = Profile(depth, speed, d["angles"])
    tr = fl.simulate(fl.phi @ d["q"], fl.phi @ d["p"], 0.1 * 2 * np.pi / speed, profile=prof)
    assert tr.complete and tr.starts.size > 100 and (tr.codes == PLASTIC).any()
    e = coating_balance(tr, 0.0, tr.t_end)
    assert abs(e.relative) < 1e-9 and e.quadrature_error < 1e-9 * e.casing
    assert e.plastic > 0 and e.steps != 0 and e.friction != 0 and e.damping > 0
    assert abs(e.residual - e.steps) > 1e-3 * abs(e.residual / e.relative)
    in_flight = tr.removed() - tr.jumps.sum(axis=0)
    assert abs(e.plastic - fl.yield_force @ in_flight) < 1e-9 * e.plastic
    i = np.arange(1, tr.starts.size)
    lb, la = _fields(tr, i - 1, tr.starts[i])[2], _fields(tr, i, tr.starts[i])[2]
    switch = ~np.isin(i, surface_steps(tr))
    assert switch.sum() >= 10 and np.abs(la - lb)[:, switch].max() < 1e-9 * fl.yield_force.max()


def _rub_system() -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[4.0, 4.0])


def test_wear_rub_energy():
    """``wear_rub(..., energy=True)``: each revolution's balance closes, the surfaces' steps at work (a node that
    wore its cell steps back onto the profile's depth in the next); the answer otherwise the same as without it
    (and ``None`` there)."""
    c = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=1.0)
    f = Friction(0.1, T=np.array([[0.3, 0.0], [0.1, 0.5]]), C_nt=0.01 * np.eye(2), C_tt=0.1 * np.eye(2))
    args = (_rub_system(), c, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05))
    w = wear_rub(*args, revolutions=3, areas=[1.0, 1.0], friction=f, energy=True)
    plain = wear_rub(*args, revolutions=3, areas=[1.0, 1.0], friction=f)
    assert plain.energy is None and len(w.energy) == 3
    assert np.array_equal(w.profile.depth, plain.profile.depth) and np.array_equal(w.tip, plain.tip)
    for e in w.energy:
        assert abs(e.relative) < 1e-9 and e.plastic > 0
    assert all(e.steps != 0 for e in w.energy)  # a node leaving the cell it wore steps back onto its depth
    with pytest.raises(ValueError, match="needs the coupling 'in_flight', got 'staggered'"):
        wear_rub(*args, revolutions=1, coupling="staggered", energy=True)


def test_bad_input():
    s = _rub_system()
    tr = simulate_friction(s, None, [0.0, 0.0], [1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match="needs a CoatingTrajectory .* got NodalTrajectory"):
        coating_balance(tr, 0.0, 1.0)
    ct = simulate_coating(s, [1.0, 1.0], [0.0, 0.0], [1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match=r"must lie in the trajectory's \[0, 1.0\]"):
        coating_balance(ct, 0.5, 2.0)
