"""The building blocks of the study schema: :class:`Key` (one key: types, default, meaning, check),
:class:`StudyError` and the accepted type tuples.  The sections live in :mod:`bladecase.study.schema`
(and :mod:`bladecase.study.sections`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

REQUIRED = object()  #: marks a key without a default


class StudyError(ValueError):
    """A study file that cannot be run: the message names the key and the reason."""

    __module__ = "bladecase.study.schema"  # its public home (re-exported there)


@dataclass(frozen=True)
class Key:
    """One study-file key: accepted types, default, and a one-line meaning."""

    types: tuple
    default: Any
    doc: str
    check: Any = None  # callable(value) -> str | None (an error message)


_STR, _INT, _NUM, _BOOL, _LIST = (str,), (int,), (int, float), (bool,), (list,)


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (its lines joined with ``; ``)."""
    return "; ".join(line.strip() for line in str(exc).splitlines() if line.strip())
