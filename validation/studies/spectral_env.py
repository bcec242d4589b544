"""Studies of spectral environments (Herbert et al., §4): the regression against the upsamplers.

Every figure is measured on the synthetic target of ``reference.colour.spectral_target``: the model
is fitted on the training set (rawtoaces-190 minus look-alikes) and measured on the held-out sets it
never saw (ColorChecker N Ohta, CIE 2024 TCS, NIST CQS 9.0), in ΔE94 under the capture illuminant
(D65) and relit under A, both from 41-band spectra with specref's E308 band weights and the white
diffuser under that illuminant as the Lab white.
"""

from __future__ import annotations

import copy
import functools
from typing import NamedTuple

import numpy as np

from reference.colour.colorimetry import XYZ_to_Lab, band_weights, white_XYZ
from reference.colour.spectra import GRID_41, spectrum_from_dataset
from reference.colour.spectral_regression import (
    DEFAULT_LOSS,
    REGRESSION_FEATURES,
    features_RGB,
    fit_regression,
)
from reference.colour.spectral_target import (
    DEFAULT_AUGMENTATION,
    HELD_OUT_SETS,
    TARGET_AUGMENTATIONS,
    TRAINING_SET,
    camera_noise,
    camera_RGB,
    reflectance_set,
)
from reference.errors import require

CAMERA = "Nikon 5100 (NPL)"
LIGHTS = ("D65", "A")
#: The colour.recovery upsamplers compared (colour-science method names).
RECOVERY_METHODS = ("Jakob 2019", "Mallett 2019", "Otsu 2018", "Smits 1999")
NOISE_SEED = 15


def delta_E94_spectra(truth, estimate, illuminant: str) -> np.ndarray:
    """ΔE94 between spectra (41 bands) under an illuminant; Lab white = that illuminant's.

    Examples
    --------
    >>> S = np.full((1, 41), 0.5)
    >>> delta_E94_spectra(S, S * 1.01, "A").round(2)
    array([0.31])
    """
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", illuminant))
    return _delta_E94_XYZ(np.asarray(truth) @ W, np.asarray(estimate) @ W, W)


def _stats(truth, estimate, capture: str = "D65") -> dict:
    found = {"rms": float(np.sqrt(((truth - estimate) ** 2).mean()))}
    for light in dict.fromkeys((capture, *LIGHTS)):
        dE = delta_E94_spectra(truth, estimate, light)
        found[f"{light} mean"] = float(dE.mean())
        found[f"{light} max"] = float(dE.max())
    return found


def held_out_figures(
    predict, camera: str = CAMERA, noise: bool = False, sets=HELD_OUT_SETS, illuminant="D65"
):
    """Statistics of ``predict(RGB) -> spectra`` on each held-out set.

    Returns
    -------
    dict
        ``{set: {"rms", "D65 mean", "D65 max", "A mean", "A max"}}``.
    """
    rng = np.random.default_rng(NOISE_SEED + 1)
    found = {}
    for name in sets:
        _, spectra = reflectance_set(name)
        RGB = camera_RGB(spectra, camera, illuminant)
        if noise:
            RGB = camera_noise(RGB, rng)
        found[name] = _stats(spectra[:, ::2], predict(RGB), illuminant)
    return found


def fit_target(
    kind: str,
    degree: int,
    camera: str = CAMERA,
    noise: bool = False,
    ridge=None,
    illuminant: str = "D65",
    loss: str = DEFAULT_LOSS,
    spectral_weight=None,
    augmentation: str = DEFAULT_AUGMENTATION,
):
    """Fit on the training set (with camera noise if asked); the model and in-sample figures.

    ``augmentation``: a key of ``TARGET_AUGMENTATIONS`` (products of training patches by default,
    their weight by cross-validation, erratum E44). In-sample figures are on the target's patches.

    Examples
    --------
    >>> model, in_sample = fit_target("root_polynomial", 4)
    >>> model.loss, model.augmentation["weight"], round(in_sample["D65 mean"], 2)
    ('colorimetric', 2.0, 0.76)
    >>> round(fit_target("root_polynomial", 4, augmentation="none")[1]["D65 mean"], 2)
    0.74

    A fit is deterministic: the same arguments in one process return the same model object (do
    not modify it) and a fresh copy of the figures, without fitting again.

    >>> fit_target("root_polynomial", 4)[0] is model
    True
    """
    args = (kind, degree, camera, noise, ridge, illuminant, loss, spectral_weight, augmentation)
    try:
        hash(args)
    except TypeError:  # a ridge grid given as a list: fitted, not remembered
        model, in_sample = _fit_target(*args)
    else:
        model, in_sample = _fit_target_cached(*args)
    return model, copy.deepcopy(in_sample)


