"""One phase of the stick–slip model (:mod:`~bladecase.nsm.massless.friction_coulomb`): each contact node open,
sliding one way or the other, or sticking; the phase's linear, non-symmetric dynamics and its switching signals.

Each node ``j`` has a code: :data:`OPEN`, :data:`SLIP_POS` (``τ_j = +μλ_j``), :data:`SLIP_NEG` (``τ_j = −μλ_j``) or
:data:`STICK` (its tangential displacement follows the casing: ``z_j = z̄_j + V_j t``). The unknown forces of a phase,
``u = (λ_A, τ_S)`` (the closed nodes' normal forces, the sticking nodes' tangential ones), solve the phase's linear
constraints — closed: ``W_Aᵀx − H_A·λ + C_nt,A·τ = g_A(t)``; sticking: ``T_Sᵀx − C_nt,Sᵀλ + C_tt,S·τ = z̄_S(t)`` —
so ``u = U_q q + U_ρ ρ(t)``, ``ρ = (g, z̄)`` the inputs, and the interior (open-phase modal coordinates ``q``)
obeys ``q'' + C q' + Ω²q = (−W λ + T τ) + f``: a linear phase, ``K = Ω² − D U_q``, forced by the inputs
``ρ(t) = ρ₀ + ρ₁t + Re(R e^{iνt})`` (a constant, the sticking nodes' ramp ``V t``, the out-of-round casing). Its
flight is exact: the first-order eigenvectors of ``(K, C)`` plus the particular solution
``a + bt + Re(X e^{iνt})``.

The switching signals, each linear in ``(q, q', ρ, ρ')``: an open node's clearance; a closed node's ``λ_j``; a sliding
node's relative velocity ``σ_j(V_j − z'_j)`` (the casing's sliding speed ``V_j`` less the node's tangential vibration
velocity); a sticking node's distance to the friction cone on either side, ``μλ_j ∓ τ_j``. Along a flight each is
``base + slope·τ + Re(Σ C e^{λτ} + E e^{iντ})`` (:class:`RampSignals`: the ramp's linear term added to the
certified search's signals; its second derivative is that of the exponential terms, so the search's bound holds).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from .friction import first_order_modes
from .nodal_switches import _Row, _Signals
from .nodes import EIGVEC_COND_LIMIT

__all__ = ["KINDS", "OPEN", "SLIP_NEG", "SLIP_POS", "STICK", "CoulombPhase", "RampSignals"]

#: A node's codes.
OPEN, SLIP_POS, SLIP_NEG, STICK = 0, 1, 2, 3

#: The kinds of switching signal: an open node's clearance, a closed node's normal force, a sliding node's relative
#: velocity, a sticking node's distance to the cone on the positive and on the negative side.
KINDS = ("gap", "force", "slip", "cone+", "cone-")



@dataclass(frozen=True, eq=False)
class RampSignals(_Signals):
    """``f_j(τ) = base_j + slope_j·τ + Re(Σ_k C_jk e^{λ_kτ} + E_j e^{iντ})``. ``const`` (what the certified search
    reads to drop a signal that cannot reach 0) is ``base − max(0, −slope)·horizon``: a lower bound of the constant
    part over the flight."""

    slope: np.ndarray = None  # type: ignore[assignment]
    base: np.ndarray = None  # type: ignore[assignment]
    horizon: float = np.inf

    def at(self, tau: float, js: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        e = np.exp(tau * self.lam)
        C = self.C[js]
        f = (C @ e).real + self.base[js] + self.slope[js] * tau
        df = (C @ (self.lam * e)).real + self.slope[js]
        if self.nu > 0:
            z = np.exp(1j * self.nu * tau) * self.E[js]
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    def values(self, tau) -> tuple[np.ndarray, np.ndarray]:
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        e = np.exp(np.multiply.outer(tau, self.lam))
        f = (e @ self.C.T).real + self.base + np.multiply.outer(tau, self.slope)
        df = (e @ (self.C * self.lam).T).real + self.slope
        if self.nu > 0:
            z = np.multiply.outer(np.exp(1j * self.nu * tau), self.E)
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    @cached_property
    def magnitude(self) -> np.ndarray:
        ramp = np.abs(self.slope) * (self.horizon if np.isfinite(self.horizon) else 0.0)
        return np.abs(self.C).sum(axis=1) + np.abs(self.E) + np.abs(self.base) + ramp

    def second(self) -> np.ndarray:
        """``f''(0)`` of every signal."""
        return (self.C @ self.lam**2).real - self.nu**2 * self.E.real

    def row(self, j: int) -> _RampRow:
        return _RampRow(self, j)


class _RampRow(_Row):
    def __init__(self, sig: RampSignals, j: int):
        super().__init__(sig, j)
        self.const, self.slope = sig.base[j], sig.slope[j]

    def __call__(self, tau):
        f, df = super().__call__(tau)
        return f - self.slope * np.asarray(tau, dtype=float), df - self.slope


class CoulombPhase:
    """The phase of the node codes ``codes`` (module docstring) for the flight ``fl``
    (:class:`~bladecase.nsm.massless.friction_coulomb.CoulombFlight`); the sticking nodes' anchors
    ``z̄_j(t) = anchor_j + V_j t`` enter only its constants (:meth:`particular`, :meth:`signals`)."""

    def __init__(self, fl, codes: np.ndarray):
        m, n, mu = fl.m, fl.n, fl.mu
        self.codes = codes = np.asarray(codes, dtype=np.int8)
        ia, isk = np.flatnonzero(codes > OPEN), np.flatnonzero(codes == STICK)
        na, ns = ia.size, isk.size
        El, Pt = np.zeros((m, na + ns)), np.zeros((m, na + ns))
        El[ia, np.arange(na)] = 1.0
        sign = np.where(codes == SLIP_POS, 1.0, np.where(codes == SLIP_NEG, -1.0, 0.0))
        Pt[ia, np.arange(na)] = mu * sign[ia]
        Pt[isk, na + np.arange(ns)] = 1.0
        H, Cnt, Ctt = fl.H, fl.C_nt, fl.C_tt
        J = np.vstack([-H[ia] @ El + Cnt[ia] @ Pt, -Cnt[:, isk].T @ El + Ctt[isk] @ Pt])
        Bq = np.vstack([fl.Wq[:, ia].T, fl.Tq[:, isk].T])
        Rsel = np.zeros((na + ns, 2 * m))
        Rsel[np.arange(na), ia] = 1.0
        Rsel[na + np.arange(ns), m + isk] = 1.0
        if na + ns:
            try:
                Uq, Ur = np.linalg.solve(J, -Bq), np.linalg.solve(J, Rsel)
            except np.linalg.LinAlgError:
                raise ValueError(f"the contact phase with nodes {[fl.system.nodes[k] for k in ia]} closed has no "
                                 "unique contact forces (singular compliance)") from None
        else:
            Uq, Ur = np.zeros((0, n)), np.zeros((0, 2 * m))
        Dm = -fl.Wq @ El + fl.Tq @ Pt
        self.Uq, self.Ur, self.El, self.Pt, self.idx = Uq, Ur, El, Pt, ia
        K = np.diag(fl.omega**2) - Dm @ Uq
        C = fl.Cq if fl.Cq is not None else np.zeros((n, n))
        self.K = K
        # particular solution a + b t + Re(X e^{iνt}) for ρ = ρ₀ + ρ₁t + Re(R e^{iνt}), ρ₁ = (0, V), R = (D, 0)
        F = Dm @ Ur
        self.b = np.linalg.solve(K, F @ fl.rho1)
        self.a_fix = np.linalg.solve(K, F[:, :m] @ fl.system.gap + fl.fq - C @ self.b)
        self.a_map = np.linalg.solve(K, F[:, m:])
        nu = fl.nu
        self.nu = nu
        self.X = np.zeros(n, complex)
        if nu > 0 and fl.R is not None:
            try:
                self.X = np.linalg.solve(K - nu**2 * np.eye(n) + 1j * nu * C, F @ fl.R)
            except np.linalg.LinAlgError:
                raise ValueError(f"the casing's excitation at {nu / 2 / np.pi:.6g} Hz is at an undamped resonance "
                                 "of a stick–slip contact phase: add damping or change the speed") from None
        growth = getattr(fl, "allow_growth", False)  # the extended periodic motion concept feeds its phases

        def what():
            names = {c: [fl.system.nodes[k] for k in np.flatnonzero(codes == c)] for c in (SLIP_POS, SLIP_NEG, STICK)}
            return (f"a stick–slip contact phase (nodes sliding {names[SLIP_POS] + names[SLIP_NEG]}, sticking "
                    f"{names[STICK]}, mu = {mu:g})")

        lam, V = first_order_modes(K, C, what, growth)
        lu = sla.lu_factor(V)
        if not sla.lapack.zgecon(lu[0], np.abs(V).sum(axis=0).max())[0] * EIGVEC_COND_LIMIT > 1:
            raise ValueError("a stick–slip contact phase is nearly defective (two of its modes coincide): change mu "
                             "or the damping slightly")
        self.lam = lam if growth else np.minimum(lam.real, 0.0) + 1j * lam.imag
        self.Vx, self.Vv = V[:n], V[n:]
        self._Vinv = sla.lu_solve(lu, np.eye(2 * n, dtype=complex))
        self._signal_rows(fl, sign)

    def _signal_rows(self, fl, sign: np.ndarray) -> None:
        """The phase's switching signals ``Lq q + Lp q' + Lr ρ + Ld ρ' + c`` and what each watches (node, kind)."""
        m, n, mu, codes = fl.m, fl.n, fl.mu, self.codes
        Uq, Ur, El, Pt = self.Uq, self.Ur, self.El, self.Pt
        lamq, lamr = El @ Uq, El @ Ur  # λ = lamq q + lamr ρ
        tauq, taur = Pt @ Uq, Pt @ Ur
        Z = -fl.C_nt.T @ El + fl.C_tt @ Pt  # z = Tqᵀq + Z u (the nodes' tangential displacements)
        self.Zq, self.Zr = fl.Tq.T + Z @ Uq, Z @ Ur
        rows, meta = [], []
        eye = np.eye(m, 2 * m)
        for j in range(m):
            zero_n, zero_r = np.zeros(n), np.zeros(2 * m)
            if codes[j] == OPEN:
                sq = -fl.Wq[:, j] + fl.H[j] @ lamq - fl.C_nt[j] @ tauq
                sr = eye[j] + fl.H[j] @ lamr - fl.C_nt[j] @ taur
                rows.append((sq, zero_n, sr, zero_r, 0.0))
                meta.append((j, "gap"))
                continue
            rows.append((lamq[j], zero_n, lamr[j], zero_r, 0.0))
            meta.append((j, "force"))
            if codes[j] == STICK:
                for s, kind in ((1.0, "cone+"), (-1.0, "cone-")):
                    rows.append((mu * lamq[j] - s * tauq[j], zero_n, mu * lamr[j] - s * taur[j], zero_r, 0.0))
                    meta.append((j, kind))
            else:
                s = sign[j]
                rows.append((zero_n, -s * self.Zq[j], zero_r, -s * self.Zr[j], s * fl.V[j]))
                meta.append((j, "slip"))
        self.Lq, self.Lp, self.Lr, self.Ld = (np.array([r[k] for r in rows]) for k in range(4))
        self.c = np.array([r[4] for r in rows])
        self.meta = meta
        nu = self.nu
        self.LV = self.Lq @ self.Vx + self.Lp @ self.Vv
        R = fl.R if fl.R is not None else np.zeros(2 * m, complex)
        self.EX = self.Lq @ self.X + 1j * nu * (self.Lp @ self.X) + self.Lr @ R + 1j * nu * (self.Ld @ R)
        self.slope = self.Lq @ self.b + self.Lr @ fl.rho1
        self.lam2 = np.abs(self.lam) ** 2

    def rho(self, fl, t, anchors: np.ndarray) -> np.ndarray:
        """The inputs ``ρ(t) = (g(t), z̄(t))``: ``(2m,)`` or ``(2m, k)``."""
        t = np.asarray(t, dtype=float)
        zbar = anchors[:, None] + np.multiply.outer(fl.V, np.atleast_1d(t))
        out = np.vstack([fl.gap(np.atleast_1d(t)), zbar])
        return out[:, 0] if t.ndim == 0 else out

    def particular(self, t, anchors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(q_p, q_p')`` at the times ``t`` (``(n,)`` or ``(n, k)``)."""
        t = np.asarray(t, dtype=float)
        a = self.a_fix + self.a_map @ anchors
        q = np.add.outer(a, np.zeros(t.shape)) + np.multiply.outer(self.b, t)
        p = np.add.outer(self.b, np.zeros(t.shape))
        if self.nu > 0:
            e = np.multiply.outer(self.X, np.exp(1j * self.nu * t))
            q, p = q + e.real, p + (1j * self.nu * e).real
        return q, p

    def amplitudes(self, q, p, t0: float, anchors: np.ndarray) -> np.ndarray:
        qp, pp = self.particular(t0, anchors)
        return self._Vinv @ np.concatenate([q - qp, p - pp])

    def advance(self, amp: np.ndarray, t0: float, tau, anchors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """States at ``t₀ + τ`` (``tau`` scalar or ``(k,)``: columns)."""
        tau = np.asarray(tau, dtype=float)
        e = np.exp(np.multiply.outer(self.lam, tau)) * (amp if tau.ndim == 0 else amp[:, None])
        qp, pp = self.particular(t0 + tau, anchors)
        return qp + (self.Vx @ e).real, pp + (self.Vv @ e).real

    def forces(self, fl, q, t, anchors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(λ, τ)`` of the states ``q`` (``(n, k)``) at the times ``t``: ``(m, k)`` each."""
        u = self.Uq @ q + self.Ur @ self.rho(fl, np.atleast_1d(t), anchors)
        return self.El @ u, self.Pt @ u

    def signals(self, fl, amp: np.ndarray, t0: float, anchors: np.ndarray, horizon: float) -> RampSignals:
        """The switching signals of a flight from ``t₀`` with the amplitudes ``amp`` over ``[0, horizon]``."""
        a = self.a_fix + self.a_map @ anchors
        rho0 = np.r_[fl.system.gap, anchors]
        base = (self.Lq @ (a + self.b * t0) + self.Lp @ self.b + self.Lr @ (rho0 + fl.rho1 * t0)
                + self.Ld @ fl.rho1 + self.c)
        E = self.EX * np.exp(1j * self.nu * t0) if self.nu > 0 else np.zeros(self.c.size, complex)
        const = base - np.maximum(0.0, -self.slope) * horizon
        return RampSignals(self.lam, self.LV * amp, E, self.nu, const, self.lam2, self.slope, base, horizon)
