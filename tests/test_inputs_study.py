"""Study files as input: every bad value refused at load time with ``[section] key``, the value and what is valid;
files that are not studies (pipes, devices, binary, huge, nested without end) refused before they are read; work
out of proportion refused up front with the estimate and the ``[limits]`` key that raises the cap."""

from __future__ import annotations

import copy
import math
import os
import threading
from pathlib import Path

import pytest
from _studies import PLATE, ROOT, absolute, as_raw

from bladecase.cli import main
from bladecase.study.schema import GEOMETRY_FIELDS, SCHEMA, Study, StudyError, load_study, loads, validate

#: A parametric plate study (meshed by gmsh in well under a second).
GEOMETRY = """
[study]
name = "plate"
[geometry]
kind = "plate"
span = 0.1
chord = 0.02
contact_point = [0.0, 0.1]
size = 0.005
[fem]
order = 1
thickness = 0.002
[contact]
clearance = 1e-4
"""

#: A parametric blade study (not meshed here: only validated).
BLADE = """
[geometry]
kind = "blade"
span = 0.15
root_chord = 0.05
naca = "2412"
contact_point = [0.0, 0.0, 0.15]
[contact]
clearance = 1e-4
"""


def _refused(text: str, *words: str, base=ROOT) -> str:
    with pytest.raises(StudyError) as info:
        loads(text, base=base)
    message = str(info.value)
    assert "\n" not in message, message
    for w in words:
        assert w in message, message
    return message


def _raw(text: str = PLATE) -> dict:
    return as_raw(copy.deepcopy(loads(absolute(text)).config))


def _edit(raw: dict, section: str, key: str, value) -> dict:
    raw = copy.deepcopy(raw)
    raw.setdefault(section, {})[key] = value
    return raw


# ----------------------------------------------------------------------------- case 1: names and folders

@pytest.mark.parametrize("name", ["..", ".", "...", ".hidden", "../up", "a/b", "", "x" * 65, "na me"])
def test_study_name_is_a_plain_folder_name(name):
    message = _refused(f'[study]\nname = "{name}"\n' + PLATE.replace('[study]\nname = "plate"\n', ""),
                       "[study] name: must be a plain folder name", "not starting with '.'")
    assert f"got {name!r}" in message


@pytest.mark.parametrize("name", ["a", "plate.v2", "run_1-b", "A" * 64, "0.5mm"])
def test_study_name_valid_folder_names(name):
    assert loads(PLATE.replace('name = "plate"', f'name = "{name}"'), base=ROOT).name == name


def test_study_name_refused_through_the_python_api():
    raw = _raw()
    raw["study"]["name"] = ".."
    with pytest.raises(StudyError, match=r"\[study\] name: must be a plain folder name"):
        validate(raw)
    # a Study made by hand, without validate(), cannot send results outside results/ either
    study = Study({"study": {"name": ".."}, "output": {"directory": None}})
    with pytest.raises(StudyError, match=r"\[study\] name: must be a plain folder name.*got the string '\.\.'"):
        study.output_dir()


def test_cli_run_with_name_dotdot_writes_nothing(tmp_path, capsys, monkeypatch):
    work = tmp_path / "work"
    work.mkdir()
    study = tmp_path / "s.toml"
    study.write_text(absolute(PLATE).replace('name = "plate"', 'name = ".."'))
    monkeypatch.chdir(work)
    code = main(["run", str(study), "--quiet", "--no-progress"])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert err.startswith("bladecase run: error: [study] name: must be a plain folder name"), err
    assert list(work.iterdir()) == [] and sorted(p.name for p in tmp_path.iterdir()) == ["s.toml", "work"]


@pytest.mark.parametrize("directory, words", [
    ("", 'must name a folder (give a folder, e.g. "results/plate")'),
    ("   ", "must name a folder"),
    ("out\u0000put", "without control characters"),
])
def test_output_directory_must_name_a_folder(directory, words):
    with pytest.raises(StudyError) as info:
        validate(_edit(_raw(), "output", "directory", directory))
    assert str(info.value).startswith("[output] directory: ") and words in str(info.value), str(info.value)


