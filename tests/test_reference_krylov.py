"""The reference model as the Krylov extension of the model it checks (bladecase.reduction.extension).

Claims: the extension contains the model (to round-off) and is what the model's own Krylov sequence would have
grown into — the same space as a Lanczos model of 4 × the steps, for a Lanczos model; it reuses the model's
factorisation (one solve per added dof, none wasted on modes); an orbit's drift in it agrees with the drift in an
independent reference from its own eigen-solve; bad input is refused with a clear message.
"""

from __future__ import annotations

import numpy as np
import pytest
from _studies import ROOT
from skfem import MeshTri
from test_reference import MASSLESS_PLATE

from bladecase.fe import Mesh, assemble, stiffness_factor
from bladecase.reduction import Contact, krylov_extension, reduce
from bladecase.reduction.extension import extend_basis
from bladecase.study import stages
from bladecase.study.choose import choose_orbits
from bladecase.study.reference import REFERENCE_FACTOR, SURVIVAL_RTOL, check_in_reference, reference_model
from bladecase.study.schema import loads


def _strip(mass: str):
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 31), np.linspace(0, 0.02, 6))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)})
    model = assemble(mesh, "steel", order=1, thickness=0.002, mass=mass)
    return model, Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)


@pytest.fixture(scope="module")
def strip():
    model, contact = _strip("consistent")
    return model, contact, stiffness_factor(model)


def _gap(A: np.ndarray, B: np.ndarray, M) -> float:
    """Largest relative M-norm residual of A's columns projected on span B (0: span A ⊂ span B)."""
    MB = M @ B
    R = A - B @ np.linalg.solve(B.T @ MB, MB.T @ A)
    return float(np.sqrt(np.max(np.einsum("ij,ij->j", R, M @ R) / np.einsum("ij,ij->j", A, M @ A))))


class CountingFactor:
    """A factor that counts the right-hand sides it solves (the extension's cost in solves)."""

    def __init__(self, factor):
        self.factor, self.columns = factor, 0

    def solve(self, b):
        b = np.asarray(b)
        self.columns += 1 if b.ndim == 1 else b.shape[1]
        return self.factor.solve(b)


@pytest.mark.parametrize("method", ["modal", "lanczos-si", "lanczos", "craig-bampton"])
def test_the_extension_contains_the_model_and_is_m_orthonormal(strip, method):
    model, contact, factor = strip
    reduced = reduce(model, contact, method, 6, factor=factor)
    ext = krylov_extension(reduced, 4 * reduced.n, factor)
    Q = ext.basis
    assert ext.method == method + "+krylov" and ext.n == 4 * reduced.n
    assert np.abs(Q.T @ (model.M @ Q) - np.eye(ext.n)).max() < 1e-10
    assert _gap(np.asarray(reduced.basis), Q, model.M) < 1e-12
    # the linear frequencies of the model are bounded above by the extension's (Rayleigh–Ritz on a larger space)
    lam_r = np.sort(np.linalg.eigvals(np.linalg.solve(reduced.system.M, reduced.system.K)).real)
    lam_e = np.sort(np.linalg.eigvalsh(ext.system.K))[:reduced.n]
    assert np.all(lam_e <= lam_r * (1 + 1e-10))


def test_a_lanczos_model_is_extended_into_the_lanczos_model_of_four_times_the_steps(strip):
    """Shift-invert Lanczos continued: the extension of 6 steps to 24 dofs spans what 24 steps span (to 1e-7:
    the Krylov vectors of two orthogonalisations in floating point)."""
    model, contact, factor = strip
    ext = krylov_extension(reduce(model, contact, "lanczos-si", 6, factor=factor), 24, factor)
    lanczos24 = reduce(model, contact, "lanczos-si", 24, factor=factor)
    assert _gap(np.asarray(lanczos24.basis), ext.basis, model.M) < 1e-7
    assert _gap(ext.basis, np.asarray(lanczos24.basis), model.M) < 1e-7


def test_a_modal_model_gains_the_attachment_vector_and_its_krylov_sequence(strip):
    """Modes are invariant under K⁻¹M: the extension of 6 modes is the 6 modes plus the Krylov sequence of the
    attachment vector K⁻¹w — the static contact compliance wᵀK⁻¹w becomes exact (it is not in the modal model)."""
    model, contact, factor = strip
    modal = reduce(model, contact, "modal", 6, factor=factor)
    ext = krylov_extension(modal, 24, factor)
    w = contact.w(model)
    exact = float(w @ factor.solve(w))

    def compliance(r):
        return float(r.system.w @ np.linalg.solve(r.system.K, r.system.w))
    assert abs(compliance(modal) / exact - 1) > 1e-3
    assert abs(compliance(ext) / exact - 1) < 1e-10


