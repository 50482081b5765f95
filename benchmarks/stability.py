"""Stability of force–displacement curves on stiff and extreme scenes (issue 5, part 2).

One thing is varied at a time around the base preset (gamma 1, rho 0.2,
beta 0.01, Mooney–Rivlin alpha 0.1, xi 1): beta, gamma (where gamma < 1/rho),
rho, xi, alpha, and the Gent material; each scene with both contact models.
Every scene is one ``sb.curve(scene, delta_max=..., delta_min=...,
estimate_error=True)`` in its own process (warm code cache; code generation
is done first and not timed), with a per-scene time limit: SIGALRM raises
KeyboardInterrupt, which ``curve`` treats as a clean interruption (the points
so far are kept, ``interrupted = True``); a process that does not come back
within the limit plus a grace period is killed and recorded as such.

For each scene: how far the curve got (delta range, max F), why it stopped,
complete or not, points, max nodes, wall time, the worst Richardson error
estimate (max force_error), min contact pressure, invalid points, where F < 0,
and the energy-identity residual max |dE/ddelta - F|.

Writes benchmarks/results/stability.json and benchmarks/results/stability.md.

    python benchmarks/stability.py            # full grid (about 30 min on 2 shared cores)
    python benchmarks/stability.py --quick    # a few scenes, small delta_max, for smoke tests
    python benchmarks/stability.py --only 'beta=1e-05' --contact smooth   # a subset (regex on the id)
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from checkout import commit_label  # benchmarks/ is on sys.path when run as a script

RESULTS = Path(__file__).parent / "results"

BASE = dict(gamma=1.0, rho=0.2, beta=0.01, xi=1, material=("mooney-rivlin", 0.1))


def _fmt(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def grid():
    """Scenes as (id, what is varied, overrides of BASE); the base scene once."""
    scenes = [("base", "base", {})]
    for b in (1e-1, 1e-3, 1e-4, 1e-5):
        scenes.append((f"beta={b:g}", "beta", dict(beta=b)))
    for g in (-2.0, -1.0, 0.0, 0.5, 2.0, 2.5, 3.0, 4.0):
        if g < 1 / BASE["rho"]:
            scenes.append((f"gamma={g:g}", "gamma", dict(gamma=g)))
    for r in (0.05, 1 / 3, 0.5):
        if BASE["gamma"] < 1 / r:
            scenes.append((f"rho={r:.4g}", "rho", dict(rho=r)))
    scenes.append(("xi=0", "xi", dict(xi=0)))
    for a in (0.0, 0.5):
        scenes.append((f"alpha={a:g}", "alpha", dict(material=("mooney-rivlin", a))))
    for jm in (0.4, 1.0, 97.2):
        scenes.append((f"Gent Jm={jm:g}", "Gent", dict(material=("gent", jm))))
    return scenes


QUICK = ("base", "beta=0.001", "gamma=-1", "Gent Jm=1")


def make_scene(spec):
    import shellbvp as sb

    d = dict(BASE)
    d.update(spec["overrides"])
    family, value = d.pop("material")
    material = sb.MooneyRivlin(value) if family == "mooney-rivlin" else sb.Gent(value)
    return sb.Scene(material=material, contact=spec["contact"], **d)


# -- worker: one curve in this process -----------------------------------------------------

def free_det(sol):
    """det d(tau_s, M_s)/d(lambda_s, kappa_s) over the free region's mesh (at fixed S, r, phi).

    The free-region ODE solves a 2x2 linear system with exactly this matrix for
    (lambda_s', kappa_s') (symbolic/equations.py): where it is singular the
    equations are.  Central differences of the generated ``free_profile``.
    Returns (value at S = Sc+, minimum over the free mesh, S/Sc at the minimum).
    """
    import numpy as np

    sysm = sol.system
    mod, par = sysm.model, sysm.par
    S = sysm.S(1, sol.x, sol.p)
    y = sol.y[sysm.rows(1)]
    cols = [mod.FREE_STATES.index("ls"), mod.FREE_STATES.index("ks")]
    J = np.zeros((2, 2, S.size))
    for j, k in enumerate(cols):
        h = 1e-6 * np.maximum(1.0, np.abs(y[k]))
        yp, ym = y.copy(), y.copy()
        yp[k] += h
        ym[k] -= h
        pp, pm = mod.free_profile(S, yp, par), mod.free_profile(S, ym, par)
        J[0, j] = (pp["tau_s"] - pm["tau_s"]) / (2 * h)
        J[1, j] = (pp["M_s"] - pm["M_s"]) / (2 * h)
    det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
    i = int(np.argmin(det))
    return float(det[0]), float(det[i]), float(S[i] / sol.Sc)


def gent_ratio(sol, Jm):
    """max (I1 - 3)/Jm over the shell (Gent's limiting stretch at 1)."""
    import numpy as np

    p = sol.profile()
    ls, lt = p["lambda_s"], p["lambda_theta"]
    I1 = ls ** 2 + lt ** 2 + 1 / (ls * lt) ** 2
    return float(np.nanmax(I1 - 3) / Jm)


def worker(spec_path, out_path):
    import numpy as np

    import shellbvp as sb

    spec = json.loads(Path(spec_path).read_text())
    row = {"id": spec["id"], "contact": spec["contact"], "varied": spec["varied"],
           "overrides": spec["overrides"]}
    try:
        scene = make_scene(spec)
    except ValueError as e:
        row.update(skipped=str(e))
        Path(out_path).write_text(json.dumps(row))
        return
    t0 = time.perf_counter()
    scene.model()  # code generation / cache load: not part of the curve time
    row["model_load_s"] = time.perf_counter() - t0

    def alarm(signum, frame):
        raise KeyboardInterrupt

    accepted = []

    def callback(curve_so_far, sol):
        accepted.append(time.perf_counter())

    signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, spec["time_limit"])
    t0 = time.perf_counter()
    try:
        c = sb.curve(scene, delta_max=spec["delta_max"], delta_min=spec["delta_min"],
                     estimate_error=True, callback=callback)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    wall = time.perf_counter() - t0
    # seconds spent after the last accepted point (failed attempts before the stop)
    row["stall_s"] = wall - (accepted[-1] - t0) if accepted else wall
    # ... of which the continuation's own search for a next point (the rest: switches located,
    # error estimates finished); issue 14: at most 2 s
    row["after_last_point_s"] = c.settings.get("after_last_point_s")

    n = len(c)
    p = c.points
    row.update(stop_reason=c.stop_reason, complete=bool(c.complete), interrupted=bool(c.interrupted),
               timed_out=bool(c.interrupted), points=n, wall_time=wall)
    if n:
        F, d = p["force"], p["delta"]
        neg = d[F < 0]
        with np.errstate(all="ignore"):
            er = c.energy_residual
        fin = lambda a: float(np.nanmax(a)) if np.any(np.isfinite(a)) else None  # noqa: E731
        finmin = lambda a: float(np.nanmin(a)) if np.any(np.isfinite(a)) else None  # noqa: E731
        row.update(
            delta_min=float(d.min()), delta_max=float(d.max()), force_max=float(F.max()),
            force_at_delta_max=float(F[np.argmax(d)]),
            nodes_max=int(p["nodes"].max()), force_error_max=fin(p["force_error"]),
            force_error_nan=int(np.sum(~np.isfinite(p["force_error"]))),
            pressure_min=finmin(p["pressure_min"]), invalid=int(np.sum(~p["valid"])),
            F_negative=bool(neg.size), F_negative_delta=[float(neg.min()), float(neg.max())] if neg.size else None,
            energy_residual_max=fin(np.abs(er)),
            energy_residual_rel=(fin(np.abs(er)) / float(np.max(np.abs(F)))) if fin(np.abs(er)) is not None else None,
            step_time_median=float(np.median(p["wall_time"])),
            monotone_delta=bool(np.all(np.diff(d) > 0)),
            curve={k: [float(v) for v in p[k]] for k in
                   ("delta", "force", "lambda0", "Sc", "nodes", "force_error", "pressure_min",
                    "ring_force", "wall_time")} | {"valid": [bool(v) for v in p["valid"]],
                                                   "flags": list(c.flags)},
        )
        # Diagnostics of the first and the last point of the branch (in delta).
        # (only single-cap states have the cap angle and Sc+ used here; point-load, line and
        # annulus states are skipped)
        sols = c.solutions
        cap = lambda s: s.topology == "cap"  # noqa: E731
        row["point_load_points"] = int(sum(s.topology == "point" for s in sols))
        row["curve"]["topology"] = [s.topology for s in sols]
        row["topologies"] = c.topology_summary() if hasattr(c, "topology_summary") else ""
        if "edge_legendre" in p:
            row["curve"]["edge_legendre"] = [float(v) for v in p["edge_legendre"]]
        omega_c = [float(s.Sc * s.y[0, -1] / scene.rho) if cap(s) else float("nan") for s in sols]
        row["curve"]["omega_c"] = omega_c
        last = sols[int(np.argmax(d))]
        row["omega_c_last_frac"] = omega_c[int(np.argmax(d))] / scene.tip_omega_max
        caps = [i for i in np.argsort(d) if cap(sols[i])]
        if caps and cap(last):
            with np.errstate(all="ignore"):
                d0 = free_det(sols[caps[0]])
                d1 = free_det(last)
            row.update(det_first=d0[0], det_last=d1[0], det_last_min=d1[1], det_last_min_at=d1[2])
        if spec["overrides"].get("material", ("",))[0] == "gent" and cap(last):
            with np.errstate(all="ignore"):
                row["gent_ratio_last"] = gent_ratio(last, spec["overrides"]["material"][1])
        row["diagnosis"] = diagnose(row)
    Path(out_path).write_text(json.dumps(row, default=float))


