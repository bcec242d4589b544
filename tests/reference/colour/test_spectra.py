import numpy as np
import pytest

from reference.colour.spectra import (
    GRID_31,
    GRID_41,
    SpectralGrid,
    make_spectrum,
    resample_spectrum,
    spectrum_constant,
    spectrum_from_csv,
    spectrum_from_dataset,
    spectrum_to_colour_sd,
)
from reference.errors import SpecrefError

# --- grids ----------------------------------------


def test_builtin_grids_values():
    # Source: Herbert et al. §4 (41 bands, 380-780 nm, 10 nm) and the 31-band 400-700 nm convention.
    assert GRID_41.n_bands == 41
    assert GRID_41.wavelengths_nm[0] == 380.0
    assert GRID_41.wavelengths_nm[-1] == 780.0
    assert GRID_31.n_bands == 31
    np.testing.assert_array_equal(GRID_31.wavelengths_nm, np.arange(400.0, 701.0, 10.0))
    assert GRID_41.label == "380-780/10"


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((400, 700, 0), "step_nm: must be > 0"),
        ((700, 400, 10), "end_nm: must be > start_nm"),
        ((400, 705, 10), "must divide"),
        ((400, float("nan"), 10), "end_nm: must be a finite number"),
        ((0, 10000, 0.1), "at most 4096 bands"),
        ((380, 780, 1e308), "must divide"),  # was a grid of one band (brdf convert --step-nm)
    ],
)
def test_grid_bad_input(args, match):
    with pytest.raises(SpecrefError, match=match):
        SpectralGrid(*args)


# --- make_spectrum ----------------------------------------


def test_make_spectrum_values_are_read_only_copies():
    wl = [400.0, 500.0, 600.0]
    s = make_spectrum(wl, [0.1, 0.2, 0.3], "x")
    assert not s.values.flags.writeable
    np.testing.assert_array_equal(s.wavelengths_nm, wl)


@pytest.mark.parametrize(
    ("wl", "values", "kwargs", "match"),
    [
        ([400, 500], [0.1, 0.2, 0.3], {}, "2 wavelengths but 3 values"),
        (
            [400, 500, 450],
            [0.1, 0.2, 0.3],
            {},
            "increase strictly, got 500.0 then 450.0 at index 2",
        ),
        ([400, 400], [0.1, 0.2], {}, "increase strictly"),
        ([400, 500], [0.1, float("nan")], {}, "values must be finite, got nan at 500 nm"),
        ([400, 500], [0.1, float("inf")], {}, "values must be finite"),
        ([400, 500], [-0.1, 0.2], {}, "values must be >= 0, got -0.1 at 400 nm"),
        ([400, float("nan")], [0.1, 0.2], {}, "wavelengths must be finite"),
        ([400], [0.1], {}, "at least 2 samples"),
        ([[400, 500]], [[0.1, 0.2]], {}, "1-D"),
        (["a", "b"], [0.1, 0.2], {}, "must be numbers"),
        ([-5, 500], [0.1, 0.2], {}, "within"),
    ],
)
def test_make_spectrum_bad_input(wl, values, kwargs, match):
    with pytest.raises(SpecrefError, match=match):
        make_spectrum(wl, values, "s", **kwargs)


def test_make_spectrum_allows_negative_when_asked():
    s = make_spectrum([400, 500], [-1.0, 1.0], "basis", allow_negative=True)
    assert s.values[0] == -1.0


def test_spectrum_constant_covers_any_grid():
    s = spectrum_constant(0.25)
    for grid in (GRID_41, GRID_31, SpectralGrid(300, 900, 50)):
        np.testing.assert_array_equal(resample_spectrum(s, grid), np.full(grid.n_bands, 0.25))
    with pytest.raises(SpecrefError, match="constant must be finite and >= 0"):
        spectrum_constant(-1)
    with pytest.raises(SpecrefError, match="constant must be a number"):
        spectrum_constant("grey")


# --- datasets ----------------------------------------


