"""Linear algebra shared by the FE front end and the reduction layer.

One factorisation of a symmetric positive definite matrix, :func:`spd_factor`, and one solver for the
lowest modes of ``K φ = λ M φ``, :func:`lowest_modes` (shift-invert Lanczos about 0 with that factorisation,
or a dense eigen-solution for small problems asking for many modes).  Every site of :mod:`bladecase.fe` and
:mod:`bladecase.reduction` that solves with ``K``, ``M``, ``K - σM`` or ``K_ii`` goes through here; no dense
``n × n`` matrix is formed from a sparse matrix except by :func:`lowest_modes` on request or below
:data:`DENSE_LIMIT`.

Backend (the seam for CHOLMOD/MUMPS): :func:`factor_backend` is the ONE place that chooses how sparse
matrices are factorised.  Today it is always ``"superlu"``: scipy's SuperLU in symmetric mode without
pivoting (minimum degree on ``A + Aᵀ``, ``diag_pivot_thresh = 0``), which for an SPD matrix is an LDLᵀ,
``Pᵀ A P = L D Lᵀ``, ``A`` positive definite iff every pivot of ``D`` is > 0 and no off-diagonal pivot was
taken.  A faster backend (CHOLMOD through scikit-sparse, MUMPS) is added by detecting it in
:func:`factor_backend` and giving :data:`_SPARSE_BACKENDS` its ``factor`` function; callers keep using
:class:`SPDFactor` (``solve``, ``operator``, ``ldlt``).

Reuse: a factor can be computed once and passed on (``factor=``) to :func:`lowest_modes`,
:func:`bladecase.fe.natural_frequencies` and :func:`bladecase.reduction.reduce`;
:meth:`Factor.is_of` tells whether it was made from a given matrix object.

>>> import scipy.sparse as sp
>>> K = sp.diags_array([[-1.0] * 3, [2.0] * 4, [-1.0] * 3], offsets=[-1, 0, 1], format="csr")
>>> lam, phi = lowest_modes(K, sp.eye_array(4, format="csr"), 2)
>>> np.round(lam, 6)
array([0.381966, 1.381966])
"""

from __future__ import annotations

import warnings
import weakref
from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .checks import integer

__all__ = [
    "DENSE_LIMIT", "Factor", "SPDFactor", "check_factor", "diagonal", "factor_backend", "is_sparse", "lowest_modes",
    "sign_convention", "spd_factor", "symmetric_factor",
]

#: Largest matrix :func:`lowest_modes` turns dense on its own (when more than half of the modes are asked
#: for); a dense ``n × n`` float matrix is 72 MB at 3000 dofs.
DENSE_LIMIT = 3000

#: Diagonal pivot threshold of the indefinite factorisation (:func:`symmetric_factor`): SuperLU keeps the
#: diagonal pivot unless it is below this fraction of the largest entry of its column.
INDEFINITE_PIVOT_THRESHOLD = 0.1


def is_sparse(a) -> bool:
    """True for scipy sparse matrices and arrays."""
    return sp.issparse(a)


def diagonal(a) -> np.ndarray | None:
    """The diagonal of ``a`` (dense or sparse) if ``a`` is a diagonal matrix, else ``None``.

    >>> diagonal(sp.diags_array([1.0, 2.0]))
    array([1., 2.])
    >>> diagonal(np.ones((2, 2))) is None
    True
    """
    d = a.diagonal()
    off = (a - sp.diags_array(d)) if is_sparse(a) else (a - np.diag(d))
    nonzero = off.count_nonzero() if is_sparse(off) else np.count_nonzero(off)
    return d if nonzero == 0 else None


def _dense(a) -> np.ndarray:
    return a.toarray() if is_sparse(a) else np.asarray(a, dtype=float)


def factor_backend() -> str:
    """The sparse factorisation backend: the one place where it is chosen.

    Always ``"superlu"`` (scipy) today.  Issue 14 detects CHOLMOD (``sksparse.cholmod``) or MUMPS here at
    run time, and registers its ``factor`` function in :data:`_SPARSE_BACKENDS`.

    >>> factor_backend()
    'superlu'
    """
    return "superlu"


# ----------------------------------------------------------------------------- factors


