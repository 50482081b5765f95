"""Regenerate the synthetic records that ship with the package (shellbvp/data/):

* lepidium_synthetic.csv, the example of the README: a Lepidium-like endosperm (preset "fit":
  gamma 2.5, rho 1/3, beta 0.01, Mooney-Rivlin 0.1, smooth contact) of rim radius 0.3 mm and
  mu*H = 52 N/m, contact point 10 um after the start of the record, 2 % multiplicative noise
  (seed 1), 40 points, in mm and mN;
* cell_glass_synthetic.csv (docs/closed.md): a walled cell on glass under a colloidal probe
  (preset "cell-glass") of radius 2.5 um and mu*H = 3.3 N/m, an approach of 15 rows (force
  noise only) to the contact at 50 nm, 30 points to 0.25 of the radius, 1 % noise and 0.05 %
  of the largest force as the approach's (seed 2), in nm and nN;
* capsule_plates_synthetic.csv (docs/closed.md): a sealed capsule between plates (preset
  "capsule-plates") of radius 30 um and mu*H = 0.5 N/m, an approach of 15 rows to the contact
  at 3 um, 30 points to 0.4 of the radius, the same noise (seed 3), in um and uN.

    python benchmarks/make_example_data.py --write             # the shipped records, rewritten
    python benchmarks/make_example_data.py --out-dir /tmp/x    # the same files elsewhere (to compare)
    python benchmarks/make_example_data.py --out-dir /tmp/x --only cell_glass_synthetic.csv

One of ``--write`` or ``--out-dir`` is required: without either the script does nothing.
Each file is written atomically and read back (the numbers it holds, against those computed).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import shellbvp as sb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checkout import write_atomic  # noqa: E402

#: where the shipped records live
DATA = Path(__file__).resolve().parents[1] / "shellbvp" / "data"

#: (file, preset, R_L (m), mu*H (N/m), contact offset (m), noise, seed, depths over R_L, units and scales)
RECORDS = (
    ("lepidium_synthetic.csv", "fit", 0.3e-3, 52.0, 10e-6, 0.02, 1, np.linspace(0.01, 0.4, 40), ("mm", 1e3, "mN", 1e3)),
    ("cell_glass_synthetic.csv", "cell-glass", 2.5e-6, 3.3, 50e-9, 0.01, 2, np.linspace(0.01, 0.25, 30),
     ("nm", 1e9, "nN", 1e9), 15),
    ("capsule_plates_synthetic.csv", "capsule-plates", 30e-6, 0.5, 3e-6, 0.01, 3, np.linspace(0.02, 0.4, 30),
     ("um", 1e6, "uN", 1e6), 15),
)


#: the approach's force noise, a fraction of the largest force
APPROACH_NOISE = 5e-4


def write(out_dir, name, preset, R_L, mu_H, d0, noise, seed, deltas, units, approach=0):
    scene = sb.Scene.preset(preset)
    c = sb.curve(scene, deltas=deltas, estimate_error=False)
    rng = np.random.default_rng(seed)
    disp = R_L * c.delta + d0
    force = mu_H * R_L * c.force * (1 + noise * rng.standard_normal(len(c)))
    if approach:  # rows before the contact: the force's noise only
        disp = np.r_[np.linspace(0.0, d0, approach, endpoint=False), disp]
        force = np.r_[APPROACH_NOISE * force.max() * rng.standard_normal(approach), force]
    du, ds, fu, fs = units
    out = Path(out_dir) / name
    lines = [f"# synthetic: preset {preset}, R_L = {R_L * ds:g} {du}, mu*H = {mu_H:g} N/m, contact at "
             f"{d0 * ds:g} {du}, {noise:.0%} noise (seed {seed})" + (f", an approach of {approach} rows" if approach
                                                                      else ""), f"displacement ({du}),force ({fu})"]
    lines += [f"{d * ds:.6f},{f * fs:.6f}" for d, f in zip(disp, force)]
    write_atomic(out, "\n".join(lines) + "\n")
    back = np.loadtxt(out, delimiter=",", comments="#", skiprows=2)
    if back.shape != (len(disp), 2) or not np.allclose(back, np.c_[disp * ds, force * fs], rtol=0, atol=1e-6):
        raise SystemExit(f"make_example_data.py: {out} does not read back as written")
    print(f"wrote {out} ({len(disp)} rows, read back)")
    return out


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 epilog="One of --write or --out-dir is required.")
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--write", action="store_true", help=f"rewrite the shipped records in {DATA}")
    where.add_argument("--out-dir", type=Path, help="write the records into this existing directory instead")
    ap.add_argument("--only", action="append", choices=[r[0] for r in RECORDS], metavar="FILE",
                    help="only this record (repeatable; choices: " + ", ".join(r[0] for r in RECORDS) + ")")
    args = ap.parse_args(argv)
    if args.out_dir is not None and not args.out_dir.is_dir():
        ap.error(f"--out-dir: {args.out_dir} is not a directory")
    return args


def main(argv=None):
    args = parse_args(argv)
    out_dir = DATA if args.write else args.out_dir
    for record in RECORDS:
        if args.only is None or record[0] in args.only:
            write(out_dir, *record)


if __name__ == "__main__":
    main()
