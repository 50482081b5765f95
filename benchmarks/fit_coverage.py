"""Coverage of the fit's 95 % intervals, per noise model (weights) and noise type.

Synthetic Lepidium-like data (preset "fit", R_L = 0.3 mm, mu*H = 52 N/m,
contact point 10 um into the record, 40 points at delta = 0.01..0.4 as in the
shipped example) with

* proportional noise: F (1 + 0.02 N(0,1)) -- what the README example has;
* additive noise: F + 0.02 max(F) N(0,1) -- homoscedastic, for contrast;

fitted with each noise model of ``sb.fit`` (``weights="uniform"``, ``"relative"``,
``"mixed"``), with 40 points and with 12.  For each case:
how often the 95 % interval of mu*H (and of the offset) contains the truth
(with a Wilson 95 % interval of that rate), the median interval width and the
RMS error of mu*H.  Then ``fit_beta=True`` on data made with beta = 0.02 (the
fit starts from the preset's 0.01): coverage of beta and mu*H (and the mixed weights with the
floor of relative weights, 0.05).

Then records with an approach, fitted as ``fit_record`` fits them (a constant baseline and
the contact point, from ``estimate_contact``'s guess):

* ``approach``: 20 approach rows, then 140 to delta 0.4 (R_L = 0.3 mm, mu*H = 52 N/m,
  contact at 25 um, a 50 uN baseline);
* ``afm``: an AFM-like long baseline, 250 approach rows, then 150 to delta 0.3 (R_L = 10 um,
  mu*H = 0.6 mN/m, contact at 0.3 um, a 0.2 nN baseline);

with *proportional* noise F (1 + 0.01 e) -- the approach rows exactly noise-free, as in a
synthetic force map -- and *mixed* noise F (1 + 0.01 e1) + 0.005 max(F) e2; and the mixed
weights with other floors (``fit(..., floor=)``) on the noise-free approaches.

    python benchmarks/fit_coverage.py [--seeds 200] [--beta-seeds 20] [--report-only] [--quick] [--out-dir DIR]
    python benchmarks/fit_coverage.py --approach-only --tag before   # another checkout's package

Writes benchmarks/results/fit_coverage.md and .json.  The fit's model curve
is computed once and reused (memoised in the process), so the seeds cost
milliseconds each; fits of beta add one model curve per seed.
"""

import argparse
import json
import math
import subprocess
import time
from pathlib import Path

import numpy as np

import shellbvp as sb
import shellbvp.fitting  # noqa: F401  (sb.fitting.WEIGHTS below)

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path

R_L, MU_H, D0, NOISE, N = 0.3e-3, 52.0, 10e-6, 0.02, 40
RESULTS = Path(__file__).parent / "results"
#: records with an approach: (R_L (m), contact (m), approach rows, contact rows, deepest delta, mu*H (N/m),
#: baseline (N))
APPROACH = {"approach": (0.3e-3, 25e-6, 20, 140, 0.4, 52.0, 50e-6),
            "afm": (10e-6, 0.3e-6, 250, 150, 0.3, 0.6e-3, 0.2e-9)}
#: their noise: (proportional, additive as a fraction of the largest force)
APPROACH_NOISE = {"proportional": (0.01, 0.0), "mixed": (0.01, 0.005)}
#: floors of the mixed weights' proportional part tried besides the default (sb.fitting.WEIGHT_FLOORS)
FLOORS = (0.01, 0.05, 0.1)


def wilson(k, n, z=1.96):
    p = k / n
    den = 1 + z * z / n
    c = (p + z * z / (2 * n)) / den
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return c - h, c + h


def truth(scene, n=N):
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.4, n), estimate_error=False)
    assert len(c) == n, c.stop_reason
    return R_L * c.delta + D0, MU_H * R_L * c.force


def noisy(F, kind, seed):
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(F.size)
    return F * (1 + NOISE * e) if kind == "proportional" else F + NOISE * np.max(F) * e


