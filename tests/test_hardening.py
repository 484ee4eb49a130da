"""Issue 15 in the library: no silent wrong answer (strict JSON, extreme scales, mixed meshes, unclamped
models, complex matrices), no study that cannot run, and a results folder that stays the user's (lock,
stale staging, ownership, publishing that Ctrl-C cannot cut)."""

from __future__ import annotations

import copy
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest
from _studies import PLATE, ROOT, absolute, as_raw
from skfem import MeshTet, MeshTri

import bladecase as bc
from bladecase.fe import Material, Mesh, assemble
from bladecase.fe.mesh import from_meshio
from bladecase.io import strict_json, write_json
from bladecase.reduction import Contact, reduce
from bladecase.study import publish as pub
from bladecase.study.documents import families_document, family_summary, load_families
from bladecase.study.schema import StudyError, loads, validate


def _strict_load(path: Path):
    """``json.loads`` that refuses NaN/Infinity, as strict parsers (JavaScript, Go, jq) do."""
    def refuse(token):
        raise AssertionError(f"{path}: non-standard JSON constant {token}")
    return json.loads(Path(path).read_text(), parse_constant=refuse)


def _strip(clamp="root", nx=11) -> Mesh:
    t = MeshTri.init_tensor(np.linspace(0, 0.1, nx), np.linspace(0, 0.02, 3)).oriented()
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    return Mesh(points, {"triangle": t.t.T}, dim=2, source="strip",
                groups={"root": np.flatnonzero(points[:, 0] == 0), "all": np.arange(len(points))})


# ----------------------------------------------------------------------------- strict JSON

def test_write_json_is_strict_and_says_what_it_encoded(tmp_path, caplog):
    data = {"energy": [1.0, float("nan")], "ok": np.bool_(True), "n": np.int64(3),
            "range": np.array([float("-inf"), 2.0])}
    with caplog.at_level("WARNING", logger="bladecase"):
        write_json(tmp_path / "a.json", data)
    assert _strict_load(tmp_path / "a.json") == {"energy": [1.0, None], "ok": True, "n": 3, "range": [None, 2.0]}
    assert "2 non-finite number(s) written as null (energy[1], range[0])" in caplog.text
    assert strict_json({"x": 1e308 * 10})[1] == ["x"]


def test_full_disk_is_an_oserror_and_a_valueerror(tmp_path, monkeypatch):
    import errno

    import bladecase.io as bio

    def full(src, dst):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(bio.os, "replace", full)
    with pytest.raises(bio.WriteError) as info:
        bio.write_text(tmp_path / "a.txt", "x")
    assert isinstance(info.value, ValueError) and isinstance(info.value, OSError)
    assert info.value.errno == errno.ENOSPC
    assert str(info.value) == f"cannot write {str(tmp_path / 'a.txt')!r}: no space left on device (free some space " \
                              "or choose another place)"
    assert list(tmp_path.iterdir()) == []  # the temporary file is gone


def test_empty_family_summary_has_no_nan(two_dof):
    empty = bc.Branch(two_dof, 2, [], [], None, "curve")
    summary = family_summary(empty)
    assert summary["period_range_s"] == [None, None] and summary["energy_range_j"] == [None, None]
    assert json.dumps(summary, allow_nan=False)


def test_nan_in_an_orbit_survives_a_strict_modes_file(tmp_path, two_dof):
    branch = bc.backbone(two_dof, np.linspace(4.0, 6.0, 5))
    doc = families_document([branch], two_dof)
    doc["families"][0]["orbits"][0]["max_violation_time"] = float("nan")
    write_json(tmp_path / "m.json", doc)
    raw = _strict_load(tmp_path / "m.json")
    assert raw["families"][0]["orbits"][0]["max_violation_time"] is None
    back = load_families(tmp_path / "m.json", two_dof)[0]
    assert math.isnan(back.orbits[0].max_violation_time)
    assert back.orbits[1].T == branch.orbits[1].T and back.orbits[0].energy == branch.orbits[0].energy


# ----------------------------------------------------------------------------- study values

def _study(**edits):
    raw = copy.deepcopy(loads(absolute(PLATE)).config)
    for key, value in edits.items():
        section, name = key.split("__")
        raw[section][name] = value
    return validate(as_raw(raw))


