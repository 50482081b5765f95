"""Regenerate every benchmark result (issue 5): one command.

    python benchmarks/run.py                 # every result (9.5 h or more on 2 shared cores; below)
    python benchmarks/run.py --quick         # each step's quick mode, ~6 min: a smoke test (*-quick files)
    python benchmarks/run.py --figures       # ... and the paper's figures (benchmarks/paper_figures.py)
    python benchmarks/run.py --only work_precision,profile    # steps by name
    python benchmarks/run.py --only solid,stability           # or by group
    python benchmarks/run.py --list [--quick] [--out DIR]     # print the plan, what it leaves out and why
    python benchmarks/run.py --quick --out /tmp/bench         # results/ and figures/ under /tmp/bench

The plan is ``benchmarks/steps.py``: every result generator of benchmarks/ is a step (its
group: precision, speed, model, stability, solid, fits, trust, figures), every other script is
a tool listed there with the reason (``TOOLS``: the census ``architecture.py``, which has its
own test; ``same_curves.py``, which compares commits; ``checkout.py``, a library; the
``make_*.py`` scripts, which write shipped or example data; ``regression_reference.py``, which
writes test data at an old commit; the trust tally's kinds), and every file of results/ that no
step writes is a record listed with its reason (``RECORDS``: runs at other commits, text
kept by hand).  tests/test_benchmarks.py fails for a script or a result file in none of these.

Each step is its own script, run as a fresh process with this interpreter and this checkout's
package; results go to benchmarks/results/ (figures to benchmarks/figures/) or under ``--out``.
Every step's script takes an output option; one that took none would be left out with ``--out``
rather than write into the checkout (``--list --out DIR`` would name it).  ``--quick`` runs every step's own quick
mode, whose files carry a ``-quick`` suffix, so the committed full results are never
overwritten; steps without a quick mode that is fast enough (about a minute) are left out of
``--quick`` (the shooting peer needs its 10-20 s cold starts; the solid's curves, the maps, the
trust kinds beyond the tally's own quick mode take minutes).  A summary (step, seconds, exit
status) goes to ``results/run[-quick].json``; the exit status is non-zero if any step failed.

Time: the full plan's stated costs (each result file's own time for its whole run, or the sum
of its per-case times; ``--list`` prints them) add up to 34,268 s (9.5 h on 2 shared cores)
over 43 of the 59 steps; the other 16 (shooting, profile, point_budget, codegen_timing, kernels,
sweep_scaling, sweep_kill_resume, topologies, bending_koiter_map, vella, stability_pressure,
thick_fits_closed_check, fit_baseline_coverage, contact_estimate, profile_fit, paper_figures) give
no time, so 9.5 h is a floor.  ``--quick`` (25 steps; 23 before profile_solid's and closed_matrix's) took 380 s measured on the same machine at load 6 (nice 10;
1,260 s at load 10-12 with the whole trust tally), 2-76 s a step; the per-step times go to ``results/run-quick.json``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import subprocess
import sys
import time
from pathlib import Path

from checkout import checkout_env  # benchmarks/ is on sys.path when run as a script
from steps import GROUPS, STEPS, select

HERE = Path(__file__).resolve().parent


def _why_not(s, quick, out, figures, only):
    """Why a step is left out of this run, or None."""
    if s.optional and not (figures or (only and (s.name in only or s.group in only))):
        return "only with --figures or --only"
    if quick and s.quick is None:
        return "no quick mode under a minute"
    if out is not None and s.out is None:
        return "cannot write under --out yet (no --out-dir)"
    if not quick and s.needs and importlib.util.find_spec(s.needs) is None:
        return f"needs {s.needs}, not installed"
    return None


def plan(quick=False, only=None, figures=False, out=None, skipped=None):
    """The steps to run: [(Step, argv)]; ``skipped`` (a list) receives (Step, why) of the others."""
    out_steps = []
    for s in select(only):
        why = _why_not(s, quick, out, figures, only)
        if why is None:
            out_steps.append((s, s.argv(quick, out, sys.executable)))
        elif skipped is not None:
            skipped.append((s, why))
    return out_steps


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="each step's quick mode (~6 min), *-quick result files")
    ap.add_argument("--figures", action="store_true", help="also regenerate the paper's figures (slow)")
    ap.add_argument("--only", type=lambda s: [x for x in s.split(",") if x], default=None,
                    help="comma-separated steps or groups (" + ",".join(GROUPS) + "): "
                         + ",".join(s.name for s in STEPS))
    ap.add_argument("--out", default=None, help="write results/ and figures/ under this directory")
    ap.add_argument("--list", action="store_true", help="print the plan and exit")
    ap.add_argument("--keep-going", action="store_true", help="run the remaining steps after a failure")
    return ap.parse_args(argv)


def _rel(path):
    p = Path(path)
    return str(p.relative_to(HERE.parent)) if p.is_relative_to(HERE.parent) else path


def _cost(s):
    return f"{s.cost:>6.0f} s {s.source}" if s.cost is not None else "     ? (not stated)"


def main(argv=None):
    args = parse_args(argv)
    skipped = []
    try:
        steps = plan(args.quick, args.only, args.figures, args.out, skipped)
    except ValueError as e:
        print(f"run.py: {e}", file=sys.stderr)
        return 2
    if args.list:
        for s, a in steps:
            cost = "" if args.quick else f"  [{_cost(s)}]"
            print(f"{s.name:>26} {s.group:>9}: {' '.join([_rel(a[1]), *a[2:]])}{cost}")
        for s, why in skipped:
            print(f"{s.name:>26} {s.group:>9}: left out: {why}")
        if not args.quick:
            known = [s.cost for s, _ in steps if s.cost is not None]
            print(f"{len(steps)} steps; stated costs {sum(known):.0f} s over {len(known)} of them")
        return 0
    summary, failed = [], False
    env = checkout_env()  # every step, and the processes it starts, measures this checkout's package
    t_all = time.perf_counter()
    for s, why in skipped:
        print(f"== {s.name}: left out: {why}", flush=True)
    for s, a in steps:
        print(f"== {s.name}: {' '.join(a[1:])}", flush=True)
        t0 = time.perf_counter()
        rc = subprocess.run(a, cwd=HERE.parent, env=env).returncode
        dt = time.perf_counter() - t0
        summary.append(dict(step=s.name, group=s.group, argv=a[1:], seconds=dt, returncode=rc))
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
        (res / name).write_text(json.dumps(dict(quick=args.quick, total_s=total, steps=summary,
                                                left_out=[dict(step=s.name, why=w) for s, w in skipped]), indent=1))
    print(f"== {'all ok' if not failed else 'FAILED'}: {len(summary)} steps in {total:.0f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
