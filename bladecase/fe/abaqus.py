"""Abaqus keyword files — Abaqus ``.inp``, and CalculiX's ``.inp``/``.msh``/``.nam`` — read into a ``meshio.Mesh``.

meshio's own Abaqus reader drops the node numbers, follows no ``*INCLUDE`` relative to the including file, keeps
only the last ``*NODE`` block and reads no ``*BOUNDARY``; :func:`read_abaqus` reads a whole deck:

* ``*INCLUDE, INPUT=file`` followed, relative to the including file, nested (a missing file names both files);
* ``*NODE`` blocks (any number; node numbers in any order, gaps allowed) — the numbers are kept as the point data
  :data:`NODE_ID_KEY`, so that every message can name a node as the file does;
* ``*ELEMENT, TYPE=…``: solids ``C3D4``, ``C3D6``, ``C3D8``, ``C3D10``, ``C3D15``, ``C3D20`` and their variants
  (``R``, ``H``, ``I``, ``M``, ``T``, …: ``C3D20R``, ``C3D8I``, ``C3D10MH``), plane ``CPS3/4/6/8``, ``CPE3/4/6/8``
  (same variants); other elements (shells, beams, springs, masses, axisymmetric ``CAX``) are left out with a log
  line counting them;
* ``*NSET`` / ``*ELSET`` (``GENERATE``, nested set names, case-insensitive as in Abaqus) as named node groups
  (``point_sets``; an element set becomes the nodes of its elements; ``*NSET, NSET=…, ELSET`` the nodes of the
  elements it lists);
* ``*BOUNDARY`` (node numbers or node sets, a dof range or ``ENCASTRE``, ``PINNED``, ``XSYMM``, …) as the groups
  ``boundary`` (every node with a fixed dof), ``boundary_fixed`` (the nodes whose three translations are all
  fixed, by one line or several) and ``boundary_<first>_<last>`` per dof range as written (``boundary_1_3``;
  ``ENCASTRE`` is ``boundary_1_6``, ``PINNED`` ``boundary_1_3``, ``XSYMM`` ``boundary_xsymm``); a prescribed
  non-zero displacement is not a fixed dof.
* ``*SURFACE, NAME=…``: node-based (``TYPE=NODE``: node numbers or node sets) and element-based (``TYPE=ELEMENT``,
  the default: ``element or element set, S1 … S6``, :mod:`~bladecase.fe.abaqus_surfaces`) surfaces as node groups
  of their name — every node of the faces, midside nodes included — e.g. the cyclic faces of a ``*TIE``.
* ``*MATERIAL`` with its ``*ELASTIC`` (isotropic ``E, nu``) and ``*DENSITY``, and the ``*SOLID SECTION, ELSET=…,
  MATERIAL=…`` lines that give the elements their material: the material of the body's elements (the deck's only
  one when no section names one) is the mesh's ``info["material"]`` (:attr:`bladecase.fe.mesh.Mesh.material`, in
  the deck's units). Body elements of several materials, a table over temperatures, an anisotropic ``*ELASTIC`` or
  a missing ``*DENSITY`` are recorded as the reason it cannot be used, raised only when a model needs it
  (:func:`bladecase.fe.material.mesh_material`): a study's ``[material]`` replaces it.

A set or a ``*BOUNDARY`` line must name nodes and elements the deck defines, or the study would run on a group
that silently lost members:

* a listed node or element number the deck does not define is an error (CalculiX warns about a node number above
  its largest one and leaves it out: a misspelt number would quietly shrink a clamp);
* a ``GENERATE`` range ``first, last, step`` is an error when it reaches below the deck's smallest number or
  beyond its largest one, or holds none of its numbers (CalculiX stops when ``first`` is beyond its largest number,
  and warns and cuts ``last`` down to it: here both are errors);
* inside the deck's numbering, the numbers of a range that a gappy numbering leaves out are skipped without a
  word, as CalculiX does (it keeps the range as written and says nothing of the numbers no node has): ``1, 99``
  over nodes 1, 3, …, 99 names those 50 nodes.

Each error names the file, the line, the set, the number or range and the deck's numbering ("the file has 412
nodes, numbered 1 to 412"). Ranges are checked by binary search before anything is expanded, so ``1, 1000000000``
costs no memory. Sets are checked once the whole deck is read (a set may name nodes defined further down), and a
``*BOUNDARY`` line naming a node set takes the whole set.

Coordinates are taken as they are (the length unit is the study's ``[mesh] unit``). Errors name the file, the line
and what was expected. :func:`looks_like_abaqus` tells an Abaqus-syntax file from its content (a CalculiX ``.msh``).

>>> import tempfile, os
>>> folder = tempfile.TemporaryDirectory()
>>> _ = open(os.path.join(folder.name, "cube.msh"), "w").write('''*NODE, NSET=NALL
... 101, 0, 0, 0
... 103, 1, 0, 0
... 105, 1, 1, 0
... 107, 0, 1, 0
... 109, 0, 0, 1
... 111, 1, 0, 1
... 113, 1, 1, 1
... 115, 0, 1, 1
... *ELEMENT, TYPE=C3D8R, ELSET=EALL
... 7, 101, 103, 105, 107, 109, 111, 113, 115
... ''')
>>> _ = open(os.path.join(folder.name, "cube.inp"), "w").write('''*INCLUDE, INPUT=cube.msh
... *BOUNDARY
... 101, 1, 3
... 103, 1, 3
... 105, 1, 1
... 105, 2, 3
... ''')
>>> m = read_abaqus(os.path.join(folder.name, "cube.inp"))
>>> m.cells[0].type, m.cells[0].data.tolist(), m.point_data[NODE_ID_KEY].tolist()
('hexahedron', [[0, 1, 2, 3, 4, 5, 6, 7]], [101, 103, 105, 107, 109, 111, 113, 115])
>>> {k: v.tolist() for k, v in sorted(m.point_sets.items())}  # doctest: +NORMALIZE_WHITESPACE
{'EALL': [0, 1, 2, 3, 4, 5, 6, 7], 'NALL': [0, 1, 2, 3, 4, 5, 6, 7], 'boundary': [0, 1, 2],
 'boundary_1_1': [2], 'boundary_1_3': [0, 1], 'boundary_2_3': [2], 'boundary_fixed': [0, 1, 2]}
>>> looks_like_abaqus(os.path.join(folder.name, "cube.msh"))
True
>>> folder.cleanup()
"""

