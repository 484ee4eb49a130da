"""Test helpers of the cyclic-symmetry tests, independent of ``bladecase.fe.cyclic``: a structured hexahedral
bladed-disk sector (an annular disk sector with a curved plate blade) and the full annulus assembled from rotated
copies of a sector mesh (scipy's rotations, nodes merged), solved as an ordinary mesh."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from bladecase.fe import Mesh


def hex_sector(sectors: int, *, r_hub=0.10, r_rim=0.16, r_tip=0.26, thickness=0.02, nr=2, nb=4, nt=4, nx=2,
               band=(1, 3), offset=0.0) -> Mesh:
    """A sector of ``360°/N`` about the x axis (angles right-handed about +x from +z, centred on ``offset``):
    disk ``r_hub..r_rim`` × ``thickness`` (x), blade ``r_rim..r_tip`` over the θ cells ``band``; groups
    ``hub`` (r = r_hub) and ``tip``."""
    alpha = 2 * np.pi / sectors
    xs = np.linspace(-thickness / 2, thickness / 2, nx + 1)
    rs = np.r_[np.linspace(r_hub, r_rim, nr + 1), np.linspace(r_rim, r_tip, nb + 1)[1:]]
    ts = offset + np.linspace(-alpha / 2, alpha / 2, nt + 1)
    X, Rr, T = np.meshgrid(xs, rs, ts, indexing="ij")
    points = np.c_[X.ravel(), -Rr.ravel() * np.sin(T.ravel()), Rr.ravel() * np.cos(T.ravel())]
    idx = np.arange(points.shape[0]).reshape(X.shape)
    cells = []
    for i in range(nx):
        for j in range(nr + nb):
            for m in range(nt):
                if j >= nr and not band[0] <= m < band[1]:
                    continue
                c = [idx[i, j, m], idx[i + 1, j, m], idx[i + 1, j + 1, m], idx[i, j + 1, m],
                     idx[i, j, m + 1], idx[i + 1, j, m + 1], idx[i + 1, j + 1, m + 1], idx[i, j + 1, m + 1]]
                cells.append(c)
    cells = np.array(cells)
    used = np.unique(cells)
    renumber = np.full(points.shape[0], -1)
    renumber[used] = np.arange(used.size)
    points, cells = points[used], renumber[cells]
    r = np.hypot(points[:, 1], points[:, 2])
    groups = {"hub": np.flatnonzero(np.isclose(r, r_hub)), "tip": np.flatnonzero(np.isclose(r, r_tip))}
    return Mesh(points, {"hexahedron": cells}, dim=3, groups=groups, source=f"hex_sector({sectors})")


def annulus(mesh: Mesh, sectors: int, tol: float = 1e-9, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """The whole disk: ``mesh`` rotated by ``j·360°/N`` about the line through ``origin`` along +x (scipy),
    coincident nodes merged."""
    btype = mesh.body_type
    n = mesh.points.shape[0]
    o = np.asarray(origin, dtype=float)
    pts = np.vstack([Rotation.from_rotvec([2 * np.pi * j / sectors, 0, 0]).apply(mesh.points - o) + o
                     for j in range(sectors)])
    cells = np.vstack([np.asarray(mesh.cells[btype]) + j * n for j in range(sectors)])
    tree = cKDTree(pts)
    rep = np.arange(pts.shape[0])
    for a, b in sorted(tree.query_pairs(tol)):
        rep[max(a, b)] = min(rep[a], rep[b])
    rep = rep[rep]  # chains of merges point at their first node
    used, inverse = np.unique(rep, return_inverse=True)
    cells = inverse[cells]
    groups = {name: np.unique(inverse[np.concatenate([g + j * n for j in range(sectors)])])
              for name, g in mesh.groups.items()}
    return Mesh(pts[used], {btype: cells}, dim=3, groups=groups, source=f"annulus of {sectors}")


def frequencies_union(spectrum: dict) -> tuple[np.ndarray, float]:
    """The disk's frequencies from a cyclic spectrum, each repeated by its multiplicity, sorted; and the frequency
    below which the union is complete (the least of every diameter's highest computed one)."""
    f = np.sort(np.concatenate([np.repeat(m.frequencies, m.multiplicity) for m in spectrum.values()]))
    return f, min(m.frequencies[-1] for m in spectrum.values())
