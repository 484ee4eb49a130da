"""The Campbell stage's nonsmooth-mode bands cut at the small-displacement limit (``[search] amplitude_limit`` ×
the span, as the run's arcs): on a stiff casing the band's upper edge stops where the tip amplitude reaches the
limit, ``summary["campbell"]["band_cuts"]`` says where and why and the report says it in words; an ordinary band
(a rigid casing, Newton's law) is not cut."""

from __future__ import annotations

import pytest
from _studies import PLATE, ROOT

from bladecase.post.rotation.report import rotation_report
from bladecase.study.executor import SerialExecutor
from bladecase.study.rotation import stage as rotation
from bladecase.study.rotation.stage import campbell_stage
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model

cut_band = rotation._cut_band

ROTATION = """
[rotation]
speeds = [8000]
axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}
modes = 1
"""
STIFF = ("clearance = 1e-4\nmodel = \"massless\"\ncasing_stiffness = 1e8", 'method = "massless"',
         "periods = [0.9, 0.9999]")


def _stage(text: str, monkeypatch=None) -> tuple[dict, list]:
    """The Campbell section of the plate at 8000 rpm, and the families as searched before the cut."""
    study = loads(text.replace("size = 10", "size = 4") + ROTATION, base=ROOT)
    model = build_model(study, build_mesh(study))
    uncut: list = []
    if monkeypatch is not None:
        def spy(study, model, reduced, families):
            uncut.extend(families)
            return cut_band(study, model, reduced, families)

        monkeypatch.setattr(rotation, "_cut_band", spy)
    return campbell_stage(study, model, build_contact(study, model), SerialExecutor())[1], uncut


def test_a_band_on_a_stiff_casing_is_cut_where_the_tip_reaches_the_limit(monkeypatch):
    text = (PLATE.replace("clearance = 1e-4", STIFF[0]).replace('method = "modal"', STIFF[1])
            .replace("periods = [0.5, 0.9999]", STIFF[2]))
    c, uncut = _stage(text, monkeypatch)
    band, cut = c["bands"][0], c["band_cuts"][0]
    assert band["cut"] and cut is not None and cut["mode"] == band["mode"] == 0
    span = (0.1**2 + 0.01**2) ** 0.5  # the plate's root centre to its far corner: 100 mm × 20 mm (half: 10 mm)
    assert cut["span_m"] == pytest.approx(span, rel=1e-9) and cut["limit_m"] == pytest.approx(0.05 * span, rel=1e-9)
    # where: the band's upper edge stops below the first frequency beyond the limit; why: the tip moves more there
    assert cut["high_hz"] == band["high_hz"] < cut["f_beyond_hz"]
    assert cut["tip_amplitude_beyond_m"] > cut["limit_m"]
    # the search before the cut had admissible orbits up to and beyond that frequency
    assert max(1 / a.T_lo for f in uncut for a in f.arcs) >= cut["f_beyond_hz"] * (1 - 1e-12)
    text = "\n".join(rotation_report(None, c))
    assert "(cut at the small-displacement limit)" in text
    assert f"the band stops at {band['high_hz']:.2f} Hz: the tip amplitude reaches" in text
    assert "beyond the small-displacement limit 5.025 mm (5 % of the 100.5 mm span" in text


def test_an_ordinary_band_is_not_cut():
    c, _ = _stage(PLATE)
    assert c["bands"][0] is not None and not c["bands"][0]["cut"]
    assert c["band_cuts"] == [None]
    assert "small-displacement" not in "\n".join(rotation_report(None, c))
