"""Shading with environment light: prefiltered maps looked up per pixel (Herbert et al. §5.4).

Importing ``shrm`` registers two shaders in ``reference.scene.shading.SHADERS``:

- ``LambertMaterial/EnvironmentLight``: reflected radiance ``k_d(λ) E(n, λ) / π`` with E the
  prefiltered irradiance map (kernel ``lambert``), looked up by the normal.
- ``PhongMaterial/EnvironmentLight``: the diffuse term above plus ``k_s(λ) S_n(λ)(r)``, the
  prefiltered Phong map of the band's exponent n(λ) looked up by the reflected view vector
  ``r = 2 (N·V) N − V``. The lobe is ``max(r·ω, 0)^n / π``, so that a small light of solid angle
  Ω and radiance L_s gives exactly the highlight of a point light of intensity ``L_s Ω / π`` in the
  point-light model (Eq. (2), Wang et al.), as the diffuse term does; in frequency space this is the
  normalized Phong kernel times ``2 / (n + 1)``.

The maps are computed in frequency space (project, scale by Λ_l, synthesize a cube map per band,
faces of ``min(256, max(64, 2L))`` texels), at the order :func:`shrm.accuracy.accuracy_order` picks
for a per-pixel tolerance on Y from the map's own spectrum (default 0.5 % mean, 2 % max over lit
pixels), and cached per environment. Each choice and the bound it promises is recorded in
``ctx.records["environment"]`` for the render metadata. With
``ctx.options["environment"] == "bruteforce"`` (``specref render --oracle``) each pixel integrates
the whole map instead (:func:`shrm.prefilter.prefilter_bruteforce`; with
``ctx.options["irradiance_quadrature"] == "texels"`` a Lambertian's irradiance integrates each
texel's cosine exactly, :func:`shrm.texel_irradiance.irradiance_texel_constant`).

A spectral environment (one channel per band) is resampled linearly onto the scene's grid; an RGB
one is upsampled with ``reference.colour.upsampling.RGB_to_radiance_spectra`` (Mallett & Yuksel 2019
by default, times the colourspace's white illuminant, so a white texel becomes a D65-shaped spectrum
and renders white; options ``ctx.options["upsampling"]`` and, for ``"regression"``,
``ctx.options["upsampling_model"]``, a model file). XYZ uses the equal-energy band weights:
radiance spectra carry no light to fold in.

Options read from ``ctx.options``: ``environment`` (``"frequency"`` default, or ``"bruteforce"``),
``environment_accuracy`` (mean relative error of Y, default :data:`shrm.accuracy.DEFAULT_ACCURACY`),
``environment_tol`` (the older kernel-only tail tolerance of :func:`shrm.lobes.adaptive_order`;
when given it replaces the accuracy rule), ``environment_size`` (cube face), ``upsampling``,
``upsampling_model``, ``irradiance_quadrature`` (``"fejer"`` default, or ``"texels"``).
"""

from __future__ import annotations

import weakref

import numpy as np

from reference.colour.colorimetry import band_weights
from reference.colour.spectra import SpectralGrid
from reference.colour.upsampling import DEFAULT_UPSAMPLING, RGB_to_radiance_spectra
from reference.errors import require
from reference.geometry.cubemap import cubemap_lookup_bilinear, cubemap_texel_directions
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.registry import Method
from reference.scene.lights import EnvironmentLight
from reference.scene.metadata import DEFAULT_ACCURACY, check_accuracy
from reference.scene.options import (
    check_choice,
    check_fraction,
    check_int_range,
    register_render_option,
)
from reference.scene.shading import SHADERS, Surface
from shrm.accuracy import accuracy_order, bright_texels, sparse_convolution
from shrm.lobes import adaptive_order, kernel_phong, parse_kernel
from shrm.prefilter import MAX_PREFILTER_FACE, prefilter_bruteforce, prefilter_coefficients
from shrm.sh import sh_evaluate
from shrm.texel_irradiance import irradiance_texel_constant
from shrm.transform import project_latlong

