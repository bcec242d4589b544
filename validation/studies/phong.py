"""Validation of the spectral Phong tables: Table 1 of Wang et al., sweeps and the tolerance search.

**Error.** RMS over the sphere's pixels and the three channels, against the exact spectral render of
the same view, in 8-bit units, before quantization (:func:`rms_8bit`):

- ``rms_display``: the paper's figure, ``255 × sRGB-encoded value`` with the linear values clipped
  to [0, 1] before encoding;
- ``rms_linear``: ``255 × linear value``, unclipped.

Clipping hides negative overshoot (a clipped 0.05 can be an unclipped 186), so every target uses
``rms = max(rms_display, rms_linear)``.

Table 1 itself, its target checks and ``specref phong --material`` are in
:mod:`validation.studies.phong_table1`.

**Time** (:func:`time_row`), with the JIT warm, on the same cached G-buffer and the same per-pixel
geometry (``phong_table.render.ShadingBuffer``: ``cos θ``, ``t``, ``f_att``, which stay fixed while
a user edits spectra):

- ``build_s``: the table build (placement, values, slopes, index; compiled), minimum of N;
- ``shade_s``: ``build_s`` plus the deferred shading to linear RGB, timed per tile of
  :data:`TILE_PIXELS` pixels (minimum of N per tile, summed);
- ``exact_shade_s``: the exact 41-band shading (one ``ln t`` per pixel, one ``exp`` per band),
  timed the same way: the baseline;
- ``frame_s``, ``exact_frame_s``: the full frame, ``shade_s`` plus the shared components, each the
  minimum of N: ray-casting the G-buffer, the per-pixel light geometry, scattering to the image and
  sRGB display encoding. Those shared components dominate a frame, so the full-frame ratio stays
  near 1; it is reported, not gated.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.model import SpectralPhong
from phong_table.placement import PLACEMENT_METHODS
from phong_table.render import (
    SphereGeometry,
    compiled_shader,
    render_sphere_gbuffer,
    rms_8bit,
    shade_pixels,
    shading_buffer,
    sphere_gbuffer,
)
from phong_table.scenes import SCENES, spectral_phong_unit_peak
from phong_table.table import build_table, check_interpolation
from reference.colour.spectra import DEFAULT_GRID
from reference.display.encodings import linear_to_display
from reference.errors import require

__all__ = [
    "ENTRY_LADDER",
    "TABLE1_ENTRIES",
    "TIE_8BIT",
    "TILE_PIXELS",
    "TableVariant",
    "ViewState",
    "bimodal_material",
    "format_tolerance",
    "never_worse_interpolations",
    "scene_state",
    "shared_frame_time",
    "table1_scenes",
    "table_error_row",
    "table_variants",
    "time_row",
    "time_shading",
    "tolerance_search",
    "view_state",
]

#: Entry counts of the sweeps: m from 25 to 800, doubling.
ENTRY_LADDER = (25, 50, 100, 200, 400, 800)
#: Entries of Table 1 (the paper's 200).
TABLE1_ENTRIES = 200
#: Pixels per timing tile.
TILE_PIXELS = 32768
#: Two RMS values closer than this (8-bit units, far below the 0.5 of quantization) count as equal
#: when the error placement is compared with the others (all reach rounding level).
TIE_8BIT = 1e-6


def table1_scenes() -> tuple[str, ...]:
    """The scenes of Table 1: every registered scene marked ``table1`` (shown in each of ``VIEWS``).

    Examples
    --------
    >>> table1_scenes()
    ('R1', 'R2', 'R3')
    """
    return tuple(scene.name for scene in SCENES.values() if scene.table1)


@dataclass(frozen=True)
class TableVariant:
    """A table of the studies: a placement and its segment count ``p`` as a function of ``m``."""

    name: str
    placement: str
    segments: Callable[[int], int | None]


def _segments_m(m: int) -> int:
    return m


def _segments_m10(m: int) -> int:
    return max(m // 10, 1) if m % 10 == 0 else 1


def _no_segments(m: int) -> None:
    return None


def table_variants() -> list[TableVariant]:
    """The tables of Table 1 and the sweeps: every registered placement, in registry order.

    The rule: a placement that takes segments (``Placement.segments``, the importance placement)
    is studied at ``p = m`` (the paper's setting, named ``"<placement> p=m"``) and at ``p = m/10``
    (``"<placement> p=m/10"``; ``p = 1`` where 10 does not divide ``m``); every other placement
    once, under its key.

    Examples
    --------
    >>> [(v.name, v.segments(200)) for v in table_variants()]
    [('importance p=m', 200), ('importance p=m/10', 20), ('uniform', None), ('error', None)]
    """
    variants = []
    for name, method in PLACEMENT_METHODS.items():
        if method.segments:
            variants.append(TableVariant(f"{name} p=m", name, _segments_m))
            variants.append(TableVariant(f"{name} p=m/10", name, _segments_m10))
        else:
            variants.append(TableVariant(name, name, _no_segments))
    return variants


def never_worse_interpolations() -> list[str]:
    """The interpolations of the "never worse" target and the failure sweeps.

    Every registered interpolation in ``t`` (``Interpolation.coordinate == "t"``): the parabola in
    ``w`` is Wang's importance coordinate, meaningless on other node sets, and is compared in the
    report only. Ordered by convergence order (``Interpolation.order``), then registry order.

    Examples
    --------
    >>> never_worse_interpolations()
    ['linear', 'parabolic', 'monotone']
    """
    in_t = [m for m in INTERPOLATION_METHODS.values() if m.coordinate == "t"]
    return [m.name for m in sorted(in_t, key=lambda m: m.order)]


@dataclass(frozen=True, eq=False)
class ViewState:
    """A material in a view: the cached G-buffer, per-pixel geometry and the exact render."""

    model: SpectralPhong
    view: str
    geometry: SphereGeometry
    buffer: object
    exact: np.ndarray
    exact_encoded: np.ndarray
    compiled: bool


def view_state(
    model: SpectralPhong, view: str, resolution: int = 512, compiled: bool = True
) -> ViewState:
    """Render the exact reference of a view once, for many table evaluations.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "far", 16, compiled=False)
    >>> state.exact.shape
    (148, 3)
    """
    geometry = sphere_gbuffer(view, resolution)
    buffer = shading_buffer(geometry, model, compiled)
    exact = shade_pixels(buffer, model, "exact", compiled=compiled)
    return ViewState(
        model, view, geometry, buffer, exact, linear_to_display(exact, "srgb"), compiled
    )


def table_pixels(state: ViewState, placement: str, interpolation: str, entries: int, segments=None):
    """Build one table for a view and shade its pixels: ``(table, RGB (n_pixels, 3))``.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "far", 12, compiled=False)
    >>> table, RGB = table_pixels(state, "error", "monotone", 16)
    >>> RGB.shape == state.exact.shape
    True
    """
    buffer = state.buffer
    table = build_table(
        state.model,
        entries,
        placement,
        segments,
        state.compiled,
        buffer.t_range,
        buffer.t_density,
        interpolation,
    )
    RGB = shade_pixels(buffer, state.model, "table", table, interpolation, compiled=state.compiled)
    return table, RGB


def table_error_row(
    state: ViewState, placement: str, interpolation: str, entries: int, segments=None
) -> dict:
    """Errors of one table on one view: RMS (display, linear, max) and the overshoot.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "near", 16, compiled=False)
    >>> row = table_error_row(state, "error", "monotone", 64)
    >>> row["rms"] < 1e-3, row["overshoot"]
    (True, 0.0)
    """
    check_interpolation(interpolation, entries)
    table, RGB = table_pixels(state, placement, interpolation, entries, segments)
    rms_display, rms_linear = rms_8bit(RGB, state.exact, exact_encoded=state.exact_encoded)
    return {
        "placement": placement,
        "interpolation": interpolation,
        "entries": entries,
        "segments": table.segments,
        "rms_display": rms_display,
        "rms_linear": rms_linear,
        "rms": max(rms_display, rms_linear),
        "overshoot": table.overshoot(interpolation),
    }


def _minimum_time(function, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return float(best)


def _tiles(buffer, size: int = TILE_PIXELS):
    from phong_table.render import ShadingBuffer

    n = buffer.t.size
    return [
        ShadingBuffer(
            buffer.geometry,
            buffer.cos_theta[a : a + size],
            buffer.t[a : a + size],
            buffer.f_att[a : a + size],
        )
        for a in range(0, n, size)
    ]


def time_shading(state: ViewState, table=None, interpolation: str = "monotone", repeats=9):
    """Shading time of a path on the view's buffer: per tile, minimum of ``repeats``, summed.

    The compiled path calls the kernel directly (``phong_table.render.compiled_shader``); the
    NumPy path (``state.compiled`` False) calls the reference.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "far", 16, compiled=False)
    >>> time_shading(state, repeats=1) > 0
    True
    """
    method = "exact" if table is None else "table"
    if state.compiled:
        shade = compiled_shader(state.model, table, interpolation)
    else:

        def shade(tile, out):
            return shade_pixels(tile, state.model, method, table, interpolation, False, out)

    total = 0.0
    for tile in _tiles(state.buffer):
        out = np.empty((tile.t.size, 3))
        total += _minimum_time(lambda tile=tile, out=out: shade(tile, out), repeats)
    return total


def shared_frame_time(state: ViewState, resolution: int, repeats: int = 3) -> float:
    """The frame time shared by all methods: G-buffer, light geometry, scatter, sRGB encoding.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "far", 16, compiled=False)
    >>> shared_frame_time(state, 16, 1) > 0
    True
    """
    gbuffer_s = _minimum_time(lambda: render_sphere_gbuffer(state.view, resolution), repeats)
    geometry_s = _minimum_time(
        lambda: shading_buffer(state.geometry, state.model, state.compiled), repeats
    )
    encode_s = _minimum_time(
        lambda: linear_to_display(state.geometry.to_image(state.exact), "srgb"), repeats
    )
    return gbuffer_s + geometry_s + encode_s


def time_row(state: ViewState, row: dict, exact_shade_s: float, shared_s: float, repeats=9):
    """Add the timings of a table row (``build_s``, ``shade_s``, ``frame_s`` and the exact ones).

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(20.0), "far", 16, compiled=False)
    >>> row = time_row(state, table_error_row(state, "uniform", "linear", 8), 1.0, 2.0, 1)
    >>> row["frame_s"] - row["shade_s"], row["exact_frame_s"]
    (2.0, 3.0)
    """
    args = (state.model, row["entries"], row["placement"], row["segments"])
    compiled = state.compiled
    # properties of the cached G-buffer, like t itself
    seen = (state.buffer.t_range, state.buffer.t_density, row["interpolation"])
    build_s = _minimum_time(lambda: build_table(*args, compiled, *seen), repeats)
    table = build_table(*args, compiled, *seen)
    shade_s = build_s + time_shading(state, table, row["interpolation"], repeats)
    row.update(
        build_s=build_s,
        shade_s=shade_s,
        exact_shade_s=exact_shade_s,
        frame_s=shade_s + shared_s,
        exact_frame_s=exact_shade_s + shared_s,
        speedup=exact_shade_s / shade_s,
        frame_speedup=(exact_shade_s + shared_s) / (shade_s + shared_s),
    )
    return row


def _segments(placement: str, entries: int) -> int | None:
    """The segments of a table: ``p = m`` for a placement that takes segments, else None."""
    return entries if PLACEMENT_METHODS.lookup(placement).segments else None


def _rms_by_entries(state: ViewState, placement: str, interpolation: str):
    """``rms(m)``: the rendered RMS of the placement's table of ``m`` entries, each m once."""
    cache: dict[int, float] = {}

    def rms(m: int) -> float:
        if m not in cache:
            segments = _segments(placement, m)
            cache[m] = table_error_row(state, placement, interpolation, m, segments)["rms"]
        return cache[m]

    return rms


