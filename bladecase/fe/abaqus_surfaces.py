"""Element-based surfaces of an Abaqus/CalculiX deck (``*SURFACE, NAME=…, TYPE=ELEMENT``, the default type), read
by :func:`bladecase.fe.abaqus.read_abaqus` as node groups: every node of the named element faces, corner and
midside nodes, so that a cyclic face of a ``*TIE, CYCLIC SYMMETRY`` or a contact face written as element faces is
used exactly as the same face written as a node set.

A surface line is ``element or element set, face label``: ``12, S3`` or ``BLADE_LEFT, S1``.  The face labels and
their nodes are those of the Abaqus and CalculiX manuals (CalculiX's own tables ``ifaceq``, ``ifacet``,
``ifacew1``, ``ifacew2``, ``ifacequad``, ``ifacetria`` hold the same node sets), :data:`FACE_NODES`:

* ``C3D4``/``C3D10`` (tetrahedra): S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1;
* ``C3D6``/``C3D15`` (wedges): S1 = 1-2-3, S2 = 4-5-6, S3 = 1-2-5-4, S4 = 2-3-6-5, S5 = 3-1-4-6;
* ``C3D8``/``C3D20`` (hexahedra): S1 = 1-2-3-4, S2 = 5-8-7-6, S3 = 1-5-6-2, S4 = 2-6-7-3, S5 = 3-7-8-4,
  S6 = 4-8-5-1;
* plane ``CPS``/``CPE`` 3, 4, 6, 8: the edges S1 = 1-2, S2 = 2-3, S3 = 3-1 (triangles) or 3-4, S4 = 4-1;

and a quadratic element's face adds the midside nodes of its edges.

A line **without a face label** (``EALL`` or ``EALL,``) is, as in Abaqus, the **free faces** of its elements: every
face of them that no other element of the whole mesh shares (its corner nodes those of exactly one element face of
the deck) — for solid elements the exterior faces of the body among them, for plane elements the outline edges.  A
face two elements share (inside the body, or between the set and the rest of the mesh) is not free.  CalculiX
(2.21, ``surfaces.f``) reads only lines with a label S1 … S6: a deck that CalculiX also runs keeps them.

A face label the element type does not have, an element number the deck does not define, an element set it does not
define, a line without an element, a line without a label whose elements have no free face, and an element of a type
bladecase leaves out (shells, beams) are errors naming the line and what is valid.
"""

from __future__ import annotations

import re

import numpy as np

from .. import log
from .abaqus_sets import AbaqusError, at_line

#: Nodes (1-based, in the element's node order as the deck writes it) of each face label, per element kind (the
#: meshio type the reader gives the element): corners first, then the midside nodes of a quadratic element.
FACE_NODES: dict[str, dict[str, tuple[int, ...]]] = {
    "tetra": {"S1": (1, 2, 3), "S2": (1, 4, 2), "S3": (2, 4, 3), "S4": (3, 4, 1)},
    "tetra10": {"S1": (1, 2, 3, 5, 6, 7), "S2": (1, 4, 2, 8, 9, 5), "S3": (2, 4, 3, 9, 10, 6),
                "S4": (3, 4, 1, 10, 8, 7)},
    "wedge": {"S1": (1, 2, 3), "S2": (4, 5, 6), "S3": (1, 2, 5, 4), "S4": (2, 3, 6, 5), "S5": (3, 1, 4, 6)},
    "wedge15": {"S1": (1, 2, 3, 7, 8, 9), "S2": (4, 5, 6, 10, 11, 12), "S3": (1, 2, 5, 4, 7, 14, 10, 13),
                "S4": (2, 3, 6, 5, 8, 15, 11, 14), "S5": (3, 1, 4, 6, 9, 13, 12, 15)},
    "hexahedron": {"S1": (1, 2, 3, 4), "S2": (5, 8, 7, 6), "S3": (1, 5, 6, 2), "S4": (2, 6, 7, 3),
                   "S5": (3, 7, 8, 4), "S6": (4, 8, 5, 1)},
    "hexahedron20": {"S1": (1, 2, 3, 4, 9, 10, 11, 12), "S2": (5, 8, 7, 6, 16, 15, 14, 13),
                     "S3": (1, 5, 6, 2, 17, 13, 18, 9), "S4": (2, 6, 7, 3, 18, 14, 19, 10),
                     "S5": (3, 7, 8, 4, 19, 15, 20, 11), "S6": (4, 8, 5, 1, 20, 16, 17, 12)},
    "triangle": {"S1": (1, 2), "S2": (2, 3), "S3": (3, 1)},
    "triangle6": {"S1": (1, 2, 4), "S2": (2, 3, 5), "S3": (3, 1, 6)},
    "quad": {"S1": (1, 2), "S2": (2, 3), "S3": (3, 4), "S4": (4, 1)},
    "quad8": {"S1": (1, 2, 5), "S2": (2, 3, 6), "S3": (3, 4, 7), "S4": (4, 1, 8)},
}

