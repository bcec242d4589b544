"""ImpastoR colour validation (§3.1, §3.4, §5.1, Ferwerda): Table 1, channels, metamers, display.

The colour half of what the ``specref impastor`` command and the report's "ImpastoR" section show;
the lighting half (the booth, the painting, gloss curves, shadows, the hybrid) is
``validation.studies.impastor_lighting``:

- :func:`table1`: the ColorChecker under D65, D50 and A, six-channel simulation against the 5 nm
  spectral truth, and the "screen output" through the virtual display with out-of-gamut patches
  counted and listed (Table 1, Ferwerda).
- :func:`channel_count_errors`, :func:`naive_rgb_delta_E`: accuracy against the channel count and
  the RGB-product baseline; lights outside the fit (FL2, a white LED) are reported too.
- :func:`metamer_pair`, :func:`metamer_delta_E`: two reflectances that match under A and differ
  under D65 (Fig. 4, Ferwerda).
- :func:`display_round_trip`: digital counts → XYZ → counts, and XYZ → counts → XYZ, through the
  display model (Eq. (1), Ferwerda, and its inverse).
"""

from __future__ import annotations

import functools

import numpy as np

from impastor.multispectral import (
    MS_GRID,
    MULTISPECTRAL_DESIGNS,
    channels_to_XYZ,
    light_to_channels,
    spectra_to_channels,
)
from reference.colour.colorimetry import XYZ_to_display_RGB, XYZ_to_Lab, delta_E_00
from reference.colour.spectra import resample_spectrum, spectrum_from_dataset
from reference.display.model import (
    XYZ_to_display_counts,
    display_counts_to_XYZ,
    screen_flare_XYZ,
    virtual_display,
)
from reference.errors import require
from reference.tasks import SERIAL, run_tasks
from validation.studies.metrics import colorchecker_truth, delta_E_stats

__all__ = [
    "EXTRA_LIGHTS",
    "LIGHTS",
    "channel_count_errors",
    "colorchecker_truth_cached",
    "design_delta_E",
    "display_round_trip",
    "metamer_delta_E",
    "metamer_pair",
    "naive_rgb_delta_E",
    "table1",
]

#: The booth lights of the paper (and of the fit).
LIGHTS = ("D65", "D50", "A")
#: Lights not used in the fit, reported without a target.
EXTRA_LIGHTS = ("FL2", "LED-B3")


@functools.lru_cache(maxsize=32)
def colorchecker_truth_cached(light: str):
    """:func:`~validation.studies.metrics.colorchecker_truth`, cached per light (do not modify it).

    Examples
    --------
    >>> colorchecker_truth_cached("A") is colorchecker_truth_cached("A")
    True
    """
    return colorchecker_truth(light)


def _lab_delta_E(XYZ, XYZ_true, white) -> np.ndarray:
    return np.asarray(delta_E_00(XYZ_to_Lab(XYZ, white), XYZ_to_Lab(XYZ_true, white)))


def _cc_on_grid(patches) -> np.ndarray:
    from reference.colour.spectra import make_spectrum

    return np.stack(
        [
            resample_spectrum(make_spectrum(sd.wavelengths, sd.values, name), MS_GRID)
            for name, sd in patches.items()
        ]
    )


def design_delta_E(design: str = "optimized", n_channels: int = 6, light: str = "D65"):
    """ΔE00 per ColorChecker patch: the N-channel pipeline against the 5 nm spectral truth.

    Fig. 3, Ferwerda (``XYZ = M · (R6 ⊙ S6)``) against ``colour.sd_to_XYZ`` on the N Ohta data,
    both in CIELAB relative to the true white under the light.

    Parameters
    ----------
    design : str
        A key of :data:`impastor.multispectral.MULTISPECTRAL_DESIGNS`.
    n_channels : int
        N (3 … 10).
    light : str
        A colour-science illuminant key.

    Returns
    -------
    ndarray, shape (24,)

    Examples
    --------
    >>> float(design_delta_E("optimized", 6, "D65").mean()) < 0.25
    True
    """
    d = MULTISPECTRAL_DESIGNS.lookup(design).reference(n_channels)
    patches, truth, white = colorchecker_truth_cached(light)
    R = _cc_on_grid(patches)
    # Fig. 3, Ferwerda: XYZ = M · (R6 ⊙ S6)
    U = spectra_to_channels(R, d) * light_to_channels(spectrum_from_dataset("illuminant", light), d)
    return _lab_delta_E(channels_to_XYZ(U, d), truth, white)


