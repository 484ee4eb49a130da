"""The output folder is the user's: a run replaces or removes only what it can prove it wrote (a manifest
signed with the user's key, content hashes checked), never follows a planted link, refuses outputs onto its
own inputs, and leaves either the previous complete result set or the new one whatever kills it."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import textwrap
import time
from pathlib import Path

import pytest
from _studies import PLATE, absolute
from conftest import fork_script, run_forked

from bladecase.cli import main
from bladecase.study import manifest as mf
from bladecase.study import publish as pub


def _tree(folder: Path) -> dict[str, bytes | None]:
    """Every entry under ``folder``: files with their bytes, folders as ``None``, links by their target."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        out[rel] = (b"->" + os.readlink(p).encode()) if p.is_symlink() else None if p.is_dir() else p.read_bytes()
    return out


def _results(out: Path, files: dict[str, str]) -> None:
    """Publish ``files`` (name → text; ``a/b`` makes a folder ``a``) into ``out`` as a run would."""
    staging = pub.staging_dir(out, [n.split("/")[0] for n in files])
    for name, text in files.items():
        (staging / name).parent.mkdir(parents=True, exist_ok=True)
        (staging / name).write_text(text)
    pub.publish(staging, out, pub.RUN_RESULTS, whole=True)


def _run(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


@pytest.fixture()
def plate_toml(tmp_path) -> Path:
    path = tmp_path / "plate.toml"
    path.write_text(absolute(PLATE) + "[output]\nformats = []\nreference = false\nframes = 4\n")
    return path


# ----------------------------------------------------------------------------- the user's entries stay

@pytest.mark.parametrize("entries", [
    {"animations/talk.gif": "my GIF", "animations/notes.mp4": "my film"},          # only what bladecase writes there
    {"vtk/blade.pvd": "<VTKFile/>", "vtk/blade/blade_0.vtu": "frame", "vtk/blade_manifold.vtu": "m"},
    {"report.md": "my notes"},
])
def test_a_run_never_replaces_a_users_entry_that_looks_like_a_result(tmp_path, entries):
    out = tmp_path / "out"
    for name, text in entries.items():
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(text)
    before = _tree(out)
    top = next(iter(entries)).split("/")[0]
    with pytest.raises(ValueError, match=rf"already holds '{top}', not written by a bladecase run of yours"):
        pub.staging_dir(out)
    assert _tree(out) == before


def test_animate_refuses_a_users_animations_folder(tmp_path):
    out = tmp_path / "out"
    (out / "animations").mkdir(parents=True)
    (out / "animations" / "holiday.gif").write_text("mine")
    before = _tree(out)
    with pytest.raises(ValueError, match="already holds 'animations'"):
        pub.staging_dir(out, ("animations", "vtk"))
    assert _tree(out) == before


def test_a_result_changed_by_hand_is_the_users(tmp_path):
    out = tmp_path / "out"
    _results(out, {"report.md": "report", "animations/a.gif": "gif"})
    (out / "animations" / "my_notes.txt").write_text("notes added after the run")
    with pytest.raises(ValueError, match=r"holds 'animations', changed since bladecase wrote it"):
        pub.staging_dir(out)
    # a stale result bladecase cannot prove its own is left in place, with a warning, never removed
    staging = pub.staging_dir(out, ("report.md",))
    (staging / "report.md").write_text("new report")
    pub.publish(staging, out, pub.RUN_RESULTS, whole=True)
    assert (out / "animations" / "my_notes.txt").read_text() == "notes added after the run"
    assert (out / "report.md").read_text() == "new report"
    assert pub.owned(out) == {"report.md"}


def test_results_are_replaced_and_stale_ones_removed_when_proved(tmp_path):
    out = tmp_path / "out"
    _results(out, {"report.md": "1", "forced.csv": "1", "vtk/a.pvd": "1", "vtk/a/a_0.vtu": "1"})
    assert pub.owned(out) == {"report.md", "forced.csv", "vtk"}
    (out / "notes.txt").write_text("mine")
    _results(out, {"report.md": "2", "animations/b.gif": "2"})
    assert sorted(p.name for p in out.iterdir()) == [pub.MANIFEST, "animations", "notes.txt", "report.md"]
    assert (out / "report.md").read_text() == "2" and (out / "notes.txt").read_text() == "mine"


def test_user_folders_named_like_bladecases_own_are_kept(tmp_path):
    out = tmp_path / "out"
    for name in (".vtk.old-2024", ".animations.old-x", ".bladecase-run-notes"):
        (out / name).mkdir(parents=True)
        (out / name / "thesis.tex").write_text("mine")
    before = _tree(out)
    _results(out, {"report.md": "r"})
    after = _tree(out)
    assert {k: v for k, v in after.items() if k in before} == before


# ----------------------------------------------------------------------------- planted files are not trusted

def test_a_planted_summary_naming_a_users_folder_deletes_nothing(tmp_path):
    out = tmp_path / "out"
    (out / "thesis").mkdir(parents=True)
    (out / "thesis" / "chapter1.tex").write_text("mine")
    (out / "summary.json").write_text(json.dumps({"bladecase_version": "0.1.0",
                                                  "outputs": ["thesis", "summary.json", "report.md"]}))
    before = _tree(out)
    with pytest.raises(ValueError, match="already holds 'summary.json'"):
        pub.staging_dir(out)
    assert _tree(out) == before
    (out / "summary.json").unlink()
    _results(out, {"report.md": "r"})
    assert (out / "thesis" / "chapter1.tex").read_text() == "mine"


@pytest.mark.parametrize("how", ["unsigned", "another key", "edited"])
def test_a_planted_or_edited_manifest_proves_nothing(tmp_path, monkeypatch, how):
    out = tmp_path / "out"
    _results(out, {"report.md": "r"})
    (out / "thesis").mkdir()
    (out / "thesis" / "chapter1.tex").write_text("mine")
    doc = json.loads((out / mf.MANIFEST).read_text())
    doc["entries"]["thesis"] = mf.entry_hash(out / "thesis")  # the planted entry has the right hash
    if how == "unsigned":
        del doc["signature"]
    elif how == "another key":
        monkeypatch.setenv("BLADECASE_KEY_FILE", str(tmp_path / "attacker.key"))
        doc = mf.sign(doc)
        monkeypatch.delenv("BLADECASE_KEY_FILE")
    (out / mf.MANIFEST).write_text(json.dumps(doc))
    assert "thesis" not in pub.owned(out)
    with pytest.raises(ValueError, match="already holds 'report.md'"):  # the whole manifest fails
        pub.staging_dir(out, ("report.md", "thesis"))
    assert (out / "thesis" / "chapter1.tex").read_text() == "mine"


def test_results_of_another_user_are_not_replaced(tmp_path, monkeypatch):
    out = tmp_path / "out"
    monkeypatch.setenv("BLADECASE_KEY_FILE", str(tmp_path / "colleague.key"))
    _results(out, {"report.md": "colleague's"})
    monkeypatch.delenv("BLADECASE_KEY_FILE")
    with pytest.raises(ValueError, match="already holds 'report.md', not written by a bladecase run of yours"):
        pub.staging_dir(out)
    assert (out / "report.md").read_text() == "colleague's"


@pytest.mark.parametrize("name", [pub.LOCK, pub.MARKER])
def test_a_planted_link_is_never_written_through(tmp_path, name):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "thesis.tex"
    victim.write_text("years of work")
    (out / name).symlink_to(victim)
    with pytest.raises(ValueError, match=rf"{name} is a symbolic link"):
        pub.staging_dir(out)
    assert victim.read_text() == "years of work" and (out / name).is_symlink()


def test_a_hard_linked_lock_is_refused(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "thesis.tex"
    victim.write_text("years of work")
    os.link(victim, out / pub.LOCK)
    with pytest.raises(ValueError, match="a hard link to another file"):
        pub.staging_dir(out)
    assert victim.read_text() == "years of work"


def test_a_planted_journal_naming_a_users_folder_is_ignored(tmp_path, caplog):
    out = tmp_path / "out"
    _results(out, {"report.md": "r"})
    (out / "animations").mkdir()
    (out / "animations" / "notes.txt").write_text("mine")
    (out / pub.MARKER).write_text(json.dumps({"staging": ".bladecase-run-x", "moves": [], "removes": ["animations"],
                                              "entries": {}, "before": {"animations": "x"}}))
    with caplog.at_level("WARNING", logger="bladecase"):
        staging = pub.staging_dir(out, ("report.md",))
    assert "not a publication journal of your bladecase runs" in caplog.text
    (staging / "report.md").write_text("new")
    pub.publish(staging, out, ("report.md", "animations"), whole=True)
    assert (out / "animations" / "notes.txt").read_text() == "mine"


# ----------------------------------------------------------------------------- where results may go

def test_empty_or_enclosing_output_folders_are_refused(tmp_path, plate_toml, capsys, monkeypatch):
    before = _tree(tmp_path)
    code, err = _run(["run", plate_toml, "--out", "", "--quiet", "--no-progress"], capsys)
    assert code == 2 and "--out: expected a folder, got an empty name ''" in err
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    code, err = _run(["run", plate_toml, "--out", "..", "--quiet", "--no-progress"], capsys)
    assert code == 2 and "holds the working folder" in err
    assert {k for k in _tree(tmp_path)} == set(before) | {"work"}
    from bladecase.study import run
    from bladecase.study.schema import load_study

    with pytest.raises(ValueError, match="empty name"):
        run(load_study(plate_toml), out="", progress=False)


def test_a_study_file_inside_a_result_entry_is_refused(tmp_path, plate_toml):
    from bladecase.study import run
    from bladecase.study.schema import load_study

    out = tmp_path / "out"
    (out / "vtk").mkdir(parents=True)
    inside = out / "vtk" / "study.toml"
    inside.write_text(plate_toml.read_text())
    with pytest.raises(ValueError, match="which this run replaces"):
        run(load_study(inside), out=out, progress=False)
    assert inside.read_text() == plate_toml.read_text()


# ----------------------------------------------------------------------------- stage commands and their inputs

def test_stage_commands_refuse_to_write_onto_their_inputs(tmp_path, plate_toml, capsys):
    import numpy as np

    study_bytes = plate_toml.read_bytes()
    code, err = _run(["assemble", plate_toml, "-o", plate_toml, "--quiet"], capsys)
    assert code == 2 and f"-o {str(plate_toml)!r} is its input STUDY" in err
    code, err = _run(["mesh", plate_toml, "-o", plate_toml, "--quiet"], capsys)
    assert code == 2 and "is its input STUDY" in err
    assert plate_toml.read_bytes() == study_bytes
    model = tmp_path / "model.npz"
    assert _run(["assemble", plate_toml, "-o", model, "--quiet"], capsys)[0] == 0
    model_bytes = model.read_bytes()
    code, err = _run(["reduce", plate_toml, "--model", model, "-o", model, "--quiet"], capsys)
    assert code == 2 and "is its input --model" in err and model.read_bytes() == model_bytes
    reduced = tmp_path / "reduced.npz"
    assert _run(["reduce", plate_toml, "--model", model, "-o", reduced, "--quiet"], capsys)[0] == 0
    reduced_bytes = reduced.read_bytes()
    code, err = _run(["modes", plate_toml, "--reduced", reduced, "-o", reduced, "--quiet"], capsys)
    assert code == 2 and "is its input --reduced" in err and reduced.read_bytes() == reduced_bytes
    code, err = _run(["modes", plate_toml, "--reduced", reduced, "-o", tmp_path / "m.json", "--plot",
                      tmp_path / "link_to_reduced.npz", "--quiet"], capsys) if (
        (tmp_path / "link_to_reduced.npz").symlink_to(reduced) or True) else (0, "")
    assert code == 2 and "is its input --reduced" in err and reduced.read_bytes() == reduced_bytes
    matrices = tmp_path / "m.npz"
    np.savez(matrices, M=np.eye(2), K=np.array([[2.0, -1.0], [-1.0, 2.0]]), w=np.array([0.0, 1.0]), gap=1.0)
    code, err = _run(["backbone", "--matrices", matrices, "--periods", "1:2:3", "--json", matrices], capsys)
    assert code == 2 and "is its input --matrices" in err


# ----------------------------------------------------------------------------- kills and races while publishing

_PUBLISHER = textwrap.dedent("""
    import os, signal, sys
    from pathlib import Path
    from bladecase.study import publish as pub

    out, kill_at, signum = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    staging = pub.staging_dir(out)
    for name, text in {"modes.json": "new modes", "report.md": "new report", "summary.json": "new summary",
                       "animations/b.gif": "new gif", "vtk/b.pvd": "new pvd"}.items():
        (staging / name).parent.mkdir(parents=True, exist_ok=True)
        (staging / name).write_text(text)
    calls = [0]
    real = {"replace": os.replace, "rename": os.rename}

    def hooked(kind):
        def move(src, dst):
            calls[0] += 1
            if calls[0] == kill_at:
                os.kill(os.getpid(), signum)
            return real[kind](src, dst)
        return move

    os.replace, os.rename = hooked("replace"), hooked("rename")
    pub.publish(staging, out, pub.RUN_RESULTS, whole=True)
    print("moves", calls[0])
""")

_OLD = {"modes.json": "old modes", "report.md": "old report", "summary.json": "old summary", "run.log": "old log",
        "animations/a.gif": "old gif", "vtk/a.pvd": "old pvd"}
_NEW = {"modes.json": "new modes", "report.md": "new report", "summary.json": "new summary",
        "animations/b.gif": "new gif", "vtk/b.pvd": "new pvd"}


def _publisher(out: Path, kill_at: int, signum: int) -> tuple[int, str]:
    """``_PUBLISHER`` on ``out`` in a forked child (conftest's :func:`run_forked`: bladecase already imported, no
    interpreter start per run), sending itself ``signum`` at its ``kill_at``-th move: its exit code (``-signum``
    when cut) and output."""
    return run_forked(_PUBLISHER, out, kill_at, int(signum))


def _forked_publisher(out: Path, kill_at: int) -> int:
    """``_PUBLISHER`` SIGKILLed at its ``kill_at``-th move; its exit code (``-SIGKILL`` when cut)."""
    return _publisher(out, kill_at, signal.SIGKILL)[0]


def _files(out: Path) -> dict[str, str]:
    return {str(p.relative_to(out)): p.read_text() for p in out.rglob("*")
            if p.is_file() and not p.name.startswith(".")}


def test_publishing_cut_by_sigkill_at_every_step_leaves_old_or_new(tmp_path):
    """SIGKILL at every move of a publication (the journal's, each entry's, each folder set aside, the manifest):
    after the next run's recovery the folder holds exactly the previous result set or the new one."""
    out = tmp_path / "out"
    _results(out, _OLD)
    template = tmp_path / "template"
    os.rename(out, template)
    subprocess.run(["cp", "-a", str(template), str(tmp_path / "probe")], check=True)
    code, output = _publisher(tmp_path / "probe", 10**6, signal.SIGKILL)  # count the moves of a whole publication
    assert code == 0, output
    moves = int(output.split()[-1])
    assert moves >= 8
    seen = set()
    for k in range(1, moves + 1):
        out = tmp_path / f"out{k}"
        subprocess.run(["cp", "-a", str(template), str(out)], check=True)
        assert _forked_publisher(out, k) == -signal.SIGKILL, k
        pub.recover(out)
        staging = pub.staging_dir(out, ())  # what the next run sees (and cleans up)
        pub.release(out)
        staging_files = list(staging.iterdir())
        assert [p.name for p in staging_files] == [".bladecase-staging"]
        got = _files(out)
        assert got in (_OLD, _NEW), (k, got)
        assert pub.owned(out) == {n.split("/")[0] for n in got}, k  # the manifest proves every entry
        seen.add("old" if got == _OLD else "new")
    assert seen == {"old", "new"}


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_sigterm_or_ctrl_c_while_publishing_waits_for_the_whole_new_set(tmp_path, signum):
    out = tmp_path / "out"
    _results(out, _OLD)
    code, output = _publisher(out, 3, signum)
    assert code in (-signum, 1), output  # killed by the signal once the entries are in place
    assert not (out / pub.MARKER).exists()
    assert _files(out) == _NEW


_RACER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from bladecase.study import publish as pub

    out, tag = Path(sys.argv[1]), sys.argv[2]
    (out.parent / f"ready-{tag}").touch()  # imported: both racers start together, whatever the machine's load
    while not (out.parent / "go").exists():
        time.sleep(0.01)
    try:
        staging = pub.staging_dir(out)
    except pub.OutputInUse as exc:
        print("refused", exc)
        (out.parent / "refused").touch()
        sys.exit(3)
    for name in ("modes.json", "report.md", "summary.json"):
        (staging / name).write_text(tag)
    # the folder is held until the other run was refused (60 s at most: a run let in as well fails the test)
    deadline = time.monotonic() + 60
    while not (out.parent / "refused").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    pub.publish(staging, out, pub.RUN_RESULTS, whole=True)
    print("published")
""")


def test_two_runs_into_one_folder(tmp_path):
    out = tmp_path / "out"
    _results(out, {"modes.json": "old", "report.md": "old", "summary.json": "old"})
    procs = [fork_script(_RACER, out, tag, log=tmp_path / f"{tag}.log") for tag in ("first", "second")]
    deadline = time.monotonic() + 120
    while not all((tmp_path / f"ready-{tag}").exists() for tag in ("first", "second")):
        assert time.monotonic() < deadline and all(p.is_alive() for p in procs), "a racer did not start"
        time.sleep(0.01)
    (tmp_path / "go").touch()
    for p in procs:
        p.join(120)
    outputs = [(tmp_path / f"{tag}.log").read_text() for tag in ("first", "second")]
    codes = sorted(p.exitcode for p in procs)
    assert codes == [0, 3], outputs
    assert "in use by another bladecase run" in "".join(outputs)
    values = set(_files(out).values())
    assert len(values) == 1 and values <= {"first", "second"}
