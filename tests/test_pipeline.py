"""End to end: study file → mesh → FE → reduced model → nonsmooth modes → animations, VTK, report.

* The demo study at tiny resolution (coarser mesh, 6 Lanczos steps, 4 start
  periods, 8 frames of 320×240) runs through :func:`bladecase.study.pipeline.run`
  and writes every result; each file is read back and checked against the
  physics: at frame 0 (an impact) the contact node is at the casing, ``ν·u =
  d`` to 1e-9·d, and ``ν·u <= d`` on every frame; the event-driven simulator
  started from each animated orbit's post-impact state returns to it
  (``VERIFY_RTOL`` = 1e-8; measured 1e-14–4e-11).
* A user mesh (``meshes/plate.vtu``, not ``.msh``) study runs, through
  ``bladecase run`` and through the stage commands (mesh → assemble →
  reduce → modes → animate) with the same families.
* A run that fails while rendering leaves the previous results untouched and
  no staging folder.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import shutil
from pathlib import Path

import imageio.v3 as iio
import meshio
import numpy as np
import pytest
from _studies import PLATE as PLATE_BASE
from _studies import ROOT, absolute, as_raw

import bladecase as bc
from bladecase.cli import main
from bladecase.fe.assembly import load_model, save_model
from bladecase.post.animation import mp4_available
from bladecase.post.vtk import read_time_series
from bladecase.reduction import load_reduced, reduce, save_reduced
from bladecase.study import pipeline
from bladecase.study.demo import demo_study
from bladecase.study.schema import loads, validate

FRAMES = 8
WINDOW = (320, 240)


def tiny_demo():
    """The demo blade with the seed paper's Newton contact on its tip node (the demo itself is massless)."""
    c = copy.deepcopy(demo_study("newton").config)
    c["geometry"].update(size=0.01, tip_size=0.005)
    c["reduction"]["size"] = 6
    c["search"]["scan"] = 4
    # rendering tests: the Newton orbits of a 6-dof Lanczos model do not survive in a reference model
    # (tests/test_reference.py), so the reference check is off here
    c["output"].update(frames=FRAMES, window=list(WINDOW), manifold_size=[10, 16], reference=False)
    return validate(as_raw(c), source="<tiny demo>")


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    return pipeline.run(tiny_demo(), out=out, progress=False)


def test_demo_writes_every_file(demo_run):
    out = demo_run.directory
    s = json.loads((out / "summary.json").read_text())
    assert s == json.loads(json.dumps(demo_run.summary))
    for name in ("summary.json", "report.md", "run.log", "modes.json", "frequency_energy.png", "mesh.vtu"):
        assert (out / name).stat().st_size > 0, name
    anims = s["files"]["animations"]
    assert len(anims) == 2
    for a in anims:
        assert (out / a["gif"]).exists() and (out / a["pvd"]).exists() and (out / a["manifold"]).exists()
        assert ("mp4" in a) == mp4_available()
        if "mp4" in a:
            assert (out / a["mp4"]).stat().st_size > 1000
    # nothing hidden left behind (staging folders, temporary files) but the signed manifest of the results
    assert [p.name for p in out.rglob(".*")] == [".bladecase-manifest.json"]
    report = (out / "report.md").read_text()
    for a in anims:
        assert a["gif"] in report
    assert "Linear frequencies" in report and "Nonsmooth modes" in report


def test_summary_model_and_families(demo_run):
    s = demo_run.summary
    m = s["model"]
    assert m["dim"] == 3 and m["mass_matrix"] == "lumped" and m["order"] == 2 and m["dofs"] > 1000
    assert m["material"]["name"] == "Ti-6Al-4V"
    f = np.array(m["linear_frequencies_hz"])
    assert np.all(np.diff(f) > 0) and 150 < f[0] < 300  # a 15 cm titanium blade (converged P2: 213.6 Hz)
    # shift-invert Lanczos resolves the lowest modes: reduced = FE to 1e-8
    assert s["reduction"]["relative_error_vs_fe"][0] < 1e-8
    fams = s["families"]
    assert {f["ipp"] for f in fams} == {1, 2}
    assert sum(len(f["admissible_arcs"]) for f in fams) >= 2
    T_unit = s["search"]["period_unit_s"]
    assert T_unit == pytest.approx(1 / s["reduction"]["frequencies_hz"][0], rel=1e-12)
    for fam in fams:
        for arc in fam["admissible_arcs"]:
            assert 0.9 * T_unit * (1 - 1e-9) <= arc["T_lo"] <= arc["T_hi"] <= 0.9999 * T_unit * (1 + 1e-9)
    for a in s["files"]["animations"]:
        assert a["verification"]["ok"] and a["verification"]["return_error"] < 1e-8
        assert a["verification"]["impacts"] == a["ipp"]


