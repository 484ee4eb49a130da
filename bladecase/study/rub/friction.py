"""The ``[rub]`` stage with ``[contact] friction``: the model's response at one speed (:func:`friction_response`:
the rotation model, or stick–slip with ``model = "coulomb"``), the assumption in words, the friction's columns of
``rub.csv`` (the energy balance of the last revolution, the sliding check, the share of contact time in stick) and
its part of the summary.

>>> friction_words({"mu": 0.15, "model": "rotation"})[:63]
'friction mu = 0.15 at every contact node, the sliding dominated'
>>> friction_words({"mu": 0.15, "model": "coulomb"})[42:71]
"stick–slip (model 'coulomb'):"
"""

from __future__ import annotations

from dataclasses import replace

from ... import log
from ...nsm.massless.friction import SLIDING_RATIO, friction_flight
from ...nsm.massless.friction_coulomb_rub import coulomb_rub_response
from ...nsm.massless.nodes import Rub
from ...nsm.massless.rub import rub_response
from ...reduction.nodal_friction import nodal_friction

__all__ = ["FRICTION_COLUMNS", "friction_columns", "friction_response", "friction_section", "friction_words",
           "log_friction"]

#: Columns added to ``rub.csv`` with friction: name → what it holds (the last revolution's energy balance, J).
FRICTION_COLUMNS = {
    "casing_input_j": "the work of the out-of-round casing on the blade over the last revolution (J)",
    "friction_work_j": "the work of friction on the vibration over the last revolution (J; negative: it dissipates)",
    "damping_j": "the energy the structural damping dissipates over the last revolution (J)",
    "stored_change_j": "the change of the stored energy over the last revolution (J)",
    "balance_residual": "the largest relative residual of stored change = casing + friction − damping over the "
                        "window's revolutions",
    "rotation_dominated": "whether every node's max |tangential vibration velocity| / ΩR stays at most 0.1",
    "sliding_ratio": "the largest max |tangential vibration velocity| / ΩR over the nodes",
    "stick_share": "model 'coulomb': the largest share of a node's contact time spent sticking to the casing over "
                   "the window (empty with the rotation model, which never sticks)",
}


def friction_response(reduced, friction: dict | None, axis, factor, speed: float, lobes: int, amplitude: float,
                      angles, damping, revolutions: int, window: int, max_revolutions: int, respond=rub_response):
    """One speed's rub response with ``friction`` (``None``: none): ``(Friction or None, the flight or None, the
    response)``. The rotation model (and friction off) runs ``respond`` (the stage's
    :func:`~bladecase.nsm.massless.rub.rub_response`) on
    :func:`~bladecase.nsm.massless.friction.friction_flight`; ``model = "coulomb"`` the stick–slip rub
    (:func:`~bladecase.nsm.massless.friction_coulomb_rub.coulomb_rub_response`, over ``revolutions`` without running
    on), each node sliding past the casing at ``ΩR`` — the flight is then ``None``."""
    fr = None if friction is None else nodal_friction(reduced, friction["mu"], axis.origin, axis.direction,
                                                      factor=factor if reduced.residual else None)
    if fr is not None and friction["model"] == "coulomb" and fr.mu > 0:
        fr = replace(fr, model="coulomb")
        response = coulomb_rub_response(reduced.system, fr, speed, lobes, amplitude, angles, damping, revolutions,
                                        window, areas=reduced.areas)
        return fr, None, response
    flight = friction_flight(reduced.system, fr, damping, Rub(lobes, amplitude, speed, angles))
    response = respond(reduced.system, speed, lobes, amplitude, angles, damping, revolutions, window,
                       areas=reduced.areas, max_revolutions=max_revolutions, friction=fr, flight=flight)
    return fr, flight, response


