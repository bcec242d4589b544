"""BRDF coefficients of isotropic 3-D BRDFs for SHRMs, and the orders F and P from a tolerance.

R&H 2002 (the reparameterization and the isotropic BRDF coefficients); the method is described in
:mod:`shrm.shrm`. The *transfer function* ``ρ̃`` is the BRDF times the cosine in a texel's frame
(``frame="normal"``: the polar axis is the surface normal; ``frame="reflection"``: it is the
reflection vector and the normal is the bisector of it and the view). Isotropy makes ``ρ̃`` depend
on ``(θ_i, θ_o, Δφ)`` only, so its double SH expansion has ``ρ_{lm,pq} = δ_mq ρ_{lp|m|}`` with

    ρ_{lpm} = 2π ∫∫∫ ρ̃(θ_i, θ_o, Δφ) cos(mΔφ) λ_lm(cos θ_i) λ_pm(cos θ_o) dcos θ_i dcos θ_o dΔφ

computed by :func:`brdf_sh_coefficients` (composite Gauss–Legendre in ``cos θ_i`` and
``cos θ_o``, the trapezoid rule in Δφ). :func:`choose_orders` and :func:`shrm_orders` pick F
(lighting) and P (view) from the coefficients' tails. :func:`shrm_brdf_parts` splits a registered
BRDF as SHRMs take it (its Lambertian part to an irradiance map, its grazing view power factored
out).

**The view fit.** In the normal frame a texel is only ever seen from views above its horizon,
``x = cos θ_o > 0``. Projecting over all views (``view_fit="sphere"``, R&H 2002) needs a
continuation below the horizon; the even one (``ω_o`` mirrored) has a kink at ``x = 0`` whenever
``ρ̃`` has a slope there, so only the ``p − m`` even terms survive and they decay slowly: the
error of order P concentrates at grazing views. ``view_fit="hemisphere"`` (the default in the
normal frame) instead fits the same basis ``λ_pm(x)``, ``p <= P``, to the views that reach the
texel only, by regularized weighted least squares per ``(l, m)``:

    min over ρ_{l·m}:  2π ∫_0^1 w(x) |g_lm(x) − Σ_p ρ_{lpm} λ_pm(x)|² dx
                       + μ Σ_p (ρ_{lpm} − ρ^sphere_{lpm})²,      w(x) = x^{−2k},

where ``g_lm`` is ρ̃'s ``(l, m)`` moment and k the grazing view power (:func:`shrm_brdf_parts`):
what is weighed is the error of the rendered radiance, ``x^{−k}`` times the stored one (Ward:
``w = 1/x``, whose log-divergent integral pulls the fit onto the horizon value). Every polynomial
degree in ``x`` now counts, not only the even ones. The normal equations are
``(G_m + μ I) ρ_{l·m} = b_{l·m} + μ ρ^sphere_{l·m}`` with ``G_m[p, p'] = 2π ∫_0^1 w λ_pm λ_p'm dx``
and ``b`` the weighted moments over the seen views (:func:`hemisphere_gram`). On the half range
alone ``G_m`` is nearly singular (condition 1e11 at P = 8): a polynomial fitted on [0, 1] may grow
without bound on [−1, 0], where bilinear lookups at neighbouring texels still read it. The
Tikhonov term (Tikhonov 1963; Hoerl & Kennard 1970) keeps it bounded: among near-best fits it
picks the one nearest the sphere projection ``ρ^sphere`` (the basis is orthonormal over all
views, so ``Σ (ρ − ρ^sphere)²`` is their distance there), and a view dependence that the sphere
projection already represents exactly (view-independent or even in ``x``) is left unchanged.
μ = :data:`VIEW_FIT_RIDGE`; the report study's image errors barely move for μ from 1e-8 to 1e-4
(docs/shrm.md). The fit of order P is not a truncation of the fit of a higher order: compute the
coefficients at the P used.

References
----------
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
- A. N. Tikhonov, "Solution of incorrectly formulated problems and the regularization method",
  Soviet Math. Dokl. 4, 1963.
- A. E. Hoerl, R. W. Kennard, "Ridge regression: biased estimation for nonorthogonal problems",
  Technometrics 12, 1970.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from reference.errors import require, require_choice
from shrm.sh import legendre_table

__all__ = [
    "FRAMES",
    "P_RANGE",
    "VIEW_FITS",
    "VIEW_FIT_RIDGE",
    "brdf_sh_coefficients",
    "choose_orders",
    "default_view_fit",
    "hemisphere_gram",
    "shrm_brdf_parts",
    "shrm_orders",
    "transfer_function",
]

#: The index frames of a SHRM (:mod:`shrm.shrm`).
FRAMES = ("normal", "reflection")
#: View orders P that §5.5, Herbert et al. allows: "typically between 2 and 10".
P_RANGE = (2, 10)
#: How the view dependence is fitted (module docstring): projection over all views (R&H 2002), or
#: weighted least squares over the views above a texel's horizon (normal frame).
VIEW_FITS = ("sphere", "hemisphere")
#: μ, the Tikhonov weight of the hemisphere fit (module docstring): small against the fit's
#: error, large enough to bound its energy below the horizon; the middle of the range 1e-8..1e-4
#: over which the study's image errors change by < 0.1 % of the peak.
VIEW_FIT_RIDGE = 1e-6
_Y = np.array([0.0, 1.0, 0.0])


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def transfer_function(
    brdf, params: dict, wi, wo, frame: str = "reflection", view_power: float = 0.0
) -> np.ndarray:
    """The transfer function ρ̃ = BRDF × cosine in a texel's local frame (polar axis +y).

    The integrand of the reflection equation (R&H 2002), in the frame of the module
    docstring; views below the horizon are mirrored above it. With a grazing view power k > 0
    it is ``cos^k θ_o · ρ̃``, the regular part of a BRDF that grows like ``cos^{−k} θ_o``
    (:func:`shrm_brdf_parts`).

    Parameters
    ----------
    brdf : callable
        ``brdf(wi, wo, normal, **params) -> (..., C)`` (the
        :data:`reference.materials.brdf.BRDF_METHODS` convention).
    params : dict
        Its parameters.
    wi, wo : ndarray, shape (..., 3)
        Local incident and view directions (unit).
    frame : {"normal", "reflection"}
    view_power : float
        k >= 0.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> y = np.array([0.0, 1.0, 0.0])
    >>> transfer_function(brdf_lambert, {"rho_d": [np.pi]}, y, y, "normal")
    array([1.])
    """
    require_choice(frame, FRAMES, "SHRM frame")
    wi, wo = np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)
    if frame == "normal":
        normal = np.broadcast_to(_Y, wo.shape)
        # Views below the horizon never occur: continue ρ̃ evenly across the tangent plane.
        wo = wo * np.where(wo[..., 1:2] < 0.0, np.array([1.0, -1.0, 1.0]), 1.0)
    else:
        # Reflection frame: the surface normal bisects the pole (the reflection vector) and the view
        h = wo + _Y
        normal = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    cosine = np.maximum(_dot(wi, normal), 0.0)[..., None]
    rho = brdf(wi, wo, normal, **params) * cosine
    if view_power:
        # The regular part cos^k θ_o ρ̃ of a BRDF that grows like cos^{-k} θ_o at grazing views
        rho = rho * np.maximum(_dot(wo, normal), 0.0)[..., None] ** view_power
    return rho


def default_view_fit(frame: str, view_fit: str | None = None) -> str:
    """The view fit of a frame: ``view_fit`` checked, or the frame's default.

    The default is ``"hemisphere"`` in the normal frame and ``"sphere"`` in the reflection frame.
    In the normal frame only views above a texel's horizon reach it; in the reflection frame every
    view but ``−r`` does (R&H 2002, reparameterization), so there is nothing to leave out and the
    hemisphere fit is refused.

    Examples
    --------
    >>> default_view_fit("normal"), default_view_fit("reflection")
    ('hemisphere', 'sphere')
    >>> default_view_fit("normal", "sphere")
    'sphere'
    >>> default_view_fit("reflection", "hemisphere")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: SHRM: view_fit 'hemisphere' needs frame 'normal' ...
    """
    require_choice(frame, FRAMES, "SHRM frame")
    if view_fit is None:
        return "hemisphere" if frame == "normal" else "sphere"
    require_choice(view_fit, VIEW_FITS, "SHRM view fit")
    require(
        view_fit == "sphere" or frame == "normal",
        "SHRM: view_fit 'hemisphere' needs frame 'normal' (in the reflection frame every view but "
        "one reaches a texel)",
    )
    return view_fit


def _view_nodes(P: int, quadrature: int, view_fit: str, view_power: float):
    """Nodes θ_o, weights of dcos θ_o and the fit's weights w(x) of the view integrals."""
    top = np.pi / 2 if view_fit == "hemisphere" else np.pi
    theta_o, w_o = _panels_gauss(np.linspace(0, top, max(8, P) + 1), quadrature)
    # The panels are in θ; dcos θ = sin θ dθ
    w_o = w_o * np.sin(theta_o)
    # w(x) = x^{-2k}: the error of the rendered radiance x^{-k} B (module docstring)
    fit = np.cos(theta_o) ** (-2.0 * view_power) if view_fit == "hemisphere" else 1.0
    return theta_o, w_o, w_o * fit


