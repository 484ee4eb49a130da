"""Linear algebra shared by the FE front end and the reduction layer.

One factorisation of a symmetric positive definite matrix, :func:`spd_factor`, and one solver for the
lowest modes of ``K φ = λ M φ``, :func:`lowest_modes` (shift-invert Lanczos about 0 with that factorisation,
or a dense eigen-solution for small problems asking for many modes).  Every site of :mod:`bladecase.fe` and
:mod:`bladecase.reduction` that solves with ``K``, ``M``, ``K - σM`` or ``K_ii`` goes through here; no dense
``n × n`` matrix is formed from a sparse matrix except by :func:`lowest_modes` on request or below
:data:`DENSE_LIMIT`.

Backend: :func:`factor_backend` is the ONE place that chooses how sparse matrices are factorised, at run
time, the first that imports of: ``"cholmod"`` (supernodal Cholesky of SuiteSparse through the optional
``scikit-sparse``, ``<0.5`` on Debian's SuiteSparse 5, built where SuiteSparse's headers are installed),
``"cvxopt"`` (the same CHOLMOD from cvxopt's wheels, which ``make`` installs with pip alone:
:mod:`bladecase.linalg_backends`), ``"superlu"``; the environment variable ``BLADECASE_FACTOR`` (``superlu``,
``cvxopt`` or ``cholmod``) forces one.  SuperLU: scipy's SuperLU in symmetric mode without pivoting
(minimum degree on ``A + Aᵀ``, ``diag_pivot_thresh = 0``), which for an SPD matrix is an LDLᵀ,
``Pᵀ A P = L D Lᵀ``, ``A`` positive definite iff every pivot of ``D`` is > 0 and no off-diagonal pivot was
taken.  CHOLMOD (either): ``Pᵀ A P = L Lᵀ``, 3 to 6 times faster and 3 to 5 times leaner on the 110k-dof blade;
it fails on a matrix that is not positive definite (``NotPositiveDefinite``: the message then comes from
SuperLU's diagnosis) and, having no pivoting, leaves indefinite matrices (:func:`symmetric_factor`) to SuperLU.
A backend is one ``factor`` function in :data:`_SPARSE_BACKENDS` (plus an import probe in :data:`_PROBES`);
callers keep using :class:`SPDFactor` (``solve``, ``operator``, ``ldlt``).

Eigen-solver: :func:`lowest_modes` uses ARPACK's shift-invert Lanczos, or the block shift-invert Lanczos of
:mod:`bladecase.linalg_block` when the factor solves blocks of right-hand sides much faster than one at a time
(either CHOLMOD: scikit-sparse's in blocks of 8, cvxopt's in blocks of 4) and ``K`` has at least
:data:`BLOCK_MIN_DOFS` rows (110k dofs, 20 modes: 2.7 s vs 3.7 to 7.5 s; cvxopt at 61.7k dofs: 1.7 s vs 2.1 to
3.1 s).

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

import os
import warnings
import weakref
from collections.abc import Callable
from functools import cache

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .checks import SINGULAR_RTOL, integer
from .linalg_backends import (  # noqa: F401  (INDEFINITE_PIVOT_THRESHOLD: a public name of this module)
    INDEFINITE_PIVOT_THRESHOLD,
    NotPositiveDefinite,
    cholmod_factor,
    cvxopt_cholesky,
    fail,
    import_cholmod,
    import_cvxopt,
    superlu_factor,
)
from .linalg_block import BLOCK_SIZE, block_lanczos
from .threads import blas_threads

__all__ = [
    "BACKEND_ENV", "BLOCK_MIN_DOFS", "DENSE_LIMIT", "EIGEN_METHODS", "Factor", "SPDFactor", "available_backends",
    "check_factor", "diagonal", "factor_backend", "is_sparse", "lowest_modes", "positive_definite", "sign_convention",
    "spd_factor", "symmetric_factor",
]

#: Largest matrix :func:`lowest_modes` turns dense on its own (when more than half of the modes are asked
#: for); a dense ``n × n`` float matrix is 72 MB at 3000 dofs.
DENSE_LIMIT = 3000

#: Environment variable that forces the sparse factorisation backend (``superlu``, ``cvxopt``, ``cholmod``).
BACKEND_ENV = "BLADECASE_FACTOR"

#: Smallest ``K`` for which :func:`lowest_modes` (``method="auto"``) uses the block Lanczos with a factor that
#: solves blocks fast (CHOLMOD).  20 modes of the blade, block vs ARPACK: 10k dofs 0.17 vs 0.18 s (a tie),
#: 26k 0.52 vs 0.68 s, 110k 2.7 vs 3.7-7.5 s (ARPACK's single solves suffer most on a busy machine); cvxopt,
#: blocks of 4, CPU: 10k 0.16 vs 0.11 s, 17k 0.34 vs 0.37 s, 26k 0.55 vs 0.66 s.
BLOCK_MIN_DOFS = 20_000

#: Accepted ``method`` of :func:`lowest_modes`.
EIGEN_METHODS = ("auto", "arpack", "block")

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


#: Import probes of the optional backends: ``name -> () -> module`` (raises ``ImportError`` if missing).
_PROBES: dict[str, Callable] = {"cholmod": import_cholmod, "cvxopt": import_cvxopt}

#: How to install each optional backend (in the error of a forced backend that is missing).
_INSTALL = {"cholmod": "install scikit-sparse<0.5 with SuiteSparse (apt install libsuitesparse-dev)",
            "cvxopt": "pip install cvxopt (make installs its wheel)"}

#: Preference order of :func:`factor_backend` (the first available wins); SuperLU is always available.
_PREFERENCE = ("cholmod", "cvxopt", "superlu")

#: Backends that pivot, hence factor indefinite matrices (:func:`symmetric_factor`); the others use SuperLU.
_PIVOTING = frozenset({"superlu"})

#: Backends whose block solves are much cheaper per right-hand side than single solves (block eigen-solver),
#: with the block size that suits them: scikit-sparse's CHOLMOD solves 8 columns in about twice the time of
#: one; cvxopt's (``spsolve``) 4 at a time, at about half the cost per column (20 modes of the 61.7k-dof blade,
#: CPU: block of 4, 80 columns, 1.7 s against ARPACK's 53-64 columns, 2.1-3.1 s; blocks of 8: 2.2-2.6 s).
_BLOCK_SOLVES = {"cholmod": BLOCK_SIZE, "cvxopt": 4}


@cache
def _missing(name: str) -> str | None:
    """Why backend ``name`` cannot be used here (``None`` if it can); probed once per process."""
    try:
        _PROBES[name]()
    except (ImportError, OSError) as exc:  # OSError: a shared library that does not load
        return f"{type(exc).__name__}: {exc}"
    return None


def available_backends() -> list[str]:
    """The sparse factorisation backends usable here, in :func:`factor_backend`'s order of preference.

    >>> available_backends()[-1]
    'superlu'
    """
    return [name for name in _PREFERENCE if name not in _PROBES or _missing(name) is None]


def factor_backend() -> str:
    """The sparse factorisation backend: the one place where it is chosen.

    ``$BLADECASE_FACTOR`` (:data:`BACKEND_ENV`) if set (``"superlu"``, ``"cvxopt"`` or ``"cholmod"``), else the
    first of :func:`available_backends`: ``"cholmod"`` where ``sksparse.cholmod`` imports, else ``"cvxopt"``
    where ``cvxopt.cholmod`` imports, else ``"superlu"``.

    Raises
    ------
    ValueError
        ``$BLADECASE_FACTOR`` names no backend, or one that is not installed (the message says why).

    >>> factor_backend() in ("cholmod", "cvxopt", "superlu")
    True
    """
    forced = os.environ.get(BACKEND_ENV, "").strip().lower()
    if not forced:
        return available_backends()[0]
    if forced not in _SPARSE_BACKENDS:
        raise ValueError(f"{BACKEND_ENV} = {forced!r} is not a factorisation backend: valid values are "
                         f"{', '.join(repr(k) for k in _PREFERENCE)} (or unset it to choose automatically)")
    why = _missing(forced) if forced in _PROBES else None
    if why is not None:
        raise ValueError(f"{BACKEND_ENV} = {forced!r} but that backend is not installed ({why}): "
                         f"{_INSTALL[forced]}, or unset {BACKEND_ENV} to use {available_backends()[0]!r}")
    return forced


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
        ``"superlu"``, ``"cvxopt"`` or ``"cholmod"`` (sparse, :func:`factor_backend`), ``"cholesky"`` or ``"lu"``
        (dense, scipy).
    fill : int
        Entries stored by the factors (``nnz(L) + nnz(U)`` for SuperLU, ``nnz(L)`` for CHOLMOD — counted on a
        copy, or for cvxopt a second factorisation, when first read —, ``n²`` dense): the memory it takes.
    """

    def __init__(self, name: str, n: int, kind: str, backend: str, solve: Callable, source=None, parts=None,
                 fill: int | Callable[[], int] | None = None):
        self.name, self.n, self.kind, self.backend = name, n, kind, backend
        self._fill = n * n if fill is None else fill
        self._solve = solve
        self._parts = parts
        try:
            self._source = weakref.ref(source) if source is not None else None
        except TypeError:  # not weak-referenceable
            self._source = None

    @property
    def fill(self) -> int:
        if callable(self._fill):
            self._fill = self._fill()
        return int(self._fill)

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


