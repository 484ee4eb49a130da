"""Contact, orthogonal-symmetry basis and Lanczos chain (theory §1–2).

References (independent of ``bladecase.lanczos``):

* the dense generalised eigen-solution ``scipy.linalg.eigh(K, M)`` of small FE
  models: frequencies ``ω_j`` and contact participations ``b_j = wᵀφ_j``
  (M-normalised ``φ``), hence the contact spectral measure and its moments
  ``μ_p = Σ_j b_j² ω_j^{2p}``;
* the theory's formula of the Moreau map ``R = I - 2 M⁻¹w wᵀ/(wᵀM⁻¹w)``
  (dense ``numpy.linalg.solve``);
* the 1-ipp orbit of the FULL model (``bladecase.orbit_1ipp`` on
  ``Contact.system``: dense modal data of all ``n`` dofs).

The small FE "blades" are built here from scikit-fem's structured generators:
a swept, tapered plane-stress plate (radial along ``+y``, 360 dofs) and a
twisted 3-D bar of tetrahedra (radial along ``+z``, 540 dofs).  Both are
asymmetric, so a tip-corner contact sees every mode.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
from skfem import MeshTet, MeshTri

import bladecase as bc
from bladecase.fe import Mesh
from bladecase.reduction import chain_jacobi, per_dof_law

GAP = 1e-4  # 0.1 mm tip clearance


# --------------------------------------------------------------------------- small FE blades


def swept_plate(nx: int = 8, ny: int = 20, span: float = 0.1, chord: float = 0.03,
                taper: float = 0.7, sweep: float = 0.01) -> Mesh:
    """Tapered, swept plate in the xy-plane, root at ``y = 0``, tip at ``y = span``."""
    m = MeshTri.init_tensor(np.linspace(-0.5, 0.5, nx + 1), np.linspace(0.0, 1.0, ny + 1))
    s, e = m.p
    x = chord * s * (1 + (taper - 1) * e) + sweep * e
    p = np.c_[x, span * e, np.zeros_like(x)]
    groups = {"root": np.flatnonzero(e < 1e-12), "tip": np.flatnonzero(e > 1 - 1e-12)}
    return Mesh(points=p, cells={"triangle": m.t.T.copy()}, dim=2, groups=groups, source="swept_plate")


def twisted_bar(nx: int = 5, ny: int = 2, nz: int = 10, span: float = 0.1, chord: float = 0.02,
                thick: float = 0.004, twist: float = 0.6) -> Mesh:
    """Tetrahedral bar radial along ``+z``, its section twisted by ``twist`` rad from root to tip."""
    m = MeshTet.init_tensor(np.linspace(-0.5, 0.5, nx + 1), np.linspace(-0.5, 0.5, ny + 1), np.linspace(0, 1, nz + 1))
    s, t, e = m.p
    a = twist * e
    x0, y0 = chord * s, thick * t
    p = np.c_[x0 * np.cos(a) - y0 * np.sin(a), x0 * np.sin(a) + y0 * np.cos(a), span * e]
    groups = {"root": np.flatnonzero(e < 1e-12), "tip": np.flatnonzero(e > 1 - 1e-12)}
    return Mesh(points=p, cells={"tetra": m.t.T.copy()}, dim=3, groups=groups, source="twisted_bar")


@pytest.fixture(scope="module")
def plate_model() -> bc.FEModel:
    return bc.assemble(swept_plate(), "Ti-6Al-4V", order=1, thickness=0.002)


@pytest.fixture(scope="module")
def plate_lumped() -> bc.FEModel:
    return bc.assemble(swept_plate(), "Ti-6Al-4V", order=1, thickness=0.002, mass="lumped")


@pytest.fixture(scope="module")
def bar_model() -> bc.FEModel:
    return bc.assemble(twisted_bar(), "Inconel 718", order=1)


@pytest.fixture(scope="module")
def modes(plate_model, plate_lumped, bar_model):
    """Dense ``(λ, b)`` of the three models with their leading-edge contact (computed once)."""
    out = {}
    for name, model in (("plate", plate_model), ("plate_lumped", plate_lumped), ("bar", bar_model)):
        lam, b, _ = dense_modes(model, le_contact(model).w(model))
        out[name] = lam, b
    return out


def le_contact(model: bc.FEModel) -> bc.Contact:
    """The leading-edge tip corner (smallest x on the tip), radial normal."""
    return bc.Contact.farthest(model, (-1.0, 0.0, 0.0)[: model.dim], gap=GAP)


def dense_modes(model: bc.FEModel, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(λ = ω², b, φ)`` from the dense generalised eigen-solution."""
    lam, phi = sla.eigh(model.K.toarray(), model.M.toarray())
    return lam, w @ phi, phi


