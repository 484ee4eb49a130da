"""The checks of a study that span several keys or sections (:func:`cross_checks`): the material given whole,
one contact picker, the massless contact model and the keys it needs, searches that would not end, the comparison
grid, the mesh cells a geometry makes; the sections of :mod:`~bladecase.study.sections` check their own.
"""

from __future__ import annotations

import math

from ..fe import Material, PlateGeometry
from .disk.cyclic_keys import cyclic_checks
from .disk.mistuning_keys import mistuning_checks
from .geometry_section import estimate_cells, geometry_of
from .keys import StudyError, one_line
from .sections import (
    casing_checks,
    convergence_checks,
    execution_checks,
    forcing_checks,
    rotation_checks,
    rub_checks,
)
from .values import LIMITS

__all__ = ["MASSLESS_METHODS", "campbell_only", "cross_checks", "modes_only_checks"]


def _cell_checks(c: dict) -> None:
    """The mesh gmsh would make from ``[geometry]`` within ``[limits] cells`` (estimated before meshing)."""
    if "geometry" not in c:
        return
    g, cap = c["geometry"], c["limits"]["cells"]
    geometry = geometry_of(g)
    try:
        n = estimate_cells(geometry, size=g["size"], tip_size=g["tip_size"], cells=g["cells"])
    except ValueError as exc:
        raise StudyError(f"[geometry] {one_line(exc)}") from None
    if n <= cap:
        return
    size = g["size"] if g["size"] is not None else getattr(geometry, "blade", geometry).default_size()
    uniform = estimate_cells(geometry, size=size, cells=g["cells"])
    dim = 2 if isinstance(geometry, PlateGeometry) else 3
    if g["tip_size"] is not None and uniform <= cap:
        key, value, fix = "tip_size", g["tip_size"], "a larger tip_size"
    else:
        key, value = "size", size
        least = size * (uniform / cap) ** (1 / dim)  # cells ~ size^-dim
        for _ in range(60):
            if estimate_cells(geometry, size=least, cells=g["cells"]) <= cap:
                break
            least *= 1.05
        e = math.floor(math.log10(least)) - 1
        fix = f"size >= {math.ceil(least / 10**e) * 10**e:.2g} m"  # 2 digits, rounded up
        fix += " (without a finer tip_size)" if g["tip_size"] is not None else ""
    shown = f"{value:g} m" + ("" if g["size"] is not None or key != "size" else " (the geometry's default)")
    raise StudyError(f"[geometry] {key}: {key} = {shown} makes about {n:.2g} mesh cells (estimated before meshing), "
                     f"more than [limits] cells = {cap}: {fix}, or raise [limits] cells")


def cross_checks(c: dict, model: bool = True, contact: bool = True) -> None:
    """Every check across keys and sections of a validated study ``c`` (its sections filled in); ``contact=False``:
    the contact's clearance is not needed (the stages before the contact)."""
    m = c["material"]
    given = [k for k in ("E", "nu", "rho") if m[k] is not None]
    if given and len(given) != 3:
        missing = [k for k in ("E", "nu", "rho") if m[k] is None]
        raise StudyError(f"[material] {', '.join(missing)}: give E, nu and rho together (or only 'preset')")
    ct = c["contact"]
    pickers = [k for k in ("node", "farthest", "nearest", "face", "nodes") if ct[k] is not None]
    if len(pickers) > 1:
        raise StudyError(f"[contact] {pickers[1]}: give at most one of node, farthest, nearest, face, nodes (got "
                         f"{pickers})")
    for key in ("normal", "farthest"):  # directions: scaled to a largest component of 1 (no overflow later)
        v = ct[key]
        if v is not None:
            top = max(abs(x) for x in v)
            ct[key] = [x / top for x in v]
    if ct["weights"] is not None and ct["face"] is None and ct["nodes"] is None:
        raise StudyError(f"[contact] weights: only with [contact] face or nodes (the weights of its nodes), got "
                         f"{ct['weights']!r} without a face")
    if not given and m["preset"] is not None:  # not set: the mesh file's material, else the default preset
        try:
            Material.preset(m["preset"])
        except ValueError as exc:
            raise StudyError(f"[material] preset: {exc}") from None
    r = c["reduction"]
    if r["method"] == "full":
        r["size"] = None
    _expand_grid(r)
    _contact_model_checks(c)
    _work_checks(c["search"])
    _cell_checks(c)
    forcing_checks(c)
    execution_checks(c)
    rotation_checks(c)
    casing_checks(c, model and contact)
    rub_checks(c)
    convergence_checks(c)
    cyclic_checks(c)
    mistuning_checks(c)
    o, s = c["output"], c["search"]
    for i, item in enumerate(o["orbits"]):
        if item["ipp"] not in s["ipp"]:
            raise StudyError(f"[output] orbits: item {i} asks for ipp = {item['ipp']}, which [search] ipp = "
                             f"{s['ipp']} does not look for")


