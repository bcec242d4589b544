"""The conformance scenes in other renderers' formats: specref's own files and Mitsuba 3 XML.

``specref conformance export DIR --format specref|mitsuba`` writes every scene the format can
express, with what they need beside them (maps, spectra, the calibrated display), and
``scenes.json``: per scene its size, what it tests, the mistakes it catches, what its render holds,
and the scenes the format cannot express, with why.

**Mitsuba 3** (scene format version 3.0.0, a spectral variant): the camera as a ``perspective`` or
``orthographic`` sensor with ``fov_axis = "y"`` and a ``lookat`` transform; an ``hdrfilm`` of the
scene's size with ``pixel_format = "xyz"`` and a ``box`` filter; each map resampled for Mitsuba's
placement of texels (:func:`texels_for_mitsuba`); the ``path`` integrator with
``max_depth = 2`` (direct light only: the scenes have one convex object, or a flat chart);
Lambertian materials as ``diffuse``; the GGX conductor as ``roughconductor`` with
``distribution = "ggx"`` and ``material = "none"`` (F = 1). specref's units become Mitsuba's
(docs/conformance.md): a light spectrum ``S`` normalized to Y = 1 (``Y_S = Σ S ȳ / Σ ȳ``); a
point light of ``intensity`` I is ``π I S / Y_S`` in W/sr (a white diffuser facing it at unit
distance then reflects radiance ``I S / Y_S``, specref's Y = I), a sphere light of ``intensity``
I is a ``sphere`` shape with an ``area`` emitter of radiance ``I S / Y_S``, and an ambient light is
a ``constant`` emitter of radiance ``I S / Y_S``. The ColorChecker is 24 ``rectangle`` shapes (the
chart's black gaps are the background). Spectra are written as ``wavelength:value`` pairs at 5 nm.
"""

from __future__ import annotations

import json
import re
import shutil
import tomllib
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from reference.errors import require
from validation.conformance.scenes import CONFORMANCE_SCENES, scene_text

__all__ = ["EXPORT_FORMATS", "export_scenes", "mitsuba_xml", "texels_for_mitsuba"]

#: Formats of ``specref conformance export``.
EXPORT_FORMATS = ("specref", "mitsuba")
_DATA = re.compile(r'"data:([^"]+)"')
#: Most samples per pixel written into a Mitsuba scene (2^20: hours per scene on a laptop).
MAX_SPP = 1 << 20
#: Wavelengths of the spectra written for Mitsuba, nm.
MITSUBA_WAVELENGTHS = np.arange(360.0, 831.0, 5.0)


def _spectrum_values(table, where: str) -> np.ndarray:
    """A scene file's spectrum (a number or a spectrum table) at MITSUBA_WAVELENGTHS."""
    from reference.colour.spectra import SpectralGrid
    from reference.scene.values import SceneReader

    if isinstance(table, int | float):
        return np.full(MITSUBA_WAVELENGTHS.size, float(table))
    from reference.data import data_root

    reader = SceneReader(where, data_root() / "conformance", SpectralGrid(360.0, 830.0, 5.0))
    return reader.spectrum_on_grid({**table, "extrapolation": "constant"}, where)


def _pairs(values: np.ndarray, wavelengths=MITSUBA_WAVELENGTHS) -> str:
    return ", ".join(f"{w:g}:{v:.6g}" for w, v in zip(wavelengths, values, strict=True))


def _normalized(illuminant: str) -> tuple[np.ndarray, np.ndarray]:
    """An illuminant at 1 nm, scaled to Y = 1, as Mitsuba ``wavelength:value`` pairs.

    At 1 nm as the band weights fold it in (colour-science's ``align``: Sprague interpolation,
    constant beyond the table), so that Mitsuba's linear interpolation sees the same lines; Y as
    Mitsuba's XYZ film computes it, ``Σ S ȳ / Σ ȳ``.
    """
    import colour

    shape = colour.SpectralShape(360, 830, 1)
    S = colour.SDS_ILLUMINANTS[illuminant].copy().align(shape)
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    Y_S = float((S.values * ybar.values[:, 1]).sum() / ybar.values[:, 1].sum())
    return S.values / Y_S, S.wavelengths


