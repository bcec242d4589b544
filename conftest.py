"""Suite-wide pytest set-up: NumPy printing for doctests, shared fixtures, the benchmark switch."""

from __future__ import annotations

import os
from pathlib import Path

import colour  # noqa: F401  (imported first: it sets NumPy's legacy print mode, which we undo below)
import matplotlib
import numpy as np
import pytest

# Import the packages (and with them every registry) once, under their package names: pytest's
# importlib mode then finds them in sys.modules instead of executing a module a second time when a
# test run names its file directly, which would register its methods twice.
import impastor  # noqa: F401
import phong_table  # noqa: F401
import reference  # noqa: F401
import shrm  # noqa: F401
import validation.cli
import validation.report.runner  # noqa: F401  (imports every section)

matplotlib.use("Agg")
np.set_printoptions(legacy=False)

ROOT = Path(__file__).resolve().parent

# Benchmarks run only under `make bench` (SPECREF_BENCH=1); the ordinary suite does not collect
# them.
collect_ignore = [] if os.environ.get("SPECREF_BENCH") else ["tests/benchmarks"]
# ``python -m validation.cli`` runs the command on import: never collect it for doctests.
collect_ignore += ["validation/cli/__main__.py", "phong_table/editor/__main__.py"]

# An unreachable scheduler is refused after two seconds here rather than the default ten (the
# tests prove the refusal, not the patience); a value set outside the suite wins.
os.environ.setdefault("SPECREF_DASK_TIMEOUT", "2")


@pytest.fixture
def rng():
    """The suite's seeded generator; other streams use a local generator with a literal seed."""
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def package_data() -> Path:
    """The data shipped with specref (``reference/data``: environment maps, measured spectra)."""
    from reference.data import data_root

    return data_root()


@pytest.fixture(scope="session")
def dask_local_client():
    """One local Dask cluster for the session: two single-threaded worker processes on 127.0.0.1.

    Starting a cluster costs seconds; every test that only needs *a* cluster shares this one.
    Tests that kill workers or start their own ``dask scheduler`` make their own.
    """
    from reference.tasks import dask_client

    with dask_client("local", n_workers=2) as client:
        yield client


@pytest.fixture(autouse=True)
def _numpy_printing(doctest_namespace):
    """Doctests see ``np`` and modern NumPy printing, whatever a library did to them."""
    doctest_namespace["np"] = np
    np.set_printoptions(legacy=False)


def pytest_collection_modifyitems(config, items):
    """``xslow`` tests run only with SPECREF_XSLOW=1 (the default addopts already deselect them)."""
    if os.environ.get("SPECREF_XSLOW"):
        return
    for item in items:
        if "xslow" in item.keywords:
            item.add_marker(pytest.mark.skip(reason="xslow: set SPECREF_XSLOW=1 to run"))
