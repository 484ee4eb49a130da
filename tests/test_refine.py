"""A user's mesh refined by splitting its cells (``bladecase.fe.refine``).

Checked: a straight mesh of every supported type refined into 2 and 3 parts per edge fills the same body (volume
to 1e-12, the new nodes at the cell's own linear map) with distinct nodes; a curved second-order mesh keeps its
curved geometry (the refined volume is the coarse curved one to 1e-12, not the chords'), and its breathing frequency
converges towards the closed form; named groups map (a plane's nodes are exactly the refined mesh's nodes on that
plane, the outer surface's on the outer surface); an unsupported split is refused.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree
from test_isoparametric import R_OUT, STEEL, annulus, breathing_frequency, fe_breathing, parameter_mesh

from bladecase.fe import Mesh, assemble
from bladecase.fe.cells import KINDS
from bladecase.fe.refine import refine_mesh

TYPES = ["tetra", "tetra10", "hexahedron", "hexahedron20", "hexahedron27", "wedge", "wedge15", "wedge18",
         "triangle", "triangle6", "quad", "quad8", "quad9"]


def box_mesh(btype: str) -> Mesh:
    """A 0.3 × 0.2 × 0.1 box (or rectangle) of ``btype`` cells, sheared, with the group ``top`` (z or y maximal)."""
    dim = KINDS[btype].dim
    pts, cells = parameter_mesh(btype, (2, 2, 1)[:dim])
    xyz = np.zeros((len(pts), 3))
    xyz[:, :dim] = pts[:, :dim] * np.array([0.3, 0.2, 0.1])[:dim]
    xyz[:, 0] += 0.5 * xyz[:, dim - 1]  # sheared: the cells are not rectangular
    top = np.flatnonzero(np.isclose(xyz[:, dim - 1], xyz[:, dim - 1].max()))
    return Mesh(xyz, {btype: cells}, dim=dim, groups={"top": top}, source=f"box {btype}")


@pytest.mark.parametrize("btype", TYPES)
@pytest.mark.parametrize("n", [2, 3])
def test_a_straight_mesh_is_refilled_exactly(btype, n):
    mesh = box_mesh(btype)
    fine = refine_mesh(mesh, n)
    kind = KINDS[btype]
    assert len(fine.cells[btype]) == n ** kind.dim * len(mesh.cells[btype])
    thickness = None if kind.dim == 3 else 0.01
    v0 = assemble(mesh, STEEL, order=1, clamp=None, thickness=thickness).volume
    v1 = assemble(fine, STEEL, order=1, clamp=None, thickness=thickness).volume
    assert v1 == pytest.approx(v0, rel=1e-12)
    assert cKDTree(fine.points).query(fine.points, k=2)[0][:, 1].min() > 1e-3 * 0.1 / n  # no duplicate node
    assert np.unique(fine.cells[btype]).size == len(fine.points)  # no unused node
    # the group on the top plane: exactly the refined mesh's nodes on that plane
    axis = kind.dim - 1
    on_top = np.flatnonzero(np.abs(fine.points[:, axis] - mesh.points[:, axis].max()) < 1e-12)
    assert fine.groups["top"].tolist() == on_top.tolist()
    # every original node keeps its coordinates and number, first (midside, face-centre, centre nodes included)
    k = len(mesh.points)
    assert np.array_equal(fine.points[:k], mesh.points) and np.array_equal(fine.node_ids[:k], mesh.node_ids)


def chord_volume(mesh: Mesh) -> float:
    """The volume of ``mesh``'s cells through their corners only (signed, for tetrahedra: a coarse curved cell's
    sub-cells can fold once straightened)."""
    kind = KINDS[mesh.body_type]
    cells = mesh.cells[mesh.body_type][:, :kind.corners]
    if kind.family == "tetra":
        x = mesh.points[cells]
        return float(np.einsum("ij,ij->", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0]) / 6)
    return assemble(Mesh(mesh.points, {kind.family: cells}, dim=3), STEEL, order=1, clamp=None).volume


@pytest.mark.parametrize("btype", ["tetra10", "hexahedron20", "wedge15"])
def test_a_curved_mesh_stays_curved(btype):
    """A hollow cylinder (8 cells around): the refined cells follow the coarse cells' curved map (volume to 1e-12),
    not their chords (the chords' volume is 2.5e-2 smaller); the outer surface group maps."""
    mesh = annulus(btype, 8)
    r = np.hypot(mesh.points[:, 0], mesh.points[:, 1])
    mesh = Mesh(mesh.points, mesh.cells, dim=3, groups={"outer": np.flatnonzero(np.isclose(r, R_OUT))},
                source=mesh.source)
    coarse = assemble(mesh, STEEL, order=2, clamp=None).volume
    for n in (2, 3):
        fine = refine_mesh(mesh, n)
        assert assemble(fine, STEEL, order=2, clamp=None).volume == pytest.approx(coarse, rel=1e-12)
        flat = chord_volume(fine)
        assert flat / coarse - 1 < -2e-3 / n ** 2  # the corners alone: the polygon's volume
        rf = np.hypot(fine.points[:, 0], fine.points[:, 1])
        outer = fine.groups["outer"]
        assert np.abs(rf[outer] - R_OUT).max() < 2e-3 and np.delete(rf, outer).max() < R_OUT - 5e-3
        assert outer.size == np.count_nonzero(np.abs(rf - R_OUT) < 2e-3)  # every node on the surface


def test_the_breathing_frequency_of_a_curved_ring_converges():
    """triangle6 ring, 8 cells around, each edge split in 1 to 4: the error against the closed form falls (4.13e-4,
    3.93e-4, 3.67e-4, 3.60e-4 measured) towards that of the coarse cells' curved geometry (3.5e-4 with 6 splits),
    the changes shrinking after the first two."""
    exact = breathing_frequency()
    mesh = annulus("triangle6", 8)
    f = [fe_breathing(assemble(refine_mesh(mesh, n), STEEL, order=2, clamp=None, thickness=0.01), exact)
         for n in (1, 2, 3, 4)]
    err = [x / exact - 1 for x in f]
    assert err[0] > err[1] > err[2] > err[3] > 3e-4 and abs(f[3] - f[2]) < 0.5 * abs(f[2] - f[1])


def test_unsupported_splits_are_refused():
    mesh = box_mesh("tetra")
    for bad in (0, 7, 1.5, True):
        with pytest.raises(ValueError, match=r"n \(parts per edge\) must be an integer from 1 to 6"):
            refine_mesh(mesh, bad)
    assert refine_mesh(mesh, 1) is mesh


@pytest.mark.parametrize("btype", ["tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18", "triangle6",
                                   "quad8"])
def test_every_cell_puts_a_shared_node_at_the_same_place(btype):
    """A node made once for all the cells around an edge or face: each of those cells' own curved map puts it at
    the same point (measured ≤ 8e-13 on distorted curved meshes, split in 3)."""
    from bladecase.fe import refine as r

    kind = KINDS[btype]
    mesh = annulus(btype, 8, distort=0.2) if kind.dim == 3 else annulus(btype, 8, n_r=2, distort=0.2)
    cells, n = np.asarray(mesh.cells[btype]), 3
    U = np.unique(r._sub_cells(btype, n).reshape(-1, kind.dim).round(12), axis=0)
    Wi = np.rint(r._basis(btype, 1, U) * (2 * n) ** kind.dim).astype(np.int64)
    nodemap, new_points, _ = r._number_nodes(mesh, kind, cells, U, Wi)
    points = np.concatenate([mesh.points, new_points])
    own = np.einsum("qa,cai->cqi", r._basis(btype, kind.order, U), mesh.points[cells])
    assert np.abs(points[nodemap] - own).max() < 1e-11
