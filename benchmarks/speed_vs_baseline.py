"""The package at this commit against the package at a baseline commit, and against shooting (issue 14).

One run measures, side by side on the same machine, the curves of the base scene (the default
adaptive curve; 40 depths ``linspace(0.0125, 0.5, 40)`` with lift-off; the same cap-only) and
the default curve of every other preset: wall time, solve_bvp runs, Newton iterations, nodes,
and the largest relative F error of each curve against a reference (every depth at tol 1e-9,
every 12th also at 1e-10 to show the reference's own error).

* The baseline (default 1109cdf) is extracted with ``git archive`` into a work directory and
  imported from there (``PYTHONPATH``); this commit is the checkout this script lives in.
  Each side has its own code cache (``XDG_CACHE_HOME`` and ``SHELLBVP_CACHE_DIR``), warmed
  before timing, so the generated modules of the two never collide.
* Every curve is a fresh process (``--worker``) that imports scipy.integrate and
  scipy.interpolate (which solve_bvp's first run imports; timed apart, ``interpolate_import_s``:
  until e4383b6 it was inside the first curve's time, on both sides) and loads the cached model,
  then times the curve alone; solve_bvp runs and Newton iterations are counted by wrapping
  ``scipy.integrate.solve_bvp`` in that process (both sides import it on first use).
* Runs alternate: each repeat runs every case on every variant, the variants' order rotating,
  so that a noisy shared machine weighs on both sides alike; a ratio is the median of the
  per-repeat ratios.
* Variants of this commit with one change switched off by a private flag measure what each
  change bought: ``cold lift-off`` (lift-off states from the cap's guesses first, as before),
  ``no secant guard`` (the secant predictor in ln Sc unguarded), ``full Richardson``
  (``estimate_error="full"``: a Richardson solve at every point, as at the baseline),
  ``thinned warm meshes`` (warm starts on every third node instead of a mesh equidistributing
  the residual), ``explicit zeros kept`` (scipy's own assembly of solve_bvp's Jacobian, with its
  stored zeros, and SuperLU, with the numpy functions and with numba's: compare with ``this
  commit, numba``), ``SuperLU, numba`` (numba's kernels, but the Jacobian assembled and
  factorised by SuperLU instead of the kernels' elimination), ``annulus before split`` (where
  the line's pole is down on the tip, the annulus probed before the split cap+line(tip)); these
  on the base curves only.
* Shooting (``benchmarks/shooting.py``, the paper's method) re-solves the reference's cap
  states (delta >= 0.15) at its rtol 1e-6 to 1e-9, each from its neighbour with the
  tangent predictor (the first from the reference's own unknowns: no cold start is counted);
  its time per point at its loosest rtol with equal or better F error is compared with three
  collocation measures: the default curve's time per point (lift-off states, switches and the
  small-delta leg included, which shooting does not solve); the time per point of a cap-only
  curve through exactly shooting's states (natural continuation, default error estimates, its
  cold first point counted); and that curve's time per point after its first point (the first
  point's curve timed alone after it, in the same process), against shooting's, which starts
  warm: the same work on both sides.  States closer than SAME_STATE_RTOL count once (before
  695242b the union of the curves' depths kept pairs 1e-10 apart).  Shooting and those
  cap-only curves run interleaved, one round per repeat, each side's time the median over
  rounds (before 425cc53 shooting ran once, apart from them).

Writes benchmarks/results/speed_vs_baseline.json and .md (``--quick``: base default curve, one
repeat, no shooting, ``speed_vs_baseline-quick.*``).

    python benchmarks/speed_vs_baseline.py [--baseline 1109cdf] [--repeat 3] [--quick] [--out-dir DIR]
"""

from __future__ import annotations

import argparse
import datetime
import io
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import time
from pathlib import Path

import numpy as np

from checkout import add_output_args, commit_label, results_dir  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
#: The reference: every depth at tol 1e-9 (at 1e-10 a state costs ~10x: 3-10 s and 5000-7000 nodes
#: on the base curve, 30 s and a failure at 30000 nodes at delta 0.49); every CHECK_EVERY-th
#: depth also at 1e-10 (base: the two agree to ~1e-12 relative)
REF_TOL, CHECK_TOL, CHECK_EVERY, REF_MAX_NODES = 1e-9, 1e-10, 12, 30000
DELTAS40 = np.linspace(0.0125, 0.5, 40)
#: F errors ~3e-7, ~1e-8, ~4e-8 and ~2e-9 on base (work_precision.md, shooting.md): the loosest that
#: still reaches the collocation curve's error is the one compared, so looser ones are tried too
SHOOT_RTOLS = (1e-6, 1e-7, 1e-8, 1e-9)
SHOOT_FROM = 0.15  # shooting solves single caps: from where every preset's curve is a cap
#: depths closer than this (relative) are one state to shooting and the same-states curves: the
#: curves' depths agree to ~1e-10 where they are the same point; their real spacing is ~1e-2
SAME_STATE_RTOL = 1e-7
#: collocation tolerances of the curves through shooting's states: each side at its cheapest setting
#: that reaches the other's error (1e-6, the default, first: the rows compared at default settings)
SAME_TOLS = (1e-6, 1e-5, 1e-4)

#: (id, preset, kind): the curves compared
CASES = [("base default", "base", "default"), ("base 40 depths", "base", "deltas40"),
         ("base 40 depths, cap only", "base", "deltas40-cap")] + [
    (f"{p} default", p, "default") for p in ("base-xi0", "prolate2", "fit", "flat", "gent1", "dome")]

