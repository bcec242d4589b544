"""Settings from a tolerance: the brute force, the pilot's promise and the render's metadata."""

import numpy as np
import pytest

from impastor.horizon import horizon_at_texels, horizon_map
from impastor.multispectral import channels_to_XYZ
from impastor.painting import (
    canvas_materials,
    canvas_pixels,
    impasto_painting,
    lights_visibility,
    painting_scene,
    render_painting,
)
from impastor.point_lights import point_lights_every_pixel
from impastor.settings import (
    BRUTE_FORCE_METHODS,
    FIXED_SETTINGS,
    LIGHT_LADDER,
    PaintingPilot,
    painting_brute_force,
    relative_rms_error,
    render_painting_to_tolerance,
    settings_from_tolerance,
    settings_no_worse_than,
    specular_brute_force_shadowed,
)
from impastor.specular_lighting import specular_brute_force, specular_point_lights
from reference.errors import SpecrefError


@pytest.fixture(scope="module")
def scene():
    # a small held-out painting (seed 71; the ladders and the margin were set on seeds 41-44)
    return painting_scene("A", "hybrid", impasto_painting(64, seed=71), light_resolution=(32, 16))


def test_horizon_at_texels_is_the_map_at_those_texels(rng):
    h = rng.random((24, 24)) * 2e-3
    rows, cols = rng.integers(0, 24, 40), rng.integers(0, 24, 40)
    full = horizon_map(h, 1e-3, 12, 8, "numba")
    for backend in ("numpy", "numba"):
        np.testing.assert_allclose(
            horizon_at_texels(h, 1e-3, rows, cols, 12, 8, backend), full[rows, cols],
            rtol=1e-13, atol=1e-16,
        )  # fmt: skip
    with pytest.raises(SpecrefError, match="rows and cols must be indices"):
        horizon_at_texels(h, 1e-3, [30], [0])


@pytest.mark.parametrize("method", BRUTE_FORCE_METHODS.values(), ids=lambda m: m.name)
def test_brute_force_kernels_agree_with_numpy(method, rng):
    scene, px, horizon = method.example_inputs(rng)  # horizons on every side: shadows
    numpy = method.reference(scene, px, horizon, "numpy")
    kernel = method.reference(scene, px, horizon, "numba")
    np.testing.assert_allclose(kernel, numpy, rtol=1e-12, atol=1e-12 * numpy.max())
    # the horizons shadow part of the light, never add any
    open_sky = method.reference(scene, px, np.zeros_like(horizon), "numba")
    assert (kernel <= open_sky * (1 + 1e-12)).all()
    assert (kernel < 0.99 * open_sky).any()


def test_the_shadowed_specular_brute_force_is_every_light_pixel_shadowed(rng):
    # two other paths: every light pixel a point light shadowed by lights_visibility, and the
    # unshadowed brute force under an open sky
    scene = painting_scene("A", "hybrid", impasto_painting(32, seed=3), light_resolution=(16, 8))
    px = canvas_pixels(scene.painting, 12)
    horizon = rng.uniform(0.3, 1.2, (px.P.shape[0], 9))
    alpha = canvas_materials(scene.painting, scene.spectra, scene.design, px)[2]
    every = point_lights_every_pixel(scene.plane)
    visibility = lights_visibility(horizon, px.P, every)
    shadowed = specular_brute_force_shadowed(scene, px, horizon, "numba", supersample=1)
    as_lights = specular_point_lights(px.P, px.N, px.V, alpha, every, visibility, backend="numba")
    np.testing.assert_allclose(shadowed, as_lights, rtol=1e-10, atol=1e-12 * as_lights.max())
    open_sky = specular_brute_force_shadowed(scene, px, np.zeros_like(horizon), "numba")
    unshadowed = specular_brute_force(px.P, px.N, px.V, alpha, scene.plane, 2, "numba")
    np.testing.assert_allclose(open_sky, unshadowed, rtol=1e-12, atol=1e-14 * unshadowed.max())
    assert (shadowed < 0.9 * open_sky).any()


def test_many_median_cut_lights_converge_to_the_brute_force(scene):
    # Eq. (2), Ferwerda: as N grows the median-cut lights' frame tends to the brute force
    # (with the brute force's own horizon: only the lights' placement differs)
    pilot = PaintingPilot(scene, 16)
    errors = [pilot.error(n, 64, 48, True) for n in LIGHT_LADDER]
    assert errors[-1] < errors[0] / 2
    assert errors[-1] < 0.02


