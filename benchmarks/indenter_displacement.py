"""The indenter's displacement against the mid-surface pole's, and what it does to a shell fit (issue 54).

A shell fit compares the shell model's delta (its mid-surface pole's displacement) with the
instrument's displacement of the indenter, which also holds the wall's thinning and compression
under the tip.  On issue 54's five held-out scenes (thick_fits.py's), the package's solid
(``sb.fe_curve(at="pole")``) gives both at each pole depth; the shell model gives F there and the
wall's membrane thinning at its pole, ``(H/2) (1 - 1/(lambda_s lambda_theta))``.  Reported per depth:

* ``gap / H``: the indenter's displacement minus the mid-surface pole's (the solid's), and the
  part of it the shell's membrane thinning predicts;
* the shell's error in F against the solid (a) at equal pole displacement, (b) at the indenter's
  displacement taken as delta (what a fit of an instrument record compares), (c) at the indenter's
  displacement less the predicted thinning (a first-order correction of (b)).

A correction is worth building only if (c) is smaller than (b) on every scene.

    python benchmarks/indenter_displacement.py [--workers 2]
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
from thick_fits import HELD_OUT, scene_of  # noqa: E402

#: pole depths in units of H, up to 0.3 R_L
DEPTHS_H = (0.25, 0.5, 1.0, 2.0, 3.0)


def shell_at(scene, delta):
    """(F, predicted thinning) of the shell model at pole displacement ``delta``."""
    s = sb.solve(scene, delta=float(delta), tol=1e-6)
    if not s.success:
        return float("nan"), float("nan")
    p = s.profile()
    lam3 = 1.0 / (p["lambda_s"][0] * p["lambda_theta"][0])
    return float(s.force), 0.5 * scene.thickness * (1.0 - lam3)


def measure(name):
    gamma, rho, eps = HELD_OUT[name]
    scene = scene_of(gamma, rho, eps)
    deltas = np.array([d * eps for d in DEPTHS_H if d * eps <= 0.3])
    t0 = time.perf_counter()
    fe = sb.fe_curve(scene, eps, deltas, at="pole")
    rows = []
    for d, ind, F in zip(fe.delta, fe.indenter, fe.force):
        F_pole, thin = shell_at(scene, d)
        F_ind, thin_ind = shell_at(scene, ind)
        F_corr, _ = shell_at(scene, ind - thin_ind)
        rows.append({"delta_H": d / eps, "gap_H": (ind - d) / eps, "thinning_H": thin / eps, "F_solid": F,
                     "at_pole": F_pole / F - 1, "at_indenter": F_ind / F - 1, "corrected": F_corr / F - 1})
    return {"scene": name, "gamma": gamma, "rho": rho, "eps": eps, "rows": rows,
            "seconds": time.perf_counter() - t0, "solid": fe.summary()}


def table(results):
    out = ["| scene | delta / H | gap / H (solid) | thinning / H (shell) | F error at equal pole delta | "
           "at the indenter's displacement | corrected by the thinning |", "|---|---|---|---|---|---|---|"]
    for r in results:
        for row in r["rows"]:
            out.append(f"| {r['scene']} (eps {r['eps']:.3g}) | {row['delta_H']:.2f} | {row['gap_H']:+.3f} | "
                       f"{row['thinning_H']:+.3f} | {100 * row['at_pole']:+.1f} % | {100 * row['at_indenter']:+.1f} % | "
                       f"{100 * row['corrected']:+.1f} % |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=str(HERE / "results" / "indenter_displacement"))
    args = ap.parse_args()
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(measure, HELD_OUT))
    doc = {"results": results, "machine": platform.platform(), "version": sb.__version__,
           "seconds": time.perf_counter() - t0}
    Path(args.out + ".json").write_text(json.dumps(doc, indent=1))
    text = (f"# The indenter's displacement against the mid-surface pole's\n\n"
            f"`python benchmarks/indenter_displacement.py` ({doc['seconds']:.0f} s, {doc['machine']}, "
            f"shellbvp {doc['version']}).  {__doc__.split(chr(10), 2)[2].split('    python')[0].strip()}\n\n"
            f"{table(results)}\n")
    Path(args.out + ".md").write_text(text)
    print(table(results))


if __name__ == "__main__":
    main()