def chain_spectrum(ch: bc.LanczosChain) -> tuple[np.ndarray, np.ndarray]:
    """``(λ, b²)`` of a chain: eigenvalues of ``J`` and ``|ŵ|²`` × squared first eigenvector components."""
    mu, psi = sla.eigh_tridiagonal(ch.alpha, ch.beta)
    return mu, ch.w_hat_norm**2 * psi[0] ** 2


# --------------------------------------------------------------------------- Contact


def test_contact_w_carries_the_normal_on_the_node_dofs(bar_model):
    c = bc.Contact.at(bar_model, int(bar_model.mesh.group("tip")[3]), normal=(1.0, 2.0, 2.0), gap=GAP)
    assert c.normal == pytest.approx((1 / 3, 2 / 3, 2 / 3), rel=1e-15)  # normalised
    w = c.w(bar_model)
    idx = [bar_model.dof_of(c.node, d) for d in range(3)]
    np.testing.assert_allclose(w[idx], [1 / 3, 2 / 3, 2 / 3], rtol=1e-15)
    assert np.count_nonzero(w) == 3
    # wᵀx = ν·u_node for a displacement field
    x = np.random.default_rng(0).standard_normal(bar_model.n_dofs)
    assert w @ x == pytest.approx(np.dot(c.normal, x[idx]), rel=1e-14)


def test_default_normal_is_the_last_axis():
    np.testing.assert_array_equal(bc.radial_normal(3), [0, 0, 1])
    np.testing.assert_array_equal(bc.radial_normal(2), [0, 1])


def test_contact_defaults_to_radial_normal(plate_model, bar_model):
    cp = le_contact(plate_model)
    assert cp.normal == (0.0, 1.0)
    assert np.flatnonzero(cp.w(plate_model)).tolist() == [plate_model.dof_of(cp.node, "y")]
    cb = le_contact(bar_model)
    assert cb.normal == (0.0, 0.0, 1.0)
    # Contact(node, None, gap) resolves the default per model
    c = bc.Contact(cb.node, None, GAP)
    np.testing.assert_array_equal(c.w(bar_model), cb.w(bar_model))


def test_farthest_picks_the_leading_edge_tip_corner(plate_model, bar_model):
    for model in (plate_model, bar_model):
        c = le_contact(model)
        pts = model.mesh.points
        tip = model.mesh.group("tip")
        assert c.node in tip
        assert pts[c.node, 0] == pts[tip, 0].min()
    # group=None searches every free node: still the tip corner of the swept plate (x grows with y)
    c = bc.Contact.farthest(plate_model, (0.0, 1.0), gap=GAP, group=None)
    assert plate_model.mesh.points[c.node, 1] == pytest.approx(0.1)


def test_nearest_free_node(plate_model):
    pts = plate_model.mesh.points
    target = pts[57, :2] + [1e-5, -2e-5]
    c = bc.Contact.nearest(plate_model, target, gap=GAP)
    assert c.node == 57
    c3 = bc.Contact.nearest(plate_model, (*target, 0.0), (0.0, -1.0), GAP)  # (x, y, 0) accepted in 2-D
    assert c3.node == 57 and c3.normal == (0.0, -1.0)
    # a point at the root: the nearest FREE node, never a clamped one
    c_root = bc.Contact.nearest(plate_model, pts[plate_model.clamped[0], :2], gap=GAP)
    assert c_root.node not in plate_model.clamped


def test_contact_system_is_the_full_model(plate_model):
    c = le_contact(plate_model)
    s = c.system(plate_model)
    assert s.n == plate_model.n_dofs and s.gap == GAP
    assert sp.issparse(s.M) and sp.issparse(s.K)
    np.testing.assert_array_equal(s.w, c.w(plate_model))


