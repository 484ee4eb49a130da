"""The wear of an abradable coating coupled to the blade's dynamics (bladecase.nsm.massless.wear_rub): each
revolution flown with the profile the revolutions before left, the removed volume against the profile, the lobes
against the response's frequency."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm import Damping
from bladecase.nsm.massless.nodes import NodalSystem, Profile, Rub, simulate_nodes
from bladecase.nsm.massless.wear import Abradable
from bladecase.nsm.massless.wear_rub import vibration_ratio, wear_rub

SPEED, ANGLES, DAMPING = 0.4, [0.0, 0.3], Damping(zeta=0.05)


def _system(k: float = 4.0) -> NodalSystem:
    return NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                       gap=[1.0, 1.0], casing=[k, k])


def _coating(cells: int = 60, yield_pressure: float = 0.4) -> Abradable:
    return Abradable(thickness=1.0, yield_pressure=yield_pressure, stiffness=4.0, cells=cells, radius=30.0,
                     width=0.7)


@pytest.fixture(scope="module")
def worn():
    return wear_rub(_system(), _coating(), SPEED, 3, 1.2, ANGLES, DAMPING, revolutions=5, areas=[1.0, 1.0],
                    coupling="staggered")


def test_removed_volume_is_the_profiles_missing_area_times_width(worn):
    """The volume removed passage by passage, revolution after revolution, equals the final profile's missing
    annulus area × the band's width to 1e-6 (measured: 1e-16), and it grows with each revolution."""
    p = worn.profile
    c = p.coating
    area = float((0.5 * p.depth * (2 * c.radius + p.depth) * 2 * np.pi / c.cells).sum())   # independently
    assert p.removed == pytest.approx(area * c.width, rel=1e-6)
    assert np.all(np.diff(worn.removed) >= 0) and worn.removed[-1] > 0
    assert worn.depths.shape == (5, 60) and np.all(np.diff(worn.depths, axis=0) >= 0)   # wear only deepens


def test_each_revolution_is_flown_with_the_profile_the_ones_before_left(worn):
    """The coupling: the second revolution re-flown independently, from the first's end state and with the first
    revolution's worn profile as the clearance profile, gives the second revolution's peak displacement; flown
    without the profile it does not (the wear changed the response)."""
    s = _system()
    turn = 2 * np.pi / SPEED
    rub = Rub(3, 1.2, SPEED, ANGLES)
    first = simulate_nodes(s, np.zeros(2), np.zeros(2), turn, damping=DAMPING, rub=rub)
    t = np.linspace(0.0, turn, 4001)

    def peak(profile):
        tr = simulate_nodes(s, first.x_end, first.v_end, turn, damping=DAMPING, rub=rub, profile=profile)
        times = np.unique(np.r_[t, tr.starts])
        x, _, lam = tr.sample(times)
        return float((s.W.T @ x - s.flexibility @ lam).max())

    coupled = peak(Profile(worn.depths[0], SPEED, ANGLES))
    assert coupled == pytest.approx(worn.peak_displacement[1], rel=1e-6)
    assert abs(peak(None) - worn.peak_displacement[1]) > 1e-3 * worn.peak_displacement[1]


def test_a_coating_that_never_yields_is_the_rub_without_wear():
    w = wear_rub(_system(), _coating(yield_pressure=1e9), SPEED, 3, 1.2, ANGLES, DAMPING, revolutions=2,
                 areas=[1.0, 1.0])
    assert w.removed[-1] == 0 and w.profile.lobes() == 0 and not w.profile.worn_through


def test_the_lobes_follow_the_tip_vibration_frequency(worn):
    """The tip, driven by a three-lobe casing, vibrates at 3 × the rotation frequency, and the profile it wears has
    round(f_vib / f_rot) = 3 lobes."""
    assert worn.vibration_ratio == pytest.approx(3.0, abs=0.05)
    assert worn.lobes[-1] == round(worn.vibration_ratio) == 3


def test_vibration_ratio_and_input_errors():
    t = np.arange(600) / 150
    assert vibration_ratio(0.2 + np.sin(2 * np.pi * 5.0 * t), 150) == pytest.approx(5.0, abs=1e-6)
    with pytest.raises(ValueError, match="coating must be an Abradable"):
        wear_rub(_system(), None, SPEED, 3, 1.2, ANGLES)
    with pytest.raises(ValueError, match="revolutions must be an integer >= 1"):
        wear_rub(_system(), _coating(), SPEED, 3, 1.2, ANGLES, revolutions=0)
