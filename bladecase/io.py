"""Atomic result files: written to a temporary file beside the target, then renamed.

A reader (or a crash) never sees a half-written result.  Where a result cannot go (a folder, a device,
a path under a file, a read-only place, a full disk) the error is one ``ValueError`` naming the path
and the reason, never a raw ``OSError``.  JSON is strict (no ``NaN``/``Infinity``), and stage files
(``.npz``) are read whole, with their fields checked (:func:`read_npz`, :func:`npz_scalar`).

>>> import tempfile
>>> folder = tempfile.TemporaryDirectory()
>>> write_json(f"{folder.name}/a.json", {"x": 1.5, "y": float("nan")})   # NaN → null (and a warning)
>>> open(f"{folder.name}/a.json").read().split()
['{', '"x":', '1.5,', '"y":', 'null', '}']
>>> write_text(folder.name, "text")  # doctest: +ELLIPSIS
Traceback (most recent call last):
    ...
ValueError: cannot write '...': it is a folder; give a file path (e.g. '.../result.txt')
>>> folder.cleanup()
"""

from __future__ import annotations

import csv
import errno
import io
import json
import math
import os
import shutil
import stat
import tempfile
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["WriteError", "atomic_path", "check_output_dir", "check_output_file", "csv_cell", "npz_array", "npz_scalar",
           "os_reason", "read_npz", "replace_dir", "rows_csv", "save_figure", "strict_json", "write_json", "write_text",
           "written_together"]


class WriteError(OSError, ValueError):
    """A result that could not be written (full disk, permissions…): an ``OSError`` as the system's own,
    and a ``ValueError`` (the command line's one-line error, exit 2); the message names the path."""


def os_reason(exc: OSError) -> str:
    """A short reason for an ``OSError`` (``"permission denied"``, ``"no space left on device"``, …)."""
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return "no space left on device (free some space or choose another place)"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied (choose a place you may write to)"
    if exc.errno == errno.EROFS:
        return "read-only file system (choose a writable place)"
    text = (exc.strerror or str(exc) or type(exc).__name__).rstrip(".")
    return text[:1].lower() + text[1:]


def _existing_ancestor(path: Path) -> Path:
    """The deepest existing ancestor of ``path`` (``path`` itself excluded)."""
    parent = path.parent
    while not os.path.lexists(parent) and parent != parent.parent:
        parent = parent.parent
    return parent


