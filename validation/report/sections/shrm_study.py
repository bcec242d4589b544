"""The accuracy study of the report section "SHRMs" (:mod:`validation.report.sections.shrm`).

§5.5-5.6, Herbert et al. For each synthesized isotropic BRDF of :data:`SUITE` under a shared
environment, the image error of SHRM rendering against a per-pixel brute-force render (every pixel
integrates BRDF × environment over all environment pixels), as a function of the view order P, the
lighting order F, the cube-map size, the frame and the view fit (:mod:`shrm.brdf_sh`), and the
cheapest setting (by measured creation time) under a tolerance of 1 % of the peak.
"""

from __future__ import annotations

import time

import numpy as np

from reference.data import data_path

__all__ = [
    "create_timed",
    "image_error",
    "rho_corner",
    "study_brdf",
    "study_params",
    "study_setup",
    "sweep_plan",
]


#: Image tolerance of the target, relative to the brute-force image's peak.
TOLERANCE = 0.01
#: The synthesized BRDFs of the study (RGB channels; the pigment at 610, 550 and 465 nm).
SUITE = {
    "ward_isotropic": {"rho_d": [0.1, 0.2, 0.3], "rho_s": 0.5, "alpha": 0.3},
    "ggx": {"rho_d": [0.1, 0.2, 0.3], "F_0": 0.5, "alpha": 0.5},
    "lafortune": {
        "rho_d": [0.1, 0.2, 0.3],
        "rho_s": 0.6,
        "C_xy": -1.0,
        "C_z": 0.95,
        "n": [6, 8, 10],
    },
    "effect_pigment": {
        "wavelengths_nm": [610.0, 550.0, 465.0],
        "thickness_nm": 380.0,
        "n_film": 2.0,
        "n_base": 3.2,
        "k_base": 3.3,
        "rho_base": 0.05,
        "alpha": 0.5,
    },
}


def study_setup(quick: bool, rows: int | None = None, size: int | None = None):
    """Environment (RGB), G-buffer of a sphere (orthographic, distant viewer) and the view.

    ``rows`` (environment height) and ``size`` (image side) default to 16 and 20 in quick mode,
    64 and 48 otherwise.

    Examples
    --------
    >>> env, g, view = study_setup(quick=True)
    >>> env.shape, g.shape, view.tolist()
    ((16, 32, 3), (20, 20), [0.0, 0.0, 1.0])
    """
    from reference.geometry.camera import Camera, downsample_box
    from reference.geometry.gbuffer import render_gbuffer
    from reference.geometry.shapes import Sphere
    from reference.images.formats import read_image

    rows = rows or (16 if quick else 64)
    image = read_image(data_path("environments/venice_sunset_1k.hdr"))
    env = downsample_box(image[:, : 2 * image.shape[0]], image.shape[0] // rows)
    size = size or (20 if quick else 48)
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.2)
    g = render_gbuffer([Sphere()], camera, size, size)
    return env, g, np.asarray(camera.basis()[2], dtype=np.float64)


def study_params(name: str) -> dict:
    """The study's parameters of one BRDF (lists as arrays).

    Examples
    --------
    >>> study_params("ggx")["rho_d"]
    array([0.1, 0.2, 0.3])
    """
    return {
        k: (np.asarray(v, dtype=np.float64) if isinstance(v, list) else v)
        for k, v in SUITE[name].items()
    }


#: The (frame, view fit) pairs of the study: the default fit of each frame, and R&H 2002's
#: projection over all views in the normal frame for comparison.
FITS = (("normal", "hemisphere"), ("normal", "sphere"), ("reflection", "sphere"))


