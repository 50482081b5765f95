"""The first instability with a sticking tip beside the frictionless one (issue 44, open point 4).

``sb.stability(state, friction=...)`` bounds the stability of a state on the tip under any
friction coefficient: free sliding (``"frictionless"``, the default) and no slip
(``"sticking"``: ``u = v = 0`` on the contact set).  For the two curves that
benchmarks/results/stability_modes.md finds unstable in n = 1 (the pole sliding sideways: the
grid scene with rho 0.05 and the one with gamma -2) and for one that goes unstable in n = 3 (the
dome preset at beta 1e-5, rho 0.2), the curve's states are analysed with both (every mode of
:func:`shellbvp.modal_stability.default_modes`; the dome's near its crossing only), and each
first sign change of the smallest eigenvalue is narrowed between its neighbours by solving states
in between (``locate_zero``, to 1e-4 in delta).

Writes benchmarks/results/stability_friction.json and .md.

    python benchmarks/stability_friction.py                # the three cases (a few minutes)
    python benchmarks/stability_friction.py --only rho     # a subset (regex on the id)
    python benchmarks/stability_friction.py --quick [--out-dir DIR]   # stability_friction-quick.* (under DIR/results)
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
from stability import make_scene as grid_scene  # noqa: E402

QUICK = r"^dome"  # --quick: the dome near its crossing only
FRICTIONS = ("frictionless", "sticking")
DELTA_TOL = 1e-4


def cases():
    """(id, scene builder, delta_max, the deltas from which states are analysed, the frictionless
    onset of benchmarks/results/stability_modes.md)."""
    import shellbvp as sb

    return [
        ("grid rho=0.05", lambda: grid_scene({"overrides": {"rho": 0.05}, "contact": "smooth"}), 1.0, 0.0,
         "0.03596, n = 1"),
        ("grid gamma=-2", lambda: grid_scene({"overrides": {"gamma": -2.0}, "contact": "smooth"}), 1.0, 0.0,
         "0.3668, n = 1"),
        ("dome beta=1e-5 rho=0.2", lambda: sb.Scene.preset("dome", beta=1e-5, rho=0.2), 0.1, 0.08,
         "0.08982, n = 3"),
    ]


def analyse(state, friction, modes=None):
    """(smallest eigenvalue, its mode, the n = 1 eigenvalue or NaN, why not analysed)."""
    import numpy as np

    import shellbvp as sb

    try:
        res = sb.stability(state, modes=modes, friction=friction)
    except ValueError as exc:
        return math.nan, -1, math.nan, " ".join(str(exc).split())
    one = np.flatnonzero(res.modes == 1)
    return res.minimum, res.critical_mode, float(res.smallest[one[0]]) if one.size else math.nan, ""


def first_crossing(scene, states, rows, friction, modes):
    """The first sign change of ``friction``'s smallest eigenvalue along the analysed states,
    narrowed between its neighbours: a dict, or None (stable at every analysed state)."""
    import shellbvp as sb
    from shellbvp.curve_stability import locate_zero

    lam = [r[friction]["min"] for r in rows]
    bad = [i for i, v in enumerate(lam) if v < 0]
    if not bad:
        return None
    i = bad[0]
    out = {"bracket_states": [rows[i - 1]["delta"] if i else None, rows[i]["delta"]], "mode_after": rows[i][friction]["mode"]}
    if i == 0 or not math.isfinite(lam[i - 1]):
        out.update(delta=rows[i]["delta"], located=False, message="no stable analysed state before it")
        return out
    found = {}

    def f(delta):
        j = i - 1 if abs(delta - rows[i - 1]["delta"]) <= abs(delta - rows[i]["delta"]) else i
        s = sb.solve(scene, delta=delta, guess=states[j], estimate_error=False)
        if not s.success or s.topology not in (states[i - 1].topology, states[i].topology):
            return math.nan
        value, mode, _, _ = analyse(s, friction, modes)
        found[delta] = (mode, float(s.force))
        return value

    a, fa, b, fb, evals = locate_zero(f, rows[i - 1]["delta"], lam[i - 1], rows[i]["delta"], lam[i], xtol=DELTA_TOL)
    t = fa / (fa - fb) if fa != fb else 0.5
    out.update(delta=a + t * (b - a), bracket=[a, b], located=abs(b - a) <= DELTA_TOL, evaluations=evals,
               mode=found[b][0] if b in found else rows[i][friction]["mode"],
               delta_over_H=(a + t * (b - a)) / math.sqrt(3 * scene.beta))
    return out


def run_case(cid, build, delta_max, analyse_from, reference):
    import numpy as np

    import shellbvp as sb
    from shellbvp.modal_stability import default_elements, default_modes

    t0 = time.perf_counter()
    scene = build()
    scene.model()
    curve = sb.curve(scene, delta_max=delta_max, estimate_error=False)
    t_curve = time.perf_counter() - t0
    states = [s for s in curve.solutions if s.delta >= analyse_from]
    rows = []
    t1 = time.perf_counter()
    for s in states:
        row = {"delta": float(s.delta), "force": float(s.force), "topology": s.topology}
        for friction in FRICTIONS:
            lam, mode, lam1, why = analyse(s, friction)
            row[friction] = {"min": lam, "mode": mode, "n1": lam1, "why": why}
        rows.append(row)
    t_states = time.perf_counter() - t1
    # the mesh: n = 1 and the crossing's mode at twice and four times the elements, on the first
    # state unstable without friction and on the last state
    first_bad = next((i for i, r in enumerate(rows) if r["frictionless"]["min"] < 0), None)
    checks = []
    for i in sorted({i for i in (first_bad, len(rows) - 1) if i is not None}):
        modes = sorted({1, max(rows[i]["frictionless"]["mode"], 0)})
        for friction in FRICTIONS:
            base = default_elements(scene)
            values = [sb.stability(states[i], modes=modes, friction=friction, elements=k * base).smallest.tolist()
                      for k in (1, 2, 4)]
            checks.append({"delta": rows[i]["delta"], "friction": friction, "modes": modes, "elements": base,
                           "smallest": values})
    every = default_modes(scene)
    # the crossing narrowed with every mode for the beta 0.01 scenes (cheap), the modes near the
    # state-level critical one for the dome
    out = {"id": cid, "beta": scene.beta, "thickness": math.sqrt(3 * scene.beta), "reference": reference,
           "curve_points": len(curve), "curve_end": float(curve.delta.max()), "stop": curve.stop_reason,
           "rows": rows, "mesh_checks": checks, "curve_s": t_curve, "states_s": t_states}
    for friction in FRICTIONS:
        modes = None
        crit = {r[friction]["mode"] for r in rows if r[friction]["min"] < 0}
        if scene.beta < 1e-3 and crit:
            near = min(crit)
            modes = np.arange(max(0, near - 2), min(int(every[-1]), near + 2) + 1)
        t2 = time.perf_counter()
        out[friction] = first_crossing(scene, states, rows, friction, modes)
        out[friction + "_locate_s"] = time.perf_counter() - t2
    return out


def verdict(first, rows, friction):
    if first is None:
        unanalysed = [r for r in rows if r[friction]["why"]]
        tail = (f"; {len(unanalysed)} states not analysed from delta {unanalysed[0]['delta']:.3g} "
                f"({unanalysed[0][friction]['why'][:80]}...)" if unanalysed else "")
        return f"stable at every analysed state (to delta {max(r['delta'] for r in rows if not r[friction]['why']):.3g}){tail}"
    if not first["located"]:
        return f"unstable from delta <= {first['delta']:.4g} ({first.get('message', 'not narrowed')})"
    return (f"unstable from delta {first['delta']:.6g} (bracket {first['bracket'][0]:.6g}-{first['bracket'][1]:.6g}; "
            f"delta/H {first['delta_over_H']:.3g}), n = {first['mode']}")


def unstable_ranges(rows, friction):
    """The analysed states' deltas where ``friction``'s smallest eigenvalue is negative, as runs
    of consecutive states ``"a-b"``."""
    runs, current = [], None
    for r in rows:
        if r[friction]["min"] < 0:
            current = [r["delta"], r["delta"]] if current is None else [current[0], r["delta"]]
        elif current is not None:
            runs.append(current)
            current = None
    if current is not None:
        runs.append(current)
    return ", ".join(f"{a:.4g}-{b:.4g}" if a != b else f"{a:.4g}" for a, b in runs) or "none"


def markdown(results, meta):
    lines = ["# The first instability with a frictionless and a sticking tip (issue 44, open point 4)", "",
             f"Written by `benchmarks/stability_friction.py` at {meta['commit']} ({meta['date']}; {meta['machine']}).  "
             "`sb.stability(state, friction=...)` on every state of `sb.curve(scene, delta_max=...)` (smooth "
             "contact; the dome's from delta 0.08), each first sign change narrowed to 1e-4 in delta between its "
             "neighbours.  Frictionless: u, v free on the contact set; sticking: u = v = 0 there (docs/stability.md). "
             "Any friction coefficient's verdict on the (frictionless) state lies between the two: stable without "
             "friction, stable with any; unstable with sticking, unstable with any.  H/R_L = "
             "sqrt(3 beta).", "",
             "| scene | curve to delta | frictionless (stability_modes.md) | frictionless | sticking | s |",
             "|---|---|---|---|---|---|"]
    for r in results:
        s = r["curve_s"] + r["states_s"] + r["frictionless_locate_s"] + r["sticking_locate_s"]
        stop = r["stop"].split(":")[0]  # the reason's first clause
        lines.append(f"| {r['id']} | {r['curve_end']:.3g} ({stop}) | {r['reference']} | "
                     f"{verdict(r['frictionless'], r['rows'], 'frictionless')} | "
                     f"{verdict(r['sticking'], r['rows'], 'sticking')} | {s:.0f} |")
    lines += ["", "Per state: the smallest eigenvalue (its mode) and the n = 1 eigenvalue, frictionless | sticking.", ""]
    for r in results:
        lines += [f"## {r['id']}", "", "Analysed states with a negative eigenvalue: frictionless "
                  f"{unstable_ranges(r['rows'], 'frictionless')}; sticking {unstable_ranges(r['rows'], 'sticking')}.",
                  "", "| delta | topology | min frictionless (n) | n = 1 frictionless | "
                  "min sticking (n) | n = 1 sticking |", "|---|---|---|---|---|---|"]
        for row in r["rows"]:
            a, b = row["frictionless"], row["sticking"]
            if a["why"]:
                lines.append(f"| {row['delta']:.4g} | {row['topology']} | not analysed | | | |")
                continue
            lines.append(f"| {row['delta']:.4g} | {row['topology']} | {a['min']:.4g} ({a['mode']}) | {a['n1']:.4g} | "
                         f"{b['min']:.4g} ({b['mode']}) | {b['n1']:.4g} |")
        lines += ["", "The mesh: the smallest eigenvalue of each mode at the default elements E, 2E and 4E (at a pole "
                  "held at a point, n = 1 depends on the first element's length against the mesh's start S0, whose "
                  "ratio alternates with E: the values alternate).", "",
                  "| delta | friction | E | mode: E, 2E, 4E |", "|---|---|---|---|"]
        for c in r["mesh_checks"]:
            per = "; ".join(f"n = {n}: " + ", ".join(f"{v[k]:.4g}" for v in c["smallest"]) for k, n in enumerate(c["modes"]))
            lines.append(f"| {c['delta']:.4g} | {c['friction']} | {c['elements']} | {per} |")
        lines.append("")
    lines.append(f"Total {meta['seconds']:.0f} s.")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="regex on the scene id")
    add_output_args(ap, quick="the dome near its crossing only")
    args = ap.parse_args()
    if args.quick:
        args.only = QUICK
    t0 = time.perf_counter()
    results = []
    for cid, build, dmax, start, ref in cases():
        if args.only and not re.search(args.only, cid):
            continue
        r = run_case(cid, build, dmax, start, ref)
        print(f"{cid}: frictionless {verdict(r['frictionless'], r['rows'], 'frictionless')}; "
              f"sticking {verdict(r['sticking'], r['rows'], 'sticking')}", flush=True)
        results.append(r)
    meta = {"commit": commit_label(), "date": datetime.date.today().isoformat(),
            "machine": f"{platform.platform()}, Python {platform.python_version()}, {os.cpu_count()} cores",
            "seconds": time.perf_counter() - t0}
    suffix = "" if not args.only else "-" + re.sub(r"[^A-Za-z0-9]+", "_", args.only).strip("_")
    suffix = "-quick" if args.quick else suffix
    res = results_dir(args.out_dir)
    (res / f"stability_friction{suffix}.json").write_text(json.dumps({"meta": meta, "results": results}, indent=1))
    (res / f"stability_friction{suffix}.md").write_text(markdown(results, meta))
    print(markdown(results, meta))
    return 0


if __name__ == "__main__":
    sys.exit(main())
