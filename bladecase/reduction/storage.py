"""Stage files of the reduction layer: a :class:`~bladecase.reduction.model.ReducedModel` as a ``.npz`` file.

The file holds the reduced system, the basis, the contact and the whole FE model
(:func:`bladecase.fe.model_to_arrays`); the Lanczos chain object is not stored
(its Jacobi matrix is the reduced ``K``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..fe import model_from_arrays, model_to_arrays, sparse_from_arrays, sparse_to_arrays
from ..io import atomic_path
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
    """Read a :class:`ReducedModel` written by :func:`save_reduced`."""
    try:
        with np.load(path, allow_pickle=False) as data:
            if "format" not in data or str(data["format"]) != REDUCED_FORMAT:
                raise ValueError(
                    f"{str(path)!r} is not a bladecase reduced-model file (expected format {REDUCED_FORMAT!r}; "
                    "write one with 'bladecase reduce' or bladecase.reduction.save_reduced)")

            def matrix(name):
                return sparse_from_arrays(data, name) if f"{name}/data" in data else np.asarray(data[name])

            model = model_from_arrays(data, prefix="model/", source=str(path))
            normal = np.asarray(data["contact/normal"])
            nodes = tuple(int(k) for k in data["contact/nodes"]) if "contact/nodes" in data else ()
            weights = tuple(float(x) for x in data["contact/weights"]) if "contact/weights" in data else ()
            contact = Contact(int(data["contact/node"]), tuple(normal) if normal.size else None,
                              float(data["contact/gap"]), nodes, weights)
            size = int(data["size"])
            if "contact_model" in data and str(data["contact_model"]) == "massless":
                from ..nsm import MasslessSystem
                from .massless import MasslessReducedModel

                system = MasslessSystem(np.asarray(data["Mr"]), np.asarray(data["Sr"]), np.asarray(data["w"]),
                                        float(data["kc"]), float(data["gap"]))
                return MasslessReducedModel(method=str(data["method"]), size=None if size < 0 else size,
                                            system=system,
                                            basis=matrix("basis"), model=model, contact=contact,
                                            closed_shape=np.asarray(data["closed_shape"]),
                                            masses=np.asarray(data["masses"]))
            system = LinearSystem(matrix("Mr"), matrix("Kr"), np.asarray(data["w"]), float(data["gap"]))
            return ReducedModel(method=str(data["method"]), size=None if size < 0 else size, system=system,
                                basis=matrix("basis"), model=model, contact=contact)
    except (OSError, EOFError, KeyError) as exc:
        raise ValueError(f"cannot read reduced-model file {str(path)!r}: {exc}") from None
