"""Where the time of a force–displacement curve goes (cProfile), for results/profile.md.

Profiles the base curve at tol 1e-6 (natural continuation at the 40 depths of the
work–precision study, ``estimate_error=False``; and the adaptive curve) after a warm-up
run, and splits the time into categories: the generated model code (right-hand sides,
Jacobians, boundary/junction conditions, profiles), solve_bvp's internals (sparse LU,
Jacobian assembly, the rest of its Python), shellbvp's glue (chain.py), diagnostics
(state.py) and continuation.  Time in builtins and NumPy/SciPy helpers is attributed to
the categories of their callers (in proportion to the callers' cumulative time).  It also
times single calls of the generated functions against the number of nodes, to show how
much of a call is fixed per-call overhead.

Writes results/profile.json and results/profile.md: the measured tables, and suggested
optimisations whose estimated gains are computed from the measured shares.

    python benchmarks/profile_hot_path.py [--out-dir DIR] [--quick]
"""

from __future__ import annotations

import argparse
import cProfile
import json
import math
import pstats
import statistics
import sys
import time
import timeit
from pathlib import Path

import numpy as np

from checkout import add_output_args, commit_label, results_dir  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent

CATEGORIES = (
    "generated right-hand sides (free_rhs, contact_rhs)",
    "generated Jacobians (free_jac, contact_jac, *_jac_par)",
    "generated boundary and contact-line conditions",
    "generated profiles (diagnostics: free_profile, contact_profile, ...)",
    "solve_bvp: sparse LU (SuperLU factorise + solve)",
    "solve_bvp: global Jacobian assembly (sparse COO -> CSC)",
    "solve_bvp: other (collocation residuals, mesh refinement, splines)",
    "shellbvp glue (chain.py: fun, fun_jac, bc, bc_jac)",
    "shellbvp diagnostics (state.py: _diagnose, energy, guesses)",
    "continuation logic (continuation.py)",
    "other",
)


def _category(key):
    path, _, name = key
    if "/model_" in path or path.startswith("model_"):
        if name in ("free_rhs", "contact_rhs"):
            return CATEGORIES[0]
        if name.startswith(("pole_", "rim_", "junction_", "force_")):
            return CATEGORIES[2]
        if name.endswith(("_jac", "_jac_par")):
            return CATEGORIES[1]
        return CATEGORIES[3]
    if "gstrf" in name or "SuperLU" in name or name == "splu" or "_dsolve" in path:
        return CATEGORIES[4]
    if "scipy/sparse" in path or name == "construct_global_jac":
        return CATEGORIES[5]
    if "scipy/integrate/_bvp.py" in path or "scipy/interpolate" in path:
        return CATEGORIES[6]
    if "shellbvp/chain/" in path:  # the assembler and its conditions
        return CATEGORIES[7]
    if path.endswith("shellbvp/state.py"):
        return CATEGORIES[8]
    if path.endswith("shellbvp/continuation.py"):
        return CATEGORIES[9]
    if path.startswith("~") or "numpy" in path or "scipy" in path:
        return None  # builtins and helpers: attributed to callers
    return CATEGORIES[10]


def split(stats: pstats.Stats):
    """Exclusive time per category (helpers attributed to their callers)."""
    raw = stats.stats
    memo = {}

    def attr(key, depth=0):
        if key in memo:
            return memo[key]
        cat = _category(key)
        if cat is not None:
            memo[key] = {cat: 1.0}
            return memo[key]
        memo[key] = {CATEGORIES[10]: 1.0}  # cycle guard
        callers = raw[key][4]
        tot = sum(v[3] for v in callers.values()) if callers else 0.0
        if not callers or tot <= 0 or depth > 30:
            return memo[key]
        out = {}
        for ck, v in callers.items():
            if ck not in raw:
                continue
            for c, f in attr(ck, depth + 1).items():
                out[c] = out.get(c, 0.0) + f * v[3] / tot
        memo[key] = out or {CATEGORIES[10]: 1.0}
        return memo[key]

    times = dict.fromkeys(CATEGORIES, 0.0)
    for key, (cc, nc, tt, ct, callers) in raw.items():
        for c, f in attr(key).items():
            times[c] += f * tt
    return times


