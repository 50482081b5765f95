"""The solid's mesh convergence on a thin shell (issue 54, item 2): the hemisphere, rho 0.2,
eps 0.02, neo-Hookean, its rim face hinged (the default), at the indenter's displacements
H/2, H and 5H from first touch, on the default mesh (0.5 H along the meridian, 3 elements
through H) and on the records' mesh of ``thick_fits.py`` (0.33 H, 4; ``--finest`` adds 0.25 H,
6).  The paper's seed (eps 1/6) is in ``thick_fits.py``'s convergence table; ``validation.py
--mesh-check`` compares each curve of the error map with a coarser mesh (2/3 the elements).

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
from checkout import add_output_args, results_dir, write_atomic  # noqa: E402

EPS = 0.02
DEPTHS = [0.5 * EPS, EPS, 5 * EPS]
MESHES = [dict(element_length=0.5, through_thickness=3), dict(element_length=0.33, through_thickness=4)]
FINEST = dict(element_length=0.25, through_thickness=6)


def run(meshes):
    """Each mesh's forces at DEPTHS (the default mesh first)."""
    scene = sb.Scene(gamma=1.0, rho=0.2, material=sb.NeoHookean(), thickness=EPS)
    rows, t_all = [], time.perf_counter()
    for mesh in meshes:
        t0 = time.perf_counter()
        c = sb.fe_curve(scene, EPS, DEPTHS, at="indenter", **mesh)
        rows.append({**mesh, "elements": list(c.elements), "force": list(map(float, c.force)),
                     "success": bool(c.success), "seconds": time.perf_counter() - t0})
        print(rows[-1], flush=True)
    return {"scene": "hemisphere rho 0.2, eps 0.02, neo-Hookean, rim face hinged", "eps": EPS, "depths": DEPTHS,
            "force_units": "mu R_L H", "rows": rows, "machine": platform.platform(), "version": sb.__version__,
            "seconds": time.perf_counter() - t_all}


def report(doc):
    """The table: each mesh's forces, then every coarser mesh against the finest one run."""
    rows = doc["rows"]
    finest = rows[-1]
    name = f"{finest['element_length']}, {finest['through_thickness']}"
    lines = ["# The solid's mesh convergence on a thin shell", "",
             f"`python benchmarks/fe_convergence.py{' --finest' if len(rows) > len(MESHES) else ''}` "
             f"({doc['seconds']:.0f} s, {doc['machine']}, shellbvp {doc['version']}): the {doc['scene']}; the force "
             f"(units {doc['force_units']}) at the indenter's displacements H/2, H, 5H from first touch on each mesh, "
             f"and each coarser mesh against the finest ({name}).", "",
             "| mesh (element length / H, through H) | elements | F at H/2 | F at H | F at 5H | seconds |",
             "|---|---|---|---|---|---|"]
    for i, row in enumerate(rows):
        forces = " | ".join(f"{f:.6g}" if row["success"] else f"{f:.6g} (not converged)" for f in row["force"])
        lines.append(f"| {row['element_length']}, {row['through_thickness']}{' (default)' if i == 0 else ''} | "
                     f"{row['elements'][0]}x{row['elements'][1]} | {forces} | {row['seconds']:.0f} |")
    for row in rows[:-1]:
        rel = np.array(row["force"]) / np.array(finest["force"]) - 1
        lines.append(f"| {row['element_length']}, {row['through_thickness']} against {name} | | "
                     + " | ".join(f"{100 * e:+.3f} %" for e in rel) + " | |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--finest", action="store_true", help="also the 0.25 H, 6 mesh (slow)")
    args = add_output_args(ap).parse_args(argv)
    doc = run(MESHES + ([FINEST] if args.finest else []))
    out = results_dir(args.out_dir) / "fe_convergence"
    write_atomic(out.with_suffix(".json"), json.dumps(doc, indent=1))
    if json.loads(out.with_suffix(".json").read_text()) != doc:
        raise SystemExit(f"fe_convergence.py: {out}.json does not read back as written")
    write_atomic(out.with_suffix(".md"), report(doc))
    print(report(doc))


if __name__ == "__main__":
    main()
