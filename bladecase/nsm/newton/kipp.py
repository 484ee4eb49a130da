"""Every periodic orbit with k impacts per period at one period ``T`` (theory §4).

The orbits solve ``Π(t)Λ = 0``, ``Σ(t)Λ = d·1`` for ``0 < t₁ < … < t_k = T`` (:mod:`bladecase.nsm.newton.modal`).
k = 2 reduces to the scalar ``s(t₁) = 0`` (the paper's Eq. 15), whose sign changes are all found with certified
root exclusion; k >= 3 is a multistart (Newton from every cell of a grid of ordered impact times,
Levenberg–Marquardt from the most promising cells and from repeated lower-order patterns).
"""

from __future__ import annotations

import math
from itertools import combinations
from math import comb

import numpy as np

from ..continuation import lstsq_stack
from ..signals import TrigSum, all_roots
from ..system import LinearSystem
from .modal import ModalKernel, _newton_stack, check_period, impact_kernels, impulses_for, solve_times
from .orbits import REPEAT_RTOL, PeriodicOrbit, check_newton_system, make_orbit, orbit_1ipp

__all__ = ["MAX_GRID_CELLS", "MAX_K", "canonical_rotation", "check_k", "check_newton_system",
           "check_resolution", "check_search_k", "orbits_kipp"]

#: Largest ``k`` the k-ipp search takes (its start grid grows combinatorially with ``k``; as the CLI's ``--ipp``
#: and the study's ``[search] ipp``).
MAX_K = 8

#: Most start cells of the k >= 3 grid at one period (``C(resolution - 1, k - 1)``; as the study's
#: ``LIMITS["grid_cells"]``): beyond, one period's search would not end or not fit in memory.
MAX_GRID_CELLS = 1_000_000

#: Largest ``resolution`` (grid points per impact time) of the k >= 3 start search.
MAX_RESOLUTION = 1000


