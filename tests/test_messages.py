"""Messages that named the wrong thing: each bad (or merely unusual) input now gets a one-line error naming the
value and what is valid — or, where the input is valid, the right answer.

* a plane normal of huge (or tiny) components is a direction, not "zero"; a selection whose distances to the
  mesh overflow is "too large", not "inf away" (nor, for ``nearest``, an arbitrary node);
* a clamp that holds every node says so, and what to change (a smaller radius, box, …);
* an ``.npz`` member whose header claims more data than it holds is a damaged file (named, with the member and
  the claimed shape), not "out of memory";
* a period so long that ``ω T`` has no phase left is refused as too long, with numbers in ``%.6g``;
* a study file mostly of comments loads; only its non-comment content counts against the study size;
* ``[output] animate`` above the cap animates every orbit it can (at most the cap), logged; a float count is
  refused saying how to write an integer.
"""

from __future__ import annotations

import io
import logging
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _studies import PLATE, absolute
from test_fe_elements import box

import bladecase as bc
from bladecase.cli import main
from bladecase.fe import assemble
from bladecase.fe.mesh import from_meshio
from bladecase.fe.select import select_nodes
from bladecase.io import read_npz
from bladecase.nsm.newton.orbits import make_orbit, orbit_1ipp
from bladecase.study.demo import demo_text
from bladecase.study.schema import MAX_STUDY_BYTES, StudyError, load_study, loads


@pytest.fixture(scope="module")
def bar():
    """8 × 2 × 2 hexahedra on [0, 0.08] × [0, 0.01] × [0, 0.01]."""
    return from_meshio(box((0.08, 0.01, 0.01), (8, 2, 2), "hexahedron"), source="bar")


