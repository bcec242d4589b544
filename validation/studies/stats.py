"""Statistical tests for samplers: Pearson's chi-square on a (cos θ, φ) histogram (STYLE.md §9).

:func:`chi2_test` draws ``n_samples`` directions from a sampler, bins them on a grid in ``(cos θ,
φ)`` about the +z axis, and compares the counts with the counts expected from the sampler's pdf,
integrated over each cell by composite Gauss–Legendre quadrature in both coordinates. Before any
statistics it refuses samples outside the domain, a negative pdf, and pdf mass above 1 + 1e-3. Cells
expecting fewer than 5 samples are pooled into one bin; the p-value comes from
``scipy.stats.chi2.sf`` and is compared with a Šidák-corrected significance level, so that the whole
suite's chi-square tests together have a false-alarm rate of α = 0.01. The family size ``n_tests``
is an argument: the suite's tests run through ``validation.studies.chi2_cases``, which passes the
number of registered cases, so no count is kept by hand.

Grid. ``res`` is the number of cell *edges* in cos θ and must be odd; the cos θ range of the domain
([0, 1] for ``"hemisphere"``, [−1, 1] for ``"sphere"``) is split into ``res − 1`` equal cells, so on
the sphere the horizon cos θ = 0 is an edge and no cell straddles it (where a BRDF sampler's density
jumps). φ ∈ [0, 2π) has ``2 (res − 1)`` cells.

References
----------
- W. Jakob et al., Mitsuba 3, ``mitsuba/python/chi2.py`` (the design this test follows).
- Z. Šidák, "Rectangular confidence regions for the means of multivariate normal distributions",
  JASA 62, 1967.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from reference.errors import require, require_choice

__all__ = ["DOMAINS", "Chi2Result", "chi2_test", "sidak_alpha"]

#: Domains of :func:`chi2_test`: the cos θ range each covers.
DOMAINS = {"hemisphere": (0.0, 1.0), "sphere": (-1.0, 1.0)}


def sidak_alpha(alpha: float, n_tests: int) -> float:
    """Per-test significance level so that ``n_tests`` independent tests have family level α.

    ``1 − (1 − α)^(1/n)`` (Šidák 1967).

    Examples
    --------
    >>> round(sidak_alpha(0.01, 1), 12), round(sidak_alpha(0.05, 2), 6)
    (0.01, 0.025321)
    """
    require(0.0 < alpha < 1.0, f"sidak_alpha: alpha: must be in (0, 1), got {alpha}")
    require(n_tests >= 1, f"sidak_alpha: n_tests: must be >= 1, got {n_tests}")
    return 1.0 - (1.0 - alpha) ** (1.0 / n_tests)


@dataclass
class Chi2Result:
    """Outcome of :func:`chi2_test`.

    Attributes
    ----------
    passed : bool
        True when the checks hold and ``p_value >= alpha``.
    message : str
        One line: the verdict, the statistic, and the saved files on failure.
    p_value, statistic, alpha : float
        The p-value, Pearson's statistic, the Šidák-corrected level.
    dof : int
        Degrees of freedom (bins after pooling − 1).
    observed, expected : ndarray, shape (n_theta, n_phi)
        Histograms; ``expected`` is scaled to ``n_samples``.
    files : list of Path
        Diagnostics written on failure.
    """

    passed: bool
    message: str
    p_value: float = float("nan")
    statistic: float = float("nan")
    alpha: float = float("nan")
    dof: int = 0
    observed: np.ndarray | None = None
    expected: np.ndarray | None = None
    files: list = field(default_factory=list)


def _gauss_legendre(edges: np.ndarray, order: int, sub: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss–Legendre nodes and weights on each interval of ``edges``.

    Returns nodes and weights of shape ``(n_cells, sub·order)``.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    lo, hi = edges[:-1, None], edges[1:, None]
    fine = lo + (hi - lo) * (np.arange(sub + 1)[None, :] / sub)  # (n, sub+1)
    a, b = fine[:, :-1, None], fine[:, 1:, None]
    nodes = (a + b) / 2.0 + (b - a) / 2.0 * x[None, None, :]
    weights = (b - a) / 2.0 * w[None, None, :]
    n = edges.size - 1
    return nodes.reshape(n, -1), weights.reshape(n, -1)


def _directions(cos_theta, phi) -> np.ndarray:
    """Unit directions ``(..., 3)`` at ``(cos θ, φ)`` about +z."""
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


def _save_diagnostics(out_dir, name, observed, expected) -> list[Path]:
    """Write ``chi2_<name>.npz`` and a PNG of expected, observed and their difference."""
    import io

    import matplotlib.pyplot as plt

    from reference.files import write_bytes_atomic

    out_dir = Path(out_dir)
    npz = out_dir / f"chi2_{name}.npz"
    buffer = io.BytesIO()
    np.savez(buffer, observed=observed, expected=expected)
    write_bytes_atomic(npz, buffer.getvalue())
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.5))
    for ax, image, title in zip(
        axes,
        (expected, observed, observed - expected),
        ("expected", "observed", "observed − expected"),
        strict=True,
    ):
        shown = ax.imshow(image, aspect="auto", cmap="coolwarm" if "−" in title else "viridis")
        ax.set_title(title)
        ax.set_xlabel("φ cell")
        ax.set_ylabel("cos θ cell")
        fig.colorbar(shown, ax=ax)
    png = out_dir / f"chi2_{name}.png"
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    write_bytes_atomic(png, buffer.getvalue())
    return [npz, png]


class _RefusedError(Exception):
    """A check before the statistics failed; the message says which."""


@dataclass(frozen=True)
class _Grid:
    """The histogram grid of one test: the domain and the cell edges in cos θ and in φ."""

    domain: str
    cos_edges: np.ndarray
    phi_edges: np.ndarray

    @classmethod
    def on(cls, domain: str, res: int) -> _Grid:
        """Check ``domain`` and ``res``; ``res − 1`` cells in cos θ and ``2 (res − 1)`` in φ."""
        require_choice(domain, DOMAINS, "chi2 domain")
        require(
            isinstance(res, int) and res >= 3 and res % 2 == 1,
            f"chi2_test: res: must be an odd integer >= 3 (cos θ cell edges), got {res!r}",
        )
        lo, hi = DOMAINS[domain]
        n_phi = 2 * (res - 1)
        return cls(domain, np.linspace(lo, hi, res), np.linspace(0.0, 2.0 * np.pi, n_phi + 1))

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_theta, n_phi)``: the number of cells in cos θ and in φ."""
        return self.cos_edges.size - 1, self.phi_edges.size - 1


