"""``specref conformance check --html``: the check's table with each scene's images, one page.

Per scene: the render and the reference (sRGB, each scaled by the reference's 99th percentile of
Y, so that a wrong brightness shows), the relative ΔY per compared pixel (0 black, 10 % and more
white) and the figures and diagnosis of the table (:func:`validation.conformance.check
.summary_table`). Images are inline PNGs, so the page is one file.
"""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np

__all__ = ["write_html"]


def _png(image: np.ndarray) -> str:
    import imageio.v3 as iio

    data = np.clip(np.round(image * 255.0), 0, 255).astype(np.uint8)
    buffer = io.BytesIO()
    iio.imwrite(buffer, data, extension=".png")
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def _shown(XYZ: np.ndarray, scale: float) -> str:
    from reference.colour.colorimetry import XYZ_to_display_RGB
    from reference.display.encodings import encode_srgb

    RGB = np.clip(XYZ_to_display_RGB(XYZ) / scale, 0.0, 1.0)
    return _png(np.repeat(np.repeat(encode_srgb(RGB), 4, axis=0), 4, axis=1))


def _scene_block(row: dict, references, colourspace=None) -> str:
    from validation.conformance.check import _compared, compared_images

    XYZ, ref = compared_images(row["scene"], row["file"], references, colourspace)
    scale = max(float(np.percentile(ref.XYZ[..., 1], 99)), 1e-12)
    mask = _compared(ref)
    rel = np.where(
        mask, np.abs(XYZ[..., 1] - ref.XYZ[..., 1]) / np.maximum(ref.XYZ[..., 1], 1e-300), 0.0
    )
    diff = np.repeat(np.clip(rel / 0.1, 0.0, 1.0)[..., None], 3, axis=-1)
    diff = np.repeat(np.repeat(diff, 4, axis=0), 4, axis=1)
    d = row.get("diagnosis") or {}
    why = f"{d['mistake']}: {d['detail']}" if d.get("mistake") else ""
    verdict = "pass" if row["passed"] else "FAIL"
    return (
        f"<h2>{html.escape(row['scene'])}: {verdict}</h2>"
        f"<p>ΔY of 4×4 blocks {row['block_rel_Y']:.3g} (tolerance {row['tol_Y']:.3g}), ΔE00 "
        f"{row['block_dE00']:.3g} (tolerance {row['tol_dE00']:.3g}). {html.escape(why)}</p>"
        f'<figure><img src="{_shown(XYZ, scale)}" alt="render"><figcaption>render</figcaption>'
        f'</figure><figure><img src="{_shown(ref.XYZ, scale)}" alt="reference"><figcaption>'
        f'reference</figcaption></figure><figure><img src="{_png(diff)}" alt="relative ΔY">'
        "<figcaption>|ΔY|/Y, white at 10 %</figcaption></figure>"
    )


def write_html(result: dict, path, references=None, colourspace=None) -> Path:
    """Write the page for a :func:`validation.conformance.check.check_folder` result, atomically.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "c.html"
    >>> write_html({"scenes": [], "passed": 0, "failed": 0, "missing": ["x"]}, out).name
    'c.html'
    """
    from reference.files import write_text_atomic
    from validation.conformance.check import summary_table

    blocks = "".join(_scene_block(row, references, colourspace) for row in result["scenes"])
    page = (
        "<!doctype html><meta charset='utf-8'><title>specref conformance check</title>"
        "<style>body{font-family:sans-serif;max-width:60em;margin:auto}figure{display:inline-"
        "block;margin:0.5em}img{image-rendering:pixelated}</style>"
        f"<h1>specref conformance check</h1><pre>{html.escape(summary_table(result))}</pre>"
        f"{blocks}"
    )
    return write_text_atomic(path, page)
