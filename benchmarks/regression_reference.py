"""Reference states for the regression test of the configuration assembler (issue 12).

Run at commit 1109cdf (the three hand-written BVP classes) to write
``tests/data/regression_states.json``: F, delta, lambda0, Sc, S1 and the topology of
``sb.solve`` on every preset at a few depths and each control mode, at tol 1e-8.
The test ``tests/test_chain.py`` solves the same states with the current code and
compares to 1e-10 (relative): a refactor of the assembly must not change a state.

    git worktree add /tmp/at1109 1109cdf && cd /tmp/at1109
    python benchmarks/regression_reference.py --out /tmp/regression_states.json

``--out`` is required; an existing file is refused unless ``--overwrite`` (the test's file,
written at 1109cdf, is what a refactor is compared with: rewritten at a later commit it would
compare the code with itself).  The file is written atomically and read back.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import shellbvp as sb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checkout import write_atomic  # noqa: E402

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
    doc = {"commit": commit, "tol": 1e-8, "states": rows}
    write_atomic(out, json.dumps(doc, indent=1) + "\n")
    if json.loads(Path(out).read_text()) != json.loads(json.dumps(doc)):
        raise SystemExit(f"regression_reference.py: {out} does not read back as written")
    print(f"wrote {out} ({len(rows)} states at {commit})")


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="the JSON file to write (its folder must exist)")
    ap.add_argument("--overwrite", action="store_true", help="replace an existing file")
    args = ap.parse_args(argv)
    if args.out.suffix != ".json":
        ap.error(f"--out: {args.out} must end in .json")
    if not args.out.parent.is_dir():
        ap.error(f"--out: the folder {args.out.parent} does not exist")
    if args.out.exists() and not args.overwrite:
        ap.error(f"--out: {args.out} exists (give --overwrite to replace it)")
    return args


if __name__ == "__main__":
    main(parse_args().out)