@pytest.mark.parametrize("method, most", [("modal", 24 - 6 + 1), ("lanczos-si", 24 - 6 + 2),
                                          ("craig-bampton", 24 + 1)])
def test_the_extension_solves_once_per_added_dof(strip, method, most):
    """The cost in solves with the model's factorisation: one per added dof (+1 for the attachment vector, +1 for
    a Krylov model's frontier); the modes of a modal model are not solved again. Craig–Bampton's basis is not
    invariant: its first block is applied whole."""
    model, contact, factor = strip
    reduced = reduce(model, contact, method, 6, factor=factor)
    counting = CountingFactor(factor)
    from bladecase.reduction.extension import FRONTIER
    from bladecase.reduction.methods.common import constraint
    V = extend_basis(np.asarray(reduced.basis), counting.solve(constraint(model, contact)),
                     lambda X: counting.solve(model.M @ X), lambda X: model.M @ X, 24, FRONTIER.get(method))
    assert V.shape[1] == 24 and counting.columns <= most


def test_a_modal_model_is_extended_in_blocks_of_four_the_same_on_every_run(strip, monkeypatch):
    """A modal model's extension runs in blocks of 4 right-hand sides (the attachment vector's sequence and three
    seeded random directions smoothed twice), which a sparse Cholesky factor solves at about half the cost per
    column; the same basis on every run; a Krylov model (lanczos-si) continues its single sequence."""
    from bladecase.reduction.extension import WIDEN, WIDEN_SMOOTHING

    model, contact, factor = strip
    modal = reduce(model, contact, "modal", 6, factor=factor)
    lanczos = reduce(model, contact, "lanczos-si", 6, factor=factor)
    first = krylov_extension(modal, 28, factor)
    widths, inner = [], factor._solve

    def recording(b):
        widths.append(1 if b.ndim == 1 else b.shape[1])
        return inner(b)
    monkeypatch.setattr(factor, "_solve", recording)
    ext = krylov_extension(modal, 28, factor)
    first_blocks = 1 + WIDEN_SMOOTHING  # the attachment vector, the random directions smoothed
    assert WIDEN["modal"] == 3 and widths[:first_blocks] == [1, 3, 3] and set(widths[first_blocks:]) == {4}
    assert sum(widths) <= 28 - 6 + 1 + WIDEN_SMOOTHING * 3
    np.testing.assert_array_equal(first.basis, ext.basis)
    widths.clear()
    krylov_extension(lanczos, 24, factor)
    assert set(widths[1:]) == {1}


def test_a_massless_model_is_extended_in_its_interior(strip):
    """The massless model (lumped mass, contact dofs massless and slaved): its extension keeps the contact's
    stiffness k_c and the contact rows slaved, contains the model, and is the massless-lanczos model of the same
    dofs when extending a massless-lanczos model."""
    model, contact = _strip("lumped")
    factor = stiffness_factor(model)
    reduced = reduce(model, contact, "massless", 6, factor=factor)
    ext = krylov_extension(reduced, 28, factor)
    assert ext.method == "massless+krylov" and ext.n == 28 and ext.system.kc == reduced.system.kc
    M = ext.mass_matrix
    assert _gap(np.asarray(reduced.basis), ext.basis, M) < 1e-12
    c = np.flatnonzero(contact.w(model))
    open_state = ext.free_dofs(np.zeros(ext.n))  # the zero state: nothing on the contact
    assert np.all(open_state[c] == 0.0)
    krylov = reduce(model, contact, "massless-lanczos", 6, factor=factor)  # 7 dofs: K⁻¹w and 6 steps
    ext = krylov_extension(krylov, 28, factor)
    longer = reduce(model, contact, "massless-lanczos", 27, factor=factor)
    assert _gap(np.asarray(longer.basis), ext.basis, M) < 1e-7