def diagnose(r):
    """What the last point shows (automatic; the report's analysis goes further)."""
    out = []
    if "det_first" not in r:
        pass
    elif r["det_first"] > 0 and r["det_last"] < 0.05 * r["det_first"]:
        out.append(f"free ODE singular at Sc+: det d(tau_s,M_s)/d(ls,ks) = {r['det_last']:.1e} "
                   f"({r['det_last'] / r['det_first']:.1e} x its small-delta value)")
    elif r["det_first"] > 0 and r["det_last_min"] < 0.05 * r["det_first"]:
        out.append(f"free ODE nearly singular at S = {r['det_last_min_at']:.3g} Sc (det {r['det_last_min']:.1e})")
    if r.get("gent_ratio_last", 0) > 0.95:
        out.append(f"Gent limit: max (I1-3)/Jm = {r['gent_ratio_last']:.4f} (F -> infinity)")
    if r["omega_c_last_frac"] > 0.95:
        out.append(f"contact at omega_c = {r['omega_c_last_frac']:.4f} x the tip's end (cylinder)")
    if (r.get("after_last_point_s") or 0) > 2:
        out.append(f"{r['after_last_point_s']:.1f} s spent after the last accepted point before the stop")
    return "; ".join(out)


# -- driver ---------------------------------------------------------------------------

