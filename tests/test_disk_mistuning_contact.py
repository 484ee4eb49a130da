"""How hard each mistuned blade rubs: the engine-order response of a lumped 4-blade disk (disk and blade masses, a
massless tip on a spring, each tip its own contact against a compliant casing) from the reduced disk
(:func:`~bladecase.reduction.disk.disk_model`, every mode kept) with the blade springs scaled
(:mod:`bladecase.reduction.mistuning_disk`) and the exact simulator with the load split off
(:func:`~bladecase.nsm.massless.disk_forced.forced_contacts`), against the disk assembled in physical dofs and
integrated directly (scipy's DOP853, restarted at every contact switch found as an event): each blade's peak contact
force over the same span."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from bladecase.fe.cyclic import CyclicSector
from bladecase.nsm.massless.disk_forced import forced_contacts, linear_contacts
from bladecase.reduction.disk import disk_model
from bladecase.reduction.mistuning_disk import blade_coupling, engine_order_load, mistuned_disk

N, ORDER, ZETA = 4, 1, 0.03
MD, MB, KD, KB, KC, KT, KCASE, GAP = 2.0, 0.5, 4.0, 2.0, 0.7, 5.0, 3.0, 0.1
DELTA = np.array([0.04, -0.03, 0.02, -0.05])
AMP = 0.2  # the blade force amplitude


def _ring() -> CyclicSector:
    K = np.array([[KD + KB + KC, -KB, 0.0, -KC], [-KB, KB + KT, -KT, 0.0], [0.0, -KT, KT, 0.0],
                  [-KC, 0.0, 0.0, KC]])  # disk, blade, massless tip, next disk
    return CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([MD, MB, 0.0, 0.0])), N, left=[0], right=[3])


def _direct(omega: float, t_end: float, window: float, tip: bool) -> np.ndarray:
    """Each blade's peak contact force over ``[t_end − window, t_end]``, the disk in physical dofs; ``tip``: the
    load on the massless tip (the blade feels it through the tip's spring, the tip moves ``(f − λ)/k_t`` beyond
    its blade)."""
    K = np.zeros((2 * N, 2 * N))
    for j in range(N):
        a, b, nxt = 2 * j, 2 * j + 1, 2 * ((j + 1) % N)
        K[a, a] += KD
        K[np.ix_([a, b], [a, b])] += KB * (1 + DELTA[j]) * np.array([[1, -1], [-1, 1]])
        K[np.ix_([a, nxt], [a, nxt])] += KC * np.array([[1, -1], [-1, 1]])
    M = np.diag(np.tile([MD, MB], N))
    lam, Phi = sla.eigh(K, M)
    C = M @ Phi @ np.diag(2 * ZETA * np.sqrt(lam)) @ Phi.T @ M
    F = np.zeros(2 * N, dtype=complex)
    F[1::2] = AMP * np.exp(2j * math.pi * ORDER * np.arange(N) / N)
    U = np.linalg.solve(K - omega**2 * M + 1j * omega * C, F)  # the linear steady state: the start
    series = 1.0 / (1.0 / KT + 1.0 / KCASE)
    Minv = np.linalg.inv(M)

    def tip_offset(t):
        return (F[1::2] * np.exp(1j * omega * t)).real / KT if tip else 0.0

    def rhs(t, y):
        u, v = y[:2 * N], y[2 * N:]
        f = (F * np.exp(1j * omega * t)).real
        f[1::2] -= series * np.maximum(u[1::2] + tip_offset(t) - GAP, 0.0)
        return np.r_[v, Minv @ (f - C @ v - K @ u)]

    events = []
    for j in range(N):
        def ev(t, y, j=j):
            return y[2 * j + 1] + (tip_offset(t)[j] if tip else 0.0) - GAP
        ev.terminal = True
        events.append(ev)
    t, y = 0.0, np.r_[U.real, (1j * omega * U).real]
    ts = []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-10, atol=1e-12, events=events,
                        dense_output=True)
        ts.append((t, sol.t[-1], sol.sol))
        t, y = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:  # a switch: step over it on the next piece's side
            t2 = min(t + 1e-9, t_end)
            y = sol.sol(t2) if t2 <= sol.t[-1] else y
            t = t2 if t2 <= sol.t[-1] else t
            sol2 = solve_ivp(rhs, (t, min(t + 1e-9, t_end)), y, method="DOP853", rtol=1e-10, atol=1e-12)
            t, y = sol2.t[-1], sol2.y[:, -1]
    pieces = [(a, b, s) for a, b, s in ts if b > a]

    def force(tt: float) -> np.ndarray:
        for a, b, s in pieces:
            if a <= tt <= b:
                return series * np.maximum(s(tt)[1:2 * N:2] + tip_offset(tt) - GAP, 0.0)
        raise AssertionError(tt)

    grid = np.linspace(t_end - window, t_end, 2001)
    values = np.array([force(tt) for tt in grid])  # (samples, N)
    peaks = values.max(axis=0)
    for j in range(N):
        i = int(np.argmax(values[:, j]))
        res = minimize_scalar(lambda tt, j=j: -force(tt)[j], bounds=(grid[max(i - 1, 0)], grid[min(i + 1, 2000)]),
                              method="bounded", options={"xatol": 1e-13})
        peaks[j] = max(peaks[j], -res.fun)
    return peaks


@pytest.mark.parametrize("tip", [False, True], ids=["load on the blade", "load on the massless tip"])
def test_each_blades_peak_contact_force_equals_the_direct_integration(tip):
    ring = _ring()
    disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], GAP, count=2, casing=KCASE)  # every mode kept
    Kb = np.zeros((4, 4))
    Kb[:2, :2] = KB * np.array([[1.0, -1.0], [-1.0, 1.0]])
    system = mistuned_disk(disk, blade_coupling(disk, Kb), DELTA)
    load, residual = engine_order_load(disk, AMP * np.array([0.0, float(not tip), float(tip), 0.0]), ORDER)
    pattern = AMP * np.exp(2j * math.pi * ORDER * np.arange(N) / N)
    # on the blade: no residual; on the tip: the tip's own spring, f/k_t (reciprocity with the contacts' fields)
    assert np.abs(residual - (pattern / KT if tip else 0.0)).max() < 1e-12 * AMP
    omega = float(np.sort(system.modes[0])[2])  # near a 1-diameter mode of the mistuned disk
    Y = linear_contacts(system, load, residual, omega, ZETA)
    assert np.abs(Y).max() > 1.5 * GAP  # the linear response would pass the clearance: they rub
    # a fixed span, settled or not: the same flight compared period for period (settling is the loop's business)
    out = forced_contacts(system, load, residual, omega, ZETA, periods=5, window=2, max_periods=7, rtol=1e-12)
    assert out.periods_run == 7 and out.peak_force.min() > 0
    assert np.ptp(out.peak_force) > 0.02 * out.peak_force.max()  # mistuned: the blades rub unequally
    T = 2 * math.pi / omega
    direct = _direct(omega, out.periods_run * T, T, tip)
    assert np.abs(out.peak_force - direct).max() <= 1e-6 * direct.max()


def test_the_forced_rub_settles():
    ring = _ring()
    disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], GAP, count=2, casing=KCASE)
    Kb = np.zeros((4, 4))
    Kb[:2, :2] = KB * np.array([[1.0, -1.0], [-1.0, 1.0]])
    system = mistuned_disk(disk, blade_coupling(disk, Kb), DELTA)
    load, residual = engine_order_load(disk, AMP * np.array([0.0, 1.0, 0.0, 0.0]), ORDER)
    out = forced_contacts(system, load, residual, float(np.sort(system.modes[0])[2]), ZETA, periods=20, window=5,
                          rtol=1e-5)
    assert out.settled and out.change <= 1e-5 and 0 < out.contact_fraction.min() < 1
