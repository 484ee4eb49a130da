"""The registry of output formats: what ``[output] formats`` may name, and the writer of each.

An output is a name, a scope and a writer.  ``scope="run"`` writers are called once per run with a
:class:`PlotScene` (every model's branches); ``scope="orbit"`` writers once per animated orbit with an
:class:`OrbitScene` (the orbit on the mesh).  A writer has the signature::

    write(scene, folder: Path, formats: set[str]) -> dict[str, str]

It writes into ``folder`` (the run's staging folder: published all-or-nothing) and returns the names of
what it wrote, relative to ``folder``, keyed as they appear in ``summary.json``.  Several format names
may share one writer (``gif`` and ``mp4`` render the frames once): it is called once, with the requested
names in ``formats``.

Adding a format = one new file in ``bladecase/post/outputs/`` + one registration line in
``bladecase/post/outputs/__init__.py``.  For example, the contact force history as CSV::

    # bladecase/post/outputs/csv.py
    import numpy as np

    def write(scene, folder, formats):
        path = folder / "csv" / f"{scene.stem}.csv"
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savetxt(path, np.c_[scene.times, scene.contact_displacement], delimiter=",",
                   header="t (s), contact displacement (m)")
        return {"csv": f"csv/{path.name}"}

    # bladecase/post/outputs/__init__.py
    register("csv", csv.write, "orbit", "contact displacement over one period, CSV")

>>> formats = OutputRegistry()
>>> _ = formats.register("txt", lambda scene, folder, formats: {}, "run", "a text file")
>>> list(formats), formats.summaries()["txt"]
(['txt'], 'a text file')
>>> formats.entry("pdf")
Traceback (most recent call last):
    ...
ValueError: unknown output format 'pdf' (valid: 'txt')
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...fe import Mesh
from ...nsm import Branch, PeriodicOrbit
from ...registry import Registry

SCOPES = ("run", "orbit")

Writer = Callable[..., dict]


@dataclass(frozen=True)
class Output:
    """One registered format: its ``name``, ``writer``, ``scope`` (``"run"`` or ``"orbit"``) and a one-line
    ``summary``."""

    name: str
    writer: Writer
    scope: str
    summary: str


@dataclass
class PlotScene:
    """What a run-scope writer draws: each model's label and branches, the reference (full FE) frequencies."""

    title: str
    models: list[tuple[str, list[Branch]]]
    reference_hz: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass
class OrbitScene:
    """What an orbit-scope writer draws: one periodic orbit expanded to every node of the mesh.

    ``u``, ``v``: displacements and velocities ``(n_points, 3, n_frames)`` at ``times`` (``impact`` marks
    the impact frames); ``scale``: display magnification; ``branch``: the orbit's branch (for manifold
    samples), ``None`` if unknown; ``options``: the ``[output]`` section (``fps``, ``window``, ``manifold``,
    ``manifold_size``…).
    """

    stem: str
    title: str
    mesh: Mesh
    orbit: PeriodicOrbit
    times: np.ndarray
    u: np.ndarray
    v: np.ndarray
    impact: np.ndarray
    contact_node: int
    normal: np.ndarray
    scale: float
    options: dict
    branch: Branch | None = None
    #: Grid points of a contact face's nodes and, per frame, which of them are past their own clearance
    #: (``(k,)``, ``(k, n_frames)``; ``None``: a one-node contact).
    face_points: np.ndarray | None = None
    face_beyond: np.ndarray | None = None
    #: Extra point data of the VTK frames: constant ``(n_points,)`` and per frame ``(n_points, n_frames)``.
    point_data: dict | None = None
    frame_data: dict | None = None
    #: The clearance drawn at ``contact_node`` (m); ``None``: the orbit's system's gap.
    casing_gap: float | None = None

    @property
    def gap(self) -> float:
        return self.orbit.system.gap if self.casing_gap is None else self.casing_gap

    @property
    def contact_displacement(self) -> np.ndarray:
        """Displacement of the contact node along the casing normal at each frame (m)."""
        return self.normal @ self.u[self.contact_node]


class OutputRegistry(Registry[Output]):
    """Output formats in registration order; iterating gives their names."""

    def __init__(self) -> None:
        super().__init__("output format")

    def register(self, name: str, writer: Writer, scope: str, summary: str) -> Output:
        """Add a format; ``ValueError`` for an empty or taken name, a bad scope, a writer that is not callable."""
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"an {self.kind} name must be a plain word, got {name!r}")
        if scope not in SCOPES:
            raise ValueError(f"scope of {self.kind} {name!r} must be one of {SCOPES}, got {scope!r}")
        if not callable(writer):
            raise ValueError(f"the writer of {self.kind} {name!r} must be callable, got {writer!r}")
        return self.add(Output(name, writer, scope, str(summary)))

    def write(self, formats: Iterable[str], scope: str, scene, folder: Path) -> dict[str, str]:
        """Call each writer of the requested ``formats`` of ``scope`` once; merge what they return."""
        groups: dict[Writer, set[str]] = {}
        for name in formats:
            entry = self.entry(name)
            if entry.scope == scope:
                groups.setdefault(entry.writer, set()).add(name)
        written: dict[str, str] = {}
        for writer, names in groups.items():
            written.update(writer(scene, Path(folder), names))
        return written

    def __repr__(self) -> str:
        return f"OutputRegistry{tuple(self)!r}"
