"""Sparse factorisation backends of ``bladecase.linalg``: run-time detection, ``$BLADECASE_FACTOR``, CHOLMOD
(scikit-sparse) and cvxopt's CHOLMOD.

References: SuperLU (always installed) for the same solves and the same error messages; the dense
``numpy``/``scipy`` solution of small SPD matrices.  The CHOLMOD tests run where ``sksparse.cholmod``
imports (``scikit-sparse<0.5`` built on SuiteSparse), the cvxopt tests where ``cvxopt.cholmod`` imports
(``make`` installs its wheel); each set is skipped elsewhere.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from bladecase import linalg
from bladecase.linalg import (
    BACKEND_ENV,
    BLOCK_MIN_DOFS,
    Factor,
    available_backends,
    factor_backend,
    lowest_modes,
    spd_factor,
    symmetric_factor,
)


def laplacian(k: int) -> sp.csr_array:
    """The 5-point Laplacian of a k × k grid, Dirichlet (SPD, k² rows)."""
    t = sp.diags_array([[-1.0] * (k - 1), [2.0] * k, [-1.0] * (k - 1)], offsets=[-1, 0, 1])
    return sp.csr_array(sp.kron(t, sp.eye_array(k)) + sp.kron(sp.eye_array(k), t))


def laplacian3(k: int) -> sp.csc_array:
    """The 7-point Laplacian of a k × k × k grid, Dirichlet (SPD, k³ rows, fill like a 3-D FE stiffness)."""
    t = sp.diags_array([[-1.0] * (k - 1), [2.0] * k, [-1.0] * (k - 1)], offsets=[-1, 0, 1])
    i = sp.eye_array(k)
    return sp.csc_array(sp.kron(sp.kron(t, i), i) + sp.kron(sp.kron(i, t), i) + sp.kron(sp.kron(i, i), t))


def _without(monkeypatch, *names):
    """A machine where the optional backends ``names`` do not import."""
    def missing(module):
        def probe():
            raise ImportError(f"No module named {module!r}")
        return probe

    linalg._missing.cache_clear()
    for name in names:
        monkeypatch.setitem(linalg._PROBES, name, missing({"cholmod": "sksparse"}.get(name, name)))


@pytest.fixture
def no_optional(monkeypatch):
    """A machine with neither scikit-sparse nor cvxopt (a fresh machine where make could not install cvxopt)."""
    _without(monkeypatch, "cholmod", "cvxopt")
    yield
    linalg._missing.cache_clear()


@pytest.fixture
def no_cholmod(monkeypatch):
    """A machine without scikit-sparse: its import probe fails."""
    _without(monkeypatch, "cholmod")
    yield
    linalg._missing.cache_clear()


def test_superlu_is_the_fallback_and_can_be_forced(monkeypatch, no_optional):
    monkeypatch.delenv(BACKEND_ENV, raising=False)
    assert available_backends() == ["superlu"] and factor_backend() == "superlu"
    assert spd_factor(laplacian(5), "K").backend == "superlu"
    monkeypatch.setenv(BACKEND_ENV, " SuperLU ")
    assert factor_backend() == "superlu"


def test_a_forced_backend_that_is_missing_or_unknown_is_an_error(monkeypatch, no_optional):
    monkeypatch.setenv(BACKEND_ENV, "cholmod")
    with pytest.raises(ValueError, match=r"BLADECASE_FACTOR = 'cholmod' but that backend is not installed "
                                         r"\(ImportError: No module named 'sksparse'\): install scikit-sparse<0.5"):
        factor_backend()
    with pytest.raises(ValueError, match="BLADECASE_FACTOR = 'cholmod' but"):
        spd_factor(laplacian(3), "K")
    monkeypatch.setenv(BACKEND_ENV, "cvxopt")
    with pytest.raises(ValueError, match=r"BLADECASE_FACTOR = 'cvxopt' but that backend is not installed "
                                         r"\(ImportError: No module named 'cvxopt'\): pip install cvxopt .* or "
                                         r"unset BLADECASE_FACTOR to use 'superlu'"):
        spd_factor(laplacian(3), "K")
    monkeypatch.setenv(BACKEND_ENV, "pardisoo")
    with pytest.raises(ValueError, match=r"BLADECASE_FACTOR = 'pardisoo' is not a factorisation backend: valid "
                                         r"values are 'cholmod', 'cvxopt', 'superlu'"):
        factor_backend()


def test_the_preferred_backend_is_the_first_available(monkeypatch):
    monkeypatch.delenv(BACKEND_ENV, raising=False)
    expected = next(name for name in ("cholmod", "cvxopt", "superlu")
                    if name == "superlu" or linalg._missing(name) is None)
    assert factor_backend() == expected == available_backends()[0]


# --------------------------------------------------------------------------- CHOLMOD (where installed)


@pytest.fixture
def cholmod(monkeypatch):
    pytest.importorskip("sksparse.cholmod")
    monkeypatch.setenv(BACKEND_ENV, "cholmod")


def test_cholmod_solves_like_superlu_and_reproduces_its_ldlt(cholmod, monkeypatch):
    K = laplacian(12)  # 144 rows
    f = spd_factor(K, "K")
    assert f.backend == "cholmod" and f.kind == "sparse" and f.is_of(K)
    B = np.random.default_rng(0).standard_normal((144, 4))
    X = f.solve(B)
    np.testing.assert_allclose(K @ X, B, rtol=0, atol=1e-12)
    np.testing.assert_allclose(f.solve(B[:, 0]), X[:, 0], rtol=0, atol=1e-14)
    monkeypatch.setenv(BACKEND_ENV, "superlu")
    np.testing.assert_allclose(X, spd_factor(K, "K").solve(B), rtol=0, atol=1e-12)
    lower = np.linalg.cholesky(K.toarray())
    assert np.count_nonzero(np.abs(lower) > 1e-14) <= f.fill < 144 * 145 // 2  # fill-reducing ordering
    L, d, perm = f.ldlt()
    assert np.all(d > 0) and np.allclose(L.diagonal(), 1.0) and sorted(perm) == list(range(144))
    P = sp.csr_array((np.ones(144), (np.arange(144), perm)), shape=(144, 144))  # (Pᵀx)[perm] = x
    np.testing.assert_allclose((P.T @ K @ P).toarray(), (L @ sp.diags_array(d) @ L.T).toarray(), atol=1e-13)
    np.testing.assert_allclose(K @ f.solve(B), B, rtol=0, atol=1e-12)  # still solves after ldlt()


@pytest.mark.parametrize("matrix, pattern", [
    (np.array([[1.0, 2.0], [2.0, 1.0]]), r"Kx is not positive definite: its LDLᵀ .* pivot -3 <= 0: hint$"),
    (np.array([[1.0, 1.0], [1.0, 1.0]]), r"Kx is singular, hence not positive definite"),
    (np.diag([1.0, -1.0]), r"Kx is not positive definite: diagonal entry Kx\[1,1\] = -1 <= 0"),
])
def test_cholmod_reports_indefinite_matrices_as_superlu_does(cholmod, matrix, pattern):
    with pytest.raises(ValueError, match=pattern):
        spd_factor(sp.csr_array(matrix), "Kx", hint="hint")


def _indefinite_goes_to_superlu(A, atol: float) -> None:
    """``spd_factor`` refuses the indefinite ``A``; ``symmetric_factor`` solves it with SuperLU."""
    with pytest.raises(ValueError, match=r"^A is not positive definite"):
        spd_factor(A, "A")
    f = symmetric_factor(A, "A")
    assert f.backend == "superlu"
    b = np.linspace(-1.0, 1.0, A.shape[0])
    np.testing.assert_allclose(A @ f.solve(b), b, rtol=0, atol=atol)


def test_cholmod_leaves_indefinite_factorisations_to_superlu(cholmod):
    _indefinite_goes_to_superlu(laplacian(6) - 1.5 * sp.eye_array(36), 1e-12)  # indefinite, non-singular


def _laplacian_modes(methods) -> tuple:
    """The 5 lowest modes of the 20 × 20 grid Laplacian by each of ``methods`` with the backend's own factor, against
    the closed form ``4 sin²(iπ/42) + 4 sin²(jπ/42)``; ``(K, M, factor, exact)`` for more checks."""
    K = laplacian(20)
    M = sp.eye_array(400, format="csr")
    f = spd_factor(K, "K")
    k = np.arange(1, 4)
    exact = np.sort((4 * np.sin(k[:, None] * np.pi / 42) ** 2 + 4 * np.sin(k[None, :] * np.pi / 42) ** 2).ravel())
    for method in methods:
        lam, phi = lowest_modes(K, M, 5, factor=f, method=method)
        np.testing.assert_allclose(lam, exact[:5], rtol=1e-10, atol=0)
        np.testing.assert_allclose(phi.T @ phi, np.eye(5), atol=1e-10)
    return K, M, f, exact


def test_cholmod_factor_gives_the_modes_with_either_eigen_solver(cholmod):
    _laplacian_modes(("arpack", "block"))


# --------------------------------------------------------------------------- cvxopt's CHOLMOD (where installed)


@pytest.fixture
def cvxopt_forced(monkeypatch):
    """``BLADECASE_FACTOR=cvxopt`` where cvxopt is installed (skipped elsewhere)."""
    pytest.importorskip("cvxopt.cholmod")
    monkeypatch.setenv(BACKEND_ENV, "cvxopt")


def test_cvxopt_is_chosen_without_scikit_sparse(monkeypatch, no_cholmod):
    pytest.importorskip("cvxopt.cholmod")
    monkeypatch.delenv(BACKEND_ENV, raising=False)
    assert available_backends() == ["cvxopt", "superlu"] and factor_backend() == "cvxopt"
    assert spd_factor(laplacian(4), "K").backend == "cvxopt"
    monkeypatch.setenv(BACKEND_ENV, "superlu")  # and SuperLU can still be forced
    assert spd_factor(laplacian(4), "K").backend == "superlu"


def test_cvxopt_solves_like_superlu(cvxopt_forced, monkeypatch):
    K = laplacian3(11)  # 1331 rows, supernodal
    f = spd_factor(K, "K")
    assert f.backend == "cvxopt" and f.kind == "sparse" and f.is_of(K) and f.n == 1331
    B = np.random.default_rng(0).standard_normal((1331, 5))
    X = f.solve(B)
    assert X.shape == (1331, 5)
    np.testing.assert_allclose(K @ X, B, rtol=0, atol=1e-12)
    x = f.solve(B[:, 1])  # a 1-D right-hand side (a strided view) gives a 1-D answer
    assert x.shape == (1331,)
    np.testing.assert_allclose(x, X[:, 1], rtol=0, atol=1e-14)
    np.testing.assert_allclose(f.solve(np.asfortranarray(B)), X, rtol=0, atol=0)
    # two columns are solved one by one, five by CHOLMOD's block solve (``spsolve``): the same to round-off
    np.testing.assert_allclose(f.solve(sp.csr_array(B[:, :2])), X[:, :2], rtol=0, atol=1e-14)  # sparse right-hand side
    np.testing.assert_allclose(f.solve(sp.csr_array(B[:, :2])), f.solve(B[:, :2]), rtol=0, atol=0)
    np.testing.assert_allclose(f.operator() @ B[:, 1], x, rtol=0, atol=0)
    Z = B.copy()
    Z[:, 3] = 0.0  # a zero column in a block: zeros back
    assert not np.any(f.solve(Z)[:, 3]) and f.solve(Z[:, 2:5]).shape == (1331, 3)
    monkeypatch.setenv(BACKEND_ENV, "superlu")
    reference = spd_factor(K, "K").solve(B)
    assert np.abs(X - reference).max() <= 1e-10 * np.abs(reference).max()


def test_cvxopt_reproduces_the_ldlt_and_counts_its_fill(cvxopt_forced):
    K = laplacian(12)  # 144 rows
    f = spd_factor(K, "K")
    lower = np.linalg.cholesky(K.toarray())
    assert np.count_nonzero(np.abs(lower) > 1e-14) <= f.fill < 144 * 145 // 2  # fill-reducing ordering
    L, d, perm = f.ldlt()
    assert L.has_sorted_indices and sp.triu(L, 1).nnz == 0 and np.allclose(L.diagonal(), 1.0)
    assert np.all(d > 0) and sorted(perm) == list(range(144)) and L.nnz == f.fill
    P = sp.csr_array((np.ones(144), (np.arange(144), perm)), shape=(144, 144))  # (Pᵀx)[perm] = x
    np.testing.assert_allclose((P.T @ K @ P).toarray(), (L @ sp.diags_array(d) @ L.T).toarray(), atol=1e-13)
    b = np.linspace(-1.0, 1.0, 144)
    np.testing.assert_allclose(K @ f.solve(b), b, rtol=0, atol=1e-12)  # still solves after ldlt()


@pytest.mark.parametrize("matrix", [
    np.array([[1.0, 2.0], [2.0, 1.0]]),  # a negative pivot
    np.array([[1.0, 1.0], [1.0, 1.0]]),  # singular
    np.diag([1.0, -1.0]),  # a negative diagonal entry
    np.array([[2.0, 1.0, 0.0], [1.0, 0.5, 1.0], [0.0, 1.0, 2.0]]),  # a zero pivot after elimination
])
def test_cvxopt_refuses_what_superlu_refuses_with_the_same_message(cvxopt_forced, monkeypatch, matrix):
    A = sp.csr_array(matrix)
    with pytest.raises(ValueError, match="^Kx is (not positive definite|singular)") as mine:
        spd_factor(A, "Kx", hint="is the model clamped?")
    monkeypatch.setenv(BACKEND_ENV, "superlu")
    with pytest.raises(ValueError) as superlu:
        spd_factor(A, "Kx", hint="is the model clamped?")
    assert str(mine.value) == str(superlu.value) and str(mine.value).endswith(": is the model clamped?")


def test_cvxopt_refuses_an_indefinite_matrix_and_leaves_it_to_superlu(cvxopt_forced):
    A = sp.csc_array(laplacian3(8) - 0.8 * sp.eye_array(512))  # eigenvalues -0.44 (lowest), -0.09, 0.26, ...
    _indefinite_goes_to_superlu(A, 1e-10)


def test_cvxopt_ignores_and_keeps_the_users_cholmod_options(cvxopt_forced):
    from cvxopt import cholmod

    cholmod.options["supernodal"] = 0  # simplicial LDLᵀ would accept an indefinite matrix
    try:
        with pytest.raises(ValueError, match="not positive definite"):
            spd_factor(sp.csr_array(np.array([[1.0, 2.0], [2.0, 1.0]])), "K")
        assert cholmod.options == {"supernodal": 0}
    finally:
        cholmod.options.clear()


def test_cvxopt_factor_gives_the_modes_with_either_eigen_solver_and_auto_takes_blocks_of_four_on_large_models(
        cvxopt_forced, monkeypatch):
    K, M, f, exact = _laplacian_modes(("arpack", "block", "auto"))
    lam, _ = lowest_modes(K, M, 5)  # factorised here, by the forced backend
    np.testing.assert_allclose(lam, exact[:5], rtol=1e-10, atol=0)
    solve = f.solve
    assert linalg._eigen_method("auto", Factor("K", BLOCK_MIN_DOFS - 1, "sparse", "cvxopt", solve),
                                BLOCK_MIN_DOFS - 1) == "arpack"
    # at BLOCK_MIN_DOFS rows the block Lanczos, 4 right-hand sides per solve (cvxopt's spsolve chunk)
    k = 28
    K = laplacian3(k)  # 21 952 rows
    f = spd_factor(K, "K")
    widths, inner = [], f._solve

    def recording(b):
        widths.append(1 if b.ndim == 1 else b.shape[1])
        return inner(b)
    monkeypatch.setattr(f, "_solve", recording)
    lam, phi = lowest_modes(K, sp.eye_array(k**3, format="csr"), 4, factor=f)
    assert K.shape[0] >= BLOCK_MIN_DOFS and widths and set(widths) == {4}
    s = 4 * np.sin(np.arange(1, 4) * np.pi / (2 * (k + 1))) ** 2  # 1-D eigenvalues; the 3-D ones are sums
    exact = np.sort((s[:, None, None] + s[None, :, None] + s[None, None, :]).ravel())
    np.testing.assert_allclose(lam, exact[:4], rtol=1e-10, atol=0)
