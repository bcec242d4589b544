"""numba twins of the readable NumPy functions of ``shrm.sh`` and ``shrm.prefilter``.

Each kernel keeps the names and equation comments of its NumPy reference, never validates, never
prints, and writes into an output array that the public entry point allocated. The equality tests
live in ``tests/shrm``.
"""

from __future__ import annotations

import math

import numpy as np

from reference.jit import njit

# Rescaling step of the extended-exponent recurrence: values are kept in [2^-SCALE, 2^SCALE].
SCALE_BITS = 200
_BIG = 2.0**SCALE_BITS
_SMALL = 2.0**-SCALE_BITS
_INV_SQRT_4PI = 1.0 / math.sqrt(4.0 * math.pi)


@njit
def _sectoral_next(p, e, m, sin_theta, scaled):
    """λ_mm from λ_{m-1,m-1}, as (mantissa, binary exponent); the exponent moves only if scaled."""
    # Sectoral recurrence: λ_mm = -sqrt((2m+1)/(2m)) sin θ λ_{m-1,m-1}
    p = -math.sqrt((2.0 * m + 1.0) / (2.0 * m)) * sin_theta * p
    if scaled and p != 0.0 and abs(p) < _SMALL:
        p *= _BIG
        e -= SCALE_BITS
    return p, e


@njit
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


@njit
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


@njit
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


@njit
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


@njit
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


@njit
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


@njit
def _power(t, s):
    """``t**s``; by repeated squaring when ``s`` is a whole number from 1 to 64.

    Lambert's s = 1 and the Phong lobes' whole exponents: the general ``pow`` was a third of the
    brute-force kernel's time (equal to 1e-15).
    """
    if s == math.floor(s) and 1.0 <= s <= 64.0:
        result, base, e = 1.0, t, int(s)
        while e:
            if e & 1:
                result *= base
            base *= base
            e >>= 1
        return result
    return t**s


@njit
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
            kern = scale * _power(t, s) * weights[p]
            for c in range(C):
                out[k, c] += radiance[p, c] * kern


@njit
def _phi_breaks_into(breaks, nx, ny, nz, H, W):
    """Twin of ``shrm.texel_irradiance.phi_breaks`` into ``breaks`` (sorted); returns the count."""
    for i in range(W + 1):
        breaks[i] = 2.0 * np.pi * i / W
    count = W + 1
    R, c = math.hypot(nx, nz), ny
    if R == 0.0:
        return count
    phi_0 = math.atan2(nz, nx)
    for e in range(1, H):
        # R sin(φ − φ_0) = −c cot θ_e
        s = -c / (math.tan(math.pi * e / H) * R)
        if abs(s) <= 1.0:
            arc = math.asin(s)
            breaks[count] = (phi_0 + arc) % (2.0 * np.pi)
            breaks[count + 1] = (phi_0 + np.pi - arc) % (2.0 * np.pi)
            count += 2
    breaks[:count].sort()
    return count


