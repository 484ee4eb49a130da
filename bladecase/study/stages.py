"""The stages of a study, each a plain function of the validated :class:`~bladecase.study.schema.Study`
and the previous stage's data: mesh → FE model → contact → reduced model → nonsmooth modes.

The command line runs one stage from files (``bladecase mesh / assemble / reduce / modes``) or all of
them (:func:`bladecase.study.run`).  Bad study values raise :class:`~bladecase.study.schema.StudyError`
naming the key.
"""

from __future__ import annotations

import os
import time

import numpy as np

from .. import log
from ..fe import FEModel, Material, Mesh, assemble, blade_mesh, load_mesh
from ..linalg import DENSE_LIMIT, SPDFactor
from ..nsm import Branch, LinearSystem, nonsmooth_mode
from ..nsm.system import DENSE_LIMIT as NSM_DENSE_LIMIT
from ..reduction import Contact, ReducedModel, reduce
from .schema import Study, StudyError


def build_mesh(study: Study, path: str | os.PathLike | None = None) -> Mesh:
    """The study's mesh: gmsh on ``[geometry]`` (written to ``path`` if given) or the ``[mesh]`` file.

    The clamp group and, when the contact is picked by group, the contact group must exist.
    """
    clamp = study["fem"]["clamp"]
    need = [("[fem] clamp", clamp)] if isinstance(clamp, str) else []  # a table selects by coordinates
    group = contact_group(study)
    if group is not None:
        need.append(("[contact] group", group))
    if study.parametric and study["geometry"]["kind"] == "sector":  # a bladed disk's sector (study/disk/cyclic.py)
        from ..fe import save_mesh, sector_mesh

        g = study["geometry"]
        try:
            mesh = sector_mesh(study.geometry(), size=g["size"], order=g["mesh_order"])
        except (ValueError, RuntimeError) as exc:
            raise StudyError(f"[geometry] {exc}") from None
        if path is not None:
            save_mesh(mesh, path)
        need = [(key, name) for key, name in need if (key, name) != ("[fem] clamp", "root")]  # clamped at its hub
    elif study.parametric:
        g = study["geometry"]
        try:
            mesh = blade_mesh(study.geometry(), size=g["size"], tip_size=g["tip_size"], order=g["mesh_order"],
                              path=path, cells=g["cells"], max_cells=_limits(study)["cells"])
        except ValueError as exc:
            raise StudyError(f"[geometry] {exc}") from None
    else:
        source = study.mesh_path()
        if not source.exists():
            raise StudyError(f"[mesh] path: no such file {str(source)!r}")
        m = study["mesh"]
        mesh = load_mesh(source, unit=m.get("unit") or "m", file_format=m.get("format"))
        if mesh.unit != "m":
            log.info("mesh %s: coordinates in %s, scaled to metres (every result is SI)", mesh.source, mesh.unit)
        if mesh.numbering == "file":
            log.info("mesh %s: nodes numbered as in the file (%d to %d): messages and summary.json name them so",
                     mesh.source, mesh.node_ids.min(), mesh.node_ids.max())
        if path is not None:
            from ..fe import save_mesh

            save_mesh(mesh, path)
    mesh = _with_selections(study, mesh)
    for key, name in need:
        if name not in mesh.groups:
            have = ", ".join(sorted(mesh.groups)) or "none"
            raise StudyError(f"{key}: the mesh {mesh.source} has no group {name!r} (groups: {have})")
    return mesh


