"""Multi-angle (five-angle) measurements of effect paints, and a BRDF fitted to them (Herbert §3.2).

Herbert et al. (§3.2) characterize effect pigments by gonio-spectral measurements "at five
angles", the geometry of the multi-angle spectrophotometers used for automotive and effect
finishes (ASTM E2194, DIN 6175-2): the sample is lit at 45° from the normal and read in the plane
of incidence at the **aspecular angles** 15°, 25°, 45°, 75° and 110°, measured from the specular
direction towards the light. An instrument reports the **reflectance factor** ``R(λ)`` of each
reading, the ratio to a perfect white diffuser under the same geometry: ``R = π f_r`` with
``f_r`` the BRDF (1/sr).

- :class:`MultiAngleMeasurement` holds one sample's readings; :func:`read_five_angle_csv` and
  :func:`write_five_angle_csv` are its file format (``docs/herbert-polymer.md``, "Five-angle
  measurements"), and :func:`five_angle_readings` makes the readings of any BRDF of specref's
  registry (a synthetic instrument).
- :func:`fit_ggx_five_angle` fits the GGX microfacet BRDF with a Lambertian base
  (``reference.materials.isotropic.brdf_ggx``, Eq. (20), Walter et al. 2007) to the
  readings: a diffuse reflectance ``ρ_d(λ)`` and a normal-incidence Fresnel reflectance
  ``F_0(λ)`` per band, one roughness ``α``; each reading weighs by its own size, so the dim
  far-from-specular angles count as much as the bright near-specular ones (specref's choice,
  erratum E110). The fit renders through every path a registered BRDF takes (point lights,
  SHRMs): :func:`ggx_fit_material`.

References
----------
- F. Herbert et al., "Multispectral Virtual Reality", 2004, §3.2.
- ASTM E2194, "Standard Practice for Multiangle Color Measurement of Metal Flake Pigmented
  Materials" (the 45° illumination and the aspecular angles 15°, 45°, 110°; 25° and 75° from
  DIN 6175-2).
- B. Walter et al., "Microfacet Models for Refraction through Rough Surfaces", EGSR 2007.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.files import write_text_atomic

__all__ = [
    "FIVE_ASPECULAR_DEG",
    "GGXFit",
    "MultiAngleMeasurement",
    "aspecular_directions",
    "fit_ggx_five_angle",
    "five_angle_readings",
    "ggx_fit_material",
    "read_five_angle_csv",
    "write_five_angle_csv",
]

#: The five aspecular angles of multi-angle instruments, degrees from the specular direction.
FIVE_ASPECULAR_DEG = (15.0, 25.0, 45.0, 75.0, 110.0)
#: The illumination angle of those instruments, degrees from the normal.
ILLUMINATION_DEG = 45.0
_MAGIC = "# specref five-angle 1"


@dataclass(frozen=True)
class MultiAngleMeasurement:
    """One sample's multi-angle readings.

    Attributes
    ----------
    name : str
    illumination_deg : float
        The light's angle from the normal, degrees.
    aspecular_deg : ndarray, shape (A,)
        The readings' aspecular angles, degrees from the specular direction towards the light.
    wavelengths_nm : ndarray, shape (B,)
    reflectance_factor : ndarray, shape (A, B)
        ``R = π f_r`` per reading and band (a perfect white diffuser is 1).
    """

    name: str
    illumination_deg: float
    aspecular_deg: np.ndarray
    wavelengths_nm: np.ndarray
    reflectance_factor: np.ndarray


def aspecular_directions(aspecular_deg, illumination_deg: float = ILLUMINATION_DEG):
    """Unit directions of the light and of each reading, in the plane of incidence (normal +z).

    The light is at ``θ_i`` on the −x side, ``ω_i = (−sin θ_i, 0, cos θ_i)``; the specular
    direction at ``+θ_i``; a reading at aspecular angle ``a`` at ``θ_i − a`` (signed: a reading
    past the normal, ``a > θ_i``, is on the light's side).

    Returns
    -------
    wi : ndarray, shape (3,)
    wo : ndarray, shape (A, 3)

    Examples
    --------
    >>> wi, wo = aspecular_directions([0.0, 45.0])
    >>> wi.round(4).tolist(), wo.round(4).tolist()
    ([-0.7071, 0.0, 0.7071], [[0.7071, 0.0, 0.7071], [0.0, 0.0, 1.0]])
    """
    theta_i = math.radians(illumination_deg)
    view = theta_i - np.radians(np.asarray(aspecular_deg, dtype=np.float64))
    wi = np.array([-math.sin(theta_i), 0.0, math.cos(theta_i)])
    wo = np.stack([np.sin(view), np.zeros_like(view), np.cos(view)], axis=-1)
    return wi, wo


def five_angle_readings(
    brdf, wavelengths_nm, name: str = "synthetic", aspecular_deg=FIVE_ASPECULAR_DEG,
    illumination_deg: float = ILLUMINATION_DEG,
) -> MultiAngleMeasurement:  # fmt: skip
    """What a multi-angle instrument reads of a BRDF: ``R = π f_r(ω_i, ω_o)`` per angle and band.

    ``brdf(wi, wo, normal)`` returns shape ``(..., B)`` (a registered BRDF with its parameters
    bound, e.g. ``functools.partial(brdf_ggx, rho_d=..., F_0=..., alpha=...)``).

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> m = five_angle_readings(lambda wi, wo, n: brdf_lambert(wi, wo, n, [0.5, 0.5]), [500, 600])
    >>> m.reflectance_factor.round(6).tolist()[0]
    [0.5, 0.5]
    """
    wi, wo = aspecular_directions(aspecular_deg, illumination_deg)
    normal = np.array([0.0, 0.0, 1.0])
    f = np.asarray(brdf(np.broadcast_to(wi, wo.shape), wo, normal), dtype=np.float64)
    return MultiAngleMeasurement(
        name, float(illumination_deg), np.asarray(aspecular_deg, dtype=np.float64),
        np.asarray(wavelengths_nm, dtype=np.float64), np.pi * f.reshape(len(wo), -1),
    )  # fmt: skip


def write_five_angle_csv(path, m: MultiAngleMeasurement) -> Path:
    """Write readings in the five-angle CSV format (atomic write; module docstring).

    Examples
    --------
    >>> import tempfile, os
    >>> m = MultiAngleMeasurement("grey", 45.0, np.array(FIVE_ASPECULAR_DEG),
    ...                           np.array([400.0, 700.0]), np.full((5, 2), 0.3))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = read_five_angle_csv(write_five_angle_csv(os.path.join(d, "g.csv"), m))
    >>> back.name, back.reflectance_factor.shape
    ('grey', (5, 2))
    """
    out = io.StringIO()
    out.write(f"{_MAGIC}\n# name: {m.name}\n# illumination_deg: {m.illumination_deg:g}\n")
    out.write("# values: reflectance factor R = pi * BRDF (a perfect white diffuser is 1)\n")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["aspecular_deg", *(f"{w:g}" for w in m.wavelengths_nm)])
    for angle, row in zip(m.aspecular_deg, m.reflectance_factor, strict=True):
        writer.writerow([f"{angle:g}", *(repr(float(v)) for v in row)])
    return write_text_atomic(Path(path), out.getvalue())


def _number(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SpecrefError(f"{where}: must be a number, got {text.strip()!r:.40}") from None
    require(math.isfinite(value), f"{where}: must be finite, got {text.strip()!r}")
    return value


def read_five_angle_csv(path, aspecular_deg=FIVE_ASPECULAR_DEG) -> MultiAngleMeasurement:
    """Read a five-angle CSV file (format: module docstring and ``docs/herbert-polymer.md``).

    Raises
    ------
    SpecrefError
        One line naming the file (and line): an unreadable or non-UTF-8 file, a missing header,
        an illumination angle outside (0°, 90°), wavelengths not increasing, a row of the wrong
        length, a value that is not a finite number >= 0, and readings that are not exactly the
        angles ``aspecular_deg`` (missing, extra or repeated).

    Examples
    --------
    >>> read_five_angle_csv("/nonexistent/paint.csv")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/paint.csv: file not found
    """
    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise SpecrefError(
            f"{path}: cannot read a UTF-8 CSV file ({type(error).__name__})"
        ) from None
    meta, rows = {"name": path.stem, "illumination_deg": str(ILLUMINATION_DEG)}, []
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            if key.strip() in meta and value.strip():
                meta[key.strip()] = value.strip()
        elif line.strip():
            rows.append((number, next(csv.reader([line]))))
    require(rows, f"{path}: no header row (aspecular_deg, then one wavelength per column)")
    (number, header), data = rows[0], rows[1:]
    at = f"{path}: line {number}"
    require(header[0].strip() == "aspecular_deg", f"{at}: the first column must be aspecular_deg")
    wavelengths = np.array([_number(w, f"{at}: wavelength") for w in header[1:]])
    require(wavelengths.size >= 1, f"{at}: no wavelength columns")
    require(bool((np.diff(wavelengths) > 0).all()), f"{at}: wavelengths must increase")
    illumination = _number(meta["illumination_deg"], f"{path}: illumination_deg")
    require(
        0 < illumination < 90, f"{path}: illumination_deg: must be in (0, 90), got {illumination:g}"
    )
    angles, values = [], []
    for number, fields in data:
        where = f"{path}: line {number}"
        require(
            len(fields) == len(header),
            f"{where}: {len(fields)} columns, the header has {len(header)}",
        )
        angles.append(_number(fields[0], f"{where}: aspecular_deg"))
        row = [_number(v, f"{where}: value") for v in fields[1:]]
        require(min(row) >= 0, f"{where}: reflectance factors must be >= 0, got {min(row):g}")
        # a reflectance factor of 1000 is beyond any paint's flop (1e308 overflowed the fit)
        require(max(row) <= 1e3, f"{where}: reflectance factors must be <= 1000, got {max(row):g}")
        values.append(row)
    expected = sorted(float(a) for a in aspecular_deg)
    require(
        sorted(angles) == expected,
        f"{path}: readings at {', '.join(f'{a:g}' for a in angles) or 'no angle'}°; a five-angle "
        f"file needs exactly one row at each of {', '.join(f'{a:g}' for a in expected)}°",
    )
    require(
        max(max(r) for r in values) >= 1e-4,
        f"{path}: every reading is below 1e-4: nothing to fit (all zero ended in an SVD failure)",
    )
    order = np.argsort(angles)
    return MultiAngleMeasurement(
        meta["name"], illumination, np.array(angles)[order], wavelengths, np.array(values)[order]
    )


@dataclass(frozen=True)
class GGXFit:
    """GGX with a Lambertian base fitted to multi-angle readings (:func:`fit_ggx_five_angle`).

    Attributes
    ----------
    wavelengths_nm : ndarray, shape (B,)
    rho_d, F_0 : ndarray, shape (B,)
        Diffuse reflectance and normal-incidence Fresnel reflectance per band.
    alpha : float
        GGX roughness.
    relative_error : ndarray, shape (A,)
        Per reading, the RMS over bands of ``(R_fit − R) / R``: the fit's error where measured.
    """

    wavelengths_nm: np.ndarray
    rho_d: np.ndarray
    F_0: np.ndarray
    alpha: float
    relative_error: np.ndarray

    def brdf(self, wi, wo, normal) -> np.ndarray:
        """The fitted BRDF, 1/sr, shape ``(..., B)`` (``brdf_ggx`` with these parameters)."""
        from reference.materials.isotropic import brdf_ggx

        return brdf_ggx(wi, wo, normal, self.rho_d, self.F_0, self.alpha)


def _ggx_columns(m: MultiAngleMeasurement, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """The readings' design for one α, ``R = π f = A [ρ_d, F_0] + b``.

    Eq. (20), Walter et al. 2007 (GGX with Schlick's Fresnel, plus Lambert).
    """
    from reference.materials.isotropic import brdf_ggx

    wi, wo = aspecular_directions(m.aspecular_deg, m.illumination_deg)
    n, wis = np.array([0.0, 0.0, 1.0]), np.broadcast_to(wi, wo.shape)
    # Schlick's F = F_0 (1 − s) + s is linear in F_0: three evaluations give the columns
    lobe_0 = np.pi * brdf_ggx(wis, wo, n, 0.0, 0.0, alpha)[..., 0]  # s · GD / (4 cos cos)
    lobe_1 = np.pi * brdf_ggx(wis, wo, n, 0.0, 1.0, alpha)[..., 0]  # GD / (4 cos cos)
    A = np.stack([np.ones(len(wo)), lobe_1 - lobe_0], axis=1)  # ρ_d/π · π = ρ_d
    return A, lobe_0


def _solve_bands(m: MultiAngleMeasurement, alpha: float):
    """For one α: per band the bounded, relatively weighted least squares (ρ_d, F_0); its cost."""
    from scipy.optimize import lsq_linear

    A, b = _ggx_columns(m, alpha)
    R = m.reflectance_factor
    weight = 1.0 / np.maximum(R, 1e-3 * R.max())  # each reading by its own size (erratum E110)
    params, cost = np.zeros((R.shape[1], 2)), 0.0
    for band in range(R.shape[1]):
        w = weight[:, band]
        fit = lsq_linear(A * w[:, None], (R[:, band] - b) * w, bounds=([0, 0], [np.inf, 1]))
        params[band], cost = fit.x, cost + 2 * fit.cost
    return params, cost


def fit_ggx_five_angle(m: MultiAngleMeasurement, alphas=None) -> GGXFit:
    """GGX plus Lambert fitted to multi-angle readings (module docstring; erratum E110).

    α is found on a logarithmic grid from 0.01 to 1 and refined around the best by a bounded
    scalar search; for each α, ``ρ_d(λ) >= 0`` and ``F_0(λ)`` in [0, 1] solve a bounded linear
    least squares per band, the readings weighted by their own size.

    Examples
    --------
    >>> from functools import partial
    >>> from reference.materials.isotropic import brdf_ggx
    >>> truth = partial(brdf_ggx, rho_d=[0.1, 0.3], F_0=[0.6, 0.2], alpha=0.15)
    >>> fit = fit_ggx_five_angle(five_angle_readings(truth, [450.0, 650.0]))
    >>> round(fit.alpha, 4), fit.rho_d.round(4).tolist(), fit.F_0.round(4).tolist()
    (0.15, [0.1, 0.3], [0.6, 0.2])
    """
    from scipy.optimize import minimize_scalar

    grid = np.geomspace(0.01, 1.0, 25) if alphas is None else np.asarray(alphas, dtype=float)
    costs = [_solve_bands(m, a)[1] for a in grid]
    k = int(np.argmin(costs))
    low, high = np.log(grid[max(k - 1, 0)]), np.log(grid[min(k + 1, len(grid) - 1)])
    best = minimize_scalar(
        lambda x: _solve_bands(m, float(np.exp(x)))[1], bounds=(low, high), method="bounded",
        options={"xatol": 1e-7},
    )  # fmt: skip
    alpha = float(np.exp(best.x)) if best.fun <= costs[k] else float(grid[k])
    params, _ = _solve_bands(m, alpha)
    A, b = _ggx_columns(m, alpha)
    R_fit = A @ params.T + b[:, None]
    R = m.reflectance_factor
    relative = (R_fit - R) / np.maximum(R, 1e-3 * R.max())
    return GGXFit(
        m.wavelengths_nm.copy(), params[:, 0].copy(), params[:, 1].copy(), alpha,
        np.sqrt(np.mean(relative**2, axis=1)),
    )  # fmt: skip


def ggx_fit_material(fit: GGXFit, name: str = "fitted") -> str:
    """The fit as a scene material (``type = "isotropic_brdf"``, ``brdf = "ggx"``; TOML).

    Its spectra keep their ends beyond the measured wavelengths (``extrapolation = "constant"``):
    instruments read 400-700 nm, specref's grid is 380-780 nm.

    Examples
    --------
    >>> fit = GGXFit(np.array([400.0, 700.0]), np.array([0.1, 0.2]), np.array([0.5, 0.5]),
    ...              0.2, np.zeros(5))
    >>> print(ggx_fit_material(fit, "paint").splitlines()[0])
    [materials.paint]
    """

    def spectrum(values):
        wl = ", ".join(f"{w:g}" for w in fit.wavelengths_nm)
        values = ", ".join(repr(float(v)) for v in values)
        # outside the measured range the ends are held (an instrument reads 400-700 nm)
        return f'{{ wavelengths = [{wl}], values = [{values}], extrapolation = "constant" }}'

    return "\n".join([
        f"[materials.{name}]",
        'type = "isotropic_brdf"',
        'brdf = "ggx"',
        f"rho_d = {spectrum(fit.rho_d)}",
        f"F_0 = {spectrum(fit.F_0)}",
        f"alpha = {fit.alpha!r}",
        "",
    ])  # fmt: skip
