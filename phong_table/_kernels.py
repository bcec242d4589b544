"""numba twins of the readable NumPy functions in ``phong_table`` (same names plus ``_kernel``).

Each kernel is the compiled twin of a NumPy reference, and ``tests/phong_table/test_kernels.py``
shows that the two agree to ~1e-12:

- :func:`shade_exact_kernel` ↔ ``phong_table.render.shade_exact``: the exact spectral shading, one
  ``ln t`` per pixel and one ``exp`` per band (the speed baseline);
- :func:`shade_table_kernel` ↔ ``phong_table.render.shade_table``: the same pixels through a table
  of Eq. (11), Wang et al. with any registered interpolation (it calls that interpolation's kernel
  of :data:`TABLE_KERNELS`, which a render calls directly, so it compiles only that one);
- :func:`table_error_kernel` ↔ ``phong_table.placement.table_error``: the node density of the
  error-equidistributing placement;
- :func:`tabulate_kernel` ↔ ``phong_table.table.tabulate``: the table's values, slopes and index;
- :func:`light_geometry_kernel` ↔ ``phong_table.render.light_geometry``: ``cos θ``, ``t`` and
  ``f_att`` per pixel from the G-buffer (``phong_cosines``, ``attenuation_Wang``);
- the private ``_fine_weights_kernel`` ↔ ``phong_table.placement._fine_weights``,
  ``_zero_below_kernel`` ↔ ``phong_table.table.zero_below`` and ``_increasing_kernel`` ↔
  ``phong_table.table.increasing``: the small steps of a compiled table build, so that it runs no
  NumPy array operation between its kernels. With them, the shading that follows a build ran
  ~10 % slower on the benchmark machine (Xeon, AVX-512); with NumPy's AVX-512 loops disabled
  (``NPY_DISABLE_CPU_FEATURES``) most of that went, so we think they lower the core's clock.

The private helpers (``_interval``, ``_linear``, ``_monotone_row``, ``_monotone_channel``,
``_parabolic_row``, ``_parabolic_w_row``, ``_write``) are inlined into the render kernels;
``_monotone_records``, ``_parabolic_records`` and ``_parabolic_w_records`` pack a table's monotone
cubics and parabolas once per call, and one pixel loop per interpolation reads them. No kernel
sets ``fastmath``.
"""

from __future__ import annotations

import math

import numpy as np

from reference.jit import njit

#: ``exp(x)`` is below the smallest normal double for ``x`` under this; such terms are skipped,
#: since a subnormal result takes the C library's slow path and the term is below 2.2e-308 anyway.
LOG_SMALLEST_NORMAL = -708.39

#: Entries of a monotone table row (values and Horner coefficients) smaller than this in magnitude
#: are read as 0 by the table kernel (Erratum E38): products ``c s^k`` of such tiny coefficients
#: land among the subnormal doubles, whose arithmetic is ~50x slower (the R3 far view took 2.5x as
#: long with them), and each flushed entry moves a pixel by less than 1e-290 (peaks are ~1), as
#: the exact kernel skips the terms below the smallest normal double.
TABLE_FLUSH = 1e-290

#: Interpolation codes the table kernel understands; ``INTERPOLATION_METHODS`` stores them.
LINEAR, PARABOLIC, PARABOLIC_W, MONOTONE = 0, 1, 2, 3
#: Smallest node spacing of a stencil in the rescaled w = ir(t) (its span is 1) for which the
#: parabola is taken in w; below it w cannot resolve the nodes (t^(an+1) has underflowed or the
#: nodes crowd at w = 0) and the parabola is taken in t
#: (``phong_table.interpolation.interpolate_parabolic_w``).
W_RESOLUTION = 1e-6


@njit
def light_geometry_kernel(position, normal, view, light_position, attenuation, out):
    """``cos θ``, ``t`` and ``f_att`` per pixel, into ``out`` (3, N).

    Twin of ``phong_table.render.light_geometry`` (``phong_cosines`` and ``attenuation_Wang``).
    """
    for p in range(position.shape[0]):
        Lx = light_position[0] - position[p, 0]
        Ly = light_position[1] - position[p, 1]
        Lz = light_position[2] - position[p, 2]
        d = math.sqrt(Lx * Lx + Ly * Ly + Lz * Lz)
        Lx, Ly, Lz = Lx / d, Ly / d, Lz / d
        # Eq. (1), Wang et al. (Erratum E2: min, not max): f_att = min(1/(c1 + c2 d + c3 d²), 1)
        denominator = attenuation[0] + attenuation[1] * d + attenuation[2] * d * d
        out[2, p] = 1.0 if denominator <= 1.0 else 1.0 / denominator
        Nx, Ny, Nz = normal[p, 0], normal[p, 1], normal[p, 2]
        N_dot_L = Nx * Lx + Ny * Ly + Nz * Lz
        if N_dot_L <= 0.0:
            out[0, p] = 0.0
            out[1, p] = 0.0
            continue
        # Eq. (1), Wang et al., Figure 1: R = 2 (N·L) N − L and t = cos α = R·V
        Rx = 2.0 * N_dot_L * Nx - Lx
        Ry = 2.0 * N_dot_L * Ny - Ly
        Rz = 2.0 * N_dot_L * Nz - Lz
        t = Rx * view[p, 0] + Ry * view[p, 1] + Rz * view[p, 2]
        out[0, p] = N_dot_L
        out[1, p] = min(max(t, 0.0), 1.0)
    return out