def material(study: Study, mesh: Mesh | None = None) -> Material:
    """The model's material (SI): ``[material] E, nu, rho``, else its ``preset``, else the material the mesh file
    gives its body (a deck's ``*MATERIAL``, an ANSYS archive's ``MP`` records: converted from the file's units with
    ``[mesh] unit``, :func:`bladecase.fe.material.mesh_material`), else the Ti-6Al-4V preset. Logged: the SI values
    and where they came from (and that ``[material]`` overrides the file's)."""
    from ..fe.material import DEFAULT_PRESET, material_words, mesh_material

    m = study["material"]
    in_file = getattr(mesh, "material", None)
    if m["E"] is not None:
        chosen, where = Material(float(m["E"]), float(m["nu"]), float(m["rho"]), "custom"), "[material] E, nu, rho"
    elif m["preset"] is not None:
        try:
            chosen, where = Material.preset(m["preset"]), f"[material] preset = {m['preset']!r}"
        except ValueError as exc:
            raise StudyError(f"[material] preset: {exc}") from None
    elif in_file is not None:
        try:
            chosen = mesh_material(mesh)
        except ValueError as exc:
            raise StudyError(f"[material]: not given, and the mesh file's material cannot be used: {exc}") from None
        where = f"the mesh file: {material_words(mesh)}"
    else:
        chosen, where = Material.preset(DEFAULT_PRESET), "the default preset: no [material], none in the mesh file"
    if in_file is not None and where.startswith("[material]"):
        log.info("material: %s overrides the mesh file's material %s", where, in_file.get("name"))
    log.info("material %s: E = %.6g Pa, nu = %.6g, rho = %.6g kg/m³ (%s)", chosen.name, chosen.E, chosen.nu,
             chosen.rho, where)
    return chosen


def build_model(study: Study, mesh: Mesh) -> FEModel:
    """Assemble the FE model of ``[material]`` (else the mesh file's material: :func:`material`) and ``[fem]`` on
    ``mesh``; log the nodes the clamp holds (midside nodes included) and warn when the model's mass is not a
    blade's (:func:`check_plausibility`)."""
    f = study["fem"]
    if mesh.dim == 2 and f["thickness"] is None:
        raise StudyError("[fem] thickness: required for a 2-D (plane) mesh, e.g. thickness = 0.002 (metres)")
    if mesh.dim == 3 and f["thickness"] is not None:
        raise StudyError(f"[fem] thickness: only for 2-D meshes; this mesh is 3-D (got {f['thickness']!r})")
    clamp = f["clamp"]
    if isinstance(clamp, dict):  # by coordinates or node numbers: the nodes, named in the messages
        clamp = selected_nodes(study, mesh, clamp, "[fem] clamp", allow_all=False)
    try:
        model = assemble(mesh, material(study, mesh), order=f["order"], mass=f["mass"], clamp=clamp,
                         thickness=f["thickness"], plane=f["plane"])
    except ValueError as exc:
        if isinstance(f["clamp"], dict) and str(exc).startswith("clamp"):
            raise StudyError(f"[fem] {exc}") from None
        raise
    _log_clamp(f["clamp"], mesh, model, mesh.group(clamp) if isinstance(clamp, str) else clamp)
    check_plausibility(study, model)
    return model


def _log_clamp(spec, mesh: Mesh, model: FEModel, chosen: np.ndarray) -> None:
    """The nodes the clamp holds — corners and midside nodes, as a deck counts them — and a warning for the nodes of
    the selection it cannot hold (a midside node whose edge has a free end)."""
    from ..fe.select import describe, held_nodes

    held = held_nodes(mesh, model.clamped)
    name = repr(spec) if isinstance(spec, str) else describe(spec)
    log.info("clamp %s: %d nodes held fixed (%d corner nodes, %d midside or face nodes)", name, held.size,
             model.clamped.size, held.size - model.clamped.size)
    body = np.unique(np.asarray(mesh.cells[mesh.body_type]))
    loose = np.setdiff1d(np.intersect1d(chosen, body), held)
    if loose.size:
        log.warning("clamp %s: %d of its nodes are not held (midside nodes whose edge has a free corner; first: node "
                    "%d): the elements clamp an edge's middle only with its corners", name, loose.size,
                    mesh.node_id(loose[0]))


#: A modulus (Pa) below which no blade is made (polymers start near 1e9; a metal's modulus typed in MPa is ~1e5).
SOFTEST_BLADE_E = 1e7


