"""ImpastoR lighting validation (§3.5, §5.2, Ferwerda): the booth, the painting, gloss, shadows.

The lighting half of what ``specref impastor`` and the report's "ImpastoR" section show; the
colour half (Table 1, channel counts, metamers, the display) is ``validation.impastor``:

- :func:`booth_plane_light`, :func:`impasto_painting`, :func:`render_painting`: the demo painting
  under the booth lights, with per-stage frame times; :func:`cached_horizon_map` computes a height
  field's horizon map once, not once per frame.
- :func:`specular_error_vs_alpha`: point lights, FIS and the hybrid against the brute-force
  integral, over roughness (§3.5.2).
- :func:`shadow_agreement`: horizon maps against ray-marched shadows over the sector count
  (§3.5.3).
- :func:`gloss_validation`: goniometric luminance curves of gray Ward–Dür samples (Fig. 15);
  :func:`ward_duer_albedo`: the white-furnace albedo of the Ward–Dür lobe.
"""

from __future__ import annotations

import hashlib
import time
from collections import OrderedDict
from pathlib import Path

import numpy as np

from reference.arealights import PlaneLight, booth_light_image
from reference.colorimetry import XYZ_to_display_RGB
from reference.errors import require, require_positive_int
from reference.horizon import (
    horizon_lookup,
    horizon_map,
    light_azimuth_elevation,
    normal_map_from_height,
    ray_march_shadows,
    tangent_to_world,
)
from reference.multispectral import (
    MS_GRID,
    MULTISPECTRAL_DESIGNS,
    channels_to_XYZ,
    light_to_channels,
    spectra_to_channels,
)
from reference.point_lights import illuminance_point_lights, point_lights_from_plane
from reference.spectra import resample_spectrum, spectrum_from_csv, spectrum_from_dataset
from reference.specular_hybrid import specular_hybrid, specular_hybrid_parts
from reference.specular_lighting import (
    specular_brute_force,
    specular_fis,
    specular_point_lights,
)

__all__ = [
    "EYE",
    "LIGHTING_METHODS",
    "PAINT_SPECTRA",
    "booth_plane_light",
    "cached_horizon_map",
    "gloss_validation",
    "impasto_painting",
    "load_paint_spectra",
    "render_painting",
    "shadow_agreement",
    "specular_error_vs_alpha",
    "ward_duer_albedo",
]

#: Lighting methods of the demo painting (frame times in the report).
LIGHTING_METHODS = ("median_cut", "variance_min", "fis", "hybrid")
#: Measured reflectances used for the painting's strokes (``../shared/data/spectra``).
PAINT_SPECTRA = (
    "lemon",
    "orange",
    "brick",
    "terracotta",
    "chocolate",
    "blackboard",
    "egg-shell-brown",
    "cardboard",
    "toothpaste",
    "office-paper",
)
#: The booth: the viewer's eye and the ceiling light (§3.2, Fig. 7), metres, y up.
EYE = (0.0, 0.45, 0.6)


# --- the booth and the painting ------------------------------------------------------------------