def test_bad_input_is_refused(strip):
    model, contact, factor = strip
    reduced = reduce(model, contact, "modal", 6, factor=factor)
    with pytest.raises(ValueError, match=r"count .*at least the model's 6 dofs"):
        krylov_extension(reduced, 3, factor)
    with pytest.raises(ValueError, match="nothing to extend"):
        krylov_extension(reduce(model, contact, "full", None), 400)
    with pytest.raises(ValueError, match="factor must be None or the factorisation"):
        krylov_extension(reduced, 24, stiffness_factor(_strip("consistent")[0]))


@pytest.fixture(scope="module")
def massless_plate():
    st = loads(MASSLESS_PLATE, base=ROOT)
    model = stages.build_model(st, stages.build_mesh(st))
    contact = stages.build_contact(st, model)
    factor = stiffness_factor(model)
    reduced = stages.build_reduced(st, model, contact, factor=factor)
    unit, _ = stages.period_unit(st, reduced.system)
    chosen = choose_orbits(st, stages.search(st, reduced.system), unit)
    return model, contact, factor, reduced, [c.orbit for c in chosen]


def test_an_orbit_drifts_alike_in_the_krylov_and_in_an_independent_reference(massless_plate):
    """The massless plate's chosen orbits (11-dof model): drift in the 44-dof Krylov extension and in the 81-dof
    massless model from its own eigen-solve (8 × the size) agree within a factor 2 (measured: 2.7e-3 / 2.6e-3 and
    4.3e-5 / 5.7e-5); both survive, with one contact phase."""
    model, contact, factor, reduced, orbits = massless_plate
    krylov = reference_model(model, contact, reduced, factor)
    independent = reduce(model, contact, "massless", 8 * reduced.size, factor=factor)
    assert krylov.n == REFERENCE_FACTOR * reduced.n
    assert orbits
    for orbit in orbits:
        a, b = (check_in_reference(orbit, reduced, r) for r in (krylov, independent))
        assert a["survives"] and b["survives"] and a["contacts"] == b["contacts"] == 1
        assert 0.5 < a["drift"] / b["drift"] < 2.0 and a["drift"] < SURVIVAL_RTOL


def test_a_massless_model_from_the_block_lanczos_lends_its_krylov_space_to_the_reference(massless_plate, monkeypatch):
    """When the block Lanczos found the massless modes (large models; forced here on the plate), the Ritz vectors of
    the rest of its Krylov space stand for the random directions: the reference costs only the contact's own
    sequence (one solve per quarter of the new dofs, single right-hand sides), contains the model, and the orbits
    drift in it as in the independent 81-dof reference (measured: 2.50e-3 / 2.58e-3 and 4.25e-5 / 5.71e-5)."""
    from bladecase import linalg

    model, contact, factor, _, _ = massless_plate
    monkeypatch.setattr(linalg, "BLOCK_MIN_DOFS", 0)
    st = loads(MASSLESS_PLATE, base=ROOT)
    reduced = stages.build_reduced(st, model, contact, factor=factor)
    m_i = reduced.masses[reduced.masses > 0]
    V_i, spare = np.asarray(reduced.basis)[reduced.masses > 0], reduced.spare
    assert spare is not None and spare.shape[1] >= 3 * reduced.n
    assert np.abs(spare.T @ (m_i[:, None] * spare) - np.eye(spare.shape[1])).max() < 1e-8
    assert np.abs(V_i[:, :-1].T @ (m_i[:, None] * spare)).max() < 1e-8  # beyond the modes
    widths, inner = [], factor._solve

    def recording(b):
        widths.append(1 if b.ndim == 1 else b.shape[1])
        return inner(b)
    monkeypatch.setattr(factor, "_solve", recording)
    krylov = reference_model(model, contact, reduced, factor)
    monkeypatch.setattr(factor, "_solve", inner)
    assert krylov.n == REFERENCE_FACTOR * reduced.n and set(widths) == {1}
    assert len(widths) == 1 + (krylov.n - reduced.n) // 4  # the attachment vector, then its sequence
    assert _gap(np.asarray(reduced.basis), krylov.basis, krylov.mass_matrix) < 1e-12
    unit, _ = stages.period_unit(st, reduced.system)
    orbits = [c.orbit for c in choose_orbits(st, stages.search(st, reduced.system), unit)]
    independent = reduce(model, contact, "massless", 8 * reduced.size, factor=factor)
    assert orbits
    for orbit in orbits:
        a, b = (check_in_reference(orbit, reduced, r) for r in (krylov, independent))
        assert a["survives"] and b["survives"] and a["contacts"] == b["contacts"] == 1
        assert 0.5 < a["drift"] / b["drift"] < 2.0
