"""``[mistuning] force`` end to end through the CLI on a coarse hexahedral sector mesh of 6 blades, lumped mass: every
blade's steady rub at each sample's resonance (``mistuning_contact.csv``, the summary, the report); the tuned disk's
blades all press alike (a symmetry the flight is not told: every blade is its own contact); the keys' errors."""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.cli import main
from bladecase.fe import save_mesh

R_RIM = 0.16  # hex_sector's rim radius: the blade's nodes lie at and beyond it
MISTUNING = ("std = 0.03\nsamples = 3\nseed = 4\nengine_order = 2\ndamping = 0.05\nclearance = 1e-4\n"
             "casing_stiffness = 1e7\n")


def _run(tmp_path, extra: str, mass: str = "lumped"):
    mesh = hex_sector(6, nt=3, band=(1, 2), nr=1, nb=3, nx=1)
    r = np.hypot(mesh.points[:, 1], mesh.points[:, 2])
    save_mesh(dataclasses.replace(mesh, groups={**mesh.groups, "blade": np.flatnonzero(r >= R_RIM - 1e-9)}),
              tmp_path / "sector.vtu")
    path = tmp_path / "disk.toml"
    path.write_text('study = {name = "disk"}\nmesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\n'
                    f'fem = {{order = 1, mass = "{mass}", clamp = "hub"}}\noutput = {{formats = []}}\n'
                    "rotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n"
                    f'cyclic = {{sectors = 6, modes = 1}}\n[mistuning]\nblade = "blade"\n{MISTUNING}{extra}\n')
    out = tmp_path / "out"
    return main(["run", str(path), "--out", str(out), "--quiet"]), out


def test_every_blades_rub_in_the_summary_the_csv_and_the_report(tmp_path):
    code, out = _run(tmp_path, "force = 6000.0\ncontact_samples = 2")
    assert code == 0
    c = json.loads((out / "summary.json").read_text())["mistuning"]["contact"]
    rows = list(csv.DictReader(open(out / "mistuning_contact.csv")))
    assert len(rows) == c["samples"] == 2 and all(r["settled"] == "True" for r in rows)
    forces = np.array([[float(r[f"force_{j}_n"]) for j in range(6)] for r in rows])
    assert forces.max() == pytest.approx(c["largest_force_n"]["max"], rel=1e-12) and forces.max() > 0
    tuned = np.array(c["tuned_forces_n"])
    assert tuned.min() > 0 and np.ptp(tuned) <= 1e-4 * tuned.max()  # tuned: every blade alike (settled to 1e-4)
    assert np.ptp(forces[0]) > 0.1 * forces[0].max()  # mistuned: the blades rub unequally
    assert "- Rub at a tip force of 6000 N" in (out / "report.md").read_text()


@pytest.mark.parametrize("extra, mass, words", [
    ("force = 300.0", "consistent", "[mistuning] force: each blade's contact is a massless contact"),
    ("force = -1.0", "lumped", "[mistuning] force: must be a force amplitude > 0"),
])
def test_bad_force_keys_exit_2(tmp_path, capsys, extra, mass, words):
    code, out = _run(tmp_path, extra, mass)
    assert code == 2 and words in capsys.readouterr().err and not out.exists()
