"""The linear system that travels between stages, and its contact spectral data.

A :class:`LinearSystem` is the one small object every stage exchanges: the
mass and stiffness matrices of the free flight ``M x'' + K x = 0`` and the
unilateral constraint ``wᵀx <= gap``.  Whether it came from a spring–mass
chain, a reduced finite-element model or a user's own matrices, the
nonsmooth-mode solver only ever sees this object.

Its :attr:`LinearSystem.spectrum` (frequencies, M-normalised modes and contact
participations ``b_j = wᵀφ_j``) is computed once, on first use, and cached.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..checks import SINGULAR_RTOL as SINGULAR_RTOL  # re-exported: the tolerances of the checks below
from ..checks import SYMMETRY_RTOL as SYMMETRY_RTOL
from ..checks import numbers, symmetric
from ..linalg import positive_definite

ArrayLike = np.ndarray | sp.spmatrix | sp.sparray

# SYMMETRY_RTOL (1e-10): ``max|A - Aᵀ| <= SYMMETRY_RTOL * max|A|`` for M and K; SINGULAR_RTOL (1e-12): M and K
# are refused as singular to working precision when an upper bound of their smallest eigenvalue (the smallest
# Cholesky pivot; a Rayleigh quotient of inverse iteration with the sparse LDLᵀ) is below that fraction of their
# largest diagonal entry (both from :mod:`bladecase.checks`).

#: Scales a system may have: ``gap``, ``max|M|``, ``max|K|`` and ``max|w|`` within
#: ``[1 / SCALE_LIMIT, SCALE_LIMIT]``.  Beyond, energies (``~ K gap²``) and frequencies
#: (``~ K / M``) overflow or lose precision in double arithmetic: rescale the units instead.
SCALE_LIMIT = 1e80

#: Largest model whose spectrum is computed densely.  Larger models go
#: through the reduction layer (Lanczos, modal, Craig–Bampton) first.
DENSE_LIMIT = 6000

#: Largest :func:`chain`: the spectrum is dense in ``n`` (an ``n × n`` mode matrix, 8·n² bytes, whatever the
#: sparsity of the chain).  Measured (spectrum + a 20-period backbone, one core): n = 2000 in 2.7 s and 0.25 GB,
#: 5000 in 16 s and 0.7 GB, 6000 in 21 s and 0.9 GB; n = 100 000 would need 80 GB for the modes alone.
MAX_CHAIN = DENSE_LIMIT

#: Hints of the positive-definiteness errors: what the solver needs and the usual cause.
_HINTS = {"M": "every degree of freedom needs a positive mass",
          "K": "the solver needs K positive definite (no rigid-body motion): a free–free structure? clamp it, "
               "or ground it with a spring"}

#: A mode with ``|b_j| <= INACTIVE_RTOL * max|b|`` does not see the contact
#: (symmetry zeros computed as round-off); it is left out of the impact
#: dynamics and of the resonance test.
INACTIVE_RTOL = 1e-11


def _is_sparse(a) -> bool:
    return sp.issparse(a)


def _as_matrix(name: str, a, n: int | None = None):
    """Return ``a`` as a float dense ndarray or CSR matrix, checking dtype, shape and values."""
    if _is_sparse(a):
        numbers(name, a, complex_ok=True)
        a = sp.csr_array(a)
        _check_real(name, a.data)
        a = sp.csr_array(a.real if a.dtype.kind == "c" else a, dtype=float)
        data = a.data
    else:
        try:
            raw = np.asarray(a)
            numbers(name, raw, complex_ok=True)
            _check_real(name, raw)
            a = np.array(raw.real if raw.dtype.kind == "c" else raw, dtype=float)
        except (TypeError, ValueError) as exc:
            if "imaginary" in str(exc) or "must hold" in str(exc):
                raise
            raise ValueError(f"{name} must be a real matrix: {exc}") from None
        data = a
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"{name} must be a square matrix, got shape {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"{name} is empty: a system needs at least one degree of freedom")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has shape {a.shape}, expected ({n}, {n}) to match M")
    bad = ~np.isfinite(data)
    if bad.any():
        raise ValueError(f"{name} contains {int(bad.sum())} non-finite value(s) (NaN or inf)")
    return a


def _check_real(name: str, values) -> None:
    """Refuse complex values with a non-zero imaginary part (numpy would drop it with a mere warning)."""
    values = np.asarray(values)
    if values.dtype.kind == "c" and np.any(values.imag != 0):
        bad = int(np.count_nonzero(values.imag))
        raise ValueError(f"{name} must be real: {bad} entr{'y has' if bad == 1 else 'ies have'} a non-zero imaginary "
                         f"part (max |Im| = {np.abs(values.imag).max():.3g}); bladecase models undamped, real "
                         "structures")


def _check_scale(name: str, value: float) -> None:
    if not 1 / SCALE_LIMIT <= value <= SCALE_LIMIT:
        raise ValueError(f"{name} = {value:.3g} is out of the range double precision handles here: "
                         f"[{1 / SCALE_LIMIT:g}, {SCALE_LIMIT:g}]; rescale the units (e.g. of length or time)")


def _check_positive_definite(name: str, a) -> None:
    """``ValueError`` unless the symmetric ``a`` is positive definite and not singular to working precision
    (:func:`bladecase.linalg.positive_definite`: dense Cholesky; sparse LDLᵀ of
    :func:`bladecase.linalg.spd_factor`), with the hint of :data:`_HINTS`."""
    positive_definite(name, a, hint=_HINTS.get(name, ""))


@dataclass(frozen=True)
class Spectrum:
    """Contact spectral data of a :class:`LinearSystem`.

    Attributes
    ----------
    omega : (m,) ndarray
        Angular eigenfrequencies ``ω_j`` (rad per time unit), ascending.
    phi : (n, m) ndarray
        M-normalised mode shapes (``φᵀMφ = I``, ``φᵀKφ = diag(ω²)``).
    b : (m,) ndarray
        Contact participations ``b_j = wᵀφ_j``.
    active : (m,) bool ndarray
        Modes that see the contact: ``|b_j| > INACTIVE_RTOL * max|b|``.
    """

    omega: np.ndarray
    phi: np.ndarray
    b: np.ndarray
    active: np.ndarray

    @cached_property
    def contact_modes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(ω, b, φ)`` restricted to the active modes (cached; no copy when all are active)."""
        if self.active.all():
            return self.omega, self.b, self.phi
        return self.omega[self.active], self.b[self.active], self.phi[:, self.active]

    @property
    def frequencies(self) -> np.ndarray:
        """Eigenfrequencies ``ω_j / 2π`` (cycles per time unit)."""
        return self.omega / (2 * np.pi)

    @property
    def periods(self) -> np.ndarray:
        """Linear periods ``2π / ω_j``."""
        return 2 * np.pi / self.omega


