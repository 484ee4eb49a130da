"""Progress bars for long work: tqdm's plain text bar on standard error, or nothing at all.

Library functions take ``progress: bool``; with ``False`` no tqdm object is made, so nothing is
printed and no warning is issued (``tqdm.auto`` would warn about ipywidgets in notebooks: the plain
bar is used on purpose).

>>> list(progress_bar(range(3), "demo", enabled=False))
[0, 1, 2]
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


def progress_bar(items: Iterable[T], desc: str, enabled: bool = True, unit: str = "it",
                 total: int | None = None) -> Iterator[T] | Iterable[T]:
    """``items`` wrapped in a tqdm bar (text, on stderr) when ``enabled``, else ``items`` unchanged."""
    if not enabled:
        return items
    from tqdm import tqdm

    return tqdm(items, desc=desc, unit=unit, total=total, leave=False)


def progress_counter(total: int, desc: str, enabled: bool = True, unit: str = "it"):
    """A manual bar (``.update(n)``, ``.close()``, context manager); a silent stand-in when disabled."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=False, disable=not enabled)
