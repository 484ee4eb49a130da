"""The ``[rub]`` stage: the rub response of the blade turning inside an out-of-round casing, over speeds.

At each speed of ``[rub] speeds`` the blade is taken about its centrifugal state at that speed (stiffness and
running clearances, :func:`bladecase.fe.rotation.spin` about the casing's axis) and reduced with one massless
contact per node of the contact face (:func:`bladecase.reduction.nodes.nodal_model` with the residual correction:
``[rub] size`` modes of the massless structure, the static flexibility they miss added to the nodes'; one
interior basis for every speed, computed at the middle of the range: each speed's model is its Ritz projection,
the contact rows and the residual flexibility computed with that speed's stiffness); then simulated from rest
(:func:`bladecase.nsm.massless.rub.rub_response`: a speed that has not settled after ``[rub] revolutions`` runs on,
a window at a time, up to ``[rub] max_revolutions``; one that never settles is characterised — periodic over
another period, a transient still converging, quasi-periodic or irregular). The speeds run through the study's
executor. Each speed is also given as its ratio to the **crossing speed** of mode 1 (where the lobes' excitation
``lobes·Ω/2π`` meets mode 1's frequency at speed, :func:`crossing_speed`): at the same ratio the rub of two meshes
compares without the meshes' error in ``f1``. Outputs:
``rub.csv`` (one row per speed), ``rub_nodes.csv`` (one row per speed and node), ``rub.png`` (the interaction
diagram: peak tip normal displacement, peak total contact force and peak contact pressure against speed, with the speeds
where the casing's lobes excite a linear mode and, when the study found nonsmooth modes, where they excite the
nonsmooth mode's band).

How hard the tip rubs is said by what converges as the tip mesh is refined: the **contact pressure** (each node's
force over its tributary area), the **total contact force** (the sum over the nodes; its peak over the window),
the **loaded area** (the area of the nodes in contact at that peak, and the largest over the window) and where
the load sits along the chord (:func:`bladecase.reduction.nodes.contact_load`). A node's own force falls like its
area under refinement: it stays in ``rub_nodes.csv`` and ``rub.vtu`` as data, not as a figure of the rub.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ... import log
from ...fe.rotation import SPEED_UNITS, RotationAxis, spin, to_rad_s
from ...io import csv_cell, save_figure, write_text
from ...nsm.damping import Damping
from ...nsm.massless.rub import RUN_ON_FACTOR, rub_response
from ...nsm.massless.wear_rub import wear_rub
from ...reduction.contact import Contact
from ...reduction.nodes import chord_positions, contact_pressure, nodal_model
from ..keys import StudyError
from .contact import check_rub_contact, contact_measure
from .friction import (
    FRICTION_COLUMNS,
    friction_columns,
    friction_response,
    friction_section,
    friction_words,
    log_friction,
)
from .friction_modes import log_friction_modes, mode_points, modes_section, write_friction_modes
from .wear import coating_of, log_wear, wear_figures, wear_section, write_wear

__all__ = ["check_rub_contact", "contact_measure", "crossing_speed", "node_angles", "rub_stage"]

#: Columns of ``rub.csv``: name (its unit is the suffix) → what it holds.
COLUMNS = {
    "speed": "the speed, in [rub] speed_unit",
    "speed_rad_s": "the speed (rad/s)",
    "speed_ratio": "the speed over the crossing speed of mode 1 with the lobes' excitation (empty: no crossing)",
    "tip_normal_displacement_mm": "the largest peak outward normal displacement over the contact nodes (mm)",
    "max_pressure_mpa": "the largest contact pressure over the nodes and the window (MPa): force over tributary area "
                        "(empty for a line of nodes: no area)",
    "total_force_n": "the peak over the window of the total contact force, the sum over the nodes (N)",
    "loaded_area_mm2": "the area of the nodes in contact at the instant of that peak (mm²)",
    "peak_loaded_area_mm2": "the largest area in contact over the window (mm²)",
    "load_centre": "the force-weighted centroid at that peak along the chord: 0 leading edge, 1 trailing edge (a "
                   "line of nodes: from its end of lowest coordinate)",
    "load_location": "that centroid's third of the chord: leading edge, mid-chord or trailing edge (empty for a line)",
    "max_node_force_n": "the largest peak force on one node (N; a mesh quantity: it falls like the node's area)",
    "contact_fraction": "the largest fraction of a revolution a node spends in contact",
    "penetration_mm": "the casing's largest yield under a node (mm; 0 for a rigid casing)",
    "nodes_touching": "how many contact nodes touch the casing",
    "switches": "contact switches simulated",
    "settled": "whether the response is steady: the last window's peaks (over a whole number of its periods) match "
               "the span before's within 2 %",
    "response": "settled, periodic-q (repeating every q lobe passings: a sub-harmonic), or, not settled within "
                "max_revolutions: transient (still converging), quasi-periodic or irregular",
    "period_revolutions": "the response's period in revolutions (q / lobes; 1 / lobes when settled; empty: none)",
    "revolutions_run": "revolutions simulated (more than [rub] revolutions when the speed ran on)",
}


def node_angles(model, nodes, axis: RotationAxis) -> np.ndarray:
    """Each node's angle (rad) about ``axis``, from the nodes' mean radial direction.

    >>> from types import SimpleNamespace
    >>> m = SimpleNamespace(mesh=SimpleNamespace(points=np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])), dim=3)
    >>> np.degrees(node_angles(m, [0, 1], RotationAxis((0, 0, 0), (1, 0, 0)))).round(6).tolist()   # from their mean
    [-45.0, 45.0]
    """
    a = axis.direction
    P = np.zeros((len(nodes), 3))
    P[:, : model.dim] = np.asarray(model.mesh.points, dtype=float)[list(nodes), : model.dim]
    x = P - axis.origin
    radial = x - np.outer(x @ a, a)
    e1 = radial.mean(axis=0)
    if np.linalg.norm(e1) == 0:
        e1 = np.eye(3)[int(np.argmin(np.abs(a)))] - a * a[int(np.argmin(np.abs(a)))]
    e1 = e1 / np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    return np.arctan2(radial @ e2, radial @ e1)


def _axis(study) -> RotationAxis:
    k = study["casing"]["axis"]
    return RotationAxis(k["origin"], k["direction"])


def _node_stiffness(study, model, contact: Contact, shares: np.ndarray | None = None) -> np.ndarray:
    """The casing's stiffness at each node (N/m): per area × tributary area, or the total shared by each node's
    ``shares`` (of the face's area, or of a line's length: :func:`check_rub_contact`, which gives them when
    ``None``)."""
    if shares is None:
        shares = check_rub_contact(study, model, contact)[1]
    c = study["contact"]
    coating = (study.config.get("casing") or {}).get("abradable")
    if coating is not None:  # the coating's elastic layer is the casing's compliance at each node (per area)
        return coating["stiffness"] * shares
    if c.get("casing_stiffness_per_area") is not None:
        return c["casing_stiffness_per_area"] * shares
    from ..stages import casing_stiffness

    total = casing_stiffness(study)
    if total is None:
        return np.full(shares.size, np.inf)
    return total * shares / shares.sum()


def _damping(r: dict) -> Damping:
    if r["rayleigh"] is not None:
        alpha, beta = r["rayleigh"]
        return Damping(alpha=alpha, beta=beta)
    return Damping(zeta=r["ratio"])


def _running(model, contact: Contact, u: np.ndarray, speed: float) -> Contact:
    """The contact at its running clearances (the centrifugal displacement ``u``); ``ValueError`` naming the first
    node whose clearance it closes."""
    d = np.array(contact.clearances) - contact.node_normal_map(model) @ u
    if d.min() <= 0:
        k = int(np.argmin(d))
        raise ValueError(f"at {speed:.6g} rad/s ({speed * 60 / (2 * np.pi):.6g} rpm) the blade's centrifugal growth "
                         f"({(contact.clearances[k] - d[k]) * 1e3:.4g} mm along the normal) closes the clearance of "
                         f"contact node {model.mesh.node_id(contact.nodes[k])} ({contact.clearances[k] * 1e3:.4g} mm "
                         "cold): it rubs statically there; lower the speeds or widen the casing")
    return contact.closed_by(model, u)


class _Interior:
    """The interior basis of the nodal models at the ``middle`` speed (rad/s), solved once per process where a speed
    first needs it (shipped to the workers unsolved)."""

    def __init__(self, middle: float):
        self.middle, self.basis = middle, None

    def __getstate__(self) -> dict:
        return {"middle": self.middle, "basis": None}

    def of(self, model, contact: Contact, size: int, casing: np.ndarray, axis: RotationAxis, static: str) -> np.ndarray:
        if self.basis is None:
            base = spin(model, self.middle, axis, static=static)
            hot = _running(model, contact, base.displacement, self.middle)
            self.basis = nodal_model(base.model, hot, size, factor=base.factor, casing=casing, residual=True).interior
        return self.basis


class _Earlier:
    """The centrifugal states this process solved for the speeds before (shipped to the workers empty): each speed
    starts from them (:func:`bladecase.fe.rotation.spin`'s ``previous``: the nonlinear state from the two last, the
    static solves preconditioned by the last one's factorisation of ``K(Ω)``; the older kept without its
    factorisation)."""

    def __init__(self):
        self.states = []

    def __getstate__(self) -> dict:
        return {"states": []}

    def add(self, state) -> None:
        self.states = [replace(s, factor=None) for s in self.states[-1:]] + [state]


def _rub_point(speed: float, *, model, contact: Contact, interior: np.ndarray | _Interior, size: int,
               casing: np.ndarray, angles: np.ndarray, axis: RotationAxis, static: str, lobes: int, amplitude: float,
               damping: Damping, revolutions: int, window: int, max_revolutions: int, friction: dict | None = None,
               coating=None, earlier: _Earlier | None = None) -> dict:
    """One speed (module level: an executor ships it to its workers). Its CPU seconds (``seconds``: the centrifugal
    state, the reduction, the simulation) and the centrifugal state's factorisations and conjugate-gradient solves
    are logged in one line when it ends."""
    clock = [time.process_time()]
    state = spin(model, speed, axis, static=static, previous=earlier.states if earlier is not None else ())
    if earlier is not None:
        earlier.add(state)
    hot = _running(model, contact, state.displacement, speed)
    clock.append(time.process_time())
    # about a geometrically nonlinear state the modes turn with the deformed blade: another speed's interior basis
    # would carry spurious stretching (f1 +1.4 % at 1450 rpm from a 1547 rpm basis): each speed takes its own
    own = None if state.static == "nonlinear" else interior if isinstance(interior, np.ndarray) else interior.of(
        model, contact, size, casing, axis, static)
    reduced = nodal_model(state.model, hot, size, factor=state.factor, casing=casing, interior=own, residual=True)
    clock.append(time.process_time())
    try:
        fr, flight, response = friction_response(reduced, friction, axis, state.factor, speed, lobes, amplitude,
                                                 angles, damping, revolutions, window, max_revolutions,
                                                 respond=rub_response)
        worn = None if coating is None else wear_rub(reduced.system, coating, speed, lobes, amplitude, angles,
                                                     damping, revolutions, areas=reduced.areas, friction=fr,
                                                     flight=flight, energy=True)
    except ValueError as exc:  # the simulation refused this speed (a grazing switch, friction-induced flutter on the
        # worn casing, …): it is that speed's result, the others go on
        out = {"error": str(exc), "nodes": list(reduced.system.nodes)}
    else:
        out = response.as_dict()
        if friction is not None and friction.get("mode_amplitudes") and fr is not None:
            out["friction_modes"] = mode_points(reduced.system, fr, speed, friction["mode_amplitudes"], damping)
        if worn is not None:
            out["wear"] = wear_figures(worn)
        out["load"] = reduced.contact_load(response.force_at_peak)
        out["peak_pressure"] = np.nan_to_num(contact_pressure(response.peak_force, reduced.areas)).tolist()
    out["open_hz"] = (reduced.system.modes[0][:6] / (2 * np.pi)).tolist()
    out["clearances_m"] = reduced.system.gap.tolist()
    clock.append(time.process_time())
    out["seconds"] = dict(zip(("state", "reduction", "simulation"), np.diff(clock).tolist()))
    out["state_solves"] = {"factorisations": state.factorisations, "krylov": state.krylov_iterations,
                           "newton": state.iterations if state.static == "nonlinear" else 0}
    _log_point(speed, out)
    return out


def _log_point(speed: float, out: dict) -> None:
    """One line per speed as it ends (a long sweep logs its progress even without a progress bar)."""
    sec, n = out["seconds"], out.get("state_solves") or {"factorisations": 0, "krylov": 0, "newton": 0}
    what = (f"refused ({out['error'][:80]})" if "error" in out else
            f"{out['switches']} switches over {out['revolutions_run']} revolutions, {out['response']}")
    log.info("rub: %.6g rad/s: %s; %.1f s (centrifugal state %.1f s, reduction %.1f s, simulation %.1f s); "
             "centrifugal state: %d Newton iterations, %d factorisations, %d conjugate-gradient solves", speed, what,
             sum(sec.values()), sec["state"], sec["reduction"], sec["simulation"], n["newton"], n["factorisations"],
             n["krylov"])


def _meet(X: np.ndarray, F: np.ndarray, c2: float) -> float | None:
    """Where the line through ``(X[0], F[0])`` and ``(X[1], F[1])`` (a constant ``F`` with one point) meets
    ``F = c2·X``: ``X = Ω²``, ``F = f²``."""
    slope = (F[1] - F[0]) / (X[1] - X[0]) if X.size > 1 else 0.0
    if c2 == slope:
        return None
    return float((F[0] - slope * X[0]) / (c2 - slope))


def _crossings(speeds: np.ndarray, f_hz: np.ndarray, lobes: int) -> list[float]:
    """The speeds (rad/s) between two given speeds where ``lobes·Ω/2π`` meets ``f(Ω)``, with ``f²`` linear in
    ``Ω²`` between them (Southwell's law of stress stiffening and spin softening)."""
    X, F, c2 = speeds**2, f_hz**2, (lobes / (2 * np.pi)) ** 2
    h = F - c2 * X
    out = []
    for i in np.flatnonzero(np.sign(h[:-1]) * np.sign(h[1:]) <= 0):
        if h[i] == h[i + 1]:
            continue
        out.append(float(np.sqrt(_meet(X[i:i + 2], F[i:i + 2], c2))))
    return out


def crossing_speed(speeds, f1_hz, lobes: int) -> dict | None:
    """The crossing speed of mode 1: where the lobes' excitation ``lobes·Ω/2π`` meets mode 1's frequency at speed
    ``f1(Ω)``, from ``f1`` at the given speeds (rad/s), ``f1²`` taken linear in ``Ω²`` (Southwell's law: exact for
    a stiffness linear in ``Ω²``): interpolated between the two speeds around it (the first, from below), or
    extrapolated from the two nearest speeds (``how``); with one speed, ``f1`` taken constant. ``None`` when ``f1``
    grows as fast as the excitation (no crossing).

    >>> w = np.array([700.0, 800.0, 900.0])                 # rad/s; f1² = 200² + 0.5 (Ω/2π)²
    >>> c = crossing_speed(w, np.sqrt(200**2 + 0.5 * (w / 2 / np.pi) ** 2), lobes=1)
    >>> round(c["speed_rad_s"] / (2 * np.pi), 6), c["how"]   # 200 / sqrt(1 - 0.5) Hz
    (282.842712, 'extrapolated')
    """
    w = np.asarray(speeds, dtype=float).reshape(-1)
    f = np.asarray(f1_hz, dtype=float).reshape(-1)
    order = np.argsort(w)
    w, f = w[order], f[order]
    c = lobes / (2 * np.pi)
    inside = _crossings(w, f, lobes)
    if inside:
        speed, how = inside[0], "interpolated"
    else:
        below = f[0] < c * w[0]  # every speed above the crossing: from the lowest two
        near = slice(0, 2) if below else slice(-2, None)
        met = _meet(w[near] ** 2, f[near] ** 2, c**2)
        if met is None or met <= 0 or (met > w[0] ** 2 if below else met < w[-1] ** 2):
            return None
        speed, how = float(np.sqrt(met)), "extrapolated" if w.size > 1 else "one speed"
    return {"mode": 1, "speed_rad_s": speed, "frequency_hz": float(c * speed), "how": how}


def _resonances(speeds: np.ndarray, open_hz: np.ndarray, lobes: int) -> list[dict]:
    """Speeds where ``lobes·Ω/2π`` crosses an open-phase frequency between two speeds (:func:`_crossings`)."""
    return [{"mode": k + 1, "speed_rad_s": w, "frequency_hz": float(lobes * w / (2 * np.pi))}
            for k in range(open_hz.shape[1]) for w in _crossings(speeds, open_hz[:, k], lobes)]


def _bands(families) -> list[tuple[float, float]]:
    """The admissible frequency ranges (Hz) of the study's nonsmooth modes."""
    out = []
    for f in families or []:
        ok = np.asarray(f.admissible, dtype=bool)
        if ok.any():
            fr = np.asarray(f.frequencies, dtype=float)[ok]
            out.append((float(fr.min()), float(fr.max())))
    return out


def rub_stage(study, model, contact: Contact, *, families=None, executor=None, progress: bool = False,
              folder: str | Path | None = None, figures: bool = True, title: str | None = None) -> dict:
    """The rub response over ``[rub] speeds`` (module docstring) of ``model`` at rest with its cold ``contact`` (a
    face on the [casing]); writes ``rub.csv``, ``rub_nodes.csv`` and ``rub.png`` into ``folder``; returns the
    summary section."""
    kind, shares = check_rub_contact(study, model, contact)  # before any factorisation
    if study["casing"].get("abradable") is not None and kind != "area":
        raise StudyError("[casing] abradable: the coating's pressure needs each contact node's area: give a contact "
                         "face ([contact] face), not a line of nodes")
    r, k = study["rub"], study["casing"]
    unit = r["speed_unit"]
    speeds = np.array([to_rad_s(v, unit) for v in r["speeds"]])
    axis = _axis(study)
    static = (study.config.get("rotation") or {}).get("static", "auto")
    nodes = list(contact.nodes)
    angles = node_angles(model, nodes, axis)
    casing = _node_stiffness(study, model, contact, shares)
    if kind == "length":
        log.info("rub: the %d contact nodes are a line (they hold no facet of the body): each is weighted by its "
                 "tributary length along it (%.4g to %.4g mm of %.4g mm); no contact pressure or loaded area (a "
                 "line has no area): the forces are read", len(nodes), shares.min() * 1e3, shares.max() * 1e3,
                 shares.sum() * 1e3)
    # the interior basis at the middle of the range, computed where a speed first needs it (a speed about a
    # geometrically nonlinear state takes its own: a sweep of such speeds never solves the middle one)
    interior = _Interior(float(np.sqrt(speeds.min() * speeds.max())))
    damping = _damping(r)
    cap = max_revolutions(r)
    friction = study["contact"].get("friction")
    if friction is not None:
        log.info("rub: %s", friction_words(friction))
    coating = coating_of(study, model, contact) if k.get("abradable") is not None else None
    if coating is not None:
        log.info("rub: an abradable coating of %.4g mm (yield %.4g MPa, %.4g Pa/m, %d cells over a band of %.4g mm "
                 "at radius %.4g mm) worn over %d revolutions at each speed, each revolution flown with the profile "
                 "the revolutions before left", coating.thickness * 1e3, coating.yield_pressure * 1e-6,
                 coating.stiffness, coating.cells, coating.width * 1e3, coating.radius * 1e3, r["revolutions"])
    log.info("rub: %d speeds %.6g–%.6g %s, casing with %d lobes of %.4g mm, %d contact nodes (%s casing), %d "
             "revolutions each (the last %d read; on to at most %d until settled)", speeds.size, min(r["speeds"]),
             max(r["speeds"]), unit, k["lobes"], k["amplitude"] * 1e3, len(nodes),
             "rigid" if np.isinf(casing).all() else f"{casing.sum():.4g} N/m", r["revolutions"], r["window"], cap)
    shared = dict(model=model, contact=contact, interior=interior, earlier=_Earlier(), size=r["size"],
                  casing=casing, angles=angles,
                  axis=axis, static=static, lobes=k["lobes"], amplitude=k["amplitude"], damping=damping,
                  revolutions=r["revolutions"], window=r["window"], max_revolutions=cap,
                  **({"friction": friction} if friction is not None else {}),
                  **({"coating": coating} if coating is not None else {}))
    try:
        points = executor.map(_rub_point, [float(w) for w in speeds], shared=shared, desc="rub speeds",
                              progress=progress)
    except ValueError as exc:
        raise StudyError(f"[rub] speeds: {exc}") from None
    section = _summary(study, speeds, points, families, contact, model, casing, (kind, shares))
    points = [p for p in points if "error" not in p]  # aligned with the rows
    if coating is not None:
        section["wear"] = wear_section(study, coating, section["rows"], points)
    if friction is not None and friction.get("mode_amplitudes"):
        section["friction"]["modes"] = modes_section(section["rows"], points, unit)
        log_friction_modes(section["friction"]["modes"], unit)
    log_friction(section, unit)
    log_wear(section, unit)
    if folder is not None:
        section["files"] = _write(Path(folder), section, points, figures, title)
        if "vtu" in study["output"]["formats"]:
            section["files"]["vtu"] = _write_vtu(Path(folder) / "rub.vtu", model, contact, section, points)
        if (section.get("friction") or {}).get("modes"):
            section["files"].update(write_friction_modes(Path(folder), section["friction"]["modes"], figures, title))
        if coating is not None:
            section["files"].update(write_wear(Path(folder), study, model, contact, section, points, figures,
                                               "vtu" in study["output"]["formats"], title))
    return section


def max_revolutions(r: dict) -> int:
    """``[rub] max_revolutions``, or its default: ``10 × revolutions``."""
    return int(r.get("max_revolutions") or RUN_ON_FACTOR * r["revolutions"])


def _write_vtu(path: Path, model, contact: Contact, section: dict, points: list[dict]) -> str:
    """The mesh with the rub's per-node figures as point data, for ParaView: at the hardest speed (``rub_*``) and
    the largest over every speed (``rub_max_*``) — the peak contact pressure as ``contact_pressure`` (Pa, at the
    hardest speed) and ``contact_pressure_max``; zero off the contact nodes."""
    import meshio

    from ...io import atomic_path

    mesh = model.mesh
    n = len(mesh.points)
    idx = np.asarray(contact.nodes)
    worst = points[int(np.argmax([r["tip_normal_displacement_mm"] for r in section["rows"]]))]
    data = {}
    keys = (("peak_displacement", 1e3, "mm"), ("peak_force", 1.0, "n"), ("contact_fraction", 1.0, ""),
            ("penetration", 1e3, "mm"), ("peak_pressure", 1.0, ""))
    for key, scale, unit in keys[:-1] if _line(section) else keys:  # a line of nodes has no area: no pressure
        name = f"{key}_{unit}" if unit else key
        at, top = np.zeros(n), np.zeros(n)
        at[idx] = np.asarray(worst[key]) * scale
        top[idx] = np.max([np.asarray(p[key]) for p in points], axis=0) * scale
        if key == "peak_pressure":  # Pa: the figure to read, where a node's force is a mesh quantity
            data["contact_pressure"], data["contact_pressure_max"] = at, top
        else:
            data[f"rub_{name}"], data[f"rub_max_{name}"] = at, top
    mask = np.zeros(n, dtype=np.uint8)
    mask[idx] = 1
    data["rub_contact_node"] = mask
    if mesh.numbering == "file":
        data["node_id"] = np.asarray(mesh.node_ids)
    out = meshio.Mesh(mesh.points, [(t, np.asarray(c)) for t, c in mesh.cells.items()], point_data=data,
                      field_data={"rub_hardest_speed": np.array([section["worst"]["speed"]])})
    with atomic_path(path) as tmp:
        meshio.write(tmp, out, file_format="vtu")
    return path.name


def _summary(study, speeds: np.ndarray, points: list[dict], families, contact: Contact, model,
             casing: np.ndarray, measure: tuple[str, np.ndarray]) -> dict:
    r, k = study["rub"], study["casing"]
    unit = r["speed_unit"]
    scale = SPEED_UNITS[unit.lower()]
    ok = np.array(["error" not in q for q in points])
    good = [p for p in points if "error" not in p]
    open_hz = np.array([q["open_hz"] for q in good]) if good else np.zeros((0, 1))
    crossing = crossing_speed(speeds[ok], open_hz[:, 0], k["lobes"]) if good else None
    if crossing is not None:
        crossing["speed"] = crossing["speed_rad_s"] / scale
    rows, failed, characterised = [], [], []
    for given, w, p in zip(r["speeds"], speeds, points):
        if "error" in p:
            failed.append({"speed": float(given), "reason": p["error"]})
            continue
        row = _row(float(given), float(w), p, crossing, k["lobes"], line=measure[0] == "length")
        if study["contact"].get("friction") is not None:
            row.update(friction_columns(p))
        rows.append(row)
        if row["response"] != "settled" or row["revolutions_run"] > r["revolutions"]:
            characterised.append({"speed": row["speed"], "response": p["response"], "settled": bool(p["settled"]),
                                  "period_lobe_passings": p["period"], "period_revolutions": row["period_revolutions"],
                                  "revolutions_run": p["revolutions_run"], "read_revolutions": p["read_revolutions"],
                                  "change": p["change"], **p["detail"]})
    if not rows:
        raise StudyError(f"[rub] speeds: the simulation was refused at every speed; at {failed[0]['speed']:.6g} "
                         f"{unit}: {failed[0]['reason']}")
    worst = int(np.argmax([row["tip_normal_displacement_mm"] for row in rows]))
    p = good[worst]
    touching = [i for i, f in enumerate(p["contact_fraction"]) if f > 0]
    where = _along_tip(model, contact, touching, measure[1] if measure[0] == "area" else None)
    resonances = _resonances(speeds[ok], open_hz, k["lobes"]) if ok.sum() > 1 else []
    for res in resonances:
        res["speed"] = res["speed_rad_s"] / scale
    friction = study["contact"].get("friction")
    return {
        **({"friction": friction_section(friction, rows, good)} if friction is not None else {}),
        "speed_unit": unit, "lobes": k["lobes"], "amplitude_m": k["amplitude"], "revolutions": r["revolutions"],
        "window": r["window"], "max_revolutions": max_revolutions(r),
        "damping": {"ratio": r["ratio"]} if r["ratio"] is not None else {"rayleigh": r["rayleigh"]},
        "nodes": [int(n) for n in points[0]["nodes"]],
        "rows": rows,
        "worst": {**rows[worst], "touching_nodes": [int(p["nodes"][i]) for i in touching],
                  "touching_along_tip": where},
        "unsettled_speeds": [row["speed"] for row in rows if not row["settled"]],
        "characterised": characterised,
        "crossing": crossing,
        "failed_speeds": failed,
        "resonances": resonances,
        "open_hz": open_hz[:, :3].tolist(),
        "nonsmooth_bands_hz": _bands(families),
        "bands_at": _bands_at(study),
        "model": {"size": r["size"], "contact_nodes": len(contact.nodes),
                  "face_area_mm2": float(measure[1].sum()) * 1e6 if measure[0] == "area" else None,
                  "contact_measure": measure[0],
                  "line_length_mm": float(measure[1].sum()) * 1e3 if measure[0] == "length" else None,
                  "casing_n_per_m": None if np.isinf(casing).all() else float(casing.sum())},
    }


def _row(speed: float, w: float, p: dict, crossing: dict | None, lobes: int, line: bool = False) -> dict:
    """One speed's row of ``rub.csv`` (:data:`COLUMNS`) from its point (:func:`_rub_point`); for a ``line`` of
    nodes the pressure and the loaded areas are empty (a line has no area), and so is the load's third of the chord
    (no thick end tells the leading edge: ``load_centre`` is then from the line's end of lowest coordinate)."""
    frac = np.array(p["contact_fraction"])
    load = p["load"]
    row = {"speed": speed, "speed_rad_s": w,
            "speed_ratio": None if crossing is None else w / crossing["speed_rad_s"],
            "tip_normal_displacement_mm": 1e3 * max(p["peak_displacement"]),
            "max_pressure_mpa": 1e-6 * max(p["peak_pressure"]), "total_force_n": float(p["total_force"]),
            "loaded_area_mm2": 1e6 * load["loaded_area_m2"], "peak_loaded_area_mm2": 1e6 * p["loaded_area"],
            "load_centre": load["centre"], "load_location": load["location"],
            "max_node_force_n": max(p["peak_force"]), "contact_fraction": float(frac.max()),
            "penetration_mm": 1e3 * max(p["penetration"]), "nodes_touching": int((frac > 0).sum()),
            "switches": p["switches"], "settled": bool(p["settled"]), "response": p["response"],
            "period_revolutions": None if p["period"] is None else p["period"] / lobes,
            "revolutions_run": p["revolutions_run"]}
    if line:
        row.update(max_pressure_mpa=None, loaded_area_mm2=None, peak_loaded_area_mm2=None, load_location=None)
    return row


def _line(section: dict) -> bool:
    """Whether the contact nodes of the section are a line (no area: no pressure)."""
    return (section.get("model") or {}).get("contact_measure") == "length"


def _bands_at(study) -> str:
    """Where the study's own nonsmooth modes were computed: at rest, or at its [rotation] speed."""
    r = study.config.get("rotation") or {}
    if r.get("speed") is None and not r.get("speeds"):
        return "at rest"
    speed = r["speed"] if r.get("speed") is not None else max(r["speeds"])
    return f"at {speed:.6g} {r.get('speed_unit', 'rpm')}"


def _along_tip(model, contact: Contact, touching: list[int], areas: np.ndarray | None) -> list[float] | None:
    """Where the touching nodes sit along the tip's chord (0 leading edge – 1 trailing edge:
    :func:`bladecase.reduction.nodes.chord_positions`; a line of nodes, ``areas`` ``None``, has no thick end: its 0
    is the end of lowest coordinate along it)."""
    if not touching:
        return None
    nodes = list(contact.nodes)
    s = chord_positions(np.asarray(model.mesh.points, dtype=float)[nodes],
                        np.zeros(len(nodes)) if areas is None else areas)
    return [float(np.round(s[i], 3)) for i in touching]


def _write(folder: Path, section: dict, points: list[dict], figures: bool, title: str | None) -> dict:
    rows = section["rows"]
    columns = {**COLUMNS, **(FRICTION_COLUMNS if "friction" in section else {})}
    lines = [",".join(columns)]
    for row in rows:
        lines.append(",".join(csv_cell(row[c]) for c in columns))
    write_text(folder / "rub.csv", "\n".join(lines) + "\n")
    node_lines = ["speed,speed_rad_s,node,peak_displacement_mm,peak_force_n,contact_pressure_mpa,contact_fraction,"
                  "penetration_mm,clearance_mm"]
    line = _line(section)
    for row, p in zip(rows, points):
        for j, n in enumerate(p["nodes"]):
            node_lines.append(f"{row['speed']:.9g},{row['speed_rad_s']:.9g},{n},{p['peak_displacement'][j] * 1e3:.9g},"
                              f"{p['peak_force'][j]:.9g},{csv_cell(None if line else p['peak_pressure'][j] * 1e-6)},"
                              f"{p['contact_fraction'][j]:.9g},{p['penetration'][j] * 1e3:.9g},"
                              f"{p['clearances_m'][j] * 1e3:.9g}")
    write_text(folder / "rub_nodes.csv", "\n".join(node_lines) + "\n")
    files = {"csv": "rub.csv", "nodes_csv": "rub_nodes.csv"}
    if figures:
        from ...post.rub.plot import interaction_plot

        fig = interaction_plot(section, title=f"{title}: rub response" if title else None)
        save_figure(fig, folder / "rub.png")
        files["figure"] = "rub.png"
    return files
