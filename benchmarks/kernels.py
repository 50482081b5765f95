"""Compiled kernels (numba) against the numpy functions: calls, curves, compile and start-up.

Measures, on the base scene (issue 14 item 2):

* per call at a solved state (delta 0.3, ~280 nodes): the generated functions and the
  solver's ``fun`` / ``fun_jac`` (all regions plus glue), numpy and compiled;
* per curve, in one process, numpy and compiled runs interleaved (``--repeat`` each,
  medians): the default base curve to delta 0.5, the 40-depth curve cap-only
  (``deltas=linspace(0.0125, 0.5, 40), topology="cap"``) and the same with lift-off;
  the share of the boundary and junction conditions (left in numpy) in a compiled curve;
* cold start in fresh processes and empty code caches: derivation + generation of both
  modules, compilation (``SHELLBVP_KERNELS=numba``); warm start: a fresh process to the
  end of its first solve under numpy, auto and numba, with the caches full;
* "never slower": a fresh process whose kernels are not yet compiled runs the base curve
  under numpy; under auto (compiled in a background process meanwhile); and, for the
  record, under numpy while a thread of the same process compiles (the rejected design).

Writes results/kernels.json and results/kernels.md (``--quick``: one run each, the
base curve only, no "never slower" runs, ``kernels-quick.*``).  Without numba it writes nothing and says so.

    python benchmarks/kernels.py [--quick] [--repeat N] [--out-dir DIR]
"""

from __future__ import annotations

import argparse
import compileall
import datetime
import importlib.util
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

from checkout import add_output_args, checkout_env, results_dir  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

_DEPTHS = [0.0125 * (k + 1) for k in range(40)]  # linspace(0.0125, 0.5, 40)
#: label -> keyword arguments of sb.curve (plain data: also handed to fresh processes as JSON)
CURVES = {
    "base curve to delta 0.5 (default settings)": {"delta_max": 0.5},
    "40 depths, cap only": {"deltas": _DEPTHS, "topology": "cap"},
    "40 depths, with lift-off": {"deltas": _DEPTHS},
}


def _env(cache, kernels):
    return checkout_env(SHELLBVP_CACHE_DIR=str(cache), SHELLBVP_KERNELS=kernels)


def _probe(code, cache, kernels):
    """Run ``code`` in a fresh interpreter; its last stdout line as JSON, plus the process wall time."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], env=_env(cache, kernels), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"probe failed ({kernels}):\n{out.stderr[-3000:]}")
    return dict(json.loads(out.stdout.strip().splitlines()[-1]), process_wall_s=wall)


START = """
import time, json
t0 = time.perf_counter()
import shellbvp as sb
from shellbvp import kernels as sk
t1 = time.perf_counter()
scene = sb.Scene.preset("base")
model = scene.model()
t2 = time.perf_counter()
ks = sk.kernel_set(model, scene.structure)
t3 = time.perf_counter()
sol = sb.solve(scene, delta=0.2)
t4 = time.perf_counter()
if ks.status == "waiting":
    ks.settled.wait(900)
t5 = time.perf_counter()
print(json.dumps(dict(import_s=t1 - t0, model_s=t2 - t1, kernels_s=t3 - t2, first_solve_s=t4 - t3,
                      start_to_first_solve_s=t4 - t0, settled_s=t5 - t0, status=ks.status,
                      ok=bool(sol.status == 0))))
"""

CURVE_IN_FRESH_PROCESS = """
import time, json, threading
import numpy as np
import shellbvp as sb
from shellbvp import kernels as sk, model as sbm
scene = sb.Scene.preset("base")
scene.model()
if {thread}:  # the rejected design: compile in a thread of this process
    desc = scene.structure()
    src = sbm.kernel_path(desc)
    threading.Thread(target=sk._compile_here, args=(src, scene.model().KEY, desc), daemon=True).start()
