"""Stage 4 — results: plots (matplotlib Figures), animations (pyvista), VTK series, reports.

Data in: branches and orbits from :mod:`bladecase.nsm`, the mesh and a reduced model's expansion.
Modules are imported on use (pyvista is heavy): ``from bladecase.post import animation``. Figures are
:class:`matplotlib.figure.Figure` objects made without pyplot.

Module map, one entry per module (the details are in each module's own docstring). Generic drawing sits at the
top:

- :mod:`~bladecase.post.plots` — frequency–energy figures of nonsmooth-mode branches (no pyplot);
- :mod:`~bladecase.post.grid` — ``fe_grid``: every FE node, quadratic cells whole (tetra10, hex20/27, wedge15/18,
  tri6, quad8/9, as ``mesh.vtu``); ``nodal_field``: free-dof vectors on those points, midside values from the
  model or the edge mean;
- :mod:`~bladecase.post.animation` — an orbit animated on the whole mesh with the casing (pyvista, off-screen);
- :mod:`~bladecase.post.vtk` — time series and invariant manifolds for ParaView, through pyvista;
- :mod:`~bladecase.post.prestress` — a study at speed: the centrifugal displacement and von Mises prestress as
  point data of ``mesh.vtu`` and every VTK frame;
- :mod:`~bladecase.post.report` — the Markdown report from the summary; each study kind's words come from its
  subpackage;
- :mod:`~bladecase.post.verdict` — the report's three first lines and their reason codes: thresholds and
  ``REASONS`` in ``words``, the summary read in ``base``, one module per line (``found``, ``trust``, ``advice``);
  a new reason goes into ``REASONS`` and the line that says it;
- :mod:`~bladecase.post.outputs` — one file per output format and the registry ``FORMATS``.

Then one subpackage per study kind, its report and figures, mirroring :mod:`bladecase.study` (each with its own
module map): ``rotation`` (Campbell figure, rotation words), ``rub`` (interaction diagram, worn coating),
``nodal`` (every face node a contact), ``disk`` (bladed disks: SAFE (ZZENF) diagram, mistuning), ``comparison``
(model comparison: MAC matching, table, diagnostics), ``forcing`` (forced response), ``convergence`` (mesh
convergence), ``casing`` (casing-stiffness sweep).
"""
