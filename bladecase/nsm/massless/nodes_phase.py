"""One phase of the every-node massless contact model (:mod:`bladecase.nsm.massless.nodes`): a set ``A`` of closed
contacts, flown in closed form in the open-phase modal coordinates.

Everything a phase needs from the closed contacts' block of the flexibility, ``G_A = H_AA⁻¹``, is ``G_A`` applied to
``n + 1`` (``n + 3`` with an out-of-round casing) columns — the closed nodes' modal rows ``W_Aᵀ``, their clearances
``g_A`` and the casing's complex amplitudes ``D_A`` —: one Cholesky factorisation of ``H_AA`` and one solve with
those columns, never the inverse, and never the ``m × m`` clearance matrix of the switching signals (both are made
again when asked: :attr:`_Phase.G`, :attr:`_Phase.P`). With ``m`` contact nodes of which ``a`` are closed a phase
costs ``a³/3 + m·a·n`` operations and keeps ``m·n`` numbers, where the inverse and the clearance matrix cost
``a³ + m²·a`` and kept ``m²``; the phases are cached by :class:`~bladecase.nsm.massless.nodes.NodalFlight`, the
least recently used dropped past :data:`PHASE_CACHE` (a dropped phase is made again, the same numbers bit for bit).
"""

from __future__ import annotations

import copy

import numpy as np
import scipy.linalg as sla

from .nodal_switches import _Signals

__all__ = ["EIGVEC_COND_LIMIT", "PHASE_CACHE", "phase_signals"]

#: Largest condition number of a damped phase's state-space eigenvectors (near-defective: refused).
EIGVEC_COND_LIMIT = 1e10

#: Phases a flight keeps (the least recently used dropped past it): a rub of 134 nodes can make a new set of closed
#: contacts at most of its switches, each phase some 70 kB with 8 modes (at most about 300 MB kept).
PHASE_CACHE = 4096


