"""numba twins of the readable NumPy functions of ``shrm.sh`` and ``shrm.prefilter``.

Each kernel keeps the names and equation comments of its NumPy reference, never validates, never
prints, and writes into an output array that the public entry point allocated. The equality tests
live in ``tests/shrm``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# Rescaling step of the extended-exponent recurrence: values are kept in [2^-SCALE, 2^SCALE].
SCALE_BITS = 200
_BIG = 2.0**SCALE_BITS
_SMALL = 2.0**-SCALE_BITS
_INV_SQRT_4PI = 1.0 / math.sqrt(4.0 * math.pi)


@numba.njit(cache=False)
def _sectoral_next(p, e, m, sin_theta, scaled):
    """λ_mm from λ_{m-1,m-1}, as (mantissa, binary exponent); the exponent moves only if scaled."""
    # Sectoral recurrence: λ_mm = -sqrt((2m+1)/(2m)) sin θ λ_{m-1,m-1}
    p = -math.sqrt((2.0 * m + 1.0) / (2.0 * m)) * sin_theta * p
    if scaled and p != 0.0 and abs(p) < _SMALL:
        p *= _BIG
        e -= SCALE_BITS
    return p, e


@numba.njit(cache=False)
def _point_table(L, sgn, u, sin_theta, A, B, scaled, keep, lam):
    """lam[t(l, m)] = λ_lm(x) for one point, m-major, for the orders with ``keep[m]``.

    x = sgn (1 - u) with u = 1 - |x| (``shrm.sh.ring_cosines``); the other entries are left alone.
    """
    p, e = _INV_SQRT_4PI, 0
    t0 = 0
    for m in range(L + 1):
        if m > 0:
            p, e = _sectoral_next(p, e, m, sin_theta, scaled)
        if keep[m]:
            p1 = p
            p2 = 0.0
            e_col = e
            lam[t0] = math.ldexp(p1, e_col) if scaled else p1
            for l in range(m + 1, L + 1):
                # λ_lm = a_lm (x λ_{l-1,m} - b_lm λ_{l-2,m})  (b_{m+1,m} = 0, a_{m+1,m} = √(2m+3))
                # x p = sgn (p - u p): exact near the poles, where x = cos θ is not representable
                p1, p2 = A[t0 + l - m] * (sgn * (p1 - u * p1) - B[t0 + l - m] * p2), p1
                if scaled and abs(p1) > _BIG:
                    p1 *= _SMALL
                    p2 *= _SMALL
                    e_col += SCALE_BITS
                lam[t0 + l - m] = math.ldexp(p1, e_col) if scaled else p1
        t0 += L + 1 - m


@numba.njit(cache=False)
def legendre_table_kernel(L, sgn, u, sin_theta, A, B, scaled, keep, out):
    """Twin of ``shrm.sh.legendre_table``: out[t(l, m), j] = λ_lm(x_j), m-major layout.

    Only the blocks with ``keep[m]`` are written, one after the other.
    """
    lam = np.empty((L + 1) * (L + 2) // 2)
    for j in range(u.shape[0]):
        _point_table(L, sgn[j], u[j], sin_theta[j], A, B, scaled, keep, lam)
        t0 = 0
        row = 0
        for m in range(L + 1):
            if keep[m]:
                for i in range(L + 1 - m):
                    out[row + i, j] = lam[t0 + i]
                row += L + 1 - m
            t0 += L + 1 - m


@numba.njit(cache=False)
def legendre_analysis_kernel(L, sgn, u, sin_theta, w, A, B, F_cos, F_sin, scaled, out):
    """Twin of ``shrm.transform.legendre_analysis``: c_lm = Σ_j w_j √2 λ_lm(θ_j) F_m(θ_j).

    ``F_cos, F_sin``: (L+1, H, C) ring integrals of f cos(mφ) and f sin(mφ); out: ((L+1)², C).
    """
    C = F_cos.shape[2]
    sqrt2 = math.sqrt(2.0)
    keep = np.ones(L + 1, dtype=np.bool_)
    lam = np.empty((L + 1) * (L + 2) // 2)
    for j in range(u.shape[0]):
        _point_table(L, sgn[j], u[j], sin_theta[j], A, B, scaled, keep, lam)
        t0 = 0
        for m in range(L + 1):
            # Fejér-1 quadrature: c_lm = Σ_j w_j λ_lm(θ_j) ∫ f(θ_j, φ) √2 trig(mφ) dφ
            for l in range(m, L + 1):
                if m == 0:
                    q = w[j] * lam[t0 + l]
                    for c in range(C):
                        out[l * l + l, c] += q * F_cos[0, j, c]
                else:
                    q = sqrt2 * w[j] * lam[t0 + l - m]
                    for c in range(C):
                        out[l * l + l + m, c] += q * F_cos[m, j, c]
                        out[l * l + l - m, c] += q * F_sin[m, j, c]
            t0 += L + 1 - m


@numba.njit(cache=False)
def legendre_synthesis_kernel(L, sgn, u, sin_theta, A, B, coeffs, scaled, G_cos, G_sin):
    """Twin of ``shrm.transform.legendre_synthesis``: ring Fourier amplitudes of Σ c_lm Y_lm.

    ``coeffs``: ((L+1)², C); ``G_cos, G_sin``: (L+1, H, C), the cos(mφ) and sin(mφ) amplitudes.
    """
    C = coeffs.shape[1]
    sqrt2 = math.sqrt(2.0)
    keep = np.ones(L + 1, dtype=np.bool_)
    lam = np.empty((L + 1) * (L + 2) // 2)
    for j in range(u.shape[0]):
        _point_table(L, sgn[j], u[j], sin_theta[j], A, B, scaled, keep, lam)
        t0 = 0
        for m in range(L + 1):
            for l in range(m, L + 1):
                if m == 0:
                    for c in range(C):
                        G_cos[0, j, c] += lam[t0 + l] * coeffs[l * l + l, c]
                else:
                    q = sqrt2 * lam[t0 + l - m]
                    for c in range(C):
                        G_cos[m, j, c] += q * coeffs[l * l + l + m, c]
                        G_sin[m, j, c] += q * coeffs[l * l + l - m, c]
            t0 += L + 1 - m


@numba.njit(cache=False)
def sh_evaluate_kernel(L, sgn, u, sin_theta, phi, A, B, coeffs, scaled, out):
    """Twin of ``shrm.sh.sh_evaluate``: out[n, c] = Σ_lm c_lm Y_lm(θ_n, φ_n) at any directions."""
    C = coeffs.shape[1]
    sqrt2 = math.sqrt(2.0)
    keep = np.ones(L + 1, dtype=np.bool_)
    lam = np.empty((L + 1) * (L + 2) // 2)
    for n in range(u.shape[0]):
        _point_table(L, sgn[n], u[n], sin_theta[n], A, B, scaled, keep, lam)
        t0 = 0
        for m in range(L + 1):
            # Real SH: Y_lm = √2 λ_l|m| cos(mφ) (m > 0), √2 λ_l|m| sin(|m|φ) (m < 0)
            cos_m = sqrt2 * math.cos(m * phi[n])
            sin_m = sqrt2 * math.sin(m * phi[n])
            for l in range(m, L + 1):
                if m == 0:
                    for c in range(C):
                        out[n, c] += lam[t0 + l] * coeffs[l * l + l, c]
                else:
                    for c in range(C):
                        out[n, c] += lam[t0 + l - m] * (
                            cos_m * coeffs[l * l + l + m, c] + sin_m * coeffs[l * l + l - m, c]
                        )
            t0 += L + 1 - m


@numba.njit(cache=False)
def prefilter_bruteforce_table_kernel(normals, directions, weights, radiance, angles, values, out):
    """Twin of ``shrm.prefilter.prefilter_bruteforce`` for tabulated lobes K(γ).

    ``out[k, c] = Σ_p radiance[p, c] K(acos(ω_p · n_k)) w_p``, K linear in γ between the samples
    and 0 beyond the last angle.
    """
    K = normals.shape[0]
    P = directions.shape[0]
    C = radiance.shape[1]
    last = angles[angles.shape[0] - 1]
    for k in range(K):
        for p in range(P):
            t = (
                normals[k, 0] * directions[p, 0]
                + normals[k, 1] * directions[p, 1]
                + normals[k, 2] * directions[p, 2]
            )
            gamma = math.acos(min(max(t, -1.0), 1.0))
            if gamma > last:
                continue
            # Eq. (7), Ramamoorthi & Hanrahan 2001, in the angular domain: Σ_p L_p K(γ_p) w_p
            kern = np.interp(gamma, angles, values) * weights[p]
            for c in range(C):
                out[k, c] += radiance[p, c] * kern


@numba.njit(cache=False)
def prefilter_bruteforce_power_kernel(normals, directions, weights, radiance, s, scale, out):
    """Twin of ``shrm.prefilter.prefilter_bruteforce`` for the power lobes K(t) = scale·max(t, 0)^s.

    Lambert is s = 1, scale = 1; normalized Phong is scale = (s + 1)/(2π).
    """
    K = normals.shape[0]
    P = directions.shape[0]
    C = radiance.shape[1]
    for k in range(K):
        for p in range(P):
            t = (
                normals[k, 0] * directions[p, 0]
                + normals[k, 1] * directions[p, 1]
                + normals[k, 2] * directions[p, 2]
            )
            if t <= 0.0:
                continue
            # Eq. (7), Ramamoorthi & Hanrahan 2001, in the angular domain: Σ_p L_p K(ω_p · n) w_p
            kern = scale * t**s * weights[p]
            for c in range(C):
                out[k, c] += radiance[p, c] * kern


__all__ = [
    "legendre_analysis_kernel",
    "legendre_synthesis_kernel",
    "legendre_table_kernel",
    "prefilter_bruteforce_power_kernel",
    "prefilter_bruteforce_table_kernel",
    "sh_evaluate_kernel",
]


@numba.njit(cache=False)
def _fresnel_dielectric(cos_i, n):
    """Exact unpolarized Fresnel reflectance from air (``reference.fresnel.fresnel_dielectric``)."""
    cos_i = min(max(cos_i, 0.0), 1.0)
    # Snell's law: cos θ_t = sqrt(1 - (1 - cos² θ_i) / n²)
    cos_t = math.sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n))
    # Born & Wolf §1.5.2
    r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (r_s * r_s + r_p * r_p)


@numba.njit(cache=False)
def _latlong_bilinear_add(image, dx, dy, dz, weight, x_out):
    """x_out[b] = weight × bilinear look-up of the lat-long map (``latlong_lookup_bilinear``)."""
    H, W = image.shape[0], image.shape[1]
    u = math.atan2(dx, -dz) / (2.0 * math.pi)
    if u < 0.0:
        u += 1.0
    if u >= 1.0:
        u = 0.0
    v = math.acos(min(max(dy, -1.0), 1.0)) / math.pi
    x = u * W - 0.5
    y = min(max(v * H - 0.5, 0.0), H - 1.0)
    x0 = math.floor(x)
    y0 = min(math.floor(y), H - 1)
    fx, fy = x - x0, y - y0
    x1, y1 = (x0 + 1) % W, min(y0 + 1, H - 1)
    x0 = x0 % W
    for b in range(image.shape[2]):
        top = image[y0, x0, b] * (1 - fx) + image[y0, x1, b] * fx
        bottom = image[y1, x0, b] * (1 - fx) + image[y1, x1, b] * fx
        x_out[b] = weight * (top * (1 - fy) + bottom * fy)


@numba.njit(cache=False)
def rough_specular_samples_kernel(N, V, radiance, alpha, n, u, total, total_sq):
    """Twin of ``shrm.polymer_oracle.rough_specular_samples``: sums of F(o·h) G_1(i) L(i)."""
    nb = radiance.shape[2]
    x = np.empty(nb)
    for p in range(N.shape[0]):
        nx, ny, nz = N[p, 0], N[p, 1], N[p, 2]
        # Duff et al. 2017: the tangent frame (T, B, N)
        sign = math.copysign(1.0, nz)
        a = -1.0 / (sign + nz)
        b = nx * ny * a
        tx, ty, tz = 1.0 + sign * nx * nx * a, sign * b, -sign * nx
        bx, by, bz = b, sign + ny * ny * a, -ny
        ox = V[p, 0] * tx + V[p, 1] * ty + V[p, 2] * tz
        oy = V[p, 0] * bx + V[p, 1] * by + V[p, 2] * bz
        oz = max(V[p, 0] * nx + V[p, 1] * ny + V[p, 2] * nz, 1e-6)
        norm = math.sqrt(ox * ox + oy * oy + oz * oz)
        ox, oy, oz = ox / norm, oy / norm, oz / norm
        # Heitz 2018, listing 1: the view in the stretched configuration
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
        s = 0.5 * (1.0 + vz)
        for m in range(u.shape[1]):
            r = math.sqrt(u[p, m, 0])
            phi = 2.0 * math.pi * u[p, m, 1]
            q1 = r * math.cos(phi)
            q2 = (1.0 - s) * math.sqrt(1.0 - q1 * q1) + s * r * math.sin(phi)
            q3 = math.sqrt(max(0.0, 1.0 - q1 * q1 - q2 * q2))
            hx = alpha * (q1 * t1x + q2 * t2x + q3 * vx)
            hy = alpha * (q1 * t1y + q2 * t2y + q3 * vy)
            hz = max(0.0, q1 * t1z + q2 * t2z + q3 * vz)
            norm = math.sqrt(hx * hx + hy * hy + hz * hz)
            hx, hy, hz = hx / norm, hy / norm, hz / norm
            # i = 2 (o·h) h − o; weight F(o·h) G_1(i) (Eq. (34), Walter et al. 2007)
            oh = ox * hx + oy * hy + oz * hz
            ix, iy, iz = 2.0 * oh * hx - ox, 2.0 * oh * hy - oy, 2.0 * oh * hz - oz
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


@numba.njit(cache=False)
def polymer_shade_parts_kernel(E_d, S, B, L, E_effect, D_Tint, Col_B, Col_L, gloss, Mod, out):
    """Twin of ``shrm.polymer_material.polymer_shade_parts``: Eq. (1), Herbert et al., one pass.

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
            # Eq. (2), Herbert et al.: E_d D_polymer Tint_polymer (1 − Mod_effect), then Eq. (1),
            # Herbert et al.: + gloss S + Col_trans ((1 − u) B + u L)
            I = E_d[p, b] * (D_Tint[b] * (1.0 - m)) + S[p, b] * gloss + B[p, b] * Col_B[b]
            if use_L:
                I += L[p, b] * Col_L[b]
            # Eq. (3), Herbert et al.: + E_effect Mod_effect
            if use_effect:
                I += E_effect[p, b] * m
            out[p, b] = I
    return out