def sweep_plan(quick: bool) -> dict:
    """The settings the study sweeps: per frame and fit, lighting orders F, cube sizes S, and P.

    With the sphere fit every (frame, F, S) is created once at ``P_max`` and a lower P is the same
    SHRM truncated to ``(P+1)²`` view coefficients (``B_pq`` does not depend on the orders above
    p); a hemisphere fit is created at each P (it is not a truncation).

    Examples
    --------
    >>> sweep_plan(quick=True)["P"]
    (2, 4, 6, 8, 10, 12)
    """
    if quick:
        return {
            "P": (2, 4, 6, 8, 10, 12),
            ("normal", "hemisphere"): ((12, 16),),
            ("normal", "sphere"): ((12, 16),),
            ("reflection", "sphere"): ((12, 16),),
        }
    return {
        "P": (2, 4, 6, 8, 10, 12, 14),
        ("normal", "hemisphere"): ((8, 32), (16, 32), (24, 32), (16, 64)),
        ("normal", "sphere"): ((16, 32), (16, 64)),
        ("reflection", "sphere"): ((16, 64),),
    }


def image_error(image, truth, mask, far=None) -> float:
    """Largest per-pixel difference (any band) over the brute-force image's peak.

    Examples
    --------
    >>> truth = np.ones((1, 2, 1)); image = truth + [[[0.0], [0.02]]]
    >>> image_error(image, truth, np.ones((1, 2), bool))
    0.02
    """
    sel = mask if far is None else mask & far
    peak = truth[mask].max()
    return float(np.abs(image - truth).max(-1)[sel].max() / peak)


def create_timed(L_env, rho, frame, F, S, k, lam):
    """A SHRM of lighting order F and cube size S, and the seconds its creation took.

    Examples
    --------
    >>> from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    >>> env = np.ones((8, 16, 1)); L_env = np.zeros((1, 9)); L_env[0, 0] = 1.0
    >>> brdf, expand, lam, k = shrm_brdf_parts("ggx", study_params("ggx"))
    >>> rho = brdf_sh_coefficients(brdf, expand, 2, 2, "normal", view_power=k)
    >>> s, seconds = create_timed(L_env, rho[:1], "normal", 2, 4, k, None)
    >>> s.coeffs.shape[:2], seconds > 0
    ((6, 4), True)
    """
    from shrm.shrm import shrm_create

    start = time.perf_counter()
    s = shrm_create(L_env[:, : (F + 1) ** 2], rho, frame, size=S, view_power=k, lambert=lam)
    return s, time.perf_counter() - start


def _truncated(s, P):
    from dataclasses import replace

    return replace(s, coeffs=np.ascontiguousarray(s.coeffs[..., : (P + 1) ** 2]), P=P)


def rho_corner(rho, F, P):
    """The BRDF coefficients of orders (F, P), a corner of a larger set.

    Examples
    --------
    >>> rho_corner(np.zeros((3, 9, 9, 9)), 4, 2).shape
    (3, 5, 3, 3)
    """
    return np.ascontiguousarray(rho[:, : F + 1, : P + 1, : min(F, P) + 1])


def study_brdf(name, env, L_env, g, view, plan) -> dict:
    """The sweep for one BRDF: image errors of every setting and the cheapest under tolerance.

    Returns
    -------
    dict
        ``truth`` (the brute-force image) and its seconds, ``candidates`` (frame, F, P, S, error,
        error at N·V > 0.2, view fit), the ``choice`` with its measured creation seconds, its
        ``shrm`` and BRDF coefficients ``rho``, and whether it meets :data:`TOLERANCE`; the best
        settings with P <= 10 (any fit, and the sphere fit: None when the plan has none).

    Examples
    --------
    >>> from shrm.transform import project_latlong
    >>> env, g, view = study_setup(quick=True, rows=8, size=8)
    >>> plan = {"P": (2, 4), **{fit: ((4, 8),) for fit in FITS}}
    >>> st = study_brdf("ggx", env, project_latlong(env, 4), g, view, plan)
    >>> len(st["candidates"]), st["choice"] in st["candidates"]
    (6, True)
    """
    from shrm.brdf_sh import shrm_brdf_parts
    from shrm.shrm_oracles import render_bruteforce

    params = study_params(name)
    brdf, expand, lam, k = shrm_brdf_parts(name, params)
    start = time.perf_counter()
    truth = render_bruteforce(g, env, brdf, params, view)
    t_truth = time.perf_counter() - start
    coefficients = _Coefficients(brdf, expand, k, plan)
    candidates = _sweep(coefficients, L_env, g, view, truth, plan, lam)
    ok = [c for c in candidates if c[4] <= TOLERANCE]
    seconds, choice, shrm, r = _cheapest(ok, candidates, coefficients, L_env, lam)
    low = [c for c in candidates if c[2] <= 10]
    return {
        "truth": truth,
        "bruteforce_seconds": t_truth,
        "candidates": candidates,
        "meets_tolerance": bool(ok),
        "choice": choice,
        "shrm": shrm,
        "rho": r,
        "create_seconds": seconds,
        "best_with_P_at_most_10": min(low, key=lambda c: c[4]),
        "best_sphere_fit_with_P_at_most_10": min(
            (c for c in low if c[6] == "sphere"), key=lambda c: c[4], default=None
        ),
        "lambert_split": lam is not None,
        "grazing_view_power": k,
    }


