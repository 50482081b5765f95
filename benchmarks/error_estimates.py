"""Error estimates at a fraction of the cost (issue 14, item 3): are they right?

For each work-precision scene (presets base, base-xi0, prolate2, fit, gent1; smooth
contact, lift-off on) a natural-continuation curve of 40 depths on [0.0125, 0.5] at
tol 1e-6 is computed three times, interleaved: ``estimate_error=False``, ``"full"``
(Richardson at every point) and ``"auto"`` (Richardson at the ends, next to
configuration changes and every ``RICHARDSON_EVERY``-th point; calibrated in between).
The true error of each point's F is ``|F - F_ref|``, F_ref re-solved warm from the
point at tol 1e-10 (node cap 30000, as in work_precision.py); the estimate is
compared with it both ways (estimate/true and true/estimate; the criterion is that
both stay <= 10 at every point).  delta is prescribed on these curves, so its error
and estimate are both 0 and are not tabulated.

Other spacings of the Richardson points (k = 3, 8, 10) are evaluated without new
solves: the states of the "auto" and "full" curves are the same (estimates do not
change the continuation), so the calibrated estimate for another k is rebuilt from the
"full" curve's Richardson values with ``shellbvp.solution.calibrated_error``.

Writes results/error_estimates.json and .md.  Times are from one run each on a shared
machine; the process CPU time is tabulated (wall time, in the JSON, moves with the
other users' load): the ratios, not the seconds, are the result.

    python benchmarks/error_estimates.py                      # all presets (~20 min on 2 shared cores)
    python benchmarks/error_estimates.py --presets base fit   # a subset (JSON per preset is merged)
    python benchmarks/error_estimates.py --rebuild            # only rewrite the Markdown from the JSON
    python benchmarks/error_estimates.py --out-dir DIR        # results/ under DIR
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from checkout import add_output_args, commit_label, results_dir  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
PRESETS = ("base", "base-xi0", "prolate2", "fit", "gent1")
DELTAS = np.linspace(0.0125, 0.5, 40)
TOL, REF_TOL, REF_MAX_NODES = 1e-6, 1e-10, 30000
OTHER_K = (3, 4, 8, 10)


def _write_atomic(path: Path, text: str):
    """Write next to the target and rename: a reader never sees half a file."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _configuration(s):
    return s.topology, s.contact_edge


def _geometric(residual, key, anchors):
    """The rule tried first: the bracketing ratios interpolated geometrically in key."""
    below = [a for a in anchors if a[0] <= key]
    above = [a for a in anchors if a[0] >= key]
    if not below or not above:
        return (above[0] if above else below[-1])[1] * residual
    (k0, r0), (k1, r1) = below[-1], above[0]
    w = (key - k0) / (k1 - k0) if k1 > k0 else 0.0
    return math.exp((1 - w) * math.log(r0) + w * math.log(r1)) * residual


def simulated_auto(full, k, rule=None):
    """Force estimates an "auto" curve with RICHARDSON_EVERY = k would give (no solve)."""
    from shellbvp.solution import calibrated_error

    sols = full.solutions
    conf = [_configuration(s) for s in sols]
    n = len(sols)
    rich, since = [], None
    for i in range(n):  # the add-time rule (points come in delta order on these curves) ...
        if since is None or since >= k - 1 or conf[i] != conf[i - 1]:
            rich.append(True)
            since = 0
        else:
            rich.append(False)
            since += 1
    for i in range(n):  # ... and the final one: ends and configuration edges
        if i in (0, n - 1) or conf[i - 1] != conf[i] or conf[i + 1] != conf[i]:
            rich[i] = True
    est = []
    for i, s in enumerate(sols):
        if rich[i]:
            est.append(s.force_error)
            continue
        anchors = [(j, sols[j].force_error / sols[j].max_residual) for j in range(n)
                   if rich[j] and conf[j] == conf[i] and math.isfinite(sols[j].force_error)]
        est.append((rule or calibrated_error)(s.max_residual, i, anchors))
    return np.array(est), int(sum(rich))


def _ratios(est, true):
    est, true = np.asarray(est, float), np.asarray(true, float)
    good = np.isfinite(est) & np.isfinite(true) & (true > 0) & (est > 0)
    over = est[good] / true[good]
    return dict(points=int(good.sum()), worst_over=float(over.max()) if over.size else math.nan,
                worst_under=float((1 / over).max()) if over.size else math.nan,
                within_10=int(np.sum((over <= 10) & (over >= 0.1))),
                bad=int(np.sum(~good & np.isfinite(true))))