def _sensor(data: dict) -> list[str]:
    cam, r = data["camera"], data["render"]
    eye, target = cam.get("eye", [0, 0, 5]), cam.get("target", [0, 0, 0])
    look = (
        f'<lookat origin="{",".join(map(str, eye))}" target="{",".join(map(str, target))}" '
        'up="0,1,0"/>'
    )
    film = [
        '    <film type="hdrfilm">',
        f'      <integer name="width" value="{r["width"]}"/>',
        f'      <integer name="height" value="{r["height"]}"/>',
        '      <string name="pixel_format" value="xyz"/>',
        '      <rfilter type="box"/>',
        "    </film>",
        '    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>',
    ]
    if cam.get("projection") == "orthographic":
        # Mitsuba's orthographic film spans ±1 across its width: the scale is half the width
        half = cam.get("extent", 2.0) / 2.0 * r["width"] / r["height"]
        return [
            '  <sensor type="orthographic">',
            f'    <transform name="to_world">{look}<scale x="{half}" y="{half}" z="1"/>'
            "</transform>",
            *film,
            "  </sensor>",
        ]
    return [
        '  <sensor type="perspective">',
        f'    <float name="fov" value="{cam["fov_deg"]}"/>',
        '    <string name="fov_axis" value="y"/>',
        f'    <transform name="to_world">{look}</transform>',
        *film,
        "  </sensor>",
    ]


def _bsdf(material: dict, where: str) -> list[str]:
    if material["type"] == "lambert":
        k_d = _spectrum_values(material["k_d"], f"{where}.k_d")
        return [
            '    <bsdf type="diffuse">',
            f'      <spectrum name="reflectance" value="{_pairs(k_d)}"/>',
            "    </bsdf>",
        ]
    if material["type"] == "polymer":  # the opaque smooth chip: Mitsuba's smooth plastic
        return _plastic(material)
    # the GGX conductor of F = 1 (ConformanceScene.cannot_export lists the other BRDFs)
    return ['    <bsdf type="roughconductor">', '      <string name="distribution" value="ggx"/>',
            f'      <float name="alpha" value="{material["alpha"]}"/>',
            '      <string name="material" value="none"/>', "    </bsdf>"]  # fmt: skip


def _plastic(material: dict) -> list[str]:
    """A smooth opaque polymer chip as Mitsuba 3's ``plastic``.

    ``nonlinear``: the internal reflections between the coat and the body (Saunderson's). The
    diffuse reflectance is the slab's body reflectance ``R_0 + T² r_b / (1 − R_0 r_b)``
    (Kubelka-Munk, the constituents' K and S at the chip's TiO2 load); ``T`` is below 1 % for the
    suite's chip, so the light it passes is left out.
    """
    from reference.colour.spectra import SpectralGrid
    from shrm.polymer.kubelka_munk import km_slab, polymer_constituents, polymer_K_S
    from shrm.polymer.oracle import interface_coupling

    wl = MITSUBA_WAVELENGTHS
    constituents = polymer_constituents(SpectralGrid(float(wl[0]), float(wl[-1]), 5.0))
    K, S = polymer_K_S(constituents, float(material["tio2"]))
    R_0, T = km_slab(K, S, float(material["thickness"]))
    r_b = interface_coupling(constituents.index, 0.0).r_i
    body = R_0 + T**2 * r_b / (1.0 - R_0 * r_b)
    return ['    <bsdf type="plastic">',
            f'      <float name="int_ior" value="{constituents.index}"/>',
            '      <float name="ext_ior" value="1.0"/>',
            '      <boolean name="nonlinear" value="true"/>',
            f'      <spectrum name="diffuse_reflectance" value="{_pairs(body, wl)}"/>',
            "    </bsdf>"]  # fmt: skip


def _chart_shapes() -> list[str]:
    import colour

    from reference.scene.colorchecker import colorchecker_patch_centres_uv

    uv = colorchecker_patch_centres_uv()
    chart = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    out = []
    for (u, v), sd in zip(uv, chart.values(), strict=True):
        x, y = -0.3 + 0.6 * u, 0.2 - 0.4 * v
        values = np.interp(MITSUBA_WAVELENGTHS, sd.wavelengths, sd.values)
        out += [
            '  <shape type="rectangle">',
            f'    <transform name="to_world"><scale value="0.044"/><translate x="{x:.6g}" '
            f'y="{y:.6g}" z="0"/></transform>',
            f'    <bsdf type="diffuse"><spectrum name="reflectance" value="{_pairs(values)}"/>'
            "</bsdf>",
            "  </shape>",
        ]
    return out


