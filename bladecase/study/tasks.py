"""What every executor of :mod:`bladecase.study.executor` (and :mod:`~bladecase.study.dask_executor`) shares: the
workers' environment, a task run with its log transcript, a failing item named in the exception, the workers
argument checked."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

from .. import log

A = TypeVar("A")
R = TypeVar("R")

#: The environment of every worker: one BLAS/OpenMP thread each (the tasks are the parallelism).
WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def label(item: Any, width: int = 60) -> str:
    text = repr(item)
    return text if len(text) <= width else text[: width - 3] + "..."


def named(exc: BaseException, desc: str, index: int, item: Any) -> BaseException:
    """``exc`` (same object, same type) with the failing item in its message and as a note."""
    where = f"{desc or 'task'} {index} (item {label(item)})"
    if exc.args and isinstance(exc.args[0], str) and not exc.args[0].startswith(where):
        exc.args = (f"{where}: {exc.args[0]}", *exc.args[1:])
    exc.add_note(f"raised by {where}")
    return exc


class Logged:
    """A task run in a worker: ``(fn(item, **shared), the bladecase log lines it wrote, its wall time in s)``.

    ``shared`` is one positional dict (never keywords of Dask's ``submit``, whatever its names)."""

    def __init__(self, fn: Callable[..., Any]):
        self.fn = fn

    def __call__(self, item: Any, shared: dict[str, Any]) -> tuple[Any, list[str], float]:
        start = time.perf_counter()
        with log.transcript() as lines:
            out = self.fn(item, **shared)
        return out, lines, time.perf_counter() - start


#: A map of at most this many items logs every item; a longer one about a hundred of them, evenly spread.
LOG_EVERY_ITEM = 200


class ItemLog:
    """One INFO line per finished item of a map, with its wall time — what a long sweep run without a progress bar
    (``--no-progress``, a batch job) tells as it goes: ``"rub speeds 3/50 done (item 1650.0): 12.3 s"``. A map of
    one item says nothing (its stage's own line does); a map of more than :data:`LOG_EVERY_ITEM` items logs about a
    hundred lines, and the last.

    >>> progress = ItemLog("speeds", 3)
    >>> progress(1450.0, 2.5)
    >>> progress.done
    1
    """

    def __init__(self, desc: str, n: int):
        self.desc, self.n, self.done = desc or "tasks", n, 0
        self.step = 1 if n <= LOG_EVERY_ITEM else -(-n // 100)

    def __call__(self, item: Any, seconds: float) -> None:
        self.done += 1
        if self.n > 1 and (self.done % self.step == 0 or self.done == self.n):
            log.info("%s %d/%d done (item %s): %.3g s", self.desc, self.done, self.n, label(item), seconds)


def relay(lines: list[str]) -> None:
    """Re-log a worker's transcript lines (``date time LEVEL message``) in this process."""
    for line in lines:
        parts = line.split(" ", 3)
        level, msg = (parts[2], parts[3]) if len(parts) == 4 else ("INFO", line)
        (log.warning if level in ("WARNING", "ERROR", "CRITICAL") else log.info)("%s", msg)


def check_workers(workers: int | None, what: str) -> int | None:
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"{what}: workers must be a positive integer (or None for one per core), got {workers!r}")
    return workers


@contextmanager
def environ_kept() -> Iterator[None]:
    """``os.environ`` as it was before the block, whatever the block set."""
    saved = dict(os.environ)
    try:
        yield
    finally:
        for k in set(os.environ) - set(saved):
            del os.environ[k]
        os.environ.update(saved)
