"""Where the axisymmetric curves lose stability (issue 44, item 5).

For every preset (smooth contact), every smooth scene of the stability grid
(``benchmarks/stability.py``) and the convex thin dome (gamma -1, beta 1e-5) at rho 0.05,
0.2 and 0.5: one ``sb.curve(scene, delta_max=..., stability="locate")`` in its own process
with a time limit, and its verdict: stable to where the curve ends, the first instability
(delta, delta over the shell's thickness ``H/R_L = sqrt(3 beta)``, F, the mode n), or states
not analysed (and why).  Every state is analysed in order up to the first unstable one (no sample).  The time of the stability analysis is reported beside the curve's.

Writes benchmarks/results/stability_modes.json and .md.

    python benchmarks/stability_modes.py                # everything (long: hours on 2 shared cores)
    python benchmarks/stability_modes.py --only dome    # a subset (regex on the id)
    python benchmarks/stability_modes.py --quick [--out-dir DIR]   # stability_modes-quick.* (under DIR/results)
"""

from __future__ import annotations

import argparse
import contextlib
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

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from checkout import add_output_args, commit_label, results_dir  # noqa: E402
from stability import grid as stability_grid  # noqa: E402

QUICK = r"^preset base$"  # --quick: the base preset's curve only
DOME_RHOS = (0.05, 0.2, 0.5)


def scenes(delta_max):
    """(id, how to build the scene, delta_max) for every scene of the table."""
    from shellbvp.scene import PRESETS

    out = [(f"preset {name}", {"preset": name}, delta_max) for name in PRESETS]
    out += [(f"grid {sid}", {"grid": over}, delta_max) for sid, _, over in stability_grid()]
    out += [(f"dome beta=1e-5 rho={r:g}", {"preset": "dome", "over": {"beta": 1e-5, "rho": r}}, delta_max)
            for r in DOME_RHOS]
    return out


def make_scene(how):
    import shellbvp as sb

    if "preset" in how:
        return sb.Scene.preset(how["preset"], **how.get("over", {}))
    from stability import make_scene as grid_scene

    return grid_scene({"overrides": how["grid"], "contact": "smooth"})


def worker_scene(spec_path, out_path):
    """(spec, row, scene) of a worker's spec file, or None where the scene is refused (its row,
    with the reason, written to ``out_path``)."""
    spec = json.loads(Path(spec_path).read_text())
    row = {"id": spec["id"]}
    try:
        scene = make_scene(spec["how"])
    except ValueError as exc:
        row["skipped"] = str(exc)
        Path(out_path).write_text(json.dumps(row))
        return None
    scene.model()
    return spec, row, scene