def naive_rgb_delta_E(light: str = "A") -> np.ndarray:
    """ΔE00 per patch of the naive RGB product: sRGB(reflectance) × sRGB(light), to XYZ.

    The reflectance's linear sRGB is its colour under D65 (white = 1, 1, 1); the light's is its
    white point with Y = 1; their product is taken back to XYZ. This is the "products of
    normalized RGB values" that §3.1.1, Ferwerda, warns about.

    Examples
    --------
    >>> float(naive_rgb_delta_E("D65").mean()) < 0.5
    True
    """
    _, truth_d65, _ = colorchecker_truth_cached("D65")
    _, truth, white = colorchecker_truth_cached(light)
    rgb_reflectance = XYZ_to_display_RGB(truth_d65)
    rgb_light = XYZ_to_display_RGB(white)
    from reference.colour.colorimetry import display_RGB_to_XYZ

    XYZ = display_RGB_to_XYZ(rgb_reflectance * rgb_light)
    return _lab_delta_E(XYZ, truth, white)


def channel_count_errors(designs=None, counts=range(3, 11), lights=LIGHTS + EXTRA_LIGHTS) -> dict:
    """Mean and max ΔE00 on the ColorChecker for each design, channel count and light.

    Parameters
    ----------
    designs : sequence of str, optional
        Keys of :data:`impastor.multispectral.MULTISPECTRAL_DESIGNS`; default all of them.
    counts : sequence of int
        Channel counts N (3 … 10).
    lights : sequence of str
        Colour-science illuminant keys.

    Returns
    -------
    dict
        ``[design][str(N)][light]``: ΔE00 statistics (mean, std, p90, max).

    Examples
    --------
    >>> table = channel_count_errors(["box"], [6], ["D65"])
    >>> sorted(table["box"]["6"]["D65"])
    ['max', 'mean', 'p90', 'std']
    """
    out: dict = {}
    for design in MULTISPECTRAL_DESIGNS.names() if designs is None else designs:
        out[design] = {}
        for n in counts:
            out[design][str(n)] = {
                light: delta_E_stats(design_delta_E(design, int(n), light)) for light in lights
            }
    return out


def _table1_light(cell: tuple) -> tuple[list[dict], dict]:
    """One light of :func:`table1` (a task): its rows and its per-light record."""
    light, d, white_luminance, display = cell
    rows = []
    patches, truth, white = colorchecker_truth_cached(light)
    names = list(patches)
    S6 = light_to_channels(spectrum_from_dataset("illuminant", light), d)
    XYZ_sim = channels_to_XYZ(spectra_to_channels(_cc_on_grid(patches), d) * S6, d)
    dE_sim = _lab_delta_E(XYZ_sim, truth, white)
    # Screen output: absolute luminance, booth-light flare off the screen, Eq. (1), Ferwerda.
    white_abs = white * white_luminance
    flare = screen_flare_XYZ(display, white * white_luminance * np.pi)
    counts, in_gamut, _ = XYZ_to_display_counts(XYZ_sim * white_luminance, display, 0, 0, flare)
    shown = display_counts_to_XYZ(counts, display) + flare
    dE_screen = _lab_delta_E(shown, truth * white_luminance, white_abs)
    out_names = [n for n, ok in zip(names, in_gamut, strict=True) if not ok]
    entry = {
        "out_of_gamut": out_names,
        "simulation_delta_E00": dE_sim.tolist(),
        "screen_delta_E00": dE_screen.tolist(),
    }
    rows.append(
        {
            "label": f"{light} (24)",
            "light": light,
            "n": 24,
            "simulation": delta_E_stats(dE_sim),
            "screen": delta_E_stats(dE_screen),
        }
    )
    if out_names:
        keep = np.asarray(in_gamut)
        rows.append(
            {
                "label": f"{light} ({int(keep.sum())})",
                "light": light,
                "n": int(keep.sum()),
                "simulation": delta_E_stats(dE_sim[keep]),
                "screen": delta_E_stats(dE_screen[keep]) if keep.any() else None,
            }
        )
    return rows, entry