from __future__ import annotations

import os
import re

import numpy as np

from .. import log
from .abaqus_sets import (
    AbaqusError,
    Numbers,
    body_material,
    boundary_groups,
    cyclic_records,
    log_boundary,
    node_surface,
)
from .abaqus_sets import at_line as _where
from .abaqus_surfaces import record_surface, surface_nodes
from .abaqus_write import ABAQUS_TYPES, abaqus_text, node_numbers  # noqa: F401  (public names of this module)
from .groups import NODE_ID_KEY  # the point-data key of the file's node numbers (Mesh.node_ids)
from .mesh_checks import SNIFFERS, check_input_file

#: Corner/quadratic node count of the solid and plane elements → meshio type (Abaqus and VTK share node orders).
_SOLID = {4: "tetra", 10: "tetra10", 6: "wedge", 15: "wedge15", 8: "hexahedron", 20: "hexahedron20"}
_PLANE = {3: "triangle", 6: "triangle6", 4: "quad", 8: "quad8"}
_ELEMENT_NAME = re.compile(r"^(C3D|CPS|CPE)(\d+)([A-Z]*)$")

#: Fixed dofs of the named ``*BOUNDARY`` types, and the group each makes.
_NAMED_BC = {"ENCASTRE": ((1, 2, 3, 4, 5, 6), "boundary_1_6"), "PINNED": ((1, 2, 3), "boundary_1_3"),
             "XSYMM": ((1, 5, 6), "boundary_xsymm"), "YSYMM": ((2, 4, 6), "boundary_ysymm"),
             "ZSYMM": ((3, 4, 5), "boundary_zsymm"), "XASYMM": ((2, 3, 4), "boundary_xasymm"),
             "YASYMM": ((1, 3, 5), "boundary_yasymm"), "ZASYMM": ((1, 2, 6), "boundary_zasymm")}