def _fit_target(
    kind, degree, camera, noise, ridge, illuminant, loss, spectral_weight, augmentation
):
    _, spectra = reflectance_set(TRAINING_SET)
    RGB = camera_RGB(spectra, camera, illuminant)
    if noise:
        RGB = camera_noise(RGB, np.random.default_rng(NOISE_SEED))
    make = TARGET_AUGMENTATIONS.lookup(augmentation)
    augment = None
    if make is not None:
        rng = np.random.default_rng(NOISE_SEED + 2) if noise else None
        augment = make(spectra, camera, illuminant, rng)
    model = fit_regression(
        RGB,
        spectra[:, ::2],
        GRID_41.wavelengths_nm,
        kind,
        degree,
        ridge,
        illuminant,
        camera,
        TRAINING_SET,
        loss,
        spectral_weight,
        augment,
    )
    return model, _stats(spectra[:, ::2], model.predict(RGB), illuminant)


#: The section, the docs and the tests ask for the same fits again; each is seconds of CV.
_fit_target_cached = functools.lru_cache(maxsize=64)(_fit_target)


def XYZ_floor(kind: str, degree: int, camera: str = CAMERA, sets=HELD_OUT_SETS) -> dict:
    """ΔE94 (D65) of the direct RGB → XYZ least squares on the same features: the floor.

    A spectral expansion's XYZ is a linear function of the same features, so on the training set
    none can beat this fit; held out it is the reference a spectral method should approach.
    """
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    M = _floor_map(kind, degree, camera, False, W)
    found = {}
    for name in sets:
        _, held = reflectance_set(name)
        XYZ = features_RGB(camera_RGB(held, camera, "D65"), kind, degree) @ M
        dE = _delta_E94_XYZ(held[:, ::2] @ W, XYZ, W)
        found[name] = {"D65 mean": float(np.mean(dE)), "D65 max": float(np.max(dE))}
    return found


def _floor_map(kind: str, degree: int, camera: str, noise: bool, W) -> np.ndarray:
    """The least-squares map from the training RGB's features to its XYZ (weights ``W``).

    With ``noise``, the same noisy training RGB as :func:`fit_target`'s fit.
    """
    _, train = reflectance_set(TRAINING_SET)
    RGB = camera_RGB(train, camera, "D65")
    if noise:
        RGB = camera_noise(RGB, np.random.default_rng(NOISE_SEED))
    X = features_RGB(RGB, kind, degree)
    return np.linalg.lstsq(X, train[:, ::2] @ W, rcond=None)[0]


def regression_table(
    camera: str = CAMERA, sets=HELD_OUT_SETS, run=None, leave_out=()
) -> list[dict]:
    """Every feature family and degree, noise-free and noisy: in-sample and held-out figures.

    Each feature family and degree is one task of ``run(function, tasks, desc)`` (default: in
    this process; the report passes ``ReportContext.run_tasks``); ``(kind, degree)`` pairs in
    ``leave_out`` are left out (the report's quick mode).

    Returns
    -------
    list of dict
        ``{"features", "degree", "noise", "augment_weight", "ridge", "in_sample": {...},
        "held_out": {set: {...}}, "xyz_floor": {set: {...}}}``.
    """
    tasks = [
        (kind, degree, camera, tuple(sets))
        for kind, degrees in REGRESSION_FEATURES.items()
        for degree in degrees
        if (kind, degree) not in leave_out
    ]
    run = run or (lambda function, items, desc: [function(item) for item in items])
    return [row for rows in run(_regression_rows, tasks, "regression degrees") for row in rows]


