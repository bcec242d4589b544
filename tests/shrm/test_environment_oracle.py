"""`--oracle` on every material type under an environment light (erratum E90).

For each scene-file material type with an environment shader: the oracle and the default path
differ, and the oracle equals a direct brute-force sum over the map's pixels on sampled pixels.
"""

import numpy as np
import pytest

import shrm  # noqa: F401  (registers the environment shaders)
from reference.images.formats import write_exr
from reference.materials.types import MATERIAL_TYPES
from reference.scene.loader import load_scene
from reference.scene.render import render_scene
from reference.scene.shading import SHADERS
from shrm.environment import cached_spectral_radiance
from shrm.shrm_oracles import env_quadrature

#: One material of each type that has an environment shader (a new type must be added here).
MATERIALS = {
    "lambert": "k_d = 0.7",
    "phong": "k_d = 0.3" + "\n" + "k_s = 0.6" + "\n" + "n = 20.0",
    "isotropic_brdf": 'brdf = "ggx"'
    + "\n"
    + "alpha = 0.25"
    + "\n"
    + "rho_d = 0.1"
    + "\n"
    + "F_0 = 0.9",
}


def _env_types():
    return [
        t.name for t in MATERIAL_TYPES.values() if f"{t.cls.__name__}/EnvironmentLight" in SHADERS
    ]


#: Material types whose oracle is not a sum of their own BRDF over the map, and where it is tested:
#: the polymer's is the layered oracle of the physics both its models approximate (E60).
OTHER_ORACLE = {"polymer": "tests/shrm/polymer/test_material.py::test_the_oracle_option_shades"}


def test_every_material_type_with_an_environment_shader_is_covered():
    assert sorted(_env_types()) == sorted([*MATERIALS, *OTHER_ORACLE])


def _scene(tmp_path, kind, options=""):
    rng = np.random.default_rng(7)
    env = rng.uniform(0.05, 0.3, (16, 32, 3))
    env[4, 9] = [40.0, 30.0, 20.0]  # a small bright source: frequency paths and oracle differ
    write_exr(tmp_path / "env.exr", env)
    (tmp_path / "s.toml").write_text(
        f"""
[spectral]
start_nm = 410
end_nm = 710
step_nm = 50
[render]
width = 10
height = 10
{options}
[camera]
projection = "orthographic"
eye = [0, 0, 5]
extent = 2.2
[materials.m]
type = "{"isotropic_brdf" if kind == "table" else kind}"
{MATERIALS[kind]}
[[objects]]
type = "sphere"
material = "m"
[[lights]]
type = "environment"
file = "env.exr"
"""
    )
    return load_scene(tmp_path / "s.toml")


def _direct_sum(scene, normal, view):
    """Σ over map pixels of f L cos w, with the material's own reflectance model (XYZ)."""
    from reference.materials.brdf import BRDF_METHODS

    ctx = scene.shading_context()
    light, m = scene.lights[0], scene.materials[0]
    d, w, L = env_quadrature(cached_spectral_radiance(light, ctx))
    cosine = np.maximum(d @ normal, 0.0)
    kind = type(m).__name__
    if kind == "LambertMaterial":
        integrand = m.k_d / np.pi * cosine[:, None]
    elif kind == "PhongMaterial":
        r = 2 * (normal @ view) * normal - view
        # The environment Phong lobe max(r·ω, 0)^n / π over the whole sphere (shrm.environment)
        lobe = np.maximum(d @ r, 0.0)[:, None] ** m.n / np.pi
        integrand = m.k_d / np.pi * cosine[:, None] + m.k_s * lobe
    else:
        brdf = BRDF_METHODS.lookup(m.brdf).reference
        f = brdf(d, np.broadcast_to(view, d.shape), np.broadcast_to(normal, d.shape), **m.params)
        integrand = f * cosine[:, None]
    spectra = (integrand * L * w[:, None]).sum(0)
    return spectra @ ctx.weights(None)


@pytest.mark.parametrize("kind", sorted(MATERIALS))
def test_oracle_differs_and_equals_the_direct_sum(tmp_path, kind):
    scene = _scene(tmp_path, kind)
    fast = render_scene(scene)
    oracle = render_scene(scene, options={"environment": "bruteforce"})
    assert not np.allclose(fast.XYZ, oracle.XYZ, rtol=1e-6)
    g = oracle.gbuffer
    for i, j in [(5, 5), (2, 6), (7, 3), (4, 8)]:
        assert g.mask[i, j]
        view = -scene.camera.rays(10, 10)[1][i, j]
        expected = _direct_sum(scene, g.normal[i, j], view)
        np.testing.assert_allclose(oracle.XYZ[i, j], expected, rtol=1e-10)


