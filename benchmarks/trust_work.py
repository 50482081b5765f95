"""Tally classes of issue 59 (items 6, 7) and issue 56 (item 5), hooked into trust_tally.py.

* ``work``: problems too large for the machine, refused from an estimate before any work
  (the 3D solid of ``validate``/``fe_curve``/``fit --model solid``, the stability analysis of
  thin shells), a pressure whose inflation outgrows the memory (run under a 1.5 GiB address
  space), a first instability with an unknown bracket end (strict JSON in the file, read back),
  and the stability verdict printed and stored when the curve is stable;
* ``options``: every option each command accepts is read by its handler (a static check of the
  parser against the sources of the command's module, its handler in ``shellbvp/cli/handlers/`` and
  the shared helpers they call), and invalid node budgets are refused.

Run: ``python3 benchmarks/trust_tally.py --only options,work --out benchmarks/results/trust_work.md`` (about
3 minutes; results/trust_work.md: 259 inputs, 0 defects).
"""

from __future__ import annotations

import argparse
import ast
import importlib
import inspect
import json
import math
import re
import sys
import time

import numpy as np

import shellbvp as sb

KINDS = {"work": "15. oversized work, memory and stability verdicts", "options": "16. accepted options read"}
SIZES = {"work": 0, "options": 0}  # fixed lists: the sizes play no part
KIND_NOTES = {
    "work": "Inputs: the 3D solid at eps 1e-4, 1e-3, 1e-7 and over a small max_dofs (fe_curve, validate, "
            "fit with model='solid', the CLI's validate and fit), invalid max_dofs, the stability analysis "
            "of thin shells (beta 1e-8 to 1e-10) and over a small limit (sb.stability, curve and fit "
            "--stability); each must be refused in one line naming the estimate and the limit within "
            "20 s. The estimate against the mesh built at eps 0.05. curve --pressure 1000 "
            "and -50 in a 1.5 GiB address space: a clear error or a failed status, no MemoryError. A first "
            "instability with an unknown bracket end: strict JSON in the file, read back. A stable curve and "
            "fit with --stability, info on its file and a curve without: the verdict line printed.",
    "options": "Inputs: every option of every command, found in the parser (shellbvp.cli.build_parser): a "
               "DEFECT if neither the handler nor a shared helper it calls reads it (a static check of the "
               "source, benchmarks/trust_work.py unread_options); invalid and out-of-range --max-nodes and "
               "solver options of commands that solve nothing: clear errors.",
}
#: A refusal from an estimate must come before any real work
REFUSE_WITHIN = 20.0
#: A refusal must name the estimate and the limit
ESTIMATE_WORDS = re.compile(r"unknowns.*limit", re.S)
MEMORY_LIMIT = int(1.5 * 2**30)


def _tally():
    """trust_tally's classification helpers (late: trust_tally imports this module; run as a script
    it is ``__main__``)."""
    main = sys.modules.get("__main__")
    if hasattr(main, "judge_exception"):
        return main
    import trust_tally

    return trust_tally


def _refused(kind, target, text, out, t):
    """A call that must be refused at once, with the estimate and the limit in its message."""
    if out["exc"] is None:
        return t.rec(kind, target, text, "DEFECT", f"accepted: {out['result']!r:.200}", out["seconds"])
    outcome, detail = t.judge_exception(out)
    if outcome == "clear error" and out["seconds"] > REFUSE_WITHIN:
        outcome, detail = "DEFECT", f"refused only after {out['seconds']:.0f} s: {detail}"
    if outcome == "clear error" and "unknowns" in text and not ESTIMATE_WORDS.search(detail):
        outcome, detail = "DEFECT", f"the refusal names no estimate and limit: {detail}"
    return t.rec(kind, target, text, outcome, detail, out["seconds"])


def _cli(kind, text, args, cwd, t, expect=None, limit_memory=False, timeout=300):
    """A CLI call judged by trust_tally's rules; ``expect``: a pattern stdout must hold."""
    if limit_memory:
        return _cli_in_memory(kind, text, args, cwd, t, timeout)
    if expect is not None:
        return _cli_expect(kind, text, args, cwd, t, expect, timeout)
    outcome, detail, dt = t.run_cli(args, cwd, json_mode="--json" in args, timeout=timeout)
    if outcome == "clear error" and dt > REFUSE_WITHIN:
        outcome, detail = "DEFECT", f"refused only after {dt:.0f} s: {detail}"
    return t.rec(kind, "CLI", text, outcome, detail, dt)


