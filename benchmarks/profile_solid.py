"""A wall thinning towards the pole against the 3D solid (issue 58).

The issue's check: "a wall thinning linearly by half from rim to pole, eps 0.05 at the rim:
the same error band as the uniform shell of the pole's thickness."  On the hemisphere with
rho 0.2 (preset ``base``), neo-Hookean as ``benchmarks/validation.py``, three walls are
indented to the same mid-surface pole displacements (``default_depths``: delta/H0 = 0.25, 0.5,
1, 2, 5, 10, ... and delta 0.5, H0 the pole's thickness, 0.025 as the issue's):

* ``profile``: H(S)/R_L = H0 (1 + S/L), H0 at the pole, 2 H0 at the rim;
* ``uniform H0``: the uniform wall of the pole's thickness (the band the issue asks for);
* ``uniform 2 H0``: the uniform wall of the rim's thickness (for scale; H0 = 0.025 only).

The same at H0 = 0.0125 tells how the difference between the profile's error and the uniform
wall's scales with the thickness.  And a flat disk (gamma 0) of eps 0.02 thickening to twice
that at the rim, under a small central load (delta = 0.05 H0): the stiffness over the uniform
disk's, of the solid, of the shell model and of Kirchhoff's plate with D(r) = mu H(r)^3/3 at
Poisson ratio 1/2 (3D incompressible) and 1 (a bending energy of the mean curvature alone),
solved here by Ritz on the slope.

With the Gaussian-curvature term: the shell side again with Koiter's bending energy at Poisson
ratio 1/2 (``sb.KoiterBending``, ``--bending koiter``: Kirchhoff's plate at Poisson ratio 1/2 for
a flat plate, ``B = (Ds + Dt)^2/2 - Ds Dt/2``), against the same stored FE forces: the disk and
the hemisphere's walls in ``KOITER_WALLS``.  (The same energy as a user formula, ``GAUSS``, was
measured before it was built in; its numbers stay in the JSON, ``"gauss"`` and ``"shell_gauss"``,
and the report says how far the built-in's are from them.)

Each wall's 3D solid (``sb.fe_curve``, the default mesh and its mesh check) against the shell
model (smooth contact, trace bending, beta from the pole's thickness), without and with
transverse shear.  Forces in units of mu R_L H0 (the pole's H).  Reported: ``F_shell / F_FE -
1`` at each depth and its largest magnitude by depth band, as ``results/validation.md``.

FE curves are kept in ``results/profile_solid.json`` (a second run recomputes only what is
missing; ``--recompute`` starts afresh).  ``--quick`` (a smoke test, about a minute; afresh each
time, into ``profile_solid-quick.{json,md}``): H0 = 0.025's profile and uniform wall to delta = H0
(``QUICK_DEPTHS``), without the mesh check, Koiter's energy or the flat disk.

    nice -n 10 python benchmarks/profile_solid.py [--workers 1] [--no-mesh-check] [--quick] [--out-dir DIR]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import math

import numpy as np
from scipy.sparse import diags
from scipy.sparse.linalg import spsolve

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package

import shellbvp as sb  # noqa: E402
from shellbvp.validation import Validation, default_depths, shell_curve  # noqa: E402

sys.path.insert(0, str(HERE))
from checkout import add_output_args, results_dir, stem  # noqa: E402

DELTA_MAX = 0.5
#: Each pole thickness H0 and its walls: a profile's formula or a uniform thickness
CASES = {
    0.025: {"profile": "0.025*(1 + S/L)", "uniform H0": 0.025, "uniform 2 H0": 0.05},
    0.0125: {"profile": "0.0125*(1 + S/L)", "uniform H0": 0.0125},
}

#: Kirchhoff's bending at Poisson ratio 1/2 as a user bending energy (before ``sb.KoiterBending``): the trace
#: energy less half the product of the bending strains Ds = lambda_s^2 kappa_s - kappa_s0, Dt = lambda_theta^2
#: kappa_theta - kappa_theta0.  Kept for the stored numbers measured with it.
GAUSS = ("(lambda_s**2*kappa_s - kappa_s0 + lambda_theta**2*kappa_theta - kappa_theta0)**2/2"
         " - (lambda_s**2*kappa_s - kappa_s0)*(lambda_theta**2*kappa_theta - kappa_theta0)/2")
#: The walls whose shell side is solved with Koiter's energy too
KOITER_WALLS = ((0.025, "profile"), (0.025, "uniform H0"), (0.0125, "profile"), (0.0125, "uniform H0"))


#: ``--quick``: the walls and the depths over H0
QUICK_WALLS = ((0.025, "profile"), (0.025, "uniform H0"))
QUICK_DEPTHS = (0.25, 0.5, 1.0)


def key(pole, name):
    return f"pole {pole:g}: {name}"
BANDS = (("delta <= H0", lambda k, wrap: k <= 1 + 1e-9 and not wrap),
         ("H0 < delta < 5 H0", lambda k, wrap: 1 + 1e-9 < k < 5 - 1e-9 and not wrap),
         ("delta >= 5 H0, contact short of the tip's equator", lambda k, wrap: k >= 5 - 1e-9 and not wrap),
         ("contact round the tip's equator (r_c >= 0.95 rho)", lambda k, wrap: wrap))


def scene_of(wall, **over):
    thickness = sb.ThicknessProfile.formula(wall) if isinstance(wall, str) else wall
    return sb.Scene.preset("base", material=sb.NeoHookean(), thickness=thickness, **over)


def fe_case(args):
    pole, name, mesh_check, quick = args
    wall = CASES[pole][name]
    scene = scene_of(wall)
    depths = [pole * k for k in QUICK_DEPTHS] if quick else default_depths(pole, DELTA_MAX)
    c = sb.fe_curve(scene, scene.thickness, depths, mesh_check=mesh_check)
    return key(pole, name), {"wall": wall, "pole": pole, "eps": scene.thickness, "delta": c.delta.tolist(), "force": c.force.tolist(),
                  "indenter": c.indenter.tolist(), "contact_radius": c.contact_radius.tolist(),
                  "mesh_error": c.mesh_error.tolist(), "success": c.success, "message": c.message,
                  "elements": list(c.elements), "seconds": c.wall_time}


def shell_rows(fe, bending=None):
    """The shell model at the FE's depths, without and with transverse shear, in units of mu R_L H0
    (``bending``: a Bending, default the trace energy)."""
    d = np.asarray(fe["delta"], float)
    rows = {}
    over = {} if bending is None else {"bending": bending}
    for label, shear in (("Kirchhoff", False), ("shear", True)):
        scene = scene_of(fe["wall"], transverse_shear=shear, **over)
        t0 = time.perf_counter()
        shell = shell_curve(scene, d)
        fake = _FE(d)
        force = Validation(scene, shell, fake).force_shell
        # forces in units of mu R_L H0: a uniform wall's own H is eps
        rows[label] = {"force": (force * scene.thickness / fe["pole"]).tolist(), "seconds": time.perf_counter() - t0}
    return rows


class _FE:
    """The FE depths, all a Validation needs to read the shell's forces there."""

    def __init__(self, delta):
        self.delta = delta


