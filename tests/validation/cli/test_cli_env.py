"""``specref env fit|spectralize``: round trips through the files, read back, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colour.spectral_regression import (
    SpectralRegression,
    features_RGB,
    load_regression,
    save_regression,
)
from reference.colour.upsampling import default_regression
from reference.images.formats import channel_wavelengths_nm, write_exr, write_png
from reference.images.spectral import read_environment_file
from reference.scene.loader import loads_scene
from validation.cli import main


def _panorama(tmp_path, rng, name="pano.exr"):
    RGB = rng.uniform(0.0, 3.0, (8, 16, 3))
    return write_exr(tmp_path / name, RGB), RGB


@pytest.mark.parametrize("suffix", [".exr", ".tif"])
def test_spectralize_round_trip_and_readers(tmp_path, rng, capsys, suffix):
    path, RGB = _panorama(tmp_path, rng)
    out = tmp_path / f"spectral{suffix}"
    code = main(
        ["env", "spectralize", str(path), "--model", "default", "--rows", "3", "-o", str(out)]
    )
    assert code == 0
    assert "8x16, 41 bands, 3 row blocks" in capsys.readouterr().out
    image, names = read_environment_file(out)
    assert image.shape == (8, 16, 41)
    assert_allclose(channel_wavelengths_nm(names), np.arange(380.0, 781.0, 10.0))
    # float32 on disk: the model's float64 prediction within erratum E45's rounding bound
    # (n_features + 7)·2⁻²⁴·Σ|x_i c_i| (root-polynomials: no exposure factor)
    model = default_regression()
    X = features_RGB(RGB.reshape(-1, 3), model.kind, model.degree)
    bound = (X.shape[1] + 7) * 2.0**-24 * (np.abs(X) @ np.abs(model.coefficients))
    assert model.kind == "root_polynomial"
    assert (np.abs(image - model.predict(RGB)) <= bound.reshape(image.shape)).all()
    # the scene reader's environment light takes it as a spectral map
    scene = loads_scene(
        f'[[lights]]\ntype = "environment"\nfile = "{out.name}"\n', "s.toml", tmp_path
    )
    assert scene.lights[0].is_spectral
    assert scene.lights[0].image.shape == (8, 16, 41)
    # specref sh project --bands spectral reads it as it is
    coefficients = tmp_path / "sh.npz"
    assert (
        main(
            [
                "sh",
                "project",
                str(out),
                "--order",
                "2",
                "--bands",
                "spectral",
                "-o",
                str(coefficients),
            ]
        )
        == 0
    )
    assert "41 channels" in capsys.readouterr().out


def test_fit_saves_a_model_that_loads(tmp_path, capsys):
    out = tmp_path / "m.json"
    assert main(["env", "fit", "--features", "polynomial", "--degree", "2", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "held out, ColorChecker N Ohta: ΔE94 D65 mean" in printed
    model = load_regression(out, np.arange(380.0, 781.0, 10.0))
    assert (model.kind, model.degree, model.camera) == ("polynomial", 2, "Nikon 5100 (NPL)")
    # the synthetic target is augmented by default (weight by cross-validation, erratum E44)
    assert model.augmentation["method"] == "products"
    assert f"products at weight {model.augmentation['weight']:g}" in printed


def test_fit_from_a_target_file(tmp_path, rng, capsys):
    RGB = rng.uniform(0, 1, (30, 3))
    wl = np.arange(380, 781, 5)
    spectra = np.clip(RGB @ rng.uniform(0, 1, (3, wl.size)) / 3, 0, None)  # reflectances <= 1
    header = "R,G,B," + ",".join(f"{w}nm" for w in wl)
    rows = [",".join(f"{v:.6f}" for v in (*c, *s)) for c, s in zip(RGB, spectra, strict=True)]
    (tmp_path / "t.csv").write_text(header + "\n" + "\n".join(rows) + "\n")
    out = tmp_path / "m.json"
    code = main(
        ["env", "fit", "--target", str(tmp_path / "t.csv"), "--degree", "1", "-o", str(out)]
    )
    assert code == 0
    model = load_regression(out)
    assert_allclose(model.predict(RGB[:3]), spectra[:3, ::2], atol=1e-3)


def _expect_error(capsys, argv, message):
    try:
        code = main(argv)
    except SystemExit as usage_error:  # a flag's value refused while parsing
        code = usage_error.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert message in err[0]


def test_bad_input_one_line_exit_2(tmp_path, rng, capsys):
    pano, _ = _panorama(tmp_path, rng)
    # the colorimetric loss's spectral weight: NaN, negative and overflowing values
    for weight in ("nan", "-1", "1e400", "1e308"):  # 1e308 overflowed the normal equations
        _expect_error(
            capsys,
            ["env", "fit", "--spectral-weight", weight, "-o", str(tmp_path / "w.json")],
            "--spectral-weight: β (colorimetric loss only) must be in (0, 1e+06]",
        )
    assert not (tmp_path / "w.json").exists()
    # a target whose patch counts differ between RGB and spectra
    (tmp_path / "rgb.csv").write_text("R,G,B\n0.1,0.2,0.3\n0.3,0.2,0.1\n")
    (tmp_path / "spec.csv").write_text("380,780\n0.1,0.2\n")
    _expect_error(
        capsys,
        [
            "env",
            "fit",
            "--target",
            str(tmp_path / "rgb.csv"),
            "--spectra",
            str(tmp_path / "spec.csv"),
            "-o",
            str(tmp_path / "m.json"),
        ],
        "1 spectra for 2 RGB patches",
    )
    # spectra on a grid that does not cover the scene grid
    (tmp_path / "short.csv").write_text("R,G,B,400,700\n0.1,0.2,0.3,0.1,0.2\n")
    _expect_error(
        capsys,
        ["env", "fit", "--target", str(tmp_path / "short.csv"), "-o", str(tmp_path / "m.json")],
        "do not cover the scene grid 380-780/10",
    )
    # an augmentation asked of a target file (its products' RGB needs the camera), a wrong key
    _expect_error(
        capsys,
        [
            "env",
            "fit",
            "--target",
            str(tmp_path / "short.csv"),
            "--augment",
            "products",
            "-o",
            str(tmp_path / "m.json"),
        ],
        "short.csv: --augment products: a target file cannot be augmented",
    )
    _expect_error(
        capsys,
        ["env", "fit", "--augment", "glaze", "-o", str(tmp_path / "m.json")],
        "argument --augment: unknown value 'glaze'; allowed: products, none",
    )
    assert not (tmp_path / "m.json").exists()
    # negative or NaN RGB
    (tmp_path / "neg.csv").write_text("R,G,B,380,780\n-0.1,0.2,0.3,0.1,0.2\n")
    _expect_error(
        capsys,
        ["env", "fit", "--target", str(tmp_path / "neg.csv"), "-o", str(tmp_path / "m.json")],
        "neg.csv: patch 1: RGB must be finite and in [0, 10]",
    )
    # a degree outside 1…5, an out-of-range ridge strength
    _expect_error(
        capsys,
        ["env", "fit", "--features", "polynomial", "--degree", "6", "-o", str(tmp_path / "m.json")],
        "degree must be an integer in 1…5, got 6",
    )
    _expect_error(
        capsys,
        ["env", "fit", "--ridge", "5", "-o", str(tmp_path / "m.json")],
        "argument --ridge: must be a number in [0, 1], got '5'",
    )
    # a model file of another grid
    other = save_regression(
        SpectralRegression("polynomial", 1, np.eye(3), [450.0, 550.0, 650.0]),
        tmp_path / "other.json",
    )
    _expect_error(
        capsys,
        ["env", "spectralize", str(pano), "--model", str(other), "-o", str(tmp_path / "o.exr")],
        "model grid 450-650 nm, 3 bands; expected",
    )
    # a panorama that is not HDR
    png = write_png(tmp_path / "pano.png", np.zeros((8, 16, 3)))
    _expect_error(
        capsys,
        ["env", "spectralize", str(png), "--model", "default", "-o", str(tmp_path / "o.exr")],
        "an 8-bit image is not HDR; merge bracketed",
    )
    assert not (tmp_path / "o.exr").exists()
