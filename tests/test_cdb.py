"""ANSYS archive files (.cdb) through bladecase.fe.load_mesh (bladecase/fe/cdb.py).

Real archives (tests/data/README.md): HexBeam.cdb (ANSYS-written, 321 nodes, 40 SOLID186 bricks, two node and two
element components), HexBeam185.cdb (the same 1 × 1 × 5 beam with 40 SOLID185 bricks), ErnoRadiation.cdb
(Workbench, 27 SOLID70 bricks and 9 SURF152 surface elements, fields run together, trailing zero coordinates left
out), all_solid_cells.cdb (degenerate SOLID186 forms, a pyramid among them). Checked: counts and component sizes
(the ranges expanded), the cantilever's first frequency against Timoshenko (+1.37 % ± 0.3 %, the figure of the
same 10 × 2 × 2 hex20 discretisation in test_fe_elements.py), the SOLID185 and SOLID186 archives and the .vtu
round trip giving the same frequency (1e-9), a hand-written SOLID186 cantilever with ROOT/TIP components
(clamp="ROOT", Euler–Bernoulli +1.02 %, .vtu identical), degenerate bricks and PLANE183 in VTK order, and errors
naming file and line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_fe_elements import STEEL, euler_bernoulli, hex_beam, timoshenko
from test_fe_elements import first_frequency as beam_frequency

import bladecase as bc
from bladecase.fe import load_mesh, natural_frequencies, save_mesh
from bladecase.fe.cdb import read_cdb

DATA = Path(__file__).parent / "data"
ROOT_Z = {"plane": [0, 0, 0, 0, 0, 1]}


def first_frequency(mesh) -> float:
    return natural_frequencies(bc.assemble(mesh, STEEL, order=2, clamp=ROOT_Z), 1)[0]


def test_hex_beam_archive_and_its_components():
    m = load_mesh(DATA / "HexBeam.cdb")
    assert m.body_type == "hexahedron20" and len(m.cells["hexahedron20"]) == 40 and len(m.points) == 321
    np.testing.assert_allclose(m.points.min(axis=0), [0, 0, 0]) and np.testing.assert_allclose(
        m.points.max(axis=0), [1, 1, 5])
    sizes = {k: len(m.group(k)) for k in ("ECOMP1", "ECOMP2", "NCOMP2", "NODE_SELECTION")}
    # NCOMP2: 1-21, 43-47, … (42 entries, ranges expanded: 98 nodes); element components: the nodes of 22 elements
    assert sizes == {"ECOMP1": 190, "ECOMP2": 190, "NCOMP2": 98, "NODE_SELECTION": 164}
    assert m.group("NCOMP2")[:21].tolist() == list(range(21))  # ANSYS nodes 1…21 are the first 21 of the NBLOCK


def test_cantilever_from_two_archives_against_timoshenko():
    """SOLID186 and SOLID185 archives of one beam: the same corners, hence the same order-2 model (1e-9); against
    Timoshenko (L/h = 5) +1.37 % like the same discretisation built in numpy; the .vtu round trip changes nothing."""
    f186 = first_frequency(load_mesh(DATA / "HexBeam.cdb"))
    f185 = first_frequency(load_mesh(DATA / "HexBeam185.cdb"))
    assert f185 == pytest.approx(f186, rel=1e-9)
    assert f186 / timoshenko(5.0, 1.0) - 1 == pytest.approx(0.0137, abs=0.003)


def test_round_trip_through_vtu_keeps_mesh_and_components(tmp_path):
    m = load_mesh(DATA / "HexBeam.cdb")
    save_mesh(m, tmp_path / "beam.vtu")
    back = load_mesh(tmp_path / "beam.vtu", require=("NCOMP2",))
    assert np.array_equal(back.group("NCOMP2"), m.group("NCOMP2"))
    assert first_frequency(back) == pytest.approx(first_frequency(m), rel=1e-12)


def test_workbench_archive_with_surface_elements(caplog):
    with caplog.at_level("INFO", logger="bladecase"):
        raw = read_cdb(DATA / "ErnoRadiation.cdb")
        m = load_mesh(DATA / "ErnoRadiation.cdb")
    assert raw.field_data["ansys:types"] == {"70": 27, "152": 9}
    # pymapdl-reader's own test_rlblock_prior_to_nblock: n_node == 65, n_elem == 36
    assert len(raw.points) == 65 and sum(raw.field_data["ansys:types"].values()) == 36
    assert "left out 9 element(s) of type 152" in caplog.text
    assert m.body_type == "hexahedron" and len(m.cells["hexahedron"]) == 27 and len(m.points) == 65
    assert m.points[27].tolist() == [0.0, 0.0, 0.0]  # node 28: "0.0E+000" alone, y and z left out
    assert m.points[0].tolist() == pytest.approx([0.066, 0.066, -0.066])  # fields run together: "…E-002-6.6…"
    # the element component of the 9 surface elements becomes the nodes they use; node 65 is only theirs
    assert len(m.group("INTERFACE")) == 16 and m.group("_SPND56").tolist() == [64]
    assert set(m.group("_ELMISC")) == set(m.group("INTERFACE")) | {64}


def test_a_pyramid_is_refused_with_its_line():
    with pytest.raises(ValueError, match=r"all_solid_cells.cdb', line \d+: element \d+ \(type 186\) is a pyramid"):
        load_mesh(DATA / "all_solid_cells.cdb")


HEAD = "ET,1,{t}\nNBLOCK,6,SOLID\n(3i9,6e21.13e3)\n{nodes}N,R5.3,LOC,-1,\nEBLOCK,19,SOLID\n(19i9)\n{elems}       -1\n"


def archive(tmp_path, etype: int, points, elements, name="x.cdb") -> Path:
    nodes = "".join(f"{k + 1:9d}{0:9d}{0:9d}" + "".join(f"{c:21.13E}" for c in p) + "\n" for k, p in enumerate(points))
    elems = ""
    for e, conn in enumerate(elements, start=1):
        fields = [1, 1, 1, 1, 0, 0, 0, 0, len(conn), 0, e] + list(conn)
        lines = [fields[:19]] + [fields[19 + 19 * k: 38 + 19 * k] for k in range((len(fields) - 1) // 19)]
        elems += "".join("".join(f"{v:9d}" for v in line) + "\n" for line in lines if line)
    path = tmp_path / name
    path.write_text(HEAD.format(t=etype, nodes=nodes, elems=elems))
    return path


PRISM = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)]


def test_degenerate_bricks_become_wedges_and_tetrahedra(tmp_path):
    # SOLID185 I J K L M N O P with K = L, O = P: the wedge I J K / M N O
    m = read_cdb(archive(tmp_path, 185, PRISM, [(1, 2, 3, 3, 4, 5, 6, 6)]))
    assert m.cells[0].type == "wedge" and m.cells[0].data.tolist() == [[0, 1, 2, 3, 4, 5]]
    assert load_mesh(archive(tmp_path, 185, PRISM, [(1, 2, 3, 3, 4, 5, 6, 6)], "w.cdb")).body_type == "wedge"
    tet = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    m = read_cdb(archive(tmp_path, 185, tet, [(1, 2, 3, 3, 4, 4, 4, 4)]))
    assert m.cells[0].type == "tetra" and m.cells[0].data.tolist() == [[0, 1, 2, 3]]
    # SOLID186 prism: corners I J K M N O, edges Q R T (bottom), U V X (top), Y Z A (vertical) in VTK order
    mid = {(a, b): tuple((np.add(PRISM[a], PRISM[b]) / 2).tolist()) for a, b in
           ((0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5))}
    pts = PRISM + list(mid.values())
    ij, jk, ki, mn, no, om, im, jn, ko = range(7, 16)  # 1-based node numbers of the midside nodes
    brick = (1, 2, 3, 3, 4, 5, 6, 6, ij, jk, 3, ki, mn, no, 6, om, im, jn, ko, ko)
    m = read_cdb(archive(tmp_path, 186, pts, [brick]))
    assert m.cells[0].type == "wedge15" and m.cells[0].data.tolist() == [list(range(15))]
    assert load_mesh(archive(tmp_path, 186, pts, [brick], "w15.cdb")).body_type == "wedge15"


ONE_NODE = "        1        0        0\n"


def record(itype: int, nodes) -> str:
    """One 8-node element record of the solid EBLOCK format (19i9)."""
    return "".join(f"{v:9d}" for v in [1, itype, 1, 1, 0, 0, 0, 0, 8, 0, 1, *nodes]) + "\n"


@pytest.mark.parametrize("text, message", [
    ("ET,1,185\nEBLOCK,19,SOLID\n(19i9)\n       -1\n", "has no NBLOCK"),
    ("NBLOCK,6,SOLID\n(3i9,6e21.13e3)\n        1        0        0 1.0\n", "has no end"),
    ("NBLOCK,6,SOLID\nnot a format\n", "line 2: expected a Fortran format"),
    ("NBLOCK,6,SOLID\n(3i9,6e21.13e3)\n        1        0        0 one\n-1\n", "line 3: not a node record"),
    (HEAD.format(t=185, nodes=ONE_NODE, elems=record(2, [1] * 8)),
     "line 8: element 1 has type 2, which no ET record defines"),
    (HEAD.format(t=185, nodes=ONE_NODE, elems=record(1, range(1, 9))),
     "element 1 uses node 2, which the NBLOCK does not define"),
    (HEAD.format(t=181, nodes=ONE_NODE, elems=""), "has no solid element bladecase reads"),
])
def test_bad_archives_are_named_with_their_line(tmp_path, text, message):
    path = tmp_path / "bad.cdb"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as err:
        load_mesh(path)
    assert "bad.cdb" in str(err.value)


def cmblock(name: str, kind: str, entries) -> str:
    """A CMBLOCK in ANSYS's (8i10) layout; ``entries`` as ANSYS writes them (a negative number closes a range)."""
    rows = [entries[k:k + 8] for k in range(0, len(entries), 8)]
    return (f"CMBLOCK,{name},{kind},{len(entries):8d}\n(8i10)\n"
            + "".join("".join(f"{v:10d}" for v in row) + "\n" for row in rows))


