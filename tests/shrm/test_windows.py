import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images.formats import read_hdr
from shrm.transform import project_latlong, synthesize_latlong
from shrm.windows import apply_window, parse_window, ringing_statistics, window_gaussian


def test_windows_and_ringing(package_data):
    # The default Gaussian window (σ = π/L) leaves no negative pixel on venice_sunset at L = 100;
    # the plain truncation rings below zero.
    image = read_hdr(package_data / "environments" / "venice_sunset_1k.hdr")
    c = project_latlong(image, 100, backend="ducc0")
    none = ringing_statistics(synthesize_latlong(c, 512, backend="ducc0"))
    gauss = ringing_statistics(
        synthesize_latlong(apply_window(c, "gaussian"), 512, backend="ducc0")
    )
    assert none["negative_share"] > 0.01
    assert gauss["negative_share"] == 0.0
    assert window_gaussian(100)[1] == pytest.approx(np.exp(-((np.pi / 100) ** 2)))
    with pytest.raises(SpecrefError, match="unknown window"):
        parse_window("hamming")
    with pytest.raises(SpecrefError, match="no parameter"):
        parse_window("hanning:3")
