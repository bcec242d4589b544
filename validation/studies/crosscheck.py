"""Cross-check against Mitsuba 3: the same small scenes in specref and Mitsuba, compared per pixel.

Mitsuba 3 (``pip install .[mitsuba]``; the ``scalar_spectral`` variant needs no LLVM, the
``llvm_ad_spectral`` one needs Debian's ``libllvm19``) is an independent spectral path tracer. Each
case is rendered in both with the same camera and conventions:

- **environments**: a Lambertian sphere (ρ = 0.5, flat) filling the frame, under each map of
  ``data:environments`` (shipped with specref), box-averaged to a small map
  (``CrosscheckSettings.env_height``) written as an EXR that both read. specref reads it as Mitsuba
  does: ``texel_placement = "mitsuba"`` (rows at ``v = j/(H − 1)``) and ``upsampling = "jakob2019"``
  (scale ``2·max``, erratum E80), and integrates by brute force (``--oracle``), so only its physics
  is compared, not the SH truncation;
- **measured reflectance**: the sphere with a measured reflectance (a Nix export from
  ``data:spectra``, held constant beyond its 400-700 nm) under the first map;
- **ColorChecker under D65 and under A**: the 24 N Ohta patches, each a square facing an
  orthographic camera, under a uniform sky of the illuminant (Mitsuba's ``constant`` emitter; in
  specref the ambient term, which is what a uniform sky gives a Lambertian: ``ρ L``), normalized so
  that a white diffuser has Y = 1 in both.

Mitsuba writes CIE XYZ (``hdrfilm``, ``pixel_format = "xyz"``, box filter). Its Monte Carlo error is
estimated from ``seeds`` independent renders: per pixel the mean m and the standard error
``s = sd / sqrt(K)`` (K seeds), and ``z = (specref − m) / s``. With s estimated from K samples, z
follows Student's t with K − 1 degrees of freedom when the two agree in expectation: E[z²] =
(K − 1)/(K − 3) and P(|z| > 4) is ``scipy.stats.t.sf``; :func:`crosscheck_summary` states both.
specref's own remaining differences (41 bands at 380-780 nm against Mitsuba's continuous 360-830
nm; the two Jakob tables, erratum E82; interpolation of the product, erratum E81) are systematic,
and show as a mean relative difference.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.data import data_root
from reference.errors import SpecrefError, require

__all__ = [
    "FULL",
    "INSTALL_HINT",
    "MITSUBA_VARIANT",
    "QUICK",
    "CrosscheckSettings",
    "crosscheck_cases",
    "crosscheck_summary",
    "mitsuba_missing",
    "run_crosscheck",
]

#: How to enable the cross-check.
INSTALL_HINT = (
    "pip install '.[mitsuba]' (or pip install mitsuba) to enable the Mitsuba 3 cross-check"
)
#: The Mitsuba variant used: spectral, CPU, no LLVM needed.
MITSUBA_VARIANT = "scalar_spectral"

_REFLECTANCE = "physicallybased/orange__nix_export.csv"


@dataclass(frozen=True)
class CrosscheckSettings:
    """Render sizes: image side (pixels), Mitsuba samples per pixel per seed, seeds, map height."""

    size: int = 24
    spp: int = 256
    seeds: int = 8
    env_height: int = 64
    supersample: int = 3


#: ``specref crosscheck`` and the report (a few minutes in all).
FULL = CrosscheckSettings()
#: Tests.
QUICK = CrosscheckSettings(size=12, spp=64, seeds=6, env_height=64, supersample=3)


def mitsuba_missing() -> str | None:
    """None if Mitsuba 3's spectral variant loads, else why not (with :data:`INSTALL_HINT`).

    Examples
    --------
    >>> mitsuba_missing() is None or "pip install" in mitsuba_missing()
    True
    """
    try:
        import mitsuba as mi

        mi.set_variant(MITSUBA_VARIANT)
    except (ImportError, AttributeError, ValueError) as error:
        return f"Mitsuba 3 ({MITSUBA_VARIANT}) not available ({error}); {INSTALL_HINT}"
    return None


def crosscheck_cases(data_folder=None) -> list[dict]:
    """The cases: a sphere per shipped environment, a measured reflectance, the ColorChecker twice.

    Parameters
    ----------
    data_folder : str or Path, optional
        A folder laid out as the package data (``environments/``, ``spectra/``); default the data
        shipped with specref (:func:`reference.data.data_root`).

    Examples
    --------
    >>> [c["name"] for c in crosscheck_cases()][-2:]
    ['ColorChecker D65', 'ColorChecker A']
    """
    data_folder = Path(data_folder) if data_folder is not None else data_root()
    for sub in ("environments", "spectra"):
        require(
            (data_folder / sub).is_dir(),
            f"--data: {data_folder}: not a folder laid out as specref's data (no {sub}/ folder)",
        )
    maps = sorted(
        p for p in (data_folder / "environments").iterdir() if p.suffix in (".hdr", ".exr")
    )
    require(maps, f"{data_folder / 'environments'}: no .hdr or .exr environment maps")
    cases = [{"name": f"sphere ρ=0.5, {p.name}", "kind": "sphere", "env": p} for p in maps]
    spectrum = data_folder / "spectra" / _REFLECTANCE
    cases.append({"name": f"sphere {spectrum.stem}, {maps[0].name}", "kind": "sphere",
                  "env": maps[0], "reflectance": spectrum})  # fmt: skip
    cases += [{"name": f"ColorChecker {i}", "kind": "chart", "illuminant": i} for i in ("D65", "A")]
    return cases


def _small_map(path: Path, height: int, folder: Path) -> Path:
    """The map box-averaged to ``height`` rows (2:1), as an RGB EXR both renderers read."""
    from reference.images.formats import read_exr, read_hdr, write_exr

    image = read_hdr(path) if path.suffix == ".hdr" else read_exr(path)[0][..., :3]
    H, W = image.shape[:2]
    # the user's map named, not the small copy: a lat-long panorama taller than the copy, finite
    require(
        W == 2 * H and height <= H,
        f"{path}: a lat-long map (2:1) of at least {height} rows is needed, got {W} × {H}",
    )
    require(bool(np.isfinite(image).all()), f"{path}: NaN or infinite values")
    rows = np.array_split(np.arange(H), height)
    cols = np.array_split(np.arange(W), 2 * height)
    small = np.array([[image[r][:, c].mean(axis=(0, 1)) for c in cols] for r in rows])
    out = folder / f"{path.stem}-{height}.exr"
    write_exr(out, small)
    return out


def _reflectance_pairs(spectrum_path: Path | None):
    """(specref scene value, Mitsuba spectrum) of a case's reflectance."""
    if spectrum_path is None:
        return "0.5", {"type": "spectrum", "value": 0.5}
    from reference.colour.spectra import spectrum_from_csv

    s = spectrum_from_csv(spectrum_path)
    wl = np.concatenate([[360.0], s.wavelengths_nm, [830.0]])
    values = np.concatenate([[s.values[0]], s.values, [s.values[-1]]])
    pairs = [(float(a), float(b)) for a, b in zip(wl, values, strict=True)]
    scene = f'{{ csv = "{spectrum_path}", extrapolation = "constant" }}'
    return scene, {"type": "spectrum", "value": pairs}


