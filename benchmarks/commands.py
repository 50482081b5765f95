"""Whole commands as the user runs them, against the baseline commit (issue 46).

Each command is a fresh ``python -m shellbvp ...`` process, timed from start to exit (wall
clock) with its peak resident memory (``wait4``'s ``ru_maxrss``).  Sides:

* ``1109cdf`` (``--baseline``): extracted with ``git archive`` and imported from there
  (``PYTHONPATH``), the numpy functions (it has no compiled kernels);
* this commit, plain: ``SHELLBVP_KERNELS=numpy``, what a plain install runs;
* this commit, ``[fast]``: numba installed and ``SHELLBVP_KERNELS=auto`` (what a user of the
  extra runs), the kernels compiled beforehand by the untimed warming run (``numba``).

Warm: each side has its own code cache, filled by one untimed run of each command first (a fit
then reads the model curve that run kept, as a repeated fit of a sample does; "curve not kept"
sets the kept curves aside for its runs: a sample's first fit; the others keep theirs), and
the repeats alternate the sides (A B C A B C ...) so a noisy shared machine weighs on all
alike; a ratio is the median of the per-repeat ratios.  Cold: the first run of ``curve`` with
an empty code cache (the equations derived and their code generated), once per side.
Commands the baseline does not have are measured on this commit only.

    python benchmarks/commands.py [--repeat 5] [--quick] [--out-dir DIR]

Writes ``benchmarks/results/commands.md`` and ``.json`` (``--quick``: ``commands-quick.*``;
``--only NAME``: ``commands-<name>.*``, the cold curve only when it is among them).

The force map is a synthetic JPK ``.jpk-force-map`` of 16 x 16 curves of 500 + 500 points
(``benchmarks/make_force_map.py``), written before the timing, read through afmformats; the map
with a thickness per pixel has its pixels' shells 0.3 .. 1.0 um thick (8 levels, each pixel's
curve from its own scene) and is fitted with that table (``--pixel-table``): warm (the node
curves kept by the warming run) and with the kept curves set aside (every node computed).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from checkout import add_output_args, commit_label, results_dir  # noqa: E402
from speed_vs_baseline import extract  # noqa: E402

#: (name, argv after ``python -m shellbvp``, expected exit status, on the baseline too)
COMMANDS = (
    ("bad option", ["curve", "--no-such-option"], 2, True),
    ("missing file", ["fit", "missing.csv", "--preset", "fit", "--radius", "0.3mm"], 2, True),
    ("curve (default base)", ["curve", "-o", "{out}.h5"], 0, True),
    ("solve --delta 0.2", ["solve", "--delta", "0.2"], 0, True),
    ("fit --example", ["fit", "--example", "--preset", "fit", "--radius", "0.3mm"], 0, True),
    ("fit --example, curve not kept", ["fit", "--example", "--preset", "fit", "--radius", "0.3mm"], 0, False),
    ("fit a folder of 10 files", ["fit", "{folder}", "--preset", "fit", "--radius", "0.3mm", "--table",
                                  "{out}.csv"], 0, False),
    ("sweep 2x2 to delta 0.2", ["sweep", "--beta", "0.005,0.01", "--rho", "0.2,0.25", "--delta-max", "0.2",
                                "-o", "{out}.h5", "--workers", "2", "-q"], 0, False),
    ("validate eps 0.1 to 0.5", ["validate", "--preset", "base", "--neo-hookean", "--thickness", "0.1",
                                 "-o", "{out}.h5"], 0, False),
    ("force map 16x16 (one geometry)", ["fit", "{force_map}", "--preset", "fit", "--radius", "10um", "-o",
                                        "{out}.h5", "-q"], 0, False),
    ("force map 16x16, thickness per pixel from a table", ["fit", "{thick_map}", "--preset", "fit", "--radius",
                                                           "10um", "--pixel-table", "{thick_table}", "-o",
                                                           "{out}.h5", "-q"], 0, False),
    ("force map 16x16, thickness per pixel, curves not kept", ["fit", "{thick_map}", "--preset", "fit", "--radius",
                                                               "10um", "--pixel-table", "{thick_table}", "-o",
                                                               "{out}.h5", "-q"], 0, False),
)
QUICK = ("bad option", "curve (default base)", "fit --example", "fit --example, curve not kept")
#: Commands run with the kept model curves deleted first (a sample fitted for the first time;
#: every other fit reads the curve its warming run kept, as a repeated fit does)
FRESH_CURVES = ("fit --example, curve not kept", "force map 16x16, thickness per pixel, curves not kept")
#: Commands of the issue not measured, and why (a line under the table)
NOT_MEASURED = ()


def run(argv, env, cwd):
    """(wall seconds, peak RSS MiB, exit status, stderr) of one process.  The memory is GNU
    time's ``%M`` of the exec'ed interpreter (this script's own resident set, copied into a
    forked child before its exec, would otherwise count as the child's peak)."""
    marker = "@@peak-kib "
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", marker + "%M", sys.executable, "-m", "shellbvp", *argv], env=env,
                       cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    lines = p.stderr.splitlines()
    peak = next((float(ln[len(marker):]) / 1024.0 for ln in reversed(lines) if ln.startswith(marker)), float("nan"))
    err = "\n".join(ln for ln in lines if not ln.startswith(marker))
    code = p.returncode
    return wall, peak, code, err


def make_folder(dest: Path):
    """Ten records of one sample: the shipped example at ten force scales."""
    sys.path.insert(0, str(REPO))
    from shellbvp.fitting import example_data_path

    dest.mkdir(parents=True, exist_ok=True)
    lines = example_data_path().read_text().splitlines()
    head = [ln for ln in lines if not ln[:1].isdigit() and not ln[:1] == "-"]
    rows = [ln for ln in lines if ln[:1].isdigit() or ln[:1] == "-"]
    for k in range(10):
        scale = 1.0 + 0.05 * k
        out = [f"{a},{float(b) * scale:.6g}" for a, b in (r.split(",") for r in rows)]
        (dest / f"seed{k:02d}.csv").write_text("\n".join(head + out) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="1109cdf")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help=f"{', '.join(QUICK)}; 3 repeats")
    ap.add_argument("--only", action="append", metavar="NAME",
                    help="only the commands whose name starts with NAME (may be given again): "
                         + "; ".join(c[0] for c in COMMANDS))
    add_output_args(ap)
    args = ap.parse_args(argv)
    repeat = 3 if args.quick else args.repeat
    commands = [c for c in COMMANDS if (not args.quick or c[0] in QUICK)
                and (not args.only or any(c[0].startswith(n) for n in args.only))]
    if not commands:
        raise SystemExit(f"no command named {args.only}")
    work = Path(tempfile.mkdtemp(prefix="commands-"))
    old = work / "baseline"
    full = extract(args.baseline, old)
    folder = work / "folder"
    make_folder(folder)
    force_map = work / "map16.jpk-force-map"
    if any("{force_map}" in cmd for _, cmd, _, _ in commands):
        from make_force_map import write_map

        write_map(force_map, n=16, points=500)
    thick_map, thick_table = work / "map16-thickness.jpk-force-map", work / "map16-thickness.csv"
    if any("{thick_map}" in cmd for _, cmd, _, _ in commands):
        from make_force_map import thickness_pattern, write_map, write_thickness_table

        thickness = thickness_pattern(16, 0.3e-6, 1.0e-6)  # um 0.3 .. 1.0 in 8 levels, thicker in the middle
        write_map(thick_map, n=16, points=500, thickness=thickness)
        write_thickness_table(thick_table, thickness)
    sides = {args.baseline: {"PYTHONPATH": str(old), "SHELLBVP_KERNELS": "numpy"},
             "plain": {"PYTHONPATH": str(REPO), "SHELLBVP_KERNELS": "numpy"},
             "[fast]": {"PYTHONPATH": str(REPO), "SHELLBVP_KERNELS": "auto"}}

    def env_of(side, cache, warming=False):
        env = dict(os.environ, **sides[side], OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
                   SHELLBVP_CACHE_DIR=str(cache), XDG_CACHE_HOME=str(cache), NUMBA_CACHE_DIR=str(cache / "numba"))
        if warming and side == "[fast]":
            env["SHELLBVP_KERNELS"] = "numba"  # compile in the foreground: nothing left running when timing starts
        return env

    counter = [0]

    def argv_of(cmd):
        counter[0] += 1
        return [a.format(out=work / f"out{counter[0]}", folder=folder, force_map=force_map, thick_map=thick_map,
                         thick_table=thick_table) for a in cmd]

    rows = {}
    t_start = time.perf_counter()
    # cold: the first curve with an empty cache, per side
    cold = {}
    for side in sides if any(name == "curve (default base)" for name, *_ in commands) else ():
        cache = work / f"cold-{side.strip('[]')}"
        wall, rss, code, err = run(argv_of(["curve", "-o", "{out}.h5"]), env_of(side, cache), work)
        cold[side] = (wall, rss, code)
        shutil.rmtree(cache, ignore_errors=True)
    # warm caches: one untimed run of every command per side
    caches = {side: work / f"warm-{side.strip('[]')}" for side in sides}
    for name, cmd, expected, on_base in commands:
        for side in sides:
            if side == args.baseline and not on_base:
                continue
            wall, rss, code, err = run(argv_of(cmd), env_of(side, caches[side], warming=True), work)
            if code != expected:
                raise SystemExit(f"{name} on {side}: exit {code}, expected {expected}: {err[-400:]}")
    order = list(sides)
    for r in range(repeat):
        for name, cmd, expected, on_base in commands:
            for side in order[r % len(order):] + order[:r % len(order)]:
                if side == args.baseline and not on_base:
                    continue
                kept, aside = caches[side] / "curves", caches[side] / "curves.aside"
                if name in FRESH_CURVES:  # the kept curves set aside for this run, then put back for the others
                    shutil.rmtree(aside, ignore_errors=True)
                    if kept.exists():
                        kept.rename(aside)
                wall, rss, code, err = run(argv_of(cmd), env_of(side, caches[side]), work)
                if name in FRESH_CURVES:
                    shutil.rmtree(kept, ignore_errors=True)
                    if aside.exists():
                        aside.rename(kept)
                rows.setdefault(name, {}).setdefault(side, []).append((wall, rss, code))
        print(f"repeat {r + 1}/{repeat} done ({time.perf_counter() - t_start:.0f} s)", flush=True)
    result = {"baseline": full, "commit": commit_label(), "repeat": repeat, "cold": cold, "rows": rows,
              "machine": platform.machine(), "python": platform.python_version(), "cores": os.cpu_count(),
              "seconds": time.perf_counter() - t_start}
    suffix = "-quick" if args.quick else ""
    if args.only:
        suffix += "-" + "-".join("".join(ch if ch.isalnum() else "-" for ch in n).strip("-") for n in args.only)
    out = results_dir(args.out_dir)
    (out / f"commands{suffix}.json").write_text(json.dumps(result, indent=1))
    (out / f"commands{suffix}.md").write_text(report(result, args.baseline, list(sides)))
    print(report(result, args.baseline, list(sides)))
    shutil.rmtree(work, ignore_errors=True)


