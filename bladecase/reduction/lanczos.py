"""The orthogonal-symmetry basis and the Lanczos chain (theory §2).

Mass-normalised coordinates
---------------------------
Factor ``M = F Fᵀ`` (:func:`mass_factor`) and set ``y = Fᵀx``: the free flight
becomes ``y'' + A y = 0`` with ``A = F⁻¹ K F⁻ᵀ``, the gap ``d - ŵᵀy`` with
``ŵ = F⁻¹w``, and Moreau's impact law (restitution 1) the Householder
reflection ``H = I - 2ûûᵀ``, ``û = ŵ/|ŵ|`` — an orthogonal symmetry about
the hyperplane ``û⊥``.  In physical coordinates ``R = F⁻ᵀ H Fᵀ
= I - 2 M⁻¹w wᵀ/(wᵀM⁻¹w)``: an M-orthogonal involution for any SPD ``M``
(:class:`SymmetryBasis`).

* Diagonal (lumped) ``M``: ``F = M^{1/2}``.
* Sparse ``M``: scipy has no sparse Cholesky; SuperLU in symmetric mode without
  pivoting (minimum degree on ``M + Mᵀ``) gives ``Pᵀ M P = L D Lᵀ`` (``L`` unit
  lower triangular, ``D`` the pivots, all > 0 for an SPD ``M``) and
  ``F = P L D^{1/2}``; ``F⁻¹`` and ``F⁻ᵀ`` are sparse triangular solves.
* Dense ``M``: Cholesky.

For a consistent mass the paper's per-dof law ``v_c⁺ = -v_c⁻`` is not
energy-preserving; :func:`per_dof_defect` measures by how much.

The Lanczos chain
-----------------
:func:`lanczos_chain` runs Lanczos on ``A`` from ``q₁ = û`` with full
reorthogonalisation (twice by default), using sparse products and triangular
solves only.  ``m`` steps give ``AQ ≈ QJ``, ``J`` the ``m × m`` Jacobi matrix,
and the reduced model ``x ≈ V z``, ``V = F⁻ᵀQ`` (``VᵀMV = I``, ``VᵀKV = J``):
a spring–mass chain of unit masses with the contact on the FIRST mass, the
``m``-point Gauss quadrature of the contact spectral measure
``Σ_j b_j² δ(λ - ω_j²)`` (its first ``2m`` moments are exact).

The shift-invert variant (Nour-Omid & Clough 1984; Ericsson & Ruhe 1980) runs
M-inner-product Lanczos on ``(K - σM)⁻¹M`` from ``(K - σM)⁻¹w``: its Ritz
basis captures the modes near ``σ`` (the lowest ones for ``σ = 0``) and the
reduced model matches the moments ``Σ_j b_j² (ω_j² - σ)^{-p}``, ``p = 1..2m``.
The reduced ``(VᵀKV, Vᵀw)`` is then re-tridiagonalised from ``Vᵀw`` so the
result is again a chain with the contact on mass 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..fe import FEModel
from ..nsm.system import LinearSystem, _diagonal, _is_sparse
from .contact import Contact

#: Lanczos stops (invariant subspace reached) when the next off-diagonal
#: ``β_j <= BREAKDOWN_RTOL · ‖A‖`` (``‖A‖`` estimated by the largest
#: ``‖A q_i‖ = (β_{i-1}² + α_i² + β_i²)^{1/2}`` so far).  Round-off leaves
#: ``β ≈ ε‖A‖√j`` when the contact sees no further mode.
BREAKDOWN_RTOL = 1e-12

#: ``κ - 1 <= KAPPA_ROUNDOFF`` is round-off: ``κ = 1`` (the per-dof law is
#: exact), otherwise ``√(κ - 1) ≈ 1e-8`` would show as a spurious defect.
KAPPA_ROUNDOFF = 64 * np.finfo(float).eps

#: Accepted values of ``reorth`` (number of full reorthogonalisation passes per step).
REORTH_PASSES = (0, 1, 2)


# ============================================================================ M = F Fᵀ


@dataclass(frozen=True, eq=False)
class MassFactor:
    """A factor ``F`` of the mass matrix, ``M = F Fᵀ``.

    Attributes
    ----------
    kind : str
        ``"diagonal"`` (``F = M^{1/2}``), ``"ldlt"`` (sparse, ``F = P L D^{1/2}``)
        or ``"cholesky"`` (dense, ``F`` lower triangular).
    n : int
        Size of ``M``.

    The four operators act on vectors or on ``(n, k)`` blocks of columns.
    """

    kind: str
    n: int
    _sqrt_d: np.ndarray = field(repr=False)  # D^{1/2} (diagonal / ldlt), unused for cholesky
    _L: object = field(repr=False, default=None)  # csc unit lower (ldlt) or dense lower (cholesky)
    _perm: np.ndarray | None = field(repr=False, default=None)  # ldlt: (Pᵀx)[perm] = x

    def solve(self, x: np.ndarray) -> np.ndarray:
        """``F⁻¹x`` (physical → mass-normalised, for forces: ``ŵ = F⁻¹w``)."""
        x = np.asarray(x, dtype=float)
        if self.kind == "diagonal":
            return _scale_rows(x, 1.0 / self._sqrt_d)
        if self.kind == "cholesky":
            return sla.solve_triangular(self._L, x, lower=True)
        z = np.empty_like(x)
        z[self._perm] = x  # Pᵀx
        z = spla.spsolve_triangular(self._L, z, lower=True, unit_diagonal=True, overwrite_A=True, overwrite_b=True)
        return _scale_rows(z, 1.0 / self._sqrt_d)

    def solve_t(self, y: np.ndarray) -> np.ndarray:
        """``F⁻ᵀy`` (mass-normalised → physical displacements: ``x = F⁻ᵀy``)."""
        y = np.asarray(y, dtype=float)
        if self.kind == "diagonal":
            return _scale_rows(y, 1.0 / self._sqrt_d)
        if self.kind == "cholesky":
            return sla.solve_triangular(self._L, y, lower=True, trans="T")
        z = _scale_rows(y, 1.0 / self._sqrt_d)
        z = spla.spsolve_triangular(self._L.T, z, lower=False, unit_diagonal=True, overwrite_A=True, overwrite_b=True)
        return z[self._perm]  # P z

    def matvec(self, y: np.ndarray) -> np.ndarray:
        """``F y``."""
        y = np.asarray(y, dtype=float)
        if self.kind == "diagonal":
            return _scale_rows(y, self._sqrt_d)
        if self.kind == "cholesky":
            return self._L @ y
        return (self._L @ _scale_rows(y, self._sqrt_d))[self._perm]

    def rmatvec(self, x: np.ndarray) -> np.ndarray:
        """``Fᵀx`` (physical → mass-normalised displacements: ``y = Fᵀx``)."""
        x = np.asarray(x, dtype=float)
        if self.kind == "diagonal":
            return _scale_rows(x, self._sqrt_d)
        if self.kind == "cholesky":
            return self._L.T @ x
        z = np.empty_like(x)
        z[self._perm] = x
        return _scale_rows(self._L.T @ z, self._sqrt_d)


def _scale_rows(x: np.ndarray, s: np.ndarray) -> np.ndarray:
    return x * s if x.ndim == 1 else x * s[:, None]


def mass_factor(M) -> MassFactor:
    """Factor an SPD mass matrix as ``M = F Fᵀ`` (dense or scipy sparse).

    Diagonal ``M``: ``F = M^{1/2}``.  Sparse ``M``: SuperLU with
    ``permc_spec="MMD_AT_PLUS_A"``, ``diag_pivot_thresh=0`` and
    ``SymmetricMode``, so that ``Pᵀ M P = L U`` with ``U = D Lᵀ``; ``F = P L D^{1/2}``.
    Dense ``M``: Cholesky ``M = L Lᵀ``, ``F = L``.

    Raises
    ------
    ValueError
        ``M`` not square, or not positive definite (a pivot ``<= 0``, or
        SuperLU had to pivot off the diagonal).
    """
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"M must be a square matrix, got shape {M.shape}")
    n = M.shape[0]
    diag = _diagonal(M)
    if diag is not None:
        diag = np.asarray(diag, dtype=float)
        if np.any(~(diag > 0)):
            i = int(np.flatnonzero(~(diag > 0))[0])
            raise ValueError(f"M is not positive definite: diagonal entry M[{i},{i}] = {diag[i]:.6g} <= 0")
        return MassFactor("diagonal", n, np.sqrt(diag))
    if not _is_sparse(M):
        try:
            L = np.linalg.cholesky(np.asarray(M, dtype=float))
        except np.linalg.LinAlgError:
            raise ValueError("M is not positive definite (dense Cholesky failed)") from None
        return MassFactor("cholesky", n, np.ones(n), L)
    try:
        lu = spla.splu(
            sp.csc_array(M, dtype=float),
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
    except RuntimeError as exc:
        raise ValueError(f"M is singular, hence not positive definite ({exc})") from None
    pivots = lu.U.diagonal()
    if not np.array_equal(lu.perm_r, lu.perm_c):
        raise ValueError("M is not positive definite: its LDLᵀ factorisation needed off-diagonal pivoting")
    if np.any(~(pivots > 0)):
        raise ValueError(f"M is not positive definite: its LDLᵀ factorisation has a pivot {pivots.min():.6g} <= 0")
    L = sp.csc_array(lu.L)
    L.sum_duplicates()
    L.sort_indices()
    return MassFactor("ldlt", n, np.sqrt(pivots), L, np.asarray(lu.perm_c))


# ============================================================================ symmetry basis


@dataclass(frozen=True)
class PerDofDefect:
    """How far the paper's per-dof impact law is from energy-preserving.

    The per-dof law reflects the normal velocity of the contact node and
    leaves every other velocity unchanged: ``v⁺ = P v⁻``,
    ``P = I - 2nnᵀ``, ``n = w/|w|`` (for ``w = e_c`` exactly the paper's
    ``v_c⁺ = -v_c⁻``).  It preserves the kinetic energy ``½vᵀMv`` for every
    ``v`` iff ``n`` is an eigenvector of ``M`` (diagonal/lumped mass); in general
    the ratio ``T⁺/T⁻`` ranges over ``[1/ρ, ρ]``,
    ``ρ = (√κ + √(κ-1))²``, ``κ = (nᵀMn)(nᵀM⁻¹n) >= 1`` (a closed form: ``PᵀMP - M``
    has rank 2).  The Moreau law (:meth:`SymmetryBasis.reflect`) has ``T⁺ = T⁻``
    always.

    Attributes
    ----------
    kappa : float
        ``κ = (nᵀMn)(nᵀM⁻¹n)`` (1 for a lumped mass).
    max_gain : float
        Largest relative energy change ``T⁺/T⁻ - 1 = ρ - 1`` over all pre-impact velocities.
    max_loss : float
        Largest relative energy loss ``1 - 1/ρ``.
    impulse_gain : float
        Relative energy change ``4(κ - 1)`` for a unit normal impact of the
        structure moving as an impulse on the contact sets it moving
        (``v⁻ ∝ M⁻¹w``, the direction the Moreau law acts along).
    """

    kappa: float
    max_gain: float
    max_loss: float
    impulse_gain: float


def per_dof_law(v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The paper's per-dof impact law ``v⁺ = v - 2 w (wᵀv)/(wᵀw)`` (columns of ``v`` if 2-D).

    With ``w = e_c``: ``v_c⁺ = -v_c⁻``, other velocities unchanged.  Not
    energy-preserving for a non-diagonal ``M``: see :func:`per_dof_defect`.
    """
    v = np.asarray(v, dtype=float)
    w = np.asarray(w, dtype=float)
    return v - 2.0 * np.multiply.outer(w, w @ v) / (w @ w)


