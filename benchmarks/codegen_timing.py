"""Cold (derive + generate + import) and warm (cached import) start of a scene's code.

Each measurement is a fresh Python process (what a user meets), median of
``--repeat`` runs.  Writes benchmarks/results/codegen.json and prints a
Markdown table.

    python benchmarks/codegen_timing.py [--repeat 5] [--quick] [--out-dir DIR]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path

SCENES = {
    "base (Mooney-Rivlin, xi=1)": "sb.Scene.preset('base')",
    "base-xi0 (xi=0)": "sb.Scene.preset('base-xi0')",
    "gent1 (Gent)": "sb.Scene.preset('gent1')",
    "neo-Hookean": "sb.Scene.preset('base', material=sb.NeoHookean())",
}

PROBE = """
import time
t0 = time.perf_counter()
import shellbvp as sb
t1 = time.perf_counter()
m = {scene}.model()
t2 = time.perf_counter()
print(t1 - t0, t2 - t1, t2 - t0)
"""


def run(scene, cache):
    env = dict(os.environ, SHELLBVP_CACHE_DIR=cache)
    t0 = __import__("time").perf_counter()
    out = subprocess.run([sys.executable, "-c", PROBE.format(scene=scene)], env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    wall = __import__("time").perf_counter() - t0
    imp, load, total = map(float, out)
    return {"import_s": imp, "model_s": load, "in_process_s": total, "process_wall_s": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="base only, one repeat (writes codegen-quick.*)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    scenes = dict(list(SCENES.items())[:1]) if args.quick else SCENES
    if args.quick:
        args.repeat = 1
    rows = {}
    for label, scene in scenes.items():
        cold, warm = [], []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as cache:
                cold.append(run(scene, cache))
                warm.append(run(scene, cache))
        med = lambda xs, k: statistics.median(x[k] for x in xs)  # noqa: E731
        rows[label] = {
            "cold_model_s": med(cold, "model_s"),
            "warm_model_s": med(warm, "model_s"),
            "warm_process_wall_s": med(warm, "process_wall_s"),
            "import_shellbvp_s": med(warm, "import_s"),
        }
    res = results_dir(args.out_dir)
    name = "codegen-quick" if args.quick else "codegen"
    (res / f"{name}.json").write_text(json.dumps({"repeat": args.repeat, "python": sys.version.split()[0],
                                                 "rows": rows}, indent=2))
    lines = ["| structure | cold: derive+generate+load (s) | warm: load cached (s) | warm process, total (s) |",
             "|---|---|---|---|"]
    for label, r in rows.items():
        lines.append(f"| {label} | {r['cold_model_s']:.2f} | {r['warm_model_s']:.3f} | "
                     f"{r['warm_process_wall_s']:.2f} |")
    (res / f"{name}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