def _sphere_specref(case, env: Path, settings) -> np.ndarray:
    from reference.scene.loader import loads_scene
    from reference.scene.render import render_scene

    k_d, _ = _reflectance_pairs(case.get("reflectance"))
    toml = "\n".join([
        "[render]", f"width = {settings.size}", f"height = {settings.size}",
        f"supersample = {settings.supersample}", "[render.options]", 'upsampling = "jakob2019"',
        "[camera]", "eye = [0, 0, 4]", "target = [0, 0, 0]", "fov_deg = 20",
        "[materials.m]", 'type = "lambert"', f"k_d = {k_d}",
        "[[objects]]", 'type = "sphere"', 'material = "m"',
        "[[lights]]", 'type = "environment"', f'file = "{env}"', 'texel_placement = "mitsuba"',
    ])  # fmt: skip
    scene = loads_scene(toml)
    return render_scene(scene, options={"environment": "bruteforce"}).XYZ


def _sphere_mitsuba(case, env: Path, settings) -> dict:
    import mitsuba as mi

    _, reflectance = _reflectance_pairs(case.get("reflectance"))
    film = {"type": "hdrfilm", "width": settings.size, "height": settings.size,
            "pixel_format": "xyz", "rfilter": {"type": "box"}}  # fmt: skip
    look = mi.ScalarTransform4f().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0])
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2},
        "sensor": {"type": "perspective", "fov": 20, "fov_axis": "y", "to_world": look,
                   "film": film, "sampler": {"type": "independent", "sample_count": settings.spp}},
        "sphere": {"type": "sphere", "bsdf": {"type": "diffuse", "reflectance": reflectance}},
        "env": {"type": "envmap", "filename": str(env)},
    }  # fmt: skip


