"""An element-based ``*SURFACE`` line without a face label (``EALL,`` or ``EALL``): the free faces of its elements,
as in Abaqus (:func:`bladecase.fe.abaqus_surfaces.free_faces`), read as a node group.

Checked independently of the reader's face tables and face matching:

* on a structured hexahedral block (linear and quadratic, written here), the group is the nodes on the block's six
  planes — by coordinates; an element set of half the block gives its nodes on the block's outside, not those of the
  face it shares with the other half;
* on real gmsh meshes of an annular sector (C3D10, C3D20, C3D6), the group is exactly the nodes that lie on the
  geometry's boundary (two radii, two angles, two axial planes), midside nodes included; on the linear tetrahedra
  it is also scikit-fem's own boundary nodes of the same mesh (another code's face matching);
* plane elements (CPS4): the outline's nodes;
* a line whose elements have no free face, and a line without an element, are errors naming the line.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from test_abaqus_element_surfaces import _gmsh_sector

from bladecase.fe.abaqus import abaqus_text, read_abaqus
from bladecase.fe.abaqus_sets import AbaqusError
from bladecase.fe.abaqus_surfaces import FACE_NODES, free_faces

HEX20_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


def _block(n=(3, 2, 2), quadratic: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A unit-spaced block of ``n`` hexahedra: ``(points, cells)`` (C3D8, or C3D20 with the midside nodes)."""
    nx, ny, nz = n
    grid = np.array(list(itertools.product(range(nx + 1), range(ny + 1), range(nz + 1))), dtype=float)
    at = {tuple(p): i for i, p in enumerate(grid.astype(int).tolist())}
    points = [tuple(p) for p in grid.tolist()]
    cells = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        c = [at[(i, j, k)], at[(i + 1, j, k)], at[(i + 1, j + 1, k)], at[(i, j + 1, k)],
             at[(i, j, k + 1)], at[(i + 1, j, k + 1)], at[(i + 1, j + 1, k + 1)], at[(i, j + 1, k + 1)]]
        if quadratic:
            for a, b in HEX20_EDGES:
                mid = tuple(0.5 * (np.array(points[c[a]]) + np.array(points[c[b]])))
                if mid not in at:
                    at[mid] = len(points)
                    points.append(mid)
                c.append(at[mid])
        cells.append(c)
    return np.array(points, dtype=float), np.array(cells)


def _deck(points, cells, element: str, surface: str, sets: dict | None = None) -> str:
    lines = ["*NODE"] + [f"{i + 1}, {x!r}, {y!r}, {z!r}" for i, (x, y, z) in enumerate(points.tolist())]
    lines.append(f"*ELEMENT, TYPE={element}, ELSET=EALL")
    for e, row in enumerate(cells.tolist()):
        items = [str(e + 1)] + [str(v + 1) for v in row]
        lines += [", ".join(items[i:i + 16]) + ("," if i + 16 < len(items) else "") for i in range(0, len(items), 16)]
    for name, members in (sets or {}).items():
        lines += [f"*ELSET, ELSET={name}", ", ".join(str(e + 1) for e in members)]
    return "\n".join(lines + ["*SURFACE, NAME=OUTSIDE", surface]) + "\n"


@pytest.mark.parametrize("quadratic, element", [(False, "C3D8"), (True, "C3D20R")])
@pytest.mark.parametrize("line", ["EALL,", "EALL", "eall, "])
def test_the_free_faces_of_a_block_are_its_six_planes(tmp_path, quadratic, element, line):
    points, cells = _block(quadratic=quadratic)
    (tmp_path / "b.inp").write_text(_deck(points, cells, element, line))
    m = read_abaqus(tmp_path / "b.inp")
    top = points.max(axis=0)
    on = np.flatnonzero(((points == 0) | (points == top)).any(axis=1))
    assert np.array_equal(m.point_sets["OUTSIDE"], on)
    assert on.size < len(points)  # the block has inner nodes, left out


def test_a_set_of_half_the_block_keeps_only_its_outside(tmp_path):
    points, cells = _block(n=(4, 2, 2))
    half = np.flatnonzero(points[cells].mean(axis=1)[:, 0] < 2)
    deck = _deck(points, cells, "C3D8", "LEFT,", sets={"LEFT": half})
    (tmp_path / "b.inp").write_text(deck)
    m = read_abaqus(tmp_path / "b.inp")
    x, y, z = points.T
    outside = (x == 0) | (y == 0) | (y == 2) | (z == 0) | (z == 2)  # the block's planes, x = 4 beyond the half
    expected = np.flatnonzero((x <= 2) & outside)
    assert np.array_equal(m.point_sets["OUTSIDE"], expected)
    inner = np.flatnonzero((x == 2) & (y == 1) & (z == 1))  # on the shared face x = 2 only: not free
    assert inner.size == 1 and inner[0] not in m.point_sets["OUTSIDE"]
    # the same set with element numbers written one by one, and mixed with a labelled line of the same surface
    listed = "\n".join(str(e + 1) for e in half)
    (tmp_path / "c.inp").write_text(deck.replace("LEFT,\n", listed + "\n"))
    assert np.array_equal(read_abaqus(tmp_path / "c.inp").point_sets["OUTSIDE"], expected)


