"""The massless contact model of a finite-element structure (bladecase.reduction.methods.massless): mass moved
off the contact dofs, static condensation per phase, reduction by the massless structure's modes plus the
contact's attachment vector; checked against the exact dense condensation (bladecase.nsm.condense)."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

import bladecase as bc
from bladecase.linalg import spd_factor
from bladecase.nsm import MasslessSystem, condense
from bladecase.reduction import MasslessReducedModel, massless_model
from bladecase.reduction.methods.massless import massless_masses


def strip(nx: int = 21, ny: int = 5, mass: str = "lumped", order: int = 1):
    """Steel strip 100 mm × 20 mm × 2 mm clamped at x = 0 (groups root, tip), contact at the corner (0.1, 0.02)."""
    t = MeshTri.init_tensor(np.linspace(0, 0.1, nx), np.linspace(0, 0.02, ny))
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = bc.Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0),
                                                              "tip": np.flatnonzero(np.isclose(points[:, 0], 0.1))})
    model = bc.assemble(mesh, "steel", order=order, thickness=0.002, mass=mass)
    return model, bc.Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)


def bar3(k: int):
    """Steel bar 40 mm × 10 mm × 10 mm of P1 tetrahedra (4k × k × k boxes), clamped at x = 0, tip at x = 0.04."""
    m = MeshTet.init_tensor(np.linspace(0, 0.04, 4 * k + 1), np.linspace(0, 0.01, k + 1), np.linspace(0, 0.01, k + 1))
    p = m.p.T.copy()
    mesh = bc.Mesh(p, {"tetra": m.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(p[:, 0] == 0),
                                                               "tip": np.flatnonzero(np.isclose(p[:, 0], 0.04))})
    return bc.assemble(mesh, "steel", order=1, mass="lumped")


def compliance(model, contact) -> float:
    """The full model's static contact compliance wᵀK⁻¹w."""
    w = contact.w(model)
    return float(w @ spd_factor(model.K, "K").solve(w))


def faces(model):
    """Face contacts on the strip's tip: axial, tangential and oblique normals, equal and area weights."""
    return [bc.Contact.face(model, "tip", n, 1e-4, weights=k) for n in ((1.0, 0.0), (0.0, 1.0), (1.0, 1.0))
            for k in ("equal", "area")]


@pytest.fixture(scope="module")
def exact():
    model, contact = strip()
    w = contact.w(model)
    masses = massless_masses(model, np.flatnonzero(w))
    return model, contact, w, masses, condense(np.diag(masses), model.K.toarray(), w, contact.gap)


def test_mass_moved_off_the_contact_keeps_total_and_centre(exact):
    model, _, w, masses, _ = exact
    m0, x = model.M.diagonal(), model.dofs.coords
    assert masses[w != 0].tolist() == [0.0] and masses.min() >= 0 and masses[w == 0].min() > 0
    for d in range(2):
        sel = model.dofs.direction == d
        assert masses[sel].sum() == pytest.approx(m0[sel].sum(), rel=1e-12)
        assert masses[sel] @ x[sel] == pytest.approx(m0[sel] @ x[sel], rel=1e-12)


def test_full_size_reduction_is_the_exact_condensation(exact):
    model, contact, _, _, ex = exact
    r = bc.reduce(model, contact, "massless", ex.n - 1)
    assert isinstance(r.system, MasslessSystem) and r.n == ex.n
    assert r.system.kc == pytest.approx(ex.kc, rel=1e-12)
    for phase in ("open", "closed"):
        a, b = getattr(r.system, phase).omega, getattr(ex, phase).omega
        assert np.abs(a - b).max() <= 1e-10 * b.max()


def test_attachment_vector_makes_the_static_compliance_exact_at_any_size(exact):
    model, contact, w, _, _ = exact
    full = w @ np.linalg.solve(model.K.toarray(), w)
    for size in (1, 4, 10):
        s = bc.reduce(model, contact, "massless", size).system
        assert 1 / s.kc + s.w @ np.linalg.solve(s.S, s.w) == pytest.approx(full, rel=1e-10)


