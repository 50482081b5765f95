"""Regenerate every benchmark result (issue 5): one command.

    python benchmarks/run.py                 # everything (about 2-2.5 h on 2 shared cores)
    python benchmarks/run.py --quick         # a small subset, < 2 min: a smoke test (writes *-quick files)
    python benchmarks/run.py --figures       # ... and the paper's figures (benchmarks/paper_figures.py)
    python benchmarks/run.py --only work_precision,profile
    python benchmarks/run.py --list [--quick]   # print the plan
    python benchmarks/run.py --quick --out /tmp/bench   # results/ and figures/ under /tmp/bench

Each step is its own script in benchmarks/, run as a fresh process with this
interpreter; results go to benchmarks/results/ (figures to benchmarks/figures/)
or under ``--out``.  ``--quick`` runs every step's own quick mode, whose files
carry a ``-quick`` suffix, so the committed full results are never overwritten.
Steps without a quick mode that is fast enough (shooting's validation needs its
10-20 s cold starts) are left out of ``--quick``; the work–precision quick mode
still runs the shooting peer.  A summary (step, seconds, exit status) goes to
``results/run[-quick].json``; the exit status is non-zero if any step failed.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from checkout import checkout_env  # benchmarks/ is on sys.path when run as a script

HERE = Path(__file__).resolve().parent


class Step:
    def __init__(self, name, script, full, quick=None, outputs=(), quick_outputs=(), out_flag="--out-dir",
                 optional=False):
        self.name, self.script = name, script
        self.full, self.quick = list(full), (None if quick is None else list(quick))
        self.outputs, self.quick_outputs = tuple(outputs), tuple(quick_outputs)
        self.out_flag, self.optional = out_flag, optional

    def argv(self, quick, out):
        args = self.quick if quick else self.full
        if args is None:
            return None
        args = list(args)
        if self.out_flag == "--out-dir" and out is not None:
            args += ["--out-dir", str(out)]
        elif self.out_flag == "--out":  # a JSON path (shooting.py)
            base = out if out is not None else HERE
            args += ["--out", str(Path(base) / "results" / ("shooting-quick.json" if quick else "shooting.json"))]
        return [sys.executable, str(HERE / self.script)] + args


STEPS = (
    Step("work_precision", "work_precision.py", [], ["--quick"],
         ["results/work_precision.json", "results/work_precision.md", "figures/work_precision.png"],
         ["results/work_precision-quick.json", "results/work_precision-quick.md",
          "figures/work_precision-quick.png"]),
    Step("profile", "profile_hot_path.py", [], ["--quick"],
         ["results/profile.json", "results/profile.md"], ["results/profile-quick.json", "results/profile-quick.md"]),
    Step("stability", "stability.py", [], ["--quick", "--only", "^base$"],
         ["results/stability.json", "results/stability.md"],
         ["results/stability-quick.json", "results/stability-quick.md"]),
    Step("shooting", "shooting.py", [], None, ["results/shooting.json", "results/shooting.md"], out_flag="--out"),
    Step("states_table", "states_table.py", [], ["--quick"], ["results/states.json", "results/states.md"],
         ["results/states-quick.json", "results/states-quick.md"]),
    Step("preset_curves", "preset_curves.py", [], ["--quick"],
         ["results/preset_curves.json", "results/preset_curves.md"],
         ["results/preset_curves-quick.json", "results/preset_curves-quick.md"]),
    Step("topologies", "topologies.py", [], ["--quick"], ["results/topologies.json", "results/topologies.md"],
         ["results/topologies-quick.json", "results/topologies-quick.md"]),
    Step("codegen_timing", "codegen_timing.py", ["--repeat", "3"], ["--quick"],
         ["results/codegen.json", "results/codegen.md"], ["results/codegen-quick.json", "results/codegen-quick.md"]),
    # needs numba (pip install 'shellbvp[fast]'); without it the script says so and writes nothing
    Step("kernels", "kernels.py", [], ["--quick"], ["results/kernels.json", "results/kernels.md"],
         ["results/kernels-quick.json", "results/kernels-quick.md"]),
    Step("vella", "vella.py", [], ["--quick"], ["results/vella.json", "results/vella.md"],
         ["results/vella-quick.json", "results/vella-quick.md"]),
    Step("speed_vs_baseline", "speed_vs_baseline.py", [], ["--quick"],
         ["results/speed_vs_baseline.json", "results/speed_vs_baseline.md"],
         ["results/speed_vs_baseline-quick.json", "results/speed_vs_baseline-quick.md"]),
    Step("paper_figures", "paper_figures.py", [], None, ["figures/*.png"], out_flag=None, optional=True),
)


def plan(quick=False, only=None, figures=False, out=None):
    """The steps to run: [(Step, argv)]."""
    names = {s.name for s in STEPS}
    if only:
        unknown = set(only) - names
        if unknown:
            raise ValueError(f"unknown steps {sorted(unknown)}; choose from {sorted(names)}")
    out_steps = []
    for s in STEPS:
        if only and s.name not in only:
            continue
        if s.optional and not (figures or (only and s.name in only)):
            continue
        if s.out_flag is None and out is not None:
            continue  # writes only into benchmarks/ (no output option): not with --out
        argv = s.argv(quick, out)
        if argv is None:
            continue
        out_steps.append((s, argv))
    return out_steps


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small subset (< 2 min), *-quick result files")
    ap.add_argument("--figures", action="store_true", help="also regenerate the paper's figures (slow)")
    ap.add_argument("--only", type=lambda s: [x for x in s.split(",") if x], default=None,
                    help="comma-separated steps: " + ",".join(s.name for s in STEPS))
    ap.add_argument("--out", default=None, help="write results/ and figures/ under this directory")
    ap.add_argument("--list", action="store_true", help="print the plan and exit")
    ap.add_argument("--keep-going", action="store_true", help="run the remaining steps after a failure")
    return ap.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    try:
        steps = plan(args.quick, args.only, args.figures, args.out)
    except ValueError as e:
        print(f"run.py: {e}", file=sys.stderr)
        return 2
    if args.list:
        for s, a in steps:
            print(f"{s.name:>15}: {' '.join(a[1:])}")
        return 0
    summary, failed = [], False
    env = checkout_env()  # every step, and the processes it starts, measures this checkout's package
    t_all = time.perf_counter()
    for s, a in steps:
        print(f"== {s.name}: {' '.join(a[1:])}", flush=True)
        t0 = time.perf_counter()
        rc = subprocess.run(a, cwd=HERE.parent, env=env).returncode
        dt = time.perf_counter() - t0
        summary.append(dict(step=s.name, argv=a[1:], seconds=dt, returncode=rc))
        print(f"== {s.name}: {'ok' if rc == 0 else f'FAILED (exit {rc})'} in {dt:.0f} s", flush=True)
        if rc != 0:
            failed = True
            if not args.keep_going:
                break
    total = time.perf_counter() - t_all
    res = (Path(args.out) if args.out else HERE) / "results"
    res.mkdir(parents=True, exist_ok=True)
    name = "run-quick.json" if args.quick else "run.json"
    if not args.only:
        (res / name).write_text(json.dumps(dict(quick=args.quick, total_s=total, steps=summary), indent=1))
    print(f"== {'all ok' if not failed else 'FAILED'}: {len(summary)} steps in {total:.0f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
