"""numba twins of the polymer family: the oracle's rough specular sum, the shading of the hybrid.

Twins of ``shrm.polymer.oracle.rough_specular_samples``, ``rough_specular_samples_mis`` and
``rough_reflection_albedo``, of
``shrm.polymer.material.polymer_shade_parts``, of its baseline
``shrm.polymer.material.lambert_phong_shade_parts`` and of the layered model's re-shade
``shrm.polymer.layered.layered_reshade_XYZ`` and of its filtered importance sampling
``shrm.polymer.layered.fis_specular_latlong``. Each kernel keeps the names and equation
comments of its NumPy reference, never validates, never prints, and writes into an output array
that the public entry point allocated. The equality tests live in ``tests/shrm/polymer``.
"""

from __future__ import annotations

import math

import numpy as np

from reference.jit import njit

__all__ = [
    "lambert_phong_shade_parts_kernel",
    "layered_fis_kernel",
    "layered_reshade_kernel",
    "polymer_shade_parts_kernel",
    "rough_reflection_albedo_kernel",
    "rough_specular_mis_kernel",
    "rough_specular_samples_kernel",
]


@njit
def _fresnel_dielectric(cos_i, n):
    """Exact unpolarized Fresnel reflectance from air (``reference.materials.fresnel``)."""
    cos_i = min(max(cos_i, 0.0), 1.0)
    # Snell's law: cos θ_t = sqrt(1 - (1 - cos² θ_i) / n²)
    cos_t = math.sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n))
    # Born & Wolf §1.5.2
    r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (r_s * r_s + r_p * r_p)


@njit
def _latlong_uv(dx, dy, dz):
    """Lat-long texture coordinates of a unit direction (``direction_to_latlong_uv``)."""
    u = math.atan2(dx, -dz) / (2.0 * math.pi)
    if u < 0.0:
        u += 1.0
    if u >= 1.0:
        u = 0.0
    return u, math.acos(min(max(dy, -1.0), 1.0)) / math.pi


@njit
def _latlong_bilinear_taps(H, W, dx, dy, dz):
    """The texels and weights of a bilinear look-up at a direction (``latlong_lookup_bilinear``)."""
    u, v = _latlong_uv(dx, dy, dz)
    return _latlong_taps_at(H, W, u, v)


@njit
def _latlong_taps_at(H, W, u, v):
    """:func:`_latlong_bilinear_taps` at the direction's lat-long coordinates ``(u, v)``."""
    x = u * W - 0.5
    y = min(max(v * H - 0.5, 0.0), H - 1.0)
    x0 = math.floor(x)
    y0 = min(math.floor(y), H - 1)
    fx, fy = x - x0, y - y0
    return x0 % W, (x0 + 1) % W, y0, min(y0 + 1, H - 1), fx, fy


@njit
def _latlong_bilinear_add(image, dx, dy, dz, weight, x_out):
    """x_out[b] = weight × bilinear look-up of the lat-long map (``latlong_lookup_bilinear``)."""
    x0, x1, y0, y1, fx, fy = _latlong_bilinear_taps(image.shape[0], image.shape[1], dx, dy, dz)
    for b in range(image.shape[2]):
        top = image[y0, x0, b] * (1 - fx) + image[y0, x1, b] * fx
        bottom = image[y1, x0, b] * (1 - fx) + image[y1, x1, b] * fx
        x_out[b] = weight * (top * (1 - fy) + bottom * fy)


@njit
def _latlong_bilinear_accumulate(image, u, v, weight, out):
    """out[b] += weight × bilinear look-up of the lat-long map at coordinates ``(u, v)``."""
    x0, x1, y0, y1, fx, fy = _latlong_taps_at(image.shape[0], image.shape[1], u, v)
    for b in range(image.shape[2]):
        top = image[y0, x0, b] * (1 - fx) + image[y0, x1, b] * fx
        bottom = image[y1, x0, b] * (1 - fx) + image[y1, x1, b] * fx
        out[b] += weight * (top * (1 - fy) + bottom * fy)


