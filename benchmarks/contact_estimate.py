"""The contact point's first estimate (``shellbvp.segments.estimate_contact``) on records with and
without an approach (issue 55).

* The shipped capsule record (``shellbvp/data/capsule_plates_synthetic.csv``: preset
  ``capsule-plates``, R_L = 30 um, mu*H = 0.5 N/m, contact at 3 um, 1 % noise) without its
  approach (the rows before contact dropped), fitted by ``fit_record``; and with the contact
  known (``fit_offset=False``).
* Rates on synthetic records of the presets ``fit`` and ``capsule-plates`` (their own curves, 30
  to 500 rows, proportional noise 0-2 % and additive 0-0.5 % of the largest force): records with
  an approach (15-50 % of the rows; a flat baseline or one tilted by 0.1-3 % of the largest force
  per unit delta) should get an estimate near the contact; records loaded from their first row
  (delta 0-0.05 at the first row) should get none.
* With ``--fits N``: N of the capsule's records loaded from their first row (0.5-1 % proportional
  noise, 0-0.5 % additive) that still get an estimate, fitted as ``fit_record`` fits them (a
  constant baseline, the contact's first guess at the estimate): mu*H's coverage of the truth.
* With ``--afm-dir``: the estimate on the first curves of every AFM file there, beside the one
  of the package at ``--against`` (a checkout's path), if given.  The step of ``run.py`` passes
  ``tests/data/afm`` (the AFM files the repository ships: 6 of afmformats' test files); the
  committed table was made on all of afmformats' test files (its repository's ``tests/data/``).

    python benchmarks/contact_estimate.py [--records 2000] [--fits 10] [--afm-dir DIR] [--against CHECKOUT]
                                          [--quick] [--out-dir DIR]

Writes results/contact_estimate.md (``--quick``: 100 records, no fits: contact_estimate-quick.md).
"""

import argparse
import glob
import importlib.util
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

import shellbvp as sb

from checkout import add_output_args, results_dir, stem, write_atomic  # benchmarks/ is on sys.path
from shellbvp.segments import estimate_contact

DATA = Path(sb.__file__).parent / "data" / "capsule_plates_synthetic.csv"
R_L, MU_H, CONTACT, APPROACH_ROWS = 30e-6, 0.5, 3e-6, 15


def loading_only(out):
    """The shipped capsule record without its approach rows, written to ``out``: (d, f) in m, N."""
    lines = DATA.read_text().splitlines()
    rows = lines[2 + APPROACH_ROWS:]
    out.write_text("\n".join(lines[:2] + rows) + "\n")
    return np.array([[float(v) for v in r.split(",")] for r in rows]).T * 1e-6


def capsule_lines(tmp):
    d, f = loading_only(tmp)
    scene = sb.Scene.preset("capsule-plates")
    rec = sb.read_instrument(tmp)
    res, _ = sb.fit_record(scene, rec, R_L=R_L)
    known = sb.fit(scene, d - CONTACT, f, R_L=R_L, fit_offset=False)
    um = 1e6
    return [f"* {d.size} rows from {d[0] * um:.2f} um (contact at {CONTACT * um:g} um): estimate_contact "
            f"{'None' if rec.contact_estimate is None else f'{rec.contact_estimate * um:.3f} um'}",
            f"* fit_record: mu*H {res.mu_H:.4f} [{res.mu_H_ci95[0]:.4f}, {res.mu_H_ci95[1]:.4f}] N/m, contact "
            f"{res.offset * um:.3f} um [{res.offset_ci95[0] * um:.3f}, {res.offset_ci95[1] * um:.3f}], baseline "
            f"{res.baseline_model}, quality {res.quality}, warnings {res.warning_codes or 'none'}",
            f"* the contact known: mu*H {known.mu_H:.4f} [{known.mu_H_ci95[0]:.4f}, {known.mu_H_ci95[1]:.4f}] N/m"]


