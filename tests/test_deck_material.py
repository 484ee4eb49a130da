"""The material a mesh file carries (``Mesh.material``; ``bladecase.fe.material.mesh_material``).

An Abaqus/CalculiX deck's ``*MATERIAL`` / ``*ELASTIC`` / ``*DENSITY`` named by the ``*SOLID SECTION`` of its body
elements, and an ANSYS archive's ``MP``/``MPDATA`` records of its solid elements' material number, read in the
file's units and converted to SI with the consistent system the mesh's length unit implies (mm: N, mm, t, s;
m: SI; in: lbf, in, lbf·s²/in, s; ft: lbf, ft, slug, s; cm: refused). References: the constants typed by hand in
SI, the conversion factors from the definitions of the units (lbf = 0.45359237 kg × 9.80665 m/s², in = 0.0254 m,
ft = 0.3048 m), and a model assembled with the material typed by hand.

The study's side — a study without ``[material]`` takes the file's material, a ``[material]`` overrides it, both
logged — goes through ``stages.material(study, mesh)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_fe_elements import box

from bladecase import log
from bladecase.fe import Material, assemble, load_mesh, natural_frequencies
from bladecase.fe.material import DEFAULT_PRESET, UNIT_SYSTEMS, material_words, mesh_material
from bladecase.study import stages
from bladecase.study.schema import StudyError, loads

#: The NASA Rotor 37 CalculiX deck's material (N, mm, t, s) and the same in SI, typed by hand.
ROTOR37_MM = {"E": 210000.0, "nu": 0.3, "rho": 9e-9}
ROTOR37_SI = Material(2.1e11, 0.3, 9000.0, "by hand")

#: A 4 × 1 × 1 cantilever of C3D20 hexahedra, 40 × 10 × 10 (mm or m, as the deck's unit says).
SIZES, CELLS = (40.0, 10.0, 10.0), (4, 1, 1)


def write_deck(path: Path, material: str, scale: float = 1.0, sections: str | None = None) -> dict:
    """A deck of :data:`CELLS` hexahedra (``C3D20``) numbered 1, 2, … in the element sets ``LEFT`` (the first two)
    and ``RIGHT``, its root as ``*BOUNDARY``, then ``material`` (keyword lines) and ``sections`` (default: one
    ``*SOLID SECTION`` of ``Eall`` with the first material named in ``material``)."""
    m = box(tuple(s * scale for s in SIZES), CELLS, "hexahedron20")
    pts, cells = m.points, m.cells[0].data
    lines = ["*HEADING", "a cantilever", "*NODE, NSET=Nall"]
    lines += [f"{k + 1}, {x!r}, {y!r}, {z!r}" for k, (x, y, z) in enumerate(pts.tolist())]
    lines.append("*ELEMENT, TYPE=C3D20, ELSET=Eall")
    for e, row in enumerate(cells.tolist()):
        items = [str(e + 1)] + [str(v + 1) for v in row]
        lines += [", ".join(items[:16]) + ",", ", ".join(items[16:])]
    lines += ["*ELSET, ELSET=LEFT", "1, 2", "*ELSET, ELSET=RIGHT, GENERATE", "3, 4, 1", "*BOUNDARY"]
    lines += [f"{k + 1}, 1, 3" for k in np.flatnonzero(pts[:, 0] == 0)]
    lines += material.strip().splitlines()
    if sections is None:  # the first material named, for every element
        names = [x.split("=")[1] for x in material.split() if x.upper().startswith("NAME=")]
        sections = f"*SOLID SECTION, ELSET=Eall, MATERIAL={names[0]}" if names else ""
    lines += sections.strip().splitlines() + ["*STEP", "*FREQUENCY", "6", "*END STEP"]
    path.write_text("\n".join(lines) + "\n")
    return {"points": pts}


def material_lines(name: str, E: float, nu: float, rho: float) -> str:
    return f"*MATERIAL, NAME={name}\n*ELASTIC\n{E!r}, {nu!r}\n*DENSITY\n{rho!r}\n"


ROTOR = material_lines("ROTOR37", **ROTOR37_MM)


def study_text(path: str, unit: str, material: str = "") -> str:
    return f"""
