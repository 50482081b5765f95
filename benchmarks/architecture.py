"""A census of the package's structure, from its source (nothing of it is run).

    python benchmarks/architecture.py [--markdown] [--layers] [--root CHECKOUT]

Counts what issue 43 names: comparisons with configuration names, modules and functions
by length, ``.get`` on results, places that build a ``Solution``, function-level
imports, module flags that tests patch; and of issue 57:

* string hooks: ``"module:function"`` strings that name a function of the package (``shellbvp.``
  or not), resolved by name at run time (an upward path the import graph does not show);
* writes of a curve's settings below their owner (a subscript stored or deleted,
  ``setdefault``/``update``/... called, on ``settings``, ``st`` or ``<x>.settings`` in a module on
  a floor below ``continuation``, which builds them; ``io``, whose ``Curve.learned`` records beside
  them what a step learned, excepted);
* writes of a ``Solution``'s fields outside ``solution`` and ``diagnosis`` (``x.field = ...`` or
  ``setattr(x, "field", ...)`` of a field of the dataclass, ``self`` excepted; a field that a class
  the module defines or imports also has is left out: there ``x`` may be that class's);
* parallel parameter lists: a literal tuple, list, set or dict of two or more of the scene's
  parameter names (the ``Scene``'s float fields, the fitted parameters, the materials'
  parameters) outside the one registry (:data:`PARAMETER_REGISTRIES`);
* function-level imports of the package itself, split by the reason the census can see: those of
  the command line (``shellbvp/cli/``) whose module loads numpy, SciPy, SymPy or h5py when imported
  (the parser must not: tests/test_imports.py; they wait for the command's dispatch) and the rest,
  the count that must fall (package imports stand at the top of a module: docs/architecture.md);
  and separately the function-level imports of optional dependencies (the extras of
  pyproject.toml but ``test`` and ``docs``);
* instrument formats named outside the readers' registry (``shellbvp/readers/``): a string that
  is a reader's file name ending (``".jpk-force"``, ``".ibw"``), or a reader's name compared;
* contact and edge models named outside their registry (``shellbvp/edge_models.py``): a
  comparison with a model's name (``scene.contact == "smooth"``, ``"corner" in models``; the
  rim's ``"pinned"``, a comparison with ``rim``, is the rim's, not an edge's), and a literal
  tuple, list or set of two or more of their names (a table of them by hand: ``choices=``).

The numbers are what the redesign is judged by;
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
STRING_HOOK = re.compile(r"^(?:shellbvp)?\.*(\w+(?:\.\w+)*):\w+$")
#: Names under which a curve's settings are passed (``settings``, ``st``, ``curve.settings`` ...)
SETTINGS_RECEIVER = re.compile(r"^(st|settings|[\w.]+\.settings)$")
#: Methods that change a dict (or a list held in it) in place
MUTATORS = {"setdefault", "update", "pop", "popitem", "clear", "append", "extend"}
#: Where a curve's settings are built (the owner) and where the curve records what it learned
SETTINGS_OWNERS = ("continuation", "io")
#: Where a Solution is built and its fields set
SOLUTION_OWNERS = ("solution", "diagnosis")
#: The registry of the parameters of a scene that a fit, a sweep or a table handles (issue 57:
#: the one registry of scene parameters replaces the shape parameters' when it lands)
PARAMETER_REGISTRIES = ("shape_parameters", "scene_parameters")
#: The readers' registry: the one place that names instrument formats
READERS_PACKAGE = "readers"
#: The registry of contact and edge models: the one module that names them
EDGE_MODELS_MODULE = "edge_models"
#: A comparison of a scene's rim (``Scene.rim``, whose ``"pinned"`` is not an edge's)
RIM = re.compile(r"\brim\b")
#: Extras of pyproject.toml that are tools, not optional dependencies of the package
TOOL_EXTRAS = ("test", "docs")
#: The numeric libraries the command line's parser must not load (tests/test_imports.py)
NUMERIC = ("numpy", "scipy", "sympy", "h5py")
#: The command line's package: its imports of numeric modules wait for the command's dispatch
CLI_PACKAGE = "cli"
#: The checkout's packages whose modules an import may run (symbolic/ loads numpy and SymPy)
LOCAL_PACKAGES = ("shellbvp", "symbolic")
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


def _parse_all(pkg):
    """{module: (path, tree)} of every module of the package (subpackages' modules dotted)."""
    return {".".join(p.relative_to(pkg).with_suffix("").parts): (p, ast.parse(p.read_text()))
            for p in sorted(pkg.rglob("*.py"))}


def _class_fields(tree, name):
    """The annotated fields of the class ``name`` in ``tree`` (empty when there is none)."""
    cls = next((n for n in ast.walk(tree) if isinstance(n, ast.ClassDef) and n.name == name), None)
    return set() if cls is None else {n.target.id for n in cls.body
                                      if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)}