#: variant -> (side, patches {module: {attribute: value}} (for "shellbvp.config": the options),
#: curve keyword arguments, environment).
#: This commit runs with the numpy functions (SHELLBVP_KERNELS=numpy: the reference, and what
#: the ablations switch changes off from) and with numba's compiled kernels (compiled while
#: warming, not timed); the baseline has no compiled kernels.
NUMPY, NUMBA = {"SHELLBVP_KERNELS": "numpy"}, {"SHELLBVP_KERNELS": "numba"}
VARIANTS = {
    "baseline": ("old", {}, {}, {}),
    "this commit": ("new", {}, {}, NUMPY),
    "this commit, numba": ("new", {}, {}, NUMBA),
    "cold lift-off": ("new", {"shellbvp.config": {"warm_first": False}}, {}, NUMPY),
    "no secant guard": ("new", {"shellbvp.config": {"secant_max_ln_sc": math.inf}}, {}, NUMPY),
    "full Richardson": ("new", {}, {"estimate_error": "full"}, NUMPY),
    "no split rule": ("new", {"shellbvp.config": {"split_rule": False}}, {}, NUMPY),
    "annulus before split": ("new", {"shellbvp.config": {"split_first": False}}, {}, NUMPY),
    "no tightening": ("new", {"shellbvp.config": {"tighten": False}}, {}, NUMPY),
    "thinned warm meshes": ("new", {"shellbvp.config": {"equidistribute": False}}, {}, NUMPY),
    "explicit zeros kept": ("new", {"shellbvp.config": {"collocation": False}}, {}, NUMPY),
    "explicit zeros kept, numba": ("new", {"shellbvp.config": {"collocation": False}}, {}, NUMBA),
    "SuperLU, numba": ("new", {"shellbvp.config": {"compiled_elimination": False}}, {}, NUMBA),
}

#: variant -> the curves it runs on (each change switched off where it acts; the others run everywhere)
ABLATIONS = {
    "cold lift-off": ("base default", "base 40 depths"),
    "no secant guard": ("base default", "base 40 depths", "base 40 depths, cap only"),
    "full Richardson": ("base default", "base 40 depths", "base 40 depths, cap only"),
    "no split rule": ("base default", "base 40 depths"),
    "annulus before split": ("base 40 depths",),
    "no tightening": ("base default", "fit default", "flat default"),
    "thinned warm meshes": ("base default", "base 40 depths", "base 40 depths, cap only"),
    "explicit zeros kept": ("base default", "base 40 depths", "base 40 depths, cap only"),
    "explicit zeros kept, numba": ("base default", "base 40 depths", "base 40 depths, cap only"),
    "SuperLU, numba": ("base default", "base 40 depths", "base 40 depths, cap only"),
}


# ---------------------------------------------------------------------------------------------
# the worker: one curve in a fresh process
# ---------------------------------------------------------------------------------------------
def _curve_kwargs(kind):
    if kind == "default":
        return {}
    if kind == "deltas40":
        return {"deltas": DELTAS40}
    if kind == "deltas40-cap":
        return {"deltas": DELTAS40, "topology": "cap"}
    if kind == "same-states":  # shooting's states: their depths come in the spec's curve_kw
        return {"topology": "cap"}
    raise ValueError(f"unknown curve kind {kind!r}")


def worker(spec):
    """Run one curve as ``spec`` says; print one JSON line of measurements."""
    import importlib

    import scipy.integrate

    # what solve_bvp's first run imports (scipy.interpolate, for its PPoly): a cost of the
    # process, like importing scipy.integrate, not of the curve; timed apart (~25-30 ms, each side)
    t0 = time.perf_counter()
    import scipy.interpolate  # noqa: F401

    interpolate_import = time.perf_counter() - t0

    import shellbvp as sb

    import sys as _sys

    counts = dict(calls=0, niter=0, richardson=0, failed=0, max_nodes=0, fixed_mesh=0)
    orig = scipy.integrate.solve_bvp

    def counted(*args, **kw):
        # a Richardson estimate is one Newton iteration on the halved mesh, whose status is
        # "too many nodes" by design: counted apart, not as a failure
        f, richardson = _sys._getframe(1), False
        while f is not None and not richardson:
            richardson, f = f.f_code.co_name == "richardson_error", f.f_back
        counts["calls"] += 1
        counts["richardson"] += int(richardson)
        try:
            r = orig(*args, **kw)
        except Exception:  # a run the package's guards end from inside (a Jacobian overflowing: status 2)
            counts["failed"] += int(not richardson)
            raise
        counts["niter"] += int(r.niter)
        counts["failed"] += int(not r.success and not richardson)
        counts["max_nodes"] = max(counts["max_nodes"], int(r.x.size))
        return r

    # Richardson estimates since 425cc53: a Newton on the fixed halved mesh, solve_bvp only
    # where that does not converge; counted as runs too (one Newton iteration each)
    from shellbvp import collocation as _collocation

    fixed_mesh = getattr(_collocation, "newton_on_mesh", None)

    def counted_fixed_mesh(*args, **kw):
        r = fixed_mesh(*args, **kw)
        counts["calls"] += 1
        counts["niter"] += 1
        counts["richardson"] += 1
        counts["fixed_mesh"] += 1
        counts["max_nodes"] = max(counts["max_nodes"], int(np.size(args[4])))
        return r

    if fixed_mesh is not None:
        _collocation.newton_on_mesh = counted_fixed_mesh
    scene = sb.Scene.preset(spec["preset"])
    scene.model()  # the cached generated code: loaded, not timed
    kernel_load = 0.0
    if os.environ.get("SHELLBVP_KERNELS") == "numba":  # numba's compiled kernels: loaded from its cache,
        from shellbvp.kernels import kernel_set          # timed apart (once per process and structure)

        t0 = time.perf_counter()
        kernel_set(scene.model(), scene.structure)
        kernel_load = time.perf_counter() - t0
    for module, attrs in spec["patches"].items():
        m = importlib.import_module(module)
        m = m.OPTIONS if module == "shellbvp.config" else m  # the package's options object
        for name, value in attrs.items():
            if not hasattr(m, name):
                raise SystemExit(f"{module} has no {name}: this variant does not apply to this tree")
            setattr(m, name, value)
    kw = dict(_curve_kwargs(spec["kind"]), **spec["curve_kw"])
    scipy.integrate.solve_bvp = counted
    t0, c0 = time.perf_counter(), time.process_time()
    c = sb.curve(scene, **kw)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    scipy.integrate.solve_bvp = orig
    first_cpu = None
    if spec["kind"] == "same-states" and kw.get("deltas"):
        # the first point alone (its cold solve and estimate), after the curve: what the curve's
        # time per point of the continuation leaves out -- shooting starts from the reference's
        # own unknowns.  In this warmer process it costs at most what it cost in the curve.
        c0 = time.process_time()
        sb.curve(scene, **dict(kw, deltas=list(kw["deltas"])[:1]))
        first_cpu = time.process_time() - c0
    sols = getattr(c, "solutions", None) or []
    out = dict(wall=wall, cpu=cpu, points=len(c), stop=c.stop_reason, complete=bool(c.complete),
               delta=[float(v) for v in c.delta], force=[float(v) for v in c.force],
               topology=[str(getattr(s, "topology", "cap")) for s in sols] or ["cap"] * len(c),
               valid=[bool(v) for v in c.valid], nodes=[int(v) for v in c.points["nodes"]],
               shellbvp=str(Path(sb.__file__).parent), kernel_load_s=kernel_load,
               interpolate_import_s=interpolate_import, first_point_cpu=first_cpu, **counts)
    print(json.dumps(out))