class _Coefficients:
    """BRDF coefficients of one BRDF per (frame, fit, F, P), each projection made once.

    A sphere fit of order P is the corner of one at P_max; a hemisphere fit is made at P.
    """

    def __init__(self, brdf, expand, k, plan):
        self.brdf, self.expand, self.k, self.plan = brdf, expand, k, plan
        self.P_max = max(plan["P"])
        self.rho = {}

    def __call__(self, frame, fit, F, P):
        from shrm.brdf_sh import brdf_sh_coefficients

        key = (frame, fit, self.P_max if fit == "sphere" else P)
        if key not in self.rho:
            F_max = max(F for F, _ in self.plan[(frame, fit)])
            self.rho[key] = brdf_sh_coefficients(
                self.brdf, self.expand, F_max, key[2], frame, view_power=self.k, view_fit=fit
            )
        return rho_corner(self.rho[key], F, P)


def _sweep(coefficients, L_env, g, view, truth, plan, lam) -> list[tuple]:
    """Image error of each setting of the plan: (frame, F, P, S, error, error at N·V > 0.2, fit)."""
    from shrm.shrm import render_shrm

    k, P_max = coefficients.k, coefficients.P_max
    far = np.einsum("...i,...i->...", g.normal, g.view) > 0.2
    candidates = []
    for frame, fit in FITS:
        for F, S in plan[(frame, fit)]:
            if fit == "sphere":
                s, _ = create_timed(L_env, coefficients(frame, fit, F, P_max), frame, F, S, k, lam)
            for P in plan["P"]:
                if fit == "sphere":
                    shrm = _truncated(s, P)
                else:
                    shrm, _ = create_timed(
                        L_env, coefficients(frame, fit, F, P), frame, F, S, k, lam
                    )
                image = render_shrm(g, shrm, view)
                err = image_error(image, truth, g.mask)
                inner = image_error(image, truth, g.mask, far)
                candidates.append((frame, F, P, S, err, inner, fit))
    return candidates


def _cheapest(ok, candidates, coefficients, L_env, lam):
    """Time the settings that meet the tolerance and are not dominated; the fastest to create.

    Not dominated: no other with the same frame and fit and no more F, P, S. When none meets the
    tolerance, the most accurate setting. Returns (seconds, candidate, SHRM, BRDF coefficients).
    """
    pareto = [
        c
        for c in ok
        if not any(
            o is not c
            and (o[0], o[6]) == (c[0], c[6])
            and o[1] <= c[1]
            and o[2] <= c[2]
            and o[3] <= c[3]
            for o in ok
        )
    ] or [min(candidates, key=lambda c: c[4])]
    timed = []
    for c in pareto:
        frame, F, P, S = c[:4]
        r = coefficients(frame, c[6], F, P)
        s, seconds = create_timed(L_env, r, frame, F, S, coefficients.k, lam)
        timed.append((seconds, c, s, r))
    return min(timed, key=lambda t: t[0])