def _illuminant_radiance(name: str):
    """(wavelengths, radiance) of an illuminant scaled so that a white diffuser has Y = 1."""
    import colour

    sd = colour.SDS_ILLUMINANTS[name].copy().align(colour.SpectralShape(360, 830, 1))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd.shape)
    # Mitsuba's XYZ film: Y = ∫ L ȳ dλ / ∫ ȳ dλ
    scale = cmfs.values[:, 1].sum() / (sd.values * cmfs.values[:, 1]).sum()
    return sd.wavelengths, sd.values * scale


def _chart_layout():
    """Patch centres (24, 2) in the chart plane (z = 0) and reflectances (24, n) on their grid."""
    from reference.scene.colorchecker import colorchecker_patch_centres_uv

    uv = colorchecker_patch_centres_uv()
    centres = np.stack([-0.3 + 0.6 * uv[:, 0], 0.2 - 0.4 * uv[:, 1]], axis=-1)
    return centres


def _chart_specref(case, settings) -> np.ndarray:
    from reference.scene.loader import loads_scene
    from reference.scene.render import render_scene

    toml = "\n".join([
        "[render]", f"width = {3 * settings.size}", f"height = {2 * settings.size}",
        f"supersample = {settings.supersample}",
        "[camera]", 'projection = "orthographic"', "eye = [0, 0, 5]", "target = [0, 0, 0]",
        "extent = 0.4",
        "[materials.chart]", 'type = "colorchecker"', "gap_width = 0.12",
        "[[objects]]", 'type = "rectangle"', "point = [0, 0, 0]", "normal = [0, 0, 1]",
        "u_axis = [1, 0, 0]", "size = [0.6, 0.4]", 'material = "chart"',
        "[[lights]]", 'type = "ambient"', f'spectrum = {{ illuminant = "{case["illuminant"]}" }}',
    ])  # fmt: skip
    return _patch_means(render_scene(loads_scene(toml)).XYZ)


def _chart_mitsuba(case, settings) -> dict:
    import colour
    import mitsuba as mi

    wl, radiance = _illuminant_radiance(case["illuminant"])
    sky = [(float(a), float(b)) for a, b in zip(wl, radiance, strict=True)]
    chart = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    film = {"type": "hdrfilm", "width": 3 * settings.size, "height": 2 * settings.size,
            "pixel_format": "xyz", "rfilter": {"type": "box"}}  # fmt: skip
    look = mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2},
        "sensor": {"type": "orthographic", "film": film,
                   "to_world": look @ mi.ScalarTransform4f().scale([0.3, 0.3, 1]),
                   "sampler": {"type": "independent", "sample_count": settings.spp}},
        "sky": {"type": "constant", "radiance": {"type": "spectrum", "value": sky}},
    }  # fmt: skip
    for k, ((x, y), sd) in enumerate(zip(_chart_layout(), chart.values(), strict=True)):
        s = sd.copy().align(colour.SpectralShape(360, 830, 5), extrapolator_kwargs={
            "method": "Constant"})  # fmt: skip
        pairs = [(float(a), float(b)) for a, b in zip(s.wavelengths, s.values, strict=True)]
        place = mi.ScalarTransform4f().translate([x, y, 0]) @ mi.ScalarTransform4f().scale(0.044)
        bsdf = {"type": "diffuse", "reflectance": {"type": "spectrum", "value": pairs}}
        scene[f"patch{k}"] = {"type": "rectangle", "to_world": place, "bsdf": bsdf}
    return scene


def _patch_means(XYZ: np.ndarray) -> np.ndarray:
    """Mean XYZ over the inner third of each patch of a chart image (2S × 3S), (24, 1, 3)."""
    H, W = XYZ.shape[:2]
    out = []
    for x, y in _chart_layout():
        # orthographic, 0.4 high and 0.6 wide, centred on the origin, row 0 at the top
        col, row = (x + 0.3) / 0.6 * W, (0.2 - y) / 0.4 * H
        half = max(1, round(0.015 / 0.4 * H))
        block = XYZ[round(row) - half : round(row) + half, round(col) - half : round(col) + half]
        out.append(block.reshape(-1, 3).mean(axis=0))
    return np.array(out)[:, None, :]


