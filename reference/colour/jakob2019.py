"""Jakob & Hanika's coefficient table: colours fitted in batches, cached, read by colour-science.

Jakob & Hanika (2019) represent a reflectance by a sigmoid of a quadratic in wavelength,
``R(λ) = S(c0 λ² + c1 λ + c2)`` with ``S(x) = ½ + x / (2 sqrt(1 + x²))`` (Eq. (3), Jakob & Hanika
2019), and fit the three coefficients of each colour by minimizing the CIE 1976 colour difference
to the target (§3.2). Renderers do not fit per texel: they look the coefficients up in a precomputed
3-D table (Mitsuba 3's ``srgb.coeff`` and pbrt-v4's ``RGBToSpectrumTable``, both 64³ per largest
component, made by the authors' ``rgb2spec_opt``). colour-science ships that table's layout and
look-up (``colour.recovery.LUT3D_Jakob2019``: three blocks by largest component, a
``smoothstep(smoothstep(·))`` scale on it, trilinear interpolation), and a per-colour fit
(``find_coefficients_Jakob2019``, L-BFGS-B, about 0.5-2 s a colour), too slow to fill a table here
(4.7 h for 16³ on this project's machine).

:func:`fit_coefficients_Jakob2019` solves the same problem for a whole batch of colours at once:
Gauss-Newton on the three Lab residuals (three equations, three unknowns), with step halving,
on colour-science's objective exactly (its 360-780 nm, 5 nm grid in normalized wavelength, CIE 1931
2°, D65, Lab relative to the illuminant's white). :func:`generate_table_Jakob2019` fills
colour-science's table as ``rgb2spec_opt`` does: every chromaticity of a block at once, starting
in the middle of the brightness scale and stepping up and down it, each step started from the
previous one (64³ in seconds). :func:`table_Jakob2019` loads it from specref's cache folder, or
generates and writes it there atomically; an unusable cache folder gives a warning and an in-memory
table.

References
----------
- W. Jakob, J. Hanika, "A Low-Dimensional Function Space for Efficient Spectral Upsampling",
  Computer Graphics Forum 38(2), 2019.
- W. Jakob et al., Mitsuba 3, ``src/emitters/envmap.cpp``; M. Pharr et al., pbrt-v4,
  ``src/pbrt/util/spectrum.cpp`` (``RGBIlluminantSpectrum``).
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

import numpy as np

from reference.errors import SpecrefWarning, require
from reference.files import default_cache_dir

__all__ = [
    "DEFAULT_TABLE_SIZE",
    "fit_coefficients_Jakob2019",
    "generate_table_Jakob2019",
    "table_Jakob2019",
]

#: Resolution of the coefficient table (per axis, per largest component), as Mitsuba 3 and pbrt-v4.
DEFAULT_TABLE_SIZE = 64

# Gauss-Newton stops when every colour is within this ΔE76 of its target (or after _MAX_ITER).
_TOLERANCE_DELTA_E = 1e-6
_MAX_ITER = 60


@functools.lru_cache(maxsize=1)
def _observer():
    """(M, white): XYZ = M @ R on colour-science's Jakob 2019 grid (Y = 1 for R = 1); the white."""
    import colour
    from colour.recovery.jakob2019 import SPECTRAL_SHAPE_JAKOB2019

    shape = SPECTRAL_SHAPE_JAKOB2019
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    illuminant = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    weighted = cmfs.values * illuminant.values[:, None]  # (n_wl, 3)
    M = (weighted / weighted[:, 1].sum()).T  # (3, n_wl)
    return M, M.sum(axis=1), shape


def _f_Lab(t):
    """CIE 1976 companding and its derivative."""
    eps = (6.0 / 29.0) ** 3
    cube = np.cbrt(np.maximum(t, eps))
    f = np.where(t > eps, cube, t * (841.0 / 108.0) + 4.0 / 29.0)
    df = np.where(t > eps, 1.0 / (3.0 * cube * cube), 841.0 / 108.0)
    return f, df


