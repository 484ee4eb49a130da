"""Load vectors on FE models (bladecase.reduction.loads): totals, symmetry, engine order, Galerkin projection."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from skfem import MeshTet, MeshTri

from bladecase.fe import Mesh, assemble
from bladecase.reduction import Contact, reduce
from bladecase.reduction.loads import engine_order_load, nodal_load, pressure_load, project_load

L, H, B, THICK = 0.1, 0.02, 0.01, 0.002


def strip(nx: int = 21, ny: int = 5) -> Mesh:
    t = MeshTri.init_tensor(np.linspace(0, L, nx), np.linspace(0, H, ny))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    groups = {"root": np.flatnonzero(p[:, 0] == 0), "tip": np.flatnonzero(np.isclose(p[:, 0], L)),
              "bottom": np.flatnonzero(p[:, 1] == 0)}
    return Mesh(p, {"triangle": t.t.T}, dim=2, groups=groups)


def box() -> Mesh:
    t = MeshTet.init_tensor(np.linspace(0, L, 6), np.linspace(0, H, 3), np.linspace(0, B, 3))
    p = t.p.T
    groups = {"root": np.flatnonzero(p[:, 0] == 0), "tip": np.flatnonzero(np.isclose(p[:, 0], L)),
              "side": np.flatnonzero(p[:, 1] == 0)}
    return Mesh(p, {"tetra": t.t.T}, dim=3, groups=groups)


@pytest.fixture(scope="module")
def strip_model():
    return assemble(strip(), "steel", order=1, thickness=THICK, mass="lumped")


def _sum(model, f, c: int) -> float:
    return float(f[model.dofs.direction == c].sum())


@pytest.mark.parametrize("order", [1, 2])
def test_pressure_totals_2d(order):
    """Total force of a pressure = −p × area × outward normal, to 1e-10 (tip: n = +x; bottom: n = −y)."""
    model = assemble(strip(), "steel", order=order, thickness=THICK)
    p = 2.5e5
    f = pressure_load(model, "tip", p)
    area = H * THICK
    assert abs(_sum(model, f, 0) - (-p * area)) <= 1e-10 * p * area
    assert abs(_sum(model, f, 1)) <= 1e-10 * p * area
    g = pressure_load(model, "bottom", p)       # the clamped root corner's share is a reaction: dropped
    bottom_free = L * THICK - (L / 20 / (2 if order == 1 else 6)) * THICK
    assert abs(_sum(model, g, 1) - p * bottom_free) <= 1e-10 * p * L * THICK
    assert abs(_sum(model, g, 0)) <= 1e-10 * p * L * THICK


def test_pressure_p1_consistent_and_symmetric(strip_model):
    """P1, uniform edges of length h: end nodes p·h·t/2, inner nodes p·h·t; mirror-symmetric about mid-height."""
    model, p = strip_model, 1e5
    f = pressure_load(model, "tip", p)
    tip = np.sort(model.mesh.group("tip"))
    fx = f[model.dof_of(tip, 0)]
    h = H / 4
    expect = p * h * THICK * np.array([0.5, 1, 1, 1, 0.5])
    order = np.argsort(model.mesh.points[tip, 1])
    assert np.allclose(-fx[order], expect, rtol=1e-12, atol=0)
    assert np.allclose(fx[order], fx[order][::-1], rtol=1e-13, atol=0)


@pytest.mark.parametrize("order", [1, 2])
def test_pressure_totals_3d(order):
    model = assemble(box(), "steel", order=order)
    p = 3e4
    f = pressure_load(model, "tip", p)
    area = H * B
    assert abs(_sum(model, f, 0) + p * area) <= 1e-10 * p * area
    assert max(abs(_sum(model, f, 1)), abs(_sum(model, f, 2))) <= 1e-10 * p * area
    g = pressure_load(model, "side", p)           # y = 0: outward normal −y, force +y; root edge clamped
    assert _sum(model, g, 1) > 0
    assert abs(_sum(model, g, 0)) <= 1e-10 * p * L * B
    # the free part of the side face: all of it minus the root edge's share (every facet integrates exactly)
    full = pressure_load(assemble(box(), "steel", order=order, clamp=None), "side", p)
    assert abs(float(full[1::3].sum()) - p * L * B) <= 1e-10 * p * L * B


def test_pressure_errors(strip_model):
    mesh = strip_model.mesh
    corner = Mesh(mesh.points, mesh.cells, dim=2, groups={**mesh.groups, "corner": mesh.group("tip")[:1]})
    with pytest.raises(ValueError, match="no boundary facet"):
        pressure_load(dataclasses.replace(strip_model, mesh=corner), "corner", 1.0)
    with pytest.raises(ValueError, match="no group"):
        pressure_load(strip_model, "nope", 1.0)
    with pytest.raises(ValueError, match="pressure must be a finite number"):
        pressure_load(strip_model, "tip", float("nan"))


def test_nodal_load(strip_model):
    model = strip_model
    tip = model.mesh.group("tip")
    f = nodal_load(model, "tip", (3.0, 4.0), 10.0)
    assert abs(_sum(model, f, 0) - 6.0) <= 1e-13 and abs(_sum(model, f, 1) - 8.0) <= 1e-13
    assert np.allclose(f[model.dof_of(tip, 1)], 8.0 / tip.size, rtol=1e-14)
    assert np.count_nonzero(f) == 2 * tip.size
    g = nodal_load(model, int(tip[0]), (0.0, 1.0, 0.0), -2.0)
    assert g[model.dof_of(int(tip[0]), 1)] == -2.0 and np.count_nonzero(g) == 1
    with pytest.raises(ValueError, match="is clamped"):
        nodal_load(model, int(model.mesh.group("root")[0]), (0, 1), 1.0)
    with pytest.raises(ValueError, match="direction must be"):
        nodal_load(model, "tip", (0, 0), 1.0)


def test_engine_order():
    eo = engine_order_load(np.ones(4), 5, blades=20, blade=3)
    assert abs(eo.phase - np.mod(2 * np.pi * 5 * 3 / 20, 2 * np.pi)) <= 1e-15
    assert engine_order_load(np.ones(4), 5).phase == 0.0
    assert abs(float(eo.speed(eo.frequency(7200.0))) - 7200.0) <= 1e-9
    assert float(eo.frequency(7200.0)) == 600.0
    for bad in (dict(engine_order=0), dict(engine_order=2, blades=4, blade=4), dict(engine_order=1.5)):
        with pytest.raises(ValueError):
            engine_order_load(np.ones(4), **bad)


def _static(model, f):
    return spla.spsolve(model.K.tocsc(), f)


def _reduced_static(r, f):
    K = r.system.S if hasattr(r.system, "S") else r.system.K
    K = K.toarray() if hasattr(K, "toarray") else np.asarray(K)
    return r.free_dofs(np.linalg.solve(K, project_load(r, f)))


@pytest.fixture(scope="module")
def contact(strip_model):
    return Contact.nearest(strip_model, (L, H), normal=(0.0, 1.0), gap=1e-4)


@pytest.mark.parametrize("method, size", [("full", None), ("modal", 8), ("lanczos", 8), ("lanczos-si", 8),
                                          ("craig-bampton", 8), ("massless", 8)])
def test_projection_is_work_consistent(strip_model, contact, method, size):
    r = reduce(strip_model, contact, method, size)
    rng = np.random.default_rng(7)
    f, q = rng.standard_normal(strip_model.n_dofs), rng.standard_normal(r.n)
    fr = project_load(r, f)
    assert fr.shape == (r.n,)
    assert abs(fr @ q - f @ np.asarray(r.basis @ q)) <= 1e-12 * np.abs(f).sum() * np.abs(r.basis @ q).max()


def test_static_response_full_and_contact_exact(strip_model, contact):
    """K_r⁻¹f_r expanded = K⁻¹f: every dof for 'full'; at the contact for a load on the contact along the normal
    for the methods whose basis holds K⁻¹w (Lanczos about 0, Craig–Bampton)."""
    model = strip_model
    w = contact.w(model)
    pres = pressure_load(model, "tip", 1e5)
    for f in (pres, w):
        x, xr = _static(model, f), _reduced_static(reduce(model, contact, "full"), f)
        assert np.linalg.norm(xr - x) <= 1e-9 * np.linalg.norm(x)
    x = _static(model, w)
    for method in ("lanczos-si", "craig-bampton"):
        xr = _reduced_static(reduce(model, contact, method, 8), w)
        assert abs(w @ xr / (w @ x) - 1) <= 1e-9, method


def test_static_response_modal_converges(strip_model, contact):
    model = strip_model
    f = pressure_load(model, "bottom", 1e5)        # bending: the tip deflects along the contact normal
    x = _static(model, f)
    w = contact.w(model)
    err = [abs(w @ _reduced_static(reduce(model, contact, "modal", n), f) / (w @ x) - 1) for n in (4, 16, 40)]
    assert err[2] < err[1] < err[0]
    assert err[2] < 0.02


def test_static_response_massless_condensation(strip_model, contact):
    """The exact massless condensation (V_i = I) carries a load on interior dofs exactly (the load on the massless
    contact dofs is the one thing its open-phase basis does not carry)."""
    model = strip_model
    f = nodal_load(model, int(np.argmin(np.linalg.norm(model.mesh.points - [L / 2, H, 0], axis=1))), (0, 1), 1.0)
    assert not np.any(f[contact.dofs(model)])
    x = _static(model, f)
    xr = _reduced_static(reduce(model, contact, "massless", None), f)
    assert np.linalg.norm(xr - x) <= 1e-9 * np.linalg.norm(x)


def test_project_load_errors(strip_model, contact):
    r = reduce(strip_model, contact, "modal", 4)
    with pytest.raises(ValueError, match="free dofs"):
        project_load(r, np.ones(3))
    with pytest.raises(ValueError, match="ReducedModel"):
        project_load(object(), np.ones(3))
