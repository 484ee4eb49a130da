"""The value checks of the study schema (:mod:`bladecase.study.schema`): each takes a value of the right
type and returns ``None`` or the reason it is refused (the schema adds the key and the value), and the
ranges and caps they enforce (:data:`RANGES`, :data:`LIMITS`).

>>> _in_range("clearance")(1e300)
'must be in [1e-09, 10] (m)'
>>> _manifold_size([1000, 1000])
'must sample at most 100000 points (orbits × phases), asks for 1000000'
"""

from __future__ import annotations

import math
import re

from ..post.outputs import FORMATS as OUTPUT_FORMATS
from ..reduction import METHODS


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _positive(v) -> str | None:
    return None if math.isfinite(v) and v > 0 else "must be a finite number > 0"


def _int_at_least(n):
    return lambda v: None if v >= n else f"must be >= {n}"


#: Physical ranges (SI) of the study's scales.  Outside them the value is a unit mistake, and double
#: precision no longer delivers the stated tolerances (energies ``~ K d²`` overflow, eigen-solutions and
#: impact times lose their digits): ``[contact] clearance``, ``[material] E`` and ``rho``.
RANGES = {"clearance": (1e-9, 10.0, "m"), "E": (1e3, 1e13, "Pa"), "rho": (1e-2, 1e5, "kg/m³"),
          "casing_stiffness": (1e-3, 1e15, "N/m")}

#: Caps on the work a study may ask for (each is far above any useful value; beyond, a run would not end
#: or not fit in memory).
LIMITS = {"frames": 1000, "scan": 2000, "resolution": 1000, "max_points": 100_000, "fps": 1000, "frequencies": 100,
          "manifold_axis": 1000, "manifold_samples": 100_000, "period_multiple": 100, "grid_cells": 1_000_000,
          "models": 32, "forcing_points": 2000, "forcing_periods": 100_000, "engine_order": 1000}


def _in_range(name: str):
    lo, hi, unit = RANGES[name]
    return lambda v: None if math.isfinite(v) and lo <= v <= hi else f"must be in [{lo:g}, {hi:g}] ({unit})"


def _int_between(lo: int, hi: int, why: str = ""):
    return lambda v: None if lo <= v <= hi else f"must be an integer with {lo} <= value <= {hi}{why}"


def _one_of(*choices):
    return lambda v: None if v in choices else f"must be one of {', '.join(repr(c) for c in choices)}"


def _vector(v) -> str | None:
    if len(v) not in (2, 3) or not all(_num(x) and math.isfinite(x) for x in v):
        return "must be a list of 2 or 3 finite numbers"
    return None


def _direction(v) -> str | None:
    return _vector(v) or (None if any(x != 0 for x in v) else "must be a non-zero direction")


def _manifold_size(v) -> str | None:
    cap, total = LIMITS["manifold_axis"], LIMITS["manifold_samples"]
    if len(v) != 2 or not all(isinstance(x, int) and not isinstance(x, bool) and 2 <= x <= cap for x in v):
        return f"must be [orbits, phases], integers between 2 and {cap}"
    if v[0] * v[1] > total:
        return f"must sample at most {total} points (orbits × phases), asks for {v[0] * v[1]}"
    return None


def _period_unit(v) -> str | None:
    return None if v == "s" or re.fullmatch(r"T[1-9][0-9]*", v) else (
        "must be 's' (seconds) or 'T<j>' (the period of the j-th linear mode seen by the contact, e.g. 'T1')")


def _periods(v) -> str | None:
    if len(v) != 2 or not all(_num(x) and math.isfinite(x) for x in v) or not 0 < v[0] < v[1]:
        return "must be [lower, upper] with 0 < lower < upper"
    return None


def _ipp(v) -> str | None:
    if not v or not all(isinstance(k, int) and not isinstance(k, bool) and 1 <= k <= 8 for k in v):
        return "must be a non-empty list of integers between 1 and 8 (impacts per period)"
    if len(set(v)) != len(v):
        return "must not repeat a value"
    return None


