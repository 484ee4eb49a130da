"""The registry of reduction methods, and :func:`reduce`, the front door of the reduction layer.

A method is a name, a builder and a one-line summary.  The builder turns a model and its contact into a
:class:`~bladecase.reduction.model.ReducedModel`::

    builder(model: FEModel, contact: Contact, size: int | None, factor: SPDFactor | None = None) -> ReducedModel

``size`` has been checked to be an integer >= 1 (``sized=True``, the default) or is passed as given
(``sized=False``, e.g. ``"full"``); ``factor`` is the caller's factorisation of ``model.K``
(:func:`bladecase.fe.stiffness_factor`) or ``None`` — a builder that factorises ``K`` should reuse it.
A method that keeps the whole model dense (``limited=True``, e.g. ``"full"``) also takes ``limit=``, the
largest number of free dofs it may take (:func:`reduce`'s ``limit``).
:data:`METHODS` is the registry of :func:`reduce`: it iterates over the names in registration order, so it
is used as the tuple of names it was before (``", ".join(METHODS)``, ``method in METHODS``).

Adding a method = one new file in ``bladecase/reduction/methods/`` + one registration line in
``bladecase/reduction/methods/__init__.py``.  For example, a Guyan (static) condensation onto the contact
node's dofs::

    # bladecase/reduction/methods/guyan.py
    import numpy as np
    from ...linalg import spd_factor
    from ..model import ReducedModel
    from .common import projected_system

    def build(model, contact, size=None, factor=None):
        b = contact.dofs(model)
        inner = np.setdiff1d(np.arange(model.n_dofs), b)
        K_ii = model.K[inner][:, inner]
        V = np.zeros((model.n_dofs, b.size))
        V[b, np.arange(b.size)] = 1.0
        V[inner] = -spd_factor(K_ii, "K_ii").solve(model.K[inner][:, b].toarray())
        return ReducedModel("guyan", b.size, projected_system(model, contact, V), V, model, contact)

    # bladecase/reduction/methods/__init__.py
    register("guyan", guyan.build, "static condensation onto the contact node's dofs", sized=False)

A massless-boundary Craig–Bampton is such a new file.  The same :class:`Registry` serves other pluggable
choices: contact models (e.g. ``"massless"``: contact dofs without inertia) can be a
``Registry("contact model")`` whose entries the builders consult through the contact they are given.

>>> registry = Registry("demo method")
>>> _ = registry.register("twice", lambda model, contact, size, factor=None: 2 * size, "doubles the size")
>>> list(registry), "twice" in registry, registry.entry("twice").builder(None, None, 21)
(['twice'], True, 42)
>>> registry.entry("thrice")
Traceback (most recent call last):
    ...
ValueError: unknown demo method 'thrice' (valid: 'twice')
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..checks import integer
from ..fe import FEModel
from ..linalg import SPDFactor, check_factor
from ..registry import Registry as BaseRegistry
from .contact import Contact
from .model import ReducedModel

__all__ = ["METHODS", "Entry", "Registry", "reduce", "register"]

#: ``builder(model, contact, size, factor=None) -> ReducedModel``.
Builder = Callable[..., ReducedModel]


@dataclass(frozen=True)
class Entry:
    """One registered method: its ``name``, ``builder``, one-line ``summary``, whether it takes a ``size``,
    whether it takes a compliant casing (``casing``: a contact law without impacts; the others model Newton's
    impact law, which :func:`reduce` refuses against a compliant casing), and whether its cost is that of the
    whole model kept dense (``limited``: the builder takes ``limit=``, the most free dofs it may keep)."""

    name: str
    builder: Builder
    summary: str
    sized: bool = True
    casing: bool = False
    limited: bool = False


class Registry(BaseRegistry[Entry]):
    """Reduction methods by name, in registration order; a read-only sequence of their names.

    Parameters
    ----------
    kind : str
        What an entry is, for messages (``"reduction method"``).
    """

    def register(self, name: str, builder: Builder, summary: str, *, sized: bool = True,
                 casing: bool = False, limited: bool = False) -> Entry:
        """Add an entry; ``ValueError`` for an empty or taken name or a builder that is not callable."""
        if not callable(builder):
            raise ValueError(f"the builder of {self.kind} {name!r} must be callable, got {builder!r}")
        return self.add(Entry(name, builder, str(summary), bool(sized), bool(casing), bool(limited)))


#: The reduction methods of :func:`reduce`, by name (filled by :mod:`bladecase.reduction.methods`).
METHODS = Registry("reduction method")


def register(name: str, builder: Builder, summary: str, *, sized: bool = True, casing: bool = False,
             limited: bool = False) -> Entry:
    """Register a reduction method in :data:`METHODS` (see the module docstring)."""
    return METHODS.register(name, builder, summary, sized=sized, casing=casing, limited=limited)


def reduce(
    model: FEModel, contact: Contact, method: str, size: int | None = None, *, factor: SPDFactor | None = None,
    limit: int | None = None,
) -> ReducedModel:
    """Reduce a finite-element model with one contact to the system the solver consumes.

    Parameters
    ----------
    model : FEModel
        A clamped model (:func:`bladecase.assemble`).
    contact : Contact
        Contact node, casing normal and clearance (:class:`bladecase.reduction.contact.Contact`);
        ``contact.w(model)`` is the constraint vector on the free dofs.
    method : str
        One of :data:`METHODS`: ``"full"``, ``"modal"``, ``"lanczos"``, ``"lanczos-si"``,
        ``"craig-bampton"``, ``"massless"`` (see :mod:`bladecase.reduction.methods`).
    size : int or None
        Modes (``"modal"``, ``1 <= size <= n_free``), fixed-interface modes
        (``"craig-bampton"``, ``1 <= size <= n_free - n_boundary``) or
        Lanczos steps (``1 <= size <= n_free``).  Asking for more than half
        of the available modes switches to a dense eigen-solution, allowed
        up to :data:`~bladecase.reduction.FULL_LIMIT` dofs.  ``"full"`` takes
        ``None`` (or ``n_free``).  ``"massless"``: modes of the massless
        structure (``1 <= size <= n_interior - 1``, plus the attachment
        vector), or ``None`` for the exact condensation of a small model
        (:func:`bladecase.reduction.massless_model`).
    factor : SPDFactor or None
        ``bladecase.fe.stiffness_factor(model)`` to reuse a factorisation of
        ``K`` (``"modal"`` and ``"lanczos-si"`` use it); computed when needed if ``None``.
    limit : int or None
        The most free dofs a method that keeps the whole model dense (``"full"``) may take; ``None``:
        :data:`~bladecase.reduction.FULL_LIMIT`.  Refused before any matrix is made dense; the other methods
        ignore it.

    Returns
    -------
    ReducedModel

    Raises
    ------
    ValueError
        Unknown method (the message lists the valid ones), a bad size, a
        ``"full"`` model above ``FULL_LIMIT`` dofs, a contact node with
        no free dof, an unclamped model (``model.rigid_modes > 0``: refused by every method alike), a
        ``factor`` of another matrix.

    Examples
    --------
    >>> import numpy as np
    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.reduction import Contact
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> contact = Contact.nearest(model, (0.1, 0.02), normal=(1.0, 0.0), gap=1e-4)
    >>> reduced = reduce(model, contact, "lanczos-si", 6)
    >>> reduced
    ReducedModel('lanczos-si', size=6, 6 reduced dofs of 200 free dofs, gap=0.0001)
    >>> reduce(model, contact, "guyan", 6)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: unknown reduction method 'guyan' (valid: 'full', 'modal', 'lanczos', 'lanczos-si', ...)
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    entry = METHODS.entry(method)
    if not isinstance(contact, Contact):
        raise ValueError(
            f"contact must be a bladecase.Contact (node, normal, gap), got {type(contact).__name__}"
        )
    if model.rigid_modes:
        raise ValueError(f"the model is not clamped: {model.rigid_modes} rigid-body motion(s) are free, so K is "
                         f"singular; clamp a face of every part (every reduction, {method!r} included, needs a "
                         "clamped model)")
    if not entry.casing:
        contact.rigid(f"method {method!r} (Newton's impact law)")
    factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
    if entry.sized:
        if size is None:
            raise ValueError(f"method {method!r} needs a size (an integer >= 1), got None")
        size = integer("size", size, 1, note=" (modes or Lanczos steps)")
    if entry.limited:
        return entry.builder(model, contact, size, factor=factor, limit=limit)
    return entry.builder(model, contact, size, factor=factor)