__all__ = [
    "cached_map_names",
    "cached_spectral_radiance",
    "environment_spectral_radiance",
    "phong_environment_Lambda",
    "shade_lambert_environment",
    "shade_phong_environment",
]

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def environment_spectral_radiance(
    light: EnvironmentLight,
    grid: SpectralGrid,
    upsampling: str = DEFAULT_UPSAMPLING,
    upsampling_model=None,
) -> np.ndarray:
    """The environment's spectral radiance on ``grid``: ``(H, W, n_bands)``, times its intensity.

    Spectral maps are interpolated linearly between their wavelengths (constant beyond them); RGB
    maps are upsampled (Eq. (4), Mallett & Yuksel 2019 by default). A map with another texel
    placement (``light.texel_placement``) is then resampled onto specref's rows.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_31
    >>> env = EnvironmentLight(np.full((2, 4, 3), 0.5))
    >>> environment_spectral_radiance(env, GRID_31).shape
    (2, 4, 31)
    """
    image = light.image
    if light.is_spectral:
        wl = light.wavelengths_nm
        target = grid.wavelengths_nm
        # Linear interpolation matrix from the map's bands to the grid's bands
        M = np.stack([np.interp(target, wl, np.eye(wl.size)[i]) for i in range(wl.size)])
        spectra = image @ M
    else:
        spectra = RGB_to_radiance_spectra(
            image, grid, upsampling, light.colourspace, upsampling_model
        )
    # The texels on specref's rows (light.texel_placement: "mitsuba" resamples Mitsuba 3's rows)
    return light.intensity * light.centred_image(spectra)


def _state(light: EnvironmentLight, ctx) -> dict:
    key = (
        ctx.grid,
        ctx.options.get("upsampling", DEFAULT_UPSAMPLING),
        ctx.options.get("upsampling_model"),
    )
    per_light = _CACHE.setdefault(light, {})
    if key not in per_light:
        per_light.clear()
        radiance = environment_spectral_radiance(light, ctx.grid, key[1], key[2])
        per_light[key] = {"radiance": radiance}
    return per_light[key]


def cached_map_names(light: EnvironmentLight) -> list[str]:
    """The maps this process holds for ``light``, by name (``"lambert"``, ``"normalized-phong:8"``).

    The cache keeps one entry per light, grid and upsampling; a map's key starts with its kernel's
    name. The report's scene section counts them to show that material groups share maps.

    Examples
    --------
    >>> cached_map_names(EnvironmentLight(np.ones((2, 4, 3))))
    []
    """
    return [
        str(key[0])
        for state in _CACHE.get(light, {}).values()
        for key in state
        if isinstance(key, tuple)
    ]


def cached_spectral_radiance(light: EnvironmentLight, ctx) -> np.ndarray:
    """:func:`environment_spectral_radiance` with the context's grid and upsampling, cached.

    One array per light, grid and upsampling method (dropped with the light).

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> env = EnvironmentLight(np.full((2, 4, 3), 0.5))
    >>> cached_spectral_radiance(env, ShadingContext()) is cached_spectral_radiance(
    ...     env, ShadingContext())
    True
    """
    return _state(light, ctx)["radiance"]


def phong_environment_Lambda(n, order: int) -> np.ndarray:
    """Λ_l of the lobe ``max(t, 0)^n / π`` per band: the normalized Phong Λ_l times ``2/(n+1)``.

    Eq. (7), Ramamoorthi & Hanrahan 2001 with the kernel of the module docstring.

    Parameters
    ----------
    n : array_like, shape (n_bands,)
        Phong exponent per band.
    order : int

    Returns
    -------
    ndarray, shape (n_bands, order+1)

    Examples
    --------
    >>> phong_environment_Lambda([1.0], 1).round(6)       # ∫ max(t,0)/π dω = 1
    array([[1.      , 0.666667]])
    """
    n = np.asarray(n, dtype=np.float64)
    unique = {float(v): (2.0 / (v + 1.0)) * kernel_phong(v).Lambda(order) for v in np.unique(n)}
    return np.stack([unique[float(v)] for v in n])


def _bright(light, ctx):
    """The texels lit exactly (``shrm.accuracy.bright_texels``), or None on the legacy rule."""
    if "environment_tol" in ctx.options:
        return None
    state = _state(light, ctx)
    if "bright" not in state:
        state["bright"] = bright_texels(_luminance(light, ctx))
    return state["bright"]


def _exact_part(light, ctx, kernel, directions) -> np.ndarray:
    """The bright texels' share of the prefiltered map at ``directions``, (N, n_bands), or 0."""
    bright = _bright(light, ctx)
    if bright is None or not bright.index.size:
        return 0.0
    values = bright.exact_part(_state(light, ctx)["radiance"])
    return sparse_convolution(values, bright.directions, bright.weights, kernel, directions)


