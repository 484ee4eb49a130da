"""The fast k-ipp search (issue 14) finds what the one-by-one search finds; each branch is listed once (issue 15).

Correctness only (timings: ``benchmarks/bench_search.py``): the vectorised pieces against their scalar
counterparts (stacked least squares, kernel sums, the closed-form k = 2 residual, fixed-period solves,
continuation of many curves at once, the certification of many orbits, the bisection of many arc ends, the
half-angle sine and cosine), the start-coverage lookup against the start-by-start test, the whole search
against a plain sequential reference, and the geometric de-duplication of the families.
"""

from __future__ import annotations

import numpy as np
import pytest

import bladecase as bc
from bladecase.nsm import continuation, modes
from bladecase.nsm.newton.arc_ends import _bisect_end, bisect_ends
from bladecase.nsm.newton.families import (
    ARC_RTOL,
    KippCurve,
    KippCurves,
    _arcs,
    polished_orbit,
    polished_orbits,
    trace_families,
)
from bladecase.nsm.newton.kipp import canonical_rotation
from bladecase.nsm.newton.modal import (
    ModalKernel,
    impact_kernels,
    impulses_for,
    newton_times,
    solve_pairs,
    solve_times,
    solve_times_stack,
)
from bladecase.nsm.newton.orbits import REPEAT_RTOL, make_orbit, make_orbits
from bladecase.nsm.signals import TrigSum, certified_max, certified_max_stack, sincos

# two_dof, five_dof: conftest's (chain(2, k=1, m=0.5, gap=1) and chain(5, k=1, m=0.2, gap=1))

# ---------------------------------------------------------------------------------------------------------
# 1. Vectorised pieces against their scalar counterparts
# ---------------------------------------------------------------------------------------------------------


def test_lstsq_stack_is_numpy_lstsq():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((40, 5, 3))
    A[::7, :, 2] = A[::7, :, 0]  # rank-deficient members: the same minimum-norm solution as numpy's
    b = rng.standard_normal((40, 5))
    ref = np.array([np.linalg.lstsq(a, v, rcond=None)[0] for a, v in zip(A, b)])
    np.testing.assert_allclose(continuation.lstsq_stack(A, b), ref, rtol=0, atol=1e-13 * np.abs(ref).max())
    P = continuation.pinv_stack(A)
    np.testing.assert_allclose(np.einsum("bij,bj->bi", P, b), ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_lstsq2_stack_is_lstsq_stack():
    """The closed-form two-unknown least squares of the k = 2 corrector: LAPACK's solutions to round-off times the
    condition number, the rank-deficient rows (handed to LAPACK) its minimum-norm ones exactly."""
    rng = np.random.default_rng(1)
    A = rng.standard_normal((200, 3, 2))
    A[:, :2] *= 10.0 ** rng.uniform(-2, 6, (200, 1, 1))  # a corrector's [J; tangent]: |J| up to 1e6
    A[::9, :, 1] = 2 * A[::9, :, 0]  # rank deficient
    A[5, 0, 0] = np.nan  # not finite: NaN as lstsq_stack
    b = rng.standard_normal((200, 3))
    ref = continuation.lstsq_stack(A, b)
    got = continuation.lstsq2_stack(A, b, min_rows=0)
    cond = np.linalg.cond(np.nan_to_num(A))
    ok = np.isfinite(ref).all(axis=1)
    assert np.isnan(got[5]).all() and not ok[5]
    err = np.abs(got - ref).max(axis=1)[ok] / np.abs(ref).max(axis=1)[ok]
    assert (err <= 1e-14 * cond[ok]).all(), err.max()
    np.testing.assert_array_equal(got[::9][1:], ref[::9][1:])  # rank deficient: LAPACK's own answer
    square = A[:, :2]  # M = N = 2 (rows 10-16 regular): the solution of the square system
    np.testing.assert_allclose(continuation.lstsq2_stack(square[10:17], b[10:17, :2], min_rows=0),
                               np.linalg.solve(square[10:17], b[10:17, :2, None])[..., 0], rtol=1e-9)


@pytest.mark.parametrize("sysname,k", [("two_dof", 2), ("five_dof", 2), ("five_dof", 3), ("five_dof", 4)])
def test_impact_kernels_are_the_modal_kernel(request, sysname, k):
    system = request.getfixturevalue(sysname)
    rng = np.random.default_rng(k)
    T = rng.uniform(5.0, 9.0, 6)
    times = np.sort(rng.uniform(0.05, 0.95, (6, k)), axis=1) * T[:, None]
    times[:, -1] = T
    g, s, ds, gT, sT = impact_kernels(*system.spectrum.contact_modes[:2], times, derivatives=True)
    for b in range(6):
        md = ModalKernel.of(system, T[b])
        D = np.mod(times[b][:, None] - times[b][None, :], T[b])
        for got, want in zip((g[b], s[b], ds[b], *(gT[b], sT[b])), (*md.g_s(D), md.ds(D), *md.dT(D))):
            np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11 * np.abs(want).max())


