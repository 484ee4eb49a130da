"""The k-ipp families as curves: the k-ipp residual with its exact Jacobian, followed by the generic driver.

A k-ipp orbit is a zero of ``[ΠΛ ; ΣΛ - d·1]`` (theory §4): ``2k`` equations in the ``2k`` unknowns
``(t₁…t_{k-1}, T, Λ)``, one of them redundant (``ΛᵀΠΛ ≡ 0``), so the solutions form curves — the nonsmooth
modes.  :class:`KippCurve` eliminates the impulses (``Λ = d Σ⁻¹ 1``) and gives the remaining impact-law
condition ``Π n``, ``n = Σ⁻¹1/|Σ⁻¹1|``, with its exact Jacobian (derivatives of the modal kernel in the impact
times and in ``T``, :meth:`bladecase.nsm.modal.ModalKernel.dT`); :mod:`bladecase.nsm.continuation` follows it.
:func:`follow_family` returns the family's certified orbits and its admissible arcs, whose ends are refined by
bisection along the curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import continuation
from .modal import ModalKernel, check_period, solve_times
from .orbits import REPEAT_RTOL, PeriodicOrbit, make_orbit
from .system import LinearSystem

#: Relative precision in ``T`` of the refined ends of admissible arcs.
ARC_RTOL = 1e-9

#: A family is not followed past two impacts closer than ``MERGE_RTOL·T``
#: (it then tends to an orbit with fewer impacts).
MERGE_RTOL = 1e-4

#: A start orbit is only re-solved from a crossing segment of a followed curve
#: when the interpolated impact times lie within ``PASS_GATE·T`` of its own
#: (under every re-anchoring); farther crossings are other orbits of that period.
PASS_GATE = 0.05


class KippCurve:
    """The k-ipp equations with the impulses eliminated, in the scaled
    unknowns ``z = (t₁/T₀ … t_{k-1}/T₀, T/T₀)``.

    ``Λ = d Σ⁻¹ 1`` satisfies the position conditions; the residual is the
    impact-law condition ``Π n`` with the direction ``n = Σ⁻¹1 / |Σ⁻¹1|``,
    scaled by ``wᵀM⁻¹w / 2`` (``k`` equations, one redundant since
    ``nᵀΠn ≡ 0``).  For k = 2 this is the paper's Eq. 15, ``s(t₁) = 0``, and
    the curve lives in the ``(t₁, T)`` plane of its Fig. 2.
    """

    def __init__(self, system: LinearSystem, k: int, T0: float, lam0: float):
        self.system, self.k, self.T0, self.lam0 = system, k, T0, lam0
        self.d = system.gap
        b = system.spectrum.contact_modes[1]
        self.scale = float(b @ b) / 2

    def times(self, z) -> tuple[float, np.ndarray]:
        """``(T, impact times)`` at ``z``."""
        T = z[-1] * self.T0
        return T, np.append(z[:-1] * self.T0, T)

    def period(self, z) -> float:
        return float(z[-1] * self.T0)

    def split(self, z):
        """``(T, times, Λ)`` at ``z`` (``LinAlgError`` if ``Σ`` is singular)."""
        T, times = self.times(z)
        _, Sigma = ModalKernel.of(self.system, T).matrices(times)
        lam = self.d * np.linalg.solve(Sigma, np.ones(self.k))
        return T, times, lam

    def join(self, times) -> np.ndarray:
        """``z`` of the impact times ``(t₁, …, t_k = T)``."""
        return times / self.T0

    def residual(self, z) -> np.ndarray:
        T, times = self.times(z)
        Pi, Sigma = ModalKernel.of(self.system, T).matrices(times)
        try:
            n = np.linalg.solve(Sigma, np.ones(self.k))
        except np.linalg.LinAlgError:
            return np.full(self.k, np.nan)
        return Pi @ (n / np.linalg.norm(n)) / self.scale

    def jacobian(self, z) -> np.ndarray:
        """Exact ``∂R/∂z`` (``k × k``): ``R = Π u / S``, ``u = n/|n|``, ``n = Σ⁻¹1``, so
        ``dR = (dΠ u + Π du)/S``, ``du = (I - uuᵀ) dn/|n|``, ``dn = -Σ⁻¹ dΣ n``."""
        k = self.k
        T, times = self.times(z)
        md = ModalKernel.of(self.system, T)
        D = np.mod(times[:, None] - times[None, :], T)
        g, s = md.g_s(D)
        dsD = md.ds(D)
        gT, sT = md.dT(D)
        off = ~np.eye(k, dtype=bool)
        s0, ds0 = np.where(off, s, 0.0), np.where(off, dsD, 0.0)
        Sigma = -g
        try:
            n = np.linalg.solve(Sigma, np.ones(k))
        except np.linalg.LinAlgError:
            return np.full((k, k), np.nan)
        nn = np.linalg.norm(n)
        u = n / nn
        # Impact times t_l (l < k): dD_ij/dt_l = δ_il - δ_jl, so column l of dX·v is
        # δ_il Σ_j X'(D_ij) v_j - X'(D_il) v_l (X = s for Π, -g for Σ).
        dPi_u = np.diag(ds0 @ u) - ds0 * u[None, :]
        dSig_n = -(np.diag(s0 @ n) - s0 * n[None, :])
        # Period (t_k = T too): D_ij = t_i - t_j + T[i < j], so dD_ij/dT = δ_ik - δ_jk + [i < j],
        # plus the kernel's own dependence on T at fixed D.
        idx = np.arange(k)
        E = (idx[:, None] == k - 1).astype(float) - (idx[None, :] == k - 1) + (idx[:, None] < idx[None, :])
        dPi_u[:, k - 1] = np.where(off, dsD * E + sT, 0.0) @ u
        dSig_n[:, k - 1] = -(s0 * E + gT) @ n
        dn = -np.linalg.solve(Sigma, dSig_n)
        du = (dn - np.outer(u, u @ dn)) / nn
        return (dPi_u + s0 @ du) * (self.T0 / self.scale)

    def valid(self, z) -> bool:
        """Ordered impacts, no two closer than ``MERGE_RTOL·T``, finite impulses,
        and not within ``MERGE_RTOL`` of a repeated orbit (period ``T/j``)."""
        T, times = self.times(z)
        gaps = np.diff(np.concatenate([[0.0], times]))
        if not (np.all(np.isfinite(z)) and T > 0 and gaps.min() > MERGE_RTOL * T):
            return False
        try:
            T, times, lam = self.split(z)
        except np.linalg.LinAlgError:
            return False
        if not np.all(np.isfinite(lam)) or np.abs(lam).max() > 1e8 * self.lam0:
            return False
        return _distance_to_repetition(times, lam, T) > MERGE_RTOL

    def crossing(self, z_a, z_b) -> bool:
        """Does the segment ``z_a → z_b`` cross a repeated orbit (all offsets flip sign)?  That is a
        branch point with the family of period-``T/j`` orbits: the family ends there."""
        for da, db in zip(_repetition_offsets(*self.times(z_a)[::-1]), _repetition_offsets(*self.times(z_b)[::-1])):
            if np.all(np.sign(da) * np.sign(db) < 0):
                return True
        return False

    def curve(self) -> continuation.Curve:
        """This problem as the continuation driver's :class:`~bladecase.nsm.continuation.Curve`."""
        return continuation.Curve(self.residual, self.jacobian, self.valid, self.crossing)


