"""Study files: a TOML description of a whole analysis, validated before any work starts.

A study names the blade (a parametric geometry meshed by gmsh, or a mesh file),
the material and the finite elements, the contact (node, casing normal,
clearance), the reduced model(s), the nonsmooth-mode search and the outputs.
:func:`load_study` reads and validates it into a :class:`Study` (plain nested
dicts with every default filled in); :mod:`bladecase.pipeline` runs it.

Every key, its type, default and meaning is in :data:`SCHEMA` (and
``docs/study.md``, which a test keeps in step with it).  Unknown keys, wrong
types and out-of-range values raise :class:`StudyError` naming the key, e.g.
``[contact] clearance: must be > 0 (metres), got -0.0001``.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .. import log
from ..fe import BladeGeometry, PlateGeometry
from ..fe.mesh_checks import LENGTH_UNITS
from ..post.outputs import FORMATS as OUTPUT_FORMATS
from ..reduction import METHODS
from .cross_checks import (  # noqa: F401 (MASSLESS_METHODS lived here)
    MASSLESS_METHODS,
    campbell_only,
    cross_checks,
    modes_only_checks,
)
from .disk.cyclic_keys import CYCLIC_KEYS
from .disk.mistuning_keys import MISTUNING_KEYS
from .geometry_section import GEOMETRY_FIELDS, GEOMETRY_KEYS, geometry_of, geometry_section  # noqa: F401
from .keys import _BOOL, _INT, _LIST, _NUM, _STR, REQUIRED, Key, StudyError, _check_field, _check_value, one_line  # noqa: F401
from .sections import (
    CASING_KEYS,
    CONVERGENCE_KEYS,
    EXECUTION_KEYS,
    FORCING_KEYS,
    FRICTION_KEY,
    LIMIT_KEYS,
    ROTATION_KEYS,
    RUB_KEYS,
)
from .study_file import MAX_STUDY_BYTES, MAX_STUDY_FILE_BYTES, content_size, read_study_text  # noqa: F401
from .values import (  # noqa: F401  (RANGES, LIMITS: part of the schema's documented surface)
    LIMITS,
    MIN_FPS,
    RANGES,
    _clamp_spec,
    _compare_periods,
    _count_capped,
    _density,
    _direction,
    _file,
    _folder,
    _formats,
    _in_range,
    _int_at_least,
    _int_between,
    _ipp,
    _manifold_size,
    _mesh_format,
    _method_names,
    _name,
    _node_list,
    _nonzero,
    _num,
    _one_of,
    _orbit_list,
    _period_unit,
    _period_unit_index,
    _periods,
    _point,
    _positive,
    _rayleigh,
    _reduction_list,
    _scale,
    _size_list,
    _study_name,
    _vector,
    _window,
    _yield_strength,
    show,
)

#: The registry of output formats (:mod:`bladecase.post.outputs`): GIF/MP4 animations, VTK time series
#: (+ manifold samples), PNG plots, and any format registered there.
FORMATS = OUTPUT_FORMATS


def _casing_stiffness(v) -> str | None:
    """One casing stiffness (N/m), or a list of 2 to 12 of them (a sensitivity sweep)."""
    values = v if isinstance(v, list) else [v]
    if isinstance(v, list) and not 2 <= len(v) <= 12:
        return f"must be a number (N/m) or a list of 2 to 12 numbers, got a list of {len(v)}"
    for x in values:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not x > 0:
            return f"must be > 0 (N/m), got {x!r}" if isinstance(v, list) else "must be > 0 (N/m)"
        err = _in_range("casing_stiffness")(x)
        if err:
            return err
    return None


#: The study-file schema: section → key → :class:`Key`.  ``[geometry]`` also
#: takes the fields of :class:`~bladecase.BladeGeometry` (``kind = "blade"``)
#: or :class:`~bladecase.PlateGeometry` (``kind = "plate"``), see :data:`GEOMETRY_FIELDS`.
SCHEMA: dict[str, dict[str, Key]] = {
    "study": {
        "name": Key(_STR, "study", "Name used in titles and file names (a plain folder name).", _study_name),
    },
    "geometry": GEOMETRY_KEYS,
    "mesh": {
        "path": Key(_STR, REQUIRED, "Mesh file (any meshio format with named groups), relative to the study file.",
                    _file),
        "unit": Key(_STR, "m", "Length unit of the mesh file's coordinates ('m', 'mm', 'cm', 'in', 'ft'): scaled to "
                    "metres when read; every result stays SI.", _one_of(*LENGTH_UNITS)),
        "format": Key(_STR, None, "Format of the mesh file ('abaqus' for Abaqus/CalculiX syntax, 'gmsh', 'ansys', or "
                      "any meshio format name); default: from the suffix and the content.", _mesh_format),
    },
    "material": {
        "preset": Key(_STR, None, "Material preset (Ti-6Al-4V, steel, Inconel 718, Al 6061-T6); ignored when E, "
                      "nu and rho are given; not set: the mesh file's own material (a deck's *MATERIAL, an ANSYS "
                      "archive's MP records, converted to SI with [mesh] unit) when it has one, else Ti-6Al-4V."),
        "E": Key(_NUM, None, "Young's modulus (Pa).", _in_range("E")),
        "nu": Key(_NUM, None, "Poisson's ratio.", lambda v: None if -1 < v < 0.5 else "must be in (-1, 0.5)"),
        "rho": Key(_NUM, None, "Density (kg/m³).", _density),
        "yield_strength": Key(_NUM, None, "Yield strength (Pa, SI as E): when given, admissible arcs are cut where an "
                              "orbit's peak von Mises stress exceeds it (the linear-elastic model's limit); not set: "
                              "no stress limit.", _yield_strength),
    },
    "fem": {
        "order": Key(_INT, 2, "Polynomial order of the elements (1 or 2).", _one_of(1, 2)),
        "mass": Key(_STR, "consistent", "'consistent' or 'lumped' mass matrix.", _one_of("consistent", "lumped")),
        "clamp": Key((str, dict), "root", "Clamped nodes: a mesh group, or by coordinates (meshes without groups): "
                     "{plane = [x0, y0, z0, nx, ny, nz]}, {box = [[xmin, ymin, zmin], [xmax, ymax, zmax]]} or "
                     "{sphere = [x, y, z, r]}, with an optional tol (m); or node numbers as in the mesh file: "
                     "{nodes = [...]} or {nodes_file = 'root.txt'}.", _clamp_spec),
        "thickness": Key(_NUM, None, "Out-of-plane thickness of a 2-D model (m); required in 2-D.",
                         lambda v: "must be > 0 (metres)" if not v > 0 else _in_range("thickness")(v)),
        "plane": Key(_STR, "stress", "'stress' or 'strain' (2-D models).", _one_of("stress", "strain")),
        "frequencies": Key(_INT, 6, "Linear frequencies of the full FE model to compute and report.",
                           _int_between(1, LIMITS["frequencies"])),
    },
    "contact": {
        "clearance": Key(_NUM, None, "Clearance d between the contact node at rest and the casing (m); required "
                         "unless a [casing] gives each node's.",
                         lambda v: "must be > 0 (metres)" if not v > 0 else _in_range("clearance")(v)),
        "group": Key(_STR, None, "Mesh group of the contact node: alone, a one-node group (default "
                     "'contact'); with 'farthest', the group searched (default 'tip'); with 'nearest', the group "
                     "searched (default: every free node).", _name),
        "node": Key(_INT, None, "Node number of the contact as in the mesh file (the 0-based index for files without "
                    "node numbers); overrides group.", _int_between(0, LIMITS["node"])),
        "nodes": Key(_LIST, None, "A contact face given as node numbers of the mesh file: the mean normal "
                     "displacement of its free nodes, as 'face' does for a group.", _node_list),
        "farthest": Key(_LIST, None, "Pick the free node of 'group' (default 'tip') farthest along this "
                        "direction, e.g. [-1, 0, 0].", _direction),
        "nearest": Key(_LIST, None, "Pick the free node nearest this point (within 'group' if given).", _point),
        "face": Key((str, dict), None, "Contact on a whole face instead of one node: the mean normal displacement "
                    "of the free nodes of this mesh group (e.g. 'tip'), one constraint all the same; or the face's "
                    "nodes by coordinates: {plane = [x0, y0, z0, nx, ny, nz]}, {box = [[..], [..]]} or "
                    "{sphere = [x, y, z, r]}, with an optional tol (m); or node numbers: {nodes = [...]} or "
                    "{nodes_file = 'tip.txt'}.", _clamp_spec),
        "normal": Key(_LIST, None, "Casing normal, from the blade towards the casing; default: radial "
                      "(+z in 3-D, +y in 2-D).", _direction),
        "weights": Key(_STR, None, "With 'face': how the face's nodes are weighted in the mean normal "
                       "displacement: 'equal' (default) or 'area' (each node's share of the face area, which "
                       "converges under mesh refinement).", _one_of("equal", "area")),
        "model": Key(_STR, "newton", "Contact model: 'newton' (the node keeps its mass; Newton's impact law, "
                     "the seed paper's formulation) or 'massless' (the contact dofs carry no inertia, their lumped "
                     "mass is moved to the neighbours; Signorini without an impact law; needs [fem] mass = "
                     "'lumped', [reduction] method = 'massless', [search] ipp = [1]).",
                     _one_of("newton", "massless")),
        "casing_stiffness": Key((int, float, list), None, "Stiffness of a compliant casing (N/m) in series with the "
                                "contact (its local flexibility and coating); default: a rigid casing. Massless model "
                                "only; well below the contact's own stiffness, the modes converge (docs/massless.md). "
                                "With one contact per node ([rub]), shared by the nodes' tributary areas. A list "
                                "[k1, k2, …]: the results use k1, and the nonsmooth modes are also searched with each "
                                "of the others (casing.png, the report: how much the answer moves).",
                                _casing_stiffness),
        "casing_stiffness_per_area": Key(_NUM, None, "A compliant casing's stiffness per unit area (N/m³, e.g. an "
                                         "abradable layer's modulus / thickness): each node gets it times its "
                                         "tributary area, the face mean its total; instead of casing_stiffness.",
                                         lambda v: None if math.isfinite(v) and 1 <= v <= 1e18
                                         else "must be a finite number in [1, 1e18] (N/m³)"),
        "points": Key(_STR, "face", "'face': the face's nodes meet the casing through their (weighted) mean, one "
                      "constraint; 'nodes': also the nonsmooth mode with every node of the face a contact of its own "
                      "(massless model; nodal_modes.csv, nodal_modes.png).", _one_of("face", "nodes")),
        "clearance_at": Key(_STR, "cold", "A rotating blade's 'clearance' is the cold one ('cold': the "
                            "centrifugal growth of the blade along the normal closes it at speed) or the running "
                            "one at [rotation] speed ('speed').", _one_of("cold", "speed")),
        "friction": FRICTION_KEY,
    },
    "reduction": {
        "method": Key(_STR, "lanczos-si", f"Reduced model: {', '.join(METHODS)}; not set with 'methods': the first "
                      "of them.", _one_of(*METHODS)),
        "size": Key(_INT, 20, "Modes / Lanczos steps / fixed-interface modes kept (ignored by 'full'); not set with "
                    "'sizes': the largest of them.", _int_between(1, LIMITS["size"])),
        "compare": Key(_LIST, [], "Other reduced models run through the same search for comparison: "
                       "[{method = 'modal', size = 20}, …].", _reduction_list),
        "methods": Key(_LIST, [], "A comparison grid: these methods × 'sizes' (default: [method]), each run "
                       "through the same search, compared in comparison.csv and the report; without 'method', the "
                       "main model's method is the first of them.", _method_names),
        "sizes": Key(_LIST, [], "Sizes of the comparison grid (default: [size]), e.g. [8, 16, 32, 64]; without "
                     "'size', the main model's size is the largest of them (no model outside the grid is built).",
                     _size_list),
        "compare_periods": Key(_LIST, [0.9, 0.95, 0.99], "Periods (× the FE model's first period) at which the "
                               "comparison reads each model's energy, e.g. [0.99999, 0.999999] for arcs next to "
                               "grazing.", _compare_periods),
    },
    "search": {
        "ipp": Key(_LIST, [1, 2], "Impacts per period of the families to look for.", _ipp),
        "periods": Key(_LIST, [0.9, 0.9999], "Period range [lower, upper] in 'period_unit'.", _periods),
        "period_unit": Key(_STR, "T1", "'s', or 'T<j>': the period 2π/ω_j of the j-th linear mode of the "
                           "reduced model that sees the contact.", _period_unit_index),
        "scan": Key(_INT, 24, "Starting periods scanned for k >= 2 (1 ipp scans max(scan, 200)).",
                    _int_between(2, LIMITS["scan"])),
        "resolution": Key(_INT, None, "Grid points per impact time of the k >= 3 start search at each scanned "
                          "period; default: 4 per period of the highest mode, clipped to [16, 48].",
                          _int_between(4, LIMITS["resolution"])),
        "step": Key(_NUM, 0.01, "Initial continuation step (scaled arclength).",
                    lambda v: None if 1e-6 <= v <= 1 else "must be in [1e-06, 1] (scaled arclength: impact times / T)"),
        "max_points": Key(_INT, 400, "Cap on continuation points per direction of each family.",
                          _int_between(2, LIMITS["max_points"])),
        "amplitude_limit": Key(_NUM, 0.05, "Tip amplitude, as a fraction of the blade's span, beyond which a "
                               "linear-elastic, small-displacement model no longer holds: admissible arcs are cut "
                               "there (the report says where).",
                               lambda v: None if 0 < v <= 1 else "must be in (0, 1] (a fraction of the span)"),
    },
    "forcing": FORCING_KEYS,
    "output": {
        "directory": Key(_STR, None, "Output directory, relative to the current directory; default "
                         "'results/<name>'; the command line's --out overrides it.", _folder),
        "animate": Key(_INT, 2, "How many orbits to animate when 'orbits' is empty: the middles of the "
                       f"widest admissible arcs, one per family; above {LIMITS['animate']}: every admissible arc's "
                       f"middle, at most {LIMITS['animate']} (logged).", _count_capped(LIMITS["animate"])),
        "orbits": Key(_LIST, [], "Orbits to animate: [{ipp = 1, T = 0.95}, …], T in search.period_unit "
                      "(the nearest admissible orbit of a family of that ipp).", _orbit_list),
        "reference": Key(_BOOL, True, "Check each chosen orbit in a reference model (4 times the reduced model's "
                         "dofs, see 'reference_basis'): an orbit that does not survive there is not animated (unless "
                         "named in 'orbits', then it is flagged), and the report says so."),
        "reference_basis": Key(_STR, "auto", "How the reference model is built: 'krylov' (the reduced model's "
                               "basis extended by the Krylov sequence of its own factorisation: no second "
                               "eigen-solve), 'independent' (a reduced model of another method from its own "
                               "eigen-solve, several times the cost) or 'auto' ('independent' in a study that "
                               "compares reduced models — the yardstick is built from none of them —, 'krylov' "
                               "otherwise).", _one_of("auto", "krylov", "independent")),
        "frames": Key(_INT, 40, "Frames per period of the animations and VTK time series.",
                      _int_between(2, LIMITS["frames"])),
        "scale": Key((str, int, float), "auto", "Amplitude scale of the animations, or 'auto' (largest "
                     "displacement drawn at 'auto_fraction' of the blade's bounding-box diagonal).", _scale),
        "auto_fraction": Key(_NUM, 0.1, "Drawn size of the largest displacement with scale = 'auto'.",
                             lambda v: None if 0 < v <= 1 else "must be in (0, 1]"),
        "formats": Key(_LIST, ["gif", "mp4", "vtu", "png"], f"Outputs among {', '.join(FORMATS)} (mp4 needs "
                       "imageio-ffmpeg: skipped with a note without it).", _formats),
        "manifold": Key(_BOOL, True, "Export the invariant-manifold samples of each animated family (VTK)."),
        "manifold_size": Key(_LIST, [40, 100], "[orbits, phases] sampled on the manifold.", _manifold_size),
        "window": Key(_LIST, [800, 600], "Animation size [width, height] in pixels.", _window),
        "fps": Key(_NUM, 20, "Frames per second of the animations.",
                   lambda v: f"must be a number in (0, {LIMITS['fps']}]" if not 0 < v <= LIMITS["fps"] else
                   None if v >= MIN_FPS else f"must be at least {MIN_FPS:g} frames per second"),
    },
    "rotation": ROTATION_KEYS,
    "casing": CASING_KEYS,
    "rub": RUB_KEYS,
    "convergence": CONVERGENCE_KEYS,
    "cyclic": CYCLIC_KEYS,
    "mistuning": MISTUNING_KEYS,
    "execution": EXECUTION_KEYS,
    "limits": LIMIT_KEYS,
}

@dataclass(frozen=True)
class Study:
    """A validated study: every section with its defaults filled in.

    Attributes
    ----------
    config : dict
        ``section → key → value`` (``[geometry]`` or ``[mesh]``, never both).
    source : str
        The study file (or ``"<demo>"``) for messages.
    base : Path
        Folder that relative paths in the study (the mesh file) are relative to.

    Examples
    --------
    Sections read as dicts, with every default filled in:

    >>> from bladecase.study.demo import demo_study
    >>> study = demo_study()
    >>> study.name, study.source, study.parametric
    ('demo', '<demo>', True)
    >>> study["contact"]["clearance"], study["reduction"]["method"], study["reduction"]["size"]
    (0.0001, 'massless', 8)
    >>> study["search"]["max_points"], study["fem"]["frequencies"]        # defaults: not in the file
    (400, 6)
    >>> study.output_dir().as_posix(), study.output_dir("elsewhere").as_posix()
    ('results/demo', 'elsewhere')
    """

    config: dict
    source: str = "<string>"
    base: Path = field(default_factory=Path.cwd)

    def __getitem__(self, section: str) -> dict:
        return self.config[section]

    @property
    def name(self) -> str:
        return self.config["study"]["name"]

    @property
    def has_contact(self) -> bool:
        """False for a study without a contact (no ``[contact] clearance`` and no ``[casing]``): a study of the
        linear modes and the Campbell diagram alone (``[rotation] speeds`` without ``[contact]``)."""
        k = self.config.get("casing") or {}
        return (self.config["contact"].get("clearance") is not None or k.get("radius") is not None
                or k.get("radii") is not None)

    @property
    def parametric(self) -> bool:
        """True when the blade is generated from ``[geometry]`` (else read from ``[mesh]``)."""
        return "geometry" in self.config

    def geometry(self) -> BladeGeometry | PlateGeometry:
        """The parametric geometry of ``[geometry]``."""
        return geometry_of(self.config["geometry"])

    def mesh_path(self) -> Path:
        """The mesh file of ``[mesh]``, resolved against :attr:`base` (``ValueError`` for a parametric study, whose
        mesh gmsh makes from ``[geometry]``)."""
        if "mesh" not in self.config:
            raise ValueError(f"study {self.name!r} has no mesh file: its mesh is made by gmsh from [geometry]")
        return (self.base / self.config["mesh"]["path"]).resolve()

    def output_dir(self, override: str | os.PathLike | None = None) -> Path:
        """The output directory: ``override`` (command line), else ``[output] directory``, else ``results/<name>``."""
        if override is not None:
            return Path(override)
        d = self.config["output"]["directory"]
        if d is not None:
            return Path(d)
        if not isinstance(self.name, str) or _study_name(self.name):  # a Study made without validate()
            raise StudyError(f"[study] name: {_study_name('')}, got {show(self.name)}")
        return Path("results") / self.name


def validate(raw: dict, source: str = "<string>", base: str | os.PathLike | None = None,
             model: bool = True, contact: bool = True) -> Study:
    """Check a parsed study (a dict as from ``tomllib``) and fill in the defaults.

    ``model=False`` is for studies that only drive the search on a given
    system (``bladecase modes --matrices``): the blade (``[geometry]`` /
    ``[mesh]``) and the contact clearance may then be left out.
    ``contact=False`` is for the stages before the contact (``bladecase mesh``,
    ``bladecase assemble``): the contact clearance may be left out.
    A study with ``[rotation] speeds`` and no ``[contact]`` section (nor ``[casing]``) is a study of the linear
    modes and the Campbell diagram alone (:attr:`Study.has_contact` is False; :func:`modes_only_checks`).

    Raises
    ------
    StudyError
        An unknown section or key, a wrong type or value, a missing required
        key, both or neither of ``[geometry]`` and ``[mesh]``, or an
        inconsistent combination (the message names the key).
    """
    if not isinstance(raw, dict):
        raise StudyError(f"{source}: a study is a TOML table, got {type(raw).__name__}")
    unknown = set(raw) - set(SCHEMA)
    if unknown:
        key = sorted(unknown)[0]
        raise StudyError(f"[{key}]: unknown section (valid: {', '.join(SCHEMA)})")
    if ("geometry" in raw) == ("mesh" in raw) and (model or "geometry" in raw):
        raise StudyError("[geometry] / [mesh]: give exactly one: a parametric blade ([geometry]) or a mesh "
                         "file ([mesh] path = ...)")
    config: dict[str, dict] = {}
    for section, keys in SCHEMA.items():
        if section in ("geometry", "mesh") and section not in raw:
            continue
        given = raw.get(section, {})
        if not isinstance(given, dict):
            raise StudyError(f"[{section}]: must be a table ([{section}] with keys), got {type(given).__name__}")
        if section == "geometry":
            config[section] = geometry_section(given)
            continue
        out = {}
        for key, value in given.items():
            if key not in keys:
                raise StudyError(f"[{section}] {key}: unknown key (valid: {', '.join(keys)})")
            out[key] = _check_value(section, key, keys[key], value)
        for key, spec in keys.items():
            if key not in out:
                if spec.default is REQUIRED and not model:
                    out[key] = None  # not needed without a model
                    continue
                if spec.default is REQUIRED:
                    raise StudyError(f"[{section}] {key}: required ({spec.doc})")
                out[key] = list(spec.default) if isinstance(spec.default, list) else spec.default
        if section == "reduction":
            _grid_main_model(out, given)
        if section in ("output", "forcing"):
            _cap_animate(out, section)
        config[section] = out
    _follow_contact_model(config, raw)
    modes_only = model and contact and campbell_only(raw)
    if modes_only:
        modes_only_checks(config)
    cross_checks(config, model=model, contact=contact and not modes_only)
    return Study(config=config, source=source, base=Path(base) if base is not None else Path.cwd())


def _follow_contact_model(config: dict, raw: dict) -> None:
    """Defaults that follow ``[contact] model = "massless"``: the massless reduction and the lumped mass it moves,
    where the study does not set them (logged); a value the study sets is kept (and checked)."""
    if config["contact"]["model"] != "massless":
        return
    r, f = raw.get("reduction") or {}, raw.get("fem") or {}
    if "method" not in r and "methods" not in r:
        config["reduction"]["method"] = "massless"
        log.info("[reduction] method: 'massless' (the default with [contact] model = 'massless')")
    if "mass" not in f:
        config["fem"]["mass"] = "lumped"
        log.info("[fem] mass: 'lumped' (the default with [contact] model = 'massless': its contact dofs' mass is "
                 "moved to their neighbours, which needs a diagonal mass)")


def _cap_animate(o: dict, section: str = "output") -> None:
    """``[output] animate`` (``[forcing] animate``) above :data:`LIMITS` ``["animate"]`` means every orbit (steady
    state) the study can animate: capped there, and logged."""
    cap = LIMITS["animate"]
    if o.get("animate") is not None and o["animate"] > cap:
        what = ("the middle orbit of every admissible arc" if section == "output"
                else "every periodic steady state with impacts")
        log.info("[%s] animate = %d: more than any study can animate; %s is animated (at most %d)", section,
                 o["animate"], what, cap)
        o["animate"] = cap


def _grid_main_model(r: dict, given: dict) -> None:
    """The main model of a comparison grid whose study does not name it: ``method`` not set → the first of
    ``methods``, ``size`` not set → the largest of ``sizes`` (the grid's most converged model, the one every
    later stage then uses), so that the grid builds no model the study did not ask for (the schema's defaults,
    lanczos-si and 20, would add one).

    >>> r = {"method": "lanczos-si", "size": 20, "methods": ["modal"], "sizes": [8, 32, 16]}
    >>> _grid_main_model(r, {"methods": ["modal"], "sizes": [8, 32, 16]}); (r["method"], r["size"])
    ('modal', 32)
    >>> r = {"method": "lanczos-si", "size": 10, "methods": [], "sizes": [8, 16]}
    >>> _grid_main_model(r, {"size": 10, "sizes": [8, 16]}); (r["method"], r["size"])   # given: kept
    ('lanczos-si', 10)
    """
    if "method" not in given and r["methods"]:
        r["method"] = r["methods"][0]
    if "size" not in given and r["sizes"]:
        r["size"] = max(r["sizes"])


def loads(text: str, source: str = "<string>", base: str | os.PathLike | None = None, model: bool = True,
          contact: bool = True) -> Study:
    """Parse and validate a study from TOML text (``model``: see :func:`validate`).

    >>> loads("x = " + "[" * 10000 + "]" * 10000)
    Traceback (most recent call last):
        ...
    bladecase.study.schema.StudyError: <string>: not valid TOML: nested too deeply (arrays or tables inside each other)
    """
    if not isinstance(text, str):
        raise StudyError(f"{source}: a study is TOML text, got {type(text).__name__}")
    if len(text) > MAX_STUDY_FILE_BYTES:
        raise StudyError(f"{source}: {len(text)} characters, more than a study file's {MAX_STUDY_FILE_BYTES} (is it a "
                         "study file?)")
    if len(text) > MAX_STUDY_BYTES and content_size(text, stop=MAX_STUDY_BYTES) > MAX_STUDY_BYTES:
        raise StudyError(f"{source}: more than a study's {MAX_STUDY_BYTES} characters besides comments (is it a study "
                         "file?)")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"{source}: not valid TOML: {one_line(exc)}") from None
    except RecursionError:
        raise StudyError(f"{source}: not valid TOML: nested too deeply (arrays or tables inside each other)") from None
    try:
        return validate(raw, source=source, base=base, model=model, contact=contact)
    except RecursionError:
        raise StudyError(f"{source}: nested too deeply (arrays or tables inside each other)") from None


def load_study(path: str | os.PathLike, model: bool = True, contact: bool = True) -> Study:
    """Read and validate a study file; relative paths in it are relative to its folder.

    ``model=False``: a search-only study; ``contact=False``: a study for the stages before the contact (see
    :func:`validate`).

    Examples
    --------
    A study on a mesh file next to it (TOML inline tables are sections too):

    >>> import tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = Path(folder.name, "plate.toml")
    >>> _ = path.write_text('''
    ... mesh = {path = "meshes/plate.vtu"}
    ... fem = {order = 1, thickness = 0.002}
    ... contact = {clearance = 1e-4}
    ... ''')
    >>> study = load_study(path)
    >>> study.name, study.parametric, study.mesh_path() == Path(folder.name, "meshes", "plate.vtu").resolve()
    ('study', False, True)
    >>> study["fem"]["order"], study["reduction"]["method"], study["reduction"]["size"]   # defaults filled in
    (1, 'lanczos-si', 20)
    >>> _ = path.write_text('''
    ... mesh = {path = "meshes/plate.vtu"}
    ... contact = {clearance = -1e-4}
    ... ''')
    >>> load_study(path)
    Traceback (most recent call last):
        ...
    bladecase.study.schema.StudyError: [contact] clearance: must be > 0 (metres), got -0.0001
    >>> folder.cleanup()
    """
    path = Path(path)
    return loads(read_study_text(path), source=str(path), base=path.resolve().parent, model=model, contact=contact)
