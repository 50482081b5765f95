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
* ``lifted fold``: the base scene thickened to beta 0.2, whose lifted-pole (line) branch turns
  back in delta at 0.356818 (``shellbvp.lifted_ends.lifted_pole_fold``, docs/limits.md): the
  n = 0 (and n = 2) eigenvalue before, at and past the fold (followed in the lifted pole's
  stretch lambda0) by where the mesh starts and the elements: it is not resolved there.
* ``dome onset``: the same dome at rho 0.05, 0.2, 0.5: along the curve, the first sign change of
  the smallest eigenvalue over n >= 2 (and over n >= 1), refined by Brent's method in delta
  (each delta its own state, warm-started from its neighbour), with its n, the depth over the
  thickness ``H = sqrt(3 beta) R_L`` (``shellbvp.units.beta_from_thickness``: beta = eps^2/3)
  and over the paper's ``sqrt(12 beta)``, and the eigenvalue there with twice the elements.

* ``closed``: a thin sphere (eps = H/R 0.02, beta = eps^2/3, Mooney-Rivlin 0.1) on a substrate
  under a sphere tip (rho 0.3; both halves' modes, issue 55) and the same sphere between plates:
  ``sb.curve(..., stability="locate")`` to delta 0.6 (plates: 0.7), the first instability's
  delta and n (n = 1 left out: the slip and roll of the frictionless model), the mode's eigenvalue
  past it with twice the elements and where the mode lives; along the substrate's curve n = 1's
  slip against a rigid ball's ``-F/(R + rho)/(4 pi)``; and the ``cell-glass`` preset (eps 0.04,
  turgor 0.15, rho 0.34) to delta 1.

Writes benchmarks/results/stability_contact.md (and .json), or DIR/results/ with ``--out-dir DIR``.
The JSON's ``runs`` says which run wrote each section (the commit, the date, the machine), and
``whole_run`` the last run of every section at once; ``--only`` updates its section's entry only,
and the report's last lines say which sections were run at which commit.

    python benchmarks/stability_contact.py
    python benchmarks/stability_contact.py --rewrite   # the .md again from the .json
    python benchmarks/stability_contact.py --only lifted   # one section (fold, base, lifted, onset, closed)
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq, minimize_scalar

import shellbvp as sb
from shellbvp import modal_stability as st

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checkout import add_output_args, commit_label, results_dir, write_atomic  # noqa: E402

#: the sections, each rerun alone by ``--only``
SECTIONS = ("fold", "base", "lifted", "onset", "closed")
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


def lifted_fold(beta=0.2, step=0.003):
    """The n = 0 eigenvalue on both sides of a thick shell's lifted-pole fold, by where the mesh
    starts (S0 x 0.25 .. 10) and with the default and 160 elements (``sb.stability`` refuses these
    states: their eigenvalues move with S0, module docstring of shellbvp.modal_stability)."""
    from shellbvp.lifted_ends import lifted_pole_fold
    from shellbvp.liftoff import make_liftoff_system, moved_guess, solve_liftoff_from

    t0 = time.perf_counter()
    scene = sb.Scene.preset("base", beta=beta)
    curve = sb.curve(scene, delta_max=0.352, estimate_error=False)
    line = [s for s in curve.solutions if s.topology == "line"]
    fold, states = lifted_pole_fold(line[-1], line[-2])
    ordered = sorted(states + [fold], key=lambda s: s.lambda0)
    prev, before = ordered[0], ordered[1]
    lam = fold.lambda0 - step  # past the fold: delta falls again
    sysm = make_liftoff_system(scene, "line", "lambda0", lam, prev.system.eps)
    past = solve_liftoff_from(sysm, moved_guess(sysm, prev, before, (lam - prev.lambda0) / (prev.lambda0 - before.lambda0)),
                              tol=1e-6, max_nodes=10000, bc_tol=1e-10)
    rows = []
    for state, where in ((ordered[3], "before the fold"), (fold, "the fold"), (past, "past the fold")):
        S0 = st.contact_of(state).S0
        for factor in (0.25, 1, 4, 10):
            for elements in (None, 160):
                con = st.contact_of(state, S0 * factor)
                res = st.spectrum(scene, con.base, con.S0, float(state.system.L), [0, 2], elements=elements,
                                  contact=con)
                rows.append({"where": where, "lambda0": state.lambda0, "delta": state.delta, "S0": con.S0,
                             "elements": res.elements, "n0": float(res.smallest[0]), "n2": float(res.smallest[1])})
    try:
        st.stability(fold)
        verdict = "resolved"
    except ValueError as exc:
        verdict = str(exc)
    return {"beta": beta, "fold_delta": fold.delta, "fold_lambda0": fold.lambda0, "rows": rows,
            "verdict": verdict, "seconds": time.perf_counter() - t0}


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


