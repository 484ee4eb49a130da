"""A command that fails leaves its output folder — or its output files — exactly as it found them.

Each command is driven to a failure after it has computed something (nothing admissible to animate, nothing to
plot, a deck that cannot be written, a mesh group missing after gmsh wrote the mesh) in a folder that holds the
results of an earlier, successful command; the folder's every file, hidden ones included, is compared byte for
byte. Also: one file stem per animated orbit whatever their periods, and the stage command ``assemble`` warns of
the unit slips a run warns of and says what it does with ``[rotation]``.
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pytest
from _studies import PLATE as _PLATE
from _studies import ROOT

import bladecase as bc
from bladecase.cli import main
from bladecase.reduction import load_reduced
from bladecase.study.choose import Choice, distinct_stems

#: The plate study of tests/_studies.py beside its mesh (copied into each test's folder), 6 modes, a short scan.
PLATE = _PLATE.replace("meshes/plate.vtu", "plate.vtu").replace("size = 10", "size = 6").replace(
    "periods = [0.5, 0.9999]\n", "periods = [0.5, 0.9999]\nscan = 24\n") + """[output]
formats = ["gif", "vtu"]
frames = 4
reference = false
manifold = false
"""

def _run(*args) -> int:
    return main([*map(str, args), "--quiet", "--no-progress"])


def snapshot(folder: Path) -> dict:
    """Every entry under ``folder`` (hidden ones included): files by content, folders by name."""
    return {p.relative_to(folder).as_posix(): (p.read_bytes() if p.is_file() else "dir")
            for p in sorted(folder.rglob("*"))}


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """The plate's stage files: FE model, a 6-mode reduced model, the modes of a range with admissible arcs and
    of one (0.3–0.31 T1) without any, and a folder holding the animations of the first."""
    d = tmp_path_factory.mktemp("plate")
    shutil.copy(ROOT / "meshes" / "plate.vtu", d / "plate.vtu")
    (d / "plate.toml").write_text(PLATE)
    (d / "none.toml").write_text(PLATE.replace("periods = [0.5, 0.9999]", "periods = [0.3, 0.31]"))
    assert _run("assemble", d / "plate.toml", "-o", d / "model.npz") == 0
    assert _run("reduce", d / "plate.toml", "--model", d / "model.npz", "-o", d / "red.npz") == 0
    assert _run("modes", d / "plate.toml", "--reduced", d / "red.npz", "-o", d / "modes.json") == 0
    assert _run("modes", d / "none.toml", "--reduced", d / "red.npz", "-o", d / "none.json") == 0
    assert _run("animate", d / "plate.toml", "--reduced", d / "red.npz", "--modes", d / "modes.json",
                "--out", d / "animated") == 0
    assert any((d / "animated" / "animations").iterdir())
    return d


def test_animate_with_nothing_admissible_leaves_the_previous_animations(plate, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(plate / "animated", out)
    before = snapshot(out)
    capsys.readouterr()
    code = _run("animate", plate / "plate.toml", "--reduced", plate / "red.npz", "--modes", plate / "none.json",
                "--out", out)
    err = capsys.readouterr().err
    assert code == 1
    assert "no admissible orbit to animate: nothing written, the output folder is as it was" in err
    assert snapshot(out) == before


def test_animate_that_fails_into_a_new_folder_leaves_no_folder(plate, tmp_path):
    out = tmp_path / "new" / "anim"
    code = _run("animate", plate / "plate.toml", "--reduced", plate / "red.npz", "--modes", plate / "none.json",
                "--out", out)
    assert code == 1 and not (tmp_path / "new").exists()


def test_animate_api_with_nothing_to_animate_publishes_nothing(plate, tmp_path):
    from bladecase.reduction import load_reduced
    from bladecase.study import load_study
    from bladecase.study.render import animate_families

    out = tmp_path / "out"
    shutil.copytree(plate / "animated", out)
    before = snapshot(out)
    assert animate_families(load_study(plate / "plate.toml"), load_reduced(plate / "red.npz"), [], out=out) == []
    assert snapshot(out) == before
    # the folder is free again (its lock given up): a later animation publishes as usual
    assert _run("animate", plate / "plate.toml", "--reduced", plate / "red.npz", "--modes", plate / "modes.json",
                "--out", out) == 0


def test_modes_with_a_plot_of_nothing_writes_neither_file(tmp_path, capsys):
    """No family is found: the plot cannot be drawn, so the modes file (from an earlier run) is not replaced."""
    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "chain2"\n[search]\nipp = [2]\nperiods = [0.1, 0.11]\nscan = 4\n')
    system = bc.chain(2, k=1.0, m=1.0, gap=1.0)


    np.savez(tmp_path / "sys.npz", M=system.M.toarray(), K=system.K.toarray(), w=system.w, gap=1.0)
    (tmp_path / "modes.json").write_text("an earlier result\n")
    before = snapshot(tmp_path)
    code = _run("modes", study, "--matrices", tmp_path / "sys.npz", "-o", tmp_path / "modes.json",
                "--plot", tmp_path / "fe.png")
    assert code == 2 and "nothing to plot: no family found" in capsys.readouterr().err
    assert snapshot(tmp_path) == before


def test_backbone_with_a_plot_of_nothing_writes_none_of_its_files(tmp_path, capsys):
    (tmp_path / "b.json").write_text("an earlier result\n")
    before = snapshot(tmp_path)
    code = main(["backbone", "--chain", "2", "--gap", "1", "--ipp", "2", "--periods", "0.1:0.11:3",
                 "--json", str(tmp_path / "b.json"), "--table", str(tmp_path / "b.txt"),
                 "--plot", str(tmp_path / "b.png"), "--no-progress"])
    assert code == 2 and "nothing to plot" in capsys.readouterr().err
    assert snapshot(tmp_path) == before


def test_assemble_whose_deck_cannot_be_written_leaves_the_model_file(plate, tmp_path, monkeypatch):
    (tmp_path / "model.npz").write_bytes(b"an earlier model")
    before = snapshot(tmp_path)
    import bladecase.io as bio

    def full_disk(path, text):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(bio, "write_text", full_disk)
    code = _run("assemble", plate / "plate.toml", "-o", tmp_path / "model.npz", "--calculix", tmp_path / "deck.inp")
    assert code == 2
    assert snapshot(tmp_path) == before


def test_gmsh_mesh_of_a_study_with_a_missing_group_is_not_written(tmp_path, capsys):
    from bladecase.study.demo import demo_text

    text = demo_text().replace('clamp = "root"', 'clamp = "nosuch"')
    assert 'clamp = "nosuch"' in text
    study = tmp_path / "s.toml"
    study.write_text(text)
    (tmp_path / "blade.msh").write_text("an earlier mesh\n")
    before = snapshot(tmp_path)
    code = _run("mesh", study, "-o", tmp_path / "blade.msh")
    assert code == 2 and "no group 'nosuch'" in capsys.readouterr().err
    assert snapshot(tmp_path) == before


# ----------------------------------------------------------------------------- one file stem per orbit

def test_orbits_whose_periods_agree_to_seven_digits_get_their_own_stems():
    """Rotor 37's two orbits 1.3964859e-3 and 1.3964865e-3 s shared one stem (7 digits): each has its own now,
    the others keep the usual 7 digits, and one orbit chosen twice is numbered."""
    s = bc.chain(2, k=1.0, m=1.0, gap=1.0)
    a, b, c = (bc.orbit_1ipp(s, T) for T in (1.3964859, 1.3964865, 1.5))
    stems = [ch.stem for ch in distinct_stems([Choice(0, a), Choice(0, b), Choice(0, c), Choice(0, a)])]
    assert stems == ["mode00_1ipp_T1p3964859e00", "mode00_1ipp_T1p3964865e00", "mode00_1ipp_T1p500000e00",
                     "mode00_1ipp_T1p3964859e00_2"]
    assert len(set(stems)) == 4
    assert [ch.stem for ch in distinct_stems([Choice(0, a), Choice(1, b)])] == \
        ["mode00_1ipp_T1p396486e00", "mode01_1ipp_T1p396486e00"]  # different families: no clash


# ----------------------------------------------------------------------------- assemble says what run says

def test_assemble_warns_of_a_modulus_in_mpa(plate, tmp_path, caplog):
    text = PLATE.replace("[fem]\n", "[material]\nE = 210000\nnu = 0.3\nrho = 7800\n[fem]\n")
    study = plate / "mpa.toml"
    study.write_text(text)
    with caplog.at_level(logging.WARNING, logger="bladecase"):
        assert _run("assemble", study, "-o", tmp_path / "m.npz") == 0
    assert "E = 210000 Pa is a rubber's stiffness" in caplog.text and "Give it in Pa (E = 2.1e+11)" in caplog.text


def test_assemble_gives_the_frequencies_at_the_operating_speed(plate, tmp_path, capsys):
    text = PLATE.replace("[fem]\n", "[rotation]\nspeed = 3000\naxis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}"
                         "\n[fem]\n")
    study = plate / "spin.toml"
    study.write_text(text)
    capsys.readouterr()
    assert _run("assemble", study, "-o", tmp_path / "m.npz") == 0
    out = capsys.readouterr().out
    rest = [float(x) for x in out.split("linear frequencies (Hz): ")[1].split("\n")[0].split(", ")]
    first = "at the operating speed 3000 rpm (314.159 rad/s) "  # the study's unit first
    line = next(x for x in out.splitlines() if x.startswith(first))
    spun = [float(x) for x in line.split("linear frequencies (Hz): ")[1].split(" — ")[0].split(", ")]
    assert "the model file holds the structure at rest" in line
    assert spun[0] > rest[0]  # stress stiffening of a blade spun about an axis below its root


def test_reduce_spins_the_model_to_the_operating_speed(plate, tmp_path, capsys):
    study = plate / "spin_reduce.toml"
    study.write_text(PLATE.replace("[fem]\n", "[rotation]\nspeed = 3000\naxis = {origin = [0, -0.3, 0], direction = "
                                   "[0, 0, 1]}\n[fem]\n"))
    capsys.readouterr()
    assert _run("reduce", study, "--model", plate / "model.npz", "-o", tmp_path / "r.npz") == 0
    out = capsys.readouterr().out
    assert "rad/s ([rotation]), running clearance" in out
    spun = load_reduced(tmp_path / "r.npz").system.spectrum.frequencies[0]
    rest = load_reduced(plate / "red.npz").system.spectrum.frequencies[0]
    assert spun > rest * (1 + 1e-4)


# ----------------------------------------------------------------------------- [output] orbits never silent

def test_requested_orbits_substituted_or_merged_are_said(plate, tmp_path, caplog):
    """Ten periods asked for between the plate's narrow arcs: the nearest admissible orbits stand in for them,
    each substitution is a warning and a field of its entry, and requests that end on one orbit give it once."""
    from bladecase.study import load_study
    from bladecase.study.documents import load_families
    from bladecase.study.render import animate_families

    asked = [round(0.70 + 0.01 * i, 2) for i in range(10)]
    study = plate / "asked.toml"
    study.write_text(PLATE.replace('reference = false', 'reference = false\norbits = [' + ", ".join(
        f"{{ipp = 1, T = {t}}}" for t in asked) + "]\nformats = []").replace('formats = ["gif", "vtu"]\n', ""))
    reduced = load_reduced(plate / "red.npz")
    families = load_families(plate / "modes.json", reduced.system, reduced=plate / "red.npz")
    with caplog.at_level(logging.WARNING, logger="bladecase"):
        entries = animate_families(load_study(study), reduced, families, out=tmp_path / "out")
    subs = [t for e in entries for t in e.get("substitutes_for_T", [])]
    assert len(entries) < len(asked) and len({e["T"] for e in entries}) == len(entries)
    assert len(subs) == len(asked)  # none of the ten is on an arc here: every one is said
    assert caplog.text.count("animating the nearest admissible one") == len(entries)
    assert "requests (T = " in caplog.text and "give one orbit" in caplog.text


def test_run_that_fails_into_a_new_folder_leaves_no_folder(plate, tmp_path, capsys):
    study = plate / "noclamp.toml"
    study.write_text(PLATE.replace("thickness = 0.002\n", 'thickness = 0.002\nclamp = "nosuch"\n'))
    code = _run("run", study, "--out", tmp_path / "new" / "out")
    assert code == 2 and "no group 'nosuch'" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_mesh_and_assemble_need_no_contact(plate, tmp_path, capsys):
    """Assembling needs no casing: a study without [contact] clearance meshes and assembles; run still needs it."""
    study = plate / "nocontact.toml"
    study.write_text(PLATE.replace("[contact]\nclearance = 1e-4\n", ""))
    assert _run("assemble", study, "-o", tmp_path / "m.npz") == 0
    assert _run("mesh", study, "-o", tmp_path / "m.vtu") == 0
    capsys.readouterr()
    assert _run("reduce", study, "--model", tmp_path / "m.npz", "-o", tmp_path / "r.npz") == 2
    assert "[contact] clearance: required" in capsys.readouterr().err


def test_a_run_without_png_removes_the_previous_runs_figure(plate, tmp_path):
    """As docs/study.md promises: results of the previous run that this run does not produce are removed —
    frequency_energy.png after dropping png from [output] formats — and nothing else of the folder is touched."""
    study = plate / "png.toml"
    study.write_text(PLATE.replace('formats = ["gif", "vtu"]', 'formats = ["png"]'))
    out = tmp_path / "out"
    assert _run("run", study, "--out", out) == 0 and (out / "frequency_energy.png").is_file()
    (out / "notes.txt").write_text("mine")
    study.write_text(PLATE.replace('formats = ["gif", "vtu"]', "formats = []"))
    assert _run("run", study, "--out", out) == 0
    assert not (out / "frequency_energy.png").exists() and (out / "notes.txt").read_text() == "mine"
    text = (ROOT / "docs" / "study.md").read_text()
    assert "`frequency_energy.png` after dropping `png` from `[output] formats`) are removed" in text
