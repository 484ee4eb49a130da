"""Issue 15 on the command line: bad input gives one line naming the value and what is valid, exit 2
(never a traceback, never a wrong answer); Ctrl-C / SIGTERM leave previous results untouched.

Everything runs in-process through ``bladecase.cli.main``; no case computes more than a tiny system.
"""

from __future__ import annotations

import errno
import importlib
import json
import os
import signal
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _studies import PLATE, absolute
from skfem import MeshTri

import bladecase as bc
from bladecase.cli import main
from bladecase.fe import Mesh, assemble, load_model, save_model
from bladecase.reduction import Contact, load_reduced, reduce, save_reduced
from bladecase.study.documents import families_document

CHAIN = ["backbone", "--chain", "2", "--k", "1", "--m", "0.5", "--gap", "1", "--periods", "1:12:11", "--quiet",
         "--no-progress"]


def _run(argv, capsys) -> tuple[int, str]:
    """Exit code and stderr of ``main(argv)``; the error is one line without a traceback."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse
        code = exc.code
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return code, err


def _one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if "error" in line or "interrupted" in line or "terminated" in line]
    assert len(lines) == 1, err
    return lines[0]


@pytest.fixture()
def plate_toml(tmp_path) -> Path:
    path = tmp_path / "plate.toml"
    path.write_text(absolute(PLATE) + "[output]\nformats = []\nreference = false\nframes = 4\n")
    return path


@pytest.fixture(scope="module")
def strip_files(tmp_path_factory) -> dict[str, Path]:
    """A 2-D steel strip (20 × 4 cells): its FE model and a 4-mode modal reduced model, as stage files."""
    folder = tmp_path_factory.mktemp("strip")
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5)).oriented()
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)},
                source="strip")
    model = assemble(mesh, "steel", order=1, thickness=0.002)
    reduced = reduce(model, Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4), "modal", 4)
    save_model(model, folder / "model.npz")
    save_reduced(reduced, folder / "reduced.npz")
    return {"model": folder / "model.npz", "reduced": folder / "reduced.npz", "system": reduced.system}


# ----------------------------------------------------------------------------- output places

@pytest.mark.parametrize("where, words", [
    ("afile", "is not a folder (a file)"),
    ("afile/sub", "'afile' is a file, not a folder"),
    ("/dev/null", "is not a folder (a device, pipe or socket)"),
    ("/proc/bladecase-hardening", "cannot be created: no such file or directory"),
])
def test_out_that_is_not_a_writable_folder(tmp_path, plate_toml, capsys, monkeypatch, where, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("mine")
    code, err = _run(["run", plate_toml, "--out", where, "--quiet", "--no-progress"], capsys)
    line = _one_error_line(err)
    assert code == 2 and words in line and where in line, err
    assert (tmp_path / "afile").read_text() == "mine"
    assert os.path.exists("/dev/null") and not Path("/dev/null").is_file()


def test_out_where_no_file_can_be_created(tmp_path, plate_toml, capsys, monkeypatch):
    """A read-only or full place (simulated: root may write anywhere): refused up front, before any work."""
    import bladecase.io as bio

    def refuse(*args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(bio.tempfile, "mkstemp", refuse)
    code, err = _run(["run", plate_toml, "--out", tmp_path / "ro", "--quiet", "--no-progress"], capsys)
    assert code == 2 and "read-only file system" in _one_error_line(err)


@pytest.mark.parametrize("option", ["--json", "--plot", "--table"])
def test_backbone_output_at_a_folder_is_refused_before_computing(tmp_path, capsys, monkeypatch, option):
    import bladecase.nsm as nsm

    monkeypatch.setattr(nsm, "backbone", lambda *a, **k: pytest.fail("computed before checking the output"))
    code, err = _run(CHAIN + [option, tmp_path], capsys)
    line = _one_error_line(err)
    assert code == 2 and "it is a folder; give a file path" in line and str(tmp_path) in line


@pytest.mark.parametrize("target, words", [
    ("afile/x.json", "'afile' is a file, not a folder"),
    ("/dev/null", "is not a regular file"),
])
def test_backbone_json_under_a_file_or_at_a_device(tmp_path, capsys, monkeypatch, target, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("mine")
    code, err = _run(CHAIN + ["--json", target], capsys)
    assert code == 2 and words in _one_error_line(err)
    assert Path("/dev/null").is_char_device() and (tmp_path / "afile").read_text() == "mine"


def test_full_disk_while_writing_is_one_line_and_leaves_no_temporary_file(tmp_path, capsys, monkeypatch):
    import bladecase.io as bio

    def full(src, dst):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(bio.os, "replace", full)
    code, err = _run(CHAIN + ["--json", tmp_path / "bb.json"], capsys)
    assert code == 2 and "no space left on device" in _one_error_line(err)
    assert list(tmp_path.iterdir()) == []


def test_stage_outputs_at_a_folder(tmp_path, plate_toml, strip_files, capsys):
    for argv in (["mesh", plate_toml, "-o", tmp_path], ["assemble", plate_toml, "-o", tmp_path],
                 ["reduce", plate_toml, "--model", strip_files["model"], "-o", tmp_path],
                 ["modes", plate_toml, "--reduced", strip_files["reduced"], "-o", tmp_path],
                 ["modes", plate_toml, "--reduced", strip_files["reduced"], "-o", tmp_path / "m.json",
                  "--plot", tmp_path]):
        code, err = _run(argv + ["--quiet"], capsys)
        assert code == 2 and "it is a folder; give a file path" in _one_error_line(err), argv
    assert list(tmp_path.iterdir()) == [plate_toml]


def test_save_mesh_at_a_folder_or_under_a_file(tmp_path):
    mesh = bc.load_mesh(Path(__file__).resolve().parent.parent / "meshes" / "plate.vtu")
    with pytest.raises(ValueError, match="it is a folder; give a file path"):
        bc.save_mesh(mesh, tmp_path)
    (tmp_path / "f").write_text("")
    with pytest.raises(ValueError, match="'.*f' is a file, not a folder"):
        bc.save_mesh(mesh, tmp_path / "f" / "m.vtu")


# ----------------------------------------------------------------------------- stage files

def _matrices(tmp_path, name="m.npz", **fields) -> Path:
    base = {"M": np.eye(3), "K": np.array([[2.0, -1, 0], [-1, 2, -1], [0, -1, 1]]), "w": 2, "gap": 1.0}
    base.update(fields)
    path = tmp_path / name
    np.savez(path, **{k: v for k, v in base.items() if v is not None})
    return path


def _truncated(path: Path) -> Path:
    out = path.with_name("truncated.npz")
    out.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    return out


def _corrupted(path: Path) -> Path:
    """The same archive with one member's compressed data overwritten (its CRC no longer matches)."""
    blob = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as z:
        info = max(z.infolist(), key=lambda i: i.compress_size)
    end = info.header_offset + 30 + len(info.filename) + len(info.extra) + info.compress_size
    blob[end - 24:end - 8] = bytes(b ^ 0xFF for b in blob[end - 24:end - 8])  # the member's last data bytes
    out = path.with_name("corrupted.npz")
    out.write_bytes(bytes(blob))
    return out


