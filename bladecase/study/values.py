"""The value checks of the study schema (:mod:`bladecase.study.schema`): each takes a value of the right
type and returns ``None`` or the reason it is refused (the schema adds the key and the value), and the
ranges and caps they enforce (:data:`RANGES`, :data:`LIMITS`).

>>> _in_range("clearance")(1e300)
'must be in [1e-09, 10] (m)'
>>> _manifold_size([1000, 1000])
'must sample at most 100000 points (orbits × phases), asks for 1000000'
>>> _study_name("..")
"must be a plain folder name: 1-64 characters among letters, digits, '_', '.', '-', not starting with '.'"
>>> show("0.1"), show(True), show([1.0] * 100)[-11:]
("the string '0.1'", 'the boolean true', '(100 items)')
"""

from __future__ import annotations

import math
import re

from ..post.outputs import FORMATS as OUTPUT_FORMATS
from ..reduction import METHODS


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _finite_num(x) -> bool:
    """A finite number (not a boolean, not a string), as TOML gives them (``nan``, ``inf`` are refused)."""
    return _num(x) and math.isfinite(x)


def _count(x, lo: int, hi: int) -> bool:
    """An integer (not a boolean) in ``[lo, hi]``."""
    return isinstance(x, int) and not isinstance(x, bool) and lo <= x <= hi


#: Longest repr of a value quoted in a message (a 10 000-item list is cut, with its length).
SHOW_CHARS = 80


def show(value) -> str:
    """A value for a message, with what it is when that is not plain from its TOML spelling: ``the string '0.1'``,
    ``the boolean true``, ``a list [...]``, ``a table {...}``; long reprs are cut (with the item count)."""
    import datetime

    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, str):
        text = repr(value)
        return "the string " + (text if len(text) <= SHOW_CHARS else f"{text[:SHOW_CHARS]}…' ({len(value)} characters)")
    if isinstance(value, (datetime.date, datetime.time)):
        return f"the date/time {value.isoformat()}"
    text = repr(value)
    if isinstance(value, (list, tuple, dict)):
        what = "a table" if isinstance(value, dict) else "a list"
        if len(text) > SHOW_CHARS:
            text = f"{text[:SHOW_CHARS]}… ({len(value)} items)"
        return f"{what} {text}"
    if isinstance(value, int) and len(text) > 24:
        return f"{value:.3g}"
    return text if len(text) <= SHOW_CHARS else f"{text[:SHOW_CHARS]}…"


#: A study name is a plain folder name (results go to ``results/<name>``): no ``..``, no hidden folder.
NAME_PATTERN = r"[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}"


def _study_name(v) -> str | None:
    return None if re.fullmatch(NAME_PATTERN, v) else (
        "must be a plain folder name: 1-64 characters among letters, digits, '_', '.', '-', not starting with '.'")


def _path(kind: str, example: str):
    """A check of a ``kind`` path (``"folder"``, ``"file"``): not empty, no control characters (no NUL byte)."""

    def check(v) -> str | None:
        if not v.strip():
            return f'must name a {kind} (e.g. "{example}")' if kind == "file" else \
                f'must name a {kind} (give a {kind}, e.g. "{example}")'
        if any(ord(c) < 32 or ord(c) == 127 for c in v):
            return f"must be a {kind} path without control characters"
        return None

    return check


_folder = _path("folder", "results/plate")
_file = _path("file", "meshes/plate.vtu")


def _name(v) -> str | None:
    """A mesh group name: not empty."""
    return None if v.strip() else "must be a mesh group name such as 'tip', not empty"


def _positive(v) -> str | None:
    return None if math.isfinite(v) and v > 0 else "must be a finite number > 0"


def _int_at_least(n):
    return lambda v: None if v >= n else f"must be >= {n}"


