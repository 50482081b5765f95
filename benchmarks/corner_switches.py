"""Where the smooth model's contact edge becomes a corner, on every stability-grid scene where it does.

For each scene: the curve to delta = 1 (``sb.curve``, tol 1e-6, no error estimates), and the
located switch (``settings["topology_switches"]``): delta* from the smooth side (the edge
Legendre determinant -> 0) and from the corner side (the jump of lambda_s -> 0), the jumps of F
and E across it extrapolated from each side, its kind, and the jump of lambda_s at delta = 1.

    python benchmarks/corner_switches.py [--quick] [--out-dir DIR]   # results/corner_switches[-quick].md

``--quick``: the base scene only.
"""

from __future__ import annotations

import argparse
import time

import shellbvp as sb

from checkout import add_output_args, results_dir, stem  # benchmarks/ is on sys.path

SCENES = {
    "base": {}, "beta=0.1": dict(beta=0.1), "gamma=0": dict(gamma=0.0), "gamma=0.5": dict(gamma=0.5),
    "gamma=2": dict(gamma=2.0), "gamma=2.5": dict(gamma=2.5), "gamma=3": dict(gamma=3.0),
    "rho=0.05": dict(rho=0.05), "alpha=0": dict(material=sb.MooneyRivlin(0.0)),
    "alpha=0.5": dict(material=sb.MooneyRivlin(0.5)), "Gent Jm=97.2": dict(material=sb.Gent(97.2)),
}


def main(argv=None):
    ap = add_output_args(argparse.ArgumentParser(description=__doc__.splitlines()[0]), quick="the base scene only")
    args = ap.parse_args(argv)
    rows, t0 = [], time.perf_counter()
    for name, kw in SCENES.items():
        if args.quick and name != "base":
            continue
        t = time.perf_counter()
        c = sb.curve(sb.Scene.preset("base", **kw), delta_max=1.0, estimate_error=False)
        sw = [s for s in c.settings.get("topology_switches", []) if s["to"] == "cap (corner edge)"]
        s = sw[0] if sw else {}
        P = c.points
        rows.append((name, P["delta"][-1], int((~P["valid"]).sum()), s.get("delta", float("nan")),
                     s.get("delta_from_jump", float("nan")), s.get("force_jump", float("nan")),
                     s.get("energy_jump", float("nan")), s.get("kind", "no switch").split(":")[0],
                     P["edge_jump_ls"][-1], time.perf_counter() - t))
        print(rows[-1], flush=True)
    lines = [f"Measured {time.strftime('%Y-%m-%d')}, shellbvp {sb.__version__}; `sb.curve(scene, delta_max=1, "
             f"estimate_error=False)`; total {time.perf_counter() - t0:.0f} s on 2 shared cores.", "",
             "| scene | delta reached | invalid points | delta* (edge Legendre -> 0) | delta* (jump -> 0) | "
             "jump of F at delta* | jump of E at delta* | kind | jump of lambda_s at the last point | time (s) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r[0]} | {r[1]:.4g} | {r[2]} | {r[3]:.6f} | {r[4]:.6f} | {r[5]:.1e} | {r[6]:.1e} | {r[7]} | "
                     f"{r[8]:.3f} | {r[9]:.1f} |")
    out = results_dir(args.out_dir) / f"{stem('corner_switches', args.quick)}.md"
    out.write_text("\n".join(lines) + "\n")
    print(out.read_text())


if __name__ == "__main__":
    main()