def _regression_rows(task) -> list[dict]:
    # one feature family and degree (a task): the noise-free and the noisy fit
    kind, degree, camera, sets = task
    floor = XYZ_floor(kind, degree, camera, sets)
    rows = []
    for noise in (False, True):
        model, in_sample = fit_target(kind, degree, camera, noise)
        rows.append(
            {
                "features": kind,
                "degree": degree,
                "noise": noise,
                "augment_weight": (model.augmentation or {}).get("weight", 0.0),
                "ridge": model.ridge,
                "in_sample": in_sample,
                "held_out": held_out_figures(model.predict, camera, noise, sets),
                "xyz_floor": floor,
            }
        )
    return rows


#: Targets relative to what the camera allows (erratum E107): on every set, the regression's
#: held-out mean and max ΔE94 (capture illuminant) at most the direct RGB → XYZ fit's plus these.
FLOOR_MARGIN_MEAN, FLOOR_MARGIN_MAX = 0.05, 0.1


def every_set_study(kind: str, degree: int, camera: str = CAMERA) -> list[dict]:
    """The fit on every reflectance set, against the direct RGB → XYZ fit, noise-free and noisy.

    For each set of :data:`~reference.colour.spectral_target.EVALUATION_SETS` and each noise
    setting, the regression fitted on the training set (:func:`fit_target`) and the least-squares
    RGB → XYZ map on the same features and the same training RGB (the camera's floor,
    :func:`XYZ_floor`) read the same camera RGB (with the same noise): ΔE94 under D65, mean and
    max, the regression's mean relit under A, and whether the targets
    ``mean <= floor mean + FLOOR_MARGIN_MEAN`` and ``max <= floor max + FLOOR_MARGIN_MAX`` hold.

    Returns
    -------
    list of dict
        ``set``, ``noise``, ``patches``, ``mean``, ``max``, ``A mean``, ``floor mean``,
        ``floor max``, ``mean met``, ``max met``; ``A Jakob 2019``, ``A Otsu 2018``: those
        upsamplers' mean relit under A from the floor's XYZ (:func:`_relit_from_camera_XYZ`), and
        ``A met``: the regression's A mean at most the better of them.
    """
    from reference.colour.spectral_target import EVALUATION_SETS

    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    rows = []
    for noise in (False, True):
        model, _ = fit_target(kind, degree, camera, noise)
        M = _floor_map(kind, degree, camera, noise, W)
        rng = np.random.default_rng(NOISE_SEED + 1)
        for name in EVALUATION_SETS:
            _, spectra = reflectance_set(name)
            RGB = camera_RGB(spectra, camera, "D65")
            RGB = camera_noise(RGB, rng) if noise else RGB
            truth = spectra[:, ::2]
            dE = delta_E94_spectra(truth, model.predict(RGB), "D65")
            floor = _delta_E94_XYZ(truth @ W, features_RGB(RGB, kind, degree) @ M, W)
            row = {"set": name, "noise": noise, "patches": len(spectra)}
            row |= {"mean": float(dE.mean()), "max": float(dE.max())}
            row["A mean"] = float(delta_E94_spectra(truth, model.predict(RGB), "A").mean())
            row |= {"floor mean": float(floor.mean()), "floor max": float(floor.max())}
            row["mean met"] = row["mean"] <= row["floor mean"] + FLOOR_MARGIN_MEAN
            row["max met"] = row["max"] <= row["floor max"] + FLOOR_MARGIN_MAX
            row |= _relit_from_camera_XYZ(truth, features_RGB(RGB, kind, degree) @ M)
            row["A met"] = row["A mean"] <= min(row[f"A {m}"] for m in CAMERA_XYZ_UPSAMPLERS)
            rows.append(row)
    return rows


#: The upsamplers the regression is compared with relit under A, given the camera's XYZ.
CAMERA_XYZ_UPSAMPLERS = ("Jakob 2019", "Otsu 2018")


