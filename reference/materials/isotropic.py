"""Isotropic 3-D BRDFs f(θ_i, θ_o, Δφ), spectral: Ward, GGX microfacet and Lafortune lobes.

Herbert et al. render "measured 1-D and 3-D BRDFs" with SHRMs (§5, §5.5). A 3-D BRDF is isotropic:
it depends on the two polar angles and the difference of azimuths only. This module holds the
analytic models that specref tabulates and renders the same way as measured data
(:mod:`reference.materials.table`):

- **Ward isotropic**, Eq. (4), Ward 1992:
  ``ρ_d/π + ρ_s exp(−tan²θ_h/α²) / (4π α² √(cos θ_i cos θ_o))``.
- **GGX microfacet**, Eq. (20), Walter et al. 2007: ``ρ_d/π + F D G / (4 cos θ_i cos θ_o)`` with the
  GGX distribution D (Eq. (33), Walter et al. 2007), the separable Smith shadowing
  ``G = G_1(ω_i) G_1(ω_o)`` (Eq. (34), Walter et al. 2007) and Schlick's Fresnel
  ``F = F_0 + (1 − F_0)(1 − ω_i·h)^5`` per band.
- **Lafortune**, one isotropic generalized cosine lobe (Lafortune et al. 1997):
  ``ρ_d/π + ρ_s (n+2)/(2π) max(0, C_xy (u_x v_x + u_y v_y) + C_z u_z v_z)^n``; ``C_xy = −1``,
  ``C_z = 1`` is the normalized Phong lobe about the mirror direction.

Conventions follow :mod:`reference.materials.brdf`: directions are unit vectors ``(..., 3)``
pointing away from the surface, the normal is passed explicitly, spectral parameters carry the band
axis last and the result is ``(..., C)``. Below the horizon the BRDF is 0. :func:`isotropic_angles`
and :func:`isotropic_directions` convert between directions and ``(θ_i, θ_o, Δφ)``, with ``Δφ = φ_o
− φ_i`` folded to [0, π] (π is the plane of incidence on the mirror side).

Albedo bounds (checked by the white-furnace tests): Lafortune's lobe with ``|C_xy|, |C_z| <= 1`` has
albedo at most ``ρ_d + ρ_s`` at every incidence (the normalized Phong lobe about the normal has
albedo exactly ρ_s, and a lobe about any other axis, or with a shorter axis, has less); GGX with
separable Smith shadowing has albedo at most ``ρ_d + max F`` (single scattering loses energy);
Ward's normalization is accurate for α up to about 0.2 away from grazing incidence (Ward 1992, §4).

References
----------
- G. J. Ward, "Measuring and modeling anisotropic reflection", SIGGRAPH 1992.
- B. Walter, S. R. Marschner, H. Li, K. E. Torrance, "Microfacet models for refraction through rough
  surfaces", EGSR 2007.
- C. Schlick, "An inexpensive BRDF model for physically-based rendering", CGF 13(3), 1994.
- E. P. F. Lafortune, S.-C. Foo, K. E. Torrance, D. P. Greenberg, "Non-linear approximation of
  reflectance functions", SIGGRAPH 1997.
- R. R. Lewis, "Making shaders more physically plausible", CGF 13(2), 1994 (Phong normalization).
"""

from __future__ import annotations

import numpy as np

from reference.errors import require, require_nonnegative
from reference.materials.brdf import BRDF_METHODS, BRDFMethod, _dot, pdf_cosine, sample_cosine

__all__ = [
    "brdf_ggx",
    "brdf_lafortune",
    "brdf_ward_isotropic",
    "ggx_distribution",
    "ggx_smith_G1",
    "isotropic_angles",
    "isotropic_directions",
    "register_brdf",
]


