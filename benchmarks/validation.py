"""The shell model's error against 3D elasticity, mapped (issue 41).

For each scene (shell gamma, indenter rho) and thickness eps, the 3D reference
(``shellbvp.fe_curve``: FElupe, axisymmetric u/p/J quadratic elements, neo-Hookean) is
solved at the mid-surface pole displacements delta/H = 0.25, 0.5, 1, 2, 5, 10, 25 (up to
delta 0.5); the shell model at the same depths with beta = eps^2/3, for both contact models
(smooth, paper) and both bending energies (trace, rotation), and with the paper's old map
eps^2/12 for comparison.  Reported: ``F_shell / F_FE - 1``, the contact radius of both, the
FE's own mesh error (``--mesh-check``).

FE curves are cached in ``results/validation.json`` (keyed by scene and eps): a second run
recomputes only what is missing (``--recompute`` to start afresh).  ``--quick``: eps 0.1 and
0.05 on the hemisphere with rho 0.2.

    python benchmarks/validation.py [--quick] [--workers 2] [--mesh-check]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package

import shellbvp as sb  # noqa: E402
from shellbvp.validation import default_depths, shell_curve  # noqa: E402
from checkout import add_output_args, results_dir  # noqa: E402

EPS = (0.1, 0.05, 0.02, 0.01)
#: (gamma, rho): hemisphere and a prolate Lepidium-like shell at three indenter sizes (the
#: prolate one needs gamma < 1/rho), and a dome indented from its convex side.
SCENES = ((1.0, 0.1), (1.0, 0.2), (1.0, 0.5), (2.5, 0.1), (2.5, 0.2), (-1.0, 0.2))
VARIANTS = {  # shell-model variants compared with the same FE curve
    "smooth": dict(contact="smooth", bending=sb.TraceBending()),
    "smooth, rotation": dict(contact="smooth", bending=sb.RotationBending()),
    "paper": dict(contact="paper", bending=sb.TraceBending()),
    "paper, rotation": dict(contact="paper", bending=sb.RotationBending()),
    "smooth, shear": dict(contact="smooth", bending=sb.TraceBending(), transverse_shear=True),
    "smooth, rotation, shear": dict(contact="smooth", bending=sb.RotationBending(), transverse_shear=True),
}
DELTA_MAX = 0.5


def scene_of(gamma, rho, eps, **over):
    return sb.Scene(gamma=gamma, rho=rho, material=sb.NeoHookean(), thickness=eps, **over)


def key(gamma, rho, eps):
    return f"gamma={gamma:g} rho={rho:g} eps={eps:g}"


def fe_case(args):
    gamma, rho, eps, mesh_check = args
    t0 = time.perf_counter()
    depths = default_depths(eps, DELTA_MAX)
    c = sb.fe_curve(scene_of(gamma, rho, eps), eps, depths, mesh_check=mesh_check)
    return key(gamma, rho, eps), {
        "gamma": gamma, "rho": rho, "eps": eps, "delta": c.delta.tolist(), "force": c.force.tolist(),
        "indenter": c.indenter.tolist(), "contact_radius": c.contact_radius.tolist(),
        "mesh_error": c.mesh_error.tolist(), "success": c.success, "message": c.message,
        "elements": list(c.elements), "seconds": time.perf_counter() - t0}


def shell_rows(fe):
    """The shell model's variants at the FE's depths."""
    gamma, rho, eps = fe["gamma"], fe["rho"], fe["eps"]
    d = np.asarray(fe["delta"])
    rows = {}
    plans = dict(VARIANTS)
    plans["smooth, eps^2/12"] = dict(contact="smooth", bending=sb.TraceBending(), beta=eps**2 / 12)
    for name, over in plans.items():
        over = dict(over)
        if "beta" in over:
            scene = sb.Scene(gamma=gamma, rho=rho, material=sb.NeoHookean(), **over)
        else:
            scene = scene_of(gamma, rho, eps, **over)
        t0 = time.perf_counter()
        if scene.transverse_shear:  # forces at the thick shell's depths delta + shear_delta
            c = shell_curve(scene, d)
            rows[name] = {"force": c.force_at(d).tolist(), "seconds": time.perf_counter() - t0}
            continue
        c = sb.curve(scene, deltas=d, estimate_error=False)
        F = np.full(d.size, np.nan)
        rc = np.full(d.size, np.nan)
        topo = [""] * d.size
        for i, x in enumerate(d):
            j = np.flatnonzero(np.isclose(c.points["delta"], x, rtol=1e-9))
            if j.size and c.points["status"][j[0]] == 0:
                F[i] = c.points["force"][j[0]]
                topo[i] = str(c.points["topology"][j[0]])
                sol = c.solutions[j[0]] if j[0] < len(c.solutions) else None
                if sol is not None and topo[i] == "cap":
                    p = sol.profile()
                    rc[i] = float(np.interp(c.points["Sc"][j[0]], p["S"], p["r"]))
        rows[name] = {"force": F.tolist(), "contact_radius": rc.tolist(), "topology": topo,
                      "seconds": time.perf_counter() - t0}
    return rows


def pct(x):
    return f"{100 * x:+.1f}" if np.isfinite(x) else "-"


def report(cache, plan, args):
    from checkout import commit_label

    lines = [f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()}, shellbvp {sb.__version__} at "
             f"{commit_label() or 'unknown commit'}; `python benchmarks/validation.py"
             f"{' --quick' if args.quick else ''}{' --mesh-check' if args.mesh_check else ''}`.", "",
             "F_shell / F_FE - 1 in percent, at the same mid-surface pole displacement delta; the 3D "
             "model is `shellbvp.fe_curve` (FElupe: 9-node u/p/J elements, neo-Hookean, bulk 5000 mu, "
             "3 elements through H, H/2 along the meridian, H/4 near the pole; rim pinned at "
             "mid-thickness; frictionless penalty contact on the surface facing the indenter).  Shell "
             "model: beta = eps^2/3 (`beta_from_thickness`) unless the column says eps^2/12; "
             "'smooth' is the default variational contact, 'paper' the paper's contact conditions; "
             "trace bending unless 'rotation'.", ""]
    summary, wraps = [], {}
    for gamma, rho in plan["scenes"]:
        lines += [f"## gamma {gamma:g}, rho {rho:g}", ""]
        for eps in plan["eps"]:
            fe = cache.get(key(gamma, rho, eps))
            if fe is None:
                continue
            d = np.asarray(fe["delta"])
            ff = np.asarray(fe["force"])
            lines += [f"eps = {eps:g} (FE {fe['elements'][0]}x{fe['elements'][1]} elements, "
                      f"{fe['seconds']:.0f} s{'' if fe['success'] else '; ' + fe['message']})", "",
                      "| delta/H | delta | F_FE | " + " | ".join(fe["shell"]) + " | FE mesh | r_c FE | r_c smooth |",
                      "|" + "---|" * (len(fe["shell"]) + 6)]
            for i, x in enumerate(d):
                errs = [np.asarray(v["force"])[i] / ff[i] - 1 for v in fe["shell"].values()]
                me = fe["mesh_error"][i]
                rs = fe["shell"]["smooth"]["contact_radius"][i]
                lines.append(f"| {x / eps:.3g} | {x:.4g} | {ff[i]:.5g} | " + " | ".join(pct(e) for e in errs)
                             + f" | {'-' if not np.isfinite(me) else f'{100 * me:.2f}'} | "
                             f"{fe['contact_radius'][i]:.4f} | {'-' if not np.isfinite(rs) else f'{rs:.4f}'} |")
                summary.append((gamma, rho, eps, x / eps, {k: errs[j] for j, k in enumerate(fe["shell"])}))
                wraps[(gamma, rho, eps, x / eps)] = fe["contact_radius"][i] >= 0.95 * rho
            lines.append("")
    # the domain: the largest error by thickness and by depth band, over every scene
    bands = (("delta <= H", lambda k, wrap: k <= 1 + 1e-9 and not wrap),
             ("H < delta < 5H", lambda k, wrap: 1 + 1e-9 < k < 5 - 1e-9 and not wrap),
             ("delta >= 5H, contact short of the tip's equator", lambda k, wrap: k >= 5 - 1e-9 and not wrap),
             ("contact round the tip's equator (r_c >= 0.95 rho)", lambda k, wrap: wrap))
    variants = ("smooth", "smooth, shear", "smooth, rotation", "smooth, rotation, shear", "paper")
    lines += ["## Summary: the largest |F_shell / F_FE - 1| over the scenes, by depth", "",
              "Depth bands an experimenter can tell apart: delta against the thickness H, and whether the "
              "contact has spread round the indenter's equator (the FE's contact radius r_c at 0.95 rho or "
              "more: the shell wraps the tip).  Each cell: the largest error in percent, and where "
              "(gamma, rho, delta/H).", "",
              "| eps | depth | " + " | ".join(variants) + " |", "|---|---|" + "---|" * len(variants)]
    for eps in sorted({e for _, _, e, _, _ in summary}, reverse=True):
        for label, test in bands:
            cells = []
            for var in variants:
                sel = [(abs(v[var]), g, r, k) for g, r, e, k, v in summary
                       if e == eps and test(k, wraps[(g, r, e, k)]) and np.isfinite(v[var])]
                if not sel:
                    cells.append("-")
                    continue
                err, g, r, k = max(sel)
                cells.append(f"{100 * err:.1f} ({g:g}, {r:g}, {k:g})")
            lines.append(f"| {eps:g} | {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="eps 0.1 and 0.05 on the hemisphere, rho 0.2")
    ap.add_argument("--workers", type=int, default=2, help="FE curves in parallel (default 2)")
    ap.add_argument("--mesh-check", action="store_true", dest="mesh_check",
                    help="each FE curve also on a coarser mesh (FECurve.mesh_error)")
    ap.add_argument("--recompute", action="store_true", help="ignore the cached FE curves")
    ap.add_argument("--shell-only", action="store_true", dest="shell_only",
                    help="no FE: recompute the shell model's rows of every cached FE curve")
    ap.add_argument("--eps", default=None, help="only these thicknesses, comma-separated (default: 0.1,0.05,0.02,0.01); "
                    "the report shows every cached one")
    add_output_args(ap)
    args = ap.parse_args(argv)
    plan = {"scenes": ((1.0, 0.2),), "eps": (0.1, 0.05)} if args.quick else {"scenes": SCENES, "eps": EPS}
    todo_eps = plan["eps"] if args.eps is None else tuple(float(x) for x in args.eps.split(","))
    suffix = "-quick" if args.quick else ""
    out = results_dir(args.out_dir)
    store = out / f"validation{suffix}.json"
    cache = {} if args.recompute or not store.exists() else json.loads(store.read_text())
    todo = [(g, r, e, args.mesh_check) for g, r in plan["scenes"] for e in todo_eps
            if key(g, r, e) not in cache or not cache[key(g, r, e)].get("success")]
    todo.sort(key=lambda t: t[2])  # thinnest (slowest) first
    if args.shell_only:
        todo = []
        for fe in cache.values():
            fe.pop("shell", None)
    with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        for k, fe in pool.map(fe_case, todo):
            fe["shell"] = shell_rows(fe)
            cache[k] = fe
            print(f"{k}: FE {fe['seconds']:.0f} s, {fe['message']}; smooth "
                  + " ".join(pct(a / b - 1) for a, b in zip(fe["shell"]["smooth"]["force"], fe["force"])), flush=True)
            store.write_text(json.dumps(cache, indent=1, default=float))  # no finished curve is lost
    missing = [k for k, fe in cache.items() if "shell" not in fe]
    with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        for k, rows in zip(missing, pool.map(shell_rows, [cache[k] for k in missing])):
            cache[k]["shell"] = rows
    store.write_text(json.dumps(cache, indent=1, default=float))
    (out / f"validation{suffix}.md").write_text(report(cache, plan, args))
    print(f"wrote {out / f'validation{suffix}.md'}")


if __name__ == "__main__":
    main()
