"""The mesh-convergence study (``[convergence] meshes``).

- :mod:`~bladecase.study.convergence.stage` — the study on finer meshes through the executor, each headline figure's
  observed order, Richardson extrapolation and mesh error.

The names of :mod:`~bladecase.study.convergence.stage` are re-exported here.
"""

from .stage import (
    FIGURES,
    FLAG,
    SAFETY,
    SAFETY_UNESTABLISHED,
    convergence_stage,
    estimate_words,
    mesh_figures,
    mesh_row,
    mesh_size,
    refined_mesh,
    richardson,
    scaled_study,
)

__all__ = ["FIGURES", "FLAG", "SAFETY", "SAFETY_UNESTABLISHED", "convergence_stage", "estimate_words", "mesh_figures",
           "mesh_row", "mesh_size", "refined_mesh", "richardson", "scaled_study"]
