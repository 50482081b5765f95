"""A census of the package's structure, from its source (nothing of it is run).

    python benchmarks/architecture.py [--markdown] [--layers] [--root CHECKOUT]

Counts what issue 43 names: comparisons with configuration names, modules and functions
by length, ``.get`` on results, places that build a ``Solution``, function-level
imports, module flags that tests patch; and of issue 57, string hooks: ``"module:function"``
strings that name a function of the package, resolved by name at run time (an upward path
the import graph does not show), and writes of a curve's settings below their owner (a
subscript stored or deleted, ``setdefault``/``update``/... called, on ``settings``, ``st`` or
``<x>.settings`` in a module on a floor below ``continuation``, which builds them; ``io``, whose
``Curve.learned`` records beside them what a step learned, excepted).  The numbers are what the redesign is judged by;
``--markdown`` prints them as the table of benchmarks/results/architecture.md.  A ``.get`` is
counted where its key is a result's field name; ``--verbose`` shows its receiver, which may
be a dict of another kind.  ``--layers`` prints the package's modules by floor: a module
stands one floor above the highest module it imports (at its top or inside a function: an
import made late for its cost is still a dependency), so every arrow points down.
"""

from __future__ import annotations

import argparse
import ast
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: A string naming a function of the package, ``"shellbvp.module:function"``
STRING_HOOK = re.compile(r"^shellbvp(\.\w+)+:\w+$")
#: Names under which a curve's settings are passed (``settings``, ``st``, ``curve.settings`` ...)
SETTINGS_RECEIVER = re.compile(r"^(st|settings|[\w.]+\.settings)$")
#: Methods that change a dict (or a list held in it) in place
MUTATORS = {"setdefault", "update", "pop", "popitem", "clear", "append", "extend"}
#: Where a curve's settings are built (the owner) and where the curve records what it learned
SETTINGS_OWNERS = ("continuation", "io")
MODULE_LINES = 600
FUNCTION_LINES = 80
#: Module-level names that a result carries (a ``.get`` of one of them reads a result)
RESULT_KEYS = {
    "success", "status", "message", "topology", "delta", "force", "lambda0", "Sc", "S1", "x", "y", "p", "sol",
    "rms_residuals", "tol", "niter", "nodes", "max_residual", "energy", "ring_force", "ring_force_inner",
    "cap_force", "edge_forces", "edge_S", "pressure", "pressure_min", "edge_legendre", "legendre_min",
    "legendre_min_S", "penetration", "valid", "flags", "force_defect", "past_tip_end", "force_error",
    "delta_error", "wall_time", "control", "scene", "system", "z_tip", "shear_delta", "S_end", "contact_edge",
    "edge_jump_ls", "edge_jump_ks", "wall_gap", "lifted", "estimate",
}


def configuration_names(root):
    """The registered names: declared in the modules of ``shellbvp/configurations/``, or in a
    checkout from before that package registered in ``shellbvp/configurations.py``, or before
    the registry the tuple ``chain.CONFIGURATION_NAMES``."""
    package = root / "shellbvp" / "configurations"
    if package.is_dir():
        return {name for path in package.glob("*.py")
                for name in re.findall(r'\bConfiguration\("([^"]+)"', path.read_text())}
    registry = root / "shellbvp" / "configurations.py"
    if registry.exists():
        return set(re.findall(r'register\(Configuration\("([^"]+)"', registry.read_text()))
    match = re.search(r"CONFIGURATION_NAMES = \((.*?)\)\n", (root / "shellbvp" / "chain.py").read_text(), re.S)
    return set(re.findall(r'"([^"]+)"', match.group(1)))


def _strings(node):
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return [s for e in node.elts for s in _strings(e)]
    return []


def _module_level(tree):
    """Statements outside every function (imports under ``if``/``try`` at the top included)."""
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        yield node
        todo.extend(ast.iter_child_nodes(node))


def _adapts_a_step(loop):
    """A loop that grows a step after a success and halves it after a failure: natural
    continuation written out (``x *= 1.5`` or ``x = 1.5 * x`` ..., and ``x /= 2``)."""
    grows = halves = False
    for n in ast.walk(loop):
        if isinstance(n, ast.AugAssign) and isinstance(n.value, ast.Constant):
            grows |= isinstance(n.op, ast.Mult) and n.value.value == 1.5
            halves |= isinstance(n.op, ast.Div) and n.value.value == 2
        elif isinstance(n, ast.BinOp) and isinstance(n.op, ast.Mult):
            grows |= any(isinstance(x, ast.Constant) and x.value == 1.5 for x in (n.left, n.right))
    return grows and halves