def check_plausibility(study: Study, model: FEModel, f1_hz: float | None = None) -> str | None:
    """Warn (log) when ``model`` is not a blade: its total mass (and, given, its first frequency ``f1_hz``) far
    outside :data:`~bladecase.fe.mesh_checks.BLADE_MASS_KG` (:data:`~bladecase.fe.mesh_checks.BLADE_F1_HZ`), naming
    the likely unit slip; a plane-stress thickness beyond the plate's size.  Returns the sentence (``None``: plausible).
    With ``f1_hz``, only a first frequency out of range is logged (the mass was, by :func:`build_model`)."""
    from ..fe.mesh_checks import BLADE_F1_HZ, plausibility, thin_plate

    sentence = plausibility(model.total_mass, f1_hz, unit=model.mesh.unit, dim=model.dim, E=model.material.E,
                            source="geometry" if study.parametric else "mesh")
    if f1_hz is None and model.dim == 2 and model.plane == "stress":
        thick = thin_plate(model.thickness, float(np.ptp(model.mesh.points[:, :2], axis=0).max()))
        if thick:
            log.warning("%s", thick)
    E = model.material.E
    if f1_hz is None and sentence is None and E < SOFTEST_BLADE_E:  # whatever the frequencies: no blade is rubber
        log.warning("[material] E = %g Pa is a rubber's stiffness (a blade's metal or composite: 1e10 to 5e11 Pa): "
                    "a modulus in MPa? Give it in Pa (E = %.4g) with rho in kg/m³", E, E * 1e6)
    if sentence and (f1_hz is None or not BLADE_F1_HZ[0] <= f1_hz <= BLADE_F1_HZ[1]):
        log.warning("FE model of %s: %s", model.mesh.source or "the mesh", sentence)
    return sentence


#: The mesh group made from a ``[contact] face`` given by coordinates (a plane, box or sphere table).
SELECTED_FACE = "contact_face_selected"


def _with_selections(study: Study, mesh: Mesh) -> Mesh:
    """``mesh`` with the node sets the study selects by coordinates or node numbers as named groups
    (``[contact] face`` given as a table, ``[contact] nodes``)."""
    c = study["contact"]
    face, key = (c["face"], "[contact] face") if isinstance(c["face"], dict) else (
        ({"nodes": c["nodes"]}, "[contact] nodes") if c.get("nodes") is not None else (None, ""))
    if face is None:
        return mesh
    from dataclasses import replace

    nodes = selected_nodes(study, mesh, face, key)
    return replace(mesh, groups={**mesh.groups, SELECTED_FACE: nodes})


def selected_nodes(study: Study, mesh: Mesh, spec: dict, key: str, allow_all: bool = True) -> np.ndarray:
    """The 0-based nodes of a selection table of ``key`` (``[fem] clamp``, ``[contact] face``): by coordinates
    (:func:`bladecase.fe.select_nodes`) or by node numbers as in the mesh file, ``nodes = [...]`` or ``nodes_file``
    (relative to the study file; a number not in the mesh is named, with its line)."""
    from ..fe import select_nodes

    try:
        if "nodes_file" in spec:
            listed = read_node_list(study.base / spec["nodes_file"], key)
            _check_listed(mesh, listed, key, spec["nodes_file"])
            spec = {"nodes": [k for k, _ in listed]}
        if "nodes" in spec:
            mesh.index_of(spec["nodes"], f"{key}: node")  # the first number that is not a node, named
        return select_nodes(mesh, spec, what=key, allow_all=allow_all)
    except StudyError:
        raise
    except ValueError as exc:
        raise StudyError(str(exc) if str(exc).startswith("[") else f"{key}: {exc}") from None


def _check_listed(mesh: Mesh, listed: list[tuple[int, int]], key: str, name: str) -> None:
    """``StudyError`` naming the first listed number (and its line in the file ``name``) that is not a node of
    ``mesh``."""
    ids = np.array([k for k, _ in listed], dtype=np.int64)
    missing = np.flatnonzero(~np.isin(ids, mesh.node_ids))
    if missing.size:
        k, line = listed[int(missing[0])]
        try:
            mesh.index_of([k], f"{key}: node")
        except ValueError as exc:
            raise StudyError(str(exc).replace(f"node {k} ", f"node {k} ({name}, line {line}) ", 1)) from None