def _cli_expect(kind, text, args, cwd, t, expect, timeout):
    """A CLI call that must succeed (exit 0, no traceback) and print ``expect``."""
    t0 = time.perf_counter()
    try:
        p = t.subprocess.run([sys.executable, "-m", "shellbvp", *args], cwd=cwd, capture_output=True, text=True,
                             timeout=timeout, stdin=t.subprocess.DEVNULL)
    except t.subprocess.TimeoutExpired:
        return t.rec(kind, "CLI", text, "DEFECT", f"no exit within {timeout} s", timeout)
    dt = time.perf_counter() - t0
    found = re.search(expect, p.stdout)
    if p.returncode == 0 and found and "Traceback" not in p.stderr:
        return t.rec(kind, "CLI", text, "correct result", found.group(0), dt)
    return t.rec(kind, "CLI", text, "DEFECT", f"exit {p.returncode}; stdout lacks {expect!r}: {p.stdout[-200:]!r}; "
                                              f"stderr {p.stderr.strip()[-200:]!r}", dt)


def _cli_in_memory(kind, text, args, cwd, t, timeout):
    import resource

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))

    t0 = time.perf_counter()
    try:
        p = t.subprocess.run([sys.executable, "-m", "shellbvp", *args], cwd=cwd, capture_output=True, text=True,
                             timeout=timeout, preexec_fn=cap, stdin=t.subprocess.DEVNULL)
    except t.subprocess.TimeoutExpired:
        return t.rec(kind, "CLI", text, "DEFECT", f"no exit within {timeout} s", timeout)
    dt = time.perf_counter() - t0
    last = p.stderr.strip().splitlines()[-1:] or [""]
    if "Traceback" in p.stderr or "MemoryError" in p.stderr:
        return t.rec(kind, "CLI", text, "DEFECT", f"traceback; exit {p.returncode}; {p.stderr.strip()[-300:]!r}", dt)
    if p.returncode == 2 and last[0].startswith("shellbvp: error:"):
        # SuperLU's own "Not enough memory" lines may precede it (C code, not ours): the last line decides
        return t.rec(kind, "CLI", text, "clear error", last[0][:300], dt)
    if p.returncode in (0, 1):
        return t.rec(kind, "CLI", text, "failed status" if p.returncode else "correct result",
                     f"exit {p.returncode}; {p.stdout.strip()[-200:]!r}", dt)
    return t.rec(kind, "CLI", text, "DEFECT", f"exit {p.returncode}; {p.stderr.strip()[-300:]!r}", dt)