@njit
def _frame_and_view(N, V, p):
    """Duff et al. 2017's tangent frame (T, B) of normal p and the unit view in it, above it."""
    nx, ny, nz = N[p, 0], N[p, 1], N[p, 2]
    sign = math.copysign(1.0, nz)
    a = -1.0 / (sign + nz)
    b = nx * ny * a
    tx, ty, tz = 1.0 + sign * nx * nx * a, sign * b, -sign * nx
    bx, by, bz = b, sign + ny * ny * a, -ny
    ox = V[p, 0] * tx + V[p, 1] * ty + V[p, 2] * tz
    oy = V[p, 0] * bx + V[p, 1] * by + V[p, 2] * bz
    oz = max(V[p, 0] * nx + V[p, 1] * ny + V[p, 2] * nz, 1e-6)
    norm = math.sqrt(ox * ox + oy * oy + oz * oz)
    return tx, ty, tz, bx, by, bz, ox / norm, oy / norm, oz / norm


@njit
def _stretched_view(ox, oy, oz, alpha):
    """Heitz 2018, listing 1: the view in the stretched configuration and its frame (T1, T2)."""
    vx, vy, vz = alpha * ox, alpha * oy, oz
    norm = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / norm, vy / norm, vz / norm
    lensq = vx * vx + vy * vy
    if lensq > 0:
        inv = 1.0 / math.sqrt(lensq)
        t1x, t1y, t1z = -vy * inv, vx * inv, 0.0
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
    t2x, t2y, t2z = vy * t1z - vz * t1y, vz * t1x - vx * t1z, vx * t1y - vy * t1x
    return vx, vy, vz, t1x, t1y, t1z, t2x, t2y, t2z, 0.5 * (1.0 + vz)


@njit
def _reflected_sample(ox, oy, oz, alpha, view, u1, u2):
    """A GGX visible normal h (Heitz 2018, listing 1) from two uniforms: o·h, i = 2 (o·h) h − o."""
    phi = 2.0 * math.pi * u2
    return _reflected_sample_at(
        ox, oy, oz, alpha, view, math.sqrt(u1), math.cos(phi), math.sin(phi)
    )


@njit
def _reflected_sample_at(ox, oy, oz, alpha, view, r, cos_phi, sin_phi):
    """:func:`_reflected_sample` from the disk point's ``r = √u1``, ``cos φ`` and ``sin φ``.

    They depend on the uniforms alone: a kernel that reads the same points at every pixel (the
    Hammersley set of filtered importance sampling) computes them once.
    """
    vx, vy, vz, t1x, t1y, t1z, t2x, t2y, t2z, s = view
    q1 = r * cos_phi
    q2 = (1.0 - s) * math.sqrt(1.0 - q1 * q1) + s * r * sin_phi
    q3 = math.sqrt(max(0.0, 1.0 - q1 * q1 - q2 * q2))
    hx = alpha * (q1 * t1x + q2 * t2x + q3 * vx)
    hy = alpha * (q1 * t1y + q2 * t2y + q3 * vy)
    hz = max(0.0, q1 * t1z + q2 * t2z + q3 * vz)
    norm = math.sqrt(hx * hx + hy * hy + hz * hz)
    hx, hy, hz = hx / norm, hy / norm, hz / norm
    oh = ox * hx + oy * hy + oz * hz
    return oh, 2.0 * oh * hx - ox, 2.0 * oh * hy - oy, 2.0 * oh * hz - oz, hz


