"""Registries: one per family of methods, read by tests, benchmarks, the CLI and the report.

A registry maps the short key a user types (in a CLI flag or a scene file) to a :class:`Method`: the
NumPy reference (the oracle), its numba twin if there is one, the equation it cites, and a function
that makes small valid inputs for tests and docs. A new method is added by registering it; no
dispatcher is edited.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from reference.errors import SpecrefError, format_allowed

__all__ = ["Method", "Registry"]


@dataclass(frozen=True)
class Method:
    """One registered method.

    Parameters
    ----------
    name : str
        The key users type, e.g. ``"importance"``.
    reference : callable
        The readable NumPy implementation, which is the oracle.
    kernel : callable or None
        The numba twin, or None when the reference is fast enough.
    cites : str
        The equation, in the fixed format ``"Eq. (N), Author"`` (STYLE.md §5).
    example_inputs : callable or None
        ``example_inputs(rng) -> tuple`` of small valid positional inputs for tests and docs.
    extra : dict
        Family-specific metadata (for example whether a placement needs ``segments``).

    Examples
    --------
    >>> m = Method("double", lambda x: 2 * x, None, "Eq. (0), nobody")
    >>> m.reference(2)
    4
    """

    name: str
    reference: Callable[..., Any]
    kernel: Callable[..., Any] | None
    cites: str
    example_inputs: Callable[..., tuple] | None = None
    extra: dict = field(default_factory=dict)


class Registry:
    """An ordered mapping from key to :class:`Method` (or any value), with one-line lookup errors.

    Parameters
    ----------
    family : str
        What the entries are, used in messages: ``"placement"``, ``"report section"``.

    Examples
    --------
    >>> PLACEMENT_METHODS = Registry("placement")
    >>> _ = PLACEMENT_METHODS.register(Method("uniform", abs, None, "Eq. (16), Wang et al."))
    >>> PLACEMENT_METHODS.lookup("uniform").name
    'uniform'
    >>> PLACEMENT_METHODS.lookup("unifrom")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown placement 'unifrom'; allowed: uniform
    """

    def __init__(self, family: str):
        self.family = family
        self._entries: dict[str, Any] = {}

    def register(self, entry: Any, name: str | None = None) -> Any:
        """Add ``entry`` under ``name`` (default ``entry.name``) and return it (a decorator).

        Raises
        ------
        SpecrefError
            When the key is already taken: two methods must never share a key.
        """
        key = name if name is not None else entry.name
        if key in self._entries:
            raise SpecrefError(f"{self.family} {key!r} is registered twice")
        self._entries[key] = entry
        return entry

    def lookup(self, name: str) -> Any:
        """Return the entry for ``name``; raise a one-line :class:`SpecrefError` if unknown."""
        try:
            return self._entries[name]
        except (KeyError, TypeError):
            raise SpecrefError(
                f"unknown {self.family} {name!r}; allowed: {format_allowed(self._entries)}"
            ) from None

    def names(self) -> list[str]:
        """Registered keys in registration order."""
        return list(self._entries)

    def values(self) -> list[Any]:
        """Registered entries in registration order (what ``pytest.mark.parametrize`` takes)."""
        return list(self._entries.values())

    def items(self) -> list[tuple[str, Any]]:
        """``(key, entry)`` pairs in registration order."""
        return list(self._entries.items())

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.family!r}: {format_allowed(self._entries)})"
