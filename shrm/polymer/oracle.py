"""The layered physical model behind Herbert et al.'s hybrid polymer shading, by brute force.

The physical counterpart of Eq. (1), Herbert et al.

The hybrid model of ``shrm.polymer.hybrid`` (Eqs. (1)-(5), Herbert et al.) sums prefiltered-map
terms. The material it imitates is a layer: a dielectric interface of index ``n`` (rough when gloss
< 1) over a Kubelka–Munk slab that absorbs (K), scatters (S) and, when thin, lets light through.
This module shades that layer per pixel by integrating over the environment directly, with no
prefiltering:

- **specular**: reflection at the interface. Smooth (gloss = 1): ``F(cos θ_o) L(r)``, the exact
  Fresnel factor times the environment in the mirror direction (bilinear look-up). Rough: the GGX
  microfacet reflection ``f_s = F(o·h) D(h) G_1(i) G_1(o) / (4 cos θ_i cos θ_o)`` (Eq. (20),
  Walter et al. 2007; Eq. (33), Walter et al. 2007; Eq. (34), Walter et al. 2007; separable Smith
  masking), integrated by Monte Carlo with GGX
  visible-normal sampling (Heitz 2018) and the map's own texels sampled by their power, the two
  combined by Veach's balance heuristic (:func:`rough_specular_samples_mis`, erratum E117), seeded,
  in rounds until a stated tolerance (erratum E65).
- **body**: the light that is not reflected enters the slab, ``1 − E_ρ(θ)`` of it, where ``E_ρ`` is
  the interface's directional reflectance (``F`` when smooth; the rough lobe's albedo otherwise,
  E66). The KM body diffuses it (two-flux: the light inside is diffuse, E67); the body and the back
  surface reflect ``R_B``, the front surface reflects ``r_t`` back in, so ``(1 − r_t) R_B /
  (1 − r_t R_B)`` of the entering flux leaves again (Saunderson 1942), with the radiance
  distribution ``(1 − E_ρ(θ_o)) / (π (1 − k_e))`` that reciprocity gives.
- **transmission**: light from the back hemisphere enters through the (smooth) back surface and
  leaves through the front: ``τ = T (1 − r_t) / D`` of the entering flux.

With an opaque body and a smooth interface this is the standard smooth-plastic model (Weidlich &
Wilkie 2007; Mitsuba 3's ``plastic`` with ``nonlinear = true``), whose white-furnace albedo has the
closed form :func:`smooth_plastic_albedo`.

The integrals over the environment: the body and transmission irradiances are sums over the map's
pixels (the midpoint rule with exact pixel solid angles, converging as the map is refined);
the rough specular lobe, too narrow for that, is sampled.

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality (specref's Herbert et al.).
Walter, B., Marschner, S., Li, H., Torrance, K. (2007). Microfacet models for refraction through
    rough surfaces. EGSR 2007.
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Veach, E., Guibas, L. (1995). Optimally combining sampling techniques for Monte Carlo rendering.
    SIGGRAPH 1995.
Pharr, M., Jakob, W., Humphreys, G. (2016). Physically Based Rendering, 3rd ed.
Weidlich, A., Wilkie, A. (2007). Arbitrarily layered micro-facet surfaces. GRAPHITE 2007.
Saunderson, J. L. (1942). Calculation of the color of pigmented plastics. JOSA 32, 727-736.
Duff, T., et al. (2017). Building an orthonormal basis, revisited. JCGT 6(1).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np

from reference.errors import require, require_choice, require_finite, require_positive_int
from reference.geometry.envmap import (
    check_latlong_shape,
    direction_to_latlong_uv,
    latlong_lookup_bilinear,
    latlong_pixel_directions,
    latlong_pixel_solid_angles,
)
from reference.materials.fresnel import fresnel_dielectric, fresnel_diffuse
from reference.registry import Method, Registry
from shrm.polymer.kubelka_munk import km_slab

__all__ = [
    "GLOSS_ALPHA_MAX",
    "ORACLE_KERNELS",
    "PHONG_EXPONENT_MAX",
    "SPECULAR_CHUNK_SAMPLES",
    "OracleResult",
    "body_factors",
    "coupled_irradiance",
    "environment_sampling",
    "gloss_alpha",
    "gloss_phong_exponent",
    "interface_coupling",
    "oracle_bsdf",
    "oracle_diffuse",
    "polymer_oracle",
    "rough_reflection_albedo",
    "rough_specular_samples",
    "rough_specular_samples_mis",
    "smooth_plastic_albedo",
]

#: GGX width at gloss 0: ``α = GLOSS_ALPHA_MAX (1 − gloss)`` (our mapping, erratum E65).
GLOSS_ALPHA_MAX = 0.5
#: The hybrid's Phong exponent for a smooth interface (an infinite exponent cannot be prefiltered).
PHONG_EXPONENT_MAX = 1000.0


def gloss_alpha(gloss) -> float:
    """GGX width of the interface for a gloss in [0, 1]: ``α = 0.5 (1 − gloss)`` (erratum E65).

    Herbert et al. give gloss as a factor of Eq. (5), Herbert et al., not a roughness; the oracle
    needs one. Gloss 1 is a smooth (mirror) interface.

    Examples
    --------
    >>> gloss_alpha(1.0), gloss_alpha(0.8), gloss_alpha(0.0)
    (0.0, 0.09999999999999998, 0.5)
    """
    g = float(require_finite(gloss, "polymer oracle: gloss"))
    require(0.0 <= g <= 1.0, f"polymer oracle: gloss: must be in [0, 1], got {gloss!r}")
    return GLOSS_ALPHA_MAX * (1.0 - g)


def gloss_phong_exponent(gloss) -> float:
    """The hybrid's Phong exponent matching the oracle's GGX width: ``s = 2/α² − 2`` (E65).

    Walter et al. 2007 (§5.2) relate a Phong exponent to a Beckmann width by ``α = sqrt(2/(s+2))``;
    specref applies it to the GGX width of :func:`gloss_alpha`, capped at
    :data:`PHONG_EXPONENT_MAX` for a smooth interface.

    Examples
    --------
    >>> round(gloss_phong_exponent(0.8), 6), gloss_phong_exponent(1.0)
    (198.0, 1000.0)
    """
    alpha = gloss_alpha(gloss)
    if alpha <= 0.0:
        return PHONG_EXPONENT_MAX
    return float(min(2.0 / alpha**2 - 2.0, PHONG_EXPONENT_MAX))


def smooth_plastic_albedo(cos_theta, n, rho) -> np.ndarray:
    """White-furnace albedo of the smooth-plastic model (dielectric over a Lambertian base).

    ``a(θ) = F(θ) + (1 − F(θ)) ρ (1 − F_dr,int) / (1 − ρ F_dr,int)``: the Fresnel reflection plus
    the light that enters, ``1 − F(θ)``, is reflected by the base ``ρ`` and escapes after any number
    of internal reflections ``F_dr,int`` (the internal diffuse Fresnel reflectance, total internal
    reflection included). It follows from the BRDF of Weidlich & Wilkie 2007 (and Mitsuba 3
    ``plastic`` with ``nonlinear = true``),
    ``f_d = (1 − F_i)(1 − F_o) ρ / (π n² (1 − ρ F_dr,int))``,
    integrated over the hemisphere with ``∫ (1 − F) cos θ dω = π (1 − F_dr,ext)`` and the identity
    ``1 − F_dr,int = (1 − F_dr,ext) / n²``. It is the opaque, smooth limit of
    :func:`polymer_oracle` (the physical counterpart of Eq. (1), Herbert et al.).

    Parameters
    ----------
    cos_theta : array_like, shape (...,)
        cos of the view angle.
    n : float
        Index, > 1.
    rho : float or array_like, shape (n_bands,)
        Reflectance of the base, in [0, 1].

    Returns
    -------
    ndarray, shape (..., n_bands) or (...,)
        Radiance reflected under a uniform environment of radiance 1 (= the directional albedo).

    Examples
    --------
    >>> smooth_plastic_albedo([1.0, 0.0], 1.5, 1.0).round(12)   # a white base loses nothing
    array([1., 1.])
    >>> float(smooth_plastic_albedo(1.0, 1.5, 0.0)).__round__(4)  # a black base: F_0
    0.04
    """
    F = fresnel_dielectric(cos_theta, n)
    rho = np.asarray(rho, dtype=np.float64)
    if rho.ndim:
        F = np.asarray(F)[..., None]
    F_dr_int = fresnel_diffuse(n, "inside")
    return F + (1.0 - F) * rho * (1.0 - F_dr_int) / (1.0 - rho * F_dr_int)


def _frame(N):
    """Tangent and bitangent of unit normals (Duff et al. 2017), shape (P, 3) each."""
    sign = np.copysign(1.0, N[:, 2])
    a = -1.0 / (sign + N[:, 2])
    b = N[:, 0] * N[:, 1] * a
    T = np.stack([1.0 + sign * N[:, 0] ** 2 * a, sign * b, -sign * N[:, 0]], axis=-1)
    B = np.stack([b, sign + N[:, 1] ** 2 * a, -N[:, 1]], axis=-1)
    return T, B


def _local_views(N, V, shape):
    """Tangent frames (T, B) and the views in them, above the surface, broadcast to shape + (3,)."""
    T, B = _frame(N)
    o = np.stack([np.einsum("ij,ij->i", V, A) for A in (T, B, N)], axis=-1)
    o[:, 2] = np.maximum(o[:, 2], 1e-6)
    o = o / np.linalg.norm(o, axis=-1, keepdims=True)
    return T, B, np.broadcast_to(o[:, None, :], (*shape, 3))


def _sample_visible_normal(o, alpha, u1, u2):
    """GGX visible normals for local view directions ``o`` (Heitz 2018, listing 1)."""
    Vh = np.stack([alpha * o[..., 0], alpha * o[..., 1], o[..., 2]], axis=-1)
    Vh = Vh / np.linalg.norm(Vh, axis=-1, keepdims=True)
    lensq = Vh[..., 0] ** 2 + Vh[..., 1] ** 2
    inv = np.where(lensq > 0, 1.0 / np.sqrt(np.where(lensq > 0, lensq, 1.0)), 0.0)
    T1 = np.where(
        (lensq > 0)[..., None],
        np.stack([-Vh[..., 1] * inv, Vh[..., 0] * inv, np.zeros_like(inv)], axis=-1),
        np.array([1.0, 0.0, 0.0]),
    )
    T2 = np.cross(Vh, T1)
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    t1 = r * np.cos(phi)
    s = 0.5 * (1.0 + Vh[..., 2])
    t2 = (1.0 - s) * np.sqrt(1.0 - t1 * t1) + s * r * np.sin(phi)
    t3 = np.sqrt(np.maximum(0.0, 1.0 - t1 * t1 - t2 * t2))
    Nh = t1[..., None] * T1 + t2[..., None] * T2 + t3[..., None] * Vh
    h = np.stack([alpha * Nh[..., 0], alpha * Nh[..., 1], np.maximum(0.0, Nh[..., 2])], axis=-1)
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def _smith_G1(cos_v, alpha):
    """Smith's GGX masking, Eq. (34), Walter et al. 2007 (0 below the horizon)."""
    c2 = np.maximum(cos_v * cos_v, 1e-300)
    G = 2.0 / (1.0 + np.sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2))
    return np.where(cos_v > 0.0, G, 0.0)


