"""Thin-film interference (Airy) and a gonio-apparent "effect pigment" BRDF.

Herbert et al. (§3.2, Figure 4) show ChromaFlair, an interference pigment whose colour shifts with
the viewing angle and which "is only properly characterized by a complete 3-D BRDF". specref stands
in for it with a physical model: flakes coated with a thin dielectric film over an absorbing base.

**Airy reflectance** of a film of index ``n_1`` and thickness ``d`` between an ambient medium
``n_0`` and a base of complex index ``n_2 = n + iκ`` (Born & Wolf, §1.6.4 and §13.4):

    r = (r_01 + r_12 e^{iδ}) / (1 + r_01 r_12 e^{iδ}),    δ = 4π d n_1 cos θ_1 / λ,    R = |r|²,

with the Fresnel amplitude coefficients ``r_jk`` of the two interfaces for s and p polarization,
written with ``q_j = n_j cos θ_j = √(n_j² − n_0² sin²θ_0)`` (principal branch, so that waves decay
in an absorbing base): ``r_jk^s = (q_j − q_k)/(q_j + q_k)``,
``r_jk^p = (n_k² q_j − n_j² q_k)/(n_k² q_j + n_j² q_k)``. Unpolarized light gets ``(R_s + R_p)/2``.
Because δ shrinks as cos θ_1 does, the reflectance peaks move to shorter wavelengths at oblique
angles: the colour shifts with angle.

**The effect pigment BRDF** (:func:`brdf_effect_pigment`): flakes whose normals follow the GGX
distribution (Eq. (33), Walter et al. 2007) reflect with the film's Airy reflectance at the
microfacet angle ``ω_i·h``, in place of Fresnel's (Eq. (20), Walter et al. 2007); light that the
film transmits twice reaches a Lambertian base:

    f = R(λ, ω_i·h) D G / (4 cos θ_i cos θ_o) + (1 − R(λ, cos θ_i))(1 − R(λ, cos θ_o)) ρ_base(λ)/π.

Both terms are symmetric in ``ω_i, ω_o``, so the model is reciprocal.

References
----------
- M. Born, E. Wolf, *Principles of Optics*, 7th ed., Cambridge 1999, §1.6.4 and §13.4.
- L. Belcour, P. Barla, "A practical extension to microfacet theory for the modeling of varying
  iridescence", ACM TOG 36(4), 2017.
- B. Walter, S. R. Marschner, H. Li, K. E. Torrance, "Microfacet models for refraction through rough
  surfaces", EGSR 2007.
"""

from __future__ import annotations

import numpy as np

from reference.errors import require, require_finite, require_nonnegative
from reference.materials.brdf import BRDFMethod, _dot
from reference.materials.isotropic import (
    _cosine_pdf,
    _cosine_sample,
    _geometry,
    ggx_distribution,
    ggx_smith_G1,
    register_brdf,
)

__all__ = ["airy_reflectance", "brdf_effect_pigment"]


def _q(n, sin2_0):
    """``n cos θ`` inside a medium of (complex) index ``n`` by Snell's law, principal branch."""
    return np.sqrt(n * n - sin2_0 + 0j)


def airy_reflectance(
    cos_theta_0, wavelengths_nm, thickness_nm, n_film, n_base, k_base=0.0, n_0=1.0
):
    """Reflectance of a thin film on a base (Airy summation), unpolarized, per wavelength.

    Born & Wolf, §1.6.4: ``r = (r_01 + r_12 e^{iδ}) / (1 + r_01 r_12 e^{iδ})``, ``R = |r|²``.

    Parameters
    ----------
    cos_theta_0 : array_like, shape (...,)
        Cosine of the angle of incidence in the ambient medium, in [0, 1].
    wavelengths_nm : array_like, shape (C,)
        Wavelengths in vacuum, nm, > 0.
    thickness_nm : float
        Film thickness ``d``, nm, >= 0 (0 gives the bare base).
    n_film : array_like, shape (C,) or scalar
        Real refractive index of the film, > 0.
    n_base, k_base : array_like, shape (C,) or scalar
        Refractive index and extinction coefficient of the base (``n + iκ``), ``n > 0``,
        ``κ >= 0``.
    n_0 : float
        Ambient index (1 for air).

    Returns
    -------
    ndarray, shape (..., C)
        ``(R_s + R_p)/2`` in [0, 1].

    Examples
    --------
    >>> # A quarter-wave antireflection film, n_1 = sqrt(n_0 n_2), n_1 d = λ/4 at 550 nm
    >>> float(airy_reflectance(1.0, [550.0], 550 / 4 / 1.5**0.5, 1.5**0.5, 1.5)[0]).__round__(12)
    0.0
    >>> airy_reflectance(1.0, [550.0], 0.0, 1.3, 1.5).round(6)  # bare glass: ((1.5-1)/2.5)²
    array([0.04])
    """
    cos_0 = np.clip(require_finite(cos_theta_0, "airy: cos_theta_0"), 0.0, 1.0)
    lam = require_nonnegative(wavelengths_nm, "airy: wavelengths_nm")
    require(bool((lam > 0).all()), "airy: wavelengths_nm: must be > 0")
    d = float(require_nonnegative(thickness_nm, "airy: thickness_nm"))
    n_1 = require_nonnegative(n_film, "airy: n_film")
    n_b = require_nonnegative(n_base, "airy: n_base")
    k_b = require_nonnegative(k_base, "airy: k_base")
    require(bool((n_1 > 0).all()) and bool((n_b > 0).all()), "airy: indices must be > 0")
    # The reflectance depends on the angle alone: evaluated once per distinct angle (a BRDF's
    # R(cos θ_o) is one value over all its lights), then spread back
    unique, where = np.unique(cos_0, return_inverse=True)
    R = _airy(unique[:, None], lam, d, n_1, n_b + 1j * k_b, n_0)
    return R[where.reshape(cos_0.shape)]


