"""Event-driven simulation: the independent truth for every periodic orbit.

Free flight is integrated exactly in modal coordinates (each mode is a
rotation in its phase plane).  The next impact is the FIRST root of
``wᵀx(t) - d`` after the current time, found by
:func:`bladecase.nsm.signals.first_upcrossing`, which proves every skipped
interval free of contact (no grazing contact missed) and refines the root to
machine precision.  The impact law is Moreau's (theory §1), valid for any SPD
``M``: ``v⁺ = v⁻ - (1+e) M⁻¹w (wᵀv⁻)/(wᵀM⁻¹w)``; in modal coordinates
``q̇⁺ = q̇⁻ - (1+e) b (bᵀq̇⁻)/(bᵀb)``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from .signals import TrigSum, first_upcrossing
from .system import LinearSystem

#: Relative tolerance (of ``gap``) within which a state counts as "at the obstacle"
#: (raised to the round-off of ``wᵀx`` for large amplitudes).
CONTACT_RTOL = 1e-12


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
        sp = self.system.spectrum
        starts = np.concatenate([[self._t0], self.impact_times])
        q0 = np.column_stack([self._q0, self._q]) if self._q.size else self._q0[:, None]
        p0 = np.column_stack([self._p0, self._p]) if self._p.size else self._p0[:, None]
        idx = np.searchsorted(starts, t, side="right") - 1
        if np.any(idx < 0) or np.any(t > self.t_end * (1 + 1e-14) + 1e-300):
            raise ValueError(f"times must lie in [{self._t0}, {self.t_end}]")
        tau = t - starts[idx]
        ph = sp.omega[:, None] * tau[None, :]
        c, s = np.cos(ph), np.sin(ph)
        q = q0[:, idx] * c + p0[:, idx] / sp.omega[:, None] * s
        p = -q0[:, idx] * sp.omega[:, None] * s + p0[:, idx] * c
        return sp.phi @ q, sp.phi @ p

    def energy(self) -> np.ndarray:
        """Energy after each impact (``½vᵀMv + ½xᵀKx``), shape ``(k,)``."""
        om = self.system.spectrum.omega[:, None]
        return 0.5 * np.sum(self._p**2 + (om * self._q) ** 2, axis=0)


def _contact_tol(b: np.ndarray, q: np.ndarray, d: float) -> float:
    """Distance to the obstacle below which a state counts as at the obstacle:
    ``CONTACT_RTOL·d``, or the round-off of ``wᵀx = bᵀq`` when larger."""
    return max(CONTACT_RTOL * d, 64 * np.finfo(float).eps * float(np.abs(b) @ np.abs(q)))


def _modal(system: LinearSystem, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    phi = system.spectrum.phi
    return phi.T @ (system.M @ x), phi.T @ (system.M @ v)


def _flight(omega, q, p, tau):
    c, s = np.cos(omega * tau), np.sin(omega * tau)
    return q * c + p / omega * s, -q * omega * s + p * c


def simulate(
    system: LinearSystem,
    x0,
    v0,
    t_end: float,
    restitution: float = 1.0,
    max_impacts: int = 1_000_000,
) -> Trajectory:
    """Integrate the impacting system from ``(x0, v0)`` at ``t = 0`` to ``t_end``.

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
    max_impacts : int
        Safety stop; the result then has ``complete = False``.

    Returns
    -------
    Trajectory
        Impact times, impulses, post-impact states, final state.
    """
    n = system.n
    x0 = np.asarray(x0, dtype=float).reshape(-1)
    v0 = np.asarray(v0, dtype=float).reshape(-1)
    for name, a in (("x0", x0), ("v0", v0)):
        if a.shape != (n,):
            raise ValueError(f"{name} has {a.size} entries, expected {n}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} contains non-finite values")
    t_end = float(t_end)
    if not np.isfinite(t_end) or t_end <= 0:
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    e = float(restitution)
    if not 0 < e <= 1:
        raise ValueError(f"restitution must be in (0, 1], got {restitution!r}")
    d = system.gap
    w = system.w
    sp = system.spectrum
    tol0 = _contact_tol(sp.b, _modal(system, x0, v0)[0], d)
    if w @ x0 - d > tol0:
        raise ValueError(f"initial state violates the constraint: wᵀx0 - d = {w @ x0 - d:.6g} > 0 "
                         f"(tolerance {tol0:.3g})")

    sp = system.spectrum
    omega, b = sp.omega, sp.b
    bb = float(b @ b)
    q, p = _modal(system, x0, v0)
    times, lams, qs, ps = [], [], [], []
    t = 0.0
    complete = True
    tiny_flights = 0
    while True:
        f = TrigSum(alpha=b * q, beta=b * p / omega, omega=omega, const=-d)
        f0 = float(b @ q) - d
        vn = float(b @ p)
        start = 0.0
        if f0 >= -_contact_tol(b, q, d):
            if vn > 0:
                tau = 0.0  # at the obstacle and moving into it: impact now
            else:
                # Leaving the obstacle: f(τ) <= f0 + vn τ + B₂τ²/2 < 0 just after.
                B2 = f.curvature_bound
                start = min(f.step, abs(vn) / B2) if B2 > 0 else f.step
                if vn == 0.0 or float(f(start)[0]) >= 0:
                    start = min(f.step, 1e-9 / float(omega.max()))
                    if float(f(start)[0]) >= 0:
                        raise RuntimeError(f"grazing contact at t = {t!r} with zero normal velocity: the "
                                           "motion would slide along the obstacle (not an impact motion)")
                tau = first_upcrossing(f, start, t_end - t) if start < t_end - t else None
        else:
            tau = first_upcrossing(f, 0.0, t_end - t)
        if tau is None:
            q, p = _flight(omega, q, p, t_end - t)
            t = t_end
            break
        q, p = _flight(omega, q, p, tau)
        t += tau
        vn = float(b @ p)
        if vn <= 0:
            continue  # grazing touch: no impulse
        lam_modal = (1 + e) * vn / bb
        p = p - lam_modal * b
        times.append(t)
        lams.append(lam_modal)
        qs.append(q.copy())
        ps.append(p.copy())
        tiny_flights = tiny_flights + 1 if tau < 1e-12 * max(t, 1.0) else 0
        if len(times) >= max_impacts or tiny_flights > 50:
            complete = False
            why = "max_impacts reached" if len(times) >= max_impacts else "impacts accumulate (chattering)"
            warnings.warn(f"simulate stopped at t = {t:.6g} after {len(times)} impacts: {why}", RuntimeWarning,
                          stacklevel=2)
            break
    phi = sp.phi
    Q = np.array(qs).T if qs else np.zeros((n, 0))
    P = np.array(ps).T if ps else np.zeros((n, 0))
    q0, p0 = _modal(system, x0, v0)
    return Trajectory(
        system=system,
        impact_times=np.array(times),
        impulses=np.array(lams),
        x=phi @ Q,
        v=phi @ P,
        t_end=t,
        x_end=phi @ q,
        v_end=phi @ p,
        complete=complete,
        _t0=0.0,
        _q0=q0,
        _p0=p0,
        _q=Q,
        _p=P,
    )
