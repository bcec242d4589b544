"""numba twins of ``reference.horizon``: same names, same equations, no validation."""

from __future__ import annotations

import math

import numba


@numba.njit(cache=False)
def _sample_periodic(h, y, x):
    """Bilinear height at fractional pixel coordinates (periodic)."""
    H, W = h.shape
    xf, yf = math.floor(x), math.floor(y)
    fx, fy = x - xf, y - yf
    x0, y0 = int(xf) % W, int(yf) % H
    x1, y1 = (x0 + 1) % W, (y0 + 1) % H
    top = h[y0, x0] * (1.0 - fx) + h[y0, x1] * fx
    bottom = h[y1, x0] * (1.0 - fx) + h[y1, x1] * fx
    return top * (1.0 - fy) + bottom * fy


@numba.njit(cache=False)
def _horizon_along(h, pixel_size, j, i, phi, max_steps):
    dx, dy = math.cos(phi), math.sin(phi)
    best = 0.0
    for t in range(1, max_steps + 1):
        rise = _sample_periodic(h, j + t * dy, i + t * dx) - h[j, i]
        # Sloan & Cohen 2000: the horizon is the largest elevation angle seen along the ray
        best = max(best, rise / (t * pixel_size))
    return math.atan(best)


@numba.njit(cache=False)
def horizon_map_kernel(h, pixel_size, n_sectors, max_steps, out):
    """Twin of ``horizon_map``: each sector marched along its centre azimuth."""
    H, W = h.shape
    for s in range(n_sectors):
        phi = (s + 0.5) * 2.0 * math.pi / n_sectors
        for j in range(H):
            for i in range(W):
                out[j, i, s] = _horizon_along(h, pixel_size, j, i, phi, max_steps)


@numba.njit(cache=False)
def ray_march_shadows_kernel(h, pixel_size, phi, beta, max_steps, out):
    """Twin of ``ray_march_shadows``: lit where β exceeds the horizon along the exact azimuth."""
    H, W = h.shape
    for j in range(H):
        for i in range(W):
            horizon = _horizon_along(h, pixel_size, j, i, phi[j, i], max_steps)
            out[j, i] = beta[j, i] > horizon and beta[j, i] > 0.0
