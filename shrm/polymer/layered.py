"""The layered polymer from prefiltered maps: a real-time model beyond Herbert et al.'s hybrid.

The hybrid of ``shrm.polymer.hybrid`` (Eqs. (1)-(5), Herbert et al.) sums a Lambert map and a
Phong map weighted by the chip's measured reflectance and a mirror factor. The layered oracle
(``shrm.polymer.oracle``) shades the material that hybrid imitates by brute force: a dielectric
interface (rough when gloss < 1) over a Kubelka–Munk slab. This module evaluates the oracle's own
three terms from maps prefiltered once per environment, index and gloss, with the oracle's tables:

- **body**: ``exit(θ_o) ρ_out E_f(n)``, where ``E_f(n) = ∫ (1 − E_ρ(θ_i)) cos θ_i L dω`` is the
  irradiance through the front interface's coupling. Its kernel ``(1 − E_ρ(cos γ)) cos γ`` is
  radially symmetric about the normal, so ``E_f`` is a prefiltered map (Eq. (7), Ramamoorthi &
  Hanrahan 2001, as for Herbert's Lambert map) and the term is the oracle's, to the map's
  truncation and interpolation;
- **transmission**: ``exit(θ_o) τ E_b(−n)`` with the smooth back surface's kernel
  ``(1 − F(cos γ)) cos γ``, the same way;
- **specular**: smooth interface: ``F(θ_o) L(r)``, the oracle's mirror look-up. Rough: the split
  sum of Karis 2013, ``E_ρ(θ_o) L_α(r)``: the interface's directional albedo (the oracle's table)
  times the environment prefiltered by the GGX lobe about the mirror direction ``r``, which
  assumes ``n = v = r`` for the lobe's shape (its only approximation; erratum E108).

``exit(θ_o) = (1 − E_ρ(θ_o)) / (π (1 − k_e))`` and the slab's ``ρ_out`` and ``τ`` are the
oracle's (:func:`shrm.polymer.oracle.body_factors`). Thickness and TiO2 (the slab) change only
``ρ_out`` and ``τ``: a dynamic change re-shades from the per-pixel parts
(:func:`layered_pixel_parts`, :func:`layered_shade_parts`) without prefiltering again; the gloss
and the index choose the maps.

References
----------
Karis, B. (2013). Real shading in Unreal Engine 4. SIGGRAPH course notes (the split sum).
Ramamoorthi, R., Hanrahan, P. (2001). An efficient representation for irradiance environment
    maps. SIGGRAPH 2001.
Walter, B., Marschner, S., Li, H., Torrance, K. (2007). Microfacet models for refraction through
    rough surfaces. EGSR 2007.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_finite
from reference.geometry.envmap import (
    check_latlong_shape,
    latlong_lookup_bilinear,
    latlong_pixel_directions,
    latlong_pixel_solid_angles,
)
from reference.materials.fresnel import fresnel_dielectric
from reference.registry import Method, Registry
from shrm.polymer.oracle import (
    Coupling,
    body_factors,
    coupled_irradiance,
    gloss_alpha,
    interface_coupling,
)

__all__ = [
    "LAYERED_KERNELS",
    "PREFILTER_MAX_ROWS",
    "LayeredMaps",
    "coupled_irradiance_latlong",
    "ggx_prefiltered_latlong",
    "layered_maps",
    "layered_pixel_parts",
    "layered_reshade_XYZ",
    "layered_shade_parts",
    "layered_terms",
]

#: Rows of the map the prefilters sum over: larger maps are box-filtered to this first, which
#: bounds their cost to (64 · 128)² weights per map (erratum E108).
PREFILTER_MAX_ROWS = 64


def _box_rows(radiance: np.ndarray, rows: int) -> np.ndarray:
    """The map box-filtered to ``rows`` rows and ``2 rows`` columns, solid-angle weighted.

    Output texel k averages the source rows (columns) from ``⌊k H / rows⌋`` up to the next
    texel's start, so any height works; blocks are equal when ``rows`` divides it.
    """
    H, W = radiance.shape[:2]
    starts_y = (np.arange(rows) * H) // rows
    starts_x = (np.arange(2 * rows) * W) // (2 * rows)
    omega = latlong_pixel_solid_angles(H, W)[..., None]

    def blocks(a):
        return np.add.reduceat(np.add.reduceat(a, starts_y, axis=0), starts_x, axis=1)

    return blocks(radiance * omega) / blocks(omega)


def _radial_sum(radiance, weight, chunk: int = 512) -> np.ndarray:
    """``Σ_ω w(d·ω) L(ω) Ω(ω) / Σ_ω w(d·ω) Ω(ω)`` at every pixel direction d of the map.

    The map is box-filtered to :data:`PREFILTER_MAX_ROWS` rows first when taller.
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    if radiance.shape[0] > PREFILTER_MAX_ROWS:
        radiance = _box_rows(radiance, PREFILTER_MAX_ROWS)
    H, W, B = radiance.shape
    D = latlong_pixel_directions(H, W).reshape(-1, 3)
    omega = latlong_pixel_solid_angles(H, W).ravel()
    L = radiance.reshape(-1, B)
    out = np.empty((H * W, B))
    for s in range(0, H * W, chunk):
        w = weight(np.clip(D[s : s + chunk] @ D.T, -1.0, 1.0)) * omega
        out[s : s + chunk] = (w @ L) / w.sum(axis=1, keepdims=True)
    return out.reshape(H, W, B)


