"""All-or-nothing results: a run writes into a hidden staging folder inside the output directory and
moves everything into place only when it succeeded.  A failed or interrupted run leaves the previous
results as they were; a run removes or replaces only result names a bladecase run wrote there, never a
user's file or folder.

* **Lock**: one run at a time per output folder (``.bladecase.lock``, an advisory ``flock`` the system
  releases even when the process is killed); a second run is refused with the holder's pid.
* **Stale staging**: with the lock held, staging folders and set-aside folders left by a killed run
  (``.bladecase-run-*``, ``.<name>.old-*``) are removed.
* **Ownership**: a result name (:data:`RUN_RESULTS`) already in the folder must have been written by
  bladecase — listed in the previous run's ``summary.json`` (``"outputs"``), or in the publishing marker
  of a publication that was killed, or (``animations/``, ``vtk/``) holding only what bladecase writes
  there (``<stem>.gif``/``.mp4``; ``<stem>.pvd`` + ``<stem>/*.vtu``, ``<stem>_manifold.vtu``); otherwise
  the run is refused up front, before any computation.
* **Publishing**: Ctrl-C and SIGTERM are held back while the entries are moved; a marker
  (``.bladecase-publishing``) lists the names being published and is removed last, so that the next run
  knows a publication killed half-way (SIGKILL, power loss) and replaces its entries.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from .. import log
from ..io import check_output_dir, replace_dir

#: Top-level result names a run owns in its output directory (older ones it did not write are removed).
RUN_RESULTS = ("summary.json", "report.md", "run.log", "modes.json", "frequency_energy.png", "mesh.vtu", "animations",
               "vtk", "forced.csv", "forced_response.png")

LOCK = ".bladecase.lock"
STAGING_PREFIX = ".bladecase-run-"
MARKER = ".bladecase-publishing"

#: Result folders recognised by their content when no summary lists them (``bladecase animate`` alone).
_FOLDERS = ("animations", "vtk")

#: Locks this process holds: output folder → (file descriptor, staging folder or None while being set up).
_LOCKS: dict[str, tuple[int, Path | None]] = {}
_GUARD = threading.Lock()


class OutputInUse(ValueError):
    """The output folder is being written by another run (the message names its pid)."""


# ----------------------------------------------------------------------------- lock

def _lock(out: Path) -> None:
    key = str(out.resolve())
    with _GUARD:
        held = _LOCKS.get(key)
        if held is not None:
            if held[1] is None or held[1].exists():
                raise OutputInUse(f"output folder {str(out)!r} is in use by another run of this process (pid "
                                  f"{os.getpid()}): wait for it to finish or choose another output folder")
            _release(key)  # a failed run whose staging is gone: its lock is stale
        path = out / LOCK
        for _ in range(10):
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                import fcntl

                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except ImportError:  # no flock (Windows): the lock file alone
                pass
            except OSError as exc:
                holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
                os.close(fd)
                if exc.errno not in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    raise
                raise OutputInUse(f"output folder {str(out)!r} is in use by another bladecase run (pid {holder}): "
                                  "wait for it to finish or choose another output folder") from None
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(path))
            except FileNotFoundError:
                same = False
            if same:  # else the holder removed the file between our open and flock: try again
                os.ftruncate(fd, 0)
                os.pwrite(fd, str(os.getpid()).encode(), 0)
                _LOCKS[key] = (fd, None)
                return
            os.close(fd)
        raise OutputInUse(f"output folder {str(out)!r}: could not take the lock {LOCK} (busy)")


def _release(key: str) -> None:
    fd, _ = _LOCKS.pop(key)
    try:
        os.unlink(Path(key) / LOCK)  # removed while still locked: no other run can hold it now
    except OSError:
        pass
    os.close(fd)


def release(out: Path) -> None:
    """Give up the lock of ``out`` taken by :func:`staging_dir` (nothing if not held)."""
    key = str(Path(out).resolve())
    with _GUARD:
        if key in _LOCKS:
            _release(key)


# ----------------------------------------------------------------------------- ownership

def _summary_outputs(out: Path) -> set[str] | None:
    """Names the previous complete run recorded in its ``summary.json`` (``None``: no bladecase summary)."""
    try:
        data = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or "bladecase_version" not in data:
        return None
    names = data.get("outputs")
    if not isinstance(names, list):  # written before "outputs" existed: the result names of that version
        return set(RUN_RESULTS)
    return {n for n in names if isinstance(n, str) and n and "/" not in n and "\\" not in n and n not in (".", "..")}


def _marker_names(out: Path) -> set[str]:
    """Names of a publication that was killed half-way (its marker is still there)."""
    try:
        names = json.loads((out / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    return {n for n in names if isinstance(n, str) and n in RUN_RESULTS} if isinstance(names, list) else set()


def _looks_written(folder: Path) -> bool:
    """True if ``folder`` holds only what bladecase writes there: ``animations/<stem>.gif|.mp4``;
    ``vtk/<stem>.pvd`` with its frames ``vtk/<stem>/*.vtu``, and ``vtk/<stem>_manifold.vtu``."""
    if folder.is_symlink():
        return False
    entries = list(folder.iterdir())
    if folder.name == "animations":
        return all(p.is_file() and p.suffix.lower() in (".gif", ".mp4") for p in entries)
    stems = {p.stem for p in entries if p.is_file() and p.suffix == ".pvd"}
    for p in entries:
        if p.is_dir():
            frames_only = all(q.is_file() and q.suffix == ".vtu" for q in p.iterdir())
            if p.name not in stems or p.is_symlink() or not frames_only:
                return False
        elif not (p.suffix == ".pvd" or p.name.endswith("_manifold.vtu")):
            return False
    return True


def owned(out: Path) -> set[str]:
    """The result names in ``out`` a bladecase run wrote (see the module's *Ownership*)."""
    names = (_summary_outputs(out) or set()) | _marker_names(out)
    names |= {n for n in _FOLDERS if (out / n).is_dir() and _looks_written(out / n)}
    return names


def check_ownership(out: Path, names: Iterable[str] = RUN_RESULTS) -> None:
    """``ValueError`` if a result name of ``names`` is in ``out`` but was not written by bladecase."""
    mine = owned(out)
    foreign = [n for n in names if os.path.lexists(out / n) and n not in mine]
    if foreign:
        raise ValueError(f"output folder {str(out)!r} already holds {', '.join(repr(n) for n in foreign)}, not written "
                         "by a bladecase run (no bladecase summary.json lists it): bladecase never replaces a user's "
                         "files — move them, or choose another output folder")


def check_inputs(out: Path, inputs: Iterable[str | os.PathLike], names: Iterable[str] = RUN_RESULTS) -> None:
    """``ValueError`` if an input file lies where a result of ``names`` will be written (it would be replaced)."""
    out = Path(out).resolve()
    for path in inputs:
        p = Path(path).resolve()
        for name in names:
            target = out / name
            if p == target or target in p.parents:
                raise ValueError(f"input {str(path)!r} lies in {str(target)!r}, which this run replaces with its "
                                 "results: move the input, or choose another output folder")


# ----------------------------------------------------------------------------- staging and publishing

def _clean_stale(out: Path) -> None:
    """Remove staging and set-aside folders of killed runs (called with the lock held: none is in use)."""
    for entry in out.iterdir():
        stale = entry.name.startswith(STAGING_PREFIX) or any(entry.name.startswith(f".{n}.old-") for n in RUN_RESULTS)
        if stale and entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
            log.info("removed %s, left by an interrupted run", entry)


def staging_dir(out: Path, names: Iterable[str] = RUN_RESULTS) -> Path:
    """A fresh hidden staging folder inside ``out`` (created if missing), with ``out`` locked for this run.

    ``ValueError`` (before any work) if ``out`` cannot be written, is in use by another run, or holds one
    of ``names`` not written by bladecase.  Staging left by killed runs is removed.  The lock is given up
    by :func:`publish`, by :func:`release`, or by the next run of this process once the staging is gone.
    """
    out = check_output_dir(out)
    _lock(out)
    key = str(out.resolve())
    try:
        if (out / MARKER).exists():
            log.warning("the previous run into %s was interrupted while publishing: its results are incomplete "
                        "and will be replaced", out)
        _clean_stale(out)
        check_ownership(out, names)
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out))
    except BaseException:
        release(out)
        raise
    with _GUARD:
        _LOCKS[key] = (_LOCKS[key][0], staging)
    return staging


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold back SIGINT and SIGTERM (delivered after the block) so that publishing is never cut half-way."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    old = {s: signal.signal(s, lambda signum, frame: caught.append(signum)) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        if caught:
            handler = old[caught[0]]
            if callable(handler):
                handler(caught[0], None)
            elif caught[0] == signal.SIGINT:
                raise KeyboardInterrupt
            else:
                signal.raise_signal(caught[0])


def publish(staging: Path, out: Path, owned_names: tuple[str, ...] = (), whole: bool = False) -> None:
    """Move every entry of ``staging`` into ``out`` (replacing older results of the same name);
    remove the ``owned_names`` this run did not write (stale results of an older run) — with ``whole`` (a
    complete run), also every name the previous run recorded in its ``summary.json`` (``"outputs"``: e.g.
    the folder of an output format no longer asked for); never a name bladecase did not write.  Ctrl-C and
    SIGTERM wait until the entries are in place; the lock of ``out`` is given up."""
    out = Path(out)
    try:
        with _signals_held():
            _move_all(staging, out, owned_names, whole)
    finally:
        release(out)


def _move_all(staging: Path, out: Path, owned_names: tuple[str, ...], whole: bool) -> None:
    mine = owned(out)
    staged = sorted(p.name for p in staging.iterdir())
    foreign = [n for n in staged if os.path.lexists(out / n) and n not in mine]
    if foreign:  # appeared during the run
        raise ValueError(f"output folder {str(out)!r}: {', '.join(map(repr, foreign))} appeared during the run and "
                         "was not written by bladecase: results left unpublished; move them and run again")
    previous = _summary_outputs(out) or set()
    stale = sorted(n for n in (set(owned_names) | (previous if whole else set())) & mine if n not in staged)
    (out / MARKER).write_text(json.dumps(sorted(set(staged) | set(stale))), encoding="utf-8")
    for name in stale:
        target = out / name
        if os.path.lexists(target):
            shutil.rmtree(target) if target.is_dir() and not target.is_symlink() else target.unlink()
    last = [n for n in staged if n == "summary.json"]  # the manifest goes last
    for name in [n for n in staged if n != "summary.json"] + last:
        entry, target = staging / name, out / name
        if target.is_dir() and not target.is_symlink():
            replace_dir(entry, target)
        else:
            os.replace(entry, target)
    staging.rmdir()
    (out / MARKER).unlink()
