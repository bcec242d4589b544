"""Report section "Rasterizer": a tessellated sphere against the exact one, watertightness, speed.

The figures: normal error and coverage mismatch of ``uv_sphere_mesh`` tessellations against the
exact ray-cast sphere as the triangle count grows, with the bound that the tessellation's chord
error implies; pixel-coverage counts of a closed mesh (each centre exactly once front-facing and
once back-facing); NumPy-reference against numba-kernel agreement; and the ``raster-*`` benchmark
groups of ``tests/benchmarks/bench_raster.py`` as ratios to their same-run baselines.
"""

from __future__ import annotations

import numpy as np

from reference.camera import Camera
from reference.gbuffer import render_gbuffer
from reference.geometry import Plane, Sphere
from reference.mesh import TriangleMesh, grid_mesh, uv_sphere_mesh
from reference.raster import RASTER_METHODS, pixel_coverage, rasterize_mesh
from validation.report import (
    Check,
    ReportContext,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

__all__ = ["sphere_tessellation_errors"]

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


def _normals_image(ctx: ReportContext, size: tuple[int, int]):
    """Normals of a scene mixing an exact sphere, a smooth mesh sphere and a flat-shaded one."""
    W, H = size
    camera = Camera(eye=(0.0, 1.6, 5.2), target=(0.0, 0.0, 0.0), fov_deg=36)
    smooth = uv_sphere_mesh(12, 24, 0.8, (0.0, 0.0, 0.0))
    low = uv_sphere_mesh(8, 16, 0.8, (1.9, 0.0, 0.0))
    flat = TriangleMesh(low.vertices, low.faces)  # no normals: each face's own, flat shading
    floor = grid_mesh(Plane((0.0, -0.8, 0.0), (0, 1, 0), (1, 0, 0), size=(6.0, 3.0)), 6, 3)
    scene = [Sphere((-1.9, 0.0, 0.0), 0.8), smooth, flat, floor]
    g = render_gbuffer(scene, camera, W, H)
    image = np.where(g.mask[..., None], (np.nan_to_num(g.normal) + 1.0) / 2.0, 0.0)
    return ctx.image(
        "normals",
        image,
        f"Normals (n + 1)/2 from one G-buffer: an exact ray-cast sphere (left), a "
        f"{smooth.n_faces}-triangle mesh sphere with interpolated normals (centre), a "
        f"{flat.n_faces}-triangle mesh with flat face normals (right), and a floor grid mesh",
    )


def _bench_rows(ctx: ReportContext):
    """Rows ``[group, benchmark, triangles, median ms, ratio to baseline]`` and results."""
    rows, results = [], {}
    for group, records in sorted(ctx.bench_groups("raster").items()):
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


def run(ctx: ReportContext) -> SectionResult:
    """Tessellated-sphere accuracy, coverage counts, twin agreement, normals image, benchmarks."""
    import matplotlib.pyplot as plt

    size = 128 if ctx.quick else 256
    levels = (4, 8, 16, 32) if ctx.quick else (4, 8, 16, 32, 64, 128)
    errors = [sphere_tessellation_errors(n, CAMERA, size, size) for n in levels]
    rows = [
        [
            f"{n}×{2 * n}",
            e["triangles"],
            np.degrees(e["bound"]),
            np.degrees(e["max"]),
            np.degrees(e["mean"]),
            e["band_pixels"],
            e["mismatch_pixels"],
            e["mismatch_outside_band"],
        ]
        for n, e in zip(levels, errors, strict=True)
    ]
    results: dict = {
        "tessellation": {f"{n}x{2 * n}": e for n, e in zip(levels, errors, strict=True)}
    }
    checks = [
        Check(
            f"normal error, {e['triangles']} triangles",
            f"<= chord bound {np.degrees(e['bound']):.3g}°",
            np.degrees(e["max"]),
            e["max"] <= e["bound"] + 1e-9,
        )
        for e in errors
    ]
    checks.append(
        Check(
            "coverage differences outside the silhouette band",
            "0 pixels",
            sum(e["mismatch_outside_band"] for e in errors),
            all(e["mismatch_outside_band"] == 0 for e in errors),
        )
    )

    # Watertightness: a closed mesh covers each pixel centre once front- and once back-facing.
    sphere = uv_sphere_mesh(10, 20)
    front = pixel_coverage(
        TriangleMesh(sphere.vertices, sphere.faces, cull_backfaces=True), CAMERA, 64, 64
    )
    back = pixel_coverage(
        TriangleMesh(sphere.vertices, sphere.faces[:, ::-1], cull_backfaces=True), CAMERA, 64, 64
    )
    results["closed_mesh"] = {
        "covered_pixels": int((front > 0).sum()),
        "max_front_count": int(front.max()),
        "front_back_mismatch": int((front != back).sum()),
    }
    checks.append(
        Check(
            "pixel centres covered twice by front faces (closed 360-triangle sphere)",
            "0",
            int((front > 1).sum()),
            int(front.max()) <= 1,
        )
    )
    checks.append(
        Check(
            "pixel centres with front ≠ back coverage (cracks)",
            "0",
            results["closed_mesh"]["front_back_mismatch"],
            results["closed_mesh"]["front_back_mismatch"] == 0,
        )
    )

    # Twin agreement on a small mesh, every registered method.
    twin = {}
    for name in RASTER_METHODS.names():
        mesh = uv_sphere_mesh(12, 24, 0.9, (0.1, 0.0, -0.2))
        a = rasterize_mesh(mesh, CAMERA, 64, 48, backend="numpy", method=name)
        b = rasterize_mesh(mesh, CAMERA, 64, 48, backend="numba", method=name)
        same_mask = bool(np.array_equal(a.mask, b.mask))
        diff = max(
            float(np.abs(getattr(a, f)[a.mask] - getattr(b, f)[a.mask]).max())
            for f in ("position", "normal", "uv", "depth")
        )
        twin[name] = {"same_coverage": same_mask, "max_abs_difference": diff}
        checks.append(
            Check(
                f"NumPy reference vs numba kernel ({name})",
                "same coverage, <= 1e-12",
                diff,
                same_mask and diff <= 1e-12,
            )
        )
    results["twin"] = twin

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
        ctx.figure("convergence", fig, "Normal error and coverage mismatch against triangle count"),
        _normals_image(ctx, (256, 128) if ctx.quick else (512, 256)),
    ]
    bench_rows, bench_results = _bench_rows(ctx)
    if bench_rows:
        blocks.append(
            Table(
                ["group", "benchmark", "triangles", "median (ms)", "× baseline"],
                bench_rows,
                "Benchmarks (make bench): each group's ratio to its same-run baseline",
                "{:.3g}",
            )
        )
        results["benchmarks"] = bench_results
    else:
        blocks.append(
            Text("No benchmark results: run `make bench` for the 100k-triangle G-buffer timings.")
        )
    return SectionResult(blocks, results, checks)


# pytest's importlib mode may execute this module a second time: register once.
SECTION = ReportSection("rasterizer", "Rasterizer", legacy_run=run)
