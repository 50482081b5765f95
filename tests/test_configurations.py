"""The configurations package (issue 43, item 1): one module per configuration, registered
in the order its ``ORDER`` says, and a new configuration of an existing family is one new
module -- shown by a copy of ``line.py`` made here, found, registered and solved."""

import importlib
import pathlib
import sys

import pytest

import shellbvp as sb
from shellbvp import configurations as cf
from shellbvp.configurations import registry

#: The registration order: names() lists candidates, curves and files in it
ORDER = ("cap", "point", "line", "annulus", "cap+line(tip)", "cap+band(tip)", "cap+line(cylinder)",
         "cap+band(cylinder)", "cap+cylinder", "line+corner") + tuple(
    f"closed-{u}-{l}" for u in ("point", "cap", "line", "annulus") for l in ("point", "cap", "line", "annulus"))


@pytest.fixture
def registry_restored():
    """The registry as it was before the test, whatever the test registered."""
    confs, switches = dict(cf.CONFIGURATIONS), list(cf.SWITCHES)
    yield
    cf.CONFIGURATIONS.clear()
    cf.CONFIGURATIONS.update(confs)
    cf.SWITCHES[:] = switches


def make_package(root: pathlib.Path, name: str, modules: dict):
    """A package ``name`` under ``root`` holding ``modules`` ({file stem: source}), imported."""
    (root / name).mkdir()
    (root / name / "__init__.py").write_text("")
    for stem, source in modules.items():
        (root / name / f"{stem}.py").write_text(source)
    sys.path.insert(0, str(root))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(root))


def copy_of_line(new_name: str, order: int) -> str:
    """The source of ``configurations/line.py`` declaring ``new_name`` instead, importing the
    package by its absolute name (it lives outside it)."""
    source = pathlib.Path(cf.__file__).with_name("line.py").read_text()
    assert '"line"' in source and "ORDER = 30" in source
    return (source.replace("from ..chain import", "from shellbvp.chain import")
            .replace("from .registry import", "from shellbvp.configurations.registry import")
            .replace('"line"', f'"{new_name}"').replace("line_chain", "copied_chain")
            .replace("ORDER = 30", f"ORDER = {order}"))


def test_configurations_are_registered_in_the_order_of_their_modules():
    modules = cf.discover(cf)
    assert [m.ORDER for m in modules] == sorted(m.ORDER for m in modules)
    declared = tuple(c.name for m in modules for c in m.CONFIGURATIONS)
    assert declared == cf.CONFIGURATION_NAMES == cf.names() == ORDER
    assert [s.between for s in cf.SWITCHES] == [s.between for m in modules for s in getattr(m, "SWITCHES", ())]
    assert "registry" not in {m.__name__.rpartition(".")[2] for m in modules}
    assert cf.ASKED == cf.asked() == ("auto", "cap", "line", "annulus", "cap+line(cylinder)", "cap+band(cylinder)",
                                      "cap+cylinder")


def test_each_module_declares_its_own_configuration_and_switches_to_earlier_ones():
    """A switch lives in the module of the later of its two configurations, so that a new
    configuration brings its switches with it."""
    earlier = set()
    for module in cf.discover(cf):
        own = {c.name for c in module.CONFIGURATIONS}
        for conf in module.CONFIGURATIONS:
            assert conf.chain(1e-3, 1.5, "smooth").name == conf.name, module.__name__
        for switch in getattr(module, "SWITCHES", ()):
            assert switch.between & own and switch.between - own <= earlier, (module.__name__, switch)
        earlier |= own


def test_discovery_refuses_a_module_without_order_or_with_a_taken_one(tmp_path):
    pkg = make_package(tmp_path, "configurations_same_order",
                       {"first": "ORDER = 10\nCONFIGURATIONS = ()\n", "second": "ORDER = 10\nCONFIGURATIONS = ()\n"})
    with pytest.raises(ValueError, match="have the same ORDER 10"):
        cf.discover(pkg)
    pkg = make_package(tmp_path, "configurations_no_order", {"first": "CONFIGURATIONS = ()\n"})
    with pytest.raises(ValueError, match="has no integer ORDER"):
        cf.discover(pkg)


def test_a_switch_needs_both_configurations_registered(registry_restored):
    with pytest.raises(ValueError, match="not registered"):
        cf.register_switch(cf.Switch(frozenset({"cap", "nowhere"}), "cap", ("pressure_min",)))
    with pytest.raises(ValueError, match="registered already"):
        cf.register_switch(cf.Switch(frozenset({"cap", "line"}), "cap", ("pressure_min",)))
    with pytest.raises(ValueError, match="measured on"):
        cf.register_switch(cf.Switch(frozenset({"cap", "line+corner"}), "line", ("pressure_min",)))
    assert cf.switch_between("cap", "line+corner") is None


def test_a_new_configuration_is_one_module(tmp_path, registry_restored):
    """A copy of line.py under another name, in a package of its own: discovered, registered
    with its switch, asked for by ``solve`` and found by the lifted-pole search from the cap,
    the same state as the line's (the same declaration)."""
    pkg = make_package(tmp_path, "more_configurations", {"line_copy": copy_of_line("line-copy", 35)})
    (module,) = cf.discover(pkg)
    cf.install(module)
    assert cf.names("lifted") == ("line", "annulus", "line+corner", "line-copy")
    assert cf.switch_between("line-copy", "cap").criteria == ("pressure_min",)
    assert registry.configuration("line-copy").line_contact and cf.asked()[-1] == "line-copy"
    scene = sb.Scene.preset("base")
    copied = sb.solve(scene, delta=0.05, topology="line-copy", estimate_error=False)
    line = sb.solve(scene, delta=0.05, topology="line", estimate_error=False)
    assert copied.topology == "line-copy" and line.topology == "line"
    assert copied.success and copied.valid
    assert copied.force == line.force and copied.Sc == line.Sc


def test_a_configuration_not_registered_is_not_asked_for():
    with pytest.raises(ValueError, match="topology must be one of"):
        sb.solve(sb.Scene.preset("base"), delta=0.05, topology="line-copy")
