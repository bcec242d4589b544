"""The painting's settings from a tolerance: no more lights, samples and sectors than it needs.

Ferwerda (§3.5) renders every painting with 32 median-cut lights N, 32 FIS samples K and a horizon
map of 18 sectors (specref: 36, erratum E95), and specref's hybrid always runs its fail-safe
(erratum E17). Whether a painting needs that much depends on its gloss, its relief and the light.
:func:`settings_from_tolerance` asks the painting (erratum E96, specref's heuristic):

1. a **pilot** (:class:`PaintingPilot`): :data:`PILOT_PIXELS` of the frame's own visible canvas
   pixels, a stratified sample (:func:`pilot_pixels`), with their brute-force radiance
   (:func:`painting_brute_force`: every light pixel a point light with its own shadow test against
   a :data:`REFERENCE_SECTORS`-sector horizon, and the specular integral summed over every light
   sub-pixel). The pixels are the frame's, not a coarser frame's: the error of the sample is an
   estimate of the frame's error (a 48² frame's error was up to a third below a 256² frame's);
2. a **descent** down each setting's ladder (:data:`LIGHT_LADDER`, :data:`SAMPLE_LADDER`,
   :data:`SECTOR_LADDER`, the fail-safe off or on) from the top of all four: one rung at a time,
   always the step that saves most of a frame's cost (:func:`frame_cost`), as long as the pilot's
   error stays within :data:`PILOT_MARGIN` × the tolerance. When even the top misses it, the top
   is kept and the settings say so (``met=False``).

:func:`settings_no_worse_than` runs the same descent against a baseline's pilot error instead (the
fixed settings by default), with the pilot's own standard error of the difference as the margin.

The error is the relative RMS of XYZ over the pixels (:func:`relative_rms_error`). The pilot's error
at the chosen settings is the **promised bound**; the report checks the tolerance on held-out
paintings, on frames at the render's resolution, against the same brute force, and times the
frames against the fixed settings.

References
----------
J. A. Ferwerda, "ImpastoR: A Realistic Surface Display System", ACM TAP 12(4), 2015.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from functools import lru_cache

import numpy as np

from impastor._kernels import diffuse_brute_force_kernel, specular_brute_force_shadowed_kernel
from impastor.horizon import horizon_at_texels, horizon_lookup, light_azimuth_elevation
from impastor.multispectral import channels_to_XYZ
from impastor.painting import (
    EYE,
    HORIZON_SECTORS,
    PaintingScene,
    canvas_frame,
    canvas_materials,
    canvas_pixels,
    impasto_painting,
    lights_visibility,
    painting_scene,
    posed_scene,
    render_painting,
    shade_canvas,
)
from impastor.point_lights import (
    PointLights,
    illuminance_point_lights,
    point_lights_every_pixel,
)
from impastor.specular_hybrid import GROUP_METHODS, alpha_groups
from reference.errors import require, require_positive_int
from reference.materials.brdf import brdf_ward_duer_specular
from reference.registry import Method, Registry

__all__ = [
    "BRUTE_FORCE_METHODS",
    "FIXED_SETTINGS",
    "FRAME_COST",
    "LIGHT_LADDER",
    "MIN_GROUP_PIXELS",
    "NO_WORSE_THAN_FIXED",
    "PAIRED_Z",
    "PILOT_MARGIN",
    "PILOT_PIXELS",
    "REFERENCE_SECTORS",
    "SAMPLE_LADDER",
    "SECTOR_LADDER",
    "PaintingPilot",
    "PaintingSettings",
    "check_tolerance",
    "diffuse_brute_force",
    "frame_cost",
    "painting_brute_force",
    "pilot_pixels",
    "relative_rms_error",
    "render_painting_to_tolerance",
    "settings_from_tolerance",
    "settings_no_worse_than",
    "specular_brute_force_shadowed",
]

#: The rungs each setting may take, cheapest first (N point lights, K FIS samples, S sectors).
LIGHT_LADDER = (4, 8, 16, 32, 64)
SAMPLE_LADDER = (4, 8, 16, 32, 64)
SECTOR_LADDER = (6, 9, 12, 18, 24, 36, 48)
#: The pilot's pixels: this many of the frame's visible canvas pixels (a stratified sample, seeded).
PILOT_PIXELS = 1200
PILOT_SEED = 0
#: The brute force's horizon: sectors (far beyond any rung) and specular sub-pixels per light pixel.
REFERENCE_SECTORS = 144
REFERENCE_SUPERSAMPLE = 2
#: The pilot must meet this fraction of the tolerance: the pilot's pixels are a sample of the
#: frame's, and where the pilot met a tolerance a frame's error was up to 1.35 times its pilot's on
#: the design paintings (seeds 41-44 under D65 and A, 256² frames measured on 3000 other pixels):
#: 1 / 1.35.
PILOT_MARGIN = 0.74


@dataclass(frozen=True)
class PaintingSettings:
    """How much model a frame of the painting gets.

    Attributes
    ----------
    n_lights, n_samples, n_sectors : int
        Point lights N, FIS samples K and horizon sectors S.
    failsafe : bool
        Whether the hybrid runs its fail-safe (erratum E17).
    tolerance : float or None
        The relative RMS error asked for (None: fixed settings).
    pilot_error : float or None
        The pilot's error at these settings: the promised bound.
    met : bool
        False when even the top of every ladder missed the tolerance on the pilot.
    by_group : tuple of (int, str)
        The groups of similar α (:func:`~impastor.specular_hybrid.alpha_groups`) that take the
        point lights or FIS alone instead of the hybrid, sorted; the others take the hybrid.
    shares : tuple of float or None
        The pilot pixels' fractions on the point lights, FIS and the hybrid.
    baseline : str or None
        Set when the settings were chosen as no worse than a baseline's
        (:func:`settings_no_worse_than`; ``tolerance`` is then the baseline's pilot error):
        ``"fixed"`` for the fixed settings, ``"given"`` for others.
    """

    n_lights: int
    n_samples: int
    n_sectors: int
    failsafe: bool
    tolerance: float | None = None
    pilot_error: float | None = None
    met: bool = True
    by_group: tuple = ()
    shares: tuple | None = None
    baseline: str | None = None

    def render_options(self) -> dict:
        """The keyword arguments of :func:`render_painting` for these settings."""
        return {
            "n_lights": self.n_lights,
            "n_samples": self.n_samples,
            "n_sectors": self.n_sectors,
            "failsafe": self.failsafe,
            "by_group": dict(self.by_group) or None,
        }


#: The fixed settings: the paper's 32 lights and 32 samples, 36 sectors (E95), the fail-safe on.
FIXED_SETTINGS = PaintingSettings(32, 32, HORIZON_SECTORS, True)


def relative_rms_error(XYZ, XYZ_reference) -> float:
    """Relative RMS error of a set of colours: ``‖XYZ − XYZ_ref‖ / ‖XYZ_ref‖`` over all pixels.

    Parameters
    ----------
    XYZ, XYZ_reference : array_like, shape (n, 3)

    Examples
    --------
    >>> relative_rms_error([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]], [[1.0, 1.0, 1.0], [2.0, 2.0, 1.0]])
    0.28867513459481287
    """
    X, R = np.asarray(XYZ, dtype=np.float64), np.asarray(XYZ_reference, dtype=np.float64)
    return float(np.sqrt(np.sum((X - R) ** 2) / np.sum(R**2)))


def _every_pixel_lights(scene: PaintingScene) -> PointLights:
    """Every pixel of the booth light a point light at its centre (the diffuse brute force)."""
    return point_lights_every_pixel(scene.plane)


def diffuse_brute_force(scene: PaintingScene, px, horizon, backend: str = "numba", chunk=128):
    """Illuminance at canvas pixels from every light pixel, each with its own shadow test.

    Eq. (2), Ferwerda, with every pixel of the booth light a point light at its centre, shadowed
    where its elevation is under the texel's horizon at its azimuth (``horizon_lookup``,
    interpolated): the limit of the median-cut lights as N reaches the light's pixel count.

    Parameters
    ----------
    scene : PaintingScene
    px : canvas pixels (:func:`impastor.painting.canvas_pixels`)
    horizon : ndarray, shape (n, S)
        Horizon angles at the pixels' texels.
    backend : {"numba", "numpy"}
        The NumPy reference tests ``chunk`` pixels against all light pixels at a time.

    Returns
    -------
    ndarray, shape (n, C)
        Illuminance, lux (C = the light image's channels).

    Examples
    --------
    >>> scene = painting_scene("D65", "hybrid", impasto_painting(16), light_resolution=(8, 4))
    >>> px = canvas_pixels(scene.painting, 6)
    >>> horizon = np.zeros((px.P.shape[0], 4))
    >>> E = diffuse_brute_force(scene, px, horizon, "numpy")
    >>> bool(np.allclose(E, diffuse_brute_force(scene, px, horizon, "numba"), rtol=1e-12))
    True
    """
    every = _every_pixel_lights(scene)
    horizon = np.ascontiguousarray(horizon, dtype=np.float64)
    E = np.zeros((px.P.shape[0], every.L.shape[-1]))
    if backend == "numba":
        frame = np.array(canvas_frame())
        diffuse_brute_force_kernel(
            px.P, px.N, horizon, frame, every.position, every.L, np.asarray(every.n_light),
            float(every.pixel_area), E,
        )  # fmt: skip
        return E
    for start in range(0, px.P.shape[0], chunk):
        block = slice(start, start + chunk)
        visibility = lights_visibility(horizon[block], px.P[block], every)
        E[block] = illuminance_point_lights(px.P[block], px.N[block], every, visibility)
    return E


def specular_brute_force_shadowed(
    scene: PaintingScene, px, horizon, backend: str = "numba", supersample=REFERENCE_SUPERSAMPLE
):
    """Specular integral at canvas pixels over every light sub-pixel, each with its shadow test.

    Eq. (4), Ferwerda, integrated against the piecewise-constant light image with the geometry of
    Eq. (2), Ferwerda, at every sub-pixel centre (``supersample``² per light pixel), a sub-pixel
    counted only where its elevation is above the texel's horizon at its azimuth
    (``horizon_lookup``, interpolated): §3.5.3, Ferwerda, leaves out of the rendering every
    source under the horizon, the specular term's as well as the diffuse term's, as the point
    lights do (``lights_visibility``). FIS has no shadows, so its error includes them.

    Parameters
    ----------
    scene : PaintingScene
    px : canvas pixels (:func:`impastor.painting.canvas_pixels`)
    horizon : ndarray, shape (n, S)
        Horizon angles at the pixels' texels.
    backend : {"numba", "numpy"}
        The NumPy reference loops over pixels (slow; for tests).
    supersample : int
        Sub-pixels per light pixel and axis.

    Returns
    -------
    ndarray, shape (n, C)
        The specular integral for ρ_s = 1, cd/m² (C = the light image's channels).

    Examples
    --------
    >>> scene = painting_scene("D65", "hybrid", impasto_painting(16), light_resolution=(8, 4))
    >>> px = canvas_pixels(scene.painting, 6)
    >>> horizon = np.full((px.P.shape[0], 4), 0.9)
    >>> I = specular_brute_force_shadowed(scene, px, horizon, "numpy")
    >>> bool(np.allclose(I, specular_brute_force_shadowed(scene, px, horizon, "numba"), rtol=1e-12))
    True
    """
    supersample = require_positive_int(supersample, "brute force: supersample", 256)
    alpha = canvas_materials(scene.painting, scene.spectra, scene.design, px)[2]
    horizon = np.ascontiguousarray(horizon, dtype=np.float64)
    light, s = scene.plane, supersample
    images = light.image[..., None] if light.image.ndim == 2 else light.image
    out = np.zeros((px.P.shape[0], images.shape[-1]))
    if backend == "numba":
        frame, o, A, B = (np.asarray(x, dtype=np.float64) for x in
                          (canvas_frame(), light.origin, light.A, light.B))  # fmt: skip
        for c in range(images.shape[-1]):
            specular_brute_force_shadowed_kernel(
                px.P, px.N, px.V, alpha, horizon, frame, np.ascontiguousarray(images[..., c]), o,
                A, B, light.l_A, light.l_B, light.n_light, s, out[:, c],
            )  # fmt: skip
        return out
    H, W = light.shape
    R, C = np.meshgrid((np.arange(H * s) + 0.5) / s, (np.arange(W * s) + 0.5) / s, indexing="ij")
    X = light.pixel_positions(R, C).reshape(-1, 3)
    L = np.repeat(np.repeat(images, s, axis=0), s, axis=1).reshape(-1, images.shape[-1])
    for p in range(px.P.shape[0]):
        to_light = X - px.P[p]
        d2 = np.einsum("xi,xi->x", to_light, to_light)
        I_n = to_light / np.sqrt(d2)[:, None]
        cos_s, cos_l = I_n @ px.N[p], -(I_n @ light.n_light)
        f = brdf_ward_duer_specular(I_n, px.V[p], px.N[p], alpha[p])
        # §3.5.3, Ferwerda: a source under the texel's horizon is left out
        phi, beta = light_azimuth_elevation(to_light, *canvas_frame())
        lit = horizon_lookup(horizon[p][None, :], phi, beta)
        g = np.where((cos_s > 0) & (cos_l > 0) & lit, f * cos_s * cos_l / d2, 0.0)
        out[p] = (g * light.pixel_area / (s * s)) @ L
    return out


def _diffuse_example(rng):
    scene = painting_scene("D65", "hybrid", impasto_painting(16), light_resolution=(8, 4))
    px = canvas_pixels(scene.painting, 6)
    # horizons up to 75°: the ceiling (40°-90° above the canvas) is partly shadowed
    return scene, px, rng.uniform(0.5, 1.3, (px.P.shape[0], 6))


#: The brute-force references of the painting that have kernels (the specular one is
#: ``impastor.specular_hybrid.SPECULAR_METHODS["brute_force"]``).
BRUTE_FORCE_METHODS = Registry("painting brute force")
BRUTE_FORCE_METHODS.register(
    Method(
        "diffuse",
        diffuse_brute_force,
        diffuse_brute_force_kernel,
        "Eq. (2), Ferwerda (every light pixel, shadowed)",
        _diffuse_example,
    )
)
BRUTE_FORCE_METHODS.register(
    Method(
        "specular",
        specular_brute_force_shadowed,
        specular_brute_force_shadowed_kernel,
        "Eq. (4), Ferwerda (every light sub-pixel, shadowed)",
        _diffuse_example,
    )
)


def painting_brute_force(scene: PaintingScene, px, backend: str = "numba"):
    """Brute-force radiance of the painting at canvas pixels, per channel: the reference.

    The diffuse radiance of Eq. (3), Ferwerda, from :func:`diffuse_brute_force` with the
    horizon at :data:`REFERENCE_SECTORS` sectors, plus Eq. (4), Ferwerda, integrated over every
    light sub-pixel with the same horizon (:func:`specular_brute_force_shadowed`): §3.5.3,
    Ferwerda, shadows both terms.

    Parameters
    ----------
    scene : PaintingScene
    px : canvas pixels (:func:`impastor.painting.canvas_pixels`)
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray, shape (n, 6)

    Examples
    --------
    >>> scene = painting_scene("D65", "hybrid", impasto_painting(16), light_resolution=(8, 4))
    >>> px = canvas_pixels(scene.painting, 6)
    >>> painting_brute_force(scene, px, "numpy").shape == (px.P.shape[0], 6)
    True
    """
    painting = scene.painting
    horizon = horizon_at_texels(
        painting["height"], painting["pixel_size"], px.row, px.col, REFERENCE_SECTORS, 32, backend
    )
    E = diffuse_brute_force(scene, px, horizon, backend)
    rho_d, rho_s, _ = canvas_materials(painting, scene.spectra, scene.design, px)
    I_s = specular_brute_force_shadowed(scene, px, horizon, backend)
    return rho_d * scene.S6 * E / np.pi + rho_s * scene.S6 * I_s


def pilot_pixels(painting: dict, size: int, eye=EYE, count: int = PILOT_PIXELS, seed=PILOT_SEED):
    """The pilot's pixels: a stratified sample of ``count`` of the frame's visible canvas pixels.

    The frame's visible pixels at ``size``² in raster order are cut into ``count`` runs of
    (nearly) equal length and one pixel is drawn uniformly from each (a seeded generator), so the
    sample covers the canvas evenly, as the frame does, and its error estimates the frame's
    (erratum E96). A frame with no more than ``count`` visible pixels is its own pilot.

    Parameters
    ----------
    painting : dict
        :func:`impastor.painting.impasto_painting` or a painting read from files.
    size : int
        The frame's side, pixels.
    eye : (3,) array_like
        The viewer in the canvas's frame, m.
    count : int
        Pixels to draw, >= 1.
    seed : int
        The generator's seed.

    Returns
    -------
    canvas pixels (:func:`impastor.painting.canvas_pixels`)

    Examples
    --------
    >>> painting = impasto_painting(32)
    >>> pilot_pixels(painting, 32, count=100).P.shape
    (100, 3)
    >>> pilot_pixels(painting, 8, count=100).P.shape == canvas_pixels(painting, 8).P.shape
    True
    """
    count = require_positive_int(count, "pilot: pixels", 1 << 24)
    px = canvas_pixels(painting, size, eye)
    n = px.P.shape[0]
    if n <= count:
        return px
    # runs [b_k, b_k+1) of whole pixels, each at least one long (n > count)
    bounds = (np.arange(count + 1) * n) // count
    draw = np.random.default_rng(seed).random(count)
    return px.subset(bounds[:-1] + (draw * np.diff(bounds)).astype(int))


class PaintingPilot:
    """The pilot: a thousand of the frame's pixels, their brute force, and any settings' error.

    Parameters
    ----------
    scene : PaintingScene
    size : int
        The frame's side, pixels (:func:`pilot_pixels` draws the pilot's pixels from it).
    backend : {"numba", "numpy"}
    eye : (3,) array_like
        The viewer in the canvas's frame, m (:func:`impastor.painting.posed_scene`).
    pixels : int
        How many pixels the pilot draws.

    Attributes
    ----------
    reference : ndarray, shape (n, 3)
        Brute-force XYZ at the pilot pixels (:func:`painting_brute_force`).
    groups : ndarray, shape (n,)
        The pilot pixels' groups of similar α (:func:`~impastor.specular_hybrid.alpha_groups`).
    """

    def __init__(
        self,
        scene: PaintingScene,
        size: int = 256,
        backend: str = "numba",
        eye=EYE,
        pixels: int = PILOT_PIXELS,
    ):
        painting = scene.painting
        self.scene, self.backend = scene, backend
        self.px = pilot_pixels(painting, size, eye, pixels)
        brute_force = painting_brute_force(scene, self.px, backend)
        self.reference = channels_to_XYZ(brute_force, scene.design)
        alpha = canvas_materials(painting, scene.spectra, scene.design, self.px)[2]
        self.groups = alpha_groups(alpha)
        height, pixel_size, rows, cols = (
            painting["height"], painting["pixel_size"], self.px.row, self.px.col
        )  # fmt: skip
        self.horizons = {
            S: horizon_at_texels(height, pixel_size, rows, cols, S, 32, backend)
            for S in SECTOR_LADDER
        }
        self._squared = lru_cache(maxsize=None)(self._squared_errors)
        self._squared_of = lru_cache(maxsize=None)(self._squared_of_method)

    def switchable_groups(self) -> tuple:
        """The groups that may take a method of their own: the hybrid's, with enough pixels."""
        if not self.scene.lighting.failsafe:  # other lighting methods have one method
            return ()
        values, counts = np.unique(self.groups, return_counts=True)
        return tuple(int(g) for g, c in zip(values, counts, strict=True) if c >= MIN_GROUP_PIXELS)

    def error(self, n_lights, n_samples, n_sectors, failsafe, by_group=()) -> float:
        """Relative RMS error of XYZ on the pilot's pixels at these settings (memoised shading).

        ``by_group``: ``((group, method), ...)``, the groups on the point lights or FIS alone.
        """
        squared = self.pixel_squared_errors(n_lights, n_samples, n_sectors, failsafe, by_group)
        return float(np.sqrt(np.sum(squared) / np.sum(self.reference**2)))

    def pixel_squared_errors(self, n_lights, n_samples, n_sectors, failsafe, by_group=()):
        """Each pilot pixel's squared XYZ error at these settings, shape (n,)."""
        squared = self._squared(n_lights, n_samples, n_sectors, failsafe)
        method = self._pixel_methods(by_group)
        require(
            set(np.unique(method)) <= set(squared),
            f"pilot: by_group {by_group!r}: only the hybrid's groups may take another method",
        )
        return np.select([method == m for m in squared], list(squared.values()))

    def difference_sigma(self, settings, baseline) -> float:
        """Standard error of ``error(*settings) − error(*baseline)`` from the pilot's pixels.

        The pixels are a sample of the frame's: the difference of the two errors, a function of
        the two sums of squared errors, varies with the sample. By the delta method, pixel ``i``
        adds ``d_i = (q_i / e_a − p_i / e_b) / (2 ΣR²)`` to it (``q``, ``p`` the two settings'
        squared errors, ``e`` their errors), and its standard error is ``√n · std(d)``: the
        pixels taken as independent draws, which overstates the spread of a stratified sample.
        """
        q, p = self.pixel_squared_errors(*settings), self.pixel_squared_errors(*baseline)
        total = np.sum(self.reference**2)
        e_a, e_b = np.sqrt(np.sum(q) / total), np.sqrt(np.sum(p) / total)
        d = (q / max(e_a, 1e-300) - p / max(e_b, 1e-300)) / (2.0 * total)
        return float(np.sqrt(d.size) * np.std(d))

    def cost(self, n_lights, n_samples, n_sectors, failsafe, by_group=()) -> float:
        """:func:`frame_cost` at these settings, with the pilot pixels' shares of each method."""
        return frame_cost(n_lights, n_samples, n_sectors, failsafe, self.shares(by_group))

    def shares(self, by_group=()) -> tuple:
        """The pilot pixels' fractions on the point lights, FIS and the hybrid."""
        method = self._pixel_methods(by_group)
        return tuple(float(np.mean(method == m)) for m in GROUP_METHODS)

    def _pixel_methods(self, by_group) -> np.ndarray:
        method = np.full(self.groups.shape, "hybrid", dtype=object)
        for group, key in by_group:
            method[self.groups == group] = key
        return method

    def _squared_errors(self, n_lights, n_samples, n_sectors, failsafe) -> dict:
        """Per method, each pilot pixel's squared XYZ error with every pixel on that method."""
        squared = {"hybrid": self._squared_of(n_lights, n_samples, n_sectors, failsafe, "hybrid")}
        if self.switchable_groups():  # the point lights and FIS alone have no fail-safe: once
            for key in GROUP_METHODS[:-1]:
                squared[key] = self._squared_of(n_lights, n_samples, n_sectors, False, key)
        return squared

    def _squared_of_method(self, n_lights, n_samples, n_sectors, failsafe, key) -> np.ndarray:
        """Each pilot pixel's squared XYZ error with every pixel on method ``key``."""
        settings = {"n_lights": n_lights, "n_samples": n_samples, "failsafe": failsafe}
        horizon = self.horizons[n_sectors]
        only = None if key == "hybrid" else {int(g): key for g in np.unique(self.groups)}
        L, _ = shade_canvas(
            self.scene, self.px, settings | {"by_group": only}, lambda: horizon, self.backend
        )
        return np.sum((channels_to_XYZ(L, self.scene.design) - self.reference) ** 2, axis=-1)


#: The constants of :func:`frame_cost`: per point light for every pixel's shadow and diffuse
#: light, per point light and per FIS sample on the hybrid, per FIS sample alone, the fail-safe.
FRAME_COST = (1.3, 4.3, 1.3, 0.85, 74.0)
#: A group of similar α needs this many pilot pixels to take a method of its own.
MIN_GROUP_PIXELS = 32

#: The ladders in the order of :class:`PaintingSettings`'s first four fields.
_LADDERS = (LIGHT_LADDER, SAMPLE_LADDER, SECTOR_LADDER, (False, True))


def frame_cost(
    n_lights: int, n_samples: int, n_sectors: int, failsafe: bool, shares=(0.0, 0.0, 1.0)
) -> float:
    """A frame's cost model, in point-light evaluations per pixel (erratum E96).

    Every pixel tests each point light's shadow and sums its diffuse light (``c_d N``); a pixel
    on the point lights alone evaluates the lobe once per light (``N``), one on FIS alone once
    per sample (``c_f K``), and one on the hybrid evaluates the point lights and the four sigma
    points of each, weighs each light's region against the lobe and takes FIS's ``K + K/2``
    samples (``c_h N + c_hf K``), and its fail-safe (``c_s``). ``shares`` are the fractions of
    the pixels on the point lights, FIS and the hybrid; a sector costs only the horizon map's
    memory and precomputation (0.01). The constants (:data:`FRAME_COST`) are a least-squares fit to
    the times of 20 frames at 256² on the design painting (seed 41: each method alone and the
    hybrid with and without its fail-safe, N and K from 8 to 64; the model within 7 % of the
    hybrid's frames, within 30 % of the cheapest, 0.13 s); the report measures real frame times.

    Examples
    --------
    >>> frame_cost(32, 32, 36, True), frame_cost(16, 16, 12, False, (0.75, 0.25, 0.0))
    (295.16, 36.32)
    """
    c_d, c_h, c_hf, c_f, c_s = FRAME_COST
    share_pl, share_fis, share_hybrid = shares
    hybrid = c_h * n_lights + c_hf * n_samples + c_s * bool(failsafe)
    per_method = share_pl * n_lights + share_fis * c_f * n_samples + share_hybrid * hybrid
    return c_d * n_lights + per_method + 0.01 * n_sectors


def _moves(pilot: PaintingPilot, current: tuple) -> list:
    """Every one-step move from ``current``, ``(N, K, S, fail-safe, by_group)``.

    A rung down one ladder, or a group of similar α off the hybrid onto the point lights or FIS.
    """
    *rungs, by_group = current
    moves = []
    for k, ladder in enumerate(_LADDERS):
        rung = ladder.index(rungs[k])
        if rung > 0:
            moves.append((*rungs[:k], ladder[rung - 1], *rungs[k + 1 :], by_group))
    switched = dict(by_group)
    for group in pilot.switchable_groups():
        if group not in switched:
            for method in GROUP_METHODS[:-1]:
                moves.append((*rungs, tuple(sorted({**switched, group: method}.items()))))
    return moves


def _descend(pilot: PaintingPilot, start: tuple, accept) -> tuple:
    """From ``start``, one move at a time (:func:`_moves`): the largest saving ``accept`` takes."""
    current = start
    while True:
        saving = [(pilot.cost(*current) - pilot.cost(*m), m) for m in _moves(pilot, current)]
        # cheapest first: the largest saving whose pilot error ``accept`` allows
        for _, candidate in sorted(saving, key=lambda m: -m[0]):
            if accept(candidate):
                current = candidate
                break
        else:
            return current


def check_tolerance(tolerance) -> float:
    """``tolerance`` as a float after checking it is a relative error in (0, 1) (one-line error).

    Examples
    --------
    >>> check_tolerance(0.02)
    0.02
    >>> check_tolerance(float("nan"))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --tolerance: must be a relative error in (0, 1) (0.02 is 2 %),
    got nan
    """
    require(
        isinstance(tolerance, int | float) and np.isfinite(tolerance) and 0 < tolerance < 1,
        f"--tolerance: must be a relative error in (0, 1) (0.02 is 2 %), got {tolerance!r}",
    )
    return float(tolerance)


def settings_from_tolerance(
    scene: PaintingScene,
    tolerance: float,
    size: int = 256,
    backend: str = "numba",
    pilot: PaintingPilot | None = None,
    eye=EYE,
) -> PaintingSettings:
    """The cheapest N, K, S and fail-safe whose pilot error is within ``tolerance`` (erratum E96).

    From the top of every ladder, one rung down at a time, always the step that saves most of
    :func:`frame_cost` while the pilot's error stays within ``PILOT_MARGIN × tolerance``.

    Parameters
    ----------
    scene : PaintingScene
        The painting, its light and its lighting method (:func:`painting_scene`).
    tolerance : float
        Relative RMS error of the frame's XYZ against brute force, > 0 (0.02 is 2 %).
    size : int
        The frame's side, pixels: the pilot's pixels are drawn from the frame's.
    backend : {"numba", "numpy"}
    pilot : PaintingPilot, optional
        A pilot of this scene already made (several tolerances share one).
    eye : (3,) array_like
        The viewer in the canvas's frame, m: the pilot's pixels are the canvas as they see it.

    Returns
    -------
    PaintingSettings
        With ``tolerance``, ``pilot_error`` (the promised bound) and ``met``.

    Examples
    --------
    >>> scene = painting_scene("D65", "hybrid", impasto_painting(32, seed=5),
    ...                        light_resolution=(16, 8))
    >>> s = settings_from_tolerance(scene, 0.05, size=12, backend="numpy")
    >>> s.met, s.pilot_error <= 0.05, s.n_lights in LIGHT_LADDER
    (True, True, True)
    """
    check_tolerance(tolerance)
    pilot = pilot or PaintingPilot(scene, size, backend, eye)
    top = (*(ladder[-1] for ladder in _LADDERS), ())
    within = PILOT_MARGIN * tolerance
    met = pilot.error(*top) <= within
    chosen = _descend(pilot, top, lambda c: pilot.error(*c) <= within) if met else top
    return PaintingSettings(
        *chosen[:-1],
        tolerance=float(tolerance),
        pilot_error=pilot.error(*chosen),
        met=bool(met),
        by_group=chosen[-1],
        shares=tuple(round(x, 4) for x in pilot.shares(chosen[-1]))
        if pilot.switchable_groups()
        else None,
    )


#: ``tolerance`` of :func:`render_painting_to_tolerance` (``--tolerance fixed``): no worse than
#: the fixed settings, on the pilot's evidence (:func:`settings_no_worse_than`).
NO_WORSE_THAN_FIXED = "fixed"

#: How many standard errors of the pilot's difference (:meth:`PaintingPilot.difference_sigma`)
#: settings must stay below their baseline's pilot error to count as no worse (one-sided, 98 %).
PAIRED_Z = 2.0


def settings_no_worse_than(
    scene: PaintingScene,
    baseline: PaintingSettings = FIXED_SETTINGS,
    size: int = 256,
    backend: str = "numba",
    pilot: PaintingPilot | None = None,
    eye=EYE,
    z: float = PAIRED_Z,
) -> PaintingSettings:
    """The cheapest settings whose error is, on the pilot's evidence, no worse than a baseline's.

    The descent of :func:`settings_from_tolerance`, from the top of every ladder, accepts a move
    when the pilot's error stays below ``baseline``'s by ``z`` standard errors of the difference
    (:meth:`PaintingPilot.difference_sigma`): the two errors come from the same pixels, and the
    frame's pixels would rank them otherwise about as often as their difference is within its
    noise. Where no settings cheaper than ``baseline`` qualify (by :func:`frame_cost`), the
    baseline is returned (erratum E96).

    Parameters
    ----------
    scene : PaintingScene
    baseline : PaintingSettings
        The settings to match (default: the fixed 32/32/36 with the fail-safe).
    size, backend, pilot, eye
        As in :func:`settings_from_tolerance`.
    z : float
        Standard errors of margin, >= 0.

    Returns
    -------
    PaintingSettings
        ``tolerance`` is the baseline's pilot error and ``pilot_error`` the chosen settings'.

    Examples
    --------
    >>> scene = painting_scene("D65", "hybrid", impasto_painting(32, seed=5),
    ...                        light_resolution=(16, 8))
    >>> pilot = PaintingPilot(scene, 12, "numpy")
    >>> s = settings_no_worse_than(scene, pilot=pilot)
    >>> s.pilot_error <= s.tolerance
    True
    """
    require(np.isfinite(z) and z >= 0, f"no worse than: z must be >= 0, got {z!r}")
    pilot = pilot or PaintingPilot(scene, size, backend, eye)
    base = (baseline.n_lights, baseline.n_samples, baseline.n_sectors, baseline.failsafe,
            tuple(baseline.by_group))  # fmt: skip
    limit = pilot.error(*base)

    def no_worse(candidate) -> bool:
        return pilot.error(*candidate) + z * pilot.difference_sigma(candidate, base) <= limit

    top = (*(ladder[-1] for ladder in _LADDERS), ())
    chosen = _descend(pilot, top, no_worse) if no_worse(top) else base
    if pilot.cost(*chosen) >= pilot.cost(*base):
        chosen = base
    return PaintingSettings(
        *chosen[:-1],
        tolerance=float(limit),
        pilot_error=pilot.error(*chosen),
        by_group=chosen[-1],
        baseline="fixed" if baseline == FIXED_SETTINGS else "given",
        shares=tuple(round(x, 4) for x in pilot.shares(chosen[-1]))
        if pilot.switchable_groups()
        else None,
    )


def render_painting_to_tolerance(
    light: str = "D65",
    size: int = 256,
    tolerance: float = 0.02,
    method: str = "hybrid",
    painting=None,
    progress=None,
    **options,
) -> dict:
    """:func:`render_painting` at the settings :func:`settings_from_tolerance` chooses.

    Parameters
    ----------
    light, size, method, painting, progress
        As in :func:`render_painting`.
    tolerance : float or "fixed"
        Relative RMS error against brute force, > 0; or ``"fixed"``: the cheapest settings the
        pilot finds no worse than the fixed 32/32/36 (:func:`settings_no_worse_than`).
    **options
        ``design``, ``light_resolution``, ``spectra``, ``light_map``, ``backend``, ``eye``,
        ``tilt`` of :func:`render_painting` (the pilot is made in the frame's pose and light).

    Returns
    -------
    dict
        As :func:`render_painting`; ``settings`` also holds ``tolerance``, ``pilot_error`` (the
        promised bound), ``met`` and ``choose_seconds`` (the pilot's cost, not in ``seconds``).

    Examples
    --------
    >>> out = render_painting_to_tolerance("A", 24, 0.05, painting=impasto_painting(32, seed=5),
    ...     light_resolution=(16, 8), backend="numpy")
    >>> out["settings"]["met"], out["settings"]["pilot_error"] <= 0.05
    (True, True)
    """
    from reference.progress import StageTimer

    if tolerance != NO_WORSE_THAN_FIXED:
        check_tolerance(tolerance)
    painting = painting or impasto_painting(size)
    keys = ("design", "light_resolution", "spectra", "light_map")
    scene_options = {k: options[k] for k in keys if k in options}
    rest = painting_scene(light, method, painting, **scene_options)
    # the pilot sees the canvas in the frame's pose
    scene, eye = posed_scene(rest, options.get("eye", EYE), options.get("tilt", 0.0))
    fixed = tolerance == NO_WORSE_THAN_FIXED
    timer = StageTimer(
        progress,
        "settings no worse than fixed" if fixed else f"settings for a tolerance of {tolerance:g}",
    )
    with timer.stage("pilot"):
        backend = options.get("backend", "numba")
        if fixed:
            chosen = settings_no_worse_than(scene, FIXED_SETTINGS, size, backend, eye=eye)
        else:
            chosen = settings_from_tolerance(scene, tolerance, size, backend, eye=eye)
    out = render_painting(
        light, size, method, painting, progress=progress, **options, **chosen.render_options()
    )
    out["settings"] = asdict(chosen) | {"choose_seconds": timer.seconds["pilot"]}
    return out
