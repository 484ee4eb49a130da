"""The reduced annulus of an FE bladed disk (hexahedral sector, 6 blades, each blade's tip face its contact)
against the annulus assembled as one mesh (scipy's rotations, nodes merged; ``tests/_cyclic_util.py``) with the
same massless masses: the massless modes (sparse shift-invert on the whole disk) and the contacts' static and
residual compliances (a sparse solve on the whole disk)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from _cyclic_util import annulus, hex_sector
from scipy.sparse.linalg import LinearOperator, eigsh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from bladecase.fe import assemble
from bladecase.fe.cyclic import fe_sector
from bladecase.fe.rotation import RotationAxis
from bladecase.linalg import spd_factor
from bladecase.reduction import Contact
from bladecase.reduction.disk import disk_model, massless_sector

AXIS = RotationAxis((0, 0, 0), (1, 0, 0))
N = 6


@pytest.fixture(scope="module")
def disk():
    mesh = hex_sector(N, nt=4, band=(1, 3))
    model = assemble(mesh, "steel", order=1, clamp="hub", mass="lumped")
    sector = fe_sector(model, N, AXIS)
    out = {}
    for nodes in (False, True):
        contact = Contact.face(model, "tip", (0.0, 0.0, 1.0), 2e-4, weights="area")
        ms, W, gap = massless_sector(model, sector, contact, nodes=nodes)
        out[nodes] = (ms, W, gap)
    ring = assemble(annulus(mesh, N), "steel", order=1, clamp="hub", mass="lumped")
    return model, out, ring


def _on_annulus(model, ring, delta, W):
    """The sector's mass change (``delta`` per dof: the tip's mass moved) and contact columns placed on every
    sector of the assembled annulus: sector ``j``'s node at the rotated point, its 3 × 3 mass block ``R diag(δ) Rᵀ``
    and contact vectors ``R w`` (``R`` scipy's rotation)."""
    tree = cKDTree(ring.dofs.coords)
    m = W.shape[1]
    rows, cols, vals = [], [], []
    Wa = np.zeros((ring.n_dofs, N * m))
    touched = np.flatnonzero((delta != 0) | np.any(W != 0, axis=1))
    points = np.unique(model.dofs.coords[touched], axis=0)
    for j in range(N):
        R = Rotation.from_rotvec([2 * np.pi * j / N, 0, 0]).as_matrix()
        for p in points:
            here = np.flatnonzero(np.all(model.dofs.coords == p, axis=1))
            D, Wp = np.zeros(3), np.zeros((3, m))
            D[model.dofs.direction[here]] = delta[here]
            Wp[model.dofs.direction[here]] = W[here]
            there = np.array(tree.query_ball_point(R @ p, 1e-9))
            assert there.size == 3
            there = there[np.argsort(ring.dofs.direction[there])]
            B = R @ np.diag(D) @ R.T
            rows += np.repeat(there, 3).tolist()
            cols += np.tile(there, 3).tolist()
            vals += B.ravel().tolist()
            Wa[there, j * m:(j + 1) * m] += R @ Wp
    dM = sp.csr_array((vals, (rows, cols)), shape=(ring.n_dofs, ring.n_dofs))
    return dM, Wa


@pytest.mark.parametrize("nodes", [False, True])
def test_the_fe_disk_model_equals_the_assembled_annulus(disk, nodes):
    model, out, ring = disk
    ms, W, gap = out[nodes]
    probe = disk_model(ms, W, gap, count=8)
    cutoff = min(np.sqrt(d.lam[-1]) for d in probe.diameters.values()) / (2 * np.pi) * 0.999
    red = disk_model(ms, W, gap, count=8, cutoff=cutoff, diameters=probe.diameters)
    s = red.system
    # the assembled annulus with the same massless masses (the tip's mass moved within each blade)
    dM, Wa = _on_annulus(model, ring, ms.M.diagonal() - model.M.diagonal(), W)
    Ma = sp.csr_array(ring.M + dM)
    Ma = 0.5 * (Ma + Ma.T)
    assert np.abs(Ma @ Wa).max() < 1e-12 * Ma.max()  # the contacts' directions massless on the annulus too
    K = sp.csc_array(ring.K)
    f = spd_factor(K, "K")
    lam, _ = eigsh(K, k=s.n, M=Ma, sigma=0.0, OPinv=LinearOperator(K.shape, f.solve),
                   which="LM")
    lam = np.sort(lam)
    assert np.allclose(np.sort(np.diag(s.S)), lam, rtol=1e-10, atol=0), np.abs(np.sort(np.diag(s.S)) / lam - 1).max()
    X = f.solve(Wa)
    C = Wa.T @ X
    assert np.abs(red.compliance - C).max() <= 1e-11 * np.abs(C).max()
    # the residual: the static compliance less the kept modes' (the annulus modes: eigenvectors of any basis)
    _, V = eigsh(K, k=s.n, M=Ma, sigma=0.0, OPinv=LinearOperator(K.shape, f.solve), which="LM")
    V = V / np.sqrt(np.einsum("ij,ij->j", V, Ma @ V))
    lam_v = np.einsum("ij,ij->j", V, K @ V)
    WV = Wa.T @ V
    H = C - (WV / lam_v) @ WV.T
    assert np.abs(s.flexibility - H).max() <= 1e-10 * np.abs(H).max()
