"""The ``shellbvp`` command line: a thin layer over the Python API.

    shellbvp curve [--preset base] [scene options] [-o base.h5]   force-displacement curve -> HDF5
    shellbvp solve [scene options] --delta 0.2 [--profiles] [--json]   one state
    shellbvp sweep --beta 0.005,0.01 --rho 0.15:0.3:4 -o grid.h5   one curve per combination -> one file
    shellbvp fit DATA.csv --preset fit --radius 0.3mm [--json]         mu*H from measured data
    shellbvp plot A.h5 [B.h5 ...] -o fig.png [--profiles 0.1,0.3]   figures (matplotlib)
    shellbvp info FILE.h5                                            what a curve or sweep file holds
    shellbvp presets                                                 the built-in scenes

Invalid input exits with status 2 and a one-line message naming the parameter.
``fit`` exits 0 when the fit succeeded (warnings allowed, printed as ``warning: ...``
lines and listed under ``warnings`` in ``--json``), 1 when the fit ran but failed its
checks (``success`` false, ``status`` one of ``shellbvp.fitting.FIT_STATUS``), 2 on bad
input (data the fit cannot use included); with ``--json`` stdout is one JSON document
in every case.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
import time
from pathlib import Path

from .shape_parameters import SHAPE_PARAMETERS

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    json_errors = False  # set by main when --json was asked for: errors are JSON on stdout too

    def error(self, message):  # one line, exit 2 (argparse's own convention)
        if _Parser.json_errors:
            _print_json_error(message)
        self.exit(2, f"shellbvp: error: {message}\n")


def _print_json_error(message):
    """The one JSON document of a --json run that stopped on bad input (exit status 2)."""
    print(json.dumps({"success": False, "status": None, "exit_status": 2, "message": str(message),
                      "warnings": [], "warning_codes": []}))


def _number(text):
    """argparse type: a plain finite number (float() would also take 5_0, inf, nan, 1e999)."""
    from .units import plain_number

    try:
        return plain_number(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _numbers(text, name):
    """Comma-separated plain finite numbers of an option."""
    from .units import plain_number

    return [plain_number(v, name) for v in text.split(",")]


def quantity(kind):
    """argparse type: a quantity with its unit (``0.3mm``, ``52N/m``), > 0; a bare number is an
    error that says which unit to add.  Every subcommand takes dimensional options this way."""
    from .units import Quantity

    def parse(text):
        try:
            return Quantity.parse(text, kind, "the value")  # argparse names the option
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = f"{kind} with a unit"
    return parse


def _uncertain(text):
    """argparse type: ``VALUE`` or ``VALUE+-U`` (plain numbers) -> (value, U or None)."""
    from .uncertainty import parse_uncertain

    try:
        return parse_uncertain(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _pressure(text):
    """argparse type: a plain number (``p R_L/(mu H)``) or a pressure with its unit (``0.2MPa``)."""
    from .units import Quantity, plain_number, split_quantity

    try:
        if split_quantity(text, "pressure", "the value")[1]:
            return Quantity.parse(text, "pressure", "the value", positive=False)
        return plain_number(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _say(line=""):
    """Print a line that may hold text from a file or a user: control characters escaped
    (shellbvp.textdata), so that a file cannot drive the terminal or forge a result line."""
    from .textdata import printable

    print(printable(line))


def number_or(kind):
    """argparse type: a plain number (nondimensional) or a quantity with its unit (``50um``,
    ``10mN``), which :func:`_nondimensional` turns into the model's units."""
    from .units import Quantity, plain_number, split_quantity

    def parse(text):
        try:
            if split_quantity(text, kind, "the value")[1]:
                return Quantity.parse(text, kind, "the value")
            return plain_number(text, "the value")
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = f"number or {kind}"
    return parse


_thickness = number_or("length")  # eps = H / R_L, or the thickness with its unit


def _nondimensional(args, value, option):
    """``value`` of ``option`` in the model's units: a plain number as it is; a length over the rim
    radius (``--radius``), a force over mu*H times it (``--muH`` too)."""
    from .units import Quantity

    if not isinstance(value, Quantity):
        return value
    if value.kind == "length":
        if args.radius is None:
            raise ValueError(f"{option} {value} needs --radius (the rim radius, e.g. 0.3mm), or give it in "
                             f"rim radii (a plain number)")
        return value.si / args.radius.si
    if args.radius is None or args.mu_h is None:
        raise ValueError(f"{option} {value} needs --radius and --muH (e.g. 0.3mm and 52N/m), or give it in "
                         f"mu*H R_L (a plain number)")
    return value.si / (args.mu_h.si * args.radius.si)


def _material(text):
    """argparse type: ``FAMILY[:NAME=VALUE,...]`` (``--material yeoh:c2=0.1,c3=0.01``), a registered
    material's family and its parameters by the names files use; read as data, never run."""
    from .materials import MATERIALS
    from .units import plain_number

    try:
        family, _, options = (t.strip() for t in text.partition(":"))
        known = {f: c for f, c in MATERIALS.items() if c.cli}
        if family not in known:
            raise ValueError(f"unknown material {family!r}; one of {', '.join(known)}")
        names = [p.name for p in known[family].parameters]
        values = {}
        for item in (t.strip() for t in options.split(",") if options):
            name, equals, value = (t.strip() for t in item.partition("="))
            if not equals or name not in names or name in values:
                wanted = f"give NAME=VALUE once each, NAME one of {', '.join(names)}" if names else "takes no parameters"
                raise ValueError(f"{family}: {wanted}; got {item!r}")
            values[name] = plain_number(value, f"{family}: {name}")
        material = known[family](**values)
        material.validate()
        return material
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _material_help() -> str:
    """What --material takes, from the registry of materials."""
    from .materials import MATERIALS

    kinds = [c.family + "".join(f", {p.name} {p.range_text()}" for p in c.parameters)
             for c in MATERIALS.values() if c.cli]
    return ("a material as FAMILY[:NAME=VALUE,...], e.g. gent:Jm=1 (parameters not given keep their "
            f"defaults): {'; '.join(kinds)}")


def _bending_families() -> tuple:
    from .materials import BENDINGS

    return tuple(f for f, c in BENDINGS.items() if c.cli)


def _scene_options(p, uncertain=False, preset_required=False):
    g = p.add_argument_group("scene (overrides of the preset)")
    g.add_argument("--preset", default=None,
                   help="built-in scene (see `shellbvp presets`); " + (
                       "give it, or the sample's geometry: --indenter-radius (or --rho) and --rise (or --gamma) "
                       "and --thickness (or --beta)" if preset_required else "default base"))
    kind, note = (_uncertain, "; VALUE+-U: with a standard uncertainty U") if uncertain else (_number, "")
    shape = g.add_mutually_exclusive_group()
    shape.add_argument("--gamma", type=kind, help=f"spheroid aspect parameter (< 1/rho; >0 bowl, <0 dome){note}")
    shape.add_argument("--rise", type=quantity("length"),
                       help="the shell's depth from its rim's plane to its pole, with its unit (with --radius): "
                            "gamma = rise / R_L (a bowl indented from inside; a dome: --gamma < 0)")
    tip = g.add_mutually_exclusive_group()
    tip.add_argument("--rho", type=kind, help=f"indenter radius / rim radius (> 0){note}")
    tip.add_argument("--indenter-radius", type=quantity("length"), dest="indenter_radius",
                     help="the indenter's tip radius with its unit (with --radius): rho = it / R_L")
    g.add_argument("--beta", type=kind, help=f"bending stiffness B/(mu R_L^2) (> 0){note}")
    g.add_argument("--thickness", type=_thickness,
                   help="shell thickness: H/R_L in (0, 0.5], or with a unit (50um) together with --radius; "
                        "sets beta = (H/R_L)^2/3, the bending stiffness of a 3D plate")
    g.add_argument("--transverse-shear", action="store_true", default=None, dest="transverse_shear",
                   help="with --thickness: add the shell's transverse shear compliance (forces at the thick "
                        "shell's depth; removes most of the model's O(H/R_L) error, see docs/accuracy.md)")
    m = g.add_mutually_exclusive_group()
    m.add_argument("--alpha", type=kind, help=f"Mooney-Rivlin alpha in [0, 1]{note}")
    m.add_argument("--gent-jm", type=_number, dest="gent_jm", help="Gent model with this Jm (> 0)")
    m.add_argument("--neo-hookean", action="store_true", help="neo-Hookean material")
    m.add_argument("--material", type=_material, metavar="FAMILY[:NAME=VALUE,...]",
                   help=_material_help())
    g.add_argument("--xi", type=int, choices=(0, 1), help="1: full generalised tensions; 0: first approximation")
    g.add_argument("--pressure", type=_pressure,
                   help="pressure below the shell (from the side away from the indenter; > 0 inflates a dome or "
                        "cell): p R_L/(mu H), or with a unit (0.2MPa, 50kPa) together with --radius and --muH")
    g.add_argument("--sealed", action="store_true", default=None,
                   help="volume control: the shell encloses the volume it has when inflated at --pressure (a "
                        "sealed capsule); the pressure becomes an unknown of every state")
    g.add_argument("--contact", choices=("smooth", "paper"), help="contact-line model (default smooth)")
    b = g.add_mutually_exclusive_group()
    b.add_argument("--bending", choices=_bending_families(),
                   help="bending energy B in U = W + beta B: trace (the paper's, default) or rotation (convex)")
    b.add_argument("--bending-formula", dest="bending_formula",
                   help="a user bending energy B per beta in lambda_s, lambda_theta, kappa_s, kappa_theta, "
                        "kappa_s0, kappa_theta0 (the reference curvatures)")
    s = p.add_argument_group("solver")
    s.add_argument("--tol", type=_number, default=1e-6, help="collocation tolerance (default 1e-6)")
    s.add_argument("--max-nodes", type=int, default=10000, dest="max_nodes", help="largest collocation mesh of a state (default 10000)")


