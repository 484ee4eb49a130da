"""A study run end to end: mesh → FE model → contact → reduced model(s) → nonsmooth modes → results.

:func:`run` writes into a hidden staging folder inside the output directory and publishes the results
only when everything succeeded (:mod:`~bladecase.study.publish`).  It changes no global state: its
messages go to the ``bladecase`` logger and into ``run.log`` from its own transcript; progress bars are
plain tqdm, absent with ``progress=False``.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import log
from ..fe import stiffness_factor
from ..io import write_json, write_text
from ..post.comparison.compare import ModelResult, fe_reference
from ..post.disk.cyclic_report import cyclic_report, cyclic_verdict
from ..post.outputs import FORMATS, PlotScene
from ..post.prestress import add_to_mesh_file
from ..post.report import report
from ..post.rotation.modes_report import modes_verdict
from ..post.verdict import verdict
from ..progress import progress_counter
from .comparison.stage import FE_MODES, compare_models, summary_section
from .disk.cyclic import compute_linear
from .disk.cyclic_keys import cyclic_requested
from .documents import contact_summary, families_document, family_summary, model_summary, reduced_summary, write_mesh
from .executor import Executor, make_executor
from .forcing.stage import forced_response, forced_scene
from .publish import RUN_RESULTS, check_inputs, output_folder, publish, release, staged_names, staging_dir
from .reference import reference_model, study_basis
from .render import orbit_engineering, render_all
from .rotation.modes_run import campbell_with_figure
from .rotation.stage import operating_point
from .schema import Study, load_study
from .stages import (
    build_contact,
    build_mesh,
    build_model,
    build_reduced,
    casing_sweep_values,
    check_plausibility,
    contact_group,
    period_unit,
    search,
)


@dataclass
class RunResult:
    """What :func:`run` produced: the output directory and the summary written there."""

    directory: Path
    summary: dict = field(repr=False)
    families: list = field(repr=False, default_factory=list)
    #: Every model of the run by name (the main one first, then ``compare`` and the methods × sizes grid):
    #: :class:`~bladecase.post.comparison.compare.ModelResult` with the reduced model, its families and timings.
    models: dict = field(repr=False, default_factory=dict)

    @property
    def fe_model(self):
        """The FE model every reduced model came from (``None`` for a result without models)."""
        return next((m.reduced.model for m in self.models.values()), None)

    @property
    def comparison(self) -> dict | None:
        """The comparison table as a dict of columns (column name → list, one entry per row: the FE model, then
        every model), or ``None`` when the run compared nothing."""
        section = self.summary.get("comparison")
        if not section:
            return None
        rows = section["rows"]
        return {key: [r.get(key) for r in rows] for key in rows[0]}


class _Stages:
    """Times each stage and advances the run's progress bar."""

    def __init__(self, progress: bool, total: int = 6):
        self.timings: dict[str, float] = {}
        self.bar = progress_counter(total, "bladecase run", enabled=progress, unit="stage")

    def __call__(self, name: str) -> _Stages:
        self.name = name
        self.bar.set_postfix_str(name)
        self.timings[name] = time.perf_counter()
        return self

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self.timings[self.name] = round(time.perf_counter() - self.timings[self.name], 3)
            self.bar.update()