# ---------------------------------------------------------------------------------------------
# the driver
# ---------------------------------------------------------------------------------------------
def extract(commit, dest: Path) -> str:
    """``git archive`` of ``commit`` into ``dest`` (once); returns the full hash."""
    full = subprocess.run(["git", "rev-parse", commit], cwd=REPO, capture_output=True, text=True,
                          check=True).stdout.strip()
    stamp = dest / ".commit"
    if not (stamp.exists() and stamp.read_text() == full):
        dest.mkdir(parents=True, exist_ok=True)
        tar = subprocess.run(["git", "archive", "--format=tar", full], cwd=REPO, capture_output=True,
                             check=True).stdout
        with tarfile.open(fileobj=io.BytesIO(tar)) as t:
            t.extractall(dest, filter="data")
        stamp.write_text(full)
    return full


class Sides:
    def __init__(self, work: Path, old_tree: Path):
        self.trees = {"old": old_tree, "new": REPO}
        self.caches = {side: work / f"cache-{side}" for side in self.trees}

    def env(self, side, extra=None):
        # one BLAS thread: OpenBLAS's threads spin while they wait, which CPU time would count as work
        # (the baseline's big meshes ran two: 19.5 s CPU in 13.7 s wall)
        env = dict(os.environ, PYTHONPATH=str(self.trees[side]), XDG_CACHE_HOME=str(self.caches[side]),
                   SHELLBVP_CACHE_DIR=str(self.caches[side] / "shellbvp"), PYTHONHASHSEED="0",
                   OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", **(extra or {}))
        env.pop("PYTHONSTARTUP", None)
        return env

    def run(self, variant, case, curve_kw=None):
        side, patches, kw, extra = VARIANTS[variant]
        _, preset, kind = case
        spec = dict(preset=preset, kind=kind, patches=patches, curve_kw=dict(kw, **(curve_kw or {})))
        r = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", json.dumps(spec)],
                           env=self.env(side, extra), capture_output=True, text=True, cwd=str(self.trees[side]))
        if r.returncode != 0:
            raise RuntimeError(f"{variant} / {case[0]} failed:\n{r.stderr[-3000:]}")
        out = json.loads(r.stdout.strip().splitlines()[-1])
        if Path(out["shellbvp"]).resolve().parent != self.trees[side].resolve():
            raise RuntimeError(f"{variant} imported {out['shellbvp']}, not the {side} tree")
        return out

    def warm(self, presets, log, numba=False):
        """Generate every structure's code into each side's cache, and on this commit's side
        compile numba's kernels (a solve with SHELLBVP_KERNELS=numba compiles them first); not timed."""
        code = "import sys, shellbvp as sb\nfor p in sys.argv[1:]: sb.Scene.preset(p).model()"
        kernels = ("import sys, shellbvp as sb\nfor p in sys.argv[1:]: "
                   "sb.solve(sb.Scene.preset(p), delta=0.1, estimate_error=False)")
        for side in self.trees:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code, *presets], env=self.env(side), check=True,
                           cwd=str(self.trees[side]))
            if side == "new" and numba:
                subprocess.run([sys.executable, "-c", kernels, *presets], env=self.env(side, NUMBA), check=True,
                               cwd=str(self.trees[side]))
            log(f"code cache of the {side} side ready in {time.perf_counter() - t0:.0f} s")


def _tight(scene, state, tol):
    """``state`` solved again at ``tol``, same depth and topology, warm from it."""
    import shellbvp as sb
    from shellbvp.pointload import solve_point_load
    from shellbvp.state import TOPOLOGIES

    top = getattr(state, "topology", "cap")
    if top == "point":
        return solve_point_load(scene, float(state.delta), tol=tol, max_nodes=REF_MAX_NODES, guess=state)
    return sb.solve(scene, delta=float(state.delta), tol=tol, guess=state, max_nodes=REF_MAX_NODES,
                    estimate_error=False, topology=top if top in TOPOLOGIES else "auto")


def reference(preset, deltas, topology, log, quick=False):
    """F at each depth solved at tol REF_TOL, each state warm from the state of the same
    topology at that depth on a tol-1e-6 curve through the same depths (as work_precision.py
    does); every CHECK_EVERY-th depth also at CHECK_TOL, to show the reference's own error.
    With each state's topology, lambda0 and, for caps, shooting's unknowns (Sc, u = rQ(Sc+))."""
    import shellbvp as sb

    t0 = time.perf_counter()
    scene = sb.Scene.preset(preset)
    c = sb.curve(scene, deltas=deltas, estimate_error=False, topology=topology)
    ref = dict(delta=[], force=[], lambda0=[], topology=[], start=[], nodes=[], check=[])
    for i, s in enumerate(c.solutions):
        r = _tight(scene, s, REF_TOL)
        ok = bool(r.success)
        ref["delta"].append(float(s.delta))
        ref["force"].append(float(r.force) if ok else math.nan)
        ref["lambda0"].append(float(r.lambda0) if ok else math.nan)
        ref["topology"].append(str(getattr(r, "topology", "cap")) if ok else "failed")
        ref["nodes"].append(int(r.nodes))
        is_cap = ok and getattr(r, "topology", "cap") == "cap" and r.y.shape[0] == 8
        ref["start"].append(dict(Sc=float(r.Sc), u=float(r.y[6, 0])) if is_cap else None)
        if ok and not quick and i % CHECK_EVERY == 0:
            t = _tight(scene, r, CHECK_TOL)
            ref["check"].append(dict(delta=float(s.delta), topology=ref["topology"][-1], converged=bool(t.success),
                                     rel=abs(t.force - r.force) / abs(r.force) if t.success else math.nan))
    ref.update(complete=bool(c.complete), stop=c.stop_reason, seconds=time.perf_counter() - t0)
    rels = [ch["rel"] for ch in ref["check"] if ch["converged"]]
    log(f"  reference {preset} ({topology}) at tol {REF_TOL:g}: {len(ref['delta'])} depths, "
        f"{sum(t != 'failed' for t in ref['topology'])} converged, max nodes {max(ref['nodes'], default=0)}; "
        f"tol {CHECK_TOL:g} at {len(rels)}/{len(ref['check'])} of them: max |dF|/F {max(rels, default=math.nan):.1e}; "
        f"{ref['seconds']:.0f} s")
    return ref


