import subprocess
import sys

import numpy as np
import pytest

from reference.data import data_path
from reference.errors import SpecrefError
from reference.images.formats import read_png
from reference.scene.loader import load_scene, loads_scene
from shrm.orbit import render_orbit, scene_state, turn_camera
from shrm.session import HERBERT_STAGES, RenderSession
from validation.cli import main

ALL = [s.name for s in HERBERT_STAGES]
EXAMPLE = data_path("examples/shrm-orbit.toml")
LATER = ["extract", "gbuffer", "shade"]


def test_turn_camera_is_a_rotation_about_the_target():
    from reference.geometry.camera import Camera

    c = Camera(eye=(1.0, 2.0, 4.0), target=(1.0, 0.0, 0.0))
    # A quarter turn about y through the target: (0, 2, 4) relative becomes (4, 2, 0)
    assert turn_camera(c, np.pi / 2).eye == (5.0, 2.0, 0.0)
    assert turn_camera(c, 2 * np.pi).eye == pytest.approx(c.eye)


def test_orbit_pays_for_creation_once(state, tmp_path):
    session = RenderSession(state)
    times = render_orbit(session, 3, tmp_path, progress=False)
    assert "shrm_create" in times[0]
    assert all(sorted(t) == LATER for t in times[1:])
    assert session.executions["shrm_create"] == 1
    assert session.executions["extract"] == 3
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [
        "frame_000.png",
        "frame_001.png",
        "frame_002.png",
    ]
    header = (tmp_path / "timings.csv").read_text().splitlines()[0]
    assert header == "frame," + ",".join(ALL) + ",total"


def test_cli_orbit_of_the_example_scene(tmp_path, capsys):
    out = tmp_path / "orbit"
    argv = ["shrm", "orbit", str(EXAMPLE), "--frames", "3", "-o", str(out), "--no-cache"]
    assert main(argv) == 0
    assert "wrote 3 frames" in capsys.readouterr().out
    frames = [read_png(out / f"frame_{f:03d}.png") for f in range(3)]
    assert all(f.shape == (64, 64, 3) for f in frames)  # the scene's [render] size
    assert frames[0].max() > 0.2  # the sphere is lit
    assert not np.array_equal(frames[0], frames[1])  # the camera moved
    lines = (out / "timings.csv").read_text().splitlines()
    assert lines[0] == "frame," + ",".join(ALL) + ",total"
    rows = [
        dict(zip(lines[0].split(","), map(float, r.split(",")), strict=True)) for r in lines[1:]
    ]
    # The first frame pays for creation; later frames only for gbuffer, extraction and shading
    assert rows[0]["shrm_create"] > 0
    assert rows[0]["brdf_coeffs"] > 0
    for r in rows[1:]:
        assert {k for k, v in r.items() if v > 0} - {"frame", "total"} == set(LATER)
    assert not list(out.glob("*.tmp*"))  # written atomically: no temporaries left


def test_scene_state_counts_stages(tmp_path):
    state = scene_state(load_scene(EXAMPLE), env_height=16, size=4, F_max=12)
    state["config"].update(width=8, height=8)
    session = RenderSession(state)
    render_orbit(session, 2, progress=False)
    assert session.executions["shrm_create"] == 1
    assert session.executions["extract"] == session.executions["shade"] == 2


SCENE = """
[materials.m]
type = "isotropic_brdf"
{material}
[[objects]]
type = "sphere"
material = "m"
[[lights]]
{light}
"""
ENV = 'type = "environment"\nfile = "sky.exr"'

#: name -> (material lines, light lines, expected message)
BAD_SCENES = {
    "unknown BRDF": ('brdf = "phong"', ENV, "materials.m.brdf: unknown brdf 'phong'; allowed:"),
    "anisotropic BRDF": (
        'brdf = "ward_duer"',
        ENV,
        "materials.m.brdf: must be an analytic isotropic 3-D BRDF; allowed: ",
    ),
    "missing brdf": ("", ENV, "materials.m: missing key 'brdf'"),
    "unknown parameter": (
        'brdf = "ggx"\nroughness = 0.3',
        ENV,
        "materials.m: unknown key 'roughness'; allowed: F_0, alpha, brdf, rho_d, type",
    ),
    "NaN parameter": ('brdf = "ggx"\nalpha = nan', ENV, "materials.m.alpha: must be finite"),
    "point light": (
        'brdf = "ggx"',
        'type = "point"\nposition = [0, 0, 5]',
        "lights: SHRM orbits need one environment light; got point",
    ),
}


