"""The per-pixel hybrid on cases it was not designed on (§3.5.2, Ferwerda; erratum E17).

The hybrid of median-cut point lights and FIS (``impastor.specular_hybrid``) must never be much
worse than the better of the two. This module builds the cases that claim is measured on and
measures it:

- lights: both booth lights, a small bright lamp beside a dim panel (:func:`lamp_and_panel_image`),
  and ceiling images cut from the shipped environment maps (:func:`ceiling_from_environment`);
- paintings: procedural impasto paintings by seed, sampled on a grid of points;
- N point lights, K FIS samples, the report's α grid.

:data:`TRAINING` lists the cases the hybrid was designed on; :func:`held_out_cases` generates the
others from seeds the design never used. :func:`hybrid_case_ratios` returns, per α, the hybrid's
relative RMS error over the better method's.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from impastor.arealights import PlaneLight
from impastor.painting import booth_plane_light, impasto_painting, painting_samples
from impastor.point_lights import point_lights_from_plane
from impastor.specular_hybrid import specular_hybrid_parts
from impastor.specular_lighting import specular_brute_force
from reference.data import data_path
from reference.errors import require
from reference.geometry.envmap import latlong_lookup_bilinear

__all__ = [
    "ALPHAS",
    "ENVIRONMENTS",
    "TRAINING",
    "HybridCase",
    "case_light",
    "ceiling_from_environment",
    "held_out_cases",
    "hybrid_case_ratios",
    "lamp_and_panel_image",
    "ratio_distribution",
]

#: The report's α grid (``validation.studies.impastor_lighting.specular_error_vs_alpha``).
ALPHAS = (0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5)
#: The shipped environment maps (``data:environments``).
ENVIRONMENTS = (
    "StageEnvLatLong.exr",
    "st_fagans_interior_1k.hdr",
    "studio_small_03_1k.hdr",
    "venice_sunset_1k.hdr",
)


@dataclass(frozen=True)
class HybridCase:
    """One painting under one light with N point lights and K FIS samples.

    ``light`` is ``"fluorescent"``, ``"incandescent"``, ``"lamp_panel:<seed>"`` or
    ``"env:<file>:<azimuth_deg>"`` (a ceiling cut from that map, turned by the azimuth).
    """

    painting_seed: int
    light: str
    n_lights: int = 32
    n_samples: int = 32

    @property
    def name(self) -> str:
        """A readable label: light, painting seed, N and K."""
        return f"{self.light} seed {self.painting_seed} N={self.n_lights} K={self.n_samples}"


#: The cases the hybrid was designed on (painting seeds 2, 5, 7; ceilings at azimuth 0°; the
#: lamp-and-panel light of seed 0). No held-out case shares a painting seed, a ceiling azimuth or
#: a lamp seed with these.
TRAINING = (
    HybridCase(2, "fluorescent"),
    HybridCase(7, "fluorescent", 64, 64),
    HybridCase(5, "incandescent", 8, 16),
    HybridCase(2, "incandescent", 64, 32),
    HybridCase(7, "lamp_panel:0", 32, 32),
    HybridCase(5, "env:studio_small_03_1k.hdr:0", 32, 32),
    HybridCase(2, "env:st_fagans_interior_1k.hdr:0", 32, 64),
    HybridCase(7, "env:venice_sunset_1k.hdr:0", 8, 32),
)


def held_out_cases(n_paintings: int = 24, first_seed: int = 101) -> list[HybridCase]:
    """Cases the design never saw: painting seeds from ``first_seed``, every light kind.

    Each painting seed gets one light and one (N, K) pair, cycling through both booth lights, the
    lamp-and-panel light (its own seed) and a ceiling cut from each shipped environment map (at an
    azimuth from the seed), and through N ∈ {8, 32, 64}, K ∈ {16, 32, 64}.

    Examples
    --------
    >>> cases = held_out_cases(7)
    >>> len(cases), cases[0].painting_seed, sorted({c.light.split(":")[0] for c in cases})
    (7, 101, ['env', 'fluorescent', 'incandescent', 'lamp_panel'])
    """
    rng = np.random.default_rng(first_seed)
    lights = ["fluorescent", "incandescent", "lamp_panel", *(f"env:{e}" for e in ENVIRONMENTS)]
    out = []
    for k in range(n_paintings):
        seed = first_seed + k
        kind = lights[k % len(lights)]
        if kind == "lamp_panel":
            kind = f"lamp_panel:{seed}"
        elif kind.startswith("env:"):
            kind = f"{kind}:{int(rng.integers(10, 350))}"
        n_lights = (8, 32, 64)[(k // len(lights)) % 3]
        n_samples = (16, 32, 64)[k % 3]
        out.append(HybridCase(seed, kind, n_lights, n_samples))
    return out


def lamp_and_panel_image(seed: int, width: int = 64, height: int = 32) -> np.ndarray:
    """A dim diffuser panel with one small bright lamp at a random place (cd/m²).

    Examples
    --------
    >>> image = lamp_and_panel_image(1)
    >>> image.shape, bool(image.max() > 100 * image.min())
    ((32, 64), True)
    """
    rng = np.random.default_rng(seed)
    x = (np.arange(width) + 0.5) / width
    y = (np.arange(height) + 0.5) / height
    X, Y = np.meshgrid(x, y)
    cx, cy = rng.uniform(0.15, 0.85, 2)
    radius = rng.uniform(0.015, 0.04)
    panel = 40.0 * (1.0 + 0.5 * np.exp(-0.5 * ((X - 0.5) ** 2 + (Y - 0.5) ** 2) / 0.1))
    lamp = 2e4 * np.exp(-0.5 * ((X - cx) ** 2 + ((Y - cy) * height / width * 2) ** 2) / radius**2)
    return panel + lamp


def ceiling_from_environment(
    path, azimuth_deg: float = 0.0, width: int = 64, height: int = 32, supersample: int = 4
) -> PlaneLight:
    """The booth's ceiling rectangle filled with what an environment map shows above the painting.

    Each light pixel holds the map's luminance (Rec. 709 weights) in the direction from the
    painting's centre to the pixel, averaged over ``supersample²`` bilinear lookups, with the map
    turned by ``azimuth_deg`` about the vertical. The plane's geometry is
    :func:`impastor.painting.booth_plane_light`'s.

    Examples
    --------
    >>> plane = ceiling_from_environment("studio_small_03_1k.hdr", 0.0, 16, 8, 1)
    >>> plane.shape, bool(plane.image.min() >= 0)
    ((8, 16), True)
    """
    from reference.images.formats import read_image

    path = Path(path)
    if not path.is_absolute():
        path = data_path(f"environments/{path.as_posix()}")
    require(path.is_file(), f"{path}: environment map not found")
    env = read_image(path)[..., :3]
    luminance = env @ np.array([0.2126, 0.7152, 0.0722])
    geometry = booth_plane_light("fluorescent", width, height)
    s = int(supersample)
    rows = (np.arange(height * s) + 0.5) / s
    cols = (np.arange(width * s) + 0.5) / s
    R, C = np.meshgrid(rows, cols, indexing="ij")
    d = geometry.pixel_positions(R, C)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    turn = np.radians(azimuth_deg)
    x = np.cos(turn) * d[..., 0] + np.sin(turn) * d[..., 2]
    z = -np.sin(turn) * d[..., 0] + np.cos(turn) * d[..., 2]
    d = np.stack([x, d[..., 1], z], axis=-1)
    values = latlong_lookup_bilinear(luminance[..., None], d)[..., 0]
    image = values.reshape(height, s, width, s).mean(axis=(1, 3))
    return PlaneLight(
        np.maximum(image, 0.0),
        geometry.origin,
        geometry.A,
        geometry.B,
        geometry.l_A,
        geometry.l_B,
    )


def case_light(light: str, width: int = 64, height: int = 32) -> PlaneLight:
    """The plane light a :class:`HybridCase` names.

    Examples
    --------
    >>> case_light("lamp_panel:3", 16, 8).shape
    (8, 16)
    """
    kind, _, rest = light.partition(":")
    if kind in ("fluorescent", "incandescent"):
        return booth_plane_light(kind, width, height)
    geometry = booth_plane_light("fluorescent", width, height)
    if kind == "lamp_panel":
        image = lamp_and_panel_image(int(rest), width, height)
        return PlaneLight(
            image, geometry.origin, geometry.A, geometry.B, geometry.l_A, geometry.l_B
        )
    require(kind == "env", f"hybrid case: light: unknown kind {kind!r}")
    name, _, azimuth = rest.rpartition(":")
    return ceiling_from_environment(name, float(azimuth), width, height)


def hybrid_brute_force(
    seed: int,
    light: str,
    alpha: float,
    n_side: int = 6,
    painting_size: int = 128,
    light_resolution: tuple = (64, 32),
    supersample: int = 8,
    backend: str = "numba",
) -> tuple[np.ndarray, np.ndarray]:
    """The brute-force specular reference of a painting under a light at one α, and its check.

    What :func:`hybrid_case_ratios` measures against; it does not depend on the case's N and K,
    so cases that differ only in those can share it. Returns the renders at ``2·supersample``
    (the reference) and at ``supersample`` (its own error), each shape (n_side², C).

    Examples
    --------
    >>> reference, coarse = hybrid_brute_force(3, "fluorescent", 0.1, 2, 16, (16, 8), 2, "numpy")
    >>> reference.shape == coarse.shape, bool((reference >= 0).all())
    (True, True)
    """
    painting = impasto_painting(painting_size, seed=seed)
    P, N, V = painting_samples(n_side, painting)
    plane = case_light(light, *light_resolution)
    a = np.full(len(P), float(alpha))
    reference = specular_brute_force(P, N, V, a, plane, 2 * supersample, backend)[..., 0]
    coarse = specular_brute_force(P, N, V, a, plane, supersample, backend)[..., 0]
    return reference, coarse


def hybrid_case_ratios(
    case: HybridCase,
    alphas=ALPHAS,
    n_side: int = 6,
    painting_size: int = 128,
    light_resolution: tuple = (64, 32),
    supersample: int = 8,
    backend: str = "numba",
    brute_force: dict | None = None,
) -> dict:
    """Relative RMS errors of median cut, FIS and the hybrid against brute force, per α.

    ``brute_force`` maps α to :func:`hybrid_brute_force`'s pair for this case's painting and
    light, when already rendered (a sweep shares it between cases of other N and K).

    Returns
    -------
    dict
        ``alpha``, ``median_cut``, ``fis``, ``hybrid``, ``reference_error`` (doubling the
        supersampling) and ``ratio`` (hybrid over the better of the other two), lists.

    Examples
    --------
    >>> r = hybrid_case_ratios(HybridCase(3, "fluorescent", 8, 16), (0.1,), 2, 16, (16, 8), 2,
    ...                        "numpy")
    >>> len(r["ratio"]), r["ratio"][0] > 0
    (1, True)
    """
    painting = impasto_painting(painting_size, seed=case.painting_seed)
    P, N, V = painting_samples(n_side, painting)
    plane = case_light(case.light, *light_resolution)
    lights = point_lights_from_plane(plane, "median_cut", case.n_lights)
    out = {k: [] for k in ("alpha", "median_cut", "fis", "hybrid", "reference_error", "ratio")}
    rms = lambda x, ref: float(np.sqrt(np.mean((x - ref) ** 2) / np.mean(ref**2)))  # noqa: E731
    brute_force = brute_force or {}
    for alpha in alphas:
        a = np.full(len(P), float(alpha))
        reference, coarse = brute_force.get(alpha) or hybrid_brute_force(
            case.painting_seed,
            case.light,
            alpha,
            n_side,
            painting_size,
            light_resolution,
            supersample,
            backend,
        )
        parts = specular_hybrid_parts(P, N, V, a, plane, lights, case.n_samples, backend=backend)
        pairs = (("median_cut", "point_lights"), ("fis", "fis"), ("hybrid", "hybrid"))
        errors = {k: rms(parts[m][..., 0], reference) for k, m in pairs}
        out["alpha"].append(float(alpha))
        for key, value in errors.items():
            out[key].append(value)
        out["reference_error"].append(rms(coarse, reference))
        out["ratio"].append(errors["hybrid"] / min(errors["median_cut"], errors["fis"]))
    return out


def ratio_distribution(ratios) -> dict:
    """Summary of hybrid/better ratios over (case, α) pairs.

    Examples
    --------
    >>> d = ratio_distribution([1.0, 1.05, 1.2])
    >>> d["n"], round(d["share_within_1.1"], 3), d["max"]
    (3, 0.667, 1.2)
    """
    r = np.asarray(ratios, dtype=np.float64)
    return {
        "n": int(r.size),
        "share_within_1.1": float(np.mean(r <= 1.1)),
        "share_within_1.5": float(np.mean(r <= 1.5)),
        "median": float(np.median(r)),
        "p95": float(np.quantile(r, 0.95)),
        "max": float(r.max()),
    }
