"""Tests of reference.display.cgats: .cal and .ti3 written and read back, bad files."""

from __future__ import annotations

import numpy as np
import pytest

from reference.display.cgats import read_cal, read_cgats, read_ti3, write_cal, write_ti3
from reference.errors import SpecrefError


def test_cal_round_trip(tmp_path, rng):
    lut = np.sort(rng.uniform(0, 1, (3, 256)), axis=1)
    back = read_cal(write_cal(tmp_path / "d.cal", lut))
    np.testing.assert_allclose(back, lut, rtol=1e-9)


def test_cal_has_argyll_layout(tmp_path):
    # Source: ArgyllCMS cal_format.html: type CAL, DEVICE_CLASS DISPLAY, COLOR_REP RGB and the
    # fields RGB_I RGB_R RGB_G RGB_B.
    path = write_cal(tmp_path / "d.cal", np.tile(np.linspace(0, 1, 256), (3, 1)))
    file_type, keywords, fields, data = read_cgats(path)
    assert file_type == "CAL"
    assert keywords["DEVICE_CLASS"] == "DISPLAY"
    assert keywords["COLOR_REP"] == "RGB"
    assert fields == ["RGB_I", "RGB_R", "RGB_G", "RGB_B"]
    assert data.shape == (256, 4)
    assert 'KEYWORD "DEVICE_CLASS"' in path.read_text()


def test_cal_channels_of_different_lengths(tmp_path):
    path = tmp_path / "short.cal"
    text = write_cal(tmp_path / "ok.cal", np.tile(np.linspace(0, 1, 4), (3, 1))).read_text()
    lines = text.splitlines()
    row = lines.index("BEGIN_DATA") + 3
    lines[row] = " ".join(lines[row].split()[:3])
    path.write_text("\n".join(lines))
    with pytest.raises(SpecrefError, match=r"short.cal: line \d+: 3 values for 4 fields"):
        read_cal(path)


def test_cal_number_of_sets_mismatch(tmp_path):
    path = tmp_path / "bad.cal"
    text = write_cal(tmp_path / "ok.cal", np.tile(np.linspace(0, 1, 4), (3, 1))).read_text()
    path.write_text(text.replace("NUMBER_OF_SETS 4", "NUMBER_OF_SETS 5"))
    with pytest.raises(SpecrefError, match=r"bad.cal: NUMBER_OF_SETS is 5 but there are 4 rows"):
        read_cal(path)


def test_cal_values_out_of_range(tmp_path):
    with pytest.raises(SpecrefError, match=r"x.cal: .cal values must be in \[0, 1\]"):
        read_cal(write_cal(tmp_path / "x.cal", np.full((3, 4), 1.5)))


def test_ti3_round_trip(tmp_path, rng):
    RGB = rng.uniform(0, 1, (20, 3))
    XYZ = rng.uniform(1, 90, (20, 3))
    white = np.array([95.0, 100.0, 108.0])
    back_RGB, back_XYZ = read_ti3(write_ti3(tmp_path / "v.ti3", RGB, XYZ, white))
    np.testing.assert_allclose(back_RGB, RGB, rtol=1e-9)
    np.testing.assert_allclose(back_XYZ, XYZ, rtol=1e-9)  # white Y = 100: unchanged


def test_ti3_is_not_a_cal(tmp_path):
    path = write_ti3(tmp_path / "v.ti3", np.ones((2, 3)), np.ones((2, 3)), np.ones(3))
    with pytest.raises(SpecrefError, match=r"v.ti3: not a .cal file \(type 'CTI3'\)"):
        read_cal(path)
