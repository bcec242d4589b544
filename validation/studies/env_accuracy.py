"""Studies of the environment SH order chosen from an accuracy (erratum E75; ``shrm.accuracy``).

- :func:`worst_case_maps`: synthetic maps where truncation hurts most, a single bright texel and a
  small sun disc over a dim sky;
- :func:`error_by_order`: the relative error of Y of the order-L frequency path against the
  brute-force angular oracle at fixed directions, per order, with the order
  :func:`shrm.accuracy.accuracy_order` picks (the report's error-against-order chart);
- :func:`render_against_oracle`: a sphere rendered by ``reference.scene.render.render_scene`` (the
  path of
  ``specref render``) with default settings against the same render with ``--oracle``, per pixel.
"""

from __future__ import annotations

import numpy as np

from reference.geometry.envmap import latlong_pixel_directions
from reference.scene.metadata import LIT_FRACTION
from shrm.accuracy import accuracy_order, bright_texels, sparse_convolution
from shrm.lobes import parse_kernel
from shrm.prefilter import prefilter_bruteforce
from shrm.sh import n_coefficients, sh_evaluate
from shrm.transform import project_latlong

__all__ = [
    "error_by_order",
    "fibonacci_directions",
    "relative_errors",
    "render_against_oracle",
    "sphere_scene_toml",
    "worst_case_maps",
]

#: Luminance of linear Rec. 709 / sRGB primaries (D65), for RGB maps in the order study.
SRGB_Y = np.array([0.2126729, 0.7151522, 0.0721750])


