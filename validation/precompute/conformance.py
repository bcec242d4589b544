"""Write the conformance scenes and their maps into ``reference/data/conformance/``.

Run ``python -m validation.precompute.conformance`` to rewrite them from
:data:`validation.conformance.scenes.CONFORMANCE_SCENES`:

- ``<name>.toml``: each scene file (:func:`validation.conformance.scenes.scene_text`);
- ``manifest.json``: each scene's reference summary (size, mean XYZ and its standard error, and
  the SHA-256 of the reference files as rendered here;
  :func:`validation.conformance.references.ensure_references`), which the tests check a fresh
  render against;
- ``displays/<stem>.cal`` (with ``.ti3``, ``.json``, ``.cube``): the calibrated display of the
  display scene (:data:`validation.conformance.scenes.CALIBRATED_DISPLAY`), as ``specref display
  calibrate`` writes it, the summary's file names made relative;
- ``maps/<key>.exr``: each map of ``ENVIRONMENT_MAPS`` box-averaged to 32 × 64 texels (the mean
  of the texels of each of 32 × 64 near-equal blocks, ``np.array_split``), 32-bit float RGB in
  the source's orientation (Mitsuba 3's lat-long convention; docs/conventions.md), and the
  synthetic ``maps/ring.exr`` (:func:`validation.conformance.scenes.ring_map`).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from reference.data import data_path, data_root
from reference.files import write_text_atomic
from reference.images.formats import read_exr, read_hdr, write_exr
from validation.conformance.references import ensure_references
from validation.conformance.scenes import (
    CALIBRATED_DISPLAY,
    CONFORMANCE_SCENES,
    ENVIRONMENT_MAPS,
    MAP_ROWS,
    ring_map,
    scene_text,
)


def box_average(image: np.ndarray, rows: int) -> np.ndarray:
    """The image averaged over ``rows × 2 rows`` near-equal blocks of texels.

    Examples
    --------
    >>> box_average(np.arange(32.0).reshape(4, 8, 1), 2)[..., 0]
    array([[ 4.5,  6.5,  8.5, 10.5],
           [20.5, 22.5, 24.5, 26.5]])
    """
    r = np.array_split(np.arange(image.shape[0]), rows)
    c = np.array_split(np.arange(image.shape[1]), 2 * rows)
    return np.array([[image[i][:, j].mean(axis=(0, 1)) for j in c] for i in r])


def small_map(name: str, rows: int = MAP_ROWS) -> np.ndarray:
    """A shipped environment map (``data:environments/<name>``) box-averaged to rows × 2 rows."""
    path = data_path(f"environments/{name}")
    image = read_hdr(path) if path.suffix == ".hdr" else read_exr(path)[0][..., :3]
    return box_average(np.asarray(image, dtype=np.float64), rows)


def write_calibrated_display(folder) -> Path:
    """Calibrate the display of :data:`CALIBRATED_DISPLAY` and write its files into ``folder``.

    Returns the ``.cal``'s path. The calibration is seeded: a second run writes the same tables
    (the ``.ti3``'s date aside).
    """
    from reference.display.calibration import calibrate_display
    from reference.display.calibration_files import write_calibration
    from reference.display.spectral import spectral_display

    c = CALIBRATED_DISPLAY
    display = spectral_display(c["primaries"])
    calibration = calibrate_display(
        display, c["white"], c["curve"], points=c["points"], seed=c["seed"]
    )
    path = Path(folder) / f"{c['stem']}.cal"
    path.parent.mkdir(parents=True, exist_ok=True)
    summary = write_calibration(path, display, calibration, seed=c["seed"])
    summary["files"] = {k: Path(v).name for k, v in summary["files"].items()}
    write_text_atomic(path.with_suffix(".json"), json.dumps(summary, indent=1) + "\n")
    return path


def main(folder=None) -> None:
    """Write every scene file and map into ``folder`` (default the package's data folder)."""
    folder = Path(folder) if folder is not None else data_root() / "conformance"
    (folder / "maps").mkdir(parents=True, exist_ok=True)
    for key, name in ENVIRONMENT_MAPS.items():
        write_exr(folder / "maps" / f"{key}.exr", small_map(name).astype(np.float32))
    write_exr(folder / "maps" / "ring.exr", ring_map())
    write_calibrated_display(folder / "displays")
    for scene in CONFORMANCE_SCENES.values():
        write_text_atomic(folder / f"{scene.name}.toml", scene_text(scene))
    with tempfile.TemporaryDirectory() as tmp:
        manifest = ensure_references(
            folder=tmp, progress=lambda line: sys.stderr.write(line + "\n")
        )
    write_text_atomic(folder / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    sys.stdout.write(
        f"wrote {len(CONFORMANCE_SCENES)} scenes and {len(ENVIRONMENT_MAPS) + 1} maps to {folder}\n"
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
