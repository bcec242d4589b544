"""Sphere lights: the reflected radiance integrated over the cone of directions the sphere fills.

Not in the three papers (docs/errata.md, E114); written by hand because it is what the scene format
adds to them. A sphere of radius ``r`` and uniform radiance ``L_e(λ)`` seen from a surface point
``x`` at distance ``d`` from its centre fills the cone of half-angle ``σ``, ``sin σ = r/d``, about
the direction ``w`` to the centre. The reflected radiance is the rendering equation over that cone
(Pharr et al., pbrt-v4 §12.2, area lights):

    ``L_o(x, ω_o) = ∫_cone f(ω_i, ω_o) L_e(λ) max(N·ω_i, 0) dω_i``

A convex receiver cannot shadow itself in a direction above its horizon, so ``max(N·ω_i, 0)`` is
the whole of the visibility on a single convex object.

**The quadrature.** With ``μ = cos θ`` about ``w`` and the azimuth ``φ``, ``dω = dμ dφ``;
``μ ∈ [cos σ, 1]`` is split where the rings of the cone start to cross the horizon and each part
takes ``n`` Gauss-Legendre nodes, and each ring takes ``2n`` Gauss-Legendre nodes over its part
above the horizon (:func:`sphere_light_quadrature`); each direction is handed to the material's
point-light shader (directions batched, :data:`BATCH_ROWS` rows a call) as a point light one unit
away with no fall-off, whose value is
``π f cos θ_i`` in the scene's units (a white diffuser facing a unit point light has Y = 1), so

    ``Y = (intensity / π) Σ_k w_k · shade_point(x, ω_k)``,   ``Σ_k w_k = 2π (1 − cos σ)``.

Pixel by pixel, the order doubles from 2 until two successive orders agree within
``sphere_light_tol`` (default :data:`DEFAULT_TOLERANCE`) of the pixel's value or, if larger, of
the value a white diffuser facing the light would have there (``intensity · r²/d²``), up to
:data:`MAX_ORDER`; the higher order is kept. So a pixel's result does not depend on its
neighbours, and dark materials are held to the light's own scale. Where the whole cone is above
the horizon the integrand is smooth and a few nodes do (a Lambertian surface's ``cos θ_i`` is
linear in ``ω_i``); the horizon bounds the integration instead of cutting the integrand
(:func:`sphere_light_quadrature`). The highest order used and the largest accepted change
(relative, as above) are recorded in ``ctx.records["sphere_light"]`` (the render metadata).

A point shader works here if it takes the light's position through
``reference.scene.lights.point_light_vectors`` (which broadcasts an ``(N, 3)`` array of positions,
one per pixel) and honours ``attenuation = (1, 0, 0)``: every point shader of specref does; Phong
materials use the exact per-band evaluation (Eq. (2), Wang et al.), never a table, whose kernel
takes one light position.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from reference.colour.spectra import Spectrum
from reference.errors import require
from reference.materials.brdf import frame_from_normal
from reference.registry import Method
from reference.scene.lights import SphereLight
from reference.scene.shading import (
    SHADERS,
    Surface,
    shade_lambert_point,
    shade_phong_point_exact,
)

__all__ = [
    "BATCH_ROWS",
    "DEFAULT_TOLERANCE",
    "MAX_ORDER",
    "shade_lambert_sphere",
    "shade_phong_sphere",
    "sphere_light_irradiance_closed_form",
    "sphere_light_quadrature",
    "sphere_light_shader",
]

#: Default of ``options.sphere_light_tol``: two successive orders agree within this fraction of
#: the pixel's value (or of a white diffuser's facing the light, if larger).
DEFAULT_TOLERANCE = 1e-3
#: Largest Gauss-Legendre order on each part of ``[cos σ, 1]`` (with twice as many azimuths):
#: 4 × 32² directions per pixel.
MAX_ORDER = 32


def sphere_light_quadrature(
    centre, radius: float, positions, normals, order: int
) -> tuple[np.ndarray, np.ndarray]:
    """Directions and solid-angle weights over the part of a sphere's cone above the horizon.

    About the direction ``w`` to the centre, ``μ = cos θ`` runs over ``[cos σ, 1]`` and the
    azimuth ``φ`` is measured from the normal's side of ``w``, so that ``N·ω = c sin θ cos φ + a μ``
    with ``a = N·w`` and ``c = √(1 − a²)``: the ring at ``μ`` is visible for ``|φ| ≤ φ_max(μ)``,
    ``cos φ_max = −a μ / (c sin θ)``, clipped to [0, π]. A ring turns from wholly visible (or
    wholly hidden) to cut by the horizon at ``μ = c``, so ``[cos σ, 1]`` is split there and each
    part takes ``order`` Gauss-Legendre nodes; each ring takes ``2 · order`` Gauss-Legendre nodes
    on ``[−φ_max, φ_max]``. The horizon then bounds the integration instead of cutting the
    integrand, which stays smooth (:mod:`reference.scene.sphere_light`).

    Parameters
    ----------
    centre : array_like, shape (3,)
        The sphere's centre.
    radius : float
        Its radius, > 0.
    positions, normals : ndarray, shape (N, 3)
        Surface points and their unit normals.
    order : int
        Gauss-Legendre nodes on each of the two parts of ``[cos σ, 1]``.

    Returns
    -------
    directions : ndarray, shape (4 order², N, 3)
        Unit directions from each point into the sphere, above its horizon.
    weights : ndarray, shape (4 order², N)
        Solid angles, sr: per point, the solid angle of the visible part of the cone (``2π (1 −
        cos σ)`` when the whole sphere is above the horizon; 0 for a point inside the sphere).

    Examples
    --------
    >>> x, up = np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]])
    >>> omega, w = sphere_light_quadrature((0.0, 0.0, 2.0), 1.0, x, up, 3)
    >>> omega.shape, bool(np.isclose(w.sum(), 2 * np.pi * (1 - np.sqrt(0.75)), rtol=1e-14))
    ((36, 1, 3), True)
    >>> _, w = sphere_light_quadrature((2.0, 0.0, 0.0), 1.0, x, up, 3)   # half below
    >>> bool(np.isclose(w.sum(), np.pi * (1 - np.sqrt(0.75)), rtol=1e-14))
    True
    """
    D = np.asarray(centre, dtype=np.float64) - np.asarray(positions, dtype=np.float64)
    N = np.asarray(normals, dtype=np.float64)
    d = np.linalg.norm(D, axis=-1)
    outside = d > radius
    w_axis = D / np.where(outside, d, 1.0)[:, None]
    # sin σ = r/d: the half-angle of the cone the sphere fills
    cos_sigma = np.sqrt(np.clip(1.0 - (radius / np.where(outside, d, np.inf)) ** 2, 0.0, 1.0))
    a = np.einsum("ij,ij->i", N, w_axis)
    t, b = _horizon_frame(N, w_axis, a)
    c = np.sqrt(np.clip(1.0 - a**2, 0.0, 1.0))
    mu, w_mu = _split_nodes(cos_sigma, np.clip(c, cos_sigma, 1.0), order)
    sin_theta = np.sqrt(np.clip(1.0 - mu**2, 0.0, 1.0))
    # the visible azimuths: c sin θ cos φ + a μ >= 0
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(c * sin_theta > 0, -a * mu / (c * sin_theta), np.where(a >= 0, -2, 2))
    phi_max = np.arccos(np.clip(ratio, -1.0, 1.0))  # (2 order, N)
    x, g = np.polynomial.legendre.leggauss(2 * order)
    phi = phi_max[None] * x[:, None, None]  # (2 order, 2 order, N)
    w_phi = phi_max[None] * g[:, None, None]
    # ω = sin θ cos φ t + sin θ sin φ b + μ w, for every (φ, μ) pair
    omega = (
        (sin_theta * np.cos(phi))[..., None] * t
        + (sin_theta * np.sin(phi))[..., None] * b
        + mu[None, ..., None] * w_axis
    )
    # dω = dμ dφ
    weights = w_phi * (w_mu * outside)[None]
    return omega.reshape(-1, d.size, 3), weights.reshape(-1, d.size)


def _split_nodes(lower, split, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on ``[lower, split]`` and ``[split, 1]``, per point."""
    x, g = np.polynomial.legendre.leggauss(order)
    nodes, weights = [], []
    for start, end in ((lower, split), (split, np.ones_like(split))):
        half = 0.5 * (end - start)
        nodes.append(start[None] + half[None] * (x[:, None] + 1.0))
        weights.append(g[:, None] * half[None])
    return np.concatenate(nodes), np.concatenate(weights)


