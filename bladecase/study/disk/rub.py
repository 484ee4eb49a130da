"""The whole disk's rub in a cyclic study (``[rub] speeds`` with an out-of-round ``[casing]`` and a ``[contact]``):
every blade turning inside the casing, each seeing the lobes at its own angle.

The sector's contact (``[contact]``: a face's mean, or every node with ``points = "nodes"``; the massless model; the
clearances from the ``[casing]``) is every blade's own: the reduced disk of
:func:`~bladecase.reduction.disk.disk_model` (``[rub] size`` cyclic modes per nodal diameter, the contacts' residual
flexibility restored; one model for every speed, about the study's speed when ``[rotation]`` gives one). At each
speed of ``[rub] speeds`` (one task per speed through the study's executor) the whole disk is simulated exactly from
rest (:func:`~bladecase.nsm.massless.disk_rub.disk_rub`, with the single blade's settling: ``revolutions``, ``window``,
``max_revolutions``; damping ``ratio`` or ``rayleigh``). It writes ``disk_rub.csv`` (one row per speed and blade:
peak force, penetration, contact share, the dominant nodal diameter), ``disk_rub.png`` and
``summary.json["cyclic"]["rub"]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ... import log
from ...fe.rotation import RotationAxis, to_rad_s
from ...io import rows_csv, save_figure, write_text
from ..schema import Study, StudyError
from ..stages import build_contact

__all__ = ["COLUMNS", "compute_disk_rub"]

#: Columns of ``disk_rub.csv``.
COLUMNS = ("speed", "speed_rad_s", "blade", "peak_force_n", "penetration_m", "contact_share", "dominant_nd",
           "response")


def _point(speed: float, *, disk, lobes: int, amplitude: float, damping, offsets, revolutions: int, window: int,
           max_revolutions: int | None):
    """One speed (module level: an executor ships it to its workers)."""
    from ...nsm.massless.disk_rub import disk_rub

    return disk_rub(disk, speed, lobes, amplitude, damping, offsets=offsets, revolutions=revolutions,
                    window=window, max_revolutions=max_revolutions)


def compute_disk_rub(study: Study, staging: Path, files: dict, *, model, sector, executor,
                     progress: bool = False) -> dict:
    """The stage (module docstring) on the FE ``model`` and its cyclic ``sector``; returns
    ``summary["cyclic"]["rub"]``. ``StudyError`` without a contact, for a contact on a cyclic face, or a speed
    whose simulation fails."""
    from ...nsm.damping import Damping
    from ...reduction.disk import disk_model, massless_sector
    from ..rub.stage import _node_stiffness, max_revolutions, node_angles

    if not study.has_contact:
        raise StudyError("[rub] speeds: the disk's rub needs each blade's contact: add [contact] with its face "
                         "(e.g. face = \"tip\", model = \"massless\") and the out-of-round [casing]")
    r, k = study["rub"], study["casing"]
    start = time.perf_counter()
    contact = build_contact(study, model)
    nodes = study["contact"].get("points") == "nodes"
    if nodes:  # each node its share of the casing's stiffness (by tributary area), as the single blade's rub
        casing = _node_stiffness(study, model, contact)
    else:
        casing = contact.casing
    try:
        ms, W, gap = massless_sector(model, sector, contact, nodes=nodes)
        disk = disk_model(ms, W, gap, count=r["size"], casing=None if np.all(np.isinf(casing)) else casing)
    except ValueError as exc:
        raise StudyError(f"[contact]: {exc}") from None
    axis = RotationAxis(k["axis"]["origin"], k["axis"]["direction"])
    offsets = node_angles(model, contact.nodes, axis) if nodes else None
    damping = (Damping(alpha=r["rayleigh"][0], beta=r["rayleigh"][1]) if r["rayleigh"] is not None
               else Damping(zeta=r["ratio"]))
    unit = r["speed_unit"]
    speeds = [float(to_rad_s(w, unit)) for w in r["speeds"]]
    cap = max_revolutions(r)
    log.info("disk rub: %d blades × %d contact%s, %d modes, %d speeds, a casing of %d lobes of %.4g mm (forcing "
             "nodal diameter %d)", disk.sectors, disk.per_blade, "s" if disk.per_blade > 1 else "", disk.system.n,
             len(speeds), k["lobes"], k["amplitude"] * 1e3, min(k["lobes"] % disk.sectors,
                                                                disk.sectors - k["lobes"] % disk.sectors))
    shared = dict(disk=disk, lobes=k["lobes"], amplitude=k["amplitude"], damping=damping, offsets=offsets,
                  revolutions=r["revolutions"], window=r["window"], max_revolutions=cap)
    try:
        points = executor.map(_point, speeds, shared=shared, desc="disk rub speeds", progress=progress)
    except ValueError as exc:
        raise StudyError(f"[rub] speeds: {exc}") from None
    rows = []
    for given, p in zip(r["speeds"], points):
        for row in p.rows():
            rows.append({"speed": float(given), **row})
        log.info("disk rub at %.6g %s: %s, peak force %.4g–%.4g N, contact share %.3g, nodal diameter %d (%.0f %% "
                 "of the tips' oscillation; the lobes force %d)", given, unit, p.response, p.peak_force.min(),
                 p.peak_force.max(), p.contact_share.max(), p.dominant, 100 * p.nd_share[p.dominant], p.expected)
    write_text(staging / "disk_rub.csv", rows_csv(rows, COLUMNS))
    files["disk_rub"] = "disk_rub.csv"
    section = {"sectors": disk.sectors, "contacts": disk.system.m, "modes": disk.system.n, "lobes": k["lobes"],
               "amplitude_m": k["amplitude"], "speed_unit": unit, "expected_nd": points[0].expected,
               "speeds": [{"speed": float(g), **p.as_dict()} for g, p in zip(r["speeds"], points)],
               "seconds": time.perf_counter() - start}
    if "png" in study["output"]["formats"]:
        from ...post.disk.rub_plot import disk_rub_figure

        save_figure(disk_rub_figure(section, title=f"{study.name}: the disk's rub, {disk.sectors} blades"),
                    staging / "disk_rub.png", dpi=150)
        files["disk_rub_plot"] = "disk_rub.png"
    return section