def test_contact_errors(plate_model, bar_model):
    clamped = int(plate_model.clamped[0])
    n_nodes = plate_model.mesh.points.shape[0]
    with pytest.raises(ValueError, match=f"contact node {clamped} is clamped"):
        bc.Contact.at(plate_model, clamped, gap=GAP)
    with pytest.raises(ValueError, match=f"contact node {clamped} is clamped"):
        bc.Contact(clamped, None, GAP).w(plate_model)
    with pytest.raises(ValueError, match=rf"not a mesh node \(mesh nodes 0..{n_nodes - 1}\)"):
        bc.Contact(n_nodes, (0, 1), GAP).w(plate_model)
    with pytest.raises(ValueError, match="normal must be a non-zero vector"):
        bc.Contact(5, (0.0, 0.0), GAP)
    with pytest.raises(ValueError, match="normal must have 2 or 3 components"):
        bc.Contact(5, (1.0,), GAP)
    for gap in (0.0, -1e-4, float("nan")):
        with pytest.raises(ValueError, match="gap must be a finite clearance > 0"):
            bc.Contact(5, (0, 1), gap)
    with pytest.raises(ValueError, match="gap is required"):
        bc.Contact.farthest(plate_model, (-1, 0))
    with pytest.raises(ValueError, match="node must be a mesh node index"):
        bc.Contact(-1, (0, 1), GAP)
    with pytest.raises(ValueError, match="does not fit a 3-D model"):
        bc.Contact(int(bar_model.mesh.group("tip")[0]), (0, 1), GAP).w(bar_model)
    with pytest.raises(ValueError, match="group 'root' has no free node"):
        bc.Contact.farthest(plate_model, (1, 0), gap=GAP, group="root")
    with pytest.raises(ValueError, match="has no group 'casing'"):
        bc.Contact.farthest(plate_model, (1, 0), gap=GAP, group="casing")


# --------------------------------------------------------------------------- symmetry basis


@pytest.mark.parametrize("kind", ["consistent", "lumped", "dense"])
def test_mass_factor_reproduces_M(kind, plate_model, plate_lumped, random_sys):
    M = {"consistent": plate_model.M, "lumped": plate_lumped.M, "dense": random_sys.M}[kind]
    F = bc.mass_factor(M)
    assert F.kind == {"consistent": "ldlt", "lumped": "diagonal", "dense": "cholesky"}[kind]
    Md = M.toarray() if sp.issparse(M) else M
    n = Md.shape[0]
    Fd = F.matvec(np.eye(n))
    np.testing.assert_allclose(Fd @ Fd.T, Md, rtol=0, atol=1e-14 * np.abs(Md).max())  # M = F Fᵀ
    np.testing.assert_allclose(F.rmatvec(np.eye(n)), Fd.T, rtol=0, atol=1e-15 * np.abs(Fd).max())
    x = np.random.default_rng(1).standard_normal(n)
    np.testing.assert_allclose(Fd @ F.solve(x), x, rtol=0, atol=1e-13)  # F⁻¹
    np.testing.assert_allclose(Fd.T @ F.solve_t(x), x, rtol=0, atol=1e-13)  # F⁻ᵀ


def test_mass_factor_rejects_indefinite():
    with pytest.raises(ValueError, match="M is not positive definite"):
        bc.mass_factor(sp.csr_array(np.array([[1.0, 2.0], [2.0, 1.0]])))
    with pytest.raises(ValueError, match=r"M\[1,1\] = -1 <= 0"):
        bc.mass_factor(sp.diags_array([1.0, -1.0]).tocsr())


