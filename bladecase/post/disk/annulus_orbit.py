"""A nonsmooth mode of the whole bladed disk drawn on the annulus: the orbit of the reduced disk
(:func:`~bladecase.reduction.disk.disk_model`, e.g. a travelling-wave family of
:mod:`~bladecase.nsm.massless.disk_modes`) flown over one period in the whole disk — every blade, no symmetry
assumed — and expanded onto every node of every sector (:func:`~bladecase.reduction.disk_fields.sector_fields`: the
waves and each contact's residual static field), written as the study's orbits are: a ParaView time series and the
GIF/MP4 (the ``[output] formats`` of scope ``"orbit"``).

The frames: ``frames`` instants over the period, the one nearest the instant of the largest penetration into the
casing (``λ/k``; a rigid casing: the largest contact force) moved onto it, so the frames show the peak the summary
gives. Besides each node's ``displacement`` and ``velocity`` (global frame), the VTK frames carry on each blade's
contact nodes (NaN or 0 elsewhere): ``normal_gap`` (m: the contact's clearance minus its normal displacement read
on the expanded field — a face-mean contact gives its value to every node of its face; negative where it presses
into the casing), ``contact_force`` (N) and ``casing_yield`` (m, ``λ/k``); constant: ``blade`` (each node's
sector; a node of a cut face: the later one) and the mask ``contact_node``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...fe.cyclic import rotation_matrix
from ...fe.cyclic_waves import annulus_mesh, rotate_field
from ...fe.model import node_operator
from ...nsm.massless.nodes import simulate_nodes
from ...reduction.disk_fields import contact_displacements, sector_fields
from ..outputs import FORMATS, OrbitScene

__all__ = ["PEAK_SAMPLES", "annulus_frames", "write_annulus_orbit"]

#: Samples over the period in which the instant of the largest penetration is found before its frame is moved.
PEAK_SAMPLES = 4000


def _depth(disk, forces: np.ndarray) -> np.ndarray:
    """``λ/k`` per contact and instant (a rigid casing: ``λ``, the force, to find the peak by)."""
    k = np.asarray(disk.system.casing, dtype=float)
    return forces / np.where(np.isfinite(k), k, 1.0)[:, None]


def annulus_frames(disk, orbit, frames: int) -> dict:
    """One period of ``orbit`` (``x0``, ``v0``, ``T``: a state of ``disk.system``) flown by the exact event-driven
    simulator in the whole disk, sampled at ``frames`` instants (the nearest moved onto the largest penetration):
    ``{"times", "x", "v", "forces", "force_rate", "trajectory", "peak_t", "max_penetration", "max_force"}``
    (``max_penetration``: the largest ``λ/k`` over :data:`PEAK_SAMPLES` instants, m; 0 with a rigid casing)."""
    s, T = disk.system, float(orbit.T)
    tr = simulate_nodes(s, orbit.x0, orbit.v0, T)
    dense = np.linspace(0.0, T, PEAK_SAMPLES, endpoint=False)
    lam = tr.forces(dense)
    depth = _depth(disk, lam)
    peak = float(dense[int(np.unravel_index(np.argmax(depth), depth.shape)[1])])
    t = np.arange(int(frames)) * T / int(frames)
    j = int(np.argmin(np.abs(t - peak)))
    t[j] = peak
    t = np.sort(t)
    x, v, forces = tr.sample(t)
    dt = 1e-7 * T  # the pressed contacts move with λ' too: λ is piecewise linear in the state
    rate = (tr.forces(t + dt) - tr.forces(t - dt)) / (2 * dt)
    rigid = not np.isfinite(np.asarray(s.casing, dtype=float)).any()
    return {"times": t, "x": x, "v": v, "forces": forces, "force_rate": rate, "trajectory": tr, "peak_t": peak,
            "max_penetration": 0.0 if rigid else float(depth.max(initial=0.0)), "max_force": float(lam.max())}


def _contact_nodes(model, W: np.ndarray) -> list[np.ndarray]:
    """The mesh nodes of each contact column of the sector's contact map."""
    return [np.unique(model.dofs.node[np.flatnonzero(W[:, i])]) for i in range(W.shape[1])]


def _normal(model, W: np.ndarray, i: int, node: int) -> np.ndarray:
    """The contact's normal at ``node`` (sector 0's frame) from its column of the contact map."""
    here = np.flatnonzero((model.dofs.node == node) & (W[:, i] != 0))
    n = np.zeros(3)
    n[model.dofs.direction[here]] = W[here, i]
    return n / np.linalg.norm(n)


