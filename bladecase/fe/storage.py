"""Stage files of the FE front end: an :class:`~bladecase.fe.model.FEModel` as named arrays and ``.npz`` files.

:func:`save_model`/:func:`load_model` write and read a whole model; the array
converters (:func:`sparse_to_arrays`, :func:`model_to_arrays` and their
inverses) are shared with :mod:`bladecase.reduction.storage`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..io import npz_array, npz_scalar
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


def sparse_from_arrays(data, name: str, source: str = "data") -> sp.csr_array:
    """Inverse of :func:`sparse_to_arrays`; ``ValueError`` naming ``source`` and the field if they do not fit."""
    shape = npz_array(data, f"{name}/shape", source, ndim=1, kind="int")
    if shape.shape != (2,) or np.any(shape < 0):
        raise ValueError(f"{source}: field '{name}/shape' must be 2 sizes >= 0, got {shape.tolist()}")
    try:
        return sp.csr_array((npz_array(data, f"{name}/data", source, ndim=1),
                             npz_array(data, f"{name}/indices", source, ndim=1, kind="int"),
                             npz_array(data, f"{name}/indptr", source, ndim=1, kind="int")),
                            shape=tuple(int(s) for s in shape))
    except (TypeError, ValueError, IndexError) as exc:
        raise ValueError(f"{source}: the arrays of matrix {name!r} do not form a sparse matrix ({exc})") from None


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
    """Inverse of :func:`model_to_arrays`; ``ValueError`` if ``data`` is not a saved model or a field has the
    wrong type (the message names ``source`` and the field)."""
    key = f"{prefix}format"
    source = source or "data"
    if key not in data or str(data[key]) != MODEL_FORMAT:
        raise ValueError(f"{source} is not a bladecase FE model file (expected format {MODEL_FORMAT!r}; "
                         "write one with 'bladecase assemble' or bladecase.fe.save_model)")

    def scalar(name: str, kind: str = "real"):
        return npz_scalar(data, prefix + name, source, kind)

    material = npz_array(data, f"{prefix}material", source, ndim=1)
    if material.shape != (3,):
        raise ValueError(f"{source}: field '{prefix}material' must be [E, nu, rho], got shape {material.shape}")
    E, nu, rho = (float(x) for x in material)
    thickness = scalar("thickness")
    dofs = DofMap(node=npz_array(data, f"{prefix}dofs/node", source, 1, "int"),
                  direction=npz_array(data, f"{prefix}dofs/direction", source, 1, "int"),
                  coords=npz_array(data, f"{prefix}dofs/coords", source, 2),
                  fe_index=npz_array(data, f"{prefix}dofs/fe_index", source, 1, "int"),
                  n_total=scalar("dofs/n_total", "int"))
    return FEModel(
        K=sparse_from_arrays(data, f"{prefix}K", source), M=sparse_from_arrays(data, f"{prefix}M", source),
        dofs=dofs, mesh=mesh_from_arrays(data, f"{prefix}mesh/", source),
        material=Material(E, nu, rho, scalar("material_name", "str")),
        order=scalar("order", "int"), mass=scalar("mass", "str"),
        thickness=None if math.isnan(thickness) else thickness, plane=scalar("plane", "str") or None,
        clamped=npz_array(data, f"{prefix}clamped", source, 1, "int"), volume=scalar("volume"),
        rigid_modes=scalar("rigid_modes", "int"),
    )


def save_model(model: FEModel, path) -> None:
    """Write an :class:`FEModel` (matrices, dof map, mesh, material) to a ``.npz`` file, atomically."""
    from ..io import atomic_path

    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **model_to_arrays(model))


def load_model(path) -> FEModel:
    """Read an :class:`FEModel` written by :func:`save_model`; ``ValueError`` naming the file when it is
    missing, truncated, corrupted, not a model file, or holds a field of the wrong type."""
    from ..io import read_npz

    data = read_npz(path, "FE model file")
    try:
        return model_from_arrays(data, source=str(path))
    except KeyError as exc:
        raise ValueError(f"cannot read FE model file {str(path)!r}: field {exc} is missing") from None
