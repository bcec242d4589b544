"""Mitsuba 3 renders of the exported conformance scenes: an independent renderer that passes.

``render_mitsuba_folder`` renders every ``<scene>.xml`` of a folder written by
``export_scenes(folder, "mitsuba")`` with Mitsuba 3's ``scalar_spectral`` variant and writes
``<scene>.exr`` (channels ``X, Y, Z``) into an output folder, ready for
``specref conformance check``. Needs the optional extra (``pip install '.[mitsuba]'``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference.errors import SpecrefError

__all__ = [
    "PROOF_SPP",
    "PROOF_SPP_OVERRIDE",
    "QUICK_PROOF",
    "proof_spp",
    "render_mitsuba",
    "render_mitsuba_folder",
    "run_mitsuba_proof",
]


def render_mitsuba(
    xml, out, seed: int = 1, spp: int | None = None, variant: str = "scalar_spectral"
) -> Path:
    """Render one Mitsuba scene file and write its XYZ image as ``out`` (an EXR).

    ``spp`` overrides the file's samples per pixel.

    Raises
    ------
    SpecrefError
        When Mitsuba 3 or the variant is not available (with how to install it).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from validation.conformance.export import export_scenes
    >>> from validation.studies.crosscheck import mitsuba_missing
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> if mitsuba_missing() is None:
    ...     _ = export_scenes(folder, "mitsuba", spp=4)
    ...     print(render_mitsuba(folder / "colorchecker-a.xml", folder / "a.exr").name)
    ... else:
    ...     print("a.exr")
    a.exr
    """
    from reference.images.formats import write_exr
    from validation.studies.crosscheck import INSTALL_HINT

    try:
        import mitsuba as mi

        mi.set_variant(variant)
    except (ImportError, AttributeError, ValueError) as error:
        raise SpecrefError(
            f"Mitsuba 3 ({variant}) not available ({error}); {INSTALL_HINT}"
        ) from None
    # The RGB variants render the suite's mistakes on purpose: their clamping of out-of-gamut
    # colours is the mistake, not news; the spectral variant's warnings stay on.
    mi.set_log_level(mi.LogLevel.Warn if "spectral" in variant else mi.LogLevel.Error)
    xml = Path(xml)
    scene = mi.load_file(str(xml))
    image = np.array(mi.render(scene, seed=seed, spp=spp or 0), dtype=np.float64)[..., :3]
    return write_exr(out, image.astype(np.float32), ["X", "Y", "Z"])


def render_mitsuba_folder(
    folder, out, names=None, seed: int = 1, spp: dict | None = None, progress=None
) -> list[Path]:
    """Render the exported scenes of ``folder`` (all, or ``names``) into ``out``.

    ``spp`` maps scene names to samples per pixel that override the files'.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from validation.conformance.export import export_scenes
    >>> from validation.studies.crosscheck import mitsuba_missing
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> if mitsuba_missing() is None:
    ...     _ = export_scenes(folder, "mitsuba", spp=4)
    ...     out = render_mitsuba_folder(folder, folder / "renders", ["colorchecker-d65"])
    ...     print([p.name for p in out])
    ... else:
    ...     print(["colorchecker-d65.exr"])
    ['colorchecker-d65.exr']
    """
    folder, out = Path(folder), Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = sorted(folder.glob("*.xml"))
    if names is not None:
        files = [f for f in files if f.stem in set(names)]
    written = []
    for xml in files:
        if progress is not None:
            progress(f"{xml.stem}: rendering in Mitsuba 3")
        written.append(
            render_mitsuba(xml, out / f"{xml.stem}.exr", seed, (spp or {}).get(xml.stem))
        )
    return written


#: Samples per pixel of the proof, per scene (:func:`proof_spp`): as many as keep Mitsuba's noise,
#: averaged over 4 × 4 blocks, near half the 1 % floor in Y or below (measured at 128 to 4096). The
#: point-lit spheres and the broadband charts reach it at 256; FL11's narrow lines make Mitsuba's
#: wavelength sampling noisier, and the studio map's small bright lamps its environment sampling;
#: the Lambertian sphere under a sphere light reaches it at 512.
PROOF_SPP = 1024
PROOF_SPP_OVERRIDE = {
    "lambert-point-d65": 256,
    "lambert-point-orange-a": 256,
    "ggx-point-d65": 256,
    "colorchecker-d65": 256,
    "colorchecker-a": 256,
    "colorchecker-fl11": 4096,
    "lambert-env-studio": 2048,
    "polymer-smooth-env-studio": 2048,
    "lambert-sphere-light-d65": 512,
}


def proof_spp(name: str) -> int:
    """Samples per pixel with which the proof renders scene ``name`` in Mitsuba 3.

    Examples
    --------
    >>> proof_spp("colorchecker-fl11"), proof_spp("lambert-env-venice")
    (4096, 1024)
    """
    return PROOF_SPP_OVERRIDE.get(name, PROOF_SPP)


#: The scenes of the quick proof (``specref report``'s default effort): a point light, a lamp with
#: lines and an environment, each with the mistake it is broken with.
QUICK_PROOF = ("lambert-point-d65", "colorchecker-fl2", "lambert-env-venice")


def _broken_renders(scenes: Path, renders: Path, out: Path) -> dict[str, tuple[str, Path]]:
    """Mitsuba's renders broken on purpose: scene -> (the mistake made, the render)."""
    from reference.colour.colorimetry import XYZ_to_display_RGB, display_RGB_to_XYZ
    from reference.display.encodings import encode_srgb
    from reference.images.formats import read_exr, write_exr
    from validation.conformance.scenes import ring_map

    out.mkdir(parents=True, exist_ok=True)
    image = read_exr(scenes / "maps" / "venice.exr")[0][..., :3]
    write_exr(out / "venice-mirrored.exr", np.ascontiguousarray(image[:, ::-1]))
    xml = (scenes / "lambert-env-venice.xml").read_text(encoding="utf-8")
    mirrored = out / "lambert-env-venice.xml"
    mirrored.write_text(xml.replace("maps/venice.exr", str(out / "venice-mirrored.exr")))
    # the ring map's own 32 rows, which Mitsuba reads at v = j/(H − 1): half a texel off
    write_exr(out / "ring-own-rows.exr", ring_map())
    xml = (scenes / "lambert-env-ring.xml").read_text(encoding="utf-8")
    own_rows = out / "lambert-env-ring.xml"
    own_rows.write_text(xml.replace("maps/ring.exr", str(out / "ring-own-rows.exr")))
    XYZ = read_exr(renders / "lambert-point-d65.exr")[0][..., :3].astype(np.float64)
    encoded = display_RGB_to_XYZ(encode_srgb(np.clip(XYZ_to_display_RGB(XYZ), 0.0, None)))
    return {
        "lambert-env-venice": (
            "environment_mirrored",
            render_mitsuba(mirrored, out / "lambert-env-venice.exr", spp=256),
        ),
        "lambert-env-ring": (
            "environment_rows_offset",
            render_mitsuba(own_rows, out / "lambert-env-ring.exr", spp=256),
        ),
        "lambert-point-d65": (
            "srgb_encoded",
            write_exr(out / "lambert-point-d65.exr", encoded.astype(np.float32), list("XYZ")),
        ),
        "colorchecker-fl2": (
            "rgb_rendering",
            render_mitsuba(
                scenes / "colorchecker-fl2.xml", out / "colorchecker-fl2.exr", variant="scalar_rgb"
            ),
        ),
    }