def test_closed_form_k2_is_the_general_residual(five_dof):
    rng = np.random.default_rng(5)
    curves = KippCurves(five_dof, 2, rng.uniform(5.0, 9.0, 30), np.ones(30))
    Z = np.column_stack([rng.uniform(0.05, 0.95, 30), rng.uniform(0.97, 1.03, 30)])
    idx = np.arange(30)
    R2, J2 = curves._evaluate2(Z, idx, True)
    R, J = curves._evaluate(Z, idx, True)
    np.testing.assert_allclose(R2, R, rtol=0, atol=1e-12 * np.abs(R).max())
    np.testing.assert_allclose(J2, J, rtol=0, atol=1e-11 * np.abs(J).max())
    # and the Jacobian is exact: central differences converge to it at second order (100x per 10x step)
    for i in (0, 7, 19):
        errs = []
        for h in (1e-3, 1e-4):
            fd = np.column_stack([(curves.evaluate(Z[i: i + 1] + h * e, idx[i: i + 1])[0][0]
                                   - curves.evaluate(Z[i: i + 1] - h * e, idx[i: i + 1])[0][0]) / (2 * h)
                                  for e in np.eye(2)[:, None, :]])
            errs.append(np.abs(fd - J2[i]).max() / np.abs(J2[i]).max())
        assert errs[1] <= 2e-2 * errs[0] + 1e-9, (i, errs)


def test_solve_times_stack_is_solve_times(five_dof):
    T = 7.3
    orbits = bc.orbits_kipp(five_dof, T, 2)
    rng = np.random.default_rng(2)
    guesses = np.array([o.impact_times * (1 + 0.01 * rng.uniform(-1, 1, 2)) for o in orbits])
    guesses[:, -1] = T
    stack = solve_times_stack(five_dof, np.full(len(orbits), T), guesses, five_dof.gap)
    n_found = 0
    for guess, got in zip(guesses, stack):
        want = solve_times(ModalKernel.of(five_dof, T), guess, five_dof.gap)
        assert (got is None) == (want is None)
        if want is not None:
            np.testing.assert_allclose(got[0], want[0], rtol=1e-12)
            np.testing.assert_allclose(got[1], want[1], rtol=1e-9)
            n_found += 1
    assert n_found >= 0.8 * len(orbits)


