"""The ends of admissible arcs, refined by bisection along their curves — many ends at once.

Where a k-ipp family stops being admissible between two of its computed orbits, the period where it does is
found by bisection along the curve (:func:`_bisect_end` does one end): the midpoint is
solved at the mean period by Newton from the interpolated impact times, else by the arclength corrector
orthogonal to the chord, a midpoint leaving the bracket stops the bisection, and the midpoint's orbit is
certified (:func:`~bladecase.nsm.newton.orbits.make_orbits`: the same proof as
:func:`~bladecase.nsm.newton.orbits.make_orbit`).
:func:`bisect_ends` runs every bracket of a search in lockstep: per bisection step, one vectorised fixed-period
Newton solve (:func:`~bladecase.nsm.newton.modal.solve_times_stack`) and one vectorised certification for all of
them.
"""

from __future__ import annotations

import numpy as np

from .. import continuation
from .modal import (
    RESONANCE_RTOL,
    ModalKernel,
    check_period,
    impact_kernels,
    solve_stack,
    solve_times,
    solve_times_stack,
)
from .orbits import PeriodicOrbit, make_orbit, make_orbits

__all__ = ["bisect_ends"]

#: Bisection steps at most per end (as :func:`bladecase.nsm.continuation.bisect`).
MAX_STEPS = 80


def bisect_ends(ends: list[tuple], rtol: float) -> list[tuple[float, bool]]:
    """For each ``(problem, z_in, z_out)`` — a :class:`~bladecase.nsm.newton.families.KippCurve` (one system and ``k``
    for all) and two of its points, ``z_in`` admissible, ``z_out`` not — the period where admissibility is lost
    between them and whether the bracket was narrowed to ``rtol`` (relative, in ``T``): the result of
    :func:`_bisect_end` for each, all bisected together.

    >>> import numpy as np
    >>> from bladecase.nsm import chain, orbits_kipp
    >>> from bladecase.nsm.newton.families import KippCurve, trace_families, polished_orbits
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> start = [o for o in orbits_kipp(system, 13.5, 2) if o.repeats == 1][1]
    >>> (problem, zs), = trace_families(system, 2, [start], (13.2, 13.75), 0.01, 400)
    >>> adm = [o.admissible for o in polished_orbits([(problem, z) for z in zs])]
    >>> i = adm.index(False) - 1                  # the last admissible point: the arc ends after it
    >>> (T, done), = bisect_ends([(problem, zs[i], zs[i + 1])], 1e-9)
    >>> round(T, 4), done                         # 5T₂, where the mode grazes (seed Fig. 2)
    (13.7293, True)
    """
    n = len(ends)
    if n == 0:
        return []
    problems = [e[0] for e in ends]
    system, d = problems[0].system, problems[0].d
    T0 = np.array([p.T0 for p in problems], dtype=float)
    Zin = np.array([e[1] for e in ends], dtype=float)
    Zout = np.array([e[2] for e in ends], dtype=float)
    live, done = np.ones(n, dtype=bool), np.zeros(n, dtype=bool)
    phase = np.full(n, np.nan)  # where (over T) the bracket's last refuted midpoint violated: checked first
    for _ in range(MAX_STEPS + 1):
        T_in, T_out = Zin[:, -1] * T0, Zout[:, -1] * T0
        near = np.abs(T_out - T_in) <= rtol * np.abs(T_in)
        done |= live & near
        live &= ~near
        rows = np.flatnonzero(live)
        if rows.size == 0 or _ == MAX_STEPS:
            break
        Zm, ok = _midpoints(problems, system, d, T0, Zin, Zout, rows)
        live[rows[~ok]] = False  # no midpoint on this stretch of the curve: the bisection stops there
        rows, Zm = rows[ok], Zm[ok]
        if rows.size == 0:
            continue
        inside, seen = _admissible(system, d, Zm * T0[rows, None], phase[rows])
        phase[rows] = np.where(np.isnan(seen), phase[rows], seen)
        Zin[rows[inside]] = Zm[inside]
        Zout[rows[~inside]] = Zm[~inside]
    return [(float(Zin[i, -1] * T0[i]), bool(done[i])) for i in range(n)]


def _midpoints(problems, system, d: float, T0, Zin, Zout, rows) -> tuple[np.ndarray, np.ndarray]:
    """The midpoints of the brackets ``rows`` and whether each is usable (found, and on the stretch between the
    two ends, near their chord)."""
    Za, Zb = Zin[rows], Zout[rows]
    Ta, Tb = Za[:, -1] * T0[rows], Zb[:, -1] * T0[rows]
    Tm = 0.5 * (Ta + Tb)
    t0 = T0[rows, None]
    guess = 0.5 * (Za * t0 / Ta[:, None] + Zb * t0 / Tb[:, None]) * Tm[:, None]  # times/T interpolated at Tm
    Zm = np.full(Za.shape, np.nan)
    fixed = np.flatnonzero(Ta != Tb)
    fixed = fixed[_regular_many(system, Tm[fixed])]
    for j, sol in zip(fixed, solve_times_stack(system, Tm[fixed], guess[fixed], d)):
        if sol is not None:
            Zm[j] = sol[0] / T0[rows[j]]
    for j in np.flatnonzero(np.isnan(Zm[:, 0])):  # no fixed-period solution: the corrector across the chord
        chord = (Zb[j] - Za[j]) / np.linalg.norm(Zb[j] - Za[j])
        z, _ = continuation.correct(problems[rows[j]].curve(), 0.5 * (Za[j] + Zb[j]), chord)
        if z is not None:
            Zm[j] = z
    span = Zb - Za
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.einsum("ij,ij->i", Zm - Za, span) / np.einsum("ij,ij->i", span, span)
        off = np.linalg.norm(Zm - Za - a[:, None] * span, axis=1)
        ok = (a > 0) & (a < 1) & (off <= np.linalg.norm(span, axis=1))
    return Zm, ok


