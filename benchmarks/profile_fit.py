"""A fit with a measured-looking wall profile, and what a profiled curve costs (issue 58).

The sample: the Lepidium-like endosperm of the README's example (preset "fit": gamma 2.5, rho
1/3, Mooney-Rivlin 0.1, rim radius 0.3 mm) with a wall thinning from 20 um at the pole to 12 um
at the rim, ``H = 20 um (1 - 0.4 (S/L)^2)``, and mu = 2.6 MPa (mu*H0 = 52 N/m).  Its record:
40 points to 0.4 R_L, 2 % noise, an approach of 15 rows to the contact at 10 um (as the shipped
records).  The wall as a microscopist measures it: 7 sections along the arc, each to 3 %.

Fitted three ways with the command line (``shellbvp fit``): with the measured table
(``--thickness-profile``), with one thickness (the measured pole's, and the table's mean), and
the modulus mu = mu*H/H of each against the truth; and the table's shape with its scale (the
pole's thickness) fitted too.  Then the cost of a curve to delta 0.4,
profiled against uniform, warm (generated code cached) and the profiled one's first generation.

    python benchmarks/profile_fit.py [--out benchmarks/results/profile_fit.md]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import shellbvp as sb
from shellbvp.thickness_profile import positions_to_S

R_L, H0, MU = 0.3e-3, 20e-6, 2.6e6
SHAPE = "1 - 0.4*(S/L)**2"
TRUE = f"{H0 / R_L!r}*({SHAPE})"


def sample():
    base = sb.Scene.preset("fit", beta=None, thickness=H0 / R_L)
    return base, base.replace(thickness=sb.ThicknessProfile.formula(TRUE))


def measured_table(scene, path, rng):
    """7 sections at equal arc lengths from pole to rim, each thickness read to 3 %."""
    S = np.linspace(0.0, scene.shell_length, 4001)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(np.sin(S)), np.diff(scene.gamma * np.cos(S))))])
    at = np.linspace(0.0, arc[-1], 7)
    H = scene.thickness_profile.at(positions_to_S(scene, at, "arc"), L=scene.shell_length) * R_L
    H *= 1 + 0.03 * rng.standard_normal(H.size)
    path.write_text("arc_um,thickness_um\n" + "".join(f"{a * R_L * 1e6:.3f},{h * 1e6:.3f}\n" for a, h in zip(at, H)))
    return H


def record(scene, path, rng):
    deltas = np.linspace(0.01, 0.4, 40)
    c = sb.curve(scene, deltas=deltas, estimate_error=False)
    d0 = 10e-6
    disp = R_L * np.asarray(c.delta) + d0
    force = MU * H0 * R_L * np.asarray(c.force) * (1 + 0.02 * rng.standard_normal(len(c)))
    disp = np.r_[np.linspace(0.0, d0, 15, endpoint=False), disp]
    force = np.r_[5e-4 * force.max() * rng.standard_normal(15), force]
    path.write_text("displacement (mm),force (mN)\n" + "".join(f"{d * 1e3:.6f},{f * 1e3:.6f}\n"
                                                               for d, f in zip(disp, force)))


def fit(path, extra, out):
    cmd = [sys.executable, "-m", "shellbvp", "fit", str(path), "--preset", "fit", "--radius", "0.3mm",
           "--output", str(out), "--json", *extra]
    t = time.perf_counter()
    run = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if run.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{run.stderr}")
    return json.loads(run.stdout), wall


def cold_generation(code):
    """Wall time of a new process that generates a scene's code into an empty cache."""
    import os

    with tempfile.TemporaryDirectory() as cache:
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", f"import shellbvp as sb; {code}"], check=True,
                       env={**os.environ, "SHELLBVP_CACHE_DIR": cache})
        return time.perf_counter() - t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(58)
    uniform, truth = sample()
    lines = ["# A fit with a measured wall profile (benchmarks/profile_fit.py)", "",
             f"Truth: preset fit, R_L 0.3 mm, H = 20 um (1 - 0.4 (S/L)^2) (12 um at the rim), mu = 2.6 MPa "
             f"(mu*H0 = 52 N/m); record: 40 points to 0.4 R_L, 2 % noise, 15 approach rows.", ""]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        table = tmp / "wall.csv"
        H = measured_table(truth, table, rng)
        rec = tmp / "record.csv"
        record(truth, rec, rng)
        lines += ["Measured wall (7 sections, 3 % each): " + ", ".join(f"{h * 1e6:.2f}" for h in H) + " um", "",
                  "| model of the wall | mu*H (N/m) [95 %] | H used (um) | mu = mu*H/H (MPa) | error in mu | warnings | wall time (s) |",
                  "|---|---|---|---|---|---|---|"]
        runs = (("the measured table (--thickness-profile)", ["--thickness-profile", str(table)], H[0]),
                ("one thickness: the measured pole's", ["--thickness", f"{H[0] * 1e6:.3f}um"], H[0]),
                ("one thickness: the table's mean", ["--thickness", f"{H.mean() * 1e6:.3f}um"], H.mean()),
                ("the table's shape, its scale fitted (--fit-thickness)",
                 ["--thickness-profile", str(table), "--fit-thickness"], None))
        for k, (name, extra, H_used) in enumerate(runs):
            res, wall = fit(rec, extra, tmp / f"fit{k}.h5")
            muH, lo, hi = res["mu_H"], res["mu_H_ci95"][0], res["mu_H_ci95"][1]
            H_text = f"{H_used * 1e6:.2f}" if H_used is not None else (
                f"{res['thickness'] * 1e6:.2f} [{res['thickness_ci95'][0] * 1e6:.2f}, "
                f"{res['thickness_ci95'][1] * 1e6:.2f}] (fitted)")
            H_used = res["thickness"] if H_used is None else H_used  # the fitted pole thickness (m)
            mu = muH / H_used
            lines.append(f"| {name} | {muH:.2f} [{lo:.2f}, {hi:.2f}] | {H_text} | {mu / 1e6:.3f} | "
                         f"{mu / MU - 1:+.1%} | {', '.join(res['warning_codes']) or 'none'} | {wall:.1f} |")
    # the cost of a curve to delta 0.4, uniform against profiled, one run
    generate = {name: cold_generation(code) for name, code in
                (("uniform", f"sb.Scene.preset('fit', beta=None, thickness={H0 / R_L!r}).model()"),
                 ("profiled", f"sb.Scene.preset('fit', beta=None, thickness=sb.ThicknessProfile.formula({TRUE!r})).model()"))}
    costs = {}
    for name, scene in (("uniform", uniform), ("profiled", truth)):
        scene.model()
        t0, c0 = time.perf_counter(), time.process_time()
        sb.curve(scene, delta_max=0.4)
        costs[name] = (time.perf_counter() - t0, time.process_time() - c0)
    lines += ["", "Cost of a curve to delta 0.4 (`sb.curve`, generated code warm, one process):", "",
              "| wall | wall time (s) | CPU (s) |", "|---|---|---|"]
    lines += [f"| {n} | {w:.2f} | {c:.2f} |" for n, (w, c) in costs.items()]
    lines += ["", f"profiled / uniform: {costs['profiled'][0] / costs['uniform'][0]:.2f}x wall, "
                  f"{costs['profiled'][1] / costs['uniform'][1]:.2f}x CPU.  Generating the code the first time "
                  f"(a new process, empty cache, wall time): uniform {generate['uniform']:.1f} s, profiled "
                  f"{generate['profiled']:.1f} s."]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