def test_solve_pairs_is_the_general_fixed_period_solve(five_dof):
    """The scalar 2-ipp equation s(t1) = 0 (solve_pairs) gives the general Gauss-Newton solution (times to
    1e-12 T, impulses to 1e-9) from the same guesses; where it fails the row is NaN, and solve_times falls
    back on the general solve."""
    omega, b, _ = five_dof.spectrum.contact_modes
    rng = np.random.default_rng(3)
    T, guesses, wants = [], [], []
    for Tk in (5.9, 7.3, 8.6):
        kernel = ModalKernel.of(five_dof, Tk)
        for o in bc.orbits_kipp(five_dof, Tk, 2):
            guess = o.impact_times * np.array([1 + 0.005 * rng.uniform(-1, 1), 1.0])
            want = newton_times(kernel, guess, impulses_for(kernel, guess, five_dof.gap), five_dof.gap)
            if want is not None:
                T.append(Tk)
                guesses.append(guess)
                wants.append(want)
    assert len(wants) >= 10
    times, lam = solve_pairs(omega, b, np.array(T), np.array(guesses)[:, 0], five_dof.gap)
    for Tk, got_t, got_l, (want_t, want_l) in zip(T, times, lam, wants):
        np.testing.assert_allclose(got_t, want_t, rtol=0, atol=1e-12 * Tk)
        np.testing.assert_allclose(got_l, want_l, rtol=1e-9)
    # a guess on a maximum of |s| (s' = 0): Newton cannot start, the row is NaN
    kernel = ModalKernel.of(five_dof, 7.3)
    u = np.linspace(0.01, 7.29, 20001)
    top = u[np.argmax(np.abs(kernel.g_s(u)[1]))]
    bad, _ = solve_pairs(omega, b, np.array([7.3]), np.array([top]), five_dof.gap)
    assert np.isnan(bad).all() or abs(bad[0, 0] - top) > 1e-3  # never "converged" where it started


def test_many_curves_followed_as_one_by_one(five_dof):
    """trace_stack (all families together) gives each family's points as continuation.trace does alone."""
    T_range = (6.0, 9.0)
    starts = [o for o in bc.orbits_kipp(five_dof, 7.5, 2) if o.repeats == 1]
    together = trace_families(five_dof, 2, starts, T_range, 0.01, 400)
    for o, (_, zs) in zip(starts, together):
        problem = KippCurve(five_dof, 2, o.T, max(np.abs(o.impulses).max(), five_dof.gap))
        alone, _ = continuation.trace(problem.curve(), problem.join(o.impact_times), np.eye(2)[-1], ds=0.01,
                                      ds_min=1e-5, ds_max=0.02, max_points=400,
                                      stop=lambda z, p=problem: not T_range[0] <= p.period(z) <= T_range[1])
        if problem.period(alone[0]) > problem.period(alone[-1]):
            alone = alone[::-1]
        assert len(zs) == len(alone)
        np.testing.assert_allclose(np.array(zs), np.array(alone), rtol=0, atol=1e-9)


def test_batch_driver_on_another_curve():
    """BatchCurve.of wraps scalar curves: circles of three radii followed together close on themselves."""
    radii = [1.0, 2.0, 0.5]
    curves = [continuation.Curve(residual=lambda z, r=r: np.array([z @ z - r * r]),
                                 jacobian=lambda z: 2 * z[None, :]) for r in radii]
    traced = continuation.trace_stack(continuation.BatchCurve.of(curves), np.array([[r, 0.0] for r in radii]),
                                      np.array([0.0, 1.0]), np.arange(3), ds=0.1, max_points=400)
    for r, (pts, _) in zip(radii, traced):
        np.testing.assert_allclose([np.hypot(*p) for p in pts], r, rtol=1e-9)
        assert len(pts) > 2 * np.pi * r / 0.2 - 2


def test_sincos_is_sin_and_cos():
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.uniform(-1e4, 1e4, 200_000), rng.uniform(-3, 3, 100_000),
                        np.arange(1, 20_000) * np.pi, (np.arange(1, 20_000) + 0.5) * np.pi, [0.0, -0.0]])
    s, c = sincos(x)
    assert np.abs(s - np.sin(x)).max() <= 3e-16 and np.abs(c - np.cos(x)).max() <= 3e-16
    assert np.abs(s * s + c * c - 1).max() <= 1e-15