def _on_boundary(points, alpha: float) -> np.ndarray:
    """The nodes on the gmsh sector's boundary, by geometry: r = 0.1 or 0.16, θ = ±α/2, x = 0 or 0.02."""
    x, y, z = points.T
    r, theta = np.hypot(y, z), np.arctan2(-y, z)
    tol = 1e-9
    return np.flatnonzero((np.abs(r - 0.1) < tol) | (np.abs(r - 0.16) < tol) | (np.abs(np.abs(theta) - alpha / 2)
                          < tol) | (np.abs(x) < tol) | (np.abs(x - 0.02) < tol))


@pytest.mark.parametrize("kind", ["tetra", "tetra10", "hexahedron20", "wedge"])
def test_the_free_faces_of_a_gmsh_sector_lie_on_its_boundary(tmp_path, kind):
    alpha = math.pi / 6
    mesh = _gmsh_sector(tmp_path, kind, alpha)
    text = abaqus_text(mesh, groups={}).replace("*ELEMENT, TYPE=", "*ELEMENT, ELSET=BODY, TYPE=")
    (tmp_path / "s.inp").write_text(text + "*SURFACE, NAME=SKIN\nBODY,\n")
    m = read_abaqus(tmp_path / "s.inp")
    np.testing.assert_allclose(m.points, mesh.points, rtol=0, atol=0)  # the same node order
    skin = m.point_sets["SKIN"]
    assert np.array_equal(skin, _on_boundary(mesh.points, alpha))
    cells = np.asarray(mesh.cells[kind])
    free = free_faces({kind: (np.arange(1, len(cells) + 1), cells)})[kind]
    assert 0 < free.sum() < free.size  # faces inside the body are shared, not free
    if kind == "tetra":  # scikit-fem's boundary faces of the same tetrahedra: the same faces, not only nodes
        skfem = pytest.importorskip("skfem")
        tets = skfem.MeshTet(np.ascontiguousarray(mesh.points.T), np.ascontiguousarray(cells.T))
        theirs = {tuple(sorted(f)) for f in tets.facets[:, tets.boundary_facets()].T.tolist()}
        ours = {tuple(sorted(cells[e, np.array(nodes) - 1].tolist()))
                for e, i in zip(*np.nonzero(free)) for nodes in [list(FACE_NODES["tetra"].values())[i]]}
        assert ours == theirs and np.array_equal(skin, np.sort(tets.boundary_nodes()))


def test_plane_elements_give_their_outline(tmp_path):
    points, cells = _block(n=(3, 2, 1))
    bottom = points[:, 2] == 0
    keep = np.flatnonzero(bottom)
    renumber = np.full(len(points), -1)
    renumber[keep] = np.arange(keep.size)
    quads = renumber[cells[:, :4]]  # the block's bottom face as CPS4 quadrangles
    (tmp_path / "q.inp").write_text(_deck(points[keep], quads, "CPS4", "EALL,"))
    m = read_abaqus(tmp_path / "q.inp")
    x, y = points[keep, 0], points[keep, 1]
    assert np.array_equal(m.point_sets["OUTSIDE"], np.flatnonzero((x == 0) | (x == 3) | (y == 0) | (y == 2)))


@pytest.mark.parametrize("surface, words", [
    ("MIDDLE,", r"line \d+: \*SURFACE, NAME=OUTSIDE: a line without a face label is the free faces of its elements, "
                r"but none of these 1 element\(s\) has a free face .*give their face labels"),
    (", S1", r"line \d+: \*SURFACE, NAME=OUTSIDE: an element-based surface line is 'element or element set, face "
             r"label' .* or 'element or element set' alone for the free faces of its elements, got ', S1'"),
])
def test_bad_free_face_lines_are_named(tmp_path, surface, words):
    points, cells = _block(n=(3, 3, 3))
    middle = np.flatnonzero((points[cells].mean(axis=1) == 1.5).all(axis=1))  # the one element inside
    (tmp_path / "b.inp").write_text(_deck(points, cells, "C3D8", surface, sets={"MIDDLE": middle}))
    with pytest.raises(AbaqusError, match=words):
        read_abaqus(tmp_path / "b.inp")
