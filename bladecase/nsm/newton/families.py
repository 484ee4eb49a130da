"""The k-ipp families as curves: the k-ipp residual with its exact Jacobian, followed by the generic driver.

A k-ipp orbit is a zero of ``[ΠΛ ; ΣΛ - d·1]`` (theory §4): ``2k`` equations in the ``2k`` unknowns
``(t₁…t_{k-1}, T, Λ)``, one of them redundant (``ΛᵀΠΛ ≡ 0``), so the solutions form curves — the nonsmooth
modes.  :class:`KippCurve` eliminates the impulses (``Λ = d Σ⁻¹ 1``) and gives the remaining impact-law
condition ``Π n``, ``n = Σ⁻¹1/|Σ⁻¹1|``, with its exact Jacobian (derivatives of the modal kernel in the impact
times and in ``T``, :meth:`bladecase.nsm.newton.modal.ModalKernel.dT`); :mod:`bladecase.nsm.continuation` follows it.
:class:`KippCurves` evaluates many such curves at once, so that :class:`FamilyTracer` and :func:`trace_families`
follow many families together (the same algorithm on each, its numerical work vectorised over the families).
:func:`follow_family` and :func:`complete_families` give the families' certified orbits
(:func:`polished_orbits`: the fixed-period Newton polish and the certification vectorised,
:func:`~bladecase.nsm.newton.orbits.make_orbits`) and admissible arcs, whose ends are refined by bisection along the
curve (all ends of a batch of families together, :func:`~bladecase.nsm.newton.arc_ends.bisect_ends`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import continuation
from ..arcs import admissible_arcs
from ..system import LinearSystem
from .arc_ends import _bisect_end, bisect_ends
from .modal import (
    ModalKernel,
    impact_kernels,
    solve_stack,
    solve_times,
    solve_times_stack,
)
from .orbits import PeriodicOrbit, make_orbit, make_orbits

#: Relative precision in ``T`` of the refined ends of admissible arcs.
ARC_RTOL = 1e-9

#: A family is not followed past two impacts closer than ``MERGE_RTOL·T``
#: (it then tends to an orbit with fewer impacts).
MERGE_RTOL = 1e-4


class KippCurves:
    """Many k-ipp curves of one system, evaluated together: member ``i`` is the curve of
    :class:`KippCurve` with scales ``T0[i]``, ``lam0[i]`` (rows of a stack carry their member index).
    For k = 2 the residual and its Jacobian are in closed form (``Σ⁻¹1 ∝ (1, 1)``).

    >>> from bladecase.nsm import chain, orbits_kipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> o = orbits_kipp(system, 13.5, 2)[1]
    >>> curves = KippCurves(system, 2, [13.5, 13.5], [1.0, 1.0])
    >>> R, J = curves.evaluate(np.array([o.impact_times / 13.5, [0.3, 1.0]]), np.array([0, 1]), jacobian=True)
    >>> bool(np.abs(R[0]).max() < 1e-12), bool(np.abs(R[1]).max() > 1e-3), J.shape
    (True, True, (2, 2, 2))
    """

    def __init__(self, system: LinearSystem, k: int, T0, lam0):
        self.system, self.k, self.d = system, k, system.gap
        self.T0, self.lam0 = np.atleast_1d(np.asarray(T0, dtype=float)), np.atleast_1d(np.asarray(lam0, dtype=float))
        self.omega, self.b, _ = system.spectrum.contact_modes
        self.scale = float(self.b @ self.b) / 2
        self._b2, self._sqrt2_scale = self.b**2, np.sqrt(2) * self.scale
        self._work = np.zeros(0)

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_work": np.zeros(0)}  # the scratch space is not state

    def _scratch(self, rows: int) -> np.ndarray:
        """Scratch space ``(4, 2, rows, m)`` for the k = 2 kernel terms, reused from call to call: the
        evaluations of a trace are many and large, and fresh temporaries of that size each time would cost
        more in page faults than in arithmetic."""
        size = 8 * rows * self.omega.size
        if self._work.size < size:
            self._work = np.empty(max(size, 2 * self._work.size))
        return self._work[:size].reshape(4, 2, rows, self.omega.size)

    def extend(self, T0, lam0) -> np.ndarray:
        """Add members (scales ``T0``, ``lam0``); their indices."""
        first = self.T0.size
        self.T0 = np.concatenate([self.T0, np.asarray(T0, dtype=float)])
        self.lam0 = np.concatenate([self.lam0, np.asarray(lam0, dtype=float)])
        return np.arange(first, self.T0.size)

    def times(self, Z, idx) -> np.ndarray:
        """Impact times ``(t₁, …, t_k = T)`` of the rows of ``Z``."""
        return Z * self.T0[idx][:, None]

    def _pair(self, Z, idx, sines: bool = True):
        """k = 2: ``(T0, T, D, c, sin, cos of ωT/2, cos, sin of ω(D - T/2))`` at the one delay
        ``D = (t₁ - T) mod T`` (``Σ = -[[g(0), g(D)], [g(D), g(0)]]``, ``Π = [[0, s(D)], [-s(D), 0]]``).

        The terms of :func:`~bladecase.nsm.newton.modal.half_period_terms` and
        :func:`~bladecase.nsm.newton.modal.delay_terms` (the same arithmetic, so the same values), both angles
        through one pass of :func:`~bladecase.nsm.signals.sincos_half`'s half-angle formulas, in this object's
        scratch space (:meth:`_scratch`): views valid until its next evaluation."""
        return self._terms(Z, idx)[:8] if sines else (*self._terms(Z, idx)[:7], None)

    def _terms(self, Z, idx):
        """:meth:`_pair`'s terms, then the scratch blocks ``W[1]`` and ``X`` ``(2, B, m)`` left free."""
        T0 = self.T0[idx]
        T = Z[:, 1] * T0
        D = np.mod(Z[:, 0] * T0 - T, T)
        S, C, W, X = self._scratch(len(T))  # sines, cosines, then c = b²/(2 sin(ωT/2)) in W[0]
        np.multiply((T / 4)[:, None], self.omega, out=S[0])
        np.multiply(((D - T / 2) / 2)[:, None], self.omega, out=S[1])
        np.tan(S, out=S)  # sincos_half, in place: t = tan y, sin 2y = 2t/(1 + t²), cos 2y = (1 - t²)/(1 + t²)
        np.multiply(S, S, out=C)
        np.add(C, 1.0, out=W)
        np.reciprocal(W, out=W)
        np.subtract(1.0, C, out=C)
        C *= W
        S *= W
        S *= 2.0
        c = np.multiply(S[0], 2.0, out=W[0])
        np.divide(self._b2, c, out=c)
        return T0, T, D, c, S[0], C[0], C[1], S[1], W[1], X

    def _sigma(self, c, ch, cp, w, x) -> np.ndarray:
        """``g(0) + g(D) = Σ (cos ωT/2 + cos ω(D - T/2)) c/ω`` of :meth:`_pair`'s terms (``Σ`` is singular where
        it vanishes), with the scratch blocks ``w``, ``x`` ``(B, m)``."""
        return np.einsum("bm,bm->b", np.add(ch, cp, out=x), np.divide(c, self.omega, out=w))

    def _evaluate2(self, Z, idx, jacobian: bool):
        """:meth:`evaluate` for k = 2 in closed form: ``n = Σ⁻¹1 ∝ (1, 1)``, so ``R = ∓s(D) (1, -1)/(√2 S)``."""
        T0, _, _, c, sh, ch, cp, sp, w, X = self._terms(Z, idx)
        sigma = self._sigma(c, ch, cp, w, X[0])
        f = np.where(sigma == 0, np.nan, -np.sign(sigma)) / self._sqrt2_scale  # u = -sign(σ)(1, 1)/√2
        R = np.empty((len(T0), 2))
        np.multiply(f, np.einsum("bm,bm->b", sp, c), out=R[:, 1])  # -f·s(D), s(D) = -Σ c sin
        np.negative(R[:, 1], out=R[:, 0])
        if not jacobian:
            return R, None
        cw = np.multiply(c, self.omega, out=w)
        ds = -np.einsum("bm,bm->b", cp, cw)  # s'(D)
        x = np.multiply(cw, ch, out=X[1])
        np.divide(x, sh, out=x)
        b1, b2 = -ds / 2, np.einsum("bm,bm->b", sp, x) / 2  # ∂s/∂T at D and T - D: b1 ± b2
        g = f * T0
        J = np.empty((len(T0), 2, 2))
        np.multiply(g, ds, out=J[:, 0, 0])
        np.multiply(g, b1 + b2, out=J[:, 0, 1])
        np.negative(J[:, 0, 0], out=J[:, 1, 0])
        np.multiply(g, ds + b1 - b2, out=J[:, 1, 1])
        return R, J

    def evaluate(self, Z, idx, jacobian: bool = False):
        """Residuals ``(B, k)`` and, with ``jacobian``, exact Jacobians ``(B, k, k)`` (see :meth:`KippCurve.jacobian`);
        NaN rows where ``Σ`` is singular."""
        return self._evaluate2(Z, idx, jacobian) if self.k == 2 else self._evaluate(Z, idx, jacobian)

    def _evaluate(self, Z, idx, jacobian: bool):
        """:meth:`evaluate` for any ``k``."""
        k = self.k
        times = self.times(Z, idx)
        T = times[:, -1]
        sums = impact_kernels(self.omega, self.b, times, derivatives=jacobian)
        off = ~np.eye(k, dtype=bool)
        Sigma, s0 = -sums[0], np.where(off, sums[1], 0.0)
        n = solve_stack(Sigma, np.ones((len(T), k)))
        nn = np.linalg.norm(n, axis=1)
        u = n / nn[:, None]
        R = np.einsum("bij,bj->bi", s0, u) / self.scale
        if not jacobian:
            return R, None
        dsD, gT, sT = sums[2:]
        ds0, eye = np.where(off, dsD, 0.0), np.eye(k)
        # Impact times t_l (l < k): dD_ij/dt_l = δ_il - δ_jl, so column l of dX·v is
        # δ_il Σ_j X'(D_ij) v_j - X'(D_il) v_l (X = s for Π, -g for Σ).
        dPi_u = np.einsum("bij,bj->bi", ds0, u)[:, :, None] * eye - ds0 * u[:, None, :]
        dSig_n = -(np.einsum("bij,bj->bi", s0, n)[:, :, None] * eye - s0 * n[:, None, :])
        # Period (t_k = T too): D_ij = t_i - t_j + T[i < j], so dD_ij/dT = δ_ik - δ_jk + [i < j],
        # plus the kernel's own dependence on T at fixed D.
        i = np.arange(k)
        E = (i[:, None] == k - 1).astype(float) - (i[None, :] == k - 1) + (i[:, None] < i[None, :])
        dPi_u[:, :, k - 1] = np.einsum("bij,bj->bi", np.where(off, dsD * E + sT, 0.0), u)
        dSig_n[:, :, k - 1] = -np.einsum("bij,bj->bi", s0 * E + gT, n)
        dn = -solve_stack(Sigma, dSig_n)
        du = (dn - u[:, :, None] * np.einsum("bi,bij->bj", u, dn)[:, None, :]) / nn[:, None, None]
        return R, (dPi_u + s0 @ du) * (self.T0[idx] / self.scale)[:, None, None]

    def valid(self, Z, idx) -> np.ndarray:
        """:meth:`KippCurve.valid` of every row."""
        times = self.times(Z, idx)
        T = times[:, -1]
        with np.errstate(invalid="ignore"):
            gaps = np.diff(np.concatenate([np.zeros((len(T), 1)), times], axis=1), axis=1)
            ok = np.all(np.isfinite(Z), axis=1) & (T > 0) & (gaps.min(axis=1) > MERGE_RTOL * T)
        rows = np.flatnonzero(ok)
        if rows.size == 0:
            return ok
        t, T = times[rows], T[rows]
        if self.k == 2:  # Σ⁻¹1 = -(1, 1)/(g(0) + g(D))
            _, _, _, c, _, ch, cp, _, w, X = self._terms(Z[rows], idx[rows])
            with np.errstate(divide="ignore"):
                lam = np.repeat((-self.d / self._sigma(c, ch, cp, w, X[0]))[:, None], 2, axis=1)
        else:
            lam = self.d * solve_stack(-impact_kernels(self.omega, self.b, t, which="g")[0], np.ones(t.shape))
        with np.errstate(invalid="ignore"):
            fine = np.all(np.isfinite(lam), axis=1) & (np.abs(lam).max(axis=1) <= 1e8 * self.lam0[idx[rows]])
            ok[rows] = fine & (_distance_to_repetition(t, lam, T) > MERGE_RTOL)
        return ok

    def crossing(self, ZA, ZB, idx) -> np.ndarray:
        """:meth:`KippCurve.crossing` of every pair of rows."""
        out = np.zeros(len(ZA), dtype=bool)
        for da, db in zip(_repetition_offsets(self.times(ZA, idx)), _repetition_offsets(self.times(ZB, idx))):
            out |= np.all(np.sign(da) * np.sign(db) < 0, axis=1)
        return out

    def batch(self) -> continuation.BatchCurve:
        """These curves as the continuation driver's :class:`~bladecase.nsm.continuation.BatchCurve`."""
        return continuation.BatchCurve(self.evaluate, self.valid, self.crossing)


