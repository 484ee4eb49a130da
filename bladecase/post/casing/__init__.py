"""The casing's stiffness in a study: the casing-stiffness sweep's figure and words, and a casing too
soft to matter.

- :mod:`~bladecase.post.casing.report` — the casing-stiffness sweep's figure and words;
- :mod:`~bladecase.post.casing.words` — a casing too soft to matter, in words: its stiffness against the blade's own
  at the contact.

The names of :mod:`~bladecase.post.casing.report` are re-exported here.
"""

from .report import (
    casing_figure,
    casing_report,
)

__all__ = ["casing_figure", "casing_report"]
