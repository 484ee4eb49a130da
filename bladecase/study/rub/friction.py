"""The ``[rub]`` stage with ``[contact] friction``: the assumption in words, the friction's columns of ``rub.csv``
(the energy balance of the last revolution, the sliding check) and its part of the summary.

>>> friction_words({"mu": 0.15, "model": "rotation"})[:63]
'friction mu = 0.15 at every contact node, the sliding dominated'
"""

from __future__ import annotations

from ... import log

__all__ = ["FRICTION_COLUMNS", "friction_columns", "friction_section", "friction_words", "log_friction"]

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
}


def friction_words(friction: dict) -> str:
    """The friction model and the assumption it rests on, in words (the log and the report)."""
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
    return {"casing_input_j": f["casing_j"], "friction_work_j": f["friction_j"], "damping_j": f["damping_j"],
            "stored_change_j": f["stored_change_j"], "balance_residual": f["relative_residual"],
            "rotation_dominated": f.get("rotation_dominated"), "sliding_ratio": f.get("sliding_ratio")}


def friction_section(friction: dict, rows: list[dict], points: list[dict]) -> dict:
    """The summary's ``rub.friction``: the model, the assumption, per speed the energy of the last revolution and
    the sliding check (with its message), the worst balance residual, the speeds where the assumption fails."""
    per = []
    for row, p in zip(rows, points):
        f = p.get("friction") or {}
        per.append({"speed": row["speed"], **{k: row[k] for k in FRICTION_COLUMNS},
                    "quadrature_error_j": f.get("quadrature_error_j"), "sliding": f.get("sliding_message"),
                    "sliding_node_ratio": f.get("sliding_node_ratio")})
    residuals = [abs(r["balance_residual"]) for r in per if r["balance_residual"] is not None]
    return {"mu": friction["mu"], "model": friction["model"], "assumption": friction_words(friction),
            "speeds": per, "worst_residual": max(residuals) if residuals else None,
            "not_rotation_dominated": [r["speed"] for r in per if r["rotation_dominated"] is False]}


def log_friction(section: dict, unit: str) -> None:
    """Per speed, the friction's energy balance and the sliding check, in the log."""
    for f in (section.get("friction") or {}).get("speeds", []):
        if f["casing_input_j"] is not None:
            log.info("rub: at %.6g %s friction does %.4g J over the last revolution (casing %.4g J, damping %.4g J, "
                     "stored change %.4g J; balance to %.1e); %s", f["speed"], unit, f["friction_work_j"],
                     f["casing_input_j"], f["damping_j"], f["stored_change_j"], f["balance_residual"],
                     f["sliding"] or "no nodes' radii: the sliding not checked")
