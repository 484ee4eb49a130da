"""Hardened mesh input: corrupt, truncated, non-regular, out-of-scale or ill-typed inputs are refused with a
``ValueError`` naming the file (and the line and field where it makes sense), the offending value and what would be
valid; never a traceback, a hang or a silent wrong answer.

Covers ``bladecase/fe/mesh.py`` (load_mesh, from_meshio), ``groups.py``, ``cdb.py``, ``geometry.py``
(estimate_cells, the dataclasses' field types), ``assembly.py`` and ``bladecase/linalg.py`` (M = 0, non-finite
matrices, ARPACK failures).
"""

from __future__ import annotations

import dataclasses
import os
import re
import textwrap
import time
from pathlib import Path

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
from conftest import run_forked_split

import bladecase as bc
from bladecase.fe import Mesh, assemble, load_mesh, natural_frequencies
from bladecase.fe.cdb import read_cdb
from bladecase.fe.mesh import from_meshio
from bladecase.linalg import lowest_modes, spd_factor

REPO = Path(__file__).resolve().parents[1]
MESHES = REPO / "meshes"
DATA = Path(__file__).parent / "data"
TET = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) * 0.01


def _cut(src: Path, dst: Path, fraction: float) -> Path:
    data = src.read_bytes()
    dst.write_bytes(data[: int(len(data) * fraction)])
    return dst


# ----------------------------------------------------------------------------- 1. truncated / corrupt files


@pytest.mark.parametrize("name", ["plate.vtu", "plate.msh", "twisted_blade.msh", "plate.inp"])
@pytest.mark.parametrize("fraction", [0.3, 0.6, 0.9, 0.99])
def test_truncated_mesh_files_are_refused(tmp_path, name, fraction):
    path = _cut(MESHES / name, tmp_path / f"cut_{name}", fraction)
    with pytest.raises(ValueError, match=r"cut_.*(truncated|corrupt)") as err:
        load_mesh(path)
    assert str(path) in str(err.value)


def test_truncated_vtu_says_what_is_missing(tmp_path):
    path = _cut(MESHES / "plate.vtu", tmp_path / "plate.vtu", 0.6)
    with pytest.raises(ValueError, match=r"plate.vtu' is truncated or corrupt: an XML VTK file ends with its "
                                         r"closing tag </VTKFile>, this one ends after \d+ bytes"):
        load_mesh(path)


def test_truncated_gmsh_file_is_not_retried_as_ansys(tmp_path):
    path = _cut(MESHES / "plate.msh", tmp_path / "plate.msh", 0.6)
    with pytest.raises(ValueError, match=r"plate.msh' is truncated or corrupt: a gmsh file ends with .*binary data"
                       ) as err:
        load_mesh(path)
    assert "ansys" not in str(err.value)


def test_truncated_demo_mesh(tmp_path):
    """The demo's blade mesh, written as .vtu by save_mesh (the study's mesh.vtu), cut at 60 %."""
    mesh = bc.blade_mesh(bc.BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", twist_deg=40.0,
                                          lean=0.03, contact_point=(0, 0.03, 0.15)), size=0.02)
    bc.save_mesh(mesh, tmp_path / "mesh.vtu")
    assert len(load_mesh(tmp_path / "mesh.vtu").points) == len(mesh.points)
    with pytest.raises(ValueError, match="cut.vtu' is truncated or corrupt"):
        load_mesh(_cut(tmp_path / "mesh.vtu", tmp_path / "cut.vtu", 0.6))


@pytest.mark.parametrize("fraction", [0.3, 0.6, 0.9, 0.99])
def test_truncated_cdb_is_refused(tmp_path, fraction):
    path = _cut(DATA / "HexBeam.cdb", tmp_path / "cut.cdb", fraction)
    with pytest.raises(ValueError, match=r"cut.cdb.*truncated"):
        load_mesh(path)


