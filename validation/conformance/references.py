"""Reference images of the conformance scenes, with a per-pixel standard error and a manifest.

Each scene is rendered by specref's oracle path: environment lights integrated by brute force over
every texel (``options["environment"] = "bruteforce"``, ``specref render --oracle``; a
Lambertian's irradiance with each texel's cosine integrated exactly, as the maps are constant over
each texel: ``irradiance_quadrature = "texels"``, :mod:`shrm.texel_irradiance`), Phong
materials by the exact per-band evaluation, Eq. (2), Wang et al., sphere lights to 1e-3 of each
pixel's value (``sphere_light_tol``; the quadrature's error is then far below the sub-samples').
Each pixel is the box-filtered mean of its ``S × S`` sub-samples (the scene's ``supersample``), and
its uncertainty is the standard error of that mean, ``σ = sd / S`` over the sub-samples: on the
regular sub-sample grid this over-states the error of the box integral, which the grid estimates
better than random samples would, so it is a conservative figure. A pixel's ``coverage`` is the
fraction of its sub-samples that hit a surface; the check compares pixels of full coverage only
(edge pixels depend on each renderer's pixel filter).

Files, per scene, in a folder (default ``<cache>/conformance/v<REFERENCE_VERSION>``, see
``reference.files.default_cache_dir``):

- ``<name>.xyz.exr``: channels ``X, Y, Z`` (CIE 1931 2°, Y = 1 for a white diffuser facing a unit
  light), ``X.stderr, Y.stderr, Z.stderr`` and ``coverage``, 32-bit float;
- ``<name>.spectral.exr``: the relative spectral radiance per band in the spectral OpenEXR layout
  (``S0.380,000000nm`` ...; docs/render-outputs.md). Under environments XYZ is its integral; under
  point and ambient lights XYZ folds the light into the band weights at the light's own sampling
  (errata E7, E77), which the per-band spectrum cannot; on the 1 nm grid of those scenes the two
  differ by less than 1e-4 of each value;
- ``manifest.json``: the version, and per scene its size, mean XYZ with its standard error and the
  SHA-256 of each file; a reference whose file does not match its digest is refused.

The shipped ``data:conformance/manifest.json`` holds the same summary as rendered when the suite
was made; the tests re-render and check that the means agree within their standard errors.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require

__all__ = [
    "REFERENCE_OPTIONS",
    "REFERENCE_VERSION",
    "Reference",
    "ensure_references",
    "load_reference",
    "reference_folder",
    "reference_summary",
    "render_reference",
    "shipped_manifest",
    "write_reference",
]

#: Version of the reference set; a change of a scene or of the oracle's output bumps it.
REFERENCE_VERSION = 3
#: Shader options of the oracle path.
REFERENCE_OPTIONS = {
    "environment": "bruteforce",
    "irradiance_quadrature": "texels",
    "phong": {"method": "exact"},
    "sphere_light_tol": 1e-3,
}


@dataclass(frozen=True)
class Reference:
    """A scene's reference image.

    Attributes
    ----------
    name : str
    XYZ, stderr : ndarray, shape (H, W, 3)
        Box-filtered XYZ and the standard error of each value.
    spectral : ndarray, shape (H, W, C)
        Relative spectral radiance per band (XYZ is its integral, docs/render-outputs.md).
    wavelengths : ndarray, shape (C,)
    coverage : ndarray, shape (H, W)
        Fraction of the pixel's sub-samples on a surface.
    """

    name: str
    XYZ: np.ndarray
    stderr: np.ndarray
    spectral: np.ndarray
    wavelengths: np.ndarray
    coverage: np.ndarray


def _mean_and_stderr(samples: np.ndarray, S: int) -> tuple[np.ndarray, np.ndarray]:
    """Box mean of ``S × S`` blocks and the standard error of that mean (sd / S, ddof 1)."""
    H, W = samples.shape[0] // S, samples.shape[1] // S
    blocks = samples.reshape(H, S, W, S, -1)
    mean = blocks.mean(axis=(1, 3))
    if S == 1:
        return mean, np.zeros_like(mean)
    sd = blocks.std(axis=(1, 3), ddof=1)
    return mean, sd / S


def render_reference(name: str, scene=None) -> Reference:
    """Render a conformance scene by the oracle path (module docstring).

    Parameters
    ----------
    name : str
        A key of ``CONFORMANCE_SCENES``.
    scene : reference.scene.loader.Scene, optional
        The loaded scene (default: its shipped file); a variant of it for the diagnoses.

    Examples
    --------
    >>> ref = render_reference("lambert-point-d65")
    >>> ref.XYZ.shape, ref.spectral.shape[-1], float(ref.coverage.max())
    ((64, 64, 3), 401, 1.0)
    >>> S = ref.spectral @ _equal_energy_weights(ref)    # the light folded in per band (E7)
    >>> bool(np.allclose(S, ref.XYZ, rtol=1e-4, atol=1e-9))
    True
    """
    import phong_table  # noqa: F401  (registers the Phong table methods)
    import shrm  # noqa: F401  (registers the environment-light shaders)
    from reference.colour.colorimetry import band_weights
    from reference.scene.lights import EnvironmentLight
    from reference.scene.loader import load_scene
    from reference.scene.render import scene_gbuffer, shade_scene
    from validation.conformance.scenes import scene_path

    scene = load_scene(scene_path(name)) if scene is None else scene
    S = scene.render.supersample
    gbuffer = scene_gbuffer(scene)
    samples = shade_scene(scene, gbuffer, REFERENCE_OPTIONS, "spectral")
    if all(isinstance(light, EnvironmentLight) for light in scene.lights):
        # radiance spectra: XYZ is their integral with the equal-energy weights
        W_E = band_weights(scene.grid, None, scene.weights_method, scene.observer)
        XYZ_samples = samples @ W_E
    else:  # point and ambient lights fold their spectra into the band weights at their sampling
        XYZ_samples = shade_scene(scene, gbuffer, REFERENCE_OPTIONS)
    XYZ, stderr = _mean_and_stderr(XYZ_samples, S)
    spectral, _ = _mean_and_stderr(samples, S)
    coverage = _mean_and_stderr(gbuffer.mask[..., None].astype(np.float64), S)[0][..., 0]
    return Reference(name, XYZ, stderr, spectral, scene.grid.wavelengths_nm.copy(), coverage)


def _equal_energy_weights(ref: Reference) -> np.ndarray:
    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import SpectralGrid

    wl = ref.wavelengths
    return band_weights(SpectralGrid(wl[0], wl[-1], wl[1] - wl[0]))


def reference_summary(ref: Reference) -> dict:
    """Size, mean XYZ over the image and the standard error of that mean (manifest entries).

    Examples
    --------
    >>> XYZ = np.ones((2, 2, 3)); z = np.zeros((2, 2))
    >>> s = reference_summary(Reference("x", XYZ, XYZ * 0.1, XYZ, np.ones(3), z))
    >>> s["mean_XYZ"], s["stderr_mean_XYZ"]
    ([1.0, 1.0, 1.0], [0.05, 0.05, 0.05])
    """
    H, W = ref.XYZ.shape[:2]
    n = H * W
    return {
        "width": W,
        "height": H,
        "mean_XYZ": [float(v) for v in ref.XYZ.reshape(n, 3).mean(axis=0)],
        "stderr_mean_XYZ": [float(v) for v in np.sqrt((ref.stderr.reshape(n, 3) ** 2).sum(0)) / n],
    }


def _sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def write_reference(ref: Reference, folder) -> dict:
    """Write a reference's two EXRs into ``folder``; returns its manifest entry (with digests).

    Examples
    --------
    >>> import tempfile
    >>> XYZ = np.ones((2, 2, 3)); z = np.ones((2, 2))
    >>> entry = write_reference(Reference("x", XYZ, XYZ * 0, XYZ, np.array([400.0, 500, 600]), z),
    ...                         tempfile.mkdtemp())
    >>> sorted(entry["files"])
    ['x.spectral.exr', 'x.xyz.exr']
    """
    from reference.images.formats import spectral_channel_names, write_exr

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    xyz = np.concatenate([ref.XYZ, ref.stderr, ref.coverage[..., None]], axis=-1)
    channels = ["X", "Y", "Z", "X.stderr", "Y.stderr", "Z.stderr", "coverage"]
    files = {
        f"{ref.name}.xyz.exr": write_exr(
            folder / f"{ref.name}.xyz.exr", xyz.astype(np.float32), channels
        ),
        f"{ref.name}.spectral.exr": write_exr(
            folder / f"{ref.name}.spectral.exr",
            ref.spectral.astype(np.float32),
            spectral_channel_names(ref.wavelengths),
        ),
    }
    return {**reference_summary(ref), "files": {k: _sha256(p) for k, p in files.items()}}


def reference_folder() -> Path:
    """``<cache>/conformance/v<REFERENCE_VERSION>`` (``reference.files.default_cache_dir``).

    Examples
    --------
    >>> reference_folder().name
    'v3'
    """
    from reference.files import default_cache_dir

    return default_cache_dir() / "conformance" / f"v{REFERENCE_VERSION}"


def _read_manifest(folder: Path) -> dict:
    path = folder / "manifest.json"
    if not path.is_file():
        return {"version": REFERENCE_VERSION, "scenes": {}}
    from reference.files import read_json

    manifest = read_json(path, "conformance manifest")
    require(
        isinstance(manifest, dict) and isinstance(manifest.get("scenes"), dict),
        f"{path}: not a conformance manifest (no 'scenes' table)",
    )
    require(
        manifest.get("version") == REFERENCE_VERSION,
        f"{path}: version: references of version {manifest.get('version')!r}; this specref "
        f"makes version {REFERENCE_VERSION} (render them again: specref conformance references)",
    )
    for name, entry in manifest["scenes"].items():
        _check_entry(entry, f"{path}: scenes.{name}")
    return manifest


def _check_entry(entry, where: str) -> None:
    # a manifest entry as write_reference makes it: files of the folder itself, sizes and means
    # that a render could have (a changed manifest is refused, never read outside its folder)
    require(isinstance(entry, dict), f"{where}: not a table")
    files = entry.get("files")
    require(
        isinstance(files, dict)
        and all(isinstance(f, str) and f == Path(f).name and f.endswith(".exr") for f in files),
        f"{where}.files: must name .exr files of the manifest's own folder",
    )
    for key in ("width", "height"):
        size = entry.get(key)
        require(
            isinstance(size, int) and not isinstance(size, bool) and 1 <= size <= 4096,
            f"{where}.{key}: must be a size in pixels (1-4096), got {size!r}",
        )
    for key in ("mean_XYZ", "stderr_mean_XYZ"):
        values = entry.get(key)
        require(
            isinstance(values, list) and len(values) == 3
            and all(isinstance(v, int | float) and np.isfinite(v) and v >= 0 for v in values),
            f"{where}.{key}: must be three finite values >= 0",
        )  # fmt: skip


def _intact(folder: Path, entry: dict | None) -> bool:
    if not entry:
        return False
    files = entry.get("files", {})
    return bool(files) and all(
        (folder / f).is_file() and _sha256(folder / f) == digest for f, digest in files.items()
    )


def ensure_references(names=None, folder=None, progress=None, force: bool = False) -> dict:
    """Render the references that ``folder`` lacks (or all, with ``force``); return the manifest.

    Parameters
    ----------
    names : iterable of str, optional
        Scenes (default all of ``CONFORMANCE_SCENES``).
    folder : str or Path, optional
        Default :func:`reference_folder`.
    progress : callable, optional
        Called with a line per scene (its name, then its time).
    force : bool
        Render even the scenes whose files are present and intact.

    Returns
    -------
    dict
        The folder's manifest (``version``, ``scenes``), rewritten atomically after each scene.

    Examples
    --------
    >>> import tempfile
    >>> manifest = ensure_references(["colorchecker-d65"], tempfile.mkdtemp())
    >>> sorted(manifest["scenes"]["colorchecker-d65"]["files"])
    ['colorchecker-d65.spectral.exr', 'colorchecker-d65.xyz.exr']
    """
    from reference.files import check_output_folder, folder_lock
    from validation.conformance.scenes import CONFORMANCE_SCENES

    names = list(CONFORMANCE_SCENES.names() if names is None else names)
    for name in names:  # before the folder is made
        CONFORMANCE_SCENES.lookup(name)
    folder = check_output_folder(
        folder if folder is not None else reference_folder(), marker="manifest.json"
    )
    with folder_lock(folder):
        before = _read_manifest(folder)["scenes"]
    # Each scene under a lock of its own: processes filling one folder render different scenes side
    # by side, a process passing over the scenes another holds; then it waits for those, and
    # renders any that the other left undone (it stopped, or it was killed)
    pending = list(enumerate(names, 1))
    for wait in (False, True):
        busy = []
        for i, name in pending:
            with folder_lock(folder, name, wait=wait) as held:
                if not held:
                    busy.append((i, name))
                    continue
                label = f"[{i}/{len(names)}] {name}"
                _render_if_missing(folder, name, before.get(name), force, label, progress)
        pending = busy
    with folder_lock(folder):
        return _read_manifest(folder)


def _render_if_missing(folder: Path, name, before, force: bool, label: str, progress) -> None:
    # one scene of ensure_references, under the scene's lock: the manifest read and written under
    # the folder's (brief), the render outside it
    import time

    from reference.files import folder_lock, write_text_atomic

    with folder_lock(folder):
        entry = _read_manifest(folder)["scenes"].get(name)
    done = force and entry is not None and entry != before  # rendered anew by another process
    if (done or not force) and _intact(folder, entry):
        return
    start = time.perf_counter()
    if progress is not None:
        progress(f"{label}: rendering the reference")
    entry = write_reference(render_reference(name), folder)
    with folder_lock(folder):
        manifest = _read_manifest(folder)
        manifest["scenes"][name] = entry
        write_text_atomic(folder / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    if progress is not None:
        progress(f"{label}: {time.perf_counter() - start:.1f} s")


def load_reference(name: str, folder=None, progress=None) -> Reference:
    """A scene's reference from ``folder``, rendered there first if missing; digests checked.

    Raises
    ------
    SpecrefError
        A file whose SHA-256 differs from the manifest (one line naming it).

    Examples
    --------
    >>> import tempfile
    >>> ref = load_reference("colorchecker-d65", tempfile.mkdtemp())   # rendered there first
    >>> ref.XYZ.shape, ref.wavelengths[[0, -1]].tolist()
    ((40, 60, 3), [380.0, 780.0])
    """
    from reference.images.formats import channel_wavelengths_nm, read_exr

    folder = Path(folder) if folder is not None else reference_folder()
    manifest = _read_manifest(folder)
    entry = manifest["scenes"].get(name)
    if entry is None:
        entry = ensure_references([name], folder, progress)["scenes"][name]
    for file, digest in entry["files"].items():
        path = folder / file
        require(path.is_file(), f"{path}: listed in {folder / 'manifest.json'} but missing")
        if _sha256(path) != digest:
            raise SpecrefError(
                f"{path}: SHA-256 differs from {folder / 'manifest.json'} (the file was changed; "
                "render it again: specref conformance references --force)"
            )
    xyz, names = read_exr(folder / f"{name}.xyz.exr")
    spectral, channels = read_exr(folder / f"{name}.spectral.exr")
    pick = [names.index(c) for c in ("X", "Y", "Z", "X.stderr", "Y.stderr", "Z.stderr")]
    xyz = xyz.astype(np.float64)
    return Reference(
        name,
        xyz[..., pick[:3]],
        xyz[..., pick[3:]],
        spectral.astype(np.float64),
        channel_wavelengths_nm(channels),
        xyz[..., names.index("coverage")],
    )


def shipped_manifest() -> dict:
    """The summary shipped in ``data:conformance/manifest.json`` (module docstring).

    Examples
    --------
    >>> shipped_manifest()["version"] == REFERENCE_VERSION
    True
    """
    from reference.data import data_path

    return json.loads(data_path("conformance/manifest.json").read_text(encoding="utf-8"))
