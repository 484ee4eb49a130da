"""Method ``"modal"``: the ``size`` lowest M-normalised modes ``Φ``.

``M_r = I``, ``K_r = diag(ω²)``, ``w_r = Φᵀw``: keeps the lowest ``size``
pairs ``(ω_j, b_j)`` exactly.  Sparse shift-invert about 0
(:func:`bladecase.linalg.lowest_modes` with the factor of ``K``), dense for
more than half of the modes of a small model.
"""

from __future__ import annotations

import numpy as np

from ...fe import FEModel, stiffness_factor
from ...linalg import SPDFactor, lowest_modes
from ...nsm import LinearSystem
from ..contact import Contact
from ..model import ReducedModel
from .common import check_count, constraint


def build(model: FEModel, contact: Contact, size: int, factor: SPDFactor | None = None) -> ReducedModel:
    """The modal truncation to ``size`` modes; ``factor`` (of ``model.K``) is reused on the sparse path."""
    n = model.n_dofs
    dense = check_count("modal", size, n, f"the model ({n} free dofs)")
    w = constraint(model, contact)
    if not dense and factor is None:
        factor = stiffness_factor(model)  # with the rigid-body check and its message
    lam, phi = lowest_modes(model.K, model.M, size, factor=factor, dense=dense, name="the stiffness")
    system = LinearSystem(np.eye(size), np.diag(lam), phi.T @ w, contact.gap)
    return ReducedModel("modal", size, system, phi, model, contact)
