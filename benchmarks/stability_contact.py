"""Stability of states on the tip: folds and the first non-axisymmetric crossings (issue 44, item 2).

* ``dome fold``: the convex dome of tests/test_dome.py (a spherical cap of radius 5 over the
  rim radius 1, rho 0.05, beta 1e-5, Mooney-Rivlin 0.1) turns back in delta near 0.18289 (a
  snap under displacement control).  Its n = 0 eigenvalue (``sb.stability``, pole held: the
  contact there is a line of radius < 1e-9, inside the mesh's start S0) is bracketed on states
  of the curve and, past its last point, on force-controlled states round the fold; the zero
  is refined by Brent's method in F, and the fold itself located independently as the largest
  delta over F (bounded scalar search).
* ``base curve``: the default scene's curve to delta 1: every point's n = 0 eigenvalue (no
  fold: all positive) and the smallest over all n.
* ``dome onset``: the same dome at rho 0.05, 0.2, 0.5: along the curve, the first sign change of
  the smallest eigenvalue over n >= 2 (and over n >= 1), refined by Brent's method in delta
  (each delta its own state, warm-started from its neighbour), with its n, the depth over the
  thickness ``H = sqrt(3 beta) R_L`` (``shellbvp.units.beta_from_thickness``: beta = eps^2/3)
  and over the paper's ``sqrt(12 beta)``, and the eigenvalue there with twice the elements.

Writes benchmarks/results/stability_contact.md (and .json).

    python benchmarks/stability_contact.py
    python benchmarks/stability_contact.py --rewrite   # the .md again from the .json
"""

from __future__ import annotations

import json
import math
import platform
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq, minimize_scalar

import shellbvp as sb
from shellbvp import modal_stability as st

OUT = Path(__file__).parent / "results"
RS = 5.0
BETA = 1e-5
FOLD = 0.18289  # tests/test_dome.py


def dome(rho=0.05):
    shell = sb.UserShell(f"{RS}*sin(S/{RS})", f"{RS}*cos(S/{RS})", f"{RS}*asin(1/{RS})")
    return sb.Scene(rho=rho, beta=BETA, material=sb.MooneyRivlin(0.1), shell=shell)


def lam0(state):
    return float(st.stability(state, modes=[0]).smallest[0])


def dome_fold():
    t0 = time.perf_counter()
    scene = dome()
    curve = sb.curve(scene, delta_max=0.25)
    rows = [{"delta": s.delta, "force": s.force, "topology": s.topology, "lambda0": lam0(s)}
            for s in curve.solutions]
    states = {}

    def at_force(F, guess):
        s = sb.solve(scene, force=F, guess=guess, estimate_error=False, tol=1e-8)
        if not s.success:
            raise RuntimeError(f"no state at F = {F}: {s.message}")
        states[F] = s
        return s

    guess = curve.solutions[-1]
    forces = np.linspace(guess.force, 1.1e-4, 12)[1:]
    for F in forces:  # down the falling force, round the fold
        guess = at_force(F, guess)
        rows.append({"delta": guess.delta, "force": F, "topology": guess.topology, "lambda0": lam0(guess),
                     "forced": True})

    def nearest(F):
        return states[min(states, key=lambda k: abs(k - F))]

    forced = [r for r in rows if r.get("forced")]
    i = next(k for k in range(1, len(forced)) if forced[k - 1]["lambda0"] > 0 >= forced[k]["lambda0"])
    a, b = forced[i - 1]["force"], forced[i]["force"]
    F_zero = brentq(lambda F: lam0(at_force(F, nearest(F))), b, a, xtol=1e-12)
    zero = at_force(F_zero, nearest(F_zero))
    top = minimize_scalar(lambda F: -at_force(F, nearest(F)).delta, bounds=(forces[-1], forces[0]),
                          method="bounded", options={"xatol": 1e-12})
    fold = nearest(top.x)
    return {"rows": rows, "F_zero": F_zero, "delta_zero": zero.delta, "topology_zero": zero.topology,
            "line_radius_zero": zero.S1, "F_fold": float(top.x), "delta_fold": fold.delta,
            "curve_stop": curve.stop_reason, "seconds": time.perf_counter() - t0}


