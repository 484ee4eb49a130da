"""Nonsmooth modes of the massless contact model as :class:`~bladecase.nsm.Branch` es.

Each branch grows from an open-phase linear mode at grazing (contact time ``2β → 0``, ``T → 2π/ω_j``) and is
followed by pseudo-arclength continuation of the closing residual in ``(α, β)`` with its exact gradient
(:func:`~bladecase.nsm.massless.orbits.follow_from_grazing`), through folds in ``T`` on the same branch. Its
admissible arcs are the maximal runs of certified admissible orbits; their ends are refined by bisection along
the curve. The branch is the same type as the Newton modes': plots, reports, files and animations take it as is.
"""

from __future__ import annotations

import numpy as np

from ... import log
from ..arcs import admissible_arcs, check_period_range
from .model import MasslessSystem
from .orbit_at import massless_orbit_at  # noqa: F401  (public here too)
from .orbits import (
    GRAZING_BETA_MAX,
    GRAZING_RESOLUTION,
    SymmetricOrbit,
    _correct,
    check_massless_system,
    closing_residual,
    contact_share,
    follow_from_grazing,
)

#: Relative precision (of ``T``) of the admissible arcs' ends.
ARC_RTOL = 1e-9


def massless_modes(system: MasslessSystem, T_range: tuple[float, float], max_points: int = 400,
                   refine: bool = True, ds: float = 1e-3, ds_max: float = 0.02) -> list:
    """The one-contact-phase branches of ``system`` in ``T_range``: one per open-phase mode whose linear period
    ``2π/ω_j`` is at least ``T_range[0]``, kept from where it enters the range until it leaves it.

    Branches are ordered by mode; a branch that never enters the range is left out.
    """
    from ..branches import Arc, Branch

    check_massless_system(system, "massless_modes")
    T_lo, T_hi = check_period_range("T_range", T_range)
    max_points = _integer("max_points", max_points, 2)
    if not isinstance(refine, (bool, np.bool_)):
        raise ValueError(f"refine must be True or False, got {refine!r}")
    for name, value in (("ds", ds), ("ds_max", ds_max)):
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)) or \
                not 0 < value <= 1:
            raise ValueError(f"{name} must be a number with 0 < {name} <= 1 (a fraction of a quarter linear period), "
                             f"got {value!r}")
    out = []
    for j in np.flatnonzero(2 * np.pi / system.open.omega >= T_lo):
        if abs(system.open.b[j]) <= 1e-12 * np.abs(system.open.b).max():
            continue  # the contact does not see this mode: no branch grows from it
        try:
            orbits = follow_from_grazing(system, T_lo, mode=int(j), ds=ds, ds_max=ds_max,
                                         max_points=max_points + _entry(system, j, T_hi))
        except ValueError as exc:
            if contact_share(system, int(j)) * GRAZING_BETA_MAX >= GRAZING_RESOLUTION:
                raise
            log.warning("massless branch of open mode %d skipped: %s", j + 1, exc)  # the contact barely sees it
            continue
        Ts = np.array([o.T for o in orbits])
        inside = np.flatnonzero((Ts >= T_lo) & (Ts <= T_hi))
        if inside.size < 2:
            continue
        orbits = orbits[inside[0]: inside[0] + max_points]
        exit_ = _first_exit(np.array([o.T for o in orbits]), T_lo, T_hi)
        if exit_ == len(orbits) and len(orbits) == max_points:
            log.info("massless branch of open mode %d: the point budget (%d) ran out at T = %.6g, inside the range "
                     "[%.6g, %.6g] (the branch winds through internal resonances); raise max_points to follow it "
                     "further", j + 1, max_points, orbits[-1].T, T_lo, T_hi)
        orbits = orbits[:exit_]
        if len(orbits) >= 2:
            out.append(Branch(system, 1, orbits, [Arc(*a) for a in _arcs(system, orbits, refine)]))
    return out


