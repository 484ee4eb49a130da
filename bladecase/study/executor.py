"""Where the independent tasks of a study run: one after the other in this process today.

A task is a plain function applied to each item (e.g. the nonsmooth-mode search of each model of a
comparison).  An executor maps it; the results come back in the order of the items.  A distributed
executor (Dask) is another class with the same ``map`` — the stages do not change.

>>> SerialExecutor().map(lambda x: x * x, [1, 2, 3])
[1, 4, 9]
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Protocol, TypeVar

from ..progress import progress_bar

A = TypeVar("A")
R = TypeVar("R")


class Executor(Protocol):
    """Maps a function over items and returns the results in the items' order."""

    def map(self, fn: Callable[[A], R], items: Iterable[A], *, desc: str = "", progress: bool = False) -> list[R]:
        ...


class SerialExecutor:
    """Every task in this process, one after the other (with a progress bar when ``progress``)."""

    name = "serial"

    def map(self, fn: Callable[[A], R], items: Iterable[A], *, desc: str = "tasks", progress: bool = False) -> list[R]:
        items = list(items)
        return [fn(x) for x in progress_bar(items, desc, enabled=progress and len(items) > 1, unit="task")]

    def __repr__(self) -> str:
        return "SerialExecutor()"
