"""Reduction layer (``bladecase.reduce``): each reduced model against the full FE model.

Reference model: the committed plane-stress plate ``meshes/plate.msh`` (P1,
1084 free dofs, Ti-6Al-4V, 2 mm thick, root clamped), contact at its
``contact`` node (tip edge) with the radial casing normal ``+y`` and a
0.1 mm clearance.  Independent references are numpy/scipy only: dense
generalised eigen-solutions, a dense Rayleigh–Ritz on the Craig–Bampton
subspace, and finite differences in time of the expanded velocities.

Measured on this model (the tolerances keep a margin of 10–100 unless said):

* Craig–Bampton with all fixed-interface modes vs full: ω 1e-11–7e-11, b²
  1.4e-10 (relative, modes with b² >= 1e-6 max b²; 2e-12 of max b² for all);
  1-ipp impulses and energies 1e-11–2e-9, up to 1e-6 at ``T = 0.9999·T₁``
  where ``1/sin(ω₁T/2)`` amplifies the 1e-11 frequency error (tolerance
  scaled by that conditioning);
* modal with all modes vs full: ω 7e-11, b² 2e-10;
* Craig–Bampton truncations, worst of the 5 lowest ω: 3.5e-2 (5 modes),
  5.5e-4 (10), 2.3e-4 (20), 2.8e-5 (40), 4.2e-6 (80);
* residual of the expanded orbit, ``a`` from sixth-order central differences
  of the expanded velocity: full ``‖M a + K u‖/‖K u‖`` 9e-13; projected
  ``‖Vᵀ(M a + K u)‖/‖VᵀK u‖`` 4e-12 (modal 20), 6e-12 (Craig–Bampton 20),
  5e-12 (Lanczos 20), 2.5e-12 (shift-invert Lanczos 20); the unprojected
  residual is 4.6e-12 for modal (its span is invariant) but O(0.1–1) for the
  others;
* contact node: ``ν·u_node`` equals ``wᵀx`` of the orbit to 1e-15 of the gap.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import bladecase as bc
from bladecase.reduction import FULL_LIMIT, METHODS, Contact, ReducedModel, reduce

MESHES = Path(__file__).resolve().parent.parent / "meshes"
GAP = 1e-4

# --------------------------------------------------------------------------- fixtures and helpers

@pytest.fixture(scope="module")
def plate() -> bc.FEModel:
    mesh = bc.load_mesh(MESHES / "plate.msh")
    return bc.assemble(mesh, "Ti-6Al-4V", order=1, thickness=0.002)


@pytest.fixture(scope="module")
def contact(plate) -> Contact:
    return Contact(int(plate.mesh.group("contact")[0]), [0.0, 1.0], GAP)


@pytest.fixture(scope="module")
def full(plate, contact) -> ReducedModel:
    return reduce(plate, contact, "full")


@pytest.fixture(scope="module")
def cb_all(plate, contact) -> ReducedModel:
    n_b = plate.dim  # the contact node's free dofs
    return reduce(plate, contact, "craig-bampton", plate.n_dofs - n_b)


def dense(a) -> np.ndarray:
    return a.toarray() if sp.issparse(a) else np.asarray(a)


def relative(a, b) -> np.ndarray:
    return np.abs(np.asarray(a) / np.asarray(b) - 1.0)


def significant(b2: np.ndarray) -> np.ndarray:
    return b2 >= 1e-6 * b2.max()


def periods(system: bc.LinearSystem, modes=range(8), ratios=(0.9, 0.95, 0.99, 0.995, 0.999, 0.9995, 0.9999, 0.99999)):
    omega = system.spectrum.omega
    return [r * 2 * np.pi / omega[j] for j in modes for r in ratios]


def admissible_orbit(system: bc.LinearSystem) -> bc.PeriodicOrbit:
    """The first admissible 1-ipp orbit just below one of the eight lowest linear periods."""
    for T in periods(system):
        orbit = bc.orbit_1ipp(system, T)
        if orbit.admissible:
            return orbit
    raise AssertionError("no admissible 1-ipp orbit found below the eight lowest linear periods")


def at_free_dofs(model: bc.FEModel, u: np.ndarray) -> np.ndarray:
    """Per-node array ``(n_nodes, dim, k)`` back to the free (vertex) dofs ``(n_free, k)``."""
    return u[model.dofs.node, model.dofs.direction]


def fd_acceleration(reduced: ReducedModel, orbit, t: np.ndarray, h: float) -> np.ndarray:
    """Sixth-order central difference of the expanded velocity, ``(n_nodes, dim, len(t))``."""
    a = 0.0
    for k, c in ((1, 3 / 4), (2, -3 / 20), (3, 1 / 60)):
        a = a + c * (reduced.expand(orbit, t + k * h)[1] - reduced.expand(orbit, t - k * h)[1])
    return a / h


# --------------------------------------------------------------------------- exactness of complete bases

def test_craig_bampton_with_all_fixed_interface_modes_equals_the_full_model(full, cb_all):
    sf, sc = full.system.spectrum, cb_all.system.spectrum
    assert cb_all.n == full.n
    assert relative(sc.omega, sf.omega).max() < 1e-8
    b2f, b2c = sf.b**2, sc.b**2
    keep = significant(b2f)
    assert keep.sum() > 0.9 * keep.size
    assert relative(b2c[keep], b2f[keep]).max() < 1e-8
    assert np.abs(b2c - b2f).max() < 1e-8 * b2f.max()
    # the reduced mass is not diagonal: the contact dofs are coupled to the modes
    M_r = dense(cb_all.system.M)
    assert np.abs(M_r - np.diag(np.diag(M_r))).max() > 1e-3 * np.abs(M_r).max()


def test_craig_bampton_complete_basis_gives_the_same_1ipp_orbits(full, cb_all):
    """Same impulses and energies, to the conditioning of the orbit near a resonance.

    ``Λ = -d/g(0)`` and the energy go through ``1/sin(ω_j T/2)``: a relative
    error ``δ`` in ``ω_j`` moves them by about ``δ·ω_jT/(2|sin(ω_jT/2)|)``.
    """
    seen_admissible = False
    omega = full.system.spectrum.omega
    for T in periods(full.system, modes=(0, 3), ratios=(0.5, 0.95, 0.99, 0.9999)):
        of, oc = bc.orbit_1ipp(full.system, T), bc.orbit_1ipp(cb_all.system, T)
        tol = max(1e-7, 1e-9 / np.abs(np.sin(omega * T / 2)).min())
        assert relative(oc.impulses, of.impulses).max() < tol
        assert relative(oc.energy, of.energy) < tol
        assert oc.admissible == of.admissible
        seen_admissible |= of.admissible
    assert seen_admissible


def test_modal_with_all_modes_equals_the_full_model(plate, contact, full):
    modal = reduce(plate, contact, "modal", plate.n_dofs)
    sf, sm = full.system.spectrum, modal.system.spectrum
    assert relative(sm.omega, sf.omega).max() < 1e-8
    keep = significant(sf.b**2)
    assert relative(sm.b[keep] ** 2, sf.b[keep] ** 2).max() < 1e-8
    assert np.allclose(dense(modal.system.M), np.eye(plate.n_dofs), rtol=0, atol=1e-12)
    V = modal.basis
    assert np.abs(V.T @ (plate.M @ V) - np.eye(V.shape[1])).max() < 1e-8


# --------------------------------------------------------------------------- truncations

def test_modal_truncation_keeps_the_lowest_modes_exactly(plate, contact, full):
    sf = full.system.spectrum
    modal = reduce(plate, contact, "modal", 10)  # sparse shift-invert
    sm = modal.system.spectrum
    assert modal.n == 10 and modal.basis.shape == (plate.n_dofs, 10)
    assert relative(sm.omega, sf.omega[:10]).max() < 1e-8
    assert relative(np.abs(sm.b), np.abs(sf.b[:10])).max() < 1e-6
    assert np.allclose(modal.system.w, modal.basis.T @ contact.w(plate), rtol=1e-12, atol=0)
    V = modal.basis
    assert np.abs(V.T @ (plate.M @ V) - np.eye(10)).max() < 1e-10
    K_r = V.T @ (plate.K @ V)
    assert np.abs(K_r - dense(modal.system.K)).max() < 1e-8 * sm.omega[-1] ** 2


def test_craig_bampton_truncation_is_rayleigh_ritz_on_its_subspace(plate, contact):
    """CB(20) (sparse LU and shift-invert) against a dense Rayleigh–Ritz on the same subspace."""
    cb = reduce(plate, contact, "craig-bampton", 20)
    K, M = plate.K.toarray(), plate.M.toarray()
    b = np.flatnonzero(plate.dofs.node == contact.node)
    i = np.setdiff1d(np.arange(plate.n_dofs), b)
    psi = -np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, b)])
    _, phi = sla.eigh(K[np.ix_(i, i)], M[np.ix_(i, i)], subset_by_index=[0, 19])
    V = np.zeros((plate.n_dofs, b.size + 20))
    V[b, np.arange(b.size)] = 1.0
    V[np.ix_(i, np.arange(b.size))] = psi
    V[np.ix_(i, b.size + np.arange(20))] = phi
    lam = sla.eigh(V.T @ K @ V, V.T @ M @ V, eigvals_only=True)
    assert cb.n == b.size + 20 and cb.basis.shape == (plate.n_dofs, cb.n)
    assert relative(cb.system.spectrum.omega, np.sqrt(lam)).max() < 1e-8
    assert np.allclose(cb.basis[b], np.c_[np.eye(b.size), np.zeros((b.size, 20))])  # physical contact dofs
    assert np.allclose(cb.system.w, cb.basis.T @ contact.w(plate), rtol=1e-12, atol=0)


def test_truncations_converge_to_the_lowest_full_frequencies(plate, contact, full):
    omega = full.system.spectrum.omega[:5]
    errors = []
    for size in (5, 10, 20, 40, 80):
        cb = reduce(plate, contact, "craig-bampton", size).system.spectrum.omega[:5]
        err = cb / omega - 1.0
        assert np.all(err > -1e-9)  # Rayleigh–Ritz: upper bounds
        errors.append(err)
        modal = reduce(plate, contact, "modal", size).system.spectrum.omega[: min(size, 5)]
        assert relative(modal, omega[: modal.size]).max() < 1e-8
    errors = np.array(errors)
    assert np.all(np.diff(errors, axis=0) <= 1e-12)  # monotone in size
    assert errors[0].max() > 1e-2 and errors[-1].max() < 1e-5


@pytest.mark.parametrize("method", ["lanczos", "lanczos-si"])
def test_lanczos_models_are_chains_on_an_m_orthonormal_basis(plate, contact, method):
    reduced = reduce(plate, contact, method, 12)
    V, system = reduced.basis, reduced.system
    assert reduced.chain is not None and reduced.n == reduced.chain.steps == 12
    assert np.abs(V.T @ (plate.M @ V) - np.eye(12)).max() < 1e-12
    K_r = dense(system.K)
    assert np.abs(V.T @ (plate.K @ V) - K_r).max() < 1e-12 * np.abs(K_r).max()
    assert np.abs(np.triu(K_r, 2)).max() == 0.0  # tridiagonal: a spring–mass chain
    assert np.allclose(V.T @ contact.w(plate), system.w, rtol=0, atol=1e-12 * np.abs(system.w).max())
    assert np.flatnonzero(system.w).tolist() == [0]  # contact on the first mass


def test_lanczos_matches_the_moments_of_the_contact_spectral_measure(plate, contact, full):
    """m steps: Σ b_j² λ_j^p exact for p < 2m (plain), p = 1..2m for λ^-p (shift-invert)."""
    sf = full.system.spectrum
    lam, b2 = sf.omega**2, sf.b**2
    scale = lam.max()
    m = 5
    plain = reduce(plate, contact, "lanczos", m).system.spectrum
    p = np.arange(2 * m)
    got = [(plain.b**2) @ (plain.omega**2 / scale) ** k for k in p]
    ref = [b2 @ (lam / scale) ** k for k in p]
    assert relative(got, ref).max() < 1e-10
    si = reduce(plate, contact, "lanczos-si", m).system.spectrum
    p = np.arange(1, 2 * m + 1)
    scale = lam.min()
    got = [(si.b**2) @ (si.omega**2 / scale) ** -k for k in p]
    ref = [b2 @ (lam / scale) ** -k for k in p]
    assert relative(got, ref).max() < 1e-8
    # and the shift-invert chain converges to the lowest modes from above
    omega = reduce(plate, contact, "lanczos-si", 12).system.spectrum.omega[:3]
    assert relative(omega, sf.omega[:3]).max() < 1e-9


# --------------------------------------------------------------------------- expansion

def test_the_expanded_full_orbit_satisfies_the_fe_equations_between_impacts(plate, full):
    orbit = admissible_orbit(full.system)
    omega_max = full.system.spectrum.omega.max()
    t = np.array([0.13, 0.5, 0.77]) * orbit.T  # inside the flight (0, T)
    u, _ = full.expand(orbit, t)
    a = fd_acceleration(full, orbit, t, 0.03 / omega_max)
    U, A = at_free_dofs(plate, u), at_free_dofs(plate, a)
    residual = np.linalg.norm(plate.M @ A + plate.K @ U, axis=0) / np.linalg.norm(plate.K @ U, axis=0)
    assert residual.max() < 1e-8


@pytest.mark.parametrize("method, size", [("modal", 20), ("craig-bampton", 20), ("lanczos", 20), ("lanczos-si", 20)])
def test_the_expanded_reduced_orbit_satisfies_the_projected_fe_equations(plate, contact, method, size):
    reduced = reduce(plate, contact, method, size)
    orbit = admissible_orbit(reduced.system)
    omega_max = reduced.system.spectrum.omega.max()
    t = np.array([0.2, 0.5, 0.9]) * orbit.T
    u, v = reduced.expand(orbit, t)
    a = fd_acceleration(reduced, orbit, t, 0.03 / omega_max)
    U, A = at_free_dofs(plate, u), at_free_dofs(plate, a)
    V = reduced.basis
    residual = plate.M @ A + plate.K @ U
    projected = np.linalg.norm(V.T @ residual, axis=0)
    assert (projected / np.linalg.norm(V.T @ (plate.K @ U), axis=0)).max() < 1e-8
    if method == "modal":  # the span of exact modes is invariant: the full residual vanishes too
        assert (np.linalg.norm(residual, axis=0) / np.linalg.norm(plate.K @ U, axis=0)).max() < 1e-8
    # the expanded fields are V x_r exactly
    x_r, v_r = orbit.state(t)
    assert np.allclose(U, V @ x_r, rtol=0, atol=1e-14 * np.abs(U).max())
    assert np.allclose(at_free_dofs(plate, v), V @ v_r, rtol=0, atol=1e-14 * np.abs(v).max())


@pytest.mark.parametrize("method, size", [("full", None), ("modal", 12), ("craig-bampton", 12), ("lanczos", 12),
                                          ("lanczos-si", 12)])
def test_expand_shapes_clamped_nodes_and_contact_displacement(plate, contact, full, method, size):
    reduced = full if method == "full" else reduce(plate, contact, method, size)
    orbit = admissible_orbit(reduced.system)
    t = np.linspace(0.0, orbit.T, 7)
    u, v = reduced.expand(orbit, t)
    n_nodes = plate.mesh.points.shape[0]
    assert u.shape == v.shape == (n_nodes, 2, t.size)
    assert not np.any(u[plate.clamped]) and not np.any(v[plate.clamped])
    normal = contact.normal_for(plate)
    un = np.einsum("c,ct->t", normal, u[contact.node])
    assert np.allclose(un, orbit.contact(t), rtol=0, atol=1e-10 * GAP)
    assert abs(un[0] - GAP) < 1e-9 * GAP and abs(un[-1] - GAP) < 1e-9 * GAP  # at the obstacle at t = 0, T
    assert np.all(un <= GAP * (1 + 1e-9))
    # a scalar time and raw reduced states
    u1, _ = reduced.expand(orbit, 0.25 * orbit.T)
    assert u1.shape == (n_nodes, 2, 1)
    x_r, _ = orbit.state(0.25 * orbit.T)
    assert np.array_equal(reduced.expand_state(x_r[:, 0]), u1[:, :, 0])
    assert reduced.expand_state(x_r).shape == (n_nodes, 2, 1)


def test_expand_of_quadratic_meshes_and_p2_models():
    """Edge dofs (node == -1) get no row; midside mesh nodes carry the field at their edge midpoint."""
    geometry = bc.PlateGeometry(span=0.05, chord=0.02, contact_point=(0.0, 0.05))
    mesh = bc.blade_mesh(geometry, size=0.01, order=2)
    assert mesh.body_type == "triangle6"
    node = int(mesh.group("contact")[0])
    tri = mesh.cells["triangle6"]
    rng = np.random.default_rng(7)
    for order in (1, 2):
        model = bc.assemble(mesh, "steel", order=order, thickness=0.001)
        reduced = reduce(model, Contact(node, [0.0, 1.0], GAP), "full")
        x = rng.standard_normal(model.n_dofs)
        u = reduced.expand_state(x)
        assert u.shape == (mesh.points.shape[0], 2)
        vertex = model.dofs.node >= 0
        assert np.array_equal(u[model.dofs.node[vertex], model.dofs.direction[vertex]], x[vertex])
        assert not np.any(u[model.clamped])
        for k, (p, q) in enumerate([(0, 1), (1, 2), (0, 2)]):
            mid = tri[:, 3 + k]
            ends = u[tri[:, p]], u[tri[:, q]]
            if order == 1:
                expected = 0.5 * (ends[0] + ends[1])
            else:  # the edge dof at the straight midpoint
                centre = 0.5 * (mesh.points[tri[:, p]] + mesh.points[tri[:, q]])
                expected = np.zeros_like(u[mid])
                edge = np.flatnonzero(~vertex)
                for c in range(2):
                    e = edge[model.dofs.direction[edge] == c]
                    d = np.linalg.norm(model.dofs.coords[e][None, :, :] - centre[:, None, :], axis=2)
                    j = d.argmin(axis=1)
                    hit = d[np.arange(j.size), j] < 1e-12
                    expected[hit, c] = x[e[j[hit]]]
            assert np.allclose(u[mid], expected, rtol=0, atol=1e-15)
        assert (order == 2) == bool(np.any(~vertex))  # P2 edge dofs exist, and have no row of their own


def test_craig_bampton_in_3d_keeps_the_contact_node_dofs():
    from skfem import MeshTet

    m = MeshTet.init_tensor(np.linspace(0, 0.05, 11), np.linspace(0, 0.01, 3), np.linspace(0, 0.004, 2))
    p = m.p.T.copy()
    mesh = bc.Mesh(points=p, cells={"tetra": m.t.T.copy()}, dim=3,
                   groups={"root": np.flatnonzero(p[:, 0] < 1e-12)}, source="bar")
    model = bc.assemble(mesh, "Ti-6Al-4V", order=1)
    tip = int(np.flatnonzero((p[:, 0] > 0.05 - 1e-12) & (p[:, 1] > 0.01 - 1e-12) & (p[:, 2] > 0.004 - 1e-12))[0])
    contact = Contact(tip, [0.0, 0.6, 0.8], GAP)
    cb = reduce(model, contact, "craig-bampton", 8)
    assert cb.n == 3 + 8
    full = reduce(model, contact, "full")
    omega = full.system.spectrum.omega[:3]
    assert np.all(cb.system.spectrum.omega[:3] >= omega * (1 - 1e-10))
    assert relative(cb.system.spectrum.omega[:3], omega).max() < 1e-2
    orbit = admissible_orbit(cb.system)
    u, v = cb.expand(orbit, [0.0, 0.3 * orbit.T])
    assert u.shape == (p.shape[0], 3, 2)
    assert abs(np.dot([0.0, 0.6, 0.8], u[tip, :, 0]) - GAP) < 1e-9 * GAP


# --------------------------------------------------------------------------- errors

def test_unknown_method_lists_the_valid_ones(plate, contact):
    with pytest.raises(ValueError, match="unknown reduction method 'guyan'") as exc:
        reduce(plate, contact, "guyan", 10)
    for m in METHODS:
        assert repr(m) in str(exc.value)


@pytest.mark.parametrize("size", [0, -3, 2.5, True, "10"])
def test_size_must_be_a_positive_integer(plate, contact, size):
    with pytest.raises(ValueError, match="size must be an integer >= 1"):
        reduce(plate, contact, "modal", size)


def test_size_is_required_and_bounded(plate, contact):
    n = plate.n_dofs
    with pytest.raises(ValueError, match="needs a size"):
        reduce(plate, contact, "craig-bampton")
    with pytest.raises(ValueError, match=rf"size = {n + 1} is too large for method 'modal'.*valid: 1..{n}"):
        reduce(plate, contact, "modal", n + 1)
    with pytest.raises(ValueError, match=rf"size = {n - 1} is too large for method 'craig-bampton'.*{n - 2} interior"):
        reduce(plate, contact, "craig-bampton", n - 1)
    with pytest.raises(ValueError, match=rf"size = {n + 1} is too large for method 'lanczos-si'.*at most {n}"):
        reduce(plate, contact, "lanczos-si", n + 1)
    with pytest.raises(ValueError, match="'full' keeps all"):
        reduce(plate, contact, "full", 10)


def test_full_refuses_large_models_and_names_the_size(contact):
    mesh = bc.load_mesh(MESHES / "plate.msh")
    big = bc.assemble(mesh, "Ti-6Al-4V", order=2, thickness=0.002)
    assert big.n_dofs > FULL_LIMIT
    with pytest.raises(ValueError, match=rf"limited to FULL_LIMIT = {FULL_LIMIT}.*has {big.n_dofs} free dofs.*'modal'"):
        reduce(big, contact, "full")
    with pytest.raises(ValueError, match="sparse eigen-solver computes at most"):
        reduce(big, contact, "modal", big.n_dofs - 10)


def test_contact_node_without_free_dof(plate):
    clamped = Contact(int(plate.clamped[0]), [0.0, 1.0], GAP)
    with pytest.raises(ValueError, match=f"contact node {int(plate.clamped[0])} is clamped"):
        reduce(plate, clamped, "craig-bampton", 5)


def test_model_and_contact_types(plate, contact, full):
    with pytest.raises(ValueError, match="model must be an FEModel"):
        reduce(full.system, contact, "modal", 5)
    with pytest.raises(ValueError, match="contact must be a bladecase.Contact"):
        reduce(plate, contact.node, "modal", 5)


def test_default_radial_normal_and_contact_helpers(plate, contact):
    """``normal=None`` is the radial +y of a plate; ``Contact.nearest`` finds the same node."""
    a = reduce(plate, Contact(contact.node, None, GAP), "modal", 6)
    p = plate.mesh.points[contact.node]
    b = reduce(plate, Contact.nearest(plate, p, gap=GAP), "modal", 6)
    ref = reduce(plate, contact, "modal", 6)
    for other in (a, b):  # ARPACK starts from a random vector: equal to round-off
        assert np.allclose(other.system.w, ref.system.w, rtol=1e-8, atol=0)
        assert relative(other.system.spectrum.omega, ref.system.spectrum.omega).max() < 1e-12
