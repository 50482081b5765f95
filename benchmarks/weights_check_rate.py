"""False alarms and power of the fit's model checks: the weights check and the residuals' lag-1
autocorrelation (issue 56).

A fit is refitted with another weighting (uniform; ``shellbvp.fit_checks.weights_disagreement``)
and fails (status 6) when mu*H's two estimates lie further apart than ``level`` times the sum of
their 95 % half-widths; ``z = |mu_a - mu_b| / (h_a + h_b)`` is recorded for every fit, so the
rate at any level is read off the same fits.  The lag-1 autocorrelation of the weighted residuals
in depth order (``FitResult.residual_autocorrelation``) is recorded too.

**Correct-model records** (the false alarms): the model's own curve (``sb.curve`` at exactly the
record's depths) times mu*H, plus noise ``F (1 + p e1) + a max(F) e2`` (e1, e2 ~ N(0, 1)):

* scenes: preset ``fit`` (gamma 2.5, rho 1/3, beta 0.01) and a thin hemisphere (gamma 1, rho 0.2,
  thickness 0.05 R_L);
* designs: ``loading`` (40 rows, delta 0.01..0.4, no approach, R_L = 0.3 mm; ``short``: 12 such
  rows, correct-model records only), ``approach``
  (20 approach rows, then 140 to delta 0.4, a 50 uN force baseline, R_L = 0.3 mm) and ``afm``
  (an AFM-like long baseline: 250 approach rows, then 150 to delta 0.3, R_L = 10 um, a 0.2 nN
  baseline);
* noise (p, a): ``proportional`` (1 %, 0: the approach rows exactly noise-free, as a synthetic
  map's), ``additive`` (0, 1 %), ``low`` (0.2 %, 0.1 %), ``high`` (3 %, 2 %).

Records with an approach are fitted as ``fit_record`` fits them (a constant baseline, the contact
point from ``estimate_contact``), the loading alone with no baseline; default (mixed) weights,
``model="shell"``, the model curve's depth fixed per design (one curve per scene and design).

**Wrong-model records** (the power), each fitted with the wrong scene:

* the rim radius R_L wrong by 0.5x and 2x, the sample's other lengths right (lab units: rise,
  tip radius and thickness as measured, so gamma, rho and eps change with R_L), on the thin
  hemisphere; 2x on preset ``fit`` (given as its thickness, sqrt(3 beta) R_L);
* the indenter's radius wrong by 0.5x and 2x (thin hemisphere);
* thick shells: the five held-out scenes of ``benchmarks/thick_fits.py`` made by the 3D solid
  (its record mesh, the indenter's displacement: an approach then the loading to 0.25 R_L),
  fitted with the shell model, whole and loading only.

Noise ``low`` and ``moderate`` (p 1 %, a 0.5 %).  Reported per cell: the fraction of fits that
fail the weights check at each level, whose autocorrelation exceeds each threshold, whose
interval misses the truth, which no check flags (the truth outside the interval, status 0, no
warning), and which are *silently wrong* (those, and a quality better than poor: a shell fit
with a thickness is rated poor where its mapped model error exceeds its interval).

    nice -n 10 python benchmarks/weights_check_rate.py [--seeds 200] [--power-seeds 100] [--no-thick] [--out-dir DIR]
    python benchmarks/weights_check_rate.py --report-only

Writes benchmarks/results/weights_check_rate.md and .json.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # this checkout's package
sys.path.insert(0, str(HERE))

import shellbvp as sb  # noqa: E402
from shellbvp import fit_checks  # noqa: E402
from shellbvp.segments import estimate_contact  # noqa: E402

from checkout import add_output_args, results_dir  # noqa: E402

RESULTS = HERE / "results"
#: design: (R_L (m), contact (m), approach rows, contact rows, deepest delta, mu*H (N/m), baseline (N))
DESIGNS = {"short": (0.3e-3, 10e-6, 0, 12, 0.4, 52.0, 0.0),
           "loading": (0.3e-3, 10e-6, 0, 40, 0.4, 52.0, 0.0),
           "approach": (0.3e-3, 25e-6, 20, 140, 0.4, 52.0, 50e-6),
           "afm": (10e-6, 0.3e-6, 250, 150, 0.3, 0.6e-3, 0.2e-9)}
#: noise: (proportional, additive as a fraction of the largest force)
NOISES = {"proportional": (0.01, 0.0), "additive": (0.0, 0.01), "low": (0.002, 0.001), "high": (0.03, 0.02),
          "moderate": (0.01, 0.005)}
NULL_NOISES = ("proportional", "additive", "low", "high")
POWER_DESIGNS = ("loading", "approach", "afm")
POWER_NOISES = ("low", "moderate")
#: weights-check levels (times the sum of the half-widths) and autocorrelation thresholds reported
LEVELS = (0.75, 1.0, 1.25, 1.5)
THRESHOLDS = (0.3, 0.4, 0.5, 0.6)


def hemisphere(R_factor=1.0, tip_factor=1.0):
    """The thin hemisphere (gamma 1, rho 0.2, eps 0.05) as a user with a rim radius ``R_factor``
    times the truth and a tip radius ``tip_factor`` times it (the rise and thickness as measured)
    describes it."""
    return sb.Scene.preset("base", gamma=1.0 / R_factor, rho=0.2 * tip_factor / R_factor, thickness=0.05 / R_factor)


def fit_preset(R_factor=1.0):
    """Preset ``fit`` given in lab units (its beta as a thickness) with the rim radius ``R_factor`` off."""
    eps = math.sqrt(3 * 0.01)
    return sb.Scene.preset("fit", gamma=2.5 / R_factor, rho=(1 / 3) / R_factor, thickness=eps / R_factor)


SCENES = {"fit": fit_preset, "hemisphere": hemisphere}
#: wrong-model cases: name -> (true scene, fitted scene, R_L factor)
WRONG = {"R_L 0.5x": ("hemisphere", lambda: hemisphere(0.5), 0.5),
         "R_L 2x": ("hemisphere", lambda: hemisphere(2.0), 2.0),
         "R_L 2x (preset fit)": ("fit", lambda: fit_preset(2.0), 2.0),
         "tip 0.5x": ("hemisphere", lambda: hemisphere(1.0, 0.5), 1.0),
         "tip 2x": ("hemisphere", lambda: hemisphere(1.0, 2.0), 1.0)}

_SHAPES = {}


def model_force(scene, deltas):
    """The scene's nondimensional force at exactly ``deltas`` (memoised)."""
    key = (scene, tuple(np.round(deltas, 12)))
    if key not in _SHAPES:
        c = sb.curve(scene, deltas=np.asarray(deltas), estimate_error=False)
        if len(c) != len(deltas):
            raise RuntimeError(f"the record's curve ended early: {c.stop_reason}")
        _SHAPES[key] = np.asarray(c.force, float)
    return _SHAPES[key]


