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

* ``pinned cap``: a shallow spherical cap (sphere radius 5 over the rim radius 1, beta 1e-5)
  with the package's simply supported rim: its axisymmetric fold and first non-axisymmetric
  crossing;
* ``clamped caps``: the same cap with its rim clamped (``Scene(rim="clamped")``: the slope held
  too), at beta chosen for the cap parameters lambda of the literature's tables (default 6, 8,
  12; and a cap of sphere radius 10 at lambda 8), against Huang 1964 / Teng & Rotter 1989b (first asymmetric bifurcation, p/p_c and n) and
  Budiansky 1959 (axisymmetric snap, lambda <= 8).

Writes benchmarks/results/stability_pressure.md (and .json).

    python benchmarks/stability_pressure.py            # beta 1e-4, 1e-5, 1e-6, the caps
    python benchmarks/stability_pressure.py --betas 1e-4
    python benchmarks/stability_pressure.py --only clamped --lambdas 6 8 12 --shallower 8   # others from the .json
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

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path

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


def held_rim(beta, scan=(0.6, 0.7, 0.8, 0.9), rtol=2e-3, elements=None, shell=None, pc=None, first_mode=2,
             rim="pinned"):
    """Bracket and refine the held-rim shell's first crossing over n >= first_mode (the
    hemisphere by default; ``rim`` as ``Scene.rim``)."""
    t0 = time.perf_counter()
    pc = pc or classical(beta)
    cache = {}
    scene_of = (lambda p: sb.Scene(gamma=1, beta=beta, pressure=p, rim=rim)) if shell is None else (
        lambda p: sb.Scene(shell=shell, beta=beta, pressure=p, rim=rim))

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


def shallow_cap(beta=1e-5, rim="pinned", bracket=(0.84, 0.86), scan=(0.5, 0.6, 0.7, 0.8)):
    """The shallow cap (sphere radius 5, rim radius 1; ``rim`` as ``Scene.rim``) under external
    pressure: where the axisymmetric continuation (``inflate``) stops, the n = 0 eigenvalue on the
    way there, and the first non-axisymmetric crossing (n >= 1), looked for on ``scan`` (p/p_c)
    and refined.  p_c = 4 sqrt(3 beta)/25 (the sphere's radius 5).  ``bracket``: p/p_c where
    inflate reaches and where it stops (None: found by steps of 0.05 from 0.7)."""
    t0 = time.perf_counter()
    shell = sb.UserShell(*CAP)
    pc = classical(beta) / 25

    def state(f, max_nodes=FOLD_NODES):
        return sb.inflate(sb.Scene(shell=shell, beta=beta, pressure=f * pc, rim=rim), max_nodes=max_nodes)

    if bracket is None:
        lo = 0.7
        assert state(lo).success
        while state(lo + 0.05).success:
            lo += 0.05
            print(f"  cap p/p_c {lo:.2f}: inflate reached", flush=True)
        bracket = (lo, lo + 0.05)
    lo, hi = bracket
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
    asym = held_rim(beta, scan=scan, shell=shell, pc=pc, first_mode=1, rim=rim)
    return {"beta": beta, "rim": rim, "lambda": cap_lambda(beta), "p_c": pc, "stall_p_over_pc": fold, "approach": approach, "n0_exponent": exponent, "n0_zero_p_over_pc": zero,
            "asymmetric": asym, "seconds": time.perf_counter() - t0}


def cap_shell(radius=5):
    """A spherical cap of the given sphere radius over the rim radius 1 (``CAP`` for 5)."""
    return (f"{radius:g}*sin(S/{radius:g})", f"-{radius:g}*cos(S/{radius:g})", f"{radius:g}*asin(1/{radius:g})")


def cap_rise(radius=5):
    """The cap's rise H over the rim radius."""
    return radius - math.sqrt(radius**2 - 1)


def cap_lambda(beta, radius=5):
    """The cap parameter ``lambda = 2 [3 (1 - nu^2)]^(1/4) sqrt(H/h)`` (the literature's tables'
    definition, benchmarks/results/stability_literature.md) of the cap at ``beta``, with our
    nu = 1/2 (incompressible): ``sqrt(6 H/h)``, ``h = sqrt(3 beta)``."""
    return math.sqrt(6 * cap_rise(radius) / math.sqrt(3 * beta))


def cap_beta(lam, radius=5):
    """The beta of the cap whose :func:`cap_lambda` is ``lam``."""
    return (6 * cap_rise(radius) / lam**2) ** 2 / 3


