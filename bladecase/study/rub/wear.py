"""The ``[rub]`` stage with a ``[casing] abradable`` coating: the wear coupled to the blade's dynamics at each
speed (:func:`bladecase.nsm.massless.wear_rub.wear_rub`), its summary, ``wear.csv`` (per speed and revolution),
``wear_profile.csv`` (each speed's final profile), ``wear.png`` and the worn casing as a ring surface
(``wear.vtu``).

The coating lines the casing over the axial band the tip nodes span (its ``width``), at the casing's radius; its
cells are counted from the contact nodes' mean radial direction about the axis, the angle the blade turns through
(as the nodes' angles of the rub)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import log
from ...io import csv_cell, save_figure, write_text
from ...nsm.massless.wear import Abradable
from ...nsm.massless.wear_lobes import lobe_words
from ..keys import StudyError

__all__ = ["WEAR_COLUMNS", "coating_of", "log_wear", "wear_figures", "wear_section", "write_wear"]

#: Columns of ``wear.csv``: name → what it holds.
WEAR_COLUMNS = {
    "speed": "the speed, in [rub] speed_unit",
    "revolution": "the revolution (from rest), after which the profile is read",
    "removed_volume_mm3": "the coating's volume removed so far, added passage by passage (mm³)",
    "missing_volume_mm3": "the worn profile's missing area × the band's width (mm³): equals removed_volume_mm3",
    "max_depth_um": "the deepest wear of the profile (µm)",
    "lobe_depth_um": "the profile's depth from its shallowest to its deepest cell (µm)",
    "lobes": "the number of lobes of the profile (its strongest circumferential harmonic; 0: unworn)",
    "tip_normal_displacement_mm": "the peak outward normal displacement over the contact nodes in the revolution (mm)",
    "max_pressure_mpa": "the peak contact pressure on the coating in the revolution (MPa)",
    "casing_input_j": "the work of the out-of-round casing on the blade over the revolution (J)",
    "friction_work_j": "the work of friction on the vibration over the revolution (J; negative: it dissipates)",
    "damping_j": "the energy the structural damping dissipates over the revolution (J)",
    "removal_work_j": "the work of removing coating (yield force × depth removed in flight) over the revolution (J)",
    "surface_steps_j": "the stored energy's jumps where the worn profile steps under a touching node (J)",
    "stored_change_j": "the change of the stored energy over the revolution (J)",
    "balance_residual": "the relative residual of stored change = casing + friction − damping − removal + steps",
}

#: ``wear.csv``'s energy columns → the balance's terms (:class:`~bladecase.nsm.massless.coating_energy.CoatingEnergy`).
ENERGY_TERMS = {"casing_input_j": "casing", "friction_work_j": "friction", "damping_j": "damping",
                "removal_work_j": "plastic", "surface_steps_j": "steps", "stored_change_j": "stored_change",
                "balance_residual": "relative"}


def _frame(study, model, nodes) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(origin, a, e1, e2, s)``: the casing's axis, the nodes' mean radial direction (angle 0), the third
    direction, and each node's station along the axis (m)."""
    k = study["casing"]["axis"]
    a = np.zeros(3)
    a[: len(k["direction"])] = k["direction"]
    a /= np.linalg.norm(a)
    o = np.zeros(3)
    o[: len(k["origin"])] = k["origin"]
    P = np.zeros((len(nodes), 3))
    P[:, : model.dim] = np.asarray(model.mesh.points, dtype=float)[list(nodes), : model.dim]
    x = P - o
    radial = x - np.outer(x @ a, a)
    e1 = radial.mean(axis=0)
    e1 /= np.linalg.norm(e1)
    return o, a, e1, np.cross(a, e1), x @ a


def coating_of(study, model, contact) -> Abradable:
    """The study's ``[casing] abradable`` as an :class:`~bladecase.nsm.massless.wear.Abradable` over the band the
    contact nodes span along the axis, at the casing's radius."""
    ab, k = study["casing"]["abradable"], study["casing"]
    s = _frame(study, model, contact.nodes)[4]
    width = float(np.ptp(s))
    if not width > 0:
        raise StudyError("[casing] abradable: the contact nodes span no width along the casing's axis: the coating's "
                         "removed volume needs the band the tip rubs")
    radius = k["radius"] if k.get("radius") is not None else float(np.mean([r for _, r in k["radii"]]))
    try:
        return Abradable(ab["thickness"], ab["yield"], ab["stiffness"], ab["cells"], radius, width)
    except ValueError as exc:
        raise StudyError(f"[casing] {exc}") from None


