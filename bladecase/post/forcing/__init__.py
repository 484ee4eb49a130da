"""The forced response's figure.

- :mod:`~bladecase.post.forcing.plots` — a forced response over the nonsmooth-mode arcs.
"""