def closed_sphere(support, eps=0.02, rho=0.3):
    """The first instability of a thin closed sphere on a substrate under a sphere tip, or between
    plates, or of the ``cell-glass`` preset (``support="cell-glass"``; the benchmark's ``closed``
    section)."""
    t0 = time.perf_counter()
    beta = eps**2 / 3
    if support == "cell-glass":
        scene = sb.Scene.preset("cell-glass")
        eps, rho, delta_max = math.sqrt(3 * scene.beta), scene.rho, 1.0
    elif support == "substrate":
        scene = sb.Scene(closed=True, tip=sb.SphereTip(), rho=rho, gamma=1.0, beta=beta,
                         material=sb.MooneyRivlin(0.1))
        delta_max = 0.6
    else:
        scene = sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=beta,
                         material=sb.MooneyRivlin(0.1))
        delta_max = 0.7  # its curve stops near 0.74 (continuation)
    curve = sb.curve(scene, delta_max=delta_max, stability="locate")
    out = {"support": support, "eps": eps, "rho": rho if support != "plates" else None, "delta_max": delta_max,
           "stop": curve.stop_reason, "topologies": sorted({str(t) for t in curve.topology}),
           "points": len(curve), "last_delta": float(curve.delta[-1])}
    fi = curve.first_instability
    if fi is not None:
        out.update(delta=fi.delta, over_H=fi.delta / eps, n=fi.mode, force=fi.force, located=fi.located,
                   bracket=list(fi.bracket), message=fi.message)
        past = sb.solve(scene, delta=float(fi.bracket[1]), guess=min(curve.solutions, key=lambda s: abs(s.delta - fi.delta)),
                        estimate_error=False)
        res = st.stability(past, modes=[fi.mode], vectors=True)
        fine = st.stability(past, modes=[fi.mode], elements=2 * res.elements)
        v = res.vectors[fi.mode]
        k = int(np.argmax(np.abs(v["w"])))
        out.update(topology=past.topology, lam_past=float(res.smallest[0]), lam_past_2x=float(fine.smallest[0]),
                   mode_peak_S=float(v["S"][k]), L=float(past.system.L))
    if support == "substrate":  # n = 1: the slip against the rigid ball's, and n = 0, along the curve
        rows = []
        for s in curve.solutions[::3]:
            # the spectrum on the default mesh, without stability()'s checks of a negative eigenvalue:
            # the slip's is small at shallow depths, where the ring on the tip lies within 10 S0
            res = st.spectrum_closed(scene, st.halves_of(s), float(s.system.L), [0, 1], count=2)
            rows.append({"delta": s.delta, "topology": s.topology, "force": s.force, "n0": float(res.eigenvalues[0, 0]),
                         "slip": float(res.eigenvalues[1, 0]), "roll": float(res.eigenvalues[1, 1]),
                         "rigid": -s.force / (1 + rho) / (4 * math.pi)})
        out["n1"] = rows
    out["seconds"] = time.perf_counter() - t0
    return out


def closed():
    return [closed_sphere("substrate"), closed_sphere("plates"), closed_sphere("cell-glass")]


