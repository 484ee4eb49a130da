"""What a parsed Abaqus/CalculiX deck's records mean (:mod:`bladecase.fe.abaqus` reads them): its node and element
numbers, against which every set and ``*BOUNDARY`` line is checked (:class:`Numbers`), the ``*BOUNDARY`` groups,
and the material of the body's elements."""

from __future__ import annotations

import os

import numpy as np

from .. import log
from .mesh_checks import DeckError


class AbaqusError(DeckError):
    """An Abaqus file that cannot be read: the message names the file and the line."""


def at_line(place: tuple[str, int]) -> str:
    """E.g. "Abaqus file 'blade.inp', line 12"."""
    return f"Abaqus file {place[0]!r}, line {place[1]}"


def body_material(deck, numbers: Numbers, source: str) -> dict | None:
    """The material of the body's elements (:func:`bladecase.fe.material.file_material`): the ``*MATERIAL`` that
    the ``*SOLID SECTION`` lines give them, or the deck's only material when no section names one; logged."""
    from .material import file_material

    if not deck.materials:
        return None
    body = np.array(sorted(e for rows in deck.elements.values() for e, _ in rows), dtype=np.int64)
    used: dict[str, int] = {}
    covered = np.zeros(body.size, dtype=bool)
    for place, elset, name in deck.sections:
        if elset.upper() not in deck.elsets:
            log.info("%s: *SOLID SECTION, ELSET=%s: no such *ELSET; left out", at_line(place), elset)
            continue
        inside = np.isin(body, numbers.elements(deck.elsets[elset.upper()][1], f"*ELSET {elset!r}"))
        if inside.any():
            written = deck.materials.get(name.upper(), {"name": name})["name"]
            used[written] = used.get(written, 0) + int(inside.sum())
            covered |= inside
    values = {r["name"]: {k: r[k] for k in ("E", "nu", "rho", "problem") if k in r} for r in deck.materials.values()}
    record = file_material(repr(source), values, used, "", "*MATERIAL")
    if "problem" in record:
        log.info("Abaqus file %s: material(s) %s: %s (a study without [material] is refused)", source,
                 ", ".join(values), record["problem"])
        return record
    place = deck.materials[record["name"].upper()]["place"]
    how = "the *SOLID SECTION of the body's elements" if used else "the deck's only material"
    record["where"] = f"*MATERIAL, NAME={record['name']} of {place[0]!r}, line {place[1]} ({how})"
    if used and not covered.all():
        log.info("Abaqus file %s: %d of the %d body elements are in no *SOLID SECTION", source,
                 int((~covered).sum()), body.size)
    log.info("Abaqus file %s: material %s for the body: E = %g, nu = %g, rho = %g in the deck's units (used when "
             "the study gives no [material])", source, record["name"], record["E"], record["nu"], record["rho"])
    return record


