"""Cameras: look-at frames, primary rays and projection to raster coordinates.

Conventions (``docs/conventions.md``): world space is right-handed with y up; the camera looks down
its own −z axis, with +x to the right and +y up in the image. Raster coordinates put pixel ``(row j,
column i)`` over ``[i, i+1) × [j, j+1)`` with its centre at ``(i + ½, j + ½)`` and row 0 at the top
of the image.

- **Perspective:** ``fov_deg`` is the full *vertical* field of view; the horizontal one follows from
the
  aspect ratio ``width / height``.
- **Orthographic:** ``extent`` is the full vertical size of the view in world units.

Supersampling renders at ``(s·height, s·width)`` with the same field of view and box-filters back
(:func:`downsample_box`), so every sub-sample is a pixel centre of the finer raster.

References
----------
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed. (pbrt-v4), §5.1-5.2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice, require_finite

__all__ = ["MAX_COORDINATE", "MAX_RESOLUTION", "PROJECTIONS", "Camera", "downsample_box"]

PROJECTIONS = ("perspective", "orthographic")
#: Largest image side specref renders; larger requests are refused as absurd.
MAX_RESOLUTION = 16384
#: Largest camera coordinate magnitude (scene units); past it float64 view directions break down.
MAX_COORDINATE = 1e9


@dataclass(frozen=True)
class Camera:
    """A pinhole (perspective) or orthographic camera placed with look-at.

    Parameters
    ----------
    eye, target : array_like, shape (3,)
        Camera position and the point it looks at (distinct).
    up : array_like, shape (3,)
        Approximate up direction, not parallel to ``target - eye``.
    projection : {"perspective", "orthographic"}
        Projection.
    fov_deg : float
        Full vertical field of view in degrees, in (0, 180) (perspective).
    extent : float
        Full vertical size of the view in world units, > 0 (orthographic).

    Examples
    --------
    >>> cam = Camera(eye=(0, 0, 5), target=(0, 0, 0))
    >>> origins, dirs = cam.rays(3, 3)
    >>> dirs[1, 1]
    array([ 0.,  0., -1.])
    """

    eye: tuple = (0.0, 0.0, 5.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    projection: str = "perspective"
    fov_deg: float = 45.0
    extent: float = 2.0

    def __post_init__(self):
        where = "camera"
        eye = require_finite(self.eye, f"{where}.eye")
        target = require_finite(self.target, f"{where}.target")
        up = require_finite(self.up, f"{where}.up")
        for key, value in (("eye", eye), ("target", target), ("up", up)):
            require(
                value.shape == (3,), f"{where}.{key}: must be 3 numbers, got shape {value.shape}"
            )
        require_choice(self.projection, PROJECTIONS, "projection")
        for key, value in (("eye", eye), ("target", target)):
            require(
                np.abs(value).max() <= MAX_COORDINATE,
                f"{where}.{key}: coordinates must be within ±{MAX_COORDINATE:g}, "
                f"got {value.tolist()}",
            )
        forward = target - eye
        require(np.linalg.norm(forward) > 1e-12, f"{where}.target: must differ from eye")
        cross = np.linalg.norm(np.cross(forward / np.linalg.norm(forward), up))
        require(
            np.linalg.norm(up) > 0 and cross > 1e-9,
            f"{where}.up: must not be parallel to target - eye",
        )
        require(
            np.isfinite(self.fov_deg) and 0.0 < self.fov_deg < 180.0,
            f"{where}.fov_deg: must be in (0, 180), got {self.fov_deg}",
        )
        require(
            np.isfinite(self.extent) and self.extent > 0,
            f"{where}.extent: must be > 0, got {self.extent}",
        )
        object.__setattr__(self, "eye", tuple(float(x) for x in eye))
        object.__setattr__(self, "target", tuple(float(x) for x in target))
        object.__setattr__(self, "up", tuple(float(x) for x in up))

    def basis(self) -> np.ndarray:
        """Camera axes in world space as rows: right (+x), up (+y), back (+z; it looks down −z).

        Examples
        --------
        >>> Camera(eye=(0, 0, 5), target=(0, 0, 0)).basis()
        array([[1., 0., 0.],
               [0., 1., 0.],
               [0., 0., 1.]])
        """
        eye, target, up = (
            np.asarray(v, dtype=np.float64) for v in (self.eye, self.target, self.up)
        )
        back = eye - target
        back /= np.linalg.norm(back)
        right = np.cross(up, back)
        right /= np.linalg.norm(right)
        true_up = np.cross(back, right)
        return np.stack([right, true_up, back])

    def world_to_camera(self, points) -> np.ndarray:
        """Camera-space coordinates of world points, shape (..., 3); visible points have z < 0.

        Examples
        --------
        >>> Camera(eye=(0, 0, 5), target=(0, 0, 0)).world_to_camera([0.0, 0.0, 0.0])
        array([ 0.,  0., -5.])
        """
        return (np.asarray(points, dtype=np.float64) - np.asarray(self.eye)) @ self.basis().T

    def _half_height(self) -> float:
        """Half the vertical size of the image plane at distance 1 (perspective) or of the view."""
        if self.projection == "perspective":
            return float(np.tan(np.radians(self.fov_deg) / 2.0))
        return self.extent / 2.0

    def raster_to_ndc(self, x, y, width: int, height: int):
        """Raster ``(x, y)`` to camera-plane ``(p_x, p_y)`` (screen coordinates × view size).

        Examples
        --------
        >>> p_x, p_y = Camera(projection="orthographic", extent=2.0).raster_to_ndc(0.0, 0.0, 4, 2)
        >>> float(p_x), float(p_y)
        (-2.0, 1.0)
        """
        h = self._half_height()
        a = width / height
        p_x = (2.0 * np.asarray(x, dtype=np.float64) / width - 1.0) * h * a
        p_y = (1.0 - 2.0 * np.asarray(y, dtype=np.float64) / height) * h
        return p_x, p_y

    def rays(self, width: int, height: int, rows=None) -> tuple[np.ndarray, np.ndarray]:
        """Primary rays through the pixel centres.

        Parameters
        ----------
        width, height : int
            Image size in pixels, each in [1, MAX_RESOLUTION].
        rows : (int, int), optional
            Only the rows ``start ≤ y < stop`` of that image (a band, for work in pieces).

        Returns
        -------
        origins, directions : ndarray, shape (height, width, 3) or (stop − start, width, 3)
            World-space origins and unit directions.

        Examples
        --------
        >>> o, d = Camera(projection="orthographic", eye=(0, 0, 5), target=(0, 0, 0)).rays(2, 2)
        >>> o[0, 0], d[0, 0] + 0.0
        (array([-0.5,  0.5,  5. ]), array([ 0.,  0., -1.]))
        >>> bool((Camera().rays(4, 6, rows=(2, 5))[1] == Camera().rays(4, 6)[1][2:5]).all())
        True
        """
        _check_resolution(width, height)
        start, stop = (0, height) if rows is None else rows
        x = np.arange(width) + 0.5
        y = np.arange(start, stop) + 0.5
        p_x, p_y = self.raster_to_ndc(x[None, :], y[:, None], width, height)
        p_x, p_y = np.broadcast_arrays(p_x, p_y)
        right, up, back = self.basis()
        eye = np.asarray(self.eye)
        if self.projection == "perspective":
            d = p_x[..., None] * right + p_y[..., None] * up - back
            d /= np.linalg.norm(d, axis=-1, keepdims=True)
            o = np.broadcast_to(eye, d.shape).copy()
        else:
            o = eye + p_x[..., None] * right + p_y[..., None] * up
            d = np.broadcast_to(-back, o.shape).copy()
        return o, d

    def project(self, points, width: int, height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Raster coordinates and depth of world points.

        Parameters
        ----------
        points : array_like, shape (..., 3)
            World points.
        width, height : int
            Image size.

        Returns
        -------
        x, y : ndarray, shape (...,)
            Raster coordinates (pixel centres at half-integers, row 0 at the top).
        depth : ndarray, shape (...,)
            Distance in front of the camera along its view axis (−z in camera space); > 0 when
            visible.

        Examples
        --------
        >>> x, y, depth = Camera(eye=(0, 0, 5), target=(0, 0, 0)).project([0.0, 0.0, 0.0], 4, 4)
        >>> float(x), float(y), float(depth)
        (2.0, 2.0, 5.0)
        """
        pc = self.world_to_camera(points)
        depth = -pc[..., 2]
        h = self._half_height()
        a = width / height
        if self.projection == "perspective":
            with np.errstate(divide="ignore", invalid="ignore"):
                p_x, p_y = pc[..., 0] / depth, pc[..., 1] / depth
        else:
            p_x, p_y = pc[..., 0], pc[..., 1]
        x = (p_x / (h * a) + 1.0) * width / 2.0
        y = (1.0 - p_y / h) * height / 2.0
        return x, y, depth


