"""Tests of the environment order study (validation.studies.env_accuracy) and of shrm.accuracy
against the
brute-force oracle, on every shipped environment and on synthetic worst cases (erratum E75)."""

from __future__ import annotations

import numpy as np
import pytest

from reference.images.formats import write_exr
from reference.scene.loader import loads_scene
from reference.scene.metadata import DEFAULT_ACCURACY, MAX_FACTOR
from validation.studies.env_accuracy import (
    SRGB_Y,
    error_by_order,
    fibonacci_directions,
    render_against_oracle,
    sphere_scene_toml,
    worst_case_maps,
)

ENVIRONMENTS = (
    "StageEnvLatLong.exr",
    "st_fagans_interior_1k.hdr",
    "studio_small_03_1k.hdr",
    "venice_sunset_1k.hdr",
)
MEASURED = 'type = "lambert"\nk_d = { csv = "%s", row = 0, extrapolation = "constant" }'


@pytest.mark.slow  # a 1k map through the default path and the oracle: 5-20 s
@pytest.mark.parametrize("name", ENVIRONMENTS)
def test_default_render_meets_the_promised_bound_on_shipped_environments(package_data, name):
    # Source: brute force (specref render --oracle, the per-pixel angular integral). The default
    # path promises 0.5 % mean and 2 % max relative error of Y over lit pixels; before erratum E75
    # (order from the kernel's tail alone, 14) studio_small_03 was 1.8 % mean, 26 % max off.
    scene = loads_scene(sphere_scene_toml(package_data / "environments" / name, size=10))
    found = render_against_oracle(scene)
    assert found["mean"] <= DEFAULT_ACCURACY
    assert found["max"] <= MAX_FACTOR * DEFAULT_ACCURACY
    (choice,) = found["records"]["environment"].values()
    assert choice["tol_mean"] == DEFAULT_ACCURACY
    assert choice["met"]


@pytest.mark.slow  # a 1k map through the default path and the oracle: 5-20 s
def test_default_render_meets_the_bound_for_a_measured_reflectance(package_data):
    # Source: brute force. A measured brick reflectance (held-out: the order estimate reads only
    # the light) under the environment that broke the old default.
    brick = package_data / "spectra" / "physicallybased" / "brick__nix_export.csv"
    text = sphere_scene_toml(
        package_data / "environments" / "studio_small_03_1k.hdr", MEASURED % brick, size=10
    )
    found = render_against_oracle(loads_scene(text))
    assert found["mean"] <= DEFAULT_ACCURACY
    assert found["max"] <= MAX_FACTOR * DEFAULT_ACCURACY


@pytest.mark.slow  # a 1k map through the default path and the oracle: 5-20 s
def test_phong_environment_path_meets_the_bound(package_data):
    # Source: brute force. The Phong-prefiltered maps choose their order by the same rule.
    material = 'type = "phong"\nk_d = 0.3\nk_s = 0.5\nn = 40'
    text = sphere_scene_toml(package_data / "environments" / "studio_small_03_1k.hdr", material, 10)
    found = render_against_oracle(loads_scene(text))
    assert found["mean"] <= DEFAULT_ACCURACY
    assert found["max"] <= MAX_FACTOR * DEFAULT_ACCURACY
    kernels = {c["kernel"] for c in found["records"]["environment"].values()}
    assert kernels == {"lambert", "phong:40"}


@pytest.mark.slow  # a 1k map through the default path and the oracle: 5-20 s
@pytest.mark.parametrize("name", ["single texel", "sun disc"])
def test_worst_cases_meet_the_bound_in_a_render(tmp_path, name):
    # Source: brute force, on synthetic maps where the energy sits in a texel or a small disc.
    path = write_exr(tmp_path / "map.exr", worst_case_maps(128)[name])
    found = render_against_oracle(loads_scene(sphere_scene_toml(path, size=10)))
    assert found["mean"] <= DEFAULT_ACCURACY
    assert found["max"] <= MAX_FACTOR * DEFAULT_ACCURACY


@pytest.mark.parametrize("name", ["single texel", "sun disc"])
def test_chosen_order_meets_the_bound_at_held_out_directions(name):
    # Source: brute force (shrm.prefilter.prefilter_bruteforce) at Fibonacci directions the
    # estimate never saw (it measures on a lat-long grid).
    Y = worst_case_maps(128)[name] @ SRGB_Y
    directions = fibonacci_directions(400)
    chosen = error_by_order(Y, "lambert", [14], directions)["chosen"]
    assert chosen["measured_mean"] <= DEFAULT_ACCURACY
    assert chosen["measured_max"] <= MAX_FACTOR * DEFAULT_ACCURACY
    assert chosen["exact_texels"] >= 1
    # SH alone at the old default order (14, the kernel's tail alone) does not come close
    alone = error_by_order(Y, "lambert", [14], directions, split=False)
    assert alone["max"][alone["orders"].index(14)] > 5 * MAX_FACTOR * DEFAULT_ACCURACY


def test_worst_case_maps_carry_ten_times_the_sky_power():
    # Source: closed form: the source's power is 10× the sky's, by construction of the map.
    from reference.geometry.envmap import latlong_pixel_solid_angles

    H = 64
    for image in worst_case_maps(H).values():
        omega = latlong_pixel_solid_angles(H, 2 * H)
        Y = image[..., 0]
        sky = Y <= 0.075 + 1e-12
        assert np.sum((Y * omega)[~sky]) == pytest.approx(10.0 * np.sum((Y * omega)[sky]), rel=0.05)
