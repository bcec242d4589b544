"""Five-angle measurements (Herbert §3.2): the file format, GGX fitted to readings, held out."""

from functools import partial

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.isotropic import brdf_ggx, brdf_ward_isotropic
from reference.materials.multiangle import (
    FIVE_ASPECULAR_DEG,
    aspecular_directions,
    fit_ggx_five_angle,
    five_angle_readings,
    ggx_fit_material,
    read_five_angle_csv,
    write_five_angle_csv,
)

WL = np.arange(400.0, 701.0, 10.0)


def _smooth(rng, low, high):
    """A smooth random spectrum on WL between low and high (a few Gaussian bumps)."""
    bumps = sum(rng.uniform(0, 1) * np.exp(-0.5 * ((WL - c) / 60.0) ** 2)
                for c in rng.uniform(400, 700, 3))  # fmt: skip
    return low + (high - low) * bumps / bumps.max()


def test_the_geometry_is_the_instruments():
    # 45° light; aspecular 45° reads along the normal, 110° on the light's side, 20° from it
    wi, wo = aspecular_directions(FIVE_ASPECULAR_DEG)
    assert np.degrees(np.arccos(wi @ [0, 0, 1])) == pytest.approx(45.0)
    specular = np.array([-wi[0], 0.0, wi[2]])
    angles = np.degrees(np.arccos(np.clip(wo @ specular, -1, 1)))
    np.testing.assert_allclose(angles, FIVE_ASPECULAR_DEG, atol=1e-9)
    assert np.degrees(np.arccos(wo[4] @ wi)) == pytest.approx(20.0)
    assert (wo[:, 1] == 0).all()  # in the plane of incidence


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_ggx_readings_give_back_their_ggx(seed):
    rng = np.random.default_rng(seed)
    rho_d, F_0 = _smooth(rng, 0.02, 0.6), _smooth(rng, 0.05, 0.9)
    alpha = float(rng.uniform(0.05, 0.5))
    m = five_angle_readings(partial(brdf_ggx, rho_d=rho_d, F_0=F_0, alpha=alpha), WL)
    fit = fit_ggx_five_angle(m)
    assert fit.alpha == pytest.approx(alpha, rel=1e-4)
    np.testing.assert_allclose(fit.rho_d, rho_d, rtol=1e-3, atol=1e-5)
    np.testing.assert_allclose(fit.F_0, F_0, rtol=1e-3, atol=1e-5)
    assert fit.relative_error.max() < 1e-5


def test_noisy_readings_fit_within_their_noise():
    rng = np.random.default_rng(9)
    truth = partial(brdf_ggx, rho_d=_smooth(rng, 0.05, 0.4), F_0=_smooth(rng, 0.3, 0.8), alpha=0.2)
    m = five_angle_readings(truth, WL)
    noisy = m.reflectance_factor * (1 + 0.01 * rng.standard_normal(m.reflectance_factor.shape))
    fit = fit_ggx_five_angle(type(m)(m.name, m.illumination_deg, m.aspecular_deg, WL, noisy))
    assert fit.alpha == pytest.approx(0.2, rel=0.05)
    assert fit.relative_error.max() < 0.03  # 1 % noise per reading


def test_a_ward_paint_is_fitted_with_its_error_stated():
    # held out: readings of another model (Ward 1992); GGX cannot match it exactly, and the fit says
    # by how much at each angle
    rng = np.random.default_rng(4)
    truth = partial(brdf_ward_isotropic, rho_d=_smooth(rng, 0.05, 0.3), rho_s=0.08, alpha=0.15)
    m = five_angle_readings(truth, WL)
    fit = fit_ggx_five_angle(m)
    print(f"\nWard as GGX: α {fit.alpha:.3f}, error per angle {np.round(fit.relative_error, 4)}")  # noqa: T201
    assert 0.0 < fit.relative_error.max() < 0.10  # the bound docs/herbert-polymer.md states
    assert (fit.rho_d >= 0).all()
    assert ((fit.F_0 >= 0) & (fit.F_0 <= 1)).all()


def test_the_csv_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(5)
    truth = partial(brdf_ggx, rho_d=_smooth(rng, 0.1, 0.5), F_0=0.5, alpha=0.1)
    m = five_angle_readings(truth, WL, name="red metallic")
    back = read_five_angle_csv(write_five_angle_csv(tmp_path / "red.csv", m))
    assert back.name == "red metallic"
    assert back.illumination_deg == 45.0
    assert np.array_equal(back.aspecular_deg, m.aspecular_deg)
    assert np.array_equal(back.wavelengths_nm, WL)
    assert np.array_equal(back.reflectance_factor, m.reflectance_factor)


