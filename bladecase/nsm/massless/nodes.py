"""The massless contact model with several unilateral contacts: every contact node its own constraint.

A structure whose contact dofs carry no inertia (theory §8), touched at ``m`` contact nodes, each with its own
normal and clearance. The interior dofs ``x`` (``n``) obey

    M x'' + C x' + S x + W λ = 0,        λ ≥ 0,   s = g(t) − Wᵀx + H λ ≥ 0,   λᵀs = 0,

- ``S``: the open-phase stiffness (contact dofs free, statically condensed); ``Wᵀx`` the contact nodes' normal
  displacements while every contact is open;
- ``H = H_s + diag(1/k_j)``: the contact nodes' own flexibility ``H_s = W_cᵀK_cc⁻¹W_c`` (the interior held;
  symmetric positive definite when the nodes' normals are independent) plus the casing's compliance at each
  node (``k_j = inf``: rigid);
- ``λ_j``: the casing's force on node ``j``; ``s_j``: what is left of its clearance ``g_j(t)`` (node ``j`` sits at
  ``y_j − (H_sλ)_j`` and the casing has yielded by ``λ_j/k_j``);
- ``g(t) = g₀ + Re(D e^{iνt})``: the clearances, constant or seen by a blade turning inside an out-of-round
  casing (:class:`Rub`).

For ``H`` symmetric positive definite the complementarity problem has ONE solution for every ``x``, continuous
and piecewise linear in ``x``: there is no impact and no impact law. With the set ``A`` of closed contacts,
``λ_A = G_A(W_Aᵀx − g_A)``, ``G_A = H_AA⁻¹``, so each phase is LINEAR,

    M x'' + C x' + (S + W_A G_A W_Aᵀ) x = W_A G_A g_A(t),

flown in closed form (modes of the phase, or the state-space eigenvectors when damped, plus the harmonic
particular solution). A phase ends at the FIRST root of any of its ``m`` switching signals — ``λ_j`` for a
closed contact, ``s_j`` for an open one, each a linear function of the state and of ``g(t)`` — found by a
certified search over all of them at once (no switch is missed). At a switch the new set comes from the
complementarity problem at the rate level (which contacts gain force, which start to open): simultaneous
switches are taken as they come. ``x``, ``x'`` and ``λ`` are continuous at every switch: with a constant gap and
no damping, the energy ``½x'ᵀMx' + ½xᵀSx + ½λᵀHλ`` is conserved, and the saltation matrices are the identity.

With ``m = 1`` this is :class:`~bladecase.nsm.massless.model.MasslessSystem` (``k_c = 1/H``).

>>> import numpy as np
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0])
>>> tr = simulate_nodes(s, [2.0, 0.0], [0.0, 0.0], 20.0)
>>> tr.active[0].tolist(), tr.switch_times.size > 4
([True, False], True)
>>> abs(s.energy(tr.x_end, tr.v_end) - s.energy([2.0, 0.0], [0.0, 0.0])) < 1e-12
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla
from scipy.optimize import nnls

from ..signals import POINTS_PER_PERIOD, _search, interval_bound

__all__ = ["NodalFlight", "NodalSystem", "NodalTrajectory", "Rub", "lcp", "simulate_nodes"]

#: Largest interior size (dense phases).
NODES_DENSE_LIMIT = 4000

#: Largest condition number of a damped phase's state-space eigenvectors (near-defective: refused).
EIGVEC_COND_LIMIT = 1e10

#: Default ``max_switches`` of :func:`simulate_nodes`.
MAX_SWITCHES = 1_000_000

#: Relative size below which a switching signal counts as ON its surface at a switch.
SURFACE_RTOL = 1e-9


def _matrix(name: str, A, shape) -> np.ndarray:
    A = np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)
    if A.shape != shape or not np.all(np.isfinite(A)):
        raise ValueError(f"{name} must be a finite array of shape {shape}, got shape {A.shape}")
    return A


@dataclass(frozen=True, eq=False)
class NodalSystem:
    """Interior dynamics of a structure with ``m`` massless contact nodes (see the module docstring).

    Attributes
    ----------
    M, S : (n, n) ndarray
        Interior mass and open-phase stiffness (both symmetric positive definite).
    W : (n, m) ndarray
        ``Wᵀx``: the contact nodes' normal displacements while every contact is open.
    flexibility : (m, m) ndarray
        ``H_s = W_cᵀK_cc⁻¹W_c``: the contact nodes' own flexibility, the interior held (SPD; m/N).
    gap : (m,) ndarray
        Each node's clearance along its normal at rest (m; > 0).
    casing : (m,) ndarray
        The casing's stiffness at each node (N/m; ``inf``: rigid).
    expand : (n_full, n) ndarray or None
        Open-phase displacements of the full model's dofs (``None``: not kept).
    nodes : tuple of int
        The contact nodes' labels (mesh node numbers), for reports.
    """

    M: np.ndarray
    S: np.ndarray
    W: np.ndarray
    flexibility: np.ndarray
    gap: np.ndarray
    casing: np.ndarray = None  # type: ignore[assignment]
    expand: np.ndarray | None = field(default=None, repr=False)
    nodes: tuple = ()

    contact_model = "massless"

    def __post_init__(self) -> None:
        W = np.asarray(self.W, dtype=float)
        W = W.reshape(-1, 1) if W.ndim == 1 else W
        if W.ndim != 2 or W.shape[1] == 0:
            raise ValueError(f"W must be an (n, m) array with m >= 1 contacts, got shape {W.shape}")
        n, m = W.shape
        if n > NODES_DENSE_LIMIT:
            raise ValueError(f"massless model of {n} interior dofs: at most {NODES_DENSE_LIMIT} (dense phases); "
                             "reduce the model first")
        object.__setattr__(self, "W", W)
        for name in ("M", "S"):
            A = _matrix(name, getattr(self, name), (n, n))
            object.__setattr__(self, name, 0.5 * (A + A.T))
        H = _matrix("flexibility", np.atleast_2d(self.flexibility), (m, m))
        object.__setattr__(self, "flexibility", 0.5 * (H + H.T))
        gap = np.broadcast_to(np.asarray(self.gap, dtype=float), (m,)).copy()
        if not (np.all(np.isfinite(gap)) and np.all(gap > 0)):
            raise ValueError(f"every clearance must be finite and > 0, got {gap.tolist()}")
        object.__setattr__(self, "gap", gap)
        casing = np.full(m, np.inf) if self.casing is None else np.broadcast_to(
            np.asarray(self.casing, dtype=float), (m,)).copy()
        if np.any(np.isnan(casing)) or np.any(casing <= 0):
            raise ValueError(f"casing stiffness must be > 0 at every node (inf: rigid), got {casing.tolist()}")
        object.__setattr__(self, "casing", casing)
        try:
            np.linalg.cholesky(self.H)
        except np.linalg.LinAlgError:
            raise ValueError("the contact nodes' flexibility is not positive definite: two contacts constrain the "
                             "same motion (a repeated node, or parallel normals on one node)") from None
        nodes = tuple(int(k) for k in self.nodes) if len(self.nodes) else tuple(range(m))
        if len(nodes) != m:
            raise ValueError(f"nodes must name the {m} contacts, got {len(nodes)} labels")
        object.__setattr__(self, "nodes", nodes)

    @property
    def n(self) -> int:
        """Interior dofs."""
        return self.M.shape[0]

    @property
    def m(self) -> int:
        """Contacts."""
        return self.W.shape[1]

    @cached_property
    def H(self) -> np.ndarray:
        """``H_s + diag(1/k_j)``: the flexibility the forces see (m/N)."""
        return self.flexibility + np.diag(1.0 / self.casing)

    @cached_property
    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """``(ω, Φ)``: the open-phase modes (every contact open), M-normalised."""
        lam, phi = sla.eigh(self.S, self.M)
        if lam.min() <= 0:
            raise ValueError(f"the open-phase stiffness is not positive definite (lowest eigenvalue {lam.min():.3g})")
        return np.sqrt(lam), phi

    def forces(self, x, gap=None) -> np.ndarray:
        """Contact forces ``λ`` of the interior states ``x`` (``(n,)`` or ``(n, k)``) against ``gap`` (default the
        clearances at rest; ``(m,)`` or ``(m, k)``)."""
        x = np.asarray(x, dtype=float)
        g = self.gap if gap is None else np.asarray(gap, dtype=float)
        if x.ndim == 1:
            return lcp(g - self.W.T @ x, self.H)
        G = np.broadcast_to(g.reshape(self.m, -1), (self.m, x.shape[1]))
        Y = self.W.T @ x
        return np.column_stack([lcp(G[:, k] - Y[:, k], self.H) for k in range(x.shape[1])])

    def energy(self, x, v) -> float:
        """``½vᵀMv + ½xᵀSx + ½λᵀHλ`` at the clearances at rest (conserved without damping or a moving casing)."""
        x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
        lam = self.forces(x)
        return float(0.5 * v @ self.M @ v + 0.5 * x @ self.S @ x + 0.5 * lam @ self.H @ lam)

    def __repr__(self) -> str:
        rigid = np.isinf(self.casing)
        casing = "rigid" if rigid.all() else f"casing {np.min(self.casing):.3g}–{np.max(self.casing):.3g} N/m"
        return f"NodalSystem(n={self.n}, m={self.m} contacts, gap {self.gap.min():g}–{self.gap.max():g} m, {casing})"


def lcp(q, H) -> np.ndarray:
    """The ``λ >= 0`` with ``s = q + Hλ >= 0`` and ``λᵀs = 0``, ``H`` symmetric positive definite (unique).

    Solved as the bound-constrained least squares ``min |Rλ + R⁻ᵀq|``, ``H = RᵀR`` (Lawson–Hanson, exact).

    >>> lcp(np.array([-1.0, 2.0]), np.array([[2.0, 0.5], [0.5, 1.0]])).round(12).tolist()
    [0.5, 0.0]
    """
    q = np.asarray(q, dtype=float)
    if np.all(q >= 0):
        return np.zeros_like(q)
    R = np.linalg.cholesky(H).T
    lam, _ = nnls(R, -sla.solve_triangular(R, q, trans="T"), maxiter=50 * q.size)
    return lam


# ----------------------------------------------------------------------------- out-of-round casing


@dataclass(frozen=True)
class Rub:
    """Clearances seen by a blade turning at ``speed`` (rad/s) inside a casing with ``lobes`` lobes of
    ``amplitude`` (m): node ``j`` at the angle ``φ_j`` (rad) sees ``g_j(t) = d_j − a cos(n(Ωt + φ_j))``.

    >>> r = Rub(lobes=2, amplitude=1e-5, speed=100.0, angles=[0.0, np.pi / 2])
    >>> r.nu, np.round(r.D, 12).tolist()
    (200.0, [(-1e-05+0j), (1e-05-0j)])
    """

    lobes: int
    amplitude: float
    speed: float
    angles: tuple = (0.0,)

    def __post_init__(self) -> None:
        if isinstance(self.lobes, bool) or int(self.lobes) != self.lobes or self.lobes < 1:
            raise ValueError(f"lobes must be an integer >= 1, got {self.lobes!r}")
        for name in ("amplitude", "speed"):
            v = getattr(self, name)
            if isinstance(v, bool) or not np.isfinite(float(v)) or float(v) < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
        object.__setattr__(self, "angles", tuple(float(a) for a in np.atleast_1d(self.angles)))

    @property
    def nu(self) -> float:
        """The angular frequency of the clearances' variation, ``nΩ`` (rad/s)."""
        return float(self.lobes * self.speed)

    @property
    def D(self) -> np.ndarray:
        """Complex amplitudes: ``g(t) = d + Re(D e^{iνt})``."""
        return -self.amplitude * np.exp(1j * self.lobes * np.asarray(self.angles))