@pytest.mark.parametrize("section, key, value, words", [
    ("mesh", "path", "", "[mesh] path: must name a file"),
    ("contact", "group", "", "[contact] group: must be a mesh group name"),
    ("fem", "clamp", " ", "[fem] clamp: must be a mesh group name"),
])
def test_empty_names_are_refused(section, key, value, words):
    with pytest.raises(StudyError, match=words.replace("[", r"\[").replace("]", r"\]")):
        validate(_edit(_raw(), section, key, value))


# ----------------------------------------------------------------------------- case 2: files that are not studies

def _load_in_thread(path) -> BaseException | None:
    """``load_study(path)`` in a daemon thread: a FIFO would block the test forever otherwise."""
    out: list = []

    def target():
        try:
            load_study(path)
            out.append(None)
        except BaseException as exc:  # noqa: BLE001 - handed to the test
            out.append(exc)

    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(10)
    assert out, f"load_study({str(path)!r}) still waiting after 10 s (it opened a pipe)"
    return out[0]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_fifo_study_is_refused_before_opening(tmp_path):
    fifo = tmp_path / "study.toml"
    os.mkfifo(fifo)
    exc = _load_in_thread(fifo)
    assert isinstance(exc, StudyError), exc
    assert str(exc) == f"cannot read study file {str(fifo)!r}: it is a named pipe (FIFO), not a regular file"


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="a character device")
@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null"])
def test_device_study_is_refused(device):
    exc = _load_in_thread(device)
    assert isinstance(exc, StudyError) and "it is a device, not a regular file" in str(exc), exc


def test_folder_study_is_refused(tmp_path):
    with pytest.raises(StudyError, match=r"it is a folder, not a regular file"):
        load_study(tmp_path)


def test_deeply_nested_toml(tmp_path):
    text = "x = " + "[" * 10000 + "]" * 10000 + "\n"
    _refused(text, "not valid TOML: nested too deeply")
    f = tmp_path / "deep.toml"
    f.write_text(text)
    with pytest.raises(StudyError, match=r"deep.toml: not valid TOML: nested too deeply"):
        load_study(f)


def test_study_not_utf8(tmp_path):
    f = tmp_path / "latin1.toml"
    f.write_bytes(absolute(PLATE).encode("utf-8") + '# Clearance réglée\n'.encode("latin-1"))
    with pytest.raises(StudyError) as info:
        load_study(f)
    assert "not UTF-8 text" in str(info.value) and "save it as UTF-8" in str(info.value)
    assert str(f) in str(info.value)


def test_study_with_a_byte_order_mark_is_read(tmp_path):
    f = tmp_path / "bom.toml"
    f.write_bytes(b"\xef\xbb\xbf" + absolute(PLATE).encode("utf-8"))
    assert load_study(f).name == "plate"


def test_huge_study_file_is_refused_unread(tmp_path):
    f = tmp_path / "huge.toml"
    with open(f, "wb") as fh:  # a sparse 70 MB file: refused from its size, never read
        fh.truncate(70_000_000)
    with pytest.raises(StudyError, match=r"huge.toml'?: 70000000 bytes, more than a study file's 64000000"):
        load_study(f)
    # comments do not count; content beyond a study's size does
    with pytest.raises(StudyError, match=r"more than a study's 1000000 characters besides comments"):
        loads(absolute(PLATE) + "x = 1\n" * 200_000)


def test_cli_fifo_study_exit_2(tmp_path, capsys):
    if not hasattr(os, "mkfifo"):
        pytest.skip("named pipes")
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    result: list = []
    t = threading.Thread(target=lambda: result.append(main(["run", str(fifo), "--quiet", "--no-progress"])),
                         daemon=True)
    t.start()
    t.join(10)
    assert result == [2], "bladecase run waited on the pipe"
    assert "is a named pipe (FIFO), not a regular file" in capsys.readouterr().err


# ----------------------------------------------------------------------------- case 3: work out of proportion

def test_mesh_cells_refused_up_front_with_the_estimate():
    message = _refused(GEOMETRY.replace("size = 0.005", "size = 1e-6"), "[geometry] size: size = 1e-06 m makes about",
                       "mesh cells (estimated before meshing), more than [limits] cells = 2000000",
                       "or raise [limits] cells")
    assert "5.2e+09" in message
    fix = float(message.split("size >= ")[1].split(" m")[0])
    assert loads(GEOMETRY.replace("size = 0.005", f"size = {fix}"), base=ROOT)["geometry"]["size"] == fix


