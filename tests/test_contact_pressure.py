"""Contact pressure, total force, loaded area and where the load sits, with every tip node a contact.

A node's force falls like its tributary area as the tip mesh is refined; what converges is the pressure (force over
area), the total force (the sum over the nodes) and the loaded area. The references here are independent of the
code under test: a linear displacement field that a P1 mesh holds exactly (its traction on the tip is a known
uniform pressure), and dense samples of the exact orbits.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from skfem import MeshTri

from bladecase.fe import Material, Mesh, assemble
from bladecase.nsm.damping import Damping
from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.nsm.massless.nodes import NodalSystem, simulate_nodes
from bladecase.nsm.massless.rub import rub_response
from bladecase.reduction import Contact
from bladecase.reduction.contact import tributary_areas
from bladecase.reduction.nodes import chord_positions, contact_load, contact_pressure, nodal_model

#: Casing stiffness per unit area (N/m³): each tip node gets ``K_A · A_j``.
K_A = 2e9


def strip(ys, material="steel"):
    """A plane-stress strip 100 mm long, 2 mm thick, across ``ys`` (m) at its tip ``x = 0.1``, clamped at ``x = 0``
    (P1 triangles, 20 cells along)."""
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.asarray(ys, dtype=float))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
                                                       "tip": np.flatnonzero(np.isclose(p[:, 0], 0.1))})
    return assemble(mesh, material, order=1, thickness=0.002, mass="lumped")


def test_a_face_pressed_flat_has_one_pressure_on_nodes_of_unequal_area():
    """The strip (ν = 0, tip nodes 0, 2, 5, 11, 20 mm across: tributary areas 2, 5, 9, 15, 9 mm²) in the state
    ``u_x = c + εx``, ``u_y = 0`` (ε < 0) with its tip face flat on a rigid casing at ``c + εL``: a P1 mesh holds
    that linear field exactly, so the casing's traction on the tip is the uniform pressure ``p = −Eε`` (20 MPa) and
    each node's force is ``p·A_j``. The nodal model (the state as its one interior vector) gets the forces from the
    complementarity problem; their pressures are equal to 1e-9 (measured 2e-13), the forces are in the ratio of
    the areas."""
    E, eps, c = 200e9, -1e-4, 2e-4
    model = strip([0.0, 0.002, 0.005, 0.011, 0.02], Material(E=E, nu=0.0, rho=7850.0, name="ν = 0"))
    contact = Contact.face(model, "tip", (1.0, 0.0), c + eps * 0.1, weights="area")
    x = model.mesh.points[model.dofs.node, 0]
    u = np.where(model.dofs.direction == 0, c + eps * x, 0.0)
    moved = np.flatnonzero(np.asarray(abs(contact.node_normal_map(model)).sum(axis=0)).ravel())
    interior = np.setdiff1d(np.arange(model.n_dofs), moved)
    nodal = nodal_model(model, contact, 1, interior=u[interior][:, None])   # rigid casing: the contact's own
    force = nodal.system.forces(np.array([1.0]))
    np.testing.assert_allclose(nodal.areas * 1e6, [2.0, 5.0, 9.0, 15.0, 9.0], rtol=1e-12)
    pressure = contact_pressure(force, nodal.areas)
    np.testing.assert_allclose(pressure, -E * eps, rtol=1e-9)
    np.testing.assert_allclose(force / force[0], nodal.areas / nodal.areas[0], rtol=1e-9)
    assert np.ptp(force) > force.min()                       # the forces differ (40 to 300 N), the pressure does not
    load = nodal.contact_load(force)
    assert load["max_pressure_pa"] == pytest.approx(-E * eps, rel=1e-9)
    assert load["total_force_n"] == pytest.approx(-E * eps * nodal.areas.sum(), rel=1e-9)
    assert load["loaded_area_m2"] == pytest.approx(nodal.areas.sum(), rel=1e-12)
    assert load["centre"] == pytest.approx(0.5, abs=1e-9) and load["location"] == "mid-chord"   # a rectangle's middle


@pytest.fixture(scope="module")
def tilted():
    """The steel strip with 9 tip nodes (2.5 mm apart; areas 2.5 and 5 mm²) against a compliant casing of K_A per
    unit area whose clearance grows from 0.1 mm at ``y = 0`` by 4 µm per mm across the tip (and the mirror case): its
    first bending mode followed from grazing (the tip section turns, one end reaches the casing first) up to
    four times the grazing energy."""
    model = strip(np.linspace(0.0, 0.02, 9))
    face = Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")
    y = model.mesh.points[list(face.nodes), 1]
    out = {}
    for end, near in (("y = 0", 0.0), ("y = 20 mm", 0.02)):
        gaps = 1e-4 + 4e-3 * np.abs(y - near)
        contact = dataclasses.replace(face, normals=((1.0, 0.0),) * y.size, clearances=tuple(gaps))
        nodal = nodal_model(model, contact, 4, casing=K_A * tributary_areas(model, face.nodes), residual=True)
        grazing = nodal_family(nodal.system, 0, max_points=2).orbits[0].energy
        out[end] = nodal, nodal_family(nodal.system, 0, energy_max=4 * grazing), y
    return out


def test_pressure_times_area_is_the_total_force_at_every_instant(tilted):
    nodal, fam, _ = tilted["y = 0"]
    areas = nodal.areas
    checked = 0
    for o in fam.orbits[1:]:
        t = np.linspace(0.0, o.T, 2001)
        lam = o.forces(t)
        total = lam.sum(axis=0)
        p = contact_pressure(lam, areas)
        np.testing.assert_allclose((p * areas[:, None]).sum(axis=0), total, rtol=0, atol=1e-12 * total.max())
        # the peak of the total force (force signals, polished) is the samples' peak, never below it
        assert o.total_force >= total.max() * (1 - 1e-12)
        assert o.total_force == pytest.approx(total.max(), rel=1e-6)                 # measured <= 2e-14
        at = o.forces(o.total_force_time)[:, 0]
        assert at.sum() == pytest.approx(o.total_force, rel=1e-10)                   # measured <= 2e-14
        # a casing per unit area: the pressure is K_A times the casing's yield, node by node
        np.testing.assert_allclose(contact_pressure(o.peak_force, areas), K_A * o.penetration, rtol=1e-12)
        checked += 1
    assert checked >= 6                                                     # measured 8 orbits


@pytest.mark.parametrize("end, location", [("y = 0", "leading edge"), ("y = 20 mm", "trailing edge")])
def test_the_load_sits_at_the_end_that_touches(tilted, end, location):
    """Only the end nearest the casing touches: the loaded area is its touching nodes' (one, then two, then three
    nodes: 2.5, 7.5, 12.5 mm²) and the load sits in its third of the chord. The strip's tip is a rectangle: no
    thick end to call the leading edge, so the ``y = 0`` end is the chord's 0 (``chord_positions``)."""
    nodal, fam, y = tilted[end]
    near = np.abs(y - (0.0 if end == "y = 0" else 0.02)) < 0.006        # the 3 nodes nearest the casing
    np.testing.assert_allclose(nodal.chord, y / 0.02, atol=1e-12)
    seen = set()
    for o in fam.orbits[1:]:
        at = o.forces(o.total_force_time)[:, 0]
        load = nodal.contact_load(at)
        assert np.all(near[at > 0])                                       # the instant of the peak: one end only
        assert load["loaded_area_m2"] == pytest.approx(nodal.areas[at > 0].sum(), rel=1e-12)
        assert load["location"] == location
        assert load["centre"] < 0.15 if location == "leading edge" else load["centre"] > 0.85
        assert o.loaded_area(nodal.areas) >= load["loaded_area_m2"] * (1 - 1e-12)
        seen.add(round(load["loaded_area_m2"] * 1e6, 6))
    assert {2.5, 7.5} <= seen                                              # the end node, then its neighbour too