def _frequency_map(light, ctx, name: str, kernel_order: int, Lambda) -> np.ndarray:
    """Cached cube map (6, S, S, n_bands) of the environment prefiltered with Λ (per band).

    Without the bright texels (:func:`_exact_part` adds them) unless the legacy rule is in use.
    """
    state = _state(light, ctx)
    # Cube faces fine enough for the order (bilinear lookup), 64 to 256 texels (erratum E76)
    size = int(ctx.options.get("environment_size", min(256, max(64, 2 * kernel_order))))
    bright = _bright(light, ctx)
    key = (name, kernel_order, size, bright is not None)
    if key not in state:
        radiance = state["radiance"]
        if bright is not None:
            radiance = radiance * bright.scale[..., None]
        coeffs = project_latlong(radiance, kernel_order, backend="ducc0", where=light.name)
        filtered = prefilter_coefficients(coeffs, Lambda)
        state[key] = sh_evaluate(filtered, cubemap_texel_directions(size), backend="ducc0")
    return state[key]


def _luminance(light, ctx) -> np.ndarray:
    """Y of the environment's spectral radiance, (H, W): what the order estimate reads."""
    state = _state(light, ctx)
    if "luminance" not in state:
        W_E = band_weights(ctx.grid, None, ctx.weights_method, ctx.observer)
        state["luminance"] = state["radiance"] @ W_E[:, 1]
    return state["luminance"]


def _order(light, ctx, kernel) -> int:
    """The SH order for a kernel, recorded with its bound in ``ctx.records``.

    From ``environment_accuracy`` (default), or the older kernel-only ``environment_tol``.
    """
    band_limit = light.image.shape[1] // 2 - 1
    kernel = parse_kernel(kernel)
    if "environment_tol" in ctx.options:
        tol = float(ctx.options["environment_tol"])
        L = min(adaptive_order(kernel, tol), band_limit)
        ctx.record("environment", f"{light.name}:{kernel.name}", {"order": L, "kernel_tol": tol})
        return L
    tol = check_accuracy(ctx.options.get("environment_accuracy", DEFAULT_ACCURACY), "accuracy")
    state = _state(light, ctx)
    key = ("order", kernel.name, tol)
    if key not in state:
        state[key] = accuracy_order(
            _luminance(light, ctx), kernel, tol, light.name, _bright(light, ctx)
        )
    choice = state[key]
    ctx.record("environment", f"{light.name}:{kernel.name}", choice.as_dict())
    return choice.order


def _irradiance(surface: Surface, light, ctx) -> np.ndarray:
    """E(n, λ) at the surface normals, (N, n_bands)."""
    if ctx.options.get("environment") == "bruteforce":
        ctx.record("environment", f"{light.name}:lambert", {"method": "bruteforce"})
        radiance = _state(light, ctx)["radiance"]
        if ctx.options.get("irradiance_quadrature", "fejer") == "texels":
            # each texel's cosine integrated exactly: a map constant over each texel (E102)
            return irradiance_texel_constant(radiance, surface.normal)
        return prefilter_bruteforce(radiance, "lambert", surface.normal)
    L = _order(light, ctx, "lambert")
    cube = _frequency_map(light, ctx, "lambert", L, parse_kernel("lambert").Lambda(L))
    E = cubemap_lookup_bilinear(cube, surface.normal, backend="numba")
    return E + _exact_part(light, ctx, "lambert", surface.normal)


def shade_lambert_environment(
    surface: Surface, material: LambertMaterial, light: EnvironmentLight, ctx
) -> np.ndarray:
    """XYZ of a Lambertian material under an environment: ``k_d E(n) / π``.

    Eq. (2), Herbert et al. (``I_d = E_d D``, with E_d the prefiltered Lambertian map) and Eq. (8),
    Ramamoorthi & Hanrahan 2001 for the irradiance.

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> env = EnvironmentLight(np.ones((16, 32, 3)))
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 1.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]),
    ...             np.zeros((1, 2)))
    >>> shade_lambert_environment(s, LambertMaterial(np.ones(41)), env, ShadingContext()).round(3)
    ... # a white sky of radiance 1: the D65 white
    array([[0.95, 1.  , 1.09]])
    """
    require(surface.normal.ndim == 2, "environment shading: surface arrays must be (N, 3)")
    # Eq. (2), Herbert et al.: I_d = E_d D, reflected radiance k_d E / π
    spectra = material.k_d * _irradiance(surface, light, ctx) / np.pi
    return spectra @ ctx.weights(None)