def run(study: Study | str | os.PathLike, out: str | os.PathLike | None = None, progress: bool = True,
        executor: Executor | None = None) -> RunResult:
    """Run the whole study (a :class:`Study`, or the path of a study file); write every result into the output
    directory.

    Files (in ``out``, default ``[output] directory``): ``summary.json``,
    ``report.md``, ``run.log``, ``modes.json`` (every family, every orbit),
    ``frequency_energy.png``, ``mesh.vtu`` (the mesh with its groups),
    ``animations/<stem>.gif`` / ``.mp4``, ``vtk/<stem>.pvd`` with
    ``vtk/<stem>/`` (one ``.vtu`` per frame) and ``vtk/<stem>_manifold.vtu``.
    ``executor`` runs the searches of the models (default: :class:`SerialExecutor`).

    Examples
    --------
    A small plate study end to end (under a second: a coarse gmsh plate, 4 modes, no pictures):

    >>> import tempfile
    >>> from bladecase.study.schema import loads
    >>> study = loads('''
    ... study = {name = "strip"}
    ... geometry = {kind = "plate", span = 0.1, chord = 0.02, contact_point = [0.005, 0.1], size = 0.005}
    ... material = {preset = "steel"}
    ... fem = {order = 1, thickness = 0.002}
    ... contact = {clearance = 1e-4}
    ... reduction = {method = "modal", size = 4}
    ... search = {ipp = [1], periods = [0.5, 0.9999], scan = 2}
    ... output = {animate = 1, frames = 4, formats = [], reference = false}
    ... ''')
    >>> with tempfile.TemporaryDirectory() as out:
    ...     result = run(study, out, progress=False)
    ...     written = sorted(p.name for p in Path(out).iterdir())
    >>> written   # and the signed manifest of what the run wrote (bladecase.study.manifest)
    ['.bladecase-manifest.json', 'mesh.vtu', 'modes.json', 'report.md', 'run.log', 'summary.json']
    >>> model = result.summary["model"]
    >>> model["dim"], model["material"]["name"], round(model["total_mass_kg"], 6)   # 7850 × 0.1 × 0.02 × 0.002
    (2, 'steel', 0.0314)
    >>> result.summary["contact"]["position"], round(model["linear_frequencies_hz"][0], -1)
    ([0.005, 0.1, 0.0], 1650.0)
    >>> [(a["ipp"], a["frames"], a["verification"]["ok"]) for a in result.summary["files"]["animations"]]
    [(1, 4, True)]
    """
    if isinstance(study, (str, os.PathLike)):
        study = load_study(study)
    elif not isinstance(study, Study):
        raise ValueError(f"study must be a Study (bladecase.load_study) or the path of a study file, got "
                         f"{type(study).__name__} {study!r:.60}")
    out = output_folder(study, out)
    t_start = time.perf_counter()
    check_inputs(out, [study.mesh_path()] if not study.parametric else [])
    if study.source and Path(study.source).is_file():
        check_inputs(out, [study.source])
    staging = staging_dir(out)
    stages = _Stages(progress, total=3 if not study.has_contact else 6 + (study["forcing"]["amplitude"] is not None)
                     + bool(study.config.get("rotation") and study["rotation"]["speeds"])
                     + bool((study.config.get("rub") or {}).get("speeds")) + bool(casing_sweep_values(study))
                     + (study["contact"].get("points") == "nodes") + bool(study["convergence"]["meshes"]))
    x = study["execution"]
    own = None if executor is not None else make_executor(x["executor"], x["workers"], x["scheduler"])
    try:
        with log.transcript() as lines:
            log.info("study %s (%s) → %s", study.name, study.source, out)
            # no contact: linear modes; a disk (cyclic): its own stage, with its contact when it has one
            compute = _compute if study.has_contact and not cyclic_requested(study.config) else compute_linear
            summary, families, models = compute(study, staging, stages, progress, executor or own)
            summary["timings_s"] = dict(stages.timings, total=round(time.perf_counter() - t_start, 3))
            log.info("results in %s (%.1f s)", out, summary["timings_s"]["total"])
        write_text(staging / "run.log", "\n".join(lines) + "\n")
        summary["outputs"] = sorted(set(staged_names(staging)) | {"summary.json", "report.md"})
        summary["verdict"] = (cyclic_verdict(summary) if summary.get("cyclic") else
                              verdict(summary, staging / "modes.json") if study.has_contact else modes_verdict(summary))
        write_json(staging / "summary.json", summary)
        write_text(staging / "report.md", cyclic_report(summary) if summary.get("cyclic") else report(summary))
        publish(staging, out, RUN_RESULTS, whole=True)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        release(out)
        raise
    finally:
        stages.bar.close()
        if own is not None:
            own.close()
    return RunResult(directory=out, summary=summary, families=families, models=models)