def write_annulus_orbit(model, sector, disk, orbit, folder: str | Path, options: dict, *, stem: str,
                        title: str) -> dict:
    """Expand ``orbit`` of ``disk`` (built from ``sector`` of the FE ``model``) onto the annulus and write it with
    the ``[output]`` ``options`` (``formats``, ``frames``, ``scale``, ``auto_fraction``, ``fps``, ``window``) into
    ``folder`` (module docstring). Returns the files written and what the frames show: ``max_penetration_mm`` (the
    summary's, over :data:`PEAK_SAMPLES` instants), ``frames_max_penetration_mm`` (read on the expanded field,
    ``−normal_gap``), ``max_force_n``, ``peak_t_over_T``, ``worst_blade``, ``disk_nodes``, ``frames``."""
    from .. import animation

    f = annulus_frames(disk, orbit, options["frames"])
    mesh, index = annulus_mesh(model.mesh, sector)
    N, m = disk.sectors, disk.per_blade
    s = disk.system
    u_sec = sector_fields(disk, f["x"], f["forces"])
    v_sec = sector_fields(disk, f["v"], f["force_rate"])
    y = contact_displacements(disk, u_sec)  # (N·m, F): read on the field
    F = f["times"].size
    ops = node_operator(model)
    u, v = np.zeros((len(mesh.points), 3, F)), np.zeros((len(mesh.points), 3, F))
    for j in range(N):  # a node shared by two sectors gets the same value from both (the fields are cyclic)
        a = j * sector.alpha
        u[index[j]] = (ops @ rotate_field(sector, u_sec[j], a)).reshape(-1, 3, F)
        v[index[j]] = (ops @ rotate_field(sector, v_sec[j], a)).reshape(-1, 3, F)
    gap = np.asarray(s.gap, dtype=float)[:, None]
    depth = np.where(np.isfinite(s.casing)[:, None], _depth(disk, f["forces"]), 0.0)
    fields = {"normal_gap": np.full((len(mesh.points), F), np.nan), "contact_force": np.zeros((len(mesh.points), F)),
              "casing_yield": np.zeros((len(mesh.points), F))}
    mask = np.zeros(len(mesh.points), dtype=np.uint8)
    blade = np.zeros(len(mesh.points))
    nodes = _contact_nodes(model, disk.contact)
    points, beyond = [], []
    for j in range(N):
        blade[index[j]] = j
        for i, nd in enumerate(nodes):
            c = j * m + i
            p = index[j][nd]
            fields["normal_gap"][p] = gap[c] - y[c]
            fields["contact_force"][p] = f["forces"][c]
            fields["casing_yield"][p] = depth[c]
            mask[p] = 1
            points.append(p)
            beyond.append(np.broadcast_to(y[c] > gap[c], (p.size, F)))
    worst = int(np.argmax(_depth(disk, f["forces"]).max(axis=1)))
    jw, iw = divmod(worst, m)
    node = int(nodes[iw][0])
    normal = rotation_matrix(sector.axis.direction, jw * sector.alpha) @ _normal(model, disk.contact, iw, node)
    scale = animation.auto_scale(mesh, u, options["auto_fraction"]) if options["scale"] == "auto" \
        else float(options["scale"])
    scene = OrbitScene(stem=stem, title=title, mesh=mesh, orbit=orbit, times=f["times"], u=u, v=v,
                       impact=(f["forces"] > 0).any(axis=0), contact_node=int(index[jw][node]), normal=normal,
                       scale=scale, options=options, branch=None, face_points=np.concatenate(points),
                       face_beyond=np.vstack(beyond), point_data={"contact_node": mask, "blade": blade},
                       frame_data=fields, casing_gap=float(gap[worst, 0]))
    out = {"max_penetration_mm": f["max_penetration"] * 1e3,
           "frames_max_penetration_mm": float(np.nanmax(-fields["normal_gap"], initial=0.0)) * 1e3
           if np.isfinite(s.casing).any() else 0.0,
           "max_force_n": f["max_force"], "peak_t_over_T": f["peak_t"] / orbit.T, "worst_blade": jw,
           "disk_nodes": len(mesh.points), "frames": F, "scale": scale}
    out.update(FORMATS.write(options["formats"], "orbit", scene, Path(folder)))
    return out

