"""The suite's own set-up (conftest.py): how pytest-xdist's workers share out the modules."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _conftest(config):
    # the root conftest.py, as pytest loaded it
    return next(p for p in config.pluginmanager.get_plugins() if hasattr(p, "SHARED_WORK"))


class _Config:
    """What the scheduler reads of pytest's configuration: the dist mode and the workers."""

    def __init__(self, dist):
        self.values = {"dist": dist, "tx": ["2*popen"]}

    def getvalue(self, name):
        return self.values[name]


def test_shared_work_groups_name_files_of_the_suite(pytestconfig):
    shared = _conftest(pytestconfig).SHARED_WORK
    paths = [path for group in shared.values() for path in group]
    assert len(paths) == len(set(paths))  # a module is in one group at most
    assert [path for path in paths if not (ROOT / path).is_file()] == []
    assert all(len(group) >= 2 for group in shared.values())


def test_loadscope_runs_each_shared_work_group_as_one_scope(pytestconfig):
    conftest = _conftest(pytestconfig)
    scope = conftest.pytest_xdist_make_scheduler(_Config("loadscope"), None)._split_scope
    for group in conftest.SHARED_WORK.values():
        assert len({scope(f"{path}::test_x") for path in group}) == 1, group
    first, second = (group[0] for group in conftest.SHARED_WORK.values())
    assert scope(f"{first}::test_x") != scope(f"{second}::test_x")
    # the other modules keep loadscope's own scopes: a module, or a class of tests
    assert scope("tests/test_style.py::test_x[a]") == "tests/test_style.py"
    assert scope("tests/test_style.py::Case::test_x") == "tests/test_style.py::Case"
    # other modes keep pytest-xdist's own scheduler
    assert conftest.pytest_xdist_make_scheduler(_Config("load"), None) is None
