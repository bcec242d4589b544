import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.types import MATERIAL_TYPES, LambertMaterial, PhongMaterial, make_material


def test_phong_material_defaults_and_read_only():
    m = PhongMaterial(np.full(41, 0.3), np.full(41, 0.5), np.full(41, 20.0))
    np.testing.assert_array_equal(m.k_a, np.zeros(41))
    assert m.n_bands == 41
    assert not m.k_s.flags.writeable


@pytest.mark.parametrize(
    ("params", "match"),
    [
        (
            {"k_d": np.ones(4), "k_s": np.ones(4), "n": -np.ones(4)},
            r"gold\.n: must be >= 0, got -1",
        ),
        ({"k_d": np.ones(4), "k_s": np.ones(3), "n": np.ones(4)}, "has 3 bands but the grid has 4"),
        ({"k_d": np.ones(4), "k_s": [np.nan] * 4, "n": np.ones(4)}, r"k_s: must be finite"),
        ({"k_d": np.ones(4), "k_s": np.ones(4)}, "a phong material needs 'n'"),
        ({"k_d": np.ones(4), "k_s": np.ones(4), "n": 1, "q": 1}, "unknown key 'q'"),
        (
            {"k_d": np.ones((2, 2)), "k_s": np.ones(4), "n": np.ones(4)},
            r"must be a spectrum \(1-D\)",
        ),
    ],
)
def test_make_material_bad_input(params, match):
    with pytest.raises(SpecrefError, match=match):
        make_material("phong", params, "gold")


def test_registry_drives_construction():
    assert MATERIAL_TYPES.names()[:2] == ["lambert", "phong"]
    m = make_material("lambert", {"k_d": np.full(31, 0.2)}, "grey")
    assert isinstance(m, LambertMaterial)
    with pytest.raises(
        SpecrefError, match=r"unknown material type 'metal'; allowed: .*lambert, phong"
    ):
        make_material("metal", {}, "x")