def _distinct(depths):
    """The depths sorted, without repeats closer than 1e-12 relative."""
    d = np.sort(np.asarray(depths, float))
    return d[np.r_[True, np.diff(d) > 1e-12 * (1 + d[1:])]]


def f_error(run, ref):
    """Largest relative F error of a curve against the reference, over the points where the
    reference has a state of the same topology at the same depth (compared, left out)."""
    rd = np.asarray(ref["delta"])
    worst, compared, left = 0.0, 0, 0
    for d, F, top in zip(run["delta"], run["force"], run["topology"]):
        i = int(np.argmin(np.abs(rd - d))) if rd.size else -1
        if i < 0 or abs(rd[i] - d) > 1e-12 * (1 + d) or ref["topology"][i] != top or not math.isfinite(ref["force"][i]):
            left += 1
            continue
        worst = max(worst, abs(F - ref["force"][i]) / abs(ref["force"][i]))
        compared += 1
    return (worst if compared else math.nan), compared, left


def shooting_states(ref):
    """Indices of the reference's states that shooting solves: caps with delta >= SHOOT_FROM, each
    more than SAME_STATE_RTOL deeper than the one before (the reference's depths are the union of
    the curves' depths, where the same point of two curves can differ by ~1e-10: before 695242b
    half the states of some presets were such pairs, one shot each for shooting's Newton, which
    accepts its predictor there, and a whole solve_bvp run each for collocation)."""
    out, last = [], -math.inf
    for i, (d, s) in enumerate(zip(ref["delta"], ref["start"])):
        if s is not None and d >= SHOOT_FROM and d - last > SAME_STATE_RTOL * abs(d):
            out.append(i)
            last = d
    return out


def same_states_and_shooting(sides, entry, variants, repeat, shoot, log):
    """This commit's cap-only curve through exactly shooting's states (their depths, each from its
    neighbour by natural continuation, error estimates as by default; the first point's cold
    solve counted, which shooting's is not), at each of SAME_TOLS, and (``shoot``) shooting at
    those states (:func:`shooting`), interleaved: each of ``repeat`` rounds runs every
    collocation curve, then shooting at every rtol, so that both sides' medians sample the same
    stretch of a shared machine's load (before 425cc53 shooting ran once, apart).

    Returns (per variant: CPU ms per point and max F error at the default tol, and the same per
    tol (``tols``); shooting's rows, per rtol the median CPU time over rounds, [] without
    ``shoot``)."""
    ref = entry["_ref"]
    depths = [ref["delta"][i] for i in shooting_states(ref)]
    if not depths:
        return {}, []
    runs = {(v, tol): [] for v in variants for tol in SAME_TOLS}
    shots = []
    for rnd in range(repeat):
        for v in variants:
            for tol in SAME_TOLS:
                runs[v, tol].append(sides.run(v, (entry["id"], entry["preset"], "same-states"),
                                              {"deltas": depths, "tol": tol}))
        if shoot:
            shots.append(shooting(entry["preset"], ref, lambda msg: log(f"round {rnd + 1}: {msg}")))
    out = {}
    for v in variants:
        rows = []
        for tol in SAME_TOLS:
            rs = runs[v, tol]
            err, compared, left = f_error(rs[0], ref)
            cpu = statistics.median(r["cpu"] for r in rs)
            rows.append(dict(tol=tol, points=rs[0]["points"], depths=len(depths), cpu_median=cpu, f_error=err,
                             compared=compared, left_out=left, ms_per_point=1e3 * cpu / max(rs[0]["points"], 1),
                             stop=rs[0]["stop"], complete=rs[0]["complete"], cpu_runs=[r["cpu"] for r in rs],
                             continuation_ms_per_point=_continuation_ms(rs)))
            log(f"  same states {entry['preset']} | {v} | tol {tol:g}: {rows[-1]['points']} points, "
                f"{rows[-1]['ms_per_point']:.1f} ms/point, max F error {err:.1e}")
        out[v] = dict(rows[0], tols=rows)
    return out, _median_shots(shots)


def _continuation_ms(runs):
    """CPU ms per point of a same-states curve after its first point (the median over the runs of
    the curve's time less its first point's, timed alone after it), or None."""
    n = runs[0]["points"]
    if n < 2 or any(r.get("first_point_cpu") is None for r in runs):
        return None
    return 1e3 * statistics.median(r["cpu"] - r["first_point_cpu"] for r in runs) / (n - 1)


def _median_shots(shots):
    """Shooting's rows of several rounds as one: per rtol, the median CPU and wall time (the
    states, convergence and errors are the same in every round)."""
    if not shots:
        return []
    rows = []
    for per_round in zip(*shots):
        row = dict(per_round[0])
        row["cpu"] = statistics.median(r["cpu"] for r in per_round)
        row["wall"] = statistics.median(r["wall"] for r in per_round)
        row["per_point_ms"] = 1e3 * row["cpu"] / row["points"]
        row["cpu_runs"] = [r["cpu"] for r in per_round]
        row["same_every_round"] = len({(r["converged"], r["max_rel"]) for r in per_round}) == 1
        rows.append(row)
    return rows


def equal_error(case, variant):
    """Per shooting rtol that converged at every state: (rtol, its ms/point and F error, the
    cheapest collocation tol on the same states at least as accurate, its ms/point, the ratio);
    the collocation cells None where no tol measured is that accurate."""
    same = (case.get("same_states") or {}).get(variant)
    if not same:
        return []
    tols = [t for t in same.get("tols", [same]) if t.get("complete", True) and t["compared"] == t["depths"]
            and math.isfinite(t["f_error"])]
    out = []
    for s in case["shooting"]:
        if s["converged"] != s["points"] or not math.isfinite(s["max_rel"]):
            continue
        good = [t for t in tols if t["f_error"] <= s["max_rel"]]
        best = min(good, key=lambda t: t["ms_per_point"]) if good else None
        out.append(dict(rtol=s["rtol"], shooting_ms=s["per_point_ms"], shooting_error=s["max_rel"],
                        tol=best and best.get("tol", SAME_TOLS[0]), ms=best and best["ms_per_point"],
                        error=best and best["f_error"],
                        ratio=best and s["per_point_ms"] / best["ms_per_point"]))
    return out