def _calls(stats, path_part, name):
    return sum(v[1] for k, v in stats.stats.items() if path_part in k[0] and k[2] == name)


def _tottime(stats, path_part, name):
    return sum(v[2] for k, v in stats.stats.items() if path_part in k[0] and k[2] == name)


def profile_curve(make, repeat):
    make()  # warm-up
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        c = make()
        walls.append(time.perf_counter() - t0)
    pr = cProfile.Profile()
    t0 = time.perf_counter()
    pr.enable()
    c = make()
    pr.disable()
    prof_wall = time.perf_counter() - t0
    st = pstats.Stats(pr)
    cats = split(st)
    total = sum(cats.values())
    top = sorted(st.stats.items(), key=lambda kv: -kv[1][2])[:15]
    counts = dict(
        solve_bvp=_calls(st, "scipy/integrate/_bvp.py", "solve_bvp"),
        newton_solves=_calls(st, "scipy/integrate/_bvp.py", "solve_newton"),
        jacobians=_calls(st, "scipy/integrate/_bvp.py", "construct_global_jac"),
        lu_factorisations=_calls(st, "", "splu"),
        fun=_calls(st, "shellbvp/chain/", "fun"),
        fun_jac=_calls(st, "shellbvp/chain/", "fun_jac"),
        bc=_calls(st, "shellbvp/chain/", "bc"),
        free_rhs=_calls(st, "model_", "free_rhs"),
        contact_rhs=_calls(st, "model_", "contact_rhs"),
    )
    inside = sum(v[3] for k, v in st.stats.items() if k[2] == "solve_bvp" and "_bvp.py" in k[0])
    return dict(points=len(c), wall_s=statistics.median(walls), walls=walls, profiled_s=prof_wall,
                profiled_total_s=total, categories=cats, counts=counts, inside_solve_bvp_s=inside,
                median_nodes=float(np.median(c.nodes)), max_nodes=int(np.max(c.nodes)),
                median_step_ms=1e3 * float(np.median(c.wall_time)),
                top=[dict(function=f"{Path(k[0]).name}:{k[2]}", calls=v[1], tottime=v[2], cumtime=v[3])
                     for k, v in top])


def per_call(repeat=5):
    """Single calls of the generated functions and of solve_bvp's wrappers against nodes."""
    import shellbvp as sb

    scene = sb.Scene.preset("base")
    mod = scene.model()
    par = np.array(scene.parameters(mod), float)
    r = sb.solve(scene, delta=0.2, tol=1e-6, estimate_error=False)
    sysm, p = r.system, r.p
    rows = []
    a = np.linspace(1.0, 2.0, 300)
    op = min(timeit.repeat(lambda: a * a, number=2000, repeat=repeat)) / 2000
    for m in (30, 300, 3000):
        t = np.linspace(0.0, 1.0, m)
        y = r.sol(t)
        Sc, Sf = sysm.S(0, t, p), sysm.S(1, t, p)
        fns = dict(free_rhs=lambda: mod.free_rhs(Sf, y[2:], par),
                   contact_rhs=lambda: mod.contact_rhs(Sc, y[:2], par),
                   free_jac=lambda: mod.free_jac(Sf, y[2:], par),
                   contact_jac=lambda: mod.contact_jac(Sc, y[:2], par),
                   fun=lambda: sysm.fun(t, y, p), fun_jac=lambda: sysm.fun_jac(t, y, p))
        row = dict(nodes=m)
        for name, fn in fns.items():
            n = 20 if m <= 300 else 5
            row[name + "_us"] = 1e6 * min(timeit.repeat(fn, number=n, repeat=repeat)) / n
        rows.append(row)
    return dict(rows=rows, numpy_op_300_us=1e6 * op)