def test_cells_limit_raises_the_cap():
    text = GEOMETRY.replace("size = 0.005", "size = 2e-5")  # ~1.3e7 triangles
    _refused(text, "[geometry] size", "[limits] cells = 2000000")
    study = loads(text + "[limits]\ncells = 20000000\n", base=ROOT)
    assert study["limits"]["cells"] == 20_000_000


def test_tip_size_is_blamed_when_it_alone_is_too_fine():
    _refused(GEOMETRY.replace("size = 0.005", "size = 0.005\ntip_size = 1e-7"),
             "[geometry] tip_size: tip_size = 1e-07 m makes about", "a larger tip_size, or raise [limits] cells")


def test_default_size_counted_too():
    text = BLADE.replace("span = 0.15", "span = 1000.0").replace("contact_point = [0.0, 0.0, 0.15]", "")
    _refused(text, "[geometry] size: size = ", "(the geometry's default) makes about", "[limits] cells")


def test_geometry_consistency_up_front():
    _refused(GEOMETRY.replace("size = 0.005", "size = 0.005\ntip_size = 0.01"),
             "[geometry] tip_size: must not exceed size = 0.005")
    _refused(GEOMETRY.replace('kind = "plate"', 'kind = "plate"\ncells = "hexahedron"\nmesh_order = 2'),
             "[geometry] mesh_order: cells = 'hexahedron' makes order-1 cells")


@pytest.fixture(scope="module")
def plate_model():
    from bladecase.study import stages

    study = loads(PLATE, base=ROOT)
    mesh = stages.build_mesh(study)
    model = stages.build_model(study, mesh)
    return model, stages.build_contact(study, model)


def test_full_method_refused_above_dofs_full(plate_model):
    from bladecase.study.stages import build_reduced

    model, contact = plate_model
    study = loads(PLATE.replace('method = "modal"', 'method = "full"') + "[limits]\ndofs_full = 500\n", base=ROOT)
    with pytest.raises(StudyError) as info:
        build_reduced(study, model, contact)
    assert str(info.value) == (
        f"[reduction] method: method 'full' keeps all {model.n_dofs} free dofs of this model in dense matrices, more "
        "than [limits] dofs_full = 500: use a reduced method, e.g. method = 'lanczos-si' with size = 20, or raise "
        "[limits] dofs_full (at most 6000)")
    modal = loads(PLATE + "[limits]\ndofs_full = 500\n", base=ROOT)  # 'full' as a comparison model
    with pytest.raises(StudyError, match=r"\[reduction\] compare: method 'full' keeps all"):
        build_reduced(modal, model, contact, "full")
    ok = loads(PLATE.replace('method = "modal"', 'method = "full"') + "[limits]\ndofs_full = 2000\n", base=ROOT)
    assert build_reduced(ok, model, contact).system.n == model.n_dofs


def test_dofs_full_limit_is_bounded_and_passed_to_the_method(plate_model):
    from bladecase.reduction import reduce

    model, contact = plate_model
    _refused(PLATE + "[limits]\ndofs_full = 100000\n", "[limits] dofs_full: must be an integer with 1 <= value <= 6000")
    with pytest.raises(ValueError, match=r"limited to limit = 100 dofs; this model has \d+ free dofs"):
        reduce(model, contact, "full", limit=100)
    with pytest.raises(ValueError, match=r"limit must be an integer with 1 <= limit <= 6000"):
        reduce(model, contact, "full", limit=10**6)
    assert reduce(model, contact, "modal", 4, limit=10).size == 4  # the other methods ignore it


FORCED = PLATE + "[forcing]\nratio = 0.01\n"


@pytest.mark.parametrize("amplitude", ["1e300", "-1e300", "1e10", "1e-12"])
def test_forcing_amplitude_has_a_physical_range(amplitude):
    _refused(FORCED + f"amplitude = {amplitude}\n",
             "[forcing] amplitude: must be a force (N) or a pressure (Pa) with 1e-09 <= |amplitude| <= 1e+09",
             f"got {float(amplitude)!r}")


