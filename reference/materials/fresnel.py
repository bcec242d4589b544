"""Exact Fresnel reflectance of a smooth dielectric interface, and its cos θ look-up table.

The Fresnel reflection coefficient ``F_r`` of Eq. (1), Herbert et al. is "a function of the angle
between eye and surface normal vectors", realized "through look-up tables, where the look-up
frequency is per-pixel if the variable is an angle". This module gives the exact unpolarized
reflectance of an interface between air and a dielectric of real index ``n`` (the reference), the
uniform table in ``cos θ`` that the paper's renderer looks up per pixel, and the hemispherical
(diffuse) reflectances that the Saunderson correction of a Kubelka–Munk slab uses
(``shrm.polymer.kubelka_munk``). The interface is shared physics, so it lives in ``reference``.

Conventions: ``cos_theta`` is the cosine of the angle between the incident (or view) direction and
the normal on the incident side, in [0, 1]; ``n`` is the index of the far medium relative to the
near one (``n > 1`` for light arriving from air). Energy is conserved at a lossless interface, so
the transmitted fraction is ``1 - F``.

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
Born, M., & Wolf, E. (1999). Principles of Optics, 7th ed., §1.5.2 (the Fresnel formulae).
Judd, D. B. (1942). Fresnel reflection of diffusely incident light. J. Res. NBS 29, 329–332
    (the diffuse reflectances, 0.0918 outside and 0.596 inside for n = 1.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from reference.errors import require, require_finite

__all__ = [
    "FRESNEL_LUT_SIZE",
    "MAX_REFRACTIVE_INDEX",
    "FresnelLUT",
    "fresnel_dielectric",
    "fresnel_diffuse",
    "fresnel_lut",
]

#: Entries of the default cos θ table: linear interpolation between 4097 nodes keeps the table
#: within 1e-6 of the closed form for every index in [1.1, 3]
#: (``tests/reference/materials/test_fresnel.py``;
#: towards n = 1 the curve steepens at grazing incidence: 1.3e-6 at n = 1.05, 6e-4 at n = 1.0001).
FRESNEL_LUT_SIZE = 4097

#: The largest refractive index an input file may state: the cos θ table is checked up to it, and
#: no transparent dielectric of a scene exceeds it (rutile TiO2 2.6-2.9, diamond 2.42, polymers
#: 1.3-1.7). An index of 1e11 was accepted by scenes.
MAX_REFRACTIVE_INDEX = 3.0


def _check_index(n, where: str) -> np.ndarray:
    n = require_finite(n, where)
    require(bool(np.all(n > 1.0)), f"{where}: refractive index must be > 1, got {n.min()!r}")
    return n


def fresnel_dielectric(cos_theta, n) -> np.ndarray:
    """Exact unpolarized Fresnel reflectance of light arriving from air on a dielectric of index n.

    The ``F_r`` of Eq. (1), Herbert et al.

    Parameters
    ----------
    cos_theta : array_like, shape (...,)
        Cosine of the angle of incidence, clipped to [0, 1].
    n : float or array_like, shape (n_bands,)
        Refractive index of the dielectric relative to air, > 1 (a spectrum broadcasts on the last
        axis: a dispersive index).

    Returns
    -------
    ndarray, broadcast of ``cos_theta`` and ``n``
        ``F = (r_s² + r_p²) / 2``, in [0, 1].

    Raises
    ------
    SpecrefError
        For an index <= 1 or not finite.

    Examples
    --------
    >>> fresnel_dielectric([1.0, 0.0], 1.5).round(4)
    array([0.04, 1.  ])
    """
    n = _check_index(n, "fresnel_dielectric: n")
    cos_i = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    # Snell's law: n sin θ_t = sin θ_i, so cos θ_t = sqrt(1 - (1 - cos² θ_i) / n²)
    cos_t = np.sqrt(1.0 - (1.0 - cos_i**2) / n**2)
    # Born & Wolf §1.5.2: the amplitude ratios for s and p polarization
    r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (r_s**2 + r_p**2)


def _fresnel_internal(cos_theta, n) -> np.ndarray:
    """Reflectance for light inside the dielectric arriving at the interface to air (with TIR)."""
    cos_i = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    sin_t2 = n**2 * (1.0 - cos_i**2)
    cos_t = np.sqrt(np.clip(1.0 - sin_t2, 0.0, None))
    r_s = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    r_p = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    return np.where(sin_t2 >= 1.0, 1.0, 0.5 * (r_s**2 + r_p**2))


@lru_cache(maxsize=8)
def _gauss_legendre(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [-1, 1], computed once per order (an eigenproblem)."""
    nodes, weights = np.polynomial.legendre.leggauss(order)
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


