"""Named entries in registration order: the one mechanism behind every pluggable choice.

The reduction methods (:data:`bladecase.reduction.METHODS`) and the output formats
(:data:`bladecase.post.outputs.FORMATS`) are registries; each kind adds its own ``register`` that builds
its entry type (any object with ``name`` and ``summary``).  A registry is a read-only sequence of the
names, so it reads as the tuple of valid values (``", ".join(METHODS)``, ``name in FORMATS``).

>>> from types import SimpleNamespace
>>> colours = Registry("colour")
>>> _ = colours.add(SimpleNamespace(name="red", summary="warm"))
>>> list(colours), "red" in colours, colours.summaries()
(['red'], True, {'red': 'warm'})
>>> colours.entry("blue")
Traceback (most recent call last):
    ...
ValueError: unknown colour 'blue' (valid: 'red')
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Generic, TypeVar

E = TypeVar("E")


class Registry(Sequence[str], Generic[E]):
    """Entries by name, in registration order; iterating gives the names.

    Parameters
    ----------
    kind : str
        What an entry is, for messages (``"reduction method"``).
    """

    def __init__(self, kind: str):
        self.kind = kind
        self._entries: dict[str, E] = {}

    def add(self, entry: E) -> E:
        """Add an entry (its ``name`` must be a non-empty string not yet taken); returns it."""
        name = getattr(entry, "name", None)
        if not isinstance(name, str) or not name:
            raise ValueError(f"a {self.kind} name must be a non-empty string, got {name!r}")
        if name in self._entries:
            raise ValueError(f"{self.kind} {name!r} is already registered")
        self._entries[name] = entry
        return entry

    def unregister(self, name: str) -> E:
        """Remove the entry called ``name`` and return it (``ValueError`` if there is none)."""
        entry = self.entry(name)
        del self._entries[name]
        return entry

    def entry(self, name) -> E:
        """The entry called ``name``; ``ValueError`` listing the valid names otherwise."""
        if name not in self:
            valid = ", ".join(repr(m) for m in self)
            raise ValueError(f"unknown {self.kind} {name!r} (valid: {valid})")
        return self._entries[name]

    def summaries(self) -> dict[str, str]:
        """``{name: summary}`` in registration order."""
        return {name: e.summary for name, e in self._entries.items()}

    def __getitem__(self, index):
        return tuple(self._entries)[index]

    def __len__(self) -> int:
        return len(self._entries)

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(self._entries))

    def __contains__(self, name) -> bool:
        return isinstance(name, str) and name in self._entries

    def __eq__(self, other) -> bool:
        if isinstance(other, (Registry, tuple, list)):
            return tuple(self) == tuple(other)
        return NotImplemented

    __hash__ = None  # mutable

    def __repr__(self) -> str:
        return repr(tuple(self))
