"""Which mistuned blade rubs first: each blade's peak tip excursion of the reduced mistuning model (both families of
a lumped 4-blade disk: a complete basis) against the disk assembled and solved directly — physical masses and
springs, the blade springs scaled, modal damping from scipy's own modes of the assembled tuned disk, the steady state
of ``(K − ω²M + iωC) u = F`` per frequency and each blade's peak refined independently."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import minimize_scalar

from bladecase.reduction.mistuning import family_band, lumped_disk, mistuning_model
from bladecase.reduction.mistuning_rub import blade_peaks, first_rub, sample_rub

N, ZETA, ORDER = 4, 0.004, 1
MD, MB, KD, KB, KC = 5.0, 1.0, 20.0, 0.93, 2.0  # lumped_disk's defaults
DELTA = np.array([0.03, -0.02, 0.01, -0.025])


def _assembled(delta):
    """``(M, K, C)`` of the whole disk, dofs ``[disk_0, blade_0, disk_1, blade_1, …]``; ``C`` modal (``2ζω``) on
    the tuned disk's modes."""
    def stiffness(d):
        K = np.zeros((2 * N, 2 * N))
        for j in range(N):
            a, b, nxt = 2 * j, 2 * j + 1, 2 * ((j + 1) % N)
            K[a, a] += KD
            kb = KB * (1 + d[j])
            K[np.ix_([a, b], [a, b])] += kb * np.array([[1, -1], [-1, 1]])
            K[np.ix_([a, nxt], [a, nxt])] += KC * np.array([[1, -1], [-1, 1]])
        return K
    M = np.diag(np.tile([MD, MB], N))
    lam, Phi = sla.eigh(stiffness(np.zeros(N)), M)
    C = M @ Phi @ np.diag(2 * ZETA * np.sqrt(lam)) @ Phi.T @ M
    return M, stiffness(delta), C


def _direct_peaks(delta, band):
    M, K, C = _assembled(delta)
    F = np.zeros(2 * N, dtype=complex)
    F[1::2] = np.exp(2j * math.pi * ORDER * np.arange(N) / N)  # blade j: e^{2πi e j/N}

    def amp(hz):
        w = 2 * math.pi * hz
        return np.abs(np.linalg.solve(K - w * w * M + 1j * w * C, F)[1::2])

    grid = np.array([amp(f) for f in band])
    out = []
    for j in range(N):
        i = int(np.argmax(grid[:, j]))
        res = minimize_scalar(lambda f, j=j: -amp(f)[j], bounds=(band[max(i - 1, 0)], band[min(i + 1, band.size - 1)]),
                              method="bounded", options={"xatol": 1e-12})
        out.append(max(-res.fun, grid[i, j]))
    return np.array(out)


@pytest.fixture(scope="module")
def model():
    sector, kb = lumped_disk(N)
    return mistuning_model(sector, kb, families=[0, 1])


def test_each_blades_peak_equals_the_assembled_disks(model):
    band = family_band(mistuning_model(*lumped_disk(N), families=[0]), count=401)
    a, _ = blade_peaks(model, DELTA, ORDER, band, zeta=ZETA, force=1, response=1)
    direct = _direct_peaks(DELTA, band)
    assert np.abs(a - direct).max() <= 1e-7 * direct.max()
    assert np.ptp(direct) > 0.05 * direct.max()  # mistuned: the blades differ, the test can tell them apart


def test_the_first_blade_to_rub_with_uniform_and_per_blade_clearances(model):
    band = family_band(mistuning_model(*lumped_disk(N), families=[0]), count=401)
    direct = _direct_peaks(DELTA, band)
    kw = {"model": model, "order": ORDER, "frequencies": band, "zeta": ZETA, "force": 1, "response": 1}
    r = sample_rub(DELTA, clearance=0.5, **kw)
    assert r["blade"] == int(np.argmax(direct))
    assert r["level"] == pytest.approx(0.5 / direct.max(), rel=1e-7)
    tuned = _direct_peaks(np.zeros(N), band)
    assert r["tuned_ratio"] == pytest.approx(tuned.max() / direct.max(), rel=1e-7)
    second = np.sort(0.5 / direct)[1]
    assert r["lead"] == pytest.approx(second / (0.5 / direct.max()) - 1, rel=1e-6)
    # a larger clearance over the blade that peaks most: the next blade by c_j / a_j rubs first
    c = np.full(N, 0.5)
    c[int(np.argmax(direct))] = 0.5 * 1.5 * direct.max() / np.sort(direct)[-2]
    r2 = sample_rub(DELTA, clearance=c, **kw)
    assert r2["blade"] == int(np.argmin(c / direct)) != r["blade"]


def test_bad_clearances_are_named():
    with pytest.raises(ValueError, match="clearance must be > 0"):
        first_rub([1.0, 2.0], [1.0, -1.0])
    with pytest.raises(ValueError, match="peaks must be"):
        first_rub([1.0, np.nan], 1.0)
