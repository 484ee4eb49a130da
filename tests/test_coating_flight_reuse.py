"""The coating flight's shortcuts give the same numbers as the plain path: the next profile edges read from the
profile's runs of equal depth against the scan of every cell ahead, and a flight started from the start its decision
just computed against one made afresh — the trajectories and the coupled wear bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless import coating_flight
from bladecase.nsm.massless.coating_flight import PLASTIC, CoatingFlight, _runs, simulate_coating
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.nodes import NodalSystem, Profile, Rub
from bladecase.nsm.massless.wear import Abradable
from bladecase.nsm.massless.wear_rub import wear_rub


def _edges_scan(self, profile, t, codes, w):
    """The plain path: each node's cells ahead scanned for the first of another depth than its surface."""
    n = profile.depth.size
    c0 = self._cells(profile, t)
    ahead = profile.depth[(c0[:, None] + 1 + np.arange(n)) % n]
    differ = (ahead != w[:, None]) | (codes == PLASTIC)[:, None]
    k = np.where(differ.any(axis=1), np.argmax(differ, axis=1), n)
    return ((c0 + 1 + k) * profile.step - np.asarray(profile.angles)) / profile.speed


@pytest.fixture
def plain(monkeypatch):
    """Switch the shortcuts off: the scan of the cells ahead, every start made afresh."""
    def use():
        monkeypatch.setattr(CoatingFlight, "_edges", _edges_scan)
        monkeypatch.setattr(coating_flight, "REUSE", False)
    return use


def _brute_runs(depth: np.ndarray) -> np.ndarray:
    n = depth.size
    out = []
    for c in range(n):
        k = next((k for k in range(1, n) if depth[(c + k) % n] != depth[c]), n)
        out.append(k)
    return np.array(out)


def test_runs_against_the_scan():
    """The runs of equal depth (each cell's distance to the next of another depth, round the casing) against a
    plain scan, on profiles with runs, wrapping runs, one different cell and none; the next edges of nodes open,
    elastic on a cell's depth or on a surface of their own, and plastic, against the scan of every cell ahead."""
    rng = np.random.default_rng(3)
    profiles = [np.zeros(7), np.r_[np.zeros(6), 1e-5], np.r_[2e-6, np.zeros(5), 2e-6, 2e-6],
                rng.choice([0.0, 1e-6, 3e-6], size=40), rng.random(12)]
    for depth in profiles:
        assert np.array_equal(_runs(depth), _brute_runs(depth))
    s = NodalSystem(np.eye(1), np.eye(1), np.ones((1, 3)), 0.01 * np.eye(3), gap=[1.0, 1.0, 1.0],
                    casing=[50.0, 50.0, 50.0])
    fl = CoatingFlight(s, [1.0, 1.0, 1.0])
    for depth in profiles:
        p = Profile(depth, speed=3.0, angles=[0.0, 0.7, 2.9])
        for t in rng.random(25) * 4.0:
            codes = rng.integers(0, 3, 3).astype(np.int8)
            cells = fl._cells(p, t) % depth.size
            w = np.where(rng.random(3) < 0.7, depth[cells], rng.choice(depth, 3))
            w[0] = 5e-7 if rng.random() < 0.3 else w[0]  # a surface of its own (a node that stopped yielding)
            assert np.array_equal(fl._edges(p, t, codes, w), _edges_scan(fl, p, t, codes, w))


def _coating_case():
    s = NodalSystem(np.diag([1.0, 1.5]), np.array([[2.0, -1.0], [-1.0, 2.5]]), np.array([[1.0, 0.2], [0.3, 1.0]]),
                    [[0.02, 0.005], [0.005, 0.03]], gap=[1.0, 0.8], casing=[100.0, 80.0])
    depth = np.array([0.026, 0.071, 0.071, 0.175, 0.0, 0.0, 0.0, 0.048, 0.22, 0.034, 0.034, 0.155])
    return s, depth


def _same(a, b) -> None:
    for name in ("starts", "codes", "surfaces", "q", "p", "amplitudes", "jumps"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_flight_bit_for_bit(plain):
    """A worn profile with runs of equal depth, an out-of-round casing, damping and friction: nodes yield, spring
    back and are pressed beyond their yield at steps; the flight with the shortcuts is the plain one bit for bit
    (every phase's start, codes, surfaces, state and amplitudes, the depths removed at once)."""
    s, depth = _coating_case()
    speed, phi = 2.0, np.array([0.0, 0.3])
    f = Friction(0.15, T=np.array([[0.3, 0.0], [0.1, 0.5]]), C_nt=np.array([[0.004, 0.001], [0.0, 0.003]]),
                 C_tt=0.01 * np.eye(2))
    args = (s, [6.0, 5.0], np.zeros(2), np.array([2.0, 1.5]), 2 * 2 * np.pi / speed)
    kw = dict(rub=Rub(3, 0.5, speed, phi), profile=Profile(depth, speed, phi), damping=Damping(zeta=0.02))
    fast = [simulate_coating(*args, **kw), simulate_coating(*args, **kw, friction=f)]
    plain()
    slow = [simulate_coating(*args, **kw), simulate_coating(*args, **kw, friction=f)]
    for a, b in zip(fast, slow):
        assert a.starts.size > 40 and (a.codes == PLASTIC).any() and (a.jumps > 0).any()
        _same(a, b)
        assert np.array_equal(a.removed(), b.removed())


def test_wear_rub_bit_for_bit(plain, monkeypatch):
    """The coupled wear in flight with friction over three revolutions: profile, history, removed volumes, peak
    pressures and tip response bit for bit; the shortcut saves a start per phase (counted)."""
    c = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=1.0)
    s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                    gap=[1.0, 1.0], casing=[4.0, 4.0])
    f = Friction(0.1, T=np.array([[0.3, 0.0], [0.1, 0.5]]), C_nt=0.01 * np.eye(2), C_tt=0.1 * np.eye(2))
    calls = []
    start = coating_flight._start
    monkeypatch.setattr(coating_flight, "_start", lambda *a: calls.append(1) or start(*a))

    def run():
        calls.clear()
        w = wear_rub(s, c, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=3, areas=[1.0, 1.0], friction=f)
        return w, len(calls)

    (a, n_fast), _ = run(), plain()
    b, n_plain = run()
    assert a.coupling == "in_flight" and a.profile.removed > 0
    assert np.array_equal(a.depths, b.depths) and np.array_equal(a.removed, b.removed)
    assert np.array_equal(a.peak_pressure, b.peak_pressure) and np.array_equal(a.peak_displacement,
                                                                                b.peak_displacement)
    assert np.array_equal(a.tip, b.tip) and a.phases == b.phases and a.vibration_ratio == b.vibration_ratio
    assert n_plain - n_fast >= a.phases - 3  # every phase but a revolution's first starts from its decision's
