"""Method ``"massless"``: :func:`bladecase.reduction.massless.massless_model` as a registered method (theory §8).

The contact dofs lose their lumped mass (moved to their neighbours, total mass and centre of mass kept per
direction) and are condensed statically in each phase; the interior is reduced to ``size`` modes of the massless
structure plus the contact's attachment vector (``size + 1`` dofs, the static contact compliance exact), or kept
whole (``size=None``: the exact condensation, small models). The system is a :class:`~bladecase.nsm.MasslessSystem`.
This module keeps the former import path of :class:`MasslessReducedModel` and :func:`massless_masses`.
"""

from __future__ import annotations

from ...fe import FEModel
from ...linalg import SPDFactor
from ..contact import Contact
from ..massless import MasslessReducedModel, massless_masses, massless_model

__all__ = ["MasslessReducedModel", "build", "build_krylov", "build_modal", "massless_masses"]


def build(model: FEModel, contact: Contact, size: int | None, factor: SPDFactor | None = None
          ) -> MasslessReducedModel:
    """``size`` modes of the massless structure plus the attachment vector, or (``None``) every interior dof."""
    return massless_model(model, contact, size, factor=factor)


def build_krylov(model: FEModel, contact: Contact, size: int | None, factor: SPDFactor | None = None
                 ) -> MasslessReducedModel:
    """Shift-invert Lanczos on the redistributed mass: ``size`` Krylov steps from the attachment vector."""
    return massless_model(model, contact, size, factor=factor, basis="krylov")


def build_modal(model: FEModel, contact: Contact, size: int | None, factor: SPDFactor | None = None
                ) -> MasslessReducedModel:
    """The ``size`` lowest modes of the massless structure, without the attachment vector."""
    return massless_model(model, contact, size, factor=factor, basis="modal")