t0 = time.perf_counter()
c = sb.curve(scene, **json.loads({kwargs!r}))
t1 = time.perf_counter()
ks = sk.kernel_set(scene.model(), scene.structure)
print(json.dumps(dict(curve_s=t1 - t0, points=len(c), status_at_end=ks.status)))
"""


def _wait_unlocked(cache, timeout=900):
    """Wait until no background compile holds a lock in ``cache`` (it outlives its parent)."""
    t0 = time.time()
    while any(Path(cache).glob("kernels_*.lock")) and time.time() - t0 < timeout:
        time.sleep(0.2)


def _cold_kernels_copy(warm, dest):
    """A cache with the numpy and kernel modules but nothing compiled."""
    shutil.copytree(warm, dest, ignore=shutil.ignore_patterns("__pycache__", "*.ready", "*.lock", "*.log"))


#: the floor under every start: what shellbvp's import cannot avoid (solve_bvp's package)
SCIPY_FLOOR = """
import time, json
t0 = time.perf_counter()
import scipy.integrate
print(json.dumps(dict(import_s=time.perf_counter() - t0)))
"""


def startup(repeat):
    """Fresh processes, cold and warm; the package's own bytecode compiled first, as pip does
    when it installs a wheel (else, under PYTHONDONTWRITEBYTECODE, every start compiles its
    sources: ~0.1 s), and, per repeat, ``import scipy.integrate`` alone (the floor)."""
    for package in ("shellbvp", "symbolic"):
        compileall.compile_dir(str(ROOT / package), quiet=1)
    rows = {"cold": [], "warm numpy": [], "warm auto": [], "warm numba": []}
    floor = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as cache:
            rows["cold"].append(_probe(START, cache, "numba"))
            for kind in ("numpy", "auto", "numba"):
                rows[f"warm {kind}"].append(_probe(START, cache, kind))
            floor.append(_probe(SCIPY_FLOOR, cache, "numpy"))
    out = {k: _medians(v) for k, v in rows.items()}
    out["floor"] = _medians(floor)
    return out


NEVER_SLOWER = (  # label, SHELLBVP_KERNELS, kernels compiled beforehand?, compile in a thread of the process?
    ("numpy", "numpy", False, False),
    ("auto, kernels not compiled yet (compiled meanwhile in a background process)", "auto", False, False),
    ("numpy while a thread of the process compiles the kernels (the rejected design)", "numpy", False, True),
    ("auto, kernels compiled before (loaded from numba's cache meanwhile)", "auto", True, False),
)


def never_slower(repeat, warm_cache, curve):
    rows = {label: [] for label, *_ in NEVER_SLOWER}
    for _ in range(repeat):
        for label, kernels, compiled, thread in NEVER_SLOWER:
            with tempfile.TemporaryDirectory() as tmp:
                cache = Path(tmp) / "c"
                if compiled:
                    shutil.copytree(warm_cache, cache)  # time stamps kept: numba's cache stays valid
                    _probe(START, cache, "numba")  # (if it were not, this compiles it, before the run)
                else:
                    _cold_kernels_copy(warm_cache, cache)
                code = CURVE_IN_FRESH_PROCESS.format(thread=thread, kwargs=json.dumps(curve))
                rows[label].append(_probe(code, cache, kernels))
                _wait_unlocked(cache)  # the background compile finishes before the next run starts
    return {k: _medians(v) for k, v in rows.items()}


def _medians(runs):
    out = {}
    for key in runs[0]:
        vals = [r[key] for r in runs]
        out[key] = statistics.median(vals) if isinstance(vals[0], (int, float)) and not isinstance(
            vals[0], bool) else vals[0]
    out["runs"] = len(runs)
    return out


# -- in this process ----------------------------------------------------------------------------------
def per_call(sb, sk, np):
    scene = sb.Scene.preset("base")
    os.environ["SHELLBVP_KERNELS"] = "numpy"
    ref = sb.solve(scene, delta=0.3)
    systems = {"numpy": ref.system}
    os.environ["SHELLBVP_KERNELS"] = "numba"
    systems["numba"] = sb.solve(scene, delta=0.3).system
    assert systems["numba"].kernels.status == "numba"
    t, y, p = ref.x, ref.y, ref.p
    mod = scene.model()
    par = scene.parameters(mod)
    S = {k: systems["numpy"].S(k, t, p) for k in range(2)}
    rows = {}

    def best(f):
        n = 20
        return min(timeit.repeat(f, number=n, repeat=7)) / n

    # fun at a new iterate (ChainBVP.fun keeps its last results: repeated at the same arguments it
    # would return them); fun_jac as solve_bvp calls it, after fun at the same iterate (it takes the
    # right-hand sides it needs from fun's kept results)
    for s in systems.values():
        s.fun(t, y, p)
    for name, fns in (("fun (both regions + glue, a new iterate)",
                       {k: (lambda s=s: s._fun(t, y, p)[0]) for k, s in systems.items()}),
                      ("fun_jac (both regions + glue, after fun at the same iterate)",
                       {k: (lambda s=s: s.fun_jac(t, y, p)) for k, s in systems.items()})):
        rows[name] = {k: best(f) for k, f in fns.items()}
    for region, k, rows_y in (("contact", 0, slice(0, 2)), ("free", 1, slice(2, 8))):
        for what in ("rhs", "jac", "jac_par"):
            name = f"{region}_{what}"
            rows[name] = {kind: best(lambda s=s, name=name, k=k, r=rows_y: getattr(s.kernels.active, name)(
                S[k], y[r], par)) for kind, s in systems.items()}
    for name in ("bc", "bc_jac"):
        rows[name + " (numpy, not compiled)"] = {"numpy": best(lambda f=getattr(systems["numpy"], name): f(
            y[:, 0], y[:, -1], p))}
    return {"nodes": int(t.size), "delta": 0.3, "seconds_per_call": rows}


def per_curve(sb, sk, np, repeat, curves):
    scene = sb.Scene.preset("base")
    out = {}
    for label, kwargs in curves.items():
        times = {"numpy": [], "numba": []}
        forces = {}
        for _ in range(repeat):
            for kind in ("numpy", "numba"):
                os.environ["SHELLBVP_KERNELS"] = kind
                t0 = time.perf_counter()
                c = sb.curve(scene, **kwargs)
                times[kind].append(time.perf_counter() - t0)
                forces[kind] = (np.asarray(c.delta), np.asarray(c.force), len(c))
        (dn, fn, nn), (db, fb, nb) = forces["numpy"], forces["numba"]
        same = nn == nb and np.allclose(dn, db, rtol=0, atol=1e-12)
        out[label] = {
            "numpy_s": statistics.median(times["numpy"]), "numba_s": statistics.median(times["numba"]),
            "speedup": statistics.median(times["numpy"]) / statistics.median(times["numba"]),
            "points": [nn, nb], "runs": repeat,
            "max_rel_F_difference": float(np.max(np.abs(fb - fn) / np.abs(fn))) if same else None,
        }
    return out


def conditions_share(sb, np):
    """Seconds in bc and bc_jac over the default base curve with compiled kernels (their share)."""
    from shellbvp import chain

    spent = {"bc": 0.0, "bc_jac": 0.0}
    originals = {k: getattr(chain.ChainBVP, k) for k in spent}

    def timed(name):
        f = originals[name]

        def wrapper(self, *a):
            t0 = time.perf_counter()
            try:
                return f(self, *a)
            finally:
                spent[name] += time.perf_counter() - t0
        return wrapper

    os.environ["SHELLBVP_KERNELS"] = "numba"
    try:
        for k in spent:
            setattr(chain.ChainBVP, k, timed(k))
        t0 = time.perf_counter()
        sb.curve(sb.Scene.preset("base"), delta_max=0.5)
        total = time.perf_counter() - t0
    finally:
        for k, f in originals.items():
            setattr(chain.ChainBVP, k, f)
    return {"curve_s": total, **{f"{k}_s": v for k, v in spent.items()},
            "share": (spent["bc"] + spent["bc_jac"]) / total}


# -- report ---------------------------------------------------------------------------------------------
def markdown(data):
    m = data["meta"]
    load = f", load average {m['load_average']:.1f} at the start" if m.get("load_average") is not None else ""
    L = [f"Measured {m['date']} on {m['machine']} ({m['cpus']} cores, shared with other work{load}), Python "
         f"{m['python']}, NumPy {m['numpy']}, numba {m['numba']}; `python benchmarks/kernels.py"
         f"{' --quick' if m['quick'] else ''}`.  Absolute times on this machine are noisy; "
         "ratios come from runs interleaved in one process (medians).", ""]
    pc = data["per_call"]
    L += [f"### Per call, base scene at delta {pc['delta']} ({pc['nodes']} nodes)", "",
          "| function | numpy (µs) | compiled (µs) | speed-up |", "|---|---|---|---|"]
    for name, r in pc["seconds_per_call"].items():
        if "numba" in r:
            L.append(f"| {name} | {r['numpy'] * 1e6:.0f} | {r['numba'] * 1e6:.0f} | "
                     f"x{r['numpy'] / r['numba']:.1f} |")
        else:
            L.append(f"| {name} | {r['numpy'] * 1e6:.0f} | – | – |")
    L += ["", "### Per curve, base scene", "",
          "| curve | points | numpy (s) | compiled (s) | speed-up | max rel. F difference |", "|---|---|---|---|---|---|"]
    for label, r in data["per_curve"].items():
        diff = "–" if r["max_rel_F_difference"] is None else f"{r['max_rel_F_difference']:.0e}"
        L.append(f"| {label} | {r['points'][0]} | {r['numpy_s']:.2f} | {r['numba_s']:.2f} | "
                 f"x{r['speedup']:.2f} | {diff} |")
    cs = data["conditions"]
    L += ["", "Boundary and junction conditions (`bc`, `bc_jac`, left in numpy) take "
          f"{cs['bc_s'] + cs['bc_jac_s']:.3f} s of the compiled default curve's {cs['curve_s']:.2f} s ({100 * cs['share']:.1f} %): compiling them "
          "could save at most that.", ""]
    st = data["startup"]
    c = st["cold"]
    L += [f"### Start-up (fresh processes, median of {c['runs']})", "",
          "| case | import shellbvp (s) | numpy module (s) | kernels (s) | first solve (s) | "
          "process start to first solve (s) | kernels in use |", "|---|---|---|---|---|---|---|"]
    for label, r in st.items():
        if label == "floor":
            continue
        L.append(f"| {label} | {r['import_s']:.2f} | {r['model_s']:.2f} | {r['kernels_s']:.2f} | "
                 f"{r['first_solve_s']:.2f} | {r['start_to_first_solve_s']:.2f} | {r['status']} after "
                 f"{r['settled_s']:.1f} s |")
    L += ["", "cold: empty cache, `SHELLBVP_KERNELS=numba` (derive and generate both modules, then compile "
          "in the foreground).  warm auto: numpy serves (a single solve never loads the kernels).  The "
          "package's bytecode is compiled before (as pip installs a wheel); the generated modules' bytecode "
          "is written by the package into its cache."]
    if "floor" in st:
        fl, warm = st["floor"]["import_s"], st["warm numpy"]["start_to_first_solve_s"]
        L += [f"`import scipy.integrate` alone, in the same fresh processes (the floor under any first solve: "
              f"solve_bvp's package imports scipy.optimize, linalg and sparse): {fl:.2f} s (median of "
              f"{st['floor']['runs']}).  Of a warm numpy start to the end of its first solve ({warm:.2f} s) the rest, "
              f"{warm - fl:.2f} s, is shellbvp's (its import, the cached module, the solve)."]
    L += [""]
    ns = data.get("never_slower")
    if ns is None:
        return "\n".join(L) + "\n"
    L += [f"### A process whose kernels are not compiled yet: {ns['curve']} (median of "
          f"{next(iter(ns['rows'].values()))['runs']})", "",
          "| mode | curve (s) | kernels at the end of the curve |", "|---|---|---|"]
    for label, r in ns["rows"].items():
        L.append(f"| {label} | {r['curve_s']:.2f} | {r['status_at_end']} |")
    return "\n".join(L) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one run each, the base curve only, no 'never slower' runs (kernels-quick.*)")
    ap.add_argument("--repeat", type=int, default=None, help="runs per measurement (default 5, quick 1)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    if importlib.util.find_spec("numba") is None:
        print("kernels.py: numba is not installed (pip install 'shellbvp[fast]'): nothing to measure")
        return 0
    repeat = args.repeat or (1 if args.quick else 5)
    sys.path.insert(0, str(ROOT))
    import numba
    import numpy as np

    import shellbvp as sb
    from shellbvp import kernels as sk

    curves = dict(list(CURVES.items())[:1]) if args.quick else CURVES
    warm = Path(tempfile.mkdtemp(prefix="shellbvp-kernels-bench-"))
    try:
        os.environ["SHELLBVP_CACHE_DIR"] = str(warm)
        os.environ["SHELLBVP_KERNELS"] = "numba"
        t0 = time.perf_counter()
        sk.kernel_set(sb.Scene.preset("base").model(), sb.Scene.preset("base").structure)
        print(f"warm-up (derive, compile) {time.perf_counter() - t0:.1f} s", flush=True)
        data = {"meta": dict(date=datetime.date.today().isoformat(), machine=platform.machine(), cpus=os.cpu_count(),
                             python=platform.python_version(), numpy=np.__version__, numba=numba.__version__,
                             quick=args.quick, repeat=repeat,
                             load_average=os.getloadavg()[0] if hasattr(os, "getloadavg") else None)}
        data["per_call"] = per_call(sb, sk, np)
        print("per call done", flush=True)
        data["per_curve"] = per_curve(sb, sk, np, repeat, curves)
        print("per curve done", flush=True)
        data["conditions"] = conditions_share(sb, np)
        data["startup"] = startup(max(1, min(repeat, 3)))
        print("start-up done", flush=True)
        if not args.quick:  # four fresh processes, two of them compiling: minutes
            first = next(iter(CURVES))
            data["never_slower"] = {"curve": first, "rows": never_slower(min(repeat, 3), warm, CURVES[first])}
    finally:
        _wait_unlocked(warm)
        shutil.rmtree(warm, ignore_errors=True)
    res = results_dir(args.out_dir)
    name = "kernels-quick" if args.quick else "kernels"
    (res / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")
    text = markdown(data)
    (res / f"{name}.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