def base_curve():
    t0 = time.perf_counter()
    curve = sb.curve(sb.Scene.preset("base"), delta_max=1.0)
    rows = []
    for s in curve.solutions:
        try:
            res = st.stability(s)
            rows.append({"delta": s.delta, "topology": s.topology, "lambda0": float(res.smallest[0]),
                         "minimum": res.minimum, "n": res.critical_mode})
        except ValueError as e:
            rows.append({"delta": s.delta, "topology": s.topology, "refused": str(e)})
    return {"rows": rows, "seconds": time.perf_counter() - t0, "stop": curve.stop_reason}


def smallest(state, first, elements=None):
    res = st.stability(state, elements=elements)
    keep = res.modes >= first
    k = int(np.argmin(res.smallest[keep]))
    return float(res.smallest[keep][k]), int(res.modes[keep][k])


def onset(rho, first):
    """The first crossing of the smallest eigenvalue over n >= first along the dome's curve."""
    t0 = time.perf_counter()
    scene = dome(rho)
    curve = sb.curve(scene, delta_max=0.25)
    scan = []
    for s in curve.solutions:
        lam, n = smallest(s, first)
        scan.append((s, lam, n))
        if lam < 0:
            break
    k = next((i for i in range(1, len(scan)) if scan[i - 1][1] > 0 >= scan[i][1]), None)
    if k is None:
        return {"rho": rho, "first": first, "found": False, "seconds": time.perf_counter() - t0,
                "last": scan[-1][0].delta}
    lo, hi = scan[k - 1][0], scan[k][0]
    cache = {}

    def state(d):
        g = min((lo, hi, *cache.values()), key=lambda s: abs(s.delta - d))
        s = sb.solve(scene, delta=d, guess=g, estimate_error=False)
        if not s.success:
            raise RuntimeError(s.message)
        cache[d] = s
        return s

    d = brentq(lambda d: smallest(state(d), first)[0], lo.delta, hi.delta, xtol=1e-6)
    s = state(d)
    lam, n = smallest(s, first)
    elements = st.default_elements(scene)
    lam2, n2 = smallest(s, first, elements=2 * elements)
    # the crossing's shift with twice the elements: lambda2 over the slope of lambda in delta
    slope = (scan[k][1] - scan[k - 1][1]) / (hi.delta - lo.delta)
    return {"rho": rho, "first": first, "found": True, "delta": d, "n": n, "topology": s.topology,
            "Sc": s.Sc, "S1": s.S1, "force": s.force, "elements": elements, "n_2x": n2,
            "shift_2x": -lam2 / slope, "over_H": d / math.sqrt(3 * BETA), "over_h12": d / math.sqrt(12 * BETA),
            "bracket": [lo.delta, hi.delta], "seconds": time.perf_counter() - t0}