def approach_record(scene, design):
    """(displacement (m), clean force (N)) of a record with an approach: the model's own force
    at exactly the contact rows' depths, zero before contact, plus the baseline."""
    R_L_, d0, na, nc, top, mu_H, base = APPROACH[design]
    step = top * R_L_ / nc
    deltas = step * np.arange(1, nc + 1) / R_L_
    c = sb.curve(scene, deltas=deltas, estimate_error=False)
    assert len(c) == nc, c.stop_reason
    disp = np.r_[d0 - step * np.arange(na, 0, -1), d0 + R_L_ * deltas]
    return disp, np.r_[np.zeros(na), mu_H * R_L_ * np.asarray(c.force)]


def approach_coverage(scene, seeds, out):
    """Coverage on records with an approach (``APPROACH``), per noise and weights (and floors)."""
    from shellbvp.segments import estimate_contact

    for design, (R_L_, d0, na, nc, top, mu_H, base) in APPROACH.items():
        disp, F = approach_record(scene, design)
        for kind, (p, a) in APPROACH_NOISE.items():
            cases = [(w, None) for w in sb.fitting.WEIGHTS]
            cases += [("mixed", fl) for fl in FLOORS] if kind == "proportional" else []
            for w, floor in cases:
                rows = []
                t = time.perf_counter()
                for seed in range(seeds):
                    rng = np.random.default_rng(seed)
                    f = F * (1 + p * rng.standard_normal(F.size)) + a * np.max(F) * rng.standard_normal(F.size) + base
                    options = dict(R_L=R_L_, weights=w, baseline="constant", contact_guess=estimate_contact(disp, f),
                                   **({} if floor is None else {"floor": floor}))  # (an older fit: no None)
                    try:  # one model curve for every seed, unless a contact guess far off needs a deeper one
                        r = sb.fit(scene, disp, f, delta_max=1.2 * top, **options)
                    except ValueError as e:
                        if "model curve ends" not in str(e):
                            raise
                        r = sb.fit(scene, disp, f, **options)
                    rows.append(r.to_dict())
                key = f"{design}/{kind}/{w}" + (f"/floor {floor:g}" if floor is not None else "")
                out["approach"][key] = {"mu_H": summarise(rows, "mu_H", mu_H), "offset": summarise(rows, "offset", d0),
                                        "weights_check_failed": int(sum(r["status"] == 6 for r in rows)),
                                        "seconds_per_fit": (time.perf_counter() - t) / seeds}
                print(key, out["approach"][key], flush=True)


