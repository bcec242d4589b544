"""ImpastoR's settings from a tolerance against the fixed 32/32/36: frame time and error.

:func:`tolerance_case` renders one held-out painting under one booth light at the fixed settings
(:data:`impastor.settings.FIXED_SETTINGS`) and at the settings each tolerance chooses
(:func:`impastor.settings.settings_from_tolerance`, one pilot for all), times the frames and
measures each against the brute force (:func:`impastor.settings.painting_brute_force`) on pixels
of the frame itself, evenly spread: the pilot's pixels are another sample of the same frame
(stratified, seeded), so the promise is tested on pixels it was not made on.
:func:`tolerance_study` runs the cases as tasks.

:func:`method_speed_accuracy` charts every lighting method of the painting (median cut, variance
minimisation, FIS, the hybrid with and without its fail-safe) and the brute force on one set of
canvas pixels: the time of a frame's shading against its error, over the counts of lights and
samples.
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np

from impastor.horizon import horizon_at_texels
from impastor.multispectral import channels_to_XYZ
from impastor.painting import (
    HORIZON_SECTORS,
    PAINTING_LIGHTING_METHODS,
    cached_horizon_map,
    canvas_pixels,
    impasto_painting,
    load_paint_spectra,
    painting_scene,
    render_painting,
    shade_canvas,
)
from impastor.settings import (
    FIXED_SETTINGS,
    LIGHT_LADDER,
    PaintingPilot,
    painting_brute_force,
    relative_rms_error,
    settings_from_tolerance,
    settings_no_worse_than,
)

__all__ = [
    "EQUAL_ERROR",
    "METHODS_SIZE",
    "best_speedup_at_fixed_error",
    "method_speed_accuracy",
    "tolerance_case",
    "tolerance_study",
]


#: The side of the frame whose visible pixels :func:`method_speed_accuracy` shades.
METHODS_SIZE = 48


def _best_time(function, repeats: int) -> tuple:
    """``function()``'s result and its best wall time over ``repeats`` calls."""
    best, result = np.inf, None
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return result, best


def method_speed_accuracy(
    seed: int = 61,
    light: str = "D65",
    size: int = METHODS_SIZE,
    light_resolution: tuple = (128, 64),
    counts=LIGHT_LADDER,
    repeats: int = 3,
    backend: str = "numba",
) -> dict:
    """Each lighting method's shading time against its error, and the brute force's time.

    §3.5, Ferwerda: on the visible canvas pixels of a ``size``² frame of a held-out painting under
    a booth light, every method of :data:`impastor.painting.PAINTING_LIGHTING_METHODS` shades
    with N point lights and K FIS samples, N = K = each of ``counts`` (the hybrid with its
    fail-safe on and off), shadows from a :data:`~impastor.painting.HORIZON_SECTORS`-sector
    horizon; each is timed (the best of ``repeats``, the horizon look-up included) and measured
    against :func:`impastor.settings.painting_brute_force` (relative RMS of XYZ), whose own time
    is the baseline every method must beat.

    Returns
    -------
    dict
        ``pixels``, ``brute_force_seconds`` and ``rows``: per method and count ``method``,
        ``count``, ``seconds`` and ``error``.

    Examples
    --------
    >>> r = method_speed_accuracy(size=8, light_resolution=(16, 8), counts=(4,), repeats=1,
    ...                           backend="numpy")
    >>> sorted({row["method"] for row in r["rows"]})
    ['fis', 'hybrid', 'hybrid, no fail-safe', 'median_cut', 'variance_min']
    """
    painting = impasto_painting(max(size, 16), seed=seed)
    px = canvas_pixels(painting, size)
    horizon = horizon_at_texels(
        painting["height"], painting["pixel_size"], px.row, px.col, HORIZON_SECTORS, 32, backend
    )
    reference_scene = painting_scene(light, "hybrid", painting, light_resolution=light_resolution)
    truth, brute_seconds = _best_time(lambda: painting_brute_force(reference_scene, px, backend), 1)
    reference = channels_to_XYZ(truth, reference_scene.design)
    variants = [(m, m, m == "hybrid") for m in PAINTING_LIGHTING_METHODS.names()]
    variants.append(("hybrid, no fail-safe", "hybrid", False))
    rows = []
    for label, method, failsafe in variants:
        scene = painting_scene(light, method, painting, light_resolution=light_resolution)
        for count in counts:
            settings = {"n_lights": count, "n_samples": count, "failsafe": failsafe}
            (L, _), seconds = _best_time(
                lambda s=settings, sc=scene: shade_canvas(sc, px, s, lambda: horizon, backend),
                repeats,
            )
            error = relative_rms_error(channels_to_XYZ(L, scene.design), reference)
            rows.append({"method": label, "count": int(count), "seconds": seconds, "error": error})
    return {"pixels": int(px.P.shape[0]), "brute_force_seconds": brute_seconds, "rows": rows}