#: Deepest chain of ``*INCLUDE`` files followed.
MAX_INCLUDE_DEPTH = 32

#: Bytes of a file's beginning searched by :func:`looks_like_abaqus`.
SNIFF_BYTES = 65536


def element_type(name: str) -> tuple[str, int] | None:
    """``(meshio type, nodes)`` of an Abaqus/CalculiX solid or plane element name, ``None`` for the elements
    left out.

    >>> element_type("C3D20R"), element_type("c3d15"), element_type("CPS8R"), element_type("S8R")
    (('hexahedron20', 20), ('wedge15', 15), ('quad8', 8), None)
    """
    m = _ELEMENT_NAME.match(name.strip().upper())
    if m is None or "V" in m.group(3):  # C3D15V, C3D27: variable node counts
        return None
    kind = (_SOLID if m.group(1) == "C3D" else _PLANE).get(int(m.group(2)))
    return None if kind is None else (kind, int(m.group(2)))


def looks_like_abaqus(path: str | os.PathLike) -> bool:
    """True when the file's beginning holds an Abaqus keyword line ``*NODE``, ``*ELEMENT`` or ``*INCLUDE``."""
    with open(path, "rb") as fh:
        head = fh.read(SNIFF_BYTES).decode("latin-1")
    return re.search(r"^[ \t]*\*[ \t]*(NODE|ELEMENT|INCLUDE)[ \t]*(,|\r?$)", head, re.I | re.M) is not None


def _params(text: str) -> tuple[str, dict[str, str | None]]:
    """``(KEYWORD, {PARAMETER: value or None})`` of a keyword line; keywords and parameter names upper case."""
    fields = [f.strip() for f in text.strip().lstrip("*").split(",")]
    params: dict[str, str | None] = {}
    for f in fields[1:]:
        if f:
            key, eq, value = f.partition("=")
            params[" ".join(key.split()).upper()] = value.strip().strip('"').strip() if eq else None
    return " ".join(fields[0].split()).upper(), params


def _read_text(path: str, place: tuple[str, int] | None = None, target: str = "") -> list[str]:
    """The lines of ``path``; ``AbaqusError`` naming the including file and line (``place``) when it is missing."""
    by = f"{_where(place)}: *INCLUDE, INPUT={target}: " if place else ""
    if place and not os.path.exists(path):
        raise AbaqusError(f"{by}no such file {path!r} (an include is found relative to the folder of the file that "
                          "includes it)")
    try:
        check_input_file(path, "Abaqus file")
    except ValueError as exc:
        raise AbaqusError(f"{by}{exc}") from None
    with open(path, "rb") as fh:
        data = fh.read()
    if not data.endswith((b"\n", b"\r")):
        last = data.rstrip().rsplit(b"\n", 1)[-1][-60:].decode("latin-1")
        raise AbaqusError(f"{by}Abaqus file {path!r} is truncated or corrupt: it does not end with a line break "
                          f"(its last line: {last!r}); if the file is complete, end it with a line break")
    return data.decode("latin-1").splitlines()