def shooting(preset, ref, log):
    """Shooting at the reference's cap states with delta >= SHOOT_FROM: per rtol, its time
    per point and max relative F error (at equal lambda0)."""
    sys.path.insert(0, str(HERE))
    from shooting import shoot_curve

    import shellbvp as sb

    idx = shooting_states(ref)
    if not idx:
        return []
    lam = np.array([ref["lambda0"][i] for i in idx])
    Fref = np.array([ref["force"][i] for i in idx])
    start = ref["start"][idx[0]]
    rows = []
    for rtol in SHOOT_RTOLS:
        t0, c0 = time.perf_counter(), time.process_time()
        sc = shoot_curve(sb.Scene.preset(preset), lam, rtol=rtol, guess=(start["Sc"], start["u"]))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        ok = np.asarray(sc.success, bool)
        F = np.asarray(sc.F, float)
        err = np.abs(F[ok] - Fref[ok]) / np.abs(Fref[ok])
        rows.append(dict(rtol=rtol, points=int(lam.size), converged=int(ok.sum()), wall=wall, cpu=cpu,
                         per_point_ms=1e3 * cpu / lam.size, max_rel=float(err.max()) if err.size else math.nan))
        log(f"  shooting {preset} rtol {rtol:g}: {rows[-1]['converged']}/{lam.size} converged, "
            f"max F error {rows[-1]['max_rel']:.1e}, {rows[-1]['per_point_ms']:.0f} ms/point")
    return rows


def _median_ratio(num, den):
    r = [a / b for a, b in zip(num, den) if b > 0]
    return statistics.median(r) if r else math.nan


def summarize(data):
    """Per case and variant: medians, counts, errors, ratios to this commit (in place)."""
    for case in data["cases"]:
        runs = case["runs"]
        new = runs["this commit"]
        for variant, rs in runs.items():
            first = rs[0]
            case.setdefault("rows", {})[variant] = dict(
                wall_median=statistics.median(r["wall"] for r in rs), wall_min=min(r["wall"] for r in rs),
                cpu_median=statistics.median(r["cpu"] for r in rs),
                cpu_vs_this=_median_ratio([r["cpu"] for r in rs], [r["cpu"] for r in new]),
                repeats=len(rs), points=first["points"], calls=first["calls"], niter=first["niter"],
                failed=first["failed"], richardson=first["richardson"], max_nodes=first["max_nodes"],
                stop=first["stop"],
                f_error=first.get("f_error"), compared=first.get("compared"), left_out=first.get("left_out"),
                calls_per_point=first["calls"] / max(first["points"], 1),
                ms_per_point=1e3 * statistics.median(r["cpu"] for r in rs) / max(first["points"], 1),
                time_vs_this=_median_ratio([r["wall"] for r in rs], [r["wall"] for r in new]),
                deterministic_counts=len({(r["calls"], r["niter"]) for r in rs}) == 1)
    return data


def _fmt(v, f=".2f"):
    return "–" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, f)


def _kernel_load(data):
    loads = [r.get("kernel_load_s", 0.0) for c in data["cases"] for r in c["runs"].get("this commit, numba", [])]
    return f"median {statistics.median(loads):.2f} s, at most {max(loads):.2f} s" if loads else "not run"


def _interpolate_import(data):
    times = [r["interpolate_import_s"] for c in data["cases"] for runs in c["runs"].values() for r in runs
             if "interpolate_import_s" in r]
    return f"median {1e3 * statistics.median(times):.0f} ms" if times else "not recorded"


def _check_text(data):
    checks = [ch for c in data["cases"] for ch in c.get("reference", {}).get("check", [])]
    ok = [ch["rel"] for ch in checks if ch["converged"]]
    if not checks:
        return f"not checked at tol {CHECK_TOL:g}"
    return (f"every {CHECK_EVERY}th reference depth also at tol {CHECK_TOL:g}: {len(ok)} of {len(checks)} "
            f"converged, F differs by at most {max(ok, default=math.nan):.1e} relative")


