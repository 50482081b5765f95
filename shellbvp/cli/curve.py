"""The ``curve`` command: a force-displacement curve into an HDF5 file."""

from __future__ import annotations

import math
import sys
import time

from ..paths import check_output_path, partial_path
from ..progress import curve_progress, progress_bar, wanted
from ..units import force_unit_of, format_in
from .common import (
    MAX_POINTS, add_limit_options, add_mu_h_option, add_overwrite_option, add_radius_option, add_scene_options, checkpoint_seconds,
    free_default_name, nondimensional, number_or, plain_number, scene_from_args,
)

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``curve`` subcommand's arguments, on ``sub`` (the subparsers)."""
    c = sub.add_parser("curve", help="compute a force-displacement curve into an HDF5 file")
    add_scene_options(c)
    c.add_argument("--delta-max", type=number_or("length"), default=0.5, dest="delta_max",
                   help="largest pole displacement (default 0.5); with a unit (100um) it needs --radius")
    c.add_argument("--points", type=int, help="N equally spaced depths up to delta-max (default: adaptive)")
    c.add_argument("--force-max", type=number_or("force"), dest="force_max",
                   help="stop at this force; with a unit (10mN) it needs --radius and --muH")
    c.add_argument("--lambda0-max", type=plain_number, dest="lambda0_max", help="stop at this pole stretch")
    c.add_argument("--max-steps", type=int, default=400, dest="max_steps", help="most continuation steps of a curve (default 400)")
    c.add_argument("--profiles", action="store_true", help="store each point's profiles")
    add_radius_option(c, "with --muH: SI columns in the file")
    add_mu_h_option(c, "with --radius: SI columns in the file")
    c.add_argument("-o", "--output", help="output file (default <preset>.h5, or <preset>-2.h5, ... if that exists)")
    add_overwrite_option(c, "replace an existing output file")
    c.add_argument("-q", "--quiet", action="store_true", help="no progress bar (there is none when stderr is not "
                   "a terminal or tqdm is not installed: pip install 'shellbvp[progress]')")
    c.add_argument("--topology", choices=("auto", "cap"), default="auto",
                   help="auto (default): where the single contact cap would pull the shell, use the valid "
                        "lifted-off (line or annular) contact; cap: single cap only, flagged where invalid")
    c.add_argument("--stability", choices=("off", "points", "locate"), default="off",
                   help="stability of the states against non-axisymmetric modes: off (default); points: at "
                        "every point; locate: and the first instability narrowed between two points")
    add_limit_options(c, "stability")
    c.set_defaults(func=run)


def run(args):
    import dataclasses

    from ..continuation import iter_curve
    from ..io import write_curve

    out = check_output_path(args.output if args.output is not None else free_default_name(args.preset or "base", args.force),
                            overwrite=args.force)
    partial = partial_path(out)
    if partial.exists() and not args.force:
        raise ValueError(f"{partial} exists (the checkpoint of an unfinished run; `shellbvp info` reads "
                         f"it); use --overwrite to replace it")
    check_output_path(partial, overwrite=True)
    scene = scene_from_args(args)
    if args.stability != "off":  # its cost per state, estimated before the curve is computed
        from ..modal_stability import check_stability_size

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
        from ..curve_stability import assess

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
    from ..curve_stability import assess
    from ..modal_stability import stability_size

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
    from ..curve_stability import verdict

    print(f"  {verdict(c)}")
    if c.settings.get("stability_note"):
        print(f"  stability not computed where: {c.settings['stability_note']}")
