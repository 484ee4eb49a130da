"""A user's sector deck run as it is: CalculiX's ``*TIE, CYCLIC SYMMETRY`` between two node-based ``*SURFACE``s and
``*CYCLIC SYMMETRY MODEL, N=…`` (N, the axis from its two points, the faces as groups) read by
:func:`bladecase.fe.abaqus.read_cyclic`, so that the study's ``[cyclic]`` section is empty.  The same deck (in
millimetres, the axis off the origin, the dependent face left out of the clamp as CalculiX wants it) run by ``ccx``
and by ``bladecase run`` gives the same frequencies per nodal diameter: measured 1.9e-7 relative at most (CalculiX
prints 7 digits; asserted 1e-6).  Bad decks: exit 2 with the message naming the value."""

from __future__ import annotations

import csv
import math
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.cli import main
from bladecase.fe import Mesh, assemble
from bladecase.fe.abaqus import node_numbers, read_cyclic
from bladecase.fe.calculix import calculix_deck

CCX = shutil.which("ccx")
N = 8
SHIFT = 0.1  # the sector's axis: the line z = -0.1 m along +x (-100 mm in the deck)


def _nset(name: str, ids) -> list[str]:
    ids = [str(i) for i in ids]
    return [f"*NSET, NSET={name}"] + [", ".join(ids[i:i + 16]) for i in range(0, len(ids), 16)]


def sector_deck(n: int = N, *, count: int = 6, header: str | None = None, axis: str | None = None,
                move_right: float = 0.0) -> str:
    """A hexahedral sector of ``n`` about the line ``z = -SHIFT`` along ``+x``, as a CalculiX cyclic deck in mm
    (``header``/``axis``: other ``*CYCLIC SYMMETRY MODEL`` lines; ``move_right``: the right face's nodes moved, m)."""
    base = hex_sector(n)
    theta = np.arctan2(-base.points[:, 1], base.points[:, 2])
    left = np.flatnonzero(np.isclose(theta, -math.pi / n))
    right = np.flatnonzero(np.isclose(theta, math.pi / n))
    pts = base.points + [0.0, 0.0, -SHIFT]
    pts[right] += move_right * np.array([1.0, 0.0, 0.0])
    mesh = Mesh(pts, base.cells, dim=3, groups=base.groups, source="sector")
    model = assemble(mesh, "steel", order=1, clamp="hub")
    ids = node_numbers(model.mesh)
    lines = calculix_deck(model, count=count, unit="mm").splitlines()
    i = lines.index("*NSET, NSET=CLAMPED")
    j = next(k for k in range(i + 1, len(lines)) if lines[k].startswith("*"))
    clamped = [int(x) for line in lines[i + 1:j] for x in line.split(",")]
    lines[i:j] = _nset("CLAMPED", [c for c in clamped if c not in set(ids[right].tolist())])  # ccx: no BC on slaves
    k = lines.index("*STEP")
    lines[k:k] = (_nset("LEFT", ids[left]) + _nset("RIGHT", ids[right])
                  + ["*SURFACE, NAME=SLEFT, TYPE=NODE", "LEFT", "*SURFACE, NAME=SRIGHT, TYPE=NODE", "RIGHT",
                     "*TIE, NAME=CYC, CYCLIC SYMMETRY, POSITION TOLERANCE=1e-3", "SRIGHT, SLEFT",
                     header or f"*CYCLIC SYMMETRY MODEL, N={n}, NGRAPH=1, TIE=CYC, ELSET=EALL",
                     axis or f"0, 0, {-SHIFT * 1e3:g}, 1, 0, {-SHIFT * 1e3:g}"])
    f = lines.index("*FREQUENCY")
    lines[f + 2:f + 2] = [f"*SELECT CYCLIC SYMMETRY MODES, NMIN=0, NMAX={n // 2}"]
    return "\n".join(lines) + "\n"


def _study(tmp_path, deck: str, cyclic: str = "", name: str = "deck") -> str:
    (tmp_path / "sector.inp").write_text(deck)
    study = tmp_path / f"{name}.toml"
    study.write_text(f'''study = {{name = "{name}"}}
mesh = {{path = "sector.inp", unit = "mm"}}
fem = {{order = 1, clamp = "CLAMPED"}}
output = {{formats = []}}
[cyclic]
{cyclic}
''')
    return str(study)


def _csv(path) -> dict[int, np.ndarray]:
    out: dict[int, list[float]] = {}
    with open(path) as fh:
        for row in csv.DictReader(fh):
            out.setdefault(int(row["nd"]), []).append(float(row["frequency_hz"]))
    return {k: np.array(v) for k, v in out.items()}


def test_read_cyclic_takes_the_deck_as_it_is(tmp_path):
    (tmp_path / "s.inp").write_text(sector_deck())
    c = read_cyclic(tmp_path / "s.inp")
    assert (c["sectors"], c["left"], c["right"], c["tol"], c["problem"]) == (N, "SLEFT", "SRIGHT", 1e-3, None)
    assert c["axis"] == ([0.0, 0.0, -100.0], [1.0, 0.0, -100.0])


