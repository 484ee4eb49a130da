"""Method ``"full"``: no reduction (``V = I``), dense ``M``, ``K``; refused above :data:`~.common.FULL_LIMIT` dofs."""

from __future__ import annotations

import scipy.sparse as sp

from ...fe import FEModel
from ...nsm import LinearSystem
from ..contact import Contact
from ..model import ReducedModel
from .common import FULL_LIMIT, SUGGEST, constraint


def build(model: FEModel, contact: Contact, size: int | None = None, factor=None) -> ReducedModel:
    """The whole model as a dense system; ``size`` must be ``None`` or ``model.n_dofs``."""
    n = model.n_dofs
    if size is not None and size != n:
        raise ValueError(f"method 'full' keeps all {n} free dofs: size must be None (or {n}), got {size!r}")
    if n > FULL_LIMIT:
        raise ValueError(
            f"method 'full' builds dense {n} x {n} matrices and is limited to FULL_LIMIT = {FULL_LIMIT} "
            f"dofs; this model has {n} free dofs: {SUGGEST}"
        )
    system = LinearSystem(model.M.toarray(), model.K.toarray(), constraint(model, contact), contact.gap)
    return ReducedModel("full", n, system, sp.eye_array(n, format="csr"), model, contact)
