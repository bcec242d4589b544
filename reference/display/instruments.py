"""Simulated light-measuring instruments: a spectroradiometer and a three-filter colorimeter.

Herbert et al. (§6) found that "only spectrometers exhibited enough sensitivity in the shadow region
to accurately calibrate the display to the given white point", and that "the colorimeters tested
were not able to hold both x and y below approximately the quartertone". The two instruments here
are our models of why (errata E51, E52):

- :class:`Spectroradiometer`: samples the spectral radiance with a triangular band pass every
  ``step_nm`` (5 nm, or 10 nm), with per-band noise ``σ = σ_dark + ρ L(λ)``; the dark part is
  absolute, so the relative error grows as the luminance falls. With both at zero it is the
  noise-free reference instrument (``ideal``).
- :class:`ReferenceMeter`: the verifier, independent of both: the emitted spectrum integrated at
  1 nm or finer without a band pass and without noise (what the display really emits). It is not
  an instrument a calibration is read with, so it is not in :data:`INSTRUMENTS`.
- :class:`Colorimeter`: three Gaussian filters that miss the CMFs, mapped to XYZ by a 3 × 3 matrix
  fitted in the factory on one display type (a CRT), so it errs on other (narrow-band) primaries;
  in the shadows an uncorrected dark offset and dark noise per filter (in cd/m² of white) take
  over, so the chromaticity fails as the luminance falls.

Every reading takes a seeded ``numpy.random.Generator``; the same seed gives the same readings.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from reference.display.spectral import (
    DISPLAY_PRIMARIES,
    SpectralDisplay,
    display_drives_to_spectra,
    spectra_to_absolute_XYZ,
)
from reference.errors import require
from reference.registry import Method, Registry

__all__ = [
    "INSTRUMENTS",
    "Colorimeter",
    "ReferenceMeter",
    "Spectroradiometer",
    "colorimeter",
    "spectroradiometer",
    "spectroradiometer_ideal",
]


def _band_pass(wavelengths_nm: np.ndarray, step_nm: float) -> tuple[np.ndarray, np.ndarray]:
    """Centres every ``step_nm`` and the triangular band pass (n_centres, n), rows sum to 1."""
    w = np.asarray(wavelengths_nm, dtype=np.float64)
    return _band_pass_on(w.tobytes(), float(step_nm))


@lru_cache(maxsize=32)
def _band_pass_on(grid: bytes, step_nm: float) -> tuple[np.ndarray, np.ndarray]:
    w = np.frombuffer(grid, dtype=np.float64)
    centres = np.arange(w[0], w[-1] + 1e-9, step_nm)
    weights = np.maximum(1.0 - np.abs(w[None, :] - centres[:, None]) / step_nm, 0.0)
    weights /= weights.sum(axis=1, keepdims=True)
    centres.flags.writeable = weights.flags.writeable = False  # shared by every call
    return centres, weights


def _each_drive_once(display: SpectralDisplay, drives, read) -> np.ndarray:
    """``read(spectra)`` of each distinct drive once, spread back to every reading, (..., k).

    Repeated readings of one patch emit the same spectrum: it is computed once, and only the
    instrument's noise differs between them.
    """
    d = np.asarray(drives, dtype=np.float64)
    if d.ndim < 2 or d.shape[-1] != 3:
        return read(display_drives_to_spectra(display, d))
    if d.ndim >= 3 and (d == d[..., :1, :]).all():  # repeated readings of each patch, as a row
        out = read(display_drives_to_spectra(display, d[..., 0, :]))
        return np.repeat(out[..., None, :], d.shape[-2], axis=-2)
    unique, inverse = np.unique(d.reshape(-1, 3), axis=0, return_inverse=True)
    out = read(display_drives_to_spectra(display, unique))
    return out[inverse.ravel()].reshape(*d.shape[:-1], out.shape[-1])


@dataclass(frozen=True)
class Spectroradiometer:
    """A spectroradiometer (see the module docstring).

    Attributes
    ----------
    step_nm : float
        Sampling interval and triangular band-pass width, nm (<= 10).
    dark_noise : float
        Absolute noise per band, W/(sr·m²·nm) (σ_dark).
    relative_noise : float
        Noise per band relative to the band's radiance (ρ).
    name : str
    """

    step_nm: float = 5.0
    dark_noise: float = 4e-6
    relative_noise: float = 0.002
    name: str = "spectro"

    def measure(self, display: SpectralDisplay, drives, rng=None) -> np.ndarray:
        """XYZ (cd/m²) read for channel drives, shape (..., 3).

        Examples
        --------
        >>> from reference.display.spectral import spectral_display
        >>> d = spectral_display()
        >>> spectroradiometer_ideal().measure(d, [1.0, 1.0, 1.0]).round(1)
        array([105.9, 120. , 111.2])
        """
        centres, band_pass = _band_pass(display.wavelengths_nm, self.step_nm)
        bands = _each_drive_once(display, drives, lambda spectra: spectra @ band_pass.T)
        if self.dark_noise > 0 or self.relative_noise > 0:
            require(rng is not None, f"{self.name}: a noisy reading needs a seeded rng")
            # Erratum E51: our noise model, σ = σ_dark + ρ L(λ) per band
            sigma = self.dark_noise + self.relative_noise * np.abs(bands)
            bands = bands + sigma * rng.standard_normal(bands.shape)
        return spectra_to_absolute_XYZ(bands, centres)


@dataclass(frozen=True)
class Colorimeter:
    """A three-filter colorimeter (see the module docstring).

    Attributes
    ----------
    centres_nm, widths_nm : tuple of 3 floats
        Gaussian filters (peak wavelength, standard deviation).
    factory_display : str
        The ``DISPLAY_PRIMARIES`` key the factory matrix is fitted on.
    dark_offset : tuple of 3 floats
        Uncorrected dark signal per filter, in cd/m² of the factory white.
    dark_noise : float
        Noise per filter, cd/m² of the factory white.
    relative_noise : float
    name : str
    """

    centres_nm: tuple = (595.0, 550.0, 448.0)
    widths_nm: tuple = (36.0, 42.0, 22.0)
    factory_display: str = "crt_brainard"
    dark_offset: tuple = (0.5, 0.0, -0.4)
    dark_noise: float = 0.1
    relative_noise: float = 0.002
    name: str = "colorimeter"

    def filters(self, wavelengths_nm) -> np.ndarray:
        """Filter sensitivities on a grid, shape (3, n), peak 1.

        Examples
        --------
        >>> colorimeter().filters([448.0, 550.0, 595.0]).round(3)
        array([[0.   , 0.458, 1.   ],
               [0.052, 1.   , 0.563],
               [1.   , 0.   , 0.   ]])
        """
        w = np.asarray(wavelengths_nm, dtype=np.float64)
        c, s = np.asarray(self.centres_nm), np.asarray(self.widths_nm)
        return np.exp(-0.5 * ((w[None, :] - c[:, None]) / s[:, None]) ** 2)

    def _signals(self, spectra, wavelengths_nm) -> np.ndarray:
        step = float(wavelengths_nm[1] - wavelengths_nm[0])
        return step * np.asarray(spectra) @ self.filters(wavelengths_nm).T

    def factory(self) -> tuple[np.ndarray, np.ndarray]:
        """The factory matrix (signals → XYZ) and each filter's signal for 1 cd/m² of white.

        Fitted exactly on the factory display's three primaries (as a colorimeter set to "CRT").

        Examples
        --------
        >>> M, unit = colorimeter().factory()
        >>> M.shape, unit.shape
        ((3, 3), (3,))
        """
        w, spectra = DISPLAY_PRIMARIES.lookup(self.factory_display).reference()
        S = self._signals(spectra, w)  # (3 primaries, 3 filters)
        XYZ = spectra_to_absolute_XYZ(spectra, w)
        M = np.linalg.solve(S, XYZ).T  # XYZ = M · s for each primary
        unit = S.sum(axis=0) / XYZ.sum(axis=0)[1]
        return M, unit

    def measure(self, display: SpectralDisplay, drives, rng=None) -> np.ndarray:
        """XYZ (cd/m²) read for channel drives, shape (..., 3).

        Examples
        --------
        >>> from reference.display.spectral import spectral_display
        >>> c = colorimeter(); rng = np.random.default_rng(1)
        >>> c.measure(spectral_display("crt_brainard"), [1.0, 1.0, 1.0], rng).round(0)
        array([111., 120., 154.])
        """
        M, unit = self.factory()
        w = display.wavelengths_nm
        signals = _each_drive_once(display, drives, lambda spectra: self._signals(spectra, w))
        # Erratum E52: the shadow failure, an uncorrected dark signal and dark noise per filter
        signals = signals + np.asarray(self.dark_offset) * unit
        if self.dark_noise > 0 or self.relative_noise > 0:
            require(rng is not None, f"{self.name}: a noisy reading needs a seeded rng")
            sigma = self.dark_noise * unit + self.relative_noise * np.abs(signals)
            signals = signals + sigma * rng.standard_normal(signals.shape)
        return signals @ M.T


@dataclass(frozen=True)
class ReferenceMeter:
    """The verification meter: the emitted spectrum integrated at ``step_nm`` or finer.

    Independent of the calibrating instruments: no band pass (the display's spectra are resampled
    linearly to ``step_nm`` where their grid is coarser, and summed with the CIE 1931 2° CMFs),
    no noise. A calibration read by the 5 nm spectroradiometer is checked against it, not against
    the noise-free version of its own band pass, which shares that instrument's error on
    narrow-band primaries.

    Attributes
    ----------
    step_nm : float
        Integration step, nm.
    name : str
    """

    step_nm: float = 1.0
    name: str = "reference"

    def measure(self, display: SpectralDisplay, drives, rng=None) -> np.ndarray:
        """XYZ (cd/m²) the display emits for channel drives, shape (..., 3).

        Examples
        --------
        >>> from reference.display.spectral import spectral_display
        >>> ReferenceMeter().measure(spectral_display(), [1.0, 1.0, 1.0]).round(1)
        array([105.8, 120. , 111. ])
        """
        spectra = display_drives_to_spectra(display, drives)
        w = display.wavelengths_nm
        if w[1] - w[0] > self.step_nm:
            fine = np.arange(w[0], w[-1] + 1e-9, self.step_nm)
            # linear resampling as one matrix: column i is the interpolant of the i-th unit vector
            resample = np.stack([np.interp(fine, w, e) for e in np.eye(w.size)])
            spectra, w = spectra @ resample, fine
        return spectra_to_absolute_XYZ(spectra, w)


def spectroradiometer() -> Spectroradiometer:
    """The default spectroradiometer: 5 nm, noise growing as the luminance falls.

    Examples
    --------
    >>> spectroradiometer().step_nm
    5.0
    """
    return Spectroradiometer()


def spectroradiometer_ideal() -> Spectroradiometer:
    """The noise-free spectroradiometer: the simulation's truth, used for the targets.

    Examples
    --------
    >>> spectroradiometer_ideal().dark_noise
    0.0
    """
    return Spectroradiometer(dark_noise=0.0, relative_noise=0.0, name="ideal")


def colorimeter() -> Colorimeter:
    """The default three-filter colorimeter (factory matrix fitted on CRT primaries).

    Examples
    --------
    >>> colorimeter().factory_display
    'crt_brainard'
    """
    return Colorimeter()


#: Instruments by the keys of the CLI (``--instrument``); ``reference()`` builds one.
INSTRUMENTS = Registry("instrument")
INSTRUMENTS.register(Method("spectro", spectroradiometer, None, "§6, Herbert et al."))
INSTRUMENTS.register(Method("colorimeter", colorimeter, None, "§6, Herbert et al."))
INSTRUMENTS.register(Method("ideal", spectroradiometer_ideal, None, "noise-free reference"))