def table1(
    design: str = "optimized",
    n_channels: int = 6,
    white_luminance: float = 200.0,
    display=None,
    lights=LIGHTS,
    scheduler: str | None = None,
) -> dict:
    """Table 1, Ferwerda: six-channel simulation and screen output against the spectral truth.

    For each light: the ColorChecker through the N-channel pipeline, compared with the 5 nm truth
    (the "six channel simulation" columns); then scaled so that the white has ``white_luminance``
    cd/m², inverted through the display model with the screen's diffuse flare subtracted, shown
    (Eq. (1), Ferwerda, plus the flare) and compared again ("screen output"). Patches outside the
    display gamut are counted and listed, and the statistics are repeated for the in-gamut ones.

    Parameters
    ----------
    design : str
        Channel design.
    n_channels : int
        N.
    white_luminance : float
        Luminance of the perfect white under the booth light, cd/m² (the booth illuminance is
        ``π`` times it).
    display : DisplayModel, optional
        Default: :func:`reference.display.model.virtual_display`.
    lights : sequence of str
    scheduler : str, optional
        Each light is one task of :func:`reference.tasks.run_tasks` (an address, ``"local"`` or
        ``"serial"``; default ``$SPECREF_SCHEDULER``, else serial: a light takes well under a
        second, less than a local cluster takes to start).

    Returns
    -------
    dict
        ``rows``: one per light and patch set, with ``simulation`` and ``screen`` statistics
        (mean, std, p90, max), ``n``, and per light the out-of-gamut patch names.

    Examples
    --------
    >>> t = table1(lights=("D65",))
    >>> t["rows"][0]["label"], t["rows"][0]["n"]
    ('D65 (24)', 24)
    """
    require(
        np.isfinite(white_luminance) and white_luminance > 0,
        f"table1: white_luminance: must be > 0 cd/m², got {white_luminance}",
    )
    display = display or virtual_display()
    d = MULTISPECTRAL_DESIGNS.lookup(design).reference(n_channels)
    cells = [(light, d, white_luminance, display) for light in lights]
    found = run_tasks(_table1_light, cells, scheduler, progress=False, default=SERIAL)
    rows = [row for light_rows, _ in found for row in light_rows]
    per_light = {light: entry for light, (_, entry) in zip(lights, found, strict=True)}
    return {
        "design": design,
        "n_channels": n_channels,
        "white_luminance_cd_m2": white_luminance,
        "display": display.name,
        "rows": rows,
        "lights": per_light,
    }


# --- metamers (Fig. 4) ----------------------------------------------------------------------------


def metamer_pair(
    match: str = "A", differ: str = "D65", base: float = 0.45, delta_E_differ: float = 4.0
) -> tuple:
    """Two reflectances that match under ``match`` and differ under ``differ`` (Fig. 4, Ferwerda).

    The second is a flat gray plus a smooth *metameric black* for the ``match`` light: a
    combination of the cosines ``cos(kπx)``, k = 1 … 6, over 380-780 nm that lies in the null space
    of the ``match`` light's band weights (its XYZ there is exactly zero) and, among those, changes
    the colour under ``differ`` the most per unit size. It is scaled so that the true difference
    under ``differ`` is ``delta_E_differ`` ΔE00.

    Returns
    -------
    R1, R2 : ndarray, shape (81,)
        On :data:`impastor.multispectral.MS_GRID`.

    Examples
    --------
    >>> from reference.colour.colorimetry import band_weights
    >>> R1, R2 = metamer_pair()
    >>> W_A = band_weights(MS_GRID, spectrum_from_dataset("illuminant", "A"))
    >>> bool(np.allclose(R1 @ W_A, R2 @ W_A, atol=1e-12)), bool(R2.min() > 0)
    (True, True)
    """
    from scipy.optimize import brentq

    from reference.colour.colorimetry import band_weights

    W_match = band_weights(MS_GRID, spectrum_from_dataset("illuminant", match))
    W_differ = band_weights(MS_GRID, spectrum_from_dataset("illuminant", differ))
    x = np.linspace(0.0, 1.0, MS_GRID.n_bands)
    basis = np.stack([np.cos(k * np.pi * x) for k in range(1, 7)], axis=-1)
    # The null space of W_match within the basis: metameric blacks for the `match` light.
    _, _, vt = np.linalg.svd(W_match.T @ basis)
    null = vt[3:].T
    # Among them, the one that moves the `differ` colour most.
    _, _, vt = np.linalg.svd(W_differ.T @ basis @ null)
    black = basis @ (null @ vt[0])
    black /= np.abs(black).max()
    R1 = np.full(MS_GRID.n_bands, base)
    white = W_differ.sum(axis=0)

    def excess(k):
        return (
            float(_lab_delta_E(R1 @ W_differ, (R1 + k * black) @ W_differ, white)) - delta_E_differ
        )

    k = brentq(excess, 1e-6, min(base, 1.0 - base))
    return R1, R1 + k * black