#: Largest node list file read (bytes): a million node numbers take under 10 MB.
MAX_NODE_FILE_BYTES = 100_000_000


def read_node_list(path, key: str) -> list[tuple[int, int]]:
    """``(node number, line)`` of a node list file: one number per line, or numbers separated by commas or spaces;
    ``#``, ``!`` and ``**`` comments, blank lines and one Abaqus ``*NSET`` line (a CalculiX ``.nam`` file of one set)
    allowed.  ``StudyError`` naming ``key``, the file and the line of anything else."""
    from ..fe.mesh_checks import check_input_file

    try:
        name = check_input_file(path, "node list file")
    except ValueError as exc:
        raise StudyError(f"{key}: nodes_file: {exc}") from None
    if os.path.getsize(name) > MAX_NODE_FILE_BYTES:
        raise StudyError(f"{key}: nodes_file {name!r} is larger than {MAX_NODE_FILE_BYTES} bytes: not a node list")
    out, keywords = [], 0
    with open(name, encoding="latin-1") as fh:
        for line, text in enumerate(fh, start=1):
            text = text.split("#", 1)[0].split("!", 1)[0].strip()
            if not text or text.startswith("**"):
                continue
            if text.startswith("*"):
                keywords += 1
                if keywords > 1 or not text[1:].lstrip().upper().startswith("NSET"):
                    raise StudyError(f"{key}: nodes_file {name!r}, line {line}: {text!r}: a node list holds node "
                                     "numbers (and at most one *NSET line: one set of a .nam file)")
                continue
            for token in text.replace(",", " ").split():
                try:
                    out.append((int(token), line))
                except ValueError:
                    raise StudyError(f"{key}: nodes_file {name!r}, line {line}: {token!r} is not a node number "
                                     "(integers, one per line or separated by commas or spaces)") from None
    if not out:
        raise StudyError(f"{key}: nodes_file {name!r} lists no node number")
    return out


def contact_group(study: Study) -> str | None:
    """The mesh group ``[contact]`` selects from (``None``: a node index, every free node, or no contact)."""
    if not study.has_contact:
        return None
    c = study["contact"]
    if c["face"] is not None or c.get("nodes") is not None:
        return c["face"] if isinstance(c["face"], str) else SELECTED_FACE
    if c["node"] is not None:
        return None
    if c["farthest"] is not None:
        return c["group"] or "tip"
    if c["nearest"] is not None:
        return c["group"]
    return c["group"] or "contact"


def build_contact(study: Study, model: FEModel) -> Contact:
    """The contact of ``[contact]`` on ``model`` (node checked to be free).

    ``node`` → that node (its number in the mesh file); ``face`` or ``nodes`` →
    the mean normal displacement of the face's free nodes; ``farthest`` → the
    free node of ``group`` (default ``tip``) farthest along the direction;
    ``nearest`` → the free node nearest the point (within ``group`` if given);
    otherwise the node of the one-node ``group`` (default ``contact``).
    """
    if not study.has_contact:
        raise StudyError("[contact]: this study has none — a contact (its clearance, node or face) is needed for a "
                         "reduced model and nonsmooth modes; without one, 'bladecase run' gives the linear modes and "
                         "the Campbell diagram")
    contact = _picked_contact(study, model)
    mesh = model.mesh
    if mesh.numbering == "file":  # the file's number, beside the 0-based index of mesh.vtu
        log.info("contact: node %d of %s (index %d in mesh.vtu)%s", mesh.node_id(contact.node), mesh.source,
                 contact.node, f", the centre of a face of {len(contact.nodes)} nodes" if contact.nodes else "")
    casing = casing_stiffness(study)
    per_area = study["contact"].get("casing_stiffness_per_area")
    if per_area is not None:  # the face mean's spring: every node's share in parallel
        from ..reduction.contact import tributary_areas

        area = float(tributary_areas(model, contact.nodes).sum())
        casing = per_area * area
        log.info("casing: %.4g N/m³ over the contact face's %.4g mm²: %.4g N/m", per_area, area * 1e6, casing)
    return contact if casing is None else contact.with_casing(casing)