def hemisphere_gram(
    P: int, m: int, view_power: float = 0.0, quadrature: int = 8, weight: float | None = None
) -> np.ndarray:
    """The matrix of the hemisphere view fit, ``G_m[p, p'] = 2π ∫_0^1 w λ_pm λ_p'm dx + μ δ_pp'``.

    The normal equations of the regularized weighted least-squares fit over the views above a
    texel's horizon (module docstring; the basis of R&H 2002's isotropic BRDF coefficients), with
    ``w = x^{−2k}``, ``p, p' = m..P``.

    Parameters
    ----------
    P, m : int
        View order and azimuthal order, 0 <= m <= P.
    view_power : float
        The grazing view power k.
    quadrature : int
        Gauss–Legendre nodes per panel (:func:`brdf_sh_coefficients`).
    weight : float, optional
        μ; default :data:`VIEW_FIT_RIDGE`.

    Returns
    -------
    ndarray, shape (P+1−m, P+1−m)

    Examples
    --------
    >>> G = hemisphere_gram(6, 2, weight=0.0)   # half of the sphere's identity on the diagonal
    >>> G.diagonal().round(3)
    array([0.5, 0.5, 0.5, 0.5, 0.5])
    >>> f"{np.linalg.cond(hemisphere_gram(8, 0, weight=0.0)):.0e}"   # the half range alone
    '1e+11'
    """
    mu = VIEW_FIT_RIDGE if weight is None else float(weight)
    theta_o, _, w_o = _view_nodes(P, quadrature, "hemisphere", view_power)
    lam = _lambda_blocks(P, theta_o)[m]
    upper = 2.0 * np.pi * (lam * w_o) @ lam.T
    # The Tikhonov term μ Σ_p (ρ_p − ρ^sphere_p)² (the basis is orthonormal over all views)
    return upper + mu * np.eye(P + 1 - m)


