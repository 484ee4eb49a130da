"""Node selection by name or by coordinates, for meshes without groups (clamps, contact faces, contact nodes).

:func:`select_nodes` takes a group name or one geometric rule:

* ``{"plane": [x0, y0, z0, nx, ny, nz], "tol": t}``: the nodes within ``t`` of the plane through
  ``(x0, y0, z0)`` with normal ``n`` (any finite length but zero: ``[0, 0, 1e308]`` is ``+z``);
* ``{"box": [[xmin, ymin, zmin], [xmax, ymax, zmax]], "tol": t}``: the nodes inside the box (bounds
  included, widened by ``t``);
* ``{"sphere": [x, y, z, r], "tol": t}``: the nodes within ``r + t`` of the centre;
* ``{"nearest": [x, y, z]}``: the one corner node of the body cells nearest to the point;
* ``{"nodes": [id, …]}``: the nodes numbered so in the mesh file (:attr:`~bladecase.fe.mesh.Mesh.node_ids`: an
  Abaqus, CalculiX or ANSYS node list as it is; the 0-based index for files without node numbers).

In 2-D, points may leave out ``z`` and a plane may be ``[x0, y0, nx, ny]``.

``tol`` defaults to :data:`TOL_FRACTION` of the shortest edge of the body cells (a node one element away is
never caught).  Everything is vectorised over the nodes.  Messages name nodes by their number in the file.
Values whose distances to the nodes overflow double precision are refused as too large (any magnitude up to
:data:`MAX_MAGNITUDE` is safe).

:func:`held_nodes` counts every node a clamp holds (midside nodes included).
"""

from __future__ import annotations

import numpy as np

from .cells import CORNER_FRAMES, KINDS
from .mesh import Mesh

#: Default tolerance, as a fraction of the shortest edge of the body cells.
TOL_FRACTION = 1e-3

#: The rules of a selection, and the number of values each takes.
RULES = {"plane": 6, "box": 6, "sphere": 4, "nearest": 3}

#: Coordinates and radii up to this magnitude never overflow a distance (its square included) to a mesh node;
#: larger ones are refused only where a distance does overflow (a box of ±1e308 still selects every node).
MAX_MAGNITUDE = 1e150


