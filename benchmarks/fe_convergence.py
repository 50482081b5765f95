"""The solid's mesh convergence on a thin shell (issue 54, item 2): the hemisphere, rho 0.2,
eps 0.02, neo-Hookean, its rim face hinged (the default), at the indenter's displacements
H/2, H and 5H from first touch, on the default mesh (0.5 H along the meridian, 3 elements
through H) and on the records' mesh of ``thick_fits.py`` (0.33 H, 4; ``--finest`` adds 0.25 H,
6).  The paper's seed (eps 1/6) is in ``thick_fits.py``'s convergence table.

    python benchmarks/fe_convergence.py [--finest] [--out-dir DIR]   # results/fe_convergence.{json,md}
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package

import shellbvp as sb  # noqa: E402

sys.path.insert(0, str(HERE))
from checkout import add_output_args, results_dir  # noqa: E402

EPS = 0.02
DEPTHS = [0.5 * EPS, EPS, 5 * EPS]
MESHES = [dict(element_length=0.5, through_thickness=3), dict(element_length=0.33, through_thickness=4)]
FINEST = dict(element_length=0.25, through_thickness=6)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--finest", action="store_true", help="also the 0.25 H, 6 mesh (slow)")
    args = add_output_args(ap).parse_args(argv)
    meshes = MESHES + ([FINEST] if args.finest else [])
    scene = sb.Scene(gamma=1.0, rho=0.2, material=sb.NeoHookean(), thickness=EPS)
    rows, t_all = [], time.perf_counter()
    for mesh in meshes:
        t0 = time.perf_counter()
        c = sb.fe_curve(scene, EPS, DEPTHS, at="indenter", **mesh)
        rows.append({**mesh, "elements": list(c.elements), "force": list(map(float, c.force)),
                     "success": bool(c.success), "seconds": time.perf_counter() - t0})
        print(rows[-1], flush=True)
    finest = np.array(rows[-1]["force"])
    for row in rows:
        row["vs_finest"] = list(map(float, np.array(row["force"]) / finest - 1))
    doc = {"scene": "hemisphere rho 0.2, eps 0.02, neo-Hookean", "depths": DEPTHS, "rows": rows,
           "machine": platform.platform(), "version": sb.__version__, "seconds": time.perf_counter() - t_all}
    out = results_dir(args.out_dir) / "fe_convergence"
    out.with_suffix(".json").write_text(json.dumps(doc, indent=1))
    lines = [f"# The solid's mesh convergence on a thin shell\n",
             f"`python benchmarks/fe_convergence.py` ({doc['seconds']:.0f} s, {doc['machine']}, shellbvp "
             f"{doc['version']}): the hemisphere, rho 0.2, eps 0.02, neo-Hookean, rim face hinged; the force at "
             f"the indenter's displacements H/2, H, 5H against the finest mesh.\n",
             "| mesh (element length / H, through H) | elements | F at H/2 | F at H | F at 5H | seconds |",
             "|---|---|---|---|---|---|"]
    for row in rows:
        e = row["vs_finest"]
        lines.append(f"| {row['element_length']}, {row['through_thickness']} | {row['elements'][0]}x{row['elements'][1]} "
                     f"| {100 * e[0]:+.3f} % | {100 * e[1]:+.3f} % | {100 * e[2]:+.3f} % | {row['seconds']:.0f} |")
    out.with_suffix(".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
