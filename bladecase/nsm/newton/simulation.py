"""Event-driven simulation: the independent truth for every periodic orbit.

The loop (:func:`integrate`) takes two swappable pieces (:mod:`bladecase.nsm.newton.flight`): a flight propagator
(today the exact undamped modal flight, :class:`~bladecase.nsm.newton.flight.ModalFlight`) and an impact law (today
Moreau's form of Newton's law, :class:`~bladecase.nsm.newton.flight.NewtonImpact`).  The next impact is the FIRST
root of the propagator's contact signal ``wᵀx(t) - d`` after the current time, found by
:func:`bladecase.nsm.signals.first_upcrossing`, which proves every skipped interval free of contact (no grazing
contact missed) from the signal's certified curvature bound, and refines the root to machine precision.
:func:`simulate` is the usual entry point: modal flight and Newton's law with restitution ``e``, for any SPD
``M`` (theory §1): ``v⁺ = v⁻ - (1+e) M⁻¹w (wᵀv⁻)/(wᵀM⁻¹w)``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ...checks import integer
from ..signals import first_upcrossing
from ..system import LinearSystem
from .flight import CONTACT_RTOL, FlightPropagator, ImpactLaw, ModalFlight, NewtonImpact

__all__ = ["CONTACT_RTOL", "STATE_MEMORY_BYTES", "Trajectory", "default_max_impacts", "integrate", "simulate"]


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Result of :func:`simulate`.

    Attributes
    ----------
    impact_times : (k,) ndarray
        Times of the impacts, increasing.
    impulses : (k,) ndarray
        ``Λ = (1+e) wᵀv⁻ / (wᵀM⁻¹w) >= 0``.
    x, v : (n, k) ndarray
        Post-impact positions and velocities at each impact.
    t_end : float
        Final time reached (``t_end`` asked, unless ``complete`` is False).
    x_end, v_end : (n,) ndarray
        State at ``t_end``.
    complete : bool
        False when the run stopped early (``max_impacts`` reached, or an
        accumulation of impacts — chattering — with ``restitution < 1``).
    flight : FlightPropagator
        The propagator of the run (its coordinates are those of the stored states).

    Examples
    --------
    Started from the post-impact state of the 1-ipp orbit of period 6, the simulation impacts every
    6 time units and conserves the orbit's energy (restitution 1):

    >>> from bladecase.nsm import chain, orbit_1ipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> orbit = orbit_1ipp(system, 6.0)
    >>> x0, v0 = orbit.state(0.0)
    >>> tr = simulate(system, x0[:, 0], v0[:, 0], 13.0)
    >>> tr.impact_times.round(9).tolist(), tr.impulses.round(6).tolist(), tr.complete, tr.t_end
    ([6.0, 12.0], [0.791202, 0.791202], True, 13.0)
    >>> tr.energy().round(6).tolist()
    [0.602841, 0.602841]
    >>> x, v = tr.state([12.0])                     # back at the start: the last mass at the obstacle
    >>> bool(np.allclose(x, x0, atol=1e-9)), round(float(x[1, 0]), 9)
    (True, 1.0)
    """

    system: LinearSystem = field(repr=False)
    impact_times: np.ndarray
    impulses: np.ndarray
    x: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    t_end: float
    x_end: np.ndarray = field(repr=False)
    v_end: np.ndarray = field(repr=False)
    complete: bool
    flight: FlightPropagator = field(repr=False)
    _t0: float = field(repr=False)
    _q0: np.ndarray = field(repr=False)
    _p0: np.ndarray = field(repr=False)
    _q: np.ndarray = field(repr=False)
    _p: np.ndarray = field(repr=False)

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``(x, v)`` at times ``t`` in ``[t0, t_end]``, shape ``(n, len(t))``.

        Post-impact values at impact instants.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        starts = np.concatenate([[self._t0], self.impact_times])
        q0 = np.column_stack([self._q0, self._q]) if self._q.size else self._q0[:, None]
        p0 = np.column_stack([self._p0, self._p]) if self._p.size else self._p0[:, None]
        idx = np.searchsorted(starts, t, side="right") - 1
        if np.any(idx < 0) or np.any(t > self.t_end * (1 + 1e-14) + 1e-300):
            raise ValueError(f"times must lie in [{self._t0}, {self.t_end}]")
        q, p = self.flight.advance(q0[:, idx], p0[:, idx], t - starts[idx], starts[idx])
        return self.flight.decode(q, p)

    def energy(self) -> np.ndarray:
        """Energy after each impact (``½vᵀMv + ½xᵀKx``), shape ``(k,)``."""
        return self.flight.energy(self._q, self._p)