def worst_case_maps(height: int = 256) -> dict[str, np.ndarray]:
    """Synthetic RGB maps ``(H, 2H, 3)`` where a low order fails: a bright texel, a sun disc.

    Both have a dim sky (radiance 0.05, brighter towards the zenith) and a source carrying ten
    times the sky's power: ``single texel`` in one texel 20° above the horizon, ``sun disc`` in a
    disc of 1.5° radius (a sun with its aureole, several texels at H = 256) 40° above it.

    Examples
    --------
    >>> maps = worst_case_maps(16)
    >>> sorted(maps), maps["sun disc"].shape
    (['single texel', 'sun disc'], (16, 32, 3))
    """
    H = int(height)
    d = latlong_pixel_directions(H, 2 * H)
    sky = 0.05 * (1.0 + 0.5 * np.clip(d[..., 1], 0.0, None))
    theta = (np.arange(H) + 0.5) * np.pi / H
    texel_solid_angle = (np.pi / H) * (np.pi / H) * np.sin(theta)[:, None]
    sky_power = float(np.sum(sky * texel_solid_angle))
    maps = {}
    # a single bright texel, 20° above the horizon
    texel = sky.copy()
    j = int(H * (70.0 / 180.0))
    texel[j, H // 3] += 10.0 * sky_power / texel_solid_angle[j, 0]
    maps["single texel"] = texel
    # a sun disc of 1.5° radius, 40° above the horizon
    elevation = np.radians(40.0)
    sun = np.array([0.6 * np.cos(elevation), np.sin(elevation), -0.8 * np.cos(elevation)])
    cosines = d @ sun
    inside = (cosines >= np.cos(np.radians(1.5))) | (cosines == cosines.max())
    disc = sky.copy()
    disc[inside] += 10.0 * sky_power / float(np.sum(texel_solid_angle * inside))
    maps["sun disc"] = disc
    return {name: np.repeat(m[..., None], 3, axis=-1) for name, m in maps.items()}


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` nearly uniform unit directions on the sphere (Fibonacci lattice), ``(n, 3)``.

    Examples
    --------
    >>> np.linalg.norm(fibonacci_directions(5), axis=1).round(12)
    array([1., 1., 1., 1., 1.])
    """
    i = np.arange(n) + 0.5
    y = 1.0 - 2.0 * i / n
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    r = np.sqrt(1.0 - y**2)
    return np.stack([r * np.cos(phi), y, r * np.sin(phi)], axis=-1)


def relative_errors(approx, exact) -> tuple[float, float]:
    """Mean and max of ``|approx − exact| / exact`` where ``exact ≥ LIT_FRACTION · max``.

    The criterion every render promises (``reference.scene.metadata``).

    Examples
    --------
    >>> relative_errors(np.array([1.01, 2.0, 0.0]), np.array([1.0, 2.0, 1e-3]))
    (0.005..., 0.01...)
    """
    approx, exact = np.asarray(approx, dtype=float), np.asarray(exact, dtype=float)
    lit = exact >= LIT_FRACTION * exact.max()
    relative = np.abs(approx[lit] - exact[lit]) / exact[lit]
    return float(relative.mean()), float(relative.max())


def error_by_order(luminance, kernel, orders, directions, split: bool = True, exact=None) -> dict:
    """Error of the order-L frequency path of Y against brute force, per order.

    Eq. (7), Ramamoorthi & Hanrahan 2001 for the frequency path (``Λ_l L_lm`` summed to L at each
    direction); the oracle is :func:`shrm.prefilter.prefilter_bruteforce` of the same map. With
    ``split`` the brightest texels are lit exactly and SH carries the residual, as the render does
    (``shrm.accuracy.bright_texels``); without it SH carries the whole map.

    Parameters
    ----------
    luminance : ndarray, shape (H, 2H)
    kernel : str
    orders : sequence of int
        Orders to measure (those above the map's band limit are dropped).
    directions : ndarray, shape (N, 3)
    split : bool
        Light the bright texels exactly (the default render path).
    exact : ndarray, shape (N,), optional
        The oracle at ``directions``, when a call on the same map and kernel has computed it.

    Returns
    -------
    dict
        ``orders``, ``mean``, ``max`` (lists), ``chosen``: the :class:`OrderChoice` as a dict
        with its ``measured_mean`` and ``measured_max``, and ``exact`` (the oracle's values).

    Examples
    --------
    >>> sky = 1.0 + 0.2 * latlong_pixel_directions(32, 64)[..., 1]   # degrees 0 and 1 only
    >>> e = error_by_order(sky, "lambert", [0, 1], fibonacci_directions(20))
    >>> e["orders"], e["chosen"]["order"], e["max"][1] < 1e-3
    ([0, 1], 1, True)
    """
    luminance = np.asarray(luminance, dtype=np.float64)
    k = parse_kernel(kernel)
    if exact is None:
        exact = prefilter_bruteforce(luminance[..., None], k, directions)[:, 0]
    bright = bright_texels(luminance) if split else None
    chosen = accuracy_order(luminance, k, bright=bright).as_dict()
    band_limit = luminance.shape[1] // 2 - 1
    orders = sorted({int(L) for L in orders if band_limit >= L} | {chosen["order"]})
    residual, exact_part = luminance, 0.0
    if bright is not None:
        residual = luminance * bright.scale
        values = bright.exact_part(luminance[..., None])
        exact_part = sparse_convolution(values, bright.directions, bright.weights, k, directions)
        exact_part = exact_part[:, 0]
    coeffs = project_latlong(residual[..., None], orders[-1], backend="ducc0")[0]
    degree = np.repeat(np.arange(orders[-1] + 1), 2 * np.arange(orders[-1] + 1) + 1)
    filtered = k.Lambda(orders[-1])[degree] * coeffs
    out = {"orders": orders, "mean": [], "max": []}
    for L in orders:
        # Eq. (7), Ramamoorthi & Hanrahan 2001: E = Σ_{l<=L} Λ_l L_lm Y_lm
        approx = sh_evaluate(filtered[: n_coefficients(L)], directions, backend="ducc0")
        approx = approx + exact_part
        mean, worst = relative_errors(approx, exact)
        out["mean"].append(mean)
        out["max"].append(worst)
        if chosen["order"] == L:
            chosen["measured_mean"], chosen["measured_max"] = mean, worst
    out["chosen"] = chosen
    out["exact"] = exact
    return out


def sphere_scene_toml(environment, material: str = 'type = "lambert"\nk_d = 0.5', size: int = 12):
    """Scene-file TOML: a unit sphere of ``material`` (TOML lines) under an environment file.

    Examples
    --------
    >>> sphere_scene_toml("sky.hdr").splitlines()[-1]
    'file = "sky.hdr"'
    """
    return "\n".join(
        [
            "[camera]",
            "eye = [0.0, 0.0, 6.0]",
            "fov_deg = 24.0",
            "[render]",
            f"width = {size}",
            f"height = {size}",
            "supersample = 1",
            "[materials.m]",
            material,
            "[[objects]]",
            'type = "sphere"',
            'material = "m"',
            "[[lights]]",
            'type = "environment"',
            f'file = "{environment}"',
        ]
    )


def render_against_oracle(scene, options=None, oracle=None) -> dict:
    """A scene rendered with default settings (plus ``options``) against ``--oracle``, in Y.

    ``oracle`` is the ``oracle`` of an earlier call on the same scene (it does not depend on
    ``options``), so a second setting is measured without integrating the scene again.

    Returns
    -------
    dict
        ``mean``, ``max``: relative error of Y over lit sphere pixels (:func:`relative_errors`);
        ``records``: what the shaders chose (orders and promised bounds); ``oracle``: the
        brute-force render.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.images.formats import write_exr
    >>> from reference.scene.loader import loads_scene
    >>> sky = write_exr(pathlib.Path(tempfile.mkdtemp()) / "sky.exr", np.ones((32, 64, 3)))
    >>> found = render_against_oracle(loads_scene(sphere_scene_toml(sky, size=4)))
    >>> found["max"] < 1e-3, list(found["records"]["environment"].values())[0]["order"]
    ... # a uniform sky: order 0; the rest is the oracle's quadrature of the cosine's kink
    (True, 0)
    """
    import shrm  # noqa: F401  (registers the environment shaders)
    from reference.scene.render import render_scene

    fast = render_scene(scene, options=options)
    if oracle is None:
        oracle = render_scene(scene, options={"environment": "bruteforce"}, gbuffer=fast.gbuffer)
    mask = fast.gbuffer.mask
    mean, worst = relative_errors(fast.XYZ[..., 1][mask], oracle.XYZ[..., 1][mask])
    return {"mean": mean, "max": worst, "records": fast.records, "oracle": oracle}
