"""ANSYS archive files (``.cdb``, written by ``CDWRITE`` or ANSYS Workbench) read into a ``meshio.Mesh``.

meshio 5.3 reads no ``.cdb``; :func:`read_cdb` reads the blocks a mesh needs and :func:`register` teaches meshio the
``.cdb`` suffix (``"ansys-cdb"``), so :func:`bladecase.fe.load_mesh`, the CLI and ``[mesh] path`` take it:

* ``ET`` records: element type number → ANSYS element (``ET, 1, 186``);
* ``NBLOCK``: node numbers and coordinates in the fixed-width Fortran format its second line gives (e.g.
  ``(3i9,6e21.13e3)``; fields run together, trailing zero coordinates are left out), ended by ``-1`` or
  ``N,R5.3,LOC,-1``;
* ``EBLOCK`` (solid format): per element 11 header fields — material, type, real, section, coordinate system,
  birth/death, solid model, shape, number of nodes, exclude key, element number — then its nodes, 8 on the first
  line and the rest on continuation lines, ended by ``-1``;
* ``CMBLOCK``: node components (``NODE``) as they are and element components (``ELEM``) as the nodes of their
  elements, both as named node groups (``point_sets``); a negative entry closes a range (``1, -10`` is 1…10).

Element types: 3-D solids — 8-node bricks ``SOLID185``, ``SOLID45``, ``SOLID70``, ``SOLID164`` and their degenerate
forms (``K = L``, ``O = P``: a wedge; ``K = L``, ``M = N = O = P``: a tetrahedron); 20-node bricks ``SOLID186``,
``SOLID95``, ``SOLID90`` (degenerate: 15-node wedge, 10-node tetrahedron); tetrahedra ``SOLID187``, ``SOLID92``,
``SOLID87``, ``SOLID285``; 2-D solids ``PLANE182``, ``PLANE42``, ``PLANE55`` (quadrilateral, ``K = L``:
triangle), ``PLANE183``, ``PLANE82``, ``PLANE77`` (8-node quadrilateral; ``K = L = O``: 6-node triangle). Their
node orders are VTK's (checked against a brick's corner and edge numbering). Pyramids (``M = N = O = P`` of a
brick) are refused. Elements of other types — surface effect, contact, target, mesh-only, shells, beams — are left
out with a log line counting them (their nodes stay, and their components become groups like any other).

The positions are taken as they are (no unit conversion: ANSYS archives are in the model's units, SI for
Workbench). Errors name the file, the line number and what was expected.

>>> import tempfile, os
>>> text = '''ET,1,185
... NBLOCK,6,SOLID,8,8
... (3i4,3e10.3)
...    1   0   0 0.000E+00
...    2   0   0 1.000E+00
...    3   0   0 1.000E+00 1.000E+00
...    4   0   0 0.000E+00 1.000E+00
...    5   0   0 0.000E+00 0.000E+00 1.000E+00
...    6   0   0 1.000E+00 0.000E+00 1.000E+00
...    7   0   0 1.000E+00 1.000E+00 1.000E+00
...    8   0   0 0.000E+00 1.000E+00 1.000E+00
... N,R5.3,LOC,       -1,
... EBLOCK,19,SOLID,1,1
... (19i4)
...    1   1   1   1   0   0   0   0   8   0   1   1   2   3   4   5   6   7   8
...   -1
... CMBLOCK,ROOT,NODE,        2  ! users node component definition
... (8i10)
...          1        -4
... '''
>>> with tempfile.TemporaryDirectory() as d:
...     path = os.path.join(d, "cube.cdb")
...     _ = open(path, "w").write(text)
...     m = read_cdb(path)
>>> m.cells[0].type, m.cells[0].data.tolist(), m.point_sets["ROOT"].tolist()
('hexahedron', [[0, 1, 2, 3, 4, 5, 6, 7]], [0, 1, 2, 3])
"""

from __future__ import annotations

import os
import re

import numpy as np

from .. import log

#: ANSYS element number → (family, nodes in the EBLOCK record).
SOLIDS = {
    **{k: ("brick8", 8) for k in (185, 45, 70, 164)},
    **{k: ("brick20", 20) for k in (186, 95, 90)},
    **{k: ("tet10", 10) for k in (187, 92, 87)},
    285: ("tet4", 4),
    **{k: ("quad4", 4) for k in (182, 42, 55)},
    **{k: ("quad8", 8) for k in (183, 82, 77)},
}