def kind_work(n, rng, tmp):
    t = _tally()
    k = "work"
    records = []
    neo = sb.Scene.preset("base", material=sb.NeoHookean())

    def api(text, fn):
        records.append(_refused(k, "API", text, t.call(fn, limit=120), t))

    for eps in (1e-4, 1e-3, 1e-7):
        api(f"fe_curve(neo-Hookean base, thickness={eps:g}): unknowns over the limit",
            lambda eps=eps: sb.fe_curve(neo, eps, [eps]))
    api("validate(neo-Hookean base, thickness=1e-4): unknowns over the limit", lambda: sb.validate(neo, thickness=1e-4))
    api("fe_curve(thickness=0.05, max_dofs=1000): unknowns over the limit",
        lambda: sb.fe_curve(neo, 0.05, [0.05], max_dofs=1000))
    api("fe_curve(thickness=0.05, max_dofs=-1)", lambda: sb.fe_curve(neo, 0.05, [0.05], max_dofs=-1))
    api("fe_curve(thickness=0.05, max_dofs='many')", lambda: sb.fe_curve(neo, 0.05, [0.05], max_dofs="many"))
    from shellbvp.fitting import example_data_path

    d, F = np.loadtxt(example_data_path(), delimiter=",", skiprows=2, unpack=True)
    fit_scene = sb.Scene.preset("fit", material=sb.NeoHookean(), thickness=1e-4)
    api("fit(model='solid', thickness=1e-4): unknowns over the limit",
        lambda: sb.fit(fit_scene, d * 1e-3, F * 1e-3, R_L=3e-4, model="solid"))
    base_state = sb.solve(sb.Scene.preset("base"), delta=0.3)
    api("stability(base at delta 0.3, max_dofs=1000): unknowns over the limit",
        lambda: sb.stability(base_state, max_dofs=1000))
    thin = t.call(lambda: sb.inflate(sb.Scene(gamma=1, beta=1e-10, pressure=0.4 * (3e-10) ** 0.5)), limit=120)
    if thin["exc"] is None and thin["result"].success:
        api("stability(inflated hemisphere, beta 1e-10): unknowns over the limit",
            lambda: sb.stability(thin["result"]))
    # the estimate itself: the mesh fe_curve builds, before building it
    from shellbvp.fe import FE_DEFAULTS, _build, fe_size

    size = fe_size(neo, 0.05)
    built = _build(neo, 0.05, **{k_: v for k_, v in FE_DEFAULTS.items() if k_ not in ("tol", "delta_tol")})
    dofs = sum(f.values.size for f in built.field.fields)
    ok = size.elements == built.elements and size.dofs == dofs
    records.append(t.rec(k, "API", "fe_size(thickness 0.05) against the mesh built", "correct result" if ok else
                         "DEFECT", f"estimated {size.elements}, {size.dofs}; built {built.elements}, {dofs}"))
    records += _first_instability_json(k, tmp, t)
    cli = [("validate --thickness 1e-4", ["validate", "--neo-hookean", "--thickness", "1e-4"]),
           ("validate --thickness 1e-3", ["validate", "--neo-hookean", "--thickness", "1e-3"]),
           ("validate --thickness 0.05 --max-fe-dofs 100", ["validate", "--neo-hookean", "--thickness", "0.05",
                                                            "--max-fe-dofs", "100"]),
           ("validate --max-fe-dofs 0", ["validate", "--neo-hookean", "--thickness", "0.05", "--max-fe-dofs", "0"]),
           ("curve --beta 1e-8 --stability locate", ["curve", "--beta", "1e-8", "--stability", "locate"]),
           ("curve --beta 1e-10 --stability points", ["curve", "--beta", "1e-10", "--stability", "points"]),
           ("curve --stability locate --max-stability-dofs 100", ["curve", "--stability", "locate",
                                                                  "--max-stability-dofs", "100"]),
           ("fit --example --beta 1e-9 --stability", ["fit", "--example", "--preset", "fit", "--radius", "0.3mm",
                                                      "--beta", "1e-9", "--stability", "--json"]),
           ("fit --example --thickness 30nm --model solid", ["fit", "--example", "--preset", "fit", "--radius", "0.3mm",
                                                             "--neo-hookean", "--thickness", "30nm", "--model", "solid"])]
    for text, args in cli:
        records.append(_cli(k, text, args, tmp, t))
    for p in ("1000", "-50"):
        records.append(_cli(k, f"curve --pressure {p} (address space 1.5 GiB)",
                            ["curve", "--pressure", p, "-q", "-o", f"p{p}.h5"], tmp, t, limit_memory=True))
    records.append(_cli(k, "curve --stability locate (stable): the verdict printed",
                        ["curve", "--stability", "locate", "-q", "-o", "stable.h5"], tmp, t,
                        expect=r"stability: checked, stable to delta = 0\.5[^\n]*"))
    records.append(_cli(k, "info on that curve: the verdict read back", ["info", "stable.h5"], tmp, t,
                        expect=r"stability: checked, stable to delta = 0\.5"))
    records.append(_cli(k, "curve without --stability: said not checked", ["curve", "-q", "-o", "plain.h5"], tmp, t,
                        expect=r"stability: not checked"))
    records.append(_cli(k, "fit --example --stability: the verdict printed",
                        ["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--stability", "-q"], tmp, t,
                        expect=r"stability: checked[^\n]*"))
    return records