def _Lab_and_jacobian(c, M, white):
    """Lab (N, 3) of the sigmoid spectra of dimensionless coefficients c (N, 3), and dLab/dc."""
    w = np.linspace(0.0, 1.0, M.shape[1])
    powers = np.stack([w * w, w, np.ones_like(w)])  # (3, n_wl)
    # Eq. (3), Jakob & Hanika 2019: x = c0 w² + c1 w + c2, R = ½ + x / (2 sqrt(1 + x²))
    x = c @ powers
    root = np.sqrt(1.0 + x * x)
    R = 0.5 + x / (2.0 * root)
    dR = 1.0 / (2.0 * root**3)  # dR/dx
    XYZ = R @ M.T
    n_wl = M.shape[1]
    dXYZ = ((dR[:, None, :] * powers).reshape(-1, n_wl) @ M.T).reshape(-1, 3, 3)
    dXYZ = np.swapaxes(dXYZ, 1, 2)  # (N, XYZ, coefficient)
    f, df = _f_Lab(XYZ / white)
    dF = df[..., None] * dXYZ / white[None, :, None]
    A = np.array([[0.0, 116.0, 0.0], [500.0, -500.0, 0.0], [0.0, 200.0, -200.0]])
    Lab = f @ A.T + np.array([-16.0, 0.0, 0.0])
    return Lab, np.einsum("ij,njk->nik", A, dF)


def fit_coefficients_Jakob2019(RGB, coefficients_0=None):
    """Dimensionless sigmoid-polynomial coefficients of many linear sRGB reflectances at once.

    Eq. (3), Jakob & Hanika 2019, fitted by Gauss-Newton on the CIE 1976 Lab difference (§3.2), with
    colour-science's objective (module docstring).

    Parameters
    ----------
    RGB : array_like, shape (N, 3)
        Linear sRGB reflectances in [0, 1].
    coefficients_0 : array_like, shape (N, 3), optional
        Starting coefficients (normalized wavelength); default 0 (the flat 0.5).

    Returns
    -------
    coefficients : ndarray, shape (N, 3)
        For wavelength normalized to [0, 1] over 360-780 nm
        (``colour.recovery.jakob2019.dimensionalise_coefficients`` gives nm).
    delta_E : ndarray, shape (N,)
        The remaining ΔE76 of each colour (below 1e-6 inside the gamut of the model).

    Examples
    --------
    >>> c, dE = fit_coefficients_Jakob2019([[0.5, 0.5, 0.5], [0.6, 0.3, 0.1]])
    >>> bool(np.abs(c[0]).max() < 1e-2), bool((dE < 1e-6).all())   # grey: nearly flat (c ≈ 0)
    (True, True)
    """
    import colour

    M, white, _ = _observer()
    RGB = np.atleast_2d(np.asarray(RGB, dtype=np.float64))
    require(RGB.shape[-1] == 3 and RGB.ndim == 2, f"expected RGB (N, 3), got {RGB.shape}")
    space = colour.RGB_COLOURSPACES["sRGB"]
    xy_n = colour.XYZ_to_xy(white)
    target = colour.XYZ_to_Lab(colour.RGB_to_XYZ(RGB, space, xy_n), xy_n)
    c = np.zeros_like(RGB) if coefficients_0 is None else np.array(coefficients_0, dtype=float)
    Lab, J = _Lab_and_jacobian(c, M, white)
    error = np.linalg.norm(Lab - target, axis=-1)
    for _ in range(_MAX_ITER):
        active = error > _TOLERANCE_DELTA_E
        if not active.any():
            break
        # Gauss-Newton step: J Δc = −(Lab − target), least squares for near-singular J
        step = _solve(J[active], Lab[active] - target[active])
        scale = np.ones(step.shape[0])
        for _halving in range(30):
            trial = c[active] + scale[:, None] * step
            Lab_t, J_t = _Lab_and_jacobian(trial, M, white)
            err_t = np.linalg.norm(Lab_t - target[active], axis=-1)
            better = err_t < error[active]
            if better.all():
                break
            scale = np.where(better, scale, 0.5 * scale)
        index = np.flatnonzero(active)[better]
        c[index], Lab[index], J[index], error[index] = (
            trial[better],
            Lab_t[better],
            J_t[better],
            err_t[better],
        )
        if not better.any():
            break
    return c, error


def _solve(J, r):
    """−J⁻¹ r per colour (N, 3, 3), (N, 3), with a tiny Levenberg term against singular J."""
    JT = np.swapaxes(J, 1, 2)
    A = JT @ J
    A = A + 1e-12 * np.trace(A, axis1=1, axis2=2)[:, None, None] * np.eye(3)
    return -np.linalg.solve(A, (JT @ r[..., None]))[..., 0]


