"""A parametric bladed-disk sector meshed by gmsh: a disk sector with today's parametric blade on its rim.

:class:`SectorGeometry`: ``sectors`` (``N``), the disk's ``hub_radius`` and ``rim_radius`` and its axial
``disk_thickness``, and the :class:`~bladecase.fe.shapes.BladeGeometry` of the blade.  The blade keeps its own
coordinates (radial along ``+z``, root at ``z = 0``, tip at ``z = span``, its contact point where it is), so a
casing, a contact point or a ``[rotation]`` axis written for the blade stay right: the engine axis is the line
through ``(0, 0, −rim_radius)`` along ``+x`` (:attr:`SectorGeometry.axis`), the disk sector spans ``360°/N``
centred on the blade, from ``hub_radius`` to ``rim_radius`` about it, ``x`` within ``±disk_thickness/2``.  The blade's
root section is extruded down into the rim (it meets the cylindrical rim without a gap) and fused with the disk:
one body, one conformal mesh.  The two cyclic faces are meshed periodically (the right face's mesh is the left
face's rotated by ``+360°/N`` about the axis), so their nodes match one to one.

:func:`sector_mesh` returns the :class:`~bladecase.fe.mesh.Mesh` with the node groups ``hub`` (the bore, to clamp),
``left`` and ``right`` (the cyclic faces; right = left rotated by ``+360°/N``, right-handed about ``+x``), ``tip``
(the blade's tip face), ``sector`` (the body) and, with a blade contact point, ``contact``.

>>> from bladecase.fe.shapes import BladeGeometry
>>> g = SectorGeometry(sectors=12, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04,
...                    blade=BladeGeometry(span=0.15, root_chord=0.04, thickness=0.006))
>>> mesh = sector_mesh(g, size=0.03)
>>> sorted(mesh.groups), mesh.body_type
(['hub', 'left', 'right', 'sector', 'tip'], 'tetra')
>>> len(mesh.group("left")) == len(mesh.group("right"))
True
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..checks import integer, positive
from .cad import build_blade, gmsh_model
from .cyclic import rotation_matrix
from .mesh import Mesh, load_mesh
from .rotation import RotationAxis
from .shapes import BladeGeometry

__all__ = ["SectorGeometry", "sector_mesh"]

#: Relative tolerance (of the rim radius) of the node groups found by position (hub, faces, tip).
GROUP_RTOL = 1e-7


@dataclass(frozen=True)
class SectorGeometry:
    """A bladed-disk sector (module docstring).

    Parameters
    ----------
    sectors : int
        ``N >= 3`` blades round the disk; the sector spans ``360°/N``.
    hub_radius, rim_radius : float
        The disk's bore and rim radii about the engine axis (m, ``0 < hub < rim``).
    disk_thickness : float
        The disk's axial thickness (m), centred on ``x = 0``.
    blade : BladeGeometry
        The blade, as for a blade alone; it must stay inside the sector's angle.

    >>> SectorGeometry(12, 0.3, 0.25, 0.04, BladeGeometry(span=0.15, root_chord=0.04, thickness=0.006))
    Traceback (most recent call last):
        ...
    ValueError: hub_radius = 0.3 must be smaller than rim_radius = 0.25
    """

    sectors: int
    hub_radius: float
    rim_radius: float
    disk_thickness: float
    blade: BladeGeometry

    def __post_init__(self):
        object.__setattr__(self, "sectors", integer("sectors", self.sectors, 3, 10_000))
        for name in ("hub_radius", "rim_radius", "disk_thickness"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        if self.hub_radius >= self.rim_radius:
            raise ValueError(f"hub_radius = {self.hub_radius!r} must be smaller than rim_radius = {self.rim_radius!r}")
        if not isinstance(self.blade, BladeGeometry):
            raise ValueError(f"blade must be a BladeGeometry, got {type(self.blade).__name__}")
        half = math.pi / self.sectors
        for z in (0.0, self.blade.span):
            pts = np.vstack(self.blade.section(z))
            angle = np.abs(np.arctan2(pts[:, 1], pts[:, 2] + self.rim_radius)).max()
            if angle >= 0.95 * half:
                raise ValueError(f"the blade reaches {math.degrees(angle):.4g}° from the sector's middle at z = {z:g} m"
                                 f", beyond the sector's half-angle 180°/{self.sectors} = {math.degrees(half):.4g}°: "
                                 "fewer sectors, a larger rim_radius or a narrower blade")

    @property
    def axis(self) -> RotationAxis:
        """The engine axis: through ``(0, 0, −rim_radius)`` along ``+x``."""
        return RotationAxis((0.0, 0.0, -self.rim_radius), (1.0, 0.0, 0.0))

    def root_depth(self) -> float:
        """How far the blade's root section is extruded below ``z = 0`` into the rim (m): the rim's sag under the
        root section plus a tenth of the disk's radial depth."""
        y = np.abs(np.vstack(self.blade.section(0.0))[:, 1]).max()
        sag = self.rim_radius - math.sqrt(max(self.rim_radius ** 2 - y * y, 0.0))
        return sag + 0.1 * (self.rim_radius - self.hub_radius)


