"""Where one point of a cap curve goes, without a profiler (issue 14's per-point target).

cProfile (``profile_hot_path.py``) charges every Python call its own overhead, which
inflates the package's many short functions against the compiled kernels.  Here the
functions that split a point's time are wrapped in a timer instead (process time; about
40 wrapped calls a point), the rest is charged to the package's own code, and the
instrumentation's own cost is measured too: the same curve timed with and without the
wrappers, alternately, in the same process.

The curve is the cap-only natural continuation through 47 evenly spaced depths from
0.15 to 0.5 at tol 1e-6 with error estimates as by default: the collocation side of the
shooting comparison in ``speed_vs_baseline.py`` (there, shooting's own 24-57 states).
Each preset and kernel choice runs in a fresh process after a warm-up curve (the kernels
loaded, scipy imported).  The categories (time in each, exclusive of the wrapped
functions it calls):

* scipy's solve_bvp: its own Python and NumPy (Newton, residuals, splines), the callbacks
  and the linear algebra it calls excluded;
* the package's callbacks: ``ChainBVP.fun``, ``fun_jac``, ``bc``, ``bc_jac``, the kernels
  and conditions they call excluded;
* the region kernels (right-hand sides, Jacobians, profiles, energy densities): compiled,
  or the generated numpy functions;
* the collocation linear algebra: the compiled elimination, or assembly and SuperLU;
* the generated boundary and junction conditions (numpy in both);
* the diagnosis, the error estimates and the predictor: their own Python;
* the rest of the package (continuation, states, results).

Writes results/point_budget.json and results/point_budget.md.

    python benchmarks/point_budget.py [--presets base,base-xi0,flat,gent1] [--kernels numba,numpy]
                                      [--repeat 5] [--out-dir DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEPTHS = (0.15, 0.5, 47)  # linspace arguments
TOL = 1e-6
REGION_KINDS = ("free_", "contact_", "cylinder_")

SCIPY = "scipy's solve_bvp (its own Python and NumPy)"
CALLBACKS = "package callbacks (chain.py: fun, fun_jac, bc, bc_jac)"
KERNELS = "region kernels (right-hand sides, Jacobians, profiles, energy)"
LINALG = "collocation linear algebra (elimination, or assembly and SuperLU)"
CONDITIONS = "generated boundary and junction conditions"
DIAGNOSIS = "diagnosis (diagnosis.py)"
ESTIMATES = "error estimates (Richardson)"
PREDICTOR = "predictor (quadratic in delta)"
REST = "rest of the package (continuation, states, results)"
CATEGORIES = (SCIPY, CALLBACKS, KERNELS, LINALG, CONDITIONS, DIAGNOSIS, ESTIMATES, PREDICTOR, REST)


class Timers:
    """Exclusive process time of wrapped functions, by category."""

    def __init__(self):
        self.spent = dict.fromkeys(CATEGORIES, 0.0)
        self.calls = dict.fromkeys(CATEGORIES, 0)
        self._stack = []
        self._wrapped = []

    def wrap(self, obj, name, category):
        orig = getattr(obj, name)
        stack, spent, calls = self._stack, self.spent, self.calls

        def timed(*args, **kwargs):
            t0 = time.process_time()
            stack.append(0.0)
            try:
                return orig(*args, **kwargs)
            finally:
                dt = time.process_time() - t0
                spent[category] += dt - stack.pop()
                calls[category] += 1
                if stack:
                    stack[-1] += dt

        setattr(obj, name, timed)
        self._wrapped.append((obj, name, orig))

    def install(self, scene):
        """Wrap the functions that split a point (after a first solve: collocation.install
        has put the package's linear algebra into scipy's _bvp by then)."""
        import scipy.integrate
        import scipy.integrate._bvp as bvp

        import shellbvp.chain
        import shellbvp.recorder
        import shellbvp.steps
        import shellbvp.state
        from shellbvp.kernels import kernel_set

        self.wrap(scipy.integrate, "solve_bvp", SCIPY)
        for name in ("fun", "fun_jac", "bc", "bc_jac"):
            self.wrap(shellbvp.chain.ChainBVP, name, CALLBACKS)
        for name in ("construct_global_jac", "splu"):
            self.wrap(bvp, name, LINALG)
        self.wrap(shellbvp.state, "diagnose", DIAGNOSIS)
        self.wrap(shellbvp.recorder, "richardson_error", ESTIMATES)
        self.wrap(shellbvp.steps, "quadratic_guess", PREDICTOR)
        active = kernel_set(scene.model(), scene.structure).active
        model = scene.model()
        for mod in {id(active): active, id(model): model}.values():
            for name in dir(mod):
                f = getattr(mod, name)
                if name.startswith("_") or not callable(f) or isinstance(f, type):
                    continue
                if name.startswith("collocation_"):
                    self.wrap(mod, name, LINALG)
                elif name.startswith(REGION_KINDS) and mod is active:
                    self.wrap(mod, name, KERNELS)
                elif name.endswith(("_res", "_jac")) and not name.startswith(REGION_KINDS):
                    self.wrap(mod, name, CONDITIONS)

    def remove(self):
        for obj, name, orig in reversed(self._wrapped):
            setattr(obj, name, orig)
        self._wrapped.clear()

    def reset(self):
        for c in CATEGORIES:
            self.spent[c], self.calls[c] = 0.0, 0


def worker(preset, repeat):
    """One preset with the kernels of SHELLBVP_KERNELS; prints one JSON line."""
    import numpy as np
    import scipy.integrate  # noqa: F401 (imported before timing, as in speed_vs_baseline.py)
    import scipy.interpolate  # noqa: F401

    import shellbvp as sb
    from shellbvp.kernels import kernel_set

    scene = sb.Scene.preset(preset)
    kernel_set(scene.model(), scene.structure)
    depths = np.linspace(*DEPTHS)
    sb.curve(scene, deltas=depths[:3], topology="cap", tol=TOL)  # warm-up: kernels, collocation.install
    timers = Timers()
    plain, wrapped, points, nodes = [], [], None, None
    for _ in range(repeat):
        for instrumented in (False, True):
            if instrumented:
                timers.install(scene)
            c0 = time.process_time()
            c = sb.curve(scene, deltas=depths, topology="cap", tol=TOL)
            cpu = time.process_time() - c0
            timers.remove()
            (wrapped if instrumented else plain).append(cpu)
            points, nodes = len(c), float(np.median(c.points["nodes"]))
    spent = dict(timers.spent)
    total = sum(wrapped)
    spent[REST] = total - sum(v for k, v in spent.items() if k != REST)
    n = repeat * points
    print(json.dumps(dict(preset=preset, kernels=os.environ.get("SHELLBVP_KERNELS"), points=points,
                          median_nodes=nodes, ms_per_point=1e3 * float(np.median(plain)) / points,
                          ms_per_point_wrapped=1e3 * float(np.median(wrapped)) / points,
                          ms={k: 1e3 * v / n for k, v in spent.items()},
                          calls={k: v / n for k, v in timers.calls.items()})))


def markdown(rows, meta):
    out = [f"Measured {meta['date']} on {meta['machine']} ({meta['cpu']}; {meta['cpus']} cores, shared), "
           f"Python {meta['python']}, NumPy {meta['numpy']}, SciPy {meta['scipy']}, at {meta['commit']}; "
           f"`python benchmarks/point_budget.py --repeat {meta['repeat']}`. The cap-only curve through "
           f"{DEPTHS[2]} depths from {DEPTHS[0]} to {DEPTHS[1]} at tol {TOL:g} (error estimates as by default), "
           "each preset and kernel choice in a fresh process after a warm-up curve; process time, median over "
           "the repeats of the plain curve (ms/point), and the split of the instrumented curve (exclusive time "
           "of each category; its total is the instrumented ms/point, the wrappers' own cost included, mostly "
           "in the categories whose functions are called most).", ""]
    for kernels in dict.fromkeys(r["kernels"] for r in rows):
        sel = [r for r in rows if r["kernels"] == kernels]
        out += [f"### Kernels: {kernels}", "",
                "| category | " + " | ".join(f"{r['preset']} ms/point (%)" for r in sel) + " |",
                "|---|" + "---|" * len(sel)]
        for c in CATEGORIES:
            cells = []
            for r in sel:
                ms = r["ms"][c]
                cells.append(f"{ms:.2f} ({100 * ms / r['ms_per_point_wrapped']:.0f} %)")
            out.append(f"| {c} | " + " | ".join(cells) + " |")
        out.append("| **instrumented total** | " + " | ".join(f"{r['ms_per_point_wrapped']:.2f}" for r in sel) + " |")
        out.append("| **plain curve** | " + " | ".join(f"{r['ms_per_point']:.2f}" for r in sel) + " |")
        out.append("| points, median nodes | " + " | ".join(f"{r['points']}, {r['median_nodes']:.0f}" for r in sel)
                   + " |")
        out.append("")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", default="base,base-xi0,flat,gent1")
    ap.add_argument("--kernels", default="numba,numpy", help="comma-separated SHELLBVP_KERNELS values")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    sys.path.insert(0, str(HERE))
    from checkout import add_output_args, results_dir, stem

    add_output_args(ap, quick="base, numpy kernels, one repeat")
    args = ap.parse_args(argv)
    if args.quick:
        args.presets, args.kernels, args.repeat = "base", "numpy", 1
    if args.repeat < 1:
        ap.error(f"--repeat must be >= 1; got {args.repeat}")
    if args.worker:
        return worker(args.worker, args.repeat)
    from checkout import checkout_env
    from speed_vs_baseline import cpu_model, this_commit, write_atomic

    import datetime
    import platform

    import numpy as np
    import scipy

    rows = []
    for kernels in args.kernels.split(","):
        for preset in args.presets.split(","):
            env = checkout_env(SHELLBVP_KERNELS=kernels)  # this checkout's package: the commit meta names
            proc = subprocess.run([sys.executable, __file__, "--worker", preset, "--repeat", str(args.repeat)],
                                  env=env, capture_output=True, text=True)
            if proc.returncode != 0:
                raise SystemExit(f"{preset} ({kernels}) failed:\n{proc.stderr[-2000:]}")
            rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
            r = rows[-1]
            print(f"{preset:10s} {kernels:6s} {r['ms_per_point']:.2f} ms/point "
                  f"({r['ms_per_point_wrapped']:.2f} instrumented)", flush=True)
    meta = dict(date=datetime.date.today().isoformat(), machine=f"{platform.machine()} {platform.system()}",
                cpu=cpu_model(), cpus=os.cpu_count(), python=platform.python_version(), numpy=np.__version__,
                scipy=scipy.__version__, commit=this_commit(), repeat=args.repeat)
    out, name = results_dir(args.out_dir), stem("point_budget", args.quick)
    write_atomic(out / f"{name}.json", json.dumps(dict(meta=meta, rows=rows), indent=1))
    write_atomic(out / f"{name}.md", markdown(rows, meta) + "\n")


if __name__ == "__main__":
    main()
