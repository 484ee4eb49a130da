"""The ``[geometry]`` section of a study: its own keys, the fields of the parametric geometry it names (a
:class:`~bladecase.BladeGeometry` or a :class:`~bladecase.PlateGeometry`), checked before the dataclass sees them, and
the geometry it builds (:func:`geometry_of`). A new parametric geometry kind is a value of ``kind`` and a row of
:data:`GEOMETRY_FIELDS` here.  ``kind = "sector"`` is a bladed-disk sector (:class:`~bladecase.fe.SectorGeometry`):
its disk's fields (:data:`SECTOR_FIELDS`) and its blade's, those of ``"blade"``.

>>> g = geometry_section({"kind": "sector", "sectors": 12, "hub_radius": 0.15, "rim_radius": 0.25,
...                       "disk_thickness": 0.04, "span": 0.15, "root_chord": 0.04, "thickness": 0.006})
>>> geometry = geometry_of(g)
>>> type(geometry).__name__, geometry.sectors, geometry.blade.span
('SectorGeometry', 12, 0.15)
"""

from __future__ import annotations

import dataclasses
import re

from ..fe import BladeGeometry, PlateGeometry, SectorGeometry
from .keys import _INT, _NUM, _STR, Key, StudyError, _check_field, _check_value, one_line
from .values import _one_of, _positive

#: The keys of ``[geometry]`` besides its geometry's fields.
GEOMETRY_KEYS = {
    "kind": Key(_STR, "blade", "'blade' (3-D lofted solid, tetrahedra), 'plate' (2-D plane stress) or 'sector' (a "
                "bladed-disk sector: the blade on its disk sector, tetrahedra; a cyclic study).",
                _one_of("blade", "plate", "sector")),
    "size": Key(_NUM, None, "Target element size (m); default: the geometry's own default.", _positive),
    "tip_size": Key(_NUM, None, "Element size at the tip (m, <= size); default: uniform.", _positive),
    "mesh_order": Key(_INT, 1, "Geometric order of the gmsh mesh (1 or 2).", _one_of(1, 2)),
    "cells": Key(_STR, "simplex", "'simplex' (tetrahedra, triangles) or 'hexahedron' (gmsh splits each into "
                 "hexahedra / quadrilaterals; mesh_order 1).", _one_of("simplex", "hexahedron")),
}


#: The disk's fields of a ``kind = "sector"`` geometry (:class:`~bladecase.fe.SectorGeometry` but its blade).
SECTOR_FIELDS = tuple(f.name for f in dataclasses.fields(SectorGeometry) if f.name != "blade")

#: The fields of each parametric geometry kind (its dataclass's; a sector's: its disk's and its blade's).
GEOMETRY_FIELDS = {
    "blade": tuple(f.name for f in dataclasses.fields(BladeGeometry)),
    "plate": tuple(f.name for f in dataclasses.fields(PlateGeometry)),
    "sector": SECTOR_FIELDS + tuple(f.name for f in dataclasses.fields(BladeGeometry)),
}

#: The keys of ``[geometry]`` a sector does not take (gmsh meshes it uniformly, with tetrahedra).
SECTOR_REFUSED = ("tip_size", "cells")


def _field_class(kind: str, key: str):
    """The dataclass whose field ``key`` is (a sector's disk or blade)."""
    if kind == "sector":
        return SectorGeometry if key in SECTOR_FIELDS else BladeGeometry
    return BladeGeometry if kind == "blade" else PlateGeometry


def geometry_of(g: dict) -> BladeGeometry | PlateGeometry | SectorGeometry:
    """The parametric geometry of a ``[geometry]`` section (its kind's dataclass, lists as tuples)."""
    values = {k: (tuple(v) if isinstance(v, list) else v) for k, v in g.items() if k in GEOMETRY_FIELDS[g["kind"]]}
    if g["kind"] == "sector":
        disk = {k: values.pop(k) for k in SECTOR_FIELDS if k in values}
        return SectorGeometry(**disk, blade=BladeGeometry(**values))
    cls = BladeGeometry if g["kind"] == "blade" else PlateGeometry
    return cls(**values)