@pytest.mark.parametrize("which", ["consistent", "lumped", "dense"])
def test_reflection_orthogonal_involutive_and_M_orthogonal(which, plate_model, plate_lumped, random_sys):
    if which == "dense":
        M, w = random_sys.M, random_sys.w
    else:
        model = plate_model if which == "consistent" else plate_lumped
        M, w = model.M, le_contact(model).w(model)
    sb = bc.SymmetryBasis(M, w)
    Md = M.toarray() if sp.issparse(M) else M
    n = Md.shape[0]
    I = np.eye(n)
    H = sb.householder(I)
    np.testing.assert_allclose(H.T @ H, I, rtol=0, atol=1e-14)  # orthogonal
    np.testing.assert_allclose(H @ H, I, rtol=0, atol=1e-14)  # involutive
    np.testing.assert_allclose(H @ sb.u_hat, -sb.u_hat, rtol=0, atol=1e-15)  # û ↦ -û, û⊥ fixed
    assert np.linalg.norm(sb.u_hat) == pytest.approx(1.0, rel=1e-15)
    assert sb.w_hat_norm**2 == pytest.approx(w @ np.linalg.solve(Md, w), rel=1e-12)  # |ŵ|² = wᵀM⁻¹w
    R = sb.reflect(I)
    scale = np.abs(Md).max()
    np.testing.assert_allclose(R.T @ Md @ R, Md, rtol=0, atol=1e-12 * scale)  # M-orthogonal
    np.testing.assert_allclose(R @ R, I, rtol=0, atol=1e-12)
    Minv_w = np.linalg.solve(Md, w)
    np.testing.assert_allclose(R, I - 2 * np.outer(Minv_w, w) / (w @ Minv_w), rtol=0, atol=1e-12)  # theory §1
    np.testing.assert_allclose(sb.to_x(H @ sb.to_y(I)), R, rtol=0, atol=1e-12)  # R = F⁻ᵀ H Fᵀ
    x = np.random.default_rng(2).standard_normal(n)
    assert sb.to_y(x) @ sb.to_y(x) == pytest.approx(x @ Md @ x, rel=1e-13)  # |y|² = xᵀMx
    np.testing.assert_allclose(sb.to_x(sb.to_y(x)), x, rtol=0, atol=1e-12 * np.abs(x).max())
    assert sb.to_y(x) @ sb.w_hat == pytest.approx(w @ x, rel=1e-12)  # gap: ŵᵀy = wᵀx


def test_per_dof_law_defect_consistent_vs_lumped(plate_model, plate_lumped):
    # lumped: the contact node's dofs have one mass, w is an eigenvector of M: no defect
    c = le_contact(plate_lumped)
    d = bc.SymmetryBasis(plate_lumped.M, c.w(plate_lumped)).per_dof_defect()
    assert d.kappa == 1.0 and d.max_gain == 0.0 and d.max_loss == 0.0 and d.impulse_gain == 0.0
    # consistent: the closed form against the dense generalised eigenvalues of (PᵀMP, M)
    w = c.w(plate_model)
    M = plate_model.M.toarray()
    d = bc.per_dof_defect(plate_model.M, w)
    P = per_dof_law(np.eye(w.size), w)
    ratios = sla.eigvalsh(P.T @ M @ P, M)  # T⁺/T⁻ over all velocities
    assert d.kappa > 1.1
    assert ratios.max() - 1 == pytest.approx(d.max_gain, rel=1e-9)
    assert 1 - ratios.min() == pytest.approx(d.max_loss, rel=1e-9)
    v = np.linalg.solve(M, w)  # unit normal impact of the impulse-response velocity
    gain = (per_dof_law(v, w) @ M @ per_dof_law(v, w)) / (v @ M @ v) - 1
    assert gain == pytest.approx(d.impulse_gain, rel=1e-10)
    # the Moreau law conserves the energy of every state
    sb = bc.SymmetryBasis(plate_model.M, w)
    V = np.random.default_rng(3).standard_normal((w.size, 5))
    np.testing.assert_allclose(np.sum(sb.reflect(V) * (M @ sb.reflect(V)), 0), np.sum(V * (M @ V), 0), rtol=1e-12)


# --------------------------------------------------------------------------- Lanczos: full chain