def casing_stiffness(study: Study) -> float | None:
    """``[contact] casing_stiffness`` of the run's results: the value, or the first of a list (N/m; ``None``: rigid)."""
    k = study["contact"]["casing_stiffness"]
    return k[0] if isinstance(k, list) else k


def casing_sweep_values(study: Study) -> list[float]:
    """The stiffnesses of a ``casing_stiffness = [k1, k2, …]`` sensitivity sweep (N/m; empty without a list)."""
    k = study["contact"]["casing_stiffness"]
    return [float(x) for x in k] if isinstance(k, list) else []


def _casing(study: Study):
    """``[casing]`` as a :class:`~bladecase.reduction.casing.Casing` (``None`` without one)."""
    k = study.config.get("casing") or {}
    if k.get("radius") is None and k.get("radii") is None:
        return None
    from ..fe.rotation import RotationAxis
    from ..reduction.casing import Casing

    axis = RotationAxis(k["axis"]["origin"], k["axis"]["direction"])
    return Casing(axis, radius=k["radius"], radii=None if k["radii"] is None else tuple(map(tuple, k["radii"])))


def _picked_contact(study: Study, model: FEModel) -> Contact:
    c = study["contact"]
    normal, gap = c["normal"], c["clearance"]
    group = contact_group(study)
    try:
        casing = _casing(study)
        if casing is not None:  # each node its own clearance and normal from the casing of revolution
            return Contact.on_casing(model, casing, group, weights=c["weights"] or "area")
        if c["face"] is not None or c.get("nodes") is not None:
            return Contact.face(model, group, normal, gap, weights=c["weights"] or "equal")
        if c["node"] is not None:  # a node number as in the mesh file
            try:
                index = int(model.mesh.index_of([c["node"]])[0])
            except ValueError as exc:
                raise StudyError(f"[contact] node: {exc}") from None
            return Contact.at(model, index, normal, gap)
        if c["farthest"] is not None:
            return Contact.farthest(model, c["farthest"], normal, gap, group=group)
        if c["nearest"] is not None:
            return Contact.nearest(model, c["nearest"], normal, gap, group=group)
        nodes = model.mesh.group(group)
        if len(nodes) != 1:
            raise StudyError(f"[contact] group: group {group!r} has {len(nodes)} nodes; the contact is one "
                             "node: name a one-node group, or add farthest = [dx, dy, dz] or nearest = [x, y, z]")
        return Contact.at(model, int(nodes[0]), normal, gap)
    except StudyError:
        raise
    except ValueError as exc:
        raise StudyError(f"[contact] {exc}") from None


def build_reduced(study: Study, model: FEModel, contact: Contact, method: str | None = None,
                  size: int | None = None, factor: SPDFactor | None = None) -> ReducedModel:
    """The reduced model of ``[reduction]`` (or of ``method``/``size``).

    ``factor``: :func:`bladecase.fe.stiffness_factor` of ``model`` to share one factorisation of ``K``
    between the models of a study.
    """
    r = study["reduction"]
    main = method is None
    key = "method" if method is None or method == r["method"] else "compare"
    method = method or r["method"]
    size = (r["size"] if size is None else size) if method != "full" else None
    if method in EIGEN_METHODS and size is not None:
        _check_eigen_work(method, size, model.n_dofs)
    limit = _limits(study)["dofs_full"]
    if method == "full" and model.n_dofs > limit:
        raise StudyError(f"[reduction] {key}: method 'full' keeps all {model.n_dofs} free dofs of this model in dense "
                         f"matrices, more than [limits] dofs_full = {limit}: use a reduced method, e.g. method = "
                         f"'lanczos-si' with size = 20, or raise [limits] dofs_full (at most {DENSE_LIMIT_FULL})")
    try:
        reduced = reduce(model, contact, method, size, factor=factor, limit=limit)
    except ValueError as exc:
        raise StudyError(f"[reduction] {exc}") from None
    if main and (study.config.get("forcing") or {}).get("amplitude") is not None:
        check_forcing(study, reduced)
    return reduced