#: Sparse backends by name: ``factor(A_csc, name, hint, definite) -> (solve, ldlt, fill)`` (``fill`` an int
#: or a function that counts it when asked).
_SPARSE_BACKENDS = {"superlu": superlu_factor, "cvxopt": cvxopt_cholesky, "cholmod": cholmod_factor}


def _square(A, name: str) -> int:
    if getattr(A, "ndim", None) != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{name} must be a square matrix, got shape {getattr(A, 'shape', None)}")
    return A.shape[0]


def _finite(A, name: str) -> None:
    """Refuse inf/NaN entries (an overflowed model), which the factorisations report only as internals."""
    values = A.data if is_sparse(A) else np.asarray(A, dtype=float)
    bad = int(np.count_nonzero(~np.isfinite(values)))
    if bad:
        raise ValueError(f"{name} has {bad} non-finite entr{'y' if bad == 1 else 'ies'} (inf or NaN): the model "
                         "overflowed (mesh coordinates, material constants or thickness out of range?)")


def spd_factor(A, name: str = "A", *, hint: str = "") -> SPDFactor:
    """Factor a symmetric positive definite matrix (scipy sparse or dense); the symmetry is not checked.

    Sparse: the backend of :func:`factor_backend` (CHOLMOD's Cholesky or SuperLU's LDLᵀ, see the module
    docstring).  Dense: Cholesky.  A sparse matrix is never made dense.

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
    _finite(A, name)
    if not is_sparse(A):
        a = np.asarray(A, dtype=float)
        try:
            L = np.linalg.cholesky(a)
        except np.linalg.LinAlgError:
            lam_min = sla.eigvalsh(a, subset_by_index=[0, 0])[0]
            raise fail(name, f"is not positive definite: smallest eigenvalue {lam_min:.6g} (must be > 0)",
                        hint) from None
        return SPDFactor(name, n, "dense", "cholesky", lambda b: sla.cho_solve((L, True), b), A, L)
    diag = A.diagonal()
    if np.any(~(diag > 0)):
        i = int(np.flatnonzero(~(diag > 0))[0])
        raise fail(name, f"is not positive definite: diagonal entry {name}[{i},{i}] = {diag[i]:.6g} <= 0", hint)
    backend, A_csc = factor_backend(), sp.csc_array(A, dtype=float)
    try:
        solve, ldlt, fill = _SPARSE_BACKENDS[backend](A_csc, name, hint, True)
    except NotPositiveDefinite as exc:  # a Cholesky-only backend: SuperLU says why (pivot, singular, pivoting)
        superlu_factor(A_csc, name, hint, True)
        raise fail(name, f"is not positive definite: {exc}", hint) from None
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

    Sparse: the backend of :func:`factor_backend` with threshold pivoting (SuperLU if that backend does not
    pivot, as CHOLMOD).  Dense: LU.  For an SPD matrix
    use :func:`spd_factor` (it also checks definiteness).

    Raises
    ------
    ValueError
        ``A`` not square or singular (the message names ``A``, then ``hint``).
    """
    n = _square(A, name)
    _finite(A, name)
    if not is_sparse(A):
        with warnings.catch_warnings():  # a singular matrix: the error below says it
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu, piv = sla.lu_factor(np.asarray(A, dtype=float), check_finite=False)
        if np.any(np.diag(lu) == 0):
            raise fail(name, "is singular", hint)
        return Factor(name, n, "dense", "lu", lambda b: sla.lu_solve((lu, piv), b, check_finite=False), A)
    backend = factor_backend()
    backend = backend if backend in _PIVOTING else "superlu"
    solve, _, fill = _SPARSE_BACKENDS[backend](sp.csc_array(A, dtype=float), name, hint, False)
    return Factor(name, n, "sparse", backend, solve, A, fill=fill)


