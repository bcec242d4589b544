import numpy as np
import pytest

from reference.colour.colorimetry import (
    XYZ_to_Lab,
    band_weights,
    delta_E_00,
    spectra_to_XYZ,
    white_XYZ,
)
from reference.colour.spectra import spectrum_from_dataset
from reference.errors import SpecrefError
from shrm.polymer.characterization import (
    MEASUREMENTS,
    characterize_model,
    read_characterization,
    write_characterization,
)
from shrm.polymer.kubelka_munk import polymer_constituents, polymer_K_S, slab_measured
from validation.cli import main


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("polymer") / "hdpe.csv"
    write_characterization(path, characterize_model())
    return path


def test_write_read_round_trip(model_file):
    ch, back = characterize_model(), read_characterization(model_file)
    np.testing.assert_array_equal(back.thickness_mm, ch.thickness_mm)
    np.testing.assert_array_equal(back.tio2_pct, ch.tio2_pct)
    for name in MEASUREMENTS:  # written with 10 significant digits
        np.testing.assert_allclose(getattr(back, name), getattr(ch, name), rtol=1e-9, atol=1e-12)
    assert back.meta["index"] == 1.54
    assert back.meta["material"] == "HDPE-like"


def test_lookup_at_grid_points_returns_the_chips(model_file):
    ch = read_characterization(model_file)
    got = ch.lookup(ch.thickness_mm[:, None], ch.tio2_pct[None, :])
    for name in MEASUREMENTS:
        np.testing.assert_allclose(got[name], getattr(ch, name), atol=1e-12)


@pytest.mark.parametrize("illuminant", ["D65", "A"])
def test_interpolation_against_the_model_off_grid_below_half_a_delta_E(model_file, illuminant):
    # Source: the Kubelka-Munk model evaluated directly at the off-grid points (geometric midpoints
    # in thickness, midpoints in TiO2), against the file's interpolation between the chips.
    ch = read_characterization(model_file)
    d = np.sqrt(ch.thickness_mm[1:] * ch.thickness_mm[:-1])
    c = 0.5 * (ch.tio2_pct[1:] + ch.tio2_pct[:-1])
    d, c = (a.ravel() for a in np.meshgrid(d, c, indexing="ij"))
    K, S = polymer_K_S(polymer_constituents(), c)
    truth = dict(zip(("over_black", "transmittance"), slab_measured(K, S, d[:, None]), strict=True))
    truth["over_white"] = slab_measured(K, S, d[:, None], R_g=0.9)[0]
    got = ch.lookup(d, c)
    W = band_weights(illuminant=spectrum_from_dataset("illuminant", illuminant))
    white = white_XYZ(W)
    for name in MEASUREMENTS:
        Lab_got = XYZ_to_Lab(spectra_to_XYZ(got[name], W), white)
        Lab_true = XYZ_to_Lab(spectra_to_XYZ(truth[name], W), white)
        delta = delta_E_00(Lab_got, Lab_true)
        # measured: mean <= 0.07, max <= 0.3 (transmittance is the hardest)
        assert delta.mean() < 0.5, (name, delta.mean())
        assert delta.max() < 1.0, (name, delta.max())


def test_lookup_outside_the_grid_is_refused(model_file):
    ch = read_characterization(model_file)
    with pytest.raises(SpecrefError, match=r"thickness_mm: must be in \[0.381, 4.572\]"):
        ch.lookup(5.0, 0.1)
    with pytest.raises(SpecrefError, match="tio2_pct: must be in"):
        ch.lookup(1.0, -0.1)


def _lines(model_file):
    return model_file.read_text().splitlines()


def test_non_monotonic_grid_is_refused(model_file, tmp_path):
    lines = _lines(model_file)
    header = next(i for i, line in enumerate(lines) if line.startswith("thickness_mm"))
    rows = lines[header + 1 :]
    # swap the first two chips of the first thickness (TiO2 0 and 0.02)
    swapped = rows[3:6] + rows[0:3] + rows[6:]
    path = tmp_path / "swapped.csv"
    path.write_text("\n".join(lines[: header + 1] + swapped) + "\n")
    with pytest.raises(SpecrefError, match=r"swapped\.csv: the grid is not monotonic"):
        read_characterization(path)


