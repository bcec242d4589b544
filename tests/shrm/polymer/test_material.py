"""The ``polymer`` scene material: keys, the shader against closed forms, the map cache, errors."""

import dataclasses

import numpy as np
import pytest

import shrm.environment  # (import shrm registers the polymer material and its shader)
from reference.colour.spectra import SpectralGrid
from reference.errors import SpecrefError
from reference.images.formats import write_exr, write_png
from reference.scene.lights import EnvironmentLight
from reference.scene.loader import loads_scene
from reference.scene.render import render_scene
from reference.scene.shading import ShadingContext, Surface
from shrm.environment import environment_spectral_radiance
from shrm.orbit import IsotropicBRDFMaterial, brdf_params_on_grid, shade_isotropic_brdf_environment
from shrm.polymer.characterization import characterize_model, write_characterization
from shrm.polymer.material import (
    POLYMER_KERNELS,
    PolymerMaterial,
    modulation_at,
    polymer_material_look,
    shade_polymer_environment,
)
from shrm.polymer.tint import read_tint_library

GRID = SpectralGrid(400.0, 700.0, 20.0)


@pytest.mark.parametrize("name", POLYMER_KERNELS.names())
def test_every_shading_kernel_matches_its_reference(name, rng):
    method = POLYMER_KERNELS.lookup(name)
    inputs = method.example_inputs(rng)
    got = method.compiled(*inputs)
    assert np.isfinite(got).all()
    np.testing.assert_allclose(got, method.reference(*inputs), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("case", ["mod per pixel", "no mod, no transparency"])
def test_shading_kernel_matches_reference(case, rng):
    method = POLYMER_KERNELS.lookup("shade_parts")
    parts, look, Mod = method.example_inputs(rng)
    if case != "mod per pixel":
        # the kernel then never reads L and E_effect: poisoned, they must not reach the pixels
        look = dataclasses.replace(look, unscattered=np.zeros_like(look.unscattered))
        Mod = 0.0
        parts = {**parts, "L": np.full_like(parts["L"], np.nan), "E_effect": parts["L"] * np.nan}
    expected = method.reference(parts, look, Mod)
    got = method.compiled(parts, look, Mod)
    assert np.isfinite(got).all()
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-14)


@pytest.fixture
def sky(tmp_path):
    """A uniform white sky of radiance 1 (RGB EXR), 16 × 32."""
    path = tmp_path / "sky.exr"
    write_exr(path, np.ones((16, 32, 3)))
    return path


def scene_text(sky, material: str, extra: str = "") -> str:
    return f"""
[spectral]
start_nm = 400
end_nm = 700
step_nm = 20
[camera]
eye = [0.0, 0.0, 5.0]
projection = "orthographic"
extent = 2.4
[render]
width = 16
height = 16
[materials.p]
type = "polymer"
{material}
{extra}
[[objects]]
type = "sphere"
material = "p"
[[lights]]
type = "environment"
file = "{sky}"
"""


def load(sky, material: str, tmp_path=None, extra: str = ""):
    return loads_scene(scene_text(sky, material, extra), "s.toml", tmp_path or ".")


def test_scene_keys_become_the_material(sky):
    scene = load(
        sky,
        'thickness = 0.9\ntio2 = 0.3\ntint = "pb-orange"\ngloss = 0.7\ngloss_exponent = 20\n'
        'index = 1.5\ntransparency = 0.25\nmirror = "cosine"',
    )
    m = scene.materials[0]
    assert isinstance(m, PolymerMaterial)
    assert (m.thickness_mm, m.tio2_pct, m.gloss, m.gloss_exponent) == (0.9, 0.3, 0.7, 20.0)
    assert (m.index, m.transparency, m.mirror, m.effect) == (1.5, 0.25, "cosine", None)
    # Source: the shipped library, interpolated linearly onto the scene's grid
    library = read_tint_library()
    expected = np.interp(GRID.wavelengths_nm, library.wavelengths_nm, library.tint("pb-orange"))
    np.testing.assert_array_equal(m.tint, expected)


def _one_pixel(normal, view):
    n = np.asarray([normal], dtype=np.float64)
    v = np.asarray([view], dtype=np.float64)
    return Surface(n * 0, n, v / np.linalg.norm(v), np.zeros((1, 2)))


