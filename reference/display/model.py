"""Display characterization: Eq. (1), Ferwerda, its inverse, angular falloff and screen flare.

ImpastoR's display (§3.4, Ferwerda) is characterised colorimetrically (Day, Taplin & Berns 2004):

    XYZ = L_factor(θ, φ) · P · RGB + XYZ_K(θ, φ),        Eq. (1), Ferwerda,

with ``P`` the primaries matrix with the black subtracted (columns ``XYZ_max,c − XYZ_K``),
``RGB`` the linear scalars that per-channel 11-bit look-up tables give for the digital counts,
``XYZ_K`` the black, and ``L_factor(θ, φ)`` the relative luminance at viewing zenith θ (from the
screen normal) and azimuth φ (along the screen), an elliptical paraboloid fitted to measurements
(§3.4.2). specref reads ``L_factor`` as the display's physical falloff (≤ 1 off axis) and applies it
to the black too (the black is measured on axis only); the inverse divides by it, which raises the
drive off axis as the paper describes ("the luminances of colors viewed off-axis are increased").

Front-surface reflection (§3.4.3, §3.5.1): the screen reflects the booth light diffusely
(``ρ = 0.002``) and specularly (1.1 % at the mirror angle, negligible beyond 10°, modelled as a
Gaussian in the off-mirror angle that falls to 1 % of its peak at 10°). :func:`screen_flare_XYZ`
predicts it and :func:`XYZ_to_display_counts` subtracts it before inverting.

Gamut handling of the inverse: the linear scalars are computed exactly; a colour is *out of gamut*
when a scalar falls outside ``[0, 1]`` by more than half an 11-bit step; it is then clipped per
channel (hue and lightness shift; nothing is hidden: the mask is returned and counted in Table 1).

Measurement files (JSON) are described in ``docs/impastor.md`` (:func:`load_display_measurements`);
:func:`virtual_display` builds the built-in display with the paper's figures (320 cd/m² peak white,
0.73 cd/m² black) from measurements synthesised in the same format.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- E. Day, L. Taplin, R. Berns, "Colorimetric characterization of a computer-controlled liquid
  crystal display", Color Research & Application 29(5), 2004.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.errors import SpecrefError, require, require_choice, require_finite

__all__ = [
    "GAMUT_METHODS",
    "DisplayModel",
    "XYZ_to_display_counts",
    "display_counts_to_XYZ",
    "display_from_measurements",
    "fit_lfactor",
    "lfactor",
    "load_display_measurements",
    "screen_flare_XYZ",
    "virtual_display",
    "virtual_display_measurements",
]

#: How the inverse treats colours outside the display gamut.
GAMUT_METHODS = ("clip",)


@dataclass(frozen=True)
class DisplayModel:
    """A characterised display, Eq. (1), Ferwerda.

    Attributes
    ----------
    P : ndarray, shape (3, 3)
        Columns ``XYZ_max,c − XYZ_K`` for c = R, G, B, cd/m².
    black_XYZ : ndarray, shape (3,)
        ``XYZ_K`` on axis, cd/m².
    luts : ndarray, shape (3, 2**bits)
        Linear scalar of each digital count per channel, from 0 to 1, increasing.
    lfactor_coefficients : tuple of float
        ``(c0, p, q)`` of ``L_factor = c0 − p (θ cos φ)² − q (θ sin φ)²`` (θ in radians).
    front_surface : dict
        ``diffuse`` (0.002), ``specular_peak`` (0.011), ``specular_cutoff_deg`` (10).
    name : str
        Where it came from.
    """

    P: np.ndarray
    black_XYZ: np.ndarray
    luts: np.ndarray
    lfactor_coefficients: tuple
    front_surface: dict = field(default_factory=dict)
    name: str = "display"

    @property
    def bits(self) -> int:
        """Bit depth of the look-up tables (11 in the paper)."""
        return int(np.log2(self.luts.shape[1]))

    @property
    def white_XYZ(self) -> np.ndarray:
        """Full-drive white on axis, cd/m²."""
        return self.P.sum(axis=1) + self.black_XYZ


def lfactor(model: DisplayModel, theta, phi) -> np.ndarray:
    """The angular luminance factor of Eq. (1), Ferwerda: an elliptical paraboloid in (θ, φ).

    Parameters
    ----------
    model : DisplayModel
    theta, phi : array_like
        Viewing zenith from the screen normal and azimuth along the screen, radians.

    Returns
    -------
    ndarray
        ``c0 − p (θ cos φ)² − q (θ sin φ)²``, clipped to >= 0.05.

    Examples
    --------
    >>> d = virtual_display()
    >>> float(lfactor(d, 0.0, 0.0)), round(float(lfactor(d, np.radians(30), 0.0)), 3)
    (1.0, 0.85)
    """
    c0, p, q = model.lfactor_coefficients
    theta = np.asarray(theta, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    x, y = theta * np.cos(phi), theta * np.sin(phi)
    # §3.4.2, Ferwerda: the elliptical paraboloid L_factor(θ, φ)
    return np.maximum(c0 - p * x * x - q * y * y, 0.05)


def fit_lfactor(theta, phi, Y_relative) -> tuple[float, float, float]:
    """Least-squares elliptical paraboloid ``c0 − p (θ cos φ)² − q (θ sin φ)²`` (§3.4.2, Ferwerda).

    Parameters
    ----------
    theta, phi : array_like, shape (n,)
        Measurement directions, radians.
    Y_relative : array_like, shape (n,)
        Luminance relative to on-axis.

    Returns
    -------
    (c0, p, q) : tuple of float

    Examples
    --------
    >>> t = np.radians([0, 10, 20, 30, 10, 20, 30]); f = np.radians([0, 0, 0, 0, 90, 90, 90])
    >>> Y = 1 - 0.5 * (t * np.cos(f)) ** 2 - 0.8 * (t * np.sin(f)) ** 2
    >>> np.round(fit_lfactor(t, f, Y), 6)
    array([1. , 0.5, 0.8])
    """
    theta, phi, Y = (np.asarray(v, dtype=np.float64).ravel() for v in (theta, phi, Y_relative))
    x2, y2 = (theta * np.cos(phi)) ** 2, (theta * np.sin(phi)) ** 2
    A = np.stack([np.ones_like(x2), -x2, -y2], axis=-1)
    coefficients, *_ = np.linalg.lstsq(A, Y, rcond=None)
    return tuple(float(c) for c in coefficients)


def display_counts_to_XYZ(counts, model: DisplayModel, theta=0.0, phi=0.0) -> np.ndarray:
    """XYZ (cd/m²) that the display emits for digital counts, viewed from (θ, φ).

    Eq. (1), Ferwerda: ``XYZ = L_factor(θ, φ) (P · LUT(counts) + XYZ_K)``.

    Parameters
    ----------
    counts : array_like of int, shape (..., 3)
        Digital counts in ``[0, 2**bits − 1]``.
    model : DisplayModel
    theta, phi : array_like, broadcastable to (...)
        Viewing direction, radians.

    Returns
    -------
    ndarray, shape (..., 3)

    Raises
    ------
    SpecrefError
        Counts out of range.

    Examples
    --------
    >>> d = virtual_display()
    >>> display_counts_to_XYZ([2047, 2047, 2047], d).round(1)
    array([304.2, 320. , 348.5])
    """
    counts = np.asarray(counts)
    top = model.luts.shape[1] - 1
    require(
        np.issubdtype(counts.dtype, np.integer) and counts.min() >= 0 and counts.max() <= top,
        f"display counts: must be integers in [0, {top}], got range "
        f"{counts.min()}..{counts.max()} ({counts.dtype})",
    )
    RGB = np.stack([model.luts[c][counts[..., c]] for c in range(3)], axis=-1)
    L = lfactor(model, theta, phi)[..., None]
    # Eq. (1), Ferwerda: XYZ = L_factor(θ, φ) [XYZ_max − XYZ_K] RGB + XYZ_K(θ, φ)
    return L * (RGB @ model.P.T + model.black_XYZ)


def XYZ_to_display_counts(
    XYZ,
    model: DisplayModel,
    theta=0.0,
    phi=0.0,
    flare_XYZ=None,
    gamut: str = "clip",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Digital counts that reproduce XYZ (cd/m²), the inverse of Eq. (1), Ferwerda.

    ``RGB = P⁻¹ ((XYZ − flare)/L_factor(θ, φ) − XYZ_K)``, then each scalar to the nearest count
    through the inverted look-up table.

    Parameters
    ----------
    XYZ : array_like, shape (..., 3)
        Target tristimulus values as the observer should see them, cd/m².
    model : DisplayModel
    theta, phi : array_like
        Viewing direction, radians.
    flare_XYZ : array_like, shape (..., 3), optional
        Light reflected by the screen's front surface (:func:`screen_flare_XYZ`), subtracted first
        (§3.4.3, Ferwerda).
    gamut : {"clip"}
        Out-of-gamut handling (see the module docstring).

    Returns
    -------
    counts : ndarray of int64, shape (..., 3)
    in_gamut : ndarray of bool, shape (...,)
    RGB : ndarray, shape (..., 3)
        The unclipped linear scalars.

    Examples
    --------
    >>> d = virtual_display()
    >>> counts, ok, _ = XYZ_to_display_counts(display_counts_to_XYZ([1000, 500, 1500], d), d)
    >>> counts, bool(ok)
    (array([1000,  500, 1500]), True)
    """
    require_choice(gamut, GAMUT_METHODS, "gamut handling")
    XYZ = require_finite(XYZ, "XYZ")
    target = XYZ if flare_XYZ is None else XYZ - np.asarray(flare_XYZ, dtype=np.float64)
    L = lfactor(model, theta, phi)[..., None]
    # Eq. (1), Ferwerda, inverted: RGB = P⁻¹ (XYZ/L_factor − XYZ_K)
    RGB = (target / L - model.black_XYZ) @ np.linalg.inv(model.P).T
    half_step = 0.5 / (model.luts.shape[1] - 1)
    in_gamut = ((-half_step <= RGB) & (1.0 + half_step >= RGB)).all(axis=-1)
    clipped = np.clip(RGB, 0.0, 1.0)
    counts = np.stack([_lut_inverse(model.luts[c], clipped[..., c]) for c in range(3)], axis=-1)
    return counts, in_gamut, RGB