#: Element kinds whose faces list their corners first, then as many midside nodes.
_QUADRATIC = frozenset({"tetra10", "wedge15", "hexahedron20", "triangle6", "quad8"})

#: The face "label" of a surface line that has none: the free faces of its elements.
FREE = "free"

#: The element family of each kind, for the messages.
_FAMILY = {"tetra": "C3D4", "tetra10": "C3D10", "wedge": "C3D6", "wedge15": "C3D15", "hexahedron": "C3D8",
           "hexahedron20": "C3D20", "triangle": "CPS3/CPE3", "triangle6": "CPS6/CPE6", "quad": "CPS4/CPE4",
           "quad8": "CPS8/CPE8"}


def face_nodes(kind: str, label: str) -> tuple[int, ...]:
    """The nodes (1-based, in the element's node order) of face ``label`` of an element of meshio type ``kind``;
    ``KeyError`` for a kind or label it does not have.

    >>> face_nodes("hexahedron", "S2"), face_nodes("tetra10", "s4")
    ((5, 8, 7, 6), (3, 4, 1, 10, 8, 7))
    """
    return FACE_NODES[kind][label.strip().upper()]


def record_surface(deck, place: tuple[str, int], params: dict, data: list) -> None:
    """Keep the lines of an element-based ``*SURFACE`` (``TYPE=ELEMENT``, the default) for :func:`surface_nodes`,
    once the whole deck is read (its elements and element sets may come later); a surface named twice gathers both
    blocks.  A surface without ``NAME`` cannot be referred to: left out with a log line.

    >>> from types import SimpleNamespace
    >>> deck = SimpleNamespace(surfaces={})
    >>> record_surface(deck, ("s.inp", 3), {"NAME": "Top"}, [(("s.inp", 4), "CUBE, S2")])
    >>> record_surface(deck, ("s.inp", 5), {"NAME": "Side", "TYPE": "NODE"}, [(("s.inp", 6), "7")])  # not here
    >>> deck.surfaces
    {'TOP': ('Top', ('s.inp', 3), [(('s.inp', 4), 'CUBE, S2')])}
    """
    if (params.get("TYPE") or "ELEMENT").upper() != "ELEMENT":
        return
    name = params.get("NAME")
    if not name:
        log.info("%s: *SURFACE without NAME=: left out (nothing can refer to it)", at_line(place))
        return
    deck.surfaces.setdefault(name.upper(), (name, place, []))[2].extend(data)


def surface_nodes(deck, numbers) -> dict[str, np.ndarray]:
    """``{surface name as written: its node numbers (sorted, unique)}`` of the deck's element-based surfaces
    (:func:`record_surface`), every line checked against the deck's elements, element sets and face labels
    (``numbers``: the deck's :class:`~bladecase.fe.abaqus_sets.Numbers`).  :func:`~bladecase.fe.abaqus.read_abaqus`
    makes them groups:

    >>> import os, tempfile
    >>> from bladecase.fe.abaqus import read_abaqus
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = os.path.join(folder.name, "cube.inp")
    >>> corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    >>> _ = open(path, "w").write("*NODE\\n" + "".join(f"{10 + i}, {x}, {y}, {z}\\n" for i, (x, y, z) in
    ...     enumerate(corners)) + "*ELEMENT, TYPE=C3D8R, ELSET=CUBE\\n7, 10, 11, 12, 13, 14, 15, 16, 17\\n"
    ...     "*SURFACE, NAME=TOP\\nCUBE, S2\\n*SURFACE, NAME=FRONT\\n7, S3\\n")
    >>> m = read_abaqus(path)
    >>> m.point_sets["TOP"].tolist(), m.point_sets["FRONT"].tolist()  # z = 1; y = 0
    ([4, 5, 6, 7], [0, 1, 4, 5])
    >>> folder.cleanup()
    """
    if not deck.surfaces:
        return {}
    owners = {}  # kind -> (its element numbers sorted, their node numbers)
    for kind, rows in deck.elements.items():
        ids = np.array([e for e, _ in rows], dtype=np.int64)
        order = np.argsort(ids, kind="stable")
        owners[kind] = (ids[order], np.array([r for _, r in rows], dtype=np.int64)[order])
    out: dict[str, np.ndarray] = {}
    free: dict = {}  # the free faces of every element, computed once when a line asks for them
    for name, _, lines in deck.surfaces.values():
        labels: dict[str, tuple[list, list, list, list]] = {}  # face label -> its elements, each with its line:
        for where, text in lines:                                  # of its sets, then its numbers (checked at once)
            elements, label = _line_elements(deck, numbers, name, where, text)
            sets, set_places, listed, places = labels.setdefault(label, ([], [], [], []))
            if isinstance(elements, int):
                listed.append(elements)
                places.append(where)
            else:
                sets.append(elements)
                set_places += [where] * elements.size
        parts = [np.zeros(0, dtype=np.int64)]
        for label, (sets, set_places, listed, places) in labels.items():
            if listed:
                sets.append(numbers.listed(listed, places, "element", f"*SURFACE, NAME={name}"))
            if label == FREE and not free:
                free.update(free_faces(owners))
            parts += _faces_of(owners, deck, name, set_places + places, np.concatenate(sets), label, free)
        out[name] = np.unique(np.concatenate(parts))
    return out