def coupled_irradiance_latlong(radiance, coupling: Coupling) -> np.ndarray:
    """``E(d) = ∫ (1 − E_ρ(cos γ)) max(cos γ, 0) L(ω) dω`` at every pixel direction d.

    The irradiance that enters the slab through an interface (the oracle's body and transmission
    integrals, the physical counterpart of Eq. (1), Herbert et al.), summed over the map's pixels
    as the oracle sums them, once per direction of a lat-long grid rather than once per shaded
    pixel. Maps above :data:`PREFILTER_MAX_ROWS` rows are box-filtered to them first.

    Parameters
    ----------
    radiance : array_like, shape (H, W, n_bands)
        Lat-long environment (W = 2H).
    coupling : Coupling
        The interface (``interface_coupling``): ``1 − E_ρ`` by its table.

    Returns
    -------
    ndarray, shape (H', W', n_bands)

    Examples
    --------
    Under a uniform sky, ``π (1 − k_e)`` everywhere:

    >>> c = interface_coupling(1.5, 0.0)
    >>> E = coupled_irradiance_latlong(np.ones((16, 32, 1)), c)
    >>> bool(np.allclose(E, np.pi * (1 - c.k_e), rtol=2e-3))
    True
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    if radiance.shape[0] > PREFILTER_MAX_ROWS:
        radiance = _box_rows(radiance, PREFILTER_MAX_ROWS)
    H, W, B = radiance.shape
    # the oracle's own sum (coupled_irradiance) with the map's pixel directions as the normals
    D = latlong_pixel_directions(H, W).reshape(-1, 3)
    return coupled_irradiance(D, radiance, coupling, 1.0).reshape(H, W, B)


def ggx_prefiltered_latlong(radiance, alpha: float) -> np.ndarray:
    """The environment prefiltered by the GGX lobe about each direction (Karis 2013).

    The split sum's first factor: ``L_α(r) = Σ w(ω) L(ω) / Σ w(ω)`` over the map's pixels, with
    ``w = D(h) / 4 · max(ω·r, 0) · Ω``, the GGX distribution (Eq. (33), Walter et al. 2007) of the
    half vector ``h`` between ``r`` and ``ω`` for ``n = v = r``, weighted by the cosine as Karis
    does. Normalized, so a uniform environment stays uniform. Maps above
    :data:`PREFILTER_MAX_ROWS` rows are box-filtered to them first.

    Parameters
    ----------
    radiance : array_like, shape (H, W, n_bands)
        Lat-long environment (W = 2H).
    alpha : float
        GGX width, > 0.

    Returns
    -------
    ndarray, shape (H', W', n_bands)
        On the lat-long grid of the (box-filtered) map.

    Examples
    --------
    >>> bool(np.allclose(ggx_prefiltered_latlong(np.ones((8, 16, 2)), 0.3), 1.0))
    True
    """
    require(float(alpha) > 0.0, f"GGX prefilter: alpha must be > 0, got {alpha!r}")
    a2 = float(alpha) ** 2

    def weight(cos_gamma):
        # cos² θ_h of the half vector between r and ω; D(h) = α² / (π (cos² θ_h (α² − 1) + 1)²)
        cos2_h = 0.5 * (1.0 + cos_gamma)
        D_h = a2 / (np.pi * (cos2_h * (a2 - 1.0) + 1.0) ** 2)
        return 0.25 * D_h * np.maximum(cos_gamma, 0.0)

    return _radial_sum(radiance, weight)


@dataclass(frozen=True)
class LayeredMaps:
    """The layered model's inputs for one environment, index and gloss (:func:`layered_maps`).

    Parameters
    ----------
    radiance : ndarray, shape (H, W, n_bands)
        The environment (the mirror look-up of a smooth interface).
    E_front, E_back : ndarray, shape (H_e, W_e, n_bands)
        Irradiance through the front coupling and through the smooth back surface, lat-long.
    specular : ndarray or None, shape (H_s, W_s, n_bands)
        The GGX-prefiltered environment (None for a smooth interface).
    n, gloss, alpha : float
        Index, gloss and the interface's GGX width.
    """

    radiance: np.ndarray
    E_front: np.ndarray
    E_back: np.ndarray
    specular: np.ndarray | None
    n: float
    gloss: float
    alpha: float


def layered_maps(radiance, n: float = 1.54, gloss: float = 1.0) -> LayeredMaps:
    """Prefilter an environment for the layered model (once per map, index and gloss).

    Parameters
    ----------
    radiance : array_like, shape (H, W, n_bands)
        Spectral lat-long environment (W = 2H), >= 0.
    n : float
        Index of the polymer, > 1.
    gloss : float
        In [0, 1] (``gloss_alpha``, erratum E65).

    Returns
    -------
    LayeredMaps

    Examples
    --------
    >>> maps = layered_maps(np.ones((16, 32, 2)), 1.5, 0.8)
    >>> maps.E_front.shape, maps.specular.shape, round(maps.alpha, 3)
    ((16, 32, 2), (16, 32, 2), 0.1)
    """
    radiance = np.asarray(require_finite(radiance, "layered polymer: radiance"), dtype=np.float64)
    check_latlong_shape(radiance.shape, "layered polymer: radiance")
    require((radiance >= 0).all(), "layered polymer: radiance must be >= 0")
    require(float(n) > 1.0, f"layered polymer: n: refractive index must be > 1, got {n!r}")
    alpha = gloss_alpha(gloss)
    front, back = interface_coupling(float(n), alpha), interface_coupling(float(n), 0.0)
    return LayeredMaps(
        radiance,
        coupled_irradiance_latlong(radiance, front),
        coupled_irradiance_latlong(radiance, back),
        ggx_prefiltered_latlong(radiance, alpha) if alpha > 0.0 else None,
        float(n),
        float(gloss),
        alpha,
    )


def layered_pixel_parts(normal, view, maps: LayeredMaps) -> dict:
    """The per-pixel parts that do not depend on the slab: what a dynamic change re-uses.

    Parameters
    ----------
    normal, view : array_like, shape (P, 3)
        Unit normals and unit vectors towards the eye.
    maps : LayeredMaps

    Returns
    -------
    dict
        ``specular`` (P, n_bands), the interface term; ``front`` and ``back`` (P, n_bands),
        ``exit(θ_o) E_f(n)`` and ``exit(θ_o) E_b(−n)``.

    Examples
    --------
    >>> up = np.array([[0.0, 0.0, 1.0]])
    >>> parts = layered_pixel_parts(up, up, layered_maps(np.ones((16, 32, 1)), 1.5, 1.0))
    >>> float(parts["specular"][0, 0]).__round__(4)                # F_0 under L = 1
    0.04
    """
    N = np.asarray(require_finite(normal, "layered polymer: normal"), dtype=np.float64)
    V = np.asarray(require_finite(view, "layered polymer: view"), dtype=np.float64)
    require(
        N.ndim == 2 and N.shape == V.shape and N.shape[1] == 3,
        f"layered polymer: normal and view must be (P, 3), got {N.shape} and {V.shape}",
    )
    front = interface_coupling(maps.n, maps.alpha)
    cos_o = np.clip(np.einsum("ij,ij->i", N, V), 0.0, 1.0)
    # exit(θ_o) = (1 − E_ρ(θ_o)) / (π (1 − k_e)), the oracle's exit distribution
    exit_ = (front.lookup(cos_o) / (np.pi * (1.0 - front.k_e)))[:, None]
    r = 2.0 * cos_o[:, None] * N - V
    if maps.specular is None:
        # smooth: F(θ_o) L(r), the oracle's own term
        specular = fresnel_dielectric(cos_o, maps.n)[:, None] * latlong_lookup_bilinear(
            maps.radiance, r
        )
    else:
        # Karis 2013's split sum: E_ρ(θ_o) L_α(r), with E_ρ = 1 − the oracle's coupling table
        E_rho = 1.0 - front.lookup(np.maximum(cos_o, 1e-6))
        specular = E_rho[:, None] * latlong_lookup_bilinear(maps.specular, r)
    return {
        "specular": specular,
        "front": exit_ * latlong_lookup_bilinear(maps.E_front, N),
        "back": exit_ * latlong_lookup_bilinear(maps.E_back, -N),
    }


def _slab_factors(K, S, d: float, maps: LayeredMaps, n_bands: int):
    """The slab's ``ρ_out`` and ``τ`` between the maps' front interface and a smooth back."""
    front = interface_coupling(maps.n, maps.alpha)
    back = interface_coupling(maps.n, 0.0)
    K, S = (np.broadcast_to(np.asarray(a, dtype=np.float64), (n_bands,)) for a in (K, S))
    return body_factors(K, S, d, front.r_i, back.r_i)


def layered_shade_parts(parts: dict, K, S, d: float, maps: LayeredMaps) -> dict:
    """The layered model's terms from per-pixel parts and the slab (the re-shade).

    Parameters
    ----------
    parts : dict
        From :func:`layered_pixel_parts`.
    K, S : array_like, shape (n_bands,)
        Absorption and scattering of the slab, 1/mm.
    d : float
        Thickness, mm, >= 0.
    maps : LayeredMaps
        The maps the parts were looked up in (for the interface's index and gloss).

    Returns
    -------
    dict
        ``specular``, ``body``, ``transmission`` and ``result``, each (P, n_bands).

    Examples
    --------
    >>> up = np.array([[0.0, 0.0, 1.0]])
    >>> maps = layered_maps(np.ones((32, 64, 1)), 1.5, 1.0)
    >>> out = layered_shade_parts(layered_pixel_parts(up, up, maps), [0.0], [1e6], 1.0, maps)
    >>> float(out["result"][0, 0]).__round__(3)       # white furnace, white opaque base
    1.0
    """
    rho_out, tau = _slab_factors(K, S, d, maps, parts["front"].shape[1])
    body = rho_out * parts["front"]
    transmission = tau * parts["back"]
    result = parts["specular"] + body + transmission
    return {
        "specular": parts["specular"],
        "body": body,
        "transmission": transmission,
        "result": result,
    }


def layered_reshade_XYZ(parts: dict, K, S, d: float, maps: LayeredMaps, weights, compiled=False):
    """XYZ (or any channels) of the layered model from its pixel parts: the re-shade of a frame.

    The layered counterpart of Eq. (1), Herbert et al., re-shaded:
    ``(specular + ρ_out front + τ back) @ W``, :func:`layered_shade_parts`'s result in the band
    weights ``W``, the one thing a frame needs after a change of thickness or TiO2. With
    ``compiled`` the numba twin fuses the terms and the weights in one pass
    (``shrm.polymer._kernels.layered_reshade_kernel``, :data:`LAYERED_KERNELS`).

    Parameters
    ----------
    parts : dict
        From :func:`layered_pixel_parts`, each (P, n_bands).
    K, S, d
        The slab, as in :func:`layered_shade_parts`.
    maps : LayeredMaps
    weights : array_like, shape (n_bands, C)
        Band weights (``reference.colour.colorimetry.band_weights``).
    compiled : bool
        The numba twin.

    Returns
    -------
    ndarray, shape (P, C)

    Examples
    --------
    >>> up = np.array([[0.0, 0.0, 1.0]])
    >>> maps = layered_maps(np.ones((32, 64, 2)), 1.5, 1.0)
    >>> parts = layered_pixel_parts(up, up, maps)
    >>> W = np.array([[0.5], [0.5]])
    >>> layered_reshade_XYZ(parts, [0.0, 0.0], [1e9, 1e9], 1.0, maps, W).round(3)
    array([[1.]])
    """
    rho_out, tau = _slab_factors(K, S, d, maps, parts["front"].shape[1])
    W = np.asarray(weights, dtype=np.float64)
    if compiled:
        from shrm.polymer._kernels import layered_reshade_kernel

        out = np.empty((parts["front"].shape[0], W.shape[1]))
        layered_reshade_kernel(
            *(
                np.ascontiguousarray(parts[k], dtype=np.float64)
                for k in ("specular", "front", "back")
            ),
            np.ascontiguousarray(rho_out, dtype=np.float64),
            np.ascontiguousarray(tau, dtype=np.float64),
            np.ascontiguousarray(W),
            out,
        )
        return out
    # the slab's factors on the cached parts: specular + ρ_out front + τ back, then the weights
    return (parts["specular"] + rho_out * parts["front"] + tau * parts["back"]) @ W


def _reshade_example(rng):
    parts = {k: rng.uniform(0, 2, (9, 16)) for k in ("specular", "front", "back")}
    maps = layered_maps(np.ones((8, 16, 16)), 1.54, 0.7)
    K, S = rng.uniform(0, 0.5, 16), rng.uniform(1, 50, 16)
    return parts, K, S, 1.3, maps, rng.uniform(0, 1, (16, 3))


def _register():
    from shrm.polymer._kernels import layered_reshade_kernel

    LAYERED_KERNELS.register(
        Method(
            "reshade",
            layered_reshade_XYZ,
            layered_reshade_kernel,
            "Eq. (1), Herbert et al. (its layered counterpart)",
            _reshade_example,
            compiled=lambda *args: layered_reshade_XYZ(*args, compiled=True),
        )
    )


#: The layered model's re-shade and its numba twin (tests check the pair).
LAYERED_KERNELS = Registry("layered polymer kernel")
_register()


def layered_terms(normal, view, maps: LayeredMaps, K, S, d: float) -> dict:
    """Shade the layered polymer from prefiltered maps (module docstring).

    Parameters
    ----------
    normal, view : array_like, shape (P, 3)
        Unit normals and unit vectors towards the eye.
    maps : LayeredMaps
        From :func:`layered_maps`.
    K, S : array_like, shape (n_bands,)
        Absorption and scattering of the slab, 1/mm (``polymer_K_S``).
    d : float
        Thickness, mm, >= 0.

    Returns
    -------
    dict
        ``specular``, ``body``, ``transmission`` and ``result``, each (P, n_bands): the terms of
        ``polymer_oracle``'s result.

    Examples
    --------
    A clear lossless sheet under a uniform sky (the oracle gives 0.365 and 0.59):

    >>> up = np.array([[0.0, 1.0, 0.0]])
    >>> maps = layered_maps(np.ones((32, 64, 1)), 1.54, 1.0)
    >>> out = layered_terms(up, up, maps, [0.0], [0.0], 1.0)
    >>> print(out["body"].round(3), out["transmission"].round(3))
    [[0.365]] [[0.59]]
    """
    return layered_shade_parts(layered_pixel_parts(normal, view, maps), K, S, d, maps)
