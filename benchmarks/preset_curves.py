"""`shellbvp curve` on every preset (both contact models): time, points, why it stopped.

Runs the CLI itself (a fresh process per curve, warm code cache) and writes
benchmarks/results/preset_curves.json and .md.

    python benchmarks/preset_curves.py [--quick] [--out-dir DIR]
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import shellbvp as sb

from checkout import add_output_args, results_dir  # benchmarks/ is on sys.path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="base preset, smooth contact (writes preset_curves-quick.*)")
    add_output_args(ap)
    args = ap.parse_args(argv)
    presets = ("base",) if args.quick else sb.PRESETS
    contacts = ("smooth",) if args.quick else ("smooth", "paper")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in presets:
            for contact in contacts:
                sb.Scene.preset(name, contact=contact).model()  # warm the code cache
                out = Path(tmp) / f"{name}-{contact}.h5"
                t0 = time.perf_counter()
                r = subprocess.run([sys.executable, "-m", "shellbvp", "curve", "--preset", name,
                                    "--contact", contact, "-o", str(out), "-q"], capture_output=True, text=True)
                wall = time.perf_counter() - t0
                c = sb.read_curve(out) if out.exists() else None
                rows.append(dict(preset=name, contact=contact, exit=r.returncode, seconds=wall,
                                 points=len(c) if c else 0, stop=c.stop_reason if c else r.stderr.strip(),
                                 delta_max=float(c.delta.max()) if c and len(c) else None,
                                 valid=int(c.valid.sum()) if c else 0,
                                 energy_identity_max=float(abs(c.energy_residual[1:-1]).max()) if c and len(c) > 3 else None))
                print(rows[-1], flush=True)
    res = results_dir(args.out_dir)
    base = "preset_curves-quick" if args.quick else "preset_curves"
    (res / f"{base}.json").write_text(json.dumps(rows, indent=1))
    lines = ["| preset | contact | time (s) | points | valid | max delta | stopped | max abs(dE/ddelta - F) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ei = f"{r['energy_identity_max']:.2g}" if r["energy_identity_max"] is not None else ""
        lines.append(f"| {r['preset']} | {r['contact']} | {r['seconds']:.1f} | {r['points']} | {r['valid']} | "
                     f"{r['delta_max']} | {r['stop']} | {ei} |")
    (res / f"{base}.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
