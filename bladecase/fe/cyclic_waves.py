"""A sector mode of nodal diameter ``k`` expanded to the whole disk: standing and travelling waves.

Sector ``j`` (``j = 0 … N−1``) is sector 0 rotated by ``jα`` (``α = 2π/N``) about the engine axis, right-handed
about its direction ``a``; the rotor turns that way too (a positive speed about ``a``).  With the complex sector
mode ``φ`` of :func:`~bladecase.fe.cyclic.cyclic_modes` (the right face is ``e^{ikα}`` times the rotated left face),
sector ``j``'s motion in its own frame, at the phase ``τ = ωt``, is

* ``"cos"``: ``Re(φ e^{ijkα}) cos τ`` and ``"sin"``: ``Im(φ e^{ijkα}) cos τ`` — the two standing waves;
* ``"forward"``: ``Re(φ e^{i(jkα − τ)})`` — blade ``j`` repeats blade 0's motion ``jk/N`` of a period later: the
  wave's crests travel towards increasing angle, **with** the rotation (in the rotating frame); a stationary
  observer sees it at ``ω + kΩ``;
* ``"backward"``: ``Re(φ e^{i(jkα + τ)})`` — blade ``j`` is ``jk/N`` of a period ahead: the crests travel against
  the rotation; a stationary observer sees ``|ω − kΩ|``.  An engine-order excitation ``e`` (a pattern fixed in
  space, ``cos(eθ_stationary)``) is a backward wave of ``e`` diameters in the rotating frame.

For ``k = 0`` and ``k = N/2`` the mode is real and a standing wave only.  :func:`annulus_field` rotates each
sector's displacement vectors into the global frame, :func:`annulus_points` places the sectors' nodes.

>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector, cyclic_modes
>>> s = CyclicSector(sp.csr_array([[2.0, -1.0], [-1.0, 1.0]]), sp.csr_array(np.diag([1.0, 0.0])), 6,
...                  left=[0], right=[1])
>>> u = annulus_field(s, cyclic_modes(s, 1, 1), 0, "forward", phase=0.0)[:, 0]   # each sector's mass
>>> v = annulus_field(s, cyclic_modes(s, 1, 1), 0, "forward", phase=0.5)[:, 0]   # a little later
>>> crest = lambda w: -np.angle(np.sum(w * np.exp(-1j * np.arange(6) * np.pi / 3)))  # w ∝ cos(θ - crest)
>>> round(float(crest(v) - crest(u)), 9)      # the crest moved towards +θ by 0.5 rad / k
0.5
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from ..checks import finite, integer
from .cyclic import CyclicModes, CyclicSector, rotation_matrix
from .mesh import Mesh
from .model import FEModel, node_operator

__all__ = ["WAVES", "annulus_field", "annulus_mesh", "annulus_nodes", "annulus_points", "rotate_field"]

#: The expansions of :func:`annulus_field`.
WAVES = ("cos", "sin", "forward", "backward")


def rotate_field(sector: CyclicSector, u: np.ndarray, angle: float) -> np.ndarray:
    """A sector dof vector (or columns ``(n, c)``) with every location's displacement rotated by ``angle`` about
    the axis (scalar dofs, ``sector.triples is None``, as they are)."""
    u = np.array(u, dtype=np.result_type(u, float))
    if sector.triples is None or angle == 0.0:
        return u
    if sector.triples.size != sector.n_dofs:
        raise ValueError(f"{sector.n_dofs - sector.triples.size} dofs of the sector sit at nodes with some but not "
                         "all directions fixed: their displacement cannot be turned into another sector's frame")
    R = rotation_matrix(sector.axis.direction, angle)
    t = sector.triples
    block = u[t]                                   # (q, 3) or (q, 3, c)
    u[t] = np.einsum("ab,qb...->qa...", R, block)
    return u


def annulus_field(sector: CyclicSector, modes: CyclicModes, index: int, wave: str = "cos", *,
                  phase: float = 0.0) -> np.ndarray:
    """Mode ``index`` of ``modes`` on every sector of the disk at the phase ``τ = ωt`` (module docstring).

    Returns
    -------
    (N, n) ndarray
        Row ``j``: sector ``j``'s dof vector in the global frame (its nodes are sector 0's rotated by ``jα``,
        :func:`annulus_points`).

    Raises
    ------
    ValueError
        A bad ``wave``, ``index`` or ``phase``; a travelling wave of nodal diameter 0 or ``N/2`` (standing only).
    """
    if wave not in WAVES:
        raise ValueError(f"wave must be one of {', '.join(map(repr, WAVES))}, got {wave!r}")
    index = integer("index", index, 0, modes.shapes.shape[1] - 1)
    tau = finite("phase", phase)
    k, n = modes.k, sector.sectors
    if wave in ("forward", "backward") and modes.multiplicity == 1:
        raise ValueError(f"nodal diameter {k} of a disk of {n} sectors has standing waves only (k = 0 or N/2); "
                         "use wave='cos'")
    phi = modes.shapes[:, index]
    alpha = sector.alpha
    out = np.empty((n, phi.size))
    for j in range(n):
        z = phi * np.exp(1j * j * k * alpha)
        local = {"cos": z.real * math.cos(tau), "sin": z.imag * math.cos(tau),
                 "forward": (z * np.exp(-1j * tau)).real, "backward": (z * np.exp(1j * tau)).real}[wave]
        out[j] = rotate_field(sector, local, j * alpha)
    return out


def annulus_points(points: np.ndarray, sector: CyclicSector) -> np.ndarray:
    """``(N, p, 3)``: the points of sector 0 (e.g. its mesh nodes) placed in every sector."""
    pts = np.asarray(points, dtype=float)
    o = sector.axis.origin
    return np.stack([(pts - o) @ rotation_matrix(sector.axis.direction, j * sector.alpha).T + o
                     for j in range(sector.sectors)])


def annulus_mesh(mesh: Mesh, sector: CyclicSector, tol: float | None = None) -> tuple[Mesh, np.ndarray]:
    """The whole disk as one mesh: sector 0's ``mesh`` placed in every sector, the coincident nodes of the cut
    faces merged (within ``tol`` m; ``None``: ``1e-9`` of the largest coordinate).

    Returns
    -------
    (Mesh, (N, nodes) int ndarray)
        The disk's mesh (body cells only; each group of the sector's mesh holds its nodes in every sector) and the
        disk node of each sector's node.
    """
    pts = annulus_points(mesh.points, sector)
    n_sec, n = pts.shape[:2]
    flat = pts.reshape(-1, 3)
    tol = 1e-9 * float(np.abs(flat).max()) if tol is None else float(tol)
    rep = np.arange(flat.shape[0])
    for a, b in sorted(cKDTree(flat).query_pairs(tol)):
        rep[max(a, b)] = min(rep[a], rep[b])
    rep = rep[rep]
    used, inverse = np.unique(rep, return_inverse=True)
    index = inverse.reshape(n_sec, n)
    btype = mesh.body_type
    cells = np.vstack([index[j][np.asarray(mesh.cells[btype])] for j in range(n_sec)])
    groups = {name: np.unique(index[:, np.asarray(g)]) for name, g in mesh.groups.items()}
    out = Mesh(flat[used], {btype: cells}, dim=3, groups=groups, source=f"annulus of {n_sec} sectors of "
               f"{mesh.source or 'a sector'}", unit=mesh.unit)
    return out, index


def annulus_nodes(model: FEModel, field: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``(disk nodes, 3)``: the displacements of :func:`annulus_field` (rows: sectors) at the nodes of the disk's
    mesh (``index`` from :func:`annulus_mesh`); a node shared by two sectors gets the same value from both."""
    ops = node_operator(model)
    out = np.zeros((int(index.max()) + 1, 3))
    for j, row in enumerate(np.asarray(field)):
        out[index[j]] = (ops @ row).reshape(-1, 3)
    return out