def _attributes(cls):
    """A class's attributes: its annotated fields and what its methods store on ``self``."""
    out = {n.target.id for n in cls.body if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)}
    out |= {n.attr for n in ast.walk(cls) if isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store)
            and isinstance(n.value, ast.Name) and n.value.id == "self"}
    return out


def solution_writes(trees) -> dict:
    """{module: writes of a Solution's fields} outside :data:`SOLUTION_OWNERS` (module docstring)."""
    fields = _class_fields(trees["solution"][1], "Solution") if "solution" in trees else set()
    others = {}
    for _, tree in trees.values():
        for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef) and n.name != "Solution"):
            others.setdefault(cls.name, set()).update(_attributes(cls))
    out = {}
    for mod, (_, tree) in trees.items():
        if mod in SOLUTION_OWNERS or not fields:
            continue
        known = {n.name for n in ast.walk(tree) if isinstance(n, ast.ClassDef)}
        known |= {a.asname or a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
        shared = set().union(*(others[c] for c in known if c in others))
        for n in ast.walk(tree):
            if isinstance(n, ast.Attribute) and isinstance(n.ctx, (ast.Store, ast.Del)):
                target, name = n.value, n.attr
            elif isinstance(n, ast.Call) and ast.unparse(n.func) in ("setattr", "object.__setattr__") \
                    and len(n.args) >= 2 and isinstance(n.args[1], ast.Constant):
                target, name = n.args[0], n.args[1].value
            else:
                continue
            if name in fields and name not in shared and not (isinstance(target, ast.Name) and target.id == "self"):
                out[mod] = out.get(mod, 0) + 1
    return out


def scene_parameter_names(root) -> set:
    """The scene's parameter names: its float fields, the fitted (shape) parameters, the
    materials' parameters."""
    pkg = root / "shellbvp"
    scene = next(c for c in ast.walk(ast.parse((pkg / "scene.py").read_text()))
                 if isinstance(c, ast.ClassDef) and c.name == "Scene")
    names = {n.target.id for n in scene.body if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
             and ast.unparse(n.annotation) == "float"}
    for path in [pkg / "shape_parameters.py", *sorted((pkg / "materials").glob("*.py"))]:
        if path.exists():
            names |= set(re.findall(r'(?:ShapeParameter|Parameter)\(\s*"(\w+)"', path.read_text()))
    return names


def parameter_tables(trees, names) -> dict:
    """{module: literal collections of two or more scene parameter names} outside the registry."""
    out = {}
    for mod, (_, tree) in trees.items():
        if mod.split(".")[0] in PARAMETER_REGISTRIES:
            continue
        for n in ast.walk(tree):
            if isinstance(n, (ast.Tuple, ast.List, ast.Set)):
                items = n.elts
            elif isinstance(n, ast.Dict):
                items = [k for k in n.keys if k is not None]
            else:
                continue
            found = {e.value for e in items if isinstance(e, ast.Constant) and isinstance(e.value, str)} & names
            if len(found) >= 2:
                out[mod] = out.get(mod, 0) + 1
    return out


def optional_dependencies(root) -> set:
    """The import names of the optional dependencies: the extras of pyproject.toml but
    :data:`TOOL_EXTRAS`."""
    text = (root / "pyproject.toml").read_text()
    block = re.search(r"^\[project\.optional-dependencies\]\n(.*?)(?=^\[)", text, re.S | re.M)
    out = set()
    for m in re.finditer(r"^(\w+)\s*=\s*\[(.*?)\]", block.group(1) if block else "", re.S | re.M):
        if m.group(1) not in TOOL_EXTRAS:
            out |= {d.replace("-", "_").lower() for d in re.findall(r'"([A-Za-z0-9_.-]+)', m.group(2))}
    return out


def _function_imports(tree):
    """The import statements of ``tree`` inside functions (not at module level)."""
    top = {id(n) for n in _module_level(tree)}
    return [n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom)) and id(n) not in top]


