"""Symmetric periodic orbits of the massless contact model with ANY number of contact phases per period.

A time-reversible system's symmetric orbit has ``v = 0`` at two instants per period, each in the middle of a
phase.  Its half orbit starts at the middle of phase 0 (``first``: open or closed) with ``v = 0`` and the state
``x = x_eq + Φ a`` in that phase's modal coordinates, runs phases ``0, 1, …, m`` alternately open and closed for
durations ``τ_0 … τ_m`` (phase 0 and phase ``m`` by half), and ends with ``v = 0`` in the middle of phase ``m``.
So ``T = 2 Σ τ`` and the orbit has ``m`` contact phases per period (``m = 1``: the one-phase orbits of
:mod:`bladecase.nsm.massless.orbits`, ``τ = (α, β)``).

The state at every switch is affine in ``a``: ``v_end = V(τ) a + v₀(τ) = 0`` is a linear system for ``a``, and the
``m`` switch conditions ``ŵᵀx = d`` leave ``m`` equations ``r(τ) = 0`` in ``m + 1`` durations: a curve, followed
by pseudo-arclength continuation (:mod:`bladecase.nsm.continuation`) with the exact Jacobian — at fixed ``a`` the
derivative of the end state in ``τ_i`` is the vector field at the end of phase ``i`` carried by the later
flights, and ``∂a/∂τ = -V⁻¹ ∂v_end/∂τ``.

Admissibility (``ŵᵀx <= d`` over every open phase, ``λ >= 0`` over every closed one) is proved phase by phase with
certified bounds; a violated phase tells where the orbit must gain phases (:func:`split_at`).  The vector field
is continuous across switches, so the monodromy matrix is the product of the phases' flight matrices (saltation
matrices are the identity).

>>> import numpy as np
>>> from bladecase.nsm.massless.model import condense
>>> s = condense(np.diag([1.0, 0.0]), np.array([[4.0, -3.0], [-3.0, 3.0]]), np.array([0.0, 1.0]), gap=1.0)
>>> a, r, J = solve_half(s, "open", np.array([2.0, 0.5]), gradient=True)   # not yet periodic: r ≠ 0
>>> round(float(r[0]), 6), J.shape
(1.512554, (1, 2))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from ..signals import TrigSum, certified_max
from .model import BoundOrbit, MasslessSystem, Phase

__all__ = ["PHASES", "PhasedOrbit", "solve_half", "split_at", "violation"]

PHASES = ("open", "closed")

#: Relative tolerance (of the clearance) of the admissibility proofs.
ADMISSIBILITY_RTOL = 1e-9


def _kinds(first: str, count: int) -> np.ndarray:
    """0 (open) / 1 (closed) for phases ``0 … count-1`` starting with ``first``."""
    if first not in PHASES:
        raise ValueError(f"first must be 'open' or 'closed', got {first!r}")
    return (np.arange(count) + PHASES.index(first)) % 2


def _offset(system: MasslessSystem) -> np.ndarray:
    """``g = Φ_cᵀ M x_c``: closed coordinates are ``q_c = P q_o - g``."""
    c = system.closed
    return c.phi.T @ (system.M @ c.x_eq)


def _to(system: MasslessSystem, kind: int, Q: np.ndarray, V: np.ndarray, g: np.ndarray, affine: bool = True):
    """Coordinates of phase ``1 - kind`` from those of phase ``kind`` (the constant column moves with ``g``)."""
    P = system.transfer
    if kind == 0:
        Q = P @ Q
        if affine:
            Q[:, -1] -= g
        return Q, P @ V
    Q = Q.copy()
    if affine:
        Q[:, -1] += g
    return P.T @ Q, P.T @ V


def _rotate(omega: np.ndarray, tau: float, Q: np.ndarray, V: np.ndarray):
    c, s = np.cos(omega * tau)[:, None], np.sin(omega * tau)[:, None]
    w = omega[:, None]
    return c * Q + (s / w) * V, -(w * s) * Q + c * V


def solve_half(system: MasslessSystem, first: str, tau, gradient: bool = False):
    """``(a, r)`` or ``(a, r, J)``: the mid-phase amplitudes that end the half orbit at rest, the ``m`` switch
    residuals ``r_j = ŵᵀx(end of phase j) - d`` and their exact Jacobian ``J = dr/dτ`` (``m × (m+1)``).

    Non-finite ``r`` when ``V(τ)`` is singular (a linear resonance of the half orbit).
    """
    tau = np.asarray(tau, dtype=float)
    m = tau.size - 1
    kinds = _kinds(first, m + 1)
    ph = (system.open, system.closed)
    n, d, g = system.n, system.gap, _offset(system)
    Q, V = np.hstack([np.eye(n), np.zeros((n, 1))]), np.zeros((n, n + 1))
    rows, ends = [], []
    for i, t in enumerate(tau):
        p = ph[kinds[i]]
        Q, V = _rotate(p.omega, t, Q, V)
        ends.append((Q, V))
        if i < m:
            row = p.b @ Q
            row[-1] += p.y_eq - d
            rows.append(row)
            Q, V = _to(system, kinds[i], Q, V, g)
    try:
        lu = sla.lu_factor(V[:, :n], check_finite=False)
        a = sla.lu_solve(lu, -V[:, n], check_finite=False)
    except (ValueError, np.linalg.LinAlgError):
        a = np.full(n, np.nan)
    if not np.all(np.isfinite(a)):
        r = np.full(m, np.nan)
        return (a, r, np.full((m, m + 1), np.nan)) if gradient else (a, r)
    R = np.array(rows).reshape(m, n + 1)
    r = R[:, :n] @ a + R[:, n]
    if not gradient:
        return a, r
    # derivative of the end-of-phase states in τ_i at fixed a: the vector field, carried by later flights
    aa = np.append(a, 1.0)
    Dq, Dv = np.zeros((n, m + 1)), np.zeros((n, m + 1))
    Jfix = np.zeros((m, m + 1))
    for i in range(m + 1):
        p = ph[kinds[i]]
        if i > 0:
            Dq, Dv = _to(system, kinds[i - 1], Dq, Dv, g, affine=False)
            Dq, Dv = _rotate(p.omega, tau[i], Dq, Dv)
        Qi, Vi = ends[i]
        Dq[:, i], Dv[:, i] = Vi @ aa, -(p.omega**2) * (Qi @ aa)
        if i < m:
            Jfix[i] = p.b @ Dq
    da = -sla.lu_solve(lu, Dv, check_finite=False)
    return a, r, Jfix + R[:, :n] @ da


def _integral(y: TrigSum, tau: float, d: float) -> float:
    """``∫₀^τ (y - d) dt`` of a trigonometric sum (exact)."""
    om = y.omega
    safe = np.where(om > 0, om, 1.0)
    terms = np.where(om > 0, (y.alpha * np.sin(om * tau) + y.beta * (1 - np.cos(om * tau))) / safe, y.alpha * tau)
    return float((y.const - d) * tau + terms.sum())


@dataclass(frozen=True, eq=False)
class PhasedOrbit(BoundOrbit):
    """A symmetric periodic orbit of the massless model with ``m = len(durations) - 1`` contact phases.

    Time origin: the middle of phase 0 (``v = 0``); the orbit is even in time about ``t = 0`` and ``t = T/2``.
    Reads like the other orbit records (``T``, ``energy``, ``admissible``, ``state(t)``, ``impact_times`` — the
    closing instants in ``(0, T]`` — ``impulses`` — ``∫λ dt`` over each contact phase — ``to_dict``).
    Pickles without its system (:meth:`bind` re-attaches one).
    """

    system: MasslessSystem | None = field(repr=False)
    first: str
    durations: np.ndarray
    a: np.ndarray = field(repr=False)

    repeats = 1
    stable = None
    multipliers = None
    contact_model = "massless"

    def __post_init__(self) -> None:
        _kinds(self.first, 1)
        object.__setattr__(self, "durations", np.asarray(self.durations, dtype=float).reshape(-1))
        if self.durations.size < 2:
            raise ValueError(f"a phased orbit needs at least 2 half-phase durations, got {self.durations.size}")


    # -- shape of the orbit -----------------------------------------------------------------------------------

    @property
    def kinds(self) -> np.ndarray:
        """0 (open) / 1 (closed) of the half orbit's phases."""
        return _kinds(self.first, self.durations.size)

    @property
    def T(self) -> float:
        return 2.0 * float(self.durations.sum())

    @property
    def frequency(self) -> float:
        return 1.0 / self.T

    @property
    def k(self) -> int:
        """Contact phases per period."""
        return len(self.contact_intervals)

    @cached_property
    def segments(self) -> list[tuple[float, float, int]]:
        """``(start, stop, kind)`` of every phase over one period ``[0, T)`` — phase 0 split at ``t = 0``."""
        tau, kinds = self.durations, self.kinds
        m = tau.size - 1
        edges = np.concatenate([[0.0], np.cumsum(tau[:-1]), [tau.sum()]])
        half = [(edges[i], edges[i + 1], int(kinds[i])) for i in range(m + 1)]
        T = self.T
        mirror = [(T - b, T - a, k) for a, b, k in reversed(half)]
        merged = half[:-1] + [(half[-1][0], mirror[0][1], half[-1][2])] + mirror[1:]
        return merged

    @cached_property
    def contact_intervals(self) -> list[tuple[float, float]]:
        """``(closing, opening)`` of every contact phase, closing in ``[0, T)``; a phase across ``t = 0`` (mid
        phase 0 closed) is given as ``(T - τ₀, T + τ₀)``."""
        segs, T = self.segments, self.T
        out = [(a, b) for a, b, k in segs[1:-1] if k == 1]
        if segs[0][2] == 1:
            out.append((segs[-1][0], T + segs[0][1]))
        return sorted(out)

    @property
    def contact_time(self) -> float:
        """Total time in contact per period."""
        return float(sum(b - a for a, b in self.contact_intervals))

    @property
    def mid_open_time(self) -> float:
        """The middle of the first open phase of the period."""
        a, b, _ = next(seg for seg in self.segments if seg[2] == 0)
        return 0.5 * (a + b)

    def in_contact(self, t) -> np.ndarray:
        """Whether the contact is closed at times ``t``."""
        t = np.mod(np.atleast_1d(np.asarray(t, float)), self.T)
        out = np.zeros(t.shape, bool)
        for a, b in self.contact_intervals:
            out |= ((t >= a) & (t <= b)) | (t + self.T <= b)
        return out

    @property
    def impact_times(self) -> np.ndarray:
        """Closing instants of the contact phases in ``(0, T]``."""
        T = self.T
        return np.sort(np.array([a if a > 0 else T for a, _ in self.contact_intervals]))

    # -- states ------------------------------------------------------------------------------------------------

    @cached_property
    def _starts(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Interior ``(x, v)`` at the start of each half-orbit phase."""
        s = self._bound()
        ph = (s.open, s.closed)
        k0 = ph[self.kinds[0]]
        x, v = k0.x_eq + k0.phi @ self.a, np.zeros(s.n)
        out = []
        for i, t in enumerate(self.durations):
            out.append((x, v))
            x, v = ph[self.kinds[i]].advance(x, v, t)
        out.append((x, v))
        return out

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` at times ``t`` (``t = 0``: middle of phase 0), each ``(n, len(t))``."""
        s = self._bound()
        ph = (s.open, s.closed)
        T, half = self.T, 0.5 * self.T
        t = np.mod(np.atleast_1d(np.asarray(t, float)), T)
        sign = np.where(t > half, -1.0, 1.0)
        t = np.where(t > half, T - t, t)
        edges = np.concatenate([[0.0], np.cumsum(self.durations)])
        idx = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, self.durations.size - 1)
        X, V = np.empty((s.n, t.size)), np.empty((s.n, t.size))
        flights = {}  # each phase's flight from its start, its modal coordinates computed once
        for j, (tj, i) in enumerate(zip(t, idx)):
            if i not in flights:
                flights[i] = ph[self.kinds[i]].flight(*self._starts[i])
            X[:, j], V[:, j] = flights[i](tj - edges[i])
        return X, V * sign

    @cached_property
    def energy(self) -> float:
        x, v = self._starts[0]
        return self._bound().energy(x, v)

    def band_energy(self, modes: int) -> float:
        """Energy held by the lowest ``modes`` open-phase modes at ``t = 0`` (``v = 0``): ``½ Σ ω_j² q_j²``."""
        if isinstance(modes, bool) or int(modes) < 1:
            raise ValueError(f"modes must be an integer >= 1, got {modes!r}")
        s = self._bound()
        q = s.open.phi.T @ (s.M @ self._starts[0][0])
        return float(0.5 * np.sum((s.open.omega[: int(modes)] * q[: int(modes)]) ** 2))

    def _signal(self, i: int) -> tuple[Phase, TrigSum]:
        s = self._bound()
        p = (s.open, s.closed)[self.kinds[i]]
        return p, p.contact(*self._starts[i])

    @cached_property
    def impulses(self) -> np.ndarray:
        """``∫λ dt`` over each contact phase, in the order of :attr:`impact_times`."""
        s = self._bound()
        m = self.durations.size - 1
        half = [s.kc * _integral(self._signal(i)[1], self.durations[i], s.gap) if self.kinds[i] == 1 else 0.0
                for i in range(m + 1)]
        # segments: phase 0 (forward half), 1 … m-1, phase m (both halves), m-1 … 1, phase 0 (second half)
        per_segment = half[:m] + [2 * half[m]] + half[m - 1::-1]
        segs, out = self.segments, []
        for (a, _, kind), value in zip(segs[1:-1], per_segment[1:-1]):
            if kind == 1:
                out.append((a, value))
        if segs[0][2] == 1:
            out.append((segs[-1][0], 2 * half[0]))
        return np.array([v for _, v in sorted(out)])

    # -- admissibility ---------------------------------------------------------------------------------------

    @cached_property
    def proofs(self) -> list:
        """Certified ``max(y - d)`` over each open half-orbit phase and ``max(d - y)`` over each closed one."""
        s = self._bound()
        tol = ADMISSIBILITY_RTOL * s.gap
        out = []
        for i, t in enumerate(self.durations):
            _, y = self._signal(i)
            sign = 1.0 if self.kinds[i] == 0 else -1.0
            out.append(certified_max(TrigSum(sign * y.alpha, sign * y.beta, y.omega, sign * (y.const - s.gap)),
                                     float(t), tol))
        return out

    @property
    def admissible(self) -> bool:
        return all(p.certified for p in self.proofs)

    @property
    def max_violation(self) -> float:
        """Largest ``y - d`` over the open phases (``<= 0`` up to the tolerance when admissible)."""
        vals = [p.value for p, k in zip(self.proofs, self.kinds) if k == 0]
        return float(max(vals)) if vals else 0.0

    # -- stability ---------------------------------------------------------------------------------------------

    def monodromy(self) -> np.ndarray:
        """``(2n, 2n)`` monodromy of ``(x, v)`` from ``t = 0`` over one period (saltation matrices: identity)."""
        s = self._bound()
        ph = (s.open, s.closed)
        tau, kinds = self.durations, self.kinds
        m = tau.size - 1
        seq = [(kinds[i], tau[i]) for i in range(m)] + [(kinds[m], 2 * tau[m])] + \
              [(kinds[i], tau[i]) for i in range(m - 1, -1, -1)]
        out = np.eye(2 * s.n)
        for kind, t in seq:
            out = _flight_matrix(ph[kind], t) @ out
        return out

    # -- records -----------------------------------------------------------------------------------------------

    def to_dict(self) -> dict:
        """Plain-data record (JSON-ready); :meth:`from_dict` reads it back."""
        return {"T": self.T, "frequency": self.frequency, "ipp": self.k, "contact_model": "massless",
                "first": self.first, "durations": self.durations.tolist(), "a": self.a.tolist(),
                "contact_time": self.contact_time, "contact_intervals": [list(c) for c in self.contact_intervals],
                "impact_times": self.impact_times.tolist(), "impulses": self.impulses.tolist(),
                "energy": self.energy, "admissible": self.admissible, "max_violation": self.max_violation,
                "repeats": 1, "stable": None, "multipliers": None}

    @classmethod
    def from_dict(cls, system: MasslessSystem | None, data: dict) -> PhasedOrbit:
        return cls(system, str(data["first"]), np.asarray(data["durations"], float), np.asarray(data["a"], float))