def shrm_brdf_parts(name: str, params: dict, split: bool = True):
    """A registered BRDF as a SHRM takes it: the part to expand, a Lambertian part, a view power.

    R&H 2002 handle the Lambertian part of a BRDF with irradiance maps (Eq. (7), Ramamoorthi &
    Hanrahan 2001) and expand only the rest. A registry entry of
    :data:`reference.materials.brdf.BRDF_METHODS` declares

    - ``BRDFMethod.lambert``: the name of its Lambertian albedo parameter (``ρ_d/π`` is added to
      the rest of the model), which is split off and set to 0 in the part to expand;
    - ``BRDFMethod.grazing_view_power``: k where the model grows like ``cos^{−k} θ_o`` towards
      grazing views (Ward: ``1/sqrt(cos θ_i cos θ_o)``, Eq. (4), Ward 1992, k = 1/2); the SHRM
      expands ``cos^k θ_o ρ̃`` instead, which has no singularity.

    Parameters
    ----------
    name : str
        A key of ``BRDF_METHODS`` (an isotropic 3-D BRDF).
    params : dict
        Its parameters.
    split : bool
        Whether to split off the Lambertian part (needed with k > 0, whose factor would make the
        Lambertian part singular).

    Returns
    -------
    brdf : callable
    expand : dict
        Parameters of the part to expand.
    lambert : ndarray, shape (C,), or None
        The split-off albedo ρ_d.
    view_power : float
        k >= 0.

    Raises
    ------
    SpecrefError
        ``name`` is not a registered isotropic 3-D BRDF.

    Examples
    --------
    >>> _, expand, lambert, k = shrm_brdf_parts("ward_isotropic", {"rho_d": 0.2, "rho_s": 0.5,
    ...                                          "alpha": 0.3})
    >>> expand["rho_d"], lambert, k
    (0.0, array([0.2]), 0.5)
    """
    from reference.materials.brdf import BRDF_METHODS

    method = BRDF_METHODS.lookup(name)
    require(
        method.isotropic,
        f"SHRM: BRDF {name!r} is not an isotropic 3-D BRDF; allowed: "
        + ", ".join(n for n, m in BRDF_METHODS.items() if m.isotropic),
    )
    view_power = float(method.grazing_view_power)
    key = method.lambert
    expand, lambert = dict(params), None
    if key is not None and (split or view_power) and key in params:
        lambert = np.atleast_1d(np.asarray(params[key], dtype=np.float64))
        expand[key] = 0.0
    return method.reference, expand, lambert, view_power


