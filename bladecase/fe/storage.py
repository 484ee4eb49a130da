"""Stage files of the FE front end: an :class:`~bladecase.fe.model.FEModel` as named arrays and ``.npz`` files.

:func:`save_model`/:func:`load_model` write and read a whole model; the array
converters (:func:`sparse_to_arrays`, :func:`model_to_arrays` and their
inverses) are shared with :mod:`bladecase.reduction.storage`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from .material import Material
from .mesh import mesh_from_arrays, mesh_to_arrays
from .model import DofMap, FEModel

#: Format tag of the ``.npz`` files written by :func:`save_model`.
MODEL_FORMAT = "bladecase-femodel-1"


def sparse_to_arrays(name: str, A) -> dict[str, np.ndarray]:
    """A sparse matrix as CSR arrays ``name/data``, ``name/indices``, ``name/indptr``, ``name/shape``."""
    A = sp.csr_array(A)
    return {f"{name}/data": A.data, f"{name}/indices": A.indices, f"{name}/indptr": A.indptr,
            f"{name}/shape": np.array(A.shape)}


def sparse_from_arrays(data, name: str) -> sp.csr_array:
    """Inverse of :func:`sparse_to_arrays`."""
    return sp.csr_array((data[f"{name}/data"], data[f"{name}/indices"], data[f"{name}/indptr"]),
                        shape=tuple(int(s) for s in data[f"{name}/shape"]))


def model_to_arrays(model: FEModel, prefix: str = "") -> dict[str, np.ndarray]:
    """Everything of an :class:`FEModel` as named arrays (see :func:`save_model`)."""
    out = {f"{prefix}format": np.array(MODEL_FORMAT)}
    out.update(sparse_to_arrays(f"{prefix}K", model.K))
    out.update(sparse_to_arrays(f"{prefix}M", model.M))
    d = model.dofs
    out.update({f"{prefix}dofs/node": d.node, f"{prefix}dofs/direction": d.direction,
                f"{prefix}dofs/coords": d.coords, f"{prefix}dofs/fe_index": d.fe_index,
                f"{prefix}dofs/n_total": np.array(d.n_total)})
    m = model.material
    out.update({f"{prefix}material": np.array([m.E, m.nu, m.rho]), f"{prefix}material_name": np.array(m.name),
                f"{prefix}order": np.array(model.order), f"{prefix}mass": np.array(model.mass),
                f"{prefix}thickness": np.array(np.nan if model.thickness is None else model.thickness),
                f"{prefix}plane": np.array(model.plane or ""), f"{prefix}clamped": model.clamped,
                f"{prefix}volume": np.array(model.volume), f"{prefix}rigid_modes": np.array(model.rigid_modes)})
    out.update(mesh_to_arrays(model.mesh, f"{prefix}mesh/"))
    return out


def model_from_arrays(data, prefix: str = "", source: str = "") -> FEModel:
    """Inverse of :func:`model_to_arrays`; ``ValueError`` if ``data`` is not a saved model."""
    key = f"{prefix}format"
    if key not in data or str(data[key]) != MODEL_FORMAT:
        raise ValueError(f"{source or 'data'} is not a bladecase FE model file (expected format {MODEL_FORMAT!r}; "
                         "write one with 'bladecase assemble' or bladecase.fe.save_model)")
    E, nu, rho = (float(x) for x in data[f"{prefix}material"])
    thickness = float(data[f"{prefix}thickness"])
    dofs = DofMap(node=np.asarray(data[f"{prefix}dofs/node"]), direction=np.asarray(data[f"{prefix}dofs/direction"]),
                  coords=np.asarray(data[f"{prefix}dofs/coords"]), fe_index=np.asarray(data[f"{prefix}dofs/fe_index"]),
                  n_total=int(data[f"{prefix}dofs/n_total"]))
    return FEModel(
        K=sparse_from_arrays(data, f"{prefix}K"), M=sparse_from_arrays(data, f"{prefix}M"), dofs=dofs,
        mesh=mesh_from_arrays(data, f"{prefix}mesh/"),
        material=Material(E, nu, rho, str(data[f"{prefix}material_name"])),
        order=int(data[f"{prefix}order"]), mass=str(data[f"{prefix}mass"]),
        thickness=None if math.isnan(thickness) else thickness, plane=str(data[f"{prefix}plane"]) or None,
        clamped=np.asarray(data[f"{prefix}clamped"]), volume=float(data[f"{prefix}volume"]),
        rigid_modes=int(data[f"{prefix}rigid_modes"]),
    )


def save_model(model: FEModel, path) -> None:
    """Write an :class:`FEModel` (matrices, dof map, mesh, material) to a ``.npz`` file, atomically."""
    from ..io import atomic_path

    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **model_to_arrays(model))


def load_model(path) -> FEModel:
    """Read an :class:`FEModel` written by :func:`save_model`."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return model_from_arrays(data, source=str(path))
    except (OSError, EOFError, KeyError) as exc:
        raise ValueError(f"cannot read FE model file {str(path)!r}: {exc}") from None
