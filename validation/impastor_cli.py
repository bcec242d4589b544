"""Library side of ``specref impastor``: checked inputs and formatted tables."""

from __future__ import annotations

import numpy as np

from impastor.multispectral import MIN_CHANNELS, MULTISPECTRAL_DESIGNS
from reference.errors import require

__all__ = ["format_table1", "render_for_cli", "table1_for_cli"]


def table1_for_cli(design: str, n_channels: int, white_luminance: float, display_file=None):
    """Validate the CLI's arguments and compute :func:`validation.impastor.table1`.

    Examples
    --------
    >>> table1_for_cli("optimized", 2, 200.0)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --channels: channel count must be >= 3, got 2
    """
    from reference.display_model import load_display_measurements, virtual_display
    from validation.impastor import table1

    MULTISPECTRAL_DESIGNS.lookup(design)
    require(
        n_channels >= MIN_CHANNELS,
        f"--channels: channel count must be >= {MIN_CHANNELS}, got {n_channels}",
    )
    display = load_display_measurements(display_file) if display_file else virtual_display()
    return table1(design, n_channels, white_luminance, display)


def format_table1(result: dict) -> str:
    """Table 1 as text: six-channel simulation and screen output, ΔE00 statistics per row.

    Examples
    --------
    >>> row = {"label": "D65 (24)", "simulation": dict(mean=0.2, std=0.1, p90=0.3, max=0.4),
    ...        "screen": dict(mean=0.5, std=0.2, p90=0.8, max=1.0)}
    >>> print(format_table1({"design": "optimized", "n_channels": 6, "rows": [row],
    ...                      "lights": {"D65": {"out_of_gamut": []}}}).splitlines()[3])
    D65 (24)    0.20  0.10  0.30  0.40 |  0.50  0.20  0.80  1.00
    """
    lines = [
        f"Table 1 (Ferwerda 2015): CIEDE2000 against the 5 nm spectral truth, "
        f"{result['n_channels']}-channel {result['design']} design",
        f"{'':10} {'six-channel simulation':^24} | {'screen output':^24}",
        f"{'':10} {'mean':>5} {'std':>5} {'90th':>5} {'max':>5} | "
        f"{'mean':>5} {'std':>5} {'90th':>5} {'max':>5}",
    ]
    for row in result["rows"]:
        sim, scr = row["simulation"], row["screen"]
        left = f"{sim['mean']:5.2f} {sim['std']:5.2f} {sim['p90']:5.2f} {sim['max']:5.2f}"
        right = (
            f"{scr['mean']:5.2f} {scr['std']:5.2f} {scr['p90']:5.2f} {scr['max']:5.2f}"
            if scr
            else "  —"
        )
        lines.append(f"{row['label']:10} {left} | {right}")
    for light, info in result["lights"].items():
        names = ", ".join(info["out_of_gamut"]) or "none"
        lines.append(f"out of gamut under {light}: {len(info['out_of_gamut'])} ({names})")
    return "\n".join(lines)


def render_for_cli(
    light: str,
    size: int,
    method: str,
    out,
    counts_out=None,
    observer=(0.0, 0.0, 0.6),
    tilt_deg: float = 0.0,
    screen_lux: float = 1000.0,
) -> str:
    """Render the demo painting and write it as a PNG; return a one-line summary.

    With ``counts_out``, the painting's XYZ also goes through the display per pixel (Eq. (1),
    Ferwerda: ``L_factor`` at the observer's angle from each screen point, the screen's diffuse
    flare under ``screen_lux`` of the booth light subtracted; :mod:`reference.display_pipeline`)
    and the 11-bit counts are written as a 16-bit PNG.

    Examples
    --------
    >>> render_for_cli("D65", 16, "nearest", "x.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown lighting method 'nearest'; allowed: fis, hybrid,
    median_cut, variance_min
    """
    from impastor.painting import PAINTING_LIGHTING_METHODS, render_painting
    from reference.errors import require_positive_int
    from reference.images import write_png
    from reference.spectra import spectrum_from_dataset

    PAINTING_LIGHTING_METHODS.lookup(method)
    size = require_positive_int(size, "--size", 4096)
    spectrum_from_dataset("illuminant", light)
    if counts_out is not None:
        from reference.display_pipeline import ScreenGeometry, screen_view_angles

        geometry = ScreenGeometry(tilt=np.radians(tilt_deg))
        screen_view_angles(geometry, observer, 2, 2)  # an observer behind the screen fails first
    result = render_painting(light, size, method)
    write_png(out, result["sRGB"])
    seconds = sum(result["seconds"].values())
    summary = f"wrote {out} ({size}×{size}, {light}, {method}, shading {seconds:.2f} s)"
    if counts_out is not None:
        summary += "; " + _write_counts(result["XYZ"], counts_out, geometry, observer, screen_lux)
    return summary


def _write_counts(XYZ, path, geometry, observer, screen_lux) -> str:
    """The painting through the virtual display, per pixel; the counts as a 16-bit PNG."""
    import imagecodecs

    from reference.display_model import virtual_display
    from reference.display_pipeline import image_to_display_counts
    from reference.images import write_bytes_atomic

    display = virtual_display()
    white = display.white_XYZ / display.white_XYZ[1]
    out = image_to_display_counts(XYZ, display, geometry, observer, E_XYZ=screen_lux * white)
    write_bytes_atomic(path, imagecodecs.png_encode(out["counts"].astype(np.uint16)))
    lit = XYZ[..., 1] > 1.0
    error = np.abs(out["seen_XYZ"][..., 1][lit] / XYZ[..., 1][lit] - 1.0)
    return (
        f"wrote {path} (11-bit counts; θ up to {np.degrees(out['theta'].max()):.1f}°, "
        f"{int((~out['in_gamut'] & lit).sum())} of {int(lit.sum())} lit pixels out of gamut, "
        f"seen Y within "
        f"{100 * np.median(error):.2f} % of intended, median)"
    )