def test_forcing_amplitude_that_buries_the_contact_refused_before_the_sweep(plate_model):
    from bladecase.reduction import reduce
    from bladecase.study.forcing.stage import forced_response

    model, contact = plate_model
    reduced = reduce(model, contact, "modal", 10)
    with pytest.raises(ValueError) as info:
        forced_response(reduced, [], {"ratio": 0.01, "amplitude": 1e8, "points": 1, "periods": 9})
    message = str(info.value)
    assert message.startswith("[forcing] amplitude: 1e+08 N moves the contact up to "), message
    assert "× the clearance 0.0001 m (at most 1000 ×" in message and "valid: |amplitude| <= " in message
    most = float(message.split("|amplitude| <= ")[1].split(" N")[0])
    assert 1e5 < most < 1e7
    forced_response(reduced, [], {"ratio": 0.01, "amplitude": most * 0.99, "points": 1, "periods": 9})


def test_forcing_grid_product_refused():
    message = _refused(FORCED + "amplitude = 1.0\npoints = 2000\nperiods = 100000\n",
                       "[forcing] points × periods: 2000 points × 100000 periods = 200000000 forcing periods, more "
                       "than [limits] sweep_periods = 100000: fewer points or periods, or raise [limits] sweep_periods")
    assert "\n" not in message
    _refused(FORCED + "amplitude = 1.0\npoints = 200\nperiods = 300\ndirection = \"both\"\n",
             "200 points × 300 periods × 2 sweeps = 120000 forcing periods")
    study = loads(FORCED + "amplitude = 1.0\npoints = 200\nperiods = 300\ndirection = \"both\"\n"
                  "[limits]\nsweep_periods = 200000\n", base=ROOT)
    assert study["limits"]["sweep_periods"] == 200_000


def test_forcing_low_frequencies_count_in_first_mode_periods():
    _refused(FORCED + "amplitude = 1.0\nfrequencies = [0.001, 0.002]\n",
             "[forcing] points × periods: 41 points × 300 periods = 12300 forcing periods (8.", "periods T1: a "
             "forcing period longer than T1 counts in periods T1), more than [limits] sweep_periods = 100000",
             "a higher lower frequency")
    _refused(FORCED + "amplitude = 1.0\nfrequencies = [1.0, 1e6]\n",
             "[forcing] frequencies: the upper frequency must be <= 1000 f1")


def test_forcing_work_in_hz_checked_at_the_stage(plate_model):
    from bladecase.reduction import reduce
    from bladecase.study.forcing.stage import forced_response

    model, contact = plate_model
    reduced = reduce(model, contact, "modal", 10)
    forcing = {"ratio": 0.01, "amplitude": 1.0, "frequency_unit": "Hz", "frequencies": [1.0, 2.0], "points": 3,
               "periods": 100}
    with pytest.raises(ValueError, match=r"\[forcing\] points × periods: 3 points × 100 periods = 300 forcing periods "
                                         r"\(3\.49e\+05 periods T1.* more than \[limits\] sweep_periods = 1000: .*"
                                         r"f1 = 1609\.8 Hz"):
        forced_response(reduced, [], forcing, max_periods=1000)


def test_forcing_work_checked_when_the_reduced_model_is_built(plate_model):
    """A study checks the forced response as soon as its reduced model is known, before the search, with its
    own [limits] sweep_periods (frequencies in Hz: the T1 weighting needs f1)."""
    from bladecase.study.stages import build_reduced

    model, contact = plate_model
    hz = FORCED + 'amplitude = 1.0\nfrequency_unit = "Hz"\nfrequencies = [2.0, 4.0]\npoints = 5\nperiods = 100\n'
    study = loads(hz, base=ROOT)  # 500 forcing periods: fine at load time (f1 unknown)
    with pytest.raises(StudyError) as info:
        build_reduced(study, model, contact)
    assert str(info.value).startswith("[forcing] points × periods: 5 points × 100 periods = 500 forcing periods "
                                      "(2."), str(info.value)
    assert "more than [limits] sweep_periods = 100000: fewer points or periods, a higher lower frequency (f1 = " \
           "1609.8 Hz), or raise [limits] sweep_periods" in str(info.value)
    raised = loads(hz + "[limits]\nsweep_periods = 1000000\n", base=ROOT)
    assert build_reduced(raised, model, contact).size == 10
    buried = loads(FORCED + "amplitude = 1e8\n", base=ROOT)
    with pytest.raises(StudyError, match=r"^\[forcing\] amplitude: 1e\+08 N moves the contact up to 3\.\d+ m "
                                         r"statically, 3\.\d+e\+04 × the clearance 0\.0001 m"):
        build_reduced(buried, model, contact)
    build_reduced(buried, model, contact, "lanczos-si", 6)  # a comparison model: the forcing runs on the main one