def _repetition_offsets(times, T) -> list[np.ndarray]:
    """For each ``j > 1`` dividing ``k``: the offsets of the impact pattern from
    one repeating every ``T/j`` (all zero at a repeated orbit)."""
    k = times.size
    return [np.mod(np.roll(times, -(k // j)) - times, T) - T / j for j in range(2, k + 1) if k % j == 0]


def _distance_to_repetition(times, lam, T) -> float:
    """How far (relative) the impact pattern is from repeating every ``T/j``, ``j | k``."""
    k = times.size
    scale = max(np.abs(lam).max(), np.finfo(float).tiny)
    best = np.inf
    for j in range(2, k + 1):
        if k % j:
            continue
        shift = k // j
        dt = np.mod(np.roll(times, -shift) - times, T)
        dist = max(np.abs(dt - T / j).max() / T, np.abs(np.roll(lam, -shift) - lam).max() / scale)
        best = min(best, dist)
    return best


@dataclass(frozen=True, eq=False)
class FollowedFamily:
    """What :func:`follow_family` returns: the problem, the curve's points, the certified orbits, and the
    arcs as ``(start, stop, T_lo, T_hi, refined_lo, refined_hi)`` tuples."""

    problem: KippCurve
    points: list
    orbits: list
    arcs: list


def follow_family(system: LinearSystem, k: int, start: PeriodicOrbit, T_range: tuple[float, float],
                  step: float, max_points: int, refine: bool) -> FollowedFamily:
    """The k-ipp family through the orbit ``start``, followed in both directions until it leaves
    ``T_range``, two impacts merge, it reaches a repeated orbit (a branch point with the family of
    period-``T/j`` orbits), the impulses blow up (resonance), the curve closes on itself, or the
    corrector fails at the smallest step.  The points run from the end with the smaller period to
    the end with the larger one.  Orbits are certified; admissible arcs refined (``refine``)."""
    T_lo, T_hi = T_range
    lam0 = max(np.abs(start.impulses).max(), system.gap)
    problem = KippCurve(system, k, start.T, lam0)
    z0 = problem.join(start.impact_times)
    zs, _ = continuation.trace(problem.curve(), z0, np.eye(k)[-1], ds=step, ds_min=step / 1000, ds_max=2 * step,
                               max_points=max_points, stop=lambda z: not T_lo <= problem.period(z) <= T_hi)
    if problem.period(zs[0]) > problem.period(zs[-1]):
        zs = zs[::-1]  # one orientation whatever the start: the end with the smaller period first
    orbits = []
    for z in zs:
        if not T_lo <= problem.period(z) <= T_hi:
            continue  # the step that left the period range: not part of the family
        try:
            orbits.append(polished_orbit(problem, z))
        except (ValueError, np.linalg.LinAlgError):
            continue
    arcs = _arcs(problem, [problem.join(o.impact_times) for o in orbits], orbits, refine)
    return FollowedFamily(problem, zs, orbits, arcs)


def polished_orbit(problem: KippCurve, z) -> PeriodicOrbit:
    """The orbit at curve point ``z``, its impact times re-solved at fixed ``T``
    to machine precision (Newton on ``(t, Λ)``).  Admissibility is certified;
    for a non-admissible orbit ``max_violation`` is the largest sampled
    violation (not polished)."""
    T, times, lam = problem.split(z)
    sol = solve_times(ModalKernel.of(problem.system, T), times, problem.d)
    if sol is not None and np.abs(sol[0] - times).max() < 1e-6 * T:
        times, lam = sol
    return make_orbit(problem.system, T, times, lam, polish=False)


def phase_distance(times: np.ndarray, reference: np.ndarray, T: float) -> float:
    """``min`` over re-anchorings of ``times`` (shift by each ``t_r``) of the largest
    distance to ``reference`` (both sets of ``k`` impact times in ``(0, T]``)."""
    shifted = np.mod(times[None, :] - times[:, None], T)  # row r: re-anchored at impact r
    shifted[shifted == 0] = T
    shifted.sort(axis=1)
    return float(np.abs(shifted - np.sort(reference)[None, :]).max(axis=1).min())


def passes(problem: KippCurve, zs, start: tuple[float, PeriodicOrbit]) -> bool:
    """Does the polyline ``zs`` cross the start orbit (same period, same impacts)?"""
    from .kipp import canonical_rotation

    T_s, o = start
    Ts = np.array([problem.period(z) for z in zs])
    lo, hi = np.minimum(Ts[:-1], Ts[1:]), np.maximum(Ts[:-1], Ts[1:])
    segments = np.flatnonzero((lo <= T_s) & (T_s <= hi) & (hi > lo))
    if segments.size == 0:
        return False
    md = ModalKernel.of(problem.system, T_s)
    for i in segments:
        a = (T_s - Ts[i]) / (Ts[i + 1] - Ts[i])
        ta, tb = problem.times(zs[i])[1], problem.times(zs[i + 1])[1]
        guess = ((1 - a) * ta / Ts[i] + a * tb / Ts[i + 1]) * T_s
        if phase_distance(guess, o.impact_times, T_s) > PASS_GATE * T_s:
            continue  # the interpolated impacts are far from the start's: no need to solve
        sol = solve_times(md, guess, problem.d)
        if sol is None:
            continue
        times, _ = canonical_rotation(sol[0], sol[1], T_s)
        if np.abs(times - o.impact_times).max() <= 1e3 * REPEAT_RTOL * T_s:
            return True
    return False


def _arcs(problem: KippCurve, zs, orbits, refine: bool) -> list[tuple]:
    """``(start, stop, T_lo, T_hi, refined_lo, refined_hi)`` of every maximal admissible run of ``orbits``."""
    return admissible_arcs(orbits, lambda i, out: _bisect_end(problem, zs[i], zs[out]) if refine else None)


def admissible_arcs(orbits, refine_end) -> list[tuple]:
    """``(start, stop, T_lo, T_hi, refined_lo, refined_hi)`` of every maximal admissible run of ``orbits`` (a curve).

    ``refine_end(i, out)``: the period where admissibility is lost between the run's end point ``i`` and its
    non-admissible neighbour ``out``, and whether that was found — ``(T, True)`` — or ``None`` not to refine.
    Along a curve ``T`` need not be monotone: the refined flags go with whichever end gives ``T_lo``/``T_hi``.
    """
    adm = np.array([o.admissible for o in orbits], dtype=bool)
    arcs = []
    i = 0
    while i < adm.size:
        if not adm[i]:
            i += 1
            continue
        j = i
        while j + 1 < adm.size and adm[j + 1]:
            j += 1
        (T_a, ref_a), (T_b, ref_b) = (orbits[i].T, False), (orbits[j].T, False)
        if i > 0:
            T_a, ref_a = refine_end(i, i - 1) or (T_a, False)
        if j + 1 < adm.size:
            T_b, ref_b = refine_end(j, j + 1) or (T_b, False)
        Ts = [o.T for o in orbits[i:j + 1]] + [T_a, T_b]
        lo, hi = min(Ts), max(Ts)
        arcs.append((i, j, float(lo), float(hi), bool((lo == T_a and ref_a) or (lo == T_b and ref_b)),
                     bool((hi == T_a and ref_a) or (hi == T_b and ref_b))))
        i = j + 1
    return arcs


def _bisect_end(problem: KippCurve, z_in, z_out) -> tuple[float, bool]:
    """Period where admissibility is lost between curve points ``z_in``
    (admissible) and ``z_out``: bisection along the curve.

    The midpoint is solved at fixed ``T = (T_in + T_out)/2`` by Newton from
    the interpolated impact times (robust near resonances, where the
    eliminated-impulse residual is stiff), else by the arclength corrector
    orthogonal to the chord (turning points); a midpoint that leaves the
    bracket is rejected.  Returns the admissible end and whether the bracket
    was narrowed to ``ARC_RTOL``.
    """
    system = problem.system

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
            return make_orbit(system, Tm, times, lam, polish=False).admissible
        except (ValueError, np.linalg.LinAlgError):
            return False

    def converged(z_a, z_b) -> bool:
        T_a = problem.period(z_a)
        return abs(problem.period(z_b) - T_a) <= ARC_RTOL * abs(T_a)

    z_in, _, done = continuation.bisect(problem.curve(), z_in, z_out, admissible, converged=converged,
                                        midpoint=midpoint)
    return problem.period(z_in), done
