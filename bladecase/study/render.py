"""The render stage: each chosen orbit checked by simulation, expanded to every node of the mesh and
handed to the orbit-scope writers of ``[output] formats`` (:mod:`bladecase.post.outputs`)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from .. import log
from ..nsm import Branch
from ..nsm.energy import describe_split, modal_energy_split
from ..nsm.verify import verify
from ..post.grid import fe_grid, grid_index, nodal_field
from ..post.nodal.tip_excursion import tip_excursion
from ..post.nodal.tip_excursion import words as tip_words
from ..post.outputs import FORMATS, OrbitScene
from ..post.plots import is_massless
from ..post.prestress import centrifugal_fields
from ..post.report import engineering_words, orbit_words
from ..progress import progress_bar
from ..reduction import MasslessReducedModel, ReducedModel
from .choose import Choice, choose_orbits, frame_times
from .documents import orbit_stability
from .publish import output_folder, publish, release, staging_dir
from .reference import check_in_reference, log_check, reference_model, study_basis
from .schema import Study
from .stages import period_unit


def orbit_scene(study: Study, reduced: ReducedModel, families: list[Branch], choice: Choice) -> OrbitScene:
    """The chosen orbit at ``[output] frames`` instants, on every node of the FE model (quadratic cells whole); at
    speed, the centrifugal state as constant point data (:func:`~bladecase.post.prestress.centrifugal_fields`)."""
    from ..post import animation

    o = study["output"]
    orbit, model = choice.orbit, reduced.model
    times, impact = frame_times(orbit, o["frames"])
    if hasattr(orbit, "in_contact"):  # the massless model: the casing is drawn in contact during contact phases
        impact = impact | orbit.in_contact(times)
    x, v = orbit.state(times)
    mesh = fe_grid(model)
    u = nodal_field(model, reduced.free_dofs(x))
    v = nodal_field(model, reduced.free_velocities(x, v))  # the massless model's contact dofs move with λ' too
    scale = animation.auto_scale(mesh, u, o["auto_fraction"]) if o["scale"] == "auto" else float(o["scale"])
    what = (f"nonsmooth mode, {orbit.k} contact phase{'' if orbit.k == 1 else 's'} per period" if is_massless(orbit)
            else f"{orbit.k}-ipp nonsmooth mode")
    face_points = face_beyond = None
    contact = reduced.contact
    if contact.nodes:  # each face node against its own clearance, frame by frame (the mean cannot show it)
        d, nu = contact.node_clearances(model)
        face_points = np.array([grid_index(model, k) for k in contact.nodes])
        un = np.einsum("kd,kdf->kf", nu, u[face_points, : model.dim])
        face_beyond = un > d[:, None]
    return OrbitScene(stem=choice.stem, title=f"{study.name}: {what} (family {choice.family})",
                      mesh=mesh, orbit=orbit, times=times, u=u, v=v, impact=impact,
                      contact_node=int(grid_index(model, reduced.contact.node)),
                      normal=reduced.contact.normal_for(model), scale=scale, options=o,
                      branch=families[choice.family], face_points=face_points, face_beyond=face_beyond,
                      point_data=centrifugal_fields(model))


def render(study: Study, reduced: ReducedModel, families: list[Branch], choice: Choice, folder: Path,
           reference: ReducedModel | None = None) -> dict:
    """Check one chosen orbit by simulation (in its own model, and in ``reference`` if given) and write its
    orbit-scope outputs into ``folder``.

    Returns its ``summary.json`` entry: period, energy, impacts, the checks, the files written.
    """
    scene = orbit_scene(study, reduced, families, choice)
    orbit = scene.orbit
    massless = is_massless(orbit)
    check = verify(orbit)
    if massless:  # the simulator counts the contact phases it meets: no impacts in this model
        check = {("contact_phases" if k == "impacts" else k): v for k, v in check.items()}
    entry = {"family": choice.family, "ipp": orbit.k, "T": orbit.T, "frequency_hz": 1 / orbit.T,
             "energy_j": orbit.energy}
    if choice.substitutes:  # [output] orbits asked for periods where no admissible orbit is: the nearest instead
        entry["substitutes_for_T"] = list(choice.substitutes)
    if massless:  # contact phases of finite duration, and the momentum the casing gives in each (∫λ dt)
        entry.update(contact_time=orbit.contact_time, contact_intervals=[list(c) for c in orbit.contact_intervals],
                     contact_momentum_ns=orbit.impulses.tolist())
    else:
        entry.update(impact_times=orbit.impact_times.tolist(), impulses=orbit.impulses.tolist())
    entry.update(scale=scene.scale, frames=int(scene.times.size), verification=check)
    if reference is not None:
        entry["reference_check"] = check_in_reference(orbit, reduced, reference)
        log_check(entry["reference_check"], orbit.k, orbit.T)
    entry.update(_energy_split(orbit, reference))
    excursion = tip_excursion(reduced, orbit)
    if excursion is not None:
        entry["tip_excursion"] = excursion
        entry["tip_excursion"]["words"] = tip_words(excursion, nodes=study["contact"].get("points") == "nodes")
        if excursion["nodes_beyond"]:
            log.warning("orbit T = %.8g s: %s", orbit.T, entry["tip_excursion"]["words"])
    stability = orbit_stability(orbit)
    entry.update(stable=stability["stable"], stability=stability["stability"])
    entry.update(orbit_engineering(reduced, orbit))
    log.info("orbit T = %.8g s: %s", orbit.T, engineering_words(entry, massless))
    if not check["ok"]:
        log.warning("orbit T = %.8g s failed the independent check (simulation from its %s: return error %.2e, "
                    "%d %s for %d): animated anyway, flagged in summary.json", orbit.T,
                    "closing state" if massless else "post-impact state", check["return_error"],
                    check["contact_phases" if massless else "impacts"],
                    "contact phases" if massless else "impacts", orbit.k)
    entry.update(FORMATS.write(study["output"]["formats"], "orbit", scene, folder))
    log.info("animated %s T = %.8g s (f = %.2f Hz, E = %.3g J; simulator return error %.1e)",
             orbit_words(orbit.k, massless), orbit.T, 1 / orbit.T, orbit.energy, check["return_error"])
    return entry


#: Instants per period at which :func:`orbit_engineering` samples an orbit, and per contact phase besides.
ENGINEERING_SAMPLES = 400
PHASE_SAMPLES = 64


def orbit_engineering(reduced: ReducedModel, orbit) -> dict:
    """What the blade and the casing see over one period of ``orbit``, in SI engineering units.

    ``tip_amplitude_mm``: the largest displacement magnitude ``|u|`` over the period of the contact node (every
    node of a face contact) in the expansion to the FE model (:meth:`ReducedModel.free_dofs`), sampled at
    :data:`ENGINEERING_SAMPLES` instants (and :data:`PHASE_SAMPLES` per contact phase), with the node
    (``tip_amplitude_node_id``, its number in the mesh file) and the instant (``tip_amplitude_t_over_T``).
    ``contact_fraction``: the share of the period in contact. Massless model: ``contact_force_n``, the largest
    contact force ``λ`` (N: the force conjugate to the mean normal displacement ``wᵀx``, the total normal force on a
    face) over the contact phases, refined at its peak; with a compliant casing ``casing_penetration_m``, how far
    the contact moves into the casing, ``λ/k``. Newton's law: instantaneous impacts, no force —
    ``contact_force_n`` is ``None``, ``contact_impulse_ns`` the largest impulse (N·s) and ``contact_fraction`` 0.
    """
    from scipy.optimize import minimize_scalar

    T = float(orbit.T)
    out, times, x = _tip_amplitude(reduced, orbit)
    if not is_massless(orbit):
        return out | {"contact_fraction": 0.0, "contact_force_n": None,
                      "contact_impulse_ns": float(np.max(orbit.impulses)) if orbit.impulses.size else 0.0}
    lam = np.asarray(reduced.multiplier(x), dtype=float)
    peak = float(lam.max(initial=0.0))
    if peak > 0:  # refined between the samples next to the largest one
        i = int(np.argmax(lam))
        lo, hi = times[max(i - 1, 0)], times[min(i + 1, times.size - 1)]
        if hi > lo:
            res = minimize_scalar(lambda t: -float(reduced.multiplier(orbit.state([t])[0])[0]), bounds=(lo, hi),
                                  method="bounded", options={"xatol": 1e-12 * T})
            peak = max(peak, -float(res.fun))
    out |= {"contact_fraction": float(orbit.contact_time / T), "contact_force_n": peak}
    casing = float(getattr(orbit.system, "casing", np.inf))
    if np.isfinite(casing):
        out["casing_penetration_m"] = peak / casing
    return out


def _tip_amplitude(reduced: ReducedModel, orbit) -> tuple[dict, np.ndarray, np.ndarray]:
    """:func:`orbit_engineering`'s tip amplitude (with its node and instant), the sampled instants and states."""
    model, contact, T = reduced.model, reduced.contact, float(orbit.T)
    intervals = [tuple(map(float, c)) for c in getattr(orbit, "contact_intervals", [])]
    times = np.unique(np.mod(np.concatenate([np.linspace(0.0, T, ENGINEERING_SAMPLES, endpoint=False)]
                                            + [np.linspace(a, b, PHASE_SAMPLES) for a, b in intervals]), T))
    x, _ = orbit.state(times)
    nodes = list(contact.nodes) or [contact.node]
    dofs = [np.flatnonzero(model.dofs.node == k) for k in nodes]
    u = _rows(reduced, np.concatenate(dofs), x)
    ends = np.cumsum([0] + [d.size for d in dofs])
    size = np.array([np.linalg.norm(u[a:b], axis=0) for a, b in zip(ends[:-1], ends[1:])])
    k, j = np.unravel_index(int(np.argmax(size)), size.shape)
    out = {"tip_amplitude_mm": float(size[k, j] * 1e3), "tip_amplitude_node_id": int(model.mesh.node_ids[nodes[k]]),
           "tip_amplitude_t_over_T": float(times[j] / T)}
    return out, times, x


