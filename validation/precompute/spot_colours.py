"""Build the spot-colour library of ``Tint_polymer`` (``shrm/polymer/data/spot_colours.csv``).

Run ``python -m validation.precompute.spot_colours`` to rewrite it. Entries, all reflectance factors
resampled to 380-780 nm in 10 nm steps (linear, constant beyond the measured range):

- the 18 Nix Spectro 2 measurements shipped in ``data:spectra/physicallybased`` (CC0; names
  ``pb-<material>``);
- the 24 patches of the ColorChecker N Ohta set shipped with colour-science (names
  ``cc-<patch>``, lower case, spaces as hyphens).
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np

from reference.colour.spectra import (
    GRID_41,
    resample_spectrum,
    spectrum_from_csv,
    spectrum_from_dataset,
)
from reference.data import data_root
from reference.files import write_text_atomic
from shrm.polymer.tint import DEFAULT_TINT_LIBRARY

COLORCHECKER = "ColorChecker N Ohta"


def spot_colour_spectra(data_folder) -> dict[str, tuple[str, np.ndarray]]:
    """Name -> (source, spectrum on GRID_41) for every entry of the library."""
    import colour

    folder = Path(data_folder) / "spectra" / "physicallybased"
    out = {}
    for path in sorted(folder.glob("*__nix_export.csv")):
        name = "pb-" + path.name.split("__")[0]
        spectrum = spectrum_from_csv(path, name=name)
        values = resample_spectrum(spectrum, GRID_41, extrapolation="constant")
        out[name] = ("physicallybased: Nix Spectro 2 (CC0)", np.clip(values, 0.0, 1.0))
    for patch in colour.SDS_COLOURCHECKERS[COLORCHECKER]:
        name = "cc-" + patch.lower().replace(" ", "-")
        spectrum = spectrum_from_dataset("colorchecker", patch, COLORCHECKER)
        values = resample_spectrum(spectrum, GRID_41, extrapolation="constant")
        out[name] = (f"colour-science {COLORCHECKER}", np.clip(values, 0.0, 1.0))
    return out


def library_text(data_folder) -> str:
    """The CSV text of the library."""
    out = io.StringIO()
    out.write("# specref spot-colour library: reflectance factors, 380-780 nm / 10 nm\n")
    out.write("# made by validation/precompute/spot_colours.py\n")
    out.write("name,source," + ",".join(f"{w:g}" for w in GRID_41.wavelengths_nm) + "\n")
    for name, (source, values) in spot_colour_spectra(data_folder).items():
        out.write(f"{name},{source}," + ",".join(f"{v:.6f}" for v in values) + "\n")
    return out.getvalue()


def main() -> int:
    """Rewrite ``shrm/polymer/data/spot_colours.csv``."""
    write_text_atomic(DEFAULT_TINT_LIBRARY, library_text(data_root()))
    sys.stderr.write(f"wrote {DEFAULT_TINT_LIBRARY}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