def _panels_gauss(edges, order):
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.unique(np.asarray(edges, dtype=np.float64))
    half, mid = np.diff(edges) / 2, (edges[:-1] + edges[1:]) / 2
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def _lambda_blocks(order: int, theta: np.ndarray) -> list[np.ndarray]:
    """λ_lm(cos θ) as a list over m of arrays (L+1-m, N) (l = m..L)."""
    table = legendre_table(order, theta)
    starts = np.cumsum([0] + [order + 1 - m for m in range(order + 1)])
    return [table[starts[m] : starts[m + 1]] for m in range(order + 1)]


def brdf_sh_coefficients(
    brdf,
    params: dict,
    F: int,
    P: int,
    frame: str = "reflection",
    quadrature: int = 8,
    n_phi: int = 64,
    view_power: float = 0.0,
    view_fit: str | None = None,
    ridge: float | None = None,
) -> np.ndarray:
    """The isotropic BRDF's double SH coefficients ``ρ_{lpm}`` (lighting l ≤ F, view p ≤ P).

    R&H 2002, the isotropic BRDF coefficients:
    ``ρ_{lpm} = 2π ∫∫∫ ρ̃ cos(mΔφ) λ_lm(cos θ_i) λ_pm(cos θ_o)`` over
    ``cos θ_i, cos θ_o ∈ [−1, 1]`` and ``Δφ ∈ [0, 2π)`` (``view_fit="sphere"``); with
    ``view_fit="hemisphere"`` the same moments over the views above the horizon, weighted, solved
    with :func:`hemisphere_gram` (the weighted least-squares fit of the module docstring).

    Parameters
    ----------
    brdf : callable
        The BRDF (``BRDF_METHODS`` convention).
    params : dict
        Its parameters.
    F, P : int
        Lighting and view orders, >= 0.
    frame : {"normal", "reflection"}
    quadrature : int
        Gauss–Legendre nodes per panel; θ_i has panels clustered at the pole (0.01·2^k rad) plus
        ``max(8, F/2)`` uniform ones, θ_o ``max(8, P)`` uniform ones. Doubling it estimates the
        error.
    n_phi : int
        Trapezoid nodes in Δφ (exact for the cos(mΔφ) moments of trigonometric polynomials of
        degree < n_phi − m).
    view_power : float
        The grazing view power k (:func:`transfer_function`), >= 0.
    view_fit : {"sphere", "hemisphere"}, optional
        Default :func:`default_view_fit` of the frame; ``"hemisphere"`` needs the normal frame.
        A hemisphere fit of order P is not the truncation of one of a higher order.
    ridge : float, optional
        μ of the hemisphere fit, default :data:`VIEW_FIT_RIDGE`.

    Returns
    -------
    ndarray, shape (C, F+1, P+1, min(F, P)+1)
        ``rho[c, l, p, m]``, zero where ``m > min(l, p)``.

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> rho = brdf_sh_coefficients(brdf_lambert, {"rho_d": [1.0]}, 2, 2, "normal")
    >>> rho.shape, round(float(rho[0, 0, 0, 0]), 4)   # ∫∫ ρ̃ Y00 Y00 = (1/4π) · 1 · 4π
    ((1, 3, 3, 3), 1.0)

    A transfer function linear in the view, ``cos θ_i cos θ_o``: the sphere projection sees its
    even continuation ``|cos θ_o|`` (p = 0, 2, ...), the hemisphere fit the function itself (p = 1).

    >>> def f(wi, wo, normal):
    ...     return np.ones(wi.shape[:-1] + (1,)) * wo[..., 1:2]
    >>> for fit in VIEW_FITS:
    ...     r = brdf_sh_coefficients(f, {}, 1, 3, "normal", view_fit=fit)[0, 1, :, 0]
    ...     print(fit, r.round(2) + 0.0)
    sphere [1.81 0.   1.01 0.  ]
    hemisphere [0.   2.09 0.   0.  ]
    """
    require_choice(frame, FRAMES, "SHRM frame")
    view_fit = default_view_fit(frame, view_fit)
    require(isinstance(F, int) and F >= 0, f"SHRM: F: must be an integer >= 0, got {F!r}")
    require(isinstance(P, int) and P >= 0, f"SHRM: P: must be an integer >= 0, got {P!r}")
    nodes = _projection_nodes(F, P, quadrature, n_phi, view_fit, view_power)
    rho_tilde = functools.partial(
        transfer_function, brdf, params, frame=frame, view_power=view_power
    )
    rho, b = _project_transfer(rho_tilde, nodes, F, P, fit=view_fit == "hemisphere")
    if view_fit == "sphere":
        return rho
    return _fit_hemisphere(rho, b, view_power, quadrature, ridge)


