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



# ----------------------------------------------------------------------------- the material of a mesh file

#: The preset of a model whose study names no material and whose mesh file carries none.
DEFAULT_PRESET = "Ti-6Al-4V"

_LBF = 0.45359237 * 9.80665  # N (exact: the pound-mass times standard gravity)

#: The consistent unit system a mesh file's length unit implies for its material: ``(words, Pa per unit of E,
#: kg/m³ per unit of rho)``. Millimetres: N, mm, t, s (E in MPa, rho in t/mm³, as CalculiX and Abaqus decks in mm
#: write them); inches: lbf, in, lbf·s²/in, s (E in psi, rho in lbf·s²/in⁴: ANSYS's BIN system); feet: lbf, ft,
#: slug, s (ANSYS's BFT). Centimetres imply none (g, cm, s with dyn/cm² — CGS — or kg, cm, s, or …): refused.
UNIT_SYSTEMS = {
    "m": ("SI (N, m, kg, s): E in Pa, rho in kg/m³", 1.0, 1.0),
    "mm": ("N, mm, t, s: E in MPa, rho in t/mm³", 1e6, 1e12),
    "in": ("lbf, in, lbf·s²/in, s: E in psi, rho in lbf·s²/in⁴", _LBF / 0.0254**2, _LBF / 0.0254**4),
    "ft": ("lbf, ft, slug, s: E in lbf/ft², rho in slug/ft³", _LBF / 0.3048**2, _LBF / 0.3048**4),
}

#: Ranges (SI) a mesh file's material must fall in once converted — a solid's, from foams and rubbers to tungsten
#: and diamond: beyond, the file's units are not the ones its length unit implies (a density in kg/mm³ in a deck in
#: millimetres, a deck in N-mm-t read in metres, lbm/in³ for lbf·s²/in⁴).
PLAUSIBLE = {"E": (1e5, 2e12, "Pa"), "rho": (50.0, 3e4, "kg/m³")}


def file_material(name: str, values: dict, used: dict, where: str, what: str = "material") -> dict:
    """The material record of a mesh file (:attr:`bladecase.fe.mesh.Mesh.material`), from what the reader found.

    ``values``: each material the file defines (its name as written → ``{"E", "nu", "rho"}`` in the file's units,
    or ``{"problem": why it cannot be used}``); ``used``: the materials the body's elements use → how many of them
    (empty when the file does not say: its one material is then the body's). ``name`` names the file for messages,
    ``where`` says how the body's material was found, ``what`` how the file calls a material (``*MATERIAL``,
    ``material number``).

    Returns ``{"name", "E", "nu", "rho", "source": "deck", "where"}`` in the file's units, or ``{"name", "problem",
    "source": "deck", "where"}`` when the body's material cannot be taken from the file (several materials for
    its elements, a missing density, an anisotropic or temperature-dependent table): the problem is raised by
    :func:`mesh_material` only, when a model needs the file's material.

    >>> file_material("a.inp", {"STEEL": {"E": 210000.0, "nu": 0.3, "rho": 9e-9}}, {"STEEL": 12}, "its sections")
    {'name': 'STEEL', 'E': 210000.0, 'nu': 0.3, 'rho': 9e-09, 'source': 'deck', 'where': 'its sections'}
    >>> file_material("a.inp", {"A": {}, "B": {}}, {"A": 3, "B": 1}, "its sections")["problem"]
    'the body elements of a.inp use 2 materials: A (3 elements), B (1 element); bladecase takes one material per body'
    """
    chosen = [k for k, n in used.items() if n > 0]
    if len(chosen) > 1:
        listed = ", ".join(f"{k} ({n} element{'s' if n != 1 else ''})" for k, n in used.items() if n > 0)
        return {"name": ", ".join(chosen), "problem": f"the body elements of {name} use {len(chosen)} materials: "
                f"{listed}; bladecase takes one material per body", "source": "deck", "where": where}
    if not chosen and len(values) != 1:
        return {"name": ", ".join(values), "problem": f"{name} defines {len(values)} materials ({', '.join(values)}) "
                "and does not say which one its body elements use", "source": "deck", "where": where}
    key = chosen[0] if chosen else next(iter(values))
    props = values.get(key)
    if props is None:
        return {"name": key, "problem": f"the body elements of {name} use {what} {key}, which the file does not "
                "define", "source": "deck", "where": where}
    if "problem" in props:
        return {"name": key, "problem": f"{what} {key} of {name}: {props['problem']}", "source": "deck",
                "where": where}
    missing = [k for k in ("E", "nu", "rho") if props.get(k) is None]
    if missing:
        words = {"E": "Young's modulus", "nu": "Poisson's ratio", "rho": "density"}
        return {"name": key, "problem": f"{what} {key} of {name} has no {', '.join(words[k] for k in missing)} "
                "(a modal analysis needs E, nu and rho)", "source": "deck", "where": where}
    return {"name": key, "E": float(props["E"]), "nu": float(props["nu"]), "rho": float(props["rho"]),
            "source": "deck", "where": where}