def _dense(a) -> np.ndarray:
    return a.toarray() if _is_sparse(a) else a


def _diagonal(a) -> np.ndarray | None:
    """The diagonal of ``a`` if ``a`` is a diagonal matrix, else ``None``."""
    d = a.diagonal()
    off = (a - sp.diags_array(d)) if _is_sparse(a) else (a - np.diag(d))
    nonzero = off.count_nonzero() if _is_sparse(off) else np.count_nonzero(off)
    return d if nonzero == 0 else None


def _tridiagonal_bands(a):
    """``(diag, offdiag)`` if the symmetric ``a`` (dense or sparse) is tridiagonal, else ``None``."""
    if _is_sparse(a):
        coo = sp.coo_array(a)
        width = np.abs(coo.row - coo.col).max() if coo.nnz else 0
    else:
        rows, cols = np.nonzero(a)
        width = np.abs(rows - cols).max() if rows.size else 0
    if width > 1:
        return None
    return np.asarray(a.diagonal(0), dtype=float), np.asarray(a.diagonal(1), dtype=float)


def compute_spectrum(M, K, w: np.ndarray) -> Spectrum:
    """Generalised eigen-decomposition ``K φ = ω² M φ`` with M-normalised ``φ``.

    Dense eigen-solution (all modes).  For a diagonal ``M`` the problem is
    symmetrised with ``M^{-1/2}``; when ``M^{-1/2} K M^{-1/2}`` is tridiagonal
    (spring–mass chains, Lanczos chains) LAPACK's tridiagonal MRRR solver is
    used without forming a dense matrix; otherwise a symmetric dense solver.
    Models larger than :data:`DENSE_LIMIT` must be reduced first.
    """
    n = M.shape[0]
    mdiag = _diagonal(M)
    if mdiag is not None:
        s = 1.0 / np.sqrt(mdiag)
        if _is_sparse(K):
            S = sp.diags_array(s)
            A = sp.csr_array(S @ K @ S)
        else:
            A = K * s[:, None] * s[None, :]
        bands = _tridiagonal_bands(A)
        if bands is not None and n > 2:
            _check_dense_size(n)  # the n × n modes are dense, a tridiagonal K notwithstanding
            lam, psi = sla.eigh_tridiagonal(bands[0], bands[1])
        else:
            _check_dense_size(n)
            lam, psi = sla.eigh(_dense(A))
        phi = psi * s[:, None]
    else:
        _check_dense_size(n)
        lam, phi = sla.eigh(_dense(K), _dense(M))
    if lam[0] <= 0:
        raise ValueError(f"K is not positive definite: eigenvalue {lam[0]:.6g} <= 0")
    omega = np.sqrt(lam)
    # Sign convention: the largest component of each mode is positive.
    idx = np.argmax(np.abs(phi), axis=0)
    phi = phi * np.sign(phi[idx, np.arange(phi.shape[1])])[None, :]
    b = w @ phi
    active = np.abs(b) > INACTIVE_RTOL * np.abs(b).max()
    return Spectrum(omega=omega, phi=phi, b=b, active=active)


