import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import PRIMITIVES, empty_gbuffer, render_gbuffer
from reference.geometry.shapes import Plane, Sphere

ORTHO = Camera(eye=(0, 0, 10), target=(0, 0, 0), projection="orthographic", extent=3.0)


def test_orthographic_sphere_coverage_and_normals_closed_form():
    W = H = 31
    g = render_gbuffer([Sphere((0, 0, 0), 1.0)], ORTHO, W, H)
    # Source: closed form: pixel centre (x, y) is covered iff x² + y² <= 1, with normal
    # (x, y, sqrt(1 - x² - y²)).
    x = (np.arange(W) + 0.5) / W * 3.0 - 1.5
    y = 1.5 - (np.arange(H) + 0.5) / H * 3.0
    X, Y = np.meshgrid(x, y)
    inside = X**2 + Y**2 <= 1.0
    np.testing.assert_array_equal(g.mask, inside)
    n = np.stack([X, Y, np.sqrt(np.clip(1 - X**2 - Y**2, 0, None))], axis=-1)
    np.testing.assert_allclose(g.normal[inside], n[inside], atol=1e-12)
    np.testing.assert_allclose(g.depth[inside], 10 - n[inside][:, 2], atol=1e-12)
    np.testing.assert_allclose(g.view[inside], np.broadcast_to([0, 0, 1], (inside.sum(), 3)))
    assert (g.material_id[~inside] == -1).all()


def test_depth_compositing_and_ids():
    scene = [
        Plane((0, 0, -1), (0, 0, 1), (1, 0, 0), material=2),
        Sphere((0, 0, 0), 0.5, material=1),
    ]
    g = render_gbuffer(scene, ORTHO, 9, 9)
    assert g.mask.all()
    assert g.object_id[4, 4] == 1
    assert g.material_id[4, 4] == 1
    assert g.object_id[0, 0] == 0
    assert g.material_id[0, 0] == 2
    # Order does not matter: the z-test decides.
    g2 = render_gbuffer(scene[::-1], ORTHO, 9, 9)
    np.testing.assert_array_equal(g2.material_id, g.material_id)


def test_supersampling_shape_and_bad_values():
    g = render_gbuffer([Sphere()], Camera(), 8, 6, supersample=3)
    assert g.shape == (18, 24)
    for bad in (0, 17, 2.0):
        with pytest.raises(SpecrefError, match=r"supersample: must be an integer in \[1, 16\]"):
            render_gbuffer([Sphere()], Camera(), 8, 6, supersample=bad)


def test_unknown_primitive():
    with pytest.raises(SpecrefError, match="unknown primitive 'dict'"):
        render_gbuffer([{"type": "cone"}], Camera(), 4, 4)


def test_registry_and_empty():
    assert {"Sphere", "Plane"} <= set(PRIMITIVES.names())
    g = empty_gbuffer(3, 2)
    assert g.shape == (3, 2)
    assert np.isinf(g.depth).all()


def _whole_image_gbuffer(objects, camera, W, H):
    """The reference: every primitive written over the whole image, composited in order."""
    g = empty_gbuffer(H, W)
    for i, obj in enumerate(objects):
        g.composite(PRIMITIVES.lookup(type(obj).__name__)(obj, camera, W, H, i))
    return g


def test_bands_equal_the_whole_image_and_report_progress(monkeypatch):
    import dataclasses
    import functools
    import io

    import reference.geometry.gbuffer as gbuffer
    from reference.geometry.mesh import uv_sphere_mesh
    from reference.progress import Progress

    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), fov_deg=40)
    mesh = uv_sphere_mesh(12, 24)
    objects = [
        Plane((0, 0, -1), (0, 0, 1), (1, 0, 0), material=2),
        Sphere((1.2, 0, 0.3), 0.5, material=1),
        mesh,
        Sphere((1.2, 0, 0.3), 0.5, material=3),  # the same surface: the first one keeps the pixel
    ]
    expected = _whole_image_gbuffer(objects, camera, 37, 29)
    monkeypatch.setattr(gbuffer, "GBUFFER_BAND_SAMPLES", 37 * 3)  # bands of 3 rows, one of 2
    stream = io.StringIO()
    # a progress that estimates at once: the test's G-buffer takes milliseconds
    monkeypatch.setattr(gbuffer, "Progress", functools.partial(Progress, estimate_after=0.0))
    g = render_gbuffer(objects, camera, 37, 29, progress=stream)
    for f in dataclasses.fields(g):
        np.testing.assert_array_equal(getattr(g, f.name), getattr(expected, f.name), f.name)
    assert (g.material_id == 3).sum() == 0
    assert (g.material_id == 1).any()
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("G-buffer: 29 rows, about")
    assert lines[-1].startswith("G-buffer: done")