def _closed_lines(rows):
    lines = ["## A thin closed sphere on a substrate under a sphere tip, between plates, and the cell-glass preset", "",
             "eps = H/R = 0.02 (beta = eps^2/3 = 1.33e-4; the preset's 0.04), Mooney-Rivlin 0.1, smooth contact, frictionless; "
             "`sb.curve(..., stability=\"locate\")` (the CLI's `shellbvp curve --closed ... --stability locate`) "
             "with the default mesh and modes, n = 1 left out (the frictionless model's slip and roll, below).  "
             "`S peak`: where the mode's |w| is largest, the reference arclength from the upper pole (pi/2 the "
             "equator, pi the lower pole).", "",
             "| support | first unstable delta | delta/H | n | topology there | F | eigenvalue past it (2x elements) "
             "| S peak | time |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        name = {"substrate": f"substrate, sphere tip rho {r['rho']}", "plates": "plates"}.get(
            r["support"], f"preset {r['support']} (eps {r['eps']:.2g}, rho {r['rho']}, pressure 0.15)")
        if "n" not in r:
            lines.append(f"| {name} | stable to delta {r['last_delta']:.3g} ({r['points']} points; {r['stop']}) | | | "
                         f"{', '.join(r['topologies'])} | | | | {r['seconds']:.0f} s |")
            continue
        lines.append(f"| {name} | **{r['delta']:.4f}** ({r['message']}) | {r['over_H']:.1f} | {r['n']} | {r['topology']} | "
                     f"{r['force']:.4g} | {r['lam_past']:.4g} ({r['lam_past_2x']:.4g}) | {r['mode_peak_S']:.3f} | "
                     f"{r['seconds']:.0f} s |")
    sub = next((r for r in rows if r["support"] == "substrate" and "n1" in r), None)
    if sub:
        lines += ["", "n = 1 along the substrate's curve (every third point; two eigenvalues on the default mesh, "
                  "`shellbvp.modal_stability.spectrum_closed`, without `sb.stability`'s checks of a negative one: "
                  "at shallow depths the ring on the tip lies within 10 S0, where its pole check cannot move the "
                  "mesh's start): the slip, negative at every depth, against a rigid "
                  "ball of radius 1 between a ball of radius rho and a plane, `-F/(1 + rho)/(4 pi)` (its energy falls "
                  "by `F X^2/(2(1 + rho))` when moved sideways by X, over the sphere's area 4 pi); the roll (the "
                  "material turned through the unchanged deformed shape, a symmetry of the sphere) at zero.", "",
                  "| delta | topology | F | n = 0 | n = 1 slip | rigid ball | n = 1 roll |", "|---|---|---|---|---|---|---|"]
        for r in sub["n1"]:
            lines.append(f"| {r['delta']:.4g} | {r['topology']} | {r['force']:.4g} | {r['n0']:.4g} | {r['slip']:.4g} | "
                         f"{r['rigid']:.4g} | {r['roll']:.2g} |")
        lines += ["", "The slip follows the rigid ball at delta 0.018 and grows more negative than it as the sphere "
                  "flattens (its contacts widen).  At the shallowest state the ring on the tip is next to its switch "
                  "to an annulus (the curvature gap near 0: solved there from scratch the gap is -1.8e-6 and the state "
                  "is refused), where the ring's rolling term `f w1^2/gap` is large: there neither n = 1 value is "
                  "resolved (the roll reads -1.9e-5 instead of 0)."]
    return lines + [""]


def write(res, out):
    """The .json and the .md into the folder ``out``."""
    write_atomic(out / "stability_contact.json", json.dumps(res, indent=1, default=str))
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
    if "lifted" in res:
        lf = res["lifted"]
        lines += [f"## n = 0 at a thick shell's lifted-pole fold (base scene, beta {lf['beta']}): not resolved", "",
                  f"The line branch turns back in delta at **{lf['fold_delta']:.7f}** (lambda0 {lf['fold_lambda0']:.5f}; "
                  "`shellbvp.lifted_ends.lifted_pole_fold`).  The n = 0 eigenvalue should vanish there.  At the fold it "
                  "falls towards 0 as the mesh starts closer to the axis and the elements grow (0.71 and 0.34 with the "
                  "default S0, 0.49 and 0.094 with S0/4, 40 and 160 elements), and past the fold it is negative, but "
                  "it is not converged: the lifted pole, compressed to lambda0 0.37 and bent to kappa_s 71, puts its "
                  "fold mode within a few S0 of the axis, where the form's 1/r^3 coefficients cancel; n = 2 reads "
                  "-1e6 and moves by orders of magnitude.  `sb.stability` refuses these states (its pole check); at the "
                  "fold: "
                  f"{lf['verdict']}.  The check of item 4 against this fold holds in sign only, not to 1e-4.  Time {lf['seconds']:.0f} s.", "",
                  "| state | lambda0 | delta | S0 | elements | n = 0 | n = 2 |", "|---|---|---|---|---|---|---|"]
        for r in lf["rows"]:
            lines.append(f"| {r['where']} | {r['lambda0']:.5f} | {r['delta']:.7f} | {r['S0']:.2e} | {r['elements']} | "
                         f"{r['n0']:.4g} | {r['n2']:.3g} |")
        lines.append("")
    if "closed" in res:
        lines += _closed_lines(res["closed"])
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
              "so none are quoted here.", "", *provenance(res), ""]
    write_atomic(out / "stability_contact.md", "\n".join(lines))


