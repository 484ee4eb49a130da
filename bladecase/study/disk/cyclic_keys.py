"""The ``[cyclic]`` section of a study: a bladed disk computed from one sector (:mod:`bladecase.study.disk.cyclic` runs
it).  Its keys (:data:`CYCLIC_KEYS`), the checks across sections (:func:`cyclic_checks`) and whether a study is a
cyclic one (:func:`cyclic_requested`).

A study is cyclic when its ``[geometry] kind`` is ``"sector"`` or it sets a ``[cyclic]`` key; a study on a
CalculiX/Abaqus deck that declares ``*CYCLIC SYMMETRY MODEL`` is cyclic too without any key (the deck says it).

>>> from bladecase.study.schema import loads
>>> s = loads('''
... mesh = {path = "sector.inp"}
... cyclic = {sectors = 12, diameters = [0, 1, 6], expand = {diameter = 1, mode = 1, wave = "backward"}}
... ''')
>>> cyclic_requested(s.config), s["cyclic"]["diameters"], s["cyclic"]["expand"]
(True, [0, 1, 6], {'diameter': 1, 'mode': 1, 'wave': 'backward'})
>>> cyclic_requested(loads('''
... mesh = {path = "blade.inp"}
... contact = {clearance = 1e-4}
... ''').config)
False
"""

from __future__ import annotations

from ..keys import _INT, _LIST, _NUM, _STR, Key, StudyError
from ..values import _int_between, _name, _positive

__all__ = ["CYCLIC_KEYS", "NONSMOOTH_GROWTH", "WAVES", "cyclic_checks", "cyclic_requested", "expand_spec",
           "nonsmooth_checks"]

#: The expansions of ``[cyclic] expand`` (:func:`bladecase.fe.cyclic_waves.annulus_field`).
WAVES = ("cos", "sin", "forward", "backward")

#: Most sectors of a disk a study accepts.
MAX_SECTORS = 10_000


def _diameters(v) -> str | None:
    if not all(isinstance(x, int) and not isinstance(x, bool) and 0 <= x <= MAX_SECTORS // 2 for x in v):
        return "must be a list of nodal diameters: integers >= 0 (0 … N/2 for a disk of N sectors)"
    if len(set(v)) != len(v):
        return f"must list each nodal diameter once, got {v}"
    return None


def _orders(v) -> str | None:
    if not all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= 1000 for x in v):
        return "must be a list of engine orders: integers between 1 and 1000"
    return None


def _expand(v) -> str | None:
    keys = {"diameter", "mode", "wave"}
    extra = set(v) - keys
    if extra:
        return f"unknown key {sorted(extra)[0]!r} (valid: diameter, mode, wave)"
    k, m, w = v.get("diameter", 1), v.get("mode", 1), v.get("wave", "forward")
    if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k <= MAX_SECTORS // 2:
        return f"diameter must be a nodal diameter (an integer >= 0), got {k!r}"
    if isinstance(m, bool) or not isinstance(m, int) or not 1 <= m <= 50:
        return f"mode must be an integer from 1 (the lowest of its nodal diameter) to 50, got {m!r}"
    if w not in WAVES:
        return f"wave must be one of {', '.join(map(repr, WAVES))}, got {w!r}"
    return None


def _nonsmooth(v) -> str | None:
    keys = {"diameter", "mode", "growth", "modes"}
    extra = set(v) - keys
    if extra:
        return f"unknown key {sorted(extra)[0]!r} (valid: {', '.join(sorted(keys))})"
    k, m, c = v.get("diameter", 1), v.get("mode", 1), v.get("modes", 4)  # mode: default chosen in the stage
    if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k < MAX_SECTORS:
        return f"diameter must be the travelling wave's nodal diameter (1 … N−1; k > N/2: backward), got {k!r}"
    if isinstance(m, bool) or not isinstance(m, int) or not 1 <= m <= 50:
        return f"mode must be an integer from 1 (the lowest of its nodal diameter) to 50, got {m!r}"
    if isinstance(c, bool) or not isinstance(c, int) or not 1 <= c <= 50:
        return f"modes must be the modes kept per nodal diameter in the disk's reduced model, 1 … 50, got {c!r}"
    g = v.get("growth", list(NONSMOOTH_GROWTH))
    if (not isinstance(g, list) or not g or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                     and 1 < x <= 100 for x in g) or sorted(g) != g):
        return f"growth must be an increasing list of energies over the grazing wave's, each in (1, 100], got {g!r}"
    return None


#: ``[cyclic] nonsmooth``: the energies of the travelling family over its grazing wave's, by default.
NONSMOOTH_GROWTH = (1.05, 1.2, 1.4)