def _fewest_entries(rms, tolerance: float, max_entries: int, least: int = 4) -> dict:
    """The fewest entries meeting ``rms(m) <= tolerance``: ``{"entries", "rms"}``.

    Doubles ``m`` from ``least`` until it passes, then bisects between the last failing and the
    first passing count; ``entries`` is None when no ``m <= max_entries`` passes.
    """
    m = least
    while m <= max_entries and rms(m) > tolerance:
        m *= 2
    if m > max_entries:
        return {"entries": None, "rms": rms(m // 2)}
    low, high = m // 2, m
    while high - low > 1 and low >= least:
        mid = (low + high) // 2
        if rms(mid) <= tolerance:
            high = mid
        else:
            low = mid
    return {"entries": high, "rms": rms(high)}


def tolerance_search(
    state: ViewState,
    tolerance: float,
    interpolation: str = "monotone",
    placements=("error", "uniform", "importance"),
    max_entries: int = 4096,
) -> dict:
    """The smallest table (entries and placement) whose rendered RMS meets ``tolerance``.

    "Model no more than a scene needs": for each placement (importance with ``p = m``), the entry
    count is doubled from 4 until the rendered image meets ``rms <= tolerance``, then bisected
    between the last failing and the first passing count. The pick is the placement with the
    fewest entries, rendered once more to verify it.

    Parameters
    ----------
    state : ViewState
        Material, view and exact render.
    tolerance : float
        Target RMS in 8-bit units (the larger of display and linear), > 0.
    interpolation : str
        Interpolation of the table.
    placements : tuple of str
        Placements to consider.
    max_entries : int
        Largest table tried.

    Returns
    -------
    dict
        ``tolerance``, ``interpolation``, ``candidates`` (per placement: ``entries`` or None when
        not reached, and its ``rms``), and the pick: ``placement``, ``entries``, ``rms``,
        ``verified_rms``, ``verified`` (``verified_rms <= tolerance``).

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> state = view_state(constant_material(50.0), "near", 16, compiled=False)
    >>> pick = tolerance_search(state, 0.05, placements=("error",))
    >>> pick["placement"], pick["verified"]
    ('error', True)
    """
    require(
        isinstance(tolerance, int | float) and np.isfinite(tolerance) and tolerance > 0,
        f"--tolerance: must be a number > 0, got {tolerance!r}",
    )
    candidates = {
        placement: _fewest_entries(
            _rms_by_entries(state, placement, interpolation), tolerance, max_entries
        )
        for placement in placements
    }
    result = {"tolerance": float(tolerance), "interpolation": interpolation}
    result["candidates"] = candidates
    reached = [(c["entries"], p) for p, c in candidates.items() if c["entries"] is not None]
    if not reached:
        result.update(placement=None, entries=None, rms=None, verified_rms=None, verified=False)
        return result
    # The pick: the fewest entries (ties in the order of placements), rendered once more
    entries, placement = min(reached, key=lambda pair: (pair[0], placements.index(pair[1])))
    segments = _segments(placement, entries)
    verified = table_error_row(state, placement, interpolation, entries, segments)["rms"]
    result.update(
        placement=placement,
        entries=entries,
        rms=candidates[placement]["rms"],
        verified_rms=verified,
        verified=bool(verified <= tolerance),
    )
    return result


def scene_state(scene: str, view: str, resolution: int, compiled: bool = True) -> ViewState:
    """:func:`view_state` of a registered scene (``R1``, ``R2``, ``R3``, ``bimodal``, ``n2000``).

    Examples
    --------
    >>> scene_state("R1", "near", 8, compiled=False).exact.shape
    (64, 3)
    """
    return view_state(SCENES.lookup(scene).build(), view, resolution, compiled)


def bimodal_material(n_low: float, n_high: float, split_nm: float = 580.0) -> SpectralPhong:
    """Flat ``k_d = 0.2``, ``k_s = 0.5`` under D65 with ``n = n_low`` below ``split_nm``, else high.

    Examples
    --------
    >>> bimodal_material(5.0, 500.0).n[[0, -1]]
    array([  5., 500.])
    """
    wl = DEFAULT_GRID.wavelengths_nm
    flat = np.ones(wl.size)
    n = np.where(wl < split_nm, n_low, n_high)
    return spectral_phong_unit_peak(
        0.2 * flat, 0.5 * flat, n, "D65", f"bimodal {n_low:g}/{n_high:g}"
    )


def rising_material(n_top: float, power: float = 1.0, n_bottom: float = 10.0) -> SpectralPhong:
    """Flat ``k_d = 0.2``, ``k_s = 0.5`` under D65; ``n`` rises steadily to ``n_top``.

    ``n(λ) = n_bottom + (n_top − n_bottom) x^power`` with ``x`` from 0 at the grid's first band
    to 1 at its last: every band has its own exponent (41 distinct powers), the class on which the
    benchmarks' ``rising`` sweep measures the table's speed-up.

    Examples
    --------
    >>> rising_material(2000.0).n[[0, 20, -1]]
    array([  10., 1005., 2000.])
    """
    x = np.linspace(0.0, 1.0, DEFAULT_GRID.n_bands)
    n = n_bottom + (n_top - n_bottom) * x**power
    flat = np.ones(x.size)
    name = f"rising {n_top:g}" + (f"^{power:g}" if power != 1.0 else "")
    return spectral_phong_unit_peak(0.2 * flat, 0.5 * flat, n, "D65", name)


def format_tolerance(result: dict) -> str:
    """A tolerance search as text.

    Examples
    --------
    >>> r = {"tolerance": 0.05, "interpolation": "monotone", "placement": "error", "entries": 20,
    ...      "rms": 0.04, "verified_rms": 0.04, "verified": True,
    ...      "candidates": {"error": {"entries": 20, "rms": 0.04}}}
    >>> print(format_tolerance(r).splitlines()[-1])
    pick: error with 20 entries, RMS 0.04 on the rendered image (verified)
    """
    lines = [f"--tolerance {result['tolerance']:g} ({result['interpolation']} interpolation):"]
    for placement, c in result["candidates"].items():
        reached = f"{c['entries']} entries" if c["entries"] else "not reached"
        lines.append(f"  {placement:10} {reached:>14}  RMS {c['rms']:.3g}")
    if result["placement"] is None:
        lines.append("pick: none meets the tolerance")
    else:
        state = "verified" if result["verified"] else "NOT verified"
        lines.append(
            f"pick: {result['placement']} with {result['entries']} entries, RMS "
            f"{result['verified_rms']:.3g} on the rendered image ({state})"
        )
    return "\n".join(lines)
