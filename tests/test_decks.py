"""Industrial FE decks read as they are: a CalculiX/Abaqus cantilever in millimetres (an ``*INCLUDE``d mesh of
C3D20R hexahedra or C3D15 wedges, node numbers 1001, 1003, … written out of order, the root clamp as a ``*BOUNDARY``
node list, a ``*NSET`` for the tip), the length unit of the mesh, node numbers as in the file in every message,
clamps and contact faces given as node lists, and the plausibility warning of a unit slip.

The beam: 200 mm × 10 mm × 10 mm steel, 20 × 2 × 2 quadratic cells; Euler–Bernoulli f1 = 203.85 Hz. At order 2
the hexahedra give +0.30 % (shear and the clamped root's Poisson stiffening), so f1 is checked within 1 %.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_fe_elements import WEDGES, box, euler_bernoulli, hex_beam, split
from test_wedge2 import quadratic

from bladecase import log
from bladecase.fe import Material, load_mesh, natural_frequencies, save_mesh
from bladecase.fe.abaqus import AbaqusError
from bladecase.study import stages
from bladecase.study.schema import StudyError, loads

L_MM, H_MM, CELLS = 200.0, 10.0, (20, 2, 2)
STEEL = Material.preset("steel")
F_EB = euler_bernoulli(L_MM * 1e-3, H_MM * 1e-3, STEEL)  # 203.85 Hz


def write_deck(folder: Path, btype: str = "hexahedron20", etype: str = "C3D20R", mesh_name: str = "beam.msh",
               boundary: str = "nodes") -> dict:
    """``beam.inp`` (``*INCLUDE, INPUT=<mesh_name>``, material, ``*NSET`` Ntip, ``*BOUNDARY`` of the root) and the
    mesh file in CalculiX syntax, in millimetres; node numbers 1001 + 2k written in a shuffled order."""
    m = (box((L_MM, H_MM, H_MM), CELLS, btype) if btype.startswith("hex")
         else quadratic(split(hex_beam(L_MM, H_MM, CELLS), WEDGES), btype))
    pts, cells = m.points, m.cells[0].data
    ids = 1001 + 2 * np.arange(len(pts))
    lines = ["** written like CalculiX's cgx: mm", "*NODE, NSET=Nall"]
    lines += [f"{ids[k]}, {pts[k, 0]:.10g}, {pts[k, 1]:.10g}, {pts[k, 2]:.10g}"
              for k in np.random.default_rng(1).permutation(len(pts))]
    lines.append(f"*ELEMENT, TYPE={etype}, ELSET=Eall")
    for e, row in enumerate(cells):
        items = [str(e + 1)] + [str(ids[v]) for v in row]  # 16 numbers a line, then a continuation line
        lines += [", ".join(items[i:i + 16]) + ("," if i + 16 < len(items) else "") for i in range(0, len(items), 16)]
    (folder / mesh_name).write_text("\n".join(lines) + "\n")
    root, tip = ids[pts[:, 0] == 0], ids[pts[:, 0] == L_MM]
    deck = ["*HEADING", "cantilever in mm", f"*INCLUDE, INPUT={mesh_name}", "*NSET, NSET=Ntip"]
    deck += [", ".join(map(str, tip[i:i + 8])) for i in range(0, len(tip), 8)]
    deck += ["*MATERIAL, NAME=STEEL", "*ELASTIC", "200000, 0.3", "*DENSITY", "7.85e-9",
             "*SOLID SECTION, ELSET=Eall, MATERIAL=STEEL", "*BOUNDARY"]
    deck += [f"{k}, 1, 3" for k in root] if boundary == "nodes" else ["Nroot, 1, 3"]
    deck += ["*STEP", "*FREQUENCY", "6", "*NODE FILE", "U", "*END STEP"]
    if boundary != "nodes":
        deck[3:3] = ["*NSET, NSET=Nroot"] + [f"{k}," for k in root]
    (folder / "beam.inp").write_text("\n".join(deck) + "\n")
    return {"points": pts, "ids": ids, "root": root, "tip": tip}


def study(folder: Path, mesh: str = 'path = "beam.inp"\nunit = "mm"', fem: str = 'clamp = "boundary"',
          contact: str = "nearest = [0.2, 0.01, 0.01]") -> str:
    return f"""
