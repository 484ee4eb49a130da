"""The mistuned disk's tip clearances read off a ``[casing]``
(:func:`~bladecase.reduction.mistuning_rub.blade_clearances`, and the study's ``[mistuning]`` with a ``[casing]``).

* Library, against closed forms written here with trigonometry only (no rotation matrix): a coaxial cylinder (every
  blade ``R − r``), an out-of-round one (``R − r − A cos(n θ_j)``), a cylinder offset from the disk's axis
  (``R − √(r² + e² − 2re cos θ_j)``, blade angles about the casing's axis for the lobes), a cone (``R(s) − r``);
  a blade through the casing is an error naming it.
* Through the CLI on a coarse hexahedral sector mesh of 6 blades: a round ``[casing]`` gives the same first rub, row
  for row, as the uniform ``[mistuning] clearance`` it amounts to; an out-of-round one gives every blade the closed
  form's clearance and the same first rub as that list given by hand; both given and agreeing run, disagreeing (or
  a casing inside the tips) exit 2 naming the blade and both values; ``force`` with only a ``[casing]`` runs every
  blade's rub against the casing's clearances.
* On the parametric sector with no axis anywhere, the casing turns about the disk's own axis: a round casing 100 µm
  beyond the tip gives the first rub of ``[mistuning] clearance = 1e-4``.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import re

import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.cli import main
from bladecase.fe import save_mesh
from bladecase.fe.rotation import RotationAxis
from bladecase.reduction.casing import Casing
from bladecase.reduction.mistuning_rub import blade_clearances
from bladecase.study.schema import StudyError, loads

N, R_RIM, R_TIP = 6, 0.16, 0.26  # hex_sector's rim and tip radii (m)
X_AXIS = RotationAxis((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))


def _tip(r: float, theta: float, x: float = 0.01) -> np.ndarray:
    """A point at radius ``r`` and angle ``theta`` about +x (hex_sector's: from +z, right-handed: y = −r sin θ)."""
    return np.array([x, -r * math.sin(theta), r * math.cos(theta)])


def test_a_coaxial_cylinder_round_and_out_of_round():
    theta0 = 0.07  # the tip off the sector's mid-plane: the blades' angles are θ0 + jα
    tip = _tip(0.25, theta0)
    c = blade_clearances(tip, 7, X_AXIS, Casing(X_AXIS, radius=0.2502))
    np.testing.assert_allclose(c, 2e-4, rtol=1e-12)
    c = blade_clearances(tip, 7, X_AXIS, Casing(X_AXIS, radius=0.2502), lobes=3, amplitude=5e-5)
    j = np.arange(7)
    np.testing.assert_allclose(c, 2e-4 - 5e-5 * np.cos(3 * 2 * np.pi * j / 7), rtol=1e-10, atol=1e-15)


def test_an_offset_cylinder_and_its_lobes_about_its_own_axis():
    e, r, R = 3e-5, 0.25, 0.2502  # the casing's axis moved by e along +z
    theta = 2 * np.pi * np.arange(N) / N
    casing_axis = RotationAxis((0.0, 0.0, e), (1.0, 0.0, 0.0))
    c = blade_clearances(_tip(r, 0.0), N, X_AXIS, Casing(casing_axis, radius=R))
    np.testing.assert_allclose(c, R - np.sqrt(r**2 + e**2 - 2 * r * e * np.cos(theta)), rtol=1e-9)
    assert c.argmax() == 0 and c.argmin() == 3  # the casing moved towards blade 0: widest there, narrowest opposite
    lobed = blade_clearances(_tip(r, 0.0), N, X_AXIS, Casing(casing_axis, radius=R), lobes=2, amplitude=2e-5)
    y, z = -r * np.sin(theta), r * np.cos(theta) - e  # each tip about the casing's axis
    phi = np.arctan2(-y, z)
    np.testing.assert_allclose(lobed, c - 2e-5 * np.cos(2 * phi), rtol=1e-9)


def test_a_cone_gives_its_radius_at_the_tips_station():
    cone = Casing(X_AXIS, radii=((0.0, 0.2503), (0.1, 0.2493)))  # narrowing along +x: R(0.01) = 0.2502
    c = blade_clearances(_tip(0.25, 0.3, x=0.01), 5, X_AXIS, cone)
    np.testing.assert_allclose(c, 2e-4, rtol=1e-9)


def test_a_blade_through_the_casing_is_named():
    e = 3e-4  # more than the 2e-4 clearance: blade 3, opposite the way the casing moved, crosses it
    with pytest.raises(ValueError, match=r"blade 3's tip \(radius 0\.2503 m about the casing's axis\) touches or "
                                         r"crosses the casing at rest: clearance -0\.0001 m"):
        blade_clearances(_tip(0.25, 0.0), N, X_AXIS, Casing(RotationAxis((0, 0, e), (1, 0, 0)), radius=0.2502))


MISTUNING = "std = 0.03\nsamples = 3\nseed = 4\nengine_order = 2\ndamping = 0.05\n"


def _run(tmp_path, extra: str = "", casing: str = ""):
    mesh = hex_sector(N, nt=3, band=(1, 2), nr=1, nb=3, nx=1)
    r = np.hypot(mesh.points[:, 1], mesh.points[:, 2])
    save_mesh(dataclasses.replace(mesh, groups={**mesh.groups, "blade": np.flatnonzero(r >= R_RIM - 1e-9)}),
              tmp_path / "sector.vtu")
    path = tmp_path / "disk.toml"
    path.write_text('study = {name = "disk"}\nmesh = {path = "sector.vtu"}\nmaterial = {preset = "steel"}\n'
                    'fem = {order = 1, mass = "lumped", clamp = "hub"}\noutput = {formats = []}\n'
                    "rotation = {axis = {origin = [0, 0, 0], direction = [1, 0, 0]}}\n"
                    f"cyclic = {{sectors = {N}, modes = 1}}\n{casing}\n[mistuning]\nblade = \"blade\"\n{MISTUNING}"
                    f"{extra}\n")
    out = tmp_path / "out"
    return main(["run", str(path), "--out", str(out), "--quiet"]), out


def _rows(out):
    return [{k: v for k, v in r.items()} for r in csv.DictReader(open(out / "mistuning_rub.csv"))]


def _same_rub(a, b, rel=1e-8):
    """Two runs' ``mistuning_rub.csv``: the same first blade of every sample, the same figures to ``rel``."""
    ra, rb = _rows(a), _rows(b)
    assert len(ra) == len(rb) == 3 and [r["first_blade"] for r in ra] == [r["first_blade"] for r in rb]
    for x, y in zip(ra, rb):
        for key in ("level_n", "tuned_ratio", "lead"):
            assert float(x[key]) == pytest.approx(float(y[key]), rel=rel), key


@pytest.fixture(scope="module")
def round_runs(tmp_path_factory):
    """The same disk with a round casing 100 µm beyond the tips, and with that clearance given by hand."""
    runs = {}
    for name, extra, casing in (("casing", "", f"casing = {{radius = {R_TIP + 1e-4!r}}}"),
                                ("given", "clearance = 1e-4", "")):
        code, out = _run(tmp_path_factory.mktemp(name), extra, casing)
        assert code == 0
        runs[name] = out
    return runs


def test_a_round_casing_is_its_uniform_clearance(round_runs):
    a, b = (json.loads((round_runs[k] / "summary.json").read_text())["mistuning"]["rub"] for k in ("casing", "given"))
    assert a["clearance_from"] == "casing" and b["clearance_from"] == "mistuning"
    assert a["clearance_m"] == pytest.approx(1e-4, rel=1e-9)
    _same_rub(round_runs["casing"], round_runs["given"])


def test_an_out_of_round_casing_gives_each_blade_its_clearance(tmp_path, round_runs):
    amplitude, lobes = 3e-5, 2
    casing = f"casing = {{radius = {R_TIP + 1e-4!r}, lobes = {lobes}, amplitude = {amplitude}}}"
    (tmp_path / "a").mkdir()
    code, out = _run(tmp_path / "a", "", casing)
    assert code == 0
    rub = json.loads((out / "summary.json").read_text())["mistuning"]["rub"]
    tip = json.loads((out / "summary.json").read_text())["mistuning"]["tip"]
    theta0 = math.atan2(-tip["position_m"][1], tip["position_m"][2])  # blade 0's tip angle; blade j's: + jα
    j = np.arange(N)
    r_tip = math.hypot(*tip["position_m"][1:])
    expected = R_TIP + 1e-4 - r_tip - amplitude * np.cos(lobes * 2 * np.pi * j / N)
    assert abs(theta0) < math.pi / N and r_tip == pytest.approx(R_TIP, rel=1e-12)
    np.testing.assert_allclose(rub["clearance_m"], expected, rtol=1e-9)
    # the same clearances typed by hand, with the casing too (they agree): the same first rub, sample by sample
    (tmp_path / "b").mkdir()
    code, both = _run(tmp_path / "b", f"clearance = {[float(f'{x:.9g}') for x in expected]}", casing)
    assert code == 0 and _rows(both) == _rows(out)
    assert _rows(out) != _rows(round_runs["casing"])  # the lobes moved the first rub


@pytest.mark.parametrize("extra, casing, words", [
    ("clearance = 2e-4", f"casing = {{radius = {R_TIP + 1e-4!r}}}",
     r"\[mistuning\] clearance: blade 0's is 0\.0002 m, but the \[casing\] puts its tip \(node \d+ turned to blade "
     r"0\) 0\.0001 m from the casing .* give one of them, or make them agree within 0\.1%"),
    ("", f"casing = {{radius = {R_TIP - 1e-4!r}}}",
     r"\[casing\]: the mistuned disk's blade tips \(node \d+ of each sector\): blade 0's tip \(radius 0\.26 m about "
     r"the casing's axis\) touches or crosses the casing at rest: clearance -0\.0001 m"),
])
def test_inconsistent_or_crossing_casings_exit_2(tmp_path, capsys, extra, casing, words):
    code, out = _run(tmp_path, extra, casing)
    err = capsys.readouterr().err
    assert code == 2 and re.search(words, err.replace("\n", " ")) and not out.exists()


def test_force_with_a_casing_rubs_every_blade_against_its_clearance(tmp_path):
    """``force`` without ``[mistuning] clearance``: the blades' contacts take the out-of-round casing's clearances;
    the tuned disk's blades then press unequally (a uniform clearance would have them press alike)."""
    casing = f"casing = {{radius = {R_TIP + 1e-4!r}, lobes = 2, amplitude = 3e-5}}"
    code, out = _run(tmp_path, "force = 2500.0\ncontact_samples = 1\ncasing_stiffness = 1e7", casing)
    assert code == 0
    s = json.loads((out / "summary.json").read_text())["mistuning"]
    tuned = np.array(s["contact"]["tuned_forces_n"])
    gap = np.array(s["rub"]["clearance_m"])
    assert tuned.max() > 0 and np.ptp(gap) > 0
    assert np.argmax(tuned) in np.flatnonzero(gap == gap.min())  # the tuned disk presses hardest where it is closest


def test_the_keys_around_a_casing():
    base = ('mesh = {path = "s.inp"}\n[mistuning]\nblade = "b"\nstd = 0.02\nforce = 10.0\n'
            "[fem]\nmass = \"lumped\"\n")
    s = loads(base + "[cyclic]\nsectors = 6\n[casing]\nradius = 0.3\n")  # force with a casing, no face, no axis
    assert s["casing"]["axis"] is None and s["mistuning"]["clearance"] is None
    with pytest.raises(StudyError, match=r"\[casing\]: the casing of a mistuned disk read from a sector deck: add a "
                                         r"\[cyclic\] key"):
        loads(base + "[casing]\nradius = 0.3\n")
    with pytest.raises(StudyError, match=r"\[mistuning\] force: .* or a \[casing\] \(radius\)"):
        loads(base + "[cyclic]\nsectors = 6\n")


def test_the_parametric_sectors_casing_turns_about_the_disks_axis(tmp_path):
    """No axis anywhere: the casing is about the sector's engine axis (the line through (0, 0, −rim) along +x), so a
    casing 100 µm beyond the tip node's radius about it gives every blade 100 µm."""
    rim = 0.2
    geometry = (f'geometry = {{kind = "sector", sectors = {N}, hub_radius = 0.1, rim_radius = {rim}, '
                'disk_thickness = 0.03, span = 0.1, root_chord = 0.03, thickness = 0.005, size = 0.04}')
    text = (f'study = {{name = "p"}}\n{geometry}\nfem = {{order = 1}}\noutput = {{formats = []}}\n'
            f"cyclic = {{modes = 1}}\n[mistuning]\n{MISTUNING}")
    first = tmp_path / "a.toml"
    first.write_text(text + "clearance = 1e-4\n")
    assert main(["run", str(first), "--out", str(tmp_path / "a"), "--quiet"]) == 0
    tip = json.loads((tmp_path / "a" / "summary.json").read_text())["mistuning"]["tip"]
    second = tmp_path / "b.toml"
    second.write_text(text + f"[casing]\nradius = {tip['radius_m'] + 1e-4!r}\n")
    assert main(["run", str(second), "--out", str(tmp_path / "b"), "--quiet"]) == 0
    rub = json.loads((tmp_path / "b" / "summary.json").read_text())["mistuning"]["rub"]
    assert rub["clearance_from"] == "casing" and rub["clearance_m"] == pytest.approx(1e-4, rel=1e-9)
    _same_rub(tmp_path / "b", tmp_path / "a")
