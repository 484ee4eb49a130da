"""The building blocks of the study schema: :class:`Key` (one key: types, default, meaning, check),
:class:`StudyError` and the accepted type tuples.  The sections live in :mod:`bladecase.study.schema`
(and :mod:`bladecase.study.sections`); a value is checked against its key by ``_check_value`` (a ``[geometry]`` field
against its dataclass by ``_check_field``), with messages that say what was given and what is valid."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from .values import show

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


# ----------------------------------------------------------------------------- a value checked against its Key


def _type_name(types: tuple) -> str:
    names = {str: "a string", int: "an integer", float: "a number", bool: "true/false", list: "a list",
             dict: "a table"}
    if types == _NUM:
        return "a number"
    return " or ".join(names[t] for t in types)


def _integer_hint(value) -> str:
    """What to write instead of the float ``value`` where an integer is expected (TOML reads ``1e9`` and ``2.0`` as
    floats), for the message: ``" (TOML reads … as a float: write 1000000000)"``, or ``""``."""
    if not (isinstance(value, float) and math.isfinite(value) and value.is_integer()):
        return ""
    write = f": write {int(value)}" if abs(value) < 2**63 else ""
    return f" (TOML reads a number with an exponent or a decimal point as a float{write})"


def _shown_number(value) -> str:
    """A float for a message: ``1e+09`` rather than ``1000000000.0``, ``2.0`` as it is."""
    text = f"{value:g}" if isinstance(value, float) else ""
    return text if "e" in text else show(value)


def _quoted(value) -> str:
    """``repr(value)``, cut for a message (a huge list or string is not copied into it)."""
    text = show(value)
    return text.removeprefix("the string ").removeprefix("a list ").removeprefix("a table ").removeprefix(
        "the boolean ")


def _check_value(section: str, key: str, spec: Key, value) -> Any:
    where = f"[{section}] {key}"
    ok = any(isinstance(value, t) and not (t in (int, float) and isinstance(value, bool)) for t in spec.types)
    if not ok:
        hint = _integer_hint(value) if spec.types == _INT else ""
        raise StudyError(f"{where}: expected {_type_name(spec.types)}, got "
                         f"{_shown_number(value) if hint else show(value)}{hint}")
    if isinstance(value, float) and not math.isfinite(value):
        raise StudyError(f"{where}: must be finite, got {value!r}")
    if spec.check is not None:
        try:
            message = spec.check(value)
        except (TypeError, ValueError, OverflowError, RecursionError):  # an odd item inside a list or table
            message = "has an item of the wrong type or size"
        if message:  # a message that names the offending item already says what it got
            raise StudyError(f"{where}: {message}" + ("" if "got " in message else f", got {_quoted(value)}"))
    return value


def _field_kind(cls, name: str) -> str | None:
    """What a geometry dataclass field takes, from its annotation: ``"number"``, ``"integer"``, ``"string"`` or
    ``"numbers"`` (a point); ``None``: left to the dataclass."""
    annotation = str(next(f.type for f in dataclasses.fields(cls) if f.name == name))
    base = annotation.replace(" ", "").split("|")
    if any(b.startswith(("tuple", "list", "Sequence")) for b in base):
        return "numbers"
    for kind, word in (("integer", "int"), ("number", "float"), ("string", "str")):
        if word in base:
            return kind
    return None


def _check_field(kind: str, cls, key: str, value) -> None:
    """The type of a ``[geometry]`` field of the dataclass ``cls``, before the dataclass sees it (it would turn
    the string ``"0.1"`` into a number)."""
    where = f"[geometry] {key}"
    want = _field_kind(cls, key)
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if want == "integer" and not (number and isinstance(value, int)):
        hint = _integer_hint(value)
        raise StudyError(f"{where}: expected an integer, got {_shown_number(value) if hint else show(value)}{hint}")
    if want == "number" and not number:
        raise StudyError(f"{where}: expected a number, got {show(value)}")
    if want == "string" and not isinstance(value, str):
        raise StudyError(f"{where}: expected a string, got {show(value)}")
    if want == "numbers" and not (isinstance(value, list) and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)):
        raise StudyError(f"{where}: expected a list of numbers, got {show(value)}")
    items = value if isinstance(value, list) else [value]
    if any(isinstance(x, float) and not math.isfinite(x) for x in items):
        raise StudyError(f"{where}: must be finite, got {_quoted(value)}")
