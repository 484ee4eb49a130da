"""The blade's part of a finite-element sector's stiffness, for the mistuning model.

Blade-alone mistuning scales the stiffness of the blade's cells, not the disk's: :func:`blade_stiffness` assembles
the chosen body cells alone (the model's material, element order and mass kind, :func:`~bladecase.fe.assemble`)
and places their stiffness on the model's free dofs, matched by location and direction; the dofs the model clamps
are left out as in the model.  The model's ``K`` is the sum of its cells' parts, so the blade's and the disk's
parts add up to ``K``.

>>> import numpy as np
>>> from skfem import MeshHex
>>> from bladecase.fe import Mesh, assemble
>>> h = MeshHex.init_tensor(np.linspace(0, 0.1, 5), np.linspace(0, 0.02, 2), np.linspace(0, 0.02, 2))
>>> bar = Mesh(h.p.T, {"hexahedron": h.t.T}, dim=3, groups={"root": np.flatnonzero(h.p[0] == 0)})
>>> model = assemble(bar, "steel", order=1)
>>> outer = blade_stiffness(model, lambda c: c[:, 0] > 0.05)      # the cells beyond x = 5 cm
>>> inner = blade_stiffness(model, lambda c: c[:, 0] < 0.05)
>>> bool(abs(outer + inner - model.K).max() <= 1e-12 * abs(model.K).max())
True
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..fe import FEModel, assemble

__all__ = ["blade_stiffness"]


def _cell_mask(model: FEModel, cells) -> np.ndarray:
    """The chosen body cells as a boolean mask: a mask, cell indices, or a function of the cells' centroids."""
    conn = np.asarray(model.mesh.cells[model.mesh.body_type])
    count = conn.shape[0]
    if callable(cells):
        mask = np.asarray(cells(model.mesh.points[conn].mean(axis=1)))
        if mask.shape != (count,):
            raise ValueError(f"the cell selection must return one boolean per cell ({count}), got shape {mask.shape}")
        mask = mask.astype(bool)
    else:
        a = np.asarray(cells)
        if a.dtype == bool:
            if a.shape != (count,):
                raise ValueError(f"a cell mask must have one entry per body cell ({count}), got shape {a.shape}")
            mask = a
        else:
            if a.ndim != 1 or not np.issubdtype(a.dtype, np.integer) or (a.size and (a.min() < 0 or a.max() >= count)):
                raise ValueError(f"cells must be a boolean mask, cell indices in 0 … {count - 1}, or a function of "
                                 "the cells' centroids (c, 3) -> (c,) bool")
            mask = np.zeros(count, dtype=bool)
            mask[a] = True
    if not mask.any():
        raise ValueError(f"the cell selection holds no cell of the model's {count} {model.mesh.body_type} cells")
    return mask


def blade_stiffness(model: FEModel, cells) -> sp.csr_array:
    """The stiffness of the ``cells`` of ``model`` alone, on the model's free dofs (module docstring).

    ``cells``: a boolean mask over the body cells, their indices, or a function of the cells' centroids
    ``(c, 3) -> (c,) bool`` (e.g. the cells beyond the rim's radius for the blade of a disk sector).
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    mask = _cell_mask(model, cells)
    mesh = model.mesh
    conn = np.asarray(mesh.cells[mesh.body_type])
    part_mesh = replace(mesh, cells={mesh.body_type: conn[mask]}, groups={},
                        source=f"{int(mask.sum())} cells of {mesh.source or 'a mesh'}")
    part = assemble(part_mesh, model.material, order=model.order, mass=model.mass, clamp=None,
                    thickness=model.thickness, plane=model.plane or "stress")
    scale = max(1.0, float(np.abs(model.dofs.coords).max()))
    where = np.full(part.n_dofs, -1, dtype=np.int64)
    for d in range(3):
        mine, theirs = np.flatnonzero(model.dofs.direction == d), np.flatnonzero(part.dofs.direction == d)
        if mine.size == 0 or theirs.size == 0:
            continue
        dist, j = cKDTree(model.dofs.coords[mine]).query(part.dofs.coords[theirs])
        hit = dist <= 1e-9 * scale
        where[theirs[hit]] = mine[j[hit]]
    kept = np.flatnonzero(where >= 0)  # the others are clamped in the model
    P = sp.csr_array((np.ones(kept.size), (where[kept], kept)), shape=(model.n_dofs, part.n_dofs))
    K = P @ sp.csr_array(part.K) @ P.T
    return sp.csr_array(0.5 * (K + K.T))