@njit
def rough_specular_samples_kernel(N, V, radiance, alpha, n, u, total, total_sq):
    """Twin of ``shrm.polymer.oracle.rough_specular_samples``: sums of F(o·h) G_1(i) L(i)."""
    nb = radiance.shape[2]
    x = np.empty(nb)
    for p in range(N.shape[0]):
        nx, ny, nz = N[p, 0], N[p, 1], N[p, 2]
        tx, ty, tz, bx, by, bz, ox, oy, oz = _frame_and_view(N, V, p)
        view = _stretched_view(ox, oy, oz, alpha)
        for m in range(u.shape[1]):
            oh, ix, iy, iz, _ = _reflected_sample(ox, oy, oz, alpha, view, u[p, m, 0], u[p, m, 1])
            # weight F(o·h) G_1(i) (Eq. (34), Walter et al. 2007)
            if iz > 0.0:
                c2 = max(iz * iz, 1e-300)
                G = 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2))
            else:
                G = 0.0
            weight = _fresnel_dielectric(oh, n) * G
            dx = ix * tx + iy * bx + iz * nx
            dy = ix * ty + iy * by + iz * ny
            dz = ix * tz + iy * bz + iz * nz
            _latlong_bilinear_add(radiance, dx, dy, dz, weight, x)
            for band in range(nb):
                total[p, band] += x[band]
                total_sq[p, band] += x[band] * x[band]


@njit
def _vndf_pdf_local(ox, oy, oz, ix, iy, iz, alpha):
    """G_1(o) D(h) / (4 cos θ_o) of a reflected local direction, and o·h (``_vndf_pdf``)."""
    hx, hy, hz = ox + ix, oy + iy, oz + iz
    norm = max(math.sqrt(hx * hx + hy * hy + hz * hz), 1e-300)
    hx, hy, hz = hx / norm, hy / norm, hz / norm
    oh = ox * hx + oy * hy + oz * hz
    if oh <= 0.0 or hz <= 0.0:
        return 0.0, oh
    a2 = alpha * alpha
    # D of Eq. (33), Walter et al. 2007
    t = hz * hz * (a2 - 1.0) + 1.0
    D = a2 / (math.pi * t * t)
    c2 = max(oz * oz, 1e-300)
    G1_o = 2.0 / (1.0 + math.sqrt(1.0 + a2 * (1.0 - c2) / c2))
    return G1_o * D / (4.0 * oz), oh


@njit
def _texel_at(H, W, u, v):
    """The row-major texel whose solid angle holds coordinates ``(u, v)`` (``_texel_of``)."""
    return min(math.floor(v * H), H - 1) * W + min(math.floor(u * W), W - 1)


@njit
def _mis_weight(ox, oy, oz, ix, iy, iz, alpha, n, p_e):
    """F(o·h) G_1(i) p_v / (p_v + p_e) of one local direction i; −1 where p_v or cos θ_i <= 0.

    The pair adds the weight times L(i) (none where it is −1: the direction adds nothing).
    """
    p_v, oh = _vndf_pdf_local(ox, oy, oz, ix, iy, iz, alpha)
    if p_v <= 0.0 or iz <= 0.0:
        return -1.0
    c2 = max(iz * iz, 1e-300)
    G = 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2))
    # the balance heuristic's weight on the estimator F(o·h) G_1(i)
    return _fresnel_dielectric(oh, n) * G * p_v / max(p_v + p_e, 1e-300)


