"""LinearSystem / chain construction, validation errors, and the cached spectrum (theory §1)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
from _util import dense, random_spd_system, two_dof_exact

import bladecase as bc

# ---------------------------------------------------------------------------
# chain(): the paper's Fig. 1 spring–mass chain, theory §1
# ---------------------------------------------------------------------------


def test_chain_matrices_match_theory_formula_exactly():
    s = bc.chain(3, k=[1, 2, 3], m=[4, 5, 6], gap=1)
    # M = diag(m); K_ii = k_i + k_{i+1} (k_4 = 0); K_{i,i+1} = -k_{i+1}
    K_ref = np.array([[1 + 2, -2, 0], [-2, 2 + 3, -3], [0, -3, 3]], dtype=float)
    M_ref = np.diag([4.0, 5.0, 6.0])
    assert sp.issparse(s.M) and sp.issparse(s.K)
    assert s.M.format == "csr" and s.K.format == "csr"
    np.testing.assert_array_equal(s.K.toarray(), K_ref)  # exact
    np.testing.assert_array_equal(s.M.toarray(), M_ref)  # exact
    np.testing.assert_array_equal(s.w, [0.0, 0.0, 1.0])  # contact on the last mass
    assert s.gap == 1.0
    assert s.n == 3


def test_chain_scalar_parameters_broadcast():
    s = bc.chain(4, k=2.0, m=0.25, gap=0.5)
    K_ref = 2.0 * (2 * np.eye(4) - np.eye(4, k=1) - np.eye(4, k=-1))
    K_ref[3, 3] = 2.0
    np.testing.assert_array_equal(s.K.toarray(), K_ref)
    np.testing.assert_array_equal(s.M.toarray(), 0.25 * np.eye(4))
    assert s.gap == 0.5


def test_one_dof_chain():
    s = bc.chain(1, k=8.0, m=2.0, gap=0.5)
    np.testing.assert_array_equal(s.K.toarray(), [[8.0]])
    np.testing.assert_array_equal(s.M.toarray(), [[2.0]])
    assert s.spectrum.omega[0] == pytest.approx(2.0, rel=1e-15)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(n=0), "integer >= 1"),
        (dict(n=2.5), "integer >= 1"),
        (dict(n=3, k=[1, 2]), "k must be a scalar or have 3 entries"),
        (dict(n=3, m=[1, -2, 1]), "every m must be finite and > 0"),
        (dict(n=3, k=[1, np.nan, 1]), "every k must be finite and > 0"),
        (dict(n=2, gap=0.0), "gap"),
        (dict(n=2, gap=-1.0), "gap"),
    ],
)
def test_chain_rejects_bad_parameters(kwargs, match):
    with pytest.raises(ValueError, match=match):
        bc.chain(**kwargs)


# ---------------------------------------------------------------------------
# LinearSystem validation: every error is a ValueError naming the problem
# ---------------------------------------------------------------------------

M2 = np.eye(2)
K2 = np.array([[2.0, -1.0], [-1.0, 1.0]])
INDEF = np.array([[1.0, 2.0], [2.0, 1.0]])  # eigenvalues 3, -1; positive diagonal
SINGULAR = np.array([[1.0, 1.0], [1.0, 1.0]])
NONSYM = np.array([[2.0, -1.0], [-1.1, 1.0]])


def _nan_at_00(a):
    a = np.array(a, dtype=float)
    a[0, 0] = np.nan
    return a


@pytest.mark.parametrize(
    "M, K, w, gap, match",
    [
        # not positive definite, dense
        (np.diag([1.0, -1.0]), K2, 1, 1.0, r"M is not positive definite"),
        (M2, INDEF, 1, 1.0, r"K is not positive definite"),
        (M2, SINGULAR, 1, 1.0, r"K is not positive definite"),
        # not positive definite, sparse (negative diagonal, then positive diagonal but indefinite)
        (sp.csr_array(np.diag([1.0, -1.0])), K2, 1, 1.0, r"M is not positive definite"),
        (M2, sp.csr_array(INDEF), 1, 1.0, r"K is not positive definite"),
        (sp.csr_matrix(INDEF), M2, 1, 1.0, r"M is not positive definite"),
        (M2, sp.csr_array(SINGULAR), 1, 1.0, r"K is (singular|not positive definite)"),
        # not symmetric, dense and sparse
        (M2, NONSYM, 1, 1.0, r"K is not symmetric"),
        (NONSYM + np.eye(2), K2, 1, 1.0, r"M is not symmetric"),
        (M2, sp.csr_array(NONSYM), 1, 1.0, r"K is not symmetric"),
        # gap
        (M2, K2, 1, 0.0, r"gap must be a finite clearance > 0"),
        (M2, K2, 1, -1.0, r"gap must be a finite clearance > 0"),
        (M2, K2, 1, np.nan, r"gap must be a finite clearance > 0"),
        (M2, K2, 1, "wide", r"gap must be a positive number"),
        # non-finite values
        (_nan_at_00(M2), K2, 1, 1.0, r"M contains 1 non-finite value"),
        (M2, _nan_at_00(K2), 1, 1.0, r"K contains 1 non-finite value"),
        (sp.csr_array(_nan_at_00(M2)), K2, 1, 1.0, r"M contains 1 non-finite value"),
        (M2, K2, [np.nan, 1.0], 1.0, r"w contains non-finite values"),
        (M2, K2, [np.inf, 1.0], 1.0, r"w contains non-finite values"),
        # shapes
        (np.ones((2, 3)), K2, 1, 1.0, r"M must be a square matrix"),
        (M2, np.eye(3), 1, 1.0, r"K has shape \(3, 3\), expected \(2, 2\)"),
        (np.zeros((0, 0)), np.zeros((0, 0)), 0, 1.0, r"M is empty"),
        (M2, K2, [0.0, 0.0, 1.0], 1.0, r"w has 3 entries, expected 2"),
        # w == 0
        (M2, K2, [0.0, 0.0], 1.0, r"w is the zero vector"),
        # contact dof out of range
        (M2, K2, 2, 1.0, r"contact dof w = 2 is out of range"),
        (M2, K2, -3, 1.0, r"contact dof w = -3 is out of range"),
        (M2, K2, -1, 1.0, r"contact dof w = -1 is out of range .*valid: 0\.\.1\)"),
    ],
)
def test_linear_system_validation_errors(M, K, w, gap, match):
    with pytest.raises(ValueError, match=match):
        bc.LinearSystem(M, K, w, gap)


def test_linear_system_accepts_valid_inputs():
    s = bc.LinearSystem(M2, K2, 1, 2.0)
    np.testing.assert_array_equal(s.w, [0.0, 1.0])
    s = bc.LinearSystem(sp.csr_array(M2), sp.csc_array(K2), np.int64(0), 2)
    np.testing.assert_array_equal(s.w, [1.0, 0.0])
    assert s.gap == 2.0
    s = bc.LinearSystem(M2.tolist(), K2.tolist(), [0.3, -2.0], 1.0)
    np.testing.assert_array_equal(s.w, [0.3, -2.0])
    with pytest.raises(ValueError):  # w is read-only
        s.w[0] = 1.0


def test_sparse_spd_check_agrees_with_eigenvalues():
    """Sparse LDLᵀ positive-definiteness test vs dense eigenvalues on random sparse matrices."""
    rng = np.random.default_rng(0)
    for _ in range(40):
        n = int(rng.integers(2, 25))
        A = sp.random(n, n, density=0.2, random_state=rng).toarray()
        S = A @ A.T
        lam0 = np.linalg.eigvalsh(S)[0]
        shift = -lam0 + (0.05 if rng.random() < 0.5 else -0.05) * max(1.0, np.abs(S).max())
        S = S + shift * np.eye(n)
        S = 0.5 * (S + S.T)
        pd = np.linalg.eigvalsh(S)[0] > 0
        if pd:
            bc.LinearSystem(sp.eye(n, format="csr"), sp.csr_array(S), 0, 1.0)
        else:
            with pytest.raises(ValueError, match="K is (not positive definite|singular)"):
                bc.LinearSystem(sp.eye(n, format="csr"), sp.csr_array(S), 0, 1.0)


# ---------------------------------------------------------------------------
# Spectrum: M-orthonormal modes, φᵀKφ = diag(ω²), b = wᵀφ, cached
# ---------------------------------------------------------------------------


def _check_spectrum(s: bc.LinearSystem, tol=1e-12):
    spc = s.spectrum
    M, K = dense(s.M), dense(s.K)
    n = s.n
    assert spc.phi.shape == (n, n) and spc.omega.shape == (n,)
    assert np.all(np.diff(spc.omega) > 0)  # ascending
    # φᵀMφ = I to 1e-12
    np.testing.assert_allclose(spc.phi.T @ M @ spc.phi, np.eye(n), rtol=0, atol=tol)
    # φᵀKφ = diag(ω²) to 1e-12 relative to ω_max²
    np.testing.assert_allclose(
        spc.phi.T @ K @ spc.phi, np.diag(spc.omega**2), rtol=0, atol=tol * spc.omega.max() ** 2
    )
    # frequencies against scipy's generalised eigensolver (rel 1e-12)
    lam = sla.eigh(K, M, eigvals_only=True)
    np.testing.assert_allclose(spc.omega, np.sqrt(lam), rtol=1e-12)
    # contact participations
    np.testing.assert_allclose(spc.b, s.w @ spc.phi, rtol=0, atol=1e-15 * np.abs(spc.b).max())
    assert s.spectrum is spc  # cached


def test_spectrum_chain3():
    _check_spectrum(bc.chain(3, k=[1, 2, 3], m=[4, 5, 6], gap=1))


def test_spectrum_two_dof_closed_form(two_dof):
    _check_spectrum(two_dof)
    omega, b2 = two_dof_exact()
    np.testing.assert_allclose(two_dof.spectrum.omega, omega, rtol=1e-14)
    np.testing.assert_allclose(two_dof.spectrum.omega**2, [3 - np.sqrt(5), 3 + np.sqrt(5)], rtol=1e-14)
    np.testing.assert_allclose(two_dof.spectrum.b**2, b2, rtol=1e-13)
    np.testing.assert_allclose(two_dof.spectrum.periods, 2 * np.pi / omega, rtol=1e-14)
    np.testing.assert_allclose(two_dof.spectrum.frequencies, omega / (2 * np.pi), rtol=1e-14)


def test_spectrum_random_nondiagonal_mass(random_sys):
    _check_spectrum(random_sys)
    assert random_sys.spectrum.active.all()


def test_spectrum_long_chain_tridiagonal_path():
    rng = np.random.default_rng(5)
    n = 200
    s = bc.chain(n, k=rng.uniform(0.5, 2, n), m=rng.uniform(0.5, 2, n), gap=1.0)
    _check_spectrum(s, tol=1e-12)


def test_spectrum_sparse_nondiagonal_mass():
    """Consistent (tridiagonal, non-diagonal) sparse mass of a 1-D bar."""
    n = 8
    h = 1.0 / n
    Me = h / 6 * np.array([[2, 1], [1, 2]])
    Ke = 1 / h * np.array([[1, -1], [-1, 1]])
    M = np.zeros((n + 1, n + 1))
    K = np.zeros((n + 1, n + 1))
    for e in range(n):
        M[e : e + 2, e : e + 2] += Me
        K[e : e + 2, e : e + 2] += Ke
    M, K = M[1:, 1:], K[1:, 1:]  # clamp the left end
    s = bc.LinearSystem(sp.csr_array(M), sp.csr_array(K), n - 1, 0.1)
    _check_spectrum(s)


def test_inactive_mode_is_flagged():
    """Contact at the middle of a symmetric 3-mass chain: the antisymmetric mode has b = 0."""
    K = np.array([[2.0, -1, 0], [-1, 2, -1], [0, -1, 2]])
    s = bc.LinearSystem(np.eye(3), K, 1, 1.0)
    spc = s.spectrum
    # modes of [[2,-1,0],[-1,2,-1],[0,-1,2]]: ω² = 2 - √2, 2, 2 + √2; the middle one is (1, 0, -1)/√2
    np.testing.assert_allclose(spc.omega**2, [2 - np.sqrt(2), 2, 2 + np.sqrt(2)], rtol=1e-14)
    np.testing.assert_array_equal(spc.active, [True, False, True])
    # the inactive mode does not make its period resonant
    o = bc.orbit_1ipp(s, 2 * np.pi / spc.omega[1])
    assert np.isfinite(o.impulses[0])


def test_energy_of_states(random_sys):
    rng = np.random.default_rng(1)
    X = rng.standard_normal((6, 4))
    V = rng.standard_normal((6, 4))
    M, K = dense(random_sys.M), dense(random_sys.K)
    ref = 0.5 * np.einsum("ik,ij,jk->k", V, M, V) + 0.5 * np.einsum("ik,ij,jk->k", X, K, X)
    np.testing.assert_allclose(random_sys.energy(X, V), ref, rtol=1e-14)


def test_repr_and_public_api():
    s = random_spd_system()
    assert "n=6" in repr(s)
    for name in ("LinearSystem", "chain", "orbit_1ipp", "PeriodicOrbit", "backbone", "Backbone",
                 "Interval", "simulate", "Trajectory", "Spectrum"):
        assert hasattr(bc, name)