def check_k(k) -> int:
    """``k`` as an int; raise ``ValueError`` unless it is an integer >= 1 (numpy integers accepted, not bools)."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"k (impacts per period) must be an integer >= 1, got {k!r}")
    return int(k)


def check_search_k(k, name: str = "k") -> int:
    """``k`` of a search (:func:`orbits_kipp`, :func:`~bladecase.nsm.nonsmooth_mode`): an integer in
    ``1..MAX_K`` (the k-ipp start search grows combinatorially with ``k``).

    >>> check_search_k(100)
    Traceback (most recent call last):
    ...
    ValueError: k (impacts per period) must be an integer with 1 <= k <= 8, got 100
    """
    if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)) or not 1 <= k <= MAX_K:
        raise ValueError(f"{name} (impacts per period) must be an integer with 1 <= {name} <= {MAX_K}, got {k!r}")
    return int(k)


def check_resolution(resolution, k: int) -> int | None:
    """``resolution`` of the k >= 3 start search: ``None`` (the default) or an integer with
    ``k <= resolution <= MAX_RESOLUTION`` whose grid has at most :data:`MAX_GRID_CELLS` cells."""
    if resolution is None:
        return None
    if isinstance(resolution, (bool, np.bool_)) or not isinstance(resolution, (int, np.integer)) or not (
            1 <= resolution <= MAX_RESOLUTION):
        raise ValueError(f"resolution (grid points per impact time) must be None or an integer with 1 <= resolution "
                         f"<= {MAX_RESOLUTION}, got {resolution!r}")
    if k >= 3:
        if resolution < k:
            raise ValueError(f"resolution must be >= k = {k} (a grid of resolution - 1 times holds k - 1 ordered "
                             f"impact times), got {resolution!r}")
        cells = comb(int(resolution) - 1, k - 1)
        if cells > MAX_GRID_CELLS:
            fit = _largest_resolution(k)
            raise ValueError(f"resolution {resolution} makes {cells:.3g} start cells for k = {k} at each period (at "
                             f"most {MAX_GRID_CELLS:g}): resolution <= {fit} for k = {k}")
    return int(resolution)


def _largest_resolution(k: int) -> int:
    """The largest resolution whose k-ipp start grid has at most :data:`MAX_GRID_CELLS` cells."""
    r = k
    while r < MAX_RESOLUTION and comb(r, k - 1) <= MAX_GRID_CELLS:
        r += 1
    return r


def orbits_kipp(system: LinearSystem, T: float, k: int, resolution: int | None = None,
                certify: bool = True) -> list[PeriodicOrbit]:
    """Every periodic orbit of period ``T`` with ``k`` impacts per period.

    Solves ``Π(t)Λ = 0``, ``Σ(t)Λ = d·1`` for ``0 < t₁ < … < t_k = T``
    (theory §4).  k = 1: :func:`orbit_1ipp`.  k = 2: the condition is the
    scalar ``s(t₁) = 0`` (the paper's Eq. 15, ``Pf(Π) = Π₁₂``); all its sign
    changes on ``(0, T)`` are found with certified root exclusion
    (:func:`bladecase.nsm.signals.all_roots`), then ``Λ = Σ⁻¹ d·1``.  k >= 3
    (``Pf(Π) = 0`` and a two-dimensional null space for even k, the null
    vector of ``Π`` for odd k): Newton on ``(t₁…t_{k-1}, Λ)`` started from
    every cell of a grid on the ordered times, ``resolution`` points per time
    (default: 4 per period of the highest contact mode, between 16 and 48,
    and at most what keeps the grid within ``MAX_GRID_CELLS`` cells),
    from the equally spaced and repeated lower-order patterns, and
    Levenberg–Marquardt from the most promising cells; solutions closer than
    ``1e-7 T`` are merged.  For k >= 3 completeness is up to that resolution.
    Solutions that differ only by which impact is placed at ``t = 0`` (a time
    shift) are the same orbit and are returned once
    (:func:`canonical_rotation`).

    Each solution is a :class:`PeriodicOrbit` with certified admissibility
    (``certify=False``: not checked, the orbits marked non-admissible — for
    starting points, the bulk of the cost saved); orbits with a negative
    impulse are never admissible.  Solutions that are an orbit of period
    ``T/j`` counted ``j`` times (e.g. k = 2 with ``t₁ = T/2``, a 1-ipp orbit
    of period ``T/2``) have ``repeats = j``.

    Returns
    -------
    list of PeriodicOrbit, sorted by ``t₁``.

    Raises
    ------
    ValueError
        ``system`` not a :class:`LinearSystem`; ``T`` not a finite period > 0, or resonant; ``k`` not an
        integer in ``1..MAX_K``; ``resolution`` not ``None`` or an integer ``>= k`` whose grid has at most
        :data:`MAX_GRID_CELLS` cells; ``certify`` not a bool.

    Examples
    --------
    >>> from bladecase.nsm import chain
    >>> orbits = orbits_kipp(chain(2, k=1.0, m=0.5, gap=1.0), 13.5, 2)
    >>> [(round(float(o.impact_times[0]), 4), o.repeats, o.admissible) for o in orbits]
    [(3.6382, 1, False), (6.0829, 1, True), (6.75, 2, True)]
    >>> orbits_kipp(chain(2, k=1.0, m=0.5, gap=1.0), 13.5, 100)
    Traceback (most recent call last):
    ...
    ValueError: k (impacts per period) must be an integer with 1 <= k <= 8, got 100
    """
    check_newton_system(system, "orbits_kipp")
    k = check_search_k(k)
    resolution = check_resolution(resolution, k)
    if not isinstance(certify, (bool, np.bool_)):
        raise ValueError(f"certify must be True or False, got {certify!r}")
    if k == 1:
        return [orbit_1ipp(system, T, certify=certify)]
    T = check_period(system, T)
    md = ModalKernel.of(system, T)
    d = system.gap
    solutions: list[tuple[np.ndarray, np.ndarray]] = []
    if k == 2:
        for t1 in _k2_roots(md):
            times = np.array([t1, T])
            lam = impulses_for(md, times, d)
            if lam is not None:
                solutions.append((times, lam))
    else:
        solutions = _multistart(md, k, d, resolution)
    unique: list[tuple[np.ndarray, np.ndarray]] = []
    seen = np.empty((len(solutions), k))  # the impact times kept so far, one row each
    for times, lam in solutions:
        times, lam = canonical_rotation(times, lam, T)
        if not np.any(np.abs(seen[: len(unique)] - times).max(axis=1, initial=0.0) <= REPEAT_RTOL * T):
            seen[len(unique)] = times
            unique.append((times, lam))
    orbits = [make_orbit(system, T, times, lam, md, certify=certify) for times, lam in unique]
    return sorted(orbits, key=lambda o: tuple(o.impact_times))


def canonical_rotation(times: np.ndarray, impulses: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
    """The same orbit re-anchored at the impact that makes ``(t₁, …, t_k)`` smallest
    lexicographically (times closer than ``REPEAT_RTOL·T`` count as equal, so
    that round-off cannot pick different representatives of one orbit).
    Re-anchoring at impact ``r`` (a time shift by ``t_r``) gives the same
    physical orbit; this picks one representative.

    >>> t, lam = canonical_rotation(np.array([6.0, 10.0]), np.array([2.0, 1.0]), 10.0)
    >>> t.tolist(), lam.tolist()         # the same orbit, re-anchored at its first impact
    ([4.0, 10.0], [1.0, 2.0])
    """
    tol = REPEAT_RTOL * T
    if times.size == 2 and impulses.size == 2:
        pair = _canonical_pair(float(times[0]), float(times[1]), tol, T)
        if pair is not None:
            order, shifted = pair
            return np.array(shifted), impulses[list(order)]
    best = None
    for r in range(times.size):
        shifted = np.mod(times - times[r], T)
        shifted[(shifted <= tol) | (shifted >= T - tol)] = T
        order = np.argsort(shifted)
        cand = (shifted[order], impulses[order])
        if best is None:
            best = cand
            continue
        diff = cand[0] - best[0]
        first = np.flatnonzero(np.abs(diff) > tol)
        if first.size and diff[first[0]] < 0:
            best = cand
    best[0][-1] = T
    return best


def _canonical_pair(t1: float, t2: float, tol: float, T: float) -> tuple[tuple[int, int], list[float]] | None:
    """:func:`canonical_rotation` of two impacts in scalar arithmetic (the same operations: ``%`` is ``np.mod``):
    ``(order, shifted times)``, or ``None`` unless the times are finite and ``T > 0`` (the general code decides)."""
    if not (math.isfinite(t1) and math.isfinite(t2) and math.isfinite(T) and T > 0):
        return None
    best = None
    for r in (t1, t2):
        shifted = [(t1 - r) % T, (t2 - r) % T]
        shifted = [T if (x <= tol or x >= T - tol) else x for x in shifted]
        order = (1, 0) if shifted[1] < shifted[0] else (0, 1)  # np.argsort of two: ties keep their order
        cand = [shifted[order[0]], shifted[order[1]]]
        if best is None:
            best = (order, cand)
            continue
        diff = [cand[0] - best[1][0], cand[1] - best[1][1]]
        first = next((x for x in diff if abs(x) > tol), None)
        if first is not None and first < 0:
            best = (order, cand)
    best[1][-1] = T
    return best


def _screening(md: ModalKernel, starts: np.ndarray, k: int) -> np.ndarray:
    """Scale-free residual ``||Π n|| / (||n|| S)`` with ``n = Σ⁻¹1`` at each start (``inf`` if ``Σ`` is singular)."""
    S = float(md.b @ md.b) / 2
    score = np.full(len(starts), np.inf)
    for i, times in enumerate(starts):
        Pi, Sigma = md.matrices(times)
        try:
            n = np.linalg.solve(Sigma, np.ones(k))
        except np.linalg.LinAlgError:
            continue
        score[i] = np.linalg.norm(Pi @ n) / (np.linalg.norm(n) * S)
    return score


def _promising(idx: np.ndarray, score: np.ndarray, k: int) -> list[int]:
    """Grid cells whose score is a (non-strict) local minimum or among the lowest 5 %."""
    pos = {tuple(row): i for i, row in enumerate(idx)}
    finite = np.isfinite(score)
    low = set(np.flatnonzero(finite & (score <= np.quantile(score[finite], 0.05)))) if finite.any() else set()
    out = []
    for i, row in enumerate(idx):
        if not finite[i]:
            continue
        best = i in low
        if not best:
            best = True
            for delta in np.ndindex(*(3,) * (k - 1)):
                j = pos.get(tuple(row + np.array(delta) - 1))
                if j is not None and j != i and score[j] < score[i]:
                    best = False
                    break
        if best:
            out.append(i)
    return out


def _repeated_seeds(md: ModalKernel, k: int, d: float, resolution: int | None) -> list[np.ndarray]:
    """Patterns that always solve or nearly solve: equally spaced impacts, and repetitions of the
    solutions with ``k/j`` impacts at period ``T/j``."""
    T = md.T
    seeds = [T * np.arange(1, k + 1) / k]
    for j in range(2, k):
        if k % j == 0:
            sub = md.at(T / j)
            base = [np.array([T / j])] if k // j == 1 else (
                [t for t, _ in _multistart(sub, k // j, d, resolution)] if k // j >= 3 else
                [np.array([t1, T / j]) for t1 in _k2_roots(sub)])
            for t in base:
                seeds.append(np.concatenate([t + m * T / j for m in range(j)]))
    return seeds


def default_resolution(T: float, omega_max: float) -> int:
    """Grid points per impact time of the k >= 3 start search at period ``T``: 4 per period of the highest
    contact mode, clipped to [16, 48].

    >>> default_resolution(10.0, 2.0), default_resolution(10.0, 5.0), default_resolution(10.0, 20.0)
    (16, 32, 48)
    """
    return int(np.clip(np.ceil(4 * T * omega_max / (2 * np.pi)), 16, 48))


def _multistart(md: ModalKernel, k: int, d: float, resolution: int | None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Solutions for k >= 3: Levenberg–Marquardt from the equally spaced
    pattern, from every repeated lower-order solution (period ``T/j``,
    ``j | k``) and from the grid cells of ordered impact times whose screening
    residual is a local minimum (non-strict) or among the lowest 5 %; Newton
    from every grid cell."""
    T = md.T
    if resolution is None:  # the default, within the cap on the grid's cells
        resolution = min(default_resolution(T, md.omega.max()), _largest_resolution(k))
    grid = T * (np.arange(1, resolution) / resolution)
    idx = np.array(list(combinations(range(grid.size), k - 1)))
    starts = np.column_stack([grid[idx], np.full(len(idx), T)])
    candidates = [starts[i] for i in _promising(idx, _screening(md, starts, k), k)]
    seeds = _repeated_seeds(md, k, d, resolution)
    found: list[tuple[np.ndarray, np.ndarray]] = []

    def keep(sol):
        if sol is not None and not any(np.abs(sol[0] - t).max() <= REPEAT_RTOL * T for t, _ in found):
            found.append(sol)

    # Newton (exact Jacobian, cheap) from every cell: the screening score is
    # a poor guide to Newton's basins; Levenberg–Marquardt (wider basin,
    # costlier) from the seeds and the promising cells.
    for times0 in seeds + candidates:
        keep(solve_times(md, np.asarray(times0, dtype=float), d))
    # every cell's Newton at once (newton_times vectorised), kept in the order of the cells; in chunks of about
    # 2e6 kernel terms (k(k-1)/2 delays × modes per cell) to bound the memory
    chunk = max(256, 2_000_000 // max(1, k * (k - 1) // 2 * md.omega.size))
    for part in np.array_split(starts, -(-len(starts) // chunk)):
        lam0 = lstsq_stack(-impact_kernels(md.omega, md.b, part, which="g")[0], np.full(part.shape, d), rcond=1e-12)
        rows = np.flatnonzero(np.all(np.isfinite(lam0), axis=1))
        times, lam, ok = _newton_stack(md.omega, md.b, np.full(rows.size, T), part[rows], lam0[rows], d)
        for j in np.flatnonzero(ok):
            keep((times[j], lam[j]))
    return found


def _k2_roots(md: ModalKernel) -> np.ndarray:
    """Every ``t₁`` in ``(0, T)`` with ``s(t₁) = 0`` (the k = 2 condition)."""
    T = md.T
    c = md.b**2 / 2
    s_sum = TrigSum(alpha=c, beta=-c * np.cos(md.omega * T / 2) / md.sin_half, omega=md.omega)
    return np.array([t for t in all_roots(s_sum, 0.0, T) if 0 < t < T])