def _lut_inverse(lut, values) -> np.ndarray:
    """Nearest count whose LUT value matches (the LUT increases strictly)."""
    upper = np.clip(np.searchsorted(lut, values), 1, lut.size - 1)
    lower = upper - 1
    pick_upper = np.abs(lut[upper] - values) < np.abs(values - lut[lower])
    return np.where(pick_upper, upper, lower).astype(np.int64)


def screen_flare_XYZ(model: DisplayModel, E_white_XYZ, L_mirror_XYZ=None, off_mirror_deg=None):
    """Light reflected by the screen's front surface, XYZ in cd/m² (§3.4.3, Ferwerda).

    Eq. (3), Ferwerda, with ``ρ_d = 0.002`` for the diffuse part (``ρ E / π``), plus a specular
    part ``1.1 % · L_mirror · exp(−½ (δ/σ)²)`` with σ such that it falls to 1 % of its peak at 10°.

    Parameters
    ----------
    model : DisplayModel
    E_white_XYZ : array_like, shape (..., 3)
        Illuminance on the screen as XYZ (lux in Y).
    L_mirror_XYZ : array_like, shape (..., 3), optional
        Radiance of the light seen in the screen's mirror direction, cd/m².
    off_mirror_deg : array_like, optional
        Angle between the viewing direction and the mirror direction, degrees.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> d = virtual_display()
    >>> screen_flare_XYZ(d, [0.0, np.pi * 100, 0.0]).round(3)
    array([0. , 0.2, 0. ])
    """
    front = model.front_surface
    E = np.asarray(E_white_XYZ, dtype=np.float64)
    # Eq. (3), Ferwerda, with ρ_d = 0.002: the screen's diffuse reflection ρ E / π
    flare = front["diffuse"] * E / np.pi
    if L_mirror_XYZ is not None:
        sigma = front["specular_cutoff_deg"] / np.sqrt(2.0 * np.log(100.0))
        delta = np.asarray(off_mirror_deg if off_mirror_deg is not None else 0.0, float)
        lobe = front["specular_peak"] * np.exp(-0.5 * (delta / sigma) ** 2)
        flare = flare + lobe[..., None] * np.asarray(L_mirror_XYZ, dtype=np.float64)
    return flare


