"""ImpastoR lighting validation (§3.5, §5.2, Ferwerda): gloss, shadows and the lighting methods.

The lighting half of what the report's "ImpastoR" section measures; the colour half (Table 1,
channel counts, metamers, the display) is ``validation.studies.impastor``. The painting and its
renderer are ``impastor.painting``.

- :func:`specular_error_vs_alpha`: point lights, FIS and the hybrid against the brute-force
  integral, over roughness (§3.5.2).
- :func:`shadow_agreement`: horizon maps against ray-marched shadows over the sector count
  (§3.5.3).
- :func:`gloss_validation`: goniometric luminance curves of gray Ward–Dür samples (Fig. 15);
  :func:`ward_duer_albedo`: the white-furnace albedo of the Ward–Dür lobe.
"""

from __future__ import annotations

import numpy as np

from impastor.arealights import PlaneLight
from impastor.horizon import horizon_lookup, horizon_map, ray_march_shadows
from impastor.painting import booth_plane_light, impasto_painting, painting_samples
from impastor.point_lights import illuminance_point_lights, point_lights_from_plane
from impastor.specular_hybrid import specular_hybrid, specular_hybrid_parts
from impastor.specular_lighting import specular_brute_force

__all__ = [
    "gloss_validation",
    "shadow_agreement",
    "specular_error_vs_alpha",
    "ward_duer_albedo",
]


# --- lighting and shadow errors ------------------------------------------------------------------


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
    ``impastor.arealights.booth_light_image``; fluorescent by default). The reference sums every
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
    P, N, V = painting_samples(n_side, painting)
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


#: The height fields of the shadow study: (label, relief scale, amplitude of 1-pixel bumps, m).
SHADOW_FIELDS = (
    ("default", 1.0, 0.0),
    ("relief ×2", 2.0, 0.0),
    ("relief ×4", 4.0, 0.0),
    ("fine bumps", 1.0, 1e-4),
)


def shadow_field(size: int, seed: int, relief: float = 1.0, bumps: float = 0.0):
    """A painting's height field, its relief scaled, with optional 1-pixel bumps (m, std).

    Examples
    --------
    >>> h, pixel = shadow_field(16, 1, 2.0, 1e-4)
    >>> h.shape, round(pixel, 5)
    ((16, 16), 0.01875)
    """
    painting = impasto_painting(size, seed=seed)
    h = relief * painting["height"]
    if bumps > 0:
        h = h + np.random.default_rng(1000 + seed).normal(0.0, bumps, h.shape)
    return h, painting["pixel_size"]


def shadow_agreement(
    sector_counts=(6, 12, 18, 24, 36, 48),
    size: int = 256,
    elevations_deg=(10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 75.0),
    n_azimuths: int = 8,
    max_steps: int = 32,
    fields=SHADOW_FIELDS,
    seed: int = 4,
    step: float = 0.25,
    backend: str = "numba",
) -> dict:
    """Share of pixels where horizon-map and ray-marched shadows disagree, per elevation.

    §3.5.3, Ferwerda. Lights at each elevation and ``n_azimuths`` azimuths offset from the sector
    centres (raking light across a painting-like height field, :func:`shadow_field`). Both
    methods march the same ``step``; the reference along the light's exact azimuth, the map along
    sector centres, interpolated between them. Also measured, per elevation: the reference's own
    error (``step`` against ``step / 2``) and the paper's first version (one-pixel steps, the
    sector that holds φ, against a one-pixel reference) at 18 sectors.

    Returns
    -------
    dict
        ``elevation_deg``, ``sectors``, ``images`` (three-channel images per sector count),
        ``fields`` (labels) and, per field, ``disagreement[field][sector][elevation]``,
        ``reference_error[field][elevation]``, ``one_pixel_steps[field][elevation]``;
        ``shadowed[field][elevation]`` (share in shadow by the reference).

    Examples
    --------
    >>> r = shadow_agreement((4, 18), 32, (15.0,), 4, 8, (("default", 1.0, 0.0),))
    >>> r["sectors"], r["images"], all(0 <= v <= 1 for v in r["disagreement"]["default"][1])
    ([4, 18], [2, 6], True)
    """
    azimuths = (np.arange(n_azimuths) + 0.37) * 2.0 * np.pi / n_azimuths
    betas = np.radians(np.asarray(elevations_deg, dtype=np.float64))
    out = {
        "elevation_deg": [float(e) for e in elevations_deg],
        "sectors": [int(S) for S in sector_counts],
        "images": [-(-int(S) // 3) for S in sector_counts],
        "fields": [f[0] for f in fields],
        "step": float(step),
        **{k: {} for k in ("disagreement", "reference_error", "one_pixel_steps", "shadowed")},
    }
    for label, relief, bumps in fields:
        h, pixel = shadow_field(size, seed, relief, bumps)
        for key, value in _shadow_field_study(
            h, pixel, sector_counts, betas, azimuths, max_steps, step, backend
        ).items():
            out[key][label] = value
    return out


def _shadow_field_study(h, pixel, sector_counts, betas, azimuths, max_steps, step, backend):
    # shadow_agreement on one height field: per elevation, means over the azimuths
    def march(phi, beta, d):
        return ray_march_shadows(h, pixel, phi, beta, max_steps, backend=backend, step=d)

    def per_beta(wrong):
        return [float(np.mean([np.mean(wrong(b, p)) for p in azimuths])) for b in betas]

    reference = {(b, p): march(p, b, step) for b in betas for p in azimuths}
    half = {(b, p): march(p, b, step / 2) for b in betas for p in azimuths}
    coarse = {(b, p): march(p, b, 1.0) for b in betas for p in azimuths}
    # The paper's first version: one-pixel steps, the sector that holds φ, 18 sectors.
    paper = horizon_map(h, pixel, 18, max_steps, backend=backend, step=1.0)
    rows = []
    for S in sector_counts:
        hmap = horizon_map(h, pixel, int(S), max_steps, backend=backend, step=step)
        rows.append(per_beta(lambda b, p, m=hmap: horizon_lookup(m, p, b) != reference[b, p]))
    return {
        "reference_error": per_beta(lambda b, p: reference[b, p] != half[b, p]),
        "shadowed": per_beta(lambda b, p: ~reference[b, p]),
        "one_pixel_steps": per_beta(
            lambda b, p: horizon_lookup(paper, p, b, interpolate=False) != coarse[b, p]
        ),
        "disagreement": rows,
    }


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

    Dür's normalization claims the albedo stays at or below ρ_s away from grazing incidence (§3.1.2;
    errata E12 for grazing incidence). Each albedo is
    :func:`reference.materials.brdf.albedo_quadrature` at order 48, with ``|q48 − q24|`` as its
    error.

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
    from reference.materials.brdf import albedo_quadrature, brdf_ward_duer_specular

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