def select_nodes(mesh: Mesh, spec: str | dict, what: str = "selection", allow_all: bool = True) -> np.ndarray:
    """Sorted mesh node indices (0-based) selected by ``spec`` (a group name, or a dict: see the module docstring).

    Parameters
    ----------
    mesh : Mesh
    spec : str or dict
        A group name of ``mesh``, or one rule among ``plane``, ``box``, ``sphere``, ``nearest`` with an optional
        ``tol`` (length, >= 0; not with ``nearest``), or ``nodes`` (node numbers as in the file).
    what : str
        What the selection is for (``"clamp"``, ``"contact"``), named in the messages.
    allow_all : bool
        ``False`` refuses a selection of every node of the body (a clamp must leave nodes free).

    Raises
    ------
    ValueError
        An unknown group or rule, a value that is not the right count of finite numbers, a zero normal, a
        negative radius or tolerance, values so large that the nodes' distances to them overflow, an empty
        selection (with the mesh's bounding box and the distance of the nearest node), a node number that is not
        in the mesh, a selection of every node when ``allow_all`` is false (with what to make smaller).

    Examples
    --------
    A bar of 4 × 1 × 1 hexahedra, 40 mm long, its end faces at ``x = 0`` and ``x = 0.04``:

    >>> from skfem import MeshHex
    >>> h = MeshHex.init_tensor(np.linspace(0, 0.04, 5), np.linspace(0, 0.01, 2), np.linspace(0, 0.01, 2))
    >>> bar = Mesh(h.p.T, {"hexahedron": h.t[[0, 3, 6, 2, 1, 5, 7, 4]].T}, dim=3, source="bar")
    >>> select_nodes(bar, {"plane": [0, 0, 0, 1, 0, 0]}).tolist()
    [0, 1, 10, 11]
    >>> len(select_nodes(bar, {"box": [[0.015, -1, -1], [0.04, 1, 1]]}))
    12
    >>> select_nodes(bar, {"nearest": [0.05, 0.01, 0.01]}).tolist(), bar.points[19].tolist()
    ([19], [0.04, 0.01, 0.01])
    >>> select_nodes(bar, {"sphere": [0.04, 0, 0, 0.005]}).tolist(), bar.points[8].tolist()
    ([8], [0.04, 0.0, 0.0])
    >>> select_nodes(bar, {"plane": [0.05, 0, 0, 1, 0, 0]}, what="clamp")  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
        ...
    ValueError: clamp {'plane': [0.05, 0, 0, 1, 0, 0]} selects no node of mesh bar (tol 1e-05): its bounding box
    is [[0, 0, 0], [0.04, 0.01, 0.01]], the nearest node (8 at [0.04, 0, 0]) is 0.01 away
    >>> select_nodes(bar, {"circle": [0, 0, 0, 1]})  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
        ...
    ValueError: selection {'circle': [0, 0, 0, 1]}: unknown key 'circle'; valid: one of plane, box, sphere,
    nearest, and tol (or nodes alone: node numbers as in the file)

    Nodes by their numbers in the file (here the bar's nodes numbered 101, 103, …):

    >>> from dataclasses import replace
    >>> numbered = replace(bar, node_ids=101 + 2 * np.arange(20))
    >>> select_nodes(numbered, {"nodes": [101, 103]}).tolist()
    [0, 1]
    >>> select_nodes(numbered, {"nodes": [101, 102]}, what="clamp")
    Traceback (most recent call last):
        ...
    ValueError: clamp node 102 is not a node of mesh bar (20 nodes numbered 101 to 139)
    """
    if isinstance(spec, str):
        nodes = np.asarray(mesh.group(spec), dtype=np.int64)
        if nodes.size == 0:
            raise ValueError(f"{what} group {spec!r} of mesh {mesh.source or ''} is empty")
        return _checked_all(mesh, nodes, spec, what, allow_all)
    if not isinstance(spec, dict):
        raise ValueError(f"{what} must be a group name or a dict with one of {', '.join(RULES)} "
                         f"(and tol), got {spec!r}; or node numbers as in the file, {{'nodes': [...]}}")
    if "nodes" in spec:
        if len(spec) != 1:
            others = ", ".join(k for k in spec if k != "nodes")
            raise ValueError(f"{what} {describe(spec)}: nodes goes alone (not with {others})")
        ids = np.asarray(spec["nodes"])
        if ids.ndim != 1 or ids.size == 0 or ids.dtype.kind not in "iu":
            raise ValueError(f"{what} nodes must be a non-empty list of node numbers (integers), got {describe(spec)}")
        return _checked_all(mesh, mesh.index_of(ids, f"{what} node"), spec, what, allow_all)
    rule = _rule(spec, what)
    values = _numbers(spec, rule, mesh.dim, what)
    points = np.asarray(mesh.points, dtype=float)
    if rule == "nearest":
        corners = _corner_nodes(mesh)
        with np.errstate(over="ignore", invalid="ignore"):
            dist = np.linalg.norm(points[corners] - values, axis=1)
        _check_finite(mesh, spec, rule, dist, what)
        return corners[[int(np.argmin(dist))]]
    tol = _tolerance(mesh, spec, what)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused just below, naming the values
        if rule == "plane":
            normal = values[3:]
            top = float(np.abs(normal).max())  # scaled first: a normal of 1e308 (or 1e-200) is a direction too
            if top == 0.0:
                raise ValueError(f"{what} {spec!r}: the plane's normal (the last 3 values) must not be zero")
            normal = normal / top
            dist = np.abs((points - values[:3]) @ (normal / np.linalg.norm(normal)))
        elif rule == "box":
            low, high = values[:3], values[3:]
            if np.any(low > high):
                raise ValueError(f"{what} {spec!r}: box corners must be [[xmin, ymin, zmin], [xmax, ymax, zmax]] "
                                 f"with min <= max")
            dist = np.linalg.norm(np.maximum(np.maximum(low - points, points - high), 0.0), axis=1)
        else:  # sphere
            if values[3] < 0:
                raise ValueError(f"{what} {spec!r}: the sphere's radius must be >= 0, got {values[3]:g}")
            dist = np.maximum(np.linalg.norm(points - values[:3], axis=1) - values[3], 0.0)
    _check_finite(mesh, spec, rule, dist, what)
    nodes = np.flatnonzero(dist <= tol)
    if nodes.size == 0:
        k = int(np.argmin(dist))
        box = np.array([points.min(axis=0), points.max(axis=0)])
        raise ValueError(f"{what} {spec!r} selects no node of mesh {mesh.source or ''} (tol {tol:.3g}): its "
                         f"bounding box is {_fmt(box)}, the nearest node ({mesh.node_id(k)} at {_fmt(points[k])}) is "
                         f"{dist[k]:.3g} away")
    return _checked_all(mesh, nodes, spec, what, allow_all)


