"""Forced, damped event-driven simulation with Newton's impact law (seed paper Sec. 2.5, theory §5).

``M x'' + C x' + K x = F₀ cos(Ωt) f`` with the unilateral constraint ``wᵀx <= d`` and Moreau's form of
Newton's law (restitution ``e``).  Damping is modal: Rayleigh ``C = αK + βM`` (the paper uses ``C = αK``)
or modal damping ratios ``ζ_j`` (:class:`~bladecase.nsm.damping.Damping`); the load vector ``f`` defaults to a
unit force on every dof — the paper's "force acting on every mass" of the spring–mass chain.

The free flight stays EXACT between events: closed form per mode in every regime (under-, critically and
over-damped; near-resonant and exactly resonant forcing of an undamped mode) in
:mod:`bladecase.nsm.damped_signals`, whose contact signal carries a certified curvature bound, so the
unchanged event loop :func:`bladecase.nsm.newton.simulation.integrate` finds every first contact (no grazing
contact missed) and refines it to machine precision.  :class:`ForcedFlight` is the propagator plugged into
that loop; :func:`simulate_forced` is the entry point.  Pre-impact states are recorded as well
(``v⁻ = v⁺ + Λ M⁻¹w``, positions continuous).

Chattering (``e < 1``, impacts accumulating at the obstacle) ends the run exactly as the loop ends
:func:`~bladecase.nsm.simulate`: ``complete = False`` with a ``RuntimeWarning`` after 50 vanishing
flights in a row, or when the contact velocity vanishes first (at rest on the obstacle); the accumulation
point and the sticking phase after it are not modelled, nor is
``e = 0`` (plastic impacts: sticking phases from the first impact).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from ..damped_signals import DampedModes, DampedSignal
from ..damping import QUAD_NODES, Damping, EnergyBalance, _real, forcing_inputs
from ..system import LinearSystem
from .flight import ModalFlight, NewtonImpact
from .simulation import Trajectory, _check_state, integrate

__all__ = ["ForcedFlight", "ForcedTrajectory", "simulate_forced"]


class ForcedFlight(ModalFlight):
    """Damped, harmonically forced free flight, exact in modal coordinates ``(q, p) = (ΦᵀMx, ΦᵀMv)``.

    Each mode ``q_j'' + 2σ_j q_j' + ω_j² q_j = F_j cos(Ωt)`` (``F_j = F₀ φ_jᵀ f``) is flown in closed form
    (:class:`~bladecase.nsm.damped_signals.DampedModes`); the contact signal of a flight is a
    :class:`~bladecase.nsm.damped_signals.DampedSignal`, certified up to the ``horizon`` (the end time of
    the simulation).  Not autonomous: ``advance`` and ``contact_signal`` use the start time ``t0``.

    >>> import numpy as np
    >>> from bladecase.nsm import chain
    >>> fl = ForcedFlight(chain(2, k=1.0, m=0.5, gap=1.0), period=3.0, amplitude=0.2,
    ...                   damping=Damping(alpha=0.05), horizon=100.0)
    >>> q, p = fl.advance(np.zeros(2), np.zeros(2), 1.5, t0=0.0)     # from rest, half a forcing period
    >>> fl.decode(q, p)[0].round(6).tolist()
    [0.091842, 0.161224]
    """

    def __init__(self, system: LinearSystem, period: float | None = None, amplitude: float = 0.0,
                 damping: Damping | None = None, load=None, horizon: float = np.inf):
        if not isinstance(system, LinearSystem):
            raise ValueError(f"ForcedFlight: system must be a LinearSystem (Newton's contact), got "
                             f"{type(system).__name__}")
        super().__init__(system)
        amplitude = _real("amplitude", amplitude)
        if not np.isfinite(amplitude):
            raise ValueError(f"amplitude must be finite, got {amplitude!r}")
        period, Omega, damping, f = forcing_inputs(system.n, period, amplitude, damping, load)
        self.period, self.amplitude, self.damping, self.load = period, amplitude, damping, f
        self.horizon = _real("horizon", horizon, "number > 0 (inf: none)")
        if not self.horizon > 0:
            raise ValueError(f"horizon must be > 0 (inf: none), got {horizon!r}")
        self.modes = DampedModes(self.omega, damping.rates(self.omega), amplitude * (self.phi.T @ f), Omega)

    @property
    def Omega(self) -> float:
        """Forcing angular frequency ``Ω = 2π/T`` (0 when unforced)."""
        return self.modes.Omega

    def advance(self, q, p, tau, t0=0.0) -> tuple[np.ndarray, np.ndarray]:
        """State after a flight of duration ``tau`` started at time ``t0`` (one flight per column of 2-D
        ``q``, ``p``; ``tau`` and ``t0`` then of shape ``(N,)``)."""
        return self.modes.flight(q, p, t0, tau)

    def contact_signal(self, q, p, t0: float = 0.0) -> DampedSignal:
        """``wᵀx(τ) - d`` during the flight that starts from ``(q, p)`` at ``t0``, certified up to the horizon."""
        return DampedSignal(self.modes, self.b, np.asarray(q, float), np.asarray(p, float), float(t0),
                            -self.gap, max(self.horizon - float(t0), 0.0))

    def power(self, q, p, t) -> tuple[np.ndarray, np.ndarray]:
        """``(fᵀv F₀cos Ωt, vᵀCv)``: power of the forcing and viscous dissipation, per column."""
        F = self.modes.force.reshape((-1,) + (1,) * (np.ndim(q) - 1))
        s = self.modes.sigma.reshape(F.shape)
        return np.cos(self.Omega * np.asarray(t)) * np.sum(F * p, axis=0), np.sum(2 * s * p * p, axis=0)


@dataclass(frozen=True, eq=False)
class ForcedTrajectory(Trajectory):
    """Result of :func:`simulate_forced`: a :class:`~bladecase.nsm.newton.simulation.Trajectory` (post-impact
    states ``x``, ``v``, impact times, impulses, ``state(t)``) plus the pre-impact states.

    Attributes
    ----------
    v_pre : (n, k) ndarray
        Pre-impact velocities ``v⁻ = v⁺ + Λ M⁻¹w`` (positions are continuous: ``x_pre = x``).
    """

    v_pre: np.ndarray = field(repr=False, default=None)

    @property
    def x_pre(self) -> np.ndarray:
        """Pre-impact positions (= post-impact positions ``x``)."""
        return self.x

    @property
    def period(self) -> float | None:
        """Forcing period ``T = 2π/Ω``."""
        return self.flight.period

    def modal_state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Modal coordinates ``(q, p)`` at times ``t`` (post-impact values at impact instants)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        starts = np.concatenate([[self._t0], self.impact_times])
        q0 = np.column_stack([self._q0, self._q])
        p0 = np.column_stack([self._p0, self._p])
        idx = np.searchsorted(starts, t, side="right") - 1
        if np.any(idx < 0) or np.any(t > self.t_end * (1 + 1e-14) + 1e-300):
            raise ValueError(f"times must lie in [{self._t0}, {self.t_end}]")
        return self.flight.advance(q0[:, idx], p0[:, idx], t - starts[idx], starts[idx])

    def energy_at(self, t) -> np.ndarray:
        """Mechanical energy ``½vᵀMv + ½xᵀKx`` at times ``t``."""
        return self.flight.energy(*self.modal_state(t))

    def energy_balance(self) -> EnergyBalance:
        """Work of the forcing, viscous dissipation and impact losses over the run, by Gauss–Legendre
        quadrature of the exact flights (panels of at most half the shortest period, ``QUAD_NODES``
        nodes each): ``final - initial = work - dissipated - impact_loss`` to round-off."""
        fl = self.flight
        starts = np.concatenate([[self._t0], self.impact_times])
        ends = np.append(self.impact_times, self.t_end)
        q0 = np.column_stack([self._q0, self._q])
        p0 = np.column_stack([self._p0, self._p])
        panel = np.pi / fl.modes.rate_max
        npan = np.maximum(1, np.ceil((ends - starts) / panel)).astype(int)
        x, wq = np.polynomial.legendre.leggauss(QUAD_NODES)
        flight_of = np.repeat(np.arange(starts.size), npan)
        first = np.concatenate([[0], np.cumsum(npan)[:-1]])
        j = np.arange(flight_of.size) - np.repeat(first, npan)
        width = ((ends - starts) / npan)[flight_of]
        a = j * width                                     # panel starts, from the flight start
        tau = (a[:, None] + 0.5 * width[:, None] * (x + 1)[None, :]).ravel()
        wts = (0.5 * width[:, None] * wq[None, :]).ravel()
        col = np.repeat(flight_of, QUAD_NODES)
        q, p = fl.advance(q0[:, col], p0[:, col], tau, starts[col])
        pin, pdis = fl.power(q, p, starts[col] + tau)
        p_pre = self._p + fl.b[:, None] * self.impulses[None, :]
        loss = float(np.sum(fl.energy(self._q, p_pre) - fl.energy(self._q, self._p))) if self.impulses.size else 0.0
        q_end, p_end = fl.encode(self.x_end, self.v_end)
        return EnergyBalance(initial=float(fl.energy(self._q0, self._p0)), final=float(fl.energy(q_end, p_end)),
                             work=float(wts @ pin), dissipated=float(wts @ pdis), impact_loss=loss)


def _states(n: int, x0, v0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~bladecase.nsm.newton.simulation._check_state`, with a value that is not numbers named."""
    for name, a in (("x0", x0), ("v0", v0)):
        try:
            if a is None or isinstance(a, (str, bytes)):
                raise TypeError
            np.asarray(a, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a vector of {n} finite numbers (the initial state), got {a!r}") from None
    return _check_state(n, x0, v0)


def simulate_forced(
    system: LinearSystem,
    x0,
    v0,
    t_end: float,
    period: float | None = None,
    amplitude: float = 0.0,
    damping: Damping | None = None,
    load=None,
    restitution: float = 1.0,
    max_impacts: int | None = None,
) -> ForcedTrajectory:
    """Integrate ``M x'' + C x' + K x = F₀ cos(2πt/T) f`` with impacts from ``(x0, v0)`` at ``t = 0``.

    Parameters
    ----------
    system : LinearSystem
    x0, v0 : (n,) array_like
        Initial state with ``wᵀx0 <= d``.
    t_end : float
        Final time (> 0); also the horizon of the certified contact search.
    period : float or None
        Forcing period ``T = 2π/Ω`` (needed when ``amplitude != 0``).
    amplitude : float
        ``F₀``.
    damping : Damping or None
        ``Damping(alpha=α)`` for the paper's ``C = αK``; ``None``: undamped.
    load : (n,) array_like or None
        Load vector ``f``; ``None``: a unit force on every dof (the paper's "on every mass").
    restitution : float
        Newton coefficient ``e`` in ``(0, 1]``.
    max_impacts : int or None
        Safety stop (``complete = False``); default: the stored states fit in 1 GB
        (:func:`bladecase.nsm.newton.simulation.default_max_impacts`).

    Returns
    -------
    ForcedTrajectory
        Post- and pre-impact states, impulses, ``state(t)``, ``energy_at(t)``, ``energy_balance()``.

    Examples
    --------
    The paper's n = 5 chain forced at ``T = 2.4`` (``C = 0.005 K``, ``F₀ = 1``), from rest:

    >>> from bladecase.nsm import chain
    >>> s = chain(5, k=1.0, m=0.2, gap=1.0)
    >>> tr = simulate_forced(s, np.zeros(5), np.zeros(5), 24.0, period=2.4, amplitude=1.0,
    ...                      damping=Damping(alpha=0.005))
    >>> tr.impact_times.size, round(float(tr.impact_times[0]), 9), bool(np.all(tr.v_pre[4] > 0))
    (3, 0.745091528, True)
    >>> b = tr.energy_balance()
    >>> abs(b.residual) < 1e-10 * b.work
    True
    """
    if not isinstance(system, LinearSystem):
        hint = (": the massless contact model is simulate_forced_massless's"
                if getattr(system, "contact_model", None) == "massless" else "")
        raise ValueError(f"simulate_forced: system must be a LinearSystem (Newton's contact), got "
                         f"{type(system).__name__}{hint}")
    x0, v0 = _states(system.n, x0, v0)
    t_end = _real("t_end", t_end, "finite number > 0")
    if not np.isfinite(t_end) or t_end <= 0:
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    restitution = _real("restitution", restitution, "number in (0, 1]")
    flight = ForcedFlight(system, period, amplitude, damping, load, horizon=t_end)
    tr = integrate(flight, NewtonImpact(restitution), x0, v0, t_end, max_impacts, _stacklevel=3)
    p_pre = tr._p + flight.b[:, None] * tr.impulses[None, :]
    v_pre = flight.phi @ p_pre
    return ForcedTrajectory(**{f.name: getattr(tr, f.name) for f in fields(Trajectory)}, v_pre=v_pre)