def _frames(scene, light, size, chosen: list, spectra, repeats, backend):
    """Each setting's frame and its best time of ``repeats`` (horizon maps precomputed).

    The settings take turns within each round, so a burst of load on a shared machine slows
    every setting's round alike instead of one setting's block of rounds.
    """
    painting = scene.painting
    options = []
    for settings in chosen:
        options.append(dict(
            painting=painting, spectra=spectra, light_resolution=scene.plane.shape[::-1],
            backend=backend, **settings.render_options(),
        ))  # fmt: skip
    frames, seconds = [None] * len(chosen), [np.inf] * len(chosen)
    for _ in range(repeats):
        for i, kwargs in enumerate(options):
            # the horizon map outside the timing (a cache hit unless the turns evicted it)
            cached_horizon_map(
                painting["height"], painting["pixel_size"], chosen[i].n_sectors, 32, backend
            )
            start = time.perf_counter()
            out = render_painting(light, size, "hybrid", **kwargs)
            seconds[i] = min(seconds[i], time.perf_counter() - start)
            frames[i] = out["XYZ"]
    return frames, seconds


def tolerance_case(task) -> dict:
    """One painting under one light: fixed settings and each tolerance's, timed and measured.

    Parameters
    ----------
    task : tuple
        ``(seed, light, tolerances, size, light_resolution, eval_pixels, repeats, backend)``:
        the painting's seed, the illuminant, the tolerances (relative RMS), the frame's side,
        the booth light's (W, H), how many frame pixels to measure (evenly spread), frames per
        timing (the best counts) and the kernels' backend.

    Returns
    -------
    dict
        ``seed``, ``light``, ``pilot_seconds``, ``eval_pixels`` and ``rows``: per setting
        (``"fixed"`` first, then each tolerance) ``label``, ``tolerance``, ``settings``
        (N, K, S, fail-safe, the α groups off the hybrid), ``shares`` (the pilot pixels' on the
        point lights, FIS and the hybrid; None for the fixed settings), ``pilot_error``,
        ``met``, ``choose_seconds``, ``frame_seconds`` and ``error`` (the frame's relative RMS
        against brute force); ``matched``: the same for the settings
        :func:`~impastor.settings.settings_no_worse_than` chooses against the fixed ones (its
        ``tolerance`` the fixed settings' pilot error), the comparison at equal error.

    Examples
    --------
    >>> case = tolerance_case((61, "A", (0.05,), 16, (16, 8), 40, 1, "numpy"))
    >>> [r["label"] for r in case["rows"]], case["rows"][1]["met"], case["matched"]["label"]
    (['fixed', '5 %'], True, 'no worse than fixed')
    """
    seed, light, tolerances, size, light_resolution, eval_pixels, repeats, backend = task
    spectra = load_paint_spectra()
    painting = impasto_painting(size, seed=seed)
    scene = painting_scene(light, "hybrid", painting, light_resolution=light_resolution)
    start = time.perf_counter()
    pilot = PaintingPilot(scene, size, backend)
    pilot_seconds = time.perf_counter() - start
    px = canvas_pixels(painting, size)
    index = np.unique(np.linspace(0, px.P.shape[0] - 1, eval_pixels).round().astype(int))
    reference = channels_to_XYZ(
        painting_brute_force(scene, px.subset(index), backend), scene.design
    )
    # the ladder of tolerances, then the settings no worse than the fixed ones on the pilot
    labels = ["fixed", *(f"{100 * t:g} %" for t in tolerances), "no worse than fixed"]
    chosen, choose_seconds = [FIXED_SETTINGS], [0.0]
    for choose in [*(partial(settings_from_tolerance, scene, t) for t in tolerances),
                   partial(settings_no_worse_than, scene, FIXED_SETTINGS)]:  # fmt: skip
        start = time.perf_counter()
        chosen.append(choose(pilot=pilot))
        choose_seconds.append(time.perf_counter() - start)
    frames, seconds = _frames(scene, light, size, chosen, spectra, repeats, backend)
    rows = []
    for i, settings in enumerate(chosen):
        rows.append({
            "label": labels[i],
            "tolerance": settings.tolerance,
            "settings": settings.render_options(),
            "shares": settings.shares,
            "pilot_error": settings.pilot_error,
            "met": settings.met,
            "choose_seconds": choose_seconds[i],
            "frame_seconds": seconds[i],
            "error": relative_rms_error(frames[i][px.gbuffer.mask][index], reference),
        })  # fmt: skip
    return {
        "seed": seed,
        "light": light,
        "pilot_seconds": pilot_seconds,
        "eval_pixels": int(index.size),
        "rows": rows[:-1],
        "matched": rows[-1],
    }