def test_certified_max_stack_is_certified_max():
    """The batched proof gives each sum's verdict, sampled maximum and bound (polish=False) — sums that hold,
    that fail by far, that just graze the tolerance, on intervals from a fraction of a period to many."""
    rng = np.random.default_rng(4)
    omega = np.sort(rng.uniform(0.3, 7.0, 15))
    n = 300
    alpha = rng.standard_normal((n, 15)) * rng.uniform(0.01, 1.0, (n, 1))
    beta = rng.standard_normal((n, 15)) * rng.uniform(0.01, 1.0, (n, 1))
    length = rng.uniform(0.05, 40.0, n)
    peak = np.array([TrigSum(a, b, omega)(np.linspace(0, L, 4001))[0].max() for a, b, L in zip(alpha, beta, length)])
    const = -peak * rng.choice([1.2, 1.0 + 1e-12, 0.9], n)  # clear, grazing, violated
    tol = np.full(n, 1e-9)
    got = certified_max_stack(alpha, beta, omega, const, length, tol)
    want = [certified_max(TrigSum(a, b, omega, c), L, 1e-9, polish=False)
            for a, b, c, L in zip(alpha, beta, const, length)]
    assert [bool(x) for x in got[3]] == [w.certified for w in want]
    assert 30 <= int(got[3].sum()) <= n - 30  # both verdicts are exercised
    scale = np.abs(alpha).sum(axis=1) + np.abs(beta).sum(axis=1)
    np.testing.assert_allclose(got[0], [w.value for w in want], rtol=0, atol=1e-12 * scale.max())
    np.testing.assert_allclose(got[2], [w.upper for w in want], rtol=0, atol=1e-12 * scale.max())
    # flights between impacts: both ends exactly at zero
    ends = certified_max_stack(alpha, beta, omega, const, length, tol, ends_at_zero=True)
    ref = [certified_max(TrigSum(a, b, omega, c), L, 1e-9, ends_at_zero=True, polish=False)
           for a, b, c, L in zip(alpha, beta, const, length)]
    assert [bool(x) for x in ends[3]] == [w.certified for w in ref]


def _family_points(system, k, T, T_range):
    starts = [o for o in bc.orbits_kipp(system, T, k) if o.repeats == 1]
    return [(p, z) for p, zs in trace_families(system, k, starts, T_range, 0.01, 400) for z in zs]


@pytest.mark.parametrize("k", [2, 3])
def test_make_orbits_is_make_orbit(five_dof, k):
    points = _family_points(five_dof, k, 7.5, (6.0, 9.0))
    T = np.array([p.period(z) for p, z in points])
    times = np.array([p.times(z)[1] for p, z in points])
    lam = np.array([p.split(z)[2] for p, z in points])
    lam[::7] *= -1  # pulling impulses: never admissible
    many = make_orbits(five_dof, T, times, lam)
    one = [make_orbit(five_dof, *args, polish=False) for args in zip(T, times, lam)]
    assert [o.admissible for o in many] == [o.admissible for o in one]
    assert 10 <= sum(o.admissible for o in many) <= len(many) - 10
    assert [o.repeats for o in many] == [o.repeats for o in one]
    np.testing.assert_allclose([o.energy for o in many], [o.energy for o in one], rtol=1e-12)
    np.testing.assert_allclose([o.max_violation for o in many], [o.max_violation for o in one], rtol=1e-12,
                               atol=1e-14)
    unchecked = make_orbits(five_dof, T, times, lam, certify=False)
    assert not any(o.admissible for o in unchecked) and all(np.isnan(o.max_violation) for o in unchecked)
    alone = [make_orbit(five_dof, *args, certify=False) for args in zip(T, times, lam)]  # no flight looked at
    assert not any(o.admissible for o in alone) and all(np.isnan(o.max_violation) for o in alone)
    assert [o.repeats for o in alone] == [o.repeats for o in one]
    np.testing.assert_allclose([o.energy for o in alone], [o.energy for o in one], rtol=0, atol=0)
    assert make_orbits(five_dof, [], np.zeros((0, k)), np.zeros((0, k))) == []
    # a suspected violation checked first (the probe of the arc-end bisection): the same verdicts as make_orbit's
    # probe and as no probe at all, a refuted orbit's probed violation the same as make_orbit's
    bad = [o for o in one if not o.admissible and o.max_violation > 0]
    probe = np.array([np.nan if o.admissible else o.max_violation_time for o in one])
    probe[1::2] = bad[0].max_violation_time  # elsewhere for half of them: misses as well as hits
    probed = make_orbits(five_dof, T, times, lam, probe=probe)
    alone = [make_orbit(five_dof, *args, polish=False, probe=None if np.isnan(p) else p)
             for *args, p in zip(T, times, lam, probe)]
    assert [o.admissible for o in probed] == [o.admissible for o in alone] == [o.admissible for o in one]
    np.testing.assert_allclose([o.max_violation for o in probed], [o.max_violation for o in alone], rtol=1e-12,
                               atol=1e-14)
    assert sum(o.max_violation < w.max_violation for o, w in zip(probed, one)) >= 3  # some refuted by the probe