@njit
def rough_specular_mis_kernel(N, V, radiance, alpha, n, u, cdf, pdf, total, total_sq):
    """Twin of ``shrm.polymer.oracle.rough_specular_samples_mis``: visible normals and the map."""
    H, W, nb = radiance.shape[0], radiance.shape[1], radiance.shape[2]
    pair, d = np.empty(nb), np.empty(3)
    for p in range(N.shape[0]):
        nx, ny, nz = N[p, 0], N[p, 1], N[p, 2]
        tx, ty, tz, bx, by, bz, ox, oy, oz = _frame_and_view(N, V, p)
        view = _stretched_view(ox, oy, oz, alpha)
        for m in range(u.shape[1]):
            pair[:] = 0.0
            # a visible normal, reflected
            _, ix, iy, iz, _ = _reflected_sample(ox, oy, oz, alpha, view, u[p, m, 0], u[p, m, 1])
            d[0] = ix * tx + iy * bx + iz * nx
            d[1] = ix * ty + iy * by + iz * ny
            d[2] = ix * tz + iy * bz + iz * nz
            # the direction's lat-long coordinates: its texel's density and its look-up
            u_d, v_d = _latlong_uv(d[0], d[1], d[2])
            p_e = pdf[_texel_at(H, W, u_d, v_d)]
            weight = _mis_weight(ox, oy, oz, ix, iy, iz, alpha, n, p_e)
            if weight >= 0.0:
                _latlong_bilinear_accumulate(radiance, u_d, v_d, weight, pair)
            # a direction of the map: a texel by its share, then uniformly in its solid angle
            u1, u2 = u[p, m, 2], u[p, m, 3]
            k = min(np.searchsorted(cdf, u1, side="right"), H * W - 1)
            low = cdf[k - 1] if k > 0 else 0.0
            frac = min(max((u1 - low) / max(cdf[k] - low, 1e-300), 0.0), 1.0)
            row, col = k // W, k % W
            cos0, cos1 = math.cos(math.pi * row / H), math.cos(math.pi * (row + 1) / H)
            cos_t = cos0 + u2 * (cos1 - cos0)
            phi = 2.0 * math.pi * (col + frac) / W
            sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
            d[0], d[1], d[2] = sin_t * math.sin(phi), cos_t, -sin_t * math.cos(phi)
            ix = d[0] * tx + d[1] * ty + d[2] * tz
            iy = d[0] * bx + d[1] * by + d[2] * bz
            iz = d[0] * nx + d[1] * ny + d[2] * nz
            weight = _mis_weight(ox, oy, oz, ix, iy, iz, alpha, n, pdf[k])
            if weight >= 0.0:
                u_d, v_d = _latlong_uv(d[0], d[1], d[2])
                _latlong_bilinear_accumulate(radiance, u_d, v_d, weight, pair)
            for b in range(nb):
                total[p, b] += pair[b]
                total_sq[p, b] += pair[b] * pair[b]


@njit
def _pyramid_bilinear_add(flat, offset, H, u, v, weight, x_out):
    """x_out[b] += weight × bilinear look-up of one packed pyramid level (W = 2H) at ``(u, v)``."""
    W = 2 * H
    x0, x1, y0, y1, fx, fy = _latlong_taps_at(H, W, u, v)
    for b in range(flat.shape[1]):
        top = flat[offset + y0 * W + x0, b] * (1 - fx) + flat[offset + y0 * W + x1, b] * fx
        bottom = flat[offset + y1 * W + x0, b] * (1 - fx) + flat[offset + y1 * W + x1, b] * fx
        x_out[b] += weight * (top * (1 - fy) + bottom * fy)