def per_dof_defect(M, w: np.ndarray, factor: MassFactor | None = None) -> PerDofDefect:
    """Energy defect of the per-dof law for mass ``M`` and constraint ``w`` (see :class:`PerDofDefect`)."""
    w = np.asarray(w, dtype=float)
    factor = mass_factor(M) if factor is None else factor
    n = w / np.linalg.norm(w)
    z = factor.solve(n)
    kappa = float(n @ (M @ n)) * float(z @ z)  # >= 1 by Cauchy–Schwarz
    if kappa - 1.0 <= KAPPA_ROUNDOFF:  # n an eigenvector of M (lumped mass): exactly 1
        kappa = 1.0
    rho = (math.sqrt(kappa) + math.sqrt(kappa - 1.0)) ** 2
    return PerDofDefect(kappa=kappa, max_gain=rho - 1.0, max_loss=1.0 - 1.0 / rho, impulse_gain=4.0 * (kappa - 1.0))


class SymmetryBasis:
    """Mass-normalised coordinates and the impact law as an orthogonal symmetry.

    ``y = Fᵀx`` with ``M = F Fᵀ`` (:func:`mass_factor`); ``ŵ = F⁻¹w``,
    ``û = ŵ/|ŵ|``; the impact law is ``H = I - 2ûûᵀ`` on ``y`` and the Moreau
    map ``R = I - 2 M⁻¹w wᵀ/(wᵀM⁻¹w)`` on physical velocities.

    Parameters
    ----------
    M : (n, n) array_like or scipy sparse
        SPD mass matrix.
    w : (n,) array_like
        Constraint vector (non-zero).

    Attributes
    ----------
    factor : MassFactor
    w : (n,) ndarray
    w_hat : (n,) ndarray
        ``ŵ = F⁻¹w``.
    w_hat_norm : float
        ``|ŵ| = (wᵀM⁻¹w)^{1/2}``.
    u_hat : (n,) ndarray
        ``û = ŵ/|ŵ|``.
    """

    def __init__(self, M, w: np.ndarray, factor: MassFactor | None = None):
        w = np.asarray(w, dtype=float).reshape(-1)
        if w.shape != (M.shape[0],):
            raise ValueError(f"w has {w.size} entries, expected {M.shape[0]} (one per dof)")
        if not np.all(np.isfinite(w)) or not np.any(w):
            raise ValueError("w must be a finite, non-zero vector")
        self.M = M
        self.factor = mass_factor(M) if factor is None else factor
        self.w = w
        self.w_hat = self.factor.solve(w)
        self.w_hat_norm = float(np.linalg.norm(self.w_hat))
        self.u_hat = self.w_hat / self.w_hat_norm
        self._m_inv_w = self.factor.solve_t(self.w_hat)  # M⁻¹w = F⁻ᵀF⁻¹w

    @classmethod
    def of(cls, system_or_model: LinearSystem | FEModel, contact: Contact | None = None) -> SymmetryBasis:
        """The basis of a :class:`LinearSystem`, or of an :class:`FEModel` with a :class:`Contact`."""
        M, _, w, _ = _operands(system_or_model, contact)
        return cls(M, w)

    @property
    def n(self) -> int:
        """Number of dofs."""
        return self.w.size

    @property
    def m_inv_w(self) -> np.ndarray:
        """``M⁻¹w``: the velocity jump direction of the Moreau law."""
        return self._m_inv_w

    def to_y(self, x: np.ndarray) -> np.ndarray:
        """Mass-normalised coordinates ``y = Fᵀx`` (``|y|² = xᵀMx``)."""
        return self.factor.rmatvec(x)

    def to_x(self, y: np.ndarray) -> np.ndarray:
        """Physical coordinates ``x = F⁻ᵀy``."""
        return self.factor.solve_t(y)

    def householder(self, y: np.ndarray) -> np.ndarray:
        """``H y = y - 2û(ûᵀy)`` in mass-normalised coordinates (columns of ``y`` if 2-D)."""
        y = np.asarray(y, dtype=float)
        return y - 2.0 * np.multiply.outer(self.u_hat, self.u_hat @ y)

    def reflect(self, v: np.ndarray) -> np.ndarray:
        """The Moreau impact map (restitution 1) on physical velocities: ``F⁻ᵀ H Fᵀ v``.

        ``v⁺ = v - 2 M⁻¹w (wᵀv)/(wᵀM⁻¹w)``: M-orthogonal (``RᵀMR = M``) and
        involutive (``R² = I``); energy-preserving for any SPD ``M``.
        """
        v = np.asarray(v, dtype=float)
        return v - 2.0 * np.multiply.outer(self._m_inv_w, self.w @ v) / self.w_hat_norm**2

    def per_dof_defect(self) -> PerDofDefect:
        """Energy defect of the paper's per-dof law for this ``M`` and ``w`` (:func:`per_dof_defect`)."""
        return per_dof_defect(self.M, self.w, self.factor)