def _entry(system: MasslessSystem, j: int, T_hi: float) -> int:
    """Points to allow for the stretch above ``T_hi`` (grazing at ``2π/ω_j`` may lie above the range)."""
    return 0 if 2 * np.pi / system.open.omega[j] <= T_hi else 2000


def _first_exit(T: np.ndarray, T_lo: float, T_hi: float) -> int:
    out = np.flatnonzero((T < T_lo) | (T > T_hi))
    return int(out[0]) if out.size else T.size


def _arcs(system: MasslessSystem, orbits: list[SymmetricOrbit], refine: bool) -> list[tuple]:
    """``(start, stop, T_lo, T_hi, refined_lo, refined_hi)`` of every maximal admissible run."""
    return admissible_arcs(orbits, lambda i, out: (_edge(system, orbits[out], orbits[i]).T, True) if refine else None)


def _edge(system: MasslessSystem, bad: SymmetricOrbit, good: SymmetricOrbit) -> SymmetricOrbit:
    """The last admissible orbit between ``good`` and ``bad`` (bisection along the curve, to :data:`ARC_RTOL`)."""
    zb, zg = np.array([bad.alpha, bad.beta]), np.array([good.alpha, good.beta])
    best = good
    for _ in range(60):
        z, ok, _ = _correct(system, 0.5 * (zb + zg), good.T / 4)
        if not ok:
            break
        a, _ = closing_residual(system, *z)
        mid = SymmetricOrbit(system, z[0], z[1], a)
        if mid.admissible:
            zg, best = z, mid
        else:
            zb = z
        if abs(2 * (zb - zg).sum()) <= ARC_RTOL * best.T:
            break
    return best


def _integer(name: str, value, low: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def massless_mode(system: MasslessSystem, T_range: tuple[float, float], mode: int = 0, max_points: int = 4000):
    """The nonsmooth mode grown from open-phase mode ``mode`` at grazing, followed through changes of its number
    of contact phases (:func:`~bladecase.nsm.massless.follow.follow_mode`): a :class:`~bladecase.nsm.Branch` of
    admissible :class:`~bladecase.nsm.massless.phases.PhasedOrbit` s (``orbit.k`` contact phases each), ordered
    along the curve from grazing, or ``None`` when nothing admissible lies in ``T_range``.

    Where the one-phase orbit loses admissibility (``λ`` turning negative inside the contact, or the open phase
    touching the casing) the mode goes on with more phases instead of stopping; every point is proved admissible
    and the boundaries where the pattern changes are refined to ``1e-9 T``.

    >>> from bladecase.nsm import bar
    >>> branch = massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))
    >>> sorted({o.k for o in branch.orbits})[:2], bool(branch.admissible.all())
    ([1, 2], True)
    """
    from ..branches import Arc, Branch
    from .follow import follow_mode
    from .phases import PhasedOrbit

    check_massless_system(system, "massless_mode")
    T_lo, T_hi = check_period_range("T_range", T_range)
    if isinstance(mode, (bool, np.bool_)) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < system.n:
        raise ValueError(f"mode must be an open-phase mode index, an integer in [0, {system.n}), got {mode!r}")
    mode = int(mode)
    max_points = _integer("max_points", max_points, 2)
    if abs(system.open.b[mode]) <= 1e-12 * np.abs(system.open.b).max():
        raise ValueError(f"the contact does not see open-phase mode {mode} (b = {system.open.b[mode]:.3g}): "
                         "no nonsmooth mode grows from it")
    seed = follow_from_grazing(system, 0.0, mode=int(mode), max_points=2)[-1]
    start = PhasedOrbit(system, "open", [seed.alpha, seed.beta], seed.a)
    orbits = follow_mode(system, start, (T_lo, max(T_hi, start.T)), grow=1, max_points=max_points)
    orbits = [o for o in orbits if T_lo <= o.T <= T_hi]
    if len(orbits) < 2:
        return None
    return Branch(system, 1, orbits, [Arc(0, len(orbits) - 1, min(o.T for o in orbits), max(o.T for o in orbits),
                                          False, False)])