def check_forcing(study: Study, reduced: ReducedModel) -> None:
    """The forced response's work on ``reduced``, checked as soon as the reduced model is known (before the
    search): the amplitude against the clearance, the sweep within ``[limits] sweep_periods`` counted in periods
    ``T1`` (:func:`bladecase.study.forcing.stage.check_sweep_work`); and the load itself (its group, its node)."""
    from ..reduction.loads import project_load
    from .forcing.stage import build_load, check_sweep_work, contact_load

    forcing = study["forcing"]
    try:
        f_free, _ = build_load(reduced, forcing)
        check_sweep_work(reduced, forcing, project_load(reduced, f_free), contact_load(reduced, f_free),
                         max_periods=_limits(study)["sweep_periods"])
    except StudyError:
        raise
    except ValueError as exc:
        raise StudyError(str(exc) if str(exc).startswith("[forcing]") else f"[forcing] {exc}") from None


def _limits(study: Study) -> dict:
    """``[limits]`` with its defaults (a :class:`Study` made without :func:`validate` may lack the section)."""
    from .sections import LIMIT_KEYS

    given = study.config.get("limits") or {}
    return {k: spec.default if given.get(k) is None else given[k] for k, spec in LIMIT_KEYS.items()}


#: Most free dofs ``[limits] dofs_full`` may allow: the dense spectrum's bound of the search.
DENSE_LIMIT_FULL = NSM_DENSE_LIMIT


#: Reduction methods whose cost is an eigen-solution for ``size`` modes of the FE model (ARPACK shift-invert).
EIGEN_METHODS = ("modal", "craig-bampton")

#: Seconds per ``n·k²`` of ARPACK shift-invert for ``k`` modes of ``n`` dofs (measured: 5787 dofs, 200 / 500 /
#: 1000 modes in 3.5 / 17 / 72 s on one core); the estimate is only used to refuse or warn, not to time.
EIGEN_SECONDS_PER_NK2 = 1.2e-8

#: Estimated seconds above which a reduction is refused, and above which a warning is logged.
EIGEN_REFUSE_S, EIGEN_WARN_S = 3600.0, 60.0


def _check_eigen_work(method: str, size: int, n: int) -> None:
    """Refuse (or warn about) a modal / Craig–Bampton size whose eigen-solution is out of proportion."""
    if n <= DENSE_LIMIT:
        return  # a dense eigen-solution of at most DENSE_LIMIT dofs takes seconds whatever the size
    est = EIGEN_SECONDS_PER_NK2 * n * size ** 2
    if est > EIGEN_REFUSE_S:
        top = int(np.sqrt(EIGEN_REFUSE_S / (EIGEN_SECONDS_PER_NK2 * n)))
        raise StudyError(f"[reduction] size: {method} {size} on {n} dofs needs {size} eigenmodes, estimated "
                         f"{est / 3600:.1f} h; valid: at most {top} for this model (or 'lanczos-si', whose cost "
                         f"grows linearly with the size)")
    if est > EIGEN_WARN_S:
        log.warning("%s %d on %d dofs: %d eigenmodes, estimated %.0f s (ARPACK; 'lanczos-si' is linear in the "
                    "size)", method, size, n, size, est)


def period_unit(study: Study, system: LinearSystem) -> tuple[float, str]:
    """Seconds per unit of ``[search] periods``, and the unit's label."""
    unit = study["search"]["period_unit"]
    if unit == "s":
        return 1.0, "s"
    j = int(unit[1:])
    omega = system.spectrum.contact_modes[0]
    if j > omega.size:
        raise StudyError(f"[search] period_unit: {unit!r} but the reduced model has only {omega.size} modes "
                         "that see the contact")
    return float(2 * np.pi / omega[j - 1]), unit


#: Seconds per start cell × reduced dof × k² of the k >= 3 start search (measured: the plate's 4-ipp search,
#: modal 10, 2 × 16 215 cells in 236 s; chain(5) 3-ipp, 1800 cells in 1.7 s) — for estimates only.
START_CELL_SECONDS = 4e-5