# ============================================================================ the Lanczos chain


@dataclass(frozen=True, eq=False)
class LanczosChain:
    """A Lanczos chain: the reduced model ``x ≈ V z`` as unit masses and springs, contact on mass 1.

    Attributes
    ----------
    alpha : (m,) ndarray
        Diagonal of the Jacobi matrix ``J``.
    beta : (m-1,) ndarray
        Off-diagonal ``J_{i,i+1}`` — negative: alternate Lanczos vectors are
        sign-flipped so that the coupling springs ``-J_{i,i+1}`` are > 0.
    basis : (n, m) ndarray
        ``V``: physical displacements ``x ≈ V z`` (``VᵀMV = I``, ``VᵀKV = J``
        to round-off, ``Vᵀw = |ŵ| e₁``).
    w_hat_norm : float
        Contact weight ``|ŵ|`` of the chain: ``wᵀx = |ŵ| z₁``.  For plain
        Lanczos ``|ŵ| = (wᵀM⁻¹w)^{1/2}``; for shift-invert ``|Vᵀw|``.
    gap : float
        Clearance ``d`` (unchanged: the chain's constraint is ``|ŵ| z₁ <= d``).
    breakdown : bool
        True when the Krylov space became invariant: Lanczos stopped after
        :attr:`observable_dimension` steps (possibly fewer than asked), and
        the chain is exact for the contact dynamics.  Always True after ``n``
        steps.
    observable_dimension : int or None
        On breakdown, the number of distinct frequencies the contact sees
        (the chain length); ``None`` otherwise (it is then ``> steps``).

        In floating point, modes that are unobservable only through a
        symmetry of the model (e.g. the antisymmetric modes of a
        mirror-symmetric blade seen from a node on the mirror plane) are
        usually NOT detected: round-off seeds them and Lanczos amplifies them
        (measured: by about ``10^0.3`` per step, ``O(1)`` after ~50 steps), so
        no breakdown occurs and the chain also carries them, with weights
        ``b_j²`` at round-off level (``<= 1e-12 |ŵ|`` measured).
        ``system.spectrum.active`` flags them inactive and the contact
        dynamics are unaffected; only chain masses are spent on them.
        Structurally unobservable modes (uncoupled parts) give an exact breakdown.
    method : str
        ``"lanczos"`` or ``"shift-invert"``.
    sigma : float or None
        Shift of the shift-invert variant.
    """

    alpha: np.ndarray
    beta: np.ndarray
    basis: np.ndarray = field(repr=False)
    w_hat_norm: float
    gap: float
    breakdown: bool
    observable_dimension: int | None
    method: str = "lanczos"
    sigma: float | None = None

    @property
    def steps(self) -> int:
        """Number of Lanczos steps done = chain length ``m``."""
        return int(self.alpha.size)

    @property
    def jacobi(self) -> np.ndarray:
        """The ``m × m`` Jacobi matrix ``J`` (dense)."""
        return np.diag(self.alpha) + np.diag(self.beta, 1) + np.diag(self.beta, -1)

    @property
    def masses(self) -> np.ndarray:
        """Chain masses: all 1 (the chain coordinates are mass-normalised)."""
        return np.ones(self.steps)

    @property
    def springs(self) -> np.ndarray:
        """Coupling springs ``s_i = -J_{i,i+1} > 0`` between masses ``i`` and ``i+1``."""
        return -self.beta

    @property
    def grounding_springs(self) -> np.ndarray:
        """Grounding springs ``g_i = J_ii + J_{i,i-1} + J_{i,i+1}`` (row sums of ``J``).

        ``J_ii = g_i + s_{i-1} + s_i``.  Individual ``g_i`` may be negative;
        the chain as a whole is positive definite.
        """
        return chain_grounding(self.alpha, self.beta)

    @cached_property
    def system(self) -> LinearSystem:
        """``LinearSystem(I, J, |ŵ| e₁, gap)``: the chain the core solver consumes.

        The contact is on the FIRST mass with the physical gap ``d`` and
        weight ``|ŵ|`` (equivalently a unit ``w`` and gap ``d/|ŵ|``); impulses
        ``Λ`` are the physical ones.
        """
        w = np.zeros(self.steps)
        w[0] = self.w_hat_norm
        return LinearSystem(np.eye(self.steps), self.jacobi, w, self.gap)

    def expand(self, z: np.ndarray) -> np.ndarray:
        """Physical dofs ``x = V z`` from chain coordinates (columns of ``z`` if 2-D)."""
        return self.basis @ np.asarray(z, dtype=float)

    def __repr__(self) -> str:
        shift = f", sigma={self.sigma:g}" if self.sigma is not None else ""
        seen = f", observable_dimension={self.observable_dimension}" if self.breakdown else ""
        return (
            f"LanczosChain({self.method}{shift}, steps={self.steps}, n={self.basis.shape[0]}, "
            f"|ŵ|={self.w_hat_norm:.6g}, gap={self.gap:g}, breakdown={self.breakdown}{seen})"
        )


