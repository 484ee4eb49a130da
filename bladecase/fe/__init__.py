"""Stage 1 — the finite-element front end: geometry (gmsh), mesh (meshio, named groups), assembly (scikit-fem).

Data in: a parametric geometry or a mesh file. Data out: an :class:`FEModel` (sparse ``K``, ``M`` on the
free dofs, the dof map) for the reduction layer.

Module map, one entry per module (the details are in each module's own docstring):

- :mod:`~bladecase.fe.geometry` — parametric blades and plates meshed by gmsh (:func:`blade_mesh`); the
  cell-count estimate that refuses a runaway size;
- :mod:`~bladecase.fe.shapes` — :class:`BladeGeometry`, :class:`PlateGeometry`: the shapes and their checks;
- :mod:`~bladecase.fe.naca` — NACA 4-digit sections;
- :mod:`~bladecase.fe.cad` — gmsh bodies;
- :mod:`~bladecase.fe.sector` — :func:`sector_mesh`: a parametric bladed-disk sector;
- :mod:`~bladecase.fe.mesh` — :class:`Mesh`, files through meshio; the formats meshio lacks registered once
  (``_register_types``);
- :mod:`~bladecase.fe.mesh_checks` — a mesh checked where it enters (a regular complete file, a plausible extent,
  cells that refer to existing nodes, no unmerged nodes); :class:`~bladecase.fe.mesh_checks.DeckError`, the base of
  the format readers' errors, and ``SNIFFERS``, the formats' content sniffers, which the readers register: it
  imports no format;
- :mod:`~bladecase.fe.cdb` — ANSYS archives, registered with meshio;
- :mod:`~bladecase.fe.abaqus` — Abaqus and CalculiX decks whatever their suffix (``*INCLUDE``, sets, ``*BOUNDARY``
  node lists as groups, the file's node numbers kept);
- :mod:`~bladecase.fe.abaqus_sets` — what a deck's records mean: its numbering, the ``*BOUNDARY`` groups, the
  body's material;
- :mod:`~bladecase.fe.abaqus_surfaces` — element-based ``*SURFACE``s (faces ``S1``…``S6`` of each element type, as
  CalculiX numbers them) read as node groups;
- :mod:`~bladecase.fe.abaqus_write` — decks written for CalculiX;
- :mod:`~bladecase.fe.calculix` — the model as a CalculiX deck, its frequencies back;
- :mod:`~bladecase.fe.groups` — named node groups of each format;
- :mod:`~bladecase.fe.cells` — the accepted body cell types (tetrahedra, hexahedra, wedges, triangles,
  quadrilaterals): node layouts, orientation, scikit-fem element;
- :mod:`~bladecase.fe.wedge_element` — the quadratic prisms scikit-fem lacks (15-node serendipity, 18-node
  Lagrange);
- :mod:`~bladecase.fe.isoparametric` — quadratic cells curved through their midside nodes;
- :mod:`~bladecase.fe.refine` — :func:`refine_mesh`: a mesh's cells split, every edge in ``n``, on the cells' own
  map, the named groups carried (the finer meshes of ``[convergence]`` for a mesh file);
- :mod:`~bladecase.fe.select` — :func:`select_nodes`: a group, or nodes by plane, box, sphere or nearest;
- :mod:`~bladecase.fe.quality` — cell checks;
- :mod:`~bladecase.fe.material` — :class:`Material`, presets; a mesh file's own material converted to SI;
- :mod:`~bladecase.fe.model` — :class:`FEModel`, :class:`DofMap`;
- :mod:`~bladecase.fe.assembly` — :func:`assemble`: scikit-fem ``K``, ``M``;
- :mod:`~bladecase.fe.eigen` — :func:`natural_frequencies`, :func:`stiffness_factor`;
- :mod:`~bladecase.fe.centrifugal` — the rotating frame: ``RotationAxis``, speed units, a model's centrifugal
  operators at unit speed (the type that :mod:`~bladecase.fe.rotation` and
  :mod:`~bladecase.fe.nonlinear_static` share);
- :mod:`~bladecase.fe.rotation` — ``spin``: a model linearised about its centrifugal state (stress stiffening,
  spin softening) at one speed;
- :mod:`~bladecase.fe.nonlinear_static` — :func:`nonlinear_state`: the geometrically nonlinear centrifugal state
  (total Lagrangian St-Venant–Kirchhoff, follower load) and its full tangent, as CalculiX's NLGEOM;
- :mod:`~bladecase.fe.krylov` — :class:`~bladecase.fe.krylov.ReusedFactor`: solves with nearby symmetric matrices
  (Newton's tangents, a sweep's speeds) by conjugate gradients preconditioned with one reused factorisation;
- :mod:`~bladecase.fe.stress` — ``nodal_stress`` (each element's stress at its nodes, averaged), ``stress_modes``
  (many displacements in one pass), ``von_mises``;
- :mod:`~bladecase.fe.campbell` — frequencies against speed, modes followed by MAC, engine-order crossings;
- :mod:`~bladecase.fe.cyclic` — :func:`fe_sector`, :func:`cyclic_modes`: a bladed disk's sector, its cyclic faces
  matched by rotation, modes per nodal diameter with one factorisation each;
- :mod:`~bladecase.fe.cyclic_waves` — a sector mode on the whole disk: standing and forward/backward travelling
  waves, the annulus as one mesh;
- :mod:`~bladecase.fe.cyclic_spin` — the sector's centrifugal state with its faces tied, Campbell per nodal
  diameter;
- :mod:`~bladecase.fe.storage` — stage files.
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
