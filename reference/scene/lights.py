"""Light sources: point lights with Wang et al.'s attenuation, ambient light, lat-long environments.

A light carries a relative spectral power distribution ``spectrum`` and a scalar ``intensity``.
Shading folds the spectrum into the band weights (``reference.colour.colorimetry.band_weights(grid,
light.spectrum)``), so a perfect white diffuser facing a point light at unit attenuation has Y =
``intensity``; spectral lines between grid nodes are integrated, not point-sampled (docs/errata.md,
E7).

- :class:`PointLight`: position, spectrum, intensity and the attenuation constants ``(c1, c2, c3)``
of
  Eq. (1), Wang et al., with the erratum ``f_att = min(1/(c1 + c2 d + c3 d²), 1)`` (docs/errata.md,
  E2). The default ``(1, 0, 0)`` means no fall-off.
- :class:`AmbientLight`: the ``I_a`` of Eq. (1), Wang et al.
- :class:`SphereLight`: an emitting sphere of uniform radiance (not in the papers; integrated over
  the cone it subtends by :mod:`reference.scene.sphere_light`, docs/errata.md, E114).
- :class:`EnvironmentLight`: a lat-long radiance map (RGB or one channel per band) in the
orientation of
  ``reference.geometry.envmap``; the SH engine prefilters it.

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
Model".
- J. D. Foley, A. van Dam, S. K. Feiner, J. F. Hughes, *Computer Graphics: Principles and Practice*,
2nd ed.,
  §16.1 (attenuation).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.colour.spectra import Spectrum, spectrum_from_dataset
from reference.errors import require, require_finite
from reference.geometry.envmap import DEFAULT_TEXEL_PLACEMENT, TEXEL_PLACEMENTS, check_latlong_shape

__all__ = [
    "AmbientLight",
    "EnvironmentLight",
    "PointLight",
    "SphereLight",
    "attenuation_Wang",
    "point_light_vectors",
]


def attenuation_Wang(d, c1: float = 1.0, c2: float = 0.0, c3: float = 0.0) -> np.ndarray:
    """Distance attenuation of a point light, clamped to at most 1.

    Eq. (1), Wang et al., with Erratum E2 (the paper prints ``max``; the intent, after Foley et al.,
    is ``min``).

    Parameters
    ----------
    d : array_like, shape (...,)
        Distance from the light to the surface point, world units, >= 0.
    c1, c2, c3 : float
        Constant, linear and quadratic coefficients, each >= 0, not all 0.

    Returns
    -------
    ndarray, shape (...,)
        ``min(1/(c1 + c2 d + c3 d²), 1)``, in (0, 1].

    Examples
    --------
    >>> attenuation_Wang([0.5, 1.0, 2.0, 4.0], 0.0, 0.0, 1.0)
    array([1.    , 1.    , 0.25  , 0.0625])
    """
    d = np.asarray(d, dtype=np.float64)
    denominator = c1 + c2 * d + c3 * d * d
    with np.errstate(divide="ignore"):
        # Eq. (1), Wang et al. (Erratum E2: min, not max): f_att = min(1/(c1 + c2 d_L + c3 d_L²), 1)
        return np.minimum(1.0 / denominator, 1.0)


def point_light_vectors(light_position, positions) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors from surface points to a point light, and the distances.

    Parameters
    ----------
    light_position : array_like, shape (3,)
        Light position.
    positions : ndarray, shape (..., 3)
        Surface points.

    Returns
    -------
    L : ndarray, shape (..., 3)
        Unit direction towards the light.
    d : ndarray, shape (...,)
        Distance to the light.

    Examples
    --------
    >>> L, d = point_light_vectors([0.0, 0.0, 2.0], np.zeros((1, 3)))
    >>> L, d
    (array([[0., 0., 1.]]), array([2.]))
    """
    delta = np.asarray(light_position, dtype=np.float64) - np.asarray(positions, dtype=np.float64)
    d = np.linalg.norm(delta, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        L = delta / d[..., None]
    return L, d


def _default_spectrum() -> Spectrum:
    return spectrum_from_dataset("illuminant", "D65")


@dataclass(frozen=True)
class PointLight:
    """A point light with a spectrum and Wang et al.'s attenuation.

    Parameters
    ----------
    position : array_like, shape (3,)
        World position.
    spectrum : Spectrum
        Relative spectral power ``I_p(λ)``; default CIE D65.
    intensity : float
        Scale, >= 0: a white diffuser facing the light at unit attenuation has Y = ``intensity``.
    attenuation : tuple of 3 floats
        ``(c1, c2, c3)`` of Eq. (1), Wang et al., each >= 0, not all 0; default no fall-off.

    Examples
    --------
    >>> PointLight((0.0, 5.0, 5.0)).attenuation
    (1.0, 0.0, 0.0)
    """

    position: tuple = (0.0, 0.0, 10.0)
    spectrum: Spectrum = field(default_factory=_default_spectrum)
    intensity: float = 1.0
    attenuation: tuple = (1.0, 0.0, 0.0)

    def __post_init__(self):
        p = require_finite(self.position, "light.position")
        require(p.shape == (3,), f"light.position: must be 3 numbers, got shape {p.shape}")
        require(
            np.isfinite(self.intensity) and self.intensity >= 0,
            f"light.intensity: must be finite and >= 0, got {self.intensity}",
        )
        c = require_finite(self.attenuation, "light.attenuation")
        require(
            c.shape == (3,) and (c >= 0).all() and c.sum() > 0,
            f"light.attenuation: must be 3 numbers >= 0, not all 0, got {self.attenuation}",
        )
        object.__setattr__(self, "position", tuple(float(x) for x in p))
        object.__setattr__(self, "attenuation", tuple(float(x) for x in c))
        object.__setattr__(self, "intensity", float(self.intensity))


@dataclass(frozen=True)
class SphereLight:
    """A sphere that emits a uniform radiance ``intensity · S(λ)`` from every point of its surface.

    Not in the three papers (docs/errata.md, E114): the area light of physically based renderers
    (Mitsuba 3's ``sphere`` shape with an ``area`` emitter, pbrt-v4's ``diffuse`` area light on a
    sphere). Its spectrum is folded into the band weights as a point light's is, so a surface
    seeing the light's own face has Y = ``intensity``, and a white diffuser at distance ``d`` from
    the centre, facing it (the whole sphere above its horizon), has Y = ``intensity · r²/d²``:
    the value of a point light of intensity ``intensity · r²`` at the centre with
    ``attenuation = [0, 0, 1]``. The light is not seen by the camera and casts no shadows on other
    objects (as specref's point lights); a surface inside the sphere receives nothing.

    Parameters
    ----------
    position : array_like, shape (3,)
        Centre, in scene units.
    radius : float
        Radius, > 0.
    spectrum : Spectrum
        Relative spectral radiance ``S(λ)``; default CIE D65.
    intensity : float
        Scale, >= 0.

    Examples
    --------
    >>> SphereLight((0.0, 0.0, 3.0), 0.5).radius
    0.5
    """

    position: tuple = (0.0, 0.0, 10.0)
    radius: float = 1.0
    spectrum: Spectrum = field(default_factory=_default_spectrum)
    intensity: float = 1.0

    def __post_init__(self):
        p = require_finite(self.position, "light.position")
        require(p.shape == (3,), f"light.position: must be 3 numbers, got shape {p.shape}")
        require(
            np.isfinite(self.radius) and self.radius > 0,
            f"light.radius: must be finite and > 0, got {self.radius}",
        )
        require(
            np.isfinite(self.intensity) and self.intensity >= 0,
            f"light.intensity: must be finite and >= 0, got {self.intensity}",
        )
        object.__setattr__(self, "position", tuple(float(x) for x in p))
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "intensity", float(self.intensity))


