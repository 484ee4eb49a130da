"""The parametric shapes :func:`~bladecase.fe.geometry.blade_mesh` meshes: :class:`BladeGeometry` (a solid blade
lofted through sections, radial along ``+z``) and :class:`PlateGeometry` (a plane-stress membrane, radial along
``+y``), with every field checked where it is given (types, ranges, the contact point on the tip).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import finite, integer, point, positive
from .mesh_checks import EXTENT_RANGE
from .naca import naca_parameters, naca_section

__all__ = ["CONTACT_RTOL", "MAX_SECTIONS", "BladeGeometry", "PlateGeometry"]

#: Relative tolerance on the radial coordinate of a contact point (of ``span``).
CONTACT_RTOL = 1e-9

#: Most lofted sections of a :class:`BladeGeometry` (OpenCASCADE lofts through
#: hundreds of sections take minutes; a smooth blade needs a handful).
MAX_SECTIONS = 200


def _is_number(value) -> bool:
    """A real number: Python or numpy int/float, not a boolean nor a string."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _check_types(obj, units: dict[str, str], optional: tuple[str, ...] = ()) -> None:
    """Every field in ``units`` must be a number (``None`` allowed for ``optional``), else ``ValueError``."""
    for name, unit in units.items():
        value = getattr(obj, name)
        if value is None and name in optional:
            continue
        if not _is_number(value):
            hint = " or omitted" if name in optional else ""
            raise ValueError(f"{name} must be a number ({unit}){hint}, got {value!r}")


def _check_lengths(obj, names: tuple[str, ...], offsets: tuple[str, ...] = ()) -> None:
    """Lengths (``names``, > 0) within :data:`~bladecase.fe.mesh.EXTENT_RANGE` and offsets (``offsets``) at most
    its upper end: outside, a unit mistake, and gmsh and the FE matrices over- or underflow."""
    lo, hi = EXTENT_RANGE
    for name in names:
        value = getattr(obj, name)
        if value is not None and value > 0 and not lo <= value <= hi:
            raise ValueError(f"{name} = {value!r} m is out of the range [{lo:g}, {hi:g}] m of a blade's lengths "
                             "(a unit mistake?)")
    for name in offsets:
        value = getattr(obj, name)
        if math.isfinite(value) and abs(value) > hi:
            raise ValueError(f"{name} = {value!r} m is out of the range [-{hi:g}, {hi:g}] m (a unit mistake?)")


def _check_point(name: str, value, sizes: tuple[int, ...]) -> None:
    """``value`` must be a list/tuple/array of ``sizes`` numbers (then checked by :func:`~bladecase.checks.point`)."""
    counts = " or ".join(map(str, sizes))
    items = value.tolist() if isinstance(value, np.ndarray) and value.ndim == 1 else value
    if not isinstance(items, (list, tuple)) or len(items) not in sizes or not all(map(_is_number, items)):
        raise ValueError(f"{name} must be a list of {counts} numbers (metres), got {value!r}")