def _first_instability_json(k, tmp, t):
    """A curve unstable from its first state (bracket (NaN, delta)): strict JSON, read back."""
    from shellbvp.io import FirstInstability, read_curve

    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    c.first_instability = FirstInstability(0.1, float(c.force[0]), 2, False, (math.nan, 0.1), "unstable from the first")
    path = tmp / "first.h5"
    c.to_hdf5(path)
    def attribute():
        found = []
        with t.h5py.File(path, "r") as f:
            f.visititems(lambda name, obj: found.append(obj.attrs["first_instability"])
                         if "first_instability" in obj.attrs else None)
        return found[0]

    out = t.call(lambda: (attribute(), read_curve(path)))
    if out["exc"] is not None:
        return [t.rec(k, "API", "first_instability with an unknown bracket end, written and read",
                      *t.judge_exception(out))]
    text, back = out["result"]
    try:
        json.loads(text, parse_constant=t._strict)
        good = back.first_instability.delta == 0.1 and math.isnan(back.first_instability.bracket[0])
        outcome, detail = ("correct result" if good else "DEFECT"), f"{text[:160]}"
    except ValueError as exc:
        outcome, detail = "DEFECT", f"not strict JSON ({exc}): {text[:160]}"
    return [t.rec(k, "API", "first_instability with an unknown bracket end, written and read", outcome, detail)]


# -- options ------------------------------------------------------------------------------------------
def unread_options():
    """{command: [(option, read)]}: each option of each command and whether its module or its handler
    (``shellbvp/cli/handlers/NAME.py``) reads it (``args.NAME``, ``getattr(args, "NAME")``, an
    f-string over the shape parameters, a parameter's ``dest`` of the registry of scene parameters,
    or a helper of cli/common.py or cli/scene_options.py that reads it and that either calls)."""
    from shellbvp import cli
    from shellbvp.cli import common, scene_options
    from shellbvp.scene_parameters import scene_parameters
    from shellbvp.shape_parameters import SHAPE_PARAMETERS

    helpers = {}
    for module in (common, scene_options):
        source = inspect.getsource(module)
        helpers.update({f.name: ast.get_source_segment(source, f) for f in ast.parse(source).body
                        if isinstance(f, ast.FunctionDef) and not f.name.startswith("add_")})

    def reads(text):
        names = set(re.findall(r"args\.(\w+)", text)) | set(re.findall(r"getattr\(args, \"(\w+)\"", text))
        names |= {m.replace("{name}", p) for m in re.findall(r"getattr\(args, f\"([\w{}]+)\"", text)
                  for p in SHAPE_PARAMETERS}
        names |= {dest for dest in re.findall(r"\"(\w+)\"", text) if re.search(r"getattr\(args, (dest|k)\b", text)}
        if re.search(r"getattr\(args, \w+\.dest\b", text):  # the options of the registry of scene parameters
            names |= {p.dest for p in scene_parameters().values() if p.option}
        return names

    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    out = {}
    for name, sp in sub.choices.items():
        # the command's module (its parser) and its handler, which the parser imports on dispatch
        text = "".join(inspect.getsource(importlib.import_module(f"shellbvp.cli.{where}{name}"))
                       for where in ("", "handlers."))
        called = {h for h in helpers if re.search(rf"\b{h}\(", text)}
        called |= {g for h in list(called) for g in helpers if re.search(rf"\b{g}\(", helpers[h])}
        used = reads(text).union(*(reads(helpers[h]) for h in called)) | {"json", "command", "verbose"}
        used |= {dest for _, dest, _ in common.LIMIT_OPTIONS.values()}  # read by cli.main (options in force)
        out[name] = [("/".join(a.option_strings) or a.dest, a.dest in used)
                     for a in sp._actions if a.dest not in ("help", "func")]
    return out


def kind_options(n, rng, tmp):
    t = _tally()
    records = []
    for command, options in unread_options().items():
        for option, read in options:
            records.append(t.rec("options", "parser", f"{command} {option}", "correct result" if read else "DEFECT",
                                 "read by the handler" if read else "accepted and never read"))
    for text, args in (("fit --max-nodes 5", ["fit", "--example", "--preset", "fit", "--radius", "0.3mm",
                                              "--max-nodes", "5"]),
                       ("curve --max-nodes 5", ["curve", "--max-nodes", "5"]),
                       ("solve --max-nodes 5", ["solve", "--delta", "0.1", "--max-nodes", "5"]),
                       ("sweep --max-nodes 5", ["sweep", "--beta", "0.01", "--max-nodes", "5", "-o", "s.h5"]),
                       ("curve --max-nodes 1e9", ["curve", "--max-nodes", "1000000000"]),
                       ("convexity --tol 1e-3 (it solves nothing)", ["convexity", "--tol", "1e-3"]),
                       ("compile --max-nodes 100 (it solves nothing)", ["compile", "--max-nodes", "100"])):
        records.append(_cli("options", text, args, tmp, t))
    return records


FUNCS = {"work": kind_work, "options": kind_options}
