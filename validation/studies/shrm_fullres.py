"""SHRM rendering on the full-resolution shipped maps against brute force (Herbert et al., §9).

The default path of ``specref render`` for ``isotropic_brdf`` materials is the SH + angular split
(``shrm.split``): the SHRM of the band-limited part of the map plus the brightest texels summed per
pixel. This module measures it as an outside user would: an orthographic sphere (pixel centres, view
+z) of one BRDF under one shipped environment map at its full resolution, against the brute force
over every texel (``shrm.split.angular_sum``, the oracle of ``--oracle``), with the two figures the
report's targets gate (``docs/shrm.md``): the largest error relative to the image's peak, and the
mean |ΔY/Y| over pixels brighter than 1 % of the peak. Beside the split it measures the SHRM alone
(no residual, the same settings and half the lighting order), so that the report can chart time
against error for each.

Each case is independent: :func:`fullres_case` is a task of ``ReportContext.run_tasks``.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

from reference.colour.spectra import SpectralGrid

__all__ = ["FULLRES_BRDFS", "GRID", "environment_radiance", "fullres_case", "sphere_points"]

#: The spectral grid of the study (7 bands: the brute force's cost is linear in bands).
GRID = SpectralGrid(410.0, 710.0, 50.0)

#: BRDFs and widths of the full study: GGX and Ward from α 0.1 to 0.5 and the thin-film effect
#: pigment. ``rho_d`` 0 and ``F_0`` 1 for GGX (the specular lobe alone); ``table`` is a BRDF table
#: (:func:`tabulated_ggx` of that α).
FULLRES_BRDFS = (
    ("ggx", 0.1),
    ("ggx", 0.3),
    ("ggx", 0.5),
    ("ward_isotropic", 0.1),
    ("ward_isotropic", 0.3),
    ("ward_isotropic", 0.5),
    ("effect_pigment", 0.15),
    ("table", 0.3),
)


def sphere_points(R: int) -> tuple[np.ndarray, np.ndarray]:
    """Normals and views of an orthographic unit sphere seen from +z, ``R × R`` pixel centres.

    Examples
    --------
    >>> n, v = sphere_points(4)
    >>> n.shape, bool(np.allclose((n**2).sum(-1), 1.0)), v[0].tolist()
    ((12, 3), True, [0.0, 0.0, 1.0])
    """
    x, y = np.meshgrid((np.arange(R) + 0.5) / R * 2 - 1, (np.arange(R) + 0.5) / R * 2 - 1)
    inside = x**2 + y**2 < 1
    n = np.stack([x[inside], -y[inside], np.sqrt(1 - x[inside] ** 2 - y[inside] ** 2)], -1)
    return n, np.broadcast_to(np.array([0.0, 0.0, 1.0]), n.shape)


def environment_radiance(path, rows: int | None = None, grid=None) -> np.ndarray:
    """The spectral radiance ``(H, 2H, C)`` of a lat-long map on ``grid`` (default :data:`GRID`).

    ``rows`` box-filters the map to that height first (None: the full resolution).

    Examples
    --------
    >>> import tempfile
    >>> from reference.images.formats import write_exr
    >>> path = write_exr(Path(tempfile.mkdtemp()) / "sky.exr", np.ones((8, 16, 3)))
    >>> environment_radiance(path).shape, environment_radiance(path, 4).shape
    ((8, 16, 7), (4, 8, 7))
    """
    from reference.geometry.camera import downsample_box
    from reference.images.formats import read_image
    from reference.scene.lights import EnvironmentLight
    from shrm.environment import environment_spectral_radiance

    image = read_image(Path(path))
    if rows is not None and rows < image.shape[0]:
        f = image.shape[0] // rows
        image = downsample_box(image[: f * rows, : 2 * f * rows], f)
    return environment_spectral_radiance(EnvironmentLight(image), GRID if grid is None else grid)


def _errors(Y, truth) -> tuple[float, float]:
    # % of the peak, and mean |ΔY/Y| (%) over pixels brighter than 1 % of the peak
    peak = truth.max()
    bright = truth > 0.01 * peak
    return (
        float(100 * np.abs(Y - truth).max() / peak),
        float(100 * np.mean(np.abs(Y - truth)[bright] / truth[bright])),
    )


def tabulated_ggx(alpha: float):
    """GGX (ρ_d 0, F_0 1) of roughness ``alpha`` as a BRDF table: 5° in θ, 15° in Δφ.

    The full-resolution set's tabulated BRDF (``brdf = "table"`` of a scene file, read through
    ``docs/brdf-format.md``), at the resolution of that format's examples; the split and the
    brute force both evaluate the table (its interpolation), so the comparison is of the
    rendering path, not of the tabulation.

    Examples
    --------
    >>> tabulated_ggx(0.3).values.shape
    (19, 19, 13, 7)
    """
    from reference.materials.brdf import BRDF_METHODS
    from reference.materials.table import tabulate_brdf
    from shrm.orbit import brdf_params_on_grid

    params = brdf_params_on_grid("ggx", GRID, {"alpha": alpha, "rho_d": 0.0, "F_0": 1.0})
    return tabulate_brdf(
        BRDF_METHODS.lookup("ggx").reference, params, np.arange(0.0, 91.0, 5.0),
        np.arange(0.0, 181.0, 15.0), GRID.wavelengths_nm, name=f"GGX alpha {alpha:g}",
    )  # fmt: skip


class _Case(NamedTuple):
    """What every method of one case shades: the map's radiance, the BRDF, the sphere, Y weights."""

    env: np.ndarray
    brdf: str
    params: dict
    y: np.ndarray
    n: np.ndarray
    v: np.ndarray