def test_workers_capped_with_the_limits_key(capsys, tmp_path):
    cores = os.cpu_count() or 1
    message = _refused(PLATE + "[execution]\nworkers = 1000000000\n",
                       f"[execution] workers: 1000000000 local worker processes, at most {8 * cores} (8 per core of "
                       f"this machine's {cores}): fewer workers, or raise [limits] workers")
    assert "memory" not in message
    study = loads(PLATE + '[execution]\nexecutor = "processes"\nworkers = 1000\n[limits]\nworkers = 1000\n', base=ROOT)
    assert study["execution"]["workers"] == 1000
    f = tmp_path / "s.toml"
    f.write_text(absolute(PLATE) + "[execution]\nworkers = 1000000000\n")
    assert main(["run", str(f), "--out", str(tmp_path / "out"), "--quiet", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "bladecase run: error: [execution] workers: 1000000000 local worker processes" in err
    assert not (tmp_path / "out").exists()


def test_cli_out_of_proportion_mesh_exit_2(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(GEOMETRY.replace("size = 0.005", "size = 1e-6"))
    assert main(["run", str(f), "--out", str(tmp_path / "out"), "--quiet", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("bladecase run: error: [geometry] size: size = 1e-06 m makes about 5.2e+09 mesh cells"), err


# ----------------------------------------------------------------------------- case 4: types and values, every key

def _wrong_types(spec_types: tuple) -> list:
    """Values of the wrong type for a key taking ``spec_types``."""
    out = []
    if str not in spec_types:
        out += ["0.1"]
    if not ({int, float} & set(spec_types)):
        out += [3]
    out += [True] if bool not in spec_types else [1, "true"]
    if list not in spec_types:
        out += [[1, 2]]
    if dict not in spec_types:
        out += [{"a": 1}]
    if int in spec_types and float not in spec_types:
        out += [1.5]
    return out


TYPE_CASES = [(section, key, value) for section, keys in SCHEMA.items() for key, spec in keys.items()
              for value in _wrong_types(spec.types)]


@pytest.mark.parametrize("section, key, value", TYPE_CASES,
                         ids=[f"{s}.{k}={v!r}" for s, k, v in TYPE_CASES])
def test_every_key_refuses_wrong_types(section, key, value):
    raw = _raw(BLADE if section == "geometry" else PLATE)
    if section == "mesh" and "geometry" in raw:
        raw.pop("geometry")
    with pytest.raises(StudyError) as info:
        validate(_edit(raw, section, key, value))
    message = str(info.value)
    assert message.startswith(f"[{section}] {key}: "), message
    assert "\n" not in message


NUMBER_KEYS = [(section, key) for section, keys in SCHEMA.items() for key, spec in keys.items()
               if float in spec.types]


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("section, key", NUMBER_KEYS, ids=[f"{s}.{k}" for s, k in NUMBER_KEYS])
def test_every_number_key_refuses_nan_and_inf(section, key, value):
    raw = _raw(BLADE if section == "geometry" else PLATE)
    with pytest.raises(StudyError, match=rf"^\[{section}\] {key}: must be finite, got -?(nan|inf)$"):
        validate(_edit(raw, section, key, value))


COUNT_KEYS = [(section, key) for section, keys in SCHEMA.items() for key, spec in keys.items()
              if spec.types == (int,)]


@pytest.mark.parametrize("section, key", COUNT_KEYS, ids=[f"{s}.{k}" for s, k in COUNT_KEYS])
def test_every_integer_key_refuses_huge_and_negative_values(section, key):
    raw = _raw(BLADE if section == "geometry" else PLATE)
    capped = (section, key) in (("output", "animate"), ("forcing", "animate"))  # a huge count means "all"
    for value in ((-1,) if capped else (10**30, -1)):
        with pytest.raises(StudyError) as info:
            validate(_edit(raw, section, key, value))
        assert str(info.value).startswith(f"[{section}] {key}: "), str(info.value)


def test_a_number_as_a_string_says_so():
    assert _refused(GEOMETRY.replace("span = 0.1", 'span = "0.1"')) == \
        "[geometry] span: expected a number, got the string '0.1'"
    assert _refused(PLATE.replace("clearance = 1e-4", 'clearance = "1e-4"')) == \
        "[contact] clearance: expected a number, got the string '1e-4'"
    assert _refused(PLATE.replace("size = 10", 'size = "10"')) == \
        "[reduction] size: expected an integer, got the string '10'"
    assert _refused(PLATE + '[output]\nmanifold = "true"\n') == \
        "[output] manifold: expected true/false, got the string 'true'"
    assert _refused(PLATE.replace("size = 10", "size = true")) == "[reduction] size: expected an integer, got the " \
                                                                  "boolean true"


GEOMETRY_CASES = [
    (kind, name, value) for kind, text in (("plate", GEOMETRY), ("blade", BLADE)) for name in GEOMETRY_FIELDS[kind]
    for value in ("0.1", True, {"a": 1}, float("nan"))
]


@pytest.mark.parametrize("kind, name, value", GEOMETRY_CASES, ids=[f"{k}.{n}={v!r}" for k, n, v in GEOMETRY_CASES])
def test_every_geometry_field_refuses_wrong_types(kind, name, value):
    raw = _raw(GEOMETRY if kind == "plate" else BLADE)
    if name == "naca" and isinstance(value, str):
        value = 2412  # a number where a string is expected
    with pytest.raises(StudyError) as info:
        validate(_edit(raw, "geometry", name, value))
    message = str(info.value)
    assert message.startswith(f"[geometry] {name}: "), message
    if value == "0.1":
        assert message == f"[geometry] {name}: expected " + (
            "a list of numbers" if name == "contact_point" else "an integer" if name == "n_sections"
            else "a number") + ", got the string '0.1'"


@pytest.mark.parametrize("section, key, value, words", [
    # negative, zero, huge where it matters
    ("fem", "thickness", 1e300, "[fem] thickness: must be in [1e-09, 100] (m), got 1e+300"),
    ("fem", "thickness", 0, "[fem] thickness: must be > 0 (metres), got 0"),
    ("contact", "node", 10**30, "[contact] node: must be an integer with 0 <= value <= 2147483647, got 1e+30"),
    ("forcing", "node", -1, "[forcing] node: must be an integer with 0 <= value <= 2147483647, got -1"),
    ("reduction", "size", 10**30, "[reduction] size: must be an integer with 1 <= value <= 6000, got 1e+30"),
    ("reduction", "sizes", [8, 10**30], "[reduction] sizes: sizes must be integers with 1 <= size <= 6000, got 1e+30"),
    ("reduction", "compare", [{"method": "modal", "size": 10**30}],
     "[reduction] compare: item 0: size must be an integer with 1 <= size <= 6000, got 1e+30"),
    ("reduction", "compare", [{"method": "full", "size": 10}], "[reduction] compare: item 0: method 'full' keeps"),
    ("reduction", "compare", [{"method": ["modal"], "size": 4}], "[reduction] compare: item 0: method must be one of"),
    ("reduction", "methods", [["modal"]], "[reduction] methods: must be a list of method names"),
    ("output", "formats", [["gif"]], "[output] formats: must be a list of format names"),
    ("output", "scale", 1e300, "[output] scale: must be 'auto' or a number in [1e-12, 1e+15], got 1e+300"),
    ("output", "scale", -1.0, "[output] scale: must be 'auto' or a number in"),
    ("output", "fps", 1e-300, "[output] fps: must be at least 0.01 frames per second, got 1e-300"),
    ("output", "orbits", [{"ipp": 10**30, "T": 0.95}], "[output] orbits: item 0: ipp must be an integer between 1"),
    ("search", "period_unit", "T99999999999", "[search] period_unit: must be 's' or 'T<j>' with j <= 1000"),
    ("search", "periods", [1e-300, 1e-299], "[search] periods: the lower period must be >= 1e-06 × T1"),
    ("search", "periods", [1e-300, 1.0], "[search] periods: must be [lower, upper] with 0 < lower < upper and lower "
     ">= 1e-12 × upper"),
    ("contact", "nearest", [1e300, 0.0, 0.0], "[contact] nearest: must be a list of 2 or 3 numbers of magnitude at "
     "most 1e+06"),
    ("fem", "clamp", {"plane": "x"}, "[fem] clamp: plane must be [x0, y0, z0, nx, ny, nz]"),
    ("fem", "clamp", {"plane": [0, 0, 0, 0, 1, 0], "tol": 1e300}, "[fem] clamp: tol must be a number in [0, 1e+06]"),
    ("fem", "clamp", {"box": [[0, 0], [1]]}, "[fem] clamp: box must be [[xmin, ymin, zmin], [xmax, ymax, zmax]]"),
    ("contact", "face", {"sphere": [0, 0, float("nan"), 1]}, "[contact] face: sphere must be [x, y, z, r]"),
    ("material", "preset", "unobtainium", "[material] preset: unknown material preset 'unobtainium'"),
    ("forcing", "rayleigh", [1e300, 0.0], "[forcing] rayleigh: must be [alpha, beta] with alpha <= 1 s and beta <= "
     "1e+06 1/s"),
    ("forcing", "frequencies", [1e-300, 1e300], "[forcing] frequencies: must be [lower, upper] with 0 < lower < "
     "upper and lower >= 1e-12 × upper"),
    ("execution", "workers", 0, "[execution] workers: must be >= 1, got 0"),
    ("limits", "cells", 0, "[limits] cells: must be an integer with 1 <= value <= 1000000000, got 0"),
    ("limits", "sweep_periods", 10**30, "[limits] sweep_periods: must be an integer with 1 <= value <= 1000000000"),
    # empty lists and lists of the wrong length
    ("search", "ipp", [], "[search] ipp: must be a non-empty list"),
    ("search", "periods", [], "[search] periods: must be [lower, upper]"),
    ("search", "periods", [0.5], "[search] periods: must be [lower, upper]"),
    ("reduction", "compare_periods", [], "[reduction] compare_periods: must be a list of 1 to 8 numbers"),
    ("output", "window", [800], "[output] window: must be [width, height]"),
    ("output", "manifold_size", [], "[output] manifold_size: must be [orbits, phases]"),
    ("contact", "normal", [], "[contact] normal: must be a list of 2 or 3 finite numbers"),
    ("contact", "normal", [0, 0, 1, 0], "[contact] normal: must be a list of 2 or 3 finite numbers"),
    ("forcing", "frequencies", [1.0], "[forcing] frequencies: must be [lower, upper]"),
    ("forcing", "rayleigh", [], "[forcing] rayleigh: must be [alpha, beta]"),
    ("forcing", "load_direction", [True, 0, 0], "[forcing] load_direction: must be a list of 2 or 3 finite numbers"),
])
def test_values_refused_naming_the_key(section, key, value, words):
    with pytest.raises(StudyError) as info:
        validate(_edit(_raw(), section, key, value))
    message = str(info.value)
    assert words in message and "\n" not in message, message


def test_geometry_values_through_the_dataclass_name_the_key():
    assert _refused(BLADE.replace('naca = "2412"', 'naca = "2412"\nn_sections = 1000000000000000000000000000000')
                    ).startswith("[geometry] n_sections: must be an integer with 2 <= n_sections <= ")
    assert _refused(BLADE.replace('naca = "2412"', "naca = 2412")) == \
        "[geometry] naca: expected a string, got 2412"
    assert _refused(GEOMETRY.replace("contact_point = [0.0, 0.1]", 'contact_point = ["0", 0.1]')) == \
        "[geometry] contact_point: expected a list of numbers, got a list ['0', 0.1]"


def test_long_values_are_cut_in_messages():
    message = _refused(PLATE.replace("ipp = [1]", "ipp = [" + ", ".join(["0"] * 5000) + "]"), "[search] ipp")
    assert len(message) < 400 and "(5000 items)" in message
    message = _refused(PLATE.replace('name = "plate"', f'name = "{"x" * 100_000}"'), "[study] name")
    assert len(message) < 400 and "(100000 characters)" in message


def test_limits_round_trip_and_defaults():
    from bladecase.fe.geometry import MAX_CELLS

    study = loads(PLATE, base=ROOT)
    assert study["limits"] == {"cells": MAX_CELLS, "dofs_full": 3000, "sweep_periods": 100_000, "workers": None}
    assert validate(as_raw(copy.deepcopy(study.config))).config == study.config
    assert math.isclose(loads(PLATE + "[limits]\ndofs_full = 6000\n", base=ROOT)["limits"]["dofs_full"], 6000)