def free_faces(owners: dict) -> dict[str, np.ndarray]:
    """``{kind: (elements, faces) bool}``: which faces of every element (in the order of ``FACE_NODES[kind]``) are
    free — no other element face of the mesh has the same corner nodes. ``owners``: ``{kind: (element numbers,
    their node numbers)}``.

    Two hexahedra sharing the face ``5-6-7-8``: each has five free faces, the shared one is not free.

    >>> conn = np.array([[1, 2, 3, 4, 5, 6, 7, 8], [5, 6, 7, 8, 9, 10, 11, 12]])
    >>> free_faces({"hexahedron": (np.array([1, 2]), conn)})["hexahedron"].astype(int).tolist()
    [[1, 0, 1, 1, 1, 1], [0, 1, 1, 1, 1, 1]]
    """
    keys, sizes = [], []
    for kind, (ids, conn) in owners.items():
        for nodes in FACE_NODES[kind].values():
            n = len(nodes) // 2 if kind in _QUADRATIC else len(nodes)  # the face's corners
            corners = np.sort(conn[:, np.array(nodes[:n]) - 1], axis=1)
            keys.append(np.pad(corners, ((0, 0), (0, 4 - n)), constant_values=-1))
        sizes.append((kind, ids.size, len(FACE_NODES[kind])))
    _, inverse, counts = np.unique(np.concatenate(keys), axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    out, start = {}, 0
    for kind, count, faces in sizes:
        out[kind] = once[start:start + count * faces].reshape(faces, count).T
        start += count * faces
    return out


def _line_elements(deck, numbers, name: str, where, text: str) -> tuple[np.ndarray | int, str]:
    """The element numbers (of a set; one number, not checked yet) and the face label of one surface line
    (:data:`FREE` without one)."""
    fields = [f.strip() for f in text.split(",")]
    owner = f"*SURFACE, NAME={name}"
    if not fields[0]:
        raise AbaqusError(f"{at_line(where)}: {owner}: an element-based surface line is 'element or element set, "
                          f"face label' (e.g. '12, S3'; S1 … S6 for a solid element), or 'element or element set' "
                          f"alone for the free faces of its elements, got {text!r}")
    target = fields[0]
    label = fields[1].upper() if len(fields) > 1 and fields[1] else FREE
    if re.fullmatch(r"[+-]?\d+", target):
        return int(target), label
    if target.upper() not in deck.elsets:
        have = ", ".join(sorted(v[0] for v in deck.elsets.values())[:20]) or "none"
        raise AbaqusError(f"{at_line(where)}: {owner} names the element set {target!r}, which the deck does not "
                          f"define (*ELSETs: {have})")
    written, members = deck.elsets[target.upper()]
    return numbers.elements(members, f"*ELSET {written!r}"), label


def _faces_of(owners, deck, name: str, places: list, elements: np.ndarray, label: str,
              free: dict) -> list[np.ndarray]:
    """The node numbers of face ``label`` of each of ``elements`` (``places``: the line naming each), by kind; for
    :data:`FREE`, of each of their free faces (``free``: :func:`free_faces`)."""
    found = np.zeros(elements.size, dtype=bool)
    parts = []
    for kind, (ids, conn) in owners.items():
        k = np.minimum(np.searchsorted(ids, elements), ids.size - 1)
        inside = ids[k] == elements
        if not inside.any():
            continue
        found |= inside
        faces = FACE_NODES[kind]
        if label == FREE:
            rows, mask = conn[k[inside]], free[kind][k[inside]]
            parts += [rows[mask[:, i]][:, np.array(nodes) - 1].ravel() for i, nodes in enumerate(faces.values())]
            continue
        if label not in faces:
            first = int(np.flatnonzero(inside)[0])
            raise AbaqusError(f"{at_line(places[first])}: *SURFACE, NAME={name}: element {elements[first]} is a "
                              f"{_FAMILY[kind]} ({kind}), whose faces are {', '.join(faces)}; got face label "
                              f"{label!r}")
        parts.append(conn[k[inside]][:, np.array(faces[label]) - 1].ravel())
    if not found.all():
        first = int(np.flatnonzero(~found)[0])
        raise AbaqusError(f"{at_line(places[first])}: *SURFACE, NAME={name}: element {elements[first]} is of a type "
                          f"bladecase leaves out (left out: {', '.join(sorted(deck.left_out)) or 'none'}): faces "
                          "are read of solid elements C3D4, C3D6, C3D8, C3D10, C3D15, C3D20 and plane CPS/CPE 3, 4, "
                          "6, 8")
    if label == FREE and not sum(p.size for p in parts):
        raise AbaqusError(f"{at_line(places[0])}: *SURFACE, NAME={name}: a line without a face label is the free "
                          f"faces of its elements, but none of these {elements.size} element(s) has a free face "
                          "(each face is shared with another element of the mesh): give their face labels, e.g. "
                          "'12, S3'")
    return parts
