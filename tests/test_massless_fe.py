"""The massless contact model of a finite-element structure (bladecase.reduction.methods.massless): mass moved
off the contact dofs, static condensation per phase, reduction by the massless structure's modes plus the
contact's attachment vector; checked against the exact dense condensation (bladecase.nsm.condense)."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTri

import bladecase as bc
from bladecase.nsm import MasslessSystem, condense
from bladecase.reduction.methods.massless import massless_masses


def strip(nx: int = 21, ny: int = 5, mass: str = "lumped"):
    t = MeshTri.init_tensor(np.linspace(0, 0.1, nx), np.linspace(0, 0.02, ny))
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = bc.Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    model = bc.assemble(mesh, "steel", order=1, thickness=0.002, mass=mass)
    return model, bc.Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)


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
