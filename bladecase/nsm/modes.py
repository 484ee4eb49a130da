"""Finding the nonsmooth modes of a system: :func:`nonsmooth_mode`, for either contact model.

Newton contact: every k-ipp family started from the orbits found at ``scan`` periods
(:func:`~bladecase.nsm.newton.kipp.orbits_kipp`) and followed by continuation (:mod:`~bladecase.nsm.newton.families`);
``k = 1`` is a scan (:func:`~bladecase.nsm.newton.scan.backbone`). Massless contact: the branches grown from the
open-phase modes at grazing (:mod:`~bladecase.nsm.massless.branches`). All are :class:`~bladecase.nsm.Branch` es.

The k-ipp search, in this module: the families of many starts traced together in start order, a start skipped
when an earlier family passes it — each crossing of a family with a scan period solved once and the starts
matched by lookup (:func:`starts_passed`, :mod:`~bladecase.nsm.newton.coverage`) — and, by geometry
(:func:`on_curve`), each stretch of a branch listed once (:func:`distinct_runs`; a family lying on another is
dropped).  The starts themselves are not certified (only the families' orbits are).
"""

from __future__ import annotations

import numpy as np

from ..progress import progress_bar, progress_counter
from .arcs import check_period_range
from .branches import Arc, Branch
from .massless.model import MasslessSystem
from .newton.coverage import (  # noqa: F401 (PASS_GATE, passes, phase_distance(s), starts_passed: lived here)
    PASS_GATE,
    _passed,
    _resolve,
    _StartIndex,
    passes,
    phase_distance,
    phase_distances,
    starts_passed,
)
from .newton.families import FamilyTracer, complete_families
from .newton.kipp import canonical_rotation, check_resolution, check_search_k, orbits_kipp
from .newton.modal import solve_times_stack
from .newton.orbits import REPEAT_RTOL, PeriodicOrbit
from .system import LinearSystem

__all__ = ["MASSLESS_MIN_POINTS", "nonsmooth_mode"]

#: Least point budget of a massless branch: its steps are short where the contact time grows fast.
MASSLESS_MIN_POINTS = 4000

#: Families traced at once (their continuation steps are vectorised together).
TRACE_WINDOW = 256

#: Two orbits at one period are the same when their canonically rotated impact times agree to ``SAME_RTOL·T``.
SAME_RTOL = REPEAT_RTOL

#: An orbit is only re-solved on a curve segment whose interpolated impact times lie within ``SAME_GATE·T``
#: of its own (:func:`on_curve`).
SAME_GATE = 1e-3

#: Up to ``FOLD_GAP`` orbits between two repeated stretches of a family count as repeated (:func:`distinct_runs`).
FOLD_GAP = 3


