"""A nonsmooth-mode band on the Campbell diagram is visible at the figure's scale, whatever its width: a band
narrower than MIN_BAND of the axis is drawn that wide, hatched, with its true width in the legend."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.fe.campbell import Campbell, crossings
from bladecase.post.rotation.campbell import MIN_BAND, campbell_figure


def _campbell():
    speeds = np.linspace(0, 1000, 5)
    f = np.c_[700 + 0.02 * speeds, 1100 + 0.01 * speeds, 1800 + 0.0 * speeds]
    return speeds, f, Campbell(speeds, f, np.tile([0, 1, 2], (5, 1)), np.ones((5, 3)), [2, 4],
                               crossings(speeds, f, [2, 4]))


@pytest.mark.parametrize("width, widened", [(0.0003, True), (0.05, False)])
def test_a_band_is_visible_and_labelled_with_its_true_width(width, widened):
    speeds, f, c = _campbell()
    fig = campbell_figure(c, bands={0: (speeds, f[:, 0], f[:, 0] * (1 + width))})
    ax = fig.axes[0]
    (band,) = [p for p in ax.collections if p.get_label().startswith("mode 1: nonsmooth mode")]
    ys = band.get_paths()[0].vertices[:, 1]
    top = ax.get_ylim()[1]
    assert ys.max() - ys.min() >= MIN_BAND * top * (1 - 1e-9) if widened else ys.max() - ys.min() >= width * 700
    label = band.get_label()
    assert f"up to +{100 * width:.2g} %" in label and ("(drawn wider)" in label) == widened
    assert (band.get_hatch() == "///") == widened


def test_the_speed_axis_speaks_the_studys_unit_with_rpm_on_top():
    speeds, f, c = _campbell()
    fig = campbell_figure(c, speed_unit="rad/s")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "rotation speed (rad/s)" and ax.get_xlim()[1] == pytest.approx(1000.0)
    (top,) = [child for child in ax.get_children() if type(child).__name__ == "SecondaryAxis"]
    assert top.get_xlabel() == "(rpm)"
    rpm = campbell_figure(c).axes[0]
    assert rpm.get_xlabel() == "rotation speed (rpm)" and rpm.get_xlim()[1] == pytest.approx(1000 * 60 / (2 * np.pi))
    eo = {t.get_text(): t.get_position() for t in ax.texts}  # EO labels on their lines f = n Ω / 2π
    for n in c.engine_orders:
        x, y = eo[f"EO {n}"]
        assert y == pytest.approx(n * x / (2 * np.pi))
