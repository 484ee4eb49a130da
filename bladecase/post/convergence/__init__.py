"""The mesh-convergence study's report.

- :mod:`~bladecase.post.convergence.report` — the mesh-convergence section, or that the mesh error is unknown.
"""