def test_chord_runs_from_the_thick_end():
    """A wedge-shaped face (thick at x = 0): its leading edge is the thick end, wherever the nodes are listed."""
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    areas = np.array([4.0, 3.0, 2.0, 1.5, 0.5])
    points = np.c_[x, np.zeros(5), np.zeros(5)]
    np.testing.assert_allclose(chord_positions(points, areas), x / 4)
    np.testing.assert_allclose(chord_positions(points[::-1] * [-1, 1, 1], areas[::-1]), x[::-1] / 4)
    load = contact_load([0.0, 0.0, 0.0, 1.0, 3.0], areas, x / 4)
    assert load["location"] == "trailing edge" and load["loaded_area_m2"] == 2.0
    assert contact_load(np.zeros(5), areas, x / 4) == {"max_pressure_pa": 0.0, "total_force_n": 0.0,
                                                       "loaded_area_m2": 0.0, "centre": None, "location": None}


def test_rub_response_total_force_and_loaded_area():
    """Two nodes of areas 1 and 2 mm² on the 2-dof system of ``bladecase.nsm.massless.rub``'s example: the total
    force's peak is the sum of the nodes' forces at one instant (between the largest node's peak and the sum of the
    peaks), the loaded area the largest over the window's phases (a dense sample never exceeds it)."""
    s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
                    gap=[1.0, 1.0], casing=[4.0, 4.0])
    areas = np.array([1e-6, 2e-6])
    r = rub_response(s, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=30, window=5, areas=areas)
    assert r.peak_force.max() <= r.total_force <= r.peak_force.sum()
    assert r.total_force == pytest.approx(r.force_at_peak.sum(), rel=1e-15)
    turn = 2 * np.pi / 0.4
    from bladecase.nsm.massless.nodes import Rub

    tr = simulate_nodes(s, np.zeros(2), np.zeros(2), 30 * turn, damping=Damping(zeta=0.05),
                        rub=Rub(3, 1.2, 0.4, [0.0, 0.3]))
    lam = tr.forces(np.linspace(25 * turn, 30 * turn, 20001))
    assert lam.sum(axis=0).max() <= r.total_force * (1 + 1e-3)
    assert (areas @ (lam > 0)).max() <= r.loaded_area + 1e-18
    assert r.loaded_area == pytest.approx(3e-6)                            # both nodes touch at once
