"""The rub of a whole bladed disk in an out-of-round casing (bladecase.nsm.massless.disk_rub), checked against the
symmetry the solver does not use, the single blade's rub, and the nodal diameter the casing's lobes force."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import minimize_scalar

from bladecase.fe.cyclic import CyclicSector
from bladecase.nsm import Damping
from bladecase.nsm.massless.disk_rub import disk_rub, disk_rub_sweep, expected_diameter, nd_content
from bladecase.nsm.massless.nodes import NodalSystem
from bladecase.nsm.massless.rub import rub_run
from bladecase.reduction.disk import disk_model

GAP = 0.1


def _disk(sectors: int, coupling: float = 0.7):
    """A lumped disk: per sector a disk mass (grounded 3, to the next sector's by ``coupling``), a blade mass
    (spring 1 to the disk) and a massless tip (spring 2 to the blade), every mode kept (the reduction is exact)."""
    K = np.array([[4.0 + coupling, -1.0, 0.0, -coupling], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0],
                  [-coupling, 0.0, 0.0, coupling]])
    ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), sectors, left=[0], right=[3])
    return disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], GAP, count=2)


def _speed(disk, lobes: int, ratio: float = 0.9) -> float:
    """The speed whose lobe passing is ``ratio`` of the first frequency of the forced nodal diameter."""
    return ratio * float(np.sqrt(disk.diameters[expected_diameter(lobes, disk.sectors)].lam[0])) / lobes


def test_tuned_disk_every_blade_the_same_and_delayed():
    disk, L = _disk(12), 9
    speed = _speed(disk, L)
    r = disk_rub(disk, speed, L, 0.12, Damping(zeta=0.2), revolutions=4, window=1, keep=True)
    assert r.response == "settled" and r.peak_force.min() > 0
    assert np.ptp(r.peak_force) <= 1e-8 * r.peak_force.max()
    assert np.ptp(r.contact_share) <= 1e-8 and 0 < r.contact_share[0] < 1
    # blade j runs j/(N f_rot) ahead of blade 0: u_j(t) = u_0(t + θ_j/Ω), the solver never told so
    turn = 2 * np.pi / speed
    t = np.linspace(r.trajectory.t_end - turn, r.trajectory.t_end - turn / 12 * 11, 200)
    u = r.tips(t)
    scale = np.abs(u).max()
    for j in range(1, 12):
        ahead = r.tips(t + j * turn / 12)[0]
        assert np.abs(u[j] - ahead).max() <= 1e-8 * scale, j
    assert np.abs(u[1] - r.tips(t - turn / 12)[0]).max() > 1e-3 * scale  # the other way round does not hold


def test_uncoupled_blades_are_the_single_blade_rub():
    """Blades on a rigid, fixed disk (no coupling): blade j is the single blade turning at its own angle θ_j."""
    disk, L, speed = _disk(4, coupling=0.0), 3, 0.3
    damping = Damping(zeta=0.1)
    r = disk_rub(disk, speed, L, 0.13, damping, revolutions=4, window=1, max_revolutions=4, keep=True)
    blade = NodalSystem(np.diag([2.0, 0.5]), np.array([[4.0, -1.0], [-1.0, 1.0]]), np.array([[0.0], [1.0]]),
                        np.array([[0.5]]), gap=[GAP])
    t = np.linspace(r.trajectory.t_end - 2 * np.pi / speed, r.trajectory.t_end, 300)
    u = r.tips(t)
    assert r.peak_force.min() > 0
    for j in range(4):
        one, tr = rub_run(blade, speed, L, 0.13, [j * np.pi / 2], damping, revolutions=4, window=1,
                          max_revolutions=4)
        x, _, lam = tr.sample(t)
        tip = blade.W.T @ x - blade.flexibility @ lam
        assert np.abs(u[j] - tip[0]).max() <= 1e-10 * np.abs(tip).max()
        assert abs(r.contact_share[j] - one.contact_fraction[0]) <= 1e-10
        assert abs(r.rub.peak_force[j] - one.peak_force[0]) <= 1e-10 * one.peak_force[0]
        # the refined peak: the single blade's own force maximised over the read span (bounded Brent here)
        span = np.linspace(tr.t_end - 2 * np.pi / speed, tr.t_end, 2001)
        i = int(np.argmax(tr.sample(span)[2][0]))
        best = minimize_scalar(lambda s, tr=tr: -tr.sample(np.array([s]))[2][0, 0], bounds=(span[i - 1], span[i + 1]),
                               method="bounded", options={"xatol": 1e-12})
        assert abs(r.peak_force[j] + best.fun) <= 1e-10 * r.peak_force[j]


@pytest.mark.parametrize("sectors, lobes, nd", [(12, 3, 3), (6, 4, 2), (6, 8, 2)])
def test_response_sits_on_lobes_mod_n(sectors, lobes, nd):
    """L < N/2, L > N/2 (folded: N − L), L > N (aliased: L − N)."""
    disk = _disk(sectors)
    r = disk_rub(disk, _speed(disk, lobes), lobes, 0.12, Damping(zeta=0.2), revolutions=2, window=1)
    assert r.expected == nd and r.dominant == nd
    assert r.nd_share[nd] > 0.9 and abs(r.nd_share.sum() - 1) < 1e-12


def test_nd_content_of_a_known_wave_and_bad_input():
    j, t = np.arange(7)[:, None], np.linspace(0, 1, 40, endpoint=False)[None, :]
    share = nd_content(2.0 + np.sin(2 * np.pi * (2 * t - 5 * j / 7)))  # 5 diameters backwards = 2 folded
    assert abs(share[2] - 1) < 1e-12
    with pytest.raises(ValueError, match="N >= 2 blades"):
        nd_content(np.ones(5))
    disk = _disk(4)
    with pytest.raises(ValueError, match="speeds must be finite numbers > 0"):
        disk_rub_sweep(disk, [0.3, -1.0], 2, 0.12)
    with pytest.raises(ValueError, match="keep=True"):
        disk_rub(disk, 0.3, 2, 0.12, revolutions=2, window=1).tips([0.0])
