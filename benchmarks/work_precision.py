"""Error against run time (work–precision) of force–displacement curves (issue 5, part 1).

For each preset (base, base-xi0, prolate2, fit, gent1; smooth contact):

Reference
    ``N`` depths ``delta = 0.5 k/N`` (k = 1..N, N = 40).  A natural continuation at tol
    1e-6 gives a state at each depth; each is then re-solved *warm from it* at tol 1e-9
    (the reference) and, independently, at tol 1e-8 and at tol 1e-10 (different meshes,
    pole starts ``eps`` and tolerances; tol 1e-10 with a node cap, since near the
    round-off floor solve_bvp can refine without end).  Convergence is shown by the
    agreement of these runs (reported; the reference is good to about that level).
    A one-shot natural continuation at tol 1e-10 was tried before: 813 s and a failure.
Curves at tol 1e-3 .. 1e-8
    * natural continuation at the reference depths (``sb.curve(scene, deltas=...)``):
      F compared with the reference depth by depth (delta is prescribed, no interpolation);
    * the adaptive curve ``sb.curve(scene, delta_max=0.5)`` (what users run; its depths
      are outputs): each point's F is compared with a reference solved *at that point's
      delta* (tol 1e-9, warm from the point) -- again no interpolation.
    Both with ``estimate_error=False`` (the default ``True`` adds a Richardson solve per
    point; its cost is reported separately at tol 1e-6).  Wall time is the median of
    ``--repeat`` runs after an instrumented warm-up run that counts solve_bvp's work:
    ``niter`` (solve_bvp's outer iterations: Newton solve + mesh refinement), Jacobian
    evaluations (``fun_jac`` is called twice per Newton Jacobian, at nodes and midpoints)
    and residual evaluations.  Per-step cost: the median of the points' own wall times
    (one solve_bvp run from the warm guess, diagnostics included) and total / points.
Peer (``--shoot``, default: base)
    ``benchmarks/shooting.py`` (the paper's method: lambda0 prescribed, DOP853, exact
    sensitivities, tangent predictor) at the reference states' lambda0 values, warm-started
    at the first from the tol-1e-6 collocation state (its cold start, a homotopy in beta
    taking 10-20 s, is not counted).  Its error is that of the point (delta_s, F_s) on the
    curve: ``|F_s - F_ref - F'_ref (delta_s - delta_ref)|``, F' by differences of the
    reference.  Times at equal error, both ways: log-log interpolation of time against
    max error along the other method's series.
Start-up
    cold solve of one state from a crude guess (``sb.solve``), and a new process
    (import + load the generated code + one solve) with a warm and with an empty code
    cache, each a fresh ``python -c``.

Writes results/work_precision.json and .md, figures/work_precision.png (``-quick`` files
with --quick).

    python benchmarks/work_precision.py                 # all presets (~30 min on 2 shared cores)
    python benchmarks/work_precision.py --quick         # base, 10 depths, 2 tolerances (about 1 min)
    python benchmarks/work_precision.py --presets base --shoot base
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from checkout import commit_label  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

PRESETS = ("base", "base-xi0", "prolate2", "fit", "gent1")
TOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
SHOOT_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
REF_TOL, CHECK_TOLS = 1e-9, (1e-8, 1e-10)
REF_MAX_NODES, CAP_1E10 = 100000, 30000
N_POINTS = 40
DELTA_MAX = 0.5

# ---------------------------------------------------------------------------------------------
# counting solve_bvp's work (monkeypatch in this process only; shellbvp is not edited)
# ---------------------------------------------------------------------------------------------


class Counter:
    def __init__(self):
        self.fun = self.jac = self.calls = self.niter = 0

    def __enter__(self):
        import shellbvp.liftoff
        import shellbvp.pointload
        import shellbvp.solution
        import shellbvp.state

        # every module that calls the guarded solve_bvp (bound at import)
        self._modules = [shellbvp.solution, shellbvp.state, shellbvp.pointload, shellbvp.liftoff]
        self._orig = orig = shellbvp.solution.solve_bvp
        counter = self

        def counted(fun, bc, x, y, p=None, *, fun_jac=None, bc_jac=None, **kw):
            def f(*a):
                counter.fun += 1
                return fun(*a)

            def j(*a):
                counter.jac += 1
                return fun_jac(*a)

            counter.calls += 1
            r = orig(f, bc, x, y, p, fun_jac=j if fun_jac is not None else None, bc_jac=bc_jac, **kw)
            counter.niter += int(r.niter)
            return r

        for m in self._modules:
            m.solve_bvp = counted
        return self

    def __exit__(self, *exc):
        for m in self._modules:
            m.solve_bvp = self._orig

    def as_dict(self):
        return dict(bvp_runs=self.calls, bvp_niter=self.niter, jacobians=self.jac // 2, rhs_evals=self.fun)


# ---------------------------------------------------------------------------------------------
# reference
# ---------------------------------------------------------------------------------------------


def reference(scene, deltas, log, every_1e10=8):
    """Tight states at the given depths, and the agreement of independent tight runs."""
    import shellbvp as sb

    t0 = time.perf_counter()
    c = sb.curve(scene, deltas=deltas, tol=1e-6, estimate_error=False)
    deltas = np.asarray(c.delta)
    runs = {}
    for tol in (REF_TOL,) + CHECK_TOLS:
        node_cap = CAP_1E10 if tol < REF_TOL else REF_MAX_NODES
        F, lam, dl, ok, nodes, secs = [], [], [], [], [], []
        for i, (d, s) in enumerate(zip(deltas, c.solutions)):
            if tol < REF_TOL and (not every_1e10 or (i % every_1e10 != every_1e10 - 1 and i != 0)):
                F.append(math.nan), lam.append(math.nan), ok.append(False), nodes.append(0)
                continue  # tol 1e-10 is costly (nodes grow towards the cap): a subset only
            t1 = time.perf_counter()
            r = sb.solve(scene, delta=float(d), tol=tol, guess=s, max_nodes=node_cap, estimate_error=False)
            secs.append(time.perf_counter() - t1)
            ok.append(bool(r.success))
            F.append(r.force if r.success else math.nan)
            lam.append(r.lambda0 if r.success else math.nan)
            nodes.append(int(r.nodes))
            if tol == REF_TOL:
                # shooting's unknown u = rQ(Sc+) (free state 4 at t = 0; cap states only)
                is_cap = r.success and r.topology == "cap" and r.y.shape[0] == 8
                dl.append(dict(Sc=float(r.Sc), u=float(r.y[6, 0])) if is_cap else None)
        runs[tol] = dict(F=np.array(F), lambda0=np.array(lam), ok=np.array(ok), nodes=np.array(nodes),
                         seconds=float(np.sum(secs)), start=dl if tol == REF_TOL else None)
        log(f"  reference tol {tol:g}: {sum(ok)} converged, max nodes {max(nodes)}, "
            f"{np.sum(secs):.1f} s")
    ref = runs[REF_TOL]
    agree = {}
    for tol in CHECK_TOLS:
        both = ref["ok"] & runs[tol]["ok"]
        rel = np.abs(runs[tol]["F"][both] - ref["F"][both]) / np.abs(ref["F"][both])
        agree[f"{tol:g}"] = dict(points=int(both.sum()), tried=int(np.sum(runs[tol]["nodes"] > 0)), max_rel=float(rel.max()) if rel.size else math.nan,
                                 median_rel=float(np.median(rel)) if rel.size else math.nan,
                                 max_nodes=int(runs[tol]["nodes"].max()), seconds=runs[tol]["seconds"])
    return dict(
        delta=deltas.tolist(), F=ref["F"].tolist(), lambda0=ref["lambda0"].tolist(), ok=ref["ok"].tolist(),
        nodes=ref["nodes"].tolist(), start=ref["start"], tol=REF_TOL, max_nodes=REF_MAX_NODES,
        agreement=agree, seconds=time.perf_counter() - t0, stop=c.stop_reason,
        F_check={f"{t:g}": runs[t]["F"].tolist() for t in CHECK_TOLS},
    )


# ---------------------------------------------------------------------------------------------
# collocation curves
# ---------------------------------------------------------------------------------------------


def _errors(F, Fref):
    F, Fref = np.asarray(F, float), np.asarray(Fref, float)
    good = np.isfinite(F) & np.isfinite(Fref)
    rel = np.abs(F[good] - Fref[good]) / np.abs(Fref[good])
    ab = np.abs(F[good] - Fref[good])
    if not rel.size:
        return dict(max_rel=math.nan, median_rel=math.nan, max_abs=math.nan, compared=0)
    return dict(max_rel=float(rel.max()), median_rel=float(np.median(rel)), max_abs=float(ab.max()),
                compared=int(good.sum()))


def _timed_curves(make, repeat):
    """Instrumented warm-up run (counts, solutions), then ``repeat`` timed runs."""
    with Counter() as cnt:
        c0 = make()
    walls, steps = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        c = make()
        walls.append(time.perf_counter() - t0)
        steps.extend(np.asarray(c.wall_time, float).tolist())
    return c0, cnt.as_dict(), walls, steps


def _curve_row(kind, tol, c, counts, walls, steps):
    n = len(c)
    wall = statistics.median(walls)
    return dict(kind=kind, tol=tol, points=n, complete=bool(c.complete), stop=c.stop_reason,
                all_converged=bool(n and np.all(c.status == 0)),
                wall_s=wall, walls=walls, per_point_ms=1e3 * wall / max(n, 1),
                median_step_ms=1e3 * float(np.median(steps)) if steps else math.nan,
                max_nodes=int(np.max(c.nodes)) if n else 0, median_nodes=float(np.median(c.nodes)) if n else 0,
                delta_range=[float(np.min(c.delta)), float(np.max(c.delta))] if n else None, **counts)


def natural_series(scene, ref, tols, repeat, log):
    import shellbvp as sb

    deltas = np.asarray(ref["delta"])
    rows = []
    for tol in tols:
        c, counts, walls, steps = _timed_curves(
            lambda: sb.curve(scene, deltas=deltas, tol=tol, estimate_error=False), repeat)
        row = _curve_row("natural", tol, c, counts, walls, steps)
        F = np.full(deltas.size, math.nan)
        idx = np.searchsorted(deltas, c.delta)
        F[idx] = c.force
        row.update(_errors(F, ref["F"]))
        row["F"] = F.tolist()
        rows.append(row)
        log(f"  natural tol {tol:g}: {len(c)} points, max rel err {row['max_rel']:.2e}, "
            f"{row['wall_s']:.2f} s, median step {row['median_step_ms']:.1f} ms, max nodes {row['max_nodes']}")
    return rows


def adaptive_series(scene, tols, repeat, log, ref_every=1):
    import shellbvp as sb

    rows = []
    for tol in tols:
        c, counts, walls, steps = _timed_curves(
            lambda: sb.curve(scene, delta_max=DELTA_MAX, tol=tol, estimate_error=False), repeat)
        row = _curve_row("adaptive", tol, c, counts, walls, steps)
        # reference at each point's own delta, warm from the point
        Fref, skipped = [], 0
        t0 = time.perf_counter()
        for i, s in enumerate(c.solutions):
            if i % ref_every and i != len(c) - 1:
                Fref.append(math.nan)  # not compared (quick mode)
                continue
            if s.topology == "point":
                Fref.append(math.nan)
                skipped += 1
                continue
            r = sb.solve(scene, delta=float(s.delta), tol=REF_TOL, guess=s, max_nodes=REF_MAX_NODES,
                         estimate_error=False)
            Fref.append(r.force if r.success else math.nan)
        row.update(_errors(c.force, Fref))
        row.update(delta=np.asarray(c.delta).tolist(), F=np.asarray(c.force).tolist(), F_ref=Fref,
                   point_load_points=skipped, reference_s=time.perf_counter() - t0)
        rows.append(row)
        log(f"  adaptive tol {tol:g}: {len(c)} points, max rel err {row['max_rel']:.2e}, "
            f"{row['wall_s']:.2f} s, median step {row['median_step_ms']:.1f} ms, max nodes {row['max_nodes']}")
    return rows


def richardson_cost(scene, repeat):
    """The default curve (estimate_error=True) at tol 1e-6: time, and estimate vs true error."""
    import shellbvp as sb

    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        c = sb.curve(scene, delta_max=DELTA_MAX, tol=1e-6)
        walls.append(time.perf_counter() - t0)
    return dict(wall_s=statistics.median(walls), walls=walls, points=len(c),
                max_force_error_estimate=float(np.nanmax(c.force_error)) if len(c) else math.nan)


# ---------------------------------------------------------------------------------------------
# the shooting peer
# ---------------------------------------------------------------------------------------------


def shooting_series(scene, ref, rtols, log, shoot_from=0.0):
    from shooting import shoot_curve

    lam = np.asarray(ref["lambda0"])
    dref, Fref = np.asarray(ref["delta"]), np.asarray(ref["F"])
    dF = np.gradient(Fref, dref)
    k = next((i for i, st in enumerate(ref["start"]) if st and dref[i] >= shoot_from), None)
    if k is None:
        return []
    lam, dref, Fref, dF = lam[k:], dref[k:], Fref[k:], dF[k:]
    start = ref["start"][k]
    rows = []
    for rtol in rtols:
        t0 = time.perf_counter()
        sc = shoot_curve(scene, lam, rtol=rtol, guess=(start["Sc"], start["u"]))
        wall = time.perf_counter() - t0
        ok = np.asarray(sc.success, bool)
        Fs, ds = np.asarray(sc.F, float), np.asarray(sc.delta, float)
        F_at = np.where(ok, Fs - dF * (ds - dref), math.nan)  # F_s moved to delta_ref along the curve
        row = dict(rtol=rtol, points=int(lam.size), delta_from=float(dref[0]), converged=int(ok.sum()), wall_s=wall,
                   per_point_ms=1e3 * wall / lam.size,
                   median_point_ms=1e3 * float(np.median(sc.wall_time)),
                   nfev=int(np.sum(sc.nfev)), niter=int(np.sum(sc.niter)), **_errors(F_at, Fref))
        eq = _errors(np.where(ok, Fs, math.nan), Fref)
        row["max_rel_F_equal_lambda0"] = eq["max_rel"]
        dd = np.abs(ds[ok] - dref[ok])
        row["max_abs_delta_err"] = float(dd.max()) if dd.size else math.nan
        rows.append(row)
        log(f"  shooting rtol {rtol:g}: {row['converged']}/{lam.size}, max rel err {row['max_rel']:.2e}, "
            f"{wall:.1f} s ({row['per_point_ms']:.0f} ms/point)")
    return rows


def equal_errors(p):
    """Every EQUAL_ERROR_VARIANTS entry of a preset with a shooting series (in place)."""
    if not p.get("shooting"):
        return
    for key, (err, tc, ts, _) in EQUAL_ERROR_VARIANTS.items():
        p[key] = equal_error(p["natural"], p["shooting"], len(p["reference"]["delta"]), err, tc, ts)


def time_at_error(series, err):
    """Time to reach max error ``err`` along a series [(max_err, time)], log-log interpolated.

    Returns (time, how): how = "interp"; "bound" when err is looser than the series'
    loosest run (the loosest run's time: an upper bound); None when err is tighter than
    any run reached.
    """
    pts = sorted((e, t) for e, t in series if math.isfinite(e) and e > 0 and math.isfinite(t))
    if not pts or not math.isfinite(err) or err <= 0:
        return None, "none"
    # make time non-increasing in error (a slower, less accurate run is never the best)
    best, clean = math.inf, []
    for e, t in pts:
        best = min(best, t)
        clean.append((e, best))
    es = np.log([e for e, _ in clean])
    ts = np.log([t for _, t in clean])
    le = math.log(err)
    if le < es[0]:
        return None, "not reached"
    if le > es[-1]:
        return float(np.exp(ts[-1])), "bound"
    return float(np.exp(np.interp(le, es, ts))), "interp"


EQUAL_ERROR_VARIANTS = {
    # key: (shooting's error, collocation's time, shooting's time, description)
    "equal_error": ("max_rel", "per_point_ms", "per_point_ms",
                    "shooting's error: its point (delta_s, F_s) against the F(delta) curve; time: total / points"),
    "equal_error_lambda0": ("max_rel_F_equal_lambda0", "per_point_ms", "per_point_ms",
                            "shooting's error: F at equal lambda0 (its delta error ignored; favours shooting); "
                            "time: total / points"),
    "equal_error_median": ("max_rel", "median_step_ms", "median_point_ms",
                           "shooting's error: its point against the curve; time: the median point (leaves out "
                           "collocation's cold first point and shooting's slow small-delta points)"),
}


def equal_error(coll_rows, shoot_rows, n, shoot_key="max_rel", coll_time="per_point_ms",
                shoot_time="per_point_ms"):
    """Times per point at equal max error, both ways.

    ``shoot_key``: shooting's error measure ("max_rel": its point against the F(delta) curve;
    "max_rel_F_equal_lambda0": F at equal lambda0, which ignores its delta error).
    """
    coll_rows = [dict(r, per_point_ms=r[coll_time]) for r in coll_rows]
    coll = [(r["max_rel"], r["per_point_ms"]) for r in coll_rows if r["all_converged"] and r["points"] == n]
    shoot_rows = [dict(r, max_rel=r[shoot_key], per_point_ms=r[shoot_time]) for r in shoot_rows]
    shoot = [(r["max_rel"], r["per_point_ms"]) for r in shoot_rows if r["converged"] == r["points"]]
    out = dict(shooting_points=[], collocation_points=[])
    for r in shoot_rows:
        if r["converged"] != r["points"]:
            continue
        tc, how = time_at_error(coll, r["max_rel"])
        out["shooting_points"].append(dict(rtol=r["rtol"], error=r["max_rel"], shooting_ms=r["per_point_ms"],
                                           collocation_ms=tc, how=how,
                                           ratio=(r["per_point_ms"] / tc) if tc else None))
    for r in coll_rows:
        if not (r["all_converged"] and r["points"] == n):
            continue
        ts, how = time_at_error(shoot, r["max_rel"])
        out["collocation_points"].append(dict(tol=r["tol"], error=r["max_rel"], collocation_ms=r["per_point_ms"],
                                              shooting_ms=ts, how=how,
                                              ratio=(ts / r["per_point_ms"]) if ts else None))
    return out


# ---------------------------------------------------------------------------------------------
# start-up costs
# ---------------------------------------------------------------------------------------------

PROBE = """
import time
t0 = time.perf_counter()
import shellbvp as sb
t1 = time.perf_counter()
scene = sb.Scene.preset('base')
scene.model()
t2 = time.perf_counter()
s = sb.solve(scene, delta=0.2, tol=1e-6, estimate_error=False)
t3 = time.perf_counter()
assert s.success
print(t1 - t0, t2 - t1, t3 - t2)
"""


def process_start(repeat_warm, repeat_cold):
    def run(cache):
        env = _env(cache)
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
        wall = time.perf_counter() - t0
        imp, model, solve = map(float, out.stdout.split())
        return dict(process_s=wall, import_s=imp, model_s=model, solve_s=solve,
                    start_s=wall - solve)  # process start up to a usable model (interpreter + import + load)

    def bare(code):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], env=_env(os.environ.get("SHELLBVP_CACHE_DIR", "")),
                       check=True, capture_output=True)
        return time.perf_counter() - t0

    base_py = statistics.median(bare("pass") for _ in range(repeat_warm))
    base_sci = statistics.median(bare("import numpy, scipy.integrate, scipy.sparse.linalg")
                                 for _ in range(repeat_warm))
    warm, cold = [], []
    with tempfile.TemporaryDirectory() as cache:
        run(cache)  # fill it
        for _ in range(repeat_warm):
            warm.append(run(cache))
    for _ in range(repeat_cold):
        with tempfile.TemporaryDirectory() as cache:
            cold.append(run(cache))
    med = lambda xs: {k: statistics.median(x[k] for x in xs) for k in xs[0]} if xs else {}  # noqa: E731
    return dict(warm=med(warm), cold=med(cold), repeat_warm=repeat_warm, repeat_cold=repeat_cold,
                python_bare_s=base_py, numpy_scipy_s=base_sci)


def _env(cache):
    """A user's environment: byte-code caching on (this machine sets PYTHONDONTWRITEBYTECODE)."""
    env = dict(os.environ, SHELLBVP_CACHE_DIR=cache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def cold_solves(repeat, deltas=(0.05, 0.2, 0.4)):
    import shellbvp as sb

    scene = sb.Scene.preset("base")
    scene.model()
    out = {}
    for d in deltas:
        ts, s = [], None
        for _ in range(repeat):
            t0 = time.perf_counter()
            s = sb.solve(scene, delta=d, tol=1e-6, estimate_error=False)
            ts.append(time.perf_counter() - t0)
        out[f"{d:g}"] = dict(seconds=statistics.median(ts), success=bool(s.success), nodes=int(s.nodes))
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        sb.solve(scene, delta=0.2, tol=1e-6)
        ts.append(time.perf_counter() - t0)
    out["0.2 with error estimate"] = dict(seconds=statistics.median(ts), success=True, nodes=None)
    return out


# ---------------------------------------------------------------------------------------------
# output
# ---------------------------------------------------------------------------------------------


def _e(v, f=".1e"):
    return "—" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, f)