def _horizon_frame(N: np.ndarray, w: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``t`` along the normal's part across ``w`` (or any, if none), ``b = w × t``."""
    p = N - a[:, None] * w
    length = np.linalg.norm(p, axis=-1, keepdims=True)
    fallback, _ = frame_from_normal(w)
    t = np.where(length > 1e-12, p / np.where(length > 1e-12, length, 1.0), fallback)
    return t, np.cross(w, t)


def sphere_light_irradiance_closed_form(cos_omega, sin_sigma) -> np.ndarray:
    """``E / L_e``: the irradiance a unit-radiance sphere gives a plane, horizon clipped.

    The form factor of a sphere to a differential area (Snyder 1996, "Area light sources for
    real-time graphics", Microsoft Research MSR-TR-96-11), times π: ``π sin²σ cos ω`` while the
    whole sphere is above the horizon (``cos ω ≥ sin σ``), 0 when it is all below, and in between

        ``(cos ω acos y − x sin ω √(1 − y²)) sin²σ + atan(sin ω √(1 − y²) / x)``,

    with ``x = cot σ`` and ``y = −x cot ω``. ``ω`` is the angle between the normal and the direction
    to the centre. The tests' golden value for :func:`sphere_light_quadrature`.

    Examples
    --------
    >>> float(sphere_light_irradiance_closed_form(1.0, 0.5)) == np.pi * 0.25
    True
    >>> float(sphere_light_irradiance_closed_form(-0.9, 0.5))
    0.0
    """
    cos_omega = np.asarray(cos_omega, dtype=np.float64)
    s2 = np.asarray(sin_sigma, dtype=np.float64) ** 2
    above = np.pi * s2 * np.maximum(cos_omega, 0.0)
    sin_omega = np.sqrt(np.clip(1.0 - cos_omega**2, 0.0, 1.0))
    x = np.sqrt(1.0 / s2 - 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.clip(-x * cos_omega / sin_omega, -1.0, 1.0)
        root = sin_omega * np.sqrt(1.0 - y**2)
        straddling = (cos_omega * np.arccos(y) - x * root) * s2 + np.arctan(root / x)
    return np.where(cos_omega**2 >= s2, above, np.maximum(straddling, 0.0))


@dataclass(frozen=True)
class _DirectionLight:
    """One quadrature direction per pixel, as the point-light shaders read a light."""

    position: np.ndarray
    spectrum: Spectrum
    intensity: float = 1.0
    attenuation: tuple = field(default=(1.0, 0.0, 0.0))


def _tolerance(ctx) -> float:
    options = getattr(ctx, "options", {}) or {}
    tol = options.get("sphere_light_tol", DEFAULT_TOLERANCE)
    require(
        isinstance(tol, (int, float)) and not isinstance(tol, bool) and 0 < tol < 1,
        f"options.sphere_light_tol: must be a number in (0, 1), got {tol!r}",
    )
    return float(tol)


_SURFACE_FIELDS = ("position", "normal", "view", "uv")


def _subset(surface: Surface, rows: np.ndarray) -> Surface:
    return Surface(*(getattr(surface, k)[rows] for k in _SURFACE_FIELDS))


def _white_diffuser(surface: Surface, light: SphereLight) -> np.ndarray:
    """Y of a white diffuser facing the light at each point: ``intensity · r²/d²`` (0 inside)."""
    d2 = np.sum((np.asarray(light.position) - surface.position) ** 2, axis=-1)
    return np.where(d2 > light.radius**2, light.intensity * light.radius**2 / d2, 0.0)


def _record(ctx, material, order: int, relative: float) -> None:
    """Merge this tile's highest order and largest accepted change into the render's records."""
    if not hasattr(ctx, "record"):
        return
    name = str(getattr(material, "name", type(material).__name__))
    before = ctx.records.get("sphere_light", {}).get(name, {})
    ctx.record(
        "sphere_light",
        name,
        {
            "highest_order": max(order, before.get("highest_order", 0)),
            "largest_change": max(relative, before.get("largest_change", 0.0)),
        },
    )


#: Rows (pixels × directions) handed to a point shader at once: directions are batched so that
#: few pixels (the ones still refining) are shaded in one call per batch, not one per direction.
BATCH_ROWS = 1 << 15


def _integrate(shade_point, surface: Surface, material, light: SphereLight, ctx, order: int):
    directions, weights = sphere_light_quadrature(
        light.position, light.radius, surface.position, surface.normal, order
    )
    n_dir, n = weights.shape
    batch = max(1, BATCH_ROWS // max(n, 1))
    total = 0.0
    for start in range(0, n_dir, batch):
        omega, w = directions[start : start + batch], weights[start : start + batch]
        k = w.shape[0]
        # every pixel repeated once per direction of the batch (rows: direction-major)
        rows = Surface(*(np.tile(getattr(surface, a), (k, 1)) for a in _SURFACE_FIELDS))
        probe = _DirectionLight(rows.position + omega.reshape(-1, 3), light.spectrum)
        values = shade_point(rows, material, probe, ctx).reshape(k, n, -1)
        # L_o = (1/π) Σ_k w_k (π f cos θ_i)_k: the shader's value is π f cos θ_i
        total = total + np.einsum("kn,knc->nc", w, values)
    return light.intensity / np.pi * total


def sphere_light_shader(shade_point: Callable) -> Callable:
    """A sphere-light shader from a material's point-light shader (module docstring).

    Parameters
    ----------
    shade_point : callable
        ``f(surface, material, point_light, ctx) -> (N, n_outputs)``, linear in the light's
        intensity, reading its position through ``point_light_vectors``.

    Returns
    -------
    callable
        ``f(surface, material, sphere_light, ctx) -> (N, n_outputs)``.

    Examples
    --------
    >>> from reference.materials.types import LambertMaterial
    >>> from reference.scene.shading import ShadingContext
    >>> z = np.array([[0.0, 0.0, 1.0]])
    >>> s = Surface(np.zeros((1, 3)), z, z, np.zeros((1, 2)))
    >>> shade = sphere_light_shader(shade_lambert_point)
    >>> Y = shade(s, LambertMaterial(np.ones(41)), SphereLight((0, 0, 2.0), 0.5), ShadingContext())
    >>> round(float(Y[0, 1]), 9)                 # a white diffuser facing it: r²/d²
    0.0625
    """

    def shade(surface: Surface, material, light: SphereLight, ctx) -> np.ndarray:
        tol = _tolerance(ctx)
        order = 2  # order 1 can agree with order 2 by chance, before the rule converges
        current = _integrate(shade_point, surface, material, light, ctx, order)
        white = _white_diffuser(surface, light)
        active = np.arange(surface.position.shape[0])
        worst = 0.0
        while active.size and order < MAX_ORDER:
            order *= 2
            part = _subset(surface, active)
            finer = _integrate(shade_point, part, material, light, ctx, order)
            # the change, over the pixel's value or a white diffuser's facing the light there
            scale = np.maximum(np.abs(finer).max(axis=-1), white[active])
            difference = np.abs(finer - current[active]).max(axis=-1)
            with np.errstate(divide="ignore", invalid="ignore"):
                change = np.where(scale > 0, difference / scale, 0.0)
            current[active] = finer
            done = (change <= tol) | (order >= MAX_ORDER)
            worst = max(worst, float(change[done].max(initial=0.0)))
            active = active[~done]
        _record(ctx, material, order, worst)
        return current

    shade.__name__ = f"sphere_light_{getattr(shade_point, '__name__', 'shader')}"
    shade.__doc__ = f"{shade_point.__name__} integrated over a sphere light (sphere_light_shader)."
    return shade


_lambert_sphere = sphere_light_shader(shade_lambert_point)
_phong_sphere = sphere_light_shader(shade_phong_point_exact)


def shade_lambert_sphere(surface: Surface, material, light: SphereLight, ctx) -> np.ndarray:
    """XYZ of a Lambertian material under a sphere light, over the light's cone.

    Eq. (2), Wang et al.'s diffuse term integrated over the cone (module docstring).

    Examples
    --------
    >>> from reference.materials.types import LambertMaterial
    >>> from reference.scene.shading import ShadingContext
    >>> z = np.array([[0.0, 0.0, 1.0]])
    >>> s = Surface(np.zeros((1, 3)), z, z, np.zeros((1, 2)))
    >>> light = SphereLight((0.0, 0.0, 2.0), 0.5, intensity=3.0)
    >>> XYZ = shade_lambert_sphere(s, LambertMaterial(np.ones(41)), light, ShadingContext())
    >>> round(float(XYZ[0, 1]), 9)               # a white diffuser facing it: 3 · 0.5²/2²
    0.1875
    """
    return _lambert_sphere(surface, material, light, ctx)


def shade_phong_sphere(surface: Surface, material, light: SphereLight, ctx) -> np.ndarray:
    """XYZ of a Phong material under a sphere light, over the light's cone.

    Eq. (2), Wang et al. evaluated exactly per band and integrated over the cone (module
    docstring).

    Examples
    --------
    >>> from reference.materials.types import PhongMaterial
    >>> from reference.scene.lights import PointLight
    >>> from reference.scene.shading import ShadingContext
    >>> m = PhongMaterial(np.full(41, 0.2), np.full(41, 0.5), np.full(41, 30.0))
    >>> z = np.array([[0.0, 0.0, 1.0]])
    >>> s = Surface(np.zeros((1, 3)), z, z, np.zeros((1, 2)))
    >>> ctx = ShadingContext(options={"sphere_light_tol": 1e-9})
    >>> small = shade_phong_sphere(s, m, SphereLight((0.0, 0.0, 2.0), 1e-3, intensity=1e6), ctx)
    >>> point = shade_phong_point_exact(s, m, PointLight((0.0, 0.0, 2.0), attenuation=(0, 0, 1)),
    ...                                 ctx)
    >>> bool(np.allclose(small, point, rtol=1e-5))   # a small sphere: a point light of L r²
    True
    """
    return _phong_sphere(surface, material, light, ctx)


SHADERS.register(
    Method(
        "LambertMaterial/SphereLight",
        shade_lambert_sphere,
        None,
        "§12.2, Pharr et al. (pbrt-v4); Eq. (2), Wang et al.",
    )
)
SHADERS.register(
    Method(
        "PhongMaterial/SphereLight",
        shade_phong_sphere,
        None,
        "§12.2, Pharr et al. (pbrt-v4); Eq. (2), Wang et al.",
    )
)