[mesh]
path = "{path}"
unit = "{unit}"
{material}
[fem]
order = 2
clamp = "boundary"
[contact]
clearance = 1e-4
nearest = [0.04, 0.01, 0.01]
"""


# ----------------------------------------------------------------------------- the stage


def model_of_study(folder: Path, text: str):
    """``(material, model, log lines)`` of a study, through ``stages.build_mesh`` and ``stages.build_model``."""
    st = loads(text, base=folder)
    with log.transcript() as lines:
        model = stages.build_model(st, stages.build_mesh(st))
    return model.material, model, lines


# ----------------------------------------------------------------------------- Abaqus / CalculiX decks


def test_mm_deck_material_read_and_converted_to_si(tmp_path):
    """N, mm, t, s: E 210000 MPa, rho 9e-9 t/mm³ → 2.1e11 Pa, 9000 kg/m³; the record keeps the deck's values."""
    write_deck(tmp_path / "rotor.inp", ROTOR)
    with log.transcript() as lines:
        mesh = load_mesh(tmp_path / "rotor.inp", unit="mm")
    record = mesh.material
    assert record["name"] == "ROTOR37" and record["source"] == "deck" and "problem" not in record
    assert (record["E"], record["nu"], record["rho"]) == (210000.0, 0.3, 9e-9)  # the deck's own units
    assert "*MATERIAL, NAME=ROTOR37" in record["where"] and "*SOLID SECTION" in record["where"]
    m = mesh_material(mesh)
    assert m.E == pytest.approx(2.1e11, rel=1e-12) and m.rho == pytest.approx(9000.0, rel=1e-12) and m.nu == 0.3
    assert m.name == "ROTOR37"
    assert any("material ROTOR37 for the body: E = 210000, nu = 0.3, rho = 9e-09" in x for x in lines)
    assert "N, mm, t, s" in material_words(mesh)


def test_si_deck_material_as_it_is(tmp_path):
    write_deck(tmp_path / "rotor.inp", material_lines("STEEL", 2.1e11, 0.3, 9000.0), scale=1e-3)
    m = mesh_material(load_mesh(tmp_path / "rotor.inp"))
    assert (m.E, m.nu, m.rho) == (2.1e11, 0.3, 9000.0)
    np.testing.assert_allclose([m.E, m.nu, m.rho], [ROTOR37_SI.E, ROTOR37_SI.nu, ROTOR37_SI.rho], rtol=1e-12)


def test_frequencies_with_the_deck_material_equal_the_material_typed_by_hand(tmp_path):
    write_deck(tmp_path / "rotor.inp", ROTOR)
    mesh = load_mesh(tmp_path / "rotor.inp", unit="mm")
    f_deck = natural_frequencies(assemble(mesh, mesh_material(mesh), order=2, clamp="boundary"), 4)
    f_hand = natural_frequencies(assemble(mesh, ROTOR37_SI, order=2, clamp="boundary"), 4)
    np.testing.assert_allclose(f_deck, f_hand, rtol=1e-12)
    assert 1e3 < f_hand[0] < 1e4  # a 40 mm steel-like cantilever of 10 mm: ~5 kHz, so the SI values are right


def test_study_without_material_takes_the_deck_one_and_a_material_section_overrides_it(tmp_path):
    write_deck(tmp_path / "rotor.inp", ROTOR)
    mat, model, lines = model_of_study(tmp_path, study_text("rotor.inp", "mm"))
    assert (mat.E, mat.nu, mat.rho) == pytest.approx((2.1e11, 0.3, 9000.0), rel=1e-12)
    f_hand = natural_frequencies(assemble(model.mesh, ROTOR37_SI, order=2, clamp="boundary"), 3)
    np.testing.assert_allclose(natural_frequencies(model, 3), f_hand, rtol=1e-12)
    said = [x for x in lines if "material ROTOR37: E = 2.1e+11 Pa, nu = 0.3, rho = 9000 kg/m³" in x]
    assert said and "the mesh file: *MATERIAL, NAME=ROTOR37" in said[0] and "N, mm, t, s" in said[0]
    # a [material] section replaces the deck's, and says so
    text = study_text("rotor.inp", "mm", '[material]\npreset = "Ti-6Al-4V"')
    mat, _, lines = model_of_study(tmp_path, text)
    assert mat.name == "Ti-6Al-4V"
    assert any("[material] preset = 'Ti-6Al-4V' overrides the mesh file's material ROTOR37" in x for x in lines)
    text = study_text("rotor.inp", "mm", "[material]\nE = 2.0e11\nnu = 0.29\nrho = 7800.0")
    mat, _, lines = model_of_study(tmp_path, text)
    assert (mat.E, mat.nu, mat.rho) == (2.0e11, 0.29, 7800.0)
    assert any("[material] E, nu, rho overrides the mesh file's material ROTOR37" in x for x in lines)