def test_modes_json_reloads(demo_run):
    reduced = pipeline.build_reduced(*_demo_model_and_contact())
    fams = pipeline.load_families(demo_run.directory / "modes.json", reduced.system)
    assert len(fams) == len(demo_run.families)
    for a, b in zip(fams, demo_run.families):
        assert a.k == b.k and np.array_equal(a.T, b.T) and np.array_equal(a.admissible, b.admissible)


def _demo_model_and_contact():
    st = tiny_demo()
    model = pipeline.build_model(st, pipeline.build_mesh(st))
    return st, model, pipeline.build_contact(st, model)


def test_time_series_reads_back(demo_run):
    out = demo_run.directory
    s = demo_run.summary
    mesh = bc.load_mesh(out / "mesh.vtu")
    node = s["contact"]["node"]
    nu = np.array(s["contact"]["normal"])
    d = s["contact"]["clearance_m"]
    for a in s["files"]["animations"]:
        times, files = read_time_series(out / a["pvd"])
        assert len(files) == FRAMES and np.all(np.diff(times) > 0)
        assert times[0] == 0.0 and times[-1] < a["T"]
        # impacts are frames: t = 0 and each impact instant (moved onto its nearest frame)
        for ti in np.mod(a["impact_times"], a["T"]):
            if min(ti, a["T"] - ti) <= 1e-12 * a["T"]:
                continue  # t_k = T: the impact at t = 0
            assert np.min(np.abs(times - ti)) < 1e-12 * a["T"]
        # frames carry every FE node of the P2 model (corners and edge nodes, quadratic cells): the mesh's
        # nodes are among them at their own positions
        grid = meshio.read(files[0])
        assert "tetra10" in grid.cells_dict and len(grid.points) > len(mesh.points)
        def at(p, points=grid.points):
            return int(np.argmin(np.linalg.norm(points - p, axis=1)))

        contact = at(mesh.points[node])
        assert np.array_equal(grid.points[contact], mesh.points[node])
        gaps = []
        for t, f in zip(times, files):
            frame = meshio.read(f)
            assert np.array_equal(frame.points, grid.points)
            u = frame.point_data["displacement"]
            v = frame.point_data["velocity"]
            assert u.shape == (len(grid.points), 3) and v.shape == u.shape
            assert np.allclose(frame.point_data["displacement_magnitude"], np.linalg.norm(u, axis=1), rtol=1e-12)
            assert float(frame.field_data["time"][0]) == t
            assert float(frame.field_data["period"][0]) == a["T"]
            gaps.append(float(u[contact] @ nu))
        gaps = np.array(gaps)
        assert gaps[0] == pytest.approx(d, rel=1e-9)  # t = 0: the contact node is at the casing
        assert gaps.max() <= d * (1 + 1e-9)           # never through it
        # the clamped root does not move
        root = [at(p) for p in mesh.points[mesh.group("root")]]
        assert np.abs(meshio.read(files[3]).point_data["displacement"][root]).max() == 0.0


def test_time_series_opens_in_pyvista(demo_run):
    pv = pytest.importorskip("pyvista")
    a = demo_run.summary["files"]["animations"][0]
    reader = pv.get_reader(str(demo_run.directory / a["pvd"]))
    times, _ = read_time_series(demo_run.directory / a["pvd"])
    assert np.allclose(reader.time_values, times, rtol=1e-15, atol=0)
    reader.set_active_time_value(reader.time_values[2])
    data = reader.read()
    block = data[0] if isinstance(data, pv.MultiBlock) else data
    assert {"displacement", "velocity"} <= set(block.point_data.keys())
    ref = meshio.read(read_time_series(demo_run.directory / a["pvd"])[1][2]).point_data["displacement"]
    assert np.array_equal(np.asarray(block.point_data["displacement"]), ref)