def test_the_pilot_keeps_its_promise_on_the_frame(scene):
    # the chosen settings meet the tolerance on the pilot (400 of the frame's pixels) and on the
    # whole frame, against the same brute force, and cost less than the fixed settings
    pilot = PaintingPilot(scene, 96, pixels=400)
    assert pilot.px.P.shape[0] == 400
    fixed = FIXED_SETTINGS
    for tolerance in (0.02, 0.05):
        chosen = settings_from_tolerance(scene, tolerance, pilot=pilot)
        assert chosen.met
        assert chosen.pilot_error <= tolerance
        assert pilot.cost(
            chosen.n_lights, chosen.n_samples, chosen.n_sectors, chosen.failsafe, chosen.by_group
        ) < pilot.cost(fixed.n_lights, fixed.n_samples, fixed.n_sectors, fixed.failsafe)
        out = render_painting("A", 96, "hybrid", scene.painting, light_resolution=(32, 16),
                              **chosen.render_options())  # fmt: skip
        px = canvas_pixels(scene.painting, 96)
        reference = channels_to_XYZ(painting_brute_force(scene, px), scene.design)
        assert relative_rms_error(out["XYZ"][px.gbuffer.mask], reference) <= tolerance


def test_the_pilots_difference_sigma_is_the_bootstraps(scene):
    # the delta method's standard error of one error minus another, against a paired bootstrap
    # of the pilot's pixels (an independent estimate)
    pilot = PaintingPilot(scene, 96, pixels=400)
    a, b = (16, 16, 12, False, ()), (32, 32, 36, True, ())
    sigma = pilot.difference_sigma(a, b)
    q, p = pilot.pixel_squared_errors(*a), pilot.pixel_squared_errors(*b)
    R = np.sum(pilot.reference**2, axis=-1)
    draws = np.random.default_rng(7).integers(0, q.size, (2000, q.size))
    boot = np.sqrt(q[draws].sum(1) / R[draws].sum(1)) - np.sqrt(p[draws].sum(1) / R[draws].sum(1))
    assert sigma == pytest.approx(np.std(boot), rel=0.25)
    assert pilot.difference_sigma(b, b) == 0.0


def test_no_worse_than_the_fixed_settings_on_the_frame(scene):
    # cheaper than the fixed settings, and on the whole frame no worse (within a twentieth)
    pilot = PaintingPilot(scene, 96, pixels=400)
    fixed = FIXED_SETTINGS
    chosen = settings_no_worse_than(scene, fixed, pilot=pilot)
    assert chosen.baseline == "fixed"
    assert chosen.pilot_error <= chosen.tolerance == pilot.error(32, 32, 36, True)
    assert pilot.cost(
        chosen.n_lights, chosen.n_samples, chosen.n_sectors, chosen.failsafe, chosen.by_group
    ) < pilot.cost(32, 32, 36, True)
    px = canvas_pixels(scene.painting, 96)
    reference = channels_to_XYZ(painting_brute_force(scene, px), scene.design)
    errors = []
    for settings in (fixed, chosen):
        out = render_painting("A", 96, "hybrid", scene.painting, light_resolution=(32, 16),
                              **settings.render_options())  # fmt: skip
        errors.append(relative_rms_error(out["XYZ"][px.gbuffer.mask], reference))
    assert errors[1] <= 1.05 * errors[0]


def test_an_unreachable_tolerance_says_so(scene):
    pilot = PaintingPilot(scene, 16)
    chosen = settings_from_tolerance(scene, 1e-5, pilot=pilot)
    assert not chosen.met
    assert chosen.render_options() == {
        "n_lights": 64, "n_samples": 64, "n_sectors": 48, "failsafe": True, "by_group": None
    }  # fmt: skip
    with pytest.raises(SpecrefError, match=r"--tolerance: must be a relative error in \(0, 1\)"):
        settings_from_tolerance(scene, 0.0, pilot=pilot)


def test_render_to_tolerance_records_its_settings(scene):
    out = render_painting_to_tolerance(
        "A", 32, 0.05, painting=scene.painting, light_resolution=(32, 16)
    )
    settings = out["settings"]
    assert settings["tolerance"] == 0.05
    assert settings["met"]
    assert settings["pilot_error"] <= 0.05
    assert settings["choose_seconds"] > 0
    assert {"n_lights", "n_samples", "n_sectors", "failsafe"} <= set(settings)