def import_times():
    """``python -X importtime -c 'import shellbvp'``: cumulative microseconds of a few modules."""
    import os
    import subprocess

    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    runs = []
    for _ in range(3):
        err = subprocess.run([sys.executable, "-X", "importtime", "-c", "import shellbvp"], env=env,
                             capture_output=True, text=True, check=True).stderr
        cum = {}
        for line in err.splitlines():
            parts = line.split("|")
            if len(parts) == 3 and parts[1].strip().isdigit():
                cum[parts[2].strip()] = int(parts[1])
        runs.append(cum)
    keys = ("shellbvp", "shellbvp.fitting", "scipy.integrate", "scipy.optimize", "h5py", "numpy", "sympy")
    return {k: statistics.median(r.get(k, 0) for r in runs) / 1e6 for k in keys}


SUGGESTIONS = """### Suggested optimisations (not made here: shellbvp/ and symbolic/ are being edited)

Estimates are fractions of the profiled natural-continuation curve above (the adaptive curve
splits the same way); they are not additive where marked as alternatives.

1. **Compile the generated model functions** (symbolic/codegen.py): a call is dominated by
   NumPy's per-operation overhead, not by arithmetic — `fun` costs {fun30:.0f} µs at 30 nodes and
   {fun300:.0f} µs at 300 (the curve's median mesh is {med_nodes:.0f} nodes), i.e. about
   {fixed:.0%} of a typical call is fixed cost of the ~100–450 NumPy operations per function.
   Emitting a loop over nodes for numba (`@njit`) or C (the same straight-line program, one pass
   per node) would make the right-hand sides and Jacobians ({rhs_jac:.0%} of the time) roughly
   10x cheaper: **about −{gain1:.0%} of curve time**.  numba would be a new optional dependency
   (keep the NumPy printer as the fallback).
2. *Alternative to 1, within NumPy:* **evaluate nodes and midpoints in one call.** solve_bvp calls
   `fun` separately at the nodes and at the midpoints, and `fun_jac` likewise; a forked
   `collocation_fun`/`construct_global_jac` (scipy's `_bvp.py` is BSD, ~1000 lines) concatenating
   both halves the number of calls; with calls ~{fixed:.0%} fixed cost: **about −{gain2:.0%}**.
3. **Do not evaluate the free right-hand side again inside `fun_jac`**: `free_rhs` is called
   {free_rhs} times against {fun} `fun` calls — the extra {extra} come from `fun_jac` (for the
   d/d ln Sc column of the mapped system).  solve_bvp has always just evaluated `fun` at the same
   points; cache the last (t, y, p) -> g in `MultipointBVP` (identity check) or let the generated
   `free_jac` return g: **about −{gain3:.0%}**.
4. **Lazy diagnostics**: the generated profiles (energy integral on Gauss points, Legendre
   determinant, penetration on nodes and midpoints) take {prof:.0%} and state.py's own code
   {diag:.0%}; computing them on first access (`Solution.energy` etc.) while keeping what the curve
   needs (F, delta, status) would save **up to −{gain4:.0%}** (the curve's `energy_residual` needs the
   energies, but only when asked for).
5. **Reuse the sparsity pattern of the collocation Jacobian** (needs the fork of 2): assembling
   COO -> CSC with index sorting on every Jacobian is {asm:.0%}; with a fixed pattern per mesh only the
   values change: **about −{gain5:.0%}**.  The sparse LU itself ({lu:.0%}) is SuperLU on an almost
   block-bidiagonal matrix; a Python block solver would not beat it.
6. **Fewer solve_bvp iterations per step**: {newton_per_point:.1f} Newton solves and {jac_per_point:.1f}
   Jacobians per point.  Each warm start on a mesh thinned to every third node must be refined
   again (at least one extra outer iteration: Newton, residual estimate, refinement).  Worth an
   experiment: coarsen only where the previous step's residual was far below tol (shellbvp can
   do that before calling solve_bvp), or thin every second node; if it saves one of the
   ~{newton_per_point:.0f} outer iterations: **up to −{gain6:.0%}** (unmeasured).
7. **Import time** (warm process start): `import shellbvp` takes {imp_total:.2f} s here, of which
   `shellbvp.fitting` {imp_fit:.2f} s — it imports `scipy.optimize` and `scipy.stats` (for the
   least-squares fit and Student's t) whenever shellbvp is imported.  Importing them inside
   `fit()` saves **about {imp_gain:.0%} of the import** for everything but fitting.  `scipy.integrate` ({imp_int:.2f} s) is needed for
   solve_bvp.

Together 1 (or 2) + 3 + 4 would take the median continuation step from the measured
{step_ms:.0f} ms to roughly {step_after:.0f} ms on this machine (the issue's target is 20 ms);
the rest is solve_bvp's own Python and SuperLU.
"""