def _emitters(data: dict) -> list[str]:
    out = []
    for light in data["lights"]:
        kind, intensity = light["type"], float(light.get("intensity", 1.0))
        if kind == "environment":
            out.append(f'  <emitter type="envmap"><string name="filename" '
                       f'value={quoteattr(light["file"])}/></emitter>')  # fmt: skip
            continue
        S, wl = _normalized(light.get("spectrum", {}).get("illuminant", "D65"))
        if kind == "point":
            p = ",".join(map(str, light["position"]))
            out.append(f'  <emitter type="point"><point name="position" value="{p}"/>'
                       f'<spectrum name="intensity" value="{_pairs(np.pi * intensity * S, wl)}"/>'
                       "</emitter>")  # fmt: skip
        elif kind == "sphere":  # an emitting sphere of radiance I S / Y_S
            p = ",".join(map(str, light["position"]))
            out.append(f'  <shape type="sphere"><point name="center" value="{p}"/>'
                       f'<float name="radius" value="{light["radius"]}"/>'
                       f'<emitter type="area"><spectrum name="radiance" '
                       f'value="{_pairs(intensity * S, wl)}"/></emitter></shape>')  # fmt: skip
        else:  # ambient: a uniform sky of radiance I S / Y_S
            out.append(f'  <emitter type="constant"><spectrum name="radiance" '
                       f'value="{_pairs(intensity * S, wl)}"/></emitter>')  # fmt: skip
    return out


def mitsuba_xml(name: str, spp: int = 64) -> str:
    """A conformance scene as a Mitsuba 3 scene file (module docstring).

    Examples
    --------
    >>> xml = mitsuba_xml("lambert-point-d65", spp=16)
    >>> xml.splitlines()[1]
    '<scene version="3.0.0">'
    >>> '<emitter type="point">' in xml, 'value="16"' in xml
    (True, True)
    >>> mitsuba_xml("phong-point-r1")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: phong-point-r1: Mitsuba 3 has no Phong BSDF ...
    """
    scene = CONFORMANCE_SCENES.lookup(name)
    why = scene.cannot_export.get("mitsuba")
    require(why is None, f"{name}: {why}")
    data = tomllib.loads(scene_text(scene))
    lines = ['<?xml version="1.0" encoding="utf-8"?>', '<scene version="3.0.0">',
             f"  <!-- specref conformance scene {name}: {data['description']} -->",
             '  <integrator type="path"><integer name="max_depth" value="2"/></integrator>',
             *_sensor(data)]  # fmt: skip
    for obj in data["objects"]:
        material = data["materials"][obj["material"]]
        if material["type"] == "colorchecker":
            lines += _chart_shapes()
        else:
            lines += ['  <shape type="sphere">', *_bsdf(material, f"materials.{obj['material']}"),
                      "  </shape>"]  # fmt: skip
    lines += [*_emitters(data), "</scene>"]
    return "\n".join(lines).replace("$spp", str(int(spp))) + "\n"


#: Each texel of a map becomes this many × this many in the Mitsuba export: Mitsuba's blending of
#: spectra between texels (erratum E81) then takes 0.19 % of the studio sphere's Y (0.38 % at 8,
#: 0.09 % at 32; it falls as 1/k), in maps of 6 MB.
TEXEL_REPEAT = 16


def texels_for_mitsuba(image: np.ndarray, k: int = TEXEL_REPEAT) -> np.ndarray:
    """A map constant over each texel, as Mitsuba 3 must be given it: ``k H × k W`` (float32).

    The scenes' maps are constant over each texel (``texel_placement = "centred"``: texel ``j``
    spans rows ``j/H`` to ``(j + 1)/H``). Mitsuba 3 interpolates bilinearly between samples it
    places at ``u = (i + ½)/W`` and, in rows, at ``v = j/(H − 1)`` (src/emitters/envmap.cpp);
    between texels of different colour it interpolates the upsampled spectrum's shape and scale
    apart (erratum E81). So each column is repeated ``k`` times, which confines the blending to a
    border of ``1/(2k)`` texel, and each of the ``k H`` rows is the mean of the map over the span
    of ``v`` that Mitsuba's sample stands for, ``[v_r − Δ/2, v_r + Δ/2]`` with ``v_r = r/(kH − 1)``
    and ``Δ = 1/(kH − 1)``: the linear interpolation of those means keeps every texel row's
    integral and puts its edges where they are. Rows merely repeated 8 times would put each edge
    up to half a repeated row (0.35° at 32 rows) towards the pole, and dim a bright row near it by
    a few per cent (erratum E100).

    Examples
    --------
    >>> texels_for_mitsuba(np.arange(2.0).reshape(1, 2, 1), 2)[..., 0]
    array([[0., 0., 1., 1.],
           [0., 0., 1., 1.]], dtype=float32)
    >>> rows = texels_for_mitsuba(np.array([[[0.0]], [[1.0]], [[0.0]]]), 2)[:, 0, 0]
    >>> rows.round(4)                          # at v = r/5: the middle texel row's 1/3, kept
    array([0.    , 0.    , 0.8333, 0.8333, 0.    , 0.    ], dtype=float32)
    """
    image = np.asarray(image, dtype=np.float64)
    H = image.shape[0]
    R = k * H
    v = np.arange(R) / (R - 1)
    half = 0.5 / (R - 1)
    lo, hi = np.clip(v - half, 0.0, 1.0), np.clip(v + half, 0.0, 1.0)
    edges = np.arange(H + 1) / H
    # the share of each texel row in each sample's span of v
    overlap = np.minimum(hi[:, None], edges[None, 1:]) - np.maximum(lo[:, None], edges[None, :-1])
    share = np.clip(overlap, 0.0, None) / (hi - lo)[:, None]
    rows = np.einsum("rj,jw...->rw...", share, image)
    return np.repeat(rows, k, axis=1).astype(np.float32)


