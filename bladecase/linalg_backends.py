"""The sparse factorisation backends of :mod:`bladecase.linalg`: SuperLU (always there; symmetric mode, LDLᵀ
pivots checked), scikit-sparse's CHOLMOD where installed, and CHOLMOD as shipped in cvxopt's wheels (below).

``cvxopt`` (PyPI wheels for Linux, macOS and Windows) bundles SuiteSparse's CHOLMOD with an optimised BLAS,
so ``pip`` installs it with no compiler and no system headers (``make`` installs it).  Its factorisation is
CHOLMOD's supernodal Cholesky ``Pᵀ A P = L Lᵀ`` (cvxopt's CHOLMOD has no METIS: large matrices are ordered by
METIS's nested dissection through ``pymetis`` where installed, :mod:`bladecase.ordering`, else by CHOLMOD's AMD),
single-threaded;
on the 110k-dof blade it is 5 to 6 times faster than SuperLU and takes a third of its memory
(``docs/performance.md``).  cvxopt's ``cholmod.solve`` solves a block of right-hand sides one column at a time;
a block of :data:`SPSOLVE_MIN_COLUMNS` or more goes through its ``cholmod.spsolve`` instead, CHOLMOD's supernodal
solve of 4 columns at a time, about twice as fast per column, so :func:`bladecase.linalg.lowest_modes` uses its
block Lanczos in blocks of 4 on large models.

The backend protocol is :mod:`bladecase.linalg`'s: ``factor(A_csc, name, hint, definite) -> (solve, ldlt,
fill)``, registered there in ``_SPARSE_BACKENDS`` with its import probe.  A matrix that is not positive definite
raises :class:`NotPositiveDefinite`, which :func:`bladecase.linalg.spd_factor` turns into SuperLU's diagnosis
(the same messages whatever the backend).  Tests: ``tests/test_linalg_backends.py`` (skipped without cvxopt).
"""

from __future__ import annotations

import ctypes
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .ordering import nested_dissection

__all__ = ["INDEFINITE_PIVOT_THRESHOLD", "NotPositiveDefinite", "SPSOLVE_MIN_COLUMNS", "cholmod_factor",
           "cvxopt_cholesky", "fail", "import_cholmod", "import_cvxopt", "superlu_factor"]

#: Blocks of at least this many right-hand sides are solved through cvxopt's ``cholmod.spsolve`` (CHOLMOD's
#: supernodal solve of 4 columns at a time, the block given and returned as sparse matrices — dense here);
#: ``cholmod.solve`` solves column by column.  61.7k-dof blade, ms per column: 1 column 33, 2: 33 (either),
#: 3: 25, 4: 18, 8: 15 (``spsolve``) against 31-33 for ``solve`` whatever the block.
SPSOLVE_MIN_COLUMNS = 3


class NotPositiveDefinite(ArithmeticError):
    """Raised by a backend that factors positive definite matrices only when its Cholesky fails."""


def import_cvxopt():
    """``(cvxopt, cvxopt.cholmod)``; ``ImportError`` where cvxopt is not installed."""
    import cvxopt  # optional: pip install cvxopt (wheels bundle CHOLMOD and a BLAS)
    from cvxopt import cholmod

    return cvxopt, cholmod


@contextmanager
def _default_options(cholmod) -> Iterator[None]:
    """cvxopt's CHOLMOD defaults (supernodal ``LLᵀ``, which fails on a pivot <= 0) whatever the user set."""
    saved = dict(cholmod.options)
    cholmod.options.clear()
    try:
        yield
    finally:
        cholmod.options.clear()
        cholmod.options.update(saved)


def _lower(cvxopt, A: sp.csc_array):
    """The lower triangle of ``A`` as a cvxopt ``spmatrix`` (built column-wise, no copy of the whole ``A``)."""
    n = A.shape[0]
    col = np.repeat(np.arange(n, dtype=np.int64), np.diff(A.indptr))
    keep = A.indices >= col
    rows, cols, values = A.indices[keep].astype(np.int64), col[keep], A.data[keep]
    return cvxopt.spmatrix(values, rows, cols, (n, n))


def _release_freed_memory() -> None:
    """Hand the heap that CHOLMOD's work arrays freed back to the system (glibc's ``malloc_trim``; elsewhere
    nothing): 130 MiB of resident memory at 110k dofs, which would otherwise stay with the process."""
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (AttributeError, OSError, TypeError):  # not glibc (macOS, musl, Windows)
        pass


def _factor(cholmod, lower, perm=None):
    with _default_options(cholmod):
        if perm is None:
            F = cholmod.symbolic(lower, uplo="L")
        else:
            import cvxopt

            F = cholmod.symbolic(lower, p=cvxopt.matrix(perm.astype(np.int32), tc="i"), uplo="L")
        try:
            cholmod.numeric(lower, F)
        except ArithmeticError:  # CHOLMOD_NOT_POSDEF: cvxopt gives the failing column
            raise NotPositiveDefinite("CHOLMOD's Cholesky factorisation met a pivot <= 0") from None
    _release_freed_memory()
    return F


