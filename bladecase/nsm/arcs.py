"""What the mode searches of both contact models share: the period range searched and the admissible arcs found.

:func:`check_period_range` checks a ``T_range`` (``(start, stop)``, ``0 < start < stop``) for
:func:`~bladecase.nsm.nonsmooth_mode` and :func:`~bladecase.nsm.massless_mode`; :func:`admissible_arcs` finds the
maximal admissible runs of the orbits along a followed curve — a k-ipp family
(:mod:`bladecase.nsm.newton.families`) or a massless mode (:mod:`bladecase.nsm.massless.branches`) — each the
:class:`~bladecase.nsm.branches.Arc` of a :class:`~bladecase.nsm.branches.Branch`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["admissible_arcs", "check_period_range"]


def check_period_range(name: str, value) -> tuple[float, float]:
    """``(start, stop)`` of a period range: two finite numbers with ``0 < start < stop`` (``ValueError`` naming
    ``name`` otherwise).

    >>> check_period_range("T_range", (4.1, 3.2))
    Traceback (most recent call last):
    ...
    ValueError: T_range must be (start, stop) with 0 < start < stop, got (4.1, 3.2)
    """
    try:
        lo, hi = (float(x) for x in value)
        if isinstance(value, (str, bytes)) or any(isinstance(x, (bool, np.bool_)) for x in value):
            raise TypeError
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (start, stop): two periods with 0 < start < stop, got {value!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi)) or not 0 < lo < hi:
        raise ValueError(f"{name} must be (start, stop) with 0 < start < stop, got {value!r}")
    return lo, hi


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
