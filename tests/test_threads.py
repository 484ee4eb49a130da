"""The BLAS thread limit of the stages that collapse when the machine's cores are shared."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from threadpoolctl import threadpool_info

from bladecase.linalg import lowest_modes, spd_factor
from bladecase.threads import blas_threads


def _blas_threads() -> set[int]:
    return {i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


def test_a_busy_machine_runs_the_eigen_stage_on_one_thread_and_restores(monkeypatch):
    monkeypatch.delenv("BLADECASE_BLAS_THREADS", raising=False)
    before = _blas_threads()
    with blas_threads("eigen", busy=True) as n:
        assert n == 1 and _blas_threads() == {1}
    assert _blas_threads() == before
    with blas_threads("factor", busy=True) as n:  # not a stage that collapses: left alone
        assert n is None and _blas_threads() == before


def test_the_environment_variable_sets_every_stage_and_is_checked(monkeypatch):
    monkeypatch.setenv("BLADECASE_BLAS_THREADS", "1")
    with blas_threads("factor", busy=False) as n:
        assert n == 1 and _blas_threads() == {1}
    for bad in ("0", "two", "-3"):
        monkeypatch.setenv("BLADECASE_BLAS_THREADS", bad)
        with pytest.raises(ValueError, match="BLADECASE_BLAS_THREADS must be a positive integer or 'auto'"):
            with blas_threads("eigen"):
                pass


def test_the_modes_do_not_depend_on_the_threads(monkeypatch):
    n = 400
    K = sp.diags_array([[-1.0] * (n - 1), [2.0] * n, [-1.0] * (n - 1)], offsets=[-1, 0, 1], format="csc")
    M = sp.eye_array(n, format="csc")
    f = spd_factor(K, "K")
    lam = {}
    for v in ("1", "auto"):
        monkeypatch.setenv("BLADECASE_BLAS_THREADS", v)
        lam[v] = lowest_modes(K, M, 6, factor=f)[0]
    exact = 2 - 2 * np.cos(np.arange(1, 7) * np.pi / (n + 1))
    assert np.allclose(lam["1"], exact, rtol=1e-10) and np.allclose(lam["auto"], exact, rtol=1e-10)
