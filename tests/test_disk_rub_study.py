"""``[rub] speeds`` in a cyclic study end to end through the CLI: a coarse hexahedral sector of 12 blades (a mesh
file), each blade's tip face its massless contact on a compliant out-of-round casing of 3 lobes; ``disk_rub.csv``,
the plot, the summary and the report; and the error without a contact face (exit 2, nothing published)."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.cli import main
from bladecase.fe import save_mesh
from bladecase.study.disk.rub import COLUMNS
from bladecase.study.schema import StudyError, loads

N = 12
CONTACT = ('contact = {face = "tip", model = "massless", casing_stiffness = 5e6}\n'
           'reduction = {method = "massless"}\nsearch = {ipp = [1]}\n')


def _study(tmp_path, contact: str = CONTACT) -> str:
    save_mesh(hex_sector(N, nt=3, band=(1, 2), nr=1, nb=3, nx=1), tmp_path / "sector.vtu")
    path = tmp_path / "s.toml"
    path.write_text('mesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\n'
                    'fem = {order = 1, clamp = "hub", mass = "lumped"}\noutput = {formats = ["png"]}\n'
                    'rotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n'
                    f'{contact}casing = {{radius = 0.2601, lobes = 3, amplitude = 1.2e-4}}\n'
                    'rub = {speeds = [1500, 2500], speed_unit = "rad/s", revolutions = 4, window = 1, ratio = 0.05, '
                    f'size = 2}}\n[cyclic]\nsectors = {N}\nmodes = 2\n')
    return str(path)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("disk_rub")
    assert main(["run", _study(tmp), "--out", str(tmp / "out"), "--quiet"]) == 0
    return tmp / "out"


def test_every_blade_rubs_alike_on_the_lobes_diameter(run):
    rows = list(csv.DictReader(open(run / "disk_rub.csv")))
    assert tuple(rows[0]) == COLUMNS and len(rows) == 2 * N
    for speed in ("1500.0", "2500.0"):
        at = [r for r in rows if r["speed"] == speed]
        force = np.array([float(r["peak_force_n"]) for r in at])
        assert [int(r["blade"]) for r in at] == list(range(N)) and force.min() > 0
        assert np.ptp(force) <= 1e-8 * force.max()  # the tuned disk's symmetry, not used by the solver
        # a compliant casing: the penetration is the force over its stiffness
        assert np.allclose([float(r["penetration_m"]) for r in at], force / 5e6, rtol=1e-12)
        assert {r["dominant_nd"] for r in at} == {"3"} and {r["response"] for r in at} == {"settled"}
    s = json.loads((run / "summary.json").read_text())["cyclic"]["rub"]
    assert s["sectors"] == N and s["contacts"] == N and s["expected_nd"] == 3 and len(s["speeds"]) == 2
    assert all(p["dominant"] == 3 and abs(sum(p["nd_share"]) - 1) < 1e-12 for p in s["speeds"])
    assert (run / "disk_rub.png").stat().st_size > 0
    report = (run / "report.md").read_text()
    assert "## The whole disk in the out-of-round casing" in report and "| 1500 | settled |" in report


def test_a_disk_rub_without_a_contact_is_an_error(tmp_path, capsys):
    assert main(["run", _study(tmp_path, contact=""), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "set [contact] face" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_a_cyclic_contact_that_nothing_uses_is_refused(tmp_path):
    """A cyclic study with a contact face and a casing but neither ``[cyclic] nonsmooth`` nor ``[rub] speeds``
    would ignore the contact: refused, naming what would use it (exit code 2 on the command line)."""
    text = re.sub(r"^rub = .*\n", "", open(_study(tmp_path)).read(), flags=re.M)
    path = tmp_path / "unused.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    with pytest.raises(StudyError, match=r"neither is asked, so the contact would be ignored"):
        loads(text.replace('mesh = {path = "sector.vtu"}', f'mesh = {{path = "{tmp_path / "sector.vtu"}"}}'))
    assert not (tmp_path / "out").exists()


def test_every_tip_node_a_contact_on_a_tuned_disk(tmp_path):
    """``points = "nodes"`` on the tuned disk: blades 0, 4, 8 (a 3-lobe casing on 12 blades) meet the lobes at the
    same instants, several nodes switch at once — decided together (it stopped with "grazing switch" when a node
    whose force was zero to round-off was kept closed). Every blade's peak force equal to 1e-5 (refined peaks)."""
    contact = CONTACT.replace('casing_stiffness = 5e6}', 'casing_stiffness = 5e6, points = "nodes"}')
    assert main(["run", _study(tmp_path, contact), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    rows = list(csv.DictReader(open(tmp_path / "out" / "disk_rub.csv")))
    for speed in {r["speed"] for r in rows}:
        force = np.array([float(r["peak_force_n"]) for r in rows if r["speed"] == speed])
        assert force.size == N and force.min() > 0 and np.ptp(force) <= 1e-5 * force.max()
        assert {r["response"] for r in rows if r["speed"] == speed} == {"settled"}