def _load_case(path, brdf: str, alpha: float, pixels: int, rows: int | None) -> _Case:
    """The map on :data:`GRID`, the BRDF's parameters, the sphere's points and the Y weights."""
    from reference.scene.shading import ShadingContext
    from shrm.orbit import brdf_params_on_grid

    env = environment_radiance(path, rows)
    y = ShadingContext(GRID).weights(None)[:, 1]
    n, v = sphere_points(pixels)
    # GGX is the specular lobe alone (ρ_d 0, F_0 1); "table" is that GGX, tabulated
    extra = {"rho_d": 0.0, "F_0": 1.0} if brdf == "ggx" else {}
    if brdf == "table":
        params = {"table": tabulated_ggx(alpha)}
    else:
        params = brdf_params_on_grid(brdf, GRID, {"alpha": alpha, **extra})
    return _Case(env, brdf, params, y, n, v)


def _timed(function, *args):
    """``function(*args)`` and the seconds it took."""
    start = time.perf_counter()
    result = function(*args)
    return result, time.perf_counter() - start


def _brute_force_Y(case: _Case, renderer):
    """Y of the brute force over every texel (``shrm.split.angular_sum``), the oracle."""
    from shrm.shrm_oracles import env_quadrature
    from shrm.split import angular_sum

    quadrature = env_quadrature(case.env)
    return angular_sum(quadrature, renderer.brdf, renderer.params, case.n, case.v) @ case.y


def _figures(out, truth_Y, y, create_s: float, shade_s: float) -> dict:
    """A method's errors against the brute force, and its seconds to create and to shade."""
    pct, mean = _errors(out @ y, truth_Y)
    return {
        "pct_of_peak": pct,
        "mean_rel_pct": mean,
        "create_seconds": create_s,
        "shade_seconds": shade_s,
    }


def _settings_figures(s) -> dict:
    """The split's chosen settings, the error it promises and its spot check against brute force."""
    return {
        "F": int(s.F),
        "P": int(s.P),
        "size": int(s.size),
        "residual_texels": int(s.residual_texels),
        "promised_pct_of_peak": float(100 * s.bound_Y / s.peak_lower_bound),
        "meets_tolerance": bool(s.meets_tolerance),
        "check_pct_of_peak": float(100 * s.check_error),
    }


def _shrm_alone(case: _Case, settings, F: int, truth_Y) -> dict:
    """The SHRM without the residual (τ = ∞), at the split's settings with lighting order F."""
    from shrm.split import split_create, split_shade

    alone = dataclasses.replace(settings, F=F, tau=float("inf"), residual_texels=0)
    made, create_s = _timed(split_create, case.env, case.brdf, case.params, case.y, alone)
    (out, _), shade_s = _timed(split_shade, made, case.n, case.v)
    return {**_figures(out, truth_Y, case.y, create_s, shade_s), "F": F}


#: Samples of the Monte Carlo estimator's timing run, from which its equal-time count is scaled.
MC_CALIBRATION_SAMPLES = 256
#: The estimator's seed.
MC_SEED = 21


