"""The smooth model past its convexity limit, beside the paper's model and a convex bending energy.

For the base and prolate2 scenes at delta = 0.7, 0.8, 0.9, 1.0: F of the variational (smooth)
contact model with the paper's bending energy (a corner at the contact edge past the limit),
of the paper's contact model, and of the smooth model with the rotation-gradient bending
energy (``sb.RotationBending``, convex: no corner); the jump of lambda_s at the edge; and the
energy-identity error |dE/ddelta - F| with dE/ddelta by Richardson-extrapolated central
differences of E (h = 0.01, 0.005), next to its differencing error.

    python benchmarks/bending_choice.py   # writes benchmarks/results/bending_choice.md
    python benchmarks/bending_choice.py --out-dir /tmp/b   # writes /tmp/b/results/bending_choice.md

``--koiter``: Koiter's energy at Poisson ratio 1/2 (``sb.KoiterBending``) against the paper's
trace energy, for deciding the default (issue 58): F of every preset (``sb.PRESETS``) at
``KOITER_DEPTHS`` with each, their relative difference; and where ``STABILITY_SCENES`` first go
unstable along ``sb.curve(scene, delta_max=1)`` (``assess(curve, "locate")``) with each.

    nice -n 10 python benchmarks/bending_choice.py --koiter   # writes results/bending_koiter.md

``--koiter-map``: the shell model with Koiter's energy, without and with transverse shear, against
the 3D solids of the model's error map (the FE curves kept in ``results/validation.json``, not
solved again), beside the trace energy's stored rows there: the largest ``|F_shell / F_FE - 1|``
by thickness and depth band (``results/bending_koiter_map.md``, its rows in ``..._map.json``: kept, and
not solved again, under the same ``--out-dir``).  The FE curves are read from benchmarks/results/
whatever ``--out-dir`` says: they are this step's input, not its output.
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package

import shellbvp as sb  # noqa: E402
from shellbvp.state import system_like, solve_from, warm_guess  # noqa: E402

sys.path.insert(0, str(HERE))
from checkout import add_output_args, results_dir, write_atomic  # noqa: E402

DELTAS = (0.7, 0.8, 0.9, 1.0)
TOL = 1e-8
#: Depths of the presets' comparison of the two energies
KOITER_DEPTHS = (0.1, 0.3, 0.5)
#: Scenes whose first instability is located with each energy: (label, preset, overrides)
STABILITY_SCENES = (("preset balloon", "balloon", {}), ("base, beta 0.001", "base", {"beta": 0.001}))


def identity_error(sol, h=0.01):
    def E(d):
        sysm = system_like(sol, "delta", d, sol.system.eps)
        s = solve_from(sysm, warm_guess(sysm, sol), tol=TOL, max_nodes=50000)
        return s.energy if s.success else np.nan

    D = [(E(sol.delta + k) - E(sol.delta - k)) / (2 * k) for k in (h, h / 2)]
    return abs((4 * D[1] - D[0]) / 3 - sol.force), abs(D[1] - D[0])


def koiter_rows():
    """(preset, delta, F trace, F koiter, their states' topologies, seconds) of every preset."""
    rows = []
    for name in sb.PRESETS:
        forces, tops, t0 = {}, {}, time.perf_counter()
        for label, bending in (("trace", sb.TraceBending()), ("koiter", sb.KoiterBending())):
            try:
                c = sb.curve(sb.Scene.preset(name, bending=bending), deltas=KOITER_DEPTHS, estimate_error=False)
                ok = {round(float(s.delta), 12): s for s in c.solutions if s.success}
                forces[label] = [float(ok[d].force) if d in ok else math.nan for d in KOITER_DEPTHS]
                tops[label] = [ok[d].topology if d in ok else "-" for d in KOITER_DEPTHS]
            except ValueError as e:  # not a scene for this energy: said, not guessed
                forces[label], tops[label] = [math.nan] * len(KOITER_DEPTHS), [f"refused: {e}"] * len(KOITER_DEPTHS)
        for i, d in enumerate(KOITER_DEPTHS):
            rows.append((name, d, forces["trace"][i], forces["koiter"][i], tops["trace"][i], tops["koiter"][i],
                         time.perf_counter() - t0))
        print(name, [f"{r[3] / r[2] - 1:+.3%}" for r in rows[-len(KOITER_DEPTHS):]], flush=True)
    return rows


def first_instabilities():
    """(label, energy, verdict, delta, mode, seconds) of each of STABILITY_SCENES."""
    from shellbvp.curve_stability import assess

    out = []
    for label, preset, over in STABILITY_SCENES:
        for name, bending in (("trace", sb.TraceBending()), ("koiter", sb.KoiterBending())):
            t0 = time.perf_counter()
            c = sb.curve(sb.Scene.preset(preset, bending=bending, **over), delta_max=1.0, estimate_error=False)
            assess(c, "locate", samples=max(len(c), 1))
            first = c.first_instability
            verdict = (f"stable at every analysed state (to delta {c.delta.max():.3g})" if first is None else
                       f"unstable from delta {first.delta:.4g}, n = {first.mode}"
                       + ("" if first.located else " (not narrowed)"))
            out.append((label, name, verdict, math.nan if first is None else first.delta,
                        -1 if first is None else first.mode, time.perf_counter() - t0))
            print(label, name, verdict, flush=True)
    return out


def koiter_main(res):
    from checkout import commit_label

    t0 = time.perf_counter()
    rows = koiter_rows()
    stab = first_instabilities()
    lines = ["# Koiter's bending energy (Poisson ratio 1/2) against the trace energy (Poisson ratio 1)", "",
             f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} (Python {platform.python_version()}), "
             f"shellbvp {sb.__version__} at {commit_label() or 'unknown commit'}; "
             f"`nice -n 10 python benchmarks/bending_choice.py --koiter`; total {time.perf_counter() - t0:.0f} s.  "
             "Each preset as it is (its own beta, material, contact, pressure), only `bending` changed; "
             f"`sb.curve(scene, deltas={list(KOITER_DEPTHS)})`.  Same beta for both (same plate stiffness).", "",
             "## F of every preset", "",
             "| preset | delta | F trace | F koiter | F koiter / F trace - 1 | state (trace / koiter) |",
             "|---|---|---|---|---|---|"]
    for name, d, ft, fk, tt, tk, _ in rows:
        diff = f"{100 * (fk / ft - 1):+.2f} %" if math.isfinite(ft) and math.isfinite(fk) and ft != 0 else "-"
        lines.append(f"| {name} | {d:g} | {ft:.6g} | {fk:.6g} | {diff} | {tt} / {tk} |")
    finite = [abs(fk / ft - 1) for _, _, ft, fk, *_ in rows if math.isfinite(ft) and math.isfinite(fk) and ft]
    if finite:
        lines += ["", f"Largest |difference| over the presets and depths: {100 * max(finite):.2f} %; median "
                      f"{100 * float(np.median(finite)):.2f} %."]
    lines += ["", "## Where the curve first goes unstable", "",
              "`sb.curve(scene, delta_max=1.0)`, then `assess(curve, \"locate\", samples=len(curve))` "
              "(benchmarks/stability_modes.py's procedure).", "",
              "| scene | energy | verdict | seconds |", "|---|---|---|---|"]
    for label, name, verdict, _, _, secs in stab:
        lines.append(f"| {label} | {name} | {verdict} | {secs:.0f} |")
    out = res / "bending_koiter.md"
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(out)
    print(out.read_text())