#: Estimated seconds of a k >= 3 start search above which the study warns, and above which it refuses.
START_WARN_S, START_REFUSE_S = 60.0, 6 * 3600.0


def _check_start_grid(system, k: int, T: float, scan: int, resolution: int | None, label: str = "") -> None:
    """Announce (or refuse) a k >= 3 start search whose grid of ordered impact times is out of proportion."""
    if k < 3 or not hasattr(system, "spectrum"):
        return
    from math import comb

    from ..nsm.newton.kipp import default_resolution

    res = resolution or default_resolution(T, float(system.spectrum.contact_modes[0].max()))
    cells = comb(res - 1, k - 1) * scan
    est = START_CELL_SECONDS * cells * system.n * k * k
    what = (f"{label + ': ' if label else ''}{k}-ipp start search: {scan} periods × {comb(res - 1, k - 1)} cells "
            f"(resolution {res}) on {system.n} dofs, estimated {est / 60:.1f} min")
    if est > START_REFUSE_S:
        raise StudyError(f"[search] ipp: {what}; valid: a smaller [search] resolution or scan, or fewer impacts "
                         "per period")
    if est > START_WARN_S:
        log.warning("%s (a smaller [search] resolution or scan shortens it)", what)


#: Seconds per resonance of the contact in the period range × reduced dof of a k-ipp search — for estimates
#: only.  Each resonance ``T = 2πm/ω_j`` cuts the families into pieces; measured (2-ipp, CPU, idle machine):
#: the demo's 16 and 32 Lanczos vectors, 190 and 684 resonances, 6.4 and 28.5 s (2.1e-3, 1.3e-3); a 58-dof
#: Craig–Bampton model of a 16-node face, modes up to 6 700 ω₁ and 12 349 resonances in [0.9, 0.9999] T₁: 24.7 s
#: for the 0.2 % of the range that holds 246 of them (1.7e-3); chains are faster (chain(50): 203, 4.8 s).
RESONANCE_SECONDS = 2e-3

#: Estimated seconds of a k-ipp search above which the study warns, and above which it refuses.
SEARCH_WARN_S, SEARCH_REFUSE_S = 60.0, 1800.0

#: A long search's warning says how much of the contact's inverse mass lies in the modes above this many times
#: the lowest frequency (on a Craig–Bampton contact face: the face's local modes).
STIFF_RATIO = 100.0


def resonance_count(system, T_range: tuple[float, float]) -> int:
    """Resonances ``T = 2πm/ω_j`` (``m ≥ 1``, ``ω_j`` the modes the contact sees) in ``T_range``.

    >>> import bladecase as bc
    >>> system = bc.chain(3, k=1.0, m=1.0, gap=1.0)
    >>> T1 = 2 * np.pi / system.spectrum.omega[0]
    >>> resonance_count(system, (0.5 * T1, T1))  # ω/ω₁ = 1, 2.8, 4.05: m = 1; 2; 3, 4
    4
    """
    omega = system.spectrum.contact_modes[0]
    lo, hi = (omega * T / (2 * np.pi) for T in T_range)
    return int(np.sum(np.floor(hi) - np.floor(lo)))


def _search_estimate(system, T_range: tuple[float, float]) -> float:
    return RESONANCE_SECONDS * resonance_count(system, T_range) * system.n


def _stiff_share(omega: np.ndarray, b: np.ndarray, omega1: float) -> str:
    """Words for the share of the contact's inverse mass ``Σ b_j² = wᵀM⁻¹w`` (the velocity an impulse gives the
    contact: what an impact excites) in the modes above :data:`STIFF_RATIO` × the lowest frequency; empty when
    there are none."""
    high = omega > STIFF_RATIO * omega1
    if not high.any():
        return ""
    share = float(b[high] @ b[high] / (b @ b))
    return (f"; {100 * share:.3g} % of the contact's inverse mass wᵀM⁻¹w (what an impact excites) lies in its "
            f"{int(high.sum())} modes above {STIFF_RATIO:g} × the lowest frequency")