@pytest.mark.parametrize("view", [(0.0, 1.0, 0.0), (1.0, 0.05, 0.0)], ids=["normal", "grazing"])
def test_shader_under_a_uniform_sky_is_the_closed_form(view):
    # Source: under a uniform sky of radiance S(λ) every map is S (the Lambert map is π S, and a
    # normalized lobe integrates to 1), so Eq. (1) is S (D Tint + gloss F_r + Col_trans (1 − F_r))
    ctx = ShadingContext(GRID, options={"environment_size": 8})
    light = EnvironmentLight(np.ones((16, 32, 3)))
    S = environment_spectral_radiance(light, GRID)[0, 0]
    m = PolymerMaterial(0.9, 0.3, tint=np.linspace(0.2, 1.0, GRID.n_bands), gloss=0.6)
    surface = _one_pixel((0.0, 1.0, 0.0), view)
    look = polymer_material_look(m, GRID)
    cos = float(surface.view[0] @ surface.normal[0])
    F = look.fresnel.lookup(cos)
    spectrum = S * (look.D_polymer * look.Tint_polymer + 0.6 * F + look.Col_trans * (1 - F))
    np.testing.assert_allclose(
        shade_polymer_environment(surface, m, light, ctx),
        (spectrum @ ctx.weights(None))[None],
        rtol=1e-6,
    )


def test_the_layered_model_is_selectable_and_shades_its_terms():
    # model = "layered": shrm.polymer.layered's result on the scene's grid, its maps made once
    # per light, index and gloss (a second material of the same gloss shares them)
    from shrm.environment import cached_map_names
    from shrm.polymer.kubelka_munk import polymer_constituents, polymer_K_S
    from shrm.polymer.layered import layered_maps, layered_terms

    ctx = ShadingContext(GRID, options={"environment_size": 8})
    light = EnvironmentLight(np.linspace(0.2, 1.0, 16 * 32 * 3).reshape(16, 32, 3))
    surface = _one_pixel((0.0, 1.0, 0.0), (0.6, 0.8, 0.0))
    m = PolymerMaterial(0.9, 0.3, gloss=0.7, model="layered")
    got = shade_polymer_environment(surface, m, light, ctx)
    constituents = polymer_constituents(GRID)
    K, S = polymer_K_S(constituents, 0.3)
    maps = layered_maps(environment_spectral_radiance(light, GRID), constituents.index, 0.7)
    want = layered_terms(surface.normal, surface.view, maps, K, S, 0.9)["result"]
    np.testing.assert_allclose(got, want @ ctx.weights(None), rtol=1e-12)
    shade_polymer_environment(surface, PolymerMaterial(2.0, 1.0, gloss=0.7, model="layered"),
                              light, ctx)  # fmt: skip
    assert cached_map_names(light).count("layered") == 1
    # a tint is a dye in the slab (erratum E115): the same terms with K' for K, same maps
    from shrm.polymer.kubelka_munk import km_tinted_K

    tint = np.linspace(0.2, 1.0, GRID.n_bands)
    tinted = dataclasses.replace(m, tint=tint)
    got = shade_polymer_environment(surface, tinted, light, ctx)
    from shrm.polymer.oracle import interface_coupling

    K_t = km_tinted_K(K, S, tint, interface_coupling(maps.n, maps.alpha).r_i)
    want = layered_terms(surface.normal, surface.view, maps, K_t, S, 0.9)["result"]
    np.testing.assert_allclose(got, want @ ctx.weights(None), rtol=1e-12)
    assert cached_map_names(light).count("layered") == 1


def test_the_layered_models_tolerance_is_a_render_option_and_its_k_is_recorded():
    # render.options.polymer_fis_tol sets the pilot's ΔL* (erratum E118): a looser tolerance
    # stops the doubling sooner; each choice is kept apart and recorded with its pilot
    from shrm.environment import cached_map_names
    from shrm.polymer.layered import FIS_TOL

    light = EnvironmentLight(np.linspace(0.2, 1.0, 16 * 32 * 3).reshape(16, 32, 3))
    surface = _one_pixel((0.0, 1.0, 0.0), (0.6, 0.8, 0.0))
    m = PolymerMaterial(0.9, 0.3, gloss=0.5, model="layered", name="chip")
    found = {}
    for tol in (FIS_TOL / 8, 20.0):
        ctx = ShadingContext(GRID, options={"environment_size": 8, "polymer_fis_tol": tol})
        shade_polymer_environment(surface, m, light, ctx)
        found[tol] = ctx.records["polymer_layered"]["chip"]
        assert found[tol]["fis_tol"] == tol
    assert found[20.0]["samples"] < found[FIS_TOL / 8]["samples"], found
    assert found[20.0]["met"]
    assert cached_map_names(light).count("layered") == 2