def _check_dense_size(n: int) -> None:
    if n > DENSE_LIMIT:
        raise ValueError(
            f"model has {n} dofs, above the dense eigen-solution limit {DENSE_LIMIT}: "
            "reduce it first (bladecase.reduce with method 'lanczos', 'modal' or 'craig-bampton')"
        )


class LinearSystem:
    """A linear structure with one unilateral contact.

    Free flight ``M x'' + K x = 0``; constraint ``wᵀx <= gap``; Moreau impact
    law ``M(v⁺ - v⁻) = -w Λ``, ``wᵀv⁺ = -e wᵀv⁻`` (theory §1).

    Parameters
    ----------
    M, K : (n, n) array_like or scipy sparse
        Symmetric positive definite mass and stiffness matrices.
    w : (n,) array_like or int
        Constraint vector; an ``int`` ``c`` means the unit vector on dof ``c``
        (negative values count from the end, like numpy indices).  A single
        float (or 0-d array) is refused when ``n > 1``: it is neither a dof nor a vector.
    gap : float
        Clearance ``d > 0`` between the structure at rest and the obstacle.

    Raises
    ------
    ValueError
        Wrong shapes, values that are not numbers (booleans, text), non-finite or complex values,
        asymmetric matrices (beyond :data:`SYMMETRY_RTOL`, 1e-10 of ``max|A|``), ``M`` or ``K`` not
        positive definite or singular to working precision (smallest eigenvalue below
        :data:`SINGULAR_RTOL`, 1e-12, of the largest diagonal entry: a free–free ``K``), ``w == 0``,
        ``gap <= 0``, or scales (``gap``, ``max|M|``, ``max|K|``, ``max|w|``) outside ``[1e-80, 1e80]``
        (:data:`SCALE_LIMIT`); the message names the argument, the value and what is valid.

    Examples
    --------
    >>> import numpy as np
    >>> s = LinearSystem(np.eye(2), [[2.0, -1.0], [-1.0, 1.0]], w=1, gap=0.5)   # contact on dof 1
    >>> s, s.w.tolist(), s.spectrum.b.round(6).tolist()
    (LinearSystem(n=2, dense, gap=0.5), [0.0, 1.0], [0.850651, -0.525731])
    >>> LinearSystem(np.eye(2), [[2.0, -1.0], [-1.0, -1.0]], w=1, gap=0.5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: K is not positive definite: smallest eigenvalue -1.30278 (largest 2.30278; it must be > 0): the ...
    """

    def __init__(self, M: ArrayLike, K: ArrayLike, w: np.ndarray | int | Sequence[float], gap: float):
        M = _as_matrix("M", M)
        n = M.shape[0]
        K = _as_matrix("K", K, n)
        symmetric("M", M)
        symmetric("K", K)
        if isinstance(w, (bool, np.bool_)):
            raise ValueError(f"w must be an integer contact dof (0..{n - 1}) or a vector of {n} numbers, got {w!r}")
        if isinstance(w, (int, np.integer)):
            c = int(w)
            if not 0 <= c < n:  # a negative index would silently pick a dof from the end
                raise ValueError(f"contact dof w = {c} is out of range for a system of {n} dofs (valid: 0..{n - 1})")
            wv = np.zeros(n)
            wv[c] = 1.0
        else:
            if n > 1 and (isinstance(w, (float, np.floating)) or (isinstance(w, np.ndarray) and w.ndim == 0)):
                raise ValueError(f"w must be an integer contact dof (0..{n - 1}) or a vector of {n} numbers, got the "
                                 f"single number {w!r}")
            try:
                raw = np.asarray(w)
                numbers("w", raw, complex_ok=True)
                _check_real("w", raw)
                wv = np.array(raw.real if raw.dtype.kind == "c" else raw, dtype=float)
            except (TypeError, ValueError) as exc:
                if "imaginary" in str(exc) or "must hold" in str(exc):
                    raise
                raise ValueError(f"w must be an int or a real vector: {exc}") from None
            if wv.ndim > 1 and sum(k > 1 for k in wv.shape) > 1:  # a row or a column is a vector; a matrix is not
                raise ValueError(f"w must be a vector of {n} numbers (one per dof), got an array of shape {wv.shape}")
            wv = wv.reshape(-1)
            if wv.shape != (n,):
                raise ValueError(f"w has {wv.size} entries, expected {n} (one per dof)")
            if not np.all(np.isfinite(wv)):
                raise ValueError("w contains non-finite values (NaN or inf)")
            if not np.any(wv):
                raise ValueError("w is the zero vector: the constraint wᵀx <= gap needs a non-zero w")
        raw_gap = gap
        try:
            gap = float(gap)
        except (TypeError, ValueError):
            raise ValueError(f"gap must be a positive number, got {gap!r}") from None
        if isinstance(raw_gap, (bool, np.bool_)) or not np.isfinite(gap) or gap <= 0:
            raise ValueError(f"gap must be a finite clearance > 0, got {raw_gap!r}")
        _check_scale("gap", gap)
        for name, A in (("M", M), ("K", K)):
            top = float(abs(A).max()) if _is_sparse(A) else float(np.abs(A).max())
            if top == 0:
                raise ValueError(f"{name} is zero (all {n}² entries 0), not positive definite: {_HINTS[name]}")
            _check_scale(f"max|{name}|", top)
        _check_scale("max|w|", float(np.abs(wv).max()))
        _check_positive_definite("M", M)
        _check_positive_definite("K", K)
        self._M, self._K, self._w, self._gap = M, K, wv, gap
        self._w.setflags(write=False)

    M = property(lambda self: self._M, doc="Mass matrix (dense ndarray or CSR).")
    K = property(lambda self: self._K, doc="Stiffness matrix (dense ndarray or CSR).")
    w = property(lambda self: self._w, doc="Constraint vector (read-only ndarray).")
    gap = property(lambda self: self._gap, doc="Clearance ``d > 0``.")

    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
        return self._M.shape[0]

    @cached_property
    def spectrum(self) -> Spectrum:
        """Frequencies, M-normalised modes and contact participations (cached)."""
        return compute_spectrum(self._M, self._K, self._w)

    def energy(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Mechanical energy ``½vᵀMv + ½xᵀKx`` of states (columns of ``x``, ``v`` if 2-D)."""
        return 0.5 * np.sum(v * (self._M @ v), axis=0) + 0.5 * np.sum(x * (self._K @ x), axis=0)

    def __repr__(self) -> str:
        kind = "sparse" if _is_sparse(self._M) else "dense"
        return f"LinearSystem(n={self.n}, {kind}, gap={self._gap:g})"


def chain(n: int, k: float | Sequence[float] = 1.0, m: float | Sequence[float] = 1.0, gap: float = 1.0) -> LinearSystem:
    """The seed paper's spring–mass chain (its Fig. 1).

    wall — k₁ — m₁ — k₂ — m₂ — … — k_n — m_n | obstacle at ``gap``.
    ``M = diag(m)``, ``K_ii = k_i + k_{i+1}`` (``k_{n+1} = 0``),
    ``K_{i,i+1} = -k_{i+1}``; contact on the last mass (``w = e_n``).

    Parameters
    ----------
    n : int
        Number of masses, ``1 <= n <=`` :data:`MAX_CHAIN` (6000: the spectrum is dense in ``n``).
    k, m : float or length-n sequence
        Spring stiffnesses and masses, all > 0.
    gap : float
        Clearance ``d > 0`` of the last mass.

    Examples
    --------
    The seed paper's Sec. 1.4 example (``ω² = 3 ∓ √5``):

    >>> s = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> s, s.K.toarray().tolist(), (s.spectrum.omega**2).round(8).tolist()
    (LinearSystem(n=2, sparse, gap=1), [[2.0, -1.0], [-1.0, 1.0]], [0.76393202, 5.23606798])
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"chain length n must be an integer >= 1, got {n!r}")
    if n > MAX_CHAIN:
        raise ValueError(f"chain length n must be <= {MAX_CHAIN}, got {n}: {dense_cost(n)}")
    ks = _per_mass("k", k, n)
    ms = _per_mass("m", m, n)
    kn = np.append(ks, 0.0)
    K = sp.diags_array([kn[:-1] + kn[1:], -ks[1:], -ks[1:]], offsets=[0, 1, -1], shape=(n, n), format="csr")
    M = sp.diags_array(ms, format="csr")
    return LinearSystem(M, K, n - 1, gap)


def dense_cost(n: int, symbol: str = "n") -> str:
    """Why a dense solver of ``n`` dofs is refused above :data:`MAX_CHAIN`, for messages (``symbol``: how the
    caller names ``n``).

    >>> dense_cost(100_000)
    'the solver is dense in n: its n × n mode matrix alone would need 80 GB (n = 6000 takes ~20 s and ~1 GB)'
    """
    need = 8.0 * n * n
    size = f"{need / 1e9:.3g} GB" if need >= 1e9 else f"{need / 1e6:.3g} MB"
    return (f"the solver is dense in {symbol}: its {symbol} × {symbol} mode matrix alone would need {size} "
            f"({symbol} = {MAX_CHAIN} takes ~20 s and ~1 GB)")


def _per_mass(name: str, value, n: int) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.size == 1:
        arr = np.full(n, arr.item())
    if arr.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have {n} entries, got {arr.size}")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        bad = arr[~(np.isfinite(arr) & (arr > 0))][0]
        raise ValueError(f"every {name} must be finite and > 0, got {bad!r}")
    return arr