@njit(inline="always")
def _interval(nodes, guide, steps, uniform, t):
    """Index i of the interval ``[t_i, t_{i+1}]`` holding ``t`` (``searchsorted`` − 1, clipped).

    Branch-free, so that it compiles to conditional moves.
    """
    m = nodes.size - 1
    if uniform:
        # O(1): uniform nodes t_i = i/m; rounding of t·m can land one interval off
        i = min(int(t * m), m - 1)
        i -= np.int64(nodes[i] > t)
        i += np.int64(nodes[min(i + 1, m)] <= t) * np.int64(i < m - 1)
        return i
    # inverse-map index: cell c of K uniform cells holds intervals guide[c] .. guide[c+1]; one
    # more on each side covers the rounding of t·K; ``steps`` halvings of the cell's widest range
    # find the largest t_i <= t
    K = guide.size - 1
    c = min(int(t * K), K - 1)
    lo = max(guide[c] - 1, 0)
    hi = min(guide[c + 1] + 1, m - 1)
    for _ in range(steps):
        mid = min((lo + hi + 1) >> 1, hi)
        below = nodes[mid] <= t
        lo = mid if below else lo
        hi = hi if below else mid - 1
    return lo


@njit(inline="always")
def _linear(nodes, values, inv_width, i, t):
    """The chord of interval ``i`` at ``t`` (3 channels)."""
    s = (t - nodes[i]) * inv_width[i]
    return (
        values[i, 0] + s * (values[i + 1, 0] - values[i, 0]),
        values[i, 1] + s * (values[i + 1, 1] - values[i, 1]),
        values[i, 2] + s * (values[i + 1, 2] - values[i, 2]),
    )


@njit
def _monotone_records(nodes, values, inv_width, cubic):
    """The monotone cubics of a table, one row of 20 per interval (read by the table kernel).

    Row ``i``: ``t_i``, ``1/h_i``, then per channel ``v_i``, the Horner cubic ``c1, c2, c3`` and
    the interval's two values' min and max (what :func:`_monotone_row` reads); entries below
    :data:`TABLE_FLUSH` in magnitude are 0 (Erratum E38).
    """
    m = nodes.size - 1
    records = np.empty((m, 20))
    for i in range(m):
        records[i, 0] = nodes[i]
        records[i, 1] = inv_width[i]
        for c in range(3):
            v0 = _flush(values[i, c])
            v1 = _flush(values[i + 1, c])
            records[i, 2 + c] = v0
            records[i, 5 + c] = _flush(cubic[i, c, 0])
            records[i, 8 + c] = _flush(cubic[i, c, 1])
            records[i, 11 + c] = _flush(cubic[i, c, 2])
            records[i, 14 + c] = min(v0, v1)
            records[i, 17 + c] = max(v0, v1)
    return records


@njit
def _parabolic_records(nodes, values):
    """The t-parabolas of a table (Wang et al., §5), one row of 10 per stencil node ``j``.

    Row ``j`` (in [1, m − 1]): ``t_j``, then per channel ``y_j``, ``B`` and ``C`` of the Lagrange
    parabola through nodes ``j − 1, j, j + 1``, written about ``t_j`` as
    ``P(t_j + d) = y_j + d (B + d C)`` with Newton's divided differences
    (``C = f[t_{j−1}, t_j, t_{j+1}]``, ``B = f[t_{j−1}, t_j] + h_{j−1} C``). Entries below
    :data:`TABLE_FLUSH` are 0 (Erratum E38). Rows 0 and ``m`` are not read.
    """
    m = nodes.size - 1
    records = np.zeros((m + 1, 10))
    for j in range(1, m):
        records[j, 0] = nodes[j]
        _write_parabola(records, j, 1, nodes[j - 1], nodes[j], nodes[j + 1], values)
    return records


@njit(inline="always")
def _write_parabola(records, j, first, x0, x1, x2, values):
    """Write stencil ``j``'s parabola about ``x1``: ``y_j``, ``B``, ``C`` from column ``first``.

    The parabola goes through ``(x0, x1, x2)`` and the values of nodes ``j − 1, j, j + 1``.
    """
    h0 = x1 - x0
    h1 = x2 - x1
    for c in range(3):
        # Newton's divided differences: f[x0, x1], f[x1, x2] and C = f[x0, x1, x2]
        f01 = (values[j, c] - values[j - 1, c]) / h0
        f12 = (values[j + 1, c] - values[j, c]) / h1
        C = (f12 - f01) / (h0 + h1)
        records[j, first + c] = _flush(values[j, c])
        records[j, first + 3 + c] = _flush(f01 + h0 * C)
        records[j, first + 6 + c] = _flush(C)


@njit
def _parabolic_w_records(nodes, values, a):
    """The w-parabolas of a table (``interpolate_parabolic_w``): per stencil and per interval.

    ``stencils``, one row of 12 per stencil node ``j`` in [1, m − 1]: the middle abscissa, ``ln``
    of the top node, 1 if the parabola is taken in ``ŵ = exp(a (ln x − ln t_{j+1}))`` (else in t,
    below :data:`W_RESOLUTION`), then per channel ``y_j``, ``B``, ``C`` of the parabola about the
    middle abscissa (as :func:`_parabolic_records`). ``intervals``, one row per interval ``i``:
    ``ln t_{i+1}`` and ``ŵ(t_i)`` relative to it, with which the nearest node in w is found.
    """
    m = nodes.size - 1
    stencils = np.zeros((m + 1, 12))
    intervals = np.zeros((m, 2))
    for i in range(m):
        log_top = math.log(nodes[i + 1])
        intervals[i, 0] = log_top
        intervals[i, 1] = math.exp(a * (math.log(nodes[i]) - log_top)) if nodes[i] > 0.0 else 0.0
    for j in range(1, m):
        x0, x1, x2 = nodes[j - 1], nodes[j], nodes[j + 1]
        # Eq. (14), Wang et al.: w = t^(an+1), relative to the top node (Erratum E19)
        log_top = math.log(x2)
        y0 = math.exp(a * (math.log(x0) - log_top)) if x0 > 0.0 else 0.0
        y1 = math.exp(a * (math.log(x1) - log_top))
        in_w = min(y1 - y0, 1.0 - y1) >= W_RESOLUTION
        if in_w:
            x0, x1, x2 = y0, y1, 1.0
        stencils[j, 0] = x1
        stencils[j, 1] = log_top
        stencils[j, 2] = 1.0 if in_w else 0.0
        _write_parabola(stencils, j, 3, x0, x1, x2, values)
    return stencils, intervals