def tip_amplitude(reduced: ReducedModel, orbit) -> float:
    """The largest displacement magnitude ``|u|`` (m) of a contact node over the period of ``orbit`` (as
    :func:`orbit_engineering` samples it)."""
    return _tip_amplitude(reduced, orbit)[0]["tip_amplitude_mm"] * 1e-3


def _rows(reduced: ReducedModel, rows: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``reduced.free_dofs(x)[rows]`` without expanding every free dof (the contact's few rows of the basis, and
    the massless model's closed-phase correction ``λ·closed_shape`` on them)."""
    kind = type(reduced).free_dofs
    if kind is ReducedModel.free_dofs:
        return np.asarray(reduced.basis[rows] @ x)
    if kind is MasslessReducedModel.free_dofs:
        return np.asarray(reduced.basis[rows] @ x) + np.multiply.outer(reduced.closed_shape[rows],
                                                                       reduced.multiplier(x))
    return reduced.free_dofs(x)[rows]  # another expansion: the whole of it


def _band(reference: ReducedModel | None) -> float | None:
    """Highest linear frequency (Hz) of the reference model: modes above it are beyond what it can check."""
    if reference is None:
        return None
    s = reference.system
    omega = s.open.omega if hasattr(s, "open") else s.spectrum.omega
    return float(omega.max() / (2 * np.pi))


def _energy_split(orbit, reference: ReducedModel | None) -> dict:
    """The orbit's modal energy split and its words (a warning when mesh-scale modes hold most of it)."""
    split = modal_energy_split(orbit)
    words = describe_split(split, 1 / orbit.T, _band(reference))
    if "Doubtful" in words:
        log.info("orbit T = %.8g s: %s", orbit.T, words.replace("**", ""))
    return {"modal_energy": split.to_dict(), "energy_words": words}


def render_all(study: Study, reduced: ReducedModel, families: list[Branch], folder: Path,
               progress: bool = False, reference: ReducedModel | None = None,
               rejected: list | None = None) -> list[dict]:
    """Choose the orbits (:func:`~bladecase.study.choose.choose_orbits`; with a ``reference`` model, only
    orbits that survive there) and render each. ``rejected``, a list, receives the check of every orbit tried
    that did not survive (``T``, ``frequency_hz``, ``ipp`` and :func:`check_in_reference`'s figures)."""
    unit, _ = period_unit(study, reduced.system)
    rejected = [] if rejected is None else rejected

    def survives(orbit) -> bool:
        check = check_in_reference(orbit, reduced, reference)
        if not check["survives"]:
            drift = check["drift"] if np.isfinite(check["drift"]) else None  # None: it started beyond the casing
            rejected.append({"T": float(orbit.T), "frequency_hz": float(1.0 / orbit.T), "ipp": int(orbit.k),
                             **{k: v for k, v in check.items() if k != "reference"}, "drift": drift})
            log.info("orbit T = %.8g s does not survive in the reference model %s: drift %.1e (energy norm), %d "
                     "contact(s) for %d%s", orbit.T, check["reference"], check["drift"], check["contacts"],
                     orbit.k, f" ({check['reason']})" if check.get("reason") else "")
        return check["survives"]

    chosen = choose_orbits(study, families, unit, accept=None if reference is None else survives)
    if rejected:
        log.warning("%d admissible orbit(s) of the %s model were not animated: they do not survive in the "
                    "reference model %s (%d dofs) — artefacts of the reduced model", len(rejected),
                    reduced.method, reference.method, reference.n)
    if not chosen and (study["output"]["animate"] > 0 or study["output"]["orbits"]):
        massless = is_massless(reduced.system)
        log.warning("no admissible orbit to animate%s: widen [search] periods%s%s",
                    " that survives in the reference model" if reference is not None else "",
                    "" if massless else " or add ipp values",
                    "; with Newton's impact law the orbits depend on the reduced model ([contact] model = "
                    "'massless' removes the impact law)" if reference is not None and not massless else "")
    return [render(study, reduced, families, c, folder, reference)
            for c in progress_bar(chosen, "animations", enabled=progress, unit="orbit")]


def animate_families(study: Study, reduced: ReducedModel, families: list[Branch],
                     out: str | os.PathLike | None = None, progress: bool = False) -> list[dict]:
    """The render stage alone (``bladecase animate``): animations and VTK files of the chosen orbits.

    Returns one entry per animated orbit (period, energy, verification, file
    names relative to the output directory); files are published together. With no orbit to animate nothing
    is published: the folder's previous ``animations/`` and ``vtk/`` stay as they were.
    """
    out = output_folder(study, out)
    staging = staging_dir(out, ("animations", "vtk"))
    entries: list[dict] = []
    try:
        o = study["output"]
        reference = (reference_model(reduced.model, reduced.contact, reduced, basis=study_basis(study))
                     if o["reference"] else None)
        entries = render_all(study, reduced, families, staging, progress, reference)
        if entries:
            publish(staging, out, ("animations", "vtk"))
    finally:
        if not entries or os.path.lexists(staging):  # failed, or nothing to publish
            shutil.rmtree(staging, ignore_errors=True)
            release(out)
    return entries