def _settings_write(node):
    """Whether ``node`` changes a curve's settings: ``st[k] = ...``, ``del settings[k]``,
    ``curve.settings.update(...)``, ``st["topology_switches"].append(...)``, ``st.x = ...``."""
    def settings(expr):
        return bool(SETTINGS_RECEIVER.match(ast.unparse(expr)))

    if isinstance(node, (ast.Subscript, ast.Attribute)) and isinstance(node.ctx, (ast.Store, ast.Del)):
        return settings(node.value)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in MUTATORS:
        receiver = node.func.value
        return settings(receiver.value if isinstance(receiver, ast.Subscript) else receiver)
    return False


def settings_writes(root, found):
    """{module: writes} of ``found`` (census's ``settings_writes``) in the modules below the
    settings' owner (``continuation``): a module stands on the floor of its top-level module or
    subpackage (:func:`layers`)."""
    floor = {mod: f for f, mods in layers(root).items() for mod in mods}
    owner = floor.get("continuation")
    if owner is None:
        return {}
    out = {}
    for mod, n in found.items():
        top = mod.split(".")[0]
        where = floor.get(top, floor.get(top + "/"))
        if where is not None and where < owner and top not in SETTINGS_OWNERS:
            out[mod] = n
    return out


def census(root=ROOT):
    names = configuration_names(root)
    out = {"step_loops": [], "name_comparisons": {}, "long_modules": {}, "long_functions": [], "result_gets": {},
           "solution_builds": {}, "function_imports": {}, "string_hooks": {}, "settings_writes": {},
           "lines": 0}
    pkg = root / "shellbvp"
    for path in sorted(pkg.rglob("*.py")):  # subpackages (materials/, cli/) too
        text = path.read_text()
        tree = ast.parse(text)
        nlines = text.count("\n")
        out["lines"] += nlines
        mod = ".".join(path.relative_to(pkg).with_suffix("").parts)
        if nlines > MODULE_LINES:
            out["long_modules"][mod] = nlines
        for node in ast.walk(tree):
            if isinstance(node, ast.Compare):
                hits = [s for side in [node.left, *node.comparators] for s in _strings(side) if s in names]
                if hits:
                    out["name_comparisons"][mod] = out["name_comparisons"].get(mod, 0) + 1
            elif isinstance(node, ast.Constant) and isinstance(node.value, str) and STRING_HOOK.match(node.value):
                out["string_hooks"][mod] = out["string_hooks"].get(mod, 0) + 1
            elif _settings_write(node):
                out["settings_writes"][mod] = out["settings_writes"].get(mod, 0) + 1
            elif isinstance(node, (ast.While, ast.For)) and _adapts_a_step(node):
                out["step_loops"].append(f"{mod}:{node.lineno}")
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > FUNCTION_LINES:
                    out["long_functions"].append((f"{mod}.{node.name}", length))
            elif isinstance(node, ast.Call):
                f = node.func
                if isinstance(f, ast.Attribute) and f.attr == "get" and node.args \
                        and isinstance(node.args[0], ast.Constant) and node.args[0].value in RESULT_KEYS:
                    receiver = ast.unparse(f.value)
                    out["result_gets"][f"{mod}:{node.lineno} ({receiver})"] = 1
                # the diagnosis builds a Solution or a subclass, passed as ``result``
                if isinstance(f, ast.Name) and f.id in ("Solution", "result"):
                    out["solution_builds"][mod] = out["solution_builds"].get(mod, 0) + 1
        n_imports = sum(isinstance(n, (ast.Import, ast.ImportFrom)) for n in ast.walk(tree)) \
            - sum(isinstance(n, (ast.Import, ast.ImportFrom)) for n in _module_level(tree))
        if n_imports:
            out["function_imports"][mod] = n_imports
    patched = set()
    for path in sorted((root / "tests").glob("*.py")) + sorted((root / "benchmarks").glob("*.py")):
        for m in re.finditer(r"monkeypatch\.setattr\(\s*([\w.]+)\s*,\s*\"(_?[A-Z_]+)\"", path.read_text()):
            patched.add(f"{m.group(1)}.{m.group(2)}")
    out["patched_flags"] = sorted(patched)
    out["settings_writes"] = settings_writes(root, out["settings_writes"])
    return out