def _local_view(cos_o):
    cos_o = np.clip(np.asarray(cos_o, dtype=np.float64), 1e-6, 1.0)
    return np.stack([np.sqrt(1.0 - cos_o**2), np.zeros_like(cos_o), cos_o], axis=-1)


def _reflect_weight(o, h, alpha, n):
    """The VNDF estimator's weight ``F(o·h) G_1(i)`` and the reflected local direction i."""
    oh = np.einsum("...k,...k->...", o, h)
    i = 2.0 * oh[..., None] * h - o
    return fresnel_dielectric(oh, n) * _smith_G1(i[..., 2], alpha), i


def rough_reflection_albedo(
    cos_o, n: float, alpha: float, order: int = 96, backend: str = "numpy"
) -> np.ndarray:
    """Directional albedo ``E_ρ(θ_o)`` of the rough interface's reflection lobe.

    ``E_ρ = ∫ f_s cos θ_i dω_i`` for ``f_s`` of Eq. (20), Walter et al. 2007 (GGX, separable
    Smith): with visible-normal sampling the integrand is ``F(o·h) G_1(i)`` over the unit square,
    here by a ``order × order`` Gauss–Legendre rule (deterministic). ``α = 0`` gives ``F(θ_o)``.
    It sets how much light enters the slab in the oracle (the physical counterpart of Eq. (1),
    Herbert et al.; erratum E66).

    Parameters
    ----------
    cos_o : array_like, shape (m,)
        cos of the view angle, in [0, 1].
    n : float
        Index, > 1.
    alpha : float
        GGX width, >= 0.
    order : int
        Gauss–Legendre nodes per axis.
    backend : {"numpy", "numba"}
        Who sums: this readable form, or its twin of :data:`ORACLE_KERNELS` (the same to 1e-12;
        :func:`interface_coupling` uses the twin).

    Returns
    -------
    ndarray, shape (m,)

    Examples
    --------
    >>> rough_reflection_albedo([1.0], 1.5, 0.0).round(6)
    array([0.04])
    >>> bool(rough_reflection_albedo([0.5], 1.5, 0.3)[0] < fresnel_dielectric(0.5, 1.5) + 0.02)
    True
    """
    require_choice(backend, ("numpy", "numba"), "rough reflection albedo: backend")
    cos_o = np.atleast_1d(np.asarray(cos_o, dtype=np.float64))
    if alpha <= 0.0:
        return fresnel_dielectric(cos_o, n)
    if backend == "numba":
        return _albedo_kernel_call(cos_o, n, alpha, order)
    u1, u2, weights = _albedo_nodes(order)
    o = _local_view(cos_o)[:, None, :]
    h = _sample_visible_normal(np.broadcast_to(o, (cos_o.size, u1.size, 3)), alpha, u1, u2)
    value, _ = _reflect_weight(o, h, alpha, n)
    return value @ weights


