"""numba twins of the ImpastoR package: same names, same equations, no validation.

Twins of ``impastor.specular_lighting`` (filtered importance sampling, point lights, the Ward–Dür
lobe) and of ``impastor.horizon`` (horizon maps and ray-marched shadows).
"""

from __future__ import annotations

import math

import numpy as np

from reference.jit import njit

# --- specular lighting (impastor.specular_lighting) ------------------------------


@njit
def _ward_lobe(wi, wo, n, alpha):
    """Eq. (4), Ferwerda, for ρ_s = 1; 0 below the horizon."""
    cos_i = wi[0] * n[0] + wi[1] * n[1] + wi[2] * n[2]
    cos_o = wo[0] * n[0] + wo[1] * n[1] + wo[2] * n[2]
    if cos_i <= 0.0 or cos_o <= 0.0:
        return 0.0
    h0, h1, h2 = wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]
    norm = math.sqrt(h0 * h0 + h1 * h1 + h2 * h2)
    cos_h = max((h0 * n[0] + h1 * n[1] + h2 * n[2]) / norm, 1e-300)
    tan2_h = (1.0 - cos_h * cos_h) / (cos_h * cos_h)
    # Eq. (4), Ferwerda: exp(−tan²θ_h/α²) / (4π α² cos θ_i cos θ_o)
    return math.exp(-tan2_h / (alpha * alpha)) / (4.0 * math.pi * alpha * alpha * cos_i * cos_o)


@njit
def _lobe_geometry(x0, x1, x2, P_p, N_p, V_p, n_light, alpha, wi):
    """Eq. (2), Ferwerda, weighted by the lobe: f_s (N·I)(−N_light·I) / d² for a light point x."""
    d0, d1, d2 = x0 - P_p[0], x1 - P_p[1], x2 - P_p[2]
    dist2 = d0 * d0 + d1 * d1 + d2 * d2
    dist = math.sqrt(dist2)
    wi[0], wi[1], wi[2] = d0 / dist, d1 / dist, d2 / dist
    cos_s = wi[0] * N_p[0] + wi[1] * N_p[1] + wi[2] * N_p[2]
    cos_l = -(wi[0] * n_light[0] + wi[1] * n_light[1] + wi[2] * n_light[2])
    if cos_s <= 0.0 or cos_l <= 0.0:
        return 0.0
    return _ward_lobe(wi, V_p, N_p, alpha) * cos_s * cos_l / dist2


@njit
def specular_point_lights_kernel(P, N, V, alpha, light_pos, light_L, n_light, pixel_area, vis, out):
    """Twin of ``specular_point_lights``: Σ_n f_s(I_n, V) L_n (N·I_n)(−N_light·I_n) A/P / d_n²."""
    wi = np.empty(3)
    for p in range(P.shape[0]):
        acc = 0.0
        for k in range(light_pos.shape[0]):
            if vis[p, k] == 0.0:
                continue
            x = light_pos[k]
            # Eq. (2), Ferwerda: each light's contribution, weighted by the lobe (_lobe_geometry)
            g = _lobe_geometry(x[0], x[1], x[2], P[p], N[p], V[p], n_light, alpha[p], wi)
            acc += g * light_L[k] * vis[p, k] * pixel_area
        out[p] = acc


@njit
def _mip_fetch(mips, offsets, heights, widths, level, a, b):
    """Bilinear fetch (texel centres, clamp to edge) of one mip level stored flat."""
    H, W = heights[level], widths[level]
    x = a * W - 0.5
    y = b * H - 0.5
    x = min(max(x, 0.0), W - 1.0)
    y = min(max(y, 0.0), H - 1.0)
    x0 = min(math.floor(x), W - 1)
    y0 = min(math.floor(y), H - 1)
    x1, y1 = min(x0 + 1, W - 1), min(y0 + 1, H - 1)
    fx, fy = x - x0, y - y0
    base = offsets[level]
    top = mips[base + y0 * W + x0] * (1.0 - fx) + mips[base + y0 * W + x1] * fx
    bottom = mips[base + y1 * W + x0] * (1.0 - fx) + mips[base + y1 * W + x1] * fx
    return top * (1.0 - fy) + bottom * fy