def nonsmooth_mode(
    system: LinearSystem,
    k: int,
    T_range: tuple[float, float],
    scan: int = 24,
    step: float = 0.01,
    max_points: int = 400,
    refine: bool = True,
    progress: bool = False,
    resolution: int | None = None,
) -> list[Branch]:
    """Follow every k-ipp family (nonsmooth mode) found in ``T_range``.

    Parameters
    ----------
    system : LinearSystem or MasslessSystem
        A Newton-contact system, or a massless-contact one (:class:`~bladecase.nsm.MasslessSystem`, from
        :func:`~bladecase.nsm.bar` or a massless reduced model): then ``k = 1`` (one contact phase per
        period) and each branch grows from an open-phase linear mode at grazing
        (:mod:`~bladecase.nsm.massless.branches`).
    k : int
        Impacts (contact phases) per period (>= 1).
    T_range : (T_min, T_max)
        Periods of interest; the curves are followed until they leave it.
    scan : int
        Number of periods (evenly spaced in ``T_range``, resonant ones
        skipped) where :func:`orbits_kipp` looks for starting orbits (not
        certified: they are only starting points; the families' orbits are).
        Orbits that are repetitions of shorter-period orbits (``repeats >
        1``) are not followed: they are not new modes.
    step : float
        Initial arclength step in scaled unknowns (times / ``T``); it adapts
        between ``step/1000`` and ``2·step``.
    max_points : int
        Cap on points per direction of each family.
    refine : bool
        Refine the ends of the admissible arcs by bisection along the curve
        (relative precision ``ARC_RTOL`` in ``T``).
    progress : bool
        Progress bar over the starting periods.
    resolution : int or None
        Grid points per impact time of the k >= 3 multistart search at each
        starting period (:func:`orbits_kipp`); ``None`` for its default.

    Returns
    -------
    list of Branch
        Each family's orbits in curve order (all within ``T_range``), certified,
        with admissible arcs.  A family crossing a later scan period is not
        started again there.  Each stretch of a branch is listed once: a
        family whose curve runs over a stretch a second time is cut there
        (what it goes on to beyond is a family of its own unless it continues
        an end), and a family whose orbits all lie on another one is dropped.
        k = 1: the one 1-ipp branch (a scan of ``max(scan, 200)`` periods,
        resonant points left out).

    Examples
    --------
    The paper's 2-dof chain: the 2-ipp mode ending at ``5T₂ = 13.7293`` (seed Fig. 2).

    >>> from bladecase.nsm import chain
    >>> families = nonsmooth_mode(chain(2, k=1.0, m=0.5, gap=1.0), 2, (13.2, 13.75), scan=2)
    >>> len(families), [(round(a.T_lo, 3), round(a.T_hi, 4), a.refined_hi) for f in families for a in f.arcs]
    (4, [(13.329, 13.7293, True)])
    """
    k = check_search_k(k)
    T_lo, T_hi = check_period_range("T_range", T_range)
    scan = _integer("scan", scan, 1)
    max_points = _integer("max_points", max_points, 2)
    if isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, float, np.integer, np.floating)) or not (
            0 < step <= 1):
        raise ValueError(f"step must be a number with 0 < step <= 1 (scaled arclength: impact times / T), got {step!r}")
    for name, flag in (("refine", refine), ("progress", progress)):
        if not isinstance(flag, (bool, np.bool_)):
            raise ValueError(f"{name} must be True or False, got {flag!r}")
    resolution = check_resolution(resolution, k)
    if not isinstance(system, (LinearSystem, MasslessSystem)):
        raise ValueError(f"nonsmooth_mode: system must be a LinearSystem (Newton's contact) or a MasslessSystem, got "
                         f"{type(system).__name__}")
    if getattr(system, "contact_model", "newton") == "massless":
        if k != 1:
            raise ValueError(f"the massless contact model has modes with one contact phase per period (k = 1) "
                             f"so far; got k = {k}")
        from .massless.branches import massless_modes

        return massless_modes(system, (T_lo, T_hi), max_points=max(max_points, MASSLESS_MIN_POINTS), refine=refine)
    if k == 1:
        from .newton.scan import backbone

        return [backbone(system, np.linspace(T_lo, T_hi, max(scan, 200))).compact()]
    starts = []
    for T in progress_bar(np.linspace(T_lo, T_hi, scan), f"{k}-ipp starts", enabled=progress, unit="T"):
        try:
            sols = orbits_kipp(system, T, k, resolution=resolution, certify=False)  # starting points only
        except ValueError:
            continue
        starts.extend((T, o) for o in sols if o.repeats == 1)
    return _follow_starts(system, k, starts, (T_lo, T_hi), step, max_points, refine, progress)


