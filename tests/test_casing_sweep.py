"""``[contact] casing_stiffness = [...]``: the nonsmooth modes searched with each casing stiffness, on the demo."""

from __future__ import annotations

import pytest

from bladecase.study import run
from bladecase.study.demo import demo_text
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


def _text(value: str) -> str:
    text = demo_text().replace("casing_stiffness = 1e6 ", f"casing_stiffness = {value} ")
    return text.replace('formats = ["gif", "mp4", "vtu", "png"]', 'formats = ["png"]').replace("animate = 2",
                                                                                                 "animate = 0")


def test_the_sweep_says_how_much_the_answer_moves(tmp_path):
    res = run(loads(_text("[1e6, 1e5]"), source="<casing>"), tmp_path, progress=False)
    s = res.summary["casing_sweep"]
    first, soft = s["rows"]
    assert (first["casing_n_per_m"], soft["casing_n_per_m"]) == (1e6, 1e5)
    # the first row is the run's own mode: the same arc as the summary's families
    arc = res.summary["families"][0]["admissible_arcs"][0]
    assert first["f_hi_hz"] == pytest.approx(arc["f_hi"], rel=1e-12)
    # measured: the arc ends at 215.42 Hz (1e6 N/m) and 213.55 Hz (1e5 N/m), top energies 0.070 J and 23 J
    assert first["f_hi_hz"] == pytest.approx(215.42, abs=0.05) and soft["f_hi_hz"] == pytest.approx(213.55, abs=0.05)
    assert s["spread"]["energy_top_ratio"] == pytest.approx(23.26 / 0.0703, rel=0.05)
    assert (tmp_path / "casing.png").is_file()
    text = (tmp_path / "report.md").read_text()
    assert "## Casing stiffness: how much the answer moves" in text
    assert "quote the frequency band" in text


@pytest.mark.parametrize("value, match", [
    ("[1e6]", "must be a number \\(N/m\\) or a list of 2 to 12 numbers, got a list of 1"),
    ("[1e6, -1.0]", "must be > 0"),
    ('[1e6, "stiff"]', "must be > 0"),
])
def test_bad_lists_are_named(value, match):
    with pytest.raises(StudyError, match=r"\[contact\] casing_stiffness: " + match):
        loads(_text(value), source="<casing>")
