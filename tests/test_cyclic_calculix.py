"""The cyclic modes of a sector against CalculiX's own cyclic-symmetry run of the same sector (``*TIE, CYCLIC
SYMMETRY``, ``*CYCLIC SYMMETRY MODEL``, ``*SELECT CYCLIC SYMMETRY MODES``): an independent code, the same C3D8 mesh
and integration rule.  Measured: the frequencies of every nodal diameter agree to CalculiX's printed digits
(largest difference 1.8e-7 relative on this sector, CalculiX printing 7 digits; asserted below 1e-6).
Skipped without ``ccx``."""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.fe import assemble
from bladecase.fe.abaqus import node_numbers
from bladecase.fe.calculix import calculix_deck
from bladecase.fe.cyclic import cyclic_spectrum, fe_sector
from bladecase.fe.rotation import RotationAxis

CCX = shutil.which("ccx")
pytestmark = pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed (apt-get install calculix-ccx)")


def _nset(name: str, ids) -> list[str]:
    ids = [str(i) for i in ids]
    return [f"*NSET, NSET={name}"] + [", ".join(ids[i:i + 16]) for i in range(0, len(ids), 16)]


def cyclic_deck(model, sectors: int, left, right, count: int) -> str:
    """bladecase's CalculiX deck of ``model`` turned into a cyclic-symmetry run: the right face (dependent, slave)
    tied to the left face about the x axis; the slave nodes leave the clamp (CalculiX refuses a boundary condition
    on a dependent node: the tie carries the master's)."""
    ids = node_numbers(model.mesh)
    left, right = ids[left], ids[right]
    lines = calculix_deck(model, count=count).splitlines()
    i = lines.index("*NSET, NSET=CLAMPED")
    j = next(n for n in range(i + 1, len(lines)) if lines[n].startswith("*"))
    clamped = [int(x) for line in lines[i + 1:j] for x in line.split(",")]
    lines[i:j] = _nset("CLAMPED", [c for c in clamped if c not in set(right.tolist())])
    k = lines.index("*STEP")
    lines[k:k] = (_nset("LEFT", left) + _nset("RIGHT", right)
                  + ["*SURFACE, NAME=SLEFT, TYPE=NODE", "LEFT", "*SURFACE, NAME=SRIGHT, TYPE=NODE", "RIGHT",
                     "*TIE, NAME=CYC, CYCLIC SYMMETRY, POSITION TOLERANCE=1e-6", "SRIGHT, SLEFT",
                     f"*CYCLIC SYMMETRY MODEL, N={sectors}, NGRAPH=1, TIE=CYC, ELSET=EALL", "0, 0, 0, 1, 0, 0"])
    f = lines.index("*FREQUENCY")
    lines[f + 2:f + 2] = [f"*SELECT CYCLIC SYMMETRY MODES, NMIN=0, NMAX={sectors // 2}"]
    return "\n".join(lines) + "\n"


def read_cyclic_dat(text: str) -> dict[int, np.ndarray]:
    """``{nodal diameter: frequencies (Hz)}`` of every eigenvalue table of a cyclic CalculiX ``.dat`` (each
    frequency is printed twice there, the cosine and sine modes: kept once)."""
    out: dict[int, list[float]] = {}
    for table in text.split("E I G E N V A L U E   O U T P U T")[1:]:
        body = table.split("P A R T I C I P A T I O N")[0]
        for nd, _, _, _, cycles, _ in re.findall(r"^\s*(\d+)\s+(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", body, re.M):
            out.setdefault(int(nd), []).append(float(cycles))
    return {k: np.array(v[::2]) for k, v in out.items()}


def test_sector_frequencies_match_calculix_cyclic_symmetry(tmp_path):
    n, count = 8, 4
    mesh = hex_sector(n)
    model = assemble(mesh, "steel", order=1, clamp="hub")
    sector = fe_sector(model, n, RotationAxis((0, 0, 0), (1, 0, 0)))
    ours = cyclic_spectrum(sector, count)
    theta = np.arctan2(-mesh.points[:, 1], mesh.points[:, 2])
    left, right = np.flatnonzero(np.isclose(theta, -math.pi / n)), np.flatnonzero(np.isclose(theta, math.pi / n))
    assert np.array_equal(np.sort(sector.pairs[:, 0]), np.setdiff1d(left, model.clamped))  # the same faces
    (tmp_path / "cyc.inp").write_text(cyclic_deck(model, n, left, right, 2 * count))
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    subprocess.run([CCX, "cyc"], cwd=tmp_path, capture_output=True, check=True, timeout=300, env=env)
    theirs = read_cyclic_dat((tmp_path / "cyc.dat").read_text())
    assert sorted(theirs) == list(range(n // 2 + 1))
    worst = 0.0
    for k, modes in ours.items():
        assert theirs[k].size == count
        worst = max(worst, float(np.max(np.abs(modes.frequencies - theirs[k]) / theirs[k])))
    assert worst < 1e-6, worst


def test_parametric_sector_matches_calculix_up_to_the_element_rule(tmp_path):
    """The gmsh sector (12 sectors, quadratic tetrahedra, 1275 dofs; C3D10 for CalculiX), the faces given as the
    mesh's groups: every nodal diameter's two lowest frequencies agree within 1.4e-5 (measured; asserted 3e-5), the
    difference of the two codes' integration rules for C3D10 (bladecase integrates with more points)."""
    from bladecase.fe.sector import SectorGeometry, sector_mesh
    from bladecase.fe.shapes import BladeGeometry

    blade = BladeGeometry(span=0.15, root_chord=0.04, thickness=0.006)
    g = SectorGeometry(sectors=12, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04, blade=blade)
    mesh = sector_mesh(g, size=0.04, order=2)
    model = assemble(mesh, "steel", order=2, clamp="hub")
    count = 2
    ours = cyclic_spectrum(fe_sector(model, 12, g.axis, left="left", right="right"), count)
    deck = cyclic_deck(model, 12, mesh.group("left"), mesh.group("right"), 2 * count)
    deck = deck.replace("0, 0, 0, 1, 0, 0", f"0, 0, {-g.rim_radius!r}, 1, 0, {-g.rim_radius!r}")
    (tmp_path / "cyc.inp").write_text(deck)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    subprocess.run([CCX, "cyc"], cwd=tmp_path, capture_output=True, check=True, timeout=300, env=env)
    theirs = read_cyclic_dat((tmp_path / "cyc.dat").read_text())
    offset = np.array([ours[k].frequencies / theirs[k] - 1 for k in sorted(ours)])  # (diameters, families)
    assert sorted(theirs) == sorted(ours) and np.abs(offset).max() < 3e-5, offset