[mesh]
{mesh}
[material]
preset = "steel"
[fem]
order = 2
{fem}
[contact]
clearance = 1e-4
normal = [0, 0, 1]
{contact}
"""


def model_of(folder: Path, text: str):
    st = loads(text, base=folder)
    with log.transcript() as lines:
        mesh = stages.build_mesh(st)
        model = stages.build_model(st, mesh)
    return st, mesh, model, lines


@pytest.fixture(scope="module")
def deck(tmp_path_factory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("deck")
    return folder, write_deck(folder)


# ----------------------------------------------------------------------------- the deck as it is


def test_calculix_deck_in_mm_clamped_by_its_boundary(deck):
    folder, d = deck
    st, mesh, model, lines = model_of(folder, study(folder))
    # every node of the file (21·3·3 corners + 540 midside nodes), numbered as in the file
    assert len(mesh.points) == len(d["ids"]) == 621 and mesh.body_type == "hexahedron20"
    assert mesh.numbering == "file" and sorted(mesh.node_ids.tolist()) == d["ids"].tolist()
    assert mesh.unit == "mm" and np.ptp(mesh.points[:, 0]) == pytest.approx(0.2, rel=1e-12)
    # the root face: 9 corners + 12 midside nodes, all 21 in the deck's *BOUNDARY and all held by the clamp
    assert sorted(mesh.node_ids[mesh.group("boundary")].tolist()) == sorted(d["root"].tolist())
    assert len(d["root"]) == 21 and model.clamped.size == 9
    assert any("clamp 'boundary': 21 nodes held fixed (9 corner nodes, 12 midside or face nodes)" in x for x in lines)
    assert model.total_mass == pytest.approx(7850 * 0.2 * 0.01 * 0.01, rel=1e-12)
    f1 = natural_frequencies(model, 1)[0]
    assert abs(f1 / F_EB - 1) < 0.01, (f1, F_EB)  # +0.30 %
    assert not any("implausible" in x for x in lines)


def test_groups_of_the_deck(deck):
    folder, d = deck
    mesh = load_mesh(folder / "beam.inp", unit="mm")
    assert sorted(mesh.groups) == ["Eall", "Nall", "Ntip", "boundary", "boundary_1_3", "boundary_fixed"]
    assert sorted(mesh.node_ids[mesh.group("Ntip")].tolist()) == sorted(d["tip"].tolist())
    assert len(mesh.group("Eall")) == len(mesh.group("Nall")) == 621


def test_calculix_msh_in_abaqus_syntax_reads_by_content(deck):
    folder, d = deck
    mesh = load_mesh(folder / "beam.msh", unit="mm")
    assert mesh.body_type == "hexahedron20" and len(mesh.points) == 621 and "Nall" in mesh.groups
    np.testing.assert_allclose(np.ptp(mesh.points, axis=0), [0.2, 0.01, 0.01], rtol=1e-12)
    # a CalculiX wedge mesh (C3D15) as .msh, its clamp a *BOUNDARY on a node set: f1 within 1 %
    wedges = folder / "wedges"
    wedges.mkdir()
    w = write_deck(wedges, "wedge15", "C3D15", "blade.msh", boundary="set")
    _, mesh, model, _ = model_of(wedges, study(wedges))  # beam.inp includes blade.msh
    assert mesh.body_type == "wedge15" and len(mesh.group("boundary")) == len(w["root"]) == 21
    assert abs(natural_frequencies(model, 1)[0] / F_EB - 1) < 0.01


def test_a_file_that_is_not_read_names_the_formats_tried(deck, tmp_path):
    folder, _ = deck
    odd = tmp_path / "beam.mesh"  # a medit suffix: meshio tries medit
    odd.write_text((folder / "beam.msh").read_text())
    with pytest.raises(ValueError, match=r"cannot read mesh file .*beam.mesh.*Formats tried: from the suffix .*"
                                         r"\[mesh\] format \(e.g. \"abaqus\""):
        load_mesh(odd)
    assert len(load_mesh(odd, unit="mm", file_format="abaqus").points) == 621
    (tmp_path / "beam.inp").write_text((folder / "beam.inp").read_text().replace("beam.msh", "beam.mesh"))
    text = study(tmp_path, 'path = "beam.inp"\nunit = "mm"\nformat = "abaqus"')
    assert len(model_of(tmp_path, text)[1].points) == 621
    with pytest.raises(StudyError, match=r"\[mesh\] format: must be a mesh format name, e.g. 'abaqus'"):
        loads(study(tmp_path, 'path = "beam.inp"\nformat = "nastran-ish"'))


def test_missing_include_names_both_files(tmp_path):
    (tmp_path / "beam.inp").write_text("*HEADING\nbeam\n*INCLUDE, INPUT=mesh/beam.msh\n*BOUNDARY\n1, 1, 3\n")
    with pytest.raises(AbaqusError) as err:
        load_mesh(tmp_path / "beam.inp")
    assert str(err.value) == (f"Abaqus file '{tmp_path / 'beam.inp'}', line 3: *INCLUDE, INPUT=mesh/beam.msh: no such "
                              f"file '{tmp_path / 'mesh' / 'beam.msh'}' (an include is found relative to the folder "
                              "of the file that includes it)")


def test_nested_includes_relative_to_the_including_file(deck, tmp_path):
    """beam.inp → mesh/all.inp → mesh/nodes.txt (the *NODE block's data lines only) and mesh/elements.inp."""
    folder, _ = deck
    text = (folder / "beam.msh").read_text()
    cut = text.index("*ELEMENT")
    (tmp_path / "mesh").mkdir()
    (tmp_path / "mesh" / "nodes.txt").write_text(text[:cut].split("*NODE, NSET=Nall\n", 1)[1])
    (tmp_path / "mesh" / "elements.inp").write_text(text[cut:])
    (tmp_path / "mesh" / "all.inp").write_text("*NODE, NSET=Nall\n*INCLUDE, INPUT=nodes.txt\n"
                                               "*INCLUDE, INPUT=elements.inp\n")
    (tmp_path / "beam.inp").write_text((folder / "beam.inp").read_text().replace("beam.msh", "mesh/all.inp"))
    mesh = load_mesh(tmp_path / "beam.inp", unit="mm")
    assert len(mesh.points) == len(mesh.group("Nall")) == 621 and len(mesh.group("boundary")) == 21
    (tmp_path / "mesh" / "all.inp").write_text("*INCLUDE, INPUT=../beam.inp\n")
    with pytest.raises(AbaqusError, match=r"all.inp', line 1: \*INCLUDE, INPUT=../beam.inp includes .*beam.inp' "
                                          r"again"):
        load_mesh(tmp_path / "beam.inp")


def test_boundary_forms_and_sets():
    """*BOUNDARY by set names, one dof per line, ENCASTRE, a prescribed value; *NSET GENERATE; shells left out."""
    import tempfile

    text = """*NODE
10, 0, 0, 0
20, 1, 0, 0
30, 0, 1, 0
40, 0, 0, 1
50, 1, 1, 1
*ELEMENT, TYPE=C3D4, ELSET=BODY
1, 10, 20, 30, 40
*ELEMENT, TYPE=S3
2, 20, 30, 50
*NSET, NSET=base, GENERATE
10, 30, 10
*boundary
BASE, 1, 1
base, 2, 2
10, 3
20, 3, 3, 0.0
30, 3, 3, 0.5
40, ENCASTRE
"""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d, "t.inp")
        path.write_text(text)
        with log.transcript() as lines:
            mesh = load_mesh(path)
    ids = {k: mesh.node_ids[v].tolist() for k, v in mesh.groups.items()}
    assert ids["boundary"] == [10, 20, 30, 40] and ids["boundary_fixed"] == [10, 20, 40]
    assert ids["boundary_1_1"] == [10, 20, 30] and ids["boundary_3_3"] == [10, 20] and ids["boundary_1_6"] == [40]
    assert ids["base"] == [10, 20, 30] and ids["BODY"] == [10, 20, 30, 40]
    assert any("1 S3 left out" in x for x in lines) and any("prescribes a displacement 0.5" in x for x in lines)
    assert any("1 of the *BOUNDARY nodes have only some translations fixed" in x and "node 30" in x for x in lines)