@njit
def specular_fis_kernel(
    P, N, V, alpha, u, mips, offsets, heights, widths, origin, A, B, l_A, l_B, pixel_area, bias, out
):
    """Twin of ``specular_fis``: filtered importance sampling of the Ward–Dür lobe."""
    K = u.shape[0]
    n_levels = heights.shape[0]
    n_light0 = A[1] * B[2] - A[2] * B[1]
    n_light1 = A[2] * B[0] - A[0] * B[2]
    n_light2 = A[0] * B[1] - A[1] * B[0]
    h = np.empty(3)
    wi = np.empty(3)
    for p in range(P.shape[0]):
        n0, n1, n2 = N[p, 0], N[p, 1], N[p, 2]
        # Tangent frame (Duff et al. 2017), as reference.materials.brdf.frame_from_normal.
        sign = 1.0 if n2 >= 0.0 else -1.0
        a_ = -1.0 / (sign + n2)
        c_ = n0 * n1 * a_
        t0, t1, t2 = 1.0 + sign * n0 * n0 * a_, sign * c_, -sign * n0
        b0, b1, b2 = c_, sign + n1 * n1 * a_, -n1
        al = alpha[p]
        acc = 0.0
        for k in range(K):
            # Ward 1992 half-vector sample
            tan2_h = -al * al * math.log1p(-min(u[k, 0], 1.0 - 1e-16))
            cos_h = 1.0 / math.sqrt(1.0 + tan2_h)
            sin_h = math.sqrt(max(0.0, 1.0 - cos_h * cos_h))
            phi = 2.0 * math.pi * u[k, 1]
            x, y = sin_h * math.cos(phi), sin_h * math.sin(phi)
            h[0] = x * t0 + y * b0 + cos_h * n0
            h[1] = x * t1 + y * b1 + cos_h * n1
            h[2] = x * t2 + y * b2 + cos_h * n2
            v_h = V[p, 0] * h[0] + V[p, 1] * h[1] + V[p, 2] * h[2]
            wi[0] = 2.0 * v_h * h[0] - V[p, 0]
            wi[1] = 2.0 * v_h * h[1] - V[p, 1]
            wi[2] = 2.0 * v_h * h[2] - V[p, 2]
            cos_i = wi[0] * n0 + wi[1] * n1 + wi[2] * n2
            if cos_i <= 0.0 or v_h <= 0.0:
                continue
            pdf = math.exp(-tan2_h / (al * al)) / (math.pi * al * al * cos_h**3) / (4.0 * v_h)
            # Eq. (5), Ferwerda: distance to the light plane
            denom = wi[0] * n_light0 + wi[1] * n_light1 + wi[2] * n_light2
            if denom >= -1e-15:
                continue
            d = (
                (origin[0] - P[p, 0]) * n_light0
                + (origin[1] - P[p, 1]) * n_light1
                + (origin[2] - P[p, 2]) * n_light2
            ) / denom
            if d <= 0.0:
                continue
            # Eq. (6), Ferwerda: the hit point on the light plane
            q0, q1, q2 = d * wi[0] + P[p, 0], d * wi[1] + P[p, 1], d * wi[2] + P[p, 2]
            # Eq. (7), Ferwerda: the hit point relative to the plane's corner o_TL
            r0, r1, r2 = q0 - origin[0], q1 - origin[1], q2 - origin[2]
            # Eq. (8), Ferwerda: pinv of [l_A A, l_B B] (orthogonal columns)
            a = (r0 * A[0] + r1 * A[1] + r2 * A[2]) / l_A
            b = (r0 * B[0] + r1 * B[1] + r2 * B[2]) / l_B
            if a < 0.0 or a >= 1.0 or b < 0.0 or b >= 1.0:
                continue
            # Colbert et al. 2010: mip level from the sample's and a texel's solid angles
            omega_s = 1.0 / (K * pdf)
            omega_p = pixel_area * (-denom) / (d * d)
            level = max(0.5 * math.log2(omega_s / omega_p) + bias, 0.0)
            level = min(level, n_levels - 1.0)
            l0 = math.floor(level)
            l1 = min(l0 + 1, n_levels - 1)
            t = level - l0
            L = (1.0 - t) * _mip_fetch(mips, offsets, heights, widths, l0, a, b)
            L += t * _mip_fetch(mips, offsets, heights, widths, l1, a, b)
            f = _ward_lobe(wi, V[p], N[p], al)
            acc += f * L * cos_i / pdf
        out[p] = acc / K