def _probe(folder: Path) -> str | None:
    """Why no file can be created in the existing ``folder`` (a temporary file is tried), or ``None``."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".bladecase-probe-", dir=folder)
    except OSError as exc:
        return os_reason(exc)
    os.close(fd)
    os.unlink(tmp)
    return None


def check_output_file(path: str | os.PathLike) -> Path:
    """``path`` as a ``Path`` if a result file may be written there, else ``ValueError`` saying why.

    Refused: an existing folder, an existing non-regular file (``/dev/null``, a pipe, a socket), a path
    under a file, a place where no file can be created (a temporary file is tried: permissions, a read-only
    or full file system).

    >>> check_output_file("/dev/null")
    Traceback (most recent call last):
        ...
    ValueError: cannot write '/dev/null': it is not a regular file (a device, pipe or socket); give a file path
    """
    path = Path(path)
    suffix = path.suffix or ".txt"
    if path.is_dir():
        raise ValueError(f"cannot write {str(path)!r}: it is a folder; give a file path "
                         f"(e.g. {str(path / ('result' + suffix))!r})")
    if os.path.lexists(path) and path.exists() and not stat.S_ISREG(path.stat().st_mode):
        raise ValueError(f"cannot write {str(path)!r}: it is not a regular file (a device, pipe or socket); "
                         "give a file path")
    parent = _existing_ancestor(path)
    if not parent.is_dir():
        raise ValueError(f"cannot write {str(path)!r}: {str(parent)!r} is a file, not a folder")
    why = _probe(parent)
    if why:
        raise ValueError(f"cannot write {str(path)!r}: cannot create a file in {str(parent)!r}: {why}")
    return path


def check_output_dir(path: str | os.PathLike) -> Path:
    """``path`` as a ``Path`` if results may be written into it (created if missing, a file tried in it), else
    ``ValueError`` saying why.

    >>> check_output_dir("/dev/null")
    Traceback (most recent call last):
        ...
    ValueError: output folder '/dev/null' is not a folder (a device, pipe or socket); give a folder (created if missing)
    """
    path = Path(path)
    if os.path.lexists(path) and not path.is_dir():
        what = "a file" if path.is_file() else "a device, pipe or socket" if path.exists() else "a broken link"
        raise ValueError(f"output folder {str(path)!r} is not a folder ({what}); give a folder (created if missing)")
    if not path.exists():
        parent = _existing_ancestor(path)
        if not parent.is_dir():
            raise ValueError(f"output folder {str(path)!r} cannot be created: {str(parent)!r} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"output folder {str(path)!r} cannot be created: {os_reason(exc)}") from None
    why = _probe(path)
    if why:
        raise ValueError(f"output folder {str(path)!r} cannot be written: {why}")
    return path


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); rename it onto ``path`` on success.

    ``ValueError`` (naming ``path``) where ``path`` cannot be written; :class:`WriteError` (an ``OSError``
    and a ``ValueError``) when writing fails, e.g. for lack of space; the temporary file is removed in
    every case.
    """
    path = check_output_file(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise WriteError(f"cannot write {str(path)!r}: {os_reason(exc)}") from None
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; results are ordinary files
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, WriteError):
            raise
        error = WriteError(f"cannot write {str(path)!r}: {os_reason(exc)}")
        error.errno = exc.errno
        raise error from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def strict_json(data: Any) -> tuple[Any, list[str]]:
    """``data`` with every non-finite float (``NaN``, ``±inf``) replaced by ``None``, and the places replaced.

    >>> strict_json({"a": [1.0, float("inf")], "b": {"c": float("nan")}})
    ({'a': [1.0, None], 'b': {'c': None}}, ['a[1]', 'b.c'])
    """
    where: list[str] = []

    def clean(x, at: str):
        if isinstance(x, (float, np.floating)):
            if math.isfinite(x):
                return float(x)
            where.append(at or "(top)")
            return None
        if isinstance(x, dict):
            return {k: clean(v, f"{at}.{k}" if at else str(k)) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v, f"{at}[{i}]") for i, v in enumerate(x)]
        if isinstance(x, np.ndarray):
            return clean(x.tolist(), at)
        if isinstance(x, np.integer):
            return int(x)
        if isinstance(x, np.bool_):
            return bool(x)
        return x

    return clean(data, ""), where