def _imports_package(node) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level >= 1 or (node.module or "").split(".")[0] == "shellbvp"
    return any(a.name.split(".")[0] == "shellbvp" for a in node.names)


def _imported_tops(node) -> set:
    if isinstance(node, ast.ImportFrom):
        return set() if node.level else {(node.module or "").split(".")[0]}
    return {a.name.split(".")[0] for a in node.names}


def _local_modules(root) -> dict:
    """{dotted name: path} of the modules of :data:`LOCAL_PACKAGES` (a package by its __init__)."""
    out = {}
    for top in LOCAL_PACKAGES:
        for path in sorted((root / top).rglob("*.py")) if (root / top).is_dir() else ():
            parts = [top, *path.relative_to(root / top).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path
    return out


def _run_by(name, path, node, modules) -> set:
    """The local modules whose code the import ``node`` of module ``name`` (at ``path``) runs: the
    module imported, the packages above it (their __init__) and the submodules named."""
    if isinstance(node, ast.ImportFrom):
        if node.level:
            here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
            base = here[:len(here) - (node.level - 1)]
            heads = [".".join(base + ([node.module] if node.module else []))]
        else:
            heads = [node.module or ""]
        heads += [f"{heads[0]}.{a.name}" for a in node.names]
    else:
        heads = [a.name for a in node.names]
    out = set()
    for head in heads:
        parts = head.split(".")
        out |= {".".join(parts[:i]) for i in range(1, len(parts) + 1)} & set(modules)
    return out


def numeric_modules(root) -> set:
    """The package's modules (dotted from ``shellbvp``) that load a library of :data:`NUMERIC` when
    imported: one of them, or a local module that does, imported at their top level; a module's
    packages run first, and a package that calls ``discover`` at its top (a registry's package:
    configurations, readers) runs each of its modules."""
    modules = _local_modules(root)
    direct, local = {}, {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        top = list(_module_level(tree))
        imports = [n for n in top if isinstance(n, (ast.Import, ast.ImportFrom))]
        direct[name] = any(_imported_tops(n) & set(NUMERIC) for n in imports)
        parts = name.split(".")
        local[name] = set().union(*(_run_by(name, path, n, modules) for n in imports))
        local[name] |= {".".join(parts[:i]) for i in range(1, len(parts))} & set(modules)
        if path.name == "__init__.py" and any(isinstance(n, ast.Call) and ast.unparse(n.func).split(".")[-1] ==
                                              "discover" for n in top):
            local[name] |= {m for m in modules if m.rpartition(".")[0] == name}
        local[name].discard(name)
    heavy = {name for name, loads in direct.items() if loads}
    grown = True
    while grown:  # what imports a module that loads one, loads one (cycles through packages too)
        more = {name for name, deps in local.items() if deps & heavy} - heavy
        heavy |= more
        grown = bool(more)
    return heavy


def cli_deferred(root, mod, path, node, numeric=None) -> bool:
    """Whether the function-level import ``node`` of module ``mod`` (census's name: ``cli.fit``)
    is one the command line defers past its parser: a module of ``shellbvp/cli/`` importing a
    module that loads a numeric library (:func:`numeric_modules`), or a subcommand's module
    importing its own handler on dispatch (every subcommand does, whatever its handler loads)."""
    if mod.split(".")[0] != CLI_PACKAGE:
        return False
    own = mod.rpartition(".")[2]
    if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module == "handlers" \
            and [a.name for a in node.names] == [own]:
        return True
    numeric = numeric_modules(root) if numeric is None else numeric
    name = "shellbvp." + (mod[:-len(".__init__")] if mod.endswith(".__init__") else mod)
    return bool(_run_by(name, path, node, _local_modules(root)) & numeric)


def reader_formats(root):
    """(the readers' file name endings, their names) as ``shellbvp/readers/`` declares them."""
    suffixes, names = set(), set()
    for path in sorted((root / "shellbvp" / READERS_PACKAGE).glob("*.py")):
        text = path.read_text()
        for tup in re.findall(r"SUFFIXES = \((.*?)\)|suffixes=\((.*?)\)", text, re.S):
            suffixes |= set(re.findall(r'"(\.[\w.-]+)"', " ".join(tup)))
        names |= set(re.findall(r'Reader\(\s*name="([^"]+)"', text))
    return suffixes, names


def _docstrings(tree):
    """The ids of the docstring constants of ``tree``."""
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body and \
                isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant):
            out.add(id(n.body[0].value))
    return out


def format_names(trees, suffixes, names) -> dict:
    """{module: instrument formats named} outside the readers' registry (module docstring)."""
    out = {}
    for mod, (_, tree) in trees.items():
        if mod.split(".")[0] == READERS_PACKAGE:
            continue
        docs = _docstrings(tree)
        for n in ast.walk(tree):
            hit = isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs and \
                n.value.lower() in suffixes
            if isinstance(n, ast.Compare):
                hit = any(s in names for side in [n.left, *n.comparators] for s in _strings(side))
            if hit:
                out[mod] = out.get(mod, 0) + 1
    return out


def edge_model_names(root) -> set:
    """The contact and edge models' names as ``shellbvp/edge_models.py`` registers them (before
    it, the names a curve file's ``contact_edge`` took)."""
    path = root / "shellbvp" / f"{EDGE_MODELS_MODULE}.py"
    if not path.exists():
        return {"smooth", "corner", "paper", "pinned"}
    return set(re.findall(r'EdgeModel\(\s*"(\w+)"', path.read_text()))


def edge_model_uses(trees, names) -> tuple:
    """({module: comparisons with an edge model's name}, {module: literal tables of two or more
    of them}) outside :data:`EDGE_MODELS_MODULE` (module docstring)."""
    compared, tables = {}, {}
    for mod, (_, tree) in trees.items():
        if mod == EDGE_MODELS_MODULE:
            continue
        for n in ast.walk(tree):
            if isinstance(n, ast.Compare):
                sides = [n.left, *n.comparators]
                if any(s in names for side in sides for s in _strings(side)) and \
                        not any(RIM.search(ast.unparse(side)) for side in sides):
                    compared[mod] = compared.get(mod, 0) + 1
            elif isinstance(n, (ast.Tuple, ast.List, ast.Set)):
                found = {e.value for e in n.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
                if len(found & names) >= 2:
                    tables[mod] = tables.get(mod, 0) + 1
    return compared, tables


def census(root=ROOT):
    names = configuration_names(root)
    out = {"step_loops": [], "name_comparisons": {}, "long_modules": {}, "long_functions": [], "result_gets": {},
           "solution_builds": {}, "function_imports": {}, "string_hooks": {}, "settings_writes": {},
           "function_imports_package": {}, "function_imports_optional": {}, "function_imports_cli_deferred": {},
           "function_imports_package_rest": {}, "lines": 0}
    pkg = root / "shellbvp"
    trees = _parse_all(pkg)
    modules = set(trees) | {m.rsplit(".", 1)[0] for m in trees if m.endswith(".__init__")}
    optional = optional_dependencies(root)
    numeric = numeric_modules(root)
    for mod, (path, tree) in trees.items():  # subpackages (materials/, cli/) too
        text = path.read_text()
        nlines = text.count("\n")
        out["lines"] += nlines
        if nlines > MODULE_LINES:
            out["long_modules"][mod] = nlines
        for node in ast.walk(tree):
            if isinstance(node, ast.Compare):
                hits = [s for side in [node.left, *node.comparators] for s in _strings(side) if s in names]
                if hits:
                    out["name_comparisons"][mod] = out["name_comparisons"].get(mod, 0) + 1
            elif isinstance(node, ast.Constant) and isinstance(node.value, str) and STRING_HOOK.match(node.value) \
                    and STRING_HOOK.match(node.value).group(1) in modules:
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
        late = _function_imports(tree)
        own = [i for i in late if _imports_package(i)]
        deferred = sum(cli_deferred(root, mod, path, i, numeric) for i in own)
        for key, n in (("function_imports", len(late)),
                       ("function_imports_package", len(own)),
                       ("function_imports_cli_deferred", deferred),
                       ("function_imports_package_rest", len(own) - deferred),
                       ("function_imports_optional", sum(bool(_imported_tops(i) & optional) for i in late))):
            if n:
                out[key][mod] = n
    patched = set()
    for path in sorted((root / "tests").glob("*.py")) + sorted((root / "benchmarks").glob("*.py")):
        for m in re.finditer(r"monkeypatch\.setattr\(\s*([\w.]+)\s*,\s*\"(_?[A-Z_]+)\"", path.read_text()):
            patched.add(f"{m.group(1)}.{m.group(2)}")
    out["patched_flags"] = sorted(patched)
    out["settings_writes"] = settings_writes(root, out["settings_writes"])
    out["solution_writes"] = solution_writes(trees)
    out["parameter_tables"] = parameter_tables(trees, scene_parameter_names(root))
    out["format_names"] = format_names(trees, *reader_formats(root)) if (pkg / READERS_PACKAGE).is_dir() else {}
    out["edge_model_comparisons"], out["edge_model_tables"] = edge_model_uses(trees, edge_model_names(root))
    return out


def layers(root=ROOT):
    """{floor: [module, ...]} of ``shellbvp``: floor 1 imports no module of the package; every
    other module stands one above the highest it imports (a subpackage is one module)."""
    pkg = root / "shellbvp"
    files = {p.stem: [p] for p in pkg.glob("*.py") if p.stem not in ("__init__", "__main__")}
    files.update({d.name + "/": sorted(d.rglob("*.py")) for d in pkg.iterdir()  # cli/handlers/ is cli/'s
                  if d.is_dir() and (d / "__init__.py").exists()})
    deps = {}
    for mod, paths in files.items():
        found = set()
        for path in paths:
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and node.level >= 1:
                    # inside a subpackage, an import that does not climb to the package is its own
                    if node.level < len(path.relative_to(pkg).parts):
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
        ("imports inside functions", total(c["function_imports"]), c["function_imports"] if args.verbose else ""),
        ("... of the package itself", total(c["function_imports_package"]), c["function_imports_package"]),
        ("...... by the command line, of modules that load numpy, SciPy, SymPy or h5py (its parser must not)",
         total(c["function_imports_cli_deferred"]), c["function_imports_cli_deferred"]),
        ("...... the rest (to move to the top of their modules)", total(c["function_imports_package_rest"]),
         c["function_imports_package_rest"]),
        ("... of optional dependencies", total(c["function_imports_optional"]), c["function_imports_optional"]),
        ("module flags patched by tests and benchmarks", len(c["patched_flags"]), c["patched_flags"]),
        ('string hooks (`"module:function"` resolved by name)', total(c["string_hooks"]), c["string_hooks"]),
        ("writes of a curve's settings below their owner (continuation)", total(c["settings_writes"]),
         c["settings_writes"]),
        ("writes of a Solution's fields outside solution and diagnosis", total(c["solution_writes"]),
         c["solution_writes"]),
        ("parallel parameter lists (scene parameter names tabled outside the registry)",
         total(c["parameter_tables"]), c["parameter_tables"]),
        ("instrument formats named outside the readers' registry", total(c["format_names"]), c["format_names"]),
        ("comparisons with contact or edge model names outside their registry", total(c["edge_model_comparisons"]),
         c["edge_model_comparisons"]),
        ("... tables of their names by hand", total(c["edge_model_tables"]), c["edge_model_tables"]),
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