@dataclass(frozen=True)
class Coupling:
    """How the front interface couples the outside to the slab (E66).

    Parameters
    ----------
    cos_nodes, enter : ndarray, shape (m,)
        ``1 − E_ρ`` against cos θ (linear interpolation between nodes).
    k_e : float
        Hemispherical mean of ``E_ρ`` (the external diffuse reflectance).
    r_i : float
        Internal diffuse reflectance, ``1 − (1 − k_e) / n²`` (so that energy is conserved).
    """

    cos_nodes: np.ndarray
    enter: np.ndarray
    k_e: float
    r_i: float

    @cached_property
    def _evenly_spaced(self) -> bool:
        """Whether the nodes are ``linspace(0, 1, m)`` (checked once per table)."""
        return bool(np.array_equal(self.cos_nodes, np.linspace(0.0, 1.0, self.cos_nodes.size)))

    def lookup(self, cos_theta) -> np.ndarray:
        """``1 − E_ρ(θ)`` at ``cos_theta`` (0 below the horizon).

        Examples
        --------
        >>> c = Coupling(np.linspace(0.0, 1.0, 5), np.linspace(1.0, 0.0, 5), 0.5, 0.8)
        >>> c.lookup([-0.5, 0.0, 0.1, 1.0, 1.5])
        array([0. , 0. , 0.9, 0. , 0. ])
        """
        c = np.asarray(cos_theta, dtype=np.float64)
        m = self.cos_nodes.size - 1
        if self._evenly_spaced:
            # evenly spaced nodes (interface_coupling's): the interval by index, not by search
            x = np.clip(c, 0.0, 1.0) * m
            i = np.minimum(x.astype(np.int64), m - 1)
            f = x - i
            value = self.enter[i] * (1.0 - f) + self.enter[i + 1] * f
        else:
            value = np.interp(np.clip(c, 0.0, 1.0), self.cos_nodes, self.enter)
        return np.where(c > 0.0, value, 0.0)


@lru_cache(maxsize=32)
def interface_coupling(n: float, alpha: float, nodes: int = 129) -> Coupling:
    """The coupling of the slab to the outside through a smooth or GGX-rough interface (E66).

    Smooth: ``1 − F(θ)``, ``k_e = F_dr,ext``, ``r_i = F_dr,int`` (``reference.materials.fresnel``).
    Rough:
    ``1 − E_ρ(θ)`` of :func:`rough_reflection_albedo` (everything the lobe does not reflect enters),
    ``k_e = ∫ E_ρ 2μ dμ`` and ``r_i = 1 − (1 − k_e)/n²``. The oracle's body term; the physical
    counterpart of Eq. (1), Herbert et al.

    Examples
    --------
    >>> c = interface_coupling(1.5, 0.0)
    >>> round(c.k_e, 4), round(c.r_i, 3), round(float(c.lookup(1.0)), 4)
    (0.0918, 0.596, 0.96)
    """
    cos_nodes = np.linspace(0.0, 1.0, int(nodes))
    if alpha <= 0.0:
        enter = 1.0 - fresnel_dielectric(cos_nodes, n)
        k_e, r_i = float(fresnel_diffuse(n)), float(fresnel_diffuse(n, "inside"))
    else:
        enter = 1.0 - rough_reflection_albedo(cos_nodes, n, alpha, backend="numba")
        x, w = np.polynomial.legendre.leggauss(64)
        mu = 0.5 * (x + 1.0)
        k_e = float(0.5 * w @ ((1.0 - np.interp(mu, cos_nodes, enter)) * 2.0 * mu))
        r_i = 1.0 - (1.0 - k_e) / n**2
    enter.setflags(write=False)
    return Coupling(cos_nodes, enter, k_e, r_i)