def _check_finite(mesh: Mesh, spec: dict, rule: str, dist: np.ndarray, what: str) -> None:
    """``ValueError`` when a distance of the nodes to the selection's values overflowed (``inf``): the selection
    (and its message's "nearest node … away") would be meaningless."""
    if np.all(np.isfinite(dist)):
        return
    points = np.asarray(mesh.points, dtype=float)
    box = np.array([points.min(axis=0), points.max(axis=0)])
    raise ValueError(f"{what} {describe(spec)}: too large: the distances from the mesh's nodes to this {rule} overflow "
                     f"double precision; valid: finite numbers whose distances to the mesh stay finite (any magnitude "
                     f"up to {MAX_MAGNITUDE:g} does; the mesh's bounding box is {_fmt(box)})")


def _rule(spec: dict, what: str) -> str:
    unknown = [k for k in spec if k not in RULES and k != "tol"]
    if unknown:
        raise ValueError(f"{what} {spec!r}: unknown key {unknown[0]!r}; valid: one of {', '.join(RULES)}, and tol "
                         "(or nodes alone: node numbers as in the file)")
    rules = [k for k in spec if k in RULES]
    if len(rules) != 1:
        raise ValueError(f"{what} {spec!r} needs exactly one of {', '.join(RULES)}, got "
                         f"{', '.join(rules) or 'none'}")
    if rules[0] == "nearest" and "tol" in spec:
        raise ValueError(f"{what} {spec!r}: tol does not apply to nearest (it selects one node)")
    return rules[0]


def _numbers(spec: dict, rule: str, dim: int, what: str) -> np.ndarray:
    """The rule's values as floats (points padded to 3 coordinates in 2-D)."""
    raw = spec[rule]
    shapes = {"plane": "[x0, y0, z0, nx, ny, nz]", "box": "[[xmin, ymin, zmin], [xmax, ymax, zmax]]",
              "sphere": "[x, y, z, r]", "nearest": "[x, y, z]"}
    try:
        v = np.array(raw, dtype=float)
    except (TypeError, ValueError):
        v = np.zeros(0)
    if dim == 2 and rule == "plane" and v.shape == (4,):
        v = np.array([v[0], v[1], 0.0, v[2], v[3], 0.0])  # [x0, y0, nx, ny]
    elif dim == 2 and v.ndim and v.shape[-1] == RULES[rule] // (2 if rule == "box" else 1) - 1:
        v = np.insert(v, 2, 0.0, axis=-1)  # 2-D points: z = 0 (the sphere's radius stays last)
    if v.size != RULES[rule] or not np.all(np.isfinite(v)):
        valid = shapes[rule] + (" (2-D: z, and nz, may be left out)" if dim == 2 else "")
        raise ValueError(f"{what} {rule} = {raw!r} must be {RULES[rule]} finite numbers {valid}")
    return v.ravel()


def _tolerance(mesh: Mesh, spec: dict, what: str) -> float:
    if "tol" not in spec:
        return TOL_FRACTION * _shortest_edge(mesh)
    tol = spec["tol"]
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) or not tol >= 0 \
            or not np.isfinite(tol):
        raise ValueError(f"{what} tol = {tol!r} must be a finite length >= 0")
    return float(tol)


def _shortest_edge(mesh: Mesh) -> float:
    kind = KINDS[mesh.body_type]
    cells = np.asarray(mesh.cells[mesh.body_type])[:, : kind.corners]
    frames = np.array(CORNER_FRAMES[kind.family])
    x = mesh.points[cells]
    edges = np.linalg.norm(x[:, frames] - x[:, np.arange(kind.corners)][:, :, None], axis=-1)
    return float(edges.min())


def _corner_nodes(mesh: Mesh) -> np.ndarray:
    kind = KINDS[mesh.body_type]
    return np.unique(np.asarray(mesh.cells[mesh.body_type])[:, : kind.corners])


def _checked_all(mesh: Mesh, nodes: np.ndarray, spec, what: str, allow_all: bool) -> np.ndarray:
    nodes = np.unique(nodes)
    if not allow_all:
        body = np.unique(np.asarray(mesh.cells[mesh.body_type]))
        if np.isin(body, nodes).all():
            raise ValueError(f"{what} {describe(spec)} selects every node of the body of mesh {mesh.source or ''} "
                             f"({body.size} nodes): the clamp holds every node, nothing is left free; "
                             f"{_smaller(mesh, spec, body)}")
    return nodes