PLATE_EPS = 0.02


def plate_compliance(t, nu, n=2000):
    """Centre deflection per unit central load of a simply supported disk (radius 1) of bending
    stiffness t(r)^3 (Kirchhoff, Poisson ratio nu): Ritz on the slope phi = w', linear elements
    graded to the centre (the uniform disk's (3 + nu)/(16 pi (1 + nu)) to 1e-7)."""
    r = np.linspace(0.0, 1.0, n + 1) ** 2
    g, gw = np.polynomial.legendre.leggauss(4)
    a, b = r[:-1, None], r[1:, None]
    h = b - a
    x = a + (g + 1) / 2 * h
    w = gw * h / 2
    N0, N1, d0, d1 = (b - x) / h, (x - a) / h, -1 / h, 1 / h
    c = 2 * math.pi * x * t(x) ** 3 * w
    k00 = (c * (d0 * d0 + 2 * nu * d0 * N0 / x + N0 * N0 / x**2)).sum(1)
    k11 = (c * (d1 * d1 + 2 * nu * d1 * N1 / x + N1 * N1 / x**2)).sum(1)
    k01 = (c * (d0 * d1 + nu * (d0 * N1 + d1 * N0) / x + N0 * N1 / x**2)).sum(1)
    main = np.zeros(n + 1)
    main[:-1] += k00
    main[1:] += k11
    f = np.zeros(n + 1)
    f[:-1] -= (N0 * w).sum(1)
    f[1:] -= (N1 * w).sum(1)
    phi = np.r_[0.0, spsolve(diags([k01, main, k01], [-1, 0, 1]).tocsc()[1:, 1:], f[1:])]
    return -np.trapezoid(phi, r)