def test_deck_study_runs_with_an_empty_cyclic_section(tmp_path, capsys):
    study = _study(tmp_path, sector_deck(count=4), "modes = 2")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    freq = _csv(tmp_path / "out" / "cyclic.csv")
    assert sorted(freq) == list(range(N // 2 + 1)) and all(v.size == 2 for v in freq.values())
    import json

    s = json.loads((tmp_path / "out" / "summary.json").read_text())["cyclic"]
    assert s["sectors"] == N and s["faces"]["from"] == "deck"
    assert np.allclose(s["axis"]["origin"], [0, 0, -SHIFT]) and np.allclose(s["axis"]["direction"], [1, 0, 0])
    # each face: 3 axial × 3 radial nodes in the disk, the 3 at the hub clamped — the dependent face's, which the
    # deck leaves free, with their images — so 6 free pairs
    assert s["faces"]["pairs"] == 6


@pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed")
def test_deck_matches_calculix_per_nodal_diameter(tmp_path):
    deck = sector_deck(count=6)
    study = _study(tmp_path, deck, "modes = 3")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    ours = _csv(tmp_path / "out" / "cyclic.csv")
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    subprocess.run([CCX, "sector"], cwd=tmp_path, capture_output=True, check=True, timeout=120, env=env)
    theirs: dict[int, list[float]] = {}
    for table in (tmp_path / "sector.dat").read_text().split("E I G E N V A L U E   O U T P U T")[1:]:
        body = table.split("P A R T I C I P A T I O N")[0]
        for nd, *_, cycles, _ in re.findall(r"^\s*(\d+)\s+(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", body, re.M):
            theirs.setdefault(int(nd), []).append(float(cycles))
    assert sorted(theirs) == sorted(ours)
    worst = max(float(np.max(np.abs(ours[k] / np.array(theirs[k][::2])[:3] - 1))) for k in ours)
    assert worst < 1e-6, worst


def _fails(tmp_path, capsys, deck: str, cyclic: str = "") -> str:
    study = _study(tmp_path, deck, cyclic)
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert not (tmp_path / "out" / "summary.json").exists()  # nothing published
    return capsys.readouterr().err


def test_unmatched_face_nodes_are_named(tmp_path, capsys):
    err = _fails(tmp_path, capsys, sector_deck(move_right=2e-4))   # 0.2 mm off, the tie's tolerance 1e-3 mm
    assert "node(s) of the left cyclic face" in err and "meet no free node of the right face within tol = 0.001 mm" \
        in err and re.search(r"node \d+ at \(", err), err


def test_a_looser_tolerance_matches_them(tmp_path, capsys):
    study = _study(tmp_path, sector_deck(move_right=2e-4), "tol = 0.5\nmodes = 1\ndiameters = [0, 4]")
    assert main(["run", study, "--out", str(tmp_path / "out"), "--quiet"]) == 0


@pytest.mark.parametrize("header, axis, words", [
    ("*CYCLIC SYMMETRY MODEL, N=1, TIE=CYC", None, "N=1: a disk has N >= 2 sectors"),
    ("*CYCLIC SYMMETRY MODEL, N=8, TIE=OTHER", None, "TIE=OTHER: no *TIE, CYCLIC SYMMETRY of that name (cyclic "
                                                     "ties: CYC)"),
    (None, "0, 0, 0, 0, 0, 0", "the same point [0.0, 0.0, 0.0]"),
])
def test_bad_cyclic_model_lines(tmp_path, capsys, header, axis, words):
    err = _fails(tmp_path, capsys, sector_deck(header=header, axis=axis))
    assert words in err and "sector.inp', line" in err, err


@pytest.mark.parametrize("cyclic, words", [
    ('left = "NOPE"\nright = "RIGHT"', "[cyclic] left: 'NOPE', but the mesh"),
    ('left = "LEFT"', "[cyclic] left: give both cyclic faces"),
    ("diameters = [0, 5]", "[cyclic] diameters: 5 is not a nodal diameter of a disk of 8 sectors (0 … 4)"),
    ("sectors = 1", "[cyclic] sectors: must be an integer with 2 <= value <= 10000"),
    ("sectors = 9", "[cyclic] sectors: the deck's *CYCLIC SYMMETRY MODEL has N=8, got 9"),
    ('left = "RIGHT"\nright = "LEFT"', "swapped faces"),
])
def test_bad_cyclic_keys(tmp_path, capsys, cyclic, words):
    err = _fails(tmp_path, capsys, sector_deck(), cyclic)
    assert words in err, err


def test_an_analytical_tie_surface_needs_groups(tmp_path, capsys):
    deck = sector_deck().replace("*SURFACE, NAME=SLEFT, TYPE=NODE\nLEFT", "*SURFACE, NAME=SLEFT, TYPE=SEGMENTS\n"
                                 "START, 0, 0")  # element-based ones are read: tests/test_abaqus_element_surfaces.py
    err = _fails(tmp_path, capsys, deck)
    assert "surface 'SLEFT' is of TYPE=SEGMENTS" in err and "[cyclic] left and right" in err, err


def test_an_empty_cyclic_section_needs_a_cyclic_deck(tmp_path, capsys):
    deck = sector_deck()
    deck = deck[:deck.index("*SURFACE")] + deck[deck.index("*STEP"):]
    deck = re.sub(r"\*SELECT CYCLIC SYMMETRY MODES.*\n", "", deck)
    err = _fails(tmp_path, capsys, deck)
    assert "declares no *CYCLIC SYMMETRY MODEL: give [cyclic] sectors = N" in err, err


def test_a_tie_surface_that_is_no_group_is_named(tmp_path, capsys):
    deck = sector_deck().replace("*SURFACE, NAME=SRIGHT, TYPE=NODE\nRIGHT", "*SURFACE, NAME=SRIGHT, TYPE=NODE\nLATER")
    err = _fails(tmp_path, capsys, deck)
    assert "names the right cyclic face 'SRIGHT', but the mesh" in err and "no such node group" in err, err