def run_preset(name, log, old=None):
    import shellbvp as sb
    from shellbvp.recorder import RICHARDSON_EVERY

    scene = sb.Scene.preset(name)
    sb.curve(scene, deltas=DELTAS[:2], tol=TOL, estimate_error=False)  # load the generated code
    curves, walls, cpus = {}, {}, {}
    for mode in (False, "full", "auto"):
        t0, c0 = time.perf_counter(), time.process_time()
        curves[mode] = sb.curve(scene, deltas=DELTAS, tol=TOL, estimate_error=mode)
        walls[str(mode)], cpus[str(mode)] = time.perf_counter() - t0, time.process_time() - c0
        log(f"{name}: estimate_error={mode!r}: {len(curves[mode])} points, {walls[str(mode)]:.1f} s "
            f"(CPU {cpus[str(mode)]:.1f} s)")
    auto, full = curves["auto"], curves["full"]
    same = len(auto) == len(full) and np.array_equal(auto.force, full.force)
    F_ref, ref_nodes, t0 = [], [], time.perf_counter()
    if old is not None and old["force"] == np.asarray(auto.force).tolist():  # the same states: reuse
        F_ref, ref_nodes = old["F_ref"], old["ref_nodes"]
        log(f"{name}: reference reused from the JSON (identical states)")
    for s in auto.solutions if not F_ref else ():
        r = sb.solve(scene, delta=float(s.delta), tol=REF_TOL, guess=s, max_nodes=REF_MAX_NODES,
                     estimate_error=False)
        ok = r.success and r.topology == s.topology
        F_ref.append(r.force if ok else math.nan)
        ref_nodes.append(int(r.nodes))
    log(f"{name}: reference at tol {REF_TOL:g}: {np.isfinite(F_ref).sum()}/{len(auto)} converged, "
        f"{time.perf_counter() - t0:.1f} s")
    F_ref = np.array(F_ref)
    true = np.abs(np.asarray(auto.force) - F_ref)
    out = dict(
        preset=name, points=len(auto), stop=auto.stop_reason, same_states=bool(same), walls=walls, cpus=cpus,
        richardson_every=RICHARDSON_EVERY,
        delta=np.asarray(auto.delta).tolist(), topology=[str(t) for t in auto.topology],
        error_method=[str(m) for m in auto.points["error_method"]],
        force=np.asarray(auto.force).tolist(), F_ref=F_ref.tolist(), ref_nodes=ref_nodes,
        max_residual=np.asarray(auto.points["max_residual"]).tolist(), true=true.tolist(),
        est_auto=np.asarray(auto.force_error).tolist(), est_full=np.asarray(full.force_error).tolist(),
        richardson_auto=int(np.sum(auto.points["error_method"] == "richardson")),
        auto=_ratios(auto.force_error, true), full=_ratios(full.force_error, true),
        max_delta_error_estimate=float(np.nanmax(np.abs(auto.delta_error))) if len(auto) else math.nan,
    )
    out["other_k"] = {}
    if same:
        for k in OTHER_K:
            est, nrich = simulated_auto(full, k)
            out["other_k"][str(k)] = dict(richardson=nrich, **_ratios(est, true))
        est, nrich = simulated_auto(full, RICHARDSON_EVERY, _geometric)
        out["geometric"] = dict(richardson=nrich, **_ratios(est, true))
    return out