@njit(inline="always")
def _parabolic_w_row(stencils, j):
    """Row ``j`` of :func:`_parabolic_w_records`: abscissa, ln top, in w, ``y``, ``B``, ``C``."""
    return (
        stencils[j, 0],
        stencils[j, 1],
        stencils[j, 2] > 0.0,
        (stencils[j, 3], stencils[j, 4], stencils[j, 5]),
        (stencils[j, 6], stencils[j, 7], stencils[j, 8]),
        (stencils[j, 9], stencils[j, 10], stencils[j, 11]),
    )


@njit(inline="always")
def _parabolic_row(records, j):
    """Row ``j`` of :func:`_parabolic_records`: ``t_j`` and the 3-tuples ``y_j``, ``B``, ``C``."""
    return (
        records[j, 0],
        (records[j, 1], records[j, 2], records[j, 3]),
        (records[j, 4], records[j, 5], records[j, 6]),
        (records[j, 7], records[j, 8], records[j, 9]),
    )


@njit(inline="always")
def _flush(x):
    """``x``, or 0 when ``|x|`` is below :data:`TABLE_FLUSH`."""
    return x if abs(x) >= TABLE_FLUSH else 0.0


@njit(inline="always")
def _monotone_row(records, i):
    """Row ``i`` of :func:`_monotone_records`: ``1/h``, then 3-tuples ``v_i``, c1, c2, c3, min, max.

    The loop holds them in registers while the pixels stay in interval ``i``.
    """
    return (
        records[i, 1],
        (records[i, 2], records[i, 3], records[i, 4]),
        (records[i, 5], records[i, 6], records[i, 7]),
        (records[i, 8], records[i, 9], records[i, 10]),
        (records[i, 11], records[i, 12], records[i, 13]),
        (records[i, 14], records[i, 15], records[i, 16]),
        (records[i, 17], records[i, 18], records[i, 19]),
    )


@njit(inline="always")
def _monotone_channel(v, c1, c2, c3, low, high, s):
    """The Hermite cubic of one channel: ``v_i + s (c1 + s (c2 + s c3))``.

    Never outside the interval's two values ``low`` and ``high`` (PCHIP is monotone there; this
    catches rounding).
    """
    return min(max(v + s * (c1 + s * (c2 + s * c3)), low), high)


@njit(inline="always")
def _write(out, p, A, D, f_att, cos_theta, r, g, b):
    """Eq. (7), Wang et al.: ambient + f_att (cos θ · diffuse RGB + specular RGB), pixel ``p``.

    ``A`` and ``D`` are the ambient and diffuse RGB as 3-tuples, read once before the pixel loop
    (read from arrays in the loop, they are reloaded after every store to ``out``).
    """
    out[p, 0] = A[0] + f_att * (cos_theta * D[0] + r)
    out[p, 1] = A[1] + f_att * (cos_theta * D[1] + g)
    out[p, 2] = A[2] + f_att * (cos_theta * D[2] + b)


@njit
def shade_exact_kernel(cos_theta, t, f_att, diffuse_RGB, C, n, ambient_RGB, out):
    """Exact spectral Phong shading to linear RGB: one ``ln t`` per pixel, one ``exp`` per band.

    Twin of ``phong_table.render.shade_exact`` (Eq. (2), Wang et al., through Eq. (7) and
    Eq. (11), Wang et al.); writes ``out`` (N, 3).
    """
    n_bands = n.size
    A = ambient_RGB[0], ambient_RGB[1], ambient_RGB[2]
    D = diffuse_RGB[0], diffuse_RGB[1], diffuse_RGB[2]
    for p in range(t.size):
        r = 0.0
        g = 0.0
        b = 0.0
        t_p = t[p]
        if t_p > 0.0:
            log_t = math.log(t_p)
            # Eq. (11), Wang et al.: Σ_λ C(λ) t^{n(λ)}, t^n = exp(n ln t)
            for k in range(n_bands):
                x = n[k] * log_t
                if x < LOG_SMALLEST_NORMAL:
                    continue
                power = math.exp(x)
                r += C[k, 0] * power
                g += C[k, 1] * power
                b += C[k, 2] * power
        else:
            # t = 0: t^n is 0, except 0^0 = 1
            for k in range(n_bands):
                if n[k] == 0.0:
                    r += C[k, 0]
                    g += C[k, 1]
                    b += C[k, 2]
        # Eq. (7), Wang et al.: ambient + f_att (cos θ · diffuse RGB + specular RGB)
        _write(out, p, A, D, f_att[p], cos_theta[p], r, g, b)
    return out