def booth_plane_light(kind: str = "fluorescent", width: int = 128, height: int = 64) -> PlaneLight:
    """The booth ceiling: a 1.2 m × 0.8 m light at y = 0.6 m over the painting (Fig. 7, Ferwerda).

    Examples
    --------
    >>> booth_plane_light("fluorescent", 16, 8).n_light
    array([ 0., -1.,  0.])
    """
    image = booth_light_image(kind, width, height)
    return PlaneLight(image, (-0.6, 0.6, -1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.2, 0.8)


def _booth_kind(light: str) -> str:
    return "incandescent" if light == "A" else "fluorescent"


def load_paint_spectra(shared_data=None, names=PAINT_SPECTRA) -> dict:
    """Measured reflectances from ``../shared/data/spectra/physicallybased`` on the 5 nm grid.

    Raises
    ------
    SpecrefError
        When the folder is missing, naming it and how to point at it.

    Examples
    --------
    >>> spectra = load_paint_spectra(names=("lemon",))
    >>> spectra["lemon"].shape
    (81,)
    """
    import os

    root = Path(
        shared_data
        or os.environ.get("SPECREF_SHARED_DATA")
        or Path(__file__).resolve().parents[1].parent / "shared" / "data"
    )
    folder = root / "spectra" / "physicallybased"
    require(
        folder.is_dir(),
        f"{folder}: measured spectra not found; the ImpastoR painting needs ../shared/data "
        "(set SPECREF_SHARED_DATA to the shared data folder)",
    )
    out = {}
    for name in names:
        spectrum = spectrum_from_csv(folder / f"{name}__nix_export.csv", name=name)
        out[name] = resample_spectrum(spectrum, MS_GRID, extrapolation="constant")
    return out


def impasto_painting(size: int = 256, seed: int = 1, width_m: float = 0.3, n_strokes=None) -> dict:
    """A procedural impasto painting: brush-stroke height field, stroke materials, gloss maps.

    Strokes are ridged bands (a raised body with a furrow along its middle) of random direction,
    length and width, laid in order so that later strokes cover earlier ones; a canvas weave lies
    under them. Everything is periodic, so the surface tiles.

    Parameters
    ----------
    size : int
        Pixels per side.
    seed : int
        Random seed.
    width_m : float
        Physical width, m (a 30 cm canvas by default).
    n_strokes : int, optional
        Default ``400 · (width_m / 0.3)²``.

    Returns
    -------
    dict
        ``height`` (m, (size, size)), ``material`` (int index into :data:`PAINT_SPECTRA`, −1 is
        the primed canvas), ``rho_s`` and ``alpha`` maps, ``pixel_size`` (m).

    Examples
    --------
    >>> p = impasto_painting(64, seed=3)
    >>> p["height"].shape, bool(p["height"].max() < 5e-3), int(p["material"].max()) < 10
    ((64, 64), True, True)
    """
    size = require_positive_int(size, "painting: size", 8192)
    rng = np.random.default_rng(seed)
    pixel = width_m / size
    n = n_strokes or int(400 * (width_m / 0.3) ** 2)
    y, x = np.meshgrid(np.arange(size) * pixel, np.arange(size) * pixel, indexing="ij")
    # Canvas weave: two crossed sinusoids, 1 mm period, 20 µm deep.
    height = 2e-5 * (np.sin(2 * np.pi * x / 1e-3) * np.sin(2 * np.pi * y / 1e-3))
    material = np.full((size, size), -1, dtype=np.int64)
    rho_s = np.full((size, size), 0.01)
    alpha = np.full((size, size), 0.4)
    for _ in range(n):
        cx, cy = rng.uniform(0, width_m, 2)
        theta = rng.uniform(0, np.pi)
        length = rng.uniform(0.02, 0.07)
        half_width = rng.uniform(0.002, 0.006)
        amplitude = rng.uniform(5e-4, 2e-3)
        # Minimum-image offsets: the canvas tiles.
        dx = (x - cx + width_m / 2) % width_m - width_m / 2
        dy = (y - cy + width_m / 2) % width_m - width_m / 2
        along = dx * np.cos(theta) + dy * np.sin(theta)
        across = -dx * np.sin(theta) + dy * np.cos(theta)
        r = np.abs(across) / half_width
        # A thick body with steep edges and a furrow along its middle (the brush's trace).
        body = np.sqrt(np.clip(1.0 - r**6, 0.0, None)) * (1.0 - 0.4 * np.exp(-((r / 0.25) ** 2)))
        ends = np.sqrt(np.clip(1.0 - (2.0 * along / length) ** 6, 0.0, None))
        bump = amplitude * body * ends
        covered = bump > 0.15 * amplitude
        # The new stroke lies on top: it replaces the surface where it is thick.
        height = np.where(covered, np.maximum(height, bump + 0.5 * height), height)
        material[covered] = rng.integers(0, len(PAINT_SPECTRA))
        rho_s[covered] = rng.uniform(0.02, 0.08)
        alpha[covered] = rng.uniform(0.04, 0.3)
    return {
        "height": height,
        "material": material,
        "rho_s": rho_s,
        "alpha": alpha,
        "pixel_size": pixel,
        "width_m": width_m,
    }


def _painting_gbuffer(size: int, width_m: float):
    from reference.camera import Camera
    from reference.gbuffer import render_gbuffer
    from reference.geometry import Plane

    plane = Plane((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), size=(width_m, width_m))
    camera = Camera(eye=EYE, target=(0.0, 0.0, 0.0), fov_deg=25.0)
    return render_gbuffer([plane], camera, size, size)


#: Horizon maps by height-field content (``cached_horizon_map``); the oldest is dropped first.
_HORIZON_CACHE: OrderedDict = OrderedDict()
_HORIZON_CACHE_SIZE = 4


def cached_horizon_map(
    height, pixel_size: float, n_sectors: int = 18, max_steps: int = 32, backend: str = "numba"
) -> np.ndarray:
    """:func:`reference.horizon.horizon_map`, computed once per height field and settings.

    The horizon map depends only on the height field (§3.5.3, Ferwerda), not on the light or the
    view, so the renderer computes it once and every frame looks it up. The cache is keyed by the
    height field's content (SHA-1 of its bytes, shape and dtype) and the settings, so an edited
    height field is never served a stale map; it holds the last four maps, read-only.

    Parameters
    ----------
    height : array_like, shape (H, W)
        Height field, m.
    pixel_size : float
        Texel size, m.
    n_sectors, max_steps : int
        As in :func:`reference.horizon.horizon_map`.
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray
        The horizon map (read-only; shared by every caller with the same inputs).

    Examples
    --------
    >>> h = impasto_painting(16, seed=1)["height"]
    >>> first = cached_horizon_map(h, 0.3 / 16, 6, 8, backend="numpy")
    >>> cached_horizon_map(h.copy(), 0.3 / 16, 6, 8, backend="numpy") is first
    True
    >>> cached_horizon_map(h + 1e-4, 0.3 / 16, 6, 8, backend="numpy") is first
    False
    """
    h = np.ascontiguousarray(height, dtype=np.float64)
    digest = hashlib.sha1(h.tobytes()).hexdigest()
    key = (digest, h.shape, float(pixel_size), int(n_sectors), int(max_steps), backend)
    if key in _HORIZON_CACHE:
        _HORIZON_CACHE.move_to_end(key)
        return _HORIZON_CACHE[key]
    hmap = horizon_map(h, pixel_size, n_sectors, max_steps, backend=backend)
    hmap.setflags(write=False)
    _HORIZON_CACHE[key] = hmap
    while len(_HORIZON_CACHE) > _HORIZON_CACHE_SIZE:
        _HORIZON_CACHE.popitem(last=False)
    return hmap


def render_painting(
    light: str = "D65",
    size: int = 256,
    method: str = "hybrid",
    painting=None,
    design: str = "optimized",
    n_lights: int = 32,
    n_samples: int = 32,
    light_resolution: tuple = (128, 64),
    shadows: bool = True,
    spectra=None,
    backend: str = "numba",
) -> dict:
    """Render the demo painting under a booth light through the whole ImpastoR pipeline.

    G-buffer of the canvas plane, normal map from the height map, six-channel ρ_d from measured
    spectra, diffuse light from median-cut lights (Eqs. (2)-(3), Ferwerda) with horizon-map
    shadows, specular light by ``method``, and XYZ through the 3×N matrix.

    Parameters
    ----------
    light : str
        Illuminant key; A uses the incandescent booth image, others the fluorescent one.
    size : int
        Image side, pixels.
    method : {"median_cut", "variance_min", "fis", "hybrid"}
        Specular lighting (the diffuse term always uses the median-cut or variance-min lights).
    painting : dict, optional
        From :func:`impasto_painting` (default: one at ``size``).
    design, n_lights, n_samples, light_resolution, shadows
        Pipeline settings.
    backend : {"numba", "numpy"}
        Kernels or their NumPy twins (no JIT warm-up: for small images).
    spectra : dict, optional
        From :func:`load_paint_spectra`.

    Returns
    -------
    dict
        ``XYZ`` (H, W, 3) in cd/m², ``sRGB`` encoded (H, W, 3) in [0, 1] (white = 1.2× the
        white diffuser's luminance), ``seconds`` per stage (``shadows`` is the horizon lookup,
        plus the horizon map the first time a height field is rendered: :func:`cached_horizon_map`).

    Examples
    --------
    >>> out = render_painting("D65", size=32, method="median_cut", light_resolution=(32, 16))
    >>> out["XYZ"].shape, sorted(out["seconds"])
    ((32, 32, 3), ['diffuse', 'shadows', 'specular'])
    """
    from reference.errors import require_choice

    require_choice(method, LIGHTING_METHODS, "lighting method")
    painting = painting or impasto_painting(size)
    spectra = spectra or load_paint_spectra()
    d = MULTISPECTRAL_DESIGNS.lookup(design).reference(6)
    plane = booth_plane_light(_booth_kind(light), *light_resolution)
    sampling = "variance_min" if method == "variance_min" else "median_cut"
    lights = point_lights_from_plane(plane, sampling, n_lights)
    S6 = light_to_channels(spectrum_from_dataset("illuminant", light), d)
    g = _painting_gbuffer(size, painting["width_m"])
    mask = g.mask
    P, V = g.position[mask], g.view[mask]
    # Texel of each visible pixel (uv: u along +x columns, v along +z rows).
    n_tex = painting["height"].shape[0]
    col = np.clip((g.uv[mask][:, 0] * n_tex).astype(int), 0, n_tex - 1)
    row = np.clip((g.uv[mask][:, 1] * n_tex).astype(int), 0, n_tex - 1)
    T, B, N_geo = np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([0, 1.0, 0])
    normals_tangent = normal_map_from_height(painting["height"], painting["pixel_size"])
    N = tangent_to_world(normals_tangent[row, col], T, B, N_geo)
    seconds = {}
    start = time.perf_counter()
    visibility = None
    if shadows:
        # Once per height field, not per frame (§3.5.3, Ferwerda: a precomputed map).
        hmap = cached_horizon_map(painting["height"], painting["pixel_size"], 18, 32, backend)
        to_light = lights.position[None] - P[:, None]
        phi, beta = light_azimuth_elevation(to_light, T, B, N_geo)
        visibility = horizon_lookup(hmap[row, col][:, None, :], phi, beta).astype(float)
    seconds["shadows"] = time.perf_counter() - start
    # Six-channel materials: ρ_d from the measured spectra, ρ_s and α from the maps.
    names = list(PAINT_SPECTRA)
    R6 = spectra_to_channels(np.stack([spectra[n] for n in names]), d)
    canvas = spectra_to_channels(spectra.get("office-paper", np.full(81, 0.85)), d)
    table = np.concatenate([R6, canvas[None]])
    material = painting["material"][row, col]
    rho_d = table[np.where(material < 0, len(names), material)]
    rho_s = painting["rho_s"][row, col][:, None]
    alpha = painting["alpha"][row, col]
    start = time.perf_counter()
    # Eq. (2), Ferwerda: illuminance from the point lights (luminance image: one channel)
    E = illuminance_point_lights(P, N, lights, visibility)
    # Eq. (3), Ferwerda: L_out,j = ρ_d,j S_j E / π
    L_diffuse = rho_d * S6 * E / np.pi
    seconds["diffuse"] = time.perf_counter() - start
    start = time.perf_counter()
    if method in ("median_cut", "variance_min"):
        I_s = specular_point_lights(P, N, V, alpha, lights, visibility, backend=backend)
    elif method == "fis":
        I_s = specular_fis(P, N, V, alpha, plane, n_samples, backend=backend)
    else:
        I_s = specular_hybrid(P, N, V, alpha, plane, lights, n_samples, visibility, backend)
    L_specular = rho_s * S6 * I_s
    seconds["specular"] = time.perf_counter() - start
    XYZ = np.zeros((*g.shape, 3))
    XYZ[mask] = channels_to_XYZ(L_diffuse + L_specular, d)
    # Display: linear sRGB with the white diffuser under the booth light at 1/1.2 of white.
    white_Y = float(np.median(E)) / np.pi
    rgb = XYZ_to_display_RGB(XYZ / (1.2 * white_Y))
    from reference.display import linear_to_display

    return {"XYZ": XYZ, "sRGB": linear_to_display(rgb, "srgb"), "seconds": seconds}


# --- lighting and shadow errors ------------------------------------------------------------------


def _painting_samples(n_side: int, painting: dict):
    """Surface points on a grid over the painting, with normal-mapped normals and view vectors."""
    w = painting["width_m"]
    g = (np.arange(n_side) + 0.5) / n_side
    u, v = np.meshgrid(g, g)
    P = np.stack([(u - 0.5) * w, np.zeros_like(u), (v - 0.5) * w], axis=-1).reshape(-1, 3)
    n_tex = painting["height"].shape[0]
    col = np.clip((u.ravel() * n_tex).astype(int), 0, n_tex - 1)
    row = np.clip((v.ravel() * n_tex).astype(int), 0, n_tex - 1)
    tangent = normal_map_from_height(painting["height"], painting["pixel_size"])[row, col]
    N = tangent_to_world(tangent, [1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0])
    V = np.asarray(EYE) - P
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    return P, N, V


def _relative_rms(x, reference) -> float:
    return float(np.sqrt(np.mean((x - reference) ** 2)) / np.sqrt(np.mean(reference**2)))


def specular_error_vs_alpha(
    alphas=(0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5),
    n_side: int = 12,
    light_resolution: tuple = (128, 64),
    n_lights: int = 32,
    n_samples: int = 32,
    supersample: int = 8,
    painting=None,
    backend: str = "numba",
    light_kind: str = "fluorescent",
) -> dict:
    """Relative RMS error of point lights, FIS and the hybrid against the brute-force integral.

    §3.5.2, Ferwerda: at each roughness α (uniform over the painting), the specular integral at
    ``n_side²`` normal-mapped points under the booth light (``light_kind``, a kind of
    ``reference.arealights.booth_light_image``; fluorescent by default). The reference sums every
    light pixel split into ``supersample²`` sub-pixels; its own error is estimated by doubling the
    supersampling and reported.

    Returns
    -------
    dict
        ``alpha`` and, per method, the relative RMS errors; ``reference_error``; ``fis_share`` (the
        mean weight the hybrid gives FIS).

    Examples
    --------
    >>> r = specular_error_vs_alpha((0.05,), n_side=3, light_resolution=(32, 16), supersample=2)
    >>> sorted(r)
    ['alpha', 'fis', 'fis_share', 'hybrid', 'median_cut', 'reference_error']
    """
    painting = painting or impasto_painting(128, seed=2)
    P, N, V = _painting_samples(n_side, painting)
    plane = booth_plane_light(light_kind, *light_resolution)
    lights = point_lights_from_plane(plane, "median_cut", n_lights)
    out = {k: [] for k in ("alpha", "median_cut", "fis", "hybrid", "reference_error", "fis_share")}
    for alpha in alphas:
        a = np.full(len(P), float(alpha))
        reference = specular_brute_force(P, N, V, a, plane, 2 * supersample, backend)[..., 0]
        coarse = specular_brute_force(P, N, V, a, plane, supersample, backend)[..., 0]
        # one evaluation gives all three methods: the hybrid shades both of the others
        parts = specular_hybrid_parts(P, N, V, a, plane, lights, n_samples, backend=backend)
        pl, fis, hybrid = (parts[k][..., 0] for k in ("point_lights", "fis", "hybrid"))
        out["alpha"].append(float(alpha))
        out["median_cut"].append(_relative_rms(pl, reference))
        out["fis"].append(_relative_rms(fis, reference))
        out["hybrid"].append(_relative_rms(hybrid, reference))
        out["reference_error"].append(_relative_rms(coarse, reference))
        out["fis_share"].append(float((1.0 - parts["w_point_lights"]).mean()))
    return out


def shadow_agreement(
    sector_counts=(3, 6, 9, 12, 18, 24, 36),
    size: int = 256,
    elevations_deg=(15.0, 30.0, 45.0),
    n_azimuths: int = 16,
    max_steps: int = 32,
    painting=None,
    backend: str = "numba",
) -> dict:
    """Share of pixels where horizon-map and ray-marched shadows disagree, per sector count.

    §3.5.3, Ferwerda. Lights at each elevation and ``n_azimuths`` azimuths offset from the sector
    centres (raking light across a painting-like height field); both methods march the same steps,
    so only the azimuth quantisation differs.

    Returns
    -------
    dict
        ``sectors``, ``disagreement`` (share of pixel-light pairs), ``shadowed`` (share of
        pixel-light pairs in shadow by the reference).

    Examples
    --------
    >>> r = shadow_agreement((4, 18), size=32, n_azimuths=4, max_steps=8)
    >>> r["sectors"], all(0 <= v <= 1 for v in r["disagreement"])
    ([4, 18], True)
    """
    painting = painting or impasto_painting(size, seed=4)
    h, pixel = painting["height"], painting["pixel_size"]
    azimuths = (np.arange(n_azimuths) + 0.37) * 2.0 * np.pi / n_azimuths
    reference = {}
    for beta in elevations_deg:
        for phi in azimuths:
            reference[(beta, phi)] = ray_march_shadows(
                h, pixel, phi, np.radians(beta), max_steps, backend=backend
            )
    shadowed = float(np.mean([~lit for lit in reference.values()]))
    out = {"sectors": [], "disagreement": [], "shadowed": shadowed}
    for S in sector_counts:
        hmap = horizon_map(h, pixel, int(S), max_steps, backend=backend)
        wrong = [
            np.mean(horizon_lookup(hmap, phi, np.radians(beta)) != lit)
            for (beta, phi), lit in reference.items()
        ]
        out["sectors"].append(int(S))
        out["disagreement"].append(float(np.mean(wrong)))
    return out


def gloss_validation(
    gloss=((0.06, 0.01), (0.06, 0.02), (0.06, 0.04), (0.06, 0.07), (0.06, 0.12), (0.06, 0.2)),
    rho_d: float = 0.18,
    angles_deg=None,
    source_luminance: float = 20000.0,
    n_samples: int = 32,
    backend: str = "numba",
) -> dict:
    """Goniometric luminance curves of gray Ward–Dür samples under a small area source (Fig. 15).

    §5.2, Ferwerda: a 2.3 cm × 3.5 cm source 0.5 m away at 7.5° incidence, the detector swept
    from 6° to 30° in the plane of incidence. The pipeline (median-cut diffuse, hybrid specular) is
    compared with the brute-force integral, sample by sample from high to low gloss.

    Returns
    -------
    dict
        ``angles_deg``, and per sample (``rho_s``, ``alpha``) the ``pipeline`` and ``reference``
        luminances (cd/m²) and the largest relative error near the peak.

    Examples
    --------
    >>> r = gloss_validation(gloss=((0.06, 0.05),), angles_deg=[7.5])
    >>> abs(r["samples"][0]["pipeline"][0] / r["samples"][0]["reference"][0] - 1) < 0.05
    True
    """
    angles = np.asarray(angles_deg if angles_deg is not None else np.concatenate(
        [np.arange(6.0, 10.01, 0.5), [11, 12, 14, 16, 20, 25, 30]]
    ), dtype=np.float64)  # fmt: skip
    theta_i = np.radians(7.5)
    L_hat = np.array([-np.sin(theta_i), np.cos(theta_i), 0.0])
    A = np.array([np.cos(theta_i), np.sin(theta_i), 0.0])
    B = np.array([0.0, 0.0, 1.0])
    l_A, l_B = 0.023, 0.035
    centre = 0.5 * L_hat
    origin = centre - 0.5 * l_A * A - 0.5 * l_B * B
    plane = PlaneLight(np.full((16, 16), source_luminance), origin, A, B, l_A, l_B)
    lights = point_lights_from_plane(plane, "median_cut", 32)
    theta = np.radians(angles)
    V = np.stack([np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)
    P = np.zeros_like(V)
    N = np.tile([0.0, 1.0, 0.0], (len(V), 1))
    E = illuminance_point_lights(P, N, lights)[:, 0]
    samples = []
    for rho_s, alpha in gloss:
        a = np.full(len(V), alpha)
        specular = specular_hybrid(P, N, V, a, plane, lights, n_samples, backend=backend)[:, 0]
        brute = specular_brute_force(P, N, V, a, plane, 8, backend)[:, 0]
        # Eq. (3), Ferwerda, for the gray diffuse part, plus ρ_s times the specular integral
        pipeline = rho_d * E / np.pi + rho_s * specular
        reference = rho_d * E / np.pi + rho_s * brute
        error = np.abs(pipeline / reference - 1.0)
        samples.append(
            {
                "rho_s": rho_s,
                "alpha": alpha,
                "pipeline": pipeline.tolist(),
                "reference": reference.tolist(),
                "max_relative_error": float(error.max()),
            }
        )
    return {"angles_deg": angles.tolist(), "rho_d": rho_d, "samples": samples}


def ward_duer_albedo(
    alphas=(0.01, 0.05, 0.1, 0.3, 0.5), thetas_deg=(0.0, 30.0, 45.0, 60.0)
) -> dict:
    """White-furnace albedo of the Ward–Dür lobe (``ρ_s = 1``, Eq. (4), Ferwerda), by quadrature.

    Dür's normalization claims the albedo stays at or below ρ_s away from grazing incidence
    (§3.1.2; errata E12 for grazing incidence). Each albedo is
    :func:`reference.brdf.albedo_quadrature` at order 48, with ``|q48 − q24|`` as its error.

    Returns
    -------
    dict
        ``alpha``, ``theta_deg``, ``albedo`` and ``error`` (lists, one per case), and ``max``.

    Examples
    --------
    >>> r = ward_duer_albedo((0.1,), (0.0,))
    >>> bool(0.9 < r["albedo"][0] <= 1.0), r["error"][0] < 1e-6
    (True, True)
    """
    from reference.brdf import albedo_quadrature, brdf_ward_duer_specular

    normal = np.array([0.0, 0.0, 1.0])
    out = {"alpha": [], "theta_deg": [], "albedo": [], "error": []}
    for alpha in alphas:
        for theta in thetas_deg:
            t = np.radians(theta)
            wi = np.array([np.sin(t), 0.0, np.cos(t)])
            f = lambda a, b, alpha=alpha: brdf_ward_duer_specular(a, b, normal, alpha)  # noqa: E731
            q48 = albedo_quadrature(f, wi, normal, 48)
            q24 = albedo_quadrature(f, wi, normal, 24)
            out["alpha"].append(float(alpha))
            out["theta_deg"].append(float(theta))
            out["albedo"].append(q48)
            out["error"].append(abs(q48 - q24))
    out["max"] = max(out["albedo"])
    return out
