"""``bladecase.fe.cyclic``: the modes of a bladed disk by nodal diameter from one sector, checked independently.

* the full annulus (the sector rotated N times by scipy, nodes merged, assembled and solved as an ordinary mesh):
  its spectrum is the union of the cyclic spectra with their multiplicities, to 1e-8; the expanded sector modes
  are its eigenvectors;
* a lumped disk–blade chain (two dofs a sector) whose frequencies per nodal diameter are in closed form, to 1e-10;
* travelling waves: a forward wave's pattern moves towards +θ (the rotation's sense, right-handed about the axis)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
from _cyclic_util import annulus, frequencies_union, hex_sector
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from bladecase.fe import assemble
from bladecase.fe.cyclic import CyclicSector, cyclic_modes, cyclic_spectrum, fe_sector, nodal_diameters
from bladecase.fe.cyclic_waves import annulus_field, annulus_points
from bladecase.fe.rotation import RotationAxis
from bladecase.linalg import lowest_modes

AXIS = RotationAxis((0, 0, 0), (1, 0, 0))


@pytest.fixture(scope="module")
def disk():
    """A 7-sector hexahedral bladed disk (odd N: no N/2 diameter) and an 8-sector one, sector and annulus."""
    out = {}
    for n in (7, 8):
        mesh = hex_sector(n)
        model = assemble(mesh, "steel", order=1, clamp="hub")
        ring = assemble(annulus(mesh, n), "steel", order=1, clamp="hub")
        out[n] = (model, ring)
    return out


@pytest.mark.parametrize("n", [7, 8])
def test_the_annulus_spectrum_is_the_union_of_the_nodal_diameters(disk, n):
    model, ring = disk[n]
    spectrum = cyclic_spectrum(fe_sector(model, n, AXIS), count=6)
    assert sorted(spectrum) == nodal_diameters(n)
    union, complete = frequencies_union(spectrum)
    lam, _ = lowest_modes(ring.K, ring.M, 30)
    f_ring = np.sqrt(lam) / (2 * math.pi)
    below = f_ring[f_ring < complete * (1 - 1e-6)]
    assert below.size >= 20  # the comparison covers many modes, doubles included
    assert np.max(np.abs(union[:below.size] - below) / below) < 1e-8
    # 0 < k < N/2 are double, k = 0 (and N/2) single
    assert [m.multiplicity for m in spectrum.values()] == [1] + [2] * ((n - 1) // 2) + ([1] if n % 2 == 0 else [])


def _dof_index(ring, points, c):
    sel = np.flatnonzero(ring.dofs.direction == c)
    d, idx = cKDTree(ring.dofs.coords[sel]).query(points)
    assert d.max() < 1e-9
    return sel[idx]


def test_expanded_modes_are_modes_of_the_annulus_and_continuous(disk):
    n = 8
    model, ring = disk[n]
    sector = fe_sector(model, n, AXIS)
    for k in (1, 3, 4):
        modes = cyclic_modes(sector, k, 3)
        for wave in ("cos", "sin", "forward") if k != 4 else ("cos",):
            for i in range(3):
                field = annulus_field(sector, modes, i, wave, phase=0.7)
                u = np.zeros(ring.n_dofs)
                for j in range(n):
                    for c in range(3):
                        sel = model.dofs.direction == c
                        u[_dof_index(ring, annulus_points(model.dofs.coords[sel], sector)[j], c)] = field[j][sel]
                # every sector's values land on the annulus: the shared face dofs get the same value from both
                for j in range(n):
                    right = annulus_points(model.dofs.coords[sector.right], sector)[j]
                    left_next = annulus_points(model.dofs.coords[sector.left], sector)[(j + 1) % n]
                    assert np.allclose(right, left_next, atol=1e-12)
                    assert np.allclose(field[j][sector.right], field[(j + 1) % n][sector.left], atol=1e-12 *
                                       np.abs(field).max())
                Ku = ring.K @ u
                res = np.linalg.norm(Ku - modes.lam[i] * (ring.M @ u)) / np.linalg.norm(Ku)
                assert res < 1e-8, (k, wave, i, res)


def _lumped(n, kd=3.0, kb=1.0, kc=0.7, md=2.0, mb=0.5):
    """Disk mass ``md`` on a ground spring ``kd``, a blade ``mb`` on it through ``kb``, neighbouring disks coupled
    by ``kc``; dofs ``[disk, blade, next disk]``."""
    K = np.array([[kd + kb + kc, -kb, -kc], [-kb, kb, 0.0], [-kc, 0.0, kc]])
    return CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([md, mb, 0.0])), n, left=[0], right=[2])


def test_lumped_disk_matches_its_closed_form_dispersion():
    kd, kb, kc, md, mb = 3.0, 1.0, 0.7, 2.0, 0.5
    for n in (5, 24):
        sector = _lumped(n, kd, kb, kc, md, mb)
        for k, modes in cyclic_spectrum(sector, 2).items():
            a = kd + kb + 2 * kc * (1 - math.cos(2 * math.pi * k / n))
            # det([[a - λ md, -kb], [-kb, kb - λ mb]]) = 0
            p, q, r = md * mb, -(a * mb + kb * md), a * kb - kb * kb
            exact = np.sort([(-q - s * math.sqrt(q * q - 4 * p * r)) / (2 * p) for s in (1, -1)])
            assert np.allclose(modes.lam, exact, rtol=1e-10, atol=0), (n, k, modes.lam, exact)
            assert modes.multiplicity == (1 if k == 0 or 2 * k == n else 2)


def test_a_forward_wave_travels_with_the_rotation(disk):
    """After a phase step kα the forward pattern is the previous one moved one sector towards +θ: sector j now
    shows what sector j−1 showed, rotated by +α about +x (scipy's right-handed rotation, the rotor's sense);
    the backward pattern moves the other way."""
    n = 8
    model, _ = disk[n]
    sector = fe_sector(model, n, AXIS)
    alpha = 2 * np.pi / n
    rot = Rotation.from_rotvec([alpha, 0, 0])
    pts = model.dofs.coords[model.dofs.direction == 0]
    assert np.allclose(annulus_points(pts, sector)[1], rot.apply(pts), atol=1e-14)
    t = sector.triples
    for k in (1, 2, 3):
        modes = cyclic_modes(sector, k, 2)
        for wave, sign in (("forward", 1), ("backward", -1)):
            now = annulus_field(sector, modes, 0, wave, phase=0.3)
            later = annulus_field(sector, modes, 0, wave, phase=0.3 + sign * k * alpha)
            for j in range(n):
                moved = rot.apply(now[j - 1][t])  # sector j−1's displacement vectors, turned by +α
                assert np.allclose(later[j][t], moved, atol=1e-12 * np.abs(now).max()), (k, wave, j)
            # and not the other way round
            wrong = annulus_field(sector, modes, 0, wave, phase=0.3 - sign * k * alpha)
            assert not np.allclose(wrong[1][t], rot.apply(now[0][t]), atol=1e-3 * np.abs(now).max())
    with pytest.raises(ValueError, match="standing waves only"):
        annulus_field(sector, cyclic_modes(sector, 0, 1), 0, "forward")


def test_tip_crest_moves_towards_positive_angle(disk):
    """The blade tips' axial motion over the disk, read at their global positions: its nodal-diameter-k crest
    angle (right-handed about +x, measured from +z) grows with time for a forward wave, at ω/k per unit time."""
    n = 8
    model, _ = disk[n]
    sector = fe_sector(model, n, AXIS)
    tip = model.mesh.group("tip")
    node = tip[np.argmax(model.mesh.points[tip, 0])]
    dof = model.dof_of(node, "x")
    where = annulus_points(model.mesh.points[[node]], sector)[:, 0]  # (N, 3)
    theta = np.arctan2(-where[:, 1], where[:, 2])  # +z towards -y: positive about +x
    k = 2
    modes = cyclic_modes(sector, k, 1)

    def crest(phase):
        w = annulus_field(sector, modes, 0, "forward", phase=phase)[:, dof]
        return -np.angle(np.sum(w * np.exp(-1j * k * theta))) / k

    step = 0.2
    assert crest(step) - crest(0.0) == pytest.approx(step / k, rel=1e-9)


def test_faces_by_group_equal_faces_by_angle_and_errors_name_the_nodes(disk):
    n = 8
    model, _ = disk[n]
    by_angle = fe_sector(model, n, AXIS)
    pts = model.mesh.points
    theta = np.arctan2(-pts[:, 1], pts[:, 2])
    left = np.flatnonzero(np.isclose(theta, -np.pi / n))
    right = np.flatnonzero(np.isclose(theta, np.pi / n))
    by_group = fe_sector(model, n, AXIS, left=left, right=right)
    assert np.array_equal(by_group.left, by_angle.left) and np.array_equal(by_group.right, by_angle.right)
    with pytest.raises(ValueError, match=r"meet no free node of the right face.*node \d+ at"):
        fe_sector(model, n, AXIS, left=right, right=left)  # swapped
    with pytest.raises(ValueError, match="spans 45° about the axis, but 7 sectors need 51.4286°"):
        fe_sector(model, 7, AXIS)
    with pytest.raises(ValueError, match="not positive definite"):
        cyclic_modes(fe_sector(assemble(model.mesh, "steel", order=1, clamp=None), n, AXIS), 0, 2)
    with pytest.raises(ValueError, match=r"nodal diameter k must be an integer with 0 <= nodal diameter k <= 4"):
        cyclic_modes(by_angle, 5, 2)


def test_order_two_sector_on_first_order_cells_matches_its_annulus():
    """P2 on hexahedra: edge and face dofs on the cyclic faces (no mesh node there), found by group and by angle."""
    n = 6
    mesh = hex_sector(n, nr=1, nb=2, nt=2, nx=1, band=(0, 2))
    model = assemble(mesh, "steel", order=2, clamp="hub")
    sector = fe_sector(model, n, AXIS)
    pts = mesh.points
    theta = np.arctan2(-pts[:, 1], pts[:, 2])
    grouped = fe_sector(model, n, AXIS, left=np.flatnonzero(np.isclose(theta, -np.pi / n)),
                        right=np.flatnonzero(np.isclose(theta, np.pi / n)))
    assert np.array_equal(np.sort(grouped.left), np.sort(sector.left))
    spectrum = cyclic_spectrum(sector, count=4)
    union, complete = frequencies_union(spectrum)
    ring = assemble(annulus(mesh, n), "steel", order=2, clamp="hub")
    f_ring = np.sqrt(lowest_modes(ring.K, ring.M, 16)[0]) / (2 * math.pi)
    below = f_ring[f_ring < complete * (1 - 1e-6)]
    assert below.size >= 10
    assert np.max(np.abs(union[:below.size] - below) / below) < 1e-8


def test_an_unmatched_face_node_is_named(disk):
    import dataclasses

    n = 8
    model, _ = disk[n]
    mesh = model.mesh
    theta = np.arctan2(-mesh.points[:, 1], mesh.points[:, 2])
    right = np.flatnonzero(np.isclose(theta, np.pi / n))
    moved = right[np.argmax(np.hypot(mesh.points[right, 1], mesh.points[right, 2]))]  # a tip node of the face
    pts = mesh.points.copy()
    pts[moved, 0] += 1e-4
    bent = assemble(dataclasses.replace(mesh, points=pts), "steel", order=1, clamp="hub")
    left = np.flatnonzero(np.isclose(theta, -np.pi / n))
    partner = Rotation.from_rotvec([-2 * np.pi / n, 0, 0]).apply(mesh.points[moved])
    (twin,) = left[np.linalg.norm(mesh.points[left] - partner, axis=1) < 1e-12]
    x, y, z = mesh.points[twin]
    with pytest.raises(ValueError, match=rf"^1 node\(s\) of the left cyclic face, rotated by 360°/8 about the axis, "
                                         rf"meet no free node of the right face within tol = 2.6e-07 m: node {twin} at "
                                         rf"\({x:.6g}, {y:.6g}, {z:.6g}\) \(nearest at 0.0001;"):
        fe_sector(bent, n, AXIS, left=left, right=right)
    assert len(fe_sector(bent, n, AXIS, left=left, right=right, tol=2e-4).pairs) == len(left) - 3  # hub nodes
    with pytest.raises(ValueError, match=r"within tol = 0.05 mm: node"):
        fe_sector(dataclasses.replace(bent, mesh=dataclasses.replace(mesh, unit="mm")), n, AXIS, left=left,
                  right=right, tol=0.05)
    with pytest.raises(ValueError, match=r"tol must be a finite length > 0 \(in the mesh's unit, m\), got -1"):
        fe_sector(model, n, AXIS, tol=-1)
    with pytest.raises(ValueError, match="K is not symmetric"):
        CyclicSector(sp.csr_array([[2.0, -1.0], [0.0, 1.0]]), sp.eye_array(2), 4, left=[0], right=[1])


def test_any_axis_gives_the_same_spectrum(disk):
    """The 8-sector disk moved to an oblique axis through another point (and the axis reversed): the same
    frequencies for every nodal diameter, the faces found by angle and matched by the rotation about that axis."""
    import dataclasses

    n = 8
    model, _ = disk[n]
    ref = cyclic_spectrum(fe_sector(model, n, AXIS), count=3)
    a = np.array([1.0, 2.0, -2.0]) / 3.0
    turn = Rotation.align_vectors([a], [[1.0, 0.0, 0.0]])[0]  # +x onto a
    origin = np.array([0.1, -0.2, 0.3])
    mesh = dataclasses.replace(model.mesh, points=turn.apply(model.mesh.points) + origin)
    moved = assemble(mesh, "steel", order=1, clamp="hub")
    for direction in (a, -a):
        spectrum = cyclic_spectrum(fe_sector(moved, n, RotationAxis(origin, direction)), count=3)
        for k in ref:
            assert np.allclose(spectrum[k].frequencies, ref[k].frequencies, rtol=1e-9, atol=0)


def test_annulus_mesh_carries_the_expanded_wave(disk):
    """The library's whole-disk mesh equals the test's own (scipy rotations), and a travelling wave put on its nodes
    is an eigenvector of its assembled model."""
    from bladecase.fe.cyclic_waves import annulus_mesh, annulus_nodes

    n = 8
    model, _ = disk[n]
    sector = fe_sector(model, n, AXIS)
    mesh, index = annulus_mesh(model.mesh, sector)
    theirs = annulus(model.mesh, n)
    assert len(mesh.points) == len(theirs.points) and len(mesh.cells["hexahedron"]) == len(theirs.cells["hexahedron"])
    d, _ = cKDTree(theirs.points).query(mesh.points)
    assert d.max() < 1e-12
    ring = assemble(mesh, "steel", order=1, clamp="hub")
    modes = cyclic_modes(sector, 3, 2)
    u_nodes = annulus_nodes(model, annulus_field(sector, modes, 1, "backward", phase=1.1), index)
    free = ring.dofs.node
    u = u_nodes[free, ring.dofs.direction]
    assert np.abs(u_nodes[mesh.group("hub")]).max() == 0.0
    Ku = ring.K @ u
    assert np.linalg.norm(Ku - modes.lam[1] * (ring.M @ u)) / np.linalg.norm(Ku) < 1e-8


def test_pairs_list_mesh_nodes_only():
    n = 6
    mesh = hex_sector(n, nr=1, nb=2, nt=2, nx=1, band=(0, 2))
    p1 = fe_sector(assemble(mesh, "steel", order=1, clamp="hub"), n, AXIS)
    p2 = fe_sector(assemble(mesh, "steel", order=2, clamp="hub"), n, AXIS)
    assert np.array_equal(p1.pairs, p2.pairs) and len(p2.left) > len(p1.left)
    turned = Rotation.from_rotvec([2 * np.pi / n, 0, 0]).apply(mesh.points[p1.pairs[:, 0]])
    assert np.allclose(turned, mesh.points[p1.pairs[:, 1]], atol=1e-12)


def test_sector_modes_satisfy_the_cyclic_constraint_and_are_normalised(disk):
    n = 8
    model, _ = disk[n]
    sector = fe_sector(model, n, AXIS)
    R = Rotation.from_rotvec([2 * np.pi / n, 0, 0]).as_matrix()
    for k in (0, 1, 3, 4):
        modes = cyclic_modes(sector, k, 3)
        phi = modes.shapes
        assert np.allclose(phi.conj().T @ (model.M @ phi), np.eye(3), atol=1e-10)
        left = phi[sector.left].reshape(-1, 3, 3)   # (face nodes, xyz, modes)
        right = phi[sector.right].reshape(-1, 3, 3)
        assert np.allclose(right, np.exp(1j * k * 2 * np.pi / n) * np.einsum("ab,qbm->qam", R, left), atol=1e-12)
        top = phi[np.argmax(np.abs(phi), axis=0), range(3)]
        assert np.allclose(top.imag, 0, atol=1e-15) and np.all(top.real > 0)
        if k in (0, 4):
            assert np.abs(phi.imag).max() < 1e-12  # standing waves only: a real mode