class KippCurve:
    """The k-ipp equations with the impulses eliminated, in the scaled
    unknowns ``z = (t₁/T₀ … t_{k-1}/T₀, T/T₀)``.

    ``Λ = d Σ⁻¹ 1`` satisfies the position conditions; the residual is the
    impact-law condition ``Π n`` with the direction ``n = Σ⁻¹1 / |Σ⁻¹1|``,
    scaled by ``wᵀM⁻¹w / 2`` (``k`` equations, one redundant since
    ``nᵀΠn ≡ 0``).  For k = 2 this is the paper's Eq. 15, ``s(t₁) = 0``, and
    the curve lives in the ``(t₁, T)`` plane of its Fig. 2.

    >>> from bladecase.nsm import chain, orbits_kipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> orbit = orbits_kipp(system, 13.5, 2)[1]         # on the curve: the residual vanishes
    >>> curve = KippCurve(system, 2, 13.5, 1.0)
    >>> z = curve.join(orbit.impact_times)
    >>> bool(np.abs(curve.residual(z)).max() < 1e-12), curve.jacobian(z).shape, curve.valid(z)
    (True, (2, 2), True)
    """

    def __init__(self, system: LinearSystem, k: int, T0: float, lam0: float):
        self.system, self.k, self.T0, self.lam0 = system, k, T0, lam0
        self.d = system.gap
        self.curves = KippCurves(system, k, [T0], [lam0])
        self.scale = self.curves.scale

    def times(self, z) -> tuple[float, np.ndarray]:
        """``(T, impact times)`` at ``z``."""
        times = np.asarray(z, dtype=float) * self.T0
        return times[-1], times

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
        return self.curves.evaluate(np.asarray(z, dtype=float)[None, :], np.zeros(1, dtype=int))[0][0]

    def jacobian(self, z) -> np.ndarray:
        """Exact ``∂R/∂z`` (``k × k``): ``R = Π u / S``, ``u = n/|n|``, ``n = Σ⁻¹1``, so
        ``dR = (dΠ u + Π du)/S``, ``du = (I - uuᵀ) dn/|n|``, ``dn = -Σ⁻¹ dΣ n``."""
        return self.curves.evaluate(np.asarray(z, dtype=float)[None, :], np.zeros(1, dtype=int), True)[1][0]

    def valid(self, z) -> bool:
        """Ordered impacts, no two closer than ``MERGE_RTOL·T``, finite impulses,
        and not within ``MERGE_RTOL`` of a repeated orbit (period ``T/j``)."""
        return bool(self.curves.valid(np.asarray(z, dtype=float)[None, :], np.zeros(1, dtype=int))[0])

    def crossing(self, z_a, z_b) -> bool:
        """Does the segment ``z_a → z_b`` cross a repeated orbit (all offsets flip sign)?  That is a
        branch point with the family of period-``T/j`` orbits: the family ends there."""
        one = np.zeros(1, dtype=int)
        return bool(self.curves.crossing(np.asarray(z_a, dtype=float)[None, :], np.asarray(z_b, dtype=float)[None, :],
                                         one)[0])

    def curve(self) -> continuation.Curve:
        """This problem as the continuation driver's :class:`~bladecase.nsm.continuation.Curve`."""
        return continuation.Curve(self.residual, self.jacobian, self.valid, self.crossing)


