"""An abradable coating round the casing, worn by the blade tip: :class:`Abradable`, :class:`WearProfile`,
:func:`pass_tip`, :func:`harmonic_lobes`.

**The coating.** A layer of ``thickness`` on the casing, discretised round the casing into ``cells`` equal
angular cells (the profile). Each cell is an elastic–perfectly plastic foundation: a tip pressing into it by
``δ`` (beyond its current worn surface) feels the pressure ``p = k·δ`` (``k``: ``stiffness``, Pa/m) up to the
``yield_pressure`` ``p_y``; pressed further, the coating does not push harder, it is removed: the worn surface
recedes so that the elastic penetration stays ``δ_y = p_y/k``. When the tip leaves, the elastic part springs back
and the removed part stays removed: the next passage sees the worn profile. A rigid–plastic coating
(``stiffness = inf``) is removed wherever the tip reaches it.

**Geometry.** Angles ``θ`` about the engine axis (rad, any real: taken modulo 2π); the tip's radial incursion
``r(θ)`` (m) is measured outwards from the coating's unworn surface at radius ``radius``; a cell's worn depth
``d_c`` (m, ``0 ≤ d_c ≤ thickness``) moves its surface out to ``radius + d_c``. In a cell, one passage leaves
``d_c ← max(d_c, max_{θ∈cell} r(θ) − δ_y)`` (capped at the thickness: the tip then reaches the casing, reported).
The coating's missing area is the annular ``Σ_c ½((R + d_c)² − R²)Δθ``; times the axial ``width``, the removed
volume. Each passage also adds its own removal to :attr:`WearProfile.removed` as it happens (the bookkeeping of
the volume, checked against the profile).

>>> c = Abradable(thickness=1e-3, yield_pressure=2e6, stiffness=1e12, cells=8, radius=0.3, width=0.02)
>>> p = WearProfile.new(c)
>>> theta = np.linspace(0.0, 2 * np.pi, 801)
>>> p, pressure = pass_tip(p, theta, 5e-5 * np.cos(2 * theta))   # a two-lobe path, 50 µm at its peaks
>>> (p.depth * 1e6).round(3).tolist()                              # 50 µm − δ_y = 48 µm at the peaks (0, π)
[48.0, 0.0, 0.0, 47.994, 48.0, 0.0, 0.0, 47.994]
>>> float(pressure.max()) == c.yield_pressure, p.lobes()
(True, 2)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["LOBE_SHARE", "Abradable", "WearProfile", "harmonic_lobes", "pass_tip"]

#: The share of the strongest harmonic (or spectral line) within which another one counts as its equal: a
#: fundamental of peaked lobes, or a rival lobe count (:func:`harmonic_lobes`).
LOBE_SHARE = 0.5


def _positive(name: str, value, allow_inf: bool = False) -> float:
    ok = isinstance(value, (int, float, np.floating)) and not isinstance(value, bool)
    v = float(value) if ok else np.nan
    if not (v > 0 and (np.isfinite(v) or (allow_inf and v == np.inf))):
        valid = "a number > 0 (inf: rigid–plastic)" if allow_inf else "a finite number > 0"
        raise ValueError(f"abradable {name} must be {valid}, got {value!r}")
    return v


@dataclass(frozen=True)
class Abradable:
    """An elastic–perfectly plastic abradable coating (module docstring): ``thickness`` (m), ``yield_pressure``
    (Pa), ``stiffness`` per area (Pa/m; ``inf``: rigid–plastic), ``cells`` round the casing, the unworn surface's
    ``radius`` (m) and the rubbed band's axial ``width`` (m).

    >>> Abradable(1e-3, 2e6, 1e12, cells=360, radius=0.3, width=0.02).yield_depth
    2e-06
    >>> Abradable(1e-3, -1.0, 1e12, cells=360, radius=0.3, width=0.02)
    Traceback (most recent call last):
    ...
    ValueError: abradable yield_pressure must be a finite number > 0, got -1.0
    """

    thickness: float
    yield_pressure: float
    stiffness: float
    cells: int = 360
    radius: float = 1.0
    width: float = 1.0

    def __post_init__(self) -> None:
        for name in ("thickness", "yield_pressure", "radius", "width"):
            object.__setattr__(self, name, _positive(name, getattr(self, name)))
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness, allow_inf=True))
        n = self.cells
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
            raise ValueError(f"abradable cells must be an integer >= 3 (cells round the casing), got {n!r}")
        object.__setattr__(self, "cells", int(n))

    @property
    def yield_depth(self) -> float:
        """``δ_y = p_y / k``: the elastic penetration at which the coating starts to be removed (m)."""
        return self.yield_pressure / self.stiffness

    @property
    def step(self) -> float:
        """A cell's angle ``Δθ = 2π / cells`` (rad)."""
        return 2 * np.pi / self.cells

    def cell(self, theta) -> np.ndarray:
        """The cell holding each angle ``theta`` (rad, any real)."""
        return np.floor(np.mod(np.asarray(theta, dtype=float), 2 * np.pi) / self.step).astype(int) % self.cells

    def annulus(self, depth) -> np.ndarray:
        """Each cell's missing area for the worn depths ``depth`` (m²): ``½((R + d)² − R²)Δθ``."""
        d = np.asarray(depth, dtype=float)
        return 0.5 * d * (2 * self.radius + d) * self.step


