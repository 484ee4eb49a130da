"""A rotating blade's report and figure, and the report of a study without a contact.

- :mod:`~bladecase.post.rotation.report` — the report's rotation and Campbell words;
- :mod:`~bladecase.post.rotation.campbell` — the Campbell figure with engine orders and nonsmooth-mode bands;
- :mod:`~bladecase.post.rotation.modes_report` — the report of a study without a contact.
"""
