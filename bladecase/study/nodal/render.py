"""The every-node mode animated: an orbit of the nonsmooth mode with every face node a contact, checked and
written as the study's own orbits are (GIF/MP4, VTK time series), with what the casing does at each node.

With ``[contact] points = "nodes"`` the every-node orbit is the answer to "where on the tip does it rub, how hard";
the face mean is its comparison. The orbit animated is the family's orbit nearest in energy to the face mean's
animated orbit (the figures of the two models are compared at equal energy), else the family's middle orbit in
energy. Before it is written it is checked twice, independently of the shooting that found it: re-simulated for
one period by the exact event-driven simulator of the same model (:func:`~bladecase.nsm.massless.nodes
.simulate_nodes`, from the middle of a phase with every node open), and, with ``[output] reference``, in the nodal
model's Krylov extension (:func:`~bladecase.study.reference.check_nodal_in_reference`); and its drift in the FE
model is estimated by a reference converged in size (:func:`converged_check`: nested extensions of 4, 8 and 16 times
its dofs, the last drift and its change from the one before). An orbit that fails a check is not animated, and the
log says why.

The frames: ``[output] frames`` instants over the period, the one nearest the instant of the largest penetration
into the casing moved onto it (so the frames show the peak the summary gives). The VTK frames carry, besides the
displacement and velocity of every node, per contact node: ``normal_gap`` (m: its clearance minus its normal
displacement; negative where it presses into the casing; NaN off the contact face), ``contact_pressure`` (Pa: its
force over its tributary area) and ``casing_yield`` (m: how far the casing gives, ``λ/k``), and the mask
``contact_node``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import log
from ...post.grid import fe_grid, grid_index, nodal_field
from ...post.outputs import FORMATS, OrbitScene
from ...post.prestress import centrifugal_fields
from ..reference import nodal_drift, open_start, phase_changes

__all__ = ["animate_nodal", "nodal_frames", "return_error"]

#: Samples over the period in which the instant of the largest penetration is found before its frame is moved.
PEAK_SAMPLES = 4000
#: A re-simulated every-node orbit passes when it returns to its start within this (energy norm, relative).
RETURN_RTOL = 1e-6


def return_error(orbit) -> dict:
    """One period of the exact event-driven simulator of ``orbit``'s own system from the middle of its longest phase
    with every node open (else from ``t = 0``): ``{"return_error", "switches", "expected", "ok"}``, the error the
    relative distance of the end state from the start in the energy norm."""
    t0 = open_start(orbit) or 0.0
    x0, v0 = (z[:, 0] for z in orbit.state(np.array([t0])))
    error, switches = nodal_drift(orbit.system, x0, v0, orbit.T)
    return {"return_error": error, "switches": switches, "expected": phase_changes(orbit),
            "ok": bool(error <= RETURN_RTOL), "from_t_over_T": float(t0 / orbit.T)}


def nodal_frames(orbit, frames: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``frames`` instants over the period, the nearest moved onto the instant of the largest penetration (the
    largest ``λ_j/k_j``; with a rigid casing, of the largest force), the mask of frames where a node touches, and
    that instant."""
    T = orbit.T
    s = orbit.system
    dense = np.linspace(0.0, T, PEAK_SAMPLES, endpoint=False)
    lam = orbit.forces(dense)
    k = np.asarray(s.casing, dtype=float)
    depth = lam / np.where(np.isfinite(k), k, 1.0)[:, None]
    peak = float(dense[int(np.unravel_index(np.argmax(depth), depth.shape)[1])])
    t = np.arange(frames) * T / frames
    j = int(np.argmin(np.abs(t - peak)))
    if j > 0 or peak < 0.5 * T / frames:
        t[j] = peak if j > 0 else t[j]
    touching = (orbit.forces(t) > 0).any(axis=0)
    return t, touching, peak


