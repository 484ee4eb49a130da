"""A casing of revolution under a face contact: each node's clearance and normal from the casing (closed forms for
a cylinder and a cone), the face's constraint as their weighted mean, stage files keep them, the study keys."""

from __future__ import annotations

import numpy as np
import pytest
from _studies import PLATE, ROOT
from skfem import MeshTri

from bladecase.fe import Mesh, assemble
from bladecase.fe.rotation import RotationAxis
from bladecase.reduction import Contact, load_reduced, reduce, save_reduced
from bladecase.reduction.casing import Casing
from bladecase.study.schema import loads

Z = RotationAxis((0, 0, 0), (0, 0, 1))


def test_cylinder_and_cone_clearances_in_closed_form():
    rng = np.random.default_rng(3)
    theta, s = rng.uniform(0, 2 * np.pi, 20), rng.uniform(-0.05, 0.05, 20)
    r = rng.uniform(0.28, 0.2995, 20)
    axis = RotationAxis((0.1, 0.0, 0.0), (1, 0, 0))
    points = np.c_[0.1 + s, r * np.cos(theta), r * np.sin(theta)]
    d, n = Casing(axis, radius=0.3).clearances(points)
    assert d == pytest.approx(0.3 - r, abs=1e-15)
    assert n == pytest.approx(np.c_[np.zeros(20), np.cos(theta), np.sin(theta)], abs=1e-15)
    # a cone R(s) = 0.3 - 0.2 s: the normal leans back by atan(0.2), the clearance is measured along it
    d, n = Casing(axis, radii=((0.0, 0.3), (0.1, 0.28))).clearances(points)
    k = np.hypot(1, 0.2)
    assert d == pytest.approx((0.3 - 0.2 * s - r) / k, abs=1e-15)
    assert n[:, 0] == pytest.approx(np.full(20, 0.2 / k)) and np.linalg.norm(n, axis=1) == pytest.approx(np.ones(20))


@pytest.fixture(scope="module")
def strip():
    """A 2-D strip radial along +y from r = 0.2 to 0.3 m, 20 mm wide, on an axis along z through the origin."""
    t = MeshTri.init_tensor(np.linspace(-0.01, 0.01, 5), np.linspace(0.2, 0.3, 21))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 1] == 0.2),
                                                       "tip": np.flatnonzero(p[:, 1] == 0.3)})
    return assemble(mesh, "steel", order=1, thickness=0.002)


def test_the_face_constraint_is_the_weighted_mean_of_the_nodes(strip):
    casing = Casing(Z, radius=0.3002)
    c = Contact.on_casing(strip, casing, "tip", weights="area")
    x = strip.mesh.points[list(c.nodes)]
    r = np.hypot(x[:, 0], x[:, 1])
    assert np.array(c.clearances) == pytest.approx(0.3002 - r, abs=1e-15)
    omega = np.array(c.weights)
    assert c.gap == pytest.approx(omega @ (0.3002 - r), rel=1e-14)
    # wᵀu of a displacement δ along each node's own normal is δ Σω: every node seen along its casing normal
    u = np.zeros(strip.n_dofs)
    for k, nu in zip(c.nodes, c.normals):
        idx = np.flatnonzero(strip.dofs.node == k)
        u[idx] = 1e-5 * np.asarray(nu)[strip.dofs.direction[idx]]
    assert c.w(strip) @ u == pytest.approx(1e-5 * omega.sum(), rel=1e-12)
    assert c.node_normal_map(strip) @ u == pytest.approx(np.full(len(c.nodes), 1e-5), rel=1e-12)
    hot = c.closed_by(strip, u)
    assert hot.gap == pytest.approx(c.gap - 1e-5 * omega.sum(), rel=1e-12)
    assert np.array(hot.clearances) == pytest.approx(np.array(c.clearances) - 1e-5, abs=1e-18)
    # the corner at (0.01, 0.3): r = 0.300167 m, 0.27 mm beyond a 0.2999 m casing
    with pytest.raises(ValueError, match=r"touches or crosses the casing at rest \(clearance -0.0002666 m\)"):
        Contact.on_casing(strip, Casing(Z, radius=0.2999), "tip")


def test_stage_files_keep_each_nodes_normal_and_clearance(strip, tmp_path):
    c = Contact.on_casing(strip, Casing(Z, radius=0.3002), "tip")
    reduced = reduce(strip, c, "modal", 4)
    save_reduced(reduced, tmp_path / "r.npz")
    back = load_reduced(tmp_path / "r.npz").contact
    assert np.array(back.normals) == pytest.approx(np.array(c.normals), abs=0)
    assert back.clearances == pytest.approx(c.clearances, abs=0)
    assert back.w(strip) == pytest.approx(c.w(strip), abs=0)


def _study(extra: str, clearance: bool = False):
    face = 'face = "tip"\n'
    text = PLATE.replace("clearance = 1e-4\n", "clearance = 1e-4\n" + face if clearance else face)
    return loads(text + extra, base=ROOT)


def test_a_study_on_a_casing(tmp_path):
    """meshes/plate.vtu: radial along +y from 0 to 0.1 m; on an axis along z 0.3 m below its root, a casing of
    radius 0.4002 m: the summary's clearance is the area-weighted mean of 0.4002 − r over the tip's nodes."""
    from bladecase.study import run

    study = _study("[casing]\nradius = 0.4002\naxis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}\n"
                   "[output]\nformats = []\nreference = false\nanimate = 0\n")
    summary = run(study, tmp_path / "out", progress=False).summary
    from bladecase.fe import load_mesh

    mesh = load_mesh(ROOT / "meshes" / "plate.vtu")
    nodes = summary["contact"]["face_nodes"]
    r = np.hypot(mesh.points[nodes, 0], mesh.points[nodes, 1] + 0.3)
    assert 0 < summary["contact"]["clearance_m"] < 0.4002 - r.min()
    assert summary["contact"]["clearance_m"] > 0.4002 - r.max()


@pytest.mark.parametrize("extra, clearance, words", [
    ("[casing]\nradius = 0.4\naxis = {direction = [0, 0, 1]}\n", True,
     r"\[contact\] clearance: with a \[casing\], each node's clearance comes from the casing"),
    ("[casing]\nradius = 0.4\n", False, r"\[casing\] axis: required \(or \[rotation\] axis\)"),
    ("[casing]\nradius = 0.4\nradii = [[0, 0.4], [0.1, 0.39]]\naxis = {direction = [0, 0, 1]}\n", False,
     r"\[casing\] radii: give radius \(a cylinder\) or radii \(a cone\), not both"),
    ("[casing]\nradii = [[0, 0.4], [0, 0.39]]\naxis = {direction = [0, 0, 1]}\n", False,
     r"\[casing\] radii: must be \[\[s1, R1\], \[s2, R2\]\]: two distinct axial stations"),
    ("", False, r"\[contact\] clearance: required \(m\), or a \[casing\]"),
])
def test_bad_casing_keys(extra, clearance, words):
    with pytest.raises(ValueError, match=words):
        _study(extra, clearance)