def _check_resolution(width, height) -> None:
    for key, value in (("width", width), ("height", height)):
        ok = isinstance(value, int | np.integer) and not isinstance(value, bool)
        require(
            ok and 1 <= value <= MAX_RESOLUTION,
            f"render.{key}: must be an integer in [1, {MAX_RESOLUTION}], got {value!r}",
        )


def downsample_box(image, factor: int) -> np.ndarray:
    """Average ``factor × factor`` blocks: the box filter that resolves a supersampled image.

    Parameters
    ----------
    image : ndarray, shape (factor·H, factor·W, ...)
        Supersampled image.
    factor : int
        Supersampling factor per axis (1 returns the image unchanged).

    Returns
    -------
    ndarray, shape (H, W, ...)

    Examples
    --------
    >>> downsample_box(np.arange(16.0).reshape(4, 4), 2)
    array([[ 2.5,  4.5],
           [10.5, 12.5]])
    """
    image = np.asarray(image)
    if factor == 1:
        return image
    H, W = image.shape[0] // factor, image.shape[1] // factor
    require(
        image.shape[0] == H * factor and image.shape[1] == W * factor,
        f"downsample_box: image of shape {image.shape[:2]} is not a multiple of {factor}",
    )
    blocks = image.reshape(H, factor, W, factor, *image.shape[2:])
    return blocks.mean(axis=(1, 3))
