"""The whole disk against the casing, on a lumped bladed disk (disk mass, blade mass, massless tip per sector):

* the reduced annulus from the sector's cyclic modes equals the directly assembled annulus (its massless modes by
  a dense eigen-solution, its contacts' static compliance by a dense solve): frequencies, compliances, the
  dynamic compliance at a few frequencies;
* the blade shift commutes with the model;
* the standing waves of nodal diameters 0 and N/2: the orbit of ONE blade (sector model) is the annulus' orbit;
* a travelling wave found over 1/N of its period with the shift comes back in the full annulus, simulated
  without the symmetry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp

from bladecase.fe.cyclic import CyclicSector
from bladecase.nsm.massless.disk_modes import full_orbit, return_error, rotating_family, rotating_orbit
from bladecase.nsm.massless.nodal_modes import nodal_family, nodal_orbit
from bladecase.nsm.massless.nodes import simulate_nodes
from bladecase.reduction.disk import disk_model, sector_system

KD, KB, KT, KC, MD, MB = 3.0, 1.0, 2.0, 0.7, 2.0, 0.5
GAP = 0.1


def _ring(n):
    """dofs [disk, blade, tip (massless), next disk]."""
    K = np.array([[KD + KB + KC, -KB, 0.0, -KC], [-KB, KB + KT, -KT, 0.0], [0.0, -KT, KT, 0.0],
                  [-KC, 0.0, 0.0, KC]])
    return CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([MD, MB, 0.0, 0.0])), n, left=[0], right=[3])


TIP = [[0.0], [0.0], [1.0], [0.0]]


def _annulus(n):
    """The assembled annulus: dofs [disk_j, blade_j, tip_j] for every blade j; M, K, the tips' columns."""
    K, M = np.zeros((3 * n, 3 * n)), np.zeros(3 * n)
    for j in range(n):
        d, b, t, nd = 3 * j, 3 * j + 1, 3 * j + 2, 3 * ((j + 1) % n)
        K[d, d] += KD
        for a, c, k in ((d, b, KB), (b, t, KT), (d, nd, KC)):
            K[a, a] += k
            K[c, c] += k
            K[a, c] -= k
            K[c, a] -= k
        M[d], M[b] = MD, MB
    return K, M, np.eye(3 * n)[:, 2::3]


@pytest.mark.parametrize("n", [6, 7])
def test_the_reduced_annulus_equals_the_assembled_one(n):
    disk = disk_model(_ring(n), TIP, GAP, count=2)
    s = disk.system
    K, M, Wf = _annulus(n)
    # massless annulus: the tips condensed (their rows of K x = ω² M x have no mass)
    a, z = np.flatnonzero(M > 0), np.flatnonzero(M == 0)
    S = K[np.ix_(a, a)] - K[np.ix_(a, z)] @ np.linalg.solve(K[np.ix_(z, z)], K[np.ix_(z, a)])
    lam = np.linalg.eigvalsh(np.diag(M[a] ** -0.5) @ S @ np.diag(M[a] ** -0.5))
    assert s.n == lam.size == 2 * n  # every mode of the massive dofs is kept
    assert np.allclose(np.sort(np.diag(s.S)), lam, rtol=1e-12, atol=0)
    C = Wf.T @ np.linalg.solve(K, Wf)
    assert np.abs(disk.compliance - C).max() <= 1e-12 * np.abs(C).max()
    assert np.abs(s.flexibility + s.W.T @ np.linalg.solve(s.S, s.W) - C).max() <= 1e-12 * np.abs(C).max()
    # with every massive mode kept, the residual is the tips' own flexibility, 1/KT each, uncoupled
    assert np.abs(s.flexibility - np.eye(n) / KT).max() <= 1e-12 / KT
    for w2 in (0.3, 1.7, 4.0):  # dynamic compliance of the contacts: the annulus' own vs the reduced model's
        Kd = K - w2 * np.diag(M)
        exact = Wf.T @ np.linalg.solve(Kd, Wf)
        reduced = s.flexibility + s.W.T @ np.linalg.solve(s.S - w2 * s.M, s.W)
        assert np.abs(reduced - exact).max() <= 1e-10 * np.abs(exact).max(), w2


def test_the_blade_shift_commutes_with_the_model():
    n = 7
    disk = disk_model(_ring(n), TIP, GAP, count=2)
    s = disk.system
    for shift in (1, 3):
        P = disk.shift(shift)
        assert np.allclose(P.T @ P, np.eye(s.n), atol=1e-14)
        assert np.allclose(P @ s.S @ P.T, s.S, atol=1e-12 * s.S.max())
        x = np.random.default_rng(1).normal(size=s.n)  # (Wᵀ P x)_j = (Wᵀ x)_{j+shift}
        assert np.allclose(s.W.T @ (P @ x), np.roll(s.W.T @ x, -shift), atol=1e-13)
        Pb = np.roll(np.eye(n), -shift, axis=0)
        assert np.allclose(Pb @ s.H @ Pb.T, s.H, atol=1e-14)
    assert np.allclose(np.linalg.matrix_power(disk.shift(1), n), np.eye(s.n), atol=1e-12)
    x = np.random.default_rng(2).normal(size=s.n)  # every sector's displacements: its contact is the model's
    u = disk.blade_displacements(x)
    assert np.allclose(u @ np.asarray(TIP)[:, 0], s.W.T @ x, atol=1e-13)
    assert np.allclose(u[:, 3], np.roll(u[:, 0], -1), atol=1e-13)  # right face = next sector's left face