def _blocks(path: str):
    """``(place, keyword, params, data)`` per keyword line of ``path`` with its ``*INCLUDE`` files read in place
    (an included file may hold whole blocks or the data lines of the block before it); ``data``: the
    ``(place, text)`` of its data lines (comments and blank lines left out)."""
    stack = [[os.path.abspath(path), 0, _read_text(path)]]
    block = None
    while stack:
        top = stack[-1]
        name, lines = top[0], top[2]
        if top[1] >= len(lines):
            stack.pop()
            continue
        place, stripped = (name, top[1] + 1), lines[top[1]].strip()
        top[1] += 1
        if not stripped or stripped.startswith("**"):
            continue
        if not stripped.startswith("*"):
            if block is not None:
                block[3].append((place, stripped))
            continue
        while stripped.endswith(",") and top[1] < len(lines) and "=" in lines[top[1]] \
                and not lines[top[1]].strip().startswith("*"):
            stripped += lines[top[1]].strip()  # a keyword line continued (parameters); a sloppy comma is not one
            top[1] += 1
        keyword, params = _params(stripped)
        if keyword != "INCLUDE":
            if block is not None:
                yield block
            block = (place, keyword, params, [])
            continue
        target = params.get("INPUT")
        if not target:
            raise AbaqusError(f"{_where(place)}: *INCLUDE needs INPUT=<file>, got {stripped!r}")
        full = os.path.normpath(os.path.join(os.path.dirname(name), os.path.expanduser(target)))
        if full in {s[0] for s in stack} or len(stack) >= MAX_INCLUDE_DEPTH:
            chain = " → ".join(repr(s[0]) for s in stack)
            raise AbaqusError(f"{_where(place)}: *INCLUDE, INPUT={target} includes {full!r} again (or too deep): "
                              f"{chain}")
        stack.append([full, 0, _read_text(full, place, target)])
    if block is not None:
        yield block


def _ints(place, text: str, what: str) -> list[int]:
    try:
        return [int(f) for f in text.replace(",", " ").split()]
    except ValueError:
        raise AbaqusError(f"{_where(place)}: expected {what} (integers separated by commas), got {text!r}") from None


class _Members:
    """What one set names, line by line: listed numbers (each with its line) and ``GENERATE`` ranges, of nodes or
    of elements (in a node set, an element stands for its nodes); checked and expanded by :class:`_Numbers` once
    the whole deck is read."""

    def __init__(self):
        self.listed: dict[str, tuple[list[int], list]] = {"node": ([], []), "element": ([], [])}
        self.ranges: list[tuple[tuple[str, int], str, int, int, int]] = []  # (line, kind, first, last, step)

    def add(self, kind: str, numbers, where) -> None:
        """The numbers of ``kind`` (node or element) one line lists."""
        listed, places = self.listed[kind]
        listed += numbers
        places += [where] * len(numbers)

    def extend(self, other: _Members) -> None:
        """Everything ``other`` names (a set named inside another)."""
        for kind, (listed, places) in other.listed.items():
            self.listed[kind][0].extend(listed)
            self.listed[kind][1].extend(places)
        self.ranges += other.ranges