def test_manifold_samples(demo_run):
    out = demo_run.directory
    for a in demo_run.summary["files"]["animations"]:
        m = meshio.read(out / a["manifold"])
        n = int(m.point_data["orbit"].max()) + 1  # orbits re-solved on the arc (<= 10 asked; a failed one is skipped)
        assert 8 <= n <= 10
        assert len(m.points) == n * 16 and m.cells_dict["quad"].shape == ((n - 1) * 16, 4)
        xc = m.point_data["contact_displacement"]
        d = demo_run.summary["contact"]["clearance_m"]
        assert xc.max() <= d * (1 + 1e-9) and xc.max() == pytest.approx(d, rel=1e-9)  # admissible, impacts at d
        assert np.allclose(m.points[:, 0], xc)
        T = m.point_data["period"]
        assert np.all(T >= 0.9 * demo_run.summary["search"]["period_unit_s"] * (1 - 1e-9))
        E = m.point_data["energy"].reshape(n, 16)
        assert np.allclose(E, E[:, :1], rtol=1e-12)  # one energy per orbit


def test_gif_frames(demo_run):
    out = demo_run.directory
    for a in demo_run.summary["files"]["animations"]:
        frames = iio.imread(out / a["gif"], index=None)
        assert frames.shape[0] == FRAMES
        assert frames.shape[1:3] == (WINDOW[1], WINDOW[0])
        f = frames.astype(float)
        assert all(fr.std() > 5.0 for fr in f)  # not blank
        diffs = [np.abs(f[i] - f[0]).max() for i in range(1, FRAMES)]
        assert max(diffs) > 50  # the blade moves
        # impact frame 0: the casing is drawn red (more strongly red pixels than a flight frame)
        red = [((fr[..., 0] > 180) & (fr[..., 1] < 140) & (fr[..., 2] < 140)).sum() for fr in f]
        flight = [i for i in range(FRAMES) if not np.any(np.isclose(
            i * a["T"] / FRAMES, np.mod(a["impact_times"], a["T"]), rtol=0, atol=a["T"] / FRAMES))]
        assert red[0] > 2 * max(red[i] for i in flight)


def test_frame_times_put_impacts_on_frames(two_dof):
    orbits = bc.orbits_kipp(two_dof, 13.5, 2)
    orbit = [o for o in orbits if o.admissible][0]
    t, impact = pipeline.frame_times(orbit, 20)
    assert t.size == 20 and np.all(np.diff(t) > 0) and t[0] == 0.0
    assert impact.sum() == 2 and impact[0]
    assert np.min(np.abs(t[impact][1:] - orbit.impact_times[0])) == 0.0


def test_verify_rejects_a_wrong_orbit(two_dof):
    orbit = bc.orbit_1ipp(two_dof, 5.0)
    assert pipeline.verify(orbit)["ok"]
    wrong = bc.make_orbit(two_dof, 5.0, orbit.impact_times, orbit.impulses * (1 + 1e-5))
    check = pipeline.verify(wrong)
    assert not check["ok"] and check["return_error"] > 1e-7


# ----------------------------------------------------------------------------- user mesh, stage commands

PLATE = PLATE_BASE.replace("size = 10\n", 'size = 10\ncompare = [{method = "lanczos-si", size = 10}]\n') + """\
[output]
frames = 10
window = [240, 180]
formats = ["gif", "vtu", "png"]
reference = false  # rendering tests; the reference check is tested in tests/test_reference.py
"""


@pytest.fixture(scope="module")
def plate_study(tmp_path_factory):
    d = tmp_path_factory.mktemp("plate")
    f = d / "plate.toml"
    f.write_text(absolute(PLATE))
    return f


