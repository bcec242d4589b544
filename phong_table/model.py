"""The spectral Phong model in display RGB: diffuse RGB, specular functions (Wang et al.).

Wang et al. render one material under one point light. Everything that does not depend on the pixel
is folded into a few RGB vectors once per edit (:class:`SpectralPhong`):

- the spectra-to-RGB matrix ``M`` of Eq. (9), Wang et al.: the band weights of the light (ASTM E308,
  light folded in, so spectral lines between grid nodes are integrated) times the XYZ-to-RGB matrix;
- the diffuse RGB of Eq. (7), Wang et al.: ``D = I · k_d @ M``, multiplied per pixel by
  ``f_att cos θ``;
- the specular functions ``[f_rsp(t), f_gsp(t), f_bsp(t)] = Σ_λ I k_s(λ) t^{n(λ)} M(λ, ·)`` of
  Eq. (11), Wang et al., *without* ``f_att`` (Erratum E18: ``f_att`` depends on the pixel's distance
  to the light, not on ``t``, so a table of Eq. (11), Wang et al. as printed would hold for one
  distance only);
- the ambient RGB ``I_a k_a @ M_a`` of Eq. (1), Wang et al.

A pixel's linear display RGB is then

``RGB = ambient + f_att (cos θ · D + f_sp(t))``,

which is Eq. (2), Wang et al., integrated against the CMFs (Eq. (4), Wang et al.) and converted to
RGB (Eq. (5), Wang et al.). Only ``f_sp(t)`` costs one exponentiation per band, which is what the
tables of ``phong_table.placement`` remove.

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
  Model".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.colour.colorimetry import DEFAULT_OBSERVER, band_weights, spectra_to_RGB_matrix
from reference.colour.spectra import DEFAULT_GRID, SpectralGrid
from reference.errors import require
from reference.materials.types import PhongMaterial
from reference.scene.lights import AmbientLight, PointLight

__all__ = [
    "SpectralPhong",
    "average_exponent_Wang",
    "diffuse_RGB_Wang",
    "specular_RGB",
    "specular_RGB_derivative",
    "specular_RGB_weights",
]


def diffuse_RGB_Wang(k_d, spectra_to_RGB, intensity: float = 1.0) -> np.ndarray:
    """The diffuse RGB of a material under a light, computed once per edit.

    Eq. (7), Wang et al.: ``D = k Σ_λ I_p(λ) k_d(λ) [x̄ ȳ z̄](λ) · XYZtoRGB``; the light ``I_p`` and
    ``k`` are inside the spectra-to-RGB matrix (Eq. (9), Wang et al.).

    Parameters
    ----------
    k_d : ndarray, shape (n_bands,)
        Diffuse coefficient per band.
    spectra_to_RGB : ndarray, shape (n_bands, 3)
        From :func:`reference.colour.colorimetry.spectra_to_RGB_matrix` (light folded in).
    intensity : float
        The light's scale.

    Returns
    -------
    ndarray, shape (3,)
        Linear display RGB of ``k_d`` facing the light at unit attenuation; multiply by
        ``f_att cos θ`` per pixel.

    Examples
    --------
    >>> diffuse_RGB_Wang(np.full(2, 0.5), np.array([[1.0, 0.0, 0.5], [1.0, 2.0, 0.5]]))
    array([1. , 1. , 0.5])
    """
    # Eq. (7), Wang et al.: the diffuse sum Σ_λ I_p(λ) k_d(λ) x̄(λ), once per material
    return intensity * (np.asarray(k_d, dtype=np.float64) @ spectra_to_RGB)


def specular_RGB_weights(k_s, spectra_to_RGB, intensity: float = 1.0) -> np.ndarray:
    """Per-band RGB weights of the specular term: ``C(λ, ·) = I k_s(λ) M(λ, ·)``.

    Eq. (11), Wang et al. (the factor in front of ``t^{n(λ)}``).

    Parameters
    ----------
    k_s : ndarray, shape (n_bands,)
        Specular coefficient per band.
    spectra_to_RGB : ndarray, shape (n_bands, 3)
        Eq. (9), Wang et al.
    intensity : float
        The light's scale.

    Returns
    -------
    ndarray, shape (n_bands, 3)
        ``C`` such that ``f_sp(t) = Σ_λ C(λ, ·) t^{n(λ)}``.

    Examples
    --------
    >>> specular_RGB_weights(np.array([0.5, 1.0]), np.ones((2, 3)), 2.0)
    array([[1., 1., 1.],
           [2., 2., 2.]])
    """
    # Eq. (11), Wang et al.: k · I_p(λ) k_s(λ) times λ's row of the spectra-to-RGB matrix
    return np.ascontiguousarray(
        intensity * np.asarray(k_s, dtype=np.float64)[:, None] * spectra_to_RGB
    )


def specular_RGB(t, C, n) -> np.ndarray:
    """The specular functions ``f_rsp(t), f_gsp(t), f_bsp(t)``, exactly, without ``f_att``.

    Eq. (11), Wang et al. (Erratum E18: ``f_att`` is applied per pixel, not tabulated).

    Parameters
    ----------
    t : array_like, shape (...,)
        ``cos α = R·V`` in [0, 1].
    C : ndarray, shape (n_bands, 3)
        From :func:`specular_RGB_weights`.
    n : ndarray, shape (n_bands,)
        Phong exponent per band, >= 0 (``0^0 = 1``, as NumPy and the exact shader).

    Returns
    -------
    ndarray, shape (..., 3)
        Linear display RGB of the specular term at unit attenuation.

    Examples
    --------
    >>> C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> specular_RGB(np.array([0.5, 1.0]), C, np.array([1.0, 2.0]))
    array([[0.5 , 0.25, 0.  ],
           [1.  , 1.  , 0.  ]])
    """
    t = np.asarray(t, dtype=np.float64)
    # Eq. (11), Wang et al.: [f_rsp f_gsp f_bsp](t) = Σ_λ I_p k_s t^{n(λ)} · (Spectra-to-RGB)(λ)
    return (t[..., None] ** n) @ C


def specular_RGB_derivative(t, C, n, order: int) -> np.ndarray:
    """The ``order``-th derivative in ``t`` of the specular functions of Eq. (11), Wang et al.

    ``d^k/dt^k Σ C t^n = Σ C n (n−1) ··· (n−k+1) t^{n−k}``, used to place table nodes where the
    interpolation error of the true function is large (``phong_table.placement.table_error``).

    Parameters
    ----------
    t : array_like, shape (...,)
        Points in (0, 1]; at ``t = 0`` terms with ``n < k`` (non-integer) are infinite.
    C : ndarray, shape (n_bands, 3)
        From :func:`specular_RGB_weights`.
    n : ndarray, shape (n_bands,)
        Exponents, >= 0.
    order : int
        Derivative order k >= 0.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> C = np.array([[1.0, 2.0, 0.0]])
    >>> specular_RGB_derivative(np.array([0.5]), C, np.array([3.0]), 2)  # 6 t
    array([[3., 6., 0.]])
    """
    t = np.asarray(t, dtype=np.float64)
    falling = np.ones_like(np.asarray(n, dtype=np.float64))
    for j in range(order):
        falling = falling * (n - j)
    # Eq. (11), Wang et al., differentiated k times: Σ C n(n−1)···(n−k+1) t^{n−k}; the terms whose
    # falling factorial vanishes (integer n < k) are polynomials of lower degree and drop out.
    with np.errstate(divide="ignore", invalid="ignore"):
        powers = np.where(falling != 0.0, t[..., None] ** (n - order), 0.0)
    return (powers * falling) @ C


def average_exponent_Wang(n) -> float:
    """The average exponent ``an`` of the importance-ratio proxy.

    Eq. (13), Wang et al., with Erratum E1 (the paper prints a sum; the text says average).

    Examples
    --------
    >>> average_exponent_Wang([10.0, 20.0, 60.0])
    30.0
    """
    # Eq. (13), Wang et al. (Erratum E1): an = (1/N) Σ_λ n(λ)
    return float(np.mean(np.asarray(n, dtype=np.float64)))


@dataclass(frozen=True, eq=False)
class SpectralPhong:
    """A spectral Phong material under one point light (and optional ambient light), in RGB.

    Eq. (7), Wang et al. (diffuse RGB) and Eq. (11), Wang et al. (specular weights), on the
    spectra-to-RGB matrix of Eq. (9), Wang et al.

    Parameters
    ----------
    material : PhongMaterial
        ``k_d``, ``k_s``, ``n`` (and ``k_a``) per band, on ``grid``.
    light : PointLight
        Position, spectrum ``I_p(λ)``, intensity and attenuation (Eq. (1), Wang et al., Erratum E2).
    ambient : AmbientLight, optional
        The ``I_a`` of Eq. (1), Wang et al.; default none.
    grid : SpectralGrid
        The material's grid; default 380-780 nm in 10 nm steps.
    colourspace : str
        Display colourspace of the linear RGB (default sRGB), or ``"XYZ"`` for tristimulus values
        (the spectra-to-XYZ matrix is then the band weights themselves).
    observer : str
        Colour-matching functions.
    weights_method : str
        Band-weight method (``"astm_e308"`` or ``"point"``).

    Attributes
    ----------
    spectra_to_RGB : ndarray, shape (n_bands, 3)
        Eq. (9), Wang et al., with the light folded in.
    diffuse_RGB : ndarray, shape (3,)
        Eq. (7), Wang et al.
    specular_weights : ndarray, shape (n_bands, 3)
        ``C`` of Eq. (11), Wang et al.
    ambient_RGB : ndarray, shape (3,)
        ``I_a k_a`` in RGB (zeros without an ambient light).
    n : ndarray, shape (n_bands,)
        The exponents.
    n_distinct : ndarray, shape (n_distinct,)
        The distinct exponents, increasing.
    specular_weights_distinct : ndarray, shape (n_distinct, 3)
        ``C`` summed over the bands of each distinct exponent: ``Σ_λ C(λ) t^{n(λ)}`` is the same
        sum over fewer powers (the table build's; the exact baseline keeps one power per band).

    Raises
    ------
    SpecrefError
        When the material's bands do not match the grid.

    Examples
    --------
    >>> m = PhongMaterial(np.full(41, 0.5), np.full(41, 0.25), np.full(41, 10.0))
    >>> model = SpectralPhong(m, PointLight((0.0, 0.0, 5.0)))
    >>> model.diffuse_RGB.round(3), model.specular(np.array([1.0])).round(3)
    (array([0.5, 0.5, 0.5]), array([[0.25, 0.25, 0.25]]))
    >>> model.n_distinct, model.specular_weights_distinct.round(3)
    (array([10.]), array([[0.25, 0.25, 0.25]]))
    """

    material: PhongMaterial
    light: PointLight
    ambient: AmbientLight | None = None
    grid: SpectralGrid = DEFAULT_GRID
    colourspace: str = "sRGB"
    observer: str = DEFAULT_OBSERVER
    weights_method: str = "astm_e308"
    spectra_to_RGB: np.ndarray = field(init=False, repr=False)
    diffuse_RGB: np.ndarray = field(init=False, repr=False)
    specular_weights: np.ndarray = field(init=False, repr=False)
    ambient_RGB: np.ndarray = field(init=False, repr=False)
    n_distinct: np.ndarray = field(init=False, repr=False)
    specular_weights_distinct: np.ndarray = field(init=False, repr=False)
    _an: float = field(init=False, repr=False)

    def __post_init__(self):
        m = self.material
        require(
            isinstance(m, PhongMaterial),
            f"SpectralPhong: material must be a PhongMaterial, got {type(m).__name__}",
        )
        require(
            isinstance(self.light, PointLight),
            f"SpectralPhong: light must be a PointLight, got {type(self.light).__name__}",
        )
        require(
            m.n_bands == self.grid.n_bands,
            f"{m.name}: has {m.n_bands} bands but the grid {self.grid.label} has "
            f"{self.grid.n_bands}; lengths must match",
        )
        # Eq. (9), Wang et al.: band weights (light folded in) times XYZ-to-RGB
        M = self._spectra_to_RGB(self.light.spectrum)
        ambient = np.zeros(3)
        if self.ambient is not None:
            # Eq. (1), Wang et al.: ambient term I_a k_a
            M_a = self._spectra_to_RGB(self.ambient.spectrum)
            ambient = self.ambient.intensity * (m.k_a @ M_a)
        values = {
            "spectra_to_RGB": M,
            "diffuse_RGB": diffuse_RGB_Wang(m.k_d, M, self.light.intensity),
            "specular_weights": specular_RGB_weights(m.k_s, M, self.light.intensity),
            "ambient_RGB": ambient,
        }
        # Eq. (11), Wang et al., with the terms of equal exponents merged: Σ_{λ: n(λ) = ν} C(λ)
        values["n_distinct"], band_of = np.unique(m.n, return_inverse=True)
        values["specular_weights_distinct"] = np.zeros((values["n_distinct"].size, 3))
        np.add.at(values["specular_weights_distinct"], band_of, values["specular_weights"])
        for key, value in values.items():
            value = np.ascontiguousarray(value, dtype=np.float64)
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        # computed once: every table build reads it
        object.__setattr__(self, "_an", float(average_exponent_Wang(m.n)))

    def _spectra_to_RGB(self, spectrum) -> np.ndarray:
        W = band_weights(self.grid, spectrum, self.weights_method, self.observer)
        return W if self.colourspace == "XYZ" else spectra_to_RGB_matrix(W, self.colourspace)

    @property
    def n(self) -> np.ndarray:
        """The exponents ``n(λ)``, shape ``(n_bands,)``."""
        return self.material.n

    @property
    def an(self) -> float:
        """The average exponent of Eq. (13), Wang et al. (Erratum E1), computed once."""
        return self._an

    @property
    def name(self) -> str:
        """The material's name."""
        return self.material.name

    def specular(self, t) -> np.ndarray:
        """``f_sp(t)`` of Eq. (11), Wang et al., exactly, shape ``(..., 3)`` (no ``f_att``)."""
        return specular_RGB(t, self.specular_weights, self.material.n)

    def specular_derivative(self, t, order: int) -> np.ndarray:
        """The ``order``-th derivative of :meth:`specular`, shape ``(..., 3)``."""
        return specular_RGB_derivative(t, self.specular_weights, self.material.n, order)
