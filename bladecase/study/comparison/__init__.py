"""The comparison study: every model against the FE model, the reference model included.

- :mod:`~bladecase.study.comparison.stage` — the comparison stage: ``comparison.csv``, the figures, the verdict.

The names of :mod:`~bladecase.study.comparison.stage` are re-exported here.
"""

from .stage import (
    DEFAULT_PERIODS,
    DPI,
    FE_MODES,
    FIGURES,
    SUMMARY_KEYS,
    compare_models,
    summary_section,
)

__all__ = ["DEFAULT_PERIODS", "DPI", "FE_MODES", "FIGURES", "SUMMARY_KEYS", "compare_models", "summary_section"]
