"""The every-node contact study's report.

- :mod:`~bladecase.post.nodal.report` — the mode with every face node a contact, in words;
- :mod:`~bladecase.post.nodal.tip_excursion` — every node of a contact face over an orbit: how far beyond the
  clearance, where, when.
"""