def _relit_from_camera_XYZ(truth, XYZ) -> dict:
    """Mean ΔE94 under A of Jakob 2019 and Otsu 2018 spectra made from the camera's XYZ (D65).

    What a renderer without the regression would do with the same camera: estimate XYZ (the
    least-squares map of :func:`every_set_study`), then upsample it. Jakob 2019 through specref's
    coefficient table from linear sRGB clipped to [0, 1] (a texel's value, as Mitsuba 3 and
    pbrt-v4 use it); Otsu 2018 through colour-science, patch by patch.
    """
    import colour

    from reference.colour.upsampling import RGB_to_spectra_Jakob2019

    RGB = np.clip(colour.XYZ_to_RGB(XYZ, "sRGB", apply_cctf_encoding=False), 0.0, 1.0)
    shape = colour.SpectralShape(380, 780, 10)
    estimates = {
        "Jakob 2019": RGB_to_spectra_Jakob2019(RGB, GRID_41),
        "Otsu 2018": np.array(
            [colour.XYZ_to_sd(x, method="Otsu 2018").copy().align(shape).values for x in XYZ]
        ),
    }
    return {f"A {m}": float(delta_E94_spectra(truth, S, "A").mean()) for m, S in estimates.items()}


def _delta_E94_XYZ(XYZ_1, XYZ_2, weights) -> np.ndarray:
    """ΔE94 between XYZ (white: the weights' white diffuser; any common scale of both)."""
    import colour

    white = white_XYZ(weights)
    Lab_1, Lab_2 = XYZ_to_Lab(XYZ_1, white), XYZ_to_Lab(XYZ_2, white)
    return np.asarray(colour.delta_E(Lab_1, Lab_2, method="CIE 1994"))


#: Erratum E44's study: ridge strengths λ and smoothness strengths μ tried by cross-validation.
SMOOTH_RIDGES = (0.0, *(10.0**k for k in range(-10, 0)))
SMOOTH_STRENGTHS = (0.0, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2)


def _fit_smooth(X, S, ridge: float, smoothness: float) -> np.ndarray:
    """``argmin (1/n)‖XW − S‖² + λ‖W‖² + μ‖W D₂ᵀ‖²`` (D₂: second differences across bands).

    Hoerl & Kennard 1970 with a Tikhonov smoothness term; the normal equations
    ``(XᵀX + nλ I) W + W (nμ D₂ᵀD₂) = XᵀS`` are a Sylvester equation.
    """
    import scipy.linalg

    n = len(X)
    D2 = np.diff(np.eye(S.shape[1]), 2, axis=0)
    A = X.T @ X + n * ridge * np.eye(X.shape[1])
    return scipy.linalg.solve_sylvester(A, n * smoothness * (D2.T @ D2), X.T @ S)


def smoothness_study(kind: str, degree: int, criterion: str = "dE94", camera: str = CAMERA):
    """Erratum E44: a smoothness prior, (λ, μ) chosen by 5-fold CV on the training set only.

    ``criterion`` is the cross-validated quantity minimized: ``"dE94"`` (mean ΔE94, D65) or
    ``"rms"`` (spectral RMS). Features scaled to unit RMS, as :func:`fit_regression` does.

    Returns
    -------
    dict
        ``ridge``, ``smoothness``, ``held_out`` (:func:`held_out_figures`) and ``clipped`` (the
        same with the predicted spectra clipped at 0).
    """
    from reference.colour.spectral_regression import CV_FOLDS, CV_SEED

    _, spectra = reflectance_set(TRAINING_SET)
    S = spectra[:, ::2]
    X = features_RGB(camera_RGB(spectra, camera, "D65"), kind, degree)
    scale = np.sqrt((X**2).mean(axis=0))
    X = X / scale
    folds = np.array_split(np.random.default_rng(CV_SEED).permutation(len(X)), CV_FOLDS)
    scores = {}
    for ridge in SMOOTH_RIDGES:
        for smoothness in SMOOTH_STRENGTHS:
            errors = []
            for held in folds:
                train = np.setdiff1d(np.arange(len(X)), held)
                P = X[held] @ _fit_smooth(X[train], S[train], ridge, smoothness)
                if criterion == "dE94":
                    errors.append(delta_E94_spectra(S[held], P, "D65"))
                else:
                    errors.append(((P - S[held]) ** 2).mean(axis=1))
            scores[(ridge, smoothness)] = float(np.concatenate(errors).mean())
    ridge, smoothness = min(scores, key=scores.get)
    W = _fit_smooth(X, S, ridge, smoothness) / scale[:, None]

    def predict(RGB):
        return features_RGB(RGB, kind, degree) @ W

    return {
        "ridge": ridge,
        "smoothness": smoothness,
        "held_out": held_out_figures(predict, camera),
        "clipped": held_out_figures(lambda RGB: np.clip(predict(RGB), 0.0, None), camera),
    }


