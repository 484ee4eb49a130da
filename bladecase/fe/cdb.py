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
* material records — ``MP,Lab,MAT,C0`` (commands), ``MPDATA,R5.0,LENGTH,Lab,MAT,STLOC,V1,…`` (as ``CDWRITE``
  writes them, each after its ``MPTEMP``) and ``MPDATA,Lab,MAT,STLOC,C1,…`` — for ``EX``, ``PRXY`` (or ``NUXY``) and
  ``DENS``: the material of the number the solid elements' EBLOCK records give (their first field) is the mesh's
  ``info["material"]`` (:attr:`bladecase.fe.mesh.Mesh.material`, in the archive's units; several material numbers
  among the solid elements, a temperature table, an anisotropic material or a missing density are recorded as the
  reason it cannot be used, raised only when a model needs it).

A component must name numbers the file has: a single number the NBLOCK (or the EBLOCK, for an element component)
does not define, a range reaching below the file's smallest number or beyond its largest (``1, -1000000000`` over 412
nodes), or a range that holds none of its numbers is an error naming the file, the line, the component, the number
or range and the file's numbering ("the file has 412 nodes, numbered 1 to 412"). Ranges are checked by binary search
before anything is expanded. Inside the file's numbering, the numbers of a range that a gappy numbering leaves out
are skipped: the range stands for the nodes (or elements) the file has between its ends.

Element types: 3-D solids — 8-node bricks ``SOLID185``, ``SOLID45``, ``SOLID70``, ``SOLID164`` and their degenerate
forms (``K = L``, ``O = P``: a wedge; ``K = L``, ``M = N = O = P``: a tetrahedron); 20-node bricks ``SOLID186``,
``SOLID95``, ``SOLID90`` (degenerate: 15-node wedge, 10-node tetrahedron); tetrahedra ``SOLID187``, ``SOLID92``,
``SOLID87``, ``SOLID285``; 2-D solids ``PLANE182``, ``PLANE42``, ``PLANE55`` (quadrilateral, ``K = L``:
triangle), ``PLANE183``, ``PLANE82``, ``PLANE77`` (8-node quadrilateral; ``K = L = O``: 6-node triangle). Their
node orders are VTK's (checked against a brick's corner and edge numbering). Pyramids (``M = N = O = P`` of a
brick) are refused. Elements of other types — surface effect, contact, target, mesh-only, shells, beams — are left
out with a log line counting them (their nodes stay, and their components become groups like any other).

The positions and material constants are taken as they are (no unit conversion here: ANSYS archives are in the
model's units, SI for Workbench; ``[mesh] unit`` says which, :func:`bladecase.fe.material.mesh_material` converts
the material with it). Errors name the file, the line number and what was expected.

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
from .mesh_checks import DeckError, check_input_file

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


class CdbError(DeckError):
    """A ``.cdb`` file that cannot be read (the message names the file and line)."""

    final_when_named = False  # with the format named, its reason is told with the other formats'


