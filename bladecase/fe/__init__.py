"""Stage 1 — the finite-element front end: geometry (gmsh), mesh (meshio, named groups), assembly (scikit-fem).

Data in: a parametric geometry or a mesh file. Data out: an :class:`FEModel` (sparse ``K``, ``M`` on the
free dofs, the dof map) for the reduction layer.
"""

from .assembly import DofMap, FEModel, Material, assemble, load_model, natural_frequencies, save_model
from .geometry import BladeGeometry, PlateGeometry, blade_mesh
from .mesh import Mesh, load_mesh, save_mesh

__all__ = [
    "BladeGeometry", "DofMap", "FEModel", "Material", "Mesh", "PlateGeometry",
    "assemble", "blade_mesh", "load_mesh", "load_model", "natural_frequencies", "save_mesh", "save_model",
]
