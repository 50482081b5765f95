"""How the fit of a force map grows with its curves (issue 56, "maps at instrument scale").

Synthetic JPK maps of the same sample (``benchmarks/make_force_map.py``: the model curve of
preset ``fit``, mu*H 0.4 .. 0.8 mN/m, 500 + 500 points a curve) of 16 x 16 and 32 x 32 curves
(and 64 x 64 with ``--large``) are fitted as a user would, one process each:

    shellbvp fit MAP --preset fit --radius 10um -o OUT.h5

cold (an empty model-curve cache) and warm (the cache filled by an untimed run first).  Each
row: wall time, CPU time (user + system: less sensitive to the other jobs of a shared machine),
peak resident memory, and the ratios to the 16 x 16 map measured in the same run.  The target
of issue 56: 64 x 64 (16x the curves) within 6x the time of 16 x 16.

With ``--before DIR`` the same commands run also with the package of another checkout (e.g.
``/work/main`` before a change), interleaved, for before/after ratios from one run.

    python benchmarks/map_scaling.py [--large] [--before DIR] [--out-dir DIR]

Writes results/map_scaling[-large].json and .md (every number generated here).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from checkout import add_output_args, results_dir  # noqa: E402
from make_force_map import write_map  # noqa: E402  (a script beside this one)

COMMAND = ["fit", "{map}", "--preset", "fit", "--radius", "10um", "-o", "{out}"]


def commit_of(checkout) -> str:
    """The checkout's short commit, with ``+`` when it has changes not committed."""
    def git(*a):
        return subprocess.run(["git", "-C", str(checkout), *a], capture_output=True, text=True).stdout.strip()

    return (git("rev-parse", "--short", "HEAD") or "?") + ("+" if git("status", "--porcelain", "--", "shellbvp") else "")


def run(argv, env, cwd):
    """(wall s, CPU s, peak RSS MiB, exit status) of one ``python -m shellbvp`` process; SystemExit
    unless it wrote its map (exit 0, or 1: some curve failed its checks)."""
    marker = "@@usage "
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", marker + "%U %S %M", sys.executable, "-m", "shellbvp", *argv],
                       env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    lines = p.stderr.splitlines()
    usage = next(ln[len(marker):].split() for ln in reversed(lines) if ln.startswith(marker))
    if p.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(argv)}: exit {p.returncode}: {p.stderr[-600:]}")
    return wall, float(usage[0]) + float(usage[1]), float(usage[2]) / 1024.0, p.returncode


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--large", action="store_true", help="also the 64 x 64 map (4,096 curves; minutes)")
    ap.add_argument("--before", metavar="DIR", help="also time the package of this checkout (its shellbvp/)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    sizes = (16, 32, 64) if args.large else (16, 32)
    work = Path(tempfile.mkdtemp(prefix="map-scaling-"))
    sides = {"this": str(REPO)}
    if args.before:
        sides = {"before": str(Path(args.before).resolve()), **sides}
    maps = {}
    for n in sizes:
        maps[n] = work / f"map{n}.jpk-force-map"
        write_map(maps[n], n=n, points=500)
    counter = [0]

    def argv_of(n):
        counter[0] += 1
        return [a.format(map=maps[n], out=work / f"out{counter[0]}.h5") for a in COMMAND]

    rows = {}
    for side, path in sides.items():
        for n in sizes:
            cache = work / f"cache-{side}-{n}"
            env = dict(os.environ, PYTHONPATH=path, SHELLBVP_CACHE_DIR=str(cache), OMP_NUM_THREADS="1",
                       OPENBLAS_NUM_THREADS="1")
            cold = run(argv_of(n), env, work)   # empty cache: the model curve computed
            warm = run(argv_of(n), env, work)   # the model curve from the cache
            rows.setdefault(side, {})[n] = {"cold": cold, "warm": warm}
            print(f"{side} {n} x {n}: cold {cold[0]:.1f} s (CPU {cold[1]:.1f} s), warm {warm[0]:.1f} s "
                  f"(CPU {warm[1]:.1f} s), peak {max(cold[2], warm[2]):.0f} MiB", flush=True)
    result = {"sizes": sizes, "command": " ".join(COMMAND), "rows": rows, "load": os.getloadavg(),
              "commits": {side: commit_of(path) for side, path in sides.items()}}
    out = results_dir(args.out_dir)
    stem = "map_scaling-large" if args.large else "map_scaling"
    (out / f"{stem}.json").write_text(json.dumps(result, indent=1))
    (out / f"{stem}.md").write_text(report(result))
    print(report(result))


def report(res) -> str:
    """The table of :func:`main`'s result (its rows keyed by the map's side n)."""
    sizes = res["sizes"]
    lines = [f"# Force maps of n x n curves: `shellbvp {res['command']}`", "",
             "Wall and CPU (user + system) seconds; ratio: to the 16 x 16 map of the same side, cache and run "
             f"(target: 64 x 64 within 6x); exit 1: the map was written, some curve failed its checks. Load average at the end: {res['load'][0]:.1f}.", "",
             "Packages: " + ", ".join(f"{side} {c}" for side, c in res["commits"].items()) + ".", "",
             "| package | map | cache | wall (s) | CPU (s) | peak (MiB) | wall ratio | CPU ratio | curves ratio | exit |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for side, by_n in res["rows"].items():
        for cache in ("cold", "warm"):
            b = by_n[sizes[0]][cache]
            for n in sizes:
                r = by_n[n][cache]
                lines.append(f"| {side} | {n} x {n} | {cache} | {r[0]:.1f} | {r[1]:.1f} | {r[2]:.0f} | "
                             f"{r[0] / b[0]:.2f} | {r[1] / b[1]:.2f} | {(n / sizes[0]) ** 2:.0f} | {r[3]} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