@pytest.mark.parametrize("key, value, words", [
    ("contact__clearance", 1e300, "[contact] clearance: must be in [1e-09, 10] (m), got 1e+300"),
    ("contact__clearance", 1e-300, "[contact] clearance: must be in [1e-09, 10] (m)"),
    ("material__E", 1e-250, "[material] E: must be in [1000, 1e+13] (Pa), got 1e-250"),
    ("material__rho", 1e-300, "[material] rho: must be in [0.01, 100000] (kg/m³)"),
    ("output__frames", 100_000_000, "[output] frames: must be an integer with 2 <= value <= 1000, got 100000000"),
    ("search__scan", 1_000_000_000, "[search] scan: must be an integer with 2 <= value <= 2000"),
    ("search__resolution", 100_000, "[search] resolution: must be an integer with 4 <= value <= 1000"),
    ("output__manifold_size", [100_000, 100_000], "[output] manifold_size: must be [orbits, phases], integers between"),
    ("output__manifold_size", [1000, 1000], "must sample at most 100000 points (orbits × phases), asks for 1000000"),
    ("search__periods", [1e6, 1e7], "[search] periods: the upper period must be <= 100 × T1"),
    ("search__step", 1e300, "[search] step: must be in [1e-06, 1]"),
    ("search__step", 1e-300, "[search] step: must be in [1e-06, 1]"),
    ("search__step", -0.01, "[search] step: must be in [1e-06, 1]"),
    ("search__max_points", 1, "[search] max_points: must be an integer with 2 <= value <= 100000"),
    ("output__fps", 1e300, "[output] fps: must be a number in (0, 1000]"),
    ("fem__frequencies", 10**9, "[fem] frequencies: must be an integer with 1 <= value <= 100"),
    ("contact__normal", [0, 0], "[contact] normal: must be a non-zero direction"),
])
def test_study_refuses_values_that_cannot_run(key, value, words):
    with pytest.raises(StudyError) as info:
        _study(**{key: value})
    assert words in str(info.value)


def test_k_ipp_start_grid_is_bounded():
    with pytest.raises(StudyError, match=r"resolution: 100 points per impact time make 3.76e\+06 start cells for "
                                         r"ipp = 5 .*resolution <= 72 for ipp = 5, got 100"):
        _study(search__ipp=[1, 5], search__resolution=100)
    assert math.comb(71, 4) <= 1_000_000 < math.comb(72, 4)
    assert _study(search__ipp=[5], search__resolution=72)["search"]["resolution"] == 72
    assert _study(search__ipp=[2], search__resolution=1000)["search"]["resolution"] == 1000  # unused for k <= 2
    assert _study(search__periods=[0.5, 100.0])["search"]["periods"] == [0.5, 100.0]
    assert _study(search__periods=[1e6, 1e7], search__period_unit="s")["search"]["period_unit"] == "s"


def test_huge_casing_normal_is_a_direction():
    study = _study(contact__normal=[1e300, 1e300], contact__farthest=None)
    assert study["contact"]["normal"] == [1.0, 1.0]
    assert _study(contact__normal=[0.0, -1e-300])["contact"]["normal"] == [0.0, -1.0]


# ----------------------------------------------------------------------------- extreme scales in the API

def test_material_scales_double_precision_cannot_carry():
    with pytest.raises(ValueError, match=r"Young's modulus E = 1e-250 is out of the range .* \[1e-60, 1e\+60\]"):
        Material(1e-250, 0.3, 7850.0)
    with pytest.raises(ValueError, match=r"density rho = 1e\+200 is out of the range"):
        Material(200e9, 0.3, 1e200)
    # inside the range the frequencies scale exactly as sqrt(E): no 10x error
    strip = _strip()
    f0 = bc.natural_frequencies(assemble(strip, Material(200e9, 0.3, 7850.0), order=1, thickness=0.002), 3)
    f1 = bc.natural_frequencies(assemble(strip, Material(200e9 * 1e-50, 0.3, 7850.0), order=1, thickness=0.002), 3)
    np.testing.assert_allclose(f1 / 1e-25, f0, rtol=1e-8)