def test_cdb_cut_at_a_line_break_inside_a_block(tmp_path):
    """Cut at a line break: no missing final newline, the block's missing end (or its count) tells."""
    lines = (DATA / "HexBeam.cdb").read_text(encoding="latin-1").splitlines(keepends=True)
    eblock = next(i for i, t in enumerate(lines) if t.startswith("EBLOCK"))
    for stop, message in [(eblock + 10, r"the EBLOCK of line 359 has no end \(-1\): the file is truncated"),
                          (eblock - 20, r"the NBLOCK of line 35 has no end"),
                          (eblock + 3, r"element \d+ lists 8 of its 20 nodes before the end of the file")]:
        path = tmp_path / "cut.cdb"
        path.write_text("".join(lines[:stop]), encoding="latin-1")
        with pytest.raises(ValueError, match=message):
            load_mesh(path)
        with pytest.raises(ValueError, match=message):
            read_cdb(path)


def test_cells_referring_to_missing_points(tmp_path):
    """A boundary cell (not only a body cell) that refers to a point the file does not have."""
    m = meshio.Mesh(TET, [("tetra", np.array([[0, 1, 2, 3]])), ("triangle", np.array([[0, 1, 7]]))])
    with pytest.raises(ValueError, match=r"mesh broken: triangle cell 0 refers to node 7, but the file has 4 points "
                                         r"\(0..3\): a truncated or corrupt file\?"):
        from_meshio(m, source="broken")


def test_point_data_shorter_than_the_points():
    m = meshio.Mesh(TET, [("tetra", np.array([[0, 1, 2, 3]]))], point_data={"group:root": np.ones(4, np.uint8)})
    m.point_data["group:root"] = np.ones(2, np.uint8)  # as a reader of a cut file could leave it
    with pytest.raises(ValueError, match=r"mesh short: point data 'group:root' has 2 values for 4 points"):
        from_meshio(m, source="short")


def test_cell_data_and_cell_sets_that_do_not_fit_their_cells():
    m = meshio.Mesh(TET, [("tetra", np.array([[0, 1, 2, 3]]))], cell_data={"gmsh:physical": [np.array([1])]})
    m.cell_data["gmsh:physical"] = [np.array([], dtype=int)]
    with pytest.raises(ValueError, match=r"cell data 'gmsh:physical' has \[0\] values for cell blocks of \[1\] cells"):
        from_meshio(m, source="cd")
    m = meshio.Mesh(TET, [("tetra", np.array([[0, 1, 2, 3]]))], cell_sets={"root": [np.array([5])]})
    with pytest.raises(ValueError, match=r"cell set 'root' refers to tetra cells outside 0..0"):
        from_meshio(m, source="cs")


def test_unmerged_mesh_with_coincident_nodes():
    """Two tetrahedra sharing a face in space but not its nodes: a crack that would lower the frequencies."""
    pts = np.vstack([TET, TET[1:4], [[0.01, 0.01, 0.01]]])  # nodes 4, 5, 6 duplicate 1, 2, 3
    m = meshio.Mesh(pts, [("tetra", np.array([[0, 1, 2, 3], [4, 5, 6, 7]]))])
    with pytest.raises(ValueError, match=r"mesh crack has 3 pair\(s\) of coincident nodes used by its tetra cells .*"
                                         r"first: nodes 1 and 4 at \[0.01, 0.0, 0.0\].*merge duplicate nodes"):
        from_meshio(m, source="crack")
    merged = meshio.Mesh(pts, [("tetra", np.array([[0, 1, 2, 3], [1, 2, 3, 7]]))])
    assert len(from_meshio(merged, source="merged").cells["tetra"]) == 2


# ----------------------------------------------------------------------------- 2. pipes and devices