def _check_resonances(system, k: int, T_range: tuple[float, float], label: str = "") -> None:
    """Announce (or refuse) a k-ipp search whose period range holds a great many resonances of the contact."""
    if not hasattr(system, "spectrum"):
        return
    est = _search_estimate(system, T_range)
    if est <= SEARCH_WARN_S:
        return
    omega, b, _ = system.spectrum.contact_modes
    ratio = float(omega.max() / system.spectrum.omega[0])
    what = (f"{label + ': ' if label else ''}{k}-ipp search: the contact sees modes up to {ratio:.0f} × the lowest "
            f"frequency ({omega.max() / (2 * np.pi):.4g} Hz) and {resonance_count(system, T_range)} resonances "
            f"T = 2πm/ω_j lie in the period range [{T_range[0]:.6g}, {T_range[1]:.6g}] s, each cutting the families "
            f"into pieces: estimated {est / 60:.{1 if est < 600 else 0}f} min on {system.n} dofs")
    share = _stiff_share(omega, b, system.spectrum.omega[0])
    if est > SEARCH_REFUSE_S:
        hi, top = T_range[0], T_range[1]  # the longest range from T_lo estimated within SEARCH_REFUSE_S
        for _ in range(60):
            mid = 0.5 * (hi + top)
            hi, top = (mid, top) if _search_estimate(system, (T_range[0], mid)) <= SEARCH_REFUSE_S else (hi, mid)
        unit = 10.0 ** (np.floor(np.log10(hi)) - 5)  # rounded down to the 6 digits the message shows
        hi = float(np.floor(hi / unit) * unit)
        raise StudyError(f"[search] periods: {what}, with thousands of families to hold in memory{share}; valid: a "
                         f"range estimated within {SEARCH_REFUSE_S / 60:.0f} min (from {T_range[0]:.6g} s: up to "
                         f"{hi:.6g} s), a reduced model without the contact's stiffest modes (a Craig–Bampton model "
                         "of a contact face keeps the face's local modes), or the massless contact model ([contact] "
                         "model = \"massless\")")
    log.warning("%s%s (a narrower [search] periods shortens it)", what, share)


def _lowest_omega(system) -> float:
    return float(system.open.omega[0] if hasattr(system, "open") else system.spectrum.omega[0])


def search(study: Study, system: LinearSystem, progress: bool = False, unit: float | None = None,
           label: str = "") -> list[Branch]:
    """Every family of every ``[search] ipp`` in the study's period range.

    ``unit``: seconds per period unit (default: from ``system``; comparison
    models pass the primary model's, so that every model searches the same
    periods).  ``label``: the model's name in the log lines.
    """
    s = study["search"]
    scale = period_unit(study, system)[0] if unit is None else unit
    T_range = (s["periods"][0] * scale, s["periods"][1] * scale)
    T_top = float(2 * np.pi / _lowest_omega(system))
    if T_range[1] > 100 * T_top:
        raise StudyError(f"[search] periods: up to {T_range[1]:.6g} s, more than 100 × the longest linear period "
                         f"{T_top:.6g} s; valid: at most {100 * T_top:.6g} s")
    families: list[Branch] = []
    for k in s["ipp"]:
        _check_resonances(system, k, T_range, label)
        _check_start_grid(system, k, T_range[1], s["scan"], s["resolution"], label)
        t0 = time.perf_counter()
        found = nonsmooth_mode(system, k, T_range, scan=s["scan"], step=s["step"], max_points=s["max_points"],
                               progress=progress, resolution=s["resolution"])
        n_arcs = sum(len(f.arcs) for f in found)
        massless = getattr(system, "contact_model", "") == "massless"
        what = f"{k} contact phase{'s' if k > 1 else ''} per period" if massless else f"{k}-ipp"
        log.info("%s%s: %d famil%s, %d with admissible arcs (%d arc%s) (%.1f s)", f"{label}: " if label else "",
                 what, len(found), "y" if len(found) == 1 else "ies", sum(1 for f in found if f.arcs), n_arcs,
                 "" if n_arcs == 1 else "s", time.perf_counter() - t0)
        families.extend(found)
    return families
