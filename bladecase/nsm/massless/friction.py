"""Coulomb friction at the contact nodes of a :class:`~bladecase.nsm.massless.nodes.NodalSystem`, sliding dominated
by the rotation: :class:`Friction`, :func:`simulate_friction`.

**The model** (``model = "rotation"``). A tip node in contact slides along the casing at the blade speed ``ΩR``
(hundreds of m/s in an engine), far faster than it vibrates. The sliding direction is then the circumferential
one, fixed, whatever the vibration does: the casing drags each touching node with the force ``μλ_j`` along the
casing's motion relative to the tip. With ``T`` (``n × m``) the interior's generalised force per unit tangential
force on each node (as ``W`` is for the normal ones) the interior obeys

    M x'' + C x' + S x + (W − μT) λ = 0,

and the node's own compliance couples the two directions: the node's normal displacement under its forces is
``y = Wᵀx − H_sλ + μC_ntλ``, its tangential one ``z = Tᵀx − C_ntᵀλ + μC_ttλ`` (``C_nt = N_cᵀK_cc⁻¹T_c``,
``C_tt = T_cᵀK_cc⁻¹T_c``: the interior held). The contact law keeps its form with ``H_μ = H − μC_nt``:
``s = g(t) − Wᵀx + H_μλ ≥ 0``, ``λ ≥ 0``, ``λᵀs = 0``. Each contact phase (a set ``A`` of closed contacts) is
still LINEAR, ``λ_A = G_A(W_Aᵀx − g_A)`` with ``G_A = (H_μ)_AA⁻¹``, but its stiffness
``S + (W_A − μT_A)G_AW_Aᵀ`` is NOT symmetric: the phase is flown in closed form from the complex eigenvectors of
its first-order system (``x``, ``x'``: the reduced size, dense), with the harmonic particular solution of the
out-of-round casing, and its first switch found by the same certified search as without friction. A phase whose
non-symmetric stiffness makes it grow (friction-induced flutter, or divergence when the growing root is real) is
refused with a clear message: the certified
search needs decaying or neutral terms (the extended periodic motion concept of
:mod:`~bladecase.nsm.massless.friction_modes`, which feeds its phases on purpose, flies them with its own search).
The set of closed contacts at a switch solves the complementarity problem
with the non-symmetric ``H_μ`` (:func:`lemke`).

**When the assumption holds.** The direction of the friction is that of the sliding velocity
``ΩR_j − z'_j``; it is the circumferential one only where ``ΩR_j ≫ |z'_j|``. :func:`sliding_check` measures
``max|z'_j| / ΩR_j`` per node on a trajectory and says where it exceeds :data:`SLIDING_RATIO`.

**Friction off.** ``μ = 0`` (or ``friction=None``) flies the plain :class:`~bladecase.nsm.massless.nodes.NodalFlight`:
the results are those without friction, bit for bit.

>>> import numpy as np
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> s = NodalSystem(np.eye(2), np.diag([1.0, 2.0]), np.array([[1.0], [0.0]]), np.array([[0.05]]), gap=[1.0])
>>> f = Friction(0.15, T=np.array([[0.0], [1.0]]))     # node 0 moves along dof 0, slides along dof 1
>>> tr = simulate_friction(s, f, [2.0, 0.0], [0.0, 0.0], 20.0)
>>> bool(tr.switch_times.size >= 4), tr.active[1].tolist()
(True, [False])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .nodes import (
    EIGVEC_COND_LIMIT,
    NodalFlight,
    NodalSystem,
    NodalTrajectory,
    Rub,
    _Phase,
    phase_signals,
    simulate_nodes,
)

__all__ = ["FRICTION_MODELS", "SLIDING_RATIO", "Friction", "FrictionFlight", "SlidingCheck", "friction_flight",
           "lemke", "simulate_friction", "sliding_check"]

#: The friction models: ``"rotation"`` flown here, ``"coulomb"`` (stick–slip) by
#: :mod:`~bladecase.nsm.massless.friction_coulomb`.
FRICTION_MODELS = ("rotation", "coulomb")

#: ``max|z'_j| / ΩR_j`` above which the rotation-dominated sliding is not a safe assumption at node ``j``.
SLIDING_RATIO = 0.1

#: Relative size of a phase eigenvalue's positive real part above which the phase is refused (it grows: flutter).
FLUTTER_RTOL = 1e-9


@dataclass(frozen=True, eq=False)
class Friction:
    """Coulomb friction with rotation-dominated sliding (module docstring).

    Attributes
    ----------
    mu : float
        Friction coefficient (``>= 0``).
    T : (n, m) array_like
        The interior's generalised force per unit tangential force on each node, the tangent taken along the
        casing's motion relative to the tip (``Tᵀx``: the nodes' tangential displacements, contacts open).
    C_nt, C_tt : (m, m) array_like or None
        The nodes' own normal–tangential and tangential compliances, the interior held (m/N; ``None``: zero).
    radius : (m,) array_like or None
        Each node's radius about the engine axis (m), for :func:`sliding_check`.
    model : str
        ``"rotation"`` (flown here) or ``"coulomb"`` (stick–slip: :func:`~bladecase.nsm.massless.friction_coulomb.
        simulate_coulomb`): :data:`FRICTION_MODELS`.

    >>> Friction(0.15, T=np.ones((3, 2))).mu
    0.15
    >>> Friction(-0.1, T=np.ones((3, 2)))
    Traceback (most recent call last):
    ...
    ValueError: friction coefficient mu must be a finite number >= 0, got -0.1
    """

    mu: float
    T: np.ndarray
    C_nt: np.ndarray | None = None
    C_tt: np.ndarray | None = None
    radius: np.ndarray | None = None
    model: str = "rotation"

    def __post_init__(self) -> None:
        mu = self.mu
        number = isinstance(mu, (int, float, np.integer, np.floating)) and not isinstance(mu, bool)
        if not number or not np.isfinite(mu) or mu < 0:
            raise ValueError(f"friction coefficient mu must be a finite number >= 0, got {mu!r}")
        if self.model not in FRICTION_MODELS:
            raise ValueError(f"friction model {self.model!r} is not known (valid: {', '.join(FRICTION_MODELS)})")
        T = np.asarray(self.T, dtype=float)
        T = T.reshape(-1, 1) if T.ndim == 1 else T
        if T.ndim != 2 or not np.all(np.isfinite(T)):
            raise ValueError(f"T must be a finite (n, m) array, got shape {T.shape}")
        object.__setattr__(self, "T", T)
        m = T.shape[1]
        for name in ("C_nt", "C_tt"):
            C = getattr(self, name)
            C = np.zeros((m, m)) if C is None else np.asarray(C, dtype=float)
            if C.shape != (m, m) or not np.all(np.isfinite(C)):
                raise ValueError(f"{name} must be a finite ({m}, {m}) array, got shape {C.shape}")
            object.__setattr__(self, name, C if name == "C_nt" else 0.5 * (C + C.T))
        if self.radius is not None:
            r = np.broadcast_to(np.asarray(self.radius, dtype=float), (m,)).copy()
            if not np.all(np.isfinite(r) & (r > 0)):
                raise ValueError(f"radius must be finite and > 0 at every node, got {r.tolist()}")
            object.__setattr__(self, "radius", r)

    def check(self, system: NodalSystem) -> None:
        """``ValueError`` unless ``T`` matches ``system`` (``n`` interior dofs, ``m`` contacts)."""
        if self.T.shape != (system.n, system.m):
            raise ValueError(f"T of shape {self.T.shape} does not match the system's (n, m) = ({system.n}, "
                             f"{system.m})")

    def H(self, system: NodalSystem) -> np.ndarray:
        """``H_μ = H − μC_nt``: the (non-symmetric) flexibility the forces see."""
        return system.H - self.mu * self.C_nt

    def stored(self, system: NodalSystem) -> np.ndarray:
        """``H − μ(C_nt + C_ntᵀ) + μ²C_tt``: ``½λᵀ(·)λ`` is the energy stored in the nodes and the casing."""
        return system.H - self.mu * (self.C_nt + self.C_nt.T) + self.mu**2 * self.C_tt


def lemke(q, M, max_pivots: int | None = None) -> np.ndarray:
    """The ``z >= 0`` with ``w = q + Mz >= 0`` and ``zᵀw = 0`` (Lemke's complementary pivoting; ``M`` need not be
    symmetric — a P-matrix gives the one solution), polished on its support by a direct solve.

    >>> lemke(np.array([-1.0, 2.0]), np.array([[2.0, 0.3], [0.7, 1.0]])).round(12).tolist()
    [0.5, 0.0]
    """
    q, M = np.asarray(q, dtype=float), np.asarray(M, dtype=float)
    n = q.size
    if np.all(q >= 0):
        return np.zeros(n)
    sc = float(np.abs(M).max()) or 1.0  # the same z for (q, M) / sc: a tableau of numbers near 1
    tab = np.hstack([np.eye(n), -M / sc, -np.ones((n, 1)), q[:, None] / sc])
    basis = np.arange(n)
    tol = 1e-13

    def pivot(r: int, c: int) -> None:
        tab[r] /= tab[r, c]
        col = tab[:, c].copy()
        col[r] = 0.0
        tab[:] -= np.outer(col, tab[r])

    r, entering = int(np.argmin(q)), 2 * n
    for _ in range(max_pivots or 50 * n + 10):
        pivot(r, entering)
        leaving, basis[r] = basis[r], entering
        if leaving == 2 * n:
            break
        entering = leaving + n if leaving < n else leaving - n
        col = tab[:, entering]
        ok = col > tol
        if not ok.any():
            raise ValueError("the contact problem with friction has no solution (ray termination): the friction "
                             "coefficient is too large for these contacts' flexibility")
        ratio = np.where(ok, tab[:, -1] / np.where(ok, col, 1.0), np.inf)
        best = np.flatnonzero(ratio <= ratio.min() * (1 + 1e-12) + 1e-300)
        r = int(best[np.argmax(basis[best] == 2 * n)]) if np.any(basis[best] == 2 * n) else int(best[0])
    else:
        raise ValueError("the contact problem with friction did not converge (cycling)")
    z = np.zeros(n)
    for i, b in enumerate(basis):
        if n <= b < 2 * n:
            z[b - n] = max(tab[i, -1], 0.0)
    A = np.flatnonzero(z > 0)
    if A.size:
        z[A] = np.linalg.solve(M[np.ix_(A, A)], -q[A])
        z = np.maximum(z, 0.0)
    return z


def instability(lam: np.ndarray) -> str:
    """What the growing root of a phase's first-order eigenvalues ``lam`` is, in words: a flutter (complex: with its
    frequency) or a divergence (real: the stiffness lost its positiveness)."""
    top = lam[np.argmax(lam.real)]
    if abs(top.imag) > FLUTTER_RTOL * np.abs(lam).max():
        return f"friction-induced flutter, an oscillation of {abs(top.imag) / 2 / np.pi:.4g} Hz"
    return ("friction-induced divergence: the phase's stiffness is no longer positive, it drifts without "
            "oscillating")


def first_order_modes(K: np.ndarray, C: np.ndarray, what, growth: bool = False, vectors: bool = True):
    """The eigenvalues (and eigenvectors, ``vectors``) of a phase's first-order system ``x'' + Cx' + Kx = …``;
    unless ``growth`` (the extended periodic motion concept feeds its phases), a growing one is refused:
    ``ValueError`` naming the phase (``what()``), its growth rate and whether it is a flutter or a divergence."""
    n = K.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -C]])
    lam, V = np.linalg.eig(A) if vectors else (np.linalg.eigvals(A), None)
    grow = lam.real.max()
    if not growth and grow > FLUTTER_RTOL * np.abs(lam).max():
        raise ValueError(f"{what()} is unstable: it grows at {grow:.3g} 1/s ({instability(lam)}); the exact flight "
                         "needs decaying phases: add damping or lower mu")
    return lam, V


class _FrictionPhase(_Phase):
    """One set ``A`` of closed contacts with friction: non-symmetric, flown from its first-order eigenvectors."""

    def __init__(self, fl: FrictionFlight, A: np.ndarray):  # noqa: D107 - the same fields as _Phase
        s, fr = fl.system, fl.friction
        self.A = A
        m, n = s.m, fl.n
        Wq, Tq, H = fl.Wq, fl.Tq, fl.H_mu
        idx = np.flatnonzero(A)
        self.idx = idx
        K = np.diag(fl.omega**2)
        G = None
        if idx.size:
            WA = Wq[:, idx]
            G = np.linalg.inv(H[np.ix_(idx, idx)])
            drive = WA - fr.mu * Tq[:, idx]
            K = K + drive @ G @ WA.T
            self.GWt, self.G = G @ WA.T, G
            self.eq_map = np.linalg.solve(K, drive @ G)  # q_eq per unit gap_A
            self.q_eq = np.linalg.solve(K, drive @ (G @ s.gap[idx]))
        else:
            self.GWt, self.G, self.q_eq = np.zeros((0, n)), np.zeros((0, 0)), np.zeros(n)
            self.eq_map = np.zeros((n, 0))
        self.L, self.P = L, P = phase_signals(Wq, H, A, G)  # the switching signals, with H of the friction (H_mu)
        self.K = K
        C = fl.Cq if fl.Cq is not None else np.zeros((n, n))
        nu = fl.nu
        self.X = np.zeros(n, complex)
        if idx.size and nu > 0 and fl.D is not None:
            try:
                self.X = np.linalg.solve(K - nu**2 * np.eye(n) + 1j * nu * C, drive @ (G @ fl.D[idx]))
            except np.linalg.LinAlgError:
                raise ValueError(f"the casing's excitation at {nu / 2 / np.pi:.6g} Hz is at an undamped resonance "
                                 "of a contact phase with friction: add damping or change the speed") from None
        growth = getattr(fl, "allow_growth", False)  # the extended periodic motion concept feeds its phases
        lam, V = first_order_modes(K, C, lambda: f"a contact phase with friction (nodes {[s.nodes[k] for k in idx]} "
                                   f"closed, mu = {fr.mu:g})", growth)
        self._lu = sla.lu_factor(V)
        rcond = sla.lapack.zgecon(self._lu[0], np.abs(V).sum(axis=0).max())[0]
        if not rcond * EIGVEC_COND_LIMIT > 1:
            raise ValueError("a contact phase with friction is nearly defective (two of its modes coincide): change "
                             "mu or the damping slightly")
        self.lam = lam if growth else np.minimum(lam.real, 0.0) + 1j * lam.imag
        self.Vx, self.Vv = V[:n], V[n:]
        self._Vinv = sla.lu_solve(self._lu, np.eye(2 * n, dtype=complex))
        self._psi = None
        self.LVx = L @ self.Vx
        self.nu = nu
        self.const = L @ self.q_eq + P @ s.gap
        self.E0 = (L @ self.X + (P @ fl.D if fl.D is not None else 0)) if nu > 0 else np.zeros(m, complex)
        self.lam2 = np.abs(self.lam) ** 2


class FrictionFlight(NodalFlight):
    """Exact flights of a :class:`NodalSystem` with :class:`Friction` (module docstring): the phases are
    non-symmetric, the complementarity problem of a switch is solved by :func:`lemke`."""

    def __init__(self, system: NodalSystem, friction: Friction, damping=None, rub: Rub | None = None):
        super().__init__(system, damping, rub)
        if not isinstance(friction, Friction):
            raise ValueError(f"friction must be a Friction, got {type(friction).__name__}")
        friction.check(system)
        if friction.model != "rotation":
            raise ValueError(f"friction model {friction.model!r} is flown by bladecase.nsm.massless.friction_coulomb "
                             "(simulate_coulomb), not by FrictionFlight (the rotation model)")
        self.friction = friction
        self.Tq = self.phi.T @ friction.T
        self.H_mu = friction.H(system)

    def _new_phase(self, A: np.ndarray) -> _Phase:
        return _FrictionPhase(self, A)

    def active_set(self, q, p, t: float, on: np.ndarray | None = None) -> np.ndarray:
        """The closed contacts from the state: the complementarity problem with ``H_μ``, at the rate level where a
        contact is on its surface (as :meth:`NodalFlight.active_set`, Lemke's method for the non-symmetric ``H_μ``)."""
        return self.closed_set(self.H_mu, q, p, t, on, lemke, lemke)


def friction_flight(system: NodalSystem, friction: Friction | None, damping=None,
                    rub: Rub | None = None) -> NodalFlight:
    """The flight of ``system`` with ``friction``: a :class:`FrictionFlight`, or the plain
    :class:`~bladecase.nsm.massless.nodes.NodalFlight` when ``friction`` is ``None`` or ``μ = 0`` (bit for bit the
    results without friction).

    >>> s = NodalSystem(np.eye(2), np.eye(2), np.eye(2), 0.1 * np.eye(2), gap=[1.0, 1.0])
    >>> type(friction_flight(s, Friction(0.0, T=np.eye(2)))).__name__, type(friction_flight(s, None)).__name__
    ('NodalFlight', 'NodalFlight')
    """
    if friction is None or friction.mu == 0:
        if friction is not None:
            friction.check(system)
        return NodalFlight(system, damping, rub)
    return FrictionFlight(system, friction, damping, rub)


def simulate_friction(system: NodalSystem, friction: Friction | None, x0, v0, t_end: float, damping=None,
                      rub: Rub | None = None, max_switches: int = 1_000_000, profile=None) -> NodalTrajectory:
    """Exact event-driven simulation with friction from ``(x0, v0)`` at ``t = 0``: :func:`simulate_nodes` flying
    :func:`friction_flight` (the trajectory's forces ``λ`` are the normal ones; the friction forces are ``μλ``).

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[0.05]]), gap=[1.0])
    >>> tr = simulate_friction(s, Friction(0.2, T=[[0.5]]), [2.0], [0.0], 10.0)
    >>> tr.active[0].tolist(), bool(tr.complete)
    ([True], True)
    """
    fl = friction_flight(system, friction, damping, rub)
    return simulate_nodes(system, x0, v0, t_end, max_switches=max_switches, flight=fl, profile=profile)


@dataclass(frozen=True)
class SlidingCheck:
    """:func:`sliding_check`'s answer: per node, ``ratio_j = max|z'_j| / ΩR_j``; ``ok`` when every ratio is at most
    ``limit``; ``message`` says where the rotation-dominated sliding does not hold."""

    ratio: np.ndarray
    limit: float
    ok: bool
    message: str


def sliding_check(trajectory: NodalTrajectory, speed: float, t0: float = 0.0, t1: float | None = None,
                  samples: int = 2001, limit: float = SLIDING_RATIO) -> SlidingCheck:
    """Whether the sliding is rotation-dominated on ``trajectory`` at ``speed`` (rad/s): each node's largest
    tangential vibration velocity ``|z'_j|`` over ``[t0, t1]`` (``samples`` points and every switch) against its
    blade speed ``ΩR_j`` (``friction.radius``).

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[0.05]]), gap=[1.0])
    >>> f = Friction(0.2, T=[[0.5]], radius=[0.3])
    >>> tr = simulate_friction(s, f, [2.0], [0.0], 10.0)
    >>> c = sliding_check(tr, speed=1000.0)
    >>> c.ok, float(c.ratio[0].round(6))   # |x'| <= √22 (friction took μT·½k_c·1² = 1 J of 12), z' = x'/2
    (True, 0.007817)
    >>> bad = sliding_check(tr, speed=10.0)
    >>> bad.ok, bad.message[:83]
    (False, 'the sliding is not dominated by the rotation at nodes [0] (max |tangential velocity')
    """
    fl = trajectory.flight
    fr = getattr(fl, "friction", None)
    if fr is None or fr.radius is None:
        raise ValueError("sliding_check needs a trajectory flown with a Friction that gives each node's radius")
    if not (np.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    t1 = trajectory.t_end if t1 is None else t1
    t = np.union1d(np.linspace(t0, t1, samples), trajectory.starts[(trajectory.starts >= t0)
                                                                  & (trajectory.starts <= t1)])
    from .friction_energy import tangential_rates

    zdot = tangential_rates(trajectory, t)
    ratio = np.abs(zdot).max(axis=1) / (speed * fr.radius)
    bad = np.flatnonzero(ratio > limit)
    if bad.size == 0:
        return SlidingCheck(ratio, limit, True, "the sliding is dominated by the rotation at every node "
                                                f"(max |tangential velocity| / ΩR = {ratio.max():.3g} <= {limit:g})")
    nodes = [trajectory.system.nodes[k] for k in bad]
    return SlidingCheck(ratio, limit, False, f"the sliding is not dominated by the rotation at nodes {nodes} (max "
                        f"|tangential velocity| / ΩR = {ratio.max():.3g} > {limit:g}): the friction direction is not "
                        "the circumferential one there")
