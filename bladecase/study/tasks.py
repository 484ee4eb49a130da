"""What every executor of :mod:`bladecase.study.executor` (and :mod:`~bladecase.study.dask_executor`) shares: the
workers' environment, a task run with its log transcript, a failing item named in the exception, the workers
argument checked."""

from __future__ import annotations

import os
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
    """A task run in a worker: ``(fn(item, **shared), the bladecase log lines it wrote)``.

    ``shared`` is one positional dict (never keywords of Dask's ``submit``, whatever its names)."""

    def __init__(self, fn: Callable[..., Any]):
        self.fn = fn

    def __call__(self, item: Any, shared: dict[str, Any]) -> tuple[Any, list[str]]:
        with log.transcript() as lines:
            out = self.fn(item, **shared)
        return out, lines


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