#: The summary's words for each coupling of the wear to the flight.
COUPLING_WORDS = {
    "staggered": "each revolution is flown with the profile worn by the revolutions before as its clearance; within a "
                 "revolution the coating is elastic, its removal taken at the revolution's end",
    "in_flight": "each revolution is flown with the profile worn by the revolutions before as its clearance; the "
                 "coating yields during the flight: a node pressing it at its yield pressure removes it as it goes"}


def wear_figures(w) -> dict:
    """One speed's wear (:class:`~bladecase.nsm.massless.wear_rub.WearRub`) as plain numbers."""
    c = w.profile.coating
    depths = w.depths
    missing = [float(c.annulus(d).sum() * c.width) for d in depths]
    return {"removed_m3": w.removed.tolist(), "missing_m3": missing, "max_depth_m": depths.max(axis=1).tolist(),
            "lobe_depth_m": np.ptp(depths, axis=1).tolist(), "lobes": w.lobes.tolist(),
            "peak_displacement_m": w.peak_displacement.tolist(), "peak_pressure_pa": w.peak_pressure.tolist(),
            "vibration_ratio": w.vibration_ratio, "depth_m": w.profile.depth.tolist(),
            "history_m": depths.tolist(), "worn_through": bool(w.profile.worn_through), "phases": w.phases,
            "lobe_check": None if w.check is None else w.check.as_dict(), "coupling": w.coupling,
            "energy": None if w.energy is None else [{c: float(getattr(e, t)) for c, t in ENERGY_TERMS.items()}
                                                     for e in w.energy]}


def wear_section(study, coating: Abradable, rows: list[dict], points: list[dict]) -> dict:
    """The summary's ``rub.wear``: the coating, per speed the final lobes and depth, the removed volume against the
    profile's missing volume, the response's vibration frequency over the rotation's, the held-out check of the
    lobes worn over the last revolutions that wore the coating against it (``lobe_check``:
    :func:`~bladecase.nsm.massless.wear_lobes.lobe_check`, as a dict); the speed of most wear."""
    per = []
    for row, p in zip(rows, points):
        w = p["wear"]
        removed, missing = w["removed_m3"][-1], w["missing_m3"][-1]
        per.append({"speed": row["speed"], "lobes": w["lobes"][-1], "max_depth_um": 1e6 * w["max_depth_m"][-1],
                    "lobe_depth_um": 1e6 * w["lobe_depth_m"][-1], "removed_mm3": 1e9 * removed,
                    "missing_mm3": 1e9 * missing,
                    "volume_mismatch": abs(removed - missing) / max(missing, np.finfo(float).tiny),
                    "vibration_ratio": w["vibration_ratio"], "expected_lobes": int(round(w["vibration_ratio"])),
                    "worn_through": w["worn_through"], "revolutions": len(w["lobes"]),
                    "peak_pressure_mpa": 1e-6 * max(w["peak_pressure_pa"]),
                    "lobe_check": w.get("lobe_check"),
                    "energy": (w.get("energy") or [None])[-1],
                    "worst_balance_residual": max((abs(e["balance_residual"]) for e in w.get("energy") or []),
                                                  default=None)})
    top = max(range(len(per)), key=lambda i: per[i]["removed_mm3"]) if per else None
    residuals = [r["worst_balance_residual"] for r in per if r["worst_balance_residual"] is not None]
    return {"worst_balance_residual": max(residuals) if residuals else None,
            "coating": {"thickness_m": coating.thickness, "yield_pa": coating.yield_pressure,
                        "stiffness_pa_per_m": coating.stiffness, "cells": coating.cells, "radius_m": coating.radius,
                        "width_m": coating.width, "yield_depth_m": coating.yield_depth},
            "speeds": per, "most_wear": None if top is None else per[top]["speed"],
            "coupling": COUPLING_WORDS[next((p["wear"].get("coupling", "staggered") for p in points if "wear" in p),
                                              "in_flight")]}