def test_effect_term_is_the_effect_pigment_through_its_shrm():
    # Source: Eq. (1) with Tint 0 and Mod_effect 1 is E_effect plus the surface and transmission
    # terms, which do not depend on Mod_effect; E_effect alone is what the isotropic_brdf shader
    # (shrm.orbit, its own SHRM) renders for the same BRDF.
    rng = np.random.default_rng(5)
    grid = SpectralGrid(440.0, 680.0, 80.0)  # 4 bands: the SHRM's cost is per band
    ctx = ShadingContext(grid, options={"environment_size": 8})
    light = EnvironmentLight(rng.uniform(0.2, 2.0, (16, 32, 3)))
    n = rng.normal(size=(6, 3))
    n[:, 2] = np.abs(n[:, 2]) + 1.0
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = np.tile([0.0, 0.0, 1.0], (6, 1))
    surface = Surface(n * 0, n, v, np.zeros((6, 2)))
    effect = IsotropicBRDFMaterial("ggx", brdf_params_on_grid("ggx", grid))
    with_effect = PolymerMaterial(tint=0.0, effect=effect, modulation=1.0)
    without = PolymerMaterial(tint=0.0, effect=effect, modulation=0.0)
    difference = shade_polymer_environment(surface, with_effect, light, ctx) - (
        shade_polymer_environment(surface, without, light, ctx)
    )
    # The isotropic_brdf shader chooses its SHRM settings from a tolerance (errata E91, E92: SH +
    # angular split); the effect term uses the fixed preview SHRM (E60): they agree to the
    # preview's error.
    expected = shade_isotropic_brdf_environment(surface, effect, light, ctx)
    np.testing.assert_allclose(difference, expected, rtol=1e-2, atol=1e-12)


def test_equal_gloss_exponents_share_one_prefiltered_map(sky, tmp_path, monkeypatch):
    # Two materials with exponent 20 and one with 50: the Lambert map once, the Phong maps twice
    calls = []
    original = shrm.environment.prefilter_coefficients

    def counting(coeffs, Lambda):
        calls.append(Lambda.shape)
        return original(coeffs, Lambda)

    monkeypatch.setattr(shrm.environment, "prefilter_coefficients", counting)
    text = scene_text(sky, "gloss_exponent = 20").replace(
        "[[objects]]",
        '[materials.q]\ntype = "polymer"\ngloss_exponent = 20\ntio2 = 1.0\n'
        '[materials.r]\ntype = "polymer"\ngloss_exponent = 50\n'
        '[[objects]]\ntype = "sphere"\nmaterial = "q"\ncenter = [-0.7, 0.0, 0.0]\nradius = 0.4\n'
        '[[objects]]\ntype = "sphere"\nmaterial = "r"\ncenter = [0.7, 0.0, 0.0]\nradius = 0.4\n'
        "[[objects]]",
        1,
    )
    scene = loads_scene(text, "s.toml", tmp_path)
    result = render_scene(scene)
    assert set(np.unique(result.gbuffer.material_id)) == {-1, 0, 1, 2}
    assert len(calls) == 3
    render_scene(scene, gbuffer=result.gbuffer)  # a second frame: every map from the cache
    assert len(calls) == 3


def test_characterization_file_between_grid_points(sky, tmp_path):
    ch = characterize_model(thickness_mm=(0.5, 1.0, 2.0), tio2_pct=(0.0, 0.5, 1.0), grid=GRID)
    write_characterization(tmp_path / "chips.csv", ch)
    scene = load(sky, 'characterization = "chips.csv"\nthickness = 0.8\ntio2 = 0.25', tmp_path)
    look = polymer_material_look(scene.materials[0], GRID)
    chip = ch.lookup(0.8, 0.25)
    # Source: the file's own look-up (PCHIP, E37) on the same grid; D_polymer removes k_1 (E31)
    np.testing.assert_allclose(look.Col_trans, chip["transmittance"], atol=1e-6)
    assert 0.0 < look.D_polymer.min() < look.D_polymer.max() < chip["over_black"].max()
    with pytest.raises(SpecrefError, match=r"s.toml: materials.p.thickness: must be in \[0.5, 2\]"):
        load(sky, 'characterization = "chips.csv"\nthickness = 3.0', tmp_path)


