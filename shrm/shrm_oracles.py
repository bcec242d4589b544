"""The oracles of SHRMs: brute-force angular creation and the per-pixel brute-force render.

Both evaluate the reflection equation (R&H 2002) by summing BRDF × environment over every pixel
of the lat-long environment, with the environment's own Fejér-1 × uniform-φ quadrature weights
(the weights :func:`shrm.transform.project_latlong` uses), so that they differ from the frequency
path of :mod:`shrm.shrm` only by the truncation of the SH series:

- :func:`shrm_texels_angular` and :func:`shrm_create_angular`: the SHRM texels, for a Fejér grid of
  views, projected onto ``Y_pq`` or fitted to the views above the texel's horizon, as
  :func:`shrm.brdf_sh.brdf_sh_coefficients` fits them (§5.5, Herbert et al., in angular space;
  the baseline of the creation-speed target);
- :func:`render_bruteforce`: every G-buffer pixel integrates BRDF × environment (the baseline of
  the image-error target).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
"""

from __future__ import annotations

import functools

import numpy as np

from reference.errors import require_choice
from shrm.brdf_sh import FRAMES, VIEW_FIT_RIDGE, default_view_fit
from shrm.sh import fejer1_weights, order_of, sh_basis
from shrm.shrm import SHRM
from shrm.transform import project_latlong

__all__ = [
    "env_quadrature",
    "reflected_bruteforce",
    "render_bruteforce",
    "shrm_create_angular",
    "shrm_texels_angular",
]


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def env_quadrature(image):
    """Pixel directions, Fejér-1 × uniform-φ weights and radiance of a lat-long map.

    The quadrature of :func:`shrm.transform.project_latlong` (Fejér's first rule in θ).

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)

    Returns
    -------
    directions : ndarray, shape (H·2H, 3)
    weights : ndarray, shape (H·2H,)
        Solid-angle weights, sr (they sum to 4π).
    radiance : ndarray, shape (H·2H, C)

    Examples
    --------
    >>> d, w, L = env_quadrature(np.ones((4, 8, 1)))
    >>> d.shape, round(float(w.sum() / np.pi), 12), L.shape
    ((32, 3), 4.0, (32, 1))
    """
    from reference.geometry.envmap import latlong_pixel_directions

    H, W = image.shape[:2]
    d = latlong_pixel_directions(H, W).reshape(-1, 3)
    w = np.repeat(fejer1_weights(H), W) * (2.0 * np.pi / W)
    return d, w, np.asarray(image, dtype=np.float64).reshape(H * W, -1)


def reflected_bruteforce(
    brdf, params, frame, index, views, env, view_power: float = 0.0, chunk: int = 4096
):
    """``∫ L(ω) ρ̃ dω`` by the sum over environment pixels, for pairs (index direction, view).

    The reflection equation (R&H 2002) with the transfer function of
    :func:`shrm.brdf_sh.transfer_function` (views below the horizon mirrored in the normal frame),
    times ``cos^k θ_o`` when ``view_power`` k > 0 (the quantity a SHRM stores).

    Parameters
    ----------
    brdf, params
        The BRDF (``BRDF_METHODS`` convention) and its parameters.
    frame : {"normal", "reflection"}
    index, views : ndarray, shape (N, 3)
        Index directions (normal or reflection vector) and views, unit.
    env : tuple
        :func:`env_quadrature` of the environment.
    view_power : float
        k >= 0.
    chunk : int
        Environment pixels per BRDF call.

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> y = np.array([[0.0, 1.0, 0.0]])
    >>> env = env_quadrature(np.ones((16, 32, 1)))
    >>> reflected_bruteforce(brdf_lambert, {"rho_d": [1.0]}, "normal", y, y, env).round(3)
    array([[1.]])
    """
    require_choice(frame, FRAMES, "SHRM frame")
    d, w, Lpx = env
    out = np.zeros((index.shape[0], Lpx.shape[1]))
    for a in range(index.shape[0]):
        n, v = index[a], views[a]
        if frame == "normal":
            normal = n
            # Views below the horizon are mirrored above it (shrm.brdf_sh.transfer_function)
            v = v if _dot(v, n) >= 0 else v - 2.0 * _dot(v, n) * n
        else:
            h = n + v
            normal = h / max(np.linalg.norm(h), 1e-300)
        factor = max(float(_dot(v, normal)), 0.0) ** view_power if view_power else 1.0
        for s in range(0, d.shape[0], chunk):
            wi = d[s : s + chunk]
            cosine = np.maximum(wi @ normal, 0.0)
            f = brdf(wi, np.broadcast_to(v, wi.shape), normal, **params)
            # The reflection equation (R&H 2002): Σ_pixels L(ω) f cos θ_i w
            out[a] += (f * (Lpx[s : s + chunk] * (cosine * w[s : s + chunk])[:, None])).sum(0)
        out[a] *= factor
    return out