def plate_walls(bending=None):
    """The disk's two walls, uniform and profiled, and its depth (``bending`` as in :func:`shell_rows`)."""
    eps = PLATE_EPS
    over = {} if bending is None else {"bending": bending}
    disk = sb.Scene(gamma=0.0, rho=0.2, material=sb.NeoHookean(), **over)
    return {"uniform": disk.replace(thickness=eps),
            "profile": disk.replace(thickness=sb.ThicknessProfile.formula(f"{eps:g}*(1 + S/L)"))}, 0.05 * eps


def plate_shell(scene, d):
    shell = sb.solve(scene, delta=d, estimate_error=False)
    return float(shell.force) if shell.success else math.nan


def plate_case():
    """The disk's stiffness ratios (profile over uniform) of the solid, the shell and Kirchhoff."""
    walls, d = plate_walls()
    out = {}
    for name, scene in walls.items():
        t0 = time.perf_counter()
        fe = sb.fe_curve(scene, PLATE_EPS, [d])
        out[name] = {"fe": float(fe.force[0]), "shell": plate_shell(scene, d),
                     "elements": list(fe.elements), "seconds": time.perf_counter() - t0}
    uniform, thick = (lambda r: np.ones_like(r)), (lambda r: 1 + np.arcsin(r) / (math.pi / 2))  # r = sin S
    out["kirchhoff"] = {f"{nu:g}": plate_compliance(uniform, nu) / plate_compliance(thick, nu) for nu in (0.5, 1.0)}
    return out


def pct(x):
    return f"{100 * x:+.1f}" if np.isfinite(x) else "-"