def isotropic_angles(wi, wo, normal) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The isotropic BRDF coordinates ``(θ_i, θ_o, Δφ)`` of direction pairs, radians.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.

    Returns
    -------
    theta_i, theta_o : ndarray, shape (...,)
        Polar angles from the normal, in [0, π].
    phi_d : ndarray, shape (...,)
        ``|φ_o − φ_i|`` folded to [0, π]; π is the mirror side of the plane of incidence, and 0
        where either direction is along the normal.

    Examples
    --------
    >>> n = np.array([0.0, 0.0, 1.0])
    >>> wi = np.array([0.6, 0.0, 0.8]); wo = np.array([-0.6, 0.0, 0.8])
    >>> [round(float(np.degrees(a)), 4) for a in isotropic_angles(wi, wo, n)]
    [36.8699, 36.8699, 180.0]
    """
    wi, wo, normal = (np.asarray(v, dtype=np.float64) for v in (wi, wo, normal))
    cos_i, cos_o = _dot(wi, normal), _dot(wo, normal)
    ti = wi - cos_i[..., None] * normal
    to = wo - cos_o[..., None] * normal
    ni, no = np.linalg.norm(ti, axis=-1), np.linalg.norm(to, axis=-1)
    ok = (ni > 1e-15) & (no > 1e-15)
    # atan2(|t_i × t_o|, t_i · t_o) stays accurate near 0 and π, where arccos loses half the digits
    sin_part = np.linalg.norm(np.cross(ti, to), axis=-1)
    phi_d = np.where(ok, np.arctan2(sin_part, _dot(ti, to)), 0.0)
    theta_i = np.arccos(np.clip(cos_i, -1.0, 1.0))
    theta_o = np.arccos(np.clip(cos_o, -1.0, 1.0))
    return theta_i, theta_o, phi_d


def isotropic_directions(theta_i, theta_o, phi_d) -> tuple[np.ndarray, np.ndarray]:
    """Directions with the given ``(θ_i, θ_o, Δφ)`` about the normal +z (inverse of the above).

    ``ω_i = (sin θ_i, 0, cos θ_i)``, ``ω_o = (sin θ_o cos Δφ, sin θ_o sin Δφ, cos θ_o)``.

    Parameters
    ----------
    theta_i, theta_o, phi_d : array_like
        Angles in radians; they broadcast.

    Returns
    -------
    wi, wo : ndarray, shape (..., 3)

    Examples
    --------
    >>> wi, wo = isotropic_directions(np.pi / 4, np.pi / 4, np.pi)
    >>> (wi + wo).round(12)
    array([0.        , 0.        , 1.41421356])
    """
    theta_i, theta_o, phi_d = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (theta_i, theta_o, phi_d))
    )
    wi = np.stack([np.sin(theta_i), np.zeros_like(theta_i), np.cos(theta_i)], axis=-1)
    s = np.sin(theta_o)
    wo = np.stack([s * np.cos(phi_d), s * np.sin(phi_d), np.cos(theta_o)], axis=-1)
    return wi, wo


def _geometry(wi, wo, normal):
    """Cosines of the pair, the above-the-surface mask and the unit half vector."""
    wi, wo, normal = (np.asarray(v, dtype=np.float64) for v in (wi, wo, normal))
    cos_i, cos_o = _dot(wi, normal), _dot(wo, normal)
    above = (cos_i > 0.0) & (cos_o > 0.0)
    h = wi + wo
    h = h / np.maximum(np.linalg.norm(h, axis=-1), 1e-300)[..., None]
    cos_h = np.clip(_dot(h, normal), 1e-150, 1.0)
    return wi, wo, normal, cos_i, cos_o, above, h, cos_h


def _spectral(values, where: str) -> np.ndarray:
    values = require_nonnegative(values, where)
    return values[None] if values.ndim == 0 else values


def brdf_ward_isotropic(wi, wo, normal, rho_d, rho_s, alpha) -> np.ndarray:
    """Ward's isotropic Gaussian BRDF, spectral.

    Eq. (4), Ward 1992: ``ρ_d/π + ρ_s exp(−tan²θ_h/α²) / (4π α² √(cos θ_i cos θ_o))``.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    rho_d, rho_s : array_like, shape (C,) or scalar
        Diffuse and specular reflectance per band, >= 0.
    alpha : array_like, shape (C,) or scalar
        RMS slope of the surface, > 0.

    Returns
    -------
    ndarray, shape (..., C)
        BRDF, 1/sr; 0 below the horizon.

    Raises
    ------
    SpecrefError
        Negative or non-finite parameters, ``α <= 0``.

    Examples
    --------
    >>> n = np.array([0.0, 0.0, 1.0])
    >>> brdf_ward_isotropic(n, n, n, 0.0, [1.0, 0.5], 0.5).round(6)
    array([0.31831 , 0.159155])
    """
    rho_d = _spectral(rho_d, "ward_isotropic: rho_d")
    rho_s = _spectral(rho_s, "ward_isotropic: rho_s")
    alpha = _spectral(alpha, "ward_isotropic: alpha")
    require(bool((alpha > 0).all()), f"ward_isotropic: alpha: must be > 0, got {alpha.min():g}")
    _, _, _, cos_i, cos_o, above, _, cos_h = _geometry(wi, wo, normal)
    cos_h = np.where(above, cos_h, 1.0)
    tan2_h = ((1.0 - cos_h * cos_h) / (cos_h * cos_h))[..., None]
    root = np.sqrt(np.where(above, cos_i * cos_o, 1.0))[..., None]
    # Eq. (4), Ward 1992: ρ_d/π + ρ_s exp(−tan²θ_h/α²) / (4π α² sqrt(cos θ_i cos θ_o))
    f = rho_d / np.pi + rho_s * np.exp(-tan2_h / alpha**2) / (4.0 * np.pi * alpha**2 * root)
    return np.where(above[..., None], f, 0.0)


def ggx_distribution(cos_h, alpha) -> np.ndarray:
    """The GGX (Trowbridge–Reitz) microfacet distribution.

    Eq. (33), Walter et al. 2007: ``D = α² / (π cos⁴θ_h (α² + tan²θ_h)²)``.

    Parameters
    ----------
    cos_h : array_like, shape (...,)
        Cosine between the microfacet normal and the surface normal, in (0, 1].
    alpha : array_like
        Width, > 0 (broadcast against ``cos_h``).

    Returns
    -------
    ndarray
        Density of microfacet normals, 1/sr; ``∫ D cos θ_h dω_h = 1``.

    Examples
    --------
    >>> float(ggx_distribution(1.0, 0.5)).__round__(6)
    1.27324
    """
    cos_h = np.asarray(cos_h, dtype=np.float64)
    alpha2 = np.asarray(alpha, dtype=np.float64) ** 2
    tan2 = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    # Eq. (33), Walter et al. 2007
    return alpha2 / (np.pi * cos_h**4 * (alpha2 + tan2) ** 2)


def ggx_smith_G1(cos_v, alpha) -> np.ndarray:
    """Smith's masking function for GGX.

    Eq. (34), Walter et al. 2007: ``G_1 = 2 / (1 + √(1 + α² tan²θ_v))`` (for ``v·h > 0``).

    Examples
    --------
    >>> float(ggx_smith_G1(1.0, 0.3)), float(ggx_smith_G1(0.5, 0.3)).__round__(6)
    (1.0, 0.940317)
    """
    cos_v = np.asarray(cos_v, dtype=np.float64)
    alpha2 = np.asarray(alpha, dtype=np.float64) ** 2
    tan2 = (1.0 - cos_v * cos_v) / np.maximum(cos_v * cos_v, 1e-300)
    # Eq. (34), Walter et al. 2007
    return 2.0 / (1.0 + np.sqrt(1.0 + alpha2 * tan2))


def brdf_ggx(wi, wo, normal, rho_d, F_0, alpha) -> np.ndarray:
    """The GGX microfacet BRDF with Smith shadowing and Schlick's Fresnel, plus Lambert, spectral.

    Eq. (20), Walter et al. 2007: ``f = ρ_d/π + F(ω_i·h) G D / (4 cos θ_i cos θ_o)``.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    rho_d : array_like, shape (C,) or scalar
        Diffuse reflectance per band, >= 0.
    F_0 : array_like, shape (C,) or scalar
        Fresnel reflectance at normal incidence per band, in [0, 1] (0.04 for n = 1.5).
    alpha : array_like, shape (C,) or scalar
        GGX width (roughness squared in Disney's parameterization), > 0.

    Returns
    -------
    ndarray, shape (..., C)
        BRDF, 1/sr; 0 below the horizon.

    Raises
    ------
    SpecrefError
        Negative or non-finite parameters, ``F_0 > 1``, ``α <= 0``.

    Examples
    --------
    >>> n = np.array([0.0, 0.0, 1.0])
    >>> brdf_ggx(n, n, n, 0.0, [1.0, 0.04], 0.5).round(6)
    array([0.31831 , 0.012732])
    """
    rho_d, F_0 = _spectral(rho_d, "ggx: rho_d"), _spectral(F_0, "ggx: F_0")
    alpha = _spectral(alpha, "ggx: alpha")
    require(bool((alpha > 0).all()), f"ggx: alpha: must be > 0, got {alpha.min():g}")
    require(bool((F_0 <= 1).all()), f"ggx: F_0: must be in [0, 1], got {F_0.max():g}")
    wi, wo, normal, cos_i, cos_o, above, h, cos_h = _geometry(wi, wo, normal)
    i_dot_h = np.clip(_dot(wi, h), 0.0, 1.0)[..., None]
    # Schlick 1994: F = F_0 + (1 − F_0)(1 − ω_i·h)^5
    F = F_0 + (1.0 - F_0) * (1.0 - i_dot_h) ** 5
    ci, co, ch = (np.where(above, c, 1.0)[..., None] for c in (cos_i, cos_o, cos_h))
    D = ggx_distribution(ch, alpha)
    G = ggx_smith_G1(ci, alpha) * ggx_smith_G1(co, alpha)
    # Eq. (20), Walter et al. 2007: f = F G D / (4 |ω_i·n| |ω_o·n|), plus Lambert
    f = rho_d / np.pi + F * G * D / (4.0 * ci * co)
    return np.where(above[..., None], f, 0.0)


def brdf_lafortune(wi, wo, normal, rho_d, rho_s, C_xy, C_z, n) -> np.ndarray:
    """One isotropic Lafortune lobe with Phong normalization, plus Lambert, spectral.

    Lafortune et al. 1997, §3, the generalized cosine lobe (one lobe, ``C_x = C_y = C_xy``):
    ``ρ_d/π + ρ_s (n+2)/(2π) max(0, C_xy (u_x v_x + u_y v_y) + C_z u_z v_z)^n``.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    rho_d, rho_s : array_like, shape (C,) or scalar
        Diffuse reflectance and lobe weight per band, >= 0.
    C_xy, C_z : float
        Lobe axis coefficients in the local frame; ``(−1, 1)`` is the mirror direction (Phong),
        ``|C_xy| > |C_z|`` moves the lobe towards grazing (off-specular peaks), ``C_xy > 0``
        reflects back towards the source (retro-reflection).
    n : array_like, shape (C,) or scalar
        Lobe exponent per band, >= 0.

    Returns
    -------
    ndarray, shape (..., C)
        BRDF, 1/sr; 0 below the horizon.

    Examples
    --------
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> brdf_lafortune(z, z, z, 0.0, 1.0, -1.0, 1.0, [0.0, 10.0]).round(6)
    array([0.31831 , 1.909859])
    """
    rho_d, rho_s = _spectral(rho_d, "lafortune: rho_d"), _spectral(rho_s, "lafortune: rho_s")
    n = _spectral(n, "lafortune: n")
    C_xy, C_z = float(C_xy), float(C_z)
    require(np.isfinite(C_xy) and np.isfinite(C_z), "lafortune: C_xy, C_z: must be finite")
    wi, wo, normal = (np.asarray(v, dtype=np.float64) for v in (wi, wo, normal))
    cos_i, cos_o = _dot(wi, normal), _dot(wo, normal)
    above = (cos_i > 0.0) & (cos_o > 0.0)
    # u_x v_x + u_y v_y in the tangent plane: ω_i·ω_o − cos θ_i cos θ_o (frame independent)
    tangential = _dot(wi, wo) - cos_i * cos_o
    dot = np.maximum(C_xy * tangential + C_z * cos_i * cos_o, 0.0)[..., None]
    # Lafortune et al. 1997, §3: ρ_s (C_xy(u_x v_x + u_y v_y) + C_z u_z v_z)^n, normalized
    f = rho_d / np.pi + rho_s * (n + 2.0) / (2.0 * np.pi) * np.where(dot > 0.0, dot, 0.0) ** n
    return np.where(above[..., None], f, 0.0)


# --- registry ---------------------------------------------------------------------------------


def _cosine_sample(wi, normal, u, **params):
    return sample_cosine(normal, u)


def _cosine_pdf(wi, wo, normal, **params):
    return pdf_cosine(wo, normal)


_WARD_PARAMS = {"rho_d": 0.2, "rho_s": np.array([0.3, 0.5, 0.7]), "alpha": 0.15}
_GGX_PARAMS = {"rho_d": np.array([0.5, 0.3, 0.1]), "F_0": 0.04, "alpha": 0.2}
_LAFORTUNE_PARAMS = {
    "rho_d": np.array([0.1, 0.2, 0.3]),
    "rho_s": 0.6,
    "C_xy": -1.0,
    "C_z": 0.9,
    "n": np.array([20.0, 30.0, 40.0]),
}


def register_brdf(method: BRDFMethod) -> None:
    """Register ``method`` in :data:`reference.materials.brdf.BRDF_METHODS`, once per key.

    A second import of the defining module (pytest's doctest collector imports modules by path)
    re-registers the same function, which is skipped; a different function under a taken key is
    refused, as :meth:`reference.registry.Registry.register` does.

    Examples
    --------
    >>> register_brdf(BRDF_METHODS.lookup("ggx"))  # the same entry again: a no-op
    >>> BRDF_METHODS.lookup("ggx").name
    'ggx'
    """
    if method.name in BRDF_METHODS:
        old = BRDF_METHODS.lookup(method.name).reference
        new = method.reference
        if (old.__module__, old.__qualname__) == (new.__module__, new.__qualname__):
            return
    BRDF_METHODS.register(method)


def _register(name, function, cites, params, bound, grazing_view_power=0.0):
    register_brdf(
        BRDFMethod(
            name,
            function,
            None,
            cites,
            lambda rng, params=params: dict(params),
            # A valid, not importance-matched sampler: cosine-weighted directions.
            sample=_cosine_sample,
            pdf=_cosine_pdf,
            params=params,
            albedo_bound=bound,
            isotropic=True,
            # The model adds rho_d/pi: SHRMs render that part with an irradiance map.
            lambert="rho_d",
            grazing_view_power=grazing_view_power,
        )
    )


_register(
    "ward_isotropic",
    brdf_ward_isotropic,
    "Eq. (4), Ward 1992",
    _WARD_PARAMS,
    "about rho_d + rho_s for alpha <= 0.2 away from grazing incidence (Ward 1992)",
    # Eq. (4), Ward 1992: 1 / sqrt(cos θ_i cos θ_o) diverges at grazing views
    grazing_view_power=0.5,
)
_register(
    "ggx",
    brdf_ggx,
    "Eq. (20), Walter et al. 2007",
    _GGX_PARAMS,
    "at most rho_d + max F (single scattering, Walter et al. 2007)",
)
_register(
    "lafortune",
    brdf_lafortune,
    "Lafortune et al. 1997, §3 (generalized cosine lobe)",
    _LAFORTUNE_PARAMS,
    "at most rho_d + rho_s for |C_xy|, |C_z| <= 1 (normalized Phong lobe, Lewis 1994)",
)
