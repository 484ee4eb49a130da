"""The study executors: serial, local processes and Dask give the same results for real bladecase tasks.

One 2-worker ``LocalCluster`` for the session (start-up takes seconds); each ``ProcessExecutor.map``
spawns its own pool, each process importing bladecase (seconds): 2 processes where results come back from
several, 1 for a log or an error.  Results are compared EXACTLY (tolerance 0): the same code on the same
inputs with one BLAS thread per worker gives the same floating-point numbers wherever it runs.
"""

from __future__ import annotations

import functools
import json
import os

import numpy as np
import pytest

from bladecase import log
from bladecase.nsm import Damping, chain, forced_point, forced_sweep, nonsmooth_mode
from bladecase.study.executor import (
    DaskExecutor,
    ProcessExecutor,
    SerialExecutor,
    keyword_task,
    make_executor,
)

TWO_DOF = chain(2, k=1.0, m=0.5, gap=1.0)
FORCING = {"damping": Damping(alpha=0.05), "amplitude": 0.6, "n_periods": 150}
PERIODS = [5.1, 4.5, 4.2, 4.8]  # not sorted: the order of the items is the order of the results


@pytest.fixture(params=["processes", "dask"])
def parallel(request):
    if request.param == "processes":
        return ProcessExecutor(2)
    return request.getfixturevalue("dask_executor")


def _point_record(p) -> tuple:
    return (p.T, p.label, p.periodic, p.energy, p.mean_energy, p.residual, p.impact_phases.tolist(),
            p.impulses.tolist(), p.x_end.tolist(), p.v_end.tolist())


@pytest.fixture(scope="module")
def serial_points():
    pts = SerialExecutor().map(keyword_task(forced_point, "T"), PERIODS, shared={"system": TWO_DOF, **FORCING})
    direct = [forced_point(TWO_DOF, T, **FORCING) for T in PERIODS]
    assert [_point_record(p) for p in pts] == [_point_record(p) for p in direct]
    assert [p.T for p in pts] == PERIODS
    assert pts[1].label == "1/1" and abs(pts[1].energy - 7.890714) < 1e-6  # the forced_point doctest's orbit
    return pts


def test_forced_points_identical(parallel, serial_points):
    """The same forced-response points (shared system sent once), in the items' order, bit for bit."""
    pts = parallel.map(keyword_task(forced_point, "T"), PERIODS, shared={"system": TWO_DOF, **FORCING},
                       desc="forced", progress=False)
    assert [p.T for p in pts] == PERIODS
    assert [_point_record(p) for p in pts] == [_point_record(p) for p in serial_points]


def test_forced_sweep_through_executor(dask_executor, serial_points):
    """forced_sweep(continuation=False) maps a functools.partial through any executor: the same points."""
    pts = forced_sweep(TWO_DOF, PERIODS, continuation=False, executor=dask_executor, **FORCING)
    by_T = {p.T: _point_record(p) for p in serial_points}
    assert [p.T for p in pts] == sorted(PERIODS, reverse=True)  # direction "up": decreasing T
    assert [_point_record(p) for p in pts] == [by_T[p.T] for p in pts]


def _families(branches, system) -> list[str]:
    return [json.dumps(b.bind(system).to_dict(), sort_keys=True) for b in branches]


def test_nonsmooth_modes_identical(dask_executor):
    """2-ipp nonsmooth modes of chains of two sizes: the same families and orbits; light records come back."""
    systems = [chain(2, k=1.0, m=1.0, gap=1.0), chain(3, k=1.0, m=1.0, gap=1.0)]
    task = functools.partial(nonsmooth_mode, k=2, T_range=(2.0, 12.0), scan=6)
    serial = SerialExecutor().map(task, systems)
    remote = dask_executor.map(task, systems, desc="models")
    assert [len(f) for f in serial] == [3, 2]
    assert all(b.system is None for fams in remote for b in fams)  # orbits pickle without their system
    for s, a, b in zip(systems, serial, remote):
        assert _families(b, s) == _families(a, s)
        for fa, fb in zip(a, b):
            T_a = np.array([o.T for o in fa.orbits if o is not None])
            T_b = np.array([o.T for o in fb.bind(s).orbits if o is not None])
            np.testing.assert_array_equal(T_b, T_a)


@pytest.mark.parametrize("kind", ["serial", "processes", "dask"])
def test_exception_names_item(kind, request):
    """A task's exception comes back with its type and the failing item named (message and note)."""
    # one local process: the failing item is named the same, and each spawned process costs seconds
    ex = request.getfixturevalue("dask_executor") if kind == "dask" else make_executor(kind, workers=1 if
                                                                                      kind != "serial" else None)
    with pytest.raises(ValueError, match=r"^forced 1 \(item -1\.0\): forcing period T must be finite and > 0") as e:
        ex.map(keyword_task(forced_point, "T"), [4.5, -1.0], shared={"system": TWO_DOF, "n_periods": 20},
               desc="forced")
    assert e.value.__notes__ == ["raised by forced 1 (item -1.0)"]