def test_reduced_frequencies_converge_to_the_exact_ones(exact):
    """Open phase: the lowest size modes exactly (1e-10); closed phase: the lowest frequency within 1e-3 already
    at size 4 and within 1e-5 at size 16 (the attachment vector carries the static pinning)."""
    model, contact, _, _, ex = exact
    errs = []
    for size in (4, 16):
        s = bc.reduce(model, contact, "massless", size).system
        assert np.abs(s.open.omega[:size] / ex.open.omega[:size] - 1).max() < 1e-10
        errs.append(abs(s.closed.omega[0] / ex.closed.omega[0] - 1))
    assert errs[0] < 1e-3 and errs[1] < 1e-5 and errs[1] < errs[0]


def test_expansion_holds_the_contact_in_a_closed_phase(exact):
    model, contact, w, _, _ = exact
    r = bc.reduce(model, contact, "massless", 8)
    s = r.system
    q_closed = 3 * np.linalg.solve(s.S + s.kc * np.outer(s.w, s.w), s.kc * s.gap * s.w)  # beyond the casing
    assert s.w @ q_closed > s.gap and w @ r.free_dofs(q_closed) == pytest.approx(s.gap, rel=1e-10)
    q_open = -q_closed
    assert np.allclose(r.free_dofs(q_open), r.basis @ q_open, rtol=0, atol=0)
    both = r.free_dofs(np.c_[q_closed, q_open])
    assert w @ both[:, 0] == pytest.approx(s.gap, rel=1e-10)


def test_massless_orbits_of_the_strip_verify():
    """A reduced massless strip: its one-phase branch near grazing is admissible and re-simulates exactly."""
    model, contact = strip()
    s = bc.reduce(model, contact, "massless", 6).system
    T1 = 2 * np.pi / s.open.omega[0]
    (branch, *_) = bc.nonsmooth_mode(s, 1, (0.9 * T1, 1.01 * T1))
    assert branch.arcs and branch.arcs[0].T_hi == pytest.approx(T1, rel=1e-3)
    arc = branch.arcs[0]
    (orbit, *_) = [o for o in branch.orbit_at(0.5 * (arc.T_lo + arc.T_hi)) if o.admissible]
    assert bc.verify(orbit)["ok"]


def test_bad_input():
    model, contact = strip(mass="consistent")
    with pytest.raises(ValueError, match="mass='lumped'"):
        bc.reduce(model, contact, "massless", 4)
    model, contact = strip()
    with pytest.raises(ValueError, match="too large for method 'massless'"):
        bc.reduce(model, contact, "massless", model.n_dofs)


def test_massless_reduced_model_file_round_trip(exact, tmp_path):
    from bladecase.reduction import load_reduced, save_reduced

    model, contact, *_ = exact
    r = bc.reduce(model, contact, "massless", 5)
    save_reduced(r, tmp_path / "r.npz")
    back = load_reduced(tmp_path / "r.npz")
    assert type(back) is type(r) and back.system.kc == r.system.kc
    assert np.array_equal(back.system.S, r.system.S) and np.array_equal(back.closed_shape, r.closed_shape)
    q = np.linspace(-1, 3, back.n) * 1e-5
    assert np.array_equal(back.free_dofs(q), r.free_dofs(q))


def test_face_contact_is_one_constraint_whose_compliance_settles():
    """[contact] face: w = the mean normal displacement of a group's free nodes. Under refinement of the strip
    (h halved twice) its static compliance wᵀK⁻¹w changes by 0.25 % then 0.19 %, while a corner node's (a point
    load) grows by 17 % then 9 % (logarithmically in 2-D): asserted as < 0.3 % and > 5 %."""
    from scipy.sparse.linalg import spsolve

    face, node = [], []
    for nx, ny in ((21, 5), (41, 9), (81, 17)):
        model, _ = strip(nx, ny)
        model.mesh.groups["tip"] = np.flatnonzero(np.isclose(model.mesh.points[:, 0], 0.1))
        f = bc.Contact.face(model, "tip", (1.0, 0.0), 1e-4)
        assert len(f.nodes) == ny and float(f.w(model).sum()) == pytest.approx(1.0)
        K = model.K.tocsc()
        for c, out in ((f, face), (bc.Contact.nearest(model, (0.1, 0.02), (1.0, 0.0), 1e-4), node)):
            w = c.w(model)
            out.append(float(w @ spsolve(K, w)))
    face_change, node_change = np.abs(np.diff(face)) / face[1:], np.diff(node) / node[1:]
    assert np.all(face_change < 3e-3) and np.all(node_change > 0.05)