def _repetition_offsets(times) -> list[np.ndarray]:
    """For each ``j > 1`` dividing ``k``: the offsets ``(B, k)`` of the impact patterns (rows of ``times``, the
    last one ``T``) from one repeating every ``T/j`` (all zero at a repeated orbit)."""
    k = times.shape[1]
    T = times[:, -1:]
    return [np.mod(np.roll(times, -(k // j), axis=1) - times, T) - T / j for j in range(2, k + 1) if k % j == 0]


def _distance_to_repetition(times, lam, T) -> np.ndarray:
    """How far (relative) each impact pattern (rows) is from repeating every ``T/j``, ``j | k``."""
    k = times.shape[1]
    scale = np.maximum(np.abs(lam).max(axis=1), np.finfo(float).tiny)
    best = np.full(len(T), np.inf)
    for j in range(2, k + 1):
        if k % j:
            continue
        shift = k // j
        dt = np.mod(np.roll(times, -shift, axis=1) - times, T[:, None])
        dist = np.maximum(np.abs(dt - T[:, None] / j).max(axis=1) / T,
                          np.abs(np.roll(lam, -shift, axis=1) - lam).max(axis=1) / scale)
        best = np.minimum(best, dist)
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
    traced = trace_families(system, k, [start], T_range, step, max_points)
    return complete_families(traced, T_range, refine)[0][0]


class FamilyTracer:
    """The curves of the families through start orbits, traced together; starts join and leave at any step.

    Each start is traced as :func:`follow_family` does (both directions, until the curve leaves ``T_range``,
    impacts merge, it reaches a repeated orbit, the impulses blow up, it closes or the corrector fails); the
    numerical work of all running traces is done together (:class:`~bladecase.nsm.continuation.Followers`).
    """

    def __init__(self, system: LinearSystem, k: int, T_range: tuple[float, float], step: float, max_points: int):
        self.system, self.k = system, k
        self.T_lo, self.T_hi = T_range
        self.curves = KippCurves(system, k, [], [])
        self.run = continuation.Followers(self.curves.batch(), ds=step, ds_min=step / 1000, ds_max=2 * step,
                                          max_points=max_points, stop=self._stop)
        self.members: dict = {}

    def _stop(self, Z, idx):
        T = Z[:, -1] * self.curves.T0[idx]
        return ~((self.T_lo <= T) & (T <= self.T_hi))

    def add(self, keys: list, starts: list[PeriodicOrbit]) -> None:
        """Start tracing the family through each orbit of ``starts``, known by its key."""
        if not starts:
            return
        lam0 = [max(np.abs(o.impulses).max(), self.system.gap) for o in starts]
        idx = self.curves.extend([o.T for o in starts], lam0)
        Z0 = np.array([o.impact_times / o.T for o in starts])
        fwd, bwd = self.run.add_traces(Z0, np.eye(self.k)[-1], idx)
        for key, i, f, b, z0 in zip(keys, idx, fwd, bwd, Z0):
            self.members[key] = (i, f, b, z0)

    def step(self) -> None:
        """One continuation step of every running trace."""
        self.run.step()

    def done(self, key) -> bool:
        _, f, b, _ = self.members[key]
        return not self.run._state["live"][[f, b]].any()

    def cancel(self, key) -> None:
        """Stop tracing this family (its points are dropped)."""
        _, f, b, _ = self.members.pop(key)
        self.run.cancel([f, b])

    def result(self, key) -> tuple[KippCurve, list]:
        """``(problem, points)`` of a finished trace, the points from the smaller period to the larger."""
        i, f, b, z0 = self.members.pop(key)
        problem = KippCurve(self.system, self.k, self.curves.T0[i], self.curves.lam0[i])
        zs = self.run.points[b][::-1] + [z0] + self.run.points[f]
        if problem.period(zs[0]) > problem.period(zs[-1]):
            zs = zs[::-1]  # one orientation whatever the start: the end with the smaller period first
        return problem, zs


def trace_families(system: LinearSystem, k: int, starts: list[PeriodicOrbit], T_range: tuple[float, float],
                   step: float, max_points: int) -> list[tuple[KippCurve, list]]:
    """The curves of the families through each orbit of ``starts``, traced together (the curve part of
    :func:`follow_family`): ``(problem, points)`` per start, the points from the smaller period to the larger.

    >>> from bladecase.nsm import chain, orbits_kipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> starts = [o for o in orbits_kipp(system, 13.5, 2) if o.repeats == 1]
    >>> traced = trace_families(system, 2, starts, (13.2, 13.75), 0.01, 400)
    >>> [(round(p.period(zs[0]), 3), round(p.period(zs[-1]), 3)) for p, zs in traced]  # to the step out of range
    [(13.038, 13.762), (13.329, 13.779)]
    """
    tracer = FamilyTracer(system, k, T_range, step, max_points)
    tracer.add(list(range(len(starts))), starts)
    while tracer.run.running.size:
        tracer.step()
    return [tracer.result(i) for i in range(len(starts))]


def complete_families(traced: list[tuple[KippCurve, list]], T_range: tuple[float, float], refine: bool,
                      runs: Callable[[list[PeriodicOrbit]], list[list[int]]] | None = None
                      ) -> list[list[FollowedFamily]]:
    """The certified orbits (:func:`polished_orbit`, the fixed-``T`` solves of all families vectorised) and the
    admissible arcs of traced families (:func:`trace_families`).

    ``runs(orbits)``: the stretches (index runs into the orbits, in curve order) each family is to be cut into,
    e.g. to leave out what its curve traces twice; default: one stretch.  Returns, per traced family, one
    :class:`FollowedFamily` per stretch (the problem and the curve points shared).
    """
    T_lo, T_hi = T_range
    todo = []  # the points within T_range (their periods as KippCurve.period computes them)
    for f, (problem, zs) in enumerate(traced):
        T = np.array(zs, dtype=float)[:, -1] * problem.T0
        todo.extend((f, zs[i]) for i in np.flatnonzero((T_lo <= T) & (T <= T_hi)).tolist())
    orbits: list[list[PeriodicOrbit]] = [[] for _ in traced]
    for (f, _), orbit in zip(todo, polished_orbits([(traced[f][0], z) for f, z in todo])):
        if orbit is not None:
            orbits[f].append(orbit)
    parts = []  # (family, the stretch's orbits, their curve points)
    for f, ((problem, _), found) in enumerate(zip(traced, orbits)):
        for run in (runs(found) if runs is not None else [list(range(len(found)))]):
            part = [found[i] for i in run]
            parts.append((f, part, [problem.join(o.impact_times) for o in part]))
    ends: dict[tuple[int, int, int], tuple] = {}  # (stretch, end, outside neighbour) → the bracket to bisect
    if refine:  # every end of every stretch's arcs, bisected together
        for n, (f, part, zp) in enumerate(parts):
            admissible_arcs(part, lambda i, out, n=n, p=traced[f][0], zp=zp:
                            ends.setdefault((n, i, out), (p, zp[i], zp[out])) and None)
    refined = dict(zip(ends, bisect_ends(list(ends.values()), ARC_RTOL)))
    out: list[list[FollowedFamily]] = [[] for _ in traced]
    for n, (f, part, _) in enumerate(parts):
        problem, zs = traced[f]
        arcs = admissible_arcs(part, lambda i, o, n=n: refined.get((n, i, o)))
        out[f].append(FollowedFamily(problem, zs, part, arcs))
    return out


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


def polished_orbits(points: list[tuple[KippCurve, np.ndarray]]) -> list[PeriodicOrbit | None]:
    """:func:`polished_orbit` of many ``(problem, z)`` pairs of one system and ``k``, the impulses and the
    fixed-``T`` Newton solves vectorised; ``None`` where the orbit is undefined (singular ``Σ``)."""
    out: list[PeriodicOrbit | None] = [None] * len(points)
    if not points:
        return out
    problem = points[0][0]
    system, d = problem.system, problem.d
    omega, b, _ = system.spectrum.contact_modes
    times = np.array([z for _, z in points], dtype=float) * np.array([problem.T0 for problem, _ in points])[:, None]
    T = times[:, -1]
    lam = d * solve_stack(-impact_kernels(omega, b, times, which="g")[0], np.ones(times.shape))  # NaN if Σ singular
    rows = np.flatnonzero(np.all(np.isfinite(lam), axis=1))
    sols = solve_times_stack(system, T[rows], times[rows], d)
    solved = np.array([sol is not None for sol in sols], dtype=bool)
    if solved.any():
        at = rows[solved]
        new_times = np.array([sol[0] for sol in sols if sol is not None])
        new_lam = np.array([sol[1] for sol in sols if sol is not None])
        near = np.abs(new_times - times[at]).max(axis=1) < 1e-6 * T[at]  # the same orbit: polished
        times[at[near]], lam[at[near]] = new_times[near], new_lam[near]
    rows = rows[np.all(np.isfinite(times[rows]), axis=1) & np.all(np.isfinite(lam[rows]), axis=1)]
    for i, orbit in zip(rows, make_orbits(system, T[rows], times[rows], lam[rows])):  # certified all together
        out[i] = orbit
    return out


def _arcs(problem: KippCurve, zs, orbits, refine: bool) -> list[tuple]:
    """``(start, stop, T_lo, T_hi, refined_lo, refined_hi)`` of every maximal admissible run of ``orbits``."""
    return admissible_arcs(orbits, lambda i, out: _bisect_end(problem, zs[i], zs[out], orbits[out], ARC_RTOL)
                           if refine else None)