# Positions within an ANSYS 20-node brick I J K L M N O P Q R S T U V W X Y Z A B (0-based).
_I, _J, _K, _L, _M, _N, _O, _P, _Q, _R, _S, _T, _U, _V, _W, _X, _Y, _Z, _A, _B = range(20)


#: The 2-D solids among :data:`SOLIDS` (named ``PLANE…``; the others ``SOLID…``).
PLANES = (182, 42, 55, 183, 82, 77)


def element_name(number: int) -> str:
    """ANSYS name of an element number, e.g. ``SOLID186``, ``PLANE182`` (``type <n>`` for the ones not read)."""
    if number in PLANES:
        return f"PLANE{number}"
    return f"SOLID{number}" if number in SOLIDS else f"type {number}"


class CdbError(ValueError):
    """A ``.cdb`` file that cannot be read (the message names the file and line)."""


def read_cdb(path: str | os.PathLike):
    """The mesh of an ANSYS archive file as a ``meshio.Mesh`` (see the module docstring for what is read).

    ``point_sets`` holds every node and element component by its ANSYS name; ``field_data["ansys:types"]`` the
    count of elements of each ANSYS type that was read or left out.
    """
    import meshio

    source = str(path)
    try:
        with open(path, encoding="latin-1") as fh:
            lines = fh.read().splitlines()
    except OSError as exc:
        raise CdbError(f"cannot read ANSYS archive {source!r}: {exc.strerror or exc}") from None
    types: dict[int, int] = {}
    ids = np.zeros(0, dtype=np.int64)
    xyz = np.zeros((0, 3))
    elements: list[tuple[int, int, list[int], int]] = []  # (type number, element number, nodes, line)
    components: dict[str, tuple[str, list[int]]] = {}
    i = 0
    while i < len(lines):
        head = lines[i].split("!")[0].strip()
        word = head.split(",")[0].strip().upper()
        if word == "ET":
            _, itype, ename = (f.strip() for f in (head.split(",") + ["", ""])[:3])
            types[_int(itype, source, i)] = _int(re.sub(r"^\D*", "", ename) or ename, source, i)
        elif word == "NBLOCK":
            ids, xyz, i = _nblock(lines, i, source)
            continue
        elif word == "EBLOCK":
            block, i = _eblock(lines, i, source)
            elements += block
            continue
        elif word == "CMBLOCK":
            name, kind, members, i = _cmblock(lines, i, source)
            components[name] = (kind, members)
            continue
        i += 1
    if ids.size == 0:
        raise CdbError(f"ANSYS archive {source!r} has no NBLOCK (node coordinates): not a mesh archive")
    index = np.full(int(ids.max()) + 1, -1, dtype=np.int64)
    index[ids] = np.arange(ids.size)
    cells, counts, by_number = _cells(elements, types, index, source)
    if not cells:
        found = ", ".join(f"{n} × {element_name(int(t))}" for t, n in counts.items()) or "none"
        raise CdbError(f"ANSYS archive {source!r} has no solid element bladecase reads (found: {found}; read: "
                       f"{', '.join(map(element_name, sorted(SOLIDS)))})")
    point_sets = {}
    for name, (kind, members) in components.items():
        if kind == "NODE":
            nodes = [index[k] for k in members if k < index.size and index[k] >= 0]
        else:
            nodes = [n for e in members for n in by_number.get(e, ())]
        point_sets[name] = np.unique(np.asarray(nodes, dtype=np.int64))
    return meshio.Mesh(xyz, [(t, np.asarray(c, dtype=np.int64)) for t, c in cells.items()], point_sets=point_sets,
                       field_data={"ansys:types": counts})


def register() -> None:
    """Teach meshio the ``.cdb`` suffix (format ``"ansys-cdb"``, read only); idempotent."""
    import meshio
    from meshio import _helpers

    if "ansys-cdb" not in _helpers.reader_map:
        meshio.register_format("ansys-cdb", [".cdb"], read_cdb, {})


def _int(text: str, source: str, line: int) -> int:
    try:
        return int(str(text).strip())
    except ValueError:
        raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: expected an integer, got {text!r}") from None