#: Physical ranges (SI) of the study's scales.  Outside them the value is a unit mistake, and double
#: precision no longer delivers the stated tolerances (energies ``~ K d²`` overflow, eigen-solutions and
#: impact times lose their digits): ``[contact] clearance``, ``[material] E`` and ``rho``.
RANGES = {"clearance": (1e-9, 10.0, "m"), "E": (1e3, 1e13, "Pa"), "rho": (1e-2, 1e5, "kg/m³"),
          "yield_strength": (1e4, 1e11, "Pa"),
          "casing_stiffness": (1e-3, 1e15, "N/m"), "thickness": (1e-9, 100.0, "m"),
          "amplitude": (1e-9, 1e9, "N or Pa"), "alpha": (0.0, 1.0, "s"), "beta": (0.0, 1e6, "1/s"),
          "scale": (1e-12, 1e15, ""), "coordinate": (0.0, 1e6, "m"), "tol": (0.0, 1e6, "m")}

#: Caps on the work a study may ask for (each is far above any useful value; beyond, a run would not end
#: or not fit in memory).
LIMITS = {"frames": 1000, "scan": 2000, "resolution": 1000, "max_points": 100_000, "fps": 1000, "frequencies": 100,
          "manifold_axis": 1000, "manifold_samples": 100_000, "period_multiple": 100, "grid_cells": 1_000_000,
          "models": 32, "forcing_points": 2000, "forcing_periods": 100_000, "engine_order": 1000,
          "size": 6000, "animate": 1000, "mode_index": 1000, "node": 2**31 - 1, "forcing_reach": 1000,
          "workers": 100_000, "period_fraction": 1e-6,
          "forcing_frequency": {"f1": 1000.0, "Hz": 1e9, "rpm": 1e10}}

#: Slowest frame rate of the animations (frames per second): a GIF frame lasts at most 100 s.
MIN_FPS = 0.01


def _in_range(name: str):
    lo, hi, unit = RANGES[name]
    return lambda v: None if math.isfinite(v) and lo <= v <= hi else f"must be in [{lo:g}, {hi:g}] ({unit})"


def _amplitude(v) -> str | None:
    """A load amplitude: ``|v|`` within :data:`RANGES` ``["amplitude"]`` (N for a force, Pa for a pressure)."""
    lo, hi, _ = RANGES["amplitude"]
    if math.isfinite(v) and lo <= abs(v) <= hi:
        return None
    return (f"must be a force (N) or a pressure (Pa) with {lo:g} <= |amplitude| <= {hi:g} (beyond: a unit mistake, "
            "and the response overflows)")


def _count_capped(cap: int):
    """A count ``>= 0`` of which any value above ``cap`` means "as many as there are" (capped to ``cap`` by
    :func:`bladecase.study.schema.validate`, and logged)."""
    return lambda v: None if v >= 0 else (f"must be an integer >= 0 (0: none; a count above {cap} animates at most "
                                          f"{cap})")


def _int_between(lo: int, hi: int, why: str = ""):
    return lambda v: None if lo <= v <= hi else f"must be an integer with {lo} <= value <= {hi}{why}"


def _positive_at_most(hi: float, unit: str = ""):
    """A finite number in ``(0, hi]``."""
    unit = f" ({unit})" if unit else ""
    return lambda v: None if math.isfinite(v) and 0 < v <= hi else f"must be a number in (0, {hi:g}]{unit}"


def _one_of(*choices):
    return lambda v: None if v in choices else f"must be one of {', '.join(repr(c) for c in choices)}"


def _vector(v) -> str | None:
    if len(v) not in (2, 3) or not all(_finite_num(x) for x in v):
        return "must be a list of 2 or 3 finite numbers"
    return None


def _point(v) -> str | None:
    """A point (m): 2 or 3 finite coordinates within :data:`RANGES` ``["coordinate"]`` (distances then stay finite)."""
    top = RANGES["coordinate"][1]
    message = _vector(v)
    if message is None and any(abs(x) > top for x in v):
        return f"must be a list of 2 or 3 numbers of magnitude at most {top:g} (m; a unit mistake?)"
    return message


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
    if len(v) != 2 or not all(_finite_num(x) for x in v) or not 0 < v[0] < v[1]:
        return "must be [lower, upper] with 0 < lower < upper"
    if v[0] < 1e-12 * v[1]:
        return "must be [lower, upper] with 0 < lower < upper and lower >= 1e-12 × upper"
    return None


