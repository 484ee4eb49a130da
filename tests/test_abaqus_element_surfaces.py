"""Element-based ``*SURFACE``s (``TYPE=ELEMENT``, ``element or element set, S1 … S6``) read as node groups
(:mod:`bladecase.fe.abaqus_surfaces`).

* The face tables equal CalculiX's own (``ifaceq``, ``ifacet``, ``ifacew1``, ``ifacew2``, ``ifacequad``,
  ``ifacetria`` of its source, transcribed here as sets of nodes).
* On real gmsh meshes (C3D10, C3D15, C3D20, C3D6 written by ``abaqus_text``): the surface of every element face whose
  corners lie on a cyclic face (the sector's lowest or highest angle about the axis) holds exactly the nodes at that
  angle — midside nodes included, none off it.
* The hexahedral sector deck of ``tests/test_cyclic_deck.py`` with its two cyclic faces written as element faces
  instead of node sets: identical groups, and the cyclic study's ``cyclic.csv`` (frequencies printed with all
  their digits) identical character for character; CalculiX runs that element-surface deck and its frequencies per
  nodal diameter agree with bladecase's on the same deck to 1e-6 (measured 1.9e-7, CalculiX printing 7 digits).
* A blade-tip surface of element faces is the contact face (``Contact.face``) of the same nodes and weights.
* Bad lines name the line and what is valid.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from test_cyclic_calculix import read_cyclic_dat
from test_cyclic_deck import N, _csv, _study, sector_deck

from bladecase.cli import main
from bladecase.fe import assemble, load_mesh
from bladecase.fe.abaqus import abaqus_text, read_abaqus
from bladecase.fe.abaqus_sets import AbaqusError
from bladecase.fe.abaqus_surfaces import FACE_NODES
from bladecase.fe.groups import NODE_ID_KEY
from bladecase.reduction.contact import Contact

CCX = shutil.which("ccx")

#: CalculiX's face tables as in its source (columns of ``ifaceq(8,6)``, … : one face each, in its order).
CCX_TABLES = {
    "hexahedron20": [(4, 3, 2, 1, 11, 10, 9, 12), (5, 6, 7, 8, 13, 14, 15, 16), (1, 2, 6, 5, 9, 18, 13, 17),
                     (2, 3, 7, 6, 10, 19, 14, 18), (3, 4, 8, 7, 11, 20, 15, 19), (4, 1, 5, 8, 12, 17, 16, 20)],
    "tetra10": [(1, 3, 2, 7, 6, 5), (1, 2, 4, 5, 9, 8), (2, 3, 4, 6, 10, 9), (1, 4, 3, 8, 10, 7)],
    "wedge": [(1, 3, 2), (4, 5, 6), (1, 2, 5, 4), (2, 3, 6, 5), (3, 1, 4, 6)],
    "wedge15": [(1, 3, 2, 9, 8, 7), (4, 5, 6, 10, 11, 12), (1, 2, 5, 4, 7, 14, 10, 13), (2, 3, 6, 5, 8, 15, 11, 14),
                (3, 1, 4, 6, 9, 13, 12, 15)],
    "quad8": [(1, 2, 5), (2, 3, 6), (3, 4, 7), (4, 1, 8)],
    "triangle6": [(1, 2, 4), (2, 3, 5), (3, 1, 6)],
}
CORNERS = {"tetra": 4, "wedge": 6, "hexahedron": 8, "quad": 4, "triangle": 3}


def test_face_tables_are_calculix_tables():
    linear = {"tetra": "tetra10", "wedge": "wedge15", "hexahedron": "hexahedron20", "quad": "quad8",
              "triangle": "triangle6"}
    for kind, faces in CCX_TABLES.items():
        assert [set(FACE_NODES[kind][f"S{i + 1}"]) for i in range(len(faces))] == [set(f) for f in faces], kind
        assert list(FACE_NODES[kind]) == [f"S{i + 1}" for i in range(len(faces))]
    for kind, quadratic in linear.items():  # a linear element's face: the corners of the quadratic one's
        n = CORNERS[kind]
        assert {s: tuple(v for v in f if v <= n) for s, f in FACE_NODES[quadratic].items()} == FACE_NODES[kind]


def _gmsh_sector(folder, kind: str, alpha: float = math.pi / 6):
    """A real gmsh mesh of an annular sector (r 0.1..0.16, angles ±alpha/2 about +x from +z) extruded 0.02 along x:
    tetrahedra (a free volume mesh), wedges or hexahedra (extruded triangles or structured quadrangles), of order 1
    or 2 (``kind``: tetra10, wedge, wedge15, hexahedron20); read back with :func:`bladecase.fe.load_mesh`."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(["", "-v", "0"], readConfigFiles=False, interruptible=False)
    try:
        geo = gmsh.model.geo
        gmsh.model.add("s")
        c = geo.addPoint(0, 0, 0)
        p = [geo.addPoint(0, -r * math.sin(t), r * math.cos(t))
             for r, t in ((0.1, -alpha / 2), (0.16, -alpha / 2), (0.16, alpha / 2), (0.1, alpha / 2))]
        lines = [geo.addLine(p[0], p[1]), geo.addCircleArc(p[1], c, p[2]), geo.addLine(p[2], p[3]),
                 geo.addCircleArc(p[3], c, p[0])]
        s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        if kind.startswith("hex"):
            for curve in lines:
                geo.mesh.setTransfiniteCurve(curve, 4)
            geo.mesh.setTransfiniteSurface(s)
            geo.mesh.setRecombine(2, s)
        structured = not kind.startswith("tetra")
        geo.extrude([(2, s)], 0.02, 0, 0, numElements=[2] if structured else [],
                    recombine=structured)
        geo.synchronize()
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], name="body")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.025)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.generate(3)
        if kind[-1].isdigit():
            gmsh.model.mesh.setOrder(2)
        gmsh.write(str(folder / "s.msh"))
    finally:
        gmsh.finalize()
    mesh = load_mesh(folder / "s.msh")
    assert mesh.body_type == kind
    return mesh