def report(cache, args):
    lines = [f"Measured {cache.get('measured') or _measured()}; `nice -n 10 python benchmarks/profile_solid.py"
             f"{' --quick' if args.quick else ''}{' --no-mesh-check' if not args.mesh_check else ''}`.", "",
             "Hemisphere, rho 0.2 (preset base), neo-Hookean, rim pinned.  F_shell / F_FE - 1 in percent at the "
             "same mid-surface pole displacement delta; 3D solid: `sb.fe_curve` with its default mesh (3 elements "
             "through the local thickness, the local H/2 along the meridian, H0/4 near the pole), 'FE mesh' its "
             "mesh check (|F - F on 2/3 the elements| / F).  Shell model: smooth contact, trace bending, beta = "
             "(H0/R_L)^2/3, Kirchhoff or with transverse shear (of the local thickness).  Forces in units of "
             "mu R_L H0, H0 the profile's pole thickness; delta/H0 likewise.", ""]
    for pole, walls in CASES.items():
        summary = {}
        if not any(key(pole, name) in cache for name in walls):
            continue
        walls = [name for name in walls if key(pole, name) in cache]
        lines += [f"# H0 = {pole:g}", ""]
        for name in walls:
            fe = cache.get(key(pole, name))
            if fe is None:
                continue
            d, ff = np.asarray(fe["delta"], float), np.asarray(fe["force"], float) * fe["eps"] / pole
            wall = f"H/R_L = {fe['wall']}" if isinstance(fe["wall"], str) else f"H/R_L = {fe['wall']:g} uniform"
            lines += [f"## {name}: {wall}", "",
                      f"FE {fe['elements'][0]}x{fe['elements'][1]} elements, {fe['seconds']:.0f} s"
                      f"{'' if fe['success'] else '; ' + fe['message']}", "",
                      "| delta/H0 | delta | F_FE | Kirchhoff | shear | FE mesh | r_c FE |", "|---|---|---|---|---|---|---|"]
            for i, x in enumerate(d):
                errs = {k: np.asarray(v["force"])[i] / ff[i] - 1 for k, v in fe["shell"].items()}
                me = fe["mesh_error"][i]
                lines.append(f"| {x / pole:.3g} | {x:.4g} | {ff[i]:.5g} | {pct(errs['Kirchhoff'])} | "
                             f"{pct(errs['shear'])} | {'-' if not np.isfinite(me) else f'{100 * me:.2f}'} | "
                             f"{fe['contact_radius'][i]:.4f} |")
                wrap = fe["contact_radius"][i] >= 0.95 * 0.2
                summary.setdefault(name, []).append((x / pole, wrap, errs))
            lines.append("")
        lines += [f"## H0 = {pole:g}: the largest |F_shell / F_FE - 1| (percent) by depth band", "",
                  "| depth | " + " | ".join(f"{n}, {v}" for n in walls for v in ("Kirchhoff", "shear")) + " |",
                  "|---|" + "---|" * (2 * len(walls))]
        for label, test in BANDS:
            cells = []
            for name in walls:
                for var in ("Kirchhoff", "shear"):
                    sel = [abs(e[var]) for k, wrap, e in summary.get(name, []) if test(k, wrap) and np.isfinite(e[var])]
                    cells.append(f"{100 * max(sel):.1f}" if sel else "-")
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += ["# The profile's stiffening, solid and shell", "",
              "F(profile) / F(uniform H0) - 1 in percent at the same delta: the 3D solid's, the shell model's "
              "(Kirchhoff), and the part of the solid's the shell model holds.", "",
              "| H0 | delta/H0 | solid | shell | shell / solid |", "|---|---|---|---|---|"]
    for pole in CASES:
        prof, unif = cache.get(key(pole, "profile")), cache.get(key(pole, "uniform H0"))
        if prof is None or unif is None:
            continue
        for i, x in enumerate(prof["delta"]):
            if x > 10 * pole * (1 + 1e-9):
                continue
            solid = prof["force"][i] / unif["force"][i] - 1
            shell = prof["shell"]["Kirchhoff"]["force"][i] / unif["shell"]["Kirchhoff"]["force"][i] - 1
            lines.append(f"| {pole:g} | {x / pole:.3g} | {100 * solid:+.1f} | {100 * shell:+.1f} | {shell / solid:.3f} |")
    lines.append("")
    plate = cache.get("plate")
    if plate is not None:
        u, p, k = plate["uniform"], plate["profile"], plate["kirchhoff"]
        lines += [f"# A flat disk thickening to twice its pole's eps {PLATE_EPS:g} at the rim", "",
                  f"H/R_L = {PLATE_EPS:g} (1 + S/L), R = sin S (gamma 0), simply supported at mid-thickness, "
                  f"delta = 0.05 H0; stiffness of the profiled disk over the uniform one (FE {u['elements'][0]}x"
                  f"{u['elements'][1]} and {p['elements'][0]}x{p['elements'][1]} elements):", "",
                  "| 3D solid | shell model | Kirchhoff, nu 1/2 | Kirchhoff, nu 1 |", "|---|---|---|---|",
                  f"| {p['fe'] / u['fe']:.4f} | {p['shell'] / u['shell']:.4f} | {k['0.5']:.4f} | {k['1']:.4f} |", "",
                  f"The uniform disk: F_shell / F_FE - 1 = {pct(u['shell'] / u['fe'] - 1)} %.", ""]
    if "koiter" in cache:
        lines += koiter_report(cache)
    return "\n".join(lines)