def test_pipes_and_devices_are_refused_before_opening(tmp_path):
    """Run in a child process with a timeout: before the fix these hung (a FIFO) or read forever (/dev/zero).  A
    forked child (conftest's ``run_forked_split``: no interpreter start; the script reads no mesh with gmsh)."""
    fifo = tmp_path / "pipe.vtu"
    os.mkfifo(fifo)
    zero = tmp_path / "zero.vtu"
    zero.symlink_to("/dev/zero")
    script = textwrap.dedent(f"""
        from bladecase.fe import load_mesh
        from bladecase.fe.cdb import read_cdb
        for p in [{str(fifo)!r}, {str(zero)!r}, "/dev/zero", "/dev/null"]:
            try:
                load_mesh(p)
            except ValueError as e:
                print(e)
        try:
            read_cdb({str(fifo)!r})
        except ValueError as e:
            print(e)
    """)
    code, stdout, stderr = run_forked_split(script, cwd=REPO, timeout=120)
    lines = stdout.splitlines()
    assert code == 0, stderr
    assert lines[0] == f"mesh file {str(fifo)!r} is not a regular file (a pipe, device or socket): give a file on disk"
    assert lines[1] == f"mesh file {str(zero)!r} is not a regular file (a pipe, device or socket): give a file on disk"
    assert lines[2] == "mesh file '/dev/zero' is not a regular file (a pipe, device or socket): give a file on disk"
    assert "'/dev/null' is not a regular file" in lines[3]
    assert lines[4].startswith(f"ANSYS archive {str(fifo)!r} is not a regular file")


def test_folders_and_empty_files(tmp_path):
    with pytest.raises(ValueError, match=r"mesh file '.*' is a folder, not a file"):
        load_mesh(tmp_path)
    (tmp_path / "empty.vtu").write_bytes(b"")
    with pytest.raises(ValueError, match=r"empty.vtu' is empty \(0 bytes\)"):
        load_mesh(tmp_path / "empty.vtu")


# ----------------------------------------------------------------------------- 3. scales, zero mass


@pytest.fixture(scope="module")
def plate():
    return load_mesh(MESHES / "plate.vtu")


@pytest.mark.parametrize("scale, across", [(1e150, "1e+149"), (1e-150, "1e-151")])
def test_meshes_out_of_scale_are_refused_at_load_and_assembly(tmp_path, plate, scale, across):
    path = tmp_path / "scaled.vtu"
    meshio.write(path, meshio.Mesh(plate.points * scale, [("triangle", plate.cells["triangle"])]))
    from bladecase.fe.mesh import EXTENT_RANGE

    lo, hi = EXTENT_RANGE
    message = (rf"mesh {re.escape(str(path))} is {re.escape(across)} across \(bounding box .*\): its extent must "
               rf"be between {lo:g} and {hi:g} \(metres, with SI material constants\)")
    with pytest.raises(ValueError, match=message):
        load_mesh(path)
    scaled = dataclasses.replace(plate, points=plate.points * scale, source="scaled")
    with pytest.raises(ValueError, match=rf"mesh scaled is {re.escape(across)} across"):
        assemble(scaled, "steel", thickness=0.002, clamp="root")


def test_all_zero_mesh(plate):
    with pytest.raises(ValueError, match=r"mesh zero: all its 551 points coincide \(bounding box 0 x 0 x 0\)"):
        assemble(dataclasses.replace(plate, points=0 * plate.points, source="zero"), "steel", thickness=0.002)
    m = meshio.Mesh(np.zeros((4, 3)), [("tetra", np.array([[0, 1, 2, 3]]))])
    with pytest.raises(ValueError, match=r"all its 4 points coincide"):
        from_meshio(m, source="zero")


def test_zero_negative_and_non_finite_mass_give_clear_messages(plate):
    model = assemble(plate, "steel", order=1, thickness=0.002)
    zero = dataclasses.replace(model, M=sp.csr_array(model.M * 0.0))
    with pytest.raises(ValueError, match=r"^M is zero: the model has no mass \(zero density, or a mesh whose cells "
                                         r"have no volume\)$"):
        natural_frequencies(zero, 3)
    with pytest.raises(ValueError, match=r"M is not positive semidefinite: diagonal entry M\[\d+,\d+\] = -"):
        natural_frequencies(dataclasses.replace(model, M=sp.csr_array(-model.M)), 3)
    with pytest.raises(ValueError, match=r"M has \d+ non-finite entries \(inf or NaN\): the model overflowed"):
        natural_frequencies(dataclasses.replace(model, M=sp.csr_array(model.M * np.nan)), 3)
    K = model.K.copy()
    K.data[0] = np.inf
    with pytest.raises(ValueError, match=r"K has 1 non-finite entry \(inf or NaN\)"):
        spd_factor(K, "K")