def _period_unit_index(v) -> str | None:
    """``period_unit``: ``'s'`` or ``'T<j>'`` with ``j`` at most :data:`LIMITS` ``["mode_index"]``."""
    message = _period_unit(v)
    if message is None and v != "s" and int(v[1:]) > LIMITS["mode_index"]:
        return f"must be 's' or 'T<j>' with j <= {LIMITS['mode_index']}"
    return message


def _ipp(v) -> str | None:
    if not v or not all(isinstance(k, int) and not isinstance(k, bool) and 1 <= k <= 8 for k in v):
        return "must be a non-empty list of integers between 1 and 8 (impacts per period)"
    if len(set(v)) != len(v):
        return "must not repeat a value"
    return None


def _formats(v) -> str | None:
    if not all(isinstance(f, str) for f in v):
        return f"must be a list of format names among {', '.join(OUTPUT_FORMATS)}"
    bad = [f for f in v if f not in OUTPUT_FORMATS]
    return f"unknown format(s) {bad} (valid: {', '.join(OUTPUT_FORMATS)})" if bad else None


def _window(v) -> str | None:
    if len(v) != 2 or not all(isinstance(x, int) and not isinstance(x, bool) and 64 <= x <= 4096 for x in v):
        return "must be [width, height] in pixels, integers between 64 and 4096"
    return None


def _scale(v) -> str | None:
    if v == "auto":
        return None
    lo, hi, _ = RANGES["scale"]
    if _num(v) and math.isfinite(v) and lo <= v <= hi:
        return None
    return f"must be 'auto' or a number in [{lo:g}, {hi:g}]"


def _reduction_list(v) -> str | None:
    for i, item in enumerate(v):
        if not isinstance(item, dict):
            return f"item {i} must be a table {{method = ..., size = ...}}"
        extra = set(item) - {"method", "size"}
        if extra:
            return f"item {i}: unknown key(s) {sorted(extra)} (valid: method, size)"
        if not isinstance(item.get("method"), str) or item.get("method") not in METHODS:
            return f"item {i}: method must be one of {', '.join(METHODS)}, got {show(item.get('method'))}"
        size, top = item.get("size"), LIMITS["size"]
        if item["method"] != "full" and not _count(size, 1, top):
            return f"item {i}: size must be an integer with 1 <= size <= {top}, got {show(size)}"
        if item["method"] == "full" and size is not None:
            return f"item {i}: method 'full' keeps every dof: no size, got {size!r}"
    return None


def _method_names(v) -> str | None:
    if not all(isinstance(m, str) for m in v):
        return f"must be a list of method names among {', '.join(METHODS)}"
    bad = [m for m in v if m not in METHODS]
    if bad:
        return f"unknown method {bad[0]!r} (valid: {', '.join(METHODS)})"
    return None if len(set(v)) == len(v) else f"methods repeat: {v}"


def _size_list(v) -> str | None:
    top = LIMITS["size"]
    bad = [x for x in v if not _count(x, 1, top)]
    if bad:
        return f"sizes must be integers with 1 <= size <= {top}, got {show(bad[0])}"
    return None if len(set(v)) == len(v) else f"sizes repeat: {v}"


def _orbit_list(v) -> str | None:
    for i, item in enumerate(v):
        if not isinstance(item, dict) or set(item) - {"ipp", "T"} or not {"ipp", "T"} <= set(item):
            return f"item {i} must be a table {{ipp = K, T = period}} (T in search.period_unit)"
        if not _count(item["ipp"], 1, 8):
            return f"item {i}: ipp must be an integer between 1 and 8, got {show(item['ipp'])}"
        if not _finite_num(item["T"]) or item["T"] <= 0:
            return f"item {i}: T must be a finite number > 0, got {show(item['T'])}"
    return None