def _flight_matrix(p: Phase, t: float) -> np.ndarray:
    """Linear part of the flight ``(x, v) -> (x, v)`` over ``t`` in phase ``p``."""
    c, s, w = np.cos(p.omega * t), np.sin(p.omega * t), p.omega
    PhiTM = p.phi.T @ p.M
    return np.block([[p.phi @ (c[:, None] * PhiTM), p.phi @ ((s / w)[:, None] * PhiTM)],
                     [p.phi @ ((-w * s)[:, None] * PhiTM), p.phi @ (c[:, None] * PhiTM)]])


def violation(orbit: PhasedOrbit) -> tuple[int, float] | None:
    """``(i, t)``: the first half-orbit phase whose admissibility is not proved and where its violation is largest
    (time from the phase's start); ``None`` for an admissible orbit."""
    for i, proof in enumerate(orbit.proofs):
        if not proof.certified:
            return i, float(proof.where)
    return None


def split_at(first: str, tau, i: int, t: float, rtol: float = 1e-6) -> tuple[str, np.ndarray, int]:
    """The phase pattern with a phase of the other kind and ZERO duration inserted in half phase ``i`` at time
    ``t`` from its start: ``(first, durations, index of the inserted phase)``.

    At an admissibility boundary (``λ`` or ``d - ŵᵀx`` touching 0 at ``t``) the boundary orbit solves the new
    pattern's equations exactly; beyond it the inserted phase lengthens.  A touch at a symmetric instant (``t = 0``
    of phase 0, ``t = τ_m`` of the last) inserts a half phase there; elsewhere the phase splits in three.

    >>> split_at("open", [1.0, 0.5], 1, 0.5)       # λ touches 0 in the middle of the contact: it opens there
    ('open', array([1. , 0.5, 0. ]), 2)
    >>> split_at("open", [1.0, 0.5], 0, 0.4)       # the open phase touches the casing at 0.4: a new contact
    ('open', array([0.4, 0. , 0.6, 0.5]), 1)
    """
    tau = np.asarray(tau, dtype=float)
    m = tau.size - 1
    kinds = _kinds(first, m + 1)
    if i == 0 and t <= rtol * tau[0]:
        return PHASES[1 - kinds[0]], np.concatenate([[0.0], tau]), 0
    if i == m and t >= (1 - rtol) * tau[m]:
        return first, np.concatenate([tau, [0.0]]), m + 1
    t = min(max(t, 0.0), float(tau[i]))
    return first, np.concatenate([tau[:i], [t, 0.0, tau[i] - t], tau[i + 1:]]), i + 1