def test_modulation_image_is_looked_up_by_uv(sky, tmp_path):
    # Source: bilinear interpolation by hand between texel centres 0.25 and 0.75
    image = np.array([[0.0, 1.0], [1.0, 0.0]])
    uv = np.array([[0.25, 0.25], [0.5, 0.25], [0.5, 0.5], [0.75, 0.75]])
    np.testing.assert_allclose(modulation_at(image, uv), [0.0, 0.5, 0.5, 0.0])
    np.testing.assert_allclose(modulation_at(0.3, uv), 0.3)
    write_png(tmp_path / "mask.png", np.repeat(image[..., None], 3, axis=-1))
    scene = load(sky, 'effect = "ggx"\nmodulation = "mask.png"', tmp_path)
    np.testing.assert_allclose(scene.materials[0].modulation, image, atol=1e-12)


@pytest.mark.parametrize(
    ("material", "message"),
    [
        ("thickness = -1.0", r"materials.p.thickness: must be > 0, got -1.0$"),
        ("thickness = nan", r"materials.p.thickness: must be finite, got nan$"),
        ("tio2 = -0.5", r"materials.p.tio2: must be >= 0, got -0.5$"),
        ("tio2 = nan", r"materials.p.tio2: must be finite, got nan$"),
        ("tio2 = 5.0", r"materials.p.tio2: must be in \[0, 2\] % \(the characterization's grid\)"),
        ("index = 1.0", r"materials.p.index: must be > 1, got 1.0$"),
        ("index = 0.5", r"materials.p.index: must be > 1, got 0.5$"),
        # 1e11 was accepted; 1e308 was refused only as beyond the scenes' ±1e12
        ("index = 5", r"materials.p.index: a refractive index must be in \(1, 3\] \(polymers"),
        ("index = 1e308", r"materials.p.index: a refractive index must be in \(1, 3\]"),
        ('tint = "lemon"', r"materials.p.tint: .*spot_colours.csv: unknown tint 'lemon'; closest"),
        ("tint = 1.5", r"materials.p.tint: must be in \[0, 1\], got a maximum of 1.5$"),
        ("gloss = 2.0", r"materials.p.gloss: must be <= 1, got 2.0$"),
        ("modulation = 0.5", r"materials.p.modulation: mixes in an effect pigment; set 'effect'"),
        ('effect = "table"', r"materials.p.effect: brdf = 'table' needs a key 'file'"),
        ("effect = 5", r"materials.p.effect: must be a BRDF key .* or a table .*, got 5$"),
        ("effect = [1, 2]", r"materials.p.effect: must be a BRDF key .*, got \[1, 2\]$"),
        ('mirror = "sharp"', r"materials.p.mirror: unknown value 'sharp'; allowed: cosine, "),
        ("thicknes = 1.0", r"materials.p: unknown key 'thicknes'; allowed: "),
        ('model = "phong"', r"materials.p.model: unknown value 'phong'; allowed: herbert, layered"),
        (
            'model = "layered"\ntransparency = 0.5',
            r"materials.p.transparency: belongs to Herbert's hybrid; the layered model .* reads "
            "thickness, tio2, tint",
        ),
        (
            'model = "layered"\nmirror = "cosine"',
            r"materials.p.mirror: belongs to Herbert's hybrid",
        ),
    ],
)
def test_bad_input_is_one_line_naming_the_key(sky, material, message):
    with pytest.raises(SpecrefError, match=message) as error:
        load(sky, material)
    assert "\n" not in str(error.value)
    assert str(error.value).startswith("s.toml: ")


@pytest.mark.parametrize("tol", [0, -0.1, 1.5, float("nan"), "tight", True])
def test_a_bad_oracle_tolerance_is_refused_in_one_line(sky, tol):
    scene = load(sky, "")
    options = {"environment": "bruteforce", "polymer_oracle_tol": tol}
    with pytest.raises(SpecrefError, match=r"options\.polymer_oracle_tol: must be a number") as e:
        render_scene(scene, width=4, height=4, options=options)
    assert "\n" not in str(e.value)


