"""Point-load stiffness of a pressurised spherical shell against Vella et al. (2012).

    python benchmarks/vella.py                  # -> results/vella.md, results/vella.json
    python benchmarks/vella.py --quick          # one beta, three tau (-quick files)

Vella, Ajdari, Vaziri & Boudaoud, "The indentation of pressurized elastic shells: from
polymeric capsules to yeast cells", J. R. Soc. Interface 9 (2012): in the shallow-shell
limit (linear shallow-shell equations with the isotropic pre-tension pR/2) the
point-load stiffness is

    k = (8 sqrt(B Y)/R) (pi/2) sqrt(tau^2 - 1)/artanh(sqrt(1 - tau^-2)),
    tau = p R^2/(4 sqrt(B Y))

(for tau < 1 the same with arctan; tau -> 0: Reissner's 8 sqrt(B Y)/R; large tau:
pi p R/ln(2 tau)).  In shellbvp's units B = beta and Y = Eh = 3 (incompressible, mu = 1).

The scene: a hemispherical dome (gamma = -1, R = 1) indented from outside at its pole by
a sphere of radius 0.05, Mooney-Rivlin 0.1, at a depth delta = f h (h = sqrt(12 beta),
the paper's thickness for this beta; twice sqrt(3 beta), the 3D map's).  The formula's assumptions: bending length
(beta/3)^(1/4) and the tension's length much smaller than R, pre-strain p R/(2 Y) small,
delta << h.  Reported: k = F/delta against the formula with R = 1 and with the inflated
pole's own radius of curvature.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
from pathlib import Path

import shellbvp as sb

HERE = Path(__file__).resolve().parent
TAUS = (0.0, 0.1, 0.3, 1.0, 3.0, 10.0)


def vella_factor(tau: float) -> float:
    """k / (8 sqrt(B Y)/R) of Vella et al. (2012) at tau = p R^2/(4 sqrt(B Y))."""
    if tau == 0:
        return 1.0
    if abs(tau - 1) < 1e-12:
        return math.pi / 2
    if tau < 1:
        return (math.pi / 2) * math.sqrt(1 - tau**2) / math.atan(math.sqrt(1 / tau**2 - 1))
    return (math.pi / 2) * math.sqrt(tau**2 - 1) / math.atanh(math.sqrt(1 - tau**-2))


def row(beta: float, tau: float, frac: float) -> dict:
    p = 4 * tau * math.sqrt(3 * beta)
    scene = sb.Scene(gamma=-1.0, rho=0.05, beta=beta, pressure=p)
    h = math.sqrt(12 * beta)
    delta = frac * h
    t0 = time.perf_counter()
    s = sb.solve(scene, delta=delta, tol=1e-8, estimate_error=False)
    R = 1.0
    if p:
        R = -1.0 / float(sb.inflate(scene).profile()["kappa_s"][0])
    k_reissner = 8 * math.sqrt(3 * beta)
    k = s.force / delta if s.success else math.nan
    tau_def = p * R**2 / (4 * math.sqrt(3 * beta))
    return {"beta": beta, "tau": tau, "p": p, "delta_over_h": frac, "success": bool(s.success),
            "topology": s.topology, "message": "" if s.success else s.message,
            "k": k, "k_formula": k_reissner * vella_factor(tau), "ratio": k / (k_reissner * vella_factor(tau)),
            "R_inflated": R, "ratio_inflated_R": k / (k_reissner / R * vella_factor(tau_def)),
            "seconds": time.perf_counter() - t0}


def main(argv=None):
    from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path (tests load this module alone)

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    add_output_args(ap)
    args = ap.parse_args(argv)
    plan = [(1e-4, t, 0.003) for t in (0.0, 1.0, 3.0)] if args.quick else (
        [(1e-4, t, f) for f in (0.003, 0.03) for t in TAUS] + [(1e-5, t, f) for f in (0.003, 0.03) for t in TAUS])
    rows = []
    for beta, tau, frac in plan:
        rows.append(row(beta, tau, frac))
        r = rows[-1]
        print(f"beta {beta:g} delta/h {frac:g} tau {tau:g}: {r['success']} k/k_formula {r['ratio']:.4f}", flush=True)
    suffix = "-quick" if args.quick else ""
    out = results_dir(args.out_dir)
    (out / f"vella{suffix}.json").write_text(json.dumps(rows, indent=1, default=float))
    lines = [f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()}, shellbvp {sb.__version__}; "
             f"`python benchmarks/vella.py{' --quick' if args.quick else ''}`.  Hemispherical dome indented at its "
             "pole from outside (rho 0.05, Mooney-Rivlin 0.1) against Vella et al. (2012); k = F/delta.", "",
             "| beta | delta/h | tau | p | state | k | formula (R = 1) | ratio | ratio (inflated R) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        state = r["topology"] if r["success"] else f"failed: {r['message'][:60]}"
        lines.append(f"| {r['beta']:g} | {r['delta_over_h']:g} | {r['tau']:g} | {r['p']:.4g} | {state} | "
                     f"{r['k']:.5g} | {r['k_formula']:.5g} | {r['ratio']:.4f} | {r['ratio_inflated_R']:.4f} |")
    (out / f"vella{suffix}.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