@pytest.mark.parametrize("make, words", [
    (lambda p: _truncated(_matrices(p)), "not a valid .npz file (truncated or corrupted"),
    (lambda p: _corrupted(_matrices(p)), "not a valid .npz file (truncated or corrupted"),
    (lambda p: (p / "r.npz").write_bytes(np.random.default_rng(0).bytes(4000)) and p / "r.npz",
     "not a valid .npz file (truncated, corrupted or another format"),
    (lambda p: (p / "e.npz").write_bytes(b"") or p / "e.npz", "the file is empty"),
    (lambda p: _matrices(p, gap=np.array([1.0, 2.0])),
     "field 'gap' must be a single number, got an array of shape (2,)"),
    (lambda p: _matrices(p, w=np.array("abc")), "field 'w' must hold numbers"),
    (lambda p: _matrices(p, w=np.array(1.7)), "must be an integer, got 1.7"),
    (lambda p: _matrices(p, K=np.eye(3) * (1 + 1e-3j)), "K must be real: 3 entries have a non-zero imaginary part"),
    (lambda p: _matrices(p, gap=1e300), "gap = 1e+300 is out of the range"),
    (lambda p: p / "missing.npz", "no such file"),
])
def test_bad_matrices_files(tmp_path, capsys, make, words):
    path = make(tmp_path)
    code, err = _run(["backbone", "--matrices", path, "--periods", "1:12:5", "--quiet", "--no-progress"], capsys)
    line = _one_error_line(err)
    assert code == 2 and words in line and path.name in line, err


