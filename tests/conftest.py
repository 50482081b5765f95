import os
from pathlib import Path

import pytest


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", default=False, help="run tests marked slow")


#: Workers of ``-n auto`` (pytest-xdist, pyproject's addopts): one per core, at most this many --
#: each worker derives and generates the code of every structure it meets in its own cache, so
#: more workers than this repeat more derivation than they save (2 cores: 10.3 -> 5.7-7.6 min).
MAX_WORKERS = 4


def pytest_xdist_auto_num_workers(config):
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # the user's count: xdist's own hook reads it
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(MAX_WORKERS, cores))


def pytest_collection_modifyitems(config, items):
    if config.getoption("--runslow"):
        return
    skip = pytest.mark.skip(reason="slow: run with --runslow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


# The suite runs the numpy functions, the reference: with numba installed, "auto" would compile
# every structure the suite meets in background processes.  tests/test_kernels.py compares the
# compiled kernels with them; SHELLBVP_KERNELS=numba runs the whole suite on the compiled ones.
os.environ.setdefault("SHELLBVP_KERNELS", "numpy")


def _run_code_cache(tmp_path_factory):
    """A fresh code cache for this run, one for all its xdist workers: each structure is derived
    once per run rather than once per worker (a worker meeting a structure the other is deriving
    waits for its module: ``shellbvp.model``'s lock)."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return tmp_path_factory.mktemp("codecache")
    shared = tmp_path_factory.getbasetemp().parent / "codecache"  # the run's root, beside popen-gw*
    shared.mkdir(mode=0o700, exist_ok=True)
    return shared


@pytest.fixture(scope="session", autouse=True)
def _fresh_code_cache(tmp_path_factory):
    """Generate code into a fresh cache: the tests exercise the derivation."""
    old = os.environ.get("SHELLBVP_CACHE_DIR")
    os.environ["SHELLBVP_CACHE_DIR"] = str(_run_code_cache(tmp_path_factory))
    yield
    if old is None:
        os.environ.pop("SHELLBVP_CACHE_DIR", None)
    else:
        os.environ["SHELLBVP_CACHE_DIR"] = old


@pytest.fixture(autouse=True)
def _model_curves_computed():
    """Fits compute their model curves (the tests count them): the disk cache of kept curves is
    off unless a test turns it on (tests/test_fit_curve_cache.py)."""
    import shellbvp as sb

    with sb.options(model_curve_cache=False):
        yield


@pytest.fixture
def closed_form(monkeypatch):
    """The fit's model curves replaced by :class:`fake_curves.FakeCurve` (counted as computed)."""
    import shellbvp.fitting.curves
    from fake_curves import FakeCurve

    def fake(scene, deltas, tol, counter=None, progress=None):
        if counter is not None:
            counter[0] += 1
        return FakeCurve(scene, deltas)

    monkeypatch.setattr(shellbvp.fitting.curves, "_model_curve", fake)


@pytest.fixture
def cli_main(monkeypatch, capsys):
    """``cli_main(*args, cwd=None)``: the command line's ``main`` run in this process, answered as
    ``subprocess.run`` would (returncode, stdout, stderr).  The same parsing, checks and one-line
    errors as ``python -m shellbvp``, without an interpreter's start (~1 s of CPU each); the tests
    that run the command as a user does (tests/test_cli.py's ``run``) keep the entry point covered."""
    import subprocess

    from shellbvp.cli import main

    def run(*args, cwd=None):
        if cwd is not None:
            monkeypatch.chdir(cwd)
        capsys.readouterr()
        try:
            code = main(list(args))
        except SystemExit as exc:  # the parser's own exits (--help, usage errors)
            code = exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(["shellbvp", *args], code or 0, out, err)

    return run


@pytest.fixture
def base_derivation(monkeypatch):
    """``symbolic.build.generate_sources`` of the base structure answered with the texts of its
    modules in the run's code cache (derived there once), counted in the returned list; other
    structures are derived.  For the tests of the cache's trust checks, which regenerate the base
    module into fresh directories (~3.5 s of CPU each); the derivation itself, and that it
    regenerates byte for byte, is tests/test_symbolic.py's."""
    import shellbvp as sb
    import symbolic.build
    from shellbvp import model

    desc = sb.Scene.preset("base").structure()
    key = model.description_key(desc)
    path = Path(model.load_module(desc).__file__)
    kernels = path.parent / f"kernels_{key[:20]}.py"
    if not model.holds_key(kernels, key):  # written beside the module by the same derivation
        model.kernel_source_path(desc)
    texts = path.read_text(), kernels.read_text()
    derive, asked = symbolic.build.generate_sources, []

    def generate_sources(d):
        asked.append(d)
        return texts if model.description_key(d) == key else derive(d)

    monkeypatch.setattr(symbolic.build, "generate_sources", generate_sources)
    return asked
