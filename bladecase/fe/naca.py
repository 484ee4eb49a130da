"""NACA 4-digit sections with a blunt trailing edge (:func:`naca_section`), lofted by the 3-D blades.

>>> naca_parameters("2412")
(0.02, 0.4, 0.12)
>>> upper, lower, tangent = naca_section("0012", chord=1.0, trailing_edge_thickness=0.01, n=5)
>>> upper[0].tolist(), round(float(upper[-1, 0]), 12), round(float(upper[-1, 1] - lower[-1, 1]), 12)
([-0.5, 0.0], 0.5, 0.01)
"""

from __future__ import annotations

import re

import numpy as np

#: Points per side (suction, pressure) of a NACA section, cosine-spaced.
SECTION_POINTS = 41

_NACA = re.compile(r"^[0-9]{4}$")


def naca_parameters(code: str) -> tuple[float, float, float]:
    """``(m, p, t)`` of a NACA 4-digit code: max camber, its chordwise position, thickness (chord fractions).

    ``"2412"`` gives ``(0.02, 0.4, 0.12)``.  ``ValueError`` unless ``code`` is
    four digits with ``t > 0`` and, for a cambered section, ``0 < p``.
    """
    if not isinstance(code, str) or not _NACA.match(code):
        raise ValueError(f"naca must be a 4-digit string such as '2412' or '0012', got {code!r}")
    m, p, t = int(code[0]) / 100, int(code[1]) / 10, int(code[2:]) / 100
    if t == 0:
        raise ValueError(f"naca {code!r} has zero thickness (last two digits must be >= 01)")
    if m > 0 and p == 0:
        raise ValueError(
            f"naca {code!r} is cambered (m = {m:g}) but puts the camber at p = 0 (second digit must be 1..9)"
        )
    return m, p, t


def naca_section(code: str, chord: float, trailing_edge_thickness: float, n: int | None = None):
    """Upper and lower surfaces of a NACA 4-digit section with a blunt trailing edge.

    The half-thickness is the closed-trailing-edge NACA polynomial
    (``a4 = -0.1036``) plus the linear ramp ``x·te/2``, so the trailing edge is
    a straight segment of length ``te·chord`` normal to the camber line.

    Parameters
    ----------
    code : str
        NACA 4-digit code.
    chord : float
        Chord length.
    trailing_edge_thickness : float
        Trailing-edge thickness as a fraction of the chord (``0 < te < t``).
    n : int or None
        Points per surface (cosine spacing, dense at both edges); ``None``
        for :data:`SECTION_POINTS`.

    Returns
    -------
    upper, lower : (n, 2) ndarray
        Points in the section frame, both from the leading edge
        ``(-chord/2, 0)`` to the trailing edge (``x ≈ +chord/2``); the suction
        (upper) side is towards ``+y`` for positive camber.
    le_tangent : (2,) ndarray
        Unit tangent at the leading edge, pointing from the upper to the lower surface.
    """
    m, p, t = naca_parameters(code)
    te = trailing_edge_thickness
    n = SECTION_POINTS if n is None else n
    x = 0.5 * (1 - np.cos(np.linspace(0.0, np.pi, n)))
    yt = 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4) + 0.5 * te * x
    if m > 0:
        front = x < p
        yc = np.where(front, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x**2))
        dyc = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
    else:
        yc = dyc = np.zeros_like(x)
    th = np.arctan(dyc)
    upper = np.column_stack([x - yt * np.sin(th), yc + yt * np.cos(th)])
    lower = np.column_stack([x + yt * np.sin(th), yc - yt * np.cos(th)])
    upper[0] = lower[0] = 0.0  # the leading edge, exactly
    shift = np.array([0.5, 0.0])
    le_tangent = np.array([np.sin(th[0]), -np.cos(th[0])])
    return (upper - shift) * chord, (lower - shift) * chord, le_tangent

