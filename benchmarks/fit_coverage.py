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
fit starts from the preset's 0.01): coverage of beta and mu*H.

    python benchmarks/fit_coverage.py [--seeds 200] [--beta-seeds 20] [--report-only]

Writes benchmarks/results/fit_coverage.md and .json.  The fit's model curve
is computed once and reused (memoised in the process), so the seeds cost
milliseconds each; fits of beta add one model curve per seed.
"""

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import shellbvp as sb

R_L, MU_H, D0, NOISE, N = 0.3e-3, 52.0, 10e-6, 0.02, 40
RESULTS = Path(__file__).parent / "results"


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
    args = ap.parse_args()
    if args.report_only:
        out = json.loads((RESULTS / "fit_coverage.json").read_text())
        (RESULTS / "fit_coverage.md").write_text(report(out))
        return
    t0 = time.perf_counter()
    scene = sb.Scene.preset("fit")
    out = {"setup": {"R_L": R_L, "mu_H": MU_H, "offset": D0, "noise": NOISE, "points": N,
                     "seeds": args.seeds, "beta_seeds": args.beta_seeds}, "mu_H": {}, "beta": {}}
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
    for w in sb.fitting.WEIGHTS:
        rows = []
        t = time.perf_counter()
        for seed in range(args.beta_seeds):
            r = sb.fit(scene, disp_b, noisy(F_b, "proportional", seed), R_L=R_L, weights=w, fit_beta=True)
            rows.append(r.to_dict())
        betas = np.array([r["beta"] for r in rows])
        out["beta"][f"proportional/{w}"] = {
            "beta": summarise(rows, "beta", beta_true), "mu_H": summarise(rows, "mu_H", MU_H),
            "beta_median": float(np.median(betas)),
            "beta_ci95_at_bound": int(sum(("end of the searched range" in r["message"]) for r in rows)),
            "curves_per_fit": float(np.mean([r["curves_computed"] for r in rows])),
            "interpolation_error_max": float(np.nanmax([r["interpolation_error"] or 0.0 for r in rows])),
            "seconds_per_fit": (time.perf_counter() - t) / args.beta_seeds}
        print("beta", w, out["beta"][f"proportional/{w}"], flush=True)
    out["seconds"] = time.perf_counter() - t0
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "fit_coverage.json").write_text(json.dumps(out, indent=1) + "\n")
    (RESULTS / "fit_coverage.md").write_text(report(out))
    print(f"wrote {RESULTS / 'fit_coverage.md'} ({out['seconds']:.0f} s)")


def report(out):
    s = out["setup"]
    L = ["# Coverage of the fit's 95 % intervals", "",
         f"Generated by `python benchmarks/fit_coverage.py` ({out['seconds']:.0f} s). Synthetic data: preset `fit`, "
         f"R_L = {s['R_L'] * 1e3:g} mm, mu*H = {s['mu_H']:g} N/m, contact point {s['offset'] * 1e6:g} um, "
         f"{s['points']} points at delta = 0.01..0.4, {s['noise'] * 100:g} % noise; "
         f"{s['seeds']} seeds per row (mu*H and offset fitted), {s['beta_seeds']} for beta.", "",
         "Noise: *proportional* F (1 + 0.02 e), *additive* F + 0.02 max(F) e, e ~ N(0, 1).",
         "Coverage: fraction of seeds whose interval contains the truth, with its Wilson 95 % interval.", "",
         "## mu*H and the contact point", "",
         "| points | noise | weights | mu*H coverage | median CI width (N/m) | RMS error (N/m) | bias (N/m) "
         "| offset coverage | median offset CI width (um) |",
         "|---|---|---|---|---|---|---|---|---|"]
    for key, v in out["mu_H"].items():
        n, kind, w = key.split("/")
        m, o = v["mu_H"], v["offset"]
        L.append(f"| {n} | {kind} | {w} | {m['covered']}/{m['n']} = {m['coverage']:.3f} "
                 f"[{m['coverage_ci95'][0]:.3f}, {m['coverage_ci95'][1]:.3f}] | {m['median_width']:.3g} | "
                 f"{m['rms_error']:.3g} | {m['bias']:+.2g} | {o['covered']}/{o['n']} = {o['coverage']:.3f} | "
                 f"{o['median_width'] * 1e6:.3g} |")
    L += ["", "## beta fitted (data at beta = 0.02, proportional noise; the fit starts at 0.01)", "",
          "| weights | beta coverage | median beta | median beta CI width | RMS error of beta | CI open at a bound "
          "| mu*H coverage | median mu*H CI width (N/m) | new model curves per fit (memoised across seeds) "
          "| max interpolation error |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for key, v in out["beta"].items():
        w = key.split("/")[1]
        b, m = v["beta"], v["mu_H"]
        L.append(f"| {w} | {b['covered']}/{b['n']} = {b['coverage']:.2f} | {v['beta_median']:.4g} | "
                 f"{b['median_width']:.3g} | {b['rms_error']:.2g} | {v['beta_ci95_at_bound']} | "
                 f"{m['covered']}/{m['n']} = {m['coverage']:.2f} | {m['median_width']:.3g} | "
                 f"{v['curves_per_fit']:.1f} | {v['interpolation_error_max']:.1e} |")
    L += ["", "## Reading", ""]
    for n in (str(s["points"]), "12"):
        for kind in ("proportional", "additive"):
            rows = {w: out["mu_H"][f"{n}/{kind}/{w}"]["mu_H"] for w in sb.fitting.WEIGHTS}
            best = min(rows, key=lambda w: (abs(rows[w]["coverage"] - 0.95), rows[w]["rms_error"]))
            L.append(f"* {n} points, {kind} noise: mu*H coverage "
                     + ", ".join(f"{w} {rows[w]['coverage']:.3f}" for w in rows)
                     + "; RMS error " + ", ".join(f"{w} {rows[w]['rms_error']:.3g}" for w in rows)
                     + f" N/m; closest to 95 %: `{best}`.")
    L += [f"* Default of `sb.fit` / `shellbvp fit`: `{sb.fitting.DEFAULT_WEIGHTS}`.", ""]
    return "\n".join(L)


if __name__ == "__main__":
    main()