def cvxopt_cholesky(A: sp.csc_array, name: str, hint: str, definite: bool):
    """CHOLMOD's supernodal Cholesky through cvxopt: ``(solve, ldlt, fill)``; SPD matrices only.

    ``ldlt`` and ``fill`` factor ``A`` a second time (cvxopt hands ``L`` out only by consuming the factor), from
    the lower triangle kept for that (16 bytes per entry, ~1/8 of the factor's memory).
    """
    if not definite:
        raise ValueError("the cvxopt backend factors positive definite matrices only (no pivoting)")
    cvxopt, cholmod = import_cvxopt()
    perm = nested_dissection(A)  # METIS where installed and worth it; else CHOLMOD's AMD
    n, lower = A.shape[0], _lower(cvxopt, sp.csc_array(A))  # the closures keep n and lower, not A
    F = _factor(cholmod, lower, perm)

    def solve(b: np.ndarray) -> np.ndarray:
        if b.ndim == 2 and b.shape[1] >= SPSOLVE_MIN_COLUMNS:  # CHOLMOD's supernodal solve, 4 columns at a time
            return np.array(cvxopt.matrix(cholmod.spsolve(F, cvxopt.sparse(cvxopt.matrix(np.asfortranarray(b))))))
        B = cvxopt.matrix(np.asfortranarray(b))  # a copy: (n,) -> (n, 1)
        cholmod.solve(F, B)
        return np.array(B).reshape(b.shape)

    def ldlt():
        G = _factor(cholmod, lower, perm)
        p = cvxopt.matrix(np.arange(n, dtype=float))
        cholmod.solve(G, p, sys=7)  # CHOLMOD_P: p = Perm, A[Perm][:, Perm] = L Lᵀ
        colptr, rows, values = (np.array(a).ravel() for a in cholmod.getfactor(G).CCS)
        L = sp.csc_array((values, rows.astype(np.int64), colptr.astype(np.int64)), shape=(n, n))
        L.sum_duplicates()
        L.sort_indices()
        root = L.diagonal()  # L Lᵀ = (L/root) root² (L/root)ᵀ
        L.data /= np.repeat(root, np.diff(L.indptr))
        return L, root**2, np.argsort(np.array(p).ravel().astype(np.int64))

    return solve, ldlt, lambda: ldlt()[0].nnz


#: Diagonal pivot threshold of the indefinite factorisation (:func:`symmetric_factor`): SuperLU keeps the
#: diagonal pivot unless it is below this fraction of the largest entry of its column.
INDEFINITE_PIVOT_THRESHOLD = 0.1


def fail(name: str, why: str, hint: str) -> ValueError:
    return ValueError(f"{name} {why}" + (f": {hint}" if hint else ""))


def import_cholmod():
    from sksparse import cholmod  # optional: scikit-sparse, needs SuiteSparse's CHOLMOD

    return cholmod


def superlu_factor(A: sp.csc_array, name: str, hint: str, definite: bool):
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
        raise fail(name, f"{what} ({exc})", hint) from None
    if definite:
        pivots = lu.U.diagonal()
        if not np.array_equal(lu.perm_r, lu.perm_c):
            raise fail(name, "is not positive definite: its LDLᵀ factorisation needed off-diagonal pivoting", hint)
        if np.any(~(pivots > 0)):
            raise fail(name, f"is not positive definite: its LDLᵀ factorisation has a pivot {pivots.min():.6g} <= 0",
                        hint)

    def ldlt():
        L = sp.csc_array(lu.L)
        L.sum_duplicates()
        L.sort_indices()
        return L, lu.U.diagonal(), np.asarray(lu.perm_c)

    return lu.solve, ldlt, lu.L.nnz + lu.U.nnz


def cholmod_factor(A: sp.csc_array, name: str, hint: str, definite: bool):
    """CHOLMOD's supernodal Cholesky ``Pᵀ A P = L Lᵀ``: ``(solve, ldlt, fill)``; SPD matrices only.

    A matrix that is not positive definite raises :class:`NotPositiveDefinite` (:func:`spd_factor` diagnoses).
    :meth:`SPDFactor.ldlt` turns the factor into CHOLMOD's simplicial LDLᵀ in place (solves stay right).
    """
    if not definite:
        raise ValueError("the CHOLMOD backend factors positive definite matrices only (no pivoting)")
    cholmod = import_cholmod()
    try:
        f = cholmod.cholesky(A, mode="supernodal")  # LLᵀ: simplicial would be an LDLᵀ, not checking definiteness
    except cholmod.CholmodNotPositiveDefiniteError:
        raise NotPositiveDefinite("CHOLMOD's Cholesky factorisation met a pivot <= 0") from None

    def ldlt():
        L, D = f.L_D()  # A[p][:, p] = L D Lᵀ
        L = sp.csc_array(L)
        L.sum_duplicates()
        L.sort_indices()
        return L, np.asarray(D.diagonal()), np.argsort(f.P())

    return f.solve_A, ldlt, lambda: f.copy().L().nnz