def chain_grounding(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Grounding springs ``J_ii + J_{i,i-1} + J_{i,i+1}`` of a Jacobi matrix given by its bands."""
    g = np.array(alpha, dtype=float)
    g[:-1] += beta
    g[1:] += beta
    return g


def chain_jacobi(springs: np.ndarray, grounding: np.ndarray) -> np.ndarray:
    """The stiffness of a unit-mass chain: ``J_ii = g_i + s_{i-1} + s_i``, ``J_{i,i+1} = -s_i``."""
    s = np.asarray(springs, dtype=float)
    g = np.asarray(grounding, dtype=float)
    if s.size != g.size - 1:
        raise ValueError(f"a chain of {g.size} masses has {g.size - 1} coupling springs, got {s.size}")
    d = g.copy()
    d[:-1] += s
    d[1:] += s
    return np.diag(d) - np.diag(s, 1) - np.diag(s, -1)


def _operands(system_or_model, contact):
    """``(M, K, w, gap)`` of a LinearSystem, or of an FEModel with its Contact."""
    if isinstance(system_or_model, LinearSystem):
        if contact is not None:
            raise ValueError("contact must be None for a LinearSystem (its w and gap already define the contact)")
        s = system_or_model
        return s.M, s.K, np.asarray(s.w, dtype=float), s.gap
    if isinstance(system_or_model, FEModel):
        if not isinstance(contact, Contact):
            raise ValueError(
                f"an FEModel needs a contact (bladecase.Contact), got {type(contact).__name__}; "
                "e.g. Contact.farthest(model, (-1, 0, 0), gap=1e-4)"
            )
        return system_or_model.M, system_or_model.K, contact.w(system_or_model), contact.gap
    raise ValueError(
        f"lanczos_chain needs a LinearSystem or an FEModel (with a Contact), got {type(system_or_model).__name__}"
    )


def _lanczos(op, v1: np.ndarray, steps: int, reorth: int, mass=None):
    """Lanczos with full reorthogonalisation in the inner product ``⟨a, b⟩ = aᵀ B b``.

    ``op`` is self-adjoint for ``B`` (``B = I`` if ``mass`` is None, else
    ``B = mass``); ``v1`` is ``B``-normalised.  Returns ``(alpha, beta, V,
    breakdown)`` with ``len(beta) = len(alpha) - 1``, ``β_j > 0``.
    """
    n = v1.size
    V = np.empty((n, steps), order="F")
    BV = V if mass is None else np.empty((n, steps), order="F")
    alpha = np.zeros(steps)
    beta = np.zeros(steps)
    v, Bv = v1, (v1 if mass is None else mass @ v1)
    anorm = 0.0
    done, breakdown = steps, False
    for j in range(steps):
        V[:, j] = v
        if mass is not None:
            BV[:, j] = Bv
        r = op(v)
        if j:
            r -= beta[j - 1] * V[:, j - 1]
        a = float(Bv @ r)
        r -= a * v
        for _ in range(reorth):
            h = BV[:, : j + 1].T @ r
            r -= V[:, : j + 1] @ h
            a += h[j]
        alpha[j] = a
        Br = r if mass is None else mass @ r
        b = math.sqrt(max(float(r @ Br), 0.0))
        anorm = max(anorm, math.sqrt(a * a + b * b + (beta[j - 1] ** 2 if j else 0.0)))
        if j + 1 == n or b <= BREAKDOWN_RTOL * anorm:
            done, breakdown = j + 1, True
            break
        beta[j] = b
        v, Bv = r / b, Br / b
    return alpha[:done], beta[: done - 1], V[:, :done], breakdown


def _check_steps(steps, n: int) -> int:
    if isinstance(steps, (bool, np.bool_)) or not isinstance(steps, (int, np.integer)) or not 1 <= steps <= n:
        raise ValueError(f"steps must be an integer with 1 <= steps <= {n} (the number of dofs), got {steps!r}")
    return int(steps)


def _alternate(m: int) -> np.ndarray:
    """Signs ``+1, -1, +1, …`` that make the Jacobi off-diagonals negative."""
    return np.where(np.arange(m) % 2 == 0, 1.0, -1.0)


def lanczos_chain(
    system_or_model: LinearSystem | FEModel,
    steps: int,
    contact: Contact | None = None,
    reorth: int = 2,
    shift_invert: bool = False,
    sigma: float = 0.0,
) -> LanczosChain:
    """Reduce a structure with one contact to a Lanczos chain (theory §2).

    Parameters
    ----------
    system_or_model : LinearSystem or FEModel
        A system (its ``M``, ``K``, ``w``, ``gap``; dense or sparse), or a
        finite-element model with ``contact``.
    steps : int
        Lanczos steps ``m``, ``1 <= m <= n``: the chain length (fewer on breakdown).
    contact : Contact or None
        Required with an FEModel, must be None with a LinearSystem.
    reorth : {2, 1, 0}
        Full reorthogonalisation passes per step (2: "twice is enough";
        0: plain three-term recurrence, which loses orthogonality).
    shift_invert : bool
        False (default): Lanczos on ``A = F⁻¹KF⁻ᵀ`` from ``û`` — the ``m``-point
        Gauss quadrature of the contact spectral measure (moments
        ``Σ b_j² ω_j^{2p}``, ``p < 2m``, exact).  True: M-inner-product Lanczos
        on ``(K - σM)⁻¹M`` from ``(K - σM)⁻¹w`` (one sparse LU of ``K - σM``),
        which converges to the modes nearest ``σ`` first and matches the
        low-frequency moments ``Σ b_j² (ω_j² - σ)^{-p}``, ``p = 1..2m``; the
        reduced ``(VᵀKV, Vᵀw)`` is re-tridiagonalised into a chain.
    sigma : float
        Shift (rad²/time², the units of ``ω²``) of the shift-invert variant;
        must not be an eigenvalue.  ``0`` targets the lowest modes.

    Returns
    -------
    LanczosChain
        Jacobi matrix, basis ``V``, the chain's springs, and its
        :attr:`~LanczosChain.system` for the nonsmooth-mode solver.

    Raises
    ------
    ValueError
        Wrong input types, a missing or superfluous contact, ``steps`` out of
        ``1..n``, ``reorth`` not 0, 1 or 2, ``M`` not positive definite, a
        singular ``K - σM``.

    Notes
    -----
    No dense ``n × n`` matrix is formed for a sparse model: each step costs
    one product with ``K`` and two sparse triangular solves (plain), or one
    LU solve and one product with ``M`` (shift-invert), plus ``O(n·j)`` for
    the reorthogonalisation.
    """
    M, K, w, gap = _operands(system_or_model, contact)
    n = M.shape[0]
    steps = _check_steps(steps, n)
    if isinstance(reorth, (bool, np.bool_)) or reorth not in REORTH_PASSES:
        raise ValueError(f"reorth must be one of {REORTH_PASSES} (full reorthogonalisation passes), got {reorth!r}")
    if shift_invert:
        return _shift_invert_chain(M, K, w, gap, steps, reorth, sigma)
    basis = SymmetryBasis(M, w)
    F = basis.factor
    V = np.empty((n, steps), order="F")  # V[:, j] = F⁻ᵀq_j, computed by the product with A anyway
    count = [0]

    def op(q):
        v = F.solve_t(q)
        V[:, count[0]] = v
        count[0] += 1
        return F.solve(K @ v)

    alpha, b, _, breakdown = _lanczos(op, basis.u_hat, steps, reorth)
    m = alpha.size
    V = V[:, :m] * _alternate(m)
    return LanczosChain(
        alpha=alpha, beta=-b, basis=V, w_hat_norm=basis.w_hat_norm, gap=gap,
        breakdown=breakdown, observable_dimension=m if breakdown else None,
    )


def _shift_invert_chain(M, K, w, gap, steps, reorth, sigma) -> LanczosChain:
    try:
        sigma = float(sigma)
    except (TypeError, ValueError):
        raise ValueError(f"sigma must be a real number (a shift in units of ω²), got {sigma!r}") from None
    if not math.isfinite(sigma):
        raise ValueError(f"sigma must be finite, got {sigma!r}")
    solve = _shifted_solver(K, M, sigma)

    def op(v):
        return solve(M @ v)

    v1 = solve(w)
    nv = math.sqrt(float(v1 @ (M @ v1)))
    if not nv > 0 or not math.isfinite(nv):
        raise ValueError(f"(K - σM)⁻¹w has M-norm {nv!r} for sigma = {sigma!r}: cannot start the shift-invert Lanczos")
    _, _, V, breakdown = _lanczos(op, v1 / nv, steps, reorth, mass=M)
    p = V.shape[1]
    # Reduced model (VᵀMV = I): Kr = VᵀKV, wr = Vᵀw; re-tridiagonalise from wr.
    Kr = V.T @ (K @ V)
    Kr = 0.5 * (Kr + Kr.T)
    wr = V.T @ w
    wr_norm = float(np.linalg.norm(wr))
    alpha, b, Qr, _ = _lanczos(lambda q: Kr @ q, wr / wr_norm, p, max(reorth, 1))
    m = alpha.size
    basis = V @ (Qr * _alternate(m))
    return LanczosChain(
        alpha=alpha, beta=-b, basis=basis, w_hat_norm=wr_norm, gap=gap,
        breakdown=breakdown, observable_dimension=m if breakdown else None,
        method="shift-invert", sigma=sigma,
    )


def _shifted_solver(K, M, sigma: float):
    """``b ↦ (K - σM)⁻¹b`` from one factorisation (sparse LU or dense LU)."""
    A = K - sigma * M if sigma else K
    what = f"K - σM (sigma = {sigma!r})" if sigma else "K"
    if _is_sparse(A):
        try:
            lu = spla.splu(
                sp.csc_array(A, dtype=float),
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0 if sigma <= 0 else 0.1,
                options={"SymmetricMode": True},
            )
        except RuntimeError as exc:
            raise ValueError(f"{what} is singular ({exc}): sigma must not be an eigenvalue ω²") from None
        return lu.solve
    A = np.asarray(A, dtype=float)
    lu, piv = sla.lu_factor(A, check_finite=False)
    if np.any(np.diag(lu) == 0):
        raise ValueError(f"{what} is singular: sigma must not be an eigenvalue ω²")
    return lambda b: sla.lu_solve((lu, piv), b, check_finite=False)
