import numpy as np
import pytest

from reference.errors import SpecrefError
from shrm.rotation import rotate_coefficients, rotation_matrix, sh_rotation_blocks
from shrm.sh import sh_evaluate
from shrm.transform import project_latlong


def test_rotation_matches_projection_of_rotated_map_L100(rng):
    # Source: projecting the rotated band-limited map (Fejér-1 exact for 2L < H).
    L, H = 100, 202
    c = rng.normal(size=(1, (L + 1) ** 2)) / (L + 1)
    R = rotation_matrix([0.3, -0.5, 0.8], 2.2)
    from reference.geometry.envmap import latlong_pixel_directions

    d = latlong_pixel_directions(H, 2 * H)
    rotated = project_latlong(sh_evaluate(c, d @ R, backend="ducc0"), L, backend="ducc0")
    assert np.abs(rotate_coefficients(c, R) - rotated).max() < 1e-11


def test_rotation_composes_and_inverts(rng):
    L = 30
    c = rng.normal(size=(2, (L + 1) ** 2))
    R1, R2 = rotation_matrix([1, 2, 3], 1.3), rotation_matrix([-2, 0, 1], 2.9)
    np.testing.assert_allclose(
        rotate_coefficients(rotate_coefficients(c, R2), R1),
        rotate_coefficients(c, R1 @ R2),
        atol=1e-12,
    )
    np.testing.assert_allclose(rotate_coefficients(rotate_coefficients(c, R1), R1.T), c, atol=1e-12)
    for D in sh_rotation_blocks(R1, L):
        np.testing.assert_allclose(D @ D.T, np.eye(D.shape[0]), atol=1e-13)
    with pytest.raises(SpecrefError, match="orthogonal"):
        rotate_coefficients(c, 2 * np.eye(3))