def test_two_materials_for_the_body_are_refused_one_used_by_all_is_taken(tmp_path):
    two = ROTOR + material_lines("DISK", 1.1e5, 0.34, 4.4e-9)
    sections = "*SOLID SECTION, ELSET=LEFT, MATERIAL=ROTOR37\n*SOLID SECTION, ELSET=RIGHT, MATERIAL=DISK"
    write_deck(tmp_path / "two.inp", two, sections=sections)
    mesh = load_mesh(tmp_path / "two.inp", unit="mm")
    with pytest.raises(ValueError) as err:
        mesh_material(mesh)
    assert "use 2 materials: ROTOR37 (2 elements), DISK (2 elements)" in str(err.value)
    assert "give [material] E, nu and rho (SI) or a preset" in str(err.value)
    with pytest.raises(StudyError, match=r"^\[material\]: not given, and the mesh file's material cannot be used: "
                                         r".*ROTOR37 \(2 elements\), DISK \(2 elements\)"):
        model_of_study(tmp_path, study_text("two.inp", "mm"))
    # the study's [material] makes the deck's irrelevant
    mat, _, _ = model_of_study(tmp_path, study_text("two.inp", "mm", '[material]\npreset = "steel"'))
    assert mat.name == "steel"
    # two materials in the deck, but every body element in one of them: that one
    write_deck(tmp_path / "one.inp", two, sections="*SOLID SECTION, ELSET=Eall, MATERIAL=DISK")
    m = mesh_material(load_mesh(tmp_path / "one.inp", unit="mm"))
    assert m.name == "DISK" and m.E == pytest.approx(1.1e11, rel=1e-12) and m.rho == pytest.approx(4400, rel=1e-12)
    # two materials and no section: which one is not said
    write_deck(tmp_path / "none.inp", two, sections="")
    with pytest.raises(ValueError, match=r"defines 2 materials \(ROTOR37, DISK\) and does not say which one"):
        mesh_material(load_mesh(tmp_path / "none.inp", unit="mm"))


def test_what_cannot_be_taken_is_named_only_when_needed(tmp_path):
    """A missing density, a table over temperatures, an orthotropic *ELASTIC: the mesh reads, the material is
    refused when a model needs it."""
    cases = {"no density": ("*MATERIAL, NAME=M\n*ELASTIC\n210000, 0.3\n", r"has no density"),
             "table": ("*MATERIAL, NAME=M\n*ELASTIC\n210000, 0.3, 20\n200000, 0.3, 400\n*DENSITY\n9e-9\n",
                       r"\*ELASTIC .* has 2 lines \(a table over temperatures\)"),
             "orthotropic": ("*MATERIAL, NAME=M\n*ELASTIC, TYPE=ENGINEERING CONSTANTS\n1, 2, 3, 4, 5, 6, 7, 8\n"
                             "9\n*DENSITY\n9e-9\n", r"TYPE=ENGINEERING CONSTANTS .*isotropic")}
    for name, (text, message) in cases.items():
        write_deck(tmp_path / "m.inp", text)
        mesh = load_mesh(tmp_path / "m.inp", unit="mm")
        assert mesh.body_type == "hexahedron20", name
        with pytest.raises(ValueError, match=message):
            mesh_material(mesh)
    # options between the elastic and the density lines (*EXPANSION) and a *DEPVAR keep the material whole
    write_deck(tmp_path / "m.inp", "*MATERIAL, NAME=M\n*ELASTIC\n210000, 0.3\n*EXPANSION\n1.2e-5\n*DENSITY\n9e-9\n")
    assert mesh_material(load_mesh(tmp_path / "m.inp", unit="mm")).rho == pytest.approx(9000, rel=1e-12)