def _format(lines: list[str], i: int, source: str) -> list[tuple[str, int]]:
    """The fields ``[(kind, width), …]`` of the Fortran format on line ``i``, e.g. ``(3i9,6e21.13e3)``."""
    text = lines[i].strip() if i < len(lines) else ""
    items = re.findall(r"(\d*)([iIeEgGfF])(\d+)", text)
    if not (text.startswith("(") and items):
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: expected a Fortran format such as "
                       f"(3i9,6e21.13e3), got {text!r}")
    return [(kind.lower(), int(width)) for count, kind, width in items for _ in range(int(count or 1))]


def _fields(line: str, widths: list[int]) -> list[str]:
    """The non-blank fixed-width fields of ``line`` (a short line leaves the trailing fields out)."""
    out, pos = [], 0
    for w in widths:
        piece = line[pos:pos + w]
        pos += w
        if not piece.strip():
            break
        out.append(piece)
    return out


def _nblock(lines: list[str], i: int, source: str) -> tuple[np.ndarray, np.ndarray, int]:
    fmt = _format(lines, i + 1, source)
    widths = [w for _, w in fmt]
    n_int = sum(1 for k, _ in fmt if k == "i")
    ids, xyz = [], []
    j = i + 2
    while j < len(lines):
        line = lines[j]
        if line.strip().upper().startswith("N,") or line.strip() == "-1":
            break
        f = _fields(line, widths)
        try:
            ids.append(int(f[0]))
            coords = [float(x.replace("D", "E").replace("d", "e")) for x in f[n_int:n_int + 3]]
        except (ValueError, IndexError):
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not a node record of the NBLOCK format "
                           f"{lines[i + 1].strip()}: {line!r}") from None
        xyz.append(coords + [0.0] * (3 - len(coords)))
        j += 1
    else:
        raise CdbError(f"ANSYS archive {source!r}: the NBLOCK of line {i + 1} has no end (-1 or N,R5.3,LOC,-1)")
    ids = np.asarray(ids, dtype=np.int64)
    if ids.size and (ids.min() < 1 or np.unique(ids).size != ids.size):
        raise CdbError(f"ANSYS archive {source!r}: node numbers must be unique and >= 1 (NBLOCK of line {i + 1})")
    return ids, np.asarray(xyz, dtype=float).reshape(-1, 3), j + 1


def _eblock(lines: list[str], i: int, source: str) -> tuple[list, int]:
    if "SOLID" not in lines[i].upper():
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: only the solid EBLOCK format is read "
                       f"(EBLOCK,...,SOLID,...), got {lines[i].strip()!r}")
    widths = [w for _, w in _format(lines, i + 1, source)]
    out = []
    j = i + 2
    while j < len(lines):
        f = _fields(lines[j], widths)
        if not f or int(f[0]) == -1:
            return out, j + 1
        try:
            v = [int(x) for x in f]
            count, first = v[8], v[11:]
            start = j
            while len(first) < count:  # continuation lines
                j += 1
                first += [int(x) for x in _fields(lines[j], widths)]
        except (ValueError, IndexError):
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not an element record of the solid EBLOCK "
                           f"format (11 header fields, then the nodes): {lines[j]!r}") from None
        out.append((v[1], v[10], first[:count], start))
        j += 1
    raise CdbError(f"ANSYS archive {source!r}: the EBLOCK of line {i + 1} has no end (-1)")


def _cmblock(lines: list[str], i: int, source: str) -> tuple[str, str, list[int], int]:
    parts = [p.strip() for p in lines[i].split("!")[0].split(",")]
    if len(parts) < 4 or parts[2].upper() not in ("NODE", "ELEM"):
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: expected CMBLOCK,name,NODE|ELEM,count, got "
                       f"{lines[i].strip()!r}")
    name, kind, count = parts[1], parts[2].upper(), _int(parts[3], source, i)
    widths = [w for _, w in _format(lines, i + 1, source)]
    values: list[int] = []
    j = i + 2
    while len(values) < count and j < len(lines):
        values += [_int(x, source, j) for x in _fields(lines[j], widths)]
        j += 1
    if len(values) < count:
        raise CdbError(f"ANSYS archive {source!r}: component {name!r} (line {i + 1}) lists {len(values)} of its "
                       f"{count} entries before the end of the file")
    members: list[int] = []
    for v in values[:count]:
        if v < 0 and members:
            members += range(members[-1] + 1, -v + 1)
        elif v > 0:
            members.append(v)
    return name, kind, members, j