def stamp(res, sections, seconds=None, commit=None, date=None):
    """Record in ``res`` that ``sections`` were just run (at ``commit``, default this checkout's, on
    ``date``, default today); ``seconds``: the time of a run of every section."""
    run = {"commit": commit or commit_label(default="unknown commit"), "date": date or time.strftime("%Y-%m-%d"),
           "machine": platform.platform(), "python": platform.python_version()}
    res.setdefault("runs", {}).update({k: dict(run) for k in sections})
    if seconds is not None:
        res["whole_run"] = dict(run, sections=list(sections), seconds=seconds)
    return res


def provenance(res):
    """The report's last lines: which sections which run wrote, and the last whole run's time."""
    runs, groups = res.get("runs", {}), {}
    for k in SECTIONS:
        if k in res:
            r = runs.get(k)
            key = (("committed in " + r["committed"]) if "committed" in r else "run at " + r["commit"],
                   r["date"], r["machine"], r["python"]) if r else ("of an unrecorded run", "", "", "")
            groups.setdefault(key, []).append(k)
    parts = [f"{', '.join(ks)}: {how}" + (f" ({date}; {machine}, Python {py})" if date else "")
             for (how, date, machine, py), ks in groups.items()]
    lines = ["Sections by the run that wrote them: " + "; ".join(parts) + "; 2 shared cores."]
    w = res.get("whole_run")
    if w:
        how = f"committed in {w['committed']}" if "committed" in w else f"at {w['commit']}"
        lines += ["", f"The last whole run ({how}, {w['date']}; its sections then: {', '.join(w['sections'])}) took "
                      f"{w['seconds']:.0f} s; each section's own time is given with it above."]
    return lines


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    again = ap.add_mutually_exclusive_group()
    again.add_argument("--rewrite", action="store_true", help="the .md again from the .json (nothing solved)")
    again.add_argument("--only", choices=SECTIONS, help="rerun this section, the others kept from the .json")
    return add_output_args(ap).parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    out = results_dir(args.out_dir)
    stored = out / "stability_contact.json"
    if (args.rewrite or args.only) and not stored.exists():
        raise SystemExit(f"stability_contact.py: --rewrite and --only need {stored} (a whole run first)")
    if args.rewrite:  # the report again from the stored numbers
        write(json.loads(stored.read_text()), out)
        return
    if args.only:  # one section, the others kept from the stored numbers
        which = args.only
        res = json.loads(stored.read_text())
        res[which] = {"fold": dome_fold, "base": base_curve, "lifted": lifted_fold, "closed": closed}[which]() if which != "onset" else \
            [onset(rho, first) for rho in (0.05, 0.2, 0.5) for first in (2, 1)]
        write(stamp(res, [which]), out)
        return
    t0 = time.perf_counter()
    res = {"fold": dome_fold()}
    print("fold", res["fold"]["delta_zero"], res["fold"]["delta_fold"], flush=True)
    res["base"] = base_curve()
    print("base done", flush=True)
    res["lifted"] = lifted_fold()
    print("lifted", res["lifted"]["verdict"], flush=True)
    res["onset"] = []
    for rho in (0.05, 0.2, 0.5):
        for first in (2, 1):
            o = onset(rho, first)
            print(o, flush=True)
            res["onset"].append(o)
    res["closed"] = closed()
    write(stamp(res, SECTIONS, seconds=time.perf_counter() - t0), out)


if __name__ == "__main__":
    main()
