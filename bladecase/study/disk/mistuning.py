"""The mistuning stage of a cyclic study (``[mistuning]``): the amplification factor of a mistuned bladed disk
under an engine order, from the study's own tuned sector.

:func:`compute_mistuning` (called by :func:`~bladecase.study.disk.cyclic.compute_cyclic`) builds the reduced-order model
of :mod:`bladecase.reduction.mistuning` from the sector the cyclic stage solved (at the SAFE speed when there is
one): the subset of nominal modes (``model = "snm"``: one mode family of every nodal diameter, the blade's own
stiffness scaled, :func:`~bladecase.reduction.mistuning_fe.blade_stiffness`) or the fundamental mistuning model
(``"fmm"``).  The blade is the sector's cells beyond the rim radius for the parametric sector, the cells with every
node in the group ``[mistuning] blade`` for a mesh file.  Blade ``j`` is forced by engine order ``e`` at its tip —
the blade's node farthest from the engine axis — in the direction in which the family's mode of the forced nodal
diameter moves most there, and its response is read at the same dof.  The samples (random, ``std``/``seed``, or the
one pattern ``deviations``) run through the study's executor, each a
:func:`~bladecase.reduction.mistuning_stats.sample_peak` task; it writes

* ``mistuning.csv`` — one row a sample: ``sample, amplitude, amplification, blade, frequency_hz``;
* ``mistuning.png`` — the histogram of the amplification factor against Whitehead's bound;
* ``summary["mistuning"]`` — the model, the forcing, the percentiles, the largest, the bound ``½(1 + √N)`` and how
  many samples exceed it;
* with ``[mistuning] clearance`` or a ``[casing]``: who rubs first (:mod:`bladecase.reduction.mistuning_rub`, each
  sample a :func:`~bladecase.reduction.mistuning_rub.sample_rub` task through the same executor) — each blade's tip
  excursion along the radius at the tip node (the casing normal) against its clearance as the forcing rises:
  ``mistuning_rub.csv`` (``sample, first_blade, level_n, tuned_ratio, lead``) and ``summary["mistuning"]["rub"]``.
  With a ``[casing]`` each blade's clearance is the casing's at its tip
  (:func:`~bladecase.reduction.mistuning_rub.blade_clearances`: offset, conical or out-of-round, the casing's axis
  the disk's unless given); a ``[mistuning] clearance`` given as well must agree with it (:data:`AGREE`).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ... import log
from ...fe.cyclic import sector_angles
from ...io import save_figure, write_text
from ...reduction.mistuning import MistuningModel, family_band, fmm_model, mistuning_model
from ...reduction.mistuning_fe import blade_stiffness
from ...reduction.mistuning_stats import (
    MistuningStatistics,
    random_mistuning,
    sample_peak,
    whitehead_bound,
)
from ..executor import Executor
from ..schema import Study, StudyError
from .mistuning_contact import compute_contacts, radial_response
from .mistuning_keys import check_deviations

__all__ = ["AGREE", "blade_cells", "compute_mistuning", "excitation_dof", "mistuning_csv", "radial_response",
           "tip_clearances"]

#: A ``[mistuning] clearance`` given with a ``[casing]`` must equal the casing's clearance at every blade's tip to
#: this relative tolerance (the digits a clearance is typed with).
AGREE = 1e-3


def blade_cells(mesh, axis, geometry, group: str | None) -> np.ndarray:
    """The blade's body cells (a boolean mask): beyond ``geometry.rim_radius`` about ``axis`` (the parametric
    sector), else those with every node in the node ``group``.

    >>> import numpy as np
    >>> from bladecase.fe import Mesh
    >>> from bladecase.fe.rotation import RotationAxis
    >>> pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 2]], float)
    >>> mesh = Mesh(pts, {"tetra": np.array([[0, 1, 2, 3], [1, 2, 3, 4]])}, dim=3, groups={"b": np.array([1, 2, 3, 4])})
    >>> blade_cells(mesh, RotationAxis((0, 0, 0), (1, 0, 0)), None, "b").tolist()
    [False, True]
    """
    conn = np.asarray(mesh.cells[mesh.body_type])
    if geometry is not None:
        radius = sector_angles(mesh.points[conn].mean(axis=1), axis)[0]
        mask = radius > geometry.rim_radius
        where = f"beyond the rim radius {geometry.rim_radius:g} m"
    else:
        if group not in mesh.groups:
            raise StudyError(f"[mistuning] blade: the mesh {mesh.source} has no node group {group!r} (groups: "
                             f"{', '.join(sorted(mesh.groups)) or 'none'})")
        inside = np.zeros(len(mesh.points), dtype=bool)
        inside[mesh.group(group)] = True
        mask = inside[conn].all(axis=1)
        where = f"with every node in the group {group!r}"
    if not mask.any() or mask.all():
        raise StudyError(f"[mistuning] blade: {int(mask.sum())} of the sector's {mask.size} cells lie {where}: the "
                         "blade must be part of the sector, not none of it nor all of it")
    return mask


def excitation_dof(model, mesh, axis, cells: np.ndarray, mistuning: MistuningModel, order: int) -> dict:
    """The tip dof that is forced and observed: the blade's node farthest from the axis, in the direction in which
    the family's travelling wave ``order mod N`` moves most there."""
    conn = np.asarray(mesh.cells[mesh.body_type])[cells]
    nodes = np.unique(conn)
    free = np.isin(nodes, model.dofs.node)
    nodes = nodes[free]
    if not nodes.size:
        raise StudyError("[mistuning] blade: every node of the blade is clamped ([fem] clamp): nothing to force")
    radius = sector_angles(mesh.points[nodes], axis)[0]
    node = int(nodes[int(np.argmax(radius))])
    dofs = np.flatnonzero(model.dofs.node == node)
    p = int(np.flatnonzero(mistuning.diameters == order % mistuning.sectors)[0])
    dof = int(dofs[int(np.argmax(np.abs(mistuning.shapes[dofs, p])))])
    return {"node": node, "dof": dof, "direction": "xyz"[int(model.dofs.direction[dof])],
            "position_m": mesh.points[node].tolist(), "radius_m": float(radius.max())}


