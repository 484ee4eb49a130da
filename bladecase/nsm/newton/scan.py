"""Backbones: 1-ipp orbits over a scan of periods and their admissible intervals.

:func:`backbone` evaluates the 1-ipp orbit at every period of a scan, keeps
the frequency–energy data, and refines the maximal admissible intervals of
``T`` by bisection on the admissibility predicate.  The result is a
:class:`~bladecase.nsm.branches.Branch` with ``source = "scan"``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...progress import progress_bar
from ..branches import Arc, Backbone, Branch, Interval
from ..system import LinearSystem
from .orbits import PeriodicOrbit, check_newton_system, orbit_1ipp

__all__ = ["BISECTION_RTOL", "Backbone", "Interval", "backbone"]  # Backbone, Interval: former names

#: Relative precision in ``T`` of the refined ends of admissible intervals.
BISECTION_RTOL = 1e-9


def _solver(ipp: int) -> Callable[[LinearSystem, float], PeriodicOrbit]:
    if isinstance(ipp, (bool, np.bool_)) or not isinstance(ipp, (int, np.integer)):
        raise ValueError(f"ipp (impacts per period) must be the integer 1, got {ipp!r}")
    if ipp == 1:
        return orbit_1ipp
    raise ValueError(
        f"backbone scans 1-ipp orbits (ipp = 1), got ipp = {ipp!r}: for k >= 2 impacts per period the "
        "orbits exist only on curves of impact times, use bladecase.nonsmooth_mode(system, k, T_range) "
        "(or orbits_kipp(system, T, k) at one period)"
    )


def _try(solve, system, T) -> PeriodicOrbit | None:
    try:
        return solve(system, T)
    except ValueError:
        return None


def _check(solve, system, T, probe) -> tuple[bool, float | None]:
    """Fast admissibility predicate: ``(admissible, time of a violation or None)``."""
    try:
        o = solve(system, T, polish=False, probe=probe)
    except ValueError:
        return False, probe
    return o.admissible, (None if o.admissible else o.max_violation_time / o.T)


def _bisect(solve, system, T_in: float, T_out: float, probe: float | None) -> float:
    """Boundary of admissibility between an admissible ``T_in`` and a non-admissible ``T_out``.

    Returns the admissible end of a bracket of relative width
    ``BISECTION_RTOL``.  The predicate is the certified admissibility; the
    phase ``probe`` where the non-admissible side violates the constraint is
    checked first, so most rejections are cheap.  (A root-finder on a
    continuous violation measure does not pay here: between two scan points
    of a large model lie thousands of high-mode resonances.)
    """
    tol = BISECTION_RTOL * abs(T_in)
    while abs(T_out - T_in) > tol:
        mid = 0.5 * (T_in + T_out)
        ok, where = _check(solve, system, mid, None if probe is None else probe * mid)
        if ok:
            T_in = mid
        else:
            T_out, probe = mid, where if where is not None else probe
    return T_in


def _first_resonance(omega: np.ndarray, T_a: float, T_b: float, last: bool = False) -> float | None:
    """Smallest (``last``: largest) resonant period ``2πm/ω_j`` in ``(T_a, T_b)``, or ``None``."""
    if last:
        m = np.ceil(omega * T_b / (2 * np.pi)) - 1
        r = 2 * np.pi * m / omega
        r = r[(m >= 1) & (r > T_a) & (r < T_b)]
        return float(r.max()) if r.size else None
    m = np.floor(omega * T_a / (2 * np.pi)) + 1
    r = 2 * np.pi * m / omega
    r = r[(r > T_a) & (r < T_b)]
    return float(r.min()) if r.size else None


def _phase(orbit: PeriodicOrbit | None) -> float | None:
    return None if orbit is None else orbit.max_violation_time / orbit.T


def backbone(
    system: LinearSystem,
    periods: Sequence[float] | np.ndarray,
    ipp: int = 1,
    progress: bool = False,
) -> Branch:
    """Orbits with ``ipp`` impacts per period at each of ``periods``.

    Parameters
    ----------
    system : LinearSystem
    periods : array_like
        Periods to scan (> 0); sorted internally.  Resonant periods get no
        orbit (``None``) rather than an error.
    ipp : int
        Impacts per period.
    progress : bool
        Show a progress bar on standard error (:func:`bladecase.progress.progress_bar`).

    Returns
    -------
    Branch
        ``source = "scan"``: one orbit per period (``None`` where resonant),
        frequency–energy data and the maximal admissible intervals of ``T``
        (:attr:`~Branch.arcs`, also :attr:`~Branch.intervals`), whose ends are
        refined by bisection to ``BISECTION_RTOL``.
        An interval never contains a resonant period ``2πm/ω_j`` of a mode
        that sees the contact (the impulse changes sign there): two
        admissible scan points with a resonance between them give two
        intervals, whose ends are refined towards the resonance (an end next
        to a resonance converges to the excluded resonant period).
        Admissible stretches between two resonances that fall between the
        same two scan points are not found: scan finer.

    Examples
    --------
    >>> from bladecase.nsm import chain
    >>> bb = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(1.0, 12.0, 111))
    >>> [(round(iv.T_lo, 6), round(iv.T_hi, 6)) for iv in bb.intervals]
    [(2.504874, 2.745853), (3.745895, 5.491705), (5.650149, 7.188736)]
    """
    check_newton_system(system, "backbone")
    if not isinstance(progress, (bool, np.bool_)):
        raise ValueError(f"progress must be True or False, got {progress!r}")
    solve = _solver(ipp)
    try:
        if periods is None or isinstance(periods, (str, bytes)):
            raise TypeError
        P = np.asarray(periods, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"periods must be a sequence of periods (numbers > 0), got {periods!r}") from None
    if P.ndim > 1:
        raise ValueError(f"periods must be a 1-D sequence of periods, got an array of shape {P.shape}")
    P = P.reshape(-1)
    if P.size == 0:
        raise ValueError("periods is empty: give at least one period")
    if not np.all(np.isfinite(P)) or np.any(P <= 0):
        raise ValueError(f"periods must be finite and > 0, got e.g. {P[~(np.isfinite(P) & (P > 0))][0]!r}")
    P = np.unique(P)
    orbits = [_try(solve, system, T) for T in progress_bar(P, f"{ipp}-ipp orbits", enabled=progress, unit="T")]
    adm = np.array([o is not None and o.admissible for o in orbits])
    omega = system.spectrum.contact_modes[0]
    # Nearest resonances 2πm/ω_j strictly inside each gap between scan points:
    # an admissible interval never contains one (Λ = -d/g(0) changes sign there).
    first_res = [_first_resonance(omega, P[g], P[g + 1]) for g in range(P.size - 1)]
    last_res = [_first_resonance(omega, P[g], P[g + 1], last=True) for g in range(P.size - 1)]
    intervals = []
    i = 0
    while i < P.size:
        if not adm[i]:
            i += 1
            continue
        j = i
        while j + 1 < P.size and adm[j + 1] and first_res[j] is None:
            j += 1
        lo = hi = None
        if i > 0:
            out = last_res[i - 1]
            lo = _bisect(solve, system, P[i], P[i - 1] if out is None else out,
                         _phase(orbits[i - 1]) if out is None else None)
        if j + 1 < P.size:
            out = first_res[j]
            hi = _bisect(solve, system, P[j], P[j + 1] if out is None else out,
                         _phase(orbits[j + 1]) if out is None else None)
        intervals.append(Arc(i, j, float(P[i] if lo is None else lo), float(P[j] if hi is None else hi),
                             lo is not None, hi is not None))
        i = j + 1
    return Branch(system=system, k=ipp, orbits=orbits, arcs=intervals, periods=P)
