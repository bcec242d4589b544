"""numba twin of ``reference.geometry.raster.rasterize_triangles`` (same names, equations, order).

The kernel is a line-by-line translation of the NumPy reference, which is the oracle: the same
operations in the same order, so the two agree bit for bit in practice and to rtol 1e-12 by test.
It loops over triangles and over the pixel centres of each triangle's bounding box, so a 100k-
triangle mesh at 512×512 takes no Python loop. No ``fastmath``: the top-left rule depends on exact
zeros and exact negation of shared edge functions.
"""

from __future__ import annotations

import math

import numpy as np

from reference.jit import njit

__all__ = ["rasterize_triangles_kernel"]

#: Must equal ``reference.geometry.raster.DEGENERATE_RELATIVE_AREA`` (a test checks).
DEGENERATE_RELATIVE_AREA = 1e-12


@njit
def rasterize_triangles_kernel(x, y, z, width, height, perspective, cull_backfaces):
    """Rasterize screen-space triangles with a z-buffer (numba twin of ``rasterize_triangles``).

    Eq. (1), Pineda 1988.

    Parameters
    ----------
    x, y, z : ndarray, shape (T, 3)
        Raster coordinates and camera depths (> 0) of each triangle's vertices.
    width, height : int
        Image size in pixels.
    perspective, cull_backfaces : bool
        Perspective-correct interpolation; skip triangles with negative area.

    Returns
    -------
    depth : ndarray, shape (height, width)
    triangle : ndarray of int64, shape (height, width)
    bary : ndarray, shape (height, width, 3)

    Examples
    --------
    >>> x = np.array([[0.5, 0.5, 2.5]]); y = np.array([[0.5, 2.5, 0.5]])
    >>> rasterize_triangles_kernel(x, y, np.ones((1, 3)), 3, 3, True, False)[1]
    array([[ 0,  0, -1],
           [ 0, -1, -1],
           [-1, -1, -1]])
    """
    depth = np.full((height, width), np.inf)
    triangle = np.full((height, width), -1, dtype=np.int64)
    bary = np.zeros((height, width, 3))
    o_x = np.empty(3)
    o_y = np.empty(3)
    d_x = np.empty(3)
    d_y = np.empty(3)
    sigma = np.empty(3)
    top_left = np.empty(3, dtype=np.bool_)
    E = np.empty(3)
    for t in range(x.shape[0]):
        x_0, x_1, x_2 = x[t, 0], x[t, 1], x[t, 2]
        y_0, y_1, y_2 = y[t, 0], y[t, 1], y[t, 2]
        # Eq. (1), Pineda 1988: twice the signed area, E_01 at vertex 2
        area = (x_2 - x_0) * (y_1 - y_0) - (y_2 - y_0) * (x_1 - x_0)
        e_01 = (x_1 - x_0) * (x_1 - x_0) + (y_1 - y_0) * (y_1 - y_0)
        e_12 = (x_2 - x_1) * (x_2 - x_1) + (y_2 - y_1) * (y_2 - y_1)
        e_20 = (x_0 - x_2) * (x_0 - x_2) + (y_0 - y_2) * (y_0 - y_2)
        longest = max(max(e_01, e_12), e_20)
        if not (math.isfinite(area) and abs(area) > DEGENERATE_RELATIVE_AREA * longest):
            continue
        if cull_backfaces and area < 0.0:
            continue
        s = 1.0 if area > 0.0 else -1.0
        # Bounding box of the pixel centres, widened by a hair (clamped before rounding).
        x_min, x_max = min(x_0, x_1, x_2), max(x_0, x_1, x_2)
        y_min, y_max = min(y_0, y_1, y_2), max(y_0, y_1, y_2)
        i_lo = max(math.ceil(max(x_min - 0.5 - 1e-9 * (1.0 + abs(x_min)), -1.0)), 0)
        i_hi = min(math.floor(min(x_max - 0.5 + 1e-9 * (1.0 + abs(x_max)), width)), width - 1)
        j_lo = max(math.ceil(max(y_min - 0.5 - 1e-9 * (1.0 + abs(y_min)), -1.0)), 0)
        j_hi = min(math.floor(min(y_max - 0.5 + 1e-9 * (1.0 + abs(y_max)), height)), height - 1)
        if i_lo > i_hi or j_lo > j_hi:
            continue
        for k in range(3):
            # Edge opposite vertex k, from a = vertex k+1 to b = vertex k+2, evaluated from its
            # lexicographically smaller end: Eq. (1), Pineda 1988
            a, b = (k + 1) % 3, (k + 2) % 3
            a_x, a_y, b_x, b_y = x[t, a], y[t, a], x[t, b], y[t, b]
            if a_x < b_x or (a_x == b_x and a_y < b_y):
                o_x[k], o_y[k], d_x[k], d_y[k], sigma[k] = a_x, a_y, b_x - a_x, b_y - a_y, 1.0
            else:
                o_x[k], o_y[k], d_x[k], d_y[k], sigma[k] = b_x, b_y, a_x - b_x, a_y - b_y, -1.0
            # Top-left rule: the edge's direction in the triangle oriented so that E > 0 inside
            t_x, t_y = s * (b_x - a_x), s * (b_y - a_y)
            top_left[k] = t_y > 0.0 or (t_y == 0.0 and t_x < 0.0)
        z_0, z_1, z_2 = z[t, 0], z[t, 1], z[t, 2]
        for j in range(j_lo, j_hi + 1):
            p_y = j + 0.5
            for i in range(i_lo, i_hi + 1):
                p_x = i + 0.5
                inside = True
                for k in range(3):
                    # Eq. (1), Pineda 1988
                    E_k = (p_x - o_x[k]) * d_y[k] - (p_y - o_y[k]) * d_x[k]
                    if sigma[k] < 0.0:
                        E_k = -E_k
                    E[k] = E_k
                    w = s * E_k
                    if not (w > 0.0 or (w == 0.0 and top_left[k])):
                        inside = False
                        break
                if not inside:
                    continue
                # Screen-space barycentrics λ_k = E_k / Σ E
                S = E[0] + E[1] + E[2]
                lambda_0, lambda_1, lambda_2 = E[0] / S, E[1] / S, E[2] / S
                if perspective:
                    # Perspective-correct: λ/z and 1/z are affine in screen space
                    q_0, q_1, q_2 = lambda_0 / z_0, lambda_1 / z_1, lambda_2 / z_2
                    Q = q_0 + q_1 + q_2
                    d = 1.0 / Q
                    b_0, b_1, b_2 = q_0 / Q, q_1 / Q, q_2 / Q
                else:
                    # Orthographic: depth and attributes are affine in screen space
                    d = lambda_0 * z_0 + lambda_1 * z_1 + lambda_2 * z_2
                    b_0, b_1, b_2 = lambda_0, lambda_1, lambda_2
                # Z-buffer: keep the nearer surface; ties keep the earlier triangle.
                if d < depth[j, i]:
                    depth[j, i] = d
                    triangle[j, i] = t
                    bary[j, i, 0] = b_0
                    bary[j, i, 1] = b_1
                    bary[j, i, 2] = b_2
    return depth, triangle, bary