def test_node_numbers_round_trip_through_vtu(deck, tmp_path):
    folder, _ = deck
    mesh = load_mesh(folder / "beam.inp", unit="mm")
    save_mesh(mesh, tmp_path / "m.vtu")
    back = load_mesh(tmp_path / "m.vtu")
    np.testing.assert_array_equal(back.node_ids, mesh.node_ids)
    save_mesh(mesh, tmp_path / "m.inp")
    again = load_mesh(tmp_path / "m.inp")
    np.testing.assert_array_equal(again.node_ids, mesh.node_ids)
    np.testing.assert_array_equal(again.cells["hexahedron20"], mesh.cells["hexahedron20"])


# ----------------------------------------------------------------------------- clamps and contacts by node numbers


def test_clamp_as_node_list_and_node_file(deck, tmp_path):
    folder, d = deck
    f_ref = natural_frequencies(model_of(folder, study(folder))[2], 1)[0]
    listed = "clamp = {nodes = [" + ", ".join(map(str, d["root"])) + "]}"
    _, _, model, lines = model_of(folder, study(folder, fem=listed))
    assert natural_frequencies(model, 1)[0] == pytest.approx(f_ref, rel=1e-10)
    assert any("21 nodes held fixed" in x for x in lines)
    (folder / "root.txt").write_text("# the root face\n" + "\n".join(
        ", ".join(map(str, d["root"][i:i + 5])) for i in range(0, 21, 5)) + "\n")
    _, _, model, _ = model_of(folder, study(folder, fem='clamp = {nodes_file = "root.txt"}'))
    assert natural_frequencies(model, 1)[0] == pytest.approx(f_ref, rel=1e-10)


