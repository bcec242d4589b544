import subprocess
import sys

import numpy as np
import pytest

from reference.errors import (
    SpecrefError,
    format_allowed,
    require,
    require_between,
    require_choice,
    require_finite,
    require_nonnegative,
    require_positive_int,
)


def test_message_is_always_one_line():
    error = SpecrefError("scene.toml: a:\n  must be\tpositive")
    assert str(error) == "scene.toml: a: must be positive"
    assert isinstance(error, ValueError)


def test_require_survives_python_O():
    code = "from reference.errors import require\nrequire(False, 'x: bad')"
    result = subprocess.run([sys.executable, "-O", "-c", code], capture_output=True, text=True)
    assert result.returncode == 1
    assert "SpecrefError: x: bad" in result.stderr


def test_require_finite_and_nonnegative_name_the_index():
    with pytest.raises(SpecrefError, match=r"k: must be finite, got inf at index \(1, 0\)"):
        require_finite([[0.0, 1.0], [np.inf, 2.0]], "k")
    with pytest.raises(SpecrefError, match=r"k: must be >= 0, got -2.0 at index 2"):
        require_nonnegative([0.0, 1.0, -2.0], "k")
    with pytest.raises(SpecrefError, match="k: must be numbers"):
        require_finite(["a"], "k")
    np.testing.assert_array_equal(require_nonnegative(np.zeros((2, 2)), "k"), np.zeros((2, 2)))
    require(True, "never")


def test_choices_and_ints():
    assert format_allowed({"b", "a"}) == "a, b"
    with pytest.raises(SpecrefError, match="unknown window 'hann'; allowed: gaussian, hanning"):
        require_choice("hann", ["hanning", "gaussian"], "window")
    assert require_positive_int(3.0, "w") == 3
    for bad in (0, -1, 2.5, True, "3", 10**9):
        with pytest.raises(SpecrefError, match=r"w: must be an integer in \[1, 100\]"):
            require_positive_int(bad, "w", maximum=100)


def test_require_between_refuses_all_but_a_real_number_inside_the_open_interval():
    assert require_between(3, "t", 0, 10) == 3.0
    assert require_between(np.float32(0.5), "t", 0, 1) == 0.5
    for bad in (0, 10, -1.0, float("nan"), float("inf"), True, "3", None, [1.0]):
        with pytest.raises(SpecrefError, match=r"^t: must be a number in \(0, 10\), got "):
            require_between(bad, "t", 0, 10)
