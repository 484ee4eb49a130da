"""Parametric blades meshed by gmsh: a lofted 3-D blade and a flat 2-D plate.

:class:`BladeGeometry` describes a solid blade built by lofting sections
(OpenCASCADE ``addThruSections``): taper, a rectangular or NACA 4-digit
section with a blunt trailing edge, twist, stagger, sweep and lean.
:class:`PlateGeometry` is the plane-stress membrane variant for fast studies.
:func:`blade_mesh` meshes either one with simplices of order 1 or 2 and
returns a :class:`~bladecase.fe.mesh.Mesh` with the node groups ``root``
(clamped), ``tip`` (facing the casing), ``blade`` (the body) and, when a
contact point is asked for, ``contact`` (exactly one node).

Axes (units are the user's; SI recommended): the 3-D blade is radial along
``+z`` (root face at ``z = 0``, tip face at ``z = span``, casing normal
``+z``); the plate is radial along ``+y`` (root edge at ``y = 0``, tip edge at
``y = span``).  At zero stagger a section's chord lies along ``+x``, from the
leading edge at ``x = -c/2`` to the trailing edge at ``x = +c/2``.

The shapes and their checks are in :mod:`~bladecase.fe.shapes`, the NACA sections in
:mod:`~bladecase.fe.naca`, the gmsh/OpenCASCADE construction in :mod:`~bladecase.fe.cad`;
:func:`estimate_cells` refuses, before gmsh runs, a size that would make more than ``max_cells`` cells.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..checks import integer, positive
from ..io import atomic_path
from .cad import build_blade, build_plate, gmsh_model, tip_field
from .mesh import Mesh, load_mesh
from .naca import SECTION_POINTS, naca_parameters, naca_section
from .shapes import CONTACT_RTOL, MAX_SECTIONS, BladeGeometry, PlateGeometry  # noqa: F401  (their former home)

__all__ = [
    "CONTACT_RTOL", "MAX_CELLS", "SECTION_POINTS", "TIP_ZONE", "BladeGeometry", "PlateGeometry", "blade_mesh",
    "cad_volume", "estimate_cells", "naca_parameters", "naca_section",
]

#: Tip refinement: the size grows from ``tip_size`` at the tip to ``size`` over
#: this fraction of the span.
TIP_ZONE = 0.25

#: Default cap on the number of cells :func:`blade_mesh` may make (checked
#: with :func:`estimate_cells` before gmsh runs): 2e6 tetrahedra of order 2
#: are about 9e6 dofs, beyond what the dense-ish eigen/reduction steps handle
#: in memory on a workstation.
MAX_CELLS = 2_000_000


#: Cells per ``size**dim`` of area/volume made by gmsh's Delaunay/frontal
#: meshers (an equilateral triangle of side h has area 0.433 h², gmsh's
#: measured ~2.3 triangles per h²; about 6-7 tetrahedra per h³ measured on the
#: blades), rounded up so that :func:`estimate_cells` over-estimates.
_CELLS_PER_UNIT = {2: 2.6, 3: 8.0}
#: Tetrahedra per surface triangle of a body thinner than the element size.
_THIN_LAYER = 2.0
#: Cells per simplex when ``cells = "hexahedron"`` (gmsh subdivision).
_SUBDIVISION = {2: 3, 3: 4}


def _measures(geometry) -> tuple[int, float, float]:
    """``(dim, measure, boundary)``: area and perimeter (plate) or volume and surface area (blade)."""
    if isinstance(geometry, PlateGeometry):
        c0, c1 = geometry.chord, geometry.taper * geometry.chord
        area = 0.5 * geometry.span * (c0 + c1)
        lo, hi = geometry.tip_edge()
        side = math.hypot(lo + 0.5 * c0, geometry.span) + math.hypot(hi - 0.5 * c0, geometry.span)
        return 2, area, c0 + c1 + side
    if isinstance(geometry, BladeGeometry):
        c0 = geometry.root_chord
        c1 = c0 if geometry.tip_chord is None else geometry.tip_chord
        span = geometry.span
        if geometry.naca is not None:  # unit-chord section: area and perimeter scale as c² and c
            upper, lower, _ = naca_section(geometry.naca, 1.0, geometry.trailing_edge_thickness, 201)
            ring = np.vstack([upper[::-1], lower])
            x, y = ring[:, 0], ring[:, 1]
            a1 = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
            p1 = float(np.sum(np.hypot(*np.diff(np.vstack([ring, ring[:1]]), axis=0).T)))
            section_area = (a1 * c0 * c0, a1 * c1 * c1)
            volume = a1 * span * (c0 * c0 + c0 * c1 + c1 * c1) / 3
            lateral = p1 * span * (c0 + c1) / 2
        else:
            t = float(geometry.thickness)
            section_area = (c0 * t, c1 * t)
            volume = span * t * (c0 + c1) / 2
            lateral = span * (c0 + c1 + 2 * t)
        # sweep and lean stretch the lateral surface
        lateral *= math.hypot(1.0, math.hypot(geometry.sweep, geometry.lean) / span)
        return 3, volume, lateral + sum(section_area)
    raise ValueError(f"geometry must be a BladeGeometry or a PlateGeometry, got {type(geometry).__name__}")


def estimate_cells(geometry, size: float | None = None, tip_size: float | None = None,
                   cells: str = "simplex") -> int:
    """An estimate (an over-estimate by up to ~3×) of the number of cells :func:`blade_mesh` would make.

    From the analytic area (plate) or volume (blade) and the element size,
    without running gmsh: about ``2.6 · A / size²`` triangles or
    ``8 · V / size³`` tetrahedra, with a floor of a layer of cells over the
    boundary when the body is thinner than ``size``; a ``tip_size`` refines
    the ``TIP_ZONE · span`` next to the tip (size growing linearly to
    ``size``); ``cells = "hexahedron"`` multiplies by 4 (3 in 2-D).

    Parameters
    ----------
    geometry : BladeGeometry or PlateGeometry
    size, tip_size : float or None
        As in :func:`blade_mesh` (``None``: ``geometry.default_size()`` and a uniform size).
    cells : {"simplex", "hexahedron"}

    Examples
    --------
    >>> plate = PlateGeometry(span=0.1, chord=0.02)
    >>> estimate_cells(plate, size=0.005) < 1000
    True
    >>> f"{estimate_cells(plate, size=1e-6):.1e}"  # far above MAX_CELLS: blade_mesh refuses it
    '5.2e+09'
    >>> estimate_cells(BladeGeometry(span=0.15, root_chord=0.05, naca="2412")) < MAX_CELLS
    True
    """
    size = geometry.default_size() if size is None else positive("size", size)
    tip_size = positive("tip_size", tip_size, allow_none=True)
    if cells not in ("simplex", "hexahedron"):
        raise ValueError(f"cells must be 'simplex' or 'hexahedron', got {cells!r}")
    n = _estimate(_measures(geometry), float(geometry.span), size, tip_size, cells)
    return int(math.ceil(min(n, 1e300)))


def _estimate(measures: tuple[int, float, float], span: float, size: float, tip_size: float | None,
              cells: str) -> float:
    """:func:`estimate_cells` from :func:`_measures` (a float, ``inf`` when it overflows)."""
    dim, measure, boundary = measures
    reach = TIP_ZONE * span
    refined = tip_size is not None and tip_size < size

    def density(m: float, d: int) -> float:
        """∫ dm / h^d over a measure ``m`` spread evenly along the span, h = size but over the tip zone."""
        w = m / size**d
        if refined:
            slope = (size - tip_size) / reach  # h = tip_size + slope · (distance to the tip)
            zone = (tip_size ** (1 - d) - size ** (1 - d)) / ((d - 1) * slope)  # ∫_0^reach ds / h^d
            w += m / span * (zone - reach / size**d)
        return w

    try:
        n = _CELLS_PER_UNIT[dim] * density(measure, dim)
        if dim == 3:  # thin bodies: at least about a layer of tetrahedra under the surface triangles
            n = max(n, _THIN_LAYER * _CELLS_PER_UNIT[2] * density(boundary, 2))
    except (ZeroDivisionError, OverflowError):
        return math.inf
    return n * _SUBDIVISION[dim] if cells == "hexahedron" else n


def _check_cells(geometry, size: float, tip_size: float | None, cells: str, max_cells: int) -> None:
    """Refuse, before gmsh runs, sizes that would make more than ``max_cells`` cells."""
    measures = _measures(geometry)
    span = float(geometry.span)
    n = _estimate(measures, span, size, tip_size, cells)
    if n <= max_cells:
        return

    def least(count, x: float, top: float = math.inf) -> float:
        """The least ``y`` in ``[x, top]`` with ``count(y) <= max_cells`` (``count`` decreasing; log bisection)."""
        lo, hi = x, min(10 * x, top)
        while count(hi) > max_cells and hi < min(top, 1e300):
            lo, hi = hi, min(10 * hi, top)
        for _ in range(80):
            mid = lo * math.sqrt(hi / lo)
            if count(mid) > max_cells:
                lo = mid
            else:
                hi = mid
        return hi

    what = "cells" if cells == "simplex" else "hexahedra" if measures[0] == 3 else "quadrilaterals"

    def up(x: float) -> str:  # 2 significant digits, rounded up
        e = math.floor(math.log10(x)) - 1
        return f"{math.ceil(x / 10**e) * 10**e:.2g}"

    if tip_size is None or _estimate(measures, span, size, None, cells) > max_cells:
        fix = f"size >= {up(least(lambda h: _estimate(measures, span, h, None, cells), size))} m"
        if tip_size is not None:
            fix += " without a finer tip_size"
    else:
        fix = f"tip_size >= {up(least(lambda t: _estimate(measures, span, size, t, cells), tip_size, size))} m"
    given = f"size = {size:g} m" + ("" if tip_size is None else f", tip_size = {tip_size:g} m")
    about = "more than 1e300" if math.isinf(n) else f"about {n:.1e}"
    raise ValueError(
        f"{given} would make {about} {what} (at most {max_cells:g}: raise [limits] cells "
        f"(max_cells), or use {fix})"
    )



def _builder(geometry) -> tuple[int, object]:
    if isinstance(geometry, BladeGeometry):
        return 3, build_blade
    if isinstance(geometry, PlateGeometry):
        return 2, build_plate
    raise ValueError(f"geometry must be a BladeGeometry or a PlateGeometry, got {type(geometry).__name__}")


def blade_mesh(
    geometry: BladeGeometry | PlateGeometry,
    size: float | None = None,
    tip_size: float | None = None,
    order: int = 1,
    path: str | os.PathLike | None = None,
    cells: str = "simplex",
    max_cells: int = MAX_CELLS,
) -> Mesh:
    """Mesh a blade with gmsh; write the ``.msh`` if ``path`` is given; return the mesh.

    Parameters
    ----------
    geometry : BladeGeometry or PlateGeometry
        The 3-D solid blade (tetrahedra) or the 2-D plate (triangles).
    size : float or None
        Target element size; ``None`` for ``geometry.default_size()``.
    tip_size : float or None
        Element size at the tip (``<= size``), growing linearly to ``size``
        over ``TIP_ZONE · span``; ``None`` for a uniform size.
    order : {1, 2}
        Element order (``tetra``/``triangle`` or ``tetra10``/``triangle6``;
        order-2 nodes on curved boundaries are placed on the geometry).
    path : path-like or None
        Where to write the mesh (gmsh MSH 4.1, binary, suffix ``.msh``),
        atomically.
    cells : {"simplex", "hexahedron"}
        ``"hexahedron"``: every tetrahedron (triangle) of the mesh split into
        four hexahedra (three quadrilaterals) by gmsh
        (``Mesh.SubdivisionAlgorithm``), order 1 only, so the mesh has about
        four times the cells; the hexahedra are checked like any mesh's, and
        at coarse sizes on thin curved blades a few come out folded, which is
        refused (try a smaller ``size``).
    max_cells : int
        Refuse, before running gmsh, a ``size``/``tip_size`` for which
        :func:`estimate_cells` exceeds this (default :data:`MAX_CELLS`).

    Returns
    -------
    Mesh
        Read back from the written file by :func:`~bladecase.fe.mesh.load_mesh`,
        with groups ``root``, ``tip``, ``blade`` and, if a contact point was
        given, ``contact``.

    Raises
    ------
    ValueError
        Bad parameters (the message names the value and what is valid), or a
        contact point outside the tip.
    RuntimeError
        gmsh failed (its last error is quoted).

    Examples
    --------
    A coarse 3-D blade (well under a second at this size); the contact point is a mesh node exactly:

    >>> blade = BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", twist_deg=40.0,
    ...                       contact_point=(0, 0, 0.15))
    >>> mesh = blade_mesh(blade, size=0.02)
    >>> mesh.dim, mesh.body_type, sorted(mesh.groups)
    (3, 'tetra', ['blade', 'contact', 'root', 'tip'])
    >>> mesh.points[mesh.group("contact")].tolist()
    [[0.0, 0.0, 0.15]]

    The 2-D plate, with quadratic triangles; the root edge is at ``y = 0``, the tip edge at ``y = span``:

    >>> plate = PlateGeometry(span=0.1, chord=0.02, contact_point=(0.005, 0.1))
    >>> mesh = blade_mesh(plate, size=0.005, order=2)
    >>> mesh.body_type, mesh.order, mesh.points[mesh.group("contact")].tolist()
    ('triangle6', 2, [[0.005, 0.1, 0.0]])
    >>> float(mesh.points[mesh.group("root"), 1].max()), float(mesh.points[mesh.group("tip"), 1].min())
    (0.0, 0.1)
    >>> blade_mesh(plate, size=0.005, tip_size=0.01)
    Traceback (most recent call last):
        ...
    ValueError: tip_size = 0.01 must not exceed size = 0.005 (it refines the tip)
    """
    dim, build = _builder(geometry)
    size = geometry.default_size() if size is None else positive("size", size)
    tip_size = positive("tip_size", tip_size, allow_none=True)
    if tip_size is not None and tip_size > size:
        raise ValueError(f"tip_size = {tip_size!r} must not exceed size = {size!r} (it refines the tip)")
    if isinstance(order, bool) or order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, got {order!r}")
    if cells not in ("simplex", "hexahedron"):
        raise ValueError(f"cells must be 'simplex' or 'hexahedron', got {cells!r}")
    if cells == "hexahedron" and order != 1:
        raise ValueError(f"cells = 'hexahedron' makes order-1 cells (order=1), got order={order!r}; the FE order is "
                         "chosen when assembling (assemble(mesh, ..., order=2))")
    if path is not None and Path(path).suffix.lower() != ".msh":
        raise ValueError(
            f"blade_mesh writes gmsh .msh files, got path {str(path)!r}; "
            "use bladecase.save_mesh for .vtu, .vtk or .inp"
        )
    max_cells = integer("max_cells", max_cells, 1)
    _check_cells(geometry, size, tip_size, cells, max_cells)

    options = {
        "General.NumThreads": 1,  # reproducible meshes
        "Mesh.MeshSizeMax": size,
        "Mesh.MeshSizeMin": 0.0,
        "Mesh.MeshSizeFromPoints": 0,
        "Mesh.MeshSizeFromCurvature": 0,
        "Mesh.MeshSizeExtendFromBoundary": 0,
        "Mesh.ElementOrder": 1,
        "Mesh.SecondOrderLinear": 0,
        "Mesh.MshFileVersion": 4.1,
        "Mesh.Binary": 1,  # exact coordinates (ASCII MSH keeps 16 digits only)
        "Mesh.SaveAll": 0,
        "Mesh.SubdivisionAlgorithm": 0 if cells == "simplex" else dim - 1,  # 2: all hexahedra, 1: all quads
    }
    target_cm = _scratch_path() if path is None else atomic_path(path)
    with target_cm as target:
        with gmsh_model("bladecase", options) as gmsh:
            try:
                body, root, tip, contact = build(gmsh, geometry)
                model = gmsh.model
                model.addPhysicalGroup(dim, [body], name="blade")
                model.addPhysicalGroup(dim - 1, root, name="root")
                model.addPhysicalGroup(dim - 1, tip, name="tip")
                if contact is not None:
                    model.addPhysicalGroup(0, [contact], name="contact")
                if tip_size is not None and tip_size < size:
                    tip_field(gmsh, dim, tip, tip_size, size, TIP_ZONE * geometry.span)
                model.mesh.generate(dim)
                if order == 2:
                    model.mesh.setOrder(2)
                    # Bare setOrder(2) can invert a few curved tetrahedra on thin curved
                    # blades (midside nodes snapped to the surface): untangle them.
                    model.mesh.optimize("HighOrder")
                gmsh.write(str(target))
            except ValueError:
                raise
            except Exception as exc:
                raise RuntimeError(f"gmsh failed to mesh {geometry!r}: {exc}") from None
        try:
            mesh = load_mesh(target)  # checked before it replaces anything at ``path``
        except ValueError as exc:
            raise RuntimeError(
                f"gmsh made an invalid mesh of {geometry!r} (try another size or order): {exc}"
            ) from None
    return replace(mesh, source=f"blade_mesh({geometry!r})" if path is None else str(path))


@contextmanager
def _scratch_path() -> Iterator[Path]:
    with tempfile.TemporaryDirectory(prefix="bladecase-") as tmpdir:
        yield Path(tmpdir) / "blade.msh"



def cad_volume(geometry: BladeGeometry | PlateGeometry) -> float:
    """Volume (3-D) or area (2-D) of the CAD model, by OpenCASCADE (``occ.getMass``).

    Exact (to round-off) for the plate and for blades with planar faces
    (rectangular sections without twist).  For lofted NACA blades OCC's
    default integration over the B-spline faces is only good to a few 1e-3
    (measured: -1.3e-3 untwisted, +3.7e-3 with 30° of twist); the meshes are
    closer to the true volume than that (see ``docs/geometry.md``).
    """
    dim, build = _builder(geometry)
    with gmsh_model("bladecase-cad", {}) as gmsh:
        body = build(gmsh, geometry)[0]
        return float(gmsh.model.occ.getMass(dim, body))