class Numbers:
    """The deck's node and element numbers, against which what a set or a ``*BOUNDARY`` line names is checked
    (module docstring): binary searches, so a range is checked before it is expanded, and expanded only to the
    numbers the deck has."""

    def __init__(self, nodes: np.ndarray, element_nodes: dict[int, list[int]], source: str, files: set[str]):
        elements = np.array(sorted(element_nodes), dtype=np.int64)
        self.have = {"node": nodes, "element": elements}
        sizes = np.fromiter((len(element_nodes[e]) for e in elements.tolist()), dtype=np.int64, count=elements.size)
        self.start = np.concatenate([[0], np.cumsum(sizes)])  # element k's nodes: flat[start[k]:start[k + 1]]
        self.flat = np.fromiter((n for e in elements.tolist() for n in element_nodes[e]), dtype=np.int64,
                                count=int(self.start[-1]))
        self.deck = "the file" if files <= {os.path.abspath(source)} else "the deck"
        self.source = source

    def numbering(self, kind: str) -> str:
        """E.g. "the file has 412 nodes, numbered 1 to 412"."""
        have = self.have[kind]
        whole = self.deck if self.deck == "the file" else f"the deck ({self.source!r} and the files it includes)"
        if not have.size:
            return f"{whole} has no {kind}"
        return f"{whole} has {have.size} {kind}{'s' if have.size > 1 else ''}, numbered {have[0]} to {have[-1]}"

    def nodes(self, members, owner: str) -> np.ndarray:
        """The node numbers (sorted, unique) a set names; ``owner`` (e.g. ``*NSET 'ROOT'``) for the messages."""
        nodes = [self.listed(*members.listed["node"], "node", owner)]
        elements = [self.listed(*members.listed["element"], "element", owner)]
        for where, kind, first, last, step in members.ranges:
            (nodes if kind == "node" else elements).append(self._range(where, kind, first, last, step, owner))
        nodes.append(self._nodes_of(np.concatenate(elements)))
        return np.unique(np.concatenate(nodes))

    def listed(self, numbers, places, kind: str, owner: str) -> np.ndarray:
        """``numbers`` (the line of each in ``places``), when the deck has every one of them."""
        numbers, have = np.asarray(numbers, dtype=np.int64), self.have[kind]
        k = np.minimum(np.searchsorted(have, numbers), max(have.size - 1, 0))
        missing = np.flatnonzero(have[k] != numbers) if have.size else np.arange(numbers.size)
        if missing.size:
            i = missing[0]
            more = f"; {missing.size - 1} more numbers it names are missing too" if missing.size > 1 else ""
            raise AbaqusError(f"{at_line(places[i])}: {owner} names {kind} {numbers[i]}, which {self.deck} does not "
                              f"have ({self.numbering(kind)}){more}")
        return numbers

    def _range(self, where, kind: str, first: int, last: int, step: int, owner: str) -> np.ndarray:
        """The numbers the deck has among ``first, first + step, …, last`` (its gaps skipped)."""
        have = self.have[kind]
        beyond = not have.size or first < have[0] or last > have[-1]
        chosen = have[np.searchsorted(have, first):np.searchsorted(have, last, "right")]
        chosen = chosen[(chosen - first) % step == 0]
        if beyond or not chosen.size:
            how = f"beyond {self.deck}'s {kind}s" if beyond else f"none of which {self.deck} has"
            raise AbaqusError(f"{at_line(where)}: {owner} names {kind}s {first}..{last}"
                              f"{f' step {step}' if step != 1 else ''}, {how} ({self.numbering(kind)})")
        return chosen

    def elements(self, members, owner: str) -> np.ndarray:
        """The element numbers (sorted, unique) an element set names."""
        parts = [self.listed(*members.listed["element"], "element", owner)]
        parts += [self._range(where, kind, first, last, step, owner)
                  for where, kind, first, last, step in members.ranges if kind == "element"]
        return np.unique(np.concatenate(parts))

    def _nodes_of(self, elements: np.ndarray) -> np.ndarray:
        """The node numbers of ``elements`` (numbers the deck has), with repeats."""
        k = np.searchsorted(self.have["element"], elements)
        first, sizes = self.start[k], self.start[k + 1] - self.start[k]
        offsets = np.repeat(first - (np.cumsum(sizes) - sizes), sizes)
        return self.flat[offsets + np.arange(int(sizes.sum()))]