@njit
def _texel_weights_into(T, nx, c, nz, H, W, q_x, q_w, a_k, edge_a, edge_c, breaks):
    """T[j, i] = ∫_texel max(0, n·ω) dω (``shrm.texel_irradiance.texel_weights``), into ``T``."""
    d_phi = 2.0 * np.pi / W
    Q = q_x.shape[0]
    # a(φ) = n_x sin φ − n_z cos φ = R sin(φ − φ_0)
    R = math.hypot(nx, nz)
    phi_0 = math.atan2(nz, nx)
    T[:, :] = 0.0
    count = _phi_breaks_into(breaks, nx, c, nz, H, W)
    for b in range(count - 1):
        left, width = breaks[b], breaks[b + 1] - breaks[b]
        if width <= 0.0:
            continue
        mid = left + 0.5 * width
        i = min(int(mid / d_phi), W - 1)
        A = 0.0
        for k in range(Q):
            a_k[k] = R * math.sin(left + 0.5 * width * (q_x[k] + 1.0) - phi_0)
            A += 0.5 * width * q_w[k] * a_k[k]
        # between breaks the horizon stays in one row (or none): the rows wholly lit take
        # Σ_k w_k F(edges), the row it crosses takes F(θ*) per node
        a_mid = a_k[Q // 2] if Q % 2 == 1 else R * math.sin(mid - phi_0)  # an odd rule's centre
        star_row = min(int((math.atan2(c, -a_mid) % math.pi) * H / math.pi), H - 1)
        if c > 0.0:
            first, last = 0, star_row  # wholly lit rows [first, last)
        elif c < 0.0:
            first, last = star_row + 1, H
        else:
            first, last = 0, (H if a_mid > 0.0 else 0)
            star_row = -1
        if star_row >= 0:
            # F(θ) = a (θ/2 − sin 2θ / 4) + c sin²θ / 2 at θ*, against the row's lit edge:
            # there (sin θ*, cos θ*) = (|c|, −a sgn c) / √(a² + c²), so F(θ*) = (a θ* + c)/2
            e = star_row if c > 0.0 else star_row + 1
            for k in range(Q):
                a = a_k[k]
                F_star = 0.5 * (a * (math.atan2(c, -a) % math.pi) + c)
                F_edge = a * edge_a[e] + c * edge_c[e]
                lit = F_star - F_edge if c > 0.0 else F_edge - F_star
                T[star_row, i] += 0.5 * width * q_w[k] * lit
        for j in range(first, last):
            # Σ_k w_k (F(θ_{j+1}) − F(θ_j)) = A Δ(θ/2 − sin 2θ/4) + c width Δ(sin²θ/2)
            T[j, i] += A * (edge_a[j + 1] - edge_a[j]) + c * width * (edge_c[j + 1] - edge_c[j])


@njit
def irradiance_texel_constant_kernel(normals, radiance, H, W, q_x, q_w, out):
    """Twin of ``shrm.texel_irradiance.irradiance_texel_constant``: Σ_t L_t ∫_t max(0, n·ω) dω."""
    # θ/2 − sin 2θ / 4 and sin²θ / 2 at the row edges θ_e = eπ/H
    edge_a = np.empty(H + 1)
    edge_c = np.empty(H + 1)
    for e in range(H + 1):
        theta = math.pi * e / H
        edge_a[e] = 0.5 * theta - 0.25 * math.sin(2.0 * theta)
        edge_c[e] = 0.5 * math.sin(theta) ** 2
    a_k = np.empty(q_x.shape[0])
    breaks = np.empty(W + 1 + 2 * (H - 1))
    # the weights of a batch of normals, then E = T L for the batch at once (a matrix product)
    batch = 256
    T = np.empty((batch, H, W))
    for start in range(0, normals.shape[0], batch):
        count = min(batch, normals.shape[0] - start)
        for p in range(count):
            n = normals[start + p]
            _texel_weights_into(T[p], n[0], n[1], n[2], H, W, q_x, q_w, a_k, edge_a, edge_c, breaks)
        out[start : start + count] += np.dot(T[:count].reshape(count, H * W), radiance)


__all__ = [
    "irradiance_texel_constant_kernel",
    "legendre_analysis_kernel",
    "legendre_synthesis_kernel",
    "legendre_table_kernel",
    "prefilter_bruteforce_power_kernel",
    "prefilter_bruteforce_table_kernel",
    "sh_evaluate_kernel",
]


@njit
def _polar_rotate_each_kernel(x, cos_ma, sin_ma, partner, out):
    """Twin of ``shrm.shrm._polar_rotate_each``: x, out (outer, angle, inner, (P+1)²).

    ``cos_ma[j, i] = cos(|m_i| a_j)`` and ``sin_ma[j, i] = sgn(m_i) sin(|m_i| a_j)``.
    """
    n_outer, n_angle, n_inner, n = x.shape
    for o in range(n_outer):
        for j in range(n_angle):
            for k in range(n_inner):
                for i in range(n):
                    # c'_m = cos(|m| a) c_m + sgn(m) sin(|m| a) c_{-m}
                    out[o, j, k, i] = (
                        cos_ma[j, i] * x[o, j, k, i] + sin_ma[j, i] * x[o, j, k, partner[i]]
                    )


@njit
def _pair_sum_kernel(f, cosine, Lw, texel, point, out):
    """Twin of ``shrm.split.angular_sum``'s spectral sum over its (point, texel) pairs.

    ``out[point[q]] += f[q] · cosine[q] · Lw[texel[q]]`` for every pair q, without the (pairs, C)
    temporaries of the NumPy form.
    """
    for q in range(f.shape[0]):
        a, b, c = point[q], texel[q], cosine[q]
        for ch in range(f.shape[1]):
            # The reflection equation (R&H 2002): Σ_k f cos θ_i L_k w_k
            out[a, ch] += f[q, ch] * (c * Lw[b, ch])
