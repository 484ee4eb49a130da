"""``bladecase.verify`` on the massless model's orbits of several contact phases (a ``PhasedOrbit``): one period of
the exact event-driven simulation from the middle of an open phase comes back, with as many closings as phases."""

from __future__ import annotations

import pytest

from bladecase.nsm import verify


@pytest.fixture(scope="module")
def mode(bar10_massless_mode):
    """The 10-element bar's first massless mode over (3.2, 4.1): one contact phase, then two (a fold in T);
    conftest's ``massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))``."""
    return bar10_massless_mode


def test_verify_accepts_the_orbits_of_one_and_of_two_contact_phases(mode):
    phases = sorted({o.k for o in mode.orbits})
    assert phases == [1, 2]
    for k in phases:
        orbit = next(o for o in mode.orbits if o.k == k and o.admissible)
        check = verify(orbit)
        assert check["ok"] and check["impacts"] == k and check["return_error"] < 1e-8


def test_verify_refuses_an_orbit_moved_off_its_period(mode):
    """The check can fail: the same orbit claimed with a period 1 % longer does not come back."""
    import dataclasses

    orbit = next(o for o in mode.orbits if o.k == 2 and o.admissible)
    wrong = dataclasses.replace(orbit, durations=orbit.durations * 1.01)
    check = verify(wrong)
    assert not check["ok"] and check["return_error"] > 1e-6
