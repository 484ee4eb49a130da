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
from ..nsm.floquet import floquet
from ..nsm.verify import verify
from ..post.grid import fe_grid, grid_index, nodal_field
from ..post.outputs import FORMATS, OrbitScene
from ..post.tip_excursion import tip_excursion
from ..post.tip_excursion import words as tip_words
from ..progress import progress_bar
from ..reduction import ReducedModel
from .choose import Choice, choose_orbits, frame_times
from .publish import output_folder, publish, release, staging_dir
from .reference import check_in_reference, log_check, reference_model
from .schema import Study
from .stages import period_unit


def orbit_scene(study: Study, reduced: ReducedModel, families: list[Branch], choice: Choice) -> OrbitScene:
    """The chosen orbit at ``[output] frames`` instants, on every node of the FE model (quadratic cells whole)."""
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
    return OrbitScene(stem=choice.stem, title=f"{study.name}: {orbit.k}-ipp nonsmooth mode (family {choice.family})",
                      mesh=mesh, orbit=orbit, times=times, u=u, v=v, impact=impact,
                      contact_node=int(grid_index(model, reduced.contact.node)),
                      normal=reduced.contact.normal_for(model), scale=scale, options=o,
                      branch=families[choice.family])


def render(study: Study, reduced: ReducedModel, families: list[Branch], choice: Choice, folder: Path,
           reference: ReducedModel | None = None) -> dict:
    """Check one chosen orbit by simulation (in its own model, and in ``reference`` if given) and write its
    orbit-scope outputs into ``folder``.

    Returns its ``summary.json`` entry: period, energy, impacts, the checks, the files written.
    """
    scene = orbit_scene(study, reduced, families, choice)
    orbit = scene.orbit
    check = verify(orbit)
    entry = {"family": choice.family, "ipp": orbit.k, "T": orbit.T, "frequency_hz": 1 / orbit.T,
             "energy_j": orbit.energy, "impact_times": orbit.impact_times.tolist(),
             "impulses": orbit.impulses.tolist(), "scale": scene.scale, "frames": int(scene.times.size),
             "verification": check}
    if hasattr(orbit, "contact_intervals"):  # the massless model: contact phases of finite duration
        entry["contact_time"] = orbit.contact_time
        entry["contact_intervals"] = [list(c) for c in orbit.contact_intervals]
    if reference is not None:
        entry["reference_check"] = check_in_reference(orbit, reduced, reference)
        log_check(entry["reference_check"], orbit.k, orbit.T)
    entry.update(_energy_split(orbit, reference))
    excursion = tip_excursion(reduced, orbit)
    if excursion is not None:
        entry["tip_excursion"] = excursion
        entry["tip_excursion"]["words"] = tip_words(excursion)
        if excursion["nodes_beyond"]:
            log.warning("orbit T = %.8g s: %s", orbit.T, entry["tip_excursion"]["words"])
    try:
        entry["stability"] = floquet(orbit).verdict
    except ValueError as exc:  # e.g. a grazing impact: no verdict, said so
        entry["stability"] = f"no verdict ({exc})"
    if not check["ok"]:
        log.warning("orbit T = %.8g s failed the independent check (simulation from its post-impact state: "
                    "return error %.2e, %d impacts for %d): animated anyway, flagged in summary.json", orbit.T,
                    check["return_error"], check["impacts"], orbit.k)
    entry.update(FORMATS.write(study["output"]["formats"], "orbit", scene, folder))
    log.info("animated %d-ipp orbit T = %.8g s (f = %.2f Hz, E = %.3g J; simulator return error %.1e)", orbit.k,
             orbit.T, 1 / orbit.T, orbit.energy, check["return_error"])
    return entry


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
               progress: bool = False, reference: ReducedModel | None = None) -> list[dict]:
    """Choose the orbits (:func:`~bladecase.study.choose.choose_orbits`; with a ``reference`` model, only
    orbits that survive there) and render each."""
    unit, _ = period_unit(study, reduced.system)
    rejected: list = []

    def survives(orbit) -> bool:
        ok = check_in_reference(orbit, reduced, reference)["survives"]
        if not ok:
            rejected.append(orbit)
        return ok

    chosen = choose_orbits(study, families, unit, accept=None if reference is None else survives)
    if rejected:
        log.warning("%d admissible orbit(s) of the %s model were not animated: they do not survive in the "
                    "reference model %s (%d dofs) — artefacts of the reduced model", len(rejected),
                    reduced.method, reference.method, reference.n)
    if not chosen and (study["output"]["animate"] > 0 or study["output"]["orbits"]):
        log.warning("no admissible orbit to animate%s: widen [search] periods or add ipp values%s",
                    " that survives in the reference model" if reference is not None else "",
                    "; with Newton's impact law the orbits depend on the reduced model ([contact] model = "
                    "'massless' removes the impact law)" if reference is not None else "")
    return [render(study, reduced, families, c, folder, reference)
            for c in progress_bar(chosen, "animations", enabled=progress, unit="orbit")]


def animate_families(study: Study, reduced: ReducedModel, families: list[Branch],
                     out: str | os.PathLike | None = None, progress: bool = False) -> list[dict]:
    """The render stage alone (``bladecase animate``): animations and VTK files of the chosen orbits.

    Returns one entry per animated orbit (period, energy, verification, file
    names relative to the output directory); files are published together.
    """
    out = output_folder(study, out)
    staging = staging_dir(out, ("animations", "vtk"))
    try:
        reference = reference_model(reduced.model, reduced.contact, reduced) if study["output"]["reference"] else None
        entries = render_all(study, reduced, families, staging, progress, reference)
        publish(staging, out, ("animations", "vtk"))
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        release(out)
        raise
    return entries
