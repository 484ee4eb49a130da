"""Optional sparse Cholesky backend of :mod:`bladecase.linalg`: CHOLMOD as shipped in cvxopt's wheels.

``cvxopt`` (PyPI wheels for Linux, macOS and Windows) bundles SuiteSparse's CHOLMOD with an optimised BLAS,
so ``pip`` installs it with no compiler and no system headers (``make`` installs it).  Its factorisation is
CHOLMOD's supernodal Cholesky ``Pᵀ A P = L Lᵀ`` (AMD ordering: cvxopt's CHOLMOD has no METIS), single-threaded;
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

__all__ = ["NotPositiveDefinite", "SPSOLVE_MIN_COLUMNS", "cvxopt_cholesky", "import_cvxopt"]

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


def _factor(cholmod, lower):
    with _default_options(cholmod):
        F = cholmod.symbolic(lower, uplo="L")
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
    n, lower = A.shape[0], _lower(cvxopt, sp.csc_array(A))  # the closures keep n and lower, not A
    F = _factor(cholmod, lower)

    def solve(b: np.ndarray) -> np.ndarray:
        if b.ndim == 2 and b.shape[1] >= SPSOLVE_MIN_COLUMNS:  # CHOLMOD's supernodal solve, 4 columns at a time
            return np.array(cvxopt.matrix(cholmod.spsolve(F, cvxopt.sparse(cvxopt.matrix(np.asfortranarray(b))))))
        B = cvxopt.matrix(np.asfortranarray(b))  # a copy: (n,) -> (n, 1)
        cholmod.solve(F, B)
        return np.array(B).reshape(b.shape)

    def ldlt():
        G = _factor(cholmod, lower)
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