@pytest.mark.parametrize("case", BAD_SCENES, ids=list(BAD_SCENES))
def test_bad_scenes_give_one_line_and_exit_2(case, tmp_path, capsys):
    from reference.images.formats import write_exr

    write_exr(tmp_path / "sky.exr", np.ones((8, 16, 3), dtype=np.float32))
    material, light, message = BAD_SCENES[case]
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(material=material, light=light))
    with pytest.raises(SpecrefError, match=message.replace("(", r"\(")):
        scene_state(load_scene(path))
    assert main(["shrm", "orbit", str(path), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert message in err[0]


def test_cli_orbit_refuses_bad_arguments(tmp_path, capsys):
    out = str(tmp_path / "o")
    cases = {
        ("--frames", "0"): "orbit --frames",
        ("--brdf", "ggx"): "--brdf is for the built-in scene, not a scene file",
    }
    for extra, message in cases.items():
        assert main(["shrm", "orbit", str(EXAMPLE), *extra, "-o", out]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, err
        assert message in err[0]
    assert main(["shrm", "orbit", str(tmp_path / "none.toml"), "-o", out]) == 2
    assert "none.toml: file not found" in capsys.readouterr().err


def test_cli_orbit_without_traceback():
    # The installed entry point: exit 2, one line, no traceback
    run = subprocess.run(
        [sys.executable, "-m", "validation.cli", "shrm", "orbit", "nope.toml", "-o", "x"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2
    assert run.stderr.strip().count("\n") == 0
    assert "Traceback" not in run.stderr


def test_loads_scene_reads_spectral_parameters(tmp_path):
    from reference.images.formats import write_exr

    write_exr(tmp_path / "sky.exr", np.ones((8, 16, 3), dtype=np.float32))
    text = SCENE.format(material='brdf = "lafortune"\nn = 12', light=ENV)
    scene = loads_scene(text, "s.toml", base_dir=tmp_path)
    m = scene.materials[0]
    assert m.params["n"].shape == (41,)
    assert (m.params["n"] == 12.0).all()
    assert m.params["rho_s"] == 0.6  # the default, a number


def _maps(tmp_path) -> dict:
    import imageio.v3 as iio

    from reference.images.formats import write_exr

    nan = np.ones((16, 32, 3), dtype=np.float32)
    nan[2, 3, 1] = np.nan
    iio.imwrite(tmp_path / "grey16.png", np.zeros((16, 32), np.uint16))
    iio.imwrite(tmp_path / "png8.png", np.zeros((16, 32, 3), np.uint8))
    return {
        "square": write_exr(tmp_path / "square.exr", np.ones((16, 16, 3), dtype=np.float32)),
        "nan": write_exr(tmp_path / "nan.exr", nan),
        "grey16": tmp_path / "grey16.png",
        "png8": tmp_path / "png8.png",
    }


#: bad arguments of the built-in orbit -> what the one line says; none needs the BRDF's coefficients
BAD_ARGUMENTS = {
    "P below 2": (["--P", "1"], "shrm orbit: --P: must be in [2, 10]"),
    "P above 10": (["--P", "11"], "shrm orbit: --P: must be in [2, 10]"),
    "negative F": (["--F", "-1"], "shrm orbit: --F: must be >= 0"),
    "negative tol": (["--tol", "-1"], "shrm orbit: --tol: must be in (0, 1)"),
    "NaN tol": (["--tol", "nan"], "shrm orbit: --tol: must be in (0, 1)"),
    "tol above 1": (["--tol", "5"], "shrm orbit: --tol: must be in (0, 1)"),
    "square map": (["--env", "{square}"], "square.exr: --env: a lat-long map is 2:1"),
    # a NaN map was refused after two progress lines, naming no file; PNGs were a traceback
    # (16-bit grey) or taken as HDR (8-bit)
    "NaN map": (["--env", "{nan}"], "nan.exr: --env: radiance must be finite and >= 0"),
    "16-bit grey PNG": (["--env", "{grey16}"], "grey16.png: an 8-bit image is not HDR"),
    "8-bit PNG": (["--env", "{png8}"], "png8.png: an 8-bit image is not HDR"),
}


@pytest.mark.parametrize("case", BAD_ARGUMENTS, ids=list(BAD_ARGUMENTS))
def test_orbit_arguments_are_refused_before_any_work(case, tmp_path, capsys):
    extra, message = BAD_ARGUMENTS[case]
    extra = [a.format(**_maps(tmp_path)) for a in extra]
    argv = ["shrm", "orbit", "--quick", "--frames", "2", "--no-cache", *extra]
    assert main([*argv, "-o", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()  # refused before the output folder is made
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    # one line, and no progress bar (or anything else) before it
    assert len(err) == 1, err
    assert err[0].startswith("specref: error: ")
    assert message in err[0], err[0]
    assert "orbit:" not in captured.err.replace("shrm orbit:", "")
    assert captured.out == ""


@pytest.mark.slow
def test_orders_the_brdf_does_not_allow_are_refused_before_the_first_frame(tmp_path, capsys):
    # F beyond what the BRDF's coefficients hold: checked on them (session.prepare), before the
    # first frame's progress line
    argv = ["shrm", "orbit", "--quick", "--frames", "2", "--no-cache", "--F", "500"]
    assert main([*argv, "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "SHRM: F = 500 is outside what tol 0.05 allows" in err[0]


def test_prepare_runs_a_stage_ahead_and_counts_it_in_the_next_frame():
    calls = []

    def first(state, inputs):
        calls.append("first")
        return {"x": np.asarray(float(state["config"]["a"]))}

    def second(state, inputs):
        calls.append("second")
        return {"y": inputs["first"]["x"] + 1.0}

    from shrm.session import Stage

    stages = [
        Stage("first", ("config",), (), first),
        Stage("second", ("gloss",), ("first",), second),
    ]
    session = RenderSession({"config": {"a": 1.0}, "gloss": 2.0}, stages)
    session.prepare("first")
    assert calls == ["first"]
    assert session.frame_times == []
    result = session.render()
    assert calls == ["first", "second"]  # first is not run again
    assert float(result["second"]["y"]) == 2.0
    assert sorted(session.frame_times[0]) == ["first", "second"]
    with pytest.raises(SpecrefError, match="render session: stage"):
        session.prepare("third")


def test_bad_brdf_parameters_are_refused_when_the_scene_loads():
    # before: the BRDF refused alpha < 0 only when shading, in a message without file or key
    from reference.errors import SpecrefError
    from reference.scene.loader import loads_scene

    text = """[camera]
eye = [0.0, 0.0, 6.0]
[materials.glossy]
type = "isotropic_brdf"
brdf = "ggx"
alpha = -1
[[objects]]
type = "sphere"
material = "glossy"
"""
    with pytest.raises(SpecrefError, match=r"^scene.toml: materials.glossy: alpha: must be >= 0"):
        loads_scene(text, "scene.toml")


def test_an_isotropic_brdf_under_a_point_light_is_the_lambert_shader_for_lambert():
    # Source: the Lambert point-light shader of reference.scene.shading (an independent path):
    # brdf = "lambert" with rho_d must give the same XYZ at random points, lights and views.
    from reference.colour.spectra import SpectralGrid
    from reference.materials.types import LambertMaterial
    from reference.scene.lights import PointLight
    from reference.scene.shading import ShadingContext, Surface, shade_lambert_point
    from shrm.orbit import IsotropicBRDFMaterial, shade_isotropic_brdf_point

    rng = np.random.default_rng(3)
    n = rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = rng.normal(size=(50, 3)) + 2 * n
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    surface = Surface(rng.normal(size=(50, 3)) * 0.3, n, v, np.zeros((50, 2)))
    ctx = ShadingContext(SpectralGrid(400.0, 700.0, 10.0))
    rho = np.linspace(0.2, 0.8, ctx.grid.n_bands)
    light = PointLight((1.0, 2.0, 3.0), intensity=2.0, attenuation=(0.0, 0.0, 1.0))
    ours = shade_isotropic_brdf_point(
        surface, IsotropicBRDFMaterial("lambert", {"rho_d": rho}), light, ctx
    )
    np.testing.assert_allclose(
        ours, shade_lambert_point(surface, LambertMaterial(rho), light, ctx), rtol=1e-12, atol=1e-15
    )


def test_a_ggx_sphere_under_a_sphere_light_is_the_monte_carlo_integral_over_its_surface():
    # Brute force, independent of the cone quadrature: points sampled uniformly on the light's
    # half facing the points (pdf 1 / 2πr²), each weighed by cos θ_y / |x − y|² (0 where the
    # light faces away), with the BRDF called directly; seeded, within 5 standard errors.
    from reference.colour.spectra import SpectralGrid, spectrum_from_dataset
    from reference.materials.isotropic import brdf_ggx
    from reference.scene.lights import SphereLight
    from reference.scene.shading import SHADERS, ShadingContext, Surface
    from shrm.orbit import IsotropicBRDFMaterial

    rng = np.random.default_rng(11)
    ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0), options={"sphere_light_tol": 1e-6})
    bands = ctx.grid.n_bands
    material = IsotropicBRDFMaterial(
        "ggx", {"rho_d": np.full(bands, 0.1), "F_0": np.linspace(0.5, 1, bands), "alpha": 0.15}
    )
    # five surface points: facing the light, oblique, and with the light across the horizon
    normals = np.array([[0, 0, 1.0], [0.3, 0, 1], [1, 0, 0.2], [1, 0, -0.05], [0, 0.6, 1]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    views = normals + np.array([-0.4, 0.0, 0.6])  # each above its surface
    views /= np.linalg.norm(views, axis=1, keepdims=True)
    surface = Surface(np.zeros((5, 3)), normals, views, np.zeros((5, 2)))
    centre, r, L = np.array([1.2, 0.1, 2.5]), 0.8, 3.0
    D65 = spectrum_from_dataset("illuminant", "D65")
    ours = SHADERS.lookup("IsotropicBRDFMaterial/SphereLight").reference(
        surface, material, SphereLight(tuple(centre), r, D65, L), ctx
    )
    n = 200_000
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    u *= np.where(u @ centre > 0, -1.0, 1.0)[:, None]  # the half facing the points: pdf 1 / 2πr²
    delta = centre + r * u  # from the surface points (all at the origin) to the samples
    dist2 = np.sum(delta**2, axis=1)
    wi = delta / np.sqrt(dist2)[:, None]
    cos_y = np.maximum(-np.sum(u * wi, axis=1), 0.0)
    samples = []
    for i in range(5):
        cos_x = np.maximum(wi @ normals[i], 0.0)
        f = brdf_ggx(wi, views[i], normals[i], **material.params)
        # L_o = L ∫ f cos θ_x cos θ_y / |x − y|² dA, in the scene's units (π f cos: Y = 1 for a
        # white diffuser facing a unit light), dA sampled with pdf 1 / 2πr²
        integrand = (f * (cos_x * cos_y / dist2 * 2 * np.pi * r**2)[:, None]) @ ctx.weights(D65)
        samples.append(L * integrand)
    samples = np.stack(samples)
    mean, stderr = samples.mean(axis=1), samples.std(axis=1, ddof=1) / np.sqrt(n)
    assert (np.abs(ours - mean) <= 5 * stderr + 1e-9).all()
    # the test can fail: a 2 % error of the integral is over 5 standard errors everywhere
    assert ours[3, 1] > 0
    assert (stderr < 0.004 * ours).all()
