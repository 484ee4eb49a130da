"""Forced, damped event-driven simulation of the massless contact model (theory §8, issue 13).

The interior dofs of a :class:`~bladecase.nsm.massless.model.MasslessSystem` obey

    M x'' + C x' + S x + ŵ λ = F₀ cos(Ωt) f,      λ = k_c max(0, y - d),      y = ŵᵀx + g F₀ cos(Ωt),

**Damping.** ``C`` acts on the interior only, the contact spring ``k_c`` is NOT damped: Rayleigh on the
open-phase matrices, ``C = αS + βM``, or modal ratios ``ζ_j`` of the open-phase modes
(:class:`~bladecase.nsm.damping.Damping`, ``ΦᵀCΦ = diag(2ζ_jω_j)``).  The same ``C`` acts in both phases, so
``λ`` stays continuous and both switches happen at ``y = d`` (closing when ``y`` rises through ``d``,
opening when ``λ`` falls to 0).  The closed phase (stiffness ``S + k_cŵŵᵀ``) then has NON-proportional
damping, except when ``C`` is undamped or mass-proportional.

**Load on the contact dofs.** ``f`` is the condensed interior load (``f_i - K_icK_cc⁻¹f_c``, what
:func:`bladecase.reduction.loads.project_load` gives); a load ``f_c`` on the massless contact dofs also moves
them statically: ``y`` gains ``g F₀ cos(Ωt)`` with ``g = w_cᵀK_cc⁻¹f_c`` (``contact_load``; ``= -closed_shapeᵀf``
of a :class:`~bladecase.reduction.massless.MasslessReducedModel`), and the closed phase's load becomes
``F₀ cos(Ωt)(f - k_c g ŵ)``.  Handled exactly (default ``g = 0``).

**Exact flights.** In the open-phase modal coordinates ``(q, p) = (ΦᵀMx, ΦᵀMv)``:

- open phase: decoupled damped modes, :class:`~bladecase.nsm.damped_signals.DampedModes` (every regime);
- closed phase, undamped or mass-proportional: the same in the closed phase's modes, about its equilibrium;
- closed phase, non-proportional: the first-order (state-space) system ``z' = Az + h cos Ωt`` with complex
  eigenvalues ``λ_k`` (``Re λ_k <= 0``): ``z(τ) = z_p(t₀+τ) + V e^{Λτ} V⁻¹(z₀ - z_p(t₀))``, the steady state
  ``z_p = Re(Z e^{iΩt})`` in closed form (refused at an undamped resonance or a defective ``A``).

The switching signal of a flight (``y - d`` open, ``d - y`` closed) carries a certified bound of its second
derivative — ``Σ|c_k||λ_k|² + |E|Ω²`` for a sum ``Re(Σ c_k e^{λ_kτ} + E e^{iΩτ})`` — so
:func:`~bladecase.nsm.signals.first_upcrossing` finds the FIRST switch (no contact phase is missed).

**Energy.** ``E = ½vᵀMv + ½xᵀSx + ½k_c max(0, y - d)²``; ``dE/dt = F₀cos(Ωt) fᵀv - vᵀCv - λ g F₀Ω sin(Ωt)``
(:meth:`MasslessForcedTrajectory.energy_balance`).

>>> import numpy as np
>>> from bladecase.nsm import Damping, bar
>>> s = bar(6, 0.05, contact="massless")
>>> tr = simulate_forced_massless(s, np.zeros(s.n), np.zeros(s.n), 40.0, period=4.2, amplitude=0.05,
...                               damping=Damping(alpha=0.02))
>>> tr.phases[:2], tr.contact_times.size
(('closed', 'open'), 10)
>>> b = tr.energy_balance()
>>> abs(b.residual) < 1e-10 * b.work
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..damped_signals import DampedModes, DampedSignal
from ..damping import QUAD_NODES, Damping, EnergyBalance, forcing_inputs
from ..signals import POINTS_PER_PERIOD, first_upcrossing
from .model import MasslessSystem, _leave_surface

__all__ = ["ExpSignal", "MasslessForcedFlight", "MasslessForcedTrajectory", "simulate_forced_massless"]

#: Largest condition number of the closed phase's state-space eigenvectors (near-defective: refused).
EIGVEC_COND_LIMIT = 1e10

#: Default ``max_switches`` of :func:`simulate_forced_massless`.
MAX_SWITCHES = 1_000_000


@dataclass(frozen=True, eq=False)
class _ShiftedSignal(DampedSignal):
    """A :class:`DampedSignal` plus ``Re(extra e^{iΩτ})`` (the contact dofs' own static response)."""

    extra: complex = 0j

    @cached_property
    def _coef(self):
        a_f, b_f, a_d, b_d, P, f0, d0 = DampedSignal._coef.func(self)
        E = complex(self.extra)
        return a_f, b_f, a_d, b_d, P + E, f0 + E.real, d0 - self.modes.Omega * E.imag

    @cached_property
    def _bounds(self) -> tuple[float, float]:
        B2, scale = DampedSignal._bounds.func(self)
        return B2 + abs(self.extra) * self.modes.Omega**2, scale + abs(self.extra)


@dataclass(frozen=True, eq=False)
class ExpSignal:
    """``f(τ) = const + Re(Σ c_k e^{λ_kτ} + E e^{iΩτ})`` with ``Re λ_k <= 0``: a damped signal with a certified
    bound ``B₂ >= max|f''|`` on ``[0, horizon]``, for :func:`~bladecase.nsm.signals.first_upcrossing`.

    >>> f = ExpSignal(np.array([-0.1 + 2j, -0.1 - 2j]), np.array([0.5, 0.5]), 1.0, 0j, -0.5)
    >>> [round(float(v), 12) for v in f(0.0)], round(f.curvature_bound, 12)
    ([0.5, -0.1], 4.01)
    """

    lam: np.ndarray
    c: np.ndarray
    Omega: float
    E: complex
    const: float
    horizon: float = np.inf

    def __call__(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """Values and first derivatives at the points ``tau`` (any shape)."""
        tau = np.asarray(tau, dtype=float)
        e = np.exp(np.multiply.outer(tau.reshape(-1), self.lam))
        f, df = (e @ self.c).real + self.const, (e @ (self.c * self.lam)).real
        if self.E:
            z = self.E * np.exp(1j * self.Omega * tau.reshape(-1))
            f, df = f + z.real, df - self.Omega * z.imag
        return f.reshape(tau.shape), df.reshape(tau.shape)

    def grid(self, start: float, h: float, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(τ, f, f')`` at ``τ = start + h·arange(count)``."""
        tau = start + h * np.arange(count)
        return (tau, *self(tau))

    @cached_property
    def _growth(self) -> np.ndarray:
        re = np.maximum(self.lam.real, 0.0)
        with np.errstate(over="ignore", invalid="ignore"):
            return np.where(re > 0, np.exp(re * self.horizon), 1.0)

    @property
    def curvature_bound(self) -> float:
        """``Σ|c_k||λ_k|² e^{max(Re λ_k, 0)·horizon} + |E|Ω²``."""
        return float(np.abs(self.c) @ (np.abs(self.lam) ** 2 * self._growth) + abs(self.E) * self.Omega**2)

    @property
    def magnitude(self) -> float:
        return float(np.abs(self.c) @ self._growth + abs(self.E))

    @property
    def step(self) -> float:
        """``2π / (POINTS_PER_PERIOD · max(|λ_k|, Ω))``."""
        return 2 * np.pi / (POINTS_PER_PERIOD * max(float(np.abs(self.lam).max()), self.Omega))


class _ModalPhase:
    """A phase flown by :class:`DampedModes` in the basis ``r = P(q - q_eq)`` (``P`` orthogonal or ``None``)."""

    def __init__(self, modes: DampedModes, P, q_eq, b, y_eq: float, sign: float, gap: float, g: float):
        self.modes, self.P, self.q_eq, self.y_eq, self.sign, self.gap, self.g = modes, P, q_eq, y_eq, sign, gap, g
        self.b = b if P is None else P @ b

    def _local(self, q, p):
        if self.P is None:
            return q, p
        return self.P @ (q - (self.q_eq if q.ndim == 1 else self.q_eq[:, None])), self.P @ p

    def advance(self, q, p, t0, tau) -> tuple[np.ndarray, np.ndarray]:
        r, s = self.modes.flight(*self._local(q, p), t0, tau)
        if self.P is None:
            return r, s
        return self.P.T @ r + (self.q_eq if r.ndim == 1 else self.q_eq[:, None]), self.P.T @ s

    def signal(self, q, p, t0: float, horizon: float) -> _ShiftedSignal:
        r, s = self._local(q, p)
        sg = self.sign
        return _ShiftedSignal(self.modes, sg * self.b, r, s, t0, sg * (self.y_eq - self.gap), horizon,
                              extra=sg * self.g * np.exp(1j * self.modes.Omega * t0))


class _StatePhase:
    """The closed phase with non-proportional damping: ``q'' + Dq' + K̃(q - q_eq) = F cos Ωt`` as a first-order
    system, complex modes ``V``, ``λ``; steady state ``Re(Z e^{iΩt})`` of ``z = (q - q_eq, p)``."""

    def __init__(self, Kt, D, F, Omega: float, q_eq, b, y_eq: float, gap: float, g: float):
        n = Kt.shape[0]
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Kt, -D]])
        lam, V = np.linalg.eig(A)
        cond = np.linalg.cond(V)
        if not cond < EIGVEC_COND_LIMIT:
            raise ValueError(f"the damped closed phase is (nearly) defective (eigenvector condition {cond:.3g}): "
                             "change the damping slightly")
        R = np.zeros(n, complex)
        if np.any(F):
            Zm = Kt - Omega**2 * np.eye(n) + 1j * Omega * D
            cz = np.linalg.cond(Zm)
            if not cz < 1e14:
                raise ValueError(f"the closed phase is forced at an undamped resonance (Ω = {Omega:.6g}): no "
                                 "bounded steady state; damp every mode or change the period")
            R = np.linalg.solve(Zm, F.astype(complex))
        self.lam, self.V, self.Vinv = lam, V, np.linalg.inv(V)
        self.Z, self.Omega, self.q_eq, self.b, self.y_eq, self.gap, self.g = \
            np.concatenate([R, 1j * Omega * R]), Omega, q_eq, b, y_eq, gap, g
        self.bV = b @ V[:n]
        self.n = n

    def _particular(self, t) -> np.ndarray:
        return (np.multiply.outer(self.Z, np.exp(1j * self.Omega * np.atleast_1d(t)))).real

    def _modal(self, q, p, t0) -> np.ndarray:
        z = np.vstack([q.reshape(self.n, -1) - self.q_eq[:, None], p.reshape(self.n, -1)])
        return self.Vinv @ (z - self._particular(t0))

    def advance(self, q, p, t0, tau) -> tuple[np.ndarray, np.ndarray]:
        one = np.ndim(q) == 1 and np.ndim(tau) == 0
        eta = self._modal(np.asarray(q, float), np.asarray(p, float), t0)
        tau, t0 = np.atleast_1d(tau), np.atleast_1d(t0)
        z = (self.V @ (np.exp(self.lam[:, None] * tau[None, :]) * eta)).real + self._particular(t0 + tau)
        q1, p1 = z[:self.n] + self.q_eq[:, None], z[self.n:]
        return (q1[:, 0], p1[:, 0]) if one else (q1, p1)

    def signal(self, q, p, t0: float, horizon: float) -> ExpSignal:
        eta = self._modal(q, p, t0)[:, 0]
        E = -(self.b @ self.Z[:self.n] + self.g) * np.exp(1j * self.Omega * t0)
        return ExpSignal(self.lam, -self.bV * eta, self.Omega, complex(E), self.gap - self.y_eq, horizon)


class MasslessForcedFlight:
    """The two phases of the forced, damped massless model in open-phase modal coordinates (module docstring).

    >>> from bladecase.nsm import bar
    >>> fl = MasslessForcedFlight(bar(5, 0.1), period=3.0, amplitude=0.2, damping=Damping(alpha=0.05))
    >>> type(fl.closed).__name__, round(fl.Omega, 6)          # Rayleigh αS: non-proportional when closed
    ('_StatePhase', 2.094395)
    """

    def __init__(self, system: MasslessSystem, period: float | None = None, amplitude: float = 0.0,
                 damping: Damping | None = None, load=None, contact_load: float = 0.0):
        if not isinstance(system, MasslessSystem):
            raise ValueError(f"system must be a MasslessSystem, got {type(system).__name__}")
        amplitude, g = float(amplitude), float(contact_load)
        if not (np.isfinite(amplitude) and np.isfinite(g)):
            raise ValueError(f"amplitude and contact_load must be finite, got {amplitude!r} and {contact_load!r}")
        period, Omega, damping, f = forcing_inputs(system.n, period, amplitude, damping, load)
        self.system, self.period, self.amplitude, self.damping, self.load = system, period, amplitude, damping, f
        self.contact_load, self.Omega = g, Omega
        o, d = system.open, system.gap
        self.phi, self.omega, self.b, self.gap, self.kc = o.phi, o.omega, o.b, d, system.kc
        self.sigma = damping.rates(o.omega)
        self.force = amplitude * (o.phi.T @ f)          # modal load amplitude
        self.g = amplitude * g                           # contact displacement amplitude of the load
        self.open = _ModalPhase(DampedModes(o.omega, self.sigma, self.force, Omega), None, None, self.b, 0.0,
                                1.0, d, self.g)
        self.closed = self._closed_phase()

    def _closed_phase(self):
        s, d = self.system, self.gap
        c = s.closed
        q_eq = self.phi.T @ (s.M @ c.x_eq)
        F = self.force - s.kc * self.g * self.b          # closed-phase load amplitude, open-modal coordinates
        P = s.transfer
        Dc = P @ np.diag(2 * self.sigma) @ P.T
        off = Dc - np.diag(np.diag(Dc))
        if not np.any(self.sigma) or np.abs(off).max() <= 1e-13 * np.abs(Dc).max():
            modes = DampedModes(c.omega, 0.5 * np.maximum(np.diag(Dc), 0.0), P @ F, self.Omega)
            return _ModalPhase(modes, P, q_eq, self.b, c.y_eq, -1.0, d, self.g)
        Kt = np.diag(self.omega**2) + s.kc * np.outer(self.b, self.b)
        return _StatePhase(Kt, np.diag(2 * self.sigma), F, self.Omega, q_eq, self.b, c.y_eq, d, self.g)

    @property
    def rate_max(self) -> float:
        """Highest angular rate: ``max(ω_max(closed), Ω)``."""
        return float(max(self.system.closed.omega.max(), self.Omega))

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """Open-phase modal coordinates ``(ΦᵀMx, ΦᵀMv)``."""
        M = self.system.M
        return self.phi.T @ (M @ np.asarray(x, float)), self.phi.T @ (M @ np.asarray(v, float))

    def decode(self, q, p) -> tuple[np.ndarray, np.ndarray]:
        return self.phi @ q, self.phi @ p

    def contact(self, q, t) -> np.ndarray:
        """``y = ŵᵀx + g F₀ cos(Ωt)``."""
        return self.b @ q + self.g * np.cos(self.Omega * np.asarray(t, float))

    def multiplier(self, q, t) -> np.ndarray:
        """``λ = k_c max(0, y - d)``."""
        return self.kc * np.maximum(0.0, self.contact(q, t) - self.gap)

    def energy(self, q, p, t) -> np.ndarray:
        """``½vᵀMv + ½xᵀSx + ½k_c max(0, y - d)²`` per column."""
        lam = self.multiplier(q, t)
        return 0.5 * (np.sum(p * p, axis=0) + (self.omega**2) @ (q * q)) + 0.5 * lam * lam / self.kc

    def power(self, q, p, t) -> tuple[np.ndarray, np.ndarray]:
        """``(input, dissipation)``: ``F₀cos(Ωt) fᵀv - λ g F₀Ω sin(Ωt)`` and ``vᵀCv``, per column."""
        ph = self.Omega * np.asarray(t, float)
        return np.cos(ph) * (self.force @ p) - self.multiplier(q, t) * self.g * self.Omega * np.sin(ph), \
            (2 * self.sigma) @ (p * p)


@dataclass(frozen=True, eq=False)
class MasslessForcedTrajectory:
    """Result of :func:`simulate_forced_massless`: the switch times, the phase entered at each (``"closed"`` /
    ``"open"``), the states ``x``, ``v`` (n, k) at the switches (continuous), the state at ``t_end`` (where the run
    stopped; ``complete = False`` when ``max_switches`` stopped it) and whether it starts closed (``closed0``)."""

    flight: MasslessForcedFlight = field(repr=False)
    switch_times: np.ndarray
    phases: tuple[str, ...]
    x: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    x_end: np.ndarray = field(repr=False)
    v_end: np.ndarray = field(repr=False)
    t_end: float
    complete: bool
    closed0: bool = False
    _q: np.ndarray = field(repr=False, default=None)  # type: ignore[assignment]  # segment starts, (n, k + 1)
    _p: np.ndarray = field(repr=False, default=None)  # type: ignore[assignment]

    @property
    def system(self) -> MasslessSystem:
        return self.flight.system

    @property
    def period(self) -> float | None:
        """Forcing period ``T = 2π/Ω``."""
        return self.flight.period

    @cached_property
    def _closed(self) -> np.ndarray:
        """Whether each flight segment (from ``0`` and from every switch) is a closed phase."""
        return np.array([self.closed0] + [ph == "closed" for ph in self.phases], dtype=bool)

    @property
    def _starts(self) -> np.ndarray:
        return np.concatenate([[0.0], self.switch_times])

    @property
    def contact_times(self) -> np.ndarray:
        """Times at which a contact phase begins (closing switches; ``t = 0`` excluded)."""
        return self.switch_times[np.asarray([ph == "closed" for ph in self.phases], dtype=bool)]

    @property
    def impact_times(self) -> np.ndarray:
        """:attr:`contact_times`, under the name the forced-response records use for the events of a cycle."""
        return self.contact_times

    def _fly(self, idx: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Modal states at times ``t`` inside the segments ``idx``."""
        fl, starts = self.flight, self._starts
        n = self._q.shape[0]
        q, p = np.empty((n, t.size)), np.empty((n, t.size))
        for closed, ph in ((False, fl.open), (True, fl.closed)):
            sel = np.flatnonzero(self._closed[idx] == closed)
            if sel.size:
                j = idx[sel]
                q[:, sel], p[:, sel] = ph.advance(self._q[:, j], self._p[:, j], starts[j], t[sel] - starts[j])
        return q, p

    def modal_state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Open-phase modal coordinates ``(q, p)`` at times ``t``, shape ``(n, len(t))``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if np.any(t < 0) or np.any(t > self.t_end * (1 + 1e-14) + 1e-300):
            raise ValueError(f"times must lie in [0, {self.t_end}]")
        return self._fly(np.searchsorted(self._starts, t, side="right") - 1, t)

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``(x, v)`` at times ``t``, shape ``(n, len(t))``."""
        return self.flight.decode(*self.modal_state(t))

    def energy_at(self, t) -> np.ndarray:
        """``½vᵀMv + ½xᵀSx + ½k_c max(0, y - d)²`` at times ``t``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.flight.energy(*self.modal_state(t), t)

    def multiplier_at(self, t) -> np.ndarray:
        """Contact force ``λ(t)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.flight.multiplier(self.modal_state(t)[0], t)

    def _quadrature(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Gauss–Legendre nodes over every segment (panels of at most half the shortest period,
        ``QUAD_NODES`` each): ``(t, weights, segment, q, p)``."""
        starts, ends = self._starts, np.append(self.switch_times, self.t_end)
        npan = np.maximum(1, np.ceil((ends - starts) / (np.pi / self.flight.rate_max))).astype(int)
        x, wq = np.polynomial.legendre.leggauss(QUAD_NODES)
        seg = np.repeat(np.arange(starts.size), npan)
        j = np.arange(seg.size) - np.repeat(np.concatenate([[0], np.cumsum(npan)[:-1]]), npan)
        width = ((ends - starts) / npan)[seg]
        t = (starts[seg] + j * width)[:, None] + 0.5 * width[:, None] * (x + 1)[None, :]
        wts = (0.5 * width[:, None] * wq[None, :]).ravel()
        seg = np.repeat(seg, QUAD_NODES)
        q, p = self._fly(seg, t.ravel())
        return t.ravel(), wts, seg, q, p

    @cached_property
    def impulses(self) -> np.ndarray:
        """``∫λ dt`` over each contact phase that begins at :attr:`contact_times` (up to ``t_end``)."""
        t, wts, seg, q, _ = self._quadrature()
        per = np.bincount(seg, wts * self.flight.multiplier(q, t), minlength=self._starts.size)
        return per[1:][self._closed[1:]]

    def energy_balance(self) -> EnergyBalance:
        """``final - initial = work - dissipated`` (``impact_loss = 0``: the contact is elastic), by
        Gauss–Legendre quadrature of the exact flights."""
        fl = self.flight
        t, wts, _, q, p = self._quadrature()
        pin, pdis = fl.power(q, p, t)
        q_end, p_end = fl.encode(self.x_end, self.v_end)
        return EnergyBalance(initial=float(fl.energy(self._q[:, 0], self._p[:, 0], 0.0)),
                             final=float(fl.energy(q_end, p_end, self.t_end)), work=float(wts @ pin),
                             dissipated=float(wts @ pdis), impact_loss=0.0)


def _start_closed(fl: MasslessForcedFlight, q, p) -> bool:
    y0, dy0 = float(fl.contact(q, 0.0)), float(fl.b @ p)
    if abs(y0 - fl.gap) <= 1e-12 * max(fl.gap, abs(y0)):
        return dy0 > 0  # on the surface: the motion decides
    return y0 > fl.gap


def _first_switch(sig, horizon: float) -> float | None:
    """First root of the switching signal ``sig`` (which starts on or below its surface) in ``(0, horizon]``."""
    start = _leave_surface(sig, horizon)
    for _ in range(60):  # the grid and the direct evaluation may differ in the last bits at ``start``
        if float(sig.grid(start, 1.0, 1)[1][0]) < 0:
            break
        start *= 2
    if start >= horizon:
        return None
    return first_upcrossing(sig, start, horizon)


def simulate_forced_massless(system: MasslessSystem, x0, v0, t_end: float, period: float | None = None,
                             amplitude: float = 0.0, damping: Damping | None = None, load=None,
                             contact_load: float = 0.0, max_switches: int | None = None
                             ) -> MasslessForcedTrajectory:
    """Exact event-driven simulation of the forced, damped massless model from ``(x0, v0)`` at ``t = 0``.

    ``M x'' + C x' + S x + ŵλ = F₀ cos(2πt/T) f`` (module docstring: ``C`` damps the interior only, the
    contact spring is undamped).  Each phase is flown in closed form; each switch is the FIRST root of the
    phase's switching signal (certified).

    Parameters
    ----------
    system : MasslessSystem
    x0, v0 : (n,) array_like
        Initial interior state.
    t_end : float
        Final time (> 0); also the horizon of the certified contact search.
    period, amplitude : float
        Forcing period ``T`` (needed when ``amplitude != 0``) and ``F₀``.
    damping : Damping or None
        Rayleigh ``C = αS + βM`` or modal ratios of the open-phase modes; ``None``: undamped.
    load : (n,) array_like or None
        Interior (condensed) load ``f``; ``None``: a unit force on every interior dof.
    contact_load : float
        ``g = w_cᵀK_cc⁻¹f_c``: the contact displacement per unit ``F₀`` of the load on the massless contact
        dofs (module docstring); 0 when they are not loaded.
    max_switches : int or None
        Safety stop (``complete = False``); default ``MAX_SWITCHES``.

    Examples
    --------
    A mass on a spring (``k₁ = 1``) behind a massless contact spring (``k₂ = 3``), forced near resonance:

    >>> from bladecase.nsm import condense
    >>> s = condense(np.diag([1.0, 0.0]), np.array([[4.0, -3.0], [-3.0, 3.0]]), np.array([0.0, 1.0]), gap=1.0)
    >>> tr = simulate_forced_massless(s, [0.0], [0.0], 30.0, period=5.5, amplitude=0.3,
    ...                               damping=Damping(zeta=0.02))
    >>> round(float(tr.contact_times[0]), 9), tr.phases[:3]
    (12.465685535, ('closed', 'open', 'closed'))
    """
    n = system.n if isinstance(system, MasslessSystem) else 0
    fl = MasslessForcedFlight(system, period, amplitude, damping, load, contact_load)
    x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
    if x.size != n or v.size != n or not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError(f"x0 and v0 must be finite with {n} interior dofs, got {x.size} and {v.size}")
    t_end = float(t_end)
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    max_switches = MAX_SWITCHES if max_switches is None else max_switches
    if isinstance(max_switches, bool) or not isinstance(max_switches, (int, np.integer)) or max_switches < 1:
        raise ValueError(f"max_switches must be an integer >= 1, got {max_switches!r}")
    q, p = fl.encode(x, v)
    closed = closed0 = _start_closed(fl, q, p)
    t, times, phases, qs, ps = 0.0, [], [], [q], [p]
    while len(times) < max_switches:
        ph = fl.closed if closed else fl.open
        tau = _first_switch(ph.signal(q, p, t, t_end - t), t_end - t)
        if tau is None:
            q, p = ph.advance(q, p, t, t_end - t)
            t = t_end
            break
        q, p = ph.advance(q, p, t, tau)
        t += tau
        closed = not closed
        times.append(t)
        phases.append("closed" if closed else "open")
        qs.append(q)
        ps.append(p)
    Q, Pm = np.array(qs).T, np.array(ps).T
    X, V = fl.decode(Q[:, 1:], Pm[:, 1:])
    x_end, v_end = fl.decode(q, p)
    return MasslessForcedTrajectory(fl, np.array(times), tuple(phases), X, V, x_end, v_end, float(t),
                                    bool(t >= t_end), closed0, Q, Pm)