def recovery_figures(method: str, sets=HELD_OUT_SETS) -> dict:
    """A colour.recovery upsampler on the held-out patches: XYZ (D65) → spectrum → figures.

    The input is each patch's XYZ under D65 (what an sRGB texel carries); the round trip under
    D65 and the relit figure under A are computed like the regression's.
    """
    import colour

    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    shape = colour.SpectralShape(380, 780, 10)
    found = {}
    for name in sets:
        _, spectra = reflectance_set(name, GRID_41)
        estimate = []
        for XYZ in spectra @ W:
            sd = colour.XYZ_to_sd(XYZ, method=method)
            estimate.append(sd.copy().align(shape).values)
        found[name] = _stats(spectra, np.array(estimate))
    return found


def _format(figures: dict, light: str) -> str:
    return (
        f"ΔE94 {light} mean {figures[f'{light} mean']:.2f} max {figures[f'{light} max']:.2f}, "
        f"A mean {figures['A mean']:.2f}, spectral RMS {figures['rms']:.4f}"
    )


class _FitSettings(NamedTuple):
    """The regression's settings, as ``specref env fit`` takes them."""

    kind: str
    degree: int
    ridge: float | None
    illuminant: str
    loss: str
    spectral_weight: float | None


def _fit_target_file(target, spectra, augmentation: str | None, fit: _FitSettings):
    """Fit on a target file, never augmented (erratum E44): the model and in-sample figures."""
    from reference.colour.spectral_target import read_target

    require(
        augmentation in (None, "none"),
        f"{target}: --augment {augmentation}: a target file cannot be augmented (the "
        "products' camera RGB needs the camera's sensitivities); allowed with --target: none",
    )
    RGB, truth = read_target(target, spectra)
    model = fit_regression(
        RGB,
        truth,
        GRID_41.wavelengths_nm,
        fit.kind,
        fit.degree,
        fit.ridge,
        fit.illuminant,
        "",
        str(target),
        fit.loss,
        fit.spectral_weight,
    )
    return model, _stats(truth, model.predict(RGB), fit.illuminant)


def _fit_lines(out, fit: _FitSettings, model, in_sample: dict, held_out: dict | None) -> list[str]:
    """The lines ``specref env fit`` prints: the model written, then its figures."""
    weight = (
        "" if model.spectral_weight is None else f", spectral weight {model.spectral_weight:.3g}"
    )
    extra = model.augmentation
    if extra:
        weight += f", {extra['method']} at weight {extra['weight']:g} ({extra['patches']} patches)"
    lines = [
        f"wrote {out}: {fit.kind} degree {fit.degree}, {model.loss} loss, "
        f"ridge {model.ridge:.3g}{weight}, {model.training_set}",
        f"in-sample: {_format(in_sample, fit.illuminant)}",
    ]
    if model.cv and "rms" in model.cv:
        best = min(model.cv["rms"])
        lines.append(f"cross-validated ({model.cv['folds']} folds) spectral RMS {best:.4f}")
    elif model.cv:
        best = min(min(row) for row in model.cv["scores"])
        lines.append(
            f"cross-validated ({model.cv['folds']} folds) {model.cv['criterion']}: {best:.2f}"
        )
    for name, figures in (held_out or {}).items():
        lines.append(f"held out, {name}: {_format(figures, fit.illuminant)}")
    return lines