class _Counts(NamedTuple):
    """Observed and expected counts per cell, and the pdf's mass over the domain."""

    observed: np.ndarray
    expected: np.ndarray
    mass: float


def _histogram(sample, n_samples: int, seed: int, grid: _Grid) -> tuple[np.ndarray, int]:
    """Draw and bin the samples: ``(observed, n_valid)``; refuses samples outside the domain."""
    # Samples: directions, then their cell.
    u = np.random.default_rng(seed).random((n_samples, 2))
    d = np.asarray(sample(u), dtype=np.float64)
    if d.shape != (n_samples, 3):
        raise _RefusedError(f"sample returned shape {d.shape}, expected {(n_samples, 3)}")
    valid = np.isfinite(d).all(axis=-1) & (np.linalg.norm(d, axis=-1) > 0.5)
    d = d[valid]
    cos_theta = np.clip(d[:, 2] / np.linalg.norm(d, axis=-1), -1.0, 1.0)
    outside = cos_theta < grid.cos_edges[0] - 1e-9
    if outside.any():
        worst = float(cos_theta.min())
        count = int(outside.sum())
        raise _RefusedError(f"{count} samples outside the {grid.domain} (cos θ = {worst:.3g})")
    phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), 2.0 * np.pi)
    observed, _, _ = np.histogram2d(cos_theta, phi, bins=[grid.cos_edges, grid.phi_edges])
    return observed, int(valid.sum())


