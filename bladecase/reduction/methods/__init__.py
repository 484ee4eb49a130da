"""The reduction methods, one module each, registered in :data:`bladecase.reduction.METHODS` here (theory §2).

``"full"`` (:mod:`.full`)
    No reduction (``V = I``): dense ``M``, ``K``; refused above :data:`FULL_LIMIT` dofs (or the caller's
    ``limit``, at most :data:`bladecase.nsm.system.DENSE_LIMIT`).
``"modal"`` (:mod:`.modal`)
    The ``size`` lowest M-normalised modes ``Φ`` (sparse shift-invert about
    0): ``M_r = I``, ``K_r = diag(ω²)``, ``w_r = Φᵀw``.  Keeps the lowest
    ``size`` pairs ``(ω_j, b_j)`` exactly.
``"lanczos"``, ``"lanczos-si"`` (:mod:`.lanczos`)
    ``size`` Lanczos steps started at the contact
    (:func:`bladecase.reduction.lanczos.lanczos_chain`, plain or shift-invert about 0):
    a chain of unit masses, ``LinearSystem(I, J, |ŵ|e₁, d)``, with the
    impacting mass first.  Plain Lanczos matches the moments
    ``Σ b_j² ω_j^{2p}``, ``p < 2·size`` — it resolves the top of the FE
    spectrum first, not the lowest modes; shift-invert matches
    ``Σ b_j² ω_j^{-2p}``, ``p = 1..2·size``, and converges to the lowest
    modes the contact sees.
``"craig-bampton"`` (:mod:`.craig_bampton`)
    Boundary dofs = the free dofs of the contact node (all its directions),
    kept as physical coordinates, plus ``size`` fixed-interface modes:
    ``V = [[I, 0], [Ψ, Φ_i]]`` with the constraint modes
    ``Ψ = -K_ii⁻¹K_ib`` and the lowest modes ``Φ_i`` of
    ``(K_ii, M_ii)``.  Its ``M_r`` is not diagonal, so the Moreau impact law
    (theory §1) is the one that conserves energy.

``"massless"`` (:mod:`.massless`)
    The massless contact model (theory §8): the contact dofs' lumped mass is moved to their neighbours,
    they are condensed statically in each phase; ``size`` modes of the massless structure plus the static
    attachment vector of the contact (``size=None``: every interior dof, the exact condensation); the system is
    a :class:`~bladecase.nsm.MasslessSystem` (:func:`bladecase.reduction.massless_model`, which checks ``size``
    itself: registered with ``sized=False``).

:mod:`.common` holds what the methods share: the constraint vector, size checks, Galerkin projection,
:data:`FULL_LIMIT`.

Every method but ``"full"`` works on sparse matrices only (no dense
``n × n`` array), so the ~100k-dof blades of the FE front end reduce in
seconds; see ``benchmarks/bench_reduction.py``.

Adding a method = one new file here with ``build(model, contact, size, factor=None) -> ReducedModel`` + one
registration line below (see :mod:`bladecase.reduction.registry`); the study schema's valid methods follow
:data:`METHODS`. A method that takes a compliant casing is registered with ``casing=True``.
This module also keeps the old import path ``bladecase.reduction.methods`` of :func:`reduce`,
:class:`ReducedModel`, :data:`METHODS`, :data:`FULL_LIMIT`, :func:`save_reduced` and :func:`load_reduced`.
"""

from ..model import ReducedModel, node_operator
from ..registry import METHODS, reduce, register
from ..storage import REDUCED_FORMAT, load_reduced, save_reduced
from . import craig_bampton, full, lanczos, massless, modal
from .common import FULL_LIMIT

__all__ = [
    "FULL_LIMIT", "METHODS", "REDUCED_FORMAT", "ReducedModel", "load_reduced", "node_operator", "reduce",
    "save_reduced",
]

# The registration order is the order of METHODS (messages, the study schema's documentation).
register("full", full.build, "no reduction: the dense M, K of all free dofs", sized=False, limited=True)
register("modal", modal.build, "the size lowest modes (sparse shift-invert about 0)")
register("lanczos", lanczos.build_plain, "size Lanczos steps from the contact: a chain of unit masses")
register("lanczos-si", lanczos.build_shift_invert, "size shift-invert Lanczos steps about 0: the lowest modes "
         "the contact sees, as a chain")
register("craig-bampton", craig_bampton.build, "the contact node's dofs plus size fixed-interface modes")
register("massless", massless.build, "massless contact dofs (mass moved to their neighbours, no impact law): size "
         "modes of the massless structure plus the contact's attachment vector (None: exact)", sized=False, casing=True)
register("massless-lanczos", massless.build_krylov, "massless contact dofs, the interior reduced by size "
         "shift-invert Lanczos steps on the redistributed mass from the attachment vector (size + 1 dofs)", casing=True)
register("massless-modal", massless.build_modal, "massless contact dofs, the interior reduced to the size lowest "
         "modes of the massless structure (no attachment vector: the static compliance is truncated)", casing=True)