def depths(design):
    """(displacement (m), delta of the contact rows) of a design's rows."""
    R_L, d0, na, nc, top = DESIGNS[design][:5]
    if na == 0:
        deltas = np.linspace(0.01, top, nc)
        return d0 + R_L * deltas, deltas
    step = top * R_L / nc
    deltas = step * np.arange(1, nc + 1) / R_L
    return np.r_[d0 - step * np.arange(na, 0, -1), d0 + R_L * deltas], deltas


def noisy(clean, noise, seed, baseline=0.0):
    p, a = NOISES[noise]
    rng = np.random.default_rng(seed)
    e1, e2 = rng.standard_normal(clean.size), rng.standard_normal(clean.size)
    return clean * (1 + p * e1) + a * np.max(clean) * e2 + baseline


def fit(scene, d, f, R_L, delta_max, approach):
    """A record with an ``approach`` as ``fit_record`` fits it (a constant baseline and the
    contact point from the approach, where ``estimate_contact`` finds one), the loading alone with
    no baseline; the shell model; the curve's depth fixed (one curve for all records), or the
    fit's own where a contact guess far off needs a deeper one."""
    est = estimate_contact(d, f) if approach else None
    options = dict(R_L=R_L, model="shell") if est is None else \
        dict(R_L=R_L, model="shell", baseline="constant", contact_guess=est)
    try:
        return sb.fit(scene, d, f, delta_max=delta_max, **options)
    except ValueError as e:
        if "beyond the" not in str(e) and "model curve ends" not in str(e):
            raise
        return sb.fit(scene, d, f, **options)