def layers(root=ROOT):
    """{floor: [module, ...]} of ``shellbvp``: floor 1 imports no module of the package; every
    other module stands one above the highest it imports (a subpackage is one module)."""
    pkg = root / "shellbvp"
    files = {p.stem: [p] for p in pkg.glob("*.py") if p.stem not in ("__init__", "__main__")}
    files.update({d.name + "/": sorted(d.glob("*.py")) for d in pkg.iterdir()
                  if d.is_dir() and (d / "__init__.py").exists()})
    deps = {}
    for mod, paths in files.items():
        found = set()
        for path in paths:
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and node.level >= 1:
                    inside = path.parent != pkg  # a subpackage's ".x" is its own module
                    if inside and node.level == 1:
                        continue
                    targets = [node.module] if node.module else [a.name for a in node.names]
                    for t in targets:
                        head = t.split(".")[0]
                        name = head if head in files else head + "/"
                        if name in files and name != mod:
                            found.add(name)
        deps[mod] = found
    floor = {}

    def level(mod, seen=()):
        if mod not in floor:
            if mod in seen:
                raise ValueError(f"import cycle through {mod}")
            floor[mod] = 1 + max((level(d, seen + (mod,)) for d in deps[mod]), default=0)
        return floor[mod]

    for mod in files:
        level(mod)
    out = {}
    for mod, f in floor.items():
        out.setdefault(f, []).append(mod)
    return {f: sorted(out[f]) for f in sorted(out, reverse=True)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("--verbose", action="store_true", help="every .get with its line and receiver")
    ap.add_argument("--root", type=pathlib.Path, default=ROOT, help="another checkout (default: this one)")
    ap.add_argument("--layers", action="store_true", help="the modules by floor of their imports")
    args = ap.parse_args(argv)
    if args.layers:
        for f, mods in layers(args.root).items():
            print(f"{f:3d}  {', '.join(mods)}")
        return 0
    c = census(args.root)
    total = lambda d: sum(d.values())  # noqa: E731
    gets = {}
    for where in c["result_gets"]:
        mod = where.split(":")[0]
        gets[mod] = gets.get(mod, 0) + 1
    rows = [
        ("loops of natural continuation (a step grown by 1.5, halved)", len(c["step_loops"]), c["step_loops"]),
        ("comparisons with configuration names", total(c["name_comparisons"]), c["name_comparisons"]),
        (f"modules over {MODULE_LINES} lines", len(c["long_modules"]), c["long_modules"]),
        (f"functions over {FUNCTION_LINES} lines", len(c["long_functions"]),
         dict(sorted(c["long_functions"], key=lambda t: -t[1]))),
        ("`.get` of a result's field", total(c["result_gets"]), c["result_gets"] if args.verbose else gets),
        ("places that build a Solution", total(c["solution_builds"]), c["solution_builds"]),
        ("imports inside functions", total(c["function_imports"]), c["function_imports"]),
        ("module flags patched by tests and benchmarks", len(c["patched_flags"]), c["patched_flags"]),
        ('string hooks (`"module:function"` resolved by name)', total(c["string_hooks"]), c["string_hooks"]),
        ("writes of a curve's settings below their owner (continuation)", total(c["settings_writes"]),
         c["settings_writes"]),
        ("lines of shellbvp/*.py", c["lines"], ""),
    ]
    if args.markdown:
        print("| measure | count | where |\n|---|---|---|")
        for what, n, where in rows:
            detail = ", ".join(f"{k} {v}" for k, v in where.items()) if isinstance(where, dict) else \
                ", ".join(where) if isinstance(where, list) else where
            print(f"| {what} | {n} | {detail} |")
    else:
        for what, n, where in rows:
            print(f"{n:6d}  {what}")
            if where:
                print("        " + (", ".join(f"{k} {v}" for k, v in where.items()) if isinstance(where, dict)
                                    else ", ".join(where)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