class Factor:
    """A factorisation of a square matrix ``A``: :meth:`solve` gives ``A⁻¹b``.

    Attributes
    ----------
    name : str
        The matrix's name in messages (``"K"``, ``"M"``, ``"K - σM (sigma = 1e6)"``…).
    n : int
        Size of ``A``.
    kind : str
        ``"sparse"`` or ``"dense"``.
    backend : str
        ``"superlu"`` (sparse, :func:`factor_backend`), ``"cholesky"`` or ``"lu"`` (dense, scipy).
    fill : int
        Entries stored by the factors (``nnz(L) + nnz(U)`` for SuperLU, ``n²`` dense): the memory it takes.
    """

    def __init__(self, name: str, n: int, kind: str, backend: str, solve: Callable, source=None, parts=None,
                 fill: int | None = None):
        self.name, self.n, self.kind, self.backend = name, n, kind, backend
        self.fill = n * n if fill is None else int(fill)
        self._solve = solve
        self._parts = parts
        try:
            self._source = weakref.ref(source) if source is not None else None
        except TypeError:  # not weak-referenceable
            self._source = None

    def solve(self, b) -> np.ndarray:
        """``A⁻¹b`` for a vector ``(n,)`` or a block of columns ``(n, k)`` (dense or sparse ``b``)."""
        b = _dense(b)
        if b.shape[0] != self.n:
            raise ValueError(f"right-hand side has {b.shape[0]} rows, expected {self.n} (the size of {self.name})")
        return self._solve(np.asarray(b, dtype=float))

    def operator(self) -> spla.LinearOperator:
        """``A⁻¹`` as a :class:`scipy.sparse.linalg.LinearOperator` (e.g. ``OPinv`` of ``eigsh``)."""
        return spla.LinearOperator((self.n, self.n), matvec=self._solve, matmat=self._solve, dtype=float)

    def is_of(self, A) -> bool:
        """True if this factor was made from the object ``A`` (the same matrix object, still alive)."""
        return self._source is not None and self._source() is A

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name}, n={self.n}, {self.kind}, {self.backend})"


class SPDFactor(Factor):
    """The factorisation of a symmetric positive definite matrix (:func:`spd_factor`).

    Sparse: ``Pᵀ A P = L D Lᵀ`` (:meth:`ldlt`).  Dense: ``A = L Lᵀ`` (:attr:`lower`).
    """

    def ldlt(self) -> tuple[sp.csc_array, np.ndarray, np.ndarray]:
        """``(L, d, perm)`` with ``Pᵀ A P = L diag(d) Lᵀ``, ``L`` unit lower triangular (CSC, sorted),
        ``d > 0`` and ``(Pᵀx)[perm] = x``; sparse factors only."""
        if self.kind != "sparse":
            raise ValueError(f"ldlt() needs a sparse factor; this factor of {self.name} is dense (use .lower)")
        return self._parts()

    @property
    def lower(self) -> np.ndarray:
        """Dense Cholesky factor ``L`` (``A = L Lᵀ``); dense factors only."""
        if self.kind != "dense":
            raise ValueError(f"lower needs a dense factor; this factor of {self.name} is sparse (use .ldlt())")
        return self._parts


def _fail(name: str, why: str, hint: str) -> ValueError:
    return ValueError(f"{name} {why}" + (f": {hint}" if hint else ""))


def _superlu(A: sp.csc_array, name: str, hint: str, definite: bool):
    """SuperLU in symmetric mode: ``(solve, ldlt, fill)``; the LDLᵀ checks if ``definite``."""
    try:
        lu = spla.splu(
            A,
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0 if definite else INDEFINITE_PIVOT_THRESHOLD,
            options={"SymmetricMode": True},
        )
    except RuntimeError as exc:
        what = "is singular, hence not positive definite" if definite else "is singular"
        raise _fail(name, f"{what} ({exc})", hint) from None
    if definite:
        pivots = lu.U.diagonal()
        if not np.array_equal(lu.perm_r, lu.perm_c):
            raise _fail(name, "is not positive definite: its LDLᵀ factorisation needed off-diagonal pivoting", hint)
        if np.any(~(pivots > 0)):
            raise _fail(name, f"is not positive definite: its LDLᵀ factorisation has a pivot {pivots.min():.6g} <= 0",
                        hint)

    def ldlt():
        L = sp.csc_array(lu.L)
        L.sum_duplicates()
        L.sort_indices()
        return L, lu.U.diagonal(), np.asarray(lu.perm_c)

    return lu.solve, ldlt, lu.L.nnz + lu.U.nnz