def _airy(cos_0, lam, d, n_1, n_2, n_0):
    """:func:`airy_reflectance` at the angles ``cos_0`` (shape (n, 1)), checked inputs."""
    sin2_0 = (n_0 * n_0) * (1.0 - cos_0 * cos_0)
    q_0, q_1, q_2 = n_0 * cos_0 + 0j, _q(n_1, sin2_0), _q(n_2, sin2_0)
    # Born & Wolf §1.6.4: phase difference of one round trip in the film, δ = 4π d n_1 cos θ_1 / λ
    phase = np.exp(1j * 4.0 * np.pi * d * q_1 / lam)
    R = 0.0
    for pol in ("s", "p"):
        if pol == "s":
            r_01 = (q_0 - q_1) / (q_0 + q_1)
            r_12 = (q_1 - q_2) / (q_1 + q_2)
        else:
            r_01 = (n_1**2 * q_0 - n_0**2 * q_1) / (n_1**2 * q_0 + n_0**2 * q_1)
            r_12 = (n_2**2 * q_1 - n_1**2 * q_2) / (n_2**2 * q_1 + n_1**2 * q_2)
        # Born & Wolf §1.6.4: Airy summation of the multiply reflected waves
        r = (r_01 + r_12 * phase) / (1.0 + r_01 * r_12 * phase)
        R = R + 0.5 * np.abs(r) ** 2
    return np.clip(R, 0.0, 1.0)


def brdf_effect_pigment(
    wi, wo, normal, wavelengths_nm, thickness_nm, n_film, n_base, k_base, rho_base, alpha
) -> np.ndarray:
    """A gonio-apparent interference pigment: thin-film-coated GGX flakes over a Lambertian base.

    Eq. (20), Walter et al. 2007, with the Airy film reflectance (Born & Wolf, §1.6.4) in place of
    Fresnel's: ``R(ω_i·h) D G / (4 cos θ_i cos θ_o) + (1 − R(cos θ_i))(1 − R(cos θ_o)) ρ_base/π``.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    wavelengths_nm : array_like, shape (C,)
        The bands, nm.
    thickness_nm, n_film, n_base, k_base
        The film and base, see :func:`airy_reflectance`.
    rho_base : array_like, shape (C,) or scalar
        Reflectance of the base under the film, in [0, 1].
    alpha : float
        GGX width of the flake orientations, > 0.

    Returns
    -------
    ndarray, shape (..., C)
        BRDF, 1/sr; 0 below the horizon.

    Examples
    --------
    >>> z = np.array([0.0, 0.0, 1.0]); w = np.array([0.6, 0.0, 0.8]); v = np.array([-0.6, 0, 0.8])
    >>> f = brdf_effect_pigment(w, v, z, [450.0, 650.0], 400.0, 2.0, 3.0, 3.0, 0.05, 0.2)
    >>> f.round(3)
    array([0.225, 0.276])
    """
    lam = np.atleast_1d(require_nonnegative(wavelengths_nm, "effect_pigment: wavelengths_nm"))
    rho_base = require_nonnegative(rho_base, "effect_pigment: rho_base")
    alpha = float(require_nonnegative(alpha, "effect_pigment: alpha"))
    require(alpha > 0, f"effect_pigment: alpha: must be > 0, got {alpha:g}")
    require(bool((rho_base <= 1).all()), "effect_pigment: rho_base: must be in [0, 1]")
    wi, wo, normal, cos_i, cos_o, above, h, cos_h = _geometry(wi, wo, normal)
    film = (thickness_nm, n_film, n_base, k_base)
    R_h = airy_reflectance(np.clip(_dot(wi, h), 0.0, 1.0), lam, *film)
    R_i = airy_reflectance(np.clip(cos_i, 0.0, 1.0), lam, *film)
    R_o = airy_reflectance(np.clip(cos_o, 0.0, 1.0), lam, *film)
    ci, co, ch = (np.where(above, c, 1.0)[..., None] for c in (cos_i, cos_o, cos_h))
    D = ggx_distribution(ch, alpha)
    G = ggx_smith_G1(ci, alpha) * ggx_smith_G1(co, alpha)
    # Eq. (20), Walter et al. 2007, with the Airy reflectance as the flakes' Fresnel factor
    flakes = R_h * D * G / (4.0 * ci * co)
    # Light transmitted by the film twice reaches the Lambertian base
    base = (1.0 - R_i) * (1.0 - R_o) * rho_base / np.pi
    return np.where(above[..., None], flakes + base, 0.0)


#: A red-gold shifting pigment: a 380 nm film of index 2.0 (TiO₂-like) on a chromium-like base.
_PIGMENT_PARAMS = {
    "wavelengths_nm": np.linspace(380.0, 780.0, 41),
    "thickness_nm": 380.0,
    "n_film": 2.0,
    "n_base": 3.2,
    "k_base": 3.3,
    "rho_base": 0.05,
    "alpha": 0.15,
}

register_brdf(
    BRDFMethod(
        "effect_pigment",
        brdf_effect_pigment,
        None,
        "Eq. (20), Walter et al. 2007",
        lambda rng: dict(_PIGMENT_PARAMS),
        sample=_cosine_sample,
        pdf=_cosine_pdf,
        params=_PIGMENT_PARAMS,
        albedo_bound="at most 1: flakes reflect R, the base receives (1 - R)^2 rho_base",
        isotropic=True,
    )
)