def test_units_of_the_deck(tmp_path):
    """in: psi and lbf·s²/in⁴; ft: lbf/ft² and slug/ft³ (factors from the units' definitions); cm: refused; an
    N-mm-t deck read in metres: refused, with the unit to set."""
    lbf = 0.45359237 * 9.80665
    steel_in = material_lines("S", 30e6, 0.29, 7.33e-4)  # psi, lbf·s²/in⁴
    write_deck(tmp_path / "in.inp", steel_in, scale=1 / 25.4)
    m = mesh_material(load_mesh(tmp_path / "in.inp", unit="in"))
    assert m.E == pytest.approx(30e6 * lbf / 0.0254**2, rel=1e-12) and m.E == pytest.approx(206.84e9, rel=1e-4)
    assert m.rho == pytest.approx(7.33e-4 * lbf / 0.0254**4, rel=1e-12) and m.rho == pytest.approx(7833, rel=1e-3)
    write_deck(tmp_path / "ft.inp", material_lines("S", 30e6 * 144, 0.29, 15.2), scale=1 / 304.8)
    m = mesh_material(load_mesh(tmp_path / "ft.inp", unit="ft"))
    assert m.E == pytest.approx(30e6 * 144 * lbf / 0.3048**2, rel=1e-12)
    assert m.rho == pytest.approx(15.2 * lbf / 0.3048**4, rel=1e-12) and m.rho == pytest.approx(7834, rel=1e-3)
    write_deck(tmp_path / "cm.inp", ROTOR, scale=0.1)
    with pytest.raises(ValueError, match=r"mesh in cm, which imply no one consistent unit system .* give \[material\]"):
        mesh_material(load_mesh(tmp_path / "cm.inp", unit="cm"))
    write_deck(tmp_path / "mm.inp", ROTOR)
    with pytest.raises(ValueError, match=r'rho = 9e-09 in SI .* looks like t/mm³: .* set \[mesh\] unit = "mm"'):
        mesh_material(load_mesh(tmp_path / "mm.inp", unit="m"))
    # a density in lbm/in³ (0.283 for steel) where lbf·s²/in⁴ belongs: 3e6 kg/m³, no solid's
    write_deck(tmp_path / "lbm.inp", material_lines("S", 30e6, 0.29, 0.283), scale=1 / 25.4)
    with pytest.raises(ValueError, match=r"rho = 0.283 in lbf, in, lbf·s²/in, s is 3.02\d*e\+06 kg/m³"):
        mesh_material(load_mesh(tmp_path / "lbm.inp", unit="in"))
    assert set(UNIT_SYSTEMS) == {"m", "mm", "in", "ft"}


def test_a_mesh_without_material_keeps_the_default_preset(tmp_path):
    write_deck(tmp_path / "bare.inp", "")  # no *MATERIAL, no *SOLID SECTION
    mesh = load_mesh(tmp_path / "bare.inp", unit="mm")
    assert mesh.material is None and mesh_material(mesh) is None
    mat, _, lines = model_of_study(tmp_path, study_text("bare.inp", "mm"))
    assert mat.name == DEFAULT_PRESET == "Ti-6Al-4V"
    assert any("the default preset: no [material], none in the mesh file" in x for x in lines)


# ----------------------------------------------------------------------------- ANSYS archives