# ----------------------------------------------------------------------------- eigenpairs


def sign_convention(phi: np.ndarray) -> np.ndarray:
    """Flip each column so that its largest component (in absolute value) is positive."""
    idx = np.argmax(np.abs(phi), axis=0)
    return phi * np.sign(phi[idx, np.arange(phi.shape[1])])[None, :]


def _eigen_method(method: str, factor: Factor, n: int) -> str:
    """``"arpack"`` or ``"block"`` for :func:`lowest_modes`'s ``method`` (``"auto"`` chooses by backend and size)."""
    if method == "auto":
        return "block" if factor.backend in _BLOCK_SOLVES and n >= BLOCK_MIN_DOFS else "arpack"
    return method


def _sparse_modes(K, M, count: int, factor: Factor, method: str,
                  space: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Shift-invert eigenpairs about 0 with ``factor``: block Lanczos (falls back to ARPACK) or ARPACK, on one
    BLAS thread when the machine is busy (:func:`bladecase.threads.blas_threads`)."""
    with blas_threads("eigen"):
        return _shift_invert_modes(K, M, count, factor, method, space)


def _shift_invert_modes(K, M, count: int, factor: Factor, method: str,
                        space: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_sparse_modes` on the threads it was given."""
    if _eigen_method(method, factor, K.shape[0]) == "block" and count + 2 <= K.shape[0]:
        block = min(_BLOCK_SOLVES.get(factor.backend, BLOCK_SIZE), K.shape[0] - count)
        found = block_lanczos(K, M, factor.solve, count, block=block, space=space)
        if found is not None:
            return found
    # a fixed start vector: the same modes (signs, and the basis of repeated eigenvalues) on every run
    v0 = np.random.default_rng(0).standard_normal(K.shape[0])
    try:
        lam, phi = spla.eigsh(K, k=count, M=M, sigma=0.0, which="LM", OPinv=factor.operator(), v0=v0)
    except (spla.ArpackError, spla.ArpackNoConvergence) as exc:  # ArpackNoConvergence is an ArpackError
        raise ValueError(f"the eigen-solver (ARPACK's shift-invert Lanczos) failed on {factor.name} and M, "
                         f"{K.shape[0]} dofs, {count} modes: {exc} (K and M must be symmetric, K positive definite "
                         "and M positive semidefinite, both of a sensible scale)") from None
    order = np.argsort(lam)
    return lam[order], phi[:, order]


def _check_pencil(K, M, name: str) -> None:
    """Refuse what the eigen-solvers would only report as ARPACK/LAPACK internals: ``M`` of another shape,
    non-finite entries, ``M = 0``, a negative diagonal entry of ``M``."""
    n = K.shape[0]
    if getattr(M, "ndim", None) != 2 or M.shape != (n, n):
        raise ValueError(f"M must be a {n} × {n} matrix like {name}, got shape {getattr(M, 'shape', None)}")
    _finite(K, name)
    _finite(M, "M")
    diag = np.asarray(M.diagonal(), dtype=float)
    if not np.any(diag) and (M.count_nonzero() if is_sparse(M) else np.count_nonzero(M)) == 0:
        raise ValueError("M is zero: the model has no mass (zero density, or a mesh whose cells have no volume)")
    if np.any(diag < 0):
        i = int(np.argmin(diag))
        raise ValueError(f"M is not positive semidefinite: diagonal entry M[{i},{i}] = {diag[i]:.6g} < 0 (a negative "
                         "density or thickness?)")


def lowest_modes(
    K, M, count: int, factor: SPDFactor | None = None, *, dense: bool | None = None, name: str = "K", hint: str = "",
    method: str = "auto", space: list | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` lowest eigenpairs ``(λ, Φ)`` of ``K φ = λ M φ`` (``K``, ``M`` symmetric positive definite).

    Sparse (default for sparse ``K``): shift-invert about ``σ = 0`` with the factorisation of ``K`` —
    ``factor`` if given (from :func:`spd_factor`, reused), else computed here — by ARPACK's Lanczos
    (``eigsh`` with the factor as ``OPinv``) or by the block Lanczos of :mod:`bladecase.linalg_block`
    (``method``; ARPACK if the block solver does not converge within its basis).  Dense
    (``scipy.linalg.eigh``): for dense ``K``, or when ``dense=True``, or (``dense=None``)
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
    method : str
        Sparse path: ``"arpack"``, ``"block"``, or ``"auto"`` (block Lanczos for a factor that solves blocks
        fast, CHOLMOD, and at least :data:`BLOCK_MIN_DOFS` rows; ARPACK otherwise).  Both give the frequencies
        to ~1e-10 relative (residuals ``‖Kφ - λMφ‖ / ‖Kφ‖`` ~1e-8).
    space : list or None
        When the block Lanczos found the modes, the Ritz vectors of the rest of its Krylov basis are appended
        to it (``block_lanczos``'s ``space``); nothing is appended otherwise.

    Returns
    -------
    lam : (count,) ndarray
        Eigenvalues ``ω²``, ascending.
    phi : (n, count) ndarray
        M-normalised modes (``ΦᵀMΦ = I``), each column's largest component positive.

    Raises
    ------
    ValueError
        ``count`` out of range, ``factor`` of another size, ``K`` not positive definite, ``method`` unknown.

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
    if method not in EIGEN_METHODS:
        raise ValueError(f"method must be one of {', '.join(map(repr, EIGEN_METHODS))}, got {method!r}")
    _check_pencil(K, M, name)
    sparse = is_sparse(K)
    if dense is None:
        dense = not sparse or count >= n or (count > n // 2 and n <= DENSE_LIMIT)
    if dense:
        if sparse and n > DENSE_LIMIT:
            raise ValueError(f"lowest_modes: {count} of the {n} modes of {name} need a dense eigen-solution, "
                             f"limited to DENSE_LIMIT = {DENSE_LIMIT} rows (the sparse solver gives at most {n - 1})")
        if count > n // 4:  # all pairs by divide and conquer: several times faster than the subset driver here
            lam, phi = sla.eigh(_dense(K), _dense(M), driver="gvd")
            lam, phi = lam[:count], phi[:, :count]
        else:
            lam, phi = sla.eigh(_dense(K), _dense(M), subset_by_index=[0, count - 1])
    else:
        if count >= n:
            raise ValueError(f"count = {count}: the sparse eigen-solver gives at most {n - 1} of the {n} modes of "
                             f"{name} (use dense=True)")
        if factor is None:
            factor = spd_factor(K, name, hint=hint)
        elif not isinstance(factor, Factor) or factor.n != n:
            raise ValueError(f"factor must be a factorisation of {name} ({n} × {n}, from spd_factor), got {factor!r}")
        lam, phi = _sparse_modes(K, M, count, factor, method, space)
        norms = np.einsum("ij,ij->j", phi, M @ phi)
        if not np.all(norms > 0):
            raise ValueError(f"M gives mode {int(np.argmin(norms > 0)) + 1} a modal mass {norms.min():.3g} <= 0: M is "
                             "not positive semidefinite or has no mass on that mode's dofs")
        phi = phi / np.sqrt(norms)[None, :]
    if not np.all(np.isfinite(lam)) or lam[0] <= 0:
        raise fail(name, f"is not positive definite: eigenvalue {lam[0]:.3g} (a mechanism? degenerate cells?)", hint)
    return lam, sign_convention(phi)


#: Largest dense matrix :func:`positive_definite` factorises by Cholesky (a sparse one goes to :func:`spd_factor`).
_DENSE_CHOLESKY = 6000


def positive_definite(name: str, a, hint: str = "", rtol: float = SINGULAR_RTOL):
    """``ValueError`` unless the finite symmetric matrix ``a`` is positive definite, and not singular to working
    precision: smallest eigenvalue ``<= rtol * max diag`` (:data:`SINGULAR_RTOL`); ``hint`` ends the message.

    Dense (at most 6000 rows): Cholesky (on failure the extreme eigenvalues go into the message); its smallest
    pivot bounds the smallest eigenvalue from above.  Sparse: the project's factorisation,
    :func:`bladecase.linalg.spd_factor` (never dense, pivots checked > 0), then two steps of inverse iteration
    whose Rayleigh quotient bounds the smallest eigenvalue from above (a singular matrix gives round-off there).
    Returns the factor of a sparse ``a`` (``None`` for a dense one).

    >>> positive_definite("K", np.array([[1.0, 2.0], [2.0, 1.0]]), hint="clamp it")
    Traceback (most recent call last):
        ...
    ValueError: K is not positive definite: smallest eigenvalue -1 (largest 3; it must be > 0): clamp it
    """
    tail = f": {hint}" if hint else ""
    n = a.shape[0]
    diag = np.asarray(a.diagonal(), dtype=float)
    scale = float(np.abs(diag).max()) if n else 0.0
    if n and not np.any(a.data if is_sparse(a) else a):
        raise ValueError(f"{name} is zero (all {n}² entries), not positive definite{tail}")
    if is_sparse(a) or n > _DENSE_CHOLESKY:
        factor = spd_factor(a, name, hint=hint)
        x = np.random.default_rng(0).standard_normal(n)
        for _ in range(2):
            x = factor.solve(x)
            x /= np.linalg.norm(x)
        low = float(x @ (a @ x))
    else:
        factor = None
        try:
            low = float(np.diag(np.linalg.cholesky(a)).min() ** 2)
        except np.linalg.LinAlgError:
            lam = sla.eigvalsh(a)[[0, -1]] if n <= 2 else np.r_[
                sla.eigvalsh(a, subset_by_index=[0, 0]), sla.eigvalsh(a, subset_by_index=[n - 1, n - 1])]
            raise ValueError(f"{name} is not positive definite: smallest eigenvalue {lam[0]:.6g} (largest "
                             f"{lam[1]:.6g}; it must be > 0){tail}") from None
    if not low > rtol * scale:
        raise ValueError(f"{name} is singular to working precision, not positive definite: its smallest eigenvalue is "
                         f"at most {low:.3g} <= {rtol:g} * max diag {name} = {rtol * scale:.3g}{tail}")
    return factor
