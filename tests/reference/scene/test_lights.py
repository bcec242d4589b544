import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.scene.lights import (
    AmbientLight,
    EnvironmentLight,
    PointLight,
    attenuation_Wang,
    point_light_vectors,
)


def test_attenuation_erratum_min_not_max():
    d = np.array([0.0, 0.5, 1.0, 3.0])
    c = (0.5, 0.25, 0.125)
    # Source: Foley et al. §16.1: f_att = min(1/(c1 + c2 d + c3 d²), 1), written out.
    expected = np.minimum(1 / (0.5 + 0.25 * d + 0.125 * d**2), 1)
    np.testing.assert_allclose(attenuation_Wang(d, *c), expected, rtol=1e-15)
    # Erratum E2: the printed max(...) is never below 1; the implemented value falls off.
    printed = np.maximum(1 / (0.5 + 0.25 * d + 0.125 * d**2), 1)
    assert printed[-1] == 1.0
    assert attenuation_Wang(3.0, *c) < 0.5
    assert (attenuation_Wang(d, *c) <= 1).all()


def test_attenuation_shapes():
    assert attenuation_Wang(2.0).shape == ()
    assert attenuation_Wang(np.ones((2, 3, 4)), 0, 0, 1).shape == (2, 3, 4)


def test_point_light_vectors(rng):
    p = rng.normal(size=(2, 5, 3))
    L, d = point_light_vectors([1.0, 2.0, 3.0], p)
    np.testing.assert_allclose(
        p + d[..., None] * L, np.broadcast_to([1, 2, 3], p.shape), atol=1e-13
    )
    np.testing.assert_allclose(np.linalg.norm(L, axis=-1), 1, rtol=1e-14)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"attenuation": (0, 0, 0)}, "not all 0"),
        ({"attenuation": (1, -1, 0)}, "must be 3 numbers >= 0"),
        ({"intensity": -1.0}, "intensity: must be finite and >= 0"),
        ({"intensity": float("nan")}, "intensity"),
        ({"position": (0, 0)}, "position: must be 3 numbers"),
    ],
)
def test_point_light_bad_input(kwargs, match):
    with pytest.raises(SpecrefError, match=match):
        PointLight(**kwargs)


def test_ambient_light():
    assert AmbientLight(intensity=0.2).intensity == 0.2
    with pytest.raises(SpecrefError, match="intensity"):
        AmbientLight(intensity=-0.2)


def test_environment_light_checks():
    env = EnvironmentLight(np.ones((2, 4, 3)), name="sky.hdr")
    assert not env.is_spectral
    assert not env.image.flags.writeable
    spectral = EnvironmentLight(np.ones((2, 4, 5)), wavelengths_nm=[400, 450, 500, 550, 600])
    assert spectral.is_spectral
    bad = np.ones((2, 4, 3))
    bad[0, 0, 0] = np.nan
    cases = [
        ({"image": np.ones((2, 2, 3))}, "must be 2:1"),
        ({"image": bad}, "must be finite"),
        ({"image": -np.ones((2, 4, 3))}, "must be >= 0"),
        ({"image": np.ones((2, 4, 4))}, "needs 3 channels"),
        ({"image": np.ones((2, 4, 2)), "wavelengths_nm": [500, 400]}, "must increase"),
        ({"image": np.ones((2, 4))}, r"must be \(H, W, C\)"),
    ]
    for kwargs, match in cases:
        with pytest.raises(SpecrefError, match=match):
            EnvironmentLight(name="sky.hdr", **kwargs)
