"""All-or-nothing results that never touch what a run did not write.

A run writes into a hidden staging folder inside the output directory and moves everything into place
only when it succeeded.  A failed or interrupted run leaves the previous results as they were.

* **Ownership**: a run replaces or removes an entry of the output folder only when it can prove that
  bladecase wrote it and that it is unchanged since: the folder's signed manifest
  (:mod:`~bladecase.study.manifest`, ``.bladecase-manifest.json``: a content hash of every entry the runs
  published, signed with the user's own key) must list the entry with its current hash.  Anything else —
  a user's ``animations/`` or ``report.md``, a result edited by hand, an entry named by a planted or copied
  ``summary.json`` or manifest — is the user's: a run that would replace it is refused up front, before
  any computation, with its name; a stale result the run would remove is left where it is.
* **Lock**: one run at a time per output folder (``.bladecase.lock``, an advisory ``flock`` the system
  releases even when the process is killed); a second run is refused with the holder's pid.  The lock
  file is opened without following links (a planted link is refused, never written through).
* **Publishing**: Ctrl-C and SIGTERM are held back while the entries are moved.  Before the first move a
  signed journal (``.bladecase-publishing``) records the whole publication; a publication killed
  half-way (SIGKILL, power loss) is finished by the next run into the folder from the journal and the
  staging folder, which still holds every entry not yet moved: the folder then holds the new result set,
  whole.  An unsigned (planted) journal is ignored.
* **Stale staging**: with the lock held, staging folders left by killed runs are removed — only those
  marked with a token signed by this user; a folder that only has such a name is left alone.
* **Where results may go**: an output folder that holds the working folder (``..``, the home folder, ``/``)
  is refused, and so is one where a result would replace a study input.
"""

from __future__ import annotations

import errno
import os
import shutil
import signal
import stat
import tempfile
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from .. import log
from ..io import check_output_dir
from .manifest import MANIFEST, TOKEN, entry_hash, read_signed, stamp_folder, stamped, write_signed

#: Top-level result names a run owns in its output directory (older ones it did not write are removed).
RUN_RESULTS = ("summary.json", "report.md", "run.log", "modes.json", "frequency_energy.png", "mesh.vtu", "animations",
               "vtk", "forced.csv", "forced_response.png", "campbell.png", "rub.csv", "rub_nodes.csv", "rub.png",
               "rub.vtu", "wear.csv", "wear_profile.csv", "wear.png", "wear.vtu", "friction_modes.csv",
               "friction_modes.png", "casing.png", "nodal_modes.csv", "nodal_modes.png", "cyclic.csv", "safe.png",
               "campbell_nd.png", "mistuning.csv", "mistuning.png", "comparison.csv", "comparison_frequency_energy.png",
               "comparison_convergence.png", "comparison_contact_spectrum.png", "disk_modes.csv", "disk_rub.csv",
               "disk_rub.png", "mistuning_contact.csv", "mistuning_rub.csv")

LOCK = ".bladecase.lock"
STAGING_PREFIX = ".bladecase-run-"
MARKER = ".bladecase-publishing"
#: Hidden names of bladecase's own bookkeeping (never published as results).
RESERVED = (LOCK, MARKER, MANIFEST)
_TRASH = ".trash"

#: Locks this process holds: output folder → (file descriptor, staging folder or None while being set up).
_LOCKS: dict[str, tuple[int, Path | None]] = {}
_GUARD = threading.Lock()


class OutputInUse(ValueError):
    """The output folder is being written by another run (the message names its pid)."""


# ----------------------------------------------------------------------------- lock