@dataclass(frozen=True, eq=False)
class WearProfile:
    """The worn depth of each cell (m), the volume removed passage by passage (m³), the profile after each
    recorded passage (``history``: ``(k, cells)``) and whether the tip has worn through to the casing anywhere."""

    coating: Abradable
    depth: np.ndarray
    removed: float = 0.0
    history: tuple = field(default=(), repr=False)
    worn_through: bool = False

    @classmethod
    def new(cls, coating: Abradable) -> WearProfile:
        """An unworn profile."""
        if not isinstance(coating, Abradable):
            raise ValueError(f"coating must be an Abradable, got {type(coating).__name__}")
        return cls(coating, np.zeros(coating.cells))

    @property
    def missing_area(self) -> float:
        """The coating's missing cross-section round the casing (m²)."""
        return float(self.coating.annulus(self.depth).sum())

    @property
    def missing_volume(self) -> float:
        """``missing_area × width`` (m³): what :attr:`removed` must equal."""
        return self.missing_area * self.coating.width

    def angles(self) -> np.ndarray:
        """The cells' centre angles (rad)."""
        return (np.arange(self.coating.cells) + 0.5) * self.coating.step

    def lobes(self, share: float = LOBE_SHARE) -> int:
        """The number of lobes of the profile (:func:`harmonic_lobes`: its strongest circumferential harmonic, or
        the lowest divisor of it within ``share`` of its amplitude; ``0``: unworn or uniform).

        >>> c = Abradable(1e-3, 1e6, np.inf, cells=90, radius=0.3, width=0.01)
        >>> WearProfile(c, 1e-5 * (1 + np.cos(7 * WearProfile.new(c).angles()))).lobes()
        7
        """
        return harmonic_lobes(self.depth, share)[0]