#: Clamped shallow caps, first asymmetric bifurcation: lambda -> (Huang 1964 p_cr/p_c, n, Teng &
#: Rotter 1989b p_cr/p_c, n), nu = 1/3, as tabulated (Teng & Rotter 1989b, Table 3) by AQUINAS
#: (AchilleasF/AQUINAS-FE at a0c3581439175d9fc854cd659110d06875b664ab,
#: src/Examples/input_Example_GNA06.csv; benchmarks/results/stability_literature.md).
HUANG = {6: (0.775, 2, 0.777, 2), 7: (0.76, 3, 0.763, 3), 8: (0.766, 4, 0.769, 4), 9: (0.777, 4, 0.778, 4),
         10: (0.776, 5, 0.778, 5), 12: (0.78, 7, 0.782, 7), 14: (0.782, 9, 0.787, 9), 16: (0.79, 11, 0.792, 11)}
#: Clamped shallow caps, axisymmetric snap-through p/p_c: Budiansky 1959 (nu = 0.3), same repository,
#: src/Examples/input_Example_GNA05.csv (Teng & Rotter 1989a, Table 1).
BUDIANSKY = {4: 0.578, 5: 0.629, 5.5: 0.789, 6: 0.995, 7: 1.068, 8: 1.13}
#: p/p_c where the clamped caps' non-axisymmetric modes are looked for (refined between the last
#: stable and the first unstable one; the scan ends where inflate stops)
CLAMPED_SCAN = (0.5, 0.6, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2)


#: The clamped caps' branch: first step in p/p_c, the smallest step before the march stops, and
#: how much faster than along its last step the enclosed volume may change in one step (more: a
#: jump to another branch, the step is halved; the volume, not the pole, as it grows with p all
#: along a stable branch, while the pole may turn)
BRANCH_STEP, BRANCH_MIN_STEP, BRANCH_JUMP = 0.01, 1e-4, 10.0


def _min_over(res, first_mode):
    keep = res.modes >= first_mode
    k = int(np.argmin(res.smallest[keep]))
    return float(res.smallest[keep][k]), int(res.modes[keep][k])


def clamped_cap(lam, radius=5, f0=0.5):
    """The clamped cap of cap parameter ``lam`` followed along its axisymmetric branch in p/p_c
    from ``f0`` (each state solved from the one before: ``inflate(..., start=)``), with its
    spectrum at every step: the first crossing over n >= 1 (refined by regula falsi), and the
    end of the branch where the n = 0 eigenvalue vanishes (steps are halved where Newton
    fails, where n = 0 is negative or where the volume jumps: another branch) down to
    ``BRANCH_MIN_STEP``."""
    t0 = time.perf_counter()
    beta, shell = cap_beta(lam, radius), sb.UserShell(*cap_shell(radius))
    pc = classical(beta) / radius**2

    def solve(f, start=None):
        return sb.inflate(sb.Scene(shell=shell, beta=beta, pressure=f * pc, rim="clamped"), max_nodes=FOLD_NODES,
                          start=start)

    def spectrum(state, asym_done):
        return st.stability(state, modes=[0] if asym_done else None, vectors=not asym_done)

    f, state = f0, solve(f0)
    assert state.success, state.message
    res = spectrum(state, False)
    branch = [(f, float(res.smallest[0]))]
    asym, step, last_move = None, BRANCH_STEP, None
    while step >= BRANCH_MIN_STEP:
        f_try = f + step
        new = solve(f_try, start=state)
        ok = new.success
        if ok:
            move = abs(new.volume_change - state.volume_change) / step
            new_res = spectrum(new, asym is not None)
            ok = new_res.smallest[0] > 0 and (last_move is None or move < BRANCH_JUMP * last_move)
        if not ok:
            step /= 2
            continue
        if asym is None and _min_over(new_res, 1)[0] <= 0 < _min_over(res, 1)[0]:
            asym = _refine_crossing(solve, (f, state, res), (f_try, new, new_res))
            print(f"  lambda {lam:g}: first n >= 1 crossing at p/p_c {asym['p_over_pc']:.5f}, n {asym['n']}",
                  flush=True)
        f, state, res, last_move = f_try, new, new_res, move
        branch.append((f, float(res.smallest[0])))
        print(f"  lambda {lam:g} p/p_c {f:.5f}: n = 0 eigenvalue {res.smallest[0]:.4g} (step {step:.2g})",
              flush=True)
        step = min(BRANCH_STEP, 1.5 * step)
    end = f
    # the n = 0 eigenvalue on the way to the end, from the branch's states (a fold: slope 1/2)
    fb = np.array([b[0] for b in branch])
    lam0 = np.array([b[1] for b in branch])
    near = (end - fb > 0) & (end - fb < 0.05 * end)
    exponent = float(np.polyfit(np.log(end - fb[near]), np.log(lam0[near]), 1)[0]) if near.sum() >= 3 else math.nan
    # lambda_0^2 is linear in p at a fold: its zero from the last two states
    zero = float(fb[-1] - lam0[-1] ** 2 * (fb[-1] - fb[-2]) / (lam0[-1] ** 2 - lam0[-2] ** 2))
    return {"lambda_table": lam, "radius": radius, "lambda": cap_lambda(beta, radius), "beta": beta, "rim": "clamped",
            "p_c": pc,
            "branch_end_p_over_pc": end, "n0_exponent": exponent, "n0_zero_p_over_pc": zero,
            "branch": [list(b) for b in branch],
            "asymmetric": asym or {"found": False, "note": f"none up to the branch's end {end:.4f}"},
            "seconds": time.perf_counter() - t0}


