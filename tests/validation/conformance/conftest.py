"""One folder of conformance references per test run, shared by its modules and its workers."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def conformance_references(tmp_path_factory, request):
    """A folder the references are rendered into where missing (``load_reference`` does it).

    With pytest-xdist, the run's workers share it (the base folder's parent is the run's): each
    reference is rendered once, by whichever worker comes to it first, under the scene's lock
    (``reference.files.folder_lock``); a worker passes over the scenes another is rendering, so
    two workers that need the references at once render them side by side.
    """
    worker = getattr(request.config, "workerinput", {}).get("workerid")
    if worker is None:
        return tmp_path_factory.mktemp("conformance-references")
    folder = tmp_path_factory.getbasetemp().parent / "conformance-references"
    folder.mkdir(exist_ok=True)
    return folder