def measure(res, truth):
    """What one fit says: the weights-check ratio z, the autocorrelation, the rows, the error, ..."""
    lo, hi = res.mu_H_ci95
    other = res.weights_check
    a, b = other["mu_H_ci95"]
    z = abs(res.mu_H - other["mu_H"]) / ((hi - lo + b - a) / 2)
    return {"z": z, "r1": res.residual_autocorrelation, "n": res.n, "err": res.mu_H / truth - 1,
            "covered": bool(lo <= truth <= hi), "status": res.status, "poor": res.quality == "poor",
            "warnings": sorted(set(res.warning_codes) - {"residual_autocorrelation"}),
            "autocorrelated": "residual_autocorrelation" in res.warning_codes}


def run_cell(true_scene, fit_scene, R_factor, design, noise, seeds, seed0):
    R_L, d0, na, nc, top, mu_H, base = DESIGNS[design]
    d, deltas = depths(design)
    clean = mu_H * R_L * np.r_[np.zeros(na), model_force(true_scene, deltas)]
    delta_max = 1.2 * (d[-1] - (d0 if na else 0.0)) / (R_L * R_factor)
    out = []
    for s in range(seeds):
        f = noisy(clean, noise, seed0 + s, base)
        out.append(measure(fit(fit_scene, d, f, R_L * R_factor, delta_max, na > 0), mu_H))
    return out


def thick_cells(noises, seeds):
    """The held-out thick scenes of thick_fits.py: records by the solid, fitted with the shell."""
    import thick_fits as tf

    cells = {}
    for name, (gamma, rho, eps) in tf.HELD_OUT.items():
        t0 = time.perf_counter()
        deep = tf.DEPTH * np.arange(1, 51) / 50
        fe = sb.fe_curve(tf.scene_of(gamma, rho, eps), eps, deep, at="indenter", **tf.RECORD_MESH)
        if not fe.success:
            raise RuntimeError(f"{name}: the record's solid failed: {fe.message}")
        print(f"thick {name}: solid curve in {time.perf_counter() - t0:.0f} s", flush=True)
        truth = tf.MU * eps * tf.R_L
        clean = np.r_[np.zeros(15), truth * tf.R_L * np.asarray(fe.force)]
        disp = np.r_[np.linspace(0.0, tf.CONTACT, 15, endpoint=False), tf.CONTACT + deep * tf.R_L]
        scene = tf.scene_of(gamma, rho, eps)
        for cut in ("whole", "loading only"):
            rows = slice(None) if cut == "whole" else slice(15, None)
            for noise in noises:
                out = []
                for s in range(seeds):
                    f = noisy(clean, noise, zlib.crc32(name.encode()) + s)[rows]
                    out.append(measure(fit(scene, disp[rows], f, tf.R_L, 1.2 * tf.DEPTH, cut == "whole"), truth))
                cells[f"thick {name}|{cut}|{noise}"] = out
                print(f"thick {name} {cut} {noise}: {_short(summary(out))}", flush=True)
    return cells


#: The shipped example (R_L = 0.3 mm) fitted with the rim radius given as these (m) ...
EXAMPLE_R_L = (0.27e-3, 0.3e-3, 0.33e-3, 0.6e-3)
#: ... and the sample described three ways: the preset scaled with R_L, lab units with beta, lab
#: units with the thickness (the shell model)
EXAMPLE_SCENES = {
    "preset fit (rise, tip and beta scale with R_L)": lambda R: sb.Scene.preset("fit"),
    "lab units: --rise 0.75mm --indenter-radius 0.1mm --beta 0.01":
        lambda R: sb.Scene.preset("fit", gamma=0.75e-3 / R, rho=0.1e-3 / R),
    "lab units with --thickness 52um (--model shell)":
        lambda R: sb.Scene.preset("fit", gamma=0.75e-3 / R, rho=0.1e-3 / R, thickness=52e-6 / R)}


