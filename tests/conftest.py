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
* ``dask_executor`` — one 2-worker Dask ``LocalCluster`` shared by the files that use it (its start-up is
  seconds), closed when the session moves on to other files.

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
import gc
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
    """One 2-worker ``LocalCluster``, started at its first ``map`` and closed as soon as this process leaves the
    files of :data:`DASK_FILES` (:func:`pytest_runtest_teardown`): an idle cluster is not free — its scheduler, two
    worker processes and their nannies heartbeat, about 10 % of a core, which ran under the rest of the session on a
    2-core machine.  A later use (another file, or another order of the files) starts it again (the executor
    starts its cluster lazily)."""
    pytest.importorskip("distributed")
    from bladecase.study import DaskExecutor

    with DaskExecutor(workers=2) as ex:
        _DASK.append(ex)
        try:
            yield ex
        finally:
            _DASK.remove(ex)


def load_example(name: str):
    """``examples/<name>.py`` as a fresh module (the scripts put ``examples/`` on ``sys.path`` themselves)."""
    spec = importlib.util.spec_from_file_location(f"bladecase_example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def fork_script(script: str | Path, *args, log: Path, cwd: Path | None = None):
    """``script`` (Python source, or a script file) run as ``__main__`` with the arguments ``args`` in a forked
    child of this process, where bladecase is already imported: no interpreter starts (about a second of CPU each).
    For what a script does, not for what importing does (that needs a fresh interpreter).  SIGINT and SIGTERM are
    handled as in a fresh interpreter, stdout and stderr go to the file ``log``, the working directory is ``cwd``
    if given.  Returns the started child (``join``, ``is_alive``, ``exitcode``: ``-signum`` when a signal killed
    it, 1 after an uncaught exception)."""
    import multiprocessing

    child = multiprocessing.get_context("fork").Process(target=_script_in_child, args=(script, args, log, cwd))
    child.start()
    return child


def run_forked(script: str | Path, *args, cwd: Path | None = None, timeout: float = 120) -> tuple[int, str]:
    """:func:`fork_script` to its end: the exit code and the output (stdout and stderr)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "output.txt"
        child = fork_script(script, *args, log=log, cwd=cwd)
        child.join(timeout)
        if child.is_alive():
            child.kill()
            child.join()
            raise TimeoutError(f"the forked script did not finish within {timeout} s")
        return child.exitcode, log.read_text()


def _script_in_child(script: str | Path, args: tuple, log: Path, cwd: Path | None) -> None:
    import runpy
    import signal
    import sys

    signal.signal(signal.SIGINT, signal.default_int_handler)  # an interpreter's own handlers, whatever the parent's
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if cwd is not None:
        os.chdir(cwd)
    sys.stdout = sys.stderr = open(log, "w", buffering=1)  # the child's streams until it exits
    if isinstance(script, Path):
        sys.argv = [str(script), *map(str, args)]
        runpy.run_path(str(script), run_name="__main__")
    else:
        sys.argv = ["-c", *map(str, args)]
        exec(script, {"__name__": "__main__"})


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
    "tests/test_inputs_api.py",  # mostly waiting (time-outs of unreachable schedulers), little CPU
    "tests/test_nodal_modes.py",
    "tests/test_fem.py",
    "tests/test_engineering_outputs.py",
    "tests/test_forcing_stage.py",
    "tests/test_compare_decides.py",
    "tests/test_readme.py",
    "tests/test_casing_sweep.py",
    "tests/test_nodal_study.py",
    "tests/test_nodes.py",
    "tests/test_forced_massless.py",
    "tests/test_calculix.py",
    "tests/test_isoparametric.py",
    "tests/test_hex_blade.py",
    "tests/test_tip_excursion.py",
    "tests/test_scan.py",
    "tests/test_orbits.py",
    "tests/test_viz.py",
    "tests/test_massless.py",
    "tests/test_rotation_study.py",
    "tests/test_rotation.py",
    "tests/test_ownership.py",
]

#: The files that use ``dask_executor`` (one work unit of :data:`SAME_WORKER`) and the session's executor while it
#: exists.
DASK_FILES = ("tests/test_executor.py", "tests/test_comparison_study.py")
_DASK: list = []


#: Files that share session fixtures, each group one work unit (run one after the other on one worker, so the
#: fixture is computed once): the Dask cluster (``dask_executor``: each start spawns and imports two Dask workers,
#: seconds of CPU) and the Fig. 8 example's computations (``fig8_example``).
SAME_WORKER = [
    DASK_FILES,
    ("tests/test_examples.py", "tests/test_fig8.py"),
]


def pytest_collection_finish(session):
    """Move what collection built (modules, test items, fixtures' definitions: most of a worker's objects, alive
    until the end) out of the cyclic garbage collector's reach: its full collections then walk only what the tests
    create (measured over the suite: about 3 s of full collections per worker, half that with the freeze)."""
    gc.collect()
    gc.freeze()


def pytest_runtest_teardown(item, nextitem):
    """Close the Dask cluster once the next test is not in :data:`DASK_FILES` (or there is none)."""
    if _DASK and (nextitem is None or nextitem.path.name not in {Path(f).name for f in DASK_FILES}):
        _DASK[0].close()


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
