"""Spectral-environment targets on the synthetic Nikon 5100 (validation.studies.spectral_env)."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.spectral_target import HELD_OUT_SETS
from validation.studies.spectral_env import (
    delta_E94_spectra,
    fit_target,
    held_out_figures,
    recovery_figures,
)

CC = "ColorChecker N Ohta"


@pytest.fixture(scope="module")
def root4():
    model, in_sample = fit_target("root_polynomial", 4)
    return model, in_sample, held_out_figures(model.predict)


def test_delta_E94_against_colour_science():
    # Source: colour-science's sd_to_XYZ (5 nm, CIE 1931) and delta_E CIE 1994, independently.
    import colour

    sds = list(colour.SDS_COLOURCHECKERS[CC].values())[:2]
    shape = colour.SpectralShape(380, 780, 10)
    a, b = (sd.copy().align(shape).values for sd in sds)
    ill = colour.SDS_ILLUMINANTS["D65"]
    XYZ = [colour.sd_to_XYZ(sd, illuminant=ill) / 100 for sd in sds]
    white = colour.XYZ_to_xy(colour.sd_to_XYZ(colour.sd_ones(), illuminant=ill) / 100)
    expected = colour.delta_E(*(colour.XYZ_to_Lab(x, white) for x in XYZ), method="CIE 1994")
    assert delta_E94_spectra(a[None], b[None], "D65")[0] == pytest.approx(expected, abs=0.05)


def test_in_sample_mean(root4):
    # Target (erratum E44): in-sample mean ΔE94 <= 0.8 (Herbert et al. §4 print 0.77, in-sample).
    assert root4[1]["D65 mean"] <= 0.8


def test_held_out_colorchecker_mean_D65_and_A(root4):
    # Targets (erratum E44): held-out ColorChecker mean ΔE94 <= 0.77 (D65), relit under A <= 1.0.
    figures = root4[2][CC]
    assert figures["D65 mean"] <= 0.77
    assert figures["A mean"] <= 1.0


def test_held_out_colorchecker_max(root4):
    # Target (erratum E44): held-out ColorChecker max ΔE94 <= 1.5 (D65); with the products of the
    # training patches (erratum E44; 1.51 without them).
    assert root4[2][CC]["D65 max"] <= 1.5


@pytest.fixture(scope="module")
def unaugmented():
    return fit_target("root_polynomial", 4, augmentation="none")[0]


def test_colorimetric_loss_improves_on_the_spectral_loss_held_out(unaugmented):
    # Erratum E44: the colorimetric loss (ΔE94 under D65 and A, λ and β by CV on the training
    # set) against spectral least squares, both on the training patches alone, on every set the
    # design never saw, the CIE 2017 samples (measured after the choice was made) included:
    # relit under A the mean is lower on each, and the peak under D65 is lower on the
    # ColorChecker and the NIST CQS samples.
    from reference.colour.spectral_target import OTHER_TEST_SET

    sets = (*HELD_OUT_SETS, OTHER_TEST_SET)
    assert unaugmented.loss == "colorimetric"
    assert unaugmented.augmentation is None
    new = held_out_figures(unaugmented.predict, sets=sets)
    spectral = fit_target("root_polynomial", 4, loss="spectral", augmentation="none")[0]
    old = held_out_figures(spectral.predict, sets=sets)
    for name in sets:
        assert new[name]["A mean"] < old[name]["A mean"], name
    for name in (CC, "NIST CQS 9.0"):
        assert new[name]["D65 max"] < old[name]["D65 max"], name


def test_products_chosen_by_cross_validation_lower_the_peaks(root4, unaugmented):
    # Erratum E44: cross-validation on the training patches gives the products a nonzero weight
    # (its held-out folds' 95th percentile of ΔE94 falls), and the peak under D65 falls on the
    # ColorChecker, the CIE 2024 samples and the CIE 2017 samples (measured after the choice);
    # the means under D65 stay within 0.02.
    from reference.colour.spectral_target import OTHER_TEST_SET

    model = root4[0]
    scores = model.cv["augment_scores"]
    assert model.augmentation["weight"] > 0
    assert min(scores) < scores[0] - 0.05
    sets = (*HELD_OUT_SETS, OTHER_TEST_SET)
    new = held_out_figures(model.predict, sets=sets)
    old = held_out_figures(unaugmented.predict, sets=sets)
    for name in (CC, "CIE 2024 TCS", OTHER_TEST_SET):
        assert new[name]["D65 max"] < old[name]["D65 max"], name
    for name in sets:
        assert new[name]["D65 mean"] <= old[name]["D65 mean"] + 0.02, name


@pytest.mark.parametrize("name", HELD_OUT_SETS[1:])
def test_other_held_out_sets(root4, name):
    # Our own bound (not one of erratum E44's targets): the sets the design never saw stay below
    # 1 ΔE94 mean.
    assert root4[2][name]["D65 mean"] <= 1.0


def test_noise_hurts_high_degrees_more():
    # 0.5 % multiplicative + 0.1 % additive noise: the degree-5 polynomial loses more than degree 1.
    loss = {}
    for degree in (1, 5):
        clean = fit_target("polynomial", degree, augmentation="none")[0]
        clean = held_out_figures(clean.predict)[CC]["D65 mean"]
        model, _ = fit_target("polynomial", degree, noise=True, augmentation="none")
        noisy = held_out_figures(model.predict, noise=True)[CC]["D65 mean"]
        loss[degree] = noisy - clean
    assert loss[5] > loss[1]


def test_smits_round_trip_is_worse_than_the_regression(root4):
    # colour.recovery's Smits 1999 is not a round trip on the ColorChecker (ΔE94 ~4 under D65).
    smits = recovery_figures("Smits 1999", (CC,))[CC]
    assert smits["D65 mean"] > root4[2][CC]["D65 mean"]
    assert np.isfinite(smits["A mean"])


@pytest.mark.parametrize(("kind", "degree"), [("root_polynomial", 4), ("polynomial", 4)])
def test_smoothness_prior_does_not_reach_the_peak(kind, degree):
    # Erratum E44, what was tried: a second-difference smoothness prior with (λ, μ) chosen by
    # cross-validated ΔE94 on the training set. It keeps the mean target and misses the peak.
    from validation.studies.spectral_env import smoothness_study

    study = smoothness_study(kind, degree)
    assert study["held_out"][CC]["D65 mean"] <= 0.77
    assert study["held_out"][CC]["D65 max"] > 1.5
    assert study["clipped"][CC]["D65 max"] > 1.5


def test_the_fit_reads_the_training_set_alone(monkeypatch):
    # The sets a fit is measured on are never read by the fit: the training set (built once, its
    # look-alikes of the held-out charts removed, erratum E40) is the only set it asks for, and
    # the regression (features, loss, augmentation weight, λ and β by cross-validation) gets the
    # training patches' arrays only
    import validation.studies.spectral_env as study
    from reference.colour.spectral_target import TRAINING_SET, reflectance_set

    asked, sizes = [], []
    monkeypatch.setattr(
        study, "reflectance_set", lambda name, *a: asked.append(name) or reflectance_set(name, *a)
    )
    fit = study.fit_regression
    monkeypatch.setattr(
        study,
        "fit_regression",
        lambda RGB, spectra, *a: sizes.append(len(RGB)) or fit(RGB, spectra, *a),
    )
    study._fit_target("root_polynomial", 2, study.CAMERA, True, None, "D65", "colorimetric",
                      None, "products")  # fmt: skip
    assert set(asked) == {TRAINING_SET}
    assert sizes == [len(reflectance_set(TRAINING_SET)[0])]


def test_every_set_is_measured_against_the_cameras_floor():
    # The noise-free floor of every_set_study is XYZ_floor's (computed apart), and each target
    # flag is its figure against that floor plus the margin (erratum E107)
    from reference.colour.spectral_target import EVALUATION_SETS
    from validation.studies.spectral_env import (
        FLOOR_MARGIN_MAX,
        FLOOR_MARGIN_MEAN,
        XYZ_floor,
        every_set_study,
    )

    rows = every_set_study("root_polynomial", 1)
    assert [r["set"] for r in rows] == [*EVALUATION_SETS, *EVALUATION_SETS]
    floor = XYZ_floor("root_polynomial", 1, sets=EVALUATION_SETS)
    for r in rows[: len(EVALUATION_SETS)]:
        assert r["floor mean"] == pytest.approx(floor[r["set"]]["D65 mean"], rel=1e-9)
        assert r["floor max"] == pytest.approx(floor[r["set"]]["D65 max"], rel=1e-9)
    for r in rows:
        assert r["mean met"] == (r["mean"] <= r["floor mean"] + FLOOR_MARGIN_MEAN)
        assert r["max met"] == (r["max"] <= r["floor max"] + FLOOR_MARGIN_MAX)
        better = min(r["A Jakob 2019"], r["A Otsu 2018"])
        assert r["A met"] == (r["A mean"] <= better)
        assert 0 < r["A Jakob 2019"] < 10
        assert 0 < r["A Otsu 2018"] < 10
    noisy = {r["set"]: r for r in rows[len(EVALUATION_SETS) :]}
    assert all(noisy[r["set"]]["mean"] != r["mean"] for r in rows[: len(EVALUATION_SETS)])