def run_one(spec, grace):
    with tempfile.TemporaryDirectory() as tmp:
        sp, op = Path(tmp, "spec.json"), Path(tmp, "out.json")
        sp.write_text(json.dumps(spec))
        t0 = time.perf_counter()
        try:
            proc = subprocess.run([sys.executable, __file__, "--worker", str(sp), str(op)],
                                  capture_output=True, text=True, timeout=spec["time_limit"] + grace)
        except subprocess.TimeoutExpired:
            return {"id": spec["id"], "contact": spec["contact"], "varied": spec["varied"],
                    "overrides": spec["overrides"], "killed": True, "timed_out": True, "complete": False,
                    "stop_reason": f"killed after {spec['time_limit'] + grace:.0f} s (did not stop at the "
                                   "time limit)", "points": 0, "wall_time": time.perf_counter() - t0}
        if proc.returncode != 0 or not op.exists():
            return {"id": spec["id"], "contact": spec["contact"], "varied": spec["varied"],
                    "overrides": spec["overrides"], "crashed": True, "complete": False, "points": 0,
                    "stop_reason": f"worker exited {proc.returncode}: "
                                   + (proc.stderr.strip().splitlines() or [""])[-1][:300],
                    "wall_time": time.perf_counter() - t0}
        row = json.loads(op.read_text())
        row["process_wall_s"] = time.perf_counter() - t0
        return row


def short_reason(r):
    if r.get("skipped"):
        return "skipped (invalid scene)"
    if r.get("killed") or r.get("crashed"):
        return r["stop_reason"][:60]
    if r.get("interrupted"):
        return f"time limit ({r['time_limit']:.0f} s)"
    s = r["stop_reason"]
    if "end of the tip" in s and "no valid contact with the cylinder" in s:
        return "contact reached the cylinder; no valid state on it"
    if "end of the tip" in s and "inadmissible" in s:
        m = re.match(r"continuation failed near delta = ([-\d.e+]+)", s)
        if m:
            return f"failed at delta {float(m.group(1)):.4g}: contact passed the cylinder (no landing)"
    if "end of the tip" in s:
        return "contact reached the cylinder"
    if s.startswith("no valid contact configuration beyond"):
        return s[:60]
    m = re.search(r"loses convexity at the lifted cap's free pole: .* ends at delta = ([-\d.e+]+)", s)
    if m:
        return f"lifted pole loses convexity: branch ends at delta {float(m.group(1)):.6g}"
    if s.startswith("delta_max"):
        return "delta_max reached"
    m = re.match(r"continuation failed near delta = ([-\d.e+]+): (.*)", s)
    if m:
        msg = m.group(2)
        if "loses convexity" in msg:
            return f"branch ends at delta {float(m.group(1)):.4g}: loss of convexity at Sc+ (solver's diagnosis)"
        for key, short in (("mesh nodes", "max nodes"), ("singular Jacobian", "singular Jacobian"),
                           ("boundary conditions", "bc not met"), ("turned back", "turned back to delta <= 0"),
                           ("inadmissible", "inadmissible")):
            if key in msg:
                msg = short
                break
        return f"failed at delta {float(m.group(1)):.4g}: {msg}"
    m = re.match(r"no solution at delta_max = ([-\d.e+]+): (.*)", s)
    if m:
        return "failed landing on delta_max: " + ("max nodes" if "mesh nodes" in m.group(2) else m.group(2)[:40])
    if s.startswith("no solution at the first point"):
        return "first point failed"
    return s[:60]


