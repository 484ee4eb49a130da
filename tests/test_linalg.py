"""Shared linear algebra (``bladecase.linalg``) and argument validators (``bladecase.checks``).

References: dense ``numpy``/``scipy.linalg`` solutions and eigen-solutions of
the same small matrices; the FE plate ``meshes/plate.msh`` (P1, 1084 free dofs)
for the no-dense-matrix check.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import bladecase as bc
from bladecase import checks
from bladecase.linalg import (
    BLOCK_MIN_DOFS,
    DENSE_LIMIT,
    Factor,
    SPDFactor,
    _eigen_method,
    check_factor,
    diagonal,
    factor_backend,
    lowest_modes,
    sign_convention,
    spd_factor,
    symmetric_factor,
)
from bladecase.linalg_block import block_lanczos

MESHES = Path(__file__).resolve().parent.parent / "meshes"


def chain_matrices(n: int, seed: int = 0) -> tuple[sp.csr_array, sp.csr_array]:
    """A grounded spring chain ``K`` (tridiagonal, SPD) and a consistent-like tridiagonal SPD ``M``."""
    rng = np.random.default_rng(seed)
    k = 1.0 + rng.random(n + 1)
    K = sp.diags_array([-k[1:-1], k[:-1] + k[1:], -k[1:-1]], offsets=[-1, 0, 1], format="csr")
    m = 1.0 + rng.random(n)
    M = sp.diags_array([m[:-1] / 6, 2 * m / 3, m[:-1] / 6], offsets=[-1, 0, 1], format="csr")
    return K, M


# --------------------------------------------------------------------------- spd_factor


def test_sparse_factor_solves_vectors_and_blocks_and_reproduces_ldlt():
    K, _ = chain_matrices(40)
    f = spd_factor(K, "K")
    assert isinstance(f, SPDFactor) and f.n == 40 and f.kind == "sparse" and f.backend == factor_backend()
    b = np.arange(40.0)
    np.testing.assert_allclose(K @ f.solve(b), b, rtol=0, atol=1e-12 * np.abs(b).max())
    B = np.random.default_rng(1).standard_normal((40, 3))
    np.testing.assert_allclose(K @ f.solve(B), B, rtol=0, atol=1e-12)
    np.testing.assert_allclose(f.solve(sp.csr_array(B)), f.solve(B), rtol=0, atol=0)  # sparse right-hand side
    np.testing.assert_allclose(f.operator() @ b, f.solve(b), rtol=0, atol=0)
    L, d, perm = f.ldlt()
    assert np.all(d > 0) and np.allclose(L.diagonal(), 1.0)
    P = sp.csr_array((np.ones(40), (np.arange(40), perm)), shape=(40, 40))  # (Pᵀx)[perm] = x
    np.testing.assert_allclose((P.T @ K @ P).toarray(), (L @ sp.diags_array(d) @ L.T).toarray(), atol=1e-13)
    with pytest.raises(ValueError, match="dense factor"):
        _ = f.lower
    with pytest.raises(ValueError, match=r"right-hand side has 3 rows, expected 40 \(the size of K\)"):
        f.solve(np.ones(3))


def test_dense_factor_is_cholesky():
    K, _ = chain_matrices(6)
    A = K.toarray()
    f = spd_factor(A, "A")
    assert f.kind == "dense" and f.backend == "cholesky"
    np.testing.assert_allclose(f.lower @ f.lower.T, A, atol=1e-14)
    np.testing.assert_allclose(f.solve(np.eye(6)), np.linalg.inv(A), atol=1e-12)
    with pytest.raises(ValueError, match="sparse factor"):
        f.ldlt()


@pytest.mark.parametrize("matrix, pattern", [
    (sp.csr_array(np.diag([1.0, -1.0])), r"Kx is not positive definite: diagonal entry Kx\[1,1\] = -1 <= 0"),
    (sp.csr_array(np.array([[1.0, 2.0], [2.0, 1.0]])), r"Kx is not positive definite: its LDLᵀ .* pivot -3 <= 0"),
    (sp.csr_array(np.array([[1.0, 1.0], [1.0, 1.0]])), r"Kx is singular, hence not positive definite"),
    (np.array([[1.0, 2.0], [2.0, 1.0]]), r"Kx is not positive definite: smallest eigenvalue -1"),
    (sp.csr_array(np.ones((2, 3))), r"Kx must be a square matrix, got shape \(2, 3\)"),
])
def test_spd_factor_names_the_matrix_when_it_is_not_positive_definite(matrix, pattern):
    with pytest.raises(ValueError, match=pattern):
        spd_factor(matrix, "Kx")


def test_the_hint_is_appended_to_the_message():
    with pytest.raises(ValueError, match=r"K is not positive definite: .*<= 0: is the model clamped\?$"):
        spd_factor(sp.csr_array(np.diag([1.0, 0.0])), "K", hint="is the model clamped?")


def test_a_factor_knows_its_matrix():
    K, M = chain_matrices(10)
    f = spd_factor(K, "K")
    assert f.is_of(K) and not f.is_of(M) and not f.is_of(K.copy())
    assert check_factor(None, K) is None and check_factor(f, K) is f
    with pytest.raises(ValueError, match=r"factor must be None or the factorisation of M \(spd_factor\(A\)\)"):
        check_factor(f, M, "M")


def test_symmetric_factor_solves_indefinite_shifted_matrices():
    K, M = chain_matrices(30)
    lam = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    sigma = 0.5 * (lam[3] + lam[4])  # between two eigenvalues: K - σM indefinite
    A = sp.csr_array(K - sigma * M)
    with pytest.raises(ValueError, match="not positive definite"):
        spd_factor(A, "K - σM")
    b = np.linspace(-1, 1, 30)
    for a in (A, A.toarray()):
        f = symmetric_factor(a, "K - σM")
        np.testing.assert_allclose(a @ f.solve(b), b, rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match=r"^S is singular: sigma\?$"):
        symmetric_factor(np.ones((2, 2)), "S", hint="sigma?")


def test_diagonal_and_sign_convention():
    assert diagonal(sp.diags_array([1.0, 2.0], format="csr")).tolist() == [1.0, 2.0]
    assert diagonal(chain_matrices(3)[1]) is None
    phi = sign_convention(np.array([[1.0, -3.0], [-2.0, 1.0]]))
    assert phi.tolist() == [[-1.0, 3.0], [2.0, -1.0]]


# --------------------------------------------------------------------------- lowest_modes


def test_lowest_modes_sparse_matches_dense_and_reuses_a_factor():
    K, M = chain_matrices(200)
    ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)[:6]
    lam, phi = lowest_modes(K, M, 6)
    np.testing.assert_allclose(lam, ref, rtol=1e-11)
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(6), atol=1e-12)
    np.testing.assert_allclose(K @ phi, (M @ phi) * lam, atol=1e-10 * lam.max())
    assert np.all(phi[np.argmax(np.abs(phi), axis=0), np.arange(6)] > 0)
    f = spd_factor(K, "K")
    lam2, phi2 = lowest_modes(K, M, 6, factor=f)
    np.testing.assert_allclose(lam2, lam, rtol=1e-12)
    np.testing.assert_allclose(phi2, phi, atol=1e-8)
    lam_d, phi_d = lowest_modes(K, M, 6, dense=True)
    np.testing.assert_allclose(lam_d, ref, rtol=1e-10)
    np.testing.assert_allclose(phi_d, phi, atol=1e-8)  # same sign convention


def test_lowest_modes_goes_dense_for_many_modes_of_small_matrices():
    K, M = chain_matrices(20)
    lam, phi = lowest_modes(K, M, 20)  # all of them: ARPACK cannot
    np.testing.assert_allclose(lam, sla.eigh(K.toarray(), M.toarray(), eigvals_only=True), rtol=1e-12)
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(20), atol=1e-12)


def test_lowest_modes_errors():
    K, M = chain_matrices(20)
    for count in (0, 21, 2.5, True):
        with pytest.raises(ValueError, match=r"count must be an integer with 1 <= count <= 20 \(the size of K\)"):
            lowest_modes(K, M, count)
    with pytest.raises(ValueError, match="the sparse eigen-solver gives at most 19"):
        lowest_modes(K, M, 20, dense=False)
    with pytest.raises(ValueError, match="factor must be a factorisation of K"):
        lowest_modes(K, M, 2, factor=spd_factor(M[:10, :10], "M"))
    big = sp.eye_array(DENSE_LIMIT + 1, format="csr")
    with pytest.raises(ValueError, match=f"limited to DENSE_LIMIT = {DENSE_LIMIT}"):
        lowest_modes(big, big, 3, dense=True)
    with pytest.raises(ValueError, match=r"K is not positive definite: eigenvalue -1 \(a mechanism"):
        lowest_modes(np.diag([-1.0, 1.0]), np.eye(2), 1)


def grid_matrices(k: int) -> tuple[sp.csr_array, sp.csr_array]:
    """Stiffness and consistent mass of a k × k grid (Kronecker products of 1-D P1 chains, clamped ends):
    double eigenvalues (modes (i, j) and (j, i)), eigenvalues ``λ_ij = (a_i + a_j) / (b_i b_j)``-like."""
    h = 1.0 / (k + 1)
    k1 = sp.diags_array([[-1.0] * (k - 1), [2.0] * k, [-1.0] * (k - 1)], offsets=[-1, 0, 1]) / h
    m1 = sp.diags_array([[1.0] * (k - 1), [4.0] * k, [1.0] * (k - 1)], offsets=[-1, 0, 1]) * (h / 6)
    return sp.csr_array(sp.kron(k1, m1) + sp.kron(m1, k1)), sp.csr_array(sp.kron(m1, m1))


@pytest.mark.parametrize("count", [1, 8, 20])
def test_block_lanczos_matches_the_dense_eigen_solution_with_double_eigenvalues(count):
    K, M = grid_matrices(30)  # 900 dofs
    ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True, subset_by_index=[0, count - 1])
    assert count < 8 or np.isclose(ref[1], ref[2], rtol=1e-12)  # a double eigenvalue among the wanted ones
    f = spd_factor(K, "K")
    assert block_lanczos(K, M, f.solve, count) is not None  # converged: no fall-back to ARPACK below
    lam, phi = lowest_modes(K, M, count, factor=f, method="block")
    np.testing.assert_allclose(lam, ref, rtol=1e-10, atol=0)
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(count), atol=1e-10)
    residual = np.linalg.norm(K @ phi - (M @ phi) * lam, axis=0) / np.linalg.norm(K @ phi, axis=0)
    assert residual.max() < 1e-7
    lam_a, _ = lowest_modes(K, M, count, factor=f, method="arpack")
    np.testing.assert_allclose(lam, lam_a, rtol=1e-10, atol=0)


def test_block_lanczos_converges_reproducibly_or_says_it_did_not():
    K, M = grid_matrices(20)
    solve = spd_factor(K, "K").solve
    lam, phi = block_lanczos(K, M, solve, 6, block=4)
    lam2, phi2 = block_lanczos(K, M, solve, 6, block=4)
    np.testing.assert_array_equal(lam, lam2)  # a seeded start block
    np.testing.assert_array_equal(phi, phi2)
    ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True, subset_by_index=[0, 5])
    np.testing.assert_allclose(lam, ref, rtol=1e-10, atol=0)
    assert block_lanczos(K, M, solve, 6, block=2, max_dim=8) is None  # 8 vectors cannot give 6 pairs to 1e-10
    with pytest.raises(ValueError, match="block must be an integer >= 1, got 0"):
        block_lanczos(K, M, solve, 6, block=0)
    with pytest.raises(ValueError, match=r"max_dim = 8 is too small for count = 6 and block = 4"):
        block_lanczos(K, M, solve, 6, block=4, max_dim=8)


def test_lowest_modes_method():
    K, M = chain_matrices(30)
    with pytest.raises(ValueError, match=r"method must be one of 'auto', 'arpack', 'block', got 'lobpcg'"):
        lowest_modes(K, M, 2, method="lobpcg")
    n, solve = BLOCK_MIN_DOFS, (lambda b: b)
    assert _eigen_method("auto", Factor("K", n, "sparse", "cholmod", solve), n) == "block"
    assert _eigen_method("auto", Factor("K", n - 1, "sparse", "cholmod", solve), n - 1) == "arpack"
    assert _eigen_method("auto", Factor("K", n, "sparse", "superlu", solve), n) == "arpack"
    assert _eigen_method("block", Factor("K", 10, "sparse", "superlu", solve), 10) == "block"


def test_natural_frequencies_block_and_arpack_agree_on_the_plate():
    model = bc.assemble(bc.load_mesh(MESHES / "plate.msh"), "Ti-6Al-4V", order=1, thickness=0.002)
    factor = bc.stiffness_factor(model)
    f_block = bc.natural_frequencies(model, 12, factor=factor, method="block")
    f_arpack = bc.natural_frequencies(model, 12, factor=factor, method="arpack")
    np.testing.assert_allclose(f_block, f_arpack, rtol=1e-9, atol=0)
    with pytest.raises(ValueError, match="method must be one of"):
        bc.natural_frequencies(model, 3, method="dense")


def test_fe_eigen_solutions_never_form_a_dense_model_matrix(monkeypatch):
    """natural_frequencies and the sparse reductions of a 1084-dof plate densify no n × n matrix."""
    model = bc.assemble(bc.load_mesh(MESHES / "plate.msh"), "Ti-6Al-4V", order=1, thickness=0.002)
    contact = bc.Contact(int(model.mesh.group("contact")[0]), [0.0, 1.0], 1e-4)
    n = model.n_dofs
    real = {cls: cls.toarray for cls in (sp.csr_array, sp.csc_array, sp.coo_array)}

    def guarded(cls):
        def toarray(self, *args, **kwargs):
            assert min(self.shape) < n // 2, f"a dense {self.shape} matrix was formed"
            return real[cls](self, *args, **kwargs)
        return toarray

    for cls in real:
        monkeypatch.setattr(cls, "toarray", guarded(cls))
    bc.natural_frequencies(model, 5)
    for method in ("modal", "lanczos", "lanczos-si", "craig-bampton"):
        bc.reduce(model, contact, method, 8)
    lumped = bc.assemble(model.mesh, "Ti-6Al-4V", order=1, thickness=0.002, mass="lumped")
    bc.reduce(lumped, contact, "massless", 8)
    with pytest.raises(AssertionError, match="dense"):  # the guard works
        bc.reduce(model, contact, "full")


# --------------------------------------------------------------------------- checks


def test_positive():
    assert checks.positive("gap", "1e-4") == 1e-4
    assert checks.positive("size", None, allow_none=True) is None
    for bad, message in [(0, "gap must be a finite clearance > 0, got 0"), (-1.0, "got -1.0"),
                         (float("nan"), "got nan"), (True, "got True"), ("wide", "gap must be a number > 0")]:
        with pytest.raises(ValueError, match=message):
            checks.positive("gap", bad, noun="clearance")


def test_integer_finite_one_of_point():
    assert checks.integer("steps", np.int64(3), 1, 5) == 3
    with pytest.raises(ValueError, match=r"^n_sections must be an integer >= 2, got 1$"):
        checks.integer("n_sections", 1, 2)
    with pytest.raises(ValueError, match=r"^steps must be an integer with 1 <= steps <= 5 \(dofs\), got 6$"):
        checks.integer("steps", 6, 1, 5, note=" (dofs)")
    for bad in (True, 2.0, "2"):
        with pytest.raises(ValueError, match="must be an integer"):
            checks.integer("k", bad, 1)
    assert checks.finite("sweep", -2) == -2.0
    with pytest.raises(ValueError, match="sweep must be a finite number, got inf"):
        checks.finite("sweep", float("inf"))
    assert checks.one_of("mass", "lumped", ("consistent", "lumped")) == "lumped"
    with pytest.raises(ValueError, match=r"mass must be one of \('consistent', 'lumped'\), got 'diagonal'"):
        checks.one_of("mass", "diagonal", ("consistent", "lumped"))
    assert checks.point("p", [1, 2], (2, 3)) == (1.0, 2.0)
    with pytest.raises(ValueError, match=r"p must be 2 or 3 finite coordinates, got \[1\]"):
        checks.point("p", [1], (2, 3))
