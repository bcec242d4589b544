"""numba twins of ``reference.geometry.cubemap``: lat-long → cube map, seamless cube-map lookups."""

from __future__ import annotations

import math

from reference.jit import njit


@njit
def _face_direction(face, s, t):
    """Direction (unnormalized) of face coordinates (s, t) in [-1, 1] (OpenGL layout)."""
    if face == 0:
        return 1.0, -t, -s
    if face == 1:
        return -1.0, -t, s
    if face == 2:
        return s, 1.0, t
    if face == 3:
        return s, -1.0, -t
    if face == 4:
        return s, -t, 1.0
    return -s, -t, -1.0


@njit
def _direction_face(x, y, z):
    """Face and (s, t) of a direction: the major axis picks the face."""
    ax, ay, az = abs(x), abs(y), abs(z)
    if ax >= ay and ax >= az:
        if x > 0:
            return 0, -z / ax, -y / ax
        return 1, z / ax, -y / ax
    if ay >= az:
        if y > 0:
            return 2, x / ay, z / ay
        return 3, x / ay, -z / ay
    if z > 0:
        return 4, x / az, -y / az
    return 5, -x / az, -y / az


@njit
def _fetch_index(face, i, j, S):
    """Texel (face, j, i), continuing across face edges by re-projecting the tap direction."""
    if 0 <= i < S and 0 <= j < S:
        return face, j, i
    x, y, z = _face_direction(face, 2.0 * (i + 0.5) / S - 1.0, 2.0 * (j + 0.5) / S - 1.0)
    f2, s2, t2 = _direction_face(x, y, z)
    i2 = min(max(math.floor((s2 + 1.0) * 0.5 * S), 0), S - 1)
    j2 = min(max(math.floor((t2 + 1.0) * 0.5 * S), 0), S - 1)
    return f2, j2, i2


@njit
def cubemap_lookup_kernel(cube, directions, out):
    """Twin of ``reference.geometry.cubemap.cubemap_lookup_bilinear``: seamless bilinear taps."""
    S = cube.shape[1]
    C = cube.shape[3]
    for n in range(directions.shape[0]):
        face, s, t = _direction_face(directions[n, 0], directions[n, 1], directions[n, 2])
        x = (s + 1.0) * 0.5 * S - 0.5
        y = (t + 1.0) * 0.5 * S - 0.5
        x0 = math.floor(x)
        y0 = math.floor(y)
        fx = x - x0
        fy = y - y0
        for c in range(C):
            out[n, c] = 0.0
        for dj in range(2):
            for di in range(2):
                wgt = (fx if di else 1.0 - fx) * (fy if dj else 1.0 - fy)
                f2, j2, i2 = _fetch_index(face, x0 + di, y0 + dj, S)
                for c in range(C):
                    out[n, c] += wgt * cube[f2, j2, i2, c]


@njit
def gather_bilinear_kernel(image, taps, weights, texel, out):
    """Twin of ``cubemap.gather_bilinear``: out[texel[j]] = Σ_k w[j, k] image[taps[j, k]].

    ``image``: (P, C) flattened pixels; ``taps``, ``weights``: (N, 4); ``texel``: (N,) output rows;
    ``out``: (M, C), M ≥ N (a subset of the texels may be gathered). The four rows of a texel are
    read as contiguous channel vectors. Taps sorted by input pixel
    (``reference.geometry.cubemap._latlong_taps``) read the input in memory order and write the
    output through ``texel``, faster on a 41-band map than walking the output in order, whose taps
    jump between distant input rows.
    """
    N = taps.shape[0]
    C = out.shape[1]
    for j in range(N):
        r0 = image[taps[j, 0]]
        r1 = image[taps[j, 1]]
        r2 = image[taps[j, 2]]
        r3 = image[taps[j, 3]]
        w0, w1, w2, w3 = weights[j, 0], weights[j, 1], weights[j, 2], weights[j, 3]
        o = out[texel[j]]
        for c in range(C):
            o[c] = w0 * r0[c] + w1 * r1[c] + w2 * r2[c] + w3 * r3[c]


__all__ = ["cubemap_lookup_kernel", "gather_bilinear_kernel"]