def markdown(data):
    m = data["meta"]
    same = ("are the same in every repeat" if all(r["deterministic_counts"] for c in data["cases"]
                                                for r in c["rows"].values()) else
            "differ between repeats in some rows (deterministic_counts in the JSON)")
    lines = [f"Measured {m['date']} on {m['machine']} ({m.get('cpu', 'processor not recorded')}; {m['cpus']} cores, "
             f"shared), Python {m['python']}, "
             f"NumPy {m['numpy']}, SciPy {m['scipy']}: this commit ({m['this_commit']}) against the baseline "
             f"{m['baseline'][:7]}, each curve a fresh process with a warm code cache (its own per side), "
             f"{m['repeat']} repeats alternating the variants; this commit with the numpy functions "
             f"(SHELLBVP_KERNELS=numpy; every ablation too) and with numba's compiled kernels (compiled "
             f"beforehand; loaded from numba's cache before the curve is timed, once per process and "
             f"structure: {_kernel_load(data)}); scipy.integrate and scipy.interpolate (which solve_bvp's "
             f"first run imports) imported before the curve is timed, on both sides (scipy.interpolate: "
             f"{_interpolate_import(data)}); time: median over repeats of the curve's CPU time "
             f"(the process's, the measure least disturbed by other users of a shared machine) and wall time; "
             f"ratio: median over repeats of (variant time / this commit's time in the same repeat); speed-ups "
             f"and per-point times use CPU time; counts (runs: solve_bvp runs and, since 425cc53, "
             f"fixed-mesh Newton runs; of them Richardson estimates (one Newton run on the halved mesh: at the "
             f"baseline a solve_bvp run, 'too many nodes' by design; now a fixed-mesh Newton, solve_bvp where "
             f"that does not converge); failed runs other than those; Newton iterations (solve_bvp's outer "
             f"iterations, 1 per fixed-mesh run); largest mesh) "
             f"{same}; F error: max relative error "
             f"against states solved at tol {REF_TOL:g} at the same depths (points of another topology than the "
             f"reference's left out; {_check_text(data)}). Total {m['total_s']:.0f} s.", ""]
    variants = list(VARIANTS)
    lines += ["| curve | variant | CPU time (s) | x this commit | wall time (s) | x this commit | points | "
              "runs (Richardson) | failed | Newton its | max nodes | CPU ms/point | "
              "max F error (compared/left out) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for case in data["cases"]:
        for v in variants:
            r = case["rows"].get(v)
            if r is None:
                continue
            lines.append(f"| {case['id']} | {v} | {_fmt(r['cpu_median'])} | {_fmt(r['cpu_vs_this'])} | "
                         f"{_fmt(r['wall_median'])} | {_fmt(r['time_vs_this'])} | "
                         f"{r['points']} | {r['calls']} ({r['richardson']}) | {r['failed']} | {r['niter']} | "
                         f"{r['max_nodes']} | "
                         f"{_fmt(r['ms_per_point'], '.0f')} | {_fmt(r['f_error'], '.1e')} "
                         f"({r['compared']}/{r['left_out']}) |")
    lines.append("")
    sh = [c for c in data["cases"] if c.get("shooting")]
    if sh:
        lines += ["Shooting (the paper's method, `benchmarks/shooting.py`) on the reference's cap states "
                  f"with delta >= {SHOOT_FROM}, each from its neighbour (tangent predictor; no cold start "
                  "counted), per point, against three collocation measures: this commit's default curve per "
                  "point (lift-off states, switches and the small-delta leg included, which shooting does not "
                  "solve), this commit's cap-only curve through exactly shooting's states (their depths, "
                  "natural continuation, error estimates as by default, its cold first point counted), and "
                  "the same after its first point ('continuation'). "
                  "Shooting and the cap-only curves run interleaved, in rounds (each round every collocation "
                  "curve, then shooting at every rtol), and each side's time is the median over the rounds. "
                  "'equal error': the loosest shooting rtol whose max F error is at most the collocation "
                  "run's; ratio: shooting's CPU ms/point over collocation's. 'continuation': the same-states "
                  "curve's time less its first point's (that point's curve timed alone after it, in the same "
                  "process), per point after the first, against shooting's time per point over all its "
                  f"states. States closer than {SAME_STATE_RTOL:g} in delta (relative) count once (the "
                  "curves' depths agree to ~1e-10 where they are the same point).", "",
                  "| preset | shooting rtol: CPU ms/point (max F error, converged) | default curve: ms/point "
                  "(F error): ratio, numpy | the same, numba | same states: ms/point (F error): ratio, numpy "
                  "| the same, numba | continuation: ms/point: ratio, numpy | the same, numba |",
                  "|---|---|---|---|---|---|---|---|"]
        if data.get("shooting_from"):
            sf = data["shooting_from"]
            lines[-2:-2] = [f"Shooting's rows of {', '.join(sf.get('presets') or ['every preset'])} are from the "
                            f"run at {sf['commit']} (measured {sf['date']}; `benchmarks/shooting.py` unchanged since), "
                            f"not measured again in this run; the collocation side is this run's.", ""]

        def cell(r, case, key, per="ms_per_point"):
            if r is None or r.get(per) is None:
                return "–"
            ratio = case.get(key)
            text = ("no shooting rtol converged everywhere" if ratio is None else
                    f">= {ratio:.1f}x (no shooting rtol as accurate)" if case.get(key + "_bound") else f"{ratio:.1f}x")
            if per != "ms_per_point":
                return f"{r[per]:.1f}: {text}"
            return f"{r['ms_per_point']:.1f} ({_fmt(r['f_error'], '.0e')}): {text}"

        cont = "continuation_ms_per_point"
        for case in sh:
            shots = "; ".join(f"{s['rtol']:g}: {s['per_point_ms']:.0f} ({_fmt(s['max_rel'], '.0e')}, "
                              f"{s['converged']}/{s['points']})" for s in case["shooting"])
            same = case.get("same_states") or {}
            lines.append(f"| {case['preset']} | {shots} | "
                         f"{cell(case['rows'].get('this commit'), case, 'shooting_ratio')} | "
                         f"{cell(case['rows'].get('this commit, numba'), case, 'shooting_ratio_numba')} | "
                         f"{cell(same.get('this commit'), case, 'shooting_ratio_same')} | "
                         f"{cell(same.get('this commit, numba'), case, 'shooting_ratio_numba_same')} | "
                         f"{cell(same.get('this commit'), case, 'shooting_ratio_same_cont', cont)} | "
                         f"{cell(same.get('this commit, numba'), case, 'shooting_ratio_numba_same_cont', cont)} |")
        lines.append("")
        lines += ["Equal error both ways, on the same cap states: for each shooting rtol that converged at "
                  "every state, the cheapest collocation tol (of " + ", ".join(f"{t:g}" for t in SAME_TOLS) +
                  ") whose F error is at most shooting's, and shooting's CPU ms/point over collocation's; "
                  "'smallest' is the least favourable of them to collocation.", "",
                  "| preset | kernels | shooting rtol (F error): collocation tol (F error, ms/point): ratio | "
                  "smallest |", "|---|---|---|---|"]
        for case in sh:
            for v, key, label in (("this commit", "shooting_ratio", "numpy"),
                                  ("this commit, numba", "shooting_ratio_numba", "numba")):
                pairs = case.get(key + "_pairs") or []
                if not pairs:
                    continue
                cells = "; ".join(
                    f"{q['rtol']:g} ({q['shooting_error']:.0e}): " +
                    (f"{q['tol']:g} ({q['error']:.0e}, {q['ms']:.1f}): {q['ratio']:.1f}x" if q["ratio"] is not None
                     else "no tol as accurate") for q in pairs)
                both = case.get(key + "_both")
                lines.append(f"| {case['preset']} | {label} | {cells} | {_fmt(both, '.1f') + 'x' if both else '–'} |")
        lines.append("")
    lines += ["| target (issue 14) | measured | met |", "|---|---|---|"]
    for t in data["targets"]:
        lines.append(f"| {t['target']} | {t['measured']} | {t['met']} |")
    return "\n".join(lines) + "\n"


def targets(data):
    cases = {c["id"]: c for c in data["cases"]}
    out = []

    def speedup(case, variant):
        """Median over repeats of baseline CPU time / ``variant``'s in the same repeat."""
        runs = case["runs"]
        if variant not in runs:
            return math.nan
        return _median_ratio([r["cpu"] for r in runs["baseline"]], [r["cpu"] for r in runs[variant]])

    def ratio_target(case_id, want, text):
        if case_id not in cases:
            return
        case, parts, met = cases[case_id], [], False
        for variant, label in (("this commit", "numpy"), ("this commit, numba", "numba kernels")):
            r = case["rows"].get(variant)
            if r is None:
                continue
            speed, err = speedup(case, variant), r["f_error"]
            parts.append(f"{label}: {speed:.2f}x CPU time ({case['rows']['baseline']['cpu_median']:.2f} s -> "
                         f"{r['cpu_median']:.2f} s), max F error {_fmt(err, '.1e')}")
            met |= speed >= want and (err is None or err <= 1e-6)
        base = case["rows"]["baseline"]
        caveat = (f" (the baseline's time includes its {base['failed']} failed solve_bvp runs; largest mesh "
                  f"{base['max_nodes']} nodes)" if base["failed"] else "")
        out.append(dict(target=text, measured="; ".join(parts) + caveat, met="yes" if met else "no"))

    ratio_target("base default", 5, "default base curve to delta 0.5, F error <= 1e-6: >= 5x faster than the baseline")
    ratio_target("base 40 depths", 8, "40-depth curve with lift-off: >= 8x")
    ratio_target("base 40 depths, cap only", 2.5, "cap-only 40-depth curve: >= 2.5x")
    for suffix, _, _, what in SHOOTING_MEASURES:
        for key, label in (("shooting_ratio", "numpy"), ("shooting_ratio_numba", "numba kernels")):
            eqs = [c[key + suffix] for c in data["cases"] if c.get(key + suffix) is not None]
            bounds = sum(bool(c.get(key + suffix + "_bound")) for c in data["cases"] if c.get(key + suffix) is not None)
            if eqs:
                note = f"; {bounds} of them lower bounds (no shooting rtol as accurate)" if bounds else ""
                out.append(dict(target=f">= 40x faster than shooting at equal or better F error, {what} ({label})",
                                measured=f"median {statistics.median(eqs):.1f}x ({min(eqs):.1f}x–{max(eqs):.1f}x "
                                         f"over {len(eqs)} presets{note})", met="yes" if min(eqs) >= 40 else
                                ("at the median, not on every preset" if statistics.median(eqs) >= 40 else "no")))
    for key, label in (("shooting_ratio", "numpy"), ("shooting_ratio_numba", "numba kernels")):
        eqs = [c[key + "_both"] for c in data["cases"] if c.get(key + "_both") is not None]
        missing = sum(1 for c in data["cases"] if c.get(key + "_both") is not None and c.get(key + "_both_missing"))
        if eqs:
            note = (f"; on {missing} of them a shooting rtol more accurate than every collocation tol measured is "
                    f"left out" if missing else "")
            out.append(dict(target=f">= 40x faster than shooting at equal or better F error, per point, on the same "
                                   f"cap states, each at its cheapest setting, at every accuracy both reached "
                                   f"({label})",
                            measured=f"median {statistics.median(eqs):.1f}x ({min(eqs):.1f}x–{max(eqs):.1f}x over "
                                     f"{len(eqs)} presets{note})", met="yes" if min(eqs) >= 40 else
                            ("at the median, not on every preset" if statistics.median(eqs) >= 40 else "no")))
    return out


def shooting_ratio(case, variant="this commit", same=False, per="ms_per_point"):
    """(ratio, lower bound?): shooting's CPU time per point at its loosest rtol whose F error is at
    most collocation's, over collocation's -- per point of the default curve, or (``same``) of the
    cap-only curve through shooting's own states (``per="continuation_ms_per_point"``: after its
    first point; shooting's time stays its total over all its states, its first one included);
    where no rtol measured is that accurate, its most accurate one's time, a lower bound
    (shooting's time grows as its rtol tightens); (None, False) without a collocation run or a
    shooting rtol that converged everywhere."""
    r = (case.get("same_states") or {}).get(variant) if same else case["rows"].get(variant)
    if r is None or r.get("f_error") is None or not math.isfinite(r["f_error"]) or not r.get(per):
        return None, False
    converged = [s for s in case["shooting"] if s["converged"] == s["points"] and math.isfinite(s["max_rel"])]
    good = [s for s in converged if s["max_rel"] <= r["f_error"]]
    if good:
        return min(s["per_point_ms"] for s in good) / r[per], False
    if not converged:
        return None, False
    return min(converged, key=lambda s: s["max_rel"])["per_point_ms"] / r[per], True


#: the per-point measures against shooting: (suffix of the entry's keys, on the same states?,
#: collocation's time per point, what the targets' rows call it)
SHOOTING_MEASURES = (("", False, "ms_per_point", "per point of the default curve"),
                     ("_same", True, "ms_per_point", "per point, on the same cap states"),
                     ("_same_cont", True, "continuation_ms_per_point",
                      "per point, on the same cap states, collocation's cold first point left out as "
                      "shooting's is"))


def ratios(entry):
    """Set the entry's shooting ratios (and whether each is a lower bound) from its rows, and the
    equal-error pairs both ways with their smallest ratio (``_both``: over every accuracy shooting
    reached, the least favourable to collocation)."""
    for v, key in (("this commit", "shooting_ratio"), ("this commit, numba", "shooting_ratio_numba")):
        for suffix, same, per, _ in SHOOTING_MEASURES:
            entry[key + suffix], entry[key + suffix + "_bound"] = shooting_ratio(entry, v, same, per)
        pairs = equal_error(entry, v)
        entry[key + "_pairs"] = pairs
        found = [q["ratio"] for q in pairs if q["ratio"] is not None]
        entry[key + "_both"] = min(found) if found else None
        entry[key + "_both_missing"] = len(pairs) - len(found)  # shooting rtols no collocation tol matched


def this_commit():
    return commit_label(REPO, "")


def cpu_model() -> str:
    """The processor's model name and its widest vector extension (from /proc/cpuinfo, if any):
    rounding, and with it the path of a fragile continuation, can differ between machines."""
    try:
        info = Path("/proc/cpuinfo").read_text()
    except OSError:
        return platform.processor() or "unknown"
    name = next((ln.split(":", 1)[1].strip() for ln in info.splitlines() if ln.startswith("model name")), "unknown")
    flags = next((ln.split(":", 1)[1].split() for ln in info.splitlines() if ln.startswith("flags")), [])
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "no AVX2"
    return f"{name}, {simd}"


def meta(args, baseline, total, head):
    import scipy

    return dict(date=datetime.date.today().isoformat(), machine=f"{platform.machine()} {platform.system()}",
                cpu=cpu_model(), cpus=os.cpu_count(), python=platform.python_version(), numpy=np.__version__,
                scipy=scipy.__version__, baseline=baseline, this_commit=head, repeat=args.repeat,
                quick=args.quick, total_s=total)


def write_atomic(path: Path, text: str):
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="1109cdf", help="the commit compared with (default 1109cdf)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per curve and variant (default 3)")
    ap.add_argument("--quick", action="store_true", help="base default curve, 1 repeat, no shooting (*-quick files)")
    ap.add_argument("--no-shooting", action="store_true", help="leave out the shooting peer")
    ap.add_argument("--reuse-shooting", default=None, metavar="JSON",
                    help="take shooting's rows from an earlier results file instead of running it again "
                         "(prolate2 and fit: ~30 min); the tables say so")
    ap.add_argument("--reuse-presets", default=None, metavar="P,Q",
                    help="with --reuse-shooting: only these presets' rows (the others are measured)")
    ap.add_argument("--work-dir", default=None,
                    help="the baseline's tree and both code caches (default: a folder in ~/.cache)")
    add_output_args(ap)
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error(f"--repeat must be >= 1; got {args.repeat}")
    return args