def read_cdb(path: str | os.PathLike):
    """The mesh of an ANSYS archive file as a ``meshio.Mesh`` (see the module docstring for what is read).

    ``point_sets`` holds every node and element component by its ANSYS name; ``field_data["ansys:types"]`` the
    count of elements of each ANSYS type that was read or left out.
    """
    import meshio

    try:
        source = check_input_file(path, "ANSYS archive")  # a pipe or a device would never end
    except ValueError as exc:
        raise CdbError(str(exc)) from None
    try:
        with open(path, encoding="latin-1") as fh:
            lines = fh.read().splitlines()
    except OSError as exc:
        raise CdbError(f"cannot read ANSYS archive {source!r}: {exc.strerror or exc}") from None
    types: dict[int, int] = {}
    ids = np.zeros(0, dtype=np.int64)
    xyz = np.zeros((0, 3))
    elements: list[tuple[int, int, list[int], int, int]] = []  # type number, element number, nodes, line, material
    tables: dict[int, dict[str, dict[int, float]]] = {}  # material number -> property -> location -> value
    broken: dict[int, str] = {}  # material number -> why its records cannot be used
    components: dict[str, tuple[str, list[tuple[int, int, int]]]] = {}  # name -> (kind, [(first, last, line)])
    i = 0
    while i < len(lines):
        head = lines[i].split("!")[0].strip()
        word = head.split(",")[0].strip().upper()
        if word == "ET":
            _, itype, ename = (f.strip() for f in (head.split(",") + ["", ""])[:3])
            types[_int(itype, source, i, "the element type number of ET")] = _int(
                re.sub(r"^\D*", "", ename) or ename, source, i, "the element name of ET (e.g. 186)")
        elif word == "NBLOCK":
            if ids.size:
                raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: a second NBLOCK (one is read per archive)")
            ids, xyz, i = _nblock(lines, i, source)
            continue
        elif word == "EBLOCK":
            block, i = _eblock(lines, i, source)
            elements += block
            continue
        elif word == "CMBLOCK":
            name, kind, ranges, i = _cmblock(lines, i, source)
            components[name] = (kind, ranges)
            continue
        elif word in ("MP", "MPDATA"):
            _mp(head, tables, broken, source, i)
        i += 1
    if ids.size == 0:
        raise CdbError(f"ANSYS archive {source!r} has no NBLOCK (node coordinates): not a mesh archive")
    index = _NodeIndex(ids)
    cells, counts, by_number = _cells(elements, types, index, source)
    if not cells:
        found = ", ".join(f"{n} × {element_name(int(t))}" for t, n in counts.items()) or "none"
        raise CdbError(f"ANSYS archive {source!r} has no solid element bladecase reads (found: {found}; read: "
                       f"{', '.join(map(element_name, sorted(SOLIDS)))})")
    numbers = np.array(sorted(by_number), dtype=np.int64)
    point_sets = {}
    for name, (kind, ranges) in components.items():
        have = index.sorted if kind == "NODE" else numbers
        _check_component(name, "node" if kind == "NODE" else "element", ranges, have, source)
        if kind == "NODE":
            nodes = [index.position[a:b] for a, b in (index.span(lo, hi) for lo, hi, _ in ranges)]
        else:
            chosen = [numbers[np.searchsorted(numbers, lo):np.searchsorted(numbers, hi, "right")]
                      for lo, hi, _ in ranges]
            nodes = [np.asarray(by_number[int(e)], dtype=np.int64) for part in chosen for e in part]
        point_sets[name] = np.unique(np.concatenate(nodes)) if nodes else np.zeros(0, dtype=np.int64)
    material = _body_material(elements, types, tables, broken, source)
    return meshio.Mesh(xyz, [(t, np.asarray(c, dtype=np.int64)) for t, c in cells.items()], point_sets=point_sets,
                       point_data={"node_id": np.asarray(ids, dtype=np.int64)}, field_data={"ansys:types": counts},
                       info={"material": material} if material else None)


def _mp(head: str, tables: dict, broken: dict, source: str, i: int) -> None:
    """One material property record into ``tables`` (material → property → location → value): ``MP,Lab,MAT,C0,C1,…``
    (``C1…`` the temperature coefficients), ``MPDATA,Lab,MAT,STLOC,C1,…`` (a command) or CDWRITE's
    ``MPDATA,R5.0,LENGTH,Lab,MAT,STLOC,V1,…``. A record that is not numbers marks its material ``broken``."""
    f = [x.strip() for x in head.split(",")]
    f += [""] * (8 - len(f))
    try:
        if f[0].upper() == "MP":
            lab, mat, loc = f[1].upper(), int(f[2]), 1
            values = [_real(x) for x in f[3:] if x]
            if any(values[1:]):  # C1, C2, … : a polynomial in the temperature
                broken.setdefault(mat, f"MP,{lab} (line {i + 1}) is a polynomial in the temperature")
            values = values[:1]
        elif f[1].upper().startswith("R"):  # MPDATA,R5.0,LENGTH,Lab,MAT,STLOC,V1,V2,…
            length, lab, mat, loc = int(f[2]), f[3].upper(), int(f[4]), int(f[5] or 1)
            values = [_real(x) for x in f[6:6 + length] if x]
        else:  # MPDATA,Lab,MAT,STLOC,C1,…
            lab, mat, loc = f[1].upper(), int(f[2]), int(f[3] or 1)
            values = [_real(x) for x in f[4:] if x]
    except ValueError:
        log.info("ANSYS archive %s, line %d: material record %r is not numbers: left out", source, i + 1, head)
        return
    table = tables.setdefault(mat, {}).setdefault(lab, {})
    table.update({loc + k: v for k, v in enumerate(values)})