def _rayleigh(v) -> str | None:
    a, b = RANGES["alpha"][1], RANGES["beta"][1]
    if len(v) != 2 or not all(_finite_num(x) and x >= 0 for x in v) or not any(v):
        return "must be [alpha, beta], two finite numbers >= 0, not both 0 (C = alpha K + beta M)"
    if v[0] > a or v[1] > b:
        return (f"must be [alpha, beta] with alpha <= {a:g} s and beta <= {b:g} 1/s (C = alpha K + beta M; beyond, "
                "every mode is overdamped: a unit mistake?)")
    return None


def _nonzero(v) -> str | None:
    return None if math.isfinite(v) and v != 0 else "must be a finite number, not 0"


#: The coordinate rules of a clamp (:func:`bladecase.fe.select_nodes`); ``tol`` may go with any of them.
CLAMP_RULES = ("plane", "box", "sphere")

#: The node-list rules of a clamp or a contact face: node numbers as in the mesh file, in the study or in a file.
NODE_RULES = ("nodes", "nodes_file")

#: Most node numbers a node list may hold, and the largest number (32-bit, as Abaqus, CalculiX and ANSYS number).
MAX_NODE_LIST, MAX_NODE_ID = 10_000_000, 2**31 - 1


def _node_list(v) -> str | None:
    """A non-empty list of node numbers (integers in ``[0, MAX_NODE_ID]``) as in the mesh file."""
    if not v or len(v) > MAX_NODE_LIST or not all(_count(x, 0, MAX_NODE_ID) for x in v):
        bad = next((x for x in v if not _count(x, 0, MAX_NODE_ID)), None)
        return (f"must be a non-empty list of node numbers as in the mesh file (integers 0 to {MAX_NODE_ID})"
                + (f", got {show(bad)} in it" if bad is not None else ""))
    return None


