"""The orthogonal-symmetry basis: mass-normalised coordinates and the impact law as a reflection (theory §2).

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
* Sparse ``M``: the LDLᵀ of :func:`bladecase.linalg.spd_factor` (SuperLU in
  symmetric mode without pivoting, minimum degree on ``M + Mᵀ``) gives
  ``Pᵀ M P = L D Lᵀ`` (``L`` unit lower triangular, ``D`` the pivots, all > 0
  for an SPD ``M``) and ``F = P L D^{1/2}``; ``F⁻¹`` and ``F⁻ᵀ`` are sparse
  triangular solves.
* Dense ``M``: Cholesky (also :func:`~bladecase.linalg.spd_factor`).

For a consistent mass the paper's per-dof law ``v_c⁺ = -v_c⁻`` is not
energy-preserving; :func:`per_dof_defect` measures by how much.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..fe import FEModel
from ..linalg import diagonal, spd_factor
from ..nsm import LinearSystem
from .contact import Contact

#: ``κ - 1 <= KAPPA_ROUNDOFF`` is round-off: ``κ = 1`` (the per-dof law is
#: exact), otherwise ``√(κ - 1) ≈ 1e-8`` would show as a spurious defect.
KAPPA_ROUNDOFF = 64 * np.finfo(float).eps


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

    Diagonal ``M``: ``F = M^{1/2}``.  Sparse ``M``: the LDLᵀ of
    :func:`bladecase.linalg.spd_factor`, ``Pᵀ M P = L D Lᵀ``; ``F = P L D^{1/2}``.
    Dense ``M``: Cholesky ``M = L Lᵀ``, ``F = L``.

    Raises
    ------
    ValueError
        ``M`` not square, or not positive definite (a pivot ``<= 0``, or
        the factorisation had to pivot off the diagonal).

    >>> import scipy.sparse as sp
    >>> M = sp.csr_array([[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]])
    >>> F = mass_factor(M)
    >>> F.kind, bool(np.allclose(F.matvec(F.rmatvec(np.eye(3))), M.toarray()))
    ('ldlt', True)
    """
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"M must be a square matrix, got shape {M.shape}")
    n = M.shape[0]
    diag = diagonal(M)
    if diag is not None:
        diag = np.asarray(diag, dtype=float)
        if np.any(~(diag > 0)):
            i = int(np.flatnonzero(~(diag > 0))[0])
            raise ValueError(f"M is not positive definite: diagonal entry M[{i},{i}] = {diag[i]:.6g} <= 0")
        return MassFactor("diagonal", n, np.sqrt(diag))
    factor = spd_factor(M, "M")
    if factor.kind == "dense":
        return MassFactor("cholesky", n, np.ones(n), factor.lower)
    L, pivots, perm = factor.ldlt()
    return MassFactor("ldlt", n, np.sqrt(pivots), L, perm)


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
        M, _, w, _ = operands(system_or_model, contact)
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


def operands(system_or_model, contact):
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