def koiter_map_main(res):
    """Koiter's energy on the error map's stored FE curves (module docstring)."""
    import json

    import validation as vmap
    from checkout import commit_label
    from shellbvp.validation import shell_curve

    store = HERE / "results" / "validation.json"
    cache = json.loads(store.read_text())
    out_json = res / "bending_koiter_map.json"
    done = json.loads(out_json.read_text()) if out_json.exists() else {}
    for k, fe in cache.items():
        if not fe.get("success") or k in done:
            continue
        d = np.asarray(fe["delta"], float)
        row = {}
        for label, shear in (("smooth, koiter", False), ("smooth, koiter, shear", True)):
            scene = vmap.scene_of(fe["gamma"], fe["rho"], fe["eps"], bending=sb.KoiterBending(), transverse_shear=shear)
            row[label] = shell_curve(scene, d).force_at(d).tolist()
        done[k] = row
        tmp = out_json.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(done, indent=1, default=float))
        tmp.replace(out_json)
        print(k, flush=True)
    variants = ("smooth", "smooth, koiter", "smooth, shear", "smooth, koiter, shear")
    bands = (("delta <= H", lambda k, wrap: k <= 1 + 1e-9 and not wrap),
             ("H < delta < 5H", lambda k, wrap: 1 + 1e-9 < k < 5 - 1e-9 and not wrap),
             ("delta >= 5H, short of the tip's equator", lambda k, wrap: k >= 5 - 1e-9 and not wrap),
             ("contact round the tip's equator", lambda k, wrap: wrap))
    summary = []
    for k, fe in cache.items():
        if k not in done:
            continue
        ff = np.asarray(fe["force"], float)
        forces = {v: np.asarray(fe["shell"][v]["force"], float) for v in ("smooth", "smooth, shear")}
        forces.update({v: np.asarray(done[k][v], float) for v in ("smooth, koiter", "smooth, koiter, shear")})
        for i, x in enumerate(fe["delta"]):
            wrap = fe["contact_radius"][i] >= 0.95 * fe["rho"]
            summary.append((fe["eps"], x / fe["eps"], wrap, {v: forces[v][i] / ff[i] - 1 for v in variants}))
    lines = ["# Koiter's energy on the model's error map", "",
             f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()}, shellbvp {sb.__version__} at "
             f"{commit_label() or 'unknown commit'}; `nice -n 10 python benchmarks/bending_choice.py --koiter-map`.  "
             "The 3D solids and the trace energy's rows ('smooth', 'smooth, shear') are those kept in "
             "results/validation.json (benchmarks/validation.py: the hemisphere and a prolate shell at rho 0.1-0.5, "
             "a dome; neo-Hookean; beta = eps^2/3); 'koiter' the same shell model with `sb.KoiterBending()`, "
             "solved here at the solid's depths.  Each cell: the largest |F_shell / F_FE - 1| in percent over the "
             f"scenes ({len(done)} FE curves).", "",
             "| eps | depth | " + " | ".join(variants) + " |", "|---|---|" + "---|" * len(variants)]
    for eps in sorted({e for e, *_ in summary}, reverse=True):
        for label, test in bands:
            cells = []
            for v in variants:
                sel = [abs(e[v]) for ee, kk, w, e in summary if ee == eps and test(kk, w) and np.isfinite(e[v])]
                cells.append(f"{100 * max(sel):.1f}" if sel else "-")
            lines.append(f"| {eps:g} | {label} | " + " | ".join(cells) + " |")
    diffs = [abs((1 + e["smooth, koiter"]) / (1 + e["smooth"]) - 1) for *_, e in summary
             if np.isfinite(e["smooth, koiter"]) and np.isfinite(e["smooth"])]
    if diffs:
        lines += ["", f"F koiter / F trace - 1 (no shear) over the map's points: largest {100 * max(diffs):.1f} %, "
                      f"median {100 * float(np.median(diffs)):.2f} %."]
    out = res / "bending_koiter_map.md"
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(out)
    print(out.read_text())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--koiter", action="store_true", help="Koiter's energy against the trace energy "
                    "(results/bending_koiter.md) instead of the convexity table")
    ap.add_argument("--koiter-map", action="store_true", dest="koiter_map",
                    help="Koiter's energy on the error map's stored 3D solids (results/bending_koiter_map.md)")
    args = add_output_args(ap).parse_args(argv)
    res = results_dir(args.out_dir)
    if args.koiter_map:
        return koiter_map_main(res)
    if args.koiter:
        return koiter_main(res)
    rows, t0 = [], time.perf_counter()
    variants = (("smooth, paper's B (corner)", dict()), ("paper's contact model", dict(contact="paper")),
                ("smooth, rotation B", dict(bending=sb.RotationBending())))
    for preset in ("base", "prolate2"):
        for label, kw in variants:
            scene = sb.Scene.preset(preset, **kw)
            c = sb.curve(scene, deltas=DELTAS, tol=TOL, estimate_error=False, max_nodes=50000)
            for s in c.solutions:
                err, scale = identity_error(s) if s.success else (np.nan, np.nan)
                rows.append((preset, label, s.delta, s.force, s.contact_edge, s.edge_jump_ls, err, scale, s.valid))
            print(preset, label, c.summary(), flush=True)
    out = res / "bending_choice.md"
    lines = [f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} ({platform.python_version()}), "
             f"shellbvp {sb.__version__}; `sb.curve(scene, deltas={list(DELTAS)}, tol={TOL:g})`; "
             f"total {time.perf_counter() - t0:.0f} s.", "",
             "| scene | model | delta | F | contact edge | jump of lambda_s at the edge | "
             "\\|dE/dδ − F\\| (Richardson) | its differencing error | valid |",
             "|---|---|---|---|---|---|---|---|---|"]
    for preset, label, d, F, edge, jump, err, scale, valid in rows:
        lines.append(f"| {preset} | {label} | {d:.2f} | {F:.6f} | {edge} | {jump:.4f} | {err:.1e} | {scale:.1e} | "
                     f"{'yes' if valid else 'no'} |")
    lines += ["", "The paper's contact model has no energy identity (its edge conditions are not the natural ones): "
              "its error is the model's, not the solver's."]
    write_atomic(out, "\n".join(lines) + "\n")
    print(out.read_text())


if __name__ == "__main__":
    main()
