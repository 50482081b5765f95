"""Whether a change of structure changed any number: every preset's curve (both contact
models) computed by this checkout and by an older commit, point by point.

    python benchmarks/same_curves.py --against a20bb93 [--only base] [--tol 1e-12] [--deep]

The older commit's package is extracted with ``git archive`` and imported in a process of
its own (its derived code is generated there, in a cache of its own).  Every number of
every point (``POINT_FIELDS`` but the wall time) is compared: identical, equal to ``--tol``
relative (arithmetic in another order), or different.  Exit status 1 if any curve differs.
``--deep`` adds scenes of the stability grid (benchmarks/stability.py) indented to delta 1,
whose curves pass the configurations the presets do not reach: contact on the cylinder, the
held edge of the paper's model, the corner edge, a second zone on the tip, the lifted pole's end
and its fold (beta 0.2).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from checkout import ROOT

#: Numbers of a point that are not the state's (time of the run)
SKIPPED = {"wall_time"}

CHILD = r"""
import json, sys, math
import numpy as np
import shellbvp as sb
from shellbvp.io import POINT_FIELDS
out = {}
for key, scene, kw in json.loads(sys.argv[1]):
    c = sb.curve(sb.Scene.from_dict(scene), **kw)
    pts = {k: [v.item() if hasattr(v, "item") else v for v in np.asarray(c.points[k]).tolist()]
           for k in POINT_FIELDS if k in c.points}
    out[key] = dict(points=pts, stop=c.stop_reason, complete=bool(c.complete))
json.dump(out, sys.stdout, allow_nan=True)
"""
#: Scenes of the stability grid (id, contact) that pass what the presets do not
DEEP = (("base", "smooth"), ("beta=0.1", "smooth"), ("beta=0.0001", "smooth"), ("beta=0.0001", "paper"),
        ("beta=1e-05", "smooth"), ("rho=0.05", "smooth"), ("gamma=-2", "smooth"), ("xi=0", "paper"),
        ("beta=0.2", "smooth"))


def jobs(presets, deep):
    import shellbvp as sb
    from shellbvp.scene import CONTACT_MODELS

    out = []
    for name in presets:
        for contact in CONTACT_MODELS:
            try:
                out.append((f"{name}/{contact}", sb.Scene.preset(name, contact=contact).to_dict(), {}))
            except ValueError as e:  # a closed shell under a curved tip has the smooth model only
                print(f"{name}/{contact}: not a scene ({e})")
    if deep:
        import stability

        specs = {sid: over for sid, _, over in stability.grid()}
        specs["beta=0.2"] = dict(beta=0.2)  # the lifted pole's fold (not on the grid)
        for sid, contact in DEEP:
            scene = stability.make_scene(dict(overrides=specs[sid], contact=contact))
            out.append((f"{sid}/{contact} to delta 1", scene.to_dict(), dict(delta_max=1.0)))
    return out


def run_tree(tree: Path, todo, cache: Path) -> dict:
    # the numpy functions throughout: with compiled kernels that arrive during a run (auto) a curve
    # switches at a time that depends on the machine, and its last bits with it
    env = {"PYTHONPATH": str(tree), "SHELLBVP_CACHE_DIR": str(cache), "PATH": "/usr/bin:/bin",
           "SHELLBVP_KERNELS": "numpy", "OMP_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(todo)], env=env, cwd=tree,
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def compare(a, b, tol):
    """'identical', 'equal to tol' with the largest relative difference, or what differs."""
    if a["stop"] != b["stop"] or set(a["points"]) != set(b["points"]):
        return "different", math.inf, f"stop: {a['stop']!r} vs {b['stop']!r}"
    worst, where = 0.0, ""
    for k, va in a["points"].items():
        if k in SKIPPED:
            continue
        vb = b["points"][k]
        if len(va) != len(vb):
            return "different", math.inf, f"{len(va)} vs {len(vb)} points"
        for x, y in zip(va, vb):
            if isinstance(x, str) or isinstance(y, str) or isinstance(x, bool):
                if x != y:
                    return "different", math.inf, f"{k}: {x!r} vs {y!r}"
                continue
            if (math.isnan(x) and math.isnan(y)) or x == y:
                continue
            rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
            if rel > worst:
                worst, where = rel, k
    if worst == 0.0:
        return "identical", 0.0, ""
    return ("equal to tol" if worst <= tol else "different"), worst, where


def main(argv=None):
    import shellbvp as sb

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--against", required=True, help="the older commit")
    ap.add_argument("--only", nargs="*", default=None, help="presets (default: all)")
    ap.add_argument("--tol", type=float, default=1e-12)
    ap.add_argument("--deep", action="store_true", help="also scenes of the stability grid to delta 1")
    args = ap.parse_args(argv)
    todo = jobs(args.only or list(sb.PRESETS), args.deep)
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "old"
        old.mkdir()
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.against], capture_output=True, check=True)
        with tarfile.open(fileobj=__import__("io").BytesIO(archive.stdout)) as tar:
            tar.extractall(old, filter="data")
        before = run_tree(old, todo, Path(tmp) / "cache-old")
        after = run_tree(ROOT, todo, Path(tmp) / "cache-new")
    bad = 0
    for key in before:
        verdict, worst, where = compare(before[key], after[key], args.tol)
        bad += verdict == "different"
        print(f"{key:36s} {verdict:14s} {worst:9.2g} {where}")
    print(f"{len(before) - bad} of {len(before)} curves the same (identical or to {args.tol:g})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
