"""The former one-module study run, kept so that ``from bladecase.study.pipeline import …`` keeps working.

New code imports from where each piece now lives: :mod:`~bladecase.study.stages` (mesh → model →
contact → reduced model → search), :mod:`~bladecase.study.choose` (orbits and frames),
:mod:`~bladecase.study.render`, :mod:`~bladecase.study.run`, :mod:`~bladecase.study.documents`,
:mod:`bladecase.nsm.verify`, :mod:`bladecase.post.report`.
"""

from __future__ import annotations

from ..nsm import Branch, LinearSystem, PeriodicOrbit
from ..nsm.verify import VERIFY_RTOL, verify
from ..post.report import report
from .choose import Choice, choose_orbits, frame_times
from .documents import families_document, family_summary, load_families, reduced_summary
from .publish import RUN_RESULTS
from .render import animate_families
from .run import RunResult, run
from .stages import (
    build_contact,
    build_mesh,
    build_model,
    build_reduced,
    contact_group,
    material,
    period_unit,
    search,
)

__all__ = [
    "RUN_RESULTS", "VERIFY_RTOL", "Choice", "RunResult", "animate_families", "arc_orbits", "build_contact",
    "build_mesh", "build_model", "build_reduced", "choose_orbits", "contact_group", "families_document",
    "family_from_dict", "family_summary", "frame_times", "load_families", "material", "period_unit",
    "reduced_summary", "report", "run", "search", "verify",
]


def family_from_dict(system: LinearSystem, data: dict) -> Branch:
    """:meth:`Branch.from_dict <bladecase.nsm.Branch.from_dict>` (the former name)."""
    return Branch.from_dict(system, data)


def arc_orbits(fam: Branch, T: float, count: int) -> list[PeriodicOrbit]:
    """``fam.sample(count, at=T, spacing="period")`` (the former name)."""
    return fam.sample(count, at=T, spacing="period")