@pytest.mark.parametrize("make, words", [
    (lambda: bc.chain(2, gap=1e300), r"gap = 1e\+300 is out of the range double precision handles here: "
                                     r"\[1e-80, 1e\+80\]"),
    (lambda: bc.chain(2, gap=1e-300), r"gap = 1e-300 is out of the range"),
    (lambda: bc.chain(2, k=1e-300, gap=1.0), r"max\|K\| = 2e-300 is out of the range"),
    (lambda: bc.LinearSystem(np.eye(2), np.eye(2) * (2 + 1e-9j), 0, 1.0),
     "K must be real: 2 entries have a non-zero imaginary part"),
    (lambda: bc.LinearSystem(np.eye(2) * (1 + 0.5j), np.eye(2), 0, 1.0), "M must be real"),
    (lambda: bc.LinearSystem(np.eye(2), np.eye(2), [1.0, 1j], 1.0), "w must be real"),
    (lambda: bc.LinearSystem(np.eye(3), np.eye(3), np.array(1.7), 1.0),
     r"w must be an integer contact dof \(0..2\) or a vector of 3 numbers, got the single number"),
    (lambda: bc.LinearSystem(np.eye(3), np.eye(3), 1.0, 1.0), "got the single number 1.0"),
    (lambda: bc.LinearSystem(np.eye(2), np.eye(2), -3, 1.0), r"out of range .* \(valid: 0..1\)"),
    (lambda: bc.LinearSystem(np.eye(2), np.eye(2), -1, 1.0), r"w = -1 is out of range .* \(valid: 0..1\)"),
])
def test_linear_system_refuses_what_it_would_get_wrong(make, words):
    with pytest.raises(ValueError, match=words):
        make()


def test_complex_matrices_without_imaginary_part_are_real():
    import scipy.sparse as sp

    s = bc.LinearSystem(np.eye(2) + 0j, sp.csr_array(np.array([[2.0, -1], [-1, 1]]) + 0j), 1, 1.0)
    assert s.K.dtype == float and s.spectrum.omega[0] == pytest.approx(math.sqrt((3 - math.sqrt(5)) / 2), rel=1e-12)


# ----------------------------------------------------------------------------- meshes and models

def test_stray_tetrahedron_beside_a_planar_mesh_is_refused_with_counts():
    t = MeshTri.init_tensor(np.linspace(0, 1, 23), np.linspace(0, 1, 12))  # 2 × 22 × 11 = 484 triangles
    points = np.r_[np.c_[t.p.T, np.zeros(t.p.shape[1])], [[2, 0, 0], [3, 0, 0], [2, 1, 0], [2, 0, 1]]]
    n = t.p.shape[1]
    m = meshio.Mesh(points, [("triangle", t.t.T), ("tetra", np.array([[n, n + 1, n + 2, n + 3]]))])
    with pytest.raises(ValueError, match=rf"mixes dimensions: 1 tetra cell\(s\) form the 3-D body, and 484 triangle "
                                         rf"cell\(s\) \({n} node\(s\) no tetra uses\) lie off it"):
        from_meshio(m, source="stray.vtu")


def test_boundary_faces_of_a_solid_are_not_stray():
    tet = MeshTet.init_tensor(*[np.linspace(0, 1, 4)] * 3)
    cells = tet.t.T.copy()
    p = tet.p.T
    volume = np.einsum("ij,ij->i", np.cross(p[cells[:, 1]] - p[cells[:, 0]], p[cells[:, 2]] - p[cells[:, 0]]),
                       p[cells[:, 3]] - p[cells[:, 0]])
    cells[volume < 0, :2] = cells[volume < 0, 1::-1]  # positively oriented
    faces = tet.facets[:, tet.boundary_facets()].T
    m = meshio.Mesh(p, [("tetra", cells), ("triangle", faces)])
    mesh = from_meshio(m, source="cube")
    assert mesh.body_type == "tetra" and len(mesh.cells["triangle"]) == len(faces) == 6 * 9 * 2


def test_clamping_every_node_is_named():
    with pytest.raises(ValueError, match=r"the clamp fixes 33 of the mesh's 33 nodes: no degree of freedom is left "
                                         r"free; clamp a face"):
        assemble(_strip(), "steel", order=1, thickness=0.002, clamp="all")


@pytest.mark.parametrize("method", ["lanczos", "lanczos-si", "modal", "craig-bampton", "full"])
def test_every_reduction_refuses_an_unclamped_model(method):
    model = assemble(_strip(), "steel", order=1, thickness=0.002, clamp=None)
    contact = Contact.nearest(model, (0.1, 0.02), normal=(1.0, 0.0), gap=1e-4)
    with pytest.raises(ValueError, match=rf"the model is not clamped: 3 rigid-body motion\(s\) are free.*{method!r}"):
        reduce(model, contact, method, None if method == "full" else 4)


# ----------------------------------------------------------------------------- the output folder is the user's

@pytest.fixture()
def plate(tmp_path):
    return loads(absolute(PLATE).replace("size = 10", "size = 4") + '[output]\nformats = []\nreference = false\n'
                 'frames = 4\n', base=ROOT)