def body_factors(K, S, d, r_t: float, r_b: float):
    """Diffuse reflection ``ρ_out`` and transmission ``τ`` of the slab between its two surfaces.

    The slab's part of the physical counterpart of Eq. (1), Herbert et al. Fluxes: ``ρ_out`` of
    the flux entering at the front leaves at the front, ``τ`` of the flux entering at the back
    leaves at the front (both already through the front surface).

    Parameters
    ----------
    K, S : array_like, shape (n_bands,)
        Absorption and scattering, 1/mm.
    d : float
        Thickness, mm.
    r_t, r_b : float
        Internal diffuse reflectances of the front and back surfaces (``Coupling.r_i``).

    Returns
    -------
    rho_out, tau : ndarray, shape (n_bands,)

    Examples
    --------
    >>> rho_out, tau = body_factors(np.array([0.0]), np.array([1e6]), 1.0, 0.6, 0.6)
    >>> rho_out.round(6), tau.round(6)              # a white opaque body loses nothing
    (array([1.]), array([0.]))
    """
    R_0, T = km_slab(K, S, d)
    # Kubelka (1948): body over the back surface, seen from the front
    R_B = R_0 + T**2 * r_b / (1.0 - R_0 * r_b)
    # Saunderson (1942): multiple reflection under the front surface
    rho_out = (1.0 - r_t) * R_B / (1.0 - r_t * R_B)
    # both surfaces around the body: D = (1 − R_0 r_t)(1 − R_0 r_b) − r_t r_b T²
    D = (1.0 - R_0 * r_t) * (1.0 - R_0 * r_b) - r_t * r_b * T**2
    tau = T * (1.0 - r_t) / D
    return rho_out, tau


def oracle_bsdf(wi, wo, normal, K, S, d, n: float = 1.54, gloss: float = 1.0) -> np.ndarray:
    """The layered BSDF for direction pairs (the physical counterpart of Eq. (1), Herbert et al.).

    Reflection (``wi`` above): the GGX lobe (rough interface only; a smooth one is a delta, left
    out) plus the body ``(1 − E_ρ(θ_i))(1 − E_ρ(θ_o)) ρ_out / (π (1 − k_e))``; transmission
    (``wi`` below): ``(1 − F(θ_i))(1 − E_ρ(θ_o)) τ / (π (1 − k_e))``. Reciprocal in both.

    Parameters
    ----------
    wi, wo, normal : ndarray, shape (P, 3)
        Unit directions (``wo`` on the normal's side).
    K, S : array_like, shape (n_bands,)
        1/mm.
    d : float
        Thickness, mm.
    n, gloss : float

    Returns
    -------
    ndarray, shape (P, n_bands), 1/sr

    Examples
    --------
    >>> up = np.array([[0.0, 0.0, 1.0]])
    >>> f = oracle_bsdf(up, up, up, [0.0], [1e6], 1.0, 1.5)   # a white opaque base
    >>> float(f[0, 0] * np.pi).__round__(4)   # ≈ (1 − F_0)² / (1 − F_dr,ext) for ρ → 1
    1.0147
    """
    wi, wo, N = (np.asarray(a, dtype=np.float64) for a in (wi, wo, normal))
    alpha = gloss_alpha(gloss)
    front = interface_coupling(float(n), alpha)
    back = interface_coupling(float(n), 0.0)
    rho_out, tau = body_factors(np.asarray(K, float), np.asarray(S, float), d, front.r_i, back.r_i)
    ci, co = np.einsum("ij,ij->i", wi, N), np.einsum("ij,ij->i", wo, N)
    exit_ = front.lookup(co)[:, None] / (np.pi * (1.0 - front.k_e))
    body = np.where((ci > 0)[:, None], front.lookup(ci)[:, None] * rho_out, 0.0)
    trans = np.where((ci < 0)[:, None], back.lookup(-ci)[:, None] * tau, 0.0)
    f = exit_ * (body + trans)
    if alpha > 0.0:
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        ch = np.clip(np.einsum("ij,ij->i", h, N), 1e-12, 1.0)
        D = alpha**2 / (np.pi * ch**4 * (alpha**2 + (1.0 - ch**2) / ch**2) ** 2)
        F = fresnel_dielectric(np.einsum("ij,ij->i", wi, h), n)
        G = _smith_G1(ci, alpha) * _smith_G1(co, alpha)
        spec = F * D * G / (4.0 * np.maximum(ci, 1e-300) * np.maximum(co, 1e-300))
        f = f + np.where(ci > 0, spec, 0.0)[:, None]
    return f


def rough_specular_samples(normal, view, radiance, alpha, n, u) -> tuple[np.ndarray, np.ndarray]:
    """Sums of the rough-specular estimator ``F(o·h) G_1(i) L(i)`` over given uniforms.

    The interface term of the oracle (physical counterpart of ``I_s F_r`` in Eq. (1), Herbert
    et al.): each sample draws a GGX visible normal ``h`` (Heitz 2018) from two uniforms, reflects
    the view about it, ``i = 2 (o·h) h − o``, and weighs the environment there (bilinear) by
    ``F(o·h) G_1(i)`` (Eq. (20), Walter et al. 2007, and Eq. (34), Walter et al. 2007; 0 below
    the horizon).

    Parameters
    ----------
    normal, view : ndarray, shape (P, 3)
        Unit normals and unit vectors towards the eye.
    radiance : ndarray, shape (H, W, n_bands)
        Lat-long environment.
    alpha, n : float
        GGX width (> 0) and index.
    u : ndarray, shape (P, M, 2)
        Uniforms in [0, 1).

    Returns
    -------
    total, total_sq : ndarray, shape (P, n_bands)
        Sum over the M samples of the estimate and of its square.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> u = rng.random((1, 4000, 2))
    >>> total, _ = rough_specular_samples(up, up, np.ones((8, 16, 1)), 0.2, 1.5, u)
    >>> abs(float(total[0, 0]) / 4000 - float(rough_reflection_albedo([1.0], 1.5, 0.2)[0])) < 2e-3
    True
    """
    N = np.asarray(normal, dtype=np.float64)
    V = np.asarray(view, dtype=np.float64)
    T, B, o = _local_views(N, V, u.shape[:2])
    h = _sample_visible_normal(o, alpha, u[..., 0], u[..., 1])
    weight, i = _reflect_weight(o, h, alpha, n)
    wi = i[..., 0:1] * T[:, None] + i[..., 1:2] * B[:, None] + i[..., 2:3] * N[:, None]
    x = weight[..., None] * latlong_lookup_bilinear(radiance, wi)
    return x.sum(axis=1), (x * x).sum(axis=1)