def mesh_material(mesh) -> Material | None:
    """The material a mesh file carries (:attr:`~bladecase.fe.mesh.Mesh.material`: a deck's ``*MATERIAL`` for its
    body's elements, an ANSYS archive's ``MP`` records) in SI units, converted with the consistent unit system the
    mesh's length unit implies (:data:`UNIT_SYSTEMS`); ``None`` when the file carries none.

    Raises
    ------
    ValueError
        The file's material cannot be used (the reason the reader recorded: several materials for the body's
        elements, a missing density, …), the mesh's unit implies no consistent system (centimetres), or the values
        converted are no solid's (:data:`PLAUSIBLE`: a density in the wrong unit); the message says what to give.

    Examples
    --------
    A deck in millimetres (N, mm, t, s): E in MPa, rho in t/mm³:

    >>> from types import SimpleNamespace
    >>> deck = {"name": "STEEL", "E": 210000.0, "nu": 0.3, "rho": 9e-9, "source": "deck", "where": "b.inp"}
    >>> m = mesh_material(SimpleNamespace(material=deck, unit="mm", source="b.inp"))
    >>> m.name, m.E, m.nu, round(m.rho, 9)
    ('STEEL', 210000000000.0, 0.3, 9000.0)
    >>> mesh_material(SimpleNamespace(material=deck, unit="m", source="b.inp"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: the material STEEL of b.inp: rho = 9e-09 in SI (N, m, kg, s) ... looks like t/mm³: ...
    """
    record = getattr(mesh, "material", None)
    if record is None:
        return None
    source = getattr(mesh, "source", "") or "the mesh file"
    name = record.get("name") or "?"
    if record.get("problem"):
        raise ValueError(f"{record['problem']}: give [material] E, nu and rho (SI) or a preset")
    unit = getattr(mesh, "unit", "m")
    if unit not in UNIT_SYSTEMS:
        raise ValueError(f"the material {name} of {source} is in the units of a mesh in {unit}, which imply no one "
                         "consistent unit system (g, cm, s with E in dyn/cm² — CGS —, or kg, cm, s, or …): bladecase "
                         "does not guess it; give [material] E, nu and rho in SI (Pa, kg/m³)")
    words, e_factor, rho_factor = UNIT_SYSTEMS[unit]
    # 15 digits: 7.85e-9 t/mm³ is 7850 kg/m³, not the product's 7850.000000000001
    E, rho = (float(f"{v:.15g}") for v in (record["E"] * e_factor, record["rho"] * rho_factor))
    for key, value, raw in (("rho", rho, record["rho"]), ("E", E, record["E"])):
        lo, hi, si = PLAUSIBLE[key]
        if not lo <= value <= hi:
            hint = ""
            if unit == "m" and key == "rho" and 1e-10 <= raw <= 1e-7:
                hint = ' looks like t/mm³: a deck in millimetres? set [mesh] unit = "mm";'
            elif unit == "m" and key == "E" and 1e2 <= raw <= 1e6:
                hint = ' looks like MPa: a deck in millimetres? set [mesh] unit = "mm";'
            raise ValueError(f"the material {name} of {source}: {key} = {raw:g} in {words.split(':')[0]} is {value:g} "
                             f"{si}, outside [{lo:g}, {hi:g}] {si} (a solid's);{hint} give [material] E, nu and rho "
                             "in SI (Pa, kg/m³), or the mesh's right [mesh] unit")
    return Material(E, record["nu"], rho, name)


def material_words(mesh) -> str:
    """Where :func:`mesh_material` takes the material from and how it converts it, for the log, e.g.
    ``*MATERIAL STEEL of beam.inp (its *SOLID SECTION), in N, mm, t, s: E in MPa, rho in t/mm³``."""
    record = getattr(mesh, "material", None) or {}
    system = UNIT_SYSTEMS.get(getattr(mesh, "unit", "m"), ("?",))[0]
    return f"{record.get('where') or getattr(mesh, 'source', '')}, in {system}"