def test_arpack_failures_become_value_errors():
    """A pencil ARPACK cannot handle (M of subnormal scale) reports what was being solved, not ARPACK's internals."""
    n = 50
    K = sp.diags_array([[-1.0] * (n - 1), [2.0] * n, [-1.0] * (n - 1)], offsets=[-1, 0, 1], format="csr")
    M = sp.diags_array(np.full(n, 1e-320), format="csr")
    with pytest.raises(ValueError, match=r"(eigen-solver \(ARPACK's shift-invert Lanczos\) failed on K and M|M gives "
                                         r"mode \d+ a modal mass)"):
        lowest_modes(K, M, 3, method="arpack")


# ----------------------------------------------------------------------------- 4. ANSYS archives

HEAD = ("ET,1,185\nNBLOCK,6,SOLID{ncount}\n(3i15,6e21.13e3)\n{nodes}N,R5.3,LOC,-1,\nEBLOCK,19,SOLID{ecount}\n"
        "(19i15)\n{elems}             -1\n{tail}")
CUBE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def cube_archive(tmp_path, ids=range(1, 9), fields=None, ncount="", ecount="", tail="", coords=CUBE,
                 name="bad.cdb") -> Path:
    """A one-brick SOLID185 archive with wide (i15) fields, so that any number fits."""
    nodes = "".join(f"{k:15d}{0:15d}{0:15d}" + "".join(f"{float(c):21.13E}" for c in p) + "\n"
                    for k, p in zip(ids, coords))
    fields = fields if fields is not None else [1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, *ids]
    elems = "".join(f"{v:>15}" for v in fields[:19]) + "\n" + (
        "".join(f"{v:>15}" for v in fields[19:]) + "\n" if len(fields) > 19 else "")
    path = tmp_path / name
    path.write_text(HEAD.format(nodes=nodes, elems=elems, ncount=ncount, ecount=ecount, tail=tail))
    return path


def test_huge_node_number_is_refused_with_its_line(tmp_path):
    """Node 1e13: before, an index array sized by the largest number (a 72.8 TiB MemoryError)."""
    path = cube_archive(tmp_path, ids=[1, 2, 3, 4, 5, 6, 7, 10**13])
    with pytest.raises(ValueError, match=r"^ANSYS archive '.*bad.cdb', line 11: node number \(field 1\) "
                                         r"10000000000000 is out of range \(ANSYS numbers are 1..2147483647\)$"):
        load_mesh(path)


def test_large_valid_node_numbers_cost_no_memory(tmp_path):
    """Node 2e9 (a valid ANSYS number): read by binary search, not through an array of 2e9 entries."""
    path = cube_archive(tmp_path, ids=[1, 2, 3, 4, 5, 6, 7, 2_000_000_000], name="big.cdb",
                        tail=f"CMBLOCK,ALL,NODE,2\n(8i12)\n{1:12d}{-2_000_000_000:12d}\n")
    start = time.perf_counter()
    m = load_mesh(path)
    assert time.perf_counter() - start < 5
    assert m.cells["hexahedron"].tolist() == [list(range(8))] and m.group("ALL").tolist() == list(range(8))


@pytest.mark.parametrize("fields, message", [
    ([1, "abc", 1, 1, 0, 0, 0, 0, 8, 0, 1, *range(1, 9)],
     r"line 15: field 2 \(element type\): expected an integer, got 'abc'"),
    ([1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, *range(1, 8), "x"],
     r"line 15: field 19 \(node 8\): expected an integer, got 'x'"),
    (["1.5", 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, *range(1, 9)],
     r"line 15: field 1 \(material, or -1 ending the EBLOCK\): expected an integer, got '1.5'"),
    ([1, 1, 1, 1, 0, 0, 0, 0, 10**9, 0, 1, *range(1, 9)], r"line 15: field 9 \(node count\) is 1000000000, expected "
                                                          r"1..64"),
    ([1, 1, 1, 1, 0, 0, 0, 0, 8, 0], r"line 15: not an element record of the solid EBLOCK format: 10 field\(s\)"),
    ([1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 10**12, *range(1, 9)], r"line 15: element number \(field 11\) 1000000000000 is "
                                                           r"out of range"),
])
def test_bad_eblock_fields_name_line_and_field(tmp_path, fields, message):
    with pytest.raises(ValueError, match="ANSYS archive '.*bad.cdb', " + message):
        load_mesh(cube_archive(tmp_path, fields=fields))