def test_dataset_matches_colour_science():
    import colour

    # Source: colour.SDS_ILLUMINANTS / colour.SDS_COLOURCHECKERS (the data themselves)
    d65 = spectrum_from_dataset("illuminant", "D65")
    np.testing.assert_array_equal(d65.values, colour.SDS_ILLUMINANTS["D65"].values)
    patch = spectrum_from_dataset("colorchecker", "dark skin")
    sd = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]["dark skin"]
    np.testing.assert_array_equal(patch.values, sd.values)
    babel = spectrum_from_dataset("colorchecker", "dark skin", set_name="BabelColor Average")
    assert babel.values.size != patch.values.size or not np.array_equal(babel.values, patch.values)
    assert spectrum_to_colour_sd(d65) is colour.SDS_ILLUMINANTS["D65"]  # keeps its interpolator


@pytest.mark.parametrize(
    ("dataset", "key", "match"),
    [
        ("illuminant", "D66", "unknown illuminant 'D66'; allowed: .*D65"),
        ("colorchecker", "dark skinn", "unknown colorchecker 'dark skinn'"),
        ("paint", "x", "unknown dataset 'paint'; allowed: colorchecker, illuminant, light_source"),
    ],
)
def test_dataset_bad_input(dataset, key, match):
    with pytest.raises(SpecrefError, match=match):
        spectrum_from_dataset(dataset, key)


# --- CSV ----------------------------------------


def test_csv_shared_nix_file(package_data):
    # Source: the file itself (wide Nix export, R400 nm ... R700 nm): the first value, read as text.
    path = package_data / "spectra" / "physicallybased" / "brick__nix_export.csv"
    s = spectrum_from_csv(path)
    np.testing.assert_array_equal(s.wavelengths_nm, np.arange(400.0, 701.0, 10.0))
    text = path.read_text().splitlines()
    header = text[3].split(";")
    first = float(text[4].split(";")[header.index("R400 nm")])
    assert s.values[0] == first
    assert ((s.values > 0) & (s.values < 1)).all()


@pytest.mark.parametrize(
    ("text", "kwargs", "expected"),
    [
        ("nm,R\n400,0.1\n410,0.2\n", {}, [0.1, 0.2]),
        ("400 0.1\n410 0.2\n420 0.4\n", {}, [0.1, 0.2, 0.4]),
        ("# comment\nnm;a;b\n400;1;5\n410;2;6\n", {"column": "b"}, [5.0, 6.0]),
        ("nm\ta\tb\n400\t1\t5\n410\t2\t6\n", {"column": 2}, [5.0, 6.0]),
        ("sep=;\n400;410;420\n0.1;0.2;0.3\n0.4;0.5;0.6\n", {"row": 1}, [0.4, 0.5, 0.6]),
        ("id,400nm,410nm,420nm\nx,10,20,30\n", {"scale": 0.01}, [0.1, 0.2, 0.3]),
    ],
)
def test_csv_layouts(tmp_path, text, kwargs, expected):
    path = tmp_path / "s.csv"
    path.write_text(text)
    np.testing.assert_allclose(spectrum_from_csv(path, **kwargs).values, expected, rtol=1e-15)