def _compute(study: Study, staging: Path, stage: _Stages, progress: bool, executor: Executor
             ) -> tuple[dict, list, dict]:
    """Every stage of :func:`run`, writing into ``staging``; returns the summary (without timings) and families."""
    o = study["output"]
    files: dict[str, object] = {}
    with stage("mesh"):
        mesh = build_mesh(study)
        write_mesh(mesh, staging, files, "gmsh" if study.parametric else mesh.source)
    with stage("assemble"):
        model = build_model(study, mesh)
        factor = stiffness_factor(model)
        contact = build_contact(study, model)
        if (study.config.get("rub") or {}).get("speeds"):  # the rub's contact selection, before minutes of work
            from .rub.stage import check_rub_contact

            check_rub_contact(study, model, contact)
        rest_model, cold_contact = model, contact
        model, contact, factor, rotation = operating_point(study, model, contact, factor)
        if rotation is not None:
            rotation["axis"] = study["rotation"]["axis"]
            add_to_mesh_file(staging / "mesh.vtu", mesh, model)  # the centrifugal state at the mesh's nodes
            cold_contact = dataclasses.replace(cold_contact, gap=rotation["clearance_cold_m"])
        count = min(study["fem"]["frequencies"], model.n_dofs - 1)
        fe = fe_reference(model, contact, min(max(count, FE_MODES), model.n_dofs - 1), factor=factor)
        f_fe = fe.frequencies[:count]
        log.info("FE model: %s; first frequencies %s Hz", model, ", ".join(f"{x:.1f}" for x in f_fe[:6]))
        check_plausibility(study, rest_model, float(f_fe[0]) if rotation is None else None)
    with stage("reduce"):
        build_s = []
        count = 1 + len(study["reduction"]["compare"]) + bool(o["reference"])
        models_bar = progress_counter(count, "reduced models", enabled=progress and count > 1, unit="model")
        t0 = time.perf_counter()
        reduced = build_reduced(study, model, contact, factor=factor)
        build_s.append(time.perf_counter() - t0)
        models_bar.update()
        compares = []
        for c in study["reduction"]["compare"]:
            t0 = time.perf_counter()
            compares.append(build_reduced(study, model, contact, c["method"], c.get("size"), factor=factor))
            build_s.append(time.perf_counter() - t0)
            models_bar.update()
        log.info("contact: %s at %s mm, normal %s, clearance %g mm", _contact_words(study, contact, mesh),
                 np.round(mesh.points[contact.node] * 1e3, 4).tolist(), np.round(contact.normal_for(model), 6).tolist(),
                 contact.gap * 1e3)
        log.info("reduced model: %s", reduced)
        log.info("contact stiffness: %s", _stiffness_words(reduced, fe))
        if (soft := _soft_casing(reduced, fe)) is not None:
            log.warning("%s", soft)
        t0 = time.perf_counter()
        reference = (reference_model(model, contact, reduced, factor, study_basis(study)) if o["reference"]
                     else None)
        build_s.append(time.perf_counter() - t0)
        models_bar.close()
        if reference is not None:
            log.info("reference model for the orbits' check: %s, %d dofs (%s)", reference.method, reference.n,
                     "the reduced model extended by the Krylov sequence of its factorisation"
                     if reference.method.endswith("+krylov") else "from its own eigen-solve")
        # a comparison study compares the reference of the verification too, through the same search
        known = {(r.method, r.size) for r in [reduced, *compares]}
        extra = compares and reference is not None and (reference.method, reference.size) not in known
        searched = [reduced, *compares, *([reference] if extra else [])]
    with stage("search"):
        unit, _ = period_unit(study, reduced.system)
        timed = executor.map(_search_model, [(f"{r.method} {r.size} ({r.n} dofs)", r.system) for r in searched],
                             shared={"study": study, "unit": unit, "progress": progress and executor.name == "serial"},
                             desc="models", progress=progress)
        # a parallel executor sends the families back without their system (light records): attach it again
        found = [[b if b.system is not None else b.bind(r.system) for b in fams]
                 for r, (fams, _) in zip(searched, timed)]
        found, validity = _small_displacements(study, model, searched, found)
        families, compare_families = found[0], found[1:1 + len(compares)]
        names = [None] * (1 + len(compares)) + ([f"{reference.method}-{reference.size} (reference)"] if extra else [])
        models = [ModelResult(r, fams, b, t, name) for r, fams, b, (_, t), name in
                  zip(searched, found, build_s, timed, names)]
        document = families_document(families, reduced.system)
        if compares:  # every model's families are kept
            document["compare"] = [dict(model=m.name, **families_document(m.branches, m.reduced.system))
                                   for m in models[1:]]
        write_json(staging / "modes.json", document)
        files["modes"] = "modes.json"
    with stage("plots"):
        scene = PlotScene(study.name, [(f"{r.method} ({r.n} dofs)", fams) for r, fams in
                                       zip([reduced], found)], f_fe)
        files.update(FORMATS.write(o["formats"], "run", scene, staging))
        comparison = None
        if compares:
            comparison = compare_models(fe, models, staging, title=study.name, figures="png" in o["formats"],
                                        fractions=study["reduction"]["compare_periods"])
            files["comparison"] = comparison["csv"]
            files["comparison_figures"] = comparison["figures"]
    campbell = None
    if study.config.get("rotation") and study["rotation"]["speeds"]:
        with stage("campbell"):
            campbell = campbell_with_figure(study, rest_model, cold_contact, executor, progress, staging, files)
    with stage("render"):
        rejected: list = []
        files["animations"] = render_all(study, reduced, families, staging, progress, reference, rejected)
    forcing = None
    if study["forcing"]["amplitude"] is not None:
        with stage("forcing"):
            forcing = forced_response(reduced, families, study["forcing"], folder=staging,
                                      figures="png" in o["formats"], title=study.name, executor=executor,
                                      progress=progress)
            orbits = forcing.pop("orbits")
            files["forced"] = dict(forcing["files"])
            files["forced_animations"] = _animate_forced(study, reduced, forcing, orbits, staging)
    nodal = None
    if study["contact"].get("points") == "nodes":
        with stage("nodes"):
            from .nodal.stage import nodal_stage

            anims = files["animations"]
            nodal = nodal_stage(study, model, contact, families, reduced, factor=factor, folder=staging,
                                figures="png" in o["formats"], title=study.name,
                                target_energy=anims[0]["energy_j"] if anims else None)
            files.update({f"nodal_{k}": v for k, v in nodal.pop("files").items()})
            files["nodal_animations"] = nodal.pop("animations", [])
    sweep = None
    if casing_sweep_values(study):
        with stage("casing"):
            sweep = _casing_sweep(study, model, contact, factor, unit, staging, "png" in o["formats"], progress,
                                  (reduced.system.kc, families))
            files.update(sweep.pop("files"))
    rub = None
    if (study.config.get("rub") or {}).get("speeds"):
        with stage("rub"):
            from .rub.stage import rub_stage

            rub = rub_stage(study, rest_model, cold_contact, families=families, executor=executor, progress=progress,
                            folder=staging, figures="png" in o["formats"], title=study.name)
            files["rub"] = rub.pop("files")
    convergence = None
    if study["convergence"]["meshes"]:
        with stage("convergence"):
            convergence = _convergence(study, model, reduced, families, float(f_fe[0]), files["animations"],
                                       executor, progress)
    files["log"] = "run.log"
    from .. import __version__

    summary = {
        "study": study.name, "source": study.source, "bladecase_version": __version__,
        "model": model_summary(mesh, model, f_fe, "gmsh (parametric [geometry])" if study.parametric
                               else str(study.mesh_path())),
        "contact": contact_summary(contact, model, reduced, fe, face=contact_group(study) if contact.nodes else None),
        "rotation": rotation,
        "campbell": campbell,
        "reduction": reduced_summary(reduced, f_fe, fe),
        "reference": None if reference is None else dict(reduced_summary(reference, f_fe), rejected=rejected),
        "compare": [dict(reduced_summary(r, f_fe), families=[family_summary(f) for f in fams])
                    for r, fams in zip(compares, compare_families)],
        "search": {**study["search"], "period_unit_s": unit},
        "families": [family_summary(f, functools.partial(orbit_engineering, reduced)) for f in families],
        "forcing": forcing,
        "rub": rub,
        "casing_sweep": sweep,
        "nodal_modes": nodal,
        "comparison": None if comparison is None else summary_section(comparison),
        "convergence": convergence,
        "validity": validity,
        "files": files,
    }
    return summary, families, {m.name: m for m in models}