@pytest.mark.parametrize("name, kind", [("vtk", "dir"), ("animations", "dir"), ("report.md", "file")])
def test_run_never_replaces_what_bladecase_did_not_write(tmp_path, plate, monkeypatch, name, kind):
    import importlib

    run_module = importlib.import_module("bladecase.study.run")
    monkeypatch.setattr(run_module, "_compute", lambda *a: pytest.fail("computed before checking the folder"))
    out = tmp_path / "out"
    out.mkdir()
    if kind == "dir":
        (out / name).mkdir()
        (out / name / "blade.vtu" if name == "vtk" else out / name / "talk.pdf").write_text("mine")
    else:
        (out / name).write_text("my notes")
    before = sorted(str(p.relative_to(out)) for p in out.rglob("*"))
    with pytest.raises(ValueError, match=rf"already holds '{name}', not written by a bladecase run"):
        bc.study.run(plate, out=out, progress=False)
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*")) == before


def test_study_mesh_inside_a_result_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    (out / "vtk").mkdir(parents=True)
    (out / "vtk" / "blade.vtu").write_bytes((ROOT / "meshes" / "plate.vtu").read_bytes())
    study = loads(PLATE.replace("meshes/plate.vtu", "vtk/blade.vtu"), base=out)
    with pytest.raises(ValueError, match=r"input '.*vtk/blade.vtu' lies in '.*vtk', which this run replaces"):
        bc.study.run(study, out=out, progress=False)
    assert (out / "vtk" / "blade.vtu").stat().st_size > 0


def test_run_results_are_strict_json_and_leave_no_lock_or_staging(tmp_path, plate):
    out = tmp_path / "out"
    out.mkdir()
    killed = pub.staging_dir(out)  # a staging folder of a killed run (signed token inside)
    (killed / "modes.json").write_text("half")
    pub.release(out)
    (out / ".bladecase-run-mine").mkdir()  # the user's folders that only look like bladecase's
    (out / ".vtk.old-2024").mkdir()
    bc.study.run(plate, out=out, progress=False)
    names = sorted(p.name for p in out.iterdir())
    assert names == [".bladecase-manifest.json", ".bladecase-run-mine", ".vtk.old-2024", "mesh.vtu", "modes.json",
                     "report.md", "run.log", "summary.json"]
    for name in ("modes.json", "summary.json"):
        _strict_load(out / name)
    # a re-run into its own results is allowed (the signed manifest lists them, unchanged)
    bc.study.run(plate, out=out, progress=False)
    assert sorted(p.name for p in out.iterdir()) == names


def test_second_run_into_a_locked_folder_is_refused_with_the_holders_pid(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", "import fcntl, os, sys, time\n"
         f"fd = os.open({str(out / pub.LOCK)!r}, os.O_RDWR | os.O_CREAT)\n"
         "fcntl.flock(fd, fcntl.LOCK_EX); os.write(fd, str(os.getpid()).encode())\n"
         "print('locked', flush=True); time.sleep(30)"], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(pub.OutputInUse, match=rf"in use by another bladecase run \(pid {holder.pid}\)"):
            pub.staging_dir(out)
    finally:
        holder.kill()
        holder.wait()
    staging = pub.staging_dir(out)  # the kernel released the killed holder's lock
    with pytest.raises(pub.OutputInUse, match=rf"in use by another run of this process \(pid {os.getpid()}\)"):
        pub.staging_dir(out)
    (staging / "report.md").write_text("new")
    pub.publish(staging, out)
    assert sorted(p.name for p in out.iterdir()) == [pub.MANIFEST, "report.md"]


def test_failed_run_frees_the_folder_for_the_next(tmp_path):
    out = tmp_path / "out"
    staging = pub.staging_dir(out)
    shutil.rmtree(staging)  # the run failed and removed its staging (without release)
    again = pub.staging_dir(out)
    pub.release(out)
    shutil.rmtree(again)
    assert list(out.iterdir()) == []