def mistuning_csv(stats: MistuningStatistics) -> str:
    """``mistuning.csv``: ``sample, amplitude, amplification, blade, frequency_hz``, one row a sample.

    >>> s = MistuningStatistics(np.zeros((2, 3)), np.array([1.0, 1.5]), np.array([0, 2]), np.array([9.0, 9.5]),
    ...                         2.0, 1.37)
    >>> print(mistuning_csv(s).strip())
    sample,amplitude,amplification,blade,frequency_hz
    0,2.0,1.0,0,9.0
    1,3.0,1.5,2,9.5
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["sample", "amplitude", "amplification", "blade", "frequency_hz"])
    for i, (a, b, f) in enumerate(zip(stats.factors, stats.blades, stats.frequencies)):
        w.writerow([i, repr(float(a * stats.tuned)), repr(float(a)), int(b), repr(float(f))])
    return buf.getvalue()


def tip_clearances(study: Study, fe_model, axis, tip: dict, sectors: int) -> tuple[np.ndarray | None, str | None]:
    """``(c, source)``: each blade's tip clearance (m) and where it comes from — ``"casing"`` (the ``[casing]`` at the
    tip ``node`` of every blade, :func:`~bladecase.reduction.mistuning_rub.blade_clearances`, its axis the disk's
    ``axis`` unless the section gives one) or ``"mistuning"`` (``[mistuning] clearance``); ``(None, None)`` without
    either. ``StudyError`` for a blade that touches the casing at rest, or a ``[mistuning] clearance`` that differs
    from the casing's by more than :data:`AGREE`."""
    from ...fe.rotation import RotationAxis
    from ...reduction.casing import Casing
    from ...reduction.mistuning_rub import blade_clearances

    given = study["mistuning"]["clearance"]
    k = study.config.get("casing") or {}
    if k.get("radius") is None and k.get("radii") is None:
        if given is None:
            return None, None
        return np.broadcast_to(np.asarray(given, dtype=float), (sectors,)).copy(), "mistuning"
    own = k.get("axis")
    where = RotationAxis(own["origin"], own["direction"]) if own else axis
    try:
        casing = Casing(where, radius=k["radius"], radii=None if k["radii"] is None else tuple(map(tuple, k["radii"])))
        c = blade_clearances(fe_model.mesh.points[tip["node"]], sectors, axis, casing, k.get("lobes"),
                             k.get("amplitude") or 0.0)
    except ValueError as exc:
        raise StudyError(f"[casing]: the mistuned disk's blade tips (node {tip['node']} of each sector): "
                         f"{exc}") from None
    if given is not None:
        g = np.broadcast_to(np.asarray(given, dtype=float), (sectors,))
        off = np.abs(g - c) > AGREE * c
        if off.any():
            j = int(np.flatnonzero(off)[0])
            raise StudyError(f"[mistuning] clearance: blade {j}'s is {g[j]:.6g} m, but the [casing] puts its tip "
                             f"(node {tip['node']} turned to blade {j}) {c[j]:.6g} m from the casing (blades 0…"
                             f"{sectors - 1}: {', '.join(f'{x:.6g}' for x in c)} m): give one of them, or make them "
                             f"agree within {AGREE:.1%}")
    return c, "casing"


