"""Images through the display: Eq. (1), Ferwerda, per pixel, for an observer and a tilted screen.

ImpastoR compensates the display for the viewing direction and for light reflected by the screen
(§3.4.2–3.4.3, Ferwerda): for each screen point, the observer's zenith θ from the screen normal and
azimuth φ along the screen give ``L_factor(θ, φ)``, and the booth light reflected by the front
surface (diffuse ``ρ E/π`` and a specular lobe around the mirror direction) is subtracted before
the inverse of Eq. (1), Ferwerda. :func:`image_to_display_counts` does this for a whole image and
returns the counts and what the observer then sees; with ``compensate=False`` it drives the
display as if viewed on axis in the dark, to show what the compensation buys.

Screen coordinates: the screen's centre is the origin; untilted, the screen lies in the plane
z = 0 facing +z, x to the right, y up (landscape azimuth φ = 0 along x). ``tilt`` rotates it
about x (positive: the top leans back, the normal turns up). Positions in metres.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015, §3.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.display.model import (
    DisplayModel,
    XYZ_to_display_counts,
    display_counts_to_XYZ,
    screen_flare_XYZ,
)
from reference.errors import require, require_finite

__all__ = [
    "ScreenGeometry",
    "image_to_display_counts",
    "off_mirror_angle_deg",
    "screen_view_angles",
]


@dataclass(frozen=True)
class ScreenGeometry:
    """A flat screen: size (m) and tilt about its horizontal axis (radians).

    The default is the EIZO RX220's active area in landscape, 0.43 × 0.32 m, upright.
    """

    width_m: float = 0.43
    height_m: float = 0.32
    tilt: float = 0.0

    @property
    def normal(self) -> np.ndarray:
        """Unit normal of the screen's front."""
        return np.array([0.0, np.sin(self.tilt), np.cos(self.tilt)])

    def points(self, height: int, width: int) -> np.ndarray:
        """Centres of an image's pixels on the screen, (height, width, 3), row 0 at the top."""
        u = ((np.arange(width) + 0.5) / width - 0.5) * self.width_m
        v = (0.5 - (np.arange(height) + 0.5) / height) * self.height_m
        up = np.array([0.0, np.cos(self.tilt), -np.sin(self.tilt)])
        return u[None, :, None] * np.array([1.0, 0.0, 0.0]) + v[:, None, None] * up


def screen_view_angles(geometry: ScreenGeometry, observer, height: int, width: int):
    """Zenith θ and azimuth φ (radians) of the observer seen from each pixel, (height, width).

    Raises
    ------
    SpecrefError
        An observer behind the screen (on the side it does not face) for any pixel.

    Examples
    --------
    >>> theta, phi = screen_view_angles(ScreenGeometry(), [0.0, 0.0, 0.6], 3, 3)
    >>> round(float(theta[1, 1]), 6), round(float(np.degrees(theta[1, 2])), 1)
    (0.0, 13.4)
    >>> screen_view_angles(ScreenGeometry(), [0.0, 0.0, -0.5], 2, 2)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: observer: (0, 0, -0.5) m is behind the screen (tilt 0°): ...
    """
    eye = require_finite(observer, "observer")
    require(eye.shape == (3,), f"observer: must be x, y, z in metres, got shape {eye.shape}")
    n = geometry.normal
    to_eye = eye - geometry.points(height, width)
    distance = np.linalg.norm(to_eye, axis=-1)
    cos_theta = (to_eye @ n) / distance
    require(
        (cos_theta > 1e-6).all(),
        f"observer: ({', '.join(f'{c:g}' for c in eye)}) m is behind the screen (tilt "
        f"{np.degrees(geometry.tilt):g}°): it must be on the side the screen faces, normal "
        f"({', '.join(f'{c + 0.0:.3g}' for c in n)})",
    )
    theta = np.arccos(np.clip(cos_theta, -1.0, 1.0))
    x_axis = np.array([1.0, 0.0, 0.0])
    y_axis = np.cross(n, x_axis)
    phi = np.arctan2(to_eye @ y_axis, to_eye @ x_axis)
    return theta, phi