CDB = """/PREP7
ET,1,185
NBLOCK,6,SOLID,12,12
(3i4,3e12.5)
   1   0   0 0.00000E+00 0.00000E+00 0.00000E+00
   2   0   0 1.00000E+00 0.00000E+00 0.00000E+00
   3   0   0 1.00000E+00 1.00000E+00 0.00000E+00
   4   0   0 0.00000E+00 1.00000E+00 0.00000E+00
   5   0   0 0.00000E+00 0.00000E+00 1.00000E+00
   6   0   0 1.00000E+00 0.00000E+00 1.00000E+00
   7   0   0 1.00000E+00 1.00000E+00 1.00000E+00
   8   0   0 0.00000E+00 1.00000E+00 1.00000E+00
   9   0   0 0.00000E+00 0.00000E+00 2.00000E+00
  10   0   0 1.00000E+00 0.00000E+00 2.00000E+00
  11   0   0 1.00000E+00 1.00000E+00 2.00000E+00
  12   0   0 0.00000E+00 1.00000E+00 2.00000E+00
N,R5.3,LOC,       -1,
EBLOCK,19,SOLID,2,2
(19i4)
   1   1   1   1   0   0   0   0   8   0   1   1   2   3   4   5   6   7   8
{mat}   1   1   1   0   0   0   0   8   0   2   5   6   7   8   9  10  11  12
  -1
{records}
"""

#: CDWRITE's material records (MPTEMP then MPDATA,R5.0, as in tests/data/HexBeam.cdb), N-mm-t constants.
MPDATA = """MPTEMP,R5.0, 1, 1,  0.00000000    ,
MPDATA,R5.0, 1,EX  ,       1, 1,  210000.000    ,
MPTEMP,R5.0, 1, 1,  0.00000000    ,
MPDATA,R5.0, 1,NUXY,       1, 1, 0.300000000    ,
MPTEMP,R5.0, 1, 1,  0.00000000    ,
MPDATA,R5.0, 1,DENS,       1, 1, 9.000000000E-09,
MPTEMP,R5.0, 1, 1,  0.00000000    ,
MPDATA,R5.0, 1,KXX ,       1, 1,  60.5000000    ,"""


def test_cdb_material_records(tmp_path):
    path = tmp_path / "two.cdb"
    path.write_text(CDB.format(mat="   1", records=MPDATA))
    mesh = load_mesh(path, unit="mm")
    assert mesh.material["name"] == "material 1" and mesh.material["E"] == 210000.0
    m = mesh_material(mesh)
    assert m.E == pytest.approx(2.1e11, rel=1e-12) and m.nu == 0.3 and m.rho == pytest.approx(9000, rel=1e-12)
    # the command forms: MP,Lab,MAT,C0 and MPDATA,Lab,MAT,STLOC,C1 (PRXY for the Poisson ratio), in SI
    path.write_text(CDB.format(mat="   1", records="MP,EX,1,2.1E11\nMPDATA,PRXY,1,1,0.3\nMP,DENS,1,9000"))
    m = mesh_material(load_mesh(path))
    assert (m.E, m.nu, m.rho) == (2.1e11, 0.3, 9000.0)
    # the real archive: EX 7e10, NUXY 0.35, DENS 2700 (SI)
    real = mesh_material(load_mesh(Path(__file__).parent / "data" / "HexBeam.cdb"))
    assert (real.E, real.nu, real.rho) == (7e10, 0.35, 2700.0)


def test_cdb_two_material_numbers_and_temperature_tables_are_refused(tmp_path):
    path = tmp_path / "two.cdb"
    records = MPDATA + "\n" + MPDATA.replace("       1, 1,", "       2, 1,")
    path.write_text(CDB.format(mat="   2", records=records))
    with pytest.raises(ValueError, match=r"use 2 materials: material 1 \(1 element\), material 2 \(1 element\)"):
        mesh_material(load_mesh(path, unit="mm"))
    table = MPDATA.replace("MPDATA,R5.0, 1,EX  ,       1, 1,  210000.000    ,",
                           "MPDATA,R5.0, 2,EX  ,       1, 1,  210000.000    , 200000.000    ,")
    path.write_text(CDB.format(mat="   1", records=table))
    with pytest.raises(ValueError, match=r"material 1 .*: temperature-dependent EX \(2 values\)"):
        mesh_material(load_mesh(path, unit="mm"))
    ortho = MPDATA + "\nMP,EY,1,100000.0"
    path.write_text(CDB.format(mat="   1", records=ortho))
    with pytest.raises(ValueError, match=r"anisotropic \(EY differ"):
        mesh_material(load_mesh(path, unit="mm"))
    path.write_text(CDB.format(mat="   1", records=""))
    assert load_mesh(path).material is None
