"""Closed shells: the shell model against the 3D solid (issue 55, items 3 and 4).

A complete sphere (gamma 1, Mooney-Rivlin alpha 0.1) between two flat plates and on a rigid
substrate under a sphere tip (rho 0.5), open, at eps = H/R 0.05 and 0.02: the solid
(``sb.fe_curve``: the half above the equator between plates, the whole wall on the substrate)
and the shell model (``sb.curve``, beta = eps^2/3) at the same approach delta of the indenters
(the scene's convention: the plates', or the tip's and the substrate's, from first touch, in
equatorial radii), and at the solid's mid-surface poles' approach (``sb.validate``'s convention),
with the solid's mesh error (``mesh_check``: 2/3 the elements each way).  ``--sealed`` adds the sealed capsule between plates (volume held);
``--egg`` the egg of docs/closed.md (halves that differ: prolate 1.3 above, oblate 0.7 below) on
the substrate under the sphere tip and between plates (its solid the whole wall in both).

Results cached in ``results/closed_solid.json`` (keyed by scene and eps; ``--recompute`` to
start afresh); the table in ``results/closed_solid.md``; both under ``--out-dir DIR`` if given
(an empty DIR: every curve computed again).

    nice -n 10 python benchmarks/closed_solid.py [--eps 0.05] [--sealed] [--egg] [--no-mesh-check] [--out-dir DIR]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package

import shellbvp as sb  # noqa: E402

sys.path.insert(0, str(HERE))
from checkout import add_output_args, results_dir  # noqa: E402

EPS = (0.05, 0.02)
DELTAS = (0.025, 0.05, 0.1, 0.2)
SCENES = {
    "plates": dict(support="plates", tip=sb.FlatTip()),
    "substrate, sphere tip rho 0.5": dict(support="substrate", tip=sb.SphereTip(), rho=0.5),
}
SEALED = {"plates, sealed": dict(support="plates", tip=sb.FlatTip(), sealed=True)}
#: An egg: a prolate upper half on an oblate lower half (docs/closed.md, "Halves that differ")
_EGG = sb.UserShell.closed_halves(upper=("sin(S)", "1.3*cos(S)", "pi/2"), lower=("sin(S)", "0.7*cos(S)", "pi/2"))
EGG = {"egg, substrate, sphere tip rho 0.5": dict(support="substrate", tip=sb.SphereTip(), rho=0.5, shell=_EGG),
       "egg, plates": dict(support="plates", tip=sb.FlatTip(), shell=_EGG)}


def scene_of(name, eps):
    kw = {**SCENES, **SEALED, **EGG}[name]
    shape = {} if "shell" in kw else {"gamma": 1.0}
    return sb.Scene(closed=True, material=sb.MooneyRivlin(0.1), thickness=eps, **shape, **kw)


def key(name, eps):
    return f"{name}, eps={eps:g}"


def shell_at(curve, deltas):
    """The shell curve's force, topology and pressure at ``deltas`` (NaN where not solved)."""
    F, topo, P = np.full(len(deltas), np.nan), [""] * len(deltas), np.full(len(deltas), np.nan)
    for i, x in enumerate(deltas):
        j = np.flatnonzero(np.isclose(curve.points["delta"], x, rtol=1e-9))
        if j.size and curve.points["status"][j[0]] == 0:
            F[i], topo[i], P[i] = curve.points["force"][j[0]], str(curve.points["topology"][j[0]]), \
                curve.points["pressure"][j[0]]
    return F, topo, P


def case(name, eps, mesh_check):
    """The solid at the indenters' approaches DELTAS, the shell at those and at the solid's
    mid-surface poles' approaches."""
    scene = scene_of(name, eps)
    t0 = time.perf_counter()
    fe = sb.fe_curve(scene, eps, DELTAS, at="indenter", mesh_check=mesh_check)
    fe_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    mid = [float(x) for x in fe.delta if np.isfinite(x)]
    sh = sb.curve(scene, deltas=sorted(set(DELTAS) | set(mid)), estimate_error=False)
    F, topo, P = shell_at(sh, DELTAS)
    F_mid = shell_at(sh, [x if np.isfinite(x) else -1.0 for x in fe.delta])[0]
    return {"name": name, "eps": eps, "approach": list(DELTAS), "delta_mid": fe.delta.tolist(),
            "force_fe": fe.force.tolist(), "contact_radius": fe.contact_radius.tolist(),
            "pressure_fe": fe.pressure.tolist(), "mesh_error": fe.mesh_error.tolist(), "success": fe.success,
            "message": fe.message, "elements": list(fe.elements), "fe_seconds": fe_s,
            "force_shell": F.tolist(), "force_shell_mid": F_mid.tolist(), "pressure_shell": P.tolist(),
            "topology": topo, "shell_seconds": time.perf_counter() - t0}


def num(x, fmt):
    return format(x, fmt) if np.isfinite(x) else "-"