def test_hand_written_solid186_cantilever_clamped_by_its_root_component(tmp_path):
    """A 10 × 1 × 1 SOLID186 cantilever (L/h = 20) with a ROOT and a TIP node component given as ranges and a
    TIPEL element component: clamp="ROOT" by name, f1 against Euler–Bernoulli (+1.02 % ± 0.2 %, inside the 0…1.25 %
    band of this hex20 discretisation in test_fe_elements.py, and equal to the same mesh built there) and identical
    to the same mesh written as .vtu."""
    L, h = 0.1, 0.005
    beam = hex_beam(L, h, (10, 1, 1), "hexahedron20")  # VTK order, which is ANSYS's I…P, Q…T, U…X, Y…B
    x = beam.points[:, 0]
    root, tip = np.flatnonzero(x == 0) + 1, np.flatnonzero(np.isclose(x, L)) + 1
    assert np.all(np.diff(root) == 1) and np.all(np.diff(tip) == 1)  # contiguous: written as ranges
    last = int(np.argmax(beam.points[beam.cells[0].data].mean(axis=1)[:, 0])) + 1
    path = archive(tmp_path, 186, beam.points, beam.cells[0].data + 1, "cantilever.cdb")
    path.write_text(path.read_text() + cmblock("ROOT", "NODE", [root[0], -root[-1]])
                    + cmblock("TIP", "NODE", [tip[0], -tip[-1]]) + cmblock("TIPEL", "ELEM", [last]))
    m = load_mesh(path, require=("ROOT", "TIP", "TIPEL"))
    assert m.body_type == "hexahedron20" and m.cells["hexahedron20"].tolist() == beam.cells[0].data.tolist()
    assert len(m.group("ROOT")) == len(root) == 8 and np.all(m.points[m.group("TIP"), 0] == pytest.approx(L))
    assert len(m.group("TIPEL")) == 20 and set(m.group("TIP")) < set(m.group("TIPEL"))
    f = natural_frequencies(bc.assemble(m, STEEL, order=2, clamp="ROOT"), 3)
    assert f[0] / euler_bernoulli(L, h) - 1 == pytest.approx(0.0102, abs=0.002)
    assert f[0] == pytest.approx(beam_frequency(beam, 2), rel=1e-9)  # = the mesh built in numpy, plane-clamped
    assert f[1] == pytest.approx(f[0], rel=1e-6)  # square section: the two bending modes coincide
    save_mesh(m, tmp_path / "cantilever.vtu")
    back = load_mesh(tmp_path / "cantilever.vtu", require=("ROOT", "TIP"))
    np.testing.assert_allclose(natural_frequencies(bc.assemble(back, STEEL, order=2, clamp="ROOT"), 3), f,
                               rtol=1e-12)


def test_plane183_quadrilaterals_and_their_triangles(tmp_path):
    """PLANE183 I J K L M N O P (corners, then mid-edges IJ JK KL LI): an 8-node quadrilateral as it is; with
    K = L = O the 6-node triangle I J K with mid-edges M, N, P."""
    square = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0, 0), (1, 0.5, 0), (0.5, 1, 0), (0, 0.5, 0)]
    m = load_mesh(archive(tmp_path, 183, square, [range(1, 9)]))
    assert m.dim == 2 and m.body_type == "quad8" and m.cells["quad8"].tolist() == [list(range(8))]
    tri = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0.5, 0, 0), (0.5, 0.5, 0), (0, 0.5, 0)]
    m = read_cdb(archive(tmp_path, 183, tri, [(1, 2, 3, 3, 4, 5, 3, 6)], "t.cdb"))
    assert m.cells[0].type == "triangle6" and m.cells[0].data.tolist() == [[0, 1, 2, 3, 4, 5]]
