"""Stage files of the FE front end: an :class:`~bladecase.fe.model.FEModel` as named arrays and ``.npz`` files.

:func:`save_model`/:func:`load_model` write and read a whole model; the array
converters (:func:`sparse_to_arrays`, :func:`model_to_arrays` and their
inverses) are shared with :mod:`bladecase.reduction.storage`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..io import npz_array, npz_index, npz_scalar
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
    """Inverse of :func:`sparse_to_arrays`; ``ValueError`` naming ``source`` and the field if they do not fit.

    Checked before anything is built (vectorised, O(nnz)): ``shape`` two sizes >= 0, finite numbers in
    ``data``, every column index in ``[0, shape[1])``, ``indptr`` ``shape[0] + 1`` non-decreasing offsets from 0
    to ``nnz``.
    """
    shape = npz_array(data, f"{name}/shape", source, ndim=1, kind="int")
    if shape.shape != (2,) or np.any(shape < 0):
        raise ValueError(f"{source}: field '{name}/shape' must be 2 sizes >= 0, got {shape.tolist()}")
    rows, cols = (int(s) for s in shape)
    values = npz_array(data, f"{name}/data", source, ndim=1, finite=True)
    indices = npz_index(data, f"{name}/indices", source, cols, what=f"column indices of the {rows} x {cols} {name}")
    indptr = npz_array(data, f"{name}/indptr", source, ndim=1, kind="int")
    if values.size != indices.size:
        raise ValueError(f"{source}: fields '{name}/data' and '{name}/indices' must have one entry per stored value "
                         f"of {name}, got {values.size} and {indices.size}")
    if indptr.size != rows + 1 or indptr[0] != 0 or indptr[-1] != indices.size or np.any(indptr[1:] < indptr[:-1]):
        raise ValueError(f"{source}: field '{name}/indptr' must hold {rows + 1} non-decreasing row offsets from 0 to "
                         f"{indices.size} (shape[0] + 1; nnz), got {indptr.size} offsets from "
                         f"{indptr[0] if indptr.size else None} to {indptr[-1] if indptr.size else None}"
                         + (" decreasing somewhere" if indptr.size > 1 and np.any(indptr[1:] < indptr[:-1]) else ""))
    return sp.csr_array((values.astype(float, copy=False), indices, indptr.astype(np.int64, copy=False)),
                        shape=(rows, cols))


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


#: Largest FE model whose ``K`` and ``M`` are factorised when read, proving them positive definite
#: (:func:`bladecase.linalg.positive_definite`).  The factorisations cost what the reduction's own does (3-D P2
#: boxes, SuperLU, one core: 4.3k dofs 0.11 s against 0.2-0.3 s for a 20-mode reduction, 13k 1.0 s against 2-3.6 s,
#: 29k 4.2 s against 6-11 s; reading the file without them: 0.02-0.1 s): below this limit that is a fraction of a
#: second.  A larger model gets the O(nnz) checks only (symmetry, positive diagonal, ...): the stage that uses it
#: factorises ``K`` (the plain Lanczos: ``M``) with its own positive-definiteness check and message.
DEFINITE_CHECK_LIMIT = 5_000

#: Nodes per cell of the meshio types a saved mesh may hold besides the body types of
#: :data:`bladecase.fe.cells.KINDS`.
_BOUNDARY_NODES = {"vertex": 1, "line": 2, "line3": 3}

_CLAMP_HINT = ("K on the free dofs of a clamped model is positive definite (is the model clamped? "
               "re-assemble it with 'bladecase assemble')")


def _mesh_checked(data, prefix: str, source: str):
    """The mesh of a model file, every field checked: finite ``(n, 3)`` points, ``dim`` 2 or 3, cells with the
    node count of their type and node indices in range, body cells of ``dim``, groups of mesh nodes."""
    from .cells import BODY_TYPES, KINDS

    pre = f"{prefix}mesh/"
    points = npz_array(data, f"{pre}points", source, 2, finite=True)
    if points.shape[1] != 3 or points.shape[0] == 0:
        raise ValueError(f"{source}: field '{pre}points' must be the (n_nodes, 3) coordinates of at least one node, "
                         f"got shape {points.shape}")
    n_nodes = points.shape[0]
    dim = npz_scalar(data, f"{pre}dim", source, "int")
    if dim not in (2, 3):
        raise ValueError(f"{source}: field '{pre}dim' must be 2 or 3, got {dim}")
    for key in data:
        if key.startswith(f"{pre}cells/"):
            kind = key[len(pre) + 6:]
            cells = npz_index(data, key, source, n_nodes, ndim=2, what="mesh nodes")
            width = len(KINDS[kind].parents) if kind in KINDS else _BOUNDARY_NODES.get(kind)
            if width is not None and cells.shape[1] != width:
                raise ValueError(f"{source}: field {key!r} must have {width} nodes per {kind} cell, got shape "
                                 f"{cells.shape}")
        elif key.startswith(f"{pre}groups/"):
            npz_index(data, key, source, n_nodes, what="mesh nodes")
    if not any(f"{pre}cells/{t}" in data and len(data[f"{pre}cells/{t}"]) for t in BODY_TYPES[dim]):
        raise ValueError(f"{source}: the mesh has no {dim}-D body cells (a field '{pre}cells/<type>' with <type> "
                         f"one of {', '.join(BODY_TYPES[dim])})")
    return mesh_from_arrays(data, pre, source)


def model_from_arrays(data, prefix: str = "", source: str = "", definite: bool = True) -> FEModel:
    """Inverse of :func:`model_to_arrays`; ``ValueError`` naming ``source`` and the field if ``data`` is not a
    saved model or a field is wrong: its type or shape, an index out of range (cells, groups, the dof map, the
    clamped nodes, the sparse matrices), a NaN or inf, a value outside its set (``order`` 1 or 2, ``mass``
    ``"consistent"``/``"lumped"``, ``plane``), or matrices ``K``, ``M`` that are not square of one size,
    symmetric (:data:`bladecase.checks.SYMMETRY_RTOL`) with a positive diagonal — and, if ``definite`` and the
    model has at most :data:`DEFINITE_CHECK_LIMIT` dofs, positive definite (``K`` unless ``rigid_modes > 0``,
    which the reduction refuses with its own message)."""
    from ..checks import symmetric
    from ..linalg import positive_definite
    from .material import PLANE_KINDS
    from .model import MASS_KINDS, ORDERS

    key = f"{prefix}format"
    source = source or "data"
    if key not in data or str(data[key]) != MODEL_FORMAT:
        raise ValueError(f"{source} is not a bladecase FE model file (expected format {MODEL_FORMAT!r}; "
                         "write one with 'bladecase assemble' or bladecase.fe.save_model)")

    def scalar(name: str, kind: str = "real"):
        return npz_scalar(data, prefix + name, source, kind)

    def fail(name: str, text: str):
        raise ValueError(f"{source}: field '{prefix}{name}' {text}")

    material = npz_array(data, f"{prefix}material", source, ndim=1)
    if material.shape != (3,):
        fail("material", f"must be [E, nu, rho], got shape {material.shape}")
    material_name = scalar("material_name", "str")
    try:
        material = Material(*(float(x) for x in material), material_name)
    except ValueError as exc:
        fail("material", f"([E, nu, rho]): {exc}")
    mesh = _mesh_checked(data, prefix, source)
    dim, n_nodes = mesh.dim, mesh.points.shape[0]
    order, mass, plane = scalar("order", "int"), scalar("mass", "str"), scalar("plane", "str")
    if order not in ORDERS:
        fail("order", f"must be the element order, 1 or 2, got {order}")
    if mass not in MASS_KINDS:
        fail("mass", f"must be one of {MASS_KINDS}, got {mass!r}")
    if dim == 2 and plane not in PLANE_KINDS:
        fail("plane", f"must be one of {PLANE_KINDS} for a 2-D model, got {plane!r}")
    if dim == 3 and plane:
        fail("plane", f"must be empty for a 3-D model, got {plane!r}")
    thickness = scalar("thickness")
    if dim == 2 and not (math.isfinite(thickness) and thickness > 0):
        fail("thickness", f"must be a finite thickness > 0 for a 2-D model, got {thickness!r}")
    if dim == 3 and not math.isnan(thickness):
        fail("thickness", f"must be NaN (none) for a 3-D model, got {thickness!r}")
    volume, rigid_modes = scalar("volume"), scalar("rigid_modes", "int")
    if not (math.isfinite(volume) and volume > 0):
        fail("volume", f"must be a finite volume (area in 2-D) > 0, got {volume!r}")
    if rigid_modes < 0:
        fail("rigid_modes", f"must be a count >= 0, got {rigid_modes}")
    clamped = npz_index(data, f"{prefix}clamped", source, n_nodes, what="mesh nodes")

    K = sparse_from_arrays(data, f"{prefix}K", source)
    M = sparse_from_arrays(data, f"{prefix}M", source)
    n = K.shape[0]
    if n == 0:
        fail("K/shape", f"is {K.shape}: the model has no free dof (its clamp fixes every node)")
    if K.shape[1] != n:
        fail("K/shape", f"must be square (n_free x n_free), got {K.shape}")
    if M.shape != K.shape:
        fail("M/shape", f"must be the shape of K, {K.shape}, got {M.shape}")

    n_total = scalar("dofs/n_total", "int")
    if n_total < n or n_total % dim:
        fail("dofs/n_total", f"must be a multiple of {dim} (the dofs of every node) >= the {n} free dofs, got "
                             f"{n_total}")
    node = npz_index(data, f"{prefix}dofs/node", source, n_nodes, low=-1,
                     what="mesh nodes (-1: a dof off the mesh nodes, e.g. on an edge)")
    direction = npz_index(data, f"{prefix}dofs/direction", source, dim, what=f"directions of a {dim}-D model")
    fe_index = npz_index(data, f"{prefix}dofs/fe_index", source, n_total, what="dofs of the unclamped model")
    coords = npz_array(data, f"{prefix}dofs/coords", source, 2, finite=True)
    for name, a, want in (("node", node, (n,)), ("direction", direction, (n,)), ("fe_index", fe_index, (n,)),
                          ("coords", coords, (n, 3))):
        if a.shape != want:
            fail(f"dofs/{name}", f"must have shape {want} (one entry per free dof of K), got {a.shape}")
    if n > 1 and np.any(fe_index[1:] <= fe_index[:-1]):
        fail("dofs/fe_index", "must be increasing (the free dofs in the order of the unclamped model)")
    if np.any(fe_index % dim != direction):
        i = int(np.flatnonzero(fe_index % dim != direction)[0])
        fail("dofs/direction", f"must be fe_index % {dim}: dof {i} has fe_index {fe_index[i]} but direction "
                               f"{direction[i]}")
    vertex = node >= 0
    if np.unique(node[vertex] * dim + direction[vertex]).size != np.count_nonzero(vertex):
        fail("dofs/node", "gives one node two dofs in the same direction")

    for name, A in (("K", K), ("M", M)):
        try:
            symmetric(name, A)
        except ValueError as exc:
            raise ValueError(f"{source}: {prefix}{exc}") from None
        diag = A.diagonal()
        if np.any(~(diag > 0)):
            i = int(np.flatnonzero(~(diag > 0))[0])
            fail(f"{name}/data", f"must give {name} a positive diagonal ({name} is positive definite), got "
                                 f"{name}[{i},{i}] = {diag[i]:.6g} (free dof {i}: node {node[i]}, direction "
                                 f"{direction[i]})")
    if mass == "lumped" and np.any(M.data[M.indices != np.repeat(np.arange(n), np.diff(M.indptr))]):
        fail("M/data", "must make M diagonal: the model's mass is 'lumped'")
    if definite and n <= DEFINITE_CHECK_LIMIT:
        for name, A, hint in (("M", M, "every free dof needs a positive mass"), ("K", K, _CLAMP_HINT)):
            if name == "K" and rigid_modes:
                continue
            try:
                positive_definite(name, A, hint=hint)
            except ValueError as exc:
                raise ValueError(f"{source}: {prefix}{exc}") from None

    dofs = DofMap(node=node, direction=direction, coords=coords.astype(float, copy=False), fe_index=fe_index,
                  n_total=n_total)
    return FEModel(
        K=K, M=M, dofs=dofs, mesh=mesh, material=material, order=order, mass=mass,
        thickness=None if dim == 3 else thickness, plane=plane or None, clamped=clamped, volume=volume,
        rigid_modes=rigid_modes,
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
