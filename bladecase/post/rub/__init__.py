"""The rub study's report and figures.

- :mod:`~bladecase.post.rub.report` — the rub response in words;
- :mod:`~bladecase.post.rub.plot` — the interaction diagram;
- :mod:`~bladecase.post.rub.friction_modes_plot` — the mode with friction: frequency and damping ratio against
  amplitude;
- :mod:`~bladecase.post.rub.wear_plot` — the worn coating unrolled over the angle, per revolution.
"""
