import numpy as np
import pytest

from reference.camera import Camera
from reference.cubemap import (
    CUBEMAP_METHODS,
    cubemap_lookup_bilinear,
    cubemap_texel_solid_angles,
    cubemap_to_latlong,
    latlong_to_cubemap,
)
from reference.gbuffer import render_gbuffer
from reference.geometry import Sphere
from reference.images import read_hdr, write_exr
from reference.lights import EnvironmentLight
from reference.materials import LambertMaterial, PhongMaterial
from reference.shading import ShadingContext, shade_gbuffer
from reference.spectra import GRID_41
from reference.upsampling import RGB_to_spectra
from shrm.sh import sh_evaluate, synthesize_latlong
from validation.cli import main


def test_cube_solid_angles_sum_and_twins(rng):
    assert abs(cubemap_texel_solid_angles(16).sum() - 4 * np.pi) < 1e-12
    for method in CUBEMAP_METHODS.values():
        args = method.example_inputs(rng)
        if method.name == "gather_bilinear":
            out = np.empty((args[1].shape[1], args[0].shape[1]))
            method.kernel(args[0], args[1], args[2], out)
        else:
            out = method.reference(*args, backend="numba")
        np.testing.assert_allclose(out, method.reference(*args), rtol=1e-12, atol=1e-14)


def test_cube_lookup_second_order_and_round_trip(rng):
    # Band-limited content (L = 6): the lookup converges; inside faces bilinear is second order, the
    # re-projected taps across face edges are first order, so the max error falls at least 2x.
    c = rng.normal(size=(1, 49))
    d = rng.normal(size=(500, 3))
    exact = sh_evaluate(c, d / np.linalg.norm(d, axis=-1, keepdims=True))
    fine = synthesize_latlong(c, 512)
    errors = [
        np.abs(cubemap_lookup_bilinear(latlong_to_cubemap(fine, S), d) - exact).max()
        for S in (32, 64, 128)
    ]
    assert errors[0] / errors[1] > 2.0
    assert errors[1] / errors[2] > 2.0
    back = cubemap_to_latlong(latlong_to_cubemap(fine, 128), 512)
    assert np.sqrt(np.mean((back - fine) ** 2)) < 1e-2 * np.abs(fine).max()


def test_upsampling_white_is_flat():
    S = RGB_to_spectra(np.array([[3.0, 3.0, 3.0]]), GRID_41)
    np.testing.assert_allclose(S, 3.0, rtol=1e-4)


def test_environment_shaders_frequency_vs_bruteforce(shared_data):
    image = read_hdr(shared_data / "environments" / "studio_small_03_1k.hdr")[::8, ::8].copy()
    env = EnvironmentLight(image, name="studio")
    g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 5)), 12, 12)
    k = np.linspace(0.2, 0.8, 41)
    for material in (LambertMaterial(k), PhongMaterial(k, 0.5 * k, np.full(41, 20.0))):
        fast = shade_gbuffer(g, [material], [env], ShadingContext())
        brute = shade_gbuffer(
            g, [material], [env], ShadingContext(options={"environment": "bruteforce"})
        )
        # Tolerance: the adaptive order's tail (1e-2 relative L2 of the kernel) plus cube lookups.
        assert np.abs(fast - brute).max() <= 0.03 * brute.max()


def test_cli_project_and_prefilter(tmp_path, shared_data):
    env = shared_data / "environments" / "studio_small_03_1k.hdr"
    assert (
        main(
            [
                "sh",
                "project",
                str(env),
                "--order",
                "8",
                "--window",
                "hanning",
                "-o",
                str(tmp_path / "c.npz"),
            ]
        )
        == 0
    )
    data = np.load(tmp_path / "c.npz")
    assert data["coeffs"].shape == (3, 81)
    assert (
        main(
            [
                "sh",
                "prefilter",
                str(env),
                "--kernel",
                "lambert",
                "--out",
                str(tmp_path / "cube.exr"),
                "--size",
                "8",
            ]
        )
        == 0
    )
    assert (tmp_path / "cube.exr").is_file()


@pytest.mark.parametrize(
    "argv",
    [
        ["sh", "project", "/nonexistent.hdr", "--order", "4", "-o", "x.npz"],
        ["sh", "project", "ENV", "--order", "-1", "-o", "x.npz"],
        ["sh", "project", "ENV", "--order", "4", "--window", "hamming", "-o", "x.npz"],
        ["sh", "prefilter", "ENV", "--kernel", "ward", "--out", "x.exr"],
        ["sh", "prefilter", "SQUARE", "--kernel", "lambert", "--out", "x.exr"],
        ["sh", "prefilter", "NEG", "--kernel", "lambert", "--out", "x.exr"],
    ],
)
def test_cli_bad_input_exit_2(argv, tmp_path, shared_data, capsys):
    write_exr(tmp_path / "square.exr", np.ones((8, 8, 3)))
    write_exr(tmp_path / "neg.exr", -np.ones((8, 16, 3)))
    mapping = {
        "ENV": str(shared_data / "environments" / "studio_small_03_1k.hdr"),
        "SQUARE": str(tmp_path / "square.exr"),
        "NEG": str(tmp_path / "neg.exr"),
        "x.npz": str(tmp_path / "x.npz"),
        "x.exr": str(tmp_path / "x.exr"),
    }
    assert main([mapping.get(a, a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("specref: error:")
    assert "Traceback" not in err
