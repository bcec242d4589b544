import numpy as np
import pytest

from reference.colour.colorimetry import XYZ_to_Lab, band_weights, spectra_to_XYZ, white_XYZ
from reference.colour.spectra import GRID_41, spectrum_from_dataset
from reference.errors import SpecrefError
from shrm.polymer.characterization import characterize_model
from shrm.polymer.hybrid import polymer_look
from shrm.polymer.tint import DEFAULT_TINT_LIBRARY, read_tint_library, tint_search


def test_shipped_library_holds_the_measured_and_colorchecker_spectra():
    library = read_tint_library()
    assert len(library.names) == 42
    assert sum(n.startswith("pb-") for n in library.names) == 18
    np.testing.assert_array_equal(library.wavelengths_nm, GRID_41.wavelengths_nm)
    # Source: colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"], at the 10 nm nodes
    import colour

    patch = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]["dark skin"]
    expected = patch.copy().align(colour.SpectralShape(380, 780, 10)).values
    np.testing.assert_allclose(library.tint("cc-dark-skin"), expected, atol=5e-7)


@pytest.mark.parametrize("illuminant", ["D65", "A"])
def test_search_finds_an_entry_from_its_own_colour(illuminant):
    library = read_tint_library()
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", illuminant))
    for name in ("pb-lemon", "cc-purple", "cc-neutral-5-(.70-d)"):
        Lab = XYZ_to_Lab(spectra_to_XYZ(library.tint(name), W), white_XYZ(W))
        best, dE = tint_search(Lab, library, illuminant, count=1)[0]
        assert best == name
        assert dE == pytest.approx(0.0, abs=1e-9)


def test_unknown_tint_lists_the_closest_names():
    with pytest.raises(SpecrefError, match="unknown tint 'pb-lemn'; closest: pb-lemon"):
        read_tint_library().tint("pb-lemn")
    with pytest.raises(SpecrefError, match="unknown tint 'lemon'; closest: pb-lemon"):
        polymer_look(characterize_model(), 1.0, 0.1, tint="lemon")


def test_polymer_look_takes_a_tint_by_name():
    look = polymer_look(characterize_model(), 1.0, 0.1, tint="pb-orange")
    np.testing.assert_array_equal(look.Tint_polymer, read_tint_library().tint("pb-orange"))


def test_bad_library_files(tmp_path):
    path = tmp_path / "tints.csv"
    path.write_text("name,source,400,500\nred,me,0.1,1.2\n")
    with pytest.raises(SpecrefError, match=r"row 2 \(red\): values must be in \[0, 1\]"):
        read_tint_library(path)
    path.write_text("name,source,400,500\nred,me,0.1\n")
    with pytest.raises(SpecrefError, match="row 2: 1 values for 2 wavelengths"):
        read_tint_library(path)
    path.write_text("name,source,400,500\nred,me,0.1,0.2\nred,me,0.1,0.2\n")
    with pytest.raises(SpecrefError, match="duplicate name 'red'"):
        read_tint_library(path)
    with pytest.raises(SpecrefError, match="no such tint library"):
        read_tint_library(tmp_path / "none.csv")


def test_shipped_library_is_what_the_script_makes(package_data):
    from validation.precompute.spot_colours import library_text

    assert library_text(package_data) == DEFAULT_TINT_LIBRARY.read_text()