def _refine_crossing(solve, a, b, rtol=1e-4):
    """Regula falsi (Illinois) on the smallest eigenvalue over n >= 1 between two states of the
    branch, each try solved from the state below it."""
    (fa, sa, ra), (fb, _, rb) = a, b
    va, vb = _min_over(ra, 1)[0], _min_over(rb, 1)[0]
    side = 0
    while fb - fa > rtol * fa:
        f = fb - vb * (fb - fa) / (vb - va)
        f = min(max(f, fa + 0.05 * (fb - fa)), fb - 0.05 * (fb - fa))
        s = solve(f, start=sa)
        r = st.stability(s, vectors=True)
        v = _min_over(r, 1)[0]
        if v > 0:
            fa, sa, ra, va = f, s, r, v
            if side == -1:
                vb /= 2
            side = -1
        else:
            fb, rb, vb = f, r, v
            if side == 1:
                va /= 2
            side = 1
    f = fb - vb * (fb - fa) / (vb - va)
    n = _min_over(rb, 1)[1]
    mode = rb.vectors[n]
    S_peak = float(mode["S"][int(np.argmax(np.abs(mode["w"])))])
    return {"found": True, "p_over_pc": f, "bracket": [fa, fb], "n": n, "S_peak": S_peak}


def clamped_caps(lambdas, shallower=()):
    """The clamped caps of sphere radius 5 at ``lambdas``, and of radius 10 (half as steep: the
    shallow-shell theory's error, of order the angle squared, a quarter) at ``shallower``."""
    out = []
    for radius, lams in ((5, lambdas), (10, shallower)):
        for lam in lams:
            print(f"clamped cap radius {radius}, lambda {lam:g}, beta {cap_beta(lam, radius):.4g}", flush=True)
            out.append(clamped_cap(lam, radius))
    return out


