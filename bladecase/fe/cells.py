"""The body cell types a model accepts: node layout (meshio/VTK order), orientation, the scikit-fem element.

Every accepted meshio type is a :class:`CellKind`: its family (``tetra``, ``hexahedron``, ``wedge``,
``triangle``, ``quad``), its corner nodes (always first) and, for second-order cells, the corners each
extra node sits between (``parents``: an edge midpoint, a face centre, the cell centre, in meshio's
VTK order).  From the parents follow the midside-node checks, the order-1 interpolation of extra nodes
(:func:`bladecase.fe.node_operator`) and the node permutation that reverses a cell (:attr:`CellKind.flip`).

The assembly numbers the cells on their corners with the scikit-fem element of :data:`SKFEM_ELEMENTS` (the
second-order wedges are bladecase's own, :mod:`~bladecase.fe.wedge_element`) and, at order 2, maps second-order
cells through all their nodes (curved cells, :mod:`~bladecase.fe.isoparametric`; each extra node found by its
``parents``); :attr:`CellKind.skfem_corners` reorders meshio's corners to the numbering of ``skfem.MeshHex1``
(``skfem.io.meshio.HEX_MAPPING``), the other families need no reordering.

>>> KINDS["hexahedron20"].family, KINDS["hexahedron20"].corners, KINDS["hexahedron20"].parents[16]
('hexahedron', 8, (0, 4))
>>> KINDS["quad8"].flip
(0, 3, 2, 1, 7, 6, 5, 4)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

#: Edges of each family (corner pairs, meshio/VTK order of the midside nodes).
EDGES = {
    "triangle": ((0, 1), (1, 2), (0, 2)),
    "tetra": ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)),
    "quad": ((0, 1), (1, 2), (2, 3), (3, 0)),
    "hexahedron": ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)),
    "wedge": ((0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)),
}
#: Quadrilateral faces whose centre is a node of the 27-node hexahedron / 18-node wedge (VTK order).
_FACES = {
    "hexahedron": ((0, 3, 7, 4), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7)),
    "wedge": ((0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)),
}
#: At each corner, three (two in 2-D) neighbour corners in right-handed order: the Jacobian of a positively
#: oriented cell at the corner is the triple (cross) product of the edge vectors towards them.
CORNER_FRAMES = {
    "triangle": ((1, 2), (2, 0), (0, 1)),
    "quad": ((1, 3), (2, 0), (3, 1), (0, 2)),
    "tetra": ((1, 2, 3), (2, 0, 3), (0, 1, 3), (0, 2, 1)),
    "hexahedron": ((1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2), (6, 4, 3)),
    "wedge": ((1, 2, 3), (2, 0, 4), (0, 1, 5), (5, 4, 0), (3, 5, 1), (4, 3, 2)),
}
_CORNERS = {"triangle": 3, "quad": 4, "tetra": 4, "hexahedron": 8, "wedge": 6}
_DIM = {"triangle": 2, "quad": 2, "tetra": 3, "hexahedron": 3, "wedge": 3}
#: Corner permutation that reverses a cell's orientation.
_CORNER_FLIP = {"triangle": (0, 2, 1), "quad": (0, 3, 2, 1), "tetra": (0, 2, 1, 3),
                "hexahedron": (0, 3, 2, 1, 4, 7, 6, 5), "wedge": (0, 2, 1, 3, 5, 4)}


@dataclass(frozen=True)
class CellKind:
    """One meshio cell type: ``family``, number of ``corners``, geometric ``order`` and the ``parents``
    (corner indices) of every node, corners included (a corner is its own parent)."""

    name: str
    family: str
    parents: tuple[tuple[int, ...], ...]

    @property
    def dim(self) -> int:
        return _DIM[self.family]

    @property
    def corners(self) -> int:
        return _CORNERS[self.family]

    @property
    def order(self) -> int:
        return 1 if len(self.parents) == self.corners else 2

    @property
    def n_nodes(self) -> int:
        return len(self.parents)

    @cached_property
    def flip(self) -> tuple[int, ...]:
        """Node permutation reversing the orientation (corners by :data:`_CORNER_FLIP`, extra nodes follow)."""
        perm = _CORNER_FLIP[self.family]
        where = {frozenset(p): k for k, p in enumerate(self.parents)}
        return tuple(where[frozenset(perm[c] for c in p)] for p in self.parents)

    @cached_property
    def edge_node(self) -> dict[tuple[int, int], int]:
        """Midside node of each edge ``(a, b)`` (both directions), for second-order cells."""
        out = {}
        for k, p in enumerate(self.parents):
            if len(p) == 2:
                out[p] = out[p[::-1]] = k
        return out

    @property
    def skfem_corners(self) -> tuple[int, ...]:
        """meshio corner indices in scikit-fem's vertex order (``skfem.io.meshio``: ``t[INV_HEX_MAPPING[:8]]``)."""
        return (0, 4, 3, 1, 7, 5, 2, 6) if self.family == "hexahedron" else tuple(range(self.corners))