def fit_file(
    out,
    target=None,
    spectra=None,
    camera: str = CAMERA,
    illuminant: str = "D65",
    kind: str = "root_polynomial",
    degree: int = 4,
    ridge=None,
    noise: bool = False,
    loss: str = DEFAULT_LOSS,
    spectral_weight=None,
    augmentation: str | None = None,
) -> dict:
    """What ``specref env fit`` runs: fit on a target file or the synthetic target, save, report.

    With ``target`` (``reference.colour.spectral_target.read_target``) the figures are in-sample and
    the cross-validated spectral RMS; without it the synthetic target of ``camera`` under
    ``illuminant`` is used, and the held-out sets are measured too. ``augmentation`` (a key of
    ``TARGET_AUGMENTATIONS``; None: products for the synthetic target, none for a file) needs the
    camera's sensitivities, so a target file is never augmented (erratum E44).

    Returns
    -------
    dict
        ``model``, ``in_sample``, ``held_out`` (None for a file target), ``lines`` (to print).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     found = fit_file(os.path.join(d, "m.json"), kind="polynomial", degree=9)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: polynomial degree must be an integer in 1…5, got 9
    """
    from reference.colour.spectral_regression import save_regression
    from reference.files import check_output_file

    check_output_file(out)  # before the fit (seconds to minutes), not after it
    fit = _FitSettings(kind, degree, ridge, illuminant, loss, spectral_weight)
    if augmentation is not None:
        TARGET_AUGMENTATIONS.lookup(augmentation)
    if target is not None:
        model, in_sample = _fit_target_file(target, spectra, augmentation, fit)
        held_out = None
    else:
        # The synthetic target of the camera, measured on the held-out sets too.
        model, in_sample = fit_target(
            kind,
            degree,
            camera,
            noise,
            ridge,
            illuminant,
            loss,
            spectral_weight,
            augmentation or DEFAULT_AUGMENTATION,
        )
        held_out = held_out_figures(model.predict, camera, noise, HELD_OUT_SETS, illuminant)
    save_regression(model, out)
    lines = _fit_lines(out, fit, model, in_sample, held_out)
    return {"model": model, "in_sample": in_sample, "held_out": held_out, "lines": lines}


def upsampling_speed_accuracy(panorama, sets=HELD_OUT_SETS, repeats: int = 3, methods=None) -> dict:
    """Speed against accuracy of the render's RGB upsamplers (``UPSAMPLING_METHODS``).

    Speed: the fastest of ``repeats`` runs of :func:`reference.colour.upsampling.
    RGB_to_radiance_spectra` on the whole ``panorama`` (41 bands), after a warm-up call that loads
    each method's tables or model. Accuracy: the same method on the held-out reflectance sets
    through the sRGB "camera" (the linear sRGB a texel carries; :func:`held_out_figures`), the
    relit figure under A averaged over the sets and its worst patch. ``methods``: keys of
    ``UPSAMPLING_METHODS`` (default all; ``jakob2019`` builds its tables the first time on a
    machine, minutes).

    Returns
    -------
    dict
        Per method ``seconds``, ``megapixels`` (the panorama's), ``A mean``, ``A max`` (ΔE94)
        and ``D65 mean``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> sky = write_exr(pathlib.Path(tempfile.mkdtemp()) / "s.exr", np.ones((8, 16, 3), np.float32))
    >>> found = upsampling_speed_accuracy(sky, sets=("ColorChecker N Ohta",), repeats=1)
    >>> sorted(found), found["mallett2019"]["megapixels"]
    (['jakob2019', 'mallett2019', 'regression'], 0.000128)
    """
    import time

    from reference.colour.upsampling import (
        UPSAMPLING_METHODS,
        RGB_to_radiance_spectra,
        RGB_to_spectra,
    )
    from reference.images.formats import read_image

    RGB = np.asarray(read_image(panorama)[..., :3], dtype=np.float64)
    found = {}
    for method in UPSAMPLING_METHODS.names() if methods is None else methods:
        RGB_to_radiance_spectra(RGB[:2, :2], GRID_41, method)  # tables, the shipped model
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            RGB_to_radiance_spectra(RGB, GRID_41, method)
            times.append(time.perf_counter() - start)
        figures = held_out_figures(
            lambda rgb, m=method: RGB_to_spectra(rgb, GRID_41, m), camera="sRGB", sets=sets
        )
        found[method] = {
            "seconds": min(times),
            "megapixels": RGB.shape[0] * RGB.shape[1] / 1e6,
            "A mean": float(np.mean([f["A mean"] for f in figures.values()])),
            "A max": float(max(f["A max"] for f in figures.values())),
            "D65 mean": float(np.mean([f["D65 mean"] for f in figures.values()])),
        }
    return found
