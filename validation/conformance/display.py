"""The display-calibrated conformance scene: device values for a calibrated display.

A scene whose ``[display]`` table names a calibration (``calibration = "displays/<name>.cal"``,
docs/display.md) is checked on what that display shows, not on scene XYZ. Its render is the
device values an application sends to the calibrated display (the ``.cal`` sits in the video
card): a PNG of 8 or 16 bits (``specref render`` writes one for the scene). Both the render
and the reference go through the display's forward model, ``XYZ = XYZ_K + P · share(values)``
(Eq. (1), Ferwerda, on the calibrated display: ``reference.display.calibration_files``), and are
compared in the scene's units (divided by the scene's ``exposure``), so the check's figures are
those of the other scenes: what the display shows against what it would show for the reference's
device values (out-of-gamut colours clipped by both).

The mistakes this scene catches (:mod:`validation.conformance.diagnose`) are those of colour
management, each made from the reference's XYZ ``X`` (times the exposure):

- ``display_srgb``: the display treated as an sRGB monitor, ``values = sRGB_encode(clip(M X))``
  with ``M`` the XYZ-to-linear-sRGB matrix: the calibration ignored altogether;
- ``display_primaries_ignored``: the calibration's tone curve applied to linear sRGB,
  ``values = share⁻¹(clip(M X))``: the display's primaries taken to be sRGB's;
- ``display_curve_ignored``: the display's primaries, but the sRGB transfer function instead of
  the calibration's curve, ``values = sRGB_encode(clip(P⁻¹ (X − XYZ_K)))``;
- ``display_linear``: the display's primaries and no curve at all, ``values = clip(P⁻¹ (X −
  XYZ_K))``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import require

__all__ = [
    "SceneDisplay",
    "display_mistake_values",
    "read_device_values",
    "scene_display",
]


@dataclass(frozen=True)
class SceneDisplay:
    """A conformance scene's calibrated display and exposure (``[display]`` of its file).

    Attributes
    ----------
    calibration : reference.display.calibration_files.CalibratedDisplay
    exposure : float
        The scene's ``display.exposure``: device values show ``exposure · X``.
    """

    calibration: object
    exposure: float

    def values(self, XYZ) -> np.ndarray:
        """Device values in [0, 1] that show ``XYZ`` (scene units, ``(..., 3)``)."""
        from reference.display.calibration_files import XYZ_to_calibrated_values

        return XYZ_to_calibrated_values(np.asarray(XYZ) * self.exposure, self.calibration)[0]

    def shown(self, values) -> np.ndarray:
        """XYZ in scene units that the display shows for device values ``(..., 3)``."""
        from reference.display.calibration_files import calibrated_values_to_XYZ

        return calibrated_values_to_XYZ(values, self.calibration) / self.exposure

    def round_trip(self, XYZ) -> np.ndarray:
        """What the display shows for the device values of ``XYZ`` (out of gamut: clipped)."""
        return self.shown(self.values(XYZ))


@functools.cache
def scene_display(name: str) -> SceneDisplay | None:
    """The calibrated display of a conformance scene, or None when it has none.

    Examples
    --------
    >>> scene_display("colorchecker-d65") is None
    True
    >>> d = scene_display("colorchecker-d65-calibrated-display")
    >>> d.exposure, d.calibration.curve
    (0.8, 'lstar')
    >>> X = np.array([0.3, 0.35, 0.2])
    >>> bool(np.allclose(d.round_trip(X), X, atol=1e-4))
    True
    """
    import tomllib

    from reference.display.calibration_files import load_calibrated_display
    from validation.conformance.scenes import scene_path, scene_text

    table = tomllib.loads(scene_text(name)).get("display", {})
    if "calibration" not in table:
        return None
    calibration = load_calibrated_display(scene_path(name).parent / table["calibration"])
    return SceneDisplay(calibration, float(table.get("exposure", 1.0)))


def read_device_values(path) -> np.ndarray:
    """A render of device values, a PNG of 8 or 16 bits: ``(H, W, 3)`` in [0, 1].

    Raises
    ------
    SpecrefError
        A file of another type, or without three colour channels.

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.formats import write_png
    >>> d = tempfile.mkdtemp()
    >>> read_device_values(write_png(os.path.join(d, "a.png"), np.full((2, 2, 3), 0.5)))[0, 0]
    array([0.50196078, 0.50196078, 0.50196078])
    >>> read_device_values(os.path.join(d, "b.exr"))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../b.exr: a frame for a calibrated display holds device ...
    """
    from reference.images.formats import read_png

    path = Path(path)
    require(
        path.suffix.lower() == ".png",
        f"{path}: a frame for a calibrated display holds device values; give them as a PNG of 8 "
        "or 16 bits",
    )
    image = read_png(path)
    require(
        image.shape[-1] in (3, 4),
        f"{path}: {image.shape[-1]} channels; device values need R, G, B (and A)",
    )
    return image[..., :3]


def _srgb_encode(linear: np.ndarray) -> np.ndarray:
    # IEC 61966-2-1
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


def display_mistake_values(mistake: str, XYZ, display: SceneDisplay) -> np.ndarray:
    """The device values a colour-management mistake sends for ``XYZ`` (module docstring).

    Parameters
    ----------
    mistake : str
        ``display_srgb``, ``display_primaries_ignored``, ``display_curve_ignored`` or
        ``display_linear``.
    XYZ : ndarray, shape (..., 3)
        Scene units.
    display : SceneDisplay

    Examples
    --------
    >>> d = scene_display("colorchecker-d65-calibrated-display")
    >>> grey = np.array([0.95047, 1.0, 1.08883]) * 0.18 / d.exposure
    >>> display_mistake_values("display_srgb", grey, d).round(3)   # sRGB's 18 % grey
    array([0.461, 0.461, 0.461])
    >>> linear = display_mistake_values("display_linear", grey, d)    # the shares themselves
    >>> bool(np.allclose(linear, d.calibration.share(d.values(grey)), atol=1e-4))
    True
    """
    from reference.colour.colorimetry import XYZ_to_display_RGB

    cal = display.calibration
    X = np.asarray(XYZ, dtype=np.float64) * display.exposure
    if mistake in ("display_srgb", "display_primaries_ignored"):
        linear = np.clip(XYZ_to_display_RGB(X), 0.0, 1.0)
        if mistake == "display_srgb":
            return _srgb_encode(linear)
        return cal.values_for_share(linear)  # the calibration's curve on sRGB's shares
    # ρ = P⁻¹ (XYZ − XYZ_K): the display's own linear channel shares
    rho = np.clip(np.linalg.solve(cal.P, (X - cal.black_XYZ)[..., None])[..., 0], 0.0, 1.0)
    if mistake == "display_curve_ignored":
        return _srgb_encode(rho)
    require(mistake == "display_linear", f"unknown display mistake {mistake!r}")
    return rho
