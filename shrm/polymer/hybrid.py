"""Herbert et al.'s hybrid polymer shading model, spectrally, from prefiltered maps.

Eqs. (1)-(5), Herbert et al.

§5.1, Herbert et al. shades "a polymer-with-glossy-finish material" by the sum

    I_result = I_d + I_effect + I_s F_r + I_trans (1 − F_r)   Eq. (1), Herbert et al. (E5)
    I_d      = E_d D_polymer Tint_polymer (1 − Mod_effect)     Eq. (2), Herbert et al.
    I_effect = E_effect Mod_effect                             Eq. (3), Herbert et al.
    I_trans  = E_trans Col_trans                               Eq. (4), Herbert et al.
    I_s      = (E_s M_s + E_mirror (1 − M_s)) gloss            Eq. (5), Herbert et al.

(E5: the paper's ``I_r`` is read as ``I_s``.)

Every term here is a spectrum on the scene's grid, shape ``(N, n_bands)`` for N pixels, until the
display step. What specref chose where the paper is silent (errata E30–E35):

- ``E_d``: reflected radiance of a white Lambertian surface, ``E(N)/π`` with E the
  Lambert-prefiltered irradiance map looked up at the normal.
- ``E_s``: the normalized-Phong-prefiltered map (exponent ``phong_exponent``) at the reflected view
  vector ``r``; ``E_mirror``: the environment itself at ``r``, by direct bilinear lookup in the
  lat-long map (no window). ``gloss`` is the overall factor of Eq. (5), Herbert et al., in
  [0, 1]; the Phong exponent of ``E_s`` is a separate parameter (the paper uses one "gloss" for
  both: E32).
- ``M_s`` (:data:`MIRROR_FACTORS`): the paper's "heuristically-determined mirror reflection
  interpolation factor ... a function of the angle between eye and surface normal" is not given.
  specref's default ``"fresnel"`` reuses the Fresnel LUT: ``M_s = 1 − (F_r − F_0)/(1 − F_0)``, which
  is 1 at normal view (the blurred lobe) and falls to 0 at grazing (the mirror), with the shape of
  the Fresnel rise; ``"cosine"`` is ``M_s = cos θ``; ``"none"`` is ``M_s ≡ 1`` (no mirror term).
- ``D_polymer``: the chip's reflectance over black with the front-surface reflection ``k_1``
  removed (specular excluded), since ``F_r I_s`` adds the surface reflection (E31).
- ``E_trans``: light from behind the surface: the diffuse part ``E(−N)/π`` (the Lambert map at the
  back normal) and the unscattered part ``L(−V)`` along the view ray, mixed by the unscattered
  fraction ``u`` of the transmittance: ``I_trans = Col_trans ((1 − u) E(−N)/π + u L(−V))`` (E33).
- ``F_r``: the exact unpolarized Fresnel reflectance of the polymer's index, from a cos θ LUT per
  pixel (``reference.materials.fresnel``).

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
Ramamoorthi, R., & Hanrahan, P. (2001). An efficient representation for irradiance environment
    maps. SIGGRAPH 2001 (the Lambert map).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_finite
from reference.geometry.cubemap import cubemap_lookup_bilinear
from reference.geometry.envmap import latlong_lookup_bilinear
from reference.materials.fresnel import FresnelLUT, fresnel_lut
from reference.registry import Method, Registry
from shrm.polymer.characterization import Characterization
from shrm.polymer.kubelka_munk import saunderson_constants
from shrm.polymer.tint import read_tint_library
from shrm.prefilter import prefilter_environment

__all__ = [
    "MIRROR_FACTORS",
    "PolymerLook",
    "PolymerMaps",
    "effect_radiance",
    "effect_shrm",
    "mirror_factor_cosine",
    "mirror_factor_fresnel",
    "mirror_factor_none",
    "polymer_look",
    "polymer_maps",
    "polymer_terms",
]


def mirror_factor_fresnel(cos_theta, F_r, F_0) -> np.ndarray:
    """The M_s of specref: one minus the normalized Fresnel rise, ``1 − (F_r − F_0) / (1 − F_0)``.

    The M_s of Eq. (5), Herbert et al. (our design, erratum E30): 1 at normal view, 0 at grazing.

    Parameters
    ----------
    cos_theta : ndarray, shape (N,)
        cos of the angle between view and normal.
    F_r : ndarray, shape (N,) or (N, n_bands)
        Fresnel reflectance at ``cos_theta``.
    F_0 : float or ndarray, shape (n_bands,)
        Fresnel reflectance at normal incidence.

    Returns
    -------
    ndarray, shape of ``F_r``, in [0, 1]

    Examples
    --------
    >>> mirror_factor_fresnel(np.array([1.0, 0.0]), np.array([0.04, 1.0]), 0.04)
    array([1., 0.])
    """
    return np.clip(1.0 - (F_r - F_0) / (1.0 - F_0), 0.0, 1.0)


def mirror_factor_cosine(cos_theta, F_r, F_0) -> np.ndarray:
    """A variant of M_s: ``M_s = cos θ`` (the mirror takes over linearly towards grazing).

    The M_s of Eq. (5), Herbert et al. (our variant, erratum E30).

    Examples
    --------
    >>> mirror_factor_cosine(np.array([1.0, 0.5]), np.zeros(2), 0.04)
    array([1. , 0.5])
    """
    c = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    c = c.reshape(c.shape + (1,) * (np.ndim(F_r) - c.ndim))
    return np.broadcast_to(c, np.shape(F_r)).copy()


def mirror_factor_none(cos_theta, F_r, F_0) -> np.ndarray:
    """``M_s ≡ 1``: no mirror term, the blurred Phong map only.

    The M_s of Eq. (5), Herbert et al. (the baseline of the report's comparison).

    Examples
    --------
    >>> mirror_factor_none(np.array([1.0, 0.0]), np.zeros(2), 0.04)
    array([1., 1.])
    """
    return np.ones(np.shape(F_r))


#: The mirror interpolation factors M_s of Eq. (5), Herbert et al., by the names scenes use.
MIRROR_FACTORS = Registry("mirror factor")
for _name, _function in (
    ("fresnel", mirror_factor_fresnel),
    ("cosine", mirror_factor_cosine),
    ("none", mirror_factor_none),
):
    MIRROR_FACTORS.register(
        Method(
            _name,
            _function,
            None,
            "Eq. (5), Herbert et al.",
            lambda rng: (rng.uniform(0, 1, 8), rng.uniform(0.04, 1, 8), 0.04),
        )
    )


@dataclass(frozen=True)
class PolymerMaps:
    """The environment's maps for Eq. (2), Eq. (4) and Eq. (5), Herbert et al. (per environment).

    Parameters
    ----------
    irradiance : ndarray, shape (6, S, S, n_bands)
        Lambert-prefiltered cube map: irradiance E(n), so that E_d = E/π.
    specular : ndarray, shape (6, S, S, n_bands)
        Normalized-Phong-prefiltered cube map at ``phong_exponent``: E_s.
    radiance : ndarray, shape (H, W, n_bands)
        The lat-long environment itself: E_mirror and the unscattered part of E_trans.
    phong_exponent : float
    """

    irradiance: np.ndarray
    specular: np.ndarray
    radiance: np.ndarray
    phong_exponent: float


def polymer_maps(
    radiance, phong_exponent: float = 64.0, size: int = 64, tol: float = 1e-2
) -> PolymerMaps:
    """Prefilter an environment for the polymer model (the §5.2 "diffuse and specular maps").

    Parameters
    ----------
    radiance : array_like, shape (H, W, n_bands)
        Spectral lat-long environment, W = 2H, >= 0.
    phong_exponent : float
        Exponent of the normalized Phong lobe of E_s, in [0, 1e5].
    size : int
        Cube face size.
    tol : float
        Adaptive-order tolerance of the prefilters (``shrm.lobes.adaptive_order``).

    Returns
    -------
    PolymerMaps

    Examples
    --------
    >>> maps = polymer_maps(np.ones((16, 32, 2)), 8.0, size=4)
    >>> maps.irradiance.shape, round(float(maps.irradiance.mean()), 4)
    ((6, 4, 4, 2), 3.1416)
    >>> round(float(maps.specular.mean()), 4)
    1.0
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    E = prefilter_environment(radiance, "lambert", tol=tol, size=size, where="polymer environment")
    s = float(phong_exponent)
    E_s = prefilter_environment(
        radiance, f"phong:{s:g}", tol=tol, size=size, where="polymer environment"
    )
    return PolymerMaps(E.values, E_s.values, radiance, s)


@dataclass(frozen=True)
class PolymerLook:
    """The per-frame spectra and factors of Eqs. (1)-(5), Herbert et al. (no per-pixel work).

    Parameters
    ----------
    D_polymer : ndarray, shape (n_bands,)
        Diffuse colour of the polymer (specular excluded), Eq. (2), Herbert et al.
    Col_trans : ndarray, shape (n_bands,)
        Transmissive colour, Eq. (4), Herbert et al.
    unscattered : ndarray, shape (n_bands,)
        Fraction of Col_trans that passes unscattered (E33), in [0, 1].
    Tint_polymer : ndarray, shape (n_bands,)
        Tint colour, Eq. (2), Herbert et al.
    gloss : float
        Overall glossiness factor of Eq. (5), Herbert et al., in [0, 1].
    fresnel : FresnelLUT
        F_r against cos θ.
    mirror : str
        Key of :data:`MIRROR_FACTORS`.
    """

    D_polymer: np.ndarray
    Col_trans: np.ndarray
    unscattered: np.ndarray
    Tint_polymer: np.ndarray
    gloss: float
    fresnel: FresnelLUT
    mirror: str = "fresnel"


def _spectrum01(values, n_bands: int, where: str) -> np.ndarray:
    values = np.broadcast_to(require_finite(values, where), (n_bands,)).astype(np.float64)
    require(
        bool(np.all((values >= 0) & (values <= 1))),
        f"{where}: must be in [0, 1], got {values.min():g}..{values.max():g}",
    )
    return values


def polymer_look(
    characterization: Characterization,
    thickness_mm: float,
    tio2_pct: float,
    tint=1.0,
    gloss: float = 1.0,
    mirror: str = "fresnel",
    unscattered=0.0,
    index=None,
    tint_library=None,
) -> PolymerLook:
    """Look a chip up once per frame and build the look of Eqs. (1)-(5), Herbert et al.

    §5.1, Herbert et al.: "All function-of parameters are realized through look-up tables, where the
    look-up frequency is per-pixel if the variable is an angle, and per-frame otherwise."
    ``D_polymer`` is the reflectance over black minus the front surface's ``k_1`` (erratum E31);
    ``Col_trans`` the transmittance.

    Parameters
    ----------
    characterization : Characterization
        The chip matrix (``shrm.polymer.characterization``).
    thickness_mm, tio2_pct : float
        The chip, inside the matrix.
    tint : float, array_like, shape (n_bands,), or str
        Tint_polymer, in [0, 1], or the name of a spot colour in ``tint_library``.
    gloss : float
        In [0, 1].
    mirror : str
        Key of :data:`MIRROR_FACTORS`.
    unscattered : float or array_like, shape (n_bands,)
        Unscattered fraction of the transmittance, in [0, 1] (E33).
    index : float or array_like, optional
        Refractive index for F_r and k_1; default the characterization's ``index``.
    tint_library : str or Path, optional
        A spot-colour library (``shrm.polymer.tint``); default the shipped one.

    Returns
    -------
    PolymerLook

    Raises
    ------
    SpecrefError
        For a chip outside the matrix, gloss or tint outside [0, 1], an unknown tint name (listing
        the closest names), an unknown mirror factor, an index <= 1.

    Examples
    --------
    >>> from shrm.polymer.characterization import characterize_model
    >>> look = polymer_look(characterize_model(), 1.0, 0.3)
    >>> look.D_polymer.shape, look.mirror, bool(look.D_polymer.max() < 1)
    ((41,), 'fresnel', True)
    """
    MIRROR_FACTORS.lookup(mirror)
    if isinstance(tint, str):
        library = read_tint_library(tint_library)
        require(
            np.array_equal(library.wavelengths_nm, characterization.wavelengths_nm),
            f"{library.path}: the tint library's wavelengths differ from the characterization's",
        )
        tint = library.tint(tint)
    g = float(require_finite(gloss, "polymer: gloss"))
    require(0.0 <= g <= 1.0, f"polymer: gloss: must be in [0, 1], got {gloss!r}")
    n = characterization.meta.get("index", 1.54) if index is None else index
    chip = characterization.lookup(thickness_mm, tio2_pct)
    k_1 = saunderson_constants(n).k_1
    nb = characterization.wavelengths_nm.size
    D = np.clip(chip["over_black"] - k_1, 0.0, 1.0)
    return PolymerLook(
        D,
        chip["transmittance"],
        _spectrum01(unscattered, nb, "polymer: unscattered"),
        _spectrum01(tint, nb, "polymer: tint"),
        g,
        fresnel_lut(n),
        mirror,
    )


def _terms_inputs(normal, view, look: PolymerLook, maps: PolymerMaps, Mod_effect):
    """The inputs of :func:`polymer_terms`, checked: N and V (N, 3), ``Mod_effect`` as (N, 1)."""
    N = np.asarray(normal, dtype=np.float64)
    V = np.asarray(view, dtype=np.float64)
    require(
        N.ndim == 2 and N.shape == V.shape and N.shape[1] == 3,
        f"polymer_terms: normal and view must be (N, 3), got {N.shape} and {V.shape}",
    )
    nb = look.D_polymer.size
    require(
        maps.radiance.shape[-1] == nb,
        f"polymer_terms: maps have {maps.radiance.shape[-1]} bands, the look {nb}",
    )
    Mod = np.asarray(require_finite(Mod_effect, "polymer: Mod_effect"), dtype=np.float64)
    require(bool(np.all((Mod >= 0) & (Mod <= 1))), "polymer: Mod_effect: must be in [0, 1]")
    Mod = np.broadcast_to(Mod, N.shape[:1])[:, None]
    return N, V, Mod


def polymer_terms(
    normal, view, look: PolymerLook, maps: PolymerMaps, Mod_effect=0.0, E_effect=None
) -> dict[str, np.ndarray]:
    """The terms of Eqs. (1)–(5), Herbert et al., per pixel, as spectra.

    Parameters
    ----------
    normal, view : ndarray, shape (N, 3)
        Unit normals and unit vectors towards the eye.
    look : PolymerLook
        From :func:`polymer_look`.
    maps : PolymerMaps
        From :func:`polymer_maps`, on the same spectral grid.
    Mod_effect : float or ndarray, shape (N,)
        The effect modulation map, in [0, 1].
    E_effect : ndarray, shape (N, n_bands), optional
        Reflected radiance of the effect pigment (an SHRM render); None is zero.

    Returns
    -------
    dict of str to ndarray
        ``I_d``, ``I_effect``, ``I_s``, ``I_trans``, ``I_result`` (N, n_bands) radiance spectra;
        ``F_r`` and ``M_s`` (N, 1) or (N, n_bands).

    Raises
    ------
    SpecrefError
        For mismatched shapes or Mod_effect outside [0, 1].

    Examples
    --------
    >>> from shrm.polymer.characterization import characterize_model
    >>> look = polymer_look(characterize_model(), 1.0, 0.3, mirror="none")
    >>> maps = polymer_maps(np.ones((16, 32, 41)), 8.0, size=4)   # a uniform white sky
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> terms = polymer_terms(up, up, look, maps)
    >>> F = look.fresnel.lookup(1.0)
    >>> expected = look.D_polymer + F + look.Col_trans * (1 - F)
    >>> bool(np.allclose(terms["I_result"], expected, atol=1e-3))
    True
    """
    N, V, Mod = _terms_inputs(normal, view, look, maps, Mod_effect)
    cos_theta = np.clip(np.einsum("ij,ij->i", N, V), 0.0, 1.0)
    # Eq. (1), Herbert et al.: F_r from the cos θ LUT, per pixel
    F_r = look.fresnel.lookup(cos_theta)
    F_r = F_r[:, None] if F_r.ndim == 1 else F_r
    F_0 = look.fresnel.lookup(1.0)
    # Eq. (2), Herbert et al.: I_d = E_d D_polymer Tint_polymer (1 − Mod_effect), E_d = E(N)/π
    E_d = cubemap_lookup_bilinear(maps.irradiance, N, backend="numba") / np.pi
    I_d = E_d * look.D_polymer * look.Tint_polymer * (1.0 - Mod)
    # Eq. (3), Herbert et al.: I_effect = E_effect Mod_effect
    I_effect = (
        np.zeros_like(I_d) if E_effect is None else np.asarray(E_effect, dtype=np.float64) * Mod
    )
    # Eq. (5), Herbert et al.: I_s = (E_s M_s + E_mirror (1 − M_s)) gloss, at r = 2 (N·V) N − V
    r = 2.0 * cos_theta[:, None] * N - V
    E_s = cubemap_lookup_bilinear(maps.specular, r, backend="numba")
    E_mirror = latlong_lookup_bilinear(maps.radiance, r)
    M_s = MIRROR_FACTORS.lookup(look.mirror).reference(cos_theta, F_r, F_0)
    I_s = (E_s * M_s + E_mirror * (1.0 - M_s)) * look.gloss
    # Eq. (4), Herbert et al.: I_trans = E_trans Col_trans, E_trans from behind the surface (E33)
    E_back = cubemap_lookup_bilinear(maps.irradiance, -N, backend="numba") / np.pi
    L_behind = latlong_lookup_bilinear(maps.radiance, -V)
    E_trans = (1.0 - look.unscattered) * E_back + look.unscattered * L_behind
    I_trans = E_trans * look.Col_trans
    # Eq. (1), Herbert et al.: I_result = I_d + I_effect + I_s F_r + I_trans (1 − F_r), I_r = I_s
    I_result = I_d + I_effect + I_s * F_r + I_trans * (1.0 - F_r)
    return {
        "I_d": I_d,
        "I_effect": I_effect,
        "I_s": I_s,
        "I_trans": I_trans,
        "F_r": F_r,
        "M_s": M_s,
        "I_result": I_result,
    }


def effect_shrm(
    radiance,
    brdf: str = "effect_pigment",
    params: dict | None = None,
    grid=None,
    F: int = 8,
    P: int = 8,
    size: int = 16,
    frame: str = "reflection",
):
    """The effect pigment's SHRM under an environment, for E_effect of Eq. (3), Herbert et al.

    §5.1, Herbert et al.: "the effect pigment ... rendered through its SHRM". The pigment is an
    isotropic BRDF of ``reference.materials.brdf.BRDF_METHODS`` (default the thin-film
    ``effect_pigment``; a tabulated BRDF works the same), expanded in double SH (``shrm.brdf_sh``)
    and combined with the environment's SH coefficients in frequency space
    (``shrm.shrm.shrm_create``), like the SHRM materials of ``shrm.orbit``. It depends on the
    environment and the pigment only: a change of ``Mod_effect`` re-shades without rebuilding it.

    Parameters
    ----------
    radiance : ndarray, shape (H, W, n_bands)
        Spectral lat-long environment (the polymer's).
    brdf : str
        Key of ``BRDF_METHODS`` (isotropic).
    params : dict, optional
        Overrides of its default parameters (``shrm.orbit.brdf_params_on_grid``).
    grid : SpectralGrid, optional
        The environment's bands; default ``reference.colour.spectra.DEFAULT_GRID``.
    F, P : int
        Lighting and view orders of the expansion (F is capped at H/2 − 1).
    size : int
        Cube face size.
    frame : {"reflection", "normal"}

    Returns
    -------
    shrm.shrm.SHRM

    Examples
    --------
    >>> from shrm.shrm import shrm_extract
    >>> s = effect_shrm(np.ones((8, 16, 41)), F=2, P=2, size=2)
    >>> s.frame, shrm_extract(s, [0.0, 0.0, 1.0]).shape               # a map per band
    ('reflection', (6, 2, 2, 41))
    """
    from reference.colour.spectra import DEFAULT_GRID
    from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    from shrm.orbit import brdf_params_on_grid
    from shrm.shrm import shrm_create
    from shrm.transform import project_latlong

    radiance = np.asarray(require_finite(radiance, "polymer: effect environment"), dtype=float)
    grid = DEFAULT_GRID if grid is None else grid
    require(
        radiance.shape[-1] == grid.n_bands,
        f"polymer: effect environment has {radiance.shape[-1]} bands, the grid {grid.n_bands}",
    )
    F = min(int(F), radiance.shape[0] // 2 - 1)
    L = project_latlong(radiance, F, backend="ducc0", where="polymer effect environment")
    function, expand, lam, k = shrm_brdf_parts(brdf, brdf_params_on_grid(brdf, grid, params))
    rho = brdf_sh_coefficients(function, expand, F, int(P), frame, view_power=k)
    return shrm_create(L, rho, frame, int(size), "ducc0", k, lam)


def effect_radiance(effect, normal, view) -> np.ndarray:
    """E_effect of Eq. (3), Herbert et al.: the effect pigment's radiance from its SHRM.

    §5.6, Herbert et al.: extract the SHRM's reflection map for the viewpoint (a distant viewer:
    the mean of the view vectors), then look it up per pixel (``shrm.shrm.shade_shrm``). Pass the
    result to :func:`polymer_terms` as ``E_effect``, with ``Mod_effect`` mixing it in.

    Parameters
    ----------
    effect : shrm.shrm.SHRM
        From :func:`effect_shrm`.
    normal, view : ndarray, shape (N, 3)
        Unit normals and unit vectors towards the eye.

    Returns
    -------
    ndarray, shape (N, n_bands)

    Examples
    --------
    >>> s = effect_shrm(np.ones((8, 16, 41)), F=2, P=2, size=2)
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> effect_radiance(s, up, up).shape
    (1, 41)
    """
    from shrm.shrm import shade_shrm, shrm_extract

    N = np.asarray(normal, dtype=np.float64)
    V = np.asarray(view, dtype=np.float64)
    require(
        N.ndim == 2 and N.shape == V.shape and N.shape[1] == 3,
        f"polymer: effect_radiance: normal and view must be (N, 3), got {N.shape} and {V.shape}",
    )
    v = V.mean(axis=0)
    v = v / np.linalg.norm(v)
    return shade_shrm(effect, shrm_extract(effect, v), N, v)