def _work_checks(s: dict) -> None:
    """Searches that would not end: periods of very many linear periods, too fine a k-ipp start grid."""
    top = LIMITS["period_multiple"]
    if s["period_unit"] != "s" and s["periods"][1] > top:
        raise StudyError(f"[search] periods: the upper period must be <= {top} × {s['period_unit']} (the work grows "
                         f"with the number of linear periods per orbit), got {s['periods']}")
    low = LIMITS["period_fraction"]
    if s["period_unit"] != "s" and s["periods"][0] < low:
        raise StudyError(f"[search] periods: the lower period must be >= {low:g} × {s['period_unit']} (shorter orbits "
                         f"belong to modes far above it: use their T<j>), got {s['periods']}")
    k = max(s["ipp"])
    if s["resolution"] is not None and k >= 3:
        cells = math.comb(s["resolution"] - 1, k - 1)
        cap = LIMITS["grid_cells"]
        if cells > cap:
            fit = max((r for r in range(4, s["resolution"]) if math.comb(r - 1, k - 1) <= cap), default=4)
            raise StudyError(f"[search] resolution: {s['resolution']} points per impact time make "
                             f"{cells:.3g} start cells for ipp = {k} at each scanned period (at most {cap}): "
                             f"resolution <= {fit} for ipp = {k}, got {s['resolution']}")


def _expand_grid(r: dict) -> None:
    """``methods`` × ``sizes`` appended to ``compare`` (the main model and repeats left out)."""
    if not (r["methods"] or r["sizes"]):
        return
    methods = r["methods"] or [r["method"]]
    sizes = r["sizes"] or [r["size"]]
    seen = {(r["method"], r["size"])} | {(x["method"], x.get("size")) for x in r["compare"]}
    for m in methods:
        for n in ([None] if m == "full" else sizes):
            if (m, n) not in seen:
                seen.add((m, n))
                r["compare"].append({"method": m, "size": n})
    if len(r["compare"]) > LIMITS["models"]:
        raise StudyError(f"[reduction] methods × sizes: {len(r['compare']) + 1} models, at most "
                         f"{LIMITS['models'] + 1}")


#: The reductions of the massless contact model (:data:`bladecase.reduction.massless.BASES`).
MASSLESS_METHODS = ("massless", "massless-lanczos", "massless-modal")