def _scene(study, nodal, orbit, stem: str) -> tuple[OrbitScene, dict]:
    """The orbit on every node of the mesh, the casing's figures per contact node and frame, and what the frames
    show (the largest penetration and pressure among them)."""
    from ...post import animation

    o = study["output"]
    model = nodal.model
    times, touching, peak = nodal_frames(orbit, o["frames"])
    x, v = orbit.state(times)
    x_free = nodal.free_dofs(x)
    dt = 1e-7 * orbit.T  # the pressed nodes move with λ' too: λ is the complementarity's, piecewise linear in x
    lam_dot = (orbit.forces(times + dt) - orbit.forces(times - dt)) / (2 * dt)
    v_free = nodal.basis @ v + nodal.closed_shapes @ lam_dot
    u, vel = nodal_field(model, x_free), nodal_field(model, v_free)
    mesh = fe_grid(model)
    nodes = np.asarray(nodal.contact.nodes)
    points = np.array([grid_index(model, k) for k in nodes])
    un = nodal.normal_map @ x_free  # (m, frames): each node's normal displacement
    d = np.asarray(nodal.system.gap, dtype=float)
    lam = orbit.forces(times)
    k = np.asarray(nodal.system.casing, dtype=float)
    yield_ = np.where(np.isfinite(k)[:, None], lam / np.where(np.isfinite(k), k, 1.0)[:, None], 0.0)
    n_points = len(mesh.points)

    def on_face(values, fill):
        out = np.full((n_points, times.size), fill, dtype=float)
        out[points] = values
        return out

    pressure = np.divide(lam, nodal.areas[:, None], out=np.zeros_like(lam), where=nodal.areas[:, None] > 0)
    mask = np.zeros(n_points, dtype=np.uint8)
    mask[points] = 1
    worst = int(np.argmax(yield_.max(axis=1) if np.isfinite(k).any() else lam.max(axis=1)))
    scale = animation.auto_scale(mesh, u, o["auto_fraction"]) if o["scale"] == "auto" else float(o["scale"])
    scene = OrbitScene(stem=stem, title=f"{study.name}: the nonsmooth mode with every tip node a contact "
                       f"({len(nodes)} nodes)", mesh=mesh, orbit=orbit, times=times, u=u, v=vel, impact=touching,
                       contact_node=int(points[worst]), normal=nodal.contact.normal_for(model),
                       scale=scale, options=o, branch=None, face_points=points, face_beyond=un > d[:, None],
                       point_data={"contact_node": mask, **(centrifugal_fields(model) or {})},
                       frame_data={"normal_gap": on_face(d[:, None] - un, np.nan),
                                   "contact_pressure": on_face(pressure, 0.0), "casing_yield": on_face(yield_, 0.0)},
                       casing_gap=float(d[worst]))
    shown = {"frames_max_penetration_mm": float(yield_.max(initial=0.0)) * 1e3,
             "frames_max_pressure_mpa": float(pressure.max(initial=0.0)) * 1e-6, "peak_t_over_T": peak / orbit.T}
    return scene, shown


#: Sizes of the nested Krylov extensions of :func:`converged_check`, × the nodal model's dofs.
CONVERGED_FACTORS = (4, 8, 16)


def converged_check(orbit, nodal, extend) -> dict:
    """The orbit's drift after one period in the FE model, estimated by a reference converged in size: the nodal
    model's Krylov extensions of :data:`CONVERGED_FACTORS` × its dofs (nested: each contains the smaller), each
    flown for one period from the same state (:func:`~bladecase.study.reference.check_nodal_in_reference`).
    ``{"dofs": [...], "drifts": [...], "drift"`` (the largest model's) ``, "bound"`` (its change from the model
    before: how far the estimate may still be from the FE model's) ``}``; measured on the demo's every-node orbit,
    the drift settles at 1.48e-4 from 128 dofs on (16, 32, 64, 128, 256, 512 dofs: 1.52, 1.31, 1.53, 1.484, 1.483,
    1.484e-4)."""
    from ..reference import check_nodal_in_reference

    dofs, drifts = [], []
    for f in CONVERGED_FACTORS:
        reference = extend(f * nodal.n)
        check = check_nodal_in_reference(orbit, nodal, reference)
        if check["drift"] is None:
            return {"dofs": [], "drifts": [], "drift": None, "bound": None, "reason": check.get("reason")}
        dofs.append(int(reference.n))
        drifts.append(float(check["drift"]))
    return {"dofs": dofs, "drifts": drifts, "drift": drifts[-1], "bound": abs(drifts[-1] - drifts[-2])}


