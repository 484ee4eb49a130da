"""A study run end to end: mesh → FE model → contact → reduced model(s) → nonsmooth modes → results.

Each stage is a plain function of the validated :class:`~bladecase.study.schema.Study`
and the previous stage's data, so the command line can run one stage from
files (``bladecase mesh / assemble / reduce / modes / animate``) or all of
them (``bladecase run``, :func:`run`).

:func:`run` writes into a hidden staging folder inside the output directory
and moves the results into place only when everything succeeded: a failed run
leaves the previous results untouched and nothing half-written.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fe import FEModel, Material, Mesh, assemble, blade_mesh, load_mesh, natural_frequencies
from ..io import replace_dir, save_figure, write_json, write_text
from ..nsm import Arc, Family, LinearSystem, PeriodicOrbit, nonsmooth_mode
from ..reduction import Contact, ReducedModel, reduce
from .schema import Study, StudyError

log = logging.getLogger("bladecase")


# ----------------------------------------------------------------------------- stages

def build_mesh(study: Study, path: str | os.PathLike | None = None) -> Mesh:
    """The study's mesh: gmsh on ``[geometry]`` (written to ``path`` if given) or the ``[mesh]`` file.

    The clamp group and, when the contact is picked by group, the contact group must exist.
    """
    need = [study["fem"]["clamp"]]
    group = contact_group(study)
    if group is not None:
        need.append(group)
    if study.parametric:
        g = study["geometry"]
        try:
            mesh = blade_mesh(study.geometry(), size=g["size"], tip_size=g["tip_size"], order=g["mesh_order"],
                              path=path)
        except ValueError as exc:
            raise StudyError(f"[geometry] {exc}") from None
    else:
        source = study.mesh_path()
        if not source.exists():
            raise StudyError(f"[mesh] path: no such file {str(source)!r}")
        mesh = load_mesh(source)
        if path is not None:
            from ..fe import save_mesh

            save_mesh(mesh, path)
    for name, key in zip(need, ("[fem] clamp", "[contact] group")):
        if name not in mesh.groups:
            have = ", ".join(sorted(mesh.groups)) or "none"
            raise StudyError(f"{key}: the mesh {mesh.source} has no group {name!r} (groups: {have})")
    return mesh


def material(study: Study) -> Material:
    m = study["material"]
    if m["E"] is not None:
        return Material(float(m["E"]), float(m["nu"]), float(m["rho"]), "custom")
    try:
        return Material.preset(m["preset"])
    except ValueError as exc:
        raise StudyError(f"[material] preset: {exc}") from None


def build_model(study: Study, mesh: Mesh) -> FEModel:
    """Assemble the FE model of ``[material]`` and ``[fem]`` on ``mesh``."""
    f = study["fem"]
    if mesh.dim == 2 and f["thickness"] is None:
        raise StudyError("[fem] thickness: required for a 2-D (plane) mesh, e.g. thickness = 0.002 (metres)")
    if mesh.dim == 3 and f["thickness"] is not None:
        raise StudyError(f"[fem] thickness: only for 2-D meshes; this mesh is 3-D (got {f['thickness']!r})")
    return assemble(mesh, material(study), order=f["order"], mass=f["mass"], clamp=f["clamp"],
                    thickness=f["thickness"], plane=f["plane"])


def contact_group(study: Study) -> str | None:
    """The mesh group ``[contact]`` selects from (``None``: a node index, or every free node)."""
    c = study["contact"]
    if c["node"] is not None:
        return None
    if c["farthest"] is not None:
        return c["group"] or "tip"
    if c["nearest"] is not None:
        return c["group"]
    return c["group"] or "contact"


def build_contact(study: Study, model: FEModel) -> Contact:
    """The contact of ``[contact]`` on ``model`` (node checked to be free).

    ``node`` → that node; ``farthest`` → the free node of ``group`` (default
    ``tip``) farthest along the direction; ``nearest`` → the free node nearest
    the point (within ``group`` if given); otherwise the node of the one-node
    ``group`` (default ``contact``).
    """
    c = study["contact"]
    normal, gap = c["normal"], c["clearance"]
    group = contact_group(study)
    try:
        if c["node"] is not None:
            return Contact.at(model, c["node"], normal, gap)
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
                  size: int | None = None) -> ReducedModel:
    """The reduced model of ``[reduction]`` (or of ``method``/``size``)."""
    r = study["reduction"]
    method = method or r["method"]
    size = (r["size"] if size is None else size) if method != "full" else None
    try:
        return reduce(model, contact, method, size)
    except ValueError as exc:
        raise StudyError(f"[reduction] {exc}") from None


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


def search(study: Study, system: LinearSystem, progress: bool = False, unit: float | None = None) -> list[Family]:
    """Every family of every ``[search] ipp`` in the study's period range.

    ``unit``: seconds per period unit (default: from ``system``; comparison
    models pass the primary model's, so that every model searches the same
    periods).
    """
    s = study["search"]
    scale = period_unit(study, system)[0] if unit is None else unit
    T_range = (s["periods"][0] * scale, s["periods"][1] * scale)
    families: list[Family] = []
    for k in s["ipp"]:
        t0 = time.perf_counter()
        found = nonsmooth_mode(system, k, T_range, scan=s["scan"], step=s["step"], max_points=s["max_points"],
                               progress=progress, resolution=s["resolution"])
        n_arcs = sum(len(f.arcs) for f in found)
        log.info("%d-ipp: %d families, %d admissible arcs (%.1f s)", k, len(found), n_arcs, time.perf_counter() - t0)
        families.extend(found)
    return families


# ----------------------------------------------------------------------------- families on file

def family_from_dict(system: LinearSystem, data: dict) -> Family:
    """A :class:`Family` back from :meth:`Family.to_dict` (orbits as stored, not re-certified)."""
    orbits = [
        PeriodicOrbit(system=system, T=float(o["T"]), impact_times=np.asarray(o["impact_times"], dtype=float),
                      impulses=np.asarray(o["impulses"], dtype=float), energy=float(o["energy"]),
                      admissible=bool(o["admissible"]), max_violation=float(o["max_violation"]),
                      max_violation_time=float("nan"), repeats=int(o.get("repeats", 1)))
        for o in data["orbits"]
    ]
    arcs = [Arc(a["start"], a["stop"], a["T_lo"], a["T_hi"], a["refined_lo"], a["refined_hi"]) for a in data["arcs"]]
    return Family(system=system, k=int(data["ipp"]), orbits=orbits, arcs=arcs)


def load_families(path: str | os.PathLike, system: LinearSystem) -> list[Family]:
    """Families from a modes JSON file (``bladecase modes``), attached to ``system``."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        fams = [family_from_dict(system, f) for f in data["families"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"cannot read modes file {str(path)!r}: {exc}") from None
    n = data.get("system_dofs")
    if n is not None and n != system.n:
        raise ValueError(f"modes file {str(path)!r} was computed on a system of {n} dofs, this one has {system.n}")
    return fams


