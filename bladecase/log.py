"""The run's messages: to the ``bladecase`` logger, and into the run's own transcript (``run.log``).

The library never adds, removes or reconfigures a logging handler, nor changes a logger's level: the
command line (or the user's application) decides what is shown.  A run records its messages itself, in
a :func:`transcript`, and writes them to ``run.log`` whatever the logging configuration.

>>> with transcript() as lines:
...     info("mesh: %d nodes", 1929)
>>> lines[0].split(" ", 2)[2]
'INFO mesh: 1929 nodes'
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

logger = logging.getLogger("bladecase")

_lines: ContextVar[list[str] | None] = ContextVar("bladecase_transcript", default=None)


def _note(level: int, msg: str, *args) -> None:
    logger.log(level, msg, *args)
    lines = _lines.get()
    if lines is not None:
        stamp = time.strftime("%Y-%m-%d %H:%M:%S")
        lines.append(f"{stamp} {logging.getLevelName(level)} {msg % args if args else msg}")


def info(msg: str, *args) -> None:
    """An informative message (``msg % args``)."""
    _note(logging.INFO, msg, *args)


def warning(msg: str, *args) -> None:
    """A warning: something a person should read (a doubtful result, a skipped output)."""
    _note(logging.WARNING, msg, *args)


@contextmanager
def transcript() -> Iterator[list[str]]:
    """Record every message of this context (this thread or task) into the yielded list of lines."""
    lines: list[str] = []
    token = _lines.set(lines)
    try:
        yield lines
    finally:
        _lines.reset(token)