@pytest.mark.parametrize("kwargs, message", [
    ({"coords": CUBE[:7] + [(0, 1, "nan")]},
     r"line 11: the z coordinate of node 8 is 'NAN': coordinates must be finite"),
    ({"ids": [1, 2, 3, 4, 5, 6, 7, 7]}, r"line 11: node 7 is defined twice \(first on line 10\)"),
    ({"ncount": ",8,9"}, r"the NBLOCK of line 2 declares 9 nodes but lists 8 \(lines 4-11\): the file is corrupt or "
                         "truncated"),
    ({"ecount": ",1,2"}, r"the EBLOCK of line 13 declares 2 elements but lists 1"),
    ({"tail": "CMBLOCK,ROOT,NODE,2\n(8i10)\n        -4         5\n"},
     r"line 19: component 'ROOT': the entry -4 closes a range .* but no first number precedes it"),
    ({"tail": "CMBLOCK,ROOT,NODE,2\n(8i10)\n         1      abcd\n"},
     r"line 19: an entry of component 'ROOT': expected an integer, got 'abcd'"),
    ({"tail": "CMBLOCK,ROOT,NODE,2\n(8i10)\n         5        -3\n"}, r"line 19: component 'ROOT': the range 5..3 "
                                                                     "runs backwards"),
    ({"tail": "CMBLOCK,ROOT,NODE,x\n(8i10)\n         5\n"},
     r"line 17: the entry count of component 'ROOT': expected an integer, got 'x'"),
    ({"tail": "CMBLOCK,ROOT,ELEM,1\n(8i10)\n -99999999\n"}, r"line 19: component 'ROOT': the entry -99999999 closes"),
])
def test_bad_nblock_and_cmblock_records(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match="ANSYS archive '.*bad.cdb'(, |: )" + message):
        load_mesh(cube_archive(tmp_path, **kwargs))


def test_nblock_record_without_a_node_number(tmp_path):
    text = cube_archive(tmp_path).read_text().replace(f"{8:15d}{0:15d}", f"{'abcd':>15}{0:15d}")
    (tmp_path / "n.cdb").write_text(text)
    with pytest.raises(ValueError, match=r"n.cdb', line 11: not a node record of the NBLOCK format .*: field 1 \(node "
                                         r"number\) is 'abcd', not an integer"):
        load_mesh(tmp_path / "n.cdb")
    (tmp_path / "e.cdb").write_text("ET,1,abc\n")
    with pytest.raises(ValueError, match=r"e.cdb', line 1: the element name of ET \(e.g. 186\): expected an integer, "
                                         r"got 'abc'"):
        load_mesh(tmp_path / "e.cdb")


def test_duplicate_element_numbers(tmp_path):
    one = [1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, *range(1, 9)]
    path = cube_archive(tmp_path)
    line = "".join(f"{v:>15}" for v in one) + "\n"
    path.write_text(path.read_text().replace(line, line + line))
    with pytest.raises(ValueError, match=r"line 16: element number 1 is used twice"):
        load_mesh(path)


# ----------------------------------------------------------------------------- 5. cell-count estimate and cap


def test_estimate_cells_is_an_over_estimate_within_a_factor_3():
    plate = bc.PlateGeometry(span=0.1, chord=0.02)
    for size, tip in [(0.005, None), (0.002, 0.0005)]:
        actual = len(bc.blade_mesh(plate, size=size, tip_size=tip).cells["triangle"])
        assert actual <= bc.fe.geometry.estimate_cells(plate, size=size, tip_size=tip) <= 3 * actual
    blade = bc.BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", twist_deg=40.0)
    actual = len(bc.blade_mesh(blade, size=0.006).cells["tetra"])
    assert actual <= bc.fe.geometry.estimate_cells(blade, size=0.006) <= 3 * actual


