"""Deferred shading: pure functions of the G-buffer, the materials and the lights.

For each light and each material, a *shader* turns the G-buffer pixels of that material into XYZ (Y
= 1 for a perfect white diffuser facing a unit light). Shaders are registered in :data:`SHADERS`
under ``"<MaterialClass>/<LightClass>"``; :func:`shade_gbuffer` sums every light's contribution. A
new light or material type is added by registering shaders (``shrm`` registers the environment-light
shaders; ``phong_table`` registers accelerated Phong shaders as *methods*), never by editing this
dispatcher.

Point lights fold their spectrum into the band weights: a shader computes the per-band reflected
fraction ``I(λ)/I_p(λ)`` and converts it with ``W = band_weights(grid, light.spectrum)``, so
spectral lines between grid nodes are integrated (docs/errata.md, E7).

The spectral Phong model, Eq. (2), Wang et al.:
``I(λ) = f_att I_p(λ) k_d(λ) cos θ + f_att I_p(λ) k_s(λ) cos^{n(λ)} α``, with ``cos θ = N·L`` and
``cos α = t = R·V``, ``R = 2(N·L)N − L``; the specular term is zero where the light is below the
surface (``N·L <= 0``) and ``t`` is clipped to [0, 1].

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
Model".
- J. D. Foley, A. van Dam, S. K. Feiner, J. F. Hughes, *Computer Graphics: Principles and Practice*,
2nd ed.,
  §16.1.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from reference.colour.colorimetry import DEFAULT_OBSERVER, band_weights
from reference.colour.spectra import DEFAULT_GRID, SpectralGrid, Spectrum
from reference.errors import require
from reference.geometry.gbuffer import GBuffer
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.registry import Method, Registry
from reference.scene.lights import AmbientLight, PointLight, attenuation_Wang, point_light_vectors

__all__ = [
    "PHONG_POINT_METHODS",
    "SHADERS",
    "ShadingContext",
    "Surface",
    "phong_cosines",
    "phong_spectral_exact",
    "shade_gbuffer",
    "shader_key",
    "spectral_output_weights",
    "surface_of",
]


@dataclass(frozen=True)
class ShadingContext:
    """What every shader needs besides the pixels: the grid and how spectra become XYZ.

    Parameters
    ----------
    grid : SpectralGrid
        The scene's wavelength grid.
    observer : str
        Standard observer for the band weights.
    weights_method : str
        Band-weight method (``"astm_e308"`` or ``"point"``).
    options : mapping
        Per-render switches that registered shaders read, e.g. ``{"environment": "bruteforce"}`` for
        the environment-light oracle; each shader documents the keys it reads and ignores the
        others.

    Examples
    --------
    >>> from reference.colour.spectra import spectrum_from_dataset
    >>> ShadingContext().weights(spectrum_from_dataset("illuminant", "D65")).shape
    (41, 3)
    """

    grid: SpectralGrid = DEFAULT_GRID
    observer: str = DEFAULT_OBSERVER
    weights_method: str = "astm_e308"
    options: Mapping = field(default_factory=dict)
    output: str = "XYZ"
    records: dict = field(default_factory=dict, compare=False)

    def weights(self, spectrum: Spectrum | None) -> np.ndarray:
        """Band weights with ``spectrum`` folded in (None: equal-energy light).

        ``(n_bands, 3)`` to XYZ; with ``output="spectral"`` the ``(n_bands, n_bands)`` diagonal
        that turns a reflected fraction into relative spectral radiance, the light scaled so that
        the equal-energy weights give Y = 1 for a white diffuser (docs/render-outputs.md).
        """
        if self.output == "spectral":
            return spectral_output_weights(self.grid, spectrum, self.weights_method, self.observer)
        return band_weights(self.grid, spectrum, self.weights_method, self.observer)

    @property
    def n_outputs(self) -> int:
        """Values per pixel that shaders return: 3 (XYZ) or the number of bands (spectral)."""
        return self.grid.n_bands if self.output == "spectral" else 3

    def record(self, group: str, key: str, value) -> None:
        """Note a setting a shader chose (an SH order and its bound) for the render metadata.

        ``records[group][key] = value``; :mod:`reference.scene.metadata` puts ``records`` under
        ``"methods"`` in the EXR header and ``specref render --json``.
        """
        self.records.setdefault(group, {})[key] = value


def spectral_output_weights(grid, spectrum, method="astm_e308", observer=DEFAULT_OBSERVER):
    """The diagonal ``(n_bands, n_bands)`` weights of spectral output.

    A shader's reflected fraction ``R`` times these is the relative spectral radiance ``S R``
    with ``S`` the light on the grid scaled by ``1 / (S · W_E,Y)``, so that ``(S R) @ W_E`` (the
    equal-energy band weights) gives Y = 1 for a white diffuser, as the XYZ output does. None (an
    equal-energy light, or radiance with no light folded in) is the identity.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> W = spectral_output_weights(GRID_41, None)
    >>> W.shape, bool((W == np.eye(41)).all())
    ((41, 41), True)
    """
    if spectrum is None:
        return np.eye(grid.n_bands)
    from reference.colour.spectra import resample_spectrum

    S = resample_spectrum(spectrum, grid, "constant")
    W_E = band_weights(grid, None, method, observer)
    return np.diag(S / float(S @ W_E[:, 1]))


@dataclass(frozen=True)
class Surface:
    """The G-buffer pixels of one material, flattened to ``(N, ...)``.

    Attributes
    ----------
    position, normal, view : ndarray, shape (N, 3)
        World position, unit normal, unit vector towards the eye.
    uv : ndarray, shape (N, 2)
        Texture coordinates.
    """

    position: np.ndarray
    normal: np.ndarray
    view: np.ndarray
    uv: np.ndarray


def surface_of(gbuffer: GBuffer, selection) -> Surface:
    """The :class:`Surface` of the G-buffer pixels where ``selection`` (H, W) is True.

    Examples
    --------
    >>> from reference.geometry.gbuffer import empty_gbuffer
    >>> surface_of(empty_gbuffer(2, 2), np.zeros((2, 2), bool)).position.shape
    (0, 3)
    """
    return Surface(
        gbuffer.position[selection],
        gbuffer.normal[selection],
        gbuffer.view[selection],
        gbuffer.uv[selection],
    )


def phong_cosines(N, L, V) -> tuple[np.ndarray, np.ndarray]:
    """The two cosines of the Phong model: ``cos θ = N·L`` and ``t = cos α = R·V``.

    Eq. (1), Wang et al. (Figure 1: ``R = 2(N·L)N − L``).

    Parameters
    ----------
    N, L, V : ndarray, shape (..., 3)
        Unit normal, unit direction to the light, unit direction to the eye.

    Returns
    -------
    cos_theta : ndarray, shape (...,)
        ``max(N·L, 0)``.
    t : ndarray, shape (...,)
        ``R·V`` clipped to [0, 1], and 0 where ``N·L <= 0`` (no highlight from below the surface).

    Examples
    --------
    >>> N = np.array([0.0, 0.0, 1.0])
    >>> L = np.array([0.0, 0.6, 0.8]); V = np.array([0.0, -0.6, 0.8])
    >>> [float(x) for x in phong_cosines(N, L, V)]
    [0.8, 1.0]
    """
    N, L, V = (np.asarray(x, dtype=np.float64) for x in (N, L, V))
    N_dot_L = np.einsum("...i,...i->...", N, L)
    # Eq. (1), Wang et al., Figure 1: the ideal specular reflection R = 2 (N·L) N − L
    R = 2.0 * N_dot_L[..., None] * N - L
    t = np.clip(np.einsum("...i,...i->...", R, V), 0.0, 1.0)
    lit = N_dot_L > 0.0
    return np.where(lit, N_dot_L, 0.0), np.where(lit, t, 0.0)


def phong_spectral_exact(cos_theta, t, k_d, k_s, n, f_att=1.0) -> np.ndarray:
    """The spectral Phong model per band, relative to the light's spectrum: ``I(λ) / I_p(λ)``.

    Eq. (2), Wang et al.

    Parameters
    ----------
    cos_theta, t : array_like, shape (...,)
        ``N·L`` and ``R·V``, each in [0, 1] (from :func:`phong_cosines`).
    k_d, k_s, n : ndarray, shape (n_bands,)
        Diffuse and specular coefficients and the exponent per band.
    f_att : array_like, shape (...,)
        Distance attenuation (Eq. (1), Wang et al., Erratum E2).

    Returns
    -------
    ndarray, shape (..., n_bands)
        ``f_att (k_d cos θ + k_s t^n)``; multiply by the light's band weights for XYZ.

    Examples
    --------
    >>> n = np.array([1.0, 2.0])
    >>> phong_spectral_exact(np.array([1.0]), np.array([0.5]), np.ones(2), np.ones(2), n)
    array([[1.5 , 1.25]])
    """
    cos_theta = np.asarray(cos_theta, dtype=np.float64)[..., None]
    t = np.asarray(t, dtype=np.float64)[..., None]
    f_att = np.asarray(f_att, dtype=np.float64)[..., None]
    # Eq. (2), Wang et al.: I(λ)/I_p(λ) = f_att k_d(λ) cos θ + f_att k_s(λ) cos^{n(λ)} α
    return f_att * (k_d * cos_theta + k_s * t**n)


def _point_geometry(surface: Surface, light: PointLight):
    L, d = point_light_vectors(light.position, surface.position)
    f_att = attenuation_Wang(d, *light.attenuation)
    cos_theta, t = phong_cosines(surface.normal, L, surface.view)
    return cos_theta, t, f_att


def shade_phong_point_exact(
    surface: Surface, material: PhongMaterial, light: PointLight, ctx
) -> np.ndarray:
    """XYZ of a Phong material under a point light, exact spectral evaluation (the speed baseline).

    Eq. (6), Wang et al.: Eq. (2), Wang et al. summed against the band weights of Eq. (4), Wang et
    al. (the light folded in).

    Examples
    --------
    >>> m = PhongMaterial(np.ones(41), np.zeros(41), np.ones(41))
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]),
    ...             np.zeros((1, 2)))
    >>> shade_phong_point_exact(s, m, PointLight((0.0, 0.0, 3.0)), ShadingContext()).round(4)
    array([[0.9505, 1.    , 1.0888]])
    """
    cos_theta, t, f_att = _point_geometry(surface, light)
    spectra = phong_spectral_exact(cos_theta, t, material.k_d, material.k_s, material.n, f_att)
    # Eq. (6), Wang et al.: XYZ = k Σ_λ I(λ) [x̄ ȳ z̄](λ), with I_p(λ) in the band weights
    return light.intensity * (spectra @ ctx.weights(light.spectrum))


#: Methods for a Phong material under a point light, chosen by ``ctx.options["phong"]["method"]``
#: (default ``"exact"``); ``phong_table`` registers ``"table"``. Each ``reference`` is a shader.
PHONG_POINT_METHODS = Registry("Phong point-light method")
PHONG_POINT_METHODS.register(Method("exact", shade_phong_point_exact, None, "Eq. (2), Wang et al."))


def shade_phong_point(
    surface: Surface, material: PhongMaterial, light: PointLight, ctx
) -> np.ndarray:
    """XYZ of a Phong material under a point light, by the method ``ctx.options["phong"]`` names.

    Eq. (2), Wang et al. Without ``options["phong"]`` (or with ``{"method": "exact"}``) this is
    :func:`shade_phong_point_exact`; other methods are registered in :data:`PHONG_POINT_METHODS`
    (``phong_table`` adds ``"table"``, which documents its keys).

    Examples
    --------
    >>> m = PhongMaterial(np.ones(41), np.zeros(41), np.ones(41))
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]),
    ...             np.zeros((1, 2)))
    >>> shade_phong_point(s, m, PointLight((0.0, 0.0, 3.0)), ShadingContext()).round(4)
    array([[0.9505, 1.    , 1.0888]])
    """
    options = ctx.options.get("phong", {}) if isinstance(ctx, ShadingContext) else {}
    method = options.get("method", "exact") if isinstance(options, Mapping) else "exact"
    return PHONG_POINT_METHODS.lookup(method).reference(surface, material, light, ctx)


def shade_lambert_point(surface: Surface, material: LambertMaterial, light: PointLight, ctx):
    """XYZ of a Lambertian material under a point light: the diffuse term of Eq. (2), Wang et al.

    Examples
    --------
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]),
    ...             np.zeros((1, 2)))
    >>> shade_lambert_point(s, LambertMaterial(np.full(41, 0.5)), PointLight((0.0, 3.0, 3.0)),
    ...                     ShadingContext()).round(4)
    array([[0.336 , 0.3536, 0.385 ]])
    """
    cos_theta, _, f_att = _point_geometry(surface, light)
    # Eq. (2), Wang et al., diffuse term: I(λ)/I_p(λ) = f_att k_d(λ) cos θ
    spectra = (f_att * cos_theta)[:, None] * material.k_d
    return light.intensity * (spectra @ ctx.weights(light.spectrum))


def shade_ambient(surface: Surface, material, light: AmbientLight, ctx) -> np.ndarray:
    """XYZ of the ambient term ``I_a k_a`` (Eq. (1), Wang et al.); Lambert materials use ``k_d``.

    Examples
    --------
    >>> s = Surface(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 2)))
    >>> shade_ambient(s, LambertMaterial(np.ones(41)), AmbientLight(intensity=0.1),
    ...               ShadingContext())[0].round(4)
    array([0.095 , 0.1   , 0.1089])
    """
    k_a = material.k_a if isinstance(material, PhongMaterial) else material.k_d
    # Eq. (1), Wang et al.: ambient term I_a k_a
    XYZ = light.intensity * (k_a @ ctx.weights(light.spectrum))
    return np.broadcast_to(XYZ, (surface.position.shape[0], XYZ.shape[-1])).copy()


def shader_key(material, light) -> str:
    """The :data:`SHADERS` key of a material and a light: ``"<MaterialClass>/<LightClass>"``.

    Examples
    --------
    >>> shader_key(LambertMaterial(np.ones(3)), PointLight())
    'LambertMaterial/PointLight'
    """
    return f"{type(material).__name__}/{type(light).__name__}"


#: Shaders by ``"<MaterialClass>/<LightClass>"``; each ``reference`` is
#: ``f(surface, material, light, ctx) -> XYZ (N, 3)``.
SHADERS = Registry("shader")
SHADERS.register(
    Method("PhongMaterial/PointLight", shade_phong_point, None, "Eq. (2), Wang et al.")
)
SHADERS.register(
    Method("LambertMaterial/PointLight", shade_lambert_point, None, "Eq. (2), Wang et al.")
)
SHADERS.register(Method("PhongMaterial/AmbientLight", shade_ambient, None, "Eq. (1), Wang et al."))
SHADERS.register(
    Method("LambertMaterial/AmbientLight", shade_ambient, None, "Eq. (1), Wang et al.")
)


def shade_gbuffer(
    gbuffer: GBuffer, materials: Sequence, lights: Sequence, ctx: ShadingContext | None = None
) -> np.ndarray:
    """Deferred shading: sum every light's XYZ over the G-buffer, material by material.

    Parameters
    ----------
    gbuffer : GBuffer
        Visible surfaces; ``material_id`` indexes ``materials``.
    materials : sequence
        Material instances.
    lights : sequence
        Light instances.
    ctx : ShadingContext, optional
        Grid and colorimetry; default the 41-band grid.

    Returns
    -------
    ndarray, shape (H, W, 3)
        XYZ, 0 where nothing is visible.

    Raises
    ------
    SpecrefError
        A material/light pair with no registered shader, or a material whose bands do not match the
        grid.

    Examples
    --------
    >>> from reference.geometry.camera import Camera
    >>> from reference.geometry.gbuffer import render_gbuffer
    >>> from reference.geometry.shapes import Sphere
    >>> g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 5)), 5, 5)
    >>> XYZ = shade_gbuffer(g, [LambertMaterial(np.ones(41))], [PointLight((0.0, 0.0, 5.0))])
    >>> XYZ[2, 2].round(4)
    array([0.9505, 1.    , 1.0888])
    """
    ctx = ctx or ShadingContext()
    H, W = gbuffer.shape
    XYZ = np.zeros((H, W, ctx.n_outputs))
    for index, material in enumerate(materials):
        bands = getattr(material, "k_d", None)
        require(
            bands is None or bands.size == ctx.grid.n_bands,
            f"{material.name}: has {None if bands is None else bands.size} bands but the grid "
            f"{ctx.grid.label} has {ctx.grid.n_bands}",
        )
        selection = gbuffer.mask & (gbuffer.material_id == index)
        if not selection.any():
            continue
        surface = surface_of(gbuffer, selection)
        for light in lights:
            key = shader_key(material, light)
            values = SHADERS.lookup(key).reference(surface, material, light, ctx)
            require(
                np.shape(values)[-1] == ctx.n_outputs,
                f"{material.name}: the shader {key} gives {np.shape(values)[-1]} values per "
                f"pixel, not {ctx.output} output ({ctx.n_outputs}); render it as display or xyz",
            )
            XYZ[selection] += values
    return XYZ
