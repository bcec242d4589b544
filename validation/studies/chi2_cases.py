"""The suite's chi-square cases: every direction sampler with the settings its test uses.

STYLE.md §9: every sampler has a chi-square test, and α is Šidák-corrected across all chi-square
tests in the suite. :data:`CHI2_CASES` is the one list of those tests: the test files parametrize
over it (:func:`cases_for` a module), and :func:`run_chi2_case` divides α among ``len(CHI2_CASES)``
tests, so the count is never kept by hand. A new sampler is covered by registering a case here;
``tests/validation/studies/test_chi2_cases.py`` checks that no test calls
:func:`validation.studies.stats.chi2_test` outside this registry (except the tests of ``chi2_test``
itself, whose samplers must fail) and that every module with cases has a test file that runs them.

Cases:

- the test's own controls (``validation.studies.stats``): uniform directions on the sphere,
  cosine-weighted
  ones on the hemisphere;
- the BRDF samplers (``reference.materials.brdf``): Lambert at 30°, the Ward–Dür lobe from a sharp
  lobe at
  normal incidence to a rough one at 60°, and one case at 30° with default parameters for every
  other distinct sampler in ``BRDF_METHODS`` (found from the registry, so a new one is covered).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from reference.materials.brdf import BRDF_METHODS
from reference.registry import Registry
from validation.studies.stats import Chi2Result, chi2_test

__all__ = ["CHI2_CASES", "Chi2Case", "cases_for", "run_chi2_case"]


@dataclass(frozen=True)
class Chi2Case:
    """One chi-square test of a direction sampler (the arguments of :func:`chi2_test`).

    Parameters
    ----------
    name : str
        Key, also used in file names of the diagnostics.
    module : str
        The module whose sampler is tested; its test file runs the case.
    make : callable
        ``make() -> (sample, pdf)``, the two callables :func:`chi2_test` takes.
    domain : {"hemisphere", "sphere"}
    n_samples, res, seed : int
        As in :func:`chi2_test`.
    """

    name: str
    module: str
    make: Callable[[], tuple[Callable, Callable]] = field(repr=False)
    domain: str
    n_samples: int
    res: int
    seed: int


#: Every chi-square test the suite runs; ``len(CHI2_CASES)`` is the Šidák family size.
CHI2_CASES = Registry("chi-square case", Chi2Case)


def cases_for(module: str) -> list[Chi2Case]:
    """The registered cases of one module, in registration order (for ``pytest.mark.parametrize``).

    Examples
    --------
    >>> [case.name for case in cases_for("validation.studies.stats")]
    ['uniform_sphere', 'cosine_hemisphere']
    """
    return [case for case in CHI2_CASES.values() if case.module == module]


def run_chi2_case(case: Chi2Case, out_dir=None) -> Chi2Result:
    """Run one registered case, with α = 0.01 Šidák-corrected across ``len(CHI2_CASES)`` tests.

    Examples
    --------
    >>> result = run_chi2_case(CHI2_CASES.lookup("cosine_hemisphere"))
    >>> result.passed, round(result.alpha * len(CHI2_CASES), 3)
    (True, 0.01)
    """
    sample, pdf = case.make()
    return chi2_test(
        sample,
        pdf,
        case.domain,
        case.n_samples,
        case.res,
        case.seed,
        name=case.name,
        out_dir=out_dir,
        n_tests=len(CHI2_CASES),
    )


# --- the controls of the test itself (validation.studies.stats) ------------------------------


def _uniform_sphere():
    def sample(u):
        z = 1 - 2 * u[:, 0]
        r = np.sqrt(np.maximum(0, 1 - z * z))
        phi = 2 * np.pi * u[:, 1]
        return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)

    # Closed form: the uniform density on the sphere is 1/(4π).
    return sample, lambda d: np.full(len(d), 1 / (4 * np.pi))


def _cosine_hemisphere():
    def sample(u):
        r = np.sqrt(u[:, 0])
        phi = 2 * np.pi * u[:, 1]
        return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u[:, 0])], -1)

    # Closed form: cos θ / π on the hemisphere.
    return sample, lambda d: np.maximum(d[:, 2], 0) / np.pi


CHI2_CASES.register(
    Chi2Case("uniform_sphere", "validation.studies.stats", _uniform_sphere, "sphere", 50_000, 11, 3)
)
CHI2_CASES.register(
    Chi2Case(
        "cosine_hemisphere",
        "validation.studies.stats",
        _cosine_hemisphere,
        "hemisphere",
        50_000,
        11,
        4,
    )
)


# --- the BRDF samplers (reference.materials.brdf) --------------------------------------------


def _brdf_sampler(name: str, params: dict, theta_deg: float):
    """``make`` of a BRDF sampler's case: incidence ``theta_deg`` from the normal +z."""

    def make():
        method = BRDF_METHODS.lookup(name)
        theta = np.radians(theta_deg)
        wi = np.array([np.sin(theta), 0.0, np.cos(theta)])
        z = np.array([0.0, 0.0, 1.0])

        def sample(u):
            return method.sample(np.broadcast_to(wi, (len(u), 3)), z, u, **params)

        def pdf(d):
            return method.pdf(np.broadcast_to(wi, d.shape), d, z, **params)

        return sample, pdf

    return make


def _register_brdf_case(key: str, name: str, params: dict, theta_deg: float):
    make = _brdf_sampler(name, params, theta_deg)
    CHI2_CASES.register(Chi2Case(key, "reference.materials.brdf", make, "sphere", 200_000, 21, 5))


def _register_brdf_cases():
    _register_brdf_case("lambert_30", "lambert", {"rho_d": 0.7}, 30.0)
    ward = {"rho_d": 0.0, "rho_s": 1.0}
    _register_brdf_case("ward_duer_0_sharp", "ward_duer", {**ward, "alpha": 0.08}, 0.0)
    _register_brdf_case("ward_duer_60_rough", "ward_duer", {**ward, "alpha": 0.3}, 60.0)
    mixed = {"rho_d": 0.4, "rho_s": 0.4, "alpha": 0.15}
    _register_brdf_case("ward_duer_45_mixed", "ward_duer", mixed, 45.0)
    # Every other distinct sampler of the registry, at its default parameters.
    covered = {id(BRDF_METHODS.lookup(name).sample) for name in ("lambert", "ward_duer")}
    for method in BRDF_METHODS.values():
        sampler = method.sample
        if sampler is not None and id(sampler) not in covered:
            covered.add(id(sampler))
            _register_brdf_case(f"{method.name}_30", method.name, method.params, 30.0)


_register_brdf_cases()
