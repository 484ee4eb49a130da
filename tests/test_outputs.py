"""Adding an output format is one new file plus one registration (``docs/architecture.md``).

The file is played here by :func:`write_csv` (the example of :mod:`bladecase.post.outputs.registry`), the
registration by :func:`bladecase.post.outputs.register`; nothing else changes:

* a study that asks for ``[output] formats = ["csv"]`` runs through :func:`bladecase.study.run`, writes one
  ``csv/<stem>.csv`` per animated orbit, names it in ``summary.json``, and writes no other format's files;
  the CSV starts at the impact, where the contact node is at the casing (displacement = clearance);
* the schema accepts ``"csv"`` only while it is registered, and otherwise names the valid formats;
* :meth:`~bladecase.post.outputs.registry.OutputRegistry.write` calls a writer shared by several names once.

Every registration made here is undone in a ``finally``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from _studies import PLATE, absolute

from bladecase.post.outputs import FORMATS, register
from bladecase.study import run
from bladecase.study.schema import StudyError, loads

FRAMES = 6
CLEARANCE = 1e-4  # [contact] clearance of the plate study

# reference = false: the orbits' check in a reference model is tested in tests/test_reference.py
STUDY = absolute(PLATE) + f"""\
[output]
frames = {FRAMES}
formats = ["csv"]
reference = false
"""


def write_csv(scene, folder: Path, formats: set[str]) -> dict[str, str]:
    """The new format's file: time and contact-node normal displacement over one period."""
    path = folder / "csv" / f"{scene.stem}.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, np.c_[scene.times, scene.contact_displacement], delimiter=",",
               header="t (s), contact displacement (m)")
    return {"csv": f"csv/{path.name}"}


def register_csv():
    assert "csv" not in FORMATS, "a csv format is already registered: this test would not be adding one"
    return register("csv", write_csv, "orbit", "contact displacement over one period, CSV")


@pytest.fixture(scope="module")
def csv_run(tmp_path_factory):
    """The plate study run with the csv format registered for the run only."""
    out = tmp_path_factory.mktemp("csv") / "run"
    register_csv()
    try:
        study = loads(STUDY)
        result = run(study, out, progress=False)
    finally:
        FORMATS.unregister("csv")
    return result


def test_csv_format_is_written_for_every_animated_orbit(csv_run):
    out = csv_run.directory
    anims = csv_run.summary["files"]["animations"]
    assert len(anims) >= 1
    names = [a["csv"] for a in anims]
    assert all(re.fullmatch(r"csv/[^/]+\.csv", n) for n in names), names
    assert len(set(names)) == len(names)
    assert sorted(p.name for p in (out / "csv").iterdir()) == sorted(Path(n).name for n in names)
    assert json.loads((out / "summary.json").read_text())["files"]["animations"] == \
        json.loads(json.dumps(anims))
    for a in anims:
        data = np.loadtxt(out / a["csv"], delimiter=",")
        assert data.shape == (FRAMES, 2) == (a["frames"], 2)
        t, u = data.T
        assert t[0] == 0.0 and np.all(np.diff(t) > 0) and t[-1] < a["T"]
        # t = 0 is an impact: the contact node is at the casing; admissible: never beyond it
        assert u[0] == pytest.approx(CLEARANCE, rel=1e-9)
        assert np.all(u <= CLEARANCE * (1 + 1e-9))


def test_csv_run_writes_no_other_format(csv_run):
    out = csv_run.directory
    for a in csv_run.summary["files"]["animations"]:
        assert not {"gif", "mp4", "pvd", "manifold"} & set(a), a
    assert not (out / "animations").exists() and not (out / "vtk").exists()
    assert not (out / "frequency_energy.png").exists()  # png (run scope) was not asked for either
    assert [p.name for p in out.rglob("*.gif")] == [] and [p.name for p in out.rglob("*.pvd")] == []
    assert [p.relative_to(out).as_posix() for p in out.rglob("*.vtu")] == ["mesh.vtu"]  # the mesh, always


def test_schema_names_valid_formats_and_accepts_csv_only_while_registered():
    valid = ", ".join(FORMATS)
    with pytest.raises(StudyError, match=re.escape(f"[output] formats: unknown format(s) ['csv'] (valid: {valid})")):
        loads(STUDY)
    register_csv()
    try:
        assert loads(STUDY)["output"]["formats"] == ["csv"]
        with pytest.raises(StudyError, match=re.escape(f"unknown format(s) ['pdf'] (valid: {valid}, csv)")):
            loads(STUDY.replace('formats = ["csv"]', 'formats = ["csv", "pdf"]'))
    finally:
        FORMATS.unregister("csv")
    assert "csv" not in FORMATS
    with pytest.raises(StudyError, match=re.escape("unknown format(s) ['csv']")):
        loads(STUDY)


def test_write_calls_a_shared_writer_once(tmp_path):
    assert FORMATS.entry("gif").writer is FORMATS.entry("mp4").writer  # the built-in shared pair
    calls: list[tuple[str, object, Path, set]] = []

    def frames(scene, folder, formats):
        calls.append(("frames", scene, folder, set(formats)))
        return {name: f"{name}/x" for name in formats}

    def plot(scene, folder, formats):
        calls.append(("plot", scene, folder, set(formats)))
        return {"plot": "plot.txt"}

    added = []
    try:
        for name, writer, scope in (("alpha", frames, "orbit"), ("beta", frames, "orbit"), ("gamma", plot, "run")):
            added.append(register(name, writer, scope, f"test format {name}").name)
        scene = object()
        written = FORMATS.write(["alpha", "beta", "gamma"], "orbit", scene, tmp_path)
        assert calls == [("frames", scene, tmp_path, {"alpha", "beta"})]
        assert written == {"alpha": "alpha/x", "beta": "beta/x"}
        calls.clear()
        assert FORMATS.write(["alpha", "beta", "gamma"], "run", scene, str(tmp_path)) == {"plot": "plot.txt"}
        assert calls == [("plot", scene, tmp_path, {"gamma"})]  # folder given as str, passed as a Path
        with pytest.raises(ValueError, match=r"unknown output format 'delta' \(valid: .*'alpha', 'beta', 'gamma'\)"):
            FORMATS.write(["alpha", "delta"], "orbit", scene, tmp_path)
    finally:
        for name in added:
            FORMATS.unregister(name)
    assert not {"alpha", "beta", "gamma"} & set(FORMATS)


def test_a_later_run_removes_a_format_folder_it_no_longer_writes_and_nothing_else(tmp_path):
    """The folder of a format written by an earlier run (recorded in the results manifest) goes when the next
    run does not write it; a user's file in the output directory stays."""
    out = tmp_path / "run"
    register_csv()
    try:
        run(loads(STUDY), out, progress=False)
    finally:
        FORMATS.unregister("csv")
    assert (out / "csv").is_dir()
    (out / "notes.txt").write_text("mine")
    run(loads(STUDY.replace('formats = ["csv"]', 'formats = ["png"]')), out, progress=False)
    assert not (out / "csv").exists() and (out / "frequency_energy.png").is_file()
    assert (out / "notes.txt").read_text() == "mine"