def _open_lock(out: Path) -> int:
    """The lock file's descriptor, opened without following a link; ``ValueError`` for anything but a plain
    file of this user with one name (a planted link or hard link is never written through)."""
    path = out / LOCK
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0)
                     | getattr(os, "O_NONBLOCK", 0), 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ValueError(f"output folder {str(out)!r}: {LOCK} is a symbolic link, not bladecase's lock file: "
                             "bladecase never writes through it — remove it and run again") from None
        raise ValueError(f"output folder {str(out)!r}: cannot open the lock file {LOCK}: "
                         f"{exc.strerror or exc}") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1 or (hasattr(os, "geteuid") and st.st_uid != os.geteuid()):
        os.close(fd)
        what = ("not a regular file" if not stat.S_ISREG(st.st_mode) else
                "a hard link to another file" if st.st_nlink != 1 else "owned by another user")
        raise ValueError(f"output folder {str(out)!r}: {LOCK} is {what}, not bladecase's lock file: bladecase "
                         "never writes into it — remove it and run again")
    return fd


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
            fd = _open_lock(out)
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
                same = os.path.samestat(os.fstat(fd), os.lstat(path))
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
        path = Path(key) / LOCK
        if os.path.samestat(os.fstat(fd), os.lstat(path)):
            os.unlink(path)  # removed while still locked: no other run can hold it now
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

def manifest_entries(out: Path) -> dict[str, str]:
    """The entries (name → content hash) of the signed manifest of ``out``; empty when there is none, or
    when it is not signed by this user (planted, copied from elsewhere, edited)."""
    doc = read_signed(Path(out) / MANIFEST)
    entries = doc.get("entries") if doc else None
    if not isinstance(entries, dict):
        return {}
    return {n: h for n, h in entries.items() if _plain_name(n) and isinstance(h, str)}


def _plain_name(name: object) -> bool:
    return (isinstance(name, str) and bool(name) and name not in (".", "..") and "/" not in name
            and "\\" not in name and "\0" not in name and name not in RESERVED and not name.startswith(STAGING_PREFIX))


def owned(out: Path) -> set[str]:
    """The entries of ``out`` that a bladecase run of this user wrote and nobody changed since."""
    return {n for n, h in manifest_entries(out).items() if entry_hash(Path(out) / n) == h}


def _foreign(out: Path, names: Iterable[str], entries: dict[str, str]) -> tuple[list[str], list[str]]:
    """Of ``names`` present in ``out``: those no signed manifest lists, and those changed since."""
    unknown, changed = [], []
    for n in names:
        if os.path.lexists(out / n):
            if n not in entries:
                unknown.append(n)
            elif entry_hash(out / n) != entries[n]:
                changed.append(n)
    return unknown, changed


def _foreign_message(out: Path, unknown: list[str], changed: list[str], when: str = "") -> str:
    parts = []
    if unknown:
        parts.append(f"already holds {', '.join(map(repr, unknown))}, not written by a bladecase run of yours "
                     f"(no manifest signed by your bladecase lists it)")
    if changed:
        parts.append(f"holds {', '.join(map(repr, changed))}, changed since bladecase wrote "
                     f"{'it' if len(changed) == 1 else 'them'}")
    return (f"output folder {str(out)!r} {' and '.join(parts)}{when}: bladecase never replaces a user's files — "
            "move them, or choose another output folder")


def check_ownership(out: Path, names: Iterable[str] = RUN_RESULTS) -> None:
    """``ValueError`` if an entry of ``names`` is in ``out`` but cannot be proved bladecase's (see the module)."""
    out = Path(out)
    unknown, changed = _foreign(out, names, manifest_entries(out))
    if unknown or changed:
        raise ValueError(_foreign_message(out, unknown, changed))


def check_inputs(out: Path, inputs: Iterable[str | os.PathLike], names: Iterable[str] = RUN_RESULTS) -> None:
    """``ValueError`` if an input file lies where a result of ``names`` will be written (it would be replaced),
    or is one of bladecase's own files in ``out``."""
    out = Path(out).resolve()
    for path in inputs:
        p = Path(path).resolve()
        for name in (*names, *RESERVED):
            target = out / name
            if p == target or target in p.parents:
                raise ValueError(f"input {str(path)!r} lies in {str(target)!r}, which this run replaces with its "
                                 "results: move the input, or choose another output folder")