@dataclass(frozen=True)
class BladeGeometry:
    """A solid blade lofted through sections, radial along ``+z``.

    Parameters
    ----------
    span : float
        Radial length: root face at ``z = 0``, tip face at ``z = span``.
    root_chord : float
        Chord at the root.
    tip_chord : float or None
        Chord at the tip (linear taper); ``None`` for no taper.
    thickness : float or None
        Absolute thickness of a rectangular section (``chord × thickness``);
        ``None`` to use ``naca``.  Give exactly one of ``thickness`` and ``naca``.
    naca : str or None
        NACA 4-digit code, e.g. ``"2412"`` (2 % camber at 40 % chord, 12 % thick).
    twist_deg : float
        Twist from root to tip (degrees), linear along the span.
    stagger_deg : float
        Stagger (setting) angle of the root section (degrees), counter-clockwise
        about ``+z`` from the ``+x`` axis.  Section ``z`` is at
        ``stagger_deg + twist_deg · z / span``.
    sweep, lean : float
        Offsets of the tip section along ``x`` (sweep) and ``y`` (lean),
        linear along the span.  Sections are stacked on their mid-chord point,
        which is at ``(sweep · z/span, lean · z/span, z)``.
    n_sections : int
        Number of lofted sections (>= 2), equally spaced along the span.
    trailing_edge_thickness : float
        Blunt trailing edge of a NACA section, as a fraction of the chord
        (``0 < te < t``).  Ignored for rectangular sections.
    contact_point : (x, y, z) or None
        A point of the tip face (``z = span`` to ``CONTACT_RTOL``; stored as
        ``(x, y, span)``) that becomes a mesh node exactly (group
        ``contact``); it must lie strictly inside the face.

    Examples
    --------
    A tapered, twisted NACA 2412 blade; chord and section angle vary linearly along the span:

    >>> g = BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", twist_deg=40.0,
    ...                   contact_point=(0, 0, 0.15))
    >>> g.chord(0.15), g.angle_deg(0.075), g.contact_point
    (0.035, 20.0, (0.0, 0.0, 0.15))
    >>> round(g.max_thickness(), 6), round(g.default_size(), 6)  # 12 % of the tip chord; a tenth of it
    (0.004307, 0.0035)

    Parameters are checked when the geometry is made:

    >>> BladeGeometry(span=0.15, root_chord=0.05, naca="2412", contact_point=(0, 0, 0.1))
    Traceback (most recent call last):
        ...
    ValueError: contact_point (0, 0, 0.1) is not on the tip face z = span = 0.15
    >>> BladeGeometry(span=0.15, root_chord=0.05, naca="2412", trailing_edge_thickness=0.2)
    Traceback (most recent call last):
        ...
    ValueError: trailing_edge_thickness = 0.2 must be smaller than the thickness ratio 0.12 of naca '2412'
    """

    span: float
    root_chord: float
    tip_chord: float | None = None
    thickness: float | None = None
    naca: str | None = None
    twist_deg: float = 0.0
    stagger_deg: float = 0.0
    sweep: float = 0.0
    lean: float = 0.0
    n_sections: int = 5
    trailing_edge_thickness: float = 0.01
    contact_point: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        _check_types(self, {
            "span": "metres", "root_chord": "metres", "tip_chord": "metres", "thickness": "metres",
            "twist_deg": "degrees", "stagger_deg": "degrees", "sweep": "metres", "lean": "metres",
            "trailing_edge_thickness": "a fraction of the chord",
        }, optional=("tip_chord", "thickness"))
        if self.naca is not None and not isinstance(self.naca, str):
            raise ValueError(f"naca must be a 4-digit string such as '2412' or '0012', got {self.naca!r}")
        integer("n_sections", self.n_sections, 2, MAX_SECTIONS)
        if self.contact_point is not None:
            _check_point("contact_point", self.contact_point, (3,))
        positive("span", self.span)
        positive("root_chord", self.root_chord)
        positive("tip_chord", self.tip_chord, allow_none=True)
        positive("thickness", self.thickness, allow_none=True)
        if (self.thickness is None) == (self.naca is None):
            raise ValueError(
                "give exactly one of thickness (rectangular section) and naca (NACA 4-digit section), "
                f"got thickness={self.thickness!r}, naca={self.naca!r}"
            )
        for name in ("twist_deg", "stagger_deg", "sweep", "lean"):
            finite(name, getattr(self, name))
        _check_lengths(self, ("span", "root_chord", "tip_chord", "thickness"), ("sweep", "lean"))
        if self.naca is not None:
            t = naca_parameters(self.naca)[2]
            te = positive("trailing_edge_thickness", self.trailing_edge_thickness)
            if te >= t:
                raise ValueError(
                    f"trailing_edge_thickness = {te!r} must be smaller than the thickness ratio {t:g} "
                    f"of naca {self.naca!r}"
                )
        if self.contact_point is not None:
            x, y, z = point("contact_point", self.contact_point, (3,))
            if abs(z - self.span) > CONTACT_RTOL * self.span:
                raise ValueError(
                    f"contact_point {self.contact_point!r} is not on the tip face z = span = {self.span!r}"
                )
            object.__setattr__(self, "contact_point", (x, y, float(self.span)))  # normalised: floats, z = span

    def chord(self, z: float) -> float:
        """Chord at height ``z`` (linear taper)."""
        tip = self.root_chord if self.tip_chord is None else self.tip_chord
        s = z / self.span
        return (1 - s) * self.root_chord + s * tip

    def angle_deg(self, z: float) -> float:
        """Section angle at height ``z``: ``stagger_deg + twist_deg · z / span``."""
        return self.stagger_deg + self.twist_deg * z / self.span

    def section(self, z: float) -> list[np.ndarray]:
        """The section at height ``z`` as polylines of ``(x, y, z)`` points in global axes.

        A NACA section gives ``[suction side, pressure side, trailing edge]``:
        the suction side from the trailing to the leading edge, the pressure
        side back to the trailing edge, then the blunt trailing edge; a
        rectangular section its four sides.  Consecutive polylines share end
        points and together run round the section counter-clockwise seen
        from ``+z``.
        """
        c = self.chord(z)
        if self.naca is not None:
            upper, lower, _ = naca_section(self.naca, c, self.trailing_edge_thickness)
            parts = [upper[::-1], lower, np.array([lower[-1], upper[-1]])]
        else:
            h = 0.5 * self.thickness
            corners = np.array([[-c / 2, -h], [c / 2, -h], [c / 2, h], [-c / 2, h]])
            parts = [corners[[i, (i + 1) % 4]] for i in range(4)]
        return [self._place(q, z) for q in parts]

    def _place(self, q: np.ndarray, z: float) -> np.ndarray:
        a = math.radians(self.angle_deg(z))
        s = z / self.span
        ca, sa = math.cos(a), math.sin(a)
        x = ca * q[:, 0] - sa * q[:, 1] + self.sweep * s
        y = sa * q[:, 0] + ca * q[:, 1] + self.lean * s
        return np.column_stack([x, y, np.full(len(q), z)])

    def le_tangent(self, z: float) -> np.ndarray:
        """Unit tangent at the leading edge (suction → pressure side), global axes."""
        t = naca_section(self.naca, 1.0, self.trailing_edge_thickness, 3)[2]
        a = math.radians(self.angle_deg(z))
        return np.array([math.cos(a) * t[0] - math.sin(a) * t[1], math.sin(a) * t[0] + math.cos(a) * t[1], 0.0])

    def max_thickness(self) -> float:
        """Maximum thickness of the thinnest section (the smaller-chord one for NACA sections)."""
        if self.thickness is not None:
            return float(self.thickness)
        chord = min(self.chord(0.0), self.chord(self.span))
        upper, lower, _ = naca_section(self.naca, chord, self.trailing_edge_thickness, 201)
        return float(np.max(np.hypot(*(upper - lower).T)))

    def default_size(self) -> float:
        """Default mesh size: the smaller of a tenth of the smaller chord and :meth:`max_thickness`."""
        return min(0.1 * min(self.chord(0.0), self.chord(self.span)), self.max_thickness())


