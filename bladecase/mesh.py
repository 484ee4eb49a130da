"""The mesh that travels from geometry (or a user's file) to the FE assembly.

A :class:`Mesh` is plain data: node coordinates, cells by meshio cell type,
and named node groups.  :func:`load_mesh` reads any format meshio reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: meshio cell types accepted as the body of a model, by dimension and order.
VOLUME_TYPES = {3: {1: "tetra", 2: "tetra10"}, 2: {1: "triangle", 2: "triangle6"}}


@dataclass(frozen=True, eq=False)
class Mesh:
    """A simplex mesh with named groups.

    Attributes
    ----------
    points : (n_nodes, 3) float ndarray
        Node coordinates (``z = 0`` for planar meshes).
    cells : dict[str, ndarray]
        Connectivity by meshio cell type (``"tetra"``, ``"tetra10"``,
        ``"triangle"``, ``"triangle6"``, ``"line"``, ``"vertex"``, …), node
        indices into ``points`` (0-based), gmsh/meshio node ordering.
    dim : int
        2 (planar, plane stress) or 3 (solid).
    groups : dict[str, ndarray]
        Named node sets (sorted unique node indices): physical groups, cell
        sets and node sets of the source file, e.g. ``"root"``, ``"tip"``,
        ``"blade"``.
    source : str
        Where the mesh came from (file path or generator), for messages.
    """

    points: np.ndarray
    cells: dict
    dim: int
    groups: dict = field(default_factory=dict)
    source: str = ""

    @property
    def body_type(self) -> str:
        """The meshio type of the body cells (tetra/tetra10 in 3-D, triangle/triangle6 in 2-D)."""
        for order in (2, 1):
            t = VOLUME_TYPES[self.dim][order]
            if t in self.cells and len(self.cells[t]):
                return t
        raise ValueError(f"mesh {self.source or ''} has no {self.dim}-D simplex cells")

    @property
    def order(self) -> int:
        """Geometric order of the body cells (1 or 2)."""
        return 2 if self.body_type in ("tetra10", "triangle6") else 1

    def group(self, name: str) -> np.ndarray:
        """Node indices of group ``name``; ``ValueError`` naming the groups that exist."""
        if name not in self.groups:
            have = ", ".join(sorted(self.groups)) or "none"
            raise ValueError(f"mesh {self.source or ''} has no group {name!r} (groups: {have})")
        return self.groups[name]