@pytest.mark.parametrize("kind", ["tetra10", "wedge15", "hexahedron20", "wedge"])
def test_face_nodes_lie_on_the_geometric_face(tmp_path, kind):
    mesh = _gmsh_sector(tmp_path, kind)
    theta = np.arctan2(-mesh.points[:, 1], mesh.points[:, 2])
    low, high = np.isclose(theta, theta.min(), atol=1e-9), np.isclose(theta, theta.max(), atol=1e-9)
    cells = np.asarray(mesh.cells[kind])
    n = CORNERS[re.sub(r"\d+$", "", kind)]
    lines = {"LOW": [], "HIGH": []}
    for e, row in enumerate(cells):
        for label, nodes in FACE_NODES[kind].items():
            corners = row[[v - 1 for v in nodes if v <= n]]
            for name, on in (("LOW", low), ("HIGH", high)):
                if on[corners].all():
                    lines[name].append(f"{e + 1}, {label}")
    assert lines["LOW"] and lines["HIGH"]
    text = abaqus_text(mesh, groups={})
    text += "*SURFACE, NAME=LOW, TYPE=ELEMENT\n" + "\n".join(lines["LOW"]) + "\n"
    text += "*SURFACE, NAME=HIGH\n" + "\n".join(lines["HIGH"]) + "\n"
    (tmp_path / "s.inp").write_text(text)
    m = read_abaqus(tmp_path / "s.inp")
    np.testing.assert_allclose(m.points, mesh.points, rtol=0, atol=0)  # the same node order
    assert np.array_equal(m.point_sets["LOW"], np.flatnonzero(low))
    assert np.array_equal(m.point_sets["HIGH"], np.flatnonzero(high))
    if kind[-1].isdigit():  # the midside nodes are in: more nodes than the faces' corners
        corners = np.unique(cells[:, :n])
        assert np.setdiff1d(np.flatnonzero(low), corners).size > 0


def _element_deck(deck: str) -> str:
    """``deck`` (test_cyclic_deck's sector) with its cyclic faces as element faces: the left face (the hexahedra's
    nodes 1-4 on it: S1) through an element set, the right face (nodes 5-8: S2) element by element."""
    block = deck[deck.index("*ELEMENT"):]
    block = block[block.index("\n") + 1:block.index("\n*")]
    rows = np.array([[int(v) for v in line.split(",")] for line in block.splitlines()])

    def members(name):
        text = deck[deck.index(f"*NSET, NSET={name}\n"):]
        text = text[text.index("\n") + 1:text.index("\n*")]
        return np.array([int(v) for v in text.replace(",", " ").split()])

    left = rows[np.isin(rows[:, 1:5], members("LEFT")).all(axis=1), 0]
    right = rows[np.isin(rows[:, 5:9], members("RIGHT")).all(axis=1), 0]
    deck = deck.replace("*SURFACE, NAME=SLEFT, TYPE=NODE\nLEFT\n",
                        "*ELSET, ELSET=ELEFT\n" + ", ".join(map(str, left)) + "\n*SURFACE, NAME=SLEFT\nELEFT, S1\n")
    return deck.replace("*SURFACE, NAME=SRIGHT, TYPE=NODE\nRIGHT\n", "*SURFACE, NAME=SRIGHT, TYPE=ELEMENT\n"
                        + "".join(f"{e}, s2\n" for e in right))