def environment_sampling(radiance) -> tuple[np.ndarray, np.ndarray]:
    """The map's texels as a sampling density: ``p(ω) = L̄_t / Σ_t L̄_t Ω_t`` inside texel t.

    ``L̄_t`` is the texel's band-mean radiance and ``Ω_t`` its exact solid angle
    (``latlong_pixel_solid_angles``): a texel is chosen with probability ``L̄_t Ω_t / Σ L̄ Ω``
    and a direction uniformly in its solid angle, so the density is constant over the texel
    (Pharr, Jakob & Humphreys 2016, §14.2.4, without its sin θ approximation).

    Parameters
    ----------
    radiance : ndarray, shape (H, W, n_bands)

    Returns
    -------
    cdf : ndarray, shape (H·W,)
        Cumulative texel probabilities, row-major (all zero for a black map).
    pdf : ndarray, shape (H·W,)
        The density inside each texel, 1/sr.

    Examples
    --------
    >>> cdf, pdf = environment_sampling(np.ones((4, 8, 2)))
    >>> float(cdf[-1]), bool(np.allclose(pdf, 1 / (4 * np.pi)))
    (1.0, True)
    """
    H, W = radiance.shape[:2]
    omega = latlong_pixel_solid_angles(H, W)
    mass = (np.asarray(radiance, dtype=np.float64).mean(axis=-1) * omega).ravel()
    total = float(mass.sum())
    if total <= 0.0:
        return np.zeros(H * W), np.zeros(H * W)
    cdf = np.cumsum(mass) / total
    cdf[-1] = 1.0
    return cdf, mass / (total * omega.ravel())


def _environment_directions(cdf, H: int, W: int, u1, u2):
    """Directions drawn from :func:`environment_sampling`'s CDF and their texels (row-major)."""
    k = np.minimum(np.searchsorted(cdf, u1, side="right"), H * W - 1)
    low = np.where(k > 0, cdf[np.maximum(k - 1, 0)], 0.0)
    # u1's place within the texel's share gives the azimuth, u2 the cosine: uniform in Ω_t
    frac = np.clip((u1 - low) / np.maximum(cdf[k] - low, 1e-300), 0.0, 1.0)
    row, col = k // W, k % W
    cos0, cos1 = np.cos(np.pi * row / H), np.cos(np.pi * (row + 1) / H)
    cos_t = cos0 + u2 * (cos1 - cos0)
    phi = 2.0 * np.pi * (col + frac) / W
    sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
    return np.stack([sin_t * np.sin(phi), cos_t, -sin_t * np.cos(phi)], axis=-1), k


def _texel_of(d, H: int, W: int):
    """The row-major texel of unit directions (the one whose solid angle holds them)."""
    u, v = direction_to_latlong_uv(d)
    row = np.minimum(np.floor(v * H), H - 1).astype(np.int64)
    col = np.minimum(np.floor(u * W), W - 1).astype(np.int64)
    return row * W + col


def _vndf_pdf(o, i, alpha):
    """``p(i) = G_1(o) D(h) / (4 cos θ_o)``: the visible-normal density of a reflected direction."""
    h = o + i
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    oh = np.einsum("...k,...k->...", o, h)
    # D of Eq. (33), Walter et al. 2007
    D = alpha**2 / (np.pi * (h[..., 2] ** 2 * (alpha**2 - 1.0) + 1.0) ** 2)
    ok = (oh > 0.0) & (h[..., 2] > 0.0)
    return np.where(ok, _smith_G1(o[..., 2], alpha) * D / (4.0 * o[..., 2]), 0.0), oh


def rough_specular_samples_mis(
    normal, view, radiance, alpha, n, u, sampling=None
) -> tuple[np.ndarray, np.ndarray]:
    """Sums of the rough-specular estimator with the map sampled too (Veach's balance heuristic).

    The interface term of the oracle (physical counterpart of ``I_s F_r`` in Eq. (1), Herbert
    et al.), as :func:`rough_specular_samples` estimates it. Each sample is a pair: a GGX
    visible normal (from ``u[..., 0:2]``) and a direction drawn from the map
    (:func:`environment_sampling`, from ``u[..., 2:4]``). Each direction ``i`` adds
    ``f_s cos θ_i L(i) / (p_v(i) + p_e(i))``
    (Veach & Guibas 1995, the balance heuristic with one sample per technique), and since
    ``f_s cos θ_i = F(o·h) G_1(i) p_v(i)`` for the separable Smith GGX of Eq. (20), Walter et al.
    2007, that is ``F(o·h) G_1(i) L(i) p_v / (p_v + p_e)``. Unbiased like the visible normals
    alone, but a small bright lamp that the lobe's samples would rarely meet is sampled where it
    is: under studio_small_03 at 32 rows, two seeds of the visible normals alone at 4,096
    samples differed by ΔE00 1.7 on a near-black chip (erratum E117).

    Parameters
    ----------
    normal, view, radiance, alpha, n
        As :func:`rough_specular_samples`.
    u : ndarray, shape (P, M, 4)
        Uniforms in [0, 1): M pairs per pixel.
    sampling : (cdf, pdf), optional
        :func:`environment_sampling` of ``radiance`` (made if not given).

    Returns
    -------
    total, total_sq : ndarray, shape (P, n_bands)
        Sums over the M pairs of the pair's estimate and of its square.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> total, _ = rough_specular_samples_mis(up, up, np.ones((8, 16, 1)), 0.2, 1.5,
    ...                                       rng.random((1, 4000, 4)))
    >>> abs(float(total[0, 0]) / 4000 - float(rough_reflection_albedo([1.0], 1.5, 0.2)[0])) < 2e-3
    True
    """
    N = np.asarray(normal, dtype=np.float64)
    V = np.asarray(view, dtype=np.float64)
    H, W = radiance.shape[:2]
    cdf, pdf = environment_sampling(radiance) if sampling is None else sampling
    T, B, o = _local_views(N, V, u.shape[:2])
    h = _sample_visible_normal(o, alpha, u[..., 0], u[..., 1])
    i_v = 2.0 * np.einsum("...k,...k->...", o, h)[..., None] * h - o
    world = np.stack([T, B, N], axis=1)  # local (t, b, n) to world: i @ world
    d_v = np.einsum("pmk,pkj->pmj", i_v, world)
    d_e, k_e = _environment_directions(cdf, H, W, u[..., 2], u[..., 3])
    i_e = np.einsum("pmj,pkj->pmk", d_e, world)
    total = 0.0
    for i, d, p_e in ((i_v, d_v, pdf[_texel_of(d_v, H, W)]), (i_e, d_e, pdf[k_e])):
        p_v, oh = _vndf_pdf(o, i, alpha)
        # F(o·h) G_1(i) p_v / (p_v + p_e): the balance heuristic's weight on the estimator
        share = np.where(p_v > 0.0, p_v / np.maximum(p_v + p_e, 1e-300), 0.0)
        weight = fresnel_dielectric(np.maximum(oh, 0.0), n) * _smith_G1(i[..., 2], alpha) * share
        total = total + weight[..., None] * latlong_lookup_bilinear(radiance, d)
    return total.sum(axis=1), (total * total).sum(axis=1)


