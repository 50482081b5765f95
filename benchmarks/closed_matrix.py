"""A curve and a fit of a closed shell on each support with each interior (issue 55).

A thin complete sphere (eps = H/R 0.02, Mooney-Rivlin alpha 0.1) between two plates and on a
substrate under a sphere tip (rho 0.3), open, with a turgor (pressure 0.1: p R/(mu H)) and sealed
(the volume held, the pressure rising from 0).  For each: the curve ``sb.curve`` to delta 0.3
(points, valid points, CPU s, the force there) and a fit of an instrument-like record made from
the model itself -- the same scene's curve at tol 1e-8 (the fit's is 1e-6) at 25 depths to 0.25 R,
mu*H 1 N/m, R 10 um, the contact 0.5 um after an approach of 10 rows, 1 % noise and a floor of
0.1 % of the largest force (seeded) -- by ``sb.fit`` with a constant baseline, as ``shellbvp fit``
does.  This checks the whole path of a closed shell's fit (record to mu*H); the model's own error
against 3D elasticity is another benchmark's (thick_fits.py --set closed, closed_solid.py).

    python benchmarks/closed_matrix.py [--quick] [--out-dir DIR]   # results/closed_matrix[-quick].md
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import shellbvp as sb

from checkout import add_output_args, commit_label, results_dir, stem, write_atomic  # benchmarks/ is on sys.path

EPS, RHO, PRESSURE = 0.02, 0.3, 0.1
R, MU_H, CONTACT, APPROACH = 10e-6, 1.0, 0.5e-6, 10
NOISE, FLOOR, DEPTH, ROWS = 0.01, 0.001, 0.25, 25
SUPPORTS = {"plates": dict(support="plates", tip=sb.FlatTip(), rho=1.0),
            "substrate": dict(support="substrate", tip=sb.SphereTip(), rho=RHO)}
INTERIORS = {"open": {}, "pressure 0.1": dict(pressure=PRESSURE), "sealed": dict(sealed=True)}


def scene_of(support, interior):
    return sb.Scene(closed=True, gamma=1.0, thickness=EPS, material=sb.MooneyRivlin(0.1), xi=1,
                    **SUPPORTS[support], **INTERIORS[interior])


def cpu(f, *args, **kw):
    t = time.process_time()
    out = f(*args, **kw)
    return out, time.process_time() - t


def record(scene, seed):
    """(displacement m, force N) of an instrument: approach rows at zero force, then the model's
    curve at tol 1e-8, with noise."""
    depths = np.linspace(DEPTH / ROWS, DEPTH, ROWS)
    c = sb.curve(scene, deltas=depths, tol=1e-8)
    ok = np.asarray(c.valid, bool) & np.isfinite(c.force)
    d, f = np.asarray(c.delta)[ok], np.asarray(c.force)[ok]
    rng = np.random.default_rng(seed)
    force = MU_H * R * f
    floor = FLOOR * force.max()
    force = force * (1 + NOISE * rng.standard_normal(force.size)) + floor * rng.standard_normal(force.size)
    before = np.linspace(0.0, CONTACT, APPROACH, endpoint=False)
    disp = np.r_[before, CONTACT + d * R]
    return disp, np.r_[floor * rng.standard_normal(APPROACH), force]


def one(support, interior, seed, quick):
    scene = scene_of(support, interior)
    c, t_curve = cpu(sb.curve, scene, delta_max=0.1 if quick else 0.3)
    valid = np.asarray(c.valid, bool)
    row = dict(support=support, interior=interior, points=len(c), valid=int(valid.sum()), curve_s=t_curve,
               delta=float(np.asarray(c.delta)[valid][-1]) if valid.any() else float("nan"),
               force=float(np.asarray(c.force)[valid][-1]) if valid.any() else float("nan"))
    if quick:
        return row
    disp, force = record(scene, seed)
    res, t_fit = cpu(sb.fit, scene, disp, force, R_L=R, baseline="constant")
    lo, hi = res.mu_H_ci95
    row.update(mu_H=res.mu_H, lo=lo, hi=hi, fit_s=t_fit, quality=res.quality,
               success=bool(res.success))
    return row


def table(rows, quick):
    head = "| support | interior | curve points (valid) | delta | F | curve CPU s |"
    sep = "|---|---|---|---|---|---|"
    if not quick:
        head += " fitted mu*H (N/m) [95 % CI] | error | truth in CI | quality | fit CPU s |"
        sep += "---|---|---|---|---|"
    lines = [head, sep]
    for r in rows:
        line = (f"| {r['support']} | {r['interior']} | {r['points']} ({r['valid']}) | {r['delta']:.3g} | "
                f"{r['force']:.5g} | {r['curve_s']:.2f} |")
        if not quick:
            inside = r["lo"] <= MU_H <= r["hi"]
            line += (f" {r['mu_H']:.4g} [{r['lo']:.4g}, {r['hi']:.4g}] | {100 * (r['mu_H'] / MU_H - 1):+.2f} % | "
                     f"{'yes' if inside else 'no'} | {r['quality']} | {r['fit_s']:.1f} |")
        lines.append(line)
    return "\n".join(lines)


def main():
    ap = add_output_args(argparse.ArgumentParser(description=__doc__.splitlines()[0]),
                         quick="curves to delta 0.1, no fits")
    args = ap.parse_args()
    start = time.time()
    rows = [one(s, i, seed, args.quick) for seed, (s, i) in enumerate((s, i) for s in SUPPORTS for i in INTERIORS)]
    text = (f"# A curve and a fit per support and interior (closed shells, issue 55)\n\n"
            f"`python benchmarks/closed_matrix.py{' --quick' if args.quick else ''}` at {commit_label()} "
            f"({platform.platform()}, {time.time() - start:.0f} s).  The module's docstring says how the scenes "
            f"and records are made; a complete sphere, eps {EPS}, sphere tip rho {RHO} on the substrate.  "
            f"Forces F / (mu R H) at the deepest valid point.\n\n{table(rows, args.quick)}\n")
    path = results_dir(args.out_dir) / f"{stem('closed_matrix', args.quick)}.md"
    write_atomic(path, text)
    print(text)


if __name__ == "__main__":
    main()
