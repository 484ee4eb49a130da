"""A study without a contact (``[rotation] speeds`` and no ``[contact]``): the linear modes at the operating speed
and the Campbell diagram — frequencies per speed followed by shape, engine orders, ``campbell.png`` — through the
same staging and all-or-nothing publication as every run (:func:`~bladecase.study.run.run` calls
:func:`compute_modes` for it).  Without a contact there are no nonsmooth modes; the report says so and how to add
one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import log
from ...fe import natural_frequencies, stiffness_factor
from ..documents import model_summary, write_mesh
from ..executor import Executor
from ..schema import Study
from ..stages import build_mesh, build_model, check_plausibility
from .stage import campbell_stage, operating_point

__all__ = ["campbell_with_figure", "compute_modes"]


def compute_modes(study: Study, staging: Path, stage, progress: bool, executor: Executor) -> tuple[dict, list, dict]:
    """The stages of a run without a contact (mesh, assemble, campbell), writing into ``staging``; returns the
    summary (without timings), no families and no models, as the run's own ``_compute``.

    >>> import tempfile
    >>> from bladecase.study import run
    >>> from bladecase.study.schema import loads
    >>> study = loads('''
    ... geometry = {kind = "plate", span = 0.1, chord = 0.02, contact_point = [0.005, 0.1], size = 0.01}
    ... fem = {order = 1, thickness = 0.002}
    ... rotation = {speeds = [0, 300], speed_unit = "rad/s", axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}}
    ... output = {formats = []}
    ... ''')
    >>> study.has_contact
    False
    >>> with tempfile.TemporaryDirectory() as out:
    ...     s = run(study, out, progress=False).summary
    >>> s["contact"], s["families"], s["campbell"]["speeds"], s["campbell"]["speed_unit"]
    (None, [], [0.0, 300.0], 'rad/s')
    >>> s["verdict"]["found"].split(":")[0]
    'No nonsmooth modes'
    """
    files: dict[str, object] = {}
    with stage("mesh"):
        mesh = build_mesh(study)
        write_mesh(mesh, staging, files, "gmsh" if study.parametric else mesh.source)
    with stage("assemble"):
        rest = build_model(study, mesh)
        model, _, factor, rotation = operating_point(study, rest, None, stiffness_factor(rest))
        rotation["axis"] = study["rotation"]["axis"]
        count = min(study["fem"]["frequencies"], model.n_dofs - 1)
        f_fe = np.asarray(natural_frequencies(model, count, factor=factor))
        log.info("FE model: %s; first frequencies %s Hz (at the operating speed)", model,
                 ", ".join(f"{x:.1f}" for x in f_fe[:6]))
        check_plausibility(study, rest)
    with stage("campbell"):
        campbell = campbell_with_figure(study, rest, None, executor, progress, staging, files)
    log.info("no [contact]: the linear modes and the Campbell diagram only, no nonsmooth modes; add a [contact] "
             "section (clearance, and where the blade touches) to search them")
    files["log"] = "run.log"
    from ... import __version__

    summary = {
        "study": study.name, "source": study.source, "bladecase_version": __version__,
        "model": model_summary(mesh, model, f_fe, "gmsh (parametric [geometry])" if study.parametric
                               else str(study.mesh_path())),
        "contact": None, "rotation": rotation, "campbell": campbell, "reduction": None, "reference": None,
        "compare": [], "search": None, "families": [], "forcing": None, "rub": None, "casing_sweep": None,
        "nodal_modes": None, "comparison": None, "convergence": None, "validity": None, "files": files,
    }
    return summary, [], {}


def campbell_with_figure(study: Study, model, contact, executor: Executor, progress: bool, staging: Path,
                         files: dict) -> dict:
    """The Campbell stage (:func:`~bladecase.study.rotation.stage.campbell_stage`; ``contact=None``: no bands): the
    diagram's summary section, and ``campbell.png`` when pictures are asked for."""
    diagram, section = campbell_stage(study, model, contact, executor, progress)
    if "png" in study["output"]["formats"]:
        from ...io import save_figure
        from ...post.rotation.campbell import campbell_figure

        w = diagram.speeds
        bands: dict[int, tuple] = {}
        for s, band in enumerate(section["bands"]):
            if band is not None:
                lo, hi = bands.setdefault(band["mode"], (w, np.full(w.size, np.nan), np.full(w.size, np.nan)))[1:]
                lo[s], hi[s] = band["low_hz"], band["high_hz"]
        save_figure(campbell_figure(diagram, bands, title=f"{study.name}: Campbell diagram",
                                    speed_unit=study["rotation"]["speed_unit"]), staging / "campbell.png", dpi=150)
        files["campbell"] = "campbell.png"
    return section