class _Deck:
    """What a deck defines, as it is read."""

    def __init__(self, source: str):
        self.source = source
        self.ids: list[int] = []
        self.xyz: list[list[float]] = []
        self.node_place: list[tuple[str, int]] = []
        self.elements: dict[str, list[tuple[int, list[int]]]] = {}
        self.element_nodes: dict[int, list[int]] = {}  # element number -> node numbers (every element read)
        self.left_out: dict[str, int] = {}
        self.nsets: dict[str, tuple[str, _Members]] = {}  # upper-case name -> (name as written, members)
        self.elsets: dict[str, tuple[str, _Members]] = {}
        self.bcs: list[tuple[tuple[str, int], int | str, tuple[int, ...], str]] = []  # line, node/set, dofs, group
        self.files: set[str] = set()  # the files read (the deck and its includes)
        self.materials: dict[str, dict] = {}  # upper-case name -> name, line, E, nu, rho (file units) or problem
        self.material_now: str | None = None  # the *MATERIAL that *ELASTIC and *DENSITY lines belong to
        self.sections: list[tuple[tuple[str, int], str, str]] = []  # line, ELSET, MATERIAL of each *SOLID SECTION
        self.surfaces: dict[str, tuple[str, tuple[str, int], list]] = {}  # element-based *SURFACEs: name, line, data

    # -------------------------------------------------------------- keywords
    def node(self, place, params, data) -> None:
        members = []
        for where, text in data:
            fields = [f for f in (x.strip() for x in text.split(",")) if f]
            try:
                number, coords = int(fields[0]), [float(x) for x in fields[1:4]]
            except (ValueError, IndexError):
                raise AbaqusError(f"{_where(where)}: a *NODE line is 'number, x, y, z', got {text!r}") from None
            self.ids.append(number)
            self.xyz.append(coords + [0.0] * (3 - len(coords)))
            self.node_place.append(where)
            members.append(number)
        if params.get("NSET"):
            self._add(self.nsets, params["NSET"], "node", members, place)

    def element(self, place, params, data) -> None:
        name = (params.get("TYPE") or "").upper()
        if not name:
            raise AbaqusError(f"{_where(place)}: *ELEMENT needs TYPE=<element type> (e.g. C3D20R)")
        known = element_type(name)
        if known is None:
            records = [r for r in self._records(data) if r]
            self.left_out[name] = self.left_out.get(name, 0) + len(records)
            for numbers in records:
                self.element_nodes[numbers[0]] = numbers[1:]
            if params.get("ELSET"):
                self._add(self.elsets, params["ELSET"], "element", [r[0] for r in records], place)
            return
        kind, width = known[0], known[1] + 1
        values = [v for where, text in data for v in _ints(where, text, f"{name} element records")]
        if len(values) % width:
            raise AbaqusError(f"{_where(place)}: the {len(values)} numbers under *ELEMENT, TYPE={name} are not "
                              f"records of {width} (element number and {width - 1} nodes): a truncated or corrupt "
                              "file?")
        rows = np.asarray(values, dtype=np.int64).reshape(-1, width)
        block = self.elements.setdefault(kind, [])
        for row in rows.tolist():
            block.append((row[0], row[1:]))
            self.element_nodes[row[0]] = row[1:]
        if params.get("ELSET"):
            self._add(self.elsets, params["ELSET"], "element", rows[:, 0].tolist(), place)

    def sets(self, place, params, data, which: str) -> None:
        table = self.nsets if which == "NSET" else self.elsets
        name = params.get(which)
        if not name:
            raise AbaqusError(f"{_where(place)}: *{which} needs {which}=<name>")
        members = _Members()
        # *NSET, NSET=A, ELSET: the nodes of the elements listed
        kind = "element" if which == "ELSET" or "ELSET" in params else "node"
        named = self.elsets if kind == "element" else self.nsets
        for where, text in data:
            if "GENERATE" in params:
                v = _ints(where, text, "'first, last, step' of a GENERATE set")
                if len(v) not in (2, 3) or (len(v) == 3 and v[2] <= 0) or v[1] < v[0]:
                    raise AbaqusError(f"{_where(where)}: a GENERATE line is 'first, last[, step]' with first <= "
                                      f"last and step > 0, got {text!r}")
                members.ranges.append((where, kind, v[0], v[1], v[2] if len(v) == 3 else 1))
                continue
            fields = [f.strip() for f in text.split(",") if f.strip()]
            members.add(kind, [int(f) for f in fields if re.fullmatch(r"[+-]?\d+", f)], where)
            itself = table.get(name.upper(), (None, None))[1]
            for f in fields:
                if re.fullmatch(r"[+-]?\d+", f) is None:  # a set named in it
                    other = self._lookup(named, f, where, "ELSET" if kind == "element" else which)[1]
                    if other is not itself:
                        members.extend(other)
        written, have = table.get(name.upper(), (name, _Members()))
        have.extend(members)
        table[name.upper()] = (written, have)

    def material(self, place, params) -> None:
        name = params.get("NAME") or "?"
        self.materials[name.upper()] = {"name": name, "place": place}
        self.material_now = name.upper()

    def material_option(self, place, keyword: str, params, data) -> None:
        """``*ELASTIC`` (isotropic ``E, nu``) or ``*DENSITY`` of the ``*MATERIAL`` above. What bladecase cannot use
        (another elastic type, a table over temperatures, a field that is no number) is recorded as the material's
        problem, not raised: a study that gives ``[material]`` does not need the deck's."""
        if self.material_now is None:
            log.info("%s: *%s outside a *MATERIAL definition: left out", _where(place), keyword)
            return
        record = self.materials[self.material_now]
        kind = (params.get("TYPE") or "ISOTROPIC").upper()
        rows = [(where, [f.strip() for f in text.split(",") if f.strip()]) for where, text in data]
        need = 2 if keyword == "ELASTIC" else 1
        try:
            values = [[float(f) for f in fields[:need]] for _, fields in rows]
        except ValueError:
            where, fields = next((w, f) for w, f in rows if not all(_number(x) for x in f[:need]))
            record.setdefault("problem", f"{_where(where)}: *{keyword} line {', '.join(fields)!r} is not numbers")
            return
        if keyword == "ELASTIC" and kind not in ("ISO", "ISOTROPIC"):
            record.setdefault("problem", f"*ELASTIC, TYPE={kind} ({_where(place)}): bladecase's materials are "
                              "isotropic (E, nu)")
        elif len(values) != 1 or len(values[0]) < need:
            what = "E, nu" if keyword == "ELASTIC" else "the density"
            got = f"{len(values)} lines (a table over temperatures)" if len(values) > 1 else f"no {what}"
            record.setdefault("problem", f"*{keyword} ({_where(place)}) has {got}: bladecase takes one {what}")
        elif keyword == "ELASTIC":
            record["E"], record["nu"] = values[0]
        else:
            record["rho"] = values[0][0]

    def bc(self, place, params, data) -> None:
        if (params.get("TYPE") or "DISPLACEMENT").upper() != "DISPLACEMENT":
            return  # velocities, accelerations: not fixed dofs
        for where, text in data:
            fields = [f.strip() for f in text.split(",")]
            if len(fields) < 2 or not fields[0]:
                raise AbaqusError(f"{_where(where)}: a *BOUNDARY line is 'node or set, first dof[, last dof[, "
                                  f"value]]', got {text!r}")
            target, first = fields[0], fields[1].upper()
            if first in _NAMED_BC:
                dofs, group = _NAMED_BC[first]
            else:
                try:
                    a = int(first)
                    b = int(fields[2]) if len(fields) > 2 and fields[2] else a
                    value = float(fields[3]) if len(fields) > 3 and fields[3] else 0.0
                except ValueError:
                    raise AbaqusError(f"{_where(where)}: a *BOUNDARY line is 'node or set, first dof[, last dof[, "
                                      f"value]]' (or a type such as ENCASTRE), got {text!r}") from None
                if not 1 <= a <= b:
                    raise AbaqusError(f"{_where(where)}: *BOUNDARY dofs must be 1 <= first <= last, got {text!r}")
                if value != 0.0:
                    log.info("%s: *BOUNDARY %s prescribes a displacement %g, not a fixed dof: left out of the "
                             "group 'boundary'", _where(where), text, value)
                    continue
                dofs, group = tuple(range(a, b + 1)), f"boundary_{a}_{b}"
            if re.fullmatch(r"[+-]?\d+", target):
                self.bcs.append((where, int(target), dofs, group))
            else:
                self._lookup(self.nsets, target, where, "NSET")  # defined before this line
                self.bcs.append((where, target.upper(), dofs, group))

    # -------------------------------------------------------------- helpers
    @staticmethod
    def _records(data) -> list[list[int]]:
        """Element records of an unknown element type: a line ending with a comma continues on the next."""
        out, current = [], []
        for where, text in data:
            current += _ints(where, text, "element records")
            if not text.rstrip().endswith(","):
                out.append(current)
                current = []
        return out + ([current] if current else [])

    @staticmethod
    def _add(table, name: str, kind: str, numbers, where) -> None:
        written, have = table.get(name.upper(), (name, _Members()))
        have.add(kind, numbers, where)
        table[name.upper()] = (written, have)

    @staticmethod
    def _lookup(table, name: str, where, which: str):
        if name.upper() not in table:
            have = ", ".join(sorted(v[0] for v in table.values())[:20]) or "none"
            raise AbaqusError(f"{_where(where)}: no {which} named {name!r} is defined before this line "
                              f"({which}s: {have})")
        return table[name.upper()]


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