def output_folder(study, out: str | os.PathLike | None = None) -> Path:
    """The output folder of ``study`` (``out`` overrides it); ``ValueError`` for an empty name (it would mean
    the working folder)."""
    if isinstance(out, str) and not out.strip():
        raise ValueError(f"output folder: got an empty name {out!r}, which would mean the working folder: give a "
                         f"folder, e.g. 'results/{study.name}'")
    return study.output_dir(out)


def check_place(out: Path) -> None:
    """``ValueError`` if ``out`` holds the working folder (``..``, the home folder, ``/``): results go into a
    folder of their own."""
    here = Path.cwd().resolve()
    where = Path(out).resolve()
    if where in here.parents:
        raise ValueError(f"output folder {str(out)!r} ({where}) holds the working folder {str(here)!r}: results go "
                         "into a folder of their own (e.g. results/<name>); choose another output folder")


# ----------------------------------------------------------------------------- staging

def staged_names(staging: Path) -> list[str]:
    """The result entries of a staging folder (its token and bladecase's bookkeeping left out)."""
    return sorted(p.name for p in Path(staging).iterdir() if p.name not in (TOKEN, _TRASH))


def _clean_stale(out: Path, keep: Path | None = None) -> None:
    """Remove staging folders of this user's killed runs (called with the lock held: none is in use)."""
    for entry in out.iterdir():
        if entry.name.startswith(STAGING_PREFIX) and entry != keep and stamped(entry):
            shutil.rmtree(entry, ignore_errors=True)
            log.info("removed %s, left by an interrupted run", entry)


def staging_dir(out: Path, names: Iterable[str] = RUN_RESULTS) -> Path:
    """A fresh hidden staging folder inside ``out`` (created if missing), with ``out`` locked for this run.

    ``ValueError`` (before any work) if ``out`` cannot be written, holds the working folder, is in use by
    another run, or holds one of ``names`` that bladecase cannot prove it wrote.  A publication killed
    half-way is finished first; staging left by killed runs is removed.  The lock is given up by
    :func:`publish`, by :func:`release`, or by the next run of this process once the staging is gone.
    """
    check_place(out)
    out = check_output_dir(out)
    _lock(out)
    key = str(out.resolve())
    try:
        recover(out, locked=True)
        _clean_stale(out)
        check_ownership(out, names)
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out))
        stamp_folder(staging)
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


# ----------------------------------------------------------------------------- publishing

def publish(staging: Path, out: Path, owned_names: tuple[str, ...] = (), whole: bool = False) -> None:
    """Move every entry of ``staging`` into ``out`` (replacing older results of the same name), and remove the
    ``owned_names`` this run did not write — with ``whole`` (a complete run) also every entry of the previous
    manifest (e.g. the folder of an output format no longer asked for) — each only if the manifest proves it
    bladecase's and unchanged; a stale entry that is not is left where it is, with a warning.  An entry to be
    replaced that is not bladecase's (it appeared during the run) refuses the whole publication.  Ctrl-C and
    SIGTERM wait until the entries are in place; the lock of ``out`` is given up."""
    out = Path(out)
    try:
        with _signals_held():
            journal = _journal(staging, out, owned_names, whole)
            write_signed(out / MARKER, journal)
            _apply(out, staging, journal)
    finally:
        release(out)