def test_unknown_tint_lists_the_closest_names(sky):
    with pytest.raises(SpecrefError, match=r"closest: pb-lemon") as error:
        load(sky, 'tint = "lemon"')
    assert "\n" not in str(error.value)


def test_the_oracle_option_shades_the_layered_oracle(sky):
    # --oracle (erratum E60): the render's pixels are shrm.polymer.oracle.polymer_oracle's for the
    # material's slab (K, S at its TiO2, tint as a dye, E115), thickness, index and gloss; both
    # models share it; a material with an effect pigment is refused in one line
    from shrm.environment import cached_spectral_radiance
    from shrm.polymer.kubelka_munk import km_tinted_K, polymer_constituents, polymer_K_S
    from shrm.polymer.oracle import gloss_alpha, interface_coupling, polymer_oracle

    scene = load(sky, 'tint = "pb-orange"\ngloss = 0.7')
    oracle = render_scene(scene, width=6, height=6, options={"environment": "bruteforce"})
    g, ctx, m = oracle.gbuffer, scene.shading_context(), scene.materials[0]
    constituents = polymer_constituents(scene.grid)
    K, S = polymer_K_S(constituents, m.tio2_pct)
    r_t = interface_coupling(constituents.index, gloss_alpha(0.7)).r_i
    K = km_tinted_K(K, S, m.tint, r_t)
    radiance = cached_spectral_radiance(scene.lights[0], ctx)
    want = polymer_oracle(g.normal[g.mask], g.view[g.mask], radiance, K, S, m.thickness_mm,
                          constituents.index, 0.7, tol=0.005, seed=0).result  # fmt: skip
    assert oracle.records["polymer_oracle"][m.name]["samples"] >= 64
    assert scene.render.supersample == 1  # one sample per pixel: the pixel is the shaded point
    np.testing.assert_allclose(oracle.XYZ[g.mask], want @ ctx.weights(None), rtol=1e-12)
    layered = load(sky, 'model = "layered"\ntint = "pb-orange"\ngloss = 0.7')
    again = render_scene(layered, width=6, height=6, options={"environment": "bruteforce"})
    np.testing.assert_array_equal(again.XYZ, oracle.XYZ)
    with pytest.raises(SpecrefError, match="--oracle shades the Kubelka-Munk slab") as error:
        render_scene(load(sky, 'effect = "ggx"\nmodulation = 0.5'), width=4, height=4,
                     options={"environment": "bruteforce"})  # fmt: skip
    assert "\n" not in str(error.value)


def test_obj_groups_render_with_their_own_polymers(sky, tmp_path):
    # Source: the closed form of Eq. (1) under a uniform sky at normal view (as above), per group:
    # two unit squares facing the camera, usemtl thin (left) and thick (right)
    (tmp_path / "two.obj").write_text(
        "v -2 -1 0\nv 0 -1 0\nv 0 1 0\nv -2 1 0\nv 2 -1 0\nv 2 1 0\n"
        "usemtl thin\nf 1 2 3 4\nusemtl thick\nf 2 5 6 3\n"
    )
    text = (
        scene_text(sky, "thickness = 0.762\ntio2 = 0.1")
        .replace(
            '[[objects]]\ntype = "sphere"\nmaterial = "p"',
            '[materials.thick]\ntype = "polymer"\nthickness = 3.048\ntio2 = 2.0\n'
            '[[objects]]\ntype = "mesh"\nfile = "two.obj"\n'
            'groups = { thin = "p", thick = "thick" }',
        )
        .replace("extent = 2.4", "extent = 2.0")
        .replace("width = 16\nheight = 16", "width = 8\nheight = 4")
    )
    scene = loads_scene(text, "s.toml", tmp_path)
    result = render_scene(scene, supersample=1)
    np.testing.assert_array_equal(result.gbuffer.material_id[1], [0] * 4 + [1] * 4)
    S = environment_spectral_radiance(scene.lights[0], GRID)[0, 0]
    W = scene.shading_context().weights(None)
    for column, material in ((1, scene.materials[0]), (6, scene.materials[1])):
        look = polymer_material_look(material, GRID)
        F = look.fresnel.lookup(1.0)
        expected = S * (look.D_polymer * look.Tint_polymer + F + look.Col_trans * (1 - F))
        np.testing.assert_allclose(result.XYZ[1, column], expected @ W, rtol=1e-6)