# --- measurements --------------------------------------------------------------------------------


def _vector(doc, key, where, length=3):
    value = doc.get(key) if isinstance(doc, dict) else None
    require(value is not None, f"{where}: missing key {key!r}")
    array = require_finite(value, f"{where}: {key}")
    require(
        array.shape == (length,) if length else array.ndim == 1,
        f"{where}: {key}: must be a list of {length or 'n'} numbers, got shape {array.shape}",
    )
    return array


def display_from_measurements(doc: dict, where: str = "display measurements") -> DisplayModel:
    """Build a :class:`DisplayModel` from a measurement document (see ``docs/impastor.md``).

    Eq. (1), Ferwerda: the primaries with the black subtracted, the 11-bit LUTs from the ramps,
    and ``L_factor`` fitted to the angular measurements (:func:`fit_lfactor`).

    Parameters
    ----------
    doc : dict
        Keys ``black_XYZ``, ``primaries_XYZ`` (``R``, ``G``, ``B``: full drive, black included),
        ``ramps`` (``R``, ``G``, ``B``: ``counts`` and ``Y``), ``bits``, ``angular``
        (``theta_deg``, ``phi_deg``, ``Y_relative``), ``front_surface``.
    where : str
        The file name, for messages.

    Returns
    -------
    DisplayModel

    Raises
    ------
    SpecrefError
        A missing key, a non-monotonic ramp, counts out of range, a singular primaries matrix.

    Examples
    --------
    >>> doc = virtual_display_measurements()
    >>> doc["ramps"]["G"]["Y"][5] = 0.0
    >>> display_from_measurements(doc, "eizo.json")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: eizo.json: ramps.G.Y: must increase with the counts (a
    non-monotonic ramp cannot be inverted), got 0 after 3.08643 at index 5
    """
    require(isinstance(doc, dict), f"{where}: must be a JSON object")
    bits = doc.get("bits", 11)
    require(
        isinstance(bits, int) and 1 <= bits <= 16, f"{where}: bits: must be 1..16, got {bits!r}"
    )
    top = 2**bits - 1
    black = _vector(doc, "black_XYZ", where)
    P = _primaries_matrix(doc, black, where)
    ramps = doc.get("ramps")
    require(isinstance(ramps, dict), f"{where}: missing key 'ramps' (R, G, B)")
    luts = np.array([_ramp_lut(ramps, c, top, where) for c in "RGB"])
    coefficients = _fit_angular(doc, where)
    front = _front_surface(doc, where)
    luts.setflags(write=False)
    return DisplayModel(P, black, luts, coefficients, front, str(doc.get("name", where)))