@njit
def layered_fis_kernel(N, V, flat, heights, offsets, alpha, n, u, bias, out):
    """Twin of ``shrm.polymer.layered.fis_specular_latlong``: Σ w L̃(i, λ) / Σ w, w = F G_1."""
    K, top = u.shape[0], heights.shape[0] - 1
    nb = flat.shape[1]
    x = np.zeros(nb)
    H = heights[0]
    texel = (math.pi / H) * (2.0 * math.pi / (2 * H))
    sin_pole = math.sin(0.5 * math.pi / H)
    a2 = alpha * alpha
    # the disk points of the K samples: the same at every pixel
    r_k, cos_k, sin_k = np.empty(K), np.empty(K), np.empty(K)
    for m in range(K):
        phi = 2.0 * math.pi * u[m, 1]
        r_k[m], cos_k[m], sin_k[m] = math.sqrt(u[m, 0]), math.cos(phi), math.sin(phi)
    for p in range(N.shape[0]):
        nx, ny, nz = N[p, 0], N[p, 1], N[p, 2]
        tx, ty, tz, bx, by, bz, ox, oy, oz = _frame_and_view(N, V, p)
        c2 = max(oz * oz, 1e-300)
        G1_o = 2.0 / (1.0 + math.sqrt(1.0 + a2 * (1.0 - c2) / c2))
        view = _stretched_view(ox, oy, oz, alpha)
        x[:] = 0.0
        total = 0.0
        for m in range(K):
            oh, ix, iy, iz, hz = _reflected_sample_at(
                ox, oy, oz, alpha, view, r_k[m], cos_k[m], sin_k[m]
            )
            if iz <= 0.0:
                continue
            # weight F(o·h) G_1(i) (Eq. (34), Walter et al. 2007)
            ci2 = max(iz * iz, 1e-300)
            G = 2.0 / (1.0 + math.sqrt(1.0 + a2 * (1.0 - ci2) / ci2))
            weight = _fresnel_dielectric(oh, n) * G
            total += weight
            dx = ix * tx + iy * bx + iz * nx
            dy = ix * ty + iy * by + iz * ny
            dz = ix * tz + iy * bz + iz * nz
            # pdf(i) = G_1(o) D(h) / (4 cos θ_o); the level of Ω_s = 1/(K pdf) over a texel's Ω_p
            D = a2 / (math.pi * (hz * hz * (a2 - 1.0) + 1.0) ** 2)
            pdf = G1_o * D / (4.0 * oz)
            omega_p = texel * max(math.sqrt(max(1.0 - dy * dy, 0.0)), sin_pole)
            level = max(0.5 * math.log2(1.0 / (K * pdf * omega_p)) + bias, 0.0)
            level = min(level, float(top))
            lo = min(math.floor(level), top)
            t = level - lo
            hi = min(lo + 1, top)
            # both levels read at the direction's lat-long coordinates; the upper one only where
            # it has a share (at t = 0 it would add zeros)
            u_d, v_d = _latlong_uv(dx, dy, dz)
            _pyramid_bilinear_add(flat, offsets[lo], heights[lo], u_d, v_d, weight * (1 - t), x)
            if t > 0.0:
                _pyramid_bilinear_add(flat, offsets[hi], heights[hi], u_d, v_d, weight * t, x)
        if total > 0.0:
            for band in range(nb):
                out[p, band] = x[band] / total


@njit
def rough_reflection_albedo_kernel(cos_o, alpha, n, u1, u2, weights, out):
    """Twin of ``shrm.polymer.oracle.rough_reflection_albedo``: Σ w F(o·h) G_1(i) per view."""
    for a in range(cos_o.shape[0]):
        oz = min(max(cos_o[a], 1e-6), 1.0)
        ox = math.sqrt(1.0 - oz * oz)
        # Heitz 2018, listing 1: the view in the stretched configuration (o_y = 0)
        vx, vz = alpha * ox, oz
        norm = math.sqrt(vx * vx + vz * vz)
        vx, vz = vx / norm, vz / norm
        if vx * vx > 0:
            t1x, t1y = 0.0, vx * (1.0 / math.sqrt(vx * vx))
        else:
            t1x, t1y = 1.0, 0.0
        # T2 = V × T1 with V = (v_x, 0, v_z), T1 = (t1x, t1y, 0)
        t2x, t2y, t2z = -vz * t1y, vz * t1x, vx * t1y
        s = 0.5 * (1.0 + vz)
        total = 0.0
        for m in range(u1.shape[0]):
            r = math.sqrt(u1[m])
            phi = 2.0 * math.pi * u2[m]
            q1 = r * math.cos(phi)
            q2 = (1.0 - s) * math.sqrt(1.0 - q1 * q1) + s * r * math.sin(phi)
            q3 = math.sqrt(max(0.0, 1.0 - q1 * q1 - q2 * q2))
            hx = alpha * (q1 * t1x + q2 * t2x + q3 * vx)
            hy = alpha * (q1 * t1y + q2 * t2y)
            hz = max(0.0, q2 * t2z + q3 * vz)
            norm = math.sqrt(hx * hx + hy * hy + hz * hz)
            hx, hy, hz = hx / norm, hy / norm, hz / norm
            # i = 2 (o·h) h − o; weight F(o·h) G_1(i) (Eq. (34), Walter et al. 2007)
            oh = ox * hx + oz * hz
            iz = 2.0 * oh * hz - oz
            if iz > 0.0:
                c2 = max(iz * iz, 1e-300)
                G = 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2))
                total += weights[m] * (_fresnel_dielectric(oh, n) * G)
        out[a] = total


