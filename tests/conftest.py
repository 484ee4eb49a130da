"""Shared fixtures of the bladecase test suite.

Reference systems
-----------------
* ``two_dof``   — the seed paper's Sec. 1.4 example, ``chain(2, k=1, m=1/2, gap=1)``
  (closed form: ``ω² = 3 ∓ √5``).
* ``chain10``   — the paper's Sec. 2 chain with n = 10 (``k = 1``, ``m = 1/n``, ``d = 1``).
* ``random_sys`` — a dense, non-diagonal SPD ``M`` and ``K`` (n = 6, seeded) with a generic,
  non-unit constraint vector ``w`` (exercises the Moreau impact law beyond the paper).
* ``five_dof``  — ``chain(5, k=1, m=0.2, gap=1)``.

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

Animation frames
----------------
The frames are rendered off-screen by Mesa's software rasteriser (llvmpipe), where pyvista's default 8× multi-sample
anti-aliasing is most of a frame's cost: ``PYVISTA_MULTI_SAMPLES=0`` (unless the caller set it; pyvista's own
variable, read when a plotter's theme is made, and inherited by the scripts and commands the tests start) renders
the same frames with hard edges at about a quarter of the CPU (measured: 20 frames of an 80k-point surface at
800×600, 7.0 s → 1.5 s).  What the tests check of a frame (its size, that it is not blank, that the blade moves,
the red casing on impact frames) does not depend on smoothed edges.
"""

from __future__ import annotations

import functools
import gc
import importlib.util
import os
import threading
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy's first import (see "BLAS threads" above)
os.environ.setdefault("PYVISTA_MULTI_SAMPLES", "0")  # before pyvista's (see "Animation frames" above)

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
def five_dof() -> bc.LinearSystem:
    return bc.chain(5, k=1.0, m=0.2, gap=1.0)


@pytest.fixture(scope="session")
def chain_families(two_dof, five_dof):
    """``chain_families(name, k, T_range, scan)``: ``nonsmooth_mode(system, k, T_range, scan=scan)`` of ``two_dof``
    or ``five_dof`` (by name), computed once per argument for the session.  tests/test_kipp.py checks these families'
    orbits and arcs, tests/test_search_speed.py compares two of them with its one-by-one search: the search is pure
    (a system and a range in, new families out), the tests only read them, so the first call serves both files
    (:data:`SEARCH_FILES`, one work unit)."""
    systems = {"two_dof": two_dof, "five_dof": five_dof}

    @functools.cache
    def families(name: str, k: int, T_range: tuple[float, float], scan: int) -> list:
        return bc.nonsmooth_mode(systems[name], k, T_range, scan=scan)

    return families


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


@pytest.fixture(scope="session")
def bar10_massless_mode() -> bc.Branch:
    """``massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))`` (about half a second): the 10-element bar's
    first massless mode, one contact phase from grazing, then two (a fold in T).  Pure (a system and a range in, a
    new branch out) and only read by the files of :data:`MASSLESS_MODE_FILES` (one work unit), so computed once;
    ``bar10_massless_mode.system`` is its bar."""
    return bc.massless_mode(bc.bar(10, 0.5, contact="massless"), (3.2, 4.1))


@pytest.fixture(scope="session")
def twisted_blade_p2() -> bc.FEModel:
    """``meshes/twisted_blade.msh`` assembled at order 2 (tetra10; about a second): the P2 model on which
    tests/test_viz.py draws and tests/test_export.py writes synthetic fields, which its material does not enter
    (both files: one work unit, :data:`SAME_WORKER`)."""
    return bc.assemble(bc.load_mesh(EXAMPLES.parent / "meshes" / "twisted_blade.msh"), "Ti-6Al-4V", order=2)