def test_element_surfaces_are_the_node_surfaces(tmp_path):
    nodes = sector_deck(count=3)
    faces = _element_deck(nodes)
    assert "TYPE=NODE" not in faces and "ELEFT, S1" in faces
    runs = {}
    for name, deck in (("nodes", nodes), ("faces", faces)):
        folder = tmp_path / name
        folder.mkdir()
        study = _study(folder, deck, "modes = 3")
        m = read_abaqus(folder / "sector.inp")
        runs[name] = {g: m.point_sets[g].tolist() for g in ("SLEFT", "SRIGHT", "LEFT", "RIGHT")}
        assert main(["run", study, "--out", str(folder / "out"), "--quiet"]) == 0
        runs[name]["csv"] = (folder / "out" / "cyclic.csv").read_text()
    assert runs["faces"] == runs["nodes"]
    assert runs["faces"]["SLEFT"] == runs["faces"]["LEFT"] and len(runs["faces"]["SLEFT"]) == 3 * 3
    assert len(runs["faces"]["csv"].splitlines()) == 1 + 3 * (N // 2 + 1)


@pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed")
def test_calculix_runs_the_element_surface_deck(tmp_path):
    deck = _element_deck(sector_deck(count=6))
    study = _study(tmp_path, deck, "modes = 3")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    ours = _csv(tmp_path / "out" / "cyclic.csv")
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    subprocess.run([CCX, "sector"], cwd=tmp_path, capture_output=True, check=True, timeout=120, env=env)
    theirs = read_cyclic_dat((tmp_path / "sector.dat").read_text())
    assert sorted(theirs) == sorted(ours) == list(range(N // 2 + 1))
    worst = max(float(np.max(np.abs(ours[k] / theirs[k][:3] - 1))) for k in ours)
    assert worst < 1e-6, worst


@pytest.mark.parametrize("line, words", [
    ("1, S7", r"line \d+: \*SURFACE, NAME=SLEFT: element 1 is a C3D8 \(hexahedron\), whose faces are S1, S2, S3, "
              r"S4, S5, S6; got face label 'S7'"),
    ("99999, S1", r"line \d+: \*SURFACE, NAME=SLEFT names element 99999, which the file does not have \(the file "
                  r"has 33 elements, numbered 1 to 99\)"),
    ("99, S1", r"line \d+: \*SURFACE, NAME=SLEFT: element 99 is of a type bladecase leaves out \(left out: S4R\)"),
    ("NOSUCH, S1", r"line \d+: \*SURFACE, NAME=SLEFT names the element set 'NOSUCH', which the deck does not "
                   r"define \(\*ELSETs: EALL"),
    (", S1", r"line \d+: \*SURFACE, NAME=SLEFT: an element-based surface line is 'element or element set, face "
             r"label' \(e.g. '12, S3'"),
])
def test_bad_surface_lines_are_named(tmp_path, line, words):
    deck = sector_deck().replace("*SURFACE, NAME=SLEFT, TYPE=NODE\nLEFT\n", f"*SURFACE, NAME=SLEFT\n{line}\n")
    deck = deck.replace("*STEP", "*ELEMENT, TYPE=S4R\n99, 1, 2, 3, 4\n*STEP", 1)  # a shell: element 99
    (tmp_path / "s.inp").write_text(deck)
    with pytest.raises(AbaqusError, match=words):
        read_abaqus(tmp_path / "s.inp")


def test_a_tip_surface_is_a_contact_group(tmp_path):
    """The blade tip as element faces: the group holds the mesh's tip nodes, usable as the ``[contact]`` group."""
    deck = sector_deck()
    m0 = read_abaqus(_write(tmp_path / "a.inp", deck))
    ids = m0.point_data[NODE_ID_KEY]
    r = np.hypot(m0.points[:, 1], m0.points[:, 2] + 100.0)
    tip = np.flatnonzero(np.isclose(r, r.max()))
    cells = np.asarray(m0.cells[0].data)
    outer = [e + 1 for e, row in enumerate(cells) if np.isin(row[[2, 3, 6, 7]], tip).all()]  # S5 = 3-7-8-4
    deck = deck.replace("*STEP", "*SURFACE, NAME=STIP\n" + "".join(f"{e}, S5\n" for e in outer) + "*STEP", 1)
    m = read_abaqus(_write(tmp_path / "b.inp", deck))
    assert np.array_equal(m.point_sets["STIP"], tip) and ids[tip].size == 3 * 3
    mesh = load_mesh(tmp_path / "b.inp", unit="mm")
    model = assemble(mesh, "steel", order=1, clamp="CLAMPED")
    faces = Contact.face(model, "STIP", (0.0, 0.0, 1.0), 1e-4, weights="area")  # the [contact] face group
    nodes = Contact.face(model, tip.tolist(), (0.0, 0.0, 1.0), 1e-4, weights="area")
    assert np.array_equal(faces.nodes, nodes.nodes) and np.array_equal(faces.weights, nodes.weights)


def _write(path, text: str):
    path.write_text(text)
    return path