def _disk(gmsh, g: SectorGeometry) -> int:
    """The disk sector: an annular sector in the plane ``x = −t/2`` extruded along ``+x``."""
    occ = gmsh.model.occ
    c = np.array([-0.5 * g.disk_thickness, 0.0, -g.rim_radius])
    half = math.pi / g.sectors

    def at(r, a):  # angle a from +z, right-handed about +x (towards −y)
        return c + r * np.array([0.0, -math.sin(a), math.cos(a)])

    centre = occ.addPoint(*c)
    p = [occ.addPoint(*at(r, a)) for r, a in ((g.hub_radius, -half), (g.rim_radius, -half), (g.rim_radius, half),
                                                (g.hub_radius, half))]
    curves = [occ.addLine(p[0], p[1]), occ.addCircleArc(p[1], centre, p[2]), occ.addLine(p[2], p[3]),
              occ.addCircleArc(p[3], centre, p[0])]
    face = occ.addPlaneSurface([occ.addCurveLoop(curves)])
    out = occ.extrude([(2, face)], g.disk_thickness, 0.0, 0.0)
    occ.remove([(0, centre)])
    return next(t for d, t in out if d == 3)


def _faces(gmsh, g: SectorGeometry) -> tuple[list[int], list[int]]:
    """The planar cyclic faces (left at −180°/N, right at +180°/N) of the fused body, by their centres of mass."""
    left, right = [], []
    half = math.pi / g.sectors
    for _, t in gmsh.model.getEntities(2):
        com = np.array(gmsh.model.occ.getCenterOfMass(2, t))
        a = math.atan2(-com[1], com[2] + g.rim_radius)
        if abs(a + half) < 1e-9:
            left.append(t)
        elif abs(a - half) < 1e-9:
            right.append(t)
    if len(left) != 1 or len(right) != 1:
        raise RuntimeError(f"could not identify the sector's cyclic faces (left {left}, right {right})")
    return left, right


def _groups(mesh: Mesh, g: SectorGeometry, contact) -> dict:
    tol = GROUP_RTOL * g.rim_radius
    theta = np.arctan2(-mesh.points[:, 1], mesh.points[:, 2] + g.rim_radius)  # right-handed about +x, from +z
    radial = np.hypot(mesh.points[:, 1], mesh.points[:, 2] + g.rim_radius)
    half = math.pi / g.sectors
    groups = {"sector": np.arange(len(mesh.points)),
              "hub": np.flatnonzero(np.abs(radial - g.hub_radius) <= tol),
              "left": np.flatnonzero(radial * np.abs(theta + half) <= tol),
              "right": np.flatnonzero(radial * np.abs(theta - half) <= tol),
              "tip": np.flatnonzero(np.abs(mesh.points[:, 2] - g.blade.span) <= tol)}
    if contact is not None:
        d = np.linalg.norm(mesh.points - np.asarray(contact), axis=1)
        groups["contact"] = np.flatnonzero(d <= tol)
    return groups