def _formats(v) -> str | None:
    bad = [f for f in v if f not in OUTPUT_FORMATS]
    return f"unknown format(s) {bad} (valid: {', '.join(OUTPUT_FORMATS)})" if bad else None


def _window(v) -> str | None:
    if len(v) != 2 or not all(isinstance(x, int) and not isinstance(x, bool) and 64 <= x <= 4096 for x in v):
        return "must be [width, height] in pixels, integers between 64 and 4096"
    return None


def _scale(v) -> str | None:
    if v == "auto":
        return None
    if _num(v):
        return _positive(v)
    return "must be 'auto' or a number > 0"


def _reduction_list(v) -> str | None:
    for i, item in enumerate(v):
        if not isinstance(item, dict):
            return f"item {i} must be a table {{method = ..., size = ...}}"
        extra = set(item) - {"method", "size"}
        if extra:
            return f"item {i}: unknown key(s) {sorted(extra)} (valid: method, size)"
        if item.get("method") not in METHODS:
            return f"item {i}: method must be one of {', '.join(METHODS)}, got {item.get('method')!r}"
        size = item.get("size")
        if item["method"] != "full" and (not isinstance(size, int) or isinstance(size, bool) or size < 1):
            return f"item {i}: size must be an integer >= 1, got {size!r}"
    return None


def _method_names(v) -> str | None:
    bad = [m for m in v if m not in METHODS]
    if bad:
        return f"unknown method {bad[0]!r} (valid: {', '.join(METHODS)})"
    return None if len(set(v)) == len(v) else f"methods repeat: {v}"


def _size_list(v) -> str | None:
    bad = [x for x in v if not isinstance(x, int) or isinstance(x, bool) or x < 1]
    if bad:
        return f"sizes must be integers >= 1, got {bad[0]!r}"
    return None if len(set(v)) == len(v) else f"sizes repeat: {v}"


def _orbit_list(v) -> str | None:
    for i, item in enumerate(v):
        if not isinstance(item, dict) or set(item) - {"ipp", "T"} or not {"ipp", "T"} <= set(item):
            return f"item {i} must be a table {{ipp = K, T = period}} (T in search.period_unit)"
        if not isinstance(item["ipp"], int) or isinstance(item["ipp"], bool) or item["ipp"] < 1:
            return f"item {i}: ipp must be an integer >= 1, got {item['ipp']!r}"
        if not _num(item["T"]) or not math.isfinite(item["T"]) or item["T"] <= 0:
            return f"item {i}: T must be a number > 0, got {item['T']!r}"
    return None


def _rayleigh(v) -> str | None:
    if len(v) != 2 or not all(_num(x) and math.isfinite(x) and x >= 0 for x in v) or not any(v):
        return "must be [alpha, beta], two finite numbers >= 0, not both 0 (C = alpha K + beta M)"
    return None


def _nonzero(v) -> str | None:
    return None if math.isfinite(v) and v != 0 else "must be a finite number, not 0"


#: The coordinate rules of a clamp (:func:`bladecase.fe.select_nodes`); ``tol`` may go with any of them.
CLAMP_RULES = ("plane", "box", "sphere")


def _clamp_spec(v) -> str | None:
    """A group name, or a table with exactly one coordinate rule (its values are checked by ``select_nodes``)."""
    if isinstance(v, str):
        return None if v else "must be a mesh group name or a table such as {plane = [0, 0, 0, 0, 0, 1]}"
    rules = [k for k in v if k in CLAMP_RULES]
    unknown = sorted(set(v) - set(CLAMP_RULES) - {"tol"})
    if unknown or len(rules) != 1:
        return (f"must hold exactly one of {', '.join(CLAMP_RULES)} (and optionally tol)"
                + (f"; unknown keys {unknown}" if unknown else ""))
    return None


def _compare_periods(v) -> str | None:
    """1 to 8 distinct finite periods in (0, 100] (× the FE first period)."""
    if not 1 <= len(v) <= 8 or not all(_num(x) and math.isfinite(x) and 0 < x <= 100 for x in v):
        return "must be a list of 1 to 8 numbers in (0, 100] (× the FE model's first period)"
    if len(set(v)) != len(v):
        return "periods repeat"
    return None
