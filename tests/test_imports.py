"""The package's architecture as its imports show it (issue 12): no import cycle inside
``shellbvp/`` (function-level imports included) and no private name imported from
another module -- what two modules share lives in a third, under a public name."""

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "shellbvp"


def module_name(path):
    """A file's module below the package: ``scene``, ``materials`` (a subpackage's __init__),
    ``materials.gent``; ``__init__`` for the package's own."""
    parts = list(path.relative_to(PKG).with_suffix("").parts)
    if parts[-1] == "__init__" and len(parts) > 1:
        parts.pop()
    return ".".join(parts)


def _resolve(base, name):
    """The module ``name`` inside the package ``base`` (a list of parts), or the package's
    __init__ when ``name`` is one of its names rather than a module."""
    target = base + [name]
    folder = PKG.joinpath(*target)
    if folder.with_suffix(".py").exists() or (folder / "__init__.py").exists():
        return ".".join(target)
    return ".".join(base) or "__init__"


def imports_of(path):
    """(module imported, names) for every relative import and ``shellbvp`` import in a file,
    modules named as :func:`module_name` names them."""
    tree = ast.parse(path.read_text())
    here = list(path.relative_to(PKG).parent.parts)  # the package the file sits in
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            base = here[:len(here) - (node.level - 1)]
            if node.module:
                yield _resolve(base, node.module.split(".")[0]) if not base else \
                    ".".join(base + node.module.split(".")[:1]), [a.name for a in node.names]
            else:  # from . import x: x is a module or a name of the package's __init__
                for a in node.names:
                    yield _resolve(base, a.name), [a.name]
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("shellbvp"):
            parts = node.module.split(".")[1:]
            yield (".".join(parts) if parts else "__init__"), [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("shellbvp"):
                    parts = a.name.split(".")[1:]
                    yield (".".join(parts) if parts else "__init__"), []


def graph():
    return {module_name(p): {m for m, _ in imports_of(p)} - {module_name(p)} for p in PKG.rglob("*.py")}


def test_no_import_cycle_inside_the_package():
    g = graph()
    # the package's __init__ and the CLI (its subcommands' modules too) sit on top: nothing below
    # may import them
    def on_top(m):
        return m in ("__init__", "cli", "__main__") or m.startswith("cli.")

    for top in ("__init__", "cli", "__main__"):
        users = sorted(m for m, deps in g.items() if top in deps and not on_top(m))
        assert not users, f"{users} import {top}, which imports them back"
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = "open"
        stack.append(m)
        for d in sorted(g.get(m, ())):
            if d in ("__init__",) or d not in g:
                continue
            if state.get(d) == "open":
                cycles.append(stack[stack.index(d):] + [d])
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = "done"

    for m in sorted(g):
        if m not in state and not on_top(m):
            visit(m)
    assert not cycles, " ; ".join(" -> ".join(c) for c in cycles)


def test_no_private_name_is_imported_from_another_module():
    bad = [(module_name(p), m, n) for p in PKG.rglob("*.py") for m, names in imports_of(p) for n in names
           if n.startswith("_") and not n.startswith("__")]
    assert not bad, bad


def test_the_cycle_check_can_fail(tmp_path, monkeypatch):
    """The walker sees function-level imports: a module importing its importer is a cycle."""
    pkg = tmp_path / "shellbvp"
    pkg.mkdir()
    (pkg / "a.py").write_text("from .b import x\n")
    (pkg / "b.py").write_text("def f():\n    from .a import y\n")
    monkeypatch.setattr(__import__(__name__), "PKG", pkg)
    assert graph() == {"a": {"b"}, "b": {"a"}}


def test_import_loads_no_scipy_solver():
    """``import shellbvp`` stays light (the CLI's --version, reading files): scipy's solvers are
    imported when first used (docs/benchmarking.md: 0.48 -> 0.13 s)."""
    import subprocess
    import sys

    code = ("import sys, shellbvp\n"
            "print(sorted(m for m in ('scipy.optimize', 'scipy.integrate', 'scipy.interpolate', 'sympy', 'h5py')"
            " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=PKG.parent).stdout.strip()
    assert out == "[]", f"import shellbvp loaded {out}"


def test_the_command_line_parses_before_numpy_and_scipy_load():
    """`import shellbvp` and the CLI's parser load no numerics (issue 46): a wrong option is
    refused before numpy, SciPy and SymPy are imported, and Ctrl-C meets the CLI's handler."""
    import subprocess
    import sys

    code = ("import sys, shellbvp, shellbvp.cli as c\n"
            "heavy = [m for m in ('numpy', 'scipy', 'sympy', 'h5py') if m in sys.modules]\n"
            "try:\n    rc = c.main(['curve', '--no-such-option'])\nexcept SystemExit as e:\n    rc = e.code\n"
            "heavy += [m for m in ('numpy', 'scipy', 'sympy', 'h5py') if m in sys.modules]\n"
            "print(rc, heavy)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.stdout.strip() == "2 []", (r.stdout, r.stderr)
    uncertain = code.replace("['curve', '--no-such-option']",
                             "['fit', 'x.csv', '--preset', 'fit', '--gamma', '2.5+-0.1', '--no-such-option']")
    r = subprocess.run([sys.executable, "-c", uncertain], capture_output=True, text=True)
    assert r.stdout.strip() == "2 []", (r.stdout, r.stderr)  # VALUE+-U parsed (shellbvp.units) before numpy
    missing = code.replace("['curve', '--no-such-option']", "['fit', 'missing.csv', '--preset', 'fit', '--radius', '0.3mm']")
    r = subprocess.run([sys.executable, "-c", missing], capture_output=True, text=True)
    assert r.stdout.strip() == "2 []" and "missing.csv: no such file" in r.stderr, (r.stdout, r.stderr)
    for command in (["info", "missing.h5"], ["report", "missing.h5"], ["plot", "missing.h5"]):
        r = subprocess.run([sys.executable, "-c", code.replace("['curve', '--no-such-option']", repr(command))],
                           capture_output=True, text=True)
        assert r.stdout.strip() == "2 []" and "missing.h5: no such file" in r.stderr, (command, r.stdout, r.stderr)