def harmonic_lobes(depth, share: float = LOBE_SHARE) -> tuple[int, int]:
    """``(lobes, rival)`` of a profile of depths round the casing (any equal cells): ``lobes`` is its strongest
    circumferential harmonic ``N``, or the lowest divisor ``k ≥ 2`` of ``N`` whose amplitude is within ``share`` of
    the strongest (``N`` is then an overtone of ``k`` lobes: peaked lobes); ``0`` for an unworn or uniform profile.
    ``rival`` is the strongest other harmonic within ``share`` of the strongest that is neither a multiple of
    ``lobes`` nor ``1`` (``0``: none): a profile with a rival has no one lobe count. Harmonic 1 is never a rival
    (nor taken as a lobe count when another harmonic is stronger): it is wear on one part of the circumference,
    the envelope of the lobes, not a lobe count.

    >>> theta = (np.arange(90) + 0.5) * 2 * np.pi / 90
    >>> harmonic_lobes(np.maximum(np.cos(8 * theta), 0.0))          # peaked lobes: overtones 16, 24, … of 8
    (8, 0)
    >>> harmonic_lobes(1.0 + np.cos(9 * theta) + 0.8 * np.cos(10 * theta))   # two lobe counts: 9 has a rival
    (9, 10)
    """
    d = np.asarray(depth, dtype=float)
    d = d - d.mean()
    amp = np.abs(np.fft.rfft(d))[1:]
    if amp.size == 0 or not np.any(np.abs(d) > 1e-15 * max(np.abs(np.asarray(depth, dtype=float)).max(), 1e-300)):
        return 0, 0
    strong = amp >= (1 - share) * amp.max()
    top = int(np.argmax(amp)) + 1
    lobes = next((k for k in range(2, top) if top % k == 0 and strong[k - 1]), top)
    rivals = [h for h in np.flatnonzero(strong) + 1 if h % lobes and h != 1]
    return lobes, int(max(rivals, key=lambda h: amp[h - 1])) if rivals else 0


def pass_tip(profile: WearProfile, theta, r, record: bool = False) -> tuple[WearProfile, np.ndarray]:
    """One tip passage along the incursion ``r(θ)`` (m, outwards from the unworn surface) sampled at the angles
    ``theta`` (rad, in the order the tip meets them): the worn profile and the contact pressure at each sample (Pa).

    The samples are taken in order: a sample removes what its cell's surface left beyond ``δ_y`` (module
    docstring), and its pressure is ``k·clip(r − d, 0, δ_y)`` against the surface as worn so far (``p_y`` while
    removing; a rigid–plastic coating: ``p_y`` wherever it touches). ``record``: keep the new profile in
    ``history``.

    >>> c = Abradable(1e-3, 1e6, np.inf, cells=4, radius=1.0, width=1.0)
    >>> p, pr = pass_tip(WearProfile.new(c), [0.1, 0.2, 2.0], [1e-4, 3e-4, -1e-5])
    >>> p.depth.tolist(), pr.tolist()
    ([0.0003, 0.0, 0.0, 0.0], [1000000.0, 1000000.0, 0.0])
    """
    if not isinstance(profile, WearProfile):
        raise ValueError(f"profile must be a WearProfile, got {type(profile).__name__}")
    c = profile.coating
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    r = np.broadcast_to(np.asarray(r, dtype=float), theta.shape)
    if theta.ndim != 1 or not (np.all(np.isfinite(theta)) and np.all(np.isfinite(r))):
        raise ValueError(f"theta and r must be finite 1-D samples of one shape, got {theta.shape} and {r.shape}")
    cell = c.cell(theta)
    depth = profile.depth.copy()
    reach = r - c.yield_depth  # the depth a sample wears the surface to
    now = np.empty_like(r)  # each sample's surface, as worn up to and with it
    for k in np.unique(cell):
        sel = np.flatnonzero(cell == k)
        run = np.maximum.accumulate(np.maximum(reach[sel], depth[k]))
        now[sel] = run
        depth[k] = run[-1]
    through = bool(np.any(depth > c.thickness))
    depth = np.minimum(depth, c.thickness)
    now = np.minimum(now, c.thickness)
    penetration = np.clip(r - now, 0.0, c.yield_depth)
    pressure = c.stiffness * penetration if np.isfinite(c.stiffness) else np.where(r >= now, c.yield_pressure, 0.0)
    if np.isfinite(c.stiffness):
        pressure = np.minimum(pressure, c.yield_pressure)
    added = float((c.annulus(depth) - c.annulus(profile.depth)).sum()) * c.width
    history = profile.history + (depth.copy(),) if record else profile.history
    return WearProfile(c, depth, profile.removed + added, history, profile.worn_through or through), pressure
