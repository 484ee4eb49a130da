"""The centrifugal state of a study at speed in its VTK files: the static displacement and the prestress.

A model linearised about its centrifugal state (:func:`bladecase.fe.rotation.spin`) carries that state
(:func:`~bladecase.fe.rotation.spun_state`); :func:`centrifugal_fields` turns it into point data of the grid every
VTK frame is drawn on (:func:`~bladecase.post.grid.fe_grid`: every FE node, quadratic cells whole), and
:func:`add_to_mesh_file` writes the same at the nodes of ``mesh.vtu``:

* ``centrifugal_displacement`` — the static displacement at speed (m, a vector: ParaView's *Warp By Vector*);
* ``prestress_von_mises`` — the von Mises stress of the small-strain prestress ``σ = C : ε(u₀)`` (Pa) of a linear
  or second-order state, or ``prestress_von_mises_cauchy`` — that of the true (Cauchy) stress ``J⁻¹ F S Fᵀ`` of a
  geometrically nonlinear state, at the nodes of the undeformed mesh (:func:`bladecase.fe.stress.nodal_stress`:
  each element's stress at its nodes, averaged over the elements that share a node).
"""

from __future__ import annotations

import os
import weakref

import numpy as np

from ..fe import FEModel, Mesh, node_operator
from ..fe.rotation import spun_state
from ..fe.stress import fe_node_points, nodal_stress, von_mises
from .grid import fe_grid, nodal_field, node_values

__all__ = ["CENTRIFUGAL_ARRAYS", "add_to_mesh_file", "centrifugal_fields", "stress_name"]

#: The point-data names this module writes.
CENTRIFUGAL_ARRAYS = ("centrifugal_displacement", "prestress_von_mises", "prestress_von_mises_cauchy")

_FIELDS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def stress_name(static: str) -> str:
    """The point-data name of the von Mises prestress of a ``static`` state (module docstring).

    >>> stress_name("linear"), stress_name("nonlinear")
    ('prestress_von_mises', 'prestress_von_mises_cauchy')
    """
    return "prestress_von_mises_cauchy" if static == "nonlinear" else "prestress_von_mises"


def centrifugal_fields(model: FEModel) -> dict[str, np.ndarray] | None:
    """The centrifugal state of a spun ``model`` on every point of :func:`~bladecase.post.grid.fe_grid`:
    ``centrifugal_displacement`` ``(n_points, 3)`` (m) and the von Mises prestress ``(n_points,)`` (Pa, named by
    :func:`stress_name`); ``None`` for a model at rest. Computed once per model.

    >>> from skfem import MeshTet
    >>> from bladecase.fe import assemble
    >>> from bladecase.fe.rotation import RotationAxis, spin
    >>> m = MeshTet.init_tensor(np.linspace(0.1, 0.2, 5), *2 * [np.linspace(0, 0.01, 2)])
    >>> bar = assemble(Mesh(m.p.T, {"tetra": m.t.T}, dim=3, groups={"root": np.flatnonzero(m.p[0] == 0.1)}),
    ...                "steel", order=2)
    >>> fields = centrifugal_fields(spin(bar, 1000.0, RotationAxis((0, 0, 0), (0, 0, 1))).model)
    >>> sorted(fields), fields["centrifugal_displacement"].shape, centrifugal_fields(bar) is None
    (['centrifugal_displacement', 'prestress_von_mises'], (81, 3), True)
    """
    state = spun_state(model)
    if state is None:
        return None
    hit = _FIELDS.get(model)
    if hit is not None:
        return hit
    _, _, u0, static = state
    disp = np.zeros((len(fe_grid(model).points), 3))
    disp[:, : model.dim] = nodal_field(model, u0)
    sigma = nodal_stress(model, u0, "cauchy" if static == "nonlinear" else "linear")
    out = {"centrifugal_displacement": disp,
           stress_name(static): node_values(model, von_mises(sigma), fe_node_points(model))}
    _FIELDS[model] = out
    return out


def mesh_fields(model: FEModel, mesh: Mesh) -> dict[str, np.ndarray] | None:
    """:func:`centrifugal_fields` at the nodes of ``mesh`` (the model's own mesh, as ``mesh.vtu`` holds it): the
    displacement there (:func:`bladecase.fe.node_operator`), the stress of the grid point at the same place (NaN at
    a node of no body cell); ``None`` at rest."""
    from scipy.spatial import cKDTree

    fields = centrifugal_fields(model)
    if fields is None:
        return None
    u0 = spun_state(model)[2]
    n, dim = len(mesh.points), model.dim
    disp = np.zeros((n, 3))
    disp[:, :dim] = (node_operator(model) @ u0).reshape(-1, dim)[:n]
    grid = fe_grid(model)
    P = np.zeros((n, 3))
    P[:, :dim] = np.asarray(mesh.points, dtype=float)[:, :dim]
    dist, near = cKDTree(grid.points).query(P)
    hit = dist <= 1e-9 * max(float(np.abs(grid.points).max()), 1e-300)
    out = {"centrifugal_displacement": disp}
    for name, values in fields.items():
        if name != "centrifugal_displacement":
            out[name] = np.where(hit, values[near], np.nan)
    return out


def add_to_mesh_file(path: str | os.PathLike, mesh: Mesh, model: FEModel) -> bool:
    """Add the centrifugal state of the spun ``model`` (:func:`mesh_fields`) to the point data of the ``.vtu`` file
    ``path`` that holds ``mesh`` (``mesh.vtu``), atomically; ``False`` (the file untouched) at rest."""
    import meshio

    from ..io import atomic_path

    fields = mesh_fields(model, mesh)
    if fields is None:
        return False
    data = meshio.read(path)
    if len(data.points) != len(mesh.points):
        raise ValueError(f"{path} holds {len(data.points)} points, the mesh {len(mesh.points)}: not its file")
    data.point_data.update(fields)
    with atomic_path(path) as tmp:
        meshio.write(tmp, data, file_format="vtu")
    return True
