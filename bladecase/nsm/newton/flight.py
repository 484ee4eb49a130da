"""The pieces of the event-driven simulator: a flight propagator and an impact law.

The event loop (:func:`bladecase.nsm.newton.simulation.integrate`) knows only these two interfaces:

* a **flight propagator** maps a state to its coordinates (``encode``/``decode``), advances it in closed form
  (``advance``), and gives the contact signal ``wᵀx(τ) - d`` of the flight starting from a state as an object
  with a certified bound on its curvature (``contact_signal``: what :func:`bladecase.nsm.signals.first_upcrossing`
  needs — values and slopes, ``curvature_bound``, ``step``, ``magnitude``, ``grid``);
* an **impact law** maps the pre-impact state to the post-impact one and the impulse (``apply``).

Today: :class:`ModalFlight` (undamped, every mode a rotation in its phase plane; the contact signal is a
trigonometric sum) and :class:`NewtonImpact` (Moreau's form of Newton's law with restitution ``e``, theory §1).
Damping and forcing (theory §5) are further propagators with the same methods.

>>> from bladecase.nsm import chain
>>> s = chain(2, k=1.0, m=0.5, gap=1.0)
>>> flight, law = ModalFlight(s), NewtonImpact(1.0)
>>> q, p = flight.encode([0.0, 1.0], [0.0, 1.0])          # at the obstacle, moving into it
>>> p_after, impulse = law.apply(flight, q, p)
>>> round(float(flight.normal_velocity(q, p_after)), 12), round(float(impulse), 12)   # wᵀv⁺ = -wᵀv⁻
(-1.0, 1.0)
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ..signals import TrigSum
from ..system import LinearSystem

#: Relative tolerance (of ``gap``) within which a state counts as "at the obstacle"
#: (raised to the round-off of ``wᵀx`` for large amplitudes).
CONTACT_RTOL = 1e-12


class FlightPropagator(Protocol):
    """What the event loop asks of a free flight (see the module docstring)."""

    system: LinearSystem

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]: ...

    def decode(self, q, p) -> tuple[np.ndarray, np.ndarray]: ...

    def advance(self, q, p, tau, t0=0.0) -> tuple[np.ndarray, np.ndarray]: ...

    def contact_signal(self, q, p, t0=0.0): ...

    def contact_tol(self, q) -> float: ...

    def gap_value(self, q) -> float: ...

    def normal_velocity(self, q, p) -> float: ...

    def energy(self, q, p) -> np.ndarray: ...

    @property
    def normal_direction(self) -> tuple[np.ndarray, float]: ...


class ImpactLaw(Protocol):
    """What the event loop asks of an impact law: ``(p⁺, Λ) = apply(flight, q, p⁻)``."""

    def apply(self, flight, q, p) -> tuple[np.ndarray, float]: ...


class ModalFlight:
    """Undamped free flight ``M x'' + K x = 0``, exact in modal coordinates ``(q, p) = (ΦᵀMx, ΦᵀMv)``.

    Every mode is a rotation in its phase plane; the contact signal ``wᵀx(τ) - d = bᵀq(τ) - d`` is the
    trigonometric sum ``Σ b_j (q_j cos ω_jτ + p_j/ω_j sin ω_jτ) - d``.  All modes are kept (an initial state
    may excite modes that do not see the contact).  Autonomous: the start time ``t0`` is not used.
    """

    def __init__(self, system: LinearSystem):
        sp = system.spectrum
        self.system = system
        self.omega, self.phi, self.b = sp.omega, sp.phi, sp.b
        self.gap = system.gap

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """Modal coordinates of the state ``(x, v)``."""
        M = self.system.M
        return self.phi.T @ (M @ np.asarray(x, dtype=float)), self.phi.T @ (M @ np.asarray(v, dtype=float))

    def decode(self, q, p) -> tuple[np.ndarray, np.ndarray]:
        """``(x, v)`` from modal coordinates (columns of 2-D arrays are states)."""
        return self.phi @ q, self.phi @ p

    def advance(self, q, p, tau, t0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """State after a flight of duration ``tau`` (``q``, ``p`` of shape ``(m,)`` with a scalar ``tau``,
        or ``(m, N)`` with ``tau`` of shape ``(N,)``: one flight per column)."""
        omega = self.omega.reshape((-1,) + (1,) * (np.ndim(q) - 1))
        c, s = np.cos(omega * tau), np.sin(omega * tau)
        return q * c + p / omega * s, -q * omega * s + p * c

    def contact_signal(self, q, p, t0: float = 0.0) -> TrigSum:
        """``wᵀx(τ) - d`` during the flight that starts from ``(q, p)``."""
        b = self.b
        return TrigSum(alpha=b * q, beta=b * p / self.omega, omega=self.omega, const=-self.gap)

    def contact_tol(self, q) -> float:
        """Distance to the obstacle below which a state counts as at the obstacle:
        ``CONTACT_RTOL·d``, or the round-off of ``wᵀx = bᵀq`` when larger."""
        return max(CONTACT_RTOL * self.gap, 64 * np.finfo(float).eps * float(np.abs(self.b) @ np.abs(q)))

    def gap_value(self, q) -> float:
        """``wᵀx - d`` (``<= 0`` when admissible)."""
        return float(self.b @ q) - self.gap

    def normal_velocity(self, q, p) -> float:
        """``wᵀv``."""
        return float(self.b @ p)

    @property
    def normal_direction(self) -> tuple[np.ndarray, float]:
        """``(M⁻¹w in these coordinates, wᵀM⁻¹w)`` = ``(b, bᵀb)``: how an impulse moves the state."""
        return self.b, float(self.b @ self.b)

    def energy(self, q, p) -> np.ndarray:
        """``½vᵀMv + ½xᵀKx`` (per column of 2-D arrays)."""
        om = self.omega.reshape((-1,) + (1,) * (np.ndim(q) - 1))
        return 0.5 * np.sum(p**2 + (om * q) ** 2, axis=0)


class NewtonImpact:
    """Moreau's form of Newton's impact law with restitution ``e`` in ``(0, 1]`` (theory §1):
    ``v⁺ = v⁻ - (1+e) M⁻¹w (wᵀv⁻)/(wᵀM⁻¹w)``, impulse ``Λ = (1+e) wᵀv⁻/(wᵀM⁻¹w)``."""

    def __init__(self, restitution: float = 1.0):
        e = float(restitution)
        if not 0 < e <= 1:
            raise ValueError(f"restitution must be in (0, 1], got {restitution!r}")
        self.restitution = e

    def apply(self, flight, q, p) -> tuple[np.ndarray, float]:
        """Post-impact ``p`` and the impulse, for a state at the obstacle moving into it."""
        direction, mobility = flight.normal_direction
        lam = (1 + self.restitution) * flight.normal_velocity(q, p) / mobility
        return p - lam * direction, lam
