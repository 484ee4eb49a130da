"""Where the independent tasks of a study run: here one after the other, in local processes, or on Dask.

A task is a plain function applied to each item (the nonsmooth-mode search of each model of a
comparison, the forced response at each period of a sweep).  An executor maps it; the results come back
in the order of the items, whichever executor ran them — the stages do not change:

* :class:`SerialExecutor` — every task in this process, one after the other;
* :class:`ProcessExecutor` — a pool of local processes (``concurrent.futures``, spawned, so safe on every
  platform and with every BLAS);
* :class:`~bladecase.study.dask_executor.DaskExecutor` — a ``dask.distributed`` cluster: a ``LocalCluster`` it
  starts (and closes), or an existing scheduler by address (``tcp://host:8786``) or ``Client``.

All three take the same call ``map(fn, items, *, shared=None, desc=, progress=)``: ``fn(item, **shared)``
for each item.  ``shared`` holds the big arguments common to every task (a system's matrices, a study):
they are sent to each worker once (a Dask ``scatter(..., broadcast=True)``; a process pool's initializer),
not once per task.  :func:`keyword_task` maps a library function over any one of its keyword parameters.

A task's exception is re-raised in the caller with its type kept and the failing item named in its
message.  The ``bladecase`` log messages of a task run elsewhere are relayed into the caller's log (and so
into a run's ``run.log``) when the task returns.  Workers run single-threaded BLAS
(``OPENBLAS_NUM_THREADS=1`` and the like): the parallelism is across tasks.

>>> SerialExecutor().map(lambda x: x * x, [1, 2, 3])
[1, 4, 9]
>>> SerialExecutor().map(lambda x, scale: scale * x, [1, 2], shared={"scale": 10})
[10, 20]
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Protocol

from ..progress import progress_bar, progress_counter
from .tasks import WORKER_ENV, A, ItemLog, R  # noqa: F401  (WORKER_ENV: public name of this module)
from .tasks import Logged as _Logged
from .tasks import check_workers as _check_workers
from .tasks import environ_kept as _environ_kept  # noqa: F401  (the former home of these names)
from .tasks import label as _label  # noqa: F401
from .tasks import named as _named
from .tasks import relay as _relay

__all__ = ["EXECUTOR_KINDS", "Executor", "KeywordTask", "ProcessExecutor", "SerialExecutor",
           "keyword_task", "make_executor"]

#: The kinds :func:`make_executor` accepts.
EXECUTOR_KINDS = ("serial", "processes", "dask")

class Executor(Protocol):
    """Maps a function over items and returns the results in the items' order."""

    name: str

    def map(self, fn: Callable[..., R], items: Iterable[A], *, shared: dict[str, Any] | None = None,
            desc: str = "tasks", progress: bool = False) -> list[R]:
        ...


@dataclass(frozen=True)
class KeywordTask:
    """``fn`` with each item passed as its keyword argument ``name`` (see :func:`keyword_task`)."""

    fn: Callable[..., Any]
    name: str

    def __call__(self, item: Any, **kwargs: Any) -> Any:
        return self.fn(**{self.name: item}, **kwargs)


def keyword_task(fn: Callable[..., R], name: str) -> KeywordTask:
    """A task that calls ``fn(name=item, **shared)``: any parameter of a library function as the mapped one.

    With the big arguments in ``shared`` (sent to each worker once), e.g. a forced sweep's system:

    >>> from bladecase.nsm import chain, forced_point
    >>> task = keyword_task(forced_point, "T")
    >>> pts = SerialExecutor().map(task, [4.5, 4.6], shared={"system": chain(2, k=1.0, m=0.5, gap=1.0),
    ...                                                      "amplitude": 0.6, "n_periods": 40})
    >>> [p.T for p in pts]
    [4.5, 4.6]
    """
    if not callable(fn):
        raise ValueError(f"keyword_task: fn must be callable, got {fn!r}")
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"keyword_task: name must be a parameter name (an identifier), got {name!r}")
    return KeywordTask(fn, name)


class SerialExecutor:
    """Every task in this process, one after the other (with a progress bar when ``progress``)."""

    name = "serial"

    def map(self, fn: Callable[..., R], items: Iterable[A], *, shared: dict[str, Any] | None = None,
            desc: str = "tasks", progress: bool = False) -> list[R]:
        items = list(items)
        kwargs = dict(shared or {})
        out = []
        done = ItemLog(desc, len(items))
        for i, x in enumerate(progress_bar(items, desc, enabled=progress and len(items) > 1, unit="task")):
            start = time.perf_counter()
            try:
                out.append(fn(x, **kwargs))
            except Exception as exc:
                raise _named(exc, desc, i, x) from None
            done(x, time.perf_counter() - start)
        return out

    def close(self) -> None:
        """Nothing to release (same interface as the parallel executors)."""

    def __enter__(self) -> SerialExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return "SerialExecutor()"


