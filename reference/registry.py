"""Registries: one per family of methods, read by tests, benchmarks, the CLI and the report.

A registry maps the short key a user types (in a CLI flag or a scene file) to a :class:`Method`: the
NumPy reference (the oracle), its numba twin if there is one, the equation it cites, and a function
that makes small valid inputs for tests and docs. A new method is added by registering it; no
dispatcher is edited.

What a family needs beyond that is a typed field of the family's own subclass of :class:`Method`
(``BRDFMethod.sample``, ``Interpolation.order``), declared where the registry is, so a misspelt or
missing field is an error where the method is written, and a registry refuses an entry of another
kind (``Registry(family, kind)``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from reference.errors import SpecrefError, format_allowed

__all__ = ["Method", "ParametricMethod", "Registry"]


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
    compiled : callable or None
        The kernel called with the reference's signature (it allocates and packs what the kernel
        writes into), where the kernel's own signature differs; the twin-equality tests compare
        ``compiled(*inputs)`` with ``reference(*inputs)``.

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
    compiled: Callable[..., Any] | None = None


@dataclass(frozen=True, kw_only=True)
class ParametricMethod(Method):
    """A method that takes one parameter, written ``key:VALUE`` in CLI flags (``gaussian:0.1``).

    Parameters
    ----------
    param : str
        The parameter's name as help texts show it (``key[:PARAM]``).

    Examples
    --------
    >>> ParametricMethod("lobe", abs, None, "Eq. (0), nobody", param="S").param
    'S'
    >>> ParametricMethod("lobe", abs, None, "Eq. (0), nobody", parm="S")
    Traceback (most recent call last):
    ...
    TypeError: ParametricMethod.__init__() got an unexpected keyword argument 'parm'
    """

    param: str


class Registry:
    """An ordered mapping from key to :class:`Method` (or any value), with one-line lookup errors.

    Parameters
    ----------
    family : str
        What the entries are, used in messages: ``"placement"``, ``"report section"``.
    kind : type
        What an entry must be (default :class:`Method`); :meth:`register` refuses anything else.

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

    def __init__(self, family: str, kind: type = Method):
        self.family = family
        self.kind = kind
        self._entries: dict[str, Any] = {}

    def register(self, entry: Any, name: str | None = None) -> Any:
        """Add ``entry`` under ``name`` (default ``entry.name``) and return it (a decorator).

        Raises
        ------
        SpecrefError
            When the key is already taken (two methods must never share a key) or the entry is not
            of the registry's kind.
        """
        if not isinstance(entry, self.kind):
            raise SpecrefError(
                f"{self.family} registry takes {self.kind.__name__} entries, got "
                f"{type(entry).__name__}"
            )
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
