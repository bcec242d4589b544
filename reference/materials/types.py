"""Materials: spectral parameters on a grid, and the registry of material types.

A material holds its spectral parameters already on the scene's wavelength grid, shape
``(n_bands,)``. The registry :data:`MATERIAL_TYPES` maps the ``type`` key of a scene file to the
class and its parameters, so a new material type is added by registering it; the scene loader
and the renderer read the registry.

- ``lambert``: diffuse reflectance ``k_d(λ)`` (the diffuse term of Eq. (2), Wang et al.).
- ``phong``: the spectral Phong model of Eq. (2), Wang et al.: ``k_d(λ)``, ``k_s(λ)``, ``n(λ)``, and
the ambient
  coefficient ``k_a(λ)`` of Eq. (1), Wang et al.

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
Model".
- B. T. Phong, "Illumination for Computer Generated Pictures", CACM 18(6), 1975.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np

from reference.errors import require, require_nonnegative
from reference.registry import Registry

__all__ = [
    "MATERIAL_TYPES",
    "LambertMaterial",
    "MaterialType",
    "PhongMaterial",
    "make_material",
]


def _spectral(values, where: str, n_bands: int | None) -> np.ndarray:
    array = require_nonnegative(values, where)
    require(array.ndim == 1, f"{where}: must be a spectrum (1-D), got shape {array.shape}")
    if n_bands is not None:
        require(
            array.size == n_bands,
            f"{where}: has {array.size} bands but the grid has {n_bands}; lengths must match",
        )
    array = array.copy()
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class LambertMaterial:
    """A Lambertian (ideal diffuse) material.

    Parameters
    ----------
    k_d : ndarray, shape (n_bands,)
        Diffuse reflectance factor per band, >= 0.
    name : str
        Name used in messages.

    Examples
    --------
    >>> LambertMaterial(np.full(41, 0.5)).k_d.shape
    (41,)
    """

    k_d: np.ndarray
    name: str = "lambert"

    def __post_init__(self):
        object.__setattr__(self, "k_d", _spectral(self.k_d, f"{self.name}.k_d", None))


@dataclass(frozen=True, eq=False)
class PhongMaterial:
    """The spectral Phong material of Eq. (2), Wang et al.

    Parameters
    ----------
    k_d, k_s : ndarray, shape (n_bands,)
        Diffuse and specular reflection coefficients per band, >= 0.
    n : ndarray, shape (n_bands,)
        Specular-reflection exponent per band, >= 0.
    k_a : ndarray, shape (n_bands,), optional
        Ambient reflection coefficient of Eq. (1), Wang et al.; default zeros.
    name : str
        Name used in messages.

    Raises
    ------
    SpecrefError
        Negative or non-finite values, mismatched spectral lengths.

    Examples
    --------
    >>> m = PhongMaterial(np.full(41, 0.3), np.full(41, 0.5), np.full(41, 50.0))
    >>> m.k_a.sum()
    np.float64(0.0)
    """

    k_d: np.ndarray
    k_s: np.ndarray
    n: np.ndarray
    k_a: np.ndarray | None = field(default=None)
    name: str = "phong"

    def __post_init__(self):
        k_d = _spectral(self.k_d, f"{self.name}.k_d", None)
        object.__setattr__(self, "k_d", k_d)
        object.__setattr__(self, "k_s", _spectral(self.k_s, f"{self.name}.k_s", k_d.size))
        object.__setattr__(self, "n", _spectral(self.n, f"{self.name}.n", k_d.size))
        k_a = np.zeros(k_d.size) if self.k_a is None else self.k_a
        object.__setattr__(self, "k_a", _spectral(k_a, f"{self.name}.k_a", k_d.size))

    @property
    def n_bands(self) -> int:
        """Number of bands."""
        return self.k_d.size


@dataclass(frozen=True)
class MaterialType:
    """A registered material type.

    Parameters
    ----------
    name : str
        The scene-file key (``type = "phong"``).
    cls : type
        The material class; its spectral parameters are its ndarray fields.
    required : tuple of str
        Parameters a scene must give.
    optional : tuple of str
        Parameters with defaults.
    cites : str
        The equation the material implements.
    parse : callable, optional
        How a scene file's table becomes the material:
        ``parse(reader, table, key, name) -> material``, with ``reader`` a
        ``reference.scene.values.SceneReader``, ``table`` the material's TOML table (``type``
        included), ``key`` its dotted path (``materials.chart``) and ``name`` the material's name.
        None (the default) reads every parameter in ``required`` and ``optional`` as a spectrum on
        the scene's grid and calls :func:`make_material`.
    """

    name: str
    cls: type
    required: tuple
    optional: tuple = ()
    cites: str = ""
    parse: Callable | None = None


#: Material types by scene-file key.
MATERIAL_TYPES = Registry("material type", MaterialType)
MATERIAL_TYPES.register(
    MaterialType("lambert", LambertMaterial, ("k_d",), (), "Eq. (2), Wang et al. (diffuse term)")
)
MATERIAL_TYPES.register(
    MaterialType("phong", PhongMaterial, ("k_d", "k_s", "n"), ("k_a",), "Eq. (2), Wang et al.")
)


def make_material(type_name: str, params: dict, name: str = "material"):
    """Build a registered material from its spectral parameters (already on the grid).

    Parameters
    ----------
    type_name : str
        A key of :data:`MATERIAL_TYPES`.
    params : dict of str to ndarray
        Spectral parameters, shape ``(n_bands,)`` each.
    name : str
        The material's name, used in messages (``scene.toml: materials.gold``).

    Returns
    -------
    A material instance.

    Raises
    ------
    SpecrefError
        Unknown type, missing or unknown parameters, bad values.

    Examples
    --------
    >>> make_material("lambert", {"k_d": np.full(31, 0.2)}, "grey").name
    'grey'
    >>> make_material("lambert", {"k_s": np.full(31, 0.2)}, "grey")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: grey: unknown key 'k_s' for a lambert material; allowed: k_d
    """
    kind = MATERIAL_TYPES.lookup(type_name)
    allowed = set(kind.required) | set(kind.optional)
    for key in params:
        require(
            key in allowed,
            f"{name}: unknown key {key!r} for a {type_name} material; allowed: "
            f"{', '.join(sorted(allowed))}",
        )
    for key in kind.required:
        require(key in params, f"{name}: a {type_name} material needs {key!r}")
    names = {f.name for f in fields(kind.cls)}
    kwargs = {k: v for k, v in params.items() if k in names}
    return kind.cls(**kwargs, name=name)
