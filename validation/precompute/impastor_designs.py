"""Fit the ImpastoR channel designs (``box`` and ``optimized``, N = 3 … 10) and ship them as JSON.

Run ``python -m validation.precompute.impastor_designs`` to rewrite
``impastor/data/designs.json`` (about an hour on one core).

Training data (all shipped with colour-science, none of it a ColorChecker):

- the 190 training reflectances of rawtoaces v1 (``colour.characterisation``);
- the CIE 2024 test-colour samples (15, ``colour.quality.SDS_TCS``);
- the NIST CQS 9.0 samples (15, ``colour.quality.SDS_VS``).

The sets in ``colour.SDS_COLOURCHECKERS`` (N Ohta, BabelColor, ISO 17321-1, PMC) are left out
entirely. A training spectrum is a *ColorChecker look-alike*, and is removed, when it lies within
ΔE00 < 3 of some ColorChecker N Ohta patch under each of D65, D50 and A (the largest of the three
differences is below 3), or when its RMS spectral difference from a patch is below 0.03. The
removed spectra are listed in the JSON. The ColorChecker N Ohta chart is the held-out test set.

Fit (all on the 5 nm grid 380-780 nm, truth from the ASTM E2022/E308 5 nm band weights, which
reproduce ``colour.sd_to_XYZ``), under D65, D50 and A with one matrix M:

- ``box``: N − 1 interior band edges by differential evolution (mean ΔE00 plus a tenth of the
  maximum), with M by linear least squares in XYZ at each step; then the edges polished by
  Nelder–Mead for the worst light's mean ΔE00, with M refined at each step by Gauss–Newton on
  CIELAB differences weighted towards CIEDE2000 (1/S_L on L*, 1/S_C on a*, b*).
- ``optimized``: the sampling functions (81 non-negative values each, as softplus of free
  parameters) and M jointly, by Levenberg–Marquardt on the same weighted CIELAB residuals with an
  analytic Jacobian and a second-difference smoothness penalty; started from Gaussians spread
  evenly over 440-640 nm.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from impastor.multispectral import DESIGNS_FILE, MS_GRID, box_sampling_functions
from reference.colour.colorimetry import band_weights
from reference.colour.spectra import make_spectrum, resample_spectrum, spectrum_from_dataset
from reference.files import write_text_atomic

TRAINING_LIGHTS = ("D65", "D50", "A")
CHANNEL_COUNTS = tuple(range(3, 11))
LOOKALIKE_DELTA_E = 3.0
LOOKALIKE_RMS = 0.03
SMOOTHNESS = 0.05
MAX_NFEV = 250
SEED = 20150101

_EPS, _KAPPA = 216.0 / 24389.0, 24389.0 / 27.0


def _on_grid(sd) -> np.ndarray:
    spectrum = make_spectrum(sd.wavelengths, np.clip(sd.values, 0.0, None), str(sd.name))
    return resample_spectrum(spectrum, MS_GRID, extrapolation="constant")


def colorchecker_spectra() -> tuple[np.ndarray, list[str]]:
    """The 24 ColorChecker N Ohta reflectances on the 5 nm grid (the held-out test set)."""
    import colour

    patches = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    return np.stack([_on_grid(sd) for sd in patches.values()]), list(patches)


def lab_with_jacobian(XYZ, white):
    """CIELAB of ``XYZ (..., 3)`` and ``dLab/dXYZ (..., 3, 3)`` (CIE 15 formulas)."""
    t = XYZ / white
    f = np.where(t > _EPS, np.cbrt(np.maximum(t, _EPS)), (_KAPPA * t + 16.0) / 116.0)
    df = np.where(t > _EPS, np.cbrt(np.maximum(t, _EPS)) ** -2 / 3.0, _KAPPA / 116.0) / white
    fx, fy, fz = f[..., 0], f[..., 1], f[..., 2]
    Lab = np.stack([116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)], axis=-1)
    D = np.zeros((*XYZ.shape, 3))
    D[..., 0, 1] = 116.0 * df[..., 1]
    D[..., 1, 0], D[..., 1, 1] = 500.0 * df[..., 0], -500.0 * df[..., 1]
    D[..., 2, 1], D[..., 2, 2] = 200.0 * df[..., 1], -200.0 * df[..., 2]
    return Lab, D


def _ciede2000_weights(Lab) -> np.ndarray:
    """Per-component weights (1/S_L, 1/S_C, 1/S_C) that bring ΔE*ab towards CIEDE2000."""
    L, C = Lab[..., 0], np.hypot(Lab[..., 1], Lab[..., 2])
    S_L = 1.0 + 0.015 * (L - 50.0) ** 2 / np.sqrt(20.0 + (L - 50.0) ** 2)
    S_C = 1.0 + 0.045 * C
    return np.stack([1.0 / S_L, 1.0 / S_C, 1.0 / S_C], axis=-1)


class Problem:
    """Training reflectances, lights and their 5 nm truth."""

    def __init__(self, R: np.ndarray, lights=TRAINING_LIGHTS):
        self.R = R
        self.lights = lights
        y_bar = band_weights(MS_GRID, None)[:, 1]
        self.S, self.white, self.Lab_true = [], [], []
        for key in lights:
            spectrum = spectrum_from_dataset("illuminant", key)
            S = resample_spectrum(spectrum, MS_GRID)
            self.S.append(S / (S @ y_bar))
            W = band_weights(MS_GRID, spectrum)
            self.white.append(W.sum(axis=0))
            self.Lab_true.append(lab_with_jacobian(R @ W, W.sum(axis=0))[0])
        self.S = np.stack(self.S)  # (n_lights, 81)
        self.white = np.stack(self.white)  # (n_lights, 3)
        self.Lab_true = np.stack(self.Lab_true, axis=1)  # (n, n_lights, 3)
        self.weights = _ciede2000_weights(self.Lab_true)
        self.XYZ_true = np.stack(
            [R @ band_weights(MS_GRID, spectrum_from_dataset("illuminant", k)) for k in lights],
            axis=1,
        )

    def products(self, s):
        """Channel values ``R6``, ``S6`` and products ``U = R6 ⊙ S6``."""
        R6 = self.R @ s.T  # (n, N)
        S6 = self.S @ s.T  # (n_lights, N)
        return R6, S6, R6[:, None, :] * S6[None, :, :]  # U: (n, n_lights, N)

    def fit_M_linear(self, s) -> np.ndarray:
        """M by least squares in XYZ over all samples and lights."""
        _, _, U = self.products(s)
        M, *_ = np.linalg.lstsq(
            U.reshape(-1, U.shape[-1]), self.XYZ_true.reshape(-1, 3), rcond=None
        )
        return M.T

    def residuals(self, s, M):
        """Weighted CIELAB residuals, ``dLab/dXYZ`` and the products ``U``."""
        _, _, U = self.products(s)
        Lab, D = lab_with_jacobian(U @ M.T, self.white[None])
        return (Lab - self.Lab_true) * self.weights, D, U

    def delta_E00(self, s, M) -> np.ndarray:
        """CIEDE2000 per sample and light, ``(n, n_lights)``."""
        import colour

        _, _, U = self.products(s)
        Lab = lab_with_jacobian(U @ M.T, self.white[None])[0]
        return colour.delta_E(Lab, self.Lab_true, method="CIE 2000")

    def refine_M(self, s, M, iterations: int = 8) -> np.ndarray:
        """Gauss–Newton on the weighted CIELAB residuals, M only."""
        for _ in range(iterations):
            r, D, U = self.residuals(s, M)
            # J[i, l, c, r, k] = w D[c, r] U[k]
            J = (self.weights[..., None, None] * D[..., None]) * U[..., None, None, :]
            J = J.reshape(-1, M.size)
            step, *_ = np.linalg.lstsq(J, -r.ravel(), rcond=None)
            M = M + step.reshape(M.shape)
        return M


def training_set(verbose: bool = False):
    """Training reflectances with ColorChecker look-alikes removed; also the removed names."""
    import colour
    from colour.characterisation import read_training_data_rawtoaces_v1
    from colour.quality import SDS_TCS, SDS_VS

    raw = read_training_data_rawtoaces_v1().align(colour.SpectralShape(380, 780, 5))
    spectra = [np.clip(v, 0.0, None) for v in raw.values.T]
    names = [f"rawtoaces_v1:{label}" for label in raw.labels]
    for set_name, table in (
        ("CIE 2024 TCS", SDS_TCS["CIE 2024"]),
        ("NIST CQS 9.0", SDS_VS["NIST CQS 9.0"]),
    ):
        for key, sd in table.items():
            spectra.append(_on_grid(sd))
            names.append(f"{set_name}:{key}")
    R = np.stack(spectra)
    cc, _ = colorchecker_spectra()
    worst = np.zeros((len(R), len(cc)))
    for key in TRAINING_LIGHTS:
        W = band_weights(MS_GRID, spectrum_from_dataset("illuminant", key))
        white = W.sum(axis=0)
        Lab_R = lab_with_jacobian(R @ W, white)[0]
        Lab_cc = lab_with_jacobian(cc @ W, white)[0]
        import colour as _colour

        d = _colour.delta_E(Lab_R[:, None, :], Lab_cc[None, :, :], method="CIE 2000")
        worst = np.maximum(worst, d)
    rms = np.sqrt(((R[:, None, :] - cc[None]) ** 2).mean(axis=-1))
    lookalike = (worst.min(axis=1) < LOOKALIKE_DELTA_E) | (rms.min(axis=1) < LOOKALIKE_RMS)
    removed = [n for n, bad in zip(names, lookalike, strict=True) if bad]
    kept = [n for n, bad in zip(names, lookalike, strict=True) if not bad]
    return R[~lookalike], kept, removed


def fit_box(problem: Problem, n_channels: int, seed: int = SEED):
    """Band edges by differential evolution, then M refined on CIELAB."""
    from scipy.optimize import differential_evolution

    def cost(interior):
        s = box_sampling_functions(np.concatenate([[380.0], np.sort(interior), [780.0]]))
        M = problem.fit_M_linear(s)
        d = problem.delta_E00(s, M)
        return d.mean() + 0.1 * d.max(axis=0).mean()

    result = differential_evolution(
        cost, [(385.0, 775.0)] * (n_channels - 1), seed=seed, maxiter=150, tol=1e-7, polish=False
    )
    from scipy.optimize import minimize

    def refined_cost(interior):
        s = box_sampling_functions(np.concatenate([[380.0], np.sort(interior), [780.0]]))
        M = problem.refine_M(s, problem.fit_M_linear(s), iterations=4)
        d = problem.delta_E00(s, M)
        return d.mean(axis=0).max() + 0.1 * d.max(axis=0).mean()

    # Polish the edges with M refined on CIELAB at every step, for the worst light's mean.
    polished = minimize(
        refined_cost, np.sort(result.x), method="Nelder-Mead", options={"maxfev": 300}
    )
    edges = np.concatenate([[380.0], np.sort(polished.x), [780.0]])
    s = box_sampling_functions(edges)
    M = problem.refine_M(s, problem.fit_M_linear(s))
    return edges, s, M


def _softplus(x):
    return np.logaddexp(0.0, x)


def fit_optimized(problem: Problem, n_channels: int, max_nfev: int = MAX_NFEV):
    """Sampling functions and M jointly, by Levenberg–Marquardt with an analytic Jacobian.

    The functions are ``s = softplus(θ)`` (non-negative without bounds), started as Gaussians
    spread evenly over 440-640 nm; a second-difference penalty on θ keeps them smooth.
    """
    from scipy.optimize import least_squares

    N, n_wl = n_channels, MS_GRID.n_bands
    wl = MS_GRID.wavelengths_nm
    D2 = np.diff(np.eye(n_wl), 2, axis=0)  # second differences

    def unpack(x):
        return x[: N * n_wl].reshape(N, n_wl), x[N * n_wl :].reshape(3, N)

    def fun(x):
        theta, M = unpack(x)
        r, _, _ = problem.residuals(_softplus(theta), M)
        return np.concatenate([r.ravel(), (SMOOTHNESS * theta @ D2.T).ravel()])

    def jac(x):
        theta, M = unpack(x)
        s = _softplus(theta)
        R6, S6, U = problem.products(s)
        _, D, _ = problem.residuals(s, M)
        WD = problem.weights[..., None] * D  # (n, l, c, r)
        DM = WD @ M  # (n, l, c, k)
        # dXYZ_r/ds_kλ = M_rk (R_λ S6_k + R6_k S_λ); ds/dθ = sigmoid(θ)
        term = (
            problem.R[:, None, None, :] * S6[None, :, :, None]
            + R6[:, None, :, None] * problem.S[None, :, None, :]
        )  # (n, l, k, λ)
        J_s = DM[..., None] * term[:, :, None, :, :] / (1.0 + np.exp(-theta))
        J_M = WD[..., None] * U[:, :, None, None, :]  # (n, l, c, r, k)
        n_res = J_s.shape[0] * J_s.shape[1] * 3
        J_top = np.concatenate([J_s.reshape(n_res, -1), J_M.reshape(n_res, -1)], axis=1)
        J_smooth = np.zeros((N * (n_wl - 2), x.size))
        for k in range(N):
            J_smooth[k * (n_wl - 2) : (k + 1) * (n_wl - 2), k * n_wl : (k + 1) * n_wl] = (
                SMOOTHNESS * D2
            )
        return np.concatenate([J_top, J_smooth])

    centres = np.linspace(440.0, 640.0, N)
    sigma = 90.0 / N
    s0 = np.exp(-0.5 * ((wl[None, :] - centres[:, None]) / sigma) ** 2)
    s0 = 10.0 * s0 / s0.sum(axis=1, keepdims=True) + 1e-4
    M0 = problem.refine_M(s0, problem.fit_M_linear(s0))
    x0 = np.concatenate([np.log(np.expm1(s0)).ravel(), M0.ravel()])
    result = least_squares(fun, x0, jac=jac, method="lm", max_nfev=max_nfev)
    theta, M = unpack(result.x)
    s = _softplus(theta)
    total = s.sum(axis=1, keepdims=True)
    return s / total, M * total.T**2  # U = R6 ⊙ S6 is quadratic in s


def _stats(d) -> dict:
    return {"mean": float(d.mean()), "max": float(d.max())}


def fit_all(channel_counts=CHANNEL_COUNTS, verbose: bool = True) -> dict:
    """Fit both design families for each channel count; return the JSON document."""
    import colour

    R, kept, removed = training_set()
    problem = Problem(R)
    cc, _ = colorchecker_spectra()
    test = Problem(cc)
    document = {
        "generator": "validation/precompute/impastor_designs.py",
        "colour_science": colour.__version__,
        "grid": MS_GRID.label,
        "training": {
            "sets": ["rawtoaces_v1 (190)", "CIE 2024 TCS (15)", "NIST CQS 9.0 (15)"],
            "lights": list(TRAINING_LIGHTS),
            "lookalike_rule": f"max over lights of ΔE00 < {LOOKALIKE_DELTA_E} to a ColorChecker "
            f"N Ohta patch, or spectral RMS < {LOOKALIKE_RMS}",
            "n_kept": len(kept),
            "removed": removed,
        },
        "designs": {"box": {}, "optimized": {}},
    }
    for N in channel_counts:
        start = time.perf_counter()
        edges, s_box, M_box = fit_box(problem, N)
        s_opt, M_opt = fit_optimized(problem, N)
        for family, s, M, extra in (
            ("box", s_box, M_box, {"edges_nm": [round(float(e), 4) for e in edges]}),
            ("optimized", s_opt, M_opt, {"s": np.round(s_opt, 10).tolist()}),
        ):
            train = problem.delta_E00(s, M)
            held_out = test.delta_E00(s, M)
            entry = dict(extra)
            entry["M"] = np.round(M, 10).tolist()
            entry["train_delta_E00"] = {
                light: _stats(train[:, i]) for i, light in enumerate(TRAINING_LIGHTS)
            }
            entry["colorchecker_delta_E00"] = {
                light: _stats(held_out[:, i]) for i, light in enumerate(TRAINING_LIGHTS)
            }
            document["designs"][family][str(N)] = entry
        if verbose:
            summary = {
                fam: {
                    k: round(v["mean"], 3)
                    for k, v in document["designs"][fam][str(N)]["colorchecker_delta_E00"].items()
                }
                for fam in ("box", "optimized")
            }
            seconds = time.perf_counter() - start
            sys.stderr.write(f"N = {N}: {seconds:.1f} s, ColorChecker mean ΔE00 {summary}\n")
    return document


def main(argv=None) -> int:
    """Fit every design and write :data:`impastor.multispectral.DESIGNS_FILE` atomically."""
    document = fit_all()
    write_text_atomic(DESIGNS_FILE, json.dumps(document, indent=1) + "\n")
    sys.stderr.write(f"wrote {DESIGNS_FILE}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
