"""The casing as a surface of revolution about the engine axis, and what each contact node sees of it.

A casing is a cylinder (``radius``) or a cone (``radii`` at two axial stations, linear in between and beyond)
about the rotation axis.  A blade node at ``x`` has an axial coordinate ``s = (x − o)·a``, a radius ``r`` (its
distance from the axis) and a radial direction ``e_r``.  The casing there has the radius ``R(s)`` and the
inward-pointing slope ``R'(s)``; its unit normal, from the blade towards the casing, is
``n = (e_r − R'(s) a) / √(1 + R'²)`` and the clearance along it ``d = (R(s) − r) / √(1 + R'²)`` (exact for a
cone, whose meridian is straight).  On NASA Rotor 37's conical casing the tip nodes' normals span about ten
degrees and their radii 17 mm: one plane and one normal do not describe them.

>>> import numpy as np
>>> from bladecase.fe.rotation import RotationAxis
>>> cone = Casing(RotationAxis((0, 0, 0), (1, 0, 0)), radii=((0.0, 0.30), (0.1, 0.29)))   # narrowing along x
>>> d, n = cone.clearances(np.array([[0.05, 0.0, 0.294], [0.0, 0.2999, 0.0]]))
>>> (d * 1e3).round(4).tolist()          # mm, along each node's casing normal
[0.995, 0.0995]
>>> n.round(4).tolist()                   # tilted by the cone's slope (-0.1) towards +x
[[0.0995, 0.0, 0.995], [0.0995, 0.995, 0.0]]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fe.rotation import RotationAxis

__all__ = ["WEAK_CASING", "Casing", "frequency_rise_bound", "ring_stiffness"]


@dataclass(frozen=True)
class Casing:
    """A casing of revolution about ``axis``: a cylinder of ``radius`` (m), or a cone through ``radii`` =
    ``((s1, R1), (s2, R2))`` (axial stations in m along the axis from its origin, radii in m)."""

    axis: RotationAxis
    radius: float | None = None
    radii: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.axis, RotationAxis):
            raise ValueError(f"casing axis must be a RotationAxis, got {type(self.axis).__name__}")
        if (self.radius is None) == (self.radii is None):
            raise ValueError("a casing has a radius (a cylinder) or radii at two axial stations (a cone), one of them")
        if self.radius is not None:
            r = float(self.radius) if not isinstance(self.radius, bool) else float("nan")
            if not (np.isfinite(r) and r > 0):
                raise ValueError(f"casing radius must be a finite number > 0 (m), got {self.radius!r}")
            object.__setattr__(self, "radius", r)
        else:
            try:
                (s1, r1), (s2, r2) = ((float(a), float(b)) for a, b in self.radii)
            except (TypeError, ValueError):
                raise ValueError(f"casing radii must be [[s1, R1], [s2, R2]] (axial station, radius; m), got "
                                 f"{self.radii!r}") from None
            if not all(np.isfinite([s1, r1, s2, r2])) or s1 == s2 or min(r1, r2) <= 0:
                raise ValueError(f"casing radii must be two distinct axial stations with radii > 0, got {self.radii!r}")
            object.__setattr__(self, "radii", ((s1, r1), (s2, r2)))

    def profile(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(R(s), R'(s))``: the casing's radius and its slope at the axial coordinates ``s``."""
        s = np.asarray(s, dtype=float)
        if self.radius is not None:
            return np.full(s.shape, self.radius), np.zeros(s.shape)
        (s1, r1), (s2, r2) = self.radii
        slope = (r2 - r1) / (s2 - s1)
        return r1 + slope * (s - s1), np.full(s.shape, slope)

    def clearances(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(d, n)``: each point's clearance to the casing (m, along ``n``) and the casing's unit normal there,
        pointing from the blade to the casing (``(k, 3)``).  ``ValueError`` for a point on the axis."""
        x = np.asarray(points, dtype=float).reshape(-1, 3) - self.axis.origin
        a = self.axis.direction
        s = x @ a
        radial = x - np.outer(s, a)
        r = np.linalg.norm(radial, axis=1)
        if np.any(r <= 0):
            raise ValueError("a contact node lies on the rotation axis: it has no radial direction to the casing")
        e_r = radial / r[:, None]
        R, slope = self.profile(s)
        scale = np.sqrt(1.0 + slope**2)
        n = (e_r - slope[:, None] * a) / scale[:, None]
        return (R - r) / scale, n


#: The casing's stiffness (in series with the contact's own) below this fraction of the blade's static stiffness at
#: the contact ``1/(wᵀK⁻¹w)`` is "far below": the closed contact then raises no mode by more than
#: ``√(1 + 0.01) − 1 ≈ 0.5 %`` (:func:`frequency_rise_bound`), below a typical mesh's own frequency error — the
#: contact barely changes the modes, and a nonsmooth-mode band, if any, is that narrow.
WEAK_CASING = 0.01


def frequency_rise_bound(casing: float, static: float) -> float:
    """The largest relative rise of a mode's frequency a closed contact of stiffness ``casing`` (N/m) can cause on a
    blade whose static stiffness at the contact is ``static = 1/(wᵀK⁻¹w)`` (N/m): ``√(1 + casing/static) − 1``.

    Why: the closed contact adds ``casing·w wᵀ`` to ``K``; in the shape of mode ``j`` (mass-normalised, contact
    participation ``b_j = wᵀφ_j``) Rayleigh's quotient grows from ``ω_j²`` to ``ω_j² + casing·b_j²``, and
    ``b_j²/ω_j² ≤ Σ_k b_k²/ω_k² = wᵀK⁻¹w``: so by at most the factor ``1 + casing/static``.  A nonsmooth mode,
    open for part of its period, lies between the open and the closed frequency.

    >>> round(100 * frequency_rise_bound(1.0e6, 7.1e8), 3)        # a 1e6 N/m casing ring on a stiff blade: %
    0.07
    """
    return float(np.sqrt(1.0 + casing / static) - 1.0)


def ring_stiffness(E: float, radius: float, thickness: float, width: float) -> float:
    """A casing ring's local radial stiffness (N/m), as an order of magnitude of the casing under one blade: a thin
    circular ring of ``radius`` (m), wall ``thickness`` and axial ``width`` (m), modulus ``E`` (Pa), pinched by two
    opposite forces ``F``, closes its diameter by ``(π/4 − 2/π) F R³/(E I)``, ``I = width·thickness³/12`` (Roark's
    formulas for a thin circular ring): ``k = E I / ((π/4 − 2/π) R³)``.

    >>> f"{ring_stiffness(200e9, 0.45, 0.020, 0.100):.3g}"      # a steel casing, 20 mm thick over 100 mm: N/m
    '9.83e+05'
    """
    values = {"E": E, "radius": radius, "thickness": thickness, "width": width}
    for name, v in values.items():
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)) or not (np.isfinite(v) and v > 0):
            raise ValueError(f"ring_stiffness: {name} must be a finite number > 0, got {v!r}")
    if thickness >= radius:
        raise ValueError(f"ring_stiffness: a thin ring's thickness must be below its radius (R = {radius!r} m), got "
                         f"{thickness!r}")
    inertia = width * thickness**3 / 12.0
    return float(E * inertia / ((np.pi / 4 - 2 / np.pi) * radius**3))
