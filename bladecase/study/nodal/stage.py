"""``[contact] points = "nodes"``: the nonsmooth mode with every node of the contact face a contact of its own,
beside the face-mean mode of the same study.

The face-mean contact (the study's main model) sees the tip through one averaged constraint: its mean meets the
clearance while the tip's corners may run far past it. With ``points = "nodes"`` the same blade is reduced with one
massless contact per face node (:func:`bladecase.reduction.nodes.nodal_model`, the residual correction, ``[reduction]
size`` modes) and its nonsmooth mode is followed from the first node's grazing
(:func:`bladecase.nsm.massless.nodal_modes.nodal_family`): each orbit's frequency, energy, the nodes that touch,
the contact pressure (each node's force over its tributary area; the largest over the nodes and the period), the
total contact force (the sum over the nodes, its peak over the period), the loaded area (the area of the nodes in
contact at the instant of that peak, and the largest over the period) and where the load sits along the chord
(:func:`bladecase.reduction.nodes.contact_load`), the contact fraction and casing yield, its Floquet verdict — a
node's own force falls like its area as the tip mesh is refined, so it is no figure of the mode; with ``[output]
reference``, up to
:data:`REFERENCE_CHECKS` orbits, evenly spread, re-simulated for one period in the nodal model's Krylov extension
(four times its dofs, :func:`bladecase.reduction.nodes.nodal_extension`). The family is cut at the small-displacement
limit as the face mean's arcs are (:mod:`~bladecase.study.validity`, ``[search] amplitude_limit`` × the span): at its
first orbit on which a contact node moves farther than that (:func:`node_amplitude`), its figures stop at the orbit
before, and ``summary.json["nodal_modes"]["validity"]`` and the report say where and why. Outputs:
``nodal_modes.csv`` (one row per orbit), ``nodal_modes.png`` (frequency–energy of both models, and the largest
penetration over the face's nodes against energy), ``summary.json["nodal_modes"]``, a section of the report.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import log
from ...io import csv_cell, save_figure, write_text
from ...nsm.massless.nodal_modes import nodal_family
from ...reduction.nodes import contact_pressure, nodal_extension, nodal_model
from ..reference import REFERENCE_FACTOR, check_nodal_in_reference

__all__ = ["node_amplitude", "nodal_stage", "orbit_load"]

COLUMNS = ("frequency_hz", "period_s", "energy_j", "nodes_touching", "touching_nodes", "max_pressure_mpa",
           "total_force_n", "loaded_area_mm2", "peak_loaded_area_mm2", "load_centre", "load_location",
           "max_contact_fraction", "max_penetration_mm", "max_tip_mm", "stable", "residual", "reference_drift",
           "on_backbone")


def orbit_load(nodal, orbit) -> dict:
    """The casing's load on the face over one orbit of the every-node model ``nodal``: the largest contact pressure
    over the nodes and the period (MPa), the peak total force (N), the area in contact at that instant and the
    largest over the period (mm²), and where the load sits then along the chord (the force-weighted centroid,
    0 leading edge – 1 trailing edge, and its third in words: :func:`bladecase.reduction.nodes.contact_load`)."""
    at = nodal.contact_load(orbit.forces(orbit.total_force_time)[:, 0])
    peak = contact_pressure(orbit.peak_force, nodal.areas)
    return {"max_pressure_mpa": float(np.nanmax(peak)) * 1e-6 if np.isfinite(peak).any() else 0.0,
            "total_force_n": float(orbit.total_force), "loaded_area_mm2": at["loaded_area_m2"] * 1e6,
            "peak_loaded_area_mm2": orbit.loaded_area(nodal.areas) * 1e6,
            "load_centre": at["centre"], "load_location": at["location"]}


#: Instants per period at which :func:`node_amplitude` samples the nodes' swing away from the casing.
AMPLITUDE_SAMPLES = 64


def node_amplitude(nodal, orbit, samples: int = AMPLITUDE_SAMPLES) -> float:
    """The largest normal displacement ``|u_j|`` of a contact node over one orbit of the every-node model ``nodal``
    (m): towards the casing its exact peak (the clearance plus the casing's yield, ``NodalOrbit.max_tip``), away from
    it ``u = Wᵀx − H_s λ`` sampled at ``samples`` instants of the period — the tip amplitude of the small-displacement
    limit (:mod:`~bladecase.study.validity`).

    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> from bladecase.nsm.massless import NodalSystem, nodal_family
    >>> s = NodalSystem(np.eye(1), 4.0 * np.eye(1), np.ones((1, 1)), np.zeros((1, 1)), gap=[1.0], casing=[1e6])
    >>> o = nodal_family(s, 0, freq_ratio=1.01).orbits[0]      # grazing: the linear mode just touching, amplitude 1
    >>> round(node_amplitude(SimpleNamespace(system=s), o), 9), round(o.max_tip, 9)
    (1.0, 1.0)
    """
    s = nodal.system
    t = np.linspace(0.0, orbit.T, samples, endpoint=False)
    x, _ = orbit.state(t)
    u = s.W.T @ x - s.flexibility @ s.forces(x)
    return float(max(orbit.max_tip, np.abs(u).max()))


def _small_displacements(study, model, nodal, fam):
    """The family cut at its first orbit beyond ``[search] amplitude_limit`` × the span, and the section's
    ``validity`` record (``cut``: where, how far the continuation went on; None when the family stays within)."""
    from ..validity import blade_span, cut_family, first_beyond

    span = blade_span(model)
    share = study["search"]["amplitude_limit"]
    limit = share * span
    record = {"span_m": span, "amplitude_limit": share, "limit_m": limit, "cut": None}
    k, amps = first_beyond(fam.orbits, lambda o: node_amplitude(nodal, o), limit)
    if k is None:
        return fam, record
    beyond, last = fam.orbits[k], (fam.orbits[k - 1] if k else None)
    top = max(fam.orbits[k:], key=lambda o: o.energy)
    cut = {"index": k, "frequency_beyond_hz": float(beyond.frequency), "energy_beyond_j": float(beyond.energy),
           "tip_amplitude_beyond_mm": amps[k] * 1e3,
           "frequency_cut_hz": None if last is None else float(last.frequency),
           "energy_cut_j": None if last is None else float(last.energy),
           "tip_amplitude_cut_mm": None if last is None else amps[k - 1] * 1e3,
           "orbits_beyond": len(fam.orbits) - k, "continuation_top_energy_j": float(top.energy),
           "continuation_top_yield_mm": float(np.max(top.penetration)) * 1e3, "continuation_stop": fam.stop}
    record["cut"] = cut
    stop = (f"cut at the small-displacement limit: at {beyond.frequency:.6g} Hz ({beyond.energy:.4g} J) a contact node "
            f"moves {amps[k] * 1e3:.4g} mm, more than {limit * 1e3:.4g} mm ({100 * share:g} % of the {span * 1e3:.4g} "
            "mm span, [search] amplitude_limit)")
    end = {"kind": "amplitude_limit", "frequency_hz": cut["frequency_cut_hz"], "energy_j": cut["energy_cut_j"],
           "limit_mm": limit * 1e3, "span_mm": span * 1e3, "amplitude_limit": share, **cut}
    went = ("the continuation stopped there: nothing beyond the limit is computed" if cut["orbits_beyond"] <= 1 else
            f"the continuation went on to {top.energy:.3g} J, a casing yield of "
            f"{cut['continuation_top_yield_mm']:.3g} mm: not reported")
    log.warning("every face node a contact: the family is %s; its figures stop at %s (%s)", stop,
                "its first orbit" if last is None else f"{last.frequency:.6g} Hz ({last.energy:.4g} J)", went)
    return cut_family(fam, k, stop, end), record


def _face_penetration(reduced, contact, model, family) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The face-mean model's admissible orbits expanded to the face's nodes: each orbit's energy, the largest
    distance a node runs past its own clearance (m; the face mean cannot say it, the nodes do), its frequency."""
    N = contact.node_normal_map(model)
    d, _ = contact.node_clearances(model)
    energies, beyond, freqs = [], [], []
    ok = np.asarray(family.admissible, dtype=bool)
    for o, good in zip(family.orbits, ok):
        if o is None or not good:
            continue
        t = np.linspace(0.0, o.T, 96, endpoint=False)
        x, _ = o.state(t)
        u = N @ reduced.free_dofs(x)
        energies.append(o.energy)
        freqs.append(1.0 / o.T)
        beyond.append(float(np.max(u - d[:, None])))
    return np.array(energies), np.array(beyond), np.array(freqs)


#: Orbits of the family checked in the reference model (evenly spread, both ends included).
REFERENCE_CHECKS = 5


def _reference_checks(study, nodal, orbits, reference) -> dict | None:
    """Up to :data:`REFERENCE_CHECKS` orbits checked in the nodal model's Krylov extension ``reference``
    (``REFERENCE_FACTOR`` × its dofs; :func:`~bladecase.study.reference.check_nodal_in_reference`), when
    ``[output] reference``."""
    if reference is None or not orbits:
        return None
    picked = np.unique(np.linspace(0, len(orbits) - 1, min(REFERENCE_CHECKS, len(orbits))).round().astype(int))
    drifts, survived, name = {}, [], f"{reference.method} ({reference.n} dofs)"
    for n in picked:
        check = check_nodal_in_reference(orbits[n], nodal, reference)
        if check["survives"] is None:
            continue
        drifts[int(n)] = check["drift"]
        survived.append(check["survives"])
        if not check["survives"]:
            log.warning("every face node a contact: the orbit at %.6g Hz does NOT survive in the reference model %s: "
                        "drift %.1e (energy norm) in one period", orbits[n].frequency, name, check["drift"])
    worst = max(drifts.values(), default=None)
    log.info("every face node a contact: %d of %d orbits checked survive in the reference model %s (drift up to "
             "%s)", sum(survived), len(survived), name, "—" if worst is None else f"{worst:.1e}")
    return {"model": name, "checked": len(survived), "survived": int(sum(survived)), "max_drift": worst,
            "drifts": drifts}


def _face_top_energy(families) -> float | None:
    """The face mean's highest admissible energy: how far the every-node family is followed (``None``: no arc)."""
    tops = [float(np.max(f.energy[a.start:a.stop + 1][f.admissible[a.start:a.stop + 1]])) for f in families
            for a in f.arcs if f.admissible[a.start:a.stop + 1].any()]
    return max(tops) if tops else None


def _log_casing(nodal) -> None:
    """What casing each node gets: the face's stiffness shared by tributary area is a stiffness per unit area."""
    k = np.asarray(nodal.system.casing, dtype=float)
    if not np.isfinite(k).all() or not (nodal.areas > 0).any():
        return
    has = nodal.areas > 0
    per_area = k[has] / nodal.areas[has]
    log.info("every face node a contact: the casing's %.4g N/m shared by the nodes' tributary areas (the face's "
             "%.4g mm²) is %.4g N/m³; each node gets %.4g to %.4g N/m", k.sum(), nodal.areas.sum() * 1e6,
             float(np.median(per_area)), k.min(), k.max())


def _row(nodal, o) -> dict:
    """An orbit's figures (a row of ``nodal_modes.csv`` but its reference drift)."""
    pen = np.asarray(o.penetration)
    return {"frequency_hz": float(o.frequency), "period_s": float(o.T), "energy_j": float(o.energy),
            "nodes_touching": int(len(o.touching_nodes)),
            "touching_nodes": " ".join(str(n) for n in o.touching_nodes),
            **orbit_load(nodal, o),
            "max_contact_fraction": float(np.max(o.contact_fraction)),
            "max_penetration_mm": float(np.max(pen)) * 1e3 if np.isfinite(pen).all() else 0.0,
            "max_tip_mm": float(o.max_tip) * 1e3, "stable": bool(o.stable()), "residual": float(o.residual)}


def nodal_stage(study, model, contact, families, reduced, *, factor=None, folder: str | Path | None = None,
                figures: bool = True, title: str | None = None, target_energy: float | None = None) -> dict:
    """The nonsmooth mode with one contact per face node of ``contact`` on ``model`` (module docstring), beside
    the study's face-mean ``families`` on ``reduced``; writes ``nodal_modes.csv`` (and ``nodal_modes.png``) into
    ``folder`` and, with ``[output] formats``, animates the family's orbit nearest in energy to ``target_energy``
    (the face mean's animated orbit's; :func:`~bladecase.study.nodal.render.animate_nodal`); returns the summary
    section (its animations under ``"animations"``)."""
    size = study["reduction"]["size"] or 8
    nodal = nodal_model(model, contact, size, factor=factor, residual=True)
    _log_casing(nodal)
    top = _face_top_energy(families)
    cap = {"energy_max": top} if top is not None else {"freq_ratio": 1.0 / study["search"]["periods"][0]}
    from ..validity import blade_span

    limit = study["search"]["amplitude_limit"] * blade_span(model)  # the small-displacement limit: nothing beyond

    def beyond(orbit):
        return "beyond the small-displacement limit" if node_amplitude(nodal, orbit) > limit else None

    fam = nodal_family(nodal.system, 0, through_resonances=True, stop_when=beyond, **cap)  # to the face mean's energy
    fam, validity = _small_displacements(study, model, nodal, fam)
    if study["material"].get("yield_strength") is not None:  # the elastic limit (study/stress_limit.py)
        from ..stress_limit import cut_nodal_family

        fam, validity["stress_cut"] = cut_nodal_family(fam, nodal, float(study["material"]["yield_strength"]))
        validity["yield_strength_pa"] = float(study["material"]["yield_strength"])
    orbits = fam.orbits
    reference = (nodal_extension(nodal, REFERENCE_FACTOR * nodal.n, factor) if study["output"]["reference"]
                 and orbits else None)
    checks = _reference_checks(study, nodal, orbits, reference)
    rows = [dict(_row(nodal, o), reference_drift=(checks["drifts"].get(n) if checks else None), on_backbone=bool(on))
            for n, (o, on) in enumerate(zip(orbits, fam.on_backbone))]
    back = [r for r in rows if r["on_backbone"]] or rows
    stable = [r["stable"] for r in rows]
    section = {
        "size": size, "contact_nodes": nodal.system.m, "reduced_dofs": nodal.system.n,
        "face_area_mm2": float(nodal.areas.sum()) * 1e6,
        "orbits": len(rows), "stop": fam.stop, "end": fam.end, "tongues": [dict(t) for t in fam.tongues],
        "frequency_range_hz": [back[0]["frequency_hz"], max(r["frequency_hz"] for r in back)] if rows else None,
        "energy_range_j": [back[0]["energy_j"], max(r["energy_j"] for r in back)] if rows else None,
        "stable_fraction": float(np.mean(stable)) if stable else None,
        "first_touch_nodes": next((r["touching_nodes"].split() for r in rows if r["touching_nodes"]), []),
        "most_nodes_touching": max((r["nodes_touching"] for r in rows), default=0),
        "reference": None if checks is None else {k: v for k, v in checks.items() if k != "drifts"},
        "validity": validity, "rows": rows,
    }
    face = [f for f in families if f.arcs]
    if face:
        e, b, fr = _face_penetration(reduced, contact, model, face[0])
        section["face_mean"] = {"energy_j": e.tolist(), "node_beyond_clearance_mm": (b * 1e3).tolist(),
                                "frequency_hz": fr.tolist(),
                                "frequency_range_hz": [float(np.min(face[0].frequencies[face[0].admissible])),
                                                       float(np.max(face[0].frequencies[face[0].admissible]))]}
    log.info("every face node a contact (%d nodes, %d dofs): %d orbits from %.5g Hz (nodes %s touch first) to "
             "%.5g Hz; %s", nodal.system.m, nodal.system.n, len(rows), rows[0]["frequency_hz"] if rows else np.nan,
             ", ".join(section["first_touch_nodes"]), section["frequency_range_hz"][1] if rows else np.nan, fam.stop)
    if folder is not None:
        folder = Path(folder)
        from .render import animate_nodal

        section["animations"] = animate_nodal(study, nodal, fam, folder, target_energy, reference,
                                              lambda o: _row(nodal, o),
                                              extend=lambda count: nodal_extension(nodal, count, factor)) \
            if orbits else []
        lines = [",".join(COLUMNS)] + [",".join(csv_cell(r[c]) for c in COLUMNS) for r in rows]
        write_text(folder / "nodal_modes.csv", "\n".join(lines) + "\n")
        section["files"] = {"csv": "nodal_modes.csv"}
        if figures and rows:
            save_figure(_figure(section, title), folder / "nodal_modes.png")
            section["files"]["figure"] = "nodal_modes.png"
    return section


def _figure(section: dict, title: str | None):
    from ...post.plots import new_figure

    fig = new_figure(figsize=(10.0, 4.2), layout="constrained")
    a, b = fig.subplots(1, 2)
    rows = section["rows"]
    f = [r["frequency_hz"] for r in rows]
    e = [r["energy_j"] for r in rows]
    pen = [r["max_penetration_mm"] for r in rows]
    a.semilogy(f, e, "-o", ms=3, color="C3", label=f"every face node a contact ({section['contact_nodes']})")
    b.plot(e, pen, "-o", ms=3, color="C3", label="every node a contact: the casing's largest yield")
    fm = section.get("face_mean")
    if fm:
        b.plot(fm["energy_j"], fm["node_beyond_clearance_mm"], "-", color="C0",
               label="face mean: the farthest node past its clearance")
        order = np.argsort(fm["frequency_hz"])
        a.semilogy(np.asarray(fm["frequency_hz"])[order], np.asarray(fm["energy_j"])[order], "-", color="C0",
                   label="face mean (one constraint): admissible orbits")
    a.set_xlabel("frequency 1/T (Hz)")
    a.set_ylabel("energy (J)")
    b.set_xscale("log")
    from matplotlib.ticker import NullFormatter

    b.xaxis.set_minor_formatter(NullFormatter())
    b.set_xlabel("energy (J)")
    b.set_ylabel("mm")
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title or "the nonsmooth mode with every face node a contact")
    return fig