def report(cache, args):
    from checkout import commit_label

    lines = ["# Closed shells: the shell model against the 3D solid", "",
             f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} (a shared 2-core machine), shellbvp "
             f"{sb.__version__} at {commit_label() or 'unknown commit'}; `nice -n 10 python "
             f"benchmarks/closed_solid.py{' --sealed' if args.sealed else ''}{' --egg' if args.egg else ''}`.", "",
             "A complete sphere (gamma 1, Mooney-Rivlin alpha 0.1, open unless sealed); the egg's halves "
             "differ (prolate 1.3 above, oblate 0.7 below: its solid the whole wall, also between plates).  `delta`: the approach of "
             "the indenters from first touch (the plates', or the tip's and the substrate's; the shell's on its "
             "mid-surface, the solid's on its outer surface), in equatorial radii R; F / (mu R H).  Solid: `sb.fe_curve` (FElupe, 9-node u/p/J elements, bulk 5000 mu, 3 through H, H/2 "
             "along the meridian, H/4 near the poles; frictionless penalty contacts on the outer surface; between "
             "plates the half above the equator with its symmetry plane, on the substrate the whole wall).  Shell: "
             "`sb.curve`, beta = eps^2/3, smooth contact.  `error` = F_shell / F_FE - 1; `FE mesh` = |F - F on "
             "2/3 the elements| / F; `poles' delta (FE)`: the solid's mid-surface poles' approach at that "
             "state, and the shell's error at it.", ""]
    summary = {}
    for k, c in cache.items():
        eps = c["eps"]
        lines += [f"## {c['name']}, eps = {eps:g}", "",
                  f"Solid {c['elements'][0]}x{c['elements'][1]} elements, {c['fe_seconds']:.0f} s"
                  f"{' with its mesh check' if np.isfinite(c['mesh_error']).any() else ''}"
                  f"{'' if c['success'] else '; ' + c['message']}; shell {c['shell_seconds']:.0f} s.", ""]
        sealed = "sealed" in c["name"]
        head = ("| delta | delta/H | F_FE | F_shell | error | error/eps | FE mesh | shell contact | poles' delta (FE) "
                "| error at it |")
        lines += [head + (" p_FE | p_shell |" if sealed else ""), "|" + "---|" * (10 + 2 * sealed)]
        for i, d in enumerate(c["approach"]):
            ff, fs, fm = c["force_fe"][i], c["force_shell"][i], c["force_shell_mid"][i]
            err = fs / ff - 1 if np.isfinite(ff) and np.isfinite(fs) else np.nan
            err_mid = fm / ff - 1 if np.isfinite(ff) and np.isfinite(fm) else np.nan
            summary.setdefault(c["name"], {}).setdefault(d, {})[eps] = (err, err_mid)
            lines.append(f"| {d:g} | {d / eps:.3g} | {num(ff, '.5g')} | {num(fs, '.5g')} | "
                         f"{num(100 * err, '+.2f')} % | {num(err / eps, '+.2f')} | "
                         f"{num(100 * c['mesh_error'][i], '.2f')} % | {c['topology'][i] or '-'} | "
                         f"{num(c['delta_mid'][i], '.4g')} | {num(100 * err_mid, '+.2f')} % |"
                         + (f" {num(c['pressure_fe'][i], '.4g')} | {num(c['pressure_shell'][i], '.4g')} |"
                            if sealed else ""))
        lines.append("")
    lines += ["## Summary: F_shell / F_FE - 1 against eps", "",
              "At equal approach of the indenters (the scene's delta); in brackets at the solid's mid-surface "
              "poles' approach (the convention of `sb.validate` for rimmed shells).", "",
              "| scene | delta | " + " | ".join(f"eps {e:g}" for e in EPS) + " |", "|---|---|" + "---|" * len(EPS)]
    for name, rows in summary.items():
        for d, by in rows.items():
            lines.append(f"| {name} | {d:g} | " + " | ".join(
                f"{num(100 * by[e][0], '+.2f')} % ({num(100 * by[e][1], '+.2f')} %)" if e in by else "-"
                for e in EPS) + " |")
    return "\n".join(lines) + "\n"


def write(path, text):
    """``text`` to ``path`` atomically (a temporary file beside it, then renamed)."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", default=None, help="only these thicknesses, comma-separated (default 0.05,0.02)")
    ap.add_argument("--sealed", action="store_true", help="also the sealed capsule between plates")
    ap.add_argument("--egg", action="store_true", help="also the egg on the substrate and between plates")
    ap.add_argument("--no-mesh-check", action="store_false", dest="mesh_check", help="no coarser mesh")
    ap.add_argument("--recompute", action="store_true", help="ignore the cached curves")
    args = add_output_args(ap).parse_args(argv)
    eps_list = EPS if args.eps is None else tuple(float(x) for x in args.eps.split(","))
    out = results_dir(args.out_dir)
    store = out / "closed_solid.json"
    cache = {} if args.recompute or not store.exists() else json.loads(store.read_text())
    names = list(SCENES) + (list(SEALED) if args.sealed else []) + (list(EGG) if args.egg else [])
    for eps in eps_list:
        for name in names:
            if key(name, eps) in cache and cache[key(name, eps)]["success"]:
                continue
            c = case(name, eps, args.mesh_check)
            cache[key(name, eps)] = c
            print(f"{key(name, eps)}: FE {c['fe_seconds']:.0f} s, {c['message']}; error "
                  + " ".join(num(100 * (a / b - 1), "+.2f") for a, b in zip(c["force_shell"], c["force_fe"])),
                  flush=True)
            write(store, json.dumps(cache, indent=1, default=float))  # no finished curve is lost
    write(out / "closed_solid.md", report(cache, args))
    print(f"wrote {out / 'closed_solid.md'}")


if __name__ == "__main__":
    main()
