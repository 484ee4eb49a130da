"""The study's speed unit everywhere: the report's rotation and Campbell words, the log, the messages and the
Campbell figure speak ``[rotation] speed_unit`` first and the other common unit in brackets (rad/s ↔ rpm)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _studies import PLATE, absolute

from bladecase.cli import main
from bladecase.fe.campbell import Campbell, crossings
from bladecase.post.rotation.campbell import campbell_figure
from bladecase.post.rotation.report import rotation_report, speed_words, to_unit

RPM = 2 * math.pi / 60


def _campbell_section(unit: str) -> dict:
    w = [0.0, 500.0, 1000.0]
    return {"speeds_rad_s": w, "speeds_rpm": [x / RPM for x in w], "speed_unit": unit,
            "tracked_frequencies_hz": [[100.0, 110.0, 130.0]], "engine_orders": [1],
            "crossings": [{"engine_order": 1, "mode": 0, "speed_rad_s": 700.0, "frequency_hz": 111.4}],
            "link_mac": [[1.0, 0.5, 0.99]], "running_clearance_m": [1e-4, 9e-5, 7e-5],
            "bands": [{"mode": 0, "low_hz": 100.0, "high_hz": 104.0}, None, None], "band_notes": [None] * 3,
            "risks": [{"engine_order": 1, "from_rad_s": 600.0, "to_rad_s": 650.0, "from_rpm": 5729.6,
                       "to_rpm": 6207.0}]}


@pytest.mark.parametrize("unit, first, second", [("rad/s", "rad/s", "rpm"), ("rpm", "rpm", "rad/s")])
def test_the_report_speaks_the_studys_unit_first(unit, first, second):
    op = {"speed_rad_s": 1000.0, "speed_rpm": 1000 / RPM, "speed_unit": unit, "closure_m": 1e-5,
          "clearance_cold_m": 1e-4, "clearance_running_m": 9e-5, "axis": {"origin": [0, 0, 0], "direction": [0, 0, 1]}}
    text = "\n".join(rotation_report(op, _campbell_section(unit)))
    words = {"rad/s": "1000 rad/s (9549.3 rpm)", "rpm": "9549.3 rpm (1000 rad/s)"}[unit]
    assert f"Operating speed {words} about" in text
    assert f"| speed ({first}) | ({second}) |" in text
    row = "| 500 | 4774.65 |" if unit == "rad/s" else "| 4774.65 | 500 |"
    assert row in text
    assert f"EO 1 × mode 1 at {speed_words(700.0, unit)}, 111.40 Hz" in text
    assert f"from {speed_words(600.0, unit)} to {speed_words(650.0, unit)}" in text
    assert f"between {speed_words(0.0, unit)} and {speed_words(500.0, unit)} (MAC 0.50" in text
    # the numbers themselves: 1000 rad/s is 9549.3 rpm
    assert to_unit(1000.0, "rpm") == pytest.approx(60_000 / (2 * math.pi))
    assert text.count(f" {first} (") >= 4


def test_a_summary_without_a_unit_reads_in_rpm():
    s = _campbell_section("rpm")
    del s["speed_unit"]
    del s["risks"][0]["from_rad_s"], s["risks"][0]["to_rad_s"]
    text = "\n".join(rotation_report(None, s))
    assert "| speed (rpm) | (rad/s) |" in text and "from 5729.6 rpm to 6207 rpm" in text


@pytest.mark.parametrize("unit, top", [("rad/s", "(rpm)"), ("rpm", "(rad/s)")])
def test_the_figure_has_the_other_unit_on_top(unit, top):
    speeds = np.linspace(0, 1000, 5)
    f = np.c_[80 + 0.02 * speeds]
    c = Campbell(speeds, f, np.zeros((5, 1), int), np.ones((5, 1)), [2], crossings(speeds, f, [2]))
    ax = campbell_figure(c, speed_unit=unit).axes[0]
    (sec,) = [child for child in ax.get_children() if type(child).__name__ == "SecondaryAxis"]
    assert sec.get_xlabel() == top
    x_end = ax.get_xlim()[1]
    assert x_end == pytest.approx(to_unit(1000.0, unit))
    # the top axis maps the bottom one's end onto the same speed in the other unit
    other = top.strip("()")
    assert sec._functions[0](x_end) == pytest.approx(to_unit(1000.0, other))


def test_a_closed_clearance_is_said_in_rad_per_second(tmp_path, capsys):
    text = absolute(PLATE).replace("size = 10", "size = 4") + """
[rotation]
speeds = [0, 1256.6370614359173]
speed_unit = "rad/s"
axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}
[output]
formats = []
"""
    path = tmp_path / "s.toml"
    path.write_text(text)
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "at 1256.64 rad/s (12000 rpm) the blade's centrifugal growth" in err
    touch = float(err.split("from about ")[1].split(" rad/s")[0])
    assert 11000 * RPM < touch < 12000 * RPM  # as the rpm study's 11000–12000 rpm
    assert not (tmp_path / "out").exists()
