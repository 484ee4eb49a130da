"""Stage 1 — the finite-element front end: geometry (gmsh), mesh (meshio, named groups), assembly (scikit-fem).

Data in: a parametric geometry or a mesh file. Data out: an :class:`FEModel` (sparse ``K``, ``M`` on the
free dofs, the dof map) for the reduction layer.

Modules: :mod:`~bladecase.fe.naca` (sections), :mod:`~bladecase.fe.geometry` (parametric blades,
:func:`blade_mesh`), :mod:`~bladecase.fe.cad` (gmsh bodies), :mod:`~bladecase.fe.mesh` (:class:`Mesh`, files),
:mod:`~bladecase.fe.cells` (accepted cell types: tetrahedra, hexahedra, wedges, triangles, quadrilaterals),
:mod:`~bladecase.fe.groups` (named groups of mesh files), :mod:`~bladecase.fe.quality` (cell checks),
:mod:`~bladecase.fe.select` (:func:`select_nodes`: nodes by group name or coordinates),
:mod:`~bladecase.fe.material` (:class:`Material`, presets), :mod:`~bladecase.fe.model` (:class:`FEModel`,
:class:`DofMap`), :mod:`~bladecase.fe.assembly` (:func:`assemble`), :mod:`~bladecase.fe.isoparametric` (the
curved map of quadratic cells through their midside nodes), :mod:`~bladecase.fe.refine` (:func:`refine_mesh`: a
mesh's cells split, every edge in ``n``), :mod:`~bladecase.fe.rotation`
(:func:`~bladecase.fe.rotation.spin`), :mod:`~bladecase.fe.nonlinear_static` (:func:`nonlinear_state`: the
geometrically nonlinear static state, large rotations), :mod:`~bladecase.fe.campbell` (frequencies against speed),
:mod:`~bladecase.fe.eigen` (:func:`natural_frequencies`, :func:`stiffness_factor`),
:mod:`~bladecase.fe.storage` (stage files), :mod:`~bladecase.fe.calculix` (the model as a CalculiX deck, its
frequencies back), :mod:`~bladecase.fe.cyclic` (:func:`fe_sector`, :func:`cyclic_modes`: a bladed disk's modes by
nodal diameter from one sector) + :mod:`~bladecase.fe.cyclic_waves` (a sector mode on the whole disk, standing or
travelling) + :mod:`~bladecase.fe.cyclic_spin` (a spinning disk from one sector, Campbell per nodal diameter),
:mod:`~bladecase.fe.sector` (:func:`sector_mesh`: a parametric bladed-disk sector).
"""

from .assembly import assemble
from .cyclic import CyclicModes, CyclicSector, cyclic_modes, cyclic_spectrum, fe_sector
from .eigen import natural_frequencies, stiffness_factor
from .geometry import BladeGeometry, PlateGeometry, blade_mesh, cad_volume
from .isoparametric import MappingCurved, curved_geometry
from .material import AL6061T6, INCONEL718, PRESETS, STEEL, TI6AL4V, Material
from .mesh import Mesh, load_mesh, save_mesh
from .model import DofMap, FEModel, node_operator
from .naca import naca_parameters, naca_section
from .nonlinear_static import NonlinearState, nonlinear_state
from .refine import refine_mesh, splits_for
from .sector import SectorGeometry, sector_mesh
from .select import select_nodes
from .storage import load_model, model_from_arrays, model_to_arrays, save_model, sparse_from_arrays, sparse_to_arrays

__all__ = [
    "AL6061T6", "INCONEL718", "PRESETS", "STEEL", "TI6AL4V",
    "BladeGeometry", "CyclicModes", "CyclicSector",
    "DofMap", "FEModel", "MappingCurved", "Material", "Mesh", "NonlinearState", "PlateGeometry",
    "SectorGeometry",
    "assemble", "blade_mesh", "cad_volume", "curved_geometry", "cyclic_modes", "cyclic_spectrum", "fe_sector",
    "load_mesh", "load_model", "model_from_arrays",
    "model_to_arrays",
    "naca_parameters", "naca_section", "natural_frequencies", "node_operator", "nonlinear_state", "refine_mesh",
    "save_mesh", "save_model", "sector_mesh", "select_nodes", "sparse_from_arrays", "sparse_to_arrays", "splits_for",
    "stiffness_factor",
]