@pytest.mark.parametrize("which", ["plate", "plate_lumped", "bar"])
def test_full_lanczos_reproduces_every_frequency_and_participation(which, plate_model, plate_lumped, bar_model, modes):
    model = {"plate": plate_model, "plate_lumped": plate_lumped, "bar": bar_model}[which]
    c = le_contact(model)
    lam, b = modes[which]
    n = model.n_dofs
    ch = bc.lanczos_chain(model, n, contact=c)
    assert ch.steps == n and ch.breakdown and ch.observable_dimension == n  # the corner sees every mode
    mu, b2 = chain_spectrum(ch)
    # every frequency, relative 1e-9 (measured ≤ 8e-11, bar: cond(A) = 5e6); both solvers are
    # backward stable: |Δω²| = O(ε ω²_max), measured ≤ 1.2e-15 ω²_max
    np.testing.assert_allclose(np.sqrt(mu), np.sqrt(lam), rtol=1e-9)
    np.testing.assert_allclose(mu, lam, rtol=0, atol=1e-14 * lam[-1])
    np.testing.assert_allclose(b2, b**2, rtol=1e-8)  # every b_j² (measured ≤ 2.1e-10)
    # the basis maps back: VᵀMV = I, VᵀKV = J, Vᵀw = |ŵ| e₁
    V = ch.basis
    np.testing.assert_allclose(V.T @ (model.M @ V), np.eye(n), rtol=0, atol=1e-12)
    np.testing.assert_allclose(V.T @ (model.K @ V), ch.jacobi, rtol=0, atol=1e-13 * np.abs(ch.jacobi).max())
    np.testing.assert_allclose(V.T @ c.w(model), ch.w_hat_norm * np.eye(n)[0], rtol=0, atol=1e-13 * ch.w_hat_norm)


def test_chain_springs_rebuild_the_jacobi_matrix(plate_model):
    ch = bc.lanczos_chain(plate_model, 40, contact=le_contact(plate_model))
    assert not ch.breakdown and ch.observable_dimension is None
    assert np.all(ch.beta < 0) and np.all(ch.springs > 0)  # alternate signs flipped
    np.testing.assert_array_equal(ch.masses, np.ones(40))
    J = ch.jacobi
    np.testing.assert_array_equal(J, np.diag(ch.alpha) + np.diag(ch.beta, 1) + np.diag(ch.beta, -1))
    g = ch.grounding_springs
    np.testing.assert_allclose(g, J.sum(axis=1), rtol=0, atol=1e-15 * np.abs(J).max())  # row sums
    # the chain wall–g–m₁–s₁–m₂–…: K_ii = g_i + s_{i-1} + s_i, K_{i,i+1} = -s_i  (rebuilt here, by hand)
    s = ch.springs
    K = np.diag(g + np.r_[0.0, s] + np.r_[s, 0.0]) - np.diag(s, 1) - np.diag(s, -1)
    np.testing.assert_allclose(K, J, rtol=0, atol=1e-15 * np.abs(J).max())
    np.testing.assert_allclose(chain_jacobi(s, g), J, rtol=0, atol=1e-15 * np.abs(J).max())
    # the solver's system: unit masses, stiffness J, contact on the FIRST mass with weight |ŵ| and gap d
    sys_ = ch.system
    np.testing.assert_array_equal(sys_.M, np.eye(40))
    np.testing.assert_array_equal(sys_.K, J)
    np.testing.assert_array_equal(sys_.w, ch.w_hat_norm * np.eye(40)[0])
    assert sys_.gap == GAP
    sb = bc.SymmetryBasis(plate_model.M, le_contact(plate_model).w(plate_model))
    assert ch.w_hat_norm == pytest.approx(sb.w_hat_norm, rel=1e-15)


def test_m_step_lanczos_is_the_gauss_quadrature_of_the_contact_measure(bar_model, modes):
    c = le_contact(bar_model)
    lam, b = modes["bar"]
    scale = lam[-1]  # moments of λ/λ_max: no overflow, every term <= b_j²
    for m in (3, 6):
        ch = bc.lanczos_chain(bar_model, m, contact=c)
        J = ch.jacobi / scale
        mu = np.array([np.sum(b**2 * (lam / scale) ** p) for p in range(2 * m + 1)])
        quad = np.array([ch.w_hat_norm**2 * np.linalg.matrix_power(J, p)[0, 0] for p in range(2 * m + 1)])
        np.testing.assert_allclose(quad[: 2 * m], mu[: 2 * m], rtol=1e-8)  # first 2m moments (measured ≤ 1e-14)
        if m == 3:
            assert abs(quad[2 * m] / mu[2 * m] - 1) > 1e-6  # and not the next one: exactly 2m