def targets(data):
    """The issue's targets, measured (not tests)."""
    out = []
    base = data["presets"].get("base")
    if not base:
        return out
    nat = base["natural"]
    good = [r for r in nat if r["all_converged"] and r["points"] >= 40 and
            max(r["max_rel"], r["max_abs"]) <= 1e-6]
    if good:
        r = min(good, key=lambda r: r["wall_s"])
        out.append(dict(target="base curve, >= 40 points on [0, 0.5], every F within 1e-6 of the reference, <= 1 s",
                        measured=f"{r['points']} points (natural continuation) at tol {r['tol']:g}: max error "
                                 f"{max(r['max_rel'], r['max_abs']):.1e}, {r['wall_s']:.2f} s",
                        met=r["wall_s"] <= 1.0, factor=r["wall_s"] / 1.0))
    else:
        out.append(dict(target="base curve, >= 40 points within 1e-6 in <= 1 s", measured="no run qualified",
                        met=False, factor=None))
    meds = {}
    for key in EQUAL_ERROR_VARIANTS:
        ratios = [p["ratio"] for p in (base.get(key) or {}).get("shooting_points", []) if p["ratio"]]
        if ratios:
            meds[key] = (statistics.median(ratios), min(ratios), max(ratios))
    if meds:
        worst = min(v[0] for v in meds.values())
        rt = ", ".join(f"{r['rtol']:.0e}" for r in base.get("shooting", []) if r["converged"] == r["points"])
        txt = []
        for key, what in (("equal_error", "its point against the curve, total / points"),
                          ("equal_error_lambda0", "F at equal lambda0, total / points"),
                          ("equal_error_median", "its point against the curve, median point")):
            if key in meds:
                med, lo, hi = meds[key]
                txt.append(f"median {med:.0f}x ({lo:.0f}x–{hi:.0f}x) ({what})")
        out.append(dict(target=">= 40x faster than shooting per point at equal error",
                        measured="; ".join(txt) + f" (at shooting's rtol {rt}; 'met' judged on the smaller)",
                        met=worst >= 40, factor=40 / worst))
    r6 = next((r for r in nat if r["tol"] == 1e-6), None)
    a6 = next((r for r in base["adaptive"] if r["tol"] == 1e-6), None)
    if r6:
        ms = r6["median_step_ms"]
        extra = f"; adaptive curve {a6['median_step_ms']:.0f} ms" if a6 else ""
        out.append(dict(target="median continuation step <= 20 ms",
                        measured=f"{ms:.0f} ms (natural, tol 1e-6){extra}", met=ms <= 20, factor=ms / 20))
    cs = data.get("cold_solve", {}).get("0.2")
    if cs:
        out.append(dict(target="cold solve of one state from a crude guess <= 0.1 s",
                        measured=f"{cs['seconds']:.3f} s (base, delta 0.2, tol 1e-6, no error estimate)",
                        met=cs["seconds"] <= 0.1, factor=cs["seconds"] / 0.1))
    ps = data.get("process", {}).get("warm")
    if ps:
        out.append(dict(target="warm start of a new process <= 0.5 s",
                        measured=f"{ps['start_s']:.2f} s (interpreter + import + load cached code; "
                                 f"+{ps['solve_s']:.2f} s for a first solve)",
                        met=ps["start_s"] <= 0.5, factor=ps["start_s"] / 0.5))
    return out


