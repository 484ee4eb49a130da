"""The abradable coating (bladecase.nsm.massless.wear): a rigid tip on a prescribed path removes exactly the path's
excess over the profile; the removed volume equals the profile's missing area × width; the next passage sees the
worn profile; the lobes of a tip vibrating at an engine order."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.nsm.massless.wear import Abradable, WearProfile, pass_tip


def path(theta):
    """A prescribed incursion (m): 30 µm of offset, two harmonics."""
    return 3e-5 + 4e-5 * np.cos(3 * theta + 0.4) + 1.5e-5 * np.sin(5 * theta)


def dpath(theta):
    return -1.2e-4 * np.sin(3 * theta + 0.4) + 7.5e-5 * np.cos(5 * theta)


def samples_with_cell_extremes(c: Abradable, theta_path: np.ndarray):
    """Samples of one turn that hold every cell's extremes of :func:`path`: both ends of each cell (the right end
    approached from inside) and the roots of the path's slope, found to machine precision."""
    from scipy.optimize import brentq

    edges = c.step * np.arange(c.cells + 1)
    pts = [theta_path]
    for k in range(c.cells):
        a, b = edges[k], edges[k + 1]
        inner = b
        while c.cell(inner) != k:
            inner = np.nextafter(inner, a)
        left = a if c.cell(a) == k else np.nextafter(a, b)
        grid = np.linspace(left, inner, 41)
        s = dpath(grid)
        roots = [brentq(dpath, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)
                 for i in np.flatnonzero(np.sign(s[:-1]) * np.sign(s[1:]) < 0)]
        pts.append(np.r_[left, inner, roots])
    return np.sort(np.concatenate(pts))


def exact_cell_peak(c: Abradable) -> np.ndarray:
    """max over each cell of :func:`path`, from its ends and its slope's roots (a finer independent search)."""
    from scipy.optimize import minimize_scalar

    out = np.empty(c.cells)
    for k in range(c.cells):
        a, b = c.step * k, c.step * (k + 1)
        grid = np.linspace(a, b, 2001)
        i = int(np.argmax(path(grid)))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        best = minimize_scalar(lambda t: -path(t), bounds=(lo, hi), method="bounded",
                               options={"xatol": 1e-13}).x
        out[k] = max(path(a), path(b), path(best))
    return out


@pytest.mark.parametrize("stiffness", [np.inf, 2e12], ids=["rigid-plastic", "elastic-plastic"])
def test_a_rigid_tip_on_a_prescribed_path_removes_its_excess(stiffness):
    c = Abradable(thickness=2e-4, yield_pressure=4e6, stiffness=stiffness, cells=72, radius=0.25, width=0.03)
    rng = np.random.default_rng(0)
    start = WearProfile(c, rng.uniform(0.0, 5e-5, c.cells))  # an already worn profile
    theta = samples_with_cell_extremes(c, np.linspace(0, 2 * np.pi, 3001, endpoint=False))
    worn, pressure = pass_tip(start, theta, path(theta))
    excess = np.maximum(exact_cell_peak(c) - c.yield_depth - start.depth, 0.0)
    assert np.abs(worn.depth - start.depth - excess).max() < 1e-12 * 7e-5
    assert (excess > 0).sum() > 10 and (excess == 0).sum() > 10  # the path both wears and misses
    assert pressure.max() == pytest.approx(c.yield_pressure, rel=1e-12) and pressure.min() == 0.0
    assert worn.removed == pytest.approx(worn.missing_volume - start.missing_volume, rel=1e-12)


def test_the_next_passage_sees_the_worn_profile():
    c = Abradable(thickness=2e-4, yield_pressure=4e6, stiffness=2e12, cells=72, radius=0.25, width=0.03)
    theta = np.linspace(0, 2 * np.pi, 4001, endpoint=False)
    once, _ = pass_tip(WearProfile.new(c), theta, path(theta), record=True)
    twice, p2 = pass_tip(once, theta, path(theta), record=True)
    assert np.array_equal(twice.depth, once.depth) and twice.removed == once.removed  # nothing more to remove
    assert p2.max() == pytest.approx(c.yield_pressure, rel=1e-9)          # pressed to the yield, no further
    lower, p3 = pass_tip(once, theta, path(theta) - 1e-6)
    assert np.array_equal(lower.depth, once.depth) and p3.max() == pytest.approx(c.yield_pressure - 1e-6 * 2e12)
    assert len(twice.history) == 2 and not twice.worn_through


def test_removed_volume_equals_missing_area_times_width_over_many_passages():
    """A tip vibrating at 7.0 times the rotation frequency and creeping outwards, 20 revolutions: the volume
    accumulated passage by passage against the final profile's missing area × width (1e-6); the profile has
    round(f_vib / f_rot) = 7 lobes."""
    c = Abradable(thickness=5e-4, yield_pressure=3e6, stiffness=1e12, cells=360, radius=0.3, width=0.025)
    prof = WearProfile.new(c)
    ratio, turns = 7.0, 20
    for k in range(turns):
        t = np.linspace(k, k + 1, 3601)[:-1]  # time in revolutions
        r = 2e-6 * k + 2.5e-5 * np.cos(2 * np.pi * ratio * t)
        prof, _ = pass_tip(prof, 2 * np.pi * t, r, record=True)
    assert prof.removed > 0
    assert abs(prof.removed - prof.missing_volume) <= 1e-6 * prof.missing_volume
    assert prof.lobes() == round(ratio) and len(prof.history) == turns
    # the count can fail: another engine order gives another count
    other, _ = pass_tip(WearProfile.new(c), 2 * np.pi * t, 2.5e-5 * np.cos(2 * np.pi * 5 * t))
    assert other.lobes() == 5


def test_wearing_through_is_flagged_and_capped():
    c = Abradable(thickness=1e-5, yield_pressure=1e6, stiffness=np.inf, cells=12, radius=0.3, width=0.01)
    theta = np.linspace(0, 2 * np.pi, 200)
    worn, _ = pass_tip(WearProfile.new(c), theta, 2e-5 * np.cos(theta))
    assert worn.worn_through and worn.depth.max() == c.thickness


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="abradable thickness must be a finite number > 0, got 0"):
        Abradable(0, 1e6, 1e12)
    with pytest.raises(ValueError, match=r"stiffness must be a number > 0 \(inf: rigid–plastic\), got nan"):
        Abradable(1e-3, 1e6, float("nan"))
    with pytest.raises(ValueError, match="cells must be an integer >= 3"):
        Abradable(1e-3, 1e6, 1e12, cells=2)
    c = Abradable(1e-3, 1e6, 1e12, cells=10)
    with pytest.raises(ValueError, match="must be finite 1-D samples"):
        pass_tip(WearProfile.new(c), [0.0, np.nan], [0.0, 0.0])
    with pytest.raises(ValueError, match="profile must be a WearProfile"):
        pass_tip(c, [0.0], [0.0])
