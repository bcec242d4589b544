import re

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.scene.colorchecker import colorchecker_material
from reference.scene.lights import PointLight, SphereLight
from reference.scene.loader import loads_scene
from reference.scene.render import render_scene
from reference.scene.shading import SHADERS, ShadingContext, Surface
from reference.scene.sphere_light import (
    DEFAULT_TOLERANCE,
    MAX_ORDER,
    sphere_light_irradiance_closed_form,
    sphere_light_quadrature,
    sphere_light_shader,
)


def _surface(normals, positions=None) -> Surface:
    normals = np.asarray(normals, dtype=np.float64)
    positions = np.zeros_like(normals) if positions is None else positions
    return Surface(positions, normals, normals, np.full((len(normals), 2), 0.05))


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_the_weights_are_the_visible_solid_angle(rng):
    # Source: closed forms: a cone of half-angle σ has 2π(1 − cos σ) sr; a horizon through its
    # axis leaves half (symmetry); a cone wholly below the horizon, none.
    centre, r = np.array([0.0, 0.0, 4.0]), 1.0
    cos_sigma = np.sqrt(1 - (r / 4) ** 2)
    x = np.zeros((3, 3))
    normals = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    directions, w = sphere_light_quadrature(centre, r, x, normals, 6)
    cone = 2 * np.pi * (1 - cos_sigma)
    np.testing.assert_allclose(w.sum(axis=0), [cone, cone / 2, 0.0], rtol=1e-13, atol=1e-15)
    # every direction is a unit vector inside the cone and above the horizon where it is weighed
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1, rtol=1e-13)
    inside = directions @ (centre / 4) >= cos_sigma - 1e-12
    above = np.einsum("kni,ni->kn", directions, normals) >= -1e-12
    assert (inside | (w == 0)).all()
    assert (above | (w == 0)).all()


def test_a_point_inside_the_light_receives_nothing():
    x = np.array([[0.0, 0.0, 0.5]])
    _, w = sphere_light_quadrature((0.0, 0.0, 0.0), 1.0, x, [[0.0, 0.0, 1.0]], 4)
    assert (w == 0).all()


@pytest.mark.parametrize("sin_sigma", [0.05, 0.2, 0.6, 0.95])
def test_lambert_irradiance_is_snyders_closed_form_horizon_included(rng, sin_sigma):
    # Source: Snyder 1996 (MSR-TR-96-11), the sphere-to-differential-area form factor, written
    # out in sphere_light_irradiance_closed_form and checked here against its limits first.
    assert sphere_light_irradiance_closed_form(1.0, sin_sigma) == pytest.approx(
        np.pi * sin_sigma**2, rel=1e-15
    )
    # the normals: random, and one with the centre on the horizon (half the cone below it)
    normals = np.concatenate([_unit(rng, 400), [[1.0, 0.0, 0.0]]])
    d = 1.0 / sin_sigma
    light = SphereLight((0.0, 0.0, d), 1.0, intensity=1.0)
    white = LambertMaterial(np.ones(41))
    Y = sphere_light_shader(SHADERS.lookup("LambertMaterial/PointLight").reference)(
        _surface(normals), white, light, ShadingContext(options={"sphere_light_tol": 1e-7})
    )[:, 1]
    # a white diffuser: Y = E / (π L_e) with the light's radiance Y = 1
    expected = sphere_light_irradiance_closed_form(normals[:, 2], sin_sigma) / np.pi
    np.testing.assert_allclose(Y, expected, rtol=0, atol=2e-6 * sin_sigma**2)


def test_the_adaptive_order_meets_its_tolerance_and_records_it(rng):
    normals = _unit(rng, 2000)
    light = SphereLight((0.0, 0.0, 3.0), 0.7, intensity=2.0)
    grey = LambertMaterial(np.full(41, 0.4), name="grey")
    for tol in (1e-2, 1e-4):
        ctx = ShadingContext(options={"sphere_light_tol": tol})
        Y = sphere_light_shader(SHADERS.lookup("LambertMaterial/PointLight").reference)(
            _surface(normals), grey, light, ctx
        )[:, 1]
        expected = 2.0 * 0.4 * sphere_light_irradiance_closed_form(normals[:, 2], 0.7 / 3) / np.pi
        # the change between the last two orders bounds the error (the rule converges fast)
        white = 2.0 * (0.7 / 3) ** 2
        assert np.abs(Y - expected).max() <= tol * white
        record = ctx.records["sphere_light"]["grey"]
        assert record["largest_change"] <= tol
        assert 2 <= record["highest_order"] <= MAX_ORDER
    # Property: the tighter tolerance needs a higher order.
    loose = ShadingContext(options={"sphere_light_tol": 1e-2})
    sphere_light_shader(SHADERS.lookup("LambertMaterial/PointLight").reference)(
        _surface(normals), grey, light, loose
    )
    assert loose.records["sphere_light"]["grey"]["highest_order"] < record["highest_order"]