def test_publication_killed_half_way_is_finished_by_the_next_run(tmp_path, caplog, monkeypatch):
    out = tmp_path / "out"
    staging = pub.staging_dir(out)
    for name in ("modes.json", "summary.json"):
        (staging / name).write_text(f"{name} of the killed run")
    real = os.replace

    def killed(src, dst):  # the process dies after its first move (SIGKILL: no clean-up runs)
        real(src, dst)
        raise SystemExit("killed")

    monkeypatch.setattr(pub.os, "replace", killed)
    with pytest.raises(SystemExit):
        pub.publish(staging, out, pub.RUN_RESULTS)
    monkeypatch.setattr(pub.os, "replace", real)
    assert (out / pub.MARKER).exists() and staging.exists()
    with caplog.at_level("WARNING", logger="bladecase"):
        again = pub.staging_dir(out)
    assert "killed while publishing" in caplog.text
    assert (out / "summary.json").read_text() == "summary.json of the killed run"  # finished, whole
    (again / "modes.json").write_text("new")
    pub.publish(again, out, pub.RUN_RESULTS)
    assert sorted(p.name for p in out.iterdir()) == [pub.MANIFEST, "modes.json"]
    assert (out / "modes.json").read_text() == "new"


def test_ctrl_c_waits_until_every_entry_is_published(tmp_path, monkeypatch):
    out = tmp_path / "out"
    staging = pub.staging_dir(out)
    for name in ("modes.json", "report.md", "summary.json"):
        (staging / name).write_text(name)
    real = os.replace
    calls = []

    def replace(src, dst):
        calls.append(Path(dst).name)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C after the first entry
            time.sleep(0.01)
        real(src, dst)

    monkeypatch.setattr(pub.os, "replace", replace)
    with pytest.raises(KeyboardInterrupt):
        pub.publish(staging, out, pub.RUN_RESULTS)
    assert calls[-2:] == ["summary.json", pub.MANIFEST]  # summary.json last, then the signed manifest
    assert [c for c in calls if not c.startswith(".")] == ["modes.json", "report.md", "summary.json"]
    assert sorted(p.name for p in out.iterdir()) == [pub.MANIFEST, "modes.json", "report.md", "summary.json"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


# ----------------------------------------------------------------------------- random input (seeded fuzzing)

_ODD_VALUES = [0, -1, 1, 2, 10**9, -(10**18), 1e300, -1e-300, 1e-300, float("nan"), float("inf"), True, "", "x",
               "T1", [], [0], [1, 2], [1e300, 1e300], [0.5, 0.9999], ["a", "b"], [[1]], {}, {"ipp": 1, "T": 0.9},
               [{"method": "modal", "size": 0}], [100_000, 100_000], [128, 96]]


def _odd(rng):
    return copy.deepcopy(_ODD_VALUES[rng.integers(len(_ODD_VALUES))])


def test_random_study_edits_give_a_study_or_one_line_naming_the_key():
    """A seeded random search over the schema's keys and fixed odd values (hypothesis generates more:
    tests/test_properties.py)."""
    from bladecase.study.schema import SCHEMA

    rng = np.random.default_rng(15)
    base = as_raw(loads(absolute(PLATE)).config)
    keys = [(s, k) for s, ks in SCHEMA.items() if s not in ("geometry", "mesh") for k in ks]
    outcomes = {"study": 0, "error": 0}
    for _ in range(600):
        raw = copy.deepcopy(base)
        for _ in range(rng.integers(1, 3)):
            section, key = keys[rng.integers(len(keys))]
            raw.setdefault(section, {})[key] = _odd(rng)
        try:
            study = validate(raw)
        except StudyError as exc:
            text = str(exc)
            assert "\n" not in text and re.match(r"\[\w+\]", text), text
            outcomes["error"] += 1
            continue
        outcomes["study"] += 1
        for section, keys_ in study.config.items():  # what passed is finite and inside the caps
            for key, value in keys_.items():
                flat = value if isinstance(value, list) else [value]
                assert not any(isinstance(x, float) and not math.isfinite(x) for x in flat), (section, key, value)
        s, o = study["search"], study["output"]
        assert s["scan"] <= 2000 and o["frames"] <= 1000 and o["manifold_size"][0] * o["manifold_size"][1] <= 1e5
    assert outcomes["study"] >= 5 and outcomes["error"] >= 300, outcomes  # both outcomes exercised


def test_random_arrays_give_a_system_or_one_line():
    rng = np.random.default_rng(1515)
    kinds = [lambda n: np.eye(n), lambda n: np.eye(n) * 1e-300, lambda n: np.eye(n) * (1 + 1j),
             lambda n: np.full((n, n), np.nan), lambda n: -np.eye(n), lambda n: np.ones((n, n + 1)),
             lambda n: np.array([["a"] * n] * n), lambda n: 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1),
             lambda n: np.zeros((0, 0)), lambda n: np.eye(n, dtype=bool), lambda n: rng.standard_normal((n, n))]
    ws = [0, -1, 7, 1.7, np.array(1.7), [1.0], "w", None, [np.nan], lambda n: np.ones(n), lambda n: np.zeros(n)]
    gaps = [1.0, 0.0, -1.0, 1e300, float("nan"), "1", None, [1.0, 2.0]]
    built = 0
    for _ in range(400):
        n = int(rng.integers(1, 5))
        M, K = kinds[rng.integers(len(kinds))](n), kinds[rng.integers(len(kinds))](n)
        w = ws[rng.integers(len(ws))]
        w = w(n) if callable(w) else w
        gap = gaps[rng.integers(len(gaps))]
        try:
            s = bc.LinearSystem(M, K, w, gap)
        except ValueError as exc:
            assert "\n" not in str(exc).strip(), str(exc)
            continue
        built += 1
        assert np.all(np.isfinite(s.spectrum.omega)) and s.spectrum.omega.min() > 0
        assert 1e-80 <= s.gap <= 1e80
    assert built >= 2  # valid systems among the random ones (seeded)


