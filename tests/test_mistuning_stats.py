"""Mistuning statistics: reproducible samples, serial and Dask bit for bit, Whitehead's bound, the histogram."""

from __future__ import annotations

import numpy as np
import pytest

from bladecase.post.disk.mistuning_plot import amplification_figure
from bladecase.reduction.mistuning import amplification, family_band, lumped_disk, mistuning_model
from bladecase.reduction.mistuning_stats import (
    mistuning_statistics,
    random_mistuning,
    whitehead_bound,
)
from bladecase.study.executor import SerialExecutor

FORCING = {"zeta": 0.001, "force": 1, "response": 1}


@pytest.fixture(scope="module")
def model():
    return mistuning_model(*lumped_disk(24))


def test_samples_are_reproducible():
    a, b, c = (random_mistuning(24, 5, 0.01, seed=s) for s in (3, 3, 4))
    assert np.array_equal(a, b) and not np.allclose(a, c)
    assert a.shape == (5, 24) and 0.005 < a.std() < 0.02


def test_statistics_serial_and_dask_bit_identical(model, dask_executor):
    """8 samples through a 2-worker local Dask cluster and through the serial executor: the same floats; each
    factor equals :func:`amplification` of its deviations, and none passes Whitehead's bound."""
    hz = family_band(model, count=201)
    kw = {"std": 0.005, "samples": 8, "seed": 11, "frequencies": hz, **FORCING}
    serial = mistuning_statistics(model, 3, executor=SerialExecutor(), **kw)
    remote = mistuning_statistics(model, 3, executor=dask_executor, **kw)
    for name in ("deltas", "factors", "blades", "frequencies"):
        assert np.array_equal(getattr(serial, name), getattr(remote, name)), name
    assert serial.tuned == remote.tuned
    assert serial.factors[0] == pytest.approx(amplification(model, serial.deltas[0], 3, hz, **FORCING), rel=1e-12)
    assert serial.bound == whitehead_bound(24) and 1.0 < serial.factors.max() <= serial.bound


def test_summary_and_figure(model):
    stats = mistuning_statistics(model, 11, std=0.003, samples=6, seed=2, frequencies=family_band(model, count=201),
                                 **FORCING)
    s = stats.summary()
    assert s["samples"] == 6 and s["largest"] == stats.factors.max() == stats.factors[s["largest_sample"]]
    assert s["percentiles"]["p5"] <= s["percentiles"]["p50"] <= s["percentiles"]["p99"] <= s["largest"]
    fig = amplification_figure(stats, bins=5)
    assert len(fig.axes[0].patches) == 5 and sum(p.get_height() for p in fig.axes[0].patches) == 6


@pytest.mark.parametrize("kwargs, message", [
    ({"std": 0.0}, "std must be a finite number > 0"),
    ({"std": 0.5}, "std must be < 0.3"),
    ({"samples": 0}, "samples must be an integer"),
    ({"seed": -1}, "seed must be an integer"),
])
def test_bad_statistics_input(model, kwargs, message):
    args = {"std": 0.01, "samples": 2, "seed": 0, **kwargs}
    with pytest.raises(ValueError, match=message):
        mistuning_statistics(model, 3, **args, **FORCING)