def test_the_fit_is_a_scene_material_that_renders(tmp_path):
    import tomllib

    from reference.scene.loader import load_scene
    from reference.scene.render import render_scene

    rng = np.random.default_rng(6)
    m = five_angle_readings(partial(brdf_ggx, rho_d=_smooth(rng, 0.1, 0.5), F_0=0.6, alpha=0.2), WL)
    fit = fit_ggx_five_angle(m)
    material = ggx_fit_material(fit, "paint")
    parsed = tomllib.loads(material)["materials"]["paint"]
    assert parsed["alpha"] == fit.alpha
    assert parsed["rho_d"]["values"] == fit.rho_d.tolist()
    scene = tmp_path / "paint.toml"
    scene.write_text(
        "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\nfov_deg = 32\n"
        "[render]\nwidth = 12\nheight = 12\nsupersample = 1\n"
        + material
        + '[[objects]]\ntype = "sphere"\nmaterial = "paint"\n'
        '[[lights]]\ntype = "point"\nposition = [3, 2, 4]\nspectrum = { illuminant = "D65" }\n'
        "intensity = 25\nattenuation = [0, 0, 1]\n"
    )
    image = render_scene(load_scene(scene)).XYZ
    assert np.isfinite(image).all()
    assert image.max() > 0


@pytest.mark.parametrize(("text", "message"), [
    ("aspecular_deg,400,500\n15,0.1,0.1\n25,0.1,0.1\n45,0.1,0.1\n75,0.1,0.1\n",
     "readings at 15, 25, 45, 75°; a five-angle file needs exactly one row at each of"),
    ("aspecular_deg,400,500\n15,0.1,0.1\n15,0.1,0.1\n25,0.1,0.1\n45,0.1,0.1\n75,0.1,0.1\n"
     "110,0.1,0.1\n", "readings at 15, 15, 25"),
    ("aspecular_deg,400,500\n15,0.1\n", "line 2: 2 columns, the header has 3"),
    ("aspecular_deg,400,500\n15,0.1,-0.2\n", "line 2: reflectance factors must be >= 0"),
    ("aspecular_deg,400,500\n15,0.1,nan\n", "line 2: value: must be finite"),
    ("aspecular_deg,400,500\n15,0.1,1e308\n", "line 2: reflectance factors must be <= 1000"),
    ("aspecular_deg,400\n15,0\n25,0\n45,0\n75,0\n110,0\n", "every reading is below 1e-4"),
    ("aspecular_deg,500,400\n", "line 1: wavelengths must increase"),
    ("angle,400\n", "line 1: the first column must be aspecular_deg"),
    ("# illumination_deg: 95\naspecular_deg,400\n", "illumination_deg: must be in (0, 90)"),
    ("# only comments\n", "no header row"),
])  # fmt: skip
def test_bad_files_are_one_line_naming_the_file(tmp_path, text, message):
    path = tmp_path / "paint.csv"
    path.write_text(text)
    with pytest.raises(SpecrefError) as error:
        read_five_angle_csv(path)
    assert str(error.value).startswith(str(path))
    assert message in str(error.value)
    assert "\n" not in str(error.value)


def test_a_binary_file_is_refused_in_one_line(tmp_path):
    path = tmp_path / "paint.csv"
    path.write_bytes(b"\xff\xfe\x00binary")
    with pytest.raises(SpecrefError, match="cannot read a UTF-8 CSV file"):
        read_five_angle_csv(path)


def test_the_command_fits_a_file_and_writes_a_material(tmp_path, capsys):
    import tomllib

    from validation.cli import main

    rng = np.random.default_rng(8)
    truth = partial(brdf_ggx, rho_d=_smooth(rng, 0.1, 0.4), F_0=_smooth(rng, 0.4, 0.8), alpha=0.18)
    path = write_five_angle_csv(tmp_path / "blue.csv", five_angle_readings(truth, WL, "blue paint"))
    out = tmp_path / "blue.toml"
    assert main(["brdf", "fit", str(path), "-o", str(out)]) == 0
    assert "GGX α 0.18" in capsys.readouterr().out
    material = tomllib.loads(out.read_text())["materials"]["blue_paint"]
    assert material["brdf"] == "ggx"
    assert material["alpha"] == pytest.approx(0.18, rel=1e-4)
    # a name that is not a TOML bare key is made one
    assert main(["brdf", "fit", str(path), "-o", str(out), "--name", 'my "red" paint']) == 0
    assert "my__red__paint" in tomllib.loads(out.read_text())["materials"]
    capsys.readouterr()
    path.write_text("aspecular_deg,400\n15,0.1\n")
    assert main(["brdf", "fit", str(path), "-o", str(tmp_path / "x.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "a five-angle file needs exactly one row at each of" in err
    assert not (tmp_path / "x.toml").exists()