def example_table():
    """The shipped example fitted at wrong rim radii (docs/fitting.md's table)."""
    from shellbvp.fitting import example_data_path

    d, F = sb.read_force_csv(example_data_path())
    out = {}
    for label, make in EXAMPLE_SCENES.items():
        for R in EXAMPLE_R_L:
            key = f"{label}|{R * 1e3:g}"
            try:
                res = sb.fit(make(R), d, F, R_L=R, model="shell")
            except ValueError as e:
                out[key] = {"refused": str(e).splitlines()[0][:160]}
            else:
                out[key] = {"mu_H": res.mu_H, "mu_H_ci95": list(res.mu_H_ci95), "status": res.status,
                            "warnings": list(res.warning_codes), "r1": res.residual_autocorrelation,
                            "runs_p": res.runs_p, "other_mu_H": res.weights_check["mu_H"]}
            print(key, out[key], flush=True)
    return out


def wilson(k, n, z=1.96):
    p = k / n
    den = 1 + z * z / n
    c = (p + z * z / (2 * n)) / den
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(c - h, 0.0), min(c + h, 1.0)


def summary(rows):
    n = len(rows)
    z = np.array([r["z"] for r in rows])
    r1 = np.array([r["r1"] for r in rows])
    unchecked = [(not r["covered"]) and r["status"] == 0 and not r["warnings"] and not r["autocorrelated"] for r in rows]
    return {"fits": n, "weights": {f"{k:g}": int(np.sum(z > k)) for k in LEVELS},
            "autocorrelation": {f"{t:g}": int(np.sum(r1 > t)) for t in THRESHOLDS},
            "autocorrelation_warning": int(sum(r["autocorrelated"] for r in rows)),
            "status6": int(sum(r["status"] == 6 for r in rows)),
            "other_warnings": int(sum(bool(r["warnings"]) for r in rows)),
            "missed": int(sum(not r["covered"] for r in rows)),
            "unflagged": int(sum(unchecked)), "poor": int(sum(r["poor"] for r in rows)),
            "silent": int(sum(u and not r["poor"] for r, u in zip(rows, unchecked))),
            "median_error": float(np.median([r["err"] for r in rows])), "median_z": float(np.median(z)),
            "median_r1": float(np.median(r1)), "max_r1": float(np.max(r1)), "max_z": float(np.max(z)),
            "rows": int(np.median([r["n"] for r in rows])),
            "z_values": [float(f"{v:.4g}") for v in z], "r1_values": [float(f"{v:.4g}") for v in r1]}