def _scene(args):
    import shellbvp as sb

    over = {k: getattr(args, k) for k in ("gamma", "rho", "beta", "xi", "contact", "sealed", "transverse_shear")
            if getattr(args, k, None) is not None}
    if args.alpha is not None:
        over["material"] = sb.MooneyRivlin(args.alpha)
    elif args.gent_jm is not None:
        over["material"] = sb.Gent(args.gent_jm)
    elif args.neo_hookean:
        over["material"] = sb.NeoHookean()
    elif args.material is not None:
        over["material"] = args.material
    if getattr(args, "bending", None):
        from .materials import bending_class

        over["bending"] = bending_class(args.bending)()
    elif getattr(args, "bending_formula", None):
        over["bending"] = sb.BendingEnergy(args.bending_formula)
    if getattr(args, "pressure", None) is not None:
        over["pressure"] = _nondimensional_pressure(args)
    if getattr(args, "thickness", None) is not None:
        over["thickness"] = _nondimensional_thickness(args)
    for name, length, what in (("rho", "indenter_radius", "--indenter-radius"), ("gamma", "rise", "--rise")):
        if getattr(args, length, None) is not None:
            over[name] = _over_rim_radius(args, getattr(args, length), what)
    return sb.Scene.preset(args.preset or "base", **over)


def _over_rim_radius(args, length, option):
    """A lab length of the sample over the rim radius ``--radius``: the nondimensional number."""
    radius = getattr(args, "radius", None)
    if radius is None:
        raise ValueError(f"{option} {length} is a length: it needs --radius (the rim radius R_L), or give "
                         f"the ratio itself ({'--rho' if option == '--indenter-radius' else '--gamma'})")
    return length.si / radius.si


def _require_sample(args):
    """``fit`` names its sample: a preset, or the geometry (no silent default hemisphere)."""
    if args.preset is not None:
        return
    missing = [what for what, given in (
        ("the indenter: --indenter-radius (or --rho)", args.rho is not None or args.indenter_radius is not None),
        ("the shell's shape: --rise (or --gamma)", args.gamma is not None or args.rise is not None),
        ("its bending stiffness: --thickness (or --beta)", args.thickness is not None or args.beta is not None))
        if not given]
    if missing:
        raise ValueError("fit needs the sample: --preset NAME (`shellbvp presets`), or its geometry; missing "
                         + "; ".join(missing))


def _nondimensional_thickness(args):
    """``--thickness`` as ``H / R_L``: a plain number as it is, a length through ``--radius``."""
    from .units import Quantity

    if not isinstance(args.thickness, Quantity):
        return args.thickness
    radius = getattr(args, "radius", None)
    if radius is None:
        raise ValueError(f"--thickness {args.thickness} has a unit: it needs --radius (the nondimensional "
                         f"thickness is H / R_L); or give that number itself")
    return args.thickness.si / radius.si


def _nondimensional_pressure(args):
    """``--pressure`` as ``p R_L/(mu H)``: a plain number as it is, a pressure with a unit through
    ``--radius`` and ``--muH``."""
    from .units import Dimensions, Quantity

    if not isinstance(args.pressure, Quantity):
        return args.pressure
    if args.command == "fit":
        raise ValueError(f"fit: --pressure {args.pressure} has a unit, but the fit estimates mu*H, which makes it "
                         f"nondimensional: give the start as p R_L/(mu H) (with --fit-pressure the fit reports "
                         f"the pressure in Pa)")
    radius, mu_h = getattr(args, "radius", None), getattr(args, "mu_h", None)
    if radius is None or mu_h is None:
        raise ValueError(f"--pressure {args.pressure} has a unit: it needs --radius and --muH (the nondimensional "
                         f"pressure is p R_L/(mu H)); or give that number itself")
    return Dimensions(R_L=radius.si, mu_H=mu_h.si).p(args.pressure.si)


def _checkpoint_seconds():
    """Seconds between checkpoints of a running curve (to ``X.h5.partial``): 5, or
    ``SHELLBVP_CHECKPOINT_SECONDS`` (0: after every point)."""
    text = os.environ.get("SHELLBVP_CHECKPOINT_SECONDS", "5")
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"SHELLBVP_CHECKPOINT_SECONDS must be a number of seconds >= 0; got {text!r}")
    return value


def _progress_bar(total, unit, args):
    """A progress bar on stderr (tqdm; none when quiet, not a terminal, or tqdm absent)."""
    from .progress import progress_bar, wanted

    return progress_bar(total, desc=args.command, unit=unit, enabled=wanted(getattr(args, "quiet", False)))


def _curve_bars(args, leave=True):
    """``progress`` for :func:`shellbvp.fit`: one bar per model curve, over delta."""
    from .progress import curve_progress, wanted

    mode = wanted(getattr(args, "quiet", False))
    if not mode:
        return None
    return lambda desc, delta_max: curve_progress(delta_max, desc, enabled=mode, leave=leave)


MAX_POINTS = 100_000  # --points: each is a solve (~0.05-0.5 s); more is a typo, not a curve


def _free_default_name(preset, force):
    """Without -o: ``<preset>.h5``, or (it exists, no --overwrite) the first free ``<preset>-N.h5``,
    so that running the quick start twice neither fails nor replaces the first result."""
    from pathlib import Path

    name = Path(f"{preset}.h5")
    n = 2
    while not force and (name.exists() or Path(f"{name}.partial").exists()):
        name = Path(f"{preset}-{n}.h5")
        n += 1
    return str(name)


