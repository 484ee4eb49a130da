"""A line of contact nodes (as a published benchmark lists the tip's nodes): weighted by each node's tributary
length along the line, accepted by the every-node model; asking for a stiffness per unit area of a line is refused
with the right hint."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshHex

import bladecase as bc
from bladecase.fe import Mesh
from bladecase.reduction.contact import tributary_areas, tributary_lengths
from bladecase.reduction.nodes import nodal_model


@pytest.fixture(scope="module")
def bar():
    """A 3-D steel bar 0.1 × 0.02 × 0.004 m clamped at x = 0 (lumped mass), and the nodes of its tip's lower edge
    (x = 0.1, z = 0): a line of 5 nodes, unevenly spaced."""
    y = np.array([0.0, 0.004, 0.01, 0.015, 0.02])
    m = MeshHex.init_tensor(np.linspace(0, 0.1, 11), y, np.linspace(0, 0.004, 2))
    p = m.p.T
    mesh = Mesh(p, {"hexahedron": m.t.T}, dim=3, groups={"root": np.flatnonzero(p[:, 0] == 0)})
    model = bc.assemble(mesh, "steel", order=1, mass="lumped")
    line = np.flatnonzero(np.isclose(p[:, 0], 0.1) & np.isclose(p[:, 2], 0.0))
    return model, line, y


def test_tributary_lengths_of_an_uneven_line(bar):
    model, line, y = bar
    lengths = tributary_lengths(model.mesh.points[line])
    order = np.argsort(model.mesh.points[line, 1])
    assert lengths[order] == pytest.approx([0.002, 0.005, 0.0055, 0.005, 0.0025], rel=1e-12)


def test_a_line_of_nodes_is_weighted_by_length_and_has_no_area(bar, caplog):
    model, line, _ = bar
    import logging

    with caplog.at_level(logging.INFO, logger="bladecase"):
        c = bc.Contact.face(model, line.tolist(), (0.0, 0.0, -1.0), 1e-4, weights="area")
    w = np.array(c.weights)
    lengths = tributary_lengths(model.mesh.points[np.array(c.nodes)])
    assert w == pytest.approx(lengths / lengths.sum(), rel=1e-12) and w.sum() == pytest.approx(1.0)
    assert "hold no facet of the body (a line of nodes): each is weighted by its tributary length" in caplog.text
    with pytest.raises(ValueError, match="they have no area — give the casing's stiffness as casing_stiffness"):
        tributary_areas(model, line)
    nodal = nodal_model(model, c.with_casing(1e6), 4, residual=True)
    assert nodal.system.m == len(line) and np.all(nodal.areas == 0)
    k = np.asarray(nodal.system.casing)
    assert k == pytest.approx(1e6 * w, rel=1e-12)  # the casing shared by the same lengths