def _primaries_matrix(doc: dict, black: np.ndarray, where: str) -> np.ndarray:
    """``P`` of Eq. (1), Ferwerda, from the measured primaries; refused if singular."""
    primaries = doc.get("primaries_XYZ")
    require(isinstance(primaries, dict), f"{where}: missing key 'primaries_XYZ' (R, G, B)")
    # Eq. (1), Ferwerda: columns XYZ_max − XYZ_K
    P = np.stack([_vector(primaries, c, f"{where}: primaries_XYZ") - black for c in "RGB"], axis=1)
    require(
        abs(np.linalg.det(P)) > 1e-9 * max(1.0, np.abs(P).max() ** 3),
        f"{where}: primaries_XYZ: the primaries are linearly dependent",
    )
    return P


def _ramp_lut(ramps: dict, c: str, top: int, where: str) -> np.ndarray:
    """Channel ``c``'s look-up table: linear scalar at every count 0..top, from its ramp."""
    ramp = ramps.get(c)
    require(isinstance(ramp, dict), f"{where}: ramps: missing channel {c!r}")
    counts = _vector(ramp, "counts", f"{where}: ramps.{c}", 0)
    Y = _vector(ramp, "Y", f"{where}: ramps.{c}", 0)
    require(
        counts.size == Y.size and counts.size >= 2,
        f"{where}: ramps.{c}: counts and Y must have the same length >= 2",
    )
    require(
        counts[0] == 0 and counts[-1] == top and (np.diff(counts) > 0).all(),
        f"{where}: ramps.{c}.counts: must increase from 0 to {top}",
    )
    steps = np.diff(Y)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0)) + 1
        raise SpecrefError(
            f"{where}: ramps.{c}.Y: must increase with the counts (a non-monotonic ramp "
            f"cannot be inverted), got {Y[i]:g} after {Y[i - 1]:g} at index {i}"
        )
    # The 11-bit LUT: normalised luminance at every count, interpolated between the steps.
    normalised = (Y - Y[0]) / (Y[-1] - Y[0])
    return np.interp(np.arange(top + 1), counts, normalised)


def _fit_angular(doc: dict, where: str) -> tuple[float, float, float]:
    """``L_factor``'s coefficients fitted to the angular measurements (:func:`fit_lfactor`)."""
    angular = doc.get("angular")
    require(isinstance(angular, dict), f"{where}: missing key 'angular'")
    theta = _vector(angular, "theta_deg", f"{where}: angular", 0)
    phi = _vector(angular, "phi_deg", f"{where}: angular", 0)
    Y_rel = _vector(angular, "Y_relative", f"{where}: angular", 0)
    require(
        theta.size == phi.size == Y_rel.size and theta.size >= 3,
        f"{where}: angular: theta_deg, phi_deg and Y_relative must have the same length >= 3",
    )
    return fit_lfactor(np.radians(theta), np.radians(phi), Y_rel)