def sector_mesh(geometry: SectorGeometry, size: float | None = None, order: int = 1) -> Mesh:
    """Mesh a :class:`SectorGeometry` with tetrahedra (order 1 or 2), the cyclic faces periodic (module docstring).

    ``size``: the element size (``None``: the blade's default size).  ``ValueError`` for a bad ``size`` or
    ``order``; ``RuntimeError`` if gmsh fails.
    """
    if not isinstance(geometry, SectorGeometry):
        raise ValueError(f"geometry must be a SectorGeometry, got {type(geometry).__name__}")
    g = geometry
    size = g.blade.default_size() if size is None else positive("size", size)
    if isinstance(order, bool) or order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, got {order!r}")
    options = {"General.NumThreads": 1, "Mesh.MeshSizeMax": size, "Mesh.MeshSizeMin": 0.0,
               "Mesh.MeshSizeFromPoints": 0, "Mesh.MeshSizeFromCurvature": 0, "Mesh.MeshSizeExtendFromBoundary": 0,
               "Mesh.ElementOrder": 1, "Mesh.MshFileVersion": 4.1, "Mesh.Binary": 1, "Mesh.SaveAll": 0}
    alpha = 2.0 * math.pi / g.sectors
    R = rotation_matrix(g.axis.direction, alpha)
    o = g.axis.origin
    affine = np.eye(4)
    affine[:3, :3], affine[:3, 3] = R, o - R @ o
    blade = replace(g.blade, contact_point=None)
    with tempfile.TemporaryDirectory(prefix="bladecase-") as tmp, gmsh_model("bladecase-sector", options) as gmsh:
        target = Path(tmp) / "sector.msh"
        try:
            occ = gmsh.model.occ
            body, root, _, _ = build_blade(gmsh, blade)
            prism = occ.extrude([(2, t) for t in root], 0.0, 0.0, -g.root_depth())
            disk = _disk(gmsh, g)
            fused, _ = occ.fuse([(3, disk)], [(3, body)] + [(d, t) for d, t in prism if d == 3])
            occ.synchronize()
            volumes = [t for d, t in fused if d == 3]
            if len(volumes) != 1:
                raise RuntimeError(f"the disk and the blade fused into {len(volumes)} bodies instead of one")
            left, right = _faces(gmsh, g)
            gmsh.model.mesh.setPeriodic(2, right, left, affine.ravel().tolist())
            if g.blade.contact_point is not None:
                tip = [t for _, t in gmsh.model.getEntities(2)
                       if abs(gmsh.model.occ.getCenterOfMass(2, t)[2] - g.blade.span) < 1e-9 * g.blade.span]
                point = occ.addPoint(*g.blade.contact_point)
                occ.synchronize()
                gmsh.model.mesh.embed(0, [point], 2, tip[0])
            gmsh.model.addPhysicalGroup(3, volumes, name="sector")
            gmsh.model.mesh.generate(3)
            if order == 2:
                gmsh.model.mesh.setOrder(2)
                gmsh.model.mesh.optimize("HighOrder")
            gmsh.write(str(target))
        except (ValueError, RuntimeError):
            raise
        except Exception as exc:
            raise RuntimeError(f"gmsh failed to mesh {g!r}: {exc}") from None
        try:
            mesh = load_mesh(target)
        except ValueError as exc:
            raise RuntimeError(f"gmsh made an invalid mesh of {g!r} (try another size or order): {exc}") from None
    groups = _groups(mesh, g, g.blade.contact_point)
    return replace(mesh, groups=groups, source=f"sector_mesh({g!r})")