def test_without_the_failsafe_the_hybrid_is_its_per_pixel_blend(scene):
    # failsafe=False keeps the per-pixel weights: the fail-safe's choice is all zeros
    from impastor.painting import booth_plane_light
    from impastor.point_lights import point_lights_from_plane
    from impastor.specular_hybrid import specular_hybrid_parts

    px = canvas_pixels(scene.painting, 12)
    plane = booth_plane_light("incandescent", 32, 16)
    lights = point_lights_from_plane(plane, "median_cut", 8)
    alpha = np.full(px.P.shape[0], 0.08)
    off = specular_hybrid_parts(px.P, px.N, px.V, alpha, plane, lights, 8, failsafe=False)
    on = specular_hybrid_parts(px.P, px.N, px.V, alpha, plane, lights, 8)
    assert not off["failsafe"].any()
    np.testing.assert_array_equal(off["point_lights"], on["point_lights"])


def test_the_pilots_pixels_are_a_stratified_sample_of_the_frames():
    from impastor.settings import pilot_pixels

    painting = impasto_painting(64, seed=71)
    frame = canvas_pixels(painting, 128)
    sample = pilot_pixels(painting, 128, count=300)
    n = frame.P.shape[0]
    # every pixel is one of the frame's, one in each run of n / 300 pixels, the same for a seed
    key = {tuple(p): i for i, p in enumerate(map(tuple, frame.P))}
    index = np.array([key[tuple(p)] for p in sample.P])
    runs = (np.arange(301) * n) // 300
    assert ((runs[:-1] <= index) & (index < runs[1:])).all()
    np.testing.assert_array_equal(pilot_pixels(painting, 128, count=300).P, sample.P)
    assert not np.array_equal(pilot_pixels(painting, 128, count=300, seed=1).P, sample.P)


def test_each_alpha_group_takes_its_method(scene):
    # a group's pixels are shaded as its method alone would shade them, the hybrid's fail-safe
    # included (it works per group), with the shadows of the point lights
    from impastor.painting import booth_plane_light
    from impastor.point_lights import point_lights_from_plane
    from impastor.specular_hybrid import alpha_groups, specular_by_alpha_group, specular_hybrid
    from impastor.specular_lighting import specular_fis, specular_point_lights

    px = canvas_pixels(scene.painting, 16)
    plane = booth_plane_light("incandescent", 32, 16)
    lights = point_lights_from_plane(plane, "median_cut", 8)
    n = px.P.shape[0]
    alpha = np.geomspace(0.01, 0.4, n)
    visibility = np.random.default_rng(3).random((n, 8)) > 0.3
    groups = alpha_groups(alpha)
    methods = {int(groups[0]): "fis", int(groups[-1]): "point_lights"}
    args = (px.P, px.N, px.V, alpha, plane, lights, 8, visibility, "numba")
    mixed = specular_by_alpha_group(*args, methods=methods)
    pl = specular_point_lights(px.P, px.N, px.V, alpha, lights, visibility, backend="numba")
    fis = specular_fis(px.P, px.N, px.V, alpha, plane, 8, backend="numba")
    first, last = groups == groups[0], groups == groups[-1]
    np.testing.assert_array_equal(mixed[first], fis[first])
    np.testing.assert_array_equal(mixed[last], pl[last])
    rest = ~(first | last)
    only = specular_hybrid(
        px.P[rest], px.N[rest], px.V[rest], alpha[rest], plane, lights, 8, visibility[rest], "numba"
    )
    np.testing.assert_allclose(mixed[rest], only, rtol=1e-12)
    with pytest.raises(SpecrefError, match="group -3: method must be one of point_lights, fis"):
        specular_by_alpha_group(*args, methods={-3: "brute_force"})
    # a group that is not an integer is refused in one line before the render's work
    with pytest.raises(SpecrefError, match=r"group 'rough': must be an integer \(2 log2 α"):
        render_painting("A", 8, "hybrid", scene.painting, light_resolution=(16, 8),
                        backend="numpy", by_group={"rough": "fis"})  # fmt: skip


def test_the_pilots_error_is_its_pixels_shaded_at_those_settings(scene):
    # the error the descent reads, combined from each method's errors, is the error of shading
    # the pilot's pixels with the chosen groups' methods
    from impastor.painting import shade_canvas

    pilot = PaintingPilot(scene, 48, pixels=300)
    chosen = settings_from_tolerance(scene, 0.05, pilot=pilot)
    assert chosen.by_group, "the groups stayed on the hybrid: nothing to check"
    assert sum(chosen.shares) == pytest.approx(1.0)
    settings = chosen.render_options()
    horizon = pilot.horizons[chosen.n_sectors]
    L, _ = shade_canvas(scene, pilot.px, settings, lambda: horizon, "numba")
    direct = relative_rms_error(channels_to_XYZ(L, scene.design), pilot.reference)
    assert chosen.pilot_error == pytest.approx(direct, rel=1e-9)