# ----------------------------------------------------------------------------- phases


class _Phase:
    """One set ``A`` of closed contacts, in the open-phase modal coordinates ``(q, p)`` (``M = I``).

    ``q(t₀+τ) = q_p(t₀+τ) + Re(Vx (a ∘ e^{Λτ}))`` with ``a`` the complex amplitudes of the homogeneous part and
    ``q_p(t) = q_eq + Re(X e^{iνt})`` the phase's particular solution.
    """

    def __init__(self, fl: NodalFlight, A: np.ndarray):
        s = fl.system
        self.A = A
        m, n = s.m, fl.n
        Wq, H = fl.Wq, s.H
        idx = np.flatnonzero(A)
        K = np.diag(fl.omega**2)
        if idx.size:
            WA = Wq[:, idx]
            G = np.linalg.inv(H[np.ix_(idx, idx)])
            G = 0.5 * (G + G.T)
            K = K + WA @ G @ WA.T
        # switching signals: L q + P g(t)
        L, P = np.zeros((m, n)), np.eye(m)
        if idx.size:
            L[idx] = G @ WA.T
            P[idx] = 0.0
            P[np.ix_(idx, idx)] = -G
            out = np.flatnonzero(~A)
            HG = H[np.ix_(out, idx)] @ G
            L[out] = -Wq[:, out].T + HG @ WA.T
            P[np.ix_(out, idx)] = -HG
        else:
            L = -Wq.T.copy()
        self.L, self.P = L, P
        self.idx = idx
        self.GWt = G @ WA.T if idx.size else np.zeros((0, n))  # λ_A = G_A(W_Aᵀq − g_A(t))
        self.G = G if idx.size else np.zeros((0, 0))
        f0 = WA @ (G @ s.gap[idx]) if idx.size else np.zeros(n)
        self.q_eq = np.linalg.solve(K, f0)
        nu = fl.nu
        if idx.size and nu > 0 and fl.D is not None:
            F = WA @ (G @ fl.D[idx])
            Z = K - nu**2 * np.eye(n) + (1j * nu * fl.Cq if fl.Cq is not None else 0)
            try:
                self.X = np.linalg.solve(Z, F)
            except np.linalg.LinAlgError:
                raise ValueError(f"the casing's excitation at {nu / 2 / np.pi:.6g} Hz is at an undamped resonance "
                                 "of a contact phase: add damping or change the speed") from None
        else:
            self.X = np.zeros(n, complex)
        if fl.Cq is None:
            lam2, psi = np.linalg.eigh(K)
            if lam2.min() <= 0:
                raise ValueError("a contact phase's stiffness is not positive definite")
            w = np.sqrt(lam2)
            self.lam = 1j * w
            self.Vx, self.Vv = psi.astype(complex), psi * (1j * w)
            self._psi, self._w = psi, w
        else:
            Ass = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -fl.Cq]])
            lam, V = np.linalg.eig(Ass)
            self._lu = sla.lu_factor(V)
            rcond = sla.lapack.zgecon(self._lu[0], np.abs(V).sum(axis=0).max())[0]
            if not rcond * EIGVEC_COND_LIMIT > 1:
                raise ValueError("a damped contact phase is nearly defective (critically damped mode): change the "
                                 "damping slightly")
            self.lam, self.Vx, self.Vv = np.minimum(lam.real, 0.0) + 1j * lam.imag, V[:n], V[n:]
            self._Vinv = sla.lu_solve(self._lu, np.eye(2 * n, dtype=complex))  # amplitudes by one small product
            self._psi = None
        self.LVx = L @ self.Vx
        self.nu = nu
        self.const = L @ self.q_eq + P @ s.gap
        self.E0 = (L @ self.X + (P @ fl.D if fl.D is not None else 0)) if nu > 0 else np.zeros(m, complex)
        self.lam2 = np.abs(self.lam) ** 2

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


