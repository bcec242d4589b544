"""The keys of ``[render.options]``: each one registered by the package whose shaders read it.

A scene file's ``[render.options]`` table is handed to the shaders as ``ShadingContext.options``.
Each key is registered in :data:`RENDER_OPTIONS` with a check (``check(value) -> value``, raising
:class:`~reference.errors.SpecrefError` with what is allowed) by the package whose shaders read
it, as material types and shaders are: the core here, ``shrm`` and ``phong_table`` when they are
imported (``specref render`` imports both). The scene loader refuses an unknown key, and checks
every known one, in one line naming the file and the key, before any work: a misspelt key used to
leave its shader at the default in silence.

Examples
--------
>>> RENDER_OPTIONS.lookup("sphere_light_tol").check(0.01)
0.01
>>> RENDER_OPTIONS.lookup("environment").check("brute force")
Traceback (most recent call last):
...
reference.errors.SpecrefError: unknown value 'brute force'; allowed: bruteforce, sh
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from reference.errors import SpecrefError, format_allowed, require, require_between
from reference.registry import Registry

__all__ = [
    "RENDER_OPTIONS",
    "RenderOption",
    "check_choice",
    "check_fraction",
    "check_int_range",
    "check_table",
    "register_render_option",
]


@dataclass(frozen=True)
class RenderOption:
    """One key of ``[render.options]``.

    Attributes
    ----------
    check : callable
        ``check(value) -> value``: the value as the shaders read it, or a one-line
        :class:`~reference.errors.SpecrefError` saying what is allowed (without the key: the
        loader adds the file and the key).
    doc : str
        What it sets, for messages and docs.
    """

    check: Callable[[object], object]
    doc: str


#: The keys of ``[render.options]`` (module docstring).
RENDER_OPTIONS = Registry("render option", RenderOption)


def check_fraction(value, maximum: float = 1.0) -> float:
    """A number in ``(0, maximum)``: a relative tolerance.

    Examples
    --------
    >>> check_fraction(0.002)
    0.002
    >>> check_fraction(float("nan"))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: must be a number in (0, 1), got nan
    """
    return require_between(value, "", 0.0, maximum)


def check_int_range(value, low: int, high: int) -> int:
    """An integer in ``[low, high]``.

    Examples
    --------
    >>> check_int_range(64, 4, 2048)
    64
    >>> check_int_range(1e9, 4, 2048)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: must be an integer in [4, 2048], got 1000000000.0
    """
    require(
        isinstance(value, int) and not isinstance(value, bool) and low <= value <= high,
        f"must be an integer in [{low}, {high}], got {value!r}",
    )
    return int(value)


def check_choice(value, allowed) -> str:
    """One of ``allowed``.

    Examples
    --------
    >>> check_choice("bruteforce", ["bruteforce"])
    'bruteforce'
    """
    allowed = list(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise SpecrefError(f"unknown value {value!r:.60}; allowed: {format_allowed(allowed)}")
    return value


def check_table(value, checks: Mapping[str, Callable]) -> dict:
    """A table whose keys are among ``checks``, each value checked by its function.

    Examples
    --------
    >>> check_table({"entries": 64}, {"entries": lambda v: check_int_range(v, 2, 10)})
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: entries: must be an integer in [2, 10], got 64
    """
    require(isinstance(value, Mapping), f"must be a table, got {value!r:.60}")
    out = {}
    for key, item in value.items():
        if key not in checks:
            raise SpecrefError(f"unknown key {key!r}; allowed: {format_allowed(checks)}")
        try:
            out[key] = checks[key](item)
        except SpecrefError as error:
            raise SpecrefError(f"{key}: {error}") from None
    return out


def register_render_option(name: str, check: Callable[[object], object], doc: str) -> None:
    """Register ``[render.options] name`` with its check, once.

    A module that a test runner imports a second time registers nothing more.

    Examples
    --------
    >>> register_render_option("sphere_light_tol", check_fraction, "sphere lights' tolerance")
    >>> RENDER_OPTIONS.lookup("sphere_light_tol").check(0.5)
    0.5
    """
    if name not in RENDER_OPTIONS:
        RENDER_OPTIONS.register(RenderOption(check, doc), name)


# The core's keys; upsampling and upsampling_model are read by the loader itself (it resolves the
# model file), so their checks here pass the value on.
register_render_option("upsampling", lambda value: value, "how RGB environment maps become spectra")
register_render_option(
    "upsampling_model",
    lambda value: value,
    'a model of `specref env fit` (upsampling = "regression")',
)
register_render_option(
    "environment",
    lambda value: check_choice(value, ["sh", "bruteforce"]),
    'environment lights in frequency space ("sh", the default) or by brute force (--oracle)',
)
register_render_option(
    "sphere_light_tol",
    check_fraction,
    "sphere lights' tolerance, of the pixel's value (default 1e-3)",
)