@dataclass(frozen=True)
class AmbientLight:
    """Uniform ambient light, the ``I_a`` of Eq. (1), Wang et al.

    Parameters
    ----------
    spectrum : Spectrum
        Relative spectral power; default CIE D65.
    intensity : float
        Scale, >= 0.

    Examples
    --------
    >>> AmbientLight(intensity=0.1).intensity
    0.1
    """

    spectrum: Spectrum = field(default_factory=_default_spectrum)
    intensity: float = 1.0

    def __post_init__(self):
        require(
            np.isfinite(self.intensity) and self.intensity >= 0,
            f"light.intensity: must be finite and >= 0, got {self.intensity}",
        )
        object.__setattr__(self, "intensity", float(self.intensity))


@dataclass(frozen=True, eq=False)
class EnvironmentLight:
    """A distant lat-long environment (Mitsuba 3 orientation, ``reference.geometry.envmap``).

    Parameters
    ----------
    image : ndarray, shape (H, W, C)
        Radiance, finite and >= 0; ``W = 2H``. ``C = 3`` for RGB (linear, in ``colourspace``), or
        one channel per wavelength in ``wavelengths_nm``.
    wavelengths_nm : ndarray, shape (C,), optional
        Wavelengths of a spectral map's channels; None for RGB.
    colourspace : str
        Colourspace of an RGB map.
    intensity : float
        Scale, >= 0.
    name : str
        Where it came from (the file), for messages and cache keys.
    texel_placement : str
        Where the texels sit on the sphere, a key of ``reference.geometry.envmap.TEXEL_PLACEMENTS``:
        ``"centred"`` (specref's rows at ``v = (j + ½)/H``, default) or ``"mitsuba"`` (Mitsuba 3's
        rows at ``v = j/(H − 1)``, for like-for-like comparisons). :meth:`centred_image` is the map
        on specref's rows.

    Examples
    --------
    >>> env = EnvironmentLight(np.ones((4, 8, 3)), name="white")
    >>> env.is_spectral
    False
    """

    image: np.ndarray
    wavelengths_nm: np.ndarray | None = None
    colourspace: str = "sRGB"
    intensity: float = 1.0
    name: str = "environment"
    texel_placement: str = DEFAULT_TEXEL_PLACEMENT

    def __post_init__(self):
        TEXEL_PLACEMENTS.lookup(self.texel_placement)
        image = np.asarray(self.image, dtype=np.float64)
        require(
            image.ndim == 3, f"{self.name}: environment image must be (H, W, C), got {image.shape}"
        )
        check_latlong_shape(image.shape, self.name)
        bad = ~np.isfinite(image)
        require(not bad.any(), f"{self.name}: radiance must be finite, found NaN or inf")
        require((image >= 0).all(), f"{self.name}: radiance must be >= 0, found {image.min():g}")
        if self.wavelengths_nm is None:
            require(
                image.shape[2] == 3,
                f"{self.name}: an RGB environment needs 3 channels, got {image.shape[2]}; give "
                "wavelengths_nm for a spectral map",
            )
        else:
            wl = require_finite(self.wavelengths_nm, f"{self.name}: wavelengths_nm")
            require(
                wl.shape == (image.shape[2],) and (np.diff(wl) > 0).all(),
                f"{self.name}: wavelengths_nm must increase and match the {image.shape[2]} "
                "channels",
            )
            object.__setattr__(self, "wavelengths_nm", wl)
        require(
            np.isfinite(self.intensity) and self.intensity >= 0,
            f"{self.name}: intensity must be finite and >= 0, got {self.intensity}",
        )
        image.setflags(write=False)
        object.__setattr__(self, "image", image)

    @property
    def is_spectral(self) -> bool:
        """True for a map with one channel per wavelength."""
        return self.wavelengths_nm is not None

    def centred_image(self, image=None) -> np.ndarray:
        """``image`` (default the map, or any per-texel data of it) on specref's centred rows.

        Examples
        --------
        >>> ramp = np.arange(4.0)[:, None, None] * np.ones((4, 8, 3))
        >>> EnvironmentLight(ramp, texel_placement="mitsuba").centred_image()[:, 0, 0]
        array([0.375, 1.125, 1.875, 2.625])
        """
        data = self.image if image is None else image
        return TEXEL_PLACEMENTS.lookup(self.texel_placement).reference(data)
