"""Stage 4 — results: plots (matplotlib Figures), animations (pyvista), VTK series, reports.

Data in: branches and orbits from :mod:`bladecase.nsm`, the mesh and a reduced model's expansion.
Modules are imported on use (pyvista is heavy): ``from bladecase.post import animation``. Generic drawing sits at
the top (``plots``, ``grid``, ``animation``, ``vtk``, ``prestress``, ``report``, ``verdict``, ``outputs``); each study
kind's report and figures in a subpackage of the kind's name, mirroring :mod:`bladecase.study`: ``rotation``, ``rub``,
``nodal``, ``disk`` (``disk.safe_plot`` draws a bladed disk's SAFE (ZZENF) diagram), ``comparison``, ``forcing``,
``convergence``, ``casing``.
"""
