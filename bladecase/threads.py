"""How many BLAS threads a stage may use when the machine's cores are shared.

OpenBLAS's threads wait for each other by spinning: when the cores are already busy with other work, a
multi-threaded BLAS call is slower than a single-threaded one, often by a factor of two.  Measured on two cores
loaded by other jobs (61 704-dof quadratic blade, 20 modes, block Lanczos with CHOLMOD): the eigen-solve took
11.9 s with two BLAS threads and 5.5 s with one; the factorisation 4.2 s and 4.9 s (threads help it a little even
then).  So the stages whose work is many small dense products and triangular solves — the eigen-solve — run on
one BLAS thread whenever the machine is busy, and keep the threads the environment gives them otherwise.

"Busy": the one-minute load average of the machine exceeds the cores this process may use less half a core
(:func:`machine_busy`).  ``BLADECASE_BLAS_THREADS`` overrides the choice: a positive integer (that many threads
in every stage) or ``auto`` (the default, as above).

>>> with blas_threads("eigen", busy=False) as n:   # an idle machine: the environment's threads, untouched
...     n is None
True
>>> with blas_threads("eigen", busy=True) as n:    # a busy one: one thread inside, restored after
...     n
1
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator

__all__ = ["SERIAL_WHEN_BUSY", "blas_threads", "machine_busy", "usable_cores"]

#: The stages that run on one BLAS thread when the machine is busy.
SERIAL_WHEN_BUSY = frozenset({"eigen"})


def usable_cores() -> int:
    """The cores this process may run on (its affinity mask where the platform has one).

    >>> usable_cores() >= 1
    True
    """
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def machine_busy(cores: int | None = None) -> bool:
    """Whether the one-minute load average exceeds ``cores`` (default :func:`usable_cores`) less half a core;
    ``False`` where the platform has no load average.

    >>> isinstance(machine_busy(), bool)
    True
    """
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return False
    return load > (usable_cores() if cores is None else cores) - 0.5


def _requested() -> int | None:
    """``BLADECASE_BLAS_THREADS`` as a positive integer, ``None`` for ``auto`` or unset; ``ValueError`` otherwise."""
    raw = os.environ.get("BLADECASE_BLAS_THREADS", "auto").strip().lower()
    if raw in ("", "auto"):
        return None
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"BLADECASE_BLAS_THREADS must be a positive integer or 'auto', got {raw!r}")
    return n


@contextlib.contextmanager
def blas_threads(stage: str, busy: bool | None = None) -> Iterator[int | None]:
    """Run the ``with`` block on the BLAS threads ``stage`` should use; yields the limit set, or ``None`` when the
    threads are left as they are.

    ``busy``: whether the machine is busy (default :func:`machine_busy`, measured now).  Without
    ``threadpoolctl`` (an optional import) nothing is limited.
    """
    limit = _requested()
    if limit is None and stage in SERIAL_WHEN_BUSY and (machine_busy() if busy is None else busy):
        limit = 1
    if limit is None:
        yield None
        return
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - a dependency; kept optional for embedded uses
        yield None
        return
    with threadpool_limits(limits=limit, user_api="blas"):
        yield limit