#: Sparse backends by name: ``factor(A_csc, name, hint, definite) -> (solve, ldlt, fill)``.
_SPARSE_BACKENDS = {"superlu": _superlu}


def _square(A, name: str) -> int:
    if getattr(A, "ndim", None) != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{name} must be a square matrix, got shape {getattr(A, 'shape', None)}")
    return A.shape[0]


def spd_factor(A, name: str = "A", *, hint: str = "") -> SPDFactor:
    """Factor a symmetric positive definite matrix (scipy sparse or dense); the symmetry is not checked.

    Sparse: the backend of :func:`factor_backend` (SuperLU LDLᵀ, see the module docstring).  Dense:
    Cholesky.  A sparse matrix is never made dense.

    Parameters
    ----------
    A : (n, n) scipy sparse or array_like
    name : str
        The matrix's name in error messages.
    hint : str
        Appended to the error message (``": <hint>"``), e.g. ``"is the model clamped?"``.

    Raises
    ------
    ValueError
        ``A`` not square, or not positive definite (a diagonal entry ``<= 0``, singular, a pivot ``<= 0``,
        off-diagonal pivoting, or a failed dense Cholesky); the message names ``A``.

    >>> A = sp.diags_array([[-1.0] * 3, [2.0] * 4, [-1.0] * 3], offsets=[-1, 0, 1], format="csc")
    >>> f = spd_factor(A, "K")
    >>> f.n, bool(np.allclose(A @ f.solve(np.ones(4)), 1.0))
    (4, True)
    >>> spd_factor(sp.csc_array([[1.0, 2.0], [2.0, 1.0]]), "M")
    Traceback (most recent call last):
        ...
    ValueError: M is not positive definite: its LDLᵀ factorisation has a pivot -3 <= 0
    """
    n = _square(A, name)
    if not is_sparse(A):
        a = np.asarray(A, dtype=float)
        try:
            L = np.linalg.cholesky(a)
        except np.linalg.LinAlgError:
            lam_min = sla.eigvalsh(a, subset_by_index=[0, 0])[0]
            raise _fail(name, f"is not positive definite: smallest eigenvalue {lam_min:.6g} (must be > 0)",
                        hint) from None
        return SPDFactor(name, n, "dense", "cholesky", lambda b: sla.cho_solve((L, True), b), A, L)
    diag = A.diagonal()
    if np.any(~(diag > 0)):
        i = int(np.flatnonzero(~(diag > 0))[0])
        raise _fail(name, f"is not positive definite: diagonal entry {name}[{i},{i}] = {diag[i]:.6g} <= 0", hint)
    backend = factor_backend()
    solve, ldlt, fill = _SPARSE_BACKENDS[backend](sp.csc_array(A, dtype=float), name, hint, True)
    return SPDFactor(name, n, "sparse", backend, solve, A, ldlt, fill)


def check_factor(factor, A, name: str = "A", how: str = "spd_factor(A)") -> SPDFactor | None:
    """``factor`` if it is ``None`` or an :class:`SPDFactor` made from the very object ``A``, else ``ValueError``.

    ``name`` and ``how`` (how to make the right factor) go into the message.
    """
    if factor is not None and not (isinstance(factor, SPDFactor) and factor.is_of(A)):
        raise ValueError(f"factor must be None or the factorisation of {name} ({how}), got {factor!r}")
    return factor


def symmetric_factor(A, name: str = "A", *, hint: str = "") -> Factor:
    """Factor a symmetric, possibly indefinite, non-singular matrix (e.g. ``K - σM`` for a shift ``σ > 0``).

    Sparse: the backend of :func:`factor_backend` with threshold pivoting.  Dense: LU.  For an SPD matrix
    use :func:`spd_factor` (it also checks definiteness).

    Raises
    ------
    ValueError
        ``A`` not square or singular (the message names ``A``, then ``hint``).
    """
    n = _square(A, name)
    if not is_sparse(A):
        with warnings.catch_warnings():  # a singular matrix: the error below says it
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu, piv = sla.lu_factor(np.asarray(A, dtype=float), check_finite=False)
        if np.any(np.diag(lu) == 0):
            raise _fail(name, "is singular", hint)
        return Factor(name, n, "dense", "lu", lambda b: sla.lu_solve((lu, piv), b, check_finite=False), A)
    backend = factor_backend()
    solve, _, fill = _SPARSE_BACKENDS[backend](sp.csc_array(A, dtype=float), name, hint, False)
    return Factor(name, n, "sparse", backend, solve, A, fill=fill)