def report(res, base, sides) -> str:
    def med(vals, k):
        return statistics.median(v[k] for v in vals)

    lines = [f"Measured {time.strftime('%Y-%m-%d')} on {res['machine']} ({res['cores']} cores, shared), Python "
             f"{res['python']}: this commit ({res['commit']}) against {base} ({res['baseline'][:7]}); "
             f"`python benchmarks/commands.py`; {res['repeat']} repeats, the sides alternating; wall time of the "
             "whole process (start to exit) and its peak resident memory; ratio: median over repeats of the "
             f"baseline's time / this side's; total {res['seconds']:.0f} s.", "",
             "| command (warm) | " + " | ".join(f"{s} s" for s in sides) + " | x vs " + base + " (plain) | x vs "
             + base + " ([fast]) | " + " | ".join(f"{s} MiB" for s in sides) + " |",
             "|---|" + "---|" * (2 * len(sides) + 2)]
    for name, by in res["rows"].items():
        t = [f"{med(by[s], 0):.2f}" if s in by else "-" for s in sides]
        m = [f"{med(by[s], 1):.0f}" if s in by else "-" for s in sides]
        ratios = []
        for s in ("plain", "[fast]"):
            if base in by and s in by:
                ratios.append(f"{statistics.median(a[0] / b[0] for a, b in zip(by[base], by[s])):.2f}")
            else:
                ratios.append("-")
        lines.append(f"| {name} | " + " | ".join(t) + " | " + " | ".join(ratios) + " | " + " | ".join(m) + " |")
    if NOT_MEASURED:
        lines += ["", "Not measured: " + "; ".join(NOT_MEASURED) + "."]
    if res["cold"]:
        lines += ["", "Cold (an empty code cache: the equations derived and their code generated, then the curve):",
                  "", "| command (cold) | " + " | ".join(f"{s} s" for s in sides) + " |",
                  "|---|" + "---|" * len(sides),
                  "| curve (default base) | " + " | ".join(f"{res['cold'][s][0]:.1f}" for s in sides) + " |"]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
