"""Sweeps on one process, two local processes and a two-worker Dask LocalCluster; and the fit of
the shipped example with the geometry's uncertainty (issue 16).

1. A 4x4 grid (beta 0.005..0.02 log-spaced, rho 0.15..0.3) of base-preset curves to
   delta_max, computed three ways: ``workers=1`` (this process, one after another), a local
   pool of 2 spawned processes, and a ``dask.distributed.LocalCluster(n_workers=2,
   processes=True)``.  Wall time, speedup over the serial run, the sum and the largest of the
   curves' own times (the slowest curve bounds any parallel run), and max |dF| between the
   three (the same code on the same inputs: 0 expected).
2. ``fit_with_geometry`` on the shipped synthetic Lepidium-like record (preset "fit",
   R_L = 0.3 mm) with gamma +- 0.2 and rho +- 0.02, on 2 local processes: mu*H with its
   interval from the data's noise alone and with the geometry's uncertainty, and the table.

    python benchmarks/sweep_scaling.py [--quick] [--out-dir DIR]

Writes results/sweep_scaling[-quick].json and .md (every number generated here).
"""

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import shellbvp as sb
from shellbvp.sweeps import sweep
from shellbvp.uncertainty import fit_with_geometry

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checkout import add_output_args, results_dir  # noqa: E402

HERE = Path(__file__).resolve().parent


def busy(n=20_000_000):
    """A pure-Python loop (no I/O, no memory traffic): seconds it takes."""
    t0 = time.perf_counter()
    x = 0
    for i in range(n):
        x += i
    return time.perf_counter() - t0


def parallel_capacity():
    """How many of the cores are free now: 2 x (a loop's time alone) / (its time with two at once).
    Measured before and after the sweeps: on a shared machine the other jobs set the speedup."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        pool.submit(busy, 1000).result()  # started
        alone = pool.submit(busy).result()
        together = max(f.result() for f in [pool.submit(busy), pool.submit(busy)])
    return {"alone_s": alone, "two_at_once_s": together, "capacity": 2 * alone / together}


def grid_of(quick):
    if quick:
        return {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}, 0.1
    return {"beta": np.geomspace(0.005, 0.02, 4).tolist(), "rho": np.linspace(0.15, 0.3, 4).tolist()}, 0.5


def run_sweeps(grid, delta_max, tmp):
    base = sb.Scene.preset("base")
    base.model()  # derived before the clocks start (every run below loads it from the cache)
    runs = {}

    def timed(name, **kw):
        t0 = time.perf_counter()
        res = sweep(base, grid, delta_max=delta_max, out=Path(tmp) / f"{name}.h5", **kw)
        runs[name] = (time.perf_counter() - t0, res)
        print(f"{name}: {runs[name][0]:.1f} s, {res.counts()}", flush=True)

    timed("serial", workers=1)
    timed("local-2", workers=2)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("dask not installed (pip install 'shellbvp[dask]'): no Dask run", flush=True)
    else:
        t0 = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            startup = time.perf_counter() - t0
            timed("dask-2", executor=client.get_executor())
        print(f"  (the LocalCluster took {startup:.1f} s to start, not counted)", flush=True)
    serial = runs["serial"][1]
    rows = []
    for name, (wall, res) in runs.items():
        dF = 0.0
        for i, c in serial.curves.items():
            other = res.curves[i]
            if len(other) != len(c):
                dF = float("inf")
                break
            dF = max(dF, float(np.max(np.abs(other.force - c.force))))
        wt = np.asarray(res.index["wall_time"], float)
        rows.append({"run": name, "wall_s": wall, "speedup": runs["serial"][0] / wall,
                     "curve_time_sum_s": float(np.sum(wt)), "slowest_curve_s": float(np.max(wt)),
                     "curves": int(res.status.size), "complete": res.counts().get("complete", 0),
                     "max_abs_dF_vs_serial": dF})
    return rows


def geometry_fit(workers):
    d, F = sb.read_force_csv(sb.fitting.example_data_path())
    t0 = time.perf_counter()
    r = fit_with_geometry(sb.Scene.preset("fit"), d, F, R_L=0.3e-3, uncertainty={"gamma": 0.2, "rho": 0.02},
                          workers=workers)
    out = r.to_dict()
    out["wall_s"] = time.perf_counter() - t0
    out["table"] = r.table()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="a 2x2 grid of short curves (a smoke test)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    grid, delta_max = grid_of(args.quick)
    before = parallel_capacity()
    print(f"free cores before: {before['capacity']:.2f} (a loop of {before['alone_s']:.2f} s alone, "
          f"{before['two_at_once_s']:.2f} s two at once)", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        rows = run_sweeps(grid, delta_max, tmp)
    after = parallel_capacity()
    print(f"free cores after: {after['capacity']:.2f}", flush=True)
    geo = geometry_fit(2)
    print(geo["table"], flush=True)
    suffix = "-quick" if args.quick else ""
    res = results_dir(args.out_dir)
    record = {"grid": grid, "delta_max": delta_max, "cores": os.cpu_count(), "package_version": sb.__version__,
              "sweeps": rows, "geometry_fit": geo, "free_cores_before": before, "free_cores_after": after}
    (res / f"sweep_scaling{suffix}.json").write_text(json.dumps(record, indent=1, default=float) + "\n")
    lines = [f"# Sweeps and the fit with the geometry's uncertainty ({'quick' if args.quick else 'full'})", "",
             f"`python benchmarks/sweep_scaling.py{' --quick' if args.quick else ''}` on {os.cpu_count()} cores "
             f"(shared), shellbvp {sb.__version__}.", "",
             f"Grid: {', '.join(f'{k} = ' + ', '.join(f'{v:.4g}' for v in vals) for k, vals in grid.items())}; "
             f"base preset, adaptive curves to delta_max = {delta_max}.", "",
             f"Free cores (2 x a pure-Python loop's time alone / its time with two at once; other jobs share "
             f"the machine): {before['capacity']:.2f} before the sweeps, {after['capacity']:.2f} after. "
             "A speedup cannot exceed what is free.", "",
             "| run | wall (s) | speedup | sum of curve times (s) | slowest curve (s) | complete | max abs dF vs serial |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['run']} | {r['wall_s']:.1f} | {r['speedup']:.2f} | {r['curve_time_sum_s']:.1f} | "
                     f"{r['slowest_curve_s']:.1f} | {r['complete']}/{r['curves']} | {r['max_abs_dF_vs_serial']:.3g} |")
    g = geo
    lines += ["", "Shipped example (`shellbvp fit --example --preset fit --radius 0.3mm`), gamma +- 0.2, "
              f"rho +- 0.02 (standard uncertainties), {g['fits_computed']} fits on 2 processes in {g['wall_s']:.1f} s:",
              "", f"* mu*H = {g['mu_H']:.4g} N/m, 95 % CI [{g['mu_H_ci95_fit'][0]:.4g}, {g['mu_H_ci95_fit'][1]:.4g}] "
              "from the data's noise alone",
              f"* 95 % CI [{g['mu_H_ci95'][0]:.4g}, {g['mu_H_ci95'][1]:.4g}] with the geometry's uncertainty "
              f"(u_geometry = {g['u_geometry']:.3g} N/m)", "", "```", g["table"], "```", ""]
    (res / f"sweep_scaling{suffix}.md").write_text("\n".join(lines))
    print(f"wrote {res / f'sweep_scaling{suffix}.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