def markdown(data, meta):
    L = ["# Error estimates at a fraction of the cost (issue 14, item 3)", "",
         f"`python benchmarks/error_estimates.py` ({meta.get('date')}, git {meta.get('git')}, "
         f"{meta.get('cpus')} shared cores).  Natural-continuation curves of 40 depths on "
         f"[0.0125, 0.5] at tol {TOL:g}, lift-off on; true error of F: |F - F_ref|, F_ref re-solved warm "
         f"from each point at tol {REF_TOL:g} (node cap {REF_MAX_NODES}).  Ratios are estimate/true "
         "(over) and true/estimate (under), worst over the points; the criterion is <= 10 both ways at "
         "every point.  delta is prescribed on these curves (its error and estimate are 0).  A point "
         "whose reference failed (did not converge below the node cap, or came back in another "
         "topology) is left out.  The cost of the estimates is the number of Richardson solves (each "
         "about one continuation step on twice the nodes); the CPU times are single runs on a shared "
         "machine (+-0.2 s), so the saving by CPU time in the last column is rough (over 100 %: "
         "noise).", "",
         "| preset | points | reference ok | Richardson solves auto / full | auto: worst over | "
         "auto: worst under | auto: points within 10x | full: worst over | full: worst under | "
         "CPU time off / full / auto (s) | auto saves of full's extra cost: by solve count / by CPU time |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, p in data.items():
        w = p["cpus"]
        extra_full, extra_auto = w["full"] - w["False"], w["auto"] - w["False"]
        saved = 1 - extra_auto / extra_full if extra_full > 0 else math.nan
        a, f = p["auto"], p["full"]
        L.append(f"| {name} | {p['points']} | {a['points'] + a['bad']} | {p['richardson_auto']} / {p['points']} "
                 f"| {a['worst_over']:.2f} | {a['worst_under']:.2f} | {a['within_10']}/{a['points']} "
                 f"| {f['worst_over']:.2f} | {f['worst_under']:.2f} "
                 f"| {w['False']:.1f} / {w['full']:.1f} / {w['auto']:.1f} "
                 f"| {100 * (1 - p['richardson_auto'] / p['points']):.0f} % / {100 * saved:.0f} % |")
    outside = [(name, d, m, e / tr) for name, p in data.items()
               for d, m, e, tr in zip(p["delta"], p["error_method"], p["est_auto"], p["true"])
               if math.isfinite(tr) and tr > 0 and not 0.1 <= e / tr <= 10]
    if not outside:
        L += ["", "Every point's estimate is within a factor 10 of its true error."]
    else:
        L += ["", f"{len(outside)} point(s) outside a factor 10: "
              + "; ".join(f"{n} delta = {d:.4f} ({m}, estimate/true = {r:.1f})" for n, d, m, r in outside) + "."]
        if all(r > 10 for *_, r in outside):
            L += ["All are over-estimates at points whose true error is far below their neighbours' (the "
                  "F error is a signed sum over the mesh intervals and cancels there for that mesh; only a "
                  "solve -- Richardson -- sees that).  No calibrated estimate is more than "
                  f"{max(p['auto']['worst_under'] for p in data.values()):.1f}x below the true error."]
    L += ["", "Other spacings of the Richardson points, and the rule tried first (the two bracketing "
          "ratios interpolated geometrically instead of the larger one), rebuilt from the full curve's "
          "estimates, no new solve; worst ratios over / under (Richardson solves):", "",
          "| preset | " + " | ".join(f"k = {k}" for k in OTHER_K) + " | geometric, k = 5 |",
          "|---|" + "---|" * (len(OTHER_K) + 1)]
    for name, p in data.items():
        cells = []
        for k in OTHER_K:
            o = p["other_k"].get(str(k))
            cells.append(f"{o['worst_over']:.2f} / {o['worst_under']:.2f} ({o['richardson']})" if o else "n/a")
        g = p.get("geometric")
        cells.append(f"{g['worst_over']:.2f} / {g['worst_under']:.2f} ({g['richardson']})" if g else "n/a")
        L.append(f"| {name} | " + " | ".join(cells) + " |")
    L += ["", "Per point (auto): delta, topology, how the estimate was made, estimate, true error, "
          "ratio estimate/true.", ""]
    for name, p in data.items():
        L += [f"## {name}", "", "| delta | topology | method | estimate | true | ratio |",
              "|---|---|---|---|---|---|"]
        for d, t, m, e, tr in zip(p["delta"], p["topology"], p["error_method"], p["est_auto"], p["true"]):
            ratio = e / tr if tr and math.isfinite(tr) and tr > 0 else math.nan
            L.append(f"| {d:.4f} | {t} | {m} | {e:.2e} | {tr:.2e} | {ratio:.2f} |")
        L += [""]
    return "\n".join(L) + "\n"


def meta():
    import shellbvp as sb

    src = Path(sb.__file__).resolve().parent.parent
    return dict(date=datetime.date.today().isoformat(), cpus=os.cpu_count(), shellbvp=sb.__version__,
                git=commit_label(src, "not a git checkout"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", nargs="+", default=list(PRESETS), choices=PRESETS)
    ap.add_argument("--rebuild", action="store_true", help="only rewrite the Markdown from the JSON")
    ap.add_argument("--reuse-reference", action="store_true",
                    help="reuse a preset's tol-1e-10 reference from the JSON when its states are identical")
    add_output_args(ap)
    args = ap.parse_args(argv)
    global RESULTS
    RESULTS = results_dir(args.out_dir)
    js = RESULTS / "error_estimates.json"
    old = json.loads(js.read_text()) if js.exists() else {"presets": {}, "meta": {}}
    if not args.rebuild:
        for name in args.presets:
            prev = old["presets"].get(name) if args.reuse_reference else None
            p = run_preset(name, lambda m: print(m, flush=True), prev)
            old = json.loads(js.read_text()) if js.exists() else {"presets": {}, "meta": {}}  # merge: runs in parallel
            old["presets"][name] = p
            old["meta"] = meta()
            _write_atomic(js, json.dumps(old, indent=1) + "\n")
    ordered = {k: old["presets"][k] for k in PRESETS if k in old["presets"]}
    _write_atomic(RESULTS / "error_estimates.md", markdown(ordered, old["meta"]))


if __name__ == "__main__":
    main()
