"""A bladed disk's report and figures.

- :mod:`~bladecase.post.disk.cyclic_report` — the modes in words: the nodal diameter each engine order excites,
  crossings;
- :mod:`~bladecase.post.disk.safe_plot` — the SAFE (ZZENF) diagram: frequency against nodal diameter, engine-order
  zig-zag;
- :mod:`~bladecase.post.disk.mistuning_report` — the mistuned samples in words;
- :mod:`~bladecase.post.disk.mistuning_plot` — the amplification factors' histogram against Whitehead's bound;
- :mod:`~bladecase.post.disk.annulus_orbit` — a travelling-wave nonsmooth orbit flown over the whole annulus: VTK
  frames with each tip's gap, force and casing yield, GIF/MP4;
- :mod:`~bladecase.post.disk.rub_plot` — the whole disk's rub over speeds: each blade's peak force, the
  nodal-diameter content, and the report's section.
"""