def _equal_time_mc(case: _Case, renderer, split_seconds: float, truth_Y) -> dict:
    """Importance-sampled Monte Carlo (``shrm.montecarlo``) given the split's time per frame.

    Equal time (Erratum E58): a run of ``m`` samples per point takes ``a + b m`` seconds (``a``:
    the set-up that does not grow with ``m``); ``a`` and ``b`` are fitted on runs of
    ``MC_CALIBRATION_SAMPLES`` and four times as many, the sample count solved for the split's
    time, and corrected once from the time that run took.
    """
    from shrm.montecarlo import environment_mc
    from shrm.shrm_oracles import env_quadrature

    quadrature = env_quadrature(case.env)

    def run(m):
        start = time.perf_counter()
        out = environment_mc(quadrature, renderer.brdf, renderer.params, case.n, case.v, m, MC_SEED)
        return out, time.perf_counter() - start

    m_1, m_2 = MC_CALIBRATION_SAMPLES, 4 * MC_CALIBRATION_SAMPLES
    t_1, t_2 = run(m_1)[1], run(m_2)[1]
    b = (t_2 - t_1) / (m_2 - m_1) if t_2 > t_1 else t_2 / m_2
    a = max(t_1 - b * m_1, 0.0)
    samples = max(1, round((split_seconds - a) / b))
    out, seconds = run(samples)
    if abs(seconds - split_seconds) > 0.25 * split_seconds and seconds > a:
        # one correction from the run's own time (the fit is of two noisy runs)
        samples = max(1, round(samples * (split_seconds - a) / (seconds - a)))
        out, seconds = run(samples)
    pct, mean = _errors(out @ case.y, truth_Y)
    return {"pct_of_peak": pct, "mean_rel_pct": mean, "shade_seconds": seconds, "samples": samples}


def fullres_case(task) -> dict:
    """One map × BRDF × α: the split, the SHRM alone and the brute force, errors and seconds.

    Parameters
    ----------
    task : tuple
        ``(path, brdf, alpha, pixels, rows, tol)``: the map, a key of ``BRDF_METHODS`` and its
        width, the sphere's image side, the map's rows (None: full resolution) and the split's
        per-pixel tolerance.

    Returns
    -------
    dict
        ``map``, ``brdf``, ``alpha``, ``side`` (the image's), ``pixels`` (shaded points),
        ``env_rows``; per method
        (``split``, ``shrm``, ``shrm_half_F``) its ``pct_of_peak``, ``mean_rel_pct``,
        ``create_seconds`` (the first frame's maps) and ``shade_seconds`` (a frame after the
        first); ``mc`` (importance-sampled Monte Carlo given the split's frame time: its
        errors, ``shade_seconds`` and ``samples`` per point); ``bruteforce_seconds``; the
        split's ``F``, ``P``, ``size``, ``residual_texels``, ``promised_pct_of_peak``,
        ``check_pct_of_peak`` (its spot check against brute force) and ``meets_tolerance``.

    Examples
    --------
    >>> import tempfile
    >>> from reference.images.formats import write_exr
    >>> sky = np.ones((16, 32, 3)); sky[3, 5] = 400.0               # a sky and a sun
    >>> path = write_exr(Path(tempfile.mkdtemp()) / "sky.exr", sky)
    >>> row = fullres_case((path, "ggx", 0.3, 6, None, 0.005))
    >>> row["split"]["pct_of_peak"] < 1.0, row["residual_texels"] > 0
    (True, True)
    """
    from shrm.split import split_renderer, split_shade

    path, brdf, alpha, pixels, rows, tol = task
    case = _load_case(path, brdf, alpha, pixels, rows)
    # The split (its maps, then a frame), then the brute force over every texel
    renderer, create_s = _timed(
        split_renderer, case.env, brdf, case.params, case.y, case.n, case.v, tol
    )
    (out, _), shade_s = _timed(split_shade, renderer, case.n, case.v)
    truth, brute_s = _timed(_brute_force_Y, case, renderer)
    s = renderer.settings
    row = {
        "map": Path(path).name,
        "brdf": brdf,
        "alpha": float(alpha),
        "side": int(pixels),
        "pixels": len(case.n),
        "env_rows": int(case.env.shape[0]),
        **_settings_figures(s),
        "bruteforce_seconds": brute_s,
    }
    row["split"] = _figures(out, truth, case.y, create_s, shade_s)
    row["mc"] = _equal_time_mc(case, renderer, shade_s, truth)
    # The SHRM alone: no residual (τ = ∞), at the split's settings and at half its F
    row["shrm"] = _shrm_alone(case, s, s.F, truth)
    row["shrm_half_F"] = _shrm_alone(case, s, max(s.F // 2, 1), truth)
    return row
