"""Sparse factorisation backends of ``bladecase.linalg``: run-time detection, ``$BLADECASE_FACTOR``, CHOLMOD.

References: SuperLU (always installed) for the same solves and the same error messages; the dense
``numpy``/``scipy`` solution of small SPD matrices.  The CHOLMOD tests run where ``sksparse.cholmod``
imports (``scikit-sparse<0.5`` built on SuiteSparse) and are skipped elsewhere.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from bladecase import linalg
from bladecase.linalg import BACKEND_ENV, available_backends, factor_backend, lowest_modes, spd_factor, symmetric_factor


def laplacian(k: int) -> sp.csr_array:
    """The 5-point Laplacian of a k × k grid, Dirichlet (SPD, k² rows)."""
    t = sp.diags_array([[-1.0] * (k - 1), [2.0] * k, [-1.0] * (k - 1)], offsets=[-1, 0, 1])
    return sp.csr_array(sp.kron(t, sp.eye_array(k)) + sp.kron(sp.eye_array(k), t))


@pytest.fixture
def no_cholmod(monkeypatch):
    """A machine without scikit-sparse: its import probe fails."""
    def missing():
        raise ImportError("No module named 'sksparse'")

    linalg._missing.cache_clear()
    monkeypatch.setitem(linalg._PROBES, "cholmod", missing)
    yield
    linalg._missing.cache_clear()


def test_superlu_is_the_fallback_and_can_be_forced(monkeypatch, no_cholmod):
    monkeypatch.delenv(BACKEND_ENV, raising=False)
    assert available_backends() == ["superlu"] and factor_backend() == "superlu"
    assert spd_factor(laplacian(5), "K").backend == "superlu"
    monkeypatch.setenv(BACKEND_ENV, " SuperLU ")
    assert factor_backend() == "superlu"


def test_a_forced_backend_that_is_missing_or_unknown_is_an_error(monkeypatch, no_cholmod):
    monkeypatch.setenv(BACKEND_ENV, "cholmod")
    with pytest.raises(ValueError, match=r"BLADECASE_FACTOR = 'cholmod' but that backend is not installed "
                                         r"\(ImportError: No module named 'sksparse'\): install scikit-sparse<0.5"):
        factor_backend()
    with pytest.raises(ValueError, match="BLADECASE_FACTOR = 'cholmod' but"):
        spd_factor(laplacian(3), "K")
    monkeypatch.setenv(BACKEND_ENV, "pardisoo")
    with pytest.raises(ValueError, match=r"BLADECASE_FACTOR = 'pardisoo' is not a factorisation backend: valid "
                                         r"values are 'cholmod', 'superlu'"):
        factor_backend()


def test_the_preferred_backend_is_the_first_available(monkeypatch):
    monkeypatch.delenv(BACKEND_ENV, raising=False)
    expected = "cholmod" if linalg._missing("cholmod") is None else "superlu"
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


def test_cholmod_leaves_indefinite_factorisations_to_superlu(cholmod):
    A = laplacian(6) - 1.5 * sp.eye_array(36)  # indefinite, non-singular
    with pytest.raises(ValueError, match="not positive definite"):
        spd_factor(A, "A")
    f = symmetric_factor(A, "A")
    assert f.backend == "superlu"
    b = np.linspace(-1, 1, 36)
    np.testing.assert_allclose(A @ f.solve(b), b, rtol=0, atol=1e-12)


def test_cholmod_factor_gives_the_modes_with_either_eigen_solver(cholmod):
    K = laplacian(20)
    M = sp.eye_array(400, format="csr")
    f = spd_factor(K, "K")
    k = np.arange(1, 4)
    exact = np.sort((4 * np.sin(k[:, None] * np.pi / 42) ** 2 + 4 * np.sin(k[None, :] * np.pi / 42) ** 2).ravel())
    for method in ("arpack", "block"):
        lam, phi = lowest_modes(K, M, 5, factor=f, method=method)
        np.testing.assert_allclose(lam, exact[:5], rtol=1e-10, atol=0)
        np.testing.assert_allclose(phi.T @ phi, np.eye(5), atol=1e-10)
