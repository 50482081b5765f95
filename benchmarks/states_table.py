"""Every preset at delta = 0.05, 0.1, 0.2, 0.3 with both contact models, cold starts.

Writes benchmarks/results/states.json and benchmarks/results/states.md
(F, Sc, lambda0, ring force, min contact pressure, validity, error estimate,
time per cold solve).

    python benchmarks/states_table.py [--quick] [--out-dir DIR]
"""

import argparse
import json
import time

import shellbvp as sb

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path

DELTAS = (0.05, 0.1, 0.2, 0.3)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="base preset, delta 0.1 and 0.3 (writes states-quick.*)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    presets = ("base",) if args.quick else sb.PRESETS
    deltas = (0.1, 0.3) if args.quick else DELTAS
    rows = []
    for name in presets:
        for contact in ("smooth", "paper"):
            scene = sb.Scene.preset(name, contact=contact)
            scene.model()  # code generation is not part of the solve time
            for d in deltas:
                t0 = time.perf_counter()
                s = sb.solve(scene, delta=d)
                rows.append(dict(preset=name, contact=contact, delta=d, success=bool(s.success),
                                 topology=s.topology,
                                 status=s.status, force=s.force, Sc=float(s.Sc), lambda0=s.lambda0,
                                 ring_force=s.ring_force, pressure_min=s.pressure_min,
                                 valid=bool(s.valid), force_error=s.force_error,
                                 nodes=s.nodes, seconds=time.perf_counter() - t0))
    out = results_dir(args.out_dir)
    name = "states-quick" if args.quick else "states"
    (out / f"{name}.json").write_text(json.dumps(rows, indent=1, default=float))
    lines = ["| preset | contact | delta | topology | F | Sc | lambda0 | ring force | min P | valid | F error | nodes "
             "| time (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if not r["success"]:
            lines.append(f"| {r['preset']} | {r['contact']} | {r['delta']} | failed (status {r['status']}) "
                         f"| | | | | | | | | {r['seconds']:.2f} |")
            continue
        lines.append(f"| {r['preset']} | {r['contact']} | {r['delta']} | {r['topology']} | {r['force']:.6f} | {r['Sc']:.3g} | "
                     f"{r['lambda0']:.4f} | {r['ring_force']:.4g} | {r['pressure_min']:.3g} | "
                     f"{'yes' if r['valid'] else 'no'} | {r['force_error']:.1e} | {r['nodes']} | "
                     f"{r['seconds']:.2f} |")
    (out / f"{name}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