def test_bisect_ends_is_bisect_end(five_dof):
    """Every admissibility change of the families through the starts at one period, bisected all together and
    one by one: the same periods (to 10 ARC_RTOL) and the same convergence flags."""
    points = _family_points(five_dof, 2, 7.5, (6.0, 9.0))
    orbits = polished_orbits(points)
    ends = []
    for n, ((p, z), o) in enumerate(zip(points, orbits)):
        for m in (n - 1, n + 1):
            if 0 <= m < len(points) and points[m][0] is p and o is not None and orbits[m] is not None:
                if o.admissible and not orbits[m].admissible:
                    ends.append((p, z, points[m][1]))
    assert len(ends) >= 4
    together = bisect_ends(ends, ARC_RTOL)
    alone = [_bisect_end(p, a, b, None, ARC_RTOL) for p, a, b in ends]
    assert [d for _, d in together] == [d for _, d in alone]
    np.testing.assert_allclose([T for T, _ in together], [T for T, _ in alone], rtol=10 * ARC_RTOL)


# ---------------------------------------------------------------------------------------------------------
# 2. The search: start coverage by lookup, and the whole search, against start-by-start references
# ---------------------------------------------------------------------------------------------------------


def _passes_one(problem, zs, T_s, start) -> bool:
    """The start-coverage test of the one-by-one search: every crossing of the start's period near it solved."""
    Ts = np.array([problem.period(z) for z in zs])
    for i in range(len(zs) - 1):
        lo, hi = sorted((Ts[i], Ts[i + 1]))
        if not (lo <= T_s <= hi and hi > lo):
            continue
        a = (T_s - Ts[i]) / (Ts[i + 1] - Ts[i])
        guess = ((1 - a) * problem.times(zs[i])[1] / Ts[i] + a * problem.times(zs[i + 1])[1] / Ts[i + 1]) * T_s
        if modes.phase_distance(guess, start.impact_times, T_s) > modes.PASS_GATE * T_s:
            continue
        sol = solve_times(ModalKernel.of(problem.system, T_s), guess, problem.d)
        if sol is not None:
            times, _ = canonical_rotation(sol[0], sol[1], T_s)
            if np.abs(times - start.impact_times).max() <= 1e3 * REPEAT_RTOL * T_s:
                return True
    return False


def _starts(system, k, T_range, scan):
    out = []
    for T in np.linspace(*T_range, scan):
        try:
            out.extend((T, o) for o in bc.orbits_kipp(system, T, k) if o.repeats == 1)
        except ValueError:
            continue
    return out


