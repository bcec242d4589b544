"""The reconstructed scenes R1, R2, R3 of Wang et al.'s Table 1, the failure cases, and the views.

The paper shows its three "combinations of reflectance" only as plots (Figures 5-7: light SPD,
``k_d``, ``k_s`` and ``n(λ)``) without numbers. The materials here are **reconstructions** with the
properties the captions and the text describe, not the paper's data:

- **R1**: smooth spectra with moderate exponents: D65, an orange ``k_d`` (logistic edge at
  600 nm), a slowly rising ``k_s`` and ``n(λ)`` rising linearly from 20 to 80;
- **R2**: an exponent that varies strongly with wavelength (the paper's hardest case for uniform
  tables): illuminant A, a blue ``k_d``, flat ``k_s = 0.4``, ``n(λ) = 10 · 100^{(λ−380)/400}``
  (10 at 380 nm to 1000 at 780 nm);
- **R3**: a narrow-band specular with high exponents: FL11 (a tri-band lamp with lines), a grey
  ``k_d`` with a red edge, ``k_s`` a 15 nm-wide Gaussian at 530 nm, ``n(λ)`` from 2000 to 3000.

Two failure cases (``docs/phong-tables.md``): ``bimodal`` (``n = 5`` below 580 nm,
500 above) and ``n2000`` (``n ≡ 2000``), both with flat ``k_d = 0.2``, ``k_s = 0.5`` under D65.

Every scene is a unit sphere at the origin, seen from ``EYE`` and lit by one point light at
``LIGHT_POSITION`` with attenuation ``LIGHT_ATTENUATION`` (so ``f_att`` varies over the sphere,
from 0.64 to 1). The light's intensity is set so that the brightest possible value,
``max_c (D_c + f_sp,c(1))``, is display white (:func:`spectral_phong_unit_peak`). Views:

- **far**: the whole sphere (vertical field of view 30°);
- **near**: zoomed on the highlight (5°), aimed at the point of the sphere where ``R·V = 1``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from phong_table.model import SpectralPhong
from reference.colour.spectra import DEFAULT_GRID, SpectralGrid, spectrum_from_dataset
from reference.errors import require
from reference.geometry.camera import Camera
from reference.geometry.shapes import Sphere
from reference.materials.types import PhongMaterial
from reference.registry import Registry
from reference.scene.lights import PointLight

__all__ = [
    "EYE",
    "LIGHT_ATTENUATION",
    "LIGHT_POSITION",
    "SCENES",
    "SPHERE",
    "VIEWS",
    "Scene",
    "constant_material",
    "highlight_point",
    "spectral_phong_unit_peak",
    "view_camera",
]

#: The sphere of every scene.
SPHERE = Sphere((0.0, 0.0, 0.0), 1.0)
#: The camera position of both views.
EYE = (0.0, 0.0, 4.5)
#: The point light of every scene.
LIGHT_POSITION = (2.5, 3.0, 4.0)
#: ``(c1, c2, c3)`` of Eq. (1), Wang et al.: f_att ranges over about 0.64-1 on the sphere.
LIGHT_ATTENUATION = (0.25, 0.1, 0.01)
#: Vertical field of view of the views, degrees.
VIEWS = {"far": 30.0, "near": 5.0}


def spectral_phong_unit_peak(
    k_d,
    k_s,
    n,
    illuminant: str = "D65",
    name: str = "material",
    grid: SpectralGrid = DEFAULT_GRID,
    position=LIGHT_POSITION,
    attenuation=LIGHT_ATTENUATION,
) -> SpectralPhong:
    """A :class:`SpectralPhong` whose light intensity makes the brightest value display white.

    Eq. (7) and Eq. (11), Wang et al.: the intensity is ``1 / max_c (D_c + f_sp,c(1))`` at unit
    intensity (``cos θ = 1``, ``t = 1``, ``f_att = 1``), so the rendered image is not clipped by
    the display except where the colour is outside the gamut.

    Parameters
    ----------
    k_d, k_s, n : array_like, shape (n_bands,)
        The material on ``grid``.
    illuminant : str
        A colour-science illuminant key for ``I_p(λ)``.
    name : str
        The material's name.
    grid : SpectralGrid
        Grid of the arrays.
    position, attenuation : tuple
        The point light.

    Returns
    -------
    SpectralPhong

    Examples
    --------
    >>> model = spectral_phong_unit_peak(np.full(41, 0.2), np.full(41, 0.5), np.full(41, 50.0))
    >>> float((model.diffuse_RGB + model.specular(1.0)).max()).__round__(12)
    1.0
    """
    material = PhongMaterial(k_d, k_s, n, name=name)
    spectrum = spectrum_from_dataset("illuminant", illuminant)
    unit = SpectralPhong(material, PointLight(position, spectrum, 1.0, attenuation), grid=grid)
    peak = float((unit.diffuse_RGB + unit.specular(1.0)).max())
    intensity = 1.0 / peak if peak > 0 else 1.0
    light = PointLight(position, spectrum, intensity, attenuation)
    return SpectralPhong(material, light, grid=grid)


def constant_material(n: float, k_d: float = 0.2, k_s: float = 0.5, illuminant: str = "D65"):
    """A flat-spectrum material with one exponent (for closed-form checks and the docs).

    Examples
    --------
    >>> constant_material(10.0).an
    10.0
    """
    bands = DEFAULT_GRID.n_bands
    return spectral_phong_unit_peak(
        np.full(bands, k_d), np.full(bands, k_s), np.full(bands, n), illuminant, f"n{n:g}"
    )


def _logistic(x):
    return 1.0 / (1.0 + np.exp(-x))


def _R1() -> SpectralPhong:
    wl = DEFAULT_GRID.wavelengths_nm
    k_d = 0.15 + 0.55 * _logistic((wl - 600.0) / 25.0)
    k_s = 0.35 + 0.15 * (wl - 380.0) / 400.0
    n = 50.0 + 30.0 * (wl - 580.0) / 200.0
    return spectral_phong_unit_peak(k_d, k_s, n, "D65", "R1")


def _R2() -> SpectralPhong:
    wl = DEFAULT_GRID.wavelengths_nm
    k_d = 0.1 + 0.4 * np.exp(-(((wl - 460.0) / 60.0) ** 2))
    k_s = np.full(wl.size, 0.4)
    n = 10.0 * 100.0 ** ((wl - 380.0) / 400.0)
    return spectral_phong_unit_peak(k_d, k_s, n, "A", "R2")


def _R3() -> SpectralPhong:
    wl = DEFAULT_GRID.wavelengths_nm
    k_d = 0.2 + 0.2 * _logistic((wl - 600.0) / 20.0)
    k_s = 0.05 + 0.6 * np.exp(-(((wl - 530.0) / 15.0) ** 2))
    n = 2000.0 + 1000.0 * np.exp(-(((wl - 530.0) / 40.0) ** 2))
    return spectral_phong_unit_peak(k_d, k_s, n, "FL11", "R3")


def _bimodal() -> SpectralPhong:
    wl = DEFAULT_GRID.wavelengths_nm
    n = np.where(wl < 580.0, 5.0, 500.0)
    flat = np.ones(wl.size)
    return spectral_phong_unit_peak(0.2 * flat, 0.5 * flat, n, "D65", "bimodal")


def _n2000() -> SpectralPhong:
    model = constant_material(2000.0)
    return spectral_phong_unit_peak(
        model.material.k_d, model.material.k_s, model.material.n, "D65", "n2000"
    )


@dataclass(frozen=True)
class Scene:
    """A registered scene: its key, a builder of its :class:`SpectralPhong`, and a description."""

    name: str
    build: Callable[[], SpectralPhong]
    description: str
    table1: bool = True


#: Scenes by key: the Table 1 reconstructions R1-R3 and the failure cases.
SCENES = Registry("Phong scene", Scene)
SCENES.register(Scene("R1", _R1, "reconstruction: smooth spectra, n = 20-80, D65"))
SCENES.register(Scene("R2", _R2, "reconstruction: n = 10-1000 across wavelengths, illuminant A"))
SCENES.register(Scene("R3", _R3, "reconstruction: narrow-band k_s at 530 nm, n = 2000-3000, FL11"))
SCENES.register(Scene("bimodal", _bimodal, "failure case: n = 5 below 580 nm, 500 above", False))
SCENES.register(Scene("n2000", _n2000, "failure case: n = 2000 in every band", False))


def highlight_point(light_position=LIGHT_POSITION, eye=EYE, sphere: Sphere = SPHERE) -> np.ndarray:
    """The point of the sphere where ``R·V = 1`` (the centre of the highlight).

    There the normal bisects the directions to the light and to the eye; the fixed point is found
    by iterating ``N ← normalise(L(p) + V(p))``, ``p = c + r N``.

    Examples
    --------
    >>> highlight_point((0.0, 0.0, 5.0), (0.0, 0.0, 3.0)).round(6)
    array([0., 0., 1.])
    """
    c = np.asarray(sphere.center)
    light = np.asarray(light_position, dtype=np.float64)
    eye = np.asarray(eye, dtype=np.float64)
    N = (light - c) / np.linalg.norm(light - c) + (eye - c) / np.linalg.norm(eye - c)
    N /= np.linalg.norm(N)
    for _ in range(100):
        p = c + sphere.radius * N
        L = (light - p) / np.linalg.norm(light - p)
        V = (eye - p) / np.linalg.norm(eye - p)
        N_new = (L + V) / np.linalg.norm(L + V)
        if np.abs(N_new - N).max() < 1e-15:
            break
        N = N_new
    return c + sphere.radius * N


def view_camera(view: str) -> Camera:
    """The camera of a view: ``"far"`` (whole sphere) or ``"near"`` (zoomed on the highlight).

    Examples
    --------
    >>> view_camera("near").fov_deg
    5.0
    >>> view_camera("side")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown view 'side'; allowed: far, near
    """
    require(view in VIEWS, f"unknown view {view!r}; allowed: {', '.join(sorted(VIEWS))}")
    target = (0.0, 0.0, 0.0) if view == "far" else tuple(highlight_point())
    return Camera(eye=EYE, target=target, fov_deg=VIEWS[view])
