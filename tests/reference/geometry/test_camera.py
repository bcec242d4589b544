import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.camera import MAX_RESOLUTION, Camera, downsample_box


def test_basis_is_right_handed_orthonormal(rng):
    for _ in range(10):
        eye, target = rng.normal(size=3) * 5, rng.normal(size=3)
        B = Camera(eye=eye, target=target).basis()
        np.testing.assert_allclose(B @ B.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(np.cross(B[0], B[1]), B[2], atol=1e-12)  # x × y = z
        forward = (target - eye) / np.linalg.norm(target - eye)
        np.testing.assert_allclose(-B[2], forward, atol=1e-12)  # looks down -z


def test_perspective_rays_field_of_view():
    cam = Camera(eye=(1, 2, 3), target=(0, 0, 0), fov_deg=60)
    W, H = 9, 7
    o, d = cam.rays(W, H)
    assert o.shape == (H, W, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1, atol=1e-14)
    forward = -cam.basis()[2]
    # Source: pinhole geometry: the ray through raster y has tan(angle) = tan(fov/2)·(1 - 2y/H).
    centre = d[H // 2, W // 2]
    np.testing.assert_allclose(centre, forward, atol=1e-12)
    for j in range(H):
        y = j + 0.5
        expected = np.arctan(np.tan(np.radians(30)) * abs(1 - 2 * y / H))
        angle = np.arccos(np.clip(d[j, W // 2] @ forward, -1, 1))
        assert angle == pytest.approx(expected, abs=1e-12)


def test_orthographic_rays_spacing():
    cam = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=4.0)
    o, d = cam.rays(4, 2)
    np.testing.assert_allclose(d, np.broadcast_to([0, 0, -1], d.shape), atol=1e-15)
    # Source: extent 4 over 2 rows -> 2 units per pixel, centres at ±1; width 4 px at aspect 2.
    np.testing.assert_allclose(o[:, 0, 1], [1.0, -1.0], atol=1e-15)
    np.testing.assert_allclose(o[0, :, 0], [-3.0, -1.0, 1.0, 3.0], atol=1e-15)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_project_inverts_rays(rng, projection):
    cam = Camera(eye=(2, 1, 4), target=(0, 0.2, 0), projection=projection, fov_deg=40, extent=3)
    W, H = 11, 6
    o, d = cam.rays(W, H)
    points = o + rng.uniform(1, 5, (H, W, 1)) * d
    x, y, depth = cam.project(points, W, H)
    np.testing.assert_allclose(x, np.broadcast_to(np.arange(W) + 0.5, (H, W)), atol=1e-10)
    np.testing.assert_allclose(
        y, np.broadcast_to((np.arange(H) + 0.5)[:, None], (H, W)), atol=1e-10
    )
    assert (depth > 0).all()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"fov_deg": 0}, r"fov_deg: must be in \(0, 180\), got 0"),
        ({"fov_deg": 180}, "fov_deg"),
        ({"eye": (0, 0, 0), "target": (0, 0, 0)}, "target: must differ from eye"),
        ({"eye": (0, 5, 0), "target": (0, 0, 0)}, "up: must not be parallel"),
        ({"eye": (1e200, 0, 5), "target": (0, 0, 0)}, r"eye: coordinates must be within ±1e\+09"),
        ({"eye": (0, 0, 5), "target": (0, -1e10, 0)}, r"target: coordinates must be within"),
        ({"eye": (0, float("nan"), 5)}, "eye: must be finite"),
        ({"eye": (0, 5)}, "eye: must be 3 numbers"),
        ({"projection": "fisheye"}, "unknown projection 'fisheye'"),
        ({"projection": "orthographic", "extent": -1}, "extent: must be > 0"),
    ],
)
def test_camera_bad_input(kwargs, match):
    with pytest.raises(SpecrefError, match=match):
        Camera(**kwargs)


@pytest.mark.parametrize("size", [(0, 10), (10, 0), (MAX_RESOLUTION + 1, 10), (2.5, 3), (True, 4)])
def test_rays_refuse_bad_resolution(size):
    with pytest.raises(SpecrefError, match=r"must be an integer in \[1, 16384\]"):
        Camera().rays(*size)


def test_downsample_box(rng):
    image = rng.uniform(size=(6, 9, 2))
    out = downsample_box(image, 3)
    assert out.shape == (2, 3, 2)
    assert out[1, 2, 0] == pytest.approx(image[3:6, 6:9, 0].mean(), rel=1e-14)
    assert downsample_box(image, 1) is image
    with pytest.raises(SpecrefError, match="not a multiple of 4"):
        downsample_box(image, 4)