def test_a_size_that_would_make_billions_of_cells_is_refused_before_gmsh():
    from bladecase.fe.geometry import MAX_CELLS, estimate_cells

    plate = bc.PlateGeometry(span=0.1, chord=0.02)
    assert MAX_CELLS == 2_000_000 and estimate_cells(plate, size=1e-6) > 1e9
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"^size = 1e-06 m would make about 5.2e\+09 cells \(at most 2e\+06: raise "
                                         r"\[limits\] cells \(max_cells\), or use size >= 5.1e-05 m\)$"):
        bc.blade_mesh(plate, size=1e-6)
    with pytest.raises(ValueError, match=r"tip_size = 1e-07 m would make about .* cells \(at most 1000: .* or use "
                                         r"tip_size >= "):
        bc.blade_mesh(plate, size=0.01, tip_size=1e-7, max_cells=1000)
    with pytest.raises(ValueError, match=r"size = 1e-300 m would make more than 1e300 cells"):
        bc.blade_mesh(bc.BladeGeometry(span=0.15, root_chord=0.05, naca="2412"), size=1e-300)
    assert time.perf_counter() - start < 5
    with pytest.raises(ValueError, match=r"max_cells must be an integer >= 1, got 0"):
        bc.blade_mesh(plate, max_cells=0)


# ----------------------------------------------------------------------------- 6. field types of the geometries

_BLADE = dict(span=0.15, root_chord=0.05, naca="2412")


@pytest.mark.parametrize("field, value, message", [
    ("span", "0.1", r"span must be a number \(metres\), got '0.1'"),
    ("span", True, r"span must be a number \(metres\), got True"),
    ("root_chord", [0.05], r"root_chord must be a number \(metres\), got \[0.05\]"),
    ("tip_chord", "0.03", r"tip_chord must be a number \(metres\) or omitted, got '0.03'"),
    ("twist_deg", "40", r"twist_deg must be a number \(degrees\), got '40'"),
    ("stagger_deg", None, r"stagger_deg must be a number \(degrees\), got None"),
    ("sweep", "0", r"sweep must be a number \(metres\), got '0'"),
    ("lean", False, r"lean must be a number \(metres\), got False"),
    ("trailing_edge_thickness", "0.01", r"trailing_edge_thickness must be a number \(a fraction of the chord\)"),
    ("n_sections", 5.0, r"n_sections must be an integer with 2 <= n_sections <= 200, got 5.0"),
    ("n_sections", 10**6, r"n_sections must be an integer with 2 <= n_sections <= 200, got 1000000"),
    ("naca", 2412, r"naca must be a 4-digit string such as '2412' or '0012', got 2412"),
    ("contact_point", ("0", 0, 0.15), r"contact_point must be a list of 3 numbers \(metres\), got \('0', 0, 0.15\)"),
    ("contact_point", (True, 0, 0.15), r"contact_point must be a list of 3 numbers"),
    ("contact_point", "abc", r"contact_point must be a list of 3 numbers"),
])
def test_blade_geometry_field_types(field, value, message):
    with pytest.raises(ValueError, match="^" + message):
        bc.BladeGeometry(**{**_BLADE, field: value})


def test_rectangular_blade_thickness_type():
    with pytest.raises(ValueError, match=r"^thickness must be a number \(metres\) or omitted, got '0.004'$"):
        bc.BladeGeometry(span=0.15, root_chord=0.05, thickness="0.004")


@pytest.mark.parametrize("field, value, message", [
    ("span", "0.1", r"span must be a number \(metres\), got '0.1'"),
    ("chord", None, r"chord must be a number \(metres\), got None"),
    ("taper", "1", r"taper must be a number \(tip chord / root chord\), got '1'"),
    ("sweep", [0.0], r"sweep must be a number \(metres\), got \[0.0\]"),
    ("contact_point", [0, "0.1"], r"contact_point must be a list of 2 or 3 numbers \(metres\), got \[0, '0.1'\]"),
])
def test_plate_geometry_field_types(field, value, message):
    with pytest.raises(ValueError, match="^" + message):
        bc.PlateGeometry(**{**dict(span=0.1, chord=0.02), field: value})