@pytest.fixture(scope="module")
def plate_cli_run(plate_study, tmp_path_factory):
    """``(results folder, exit code, stdout)`` of ``bladecase run`` on the plate study, run once for the module:
    the tests about what a later run does to existing results start from a copy of this folder."""
    out = tmp_path_factory.mktemp("plate_cli") / "run"
    with contextlib.redirect_stdout(io.StringIO()) as stdout:
        code = main(["run", str(plate_study), "--out", str(out), "--quiet", "--no-progress"])
    return out, code, stdout.getvalue()


def _copy_of(results: Path, tmp_path: Path) -> Path:
    """A copy of a published results folder (the previous results a new run finds)."""
    out = tmp_path / "out"
    shutil.copytree(results, out)
    return out


def test_user_mesh_study_cli(plate_study, plate_cli_run, tmp_path):
    out, code, stdout = plate_cli_run
    assert code == 0
    assert stdout.strip() == str(out / "report.md")
    s = json.loads((out / "summary.json").read_text())
    assert s["model"]["dim"] == 2 and s["model"]["dofs"] == 1084
    assert s["model"]["mesh"]["source"].endswith("plate.vtu")
    assert len(s["compare"]) == 1 and s["compare"][0]["method"] == "lanczos-si"
    # modal (10 modes) vs FE: the lowest frequency to round-off
    assert s["reduction"]["relative_error_vs_fe"][0] < 1e-9
    anims = s["files"]["animations"]
    assert len(anims) == 2 and all("mp4" not in a for a in anims)  # mp4 not asked for
    for a in anims:
        assert a["verification"]["ok"]
        frames = iio.imread(out / a["gif"], index=None)
        assert frames.shape == (10, 180, 240, 3)

    # the same analysis through the stage commands
    st = tmp_path / "stages"
    st.mkdir()
    def run(*args):
        return main([*args, "--quiet", "--no-progress"])
    assert run("mesh", str(plate_study), "-o", str(st / "plate.inp")) == 0
    assert run("assemble", str(plate_study), "--mesh", str(st / "plate.inp"), "-o", str(st / "model.npz")) == 0
    assert run("reduce", str(plate_study), "--model", str(st / "model.npz"), "-o", str(st / "red.npz")) == 0
    assert run("modes", str(plate_study), "--reduced", str(st / "red.npz"), "-o", str(st / "modes.json"),
               "--plot", str(st / "fe.png")) == 0
    assert run("animate", str(plate_study), "--reduced", str(st / "red.npz"), "--modes", str(st / "modes.json"),
               "--out", str(st / "anim")) == 0
    modes = json.loads((st / "modes.json").read_text())
    ref = json.loads((out / "modes.json").read_text())
    assert len(modes["families"]) == len(ref["families"])
    for a, b in zip(modes["families"], ref["families"]):
        Ta = np.array([o["T"] for o in a["orbits"]])
        Tb = np.array([o["T"] for o in b["orbits"]])
        assert np.allclose(Ta, Tb, rtol=1e-12)
        assert [x["T_lo"] for x in a["arcs"]] == pytest.approx([x["T_lo"] for x in b["arcs"]], rel=1e-9)
    assert sorted(p.name for p in (st / "anim" / "animations").iterdir()) == \
        sorted(Path(a["gif"]).name for a in anims)


def test_stage_modes_from_user_matrices(plate_study, tmp_path):
    system = bc.chain(3, k=1.0, m=1 / 3, gap=1.0)
    np.savez(tmp_path / "sys.npz", M=system.M.toarray(), K=system.K.toarray(), w=system.w, gap=1.0)
    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "chain3"\n[search]\nipp = [1]\nperiods = [0.5, 0.9999]\n')  # search only
    code = main(["modes", str(study), "--matrices", str(tmp_path / "sys.npz"), "-o", str(tmp_path / "m.json"),
                 "--quiet", "--no-progress"])
    assert code == 0
    data = json.loads((tmp_path / "m.json").read_text())
    assert data["system_dofs"] == 3 and data["families"][0]["ipp"] == 1


