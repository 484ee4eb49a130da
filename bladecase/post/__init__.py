"""Stage 4 — results: plots (matplotlib Figures), animations (pyvista), VTK series, reports.

Data in: branches and orbits from :mod:`bladecase.nsm`, the mesh and a reduced model's expansion.
Modules are imported on use (pyvista is heavy): ``from bladecase.post import animation``; ``safe_plot`` draws a
bladed disk's SAFE (ZZENF) diagram.
"""