#: Errors within this factor of the fixed settings' count as equal: the frame's error is itself
#: measured on a sample of its pixels.
EQUAL_ERROR = 1.05


def best_speedup_at_fixed_error(case: dict) -> float | None:
    """The fixed frame's time over the fastest tolerance frame at no more than its error.

    "No more" within :data:`EQUAL_ERROR`; None when no tolerance reached the fixed settings' error.
    The frames are the ladder's and, where the case has it, ``matched``'s.

    Examples
    --------
    >>> rows = [{"label": "fixed", "frame_seconds": 2.0, "error": 0.01},
    ...         {"label": "1 %", "frame_seconds": 1.0, "error": 0.009},
    ...         {"label": "2 %", "frame_seconds": 0.5, "error": 0.018}]
    >>> best_speedup_at_fixed_error({"rows": rows})
    2.0
    """
    fixed, *chosen = case["rows"]
    chosen += [case["matched"]] if case.get("matched") else []
    times = [r["frame_seconds"] for r in chosen if r["error"] <= EQUAL_ERROR * fixed["error"]]
    return fixed["frame_seconds"] / min(times) if times else None


def tolerance_study(cases, run=None, **options) -> list[dict]:
    """:func:`tolerance_case` for each ``(seed, light)`` of ``cases``, through ``run``.

    Parameters
    ----------
    cases : sequence of (int, str)
    run : callable, optional
        ``run(function, tasks, desc)`` (the report's ``ctx.run_tasks``); default in turn.
    **options
        ``tolerances``, ``size``, ``light_resolution``, ``eval_pixels``, ``repeats``,
        ``backend``.

    Examples
    --------
    >>> cases = tolerance_study([(61, "D65")], tolerances=(0.05,), size=16,
    ...                         light_resolution=(16, 8), eval_pixels=30, repeats=1,
    ...                         backend="numpy")
    >>> len(cases), cases[0]["light"]
    (1, 'D65')
    """
    keys = ("tolerances", "size", "light_resolution", "eval_pixels", "repeats", "backend")
    tasks = [(seed, light, *(options[k] for k in keys)) for seed, light in cases]
    run = run or (lambda f, items, desc: [f(t) for t in items])
    return run(tolerance_case, tasks, "ImpastoR settings from a tolerance")