def _cells(elements, types: dict[int, int], index: np.ndarray, source: str):
    """Cells by meshio type (node indices), element counts by ANSYS type, and each element's node indices."""
    cells: dict[str, list[list[int]]] = {}
    counts: dict[str, int] = {}
    by_number: dict[int, list[int]] = {}
    skipped: dict[int, int] = {}
    for itype, number, nodes, line in elements:
        ename = types.get(itype)
        if ename is None:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} has type {itype}, which no "
                           "ET record defines")
        bad = [k for k in nodes if k <= 0 or k >= index.size or index[k] < 0]
        if bad:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} uses node {bad[0]}, which "
                           "the NBLOCK does not define")
        idx = [int(index[k]) for k in nodes]
        by_number[number] = sorted(set(idx))
        counts[str(ename)] = counts.get(str(ename), 0) + 1
        if ename not in SOLIDS:
            skipped[ename] = skipped.get(ename, 0) + 1
            continue
        family, size = SOLIDS[ename]
        if len(idx) < size:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} (type {ename}) has "
                           f"{len(idx)} nodes, expected {size}")
        kind, conn = _shape(family, idx[:size], number, ename, source, line)
        cells.setdefault(kind, []).append(conn)
    if skipped:
        log.info("ANSYS archive %s: left out %s (not solid elements; their nodes and components are kept)", source,
                 ", ".join(f"{n} element(s) of {element_name(t)}" for t, n in sorted(skipped.items())))
    return cells, counts, by_number


def _shape(family: str, n: list[int], number: int, ename: int, source: str, line: int) -> tuple[str, list[int]]:
    """meshio type and VTK-ordered nodes of one element, degenerate forms resolved."""
    if family == "tet4":
        return "tetra", n
    if family == "tet10":
        return "tetra10", n
    if family == "quad4":
        return ("triangle", n[:3]) if n[2] == n[3] else ("quad", n)
    if family == "quad8":
        if n[2] == n[3]:  # K = L (= O): the 6-node triangle I J K, mid-edges M (IJ), N (JK), P (LI = KI)
            return "triangle6", [n[0], n[1], n[2], n[4], n[5], n[7]]
        return "quad8", n
    corners = n[:8]
    top_collapsed = corners[_M] == corners[_N] == corners[_O] == corners[_P]
    if top_collapsed and corners[_K] != corners[_L]:
        raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} (type {ename}) is a pyramid "
                       "(M = N = O = P), which bladecase does not assemble (tetrahedra, hexahedra, wedges)")
    if family == "brick8":
        if corners[_K] == corners[_L] and top_collapsed:
            return "tetra", [n[_I], n[_J], n[_K], n[_M]]
        if corners[_K] == corners[_L] and corners[_O] == corners[_P]:
            return "wedge", [n[_I], n[_J], n[_K], n[_M], n[_N], n[_O]]
        return _distinct("hexahedron", corners, number, ename, source, line)
    if corners[_K] == corners[_L] and top_collapsed:
        return "tetra10", [n[_I], n[_J], n[_K], n[_M], n[_Q], n[_R], n[_T], n[_Y], n[_Z], n[_A]]
    if corners[_K] == corners[_L] and corners[_O] == corners[_P]:
        return "wedge15", [n[_I], n[_J], n[_K], n[_M], n[_N], n[_O], n[_Q], n[_R], n[_T], n[_U], n[_V], n[_X],
                           n[_Y], n[_Z], n[_A]]
    return _distinct("hexahedron20", n, number, ename, source, line)


def _distinct(kind: str, nodes: list[int], number: int, ename: int, source: str, line: int) -> tuple[str, list[int]]:
    if len(set(nodes)) != len(nodes):
        raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} (type {ename}) repeats nodes "
                       f"{nodes} in a way that is neither a brick, a wedge (K = L, O = P) nor a tetrahedron "
                       "(K = L, M = N = O = P)")
    return kind, nodes
