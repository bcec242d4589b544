"""Material files for ``specref phong --material FILE.toml``: a spectral Phong material, its light.

The format is documented in ``docs/scene-format.md`` ("Phong material files"). A file holds a
``[material]`` table (``k_d``, ``k_s``, ``n`` and optionally ``k_a``, each a spectrum), an optional
``[light]`` table (``spectrum``, ``position``, ``intensity``, ``attenuation``) and an optional
``[spectral]`` table; the sphere, the camera and the views are those of the scenes
(``phong_table.scenes``). Spectra, the ``[spectral]`` table and the error messages are those of
scene files: the values are read by ``reference.scene.values.SceneReader`` (every form of
``reference.scene.values.SPECTRUM_FORMS``) and ``reference.scene.loader.parse_spectral``, so every
error names the file and the key.
"""

from __future__ import annotations

from pathlib import Path

from phong_table.model import SpectralPhong
from phong_table.scenes import LIGHT_ATTENUATION, LIGHT_POSITION
from reference.materials.types import PhongMaterial
from reference.scene.lights import PointLight
from reference.scene.loader import parse_spectral, read_toml_file
from reference.scene.values import SceneReader

__all__ = ["load_material_file"]

_TOP_KEYS = ("name", "spectral", "material", "light")
_MATERIAL_KEYS = ("name", "k_d", "k_s", "n", "k_a")
_LIGHT_KEYS = ("spectrum", "position", "intensity", "attenuation")


def load_material_file(path) -> SpectralPhong:
    """Read a material file: a spectral Phong material and its point light.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    SpectralPhong
        With the light of the file; when ``light.intensity`` is absent the intensity makes the
        brightest value, ``max_c (D_c + f_sp,c(1))``, display white (as in the scenes).

    Raises
    ------
    SpecrefError
        Unreadable file, bad TOML, unknown or missing keys, negative or NaN values, mismatched
        spectral lengths; the message names the file and the key.

    Examples
    --------
    >>> import tempfile, os
    >>> text = 'name = "gold"' + chr(10) + '[material]' + chr(10) + 'k_d = 0.2' + chr(10)
    >>> text += 'k_s = { illuminant = "A" }' + chr(10) + 'n = 40' + chr(10)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "m.toml")
    ...     _ = open(p, "w").write(text)
    ...     model = load_material_file(p)
    >>> model.material.n[:2], model.material.name
    (array([40., 40.]), 'gold')
    """
    path = Path(path)
    data = read_toml_file(path)
    reader = SceneReader(str(path), path.parent)
    for key in data:
        if key not in _TOP_KEYS:
            reader.fail(key, f"unknown key {key!r}; allowed: {', '.join(sorted(_TOP_KEYS))}")
    grid, observer, weights_method = parse_spectral(reader, data)
    reader.grid = grid
    if "material" not in data:
        reader.fail("material", "missing: the file needs a [material] table")
    material = reader.table(data["material"], "material", _MATERIAL_KEYS, ("k_d", "k_s", "n"))
    name = reader.string(material.get("name", data.get("name", path.stem)), "name")
    # the material's spectra k_d(λ), k_s(λ), n(λ) and k_a(λ), each >= 0
    params = {
        key: reader.spectrum_on_grid(material[key], f"material.{key}")
        for key in ("k_d", "k_s", "n", "k_a")
        if key in material
    }
    light = reader.table(data.get("light", {}), "light", _LIGHT_KEYS)
    spectrum = reader.light_spectrum(light.get("spectrum", {"illuminant": "D65"}), "light.spectrum")
    position = reader.vector(light.get("position", list(LIGHT_POSITION)), "light.position")
    attenuation = reader.vector(
        light.get("attenuation", list(LIGHT_ATTENUATION)), "light.attenuation"
    )
    for i, c in enumerate(attenuation):
        reader.number(c, f"light.attenuation[{i}]", minimum=0)
    intensity = reader.number(light.get("intensity", 1.0), "light.intensity", minimum=0)
    settings = {"grid": grid, "observer": observer, "weights_method": weights_method}
    with reader.context("material"):
        phong = PhongMaterial(name=name, **params)
        model = SpectralPhong(
            phong, PointLight(position, spectrum, intensity, attenuation), **settings
        )
        if "intensity" not in light:
            peak = float((model.diffuse_RGB + model.specular(1.0)).max())
            point = PointLight(position, spectrum, 1.0 / peak if peak > 0 else 1.0, attenuation)
            model = SpectralPhong(phong, point, **settings)
    return model
