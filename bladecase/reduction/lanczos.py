"""The Lanczos chain (theory §2): a structure with one contact as a spring–mass chain, contact on mass 1.

:func:`lanczos_chain` runs Lanczos on ``A = F⁻¹KF⁻ᵀ`` (``M = FFᵀ``) from ``q₁ = û`` with full
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

The mass factor and the symmetry basis it runs in are in
:mod:`~bladecase.reduction.symmetry` (re-exported here for the old import paths).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..checks import integer
from ..fe import FEModel
from ..linalg import SPDFactor, spd_factor, symmetric_factor
from ..nsm import LinearSystem
from .contact import Contact
from .symmetry import (
    KAPPA_ROUNDOFF,
    MassFactor,
    PerDofDefect,
    SymmetryBasis,
    mass_factor,
    operands,
    per_dof_defect,
    per_dof_law,
)

__all__ = [
    "BREAKDOWN_RTOL", "REORTH_PASSES", "LanczosChain", "chain_grounding", "chain_jacobi", "lanczos_chain",
    # moved to bladecase.reduction.symmetry (old import paths)
    "KAPPA_ROUNDOFF", "MassFactor", "PerDofDefect", "SymmetryBasis", "mass_factor", "per_dof_defect", "per_dof_law",
]

#: Lanczos stops (invariant subspace reached) when the next off-diagonal
#: ``β_j <= BREAKDOWN_RTOL · ‖A‖`` (``‖A‖`` estimated by the largest
#: ``‖A q_i‖ = (β_{i-1}² + α_i² + β_i²)^{1/2}`` so far).  Round-off leaves
#: ``β ≈ ε‖A‖√j`` when the contact sees no further mode.
BREAKDOWN_RTOL = 1e-12


#: Accepted values of ``reorth`` (number of full reorthogonalisation passes per step).
REORTH_PASSES = (0, 1, 2)


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

    Examples
    --------
    Two Lanczos steps on a 3-mass chain (:func:`lanczos_chain`): unit masses, the contact on the first:

    >>> from bladecase.nsm import chain
    >>> system = chain(3, k=1.0, m=1 / 3, gap=1.0)
    >>> lc = lanczos_chain(system, 2)
    >>> lc
    LanczosChain(lanczos, steps=2, n=3, |ŵ|=1.73205, gap=1, breakdown=False)
    >>> lc.masses.tolist(), lc.springs.round(9).tolist(), lc.grounding_springs.round(9).tolist()
    ([1.0, 1.0], [3.0], [0.0, 3.0])
    >>> lc.system, lc.system.w.round(6).tolist()               # |ŵ| = (wᵀM⁻¹w)^½ = √3
    (LinearSystem(n=2, dense, gap=1), [1.732051, 0.0])
    >>> V = lc.basis                                           # x ≈ V z, VᵀMV = I, VᵀKV = J
    >>> V.shape, bool(np.allclose(V.T @ system.M @ V, np.eye(2))), bool(np.allclose(V.T @ system.K @ V, lc.jacobi))
    ((3, 2), True, True)
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
    factor: SPDFactor | None = None,
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
    factor : SPDFactor or None
        A factorisation of ``K`` to reuse (:func:`bladecase.linalg.spd_factor`,
        :func:`bladecase.fe.stiffness_factor`): shift-invert with ``sigma = 0``
        only; computed here if ``None``.

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
        singular ``K - σM``, a ``factor`` of another size or with ``sigma != 0``.

    Notes
    -----
    No dense ``n × n`` matrix is formed for a sparse model: each step costs
    one product with ``K`` and two sparse triangular solves (plain), or one
    LU solve and one product with ``M`` (shift-invert), plus ``O(n·j)`` for
    the reorthogonalisation.

    Examples
    --------
    After ``n`` steps the chain is exact: its Jacobi matrix has the system's eigenvalues ``ω²``:

    >>> from bladecase.nsm import chain
    >>> system = chain(3, k=1.0, m=1 / 3, gap=1.0)
    >>> full = lanczos_chain(system, 3)
    >>> full.breakdown, np.linalg.eigvalsh(full.jacobi).round(6).tolist()
    (True, [0.594187, 4.664874, 9.740939])
    >>> (system.spectrum.omega**2).round(6).tolist()
    [0.594187, 4.664874, 9.740939]

    On a finite-element model (a 200-dof steel strip, contact at its free corner), 6 shift-invert steps
    give its first natural frequency; plain Lanczos converges to the highest modes first:

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble, natural_frequencies
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> contact = Contact.nearest(model, (0.1, 0.02), normal=(1.0, 0.0), gap=1e-4)
    >>> si = lanczos_chain(model, 6, contact, shift_invert=True)
    >>> si
    LanczosChain(shift-invert, sigma=0, steps=6, n=200, |ŵ|=70.9789, gap=0.0001, breakdown=False)
    >>> round(float(si.system.spectrum.frequencies[0]), 3), round(float(natural_frequencies(model, 1)[0]), 3)
    (1747.423, 1747.423)
    >>> round(float(lanczos_chain(model, 6, contact).system.spectrum.frequencies[0]), -3)
    135000.0
    >>> lanczos_chain(system, 4)
    Traceback (most recent call last):
        ...
    ValueError: steps must be an integer with 1 <= steps <= 3 (the number of dofs), got 4
    """
    M, K, w, gap = operands(system_or_model, contact)
    n = M.shape[0]
    steps = integer("steps", steps, 1, n, note=" (the number of dofs)")
    if isinstance(reorth, (bool, np.bool_)) or reorth not in REORTH_PASSES:
        raise ValueError(f"reorth must be one of {REORTH_PASSES} (full reorthogonalisation passes), got {reorth!r}")
    if shift_invert:
        return _shift_invert_chain(M, K, w, gap, steps, reorth, sigma, factor)
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


def _shift_invert_chain(M, K, w, gap, steps, reorth, sigma, factor) -> LanczosChain:
    try:
        sigma = float(sigma)
    except (TypeError, ValueError):
        raise ValueError(f"sigma must be a real number (a shift in units of ω²), got {sigma!r}") from None
    if not math.isfinite(sigma):
        raise ValueError(f"sigma must be finite, got {sigma!r}")
    solve = _shifted_solver(K, M, sigma, factor)

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


def _shifted_solver(K, M, sigma: float, factor: SPDFactor | None = None):
    """``b ↦ (K - σM)⁻¹b`` from one factorisation: SPD for ``σ <= 0`` (``factor`` of ``K`` reused for ``σ = 0``),
    symmetric indefinite for ``σ > 0`` (:mod:`bladecase.linalg`)."""
    if factor is not None:
        if sigma != 0 or not isinstance(factor, SPDFactor) or factor.n != K.shape[0]:
            raise ValueError(f"factor must be a factorisation of K ({K.shape[0]} × {K.shape[0]}) and is used with "
                             f"sigma = 0 only; got {factor!r} with sigma = {sigma!r}")
        return factor.solve
    A = K - sigma * M if sigma else K
    what = f"K - σM (sigma = {sigma!r})" if sigma else "K"
    hint = "sigma must not be an eigenvalue ω²"
    make = spd_factor if sigma <= 0 else symmetric_factor
    return make(A, what, hint=hint).solve