def test_coverage_lookup_is_the_start_by_start_test(five_dof):
    T_range = (6.0, 9.0)
    starts = _starts(five_dof, 2, T_range, 8)
    traced = trace_families(five_dof, 2, [o for _, o in starts[::5]], T_range, 0.01, 400)
    n_passed = 0
    for problem, zs in traced:
        by_lookup = modes.starts_passed(problem, zs, starts)
        one_by_one = [m for m, (T, o) in enumerate(starts) if _passes_one(problem, zs, T, o)]
        assert by_lookup == one_by_one
        n_passed += len(by_lookup)
    assert n_passed >= len(traced)  # each family passes at least its own start


@pytest.mark.parametrize("k", [2, 3])
def test_start_index_near_many_is_near_of_each(k):
    """The lookup of the starts near many interpolated crossings at once: for each crossing, exactly the starts
    of that period within PASS_GATE·T of it under some re-anchoring (phase_distances over all of them), in the
    index's order; none missed at the edges of the sorted first-impact ranges."""
    from types import SimpleNamespace

    from bladecase.nsm.newton.coverage import _StartIndex

    rng = np.random.default_rng(7 + k)
    T = 10.0
    refs = np.sort(rng.uniform(0.01, T, (400, k)), axis=1)
    refs[:, -1] = T
    starts = [(T, SimpleNamespace(impact_times=r)) for r in refs]
    index = _StartIndex(starts)
    guesses = refs[rng.integers(0, len(refs), 60)] + rng.normal(0.0, 0.3, (60, k))
    guesses[:, -1] = T
    members, sorted_refs = index.groups[0]
    got = index.near_many(0, guesses, T)
    assert len(got) == len(guesses)
    found = 0
    for guess, (m, r) in zip(guesses, got):
        keep = modes.phase_distances(guess, sorted_refs, T) <= modes.PASS_GATE * T
        assert m.tolist() == members[keep].tolist() and np.array_equal(r, sorted_refs[keep])
        one = index.near(0, guess, T)
        assert one[0].tolist() == m.tolist()
        found += m.size
    assert found >= len(guesses)  # each guess is near the start it was drawn from (noise 0.3 < gate 0.5)


def _reference_search(system, k, T_range, scan):
    """The search as it was: each start not passed by an earlier family followed alone, the later starts
    tested one by one."""
    lo, hi = T_range
    starts = _starts(system, k, T_range, scan)
    covered = [False] * len(starts)
    families = []
    for n, (_, o) in enumerate(starts):
        if covered[n]:
            continue
        problem = KippCurve(system, k, o.T, max(np.abs(o.impulses).max(), system.gap))
        zs, _ = continuation.trace(problem.curve(), problem.join(o.impact_times), np.eye(k)[-1], ds=0.01,
                                   ds_min=1e-5, ds_max=0.02, max_points=400,
                                   stop=lambda z, p=problem: not lo <= p.period(z) <= hi)
        if problem.period(zs[0]) > problem.period(zs[-1]):
            zs = zs[::-1]
        orbits = [polished_orbit(problem, z) for z in zs if lo <= problem.period(z) <= hi]
        arcs = _arcs(problem, [problem.join(x.impact_times) for x in orbits], orbits, True)
        for m in range(n + 1, len(starts)):
            if not covered[m] and _passes_one(problem, zs, *starts[m]):
                covered[m] = True
        families.append((orbits, arcs))
    return families


@pytest.mark.parametrize("sysname,k,T_range,scan", [("two_dof", 2, (3.0, 14.5), 24), ("five_dof", 2, (6.0, 9.0), 8),
                                                    ("two_dof", 3, (5.0, 9.0), 4)])
def test_search_finds_what_the_one_by_one_search_finds(request, chain_families, sysname, k, T_range, scan):
    system = request.getfixturevalue(sysname)
    fast = chain_families(sysname, k, T_range, scan)  # bc.nonsmooth_mode(system, k, T_range, scan=scan), once
    ref = _reference_search(system, k, T_range, scan)
    assert len(fast) == len(ref)
    for f, (orbits, arcs) in zip(fast, ref):
        np.testing.assert_allclose(f.T, [o.T for o in orbits], rtol=1e-10)
        np.testing.assert_allclose([o.impact_times for o in f.orbits], [o.impact_times for o in orbits],
                                   rtol=1e-8, atol=1e-8 * T_range[1])
        assert [o.admissible for o in f.orbits] == [o.admissible for o in orbits]
        assert len(f.arcs) == len(arcs)
        for a, b in zip(f.arcs, arcs):
            assert (a.start, a.stop, a.refined_lo, a.refined_hi) == (b[0], b[1], b[4], b[5])
            assert a.T_lo == pytest.approx(b[2], rel=10 * ARC_RTOL) and a.T_hi == pytest.approx(b[3], rel=10 * ARC_RTOL)