def fresnel_diffuse(n, side: str = "outside", order: int = 400) -> np.ndarray:
    """Hemispherical Fresnel reflectance for uniformly diffuse incident light.

    ``r = ∫ F(θ) 2 cos θ sin θ dθ`` over the hemisphere, by Gauss–Legendre quadrature in
    ``cos² θ`` (on either side of the critical angle when light arrives from inside). These are the
    Saunderson constants of ``shrm.polymer.kubelka_munk``.

    Parameters
    ----------
    n : float or array_like, shape (n_bands,)
        Refractive index of the dielectric relative to air, > 1.
    side : {"outside", "inside"}
        Where the light arrives from: air (external) or the dielectric (internal, with total
        internal reflection beyond the critical angle).
    order : int
        Gauss–Legendre nodes per interval.

    Returns
    -------
    ndarray, shape of ``n``
        The diffuse reflectance in [0, 1].

    Raises
    ------
    SpecrefError
        For an index <= 1 or an unknown side.

    Examples
    --------
    >>> float(fresnel_diffuse(1.5)).__round__(4), float(fresnel_diffuse(1.5, "inside")).__round__(3)
    (0.0918, 0.596)
    """
    n = _check_index(n, "fresnel_diffuse: n")
    require(
        side in ("outside", "inside"),
        f"fresnel_diffuse: side must be outside or inside, got {side!r}",
    )
    nodes, weights = _gauss_legendre(int(order))
    n_col = n[..., None]
    if side == "outside":
        # u = cos² θ is uniform under the cosine-weighted measure: r = ∫_0^1 F(sqrt(u)) du
        u = 0.5 * (nodes + 1.0)
        return 0.5 * (weights * fresnel_dielectric(np.sqrt(u), n_col)).sum(axis=-1)
    # Inside: F = 1 for u < u_c = 1 - 1/n² (total internal reflection), integrate the rest
    u_c = 1.0 - 1.0 / n_col**2
    u = u_c + (1.0 - u_c) * 0.5 * (nodes + 1.0)
    integral = (weights * _fresnel_internal(np.sqrt(u), n_col)).sum(axis=-1)
    return u_c[..., 0] + 0.5 * (1.0 - u_c[..., 0]) * integral


@dataclass(frozen=True)
class FresnelLUT:
    """A uniform table of ``F_r`` against ``cos θ`` in [0, 1], looked up per pixel.

    Parameters
    ----------
    table : ndarray, shape (size,) or (size, n_bands)
        ``F_r`` at ``cos θ = i / (size - 1)``.
    n : ndarray, shape () or (n_bands,)
        The index it was built for.
    """

    table: np.ndarray
    n: np.ndarray

    def lookup(self, cos_theta) -> np.ndarray:
        """Linear interpolation in the table; shape ``(..., )`` or ``(..., n_bands)``.

        Examples
        --------
        >>> float(fresnel_lut(1.5).lookup(1.0)).__round__(6)
        0.04
        """
        size = self.table.shape[0]
        x = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0) * (size - 1)
        i = np.minimum(x.astype(np.int64), size - 2)
        t = x - i
        if self.table.ndim == 2:
            t = t[..., None]
        return (1.0 - t) * self.table[i] + t * self.table[i + 1]


def fresnel_lut(n, size: int = FRESNEL_LUT_SIZE) -> FresnelLUT:
    """Tabulate the exact Fresnel reflectance against cos θ (the paper's per-pixel LUT).

    The ``F_r`` of Eq. (1), Herbert et al.: "All function-of parameters are realized through look-up
    tables ... per-pixel if the variable is an angle".

    Parameters
    ----------
    n : float or array_like, shape (n_bands,)
        Refractive index, > 1; a spectrum gives one column per band.
    size : int
        Number of nodes, >= 2.

    Returns
    -------
    FresnelLUT

    Raises
    ------
    SpecrefError
        For an index <= 1 or a size below 2.

    Examples
    --------
    >>> lut = fresnel_lut(1.54)
    >>> lut.table.shape, float(lut.lookup(0.3)).__round__(4)
    ((4097,), 0.215)
    """
    n = _check_index(n, "fresnel_lut: n")
    require(int(size) >= 2, f"fresnel_lut: size must be >= 2, got {size}")
    cos_theta = np.linspace(0.0, 1.0, int(size))
    table = fresnel_dielectric(cos_theta[:, None] if n.ndim else cos_theta, n)
    table.setflags(write=False)
    return FresnelLUT(table, n)
