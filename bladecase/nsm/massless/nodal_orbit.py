"""The flow of the massless model with one contact per node over a period, with its exact Jacobian
(:func:`flow_map`), and the periodic orbits it closes (:class:`NodalOrbit`: phases, forces, peaks, Floquet
multipliers). How orbits are found and followed: :mod:`bladecase.nsm.massless.nodal_modes`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from ..floquet import split_trivial
from .nodes import NodalFlight, NodalSystem, lcp, simulate_nodes

__all__ = ["FLOQUET_TOL", "MAX_PHASES", "NodalOrbit", "flow_map"]

#: Most phases in one period's flow (a Newton iterate that chatters beyond is refused: the step fails).
MAX_PHASES = 4000

#: Trivial multipliers within ``FLOQUET_TOL·‖monodromy‖`` of 1; stable when every other ``|μ| <= 1 + FLOQUET_TOL``.
FLOQUET_TOL = 1e-6


# ----------------------------------------------------------------------------- the flow and its Jacobian


class _Shooter:
    """The exact flow of one :class:`NodalSystem` in modal coordinates, with its Jacobian (cached phase modes)."""

    def __init__(self, system: NodalSystem, max_phases: int | None = None):
        if not isinstance(system, NodalSystem):
            raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
        self.system = system
        self.max_phases = MAX_PHASES if max_phases is None else int(max_phases)
        self.flight = NodalFlight(system)
        self.omega = self.flight.omega
        self.Wq = self.flight.Wq
        self.n, self.m = system.n, system.m
        self._modes: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def modes(self, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Ψ, ω)`` of the phase with the closed set ``A``: ``Ω² + W_A H_AA⁻¹ W_Aᵀ = Ψ ω² Ψᵀ``."""
        key = np.packbits(A).tobytes()
        out = self._modes.get(key)
        if out is None:
            K = np.diag(self.omega**2)
            idx = np.flatnonzero(A)
            if idx.size:
                WA = self.Wq[:, idx]
                K = K + WA @ np.linalg.solve(self.system.H[np.ix_(idx, idx)], WA.T)
            lam2, psi = np.linalg.eigh(0.5 * (K + K.T))
            out = self._modes[key] = (psi, np.sqrt(lam2))
        return out

    def forces(self, q: np.ndarray) -> np.ndarray:
        return lcp(self.system.gap - self.Wq.T @ q, self.system.H)

    def field(self, q: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The vector field ``(q', p') = (p, −Ω²q − W λ(q))``."""
        return p, -self.omega**2 * q - self.Wq @ self.forces(q)

    def energy(self, q: np.ndarray, p: np.ndarray) -> float:
        lam = self.forces(q)
        return float(0.5 * p @ p + 0.5 * np.sum((self.omega * q) ** 2) + 0.5 * lam @ self.system.H @ lam)

    def energy_gradient(self, q: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``∂E/∂q = Ω²q + Wλ(q)``, ``∂E/∂p = p``."""
        return self.omega**2 * q + self.Wq @ self.forces(q), p

    def flow(self, q0, p0, T: float, jacobian: bool = True) -> _Flow:
        """The exact flow over ``[0, T]`` from ``(q₀, p₀)`` by :func:`simulate_nodes`, and its Jacobian."""
        fl = self.flight
        tr = simulate_nodes(self.system, *fl.decode(q0, p0), T, flight=fl, max_switches=self.max_phases)
        if not tr.complete:
            raise ValueError(f"the flow over T = {T:.9g} s needs more than {self.max_phases} phases "
                             "(max_phases): chattering far from a periodic orbit")
        starts, active = tr.starts, tr.active
        ph = fl.phase(active[-1])
        a = ph.amplitudes(tr.q[:, -1], tr.p[:, -1], starts[-1])
        qT, pT = ph.advance(a, starts[-1], T - starts[-1])
        J = self.transition(starts, active, T) if jacobian else None
        return _Flow(np.asarray(q0, float), np.asarray(p0, float), float(T), starts, active, tr.q, tr.p, qT, pT, J)

    def transition(self, starts: np.ndarray, active: np.ndarray, T: float) -> np.ndarray:
        """The product of the phases' state-transition matrices in ``(q, p)`` (saltation matrices: identity)."""
        n = self.n
        J = np.eye(2 * n)
        tau = np.diff(np.r_[starts, T])
        for A, t in zip(active, tau):
            psi, w = self.modes(A)
            c, s = np.cos(w * t)[:, None], np.sin(w * t)[:, None]
            X, Y = psi.T @ J[:n], psi.T @ J[n:]
            J = np.vstack([psi @ (c * X + (s / w[:, None]) * Y), psi @ (-(w[:, None] * s) * X + c * Y)])
        return J


@dataclass(frozen=True, eq=False)
class _Flow:
    q0: np.ndarray
    p0: np.ndarray
    T: float
    starts: np.ndarray
    active: np.ndarray
    q: np.ndarray
    p: np.ndarray
    qT: np.ndarray
    pT: np.ndarray
    J: np.ndarray | None


def flow_map(system: NodalSystem, q0, p0, T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q_T, p_T, J)``: the exact flow of ``system`` over ``T`` from the modal state ``(q₀, p₀)`` and its
    Jacobian ``∂(q_T, p_T)/∂(q₀, p₀)`` (the product of the phases' state-transition matrices).

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])   # bilinear oscillator
    >>> qT, pT, J = flow_map(s, [-2.0], [0.0], 2.0)
    >>> bool(abs(np.linalg.det(J) - 1) < 1e-12)                                   # symplectic
    True
    """
    f = _Shooter(system).flow(np.asarray(q0, float), np.asarray(p0, float), float(T))
    return f.qT, f.pT, f.J


# ----------------------------------------------------------------------------- orbits


@dataclass(frozen=True, eq=False)
class NodalOrbit:
    """A periodic orbit of a :class:`NodalSystem`: its state at ``t = 0``, period, phases and monodromy.

    Attributes
    ----------
    system : NodalSystem
    T : float
        Period (s).
    q0, p0 : (n,) ndarray
        State at ``t = 0`` in the open-phase modal coordinates (``x = Φq``).
    starts : (k,) ndarray
        Start time of each phase in ``[0, T)``.
    active : (k, m) bool ndarray
        The closed contacts of each phase.
    monodromy : (2n, 2n) ndarray
        ``∂Φ_T/∂(q₀, p₀)``.
    residual : float
        Closing residual ``‖Φ_T(z₀) − z₀‖/‖z₀‖`` in the energy norm ``‖(Ωq, p)‖``.
    mode : int
        The open-phase mode of the phase condition (``p₀[mode] = 0``).
    """

    system: NodalSystem
    T: float
    q0: np.ndarray
    p0: np.ndarray
    starts: np.ndarray = field(repr=False)
    active: np.ndarray = field(repr=False)
    q_starts: np.ndarray = field(repr=False)
    p_starts: np.ndarray = field(repr=False)
    monodromy: np.ndarray = field(repr=False)
    residual: float
    mode: int = 0
    _shooter: _Shooter = field(default=None, repr=False, compare=False)  # type: ignore[assignment]

    @classmethod
    def _of(cls, sh: _Shooter, f: _Flow, mode: int) -> NodalOrbit:
        om = sh.omega
        size = np.sqrt(np.sum((om * f.q0) ** 2) + f.p0 @ f.p0)
        res = np.sqrt(np.sum((om * (f.qT - f.q0)) ** 2) + np.sum((f.pT - f.p0) ** 2)) / max(size, 1e-300)
        return cls(sh.system, f.T, f.q0, f.p0, f.starts, f.active, f.q, f.p, f.J, float(res), mode, sh)

    # -- basic figures -----------------------------------------------------------------------------------------

    @property
    def frequency(self) -> float:
        """Hz."""
        return 1.0 / self.T

    @cached_property
    def energy(self) -> float:
        """``½vᵀMv + ½xᵀSx + ½λᵀHλ`` (J)."""
        return self._shooter.energy(self.q0, self.p0)

    @property
    def x0(self) -> np.ndarray:
        return self._shooter.flight.phi @ self.q0

    @property
    def v0(self) -> np.ndarray:
        return self._shooter.flight.phi @ self.p0

    @property
    def modal_energy_share(self) -> np.ndarray:
        """Each open-phase mode's share of ``Σ ½(ω_j²q_j² + p_j²)`` at ``t = 0``, ``(n,)``."""
        e = (self._shooter.omega * self.q0) ** 2 + self.p0**2
        return e / e.sum()

    @cached_property
    def durations(self) -> np.ndarray:
        return np.diff(np.r_[self.starts, self.T])

    @cached_property
    def contact_fraction(self) -> np.ndarray:
        """Fraction of the period each contact is closed, ``(m,)``."""
        return (self.durations @ self.active) / self.T

    @property
    def touching(self) -> np.ndarray:
        """The contacts closed during some phase, ``(m,)`` bool."""
        return self.active.any(axis=0)

    @property
    def touching_nodes(self) -> tuple:
        """Labels (:attr:`NodalSystem.nodes`) of the touching contacts."""
        return tuple(self.system.nodes[j] for j in np.flatnonzero(self.touching))

    @property
    def sequence(self) -> tuple[tuple[int, ...], ...]:
        """The phase sequence from ``t = 0``: the closed contacts' indices of each phase."""
        return tuple(tuple(int(j) for j in np.flatnonzero(A)) for A in self.active)

    # -- along the orbit ---------------------------------------------------------------------------------------

    def _phase_data(self):
        fl = self._shooter.flight
        for i, (A, t0, tau) in enumerate(zip(self.active, self.starts, self.durations)):
            ph = fl.phase(A)
            a = ph.amplitudes(self.q_starts[:, i], self.p_starts[:, i], t0)
            yield i, A, t0, tau, ph, a

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` at the times ``t`` (taken modulo ``T``), ``(n, k)`` each."""
        t = np.mod(np.atleast_1d(np.asarray(t, dtype=float)), self.T)
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        Q, P = np.empty((self.system.n, t.size)), np.empty((self.system.n, t.size))
        for i, _, t0, _, ph, a in self._phase_data():
            sel = np.flatnonzero(k == i)
            if sel.size:
                Q[:, sel], P[:, sel] = ph.advance(a, t0, t[sel] - t0)
        return self._shooter.flight.decode(Q, P)

    def forces(self, t) -> np.ndarray:
        """Contact forces ``(m, k)`` at the times ``t``."""
        return self.system.forces(self.state(t)[0])

    @cached_property
    def _peaks(self) -> tuple[np.ndarray, np.ndarray]:
        """``(peak λ_j, peak e_j)`` over the period, ``e_j = u_j − d_j`` the node's normal displacement beyond its
        clearance (``−s_j`` while open, ``λ_j/k_j`` while closed), from the phases' switching signals.

        Each phase is sampled on a grid of 16 points per effective period (at least 9 points); a grid value
        can miss the maximum between its neighbours by at most ``B₂h²/8`` (``B₂`` the signal's bound on its
        second derivative), so every grid point within that of the best one is polished (nested grids between
        its neighbours, :func:`_polish`).
        """
        m = self.system.m
        k_inv = 1.0 / self.system.casing
        data = []
        best = {True: np.full(m, -np.inf), False: np.full(m, -np.inf)}
        for _, A, t0, tau, ph, a in self._phase_data():
            sig = ph.signals(a, t0)
            h = min(sig.step / 4, tau / 8) if np.isfinite(sig.step) else tau / 8
            grid = np.linspace(0.0, tau, int(min(np.ceil(tau / h), 20000)) + 1)
            F = sig.value(grid)
            F = np.where(A[None, :], F, -F)  # λ_j while closed, −s_j while open
            slack = sig.bound * (grid[1] - grid[0]) ** 2 / 8
            data.append((A, sig, grid, F, slack))
            top = F.max(axis=0)
            for closed in (True, False):
                cols = A == closed
                best[closed] = np.where(cols, np.maximum(best[closed], top), best[closed])
        out = {True: best[True].copy(), False: best[False].copy()}
        for A, sig, grid, F, slack in data:
            for closed, sign in ((True, 1.0), (False, -1.0)):
                for j in np.flatnonzero(A == closed):
                    for i in np.flatnonzero(F[:, j] + slack[j] >= best[closed][j]):
                        out[closed][j] = max(out[closed][j], _polish(sig, grid, int(i), sign * _unit(m, j))[0])
        lam = np.maximum(out[True], 0.0)
        closed = np.isfinite(out[True])
        e = np.maximum(np.where(closed, np.where(closed, out[True], 0.0) * k_inv, -np.inf), out[False])
        return lam, e

    @property
    def peak_force(self) -> np.ndarray:
        """Largest contact force on each node over the period (N), ``(m,)``."""
        return self._peaks[0]

    @cached_property
    def _total_peak(self) -> tuple[float, float]:
        """``(peak Σ_j λ_j, its instant)`` over the period, from the closed phases' force signals: each phase sampled
        as in :attr:`_peaks`, the grid points within ``(Σ_{j∈A} B₂_j)h²/8`` of the best polished (:func:`_polish`);
        ``(0, 0)`` when no node touches."""
        best, when = 0.0, 0.0
        for _, A, t0, tau, ph, a in self._phase_data():
            if not A.any():
                continue
            sig = ph.signals(a, t0)
            h = min(sig.step / 4, tau / 8) if np.isfinite(sig.step) else tau / 8
            grid = np.linspace(0.0, tau, int(min(np.ceil(tau / h), 20000)) + 1)
            w = A.astype(float)  # the closed nodes' signals are their forces
            F = sig.value(grid) @ w
            slack = float(sig.bound @ w) * (grid[1] - grid[0]) ** 2 / 8
            for i in np.flatnonzero(F + slack >= max(F.max(), best)):
                value, at = _polish(sig, grid, int(i), w)
                if value > best:
                    best, when = value, t0 + at
        return best, when

    @property
    def total_force(self) -> float:
        """Largest total contact force over the period, ``max_t Σ_j λ_j(t)`` (N): the casing's whole load on the
        face, which converges under mesh refinement where a node's share does not."""
        return self._total_peak[0]

    @property
    def total_force_time(self) -> float:
        """The instant of :attr:`total_force` in ``[0, T)`` (s; 0 when no node touches)."""
        return self._total_peak[1]

    def loaded_area(self, areas) -> float:
        """The largest area in contact over the period, ``max over the phases of Σ_{j closed} A_j``, for the nodes'
        tributary ``areas`` ``(m,)`` (exact: a closed node carries a positive force inside its phase)."""
        a = np.asarray(areas, dtype=float)
        if a.shape != (self.system.m,):
            raise ValueError(f"areas must hold one value per contact node ({self.system.m}), got shape {a.shape}")
        return float((self.active @ a).max(initial=0.0))

    @property
    def peak_displacement(self) -> np.ndarray:
        """Largest normal displacement of each contact node over the period (m): ``d_j + λ_j/k_j`` at its peak
        force when it touches, ``d_j − min s_j`` when it does not."""
        return self.system.gap + self._peaks[1]

    @property
    def penetration(self) -> np.ndarray:
        """Largest displacement of each node beyond its clearance (the casing's yield ``λ_j/k_j``), ``(m,)``."""
        return np.maximum(self._peaks[1], 0.0)

    @property
    def max_tip(self) -> float:
        """Largest normal displacement over the contact nodes and the period (m)."""
        return float(self.peak_displacement.max())

    # -- stability ---------------------------------------------------------------------------------------------

    @cached_property
    def _floquet(self) -> tuple[np.ndarray, tuple[int, int], np.ndarray]:
        sh = self._shooter
        om = sh.omega
        D = np.r_[om, np.ones(sh.n)]
        Y = (D[:, None] * self.monodromy) / D[None, :]  # in the energy coordinates (Ωq, p)
        fq, fp = sh.field(self.q0, self.p0)
        gq, gp = sh.energy_gradient(self.q0, self.p0)
        a, c, B = _deflate(Y, np.r_[om * fq, fp], np.r_[gq / om, gp])
        values = np.r_[np.array([a, c], complex), np.linalg.eigvals(B).astype(complex)]
        order = np.lexsort((-values.imag, np.abs(np.angle(values)), -np.round(np.abs(values), 12)))
        values = values[order]
        trivial = tuple(sorted(int(np.flatnonzero(order == i)[0]) for i in (0, 1)))
        return values, trivial, Y

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers: the two trivial ones (time shift, energy direction; split off exactly) first,
        then the others by modulus, descending."""
        values, trivial, _ = self._floquet
        return np.r_[values[list(trivial)], np.delete(values, list(trivial))]

    @property
    def nontrivial_multipliers(self) -> np.ndarray:
        return self.multipliers[2:]

    @property
    def max_modulus(self) -> float:
        """Largest ``|μ|`` of the non-trivial multipliers (NaN with one dof)."""
        mu = self.nontrivial_multipliers
        return float(np.abs(mu).max()) if mu.size else float("nan")

    def stable(self, tol: float = FLOQUET_TOL) -> bool:
        """Every non-trivial ``|μ| <= 1 + tol`` (linear stability)."""
        mu = self.nontrivial_multipliers
        return bool(mu.size == 0 or np.abs(mu).max() <= 1 + tol)

    def monodromy_xv(self) -> np.ndarray:
        """The monodromy in the interior ``(x, v)``."""
        phi, M = self._shooter.flight.phi, self.system.M
        return sla.block_diag(phi, phi) @ self.monodromy @ sla.block_diag(phi.T @ M, phi.T @ M)

    def to_dict(self) -> dict:
        """Plain-data record (JSON-ready)."""
        return {"T": self.T, "frequency": self.frequency, "energy": self.energy, "residual": self.residual,
                "mode": self.mode, "q0": self.q0.tolist(), "p0": self.p0.tolist(),
                "nodes": list(self.system.nodes), "touching": self.touching.tolist(),
                "contact_fraction": self.contact_fraction.tolist(), "peak_force": self.peak_force.tolist(),
                "total_force": self.total_force, "total_force_time": self.total_force_time,
                "peak_displacement": self.peak_displacement.tolist(), "max_tip": self.max_tip,
                "sequence": [list(s) for s in self.sequence], "starts": self.starts.tolist(),
                "multipliers": [[float(z.real), float(z.imag)] for z in self.multipliers],
                "stable": self.stable()}

    def __repr__(self) -> str:
        return (f"NodalOrbit(T={self.T:.9g}, f={self.frequency:.6g} Hz, E={self.energy:.4g} J, "
                f"{int(self.touching.sum())}/{self.system.m} nodes touch, {self.starts.size} phases, "
                f"residual {self.residual:.1e})")


def _unit(m: int, j: int) -> np.ndarray:
    e = np.zeros(m)
    e[j] = 1.0
    return e


_NINE = np.arange(9.0)


def _polish(sig, grid: np.ndarray, i: int, w: np.ndarray) -> tuple[float, float]:
    """The largest ``Σ_j w_j f_j`` between ``grid[i − 1]`` and ``grid[i + 1]`` and where (``(value, τ)``): nested
    grids of 9 points, each spanning the best point's two neighbours on the previous one (shrinking 4-fold), down
    to round-off (a derivative root would pick a local minimum where two maxima flank it). ``w = ±e_j``: one signal
    (or its opposite); ``w`` the closed set's indicator: the total force."""
    lo, hi = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, grid.size - 1)])
    best, where = -np.inf, lo
    for _ in range(40):
        ts = _NINE * ((hi - lo) / 8) + lo  # np.linspace(lo, hi, 9), the same arithmetic without its overhead
        ts[-1] = hi
        vals = sig.value(ts) @ w
        k = int(np.argmax(vals))
        if vals[k] > best:
            best, where = float(vals[k]), float(ts[k])
        if hi - lo <= 4 * np.finfo(float).eps * max(abs(hi), abs(lo), np.finfo(float).tiny):
            break
        lo, hi = float(ts[max(k - 1, 0)]), float(ts[min(k + 1, 8)])
    return best, where


def _deflate(Y: np.ndarray, f: np.ndarray, e: np.ndarray) -> tuple[float, float, np.ndarray]:
    """Trivial multipliers ``(a, c)`` (flow and energy directions) and the non-trivial block of ``Y``
    (:func:`bladecase.nsm.floquet.split_trivial`, unchecked: the caller reports them)."""
    B = split_trivial(Y, f, e)
    return float(B[0, 0]), float(B[-1, -1]), B[1:-1, 1:-1]