def _check_state(n: int, x0, v0) -> tuple[np.ndarray, np.ndarray]:
    x0 = np.asarray(x0, dtype=float).reshape(-1)
    v0 = np.asarray(v0, dtype=float).reshape(-1)
    for name, a in (("x0", x0), ("v0", v0)):
        if a.shape != (n,):
            raise ValueError(f"{name} has {a.size} entries, expected {n}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} contains non-finite values")
    return x0, v0


def _next_impact(flight: FlightPropagator, q, p, t: float, t_end: float) -> float | None:
    """Flight time to the next contact (``0``: impact now), or ``None`` if there is none before ``t_end``."""
    f = flight.contact_signal(q, p, t)
    f0 = flight.gap_value(q)
    vn = flight.normal_velocity(q, p)
    if f0 < -flight.contact_tol(q):
        return first_upcrossing(f, 0.0, t_end - t)
    if vn > 0:
        return 0.0  # at the obstacle and moving into it: impact now
    # Leaving the obstacle: f(τ) <= f0 + vn τ + B₂τ²/2 < 0 just after.
    B2 = f.curvature_bound
    start = min(f.step, abs(vn) / B2) if B2 > 0 else f.step
    if vn == 0.0 or float(f(start)[0]) >= 0:
        start = min(f.step, 1e-9 / float(f.omega.max()))
        if float(f(start)[0]) >= 0:
            raise RuntimeError(f"grazing contact at t = {t!r} with zero normal velocity: the "
                               "motion would slide along the obstacle (not an impact motion)")
    return first_upcrossing(f, start, t_end - t) if start < t_end - t else None


#: Memory the stored impact states of one simulation may take (bytes): every impact keeps its post-impact state
#: twice (modal and physical coordinates, ``4 n`` floats), so the default ``max_impacts`` is
#: ``min(1e6, STATE_MEMORY_BYTES / (32 n))`` — e.g. 156 000 impacts at ``n = 200``.
STATE_MEMORY_BYTES = 1 << 30


