"""Following a nonsmooth mode of the massless model through changes of its number of contact phases.

A mode grows from an open-phase linear mode at grazing with one short contact phase.  Along it, admissibility
can be lost in two ways only: ``λ`` reaches 0 inside a closed phase (the contact opens briefly: the phase splits
in three) or ``ŵᵀx`` reaches ``d`` inside an open phase (a new contact phase).  At that boundary orbit the
orbit with the extra phases has a phase of zero duration, and beyond it that phase grows: the mode goes on as a
symmetric orbit with more phases (:func:`~bladecase.nsm.massless.phases.split_guess` gives the split; the new
orbit is solved at the period of the first non-admissible point).  The reverse — a phase shrinking to nothing —
merges its neighbours.  Each stretch with a fixed phase pattern is followed by pseudo-arclength continuation of
:func:`~bladecase.nsm.massless.phases.solve_half` (exact Jacobian, dimensionless durations ``τ ω``), so folds in
``T`` are passed on the same branch; switches between stretches happen only at proved admissibility
boundaries (bisection along the curve to :data:`EDGE_RTOL` in ``T``).

The result is the physically continued mode: a list of admissible orbits (each switch contributes its boundary
orbit), which :func:`~bladecase.nsm.massless.branches.massless_modes` turns into a :class:`~bladecase.nsm.Branch`.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ... import log
from ..continuation import Curve, bisect, follow, tangent
from .model import MasslessSystem
from .phases import PHASES, PhasedOrbit, solve_half, split_at, violation

#: Relative precision (of ``T``) of the boundary orbits where the phase pattern changes.
EDGE_RTOL = 1e-9
#: A phase shorter than this fraction of the period is merged into its neighbours.
VANISH_RTOL = 1e-6
#: Most half-orbit phases followed (a mode that keeps splitting beyond is stopped, with a log line).
MAX_HALF_PHASES = 41


class _Stretch:
    """One phase pattern (``first``, ``m + 1`` half phases) as a continuation curve in ``z = τ ω``."""

    def __init__(self, system: MasslessSystem, first: str, count: int, omega: float):
        self.system, self.first, self.count, self.omega = system, first, count, omega
        self._cache: dict[bytes, tuple] = {}
        self.curve = Curve(residual=self.residual, jacobian=self.jacobian,
                           valid=lambda z: bool(np.all(z > 0)), tol=1e-10, step_tol=1e-12)

    def _solve(self, z: np.ndarray) -> tuple:
        key = z.tobytes()
        if key not in self._cache:
            if len(self._cache) > 64:
                self._cache.clear()
            self._cache[key] = solve_half(self.system, self.first, z / self.omega, gradient=True)
        return self._cache[key]

    def residual(self, z):
        return self._solve(z)[1] / self.system.gap

    def jacobian(self, z):
        return self._solve(z)[2] / (self.system.gap * self.omega)

    def orbit(self, z) -> PhasedOrbit:
        return PhasedOrbit(self.system, self.first, z / self.omega, self._solve(z)[0])


def solve_at_period(system: MasslessSystem, first: str, tau, T: float, maxiter: int = 40) -> PhasedOrbit | None:
    """The orbit of phase pattern ``(first, len(tau))`` and period ``T`` reached by Newton from ``tau``
    (``r(τ) = 0`` and ``2Στ = T``; exact Jacobian); ``None`` if it fails or a duration turns non-positive."""
    tau = np.asarray(tau, float) * (0.5 * T / float(np.sum(tau)))
    for _ in range(maxiter):
        a, r, J = solve_half(system, first, tau, gradient=True)
        if not np.all(np.isfinite(r)):
            return None
        F = np.append(r / system.gap, 2 * tau.sum() / T - 1)
        A = np.vstack([J / system.gap, np.full(tau.size, 2 / T)])
        try:
            step = sla.solve(A, -F, check_finite=False)
        except (ValueError, np.linalg.LinAlgError):
            return None
        tau = tau + step
        if np.any(tau <= 0):
            return None
        if np.abs(step).max() <= 1e-13 * T:
            a, r = solve_half(system, first, tau)
            return PhasedOrbit(system, first, tau, a) if np.abs(r).max() <= 1e-8 * system.gap else None
    return None


def _merge(orbit: PhasedOrbit) -> tuple[str, np.ndarray] | None:
    """The pattern without its vanishing phase (shortest, below :data:`VANISH_RTOL` ``T``)."""
    tau = orbit.durations
    i = int(np.argmin(tau))
    if tau[i] > VANISH_RTOL * orbit.T or tau.size <= 2:
        return None
    m = tau.size - 1
    if i == 0:
        return PHASES[1 - orbit.kinds[0]], tau[1:].copy()
    if i == m:
        return orbit.first, tau[:-1].copy()
    return orbit.first, np.concatenate([tau[: i - 1], [tau[i - 1] + tau[i + 1]], tau[i + 2:]])


def follow_mode(system: MasslessSystem, start: PhasedOrbit, T_range: tuple[float, float], grow: int = 1,
                max_points: int = 4000, ds: float = 2e-3, ds_max: float = 0.05) -> list[PhasedOrbit]:
    """Admissible orbits of the mode through ``start`` (admissible), following it in the direction where half
    phase ``grow`` lengthens, across changes of its phase pattern, while ``T`` stays in ``T_range``."""
    from ..arcs import check_period_range
    from .orbits import check_massless_system

    check_massless_system(system, "follow_mode")
    if not isinstance(start, PhasedOrbit):
        raise ValueError(f"follow_mode: start must be a PhasedOrbit (e.g. PhasedOrbit(system, 'open', [α, β], a)), got "
                         f"{type(start).__name__}")
    T_range = check_period_range("T_range", T_range)
    if isinstance(grow, (bool, np.bool_)) or not isinstance(grow, (int, np.integer)) or not (
            0 <= grow < start.durations.size):
        raise ValueError(f"grow must be the index of a half-orbit phase of start, an integer in "
                         f"[0, {start.durations.size}), got {grow!r}")
    if isinstance(max_points, (bool, np.bool_)) or not isinstance(max_points, (int, np.integer)) or max_points < 1:
        raise ValueError(f"max_points must be an integer >= 1, got {max_points!r}")
    omega = 2 * np.pi / start.T
    out = [start]
    first, tau, orient = start.first, start.durations, _unit(start.durations.size, grow)
    flipped, direction_T = False, 0.0
    while len(out) < max_points:
        stretch = _Stretch(system, first, tau.size, omega)
        pts, bad = _run(stretch, tau * omega, orient, T_range, ds, ds_max, max_points - len(out))
        if not pts and bad is not None and not flipped:  # left a merge point on the wrong side: the other one
            orient, flipped = -orient, True
            continue
        flipped = False
        out += [stretch.orbit(z) for z in pts]
        last = pts[-1] if pts else tau * omega
        if pts:
            direction_T = float(np.sign(np.sum(pts[-1]) - np.sum(tau * omega)))
        if bad is not None:
            o_bad = stretch.orbit(bad)
            if not T_range[0] <= o_bad.T <= T_range[1]:
                return out  # left the period range
            edge_in, edge_out = _edge(stretch, last, bad)
            out.append(stretch.orbit(edge_in))
            nxt = _switch(stretch.orbit(edge_in), stretch.orbit(edge_out))
        else:
            nxt = _merged(stretch.orbit(last))
        if nxt is None or not pts and bad is None:
            log.info("massless mode: followed to T = %.8g with %d contact phase(s) per period; no continuation "
                     "found beyond", out[-1].T, out[-1].k)
            return out
        first, tau, grow_index = nxt
        if tau.size > MAX_HALF_PHASES:
            log.info("massless mode: stopped at T = %.8g: more than %d half phases", out[-1].T, MAX_HALF_PHASES)
            return out
        orient = _unit(tau.size, grow_index) if grow_index is not None else direction_T * np.ones(tau.size)
    return out


def _run(stretch: _Stretch, z0: np.ndarray, orient: np.ndarray, T_range, ds: float, ds_max: float, budget: int
         ) -> tuple[list[np.ndarray], np.ndarray | None]:
    """Admissible points of one stretch from ``z0`` along ``orient``, and the first point that is not (or left
    the period range), if any."""
    bad: list[np.ndarray] = []

    def stop(z) -> bool:
        o = stretch.orbit(z)
        if not (T_range[0] <= o.T <= T_range[1] and o.admissible):
            bad.append(z)
            return True
        return False

    t0 = tangent(stretch.curve.jacobian(z0), orient)
    pts = follow(stretch.curve, z0, t0, ds=ds * np.pi, ds_max=ds_max * np.pi, ds_min=1e-9, max_points=budget,
                 stop=stop)
    return (pts[:-1], bad[0]) if bad else (pts, None)


def _unit(size: int, i: int) -> np.ndarray:
    e = np.zeros(size)
    e[i] = 1.0
    return e


def _edge(stretch: _Stretch, z_in: np.ndarray, z_out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Admissible / non-admissible points of the stretch within :data:`EDGE_RTOL` of each other in ``T``."""
    T_scale = 2 * float(np.sum(z_in)) / stretch.omega
    z_in, z_out, _ = bisect(stretch.curve, z_in, z_out, lambda z: stretch.orbit(z).admissible,
                            converged=lambda a, b: 2 * abs(np.sum(a) - np.sum(b)) / stretch.omega
                            <= EDGE_RTOL * T_scale and np.abs(a - b).max() <= 1e-6)
    return z_in, z_out


def _switch(edge: PhasedOrbit, beyond: PhasedOrbit) -> tuple[str, np.ndarray, int] | None:
    """The pattern with a zero-duration phase where ``beyond`` (just past the boundary ``edge``) is violated."""
    where = violation(beyond)
    return None if where is None else split_at(edge.first, edge.durations, *where)


def _merged(orbit: PhasedOrbit) -> tuple[str, np.ndarray, None] | None:
    guess = _merge(orbit)
    return None if guess is None else (*guess, None)