def friction_words(friction: dict) -> str:
    """The friction model and the assumption it rests on, in words (the log and the report)."""
    if friction.get("model") == "coulomb":
        return (f"friction mu = {friction['mu']:g} at every contact node, stick–slip (model 'coulomb'): a touching "
                "node either slides, the force mu·λ along the casing's motion relative to it (the casing slides past "
                "the tip at ΩR, its blade speed, less the node's tangential vibration velocity), or sticks to the "
                "casing, moving with it, while its tangential force stays within mu·λ; the sliding speed may "
                "vanish (a slow speed); each speed is run over [rub] revolutions from rest, without running on, and "
                "its share of contact time in stick is given")
    return (f"friction mu = {friction['mu']:g} at every contact node, the sliding dominated by the rotation "
            "(model 'rotation'): each touching node slides at ΩR, its blade speed, so the friction force is mu·λ "
            "along the casing's motion relative to the tip; the assumption is checked per node and speed "
            "(max |tangential vibration velocity| / ΩR at most 0.1)")


def friction_columns(point: dict) -> dict:
    """One speed's friction columns (:data:`FRICTION_COLUMNS`) from its point's ``friction`` figures (empty with
    ``mu = 0``: the simulation without friction)."""
    f = point.get("friction") or {}
    if not f:
        return dict.fromkeys(FRICTION_COLUMNS)
    ratio = f.get("sliding_ratio")
    dominated = f.get("rotation_dominated")
    if f.get("model") == "coulomb" and ratio is not None:
        dominated = bool(ratio <= SLIDING_RATIO)
    return {"casing_input_j": f["casing_j"], "friction_work_j": f["friction_j"], "damping_j": f["damping_j"],
            "stored_change_j": f["stored_change_j"], "balance_residual": f["relative_residual"],
            "rotation_dominated": dominated, "sliding_ratio": ratio, "stick_share": f.get("stick_share_max")}


def friction_section(friction: dict, rows: list[dict], points: list[dict]) -> dict:
    """The summary's ``rub.friction``: the model, the assumption, per speed the energy of the last revolution and
    the sliding check (with its message) — with the stick–slip model each node's share of contact time in stick —,
    the worst balance residual, the speeds where the rotation-dominated assumption fails (``rotation`` model) or
    where a node sticks (``coulomb``)."""
    coulomb = friction.get("model") == "coulomb"
    per = []
    for row, p in zip(rows, points):
        f = p.get("friction") or {}
        per.append({"speed": row["speed"], **{k: row[k] for k in FRICTION_COLUMNS},
                    "quadrature_error_j": f.get("quadrature_error_j"), "sliding": f.get("sliding_message"),
                    "sliding_node_ratio": f.get("sliding_node_ratio"),
                    **({"stick_node_share": f.get("stick_share")} if coulomb else {})})
    residuals = [abs(r["balance_residual"]) for r in per if r["balance_residual"] is not None]
    out = {"mu": friction["mu"], "model": friction["model"], "assumption": friction_words(friction),
           "speeds": per, "worst_residual": max(residuals) if residuals else None,
           "not_rotation_dominated": [] if coulomb else [r["speed"] for r in per if r["rotation_dominated"] is False]}
    if coulomb:
        out["sticking"] = [r["speed"] for r in per if (r["stick_share"] or 0) > 0]
    return out


def log_friction(section: dict, unit: str) -> None:
    """Per speed, the friction's energy balance and the sliding check (stick–slip: the share of contact time in
    stick), in the log."""
    f_all = section.get("friction") or {}
    for f in f_all.get("speeds", []):
        if f["casing_input_j"] is None:
            continue
        if f_all.get("model") == "coulomb":
            log.info("rub: at %.6g %s friction does %.4g J over the last revolution (casing %.4g J, damping %.4g J, "
                     "stored change %.4g J; balance to %.1e); stick–slip: a node spends up to %.3g %% of its contact "
                     "time sticking (max |tangential vibration velocity| / ΩR = %.3g)", f["speed"], unit,
                     f["friction_work_j"], f["casing_input_j"], f["damping_j"], f["stored_change_j"],
                     f["balance_residual"], 100 * f["stick_share"], f["sliding_ratio"])
            continue
        log.info("rub: at %.6g %s friction does %.4g J over the last revolution (casing %.4g J, damping %.4g J, "
                 "stored change %.4g J; balance to %.1e); %s", f["speed"], unit, f["friction_work_j"],
                 f["casing_input_j"], f["damping_j"], f["stored_change_j"], f["balance_residual"],
                 f["sliding"] or "no nodes' radii: the sliding not checked")
