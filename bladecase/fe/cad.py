"""The gmsh/OpenCASCADE side of :func:`~bladecase.fe.geometry.blade_mesh`: sessions, bodies, caps, size fields.

:func:`gmsh_model` opens a fresh gmsh model and leaves gmsh as it found it;
:func:`build_blade` lofts a :class:`~bladecase.fe.geometry.BladeGeometry`,
:func:`build_plate` draws a :class:`~bladecase.fe.geometry.PlateGeometry`;
both return ``(body, root entities, tip entities, contact point tag)``.
:func:`tip_field` refines the mesh towards the tip.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .shapes import BladeGeometry, PlateGeometry


@contextmanager
def gmsh_model(name: str, options: dict[str, float]) -> Iterator[object]:
    """A fresh gmsh model with ``options`` set; gmsh is left as it was found.

    If gmsh is not initialised, it is initialised here (no config files, no
    signal handler, silent) and finalised on exit; otherwise a new model is
    added and removed, and the options are restored.
    """
    import gmsh

    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        previous_model = None
    else:
        previous_model = gmsh.model.getCurrent()
    saved: list[tuple[str, float]] = []
    try:
        options = {"General.Terminal": 0, "General.Verbosity": 2, **options}
        for key, value in options.items():
            saved.append((key, gmsh.option.getNumber(key)))
            gmsh.option.setNumber(key, value)
        gmsh.model.add(name)
        try:
            yield gmsh
        finally:
            gmsh.model.remove()
    finally:
        if own:
            gmsh.finalize()
        else:
            for key, value in reversed(saved):
                gmsh.option.setNumber(key, value)
            gmsh.model.setCurrent(previous_model)


def build_blade(gmsh, g: BladeGeometry) -> tuple[int, list[int], list[int], int | None]:
    """Loft the blade; return ``(volume, root faces, tip faces, contact point tag)``."""
    occ = gmsh.model.occ
    wires, curves = [], []
    for k in range(g.n_sections):
        z = g.span * k / (g.n_sections - 1)
        parts = g.section(z)
        first = None
        tags = []
        prev_end = None
        for j, q in enumerate(parts):
            start = prev_end if prev_end is not None else occ.addPoint(*q[0])
            if first is None:
                first = start
            end = first if j == len(parts) - 1 else occ.addPoint(*q[-1])
            if len(q) == 2:
                tags.append(occ.addLine(start, end))
            else:
                inner = [occ.addPoint(*r) for r in q[1:-1]]
                tangents = np.zeros((len(q), 3))
                # G1 leading edge: the suction side ends, the pressure side starts there.
                tangents[-1 if j == 0 else 0] = g.le_tangent(z)
                tags.append(occ.addSpline([start, *inner, end], tangents=tangents.ravel().tolist()))
            prev_end = end
        curves += tags
        wires.append(occ.addWire(tags))
    out = occ.addThruSections(wires, makeSolid=True, makeRuled=False)
    volumes = [t for d, t in out if d == 3]
    if len(volumes) != 1:
        raise RuntimeError(f"lofting {g!r} gave {len(volumes)} volumes instead of one")
    occ.remove([(1, c) for c in curves], recursive=True)
    contact = occ.addPoint(*g.contact_point[:2], g.span) if g.contact_point is not None else None
    occ.synchronize()
    root, tip = _caps(gmsh, volumes[0], 3, g.span, 2)
    if contact is not None:
        _check_inside_tip(gmsh, g, tip)
        gmsh.model.mesh.embed(0, [contact], 2, tip[0])
    return volumes[0], root, tip, contact


def _caps(gmsh, body: int, dim: int, span: float, axis: int) -> tuple[list[int], list[int]]:
    """Boundary entities of ``body`` lying in the planes ``x[axis] = 0`` and ``x[axis] = span``."""
    root, tip = [], []
    for _, t in gmsh.model.getBoundary([(dim, body)], oriented=False):
        bb = gmsh.model.getBoundingBox(dim - 1, t)
        lo, hi = bb[axis], bb[axis + 3]
        if hi - lo < 1e-3 * span:  # gmsh pads bounding boxes (1e-7)
            c = 0.5 * (lo + hi)
            if abs(c) < 1e-3 * span:
                root.append(t)
            elif abs(c - span) < 1e-3 * span:
                tip.append(t)
    if not root or not tip:
        raise RuntimeError(f"could not identify the root and tip of the blade (root {root}, tip {tip})")
    return root, tip


def _check_inside_tip(gmsh, g: BladeGeometry, tip: list[int]) -> None:
    x, y = float(g.contact_point[0]), float(g.contact_point[1])
    xyz = [x, y, g.span]
    if len(tip) != 1 or not gmsh.model.isInside(2, tip[0], xyz):
        raise ValueError(
            f"contact_point {g.contact_point!r} is not inside the tip face (section at z = span = {g.span!r})"
        )
    edges = [t for _, t in gmsh.model.getBoundary([(2, tip[0])], oriented=False)]
    dist = min(np.linalg.norm(np.array(gmsh.model.getClosestPoint(1, e, xyz)[0]) - xyz) for e in edges)
    if dist <= 1e-9 * g.chord(g.span):
        raise ValueError(f"contact_point {g.contact_point!r} lies on the boundary of the tip face; move it inside")


def build_plate(gmsh, g: PlateGeometry) -> tuple[int, list[int], list[int], int | None]:
    """The trapezoid, counter-clockwise; a contact point inside the tip edge splits it in two."""
    occ = gmsh.model.occ
    lo, hi = g.tip_edge()
    c = 0.5 * g.chord
    xy = [(-c, 0.0), (c, 0.0), (hi, g.span)]
    x = None if g.contact_point is None else float(g.contact_point[0])
    if x is not None and lo < x < hi:
        xy.append((x, g.span))
    xy.append((lo, g.span))
    points = [occ.addPoint(a, b, 0.0) for a, b in xy]
    lines = [occ.addLine(points[i], points[(i + 1) % len(points)]) for i in range(len(points))]
    surface = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    occ.synchronize()
    root, tip = _caps(gmsh, surface, 2, g.span, 1)
    contact = None if x is None else next(p for p, (a, b) in zip(points, xy) if b == g.span and a == x)
    return surface, root, tip, contact



def tip_field(gmsh, dim: int, tip: list[int], tip_size: float, size: float, reach: float) -> None:
    """Background size: ``tip_size`` on the tip, growing linearly to ``size`` at the distance ``reach``."""
    field = gmsh.model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "SurfacesList" if dim == 3 else "CurvesList", tip)
    field.setNumber(dist, "Sampling", 100)
    thr = field.add("Threshold")
    field.setNumber(thr, "InField", dist)
    field.setNumber(thr, "SizeMin", tip_size)
    field.setNumber(thr, "SizeMax", size)
    field.setNumber(thr, "DistMin", 0.0)
    field.setNumber(thr, "DistMax", reach)
    field.setAsBackgroundMesh(thr)
