"""A renderer's images against the conformance references: pass or fail, figures, diagnosis.

A folder of renders holds one image per scene, named ``<scene>.exr`` (or ``.hdr``), at the scene's
size, in one of the layouts of ``reference.scene.compare.exr_to_XYZ``: channels ``X, Y, Z``;
spectral channels (``S0.550,000000nm`` or ``550nm``); or linear ``R, G, B`` of the colourspace
given (``colourspace``, default the file's specref metadata, else sRGB). A scene for a calibrated
display takes device values instead (``<scene>.png``, 8 or 16 bits), and both its render and its
reference are compared as the display shows them (:mod:`validation.conformance.display`). Per
scene, over the
pixels of full coverage whose reference Y is at least 1 % of its peak and whose reference
standard error is at most 10 % of their Y (an edge inside a surface, such as a patch's border,
depends on the pixel filter as a silhouette does):

- **blocks**: the image averaged over 4 × 4-pixel blocks (blocks with at least half their pixels
  compared), so that a Monte Carlo renderer's noise averages out while a misplaced highlight or
  a turned map does not; the mean relative ΔY and the mean ΔE00 (CIEDE2000, CIELAB relative to
  the D65 white at Y = 1) of the blocks;
- **pixels**: mean and max relative ΔY and ΔE00 per pixel, and z-scores of Y against the
  reference's standard error (``reference.scene.compare.pixel_differences``);
- **ratio_Y**: ``Σ Y_render / Σ Y_reference − 1``.

A scene **passes** when the blocks' mean relative ΔY is at most ``tol_Y = floor + 3 u`` and their
mean ΔE00 at most the scene's ΔE00 floor, where the floors are the scene's
(``ConformanceScene.tolerance_Y``, ``tolerance_dE``: what two correct renderers may differ by)
and ``u`` is the blocks' mean relative standard error of the reference. A failing scene is tried
against each mistake it catches (:mod:`validation.conformance.diagnose`); the diagnosis is the
mistake under which the render passes with the smallest block error, or the one that shrinks the
error most (at least twice) as a "likely" cause.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require

__all__ = [
    "BLOCK",
    "block_metrics",
    "check_folder",
    "check_outputs",
    "check_render",
    "compared_images",
    "read_render",
    "summary_table",
]

#: Side of the blocks the pass criterion averages over, pixels.
BLOCK = 4
#: A block counts when at least this fraction of its pixels is compared.
BLOCK_FILL = 0.5
#: Pixels whose reference standard error exceeds this fraction of their Y are not compared.
MAX_REL_STDERR = 0.1
#: Multiples of the reference's standard error added to the floor of the ΔY threshold.
K_SIGMA = 3.0


def read_render(path, colourspace: str | None = None, name: str | None = None) -> np.ndarray:
    """A user's render as XYZ ``(H, W, 3)`` (module docstring), NaN refused.

    ``name``: the scene; a scene for a calibrated display reads device values and returns what
    the display shows for them.

    Examples
    --------
    >>> read_render("/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    from reference.colour.colorimetry import display_RGB_to_XYZ
    from reference.files import require_input_file
    from reference.images.formats import read_exr
    from reference.scene.compare import exr_to_XYZ
    from validation.conformance.display import read_device_values, scene_display

    path = require_input_file(path)  # a folder, a FIFO or a link loop named as such
    display = scene_display(name) if name is not None else None
    if display is not None:
        return display.shown(read_device_values(path))
    XYZ, info = exr_to_XYZ(path)
    if colourspace is not None and info["kind"] == "rgb" and path.suffix.lower() == ".exr":
        image, names = read_exr(path)
        XYZ = display_RGB_to_XYZ(image[..., [names.index(c) for c in "RGB"]], colourspace)
    XYZ = np.asarray(XYZ, dtype=np.float64)
    bad = ~np.isfinite(XYZ).all(axis=-1)
    if bad.any():
        row, column = np.argwhere(bad)[0]
        raise SpecrefError(
            f"{path}: {int(bad.sum())} pixels are NaN or infinite (the first at row {row}, "
            f"column {column})"
        )
    return XYZ


def _compared(ref) -> np.ndarray:
    Y = ref.XYZ[..., 1]
    full = ref.coverage >= 1.0
    peak = float(Y[full].max(initial=0.0))
    # an edge inside a surface (a patch's border) leaves the sub-samples far apart: the pixel
    # filter decides there, as at an object's silhouette
    smooth = ref.stderr[..., 1] <= MAX_REL_STDERR * Y
    return full & smooth & (0.01 * peak <= Y) & (Y > 0)


def _blocks(image: np.ndarray, mask: np.ndarray, squared: bool = False):
    """Means (or root-sum-squares / n, for standard errors) over BLOCK² blocks of masked pixels."""
    H, W = mask.shape
    h, w = H // BLOCK, W // BLOCK
    m = mask[: h * BLOCK, : w * BLOCK].reshape(h, BLOCK, w, BLOCK)
    x = image[: h * BLOCK, : w * BLOCK].reshape(h, BLOCK, w, BLOCK, -1)
    n = m.sum(axis=(1, 3))
    values = np.where(m[..., None], x**2 if squared else x, 0.0).sum(axis=(1, 3))
    keep = n >= BLOCK_FILL * BLOCK * BLOCK
    safe = np.maximum(n, 1)[..., None]
    out = np.sqrt(values) / safe if squared else values / safe
    return out[keep], keep


def block_metrics(XYZ: np.ndarray, ref, tolerance_Y: float, tolerance_dE: float) -> dict:
    """The figures of the module docstring and the verdict, for one render against a reference.

    Examples
    --------
    >>> from validation.conformance.references import Reference
    >>> XYZ = np.full((8, 8, 3), 0.5); cover = np.ones((8, 8))
    >>> ref = Reference("x", XYZ, XYZ * 0.0, XYZ, np.ones(3), cover)
    >>> m = block_metrics(XYZ * 1.005, ref, 0.01, 1.0)
    >>> m["passed"], round(m["block_rel_Y"], 4), m["blocks"]
    (True, 0.005, 4)
    >>> block_metrics(XYZ * 1.05, ref, 0.01, 1.0)["passed"]
    False
    """
    from reference.colour.colorimetry import XYZ_to_Lab, delta_E_00
    from reference.scene.compare import pixel_differences

    mask = _compared(ref)
    a, _ = _blocks(XYZ, mask)
    b, keep = _blocks(ref.XYZ, mask)
    se, _ = _blocks(ref.stderr, mask, squared=True)
    Yb = np.maximum(b[:, 1], 1e-300)
    rel = np.abs(a[:, 1] - b[:, 1]) / Yb
    dE = delta_E_00(XYZ_to_Lab(a), XYZ_to_Lab(b))
    u = float(np.mean(se[:, 1] / Yb)) if b.size else 0.0
    tol_Y = tolerance_Y + K_SIGMA * u
    pixels, _ = pixel_differences(XYZ, ref.XYZ, mask, ref.stderr[..., 1])
    block_rel_Y = float(rel.mean()) if rel.size else float("inf")
    block_dE = float(dE.mean()) if dE.size else float("inf")
    total = float(ref.XYZ[..., 1][mask].sum())
    return {
        "passed": bool(block_rel_Y <= tol_Y and block_dE <= tolerance_dE),
        "blocks": int(keep.sum()),
        "block_rel_Y": block_rel_Y,
        "block_dE00": block_dE,
        "tol_Y": tol_Y,
        "tol_dE00": tolerance_dE,
        "reference_rel_stderr": u,
        "ratio_Y": float(XYZ[..., 1][mask].sum() / total - 1.0) if total > 0 else None,
        "pixels": pixels,
    }


def _diagnose(name: str, XYZ: np.ndarray, ref, scene, found: dict, folder=None) -> dict | None:
    """The best explanation among the scene's diagnoses, or None."""
    from validation.conformance.diagnose import DIAGNOSES, DiagnosisContext, diagnosis_variants
    from validation.conformance.display import scene_display

    ctx = DiagnosisContext(name, ref, XYZ)
    display = scene_display(name)
    tried = []
    for key in scene.catches:
        diagnosis = DIAGNOSES.lookup(key)
        for label, variant in diagnosis_variants(diagnosis, ctx, folder):
            if display is not None:  # what the display shows for the mistaken frame
                variant = display.round_trip(variant)
            alt = dataclasses.replace(ref, XYZ=variant)
            m = block_metrics(XYZ, alt, scene.tolerance_Y, scene.tolerance_dE)
            tried.append((key, label, m))
    if not tried:
        return None
    # a named mistake before a bare factor: Y_scaled explains any error of scale
    passing = [t for t in tried if t[2]["passed"] and t[0] != "Y_scaled"]
    passing = passing or [t for t in tried if t[2]["passed"]]
    key, label, m = min(passing or tried, key=lambda t: t[2]["block_rel_Y"])
    if not passing and m["block_rel_Y"] > 0.5 * found["block_rel_Y"]:
        return {"mistake": None, "tried": [t[0] for t in tried]}
    return {
        "mistake": key,
        "detail": label,
        "explanation": DIAGNOSES.lookup(key).explanation,
        "certain": bool(passing),
        "block_rel_Y": m["block_rel_Y"],
        "block_dE00": m["block_dE00"],
    }


def check_render(
    name: str, path, references=None, colourspace: str | None = None, diagnose: bool = True,
    progress=None,
) -> dict:  # fmt: skip
    """Check one render against its scene's reference (module docstring).

    Parameters
    ----------
    name : str
        The scene (a key of ``CONFORMANCE_SCENES``).
    path : str or Path
        The render.
    references : str or Path, optional
        The references' folder (default ``references.reference_folder()``; rendered if missing).
    colourspace : str, optional
        Of RGB renders.
    diagnose : bool
        Try the mistakes on a failing render.

    Returns
    -------
    dict
        ``scene``, ``file`` and :func:`block_metrics`' figures, with ``diagnosis`` when it fails.

    Raises
    ------
    SpecrefError
        A render of the wrong size, with NaN pixels, unreadable, or without usable channels.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> from validation.conformance.references import load_reference
    >>> refs = pathlib.Path(tempfile.mkdtemp())
    >>> XYZ = load_reference("colorchecker-d65", refs).XYZ.astype(np.float32)
    >>> found = check_render("colorchecker-d65", write_exr(refs / "r.exr", XYZ, list("XYZ")), refs)
    >>> found["passed"], found["block_rel_Y"] < 1e-6
    (True, True)
    """
    from validation.conformance.references import reference_folder
    from validation.conformance.scenes import CONFORMANCE_SCENES

    scene = CONFORMANCE_SCENES.lookup(name)
    folder = Path(references) if references is not None else reference_folder()
    XYZ, ref = compared_images(name, path, folder, colourspace, progress)
    found = {"scene": name, "file": str(path), **block_metrics(
        XYZ, ref, scene.tolerance_Y, scene.tolerance_dE)}  # fmt: skip
    if diagnose and not found["passed"]:
        if progress is not None:
            progress(f"{name}: failed; trying the mistakes it catches")
        found["diagnosis"] = _diagnose(name, XYZ, ref, scene, found, folder)
    return found


def compared_images(name: str, path, references, colourspace=None, progress=None) -> tuple:
    """The render and the reference as the check compares them: ``(XYZ (H, W, 3), Reference)``.

    A scene for a calibrated display gives both as the display shows them (the render's device
    values, the reference's through its device values, out-of-gamut colours clipped alike).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> from validation.conformance.references import load_reference
    >>> refs = pathlib.Path(tempfile.mkdtemp())
    >>> XYZ = load_reference("colorchecker-d65", refs).XYZ.astype(np.float32)
    >>> path = write_exr(refs / "r.exr", XYZ, ["X", "Y", "Z"])
    >>> render, ref = compared_images("colorchecker-d65", path, refs)
    >>> bool(np.allclose(render, ref.XYZ, rtol=1e-6, atol=0))
    True
    """
    from validation.conformance.display import scene_display
    from validation.conformance.references import load_reference

    XYZ = read_render(path, colourspace, name)
    _check_size(name, path, XYZ)
    ref = load_reference(name, references, progress)
    display = scene_display(name)
    if display is not None:
        ref = dataclasses.replace(ref, XYZ=display.round_trip(ref.XYZ))
    return XYZ, ref


def _check_size(name: str, path, XYZ: np.ndarray) -> None:
    """Refuse a render whose size is not its scene's (``[render]`` of the scene file)."""
    import tomllib

    from validation.conformance.scenes import scene_text

    r = tomllib.loads(scene_text(name))["render"]
    require(
        XYZ.shape[:2] == (r["height"], r["width"]),
        f"{path}: {XYZ.shape[1]} × {XYZ.shape[0]} pixels; the scene {name} is "
        f"{r['width']} × {r['height']} (width × height)",
    )


def _render_files(folder: Path) -> dict[str, Path]:
    from validation.conformance.display import scene_display
    from validation.conformance.scenes import CONFORMANCE_SCENES

    require(folder.is_dir(), f"{folder}: not a folder")
    files = {}
    names = CONFORMANCE_SCENES.names()
    for path in sorted(folder.iterdir()):
        suffix, stem = path.suffix.lower(), path.name[: -len(path.suffix)]
        display = stem in names and scene_display(stem) is not None
        # a PNG is the render of a frame for a calibrated display, else a preview (passed over),
        # and that frame's PNG is its render whatever lies beside it
        if suffix == ".png" and not display:
            continue
        if suffix not in (".exr", ".hdr", ".png") or (
            display and suffix != ".png" and (folder / f"{stem}.png").exists()
        ):
            continue
        require(
            stem in names,
            f"{path}: no conformance scene named {stem!r}; allowed: {', '.join(names)}",
        )
        require(
            not display or suffix == ".png",
            f"{path}: {stem} is a frame for a calibrated display; its render is the device "
            f"values sent to it, as {stem}.png (8 or 16 bits)",
        )
        require(stem not in files, f"{path}: a second render of {stem} (also {files.get(stem)})")
        files[stem] = path
    require(
        files,
        f"{folder}: no renders (.exr or .hdr named after the scenes, .png for a calibrated "
        "display)",
    )
    return files


def check_folder(folder, references=None, colourspace=None, progress=None) -> dict:
    """Check every render in ``folder`` (``<scene>.exr``); all are read before any is judged.

    Returns
    -------
    dict
        ``scenes`` (one :func:`check_render` result each), ``passed`` and ``failed`` counts and
        ``missing`` (scenes without a render).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> from validation.conformance.references import load_reference
    >>> refs, renders = pathlib.Path(tempfile.mkdtemp()), pathlib.Path(tempfile.mkdtemp())
    >>> XYZ = 2 * load_reference("colorchecker-a", refs).XYZ.astype(np.float32)
    >>> _ = write_exr(renders / "colorchecker-a.exr", XYZ, ["X", "Y", "Z"])
    >>> result = check_folder(renders, refs)
    >>> result["failed"], result["scenes"][0]["diagnosis"]["detail"]
    (1, 'by 2')
    """
    from validation.conformance.scenes import CONFORMANCE_SCENES

    files = _render_files(Path(folder))
    if colourspace is not None:
        from reference.colour.colorimetry import XYZ_to_RGB_matrix

        try:
            XYZ_to_RGB_matrix(colourspace)
        except SpecrefError as error:
            raise SpecrefError(f"colourspace: {error}") from None
    for name, path in files.items():  # bad input is refused before the references are rendered
        _check_size(name, path, read_render(path, colourspace, name))
    if references is not None and Path(references).exists():  # its manifest, before any line
        from validation.conformance.references import _read_manifest

        require(Path(references).is_dir(), f"--references: {references}: not a folder")
        _read_manifest(Path(references))
    results = []
    for name, path in files.items():
        if progress is not None:
            progress(f"{name}: checking {path.name}")
        results.append(check_render(name, path, references, colourspace, progress=progress))
    passed = sum(r["passed"] for r in results)
    return {
        "scenes": results,
        "passed": passed,
        "failed": len(results) - passed,
        "missing": [n for n in CONFORMANCE_SCENES.names() if n not in files],
    }


def check_outputs(renders, references, outputs) -> None:
    """Refuse, before any work, outputs that cannot be written or that are one of the inputs.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()); (d / "colorchecker-a.exr").write_bytes(b"")
    0
    >>> check_outputs(d, None, [d / "colorchecker-a.exr"])
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../colorchecker-a.exr: is an input of the check; ...
    """
    from reference.files import check_output_file

    folders = [Path(renders), Path(references) if references is not None else None]
    for out in (Path(o) for o in outputs if o):
        for folder in filter(None, folders):
            inside = folder.is_dir() and out.resolve().parent == folder.resolve()
            require(
                not (inside and out.exists()),
                f"{out}: is an input of the check; give another file",
            )
        check_output_file(out)


def summary_table(result: dict) -> str:
    """The check as a text table, one line per scene, with the diagnosis of each failure.

    Examples
    --------
    >>> row = {"scene": "x", "passed": False, "block_rel_Y": 0.2, "tol_Y": 0.01,
    ...        "block_dE00": 3.0, "tol_dE00": 1.0, "ratio_Y": 0.2,
    ...        "diagnosis": {"mistake": "Y_scaled", "detail": "by 1.2", "certain": True}}
    >>> print(summary_table({"scenes": [row], "passed": 0, "failed": 1, "missing": []}))
    scene  result  ΔY blocks (tol)  ΔE00 blocks (tol)  ΣY ratio − 1  diagnosis
    x      FAIL    0.2 (0.01)       3 (1)              +0.2          Y_scaled: by 1.2
    0 passed, 1 failed, 0 without a render
    """
    rows = [
        ("scene", "result", "ΔY blocks (tol)", "ΔE00 blocks (tol)", "ΣY ratio − 1", "diagnosis")
    ]
    for r in result["scenes"]:
        d = r.get("diagnosis") or {}
        why = ""
        if d.get("mistake"):
            why = f"{d['mistake']}: {d['detail']}" + ("" if d["certain"] else " (likely)")
        elif "diagnosis" in r:
            why = "no known mistake explains it"
        rows.append((
            r["scene"], "pass" if r["passed"] else "FAIL",
            f"{r['block_rel_Y']:.3g} ({r['tol_Y']:.3g})",
            f"{r['block_dE00']:.3g} ({r['tol_dE00']:.3g})",
            "" if r["ratio_Y"] is None else f"{r['ratio_Y']:+.3g}", why,
        ))  # fmt: skip
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = [
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows
    ]
    lines.append(
        f"{result['passed']} passed, {result['failed']} failed, "
        f"{len(result['missing'])} without a render"
    )
    return "\n".join(lines)


def write_json(result: dict, path) -> Path:
    """The check's result as JSON, written atomically."""
    from reference.files import write_text_atomic

    return write_text_atomic(path, json.dumps(result, indent=1, default=float) + "\n")
