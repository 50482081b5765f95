"""The documentation: its examples run, every public name is documented, the site builds.

* The Examples of every public name's docstring run as doctests (no Sphinx needed).
* The pages' ``>>>`` examples (docs/*.rst) run as doctests (no Sphinx needed).
* The Sphinx build with warnings as errors (``-W``), skipped when the ``docs`` extra
  is not installed; the gallery is built without running its scripts
  (``-D plot_gallery=0``: they recompute the paper's figures, minutes).
"""

from __future__ import annotations

import doctest
import importlib.util
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE

# Data (dicts) cannot carry docstrings: docs/api.rst documents them, with examples.
DATA = {"PRESETS", "STATUS_MESSAGES"}


def _public():
    return [(name, getattr(sb, name)) for name in sb.__all__ if name not in DATA]


def _sections(doc):
    return set(re.findall(r"^\s*([A-Z][A-Za-z ]+)\n\s*-{3,}\s*$", doc, flags=re.M))


def test_every_public_name_is_in_the_api_reference():
    text = (DOCS / "api.rst").read_text()
    listed = set(re.findall(r"^   ([A-Za-z_]+)$", text, flags=re.M)) | set(
        re.findall(r"^\.\. data:: ([A-Za-z_]+)$", text, flags=re.M))
    missing = sorted(set(sb.__all__) - listed)
    assert not missing, f"public names missing from docs/api.rst: {missing}"


@pytest.mark.parametrize("name", [n for n, _ in _public()])
def test_public_docstring_is_numpydoc_with_examples(name):
    obj = getattr(sb, name)
    doc = inspect.getdoc(obj) or ""
    assert doc, f"{name} has no docstring"
    sections = _sections(doc)
    assert "Examples" in sections, f"{name}: no Examples section (found {sorted(sections)})"
    if inspect.isfunction(obj):
        params = [p for p in inspect.signature(obj).parameters if p not in ("self",)]
        if params:
            assert "Parameters" in sections, f"{name}: no Parameters section"
        assert "Returns" in sections, f"{name}: no Returns section"


@pytest.mark.parametrize("name", [n for n, _ in _public()])
def test_public_docstring_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    obj = getattr(sb, name)
    finder = doctest.DocTestFinder(recurse=True)
    tests = [t for t in finder.find(obj, name, globs={}) if t.examples]
    assert tests, f"{name}: no doctest examples found"
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} doctest examples failed"


PAGES = sorted(p.name for p in DOCS.glob("*.rst") if ">>>" in p.read_text())


def test_pages_with_examples_exist():
    # getting started and the usage page carry the runnable walk-through
    assert {"getting_started.rst", "usage.rst", "api.rst"} <= set(PAGES)


@pytest.mark.parametrize("page", PAGES)
def test_docs_page_examples_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = doctest.testfile(str(DOCS / page), module_relative=False, optionflags=FLAGS,
                              verbose=False, report=True)
    assert result.attempted > 0
    assert result.failed == 0, f"docs/{page}: {result.failed} of {result.attempted} examples failed"


DOCS_EXTRA = ("sphinx", "numpydoc", "sphinxarg", "myst_parser", "sphinx_gallery")


@pytest.mark.slow  # 14 s; the docstring examples run by default (test_public_docstring_examples_run)
def test_docs_build_without_warnings(tmp_path):
    missing = [m for m in DOCS_EXTRA if importlib.util.find_spec(m) is None]
    if missing:
        pytest.skip(f"the docs extra is not installed ({', '.join(missing)}): pip install -e '.[docs]'")
    out = tmp_path / "html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-D", "plot_gallery=0",
         "-d", str(tmp_path / "doctrees"), str(DOCS), str(out)],
        capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, f"sphinx-build -W failed:\n{proc.stderr[-4000:]}"
    # The CLI reference is generated from the parser: every subcommand is on the page.
    from shellbvp.cli import build_parser

    cli = (out / "cli.html").read_text()
    sub = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    absent = [name for name in sub.choices if f'id="shellbvp-{name}"' not in cli]
    assert not absent, f"subcommands missing from the CLI reference: {absent}"
    # Every public name has its API page; the benchmark results and the gallery are there.
    for name in sb.__all__:
        if name not in DATA:
            assert (out / "api" / "generated" / f"shellbvp.{name}.html").exists(), name
    for md in (ROOT / "benchmarks" / "results").glob("*.md"):
        if "-quick" not in md.stem:
            assert (out / "benchmarks" / f"{md.stem}.html").exists(), md.name
    assert (out / "auto_examples" / "index.html").exists()


EXAMPLES = DOCS / "examples"
#: The real AFM file the force-map example fits, as afmformats ships it (tests/data of
#: AFM-analysis/afmformats at 731b5ad, MIT licence)
AFM_EXAMPLE = EXAMPLES / "data" / "fmt-jpk-fd_map2x2_extracted.jpk-force-map"
AFM_EXAMPLE_SHA256 = "562cac58f63f47fefa59e13307ebc2979b2190861669498e100844728d675b06"


def test_the_force_map_examples_file_is_afmformats_own_small_and_credited():
    import hashlib

    data = AFM_EXAMPLE.read_bytes()
    assert len(data) < 2**20, f"{AFM_EXAMPLE.name}: {len(data)} bytes; the docs ship files under 1 MiB"
    assert hashlib.sha256(data).hexdigest() == AFM_EXAMPLE_SHA256  # copied unchanged
    assert "Paul Müller" in (EXAMPLES / "data" / "LICENSE-afmformats.txt").read_text()
    assert AFM_EXAMPLE.name in (EXAMPLES / "README.txt").read_text()  # the attribution line


def test_the_force_map_example_runs_from_the_real_file_to_the_map_and_a_pixels_fit(tmp_path, monkeypatch):
    """docs/examples/plot_7_afm_map.py, as the gallery runs it (the docs build in
    test_docs_build_without_warnings skips the gallery's scripts): the real JPK map read, fitted
    and written, one pixel's fit drawn from the map file.  Its text says what the fits found;
    when they change, so must the text."""
    import runpy
    import warnings

    pytest.importorskip("afmformats")
    pytest.importorskip("matplotlib")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(tmp_path)
    import matplotlib.pyplot as plt

    before = set(plt.get_fignums())
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*non-interactive.*")  # plt.show() on Agg
        ns = runpy.run_path(str(EXAMPLES / "plot_7_afm_map.py"), run_name="__main__")
    try:
        fm, mf = ns["fm"], ns["mf"]
        assert fm.shape == (10, 10) and len(fm.rows) == 4
        assert [c.grid for c in fm.curves] == [(0, 0), (9, 0), (9, 9), (0, 9)]
        # what the example's text says of these fits
        assert [r.result.quality for r in fm.rows] == ["poor"] * 4, "update the example's text"
        assert [r.status for r in fm.rows] == ["failed", "failed", "failed", "ok"], "update the example's text"
        mu = [r.result.mu_H for r in fm.rows]
        assert max(mu) / min(mu) > 20, "update the example's text"
        np.testing.assert_array_equal(mf.mu_H, fm.image("mu_H"))
        shown = mf.pixel(0, 9)
        assert shown.status == "ok" and shown.displacement.size == 1000 and shown.rows_fitted == 4157
        assert len(set(plt.get_fignums()) - before) == 3  # the map with the status, two pixels
    finally:
        for n in set(plt.get_fignums()) - before:
            plt.close(n)
