"""Node and element sets that name numbers the deck does not have are refused (bladecase/fe/cdb.py,
bladecase/fe/abaqus.py).

Before, an ANSYS component ``1, -1000000000`` (nodes 1 to 1e9) over an 8-node cube was read as "every node", an
element component naming an element that does not exist lost it silently, and an Abaqus ``*NSET, GENERATE`` was
expanded in full before any check. Now each is an error naming the file, the line, the set, the number or range and
the file's numbering ("the file has 8 nodes, numbered 1 to 8"); a range is checked before it is expanded. Gaps of a
gappy numbering inside a range are skipped, as ANSYS and CalculiX do; the CLI says so in one line and exits 2.
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import pytest

from bladecase.cli import main
from bladecase.fe import load_mesh
from bladecase.fe.abaqus import AbaqusError
from bladecase.fe.cdb import CdbError

CUBE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
NUMBERING = "the file has 8 nodes, numbered 1 to 8"


# ----------------------------------------------------------------------------- ANSYS archives (.cdb)


def cmblock(name: str, kind: str, entries) -> str:
    """A CMBLOCK in (8i12) layout, wide enough for -1000000000 (a negative entry closes a range: ``1, -10`` is 1
    to 10)."""
    rows = [entries[k:k + 8] for k in range(0, len(entries), 8)]
    return (f"CMBLOCK,{name},{kind},{len(entries):8d}\n(8i12)\n"
            + "".join("".join(f"{v:12d}" for v in row) + "\n" for row in rows))


def cube_cdb(folder: Path, *components: str, name: str = "cube.cdb") -> Path:
    """A unit cube of one SOLID185 brick (nodes 1 to 8, element 1) followed by ``components``."""
    nodes = "".join(f"{k:10d}{0:10d}{0:10d}" + "".join(f"{float(c):21.13E}" for c in p) + "\n"
                    for k, p in enumerate(CUBE, start=1))
    brick = "".join(f"{v:10d}" for v in [1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, *range(1, 9)])
    path = folder / name
    path.write_text(f"ET,1,185\nNBLOCK,6,SOLID,8,8\n(3i10,6e21.13e3)\n{nodes}N,R5.3,LOC,-1,\n"
                    f"EBLOCK,19,SOLID,1,1\n(19i10)\n{brick}\n        -1\n" + "".join(components))
    return path


def test_cdb_node_range_far_beyond_the_nodes_is_refused(tmp_path):
    path = cube_cdb(tmp_path, cmblock("ROOT", "NODE", [1, -1_000_000_000]))
    with pytest.raises(CdbError) as err:
        load_mesh(path)
    message = str(err.value)
    assert "cube.cdb" in message and "'ROOT'" in message and "1..1000000000" in message, message
    assert NUMBERING in message, message


def test_cdb_single_missing_node_is_refused(tmp_path):
    path = cube_cdb(tmp_path, cmblock("TIP", "NODE", [5, 6, 9]))
    with pytest.raises(CdbError, match=r"cube.cdb', line 19: component 'TIP' names node 9, which the file does "
                                       rf"not have \({NUMBERING}\)"):
        load_mesh(path)


def test_cdb_element_component_with_a_missing_element_is_refused(tmp_path):
    m = load_mesh(cube_cdb(tmp_path, cmblock("BASE", "NODE", [1, -4]), cmblock("ALL", "ELEM", [1]), name="ok.cdb"))
    assert m.group("BASE").tolist() == [0, 1, 2, 3] and m.group("ALL").tolist() == list(range(8))
    path = cube_cdb(tmp_path, cmblock("BLADE", "ELEM", [1, 2]))
    with pytest.raises(CdbError, match=r"component 'BLADE' names element 2, which the file does not have \(the file "
                                       r"has 1 element, numbered 1 to 1\)"):
        load_mesh(path)
    with pytest.raises(CdbError, match=r"component 'HUB' names elements 1..7, .*\(the file has 1 element"):
        load_mesh(cube_cdb(tmp_path, cmblock("HUB", "ELEM", [1, -7]), name="hub.cdb"))


# ----------------------------------------------------------------------------- Abaqus / CalculiX decks (.inp)


def cube_inp(folder: Path, tail: str, ids=range(1, 9), name: str = "cube.inp") -> Path:
    """A unit cube of one C3D8 brick, its nodes numbered ``ids``, followed by ``tail``."""
    ids = list(ids)
    nodes = "".join(f"{k}, {x}, {y}, {z}\n" for k, (x, y, z) in zip(ids, CUBE))
    path = folder / name
    path.write_text(f"*NODE, NSET=NALL\n{nodes}*ELEMENT, TYPE=C3D8, ELSET=EALL\n1, "
                    + ", ".join(map(str, ids)) + "\n" + tail)
    return path


def test_inp_generate_beyond_the_last_node_is_refused_before_it_is_expanded(tmp_path):
    path = cube_inp(tmp_path, "*NSET, NSET=ROOT, GENERATE\n1, 2000000, 1\n")
    tracemalloc.start()
    try:
        with pytest.raises(AbaqusError) as err:
            load_mesh(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    message = str(err.value)
    assert "cube.inp', line 13" in message and "'ROOT'" in message and "1..2000000" in message, message
    assert NUMBERING in message, message
    assert peak < 20e6, f"{peak / 1e6:.0f} MB: the range was expanded"


def test_inp_plain_nset_with_a_missing_node_is_refused(tmp_path):
    path = cube_inp(tmp_path, "*NSET, NSET=TIP\n5, 6,\n7, 12\n")
    with pytest.raises(AbaqusError, match=r"cube.inp', line 14: \*NSET 'TIP' names node 12, which the file does not "
                                          rf"have \({NUMBERING}\)"):
        load_mesh(path)


def test_inp_elset_with_a_missing_element_is_refused(tmp_path):
    path = cube_inp(tmp_path, "*ELSET, ELSET=BLADE\n1, 3\n")
    with pytest.raises(AbaqusError, match=r"line 13: \*ELSET 'BLADE' names element 3, which the file does not have "
                                          r"\(the file has 1 element, numbered 1 to 1\)"):
        load_mesh(path)
    with pytest.raises(AbaqusError, match=r"line 13: \*NSET 'TOP' names elements 1..4, beyond .*numbered 1 to 1\)"):
        load_mesh(cube_inp(tmp_path, "*NSET, NSET=TOP, ELSET, GENERATE\n1, 4\n", name="top.inp"))


def test_inp_boundary_with_a_missing_node_is_refused(tmp_path):
    path = cube_inp(tmp_path, "*BOUNDARY\n1, 1, 3\n99, 1, 3\n")
    with pytest.raises(AbaqusError, match=r"cube.inp', line 14: \*BOUNDARY names node 99, which the file does not "
                                          rf"have \({NUMBERING}\)"):
        load_mesh(path)


def test_inp_generate_over_gappy_numbering_skips_the_gaps(tmp_path):
    """Nodes 1, 3, …, 15: ``1, 15`` names the eight of them (the even numbers are gaps, skipped as CalculiX does);
    ``1, 17`` reaches beyond node 15, and ``2, 14, 2`` names none of them."""
    odd = range(1, 16, 2)
    m = load_mesh(cube_inp(tmp_path, "*NSET, NSET=ALL, GENERATE\n1, 15\n*BOUNDARY\nALL, 1, 3\n", ids=odd))
    assert m.group("ALL").tolist() == m.group("boundary_fixed").tolist() == list(range(8))
    with pytest.raises(AbaqusError, match=r"names nodes 1..17, .*\(the file has 8 nodes, numbered 1 to 15\)"):
        load_mesh(cube_inp(tmp_path, "*NSET, NSET=ALL, GENERATE\n1, 17\n", ids=odd, name="over.inp"))
    with pytest.raises(AbaqusError, match=r"\*NSET 'EVEN' names nodes 2..14 step 2, none of which the file has"):
        load_mesh(cube_inp(tmp_path, "*NSET, NSET=EVEN, GENERATE\n2, 14, 2\n", ids=odd, name="even.inp"))


# ----------------------------------------------------------------------------- the command line


def test_cli_mesh_of_an_archive_naming_missing_nodes_exits_2_and_writes_nothing(tmp_path, capsys):
    cube_cdb(tmp_path, cmblock("ROOT", "NODE", [1, -1_000_000_000]), name="bad.cdb")
    study = tmp_path / "study.toml"
    study.write_text('[mesh]\npath = "bad.cdb"\n[material]\npreset = "steel"\n[fem]\norder = 1\nclamp = "ROOT"\n'
                     '[contact]\nclearance = 1e-4\nnormal = [0, 0, 1]\nnearest = [1, 1, 1]\n')
    out = tmp_path / "out.vtu"
    code = main(["mesh", str(study), "-o", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and "'ROOT'" in lines[0] and "1..1000000000" in lines[0] and NUMBERING in lines[0], err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bad.cdb", "study.toml"]


def test_bdf_element_naming_a_missing_grid_is_named(tmp_path):
    """meshio's bare ``KeyError: 99`` becomes the GRID the element names and the deck lacks."""
    deck = tmp_path / "bad.bdf"
    deck.write_text("BEGIN BULK\n"
                    "GRID           1              0.      0.      0.\n"
                    "GRID           2              1.      0.      0.\n"
                    "GRID           3              0.      1.      0.\n"
                    "GRID           4              0.      0.      1.\n"
                    "CTETRA         1       1       1       2       3      99\n"
                    "ENDDATA\n")
    with pytest.raises(ValueError, match="an element names GRID 99, which the deck does not define"):
        load_mesh(deck)
