"""Isotropic linear-elastic materials and their handbook presets (:class:`Material`, :meth:`Material.preset`)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from skfem.models.elasticity import lame_parameters

from ..checks import positive

#: Accepted values of ``plane`` (2-D models).
PLANE_KINDS = ("stress", "strain")


#: ``E`` and ``rho`` must lie in ``[1 / SCALE_LIMIT, SCALE_LIMIT]``: beyond, the stiffness and mass
#: matrices (``~ E·L``, ``~ rho·L³``) and their eigenvalues under- or overflow (measured on a steel strip:
#: frequencies exact to 1e-8 for ``E`` in ``[1e-150, 1e150]``, 6× off at ``E = 1e-200``, NaN at ``1e200``).
SCALE_LIMIT = 1e60


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic material (SI units).

    Parameters
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio, ``-1 < nu < 0.5``.
    rho : float
        Density (kg/m³), > 0.
    name : str
        Label for messages and reports.

    Presets (:meth:`preset`, and the module constants :data:`TI6AL4V`,
    :data:`STEEL`, :data:`INCONEL718`, :data:`AL6061T6`) hold typical
    room-temperature handbook values (ASM Aerospace Specification Metals /
    MatWeb data sheets, consistent with MMPDS typical values):

    ============  =========  =====  =========  ===========================================
    preset        E (GPa)    ν      ρ (kg/m³)  source
    ============  =========  =====  =========  ===========================================
    Ti-6Al-4V     113.8      0.342  4430       ASM data sheet, Ti-6Al-4V (Grade 5), annealed
    steel         200        0.30   7850       typical carbon/structural steel handbook value
    Inconel 718   200        0.294  8190       Special Metals INCONEL 718 data (ASM/MatWeb);
                                               Special Metals' own table lists ≈ 204.9 GPa
    Al 6061-T6    68.9       0.33   2700       ASM data sheet, aluminium 6061-T6
    ============  =========  =====  =========  ===========================================

    Raises
    ------
    ValueError
        A value that is not a finite number in its valid range (``E`` and ``rho`` within
        ``[1e-60, 1e60]``, :data:`SCALE_LIMIT`).

    Examples
    --------
    >>> steel = Material(E=200e9, nu=0.3, rho=7850.0, name="steel")
    >>> lam, mu = steel.lame()             # 3-D: μ = E / 2(1 + ν)
    >>> round(lam / 1e9, 3), round(mu / 1e9, 3)
    (115.385, 76.923)
    >>> round(steel.lame("stress")[0] / 1e9, 3)   # plane stress: λ* = Eν / (1 - ν²)
    65.934
    >>> Material(E=200e9, nu=0.5, rho=7850.0)
    Traceback (most recent call last):
        ...
    ValueError: Poisson's ratio nu must be in (-1, 0.5) (open interval), got 0.5
    """

    E: float
    nu: float
    rho: float
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "E", positive("Young's modulus E", self.E, "> 0 (Pa)"))
        object.__setattr__(self, "rho", positive("density rho", self.rho, "> 0 (kg/m³)"))
        for label, value in (("Young's modulus E", self.E), ("density rho", self.rho)):
            if not 1 / SCALE_LIMIT <= value <= SCALE_LIMIT:
                raise ValueError(f"{label} = {value:g} is out of the range double precision handles in the "
                                 f"assembly and eigen-solution: [{1 / SCALE_LIMIT:g}, {SCALE_LIMIT:g}] (rescale the "
                                 "units; SI values are far inside)")
        try:
            nu = float(self.nu)
        except (TypeError, ValueError):
            raise ValueError(f"Poisson's ratio nu must be a number in (-1, 0.5), got {self.nu!r}") from None
        if isinstance(self.nu, bool) or not -1.0 < nu < 0.5:
            raise ValueError(f"Poisson's ratio nu must be in (-1, 0.5) (open interval), got {self.nu!r}")
        object.__setattr__(self, "nu", nu)

    @classmethod
    def preset(cls, name: str) -> Material:
        """A preset by name, case and punctuation ignored.

        Names: ``"Ti-6Al-4V"`` (also ``"titanium"``), ``"steel"``,
        ``"Inconel 718"`` (also ``"IN718"``, ``"inconel"``),
        ``"aluminium"`` (also ``"aluminum"``, ``"Al 6061-T6"``, ``"6061-T6"``).

        >>> m = Material.preset("ti 6al 4v")
        >>> m.name, m.E, m.nu, m.rho
        ('Ti-6Al-4V', 113800000000.0, 0.342, 4430.0)
        >>> Material.preset("IN718") is INCONEL718
        True
        """
        key = re.sub(r"[^a-z0-9]", "", str(name).lower())
        if key not in _PRESET_KEYS:
            raise ValueError(f"unknown material preset {name!r} (presets: {', '.join(PRESETS)})")
        return PRESETS[_PRESET_KEYS[key]]

    def lame(self, plane: str | None = None) -> tuple[float, float]:
        """Lamé constants ``(λ, μ)``; ``plane="stress"`` gives ``λ* = 2λμ/(λ + 2μ) = Eν/(1 - ν²)``.

        ``plane=None`` (3-D) and ``plane="strain"`` give the 3-D constants.
        """
        lam, mu = lame_parameters(self.E, self.nu)
        if plane == "stress":
            lam = 2.0 * lam * mu / (lam + 2.0 * mu)
        elif plane not in (None, "strain"):
            raise ValueError(f"plane must be one of {PLANE_KINDS} or None, got {plane!r}")
        return lam, mu


#: Ti-6Al-4V (Grade 5), annealed: ASM data sheet.
TI6AL4V = Material(113.8e9, 0.342, 4430.0, "Ti-6Al-4V")
#: Carbon/structural steel, typical handbook value.
STEEL = Material(200e9, 0.30, 7850.0, "steel")
#: Inconel 718 (ASM/MatWeb; Special Metals lists ≈ 204.9 GPa).
INCONEL718 = Material(200e9, 0.294, 8190.0, "Inconel 718")
#: Aluminium 6061-T6: ASM data sheet.
AL6061T6 = Material(68.9e9, 0.33, 2700.0, "Al 6061-T6")
#: Alias of :data:`AL6061T6`.
ALUMINIUM = AL6061T6

#: Presets by display name.
PRESETS = {m.name: m for m in (TI6AL4V, STEEL, INCONEL718, AL6061T6)}
_PRESET_KEYS = {
    "ti6al4v": "Ti-6Al-4V", "titanium": "Ti-6Al-4V", "tc4": "Ti-6Al-4V",
    "steel": "steel",
    "inconel718": "Inconel 718", "inconel": "Inconel 718", "in718": "Inconel 718",
    "al6061t6": "Al 6061-T6", "6061t6": "Al 6061-T6", "aluminium": "Al 6061-T6",
    "aluminum": "Al 6061-T6", "aluminium6061t6": "Al 6061-T6", "aluminum6061t6": "Al 6061-T6",
}

