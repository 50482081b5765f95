"""Regenerate shellbvp/data/lepidium_synthetic.csv, the synthetic example of the README.

A Lepidium-like endosperm (preset "fit": gamma 2.5, rho 1/3, beta 0.01,
Mooney-Rivlin 0.1, smooth contact) of rim radius 0.3 mm and mu*H = 52 N/m,
contact point 10 um after the start of the record, 2 % multiplicative noise
(seed 1), 40 points, in mm and mN.

    python benchmarks/make_example_data.py
"""

from pathlib import Path

import numpy as np

import shellbvp as sb

R_L, MU_H, D0, NOISE, SEED = 0.3e-3, 52.0, 10e-6, 0.02, 1


def main():
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.4, 40), estimate_error=False)
    rng = np.random.default_rng(SEED)
    disp = R_L * c.delta + D0
    force = MU_H * R_L * c.force * (1 + NOISE * rng.standard_normal(len(c)))
    out = Path(__file__).parents[1] / "shellbvp" / "data" / "lepidium_synthetic.csv"
    lines = ["# synthetic: preset fit, R_L = 0.3 mm, mu*H = 52 N/m, contact at 0.01 mm, 2% noise (seed 1)",
             "displacement (mm),force (mN)"]
    lines += [f"{d * 1e3:.6f},{f * 1e3:.6f}" for d, f in zip(disp, force)]
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