#: ``[cyclic]``: key → :class:`~bladecase.study.keys.Key`.
CYCLIC_KEYS: dict[str, Key] = {
    "sectors": Key(_INT, None, "N, the number of sectors (blades) of the disk; default: the [geometry]'s "
                   "sectors, or the deck's *CYCLIC SYMMETRY MODEL, N=…; required for another mesh file.",
                   _int_between(2, MAX_SECTORS)),
    "left": Key(_STR, None, "Mesh group of the left cyclic face (the right face is it turned by +360°/N about the "
                "axis); with 'right'. Default: the deck's *TIE, CYCLIC SYMMETRY surfaces, the sector's own "
                "faces, else the nodes at the sector's least and greatest angle.", _name),
    "right": Key(_STR, None, "Mesh group of the right cyclic face; with 'left'.", _name),
    "tol": Key(_NUM, None, "Matching tolerance of the two faces' nodes, in the mesh file's length unit ([mesh] "
               "unit); default: the deck's *TIE POSITION TOLERANCE, else 1e-6 of the sector's largest radius.",
               _positive),
    "diameters": Key(_LIST, [], "Nodal diameters to compute; default []: all of 0 … N/2.", _diameters),
    "modes": Key(_INT, 4, "Modes computed per nodal diameter (the mode families of the SAFE diagram).",
                 _int_between(1, 50)),
    "speed": Key(_NUM, None, "The speed of the SAFE diagram's engine-order lines, in [rotation] speed_unit (rpm "
                 "by default); the modes are computed about the disk's centrifugal state at that speed. Default: "
                 "[rotation] speed, else the highest of [rotation] speeds, else at rest without engine-order lines.",
                 lambda v: None if v >= 0 and v == v and v != float("inf") else "must be a finite number >= 0"),
    "engine_orders": Key(_LIST, [], "Engine orders reported (the nodal diameter each excites, the modes it meets "
                         "and at which speed); default []: [rotation] engine_orders, else 1 … N.", _orders),
    "expand": Key((dict,), None, "The mode expanded to the whole disk (vtk/annulus_*.pvd): {diameter = k, mode = j, "
                  "wave = 'forward'} — wave 'cos' or 'sin' (standing), 'forward' or 'backward' (travelling, "
                  "0 < k < N/2). Default: mode 1 of nodal diameter 1 as a forward wave (a standing wave for N < 3).",
                  _expand),
    "nonsmooth": Key((dict,), None, "A travelling-wave nonsmooth mode of the whole disk against the casing ([contact] "
                     "with model = 'massless', each blade's contact its own): {diameter = k, mode = j, modes = 4, "
                     "growth = [1.05, 1.2, 1.4]} — the wave of mode j of k nodal diameters (k > N/2: the backward "
                     "wave of N − k; default j: the mode that moves the contacts most along the casing normal for "
                     "its energy), its family at the energies 'growth' × the grazing wave's, in a reduced disk "
                     "of 'modes' modes per nodal diameter; the last orbit flown 10 periods in the whole disk "
                     "without the symmetry, and animated on the annulus (disk_modes.csv, vtk/, animations/).",
                     _nonsmooth),
}


def cyclic_requested(c: dict) -> bool:
    """True when the study (validated sections ``c``) is a cyclic one by its keys: a sector geometry, or a
    ``[cyclic]`` key set (a deck's ``*CYCLIC SYMMETRY MODEL`` is seen when the mesh is read)."""
    if (c.get("geometry") or {}).get("kind") == "sector":
        return True
    cy = c.get("cyclic") or {}
    return any(k in cy and cy[k] != spec.default for k, spec in CYCLIC_KEYS.items())