def rates(records, seed=0):
    rng = np.random.default_rng(seed)
    shapes = {}
    for name in ("fit", "capsule-plates"):
        c = sb.curve(sb.Scene.preset(name), deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
        shapes[name] = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    tally = {}
    for i in range(records):
        name, approach = ("fit", "capsule-plates")[i % 2], i % 4 >= 2
        n = int(rng.choice([30, 60, 160, 500]))
        rel, add = rng.choice([0.0, 0.005, 0.01, 0.02]), rng.choice([0.0, 1e-4, 1e-3, 5e-3])
        if approach:
            share = rng.uniform(0.15, 0.5)
            x = np.linspace(-share / (1 - share) * 0.4, 0.4, n)
            tilt = rng.choice([0.0, 0.001, 0.01, 0.03])
        else:
            x, tilt = np.linspace(rng.choice([0.0, 0.01, 0.02, 0.05]), 0.4, n), 0.0
        F = shapes[name](np.clip(x, 0, 0.45))
        f = F * (1 + rel * rng.standard_normal(n)) + F.max() * (add * rng.standard_normal(n) + tilt * (x - x[0]))
        e = estimate_contact(x, f)
        t = tally.setdefault((name, "an approach" if approach else "loaded from the first row"), [0, 0, []])
        t[0] += 1
        t[1] += e is None
        if e is not None and approach:
            t[2].append(e)
    lines = ["| preset | records | no estimate | estimate - contact (delta): median, 95th percentile of abs |",
             "|---|---|---|---|"]
    for (name, kind), (tot, none, est) in sorted(tally.items()):
        spread = f"{np.median(est):+.4f}, {np.percentile(np.abs(est), 95):.4f}" if est else "-"
        lines.append(f"| {name} | {kind}: {tot} | {none} ({none / tot:.0%}) | {spread} |")
    return lines


def fit_lines(fits, seed=11):
    scene = sb.Scene.preset("capsule-plates")
    c = sb.curve(scene, deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    rng = np.random.default_rng(seed)
    lines = ["| rows | noise (proportional + additive) | first row (delta) | estimate - contact (delta) | mu*H (N/m) | "
             "covers 0.5 | contact - truth (um) | quality |", "|---|---|---|---|---|---|---|---|"]
    hits = done = 0
    while done < fits:
        n = int(rng.choice([30, 60, 160]))
        rel, add, lo = rng.choice([0.005, 0.01]), rng.choice([0.0, 1e-3, 5e-3]), rng.choice([0.01, 0.02, 0.05])
        x = np.linspace(lo, 0.4, n)
        F = shape(x)
        f = (F * (1 + rel * rng.standard_normal(n)) + F.max() * add * rng.standard_normal(n)) * MU_H * R_L
        d = CONTACT + x * R_L
        e = estimate_contact(d, f)
        if e is None:
            continue
        done += 1
        r = sb.fit(scene, d, f, R_L=R_L, baseline="constant", contact_guess=e)
        covers = bool(r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1])
        hits += covers
        lines.append(f"| {n} | {rel:g} + {add:g} | {lo:g} | {(e - CONTACT) / R_L:+.3f} | {r.mu_H:.4f} "
                     f"[{r.mu_H_ci95[0]:.4f}, {r.mu_H_ci95[1]:.4f}] | {covers} | {(r.offset - CONTACT) * 1e6:+.3f} | "
                     f"{r.quality} |")
    lines.append(f"\nmu*H's interval covers the truth in {hits} of {fits}.")
    return lines


def afm_lines(folder, against):
    from shellbvp.afm import read_afm

    other = None
    if against:
        spec = importlib.util.spec_from_file_location("_other_segments", Path(against) / "shellbvp" / "segments.py")
        other = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(other)
    lines = ["| curve | pushing rows | estimate (m) | at --against |", "|---|---|---|---|"]
    same = total = 0
    paths = sorted(glob.glob(str(Path(folder) / "*")))
    read = 0
    for path in paths:
        try:
            curves = read_afm(path)
        except ValueError:
            continue
        read += 1
        for c in curves[:4]:
            m = c.record.mask("loading") if c.record is not None else None
            if m is None or m.sum() < 3:
                continue
            d, f = c.record.displacement[m], c.record.force[m]
            e = estimate_contact(d, f)
            o = other.estimate_contact(d, f) if other else None
            total += 1
            same += other is not None and e == o
            show = lambda v: "None" if v is None else f"{v:.5g}"  # noqa: E731
            lines.append(f"| {Path(path).name[:48]}#{c.index} | {d.size} | {show(e)} | "
                         f"{show(o) if other else '-'} |")
    lines.append(f"\n{total} curves (up to four a file) from the {read} of the folder's {len(paths)} files that "
                 "`read_afm` reads.")
    if other is not None:
        lines.append(f"\n{same} of {total} estimates as at --against.")
    return lines


def _shown(folder):
    """``folder`` relative to the checkout when inside it (tests/data/afm), else DIR."""
    path, root = Path(folder).resolve(), Path(__file__).resolve().parents[1]
    return str(path.relative_to(root)) if path.is_relative_to(root) else "DIR"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--records", type=int, default=2000)
    p.add_argument("--fits", type=int, default=0)
    p.add_argument("--afm-dir", default=None, help="a folder of AFM files (the repository's: tests/data/afm)")
    p.add_argument("--against", default=None, help="a checkout whose shellbvp/segments.py is compared")
    add_output_args(p, quick="100 records, no fits")
    args = p.parse_args()
    if args.afm_dir is not None and not Path(args.afm_dir).is_dir():
        p.error(f"--afm-dir: {args.afm_dir} is not a folder")
    if args.against is not None and not (Path(args.against) / "shellbvp" / "segments.py").is_file():
        p.error(f"--against: {args.against} has no shellbvp/segments.py")
    if args.quick:
        args.records, args.fits = 100, 0
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        lines = ["# The contact point's first estimate", "",
                 f"`python benchmarks/contact_estimate.py{' --quick' if args.quick else ''} --records {args.records}"
                 + (f" --fits {args.fits}" if args.fits else "")
                 + (f" --afm-dir {_shown(args.afm_dir)}" if args.afm_dir else "")
                 + (" --against CHECKOUT" if args.against else "")
                 + "` (see its docstring).", "", "## The shipped capsule record without its approach", ""]
        lines += capsule_lines(Path(tmp) / "capsule_loading_only.csv")
    lines += ["", f"## Synthetic records ({args.records})", ""] + rates(args.records)
    if args.fits:
        lines += ["", f"## Capsule records loaded from their first row that get an estimate, fitted ({args.fits})",
                  ""] + fit_lines(args.fits)
    if args.afm_dir:
        lines += ["", "## AFM curves", ""] + afm_lines(args.afm_dir, args.against)
    out = results_dir(args.out_dir) / f"{stem('contact_estimate', args.quick)}.md"
    write_atomic(out, "\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
