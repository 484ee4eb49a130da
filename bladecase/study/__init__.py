"""Studies — a TOML file (:mod:`.schema`) run through every stage (:mod:`.pipeline`).

The command line (:mod:`bladecase.cli`) is a thin layer over this package.
"""

from .pipeline import RunResult, run
from .schema import Study, StudyError, demo_study, load_study

__all__ = ["RunResult", "Study", "StudyError", "demo_study", "load_study", "run"]