def _pick(family, target_energy: float | None):
    """The orbit to animate: nearest in energy to ``target_energy`` (log scale), else the middle in energy."""
    orbits = [o for o, on in zip(family.orbits, family.on_backbone) if on and o.touching.any()]  # not in a tongue
    if not orbits:
        return None
    e = np.array([o.energy for o in orbits])
    target = target_energy if target_energy else float(np.sqrt(e.min() * e.max()))
    return orbits[int(np.argmin(np.abs(np.log(e / target))))]


def animate_nodal(study, nodal, family, folder: str | Path, target_energy: float | None = None,
                  reference=None, row_of=None, extend=None) -> list[dict]:
    """Check and write the every-node orbit of ``family`` (module docstring) into ``folder``; returns its
    ``summary.json`` entry in a list (empty when nothing is animated: ``[output] animate = 0``, no orbit touching,
    or the orbit failed a check). ``reference``: the nodal model's extension for the reference check;
    ``row_of``: a function of an orbit giving its figures (the ``nodal_modes.csv`` row); ``extend``: a function
    ``count -> extension of nodal by count dofs`` for :func:`converged_check` (the FE model's drift)."""
    from ..reference import SURVIVAL_RTOL, check_nodal_in_reference

    o = study["output"]
    if o["animate"] == 0 or not o["formats"]:
        return []
    orbit = _pick(family, target_energy)
    if orbit is None:
        return []
    check = return_error(orbit)
    entry = {"model": "every node a contact", "T": float(orbit.T), "frequency_hz": float(orbit.frequency),
             "energy_j": float(orbit.energy), "nodes_touching": int(len(orbit.touching_nodes)),
             "max_penetration_mm": float(np.max(orbit.penetration)) * 1e3, "verification": check}
    if row_of is not None:
        entry.update({k: v for k, v in row_of(orbit).items() if k not in entry})
    if not check["ok"]:
        log.warning("every face node a contact: the orbit at %.6g Hz is not animated: the event-driven simulation "
                    "does not return to it (error %.1e after one period)", orbit.frequency, check["return_error"])
        return []
    if reference is not None:
        entry["reference_check"] = ref = check_nodal_in_reference(orbit, nodal, reference)
        if ref["survives"] is False:
            log.warning("every face node a contact: the orbit at %.6g Hz is not animated: it does not survive in the "
                        "reference model %s (drift %.1e)", orbit.frequency, ref["reference"], ref["drift"])
            return []
    if extend is not None:
        entry["full_model_check"] = full = converged_check(orbit, nodal, extend)
        if full["drift"] is not None and full["drift"] > SURVIVAL_RTOL:
            log.warning("every face node a contact: the orbit at %.6g Hz is not animated: in the FE model (the "
                        "reference converged in size) it drifts by %.1e in one period", orbit.frequency, full["drift"])
            return []
    stem = f"nodes_T{orbit.T:.9e}".replace("+", "").replace(".", "p")
    scene, shown = _scene(study, nodal, orbit, stem)
    entry.update(shown, frames=int(scene.times.size))
    entry.update(FORMATS.write(o["formats"], "orbit", scene, Path(folder)))
    log.info("animated the every-node orbit at %.6g Hz (E = %.3g J, %d nodes touching; largest penetration %.4g µm, "
             "%.4g µm in the frames; simulator return error %.1e)", orbit.frequency, orbit.energy,
             entry["nodes_touching"], entry["max_penetration_mm"] * 1e3, shown["frames_max_penetration_mm"] * 1e3,
             check["return_error"])
    return [entry]
