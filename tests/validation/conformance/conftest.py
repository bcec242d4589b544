"""One folder of conformance references per test process, shared by the suite's modules."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def conformance_references(tmp_path_factory):
    """A folder the references are rendered into where missing (``load_reference`` does it)."""
    return tmp_path_factory.mktemp("conformance-references")