@dataclass(frozen=True, eq=False)
class _Signals:
    """``f_j(τ) = const_j + Re(Σ_k C_jk e^{λ_kτ} + E_j e^{iντ})``, ``j = 1..m`` (``Re λ_k <= 0``)."""

    lam: np.ndarray
    C: np.ndarray
    E: np.ndarray
    nu: float
    const: np.ndarray
    lam2: np.ndarray

    def at(self, tau: float, js: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(f, f')`` of the signals ``js`` at one point ``tau``."""
        e = np.exp(tau * self.lam)
        C = self.C[js]
        f = (C @ e).real + self.const[js]
        df = (C @ (self.lam * e)).real
        if self.nu > 0:
            z = np.exp(1j * self.nu * tau) * self.E[js]
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    def values(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """``(f, f')`` at the points ``tau``: ``(len(tau), m)``."""
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        e = np.exp(np.multiply.outer(tau, self.lam))
        f = (e @ self.C.T).real + self.const
        df = (e @ (self.C * self.lam).T).real
        if self.nu > 0:
            z = np.multiply.outer(np.exp(1j * self.nu * tau), self.E)
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    @cached_property
    def bound(self) -> np.ndarray:
        """``B₂ >= max|f_j''|`` of each signal."""
        return np.abs(self.C) @ self.lam2 + np.abs(self.E) * self.nu**2

    @cached_property
    def magnitude(self) -> np.ndarray:
        return np.abs(self.C).sum(axis=1) + np.abs(self.E) + np.abs(self.const)

    @property
    def step(self) -> float:
        """The first grid's step: ``2π / (POINTS_PER_PERIOD · ω_eff)`` with ``ω_eff² = max_j B₂_j / Σ|terms_j|``,
        the signals' amplitude-weighted frequency (a component of negligible amplitude does not shorten the grid;
        the certification does not depend on it: an inconclusive interval is bisected)."""
        amp = np.abs(self.C).sum(axis=1) + np.abs(self.E)
        live = amp > 0
        if not live.any():
            return np.inf
        w2 = float(np.max(self.bound[live] / amp[live]))
        return 2 * np.pi / (POINTS_PER_PERIOD * max(np.sqrt(w2), self.nu, 1e-300))

    def row(self, j: int) -> _Row:
        return _Row(self, j)


class _Row:
    """One signal of :class:`_Signals`, NEGATED (its upcrossings are the switches), for the scalar search."""

    def __init__(self, sig: _Signals, j: int):
        self.lam, self.c, self.E, self.nu, self.const = sig.lam, sig.C[j], complex(sig.E[j]), sig.nu, sig.const[j]
        self.cl = self.c * self.lam

    def __call__(self, tau):
        t = np.asarray(tau, dtype=float)
        e = np.exp(np.multiply.outer(t, self.lam))
        f, df = (e @ self.c).real + self.const, (e @ self.cl).real
        if self.nu > 0:
            z = self.E * np.exp(1j * self.nu * t)
            f, df = f + z.real, df - self.nu * z.imag
        return -f, -df


def _newton(row: _Row, a: float, b: float, fa: float, fb: float, da: float, db: float) -> float:
    """The root of the (negated) signal in ``[a, b]`` where it rises through 0 and its slope provably stays
    positive: Newton's method from the secant point, kept in the bracket (bisection when a step leaves it), to
    machine precision — 2 to 4 evaluations where Brent's method takes 6 to 8."""
    x = a - fa * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
    for _ in range(40):
        f, d = row(x)
        f, d = float(f), float(d)
        if f == 0.0:
            return x
        if f < 0:
            a = x
        else:
            b = x
        step = f / d if d > 0 else np.inf
        new = x - step
        if not a < new < b:
            new = 0.5 * (a + b)
        if abs(new - x) <= 4 * np.finfo(float).eps * max(1.0, abs(x)) or b - a <= 4 * np.finfo(float).eps * max(
                1.0, abs(b)):
            return new
        x = new
    return x


def _leave(f0: float, d0: float, B2: float, horizon: float, row: _Row) -> float:
    """A ``τ > 0`` before which the negated signal ``-f`` (starting at ``-f0`` ≈ 0 rising as ``-d0``) stays < 0."""
    if -f0 < 0 and d0 <= 0:  # away from the surface already: the search starts at 0
        return 0.0
    if d0 <= 0:
        raise ValueError("grazing switch: a contact signal does not leave its switching surface "
                         f"(value {f0:.3g}, rate {d0:.3g})")
    tau = min(d0 / max(B2, 1e-300), horizon)
    while tau > 1e-300 and float(row(tau)[0]) >= 0:
        tau /= 2
    return tau


def first_switch(sig: _Signals, horizon: float, on: np.ndarray, chunk: int = 256) -> tuple[float, int] | None:
    """The first ``τ`` in ``(0, horizon]`` where one of the signals reaches 0, and which; ``None`` if none does.

    Every signal starts ``>= 0``; those flagged ``on`` start ON their surface (a switch just happened) and must
    be rising. The signals are evaluated together on one grid; each grid interval not proved positive for a
    signal by the bound on its second derivative is bisected (:func:`bladecase.nsm.signals.first_upcrossing`'s
    certified search), earliest interval first.
    """
    f0, d0 = sig.values(0.0)
    f0, d0 = f0[0], d0[0]
    B2 = sig.bound
    scale = np.maximum(sig.magnitude, np.finfo(float).tiny)
    hmin = np.sqrt(8e-14 * scale / np.maximum(B2, 1e-300))
    starts = np.zeros(sig.C.shape[0])
    for j in np.flatnonzero(on | (f0 <= 0)):
        starts[j] = _leave(float(f0[j]), float(d0[j]), float(B2[j]), horizon, sig.row(j))
    # a signal whose constant exceeds the sum of its oscillating terms' moduli (|e^{λτ}| <= 1) never reaches 0
    live = (B2 > 0) & (sig.const - np.abs(sig.C).sum(axis=1) - np.abs(sig.E) <= 0)
    if not live.any():
        return None
    step = min(sig.step, horizon)
    # the first grid step from the nearest linear estimate of a switch (f/|f'| of a falling signal): most flights
    # are a small fraction of the base step, and a first interval that holds the switch is bisected less;
    # the step then doubles up to the base step (the certification holds at any step)
    falling = live & (d0 < 0) & (f0 > 0)
    h = step if not falling.any() else min(step, max(2 * float(np.min(f0[falling] / -d0[falling])), step / 1024))
    t, size = 0.0, 8
    while t < horizon:
        count = min(size, int(np.ceil((horizon - t) / h))) + 1
        size = min(2 * size, chunk)
        hh = min(h, (horizon - t) / (count - 1))
        h = min(2 * h, step)
        tau = t + hh * np.arange(count)
        F, D = sig.values(tau)
        F, D = -F, -D
        U = interval_bound(F[:-1], F[1:], D[:-1], D[1:], hh, B2[None, :]) >= 0
        U &= live[None, :]
        U &= (tau[1:, None] > starts[None, :])
        for i in np.flatnonzero(U.any(axis=1)):
            js = np.flatnonzero(U[i])
            a = float(tau[i])
            late = starts[js] > a  # the interval holding a signal's start: searched from there
            for j in js[late]:
                row = sig.row(j)
                fs, ds = (float(v) for v in row(float(starts[j])))
                root = _search(row, float(B2[j]), float(hmin[j]), float(starts[j]), float(tau[i + 1]), fs,
                               float(F[i + 1, j]), ds, float(D[i + 1, j]), _newton)
                if root is not None:
                    early = _earliest(sig, B2, hmin, a, float(root), js[~late])
                    return early if early is not None else (float(root), int(j))
            js = js[~late]
            if js.size:
                hit = _many(sig, B2, hmin, a, float(tau[i + 1]), js, F[i, js], F[i + 1, js], D[i, js], D[i + 1, js])
                if hit is not None:
                    return hit
        t = float(tau[-1])
    return None


def _earliest(sig: _Signals, B2, hmin, a: float, b: float, js: np.ndarray) -> tuple[float, int] | None:
    """The first switch among the signals ``js`` in ``[a, b]``, if any (values computed afresh)."""
    if not js.size or b <= a:
        return None
    F, D = sig.values(np.array([a, b]))
    return _many(sig, B2, hmin, a, b, js, -F[0, js], -F[1, js], -D[0, js], -D[1, js])


def _many(sig: _Signals, B2, hmin, a: float, b: float, js, Fa, Fb, Da, Db) -> tuple[float, int] | None:
    """The first upcrossing in ``[a, b]`` of the NEGATED signals ``js`` (values and slopes at the ends given):
    bisected together while several may cross, then :func:`~bladecase.nsm.signals.first_upcrossing`'s certified
    scalar search on the last one."""
    keep = interval_bound(Fa, Fb, Da, Db, b - a, B2[js]) >= 0
    js, Fa, Fb, Da, Db = js[keep], Fa[keep], Fb[keep], Da[keep], Db[keep]
    if js.size == 0:
        return None
    if js.size == 1 or b - a < hmin[js].min():
        best = None
        for k, j in enumerate(js):
            root = _search(sig.row(j), float(B2[j]), float(hmin[j]), a, b, float(Fa[k]), float(Fb[k]), float(Da[k]),
                           float(Db[k]), _newton)
            if root is not None and (best is None or root < best[0]):
                best = (float(root), int(j))
        return best
    m = 0.5 * (a + b)
    Fm, Dm = sig.at(m, js)
    Fm, Dm = -Fm, -Dm
    hit = _many(sig, B2, hmin, a, m, js, Fa, Fm, Da, Dm)
    return hit if hit is not None else _many(sig, B2, hmin, m, b, js, Fm, Fb, Dm, Db)


class NodalFlight:
    """Exact flights of a :class:`NodalSystem`: its phases (cached per set of closed contacts), optional
    damping (:class:`~bladecase.nsm.damping.Damping` of the open-phase modes) and an out-of-round casing
    (:class:`Rub`)."""

    def __init__(self, system: NodalSystem, damping=None, rub: Rub | None = None):
        if not isinstance(system, NodalSystem):
            raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
        self.system = system
        self.omega, self.phi = system.modes
        self.n = system.n
        self.Wq = self.phi.T @ system.W
        if damping is not None and (damping.alpha or damping.beta or np.any(np.asarray(damping.zeta or 0) > 0)):
            self.Cq = np.diag(2 * damping.rates(self.omega))
        else:
            self.Cq = None
        if rub is not None:
            if len(rub.angles) != system.m:
                raise ValueError(f"the rub needs one angle per contact node ({system.m}), got {len(rub.angles)}")
            self.nu, self.D = rub.nu, rub.D
        else:
            self.nu, self.D = 0.0, None
        self._phases: dict[bytes, _Phase] = {}

    def phase(self, A: np.ndarray) -> _Phase:
        key = np.packbits(A).tobytes()
        ph = self._phases.get(key)
        if ph is None:
            ph = self._phases[key] = _Phase(self, A.copy())
        return ph

    def gap(self, t) -> np.ndarray:
        """The clearances at the times ``t``: ``(m,)`` or ``(m, k)``."""
        d = self.system.gap
        if self.D is None:
            return d if np.ndim(t) == 0 else np.repeat(d[:, None], np.size(t), 1)
        if np.ndim(t) == 0:
            return d + (self.D * np.exp(1j * self.nu * t)).real
        return d[:, None] + np.multiply.outer(self.D, np.exp(1j * self.nu * np.atleast_1d(t))).real

    def gap_rate(self, t: float) -> np.ndarray:
        if self.D is None:
            return np.zeros(self.system.m)
        return (1j * self.nu * self.D * np.exp(1j * self.nu * t)).real

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        M = self.system.M
        return self.phi.T @ (M @ x), self.phi.T @ (M @ v)

    def decode(self, q, p) -> tuple[np.ndarray, np.ndarray]:
        return self.phi @ q, self.phi @ p

    def active_set(self, q, p, t: float) -> np.ndarray:
        """The closed contacts from the state: the complementarity problem, at the rate level where a contact is
        on its surface (both its force and its remaining clearance zero)."""
        s = self.system
        H = s.H
        g = self.gap(t)
        y = self.Wq.T @ q
        lam = lcp(g - y, H)
        slack = g - y + H @ lam
        tol_s = SURFACE_RTOL * max(float(np.abs(g).max()), float(np.abs(y).max()))
        tol_l = tol_s / float(np.abs(H).max())
        A = lam > tol_l
        Dset = ~A & (slack <= tol_s)
        if not Dset.any():
            return A
        B, Dn = np.flatnonzero(A), np.flatnonzero(Dset)
        u = self.gap_rate(t) - self.Wq.T @ p
        if B.size:
            HBB = H[np.ix_(B, B)]
            X = np.linalg.solve(HBB, np.column_stack([u[B], H[np.ix_(B, Dn)]]))
            qD = u[Dn] - H[np.ix_(Dn, B)] @ X[:, 0]
            HD = H[np.ix_(Dn, Dn)] - H[np.ix_(Dn, B)] @ X[:, 1:]
        else:
            qD, HD = u[Dn], H[np.ix_(Dn, Dn)]
        rate = lcp(qD, 0.5 * (HD + HD.T))
        A[Dn] = rate > 0
        return A


@dataclass(frozen=True, eq=False)
class NodalTrajectory:
    """Result of :func:`simulate_nodes`: the start of every phase (time, set of closed contacts, modal state)."""

    flight: NodalFlight
    starts: np.ndarray
    active: np.ndarray
    q: np.ndarray
    p: np.ndarray
    t_end: float
    complete: bool
    amplitudes: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    @property
    def system(self) -> NodalSystem:
        return self.flight.system

    @property
    def switch_times(self) -> np.ndarray:
        """Times of the switches (the phases' starts after the first)."""
        return self.starts[1:]

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` at the times ``t`` (``(n, k)``), in closed form from the phase holding each."""
        x, v, _ = self.sample(t)
        return x, v

    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` and the contact forces ``λ`` (``(m, k)``) at the times ``t``, in closed form from the
        phase holding each (its forces from its own linear law: no complementarity problem to solve)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        fl = self.flight
        Q, P = np.empty((fl.n, t.size)), np.empty((fl.n, t.size))
        lam = np.zeros((self.system.m, t.size))
        order = np.argsort(k, kind="stable")
        bounds = np.searchsorted(k[order], np.arange(self.starts.size + 1))
        for i in np.flatnonzero(np.diff(bounds)):
            sel = order[bounds[i]:bounds[i + 1]]
            ph = fl.phase(self.active[i])
            a = self.amplitudes[i] if self.amplitudes is not None else ph.amplitudes(self.q[:, i], self.p[:, i],
                                                                                      self.starts[i])
            Q[:, sel], P[:, sel] = ph.advance(a, self.starts[i], t[sel] - self.starts[i])
            if ph.idx.size:
                lam[np.ix_(ph.idx, sel)] = np.maximum(ph.GWt @ Q[:, sel] - ph.G @ fl.gap(t[sel])[ph.idx], 0.0)
        x, v = fl.decode(Q, P)
        return x, v, lam

    @property
    def x_end(self) -> np.ndarray:
        return self.state(self.t_end)[0][:, 0]

    @property
    def v_end(self) -> np.ndarray:
        return self.state(self.t_end)[1][:, 0]

    def forces(self, t) -> np.ndarray:
        """Contact forces ``(m, k)`` at the times ``t``."""
        return self.sample(t)[2]

    def contact_time(self, t0: float = 0.0, t1: float | None = None) -> np.ndarray:
        """Time each contact spends closed in ``[t0, t1]`` (s)."""
        t1 = self.t_end if t1 is None else t1
        ends = np.r_[self.starts[1:], self.t_end]
        span = np.clip(np.minimum(ends, t1) - np.maximum(self.starts, t0), 0.0, None)
        return span @ self.active


def simulate_nodes(system: NodalSystem, x0, v0, t_end: float, damping=None, rub: Rub | None = None,
                   max_switches: int = MAX_SWITCHES, flight: NodalFlight | None = None) -> NodalTrajectory:
    """Exact event-driven simulation of the massless model with ``m`` contacts from ``(x0, v0)`` at ``t = 0``.

    Each phase is flown in closed form; each switch is the first root of any of the phase's ``m`` switching
    signals (certified); the set of closed contacts after a switch solves the complementarity problem (module
    docstring). ``damping``: :class:`~bladecase.nsm.damping.Damping` of the open-phase modes; ``rub``: the
    clearances of an out-of-round casing seen at speed (:class:`Rub`). A run that hits ``max_switches`` stops
    with ``complete = False``.
    """
    fl = flight if flight is not None else NodalFlight(system, damping, rub)
    x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
    if x.size != system.n or v.size != system.n or not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError(f"x0 and v0 must be finite with {system.n} interior dofs, got {x.size} and {v.size}")
    t_end = float(t_end)
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    if isinstance(max_switches, bool) or int(max_switches) < 1:
        raise ValueError(f"max_switches must be an integer >= 1, got {max_switches!r}")
    q, p = fl.encode(x, v)
    t = 0.0
    A = fl.active_set(q, p, t)
    on = np.zeros(system.m, dtype=bool)
    starts, actives, qs, ps, amps = [0.0], [A], [q], [p], []
    while len(starts) <= max_switches:
        ph = fl.phase(A)
        a = ph.amplitudes(q, p, t)
        amps.append(a)
        signals = ph.signals(a, t)
        hit = first_switch(signals, t_end - t, on)
        if hit is None:
            t = t_end
            break
        tau, j = hit
        q, p = ph.advance(a, t, tau)
        t += tau
        on = np.abs(signals.values(tau)[0][0]) <= SURFACE_RTOL * np.maximum(signals.magnitude, np.finfo(float).tiny)
        on[j] = True
        if on.sum() == 1:  # one contact switches: it changes status (the next flight checks it leaves its surface)
            A = A.copy()
            A[j] = not A[j]
        else:  # several on their surfaces at once: the rate-level complementarity problem decides
            A_new = fl.active_set(q, p, t)
            if np.array_equal(A_new, A):
                A_new = A.copy()
                A_new[j] = not A[j]
            A = A_new
        starts.append(t)
        actives.append(A)
        qs.append(q)
        ps.append(p)
    if len(amps) < len(starts):
        amps.append(fl.phase(A).amplitudes(q, p, starts[-1]))
    return NodalTrajectory(fl, np.array(starts), np.array(actives), np.array(qs).T, np.array(ps).T, t,
                           bool(t >= t_end), np.array(amps))