def test_an_eigen_solution_out_of_proportion_is_refused_or_announced(caplog):
    """`modal size = 2000` on a 7k-dof blade ran for minutes in silence: the study estimates the ARPACK work
    (n·k² at the measured rate) and warns with the estimate, or refuses with the largest valid size."""
    from bladecase.study.schema import StudyError
    from bladecase.study.stages import _check_eigen_work

    with caplog.at_level("WARNING", logger="bladecase"):
        _check_eigen_work("modal", 2000, 7000)  # ~336 s: runs, with the estimate in words
    assert re.search(r"modal 2000 on 7000 dofs: 2000 eigenmodes, estimated 3\d\d s", caplog.text)
    with pytest.raises(StudyError, match=r"\[reduction\] size: craig-bampton 20000 on 50000 dofs needs 20000 "
                                         r"eigenmodes, estimated 6\d\.\d h; valid: at most 2449 for this model"):
        _check_eigen_work("craig-bampton", 20000, 50000)
    caplog.clear()
    with caplog.at_level("WARNING", logger="bladecase"):
        _check_eigen_work("modal", 2000, 2500)  # dense below DENSE_LIMIT: seconds whatever the size
        _check_eigen_work("modal", 50, 100_000)  # 3 s
    assert caplog.text == ""


def test_simulate_bounds_the_memory_of_its_stored_impacts():
    """Each impact keeps its state (4 n floats); the default cap keeps them within 1 GB and says so."""
    from bladecase.nsm.newton.simulation import STATE_MEMORY_BYTES, default_max_impacts

    assert default_max_impacts(200) * 32 * 200 <= STATE_MEMORY_BYTES < (default_max_impacts(200) + 1) * 32 * 200
    assert default_max_impacts(1) == 1_000_000
    s = bc.chain(2, k=1.0, m=0.5, gap=1.0)
    o = bc.orbit_1ipp(s, 6.0)
    x0, v0 = (z[:, 0] for z in o.state(0.0))
    with pytest.warns(RuntimeWarning, match=r"max_impacts = 3 reached"):
        tr = bc.simulate(s, x0, v0, 100.0, max_impacts=3)
    assert tr.impact_times.size == 3 and not tr.complete and tr.t_end == pytest.approx(18.0, rel=1e-9)


def test_a_k_ipp_start_search_out_of_proportion_is_announced_or_refused(caplog):
    """`ipp = [4]` with `scan = 2` on the plate ran 4 minutes in silence (2 × 16 215 start cells): the study now
    announces the estimate first, and refuses a grid estimated at more than 6 hours."""
    from bladecase.study.schema import StudyError
    from bladecase.study.stages import _check_start_grid

    system = bc.chain(10, k=1.0, m=0.1, gap=1.0)
    T = 0.9999 * 2 * np.pi / system.spectrum.omega[0]
    with caplog.at_level("WARNING", logger="bladecase"):
        _check_start_grid(system, 4, T, 2, None, "modal 10")
        _check_start_grid(system, 3, T, 2, 16, "")  # 2 × 105 cells: seconds, nothing said
    assert re.search(r"modal 10: 4-ipp start search: 2 periods × 16215 cells \(resolution 48\) on 10 dofs, "
                     r"estimated 3\.5 min", caplog.text)
    assert caplog.text.count("start search") == 1
    with pytest.raises(StudyError, match=r"\[search\] ipp: 5-ipp start search: 200 periods × 178365 cells .* "
                                         r"valid: a smaller \[search\] resolution or scan"):
        _check_start_grid(system, 5, T, 200, 48)