def shrm_texels_angular(
    image,
    brdf,
    params: dict,
    P: int,
    directions,
    frame: str = "reflection",
    view_power=0.0,
    view_fit: str | None = None,
) -> np.ndarray:
    """SHRM coefficients ``B_pq`` at given texel directions, by brute-force angular integration.

    The reflection equation (R&H 2002) at every texel n and every view v of a Fejér-1 grid of
    ``2P + 2`` rows, ``B(n, v) = Σ_pixels L(ω) ρ̃ w``, then ``B_pq(n) = ∫ B(n, v) Y_pq(v) dv``
    (``shrm.transform.project_latlong``) for ``view_fit="sphere"``, or for ``"hemisphere"`` the
    fit of :mod:`shrm.brdf_sh` in world axes: ``min Σ_v w_v (n·v)^{−2k} |B − Σ B_pq Y_pq(v)|² +
    μ Σ (B_pq − B^sphere_pq)²`` over the grid's views above the texel's horizon (``w_v`` the
    grid's weights, ``B^sphere`` the projection with views below the horizon mirrored). The cost
    is texels × views × environment pixels, the same for every texel, so a few texels give the
    per-texel time of the angular path.

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)
        Linear radiance of the environment.
    brdf, params
        The BRDF.
    P : int
        View order.
    directions : array_like, shape (N, 3)
        Texel directions (unit).
    frame : {"normal", "reflection"}
    view_power : float
        The grazing view power k of the SHRM (:func:`shrm.brdf_sh.shrm_brdf_parts`).
    view_fit : {"sphere", "hemisphere"}, optional
        Default and check: :func:`shrm.brdf_sh.default_view_fit`.

    Returns
    -------
    ndarray, shape (N, C, (P+1)²)

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> B = shrm_texels_angular(np.ones((4, 8, 1)), brdf_lambert, {"rho_d": [1.0]}, 2,
    ...                         [[0.0, 0.0, 1.0]], "normal")
    >>> B.shape, round(float(B[0, 0, 0] * np.sqrt(1 / (4 * np.pi))), 6)   # B_00 Y_00 = ρ_d
    ((1, 1, 9), 1.0)
    >>> B = shrm_texels_angular(np.ones((4, 8, 1)), brdf_lambert, {"rho_d": [1.0]}, 2,
    ...                         [[0.0, 0.0, 1.0]], "normal", view_fit="hemisphere")
    >>> round(float(B[0, 0, 0] * np.sqrt(1 / (4 * np.pi))), 6)
    1.0
    """
    from reference.geometry.envmap import latlong_pixel_directions

    view_fit = default_view_fit(frame, view_fit)
    env = env_quadrature(image)
    Hv = 2 * P + 2
    views = latlong_pixel_directions(Hv, 2 * Hv).reshape(-1, 3)
    texels = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    C = env[2].shape[1]
    out = np.empty((texels.shape[0], C, (P + 1) ** 2))
    if view_fit == "hemisphere":
        Y = sh_basis(P, views)
        w_v = np.repeat(fejer1_weights(Hv), 2 * Hv) * (2.0 * np.pi / (2 * Hv))
    reflected = functools.partial(
        reflected_bruteforce, brdf, params, frame, env=env, view_power=view_power
    )
    for t, n in enumerate(texels):
        if view_fit == "sphere":
            B = reflected(np.broadcast_to(n, views.shape), views)
            # B_pq(n) = ∫ B(n, v) Y_pq(v) dv on the Fejér-1 grid of views
            out[t] = project_latlong(B.reshape(Hv, 2 * Hv, C), P, where="SHRM oracle")
        else:
            out[t] = _texel_hemisphere_fit(reflected, n, views, Y, w_v, view_power)
    return out


