"""An importance-sampled Monte Carlo estimator of environment reflection, for comparison.

Not Herbert et al.'s method: the speed–accuracy study of the report (section "SHRMs on
full-resolution maps") sets the SHRM and the SH + angular split beside the estimator a
path tracer would use at the same time per frame. :func:`environment_mc` estimates exactly the
sum that the brute-force oracle :func:`shrm.split.angular_sum` computes over every texel of a
map: ``S = Σ_k f(ω_k, v, n) max(n·ω_k, 0) L_k w_k``. It draws M texels per point with
probabilities ``q_k ∝ Y(L_k) w_k`` (the map's power, luminance by Rec. 709 weights, the
standard environment-light sampler of pbrt-v4 and Mitsuba 3 on the map's own quadrature),
stratified (one uniform number in each of M equal slices of the cumulative distribution, a
fresh shift per point), and returns ``(1/M) Σ_j g_{k_j}/q_{k_j}``, which is unbiased for ``S``
(erratum E58: why environment sampling alone).

References
----------
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed., §12.5 (image
  infinite lights: sampling by a piecewise-constant distribution).
"""

from __future__ import annotations

import numpy as np

from reference.errors import require, require_positive_int

__all__ = ["environment_mc", "environment_sampling_probabilities"]

#: Rec. 709 luminance weights: the power that the sampler follows (any positive weights would keep
#: the estimator unbiased; these make it follow what the eye sees).
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def environment_sampling_probabilities(weights, radiance) -> np.ndarray:
    """``q_k ∝ Y(L_k) w_k``: the probability of drawing texel k, shape (K,), summing to 1.

    Three channels are weighted by Rec. 709 luminance; any other channel count by the mean.
    Texels without power are never drawn (their terms are zero in the sum only if their radiance
    is zero in every channel: ``Y`` of a non-negative map is zero only then).

    Examples
    --------
    >>> q = environment_sampling_probabilities(np.array([1.0, 1.0, 2.0]),
    ...                                        np.array([[1.0], [0.0], [1.0]]))
    >>> q.round(3)
    array([0.333, 0.   , 0.667])
    """
    L = np.asarray(radiance, dtype=np.float64)
    Y = L @ LUMINANCE if L.shape[1] == 3 else L.mean(axis=1)
    power = np.maximum(Y, 0.0) * np.asarray(weights, dtype=np.float64)
    total = power.sum()
    require(total > 0, "environment_mc: the environment has no power")
    return power / total


def environment_mc(
    env, brdf, params: dict, normals, views, n_samples: int, seed: int = 0
) -> np.ndarray:
    """Importance-sampled Monte Carlo estimate of ``Σ_k f max(n·ω_k, 0) L_k w_k`` per point.

    Parameters
    ----------
    env : tuple
        ``(directions (K, 3), weights (K,) in sr, radiance (K, C))``, as for
        :func:`shrm.split.angular_sum` (:func:`shrm.shrm_oracles.env_quadrature`).
    brdf : callable
        ``brdf(wi, wo, normal, **params) -> (..., C)`` (``BRDF_METHODS`` convention).
    params : dict
    normals, views : ndarray, shape (N, 3)
        Unit normals and unit directions towards the viewer.
    n_samples : int
        M, texels drawn per point.
    seed : int
        Seeds NumPy's generator (the estimate is deterministic).

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    A white furnace: every estimate of a Lambertian surface under a constant sky is its albedo
    (the sampler follows the weights, and the integrand is the cosine).

    >>> from reference.materials.brdf import brdf_lambert
    >>> from shrm.shrm_oracles import env_quadrature
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> sky = env_quadrature(np.ones((32, 64, 1)))
    >>> float(environment_mc(sky, brdf_lambert, {"rho_d": [1.0]}, n, n, 4096)[0, 0]).__round__(2)
    1.0
    """
    d, w, L = (np.asarray(x, dtype=np.float64) for x in env)
    M = require_positive_int(n_samples, "environment_mc: n_samples", 1 << 24)
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    views = np.broadcast_to(np.asarray(views, dtype=np.float64), normals.shape)
    q = environment_sampling_probabilities(w, L)
    cdf = np.cumsum(q)
    cdf[-1] = 1.0
    rng = np.random.default_rng(seed)
    out = np.zeros((normals.shape[0], L.shape[1]))
    # points per block: about 2²² BRDF values at a time
    step = max(1, (1 << 22) // (M * L.shape[1]))
    for p in range(0, normals.shape[0], step):
        n, v = normals[p : p + step, None, :], views[p : p + step, None, :]
        # stratified: one uniform number in each slice [j/M, (j+1)/M) of the distribution
        u = (np.arange(M) + rng.random((n.shape[0], M))) / M
        k = np.minimum(np.searchsorted(cdf, u, side="right"), q.size - 1)
        wi = d[k]
        cosine = np.maximum((wi * n).sum(-1), 0.0)
        f = brdf(*np.broadcast_arrays(wi, v, n), **params)
        # (1/M) Σ_j f cos θ_i L_k w_k / q_k
        out[p : p + step] = np.einsum("pm,pmc,pmc->pc", cosine * (w[k] / q[k]), f, L[k]) / M
    return out