def test_failed_run_keeps_previous_results(plate_study, plate_cli_run, tmp_path, monkeypatch):
    # the failing run: the plate study without its figures (png), which it would draw before it renders
    text = plate_study.read_text()
    assert 'formats = ["gif", "vtu", "png"]' in text
    st = loads(text.replace('formats = ["gif", "vtu", "png"]', 'formats = ["gif", "vtu"]'), base=plate_study.parent)
    out = _copy_of(plate_cli_run[0], tmp_path)  # the previous results: the plate study, run once for the module
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    from bladecase.post import animation as viz

    def broken(*args, **kwargs):
        raise RuntimeError("renderer crashed")

    monkeypatch.setattr(viz, "animate", broken)
    with pytest.raises(RuntimeError, match="renderer crashed"):
        pipeline.run(st, out=out, progress=False)
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before


def test_model_and_reduced_files_round_trip(tmp_path):
    mesh = bc.load_mesh(ROOT / "meshes" / "plate.msh")
    model = bc.assemble(mesh, "Ti-6Al-4V", order=2, thickness=0.002)
    save_model(model, tmp_path / "m.npz")
    back = load_model(tmp_path / "m.npz")
    assert (abs(back.K - model.K)).max() == 0 and (abs(back.M - model.M)).max() == 0
    assert back.total_mass == model.total_mass and np.array_equal(back.dofs.fe_index, model.dofs.fe_index)
    contact = bc.Contact(int(mesh.group("contact")[0]), None, 1e-4)
    for method, size in (("lanczos-si", 8), ("craig-bampton", 5)):
        r = reduce(model, contact, method, size)
        save_reduced(r, tmp_path / "r.npz")
        r2 = load_reduced(tmp_path / "r.npz")
        o = bc.orbit_1ipp(r.system, 0.97 * r.system.spectrum.periods[0])
        o2 = bc.orbit_1ipp(r2.system, o.T)
        assert o2.energy == o.energy
        t = np.linspace(0, o.T, 5)
        assert np.array_equal(r.expand(o, t)[0], r2.expand(o2, t)[0])
    with pytest.raises(ValueError, match="not a bladecase reduced-model file"):
        load_reduced(tmp_path / "m.npz")
    with pytest.raises(ValueError, match="not a bladecase FE model file"):
        load_model(tmp_path / "r.npz")


def test_rerun_replaces_results_and_drops_stale_ones(plate_study, plate_cli_run, tmp_path):
    st = loads(plate_study.read_text(), base=plate_study.parent)
    out = _copy_of(plate_cli_run[0], tmp_path)  # the first run's results (every format, the comparison figures)
    (out / "notes.txt").write_text("mine")  # a user's file: never touched
    raw = copy.deepcopy(st.config)
    # 2 frames of 64×64: the test is about which results the rerun leaves, not about the frames
    raw["output"].update(formats=["gif"], frames=2, window=[64, 64])
    raw = as_raw(raw)
    raw["mesh"]["path"] = str(st.mesh_path())
    pipeline.run(validate(raw), out=out, progress=False)
    names = sorted(p.name for p in out.iterdir())
    # no png in formats: the comparison keeps its table only (comparison.csv), no figures
    assert names == [".bladecase-manifest.json", "animations", "comparison.csv", "mesh.vtu", "modes.json", "notes.txt",
                     "report.md", "run.log", "summary.json"]
    assert (out / "notes.txt").read_text() == "mine"


def test_explicit_orbit_requests(plate_study):
    st = loads(plate_study.read_text(), base=plate_study.parent)
    mesh = pipeline.build_mesh(st)
    model = pipeline.build_model(st, mesh)
    reduced = pipeline.build_reduced(st, model, pipeline.build_contact(st, model))
    fams = pipeline.search(st, reduced.system)
    unit, _ = pipeline.period_unit(st, reduced.system)
    arc = max((a for f in fams for a in f.arcs), key=lambda a: a.T_hi - a.T_lo)
    inside = 0.5 * (arc.T_lo + arc.T_hi) / unit
    raw = copy.deepcopy(st.config)
    raw["output"]["orbits"] = [{"ipp": 1, "T": inside}, {"ipp": 1, "T": 0.6}]
    raw = as_raw(raw)
    chosen = pipeline.choose_orbits(validate(raw, base=plate_study.parent), fams, unit)
    assert len(chosen) == 2
    assert chosen[0].orbit.T == pytest.approx(inside * unit, rel=1e-14) and chosen[0].orbit.admissible
    # T = 0.6 T1 is not admissible: the nearest admissible stored orbit is taken
    adm = [o.T for f in fams for o in f.orbits if o.admissible]
    assert chosen[1].orbit.T == min(adm, key=lambda T: abs(T - 0.6 * unit))