@pytest.mark.parametrize(
    ("text", "kwargs", "match"),
    [
        ("nm,R\n400,0.1\n390,0.2\n", {}, "increase strictly"),
        ("nm,R\n400,0.1\n410,abc\n", {}, "line 3: expected numbers"),
        ("# c\n\nnm,R\n400,0.1\n410,x\n", {}, "line 5: expected numbers"),
        ("nm,R\n400,0.1\n410,-0.2\n", {}, "must be >= 0"),
        ("nm,R\n400,0.1\n410,nan\n", {}, "must be finite"),
        ("nm,R\n400,0.1\n410,0.2\n", {"column": "G"}, "'G' is not a header"),
        ("400;410;420\n0.1;0.2;0.3\n", {"row": 3}, r"row: must be in \[0, 0\]"),
        ("\n\n", {}, "empty spectrum file"),
        ("nm,R\n400,0.1\n", {}, "needs at least 2 samples"),
    ],
)
def test_csv_bad_input(tmp_path, text, kwargs, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(SpecrefError, match=match):
        spectrum_from_csv(path, **kwargs)


def test_csv_missing_and_binary(tmp_path):
    with pytest.raises(SpecrefError, match=r"missing\.csv: file not found"):
        spectrum_from_csv(tmp_path / "missing.csv")
    path = tmp_path / "binary.csv"
    path.write_bytes(b"\xff\xfe\x00\x81\x00")
    with pytest.raises(SpecrefError, match=r"binary\.csv"):
        spectrum_from_csv(path)


# --- resampling ----------------------------------------


def test_resample_linear_values(rng):
    wl = np.sort(rng.uniform(350, 800, 30))
    wl[0], wl[-1] = 350.0, 800.0
    values = rng.uniform(0, 1, 30)
    out = resample_spectrum(make_spectrum(wl, values, "r"), GRID_41)
    # Source: piecewise-linear interpolation written out by hand.
    for w, got in zip(GRID_41.wavelengths_nm, out, strict=True):
        i = np.searchsorted(wl, w) - 1
        expected = values[i] + (values[i + 1] - values[i]) * (w - wl[i]) / (wl[i + 1] - wl[i])
        assert got == pytest.approx(expected, rel=1e-13, abs=1e-15)


@pytest.mark.parametrize("interpolation", ["linear", "sprague"])
def test_resample_at_own_nodes_is_identity(rng, interpolation):
    values = rng.uniform(0, 1, 81)
    s = make_spectrum(np.arange(380.0, 781.0, 5.0), values, "5nm")
    out = resample_spectrum(s, GRID_41, interpolation=interpolation)
    np.testing.assert_allclose(out, values[::2], rtol=1e-12, atol=1e-14)


def test_resample_sprague_matches_colour(rng):
    import colour

    values = rng.uniform(0.1, 0.9, 31)
    sd = colour.SpectralDistribution(values, np.arange(400.0, 701.0, 10.0))
    grid = SpectralGrid(400, 700, 5)
    # Source: colour-science's Sprague interpolation (CIE 167:2005).
    expected = sd.copy().interpolate(colour.SpectralShape(400, 700, 5)).values
    s = make_spectrum(sd.wavelengths, values, "s")
    np.testing.assert_allclose(
        resample_spectrum(s, grid, interpolation="sprague"), expected, rtol=1e-12
    )


def test_resample_extrapolation_modes():
    s = make_spectrum([400.0, 410.0, 700.0], [0.2, 0.4, 0.8], "r")
    grid = SpectralGrid(380, 720, 10)
    const = resample_spectrum(s, grid, extrapolation="constant")
    assert const[0] == 0.2
    assert const[1] == 0.2
    assert const[-1] == 0.8
    zero = resample_spectrum(s, grid, extrapolation="zero")
    assert zero[0] == 0.0
    assert zero[-1] == 0.0
    assert zero[2] == 0.2
    linear = resample_spectrum(s, grid, extrapolation="linear")
    # slope below is 0.02 /nm: 390 -> 0.0, 380 -> clipped at 0; above: 0.4/290 per nm
    assert linear[1] == pytest.approx(0.0, abs=1e-15)
    assert linear[0] == 0.0
    assert linear[-1] == pytest.approx(0.8 + 20 * 0.4 / 290, rel=1e-12)


def test_resample_refuses_uncovered_grid_naming_ranges():
    s = spectrum_from_dataset("colorchecker", "dark skin")  # 380-780
    with pytest.raises(SpecrefError, match="covers 380-780 nm but the grid needs 360-780 nm"):
        resample_spectrum(s, SpectralGrid(360, 780, 10))
    with pytest.raises(SpecrefError, match="unknown extrapolation 'nearest'"):
        resample_spectrum(s, GRID_41, extrapolation="nearest")
    with pytest.raises(SpecrefError, match="unknown interpolation 'cubic'"):
        resample_spectrum(s, GRID_41, interpolation="cubic")


def test_resample_shape_and_range_property(rng):
    # Linear interpolation and constant extrapolation never leave the data's range (a bound).
    for _ in range(5):
        values = rng.uniform(0, 1, 12)
        s = make_spectrum(np.linspace(420, 680, 12), values, "r")
        out = resample_spectrum(s, GRID_41, extrapolation="constant")
        assert out.shape == (41,)
        assert values.min() <= out.min()
        assert out.max() <= values.max()