def off_mirror_angle_deg(geometry, observer, light_position, height, width) -> np.ndarray:
    """Angle between each pixel's mirror direction of the view and the direction to a light.

    Parameters
    ----------
    geometry : ScreenGeometry
        The screen.
    observer, light_position : array_like, shape (3,)
        The eye and the light (or its reflection's source), in the screen's frame (m).
    height, width : int
        The image's pixels on the screen.

    Returns
    -------
    ndarray, shape (height, width)
        Degrees; 0 where the light is seen in the pixel's mirror direction (the screen's glare).

    Examples
    --------
    >>> g = ScreenGeometry()
    >>> bool(off_mirror_angle_deg(g, [0, 0, 0.6], [0, 0, 2.0], 3, 3)[1, 1] < 1e-6)
    True
    """
    n = geometry.normal
    points = geometry.points(height, width)
    to_eye = np.asarray(observer, float) - points
    to_eye /= np.linalg.norm(to_eye, axis=-1, keepdims=True)
    mirror = 2.0 * (to_eye @ n)[..., None] * n - to_eye
    to_light = np.asarray(light_position, float) - points
    to_light /= np.linalg.norm(to_light, axis=-1, keepdims=True)
    return np.degrees(np.arccos(np.clip((mirror * to_light).sum(axis=-1), -1.0, 1.0)))


def image_to_display_counts(
    XYZ,
    model: DisplayModel,
    geometry: ScreenGeometry,
    observer,
    E_XYZ=None,
    light_position=None,
    light_XYZ=None,
    compensate: bool = True,
) -> dict:
    """Display counts for an image of intended XYZ (cd/m²), per pixel through Eq. (1), Ferwerda.

    Parameters
    ----------
    XYZ : array_like, shape (H, W, 3)
        What the observer should see, cd/m².
    model : DisplayModel
    geometry : ScreenGeometry
    observer : array_like, shape (3,)
        Eye position, metres, in front of the screen.
    E_XYZ : array_like, shape (3,), optional
        Illuminance on the screen (lux in Y) from the booth light: the diffuse flare.
    light_position, light_XYZ : array_like, shape (3,), optional
        The booth light's centre (m) and luminance (cd/m²): the specular flare.
    compensate : bool
        True: divide by ``L_factor(θ, φ)`` and subtract the flare (§3.4.2–3.4.3). False: drive the
        display as if seen on axis in the dark.

    Returns
    -------
    dict
        ``counts`` (H, W, 3) int64, ``in_gamut`` (H, W), ``seen_XYZ`` (H, W, 3): what the observer
        sees (emitted light at their angle plus the flare), ``theta``, ``phi`` (H, W).

    Examples
    --------
    >>> from reference.display.model import virtual_display
    >>> d = virtual_display()
    >>> image = np.full((2, 2, 3), 100.0)
    >>> out = image_to_display_counts(image, d, ScreenGeometry(), [0.3, 0.0, 0.5])
    >>> bool(np.allclose(out["seen_XYZ"], image, rtol=2e-3))
    True
    """
    XYZ = require_finite(XYZ, "XYZ image")
    require(XYZ.ndim == 3 and XYZ.shape[-1] == 3, f"XYZ image: must be (H, W, 3), got {XYZ.shape}")
    height, width = XYZ.shape[:2]
    theta, phi = screen_view_angles(geometry, observer, height, width)
    flare = np.zeros_like(XYZ)
    if E_XYZ is not None or light_XYZ is not None:
        mirror = None
        if light_XYZ is not None:
            require(light_position is not None, "light_position: needed with light_XYZ")
            mirror = off_mirror_angle_deg(geometry, observer, light_position, height, width)
        E = np.zeros(3) if E_XYZ is None else np.asarray(E_XYZ, float)
        # §3.4.3, Ferwerda: the screen's diffuse and specular reflection (Erratum E57)
        flare = flare + screen_flare_XYZ(model, np.broadcast_to(E, XYZ.shape), light_XYZ, mirror)
    if compensate:
        # Eq. (1), Ferwerda, inverted per pixel at the observer's (θ, φ), flare subtracted
        counts, in_gamut, _ = XYZ_to_display_counts(XYZ, model, theta, phi, flare)
    else:
        counts, in_gamut, _ = XYZ_to_display_counts(XYZ, model)
    # what the observer sees: Eq. (1), Ferwerda, at their angle, plus the flare
    seen = display_counts_to_XYZ(counts, model, theta, phi) + flare
    return {"counts": counts, "in_gamut": in_gamut, "seen_XYZ": seen, "theta": theta, "phi": phi}