def suggestions(data):
    d = data["natural"]
    tot = d["profiled_total_s"]
    sh = {k: v / tot for k, v in d["categories"].items()}
    C = CATEGORIES
    pc = {r["nodes"]: r for r in data["per_call"]["rows"]}
    fun30, fun300 = pc[30]["fun_us"], pc[300]["fun_us"]
    fixed = min(1.0, fun30 / fun300)
    rhs, jac = sh[C[0]], sh[C[1]]
    c = d["counts"]
    extra = c["free_rhs"] - c["fun"]
    gain1 = 0.9 * (rhs + jac)
    gain2 = 0.5 * fixed * (rhs + jac)
    gain3 = sh[C[0]] * max(extra, 0) / max(c["free_rhs"] + c["contact_rhs"], 1)
    gain4 = sh[C[3]] + sh[C[8]]
    gain5 = 0.6 * sh[C[5]]
    npp = c["newton_solves"] / max(d["points"], 1)
    gain6 = 1 / npp * (sh[C[0]] + sh[C[1]] + sh[C[4]] + sh[C[5]] + sh[C[6]] + sh[C[7]])
    imp = data.get("imports", {})
    step_ms = data["natural"].get("median_step_ms", math.nan)
    after = step_ms * (1 - gain1 - gain3 - gain4)
    return SUGGESTIONS.format(
        fun30=fun30, fun300=fun300, med_nodes=d["median_nodes"], fixed=fixed, rhs_jac=rhs + jac, gain1=gain1,
        gain2=gain2, free_rhs=c["free_rhs"], fun=c["fun"], extra=extra, gain3=gain3, prof=sh[C[3]],
        diag=sh[C[8]], gain4=gain4, asm=sh[C[5]], gain5=gain5, lu=sh[C[4]], newton_per_point=npp,
        jac_per_point=c["jacobians"] / max(d["points"], 1), gain6=gain6,
        imp_total=imp.get("shellbvp", math.nan), imp_fit=imp.get("shellbvp.fitting", math.nan),
        imp_int=imp.get("scipy.integrate", math.nan),
        imp_gain=imp.get("shellbvp.fitting", 0) / imp["shellbvp"] if imp.get("shellbvp") else math.nan,
        step_ms=step_ms, step_after=after)