def _short(v):
    return {k: x for k, x in v.items() if not k.endswith("_values")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200, help="records per correct-model cell (default 200)")
    ap.add_argument("--power-seeds", type=int, default=100, dest="power_seeds",
                    help="records per wrong-model cell (default 100)")
    ap.add_argument("--no-thick", action="store_true", dest="no_thick", help="leave out the solid's records")
    ap.add_argument("--report-only", action="store_true", dest="report_only",
                    help="rewrite the .md from the .json of the last run")
    ap.add_argument("--example-only", action="store_true", dest="example_only",
                    help="only the shipped example at wrong rim radii, merged into the last run's results")
    add_output_args(ap)
    args = ap.parse_args()
    global RESULTS
    RESULTS = results_dir(args.out_dir)
    if args.report_only or args.example_only:
        out = json.loads((RESULTS / "weights_check_rate.json").read_text())
        if args.example_only:
            out["example"] = example_table()
            out["example_commit"] = _commit()
            (RESULTS / "weights_check_rate.json").write_text(json.dumps(out, indent=1) + "\n")
        (RESULTS / "weights_check_rate.md").write_text(report(out))
        return
    t0, c0 = time.perf_counter(), time.process_time()
    null, power = {}, {}
    for sname, make in SCENES.items():
        scene = make()
        for design in DESIGNS:
            for noise in NULL_NOISES:
                key = f"{sname}|{design}|{noise}"
                seed0 = (100_000 * list(SCENES).index(sname) + 10_000 * (1 + list(DESIGNS).index(design))
                         + 1_000 * NULL_NOISES.index(noise))
                null[key] = summary(run_cell(scene, scene, 1.0, design, noise, args.seeds, seed0))
                print(key, _short(null[key]), flush=True)
    for case, (sname, wrong, R_factor) in WRONG.items():
        for design in POWER_DESIGNS:
            for noise in POWER_NOISES:
                key = f"{case}|{design}|{noise}"
                try:
                    rows = run_cell(SCENES[sname](), wrong(), R_factor, design, noise, args.power_seeds, 500_000)
                except ValueError as e:  # a wrong scene the fit refuses (the tip no longer fits the bowl, ...)
                    power[key] = {"refused": str(e).splitlines()[0][:200]}
                    print(key, "refused:", e, flush=True)
                    continue
                power[key] = summary(rows)
                print(key, _short(power[key]), flush=True)
    if not args.no_thick:
        power.update({k: summary(v) for k, v in thick_cells(POWER_NOISES, args.power_seeds).items()})
    example = example_table()
    out = {"setup": {"seeds": args.seeds, "power_seeds": args.power_seeds, "levels": LEVELS,
                     "thresholds": THRESHOLDS, "weights_level": fit_checks.WEIGHTS_LEVEL,
                     "autocorrelation_level": fit_checks.AUTOCORRELATION_LEVEL, "noises": NOISES, "designs": DESIGNS},
           "null": null, "power": power, "example": example, "seconds": time.perf_counter() - t0, "cpu_seconds": time.process_time() - c0,
           "version": sb.__version__, "commit": _commit(), "machine": platform.machine()}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "weights_check_rate.json").write_text(json.dumps(out, indent=1) + "\n")
    (RESULTS / "weights_check_rate.md").write_text(report(out))
    print(f"wrote {RESULTS / 'weights_check_rate.md'} ({out['seconds']:.0f} s)")


def _commit():
    try:
        return subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip()
    except OSError:
        return ""


def _rate(k, n):
    lo, hi = wilson(k, n)
    return f"{k}/{n} = {100 * k / n:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}]"