def test_isotropic_brdf_metadata_and_upsampling(tmp_path):
    scene = _scene(tmp_path, "isotropic_brdf")
    fast = render_scene(scene)
    meta = fast.records["shrm"]
    assert meta["method"] == "shrm+angular"
    assert {"F", "P", "size", "tau", "bound_Y", "meets_tolerance", "env_rows"} <= set(meta)
    assert meta["env_rows"] == 16  # the full map
    oracle = render_scene(scene, options={"environment": "bruteforce"})
    assert oracle.records["shrm"]["method"] == "bruteforce"
    # The upsampling option reaches this path: another RGB -> spectrum method, another image
    other = render_scene(scene, options={"upsampling": "regression"})
    assert not np.allclose(other.XYZ, fast.XYZ, rtol=1e-6)
    assert (fast.XYZ[fast.gbuffer.mask[::1, ::1]][:, 1] >= 0).all()


def _table_scene(tmp_path):
    from reference.materials.table import tabulate_registered_brdf, write_brdf_table

    write_brdf_table(tmp_path / "ggx.brdf", tabulate_registered_brdf("ggx", 5.0, 15.0))
    MATERIALS["table"] = 'brdf = "table"' + "\n" + 'file = "ggx.brdf"'
    try:
        return _scene(tmp_path, "table")
    finally:
        del MATERIALS["table"]


def test_scene_files_take_tabulated_brdfs(tmp_path):
    # A GGX tabulated (docs/brdf-format.md) renders through the same path; the oracle equals the
    # direct sum with the table, and the split path is never negative.
    scene = _table_scene(tmp_path)
    assert scene.materials[0].params["table"].n_bands == scene.grid.n_bands
    fast = render_scene(scene)
    oracle = render_scene(scene, options={"environment": "bruteforce"})
    g = oracle.gbuffer
    for i, j in [(5, 5), (2, 6), (7, 3)]:
        view = -scene.camera.rays(10, 10)[1][i, j]
        expected = _direct_sum(scene, g.normal[i, j], view)
        np.testing.assert_allclose(oracle.XYZ[i, j], expected, rtol=1e-10)
    assert (fast.XYZ[g.mask][:, 1] >= 0).all()
    assert fast.records["shrm"]["method"] == "shrm+angular"


def test_scene_files_take_merl_brdfs(tmp_path):
    # A MERL file (docs/brdf-format.md, "MERL measured BRDFs") takes the tables' path: read,
    # tabulated at 2° in θ and 4° in Δφ, its RGB made spectral by Mallett & Yuksel's primaries.
    from reference.errors import SpecrefError
    from reference.materials.isotropic import brdf_ggx
    from reference.materials.merl import read_merl_brdf, write_merl_brdf
    from shrm.orbit import merl_to_spectral_brdf_table

    grey = {"rho_d": 0.2, "F_0": 0.9, "alpha": 0.3}
    path = write_merl_brdf(tmp_path / "ggx.binary", brdf_ggx, grey)
    MATERIALS["table"] = 'brdf = "table"' + "\n" + 'file = "ggx.binary"'
    try:
        scene = _scene(tmp_path, "table")
        table = scene.materials[0].params["table"]
        expected = merl_to_spectral_brdf_table(read_merl_brdf(path), scene.grid)
        np.testing.assert_array_equal(table.values, expected.values)
        # A grey BRDF stays flat across the bands: the primaries sum to 1 (to 1e-5).
        flat = np.broadcast_to(table.values[..., :1], table.values.shape)
        np.testing.assert_allclose(table.values, flat, rtol=1e-4, atol=1e-12)
        fast = render_scene(scene)
        assert fast.records["shrm"]["method"] == "shrm+angular"
        assert (fast.XYZ[fast.gbuffer.mask][:, 1] > 0).all()
        path.write_bytes(path.read_bytes()[:1000])
        with pytest.raises(
            SpecrefError, match=r"s\.toml: materials\.m\.file: .*ggx\.binary: 1,000"
        ):
            _scene(tmp_path, "table")
    finally:
        del MATERIALS["table"]


@pytest.mark.xfail(
    strict=True,
    reason="erratum E94 (docs/errata.md): a tabulated GGX on a 16-row map misses 1 % of the peak "
    "at grazing pixels (F is capped at 7 by the map)",
)
def test_tabulated_brdf_split_within_one_percent_of_the_peak(tmp_path):
    _, Y, Yo = _table_default_and_oracle(tmp_path)
    assert np.abs(Y - Yo).max() <= 0.01 * Yo.max()


def _table_default_and_oracle(tmp_path):
    """The table scene's default render, and its Y and the oracle's over the covered pixels."""
    scene = _table_scene(tmp_path)
    fast = render_scene(scene)
    oracle = render_scene(scene, options={"environment": "bruteforce"})
    mask = oracle.gbuffer.mask
    return fast, fast.XYZ[..., 1][mask], oracle.XYZ[..., 1][mask]


def test_tabulated_brdf_split_says_where_it_misses(tmp_path):
    # The miss of the strict xfail above is not quiet: the renderer's spot check against brute
    # force (E92) sees more than the tolerance where the lighting bound promised less, and the
    # render's records say that the tolerance is not met.
    fast, Y, Yo = _table_default_and_oracle(tmp_path)
    chose = fast.records["shrm"]
    assert np.abs(Y - Yo).max() > 0.01 * Yo.max()
    assert chose["check_points"] == 8
    assert chose["check_error"] > chose["tol"]
    assert chose["meets_tolerance"] is False