def test_zero_d_integer_w_is_the_contact_dof(tmp_path, capsys):
    code, _ = _run(["backbone", "--matrices", _matrices(tmp_path, w=np.array(2.0)), "--periods", "1:12:5",
                    "--json", tmp_path / "b.json", "--quiet", "--no-progress"], capsys)
    assert code == 0 and json.loads((tmp_path / "b.json").read_text())["system"]["n"] == 3


def test_corrupted_model_and_reduced_files(tmp_path, strip_files):
    for key, loader, what in (("model", load_model, "FE model file"),
                              ("reduced", load_reduced, "reduced-model file")):
        for bad in (_truncated(strip_files[key]), _corrupted(strip_files[key])):
            with pytest.raises(ValueError, match=f"cannot read {what} '.*{bad.name}': not a valid .npz file"):
                loader(bad)


@pytest.mark.parametrize("key, value, words", [
    ("order", np.array("two"), "field 'order' must be a single integer, got 'two'"),
    ("thickness", np.array([0.002, 0.003]), "field 'thickness' must be a single number, got an array of shape (2,)"),
    ("K/data", np.array(["a", "b"]), "field 'K/data' must hold numbers"),
    ("mesh/points", np.zeros(3), "field 'mesh/points' must be a 2-D array"),
    ("dofs/node", None, "field 'dofs/node' is missing"),
])
def test_model_file_with_wrong_field_types(tmp_path, strip_files, key, value, words):
    with np.load(strip_files["model"]) as data:
        fields = {k: data[k] for k in data.files}
    if value is None:
        del fields[key]
    else:
        fields[key] = value
    np.savez(tmp_path / "edited.npz", **fields)
    with pytest.raises(ValueError) as info:
        load_model(tmp_path / "edited.npz")
    assert words in str(info.value) and "edited.npz" in str(info.value)


@pytest.mark.parametrize("key, value, words", [
    ("gap", np.array([1e-4, 2e-4]), "field 'gap' must be a single number"),
    ("w", np.array("abc"), "field 'w' must hold numbers"),
    ("method", np.array(3), "field 'method' must be a single string"),
])
def test_reduced_file_with_wrong_field_types(tmp_path, strip_files, key, value, words):
    with np.load(strip_files["reduced"]) as data:
        fields = {k: data[k] for k in data.files}
    fields[key] = value
    np.savez(tmp_path / "edited.npz", **fields)
    with pytest.raises(ValueError, match="edited.npz") as info:
        load_reduced(tmp_path / "edited.npz")
    assert words in str(info.value)


# ----------------------------------------------------------------------------- modes files

@pytest.fixture(scope="module")
def strip_modes(strip_files) -> str:
    """The strip's modes file (a 1-ipp backbone with admissible arcs) as JSON text, computed once for the module."""
    system = strip_files["system"]
    branch = bc.backbone(system, np.linspace(0.5, 0.9999, 40) * system.spectrum.periods[0])
    assert branch.arcs, "the fixture needs admissible arcs"
    return json.dumps(families_document([branch], system))


def _modes_file(tmp_path, text: str, edit) -> Path:
    """The modes file ``text``, edited by ``edit`` (each test its own copy)."""
    doc = json.loads(text)
    edit(doc)
    path = tmp_path / "modes.json"
    path.write_text(json.dumps(doc))
    return path


def _drop_admissible_orbits(doc):
    fam = doc["families"][0]
    fam["orbits"] = fam["orbits"][: fam["arcs"][0]["start"]]


def _mark_inadmissible(doc):
    for orbit in doc["families"][0]["orbits"]:
        orbit["admissible"] = False