def boundary_groups(bcs, numbers: Numbers, nset_nodes: dict[str, np.ndarray], index):
    """The ``*BOUNDARY`` groups (node positions, see the module docstring) and the positions of the nodes whose
    three translations are fixed; ``index`` maps node numbers to positions."""
    singles = [bc for bc in bcs if isinstance(bc[1], int)]  # one node a line (as cgx writes them): checked at once
    single_pos = index(numbers.listed([bc[1] for bc in singles], [bc[0] for bc in singles], "node", "*BOUNDARY"))
    groups: dict[str, list[np.ndarray]] = {"boundary": [single_pos]}
    bits = np.array([sum(1 << (d - 1) for d in set(bc[2]) if d <= 3) for bc in singles], dtype=np.uint8)
    held = np.zeros(len(numbers.have["node"]), dtype=np.uint8)  # bit d - 1: translation d fixed
    np.bitwise_or.at(held, single_pos, bits)
    labels = np.array([bc[3] for bc in singles], dtype=object)
    for group in dict.fromkeys(labels.tolist()):
        groups.setdefault(group, []).append(single_pos[labels == group])
    for _, target, dofs, group in (bc for bc in bcs if isinstance(bc[1], str)):
        pos = index(nset_nodes[target])
        groups["boundary"].append(pos)
        groups.setdefault(group, []).append(pos)
        held[pos] |= sum(1 << (d - 1) for d in set(dofs) if d <= 3)
    return {g: np.unique(np.concatenate(p)) for g, p in groups.items()}, np.flatnonzero(held == 7)


def log_boundary(source: str, fixed: dict[str, np.ndarray], full: np.ndarray, ids: np.ndarray) -> None:
    groups = ", ".join(f"{g} ({len(m)})" for g, m in sorted(fixed.items()) if g != "boundary")
    log.info("Abaqus file %s: *BOUNDARY fixes %d nodes: group boundary; all three translations fixed: "
             "boundary_fixed (%d); per dof range: %s", source, len(fixed["boundary"]), len(full), groups)
    partial = np.setdiff1d(fixed["boundary"], full)
    if partial.size:
        log.info("Abaqus file %s: %d of the *BOUNDARY nodes have only some translations fixed (symmetry or "
                 "sliding conditions; first: node %d): a clamp fixes all three — clamp = \"boundary_fixed\" takes "
                 "only the nodes fixed in x, y and z", source, partial.size, int(ids[partial].min()))


def node_surface(deck, place, params, data) -> None:
    """``*SURFACE, NAME=…, TYPE=NODE``: its nodes (node numbers or node sets, one a line, an optional weight after
    them) become a node set of the surface's name — a group of the mesh, e.g. a cyclic face of a ``*TIE``. One
    naming a set not defined before it, and a name already taken by a ``*NSET`` (which keeps the set) are left
    out, with a log line. (An element-based surface, the default ``TYPE=ELEMENT``, is read by
    :mod:`~bladecase.fe.abaqus_surfaces`.)"""
    name = params.get("NAME")
    if (params.get("TYPE") or "ELEMENT").upper() != "NODE" or not name:
        return
    if name.upper() in deck.nsets:
        log.info("%s: *SURFACE, NAME=%s: a *NSET has that name: the group is the set", at_line(place), name)
        return
    entries = [(where, text.split(",")[0].strip()) for where, text in data]
    for where, first in entries:
        if not first.lstrip("+-").isdigit() and first.upper() not in deck.nsets:
            log.info("%s: *SURFACE, NAME=%s, TYPE=NODE names %r, no *NSET defined before it: the surface is no mesh "
                     "group", at_line(where), name, first)  # (a set defined later, another kind of entry)
            return
    deck._add(deck.nsets, name, "node", [], place)  # the surface's set, then what each line names
    members = deck.nsets[name.upper()][1]
    for where, first in entries:
        if first.lstrip("+-").isdigit():
            members.add("node", [int(first)], where)
        else:
            members.extend(deck.nsets[first.upper()][1])


def _floats(where, text: str, count: int, what: str) -> list[float]:
    fields = [f.strip() for f in text.split(",") if f.strip()]
    try:
        values = [float(f) for f in fields[:count]]
    except ValueError:
        values = []
    if len(values) != count:
        raise AbaqusError(f"{at_line(where)}: {what}, got {text!r}")
    return values


