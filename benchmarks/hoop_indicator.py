"""The hoop-stress wrinkling indicator against the eigenvalue analysis (issue 44, item 3).

Along the curves of ``benchmarks/stability_modes.py`` (its scene list: every preset, the
stability grid, the thin dome at three tip radii): one ``sb.curve(scene, delta_max=1)`` per
scene in its own process with a time limit; for every state the indicator of
:func:`shellbvp.hoop_indicator` (both models, ``"strip"`` and ``"band"``) and, in order up to the
first unstable state, the eigenvalues of :func:`shellbvp.stability` (``assess(curve, "locate",
samples=len(curve))``, as stability_modes.py does, the crossing narrowed).  Per curve: the first
depth where each indicator fires against the first eigenvalue instability and its n, misses
(an unstable state reached with the indicator silent up to it), false alarms (states analysed
stable where it fires), and the time of each.

Writes benchmarks/results/hoop_indicator.json and .md.

    python benchmarks/hoop_indicator.py                # every scene (~15 min on 2 shared cores)
    python benchmarks/hoop_indicator.py --only dome    # a subset (regex on the id)
    python benchmarks/hoop_indicator.py --quick [--out-dir DIR]   # hoop_indicator-quick.* (under DIR/results)
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import re
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from checkout import add_output_args, commit_label, results_dir  # noqa: E402
from stability_modes import scenes, time_limit, worker_scene  # noqa: E402
from stability_modes import run_one as run_scene  # noqa: E402

QUICK = r"^preset base$"  # --quick: the base preset's curve only
MODELS = ("strip", "band")


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
        curve_s = time.perf_counter() - t0
        per_model = {}
        for model in MODELS:
            t1 = time.perf_counter()
            inds = [sb.hoop_indicator(s, model=model) for s in c.solutions]
            per_model[model] = {"seconds": time.perf_counter() - t1,
                                "ratio": [float(i.ratio) for i in inds], "n": [float(i.n) for i in inds],
                                "S": [float(i.S) for i in inds]}
        screen = screened_pass(c.solutions, per_model["strip"]["ratio"])
        assess(c, "locate", samples=max(len(c), 1))
    smin = np.asarray(c.points["stability_min"], float)
    first = c.first_instability
    at_crossing = {}
    if first is not None and first.located:  # the indicator at the located crossing itself (grid-free)
        near = int(np.argmin(np.abs(np.asarray(c.delta) - first.delta)))
        s = sb.solve(scene, delta=first.delta, guess=c.solutions[near], estimate_error=False)
        at_crossing = {m: float(sb.hoop_indicator(s, model=m).ratio) for m in MODELS}
    row.update(points=len(c), thickness=math.sqrt(3 * scene.beta), curve_s=curve_s,
               stability_s=c.settings.get("stability_time", math.nan), note=c.settings.get("stability_note", ""),
               delta=[float(d) for d in c.delta], Sc=[float(s.Sc) if s is not None else math.nan for s in c.solutions],
               stability_min=[float(v) for v in smin], critical_mode=[int(m) for m in c.points["critical_mode"]],
               first=None if first is None else first.to_dict(), models=per_model, at_crossing=at_crossing,
               screen=screen)
    Path(out_path).write_text(json.dumps(row))


def screened_pass(states, strip_ratio):
    """Every state in order up to the first unstable one, twice: every mode (as ``assess`` does
    before narrowing), and screened -- modes n = 0, 1 only where the strip indicator is silent
    (ratio >= 1), every mode where it fires.  Times and the first unstable index of each: what
    using the indicator as a screen for n >= 2 would save, and whether it would change a verdict."""
    from shellbvp.curve_stability import point_stability

    out = {}
    if states:
        point_stability(states[0], modes=[0])  # the form's derivation (once per process) outside the timing
    for name, screened in (("full", False), ("screened", True)):
        t0 = time.perf_counter()
        first = None
        for i, s in enumerate(states):
            modes = [0, 1] if screened and not strip_ratio[i] < 1 else None
            lam, _, _ = point_stability(s, modes=modes)
            if lam < 0:
                first = i
                break
        out[name] = {"seconds": time.perf_counter() - t0, "first_unstable": first}
    return out


def run_one(spec, grace=60):
    return run_scene(spec, grace, script=__file__)


def compare(r, model):
    """Per curve and model: first firing, the verdict against the eigenvalues, counts."""
    delta = r["delta"]
    smin = [float(v) for v in r["stability_min"]]
    ratio = r["models"][model]["ratio"]
    n = r["models"][model]["n"]
    fired = [i for i, q in enumerate(ratio) if q < 1]
    unstable = [i for i, v in enumerate(smin) if v < 0]
    i_u = unstable[0] if unstable else None
    out = {"fire_delta": delta[fired[0]] if fired else None, "fire_n": n[fired[0]] if fired else None,
           "false_alarms": sum(1 for i in fired if math.isfinite(smin[i]) and smin[i] >= 0),
           "unverified": sum(1 for i in fired if not math.isfinite(smin[i]) and (i_u is None or i < i_u)),
           "analysed_stable": sum(1 for v in smin if math.isfinite(v) and v >= 0),
           "ratio_at_first_unstable": ratio[i_u] if i_u is not None else None,
           "n_at_first_unstable": n[i_u] if i_u is not None else None,
           "ratio_at_crossing": r.get("at_crossing", {}).get(model),
           "seconds": r["models"][model]["seconds"]}
    if i_u is None:
        out["verdict"] = "no instability found" + (": false alarm" if out["false_alarms"] else "")
        out["miss"] = False
    else:
        out["miss"] = not fired or fired[0] > i_u
        out["verdict"] = "MISS" if out["miss"] else ("in time" if fired[0] == i_u else "early")
    return out


def _fmt(x, f=".3g"):
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, f)


def markdown(rows, meta):
    lines = ["# The hoop-stress indicator against the eigenvalues (issue 44, item 3)", "",
             f"Written by `benchmarks/hoop_indicator.py` at {meta['commit']} ({meta['date']}; {meta['machine']}).  "
             f"`sb.curve(scene, delta_max={meta['delta_max']})`, smooth contact; per state `sb.hoop_indicator` "
             "(`strip`: pointwise `2 sqrt(B Y)|kappa_s|`; `band`: one Galerkin mode over each compressed band; "
             "shellbvp/wrinkling.py) and, in order up to the first unstable state, `sb.stability` (the crossing "
             "narrowed).  *fires*: the first recorded depth with ratio < 1, and its n; *eig*: the located first "
             "instability and its n; *ratio@unst*: the indicator's ratio at the first unstable recorded state "
             "(< 1 needed not to miss on the grid); *ratio@cross*: its ratio at the located crossing itself (< 1: it fired before the instability, whatever the grid); *false*: states analysed stable where it fires; *MISS*: an unstable "
             "state is reached with the indicator silent up to it.", "",
             "| scene | points | eig: first unstable delta (n) | strip fires (n) | strip verdict | strip ratio@unst "
             "| strip ratio@cross | strip false | band fires (n) | band verdict | band ratio@unst | band ratio@cross | band false "
             "| indicator s | stability s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "models" not in r:
            why = r.get("skipped") or ("killed" if r.get("killed") else "crashed")
            lines.append(f"| {r['id']} | | {why} | | | | | | | | | | | | |")
            continue
        f = r["first"]
        eig = "stable" if f is None else f"{f['delta']:.4g} ({f['mode']})"
        if not any(math.isfinite(v) for v in r["stability_min"]):
            eig = "not analysed"
        cells = [r["id"], str(r["points"]), eig]
        for model in MODELS:
            c = r["cmp"][model]
            fire = "never" if c["fire_delta"] is None else f"{c['fire_delta']:.4g} ({_fmt(c['fire_n'], '.1f')})"
            cells += [fire, c["verdict"], _fmt(c["ratio_at_first_unstable"]), _fmt(c["ratio_at_crossing"]),
                      str(c["false_alarms"])]
        cells += [_fmt(r["models"]["strip"]["seconds"] + r["models"]["band"]["seconds"], ".2f"),
                  _fmt(r["stability_s"], ".1f")]
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", *meta["summary"], "", f"Total {meta['seconds']:.0f} s."]
    return "\n".join(lines) + "\n"


def summarise(rows):
    done = [r for r in rows if "models" in r]
    lost = [r for r in done if r["first"] is not None]
    out = [f"{len(done)} curves computed; {len(lost)} lose stability (eigenvalues) before their end."]
    for model in MODELS:
        c = [r["cmp"][model] for r in done]
        misses = [r["id"] for r in lost if r["cmp"][model]["miss"]]
        wrinkle_lost = [r for r in lost if r["first"]["mode"] >= 2]
        wrinkle_misses = [r["id"] for r in wrinkle_lost if r["cmp"][model]["miss"]]
        alarms = sum(x["false_alarms"] for x in c)
        stable_states = sum(x["analysed_stable"] for x in c)
        stable_curves_fired = sum(1 for r in done if r["first"] is None and r["cmp"][model]["fire_delta"] is not None
                                  and any(math.isfinite(v) for v in r["stability_min"]))
        t_ind = sum(x["seconds"] for x in c)
        late = [r["id"] for r in lost if (r["cmp"][model]["ratio_at_crossing"] or 0) >= 1]
        out.append(f"* `{model}`: misses {len(misses)} of {len(lost)} instabilities"
                   + (f" ({', '.join(misses)})" if misses else "")
                   + f"; of the {len(wrinkle_lost)} in modes n >= 2: {len(wrinkle_misses)} missed; "
                   f"fires on {alarms} of {stable_states} states analysed stable, on {stable_curves_fired} curves "
                   f"that stay stable; silent at the located crossing (ratio >= 1 there) on {len(late)}"
                   + (f" ({', '.join(late)})" if late else "") + f"; {t_ind:.1f} s for every state of every curve.")
    scr = [r for r in done if r.get("screen")]
    changed = [r["id"] for r in scr if r["screen"]["full"]["first_unstable"] != r["screen"]["screened"]["first_unstable"]]
    t_full = sum(r["screen"]["full"]["seconds"] for r in scr)
    t_scr = sum(r["screen"]["screened"]["seconds"] for r in scr)
    out.append(f"* `strip` as a screen (modes n = 0, 1 only at states where it is silent, every mode where it "
               f"fires; every state in order up to the first unstable one, no narrowing): {t_scr:.0f} s against "
               f"{t_full:.0f} s with every mode; first unstable state changed on {len(changed)} curves"
               + (f" ({', '.join(changed)})" if changed else "") + ".")
    t_st = sum(r["stability_s"] for r in done if math.isfinite(r["stability_s"]))
    out.append(f"* the eigenvalue analysis (every state up to the first unstable one, then narrowed): {t_st:.0f} s; "
               f"the curves themselves {sum(r['curve_s'] for r in done):.0f} s.")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    ap.add_argument("--only", help="regex on the scene id")
    ap.add_argument("--delta-max", type=float, default=1.0)
    ap.add_argument("--time-limit", type=float, default=600.0, help="seconds per scene")
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
        if "models" in r:
            r["cmp"] = {m: compare(r, m) for m in MODELS}
        print(sid, {m: r["cmp"][m]["verdict"] for m in MODELS} if "cmp" in r else r, flush=True)
        rows.append(r)
    meta = {"commit": commit_label(), "date": datetime.date.today().isoformat(), "delta_max": args.delta_max,
            "machine": f"{platform.platform()}, Python {platform.python_version()}, {os.cpu_count()} cores",
            "seconds": time.perf_counter() - t0, "summary": summarise(rows)}
    suffix = "" if not args.only else "-" + re.sub(r"[^A-Za-z0-9]+", "_", args.only).strip("_")
    suffix = "-quick" if args.quick else suffix
    res = results_dir(args.out_dir)
    (res / f"hoop_indicator{suffix}.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    (res / f"hoop_indicator{suffix}.md").write_text(markdown(rows, meta))
    print(markdown(rows, meta))
    return 0


if __name__ == "__main__":
    sys.exit(main())
