"""``vtu``: ParaView files of an orbit — the time series ``vtk/<stem>.pvd`` (one ``.vtu`` per frame, with
displacement and velocity on every node) and, with ``[output] manifold``, samples of its branch's
invariant manifold ``vtk/<stem>_manifold.vtu``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import log
from ...nsm import Branch
from ..vtk import write_manifold, write_time_series
from .registry import OrbitScene


def write(scene: OrbitScene, folder: Path, formats: set[str]) -> dict[str, str]:
    orbit = scene.orbit
    pvd = write_time_series(folder / "vtk", scene.stem, scene.mesh, scene.times, scene.u, scene.v,
                            field_data={"period": orbit.T, "energy": orbit.energy, "scale": scene.scale},
                            point_data=scene.point_data, frame_data=scene.frame_data)
    written = {"pvd": f"vtk/{pvd.name}"}
    o = scene.options
    if o.get("manifold") and scene.branch is not None:
        try:
            path = manifold(scene.branch, orbit.T, folder / "vtk" / f"{scene.stem}_manifold.vtu",
                            *o["manifold_size"])
            written["manifold"] = f"vtk/{path.name}"
        except ValueError as exc:
            log.warning("manifold of %s not written: %s", scene.stem, exc)
    return written


def manifold(branch: Branch, T: float, path: Path, n_orbits: int, n_times: int) -> Path:
    """Manifold samples over the admissible arc of ``branch`` through ``T``, projected on
    (contact displacement wᵀx, contact velocity × T/2π, period), written as a quad surface."""
    orbits = branch.sample(n_orbits, at=T, spacing="period")
    if len(orbits) < 2:
        raise ValueError("fewer than two admissible orbits on the arc (a single-point arc)")
    theta = np.arange(n_times) / n_times
    Ts = np.array([o.T for o in orbits])
    states = [o.state(theta * o.T) for o in orbits]
    x = np.stack([st[0] for st in states], axis=1)  # (n, n_orbits, n_times)
    v = np.stack([st[1] for st in states], axis=1)
    w = orbits[0].system.w
    xc = np.einsum("i,ijk->jk", w, x)
    vc = np.einsum("i,ijk->jk", w, v)
    period = np.broadcast_to(Ts[:, None], xc.shape).copy()
    coords = np.stack([xc, vc * period / (2 * np.pi), period], axis=-1)
    energy = np.broadcast_to(np.array([o.energy for o in orbits])[:, None], xc.shape).copy()
    return write_manifold(path, coords, point_data={
        "period": period, "phase": np.broadcast_to(theta[None, :], xc.shape).copy(), "energy": energy,
        "contact_displacement": xc, "contact_velocity": vc, "reduced_state": np.moveaxis(x, 0, -1)})
