"""A phase of the every-node massless contact model built from one Cholesky solve of its closed block, against the
textbook formulas with the explicit inverse ``G = H_AA⁻¹`` and the full clearance matrix ``P``; the flight's phase
cache, bounded, gives the same trajectory bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless import nodes_phase
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, Rub, simulate_nodes
from bladecase.nsm.massless.nodes_phase import phase_signals


def system(n: int = 6, m: int = 12, seed: int = 3) -> NodalSystem:
    """A random interior (``M = I``), ``m`` coupled contact nodes, half of them on a compliant casing."""
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n))
    S = B @ B.T + n * np.eye(n)
    W = rng.standard_normal((n, m))
    C = rng.standard_normal((m, m))
    H = 0.1 * (C @ C.T / m + np.eye(m))
    casing = np.where(np.arange(m) % 2 == 0, np.inf, 20.0)
    return NodalSystem(np.eye(n), S, W, H, gap=0.5 + rng.random(m), casing=casing)


def textbook(fl: NodalFlight, A: np.ndarray) -> dict:
    """The phase's data by the explicit inverse: ``K = Ω² + W_A G W_Aᵀ``, the signals ``L q + P g(t)``, the
    equilibrium, the harmonic particular solution and the signals' constant and harmonic parts."""
    s, n = fl.system, fl.n
    idx = np.flatnonzero(A)
    G = np.linalg.inv(s.H[np.ix_(idx, idx)])
    WA = fl.Wq[:, idx]
    K = np.diag(fl.omega**2) + WA @ G @ WA.T
    L, P = phase_signals(fl.Wq, s.H, A, G)
    q_eq = np.linalg.solve(K, WA @ G @ s.gap[idx])
    Z = K - fl.nu**2 * np.eye(n) + 1j * fl.nu * fl.Cq
    X = np.linalg.solve(Z, WA @ G @ fl.D[idx])
    return {"G": G, "GWt": G @ WA.T, "L": L, "P": P, "q_eq": q_eq, "X": X, "const": L @ q_eq + P @ s.gap,
            "E0": L @ X + P @ fl.D, "eq_map": np.linalg.solve(K, WA @ G), "K": K}


def close(a, b, rtol: float = 1e-11) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and float(np.abs(a - b).max(initial=0.0)) <= rtol * max(float(np.abs(b).max()), 1e-300)


@pytest.mark.parametrize("closed", [[0], [1, 2], [0, 3, 4, 7, 8], list(range(12))])
def test_a_phase_from_one_cholesky_solve_is_the_textbook_phase(closed):
    s = system()
    fl = NodalFlight(s, Damping(zeta=0.02), Rub(3, 0.4, 7.0, np.linspace(0, 2, s.m)))
    A = np.zeros(s.m, dtype=bool)
    A[closed] = True
    ph, ref = fl.phase(A), textbook(fl, A)
    for name in ("GWt", "L", "q_eq", "X", "const", "E0", "K"):
        assert close(getattr(ph, name), ref[name]), name
    # made when asked, as the textbook has them
    assert close(ph.G, ref["G"]) and close(ph.P, ref["P"]) and close(ph.eq_map, ref["eq_map"])
    # the closed contacts' forces from the kept products: λ_A = G_A (W_Aᵀq − g_A(t))
    rng = np.random.default_rng(0)
    Q, t = rng.standard_normal((fl.n, 5)), np.linspace(0.0, 1.0, 5)
    assert close(ph.closed_forces(Q, t, fl.gap), ref["GWt"] @ Q - ref["G"] @ fl.gap(t)[ph.idx])
    # a worn casing's piece: every clearance wider by delta
    delta = 1e-2 * rng.random(s.m)
    sh = ph.shifted(delta)
    assert close(sh.const, ref["const"] + ref["L"] @ (ref["eq_map"] @ delta[ph.idx]) + ref["P"] @ delta)
    assert close(sh.closed_forces(Q, t, fl.gap), ref["GWt"] @ Q - ref["G"] @ (fl.gap(t) + delta[:, None])[ph.idx])


def test_no_contact_closed():
    s = system()
    fl = NodalFlight(s, None, Rub(3, 0.4, 7.0, np.linspace(0, 2, s.m)))
    ph = fl.phase(np.zeros(s.m, dtype=bool))
    assert np.array_equal(ph.L, -fl.Wq.T) and np.array_equal(ph.const, s.gap) and np.array_equal(ph.E0, fl.D)
    assert ph.G.shape == (0, 0) and ph.eq_map.shape == (fl.n, 0) and np.array_equal(ph.P, np.eye(s.m))


def test_a_bounded_phase_cache_gives_the_same_trajectory_bit_for_bit(monkeypatch):
    s = system()
    rub, damping = Rub(3, 1.2, 2.0, np.linspace(0, 2, s.m)), Damping(zeta=0.01)
    x0 = np.zeros(s.n)
    free = simulate_nodes(s, x0, x0, 8.0, damping=damping, rub=rub)
    sets = np.unique(free.active, axis=0).shape[0]
    assert free.switch_times.size > 40 and sets > 8  # enough sets of closed contacts to overflow a cache of 3
    monkeypatch.setattr(nodes_phase, "PHASE_CACHE", 3)
    fl = NodalFlight(s, damping, rub)
    bounded = simulate_nodes(s, x0, x0, 8.0, flight=fl)
    assert len(fl._phases) == 3
    assert np.array_equal(bounded.switch_times, free.switch_times)
    assert np.array_equal(bounded.active, free.active)
    t = np.linspace(0.0, 8.0, 161)
    assert np.array_equal(bounded.sample(t)[2], free.sample(t)[2])  # forces from phases made again
