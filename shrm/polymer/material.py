"""The ``polymer`` material of scene files: Herbert et al.'s hybrid model under environment light.

Eqs. (1)-(5), Herbert et al.

Importing ``shrm`` registers the scene-file material type ``polymer`` (:class:`PolymerMaterial`) and
its shader for environment lights, ``PolymerMaterial/EnvironmentLight``, which evaluates
:func:`shrm.polymer.hybrid.polymer_terms` per pixel from maps that are prefiltered once per
environment and kept in the environment shaders' cache (``shrm.environment``): the Lambert map (E_d
and the diffuse part of E_trans) is the very map a ``lambert`` material uses, and the normalized
Phong map (E_s) is made once per gloss exponent, so two materials with the same exponent share it.
The effect pigment's SHRM (§5.5, Herbert et al.) is made once per BRDF and environment and cached
likewise; its reflection map is extracted for the mean view (the distant viewer of ``shrm.orbit``).

Every colour is a spectrum on the scene's grid until the shader's last line, where
``ctx.weights(None)`` turns radiance spectra into XYZ. The chip comes from the Kubelka-Munk model on
the scene's grid (``shrm.polymer.characterization.characterize_model``), or from a characterization
file whose spectra are interpolated linearly onto the grid; the chip between grid points is looked
up once per frame (PCHIP, erratum E37).

Scene keys (docs/scene-format.md): ``thickness`` (mm), ``tio2`` (% by weight), ``characterization``
(file), ``tint`` (a spot-colour name of ``shrm.polymer.tint`` or a spectrum), ``gloss`` (the factor
of Eq. (5), Herbert et al.), ``gloss_exponent`` (the Phong exponent of E_s, E32), ``index`` (> 1),
``transparency`` (the unscattered fraction of E33, erratum E60), ``mirror`` (a key of
``shrm.polymer.hybrid.MIRROR_FACTORS``), ``effect`` (an analytic isotropic BRDF, a key or a table)
and ``modulation`` (Mod_effect: a number or a greyscale image looked up by uv).

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.colour.spectra import SpectralGrid
from reference.errors import SpecrefError, require, require_nonnegative
from reference.materials.fresnel import MAX_REFRACTIVE_INDEX
from reference.materials.types import MATERIAL_TYPES, MaterialType
from reference.registry import Method, Registry
from reference.scene.lights import EnvironmentLight
from reference.scene.options import check_fraction, register_render_option
from reference.scene.shading import SHADERS, Surface
from shrm.orbit import IsotropicBRDFMaterial, _parse_isotropic_brdf
from shrm.polymer.characterization import (
    Characterization,
    characterize_model,
    read_characterization,
)
from shrm.polymer.hybrid import (
    MIRROR_FACTORS,
    PolymerLook,
    PolymerMaps,
    polymer_look,
    polymer_terms,
)

__all__ = [
    "POLYMER_DEFAULTS",
    "POLYMER_KERNELS",
    "POLYMER_MODELS",
    "PolymerMaterial",
    "chip_lookup",
    "lambert_phong_shade_parts",
    "modulation_at",
    "polymer_characterization",
    "polymer_environment_maps",
    "polymer_material_look",
    "polymer_pixel_parts",
    "polymer_shade_parts",
    "shade_polymer_environment",
    "shade_polymer_oracle",
]

#: Defaults of the scene keys: a 0.06" (1.524 mm) chip with 0.5 % TiO2, untinted, fully glossy.
POLYMER_DEFAULTS = {
    "thickness": 1.524,
    "tio2": 0.5,
    "tint": 1.0,
    "gloss": 1.0,
    "gloss_exponent": 64.0,
    "transparency": 0.0,
    "mirror": "fresnel",
    "modulation": 0.0,
    "model": "herbert",
}
#: The real-time models of ``type = "polymer"``: Herbert et al.'s hybrid (``shrm.polymer.hybrid``)
#: and the layered model from prefiltered maps (``shrm.polymer.layered``, erratum E108).
POLYMER_MODELS = ("herbert", "layered")
#: Keys of the hybrid alone: the layered model refuses them (its slab is the constituents' KM;
#: its transparency follows from the slab). It reads ``tint`` as a dye (erratum E115).
_HERBERT_ONLY = ("characterization", "gloss_exponent", "transparency", "mirror", "effect",
                 "modulation")  # fmt: skip


@dataclass(frozen=True, eq=False)
class PolymerMaterial:
    """A scene material of Herbert et al.'s hybrid polymer model (``type = "polymer"``).

    Eqs. (1)-(5), Herbert et al.

    Attributes
    ----------
    thickness_mm, tio2_pct : float
        The chip, inside the characterization's grid.
    tint : ndarray, shape (n_bands,)
        Tint_polymer on the scene's grid, in [0, 1].
    gloss : float
        Factor of Eq. (5), Herbert et al., in [0, 1].
    gloss_exponent : float
        Exponent of the normalized Phong lobe of E_s, >= 0 (E32).
    index : float or None
        Refractive index (> 1); None is the characterization's.
    transparency : float
        Unscattered fraction of the transmittance (E33, E60), in [0, 1].
    mirror : str
        Key of ``shrm.polymer.hybrid.MIRROR_FACTORS``.
    characterization : str or None
        A characterization file; None is the Kubelka-Munk model.
    effect : IsotropicBRDFMaterial or None
        The effect pigment's BRDF (Eq. (3), Herbert et al.).
    modulation : float or ndarray, shape (H, W)
        Mod_effect, in [0, 1]: a constant or a greyscale image (row 0 at v = 0).
    model : str
        One of :data:`POLYMER_MODELS`: ``"herbert"`` (the hybrid) or ``"layered"`` (the layered
        model from prefiltered maps, which reads the thickness, TiO2, tint (as a dye in the slab,
        erratum E115), gloss and index).
    name : str
    """

    thickness_mm: float = 1.524
    tio2_pct: float = 0.5
    tint: np.ndarray | float = 1.0
    gloss: float = 1.0
    gloss_exponent: float = 64.0
    index: float | None = None
    transparency: float = 0.0
    mirror: str = "fresnel"
    characterization: str | None = None
    effect: IsotropicBRDFMaterial | None = None
    modulation: float | np.ndarray = 0.0
    model: str = "herbert"
    name: str = "polymer"


@functools.lru_cache(maxsize=8)
def _model_on_grid(grid: SpectralGrid) -> Characterization:
    return characterize_model(grid=grid)


@functools.lru_cache(maxsize=8)
def _file_on_grid(path: str, mtime_ns: int, grid: SpectralGrid) -> Characterization:
    ch = read_characterization(path)
    wl = grid.wavelengths_nm

    def resample(table):
        # Linear in wavelength, constant beyond the file's range
        flat = table.reshape(-1, table.shape[-1])
        out = np.stack([np.interp(wl, ch.wavelengths_nm, row) for row in flat])
        return out.reshape(*table.shape[:-1], wl.size)

    return dataclasses.replace(
        ch,
        wavelengths_nm=wl,
        over_black=resample(ch.over_black),
        over_white=resample(ch.over_white),
        transmittance=resample(ch.transmittance),
    )


#: Interpolators per characterization, by id (the object is kept, so the id stays its own).
_INTERPOLATORS: dict = {}


def _stacked_interpolator(ch: Characterization):
    from scipy.interpolate import RegularGridInterpolator

    from shrm.polymer.characterization import MEASUREMENTS

    if id(ch) not in _INTERPOLATORS:
        if len(_INTERPOLATORS) >= 16:
            _INTERPOLATORS.clear()
        axes = (np.log(ch.thickness_mm), ch.tio2_pct)
        method = "pchip" if min(len(a) for a in axes) >= 4 else "linear"
        table = np.concatenate([getattr(ch, name) for name in MEASUREMENTS], axis=-1)
        _INTERPOLATORS[id(ch)] = (ch, RegularGridInterpolator(axes, table, method=method))
    return _INTERPOLATORS[id(ch)][1]


def chip_lookup(ch: Characterization, thickness_mm: float, tio2_pct: float) -> dict:
    """``ch.lookup`` for one chip, with the three tables interpolated in one call (per frame).

    The same interpolation as :meth:`shrm.polymer.characterization.Characterization.lookup` (PCHIP
    in log thickness and TiO2, E37), on the three measurements stacked, with the interpolator kept
    per characterization.

    Examples
    --------
    >>> from reference.colour.spectra import SpectralGrid
    >>> ch = polymer_characterization(None, SpectralGrid(400.0, 700.0, 20.0))
    >>> a, b = chip_lookup(ch, 0.9, 0.3), ch.lookup(0.9, 0.3)
    >>> all(np.allclose(a[k], b[k], rtol=1e-12, atol=1e-15) for k in b)
    True
    """
    from shrm.polymer.characterization import MEASUREMENTS

    for name, value, axis in (
        ("thickness_mm", thickness_mm, ch.thickness_mm),
        ("tio2_pct", tio2_pct, ch.tio2_pct),
    ):
        require(
            bool(axis[0] <= value <= axis[-1]),
            f"characterization: {name}: must be in [{axis[0]:g}, {axis[-1]:g}] (the grid), "
            f"got {value!r}",
        )
    values = _stacked_interpolator(ch)([[np.log(thickness_mm), tio2_pct]])[0]
    nb = ch.wavelengths_nm.size
    return {
        name: np.clip(values[i * nb : (i + 1) * nb], 0.0, 1.0)
        for i, name in enumerate(MEASUREMENTS)
    }


def polymer_characterization(path, grid: SpectralGrid) -> Characterization:
    """The chip matrix of a polymer material on the scene's grid (cached).

    Parameters
    ----------
    path : str, Path or None
        A characterization file (``shrm.polymer.characterization``); None is the Kubelka-Munk model.
    grid : SpectralGrid
        The scene's grid; a file's spectra are interpolated linearly onto it.

    Returns
    -------
    Characterization

    Examples
    --------
    >>> from reference.colour.spectra import SpectralGrid
    >>> polymer_characterization(None, SpectralGrid(400.0, 700.0, 20.0)).over_black.shape
    (7, 11, 16)
    """
    if path is None:
        return _model_on_grid(grid)
    p = Path(path)
    return _file_on_grid(str(p), p.stat().st_mtime_ns, grid)


def polymer_material_look(material: PolymerMaterial, grid: SpectralGrid) -> PolymerLook:
    """The per-frame look of a polymer material (Eqs. (1)-(5), Herbert et al.) on ``grid``.

    Parameters
    ----------
    material : PolymerMaterial
    grid : SpectralGrid

    Returns
    -------
    shrm.polymer.hybrid.PolymerLook

    Examples
    --------
    >>> from reference.colour.spectra import SpectralGrid
    >>> look = polymer_material_look(PolymerMaterial(tint=0.5), SpectralGrid(400.0, 700.0, 20.0))
    >>> look.D_polymer.shape, float(look.Tint_polymer[0])
    ((16,), 0.5)
    """
    ch = polymer_characterization(material.characterization, grid)
    return polymer_look(
        ch,
        material.thickness_mm,
        material.tio2_pct,
        tint=material.tint,
        gloss=material.gloss,
        mirror=material.mirror,
        unscattered=material.transparency,
        index=material.index,
    )


def modulation_at(modulation, uv) -> np.ndarray:
    """Mod_effect at texture coordinates: a constant, or a bilinear lookup in a greyscale image.

    Eq. (3), Herbert et al. (the modulation map). ``u`` runs along columns, ``v`` along rows
    (``v = 0`` the top row), both wrapped to [0, 1); texel centres sit at ``(i + 0.5) / W``.

    Parameters
    ----------
    modulation : float or ndarray, shape (H, W)
        Values in [0, 1].
    uv : ndarray, shape (N, 2)

    Returns
    -------
    ndarray, shape (N,)

    Examples
    --------
    >>> image = np.array([[0.0, 1.0]])
    >>> modulation_at(image, np.array([[0.25, 0.5], [0.5, 0.5], [0.75, 0.5]]))
    array([0. , 0.5, 1. ])
    """
    uv = np.asarray(uv, dtype=np.float64)
    if np.ndim(modulation) == 0:
        return np.full(uv.shape[0], float(modulation))
    image = np.asarray(modulation, dtype=np.float64)
    H, W = image.shape
    x = np.clip(np.mod(uv[:, 0], 1.0) * W - 0.5, 0.0, W - 1.0)
    y = np.clip(np.mod(uv[:, 1], 1.0) * H - 0.5, 0.0, H - 1.0)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, W - 1), np.minimum(y0 + 1, H - 1)
    fx, fy = x - x0, y - y0
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def polymer_environment_maps(light: EnvironmentLight, ctx, gloss_exponent: float) -> PolymerMaps:
    """The maps of Eqs. (2), (4) and (5), Herbert et al., from the environment shaders' cache.

    The Lambert map is the one ``lambert`` materials use; the normalized Phong map is made once
    per exponent and cube size. Both live as long as the light (``shrm.environment``).

    Parameters
    ----------
    light : EnvironmentLight
    ctx : reference.scene.shading.ShadingContext
        Its grid, ``options["environment_size"]`` (cube face, default 64),
        ``options["environment_tol"]`` and ``options["upsampling"]``.
    gloss_exponent : float

    Returns
    -------
    shrm.polymer.hybrid.PolymerMaps

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0), options={"environment_size": 4})
    >>> sky = EnvironmentLight(np.ones((16, 32, 3)))
    >>> maps = polymer_environment_maps(sky, ctx, 8.0)
    >>> maps.specular.shape, polymer_environment_maps(sky, ctx, 8.0).specular is maps.specular
    ((6, 4, 4, 16), True)
    """
    from shrm.environment import _frequency_map, _order, _state
    from shrm.lobes import parse_kernel

    lambert = parse_kernel("lambert")
    L = _order(light, ctx, lambert)
    E = _frequency_map(light, ctx, "lambert", L, lambert.Lambda(L))
    s = float(gloss_exponent)
    phong = parse_kernel(f"phong:{s:g}")
    L_s = _order(light, ctx, phong)
    # The normalized Phong lobe of E_s (shrm.polymer.hybrid.polymer_maps), unlike the Phong
    # material's
    E_s = _frequency_map(light, ctx, f"normalized-phong:{s:g}", L_s, phong.Lambda(L_s))
    return PolymerMaps(E, E_s, _state(light, ctx)["radiance"], s)


def polymer_pixel_parts(normal, view, maps: PolymerMaps, fresnel, mirror="fresnel", E_effect=None):
    """The per-pixel parts of Eq. (1), Herbert et al. that depend on angles and maps only.

    §5.1, Herbert et al.: "the look-up frequency is per-pixel if the variable is an angle, and
    per-frame otherwise". These parts change with the viewpoint, the maps (environment, gloss
    exponent) and the Fresnel table (index), never with the dynamic parameters (thickness, TiO2,
    tint, transparency, gloss factor, Mod_effect), which :func:`polymer_shade_parts` applies per
    frame. Together they give :func:`shrm.polymer.hybrid.polymer_terms`'s ``I_result``.

    Parameters
    ----------
    normal, view : ndarray, shape (N, 3)
        Unit normals and unit vectors towards the eye.
    maps : shrm.polymer.hybrid.PolymerMaps
    fresnel : reference.materials.fresnel.FresnelLUT
    mirror : str
        Key of ``shrm.polymer.hybrid.MIRROR_FACTORS``.
    E_effect : ndarray, shape (N, n_bands), optional
        The effect pigment's radiance; None is zero.

    Returns
    -------
    dict of str to ndarray, shape (N, n_bands)
        ``E_d`` (E(N)/π), ``E_s`` (the Phong map at the reflection direction; read by
        :func:`lambert_phong_shade_parts`), ``S`` (``I_s F_r / gloss``), ``B`` (``E(−N)/π
        (1 − F_r)``), ``L`` (``L(−V) (1 − F_r)``), ``E_effect``.

    Examples
    --------
    >>> from reference.materials.fresnel import fresnel_lut
    >>> from shrm.polymer.hybrid import polymer_maps
    >>> maps = polymer_maps(np.ones((16, 32, 2)), 8.0, size=4)
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> parts = polymer_pixel_parts(up, up, maps, fresnel_lut(1.5))
    >>> print(parts["S"].round(3), parts["B"].round(3))
    [[0.04 0.04]] [[0.96 0.96]]
    """
    from reference.geometry.cubemap import cubemap_lookup_bilinear
    from reference.geometry.envmap import latlong_lookup_bilinear

    N = np.asarray(normal, dtype=np.float64)
    V = np.asarray(view, dtype=np.float64)
    cos_theta = np.clip(np.einsum("ij,ij->i", N, V), 0.0, 1.0)
    # Eq. (1), Herbert et al.: F_r from the cos θ LUT, per pixel
    F_r = fresnel.lookup(cos_theta)
    F_r = F_r[:, None] if F_r.ndim == 1 else F_r
    F_0 = fresnel.lookup(1.0)
    # Eq. (2), Herbert et al.: E_d = E(N)/π
    E_d = cubemap_lookup_bilinear(maps.irradiance, N, backend="numba") / np.pi
    # Eq. (5), Herbert et al.: I_s / gloss = E_s M_s + E_mirror (1 − M_s), at r = 2 (N·V) N − V
    r = 2.0 * cos_theta[:, None] * N - V
    E_s = cubemap_lookup_bilinear(maps.specular, r, backend="numba")
    E_mirror = latlong_lookup_bilinear(maps.radiance, r)
    M_s = MIRROR_FACTORS.lookup(mirror).reference(cos_theta, F_r, F_0)
    S = (E_s * M_s + E_mirror * (1.0 - M_s)) * F_r
    # Eq. (4), Herbert et al.: the two parts of E_trans (E33), times the transmitted 1 − F_r
    B = cubemap_lookup_bilinear(maps.irradiance, -N, backend="numba") / np.pi * (1.0 - F_r)
    L = latlong_lookup_bilinear(maps.radiance, -V) * (1.0 - F_r)
    effect = np.zeros_like(E_d) if E_effect is None else np.asarray(E_effect, dtype=np.float64)
    return {"E_d": E_d, "E_s": E_s, "S": S, "B": B, "L": L, "E_effect": effect}


def polymer_shade_parts(
    parts: dict, look: PolymerLook, Mod_effect=0.0, compiled: bool = False
) -> np.ndarray:
    """Eq. (1), Herbert et al. from the per-pixel parts and the per-frame look: (N, n_bands).

    ``I_result = E_d D Tint (1 − Mod) + E_effect Mod + gloss S + Col_trans ((1 − u) B + u L)``
    with the parts of :func:`polymer_pixel_parts`; a few multiply-adds per pixel and band.

    Parameters
    ----------
    parts : dict
        From :func:`polymer_pixel_parts`.
    look : shrm.polymer.hybrid.PolymerLook
        Its ``fresnel`` and ``mirror`` are not read (they are in the parts).
    Mod_effect : float or ndarray, shape (N,)
        In [0, 1].
    compiled : bool
        Shade with the numba twin ``shrm.polymer._kernels.polymer_shade_parts_kernel`` (one pass
        over the pixels; the session's frame).

    Returns
    -------
    ndarray, shape (N, n_bands)

    Examples
    --------
    >>> from shrm.polymer.characterization import characterize_model
    >>> from shrm.polymer.hybrid import polymer_look, polymer_maps, polymer_terms
    >>> look = polymer_look(characterize_model(), 1.0, 0.3, unscattered=0.2)
    >>> maps = polymer_maps(np.ones((16, 32, 41)), 8.0, size=4)
    >>> n, v = np.array([[0.0, 1.0, 0.0]]), np.array([[0.6, 0.8, 0.0]])
    >>> I = polymer_shade_parts(polymer_pixel_parts(n, v, maps, look.fresnel), look)
    >>> bool(np.allclose(I, polymer_terms(n, v, look, maps)["I_result"], rtol=1e-12))
    True
    """
    Mod = np.asarray(Mod_effect, dtype=np.float64)
    require(
        bool(np.all((Mod >= 0) & (Mod <= 1))), "polymer: Mod_effect: must be in [0, 1], not NaN"
    )
    u = look.unscattered
    if compiled:
        return _shade_parts_compiled(parts, look, Mod)
    # Eq. (2), Herbert et al.: E_d D_polymer Tint_polymer (1 − Mod_effect)
    if Mod.ndim == 0:
        out = parts["E_d"] * (look.D_polymer * look.Tint_polymer * (1.0 - float(Mod)))
    else:
        out = parts["E_d"] * (look.D_polymer * look.Tint_polymer) * (1.0 - Mod[:, None])
    scratch = np.empty_like(out)
    # Eq. (1), Herbert et al.: + I_s F_r + I_trans (1 − F_r), I_s = gloss (E_s M_s + ...)
    out += np.multiply(parts["S"], look.gloss, out=scratch)
    out += np.multiply(parts["B"], look.Col_trans * (1.0 - u), out=scratch)
    if np.any(u > 0):
        out += np.multiply(parts["L"], look.Col_trans * u, out=scratch)
    # Eq. (3), Herbert et al.: + E_effect Mod_effect
    if np.any(Mod > 0):
        out += parts["E_effect"] * (Mod if Mod.ndim == 0 else Mod[:, None])
    return out


def _shade_parts_compiled(parts: dict, look: PolymerLook, Mod: np.ndarray) -> np.ndarray:
    """:func:`polymer_shade_parts` through its numba twin (``Mod`` validated)."""
    from shrm.polymer._kernels import polymer_shade_parts_kernel

    E_d = parts["E_d"]
    u = np.asarray(look.unscattered, dtype=np.float64)
    unused = np.zeros((0, E_d.shape[1]))
    L = parts["L"] if np.any(u > 0) else unused
    E_effect = parts["E_effect"] if np.any(Mod > 0) else unused
    return polymer_shade_parts_kernel(
        *(np.ascontiguousarray(a, dtype=np.float64) for a in (E_d, parts["S"], parts["B"], L)),
        np.ascontiguousarray(E_effect, dtype=np.float64),
        np.asarray(look.D_polymer * look.Tint_polymer, dtype=np.float64),
        np.asarray(look.Col_trans * (1.0 - u), dtype=np.float64),
        np.asarray(look.Col_trans * u, dtype=np.float64),
        float(look.gloss),
        np.ascontiguousarray(np.atleast_1d(Mod), dtype=np.float64),
        np.empty(E_d.shape),
    )


def lambert_phong_shade_parts(parts: dict, k_d, k_s, compiled: bool = False) -> np.ndarray:
    """A Lambert plus Phong material from the same per-pixel parts: ``k_d E_d + k_s E_s``, (N, C).

    The cheapest shading a renderer would re-run after a material change through the polymer's
    cached maps (§5.2, Herbert et al.: "a weighted sum of the maps"): the diffuse reflectance
    times the irradiance ``E(N)/π`` and the specular one times the prefiltered normalized-Phong map
    at the reflection direction. The polymer re-shade benchmark's baseline (erratum E61).

    Parameters
    ----------
    parts : dict
        From :func:`polymer_pixel_parts` (``E_d`` and ``E_s`` are read).
    k_d, k_s : float or ndarray, shape (C,)
        Diffuse and specular reflectance per band, >= 0.
    compiled : bool
        Through the numba twin ``shrm.polymer._kernels.lambert_phong_shade_parts_kernel``.

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    >>> parts = {"E_d": np.full((1, 2), 2.0), "E_s": np.full((1, 2), 10.0)}
    >>> lambert_phong_shade_parts(parts, 0.5, [0.0, 0.1])
    array([[1., 2.]])
    """
    E_d, E_s = parts["E_d"], parts["E_s"]
    C = E_d.shape[1]
    k_d = np.broadcast_to(require_nonnegative(k_d, "lambert_phong: k_d"), (C,))
    k_s = np.broadcast_to(require_nonnegative(k_s, "lambert_phong: k_s"), (C,))
    if compiled:
        from shrm.polymer._kernels import lambert_phong_shade_parts_kernel

        return lambert_phong_shade_parts_kernel(
            *(np.ascontiguousarray(a, dtype=np.float64) for a in (E_d, E_s, k_d, k_s)),
            np.empty(E_d.shape),
        )
    # §5.2, Herbert et al.: the material's reflectances times the maps, k_d E(N)/π + k_s E_s(r)
    return E_d * k_d + E_s * k_s


def _lambert_phong_example(rng):
    parts = {k: rng.uniform(0, 2, (7, 41)) for k in ("E_d", "E_s")}
    return parts, rng.uniform(0, 1, 41), rng.uniform(0, 1, 41)


def _shade_parts_example(rng):
    from shrm.polymer.characterization import characterize_model
    from shrm.polymer.hybrid import polymer_look

    N, n_bands = 7, 41
    parts = {k: rng.uniform(0, 2, (N, n_bands)) for k in ("E_d", "S", "B", "L", "E_effect")}
    look = polymer_look(characterize_model(), 1.2, 0.4, unscattered=0.3)
    return parts, look, rng.uniform(0, 1, N)


#: The per-frame shading of the polymer pixels and its numba twin (tests check the pair).
POLYMER_KERNELS = Registry("polymer shading kernel")


def _register_kernels():
    from shrm.polymer._kernels import lambert_phong_shade_parts_kernel, polymer_shade_parts_kernel

    POLYMER_KERNELS.register(
        Method(
            "shade_parts",
            polymer_shade_parts,
            polymer_shade_parts_kernel,
            "Eq. (1), Herbert et al.",
            _shade_parts_example,
            compiled=functools.partial(polymer_shade_parts, compiled=True),
        )
    )
    POLYMER_KERNELS.register(
        Method(
            "lambert_phong",
            lambert_phong_shade_parts,
            lambert_phong_shade_parts_kernel,
            "§5.2, Herbert et al.",
            _lambert_phong_example,
            compiled=functools.partial(lambert_phong_shade_parts, compiled=True),
        )
    )


_register_kernels()


#: SHRM settings of the effect pigment's term (a small preview: the pigment is a mixed-in term,
#: erratum E60): working environment rows, F, P, cube face and frame.
EFFECT_SHRM_SETTINGS = {"env_height": 32, "F": 12, "P": 8, "size": 16, "frame": "normal"}


def _effect_radiance(surface: Surface, effect: IsotropicBRDFMaterial, light, ctx) -> np.ndarray:
    """E_effect of Eq. (3), Herbert et al.: the effect pigment through its (cached) SHRM."""
    from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    from shrm.cache import hash_inputs
    from shrm.environment import _state
    from shrm.orbit import _working_environment
    from shrm.shrm import shade_shrm, shrm_create, shrm_extract
    from shrm.transform import project_latlong

    c = EFFECT_SHRM_SETTINGS
    state = _state(light, ctx)
    key = ("polymer-effect", effect.brdf, hash_inputs({"p": effect.params}))
    if key not in state:
        from shrm.environment import environment_spectral_radiance

        work = _working_environment(light, c["env_height"])
        radiance = environment_spectral_radiance(work, ctx.grid)
        F = min(c["F"], radiance.shape[1] // 2 - 1)
        L = project_latlong(radiance, F, backend="ducc0", where=light.name)
        brdf, expand, lam, k = shrm_brdf_parts(effect.brdf, effect.params)
        rho = brdf_sh_coefficients(brdf, expand, F, c["P"], c["frame"], view_power=k)
        # §5.5, Herbert et al.: one SHRM per BRDF and environment
        state[key] = shrm_create(L, rho, c["frame"], c["size"], "ducc0", k, lam)
    s = state[key]
    v = surface.view.mean(axis=0)
    v = v / np.linalg.norm(v)
    # §5.6, Herbert et al.: extract for the viewpoint, then shade per point
    return shade_shrm(s, shrm_extract(s, v), surface.normal, v)


def shade_polymer_environment(
    surface: Surface, material: PolymerMaterial, light: EnvironmentLight, ctx
) -> np.ndarray:
    """XYZ of a polymer material under an environment: Eq. (1), Herbert et al., per pixel.

    The terms come from :func:`shrm.polymer.hybrid.polymer_terms` with the cached maps
    (:func:`polymer_environment_maps`) and the per-frame look (:func:`polymer_material_look`).
    With ``ctx.options["environment"] == "bruteforce"`` (``specref render --oracle``) both models
    are shaded by the physics they approximate, the layered oracle (:func:`shade_polymer_oracle`,
    erratum E60).

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0), options={"environment_size": 8})
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> XYZ = shade_polymer_environment(Surface(n * 0, n, n, np.zeros((1, 2))), PolymerMaterial(),
    ...                                 EnvironmentLight(np.ones((16, 32, 3))), ctx)
    >>> XYZ.shape, bool(0.5 < XYZ[0, 1] < 1.0)
    ((1, 3), True)
    """
    if surface.normal.shape[0] == 0:
        return np.zeros((0, ctx.n_outputs))
    if ctx.options.get("environment") == "bruteforce":
        return shade_polymer_oracle(surface, material, light, ctx)
    if material.model == "layered":
        return _shade_layered(surface, material, light, ctx) @ ctx.weights(None)
    maps = polymer_environment_maps(light, ctx, material.gloss_exponent)
    look = polymer_material_look(material, ctx.grid)
    Mod = modulation_at(material.modulation, surface.uv)
    E_effect = None
    if material.effect is not None:
        E_effect = _effect_radiance(surface, material.effect, light, ctx)
    terms = polymer_terms(surface.normal, surface.view, look, maps, Mod, E_effect)
    return terms["I_result"] @ ctx.weights(None)


def shade_polymer_oracle(
    surface: Surface, material: PolymerMaterial, light: EnvironmentLight, ctx
) -> np.ndarray:
    """XYZ of a polymer material by the layered oracle (``shrm.polymer.oracle.polymer_oracle``).

    The physical counterpart of Eq. (1), Herbert et al. (erratum E60): what both real-time
    models approximate: a dielectric interface (GGX-rough below gloss 1, E65) over a
    Kubelka–Munk slab of the constituents' K and S at the material's TiO2 load, its tint a dye
    (E115), its thickness and index, integrated over every pixel of the map (the specular lobe
    by seeded Monte Carlo to ``ctx.options["polymer_oracle_tol"]``, default 0.005 of the
    radiance). The hybrid's heuristics (``transparency``, ``mirror``, ``gloss_exponent``) have
    no physical counterpart and are not read; a characterization file or an effect pigment is
    refused in one line (the oracle knows neither). The samples used are recorded in
    ``ctx.records["polymer_oracle"]``.

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0))
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> XYZ = shade_polymer_oracle(Surface(n * 0, n, n, np.zeros((1, 2))), PolymerMaterial(),
    ...                            EnvironmentLight(np.ones((16, 32, 3))), ctx)
    >>> XYZ.shape, bool(0.5 < XYZ[0, 1] < 1.0)
    ((1, 3), True)
    """
    from shrm.environment import _state
    from shrm.polymer.kubelka_munk import km_tinted_K, polymer_constituents, polymer_K_S
    from shrm.polymer.oracle import gloss_alpha, interface_coupling, polymer_oracle

    require(
        material.characterization is None and material.effect is None,
        f"{material.name}: --oracle shades the Kubelka-Munk slab of the constituents; a "
        "characterization file or an effect pigment has no physical counterpart there",
    )
    constituents = polymer_constituents(ctx.grid)
    n = constituents.index if material.index is None else float(material.index)
    K, S = polymer_K_S(constituents, material.tio2_pct)
    K = km_tinted_K(K, S, material.tint, interface_coupling(n, gloss_alpha(material.gloss)).r_i)
    tol = ctx.options.get("polymer_oracle_tol", 0.005)
    require(
        isinstance(tol, (int, float)) and not isinstance(tol, bool) and 0 < tol < 1,
        f"options.polymer_oracle_tol: must be a number in (0, 1), got {tol!r}",
    )
    radiance = _state(light, ctx)["radiance"]
    out = polymer_oracle(surface.normal, surface.view, radiance, K, S, material.thickness_mm, n,
                         material.gloss, tol=float(tol), seed=0)  # fmt: skip
    before = ctx.records.get("polymer_oracle", {}).get(material.name, {})
    ctx.record("polymer_oracle", material.name, {
        "samples": max(out.samples, before.get("samples", 0)),
        "relative_error": max(out.relative_error, before.get("relative_error", 0.0)),
        "tol": float(tol),
    })  # fmt: skip
    return out.result @ ctx.weights(None)


def _shade_layered(surface: Surface, material: PolymerMaterial, light, ctx) -> np.ndarray:
    """Spectral radiance of the layered model (``shrm.polymer.layered``), maps cached per light."""
    from shrm.environment import _state
    from shrm.polymer.kubelka_munk import km_tinted_K, polymer_constituents, polymer_K_S
    from shrm.polymer.layered import FIS_TOL, layered_maps, layered_terms
    from shrm.polymer.oracle import interface_coupling

    constituents = polymer_constituents(ctx.grid)
    n = constituents.index if material.index is None else float(material.index)
    state = _state(light, ctx)
    tol = float(ctx.options.get("polymer_fis_tol", FIS_TOL))  # checked by the scene loader
    key = ("layered", n, float(material.gloss), tol)
    if key not in state:
        state[key] = layered_maps(state["radiance"], n, material.gloss, tol=tol)
    pilot = state[key].pilot
    if pilot is not None:  # K chosen from the tolerance (erratum E118), in the render's metadata
        ctx.record("polymer_layered", material.name, {
            "samples": pilot.samples, "fis_tol": pilot.tol,
            "pilot_change": pilot.change if np.isfinite(pilot.change) else None,
            "met": pilot.met,
        })  # fmt: skip
    K, S = polymer_K_S(constituents, material.tio2_pct)
    # erratum E115: the tint as a dye in the slab, through the front surface's r_i
    r_t = interface_coupling(state[key].n, state[key].alpha).r_i
    K = km_tinted_K(K, S, material.tint, r_t)
    terms = layered_terms(surface.normal, surface.view, state[key], K, S, material.thickness_mm)
    return terms["result"]


SHADERS.register(
    Method(
        "PolymerMaterial/EnvironmentLight",
        shade_polymer_environment,
        None,
        "Eq. (1), Herbert et al.",
    )
)


# --- the scene-file parser --------------------------------------------------------------------

_KEYS = (
    "type",
    "thickness",
    "tio2",
    "characterization",
    "tint",
    "gloss",
    "gloss_exponent",
    "index",
    "transparency",
    "mirror",
    "effect",
    "modulation",
    "model",
)


def _parse_tint(reader, value, key: str):
    if isinstance(value, str):
        from shrm.polymer.tint import read_tint_library

        with reader.context(key):
            library = read_tint_library()
            spectrum = library.tint(value)
        return np.interp(reader.grid.wavelengths_nm, library.wavelengths_nm, spectrum)
    tint = reader.spectrum_on_grid(value, key)
    if tint.max() > 1.0:
        reader.fail(key, f"must be in [0, 1], got a maximum of {tint.max():g}")
    return tint


def _parse_modulation(reader, value, key: str):
    if not isinstance(value, str):
        return reader.number(value, key, minimum=0.0, maximum=1.0)
    from reference.images.formats import read_image

    path = reader.file_path(value, key)
    with reader.context(key):
        image = read_image(path)
    grey = image[..., :3].mean(axis=-1) if image.ndim == 3 else image
    if not (np.all(np.isfinite(grey)) and grey.min() >= 0.0 and grey.max() <= 1.0):
        reader.fail(key, f"{path}: values must be in [0, 1]")
    return grey


def _parse_polymer(reader, table: dict, key: str, name: str) -> PolymerMaterial:
    """Scene-file parser of ``type = "polymer"`` (docs/scene-format.md)."""
    reader.table(table, key, _KEYS)
    d = POLYMER_DEFAULTS
    model = reader.choice(table.get("model", d["model"]), f"{key}.model", POLYMER_MODELS)
    if model == "layered":
        for k in _HERBERT_ONLY:
            if k in table:
                reader.fail(
                    f"{key}.{k}",
                    'belongs to Herbert\'s hybrid; the layered model (model = "layered") reads '
                    "thickness, tio2, tint, gloss and index",
                )
    path = None
    if "characterization" in table:
        path = str(reader.file_path(table["characterization"], f"{key}.characterization"))
    with reader.context(f"{key}.characterization"):
        ch = polymer_characterization(path, reader.grid)
    thickness = reader.number(
        table.get("thickness", d["thickness"]), f"{key}.thickness", 0.0, exclusive_minimum=True
    )
    tio2 = reader.number(table.get("tio2", d["tio2"]), f"{key}.tio2", 0.0)
    for k, value, axis, unit in (
        ("thickness", thickness, ch.thickness_mm, "mm"),
        ("tio2", tio2, ch.tio2_pct, "%"),
    ):
        if not axis[0] <= value <= axis[-1]:
            reader.fail(
                f"{key}.{k}",
                f"must be in [{axis[0]:g}, {axis[-1]:g}] {unit} (the characterization's grid), "
                f"got {value:g}",
            )
    index = None
    if "index" in table:
        value = table["index"]
        number = isinstance(value, int | float) and not isinstance(value, bool)
        if number and value > MAX_REFRACTIVE_INDEX:  # 1e11 was accepted
            reader.fail(
                f"{key}.index",
                f"a refractive index must be in (1, {MAX_REFRACTIVE_INDEX:g}] (polymers 1.3-1.7, "
                f"rutile 2.6-2.9), got {value:g}",
            )
        index = reader.number(value, f"{key}.index", 1.0, exclusive_minimum=True)
    effect = None
    if "effect" in table:
        value = table["effect"]
        if not isinstance(value, str | dict):
            reader.fail(
                f"{key}.effect",
                f'must be a BRDF key ("ggx") or a table {{ brdf = ... }}, got {value!r}',
            )
        effect_table = {"brdf": value} if isinstance(value, str) else value
        effect = _parse_isotropic_brdf(reader, effect_table, f"{key}.effect", f"{name}.effect")
    modulation = _parse_modulation(reader, table.get("modulation", 0.0), f"{key}.modulation")
    if effect is None and np.any(np.asarray(modulation) > 0):
        reader.fail(f"{key}.modulation", "mixes in an effect pigment; set 'effect' too")
    material = PolymerMaterial(
        thickness_mm=thickness,
        tio2_pct=tio2,
        tint=_parse_tint(reader, table.get("tint", d["tint"]), f"{key}.tint"),
        gloss=reader.number(table.get("gloss", d["gloss"]), f"{key}.gloss", 0.0, 1.0),
        gloss_exponent=reader.number(
            table.get("gloss_exponent", d["gloss_exponent"]), f"{key}.gloss_exponent", 0.0, 1e5
        ),
        index=index,
        transparency=reader.number(
            table.get("transparency", d["transparency"]), f"{key}.transparency", 0.0, 1.0
        ),
        mirror=reader.choice(table.get("mirror", d["mirror"]), f"{key}.mirror", MIRROR_FACTORS),
        characterization=path,
        effect=effect,
        modulation=modulation,
        model=model,
        name=name,
    )
    try:  # the whole look once at load time, so a bad combination is refused before rendering
        polymer_material_look(material, reader.grid)
    except SpecrefError as error:
        reader.fail(key, str(error))
    return material


MATERIAL_TYPES.register(
    MaterialType(
        "polymer",
        PolymerMaterial,
        (),
        _KEYS[1:],
        "Eq. (1), Herbert et al. (the hybrid polymer model)",
        parse=_parse_polymer,
    )
)

register_render_option(
    "polymer_oracle_tol",
    check_fraction,
    "the polymer oracle's Monte Carlo tolerance (default 0.005)",
)
register_render_option(
    "polymer_fis_tol",
    lambda value: check_fraction(value, 100.0),
    "the layered polymer model's tolerance, ΔL* of a black chip's specular between K/2 and K "
    "filtered importance samples (default 0.25, erratum E118)",
)
