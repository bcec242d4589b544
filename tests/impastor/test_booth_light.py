"""A measured lamp for the booth (Ferwerda §3.1; erratum E113): a spectrum file instead of a key."""

import numpy as np
import pytest

from impastor import painting as imp
from reference.colour.spectra import spectrum_from_dataset
from reference.errors import SpecrefError
from validation.cli import main


def _lamp_csv(path, wavelengths, values):
    path.write_text("wavelength_nm,power\n" + "".join(
        f"{w:g},{float(v)!r}\n" for w, v in zip(wavelengths, values, strict=True)
    ))  # fmt: skip
    return path


def test_a_measured_d65_is_the_d65_key(tmp_path):
    d65 = spectrum_from_dataset("illuminant", "D65")
    keep = (d65.wavelengths_nm >= 380) & (d65.wavelengths_nm <= 780)
    lamp = _lamp_csv(tmp_path / "d65.csv", d65.wavelengths_nm[keep], d65.values[keep])
    painting = imp.impasto_painting(16, seed=2)
    by_key = imp.painting_scene("D65", "median_cut", painting, light_resolution=(16, 8))
    by_file = imp.painting_scene(str(lamp), "median_cut", painting, light_resolution=(16, 8))
    np.testing.assert_allclose(by_file.S6, by_key.S6, rtol=1e-12, atol=0)


def test_a_lamp_measured_over_400_700_nm_renders(tmp_path, capsys):
    wl = np.arange(400.0, 701.0, 2.0)
    lamp = _lamp_csv(tmp_path / "led.csv", wl, np.exp(-0.5 * ((wl - 450) / 12) ** 2) + 0.6)
    out = tmp_path / "led.png"
    command = ["impastor", "render", "--light", str(lamp), "--size", "16", "--out", str(out)]
    assert main([*command, "--method", "median_cut"]) == 0
    assert out.is_file()


@pytest.mark.parametrize(("wavelengths", "values", "message"), [
    (np.arange(450.0, 651.0, 10.0), None, "covers 450-650 nm; it must cover 400-700 nm"),
    (np.arange(380.0, 781.0, 10.0), -1.0, "values must be >= 0, got -1 at 380 nm"),
])  # fmt: skip
def test_a_bad_lamp_file_is_one_line(tmp_path, capsys, wavelengths, values, message):
    power = np.ones(wavelengths.size) if values is None else np.full(wavelengths.size, values)
    lamp = _lamp_csv(tmp_path / "lamp.csv", wavelengths, power)
    with pytest.raises(SpecrefError, match=r"lamp\.csv: the lamp's spectrum"):
        imp.booth_light_spectrum(str(lamp))
    out = tmp_path / "x.png"
    assert main(["impastor", "render", "--light", str(lamp), "--size", "8", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert message in err
    assert not out.exists()