@pytest.mark.parametrize(
    "material",
    [
        PhongMaterial(np.full(41, 0.3), np.linspace(0.2, 0.6, 41), np.linspace(5, 60, 41)),
        colorchecker_material(),
    ],
    ids=["phong", "colorchecker"],
)
def test_a_small_sphere_is_a_point_light_of_intensity_L_r2(rng, material):
    # Physics: as r -> 0 with L r² fixed, the cone shrinks to the direction of the centre and the
    # sphere light becomes a point light of intensity L r² with 1/d² fall-off (O(r²) apart).
    normals = _unit(rng, 300)
    normals[:, 2] = np.abs(normals[:, 2]) + 0.3  # facing the light
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    positions = rng.uniform(-0.3, 0.3, size=(300, 3))
    views = np.tile([0.0, 0.0, 1.0], (300, 1))
    surface = Surface(positions, normals, views, rng.uniform(0, 1, (300, 2)))
    key = type(material).__name__
    ctx = ShadingContext(options={"sphere_light_tol": 1e-8})
    r = 1e-3
    sphere = SHADERS.lookup(f"{key}/SphereLight").reference(
        surface, material, SphereLight((0.2, 0.1, 3.0), r, intensity=1.5 / r**2), ctx
    )
    point = SHADERS.lookup(f"{key}/PointLight").reference(
        surface, material, PointLight((0.2, 0.1, 3.0), intensity=1.5, attenuation=(0, 0, 1)), ctx
    )
    np.testing.assert_allclose(sphere, point, rtol=1e-5, atol=1e-12)


def test_a_scene_file_names_a_sphere_light_and_its_metadata_says_what_was_done():
    scene = loads_scene(
        """
        [camera]
        eye = [0, 0, 5]
        [render]
        width = 24
        height = 24
        [materials.grey]
        type = "lambert"
        k_d = 0.5
        [[objects]]
        type = "sphere"
        material = "grey"
        [[lights]]
        type = "sphere"
        position = [3, 0, 3]
        radius = 0.5
        intensity = 8
        spectrum = { illuminant = "A" }
        """
    )
    light = scene.lights[0]
    assert isinstance(light, SphereLight)
    assert (light.radius, light.intensity) == (0.5, 8.0)
    result = render_scene(scene)
    record = result.records["sphere_light"]["grey"]
    assert record["largest_change"] <= DEFAULT_TOLERANCE
    # the light is to the right: the sphere's right side is lit, its far left side dark
    assert result.XYZ[12, 15, 1] > 0.05
    assert result.XYZ[12, 7, 1] == 0.0


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("position = [0, 0, 3]", "lights[0]: missing key 'radius'"),
        ("position = [0, 0, 3]\nradius = 0", "lights[0].radius: must be > 0, got 0"),
        ("position = [0, 0, 3]\nradius = -1", "lights[0].radius: must be >= 0, got -1"),
        ('position = [0, 0, 3]\nradius = "big"', "lights[0].radius"),
        ("radius = 1", "lights[0]: missing key 'position'"),
        ("position = [0, 0, 3]\nradius = nan", "lights[0].radius"),
        ("position = [0, 0, 3]\nradius = inf", "lights[0].radius"),
        ("position = [0, nan, 3]\nradius = 1", "lights[0].position"),
        ("position = [0, 0, 3]\nradius = 1\nintensity = -2", "lights[0].intensity: must be >= 0"),
    ],
)
def test_bad_sphere_lights_are_refused_in_one_line(table, message):
    with pytest.raises(SpecrefError, match=re.escape(message)) as error:
        loads_scene(f'[[lights]]\ntype = "sphere"\n{table}\n')
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("tol", [0, -1, 1.5, float("nan"), "tight", True])
def test_a_bad_tolerance_is_refused(tol):
    surface = _surface([[0.0, 0.0, 1.0]])
    ctx = ShadingContext(options={"sphere_light_tol": tol})
    with pytest.raises(SpecrefError, match=r"options\.sphere_light_tol: must be a number in"):
        SHADERS.lookup("LambertMaterial/SphereLight").reference(
            surface, LambertMaterial(np.ones(41)), SphereLight((0, 0, 3.0), 1.0), ctx
        )