def _clamp_spec(v) -> str | None:
    """A group name, or a table with exactly one coordinate rule (its values are checked by ``select_nodes``) or one
    node list (``nodes = [...]``, ``nodes_file = "..."``)."""
    if isinstance(v, str):
        return None if v.strip() else "must be a mesh group name or a table such as {plane = [0, 0, 0, 0, 0, 1]}"
    rules = [k for k in v if k in CLAMP_RULES + NODE_RULES]
    unknown = sorted(set(v) - set(CLAMP_RULES + NODE_RULES) - {"tol"})
    if unknown or len(rules) != 1:
        return (f"must hold exactly one of {', '.join(CLAMP_RULES + NODE_RULES)} (and optionally tol with "
                f"{', '.join(CLAMP_RULES)})" + (f"; unknown keys {unknown}" if unknown else ""))
    rule, value = rules[0], v[rules[0]]
    if rule in NODE_RULES and "tol" in v:
        return f"tol goes with {', '.join(CLAMP_RULES)}, not with {rule}"
    if rule == "nodes":
        return _node_list(value) if isinstance(value, list) else "nodes must be a list of node numbers, e.g. [1, 2, 3]"
    if rule == "nodes_file":
        return (_file(value) if isinstance(value, str) else
                'nodes_file must be a file name (one node number per line, or separated by commas or spaces), e.g. '
                '"root.txt"')
    top = RANGES["coordinate"][1]
    numbers = value if rule != "box" else (
        [x for corner in value for x in corner] if isinstance(value, list) and len(value) == 2
        and all(isinstance(c, list) and len(c) in (2, 3) for c in value) else None)
    # a plane's normal (its second half) is a direction: any finite length but zero (select_nodes scales it)
    bounded = numbers[:len(numbers) // 2] if rule == "plane" and isinstance(numbers, list) and len(numbers) in (4, 6) \
        else numbers
    if not isinstance(numbers, list) or not all(_finite_num(x) for x in numbers) or \
            not all(abs(x) <= top for x in bounded):
        shape = {"plane": "[x0, y0, z0, nx, ny, nz] (or [x0, y0, nx, ny] in 2-D)",
                 "box": "[[xmin, ymin, zmin], [xmax, ymax, zmax]] (or 2-D corners)", "sphere": "[x, y, z, r]"}[rule]
        return f"{rule} must be {shape}, finite numbers of magnitude at most {top:g}" + (
            " (the normal: any finite length but zero)" if rule == "plane" else "")
    if "tol" in v and not (_finite_num(v["tol"]) and 0 <= v["tol"] <= RANGES["tol"][1]):
        return f"tol must be a number in [0, {RANGES['tol'][1]:g}] (m)"
    return None


def _compare_periods(v) -> str | None:
    """1 to 8 distinct finite periods in (0, 100] (× the FE first period)."""
    if not 1 <= len(v) <= 8 or not all(_finite_num(x) and 0 < x <= 100 for x in v):
        return "must be a list of 1 to 8 numbers in (0, 100] (× the FE model's first period)"
    if len(set(v)) != len(v):
        return "periods repeat"
    return None


def sweep_periods(ratios, periods: int, sweeps: int) -> float:
    """The work of a forced sweep: forcing periods integrated (``periods`` per point, ``sweeps`` sweeps), each
    counted in periods ``T1`` of the first linear mode when it is longer (at ``0.1 f1`` a forcing period counts 10:
    the integration follows every mode's oscillations).  ``ratios``: the forcing frequencies over ``f1``.

    >>> sweep_periods([0.5, 1.0, 2.0], 100, 2)
    800.0
    """
    return float(sweeps * periods * sum(max(1.0, 1.0 / r) for r in ratios))



#: Densities in t/mm³ — the N-mm-t units of an Abaqus or CalculiX deck in millimetres (metals: 2.7e-9 to 8.9e-9).
NMM_DENSITY = (1e-12, 1e-6)


def _density(v) -> str | None:
    """``[material] rho`` in kg/m³, with what to do when it is a density in t/mm³ (a deck's N-mm-t units)."""
    lo, hi, _ = RANGES["rho"]
    if math.isfinite(v) and lo <= v <= hi:
        return None
    if NMM_DENSITY[0] <= v <= NMM_DENSITY[1]:
        return (f"must be a density in kg/m³ in [{lo:g}, {hi:g}]; {v:g} looks like t/mm³, the N-mm-t units of a deck "
                f"in millimetres. bladecase takes SI material constants whatever the mesh's unit: give rho = "
                f"{v * 1e12:.6g} (kg/m³) and E in Pa (MPa × 1e6, e.g. 113800 MPa is E = 1.138e11), and read the mesh "
                'in millimetres with [mesh] unit = "mm"')
    return f"must be in [{lo:g}, {hi:g}] (kg/m³)"


def _yield_strength(v) -> str | None:
    """``[material] yield_strength`` in Pa, with what to do when it looks like MPa (a metal's 200 to 2000).

    >>> _yield_strength(8.8e8) is None, _yield_strength(880.0)[:52]
    (True, 'must be a stress in Pa in [10000, 1e+11]; 880 looks ')
    """
    lo, hi, _ = RANGES["yield_strength"]
    if math.isfinite(v) and lo <= v <= hi:
        return None
    if math.isfinite(v) and 1.0 <= v < lo:
        return (f"must be a stress in Pa in [{lo:g}, {hi:g}]; {v:g} looks like MPa: bladecase takes SI material "
                f"constants whatever the mesh's unit, give yield_strength = {v * 1e6:.6g} (Pa)")
    return f"must be in [{lo:g}, {hi:g}] (Pa)"


def _mesh_format(v) -> str | None:
    """A format name :func:`bladecase.fe.load_mesh` takes."""
    from ..fe.mesh import mesh_formats

    valid = mesh_formats()
    return None if v.lower() in valid else f"must be a mesh format name, e.g. 'abaqus', 'gmsh', 'ansys'; valid: " \
        f"{', '.join(valid)}"