def main(argv=None):
    args = parse_args(argv)
    if args.worker:
        worker(json.loads(args.worker))
        return 0
    t_all = time.perf_counter()
    head = this_commit()  # read now: the workers import this tree as it is now
    if args.quick:
        args.repeat = 1
    cases = CASES[:1] if args.quick else CASES
    variants = ["baseline", "this commit", "this commit, numba"] if args.quick else list(VARIANTS)
    work = Path(args.work_dir) if args.work_dir else \
        Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "shellbvp-speed-vs-baseline"

    def log(msg):
        print(msg, flush=True)

    baseline = extract(args.baseline, work / f"tree-{args.baseline}")
    sides = Sides(work, work / f"tree-{args.baseline}")
    # this process (references, shooting) is this commit, with this side's code cache
    sys.path.insert(0, str(REPO))
    os.environ.update({k: sides.env("new")[k] for k in ("XDG_CACHE_HOME", "SHELLBVP_CACHE_DIR")})
    sides.warm(sorted({c[1] for c in cases}), log, numba="this commit, numba" in variants)
    data = dict(cases=[dict(id=c[0], preset=c[1], kind=c[2], runs={v: [] for v in variants}) for c in cases])
    for rep in range(args.repeat):
        for k, (case, entry) in enumerate(zip(cases, data["cases"])):
            shift = (rep + k) % len(variants)
            for v in variants[shift:] + variants[:shift]:
                if v in ABLATIONS and case[0] not in ABLATIONS[v]:
                    continue  # what each change bought: measured on the curves where it acts
                out = sides.run(v, case)
                entry["runs"][v].append(out)
                log(f"repeat {rep + 1}: {case[0]:>26} | {v:>16}: {out['cpu']:6.2f} s CPU, {out['wall']:6.2f} s, {out['points']} points, "
                    f"{out['calls']} solve_bvp, {out['niter']} Newton its")
    for case, entry in zip(cases, data["cases"]):
        entry["runs"] = {v: rs for v, rs in entry["runs"].items() if rs}
        depths = np.concatenate([np.asarray(rs[0]["delta"]) for rs in entry["runs"].values()])
        topology = "cap" if case[2] == "deltas40-cap" else "auto"
        ref = reference(case[1], _distinct(depths), topology, log, quick=args.quick)
        entry["reference"] = {k: ref[k] for k in ("complete", "stop", "seconds", "check")}
        entry["reference"].update(depths=len(ref["delta"]), converged=sum(t != "failed" for t in ref["topology"]),
                                  max_nodes=max(ref["nodes"], default=0))
        for rs in entry["runs"].values():
            rs[0]["f_error"], rs[0]["compared"], rs[0]["left_out"] = f_error(rs[0], ref)
        entry["_ref"] = ref
    summarize(data)
    reused = {}
    if args.reuse_shooting:  # shooting's rows measured in an earlier run (its code unchanged since)
        earlier = json.loads(Path(args.reuse_shooting).read_text())
        rows = {c["preset"]: c.get("shooting") for c in earlier["cases"] if c.get("kind") == "default"}
        keep = set(args.reuse_presets.split(",")) if args.reuse_presets else set(rows)
        reused = {p: r for p, r in rows.items() if p in keep and r}
        # rows that run itself reused keep the run where they were measured
        origin = earlier.get("shooting_from") or {}
        if not set(reused) <= set(origin.get("presets", ())):
            origin = dict(date=earlier["meta"]["date"], commit=earlier["meta"]["this_commit"])
        data["shooting_from"] = dict(file=str(args.reuse_shooting), date=origin["date"], commit=origin["commit"],
                                     presets=sorted(reused))
    collocation = [v for v in ("this commit", "this commit, numba") if v in variants]
    for entry in data["cases"]:
        if entry["kind"] != "default":
            continue
        if args.quick or (args.no_shooting and entry["preset"] not in reused):
            continue
        old_rows = reused.get(entry["preset"])
        if old_rows and {r["points"] for r in old_rows} != {len(shooting_states(entry["_ref"]))}:
            log(f"  {entry['preset']}: the reused shooting rows solved {old_rows[0]['points']} states, this run's "
                f"reference has {len(shooting_states(entry['_ref']))}: shooting runs again")
            del reused[entry["preset"]]
        shoot = entry["preset"] not in reused
        entry["same_states"], shots = same_states_and_shooting(sides, entry, collocation, args.repeat, shoot, log)
        entry["shooting"] = shots if shoot else reused[entry["preset"]]
        if not entry["shooting"]:
            continue
        ratios(entry)
    if "shooting_from" in data:  # the presets whose rows were reused after all
        data["shooting_from"]["presets"] = sorted(reused)
        if not reused:
            del data["shooting_from"]
    for entry in data["cases"]:
        entry.pop("_ref")
        for rs in entry["runs"].values():  # keep the measurements, not every point
            for r in rs[1:]:
                for k in ("delta", "force", "topology", "valid", "nodes"):
                    r.pop(k, None)
    data["targets"] = targets(data)
    data["meta"] = meta(args, baseline, time.perf_counter() - t_all, head)
    res = results_dir(args.out_dir)
    name = "speed_vs_baseline-quick" if args.quick else "speed_vs_baseline"
    write_atomic(res / f"{name}.json", json.dumps(data, indent=1, default=float))
    md = markdown(data)
    write_atomic(res / f"{name}.md", md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