def _cmd_curve(args):
    import dataclasses

    import shellbvp as sb

    from .io import write_curve
    from .paths import check_output_path, partial_path

    out = check_output_path(args.output if args.output is not None else _free_default_name(args.preset or "base", args.force),
                            overwrite=args.force)
    partial = partial_path(out)
    if partial.exists() and not args.force:
        raise ValueError(f"{partial} exists (the checkpoint of an unfinished run; `shellbvp info` reads "
                         f"it); use --overwrite to replace it")
    check_output_path(partial, overwrite=True)
    scene = _scene(args)
    units = None
    if (args.radius is None) != (args.mu_h is None):
        raise ValueError("--radius and --muH go together (rim radius, e.g. 0.3mm, and mu*H, e.g. 52N/m)")
    if args.radius is not None:
        units = {"R_L": args.radius.si, "mu_H": args.mu_h.si}
    args.delta_max = _nondimensional(args, args.delta_max, "--delta-max")
    args.force_max = _nondimensional(args, args.force_max, "--force-max")
    deltas = None
    if args.points is not None:
        if not 2 <= args.points <= MAX_POINTS:
            raise ValueError(f"--points must be in [2, {MAX_POINTS}]; got {args.points}")
        if not (math.isfinite(args.delta_max) and args.delta_max > 0):
            raise ValueError(f"--delta-max must be a finite number > 0; got {args.delta_max}")
        deltas = [args.delta_max * (i + 1) / args.points for i in range(args.points)]

    every = _checkpoint_seconds()
    from .progress import curve_progress, wanted

    bar, show = curve_progress(args.delta_max, f"curve {args.preset or 'base'}", enabled=wanted(args.quiet))
    last = [time.perf_counter()]

    t0 = time.perf_counter()
    run = sb.iter_curve(scene, args.delta_max, deltas=deltas, force_max=args.force_max,
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
    if c.interrupted and out.exists():
        # Ctrl-C is as safe as kill -9: an earlier file stays; the finished points go to the checkpoint
        write_curve(c, partial, profiles=args.profiles, overwrite=True, units=units)
        print(f"shellbvp: interrupted; {out} is kept as it was; the {len(c)} finished points are in {partial}",
              file=sys.stderr)
        return 130
    write_curve(c, out, profiles=args.profiles, overwrite=True, units=units)
    partial.unlink(missing_ok=True)
    print(f"wrote {out}: {c.summary()} in {time.perf_counter() - t0:.1f} s")
    if units is not None and len(c):
        from .units import force_unit_of, format_in

        fu = force_unit_of(args.mu_h.unit)
        scale = args.radius.si * args.mu_h.si
        print(f"  with R_L = {args.radius} and mu*H = {args.mu_h}: displacement up to "
              f"{args.radius.show(args.radius.si * float(max(c.delta)))}, force "
              f"{format_in(scale * float(min(c.force)), fu, 'force')} .. {format_in(scale * float(max(c.force)), fu, 'force')}")
    if len(c):
        print(f"  contact topologies along the curve: {c.topology_summary()}")
    if c.interrupted:
        print("shellbvp: interrupted; the file holds the finished points (complete = False)", file=sys.stderr)
        return 130
    return 0 if c.complete else 1


def _strict_json(value):
    """NaN and inf as null (JSON has neither; jq, JavaScript and most parsers refuse them)."""
    import numpy as np

    if isinstance(value, dict):
        return {k: _strict_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict_json(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def _cmd_solve(args):
    import numpy as np

    import shellbvp as sb

    scene = _scene(args)
    given = {k: _nondimensional(args, v, f"--{k}") for k, v in (("delta", args.delta), ("lambda0", args.lambda0),
                                                                ("force", args.load)) if v is not None}
    if not given:
        given = {"delta": 0.2}
    sol = sb.solve(scene, tol=args.tol, max_nodes=args.max_nodes, topology=args.topology, **given)
    keys = ("success", "status", "message", "topology", "delta", "force", "lambda0", "S1", "Sc", "pressure",
            "ring_force", "ring_force_inner", "cap_force",
            "pressure_min", "penetration", "valid", "flags", "energy", "force_defect", "force_error",
            "delta_error", "nodes", "niter", "max_residual", "wall_time")
    if scene.transverse_shear:  # the thick shell's pole is at delta + shear_delta
        keys = keys[:5] + ("shear_delta",) + keys[5:]
    out = {k: getattr(sol, k) for k in keys}
    out = {k: (float(v) if isinstance(v, (np.floating,)) else v) for k, v in out.items()}
    if (args.radius is None) != (args.mu_h is None):
        raise ValueError("--radius and --muH go together (rim radius, e.g. 0.3mm, and mu*H, e.g. 52N/m)")
    shown = {}
    if args.radius is not None:  # the state in the units given: displacement R_L delta, force mu_H R_L F
        from .units import force_unit_of, format_in

        out["displacement_m"] = args.radius.si * sol.delta
        out["force_N"] = args.mu_h.si * args.radius.si * sol.force
        shown = {"displacement": args.radius.show(out["displacement_m"]),
                 "force (SI)": format_in(out["force_N"], force_unit_of(args.mu_h.unit), "force")}
    if args.profiles and sol.success:
        out["profile"] = {k: np.asarray(v).tolist() for k, v in sol.profile().items()}
    if args.json:
        print(json.dumps(_strict_json(out), allow_nan=False))
    else:
        for k in keys:
            print(f"{k:>16s}: {out[k]}")
        for k, v in shown.items():
            print(f"{k:>16s}: {v}")
        if args.profiles and sol.success:
            prof = sol.profile()
            cols = ("S", "region", "r", "z", "lambda_s", "lambda_theta", "kappa_s", "kappa_theta",
                    "M_s", "Q", "P")
            print(" ".join(f"{c:>13s}" for c in cols))
            for i in range(prof["S"].size):
                print(" ".join(f"{prof[c][i]:13.6g}" for c in cols))
    return 0 if sol.success else 1


def _split_uncertain(args):
    """``VALUE+-U`` options of ``fit``: the values go to the scene; returns {name: U}."""
    uncertainty = {}
    for name in ("gamma", "rho", "beta", "alpha"):
        given = getattr(args, name)
        if isinstance(given, tuple):
            setattr(args, name, given[0])
            if given[1] is not None:
                uncertainty[name] = given[1]
    if (args.workers is not None or args.scheduler) and not uncertainty:
        raise ValueError("--workers and --scheduler run the fits of an uncertain geometry: give a parameter "
                         "as VALUE+-U (e.g. --rho 0.333+-0.02)")
    if args.scheduler and args.workers is not None:
        raise ValueError("--workers sets the local pool; with --scheduler the cluster has its own workers")
    return uncertainty


def _fit_inputs(args):
    """The scene, R_L and the reading and fitting options of ``fit``, checked before any work."""
    _require_sample(args)
    scene = _scene(args)
    units = None
    if args.units:
        parts = [u.strip() for u in args.units.split(",")]
        if len(parts) not in (2, 3):
            raise ValueError(f"--units must be two units, displacement and force (and a third for time), "
                             f"e.g. mm,mN; got {args.units!r}")
        units = tuple(parts)
    columns = [c.strip() for c in args.columns.split(",")] if args.columns else None
    if columns is not None and len(columns) not in (2, 3):
        raise ValueError(f"--columns must name two columns (displacement, force) or three (and time); "
                         f"got {args.columns!r}")
    free = tuple(name for name in SHAPE_PARAMETERS if getattr(args, f"fit_{name}"))
    bounds = {}
    for name, param in SHAPE_PARAMETERS.items():
        text = getattr(args, f"{name}_range")
        if text is not None:
            bounds[name] = _search_range(param, text, args.radius.si)
            if name not in free:
                raise ValueError(f"--{name}-range needs --fit-{name}")
    options = {"fit_offset": not args.no_offset, "free": free, "bounds": bounds, "weights": args.weights,
               "tol": args.tol}
    return scene, args.radius.si, {"columns": columns, "units": units, "invert": tuple(args.invert or ())}, options


def _search_range(param, text, R_L):
    """``--NAME-range LOW,HIGH`` as the nondimensional bounds of the shape parameter ``param``:
    plain numbers as they are; with a unit (a parameter with a lab unit, e.g. 20um) through R_L."""
    from .units import Quantity, plain_number, split_quantity

    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        values = []
        for part in parts:
            if param.unit_kind and split_quantity(part, param.unit_kind, f"--{param.name}-range")[1]:
                values.append(Quantity.parse(part, param.unit_kind, f"--{param.name}-range").si
                              / param.report_scale(R_L))
            else:
                values.append(plain_number(part, f"--{param.name}-range"))
    except ValueError:
        unit = f" (plain, or with a {param.unit_kind} unit)" if param.unit_kind else ""
        raise ValueError(f"--{param.name}-range must be two numbers LOW,HIGH{unit}; got {text!r}") from None
    return tuple(values)


def _cmd_fit(args):
    """``shellbvp fit``: exit 0 (fit succeeded; warnings allowed), 1 (the fit ran but failed its
    checks) or 2 (bad input: a ValueError, one line on stderr).  With ``--json`` stdout holds
    exactly one JSON document in every case (errors: see :func:`main`).  Several files (or a
    directory, a pattern, or ``--table``): a batch, see :func:`_fit_batch`; an AFM force map: every
    curve into a map, see :func:`_fit_map`."""
    if args.example == bool(args.data):
        raise ValueError("give data files (or a directory) or --example (one of them)")
    if len(args.data) == 1 and not any(ch in args.data[0] for ch in "*?[") and not Path(args.data[0]).exists():
        raise ValueError(f"{args.data[0]}: no such file or directory")  # before the numerics are imported
    from .afm import is_afm_file, read_afm
    from .batch import expand_inputs, read_record
    from .fitting import example_data_path, fit_record
    from .paths import check_output_path

    inputs = [str(example_data_path())] if args.example else args.data
    files = expand_inputs(inputs)
    uncertainty = _split_uncertain(args)
    folder = any(Path(x).is_dir() for x in inputs)
    map_curves = None
    if len(files) == 1 and not folder and is_afm_file(files[0]):
        _require_sample(args)  # its one-line error before the file is read
        curves = read_afm(files[0])
        if len(curves) > 1:  # a force map: every curve, into a map
            if uncertainty:
                raise ValueError("VALUE+-U (the geometry's uncertainty) is for one curve, not a force map")
            map_curves = curves
    if map_curves is None and (len(files) > 1 or args.table or folder):
        if uncertainty:
            raise ValueError("VALUE+-U (the geometry's uncertainty) is for one file at a time, not a batch")
        return _fit_batch(args, files)
    if args.output is not None:
        check_output_path(args.output, overwrite=args.force)
    if args.report is not None:
        _check_report_path(args.report, overwrite=args.force)
    scene, R_L, reading, options = _fit_inputs(args)
    options["progress"] = _curve_bars(args)
    if map_curves is not None:
        return _fit_map(args, files[0], map_curves, scene, R_L, reading, options)
    record = read_record(files[0], **reading)
    res, used = fit_record(scene, record, R_L=R_L, segment=args.segment, baseline=args.baseline, **options)
    geometry = None
    if uncertainty and res.success:
        from .sweep import dask_executor
        from .uncertainty import fit_with_geometry

        # the same rows, baseline model and contact point as the nominal fit, at each perturbed geometry
        kw = {k: v for k, v in options.items() if k != "progress"}
        executor = dask_executor(args.scheduler) if args.scheduler else None
        geometry = fit_with_geometry(scene, record.displacement[used], record.force[used], R_L=R_L,
                                     uncertainty=uncertainty, executor=executor, workers=args.workers,
                                     baseline=res.baseline_model, contact_guess=res.offset, **kw)
    out = res.to_dict()
    ok = res.success and (geometry is None or geometry.success)
    if geometry is not None:
        out["geometry"] = geometry.to_dict()
        out["success"] = ok
    out["exit_status"] = 0 if ok else 1
    if args.json:
        print(json.dumps(_strict_json(out), allow_nan=False))
    else:
        _print_fit(res, record, used, args)
        if geometry is not None:
            if not geometry.success:
                print(f"fit with the geometry's uncertainty failed: {geometry.message}")
            g1, g2 = geometry.mu_H_ci95
            print(f"geometry = mu*H 95% CI [{g1:.4g}, {g2:.4g}] N/m with the geometry's uncertainty "
                  f"(u = {geometry.u_geometry:.3g} N/m; {geometry.fits_computed} fits)")
            print(geometry.table())
    if args.output or args.report:
        if not res.success:
            print(f"shellbvp: not writing {args.output or args.report}: the fit failed its checks", file=sys.stderr)
        else:
            _save_fit(res, record, used, args.output, args.report, args.segment, args.force, args.json)
    return 0 if ok else 1


def _output_dir(path, what, files, suffix, force):
    """A directory for one output per file (created if its parent exists); names checked now."""
    from .paths import check_output_path

    d = Path(path)
    if d.exists() and not d.is_dir():
        raise ValueError(f"{what} {path}: with several files it must be a directory (one file each)")
    if not d.exists():
        if not d.parent.is_dir():
            raise ValueError(f"{what} {path}: its parent directory does not exist")
        d.mkdir()
    stems = [Path(f).stem for f in files]
    twice = sorted({s for s in stems if stems.count(s) > 1})
    if twice:
        raise ValueError(f"{what}: several input files are named {twice[0]!r} (their outputs would collide); "
                         "fit them in separate calls")
    for stem in stems:
        check_output_path(d / f"{stem}{suffix}", overwrite=force)
    return d


def _fit_batch(args, files):
    """``shellbvp fit A B ... [--table results.csv] [-o DIR] [--report DIR]``: every file with
    the same scene and settings, one row each (status ok, failed or error), continuing past
    a file that fails; exit 0 when every file was fitted, 1 otherwise."""
    from .batch import fit_files, write_table
    from .paths import check_output_path

    if args.table is not None:
        check_output_path(args.table, overwrite=args.force)
    outdir = _output_dir(args.output, "-o", files, ".h5", args.force) if args.output else None
    repdir = _output_dir(args.report, "--report", files, ".pdf", args.force) if args.report else None
    scene, R_L, reading, options = _fit_inputs(args)
    options["progress"] = _curve_bars(args, leave=False)
    bar = _progress_bar(len(files), "file", args)

    def step(row):
        bar.update(1)
        bar.set_postfix_str(f"{Path(row.file).name}: {row.status}")

    try:
        rows = fit_files(scene, files, R_L=R_L, segment=args.segment, baseline=args.baseline, on_file=step,
                         **reading, **options)
    finally:
        bar.close()
    for row in rows:
        if row.status == "ok" and (outdir or repdir):
            stem = Path(row.file).stem
            _save_fit(row.result, row.record, row.used, outdir / f"{stem}.h5" if outdir else None,
                      repdir / f"{stem}.pdf" if repdir else None, args.segment, args.force, True)
    if args.table is not None:
        write_table(args.table, rows, args.segment, overwrite=args.force)
    ok = all(r.status == "ok" for r in rows)
    if args.json:
        docs = [{"file": r.file, "status": r.status, "message": r.message,
                 **(r.result.to_dict() if r.result is not None else {})} for r in rows]
        print(json.dumps(_strict_json({"files": docs, "success": ok, "exit_status": 0 if ok else 1}),
                         allow_nan=False))
    else:
        width = max(len(r.file) for r in rows)
        for r in rows:
            if r.result is not None and r.status != "error":
                lo, hi = r.result.mu_H_ci95
                text = f"mu*H = {r.result.mu_H:.4g} N/m  95% CI [{lo:.4g}, {hi:.4g}]"
                if r.result.warnings:
                    text += f"  ({len(r.result.warnings)} warning{'s' * (len(r.result.warnings) > 1)})"
            else:
                text = r.message
            _say(f"{r.file:<{width}}  {r.status:<6s}  {text}")
        n_ok = sum(r.status == "ok" for r in rows)
        print(f"{n_ok} of {len(rows)} files fitted" + (f"; table: {args.table}" if args.table else ""))
    return 0 if ok else 1


def _fit_map(args, path, curves, scene, R_L, reading, options):
    """``shellbvp fit MAP.jpk-force-map [-o map.h5] [--table map.csv] [--report map.png]``: every
    curve with the same scene; exit 0 when every curve was fitted, 1 otherwise."""
    from .afm import refuse_text_options
    from .batch import fit_map, write_table
    from .paths import check_output_path

    refuse_text_options(path, **reading)
    if args.table is not None:
        check_output_path(args.table, overwrite=args.force)
    options = dict(options, progress=_curve_bars(args, leave=False))
    bar = _progress_bar(len(curves), "curve", args)

    def step(row):
        bar.update(1)
        bar.set_postfix_str(row.status)

    try:
        fm = fit_map(scene, curves, R_L=R_L, path=path, segment=args.segment, baseline=args.baseline,
                     on_curve=step, **options)
    finally:
        bar.close()
    ok = all(r.status == "ok" for r in fm.rows)
    if args.table is not None:
        write_table(args.table, fm.rows, args.segment, overwrite=args.force)
    if args.output is not None:
        fm.to_hdf5(args.output, overwrite=args.force)
    if args.report is not None:
        fm.plot(args.report)
    wrote = [w for w in (args.table, args.output, args.report) if w is not None]
    if args.json:
        docs = [{"file": r.file, "grid_index": list(c.grid), "status": r.status, "message": r.message,
                 **(r.result.to_dict() if r.result is not None else {})} for c, r in zip(fm.curves, fm.rows)]
        print(json.dumps(_strict_json({"map": str(path), "shape": list(fm.shape), "curves": docs, "success": ok,
                                       "exit_status": 0 if ok else 1}), allow_nan=False))
        for w in wrote:
            print(f"wrote {w}", file=sys.stderr)
    else:
        _say(f"data   = {path}: a force map of {len(curves)} curves; fitted the {args.segment} segment of each")
        _say(f"scene  = {scene.describe(R_L)}")
        _say(f"map    = {fm.summary()}")
        for w in wrote:
            _say(f"wrote {w}")
    return 0 if ok else 1


def _save_fit(res, record, used, output, report, segment, force, quiet_stdout=False):
    """The fit's record (HDF5) and its one-page report (PNG/PDF), as asked (with --json the
    'wrote' lines go to stderr: stdout holds the one JSON document)."""
    import os
    import tempfile

    from .fitrecord import read_fit, write_fit

    if output:
        write_fit(output, res, record, used, segment=segment, overwrite=force)
        print(f"wrote {output}", file=sys.stderr if quiet_stdout else sys.stdout)
    if report:
        from .plotting import fit_report

        if output:
            fit_report(read_fit(output), report)
        else:  # the report alone: the record goes through a temporary file
            fd, tmp = tempfile.mkstemp(suffix=".h5")
            os.close(fd)
            try:
                write_fit(tmp, res, record, used, segment=segment, overwrite=True)
                fit_report(read_fit(tmp), report)
            finally:
                os.unlink(tmp)
        print(f"wrote {report}", file=sys.stderr if quiet_stdout else sys.stdout)


def _print_fit(res, record, used, args):
    """The fit in words, in the data's own units (and mu*H in N/m)."""
    from .units import format_in

    du, fu = record.units["displacement"], record.units["force"]
    if not res.success:
        _say(f"fit failed (status {res.status}): {res.message}")
    counts = ", ".join(f"{k} {v}" for k, v in record.counts().items())
    name = Path(record.path).name if args.example else record.path
    _say(f"data   = {name}: {len(record)} rows ({counts}); fitted the {args.segment} segment, "
          f"{int(used.sum())} rows")
    _say(f"scene  = {res.scene.describe(res.R_L)}")
    lo, hi = res.mu_H_ci95
    _say(f"mu*H   = {res.mu_H:.4g} N/m (um*MPa)   95% CI [{lo:.4g}, {hi:.4g}]")
    for e in res.derived.values():
        if e.of is None:  # from a given scene value (mu of a given thickness)
            _say(_estimate_line(e))
    if res.thickness is not None:
        from .thickness import model_error_line

        _say(model_error_line(res.scene))
    show = (lambda v, unit, kind: format_in(v, unit, kind).split(" ")[0])
    if "offset" in res.fitted:
        o1, o2 = res.offset_ci95
        _say(f"offset = {format_in(res.offset, du, 'length')}   95% CI [{show(o1, du, 'length')}, "
              f"{show(o2, du, 'length')}] {du} (the contact point)")
    if res.baseline_model != "none":
        b1, b2 = res.baseline_ci95
        _say(f"baseline = {format_in(res.baseline, fu, 'force')}   95% CI [{show(b1, fu, 'force')}, "
              f"{show(b2, fu, 'force')}] {fu} ({res.baseline_model})")
    if res.baseline_model == "linear":
        s1, s2 = res.baseline_slope_ci95
        _say(f"baseline slope = {res.baseline_slope:.4g} N/m   95% CI [{s1:.4g}, {s2:.4g}]")
    for name, param in SHAPE_PARAMETERS.items():
        if name in res.fitted:
            v, (c1, c2) = res.shape_values[name], res.shape_ci95[name]
            if param.display_unit:
                unit = param.display_unit
                value = format_in(v, unit, param.unit_kind)
                interval = f"[{show(c1, unit, param.unit_kind)}, {show(c2, unit, param.unit_kind)}] {unit}"
            else:
                value, interval = f"{v:.4g}", f"[{c1:.4g}, {c2:.4g}]"
            _say(f"{name:<6s} = {value}   95% CI {interval} (profile likelihood; {res.curves_computed} model "
                 f"curves){param.note}")
            for e in res.derived.values():
                if e.of == name:
                    _say(_estimate_line(e))
    _say(f"rms residual = {format_in(res.residual_rms, fu, 'force')} over {res.n} points; R_L = "
          f"{args.radius}; {res.weights} weights")
    from .fitting import diagnostics_lines

    for line in diagnostics_lines(res.quality, res.fitted, res.correlation,
                                  {k: getattr(res, k) for k in ("noise_sigma", "aic", "bic", "runs_p",
                                                                "residual_autocorrelation")},
                                  lambda v: format_in(v, fu, "force")):
        _say(line)
    for text in res.warnings:
        _say(f"warning: {text}")


def _estimate_line(e):
    """A line of a quantity a fit reports in lab units (``FitResult.derived``)."""
    from .units import unit_factor, unit_kind

    f = unit_factor(e.display_unit, unit_kind(e.display_unit))
    c1, c2 = e.ci95
    return f"{e.label:<6s} = {e.value / f:.4g} {e.display_unit}   95% CI [{c1 / f:.4g}, {c2 / f:.4g}] ({e.note})"


def _check_report_path(path, overwrite):
    from .paths import check_output_path

    if not str(path).lower().endswith((".png", ".pdf")):
        raise ValueError(f"--report must name a .png or .pdf file; got {path!r}")
    return check_output_path(path, overwrite=overwrite)


def _cmd_report(args):
    """``shellbvp report FIT.h5 [-o FIT.pdf]``: the one-page summary of a fit file."""
    from .fitrecord import read_fit
    from .plotting import fit_report, require_matplotlib

    out = args.output or str(Path(args.file).with_suffix(".pdf"))
    _check_report_path(out, overwrite=args.force)
    require_matplotlib()
    fit_report(read_fit(args.file), out)
    print(f"wrote {out}")
    return 0


def _cmd_plot(args):
    from .fitrecord import is_fit_file, read_fit
    from .io import read_curve
    from .paths import check_output_path
    from .plotting import plot_curves, plot_fit_record, plot_profiles, require_matplotlib, save_figure, scene_label
    from .sweep import is_sweep_file, read_sweep

    fits = [f for f in args.files if is_fit_file(f)]
    if fits:
        if len(fits) != len(args.files):
            raise ValueError("plot either curve files or fit files, not both in one call")
        if args.output is None:  # each figure next to its fit file
            outs = [Path(name).with_suffix(".png") for name in fits]
        elif len(fits) > 1 or Path(args.output).is_dir():
            outdir = _output_dir(args.output, "-o", fits, ".png", True)
            outs = [outdir / (Path(name).stem + ".png") for name in fits]
        else:
            outs = [Path(args.output)]
        plt = require_matplotlib()
        for name, out in zip(fits, outs):
            check_output_path(out, overwrite=True)
            ax, _ = plot_fit_record(read_fit(name))
            ax.figure.tight_layout()
            try:
                save_figure(ax.figure, out, dpi=args.dpi)
            finally:
                plt.close(ax.figure)
            print(f"wrote {out}")
        return 0
    args.output = "curves.png" if args.output is None else args.output
    check_output_path(args.output, overwrite=True)  # a figure is cheap to redraw: replaced
    plt = require_matplotlib()
    curves, labels = [], []
    for name in args.files:
        if is_sweep_file(name):  # a family: one curve per finished combination, labelled by its values
            sw = read_sweep(name)
            for i, c in sorted(sw.curves.items()):
                curves.append(c)
                labels.append(" ".join(f"{p}={sw.index[p][i]:.4g}" for p in sw.parameters))
        else:
            curves.append(read_curve(name))
            labels.append(scene_label(curves[-1].scene))
    if not curves:
        raise ValueError(f"{', '.join(args.files)}: no finished curve to plot")
    deltas = _numbers(args.profiles, "--profiles") if args.profiles else []
    ncol = 2 if deltas else 1
    fig, axes = plt.subplots(1, ncol, figsize=(6 * ncol, 4.8), squeeze=False)
    plot_curves(curves, ax=axes[0, 0], labels=labels)
    if deltas:
        for d in deltas:
            if not d > 0:
                raise ValueError(f"--profiles depths must be > 0; got {d}")
        plot_profiles(curves[0].scene, deltas, ax=axes[0, 1])
    fig.tight_layout()
    save_figure(fig, args.output, dpi=args.dpi)
    print(f"wrote {args.output}")
    return 0


MAX_SWEEP_VALUES = 10_000  # values of one swept parameter: more is a typo, not a grid


def _sweep_values(text, name):
    """Values of a swept parameter: ``a,b,c``, ``lo:hi:n`` (n equally spaced) or ``lo:hi:n:log``
    (n spaced evenly in log), each number plain decimal text (nothing is evaluated)."""
    import numpy as np

    from .units import plain_number

    parts = text.split(":")
    if len(parts) == 1:
        return [plain_number(v, name) for v in text.split(",")]
    if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "log"):
        raise ValueError(f"{name} must be a list a,b,c or a range LOW:HIGH:N[:log]; got {text!r}")
    lo, hi = plain_number(parts[0], name), plain_number(parts[1], name)
    if not parts[2].strip().isdigit() or not 1 <= int(parts[2]) <= MAX_SWEEP_VALUES:
        raise ValueError(f"{name}: N of LOW:HIGH:N must be an integer in [1, {MAX_SWEEP_VALUES}]; got {parts[2]!r}")
    n = int(parts[2])
    if len(parts) == 4:
        if not (lo > 0 and hi > 0):
            raise ValueError(f"{name}: a log range needs LOW, HIGH > 0; got {text!r}")
        return np.geomspace(lo, hi, n).tolist()
    return np.linspace(lo, hi, n).tolist()


def _cmd_sweep(args):
    """``shellbvp sweep``: exit 0 every curve complete, 1 some stopped early, failed or were lost
    (the index says which), 2 bad input, 130 interrupted (the file keeps the finished curves)."""
    import shellbvp as sb

    from .sweep import check_grid, dask_executor, sweep

    grid = {}
    for name, text in (("beta", args.beta), ("rho", args.rho), ("gamma", args.gamma), ("alpha", args.alpha),
                       ("Jm", args.gent_jm), ("pressure", args.pressure)):  # the grid's axes in this order
        if text is not None:
            grid[name] = _sweep_values(text, f"--{'gent-jm' if name == 'Jm' else name}")
    if not grid:
        raise ValueError("give at least one of --gamma, --rho, --beta, --alpha, --gent-jm, --pressure to sweep")
    over = {k: getattr(args, k) for k in ("xi", "contact") if getattr(args, k) is not None}
    if args.gent_jm is not None:
        over["material"] = sb.Gent(grid["Jm"][0])
    elif args.neo_hookean:
        over["material"] = sb.NeoHookean()
    elif args.material is not None:
        over["material"] = args.material
    base = sb.Scene.preset(args.preset, **over)
    check_grid(base, grid, args.max_cells)  # before a scheduler is asked for anything
    settings = {"tol": args.tol, "max_nodes": args.max_nodes, "max_steps": args.max_steps, "topology": args.topology}
    if args.points is not None:
        if not 2 <= args.points <= MAX_POINTS:
            raise ValueError(f"--points must be in [2, {MAX_POINTS}]; got {args.points}")
        settings["deltas"] = [args.delta_max * (i + 1) / args.points for i in range(args.points)]
    if args.scheduler is not None and args.workers is not None:
        raise ValueError("--workers sets the local pool; with --scheduler the cluster has its own workers")
    executor = dask_executor(args.scheduler) if args.scheduler is not None else None  # '' is an error, not local

    def progress(rec, done, total):
        if not args.quiet:
            what = rec["status"] + (f", {len(rec['points']['delta'])} points" if "points" in rec else "")
            print(f"  [{done}/{total}] curve {rec['index']}: {what}, {rec['wall_time']:.1f} s"
                  + (f" ({rec['message']})" if rec["message"] else ""), file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    res = sweep(base, grid, delta_max=args.delta_max, executor=executor, out=args.output, workers=args.workers,
                extend=args.extend, restart=args.force, progress=progress, max_cells=args.max_cells, **settings)
    counts = ", ".join(f"{v} {k}" for k, v in res.counts().items())
    print(f"wrote {args.output}: {res.status.size} combinations ({counts}); {res.computed} curves computed "
          f"in {time.perf_counter() - t0:.1f} s" + (f"; {res.lost} lost (still pending)" if res.lost else ""))
    return 0 if res.counts() == {"complete": res.status.size} else 1


def _sweep_info(path):
    import numpy as np

    from .sweep import read_sweep

    sw = read_sweep(path)
    s = sw.base_scene
    _say(f"file:      {path} (shellbvp sweep)")
    _say(f"base:      gamma={s.gamma:g} rho={s.rho:g} beta={s.beta:g} xi={s.xi} contact={s.contact} "
          f"material={s.material!r}")
    for name in sw.parameters:
        _say(f"sweeps:    {name} = {', '.join(f'{v:g}' for v in sw.values[name])}")
    _say(f"settings:  delta_max={sw.delta_max:g} {json.dumps(sw.settings, sort_keys=True)}")
    counts = ", ".join(f"{v} {k}" for k, v in sw.counts().items())
    wall = np.asarray(sw.index["wall_time"], float)
    done = np.isfinite(wall)
    _say(f"curves:    {len(sw.index['status'])} combinations: {counts}")
    if np.any(done):
        _say(f"time:      {np.sum(wall[done]):.1f} s of curves in workers; slowest {np.max(wall[done]):.1f} s, "
              f"median {np.median(wall[done]):.1f} s")
    head = " ".join(f"{n:>10s}" for n in sw.parameters)
    _say(f"{head} {'status':>9s} {'points':>6s} {'delta_end':>9s} {'F_end':>10s} {'time(s)':>8s}  stop reason")
    for i, st in enumerate(sw.index["status"]):
        c = sw.curves.get(i)
        end = (f"{c.delta[-1]:9.4g} {c.force[-1]:10.5g}" if c is not None and len(c) else f"{'':9s} {'':10s}")
        why = sw.index["stop_reason"][i] or sw.index["message"][i]
        _say(" ".join(f"{sw.index[n][i]:10.5g}" for n in sw.parameters)
              + f" {st:>9s} {int(sw.index['points'][i]):6d} {end} {float(sw.index['wall_time'][i]):8.2f}  {why}")
    return 0


def _cmd_convexity(args):
    """``shellbvp convexity``: where the scene's energy is convex in stretch and curvature."""
    from .convexity import convexity_report

    print(convexity_report(_scene(args)))
    return 0


def _cmd_info(args):
    import numpy as np

    from .fitrecord import is_fit_file, read_fit
    from .io import read_curve
    from .sweep import is_sweep_file

    if is_fit_file(args.file):
        from .plotting import fit_summary_lines

        _say(f"file:      {args.file} (a fit)")
        for line in fit_summary_lines(read_fit(args.file)):
            _say(f"  {line}")
        return 0
    if os.path.isfile(args.file) and is_sweep_file(args.file):
        return _sweep_info(args.file)
    c = read_curve(args.file)
    s = c.scene
    mat = s.material
    _say(f"file:      {args.file} (shellbvp {c.version})")
    _say(f"scene:     gamma={s.gamma:g} rho={s.rho:g} beta={s.beta:g} xi={s.xi} contact={s.contact} "
          f"material={mat!r} bending={s.bending!r} shell={s.shell!r} tip={s.tip!r}"
          + (f" pressure={s.pressure:g} (delta from the inflated pole)" if s.pressure else "")
          + (" sealed (volume control: the pressure is per point)" if s.sealed else ""))
    _say(f"curve:     {c.summary()}")
    _say(f"complete:  {c.complete}  interrupted: {c.interrupted}")
    res = c.energy_residual
    if np.any(np.isfinite(res)):
        _say(f"energy identity: max |dE/ddelta - F| = {np.nanmax(np.abs(res)):.3g}")
    if len(c):
        _say(f"topology:  {c.topology_summary()}")
        _say(f"{'delta':>10s} {'force':>12s} {'lambda0':>9s} {'S1':>10s} {'Sc':>10s} {'topology':>8s} "
              f"{'status':>6s} {'valid':>5s}" + (f" {'pressure':>10s}" if s.sealed else ""))
        for i in range(len(c)):
            _say(f"{c.delta[i]:10.5f} {c.force[i]:12.6g} {c.lambda0[i]:9.5f} {c.S1[i]:10.4g} {c.Sc[i]:10.4g} "
                  f"{c.topology[i]:>8s} {int(c.status[i]):6d} {str(bool(c.valid[i])):>5s}"
                  + (f" {c.points['pressure'][i]:10.5g}" if s.sealed else ""))
    return 0


def _cmd_presets(args):
    from .scene import PRESETS

    for name, p in PRESETS.items():
        sc = p["scene"]
        shape = (f"shell=R,Z,L=({', '.join(sc['shell'])})" if isinstance(sc.get("shell"), tuple)
                 else f"gamma={sc['gamma']:<5g}")
        extra = f" pressure={sc['pressure']:g}" if sc.get("pressure") else ""
        extra += " sealed" if sc.get("sealed") else ""
        print(f"{name:9s} {shape} rho={sc['rho']:<7.4g} beta={sc['beta']:<6g} "
              f"xi={sc['xi']} material={sc['material']!r}{extra}  -- {p['doc']}")
    return 0


def _cmd_validate(args):
    import time

    from .validation import validate

    scene = _scene(args)
    if scene.thickness is None:
        raise ValueError("validate needs --thickness (H/R_L, or with a unit and --radius)")
    if scene.pressurised:
        raise ValueError("validate: the 3D model has no internal pressure yet; use a scene without --pressure")
    if not (0 < args.delta_max <= 2):
        raise ValueError(f"--delta-max must be in (0, 2]; got {args.delta_max:g}")
    deltas = None
    if args.deltas:
        deltas = _numbers(args.deltas, "--deltas")
        if any(not 0 < d <= 2 for d in deltas) or any(b <= a for a, b in zip(deltas, deltas[1:])):
            raise ValueError("--deltas must be increasing pole displacements in (0, 2]")
    from .paths import check_output_path

    out = check_output_path(args.output if args.output is not None
                            else _free_default_name(f"{args.preset or 'base'}-validate", args.force), overwrite=args.force)
    try:
        import felupe  # noqa: F401
    except ImportError:
        raise ValueError("validate needs FElupe: pip install 'shellbvp[fe]'") from None
    t0 = time.perf_counter()
    shell = "with its transverse shear" if scene.transverse_shear else "Kirchhoff (no transverse shear)"
    print(f"scene: {args.preset or 'base'}, eps = H/R_L = {scene.thickness:.4g}, beta = {scene.beta:.4g}; "
          f"3D model (FElupe) and shell model, {shell}, at the same pole displacements", flush=True)
    result = validate(scene, deltas=deltas, delta_max=args.delta_max, mesh_check=args.mesh_check, tol=args.tol,
                      progress=lambda i, d, f: print(f"  FE: delta = {d:.4g}, F = {f:.5g}", flush=True))
    print(result.table())
    if not result.fe.success:
        print(f"FE: {result.fe.message}")
    result.to_hdf5(out, overwrite=args.force)
    print(f"wrote {out} ({time.perf_counter() - t0:.1f} s)")
    return 0 if result.fe.success else 1


def _overwrite_option(p, what):
    """``--overwrite`` (``--force`` too, the older name, not shown: scripts keep working)."""
    p.add_argument("--overwrite", action="store_true", dest="force", help=what)
    p.add_argument("--force", action="store_true", dest="force", help=argparse.SUPPRESS)


def build_parser():
    from .version import __version__

    p = _Parser(prog="shellbvp", description="Indentation of thin curved hyperelastic shells.")
    p.add_argument("-v", "--verbose", action="store_true", help="log progress (INFO)")
    p.add_argument("--version", action="version", version=f"shellbvp {__version__}")
    sub = p.add_subparsers(dest="command", parser_class=_Parser)
    c = sub.add_parser("curve", help="compute a force-displacement curve into an HDF5 file")
    _scene_options(c)
    c.add_argument("--delta-max", type=number_or("length"), default=0.5, dest="delta_max",
                   help="largest pole displacement (default 0.5); with a unit (100um) it needs --radius")
    c.add_argument("--points", type=int, help="N equally spaced depths up to delta-max (default: adaptive)")
    c.add_argument("--force-max", type=number_or("force"), dest="force_max",
                   help="stop at this force; with a unit (10mN) it needs --radius and --muH")
    c.add_argument("--lambda0-max", type=_number, dest="lambda0_max", help="stop at this pole stretch")
    c.add_argument("--max-steps", type=int, default=400, dest="max_steps", help="most continuation steps of a curve (default 400)")
    c.add_argument("--profiles", action="store_true", help="store each point's profiles")
    c.add_argument("--radius", "--rim-radius", type=quantity("length"),
                   help="rim radius R_L with its unit, e.g. 0.3mm (with --muH: SI columns in the file)")
    c.add_argument("--muH", type=quantity("mu_H"), dest="mu_h", help="mu*H with its unit, e.g. 52N/m")
    c.add_argument("-o", "--output", help="output file (default <preset>.h5, or <preset>-2.h5, ... if that exists)")
    _overwrite_option(c, "replace an existing output file")
    c.add_argument("-q", "--quiet", action="store_true", help="no progress bar (there is none when stderr is not "
                   "a terminal or tqdm is not installed: pip install 'shellbvp[progress]')")
    c.add_argument("--topology", choices=("auto", "cap"), default="auto",
                   help="auto (default): where the single contact cap would pull the shell, use the valid "
                        "lifted-off (line or annular) contact; cap: single cap only, flagged where invalid")
    c.set_defaults(func=_cmd_curve)
    s = sub.add_parser("solve", help="solve one state and print it")
    _scene_options(s)
    g = s.add_mutually_exclusive_group()
    g.add_argument("--delta", type=number_or("length"),
                   help="pole displacement (default 0.2); with a unit (50um) it needs --radius")
    g.add_argument("--lambda0", type=_number, help="pole stretch")
    g.add_argument("--force", "--load", type=number_or("force"), dest="load",
                   help="indenter force F / (mu H R_L) (force control); with a unit (5mN) it needs --radius and --muH")
    s.add_argument("--radius", "--rim-radius", type=quantity("length"), help="rim radius with its unit, e.g. 0.3mm (with --muH: "
                   "the state also in these units)")
    s.add_argument("--muH", type=quantity("mu_H"), dest="mu_h", help="mu*H with its unit, e.g. 52N/m")
    s.add_argument("--profiles", action="store_true", help="print the fields over S")
    s.add_argument("--json", action="store_true", help="print JSON")
    s.add_argument("--topology", choices=("auto", "cap", "line", "annulus"), default="auto",
                   help="contact topology (default auto: the cap, or a valid lifted-off state where the cap "
                        "would pull the shell)")
    s.set_defaults(func=_cmd_solve)
    f = sub.add_parser("fit", help="fit mu*H (and the contact point) to measured force-displacement data",
                       description="Fit mu*H (and the contact point) to measured force-displacement data. "
                       "Exit status: 0 the fit succeeded (warnings, if any, printed as 'warning: ...'); "
                       "1 the fit ran but failed its checks (e.g. an interval not finite or wider than mu*H); "
                       "2 bad input (one-line message).")
    f.add_argument("data", nargs="*", help="instrument file(s) (CSV/TSV/text: displacement and force, optionally "
                   "time); several files, a directory or a pattern fit each with the same settings (a batch)")
    f.add_argument("--table", help="batch: write one row per file (CSV: file, status, mu*H and its interval, "
                   "offset, baseline, residual, warnings, ...)")
    f.add_argument("--example", action="store_true",
                   help="use the synthetic Lepidium-like data shipped with shellbvp (README)")
    _scene_options(f, uncertain=True, preset_required=True)
    f.add_argument("--workers", type=int, help="with VALUE+-U parameters: local processes for their fits "
                                               "(default: all cores)")
    f.add_argument("--scheduler", help="with VALUE+-U parameters: run their fits on this Dask scheduler")
    f.add_argument("--radius", "--rim-radius", required=True, type=quantity("length"),
                   help="rim radius R_L of the sample with its unit, e.g. 0.3mm")
    f.add_argument("--columns", help="displacement,force columns by name or 0-based index (default 0,1)")
    f.add_argument("--units", help="units of the two columns, e.g. mm,mN (default: from the header)")
    f.add_argument("--invert", action="append", choices=("displacement", "force"),
                   help="flip the sign of a column: an AFM height that falls as the tip goes in "
                        "(displacement), compression recorded as negative (force); may be given twice")
    f.add_argument("--segment", choices=("loading", "retraction", "all"), default="loading",
                   help="rows to fit: loading (default: the approach and the loading, up to the deepest point; "
                        "segments by the direction of the displacement over time), retraction, or all "
                        "(every row, whatever its direction)")
    f.add_argument("--baseline", choices=("auto", "none", "constant", "linear"), default="auto",
                   help="force baseline fitted with the contact point: auto (default: constant when the data "
                        "have an approach before contact, else none), none, constant, linear")
    f.add_argument("--no-offset", action="store_true", dest="no_offset", help="do not fit the contact point")
    for name, param in SHAPE_PARAMETERS.items():  # one of them at most
        f.add_argument(f"--fit-{name}", action="store_true", dest=f"fit_{name}", help=param.fit_help)
        f.add_argument(f"--{name}-range", dest=f"{name}_range", help=param.range_help)
    f.add_argument("--weights", choices=("uniform", "relative", "mixed"),
                   help="noise model: uniform (same force noise everywhere), relative (noise proportional "
                        "to the force) or mixed (both, estimated; the default)")
    f.add_argument("--json", action="store_true", help="print the result as one JSON document (also on errors)")
    f.add_argument("-o", "--output", help="write the fit as a record (HDF5/NeXus: data, model, parameters with "
                   "intervals, weights, warnings, scene, source file and its SHA-256); a batch: a directory "
                   "(one <name>.h5 per file)")
    f.add_argument("--report", help="write a one-page summary of the fit (.png or .pdf); a batch: a directory "
                   "(one <name>.pdf per file)")
    f.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    _overwrite_option(f, "replace an existing output file (record, report, table)")
    f.set_defaults(func=_cmd_fit)
    w = sub.add_parser("sweep", help="one curve per combination of parameter values, into one resumable file",
                       description="One force-displacement curve per combination of the swept values, computed "
                       "in parallel (a local process pool, or a Dask cluster with --scheduler), into one HDF5 file "
                       "that is written after every finished curve. Re-running the same command computes only "
                       "the curves not yet in the file. Values: a,b,c or LOW:HIGH:N (N equally spaced) or "
                       "LOW:HIGH:N:log. Exit status: 0 every curve complete; 1 some stopped early or failed "
                       "(see `shellbvp info`); 2 bad input; 130 interrupted.")
    g = w.add_argument_group("scene (the preset, with the swept parameters replaced)")
    g.add_argument("--preset", default="base", help="built-in scene (see `shellbvp presets`; default base)")
    for name, what in (("gamma", "spheroid aspect parameter"), ("rho", "indenter radius / rim radius"),
                       ("beta", "bending stiffness B/(mu R_L^2)")):
        g.add_argument(f"--{name}", help=f"{what}: values to sweep")
    m = g.add_mutually_exclusive_group()
    m.add_argument("--alpha", help="Mooney-Rivlin alpha: values to sweep")
    m.add_argument("--gent-jm", dest="gent_jm", help="Gent material, Jm values to sweep")
    m.add_argument("--neo-hookean", action="store_true", help="neo-Hookean material")
    m.add_argument("--material", type=_material, metavar="FAMILY[:NAME=VALUE,...]",
                   help=_material_help() + " (the base scene's; not swept)")
    g.add_argument("--pressure", help="pressure below the shell, nondimensional p R_L/(mu H): values to sweep")
    g.add_argument("--xi", type=int, choices=(0, 1), help="1: full generalised tensions; 0: first approximation")
    g.add_argument("--contact", choices=("smooth", "paper"), help="contact-line model (default smooth)")
    w.add_argument("--delta-max", type=_number, default=0.5, dest="delta_max", help="depth of every curve (default 0.5)")
    w.add_argument("--points", type=int, help="N equally spaced depths up to delta-max (default: adaptive)")
    w.add_argument("--tol", type=_number, default=1e-6, help="collocation tolerance (default 1e-6)")
    w.add_argument("--max-nodes", type=int, default=10000, dest="max_nodes", help="largest collocation mesh of a state (default 10000)")
    w.add_argument("--max-steps", type=int, default=400, dest="max_steps", help="most continuation steps of a curve (default 400)")
    w.add_argument("--topology", choices=("auto", "cap"), default="auto",
                   help="auto (default): lifted-off contact where the cap would pull the shell; cap: single cap only")
    w.add_argument("-o", "--output", required=True, help="the sweep file (HDF5); an existing one is resumed")
    w.add_argument("--workers", type=int, help="local worker processes (default: all cores)")
    w.add_argument("--max-cells", type=int, default=10_000, dest="max_cells",
                   help="the most combinations the grid may have (default 10000; checked before any work)")
    w.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786 (needs "
                                       "shellbvp[dask])")
    w.add_argument("--extend", action="store_true", help="add the new combinations of a changed grid to the file")
    _overwrite_option(w, "start the file anew (its curves are discarded once the new file is first written)")
    w.add_argument("-q", "--quiet", action="store_true", help="no line per finished curve")
    w.set_defaults(func=_cmd_sweep)
    pl = sub.add_parser("plot", help="plot curves (and profiles) from HDF5 files (needs matplotlib)")
    pl.add_argument("files", nargs="+", help="curve files (`shellbvp curve`), sweep files (`shellbvp sweep`: one "
                    "curve per finished combination) or fit files (`shellbvp fit -o`: data, model and residuals in "
                    "SI units)")
    pl.add_argument("-o", "--output", help="PNG or PDF (default curves.png; for fit files <name>.png next to "
                    "each); for several fit files a directory (one <name>.png each)")
    pl.add_argument("--profiles", help="also draw the deformed shell of the first file at these depths, e.g. 0.1,0.3")
    pl.add_argument("--dpi", type=int, default=150, help="resolution of a PNG (default 150)")
    pl.set_defaults(func=_cmd_plot)
    rp = sub.add_parser("report", help="one-page summary (PDF or PNG) of a fit file written by `shellbvp fit -o`")
    rp.add_argument("file", help="fit file (HDF5)")
    rp.add_argument("-o", "--output", help="PDF or PNG (default: the fit file's name with .pdf)")
    _overwrite_option(rp, "replace an existing report")
    rp.set_defaults(func=_cmd_report)
    i = sub.add_parser("info", help="describe a curve file or a fit file")
    i.add_argument("file")
    i.set_defaults(func=_cmd_info)
    cv = sub.add_parser("convexity", help="where the scene's energy is convex in stretch and curvature "
                                          "(the Legendre condition; beyond it the contact edge becomes a corner)")
    _scene_options(cv)
    cv.add_argument("--radius", "--rim-radius", type=quantity("length"),
                    help="rim radius with its unit, for the lengths of --indenter-radius, --rise, --thickness")
    cv.set_defaults(func=_cmd_convexity)
    v = sub.add_parser("validate", help="the shell model against a 3D finite-element model of the same scene "
                       "(needs FElupe: pip install 'shellbvp[fe]')")
    _scene_options(v)
    v.add_argument("--delta-max", type=_number, default=0.5, dest="delta_max",
                   help="largest pole displacement (default 0.5); the depths are delta/H = 0.25, 0.5, 1, 2, 5, "
                        "10, 25 below it and delta-max")
    v.add_argument("--deltas", help="these pole displacements instead, comma-separated (/R_L)")
    v.add_argument("--radius", "--rim-radius", type=quantity("length"), help="rim radius with its unit, for --thickness with a unit")
    v.add_argument("--mesh-check", action="store_true", dest="mesh_check",
                   help="also solve the 3D model on a coarser mesh and report the difference (~1.5x the time)")
    v.add_argument("-o", "--output", help="output file (default <preset>-validate.h5, or -2, ... if that exists)")
    _overwrite_option(v, "replace an existing output file")
    v.set_defaults(func=_cmd_validate)
    r = sub.add_parser("presets", help="list the built-in scenes")
    r.set_defaults(func=_cmd_presets)
    return p


def main(argv=None):
    try:
        return _main(argv)
    except KeyboardInterrupt:  # also while the parser is built: no traceback at any moment
        print("shellbvp: interrupted", file=sys.stderr)
        return 130


def _main(argv=None):
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv:
        argv = ["curve"]  # the quick start: the base preset into base.h5
    _Parser.json_errors = "--json" in argv
    args = parser.parse_args(argv)
    if args.command is None:
        args = parser.parse_args(["curve", *argv])
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except (ValueError, FileExistsError, ImportError) as exc:  # ImportError: an optional part missing or refused
        if getattr(args, "json", False):
            _print_json_error(exc)
        from .textdata import printable

        print(f"shellbvp: error: {printable(' '.join(str(exc).split()))}", file=sys.stderr)  # one line, always
        return 2
    except KeyboardInterrupt:
        print("shellbvp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `shellbvp info f.h5 | head`
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