# ---------------------------------------------------------------------------------------------------------
# 3. Each branch once (issue 15)
# ---------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def chain10_runs():
    """The default-range 2-ipp search of chain(10), with and without the geometric de-duplication."""
    system = bc.chain(10, k=1.0, m=0.1, gap=1.0)
    T1 = 2 * np.pi / system.spectrum.omega[0]
    T_range = (0.9 * T1, 0.9999 * T1)
    deduplicated = bc.nonsmooth_mode(system, 2, T_range)
    mp = pytest.MonkeyPatch()
    mp.setattr(modes, "distinct_runs", lambda orbits: [list(range(len(orbits)))])
    mp.setattr(modes, "_contained", lambda families, pairs: None)
    try:
        raw = bc.nonsmooth_mode(system, 2, T_range)
    finally:
        mp.undo()
    return deduplicated, raw


def _arc_keys(family):
    return [(a.T_lo, a.T_hi) for a in family.arcs]


def _repeats(keys) -> int:
    return sum(1 for i, a in enumerate(keys) for b in keys[:i]
               if abs(a[0] - b[0]) <= 10 * ARC_RTOL * a[0] and abs(a[1] - b[1]) <= 10 * ARC_RTOL * a[1])


def test_no_family_lists_an_arc_twice(chain10_runs):
    deduplicated, raw = chain10_runs
    assert max(_repeats(_arc_keys(f)) for f in raw) >= 2  # the case at hand: a family that loops and relists
    assert all(_repeats(_arc_keys(f)) == 0 for f in deduplicated)


def test_de_duplication_keeps_every_distinct_arc(chain10_runs):
    deduplicated, raw = chain10_runs

    def distinct(families):
        keys = sorted(k for f in families for k in _arc_keys(f))
        return [k for i, k in enumerate(keys) if _repeats(keys[: i + 1]) == _repeats(keys[:i])]

    got, want = distinct(deduplicated), distinct(raw)
    assert len(got) == len(want)
    np.testing.assert_allclose(got, want, rtol=10 * ARC_RTOL)
    assert sum(len(f.orbits) for f in deduplicated) < sum(len(f.orbits) for f in raw)


def test_no_family_lies_on_another(chain10_runs):
    deduplicated, _ = chain10_runs
    for i, f in enumerate(deduplicated):
        for j, g in enumerate(deduplicated):
            if i != j and len(g.orbits) >= 2 and g.T.min() <= f.T.min() and f.T.max() <= g.T.max():
                assert not modes.on_curve(g.orbits, f.orbits).all(), (i, j)


def test_distinct_runs_leaves_out_a_retraced_stretch(chain_families):
    fam = max(chain_families("two_dof", 2, (3.0, 14.5), 24), key=lambda f: len(f.orbits))  # nonsmooth_mode(...)
    n = len(fam.orbits)
    assert modes.distinct_runs(fam.orbits) == [list(range(n))]  # a plain family: one run, all of it
    back = fam.orbits + fam.orbits[n - 2: n // 2: -1]  # then back along itself: the way back is left out
    assert modes.distinct_runs(back) == [list(range(n))]
    # a family that was contained in another one
    assert modes.on_curve(fam.orbits, fam.orbits[n // 3: n // 2]).all()
    assert not modes.on_curve(fam.orbits[: n // 3], fam.orbits[n // 2:]).any()