def _small_displacements(study: Study, model, searched: list, found: list) -> tuple[list, dict]:
    """Every model's families with their arcs cut at ``[search] amplitude_limit`` × the span
    (:mod:`~bladecase.study.validity`) and, with ``[material] yield_strength``, where an orbit's peak von Mises
    stress exceeds it (:mod:`~bladecase.study.stress_limit`), and the summary's ``validity`` section (the main
    model's cuts)."""
    from .render import tip_amplitude
    from .validity import blade_span, cut_arcs

    span = blade_span(model)
    limit = study["search"]["amplitude_limit"] * span
    out, main_cuts = [], []
    for n, (r, fams) in enumerate(zip(searched, found)):
        cut, cuts = cut_arcs(fams, [functools.partial(tip_amplitude, r)] * len(fams), limit)
        out.append(cut)
        if n == 0:
            main_cuts = cuts
    for c in main_cuts:
        at = (f"its last orbit within it, T = {c['T_cut']:.8g} s ({1 / c['T_cut']:.6g} Hz)" if c["T_cut"] else
              "none of its orbits is within it")
        log.warning("family %d: an admissible arc is cut at the small-displacement limit: the tip moves %.4g mm at "
                    "T = %.8g s, more than %.4g mm (%g %% of the %.4g mm span); %s", c["family"],
                    c["tip_amplitude_beyond"] * 1e3, c["T_beyond"], limit * 1e3,
                    100 * study["search"]["amplitude_limit"], span * 1e3, at)
    validity = {"span_m": span, "amplitude_limit": study["search"]["amplitude_limit"], "limit_m": limit,
                "cuts": main_cuts}
    yield_strength = study["material"].get("yield_strength")
    if yield_strength is not None:  # the elastic limit: arcs cut where an orbit's peak von Mises exceeds the yield
        from .stress_limit import stress_cuts

        out, stress = stress_cuts(searched, out, float(yield_strength))
        validity.update(yield_strength_pa=float(yield_strength), stress_cuts=stress)
    return out, validity