def _rough_specular_kernel_call(normal, view, radiance, alpha, n, u):
    from shrm.polymer._kernels import rough_specular_samples_kernel

    return _sums_by(rough_specular_samples_kernel, normal, view, radiance, alpha, n, u)


def _rough_specular_mis_call(normal, view, radiance, alpha, n, u, sampling=None):
    from shrm.polymer._kernels import rough_specular_mis_kernel

    cdf, pdf = environment_sampling(radiance) if sampling is None else sampling
    return _sums_by(rough_specular_mis_kernel, normal, view, radiance, alpha, n, u, cdf, pdf)


def _sums_by(kernel, normal, view, radiance, alpha, n, u, *extra):
    """A rough-specular kernel's sums and sums of squares ``(P, n_bands)`` each."""
    P, nb = normal.shape[0], radiance.shape[-1]
    total, total_sq = np.zeros((P, nb)), np.zeros((P, nb))
    contiguous = (np.ascontiguousarray(a, dtype=np.float64) for a in (normal, view, radiance))
    u = np.ascontiguousarray(u, dtype=np.float64)
    kernel(*contiguous, float(alpha), float(n), u, *extra, total, total_sq)
    return total, total_sq


def _albedo_nodes(order: int):
    """The unit square's ``order × order`` Gauss–Legendre nodes ``u1, u2`` and weights."""
    x, w = np.polynomial.legendre.leggauss(int(order))
    x, w = 0.5 * (x + 1.0), 0.5 * w
    u1, u2 = (np.ascontiguousarray(a.ravel()) for a in np.meshgrid(x, x, indexing="ij"))
    return u1, u2, np.outer(w, w).ravel()


def _albedo_kernel_call(cos_o, n, alpha, order=96):
    from shrm.polymer._kernels import rough_reflection_albedo_kernel

    cos_o = np.ascontiguousarray(np.atleast_1d(cos_o), dtype=np.float64)
    out = np.empty(cos_o.size)
    rough_reflection_albedo_kernel(cos_o, float(alpha), float(n), *_albedo_nodes(order), out)
    return out


def _example_albedo_inputs(rng):
    return np.r_[0.0, rng.uniform(0.0, 1.0, 7), 1.0], 1.54, 0.35, 24


def _example_specular_inputs(rng):
    N = rng.normal(size=(5, 3))
    N /= np.linalg.norm(N, axis=-1, keepdims=True)
    V = N + 0.5 * rng.normal(size=(5, 3))
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    return N, V, rng.uniform(0, 2, (8, 16, 3)), 0.25, 1.54, rng.random((5, 32, 2))


def _example_mis_inputs(rng):
    N, V, radiance, alpha, n, _ = _example_specular_inputs(rng)
    radiance[2, 5] = 40.0  # a small lamp
    return N, V, radiance, alpha, n, rng.random((5, 32, 4))


def _register():
    from shrm.polymer import _kernels as k

    ORACLE_KERNELS.register(
        Method(
            "rough_specular",
            rough_specular_samples,
            k.rough_specular_samples_kernel,
            "Eq. (1), Herbert et al.",
            _example_specular_inputs,
            compiled=_rough_specular_kernel_call,
        )
    )
    ORACLE_KERNELS.register(
        Method(
            "rough_specular_mis",
            rough_specular_samples_mis,
            k.rough_specular_mis_kernel,
            "Eq. (1), Herbert et al.; Veach & Guibas 1995",
            _example_mis_inputs,
            compiled=_rough_specular_mis_call,
        )
    )
    ORACLE_KERNELS.register(
        Method(
            "rough_reflection_albedo",
            rough_reflection_albedo,
            k.rough_reflection_albedo_kernel,
            "Eq. (20), Walter et al. 2007",
            _example_albedo_inputs,
            compiled=_albedo_kernel_call,
        )
    )


#: The oracle's hot loop and its numba twin (tests check the pair).
ORACLE_KERNELS = Registry("polymer oracle kernel")
_register()