def _expected_counts(pdf, n_samples: int, grid: _Grid, quad_order: int, quad_sub: int) -> tuple:
    """The pdf integrated over each cell, as counts: ``(expected, mass)``.

    Refuses a negative or non-finite pdf, and pdf mass above 1 + 1e-3.
    """
    n_theta, n_phi = grid.shape
    # Composite Gauss–Legendre in cos θ and φ, one row of cos θ cells at a time.
    c_nodes, c_w = _gauss_legendre(grid.cos_edges, quad_order, quad_sub)
    p_nodes, p_w = _gauss_legendre(grid.phi_edges, quad_order, quad_sub)
    expected = np.zeros((n_theta, n_phi))
    for i in range(n_theta):
        C, P = np.meshgrid(c_nodes[i], p_nodes.ravel(), indexing="ij")
        values = np.asarray(pdf(_directions(C.ravel(), P.ravel())), dtype=np.float64)
        values = values.reshape(C.shape)
        if not np.isfinite(values).all() or (values < 0).any():
            raise _RefusedError("the pdf is negative or not finite inside the domain")
        weighted = (c_w[i][:, None] * values).sum(axis=0).reshape(n_phi, -1)
        expected[i] = (weighted * p_w).sum(axis=1)
    mass = float(expected.sum())
    if mass > 1.0 + 1e-3:
        raise _RefusedError(f"the pdf integrates to {mass:.6f} > 1 + 1e-3 over the {grid.domain}")
    expected *= n_samples
    return expected, mass


def _pool_cells(counts: _Counts, n_samples: int, n_valid: int) -> tuple[np.ndarray, np.ndarray]:
    """Pool the cells expecting fewer than 5 samples into one bin: ``(bins_o, bins_e)``."""
    # The chi-square approximation needs E >= 5.
    order = np.argsort(counts.expected.ravel())
    e_flat, o_flat = counts.expected.ravel()[order], counts.observed.ravel()[order]
    small = e_flat < 5.0
    bins_e = list(e_flat[~small])
    bins_o = list(o_flat[~small])
    pooled_e, pooled_o = float(e_flat[small].sum()), float(o_flat[small].sum())
    # Samples the pdf does not account for (mass < 1: invalid samples) join the pooled bin.
    pooled_e += n_samples * (1.0 - counts.mass) if counts.mass < 1.0 else 0.0
    pooled_o += float(n_samples - n_valid)
    if pooled_e > 0.0 or pooled_o > 0.0:
        if pooled_e < 5.0 and bins_e:
            bins_e[0] += pooled_e
            bins_o[0] += pooled_o
        else:
            bins_e.append(pooled_e)
            bins_o.append(pooled_o)
    return np.asarray(bins_o), np.asarray(bins_e)


def _pearson(bins_o: np.ndarray, bins_e: np.ndarray) -> tuple[float, int]:
    """Pearson's statistic and its degrees of freedom; refuses samples where none are expected."""
    if (bins_e <= 0).any() and (bins_o[bins_e <= 0] > 0).any():
        raise _RefusedError("samples fell where the pdf integrates to zero")
    keep = bins_e > 0
    statistic = float(((bins_o[keep] - bins_e[keep]) ** 2 / bins_e[keep]).sum())
    return statistic, int(keep.sum()) - 1