def _convergence(study: Study, model, reduced, families, f1: float, animations: list, executor, progress: bool
                 ) -> dict:
    """The mesh-convergence stage: the orbit's figures read at ``[convergence] ratio``, else at the first animated
    orbit's ``T/T₁``, else at the middle of the widest admissible arc (:mod:`~bladecase.study.convergence.stage`)."""
    from .convergence.stage import convergence_stage, mesh_figures

    T1 = 2 * np.pi / float(reduced.system.spectrum.contact_modes[0][0])
    ratio, ipp = study["convergence"]["ratio"], study["search"]["ipp"][0]
    if animations:
        ipp = animations[0]["ipp"]
        ratio = animations[0]["T"] / T1 if ratio is None else ratio
    elif ratio is None:
        arcs = [(f.k, a) for f in families for a in f.arcs]
        if arcs:
            ipp, a = max(arcs, key=lambda x: (x[1].T_hi - x[1].T_lo) / x[1].T_hi)
            ratio = 0.5 * (a.T_lo + a.T_hi) / T1
    main = mesh_figures(model, reduced, families, f1, ratio, ipp)
    return convergence_stage(study, main, ratio, ipp, executor, progress)


def _casing_sweep(study: Study, model, contact, factor, unit: float, staging: Path, figures: bool,
                  progress: bool, main: tuple) -> dict:
    """The nonsmooth modes searched with each casing stiffness of ``[contact] casing_stiffness = [...]`` (the first
    is the run's own; :mod:`bladecase.study.casing.stage`): the rows and their spread, ``casing.png``."""
    from ..io import save_figure
    from ..post.casing.report import casing_figure
    from .casing.stage import casing_sweep

    values = casing_sweep_values(study)
    out = casing_sweep(study, model, contact, values, factor=factor, unit=unit, progress=progress, first=main)
    branches = out.pop("branches")
    out["files"] = {}
    if figures:
        title = f"{study.name}: the nonsmooth mode for each casing stiffness"
        save_figure(casing_figure(values, branches, title=title), staging / "casing.png")
        out["files"]["casing_plot"] = "casing.png"
    return out