def geometry_section(raw: dict) -> dict:
    """``[geometry]`` checked: its keys (:data:`GEOMETRY_KEYS`) and the fields of its geometry dataclass
    (:data:`GEOMETRY_FIELDS`), defaults filled in, the geometry built once so that its own checks name the field."""
    kind = raw.get("kind", "blade")
    _check_value("geometry", "kind", GEOMETRY_KEYS["kind"], kind)
    out = {}
    allowed = set(GEOMETRY_KEYS) | set(GEOMETRY_FIELDS[kind])
    for key, value in raw.items():
        if key not in allowed:
            raise StudyError(
                f"[geometry] {key}: unknown key for kind = {kind!r} (valid: {', '.join(sorted(allowed))})")
        if key in GEOMETRY_KEYS:
            out[key] = _check_value("geometry", key, GEOMETRY_KEYS[key], value)
        else:
            if isinstance(value, dict):
                raise StudyError(f"[geometry] {key}: expected a number, string or list, got a table")
            _check_field(kind, _field_class(kind, key), key, value)
            out[key] = value
    for key, spec in GEOMETRY_KEYS.items():
        out.setdefault(key, spec.default)
    try:  # the dataclass validates the shape and names the offending field
        geometry_of(out)
    except TypeError as exc:
        missing = re.findall(r"'(\w+)'", str(exc))
        raise StudyError(f"[geometry] {', '.join(missing) or '?'}: required for kind = {kind!r} ({exc})") from None
    except ValueError as exc:
        text = one_line(exc)
        name = re.match(r"(\w+)\b", text)
        if name and name.group(1) in allowed and not text.startswith(f"{name.group(1)}:"):
            text = f"{name.group(1)}:{text[name.end():]}"  # "[geometry] span: must be ..."
        raise StudyError(f"[geometry] {text}") from None
    g = out
    if kind == "sector":
        for key in SECTOR_REFUSED:
            if key in raw and raw[key] != GEOMETRY_KEYS[key].default:
                raise StudyError(f"[geometry] {key}: not for kind = 'sector' (gmsh meshes the sector uniformly with "
                                 f"tetrahedra: size and mesh_order), got {raw[key]!r}")
    if g["tip_size"] is not None and g["size"] is not None and g["tip_size"] > g["size"]:
        raise StudyError(f"[geometry] tip_size: must not exceed size = {g['size']!r} (it refines the tip), got "
                         f"{g['tip_size']!r}")
    if g["cells"] == "hexahedron" and g["mesh_order"] != 1:
        raise StudyError(f"[geometry] mesh_order: cells = 'hexahedron' makes order-1 cells: mesh_order = 1, got "
                         f"{g['mesh_order']!r} ([fem] order chooses the element order)")
    return out


def estimate_cells(geometry, size: float | None = None, tip_size: float | None = None,
                   cells: str = "simplex") -> int:
    """:func:`bladecase.fe.geometry.estimate_cells` of any ``[geometry]`` kind: a sector's blade and its disk
    sector (``8 V / size³`` tetrahedra, at the blade's default size when ``size`` is not set).

    >>> g = geometry_of(geometry_section({"kind": "sector", "sectors": 12, "hub_radius": 0.15, "rim_radius": 0.25,
    ...                                   "disk_thickness": 0.04, "span": 0.15, "root_chord": 0.04,
    ...                                   "thickness": 0.006}))
    >>> 100 < estimate_cells(g, size=0.02) < 10_000
    True
    """
    import math

    from ..fe.geometry import estimate_cells as blade_cells

    if not isinstance(geometry, SectorGeometry):
        return blade_cells(geometry, size=size, tip_size=tip_size, cells=cells)
    size = geometry.blade.default_size() if size is None else size
    disk = math.pi / geometry.sectors * (geometry.rim_radius ** 2 - geometry.hub_radius ** 2) * geometry.disk_thickness
    return blade_cells(geometry.blade, size=size) + int(math.ceil(8.0 * disk / size ** 3))
