"""Six-channel multispectral colour: sampling functions, channel products and the 3×N matrix.

ImpastoR (Ferwerda 2015, §3.1.1, Fig. 3) replaces spectra by a few channel values. Each channel
k has a sampling function s_k(λ); a reflectance R and a light S become

    R6_k = Σ_λ R(λ) s_k(λ),   S6_k = Σ_λ S(λ) s_k(λ),   U6 = R6 ⊙ S6,   XYZ = M · U6,

with one 3×N matrix M shared by all lights (Fig. 3, Ferwerda). "Six is not a magic number": the
channel count N is a parameter (3 … 10 ship with specref).

Conventions
-----------
- Sampling functions live on the 5 nm grid 380-780 nm (:data:`MS_GRID`, 81 samples), the native
  grid of the CIE illuminants and of the ColorChecker N Ohta data, and are normalised to
  ``Σ_λ s_k(λ) = 1``: a perfect white (R = 1) has ``R6 = 1`` in every channel.
- A light is normalised photometrically before sampling (``Σ_λ S(λ) ȳ_E(λ) = 1`` with the
  equal-energy band weights): the "normalized multispectral illumination representation" of
  Eq. (3), Ferwerda. XYZ then has Y ≈ 1 for a perfect white under any light (exactly 1 only for the
  5 nm truth), matching specref's Y = 1 convention.

Designs are a registry, :data:`MULTISPECTRAL_DESIGNS`: ``box`` (contiguous boxes with optimised
band edges, the paper-level baseline) and ``optimized`` (non-negative smooth functions fitted
jointly with M). Both are fitted by ``validation/precompute/impastor_designs.py`` on reflectance
sets that colour-science ships, with ColorChecker look-alikes removed, under D65, D50 and A, and
are shipped as package data in ``impastor/data/designs.json``.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- B. Darling, Ph.D. dissertation, Rochester Institute of Technology, 2013.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from reference.colour.spectra import SpectralGrid, Spectrum, resample_spectrum
from reference.errors import require, require_nonnegative
from reference.registry import Method, Registry

__all__ = [
    "DESIGNS_FILE",
    "MIN_CHANNELS",
    "MS_GRID",
    "MULTISPECTRAL_DESIGNS",
    "SamplingDesign",
    "box_sampling_functions",
    "channels_to_XYZ",
    "design_box",
    "design_optimized",
    "light_to_channels",
    "load_design",
    "render_channels",
    "spectra_to_channels",
]

#: The 5 nm grid of the sampling functions (380-780 nm, 81 samples).
MS_GRID = SpectralGrid(380.0, 780.0, 5.0)
#: Fewest channels a design may have (three are needed to reach XYZ at all).
MIN_CHANNELS = 3
#: The fitted designs, written by ``validation/precompute/impastor_designs.py``.
DESIGNS_FILE = Path(__file__).with_name("data") / "designs.json"


@dataclass(frozen=True)
class SamplingDesign:
    """A set of N sampling functions and the 3×N matrix to XYZ.

    Attributes
    ----------
    name : str
        Registry key (``"box"``, ``"optimized"``).
    s : ndarray, shape (N, 81)
        Sampling functions on :data:`MS_GRID`, non-negative, each summing to 1.
    M : ndarray, shape (3, N)
        Channel products to XYZ (Y ≈ 1 for a perfect white).
    meta : dict
        Provenance (edges for boxes, fit statistics).
    """

    name: str
    s: np.ndarray
    M: np.ndarray
    meta: dict

    @property
    def n_channels(self) -> int:
        """N, the number of channels."""
        return self.s.shape[0]


def box_sampling_functions(edges_nm) -> np.ndarray:
    """Box sampling functions between consecutive band edges, on :data:`MS_GRID`.

    A 5 nm cell ``[λ − 2.5, λ + 2.5]`` that an edge cuts is shared in proportion to its overlap, so
    the functions move continuously with the edges.

    Parameters
    ----------
    edges_nm : array_like, shape (N + 1,)
        Increasing band edges, nm; the first is usually 380 and the last 780.

    Returns
    -------
    ndarray, shape (N, 81)
        Each row sums to 1.

    Raises
    ------
    SpecrefError
        Fewer than :data:`MIN_CHANNELS` boxes, edges not increasing, or an empty box.

    Examples
    --------
    >>> s = box_sampling_functions([380, 500, 600, 780])
    >>> s.shape, s.sum(axis=1).round(12)
    ((3, 81), array([1., 1., 1.]))
    """
    edges = np.asarray(edges_nm, dtype=np.float64)
    require(
        edges.ndim == 1 and edges.size - 1 >= MIN_CHANNELS,
        f"box design: needs at least {MIN_CHANNELS} channels (N + 1 edges), got {edges.size - 1}",
    )
    require(bool((np.diff(edges) > 0).all()), f"box design: edges must increase, got {edges}")
    wl = MS_GRID.wavelengths_nm
    half = MS_GRID.step_nm / 2.0
    lo = np.maximum(wl[None, :] - half, edges[:-1, None])
    hi = np.minimum(wl[None, :] + half, edges[1:, None])
    coverage = np.clip(hi - lo, 0.0, None)
    area = coverage.sum(axis=1, keepdims=True)
    require(bool((area > 0).all()), f"box design: a box lies outside 380-780 nm: {edges}")
    return coverage / area


def _spectra_on_grid(spectra, where: str) -> np.ndarray:
    """Spectra as an array on :data:`MS_GRID`: Spectrum objects are resampled (constant ends)."""
    if isinstance(spectra, Spectrum):
        return resample_spectrum(spectra, MS_GRID, extrapolation="constant")
    if isinstance(spectra, list | tuple) and spectra and isinstance(spectra[0], Spectrum):
        return np.stack([_spectra_on_grid(s, where) for s in spectra])
    values = require_nonnegative(spectra, where)
    require(
        values.shape[-1:] == (MS_GRID.n_bands,),
        f"{where}: spectra must be sampled on {MS_GRID.label} ({MS_GRID.n_bands} values last), "
        f"got shape {values.shape}",
    )
    return values


def spectra_to_channels(spectra, design: SamplingDesign) -> np.ndarray:
    """Channel values of reflectance spectra: ``R6_k = Σ_λ R(λ) s_k(λ)``.

    Fig. 3, Ferwerda (the R6ch representation).

    Parameters
    ----------
    spectra : Spectrum, list of Spectrum, or array_like, shape (..., 81)
        Reflectance factors; arrays must be on :data:`MS_GRID`.
    design : SamplingDesign
        The sampling functions.

    Returns
    -------
    ndarray, shape (..., N)

    Examples
    --------
    >>> d = design_box(6)
    >>> spectra_to_channels(np.full(81, 0.5), d).round(12)
    array([0.5, 0.5, 0.5, 0.5, 0.5, 0.5])
    """
    R = _spectra_on_grid(spectra, "reflectance")
    # Fig. 3, Ferwerda: R6_k = ∫ R(λ) s_k(λ) dλ
    return R @ design.s.T


def light_to_channels(light, design: SamplingDesign) -> np.ndarray:
    """Channel values of a light, photometrically normalised: ``S6_k = Σ_λ S(λ) s_k(λ)``.

    Eq. (3), Ferwerda (the normalised multispectral illumination ``S_j``).

    Parameters
    ----------
    light : Spectrum or array_like, shape (..., 81)
        Relative spectral power; scaled so that ``Σ S ȳ_E = 1`` first.
    design : SamplingDesign

    Returns
    -------
    ndarray, shape (..., N)

    Raises
    ------
    SpecrefError
        A light with no visible power.

    Examples
    --------
    >>> from reference.colour.spectra import spectrum_from_dataset
    >>> d = design_box(6)
    >>> S6 = light_to_channels(spectrum_from_dataset("illuminant", "D65"), d)
    >>> float(channels_to_XYZ(S6, d)[1]).__round__(2)
    1.0
    """
    from reference.colour.colorimetry import band_weights

    S = _spectra_on_grid(light, "light")
    y_bar = band_weights(MS_GRID, None)[:, 1]
    luminance = S @ y_bar
    require(bool((luminance > 0).all()), "light: has no visible power (Y = 0)")
    S = S / np.asarray(luminance)[..., None]
    # Fig. 3, Ferwerda: S6_k = ∫ S(λ) s_k(λ) dλ
    return S @ design.s.T


def channels_to_XYZ(U, design: SamplingDesign) -> np.ndarray:
    """XYZ from channel products ``U6 = R6 ⊙ S6``: ``XYZ = M · U6``.

    Fig. 3, Ferwerda (the 3×6 matrix).

    Parameters
    ----------
    U : array_like, shape (..., N)
        Channel products (or any channel values, e.g. rendered radiance).
    design : SamplingDesign

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> d = design_box(6)
    >>> channels_to_XYZ(np.zeros(6), d)
    array([0., 0., 0.])
    """
    U = np.asarray(U, dtype=np.float64)
    require(
        U.shape[-1:] == (design.n_channels,),
        f"channels_to_XYZ: expected {design.n_channels} channels last, got shape {U.shape}",
    )
    # Fig. 3, Ferwerda: XYZ = M · U6
    return U @ design.M.T


def render_channels(reflectance, light, design: SamplingDesign) -> np.ndarray:
    """XYZ of reflectances under a light through the N-channel pipeline.

    Fig. 3, Ferwerda: ``XYZ = M · (R6 ⊙ S6)``.

    Parameters
    ----------
    reflectance : Spectrum, list of Spectrum or array_like, shape (..., 81)
    light : Spectrum or array_like, shape (81,)
    design : SamplingDesign

    Returns
    -------
    ndarray, shape (..., 3)
        XYZ, Y ≈ 1 for a perfect white.

    Examples
    --------
    >>> from reference.colour.spectra import spectrum_from_dataset
    >>> d = design_optimized(6)
    >>> XYZ = render_channels(np.ones(81), spectrum_from_dataset("illuminant", "A"), d)
    >>> XYZ.round(2)
    array([1.1 , 1.  , 0.36])
    """
    U = spectra_to_channels(reflectance, design) * light_to_channels(light, design)
    return channels_to_XYZ(U, design)


@lru_cache(maxsize=1)
def _designs_json() -> dict:
    require(
        DESIGNS_FILE.is_file(),
        f"{DESIGNS_FILE}: missing; run python -m validation.precompute.impastor_designs",
    )
    return json.loads(DESIGNS_FILE.read_text())


def load_design(name: str, n_channels: int = 6) -> SamplingDesign:
    """A fitted design from :data:`DESIGNS_FILE`.

    Parameters
    ----------
    name : {"box", "optimized"}
        The design family.
    n_channels : int
        N; the file holds 3 … 10.

    Returns
    -------
    SamplingDesign

    Raises
    ------
    SpecrefError
        ``n_channels`` below 3 or not in the file.

    Examples
    --------
    >>> load_design("box", 6).n_channels
    6
    >>> load_design("box", 2)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: multispectral design 'box': channel count must be >= 3, got 2
    """
    require(
        isinstance(n_channels, int | np.integer) and n_channels >= MIN_CHANNELS,
        f"multispectral design {name!r}: channel count must be >= {MIN_CHANNELS}, "
        f"got {n_channels!r}",
    )
    family = _designs_json()["designs"][name]
    require(
        str(n_channels) in family,
        f"{DESIGNS_FILE.name}: designs.{name}: no {n_channels}-channel design; "
        f"allowed: {', '.join(sorted(family, key=int))}",
    )
    entry = family[str(n_channels)]
    M = np.asarray(entry["M"], dtype=np.float64)
    if "edges_nm" in entry:
        s = box_sampling_functions(entry["edges_nm"])
    else:
        s = np.asarray(entry["s"], dtype=np.float64)
    s.setflags(write=False)
    M.setflags(write=False)
    meta = {k: v for k, v in entry.items() if k not in ("s", "M")}
    return SamplingDesign(name, s, M, meta)


def design_box(n_channels: int = 6) -> SamplingDesign:
    """The ``box`` design: contiguous boxes with fitted band edges and one fitted M.

    Fig. 3, Ferwerda (box sampling functions, the paper-level baseline).

    Examples
    --------
    >>> d = design_box(6)
    >>> d.s.shape, d.M.shape
    ((6, 81), (3, 6))
    """
    return load_design("box", n_channels)


def design_optimized(n_channels: int = 6) -> SamplingDesign:
    """The ``optimized`` design: smooth non-negative functions fitted jointly with M.

    Fig. 3, Ferwerda ("optimized sampling functions").

    Examples
    --------
    >>> d = design_optimized(6)
    >>> bool((d.s >= 0).all()), d.s.sum(axis=1).round(9).tolist() == [1.0] * 6
    (True, True)
    """
    return load_design("optimized", n_channels)


def _design_example(rng):
    return (6,)


#: Channel designs by key; ``reference(n_channels)`` returns a :class:`SamplingDesign`.
MULTISPECTRAL_DESIGNS = Registry("multispectral design")
MULTISPECTRAL_DESIGNS.register(
    Method("box", design_box, None, "Fig. 3, Ferwerda (box functions)", _design_example)
)
MULTISPECTRAL_DESIGNS.register(
    Method("optimized", design_optimized, None, "Fig. 3, Ferwerda (fitted)", _design_example)
)