def test_breakdown_reports_the_observable_dimension():
    # two identical, uncoupled chains; the contact sees one of them only
    a = bc.chain(7, k=1.0, m=0.5, gap=1.0)
    K = sp.block_diag([a.K, 1.3 * a.K], format="csr")
    M = sp.block_diag([a.M, a.M], format="csr")
    w = np.r_[a.w, np.zeros(7)]
    s = bc.LinearSystem(M, K, w, 1.0)
    ch = bc.lanczos_chain(s, 14)
    assert ch.breakdown and ch.observable_dimension == 7 and ch.steps == 7
    mu, b2 = chain_spectrum(ch)
    np.testing.assert_allclose(np.sqrt(mu), a.spectrum.omega, rtol=1e-12)
    np.testing.assert_allclose(b2, a.spectrum.b ** 2, rtol=1e-10)
    np.testing.assert_allclose(ch.basis[7:], 0.0, atol=1e-14)  # the unseen chain never moves


def mirrored_plate(nx: int = 4, ny: int = 16, span: float = 0.1, half: float = 0.015) -> Mesh:
    """A rectangular plate ``[-half, half] × [0, span]`` whose mesh is exactly symmetric about ``x = 0``."""
    m = MeshTri.init_tensor(np.linspace(0, half, nx + 1), np.linspace(0, span, ny + 1))
    p, t = m.p.T, m.t.T
    image = np.arange(p.shape[0], 2 * p.shape[0])
    on_axis = np.flatnonzero(p[:, 0] == 0.0)
    image[on_axis] = on_axis
    cells = np.vstack([t, image[t][:, [0, 2, 1]]])  # mirrored triangles, counter-clockwise again
    used, local = np.unique(cells, return_inverse=True)
    pts = np.vstack([p, p * [-1.0, 1.0]])[used]
    pts = np.c_[pts, np.zeros(len(pts))]
    groups = {"root": np.flatnonzero(pts[:, 1] == 0.0), "tip": np.flatnonzero(pts[:, 1] == span)}
    return Mesh(points=pts, cells={"triangle": local.reshape(cells.shape)}, dim=2, groups=groups, source="mirrored")


def test_symmetry_unobservable_modes_stay_invisible_in_the_chain():
    # contact on the mirror plane, radial normal: the antisymmetric half of the modes has b_j = 0.
    # Round-off seeds them and Lanczos does not break down, but they enter the chain with
    # round-off weights (measured <= 4e-13 max|b|); the observable ones are reproduced.
    model = bc.assemble(mirrored_plate(), "steel", order=1, thickness=0.002)
    c = bc.Contact.nearest(model, (0.0, 0.1), gap=GAP)
    assert model.mesh.points[c.node, 0] == 0.0
    lam, b, _ = dense_modes(model, c.w(model))
    seen = np.abs(b) > 1e-8 * np.abs(b).max()  # a clear gap: 7.6e-4 vs 3.6e-12 measured
    assert seen.sum() == model.n_dofs // 2 == 144
    ch = bc.lanczos_chain(model, model.n_dofs, contact=c)
    mu, b2 = chain_spectrum(ch)
    seen_ch = np.sqrt(b2) > 1e-8 * np.sqrt(b2).max()
    assert seen_ch.sum() == 144
    assert np.sqrt(b2[~seen_ch]).max() < 1e-11 * np.sqrt(b2).max()
    np.testing.assert_allclose(np.sqrt(mu[seen_ch]), np.sqrt(lam[seen]), rtol=1e-10)  # measured 6e-13
    np.testing.assert_allclose(b2[seen_ch], b[seen] ** 2, rtol=1e-9)  # measured 4e-12
    assert ch.system.spectrum.active.sum() == 144  # the solver ignores the round-off modes


@pytest.mark.parametrize("name", ["chain10", "random_sys"])
def test_linear_system_input(name, request):
    s = request.getfixturevalue(name)  # diagonal sparse M (chain) and dense non-diagonal M
    ch = bc.lanczos_chain(s, s.n)
    mu, b2 = chain_spectrum(ch)
    np.testing.assert_allclose(np.sqrt(mu), s.spectrum.omega, rtol=1e-12)
    np.testing.assert_allclose(b2, s.spectrum.b ** 2, rtol=1e-10)
    with pytest.raises(ValueError, match="contact must be None for a LinearSystem"):
        bc.lanczos_chain(s, 2, contact=bc.Contact(0, (0, 1), 1.0))


