"""Which later starts a followed k-ipp family passes: the start coverage of the k-ipp search.

A start orbit (an orbit found at a scan period) needs no family of its own when the family of an earlier start
passes it.  Each crossing of a family's polyline with a scan period is solved once at that period and the starts
of that period matched to the solution by their impact times (:func:`starts_passed`); :func:`_resolve` settles
the starts in order as their families finish.  (Moved out of :mod:`~bladecase.nsm.modes`, which re-exports it.)
"""

from __future__ import annotations

import numpy as np

from .families import FamilyTracer, KippCurve
from .kipp import canonical_rotation
from .modal import ModalKernel, solve_times, solve_times_stack
from .orbits import REPEAT_RTOL, PeriodicOrbit

__all__ = ["PASS_GATE", "passes", "phase_distance", "phase_distances", "starts_passed"]

#: A start orbit is only re-solved from a crossing segment of a followed curve
#: when the interpolated impact times lie within ``PASS_GATE·T`` of its own
#: (under every re-anchoring); farther crossings are other orbits of that period.
PASS_GATE = 0.05


class _StartIndex:
    """The start orbits of each scan period sorted by their first impact time, to find those near given
    impact times without looking at the others."""

    def __init__(self, starts: list[tuple[float, PeriodicOrbit]]):
        groups: dict[float, list[int]] = {}
        for n, (T, _) in enumerate(starts):
            groups.setdefault(float(T), []).append(n)
        self.periods = np.array(list(groups), dtype=float)
        self.groups = []
        for members in groups.values():
            refs = np.array([starts[m][1].impact_times for m in members])
            order = np.argsort(refs[:, 0], kind="stable")
            self.groups.append((np.array(members)[order], refs[order]))

    def near(self, g: int, guess: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
        """The starts of period ``g`` (indices and impact times) within ``PASS_GATE·T`` of the impact times
        ``guess`` under some re-anchoring (:func:`phase_distances`)."""
        return self.near_many(g, guess[None, :], T)[0]

    def near_many(self, g: int, guesses: np.ndarray, T: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """:meth:`near` of each row of ``guesses`` ``(C, k)``, all at once (the same arithmetic)."""
        members, refs = self.groups[g]
        C, k = guesses.shape
        shifted = np.mod(guesses[:, None, :] - guesses[:, :, None], T)  # (C, r, k): re-anchored at impact r
        shifted[shifted == 0] = T
        shifted.sort(axis=2)
        first = shifted[:, :, 0]  # each re-anchoring's first impact: within the gate of the start's
        pad = PASS_GATE * T * (1 + 1e-9)
        lo = np.searchsorted(refs[:, 0], first - pad, side="left").ravel()
        hi = np.searchsorted(refs[:, 0], first + pad, side="right").ravel()
        width = np.maximum(hi - lo, 0)
        owner = np.repeat(np.repeat(np.arange(C), k), width)  # (crossing, candidate) pairs, every range
        cand = np.repeat(lo, width) + np.arange(width.sum()) - np.repeat(np.cumsum(width) - width, width)
        key = np.unique(owner * len(refs) + cand)
        owner, cand = key // len(refs), key % len(refs)
        if cand.size:
            dist = np.abs(shifted[owner] - np.sort(refs[cand], axis=1)[:, None, :]).max(axis=2).min(axis=1)
            keep = dist <= PASS_GATE * T
            owner, cand = owner[keep], cand[keep]
        cut = np.searchsorted(owner, np.arange(C + 1))
        return [(members[cand[a:b]], refs[cand[a:b]]) for a, b in zip(cut[:-1], cut[1:])]


def _passed(problem: KippCurve, zs, index: _StartIndex, wanted: np.ndarray) -> list[int]:
    """The ``wanted`` starts (a mask) that the polyline ``zs`` passes.

    Each crossing of the polyline with a start period is solved once at that period (Newton from the
    interpolated impact times) and the starts of that period are matched to the solution by their impact
    times, looked up in ``index``: the cost is one fixed-``T`` solve per crossing, whatever the number of
    starts.  A crossing is only solved when some start lies within ``PASS_GATE·T`` of its interpolated impacts
    (under every re-anchoring); a start is passed when the solution, canonically rotated, has its impact
    times to ``1e3·REPEAT_RTOL·T``.
    """
    crossings = _crossings(problem, zs, index, wanted)
    return _matched(crossings, _solve_crossings(problem, crossings), wanted)


def _crossings(problem: KippCurve, zs, index: _StartIndex, wanted: np.ndarray) -> list[tuple]:
    """The crossings of the polyline ``zs`` with the start periods that have a ``wanted`` start near them (see
    :func:`_passed`): ``(period, interpolated impact times, those starts, their impact times)``."""
    if len(zs) < 2:
        return []
    times = np.array(zs, dtype=float) * problem.T0  # each point's impact times (KippCurve.times)
    Ts = times[:, -1]
    lo, hi = np.minimum(Ts[:-1], Ts[1:]), np.maximum(Ts[:-1], Ts[1:])
    crossings = []
    for g in np.flatnonzero((index.periods >= Ts.min()) & (index.periods <= Ts.max())):
        T_s = float(index.periods[g])
        seg = np.flatnonzero((lo <= T_s) & (T_s <= hi) & (hi > lo))
        if seg.size == 0:
            continue
        a = ((T_s - Ts[seg]) / (Ts[seg + 1] - Ts[seg]))[:, None]
        guesses = ((1 - a) * times[seg] / Ts[seg, None] + a * times[seg + 1] / Ts[seg + 1, None]) * T_s
        for guess, (members, refs) in zip(guesses, index.near_many(g, guesses, T_s)):
            open_ = wanted[members]
            if open_.any():  # else no start is left near the interpolated impacts: no need to solve
                crossings.append((T_s, guess, members[open_], refs[open_]))
    return crossings


def _solve_crossings(problem: KippCurve, crossings: list[tuple]) -> list:
    """The fixed-period solutions from the crossings (``None`` where none converges): for ``k = 2`` all of them
    at once (:func:`~bladecase.nsm.newton.modal.solve_times_stack`: the scalar equation ``s(t₁) = 0``), else one
    :func:`~bladecase.nsm.newton.modal.solve_times` each."""
    if problem.k == 2 and crossings:
        return solve_times_stack(problem.system, np.array([c[0] for c in crossings]),
                                 np.array([c[1] for c in crossings]), problem.d)
    return [solve_times(ModalKernel.of(problem.system, T_s), guess, problem.d) for T_s, guess, _, _ in crossings]


def _matched(crossings: list[tuple], sols: list, wanted: np.ndarray) -> list[int]:
    """The ``wanted`` starts of the crossings that their solutions ``sols`` are (see :func:`_passed`)."""
    passed: set[int] = set()
    for (T_s, _, members, refs), sol in zip(crossings, sols):
        keep = wanted[members]
        if sol is not None and keep.any():
            members, refs = members[keep], refs[keep]
            passed.update(members[_distances(sol, refs, T_s) <= 1e3 * REPEAT_RTOL * T_s].tolist())
    return sorted(passed)


def _distances(sol: tuple[np.ndarray, np.ndarray], refs: np.ndarray, T: float) -> np.ndarray:
    """Largest impact-time difference between the solution (canonically rotated) and each row of ``refs``."""
    times, _ = canonical_rotation(sol[0], sol[1], T)
    return np.abs(refs - times[None, :]).max(axis=1)


def phase_distance(times: np.ndarray, reference: np.ndarray, T: float) -> float:
    """``min`` over re-anchorings of ``times`` (shift by each ``t_r``) of the largest
    distance to ``reference`` (both sets of ``k`` impact times in ``(0, T]``).

    >>> phase_distance(np.array([3.0, 10.0]), np.array([7.0, 10.0]), 10.0)    # the same orbit, re-anchored
    0.0
    """
    return float(phase_distances(times, np.asarray(reference)[None, :], T)[0])


def phase_distances(times: np.ndarray, references: np.ndarray, T: float) -> np.ndarray:
    """:func:`phase_distance` of ``times`` to each row of ``references`` (shape ``(c, k)``), vectorised."""
    shifted = np.mod(times[None, :] - times[:, None], T)  # row r: re-anchored at impact r
    shifted[shifted == 0] = T
    shifted.sort(axis=1)
    refs = np.sort(references, axis=1)
    return np.abs(shifted[None, :, :] - refs[:, None, :]).max(axis=2).min(axis=1)


def passes(problem: KippCurve, zs, start: tuple[float, PeriodicOrbit]) -> bool:
    """Does the polyline ``zs`` cross the start orbit (same period, same impacts)?"""
    return bool(starts_passed(problem, zs, [start]))


def starts_passed(problem: KippCurve, zs, starts: list[tuple[float, PeriodicOrbit]]) -> list[int]:
    """Indices of the ``starts`` (``(T, orbit)`` pairs) that the polyline ``zs`` crosses (same period, same
    impacts): each crossing of a start period solved once, the starts matched by lookup (see :func:`_passed`).
    """
    return _passed(problem, zs, _StartIndex(starts), np.ones(len(starts), dtype=bool)) if starts else []


def _resolve(tracer: FamilyTracer, index: _StartIndex, covered: np.ndarray, kept: np.ndarray, running: set[int],
             same: list[tuple[int, int]], todo: list, resolved: int):
    """Resolve, in order, the starts from ``resolved`` on whose fate is known (covered by an earlier family, or
    traced to the end), yielding each: a kept start's family marks the later starts it passes (``covered``),
    the earlier kept ones it passes (``same``), and joins ``todo``; a covered start's trace is dropped."""
    while resolved < covered.size and (covered[resolved] or (resolved in running and tracer.done(resolved))):
        n = resolved
        resolved += 1
        running.discard(n)
        if covered[n]:
            if n in tracer.members:
                tracer.cancel(n)
            yield n
            continue
        problem, zs = tracer.result(n)
        wanted = kept.copy()  # the earlier families' starts (the same branch?) and the later starts left
        wanted[n + 1:] = ~covered[n + 1:]
        passed = np.array(_passed(problem, zs, index, wanted), dtype=int)
        covered[passed[passed > n]] = True
        same.extend((int(m), n) for m in passed[passed < n])
        kept[n] = True
        todo.append((n, (problem, zs)))
        yield n