def _copy_data(text: str, out: Path) -> str:
    """``"data:X"`` values copied beside the scene (``data/X``) and named relative to it."""
    from reference.data import data_path

    def copy(match) -> str:
        target = out / "data" / match.group(1)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(data_path(match.group(1)), target)
        return json.dumps(f"data/{match.group(1)}")

    return _DATA.sub(copy, text)


def _render_kind(data: dict) -> str:
    """What ``specref conformance check`` reads for a scene (docs/conformance.md)."""
    calibration = data.get("display", {}).get("calibration")
    if calibration is not None:
        return f"device values for the display of {calibration} (.png, 8 or 16 bits)"
    return "scene-referred .exr: X, Y, Z, spectral channels or linear R, G, B (or .hdr)"


def export_scenes(folder, fmt: str = "specref", spp: int = 64) -> dict:
    """Write every scene ``fmt`` can express into ``folder``; return the index (``scenes.json``).

    Parameters
    ----------
    folder : str or Path
        Created if missing; the scenes' maps go to ``maps/``, other shipped files to ``data/``.
    fmt : {"specref", "mitsuba"}
    spp : int
        Samples per pixel written into Mitsuba scenes.

    Examples
    --------
    >>> import tempfile
    >>> index = export_scenes(tempfile.mkdtemp(), "mitsuba")
    >>> len(index["scenes"]) + len(index["cannot_express"]) == len(CONFORMANCE_SCENES.names())
    True
    >>> index["cannot_express"]["ward-env-stage"]
    'Mitsuba 3 has no Ward BSDF'
    """
    from reference.data import data_path
    from reference.files import check_output_folder, write_text_atomic
    from reference.images.formats import read_exr, write_exr

    require(fmt in EXPORT_FORMATS, f"--format: {fmt!r}; allowed: {', '.join(EXPORT_FORMATS)}")
    require(
        isinstance(spp, int) and 1 <= spp <= MAX_SPP,
        f"spp: samples per pixel must be an integer in 1-{MAX_SPP}, got {spp!r}",
    )
    out = check_output_folder(folder, marker="scenes.json")
    check_output_folder(out / "maps")
    for path in sorted(data_path("conformance/maps").iterdir()):
        if path.suffix == ".exr" and fmt == "mitsuba":
            write_exr(out / "maps" / path.name, texels_for_mitsuba(read_exr(path)[0][..., :3]))
        elif path.suffix == ".exr":
            shutil.copyfile(path, out / "maps" / path.name)
    if fmt == "specref":  # the calibrated display a scene names, beside it (.cal, .ti3, .json)
        check_output_folder(out / "displays")
        for path in sorted(data_path("conformance/displays").iterdir()):
            shutil.copyfile(path, out / "displays" / path.name)
    index = {"format": fmt, "scenes": {}, "cannot_express": {}}
    for scene in CONFORMANCE_SCENES.values():
        why = scene.cannot_export.get(fmt)
        if why is not None:
            index["cannot_express"][scene.name] = why
            continue
        text = scene_text(scene)
        data = tomllib.loads(text)
        if fmt == "specref":
            file = write_text_atomic(out / f"{scene.name}.toml", _copy_data(text, out))
        else:
            file = write_text_atomic(out / f"{scene.name}.xml", mitsuba_xml(scene.name, spp))
        index["scenes"][scene.name] = {
            "file": file.name,
            "width": data["render"]["width"],
            "height": data["render"]["height"],
            "tests": scene.tests,
            "catches": list(scene.catches),
            "render": _render_kind(data),
        }
    write_text_atomic(out / "scenes.json", json.dumps(index, indent=1) + "\n")
    return index