def _run(argv, capsys) -> tuple[int, str]:
    """Exit code and stderr of ``main(argv)``: one error line, no traceback."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    lines = [line for line in err.splitlines() if "error" in line]
    assert len(lines) == 1, err
    return code, lines[0]


# ----------------------------------------------------------------------------- 1. huge normals, overflowing distances

@pytest.mark.parametrize("normal, unit", [
    ([1e308, 0, 0], [1, 0, 0]),
    ([1e308, 1e308, 0], [1, 1, 0]),
    ([-1e308, 0, 0], [1, 0, 0]),
    ([1e-200, 0, 0], [1, 0, 0]),      # its squares underflow to 0
    ([0, 1e-320, 0], [0, 1, 0]),      # a subnormal component
])
def test_a_plane_normal_of_any_finite_length_is_a_direction(bar, normal, unit):
    expected = select_nodes(bar, {"plane": [0.04, 0, 0, *unit]}, what="clamp")
    assert len(expected) > 0
    np.testing.assert_array_equal(select_nodes(bar, {"plane": [0.04, 0, 0, *normal]}, what="clamp"), expected)


def test_a_zero_normal_is_still_zero(bar):
    with pytest.raises(ValueError, match=r"normal \(the last 3 values\) must not be zero"):
        select_nodes(bar, {"plane": [0, 0, 0, 0, 0, 0]}, what="clamp")


@pytest.mark.parametrize("spec", [
    {"sphere": [1e200, 0, 0, 1]},
    {"sphere": [1e308, 1e308, 0, 1e308]},
    {"nearest": [1e200, 1e200, 0]},
    {"box": [[1e200, 1e200, 1e200], [1e201, 1e201, 1e201]]},
    {"plane": [1.7e308, 1.7e308, 0, 1, 1, 0]},
])
def test_values_whose_distances_overflow_are_too_large(bar, spec):
    with pytest.raises(ValueError) as info:
        select_nodes(bar, spec, what="clamp")
    message = str(info.value)
    assert "too large" in message and "overflow" in message and "1e+150" in message, message
    assert "inf away" not in message and "zero" not in message, message
    assert repr(spec) in message and "\n" not in message


def test_a_huge_box_or_radius_that_stays_finite_still_selects(bar):
    everything = {"box": [[-1e308, -1e308, -1e308], [1e308, 1e308, 1e308]]}
    assert len(select_nodes(bar, everything, what="contact")) == len(bar.points)
    assert len(select_nodes(bar, {"sphere": [0, 0, 0, 1e308]}, what="contact")) == len(bar.points)


def test_a_study_clamp_plane_normal_of_any_length_is_accepted():
    from _studies import ROOT

    text = PLATE.replace("thickness = 0.002", "thickness = 0.002\nclamp = {plane = [0, 0, 0, 1e308, 0, 0]}")
    assert loads(text, base=ROOT)["fem"]["clamp"] == {"plane": [0, 0, 0, 1e308, 0, 0]}
    with pytest.raises(StudyError, match=r"\[fem\] clamp: plane must be .*, finite numbers of magnitude at most "
                                         r"1e\+06 \(the normal: any finite length but zero\)"):
        loads(text.replace("[0, 0, 0, 1e308, 0, 0]", "[1e308, 0, 0, 1, 0, 0]"), base=ROOT)


# ----------------------------------------------------------------------------- 2. a clamp of every node

@pytest.mark.parametrize("spec, advice", [
    ({"sphere": [0.04, 0.005, 0.005, 1.0]}, r"use a smaller radius: r \+ tol must stay below 0.0406"),
    ({"box": [[-1, -1, -1], [1, 1, 1]]}, r"use a smaller box"),
])
def test_a_clamp_of_every_node_says_nothing_is_left_free(bar, spec, advice):
    with pytest.raises(ValueError) as info:
        assemble(bar, "steel", order=1, clamp=spec)
    message = str(info.value)
    assert "(81 nodes): the clamp holds every node, nothing is left free; " in message, message
    assert re.search(advice, message), message
    assert "selects every node of the body of mesh bar (81 " in message  # the words tests/test_fe_select.py matches


def test_a_study_clamp_sphere_of_every_node_exits_2(tmp_path, capsys):
    study = tmp_path / "plate.toml"
    study.write_text(absolute(PLATE).replace("thickness = 0.002",
                                             "thickness = 0.002\nclamp = {sphere = [0, 0, 0, 10]}"))
    code, line = _run(["assemble", study, "-o", tmp_path / "fe.npz", "--quiet", "--no-progress"], capsys)
    assert code == 2
    assert "[fem] clamp {'sphere': [0, 0, 0, 10]}" in line
    assert "(551 nodes): the clamp holds every node, nothing is left free; use a smaller radius" in line, line


# ----------------------------------------------------------------------------- 3. an .npz member claiming 8 TB

def _npz_with_a_lying_member(path: Path, compression=zipfile.ZIP_STORED) -> Path:
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(head, {"descr": "<f8", "fortran_order": False,
                                                "shape": (1000000, 1000000)})
    members = {"K.npy": head.getvalue() + b"\0" * 64}
    for name, value in {"M": np.eye(2), "w": np.array([0.0, 1.0]), "gap": np.array(1.0)}.items():
        b = io.BytesIO()
        np.save(b, value)
        members[f"{name}.npy"] = b.getvalue()
    with zipfile.ZipFile(path, "w", compression=compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])
def test_read_npz_names_a_member_that_claims_more_than_it_holds(tmp_path, compression):
    bad = _npz_with_a_lying_member(tmp_path / "bad.npz", compression)
    with pytest.raises(ValueError) as info:
        read_npz(bad, "matrices file")
    message = str(info.value)
    assert f"cannot read matrices file {str(bad)!r}: damaged or truncated" in message, message
    assert "member 'K.npy'" in message and "(1000000, 1000000)" in message and "float64" in message
    assert "claims 8000000000000 bytes" in message and "holds 64" in message, message


def test_cli_backbone_on_a_lying_npz_exits_2_naming_it(tmp_path, capsys):
    bad = _npz_with_a_lying_member(tmp_path / "bad.npz")
    code, line = _run(["backbone", "--matrices", bad, "--periods", "5:7:3", "--quiet", "--no-progress"], capsys)
    assert code == 2, line
    assert "out of memory" not in line
    assert str(bad) in line and "'K.npy'" in line and "(1000000, 1000000)" in line and "truncated" in line


def test_cli_modes_on_a_lying_npz_exits_2_naming_it(tmp_path, capsys):
    bad = _npz_with_a_lying_member(tmp_path / "bad.npz")
    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "s"\n[search]\nipp = [1]\nperiods = [5.0, 7.0]\nperiod_unit = "s"\n')
    code, line = _run(["modes", study, "--matrices", bad, "-o", tmp_path / "out.json", "--quiet", "--no-progress"],
                      capsys)
    assert code == 2, line
    assert str(bad) in line and "'K.npy'" in line and "(1000000, 1000000)" in line, line


def test_read_npz_still_reads_good_files(tmp_path):
    for save in (np.savez, np.savez_compressed):
        path = tmp_path / f"{save.__name__}.npz"
        save(path, K=np.eye(3), w=np.arange(3.0), gap=np.array(1.0), empty=np.zeros((0, 4)))
        data = read_npz(path)
        np.testing.assert_array_equal(data["K"], np.eye(3))
        assert data["empty"].shape == (0, 4) and float(data["gap"]) == 1.0


# ----------------------------------------------------------------------------- 4. periods beyond phase precision

@pytest.mark.parametrize("T", [1e300, 1e20])
def test_orbit_1ipp_at_a_huge_period_is_too_long_in_short_numbers(T):
    with pytest.raises(ValueError) as info:
        orbit_1ipp(bc.chain(2, k=1.0, m=0.5, gap=1.0), T=T)
    message = str(info.value)
    assert not re.search(r"\d{12}", message), message           # no 300-digit ω·T
    assert f"T = {T:.6g}" in message and "too long" in message, message
    # 5e11 periods of the fastest mode (2.75 s), rounded down
    assert "valid: 0 < T < 1.37292e+12, away from resonances" in message, message
    assert len(message) < 400 and "\n" not in message


def test_make_orbit_at_a_huge_period_is_too_long():
    with pytest.raises(ValueError, match=r"make_orbit: period T = 1e\+300 is too long"):
        make_orbit(bc.chain(2, k=1.0, m=0.5, gap=1.0), 1e300, [1e300], [1.0])


def test_orbit_messages_print_numbers_short():
    system = bc.chain(2, k=1.0, m=0.5, gap=1.0)
    with pytest.raises(ValueError) as info:
        make_orbit(system, 4.5, [1.0, 4.5 * (1 + 1e-9)], [1.0, 1.0])
    message = str(info.value)
    assert "T = 4.5" in message and "4.500000004" not in message and "exceeds T by 4.5e-09" in message, message
    assert "got [1.0, 4.5]" in message, message


# ----------------------------------------------------------------------------- 5. comment-heavy study files

def test_a_study_file_of_mostly_comments_loads(tmp_path):
    f = tmp_path / "commented.toml"
    f.write_text(demo_text() + ("# " + "a comment, as a study's author may write many " * 2 + "\n") * 110_000)
    assert f.stat().st_size > 10_000_000
    study = load_study(f)
    assert study.name == "demo"


def test_a_study_of_more_content_than_a_study_is_still_refused(tmp_path):
    f = tmp_path / "big.toml"
    f.write_text(demo_text() + "".join(f'n{k} = "{"x" * 90}"\n' for k in range(12_000)))  # 1.2 MB of keys
    with pytest.raises(StudyError, match=rf"big.toml'?: more than a study's {MAX_STUDY_BYTES} characters besides "
                                         r"comments \(is it a study file\?\)"):
        load_study(f)


def test_a_study_file_beyond_the_read_cap_is_refused_unread(tmp_path):
    f = tmp_path / "huge.toml"
    with open(f, "wb") as fh:  # sparse: 70 MB that are never written
        fh.truncate(70_000_000)
    with pytest.raises(StudyError, match=r"huge.toml'?: 70000000 bytes, more than a study file's 64000000"):
        load_study(f)


# ----------------------------------------------------------------------------- 6. [output] animate = many

def test_animate_above_the_cap_animates_all_it_can(caplog):
    text = demo_text().replace("animate = 2", "animate = 1000000000")
    with caplog.at_level(logging.INFO, logger="bladecase"):
        study = loads(text)
    assert study["output"]["animate"] == 1000
    assert ("[output] animate = 1000000000: more than any study can animate; the middle orbit of every admissible "
            "arc is animated (at most 1000)") in caplog.text


def test_animate_as_a_float_says_how_to_write_an_integer():
    with pytest.raises(StudyError) as info:
        loads(demo_text().replace("animate = 2", "animate = 1e9"))
    message = str(info.value)
    assert message.startswith("[output] animate: expected an integer, got 1e+09"), message
    assert "write 1000000000" in message, message


def test_animate_negative_is_refused_saying_what_is_valid():
    with pytest.raises(StudyError, match=r"\[output\] animate: must be an integer >= 0 \(0: none; a count above "
                                         r"1000 animates at most 1000\), got -1"):
        loads(demo_text().replace("animate = 2", "animate = -1"))