@dataclass(frozen=True)
class OracleResult:
    """The oracle's radiance per pixel, by term (spectra, shape (P, n_bands)).

    Parameters
    ----------
    specular, body, transmission, result : ndarray, shape (P, n_bands)
        Interface reflection, light scattered back by the slab, light through it, and their sum.
    standard_error : ndarray, shape (P, n_bands)
        Monte Carlo standard error of ``specular`` (0 for a smooth interface).
    samples : int
        Samples per pixel of the specular lobe.
    relative_error : float
        The convergence measure reached: the 99th percentile over pixels of the band-mean
        standard error over the band-mean result.
    seconds : float
        Wall time.
    """

    specular: np.ndarray
    body: np.ndarray
    transmission: np.ndarray
    result: np.ndarray
    standard_error: np.ndarray
    samples: int
    relative_error: float
    seconds: float


def coupled_irradiance(
    normals,
    radiance,
    coupling: Coupling,
    side: float = 1.0,
    chunk: int = 512,
    backend: str = "numba",
) -> np.ndarray:
    """``∫ c(cos θ) max(cos θ, 0) L dω`` about each normal: the light through an interface.

    The body and transmission integrals of the oracle (the physical counterpart of Eq. (1),
    Herbert et al.; E66): ``c = 1 − E_ρ`` of the coupling, ``θ`` the angle between the normal
    (``side`` = −1: the opposite direction) and each pixel of the lat-long map, summed over the
    map's pixels with their solid angles.

    Parameters
    ----------
    normals : ndarray, shape (P, 3)
        Unit normals.
    radiance : ndarray, shape (H, W, n_bands)
        Lat-long environment (W = 2H).
    coupling : Coupling
        The interface (:func:`interface_coupling`).
    side : float
        1 for the hemisphere about the normal, −1 for the one behind it.
    chunk : int
        Normals per block (memory: ``chunk × H W`` weights).
    backend : {"numba", "numpy"}
        Who makes a block's weights ``c(cos) max(cos, 0) ω``: one pass of
        ``shrm.polymer._kernels._coupled_weights_kernel`` (tables on evenly spaced nodes, as
        :func:`interface_coupling` makes them), or :meth:`Coupling.lookup`'s array passes (the
        readable form; equal to 1e-12).

    Returns
    -------
    ndarray, shape (P, n_bands)

    Examples
    --------
    Under a uniform sky, ``π (1 − k_e)``:

    >>> c = interface_coupling(1.5, 0.0)
    >>> E = coupled_irradiance(np.array([[0.0, 1.0, 0.0]]), np.ones((32, 64, 1)), c)
    >>> bool(np.allclose(E, np.pi * (1 - c.k_e), rtol=2e-3))
    True
    """
    require_choice(backend, ("numba", "numpy"), "coupled irradiance: backend")
    chunk = require_positive_int(chunk, "coupled irradiance: chunk")
    N = np.asarray(require_finite(normals, "coupled irradiance: normals"), dtype=np.float64)
    require(N.shape[-1:] == (3,), f"coupled irradiance: normals must be (P, 3), got {N.shape}")
    N = N.reshape(-1, 3)
    radiance = np.asarray(
        require_finite(radiance, "coupled irradiance: radiance"), dtype=np.float64
    )
    check_latlong_shape(radiance.shape, "coupled irradiance: radiance")
    H, W = radiance.shape[:2]
    D = latlong_pixel_directions(H, W).reshape(-1, 3)
    omega = latlong_pixel_solid_angles(H, W).ravel()
    L = radiance.reshape(-1, radiance.shape[-1])
    out = np.empty((N.shape[0], L.shape[1]))
    fast = backend == "numba" and coupling._evenly_spaced
    if fast:
        from shrm.polymer._kernels import _coupled_weights_kernel

        N, D, weights = (
            np.ascontiguousarray(N),
            np.ascontiguousarray(D),
            np.empty((chunk, D.shape[0])),
        )
    for s in range(0, N.shape[0], chunk):
        if fast:
            A = weights[: min(chunk, N.shape[0] - s)]
            _coupled_weights_kernel(N[s : s + chunk], D, omega, float(side), coupling.enter, A)
            out[s : s + chunk] = A @ L
            continue
        cos = side * (N[s : s + chunk] @ D.T)
        out[s : s + chunk] = (coupling.lookup(cos) * np.maximum(cos, 0.0) * omega) @ L
    return out


#: Sample pairs per call of the rough lobe's estimator (:func:`polymer_oracle`): the rounds go a
#: band of pixels at a time, so their random numbers take at most 4 × 8 bytes × this (64 MiB) and
#: each call runs for a fraction of a second (an interrupt is heard between calls).
SPECULAR_CHUNK_SAMPLES = 1 << 21


class _Rounds(NamedTuple):
    """The Monte Carlo rounds of the specular lobe (:func:`polymer_oracle`'s keywords)."""

    tol: float
    samples: int
    max_samples: int
    seed: int
    backend: str