def test_search_resolution_reaches_the_start_search(plate_study, monkeypatch):
    from bladecase.nsm import modes as continuation

    seen = []
    real = continuation.orbits_kipp

    def spy(system, T, k, resolution=None, **kw):
        seen.append(resolution)
        return real(system, T, k, resolution=resolution, **kw)

    monkeypatch.setattr(continuation, "orbits_kipp", spy)
    raw = copy.deepcopy(loads(PLATE, base=ROOT).config)
    raw["search"].update(ipp=[3], scan=2, resolution=20, periods=[0.9, 0.95])
    raw = as_raw(raw)
    st = validate(raw, base=ROOT)
    system = bc.chain(3, k=1.0, m=1 / 3, gap=1.0)
    pipeline.search(st, system)
    assert seen == [20, 20]


NO_SIDE_EFFECTS = """
import logging, sys, warnings
import matplotlib
warnings.simplefilter("error")   # e.g. tqdm's ipywidgets warning would fail the run
backend = dict.__getitem__(matplotlib.rcParams, "backend")
root, lib = logging.getLogger(), logging.getLogger("bladecase")
before = (list(root.handlers), list(lib.handlers), root.level, lib.level, lib.propagate)
from bladecase.study.schema import load_study
from bladecase.study import run
result = run(load_study(sys.argv[1]), out=sys.argv[2], progress=False)
after = (list(root.handlers), list(lib.handlers), root.level, lib.level, lib.propagate)
figures = sys.modules["matplotlib.pyplot"].get_fignums() if "matplotlib.pyplot" in sys.modules else []
print(after == before, dict.__getitem__(matplotlib.rcParams, "backend") == backend,
      len(figures), (result.directory / "run.log").read_text().count(" INFO "))
"""


def test_run_changes_no_global_state(plate_study, tmp_path):
    """No backend switch, no figure left in pyplot's registry (pyvista imports pyplot, the library never
    uses it), no logging handler or level change, nothing on stderr with progress=False; run.log is
    written from the run's own transcript all the same."""
    import subprocess
    import sys

    # the plate study with 2 frames of 64×64 (every stage and format runs; the frames are not what is checked)
    study = tmp_path / "plate.toml"
    study.write_text(plate_study.read_text().replace("frames = 10", "frames = 2").replace("window = [240, 180]",
                                                                                           "window = [64, 64]"))
    assert "frames = 2" in study.read_text() and "window = [64, 64]" in study.read_text()
    proc = subprocess.run([sys.executable, "-c", NO_SIDE_EFFECTS, str(study), str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    handlers_kept, backend_kept, figures, infos = proc.stdout.split()
    assert (handlers_kept, backend_kept, figures) == ("True", "True", "0")
    assert int(infos) >= 8  # study, mesh, model, contact, reduced model, search, animations, results
    assert proc.stderr == ""


def test_library_code_never_uses_pyplot_or_switches_backend():
    import ast

    offenders = []
    for path in sorted((Path(bc.__file__).parent).rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        if "matplotlib" not in text:  # no pyplot import, no matplotlib.use without the word: nothing to parse
            continue
        for node in ast.walk(ast.parse(text)):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [f"{node.module}.{a.name}" for a in node.names] if isinstance(node, ast.ImportFrom) else [])
            if any(n.startswith("matplotlib.pyplot") for n in names):
                offenders.append(f"{path.name}:{node.lineno} imports pyplot")
            if isinstance(node, ast.Attribute) and node.attr == "use" and getattr(node.value, "id", "") == "matplotlib":
                offenders.append(f"{path.name}:{node.lineno} calls matplotlib.use")
    assert offenders == []