def load_example(name: str):
    """``examples/<name>.py`` as a fresh module (the scripts put ``examples/`` on ``sys.path`` themselves)."""
    spec = importlib.util.spec_from_file_location(f"bladecase_example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _native_threads() -> int | None:
    """Threads of this process that Python did not start (None where ``/proc`` cannot tell)."""
    try:
        return len(os.listdir("/proc/self/task")) - threading.active_count()
    except OSError:
        return None


#: :func:`_native_threads` once collection has imported the test modules (pytest-xdist's own I/O thread).
_NATIVE_AT_START: list[int | None] = []


def fork_is_safe() -> bool:
    """No thread that Python did not start has appeared in this process since collection.  A forked child has only
    the forking thread: once this process has meshed, gmsh's thread pool exists here and not in the child, and gmsh
    meshing in the child waits for it for ever.  Where this is False, run a script that may mesh in a fresh
    interpreter instead of :func:`fork_script`."""
    now = _native_threads()
    return now is not None and bool(_NATIVE_AT_START) and now <= _NATIVE_AT_START[0]


def fork_script(script: str | Path, *args, log: Path, cwd: Path | None = None, env: dict | None = None,
                errlog: Path | None = None):
    """``script`` (Python source, or a script file) run as ``__main__`` with the arguments ``args`` in a forked
    child of this process, where bladecase is already imported: no interpreter starts (about a second of CPU each).
    For what a script does, not for what importing does (that needs a fresh interpreter); a script that meshes only
    while :func:`fork_is_safe`.  SIGINT and SIGTERM are handled as in a fresh interpreter, stdout and stderr go to
    the file ``log`` (stderr to ``errlog`` if given), the working directory is ``cwd`` and ``env`` is added to
    ``os.environ`` if given.  Returns the started child (``join``, ``is_alive``, ``exitcode``: ``-signum`` when a
    signal killed it, 1 after an uncaught exception)."""
    import multiprocessing

    child = multiprocessing.get_context("fork").Process(target=_script_in_child,
                                                        args=(script, args, log, cwd, env, errlog))
    child.start()
    return child


def run_forked(script: str | Path, *args, cwd: Path | None = None, timeout: float = 120,
               env: dict | None = None) -> tuple[int, str]:
    """:func:`fork_script` to its end: the exit code and the output (stdout and stderr)."""
    code, output, _ = _run_forked(script, args, cwd, timeout, env, split=False)
    return code, output


def run_forked_split(script: str | Path, *args, cwd: Path | None = None, timeout: float = 120,
                     env: dict | None = None) -> tuple[int, str, str]:
    """:func:`fork_script` to its end: the exit code, stdout and stderr (as ``subprocess.run`` gives them)."""
    return _run_forked(script, args, cwd, timeout, env, split=True)


def _run_forked(script, args, cwd, timeout, env, split: bool) -> tuple[int, str, str]:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        log, errlog = Path(tmp) / "output.txt", (Path(tmp) / "stderr.txt" if split else None)
        child = fork_script(script, *args, log=log, cwd=cwd, env=env, errlog=errlog)
        child.join(timeout)
        if child.is_alive():
            child.kill()
            child.join()
            raise TimeoutError(f"the forked script did not finish within {timeout} s")
        return child.exitcode, log.read_text(), (errlog.read_text() if split else "")


def _script_in_child(script: str | Path, args: tuple, log: Path, cwd: Path | None, env: dict | None = None,
                     errlog: Path | None = None) -> None:
    import runpy
    import signal
    import sys

    signal.signal(signal.SIGINT, signal.default_int_handler)  # an interpreter's own handlers, whatever the parent's
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if cwd is not None:
        os.chdir(cwd)
    if env:
        os.environ.update(env)
    sys.stdout = sys.stderr = open(log, "w", buffering=1)  # the child's streams until it exits
    if errlog is not None:
        sys.stderr = open(errlog, "w", buffering=1)
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

#: Test files (or the first file of a :data:`SAME_WORKER` group), longest first (per-file CPU totals of a run on 2
#: cores).  ``make test`` runs ``--dist loadfile``: these go to the workers first, heaviest first, and the files not
#: listed (each a few seconds or less) fill in at the end, so that the two workers finish together.  (xdist's own
#: order is by the number of tests per file, which left a few slow files of 1–5 tests for the end.)  An out-of-date
#: list only costs balance, never a test.
HEAVIEST_FIRST = [
    "tests/test_docs_run.py",  # the README's commands in order (its critical path) beside the docs' Python; with
    # test_readme.py (SAME_WORKER)
    "tests/test_executor.py",  # with test_comparison_study.py and test_mistuning_stats.py (SAME_WORKER)
    "tests/test_search_speed.py",  # with test_kipp.py (SAME_WORKER)
    "tests/test_examples.py",  # with test_fig8.py (SAME_WORKER)
    "tests/test_friction_study.py",
    "tests/test_fem.py",
    "tests/test_scan.py",  # with test_orbits.py and test_simulate.py (SAME_WORKER)
    "tests/test_pipeline.py",
    "tests/test_nodal_modes.py",
    "tests/test_engineering_outputs.py",  # with the other MASSLESS_MODE_FILES (SAME_WORKER)
    "tests/test_compare_decides.py",
    "tests/test_forcing_stage.py",
    "tests/test_nodal_study.py",
    "tests/test_nodes.py",
    "tests/test_properties.py",
    "tests/test_friction_coulomb_study.py",
    "tests/test_calculix.py",
    "tests/test_rub_study.py",
    "tests/test_nonlinear_static.py",
    "tests/test_disk_rub_study.py",
    "tests/test_stress_limit.py",
    "tests/test_massless.py",
    "tests/test_forced_massless.py",
    "tests/test_tip_excursion.py",
    "tests/test_isoparametric.py",
    "tests/test_plots.py",
    "tests/test_rotation.py",
    "tests/test_hex_blade.py",
    "tests/test_validity.py",
    "tests/test_verdict.py",
    "tests/test_casing_sweep.py",
    "tests/test_reference.py",
    "tests/test_massless_casing.py",
    "tests/test_wear_in_flight.py",
    "tests/test_viz.py",  # with test_export.py (SAME_WORKER)
    "tests/test_nonlinear_static_reuse.py",
    "tests/test_failure_paths.py",
    "tests/test_mistuning_casing.py",
    "tests/test_cyclic_calculix.py",
]

#: The files that use ``dask_executor`` (one work unit of :data:`SAME_WORKER`) and the session's executor while it
#: exists.
DASK_FILES = ("tests/test_executor.py", "tests/test_comparison_study.py", "tests/test_mistuning_stats.py")
_DASK: list = []


#: The files that use the session's backbones of ``chain10`` and ``random_sys`` (about 0.9 s of CPU for both).
BACKBONE_FILES = ("tests/test_scan.py", "tests/test_orbits.py", "tests/test_simulate.py")


#: The files that read ``chain_families``.
SEARCH_FILES = ("tests/test_search_speed.py", "tests/test_kipp.py")


#: The files that read ``bar10_massless_mode``.
MASSLESS_MODE_FILES = ("tests/test_engineering_outputs.py", "tests/test_inputs_api.py", "tests/test_massless_phases.py",
                       "tests/test_review_fixes.py", "tests/test_verify_phased.py")


#: Files that fork scripts which mesh (:func:`fork_is_safe`), one work unit: the docs' run first (it meshes only in
#: its children), so that the README's Python still finds this process as collection left it.
PROCESS_CLEAN = ("tests/test_docs_run.py", "tests/test_readme.py")


#: Files that share session fixtures, each group one work unit (run one after the other on one worker, so the
#: fixture is computed once): the Dask cluster (``dask_executor``: each start spawns and imports two Dask workers,
#: seconds of CPU), the Fig. 8 example's computations (``fig8_example``), the backbones (:data:`BACKBONE_FILES`), the
#: P2 blade (``twisted_blade_p2``), the bar's massless mode (:data:`MASSLESS_MODE_FILES`) and the chains' nonsmooth
#: modes (:data:`SEARCH_FILES`); and the files that fork scripts which mesh (:data:`PROCESS_CLEAN`).
SAME_WORKER = [
    DASK_FILES,
    ("tests/test_examples.py", "tests/test_fig8.py"),
    PROCESS_CLEAN,
    BACKBONE_FILES,
    ("tests/test_viz.py", "tests/test_export.py"),
    MASSLESS_MODE_FILES,
    SEARCH_FILES,
]


#: The thread removing the previous sessions' temporary directories (:func:`pytest_configure`), if started.
_STALE_CLEANUP: list[threading.Thread] = []


@pytest.hookimpl(trylast=True)  # after pytest's tmp_path plugin has configured
def pytest_configure(config):
    """In the pytest-xdist controller of ``make test``: remove the previous sessions' ``tmp_path`` directories that
    pytest would remove at the end of this session (beyond ``tmp_path_retention_count``: each a past run's outputs,
    a full suite's about 150 MB in 3400 files) in a thread while the workers run the tests, instead of after them.
    Deleting is waiting on the disk, not CPU (measured: 10 s for one full run's folder on this machine's ext4 with
    ``discard``, 0.2 s of CPU), and at the end nothing else runs beside it.  The same candidates and the same lock
    rule as pytest's own clean-up (its functions), chosen before this session's directory exists; pytest's clean-up
    at the end still runs and finds them gone.  Not in a worker or a run without xdist (their processes fork)."""
    factory = getattr(config, "_tmp_path_factory", None)
    controller = not hasattr(config, "workerinput") and config.getoption("dist", "no") != "no"
    if (not controller or config.getoption("collectonly", False) or factory is None
            or getattr(factory, "_given_basetemp", None) is not None or getattr(factory, "_basetemp", None) is not None
            or getattr(factory, "_retention_policy", "none") == "none" or getattr(factory, "_retention_count", 0) < 1):
        return
    import tempfile
    import time

    try:  # pytest's own clean-up functions (private): without them, pytest's clean-up at the end alone
        from _pytest.pathlib import LOCK_TIMEOUT, cleanup_candidates, try_cleanup
        from _pytest.tmpdir import get_user
    except ImportError:
        return

    root = Path(os.environ.get("PYTEST_DEBUG_TEMPROOT") or tempfile.gettempdir()).resolve()
    root = root / f"pytest-of-{get_user() or 'unknown'}"
    if not root.is_dir():
        return
    # this session's directory (the next number) is not made yet: keep one fewer than pytest's count beside it
    stale = list(cleanup_candidates(root, "pytest-", factory._retention_count - 1))
    dead_before = time.time() - LOCK_TIMEOUT
    if stale:
        thread = threading.Thread(target=lambda: [try_cleanup(p, dead_before) for p in stale], daemon=True,
                                  name="stale tmp_path clean-up")
        thread.start()
        _STALE_CLEANUP.append(thread)


@pytest.hookimpl(tryfirst=True)  # before pytest's own clean-up of the numbered directories
def pytest_sessionfinish(session, exitstatus):
    """Wait for :func:`pytest_configure`'s clean-up (long done: it started with the session)."""
    for thread in _STALE_CLEANUP:
        thread.join()


def pytest_collection_finish(session):
    """Move what collection built (modules, test items, fixtures' definitions: most of a worker's objects, alive
    until the end) out of the cyclic garbage collector's reach: its full collections then walk only what the tests
    create (measured over the suite: about 3 s of full collections per worker, half that with the freeze)."""
    gc.collect()
    gc.freeze()
    _NATIVE_AT_START.append(_native_threads())


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