# ----------------------------------------------------------------------------- mass


@pytest.mark.parametrize("order", [1, 2])
def test_mass_moved_off_faces_keeps_total_and_centre(order):
    """A face at the end of the body cannot keep its centre of mass with one ring of neighbours (all on one side):
    the next ring takes part (a mass dipole). Total mass and first moments per direction to 1e-12, every other
    mass positive (here within 0.44 … 2.1 times its own, P1); the second moments are not kept but move little."""
    model, node = strip(order=order)
    m0, x, direction = model.M.diagonal(), model.dofs.coords[:, :2], model.dofs.direction
    for contact in [node, *faces(model)]:
        w = contact.w(model)
        masses = massless_masses(model, np.flatnonzero(w))
        assert np.all(masses[w != 0] == 0) and masses[w == 0].min() > 0
        assert 0.4 < (masses / m0)[w == 0].min() and (masses / m0)[w == 0].max() < 2.2
        for d in range(2):
            sel = direction == d
            assert masses[sel].sum() == pytest.approx(m0[sel].sum(), rel=1e-12)
            assert np.abs(masses[sel] @ x[sel] - m0[sel] @ x[sel]).max() <= 1e-12 * (m0[sel] @ np.abs(x[sel])).max()
            J0, J = m0[sel] @ x[sel] ** 2, masses[sel] @ x[sel] ** 2
            assert np.all(np.abs(J / J0 - 1) < 1e-3)  # rotary inertia: not kept, a mesh-scale change (≤ 0.04 %)


# ----------------------------------------------------------------------------- exact condensation


@pytest.mark.parametrize("face", [False, True])
def test_exact_model_is_condense_on_the_dense_matrices(face):
    """size=None: every interior dof, bladecase.nsm.condense of the same dense matrices (1e-10)."""
    model, contact = strip()
    if face:
        contact = bc.Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")
    w = contact.w(model)
    masses = massless_masses(model, np.flatnonzero(w))
    ex = condense(np.diag(masses), model.K.toarray(), w, contact.gap)
    r = bc.reduce(model, contact, "massless")  # size None
    assert isinstance(r, MasslessReducedModel) and r.size is None and r.n == ex.n == int(np.sum(w == 0))
    s = r.system
    assert np.array_equal(s.M, ex.M) and s.kc == pytest.approx(ex.kc, rel=1e-12)
    assert np.abs(s.S - ex.S).max() <= 1e-10 * np.abs(ex.S).max()
    assert np.abs(s.w - ex.w).max() <= 1e-10 * np.abs(ex.w).max()
    assert np.abs(r.basis.toarray() - ex.expand).max() <= 1e-10 * np.abs(ex.expand).max()
    for phase in ("open", "closed"):
        a, b = getattr(s, phase).omega, getattr(ex, phase).omega
        assert np.abs(a - b).max() <= 1e-10 * b.max()


# ----------------------------------------------------------------------------- reduction


def test_static_compliance_is_exact_for_faces_and_the_exact_model():
    model, node = strip()
    for contact in [node, *faces(model)[::2]]:
        full = compliance(model, contact)
        for size in (None, 1, 6):
            s = massless_model(model, contact, size).system
            assert 1 / s.kc + s.w @ np.linalg.solve(s.S, s.w) == pytest.approx(full, rel=1e-10)


def test_closed_phase_frequencies_converge_with_the_size(exact):
    """The open phase's lowest `size` frequencies are exact at any size (1e-10; modes of the massless structure,
    the dense path beyond half of them too); the closed phase's three lowest converge: relative errors
    6e-4, 7e-6, 1.4e-6, 1.1e-7, 2.5e-10 at sizes 4, 8, 16, 32, 150 (of 199) — asserted decreasing, < 1e-6 at 32."""
    model, contact, _, _, ex = exact
    errs = []
    for size in (4, 8, 16, 32, 150):
        s = massless_model(model, contact, size).system
        assert np.abs(s.open.omega[:size] / ex.open.omega[:size] - 1).max() < 1e-10
        errs.append(np.abs(s.closed.omega[:3] / ex.closed.omega[:3] - 1).max())
    assert np.all(np.diff(errs) < 0) and errs[3] < 1e-6 and errs[4] < 1e-9


