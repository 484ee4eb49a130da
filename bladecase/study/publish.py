"""All-or-nothing results: a run writes into a hidden staging folder inside the output directory and
moves everything into place only when it succeeded.  A failed run leaves the previous results as they
were; a run removes only result names it owns (:data:`RUN_RESULTS`), never a user's file."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

from ..io import replace_dir

#: Top-level result names a run owns in its output directory (older ones it did not write are removed).
RUN_RESULTS = ("summary.json", "report.md", "run.log", "modes.json", "frequency_energy.png", "mesh.vtu", "animations",
               "vtk")


def staging_dir(out: Path) -> Path:
    """A fresh hidden staging folder inside ``out`` (created if missing)."""
    out.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=".bladecase-run-", dir=out))


def _written(out: Path) -> set[str]:
    """The top-level names the previous complete run recorded in its ``summary.json`` (``"outputs"``)."""
    try:
        names = json.loads((out / "summary.json").read_text(encoding="utf-8")).get("outputs", [])
    except (OSError, ValueError, AttributeError):
        return set()
    return {n for n in names if isinstance(n, str) and n and "/" not in n and "\\" not in n and n not in (".", "..")}


def publish(staging: Path, out: Path, owned: tuple[str, ...] = (), whole: bool = False) -> None:
    """Move every entry of ``staging`` into ``out`` (replacing older results of the same name);
    remove the ``owned`` names this run did not write (stale results of an older run) — with ``whole`` (a
    complete run), also every name the previous run recorded in its ``summary.json`` (``"outputs"``: e.g. the
    folder of an output format no longer asked for); never anything else."""
    previous = _written(out)
    owned = tuple(sorted(set(owned) | (previous if whole else set())))
    for name in owned:
        stale = out / name
        if not (staging / name).exists() and stale.exists():
            shutil.rmtree(stale) if stale.is_dir() and not stale.is_symlink() else stale.unlink()
    for entry in sorted(staging.iterdir()):
        target = out / entry.name
        if target.is_dir() and not target.is_symlink():
            replace_dir(entry, target)
        else:
            os.replace(entry, target)
    staging.rmdir()