def default_max_impacts(n: int) -> int:
    """The impacts whose states fit in :data:`STATE_MEMORY_BYTES` (at most a million) for ``n`` dofs.

    >>> default_max_impacts(2), default_max_impacts(200)
    (1000000, 167772)
    """
    return int(min(1_000_000, STATE_MEMORY_BYTES // (32 * max(int(n), 1))))


def integrate(flight: FlightPropagator, impact: ImpactLaw, x0, v0, t_end: float,
              max_impacts: int | None = None, _stacklevel: int = 2) -> Trajectory:
    """The event loop: fly with ``flight`` to the first contact, apply ``impact``, repeat until ``t_end``.

    ``(x0, v0)`` at ``t = 0`` must satisfy ``wᵀx0 <= d`` (up to the propagator's contact tolerance).
    Stops early (``complete = False``, with a ``RuntimeWarning``) when the state comes to rest on the obstacle
    (where chattering with ``e < 1`` ends; the sticking phase is not modelled), after ``max_impacts`` impacts
    (default :func:`default_max_impacts`: the stored states stay within :data:`STATE_MEMORY_BYTES`) or when
    impacts accumulate (more than 50 flights shorter than ``1e-12`` of the time in a row).
    """
    system = flight.system
    x0, v0 = _check_state(system.n, x0, v0)
    t_end = float(t_end)
    if not np.isfinite(t_end) or t_end <= 0:
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    bounded = max_impacts is None
    max_impacts = default_max_impacts(system.n) if bounded else integer("max_impacts", max_impacts, 1)
    d = system.gap
    q0, p0 = flight.encode(x0, v0)
    tol0 = flight.contact_tol(q0)
    if system.w @ x0 - d > tol0:
        raise ValueError(f"initial state violates the constraint: wᵀx0 - d = {system.w @ x0 - d:.6g} > 0 "
                         f"(tolerance {tol0:.3g})")
    q, p = q0, p0
    times, lams, qs, ps = [], [], [], []
    t = 0.0
    complete = True
    tiny_flights = 0
    while True:
        try:
            tau = _next_impact(flight, q, p, t, t_end)
        except RuntimeError as exc:  # at rest on the obstacle: where chattering (e < 1) ends
            complete = False
            warnings.warn(f"simulate stopped at t = {t:.6g} after {len(times)} impacts: {exc}", RuntimeWarning,
                          stacklevel=_stacklevel)
            break
        if tau is None:
            q, p = flight.advance(q, p, t_end - t, t)
            t = t_end
            break
        q, p = flight.advance(q, p, tau, t)
        t += tau
        if flight.normal_velocity(q, p) <= 0:
            continue  # grazing touch: no impulse
        p, lam = impact.apply(flight, q, p)
        times.append(t)
        lams.append(lam)
        qs.append(q.copy())
        ps.append(p.copy())
        tiny_flights = tiny_flights + 1 if tau < 1e-12 * max(t, 1.0) else 0
        if len(times) >= max_impacts or tiny_flights > 50:
            complete = False
            why = "impacts accumulate (chattering)" if tiny_flights > 50 else (
                f"max_impacts = {max_impacts} reached" + (f" (the states of that many impacts fill "
                                                          f"{STATE_MEMORY_BYTES >> 20} MB: give max_impacts to go on)"
                                                          if bounded else ""))
            warnings.warn(f"simulate stopped at t = {t:.6g} after {len(times)} impacts: {why}", RuntimeWarning,
                          stacklevel=_stacklevel)
            break
    m = q0.size
    Q = np.array(qs).T if qs else np.zeros((m, 0))
    P = np.array(ps).T if ps else np.zeros((m, 0))
    X, V = flight.decode(Q, P)
    x_end, v_end = flight.decode(q, p)
    return Trajectory(system=system, impact_times=np.array(times), impulses=np.array(lams), x=X, v=V, t_end=t,
                      x_end=x_end, v_end=v_end, complete=complete, flight=flight, _t0=0.0, _q0=q0, _p0=p0,
                      _q=Q, _p=P)


def simulate(
    system: LinearSystem,
    x0,
    v0,
    t_end: float,
    restitution: float = 1.0,
    max_impacts: int | None = None,
) -> Trajectory:
    """Integrate the impacting system from ``(x0, v0)`` at ``t = 0`` to ``t_end``.

    Exact undamped modal flight (:class:`~bladecase.nsm.newton.flight.ModalFlight`) and Newton's impact law in
    Moreau's form (:class:`~bladecase.nsm.newton.flight.NewtonImpact`); :func:`integrate` takes other pieces.

    Parameters
    ----------
    system : LinearSystem
    x0, v0 : (n,) array_like
        Initial state, with ``wᵀx0 <= d``.  A state at the obstacle moving
        into it (``wᵀx0 = d``, ``wᵀv0 > 0``) impacts at ``t = 0``.
    t_end : float
        Final time (> 0).
    restitution : float
        Newton coefficient ``e`` in ``(0, 1]``; ``e = 1`` conserves energy.
    max_impacts : int or None
        Safety stop; the result then has ``complete = False``.  Default: as many impacts as the stored states
        fit in 1 GB (:func:`default_max_impacts`: a million for small systems, 167 772 at 200 dofs).

    Returns
    -------
    Trajectory
        Impact times, impulses, post-impact states, final state.

    Examples
    --------
    A 1-ipp orbit, started from its post-impact state, comes back after one period:

    >>> from bladecase.nsm import chain, orbit_1ipp
    >>> s = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> o = orbit_1ipp(s, 4.5)
    >>> x0, v0 = o.state(0.0)
    >>> tr = simulate(s, x0[:, 0], v0[:, 0], 1.5 * o.T)
    >>> tr.impact_times.round(9).tolist(), bool(np.allclose(tr.x[:, 0], x0[:, 0], atol=1e-9))
    ([4.5], True)
    """
    n = system.n
    x0, v0 = _check_state(n, x0, v0)
    t_end = float(t_end)
    if not np.isfinite(t_end) or t_end <= 0:
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    law = NewtonImpact(restitution)
    return integrate(ModalFlight(system), law, x0, v0, t_end, max_impacts, _stacklevel=3)