@contextmanager
def _worker_env() -> Iterator[None]:
    """:data:`WORKER_ENV` in ``os.environ`` (where not set) while worker processes are spawned."""
    added = {k: v for k, v in WORKER_ENV.items() if k not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for k in added:
            os.environ.pop(k, None)


_SHARED: dict[str, Any] = {}


def _install_shared(shared: dict[str, Any]) -> None:
    """Process-pool initializer: keep the shared arguments in this worker."""
    _SHARED.clear()
    _SHARED.update(shared)


def _run_with_shared(task: _Logged, item: Any) -> tuple[Any, list[str], float]:
    return task(item, _SHARED)


class ProcessExecutor:
    """Tasks in a pool of ``workers`` local processes (default: one per core), started for each ``map``.

    The processes are spawned (not forked): ``fn``, the items and ``shared`` must pickle (module-level
    functions, ``functools.partial`` of them, :func:`keyword_task`; not lambdas).  ``shared`` goes to each
    process once; each process has one BLAS thread.  The pool lives for one ``map`` call.

    >>> ProcessExecutor(2)
    ProcessExecutor(workers=2)
    """

    name = "processes"

    def __init__(self, workers: int | None = None):
        self.workers = _check_workers(workers, "ProcessExecutor")

    def map(self, fn: Callable[..., R], items: Iterable[A], *, shared: dict[str, Any] | None = None,
            desc: str = "tasks", progress: bool = False) -> list[R]:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed

        items = list(items)
        if not items:
            return []
        n = min(self.workers or os.cpu_count() or 1, len(items))
        task = _Logged(fn)
        pool = ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=_install_shared, initargs=(dict(shared or {}),))
        results: list[Any] = [None] * len(items)
        done = ItemLog(desc, len(items))
        try:
            with _worker_env():  # the workers are spawned as tasks are submitted
                index = {pool.submit(_run_with_shared, task, x): i for i, x in enumerate(items)}
            with progress_counter(len(items), desc, enabled=progress and len(items) > 1, unit="task") as bar:
                bar.set_postfix_str(f"{n} processes")
                for fut in as_completed(index):
                    i = index[fut]
                    try:
                        results[i], lines, seconds = fut.result()
                    except Exception as exc:
                        pool.shutdown(wait=False, cancel_futures=True)
                        raise _named(exc, desc, i, items[i]) from None
                    _relay(lines)
                    done(items[i], seconds)
                    bar.update()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        return results

    def close(self) -> None:
        """Nothing to release: each ``map`` closes its own pool."""

    def __enter__(self) -> ProcessExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"ProcessExecutor(workers={self.workers})"


def __getattr__(name: str):
    """:class:`~bladecase.study.dask_executor.DaskExecutor` and its names, imported when first asked for
    (``distributed`` is loaded only by the studies that use Dask)."""
    if name in ("DaskExecutor", "HOST_PORT_SCHEMES"):
        from . import dask_executor

        return getattr(dask_executor, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def make_executor(kind: str | None = None, workers: int | None = None, scheduler: Any = None) -> Executor:
    """The executor of ``kind`` (``"serial"``, ``"processes"``, ``"dask"``).

    ``kind=None`` picks from the other arguments: a ``scheduler`` → Dask on that cluster; ``workers > 1``
    → Dask on a ``LocalCluster`` of that many workers; otherwise serial.  ``workers`` is the number of local
    processes (``None``: one per core), ``scheduler`` an existing Dask scheduler (``"tcp://host:8786"``).

    >>> make_executor(), make_executor("processes", workers=2), make_executor(workers=4)
    (SerialExecutor(), ProcessExecutor(workers=2), DaskExecutor(local cluster, workers=4))
    >>> make_executor(scheduler="tcp://10.0.0.5:8786")
    DaskExecutor('tcp://10.0.0.5:8786')
    >>> make_executor("threads")
    Traceback (most recent call last):
    ...
    ValueError: executor kind 'threads' is not known; valid: 'serial', 'processes', 'dask'
    """
    if kind is None:
        kind = "dask" if scheduler is not None or (workers is not None and workers != 1) else "serial"
    if kind not in EXECUTOR_KINDS:
        raise ValueError(f"executor kind {kind!r} is not known; valid: {', '.join(map(repr, EXECUTOR_KINDS))}")
    _check_workers(workers, f"{kind} executor")
    if scheduler is not None and kind != "dask":
        raise ValueError(f"a scheduler ({scheduler!r}) needs the 'dask' executor, not {kind!r}")
    if kind == "serial":
        if workers not in (None, 1):
            raise ValueError(f"the serial executor runs 1 worker, got workers={workers!r}; valid: 'processes' or "
                             "'dask' for more")
        return SerialExecutor()
    if kind == "processes":
        return ProcessExecutor(workers)
    from .dask_executor import DaskExecutor

    return DaskExecutor(scheduler, workers)