# ----------------------------------------------------------------------------- eigenpairs


def sign_convention(phi: np.ndarray) -> np.ndarray:
    """Flip each column so that its largest component (in absolute value) is positive."""
    idx = np.argmax(np.abs(phi), axis=0)
    return phi * np.sign(phi[idx, np.arange(phi.shape[1])])[None, :]


def lowest_modes(
    K, M, count: int, factor: SPDFactor | None = None, *, dense: bool | None = None, name: str = "K", hint: str = ""
) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` lowest eigenpairs ``(λ, Φ)`` of ``K φ = λ M φ`` (``K``, ``M`` symmetric positive definite).

    Sparse (default for sparse ``K``): shift-invert Lanczos (ARPACK ``eigsh``) about ``σ = 0`` with the
    factorisation of ``K`` as ``OPinv`` — ``factor`` if given (from :func:`spd_factor`, reused), else
    computed here.  Dense (``scipy.linalg.eigh``): for dense ``K``, or when ``dense=True``, or (``dense=None``)
    when more than half of the modes of a matrix of at most :data:`DENSE_LIMIT` rows are asked for (ARPACK
    cannot give ``count >= n``).

    Parameters
    ----------
    K, M : (n, n) scipy sparse or array_like
    count : int
        ``1 <= count <= n`` (``< n`` on the sparse path).
    factor : SPDFactor or None
        A factorisation of ``K`` to reuse (sparse path).
    dense : bool or None
        Force the dense (True) or sparse (False) path; ``None`` chooses as above.
    name, hint : str
        ``K``'s name and a hint in error messages.

    Returns
    -------
    lam : (count,) ndarray
        Eigenvalues ``ω²``, ascending.
    phi : (n, count) ndarray
        M-normalised modes (``ΦᵀMΦ = I``), each column's largest component positive.

    Raises
    ------
    ValueError
        ``count`` out of range, ``factor`` of another size, ``K`` not positive definite.

    >>> K = sp.diags_array([[-1.0] * 3, [2.0] * 4, [-1.0] * 3], offsets=[-1, 0, 1], format="csr")
    >>> M = sp.diags_array([1.0, 1.0, 1.0, 2.0], format="csr")
    >>> f = spd_factor(K, "K")
    >>> sparse, _ = lowest_modes(K, M, 1, factor=f)
    >>> full, phi = lowest_modes(K, M, 4)  # all modes: dense
    >>> bool(np.isclose(sparse[0], full[0])), bool(np.allclose(phi.T @ (M @ phi), np.eye(4)))
    (True, True)
    """
    n = _square(K, name)
    count = integer("count", count, 1, n, note=f" (the size of {name})")
    sparse = is_sparse(K)
    if dense is None:
        dense = not sparse or count >= n or (count > n // 2 and n <= DENSE_LIMIT)
    if dense:
        if sparse and n > DENSE_LIMIT:
            raise ValueError(f"lowest_modes: {count} of the {n} modes of {name} need a dense eigen-solution, "
                             f"limited to DENSE_LIMIT = {DENSE_LIMIT} rows (the sparse solver gives at most {n - 1})")
        lam, phi = sla.eigh(_dense(K), _dense(M), subset_by_index=[0, count - 1])
    else:
        if count >= n:
            raise ValueError(f"count = {count}: the sparse eigen-solver gives at most {n - 1} of the {n} modes of "
                             f"{name} (use dense=True)")
        if factor is None:
            factor = spd_factor(K, name, hint=hint)
        elif not isinstance(factor, Factor) or factor.n != n:
            raise ValueError(f"factor must be a factorisation of {name} ({n} × {n}, from spd_factor), got {factor!r}")
        lam, phi = spla.eigsh(K, k=count, M=M, sigma=0.0, which="LM", OPinv=factor.operator())
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
        phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, M @ phi))[None, :]
    if not np.all(np.isfinite(lam)) or lam[0] <= 0:
        raise _fail(name, f"is not positive definite: eigenvalue {lam[0]:.3g} (a mechanism? degenerate cells?)", hint)
    return lam, sign_convention(phi)