def markdown(data):
    m = data["meta"]
    L = [f"Measured {m['date']} on a {m['machine']} ({m['cpus']} cores, shared), Python {m['python']}, "
         f"NumPy {m['numpy']}, SciPy {m['scipy']}, shellbvp {m['shellbvp']} ({m['git']}); "
         "`python benchmarks/profile_hot_path.py`. cProfile's own overhead inflates functions with many "
         "short calls; the unprofiled time is given beside it.", ""]
    for key, title in (("natural", "natural continuation at the 40 depths delta = 0.5 k/40"),
                       ("adaptive", "adaptive curve to delta = 0.5")):
        d = data[key]
        tot = d["profiled_total_s"]
        c = d["counts"]
        L += [f"### Base curve, tol 1e-6, {title} (`estimate_error=False`)", "",
              f"{d['points']} points; {d['wall_s']:.2f} s unprofiled (median of {len(d['walls'])}), "
              f"{d['profiled_s']:.2f} s under cProfile; {d['inside_solve_bvp_s'] / tot:.0%} of the profiled "
              f"time is inside solve_bvp. Nodes: median {d['median_nodes']:.0f}, max {d['max_nodes']}. "
              f"Work: {c['solve_bvp']} solve_bvp runs, {c['newton_solves']} Newton solves, "
              f"{c['jacobians']} collocation Jacobians (each {2} fun_jac calls: nodes and midpoints; "
              f"{c['lu_factorisations']} sparse LU factorisations), {c['fun']} fun calls, {c['bc']} bc calls "
              f"— per point {c['fun'] / max(d['points'], 1):.0f} fun and {c['fun_jac'] / max(d['points'], 1):.0f} "
              "fun_jac calls.", "",
              "| where | profiled s | share |", "|---|---|---|"]
        for cat, t in sorted(d["categories"].items(), key=lambda kv: -kv[1]):
            if t > 0:
                L.append(f"| {cat} | {t:.3f} | {t / tot:.0%} |")
        L += ["", "Top functions by own time:", "", "| function | calls | own s | cumulative s |", "|---|---|---|---|"]
        for r in d["top"][:12]:
            L.append(f"| {r['function']} | {r['calls']} | {r['tottime']:.3f} | {r['cumtime']:.3f} |")
        L.append("")
    pc = data["per_call"]
    L += ["### One call against the number of nodes (µs, best of 5)", "",
          "| nodes | free_rhs | contact_rhs | free_jac | contact_jac | fun (both regions) | fun_jac |",
          "|---|---|---|---|---|---|---|"]
    for r in pc["rows"]:
        L.append(f"| {r['nodes']} | {r['free_rhs_us']:.0f} | {r['contact_rhs_us']:.0f} | {r['free_jac_us']:.0f} "
                 f"| {r['contact_jac_us']:.0f} | {r['fun_us']:.0f} | {r['fun_jac_us']:.0f} |")
    L += ["", f"One NumPy multiplication of 300 doubles: {pc['numpy_op_300_us']:.1f} µs.", ""]
    imp = data.get("imports")
    if imp:
        L += ["`python -X importtime -c 'import shellbvp'` (cumulative s, median of 3): "
              + ", ".join(f"{k} {v:.2f}" for k, v in imp.items() if v) + ".", ""]
    return "\n".join(L) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_output_args(ap)
    ap.add_argument("--quick", action="store_true", help="one timed run, 10 depths (writes profile-quick.*)")
    args = ap.parse_args(argv)
    import platform
    import datetime
    import os

    import numpy
    import scipy

    import shellbvp as sb

    scene = sb.Scene.preset("base")
    scene.model()
    n = 10 if args.quick else 40
    deltas = 0.5 * np.arange(1, n + 1) / n
    repeat = 1 if args.quick else 3
    data = dict(
        natural=profile_curve(lambda: sb.curve(scene, deltas=deltas, tol=1e-6, estimate_error=False), repeat),
        adaptive=profile_curve(lambda: sb.curve(scene, delta_max=0.5, tol=1e-6, estimate_error=False), repeat),
        per_call=per_call(2 if args.quick else 5),
        imports=import_times(),
    )
    src = Path(sb.__file__).resolve().parent.parent
    data["meta"] = dict(date=datetime.date.today().isoformat(), machine=platform.machine(), cpus=os.cpu_count(),
                        python=platform.python_version(), numpy=numpy.__version__, scipy=scipy.__version__,
                        shellbvp=sb.__version__, quick=args.quick,
                        git=os.environ.get("SHELLBVP_SOURCE_NOTE") or commit_label(src, "not a git checkout"))
    out = results_dir(args.out_dir)
    name = "profile-quick" if args.quick else "profile"
    (out / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))
    md = markdown(data) + "\n" + suggestions(data)
    (out / f"{name}.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