def cyclic_records(blocks) -> dict | None:
    """What a deck's ``*CYCLIC SYMMETRY MODEL`` and its ``*TIE, CYCLIC SYMMETRY`` say (``None``: no cyclic model):
    ``{"sectors": N, "axis": (a, b)`` (the two points of the axis, in the deck's unit; angles right-handed about
    ``a → b``), ``"left"`` (the ``*TIE``'s second, independent surface), ``"right"`` (its first, dependent one: the
    left face turned by ``+360°/N``), ``"tol"`` (its ``POSITION TOLERANCE``, or ``None``), ``"where"`` (file and
    line), ``"problem"`` (why the faces cannot be used as groups, or ``None``)}``."""
    ties, surfaces, model = {}, {}, None
    for place, keyword, params, data in blocks:
        if keyword == "SURFACE" and params.get("NAME"):
            surfaces[params["NAME"].upper()] = (params.get("TYPE") or "ELEMENT").upper()
        elif keyword == "TIE" and "CYCLIC SYMMETRY" in params:
            if not data:
                raise AbaqusError(f"{at_line(place)}: *TIE, CYCLIC SYMMETRY needs a line 'dependent surface, "
                                  "independent surface'")
            names = [f.strip() for f in data[0][1].split(",") if f.strip()]
            if len(names) != 2:
                raise AbaqusError(f"{at_line(data[0][0])}: a *TIE line is 'dependent surface, independent surface', "
                                  f"got {data[0][1]!r}")
            tol = params.get("POSITION TOLERANCE")
            ties[(params.get("NAME") or "").upper()] = (place, names, float(tol) if tol else None)
        elif keyword == "CYCLIC SYMMETRY MODEL":
            if model is not None:
                raise AbaqusError(f"{at_line(place)}: a second *CYCLIC SYMMETRY MODEL (the first at line "
                                  f"{model[0][1]}): bladecase reads a deck of one cyclic model")
            model = (place, params, data)
    if model is None:
        return None
    place, params, data = model
    try:
        n = int(params.get("N") or "")
    except ValueError:
        raise AbaqusError(f"{at_line(place)}: *CYCLIC SYMMETRY MODEL needs N=<number of sectors>, an integer >= 2, "
                          f"got N={params.get('N')!r}") from None
    if n < 2:
        raise AbaqusError(f"{at_line(place)}: *CYCLIC SYMMETRY MODEL, N={n}: a disk has N >= 2 sectors")
    if not data:
        raise AbaqusError(f"{at_line(place)}: *CYCLIC SYMMETRY MODEL needs a line with the two points of the axis "
                          "'xa, ya, za, xb, yb, zb'")
    xyz = _floats(data[0][0], data[0][1], 6, "the axis of *CYCLIC SYMMETRY MODEL is two points 'xa, ya, za, xb, yb, "
                  "zb'")
    a, b = xyz[:3], xyz[3:]
    if a == b:
        raise AbaqusError(f"{at_line(data[0][0])}: the two points of the *CYCLIC SYMMETRY MODEL axis are the same "
                          f"point {a}: give two distinct points of the axis")
    tie = (params.get("TIE") or "").upper()
    if tie not in ties:
        if tie or len(ties) != 1:
            have = ", ".join(sorted(ties)) or "none"
            raise AbaqusError(f"{at_line(place)}: *CYCLIC SYMMETRY MODEL, TIE={params.get('TIE')}: no *TIE, CYCLIC "
                              f"SYMMETRY of that name (cyclic ties: {have})")
        tie = next(iter(ties))
    _, (right, left), tol = ties[tie]
    problem = None
    bad = [s for s in (right, left) if surfaces.get(s.upper(), "NODE") not in ("NODE", "ELEMENT")]
    if bad:
        problem = (f"the *TIE's surface {bad[0]!r} is of TYPE={surfaces[bad[0].upper()]}: bladecase reads cyclic "
                   "faces of TYPE=NODE or TYPE=ELEMENT, or give [cyclic] left and right node groups")
    return {"sectors": n, "axis": (a, b), "left": left, "right": right, "tol": tol,
            "where": f"{place[0]!r}, line {place[1]}", "problem": problem}