def shade_phong_environment(
    surface: Surface, material: PhongMaterial, light: EnvironmentLight, ctx
) -> np.ndarray:
    """XYZ of a spectral Phong material under an environment: diffuse map plus Phong map.

    Eq. (2), Wang et al. with the light replaced by prefiltered maps: ``k_d E(N)/π + k_s S_n(r)``
    (module docstring); Eq. (5), Herbert et al. (``I_s = E_s ...``, the specular map).

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> env = EnvironmentLight(np.ones((16, 32, 3)))
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 1.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]),
    ...             np.zeros((1, 2)))
    >>> m = PhongMaterial(np.zeros(41), np.ones(41), np.ones(41))
    >>> shade_phong_environment(s, m, env, ShadingContext()).round(3)   # D65 white, ∫ cos/π dω = 1
    array([[0.95, 1.  , 1.09]])
    """
    N, V = surface.normal, surface.view
    # Reflected view vector r = 2 (N·V) N − V
    r = 2.0 * np.einsum("ij,ij->i", N, V)[:, None] * N - V
    diffuse = material.k_d * _irradiance(surface, light, ctx) / np.pi
    if ctx.options.get("environment") == "bruteforce":
        radiance = _state(light, ctx)["radiance"]
        specular = np.zeros_like(diffuse)
        for value in np.unique(material.n):
            bands = material.n == value
            kernel = kernel_phong(value)
            # The lobe max(t,0)^n/π is the normalized Phong lobe times 2/(n+1)
            specular[:, bands] = (2.0 / (value + 1.0)) * prefilter_bruteforce(
                radiance[..., bands], kernel, r
            )
    else:
        L = max(_order(light, ctx, kernel_phong(v)) for v in np.unique(material.n))
        Lam = phong_environment_Lambda(material.n, L)
        name = "phong:" + ",".join(f"{v:g}" for v in material.n)
        cube = _frequency_map(light, ctx, name, L, Lam)
        specular = cubemap_lookup_bilinear(cube, r, backend="numba")
        for value in np.unique(material.n):
            bands = material.n == value
            # the bright texels, exactly: the lobe max(t,0)^n/π is the normalized one × 2/(n+1)
            exact = _exact_part(light, ctx, kernel_phong(value), r)
            if not np.isscalar(exact):
                specular[:, bands] += (2.0 / (value + 1.0)) * exact[:, bands]
    # Eq. (2), Wang et al., environment form: k_d E/π + k_s S_n(r)
    spectra = diffuse + material.k_s * specular
    return spectra @ ctx.weights(None)


SHADERS.register(
    Method(
        "LambertMaterial/EnvironmentLight",
        shade_lambert_environment,
        None,
        "Eq. (2), Herbert et al.",
    )
)
SHADERS.register(
    Method(
        "PhongMaterial/EnvironmentLight",
        shade_phong_environment,
        None,
        "Eq. (2), Wang et al.",
    )
)


def _check_environment_accuracy(value) -> float:
    """``[render.options] environment_accuracy``: a number, as ``--accuracy`` takes it."""
    number = isinstance(value, int | float) and not isinstance(value, bool)
    require(
        number and bool(np.isfinite(value)) and 0 < value <= 0.25,
        f"must be a relative error in (0, 0.25], got {value!r}",
    )
    return float(value)


register_render_option(
    "environment_accuracy", _check_environment_accuracy,
    f"environment lights' tolerance on Y (default {DEFAULT_ACCURACY}; specref render --accuracy)",
)  # fmt: skip
register_render_option(
    "environment_tol", check_fraction, "environment lights' kernel-only tolerance (erratum E76)"
)
register_render_option(
    "irradiance_quadrature",
    lambda value: check_choice(value, ["fejer", "texels"]),
    "the brute force's Lambertian irradiance: the cosine at texel centres with Fejér's weights "
    '("fejer", the default) or integrated over each texel of a map constant over each texel '
    '("texels", the conformance references; shrm.texel_irradiance)',
)
register_render_option(
    "environment_size",
    lambda value: check_int_range(value, 4, MAX_PREFILTER_FACE),
    "environment lights' prefiltered cube face, texels (default min(256, max(64, 2L)))",
)