def _front_surface(doc: dict, where: str) -> dict:
    """The front-surface reflection: the paper's figures, overridden by the document's."""
    front = {"diffuse": 0.002, "specular_peak": 0.011, "specular_cutoff_deg": 10.0}
    front.update(doc.get("front_surface", {}))
    for key, value in front.items():
        require(
            isinstance(value, int | float) and np.isfinite(value) and value >= 0,
            f"{where}: front_surface.{key}: must be a number >= 0, got {value!r}",
        )
    return front


def load_display_measurements(path) -> DisplayModel:
    """Read a display measurement file (JSON, format in ``docs/impastor.md``).

    Examples
    --------
    >>> import tempfile, os, json
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "display.json")
    ...     _ = open(p, "w").write(json.dumps(virtual_display_measurements()))
    ...     round(float(load_display_measurements(p).white_XYZ[1]), 6)
    320.0
    """
    from reference.files import read_json

    doc = read_json(path, "JSON display measurement file")
    return display_from_measurements(doc, str(path))


def virtual_display_measurements(
    peak_cd_m2: float = 320.0, black_cd_m2: float = 0.73, gamma: float = 2.2
) -> dict:
    """Synthetic measurements of the built-in virtual display, in the file format.

    The paper's figures (§3.4.1, Ferwerda): 320 cd/m² peak white, 0.73 cd/m² black (438:1), 11-bit
    tables. Primaries and white point are sRGB's (D65); ramps follow a 2.2 power law measured at
    33 levels; the angular falloff is 15 % at 30° in landscape and 20 % at 30° in portrait (the
    shape of Fig. 9), measured at 5° steps over ±30°.

    Examples
    --------
    >>> doc = virtual_display_measurements()
    >>> doc["bits"], len(doc["ramps"]["R"]["counts"]), doc["black_XYZ"][1]
    (11, 33, 0.73)
    """
    import colour

    space = colour.RGB_COLOURSPACES["sRGB"]
    M = np.asarray(space.matrix_RGB_to_XYZ, dtype=np.float64)  # columns: primaries, Y sums to 1
    white = colour.xy_to_XYZ(space.whitepoint)
    black = white * black_cd_m2
    span = peak_cd_m2 - black_cd_m2
    primaries = {c: (M[:, i] * span + black).tolist() for i, c in enumerate("RGB")}
    top = 2**11 - 1
    counts = np.round(np.linspace(0, top, 33)).astype(int)
    ramps = {}
    for i, c in enumerate("RGB"):
        Y = black[1] + M[1, i] * span * (counts / top) ** gamma
        ramps[c] = {"counts": counts.tolist(), "Y": Y.tolist()}
    angles = np.arange(-30, 31, 5)
    theta = np.abs(angles).astype(float)
    landscape = 1.0 - 0.15 * (theta / 30.0) ** 2
    portrait = 1.0 - 0.20 * (theta / 30.0) ** 2
    phi_land = np.where(angles < 0, 180.0, 0.0)
    phi_port = np.where(angles < 0, 270.0, 90.0)
    return {
        "name": "virtual display (ImpastoR figures: 320 cd/m² white, 0.73 cd/m² black)",
        "bits": 11,
        "black_XYZ": black.tolist(),
        "primaries_XYZ": primaries,
        "ramps": ramps,
        "angular": {
            "theta_deg": np.concatenate([theta, theta]).tolist(),
            "phi_deg": np.concatenate([phi_land, phi_port]).tolist(),
            "Y_relative": np.concatenate([landscape, portrait]).tolist(),
        },
        "front_surface": {"diffuse": 0.002, "specular_peak": 0.011, "specular_cutoff_deg": 10.0},
    }


def virtual_display() -> DisplayModel:
    """The built-in virtual display (320 cd/m² white, 0.73 cd/m² black, sRGB primaries).

    Eq. (1), Ferwerda, built from :func:`virtual_display_measurements`.

    Examples
    --------
    >>> d = virtual_display()
    >>> d.bits, round(float(d.white_XYZ[1] / d.black_XYZ[1]), 1)
    (11, 438.4)
    """
    return display_from_measurements(virtual_display_measurements(), "virtual display")
