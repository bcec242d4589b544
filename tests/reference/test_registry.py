import pytest

from reference.errors import SpecrefError
from reference.registry import Method, ParametricMethod, Registry


def test_registry_order_lookup_and_errors():
    r = Registry("placement")
    for name in ("uniform", "importance", "error"):
        r.register(Method(name, abs, None, "Eq. (16), Wang et al."))
    assert r.names() == ["uniform", "importance", "error"]
    assert [m.name for m in r.values()] == r.names()
    assert "error" in r
    assert len(r) == 3
    assert list(r) == r.names()
    assert r.lookup("error").cites == "Eq. (16), Wang et al."
    with pytest.raises(
        SpecrefError, match="unknown placement 'imporance'; allowed: error, importance"
    ):
        r.lookup("imporance")
    with pytest.raises(SpecrefError, match="placement 'error' is registered twice"):
        r.register(Method("error", abs, None, ""))
    with pytest.raises(SpecrefError, match="unknown placement"):
        r.lookup(["unhashable"])


def test_register_as_decorator_with_name():
    r = Registry("section", object)

    @r.register
    class Entry:
        name = "x"

    assert r.lookup("x") is Entry
    r.register(len, "length")
    assert r.items()[1] == ("length", len)


def test_a_registry_takes_entries_of_its_kind_only():
    r = Registry("window", ParametricMethod)
    r.register(ParametricMethod("gaussian", abs, None, "§7.3, Herbert et al.", param="sigma"))
    with pytest.raises(SpecrefError, match="window registry takes ParametricMethod entries, got"):
        r.register(Method("hanning", abs, None, "§7.3, Herbert et al."))
    with pytest.raises(SpecrefError, match="takes Method entries, got str"):
        Registry("placement").register("uniform", "uniform")


def test_a_misspelt_field_is_an_error_where_the_method_is_written():
    with pytest.raises(TypeError, match="unexpected keyword argument 'parm'"):
        ParametricMethod("gaussian", abs, None, "§7.3, Herbert et al.", parm="sigma")
    with pytest.raises(TypeError, match="missing 1 required keyword-only argument: 'param'"):
        ParametricMethod("gaussian", abs, None, "§7.3, Herbert et al.")