def _model(study: Study, fe_model, sector, cells: np.ndarray, spectrum=None) -> MistuningModel:
    m = study["mistuning"]
    try:
        if m["model"] == "fmm":
            return fmm_model(sector, m["family"], spectrum=spectrum)
        return mistuning_model(sector, blade_stiffness(fe_model, cells), families=[m["family"]], spectrum=spectrum)
    except ValueError as exc:
        if "family" in str(exc):
            raise StudyError(f"[mistuning] family: {exc}") from None
        raise


def _samples(m: dict, sectors: int) -> np.ndarray:
    """``(S, N)``: the given pattern, or the random samples (:func:`random_mistuning`, as the library draws them)."""
    if m["deviations"] is not None:
        check_deviations(m, sectors)
        return np.asarray([m["deviations"]], dtype=float)
    return random_mistuning(sectors, m["samples"], m["std"], m["seed"])


def compute_mistuning(study: Study, staging: Path, files: dict, *, fe_model, mesh, sector, axis, geometry,
                      executor: Executor, progress: bool, spectrum=None) -> dict:
    """The mistuning stage (module docstring), writing into ``staging`` and naming its files in ``files``; returns
    ``summary["mistuning"]``. ``spectrum``: the cyclic stage's modes of ``sector`` (not solved again)."""
    m = study["mistuning"]
    n = sector.sectors
    cells = blade_cells(mesh, axis, geometry, m["blade"])
    model = _model(study, fe_model, sector, cells, spectrum)
    order = m["engine_order"]
    tip = excitation_dof(fe_model, mesh, axis, cells, model, order)
    hz = family_band(model)
    shared = {"model": model, "order": order, "frequencies": hz, "zeta": m["damping"], "force": tip["dof"],
              "response": tip["dof"]}
    tuned, _, tuned_hz = sample_peak(np.zeros(n), **shared)
    if tuned == 0:
        raise StudyError(f"[mistuning] engine_order: engine order {order} does not move the blade's tip dof "
                         f"{tip['dof']} in family {m['family']}: choose another family or engine order")
    deltas = _samples(m, n)
    peaks = executor.map(sample_peak, list(deltas), shared=shared, desc="mistuning samples", progress=progress)
    amp, blades, where = (np.asarray(v) for v in zip(*peaks))
    stats = MistuningStatistics(deltas, amp / tuned, blades.astype(int), where, float(tuned), whitehead_bound(n))
    write_text(staging / "mistuning.csv", mistuning_csv(stats))
    files["mistuning"] = "mistuning.csv"
    if "png" in study["output"]["formats"]:
        from ...post.disk.mistuning_plot import amplification_figure

        save_figure(amplification_figure(stats, bins=max(5, min(40, deltas.shape[0] // 5))),
                    staging / "mistuning.png", dpi=150)
        files["mistuning_figure"] = "mistuning.png"
    section = stats.summary()
    worst = stats.worst
    above = int(np.count_nonzero(stats.factors > stats.bound))
    k = order % n
    section.update({
        "model": model.kind, "family": m["family"], "modes": model.size, "engine_order": order,
        "diameter": min(k, n - k), "damping": m["damping"], "sectors": n,
        "std": m["std"] if m["deviations"] is None else None, "seed": m["seed"] if m["deviations"] is None else None,
        "deviations": m["deviations"], "blade_cells": int(cells.sum()), "cells": int(cells.size), "tip": tip,
        "band_hz": [float(hz[0]), float(hz[-1])], "tuned_amplitude": float(tuned), "tuned_frequency_hz": tuned_hz,
        "above_bound": above, "largest_frequency_hz": float(stats.frequencies[worst]),
        "largest_deviations": stats.deltas[worst].tolist(),
    })
    clearance, source = tip_clearances(study, fe_model, axis, tip, n)
    if clearance is not None:
        section["rub"] = _first_rub(clearance, fe_model, axis, tip, shared, deltas, staging, files, executor,
                                    progress)
        section["rub"]["clearance_from"] = source
    if m["force"] is not None:
        section["contact"] = compute_contacts(m, clearance, fe_model, sector, axis, tip, cells, deltas, hz, staging,
                                              files, executor, progress)
    log.info("mistuning (%s, family %d, engine order %d, ζ = %g): %d sample(s) of %d blades, amplification "
             "median %.4f, largest %.4f (sample %d, blade %d); Whitehead's bound %.4f, %d sample(s) above it",
             model.kind, m["family"], order, m["damping"], deltas.shape[0], n, section["percentiles"]["p50"],
             section["largest"], worst, section["largest_blade"], stats.bound, above)
    if above:
        log.warning("mistuning: %d sample(s) above Whitehead's bound %.4f: the forced family is not isolated or the "
                    "sweep does not resolve the peaks", above, stats.bound)
    return section


def _first_rub(c: np.ndarray, fe_model, axis, tip: dict, shared: dict, deltas: np.ndarray, staging: Path,
               files: dict, executor: Executor, progress: bool) -> dict:
    """Who rubs first in each sample (module docstring) against each blade's clearance ``c`` (m):
    ``mistuning_rub.csv`` and ``summary["mistuning"]["rub"]``."""
    from ...reduction.mistuning_rub import blade_peaks, first_rub, sample_rub

    n = deltas.shape[1]
    kw = {**shared, "response": radial_response(fe_model, axis, tip["node"]), "clearance": c}
    tuned_peaks, _ = blade_peaks(kw["model"], np.zeros(n), kw["order"], kw["frequencies"], zeta=kw["zeta"],
                                 force=kw["force"], response=kw["response"])
    if not tuned_peaks.max() > 0:
        raise StudyError(f"[mistuning] clearance: engine order {kw['order']} does not move the blade tip (node "
                         f"{tip['node']}) along the radius: no blade ever reaches the casing")
    tuned = first_rub(tuned_peaks, c)
    rows = executor.map(sample_rub, list(deltas), shared={**kw, "tuned_level": tuned["level"]},
                        desc="first rub per sample", progress=progress)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["sample", "first_blade", "level_n", "tuned_ratio", "lead"])
    for i, r in enumerate(rows):
        w.writerow([i, r["blade"], repr(r["level"]), repr(r["tuned_ratio"]), repr(r["lead"])])
    write_text(staging / "mistuning_rub.csv", buf.getvalue())
    files["mistuning_rub"] = "mistuning_rub.csv"
    ratio = np.array([r["tuned_ratio"] for r in rows])
    lead = np.array([r["lead"] for r in rows])
    soonest = int(np.argmin(ratio))
    counts = np.bincount([r["blade"] for r in rows], minlength=n)
    uniform = np.ptp(c) <= 1e-9 * c.max()  # (a round casing's clearances differ by roundoff only)
    out = {"clearance_m": float(c.mean()) if uniform else c.tolist(), "tuned_level_n": tuned["level"],
           "tuned_blade": tuned["blade"], "response": "radial at the tip node",
           "tuned_ratio": {"min": float(ratio.min()), "p5": float(np.percentile(ratio, 5)),
                           "p50": float(np.percentile(ratio, 50)), "max": float(ratio.max())},
           "lead": {"p5": float(np.percentile(lead, 5)), "p50": float(np.percentile(lead, 50))},
           "first_blade_counts": counts.tolist(), "soonest_sample": soonest, "soonest_blade": rows[soonest]["blade"],
           "soonest_level_n": rows[soonest]["level"], "soonest_peaks": rows[soonest]["peaks"]}
    log.info("first rub (clearance %s m): the tuned disk rubs at a tip force of %.4g N; mistuned, %.4g (median) to "
             "%.4g times that (sample %d, blade %d first)", out["clearance_m"], tuned["level"],
             out["tuned_ratio"]["p50"], out["tuned_ratio"]["min"], soonest, out["soonest_blade"])
    return out