def expand_spec(cy: dict, sectors: int) -> dict:
    """``[cyclic] expand`` with its defaults for a disk of ``sectors`` (module docstring of the key).

    >>> expand_spec({"expand": None}, 12), expand_spec({"expand": {"diameter": 6}}, 12)["wave"]
    ({'diameter': 1, 'mode': 1, 'wave': 'forward'}, 'cos')
    """
    given = cy.get("expand") or {}
    ks = cy.get("diameters") or list(range(sectors // 2 + 1))
    travelling = [k for k in ks if 0 < 2 * k < sectors]
    k = given.get("diameter", 1 if 1 in travelling else (travelling or ks)[0])
    standing = k == 0 or 2 * k == sectors
    wave = given.get("wave", "cos" if standing else "forward")
    return {"diameter": k, "mode": given.get("mode", 1), "wave": wave}


def cyclic_checks(c: dict) -> None:
    """The ``[cyclic]`` keys against each other and the other sections (``StudyError`` naming the key): both faces
    or neither; a sector geometry's N; the diameters and the expanded mode within ``0 … N/2`` when N is known; no
    contact yet (a cyclic study computes the linear modes of the disk).

    >>> try:
    ...     cyclic_checks({"cyclic": {"left": "L", "right": None, "sectors": None}})
    ... except StudyError as exc:
    ...     print(str(exc).split(";")[0])
    [cyclic] left: give both cyclic faces (left and right groups) or neither (the deck's, or by angle)
    """
    cy = c.get("cyclic")
    if not cy:
        return
    if (cy["left"] is None) != (cy["right"] is None):
        given = "left" if cy["left"] is not None else "right"
        raise StudyError(f"[cyclic] {given}: give both cyclic faces (left and right groups) or neither (the deck's, or "
                         f"by angle); got only {given} = {cy[given]!r}")
    g = c.get("geometry") or {}
    n = cy["sectors"]
    if g.get("kind") == "sector":
        if n is not None and n != g["sectors"]:
            raise StudyError(f"[cyclic] sectors: the sector geometry has [geometry] sectors = {g['sectors']}, got "
                             f"{n}: leave [cyclic] sectors out (or give the same N)")
        n = g["sectors"]
    if not cyclic_requested(c):
        return
    if n is not None:
        check_diameters(cy, n)
    contact = c.get("contact", {})
    if contact.get("clearance") is not None and not cy.get("nonsmooth"):
        raise StudyError("[contact]: a cyclic study ([cyclic], [geometry] kind = 'sector') computes the linear modes "
                         "of the bladed disk by nodal diameter; its contact is for the whole disk's nonsmooth mode: "
                         "add [cyclic] nonsmooth = {diameter = k} (or remove [contact], or study one blade without "
                         "[cyclic])")
    located = any(contact.get(k) is not None for k in ("face", "group", "node", "nodes", "farthest", "nearest"))
    if located and not cy.get("nonsmooth") and not (c.get("rub") or {}).get("speeds"):
        raise StudyError("[contact]: a cyclic study uses its contact for the whole disk's nonsmooth mode ([cyclic] "
                         "nonsmooth = {diameter = k}, with [contact] clearance) or for the whole disk's rub ([rub] "
                         "speeds with an out-of-round [casing]); neither is asked, so the contact would be ignored: "
                         "add one of them, or remove [contact]")
    if cy.get("nonsmooth"):
        nonsmooth_checks(cy, contact, n)


def nonsmooth_checks(cy: dict, contact: dict, n: int | None) -> None:
    """``[cyclic] nonsmooth`` against ``[contact]`` (a clearance, the massless model) and N (a travelling wave:
    ``0 < k < N``, ``2k ≠ N``).

    >>> try:
    ...     nonsmooth_checks({"nonsmooth": {"diameter": 6}}, {"clearance": 1e-4, "model": "massless"}, 12)
    ... except StudyError as exc:
    ...     print(str(exc).split(":")[:2])
    ['[cyclic] nonsmooth', ' diameter = 6 of a disk of 12 sectors is a standing wave (k = N/2)']
    """
    ns = cy["nonsmooth"]
    if contact.get("clearance") is None:
        raise StudyError("[cyclic] nonsmooth: the whole disk's nonsmooth mode needs a casing: add [contact] with its "
                         "clearance (and face, e.g. face = 'tip', model = 'massless')")
    if contact.get("model") != "massless":
        raise StudyError(f"[contact] model: the whole disk's nonsmooth mode uses the massless contact model (each "
                         f"blade's contact its own): model = 'massless', got {contact.get('model')!r}")
    k = ns.get("diameter", 1)
    if n is not None and (k >= n or 2 * k == n):
        raise StudyError(f"[cyclic] nonsmooth: diameter = {k} of a disk of {n} sectors is "
                         + ("a standing wave (k = N/2)" if 2 * k == n else "not a nodal diameter")
                         + ": a travelling wave needs 0 < k < N, k ≠ N/2")


def check_diameters(cy: dict, n: int) -> None:
    """``[cyclic] diameters`` and ``expand`` within ``0 … ⌊N/2⌋`` for a disk of ``n`` sectors; a travelling wave
    only for ``0 < k < N/2``.

    >>> check_diameters({"diameters": [0, 7], "expand": None, "modes": 4}, 12)
    Traceback (most recent call last):
        ...
    bladecase.study.schema.StudyError: [cyclic] diameters: 7 is not a nodal diameter of a disk of 12 sectors (0 … 6)
    """
    top = n // 2
    bad = [k for k in cy["diameters"] if k > top]
    if bad:
        raise StudyError(f"[cyclic] diameters: {bad[0]} is not a nodal diameter of a disk of {n} sectors (0 … {top})")
    e = expand_spec(cy, n)
    if e["diameter"] > top:
        raise StudyError(f"[cyclic] expand: diameter = {e['diameter']} is not a nodal diameter of a disk of {n} "
                         f"sectors (valid: 0 … {top})")
    if cy["diameters"] and e["diameter"] not in cy["diameters"] and cy.get("expand"):
        raise StudyError(f"[cyclic] expand: diameter = {e['diameter']} is not among [cyclic] diameters = "
                         f"{cy['diameters']}")
    if e["mode"] > cy["modes"]:
        raise StudyError(f"[cyclic] expand: mode = {e['mode']}, but [cyclic] modes = {cy['modes']} are computed per "
                         "nodal diameter: raise modes or expand a lower mode")
    if e["wave"] in ("forward", "backward") and (e["diameter"] == 0 or 2 * e["diameter"] == n):
        raise StudyError(f"[cyclic] expand: nodal diameter {e['diameter']} of a disk of {n} sectors has standing waves "
                         f"only (k = 0 or N/2): wave = 'cos', got {e['wave']!r}")
