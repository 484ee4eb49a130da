"""Study texts and helpers shared by the study and pipeline tests."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: A user-mesh study on the committed 2-D plate (``meshes/plate.vtu``, relative to the repository root).
PLATE = """
[study]
name = "plate"
[mesh]
path = "meshes/plate.vtu"
[fem]
order = 1
mass = "lumped"
thickness = 0.002
[contact]
clearance = 1e-4
[reduction]
method = "modal"
size = 10
[search]
ipp = [1]
periods = [0.5, 0.9999]
"""


def absolute(text: str) -> str:
    """The study text with the plate mesh path made absolute (for study files written elsewhere)."""
    return text.replace("meshes/plate.vtu", str(ROOT / "meshes" / "plate.vtu"))


def as_raw(config: dict) -> dict:
    """A validated study's config back to what a user would write (keys left unset dropped)."""
    return {s: {k: v for k, v in keys.items() if v is not None} for s, keys in config.items()}