def test_velocities_in_a_closed_phase_keep_the_contact_still(exact):
    """Closed: wᵀx = d and wᵀv = 0 on the free dofs (the contact dofs move with λ' = k_c ŵ_rᵀv)."""
    model, contact, w, _, _ = exact
    r = massless_model(model, contact, 8)
    s = r.system
    q = 3 * np.linalg.solve(s.S + s.kc * np.outer(s.w, s.w), s.kc * s.gap * s.w)
    v = np.linspace(-1, 1, s.n)
    assert w @ r.free_dofs(q) == pytest.approx(s.gap, rel=1e-10)
    assert abs(w @ r.free_velocities(q, v)) <= 1e-10 * np.abs(s.w * v).sum()
    assert np.array_equal(r.free_velocities(-q, v), r.basis @ v)  # open: V v
    both = r.free_velocities(np.c_[q, -q], np.c_[v, v])
    assert np.allclose(both[:, 1], r.basis @ v, rtol=0, atol=1e-14 * np.abs(both).max())
    assert abs(w @ both[:, 0]) <= 1e-10 * np.abs(s.w * v).sum()


def test_expanded_orbit_holds_the_contact_node_in_the_contact_phase():
    model, contact = strip()
    r = bc.reduce(model, contact, "massless", 6)
    T1 = 2 * np.pi / r.system.open.omega[0]
    (branch, *_) = bc.nonsmooth_mode(r.system, 1, (0.9 * T1, 1.01 * T1))
    arc = branch.arcs[0]
    (orbit, *_) = [o for o in branch.orbit_at(0.5 * (arc.T_lo + arc.T_hi)) if o.admissible]
    t = np.array([0.5 * orbit.contact_time, orbit.contact_time + 0.25 * (orbit.T - orbit.contact_time)])
    u, v = r.expand(orbit, t)
    nu = np.array(contact.normal)
    (un_closed, un_open), (vn_closed, _) = u[contact.node].T @ nu, v[contact.node].T @ nu
    assert un_closed == pytest.approx(contact.gap, rel=1e-10) and un_open < contact.gap
    assert abs(vn_closed) <= 1e-10 * np.abs(v).max()


# ----------------------------------------------------------------------------- which contact