def _contact_model_checks(c: dict) -> None:
    """The massless contact model and the keys it needs go together."""
    massless = c["contact"]["model"] == "massless"
    if c["contact"]["casing_stiffness"] is not None and not massless:  # (a number or a list)
        raise StudyError(f"[contact] casing_stiffness: a compliant casing needs model = 'massless' (Newton's impact "
                         f"law is for a rigid casing), got {c['contact']['casing_stiffness']!r} with model = "
                         f"{c['contact']['model']!r}")
    if c["contact"].get("points") == "nodes" and (not massless or (c["contact"]["face"] is None
                                                                    and c["contact"].get("nodes") is None)):
        raise StudyError("[contact] points: 'nodes' (every node of the face a contact of its own) needs a contact "
                         "face (face or nodes) and model = 'massless'")
    per_area = c["contact"]["casing_stiffness_per_area"]
    if per_area is not None:
        if not massless:
            raise StudyError(f"[contact] casing_stiffness_per_area: a compliant casing needs model = 'massless' "
                             f"(Newton's impact law is for a rigid casing), got {per_area!r} with model = "
                             f"{c['contact']['model']!r}")
        if c["contact"]["casing_stiffness"] is not None:
            raise StudyError("[contact] casing_stiffness_per_area: give it or casing_stiffness, not both")
        if c["contact"]["face"] is None and c["contact"].get("nodes") is None:
            raise StudyError("[contact] casing_stiffness_per_area: a stiffness per unit area needs a contact face "
                             "(face or nodes) whose area it acts on")
    methods = [c["reduction"]["method"]] + [x["method"] for x in c["reduction"]["compare"]]
    if massless:
        bad = [m for m in methods if m not in MASSLESS_METHODS]
        if bad:
            raise StudyError(f"[reduction] method: the massless contact model needs a massless method "
                             f"({', '.join(map(repr, MASSLESS_METHODS))}) for every model, compare included; "
                             f"got {bad[0]!r}")
        if c["search"]["ipp"] != [1]:
            raise StudyError(f"[search] ipp: the massless contact model has modes with one contact phase per "
                             f"period: ipp = [1], got {c['search']['ipp']}")
        if c["fem"]["mass"] != "lumped":
            raise StudyError("[fem] mass: the massless contact model moves lumped masses: mass = 'lumped', got "
                             f"{c['fem']['mass']!r}")
    elif any(m in MASSLESS_METHODS for m in methods):
        m = next(m for m in methods if m in MASSLESS_METHODS)
        raise StudyError(f"[reduction] method: {m!r} is a reduction of the massless contact model: set "
                         "[contact] model = 'massless'")


def campbell_only(raw: dict) -> bool:
    """True for a study (as parsed, before its defaults) of the linear modes alone: no ``[contact]`` section and no
    casing of revolution, and ``[rotation] speeds`` given (the Campbell diagram) or a bladed disk (``[cyclic]``, or
    ``[geometry] kind = "sector"``: its modes by nodal diameter).

    >>> campbell_only({"rotation": {"speeds": [0, 1000]}}), campbell_only({"rotation": {"speeds": [0]}, "contact": {}})
    (True, False)
    >>> campbell_only({"cyclic": {}}), campbell_only({"geometry": {"kind": "sector"}})
    (True, True)
    """
    rotation, casing = raw.get("rotation"), raw.get("casing")
    speeds = rotation.get("speeds") if isinstance(rotation, dict) else None
    ring = isinstance(casing, dict) and (casing.get("radius") is not None or casing.get("radii") is not None)
    geometry = raw.get("geometry")
    disk = "cyclic" in raw or "mistuning" in raw or (isinstance(geometry, dict) and geometry.get("kind") == "sector")
    return "contact" not in raw and not ring and (disk or (isinstance(speeds, list) and len(speeds) > 0))


#: The sections (and the key that turns each on) that need a contact: refused in a study without one.
_CONTACT_STAGES = (("forcing", "amplitude", "the forced response follows the nonsmooth modes"),
                   ("convergence", "meshes", "the mesh convergence is that of the nonsmooth modes' figures"),
                   ("rub", "speeds", "the rub response is the blade's contact with its casing"))


def modes_only_checks(c: dict) -> None:
    """A study without a contact (:func:`campbell_only`) computes the linear modes and the Campbell diagram; a
    stage that needs a contact is refused, naming the section to add."""
    for section, key, why in _CONTACT_STAGES:
        value = (c.get(section) or {}).get(key)
        if value:
            raise StudyError(f"[{section}] {key}: {why}, which needs a contact: add a [contact] section (its "
                             f"clearance, e.g. clearance = 1e-4, and where it is) or remove {key} = {value!r}")