def _report(name, out_dir, alpha_test: float, counts: _Counts, statistic: float, dof: int):
    """The p-value against the Šidák-corrected level; diagnostics saved on failure."""
    from scipy.stats import chi2

    p_value = float(chi2.sf(statistic, dof))
    passed = p_value >= alpha_test
    message = (
        f"chi2 {name}: p = {p_value:.3g} vs Šidák α = {alpha_test:.3g} "
        f"(χ² = {statistic:.1f}, dof = {dof}, mass = {counts.mass:.5f})"
    )
    files = []
    if not passed and out_dir is not None:
        files = _save_diagnostics(out_dir, name, counts.observed, counts.expected)
        message += "; saved " + ", ".join(str(f) for f in files)
    return Chi2Result(
        passed,
        message,
        p_value,
        statistic,
        alpha_test,
        dof,
        counts.observed,
        counts.expected,
        files,
    )


def chi2_test(
    sample: Callable[[np.ndarray], np.ndarray],
    pdf: Callable[[np.ndarray], np.ndarray],
    domain: str,
    n_samples: int,
    res: int,
    seed: int,
    *,
    name: str = "sampler",
    out_dir=None,
    n_tests: int,
    alpha: float = 0.01,
    quad_order: int = 6,
    quad_sub: int = 4,
) -> Chi2Result:
    """Pearson's chi-square test of a direction sampler against its pdf.

    Parameters
    ----------
    sample : callable
        ``sample(u) -> directions``: maps uniform numbers ``u`` of shape ``(n, 2)`` to unit
        directions ``(n, 3)``; θ is measured from +z.
    pdf : callable
        ``pdf(directions) -> density`` w.r.t. solid angle, shape ``(n,)``.
    domain : {"hemisphere", "sphere"}
        Where samples may fall: cos θ in [0, 1] or [−1, 1].
    n_samples : int
        Number of samples, >= 1000.
    res : int
        Odd number of cell edges in cos θ (>= 3); φ gets ``2 (res − 1)`` cells.
    seed : int
        Seed of the uniform numbers (``np.random.default_rng(seed)``).
    name : str
        Used in file names and messages.
    out_dir : str or Path, optional
        Where to write ``chi2_<name>.npz`` and ``chi2_<name>.png`` on failure (a test's
        ``tmp_path``).
    n_tests : int
        Number of chi-square tests in the family (Šidák correction); the suite passes
        ``len(validation.studies.chi2_cases.CHI2_CASES)``.
    alpha : float
        Family-wise significance level.
    quad_order, quad_sub : int
        Gauss–Legendre order and number of sub-intervals per cell and coordinate.

    Returns
    -------
    Chi2Result
        ``passed`` and a one-line ``message``.

    Raises
    ------
    SpecrefError
        On a bad ``domain``, ``res``, ``n_samples``, ``alpha`` or ``n_tests``.

    Examples
    --------
    >>> def uniform_hemisphere(u):
    ...     z = u[:, 0]
    ...     r = np.sqrt(1 - z * z)
    ...     phi = 2 * np.pi * u[:, 1]
    ...     return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)
    >>> result = chi2_test(uniform_hemisphere, lambda d: np.full(len(d), 1 / (2 * np.pi)),
    ...                    "hemisphere", 20000, 9, seed=1, n_tests=1)
    >>> result.passed, result.dof
    (True, 127)
    """
    grid = _Grid.on(domain, res)
    require(n_samples >= 1000, f"chi2_test: n_samples: must be >= 1000, got {n_samples}")
    alpha_test = sidak_alpha(alpha, n_tests)
    try:
        # Check and bin the samples, integrate the pdf over each cell, pool the small cells.
        observed, n_valid = _histogram(sample, n_samples, seed, grid)
        expected, mass = _expected_counts(pdf, n_samples, grid, quad_order, quad_sub)
        counts = _Counts(observed, expected, mass)
        statistic, dof = _pearson(*_pool_cells(counts, n_samples, n_valid))
    except _RefusedError as refusal:
        return Chi2Result(False, f"chi2 {name}: {refusal}", alpha=alpha_test)
    return _report(name, out_dir, alpha_test, counts, statistic, dof)