def report(out):
    s = out["setup"]
    lv, th = f"{s['weights_level']:g}", f"{s['autocorrelation_level']:g}"
    L = ["# False alarms and power of the weights check and the residual autocorrelation", "",
         f"Generated by `python benchmarks/weights_check_rate.py` at {out['commit']} ({out['seconds']:.0f} s, "
         f"{out['cpu_seconds']:.0f} s of CPU); the module's docstring describes the records.  "
         f"{s['seeds']} records per correct-model cell, {s['power_seeds']} per wrong-model cell.  "
         f"Rates with their Wilson 95 % interval.  The package's levels: weights check {lv} (times the sum of "
         f"the two half-widths), autocorrelation warning above {th}.", "",
         "## Correct model: false alarms", "",
         "| scene | design | noise | rows | weights check > " + " | > ".join(f"{k:g}" for k in s["levels"])
         + " | lag-1 autocorr. > " + " | > ".join(f"{t:g}" for t in s["thresholds"])
         + " | max autocorr. | autocorr. warning | interval misses truth | other warnings |",
         "|---|---|---|---|" + "---|" * (len(s["levels"]) + len(s["thresholds"]) + 4)]
    tot_w = {f"{k:g}": 0 for k in s["levels"]}
    tot_a = {f"{t:g}": 0 for t in s["thresholds"]}
    n_all = warned = 0
    for key, v in out["null"].items():
        sc, design, noise = key.split("|")
        n = v["fits"]
        n_all += n
        warned += v["autocorrelation_warning"]
        for k in tot_w:
            tot_w[k] += v["weights"][k]
        for t in tot_a:
            tot_a[t] += v["autocorrelation"][t]
        L.append(f"| {sc} | {design} | {noise} | {v['rows']} | " + " | ".join(str(v["weights"][k]) for k in tot_w)
                 + " | " + " | ".join(str(v["autocorrelation"][t]) for t in tot_a)
                 + f" | {v['max_r1']:.2f} | {v['autocorrelation_warning']} | {v['missed']} | {v['other_warnings']} |")
    L += ["", f"All {n_all} correct-model fits:", ""]
    L += [f"* weights check at level {k}: {_rate(c, n_all)}" for k, c in tot_w.items()]
    L += [f"* lag-1 autocorrelation above {t}: {_rate(c, n_all)}" for t, c in tot_a.items()]
    L += [f"* the warning `residual_autocorrelation` (above {th} and r1 sqrt(n) beyond the runs test's p): "
          f"{_rate(warned, n_all)}"]
    L += ["", "## Wrong model: power", "",
          "Fits that fail the weights check at the package's level (status 6), that get the autocorrelation "
          "warning, whose 95 % interval misses the truth, which no check flags (the truth outside the interval, "
          "status 0, no warning) and which are *silently wrong* (those, and rated better than poor: a shell fit "
          "with a thickness is rated poor where its mapped model error exceeds its interval).", "",
          "| wrong | design | noise | median mu*H error | median z | weights check > " +
          " | > ".join(f"{k:g}" for k in s["levels"]) + f" | status 6 | median autocorr. | autocorr. warning "
          "| interval misses truth | no check flags it | rated poor | silently wrong |",
          "|---|---|---|---|---|" + "---|" * len(s["levels"]) + "---|---|---|---|---|---|---|"]
    for key, v in out["power"].items():
        case, design, noise = key.split("|")
        if "refused" in v:
            L.append(f"| {case} | {design} | {noise} | refused: {v['refused']} |" + " |" * (len(s["levels"]) + 9))
            continue
        n = v["fits"]
        L.append(f"| {case} | {design} | {noise} | {100 * v['median_error']:+.1f} % | {v['median_z']:.2f} | "
                 + " | ".join(f"{v['weights'][f'{k:g}']}" for k in s["levels"])
                 + f" | {v['status6']}/{n} | {v['median_r1']:.2f} | {v['autocorrelation_warning']}/{n} | "
                 f"{v['missed']}/{n} | {v['unflagged']}/{n} | {v['poor']}/{n} | {v['silent']}/{n} |")
    if out.get("example"):
        L += ["", "## The shipped example at wrong rim radii", "",
              "The example (`shellbvp/data/lepidium_synthetic.csv`: R_L = 0.3 mm, mu*H = 52 N/m, 40 rows, 2 % "
              "proportional noise) fitted with R_L given wrong, the sample described three ways "
              f"(at {out.get('example_commit', out['commit'])}).", "",
              "| R_L given | " + " | ".join(EXAMPLE_SCENES) + " |", "|---|" + "---|" * len(EXAMPLE_SCENES)]
        for R in EXAMPLE_R_L:
            cells = []
            for label in EXAMPLE_SCENES:
                v = out["example"][f"{label}|{R * 1e3:g}"]
                if "refused" in v:
                    cells.append("refused: " + v["refused"].replace("|", "/")[:90])
                    continue
                lo, hi = v["mu_H_ci95"]
                state = "status 6 (weights disagree)" if v["status"] == 6 else f"status {v['status']}"
                cells.append(f"{v['mu_H']:.1f} N/m [{lo:.1f}, {hi:.1f}] ({v['mu_H'] / 52 - 1:+.0%}); {state}; "
                             f"{', '.join(v['warnings']) or 'no warning'}; autocorr. {v['r1']:.2f}, runs p "
                             f"{v['runs_p']:.2g}; uniform {v['other_mu_H']:.1f}")
            L.append(f"| {R * 1e3:g} mm | " + " | ".join(cells) + " |")
    L.append("")
    return "\n".join(L)


if __name__ == "__main__":
    main()