def _equal_error_table(ee, m, what):
    L = []
    L += ["", f"Time per point at equal error (natural continuation over the {m['n_points']} depths, vs shooting "
          f"at the same states; {what}): log-log interpolation along the other method's series; '≥' where the error is "
          "looser than the other's loosest run (its time is then an upper bound, the ratio a lower "
          "bound); '—' where the other never got that accurate.", "",
          "| at the error of | max rel err F | shooting (ms) | collocation (ms) | "
          "shooting / collocation |",
          "|---|---|---|---|---|"]
    for q in ee["shooting_points"]:
        rat = "—" if q["ratio"] is None else ("≥ " if q["how"] == "bound" else "") + f"{q['ratio']:.1f}"
        L.append(f"| shooting rtol {q['rtol']:.0e} | {q['error']:.1e} | {q['shooting_ms']:.0f} | "
                 f"{_e(q['collocation_ms'], '.0f')} | {rat} |")
    for q in ee["collocation_points"]:
        rat = "—" if q["ratio"] is None else ("≤ " if q["how"] == "bound" else "") + f"{q['ratio']:.1f}"
        L.append(f"| collocation tol {q['tol']:.0e} | {q['error']:.1e} | {_e(q['shooting_ms'], '.0f')} | "
                 f"{q['collocation_ms']:.0f} | {rat} |")
    if any(q["how"] == "bound" for q in ee["collocation_points"]):
        L.append("")
        L.append("(≤: collocation's error is looser than shooting's loosest run; shooting's time there is "
                 "that of its loosest run, an upper bound, so the ratio is too.)")
    return L