def write(res):
    OUT.mkdir(exist_ok=True)
    (OUT / "stability_contact.json").write_text(json.dumps(res, indent=1, default=str))
    f = res["fold"]
    lines = ["# Stability of states on the tip: the dome's fold and the first non-axisymmetric crossings", "",
             "Written by `benchmarks/stability_contact.py` (issue 44, item 2).  Dome: the spherical cap of "
             "radius 5 over the rim radius 1 of tests/test_dome.py, turned convex side up, beta 1e-5, Mooney-Rivlin "
             "0.1, trace bending, xi = 1, smooth contact; `sb.stability` with its default mesh and modes.", "",
             "## n = 0 at the dome's fold (rho 0.05)", "",
             f"* the natural curve stops at: {f['curve_stop']}",
             "* past its last point the states are force-controlled, round the fold; their contact is a line of "
             "radius < 1e-9 (inside the mesh's start S0 = 1e-4: the pole held at a point).",
             f"* the n = 0 eigenvalue changes sign at F = {f['F_zero']:.6e}, delta = **{f['delta_zero']:.6f}** "
             f"(Brent in F); the largest delta over F (the fold, located without the eigenvalue) is "
             f"{f['delta_fold']:.6f} at F = {f['F_fold']:.6e}; tests/test_dome.py's fold: {FOLD}.",
             f"* |delta_zero - {FOLD}| = {abs(f['delta_zero'] - FOLD):.1e}, |delta_zero - delta_fold| = "
             f"{abs(f['delta_zero'] - f['delta_fold']):.1e}; time {f['seconds']:.0f} s.", "",
             "| delta | F | topology | n = 0 eigenvalue |", "|---|---|---|---|"]
    for r in f["rows"][-16:]:
        lines.append(f"| {r['delta']:.6f} | {r['force']:.5e} | {r['topology']}{' (F given)' if r.get('forced') else ''} "
                     f"| {r['lambda0']:.4g} |")
    b = res["base"]
    ok = [r for r in b["rows"] if "lambda0" in r]
    refused = [r for r in b["rows"] if "refused" in r]
    lines += ["", "## The base scene's curve (default scene) to delta 1", "",
              f"* {len(ok)} of {len(b['rows'])} points analysed ("
              f"{', '.join(sorted({r['topology'] for r in ok}))}, delta {ok[0]['delta']:.3g} to {ok[-1]['delta']:.3g}); "
              + (f"refused from delta {refused[0]['delta']:.3g}: {sorted({r['refused'] for r in refused})}"
                 if refused else "none refused"),
              f"* n = 0 eigenvalue: min {min(r['lambda0'] for r in ok):.4g}, all positive: "
              f"{all(r['lambda0'] > 0 for r in ok)} (no fold)",
              f"* smallest over all n: min {min(r['minimum'] for r in ok):.4g} (n = "
              f"{min(ok, key=lambda r: r['minimum'])['n']}), stable at every point: "
              f"{all(r['minimum'] > 0 for r in ok)}; curve stop: {b['stop']}; time {b['seconds']:.0f} s", ""]
    lines += ["## First crossing along the dome's curve, by rho", "",
              "H = sqrt(3 beta) = 0.00548 (`shellbvp.units.beta_from_thickness`, beta = eps^2/3); the paper's "
              "h = sqrt(12 beta) = 0.01095 beside it.  `shift 2x`: how far the crossing moves with twice the "
              "elements (the eigenvalue there over its slope in delta).", "",
              "| rho | modes | delta_c | delta_c/H | delta_c/h | n | topology at delta_c | F | shift 2x | time |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for o in res["onset"]:
        if not o["found"]:
            lines.append(f"| {o['rho']} | n >= {o['first']} | none to {o['last']:.4f} | | | | | | | {o['seconds']:.0f} s |")
            continue
        lines.append(f"| {o['rho']} | n >= {o['first']} | {o['delta']:.5f} | {o['over_H']:.2f} | {o['over_h12']:.2f} | "
                     f"{o['n']} | {o['topology']} | {o['force']:.4e} | {o['shift_2x']:.1e} | {o['seconds']:.0f} s |")
    lines += ["", "The crossing hardly depends on rho: the contact (a point, a cap of radius 0.001 or 0.012) is "
              "small against the dimple whose edge buckles, and the states at the crossing carry the same force "
              "to 1e-4.", "", "Literature (searched in the stored pages; only the opening of each is stored): Vaziri & "
              "Mahadevan, PNAS 105 (2008) 7913, and Nasto's thesis (MIT 2013) / Nasto et al. state that past a "
              "critical indentation the deformation ceases to be axisymmetric (s-cones), and that the indenter's "
              "curvature affects it; the critical depths and mode numbers themselves were not in the stored text, "
              "so none are quoted here.", "",
              f"Total {res['seconds']:.0f} s. {platform.platform()}, Python {platform.python_version()}, "
              f"{time.strftime('%Y-%m-%d')}; 2 shared cores.", ""]
    (OUT / "stability_contact.md").write_text("\n".join(lines))


def main():
    import sys

    if "--rewrite" in sys.argv:  # the report again from the stored numbers
        write(json.loads((OUT / "stability_contact.json").read_text()))
        return
    t0 = time.perf_counter()
    res = {"fold": dome_fold()}
    print("fold", res["fold"]["delta_zero"], res["fold"]["delta_fold"], flush=True)
    res["base"] = base_curve()
    print("base done", flush=True)
    res["onset"] = []
    for rho in (0.05, 0.2, 0.5):
        for first in (2, 1):
            o = onset(rho, first)
            print(o, flush=True)
            res["onset"].append(o)
    res["seconds"] = time.perf_counter() - t0
    write(res)


if __name__ == "__main__":
    main()
