"""Report section "Rasterizer": a tessellated sphere against the exact one, watertightness, speed.

compute → :func:`rasterizer_figures`; present → :func:`present`; checks → :func:`checks`.

The figures: normal error and coverage mismatch of ``uv_sphere_mesh`` tessellations against the
exact ray-cast sphere as the triangle count grows, with the bound that the tessellation's chord
error implies; pixel-coverage counts of a closed mesh (each centre exactly once front-facing and
once back-facing); NumPy-reference against numba-kernel agreement; and the ``raster-*`` benchmark
groups of ``tests/benchmarks/bench_raster.py`` as ratios to their same-run baselines.
"""

from __future__ import annotations

import numpy as np

from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.mesh import TriangleMesh, grid_mesh, uv_sphere_mesh
from reference.geometry.raster import RASTER_METHODS, pixel_coverage, rasterize_mesh
from reference.geometry.shapes import Plane, Sphere
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)

__all__ = ["rasterizer_figures", "sphere_tessellation_errors"]

CAMERA = Camera(eye=(0.7, 1.1, 3.3), target=(0.0, 0.0, 0.0), fov_deg=40)


def sphere_tessellation_errors(
    n_theta: int, camera: Camera, width: int, height: int, radius=1.0, center=(0.0, 0.0, 0.0)
) -> dict:
    """Normal error and coverage mismatch of a rasterized ``uv_sphere_mesh`` against the sphere.

    The mesh (``n_theta × 2·n_theta``, exact vertex normals) lies between the spheres of radius
    ``rho_min`` (its nearest face plane) and ``r``. Its interpolated normal at a point ``p`` is
    ``(p − c)/|p − c|``; the exact hit ``p*`` on the same ray lies nearer the eye, so wherever the
    mesh normal faces the eye, ``∠(p − c, p* − c) <= acos(rho_min / r)``: the chord-error bound.
    Coverage can differ only for rays whose distance from ``c`` is in ``[rho_min, r]`` (the
    silhouette band).

    Parameters
    ----------
    n_theta : int
        Latitude bands of the tessellation (``2·n_theta`` longitude segments).
    camera : Camera
        The camera (the eye must be outside the sphere).
    width, height : int
        Image size.
    radius, center
        The sphere.

    Returns
    -------
    dict
        ``triangles``; ``bound``, ``max``, ``mean`` (radians) of the angle between mesh and
        exact normals over the ``compared_pixels`` where both are visible and the mesh normal
        faces the eye; ``excluded_outside_band`` (visible pixels left out although their ray is
        not in the silhouette band, must be 0); ``band_pixels``
        (rays in the silhouette band), ``mismatch_pixels`` (coverage differs) and
        ``mismatch_outside_band`` (must be 0).

    Examples
    --------
    >>> e = sphere_tessellation_errors(8, CAMERA, 32, 32)
    >>> e["triangles"], bool(e["max"] <= e["bound"]), e["mismatch_outside_band"]
    (224, True, 0)
    """
    c = np.asarray(center, dtype=np.float64)
    mesh = uv_sphere_mesh(n_theta, 2 * n_theta, radius, c)
    g = rasterize_mesh(mesh, camera, width, height)
    exact = render_gbuffer([Sphere(tuple(c), radius)], camera, width, height)
    o, d = camera.rays(width, height)
    ray_distance = np.linalg.norm(np.cross(c - o, d), axis=-1)
    a = mesh.vertices[mesh.faces[:, 0]]
    rho_min = np.abs(np.einsum("ij,ij->i", mesh.face_normals(), a - c)).min()
    facing = g.mask & exact.mask & (np.einsum("...i,...i", g.normal, g.view) >= 0)
    n, n_exact = g.normal[facing], exact.normal[facing]
    error = np.arctan2(
        np.linalg.norm(np.cross(n, n_exact), axis=-1), np.einsum("ij,ij->i", n, n_exact)
    )
    band = (ray_distance >= rho_min * (1 - 1e-12)) & (ray_distance <= radius * (1 + 1e-12))
    differ = g.mask != exact.mask
    return {
        "triangles": mesh.n_faces,
        "bound": float(np.arccos(rho_min / radius)),
        "max": float(error.max()) if error.size else 0.0,
        "mean": float(error.mean()) if error.size else 0.0,
        "compared_pixels": int(facing.sum()),
        "excluded_outside_band": int((g.mask & exact.mask & ~facing & ~band).sum()),
        "band_pixels": int(band.sum()),
        "mismatch_pixels": int(differ.sum()),
        "mismatch_outside_band": int((differ & ~band).sum()),
    }