def _journal(staging: Path, out: Path, owned_names: tuple[str, ...], whole: bool) -> dict:
    """The publication as a document: what moves in, what goes, the hashes before and after."""
    entries = manifest_entries(out)
    staged = staged_names(staging)
    unknown, changed = _foreign(out, staged, entries)
    if unknown or changed:  # appeared or changed during the run
        raise ValueError(_foreign_message(out, unknown, changed, " (it appeared during the run: results left "
                                          "unpublished)"))
    current = {n: entry_hash(out / n) for n in entries if os.path.lexists(out / n)}
    proven = {n: h for n, h in current.items() if h == entries[n]}
    wanted = (set(owned_names) | (set(entries) if whole else set())) - set(staged)
    removes = sorted(n for n in wanted if n in proven)
    for n in sorted(wanted - set(removes)):
        if os.path.lexists(out / n):
            log.warning("left %s in %s: bladecase cannot prove it wrote it, or it was changed since", n, out)
    new = {n: h for n, h in proven.items() if n not in removes}
    new.update({n: entry_hash(staging / n) for n in staged})
    moves = [n for n in staged if n != "summary.json"] + [n for n in staged if n == "summary.json"]  # manifest last
    return {"staging": staging.name, "moves": moves, "removes": removes, "entries": new,
            "before": {n: proven[n] for n in [*moves, *removes] if n in proven}}


def _set_aside(target: Path, trash: Path) -> None:
    """Move ``target`` into ``trash`` (created if missing) under a name of its own."""
    trash.mkdir(exist_ok=True)
    os.rename(target, Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=trash)) / target.name)


def _apply(out: Path, staging: Path, journal: dict) -> None:
    """Carry out a publication journal; it can be repeated after being cut anywhere (each step checks what is
    already done), which is how a killed publication is finished."""
    trash = staging / _TRASH
    before, entries = journal["before"], journal["entries"]
    for name in journal["removes"]:
        target = out / name
        if os.path.lexists(target) and entry_hash(target) == before.get(name):
            _set_aside(target, trash)
    for name in journal["moves"]:
        entry, target = staging / name, out / name
        if not os.path.lexists(entry):
            continue  # moved before the cut
        if os.path.lexists(target):
            if entry_hash(target) not in (before.get(name), entries.get(name)):
                raise ValueError(_foreign_message(out, [], [name], " while publishing: results left unpublished "
                                                  f"in {staging.name}"))
            if target.is_dir() and not target.is_symlink():
                _set_aside(target, trash)
        os.replace(entry, target)
    write_signed(out / MANIFEST, {"format": 1, "tool": "bladecase", "run": journal["staging"], "entries": entries})
    shutil.rmtree(staging, ignore_errors=True)
    Path(out, MARKER).unlink(missing_ok=True)


def recover(out: Path, locked: bool = False) -> bool:
    """Finish a publication into ``out`` that was killed half-way (see the module); ``True`` if there was one.

    Takes the lock of ``out`` for the time it takes unless ``locked``.  An unsigned journal is ignored."""
    out = Path(out)
    marker = out / MARKER
    if not os.path.lexists(marker):
        return False
    if not locked:
        _lock(out)
    try:
        if marker.is_symlink():
            raise ValueError(f"output folder {str(out)!r}: {MARKER} is a symbolic link, not bladecase's journal: "
                             "remove it and run again")
        journal = read_signed(marker)
        staging = out / journal["staging"] if journal and _valid_journal(journal) else None
        done = read_signed(out / MANIFEST) if staging is not None and not os.path.lexists(staging) else None
        if done is not None and done.get("run") == journal["staging"]:
            marker.unlink()  # killed after its last step but one: the publication is complete
            return True
        if staging is None or not stamped(staging):
            log.warning("ignored %s in %s: not a publication journal of your bladecase runs", MARKER, out)
            return False
        log.warning("the previous run into %s was killed while publishing: its publication is finished now", out)
        _apply(out, staging, journal)
        return True
    finally:
        if not locked:
            release(out)


def _valid_journal(journal: dict) -> bool:
    names = [*journal.get("moves", []), *journal.get("removes", [])]
    return (isinstance(journal.get("staging"), str) and journal["staging"].startswith(STAGING_PREFIX)
            and "/" not in journal["staging"] and all(_plain_name(n) for n in names)
            and isinstance(journal.get("entries"), dict) and isinstance(journal.get("before"), dict))
