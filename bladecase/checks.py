"""Shared argument validators: each returns the value converted, or raises ``ValueError`` naming it.

The messages say what was given and what is valid, e.g. ``"gap must be a finite clearance > 0, got -1"``.
Booleans are never accepted as numbers (``True`` is not a length).

>>> positive("thickness", "0.002")
0.002
>>> positive("thickness", -1)
Traceback (most recent call last):
    ...
ValueError: thickness must be a finite number > 0, got -1
>>> integer("steps", 5, 1, 10)
5
>>> integer("count", 10, 1, 10, strict_high=True, note=" (the number of free dofs)")
Traceback (most recent call last):
    ...
ValueError: count must be an integer with 1 <= count < 10 (the number of free dofs), got 10

Matrices (dense or scipy sparse, never made dense): :func:`numbers` (a numeric dtype) and :func:`symmetric`
(to :data:`SYMMETRY_RTOL`); positive definiteness is proved by a factorisation,
:func:`bladecase.linalg.positive_definite` (singular to working precision below :data:`SINGULAR_RTOL`).

>>> symmetric("K", np.array([[2.0, 1.0], [0.0, 2.0]]))
Traceback (most recent call last):
    ...
ValueError: K is not symmetric: max|K - Kᵀ| = 1 exceeds 1e-10 * max|K| = 2e-10
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["SINGULAR_RTOL", "SYMMETRY_RTOL", "finite", "integer", "is_integer", "numbers", "one_of", "point",
           "positive", "symmetric"]

#: Relative tolerance of :func:`symmetric`: ``max|A - Aᵀ| <= SYMMETRY_RTOL * max|A|`` (assembled FE matrices and
#: ``VᵀKV`` products are symmetric to ~1e-15 of ``max|A|``).
SYMMETRY_RTOL = 1e-10

#: :func:`bladecase.linalg.positive_definite` refuses a matrix whose smallest factorisation pivot is
#: ``<= SINGULAR_RTOL`` times its largest diagonal entry: its smallest eigenvalue is at most that pivot, so it is
#: singular to working precision (a free–free chain factorises with a last pivot of ~1e-16 to 1e-15 of the diagonal
#: instead of 0, by round-off), and the lowest eigenvalue would have no correct digit.  Physical models stay far
#: above: a clamped chain of ``n`` unit springs has ``1/n``, a clamped FE model ~1e-8 or more.
SINGULAR_RTOL = 1e-12


def positive(name: str, value, what: str = "> 0", noun: str = "number", allow_none: bool = False) -> float | None:
    """``float(value)`` if it is a finite number > 0 (``None`` passes if ``allow_none``).

    Errors: ``"<name> must be a number <what>, got …"`` for a non-number,
    ``"<name> must be a finite <noun> <what>, got …"`` otherwise.
    """
    if value is None and allow_none:
        return None
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number {what}, got {value!r}") from None
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be a finite {noun} {what}, got {value!r}")
    return x


def finite(name: str, value) -> float:
    """``float(value)`` if it is a finite number, else ``ValueError``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(x):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return x


def is_integer(value) -> bool:
    """True for Python and numpy integers, False for booleans and everything else."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def integer(
    name: str, value, low: int | None = None, high: int | None = None, *, strict_high: bool = False, note: str = ""
) -> int:
    """``int(value)`` if it is an integer in ``[low, high]`` (``[low, high)`` if ``strict_high``).

    ``note`` is appended to the range in the message, e.g. ``" (the number of dofs)"``.
    """
    if high is not None:
        above = high - 1 if strict_high else high
        valid = f"with {low} <= {name} {'<' if strict_high else '<='} {high}" if low is not None else (
            f"<= {above}")
    else:
        above = None
        valid = f">= {low}" if low is not None else ""
    ok = is_integer(value) and (low is None or value >= low) and (above is None or value <= above)
    if not ok:
        raise ValueError(f"{name} must be an integer{' ' + valid if valid else ''}{note}, got {value!r}")
    return int(value)


def one_of(name: str, value, choices: Sequence):
    """``value`` if it is one of ``choices`` (booleans never match numbers), else ``ValueError`` listing them."""
    if isinstance(value, (bool, np.bool_)) or value not in tuple(choices):
        raise ValueError(f"{name} must be one of {tuple(choices)}, got {value!r}")
    return value


def point(name: str, value, sizes: Sequence[int]) -> tuple[float, ...]:
    """``value`` as a tuple of finite floats with one of ``sizes`` components."""
    counts = " or ".join(map(str, sizes))
    try:
        p = tuple(float(c) for c in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a sequence of {counts} numbers, got {value!r}") from None
    if len(p) not in sizes or not all(math.isfinite(c) for c in p):
        raise ValueError(f"{name} must be {counts} finite coordinates, got {value!r}")
    return p


def numbers(name: str, a, complex_ok: bool = False) -> None:
    """``ValueError`` unless the array ``a`` (dense or sparse) holds numbers: integers or reals (complex if
    ``complex_ok``); booleans, strings, dates and records are refused, naming the dtype."""
    dtype = np.dtype(getattr(a, "dtype", np.asarray(a).dtype))
    ok = "iuf" + ("c" if complex_ok else "")
    if dtype.kind in ok or dtype.kind == "O":  # objects: the float conversion that follows says what is wrong
        return
    what = {"b": "booleans", "U": "text", "S": "bytes", "M": "dates", "m": "time spans",
            "V": "records (a structured array)", "c": "complex numbers"}.get(dtype.kind, "no numbers")
    raise ValueError(f"{name} must hold {'real ' if not complex_ok else ''}numbers, got {what} (dtype {dtype})")


def _max_abs(a) -> float:
    if hasattr(a, "nnz"):  # scipy sparse, whatever its format (a dia array has no max: its stored values)
        return float(np.abs(a.tocoo().data).max(initial=0.0))
    return float(np.abs(a).max()) if a.size else 0.0


def symmetric(name: str, a, rtol: float = SYMMETRY_RTOL) -> None:
    """``ValueError`` unless the finite square matrix ``a`` (dense or sparse) is symmetric:
    ``max|a - aᵀ| <= rtol * max|a|``.  A sparse ``a`` stays sparse (O(nnz))."""
    scale = _max_abs(a)
    asym = _max_abs(a - a.T)
    if asym > rtol * scale:
        raise ValueError(f"{name} is not symmetric: max|{name} - {name}ᵀ| = {asym:.3g} exceeds "
                         f"{rtol:g} * max|{name}| = {rtol * scale:.3g}")
