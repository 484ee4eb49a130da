"""``bladecase.fe.sector``: the parametric bladed-disk sector (gmsh), its cyclic faces matched, and its nodal-diameter
spectrum equal to that of the whole disk built from 12 rotated copies of the mesh and solved as one mesh."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _cyclic_util import annulus, frequencies_union

from bladecase.fe import assemble
from bladecase.fe.cyclic import cyclic_spectrum, fe_sector
from bladecase.fe.sector import SectorGeometry, sector_mesh
from bladecase.fe.shapes import BladeGeometry
from bladecase.linalg import lowest_modes

BLADE = BladeGeometry(span=0.15, root_chord=0.04, thickness=0.006, contact_point=(0.0, 0.0, 0.15))
GEOMETRY = SectorGeometry(sectors=12, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04, blade=BLADE)


@pytest.fixture(scope="module")
def sector():
    mesh = sector_mesh(GEOMETRY, size=0.03)
    return mesh, assemble(mesh, "steel", order=1, clamp="hub")


def test_groups_faces_and_volume(sector):
    mesh, model = sector
    g = GEOMETRY
    assert mesh.points[mesh.group("contact")].tolist() == [[0.0, 0.0, 0.15]]
    assert np.allclose(mesh.points[mesh.group("tip"), 2], 0.15, atol=1e-12)
    radial = np.hypot(mesh.points[:, 1], mesh.points[:, 2] + g.rim_radius)
    assert radial.min() == pytest.approx(g.hub_radius, rel=1e-9)
    # the faces given as groups and found by the angle are the same, matched one to one by the rotation
    by_group = fe_sector(model, 12, g.axis, left="left", right="right")
    by_angle = fe_sector(model, 12, g.axis)
    assert np.array_equal(by_group.left, by_angle.left) and np.array_equal(by_group.right, by_angle.right)
    assert len(mesh.group("left")) == len(mesh.group("right")) == len(by_group.pairs) + len(
        np.intersect1d(mesh.group("left"), mesh.group("hub")))
    # one body: the disk sector and the blade, the root prism inside the rim (counted once: it is 2.4e-6 m³);
    # straight-sided cells on the hub and rim arcs: 7e-4 of the disk's volume at this size
    disk = math.pi / g.sectors * (g.rim_radius ** 2 - g.hub_radius ** 2) * g.disk_thickness
    blade = BLADE.span * BLADE.root_chord * BLADE.thickness
    assert abs(model.volume - (disk + blade)) <= 1.5e-3 * disk


def test_sector_spectrum_equals_the_whole_disk(sector):
    mesh, model = sector
    n = GEOMETRY.sectors
    spectrum = cyclic_spectrum(fe_sector(model, n, GEOMETRY.axis), count=4)
    union, complete = frequencies_union(spectrum)
    ring = assemble(annulus(mesh, n, origin=GEOMETRY.axis.origin), "steel", order=1, clamp="hub")
    assert ring.n_dofs == n * (model.n_dofs - len(fe_sector(model, n, GEOMETRY.axis).right))
    f = np.sqrt(lowest_modes(ring.K, ring.M, 40)[0]) / (2 * math.pi)
    below = f[f < complete * (1 - 1e-6)]
    assert below.size >= 30
    assert np.max(np.abs(union[:below.size] - below) / below) < 1e-8


def test_bad_sectors_are_refused():
    with pytest.raises(ValueError, match="beyond the sector's half-angle"):
        SectorGeometry(sectors=400, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04, blade=BLADE)
    with pytest.raises(ValueError, match="sectors must be an integer"):
        SectorGeometry(sectors=2, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04, blade=BLADE)
