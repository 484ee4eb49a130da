"""Where an orbit's energy sits (bladecase/nsm/energy.py)."""

import numpy as np
import pytest

from bladecase.nsm import bar, chain, orbit_1ipp, orbits_kipp
from bladecase.nsm.energy import ModalSplit, describe_split, modal_energy_split
from bladecase.nsm.massless.branches import massless_mode


def test_newton_split_is_the_flight_invariant_modal_energy():
    system = chain(3, k=1.0, m=1 / 3, gap=1.0)
    orbit = orbit_1ipp(system, 8.0)
    split = modal_energy_split(orbit)
    assert split.shares.sum() == pytest.approx(1.0, abs=1e-14) and np.all(np.diff(split.frequencies) > 0)
    md = orbit._modal
    q, qd = orbit.modal_state(np.array([0.1, 0.5, 0.9]) * orbit.T)  # one flight: each mode's energy is constant
    e = 0.5 * (qd**2 + (md.omega[:, None] * q) ** 2)
    assert np.abs(e - e[:, :1]).max() <= 1e-12 * e.sum(axis=0).max()
    assert e[:, 0].sum() == pytest.approx(orbit.energy, rel=1e-12)  # the modes hold all of it
    assert np.allclose(np.sort(split.shares), np.sort(e[:, 0] / e[:, 0].sum()), atol=1e-12)


def test_two_impacts_average_over_flights():
    system = chain(2, k=1.0, m=0.5, gap=1.0)
    orbit = next(o for o in orbits_kipp(system, 13.5, 2) if o.admissible)
    split = modal_energy_split(orbit)
    edges = np.r_[0.0, orbit.impact_times]
    q, qd = orbit.modal_state(0.5 * (edges[:-1] + edges[1:]))
    e = 0.5 * (qd**2 + (orbit._modal.omega[:, None] * q) ** 2) @ np.diff(edges)
    assert np.allclose(split.shares, e / e.sum(), atol=1e-12)


def test_massless_orbit_near_grazing_sits_in_its_mode():
    s = bar(10, 0.5, contact="massless")
    mode = massless_mode(s, (3.9, 4.1))
    near, far = mode.orbits[1], mode.orbits[-1]
    assert modal_energy_split(near).shares[0] >= 0.999  # at grazing: the first open-phase mode alone
    assert 0.5 < modal_energy_split(far).shares[0] < modal_energy_split(near).shares[0]


def test_words_flag_mesh_scale_modes():
    split = ModalSplit(np.array([200.0, 900.0, 41_600.0]), np.array([0.03, 0.01, 0.96]))
    words = describe_split(split, 215.9, band=20_000.0)
    assert "96% in mode 3 (4.16e+04 Hz)" in words and "Doubtful" in words and "96%" in words
    assert "Doubtful" not in describe_split(ModalSplit(np.array([200.0, 900.0]), np.array([0.9, 0.1])), 215.9)