def _integer(name: str, value, low: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def _follow_starts(system: LinearSystem, k: int, starts: list[tuple[float, PeriodicOrbit]], T_range, step: float,
                   max_points: int, refine: bool, progress: bool) -> list[Branch]:
    """The family of every start not passed by the family of an earlier start, in the order of the starts,
    each branch listed once.

    Up to ``TRACE_WINDOW`` families are traced at once (:class:`~bladecase.nsm.newton.families.FamilyTracer`); they
    are taken in the order of their starts: the first unresolved start whose family is traced is kept and
    marks the later starts its curve passes (:func:`starts_passed`), whose traces, if begun, are dropped: the
    same families as following the starts one by one (:func:`~bladecase.nsm.newton.coverage._resolve`).  Then, by
    geometry: a stretch a family's curve traces a second time is left out (the family is cut there,
    :func:`distinct_runs`), and a family whose orbits all lie on another family (one passing its start) is
    dropped (:func:`on_curve`).
    """
    tracer = FamilyTracer(system, k, T_range, step, max_points)
    index = _StartIndex(starts)
    covered = np.zeros(len(starts), dtype=bool)
    kept = np.zeros(len(starts), dtype=bool)
    running: set[int] = set()
    families: dict[int, list] = {}  # start → its family's stretches (FollowedFamily)
    same: list[tuple[int, int]] = []  # (earlier start, later start) whose families share the earlier start
    todo: list = []
    launched = resolved = 0
    with progress_counter(len(starts), f"{k}-ipp families", enabled=progress, unit="start") as bar:
        while resolved < len(starts):
            new = []
            busy = tracer.run.running.size // 2  # families still being traced (two directions each)
            while launched < len(starts) and busy + len(new) < TRACE_WINDOW and launched - resolved < 8 * TRACE_WINDOW:
                if not covered[launched]:
                    new.append(launched)
                launched += 1
            tracer.add(new, [starts[n][1] for n in new])
            running.update(new)
            for n in _resolve(tracer, index, covered, kept, running, same, todo, resolved):
                resolved = n + 1
                bar.update()
            if len(todo) >= TRACE_WINDOW or (todo and resolved == len(starts)):
                done = complete_families([t for _, t in todo], T_range, refine, distinct_runs)
                families.update((n, pieces) for (n, _), pieces in zip(todo, done))
                todo = []
                bar.set_postfix_str(f"{len(families)} families")
            if resolved < len(starts):
                tracer.step()
    _contained(families, same)
    return [Branch(system=system, k=k, orbits=f.orbits, arcs=[Arc(*a) for a in f.arcs])
            for n in sorted(families) for f in families[n] if f.orbits]


def _contained(families: dict[int, list], pairs: list[tuple[int, int]]) -> None:
    """Drop from ``families`` (start → stretches) each stretch of one of two families through a common orbit
    (``pairs``) whose orbits all lie on the other family: of two identical stretches, the earlier family's."""
    for m, n in pairs:
        for a, b in ((m, n), (n, m)):
            if a in families and b in families:
                families[a] = [f for f in families[a] if not (f.orbits and _all_on(families[b], f.orbits))]


def _all_on(pieces: list, orbits: list[PeriodicOrbit]) -> bool:
    """Do all ``orbits`` lie on the stretches ``pieces`` of a family (:func:`on_curve`)?"""
    curves = [f.orbits for f in pieces if len(f.orbits) >= 2]
    T = [o.T for o in orbits]
    if not curves or min(T) < min(o.T for c in curves for o in c) or max(T) > max(o.T for c in curves for o in c):
        return False  # outside the family's period range
    close = np.zeros(len(orbits), dtype=bool)
    for c in curves:
        close |= _near(c, orbits)[0].any(axis=1)
    if not close.all():
        return False  # some orbit is not even close to the family: no need to solve
    n = len(orbits)
    for i in [0, n - 1, *range(1, n - 1)]:  # the ends first: where a stretch would stick out
        if not any(_matches(c, [orbits[i]])[0] >= 0 for c in curves):
            return False
    return True


def distinct_runs(orbits: list[PeriodicOrbit]) -> list[list[int]]:
    """The branches in a family's ``orbits`` (in curve order), each as index runs in curve order, with each
    stretch of the curve listed once.

    A run of at least two orbits lying on segments of the curve listed before them (two points back or more,
    :func:`on_curve`) repeats a stretch already listed, and is left out (so are up to ``FOLD_GAP`` orbits
    between two such runs) — unless one of them is admissible on a segment between two orbits that are not
    (the arc it belongs to is not seen on the first pass).  Where a repetition ends at an end of a run
    already kept and the curve goes on, what follows continues that run beyond its end and is joined to it;
    elsewhere it starts a new run.

    >>> from bladecase.nsm import chain, orbits_kipp
    >>> o = orbits_kipp(chain(2, k=1.0, m=0.5, gap=1.0), 13.5, 2)[1]
    >>> distinct_runs([o])
    [[0]]
    """
    n = len(orbits)
    if n < 4:
        return [list(range(n))] if n else []
    i, j = np.arange(n)[:, None], np.arange(n - 1)[None, :]
    where = _matches(orbits, orbits, allowed=j + 1 <= i - 2)
    again = where >= 0
    pair = again[:-1] & again[1:]
    again &= np.concatenate([pair, [False]]) | np.concatenate([[False], pair])  # runs of two or more
    adm = np.array([o.admissible for o in orbits])
    seen = adm[np.maximum(where, 0)] | adm[np.minimum(np.maximum(where, 0) + 1, n - 1)]
    for a, b in zip(*_true_runs(again)):  # an admissible orbit between two that are not: its arc is only here
        if (adm[a:b] & ~seen[a:b]).any():
            again[a:b] = False
    marked = np.flatnonzero(again)
    for a, b in zip(marked[:-1], marked[1:]):
        if 1 < b - a <= FOLD_GAP + 1:  # a short gap between repetitions: the tip of a fold, beyond the
            again[a + 1: b] = True  # periods the earlier segments bracket
    runs: list[list[int]] = []
    for a, b in zip(*_true_runs(~again)):
        q = a - 1  # the segment where the repetition before this run left the curve already listed
        while q >= 0 and again[q] and where[q] < 0:
            q -= 1
        runs.append(_joined(runs, list(range(a, b)), int(where[q]) if q >= 0 and again[q] else None))
    return [r for r in runs if r]


def _true_runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and (exclusive) ends of the runs of ``True`` in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _joined(runs: list[list[int]], block: list[int], exit_: int | None) -> list[int]:
    """Add ``block`` (consecutive orbits) to ``runs``: after the end or before the start of the run whose end
    segment the repetition before it left from (``exit_``: segment ``(j, j+1)``), else as a run of its own;
    returns what to append to ``runs`` (empty when joined)."""
    if exit_ is not None:
        for r in runs:
            if len(r) >= 2 and exit_ in (r[0], r[1], r[0] - 1) and r[1] == r[0] + 1:
                r[:0] = block[::-1]  # went back along r and on past its start
                return []
            if len(r) >= 2 and exit_ in (r[-2], r[-1] - 1, r[-1]) and r[-1] == r[-2] + 1:
                r.extend(block)  # went along r and on past its end
                return []
    return block


def _canonical(orbits: list[PeriodicOrbit]) -> np.ndarray:
    """``(n, k)``: each orbit's period, then its canonically rotated impact times ``t₁ … t_{k-1}`` over ``T``."""
    out = np.empty((len(orbits), orbits[0].k))
    out[:, 0] = [o.T for o in orbits]
    if orbits[0].k == 2:  # the rotations of (t₁, T) are (t₁, T) and (T - t₁, T): the smaller first time
        t1 = np.array([o.impact_times[0] for o in orbits]) / out[:, 0]
        out[:, 1] = np.minimum(t1, 1 - t1)
        return out
    for i, o in enumerate(orbits):
        out[i, 1:] = canonical_rotation(o.impact_times, o.impulses, o.T)[0][:-1] / o.T
    return out


def on_curve(curve: list[PeriodicOrbit], orbits: list[PeriodicOrbit], allowed: np.ndarray | None = None) -> np.ndarray:
    """Which of ``orbits`` are orbits of the branch through ``curve`` (consecutive orbits of one family).

    An orbit is one when a segment of ``curve`` (``allowed[i, j]``: may orbit ``i`` be matched on segment
    ``j``) brackets its period with interpolated (canonically rotated) impact times near its own (within
    ``SAME_GATE·T`` plus the segment's length) and, re-solved at its period from there
    (:func:`~bladecase.nsm.newton.modal.solve_times`), gives its impact times to ``SAME_RTOL·T``: the same orbit,
    whatever the points the two families were sampled at.

    >>> from bladecase.nsm import chain, nonsmooth_mode
    >>> fam = nonsmooth_mode(chain(2, k=1.0, m=0.5, gap=1.0), 2, (13.2, 13.75), scan=2)[0]
    >>> on_curve(fam.orbits[::2], fam.orbits[1:-1:2]).all()      # every other point lies on the curve of the rest
    np.True_
    """
    return _matches(curve, orbits, allowed) >= 0


def _near(curve: list[PeriodicOrbit], orbits: list[PeriodicOrbit], allowed: np.ndarray | None = None):
    """The segments of ``curve`` worth re-solving each orbit on (:func:`on_curve`): ``(near, guess, dist, Q)``
    with ``near[i, j]`` true when segment ``j`` brackets orbit ``i``'s period with interpolated canonical
    times ``guess[i, j]`` at ``dist[i, j]`` from its own ``Q[i, 1:]`` within the gate."""
    P, Q = _canonical(curve), _canonical(orbits)
    Ta, Tb, T = P[:-1, 0], P[1:, 0], Q[:, :1]
    with np.errstate(invalid="ignore", divide="ignore"):
        a = (T - Ta) / (Tb - Ta)
    inside = (a >= 0) & (a <= 1) & (Ta != Tb)
    if allowed is not None:
        inside &= allowed
    guess = P[:-1, 1:] + a[:, :, None] * (P[1:, 1:] - P[:-1, 1:])
    dist = np.where(inside, np.abs(guess - Q[:, None, 1:]).max(axis=2), np.inf)
    step = np.abs(P[1:] - P[:-1])
    gate = SAME_GATE + np.maximum(step[:, 0] / P[1:, 0], step[:, 1:].max(axis=1))  # a chord strays from the curve
    return dist <= gate[None, :], guess, dist, Q  # by a fraction of its length


def _matches(curve: list[PeriodicOrbit], orbits: list[PeriodicOrbit], allowed: np.ndarray | None = None
             ) -> np.ndarray:
    """:func:`on_curve`, as the segment of ``curve`` each orbit lies on (``-1``: none).

    Each orbit tries its candidate segments nearest first and stops at the first that gives it back; the
    candidates of all orbits are solved round by round (the nearest of every orbit, then the next of those
    not yet matched, ...), each round's fixed-period solves together (:func:`_solve_candidates`)."""
    hit = np.full(len(orbits), -1)
    if len(curve) < 2 or not orbits:
        return hit
    near, guess, dist, Q = _near(curve, orbits, allowed)
    order = np.argsort(np.where(near, dist, np.inf), axis=1, kind="stable")  # each orbit's candidates, nearest first
    tries = near.sum(axis=1)
    system = curve[0].system
    for r in range(int(tries.max(initial=0))):
        rows = np.flatnonzero((tries > r) & (hit < 0))
        if rows.size == 0:
            break
        j = order[rows, r]
        T = Q[rows, 0]
        times0 = np.column_stack([guess[rows, j] * T[:, None], T])
        for i, jj, sol in zip(rows, j, solve_times_stack(system, T, times0, system.gap)):
            if sol is not None and np.abs(canonical_rotation(sol[0], sol[1], Q[i, 0])[0][:-1] / Q[i, 0]
                                          - Q[i, 1:]).max() <= SAME_RTOL:
                hit[i] = jj
    return hit