def _real(text: str) -> float:
    return float(text.replace("D", "E").replace("d", "e"))


#: ANSYS material properties that make a material anisotropic when they differ from the isotropic values.
_ORTHOTROPIC = {"EY": "E", "EZ": "E", "PRXY": "nu", "NUXY": "nu", "PRYZ": "nu", "PRXZ": "nu", "NUYZ": "nu",
                "NUXZ": "nu", "GXY": "G", "GYZ": "G", "GXZ": "G"}


def _body_material(elements, types: dict[int, int], tables: dict, broken: dict, source: str) -> dict | None:
    """The material of the solid elements (:func:`bladecase.fe.material.file_material`): the ``MP`` records of the
    material number their EBLOCK records give; ``None`` when the archive has no material records. Logged."""
    from .material import file_material

    if not tables:
        return None
    used: dict[str, int] = {}
    for itype, _, _, _, mat in elements:
        if types.get(itype) in SOLIDS:
            used[f"material {mat}"] = used.get(f"material {mat}", 0) + 1
    values = {}
    for mat, props in tables.items():
        one = {lab: table[min(table)] for lab, table in props.items() if table}
        many = [f"{lab} ({len(table)} values)" for lab, table in props.items() if len(table) > 1]
        E, nu = one.get("EX"), one.get("PRXY", one.get("NUXY"))
        rho = one.get("DENS")
        iso = {"E": E, "nu": nu, "G": E / (2 * (1 + nu)) if E is not None and nu is not None else None}
        odd = [lab for lab, key in _ORTHOTROPIC.items() if lab in one and iso[key] is not None
               and abs(one[lab] - iso[key]) > 1e-6 * abs(iso[key])]
        if mat in broken or many or odd:
            why = broken.get(mat) or (f"temperature-dependent {', '.join(many)}" if many else
                                      f"anisotropic ({', '.join(odd)} differ from the isotropic values)")
            values[f"material {mat}"] = {"problem": why}
        else:
            values[f"material {mat}"] = {k: v for k, v in (("E", E), ("nu", nu), ("rho", rho)) if v is not None}
    record = file_material(repr(source), values, used, "", "ANSYS")
    if "problem" in record:
        log.info("ANSYS archive %s: %s (a study without [material] is refused)", source, record["problem"])
        return record
    record["where"] = f"the MP records of {record['name']} in {source!r}"
    log.info("ANSYS archive %s: material %s for the solid elements: E = %g, nu = %g, rho = %g in the archive's "
             "units (used when the study gives no [material])", source, record["name"], record["E"], record["nu"],
             record["rho"])
    return record


#: Largest node or element number read: ANSYS numbers them with 32-bit integers.
MAX_NUMBER = 2**31 - 1

#: Most fields a block's Fortran format may give (ANSYS writes at most 19 per line).
MAX_FORMAT_FIELDS = 1000

#: Most nodes an EBLOCK element record may list (the solids read have at most 20).
MAX_ELEMENT_NODES = 64


class _NodeIndex:
    """ANSYS node numbers → 0-based positions in the NBLOCK, by binary search (memory: the node count, whatever
    the largest number)."""

    def __init__(self, ids: np.ndarray):
        order = np.argsort(ids, kind="stable")
        self.sorted, self.position = ids[order], order.astype(np.int64)

    def find(self, numbers) -> np.ndarray:
        """Positions of ``numbers`` (``-1`` for a number the NBLOCK does not define)."""
        numbers = np.asarray(numbers, dtype=np.int64)
        k = np.minimum(np.searchsorted(self.sorted, numbers), self.sorted.size - 1)
        return np.where(self.sorted[k] == numbers, self.position[k], -1)

    def span(self, lo: int, hi: int) -> tuple[int, int]:
        """The slice of :attr:`position` of the node numbers in ``[lo, hi]``."""
        return int(np.searchsorted(self.sorted, lo)), int(np.searchsorted(self.sorted, hi, "right"))