def test_reorthogonalisation_keeps_the_basis_orthonormal(plate_model):
    c = le_contact(plate_model)
    errors = {}
    for reorth in (0, 2):
        ch = bc.lanczos_chain(plate_model, 120, contact=c, reorth=reorth)
        V = ch.basis
        errors[reorth] = np.abs(V.T @ (plate_model.M @ V) - np.eye(ch.steps)).max()
    assert errors[2] < 1e-13
    assert errors[0] > 1e-3  # plain Lanczos loses orthogonality on an FE spectrum


# --------------------------------------------------------------------------- the 1-ipp orbit: full vs chain


@pytest.fixture(scope="module")
def plate_orbit_pair(plate_model):
    c = le_contact(plate_model)
    full = c.system(plate_model)
    ch = bc.lanczos_chain(plate_model, plate_model.n_dofs, contact=c)
    return c, full, ch


def impulse_sensitivity(system: bc.LinearSystem, T: float) -> float:
    """First-order relative change of the 1-ipp impulse ``Λ = -d/g(0)`` when every ``ω_j²`` moves by ``ε ω²_max``.

    ``g(0) = Σ_j b_j² cot(ω_j T/2)/(2ω_j)``; both the dense eigen-solution and Lanczos are backward
    stable (eigenvalue errors ``O(ε ω²_max)``), so this is the accuracy to expect from either.  It
    is large near a resonance ``ω_j T ∈ 2πℤ`` of ANY mode: on an FE model with hundreds of modes
    most periods are near some high-mode resonance.
    """
    om, b = system.spectrum.omega, system.spectrum.b
    half = om * T / 2
    g = np.sum(b**2 / np.tan(half) / (2 * om))
    dg_dlam = b**2 * (-T / (4 * om * np.sin(half) ** 2) - 1 / np.tan(half) / (2 * om**2)) / (2 * om)
    return float(np.finfo(float).eps * om[-1] ** 2 * np.sum(np.abs(dg_dlam)) / abs(g))


def test_1ipp_orbits_of_full_model_and_chain_agree(plate_model, plate_orbit_pair):
    c, full, ch = plate_orbit_pair
    red = ch.system
    w = c.w(plate_model)
    T1 = 2 * np.pi / full.spectrum.omega[0]
    # a period grid, admissible periods found by a scan (1-ipp orbits of the plate are admissible on
    # narrow windows only), and one near grazing of mode 1 (T -> T1⁻, Λ ∝ 1/(T1 - T))
    periods = T1 * np.r_[np.linspace(0.051, 2.93, 80), 0.12879799666110184, 0.5178631051752922,
                         1.2418196994991655, 0.99999]
    n_admissible = n_well = 0
    for T in periods:
        o_full = bc.orbit_1ipp(full, T)
        o_red = bc.orbit_1ipp(red, T)
        # 1e-8 where the impulse is well conditioned; else 10× its first-order sensitivity to
        # eigenvalue errors O(ε ω²_max) (measured: error <= 0.9 S for Λ, <= 2.2 S for E)
        S = impulse_sensitivity(full, T)
        tol = 1e-8 + 10 * S
        n_well += S <= 1e-10
        assert o_red.impact_times[0] == o_full.impact_times[0] == T
        assert o_red.impulses[0] == pytest.approx(o_full.impulses[0], rel=tol)
        assert o_red.energy == pytest.approx(o_full.energy, rel=tol)
        assert o_red.admissible == o_full.admissible
        n_admissible += o_full.admissible
        t = np.linspace(0.0, T, 41)
        # physical contact displacement wᵀx(t), and the whole field x = V z mapped back from the chain
        x_full = o_full.state(t)[0]
        x_red = ch.expand(o_red.state(t)[0])
        amplitude = np.abs(o_full.contact(t)).max()  # >= d, up to ~100 d on this grid
        np.testing.assert_allclose(w @ x_red, o_full.contact(t), rtol=0, atol=tol * amplitude)
        np.testing.assert_allclose(w @ x_red, o_red.contact(t), rtol=0, atol=1e-12 * amplitude)
        np.testing.assert_allclose(x_red, x_full, rtol=0, atol=tol * np.abs(x_full).max())
    assert n_admissible >= 4 and n_well >= 10