def metamer_delta_E(design: str = "optimized", n_channels: int = 6, lights=("A", "D65")) -> dict:
    """ΔE00 between the two metamers as rendered by the N-channel pipeline, and truly, per light.

    Examples
    --------
    >>> result = metamer_delta_E()
    >>> result["A"]["pipeline"] < 0.5 < 3.0 < result["D65"]["pipeline"]
    True
    """
    from reference.colour.colorimetry import band_weights

    R1, R2 = metamer_pair()
    d = MULTISPECTRAL_DESIGNS.lookup(design).reference(n_channels)
    out = {}
    for light in lights:
        spectrum = spectrum_from_dataset("illuminant", light)
        W = band_weights(MS_GRID, spectrum)
        white = W.sum(axis=0)
        S6 = light_to_channels(spectrum, d)
        XYZ = channels_to_XYZ(spectra_to_channels(np.stack([R1, R2]), d) * S6, d)
        out[light] = {
            "pipeline": float(_lab_delta_E(XYZ[0], XYZ[1], white)),
            "truth": float(_lab_delta_E(R1 @ W, R2 @ W, white)),
            "XYZ": XYZ.tolist(),
        }
    return out


# --- the display round trip (Eq. (1), Ferwerda) ---------------------------------------------------


def display_round_trip(display=None, n: int = 500, seed: int = 0) -> dict:
    """Round trips through the display model, Eq. (1), Ferwerda, and its inverse.

    Two round trips, on and off axis (θ = 25°, φ = 60°): random digital counts → XYZ → counts
    (exact, since the inverse searches the 11-bit LUTs), and random in-gamut XYZ → counts → XYZ
    (within one step of the steepest LUT segment per channel, the quantisation bound).

    Parameters
    ----------
    display : DisplayModel, optional
        Default: :func:`reference.display.model.virtual_display`.
    n : int
        Random samples per round trip.
    seed : int
        Seed of the samples.

    Returns
    -------
    dict
        ``counts_mismatches`` (counts that do not come back, of ``n_counts``),
        ``XYZ_error_over_bound`` (largest XYZ error over the quantisation bound; ≤ 1 holds),
        ``out_of_gamut`` (in-gamut samples flagged out of gamut).

    Examples
    --------
    >>> r = display_round_trip(n=50)
    >>> r["counts_mismatches"], r["out_of_gamut"], bool(r["XYZ_error_over_bound"] <= 1)
    (0, 0, True)
    """
    display = display or virtual_display()
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 2048, size=(n, 3))
    mismatches, flagged = 0, 0
    for theta, phi in ((0.0, 0.0), (np.radians(25.0), np.radians(60.0))):
        XYZ = display_counts_to_XYZ(counts, display, theta, phi)
        back, in_gamut, _ = XYZ_to_display_counts(XYZ, display, theta, phi)
        mismatches += int((back != counts).any(axis=-1).sum())
        flagged += int((~in_gamut).sum())
    RGB = rng.uniform(0.05, 0.95, size=(n, 3))
    XYZ = RGB @ display.P.T + display.black_XYZ
    counts_back, in_gamut, _ = XYZ_to_display_counts(XYZ, display)
    shown = display_counts_to_XYZ(counts_back, display)
    # One 11-bit step of the steepest LUT segment bounds the error per channel.
    bound = np.diff(display.luts, axis=1).max() * np.abs(display.P).sum(axis=1).max()
    return {
        "n_counts": 2 * n,
        "counts_mismatches": mismatches,
        "XYZ_error_over_bound": float(np.abs(shown - XYZ).max() / bound),
        "out_of_gamut": flagged + int((~in_gamut).sum()),
    }