def _contact_words(study: Study, contact, mesh) -> str:
    """The contact as the log names it: ``node 6``, or for a face ``face 'tip' of 26 nodes (area-weighted mean of
    their normal displacements), centre node 6``."""
    if not contact.nodes:
        return f"node {mesh.node_id(contact.node)}"
    weights = "area-weighted" if contact.weights else "equal-weight"
    return (f"face '{contact_group(study)}' of {len(contact.nodes)} nodes ({weights} mean of their normal "
            f"displacements), centre node {mesh.node_id(contact.node)}")


def _stiffness_words(reduced, fe) -> str:
    """The contact's own stiffness ``k_c`` and its series value with the casing (massless model), and the blade's
    static stiffness at the contact ``1/(wᵀK⁻¹w)`` (the whole FE model)."""
    s = reduced.system
    blade = f"the blade's static stiffness at the contact 1/(wᵀK⁻¹w) = {1 / fe.static_compliance:.4g} N/m"
    if getattr(s, "contact_model", "newton") != "massless":
        return f"{blade} (Newton's impact law: rigid casing)"
    own = f"k_c = {s.kc_structure:.4g} N/m (the contact dofs with the interior held, 1/(w_cᵀK_cc⁻¹w_c))"
    if np.isinf(s.casing):
        return f"{own}, rigid casing; {blade}"
    return f"{own}; casing {s.casing:.4g} N/m in series: k_s = {s.kc:.4g} N/m; {blade}"


def _soft_casing(reduced, fe) -> str | None:
    """The sentence of a compliant casing far softer than the blade's static stiffness at the contact
    (:func:`~bladecase.post.casing.words.weak_casing_words`), else ``None``."""
    from ..post.casing.words import weak_casing_words

    s = reduced.system
    if getattr(s, "contact_model", "newton") != "massless" or np.isinf(s.casing) or not fe.static_compliance > 0:
        return None
    return weak_casing_words(float(s.kc), 1.0 / float(fe.static_compliance), casing=float(s.casing))


def _animate_forced(study: Study, reduced, section: dict, orbits: list, folder: Path) -> list[dict]:
    """The ``[forcing] animate`` highest-energy periodic steady states with impacts, through the orbit writers."""
    c = section["points"]
    picks = [i for i, lab in enumerate(c["label"])
             if "/" in lab and not lab.startswith("0/") and orbits[i] is not None]
    picks = sorted(picks, key=lambda i: -c["energy_j"][i])[: study["forcing"]["animate"]]
    out = []
    for n, i in enumerate(picks):
        stem = f"forced_{n + 1}_{c['label'][i].replace('/', '-')}"
        scene = forced_scene(study, reduced, orbits[i], stem)
        entry = {"index": i, "sweep": c["sweep"][i], "frequency_hz": c["frequency_hz"][i], "label": c["label"][i],
                 "energy_j": c["energy_j"][i], "return_error": c["return_error"][i]}
        entry.update(FORMATS.write(study["output"]["formats"], "orbit", scene, folder))
        log.info("animated forced steady state %s at %.6g Hz (%s sweep)", entry["label"], entry["frequency_hz"],
                 entry["sweep"])
        out.append(entry)
    return out


def _search_model(item: tuple[str, object], *, study: Study, unit: float, progress: bool) -> tuple[list, float]:
    """One model's search, timed; ``item = (label, system)``.  Module-level so that an executor can ship it to
    other processes (the study and the period unit go once per worker, as ``shared``)."""
    label, system = item
    return _timed(search, study, system, progress=progress, unit=unit, label=label)


def _timed(fn, *args, **kwargs):
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t0
