"""A bladed-disk study: ``[geometry] kind = "sector"``, ``[cyclic]`` or a deck's cyclic symmetry, and
``[mistuning]``.

Import from the modules (``from bladecase.study.disk.cyclic import compute_linear``): the schema reads
the key modules, so this package's ``__init__`` imports nothing.

- :mod:`~bladecase.study.disk.cyclic` — modes per nodal diameter, ``cyclic.csv``, ``safe.png``, the whole disk's
  wave as a VTK series, Campbell per nodal diameter;
- :mod:`~bladecase.study.disk.cyclic_keys` — the ``[cyclic]`` section;
- :mod:`~bladecase.study.disk.mistuning` — the reduced mistuning model from the study's own sector, samples through
  the executor, ``mistuning.csv``, ``mistuning.png``, Whitehead's bound;
- :mod:`~bladecase.study.disk.mistuning_keys` — the ``[mistuning]`` section;
- :mod:`~bladecase.study.disk.nonsmooth` — ``[cyclic] nonsmooth``: the disk's travelling-wave nonsmooth modes,
  ``disk_modes.csv``, their return and stability, the annulus animation;
- :mod:`~bladecase.study.disk.mistuning_contact` — the mistuned disk's forced rub, ``mistuning_contact.csv``;
- :mod:`~bladecase.study.disk.rub` — ``[rub] speeds`` in a cyclic study: the whole disk's rub in the out-of-round
  ``[casing]``, one task per speed, ``disk_rub.csv``, ``disk_rub.png``.
"""
