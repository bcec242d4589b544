"""Comparing two renders per pixel: what ``specref compare A.exr B.exr`` computes.

A user renders a scene in their own renderer (A) and in specref (B, the reference), or the other
way round, and asks how far apart they are. Both images are brought to CIE XYZ:

- channels ``X, Y, Z`` as they are (``specref render --exr-output xyz``);
- spectral channels (Fichet et al. 2021 names ``S0.550,000000nm``, or ``550nm``) integrated with
  the equal-energy band weights of their wavelength grid (``--exr-output spectral``: Y = 1 for a
  white diffuser, docs/render-outputs.md); ASTM E308 weights where the grid allows, else point
  samples;
- channels ``R, G, B`` as linear display RGB of the colourspace in the file's specref metadata
  (sRGB without it).

Per pixel, over the pixels of the mask whose reference luminance is at least 1 % of its peak (the
pixels every render's accuracy promise speaks of, ``reference.scene.metadata``):

- the relative error of Y, ``|Y_A − Y_B| / Y_B``;
- ΔE00 (CIEDE2000) with CIELAB relative to the D65 white at Y = 1 (the white diffuser);
- the chromaticity difference ``Δu'v' = |(u', v')_A − (u', v')_B|`` (CIE 1976 UCS);
- z-scores ``(Y_A − Y_B) / σ_B`` where B carries a standard-error channel of Y named
  ``Y.stderr`` (or ``stderr``), as a Monte Carlo renderer's estimate of its own noise.

:func:`compare_images` returns a JSON-able summary (mean, 95th percentile and max of each) and the
difference image (one channel each, 0 outside the compared pixels).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_00,
    display_RGB_to_XYZ,
    spectral_channel_weights,
)
from reference.errors import SpecrefError, require
from reference.images.formats import channel_wavelengths_nm, read_exr, read_image
from reference.scene.metadata import LIT_FRACTION, read_exr_metadata

__all__ = [
    "STDERR_CHANNELS",
    "XYZ_to_uv_prime",
    "compare_files",
    "compare_images",
    "exr_to_XYZ",
    "pixel_differences",
    "summary_line",
]

#: Names of a standard-error channel of Y in the reference image (case-insensitive).
STDERR_CHANNELS = ("y.stderr", "stderr")


def XYZ_to_uv_prime(XYZ) -> np.ndarray:
    """CIE 1976 UCS chromaticity ``(u', v') = (4X, 9Y) / (X + 15Y + 3Z)``, shape ``(..., 2)``.

    Examples
    --------
    >>> XYZ_to_uv_prime([0.95047, 1.0, 1.08883]).round(4)      # D65
    array([0.1978, 0.4683])
    """
    X, Y, Z = np.moveaxis(np.asarray(XYZ, dtype=np.float64), -1, 0)
    d = X + 15.0 * Y + 3.0 * Z
    safe = np.where(d > 0, d, 1.0)
    return np.stack(
        [np.where(d > 0, 4.0 * X / safe, 0.0), np.where(d > 0, 9.0 * Y / safe, 0.0)], -1
    )


def exr_to_XYZ(path) -> tuple[np.ndarray, dict]:
    """An image file as XYZ ``(H, W, 3)`` (module docstring), with what was found in it.

    Returns
    -------
    XYZ : ndarray, shape (H, W, 3)
    info : dict
        ``kind`` ("xyz", "spectral", "rgb"), ``channels``, and ``stderr`` (the standard-error
        channel of Y, ``(H, W)``, or None).

    Raises
    ------
    SpecrefError
        Unreadable file, or no X/Y/Z, R/G/B or spectral channels (one line naming the file).

    Examples
    --------
    >>> exr_to_XYZ("/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    path = Path(path)
    require(
        path.suffix.lower() in (".exr", ".hdr"),
        f"{path}: compare reads linear images (.exr, .hdr), got {path.suffix or 'no suffix'!r}",
    )
    if path.suffix.lower() == ".hdr":
        image = read_image(path)
        require(image.shape[-1] >= 3, f"{path}: needs 3 colour channels, has {image.shape[-1]}")
        return display_RGB_to_XYZ(image[..., :3]), {"kind": "rgb", "channels": ["R", "G", "B"]}
    image, names = read_exr(path)
    lower = [n.lower() for n in names]
    stderr = next((image[..., lower.index(n)] for n in STDERR_CHANNELS if n in lower), None)
    info = {"channels": names, "stderr": stderr}
    if all(c in names for c in "XYZ"):
        info["kind"] = "xyz"
        return image[..., [names.index(c) for c in "XYZ"]], info
    spectral = [i for i, n in enumerate(names) if channel_wavelengths_nm([n]) is not None]
    if spectral:
        wavelengths = channel_wavelengths_nm([names[i] for i in spectral])
        W = spectral_channel_weights(wavelengths, str(path))
        info["kind"] = "spectral"
        return image[..., spectral] @ W, info
    if all(c in names for c in "RGB"):
        colourspace = (read_exr_metadata(path).get("colourspace") or {}).get("name") or "sRGB"
        info["kind"] = "rgb"
        RGB = image[..., [names.index(c) for c in "RGB"]]
        return display_RGB_to_XYZ(RGB, colourspace), info
    raise SpecrefError(
        f"{path}: no X, Y, Z, no R, G, B and no spectral channels (S0.<nm>nm); has "
        f"{', '.join(names)}"
    )


def pixel_differences(XYZ_a, XYZ_b, mask=None, stderr_b=None) -> tuple[dict, dict]:
    """Per-pixel differences of A against the reference B, and their summary.

    Parameters
    ----------
    XYZ_a, XYZ_b : ndarray, shape (H, W, 3)
    mask : ndarray of bool, shape (H, W), optional
        Pixels to compare (all by default); of those, only the lit ones count.
    stderr_b : ndarray, shape (H, W), optional
        Standard error of B's Y.

    Returns
    -------
    summary : dict
        ``pixels`` (compared), and for ``relative_error_Y``, ``delta_E00``, ``delta_uv`` (and
        ``z`` with a standard error) the ``mean``, ``p95`` and ``max`` (``z``: of ``|z|``, plus
        ``rms`` and ``share_within_3``).
    maps : dict of ndarray (H, W)
        The same quantities per pixel, 0 outside the compared pixels.

    Examples
    --------
    >>> white = np.broadcast_to([0.95047, 1.0, 1.08883], (1, 2, 3))
    >>> summary, _ = pixel_differences(white * 1.01, white)
    >>> round(summary["relative_error_Y"]["max"], 6), round(summary["delta_uv"]["max"], 9)
    (0.01, 0.0)
    """
    a, b = np.asarray(XYZ_a, dtype=np.float64), np.asarray(XYZ_b, dtype=np.float64)
    Y_b = b[..., 1]
    selected = np.ones(Y_b.shape, bool) if mask is None else np.asarray(mask, bool)
    peak = float(Y_b[selected].max()) if selected.any() else 0.0
    lit = selected & (Y_b >= LIT_FRACTION * peak) & (Y_b > 0)
    maps = {
        "relative_error_Y": np.where(lit, np.abs(a[..., 1] - Y_b) / np.where(lit, Y_b, 1.0), 0.0),
        "delta_E00": np.where(lit, delta_E_00(XYZ_to_Lab(a), XYZ_to_Lab(b)), 0.0),
        "delta_uv": np.where(
            lit, np.linalg.norm(XYZ_to_uv_prime(a) - XYZ_to_uv_prime(b), axis=-1), 0.0
        ),
    }
    where = {name: lit for name in maps}
    if stderr_b is not None:
        sigma = np.asarray(stderr_b, dtype=np.float64)
        # z where the reference states a noise; a pixel of zero stderr still counts elsewhere
        where["z"] = lit & (sigma > 0)
        maps["z"] = np.where(where["z"], (a[..., 1] - Y_b) / np.where(where["z"], sigma, 1.0), 0.0)
    summary = {"pixels": int(lit.sum())}
    for name, values in maps.items():
        v = np.abs(values[where[name]])
        stats = (
            {"mean": float(v.mean()), "p95": float(np.percentile(v, 95)), "max": float(v.max())}
            if v.size
            else {"mean": None, "p95": None, "max": None}
        )
        if name == "z" and v.size:
            stats["rms"] = float(np.sqrt(np.mean(v**2)))
            stats["share_within_3"] = float(np.mean(v <= 3.0))
        summary[name] = stats
    return summary, maps


def compare_images(path_a, path_b, mask=None) -> tuple[dict, np.ndarray, list[str]]:
    """Compare image A against the reference B (module docstring).

    Parameters
    ----------
    path_a, path_b : str or Path
        EXR (XYZ, spectral or RGB channels), or Radiance HDR (linear sRGB).
    mask : str or Path, optional
        An image of the same size; pixels whose first channel is > 0.5 are compared.

    Returns
    -------
    summary : dict
        :func:`pixel_differences`'s summary plus the files and the kinds of their channels.
    difference : ndarray, shape (H, W, C)
        One channel per quantity.
    names : list of str
        The channel names of ``difference``.

    Raises
    ------
    SpecrefError
        Unreadable files, missing channels, non-finite pixels, or sizes that differ (one line
        each).

    Examples
    --------
    >>> compare_images("/nonexistent.exr", "/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    XYZ_a, info_a = exr_to_XYZ(path_a)
    XYZ_b, info_b = exr_to_XYZ(path_b)
    for path, XYZ in ((path_a, XYZ_a), (path_b, XYZ_b)):
        # a NaN or an infinity would make every statistic NaN or hide the lit pixels
        bad = int((~np.isfinite(XYZ)).any(axis=-1).sum())
        require(bad == 0, f"{path}: {bad} pixels hold NaN or infinite values; compare needs finite")
    require(
        XYZ_a.shape == XYZ_b.shape,
        f"{path_a}: size {XYZ_a.shape[1]}×{XYZ_a.shape[0]} differs from {path_b}'s "
        f"{XYZ_b.shape[1]}×{XYZ_b.shape[0]}",
    )
    stderr = info_b.get("stderr")
    if stderr is not None:
        bad = int((~(np.isfinite(stderr) & (stderr >= 0))).sum())
        require(bad == 0, f"{path_b}: Y.stderr: {bad} pixels hold NaN, infinite or negative values")
    selected = None
    if mask is not None:
        image = read_image(mask)
        require(
            image.shape[:2] == XYZ_b.shape[:2],
            f"{mask}: mask size {image.shape[1]}×{image.shape[0]} differs from the images' "
            f"{XYZ_b.shape[1]}×{XYZ_b.shape[0]}",
        )
        require(bool(np.isfinite(image[..., 0]).all()), f"{mask}: the mask holds NaN or infinities")
        selected = image[..., 0] > 0.5
    summary, maps = pixel_differences(XYZ_a, XYZ_b, selected, stderr)
    require(
        summary["pixels"] > 0,
        f"{path_b}: nothing to compare: no pixel of the reference "
        + ("within the mask " if mask is not None else "")
        + f"is lit (Y > 0 and at least {LIT_FRACTION:g} of its peak)",
    )
    summary = {
        "a": str(path_a),
        "b": str(path_b),
        "a_channels": info_a["kind"],
        "b_channels": info_b["kind"],
        "mask": None if mask is None else str(mask),
        **summary,
    }
    names = list(maps)
    return summary, np.stack([maps[n] for n in names], axis=-1), names


def _check_output(path, suffix: str, flag: str) -> Path:
    path = Path(path)
    require(path.suffix.lower() == suffix, f"{flag}: must end in {suffix}, got {str(path)!r}")
    require(not path.is_dir(), f"{flag}: {path} is a folder; give a file name")
    return path


def compare_files(path_a, path_b, mask=None, json=None, diff=None) -> dict:
    """:func:`compare_images`, writing the summary (JSON) and the difference image (EXR).

    What ``specref compare`` runs; the outputs are checked before any work and written
    atomically. ``json="-"`` writes nothing (the CLI prints the summary).

    Examples
    --------
    >>> compare_files("a.exr", "b.exr", diff="d.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --diff: must end in .exr, got 'd.png'
    """
    from json import dumps

    from reference.files import write_text_atomic
    from reference.images.formats import write_exr

    if json is not None and str(json) != "-":
        json = _check_output(json, ".json", "--json")
    if diff is not None:
        diff = _check_output(diff, ".exr", "--diff")
    summary, difference, names = compare_images(path_a, path_b, mask)
    if diff is not None:
        write_exr(diff, difference, names)
    if json is not None and str(json) != "-":
        write_text_atomic(json, dumps(summary, indent=2) + "\n")
    return summary


def summary_line(summary: dict) -> str:
    """One line of a comparison's summary, for the terminal.

    Examples
    --------
    >>> s = {"pixels": 4, "relative_error_Y": {"mean": 0.01, "max": 0.02},
    ...      "delta_E00": {"mean": 0.5, "max": 1.0}, "delta_uv": {"max": 0.001}}
    >>> summary_line(s)
    "4 lit pixels: relative error of Y mean 0.01 max 0.02; ΔE00 mean 0.5 max 1; Δu'v' max 0.001"
    """
    if not summary["pixels"]:
        return "no lit pixels to compare"
    rel, dE, duv = summary["relative_error_Y"], summary["delta_E00"], summary["delta_uv"]
    line = (
        f"{summary['pixels']} lit pixels: relative error of Y mean {rel['mean']:.3g} max "
        f"{rel['max']:.3g}; ΔE00 mean {dE['mean']:.3g} max {dE['max']:.3g}; Δu'v' max "
        f"{duv['max']:.3g}"
    )
    if summary.get("z", {}).get("rms") is not None:
        z = summary["z"]
        line += f"; |z| rms {z['rms']:.3g}, within 3: {z['share_within_3']:.1%}"
    return line
