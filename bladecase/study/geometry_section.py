"""The ``[geometry]`` section of a study: its own keys, the fields of the parametric geometry it names (a
:class:`~bladecase.BladeGeometry` or a :class:`~bladecase.PlateGeometry`), checked before the dataclass sees them, and
the geometry it builds (:func:`geometry_of`). A new parametric geometry kind is a value of ``kind`` and a row of
:data:`GEOMETRY_FIELDS` here."""

from __future__ import annotations

import dataclasses
import re

from ..fe import BladeGeometry, PlateGeometry
from .keys import _INT, _NUM, _STR, Key, StudyError, _check_field, _check_value, one_line
from .values import _one_of, _positive

#: The keys of ``[geometry]`` besides its geometry's fields.
GEOMETRY_KEYS = {
    "kind": Key(_STR, "blade", "'blade' (3-D lofted solid, tetrahedra) or 'plate' (2-D plane stress).",
                _one_of("blade", "plate")),
    "size": Key(_NUM, None, "Target element size (m); default: the geometry's own default.", _positive),
    "tip_size": Key(_NUM, None, "Element size at the tip (m, <= size); default: uniform.", _positive),
    "mesh_order": Key(_INT, 1, "Geometric order of the gmsh mesh (1 or 2).", _one_of(1, 2)),
    "cells": Key(_STR, "simplex", "'simplex' (tetrahedra, triangles) or 'hexahedron' (gmsh splits each into "
                 "hexahedra / quadrilaterals; mesh_order 1).", _one_of("simplex", "hexahedron")),
}


#: The fields of each parametric geometry kind (its dataclass's).
GEOMETRY_FIELDS = {
    "blade": tuple(f.name for f in dataclasses.fields(BladeGeometry)),
    "plate": tuple(f.name for f in dataclasses.fields(PlateGeometry)),
}


def geometry_of(g: dict) -> BladeGeometry | PlateGeometry:
    """The parametric geometry of a ``[geometry]`` section (its kind's dataclass, lists as tuples)."""
    cls = BladeGeometry if g["kind"] == "blade" else PlateGeometry
    fields = GEOMETRY_FIELDS[g["kind"]]
    return cls(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in g.items() if k in fields})


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
            _check_field(kind, BladeGeometry if kind == "blade" else PlateGeometry, key, value)
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
    if g["tip_size"] is not None and g["size"] is not None and g["tip_size"] > g["size"]:
        raise StudyError(f"[geometry] tip_size: must not exceed size = {g['size']!r} (it refines the tip), got "
                         f"{g['tip_size']!r}")
    if g["cells"] == "hexahedron" and g["mesh_order"] != 1:
        raise StudyError(f"[geometry] mesh_order: cells = 'hexahedron' makes order-1 cells: mesh_order = 1, got "
                         f"{g['mesh_order']!r} ([fem] order chooses the element order)")
    return out