@njit
def _coupled_weights_kernel(N, D, omega, side, enter, out):
    """Twin of the weights of ``shrm.polymer.oracle.coupled_irradiance``: c(cos) max(cos, 0) ω.

    ``out[p, k]`` for the normals ``N`` (P, 3) and the map's pixel directions ``D`` (K, 3) and
    solid angles ``omega`` (K,); ``enter`` is ``Coupling.enter`` on evenly spaced nodes of [0, 1].
    """
    m = enter.shape[0] - 1
    for p in range(N.shape[0]):
        nx, ny, nz = side * N[p, 0], side * N[p, 1], side * N[p, 2]
        for k in range(D.shape[0]):
            cos = nx * D[k, 0] + ny * D[k, 1] + nz * D[k, 2]
            if cos > 0.0:
                # Coupling.lookup: linear between the evenly spaced nodes
                x = min(cos, 1.0) * m
                i = min(int(x), m - 1)
                f = x - i
                c = enter[i] * (1.0 - f) + enter[i + 1] * f
                out[p, k] = c * cos * omega[k]
            else:
                out[p, k] = 0.0


@njit
def polymer_shade_parts_kernel(E_d, S, B, L, E_effect, D_Tint, Col_B, Col_L, gloss, Mod, out):
    """Twin of ``shrm.polymer.material.polymer_shade_parts``: Eq. (1), Herbert et al., one pass.

    ``D_Tint = D_polymer Tint_polymer``, ``Col_B = Col_trans (1 − u)``, ``Col_L = Col_trans u``
    (n_bands,); ``Mod`` (1,) or (N,); ``L`` and ``E_effect`` are read only where their weight is
    nonzero (an empty array: never). The NumPy reference makes a pass over the pixels per term;
    here each pixel's bands are read once and written once (the frame is memory-bound).
    """
    N, n_bands = E_d.shape
    use_L = L.shape[0] == N
    use_effect = E_effect.shape[0] == N
    for p in range(N):
        m = Mod[0] if Mod.size == 1 else Mod[p]
        for b in range(n_bands):
            # Eq. (2), Herbert et al.: I_d = E_d D_polymer Tint_polymer (1 − Mod_effect)
            I_d = E_d[p, b] * (D_Tint[b] * (1.0 - m))
            # Eq. (1), Herbert et al.: I_d + gloss S + Col_trans ((1 − u) B + u L)
            I = I_d + S[p, b] * gloss + B[p, b] * Col_B[b]
            if use_L:
                I += L[p, b] * Col_L[b]
            # Eq. (3), Herbert et al.: + E_effect Mod_effect
            if use_effect:
                I += E_effect[p, b] * m
            out[p, b] = I
    return out


@njit
def lambert_phong_shade_parts_kernel(E_d, E_s, k_d, k_s, out):
    """Twin of ``shrm.polymer.material.lambert_phong_shade_parts``: one pass over the pixels.

    ``k_d``, ``k_s`` (n_bands,).
    """
    N, n_bands = E_d.shape
    for p in range(N):
        for b in range(n_bands):
            # §5.2, Herbert et al.: k_d E(N)/π + k_s E_s(r)
            out[p, b] = k_d[b] * E_d[p, b] + k_s[b] * E_s[p, b]
    return out


@njit
def layered_reshade_kernel(specular, front, back, rho_out, tau, W, out):
    """Twin of ``layered_reshade_XYZ``: the three terms of each pixel, then the band weights."""
    P, B = specular.shape
    C = W.shape[1]
    L = np.empty(B)
    for p in range(P):
        for b in range(B):
            # specular + ρ_out exit E_f(n) + τ exit E_b(−n) (the parts hold exit × E)
            L[b] = specular[p, b] + rho_out[b] * front[p, b] + tau[b] * back[p, b]
        # the band weights, summed in a register: adding into out[p, c] band by band stored and
        # reloaded it each time (2.3× slower on a 512² frame)
        for c in range(C):
            acc = 0.0
            for b in range(B):
                acc += L[b] * W[b, c]
            out[p, c] = acc