@njit(inline="always")
def _shade_monotone_loop(
    cos_theta,
    t,
    f_att,
    diffuse_RGB,
    ambient_RGB,
    nodes,
    values,
    records,
    guide,
    steps,
    uniform,
    zero_below,
    out,
):
    """The pixel loop of :func:`shade_table_kernel` for the monotone cubic (the default).

    As :func:`_shade_linear_loop`, with the hinted interval's ends and packed row
    (:func:`_monotone_records`) held in registers until the next miss: read from the arrays on
    every pixel, they are reloaded after each store to ``out`` (which numba cannot prove apart
    from them), and the loop was bound by those loads (10-15 % slower).
    """
    A = ambient_RGB[0], ambient_RGB[1], ambient_RGB[2]
    D = diffuse_RGB[0], diffuse_RGB[1], diffuse_RGB[2]
    f_0 = values[0, 0], values[0, 1], values[0, 2]
    last = nodes.size - 2
    hint = 0
    t_i, t_next = nodes[0], nodes[1]
    inv_h, v, c1, c2, c3, low, high = _monotone_row(records, 0)
    for p in range(t.size):
        t_p = t[p]
        if t_p < zero_below:
            r, g, b = 0.0, 0.0, 0.0
        elif t_p == 0.0:
            r, g, b = f_0
        else:
            if not (t_i <= t_p and t_p < t_next):
                i = hint
                i += np.int64(nodes[i + 1] <= t_p) * np.int64(i < last)
                i -= np.int64(nodes[i] > t_p) * np.int64(i > 0)
                if not (nodes[i] <= t_p and t_p < nodes[i + 1]):
                    i = _interval(nodes, guide, steps, uniform, t_p)
                hint = i
                t_i, t_next = nodes[i], nodes[i + 1]
                inv_h, v, c1, c2, c3, low, high = _monotone_row(records, i)
            s = (t_p - t_i) * inv_h
            r = _monotone_channel(v[0], c1[0], c2[0], c3[0], low[0], high[0], s)
            g = _monotone_channel(v[1], c1[1], c2[1], c3[1], low[1], high[1], s)
            b = _monotone_channel(v[2], c1[2], c2[2], c3[2], low[2], high[2], s)
        _write(out, p, A, D, f_att[p], cos_theta[p], r, g, b)


@njit(inline="always")
def _shade_parabolic_loop(
    cos_theta,
    t,
    f_att,
    diffuse_RGB,
    ambient_RGB,
    nodes,
    values,
    records,
    guide,
    steps,
    uniform,
    zero_below,
    out,
):
    """The pixel loop of :func:`shade_table_kernel` for the t-parabola (``PARABOLIC``).

    As :func:`_shade_monotone_loop`: while the pixels stay in interval ``i``, its ends and the
    rows (:func:`_parabolic_records`) of its two possible stencils, ``max(i, 1)`` and
    ``min(i + 1, m − 1)``, are held in registers; the nearer end picks one, as
    ``phong_table.interpolation.interpolate_parabolic`` does.
    """
    A = ambient_RGB[0], ambient_RGB[1], ambient_RGB[2]
    D = diffuse_RGB[0], diffuse_RGB[1], diffuse_RGB[2]
    f_0 = values[0, 0], values[0, 1], values[0, 2]
    last = nodes.size - 2
    hint = 0
    t_i, t_next = nodes[0], nodes[1]
    x_lo, y_lo, B_lo, C_lo = _parabolic_row(records, 1)
    x_hi, y_hi, B_hi, C_hi = _parabolic_row(records, min(1, last))
    for p in range(t.size):
        t_p = t[p]
        if t_p < zero_below:
            r, g, b = 0.0, 0.0, 0.0
        elif t_p == 0.0:
            r, g, b = f_0
        else:
            if not (t_i <= t_p and t_p < t_next):
                i = hint
                i += np.int64(nodes[i + 1] <= t_p) * np.int64(i < last)
                i -= np.int64(nodes[i] > t_p) * np.int64(i > 0)
                if not (nodes[i] <= t_p and t_p < nodes[i + 1]):
                    i = _interval(nodes, guide, steps, uniform, t_p)
                hint = i
                t_i, t_next = nodes[i], nodes[i + 1]
                x_lo, y_lo, B_lo, C_lo = _parabolic_row(records, max(i, 1))
                x_hi, y_hi, B_hi, C_hi = _parabolic_row(records, min(i + 1, last))
            # the stencil of the nearest node (kept in [1, m − 1])
            if t_p - t_i <= t_next - t_p:
                d = t_p - x_lo
                r = y_lo[0] + d * (B_lo[0] + d * C_lo[0])
                g = y_lo[1] + d * (B_lo[1] + d * C_lo[1])
                b = y_lo[2] + d * (B_lo[2] + d * C_lo[2])
            else:
                d = t_p - x_hi
                r = y_hi[0] + d * (B_hi[0] + d * C_hi[0])
                g = y_hi[1] + d * (B_hi[1] + d * C_hi[1])
                b = y_hi[2] + d * (B_hi[2] + d * C_hi[2])
        _write(out, p, A, D, f_att[p], cos_theta[p], r, g, b)


@njit(inline="always")
def _shade_parabolic_w_loop(
    cos_theta,
    t,
    f_att,
    diffuse_RGB,
    ambient_RGB,
    nodes,
    values,
    stencils,
    intervals,
    guide,
    steps,
    uniform,
    a,
    zero_below,
    out,
):
    """The pixel loop of :func:`shade_table_kernel` for the w-parabola (``PARABOLIC_W``).

    As :func:`_shade_parabolic_loop`, with the rows of :func:`_parabolic_w_records`: one ``ln t``
    and one ``exp`` find the nearest node in w, and a second ``exp`` gives ``ŵ`` only where the
    stencil's top node is not the interval's (the Lagrange weights from the nodes took five ``ln``
    and four ``exp`` a pixel).
    """
    A = ambient_RGB[0], ambient_RGB[1], ambient_RGB[2]
    D = diffuse_RGB[0], diffuse_RGB[1], diffuse_RGB[2]
    f_0 = values[0, 0], values[0, 1], values[0, 2]
    last = nodes.size - 2
    hint = 0
    t_i, t_next = nodes[0], nodes[1]
    log_top, w_i = intervals[0, 0], intervals[0, 1]
    lo = _parabolic_w_row(stencils, 1)
    hi = _parabolic_w_row(stencils, min(1, last))
    for p in range(t.size):
        t_p = t[p]
        if t_p < zero_below:
            r, g, b = 0.0, 0.0, 0.0
        elif t_p == 0.0:
            r, g, b = f_0
        else:
            if not (t_i <= t_p and t_p < t_next):
                i = hint
                i += np.int64(nodes[i + 1] <= t_p) * np.int64(i < last)
                i -= np.int64(nodes[i] > t_p) * np.int64(i > 0)
                if not (nodes[i] <= t_p and t_p < nodes[i + 1]):
                    i = _interval(nodes, guide, steps, uniform, t_p)
                hint = i
                t_i, t_next = nodes[i], nodes[i + 1]
                log_top, w_i = intervals[i, 0], intervals[i, 1]
                lo = _parabolic_w_row(stencils, max(i, 1))
                hi = _parabolic_w_row(stencils, min(i + 1, last))
            # Eq. (14), Wang et al.: the nearest node in w, relative to the interval's top node
            log_t = math.log(t_p)
            w = math.exp(a * (log_t - log_top))
            x1, top, in_w, y, B, C = lo if w - w_i <= 1.0 - w else hi
            x = t_p
            if in_w:
                x = w if top == log_top else math.exp(a * (log_t - top))
            d = x - x1
            r = y[0] + d * (B[0] + d * C[0])
            g = y[1] + d * (B[1] + d * C[1])
            b = y[2] + d * (B[2] + d * C[2])
        _write(out, p, A, D, f_att[p], cos_theta[p], r, g, b)