@dataclass(frozen=True)
class PlateGeometry:
    """A flat blade for plane-stress (membrane) studies, in the ``xy`` plane, radial along ``+y``.

    The plate is the trapezoid with the root edge ``[-chord/2, chord/2]`` at
    ``y = 0`` and the tip edge ``[sweep - taper·chord/2, sweep + taper·chord/2]``
    at ``y = span``.

    Parameters
    ----------
    span : float
        Radial length (along ``y``).
    chord : float
        Root chord (along ``x``).
    taper : float
        Tip chord / root chord (> 0).
    sweep : float
        ``x`` offset of the tip edge's midpoint.
    contact_point : (x, y) or (x, y, 0) or None
        A point of the tip edge (``y = span`` to ``CONTACT_RTOL``; stored as
        ``(x, span)``) that becomes a mesh node exactly (group ``contact``).
    """

    span: float
    chord: float
    taper: float = 1.0
    sweep: float = 0.0
    contact_point: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        _check_types(self, {"span": "metres", "chord": "metres", "taper": "tip chord / root chord",
                            "sweep": "metres"})
        if self.contact_point is not None:
            _check_point("contact_point", self.contact_point, (2, 3))
        positive("span", self.span)
        positive("chord", self.chord)
        positive("taper", self.taper)
        finite("sweep", self.sweep)
        _check_lengths(self, ("span", "chord"), ("sweep",))
        lo, hi = EXTENT_RANGE
        if not lo <= self.taper * self.chord <= hi:
            raise ValueError(f"taper = {self.taper!r} makes a tip chord of {self.taper * self.chord:g} m, out of the "
                             f"range [{lo:g}, {hi:g}] m of a blade's lengths")
        if self.contact_point is not None:
            p = point("contact_point", self.contact_point, (2, 3))
            x, y = p[:2]
            lo, hi = self.tip_edge()
            if abs(y - self.span) > CONTACT_RTOL * self.span or len(p) == 3 and p[2] != 0:
                raise ValueError(
                    f"contact_point {self.contact_point!r} is not on the tip edge y = span = {self.span!r} (z = 0)"
                )
            if not lo <= x <= hi:
                raise ValueError(
                    f"contact_point {self.contact_point!r} is off the tip edge: x must lie in [{lo:g}, {hi:g}]"
                )
            object.__setattr__(self, "contact_point", (x, float(self.span)))  # normalised: floats, y = span

    def tip_edge(self) -> tuple[float, float]:
        """``x`` range of the tip edge."""
        h = 0.5 * self.taper * self.chord
        return self.sweep - h, self.sweep + h

    def default_size(self) -> float:
        """Default mesh size: a tenth of the smallest of span, root and tip chords."""
        return 0.1 * min(self.span, self.chord, self.taper * self.chord)


# ----------------------------------------------------------------------------- meshing
