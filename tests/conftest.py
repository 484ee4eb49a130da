"""Shared fixtures of the bladecase test suite.

Reference systems
-----------------
* ``two_dof``   — the seed paper's Sec. 1.4 example, ``chain(2, k=1, m=1/2, gap=1)``
  (closed form: ``ω² = 3 ∓ √5``).
* ``chain10``   — the paper's Sec. 2 chain with n = 10 (``k = 1``, ``m = 1/n``, ``d = 1``).
* ``random_sys`` — a dense, non-diagonal SPD ``M`` and ``K`` (n = 6, seeded) with a generic,
  non-unit constraint vector ``w`` (exercises the Moreau impact law beyond the paper).

Engines
-------
* ``dask_executor`` — one 2-worker Dask ``LocalCluster`` for the whole session (its start-up is seconds).

Independent references (numpy / scipy only, never bladecase) live in ``_util.py``.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # headless: no display in CI

import numpy as np
import pytest
from _util import random_spd_system

import bladecase as bc


@pytest.fixture(scope="session")
def two_dof() -> bc.LinearSystem:
    return bc.chain(2, k=1.0, m=0.5, gap=1.0)


@pytest.fixture(scope="session")
def chain10() -> bc.LinearSystem:
    return bc.chain(10, k=1.0, m=0.1, gap=1.0)


@pytest.fixture(scope="session")
def random_sys() -> bc.LinearSystem:
    return random_spd_system()


@pytest.fixture(scope="session")
def two_dof_backbone(two_dof) -> bc.Backbone:
    return bc.backbone(two_dof, np.linspace(1.0, 12.0, 111))


@pytest.fixture(scope="session")
def chain10_backbone(chain10) -> bc.Backbone:
    return bc.backbone(chain10, np.linspace(1.0, 14.0, 261))


@pytest.fixture(scope="session")
def random_backbone(random_sys) -> bc.Backbone:
    return bc.backbone(random_sys, np.linspace(0.6, 4.7, 301))


@pytest.fixture(scope="session")
def dask_executor():
    pytest.importorskip("distributed")
    from bladecase.study import DaskExecutor

    with DaskExecutor(workers=2) as ex:
        yield ex
