"""Proof of what a run wrote: content hashes of every result entry, signed with the user's own key.

A results folder is the user's; a run may replace or remove an entry there only when it can prove that
bladecase wrote it and that nobody changed it since.  The proof is a *manifest*, a hidden JSON file in
the output folder (:data:`MANIFEST`) that lists every top-level entry the runs published, each with a
hash of its content (:func:`entry_hash`: a file's bytes; a folder's relative paths, kinds and bytes),
and an HMAC-SHA256 signature over the whole document made with a secret key kept in the user's
configuration folder (:func:`signing_key`).  A file anyone can edit (``summary.json``) proves nothing;
a manifest planted or copied from elsewhere fails its signature; an entry changed since (a note added
to ``animations/``) fails its hash.  Either way the entry is treated as the user's.

The same signature marks the other hidden things a run leaves only when it is killed: its staging
folder (a token file inside it, :func:`stamp_folder`) and its publishing journal.

>>> import tempfile
>>> folder = Path(tempfile.mkdtemp())
>>> _ = (folder / "report.md").write_text("results")
>>> doc = sign({"entries": {"report.md": entry_hash(folder / "report.md")}})
>>> verify(doc) is not None
True
>>> doc["entries"]["notes"] = "sha256:0"          # edited by hand: the signature no longer holds
>>> verify(doc) is None
True
"""

from __future__ import annotations

import errno
import hashlib
import hmac
import json
import os
import secrets
import stat
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["MANIFEST", "entry_hash", "key_path", "read_signed", "sign", "signing_key", "stamp_folder",
           "stamped", "verify", "write_signed"]

#: The manifest of a results folder (hidden; written and replaced only by bladecase).
MANIFEST = ".bladecase-manifest.json"
#: The token that marks a staging folder as one of this user's runs.
TOKEN = ".bladecase-staging"
#: Largest manifest or journal read (a few kB in practice).
_MAX_DOC = 4 << 20


def key_path() -> Path:
    """Where the signing key lives: ``$BLADECASE_KEY_FILE``, else ``$XDG_CONFIG_HOME/bladecase/signing.key``
    (``~/.config/bladecase/signing.key``)."""
    given = os.environ.get("BLADECASE_KEY_FILE")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "bladecase" / "signing.key"


_KEYS: dict[str, bytes] = {}


def signing_key() -> bytes:
    """The user's secret key (32 random bytes, created on first use, readable by the user alone).

    Where the configuration folder cannot be written (a read-only home), a private folder of the user's in
    the system's temporary folder holds it.  ``RuntimeError`` naming the path when neither works (results
    could then be written but never proved to be bladecase's, so nothing is written)."""
    path = key_path()
    cached = _KEYS.get(str(path))
    if cached is not None:
        return cached
    try:
        key = _key_at(path)
    except OSError as exc:
        fallback = _private_fallback()
        if os.environ.get("BLADECASE_KEY_FILE") or fallback is None:
            raise RuntimeError(f"cannot read or create bladecase's signing key {str(path)!r} ({exc.strerror or exc}): "
                               "set BLADECASE_KEY_FILE to a file in a folder you may write to") from None
        try:
            key = _key_at(fallback)
        except OSError:
            raise RuntimeError(f"cannot read or create bladecase's signing key {str(path)!r} ({exc.strerror or exc}):"
                               " set BLADECASE_KEY_FILE to a file in a folder you may write to") from None
    if key is None:
        raise RuntimeError(f"bladecase's signing key {str(path)!r} is not 32 bytes: delete it (a new one is made)")
    _KEYS[str(path)] = key
    return key


def _key_at(path: Path) -> bytes | None:
    """The key stored at ``path``, created there if missing."""
    key = _read_key(path)
    if key is None and not os.path.lexists(path):
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd, tmp = tempfile.mkstemp(prefix=".key-", dir=path.parent)
        try:
            os.write(fd, secrets.token_bytes(32))
            os.fsync(fd)
        finally:
            os.close(fd)
        try:
            os.link(tmp, path)  # atomic, and never over a key another process created meanwhile
        except FileExistsError:
            pass
        finally:
            os.unlink(tmp)
        key = _read_key(path)
    return key


def _private_fallback() -> Path | None:
    """``<tmp>/bladecase-<uid>/signing.key`` in a folder of this user's that nobody else may enter."""
    if not hasattr(os, "getuid"):
        return None
    folder = Path(tempfile.gettempdir()) / f"bladecase-{os.getuid()}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        st = os.lstat(folder)
    except OSError:
        return None
    if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid() or st.st_mode & 0o077:
        return None  # planted by someone else: not a place for a secret
    return folder / "signing.key"