def run_mitsuba_proof(
    folder, names=None, broken: bool = True, references=None, progress=None
) -> dict:
    """Export the scenes, render them in Mitsuba 3, check them; then check four broken renders.

    docs/conformance.md ("Proof on Mitsuba 3"): every scene Mitsuba 3 can express (or those of
    ``names``; :data:`QUICK_PROOF` for the report's default effort) is rendered at
    :func:`proof_spp` and checked against its reference; with ``broken``, the venice map mirrored,
    the ring map given to Mitsuba as its own 32 rows (which it reads at ``v = j/(H − 1)``), the
    point-lit sphere's values sRGB-encoded and the FL2 chart rendered by Mitsuba's ``scalar_rgb``
    variant are checked too, each expected to fail with the mistake made (the scenes of
    :data:`QUICK_PROOF` are then rendered whatever ``names`` says). ``references`` is the
    references' folder (default ``folder/references``; rendered there where missing).

    Returns
    -------
    dict
        ``check`` (:func:`validation.conformance.check.check_folder`'s result), ``broken``: per
        scene the mistake made and the check's result, and ``references`` (the folder).

    Raises
    ------
    SpecrefError
        Without Mitsuba 3 (with how to install it).

    Examples
    --------
    >>> import tempfile
    >>> from validation.studies.crosscheck import mitsuba_missing
    >>> if mitsuba_missing() is None:
    ...     proof = run_mitsuba_proof(tempfile.mkdtemp(), ["colorchecker-d65"], broken=False)
    ...     print(proof["check"]["passed"], proof["check"]["failed"])
    ... else:
    ...     print(1, 0)
    1 0
    """
    from validation.conformance.check import check_folder, check_render
    from validation.conformance.export import export_scenes
    from validation.conformance.references import ensure_references
    from validation.studies.crosscheck import mitsuba_missing

    missing = mitsuba_missing()
    if missing is not None:
        raise SpecrefError(missing)
    folder = Path(folder)
    index = export_scenes(folder / "scenes", "mitsuba", spp=PROOF_SPP)
    wanted = set(index["scenes"] if names is None else names) | set(QUICK_PROOF if broken else ())
    names = [n for n in index["scenes"] if n in wanted]
    references = Path(references) if references is not None else folder / "references"
    render_mitsuba_folder(
        folder / "scenes", folder / "renders", names, spp=PROOF_SPP_OVERRIDE, progress=progress
    )
    # after Mitsuba: another process filling the same folder has had the time to
    ensure_references(names, references, progress)
    result = check_folder(folder / "renders", references, progress=progress)
    made = {}
    if broken:
        renders = _broken_renders(folder / "scenes", folder / "renders", folder / "broken")
        for name, (mistake, path) in renders.items():
            made[name] = {"made": mistake, **check_render(name, path, references)}
    return {"check": result, "broken": made, "references": str(references)}