def summarise(rows, key, true):
    inside = [r[key + "_ci95"][0] <= true <= r[key + "_ci95"][1] for r in rows]
    k, n = int(np.sum(inside)), len(rows)
    lo, hi = wilson(k, n)
    est = np.array([r[key] for r in rows])
    width = np.array([r[key + "_ci95"][1] - r[key + "_ci95"][0] for r in rows])
    return {"covered": k, "n": n, "coverage": k / n, "coverage_ci95": [lo, hi],
            "median_width": float(np.median(width)), "rms_error": float(np.sqrt(np.mean((est - true) ** 2))),
            "bias": float(np.mean(est - true))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--beta-seeds", type=int, default=20, dest="beta_seeds")
    ap.add_argument("--report-only", action="store_true", dest="report_only",
                    help="rewrite the .md from the .json of the last run")
    ap.add_argument("--approach-only", action="store_true", dest="approach_only",
                    help="only the records with an approach (e.g. another checkout's package on PYTHONPATH)")
    ap.add_argument("--tag", default="", help="a suffix of the result files' names (fit_coverage-TAG.md)")
    add_output_args(ap, quick="5 seeds, 1 for beta")
    args = ap.parse_args()
    if args.quick:
        args.seeds, args.beta_seeds = 5, 1
    global RESULTS
    RESULTS = results_dir(args.out_dir)
    stem = "fit_coverage" + (f"-{args.tag}" if args.tag else "") + ("-quick" if args.quick else "")
    if args.report_only:
        out = json.loads((RESULTS / f"{stem}.json").read_text())
        (RESULTS / f"{stem}.md").write_text(report(out))
        return
    t0, c0 = time.perf_counter(), time.process_time()
    scene = sb.Scene.preset("fit")
    out = {"setup": {"R_L": R_L, "mu_H": MU_H, "offset": D0, "noise": NOISE, "points": N,
                     "seeds": args.seeds, "beta_seeds": args.beta_seeds, "package": str(Path(sb.__file__).parent)},
           "mu_H": {}, "beta": {}, "approach": {}}
    if args.approach_only:
        approach_coverage(scene, args.seeds, out)
        return _write(out, stem, t0, c0)
    for n in (N, 12):
        disp, F = truth(scene, n)
        for kind in ("proportional", "additive"):
            for w in sb.fitting.WEIGHTS:
                rows = []
                t = time.perf_counter()
                for seed in range(args.seeds):
                    r = sb.fit(scene, disp, noisy(F, kind, seed), R_L=R_L, weights=w)
                    rows.append(r.to_dict())
                key = f"{n}/{kind}/{w}"
                out["mu_H"][key] = {"mu_H": summarise(rows, "mu_H", MU_H), "offset": summarise(rows, "offset", D0),
                                    "seconds_per_fit": (time.perf_counter() - t) / args.seeds}
                print(key, out["mu_H"][key], flush=True)
    # beta: data at beta = 0.02, fit starts at 0.01
    beta_true = 0.02
    disp_b, F_b = truth(scene.replace(beta=beta_true))
    for w, floor in [(w, None) for w in sb.fitting.WEIGHTS] + [("mixed", 0.05)]:
        rows = []
        t = time.perf_counter()
        for seed in range(args.beta_seeds):
            r = sb.fit(scene, disp_b, noisy(F_b, "proportional", seed), R_L=R_L, weights=w, fit_beta=True,
                       **({} if floor is None else {"floor": floor}))
            rows.append(r.to_dict())
        betas = np.array([r["beta"] for r in rows])
        key = f"proportional/{w}" + (f"/floor {floor:g}" if floor is not None else "")
        out["beta"][key] = {
            "beta": summarise(rows, "beta", beta_true), "mu_H": summarise(rows, "mu_H", MU_H),
            "beta_median": float(np.median(betas)),
            "beta_ci95_at_bound": int(sum(any("end of the searched range" in text for text in [r["message"],
                                                                                             *r["warnings"]])
                                          for r in rows)),
            "curves_per_fit": float(np.mean([r["curves_computed"] for r in rows])),
            "interpolation_error_max": float(np.nanmax([r["interpolation_error"] or 0.0 for r in rows])),
            "seconds_per_fit": (time.perf_counter() - t) / args.beta_seeds}
        print("beta", key, out["beta"][key], flush=True)
    approach_coverage(scene, args.seeds, out)
    _write(out, stem, t0, c0)


def _write(out, stem, t0, c0):
    out["seconds"], out["cpu_seconds"] = time.perf_counter() - t0, time.process_time() - c0
    try:
        out["commit"] = subprocess.run(["git", "-C", out["setup"]["package"], "rev-parse", "--short", "HEAD"],
                                       capture_output=True, text=True, timeout=10).stdout.strip()
    except OSError:
        out["commit"] = ""
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{stem}.json").write_text(json.dumps(out, indent=1) + "\n")
    (RESULTS / f"{stem}.md").write_text(report(out))
    print(f"wrote {RESULTS / (stem + '.md')} ({out['seconds']:.0f} s)")


def _coverage_row(m):
    return f"{m['covered']}/{m['n']} = {m['coverage']:.3f} [{m['coverage_ci95'][0]:.3f}, {m['coverage_ci95'][1]:.3f}]"


def report(out):
    s = out["setup"]
    commit = f" at {out['commit']}" if out.get("commit") else ""
    L = ["# Coverage of the fit's 95 % intervals", "",
         f"Generated by `python benchmarks/fit_coverage.py`{commit} ({out['seconds']:.0f} s, "
         f"{out.get('cpu_seconds', math.nan):.0f} s of CPU). Synthetic data: preset `fit`, "
         f"R_L = {s['R_L'] * 1e3:g} mm, mu*H = {s['mu_H']:g} N/m, contact point {s['offset'] * 1e6:g} um, "
         f"{s['points']} points at delta = 0.01..0.4, {s['noise'] * 100:g} % noise; "
         f"{s['seeds']} seeds per row (mu*H and offset fitted), {s['beta_seeds']} for beta.", "",
         "Noise: *proportional* F (1 + 0.02 e), *additive* F + 0.02 max(F) e, e ~ N(0, 1).",
         "Coverage: fraction of seeds whose interval contains the truth, with its Wilson 95 % interval.", ""]
    if out["mu_H"]:
        L += ["## mu*H and the contact point", "",
              "| points | noise | weights | mu*H coverage | median CI width (N/m) | RMS error (N/m) | bias (N/m) "
              "| offset coverage | median offset CI width (um) |",
              "|---|---|---|---|---|---|---|---|---|"]
        for key, v in out["mu_H"].items():
            n, kind, w = key.split("/")
            m, o = v["mu_H"], v["offset"]
            L.append(f"| {n} | {kind} | {w} | {_coverage_row(m)} | {m['median_width']:.3g} | "
                     f"{m['rms_error']:.3g} | {m['bias']:+.2g} | {o['covered']}/{o['n']} = {o['coverage']:.3f} | "
                     f"{o['median_width'] * 1e6:.3g} |")
    if out["beta"]:
        L += ["", "## beta fitted (data at beta = 0.02, proportional noise; the fit starts at 0.01)", "",
              "| weights | beta coverage | median beta | median beta CI width | RMS error of beta | CI open at a bound "
              "| mu*H coverage | median mu*H CI width (N/m) | new model curves per fit (memoised across seeds) "
              "| max interpolation error |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for key, v in out["beta"].items():
            w = key.split("/", 1)[1].replace("/", ", ")
            b, m = v["beta"], v["mu_H"]
            L.append(f"| {w} | {b['covered']}/{b['n']} = {b['coverage']:.2f} | {v['beta_median']:.4g} | "
                     f"{b['median_width']:.3g} | {b['rms_error']:.2g} | {v['beta_ci95_at_bound']} | "
                     f"{m['covered']}/{m['n']} = {m['coverage']:.2f} | {m['median_width']:.3g} | "
                     f"{v['curves_per_fit']:.1f} | {v['interpolation_error_max']:.1e} |")
    if out.get("approach"):
        L += ["", "## Records with an approach (a constant baseline and the contact point fitted)", "",
              "`approach`: 20 approach rows, 140 to delta 0.4 (R_L 0.3 mm); `afm`: 250 approach rows, 150 to delta "
              "0.3 (R_L 10 um).  Noise *proportional* F (1 + 0.01 e): the approach rows exactly noise-free; *mixed* "
              "F (1 + 0.01 e1) + 0.005 max(F) e2.  Errors and widths relative to mu*H.", "",
              "| record | noise | weights | mu*H coverage | median half-width | RMS error | bias "
              "| offset coverage | weights check failed |",
              "|---|---|---|---|---|---|---|---|---|"]
        for key, v in out["approach"].items():
            design, kind, w = key.split("/", 2)
            m, o = v["mu_H"], v["offset"]
            mu = APPROACH[design][5]
            L.append(f"| {design} | {kind} | {w.replace('/', ', ')} | {_coverage_row(m)} | "
                     f"{100 * m['median_width'] / 2 / mu:.3f} % | {100 * m['rms_error'] / mu:.3f} % | "
                     f"{100 * m['bias'] / mu:+.3f} % | {o['covered']}/{o['n']} = {o['coverage']:.3f} | "
                     f"{v['weights_check_failed']}/{m['n']} |")
    if out["mu_H"]:
        L += ["", "## Reading", ""]
        for n in (str(s["points"]), "12"):
            for kind in ("proportional", "additive"):
                rows = {w: out["mu_H"][f"{n}/{kind}/{w}"]["mu_H"] for w in sb.fitting.WEIGHTS}
                best = min(rows, key=lambda w: (abs(rows[w]["coverage"] - 0.95), rows[w]["rms_error"]))
                L.append(f"* {n} points, {kind} noise: mu*H coverage "
                         + ", ".join(f"{w} {rows[w]['coverage']:.3f}" for w in rows)
                         + "; RMS error " + ", ".join(f"{w} {rows[w]['rms_error']:.3g}" for w in rows)
                         + f" N/m; closest to 95 %: `{best}`.")
        L += [f"* Default of `sb.fit` / `shellbvp fit`: `{sb.fitting.DEFAULT_WEIGHTS}`."]
    L.append("")
    return "\n".join(L)


if __name__ == "__main__":
    main()