def _clamped_lines(caps):
    lines = ["", "## Clamped shallow caps (sphere radius 5 and 10, rim radius 1, `rim=\"clamped\"`) against the "
             "literature",
             "",
             "The cap of the section above with its rim clamped (lambda_theta = 1, z = 0 and the slope held, "
             "phi(L) = Phi(L); the modes hold u = v = w = w' = 0 there), at the beta whose cap parameter "
             "lambda = 2 [3 (1 - nu^2)]^(1/4) sqrt(H/h) is the tables' with our nu = 1/2 "
             "(lambda = sqrt(6 H/h), h = sqrt(3 beta); `benchmarks/results/stability_literature.md`).  "
             "p_c = 4 sqrt(3 beta)/R^2 is the classical pressure of the sphere of radius R with nu = 1/2, "
             "the tables' p_c = 2 E h^2/(R^2 sqrt(3 (1 - nu^2))) with their nu.  `asymmetric`: the first "
             "sign change of the smallest eigenvalue over n >= 1 along the branch below, refined by regula "
             "falsi to 1e-4 in p/p_c; `fold`: the end of the axisymmetric branch, followed from 0.5 p_c in "
             "steps of 0.01 p_c (each state solved from the one before, `inflate(..., start=)`) that halve "
             "where Newton fails, the n = 0 eigenvalue turns negative or the volume jumps (another branch), "
             "down to 1e-4; with the log-log slope of the n = 0 eigenvalue over the last 5 % before it (a "
             "fold: 1/2) and the zero of lambda_0^2 extrapolated from the last two states.  "
             "(`inflate` without `start` goes to its pressure in one step first: at lambda 8 it returns, "
             "at 1.1 p_c, a state of another, unstable branch; hence the march.)  "
             "Literature: Huang 1964 and Teng & Rotter 1989b (nu = 1/3) for the asymmetric bifurcation, "
             "Budiansky 1959 (nu = 0.3) for the axisymmetric snap; transcribed by the AQUINAS authors.", "",
             "| R | lambda | beta | p_c | asymmetric p/p_c (ours) | n (ours) | Huang 1964 p/p_c, n | Teng & Rotter "
             "p/p_c, n | ours / Huang | fold p/p_c (ours; lambda_0^2 zero) | n = 0 slope | Budiansky 1959 "
             "| time |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in caps:
        lam, a = c["lambda_table"], c["asymmetric"]
        hu = HUANG.get(lam)
        lit = (f"{hu[0]:.3f}, {hu[1]} | {hu[2]:.3f}, {hu[3]}" if hu else "-- | --")
        ours = f"{a['p_over_pc']:.4f} | {a['n']}" if a["found"] else f"-- ({a['note']}) | --"
        ratio = f"{a['p_over_pc'] / hu[0]:.3f}" if hu and a["found"] else "--"
        bud = f"{BUDIANSKY[lam]:.3f}" if lam in BUDIANSKY else "--"
        lines.append(f"| {c.get('radius', 5)} | {lam:g} | {c['beta']:.3g} | {c['p_c']:.4g} | {ours} | {lit} | {ratio} "
                     f"| {c['branch_end_p_over_pc']:.4f} ({c['n0_zero_p_over_pc']:.4f}) | {c['n0_exponent']:.2f} "
                     f"| {bud} | {c['seconds']:.0f} s |")
    lines += ["", "What differs between the two sides (so agreement is expected to a few per cent, not to the "
              "digits): the Poisson ratio (ours 1/2, the tables' 1/3 and 0.3; lambda and p_c carry each side's "
              "own, so rows of equal lambda are compared, which assumes p/p_c depends on nu only through "
              "lambda: the clamped edge's in-plane condition brings nu in as well); shallow-shell "
              "(Donnell-Mushtari-Vlasov) theory with small strains against our shell with its exact spherical "
              "geometry (half-angle 11.5 degrees at R = 5, 5.7 at R = 10) and finite strains; the incompressible Mooney-Rivlin material "
              "(its strains here are of order 1e-3, so nearly linear) with bending stiffness beta = h^2/3."]
    return lines


def main():
    t0 = time.perf_counter()
    ap = argparse.ArgumentParser()
    ap.add_argument("--betas", type=float, nargs="*", default=[1e-4, 1e-5, 1e-6])
    ap.add_argument("--no-cap", action="store_true", help="skip the shallow cap")
    ap.add_argument("--cap-only", action="store_true", help="only the shallow caps")
    ap.add_argument("--lambdas", type=float, nargs="*", default=[6, 8, 12],
                    help="cap parameters of the clamped caps (none: no clamped caps)")
    ap.add_argument("--shallower", type=float, nargs="*", default=[8],
                    help="cap parameters of clamped caps of sphere radius 10 (half as steep)")
    ap.add_argument("--only", choices=["clamped"],
                    help="only the clamped caps; the other results are those of stability_pressure.json")
    add_output_args(ap)
    args = ap.parse_args()
    global OUT
    OUT = results_dir(args.out_dir)
    rows = []
    if args.only == "clamped":
        last = json.loads((OUT / "stability_pressure.json").read_text())
        args.betas, args.no_cap, cap, rows = [], True, last["cap"], last["rows"]
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
    if not args.no_cap:
        cap = shallow_cap()
    elif args.only != "clamped":
        cap = None
    clamped = clamped_caps(args.lambdas, args.shallower)
    OUT.mkdir(exist_ok=True)
    meta = {"machine": platform.platform(), "python": platform.python_version(),
            "date": time.strftime("%Y-%m-%d")}
    if args.only == "clamped":  # the other rows keep their run's
        meta = {**last["meta"], "clamped": meta}
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
    if clamped:
        lines += _clamped_lines(clamped)
    if args.only == "clamped":
        total = f" (total {meta['total_seconds']:.0f} s)" if "total_seconds" in meta else ""
        lines += ["", f"The clamped caps: {time.perf_counter() - t0:.0f} s, {meta['clamped']['date']}; the rows above "
                  f"from the run of {meta['date']}{total}."]
    else:
        meta["total_seconds"] = time.perf_counter() - t0
        lines += ["", f"Total {meta['total_seconds']:.0f} s, {meta['date']}."]
    lines[-1] += f" {meta['machine']}, Python {meta['python']}; 2 shared cores."
    lines.append("")
    (OUT / "stability_pressure.json").write_text(json.dumps({"meta": meta, "rows": rows, "cap": cap,
                                                             "clamped": clamped}, indent=1))
    (OUT / "stability_pressure.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