def test_face_compliance_converges_in_2d_with_area_weights():
    """Strip, h halved twice (axial normal, the blade's radial direction): the area-weighted face's compliance
    changes by 0.082 % then 0.033 % (observed order 1.3); the mid-tip node's grows by 6.9 % then 6.6 % (a point
    load in 2-D: logarithmically, constant increments)."""
    face, node = [], []
    for nx, ny in ((21, 5), (41, 9), (81, 17)):
        model, _ = strip(nx, ny)
        face.append(compliance(model, bc.Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")))
        node.append(compliance(model, bc.Contact.nearest(model, (0.1, 0.01), (1.0, 0.0), 1e-4)))
    d_face, d_node = np.diff(face), np.diff(node)
    order = np.log2(d_face[0] / d_face[1])
    assert np.all(np.abs(d_face) / face[1:] < 1e-3) and 1.0 < order < 1.6
    assert np.all(d_node / node[1:] > 0.05) and 0.8 < d_node[1] / d_node[0] < 1.2


def test_point_contact_diverges_in_3d_and_a_face_converges():
    """P1 tetrahedral bar, h halved twice (216, 1200, 7776 dofs): the tip-centre node's compliance grows by 27 %
    then 36 % (increments doubling: ∝ 1/h, no limit), the area-weighted tip face's changes by 0.62 % then 0.28 %
    (observed order 1.1). The massless model of the face is exact in its static compliance."""
    face, node = [], []
    for k in (2, 4, 8):
        model = bar3(k)
        f = bc.Contact.face(model, "tip", (1.0, 0.0, 0.0), 1e-4, weights="area")
        assert sum(f.weights) == pytest.approx(1.0, rel=1e-12) and len(f.nodes) == (k + 1) ** 2
        face.append(compliance(model, f))
        node.append(compliance(model, bc.Contact.nearest(model, (0.04, 0.005, 0.005), (1.0, 0.0, 0.0), 1e-4)))
        if k == 4:
            s = massless_model(model, f, 6).system
            assert 1 / s.kc + s.w @ np.linalg.solve(s.S, s.w) == pytest.approx(face[-1], rel=1e-10)
    d_face, d_node = np.diff(face), np.diff(node)
    assert np.all(d_node / node[1:] > 0.25) and d_node[1] / d_node[0] > 1.8
    assert np.all(np.abs(d_face) / face[1:] < 1e-2) and np.log2(d_face[0] / d_face[1]) > 0.8


# ----------------------------------------------------------------------------- input


def test_more_bad_input():
    model, contact = strip()
    for size in (0, 2.5, "4"):
        with pytest.raises(ValueError, match="size must be an integer >= 1"):
            bc.reduce(model, contact, "massless", size)
    with pytest.raises(ValueError, match="contact node 0 is clamped"):
        massless_model(model, bc.Contact(0, (1.0, 0.0), 1e-4))
    with pytest.raises(ValueError, match="factor must be None or the factorisation"):
        massless_model(model, contact, 4, factor=spd_factor(model.K.copy(), "K"))
    with pytest.raises(ValueError, match="weights must be 'equal' or 'area', got 'tributary'"):
        bc.Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="tributary")
    with pytest.raises(ValueError, match="weights of a face contact"):
        bc.Contact(102, (1.0, 0.0), 1e-4, (100, 102), (0.5, -0.5))
    model.mesh.groups["one"] = np.array([104])
    with pytest.raises(ValueError, match="group 'one' holds no boundary facet"):
        bc.Contact.face(model, "one", (1.0, 0.0), 1e-4, weights="area")
    big, contact = strip(201, 11)  # 4400 free dofs
    with pytest.raises(ValueError, match="size=None condenses all 4399 interior dofs exactly.*give a size"):
        bc.reduce(big, contact, "massless")


def test_exact_model_and_area_face_file_round_trip(tmp_path):
    from bladecase.reduction import load_reduced, save_reduced

    model, _ = strip()
    contact = bc.Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")
    r = massless_model(model, contact)
    save_reduced(r, tmp_path / "r.npz")
    back = load_reduced(tmp_path / "r.npz")
    assert back.size is None and back.contact == contact and np.array_equal(back.contact.w(model), contact.w(model))
    q = np.linspace(-1, 3, back.n) * 1e-6
    assert np.array_equal(back.free_dofs(q), r.free_dofs(q))


def test_the_existing_methods_on_the_redistributed_mass():
    """massless-lanczos (shift-invert Lanczos of the massless structure from the attachment vector) keeps the static
    contact compliance exact like the massless Craig-Bampton; massless-modal (modes only) truncates it; both bases
    are M-orthonormal and their open-phase frequencies converge to the exact condensation's."""
    import scipy.linalg as sla
    from skfem import MeshTri

    from bladecase.fe import Mesh, assemble
    from bladecase.reduction import Contact, reduce

    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)})
    model = assemble(strip, "steel", order=1, thickness=0.002, mass="lumped")
    contact = Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)
    exact = reduce(model, contact, "massless", None)

    def compliance(r):
        s = r.system
        return 1 / s.kc + s.w @ np.linalg.solve(s.S, s.w)

    def freqs(r, k=2):
        return np.sqrt(sla.eigh(r.system.S, r.system.M, eigvals_only=True)[:k])

    errors = []
    for size in (2, 4, 8):
        kry, modal = reduce(model, contact, "massless-lanczos", size), reduce(model, contact, "massless-modal", size)
        assert (kry.method, kry.n, modal.method, modal.n) == ("massless-lanczos", size + 1, "massless-modal", size)
        assert compliance(kry) == pytest.approx(compliance(exact), rel=1e-10)
        assert 0 < 1 - compliance(modal) / compliance(exact) < 0.01  # 0.8 %, 0.4 %, 0.24 % (measured)
        for r in (kry, modal):
            assert np.allclose(r.system.M, np.eye(r.n), atol=1e-10)
        errors.append(abs(freqs(kry)[1] / freqs(exact)[1] - 1))
    # second open-phase frequency of the Krylov models: 1.1e-3 (2 steps), 2.1e-7 (4), round-off (8)
    assert errors[0] > 1e-4 and errors[1] < 1e-5 and errors[2] < 1e-9
