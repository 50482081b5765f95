"""The hemisphere under external pressure against the classical buckling pressure (issue 44, item 4).

For beta in 1e-4, 1e-5, 1e-6 (gamma = 1, neo-Hookean... the scene's default Mooney-Rivlin 0.1,
trace bending, xi = 1; the pressure below the bowl pushes on its convex side):

* ``sphere``: the complete sphere's membrane state (the hemisphere continued through its
  equator, no rim), symmetric family at n = 2 and 3 (every degree l >= 2): the pressure where
  its smallest eigenvalue crosses zero, over ``p_c = 4 sqrt(3 beta)``; with the default mesh
  and twice as many elements;
* ``held rim``: the inflated state of ``sb.inflate`` (rim held: lambda_theta = 1, z = 0,
  M_s = 0) and its smallest eigenvalue over n >= 2 (``stability``'s default modes): the
  pressure of the sign change, bracketed on a scan and refined by regula falsi on the
  eigenvalue (each pressure its own inflated state), the critical n, where the mode's normal
  displacement peaks (distance from the rim in bending lengths ``(3 beta)^(1/4)``), and the
  local estimate ``n ~ k_c r`` at that place (``k_c = (3/beta)^(1/4)``).

Writes benchmarks/results/stability_pressure.md (and .json).

    python benchmarks/stability_pressure.py            # beta 1e-4, 1e-5, 1e-6
    python benchmarks/stability_pressure.py --betas 1e-4
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

import shellbvp as sb
from shellbvp import modal_stability as st

OUT = Path(__file__).parent / "results"


def classical(beta):
    return 4 * math.sqrt(3 * beta)


def sphere_check(beta, factor=1):
    t0 = time.perf_counter()
    elements = factor * st.default_elements(sb.Scene(gamma=1, beta=beta))

    def smallest(f):
        scene = sb.Scene(gamma=1, beta=beta, pressure=f * classical(beta))
        base = st.sphere_base(st.sphere_stretch(scene))
        return st.spectrum(scene, base, 1.5e-4, math.pi / 2, modes=[2, 3], elements=elements,
                           end="symmetric").minimum

    f = brentq(smallest, 0.9, 1.1, xtol=1e-5)
    return {"beta": beta, "elements": elements, "p_over_pc": f, "seconds": time.perf_counter() - t0}


def held_rim(beta, scan=(0.6, 0.7, 0.8, 0.9), rtol=2e-3, elements=None, shell=None, pc=None, first_mode=2):
    """Bracket and refine the held-rim shell's first crossing over n >= first_mode (the
    hemisphere by default)."""
    t0 = time.perf_counter()
    pc = pc or classical(beta)
    cache = {}
    scene_of = (lambda p: sb.Scene(gamma=1, beta=beta, pressure=p)) if shell is None else (
        lambda p: sb.Scene(shell=shell, beta=beta, pressure=p))

    def at(f):
        if f not in cache:
            state = sb.inflate(scene_of(f * pc))
            if not state.success:
                cache[f] = (None, state.message)
            else:
                res = st.stability(state, modes=st.default_modes(state.scene)[first_mode:], elements=elements,
                                   vectors=True)
                cache[f] = (res, "")
            r = cache[f][0]
            print(f"  beta {beta:g} p/p_c {f:.5f}: " + (f"min {r.minimum:.5g} at n {r.critical_mode} "
                  f"({r.wall_time:.1f} s)" if r else cache[f][1]), flush=True)
        return cache[f][0]

    lo = hi = None
    for f in scan:
        r = at(f)
        if r is None:
            break
        if r.minimum > 0:
            lo = f
        else:
            hi = f
            break
    if lo is None or hi is None:
        return {"beta": beta, "found": False, "seconds": time.perf_counter() - t0,
                "note": "no sign change on the scan " + ", ".join(f"{f:g}" for f in scan)}
    # regula falsi (Illinois) on the smallest eigenvalue over n >= 2
    flo, fhi = at(lo).minimum, at(hi).minimum
    side = 0
    while hi - lo > rtol * lo:
        f = hi - fhi * (hi - lo) / (fhi - flo)
        f = min(max(f, lo + 0.05 * (hi - lo)), hi - 0.05 * (hi - lo))
        v = at(f).minimum
        if v > 0:
            lo, flo = f, v
            if side == -1:
                fhi /= 2
            side = -1
        else:
            hi, fhi = f, v
            if side == 1:
                flo /= 2
            side = 1
    f = hi - fhi * (hi - lo) / (fhi - flo) if fhi != flo else hi
    r = at(hi)
    n = r.critical_mode
    mode = r.vectors[n]
    k = int(np.argmax(np.abs(mode["w"])))
    S_peak = float(mode["S"][k])
    kc = (3 / beta) ** 0.25
    state = sb.inflate(scene_of(hi * pc))
    prof = state.profile()
    r_peak = float(np.interp(S_peak, prof["S"], prof["r"]))
    return {"beta": beta, "found": True, "p_over_pc": f, "bracket": [lo, hi], "n": n, "S_peak": S_peak,
            "rim_distance_in_bending_lengths": (math.pi / 2 - S_peak) * kc,
            "n_local_estimate": kc * r_peak, "elements": r.elements, "modes": [int(r.modes[0]), int(r.modes[-1])],
            "pressures_solved": len(cache), "seconds": time.perf_counter() - t0}


#: solve_bvp's node limit while bisecting for the cap's stop (a stalled continuation otherwise
#: grows its mesh to inflate's default limit, minutes per try)
FOLD_NODES = 8000
CAP = ("5*sin(S/5)", "-5*cos(S/5)", "5*asin(1/5)")  # a spherical cap of radius 5 over the rim radius 1


def shallow_cap(beta=1e-5):
    """The pinned shallow cap (sphere radius 5, rim radius 1) under external pressure: where the
    axisymmetric continuation (``inflate``) stops, the n = 0 eigenvalue on the way there, and the
    first non-axisymmetric crossing (n >= 1).  p_c = 4 sqrt(3 beta)/25 (the sphere's radius 5)."""
    t0 = time.perf_counter()
    shell = sb.UserShell(*CAP)
    pc = classical(beta) / 25

    def state(f, max_nodes=FOLD_NODES):
        return sb.inflate(sb.Scene(shell=shell, beta=beta, pressure=f * pc), max_nodes=max_nodes)

    lo, hi = 0.84, 0.86
    assert state(lo).success and not state(hi).success
    while hi - lo > 1e-4:
        mid = (lo + hi) / 2
        ok = state(mid).success
        print(f"  cap p/p_c {mid:.5f}: inflate {'reached' if ok else 'stalled'}", flush=True)
        lo, hi = (mid, hi) if ok else (lo, mid)
    fold = lo
    approach = []
    for d in (3e-2, 1e-2, 3e-3, 1e-3):
        f = fold * (1 - d)
        res = st.stability(state(f), modes=[0])
        approach.append({"p_over_pc": f, "distance": d, "n0_eigenvalue": float(res.smallest[0])})
        print(f"  cap p/p_c {f:.6f}: n = 0 eigenvalue {res.smallest[0]:.4g}", flush=True)
    d = np.array([a["distance"] for a in approach])
    lam = np.array([a["n0_eigenvalue"] for a in approach])
    exponent = float(np.polyfit(np.log(d), np.log(lam), 1)[0])
    # at a fold lambda_0^2 is linear in p: its zero from the two nearest pressures
    f = np.array([a["p_over_pc"] for a in approach])
    zero = float(f[-1] - lam[-1] ** 2 * (f[-1] - f[-2]) / (lam[-1] ** 2 - lam[-2] ** 2))
    asym = held_rim(beta, scan=(0.5, 0.6, 0.7, 0.8), shell=shell, pc=pc, first_mode=1)
    return {"beta": beta, "p_c": pc, "stall_p_over_pc": fold, "approach": approach, "n0_exponent": exponent, "n0_zero_p_over_pc": zero,
            "asymmetric": asym, "seconds": time.perf_counter() - t0}


def main():
    t0 = time.perf_counter()
    ap = argparse.ArgumentParser()
    ap.add_argument("--betas", type=float, nargs="*", default=[1e-4, 1e-5, 1e-6])
    ap.add_argument("--no-cap", action="store_true", help="skip the shallow cap")
    ap.add_argument("--cap-only", action="store_true", help="only the shallow cap")
    args = ap.parse_args()
    rows = []
    for beta in ([] if args.cap_only else args.betas):
        sph = sphere_check(beta)
        sph2 = sphere_check(beta, factor=2)
        print(f"beta {beta:g}: sphere {sph['p_over_pc']:.5f} ({sph['elements']} el.), "
              f"{sph2['p_over_pc']:.5f} ({sph2['elements']} el.)", flush=True)
        rim = held_rim(beta)
        print(f"beta {beta:g}: held rim {rim}", flush=True)
        fine = held_rim(beta, scan=(rim["bracket"][0] * 0.99, rim["bracket"][1] * 1.01),
                        elements=2 * rim["elements"]) if rim["found"] else {"found": False}
        rows.append({"beta": beta, "p_c": classical(beta), "sphere": sph, "sphere_fine": sph2, "held_rim": rim,
                     "held_rim_fine": fine})
    cap = shallow_cap() if not args.no_cap else None
    OUT.mkdir(exist_ok=True)
    meta = {"machine": platform.platform(), "python": platform.python_version(),
            "date": time.strftime("%Y-%m-%d")}
    (OUT / "stability_pressure.json").write_text(json.dumps({"meta": meta, "rows": rows, "cap": cap}, indent=1))
    lines = ["# The hemisphere under external pressure: first zero eigenvalue against p_c = 4 sqrt(3 beta)", "",
             "Written by `benchmarks/stability_pressure.py` (issue 44).  gamma = 1, Mooney-Rivlin 0.1, trace "
             "bending, xi = 1; the pressure below the bowl pushes on its convex side.  `sphere`: the complete "
             "sphere's membrane state (no rim), degrees l >= 2, default mesh (and twice the elements); "
             "`held rim`: `sb.inflate`'s state with its rim held (lambda_theta = 1, z = 0, M_s = 0), smallest "
             "eigenvalue over n >= 2, bracketed in the pressure (each pressure its own inflated state).  "
             "`peak`: where the critical mode's |w| is largest, as distance from the rim in bending lengths "
             "(3 beta)^(1/4); `k_c r`: the local estimate of n there, k_c = (3/beta)^(1/4).", "",
             "| beta | p_c classical | sphere p/p_c (2x mesh) | held rim p/p_c (2x mesh) | n | k_c r at peak "
             "| peak from rim | mode | time held rim |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        sph, sph2, rim, fine = row["sphere"], row["sphere_fine"], row["held_rim"], row["held_rim_fine"]
        if rim["found"]:
            kind = "rim" if rim["rim_distance_in_bending_lengths"] < 4 else "interior"
            fine_p = f"{fine['p_over_pc']:.4f}" if fine["found"] else "--"
            lines.append(f"| {row['beta']:g} | {row['p_c']:.5g} | {sph['p_over_pc']:.4f} ({sph2['p_over_pc']:.4f}) "
                         f"| {rim['p_over_pc']:.4f} ({fine_p}) | {rim['n']} | {rim['n_local_estimate']:.1f} "
                         f"| {rim['rim_distance_in_bending_lengths']:.2f} | {kind} | {rim['seconds']:.0f} s |")
        else:
            lines.append(f"| {row['beta']:g} | {row['p_c']:.5g} | {sph['p_over_pc']:.4f} ({sph2['p_over_pc']:.4f}) "
                         f"| -- | -- | -- | -- | {rim['note']} | {rim['seconds']:.0f} s |")
    if cap:
        a = cap["asymmetric"]
        lines += ["", f"## Pinned shallow cap (sphere radius 5, rim radius 1, beta {cap['beta']:g}), p_c = "
                  f"4 sqrt(3 beta)/25 = {cap['p_c']:.5g}", "",
                  f"* the axisymmetric continuation (`inflate`) stops at p = {cap['stall_p_over_pc']:.5f} p_c "
                  f"(bisection on its success, to 1e-4, solve_bvp's nodes limited to {FOLD_NODES});",
                  "* the n = 0 eigenvalue on the way there, at p = p_stall (1 - d): " + ", ".join(
                      f"d = {x['distance']:g}: {x['n0_eigenvalue']:.3g}" for x in cap["approach"])
                  + f"; log-log slope {cap['n0_exponent']:.2f} (a fold: 1/2), and lambda_0^2, linear in p, "
                  f"vanishes at p = {cap['n0_zero_p_over_pc']:.5f} p_c: the stop is the axisymmetric fold;",
                  (f"* the first non-axisymmetric crossing (n >= 1) comes before it: p = {a['p_over_pc']:.4f} p_c, "
                   f"n = {a['n']}, |w| peaking at S = {a['S_peak']:.3f} (rim at {5 * math.asin(0.2):.3f})."
                   if a["found"] else f"* no non-axisymmetric crossing on the scan ({a['note']})."),
                  f"* time {cap['seconds']:.0f} s."]
    lines += ["", f"Total {time.perf_counter() - t0:.0f} s. {meta['machine']}, Python {meta['python']}, {meta['date']}; 2 shared cores.", ""]
    (OUT / "stability_pressure.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