class _Nodes(NamedTuple):
    """The quadrature of R&H 2002's triple integral: θ_i, θ_o and Δφ with their weights."""

    theta_i: np.ndarray  # lighting polar angles
    w_i: np.ndarray  # weights of dcos θ_i
    theta_o: np.ndarray  # view polar angles
    w_o: np.ndarray  # weights of dcos θ_o
    w_fit: np.ndarray  # the hemisphere fit's weights, w(x) dcos θ_o
    phi: np.ndarray  # Δφ, trapezoid nodes


def _projection_nodes(F, P, quadrature, n_phi, view_fit, view_power) -> _Nodes:
    """θ_i panels clustered at the pole plus ``max(8, F/2)`` uniform ones; θ_o; Δφ uniform."""
    near = 0.01 * 2.0 ** np.arange(8)
    theta_i, w_i = _panels_gauss(
        np.clip(np.concatenate([np.linspace(0, np.pi, max(8, F // 2) + 1), near]), 0, np.pi),
        quadrature,
    )
    theta_o, w_o, w_fit = _view_nodes(P, quadrature, view_fit, view_power)
    # The panels are in θ; dcos θ = sin θ dθ
    w_i = w_i * np.sin(theta_i)
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    return _Nodes(theta_i, w_i, theta_o, w_o, w_fit, phi)


def _project_transfer(rho_tilde, nodes: _Nodes, F: int, P: int, fit: bool):
    """R&H 2002's isotropic BRDF coefficients by quadrature, view by view.

    Returns ``rho`` (C, F+1, P+1, M+1) and, with ``fit``, the same moments weighted by the
    hemisphere fit's weights (``b`` of its normal equations; otherwise zeros).
    """
    theta_i, w_i, theta_o, w_o, w_fit, phi = nodes
    n_phi = phi.size
    M = min(F, P)
    lam_i, lam_o = _lambda_blocks(F, theta_i), _lambda_blocks(P, theta_o)
    cos_m_phi = np.cos(np.arange(M + 1)[:, None] * phi[None, :]) * (2.0 * np.pi / n_phi)
    s_i, s_o = np.sin(theta_i), np.sin(theta_o)
    # Local directions (y polar): ω_o at azimuth 0, ω_i at azimuth Δφ
    wo_dir = np.stack([np.zeros_like(s_o), np.cos(theta_o), -s_o], axis=-1)
    rho = None
    for a, wo_a in enumerate(wo_dir):
        wi_dir = np.stack(
            [
                s_i[:, None] * np.sin(phi)[None, :],
                np.broadcast_to(np.cos(theta_i)[:, None], (theta_i.size, n_phi)),
                -s_i[:, None] * np.cos(phi)[None, :],
            ],
            axis=-1,
        )
        wo_b = np.broadcast_to(wo_a, wi_dir.shape)
        values = rho_tilde(wi_dir, wo_b)
        if rho is None:
            rho = np.zeros((values.shape[-1], F + 1, P + 1, M + 1))
            b = np.zeros_like(rho)
        # R&H 2002, the isotropic BRDF coefficients: the Δφ moments, then the θ_i and θ_o sums
        moments = np.einsum("ijc,mj->mic", values, cos_m_phi) * w_i[None, :, None]
        for m in range(M + 1):
            # 2π ∫ λ_lm(θ_i) λ_pm(θ_o) · moment
            part = 2.0 * np.pi * (lam_i[m] @ moments[m]).T[:, :, None] * lam_o[m][None, None, :, a]
            rho[:, m:, m:, m] += part * w_o[a]  # (C, F+1-m, P+1-m)
            if fit:
                b[:, m:, m:, m] += part * w_fit[a]
    return rho, b


def _fit_hemisphere(rho, b, view_power: float, quadrature: int, ridge: float | None):
    """The hemisphere view fit: ``(G_m + μ I) ρ = b + μ ρ_sphere`` for every m (in place)."""
    P, M = rho.shape[2] - 1, rho.shape[3] - 1
    mu = VIEW_FIT_RIDGE if ridge is None else float(ridge)
    for m in range(M + 1):
        # The sphere projection of the even continuation: the moments over the seen views
        # twice for p − m even, none for p − m odd (λ_pm(−x) = (−1)^{p−m} λ_pm(x))
        prior = rho[:, :, m:, m] * (1.0 + (-1.0) ** np.arange(P + 1 - m))
        # The normal equations (G_m + μ I) ρ = b + μ ρ_sphere (module docstring)
        rhs = b[:, :, m:, m] + mu * prior
        G = hemisphere_gram(P, m, view_power, quadrature, mu)
        sol = np.linalg.solve(G, rhs.reshape(-1, P + 1 - m).T).T
        rho[:, :, m:, m] = sol.reshape(rhs.shape)
    return rho


def choose_orders(rho: np.ndarray, tol: float) -> tuple[int, int]:
    """The smallest orders (F, P) whose coefficient tails are below ``tol`` (relative, L2).

    R&H 2002, the isotropic BRDF coefficients.
    ``tail_F = sqrt(Σ_{l>F} |ρ_l|² / Σ |ρ|²)`` with
    ``|ρ_l|²`` summed over p, m (twice for m > 0, which stands for ±m) and bands; likewise for P.
    P is at least 2 and both at most what ``rho`` holds.

    Parameters
    ----------
    rho : ndarray, shape (C, F_max+1, P_max+1, M+1)
    tol : float
        In (0, 1).

    Returns
    -------
    F, P : int

    Raises
    ------
    SpecrefError
        ``tol`` outside (0, 1), or no order within ``rho`` reaches it.

    Examples
    --------
    >>> rho = np.zeros((1, 5, 4, 4)); rho[0, :, 0, 0] = [1.0, 0.5, 0.1, 0.001, 0.0]
    >>> choose_orders(rho, 0.01)
    (2, 2)
    """
    require(0.0 < tol < 1.0, f"SHRM: tol: must be in (0, 1), got {tol!r}")
    weight = np.where(np.arange(rho.shape[3]) > 0, 2.0, 1.0)
    energy = rho**2 * weight
    total = energy.sum()
    require(total > 0, "SHRM: the BRDF's transfer function is zero everywhere")
    orders = []
    for axis, name in ((1, "F"), (2, "P")):
        per = energy.sum(axis=tuple(a for a in range(4) if a != axis))
        tail = np.sqrt(np.maximum(total - np.cumsum(per), 0.0) / total)
        below = np.nonzero(tail <= tol)[0]
        require(
            below.size > 0,
            f"SHRM: no {name} up to {per.size - 1} reaches tol {tol:g} (tail {tail[-1]:.3g}); "
            "raise the tolerance or the maximum order",
        )
        orders.append(int(below[0]))
    return orders[0], max(orders[1], P_RANGE[0])


def shrm_orders(rho: np.ndarray, tol: float, F: int | None = None, P: int | None = None):
    """Orders (F, P) for a tolerance, or a check that requested orders meet it.

    R&H 2002, the isotropic BRDF coefficients (their tails, :func:`choose_orders`). P must lie in
    :data:`P_RANGE` (§5.5, Herbert et al.: "between 2 and 10") and neither order may be below what
    ``tol`` requires or above what ``rho`` holds.

    Parameters
    ----------
    rho : ndarray, shape (C, F_max+1, P_max+1, M+1)
    tol : float
    F, P : int, optional
        Requested orders; default the smallest that meet ``tol``.

    Returns
    -------
    F, P : int

    Raises
    ------
    SpecrefError
        A requested order outside what the tolerance allows.

    Examples
    --------
    >>> rho = np.zeros((1, 5, 4, 4)); rho[0, :, 0, 0] = [1.0, 0.5, 0.1, 0.001, 0.0]
    >>> shrm_orders(rho, 0.01, P=3)
    (2, 3)
    >>> shrm_orders(rho, 0.01, F=1)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: SHRM: F = 1 is outside what tol 0.01 allows: [2, 4]
    """
    F_min, P_min = choose_orders(rho, tol)
    F_max, P_max = rho.shape[1] - 1, min(rho.shape[2] - 1, P_RANGE[1])
    for name, value, low, high in (("F", F, F_min, F_max), ("P", P, P_min, P_max)):
        if value is not None:
            require(
                isinstance(value, int | np.integer) and low <= value <= high,
                f"SHRM: {name} = {value} is outside what tol {tol:g} allows: [{low}, {high}]",
            )
    require(P_min <= P_max, f"SHRM: tol {tol:g} needs P = {P_min} > {P_max} (§5.5 allows 2-10)")
    return (F_min if F is None else int(F)), (P_min if P is None else int(P))
