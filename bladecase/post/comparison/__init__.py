"""Model comparison: MAC matching, contact spectral data, table and verdict, diagnostics, figures.

- :mod:`~bladecase.post.comparison.compare` — MAC matching and contact spectral data;
- :mod:`~bladecase.post.comparison.table` — the table and its verdict;
- :mod:`~bladecase.post.comparison.diagnose` — diagnostics in words;
- :mod:`~bladecase.post.comparison.plots` — the figures.
"""