def _hello(message: str) -> tuple[str | None, str | None]:
    """A remote task: logs ``message`` through bladecase and answers its process's BLAS thread settings."""
    log.info(message)
    return os.getenv("OPENBLAS_NUM_THREADS"), os.getenv("OMP_NUM_THREADS")


def test_worker_logs_and_environment(parallel, monkeypatch):
    """bladecase log messages of remote tasks reach the caller's transcript; workers have one BLAS thread.

    One map does both, every task logs and reports its environment; local processes: one spawned process runs
    both tasks (each process spawned imports bladecase, seconds; the environment is set before any is spawned)."""
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    ex = ProcessExecutor(1) if isinstance(parallel, ProcessExecutor) else parallel
    with log.transcript() as lines:
        out = ex.map(_hello, ["first task says hello", "second task says hello"])
    said = [line for line in lines if " done (item " not in line]  # the tasks' own lines, relayed
    assert sorted(line.split(" ", 3)[3] for line in said) == ["first task says hello", "second task says hello"]
    assert all(line.split(" ", 3)[2] == "INFO" for line in lines)
    assert sum(" done (item " in line for line in lines) == 2  # and one line per finished task, with its time
    assert out == [("1", "1"), ("1", "1")]
    assert "OPENBLAS_NUM_THREADS" not in os.environ  # the caller's environment is left as it was


def test_existing_scheduler_by_address(dask_executor):
    """An executor on an existing scheduler's address maps the same; closing it leaves the cluster running."""
    address = dask_executor.client.scheduler.address
    with DaskExecutor(address) as ex:
        assert ex.map(abs, [-3, 2, -1]) == [3, 2, 1]
        assert len(ex.client.nthreads()) == 2
    assert ex._client is None
    assert dask_executor.map(abs, [-5]) == [5]  # the cluster still serves


def test_empty_items():
    for ex in (SerialExecutor(), ProcessExecutor(2), DaskExecutor(workers=2)):
        assert ex.map(abs, []) == []
        ex.close()


def test_make_executor_kinds():
    assert isinstance(make_executor(), SerialExecutor)
    assert isinstance(make_executor(workers=1), SerialExecutor)
    assert isinstance(make_executor("processes"), ProcessExecutor)
    local = make_executor(workers=2)
    assert isinstance(local, DaskExecutor) and local.scheduler is None and local.workers == 2
    remote = make_executor(scheduler="tcp://10.1.2.3:8786")
    assert isinstance(remote, DaskExecutor) and remote.scheduler == "tcp://10.1.2.3:8786"
    assert remote._client is None  # nothing is started or connected before the first map


@pytest.mark.parametrize("call, match", [
    (lambda: make_executor("threads"), "executor kind 'threads' is not known; valid: 'serial', 'processes', 'dask'"),
    (lambda: make_executor("serial", workers=4), "serial executor runs 1 worker, got workers=4"),
    (lambda: make_executor("processes", scheduler="tcp://h:8786"), "needs the 'dask' executor, not 'processes'"),
    (lambda: make_executor("dask", workers=0), "workers must be a positive integer"),
    (lambda: ProcessExecutor(2.5), "workers must be a positive integer .* got 2.5"),
    (lambda: DaskExecutor(workers=True), "workers must be a positive integer .* got True"),
    (lambda: DaskExecutor("tcp://h:8786", workers=2), "apply to a local cluster only"),
    (lambda: DaskExecutor("  "), "scheduler address is empty"),
    (lambda: DaskExecutor(timeout=0), "timeout must be > 0"),
    (lambda: keyword_task(forced_point, "not a name"), "name must be a parameter name"),
    (lambda: keyword_task(3, "T"), "fn must be callable"),
])
def test_bad_arguments_refused(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_shared_names_are_not_dask_options(dask_executor):
    """Shared arguments named like Client.submit's own options (key, workers, pure) reach the task."""
    shared = {"key": 3, "workers": [4], "pure": "no"}
    expect = [dict(a=1, **shared), dict(a=2, **shared)]
    assert SerialExecutor().map(keyword_task(dict, "a"), [1, 2], shared=shared) == expect
    assert dask_executor.map(keyword_task(dict, "a"), [1, 2], shared=shared) == expect


def test_existing_cluster_with_another_bladecase_refused(dask_executor, monkeypatch):
    """Workers of an existing cluster must run the caller's bladecase version: else RuntimeError naming it."""
    import bladecase

    address = dask_executor.client.scheduler.address
    monkeypatch.setattr(bladecase, "__version__", "0.0.0-other")
    ex = DaskExecutor(address)
    with pytest.raises(RuntimeError, match=r"must run bladecase 0\.0\.0-other .*: tcp://.* has "):
        ex.map(abs, [1])
    assert ex._client is None  # the connection was closed