def _read_key(path: Path) -> bytes | None:
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        return None
    try:
        data = os.read(fd, 64)
    finally:
        os.close(fd)
    return data if len(data) == 32 else None


def _canonical(doc: dict) -> bytes:
    body = {k: v for k, v in doc.items() if k != "signature"}
    return json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True).encode()


def sign(doc: dict) -> dict:
    """``doc`` with its ``"signature"`` (HMAC-SHA256 over its canonical JSON without the signature)."""
    body = {k: v for k, v in doc.items() if k != "signature"}
    return {**body, "signature": hmac.new(signing_key(), _canonical(body), hashlib.sha256).hexdigest()}


def verify(doc: Any) -> dict | None:
    """``doc`` if it is a dict whose signature is this user's, else ``None``."""
    if not isinstance(doc, dict) or not isinstance(doc.get("signature"), str):
        return None
    expected = hmac.new(signing_key(), _canonical(doc), hashlib.sha256).hexdigest()
    return doc if hmac.compare_digest(expected, doc["signature"]) else None


def open_regular(path: Path) -> int | None:
    """A read-only descriptor of ``path`` if it is a regular file (never through a symbolic link), else ``None``."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        return None
    return fd


def read_signed(path: Path) -> dict | None:
    """The signed JSON document at ``path`` (a regular file, not a link), or ``None`` if absent, unreadable,
    or not signed by this user."""
    fd = open_regular(path)
    if fd is None:
        return None
    try:
        with os.fdopen(fd, "rb") as fh:
            data = fh.read(_MAX_DOC + 1)
        if len(data) > _MAX_DOC:
            return None
        return verify(json.loads(data.decode("utf-8")))
    except (OSError, ValueError, RecursionError):
        return None


def write_signed(path: Path, doc: dict) -> dict:
    """Write ``doc`` signed to ``path`` atomically (a temporary file renamed over it: an existing link is
    replaced, never followed); returns the signed document."""
    signed = sign(doc)
    fd, tmp = tempfile.mkstemp(prefix=f"{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(signed, fh, indent=1, sort_keys=True)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return signed


def _file_digest(path: Path, h) -> bool:
    fd = open_regular(path)
    if fd is None:
        return False
    with os.fdopen(fd, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return True


def entry_hash(path: Path) -> str | None:
    """A hash of the entry ``path``: ``"file:<sha256>"`` of a regular file's bytes, ``"tree:<sha256>"`` of a
    folder's sorted relative paths, kinds and file bytes; ``None`` for anything bladecase never writes (a
    symbolic link anywhere inside, a device, a pipe) or an entry that does not exist."""
    try:
        st = os.lstat(path)
    except OSError:
        return None
    if stat.S_ISREG(st.st_mode):
        h = hashlib.sha256()
        return f"file:{h.hexdigest()}" if _file_digest(path, h) else None
    if not stat.S_ISDIR(st.st_mode):
        return None
    h = hashlib.sha256()
    for root, dirs, files in os.walk(path, followlinks=False):
        dirs.sort()
        rel = os.path.relpath(root, path)
        for name in dirs:
            if os.path.islink(os.path.join(root, name)):
                return None
            h.update(f"d\0{os.path.join(rel, name)}\0".encode("utf-8", "surrogateescape"))
        for name in sorted(files):
            full = Path(root, name)
            h.update(f"f\0{os.path.join(rel, name)}\0".encode("utf-8", "surrogateescape"))
            if not _file_digest(full, h):  # a link, a pipe, a device: not bladecase's
                return None
            h.update(b"\0")
    return f"tree:{h.hexdigest()}"


def stamp_folder(folder: Path) -> None:
    """Mark ``folder`` (a staging folder just created) as this user's run's."""
    token = sign({"staging": folder.name})
    fd = os.open(folder / TOKEN, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        json.dump(token, fh)


def stamped(folder: Path) -> bool:
    """True if ``folder`` is a real folder (not a link) holding a token signed for its own name."""
    try:
        if not stat.S_ISDIR(os.lstat(folder).st_mode):
            return False
    except OSError as exc:
        if exc.errno != errno.ENOENT:
            return False
        return False
    doc = read_signed(folder / TOKEN)
    return doc is not None and doc.get("staging") == folder.name