@njit(inline="always")
def _specular_sub_pixels(
    P, N, V, alpha, image, origin, A, B, l_A, l_B, n_light, supersample, horizon, frame, out
):
    """The loop of both specular brute-force kernels: the lobe over every light sub-pixel.

    Each sub-pixel is shadow-tested against ``horizon`` (n, S) when S > 0.
    """
    H, W = image.shape
    s = supersample
    sub_area = l_A * l_B / (H * W * s * s)
    shadowed = horizon.shape[1] > 0
    wi = np.empty(3)
    for p in range(P.shape[0]):
        acc = 0.0
        for j in range(H):
            for i in range(W):
                L = image[j, i]
                if L == 0.0:
                    continue
                for sj in range(s):
                    b = (j + (sj + 0.5) / s) / H
                    for si in range(s):
                        a = (i + (si + 0.5) / s) / W
                        x0 = origin[0] + a * l_A * A[0] + b * l_B * B[0]
                        x1 = origin[1] + a * l_A * A[1] + b * l_B * B[1]
                        x2 = origin[2] + a * l_A * A[2] + b * l_B * B[2]
                        g = _lobe_geometry(x0, x1, x2, P[p], N[p], V[p], n_light, alpha[p], wi)
                        if g > 0.0 and (
                            not shadowed or _above_horizon(wi[0], wi[1], wi[2], frame, horizon[p])
                        ):
                            acc += g * L * sub_area
        out[p] = acc


@njit
def specular_brute_force_kernel(
    P, N, V, alpha, image, origin, A, B, l_A, l_B, n_light, supersample, out
):
    """Twin of ``specular_brute_force``: the lobe summed over every light sub-pixel."""
    no_horizon = np.zeros((P.shape[0], 0))
    _specular_sub_pixels(
        P, N, V, alpha, image, origin, A, B, l_A, l_B, n_light, supersample, no_horizon,
        np.eye(3), out,
    )  # fmt: skip


@njit
def specular_brute_force_shadowed_kernel(
    P, N, V, alpha, horizon, frame, image, origin, A, B, l_A, l_B, n_light, supersample, out
):
    """Twin of ``specular_brute_force_shadowed``: every light sub-pixel, each shadow-tested."""
    _specular_sub_pixels(
        P, N, V, alpha, image, origin, A, B, l_A, l_B, n_light, supersample, horizon, frame, out
    )


# --- horizon maps (impastor.horizon) --------------------------------------------


@njit
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


@njit
def _horizon_along(h, pixel_size, j, i, phi, max_steps, step, h_max):
    dx, dy = math.cos(phi), math.sin(phi)
    best = 0.0
    n_steps = round(max_steps / step)
    headroom = h_max - h[j, i]
    for k in range(1, n_steps + 1):
        t = k * step
        # No later sample rises above h_max (bilinear samples stay within the heights) and t only
        # grows, so once (h_max - h₀)/t cannot beat the best slope the march stops: the same
        # result, exactly, at a fraction of the steps on most texels (a speed-up of our own).
        if headroom <= best * (t * pixel_size):
            break
        rise = _sample_periodic(h, j + t * dy, i + t * dx) - h[j, i]
        # Sloan & Cohen 2000: the horizon is the largest elevation angle seen along the ray
        best = max(best, rise / (t * pixel_size))
    return math.atan(best)


