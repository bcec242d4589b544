"""Errors and input checks at specref's public boundaries.

Every public function validates its inputs with :func:`require`, which raises :class:`SpecrefError`
(a ``ValueError``) and therefore survives ``python -O``, unlike ``assert``. Messages are one line
and name the source (a file, a function argument), the key, what is allowed and what was given, for
example ``scene.toml: materials.gold.n: must be >= 0, got -3``. The CLI prints the message and exits
with code 2.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

__all__ = [
    "SpecrefError",
    "SpecrefWarning",
    "format_allowed",
    "require",
    "require_choice",
    "require_finite",
    "require_nonnegative",
]


class SpecrefError(ValueError):
    """Bad input at a public boundary; the message is one line, meant for the user.

    Examples
    --------
    >>> try:
    ...     raise SpecrefError("scene.toml: camera.fov_deg: must be in (0, 180), got 200")
    ... except ValueError as error:
    ...     print(error)
    scene.toml: camera.fov_deg: must be in (0, 180), got 200
    """

    def __init__(self, message: str):
        # One line, always: a multi-line message would read like a traceback in the CLI.
        super().__init__(" ".join(str(message).split()))


class SpecrefWarning(UserWarning):
    """A condition the user should know about that does not stop the computation."""


def require(condition: bool, message: str) -> None:
    """Raise :class:`SpecrefError` with ``message`` unless ``condition`` holds.

    Parameters
    ----------
    condition : bool
        The check; anything truthy passes.
    message : str
        One line naming the source, the key, what is allowed and what was given.

    Raises
    ------
    SpecrefError
        When ``condition`` is false.

    Examples
    --------
    >>> require(3 > 2, "never shown")
    >>> require(False, "scene.toml: width: must be > 0, got 0")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: scene.toml: width: must be > 0, got 0
    """
    if not condition:
        raise SpecrefError(message)


def require_finite(values, where: str) -> np.ndarray:
    """Return ``values`` as a float64 array after checking that every entry is finite.

    Parameters
    ----------
    values : array_like
        Numbers to check.
    where : str
        Prefix for the message, e.g. ``"scene.toml: materials.gold.k_s"``.

    Returns
    -------
    ndarray
        ``values`` as float64.

    Raises
    ------
    SpecrefError
        On NaN or inf, naming the first offending index.

    Examples
    --------
    >>> require_finite([1.0, 2.0], "k_s")
    array([1., 2.])
    >>> require_finite([1.0, float("nan")], "k_s")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: k_s: must be finite, got nan at index 1
    """
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise SpecrefError(f"{where}: must be numbers, got {values!r:.60}") from error
    bad = ~np.isfinite(array)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        shown = index[0] if len(index) == 1 else index
        raise SpecrefError(f"{where}: must be finite, got {array[index]} at index {shown}")
    return array


def require_nonnegative(values, where: str) -> np.ndarray:
    """Return ``values`` as float64 after checking that every entry is finite and >= 0.

    Parameters
    ----------
    values : array_like
        Numbers to check.
    where : str
        Prefix for the message.

    Returns
    -------
    ndarray
        ``values`` as float64.

    Raises
    ------
    SpecrefError
        On NaN, inf or a negative entry.

    Examples
    --------
    >>> require_nonnegative([0.0, 3.0], "n")
    array([0., 3.])
    >>> require_nonnegative([0.0, -3.0], "n")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: n: must be >= 0, got -3.0 at index 1
    """
    array = require_finite(values, where)
    negative = array < 0
    if negative.any():
        index = tuple(int(i) for i in np.argwhere(negative)[0])
        shown = index[0] if len(index) == 1 else index
        raise SpecrefError(f"{where}: must be >= 0, got {array[index]} at index {shown}")
    return array


def format_allowed(allowed: Iterable[str]) -> str:
    """Join allowed keys, sorted, for an error message.

    Examples
    --------
    >>> format_allowed(["uniform", "error", "importance"])
    'error, importance, uniform'
    """
    return ", ".join(sorted(str(a) for a in allowed))


def require_choice(value, allowed: Iterable[str], where: str) -> str:
    """Return ``value`` if it is one of ``allowed``; otherwise raise naming the allowed keys.

    Parameters
    ----------
    value : str
        The key the user typed.
    allowed : iterable of str
        The keys that are accepted.
    where : str
        What is being chosen, e.g. ``"placement"`` or ``"scene.toml: display.encoding"``.

    Returns
    -------
    str
        ``value`` unchanged.

    Raises
    ------
    SpecrefError
        ``unknown placement 'imporance'; allowed: error, importance, uniform``.

    Examples
    --------
    >>> require_choice("srgb", ["srgb", "linear"], "encoding")
    'srgb'
    >>> require_choice("sRBG", ["srgb", "linear"], "encoding")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown encoding 'sRBG'; allowed: linear, srgb
    """
    allowed = list(allowed)
    if value not in allowed:
        raise SpecrefError(f"unknown {where} {value!r}; allowed: {format_allowed(allowed)}")
    return value


def require_positive_int(value, where: str, maximum: int | None = None) -> int:
    """Return ``value`` as an int after checking ``1 <= value <= maximum``.

    Examples
    --------
    >>> require_positive_int(512, "width", maximum=16384)
    512
    >>> require_positive_int(0, "width", maximum=16384)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: width: must be an integer in [1, 16384], got 0
    """
    limit = "inf" if maximum is None else str(maximum)
    ok = isinstance(value, int | np.integer) and not isinstance(value, bool)
    ok = ok and value >= 1 and (maximum is None or value <= maximum)
    if not ok and isinstance(value, float) and math.isfinite(value) and value.is_integer():
        return require_positive_int(int(value), where, maximum)
    require(ok, f"{where}: must be an integer in [1, {limit}], got {value!r}")
    return int(value)


__all__ += ["require_positive_int"]


def require_between(value, where: str, low: float, high: float) -> float:
    """Return ``value`` as a float after checking it is a real number with ``low < value < high``.

    ``where`` names the quantity in the message (empty: the message starts at "must be", for a
    caller that names it itself, e.g. a scene file's key).

    Examples
    --------
    >>> require_between(0.25, "tol", 0, 100)
    0.25
    >>> require_between(float("nan"), "tol", 0, 100)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: tol: must be a number in (0, 100), got nan
    """
    ok = isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)
    ok = ok and math.isfinite(value) and low < value < high
    prefix = f"{where}: " if where else ""
    require(ok, f"{prefix}must be a number in ({low:g}, {high:g}), got {value!r}")
    return float(value)


__all__ += ["require_between"]
