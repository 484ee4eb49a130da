"""An orbit of a computed massless branch at any period: :func:`massless_orbit_at` solves it exactly from its
interpolated neighbours (one contact phase, or any number of them), through changes of the phase pattern."""

from __future__ import annotations

import numpy as np

from .model import MasslessSystem
from .orbits import SymmetricOrbit, check_massless_system, orbit_at_period


def massless_orbit_at(system: MasslessSystem, orbits: list, T: float) -> list:
    """The orbits of period ``T`` on a massless branch (one per crossing of ``T`` by the curve), each solved
    exactly from its interpolated neighbours; ``[]`` where the branch does not reach ``T``.

    The points may be one-phase :class:`~bladecase.nsm.massless.orbits.SymmetricOrbit` s (the branches of
    :func:`massless_modes`: Newton on the closing residual from the interpolated contact half-time ``β``) or
    :class:`~bladecase.nsm.massless.phases.PhasedOrbit` s with any number of contact phases (the modes of
    :func:`massless_mode`: Newton on the half-orbit's switch residuals and ``2Στ = T`` from the interpolated
    half-phase durations, :func:`~bladecase.nsm.massless.follow.solve_at_period`).  Between two neighbours with
    different phase patterns (where the mode gains or loses contact phases) each pattern is tried from its own
    neighbour and the admissible solution kept: the mode is the admissible continuation.

    A mode that folds back in ``T`` gives several orbits at one period: on the 10-element bar's first mode
    (:func:`massless_mode` over ``(3.2, 4.1)``), ``T = 3.3`` is crossed once by the one-phase stretch and once
    by the two-phase one after the fold.  Periods outside the branch's range give ``[]``; a period that is not
    a finite number ``> 0`` is refused (``ValueError``).
    """
    from .orbits import _number

    check_massless_system(system, "massless_orbit_at")
    T = _number("period T", T)
    out: list = []
    for o1, o2 in zip(orbits[:-1], orbits[1:]):
        if o1 is None or o2 is None:
            continue
        lo, hi = sorted((o1.T, o2.T))
        if not lo <= T <= hi or hi == lo:
            continue
        s = (T - o1.T) / (o2.T - o1.T)
        if isinstance(o1, SymmetricOrbit) and isinstance(o2, SymmetricOrbit):
            found = [orbit_at_period(system, T, (1 - s) * o1.beta + s * o2.beta)]
        else:
            found = _phased_at(system, _pattern(o1), _pattern(o2), s, T)
        for orbit in found:
            if orbit is not None and not any(_same(orbit, o) for o in out):
                out.append(orbit)
    return out


def _pattern(orbit) -> tuple[str, np.ndarray]:
    """``(first, durations)`` of a massless orbit (a one-phase orbit is ``("open", [α, β])``)."""
    from .phases import PhasedOrbit

    if isinstance(orbit, PhasedOrbit):
        return orbit.first, orbit.durations
    if isinstance(orbit, SymmetricOrbit):
        return "open", np.array([orbit.alpha, orbit.beta])
    raise ValueError(f"a massless branch holds SymmetricOrbit or PhasedOrbit points, got {type(orbit).__name__}")


def _phased_at(system: MasslessSystem, p1: tuple, p2: tuple, s: float, T: float) -> list:
    """The orbit of period ``T`` between two neighbours of patterns ``p1``, ``p2`` at fraction ``s`` of the way."""
    from .follow import solve_at_period

    (first1, tau1), (first2, tau2) = p1, p2
    if first1 == first2 and tau1.size == tau2.size:
        return [solve_at_period(system, first1, (1 - s) * tau1 + s * tau2, T)]
    # the pattern changes between the neighbours: the one whose neighbour is nearer first, keep what is admissible
    tries = [(first1, tau1), (first2, tau2)] if s <= 0.5 else [(first2, tau2), (first1, tau1)]
    for first, tau in tries:
        orbit = solve_at_period(system, first, tau, T)
        if orbit is not None and orbit.admissible:
            return [orbit]
    return []


def _same(a, b) -> bool:
    """The same orbit twice (``T`` on a point shared by two pairs of neighbours)."""
    xa, xb = a.state(np.arange(8) / 8 * a.T)[0], b.state(np.arange(8) / 8 * b.T)[0]
    # the one-phase and phased records differ in their time origin: compare energies and contact times too
    scale = max(np.abs(xa).max(), 1e-300)
    return bool(abs(a.energy - b.energy) <= 1e-9 * max(abs(a.energy), 1e-300)
                and abs(a.contact_time - b.contact_time) <= 1e-9 * a.T
                and (type(a) is not type(b) or np.abs(xa - xb).max() <= 1e-7 * scale))