def test_spectra_not_matching_the_grid_are_refused(model_file, tmp_path):
    lines = _lines(model_file)
    header = next(i for i, line in enumerate(lines) if line.startswith("thickness_mm"))
    short = list(lines)
    short[header + 2] = short[header + 2].rsplit(",", 1)[0]  # one value missing
    path = tmp_path / "short.csv"
    path.write_text("\n".join(short) + "\n")
    with pytest.raises(SpecrefError, match=r"short\.csv:\d+: spectra do not match the grid: 40"):
        read_characterization(path)
    missing = lines[: header + 1] + [
        r for r in lines[header + 1 :] if "0.381,0.02,over_white" not in r
    ]
    path.write_text("\n".join(missing) + "\n")
    with pytest.raises(SpecrefError, match=r"TiO2 0\.02 has no over_white"):
        read_characterization(path)
    path.write_text("\n".join(lines[: header + 1] + lines[header + 4 :]) + "\n")  # chip 0 gone
    with pytest.raises(SpecrefError, match="not monotonic or not complete"):
        read_characterization(path)


def test_bad_values_and_header(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("thickness_mm,tio2_pct,measurement,400,390\n")
    with pytest.raises(SpecrefError, match="wavelengths must increase"):
        read_characterization(path)
    path.write_text("thickness_mm,tio2_pct,measurement,400,500\n1,0,over_black,0.1,1.2\n")
    with pytest.raises(SpecrefError, match=r"bad\.csv:2: over_black: values must be in \[0, 1\]"):
        read_characterization(path)
    path.write_text("thickness_mm,tio2_pct,measurement,400,500\n1,0,over_gray,0.1,0.2\n")
    with pytest.raises(SpecrefError, match="measurement must be one of"):
        read_characterization(path)
    with pytest.raises(SpecrefError, match="no such characterization file"):
        read_characterization(tmp_path / "none.csv")


def test_cli_characterize_writes_a_readable_file(tmp_path, capsys):
    out = tmp_path / "chips.csv"
    assert main(["polymer", "characterize", "-o", str(out), "--thickness", "0.762,3.048",
                 "--tio2", "0,1", "--grid", "31"]) == 0  # fmt: skip
    assert "2 thicknesses x 2 TiO2 loads x 31 bands" in capsys.readouterr().out
    assert read_characterization(out).over_black.shape == (2, 2, 31)


def test_a_backing_that_is_no_reflectance_and_a_partial_range_are_refused(tmp_path):
    # both used to render: a white backing of reflectance 5, and spectra of 400-500 nm only
    # (extrapolated flat over the rest of the visible range)
    good = tmp_path / "chips.csv"
    assert main(["polymer", "characterize", "-o", str(good), "--thickness", "0.762,3.048",
                 "--tio2", "0,1", "--grid", "31"]) == 0  # fmt: skip
    lines = good.read_text().splitlines()
    bright = tmp_path / "bright.csv"
    bright.write_text("\n".join(line.replace("backing_white: 0.9", "backing_white: 5")
                                for line in lines) + "\n")  # fmt: skip
    with pytest.raises(SpecrefError, match=r"bright\.csv: # backing_white: a reflectance, in"):
        read_characterization(bright)
    dense = tmp_path / "dense.csv"  # an index of 1e308 was read and rendered
    dense.write_text("\n".join(line.replace("# index: 1.54", "# index: 1e308") for line in lines))
    with pytest.raises(SpecrefError, match=r"dense\.csv: # index: a refractive index must be in"):
        read_characterization(dense)
    header = next(i for i, line in enumerate(lines) if line.startswith("thickness_mm"))
    keep = 3 + sum(float(w) <= 500 for w in lines[header].split(",")[3:])
    narrow = tmp_path / "narrow.csv"
    cut = [",".join(line.split(",")[:keep]) for line in lines[header:]]
    narrow.write_text("\n".join(lines[:header] + cut) + "\n")
    with pytest.raises(SpecrefError, match=r"narrow\.csv:\d+: wavelengths must cover 400-700 nm"):
        read_characterization(narrow)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--thickness", "2,1"], "thickness_mm: the grid is not monotonic"),
        (["--thickness=-1,1"], "--thickness: each thickness must be in [0, 1000] mm"),
        (["--tio2", "0,nan"], "--tio2: each TiO2 load must be in [0, 100] %"),
        (["--tio2", "a,b"], "--tio2: must be comma-separated numbers"),
    ],
)
def test_cli_bad_grid_exits_2_with_one_line(tmp_path, capsys, flags, message):
    assert main(["polymer", "characterize", "-o", str(tmp_path / "x.csv"), *flags]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert message in err[0]