@njit(inline="always")
def _shade_linear_loop(
    cos_theta,
    t,
    f_att,
    diffuse_RGB,
    ambient_RGB,
    nodes,
    values,
    inv_width,
    guide,
    steps,
    uniform,
    zero_below,
    out,
):
    """The pixel loop of :func:`shade_table_kernel` for linear interpolation.

    The lookup of every interpolation's loop is this one's.
    """
    # below ``zero_below`` every interpolation returns exactly 0 (SpecularTable.zero_below); at
    # t = 0 every interpolation returns the first tabulated value exactly (unlit pixels)
    A = ambient_RGB[0], ambient_RGB[1], ambient_RGB[2]
    D = diffuse_RGB[0], diffuse_RGB[1], diffuse_RGB[2]
    f_0 = values[0, 0], values[0, 1], values[0, 2]
    last = nodes.size - 2
    # Neighbouring pixels of a raster-ordered G-buffer see nearby t: the interval found last
    # (``hint``) is tried first, and :func:`_interval` runs only when it does not hold t. A branch,
    # not a conditional move, so that the CPU runs ahead over pixels that hit. ``hint`` changes only
    # on a miss: reassigned on every pixel (``i = near(..., i)``), the loop ran 2.5x slower, we
    # think because numba/LLVM then made the test a select. The interval found does not depend on
    # the pixel order.
    # On a miss, t has mostly moved to a neighbouring interval (87-99 % of misses on the scenes'
    # views with error tables): one branch-free step towards t is tried before :func:`_interval`.
    # The hinted interval's ends are held in registers until the next miss: read from ``nodes`` on
    # every pixel, they are reloaded after each store to ``out`` (which numba cannot prove apart).
    # (Written out in each loop: moved into an inlined helper, the monotone loop ran 25 % slower.)
    hint = 0
    t_i, t_next = nodes[0], nodes[1]
    for p in range(t.size):
        t_p = t[p]
        if t_p < zero_below:
            r, g, b = 0.0, 0.0, 0.0
        elif t_p == 0.0:
            r, g, b = f_0
        else:
            if not (t_i <= t_p and t_p < t_next):
                i = hint
                i += np.int64(nodes[i + 1] <= t_p) * np.int64(i < last)
                i -= np.int64(nodes[i] > t_p) * np.int64(i > 0)
                if not (nodes[i] <= t_p and t_p < nodes[i + 1]):
                    i = _interval(nodes, guide, steps, uniform, t_p)
                hint = i
                t_i, t_next = nodes[i], nodes[i + 1]
            r, g, b = _linear(nodes, values, inv_width, hint, t_p)
        _write(out, p, A, D, f_att[p], cos_theta[p], r, g, b)


@njit
def shade_table_kernel(
    cos_theta,
    t,
    f_att,
    diffuse_RGB,
    ambient_RGB,
    nodes,
    values,
    inv_width,
    cubic,
    guide,
    steps,
    uniform,
    code,
    a,
    zero_below,
    out,
):
    """Table-based spectral Phong shading to linear RGB: one lookup per pixel, no ``exp``.

    Twin of ``phong_table.render.shade_table`` (Eq. (7) and Eq. (11), Wang et al.; the table
    holds ``f_sp`` without ``f_att``, Erratum E18); writes ``out`` (N, 3). Pixels with ``t`` below
    ``zero_below`` (``SpecularTable.zero_below``: every interpolation of the table is exactly 0
    there) skip the lookup, as the exact kernel skips the bands whose ``t^n`` underflows; the
    result is the same to the bit. ``code`` picks the interpolation's kernel of
    :data:`TABLE_KERNELS`, which the render path calls directly.
    """
    args = (cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, cubic, guide)
    if code == MONOTONE:
        return _shade_table_monotone_kernel(*args, steps, uniform, a, zero_below, out)
    if code == PARABOLIC:
        return _shade_table_parabolic_kernel(*args, steps, uniform, a, zero_below, out)
    if code == PARABOLIC_W:
        return _shade_table_parabolic_w_kernel(*args, steps, uniform, a, zero_below, out)
    return _shade_table_linear_kernel(*args, steps, uniform, a, zero_below, out)


# One kernel per interpolation, each with one pixel loop per lookup (uniform or not), so that no
# loop tests either per pixel or on a miss (with the lookup's kind a runtime value, the uniform
# tables' loops ran up to 25 % slower), and a render compiles only its interpolation's kernel: the
# eight loops in one kernel took 6-9 s to compile, against 1.5-2.5 s for one kernel's two.