#: Keywords that end a ``*MATERIAL`` definition (its options — ``*ELASTIC``, ``*DENSITY``, ``*EXPANSION``, … —
#: follow it up to the next keyword that is not one).
_NOT_MATERIAL_OPTIONS = {"NODE", "ELEMENT", "NSET", "ELSET", "BOUNDARY", "STEP", "SOLID SECTION", "SHELL SECTION",
                         "BEAM SECTION", "MEMBRANE SECTION", "PART", "END PART", "ASSEMBLY", "INSTANCE", "SURFACE",
                         "ORIENTATION", "EQUATION", "AMPLITUDE", "INITIAL CONDITIONS", "HEADING"}


def read_abaqus(path: str | os.PathLike):
    """The mesh of an Abaqus/CalculiX deck as a ``meshio.Mesh`` (see the module docstring for what is read)."""
    import meshio

    source = os.fspath(path)
    deck = _Deck(source)
    for place, keyword, params, data in _blocks(source):
        deck.files.add(place[0])
        if keyword == "NODE":
            deck.node(place, params, data)
        elif keyword == "ELEMENT":
            deck.element(place, params, data)
        elif keyword in ("NSET", "ELSET"):
            deck.sets(place, params, data, keyword)
        elif keyword == "BOUNDARY":
            deck.bc(place, params, data)
        elif keyword == "SURFACE":
            node_surface(deck, place, params, data)
            record_surface(deck, place, params, data)
        if keyword in _NOT_MATERIAL_OPTIONS:
            deck.material_now = None
        if keyword == "MATERIAL":
            deck.material(place, params)
        elif keyword in ("ELASTIC", "DENSITY"):
            deck.material_option(place, keyword, params, data)
        elif keyword == "SOLID SECTION" and params.get("ELSET") and params.get("MATERIAL"):
            deck.sections.append((place, params["ELSET"], params["MATERIAL"]))
    if not deck.ids:
        raise AbaqusError(f"Abaqus file {source!r} defines no node (*NODE): not a mesh (a deck whose mesh is in "
                          "another file needs *INCLUDE, INPUT=<mesh file>)")
    ids = np.asarray(deck.ids, dtype=np.int64)
    order = np.argsort(ids, kind="stable")
    ranked = ids[order]
    twice = np.flatnonzero(ranked[1:] == ranked[:-1])
    if twice.size:
        a, b = order[twice[0]], order[twice[0] + 1]
        raise AbaqusError(f"{_where(deck.node_place[b])}: node {ids[a]} is defined a second time (first at "
                          f"{deck.node_place[a][0]!r}, line {deck.node_place[a][1]}): a deck of several parts "
                          "(*PART, *INSTANCE) is not read; export the assembly as one flat input file")

    def index(numbers, what: str, where) -> np.ndarray:
        numbers = np.asarray(numbers, dtype=np.int64)
        k = np.minimum(np.searchsorted(ranked, numbers), ranked.size - 1)
        found = ranked[k] == numbers
        if not found.all():
            raise AbaqusError(f"{what} refers to node {numbers[~found][0]}, which no *NODE of {where} defines")
        return order[k]

    cells = []
    for kind, rows in deck.elements.items():
        conn = np.asarray([r[1] for r in rows], dtype=np.int64)
        missing = ~np.isin(conn, ranked)
        if missing.any():
            e = rows[int(np.flatnonzero(missing.any(axis=1))[0])][0]
            raise AbaqusError(f"Abaqus file {source!r}: element {e} ({kind}) refers to node "
                              f"{conn[missing][0]}, which no *NODE defines")
        cells.append((kind, index(conn.ravel(), "", source).reshape(conn.shape)))
    if deck.left_out:
        log.info("Abaqus file %s: %s left out (not solid or plane elements)", source,
                 ", ".join(f"{n} {t}" for t, n in sorted(deck.left_out.items())))
    if not cells:
        found = ", ".join(f"{n} × {t}" for t, n in deck.left_out.items()) or "none"
        raise AbaqusError(f"Abaqus file {source!r} has no solid or plane element bladecase reads (found: {found}; "
                          "read: C3D4, C3D6, C3D8, C3D10, C3D15, C3D20 and variants, CPS/CPE 3, 4, 6, 8)")
    numbers = Numbers(ranked, deck.element_nodes, source, deck.files | {p[0] for p in deck.node_place})
    # element sets first: a number is named under the set whose line lists it
    elset_nodes = {key: numbers.nodes(m, f"*ELSET {w!r}") for key, (w, m) in deck.elsets.items()}
    nset_nodes = {key: numbers.nodes(m, f"*NSET {w!r}") for key, (w, m) in deck.nsets.items()}
    point_sets: dict[str, np.ndarray] = {}
    for key, (written, _) in deck.nsets.items():
        point_sets[written] = index(nset_nodes[key], f"*NSET {written!r}", source)
    for key, (written, _) in deck.elsets.items():
        extra = point_sets.get(written, np.zeros(0, dtype=np.int64))
        point_sets[written] = np.union1d(extra, index(elset_nodes[key], f"*ELSET {written!r}", source))
    for written, faces in surface_nodes(deck, numbers).items():
        if written in point_sets:
            log.info("Abaqus file %s: the group %s is the *SURFACE's face nodes (a set of that name is replaced)",
                     source, written)
        point_sets[written] = index(faces, f"*SURFACE {written!r}", source)
    if deck.bcs:
        fixed, full = boundary_groups(deck.bcs, numbers, nset_nodes, lambda n: index(n, "*BOUNDARY", source))
        point_sets.update(fixed)
        point_sets["boundary_fixed"] = full
        log_boundary(source, fixed, full, ids)
    material = body_material(deck, numbers, source)
    return meshio.Mesh(np.asarray(deck.xyz, dtype=float), cells, point_sets=point_sets,
                       point_data={NODE_ID_KEY: ids}, info={"material": material} if material else None)