def log_wear(section: dict, unit: str) -> None:
    """Per speed, the wear in the log."""
    for w in (section.get("wear") or {}).get("speeds", []):
        log.info("rub: at %.6g %s the coating is worn to %.4g µm in %d lobes after %d revolutions (%.4g mm³ removed; "
                 "the tip vibrates at %.3g × the rotation frequency)", w["speed"], unit, w["max_depth_um"], w["lobes"],
                 w["revolutions"], w["removed_mm3"], w["vibration_ratio"])
        e = w.get("energy")
        if e is not None:
            log.info("rub: at %.6g %s the last wearing revolution's energy: casing %.4g J, friction %.4g J, damping "
                     "%.4g J, coating removed %.4g J, profile steps %.4g J, stored change %.4g J (balance to %.1e; "
                     "worst revolution %.1e)", w["speed"], unit, e["casing_input_j"], e["friction_work_j"],
                     e["damping_j"], e["removal_work_j"], e["surface_steps_j"], e["stored_change_j"],
                     e["balance_residual"], w["worst_balance_residual"])
        c = w.get("lobe_check")
        if c and c.get("last"):
            log.info("rub: at %.6g %s, over revolutions %d to %d (the last that wore the coating): %s", w["speed"],
                     unit, c["last"] - c["window"] + 1, c["last"], lobe_words(c))
        elif c:
            log.info("rub: at %.6g %s: %s", w["speed"], unit, lobe_words(c))



def write_wear(folder: Path, study, model, contact, section: dict, points: list[dict], figures: bool,
               vtu: bool, title: str | None) -> dict:
    """``wear.csv``, ``wear_profile.csv``, ``wear.png`` (``figures``) and ``wear.vtu`` (``vtu``) into ``folder``."""
    wear = section["wear"]
    lines = [",".join(WEAR_COLUMNS)]
    profile_lines = ["speed,angle_deg,depth_um"]
    for row, p in zip(section["rows"], points):
        w = p["wear"]
        for k in range(len(w["lobes"])):
            cells = {"speed": row["speed"], "revolution": k + 1, "removed_volume_mm3": 1e9 * w["removed_m3"][k],
                     "missing_volume_mm3": 1e9 * w["missing_m3"][k], "max_depth_um": 1e6 * w["max_depth_m"][k],
                     "lobe_depth_um": 1e6 * w["lobe_depth_m"][k], "lobes": w["lobes"][k],
                     "tip_normal_displacement_mm": 1e3 * w["peak_displacement_m"][k],
                     "max_pressure_mpa": 1e-6 * w["peak_pressure_pa"][k],
                     **(w["energy"][k] if w.get("energy") else dict.fromkeys(ENERGY_TERMS))}
            lines.append(",".join(csv_cell(cells[c]) for c in WEAR_COLUMNS))
        step = 360.0 / len(w["depth_m"])
        for i, d in enumerate(w["depth_m"]):
            profile_lines.append(f"{row['speed']:.9g},{(i + 0.5) * step:.9g},{d * 1e6:.9g}")
    write_text(folder / "wear.csv", "\n".join(lines) + "\n")
    write_text(folder / "wear_profile.csv", "\n".join(profile_lines) + "\n")
    files = {"wear_csv": "wear.csv", "wear_profile_csv": "wear_profile.csv"}
    top = next(i for i, r in enumerate(wear["speeds"]) if r["speed"] == wear["most_wear"])
    if figures:
        from ...post.rub.wear_plot import wear_plot

        fig = wear_plot(section, points, title=f"{title}: wear of the abradable coating" if title else None)
        save_figure(fig, folder / "wear.png")
        files["wear_figure"] = "wear.png"
    if vtu:
        files["wear_vtu"] = _write_ring(folder / "wear.vtu", study, model, contact, wear, points[top]["wear"])
    return files


def _write_ring(path: Path, study, model, contact, wear: dict, w: dict) -> str:
    """The worn casing at the speed of most wear: the coating's surface as a ring of quadrilaterals over the tip's
    axial band (each cell's centre angle at both edges of the band, at its worn radius), with the worn depth (mm),
    the depth after each revolution and the cell's index as point data."""
    import meshio

    from ...io import atomic_path

    o, a, e1, e2, s = _frame(study, model, contact.nodes)
    c = wear["coating"]
    depth = np.asarray(w["depth_m"])
    n = depth.size
    theta = (np.arange(n) + 0.5) * 2 * np.pi / n
    radial = np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2
    ring = []
    for station in (s.min(), s.max()):
        ring.append(o + station * a + (c["radius_m"] + depth)[:, None] * radial)
    points = np.vstack(ring)
    i = np.arange(n)
    quads = np.c_[i, (i + 1) % n, n + (i + 1) % n, n + i]
    data = {"worn_depth_mm": np.r_[depth, depth] * 1e3, "cell": np.r_[i, i].astype(np.int32)}
    for k, d in enumerate(w["history_m"]):
        data[f"worn_depth_rev{k + 1:03d}_mm"] = np.r_[d, d] * 1e3
    out = meshio.Mesh(points, [("quad", quads)], point_data=data)
    with atomic_path(path) as tmp:
        meshio.write(tmp, out, file_format="vtu")
    return path.name
