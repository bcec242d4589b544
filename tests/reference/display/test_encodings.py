import numpy as np
import pytest

from reference.display.encodings import (
    ENCODINGS,
    decode_lstar_Herbert,
    decode_srgb,
    display_to_linear,
    encode_gamma,
    encode_lstar_Herbert,
    encode_srgb,
    linear_to_display,
    to_8bit,
)
from reference.errors import SpecrefError


def test_srgb_matches_iec_formula():
    x = np.linspace(0, 1, 1001)
    # Source: IEC 61966-2-1:1999, the sRGB encoding written out.
    expected = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(encode_srgb(x), expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(decode_srgb(expected), x, rtol=1e-12, atol=1e-15)


def test_lstar_matches_herbert_eq7():
    G = np.arange(256) / 255
    # Source: Eq. (7), Herbert et al., written out: Y = (((G/255)·100 + 16)/116)^3 · Y_max.
    expected = ((G * 100 + 16) / 116) ** 3
    np.testing.assert_allclose(decode_lstar_Herbert(G), expected, rtol=1e-14)
    # Erratum E6: the printed calibration gives (16/116)^3 of peak at G = 0, not 0.
    assert decode_lstar_Herbert(0.0) == pytest.approx((16 / 116) ** 3, rel=1e-14)
    assert encode_lstar_Herbert(0.0) == 0.0


def test_gamma_matches_herbert_eq6():
    G = np.linspace(0, 1, 11)
    # Source: Eq. (6), Herbert et al.: Y/Y_max = (G/255)^Gamma.
    np.testing.assert_allclose(display_to_linear(G, "gamma_1.8"), G**1.8, rtol=1e-14)
    np.testing.assert_allclose(encode_gamma(G**2.2, 2.2), G, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("encoding", ENCODINGS.values(), ids=lambda e: e.name)
def test_encodings_round_trip_and_monotone(encoding):
    lo = decode_lstar_Herbert(0.0) if encoding.name == "lstar" else 0.0
    x = np.linspace(lo, 1, 257)
    encoded = linear_to_display(x, encoding.name)
    assert (np.diff(encoded) > 0).all()
    assert encoded[-1] == pytest.approx(1.0, rel=1e-14)
    np.testing.assert_allclose(display_to_linear(encoded, encoding.name), x, rtol=1e-11, atol=1e-15)


@pytest.mark.parametrize("shape", [(), (5,), (2, 3, 3)])
def test_linear_to_display_shapes_and_clipping(shape):
    x = np.full(shape, 2.0)
    out = linear_to_display(x, "srgb")
    assert out.shape == shape
    np.testing.assert_allclose(out, 1.0, rtol=1e-15)  # colour's sRGB gives 1 - 1e-16 at 1
    assert (linear_to_display(-x, "srgb") == 0.0).all()
    np.testing.assert_allclose(linear_to_display(np.full(shape, 0.5), "linear", exposure=0.5), 0.25)


def test_to_8bit_rounding():
    # Source: round half up of v·255: 0.5·255 = 127.5 -> 128; 1/255·0.49 -> 0.
    assert to_8bit([0.5, 0.49 / 255, 254.5 / 255, 2.0, -1.0]).tolist() == [128, 0, 255, 255, 0]


def test_unknown_encoding():
    with pytest.raises(
        SpecrefError, match=r"unknown encoding 'sRGB'; allowed: gamma_1\.8, gamma_2\.2"
    ):
        linear_to_display([0.5], "sRGB")
