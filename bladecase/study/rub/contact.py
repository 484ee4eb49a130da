"""The ``[rub]`` stage's contact selection, checked before any factorisation: the nodes of a face, each with its
share of the face's area, or a line of tip nodes (as the published Rotor 37 rub benchmark lists them: no facet of
the body among them), each with its tributary length along the line."""

from __future__ import annotations

import numpy as np

from ...reduction.contact import Contact, tributary_areas, tributary_lengths
from ..keys import StudyError

__all__ = ["check_rub_contact", "contact_measure"]


def contact_measure(model, contact: Contact) -> tuple[str, np.ndarray]:
    """``(kind, shares)``: each contact node's tributary area (``"area"``, m²) when the nodes hold facets of the
    body — a face —, else each one's tributary length along the line they form (``"length"``, m): a line of tip
    nodes, as a published rub benchmark lists them (:func:`bladecase.reduction.contact.tributary_lengths`).

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 11), np.linspace(0, 0.02, 3))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> top = np.flatnonzero(p[:, 1] == 0.02)[[2, 5, 8]]          # 3 nodes 30 mm apart along the top edge
    >>> kind, shares = contact_measure(model, Contact.face(model, top, (0.0, 1.0), 1e-4))
    >>> kind, (shares * 1e3).round(6).tolist()                    # no edge of the body joins them: lengths (mm)
    ('length', [15.0, 30.0, 15.0])
    """
    nodes = np.asarray(contact.nodes, dtype=int)
    try:
        return "area", tributary_areas(model, nodes)
    except ValueError:  # the nodes hold no boundary facet: a line of nodes
        return "length", tributary_lengths(np.asarray(model.mesh.points, dtype=float)[nodes])


def check_rub_contact(study, model, contact: Contact) -> tuple[str, np.ndarray]:
    """The ``[rub]`` stage's check of the contact selection, before any factorisation: the nodes of a face
    (``[contact] face`` or ``nodes``), each with a share of it — of its area, or of its length for a line of
    nodes (:func:`contact_measure`). :class:`StudyError` naming the nodes and what would be valid otherwise;
    returns ``(kind, shares)``.

    >>> from types import SimpleNamespace
    >>> try:
    ...     check_rub_contact({"contact": {}}, None, SimpleNamespace(nodes=(7,)))
    ... except StudyError as exc:
    ...     print(str(exc).split(":")[0])
    [rub] needs one contact per node of a face or of a line of tip nodes
    """
    nodes = list(contact.nodes)
    if len(nodes) < 2:
        raise StudyError("[rub] needs one contact per node of a face or of a line of tip nodes: give [contact] face "
                         '= "<group>" or nodes = [...] (node numbers of the mesh), not one contact point')
    kind, shares = contact_measure(model, contact)
    ids = [model.mesh.node_id(k) for k in nodes]
    if kind == "length":
        if study["contact"].get("casing_stiffness_per_area") is not None:
            raise StudyError(f"[contact] casing_stiffness_per_area: the {len(nodes)} contact nodes are a line (they "
                             "hold no facet of the body), so they have no area to share a stiffness per unit area; "
                             "give casing_stiffness (N/m in total: a line of nodes shares it by each node's tributary "
                             "length), or a face of nodes")
        bad = [i for i, x in zip(ids, shares) if x <= 0]
        if bad:
            raise StudyError(f"[contact] nodes: the nodes {bad} coincide with another contact node, so they have no "
                             "length of the line to themselves: list each point of the line once")
    else:
        bad = [i for i, x in zip(ids, shares) if x <= 0]
        if bad:
            raise StudyError(f"[contact]: the contact nodes {bad} hold no facet of the face with the others (a "
                             "mid-side node, or a node off the face): they have no share of its area — give the nodes "
                             "of one face, or only nodes along a line (each then takes its tributary length)")
    return kind, shares