def markdown(data):
    m = data["meta"]
    L = [f"Measured {m['date']} on a {m['machine']} ({m['cpus']} cores, shared with other jobs), Python "
         f"{m['python']}, NumPy {m['numpy']}, SciPy {m['scipy']}, shellbvp {m['shellbvp']} ({m['git']}); "
         f"`python benchmarks/work_precision.py{' --quick' if m['quick'] else ''}`, total {m['total_s']:.0f} s. "
         f"Smooth contact; times are medians of {m['repeat']} runs after an untimed, instrumented warm-up run."
         + (f" Note: {m['note']}" if m.get("note") else ""),
         ""]
    L += ["### Reference", "",
          f"{m['n_points']} depths delta = 0.5 k/{m['n_points']}; natural continuation at tol 1e-6, then each "
          f"state re-solved warm at tol {REF_TOL:g} (reference, max_nodes {REF_MAX_NODES}) and, independently, "
          "at tol 1e-8" + (f" and, at a subset of depths (every {m['every_1e10']}th and, in runs since the first "
                           f"and smallest cap was added, the first; 'converged' counts those tried), at 1e-10 "
                           f"(max_nodes {CAP_1E10})" if m.get("every_1e10") else "") +
          ". The reference error is about the smaller of the two disagreements.", "",
          "| preset | points | ref converged | ref max nodes | \\|F(1e-8) − F_ref\\|/F max (median) | "
          "\\|F(1e-10) − F_ref\\|/F max (median), converged | time (s) |",
          "|---|---|---|---|---|---|---|"]
    for name, p in data["presets"].items():
        ref = p["reference"]
        a8, a10 = ref["agreement"]["1e-08"], ref["agreement"]["1e-10"]
        L.append(f"| {name} | {len(ref['delta'])} | {sum(ref['ok'])} | {max(ref['nodes'])} | "
                 f"{_e(a8['max_rel'])} ({_e(a8['median_rel'])}) | {_e(a10['max_rel'])} ({_e(a10['median_rel'])}), "
                 f"{a10['points']}/{a10['tried']} | {ref['seconds']:.0f} |")
    L += ["", "### Work–precision", "",
          "natural: `sb.curve(scene, deltas=<the reference depths>, tol=tol, estimate_error=False)`; "
          "adaptive: `sb.curve(scene, delta_max=0.5, tol=tol, estimate_error=False)` (depths from 0.005; "
          "error against a tol-1e-9 state at each point's own delta). Errors are relative, |F − F_ref|/F_ref. "
          "step: median of the points' own solve times; per point: total / points. iters: solve_bvp "
          "iterations (Newton solve + mesh refinement), summed; Jacobians: Newton Jacobian evaluations, summed.",
          "",
          "| preset | curve | tol | points | max rel err F | median rel err F | time (s) | per point (ms) "
          "| step (ms) | max nodes | median nodes | iters | Jacobians |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, p in data["presets"].items():
        for r in p["natural"] + p["adaptive"]:
            pts = f"{r['points']}" + ("" if r["all_converged"] and r["complete"] else " (incomplete)")
            L.append(f"| {name} | {r['kind']} | {r['tol']:.0e} | {pts} | {_e(r['max_rel'])} | "
                     f"{_e(r['median_rel'])} | {r['wall_s']:.2f} | {r['per_point_ms']:.0f} | "
                     f"{r['median_step_ms']:.0f} | {r['max_nodes']} | {r['median_nodes']:.0f} | "
                     f"{r['bvp_niter']} | {r['jacobians']} |")
    L += ["", "With the default error estimates (`estimate_error=True`, a Richardson solve per point), "
          "adaptive curve at tol 1e-6:", ""]
    for name, p in data["presets"].items():
        rc = p.get("richardson")
        a6 = next((r for r in p["adaptive"] if r["tol"] == 1e-6), None)
        if rc and a6:
            L.append(f"* {name}: {rc['wall_s']:.2f} s for {rc['points']} points "
                     f"(x{rc['wall_s'] / a6['wall_s']:.2f} of the run without), largest estimate "
                     f"{_e(rc['max_force_error_estimate'])} (absolute) against a true max abs error "
                     f"{_e(a6['max_abs'])}.")
    for name, p in data["presets"].items():
        if not p.get("shooting"):
            continue
        sp = p["shooting"][0]
        L += ["", f"### Shooting (the paper's method) on {name}", "",
              f"{sp['points']} states from delta = {sp.get('delta_from', p['reference']['delta'][0]):g}: "
              "`benchmarks/shooting.py`'s `shoot_curve` at the reference states' lambda0 (DOP853, exact "
              "sensitivities, tangent predictor; warm start at the first point from the tol-1e-6 collocation "
              "state; its 10–20 s cold start is not counted). err F: the point (delta_s, F_s) against the "
              "reference curve, F_s − F_ref − F'(delta_s − delta_ref); at equal lambda0: F_s − F_ref.", "",
              "| rtol | converged | max rel err F | median rel err F | max rel err F at equal lambda0 | "
              "max abs err delta | time (s) | per point (ms) | median point (ms) | RHS evals |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for r in p["shooting"]:
            L.append(f"| {r['rtol']:.0e} | {r['converged']}/{r['points']} | {_e(r['max_rel'])} | "
                     f"{_e(r['median_rel'])} | {_e(r['max_rel_F_equal_lambda0'])} | {_e(r['max_abs_delta_err'])} "
                     f"| {r['wall_s']:.2f} | {r['per_point_ms']:.0f} | {r['median_point_ms']:.0f} | {r['nfev']} |")
        for key, (_, _, _, what) in EQUAL_ERROR_VARIANTS.items():
            if key in p:
                L += _equal_error_table(p[key], m, what)
    L += ["", "### Start-up and single states", ""]
    cs = data.get("cold_solve")
    if cs:
        L.append("Cold solve of one base state from a crude guess (`sb.solve(scene, delta=d, tol=1e-6, "
                 "estimate_error=False)`, in a warm process, median of "
                 f"{m['repeat_cold_solve']}): " + ", ".join(
                     f"delta {k}: {v['seconds']:.3f} s" for k, v in cs.items()) + ".")
    ps = data.get("process")
    if ps and ps.get("warm"):
        w, c = ps["warm"], ps.get("cold") or {}
        L.append("")
        L.append(f"New process (`python -c`: import shellbvp, load the base scene's code, one solve at delta "
                 f"0.2): warm code cache {w['process_s']:.2f} s (import {w['import_s']:.2f}, load "
                 f"{w['model_s']:.3f}, solve {w['solve_s']:.2f}; start to a usable model {w['start_s']:.2f} s), "
                 f"median of {ps['repeat_warm']}" + (
                     f"; empty cache {c['process_s']:.2f} s (derivation and code generation "
                     f"{c['model_s']:.2f} s), median of {ps['repeat_cold']}" if c else "") + ". "
                 f"For scale: `python -c pass` {ps['python_bare_s']:.2f} s, importing NumPy and SciPy's "
                 f"integrate and sparse.linalg {ps['numpy_scipy_s']:.2f} s (byte-code caching on).")
    L += ["", "### Against the issue's targets", "", "| target | measured | met |", "|---|---|---|"]
    for t in data["targets"]:
        miss = "" if t["met"] or t["factor"] is None else f" (missed by {t['factor']:.{2 if t['factor'] < 1.1 else 1}f}x)"
        L.append(f"| {t['target']} | {t['measured']} | {'yes' if t['met'] else 'no' + miss} |")
    return "\n".join(L) + "\n"


def summary(data):
    """The compact table for docs/benchmarking.md: every preset's natural-continuation curve against tol,
    the shooting peer at equal error, and the targets."""
    m = data["meta"]
    tols = sorted({r["tol"] for p in data["presets"].values() for r in p["natural"]}, reverse=True)
    L = [f"Measured {m['date']} on a {m['cpus']}-core shared {m['machine']} machine, Python {m['python']}, "
         f"SciPy {m['scipy']} ({m['git']}). Curves of {m['n_points']} points at delta = 0.5 k/{m['n_points']} "
         "(natural continuation, `sb.curve(scene, deltas=..., tol=tol, estimate_error=False)`); "
         "each cell: max relative error in F against the reference / wall time of the curve "
         f"(median of {m['repeat']}).", "",
         "| tol | " + " | ".join(data["presets"]) + " |", "|---|" + "---|" * len(data["presets"])]
    for tol in tols:
        cells = []
        for p in data["presets"].values():
            r = next((r for r in p["natural"] if r["tol"] == tol), None)
            cells.append("" if r is None else f"{_e(r['max_rel'])} / {r['wall_s']:.2f} s"
                         + ("" if r["all_converged"] and r["complete"] else " (incomplete)"))
        L.append(f"| {tol:.0e} | " + " | ".join(cells) + " |")
    rows = []
    for name, p in data["presets"].items():
        r6 = next((r for r in p["natural"] if r["tol"] == 1e-6), None)
        a6 = next((r for r in p["adaptive"] if r["tol"] == 1e-6), None)
        if r6 and a6:
            rows.append(f"{name} {r6['median_step_ms']:.0f} / {a6['median_step_ms']:.0f} ms")
    if rows:
        L += ["", "Median continuation step at tol 1e-6 (natural / adaptive): " + ", ".join(rows) + "."]
    for name, p in data["presets"].items():
        if not p.get("shooting"):
            continue
        for key, (_, _, _, what) in EQUAL_ERROR_VARIANTS.items():
            ee = p.get(key)
            if not ee:
                continue
            parts = []
            for q in ee["shooting_points"]:
                if q["ratio"]:
                    parts.append(f"rtol {q['rtol']:.0e} (error {q['error']:.0e}): "
                                 f"{'≥ ' if q['how'] == 'bound' else ''}{q['ratio']:.0f}x")
            L += ["", f"Shooting (the paper's method) on {name}, its time / collocation's at equal "
                  f"error ({what}): " + ("; ".join(parts) if parts else "no shooting run converged at every point")
                  + "."]
    L += ["", "| target (issue 5) | measured | met |", "|---|---|---|"]
    for t in data["targets"]:
        miss = "" if t["met"] or t["factor"] is None else f" (missed by {t['factor']:.{2 if t['factor'] < 1.1 else 1}f}x)"
        L.append(f"| {t['target']} | {t['measured']} | {'yes' if t['met'] else 'no' + miss} |")
    return "\n".join(L) + "\n"


def plot(data, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no work-precision plot (pip install -e '.[plot]')")
        return False
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (name, p) in enumerate(data["presets"].items()):
        col = colors[i % len(colors)]
        for kind, style in (("natural", "-o"), ("adaptive", "--s")):
            rows = [r for r in p[kind] if math.isfinite(r["max_rel"])]
            if not rows:
                continue
            axes[0].loglog([r["wall_s"] for r in rows], [r["max_rel"] for r in rows], style, color=col, ms=4,
                           label=f"{name} {kind}")
            axes[1].loglog([r["per_point_ms"] for r in rows], [r["max_rel"] for r in rows], style, color=col,
                           ms=4)
            if kind == "natural" and i == 0:
                for r in rows:
                    axes[0].annotate(f"{r['tol']:.0e}", (r["wall_s"], r["max_rel"]), fontsize=6,
                                     textcoords="offset points", xytext=(3, 3))
        if p.get("shooting"):
            rows = [r for r in p["shooting"] if r["converged"] == r["points"]]
            axes[0].loglog([r["wall_s"] for r in rows], [r["max_rel"] for r in rows], ":^", color="k", ms=5,
                           label=f"{name} shooting (paper's method)")
            axes[1].loglog([r["per_point_ms"] for r in rows], [r["max_rel"] for r in rows], ":^", color="k", ms=5)
            for r in rows:
                axes[0].annotate(f"{r['rtol']:.0e}", (r["wall_s"], r["max_rel"]), fontsize=6,
                                 textcoords="offset points", xytext=(3, -8))
    axes[0].set_xlabel("wall time of the curve (s)")
    axes[1].set_xlabel("time per point (ms)")
    for ax in axes:
        ax.set_ylabel("max relative error in F")
        ax.grid(True, which="major", alpha=0.3)
    axes[1].axhline(1e-6, color="0.6", lw=0.7)
    axes[1].axvline(20, color="0.6", lw=0.7)  # the targets: 1e-6, 20 ms a step
    axes[1].set_xlim(left=min(15.0, axes[1].get_xlim()[0]))
    axes[0].legend(fontsize=6, ncol=2)
    m = data["meta"]
    fig.suptitle(f"Work–precision, force–displacement curves to delta = 0.5 ({m['date']}, "
                 f"{m['cpus']}-core shared {m['machine']}, Python {m['python']})", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def meta(args, total):
    import numpy
    import scipy

    import shellbvp as sb

    src = Path(sb.__file__).resolve().parent.parent
    return dict(date=datetime.date.today().isoformat(), machine=platform.machine(), node=platform.node(),
                cpus=os.cpu_count(), python=platform.python_version(), numpy=numpy.__version__,
                scipy=scipy.__version__, shellbvp=sb.__version__,
                git=os.environ.get("SHELLBVP_SOURCE_NOTE") or commit_label(src, "not a git checkout"),
                quick=args.quick, repeat=args.repeat, shoot_from=args.shoot_from, every_1e10=args.every_1e10,
                source_note=os.environ.get("SHELLBVP_SOURCE_NOTE", ""), n_points=args.points, tols=list(args.tols),
                shoot_rtols=list(args.shoot_rtols), repeat_cold_solve=args.repeat_cold, total_s=total)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="base only, 10 depths, tol 1e-4 and 1e-6 (adaptive curves compared at every 4th "
                         "point), shooting at rtol 1e-6 on the last two depths, one repeat")
    ap.add_argument("--presets", nargs="+", default=None, help=f"default {' '.join(PRESETS)}")
    ap.add_argument("--shoot", nargs="*", default=None, help="presets for the shooting peer (default base)")
    ap.add_argument("--shoot-from", type=float, default=None,
                    help="shoot only at depths >= this (default 0: all; quick 0.45)")
    ap.add_argument("--points", type=int, default=None, help=f"reference depths (default {N_POINTS})")
    ap.add_argument("--repeat", type=int, default=None, help="timed runs per curve (default 3; quick 1)")
    ap.add_argument("--every-1e10", type=int, default=None,
                    help="re-solve the first and every k-th reference depth at tol 1e-10 too (default 8; quick 0 = none)")
    ap.add_argument("--no-startup", action="store_true", help="skip the process start-up measurements")
    ap.add_argument("--rebuild", action="store_true", help="only rewrite the Markdown and plot from the JSON")
    ap.add_argument("--out-dir", default=None,
                    help="write results/ and figures/ under this directory (default benchmarks/)")
    args = ap.parse_args(argv)
    q = args.quick
    args.presets = args.presets or (["base"] if q else list(PRESETS))
    args.shoot = ["base"] if args.shoot is None else args.shoot
    args.points = args.points or (10 if q else N_POINTS)
    args.repeat = args.repeat or (1 if q else 3)
    if args.every_1e10 is None:
        args.every_1e10 = 0 if q else 8
    args.tols = (1e-4, 1e-6) if q else TOLS
    args.shoot_rtols = (1e-6,) if q else SHOOT_RTOLS
    if args.shoot_from is None:
        args.shoot_from = 0.45 if q else 0.0
    args.repeat_cold = 3 if q else 7
    args.name = "work_precision-quick" if q else "work_precision"
    return args


def main(argv=None):
    args = parse_args(argv)
    out_dir = Path(args.out_dir) if args.out_dir else HERE
    if args.rebuild:  # Markdown and plot from the existing JSON
        data = json.loads((out_dir / "results" / f"{args.name}.json").read_text())
        for p in data["presets"].values():
            equal_errors(p)
        data["targets"] = targets(data)
        write(data, out_dir, args.name)
        return
    log = lambda msg: print(msg, file=sys.stderr, flush=True)  # noqa: E731
    import shellbvp as sb

    t_all = time.perf_counter()
    data = dict(presets={})
    deltas = DELTA_MAX * np.arange(1, args.points + 1) / args.points
    for name in args.presets:
        scene = sb.Scene.preset(name)
        scene.model()  # code generation is not timed here (see process start-up)
        log(f"{name}:")
        ref = reference(scene, deltas, log, every_1e10=args.every_1e10)
        p = dict(reference=ref)
        p["natural"] = natural_series(scene, ref, args.tols, args.repeat, log)
        p["adaptive"] = adaptive_series(scene, args.tols, args.repeat, log, 4 if args.quick else 1)
        if 1e-6 in args.tols:
            p["richardson"] = richardson_cost(scene, args.repeat)
        if name in args.shoot:
            p["shooting"] = shooting_series(scene, ref, args.shoot_rtols, log, args.shoot_from)
            equal_errors(p)
        data["presets"][name] = p
    log("cold solves ...")
    data["cold_solve"] = cold_solves(args.repeat_cold)
    if not args.no_startup:
        log("process start-up ...")
        data["process"] = process_start(3 if args.quick else 7, 1 if args.quick else 3)
    data["meta"] = meta(args, time.perf_counter() - t_all)
    data["targets"] = targets(data)
    write(data, out_dir, args.name)


def write(data, out_dir, name):
    res = out_dir / "results"
    res.mkdir(parents=True, exist_ok=True)
    (res / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))
    md = markdown(data)
    (res / f"{name}.md").write_text(md)
    (res / f"{name}-summary.md").write_text(summary(data))
    plot(data, out_dir / "figures" / f"{name}.png")
    print(md)


if __name__ == "__main__":
    main()
