"""Reference states for the regression test of the configuration assembler (issue 12).

Run at commit 1109cdf (the three hand-written BVP classes) to write
``tests/data/regression_states.json``: F, delta, lambda0, Sc, S1 and the topology of
``sb.solve`` on every preset at a few depths and each control mode, at tol 1e-8.
The test ``tests/test_chain.py`` solves the same states with the current code and
compares to 1e-10 (relative): a refactor of the assembly must not change a state.
"""

import json
import subprocess
import sys
from pathlib import Path

import shellbvp as sb

CASES = [  # (preset, contact, control, value, topology)
    *[(p, "smooth", "delta", d, "auto") for p in ("base", "prolate2", "fit", "flat", "gent1", "dome", "base-xi0")
      for d in (0.05, 0.3)],
    *[(p, "paper", "delta", 0.3, "cap") for p in ("base", "prolate2", "dome")],
    ("base", "smooth", "force", 0.4, "cap"), ("base", "smooth", "lambda0", 1.05, "cap"),
    ("base", "paper", "force", 0.4, "cap"),
    ("base", "smooth", "delta", 0.05, "line"), ("base", "smooth", "delta", 0.05, "annulus"),
    ("fit", "smooth", "delta", 0.067, "annulus"),
]


def main(out):
    rows = []
    for preset, contact, control, value, topology in CASES:
        s = sb.solve(sb.Scene.preset(preset, contact=contact), **{control: value}, topology=topology, tol=1e-8,
                     estimate_error=False)
        rows.append(dict(preset=preset, contact=contact, control=control, value=value, topology=topology,
                         success=bool(s.success), result_topology=s.topology, force=s.force, delta=s.delta,
                         lambda0=s.lambda0, Sc=s.Sc, S1=s.S1, energy=s.energy))
        print(rows[-1], flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    Path(out).write_text(json.dumps({"commit": commit, "tol": 1e-8, "states": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "tests/data/regression_states.json")