def closed_mesh_coverage(size: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Front- and back-facing pixel-centre counts of a closed 360-triangle sphere (culled).

    A watertight mesh covers each pixel centre once front-facing and once back-facing.

    Examples
    --------
    >>> front, back = closed_mesh_coverage(16)
    >>> int(front.max()), int((front != back).sum())
    (1, 0)
    """
    sphere = uv_sphere_mesh(10, 20)
    front = pixel_coverage(
        TriangleMesh(sphere.vertices, sphere.faces, cull_backfaces=True), CAMERA, size, size
    )
    back = pixel_coverage(
        TriangleMesh(sphere.vertices, sphere.faces[:, ::-1], cull_backfaces=True),
        CAMERA,
        size,
        size,
    )
    return front, back


def twin_agreement(width: int = 64, height: int = 48) -> dict:
    """NumPy reference against numba kernel on a small mesh, for every registered raster method.

    Returns
    -------
    dict
        Per method: ``same_coverage`` and ``max_abs_difference`` (position, normal, uv, depth).
    """
    twin = {}
    for name in RASTER_METHODS.names():
        mesh = uv_sphere_mesh(12, 24, 0.9, (0.1, 0.0, -0.2))
        a = rasterize_mesh(mesh, CAMERA, width, height, backend="numpy", method=name)
        b = rasterize_mesh(mesh, CAMERA, width, height, backend="numba", method=name)
        same_mask = bool(np.array_equal(a.mask, b.mask))
        diff = max(
            float(np.abs(getattr(a, f)[a.mask] - getattr(b, f)[a.mask]).max())
            for f in ("position", "normal", "uv", "depth")
        )
        twin[name] = {"same_coverage": same_mask, "max_abs_difference": diff}
    return twin


def normals_scene(size: tuple[int, int]) -> dict:
    """Normals ``(n + 1)/2`` of one G-buffer: an exact sphere, a smooth and a flat mesh sphere.

    Returns
    -------
    dict
        ``image`` (shape (H, W, 3), in [0, 1]) and the triangle counts ``smooth_faces``,
        ``flat_faces`` of the two mesh spheres.
    """
    W, H = size
    camera = Camera(eye=(0.0, 1.6, 5.2), target=(0.0, 0.0, 0.0), fov_deg=36)
    smooth = uv_sphere_mesh(12, 24, 0.8, (0.0, 0.0, 0.0))
    low = uv_sphere_mesh(8, 16, 0.8, (1.9, 0.0, 0.0))
    flat = TriangleMesh(low.vertices, low.faces)  # no normals: each face's own, flat shading
    floor = grid_mesh(Plane((0.0, -0.8, 0.0), (0, 1, 0), (1, 0, 0), size=(6.0, 3.0)), 6, 3)
    scene = [Sphere((-1.9, 0.0, 0.0), 0.8), smooth, flat, floor]
    g = render_gbuffer(scene, camera, W, H)
    image = np.where(g.mask[..., None], (np.nan_to_num(g.normal) + 1.0) / 2.0, 0.0)
    return {"image": image, "smooth_faces": smooth.n_faces, "flat_faces": flat.n_faces}


def bench_ratios(bench_groups: dict) -> tuple[list, dict]:
    """Rows ``[group, benchmark, triangles, median ms, ratio to baseline]`` and their results.

    Parameters
    ----------
    bench_groups : dict
        ``ReportContext.bench_groups("raster")``: benchmark records by group.

    Examples
    --------
    >>> records = [{"name": "a", "extra_info": {"role": "baseline"}, "stats": {"median": 0.1}},
    ...            {"name": "b", "stats": {"median": 0.3}}]
    >>> rows, results = bench_ratios({"raster-x": records})
    >>> [round(r[-1], 6) for r in rows], list(results)
    ([1.0, 3.0], ['raster-x a', 'raster-x b'])
    """
    rows, results = [], {}
    for group, records in sorted(bench_groups.items()):
        base = [r for r in records if r.get("extra_info", {}).get("role") == "baseline"]
        base_median = base[0]["stats"]["median"] if base else float("nan")
        for r in sorted(records, key=lambda r: r["stats"]["median"]):
            median = r["stats"]["median"]
            info = r.get("extra_info", {})
            rows.append(
                [group, r["name"], info.get("triangles", ""), 1e3 * median, median / base_median]
            )
            results[f"{group} {r['name']}"] = {
                "median_s": median,
                "ratio_to_baseline": median / base_median,
            }
    return rows, results


def rasterizer_figures(
    ctx: ReportContext | None = None,
    size: int | None = None,
    levels: tuple[int, ...] | None = None,
    normals_size: tuple[int, int] | None = None,
) -> SectionData:
    """Tessellated-sphere accuracy, closed-mesh coverage, twin agreement and benchmark ratios.

    Parameters
    ----------
    ctx : ReportContext, optional
        ``ctx.quick`` picks the sizes (128 px and up to 32 bands; else 256 px and up to 128);
        ``ctx.bench`` the benchmark records. Without it: full sizes, no benchmarks.
    size, levels, normals_size : optional
        Override the image size, the latitude-band counts and the normals image's (W, H).

    Returns
    -------
    SectionData
        ``results``: ``tessellation`` (per ``"<n>x<2n>"``: :func:`sphere_tessellation_errors`),
        ``closed_mesh``, ``twin`` (:func:`twin_agreement`) and, with benchmarks, ``benchmarks``;
        ``arrays``: ``size``, ``coverage`` (front, back), ``normals`` (:func:`normals_scene`),
        ``bench_rows``.

    Examples
    --------
    >>> data = rasterizer_figures(size=32, levels=(4, 8), normals_size=(16, 8))
    >>> list(data.results["tessellation"]), data.results["closed_mesh"]["front_back_mismatch"]
    (['4x8', '8x16'], 0)
    >>> [c.passed for c in checks(data)][:3]
    [True, True, True]
    """
    quick = ctx is not None and ctx.quick
    size = size or (128 if quick else 256)
    levels = levels or ((4, 8, 16, 32) if quick else (4, 8, 16, 32, 64, 128))
    normals_size = normals_size or ((256, 128) if quick else (512, 256))
    errors = {f"{n}x{2 * n}": sphere_tessellation_errors(n, CAMERA, size, size) for n in levels}
    front, back = closed_mesh_coverage()
    results: dict = {
        "tessellation": errors,
        "closed_mesh": {
            "covered_pixels": int((front > 0).sum()),
            "max_front_count": int(front.max()),
            "front_back_mismatch": int((front != back).sum()),
        },
        "twin": twin_agreement(),
    }
    bench_rows, bench_results = bench_ratios(ctx.bench_groups("raster") if ctx else {})
    if bench_rows:
        results["benchmarks"] = bench_results
    arrays = {
        "size": size,
        "coverage": (front, back),
        "normals": normals_scene(normals_size),
        "bench_rows": bench_rows,
    }
    return SectionData(results, arrays)


def _convergence_figure(errors: list[dict], size: int):
    """Normal error and coverage mismatch against the triangle count, log-log."""
    import matplotlib.pyplot as plt

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(9, 3.4))
    triangles = [e["triangles"] for e in errors]
    ax0.loglog(triangles, [np.degrees(e["bound"]) for e in errors], "k--", label="chord bound")
    ax0.loglog(triangles, [np.degrees(e["max"]) for e in errors], "o-", label="max")
    ax0.loglog(triangles, [np.degrees(e["mean"]) for e in errors], "s-", label="mean")
    ax0.set_xlabel("triangles")
    ax0.set_ylabel("normal error (degrees)")
    ax0.legend()
    ax1.loglog(
        triangles, [max(e["band_pixels"], 0.5) for e in errors], "k--", label="silhouette band"
    )
    ax1.loglog(
        triangles, [max(e["mismatch_pixels"], 0.5) for e in errors], "o-", label="coverage mismatch"
    )
    ax1.set_xlabel("triangles")
    ax1.set_ylabel(f"pixels (of {size}×{size})")
    ax1.legend()
    fig.tight_layout()
    return fig


def present(ctx: ReportContext, data: SectionData) -> list:
    """The tessellation table and chart, the normals image and the benchmark table."""
    size, errors = data.arrays["size"], data.results["tessellation"]
    rows = [
        [
            band.replace("x", "×"),
            e["triangles"],
            np.degrees(e["bound"]),
            np.degrees(e["max"]),
            np.degrees(e["mean"]),
            e["band_pixels"],
            e["mismatch_pixels"],
            e["mismatch_outside_band"],
        ]
        for band, e in errors.items()
    ]
    coarse, fine = min(rows, key=lambda r: r[1]), max(rows, key=lambda r: r[1])
    normals = data.arrays["normals"]
    blocks = [
        Text(
            "A latitude-longitude tessellation of the unit sphere (exact vertex normals, "
            "perspective-correct interpolation) against the exactly ray-cast sphere, pixel by "
            "pixel. "
            "The normal error is bounded by acos(rho_min / r), with rho_min the distance from the "
            "centre to the nearest face plane (the chord error), where the mesh normal faces the "
            "eye; coverage may differ only in the silhouette band of rays passing between the two "
            "spheres. The mean error falls as the chord error, about 4× per doubling of the bands."
        ),
        Table(
            [
                "bands",
                "triangles",
                "bound (°)",
                "max (°)",
                "mean (°)",
                "band px",
                "mismatch px",
                "outside band",
            ],
            rows,
            f"Tessellated sphere against the analytic sphere, {size}×{size} pixels",
            "{:.3g}",
        ),
        ctx.figure(
            "convergence",
            _convergence_figure(list(errors.values()), size),
            "Normal error and coverage mismatch against triangle count: the mean normal error "
            f"is {coarse[4]:.3g}° at {coarse[1]} triangles and {fine[4]:.3g}° at {fine[1]}",
        ),
        ctx.image(
            "normals",
            normals["image"],
            f"Normals (n + 1)/2 from one G-buffer: an exact ray-cast sphere (left), a "
            f"{normals['smooth_faces']}-triangle mesh sphere with interpolated normals (centre), "
            f"a {normals['flat_faces']}-triangle mesh with flat face normals (right), and a floor "
            "grid mesh",
        ),
    ]
    if data.arrays["bench_rows"]:
        blocks.append(
            Table(
                ["group", "benchmark", "triangles", "median (ms)", "× baseline"],
                data.arrays["bench_rows"],
                "Benchmarks (make bench): each group's ratio to its same-run baseline",
                "{:.3g}",
            )
        )
    else:
        blocks.append(
            Text("No benchmark results: run `make bench` for the 100k-triangle G-buffer timings.")
        )
    return blocks


def checks(data: SectionData) -> list[Check]:
    """Chord bound per tessellation, coverage outside the band, watertightness, twin agreement."""
    errors = list(data.results["tessellation"].values())
    found = [
        Check(
            f"normal error, {e['triangles']} triangles",
            f"<= chord bound {np.degrees(e['bound']):.3g}°",
            np.degrees(e["max"]),
            e["max"] <= e["bound"] + 1e-9,
        )
        for e in errors
    ]
    found.append(
        Check(
            "coverage differences outside the silhouette band",
            "0 pixels",
            sum(e["mismatch_outside_band"] for e in errors),
            all(e["mismatch_outside_band"] == 0 for e in errors),
        )
    )
    # Watertightness: a closed mesh covers each pixel centre once front- and once back-facing.
    front, _ = data.arrays["coverage"]
    closed = data.results["closed_mesh"]
    found.append(
        Check(
            "pixel centres covered twice by front faces (closed 360-triangle sphere)",
            "0",
            int((front > 1).sum()),
            closed["max_front_count"] <= 1,
        )
    )
    found.append(
        Check(
            "pixel centres with front ≠ back coverage (cracks)",
            "0",
            closed["front_back_mismatch"],
            closed["front_back_mismatch"] == 0,
        )
    )
    for name, twin in data.results["twin"].items():
        found.append(
            Check(
                f"NumPy reference vs numba kernel ({name})",
                "same coverage, <= 1e-12",
                twin["max_abs_difference"],
                twin["same_coverage"] and twin["max_abs_difference"] <= 1e-12,
            )
        )
    return found


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: shading-normal error at the finest tessellation, watertightness."""
    finest = max(data.results["tessellation"].values(), key=lambda e: e["triangles"])
    closed = data.results["closed_mesh"]
    return [
        Headline(
            f"interpolated normals of a {finest['triangles']}-triangle sphere within "
            f"{np.degrees(finest['max']):.2f}° of the true sphere",
            f"chord bound {np.degrees(finest['bound']):.2f}°",
        ),
        Headline(
            f"watertight: {closed['front_back_mismatch']} cracks and no pixel centre covered twice "
            "on a closed mesh",
            "top-left fill rule",
        ),
    ]


SECTION = ReportSection(
    "rasterizer",
    "Rasterizer",
    rasterizer_figures,
    present,
    checks,
    headlines=headlines,
    basis="design",  # the tessellated spheres and closed meshes it was built on
)
