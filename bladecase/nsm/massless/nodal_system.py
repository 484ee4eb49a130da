"""A structure touched at several contact nodes, each its own massless unilateral contact: :class:`NodalSystem`.

The model (``M x'' + C x' + S x + W λ = 0``, ``λ ≥ 0``, ``s = g(t) − Wᵀx + Hλ ≥ 0``, ``λᵀs = 0``) is described
in :mod:`bladecase.nsm.massless.nodes`, which flies it; here are its matrices and checks (:class:`NodalSystem`),
the complementarity problem that gives the contact forces of a state (:func:`lcp`), and the clearances seen by a
blade turning inside an out-of-round casing (:class:`Rub`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla
from scipy.optimize import nnls

__all__ = ["NODES_DENSE_LIMIT", "NodalSystem", "Profile", "Rub", "lcp"]

#: Largest interior size (dense phases).
NODES_DENSE_LIMIT = 4000


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


# ----------------------------------------------------------------------------- a general clearance profile


@dataclass(frozen=True, eq=False)
class Profile:
    """A clearance profile round the casing, piecewise constant over ``cells`` equal angular cells: the casing's
    surface lies ``depth[c]`` (m) further out than its shape elsewhere says in cell ``c`` (a worn coating). A blade
    turning at ``speed`` (rad/s) carries node ``j``, at the angle ``φ_j``, over the casing angle ``θ = Ωt + φ_j``:
    its clearance steps by ``depth[c] − depth[c−1]`` when ``θ`` crosses a cell's edge — an event time known in
    advance, where the exact flight is cut (:meth:`breaks`).

    >>> p = Profile([0.0, 1e-5, 1e-5, 0.0], speed=2 * np.pi, angles=[0.0, np.pi])
    >>> p.breaks(0.0, 1.0).tolist()          # node 0 enters cell 1 at t = 1/4, leaves cell 2 at 3/4; node 1 too
    [0.25, 0.75]
    >>> p.offset(np.array([0.3, 0.8])).round(9).tolist()   # (m, k): node 0, node 1 at t = 0.3 and 0.8
    [[1e-05, 0.0], [0.0, 1e-05]]
    """

    depth: np.ndarray
    speed: float
    angles: tuple = (0.0,)

    def __post_init__(self) -> None:
        d = np.asarray(self.depth, dtype=float).reshape(-1)
        if d.size < 1 or not np.all(np.isfinite(d)):
            raise ValueError(f"the profile's depths must be finite numbers (m), one per cell, got {d.size} cells")
        object.__setattr__(self, "depth", d)
        if isinstance(self.speed, bool) or not (np.isfinite(float(self.speed)) and float(self.speed) > 0):
            raise ValueError(f"speed must be a finite number > 0 (rad/s), got {self.speed!r}")
        object.__setattr__(self, "speed", float(self.speed))
        object.__setattr__(self, "angles", tuple(float(a) for a in np.atleast_1d(self.angles)))

    @property
    def step(self) -> float:
        """A cell's angle (rad)."""
        return 2 * np.pi / self.depth.size

    def cell(self, theta) -> np.ndarray:
        """The cell holding each casing angle ``theta`` (rad)."""
        n = self.depth.size
        return np.floor(np.mod(np.asarray(theta, dtype=float), 2 * np.pi) / self.step).astype(int) % n

    def offset(self, t) -> np.ndarray:
        """Each node's extra clearance at the times ``t``: ``(m,)`` or ``(m, k)`` (m)."""
        theta = np.add.outer(np.asarray(self.angles), self.speed * np.asarray(t, dtype=float))
        return self.depth[self.cell(theta)]

    def breaks(self, t0: float, t1: float) -> np.ndarray:
        """The times in ``(t0, t1)`` where some node's clearance steps (a cell edge with a different depth on each
        side), sorted, without repeats."""
        n, h = self.depth.size, self.step
        jump = np.flatnonzero(self.depth != np.roll(self.depth, 1))  # edge k: between cells k − 1 and k
        if jump.size == 0:
            return np.zeros(0)
        out = []
        for phi in self.angles:
            k0 = int(np.floor((self.speed * t0 + phi) / h)) + 1
            k1 = int(np.ceil((self.speed * t1 + phi) / h))
            k = np.arange(k0, k1)
            k = k[np.isin(k % n, jump)]
            out.append((k * h - phi) / self.speed)
        t = np.unique(np.concatenate(out))
        return t[(t > t0) & (t < t1)]