def _texel_hemisphere_fit(reflected, n, views, Y, w_v, view_power: float) -> np.ndarray:
    """One texel's ``B_pq`` (C, (P+1)²) by the hemisphere fit of :mod:`shrm.brdf_sh`.

    ``reflected(index, views)`` is :func:`reflected_bruteforce` with the BRDF and environment
    bound; ``Y`` and ``w_v`` are ``Y_pq`` and the weights of the Fejér-1 grid of ``views``.
    """
    P = order_of(Y.shape[1])
    # The hemisphere fit (shrm.brdf_sh): weighted least squares over the seen views, plus
    # μ |B − B_sphere|², B_sphere the projection of the even continuation (views mirrored)
    x = views @ n
    seen = x > 0.0
    v = views[seen]
    B = reflected(np.broadcast_to(n, v.shape), v)
    mirrored = sh_basis(P, v - 2.0 * x[seen, None] * n)
    prior = ((Y[seen] + mirrored).T * w_v[seen]) @ B
    w = w_v[seen] * x[seen] ** (-2.0 * view_power)
    G = (Y[seen].T * w) @ Y[seen] + VIEW_FIT_RIDGE * np.eye(Y.shape[1])
    return np.linalg.solve(G, (Y[seen].T * w) @ B + VIEW_FIT_RIDGE * prior).T


def shrm_create_angular(
    image,
    brdf,
    params: dict,
    P: int,
    frame: str = "reflection",
    size=8,
    view_power=0.0,
    view_fit: str | None = None,
) -> SHRM:
    """The oracle: every texel of a cube-map SHRM by :func:`shrm_texels_angular`.

    §5.5, Herbert et al., in angular space; the reflection equation (R&H 2002) per texel and view.

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)
    brdf, params
        The BRDF.
    P : int
    frame : {"normal", "reflection"}
    size : int
        Cube face size (keep it small: the cost is texels × views × pixels).
    view_power : float
    view_fit : {"sphere", "hemisphere"}, optional
        Default and check: :func:`shrm.brdf_sh.default_view_fit`.

    Returns
    -------
    SHRM
        With ``F = -1`` (no lighting truncation).

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> from shrm.shrm import shrm_extract
    >>> s = shrm_create_angular(np.ones((4, 8, 1)), brdf_lambert, {"rho_d": [1.0]}, 2, "normal", 1)
    >>> float(shrm_extract(s, [0.0, 0.0, 1.0])[4, 0, 0, 0]).__round__(6)   # facing +z: ρ_d
    1.0
    """
    from reference.geometry.cubemap import cubemap_texel_directions

    texels = cubemap_texel_directions(size).reshape(-1, 3)
    out = shrm_texels_angular(image, brdf, params, P, texels, frame, view_power, view_fit)
    C = out.shape[1]
    return SHRM(out.reshape(6, size, size, C, (P + 1) ** 2), frame, -1, P, float(view_power))


def render_bruteforce(gbuffer, image, brdf, params: dict, view, material_id: int = 0):
    """The per-pixel oracle: every pixel integrates BRDF × environment over all map pixels.

    The reflection equation (R&H 2002), with a distant viewer ``v`` and the environment's
    Fejér-1 × uniform-φ quadrature.

    Parameters
    ----------
    gbuffer : reference.geometry.gbuffer.GBuffer
    image : ndarray, shape (H, 2H, C)
        Environment radiance.
    brdf, params
        The BRDF.
    view : array_like, shape (3,)
        Direction towards the viewer.
    material_id : int

    Returns
    -------
    ndarray, shape (H_img, W_img, C)

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> from reference.geometry.gbuffer import empty_gbuffer
    >>> g = empty_gbuffer(1, 1)
    >>> g.mask[0, 0] = True; g.material_id[0, 0] = 0; g.normal[0, 0] = [0.0, 0.0, 1.0]
    >>> render_bruteforce(g, np.ones((8, 16, 1)), brdf_lambert, {"rho_d": [0.5]},
    ...                   [0.0, 0.0, 1.0]).round(4)
    array([[[0.5]]])
    """
    v = np.asarray(view, dtype=np.float64)
    v = v / np.linalg.norm(v)
    env = env_quadrature(image)
    H, W = gbuffer.shape
    out = np.zeros((H, W, env[2].shape[1]))
    sel = gbuffer.mask & (gbuffer.material_id == material_id)
    normals = gbuffer.normal[sel]
    out[sel] = reflected_bruteforce(
        brdf, params, "normal", normals, np.broadcast_to(v, normals.shape), env
    )
    return out