@njit
def horizon_map_kernel(h, pixel_size, n_sectors, max_steps, step, row0, out):
    """Twin of ``horizon_map``: each sector marched along its centre azimuth, rows from row0.

    ``out`` holds the rows ``row0 .. row0 + len(out)``: the wrapper calls it a band at a time.
    """
    W = h.shape[1]
    h_max = h.max()
    for s in range(n_sectors):
        phi = (s + 0.5) * 2.0 * math.pi / n_sectors
        for j in range(out.shape[0]):
            for i in range(W):
                out[j, i, s] = _horizon_along(
                    h, pixel_size, row0 + j, i, phi, max_steps, step, h_max
                )


@njit
def horizon_at_texels_kernel(h, pixel_size, rows, cols, n_sectors, max_steps, step, out):
    """Twin of ``horizon_at_texels``: the horizon map's sectors at the listed texels only."""
    h_max = h.max()
    for n in range(rows.shape[0]):
        for s in range(n_sectors):
            phi = (s + 0.5) * 2.0 * math.pi / n_sectors
            out[n, s] = _horizon_along(h, pixel_size, rows[n], cols[n], phi, max_steps, step, h_max)


@njit
def _above_horizon(ix, iy, iz, frame, horizon):
    """``horizon_lookup`` for one unit direction: above the texel's horizon, interpolated in φ."""
    S = horizon.shape[0]
    # light_azimuth_elevation in the canvas frame (T, B, N) = frame's rows
    t = ix * frame[0, 0] + iy * frame[0, 1] + iz * frame[0, 2]
    b = ix * frame[1, 0] + iy * frame[1, 1] + iz * frame[1, 2]
    z = ix * frame[2, 0] + iy * frame[2, 1] + iz * frame[2, 2]
    beta = math.asin(min(max(z, -1.0), 1.0))
    if beta <= 0.0:
        return False
    x = (math.atan2(b, t) % (2.0 * math.pi)) / (2.0 * math.pi / S)
    s0 = math.floor(x - 0.5)
    f = x - 0.5 - s0
    critical = (1.0 - f) * horizon[int(s0) % S] + f * horizon[int(s0 + 1) % S]
    return beta > critical


@njit
def diffuse_brute_force_kernel(P, N, horizon, frame, position, L, n_light, pixel_area, out):
    """Twin of ``diffuse_brute_force``: Eq. (2), Ferwerda, over every light pixel, shadowed."""
    for n in range(P.shape[0]):
        for m in range(position.shape[0]):
            dx, dy, dz = (
                position[m, 0] - P[n, 0],
                position[m, 1] - P[n, 1],
                position[m, 2] - P[n, 2],
            )
            d2 = dx * dx + dy * dy + dz * dz
            r = math.sqrt(d2)
            ix, iy, iz = dx / r, dy / r, dz / r
            cos_s = max(ix * N[n, 0] + iy * N[n, 1] + iz * N[n, 2], 0.0)
            cos_l = max(-(ix * n_light[0] + iy * n_light[1] + iz * n_light[2]), 0.0)
            if cos_s == 0.0 or cos_l == 0.0:
                continue
            if not _above_horizon(ix, iy, iz, frame, horizon[n]):
                continue
            g = cos_s * cos_l * pixel_area / d2
            for c in range(L.shape[1]):
                out[n, c] += g * L[m, c]


@njit
def ray_march_shadows_kernel(h, pixel_size, phi, beta, max_steps, step, out):
    """Twin of ``ray_march_shadows``: lit where β exceeds the horizon along the exact azimuth."""
    H, W = h.shape
    h_max = h.max()
    for j in range(H):
        for i in range(W):
            horizon = _horizon_along(h, pixel_size, j, i, phi[j, i], max_steps, step, h_max)
            out[j, i] = beta[j, i] > horizon and beta[j, i] > 0.0