def register() -> None:
    """Teach meshio the ``.cdb`` suffix (format ``"ansys-cdb"``, read only); idempotent."""
    import meshio
    from meshio import _helpers

    if "ansys-cdb" not in _helpers.reader_map:
        meshio.register_format("ansys-cdb", [".cdb"], read_cdb, {})


def _int(text: str, source: str, line: int, what: str = "") -> int:
    """``int(text)``, else a :class:`CdbError` naming the file, the line (0-based ``line``) and ``what``."""
    try:
        return int(str(text).strip())
    except ValueError:
        what = f" {what}:" if what else ""
        raise CdbError(f"ANSYS archive {source!r}, line {line + 1}:{what} expected an integer, got "
                       f"{str(text).strip()!r}") from None


def _number(value: int, source: str, line: int, what: str) -> int:
    """``value`` if it is a node/element number ``1..MAX_NUMBER``, else a :class:`CdbError`."""
    if not 1 <= value <= MAX_NUMBER:
        raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: {what} {value} is out of range (ANSYS numbers "
                       f"are 1..{MAX_NUMBER})")
    return value


def _declared_count(header: str, source: str, line: int) -> int | None:
    """The count an NBLOCK/EBLOCK header declares in its fifth field (``NBLOCK,6,SOLID,max,count``), if any."""
    parts = [p.strip() for p in header.split("!")[0].split(",")]
    if len(parts) < 5 or not parts[4]:
        return None
    return _int(parts[4], source, line, f"the count (fifth field) of {parts[0].upper()}")


def _format(lines: list[str], i: int, source: str) -> list[tuple[str, int]]:
    """The fields ``[(kind, width), …]`` of the Fortran format on line ``i``, e.g. ``(3i9,6e21.13e3)``."""
    text = lines[i].strip() if i < len(lines) else ""
    items = re.findall(r"(\d*)([iIeEgGfF])(\d+)", text)
    if not (text.startswith("(") and items):
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: expected a Fortran format such as "
                       f"(3i9,6e21.13e3), got {text!r}")
    counts = [int(count or 1) for count, _, _ in items]
    if sum(counts) > MAX_FORMAT_FIELDS or any(int(width) < 1 for _, _, width in items):
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: the Fortran format {text!r} has "
                       f"{sum(counts)} fields (at most {MAX_FORMAT_FIELDS}) or a zero width: a corrupt file?")
    return [(kind.lower(), int(width)) for n, (_, kind, width) in zip(counts, items) for _ in range(n)]


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
    declared = _declared_count(lines[i], source, i)
    names = ("x", "y", "z")
    ids, xyz, first_line = [], [], {}
    j = i + 2
    while j < len(lines):
        line = lines[j]
        if line.strip().upper().startswith("N,") or line.strip() == "-1":
            break
        f = _fields(line, widths)
        if not f:
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not a node record of the NBLOCK format "
                           f"{lines[i + 1].strip()}: an empty line (expected the node number, then the coordinates)")
        try:
            node = int(f[0])
        except ValueError:
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not a node record of the NBLOCK format "
                           f"{lines[i + 1].strip()}: field 1 (node number) is {f[0].strip()!r}, not an integer"
                           ) from None
        node = _number(node, source, j, "node number (field 1)")
        coords = []
        for k, x in enumerate(f[n_int:n_int + 3]):
            try:
                c = float(x.replace("D", "E").replace("d", "e"))
            except ValueError:
                raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not a node record of the NBLOCK format "
                               f"{lines[i + 1].strip()}: the {names[k]} coordinate of node {node} (field "
                               f"{n_int + k + 1}) is {x.strip()!r}, not a number") from None
            if not np.isfinite(c):
                raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: the {names[k]} coordinate of node {node} "
                               f"is {x.strip()!r}: coordinates must be finite numbers")
            coords.append(c)
        if node in first_line:
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: node {node} is defined twice (first on line "
                           f"{first_line[node] + 1}); node numbers must be unique")
        first_line[node] = j
        ids.append(node)
        xyz.append(coords + [0.0] * (3 - len(coords)))
        j += 1
    else:
        raise CdbError(f"ANSYS archive {source!r}: the NBLOCK of line {i + 1} has no end (-1 or N,R5.3,LOC,-1): "
                       f"the file is truncated or not an ANSYS archive")
    if declared is not None and declared != len(ids):
        raise CdbError(f"ANSYS archive {source!r}: the NBLOCK of line {i + 1} declares {declared} nodes but lists "
                       f"{len(ids)} (lines {i + 3}-{j}): the file is corrupt or truncated")
    return np.asarray(ids, dtype=np.int64), np.asarray(xyz, dtype=float).reshape(-1, 3), j + 1