def csv_cell(value) -> str:
    """A CSV cell: floats to 9 significant digits, booleans lower-case, ``None`` (no value) empty.

    >>> [csv_cell(x) for x in (0.1 + 0.2, True, None, 3, "trailing edge")]
    ['0.3', 'true', '', '3', 'trailing edge']
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    return f"{value:.9g}" if isinstance(value, float) else str(value)


def rows_csv(rows: list[dict], columns) -> str:
    """CSV text of ``rows`` (dicts) under the header ``columns`` (keys beyond them ignored, missing ones empty),
    floats written with ``repr`` (every digit).

    >>> print(rows_csv([{"T": 0.1 + 0.2, "touching": True, "x": 1}], ("T", "touching")), end="")
    T,touching
    0.30000000000000004,True
    """
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(columns), lineterminator="\n", extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: repr(v) if isinstance(v, float) else v for k, v in r.items()})
    return buf.getvalue()


def write_json(path: str | os.PathLike, data: Any) -> None:
    """Write ``data`` as indented, strict JSON (RFC 8259), atomically.

    Non-finite numbers (``NaN``, ``±inf``: "no value") are written as ``null`` and a warning names the
    places, so that every JSON parser reads the file.
    """
    clean, where = strict_json(data)
    if where:
        from . import log

        shown = ", ".join(where[:5]) + (f" and {len(where) - 5} more" if len(where) > 5 else "")
        log.warning("%s: %d non-finite number(s) written as null (%s)", path, len(where), shown)
    write_text(path, json.dumps(clean, indent=2, allow_nan=False) + "\n")


def save_figure(fig, path: str | os.PathLike, **kwargs) -> None:
    """``fig.savefig`` atomically (format from the suffix of ``path``)."""
    fmt = Path(path).suffix.lstrip(".") or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kwargs)


def replace_dir(new: str | os.PathLike, target: str | os.PathLike) -> None:
    """Rename folder ``new`` to ``target``; an existing ``target`` is moved aside first, deleted after
    (put back if the rename fails), so ``target`` is always either the old or the new folder."""
    new, target = Path(new), Path(target)
    if not os.path.lexists(target):
        os.rename(new, target)
        return
    aside = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
    old = aside / target.name
    os.rename(target, old)
    try:
        os.rename(new, target)
    except BaseException:
        os.rename(old, target)  # put the previous result back
        shutil.rmtree(aside, ignore_errors=True)
        raise
    shutil.rmtree(aside, ignore_errors=True)


@contextmanager
def written_together(*paths: str | os.PathLike | None) -> Iterator[list[Path | None]]:
    """Temporary paths beside each of ``paths`` (``None`` stays ``None``), renamed onto them together when the
    block ends without error: a command's result files appear all or none. On an error in the block every
    temporary file is removed and the targets are as they were; if one rename fails, the targets already
    replaced are put back.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> write_text(folder / "a.txt", "old")
    >>> try:
    ...     with written_together(folder / "a.txt", folder / "b.txt") as (a, b):
    ...         write_text(a, "new")
    ...         raise ValueError("the second result cannot be made")
    ... except ValueError:
    ...     pass
    >>> (folder / "a.txt").read_text(), sorted(p.name for p in folder.iterdir())
    ('old', ['a.txt'])
    >>> shutil.rmtree(folder)
    """
    targets = [None if p is None else check_output_file(p) for p in paths]
    temps: list[Path | None] = []
    try:
        for target in targets:
            if target is None:
                temps.append(None)
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=target.suffix, dir=target.parent)
            os.close(fd)
            temps.append(Path(tmp))
        yield temps
        _rename_all([(t, p) for t, p in zip(temps, targets) if t is not None])
    except OSError as exc:
        if isinstance(exc, WriteError):
            raise
        raise WriteError(f"cannot write {str(exc.filename or targets[0])!r}: {os_reason(exc)}") from None
    finally:
        for tmp in temps:
            if tmp is not None:
                tmp.unlink(missing_ok=True)


def _rename_all(pairs: list[tuple[Path, Path]]) -> None:
    """``os.replace`` each ``(tmp, target)``; the previous targets are kept as hard links until every rename
    succeeded, and put back if one fails."""
    umask = os.umask(0)
    os.umask(umask)
    backups: list[tuple[Path | None, Path]] = []
    try:
        for tmp, target in pairs:
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; results are ordinary files
            backup = None
            if os.path.lexists(target):
                backup = target.parent / f".{target.stem}.old-{os.getpid()}-{len(backups)}{target.suffix}"
                backup.unlink(missing_ok=True)
                try:
                    os.link(target, backup, follow_symlinks=False)
                except OSError:  # a file system without hard links
                    shutil.copy2(target, backup, follow_symlinks=False)
            backups.append((backup, target))
            os.replace(tmp, target)
    except BaseException:
        for backup, target in backups:
            if backup is not None:
                os.replace(backup, target)
            else:
                target.unlink(missing_ok=True)
        raise
    finally:
        for backup, _ in backups:
            if backup is not None:
                backup.unlink(missing_ok=True)


# ----------------------------------------------------------------------------- stage files (.npz)

def read_npz(path: str | os.PathLike, what: str = "stage file", names: str = "") -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` file ``path``, read now (a corrupted member fails here, not later).

    ``ValueError`` naming the file for a missing, unreadable, truncated or corrupted file, a single ``.npy``
    array (``names``: the arrays the archive should hold, for that message, e.g. ``"M, K, w, gap"``), or one
    that holds pickled objects (never loaded).

    >>> import tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> _ = Path(folder.name, "bad.npz").write_bytes(b"not a zip archive")
    >>> read_npz(f"{folder.name}/bad.npz", "matrices file")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: cannot read matrices file '.../bad.npz': not a valid .npz file (truncated, corrupted or ...)
    >>> folder.cleanup()

    A member whose header claims more data than the member holds is a damaged file (checked before anything is
    allocated: a header may claim terabytes), named with the member and the claimed shape.
    """
    source = str(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(6)
        if head[:2] != b"PK" and head != b"\x93NUMPY":
            raise ValueError(f"cannot read {what} {source!r}: not a valid .npz file (truncated, corrupted or another "
                             f"format: it does not start as a zip archive{'; the file is empty' if not head else ''})")
        if head == b"\x93NUMPY":  # np.load would return the array itself, not an archive
            raise ValueError(f"cannot read {what} {source!r}: it is a single .npy array, not an .npz archive of "
                             "named arrays" + (f" {names} (write one with numpy.savez)" if names else ""))
        headers = _check_npz_members(path, what, source)
        arrays = {}
        with np.load(path, allow_pickle=False) as data:
            for key in data.files:
                try:
                    arrays[key] = data[key]
                except MemoryError:
                    shape, dtype, size = headers.get(f"{key}.npy", ("?", "?", "?"))
                    raise ValueError(f"cannot read {what} {source!r}: its array {key!r} of shape {shape} ({dtype}, "
                                     f"{size} bytes) does not fit in memory") from None
        return arrays
    except FileNotFoundError:
        raise ValueError(f"cannot read {what} {source!r}: no such file") from None
    except IsADirectoryError:
        raise ValueError(f"cannot read {what} {source!r}: it is a folder, not an .npz file") from None
    except OSError as exc:
        raise ValueError(f"cannot read {what} {source!r}: {os_reason(exc)}") from None
    except (zipfile.BadZipFile, zlib.error, EOFError) as exc:
        raise ValueError(f"cannot read {what} {source!r}: not a valid .npz file (truncated or corrupted: "
                         f"{exc})") from None
    except ValueError as exc:
        if str(exc).startswith("cannot read"):
            raise
        reason = ("it holds pickled Python objects, which are never loaded (write plain arrays with numpy.savez)"
                  if "pickle" in str(exc) else f"not a valid .npz file ({exc})")
        raise ValueError(f"cannot read {what} {source!r}: {reason}") from None


def _check_npz_members(path, what: str, source: str) -> dict[str, tuple]:
    """``ValueError`` naming the file, the member and its shape when an ``.npy`` member's header claims more bytes
    (shape × item size) than the member holds: a truncated or damaged file, which ``np.load`` would first try to
    allocate (a header claiming a 10⁶ × 10⁶ array asks for 8 TB).  Only the headers are read.  Returns each
    ``.npy`` member's ``(shape, dtype, bytes)``."""
    from numpy.lib import format as npy

    headers = {}
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            try:
                opened = archive.open(info)
            except (NotImplementedError, RuntimeError) as exc:  # an unknown compression, an encrypted member
                raise ValueError(f"cannot read {what} {source!r}: its member {info.filename!r} cannot be read "
                                 f"({exc}); write the file with numpy.savez or numpy.savez_compressed") from None
            with opened as member:
                try:
                    version = npy.read_magic(member)
                except ValueError:  # not an .npy member: np.load says what it is
                    continue
                if version not in ((1, 0), (2, 0), (3, 0)):
                    continue  # np.load names the unknown version
                try:
                    # a version 3.0 header is 2.0's in UTF-8: read as latin-1 its shape and item size are the same
                    read = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
                    shape, _, dtype = read(member)
                except ValueError:  # an unreadable header: np.load names the fault
                    continue
                if dtype.hasobject:
                    continue  # pickled objects: refused by np.load (allow_pickle=False)
                claimed = math.prod(shape) * dtype.itemsize
                held = info.file_size - member.tell()
            if claimed > held:
                raise ValueError(f"cannot read {what} {source!r}: damaged or truncated: its member {info.filename!r} "
                                 f"has a header for an array of shape {shape} ({dtype}): the header claims {claimed} "
                                 f"bytes, the member holds {max(held, 0)} (write the file again)")
            headers[info.filename] = (shape, dtype, claimed)
    return headers


def _field(data, key: str, source: str) -> np.ndarray:
    if key not in data:
        raise ValueError(f"{source}: field {key!r} is missing")
    return np.asarray(data[key])


def npz_scalar(data, key: str, source: str, kind: str = "real"):
    """The single value ``data[key]`` of a stage file as ``float`` (``kind="real"``), ``int`` or ``str``;
    ``ValueError`` naming the file, the field and what it holds otherwise (an array, text for a number…).

    >>> npz_scalar({"gap": np.array([1.0, 2.0])}, "gap", "m.npz")
    Traceback (most recent call last):
        ...
    ValueError: m.npz: field 'gap' must be a single number, got an array of shape (2,)
    """
    a = _field(data, key, source)
    noun = {"real": "number", "int": "integer", "str": "string"}[kind]
    if a.shape != ():
        raise ValueError(f"{source}: field {key!r} must be a single {noun}, got an array of shape {a.shape}")
    ok = {"real": "fiu", "int": "iu", "str": "U"}[kind]
    if a.dtype.kind not in ok:
        raise ValueError(f"{source}: field {key!r} must be a single {noun}, got {a.item()!r} ({a.dtype})")
    return {"real": float, "int": int, "str": str}[kind](a.item())


def npz_array(data, key: str, source: str, ndim: int | None = None, kind: str = "real", *,
              finite: bool = False) -> np.ndarray:
    """The array ``data[key]`` of a stage file, checked: numbers (``kind="real"``) or integers (``"int"``),
    of ``ndim`` dimensions if given, every value finite if ``finite``; ``ValueError`` naming the file and the
    field otherwise (booleans, text and objects are not numbers).

    >>> npz_array({"points": np.array([[0.0, 1.0], [np.nan, 2.0]])}, "points", "m.npz", 2, finite=True)
    Traceback (most recent call last):
        ...
    ValueError: m.npz: field 'points' must hold finite numbers, got 1 NaN or inf (the first: nan at [1, 0])
    """
    a = _field(data, key, source)
    ok = {"real": "fiu", "int": "iu"}[kind]
    if kind == "int" and a.size == 0 and a.dtype.kind == "f":
        a = a.astype(np.int64)  # an empty index array saved without a dtype
    if a.dtype.kind not in ok:
        noun = "numbers" if kind == "real" else "integers"
        raise ValueError(f"{source}: field {key!r} must hold {noun}, got dtype {a.dtype}")
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"{source}: field {key!r} must be a {ndim}-D array, got shape {a.shape}")
    if finite and a.dtype.kind == "f":
        bad = ~np.isfinite(a)
        if bad.any():
            at = np.unravel_index(int(np.flatnonzero(bad)[0]), a.shape)
            raise ValueError(f"{source}: field {key!r} must hold finite numbers, got {int(bad.sum())} NaN or inf "
                             f"(the first: {float(a[at])!r} at {list(map(int, at))})")
    return a


def npz_index(data, key: str, source: str, size: int, *, ndim: int = 1, low: int = 0,
              what: str = "an index") -> np.ndarray:
    """The integer array ``data[key]`` of a stage file with every value in ``[low, size)`` (``what``: what the
    values index, for the message); ``ValueError`` naming the file, the field and the first value out of range.

    >>> npz_index({"cells": np.array([[0, 1, 2], [1, 2, 10**6]])}, "cells", "m.npz", 500, ndim=2,
    ...           what="mesh nodes")
    Traceback (most recent call last):
        ...
    ValueError: m.npz: field 'cells' must hold mesh nodes in 0..499, got 1000000 at [1, 2]
    """
    a = npz_array(data, key, source, ndim, "int")
    if a.size:
        bad = (a < low) | (a >= size)
        if bad.any():
            at = np.unravel_index(int(np.flatnonzero(bad)[0]), a.shape)
            valid = f"in {low}..{size - 1}" if size > low else f"(there are none: the range {low}..{size - 1} is empty)"
            raise ValueError(f"{source}: field {key!r} must hold {what} {valid}, got {int(a[at])} at "
                             f"{list(map(int, at))}")
    return a.astype(np.int64, copy=False)
