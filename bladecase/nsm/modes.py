"""Finding the nonsmooth modes of a system: :func:`nonsmooth_mode`, for either contact model.

Newton contact: every k-ipp family started from the orbits found at ``scan`` periods
(:func:`~bladecase.nsm.kipp.orbits_kipp`) and followed by continuation (:mod:`~bladecase.nsm.families`);
``k = 1`` is a scan (:func:`~bladecase.nsm.scan.backbone`). Massless contact: the branches grown from the
open-phase modes at grazing (:mod:`~bladecase.nsm.massless_branches`). All are :class:`~bladecase.nsm.Branch` es.
"""

from __future__ import annotations

import numpy as np

from ..progress import progress_bar, progress_counter
from .branches import Arc, Branch
from .families import follow_family, passes
from .kipp import check_k, orbits_kipp
from .system import LinearSystem

__all__ = ["MASSLESS_MIN_POINTS", "nonsmooth_mode"]

#: Least point budget of a massless branch: its steps are short where the contact time grows fast.
MASSLESS_MIN_POINTS = 4000


def nonsmooth_mode(
    system: LinearSystem,
    k: int,
    T_range: tuple[float, float],
    scan: int = 24,
    step: float = 0.01,
    max_points: int = 400,
    refine: bool = True,
    progress: bool = False,
    resolution: int | None = None,
) -> list[Branch]:
    """Follow every k-ipp family (nonsmooth mode) found in ``T_range``.

    Parameters
    ----------
    system : LinearSystem or MasslessSystem
        A Newton-contact system, or a massless-contact one (:class:`~bladecase.nsm.MasslessSystem`, from
        :func:`~bladecase.nsm.bar` or a massless reduced model): then ``k = 1`` (one contact phase per
        period) and each branch grows from an open-phase linear mode at grazing
        (:mod:`~bladecase.nsm.massless_branches`).
    k : int
        Impacts (contact phases) per period (>= 1).
    T_range : (T_min, T_max)
        Periods of interest; the curves are followed until they leave it.
    scan : int
        Number of periods (evenly spaced in ``T_range``, resonant ones
        skipped) where :func:`orbits_kipp` looks for starting orbits.
        Orbits that are repetitions of shorter-period orbits (``repeats >
        1``) are not followed: they are not new modes.
    step : float
        Initial arclength step in scaled unknowns (times / ``T``); it adapts
        between ``step/1000`` and ``2·step``.
    max_points : int
        Cap on points per direction of each family.
    refine : bool
        Refine the ends of the admissible arcs by bisection along the curve
        (relative precision ``ARC_RTOL`` in ``T``).
    progress : bool
        Progress bar over the starting periods.
    resolution : int or None
        Grid points per impact time of the k >= 3 multistart search at each
        starting period (:func:`orbits_kipp`); ``None`` for its default.

    Returns
    -------
    list of Branch
        Each family's orbits in curve order (all within ``T_range``), certified,
        with admissible arcs.  A family crossing a later scan period is not
        started again there.  k = 1: the one 1-ipp branch (a scan of
        ``max(scan, 200)`` periods, resonant points left out).

    Examples
    --------
    The paper's 2-dof chain: the 2-ipp mode ending at ``5T₂ = 13.7293`` (seed Fig. 2).

    >>> from bladecase.nsm import chain
    >>> families = nonsmooth_mode(chain(2, k=1.0, m=0.5, gap=1.0), 2, (13.2, 13.75), scan=2)
    >>> len(families), [(round(a.T_lo, 3), round(a.T_hi, 4), a.refined_hi) for f in families for a in f.arcs]
    (4, [(13.329, 13.7293, True)])
    """
    k = check_k(k)
    T_lo, T_hi = (float(x) for x in T_range)
    if not (np.isfinite(T_lo) and np.isfinite(T_hi)) or not 0 < T_lo < T_hi:
        raise ValueError(f"T_range must be (T_min, T_max) with 0 < T_min < T_max, got {T_range!r}")
    if getattr(system, "contact_model", "newton") == "massless":
        if k != 1:
            raise ValueError(f"the massless contact model has modes with one contact phase per period (k = 1) "
                             f"so far; got k = {k}")
        from .massless_branches import massless_modes

        return massless_modes(system, (T_lo, T_hi), max_points=max(max_points, MASSLESS_MIN_POINTS), refine=refine)
    if k == 1:
        from .scan import backbone

        return [backbone(system, np.linspace(T_lo, T_hi, max(scan, 200))).compact()]
    starts = []
    for T in progress_bar(np.linspace(T_lo, T_hi, scan), f"{k}-ipp starts", enabled=progress, unit="T"):
        try:
            sols = orbits_kipp(system, T, k, resolution=resolution)
        except ValueError:
            continue
        starts.extend((T, o) for o in sols if o.repeats == 1)
    families: list[Branch] = []
    covered = [False] * len(starts)
    with progress_counter(len(starts), f"{k}-ipp families", enabled=progress, unit="start") as bar:
        for n, (_, o) in enumerate(starts):
            bar.update()
            if covered[n]:
                continue
            fam = follow_family(system, k, o, (T_lo, T_hi), step, max_points, refine)
            for m in range(n + 1, len(starts)):
                if not covered[m] and passes(fam.problem, fam.points, starts[m]):
                    covered[m] = True
            families.append(Branch(system=system, k=k, orbits=fam.orbits, arcs=[Arc(*a) for a in fam.arcs]))
            bar.set_postfix_str(f"{len(families)} families, {sum(1 for f in families if f.arcs)} with arcs")
    return families