@contextlib.contextmanager
def time_limit(seconds):
    """KeyboardInterrupt after ``seconds`` (a curve keeps what it finished and stops)."""
    def alarm(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


def worker(spec_path, out_path):
    import numpy as np

    import shellbvp as sb
    from shellbvp.curve_stability import assess

    started = worker_scene(spec_path, out_path)
    if started is None:
        return
    spec, row, scene = started
    t0 = time.perf_counter()
    with time_limit(spec["time_limit"]):
        c = sb.curve(scene, delta_max=spec["delta_max"], estimate_error=False)
        # every state in order up to the first unstable one, then the crossing narrowed
        assess(c, "locate", samples=max(len(c), 1))
    wall = time.perf_counter() - t0
    smin = np.asarray(c.points["stability_min"], float)
    first = c.first_instability
    done = np.isfinite(smin)
    stop_at = len(c) if first is None else int(np.flatnonzero(smin < 0)[0]) + 1
    row.update(points=len(c), delta_end=float(c.delta.max()) if len(c) else math.nan, stop=c.stop_reason,
               interrupted=c.interrupted, analysed=int(done.sum()), refused=int(stop_at - done[:stop_at].sum()),
               last_analysed=float(c.delta[done].max()) if done.any() else math.nan,
               first_refused=float(c.delta[:stop_at][~done[:stop_at]].min()) if (~done[:stop_at]).any() else None,
               note=c.settings.get("stability_note", ""), stability_s=c.settings.get("stability_time", math.nan),
               total_s=wall, thickness=math.sqrt(3 * scene.beta),
               first=None if first is None else first.to_dict())
    Path(out_path).write_text(json.dumps(row))


def run_one(spec, grace=60, script=__file__):
    """One scene in its own process (``script --worker spec out``): its row, or killed/crashed."""
    with tempfile.TemporaryDirectory() as d:
        sp, op = Path(d) / "spec.json", Path(d) / "out.json"
        sp.write_text(json.dumps(spec))
        try:
            subprocess.run([sys.executable, script, "--worker", str(sp), str(op)], timeout=spec["time_limit"] + grace,
                           check=False)
        except subprocess.TimeoutExpired:
            return {"id": spec["id"], "killed": True}
        if not op.exists():
            return {"id": spec["id"], "crashed": True}
        return json.loads(op.read_text())


def verdict(r):
    if r.get("skipped"):
        return "skipped: " + r["skipped"]
    if r.get("killed") or r.get("crashed"):
        return "killed" if r.get("killed") else "crashed"
    if r["analysed"] == 0:
        return "not analysed: " + r["note"]
    refused = (f"; {r['refused']} states not analysed, from delta {r['first_refused']:.3g}: {r['note']}"
               if r["refused"] else "")
    f = r["first"]
    if f is None:
        return f"stable at every analysed state (to delta {r['last_analysed']:.3g}){refused}"
    return (f"unstable from delta {f['delta']:.4g} (delta/H {f['delta'] / r['thickness']:.3g}), n = {f['mode']}"
            + ("" if f["located"] else f"; {f['message']}") + refused)


def markdown(rows, meta):
    lines = ["# Where the axisymmetric curves lose stability (issue 44, item 5)", "",
             f"Written by `benchmarks/stability_modes.py` at {meta['commit']} ({meta['date']}; {meta['machine']}).  "
             f"`sb.curve(scene, delta_max={meta['delta_max']})`, smooth contact, then every state in order up to "
             "the first unstable one (`assess(curve, \"locate\", samples=len(curve))`) and the crossing narrowed "
             "between its neighbours; H/R_L = sqrt(3 beta) (the thickness of docs/accuracy.md's map).  A state the "
             "analysis does not handle is not analysed, and the reason is given.", "",
             "| scene | points | curve to delta | verdict | stability s | total s |", "|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("skipped") or r.get("killed") or r.get("crashed"):
            lines.append(f"| {r['id']} | | | {verdict(r)} | | |")
            continue
        lines.append(f"| {r['id']} | {r['points']} | {r['delta_end']:.3g} | {verdict(r)} | "
                     f"{r['stability_s']:.1f} | {r['total_s']:.1f} |")
    lost = [r for r in rows if r.get("first")]
    done = [r for r in rows if r.get("analysed")]
    lines += ["", f"{len(lost)} of {len(done)} analysed curves lose axisymmetric stability before their end.",
              f"Total {meta['seconds']:.0f} s."]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    ap.add_argument("--only", help="regex on the scene id")
    ap.add_argument("--delta-max", type=float, default=1.0)
    ap.add_argument("--time-limit", type=float, default=900.0, help="seconds per scene")
    add_output_args(ap, quick="the base preset's curve only")
    args = ap.parse_args()
    if args.quick:
        args.only = QUICK
    if args.worker:
        worker(*args.worker)
        return 0
    t0 = time.perf_counter()
    rows = []
    for sid, how, dmax in scenes(args.delta_max):
        if args.only and not re.search(args.only, sid):
            continue
        r = run_one({"id": sid, "how": how, "delta_max": dmax, "time_limit": args.time_limit})
        print(f"{sid}: {verdict(r)}", flush=True)
        rows.append(r)
    meta = {"commit": commit_label(), "date": datetime.date.today().isoformat(), "delta_max": args.delta_max,
            "machine": f"{platform.platform()}, Python {platform.python_version()}, {os.cpu_count()} cores",
            "seconds": time.perf_counter() - t0}
    suffix = "" if not args.only else "-" + re.sub(r"[^A-Za-z0-9]+", "_", args.only).strip("_")
    suffix = "-quick" if args.quick else suffix
    res = results_dir(args.out_dir)
    (res / f"stability_modes{suffix}.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    (res / f"stability_modes{suffix}.md").write_text(markdown(rows, meta))
    print(markdown(rows, meta))
    return 0


if __name__ == "__main__":
    sys.exit(main())