def test_clamp_node_not_in_the_file_is_named(deck):
    folder, d = deck
    with pytest.raises(StudyError) as err:
        model_of(folder, study(folder, fem=f"clamp = {{nodes = [{d['root'][0]}, 1002]}}"))
    assert str(err.value) == f"[fem] clamp: node 1002 is not a node of mesh {folder / 'beam.inp'} (621 nodes " \
                             "numbered 1001 to 2241)"
    (folder / "bad.txt").write_text(f"{d['root'][0]}\n{d['root'][1]} 77\n")
    with pytest.raises(StudyError, match=r"^\[fem\] clamp: node 77 \(bad.txt, line 2\) is not a node of mesh"):
        model_of(folder, study(folder, fem='clamp = {nodes_file = "bad.txt"}'))
    (folder / "bad.txt").write_text("1001\nroot\n")
    with pytest.raises(StudyError, match=r"bad.txt', line 2: 'root' is not a node number"):
        model_of(folder, study(folder, fem='clamp = {nodes_file = "bad.txt"}'))


def test_contact_by_node_number_and_node_list(deck):
    folder, d = deck
    tip = d["tip"]
    st, mesh, model, _ = model_of(folder, study(folder, contact=f"node = {tip[-1]}"))
    contact = stages.build_contact(st, model)
    assert mesh.node_id(contact.node) == tip[-1]
    assert mesh.points[contact.node].tolist() == pytest.approx([0.2, 0.01, 0.01])
    st, mesh, model, _ = model_of(folder, study(folder, contact="nodes = [" + ", ".join(map(str, tip)) + "]"))
    face = stages.build_contact(st, model)
    assert len(face.nodes) == 9 and sorted(mesh.node_ids[list(face.nodes)]) == sorted(
        k for k in tip if k in mesh.node_ids[model.dofs.node[model.dofs.node >= 0]])
    assert float(face.w(model).sum()) == pytest.approx(1.0)
    st, _, model, _ = model_of(folder, study(folder, contact=f"node = {d['root'][0]}"))
    with pytest.raises(StudyError, match=rf"^\[contact\] contact node {d['root'][0]} is clamped"):
        stages.build_contact(st, model)
    st, _, model, _ = model_of(folder, study(folder, contact="node = 5"))
    with pytest.raises(StudyError, match=r"^\[contact\] node: node 5 is not a node of mesh .* numbered 1001 to 2241"):
        stages.build_contact(st, model)


