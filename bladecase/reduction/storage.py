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
    def matrix(name):
        return sparse_from_arrays(data, name, source) if f"{name}/data" in data else npz_array(data, name, source, 2)

    def scalar(name, kind="real"):
        return npz_scalar(data, name, source, kind)

    model = model_from_arrays(data, prefix="model/", source=source)
    normal = npz_array(data, "contact/normal", source, 1)
    nodes = tuple(int(k) for k in npz_array(data, "contact/nodes", source, 1, "int")) if "contact/nodes" in data else ()
    weights = tuple(float(x) for x in npz_array(data, "contact/weights", source, 1)) if "contact/weights" in data \
        else ()
    casing = scalar("contact/casing") if "contact/casing" in data else float("inf")
    contact = Contact(scalar("contact/node", "int"), tuple(normal) if normal.size else None, scalar("contact/gap"),
                      nodes, weights, casing)
    size = scalar("size", "int")
    w, gap, method = npz_array(data, "w", source, 1), scalar("gap"), scalar("method", "str")
    try:
        if "contact_model" in data and scalar("contact_model", "str") == "massless":
            from ..nsm import MasslessSystem
            from .massless import MasslessReducedModel

            system = MasslessSystem(npz_array(data, "Mr", source, 2), npz_array(data, "Sr", source, 2), w,
                                    scalar("kc"), gap, casing=casing)
            return MasslessReducedModel(method=method, size=None if size < 0 else size, system=system,
                                        basis=matrix("basis"), model=model, contact=contact,
                                        closed_shape=npz_array(data, "closed_shape", source),
                                        masses=npz_array(data, "masses", source))
        system = LinearSystem(matrix("Mr"), matrix("Kr"), w, gap)
    except ValueError as exc:
        raise ValueError(f"{source}: {exc}") from None
    return ReducedModel(method=method, size=None if size < 0 else size, system=system,
                        basis=matrix("basis"), model=model, contact=contact)