#: The 11 header fields of a solid EBLOCK record.
_EBLOCK_FIELDS = ("material", "element type", "real constant", "section", "coordinate system", "birth/death",
                  "solid model reference", "shape", "node count", "exclude key", "element number")


def _eblock(lines: list[str], i: int, source: str) -> tuple[list, int]:
    if "SOLID" not in lines[i].upper():
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: only the solid EBLOCK format is read "
                       f"(EBLOCK,...,SOLID,...), got {lines[i].strip()!r}")
    widths = [w for _, w in _format(lines, i + 1, source)]
    declared = _declared_count(lines[i], source, i)
    out = []
    j = i + 2
    while j < len(lines):
        f = _fields(lines[j], widths)
        if not f or _int(f[0], source, j, "field 1 (material, or -1 ending the EBLOCK)") == -1:
            if declared is not None and declared != len(out):
                raise CdbError(f"ANSYS archive {source!r}: the EBLOCK of line {i + 1} declares {declared} elements "
                               f"but lists {len(out)} (up to line {j + 1}): the file is corrupt or truncated")
            return out, j + 1
        if len(f) < 11:
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: not an element record of the solid EBLOCK "
                           f"format: {len(f)} field(s), expected 11 header fields ({', '.join(_EBLOCK_FIELDS)}) "
                           f"then the nodes: {lines[j]!r}")
        v = [_int(x, source, j, f"field {k + 1} ({_EBLOCK_FIELDS[k] if k < 11 else f'node {k - 10}'})")
             for k, x in enumerate(f)]
        count, nodes, start = v[8], v[11:], j
        if not 1 <= count <= MAX_ELEMENT_NODES:
            raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: field 9 (node count) is {count}, expected "
                           f"1..{MAX_ELEMENT_NODES}")
        number = _number(v[10], source, j, "element number (field 11)")
        while len(nodes) < count:  # continuation lines
            j += 1
            if j >= len(lines):
                raise CdbError(f"ANSYS archive {source!r}, line {start + 1}: element {number} lists {len(nodes)} "
                               f"of its {count} nodes before the end of the file: the file is truncated")
            more = _fields(lines[j], widths)
            if not more:
                raise CdbError(f"ANSYS archive {source!r}, line {j + 1}: element {number} (line {start + 1}) "
                               f"lists {len(nodes)} of its {count} nodes, then an empty line")
            nodes += [_int(x, source, j, f"node {len(nodes) + k + 1} of element {number}")
                      for k, x in enumerate(more)]
        out.append((v[1], number, nodes[:count], start, v[0]))
        j += 1
    raise CdbError(f"ANSYS archive {source!r}: the EBLOCK of line {i + 1} has no end (-1): the file is truncated")