def _smaller(mesh: Mesh, spec, body: np.ndarray) -> str:
    """What to change in a selection of every node of the body ``body`` (for :func:`_checked_all`'s message)."""
    points = np.asarray(mesh.points, dtype=float)[body]
    if points.shape[1] == 2:
        points = np.c_[points, np.zeros(len(points))]
    box = _fmt([points.min(axis=0), points.max(axis=0)])
    if isinstance(spec, str):
        return f"use a group of the root face only, not one of the whole body (the body spans {box})"
    if not isinstance(spec, dict) or "nodes" in spec:
        return "list the root face's nodes only, not every node of the body"
    if "sphere" in spec:
        centre = np.asarray(spec["sphere"], dtype=float)[:-1]
        centre = np.r_[centre, np.zeros(3 - centre.size)]
        far = float(np.linalg.norm(points - centre, axis=1).max())
        shown = float(f"{far:.3g}")
        if shown >= far > 0:  # printed rounded down: a radius below the printed bound leaves a node free
            shown -= 10.0 ** (np.floor(np.log10(shown)) - 2)
        return (f"use a smaller radius: r + tol must stay below {shown:.3g}, the distance from the centre to the "
                f"farthest node (e.g. a small sphere around the root face)")
    if "box" in spec:
        return f"use a smaller box: the body spans {box} (e.g. a thin box around the root face)"
    return (f"use a plane through the root face only, across the body (the body spans {box}; a plane that holds a "
            f"flat mesh, or a tol as large as the body, takes every node)")


def _fmt(a) -> str:
    """``[x, y, z]`` or ``[[…], […]]`` with 4 significant digits, on one line."""
    a = np.asarray(a)
    return "[" + ", ".join(_fmt(r) if a.ndim > 1 else f"{r:.4g}" for r in a) + "]"


def describe(spec) -> str:
    """``spec`` for a message: a long node list is cut (its first numbers and its length)."""
    if isinstance(spec, dict) and isinstance(spec.get("nodes"), (list, tuple, np.ndarray)) and len(spec["nodes"]) > 6:
        ids = list(spec["nodes"])
        return f"{{'nodes': [{', '.join(str(int(k)) for k in ids[:4])}, … ({len(ids)} nodes)]}}"
    return repr(spec)


def held_nodes(mesh: Mesh, clamped) -> np.ndarray:
    """Every mesh node a clamp of the corner nodes ``clamped`` holds fixed (sorted 0-based indices): those corners,
    and the midside and face-centre nodes of the body cells whose edge or face has all its corners clamped — the
    nodes whose dofs the assembly fixes with them (a cell's centre node never is).  A clamp of a quadratic mesh's
    root face holds its midside nodes too: this is the count an Abaqus or ANSYS user compares with the deck.

    >>> from skfem import MeshTri
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.02, 3), np.linspace(0, 0.01, 2)).oriented()
    >>> six = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> edges = {tuple(sorted(e)) for c in t.t.T for e in ((c[0], c[1]), (c[1], c[2]), (c[2], c[0]))}
    >>> mid = {e: len(six) + k for k, e in enumerate(sorted(edges))}
    >>> points = np.vstack([six, [(six[a] + six[b]) / 2 for a, b in sorted(edges)]])
    >>> tri6 = np.array([[*c, mid[tuple(sorted((c[0], c[1])))], mid[tuple(sorted((c[1], c[2])))],
    ...                   mid[tuple(sorted((c[2], c[0])))]] for c in t.t.T])
    >>> strip = Mesh(points, {"triangle6": tri6}, dim=2)
    >>> root = np.flatnonzero(six[:, 0] == 0)                  # the two corners at x = 0
    >>> points[held_nodes(strip, root)][:, :2].tolist()        # and the midside node between them
    [[0.0, 0.0], [0.0, 0.01], [0.0, 0.005]]
    """
    kind = KINDS[mesh.body_type]
    cells = np.asarray(mesh.cells[mesh.body_type])
    fixed = np.zeros(len(mesh.points), dtype=bool)
    fixed[np.asarray(clamped, dtype=np.int64)] = True
    held = [np.flatnonzero(fixed)]
    for j in range(kind.corners, kind.n_nodes):
        parents = list(kind.parents[j])
        if len(parents) < kind.corners:  # an edge or a face, not the cell's centre
            held.append(cells[fixed[cells[:, parents]].all(axis=1), j])
    return np.unique(np.concatenate(held))