def _mitsuba_runs(scene_dict, settings, chart: bool) -> np.ndarray:
    """(seeds, ...) XYZ of independent Mitsuba renders."""
    import mitsuba as mi

    scene = mi.load_dict(scene_dict)
    runs = []
    for seed in range(settings.seeds):
        XYZ = np.array(mi.render(scene, seed=seed + 1), dtype=np.float64)[..., :3]
        runs.append(_patch_means(XYZ) if chart else XYZ)
    return np.array(runs)


def run_crosscheck(
    data_folder=None, settings: CrosscheckSettings = FULL, progress=None, only: str | None = None
) -> dict:
    """Render every case in specref and Mitsuba 3 and compare them (module docstring).

    Parameters
    ----------
    data_folder : str or Path, optional
        Folder with ``environments/`` and ``spectra/``; default the data shipped with specref.
    settings : CrosscheckSettings
    progress : callable, optional
        Called with each case's name before it runs.
    only : str, optional
        Run only the cases whose name contains this text.

    Returns
    -------
    dict
        ``settings``, ``variant``, ``cases``: per case its name and the per-pixel (per-patch for
        the charts) ``specref``, ``mitsuba`` (mean over seeds) and ``se`` XYZ arrays, and ``z``.

    Raises
    ------
    SpecrefError
        When Mitsuba 3 is not installed (the message says how to install it), or ``only`` matches
        no case.

    Examples
    --------
    >>> if mitsuba_missing() is None:
    ...     result = run_crosscheck(None, QUICK, only="ColorChecker A")
    ...     case = result["cases"][0]
    ...     print(case["name"], case["z"].shape)
    ... else:
    ...     print("ColorChecker A (24, 1, 3)")
    ColorChecker A (24, 1, 3)
    """
    missing = mitsuba_missing()
    if missing is not None:
        raise SpecrefError(missing)
    import shrm  # noqa: F401  (registers the environment-light shaders)

    cases = [c for c in crosscheck_cases(data_folder) if only is None or only in c["name"]]
    names = ", ".join(c["name"] for c in crosscheck_cases(data_folder))
    require(cases, f"crosscheck: no case matches {only!r}; cases: {names}")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        small = {  # every map read and checked before the first case starts
            c["env"]: _small_map(c["env"], settings.env_height, Path(tmp))
            for c in cases
            if c["kind"] == "sphere"
        }
        for case in cases:
            if progress is not None:
                progress(case["name"])
            if case["kind"] == "sphere":
                env = small[case["env"]]
                ours = _sphere_specref(case, env, settings)
                runs = _mitsuba_runs(_sphere_mitsuba(case, env, settings), settings, False)
            else:
                ours = _chart_specref(case, settings)
                runs = _mitsuba_runs(_chart_mitsuba(case, settings), settings, True)
            mean = runs.mean(axis=0)
            se = runs.std(axis=0, ddof=1) / np.sqrt(settings.seeds)
            z = (ours - mean) / np.where(se > 0, se, np.inf)
            results.append(
                {"name": case["name"], "specref": ours, "mitsuba": mean, "se": se, "z": z}
            )
    return {"settings": settings, "variant": MITSUBA_VARIANT, "cases": results}


def crosscheck_summary(result: dict) -> list[dict]:
    """Per case: pixels, mean relative difference in Y, RMS z, P(|z| > 4) against Student's t.

    Examples
    --------
    >>> z = np.zeros((2, 2, 3)); ones = np.ones((2, 2, 3))
    >>> case = {"name": "x", "specref": ones, "mitsuba": ones, "se": ones, "z": z}
    >>> s = crosscheck_summary({"settings": QUICK, "cases": [case]})[0]
    >>> s["rms_z"], s["expected_rms_z"].__round__(3), s["mean_rel_Y"]
    (0.0, 1.291, 0.0)
    """
    from scipy import stats

    nu = result["settings"].seeds - 1
    rows = []
    for case in result["cases"]:
        z = case["z"].reshape(-1, 3)
        Y, Ym = case["specref"][..., 1].ravel(), case["mitsuba"][..., 1].ravel()
        rows.append({
            "name": case["name"],
            "values": int(z.size),
            "mean_rel_Y": float(np.mean(Y / Ym - 1.0)),
            "max_rel_Y": float(np.max(np.abs(Y / Ym - 1.0))),
            "rms_z": float(np.sqrt(np.mean(z**2))),
            "expected_rms_z": float(np.sqrt(nu / (nu - 2))),
            "max_abs_z": float(np.max(np.abs(z))),
            "frac_abs_z_over_4": float(np.mean(np.abs(z) > 4)),
            "expected_frac_over_4": float(2 * stats.t.sf(4, nu)),
        })  # fmt: skip
    return rows