def _cmblock(lines: list[str], i: int, source: str) -> tuple[str, str, list[tuple[int, int, int]], int]:
    """``(name, kind, ranges, next line)``: the component's members as inclusive number ranges ``(first, last,
    line)`` (a single number is the range ``n..n``; ``line`` 0-based)."""
    parts = [p.strip() for p in lines[i].split("!")[0].split(",")]
    if len(parts) < 4 or parts[2].upper() not in ("NODE", "ELEM"):
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: expected CMBLOCK,name,NODE|ELEM,count, got "
                       f"{lines[i].strip()!r}")
    name, kind = parts[1], parts[2].upper()
    count = _int(parts[3], source, i, f"the entry count of component {name!r}")
    if count < 0:
        raise CdbError(f"ANSYS archive {source!r}, line {i + 1}: component {name!r} has {count} entries (>= 0)")
    widths = [w for _, w in _format(lines, i + 1, source)]
    values: list[tuple[int, int]] = []  # (value, line)
    j = i + 2
    while len(values) < count and j < len(lines):
        values += [(_int(x, source, j, f"an entry of component {name!r}"), j) for x in _fields(lines[j], widths)]
        j += 1
    if len(values) < count:
        raise CdbError(f"ANSYS archive {source!r}: component {name!r} (line {i + 1}) lists {len(values)} of its "
                       f"{count} entries before the end of the file: the file is truncated")
    what = "node" if kind == "NODE" else "element"
    ranges: list[tuple[int, int, int]] = []
    for v, line in values[:count]:
        if v < 0:
            if not ranges or ranges[-1][0] != ranges[-1][1]:
                raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: component {name!r}: the entry {v} closes "
                               "a range (a negative entry follows the range's first number), but no first number "
                               "precedes it")
            lo = ranges[-1][0]
            hi = _number(-v, source, line, f"component {name!r}: {what} number")
            if hi < lo:
                raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: component {name!r}: the range {lo}..{hi} "
                               "runs backwards")
            ranges[-1] = (lo, hi, ranges[-1][2])
        elif v > 0:
            v = _number(v, source, line, f"component {name!r}: {what} number")
            ranges.append((v, v, line))
        else:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: component {name!r}: entry 0 is not a "
                           f"{what} number (1..{MAX_NUMBER}, or a negative number closing a range)")
    return name, kind, ranges, j


def _numbering(have: np.ndarray, what: str) -> str:
    """How the file numbers its nodes or elements (``have``: their numbers, sorted), e.g. "the file has 412 nodes,
    numbered 1 to 412"."""
    plural = what if have.size == 1 else f"{what}s"
    return f"the file has {have.size} {plural}, numbered {have[0]} to {have[-1]}"


def _check_component(name: str, what: str, ranges: list[tuple[int, int, int]], have: np.ndarray, source: str) -> None:
    """A :class:`CdbError` when component ``name`` names a ``what`` (node or element) the file does not have: a
    single number not in ``have`` (the file's numbers, sorted), a range reaching beyond them or holding none of
    them (see the module docstring). Binary searches over ``have``: no range is expanded."""
    if not ranges:
        return
    lo, hi, line = (np.asarray(column, dtype=np.int64) for column in zip(*ranges))
    inside = np.searchsorted(have, hi, "right") - np.searchsorted(have, lo)  # numbers of the file in each range
    single = lo == hi
    bad = (inside == 0) | (~single & ((lo < have[0]) | (hi > have[-1])))
    if not bad.any():
        return
    k = int(np.flatnonzero(bad)[0])
    where = f"ANSYS archive {source!r}, line {line[k] + 1}: component {name!r} names"
    more = f"; {int(bad.sum()) - 1} more of its entries name numbers the file does not have" if bad.sum() > 1 else ""
    if single[k]:
        raise CdbError(f"{where} {what} {lo[k]}, which the file does not have ({_numbering(have, what)}){more}")
    how = "none of which the file has" if have[0] <= lo[k] and hi[k] <= have[-1] else f"beyond the file's {what}s"
    raise CdbError(f"{where} {what}s {lo[k]}..{hi[k]}, {how} ({_numbering(have, what)}){more}")


def _cells(elements, types: dict[int, int], index: _NodeIndex, source: str):
    """Cells by meshio type (node indices), element counts by ANSYS type, and each element's node indices."""
    cells: dict[str, list[list[int]]] = {}
    counts: dict[str, int] = {}
    by_number: dict[int, list[int]] = {}
    skipped: dict[int, int] = {}
    for itype, number, nodes, line, _ in elements:
        ename = types.get(itype)
        if ename is None:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} has type {itype}, which no "
                           "ET record defines")
        found = index.find(nodes)
        if (found < 0).any():
            bad = nodes[int(np.flatnonzero(found < 0)[0])]
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element {number} uses node {bad}, which "
                           "the NBLOCK does not define")
        idx = found.tolist()
        if number in by_number:
            raise CdbError(f"ANSYS archive {source!r}, line {line + 1}: element number {number} is used twice; "
                           "element numbers must be unique")
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