def _kind(name: str, family: str, faces: bool = False, centre: bool = False, order: int = 2) -> CellKind:
    parents = [(c,) for c in range(_CORNERS[family])]
    if order == 2:
        parents += list(EDGES[family])
    if faces:
        parents += list(_FACES.get(family, ((0, 1, 2, 3),)))
    if centre:
        parents.append(tuple(range(_CORNERS[family])))
    return CellKind(name, family, tuple(parents))


#: The accepted body cell types, by meshio name.
KINDS = {k.name: k for k in (
    _kind("triangle", "triangle", order=1), _kind("triangle6", "triangle"),
    _kind("quad", "quad", order=1), _kind("quad8", "quad"), _kind("quad9", "quad", faces=True),
    _kind("tetra", "tetra", order=1), _kind("tetra10", "tetra"),
    _kind("hexahedron", "hexahedron", order=1), _kind("hexahedron20", "hexahedron"),
    _kind("hexahedron27", "hexahedron", faces=True, centre=True),
    _kind("wedge", "wedge", order=1), _kind("wedge15", "wedge"), _kind("wedge18", "wedge", faces=True),
)}

#: meshio body cell types by dimension.
BODY_TYPES = {d: tuple(n for n, k in KINDS.items() if k.dim == d) for d in (2, 3)}

#: Boundary (lower-dimensional) cell types kept with a body, by dimension.
BOUNDARY_TYPES = {0: ("vertex",), 1: ("line", "line3"), 2: ("triangle", "triangle6", "quad", "quad8", "quad9")}

#: scikit-fem element names by family or mesh body type, and element order: the 27-node hexahedron, 18-node
#: wedge and 9-node quadrilateral meshes get the full quadratic elements, other meshes the serendipity ones.
#: scikit-fem has no second-order wedge: ``ElementWedgeS2`` (15 nodes) and ``ElementWedge2`` (18 nodes) are
#: :mod:`bladecase.fe.wedge_element`'s.
SKFEM_ELEMENTS = {
    ("tetra", 1): "ElementTetP1", ("tetra", 2): "ElementTetP2",
    ("triangle", 1): "ElementTriP1", ("triangle", 2): "ElementTriP2",
    ("hexahedron", 1): "ElementHex1", ("hexahedron", 2): "ElementHexS2", ("hexahedron27", 2): "ElementHex2",
    ("quad", 1): "ElementQuad1", ("quad", 2): "ElementQuadS2", ("quad9", 2): "ElementQuad2",
    ("wedge", 1): "ElementWedge1", ("wedge", 2): "ElementWedgeS2", ("wedge18", 2): "ElementWedge2",
}
#: scikit-fem mesh class names by family.
SKFEM_MESHES = {"tetra": "MeshTet1", "triangle": "MeshTri1", "hexahedron": "MeshHex1", "quad": "MeshQuad1",
                "wedge": "MeshWedge1"}

#: gmsh writes the 18-node wedge in its own order and meshio 5.3 does not convert it: gmsh → VTK order.
GMSH_WEDGE18 = (0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11, 15, 17, 16)


def element_name(body_type: str, order: int) -> str:
    """The scikit-fem element used for ``body_type`` cells at Lagrange ``order``; ``ValueError`` if none.

    >>> element_name("wedge15", 2), element_name("wedge18", 2), element_name("hexahedron27", 2)
    ('ElementWedgeS2', 'ElementWedge2', 'ElementHex2')
    """
    family = KINDS[body_type].family
    name = SKFEM_ELEMENTS.get((body_type, order)) or SKFEM_ELEMENTS.get((family, order))
    if name is None:
        have = sorted(o for f, o in SKFEM_ELEMENTS if f == family)
        raise ValueError(f"order {order} is not available for {body_type} cells (no order-{order} {family} "
                         f"element); valid: order={' or '.join(map(str, have))}")
    return name


def cell_dim(cell_type: str) -> int:
    """Topological dimension of a meshio cell type (-1 if unknown)."""
    if cell_type == "vertex":
        return 0
    if cell_type.startswith("line"):
        return 1
    if cell_type.startswith(("triangle", "quad", "polygon")):
        return 2
    if cell_type.startswith(("tetra", "hexahedron", "wedge", "pyramid", "polyhedron")):
        return 3
    return -1
