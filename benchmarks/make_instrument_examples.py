"""Write three instrument-style records of known mu*H into a folder (the batch example).

Each record is what an indenter exports: tab-separated, ``#`` comment lines, columns
``Time (s)``, ``Displacement (um)``, ``Force (uN)``; an approach before contact at a force
baseline of 80 uN, the loading, a short hold with creep and a retraction with hysteresis;
2 % proportional and 1 uN additive noise.  The shell is the preset ``fit`` (gamma 2.5,
rho 1/3, beta 0.01, Mooney-Rivlin 0.1) of rim radius 0.3 mm; mu*H is 35, 40 and 47 N/m,
the contact points 20, 30 and 25 um into the record.

    python benchmarks/make_instrument_examples.py DIR
    shellbvp fit DIR --preset fit --radius 0.3mm --table results.csv -o fits
    shellbvp plot fits/*.h5
"""

import argparse
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

import shellbvp as sb

R_L, BASELINE = 0.3e-3, 80e-6
#: name: (mu*H in N/m, contact point in m, deepest delta)
SEEDS = {"seed_a": (35.0, 20e-6, 0.40), "seed_b": (40.0, 30e-6, 0.36), "seed_c": (47.0, 25e-6, 0.38)}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder")
    out = Path(p.parse_args().folder)
    out.mkdir(parents=True, exist_ok=True)
    c = sb.curve(sb.Scene.preset("fit"), deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    for k, (name, (mu_H, d0, depth)) in enumerate(SEEDS.items()):
        rng = np.random.default_rng(k)
        top = d0 + depth * R_L
        d = np.r_[np.linspace(0, top, 150), np.full(15, top), np.linspace(top, 0, 150)]
        f = mu_H * R_L * shape(np.clip((d - d0) / R_L, 0, None))
        f[150:165] *= np.linspace(1, 0.97, 15)  # creep during the hold
        f[165:] *= 0.85 * np.linspace(0.97, 1, 150)  # hysteresis: the retraction carries less force
        f = f * (1 + 0.02 * rng.standard_normal(d.size)) + BASELINE + 1e-6 * rng.standard_normal(d.size)
        lines = [f"# synthetic indentation of {name}: preset fit, R_L = 0.3 mm, mu*H = {mu_H:g} N/m, "
                 f"contact at {d0 * 1e6:g} um, baseline {BASELINE * 1e6:g} uN",
                 "Time (s)\tDisplacement (um)\tForce (uN)"]
        lines += [f"{0.1 * i:.1f}\t{a * 1e6:.4f}\t{b * 1e6:.4f}" for i, (a, b) in enumerate(zip(d, f))]
        (out / f"{name}.tsv").write_text("\n".join(lines) + "\n")
        print(f"wrote {out / name}.tsv")


if __name__ == "__main__":
    main()
