"""A study file read safely: a regular file only (a pipe or a device is refused before it is read), capped in size
(:data:`MAX_STUDY_FILE_BYTES` in all, :data:`MAX_STUDY_BYTES` besides comments), UTF-8 text."""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from .keys import StudyError

#: Largest study content (characters besides comment lines and blank lines): a study is a few kilobytes; more is
#: not a study (a mesh, a log).
MAX_STUDY_BYTES = 1_000_000

#: Largest study file read (bytes): its comments do not count against :data:`MAX_STUDY_BYTES`, so a commented
#: study may be far bigger; a file above this is refused before it is read.
MAX_STUDY_FILE_BYTES = 64_000_000

#: A line that is neither a comment nor blank (the lines that count against :data:`MAX_STUDY_BYTES`).
_CONTENT_LINE = re.compile(r"^[ \t\r]*[^#\s][^\n]*\n?", re.M)


def content_size(text: str, stop: int | None = None) -> int:
    """The characters of the study ``text`` outside its comment lines and blank lines (a comment after a value
    counts: only whole lines are left out); the count stops once it exceeds ``stop`` (a file of content is not
    scanned to its end to be refused).

    >>> content_size("# a study\\n[study]\\n\\n  # its name\\nname = 'x'  # here\\n")
    27
    """
    size = 0
    for line in _CONTENT_LINE.finditer(text):
        size += line.end() - line.start()
        if stop is not None and size > stop:
            break
    return size


def _read_study_bytes(path: Path) -> bytes:
    """The bytes of a regular file of at most :data:`MAX_STUDY_FILE_BYTES`; a pipe, a device or a folder is refused
    before it is read (reading a FIFO would wait for a writer forever).  Its content besides comments is checked
    by :func:`loads`."""
    where = f"cannot read study file {str(path)!r}"
    try:
        info = path.stat()
    except (OSError, ValueError) as exc:
        raise StudyError(f"{where}: {getattr(exc, 'strerror', None) or exc}") from None
    if not stat.S_ISREG(info.st_mode):
        kind = ("a folder" if stat.S_ISDIR(info.st_mode) else "a named pipe (FIFO)" if stat.S_ISFIFO(info.st_mode)
                else "a device" if stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode)
                else "a socket" if stat.S_ISSOCK(info.st_mode) else "a special file")
        raise StudyError(f"{where}: it is {kind}, not a regular file")
    if info.st_size > MAX_STUDY_FILE_BYTES:
        raise StudyError(f"{where}: {info.st_size} bytes, more than a study file's {MAX_STUDY_FILE_BYTES} (is it a "
                         "study file?)")
    try:  # O_NONBLOCK: should the path have become a FIFO since the stat, opening it does not wait
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise StudyError(f"{where}: {exc.strerror or exc}") from None
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
            raise StudyError(f"{where}: not a regular file")
        data = f.read(MAX_STUDY_FILE_BYTES + 1)
    if len(data) > MAX_STUDY_FILE_BYTES:
        raise StudyError(f"{where}: more than a study file's {MAX_STUDY_FILE_BYTES} bytes (is it a study file?)")
    return data


def read_study_text(path: Path) -> str:
    """The text of the study file ``path`` (:func:`_read_study_bytes`, decoded as UTF-8, a byte-order mark dropped);
    :class:`StudyError` naming the byte and line where it is not UTF-8."""
    data = _read_study_bytes(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise StudyError(f"cannot read study file {str(path)!r}: not UTF-8 text (byte {exc.start}, line {line}); "
                         "save it as UTF-8") from None
    return text.removeprefix("\ufeff")