def g(v, f=".3g"):
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, f)


def markdown(rows, meta):
    lines = [
        f"Measured {meta['date']} on {meta['machine']} ({meta['cpus']} cores, shared), "
        f"shellbvp {meta['shellbvp']} ({meta['git']}), SciPy {meta['scipy']}; `sb.curve(scene, delta_max={meta['delta_max']:g}, "
        f"delta_min={meta['delta_min']:g}, estimate_error=True)`, tol 1e-6, max_nodes 10000, "
        f"time limit {meta['time_limit']:.0f} s per curve; kernels {meta.get('kernels', 'auto')}; "
        f"total {meta['total_s']:.0f} s.",
        "",
        "| scene | contact | delta reached | max F | stopped | complete | points | max nodes | time (s) "
        "| after the last point (s) | max F error | min P | invalid | F < 0 at delta | max \\|dE/dδ − F\\| | contact topologies | at the last point |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r.get("skipped"):
            lines.append(f"| {r['id']} | {r['contact']} | skipped: {r['skipped'][:50]} |" + " |" * 14)
            continue
        if not r.get("points"):
            lines.append(f"| {r['id']} | {r['contact']} | — | | {short_reason(r)} | no | 0 | | "
                         f"{r['wall_time']:.1f} | | | | | | | | |")
            continue
        neg = ("" if not r["F_negative"] else
               f"{r['F_negative_delta'][0]:.3g}–{r['F_negative_delta'][1]:.3g}")
        nan, npl = r["force_error_nan"], r.get("point_load_points", 0)
        fe = g(r["force_error_max"], ".1e") + (
            "" if not nan else f" ({npl} point-load, not estimated)" if nan == npl else f" ({nan} NaN)")
        lines.append(
            f"| {r['id']} | {r['contact']} | {r['delta_min']:.3g}–{r['delta_max']:.4g} | {r['force_max']:.4g} "
            f"| {short_reason(r)} | {'yes' if r['complete'] else 'no'} | {r['points']} | {r['nodes_max']} "
            f"| {r['wall_time']:.1f} | {g(r.get('after_last_point_s'), '.2f')} | {fe} | {g(r['pressure_min'])} | {r['invalid']} | {neg or 'no'} "
            f"| {g(r['energy_residual_max'], '.1e')} | {r.get('topologies', '')} | {r.get('diagnosis', '')} |")
    lines += [
        "",
        "delta reached: smallest and largest delta on the curve (the small-delta leg aims at delta_min; "
        "the upward leg at delta_max or the cylinder). max F error: largest Richardson estimate. "
        "min P: smallest contact pressure over all points (of the states recorded: where the cap would "
        "pull, the valid line or annular contact replaces it; a line has no contact area). invalid: points "
        "with valid = False (with the paper's contact model, which has the single cap only, the small-delta "
        "caps that pull). contact topologies: runs along the curve and the located switches. max |dE/dδ − F|: Curve.energy_residual (finite differences along the curve; "
        "~1e-3 for the smooth model is the differencing error at this point spacing, O(0.1-1) for the "
        "paper model and for xi = 0 is real). at the last point: automatic diagnosis of the last point "
        "(det of d(tau_s, M_s)/d(lambda_s, kappa_s) at the contact line, the 2x2 system the free-region "
        "ODE inverts; Gent's (I1-3)/Jm; contact angle against the tip's end; more than 2 s spent after "
        "the last accepted point). after the last point: seconds the continuation spent after its last "
        "accepted point before it stopped (failed attempts; locating switches and finishing the error "
        "estimates come after and are not counted; issue 14's target: at most 2 s).",
    ]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a few scenes, delta_max 0.3, 60 s limit")
    ap.add_argument("--only", help="regex on scene ids")
    ap.add_argument("--contact", choices=("smooth", "paper", "both"), default="both")
    ap.add_argument("--delta-max", type=float, default=None, help="default 1.0 (quick: 0.3)")
    ap.add_argument("--delta-min", type=float, default=1e-4, help="end of the small-delta leg")
    ap.add_argument("--time-limit", type=float, default=None, help="seconds per curve (default 300; quick 60)")
    ap.add_argument("--grace", type=float, default=120.0, help="extra seconds before a worker is killed")
    ap.add_argument("--kernels", choices=("numpy", "numba", "auto"), default="numpy",
                    help="SHELLBVP_KERNELS of the workers (default numpy, the reference: with auto a curve "
                         "may switch to the compiled kernels part way, and rounding then decides a few "
                         "fragile steps, so the table would depend on the code cache's state)")
    ap.add_argument("--out", default=None, help="basename in benchmarks/results (default stability[-quick])")
    ap.add_argument("--out-dir", default=None, help="write results/ under this directory (default benchmarks/)")
    ap.add_argument("--rebuild", action="store_true",
                    help="only rewrite the Markdown (and diagnoses) from the existing JSON")
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if not args.worker:
        os.environ["SHELLBVP_KERNELS"] = args.kernels  # inherited by the workers
    global RESULTS
    if args.out_dir:
        RESULTS = Path(args.out_dir) / "results"
    if args.worker:
        worker(*args.worker)
        return
    if args.rebuild:
        name = args.out or ("stability-quick" if args.quick else "stability")
        data = json.loads((RESULTS / f"{name}.json").read_text())
        for r in data["scenes"]:
            if r.get("points") and "omega_c_last_frac" in r:
                r["diagnosis"] = diagnose(r)
        (RESULTS / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))
        (RESULTS / f"{name}.md").write_text(markdown(data["scenes"], data["meta"]))
        print(markdown(data["scenes"], data["meta"]))
        return

    import numpy
    import scipy

    import shellbvp as sb

    delta_max = args.delta_max or (0.3 if args.quick else 1.0)
    time_limit = args.time_limit or (60.0 if args.quick else 300.0)
    contacts = ("smooth", "paper") if args.contact == "both" else (args.contact,)
    scenes = grid()
    if args.quick:
        scenes = [s for s in scenes if s[0] in QUICK]
    if args.only:
        scenes = [s for s in scenes if re.search(args.only, s[0])]

    # Generate/cache the code of every structure first (not part of any timing).
    for sid, varied, ov in scenes:
        try:
            make_scene({"overrides": ov, "contact": "smooth"}).model()
        except ValueError:
            pass

    rows = []
    t_all = time.perf_counter()
    for sid, varied, ov in scenes:
        for contact in contacts:
            spec = dict(id=sid, varied=varied, overrides=ov, contact=contact, delta_max=delta_max,
                        delta_min=args.delta_min, time_limit=time_limit)
            r = run_one(spec, args.grace)
            r["time_limit"] = time_limit
            rows.append(r)
            print(f"{sid:>14} {contact:>6}: {short_reason(r):<45} points {r.get('points', 0):>3}  "
                  f"delta {g(r.get('delta_min'))}..{g(r.get('delta_max'))}  "
                  f"nodes {r.get('nodes_max', '')}  {r.get('wall_time', 0):.1f} s", flush=True)
    total = time.perf_counter() - t_all

    src = Path(sb.__file__).resolve().parent.parent
    meta = dict(source=str(src), git=commit_label(src, os.environ.get("STABILITY_SOURCE_NOTE", "not a git checkout")), date=datetime.date.today().isoformat(), machine=f"{platform.machine()} {platform.node()}",
                cpus=os.cpu_count(), python=platform.python_version(), numpy=numpy.__version__,
                scipy=scipy.__version__, shellbvp=sb.__version__, delta_max=delta_max,
                delta_min=args.delta_min, time_limit=time_limit, total_s=total,
                quick=args.quick, base=dict(BASE, material=list(BASE["material"])), kernels=args.kernels)
    RESULTS.mkdir(parents=True, exist_ok=True)
    name = args.out or ("stability-quick" if args.quick else "stability")
    (RESULTS / f"{name}.json").write_text(json.dumps({"meta": meta, "scenes": rows}, indent=1, default=float))
    md = markdown(rows, meta)
    (RESULTS / f"{name}.md").write_text(md)
    print(md)
    print(f"total {total:.0f} s")


if __name__ == "__main__":
    main()
