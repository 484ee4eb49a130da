"""Stage files of the reduction layer: a :class:`~bladecase.reduction.model.ReducedModel` as a ``.npz`` file.

The file holds the reduced system, the basis, the contact and the whole FE model
(:func:`bladecase.fe.model_to_arrays`); the Lanczos chain object is not stored
(its Jacobi matrix is the reduced ``K``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..fe import model_from_arrays, model_to_arrays, sparse_from_arrays, sparse_to_arrays
from ..io import atomic_path, npz_array, npz_scalar, read_npz
from ..nsm import LinearSystem
from .contact import Contact
from .model import ReducedModel

#: Format tag of the ``.npz`` files written by :func:`save_reduced`.
REDUCED_FORMAT = "bladecase-reduced-1"


def save_reduced(reduced: ReducedModel, path) -> None:
    """Write a :class:`ReducedModel` (reduced system, basis, contact and the FE model) to ``.npz``, atomically.

    The Lanczos chain object is not stored (its Jacobi matrix is the reduced ``K``).
    """
    s, c = reduced.system, reduced.contact
    out = {"format": np.array(REDUCED_FORMAT), "method": np.array(reduced.method),
           "size": np.array(-1 if reduced.size is None else reduced.size), "w": s.w, "gap": np.array(s.gap),
           "contact/node": np.array(c.node), "contact/gap": np.array(c.gap),
           "contact/normal": np.array([] if c.normal is None else c.normal, dtype=float),
           "contact/nodes": np.array(c.nodes, dtype=np.int64), "contact/weights": np.array(c.weights, dtype=float)}
    if np.isfinite(c.casing):
        out["contact/casing"] = np.array(c.casing)
    if c.normals:  # a face on a casing of revolution: each node's normal and clearance
        out["contact/normals"] = np.array(c.normals, dtype=float)
        out["contact/clearances"] = np.array(c.clearances, dtype=float)
    if getattr(s, "contact_model", "newton") == "massless":  # MasslessSystem: S and kc instead of K
        out.update({"contact_model": np.array("massless"), "Mr": s.M, "Sr": s.S, "kc": np.array(s.kc),
                    "closed_shape": reduced.closed_shape, "masses": reduced.masses})
    else:
        for name, A in (("Mr", s.M), ("Kr", s.K)):
            out.update(sparse_to_arrays(name, A) if sp.issparse(A) else {name: np.asarray(A)})
    if sp.issparse(reduced.basis):
        out.update(sparse_to_arrays("basis", reduced.basis))
    else:
        out["basis"] = np.asarray(reduced.basis)
    out.update(model_to_arrays(reduced.model, prefix="model/"))
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **out)


def load_reduced(path) -> ReducedModel:
    """Read a :class:`ReducedModel` written by :func:`save_reduced`; ``ValueError`` naming the file when it is
    missing, truncated, corrupted, not a reduced-model file, or holds a field of the wrong type."""
    data = read_npz(path, "reduced-model file")
    if "format" not in data or str(data["format"]) != REDUCED_FORMAT:
        raise ValueError(
            f"{str(path)!r} is not a bladecase reduced-model file (expected format {REDUCED_FORMAT!r}; "
            "write one with 'bladecase reduce' or bladecase.reduction.save_reduced)")
    try:
        return _reduced_from_arrays(data, str(path))
    except KeyError as exc:
        raise ValueError(f"cannot read reduced-model file {str(path)!r}: field {exc} is missing") from None


def _reduced_from_arrays(data: dict, source: str) -> ReducedModel:
    """The reduced model of a file's arrays, every field checked against the others (``ValueError`` naming
    ``source`` and the field): the FE model (:func:`bladecase.fe.model_from_arrays`), the contact on a free node
    of it, ``method`` a registered one, ``size`` -1 (none) or >= 1, the reduced system (:class:`LinearSystem`'s
    checks; for the massless contact model the same checks on ``Mr``, ``Sr``, ``w``, ``kc``), ``gap`` the
    contact's, and ``basis`` (and ``closed_shape``, ``masses``) of one row per free dof of the model and one
    column per reduced dof."""
    from ..checks import numbers, symmetric
    from ..linalg import positive_definite
    from .registry import METHODS

    def matrix(name):
        if f"{name}/data" in data:
            return sparse_from_arrays(data, name, source)
        return npz_array(data, name, source, 2, finite=True)

    def scalar(name, kind="real"):
        return npz_scalar(data, name, source, kind)

    def fail(name: str, text: str):
        raise ValueError(f"{source}: field {name!r} {text}")

    model = model_from_arrays(data, prefix="model/", source=source)
    normal = npz_array(data, "contact/normal", source, 1, finite=True)
    nodes = tuple(int(k) for k in npz_array(data, "contact/nodes", source, 1, "int")) if "contact/nodes" in data else ()
    weights = tuple(float(x) for x in npz_array(data, "contact/weights", source, 1)) if "contact/weights" in data \
        else ()
    casing = scalar("contact/casing") if "contact/casing" in data else float("inf")
    normals = tuple(map(tuple, npz_array(data, "contact/normals", source, 2, finite=True).tolist())) \
        if "contact/normals" in data else ()
    clearances = tuple(npz_array(data, "contact/clearances", source, 1, finite=True).tolist()) \
        if "contact/clearances" in data else ()
    try:
        contact = Contact(scalar("contact/node", "int"), tuple(normal) if normal.size else None,
                          scalar("contact/gap"), nodes, weights, casing, normals, clearances)
        contact.dofs(model)
        contact.normal_for(model)
    except ValueError as exc:
        raise ValueError(f"{source}: the contact (fields 'contact/...') does not fit the model: {exc}") from None
    size = scalar("size", "int")
    if size != -1 and size < 1:
        fail("size", f"must be the size asked for (an integer >= 1) or -1 (none), got {size}")
    w, gap, method = npz_array(data, "w", source, 1), scalar("gap"), scalar("method", "str")
    if method not in METHODS:
        fail("method", f"must be one of the reduction methods ({', '.join(map(repr, METHODS))}), got {method!r}")
    if not gap == contact.gap:
        fail("gap", f"must be the contact's clearance (field 'contact/gap' = {contact.gap!r}), got {gap!r}")
    massless = "contact_model" in data and scalar("contact_model", "str") == "massless"
    try:
        if massless:
            from ..nsm import MasslessSystem
            from .massless import MasslessReducedModel

            (Mr, Sr), r = (npz_array(data, name, source, 2, finite=True) for name in ("Mr", "Sr")), w.size
            for name, A in (("Mr", Mr), ("Sr", Sr)):
                if A.shape != (r, r):
                    fail(name, f"must be {r} x {r} (one row and column per entry of 'w'), got shape {A.shape}")
            numbers("w", w)
            if not (np.all(np.isfinite(w)) and np.any(w)):
                fail("w", f"must be a finite, non-zero vector, got {w!r}")
            for name, A in (("Mr", Mr), ("Sr", Sr)):
                symmetric(name, A)
                positive_definite(name, A)
            system = MasslessSystem(Mr, Sr, w, scalar("kc"), gap, casing=casing)
            reduced = MasslessReducedModel(method=method, size=None if size < 0 else size, system=system,
                                           basis=matrix("basis"), model=model, contact=contact,
                                           closed_shape=npz_array(data, "closed_shape", source, 1, finite=True),
                                           masses=npz_array(data, "masses", source, 1, finite=True))
            for name in ("closed_shape", "masses"):
                if getattr(reduced, name).shape != (model.n_dofs,):
                    fail(name, f"must have one entry per free dof of the model ({model.n_dofs}), got shape "
                               f"{getattr(reduced, name).shape}")
            if np.any(reduced.masses < 0):
                fail("masses", f"must be >= 0, got {float(reduced.masses.min())!r}")
        else:
            Mr, Kr = matrix("Mr"), matrix("Kr")
            try:
                system = LinearSystem(Mr, Kr, w, gap)
            except ValueError as exc:  # M, K: the fields Mr, Kr
                raise ValueError(f"{source}: the reduced system (fields 'Mr', 'Kr', 'w', 'gap'): {exc}") from None
            reduced = ReducedModel(method=method, size=None if size < 0 else size, system=system,
                                   basis=matrix("basis"), model=model, contact=contact)
    except ValueError as exc:
        raise ValueError(exc if str(exc).startswith(source) else f"{source}: {exc}") from None
    want = (model.n_dofs, reduced.system.n)
    if reduced.basis.shape != want:
        fail("basis", f"must be {want[0]} x {want[1]} (a row per free dof of the model, a column per reduced dof), "
                      f"got shape {reduced.basis.shape}")
    return reduced