def families_document(families: list[Family], system: LinearSystem) -> dict:
    return {"system_dofs": system.n, "gap": system.gap, "families": [f.to_dict() for f in families]}


# ----------------------------------------------------------------------------- choosing orbits

@dataclass(frozen=True)
class Choice:
    """An orbit chosen for animation: family index and the orbit."""

    family: int
    orbit: PeriodicOrbit

    @property
    def stem(self) -> str:
        return f"mode{self.family:02d}_{self.orbit.k}ipp_T{self.orbit.T:.6e}".replace("+", "").replace(".", "p")


def _admissible_at(fam: Family, T: float) -> PeriodicOrbit | None:
    try:
        hits = [o for o in fam.orbit_at(T) if o.admissible]
    except ValueError:
        hits = []
    return hits[0] if hits else None


def choose_orbits(study: Study, families: list[Family], unit: float) -> list[Choice]:
    """The orbits to animate: ``[output] orbits`` if given, else the middles of the widest arcs."""
    o = study["output"]
    chosen: list[Choice] = []
    if o["orbits"]:
        for req in o["orbits"]:
            T = req["T"] * unit
            best = None
            for i, fam in enumerate(families):
                if fam.k != req["ipp"]:
                    continue
                if any(a.T_lo <= T <= a.T_hi for a in fam.arcs):
                    orbit = _admissible_at(fam, T)
                    if orbit is not None:
                        best = (0.0, i, orbit)
                        break
                for orbit in fam.orbits:
                    if orbit.admissible and (best is None or abs(orbit.T - T) < best[0]):
                        best = (abs(orbit.T - T), i, orbit)
            if best is None:
                raise StudyError(f"[output] orbits: no admissible {req['ipp']}-ipp orbit was found in the search "
                                 f"range (asked T = {req['T']} {study['search']['period_unit']})")
            if best[0] > 0:
                log.info("no admissible %d-ipp orbit at T = %.6g s; animating the nearest one, T = %.6g s",
                         req["ipp"], T, best[2].T)
            chosen.append(Choice(best[1], best[2]))
        return chosen
    arcs = sorted((((a.T_hi - a.T_lo) / a.T_hi, i, n) for i, fam in enumerate(families)
                   for n, a in enumerate(fam.arcs)), reverse=True)
    # Widest arcs first, one per family; then further arcs of the same families if fewer families than asked.
    order = [x for x in arcs if x[1] not in {y[1] for y in arcs[:arcs.index(x)]}]
    order += [x for x in arcs if x not in order]
    for _width, i, n in order:
        if len(chosen) >= o["animate"]:
            break
        fam = families[i]
        arc = fam.arcs[n]
        orbit = _admissible_at(fam, 0.5 * (arc.T_lo + arc.T_hi))
        if orbit is None:  # the arc is a single point, or the middle did not converge
            candidates = [fam.orbits[j] for j in range(arc.start, arc.stop + 1) if fam.orbits[j].admissible]
            if not candidates:
                continue
            orbit = candidates[len(candidates) // 2]
        chosen.append(Choice(i, orbit))
    return chosen


def frame_times(orbit: PeriodicOrbit, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """``frames`` instants over one period, with one frame moved onto each impact instant.

    Each impact takes the nearest frame that is not already an impact and
    can move there without reordering the frames (so close impacts get
    neighbouring frames).  Returns the times (increasing, in ``[0, T)``) and
    the impact-frame mask; ``t = 0`` (``= t_k = T``) is always an impact.
    """
    T = orbit.T
    t = np.arange(frames) * T / frames
    impact = np.zeros(frames, dtype=bool)
    impact[0] = True
    edges = np.append(t, T)
    for ti in np.sort(np.mod(orbit.impact_times, T)):
        if ti <= 1e-12 * T or ti >= T * (1 - 1e-12):
            continue  # the impact at t = 0
        for j in np.argsort(np.abs(t - ti), kind="stable"):
            if j > 0 and not impact[j] and edges[j - 1] < ti < edges[j + 1]:
                t[j] = edges[j] = ti
                impact[j] = True
                break
    return t, impact


# ----------------------------------------------------------------------------- the whole run

@dataclass
class RunResult:
    """What :func:`run` produced: the output directory and the summary written there."""

    directory: Path
    summary: dict = field(repr=False)
    families: list = field(repr=False, default_factory=list)


def _staging(out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=".bladecase-run-", dir=out))


#: Top-level result names a run owns in its output directory (older ones it did not write are removed).
RUN_RESULTS = ("summary.json", "report.md", "run.log", "modes.json", "frequency_energy.png", "mesh.vtu", "animations",
               "vtk")


def _publish(staging: Path, out: Path, owned: tuple[str, ...] = ()) -> None:
    """Move every entry of ``staging`` into ``out`` (replacing older results of the same name);
    remove the ``owned`` names this run did not write (stale results of an older run)."""
    for name in owned:
        stale = out / name
        if not (staging / name).exists() and stale.exists():
            shutil.rmtree(stale) if stale.is_dir() and not stale.is_symlink() else stale.unlink()
    for entry in sorted(staging.iterdir()):
        target = out / entry.name
        if target.is_dir() and not target.is_symlink():
            replace_dir(entry, target)
        else:
            os.replace(entry, target)
    staging.rmdir()


def _range(values: np.ndarray) -> list[float]:
    values = values[np.isfinite(values)]
    return [float(values.min()), float(values.max())] if values.size else [float("nan")] * 2


def family_summary(fam: Family) -> dict:
    T, E = fam.T, fam.energy
    return {
        "ipp": fam.k,
        "orbits": len(fam.orbits),
        "period_range_s": _range(T),
        "frequency_range_hz": _range(1 / T),
        "energy_range_j": _range(E),
        "admissible_orbits": int(fam.admissible.sum()),
        "admissible_arcs": [
            {"T_lo": a.T_lo, "T_hi": a.T_hi, "f_lo": 1 / a.T_hi, "f_hi": 1 / a.T_lo,
             "energy_range_j": _range(E[a.start:a.stop + 1][fam.admissible[a.start:a.stop + 1]]),
             "refined_lo": bool(a.refined_lo), "refined_hi": bool(a.refined_hi)} for a in fam.arcs
        ],
    }


def reduced_summary(reduced: ReducedModel, reference_hz: np.ndarray) -> dict:
    sp = reduced.system.spectrum
    f = sp.frequencies[sp.active]
    nearest = [float(np.min(np.abs(f - fr)) / fr) if f.size else float("nan") for fr in reference_hz]
    return {"method": reduced.method, "size": reduced.size, "reduced_dofs": reduced.n,
            "frequencies_hz": f.tolist(), "contact_weights_b2": (sp.b[sp.active] ** 2).tolist(),
            "relative_error_vs_fe": nearest}


def run(study: Study, out: str | os.PathLike | None = None, progress: bool = True) -> RunResult:
    """Run the whole study; write every result into the output directory.

    Files (in ``out``, default ``[output] directory``): ``summary.json``,
    ``report.md``, ``run.log``, ``modes.json`` (every family, every orbit),
    ``frequency_energy.png``, ``mesh.vtu`` (the mesh with its groups),
    ``animations/<stem>.gif`` / ``.mp4``, ``vtk/<stem>.pvd`` with
    ``vtk/<stem>/`` (one ``.vtu`` per frame) and ``vtk/<stem>_manifold.vtu``.
    """
    from tqdm.auto import tqdm

    out = study.output_dir(out)
    o = study["output"]
    t_start = time.perf_counter()
    staging = _staging(out)
    logfile = logging.FileHandler(staging / "run.log", encoding="utf-8")
    logfile.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
    logfile.setLevel(logging.INFO)
    level = log.level
    log.addHandler(logfile)
    if log.getEffectiveLevel() > logging.INFO:
        log.setLevel(logging.INFO)  # the file gets the whole log; console handlers keep their own levels
    log.info("study %s (%s) → %s", study.name, study.source, out)
    files: dict[str, object] = {}
    timings: dict[str, float] = {}
    stages = tqdm(total=6, desc="bladecase run", unit="stage", disable=not progress, leave=False)

    def stage(name: str):
        stages.set_postfix_str(name)
        timings[name] = time.perf_counter()

    def done(name: str):
        timings[name] = time.perf_counter() - timings[name]
        stages.update()

    try:
        stage("mesh")
        mesh = build_mesh(study)
        from ..fe import save_mesh

        save_mesh(mesh, staging / "mesh.vtu")
        files["mesh"] = "mesh.vtu"
        log.info("mesh: %d nodes, %d %s cells (%s)", len(mesh.points), len(mesh.cells[mesh.body_type]),
                 mesh.body_type, "gmsh" if study.parametric else mesh.source)
        done("mesh")

        stage("assemble")
        model = build_model(study, mesh)
        n_f = min(study["fem"]["frequencies"], model.n_dofs - 1)
        f_fe = natural_frequencies(model, n_f)
        log.info("FE model: %s; first frequencies %s Hz", model, ", ".join(f"{x:.1f}" for x in f_fe[:6]))
        done("assemble")

        stage("reduce")
        contact = build_contact(study, model)
        reduced = build_reduced(study, model, contact)
        compares = [build_reduced(study, model, contact, c["method"], c.get("size")) for c in
                    study["reduction"]["compare"]]
        log.info("contact: node %d at %s, normal %s, clearance %g m", contact.node,
                 np.round(mesh.points[contact.node], 6).tolist(), np.round(contact.normal_for(model), 6).tolist(),
                 contact.gap)
        log.info("reduced model: %s", reduced)
        done("reduce")

        stage("search")
        unit, unit_name = period_unit(study, reduced.system)
        families = search(study, reduced.system, progress=progress)
        compare_families = [search(study, r.system, progress=progress, unit=unit) for r in compares]
        write_json(staging / "modes.json", families_document(families, reduced.system))
        files["modes"] = "modes.json"
        done("search")

        stage("plots")
        if "png" in o["formats"]:
            files["frequency_energy_plot"] = _plot(study, families, compares, compare_families, reduced, f_fe,
                                                   staging / "frequency_energy.png")
        done("plots")

        stage("render")
        files["animations"] = _animations(study, reduced, families, staging, progress)
        done("render")
    except BaseException:
        stages.close()
        _detach(logfile, level)
        shutil.rmtree(staging, ignore_errors=True)
        raise
    stages.close()
    files["log"] = "run.log"

    summary = {
        "study": study.name,
        "source": study.source,
        "bladecase_version": _version(),
        "model": {
            "mesh": {"nodes": len(mesh.points), "cells": len(mesh.cells[mesh.body_type]), "type": mesh.body_type,
                     "source": "gmsh (parametric [geometry])" if study.parametric else str(study.mesh_path())},
            "dim": model.dim, "dofs": model.n_dofs, "order": model.order, "mass_matrix": model.mass,
            "material": {"name": model.material.name, "E": model.material.E, "nu": model.material.nu,
                         "rho": model.material.rho},
            "total_mass_kg": model.total_mass, "clamped_nodes": int(model.clamped.size),
            "linear_frequencies_hz": f_fe.tolist(),
        },
        "contact": {"node": contact.node, "position": mesh.points[contact.node].tolist(),
                    "normal": contact.normal_for(model).tolist(), "clearance_m": contact.gap},
        "reduction": reduced_summary(reduced, f_fe),
        "compare": [dict(reduced_summary(r, f_fe), families=[family_summary(f) for f in fams])
                    for r, fams in zip(compares, compare_families)],
        "search": {**study["search"], "period_unit_s": unit},
        "families": [family_summary(f) for f in families],
        "timings_s": {k: round(v, 3) for k, v in timings.items()},
        "files": files,
    }
    summary["timings_s"]["total"] = round(time.perf_counter() - t_start, 3)
    try:
        log.info("results in %s (%.1f s)", out, summary["timings_s"]["total"])
        _detach(logfile, level)
        write_json(staging / "summary.json", summary)
        write_text(staging / "report.md", report(summary))
        _publish(staging, out, RUN_RESULTS)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return RunResult(directory=out, summary=summary, families=families)


def _animations(study: Study, reduced: ReducedModel, families: list[Family], staging: Path,
                progress: bool) -> list[dict]:
    from tqdm.auto import tqdm

    unit, _ = period_unit(study, reduced.system)
    chosen = choose_orbits(study, families, unit)
    if not chosen:
        log.warning("no admissible orbit to animate: widen [search] periods or add ipp values")
    return [_render(study, reduced, families, c, staging, progress) for c in
            tqdm(chosen, desc="animations", unit="orbit", disable=not progress, leave=False)]


def animate_families(study: Study, reduced: ReducedModel, families: list[Family],
                     out: str | os.PathLike | None = None, progress: bool = False) -> list[dict]:
    """The render stage alone (``bladecase animate``): animations and VTK files of the chosen orbits.

    Returns one entry per animated orbit (period, energy, verification, file
    names relative to the output directory); files are published together.
    """
    out = study.output_dir(out)
    staging = _staging(out)
    try:
        entries = _animations(study, reduced, families, staging, progress)
        _publish(staging, out, ("animations", "vtk"))
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return entries


#: Relative tolerance of the independent check of an animated orbit: the
#: event-driven simulator started from its post-impact state at ``t = 0`` must
#: come back to that state after one period (with ``k`` impacts).
VERIFY_RTOL = 1e-8


def verify(orbit: PeriodicOrbit) -> dict:
    """Simulate one period from the orbit's post-impact state (:func:`bladecase.simulate`) and compare.

    Returns ``{"return_error": ‖z(T) − z(0)‖/‖z(0)‖ (state (x, v) scaled by
    its component ranges), "impacts": impacts found in (0, T], "ok": bool}``.
    """
    from ..nsm import simulate

    T, k = orbit.T, orbit.k
    x0, v0 = orbit.state(np.array([0.0]))
    x0, v0 = x0[:, 0], v0[:, 0]
    flights = np.diff(np.concatenate([[0.0], orbit.impact_times]))
    try:
        traj = simulate(orbit.system, x0, v0, T + 0.5 * flights.min())
    except ValueError as exc:  # e.g. the orbit's state at t = 0 is not at/behind the casing
        return {"return_error": float("inf"), "impacts": 0, "ok": False, "reason": str(exc)}
    hits = np.flatnonzero((traj.impact_times > 0) & (traj.impact_times <= T + 0.25 * flights.min()))
    if hits.size == 0:
        return {"return_error": float("inf"), "impacts": 0, "ok": False}
    last = hits[-1]
    sx, sv = max(np.abs(x0).max(), 1e-300), max(np.abs(v0).max(), 1e-300)
    err = max(np.abs(traj.x[:, last] - x0).max() / sx, np.abs(traj.v[:, last] - v0).max() / sv,
              abs(traj.impact_times[last] - T) / T)
    return {"return_error": float(err), "impacts": int(hits.size), "ok": bool(err <= VERIFY_RTOL and hits.size == k)}


def _detach(handler: logging.Handler, level: int) -> None:
    log.removeHandler(handler)
    handler.close()
    log.setLevel(level)


def _version() -> str:
    from .. import __version__

    return __version__


def _plot(study, families, compares, compare_families, reduced, f_fe, path: Path) -> str:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..post.plots import frequency_energy

    models = [(reduced, families)] + list(zip(compares, compare_families))
    fig, axes = plt.subplots(len(models), 1, figsize=(8, 4.6 * len(models)), layout="constrained", squeeze=False)
    for ax, (r, fams) in zip(axes[:, 0], models):
        title = f"{study.name}: {r.method} ({r.n} dofs)"
        if fams:
            frequency_energy(fams, ax=ax, title=title)
        else:
            ax.set_title(title + ": no family found")
        for j, fj in enumerate(f_fe):
            lo, hi = ax.get_xlim()
            if lo <= fj <= hi:
                ax.axvline(fj, color="0.4", ls=":", lw=1.0, label="full FE frequencies" if j == 0 else None)
        ax.set_xlabel("frequency 1/T (Hz)")
        ax.set_ylabel("energy E (J)")
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path.name


def _render(study: Study, reduced: ReducedModel, families: list[Family], choice: Choice, staging: Path,
            progress: bool) -> dict:
    from ..post import animation as viz
    from ..post import vtk as export

    o = study["output"]
    orbit = choice.orbit
    times, impact = frame_times(orbit, o["frames"])
    u, v = reduced.expand(orbit, times)
    mesh = reduced.model.mesh
    scale = viz.auto_scale(mesh, u, o["auto_fraction"]) if o["scale"] == "auto" else float(o["scale"])
    entry = {"family": choice.family, "ipp": orbit.k, "T": orbit.T, "frequency_hz": 1 / orbit.T,
             "energy_j": orbit.energy, "impact_times": orbit.impact_times.tolist(),
             "impulses": orbit.impulses.tolist(), "scale": scale, "frames": int(times.size),
             "verification": verify(orbit)}
    if not entry["verification"]["ok"]:
        log.warning("orbit T = %.8g s failed the independent check (simulation from its post-impact state: "
                    "return error %.2e, %d impacts for %d): %s", orbit.T, entry["verification"]["return_error"],
                    entry["verification"]["impacts"], orbit.k, "animated anyway, flagged in summary.json")
    normal = reduced.contact.normal_for(reduced.model)
    title = f"{study.name}: {orbit.k}-ipp nonsmooth mode (family {choice.family})"
    if "gif" in o["formats"] or "mp4" in o["formats"]:
        want_mp4 = "mp4" in o["formats"]
        if want_mp4 and not viz.mp4_available():
            log.warning("MP4 skipped: imageio-ffmpeg is not installed (pip install imageio-ffmpeg)")
            want_mp4 = False
        paths = viz.animate(mesh, u, times, period=orbit.T, impact_frames=impact, contact_node=reduced.contact.node,
                            normal=normal, gap=reduced.system.gap, scale=scale,
                            gif=staging / "animations" / f"{choice.stem}.gif",
                            mp4=staging / "animations" / f"{choice.stem}.mp4" if want_mp4 else None,
                            title=title, window_size=tuple(o["window"]), fps=o["fps"])
        if "gif" not in o["formats"]:
            paths["gif"].unlink()
            paths.pop("gif")
        entry.update({k: f"animations/{p.name}" for k, p in paths.items()})
    if "vtu" in o["formats"]:
        pvd = export.write_time_series(staging / "vtk", choice.stem, mesh, times, u, v,
                                       point_data=None,
                                       field_data={"period": orbit.T, "energy": orbit.energy, "scale": scale})
        entry["pvd"] = f"vtk/{pvd.name}"
        if o["manifold"]:
            fam = families[choice.family]
            try:
                entry["manifold"] = _manifold(reduced, fam, orbit.T, staging / "vtk" / f"{choice.stem}_manifold.vtu",
                                              *o["manifold_size"])
            except ValueError as exc:
                log.warning("manifold of family %d not written: %s", choice.family, exc)
    log.info("animated %d-ipp orbit T = %.8g s (f = %.2f Hz, E = %.3g J; simulator return error %.1e)", orbit.k,
             orbit.T, 1 / orbit.T, orbit.energy, entry["verification"]["return_error"])
    return entry


def arc_orbits(fam: Family, T: float, count: int) -> list[PeriodicOrbit]:
    """``count`` admissible orbits evenly spread in period over the admissible arc of ``fam`` containing ``T``.

    Each is re-solved at its period (:meth:`Family.orbit_at`); where the curve
    crosses a period several times, the orbit closest in impact phases to the
    previous one is kept, so the samples follow one arc.
    """
    arcs = [a for a in fam.arcs if a.T_lo <= T <= a.T_hi] or sorted(fam.arcs, key=lambda a: a.T_lo - a.T_hi)[:1]
    if not arcs:
        return []
    arc = arcs[0]
    pad = 1e-6 * (arc.T_hi - arc.T_lo)
    out: list[PeriodicOrbit] = []
    for Tj in np.linspace(arc.T_lo + pad, arc.T_hi - pad, count):
        try:
            cands = [o for o in fam.orbit_at(Tj) if o.admissible]
        except ValueError:  # a resonant period
            continue
        if not cands:
            continue
        if out:
            ref = out[-1].impact_times / out[-1].T
            cands.sort(key=lambda o: np.abs(o.impact_times / o.T - ref).max())
        out.append(cands[0])
    return out


def _manifold(reduced: ReducedModel, fam: Family, T: float, path: Path, n_orbits: int, n_times: int) -> str:
    """Manifold samples over the admissible arc through ``T``, projected on
    (contact displacement ν·u, contact velocity × T/2π, period)."""
    from ..post.vtk import write_manifold

    orbits = arc_orbits(fam, T, n_orbits)
    if len(orbits) < 2:
        raise ValueError("fewer than two admissible orbits on the arc (a single-point arc)")
    theta = np.arange(n_times) / n_times
    Ts = np.array([o.T for o in orbits])
    states = [o.state(theta * o.T) for o in orbits]
    x = np.stack([st[0] for st in states], axis=1)  # (n, n_orbits, n_times)
    v = np.stack([st[1] for st in states], axis=1)
    w = reduced.system.w
    xc = np.einsum("i,ijk->jk", w, x)
    vc = np.einsum("i,ijk->jk", w, v)
    period = np.broadcast_to(Ts[:, None], xc.shape).copy()
    coords = np.stack([xc, vc * period / (2 * np.pi), period], axis=-1)
    energy = np.broadcast_to(np.array([o.energy for o in orbits])[:, None], xc.shape).copy()
    write_manifold(path, coords, point_data={
        "period": period, "phase": np.broadcast_to(theta[None, :], xc.shape).copy(), "energy": energy,
        "contact_displacement": xc, "contact_velocity": vc, "reduced_state": np.moveaxis(x, 0, -1)})
    return f"vtk/{path.name}"


# ----------------------------------------------------------------------------- the report

def report(summary: dict) -> str:
    """A human-readable Markdown report of a run's :data:`summary`."""
    m, c, r = summary["model"], summary["contact"], summary["reduction"]
    lines = [f"# bladecase study `{summary['study']}`", "",
             f"Study file: `{summary['source']}` — bladecase {summary['bladecase_version']} — "
             f"total {summary['timings_s']['total']:.1f} s.", "",
             "## Model", "",
             f"- Mesh: {m['mesh']['nodes']} nodes, {m['mesh']['cells']} `{m['mesh']['type']}` cells "
             f"({m['mesh']['source']}).",
             f"- FE model: {m['dim']}-D, P{m['order']}, {m['dofs']} free dofs, {m['mass_matrix']} mass, "
             f"{m['material']['name']} (E = {m['material']['E']:.4g} Pa, ν = {m['material']['nu']:g}, "
             f"ρ = {m['material']['rho']:g} kg/m³), total mass {m['total_mass_kg']:.5g} kg, "
             f"{m['clamped_nodes']} clamped nodes.",
             "- Linear frequencies (full FE model, Hz): " + ", ".join(f"{f:.2f}" for f in m["linear_frequencies_hz"]),
             "", "## Contact", "",
             f"- Node {c['node']} at ({', '.join(f'{x:.5g}' for x in c['position'])}) m, casing normal "
             f"({', '.join(f'{x:.4g}' for x in c['normal'])}), clearance {c['clearance_m'] * 1e3:.4g} mm.",
             "", "## Reduced model", "",
             f"- {r['method']} (size {r['size']}): {r['reduced_dofs']} reduced dofs.", "",
             "| mode | reduced f (Hz) | contact weight b² | full FE f (Hz) | rel. error |",
             "|---:|---:|---:|---:|---:|"]
    fe = m["linear_frequencies_hz"]
    for j, (f, b2) in enumerate(zip(r["frequencies_hz"], r["contact_weights_b2"])):
        if j >= 12:
            break
        ref = fe[int(np.argmin(np.abs(np.asarray(fe) - f)))] if fe else float("nan")
        lines.append(f"| {j + 1} | {f:.3f} | {b2:.3e} | {ref:.3f} | {abs(f - ref) / ref:.2e} |")
    for cmp in summary["compare"]:
        errs = ", ".join(f"{e:.1e}" for e in cmp["relative_error_vs_fe"])
        lines.append("")
        lines.append(f"- Comparison model {cmp['method']} (size {cmp['size']}, {cmp['reduced_dofs']} dofs): "
                     f"nearest-frequency errors vs FE [{errs}]; {len(cmp['families'])} families, "
                     f"{sum(len(f['admissible_arcs']) for f in cmp['families'])} admissible arcs.")
    s = summary["search"]
    lines += ["", "## Nonsmooth modes", "",
              f"Search: ipp {s['ipp']}, periods {s['periods']} × {s['period_unit']} "
              f"(= [{s['periods'][0] * s['period_unit_s']:.6g}, {s['periods'][1] * s['period_unit_s']:.6g}] s), "
              f"scan {s['scan']}.", ""]
    fams = summary["families"]
    with_arcs = [(i, f) for i, f in enumerate(fams) if f["admissible_arcs"]]
    lines.append(f"{len(fams)} families found, {len(with_arcs)} with admissible arcs "
                 f"(families without any are listed in `summary.json`).")
    lines += ["", "| family | ipp | orbits | f range (Hz) | admissible arc f (Hz) | energy on arc (J) |",
              "|---:|---:|---:|---|---|---|"]
    for i, f in with_arcs:
        for a in f["admissible_arcs"]:
            lines.append(f"| {i} | {f['ipp']} | {f['orbits']} | {f['frequency_range_hz'][0]:.3f} – "
                         f"{f['frequency_range_hz'][1]:.3f} | {a['f_lo']:.4f} – {a['f_hi']:.4f} | "
                         f"{a['energy_range_j'][0]:.3e} – {a['energy_range_j'][1]:.3e} |")
    files = summary["files"]
    lines += ["", "## Files", ""]
    if "frequency_energy_plot" in files:
        lines += [f"![frequency–energy]({files['frequency_energy_plot']})", ""]
    lines.append(f"- `{files['mesh']}`: the mesh with its groups; `{files['modes']}`: every family and orbit.")
    for a in files.get("animations", []):
        what = ", ".join(f"`{a[k]}`" for k in ("gif", "mp4", "pvd", "manifold") if k in a)
        phases = ", ".join(f"{t / a['T']:.4f}" for t in a["impact_times"])
        check = a["verification"]
        lines.append(f"- family {a['family']}, {a['ipp']}-ipp orbit T = {a['T']:.8g} s (f = {a['frequency_hz']:.3f} "
                     f"Hz, E = {a['energy_j']:.3e} J, impacts at t/T = "
                     f"{phases}, displacements × {a['scale']:.4g}; event-driven simulation returns to it to "
                     f"{check['return_error']:.1e}{'' if check['ok'] else ' — CHECK FAILED'}): {what}")
        if "gif" in a:
            lines.append(f"\n  ![{a['gif']}]({a['gif']})\n")
    lines += ["", "Timings (s): " + ", ".join(f"{k} {v:.2f}" for k, v in summary["timings_s"].items()), ""]
    return "\n".join(lines)