def koiter_report(cache):
    """The section of the shell side with Koiter's energy (the Gaussian-curvature term), against the same
    FE forces."""
    g = cache["koiter"]
    lines = ["# With the Gaussian-curvature term: Koiter's bending energy (`--bending koiter`)", "",
             f"Shell side measured {g['measured']}, against the FE forces above.  `sb.KoiterBending()`: "
             "B = (Ds + Dt)^2/2 - Ds Dt/2 with Ds = lambda_s^2 kappa_s - kappa_s0, Dt = lambda_theta^2 kappa_theta "
             "- kappa_theta0, Kirchhoff's plate at Poisson ratio 1/2 for a flat plate (plate limit: stiffness 1, "
             "Poisson ratio 0.5; beta = (H0/R_L)^2/3 as the trace energy's).  'trace' the columns above, "
             "'koiter' with this energy; 'Kirchhoff' the shell without transverse shear, 'shear' with it.", ""]
    plate = cache.get("plate")
    if plate is not None:
        u, p, gp = plate["uniform"], plate["profile"], g["plate"]
        user = cache.get("gauss", {}).get("plate")
        lines += ["## The flat disk", "",
                  "| | 3D solid | shell, trace | shell, koiter | the same as a user formula | Kirchhoff plate, nu 1/2 |",
                  "|---|---|---|---|---|---|",
                  f"| profiled / uniform stiffness | {p['fe'] / u['fe']:.4f} | {p['shell'] / u['shell']:.4f} | "
                  f"{gp['profile'] / gp['uniform']:.4f} | "
                  f"{user['profile'] / user['uniform'] if user else math.nan:.4f} | {plate['kirchhoff']['0.5']:.4f} |",
                  f"| uniform disk, F_shell / F_FE - 1 (%) | | {pct(u['shell'] / u['fe'] - 1)} | "
                  f"{pct(gp['uniform'] / u['fe'] - 1)} | {pct(user['uniform'] / u['fe'] - 1) if user else '-'} | |",
                  f"| profiled disk, F_shell / F_FE - 1 (%) | | {pct(p['shell'] / p['fe'] - 1)} | "
                  f"{pct(gp['profile'] / p['fe'] - 1)} | {pct(user['profile'] / p['fe'] - 1) if user else '-'} | |", ""]
    variants = [("shell", "Kirchhoff", "trace, Kirchhoff"), ("shell", "shear", "trace, shear"),
                ("shell_koiter", "Kirchhoff", "koiter, Kirchhoff"), ("shell_koiter", "shear", "koiter, shear")]
    walls = [(pole, name) for pole, name in KOITER_WALLS if "shell_koiter" in cache.get(key(pole, name), {})]
    summary = {}
    for pole, name in walls:
        fe = cache[key(pole, name)]
        d, ff = np.asarray(fe["delta"], float), np.asarray(fe["force"], float) * fe["eps"] / pole
        lines += [f"## H0 = {pole:g}, {name}: F_shell / F_FE - 1 (%)", "",
                  "| delta/H0 | F_FE | " + " | ".join(v[2] for v in variants) + " |", "|---|---|" + "---|" * len(variants)]
        for i, x in enumerate(d):
            errs = {v[2]: fe[v[0]][v[1]]["force"][i] / ff[i] - 1 for v in variants}
            lines.append(f"| {x / pole:.3g} | {ff[i]:.5g} | " + " | ".join(pct(e) for e in errs.values()) + " |")
            summary.setdefault((pole, name), []).append((x / pole, fe["contact_radius"][i] >= 0.95 * 0.2, errs))
        lines.append("")
    for pole in dict.fromkeys(p for p, _ in walls):
        names = [n for p, n in walls if p == pole]
        lines += [f"## H0 = {pole:g}: the largest |F_shell / F_FE - 1| (percent) by depth band", "",
                  "| depth | " + " | ".join(f"{n}, {v[2]}" for n in names for v in variants) + " |",
                  "|---|" + "---|" * (len(names) * len(variants))]
        for label, test in BANDS:
            cells = []
            for name in names:
                for v in variants:
                    sel = [abs(e[v[2]]) for k, wrap, e in summary[(pole, name)] if test(k, wrap) and np.isfinite(e[v[2]])]
                    cells.append(f"{100 * max(sel):.1f}" if sel else "-")
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
        lines.append("")
    same = [abs(a / b - 1) for pole, name in walls if "shell_gauss" in cache[key(pole, name)]
            for v in ("Kirchhoff", "shear")
            for a, b in zip(cache[key(pole, name)]["shell_koiter"][v]["force"], cache[key(pole, name)]["shell_gauss"][v]["force"])
            if np.isfinite(a) and np.isfinite(b)]
    if same:
        lines += [f"The same energy as a user formula (`sb.BendingEnergy`, measured before it was built in, kept in the "
                  f"JSON): its forces at these {len(same)} points differ from the built-in's by at most "
                  f"{max(same):.1e} relative.", ""]
    lines += ["## The profile's stiffening with Koiter's energy", "",
              "F(profile) / F(uniform H0) - 1 in percent (Kirchhoff, no shear), and the part of the solid's the "
              "shell model holds.", "",
              "| H0 | delta/H0 | solid | shell, trace | shell, koiter | trace / solid | koiter / solid |",
              "|---|---|---|---|---|---|---|"]
    for pole in dict.fromkeys(p for p, _ in walls):
        prof, unif = cache.get(key(pole, "profile")), cache.get(key(pole, "uniform H0"))
        if prof is None or unif is None or "shell_koiter" not in prof or "shell_koiter" not in unif:
            continue
        for i, x in enumerate(prof["delta"]):
            if x > 10 * pole * (1 + 1e-9):
                continue
            solid = prof["force"][i] / unif["force"][i] - 1
            tr = prof["shell"]["Kirchhoff"]["force"][i] / unif["shell"]["Kirchhoff"]["force"][i] - 1
            ga = prof["shell_koiter"]["Kirchhoff"]["force"][i] / unif["shell_koiter"]["Kirchhoff"]["force"][i] - 1
            lines.append(f"| {pole:g} | {x / pole:.3g} | {100 * solid:+.1f} | {100 * tr:+.1f} | {100 * ga:+.1f} | "
                         f"{tr / solid:.3f} | {ga / solid:.3f} |")
    lines.append("")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=1, help="FE curves in parallel (default 1)")
    ap.add_argument("--no-mesh-check", action="store_false", dest="mesh_check",
                    help="no FE mesh check (the default solves each wall on a coarser mesh too)")
    ap.add_argument("--recompute", action="store_true", help="ignore the kept FE curves")
    ap.add_argument("--pole", default=None, help="only these pole thicknesses, comma-separated (default: "
                    + ",".join(f"{p:g}" for p in CASES) + "); the report shows every kept one")
    add_output_args(ap, quick="H0 0.025's profile and uniform wall to delta = H0, no mesh check, Koiter or disk")
    args = ap.parse_args(argv)
    poles = tuple(CASES) if args.pole is None else tuple(float(x) for x in args.pole.split(","))
    if not set(poles) <= set(CASES):
        ap.error(f"--pole must be among {', '.join(f'{p:g}' for p in CASES)}")
    if args.quick and (args.pole is not None or args.recompute):
        ap.error("--quick takes its own walls, afresh: give neither --pole nor --recompute with it")
    out = results_dir(args.out_dir)
    store = out / f"{stem('profile_solid', args.quick)}.json"
    cache = {} if args.recompute or args.quick or not store.exists() else json.loads(store.read_text())
    if args.quick:
        args.mesh_check = False
    walls = QUICK_WALLS if args.quick else [(p, n) for p in poles for n in CASES[p]]
    todo = [(p, n, args.mesh_check, args.quick) for p, n in walls
            if key(p, n) not in cache or not cache[key(p, n)].get("success")]
    with ProcessPoolExecutor(max_workers=max(1, args.workers)) as pool:
        for k, fe in pool.map(fe_case, todo):
            fe["shell"] = shell_rows(fe)
            cache[k] = fe
            print(f"{k}: FE {fe['seconds']:.0f} s, {fe['message']}", flush=True)
            _write(store, json.dumps(cache, indent=1, default=float))  # no finished curve is lost
    if todo or "measured" not in cache:
        cache["measured"] = _measured()
    if not args.quick and ("plate" not in cache or args.recompute):
        cache["plate"] = plate_case()
    for k, fe in cache.items():
        if k.startswith("pole") and "shell" not in fe:
            fe["shell"] = shell_rows(fe)
    if not args.quick and "koiter" not in cache:
        walls, d = plate_walls(sb.KoiterBending())
        cache["koiter"] = {"measured": _measured(), "plate": {name: plate_shell(scene, d) for name, scene in walls.items()}}
    for pole, name in () if args.quick else KOITER_WALLS:
        fe = cache.get(key(pole, name))
        if fe is not None and "shell_koiter" not in fe:
            fe["shell_koiter"] = shell_rows(fe, sb.KoiterBending())
            print(f"{key(pole, name)}: shell with Koiter's energy", flush=True)
            _write(store, json.dumps(cache, indent=1, default=float))
    _write(store, json.dumps(cache, indent=1, default=float))
    _write(store.with_suffix(".md"), report(cache, args))
    if json.loads(store.read_text()).keys() != cache.keys():
        raise SystemExit(f"profile_solid.py: {store} does not read back as written")
    print(f"wrote {store.with_suffix('.md')}")


def _measured():
    from checkout import commit_label

    return (f"{time.strftime('%Y-%m-%d')} on {platform.machine()}, shellbvp {sb.__version__} at "
            f"{commit_label() or 'unknown commit'}")


def _write(path, text):
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


if __name__ == "__main__":
    main()