@pytest.mark.parametrize("edit, words", [
    (_drop_admissible_orbits, "arc 0 spans orbits"),
    (_mark_inadmissible, "which is not admissible: an arc spans admissible orbits only"),
    (lambda d: d.update(system_dofs="4"), "'system_dofs' must be an integer number of dofs, got '4'"),
    (lambda d: d.update(system_dofs=7), "computed on a system of 7 dofs, this one has 4"),
    (lambda d: d.pop("families"), "is not a bladecase modes file"),
])
def test_animate_with_a_broken_modes_file(tmp_path, plate_toml, strip_files, strip_modes, capsys, edit, words):
    modes = _modes_file(tmp_path, strip_modes, edit)
    code, err = _run(["animate", plate_toml, "--reduced", strip_files["reduced"], "--modes", modes,
                      "--out", tmp_path / "anim", "--quiet", "--no-progress"], capsys)
    line = _one_error_line(err)
    assert code == 2 and words in line and "modes.json" in line, err
    assert not (tmp_path / "anim").exists() or not any((tmp_path / "anim").iterdir())


# ----------------------------------------------------------------------------- values the CLI caps

@pytest.mark.parametrize("args, words", [
    (["--ipp", "50"], "1 <= K <= 8, got 50"),
    (["--ipp", "10"], "1 <= K <= 8, got 10"),
    (["--periods", "1:12:100000000"], "COUNT must be <= 100000"),
])
def test_backbone_refuses_work_out_of_proportion(capsys, args, words):
    code, err = _run(["backbone", "--chain", "2", "--gap", "1", "--periods", "1:12:5", *args], capsys)
    assert code == 2 and words in _one_error_line(err)


# ----------------------------------------------------------------------------- interruptions

def _fake_previous_results(out: Path) -> dict[str, bytes]:
    from bladecase.study import publish as pub

    staging = pub.staging_dir(out)  # published by bladecase: listed in the signed manifest
    (staging / "summary.json").write_text(json.dumps({"bladecase_version": bc.__version__, "outputs": [
        "summary.json", "report.md"]}))
    (staging / "report.md").write_text("# the previous report\n")
    pub.publish(staging, out)
    (out / "notes.txt").write_text("mine")
    return {p.name: p.read_bytes() for p in out.iterdir()}


@pytest.mark.parametrize("signum, code, word", [(signal.SIGINT, 130, "interrupted"),
                                                (signal.SIGTERM, 143, "terminated")])
def test_interrupted_run_leaves_previous_results_untouched(tmp_path, plate_toml, capsys, monkeypatch, signum,
                                                           code, word):
    run_module = importlib.import_module("bladecase.study.run")  # (bladecase.study.run is the function)

    out = tmp_path / "out"
    before = _fake_previous_results(out)
    handler = signal.getsignal(signal.SIGTERM)
    seen = []

    def interrupted(study, staging, *args):
        seen.append(sorted(p.name for p in out.iterdir()))  # staging and lock exist during the run
        (staging / "modes.json").write_text("half")
        os.kill(os.getpid(), signum)  # Ctrl-C raises KeyboardInterrupt; SIGTERM, the CLI's handler
        raise AssertionError("not reached")

    monkeypatch.setattr(run_module, "_compute", interrupted)
    rc, err = _run(["run", plate_toml, "--out", out, "--quiet", "--no-progress"], capsys)
    assert rc == code
    assert _one_error_line(err) == f"bladecase run: {word}, previous results untouched"
    assert any(n.startswith(".bladecase-run-") for n in seen[0]) and ".bladecase.lock" in seen[0]
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # no staging, no lock, nothing changed
    assert signal.getsignal(signal.SIGTERM) == handler  # the CLI's SIGTERM handler is gone


def test_ctrl_c_in_a_stage_command(capsys, monkeypatch):
    import bladecase.cli_backbone as backbone

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(backbone, "load_system", interrupted)
    code, err = _run(CHAIN, capsys)
    assert code == 130 and _one_error_line(err) == "bladecase backbone: interrupted, previous results untouched"