@njit
def _shade_table_monotone_kernel(
    cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, cubic, guide, steps,
    uniform, a, zero_below, out,
):  # fmt: skip
    """:func:`shade_table_kernel` for the monotone cubic (the default; ``a`` unused)."""
    # the monotone cubics packed one row per interval: one cache line or two per miss
    records = _monotone_records(nodes, values, inv_width, cubic)
    if uniform:
        _shade_monotone_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, records, guide, steps,
            True, zero_below, out,
        )  # fmt: skip
    else:
        _shade_monotone_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, records, guide, steps,
            False, zero_below, out,
        )  # fmt: skip
    return out


@njit
def _shade_table_parabolic_kernel(
    cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, cubic, guide, steps,
    uniform, a, zero_below, out,
):  # fmt: skip
    """:func:`shade_table_kernel` for the t-parabola (``inv_width``, ``cubic``, ``a`` unused)."""
    # the t-parabolas written about their middle node, one row per stencil
    records = _parabolic_records(nodes, values)
    if uniform:
        _shade_parabolic_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, records, guide, steps,
            True, zero_below, out,
        )  # fmt: skip
    else:
        _shade_parabolic_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, records, guide, steps,
            False, zero_below, out,
        )  # fmt: skip
    return out


@njit
def _shade_table_parabolic_w_kernel(
    cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, cubic, guide, steps,
    uniform, a, zero_below, out,
):  # fmt: skip
    """:func:`shade_table_kernel` for the w-parabola (``inv_width``, ``cubic`` unused)."""
    stencils, intervals = _parabolic_w_records(nodes, values, a)
    if uniform:
        _shade_parabolic_w_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, stencils, intervals,
            guide, steps, True, a, zero_below, out,
        )  # fmt: skip
    else:
        _shade_parabolic_w_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, stencils, intervals,
            guide, steps, False, a, zero_below, out,
        )  # fmt: skip
    return out


@njit
def _shade_table_linear_kernel(
    cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, cubic, guide, steps,
    uniform, a, zero_below, out,
):  # fmt: skip
    """:func:`shade_table_kernel` for linear interpolation (``cubic``, ``a`` unused)."""
    if uniform:
        _shade_linear_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, guide, steps,
            True, zero_below, out,
        )  # fmt: skip
    else:
        _shade_linear_loop(
            cos_theta, t, f_att, diffuse_RGB, ambient_RGB, nodes, values, inv_width, guide, steps,
            False, zero_below, out,
        )  # fmt: skip
    return out


#: The table kernels by interpolation code (:data:`LINEAR`, :data:`PARABOLIC`, ...).
TABLE_KERNELS = (
    _shade_table_linear_kernel,
    _shade_table_parabolic_kernel,
    _shade_table_parabolic_w_kernel,
    _shade_table_monotone_kernel,
)


