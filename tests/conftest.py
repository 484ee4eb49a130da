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

BLAS threads
------------
The suite runs one pytest-xdist worker per core, so each process gets one OpenBLAS thread
(``OPENBLAS_NUM_THREADS=1`` unless the caller set it; set here, before numpy is first imported).
Threaded OpenBLAS in two workers on two cores oversubscribes the machine: its threads spin-wait,
and the many small dense solves of the tests (4×4 ``expm``, Newton steps) ran up to 10× slower
under that contention.  The thread count changes no claim of a test.  (tests/test_executor.py's check that
executor workers get one BLAS thread removes the variable first; Dask's nanny sets it for its workers anyway.)
"""

from __future__ import annotations

import functools
import importlib.util
import os
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy's first import (see "BLAS threads" above)

import matplotlib

matplotlib.use("Agg")  # headless: no display in CI

import numpy as np
import pytest
from _util import random_spd_system

import bladecase as bc

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


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


def load_example(name: str):
    """``examples/<name>.py`` as a fresh module (the scripts put ``examples/`` on ``sys.path`` themselves)."""
    spec = importlib.util.spec_from_file_location(f"bladecase_example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="session")
def fig8_example():
    """``examples/fig8_sensitivity.py`` loaded once, its three computations memoised per argument.

    tests/test_examples.py runs its ``main(resolution="low")``, tests/test_fig8.py checks the numbers of the
    same calls (``find_fig8_period(120)``, ``newton_measure`` and ``massless_measure`` at n = 20, 50, 100, 101):
    the functions are pure (a chain and a period in, orbits and measures out, nothing changed), so the first
    call of each serves both files (run on one worker: :data:`SAME_WORKER`)."""
    mod = load_example("fig8_sensitivity")
    for name in ("find_fig8_period", "newton_measure", "massless_measure"):
        setattr(mod, name, functools.cache(getattr(mod, name)))
    return mod


# ----------------------------------------------------------------------------- scheduling (pytest-xdist)

#: Test files, longest first (per-file totals of ``--durations=0``, measured on 2 cores).  ``make test`` runs
#: ``--dist loadfile``: these go to the workers first, heaviest first, and the files not listed (each a few
#: seconds or less) fill in at the end, so that the two workers finish together.  (xdist's own order is by the
#: number of tests per file, which left a few slow files of 1–5 tests for the end.)  An out-of-date list only
#: costs balance, never a test.
HEAVIEST_FIRST = [
    "tests/test_docs_run.py",  # the README's commands in order (its critical path) beside the docs' Python
    "tests/test_executor.py",  # with test_comparison_study.py (SAME_WORKER)
    "tests/test_examples.py",  # with test_fig8.py (SAME_WORKER)
    "tests/test_pipeline.py",
    "tests/test_search_speed.py",
    "tests/test_rub_study.py",
    "tests/test_kipp.py",
    "tests/test_nodal_modes.py",
    "tests/test_ownership.py",
    "tests/test_engineering_outputs.py",
    "tests/test_nodal_study.py",
    "tests/test_fem.py",
    "tests/test_forcing_stage.py",
    "tests/test_nodes.py",
    "tests/test_compare_decides.py",
    "tests/test_inputs_api.py",
    "tests/test_readme.py",
    "tests/test_casing_sweep.py",
    "tests/test_forced_massless.py",
    "tests/test_calculix.py",
    "tests/test_isoparametric.py",
    "tests/test_scan.py",
    "tests/test_massless.py",
    "tests/test_orbits.py",
    "tests/test_hex_blade.py",
    "tests/test_viz.py",
    "tests/test_tip_excursion.py",
    "tests/test_rotation_study.py",
    "tests/test_rotation.py",
]

#: Files that share session fixtures, each group one work unit (run one after the other on one worker, so the
#: fixture is computed once): the Dask cluster (``dask_executor``: each start spawns and imports two Dask workers,
#: seconds of CPU) and the Fig. 8 example's computations (``fig8_example``).
SAME_WORKER = [
    ("tests/test_executor.py", "tests/test_comparison_study.py"),
    ("tests/test_examples.py", "tests/test_fig8.py"),
]


@pytest.hookimpl(optionalhook=True)  # a pytest-xdist hook: no error where xdist is not loaded (-p no:xdist)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the heaviest files handed out first (:data:`HEAVIEST_FIRST`) and the files of a
    :data:`SAME_WORKER` group together; any other ``--dist``: xdist's own scheduler."""
    if config.getoption("dist", None) != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    rank = {path: i for i, path in enumerate(HEAVIEST_FIRST)}
    unit = {path: group[0] for group in SAME_WORKER for path in group}

    class HeaviestFirst(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            scope = super()._split_scope(nodeid)
            return unit.get(scope, scope)

        def _assign_work_unit(self, node) -> None:
            heaviest = min(self.workqueue, key=lambda scope: rank.get(scope, len(rank)))  # ties: xdist's order
            self.workqueue.move_to_end(heaviest, last=False)
            super()._assign_work_unit(node)

    return HeaviestFirst(config, log)
