"""The ``curve`` command's handler: a force-displacement curve into an HDF5 file (its parser:
``shellbvp/cli/curve.py``)."""

from __future__ import annotations

import dataclasses
import math
import sys
import time

from ...continuation import iter_curve
from ...curve_stability import assess, verdict
from ...io import write_curve
from ...modal_stability import check_stability_size, stability_size
from ...paths import check_output_path, partial_path
from ...progress import curve_progress, progress_bar, wanted
from ...units import force_unit_of, format_in
from ..common import MAX_POINTS, checkpoint_seconds, free_default_name, nondimensional
from ..scene_options import scene_from_args

__all__ = ["run"]


def run(args):
    """``shellbvp curve``: exit 0 when the curve is complete, 1 when it stopped early, 130 interrupted."""
    out = check_output_path(args.output if args.output is not None else free_default_name(args.preset or "base", args.force),
                            overwrite=args.force)
    partial = partial_path(out)
    if partial.exists() and not args.force:
        raise ValueError(f"{partial} exists (the checkpoint of an unfinished run; `shellbvp info` reads "
                         f"it); use --overwrite to replace it")
    check_output_path(partial, overwrite=True)
    scene = scene_from_args(args)
    if args.stability != "off":  # its cost per state, estimated before the curve is computed
        check_stability_size(scene)
    units = None
    if (args.radius is None) != (args.mu_h is None):
        raise ValueError("--radius and --muH go together (rim radius, e.g. 0.3mm, and mu*H, e.g. 52N/m)")
    if args.radius is not None:
        units = {"R_L": args.radius.si, "mu_H": args.mu_h.si}
    args.delta_max = nondimensional(args, args.delta_max, "--delta-max")
    args.force_max = nondimensional(args, args.force_max, "--force-max")
    deltas = None
    if args.points is not None:
        if not 2 <= args.points <= MAX_POINTS:
            raise ValueError(f"--points must be in [2, {MAX_POINTS}]; got {args.points}")
        if not (math.isfinite(args.delta_max) and args.delta_max > 0):
            raise ValueError(f"--delta-max must be a finite number > 0; got {args.delta_max}")
        deltas = [args.delta_max * (i + 1) / args.points for i in range(args.points)]

    every = checkpoint_seconds()

    bar, show = curve_progress(args.delta_max, f"curve {args.preset or 'base'}", enabled=wanted(args.quiet))
    last = [time.perf_counter()]

    t0 = time.perf_counter()
    run = iter_curve(scene, args.delta_max, deltas=deltas, force_max=args.force_max,
                     lambda0_max=args.lambda0_max, max_steps=args.max_steps, tol=args.tol,
                     max_nodes=args.max_nodes, topology=args.topology)
    try:
        for sol in run:
            so_far = run.snapshot()
            show(so_far, sol)
            if time.perf_counter() - last[0] >= every:
                # checkpoint: no finished work is lost, and the old output stays intact until the end
                running = dataclasses.replace(so_far, stop_reason="running", complete=False, interrupted=False)
                write_curve(running, partial, overwrite=True, units=units)
                last[0] = time.perf_counter()
    except KeyboardInterrupt:
        run.interrupt()
    finally:
        bar.close()
    c = run.result()
    if not c.interrupted and args.stability != "off":
        _assess(c, args)
    elif not c.interrupted:
        assess(c, "off")
    if c.interrupted and out.exists():
        # Ctrl-C is as safe as kill -9: an earlier file stays; the finished points go to the checkpoint
        write_curve(c, partial, profiles=args.profiles, overwrite=True, units=units)
        print(f"shellbvp: interrupted; {out} is kept as it was; the {len(c)} finished points are in {partial}",
              file=sys.stderr)
        return 130
    write_curve(c, out, profiles=args.profiles, overwrite=True, units=units)
    partial.unlink(missing_ok=True)
    print(f"wrote {out}: {c.summary()} in {time.perf_counter() - t0:.1f} s")
    _print_details(c, args, units)
    if c.interrupted:
        print("shellbvp: interrupted; the file holds the finished points (complete = False)", file=sys.stderr)
        return 130
    return 0 if c.complete else 1


def _assess(c, args):
    """The states' stability, with a bar of its own: the curve's stays at 100 % meanwhile."""
    seconds = stability_size(c.scene)[3]
    total = len(c) if args.stability == "points" else None
    bar = progress_bar(total, desc=f"stability (~{seconds:.2g} s a state)", unit="state",
                       enabled=wanted(args.quiet))
    try:
        assess(c, args.stability, progress=lambda delta: (bar.update(1), bar.set_postfix_str(f"delta {delta:.4g}")))
    finally:
        bar.close()


def _print_details(c, args, units):
    """The lines under the summary: the scene (a bowl or a dome, lengths in lab units with --radius),
    the range in lab units, the configurations, the stability note."""
    print(f"  scene: {c.scene.describe(None if args.radius is None else args.radius.si)}")
    if units is not None and len(c):
        fu = force_unit_of(args.mu_h.unit)
        scale = args.radius.si * args.mu_h.si
        print(f"  with R_L = {args.radius} and mu*H = {args.mu_h}: displacement up to "
              f"{args.radius.show(args.radius.si * float(max(c.delta)))}, force "
              f"{format_in(scale * float(min(c.force)), fu, 'force')} .. {format_in(scale * float(max(c.force)), fu, 'force')}")
    if len(c):
        print(f"  contact topologies along the curve: {c.topology_summary()}")
    print(f"  {verdict(c)}")
    if c.settings.get("stability_note"):
        print(f"  stability not computed where: {c.settings['stability_note']}")
