"""Methods ``"lanczos"`` and ``"lanczos-si"``: ``size`` Lanczos steps started at the contact.

:func:`bladecase.reduction.lanczos.lanczos_chain`, plain or shift-invert about
0, gives a chain of unit masses, ``LinearSystem(I, J, |ŵ|e₁, d)``, with the
impacting mass first.  Plain Lanczos matches the moments ``Σ b_j² ω_j^{2p}``,
``p < 2·size`` — it resolves the top of the FE spectrum first, not the lowest
modes; shift-invert matches ``Σ b_j² ω_j^{-2p}``, ``p = 1..2·size``, and
converges to the lowest modes the contact sees (it reuses the factor of ``K``).
"""

from __future__ import annotations

from ...fe import FEModel
from ...linalg import SPDFactor
from ..contact import Contact
from ..lanczos import lanczos_chain
from ..model import ReducedModel


def _build(model: FEModel, contact: Contact, size: int, shift_invert: bool, factor) -> ReducedModel:
    n = model.n_dofs
    method = "lanczos-si" if shift_invert else "lanczos"
    if size > n:
        raise ValueError(f"size = {size} is too large for method {method!r}: at most {n} Lanczos steps "
                         f"(the model has {n} free dofs)")
    chain = lanczos_chain(model, size, contact=contact, shift_invert=shift_invert, factor=factor)
    return ReducedModel(method, size, chain.system, chain.basis, model, contact, chain=chain)


def build_plain(model: FEModel, contact: Contact, size: int, factor: SPDFactor | None = None) -> ReducedModel:
    """Plain Lanczos on ``F⁻¹KF⁻ᵀ`` (``M = FFᵀ``); ``factor`` of ``K`` is not used."""
    return _build(model, contact, size, False, None)


def build_shift_invert(model: FEModel, contact: Contact, size: int, factor: SPDFactor | None = None) -> ReducedModel:
    """Shift-invert Lanczos about 0 on ``K⁻¹M``, reusing ``factor`` (of ``K``) if given."""
    return _build(model, contact, size, True, factor)
