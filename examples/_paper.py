"""What the seed-paper examples share: the paper's 2-dof system, its 2-ipp families and the
nonsmooth mode of Figs. 2–4, and the scripts' command line.

System: the 2-dof spring–mass chain of the paper's Sec. 1.4
(``bladecase.chain(2, k=1, m=1/2, gap=1)``, ω = 0.874, 2.288, linear periods
T₁ = 7.1887, T₂ = 2.7459).  Its 2-ipp families are followed with
``bladecase.nonsmooth_mode(sys, 2, (3, 14.5), scan=24)``; the paper's mode
(the red curve of Fig. 2) is the admissible arc whose upper end is closest to
``5T₂ = 13.7293``: from ① (T ≈ 13.33, ``t₁ = T/2``, a 1-ipp orbit of period
``T/2`` counted twice) to ② (``T → 5T₂``, where the impulses vanish and
``t₁ → 2T₂``: the fifth harmonic of linear mode 2 grazing the obstacle).

Not an example itself: the scripts import it (``import _paper as paper``) after
putting their own folder on ``sys.path``, so that this works both for
``python examples/X.py`` and when a script is loaded by path.
"""

from __future__ import annotations

import argparse
import functools
import time

import numpy as np

import bladecase
from bladecase.nsm import Arc, Branch

FAMILY_RANGE = (3.0, 14.5)  # periods where the 2-ipp families are followed


@functools.cache
def two_dof() -> bladecase.LinearSystem:
    """The paper's Sec. 1.4 system: k₁ = k₂ = 1, m₁ = m₂ = 1/2, d = 1 (one shared instance)."""
    return bladecase.chain(2, k=1.0, m=0.5, gap=1.0)


def five_T2(system: bladecase.LinearSystem | None = None) -> float:
    """``5T₂ = 5·2π/ω₂``: the resonant period where the paper's mode ends (②)."""
    system = two_dof() if system is None else system
    return 5 * 2 * np.pi / float(system.spectrum.omega[1])


@functools.cache
def _families(system: bladecase.LinearSystem) -> tuple[Branch, ...]:
    return tuple(bladecase.nonsmooth_mode(system, 2, FAMILY_RANGE, scan=24))


def two_ipp_families(system: bladecase.LinearSystem | None = None) -> list[Branch]:
    """Every 2-ipp family of ``system`` with periods in ``FAMILY_RANGE``
    (``nonsmooth_mode(system, 2, FAMILY_RANGE, scan=24)``, computed once per system instance)."""
    return list(_families(two_dof() if system is None else system))


def paper_arc(system: bladecase.LinearSystem | None = None) -> tuple[Branch, Arc]:
    """The 2-ipp family and admissible arc of the paper's Figs. 2–4: the arc whose
    upper end is closest to ``5T₂``."""
    system = two_dof() if system is None else system
    pairs = [(f, a) for f in two_ipp_families(system) for a in f.arcs]
    if not pairs:
        raise RuntimeError("no admissible 2-ipp arc found")
    return min(pairs, key=lambda fa: abs(fa[1].T_hi - five_T2(system)))


def paper_mode(system: bladecase.LinearSystem | None = None) -> Branch:
    """The paper's nonsmooth mode from ① to ②, as a :class:`bladecase.nsm.Branch` holding
    only the orbits of :func:`paper_arc`, sorted by ``T`` (one arc, ``arcs[0]``), so that
    ``manifold()`` samples that arc alone, not other arcs of the same family.

    The continuation's points stop short of the arc's upper end ``T_hi`` (refined by
    bisection to ``5T₂``); the orbit at ``T_hi`` itself, ②, is re-solved there with
    ``Branch.orbit_at`` (the crossing next to the arc's last point) and appended.
    """
    system = two_dof() if system is None else system
    family, arc = paper_arc(system)
    orbits = sorted(family.orbits[arc.start: arc.stop + 1], key=lambda o: o.T)
    last = orbits[-1]
    ends = family.orbit_at(arc.T_hi) if arc.T_hi > last.T else []
    if ends:
        phase = last.impact_times / last.T
        orbits.append(min(ends, key=lambda o: np.abs(o.impact_times / o.T - phase).max()))
    whole = Arc(0, len(orbits) - 1, arc.T_lo, arc.T_hi, arc.refined_lo, arc.refined_hi)
    return Branch(system=system, k=family.k, orbits=orbits, arcs=[whole])


def run(main, doc: str) -> None:
    """The scripts' command line: ``[--out DIR] [--low]``, then ``main(out, resolution)``."""
    parser = argparse.ArgumentParser(description=doc.split("\n")[0])
    parser.add_argument("--out", default="results/examples", help="output directory (default: %(default)s)")
    parser.add_argument("--low", action="store_true", help="low resolution (fast)")
    args = parser.parse_args()
    t0 = time.perf_counter()
    paths = main(args.out, "low" if args.low else "full")
    print("wrote", *paths, f"({time.perf_counter() - t0:.1f} s)")