def test_a_standing_wave_of_one_blade_is_the_annulus_orbit():
    n, k = 6, 0
    ring = _ring(n)
    one = sector_system(ring, TIP, GAP, k, count=2)  # one blade, its own modes of diameter k
    fam = nodal_family(one, mode=0, freq_ratio=1.08)
    o = fam.orbits[-1]
    assert o.touching.all() and o.residual < 1e-10
    disk = disk_model(ring, TIP, GAP, count=2)
    s = disk.system
    # the sector's mode amplitudes → the annulus' (k, i, cos) coordinates: √N, the mode signs matched
    x, v = np.zeros(s.n), np.zeros(s.n)
    phi_sector = one.modes[1]
    for i in range(one.n):
        a = disk.index(k, i, 0)
        sign = np.sign(one.W[i, 0] * s.W[a, 0])
        x[a] = sign * math.sqrt(n) * (phi_sector @ o.q0)[i]
        v[a] = sign * math.sqrt(n) * (phi_sector @ o.p0)[i]
    tr = simulate_nodes(s, x, v, o.T)
    size = np.linalg.norm(np.r_[x, v])
    assert np.linalg.norm(np.r_[tr.x_end - x, tr.v_end - v]) <= 1e-8 * size
    # every blade in contact as the sector's blade, at the same times
    sec = simulate_nodes(one, phi_sector @ o.q0, phi_sector @ o.p0, o.T)
    t_sector = sec.switch_times
    t_disk = np.unique(np.round(tr.switch_times / o.T, 9)) * o.T
    assert t_sector.size == t_disk.size and np.allclose(t_disk, t_sector, atol=1e-8 * o.T)
    assert np.allclose(tr.contact_time(), sec.contact_time()[0], rtol=1e-8)
    # Newton on the whole annulus at that period: the same orbit
    ann = nodal_orbit(s, (s.modes[1].T @ x, s.modes[1].T @ v, o.T), T=o.T, mode=int(np.argmax(np.abs(x))))
    assert np.linalg.norm(np.r_[s.modes[1] @ ann.q0 - x, s.modes[1] @ ann.p0 - v]) <= 1e-8 * size