@njit(inline="always")
def _pchip_end_slope(h0, h1, m0, m1):
    """One-sided three-point end slope, kept shape-preserving (as SciPy's PCHIP)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3.0 * m0):
        return 3.0 * m0
    return d


@njit
def tabulate_kernel(nodes, C, n, cells_per_entry):
    """Values, slopes, inverse widths, Horner cubics, inverse-map index and bisection steps.

    Twin of ``phong_table.table.tabulate`` (Eq. (11), Wang et al. at the nodes).
    """
    m = nodes.size - 1
    n_bands = n.size
    values = np.zeros((m + 1, 3))
    # Eq. (11), Wang et al.: f_sp(t_q) = Σ_λ C(λ) t_q^{n(λ)} (0^0 = 1)
    for q in range(m + 1):
        t = nodes[q]
        log_t = math.log(t) if t > 0.0 else -np.inf
        for k in range(n_bands):
            if t > 0.0:
                x = n[k] * log_t
                if x < LOG_SMALLEST_NORMAL:
                    continue
                power = math.exp(x)
            else:
                power = 1.0 if n[k] == 0.0 else 0.0
            for c in range(3):
                values[q, c] += C[k, c] * power
    # PCHIP slopes: weighted harmonic mean inside, shape-preserving three-point ends
    slopes = np.zeros((m + 1, 3))
    inv_width = np.empty(m)
    for i in range(m):
        inv_width[i] = 1.0 / (nodes[i + 1] - nodes[i])
    for c in range(3):
        if m == 1:
            slopes[0, c] = (values[1, c] - values[0, c]) / (nodes[1] - nodes[0])
            slopes[1, c] = slopes[0, c]
            continue
        for i in range(1, m):
            h0 = nodes[i] - nodes[i - 1]
            h1 = nodes[i + 1] - nodes[i]
            d0 = (values[i, c] - values[i - 1, c]) / h0
            d1 = (values[i + 1, c] - values[i, c]) / h1
            if np.sign(d0) == np.sign(d1) and d0 != 0.0 and d1 != 0.0:
                w1 = 2.0 * h1 + h0
                w2 = h1 + 2.0 * h0
                slopes[i, c] = (w1 + w2) / (w1 / d0 + w2 / d1)
        h0 = nodes[1] - nodes[0]
        h1 = nodes[2] - nodes[1]
        d0 = (values[1, c] - values[0, c]) / h0
        d1 = (values[2, c] - values[1, c]) / h1
        slopes[0, c] = _pchip_end_slope(h0, h1, d0, d1)
        h0 = nodes[m] - nodes[m - 1]
        h1 = nodes[m - 1] - nodes[m - 2]
        d0 = (values[m, c] - values[m - 1, c]) / h0
        d1 = (values[m - 1, c] - values[m - 2, c]) / h1
        slopes[m, c] = _pchip_end_slope(h0, h1, d0, d1)
    # the Hermite cubic of each interval by powers of s: h00, h10, h01, h11 collected
    cubic = np.empty((m, 3, 3))
    for i in range(m):
        h = nodes[i + 1] - nodes[i]
        for c in range(3):
            delta = values[i + 1, c] - values[i, c]
            hd0 = h * slopes[i, c]
            hd1 = h * slopes[i + 1, c]
            cubic[i, c, 0] = hd0
            cubic[i, c, 1] = 3.0 * delta - 2.0 * hd0 - hd1
            cubic[i, c, 2] = hd0 + hd1 - 2.0 * delta
    # inverse-map index: the interval holding c/K for each of the K + 1 cell edges
    K = cells_per_entry * m
    guide = np.empty(K + 1, dtype=np.int64)
    i = 0
    for c in range(K + 1):
        edge = c / K
        while i < m - 1 and nodes[i + 1] <= edge:
            i += 1
        guide[c] = i
    # bisection steps for the widest cell (with the one-interval margins of _interval)
    widest = 1
    for c in range(K):
        widest = max(widest, min(guide[c + 1] + 1, m - 1) - max(guide[c] - 1, 0) + 1)
    steps = 0
    while (1 << steps) < widest:
        steps += 1
    return values, slopes, inv_width, cubic, guide, steps


@njit
def table_error_kernel(t_fine, C, n, entries, floor, p, hedge, grading):
    """Nodes that equidistribute the interpolation error of the true ``f_sp``.

    Twin of ``phong_table.placement.table_error``; one ``exp`` per band and fine point gives both
    ``t^{n−3}`` and ``t^{n−2} = t · t^{n−3}`` (Eq. (11), Wang et al., differentiated). ``p`` is
    the pixel density at the fine grid's midpoints (size 0: none); with it, the max-norm densities
    enter at the weight ``hedge``. ``grading`` > 0 caps the growth of the interval width
    (``phong_table.placement._graded``).
    """
    F = t_fine.size
    n_bands = n.size
    weighted = p.size > 0
    # per band, out of the point loop: the exponent n − 3 and C n(n−1), C n(n−1)(n−2) by channel;
    # bands with n(n−1) = 0 (no curvature) are left out
    e = np.empty(n_bands)
    W = np.empty((n_bands, 6))
    kept = 0
    for k in range(n_bands):
        nk = n[k]
        f2 = nk * (nk - 1.0)
        if f2 == 0.0:
            continue
        f3 = f2 * (nk - 2.0)
        e[kept] = nk - 3.0
        for c in range(3):
            W[kept, c] = C[k, c] * f2
            W[kept, 3 + c] = C[k, c] * f3
        kept += 1
    rho2 = np.zeros(F - 1)
    rho3 = np.zeros(F - 1)
    rho2p = np.zeros(F - 1)
    rho3p = np.zeros(F - 1)
    for q in range(F - 1):
        t = 0.5 * (t_fine[q] + t_fine[q + 1])
        log_t = math.log(t)
        d2r, d2g, d2b, d3r, d3g, d3b = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(kept):
            x = e[k] * log_t
            if x < LOG_SMALLEST_NORMAL:
                continue
            # Eq. (11), Wang et al., differentiated: Σ C n(n−1) t^(n−3) and Σ C n(n−1)(n−2) t^(n−3)
            power = math.exp(x)
            d2r += W[k, 0] * power
            d2g += W[k, 1] * power
            d2b += W[k, 2] * power
            d3r += W[k, 3] * power
            d3g += W[k, 4] * power
            d3b += W[k, 5] * power
        # the second derivative is t times its sum: Σ C n(n−1) t^(n−2)
        f2 = t * max(abs(d2r), abs(d2g), abs(d2b))
        f3 = max(abs(d3r), abs(d3g), abs(d3b))
        # largest error: |f^(k)|^(1/k); pixels' mean square error: (p |f^(k)|²)^(1/(2k+1))
        rho2[q] = math.sqrt(f2)
        rho3[q] = np.cbrt(f3)
        if weighted:
            rho2p[q] = (p[q] * f2 * f2) ** (1.0 / 5.0)
            rho3p[q] = (p[q] * f3 * f3) ** (1.0 / 7.0)
    # normalise each density, take the largest, add the floor, integrate (see phong_table.placement)
    mass2, mass3, mass2p, mass3p = 0.0, 0.0, 0.0, 0.0
    for q in range(F - 1):
        h = t_fine[q + 1] - t_fine[q]
        mass2 += rho2[q] * h
        mass3 += rho3[q] * h
        mass2p += rho2p[q] * h
        mass3p += rho3p[q] * h
    rho = np.zeros(F - 1)
    mass = 0.0
    for q in range(F - 1):
        r2 = rho2[q] / mass2 if mass2 > 0.0 else 0.0
        r3 = rho3[q] / mass3 if mass3 > 0.0 else 0.0
        r2p = rho2p[q] / mass2p if mass2p > 0.0 else 0.0
        r3p = rho3p[q] / mass3p if mass3p > 0.0 else 0.0
        rho[q] = max(hedge * r2, hedge * r3, r2p, r3p) if weighted else max(r2, r3)
        mass += rho[q] * (t_fine[q + 1] - t_fine[q])
    for q in range(F - 1):
        rho[q] = (rho[q] / mass if mass > 0.0 else 0.0) + floor
    if grading > 0.0:
        # the width w = M/(m ρ), capped each way at w(s) + grading·|t − s| (placement._graded)
        total = 0.0
        for q in range(F - 1):
            total += rho[q] * (t_fine[q + 1] - t_fine[q])
        w = np.empty(F - 1)
        for q in range(F - 1):
            w[q] = total / (entries * rho[q])
        for q in range(1, F - 1):
            step = 0.5 * (t_fine[q + 1] - t_fine[q - 1])  # between midpoints q − 1 and q
            w[q] = min(w[q], w[q - 1] + grading * step)
        for q in range(F - 3, -1, -1):
            step = 0.5 * (t_fine[q + 2] - t_fine[q])
            w[q] = min(w[q], w[q + 1] + grading * step)
        for q in range(F - 1):
            rho[q] = total / (entries * w[q])
    cdf = np.zeros(F)
    for q in range(F - 1):
        cdf[q + 1] = cdf[q] + rho[q] * (t_fine[q + 1] - t_fine[q])
    # invert the cumulative density at q/m by linear interpolation (np.interp)
    nodes = np.empty(entries + 1)
    total = cdf[F - 1]
    q = 0
    for k in range(entries + 1):
        target = total * k / entries
        while q < F - 2 and cdf[q + 1] < target:
            q += 1
        width = cdf[q + 1] - cdf[q]
        s = (target - cdf[q]) / width
        nodes[k] = t_fine[q] + min(max(s, 0.0), 1.0) * (t_fine[q + 1] - t_fine[q])
    nodes[0] = t_fine[0]
    nodes[entries] = t_fine[F - 1]
    return nodes


@njit
def _fine_weights_kernel(unit, t_lo, t_hi, r_lo, r_hi, cells):
    """The fine grid on ``[t_lo, t_hi]`` and the pixel density at its midpoints.

    Twin of ``phong_table.placement._fine_weights`` (``np.interp`` between the cell centres of
    ``cells`` over ``[r_lo, r_hi]``, constant beyond the end centres, 0 outside the range); ``p``
    is empty when ``cells`` is.
    """
    F = unit.size
    t_fine = np.empty(F)
    for q in range(F):
        t_fine[q] = t_lo + (t_hi - t_lo) * unit[q]
    K = cells.size
    p = np.zeros(F - 1 if K > 0 else 0)
    if K == 0:
        return t_fine, p
    span = r_hi - r_lo
    first = r_lo + 0.5 * span / K
    last = r_lo + (K - 0.5) * span / K
    for q in range(F - 1):
        x = 0.5 * (t_fine[q] + t_fine[q + 1])
        if not (x >= r_lo and x <= r_hi):
            continue
        if x >= last:
            p[q] = cells[K - 1]
        elif x <= first:
            p[q] = cells[0]
        else:
            k = min(max(int((x - r_lo) * K / span - 0.5), 0), K - 2)
            while k > 0 and r_lo + (k + 0.5) * span / K > x:
                k -= 1
            while k < K - 2 and r_lo + (k + 1.5) * span / K <= x:
                k += 1
            x0 = r_lo + (k + 0.5) * span / K
            x1 = r_lo + (k + 1.5) * span / K
            p[q] = (cells[k + 1] - cells[k]) / (x1 - x0) * (x - x0) + cells[k]
    return t_fine, p


@njit
def _place_seen_error_kernel(
    unit, t_lo, t_hi, entries, r_lo, r_hi, cells, C, n, floor, hedge, grading
):
    """Twin of ``phong_table.placement.place_seen`` with the error placement as ``place``.

    ``t_lo, t_hi`` from ``seen_interval``; ``floor`` is ``ERROR_DENSITY_FLOOR`` (divided here by
    the width placed over, as ``_table_error_compiled`` did). One call places the whole table, so
    that a compiled build runs no Python between its placements.
    """
    # a gap to 0 or 1 narrower than the mean seen interval is taken at once (saves a placement)
    m = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    mean = (t_hi - t_lo) / m
    t_lo = 0.0 if t_lo < mean else t_lo
    t_hi = 1.0 if 1.0 - t_hi < mean else t_hi
    m = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    low, high = 0.0, 1.0
    nodes = np.empty(0)
    for _ in range(3):
        t_fine, p = _fine_weights_kernel(unit, t_lo, t_hi, r_lo, r_hi, cells)
        nodes = table_error_kernel(t_fine, C, n, m, floor / (t_hi - t_lo), p, hedge, grading)
        low = t_lo - (nodes[1] - nodes[0]) if t_lo > 0.0 else 0.0
        high = t_hi + (nodes[m] - nodes[m - 1]) if t_hi < 1.0 else 1.0
        if (low > 0.0 or t_lo == 0.0) and (high < 1.0 or t_hi == 1.0):
            break
        # a margin reaches 0 or 1: the seen interval takes that end and the margin's intervals
        t_lo = t_lo if low > 0.0 else 0.0
        t_hi = t_hi if high < 1.0 else 1.0
        m = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    below = 2 if t_lo > 0.0 else 0
    out = np.empty(entries + 1)
    if below:
        out[0], out[1] = 0.0, low
    # element by element: a slice assignment compiles numba's shape-mismatch error message, which
    # took 3 of the kernel's 5 s to compile
    for q in range(m + 1):
        out[below + q] = nodes[q]
    if t_hi < 1.0:
        out[entries - 1], out[entries] = high, 1.0
    return out


@njit
def _zero_below_kernel(nodes, values):
    """Twin of ``phong_table.table.zero_below``: ``t_z`` with ``z`` two before the first nonzero."""
    first = nodes.size
    for q in range(values.shape[0]):
        if values[q, 0] != 0.0 or values[q, 1] != 0.0 or values[q, 2] != 0.0:
            first = q
            break
    z = first - 2
    return nodes[z] if z >= 1 else -1.0


@njit
def _finite_nonnegative_kernel(values):
    """Every value finite and >= 0 (the check of ``phong_table.placement.check_density``)."""
    for x in values:  # noqa: SIM110 (a loop numba compiles)
        if not (math.isfinite(x) and x >= 0.0):
            return False
    return True


@njit
def _increasing_kernel(nodes):
    """Twin of ``phong_table.table.increasing``: strictly increasing from 0 to 1."""
    if nodes[0] != 0.0 or nodes[nodes.size - 1] != 1.0:
        return False
    for q in range(nodes.size - 1):  # noqa: SIM110 (a loop numba compiles)
        if not nodes[q + 1] > nodes[q]:
            return False
    return True