# --------------------------------------------------------------------------- shift-invert


def test_shift_invert_chain_resolves_the_lowest_modes(plate_model, modes):
    c = le_contact(plate_model)
    lam, b = modes["plate"]
    m = 20
    si = bc.lanczos_chain(plate_model, m, contact=c, shift_invert=True)
    plain = bc.lanczos_chain(plate_model, m, contact=c)
    assert si.method == "shift-invert" and si.sigma == 0.0 and si.steps == m
    f_si = np.sqrt(sla.eigvalsh(si.jacobi))[:3]
    f_plain = np.sqrt(sla.eigvalsh(plain.jacobi))[:3]
    f_ref = np.sqrt(lam[:3])
    np.testing.assert_allclose(f_si, f_ref, rtol=1e-6)  # measured ≤ 3e-12
    assert np.all(np.abs(f_plain / f_ref - 1) > 1e-2)  # plain Lanczos: still far off at m = 20
    # still a chain: negative off-diagonals, contact on mass 1, M-orthonormal basis
    assert np.all(si.beta < 0)
    V = si.basis
    np.testing.assert_allclose(V.T @ (plate_model.M @ V), np.eye(m), rtol=0, atol=1e-12)
    np.testing.assert_allclose(V.T @ (plate_model.K @ V), si.jacobi, rtol=0, atol=1e-12 * np.abs(si.jacobi).max())
    np.testing.assert_allclose(V.T @ c.w(plate_model), si.w_hat_norm * np.eye(m)[0], rtol=0, atol=1e-12 * si.w_hat_norm)
    # low-frequency moments Σ b_j² ω_j^{-2p}, p = 1..2m, are matched
    Jinv = np.linalg.inv(si.jacobi) * lam[0]
    mu = np.array([np.sum(b**2 * (lam[0] / lam) ** p) for p in range(1, 2 * m + 1)])
    quad = np.array([si.w_hat_norm**2 * np.linalg.matrix_power(Jinv, p)[0, 0] for p in range(1, 2 * m + 1)])
    np.testing.assert_allclose(quad, mu, rtol=1e-8)  # measured ≤ 2e-10
    # the system the solver consumes works as for the plain chain
    assert si.system.n == m and si.system.gap == GAP


def test_shift_invert_with_a_shift(bar_model, modes):
    c = le_contact(bar_model)
    lam, _ = modes["bar"]
    sigma = 0.5 * (lam[4] + lam[5])  # between modes 5 and 6
    si = bc.lanczos_chain(bar_model, 12, contact=c, shift_invert=True, sigma=sigma)
    mu = sla.eigvalsh(si.jacobi)
    for j in (3, 4, 5, 6):  # the modes around the shift
        assert np.min(np.abs(mu / lam[j] - 1)) < 1e-8
    with pytest.raises(ValueError, match="sigma must be finite"):
        bc.lanczos_chain(bar_model, 4, contact=c, shift_invert=True, sigma=float("inf"))


# --------------------------------------------------------------------------- errors


def test_lanczos_errors(plate_model):
    c = le_contact(plate_model)
    n = plate_model.n_dofs
    for steps in (0, -3, n + 1, 2.5, True):
        with pytest.raises(ValueError, match=rf"steps must be an integer with 1 <= steps <= {n}"):
            bc.lanczos_chain(plate_model, steps, contact=c)
    with pytest.raises(ValueError, match="an FEModel needs a contact"):
        bc.lanczos_chain(plate_model, 5)
    with pytest.raises(ValueError, match="reorth must be one of"):
        bc.lanczos_chain(plate_model, 5, contact=c, reorth=3)
    with pytest.raises(ValueError, match="needs a LinearSystem or an FEModel"):
        bc.lanczos_chain(np.eye(3), 2)
    with pytest.raises(ValueError, match="is clamped"):
        bc.lanczos_chain(plate_model, 5, contact=bc.Contact(int(plate_model.clamped[0]), None, GAP))
