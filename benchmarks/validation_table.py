"""The closing table of issue 41: F_shell / F_FE - 1 at delta = H and delta = 0.3 against eps.

Hemisphere, rho 0.2, neo-Hookean; shell model with beta = eps^2/3, both contact models, with
and without transverse shear.  One FE curve per eps (``sb.fe_curve`` at delta = H and 0.3).

    python benchmarks/validation_table.py [--eps 0.1,0.05,0.02,0.01] [--workers 2] [--quick] [--out-dir DIR]

Writes results/validation_table.{json,md} (``--quick``: eps 0.1 only, validation_table-quick.*).
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
sys.path.insert(0, str(HERE.parent))

import shellbvp as sb  # noqa: E402
from shellbvp.validation import shell_curve  # noqa: E402

sys.path.insert(0, str(HERE))
from checkout import add_output_args, commit_label, results_dir, stem  # noqa: E402

VARIANTS = {"smooth": dict(contact="smooth"), "smooth, shear": dict(contact="smooth", transverse_shear=True),
            "paper": dict(contact="paper"), "paper, shear": dict(contact="paper", transverse_shear=True)}
DEPTH = 0.3


def row(eps):
    scene = sb.Scene(gamma=1.0, rho=0.2, material=sb.NeoHookean(), thickness=eps)
    d = np.array([eps, DEPTH])
    t0 = time.perf_counter()
    fe = sb.fe_curve(scene, eps, d)
    out = {"eps": eps, "delta": d.tolist(), "force_fe": fe.force.tolist(), "fe_seconds": time.perf_counter() - t0,
           "fe_message": fe.message}
    for name, over in VARIANTS.items():
        c = shell_curve(scene.replace(**over), d)
        out[name] = (c.force_at(d) / fe.force - 1).tolist()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", default="0.1,0.05,0.02,0.01")
    ap.add_argument("--workers", type=int, default=2)
    add_output_args(ap, quick="eps 0.1 only")
    args = ap.parse_args(argv)
    if args.quick:
        args.eps = "0.1"
    name = stem("validation_table", args.quick)
    eps = [float(x) for x in args.eps.split(",")]
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        rows = list(pool.map(row, eps))
    out = results_dir(args.out_dir)
    (out / f"{name}.json").write_text(json.dumps(rows, indent=1))
    lines = [f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()}, shellbvp at "
             f"{commit_label() or 'unknown commit'}; `python benchmarks/validation_table.py"
             f"{' --quick' if args.quick else ''}`.", "",
             "Hemisphere, rho 0.2, neo-Hookean, beta = eps^2/3: F_shell / F_FE - 1 in percent at the "
             f"mid-surface pole displacement delta = H and delta = {DEPTH:g}; 'shear': "
             "`transverse_shear=True`.", "",
             "| eps | delta | " + " | ".join(VARIANTS) + " | FE s |", "|---|---|" + "---|" * (len(VARIANTS) + 1)]
    for r in rows:
        for i, label in enumerate(("H", f"{DEPTH:g}")):
            lines.append(f"| {r['eps']:g} | {label} | " + " | ".join(f"{100 * r[v][i]:+.1f}" for v in VARIANTS)
                         + f" | {r['fe_seconds']:.0f} |")
    (out / f"{name}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