def phase_signals(Wq: np.ndarray, H: np.ndarray, A: np.ndarray, G: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The switching signals ``L q + P g(t)`` of the phase whose closed contacts are ``A`` (a boolean mask):
    the closed contacts' forces ``G (W_Aᵀ q − g_A)`` and the open ones' gaps, with ``G`` the inverse of ``H`` on
    ``A`` (``None`` when no contact is closed: the gaps ``g − Wᵀq`` alone). The same signals whether the phase is
    symmetric or, with friction, not (its stiffness differs, not its signals).

    >>> L, P = phase_signals(np.eye(2), 0.5 * np.eye(2), np.array([True, False]), np.array([[2.0]]))
    >>> (L + 0.0).tolist(), (P + 0.0).tolist()   # node 0 closed: its force 2(q₀ − g₀); node 1 open: g₁ − q₁
    ([[2.0, 0.0], [0.0, -1.0]], [[-2.0, 0.0], [0.0, 1.0]])
    """
    m = Wq.shape[1]
    L, P = -Wq.T.copy(), np.eye(m)
    idx = np.flatnonzero(A)
    if idx.size:
        WA = Wq[:, idx]
        L[idx] = G @ WA.T
        P[idx] = 0.0
        P[np.ix_(idx, idx)] = -G
        out = np.flatnonzero(~A)
        HG = H[np.ix_(out, idx)] @ G
        L[out] = -Wq[:, out].T + HG @ WA.T
        P[np.ix_(out, idx)] = -HG
    return L, P


class _Phase:
    """One set ``A`` of closed contacts, in the open-phase modal coordinates ``(q, p)`` (``M = I``).

    ``q(t₀+τ) = q_p(t₀+τ) + Re(Vx (a ∘ e^{Λτ}))`` with ``a`` the complex amplitudes of the homogeneous part and
    ``q_p(t) = q_eq + Re(X e^{iνt})`` the phase's particular solution. The closed contacts' forces are
    ``λ_A = GWt q − (Y_g + Re(Y_D e^{iνt}))`` with ``Y_g = G_A g_A``, ``Y_D = G_A D_A`` (module docstring).
    """

    # a phase with friction sets its own G, P, eq_map and K (its flexibility is not symmetric)
    _G = _P = _eq_map = _Yg = _YD = _fl = K = None

    def __init__(self, fl, A: np.ndarray):
        s = fl.system
        self.A, self._fl = A, fl
        m, n = s.m, fl.n
        Wq, H = fl.Wq, s.H
        idx = np.flatnonzero(A)
        self.idx = idx
        nu, D = fl.nu, fl.D
        forced = nu > 0 and D is not None
        K = np.diag(fl.omega**2)
        PD = D
        if idx.size:
            out = np.flatnonzero(~A)
            WA = Wq[:, idx]
            cols = [WA.T, s.gap[idx, None]] + ([D[idx].real[:, None], D[idx].imag[:, None]] if forced else [])
            try:
                chol = sla.cho_factor(H[np.ix_(idx, idx)], lower=True, check_finite=False)
            except np.linalg.LinAlgError:
                raise ValueError("the closed contacts' flexibility is not positive definite") from None
            Y = sla.cho_solve(chol, np.hstack(cols), check_finite=False)
            GWt, Yg = Y[:, :n], Y[:, n]
            K = K + WA @ GWt
            K = 0.5 * (K + K.T)
            Hoa = H[np.ix_(out, idx)]
            L = np.empty((m, n))
            L[idx] = GWt
            L[out] = Hoa @ GWt - Wq[:, out].T
            Pg = np.empty(m)
            Pg[idx] = -Yg
            Pg[out] = s.gap[out] - Hoa @ Yg
            self.q_eq = np.linalg.solve(K, WA @ Yg)
            if forced:
                YD = Y[:, n + 1] + 1j * Y[:, n + 2]
                PD = np.empty(m, complex)
                PD[idx] = -YD
                PD[out] = D[out] - Hoa @ YD
                self._YD = YD
            self._Yg = Yg
        else:
            GWt, L, Pg = np.zeros((0, n)), -Wq.T, s.gap
            self.q_eq = np.zeros(n)
        self.GWt, self.L, self.K = GWt, L, K
        self.X = np.zeros(n, complex)
        if idx.size and forced:
            Z = K - nu**2 * np.eye(n) + (1j * nu * fl.Cq if fl.Cq is not None else 0)
            try:
                self.X = np.linalg.solve(Z, WA @ self._YD)
            except np.linalg.LinAlgError:
                raise ValueError(f"the casing's excitation at {nu / 2 / np.pi:.6g} Hz is at an undamped resonance "
                                 "of a contact phase: add damping or change the speed") from None
        self._modes(K, fl.Cq, n)
        self.LVx = L @ self.Vx
        self.nu = nu
        self.const = L @ self.q_eq + Pg
        self.E0 = (L @ self.X + (PD if D is not None else 0)) if nu > 0 else np.zeros(m, complex)
        self.lam2 = np.abs(self.lam) ** 2

    def _modes(self, K: np.ndarray, Cq: np.ndarray | None, n: int) -> None:
        """The phase's modes: undamped, its own (``eigh``); damped, the state-space eigenvectors."""
        if Cq is None:
            lam2, psi = np.linalg.eigh(K)
            if lam2.min() <= 0:
                raise ValueError("a contact phase's stiffness is not positive definite")
            w = np.sqrt(lam2)
            self.lam = 1j * w
            self.Vx, self.Vv = psi.astype(complex), psi * (1j * w)
            self._psi, self._w = psi, w
            return
        Ass = np.zeros((2 * n, 2 * n))
        Ass[:n, n:] = np.eye(n)
        Ass[n:, :n], Ass[n:, n:] = -K, -Cq
        lam, V = np.linalg.eig(Ass)
        self._lu = sla.lu_factor(V, check_finite=False)
        rcond = sla.lapack.zgecon(self._lu[0], np.abs(V).sum(axis=0).max())[0]
        if not rcond * EIGVEC_COND_LIMIT > 1:
            raise ValueError("a damped contact phase is nearly defective (critically damped mode): change the "
                             "damping slightly")
        self.lam, self.Vx, self.Vv = np.minimum(lam.real, 0.0) + 1j * lam.imag, V[:n], V[n:]
        self._Vinv = sla.lu_solve(self._lu, np.eye(2 * n, dtype=complex), check_finite=False)
        self._psi = None

    @property
    def G(self) -> np.ndarray:
        """``H_AA⁻¹`` (made when asked: a phase keeps its products only, module docstring)."""
        if self._G is not None:
            return self._G
        if not self.idx.size:
            return np.zeros((0, 0))
        G = np.linalg.inv(self._fl.system.H[np.ix_(self.idx, self.idx)])
        return 0.5 * (G + G.T)

    @G.setter
    def G(self, value: np.ndarray) -> None:
        self._G = value

    @property
    def P(self) -> np.ndarray:
        """The switching signals' clearance matrix (``L q + P g(t)``, :func:`phase_signals`), made when asked."""
        if self._P is not None:
            return self._P
        return phase_signals(self._fl.Wq, self._fl.system.H, self.A, self.G if self.idx.size else None)[1]

    @P.setter
    def P(self, value: np.ndarray) -> None:
        self._P = value

    @property
    def eq_map(self) -> np.ndarray:
        """The equilibrium's displacement per unit widening of the closed contacts' clearances (``n × a``)."""
        if self._eq_map is not None:
            return self._eq_map
        if not self.idx.size:
            return np.zeros((self.q_eq.size, 0))
        return np.linalg.solve(self.K, self._fl.Wq[:, self.idx] @ self.G)

    @eq_map.setter
    def eq_map(self, value: np.ndarray) -> None:
        self._eq_map = value

    def closed_forces(self, Q: np.ndarray, t: np.ndarray, gap) -> np.ndarray:
        """The closed contacts' forces ``(a, k)`` at the modal displacements ``Q`` (``(n, k)``) and times ``t``;
        ``gap(t)``: the flight's clearances (``(m, k)``), used by a phase that keeps no products (friction's)."""
        if self._Yg is None:
            return self.GWt @ Q - self.G @ gap(t)[self.idx]
        g = self._Yg[:, None]
        if self._YD is not None:
            g = g + np.multiply.outer(self._YD, np.exp(1j * self.nu * t)).real
        return self.GWt @ Q - g

    def shifted(self, delta: np.ndarray) -> _Phase:
        """The same phase with every clearance ``delta`` (``(m,)``, m) wider: its equilibrium and switching
        signals' constants moved, its modes shared (a worn casing's piece between two steps of its profile)."""
        out = copy.copy(self)
        dq = self.eq_map @ delta[self.idx]
        out.q_eq = self.q_eq + dq
        out.const = self.const + self.L @ dq + self.P @ delta
        if self._Yg is not None:
            out._Yg = self._Yg + self.G @ delta[self.idx]
        return out

    def signals_at(self, q: np.ndarray, gap: np.ndarray) -> np.ndarray:
        """The ``m`` switching signals (``λ`` of the closed contacts, the clearance left of the open ones) of the
        modal displacement ``q`` against the clearances ``gap``."""
        return self.L @ q + self.P @ gap

    def particular(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        if self.nu == 0:
            return self.q_eq, np.zeros_like(self.q_eq)
        e = self.X * np.exp(1j * self.nu * t)
        return self.q_eq + e.real, (1j * self.nu * e).real

    def amplitudes(self, q, p, t0: float) -> np.ndarray:
        qp, pp = self.particular(t0)
        r, s = q - qp, p - pp
        if self._psi is not None:
            return self._psi.T @ r - 1j * (self._psi.T @ s) / self._w
        return self._Vinv @ np.concatenate([r, s])

    def advance(self, a: np.ndarray, t0: float, tau) -> tuple[np.ndarray, np.ndarray]:
        """States at ``t₀ + τ`` (``tau`` scalar or ``(k,)``: columns)."""
        tau = np.asarray(tau, dtype=float)
        e = np.exp(np.multiply.outer(self.lam, tau)) * (a if tau.ndim == 0 else a[:, None])
        qp, pp = self.particular(t0 + tau) if tau.ndim == 0 else self._particular_cols(t0 + tau)
        return qp + (self.Vx @ e).real, pp + (self.Vv @ e).real

    def _particular_cols(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.nu == 0:
            return np.repeat(self.q_eq[:, None], t.size, 1), np.zeros((self.q_eq.size, t.size))
        e = np.multiply.outer(self.X, np.exp(1j * self.nu * t))
        return self.q_eq[:, None] + e.real, (1j * self.nu * e).real

    def signals(self, a: np.ndarray, t0: float) -> _Signals:
        """The ``m`` switching signals of a flight starting at ``t₀`` with amplitudes ``a``."""
        E = self.E0 * np.exp(1j * self.nu * t0) if self.nu > 0 else self.E0
        return _Signals(self.lam, self.LVx * a, E, self.nu, self.const, self.lam2)