def generate_table_Jakob2019(size: int = DEFAULT_TABLE_SIZE) -> tuple[np.ndarray, np.ndarray]:
    """Coefficient table in colour-science's (and ``rgb2spec``'s) layout, fitted in batches.

    Eq. (3), Jakob & Hanika 2019, fitted as in :func:`fit_coefficients_Jakob2019` at the nodes of
    ``colour.recovery.LUT3D_Jakob2019``: block i holds colours whose largest component is channel i,
    of value ``scale[L]``; ``coefficients[i, L, j, k]`` is the colour with that component
    ``scale[L]`` and the others ``scale[L] · s_j`` (channel (i + 2) mod 3) and ``scale[L] · s_k``
    (channel (i + 1) mod 3), ``s = linspace(0, 1, size)``.

    Parameters
    ----------
    size : int
        Nodes per axis, 4 to 128.

    Returns
    -------
    scale : ndarray, shape (size,)
        ``smoothstep(smoothstep(linspace(0, 1, size)))``.
    coefficients : ndarray, shape (3, size, size, size, 3)
        For wavelength in nm (c0 λ² + c1 λ + c2).

    Examples
    --------
    >>> scale, coefficients = generate_table_Jakob2019(4)
    >>> scale.round(3), coefficients.shape
    (array([0.   , 0.167, 0.833, 1.   ]), (3, 4, 4, 4, 3))
    """
    from colour.recovery.jakob2019 import dimensionalise_coefficients, lightness_scale

    require(4 <= size <= 128, f"Jakob 2019 table size: must be in [4, 128], got {size}")
    _, _, shape = _observer()
    scale = lightness_scale(size)
    s = np.linspace(0.0, 1.0, size)
    chroma = np.empty((3, size, size, 3))
    for i in range(3):
        chroma[i, :, :, i] = 1.0
        chroma[i, :, :, (i + 2) % 3] = s[:, None]
        chroma[i, :, :, (i + 1) % 3] = s[None, :]
    chroma = chroma.reshape(-1, 3)
    table = np.empty((3 * size * size, size, 3))
    # As rgb2spec_opt: start a third of the way up the brightness scale, then step down and up it,
    # each step started from the previous one's coefficients
    middle = size // 3
    start, _ = fit_coefficients_Jakob2019(scale[middle] * chroma)
    table[:, middle] = start
    for steps in (range(middle - 1, -1, -1), range(middle + 1, size)):
        c = start
        for L in steps:
            c, _ = fit_coefficients_Jakob2019(scale[L] * chroma, c)
            table[:, L] = c
    nm = dimensionalise_coefficients(table.reshape(-1, 3), shape).T
    coefficients = nm.reshape(3, size, size, size, 3).transpose(0, 3, 1, 2, 4)
    return scale, np.ascontiguousarray(coefficients)


def _write_coeff(path: Path, scale: np.ndarray, coefficients: np.ndarray) -> None:
    """The ``.coeff`` file of rgb2spec, Mitsuba 3 and colour-science, written atomically."""
    import struct

    from reference.files import atomic_path

    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(b"SPEC" + struct.pack("i", scale.size))
        f.write(scale.astype(np.float32).tobytes())
        f.write(coefficients.astype(np.float32).tobytes())


@functools.lru_cache(maxsize=4)
def table_Jakob2019(size: int = DEFAULT_TABLE_SIZE):
    """colour-science's ``LUT3D_Jakob2019`` of ``size``, read from specref's cache or generated.

    Eq. (3), Jakob & Hanika 2019 (the coefficients of :func:`generate_table_Jakob2019`). The file is
    ``jakob2019-sRGB-<size>.coeff`` in ``$SPECREF_CACHE_DIR`` (else ``$XDG_CACHE_HOME/specref`` or
    ``~/.cache/specref``), written atomically; if the folder cannot be written, a
    :class:`SpecrefWarning` says so and the table stays in memory.

    Examples
    --------
    >>> lut = table_Jakob2019(8)
    >>> c = lut.RGB_to_coefficients(np.array([0.5, 0.5, 0.5]))      # grey: nearly flat
    >>> lut.size, bool(np.abs(c).max() < 1e-2)
    (8, True)
    """
    from colour.recovery import LUT3D_Jakob2019

    path = default_cache_dir() / f"jakob2019-sRGB-{int(size)}.coeff"
    lut = LUT3D_Jakob2019()
    try:
        return lut.read(path)
    except (OSError, ValueError):
        pass  # missing or damaged: generate it
    scale, coefficients = generate_table_Jakob2019(int(size))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _write_coeff(path, scale, coefficients)
        return lut.read(path)
    except (OSError, ValueError) as error:
        warnings.warn(
            f"{path}: cannot cache the Jakob 2019 table ({error}); keeping it in memory",
            SpecrefWarning,
            stacklevel=2,
        )
    return _read_in_memory(lut, scale, coefficients)


def _read_in_memory(lut, scale, coefficients):
    """colour-science reads tables from files only: a private temporary one, removed after."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "table.coeff"
        _write_coeff(path, scale, coefficients)
        return lut.read(path)