def _specular(N, V, radiance, n, alpha, scale, rounds: _Rounds):
    """The interface term, in rounds of doubling sample counts until ``tol`` or ``max_samples``."""
    tol, samples, max_samples, seed, backend = rounds
    P, nb = N.shape[0], radiance.shape[-1]
    if alpha <= 0.0:
        cos_o = np.clip(np.einsum("ij,ij->i", N, V), 0.0, 1.0)
        r = 2.0 * cos_o[:, None] * N - V
        spec = fresnel_dielectric(cos_o, n)[:, None] * latlong_lookup_bilinear(radiance, r)
        return spec, np.zeros((P, nb)), 0, 0.0
    rng = np.random.default_rng(seed)
    # visible normals and the map's own texels, by Veach's balance heuristic (erratum E117)
    call = rough_specular_samples_mis if backend == "numpy" else _rough_specular_mis_call
    sampling = environment_sampling(radiance)
    total, total_sq, M, batch = np.zeros((P, nb)), np.zeros((P, nb)), 0, int(samples)
    while True:
        # a band of pixels at a time (their random numbers drawn in the same order as for all
        # at once): the draws stay within SPECULAR_CHUNK_SAMPLES pairs and Ctrl-C is heard
        # between bands
        chunk = max(1, SPECULAR_CHUNK_SAMPLES // batch)
        for s in range(0, P, chunk):
            u = rng.random((min(chunk, P - s), batch, 4))
            t, t2 = call(N[s : s + chunk], V[s : s + chunk], radiance, alpha, n, u, sampling)
            total[s : s + chunk] += t
            total_sq[s : s + chunk] += t2
        M += batch
        mean = total / M
        se = np.sqrt(np.maximum(total_sq / M - mean**2, 0.0) / max(M - 1, 1))
        rel = float(
            np.percentile(se.mean(axis=1) / np.maximum(scale + mean.mean(axis=1), 1e-12), 99)
        )
        if rel <= tol or max_samples <= M:
            return mean, se, M, rel
        batch = min(M, max_samples - M)


def _inputs(normal, view, radiance):
    N = np.asarray(require_finite(normal, "polymer oracle: normal"), dtype=np.float64)
    V = np.asarray(require_finite(view, "polymer oracle: view"), dtype=np.float64)
    require(
        N.ndim == 2 and N.shape == V.shape and N.shape[1] == 3,
        f"polymer oracle: normal and view must be (P, 3), got {N.shape} and {V.shape}",
    )
    radiance = np.asarray(require_finite(radiance, "polymer oracle: radiance"), dtype=np.float64)
    check_latlong_shape(radiance.shape, "polymer oracle: radiance")
    return N, V, radiance


def oracle_diffuse(normal, view, radiance, K, S, d, n: float = 1.54, gloss: float = 1.0):
    """The oracle's body and transmission terms (no sampling: sums over the map's pixels).

    The slab's part of the physical counterpart of Eq. (1), Herbert et al.; it depends on the gloss
    only through the coupling of the front interface (E66), so a sweep over thickness and TiO2 can
    reuse one specular term (:func:`polymer_oracle` adds it).

    Parameters
    ----------
    normal, view, radiance, K, S, d, n, gloss
        As in :func:`polymer_oracle`.

    Returns
    -------
    body, transmission : ndarray, shape (P, n_bands)

    Examples
    --------
    A clear, lossless sheet under a uniform sky: what the front surface does not reflect
    (1 − F_0 = 0.955) is split between the body term (the two-flux slab's internal light is
    diffuse, so the back surface reflects it: E67) and transmission:

    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> body, trans = oracle_diffuse(up, up, np.ones((64, 128, 1)), [0.0], [0.0], 1.0)
    >>> print(body.round(3), trans.round(3), (body + trans).round(3))
    [[0.365]] [[0.59]] [[0.955]]
    """
    N, V, radiance = _inputs(normal, view, radiance)
    require(float(n) > 1.0, f"polymer oracle: n: refractive index must be > 1, got {n!r}")
    alpha = gloss_alpha(gloss)
    front, back = interface_coupling(float(n), alpha), interface_coupling(float(n), 0.0)
    K, S = (np.broadcast_to(np.asarray(a, float), radiance.shape[-1:]) for a in (K, S))
    rho_out, tau = body_factors(K, S, d, front.r_i, back.r_i)
    # the exit distribution: the flux leaving the front, (1 − E_ρ(θ_o)) / (π (1 − k_e)) per sr
    cos_o = np.einsum("ij,ij->i", N, V)
    exit_ = front.lookup(cos_o)[:, None] / (np.pi * (1.0 - front.k_e))
    body = exit_ * rho_out * coupled_irradiance(N, radiance, front, 1.0)
    transmission = exit_ * tau * coupled_irradiance(N, radiance, back, -1.0)
    return body, transmission


def polymer_oracle(
    normal,
    view,
    radiance,
    K,
    S,
    d: float,
    n: float = 1.54,
    gloss: float = 1.0,
    *,
    tol: float = 0.005,
    samples: int = 64,
    max_samples: int = 4096,
    seed: int = 0,
    backend: str = "numba",
) -> OracleResult:
    """Shade the layered polymer by brute force (physical counterpart of Eq. (1), Herbert et al.).

    Parameters
    ----------
    normal, view : array_like, shape (P, 3)
        Unit normals and unit vectors towards the eye.
    radiance : array_like, shape (H, W, n_bands)
        Spectral lat-long environment (W = 2H), >= 0.
    K, S : array_like, shape (n_bands,)
        Absorption and scattering of the slab, 1/mm (``shrm.polymer.kubelka_munk.polymer_K_S``).
    d : float
        Thickness, mm, >= 0.
    n : float
        Index of the polymer, > 1.
    gloss : float
        In [0, 1]; the interface's GGX width is :func:`gloss_alpha` (E65).
    tol : float
        Target for the specular lobe's Monte Carlo error: the rounds (doubling the samples) stop
        when, at 99 % of the pixels, the band-mean standard error is at most ``tol`` times the
        band-mean radiance, or at ``max_samples``.
    samples, max_samples : int
        First round and cap, samples per pixel.
    seed : int
        Seed of the generator (the same seed gives the same image).
    backend : {"numba", "numpy"}
        The specular loop (:data:`ORACLE_KERNELS`).

    Returns
    -------
    OracleResult

    Raises
    ------
    SpecrefError
        For bad shapes, negative K, S or d, an index <= 1, gloss outside [0, 1].

    Examples
    --------
    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> sky = np.ones((64, 128, 2))      # the white furnace, a white opaque base
    >>> out = polymer_oracle(up, up, sky, [0.0, 0.0], [1e6, 1e6], 1.0, 1.5)
    >>> out.result.round(3)
    array([[1., 1.]])
    """
    t0 = time.perf_counter()
    require(
        backend in ("numba", "numpy"), f"polymer oracle: backend: numba or numpy, got {backend!r}"
    )
    body, transmission = oracle_diffuse(normal, view, radiance, K, S, d, n, gloss)
    N, V, radiance = _inputs(normal, view, radiance)
    scale = (body + transmission).mean(axis=1)
    rounds = _Rounds(tol, samples, max_samples, seed, backend)
    spec, se, M, rel = _specular(N, V, radiance, float(n), gloss_alpha(gloss), scale, rounds)
    result = spec + body + transmission
    return OracleResult(spec, body, transmission, result, se, M, rel, time.perf_counter() - t0)
