"""Orbits of the massless model with several contact phases per period (bladecase/nsm/massless/phases.py) and the
mode followed through changes of its phase pattern (bladecase/nsm/massless/follow.py)."""

import pickle

import numpy as np
import pytest

from bladecase.nsm import Branch
from bladecase.nsm.massless.model import simulate_massless
from bladecase.nsm.massless.orbits import closing_residual
from bladecase.nsm.massless.phases import PhasedOrbit, solve_half, split_at


@pytest.fixture(scope="module")
def bar10(mode10):
    return mode10.system  # bar(10, 0.5, contact="massless")


@pytest.fixture(scope="module")
def mode10(bar10_massless_mode):
    return bar10_massless_mode  # conftest's: massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))


def test_one_phase_pattern_is_the_symmetric_orbit_residual(bar10):
    a0, r0, g0 = closing_residual(bar10, 1.6, 0.1, True)
    a1, r1, J1 = solve_half(bar10, "open", [1.6, 0.1], gradient=True)
    assert np.abs(a1 - a0).max() <= 1e-12 * np.abs(a0).max()
    assert r1[0] == pytest.approx(r0, rel=1e-12) and np.allclose(J1[0], g0, rtol=1e-11)


@pytest.mark.parametrize("first", ["open", "closed"])
def test_exact_jacobian_matches_finite_differences(bar10, first):
    tau = np.array([0.7, 0.3, 0.2, 0.5])
    _, _, J = solve_half(bar10, first, tau, gradient=True)
    h = 1e-7  # central differences: truncation O(h²) ≈ 2e-9 relative here (2e-7 at h = 1e-6)
    fd = np.column_stack([(solve_half(bar10, first, tau + h * e)[1] - solve_half(bar10, first, tau - h * e)[1])
                          / (2 * h) for e in np.eye(tau.size)])
    assert np.abs(J - fd).max() <= 1e-7 * np.abs(J).max()


def test_the_mode_gains_contact_phases_and_every_orbit_comes_back_in_the_simulator(bar10, mode10):
    ks = np.array([o.k for o in mode10.orbits])
    assert ks[0] == 1 and ks.max() >= 2 and bool(mode10.admissible.all())
    assert mode10.T.min() < 3.3 and mode10.T.max() > 4.0  # from grazing (T₁ = 4.018 for n = 10) to below 3.3
    for o in [mode10.orbits[i] for i in np.linspace(0, len(mode10.orbits) - 1, 12).astype(int)]:
        x, v = o.state(0.0)
        tr = simulate_massless(bar10, x[:, 0], v[:, 0], o.T)
        assert sum(p == "closed" for p in tr.phases) == o.k  # the independent simulation sees k contact phases
        assert np.abs(tr.x_end - x[:, 0]).max() <= 1e-10 * np.abs(x).max()
        assert np.abs(tr.v_end).max() <= 1e-9 * np.abs(x).max()
        assert bar10.energy(tr.x_end, tr.v_end) == pytest.approx(o.energy, rel=1e-10)
        assert o.impact_times.size == o.k == o.impulses.size and np.all(o.impulses > 0)
        assert np.allclose(o.impact_times, np.sort(np.mod(tr.switch_times[np.array(tr.phases) == "closed"], o.T)
                                           ) + 0.0, atol=1e-9) or o.k == 1


def test_boundary_orbits_solve_the_split_pattern(bar10, mode10):
    """Where the pattern changes, the boundary orbit solves the new pattern with a zero-duration phase."""
    ks = [o.k for o in mode10.orbits]
    i = next(j for j in range(1, len(ks)) if ks[j] != ks[j - 1])
    edge, after = mode10.orbits[i - 1], mode10.orbits[i]
    assert after.T == pytest.approx(edge.T, rel=1e-3)
    proofs = edge.proofs
    j = int(np.argmax([p.value for p in proofs]))  # the phase that touches
    first, tau, grown = split_at(edge.first, edge.durations, j, proofs[j].where)
    _, r = solve_half(bar10, first, tau)
    assert np.abs(r).max() <= 1e-6 * bar10.gap and tau[grown] == 0.0


def test_monodromy_is_symplectic_and_matches_the_simulator(bar10, mode10):
    o = next(o for o in mode10.orbits if o.k == 2)
    M = o.monodromy()
    assert np.linalg.det(M) == pytest.approx(1.0, abs=1e-8)
    mu = np.linalg.eigvals(M)
    assert np.sort(np.abs(mu - 1))[:2].max() <= 1e-4  # time shift and energy: two multipliers at 1
    x, v = o.state(0.0)
    z0, eps = np.concatenate([x[:, 0], v[:, 0]]), 1e-7 * np.abs(x).max()
    n = bar10.n
    fd = np.empty_like(M)
    for j in range(2 * n):  # the flow map over T is differentiable (continuous vector field): central differences
        ends = []
        for sgn in (1, -1):
            z = z0.copy()
            z[j] += sgn * eps
            tr = simulate_massless(bar10, z[:n], z[n:], o.T)
            ends.append(np.concatenate([tr.x_end, tr.v_end]))
        fd[:, j] = (ends[0] - ends[1]) / (2 * eps)
    assert np.abs(fd - M).max() <= 1e-5 * np.abs(M).max()


def test_records_round_trip(bar10, mode10):
    o = next(o for o in mode10.orbits if o.k == 2)
    back = PhasedOrbit.from_dict(bar10, o.to_dict())
    assert back.energy == pytest.approx(o.energy, rel=1e-13) and back.k == 2
    again = Branch.from_dict(bar10, mode10.to_dict())
    assert np.allclose(again.energy, mode10.energy, rtol=1e-12)
    assert again.impact_times.shape == mode10.impact_times.shape
    blob = pickle.dumps(o)
    assert len(blob) < 4000 and pickle.loads(blob).system is None
    with pytest.raises(ValueError, match="first must be"):
        PhasedOrbit(bar10, "shut", [1.0, 1.0], o.a)