def _regular(system, T: float) -> bool:
    try:
        check_period(system, T)
    except ValueError:
        return False
    return True


def _regular_many(system, T: np.ndarray) -> np.ndarray:
    """:func:`_regular` of each period of ``T`` (the test of :func:`~bladecase.nsm.newton.modal.check_period`, the
    same arithmetic, for all of them at once)."""
    sp = system.spectrum
    omega = sp.omega[sp.active]
    with np.errstate(invalid="ignore", over="ignore"):
        r = np.multiply.outer(T, omega) / (2 * np.pi)
        m = np.rint(r)
        bad = ((m >= 1) & (np.abs(r - m) <= RESONANCE_RTOL * r)).any(axis=1)
    return np.isfinite(T) & (T > 0) & ~bad


def _admissible(system, d: float, times: np.ndarray, phase: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Admissibility of the orbits at the impact times ``times`` (rows; impulses ``Λ = d Σ⁻¹1``), certified, a
    violation first looked for at ``phase·T`` (NaN: nowhere; the probe of :func:`_bisect_end`); and where
    (over ``T``) each refuted orbit was seen to violate the constraint (NaN: admissible, or not seen)."""
    omega, b, _ = system.spectrum.contact_modes
    lam = d * solve_stack(-impact_kernels(omega, b, times, which="g")[0], np.ones(times.shape))
    out, seen = np.zeros(len(times), dtype=bool), np.full(len(times), np.nan)
    rows = np.flatnonzero(np.all(np.isfinite(lam), axis=1) & np.all(np.isfinite(times), axis=1))
    T = times[rows, -1]
    for j, o in zip(rows, make_orbits(system, T, times[rows], lam[rows], probe=phase[rows] * T)):
        out[j], where = o.admissible, None if o.admissible else _violation_phase(o)
        seen[j] = np.nan if where is None else where
    return out, seen


def _bisect_end(problem, z_in, z_out, orbit_out: PeriodicOrbit | None = None, rtol: float = 1e-9
                ) -> tuple[float, bool]:
    """Period where admissibility is lost between curve points ``z_in``
    (admissible) and ``z_out`` (the orbit ``orbit_out``): bisection along the curve.

    The midpoint is solved at fixed ``T = (T_in + T_out)/2`` by Newton from
    the interpolated impact times (robust near resonances, where the
    eliminated-impulse residual is stiff), else by the arclength corrector
    orthogonal to the chord (turning points); a midpoint that leaves the
    bracket is rejected.  A midpoint's admissibility is checked first where
    the last non-admissible orbit of the bracket violated the constraint (the
    same verdict, found sooner).  Returns the admissible end and whether the
    bracket was narrowed to ``rtol``.
    """
    system = problem.system
    probe = [None if orbit_out is None else _violation_phase(orbit_out)]

    def midpoint(z_a, z_b):
        T_a, T_b = problem.period(z_a), problem.period(z_b)
        if T_a == T_b:
            return None
        Tm = 0.5 * (T_a + T_b)
        try:
            md = ModalKernel.of(system, check_period(system, Tm))
            guess = 0.5 * (problem.times(z_a)[1] / T_a + problem.times(z_b)[1] / T_b) * Tm
            sol = solve_times(md, guess, problem.d)
        except ValueError:
            return None
        return None if sol is None else problem.join(sol[0])

    def admissible(z) -> bool:
        try:
            Tm, times, lam = problem.split(z)
            where = None if probe[0] is None else probe[0] * Tm
            orbit = make_orbit(system, Tm, times, lam, polish=False, probe=where)
        except (ValueError, np.linalg.LinAlgError):
            return False
        if not orbit.admissible and _violation_phase(orbit) is not None:
            probe[0] = _violation_phase(orbit)
        return orbit.admissible

    def converged(z_a, z_b) -> bool:
        T_a = problem.period(z_a)
        return abs(problem.period(z_b) - T_a) <= rtol * abs(T_a)

    z_in, _, done = continuation.bisect(problem.curve(), z_in, z_out, admissible, converged=converged,
                                        midpoint=midpoint)
    return problem.period(z_in), done


def _violation_phase(orbit: PeriodicOrbit) -> float | None:
    """Where (as a fraction of the period) a non-admissible orbit was seen to violate the constraint."""
    phase = orbit.max_violation_time / orbit.T
    return float(phase) if np.isfinite(phase) and orbit.max_violation > 0 else None