# ----------------------------------------------------------------------------- units


def test_mm_mesh_read_as_metres_is_flagged(deck):
    folder, _ = deck
    st, mesh, model, lines = model_of(folder, study(folder, 'path = "beam.inp"'))
    assert model.total_mass == pytest.approx(1.57e8, rel=1e-9)  # 1e9 × 0.157 kg
    warning = [x for x in lines if "WARNING" in x and "implausible for a blade" in x]
    assert warning and 'the mesh looks like millimetres: set [mesh] unit = "mm" (the mass would be 0.157 kg)' \
        in warning[0]
    f1 = natural_frequencies(model, 1)[0]
    assert f1 == pytest.approx(F_EB * 1e-3, rel=0.01)  # 0.204 Hz
    with log.transcript() as more:
        sentence = stages.check_plausibility(st, model, f1)
    assert f"first frequency {f1:.3g} Hz" in sentence and "the first frequency 204 Hz)" in sentence
    assert any(f"first frequency {f1:.3g} Hz" in x for x in more)
    from bladecase.post.report import _plausibility_words

    summary_model = {"total_mass_kg": model.total_mass, "linear_frequencies_hz": [f1], "dim": 3,
                     "mesh": {"source": str(mesh.source), "unit": "m"}, "material": {"E": 200e9}}
    assert 'set [mesh] unit = "mm"' in _plausibility_words(summary_model)[1]


def test_n_mm_t_material_is_refused_with_what_to_do(deck):
    folder, _ = deck
    text = study(folder).replace('preset = "steel"', "E = 200000.0\nnu = 0.3\nrho = 7.85e-9")
    with pytest.raises(StudyError) as err:
        loads(text, base=folder)
    message = str(err.value)
    assert message.startswith("[material] rho: must be a density in kg/m³ in [0.01, 100000]; 7.85e-09 looks like "
                              "t/mm³")
    assert "rho = 7850 (kg/m³)" in message and 'read the mesh in millimetres with [mesh] unit = "mm"' in message


def test_unit_must_be_known(deck):
    folder, _ = deck
    with pytest.raises(StudyError, match=r"\[mesh\] unit: must be one of 'm', 'mm', 'cm', 'in', 'ft', got 'inch'"):
        loads(study(folder, 'path = "beam.inp"\nunit = "inch"'), base=folder)


def test_report_names_the_file_node_and_millimetres():
    from bladecase.post.report import _mesh_words, _node

    assert _node({"node": 4, "node_id": 1009}) == "1009 (index 4 in `mesh.vtu`)"
    assert _node({"node": 4}) == "4"
    assert _mesh_words({"unit": "mm", "node_numbering": "file"}) == \
        "; coordinates in mm, scaled to metres; nodes numbered as in the file"


def test_plate_thickness_typed_in_metres_is_flagged():
    """A 2 mm plate typed as 2 m: 17.7 kg and the same frequencies (thickness scales K and M alike) — the warning
    comes from the thickness against the plate's size."""
    from _studies import PLATE, ROOT

    from bladecase.post.report import _plausibility_words

    _, mesh, model, lines = model_of(ROOT, PLATE.replace("thickness = 0.002", "thickness = 2.0"))
    assert model.total_mass == pytest.approx(17.72, rel=1e-3)
    assert any("WARNING [fem] thickness = 2 m is more than the plate's largest in-plane size, 0.1 m" in x
               and "thickness = 0.002" in x for x in lines)
    words = _plausibility_words({"total_mass_kg": model.total_mass, "linear_frequencies_hz": [1650.0], "dim": 2,
                                 "thickness_m": 2.0, "plane": "stress", "material": {"E": 2e11},
                                 "mesh": {"source": str(mesh.source), "extent_m": 0.1}})
    assert words == ["", "**Warning — [fem] thickness = 2 m is more than the plate's largest in-plane size, 0.1 m: "
                         "plane stress is for a thin plate; a thickness in millimetres? (2 mm is thickness = 0.002).**"]
    assert not any("thickness" in x for x in model_of(ROOT, PLATE)[3])