def test_nodal_diameter_n_over_2_does_not_live_in_one_sector_with_contact():
    """Alternate blades in opposition: blade 0 rubs while blade 1 is furthest from the casing, so the contact
    breaks u_1 = −u_0 (the sector model would pull blade 1 outwards). The annulus' orbit keeps instead
    u_{j+1}(t) = u_j(t + T/2): the rotating-wave symmetry of k = N/2, found over half a period."""
    n = 6
    ring = _ring(n)
    one = sector_system(ring, TIP, GAP, n // 2, count=2)
    o = nodal_family(one, mode=0, freq_ratio=1.05).orbits[-1]
    disk = disk_model(ring, TIP, GAP, count=2)
    s = disk.system
    a = disk.index(n // 2, 0, 0)
    x, v = np.zeros(s.n), np.zeros(s.n)
    phi = one.modes[1]
    for i in range(one.n):
        b = disk.index(n // 2, i, 0)
        sign = np.sign(one.W[i, 0] * s.W[b, 0])
        x[b], v[b] = sign * math.sqrt(n) * (phi @ o.q0)[i], sign * math.sqrt(n) * (phi @ o.p0)[i]
    assert return_error(s, x, v, o.T) > 1e-3  # not an orbit of the disk
    P, n1 = disk.rotating(n // 2)
    assert n1 == 2
    w = math.sqrt(s.S[a, a])
    x0 = np.eye(s.n)[a] * GAP / abs(s.W[a, 0])
    fam = rotating_family(s, P, n1, x0, np.zeros(s.n), 2 * np.pi / w, growth=(1.1, 1.3))
    r = fam[-1]
    assert r.touching and r.T < 2 * np.pi / w and return_error(s, r.x0, r.v0, r.T, periods=10) <= 1e-8


def test_a_travelling_rub_found_with_the_shift_comes_back_without_it():
    n = 6
    disk = disk_model(_ring(n), TIP, GAP, count=2)
    s = disk.system
    for k in (1, 2, 5):  # forward 1 and 2 nodal diameters; 5 = the backward wave of 1
        P, n1 = disk.rotating(k)
        x0, v0, w = disk.travelling_wave(k)
        fam = rotating_family(s, P, n1, x0, v0, 2 * np.pi / w, growth=(1.1, 1.4))
        o = fam[-1]
        assert o.touching and o.residual < 1e-10 and o.T < 2 * np.pi / w
        err = return_error(s, o.x0, o.v0, o.T, periods=10)
        assert err <= 1e-8, (k, err)
        # blade j repeats blade 0, jk/N of a period later
        tr = simulate_nodes(s, o.x0, o.v0, 3 * o.T)
        t = np.linspace(0, o.T, 7)
        y0 = s.W.T[0] @ tr.sample(t + o.T)[0]
        for j in range(1, n):
            yj = s.W.T[j] @ tr.sample(t + o.T + (j * k % n) * o.T / n)[0]
            assert np.allclose(yj, y0, atol=1e-9 * GAP), (k, j)
        full = full_orbit(s, o.x0, o.v0, o.T)
        assert full.residual < 1e-9
        assert np.abs(np.sort(np.abs(full.multipliers - 1))[:2]).max() < 1e-6  # time shift and energy


def test_bad_input_is_refused_with_its_reason():
    ring = _ring(6)
    with pytest.raises(ValueError, match="cyclic face"):
        disk_model(ring, [[1.0], [0.0], [0.0], [0.0]], GAP)
    with pytest.raises(ValueError, match="carry mass"):
        disk_model(ring, [[0.0], [1.0], [0.0], [0.0]], GAP)
    with pytest.raises(ValueError, match="not a standing wave"):
        sector_system(ring, TIP, GAP, 1)
    disk = disk_model(ring, TIP, GAP, count=2)
    with pytest.raises(ValueError, match="standing wave only"):
        disk.travelling_wave(3)
    with pytest.raises(ValueError, match="exactly one"):
        rotating_orbit(disk.system, disk.shift(1), 6, (np.ones(disk.system.n), np.zeros(disk.system.n), 1.0))


def test_the_disk_rubs_an_out_of_round_casing_through_the_executor():
    """Each blade sees the lobes at its own angle. Lobes ≡ 0 (mod N): every blade sees the same clearance at the
    same instant, the response is the nodal-diameter-0 sector's alone (its own model, angle 0). Any lobes: the
    pattern travels round the disk, every blade rubs as hard as the others."""
    from bladecase.nsm import Damping
    from bladecase.nsm.massless.rub import rub_response, rub_sweep
    from bladecase.study.executor import make_executor

    n = 6
    ring = _ring(n)
    disk = disk_model(ring, TIP, GAP, count=2)
    damping = Damping(zeta=0.05)
    speeds = [0.9 / n]  # lobes × Ω below the first frequency, 1 rad/s
    out = rub_sweep(disk.system, speeds, n, 0.15, disk.angles(), damping, revolutions=6, window=2,
                    executor=make_executor("serial"))
    one = sector_system(ring, TIP, GAP, 0, count=2)
    for speed, r in zip(speeds, out):
        ref = rub_response(one, speed, n, 0.15, [0.0], damping, revolutions=6, window=2)
        assert r.peak_force.max() > 0 and r.touching == tuple(range(n))
        assert np.allclose(r.peak_force, ref.peak_force[0], rtol=1e-8), (r.peak_force, ref.peak_force)
        assert np.allclose(r.contact_fraction, ref.contact_fraction[0], rtol=1e-8)
    r = rub_sweep(disk.system, [1.05], 1, 0.15, disk.angles(), Damping(zeta=0.1), revolutions=6, window=2,
                  executor=make_executor("serial"))[0]
    assert r.settled and r.peak_force.max() > 0  # settled to 2 %: the blades alike to that
    assert np.ptp(r.peak_force) <= 0.02 * r.peak_force.max(), r.peak_force


def test_floquet_of_the_whole_annulus_says_which_travelling_rub_is_stable():
    """On this disk the 1-diameter travelling rub (forward 1, backward 5) is stable, the 2-diameter one is not: a
    perturbation along the monodromy's leading eigenvector, flown 20 periods by the simulator, grows as |μ|²⁰."""
    n = 6
    disk = disk_model(_ring(n), TIP, GAP, count=2)
    s = disk.system
    for k, stable in ((1, True), (5, True), (2, False)):
        P, n1 = disk.rotating(k)
        x0, v0, w = disk.travelling_wave(k)
        o = rotating_family(s, P, n1, x0, v0, 2 * np.pi / w, growth=(1.1, 1.4))[-1]
        full = full_orbit(s, o.x0, o.v0, o.T)
        assert full.stable() is stable, (k, np.abs(full.nontrivial_multipliers).max())
    mu = full.nontrivial_multipliers[np.argmax(np.abs(full.nontrivial_multipliers))]
    assert abs(mu) > 1.3
    lam, V = np.linalg.eig(full.monodromy)
    vec = V[:, np.argmin(np.abs(lam - mu))].real
    phi = s.modes[1]
    dx, dv = phi @ vec[:s.n], phi @ vec[s.n:]
    eps = 1e-7 * np.linalg.norm(np.r_[o.x0, o.v0])
    scale = eps / np.linalg.norm(np.r_[dx, dv])
    p = 20
    a = simulate_nodes(s, o.x0 + scale * dx, o.v0 + scale * dv, p * o.T)
    b = simulate_nodes(s, o.x0, o.v0, p * o.T)
    growth = np.linalg.norm(np.r_[a.x_end - b.x_end, a.v_end - b.v_end]) / eps
    assert 0.7 < growth / abs(mu) ** p < 1.3, (growth, abs(mu) ** p)