def read_cyclic(path: str | os.PathLike) -> dict | None:
    """The deck's ``*CYCLIC SYMMETRY MODEL`` and its ``*TIE, CYCLIC SYMMETRY`` (:func:`~.abaqus_sets.cyclic_records`;
    ``None``: the deck has none).  The tie's surfaces, node- or element-based, are groups of :func:`read_abaqus`'s mesh.

    >>> import tempfile, os
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = os.path.join(folder.name, "sector.inp")
    >>> _ = open(path, "w").write('''*NODE
    ... 1, 0, 0, 1
    ... *TIE, NAME=CYC, CYCLIC SYMMETRY, POSITION TOLERANCE=0.01
    ... SRIGHT, SLEFT
    ... *CYCLIC SYMMETRY MODEL, N=24, TIE=CYC
    ... 0, 0, -250, 1, 0, -250
    ... ''')
    >>> c = read_cyclic(path)
    >>> c["sectors"], c["left"], c["right"], c["tol"], c["axis"]
    (24, 'SLEFT', 'SRIGHT', 0.01, ([0.0, 0.0, -250.0], [1.0, 0.0, -250.0]))
    >>> folder.cleanup()
    """
    return cyclic_records(_blocks(os.fspath(path)))


def register() -> None:
    """Teach meshio the format ``"abaqus-deck"`` (this reader, no suffix: meshio's own ``"abaqus"`` keeps
    ``.inp``; :func:`bladecase.fe.load_mesh` chooses this one); idempotent."""
    import meshio
    from meshio import _helpers

    SNIFFERS["abaqus-deck"] = looks_like_abaqus
    if "abaqus-deck" not in _helpers.reader_map:
        meshio.register_format("abaqus-deck", [], read_abaqus, {})
