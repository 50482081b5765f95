"""`shellbvp sweep` killed and resumed, on a local pool and on a Dask LocalCluster (issue 16).

For each executor: the 3x3 grid (beta 0.005, 0.01, 0.02; rho 0.15, 0.225, 0.3; base preset,
delta_max 0.3) is run by the command line with 2 workers, killed with SIGKILL (the whole
process group: the command and its workers) as soon as its file holds a finished curve, read
back (it must be a complete, readable file), and the same command is run again: it must
compute only the remaining curves, and the file must end with the same curves as an
uninterrupted run (max |dF| = 0).

    python benchmarks/sweep_kill_resume.py [--out-dir DIR]

Writes results/sweep_kill_resume.json and .md.
"""

import argparse
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import shellbvp as sb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checkout import add_output_args, results_dir  # noqa: E402

HERE = Path(__file__).resolve().parent
GRID = ["--beta", "0.005,0.01,0.02", "--rho", "0.15:0.3:3", "--delta-max", "0.3"]


def command(out, executor):
    return [sys.executable, "-m", "shellbvp", "sweep", "--preset", "base", *GRID, "-o", str(out), *executor]


def finished(path):
    try:
        return sb.read_sweep(path).counts().get("complete", 0)
    except ValueError:  # not there yet
        return 0


def killed_and_resumed(tmp, name, executor):
    out = Path(tmp) / f"{name}.h5"
    t0 = time.perf_counter()
    proc = subprocess.Popen(command(out, executor), start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    while proc.poll() is None and finished(out) < 1:
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    first = time.perf_counter() - t0
    after_kill = sb.read_sweep(out).counts()  # a readable, complete file
    t0 = time.perf_counter()
    run = subprocess.run(command(out, executor), capture_output=True, text=True, check=False)
    resume = time.perf_counter() - t0
    m = re.search(r"(\d+) curves computed", run.stdout)
    computed = int(m.group(1)) if m else -1
    return out, {"executor": name, "killed_after_s": first, "after_kill": after_kill, "resume_s": resume,
                 "resume_exit": run.returncode, "resume_computed": computed, "final": sb.read_sweep(out).counts(),
                 "stdout": run.stdout.strip()}


def max_dF(a, b):
    A, B = sb.read_sweep(a), sb.read_sweep(b)
    worst = 0.0
    for i, c in A.curves.items():
        d = B.curves[i]
        worst = max(worst, float("inf") if len(c) != len(d) else float(np.max(np.abs(c.force - d.force))))
    return worst


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_output_args(ap)
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        ref = Path(tmp) / "uninterrupted.h5"
        t0 = time.perf_counter()
        subprocess.run(command(ref, ["--workers", "2", "-q"]), check=True, capture_output=True)
        whole = time.perf_counter() - t0
        out, row = killed_and_resumed(tmp, "local-2", ["--workers", "2", "-q"])
        row["max_abs_dF_vs_uninterrupted"] = max_dF(ref, out)
        rows.append(row)
        print(row, flush=True)
        cluster = subprocess.Popen(
            [sys.executable, "-c", "from dask.distributed import LocalCluster\nimport time\n"
             "c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)\n"
             "print(c.scheduler_address, flush=True)\ntime.sleep(3600)"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, start_new_session=True)
        try:
            address = cluster.stdout.readline().strip()
            out, row = killed_and_resumed(tmp, "dask-localcluster-2", ["--scheduler", address, "-q"])
            row["max_abs_dF_vs_uninterrupted"] = max_dF(ref, out)
            row["scheduler"] = address
            rows.append(row)
            print(row, flush=True)
        finally:
            os.killpg(cluster.pid, signal.SIGTERM)
            cluster.wait()
    res = results_dir(args.out_dir)
    (res / "sweep_kill_resume.json").write_text(json.dumps(
        {"grid": GRID, "uninterrupted_s": whole, "runs": rows}, indent=1) + "\n")
    lines = ["# `shellbvp sweep` killed (SIGKILL) and resumed", "",
             f"`python benchmarks/sweep_kill_resume.py`: `shellbvp sweep --preset base {' '.join(GRID)}`, "
             f"9 curves; uninterrupted with 2 local workers: {whole:.1f} s.", "",
             "| executor | killed after (s) | file after the kill | resumed: curves computed | resume (s) | "
             "exit | final | max abs dF vs uninterrupted |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['executor']} | {r['killed_after_s']:.1f} | {r['after_kill']} | {r['resume_computed']} | "
                     f"{r['resume_s']:.1f} | {r['resume_exit']} | {r['final']} | {r['max_abs_dF_vs_uninterrupted']:.3g} |")
    (res / "sweep_kill_resume.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {res / 'sweep_kill_resume.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
