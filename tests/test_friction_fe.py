"""Friction on a finite-element model (bladecase.reduction.nodal_friction): the reduced model's tangential coupling
and compliances give the full model's static compliance; a rub of a clamped strip with friction closes its energy
balance and reproduces the model without friction when μ = 0."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import MeshTri

from bladecase.fe import Mesh, assemble
from bladecase.nsm import Damping
from bladecase.nsm.massless.friction_rub import friction_rub
from bladecase.reduction import Contact
from bladecase.reduction.nodal_friction import nodal_friction, tangential_map
from bladecase.reduction.nodes import nodal_model

ORIGIN, AXIS = (-0.3, 0.0), (0.0, 0.0, 1.0)


@pytest.fixture(scope="module")
def strip():
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
                                                       "tip": np.flatnonzero(p[:, 0] == 0.1)})
    model = assemble(mesh, "steel", order=1, thickness=0.002, mass="lumped")
    return model, Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")


@pytest.mark.parametrize("residual", [False, True], ids=["attachment", "residual"])
def test_static_compliance_of_the_nodes_is_the_full_models(strip, residual):
    """Reduced: ``C_nt + W_rᵀS_r⁻¹T_r`` (and, residual, ``C_tt + T_rᵀS_r⁻¹T_r``) against the full model's
    ``W_fullᵀK⁻¹T_full`` (``T_fullᵀK⁻¹T_full``) by a sparse direct solve of its own."""
    model, contact = strip
    reduced = nodal_model(model, contact, 6, residual=residual)
    f = nodal_friction(reduced, 0.15, ORIGIN, AXIS)
    s = reduced.system
    T_full, radius = tangential_map(reduced, ORIGIN, AXIS)
    W_full = sp.csr_array(reduced.normal_map).T.toarray()
    KinvT = spla.spsolve(sp.csc_matrix(model.K), T_full)
    full_nt, full_tt = W_full.T @ KinvT, T_full.T @ KinvT
    red_nt = f.C_nt + s.W.T @ np.linalg.solve(s.S, f.T)
    red_tt = f.C_tt + f.T.T @ np.linalg.solve(s.S, f.T)
    assert np.abs(red_nt - full_nt).max() < 1e-9 * np.abs(full_nt).max()
    if residual:
        assert np.abs(red_tt - full_tt).max() < 1e-9 * np.abs(full_tt).max()
    # the sliding direction: perpendicular to the axis and to each node's radius, against the blade's turning
    pts = model.mesh.points[list(contact.nodes)][:, :2] - np.array(ORIGIN)
    for j, k in enumerate(contact.nodes):
        idx = np.flatnonzero(model.dofs.node == k)
        t = np.zeros(2)
        t[model.dofs.direction[idx]] = T_full[idx, j]
        assert abs(t @ pts[j]) < 1e-15 and np.linalg.norm(t) == pytest.approx(1.0)
        assert pts[j, 0] * t[1] - pts[j, 1] * t[0] < 0  # (r × t)·axis < 0: the casing moves back
    assert radius == pytest.approx(np.linalg.norm(pts, axis=1), rel=1e-15)
    with pytest.raises(ValueError, match="turning must be"):
        tangential_map(reduced, ORIGIN, AXIS, turning=2)


def test_rub_of_a_strip_with_friction(strip):
    model, contact = strip
    reduced = nodal_model(model, contact, 4, casing=2e6, residual=True)
    s = reduced.system
    f1 = s.modes[0][0]
    speed = f1 / 3 * 1.02  # 3 lobes near the crossing with mode 1
    angles = np.linspace(0.0, 0.05, s.m)
    args = (s, None, speed, 3, 2e-4, angles, Damping(zeta=0.01), 4)
    fr = nodal_friction(reduced, 0.15, ORIGIN, AXIS)
    r = friction_rub(s, fr, *args[2:])
    off = friction_rub(*args)
    e = r.energy[-1]
    assert r.worst_relative < 1e-10 and abs(e.friction) > 1e-3 * abs(e.casing) and r.sliding is not None
    assert off.worst_relative < 1e-10 and all(x.friction == 0 for x in off.energy)
    assert r.trajectory.switch_times.size > 8
