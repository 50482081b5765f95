"""Contact topologies (issue 7): lifted-off states against the cap-only model, per preset.

For every preset (smooth contact): the state at delta = 0.05, 0.1, 0.2 with
``topology="auto"`` (a valid line or annular contact where the single cap
would pull the shell) against the cap-only state, and the curve to
delta = 0.5 with the topology of each point, the switches and the energy
identity; and one scene outside the presets (base with rho = 0.3, gamma = 3)
whose curve passes through a finite annulus.  Writes
benchmarks/results/topologies.{json,md}.

    python benchmarks/topologies.py [--quick] [--out-dir DIR]
"""

import argparse
import itertools
import json
import time

import numpy as np

import shellbvp as sb

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path

DELTAS = (0.05, 0.1, 0.2)


def _runs(values):
    """'line x9, cap x12' from a sequence of topologies, in order."""
    return ", ".join(f"{k} x{len(list(g))}" for k, g in itertools.groupby(values))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="base preset, delta 0.05, curve to 0.15 (writes topologies-quick.*)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    presets = ("base",) if args.quick else sb.PRESETS
    scenes = {name: sb.Scene.preset(name) for name in presets}
    if not args.quick:  # a large indenter in a prolate shell: line, then a finite annulus, then the cap
        scenes["base rho=0.3 gamma=3"] = sb.Scene.preset("base", rho=0.3, gamma=3.0)
    states, curves = [], []
    for name, scene in scenes.items():
        scene.model()
        for d in ((0.05,) if args.quick else DELTAS):
            cap = sb.solve(scene, delta=d, topology="cap", tol=1e-8)
            t0 = time.perf_counter()
            auto = sb.solve(scene, delta=d, tol=1e-8)
            states.append(dict(preset=name, delta=d, topology=auto.topology, valid=bool(auto.valid),
                               force=auto.force, force_error=auto.force_error, S1=float(auto.S1),
                               Sc=float(auto.Sc), cap_force=cap.force, cap_valid=bool(cap.valid),
                               cap_pressure_min=cap.pressure_min, flags="; ".join(auto.flags),
                               energy_change=auto.energy - cap.energy,
                               seconds=time.perf_counter() - t0))
        t0 = time.perf_counter()
        c = sb.curve(scene, delta_max=0.15 if args.quick else 0.5)
        curves.append(dict(preset=name, points=len(c), valid=int(np.sum(c.valid)), topologies=_runs(c.topology),
                           switches=c.settings.get("topology_switches", []), stop_reason=c.stop_reason,
                           energy_identity_max=float(np.nanmax(np.abs(c.energy_residual))),
                           invalid_flags=sorted({f for f, v in zip(c.flags, c.valid) if not v}),
                           seconds=time.perf_counter() - t0))
    out = results_dir(args.out_dir)
    stem = "topologies-quick" if args.quick else "topologies"
    (out / f"{stem}.json").write_text(json.dumps(dict(states=states, curves=curves), indent=1, default=float))
    lines = ["States (smooth contact, tol 1e-8): the valid state (`auto`) against the single-cap model.", "",
             "| preset | delta | topology | F | F error | S1 | Sc | F(cap only) | F - F(cap) | E - E(cap) "
             "| cap min P | valid |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in states:
        lines.append(f"| {r['preset']} | {r['delta']} | {r['topology']} | {r['force']:.8f} | {r['force_error']:.1e} "
                     f"| {r['S1']:.3g} | {r['Sc']:.3g} | {r['cap_force']:.8f} | {r['force'] - r['cap_force']:.2e} "
                     f"| {r['energy_change']:.2e} | {r['cap_pressure_min']:.3g} | {'yes' if r['valid'] else 'no'} |")
    lines += ["", f"Curves (`shellbvp curve --preset NAME`, delta to {0.15 if args.quick else 0.5}):", "",
              "| preset | points | valid | topologies along the curve | switches at delta "
              "| max abs(dE/ddelta - F) | time (s) | stopped |",
              "|---|---|---|---|---|---|---|---|"]
    for r in curves:
        sw = ", ".join(f"{s['from']} -> {s['to']} {s['delta']:.5f}" for s in r["switches"]) or "none"
        lines.append(f"| {r['preset']} | {r['points']} | {r['valid']} | {r['topologies']} | {sw} | "
                     f"{r['energy_identity_max']:.1e} | {r['seconds']:.1f} | {r['stop_reason']} |")
    (out / f"{stem}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