def test_numpy_numbers_are_still_numbers():
    g = bc.BladeGeometry(span=np.float64(0.15), root_chord=np.float32(0.05), naca="2412", n_sections=np.int64(3),
                         contact_point=np.array([0.0, 0.0, 0.15]))
    assert g.contact_point == (0.0, 0.0, 0.15)
    assert bc.PlateGeometry(span=np.float64(0.1), chord=1, contact_point=[0, 0.1]).contact_point == (0.0, 0.1)


# ----------------------------------------------------------------------------- the mesh types still read


def test_good_meshes_still_load(plate):
    assert plate.body_type == "triangle" and len(plate.points) == 551
    assert load_mesh(MESHES / "plate.msh").body_type == "triangle"
    assert load_mesh(MESHES / "plate.inp").body_type == "triangle"
    assert load_mesh(DATA / "HexBeam.cdb").body_type == "hexahedron20"
    assert isinstance(plate, Mesh)


# ----------------------------------------------------------------------------- same classes, elsewhere


@pytest.mark.parametrize("make, message", [
    (lambda: bc.BladeGeometry(span=1e150, root_chord=0.05, naca="2412"),
     r"span = 1e\+150 m is out of the range \[1e-06, 10000\] m of a blade's lengths \(a unit mistake\?\)"),
    (lambda: bc.BladeGeometry(span=0.15, root_chord=1e-150, naca="2412"), r"root_chord = 1e-150 m is out of the range"),
    (lambda: bc.BladeGeometry(span=0.15, root_chord=0.05, naca="2412", lean=-1e5),
     r"lean = -100000.0 m is out of the range \[-10000, 10000\] m"),
    (lambda: bc.PlateGeometry(span=0.1, chord=0.02, sweep=1e300), r"sweep = 1e\+300 m is out of the range"),
    (lambda: bc.PlateGeometry(span=0.1, chord=0.02, taper=1e-9), r"taper = 1e-09 makes a tip chord of 2e-11 m, out of "
                                                                 r"the range"),
])
def test_geometry_lengths_out_of_scale(make, message):
    """Before: gmsh meshed 1e150 m blades into a mesh the loader refused, reported as a RuntimeError."""
    with pytest.raises(ValueError, match="^" + message):
        make()


def test_absurd_fortran_format_in_an_archive(tmp_path):
    path = tmp_path / "fmt.cdb"
    path.write_text("NBLOCK,6,SOLID\n(999999999i9)\n")
    with pytest.raises(ValueError, match=r"fmt.cdb', line 2: the Fortran format '\(999999999i9\)' has 999999999 fields "
                                         r"\(at most 1000\)"):
        load_mesh(path)


def test_stage_file_mesh_and_model_fields_are_checked(plate):
    from bladecase.fe.mesh import mesh_from_arrays, mesh_to_arrays

    data = mesh_to_arrays(plate)
    data["mesh/groups/root"] = np.array([0, 10**6])
    with pytest.raises(ValueError, match=r"stage.npz: field 'mesh/groups/root' refers to nodes outside 0..550"):
        mesh_from_arrays(data, source="stage.npz")
    data = mesh_to_arrays(plate)
    data["mesh/points"] = data["mesh/points"][:, :2]
    with pytest.raises(ValueError, match=r"stage.npz: the mesh must have dim 2 or 3 and finite \(n, 3\) points"):
        mesh_from_arrays(data, source="stage.npz")
    model = assemble(plate, "steel", order=1, thickness=0.002)
    with pytest.raises(ValueError, match=r"K \(\(\d+, \d+\)\) and M \(\(3, 3\)\) must be square matrices of the same"):
        dataclasses.replace(model, M=sp.eye_array(3, format="csr"))
    with pytest.raises(ValueError, match=r"its dof map has .* entries for \d+ dofs"):
        dataclasses.replace(model, dofs=dataclasses.replace(model.dofs, node=model.dofs.node[:-1]))
