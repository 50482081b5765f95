"""Coverage of the 95 % intervals when the fit places the contact point among approach rows.

Synthetic records of the preset ``fit`` (R_L = 0.3 mm, mu*H = 40 N/m, contact 25 um into
the record, loading to delta = 0.4), 2 % proportional and 2 uN additive noise, seeds
100..100+N-1, default (mixed) weights:

* ``record``: the whole instrument record (approach, loading, hold, a retraction with
  15 % hysteresis, a 150 uN baseline) through ``fit_record`` (segments, baseline auto);
* ``approach, no baseline``: the pushing rows alone, baseline 0 and not fitted;
* ``contact rows only``: the rows 2 um or more past the contact (no approach), no baseline.

    python benchmarks/fit_baseline_coverage.py [--seeds 200] [--quick] [--out-dir DIR]

Writes results/fit_baseline_coverage.md (``--quick``: 5 seeds, fit_baseline_coverage-quick.md).
"""

import argparse
import time

import numpy as np
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.fitting import fit_record
from shellbvp.instrument import InstrumentRecord, segment

from checkout import add_output_args, results_dir, stem  # benchmarks/ is on sys.path

R_L, MU_H, D0, BASE = 0.3e-3, 40.0, 25e-6, 150e-6


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=200)
    add_output_args(p, quick="5 seeds")
    args = p.parse_args()
    if args.quick:
        args.seeds = 5
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    top = D0 + 0.4 * R_L
    push = np.linspace(-20e-6, top, 160)
    d = np.r_[push, np.full(20, top), np.linspace(top, -20e-6, 160)]
    F = MU_H * R_L * shape(np.clip((d - D0) / R_L, 0, 0.45))
    rows = []
    for case in ("record", "approach, no baseline", "contact rows only"):
        hits, errs, widths, t0 = np.zeros(2), [], [], time.perf_counter()
        for seed in range(args.seeds):
            rng = np.random.default_rng(100 + seed)
            f = F * np.r_[np.ones(180), 0.85 * np.ones(160)]
            f = f * (1 + 0.02 * rng.standard_normal(d.size)) + 2e-6 * rng.standard_normal(d.size)
            if case == "record":
                rec = InstrumentRecord(path="synthetic", sha256="", displacement=d, force=f + BASE, time=None,
                                       line=np.arange(d.size), segments=segment(d), columns={}, units={})
                res, _ = fit_record(scene, rec, R_L=R_L)
            elif case == "approach, no baseline":
                res = sb.fit(scene, d[:160], f[:160], R_L=R_L, contact_guess=20e-6)
            else:
                m = push > D0 + 2e-6
                res = sb.fit(scene, push[m], f[:160][m], R_L=R_L)
            hits += [res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1], res.offset_ci95[0] < D0 < res.offset_ci95[1]]
            errs.append(res.mu_H - MU_H)
            widths.append(res.mu_H_ci95[1] - res.mu_H_ci95[0])
        rows.append((case, hits / args.seeds, float(np.sqrt(np.mean(np.square(errs)))), float(np.median(widths)),
                     time.perf_counter() - t0))
        print(rows[-1])
    lines = [f"# Interval coverage with the contact point among approach rows ({args.seeds} seeds)", "",
             "`python benchmarks/fit_baseline_coverage.py` (see its docstring for the records).", "",
             "| data | mu*H coverage | offset coverage | RMS error of mu*H (N/m) | median 95 % width (N/m) |",
             "|---|---|---|---|---|"]
    lines += [f"| {case} | {cov[0]:.3f} | {cov[1]:.3f} | {rms:.3f} | {w:.3f} |" for case, cov, rms, w, _ in rows]
    out = results_dir(args.out_dir) / f"{stem('fit_baseline_coverage', args.quick)}.md"
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
