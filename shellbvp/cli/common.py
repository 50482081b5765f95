"""What the commands share: the parser, number and unit arguments, the scene's options, output names."""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import re
import sys
from pathlib import Path

from .. import progress, units
from ..edge_models import contact_models
from ..geometry import FlatTip, UserShell
from ..materials import BENDINGS, MATERIALS, BendingEnergy, NeoHookean, bending_class, material_class
from ..paths import check_output_path
from ..scene_parameters import scene_parameter, scene_parameters
from ..textdata import printable
from ..units import Quantity, parse_uncertain, split_quantity

__all__ = ["Parser", "print_json_error", "show_code_generation", "plain_number", "plain_numbers", "quantity", "uncertain_value", "pressure_value", "say", "number_or", "thickness_value", "meridian_value", "nondimensional", "add_radius_option", "add_mu_h_option", "material_spec", "material_help", "material_options", "bending_families", "add_scene_options", "scene_from_args", "over_rim_radius", "require_sample", "nondimensional_thickness", "nondimensional_pressure", "checkpoint_seconds", "progress_bar", "curve_bars", "MAX_POINTS", "free_default_name", "strict_json", "output_dir", "check_report_path", "add_overwrite_option",
           "NODE_BUDGET", "node_budget", "add_limit_options", "limits_of", "LIMIT_OPTIONS"]


class Parser(argparse.ArgumentParser):
    json_errors = False  # set by main when --json was asked for: errors are JSON on stdout too

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # a value that starts like a negative number is a value, not an option: `--rise -5um`,
        # `--gamma -1e-3` (argparse's own pattern takes only -5 and -0.5; no option here starts -<digit>)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def parse_known_args(self, args=None, namespace=None):
        # argparse checks a subcommand's required options before its caller reports the unknown
        # ones, so `fit --frobnicate` said only "--radius is required": unknown options first
        required = [a for a in self._actions if a.required]
        if not required:
            return super().parse_known_args(args, namespace)
        for action in required:
            action.required = False
        try:
            namespace, extras = super().parse_known_args(args, namespace)
        finally:
            for action in required:
                action.required = True
        if extras:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        missing = [a for a in required if getattr(namespace, a.dest, None) is None]
        if missing:
            names = ", ".join("/".join(a.option_strings) or a.metavar or a.dest for a in missing)
            self.error(f"the following arguments are required: {names}")
        return namespace, extras

    def error(self, message):  # one line, exit 2 (argparse's own convention)
        if Parser.json_errors:
            print_json_error(message)
        self.exit(2, f"shellbvp: error: {message}\n")


class _CodeGenerationNotes(logging.Handler):
    """The model's INFO lines (code generation: 5-25 s the first time a structure is met) on a
    terminal's stderr, above a progress bar if one is drawn."""

    def emit(self, record):
        line = (f"shellbvp: {record.getMessage()}" if record.levelno == logging.INFO else
                f"{record.levelname} {record.name}: {record.getMessage()}")  # as the root logger's
        tqdm = sys.modules.get("tqdm")
        if tqdm is not None:
            tqdm.tqdm.write(line, file=sys.stderr)
        else:
            print(line, file=sys.stderr, flush=True)


def show_code_generation(args, stream=None):
    """Say on stderr when the equations are derived and their code generated (the wait of a
    first run), unless -v (the log says it), -q, or stderr is not a terminal (logs, tests)."""
    stream = sys.stderr if stream is None else stream
    if getattr(args, "verbose", False) or getattr(args, "quiet", False) or not stream.isatty():
        return
    log = logging.getLogger("shellbvp.model")
    if not any(isinstance(h, _CodeGenerationNotes) for h in log.handlers):
        log.addHandler(_CodeGenerationNotes(logging.INFO))
    log.setLevel(logging.INFO)
    log.propagate = False  # its warnings are written by the handler above, once


def print_json_error(message):
    """The one JSON document of a --json run that stopped on bad input (exit status 2)."""
    print(json.dumps({"success": False, "status": None, "exit_status": 2, "message": str(message),
                      "warnings": [], "warning_codes": []}))


def os_error_line(exc: OSError) -> str:
    """One line for a file that could not be written or read (a full disk, a read-only folder)."""
    text = exc.strerror or str(exc)
    return " ".join((f"{text}: {exc.filename}" if exc.filename else text).split())


def plain_number(text):
    """argparse type: a plain finite number (float() would also take 5_0, inf, nan, 1e999)."""
    try:
        return units.plain_number(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def plain_numbers(text, name):
    """Comma-separated plain finite numbers of an option."""
    return [units.plain_number(v, name) for v in text.split(",")]


def quantity(kind, positive=True):
    """argparse type: a quantity with its unit (``0.3mm``, ``52N/m``), > 0 (``positive``; else
    any finite value, ``-5um``); a bare number is an error that says which unit to add.  Every
    subcommand takes dimensional options this way."""
    def parse(text):
        try:
            return Quantity.parse(text, kind, "the value", positive=positive)  # argparse names the option
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = f"{kind} with a unit"
    return parse


def uncertain_value(text):
    """argparse type: ``VALUE`` or ``VALUE+-U`` (plain numbers) -> (value, U or None)."""
    try:
        return parse_uncertain(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def pressure_value(text):
    """argparse type: a plain number (``p R_L/(mu H)``) or a pressure with its unit (``0.2MPa``)."""
    try:
        if split_quantity(text, "pressure", "the value")[1]:
            return Quantity.parse(text, "pressure", "the value", positive=False)
        return units.plain_number(text, "the value")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def say(line=""):
    """Print a line that may hold text from a file or a user: control characters escaped
    (shellbvp.textdata), so that a file cannot drive the terminal or forge a result line."""
    print(printable(line))


def number_or(kind):
    """argparse type: a plain number (nondimensional) or a quantity with its unit (``50um``,
    ``10mN``), which :func:`nondimensional` turns into the model's units."""
    def parse(text):
        try:
            if split_quantity(text, kind, "the value")[1]:
                return Quantity.parse(text, kind, "the value")
            return units.plain_number(text, "the value")
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = f"number or {kind}"
    return parse


thickness_value = number_or("length")  # eps = H / R_L, or the thickness with its unit


def meridian_value(text):
    """``--meridian 'R; Z; L'``: the three formulas' text (parsed by the scene's whitelist later)."""
    parts = [part.strip() for part in text.split(";")]
    if len(parts) != 3 or not all(parts):
        raise argparse.ArgumentTypeError(f"give three formulas 'R(S); Z(S); L' separated by ';'; got {len(parts)} "
                                         f"part{'s' if len(parts) != 1 else ''} in {printable(text)!r}")
    return tuple(parts)


def nondimensional(args, value, option):
    """``value`` of ``option`` in the model's units: a plain number as it is; a length over the rim
    radius (``--radius``), a force over mu*H times it (``--muH`` too)."""
    if not isinstance(value, Quantity):
        return value
    if value.kind == "length":
        if args.radius is None:
            raise ValueError(f"{option} {value} needs --radius (the rim radius, e.g. 0.3mm), or give it in "
                             f"rim radii (a plain number)")
        return value.si / args.radius.si
    missing = [name for name, given in (("--radius", args.radius), ("--muH", getattr(args, "mu_h", None)))
               if given is None]
    if missing:
        raise ValueError(f"{option} {value} needs --radius and --muH (e.g. 0.3mm and 52N/m; missing "
                         f"{' and '.join(missing)}), or give it in mu*H R_L (a plain number)")
    return value.si / (args.mu_h.si * args.radius.si)


def add_radius_option(p, what):
    """``--radius`` (``--rim-radius``): the rim radius R_L with its unit, the length scale of the
    options given in lab units (``what`` says which)."""
    p.add_argument("--radius", "--rim-radius", type=quantity("length"),
                   help=f"rim radius R_L with its unit, e.g. 0.3mm ({what})")


def add_mu_h_option(p, what):
    """``--muH``: mu*H with its unit, the force scale (with ``--radius``) of ``what``."""
    p.add_argument("--muH", type=quantity("mu_H"), dest="mu_h", help=f"mu*H with its unit, e.g. 52N/m ({what})")


def material_spec(text):
    """argparse type: ``FAMILY[:NAME=VALUE,...]`` (``--material yeoh:c2=0.1,c3=0.01``), a registered
    material's family and its parameters by the names files use; read as data, never run."""
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
            values[name] = units.plain_number(value, f"{family}: {name}")
        material = known[family](**values)
        material.validate()
        return material
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def material_help() -> str:
    """What --material takes, from the registry of materials."""
    kinds = [c.family + "".join(f", {p.name} {p.range_text()}" for p in c.parameters)
             for c in MATERIALS.values() if c.cli]
    return ("a material as FAMILY[:NAME=VALUE,...], e.g. gent:Jm=1 (parameters not given keep their "
            f"defaults): {'; '.join(kinds)}")


def bending_families() -> tuple:
    return tuple(f for f, c in BENDINGS.items() if c.cli)


#: The collocation mesh a state may grow to (``--max-nodes``): fewer than the smallest start
#: mesh fails every solve; more than a million outgrows the memory of a workstation.
NODE_BUDGET = (100, 1_000_000)


def node_budget(text):
    """``--max-nodes``: an integer in :data:`NODE_BUDGET`."""
    lo, hi = NODE_BUDGET
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not lo <= value <= hi:
        raise argparse.ArgumentTypeError(f"must be an integer in [{lo}, {hi:,}]; got {text!r}")
    return value


#: ``--max-fe-dofs`` and ``--max-stability-dofs``: the option of :func:`shellbvp.options` each sets.
LIMIT_OPTIONS = {"fe": ("--max-fe-dofs", "max_fe_dofs",
                        "largest 3D solid built, in unknowns (default 50000: ~30 min, ~330 MB); its size is "
                        "estimated from the scene first and a larger one refused"),
                 "stability": ("--max-stability-dofs", "max_stability_dofs",
                               "largest stability analysis of a state, in unknowns over its modes (default 300000: "
                               "~15 s a state, beta ~ 1e-7); estimated first and a larger one refused")}


def positive_count(text):
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer; got {text!r}")
    return value


def add_limit_options(p, *kinds):
    """``--max-fe-dofs`` / ``--max-stability-dofs`` (:data:`LIMIT_OPTIONS`); :func:`shellbvp.cli.main`
    runs the command with them in force."""
    for kind in kinds:
        flag, dest, text = LIMIT_OPTIONS[kind]
        p.add_argument(flag, type=positive_count, dest=dest, help=text)


def limits_of(args) -> dict:
    """The ``sb.options`` the command's limit options set (those given)."""
    return {dest: getattr(args, dest) for _, dest, _ in LIMIT_OPTIONS.values() if getattr(args, dest, None) is not None}


def add_scene_options(p, uncertain=False, preset_required=False, solver=("tol", "max_nodes")):
    g = p.add_argument_group("scene (overrides of the preset)")
    g.add_argument("--preset", default=None,
                   help="built-in scene (see `shellbvp presets`); " + (
                       "give it, or the sample's geometry: --indenter-radius (or --rho) and --rise (or --gamma) "
                       "and --thickness (or --beta)" if preset_required else "default base"))
    params = scene_parameters()

    def kind(name):  # (type, the help's end): VALUE+-U where the registry lets it carry an uncertainty
        if uncertain and params[name].uncertainty:
            return uncertain_value, "; VALUE+-U: with a standard uncertainty U"
        return plain_number, ""

    shape = g.add_mutually_exclusive_group()
    kind_of, note = kind("gamma")
    shape.add_argument("--gamma", type=kind_of, help=f"spheroid aspect parameter (< 1/rho; >0 bowl, <0 dome){note}")
    shape.add_argument("--rise", type=quantity("length", positive=False),
                       help="how far the pole lies below the rim's plane, with its unit (with --radius): gamma = "
                            "rise / R_L; > 0 a bowl indented from inside (5um), < 0 a dome indented from outside "
                            "(-5um, or 5um with --dome)")
    shape.add_argument("--meridian", type=meridian_value, metavar="'R; Z; L'",
                       help="a reference meridian of your own, 'R(S); Z(S); L': formulas in S for 0 <= S <= L (read "
                            "by a whitelist, never run; rescaled to R(L) = 1, Z(L) = 0), e.g. 'sin(S); -2*cos(S); "
                            "pi/2': pole to rim, or with --closed the upper half, pole to equator (R'(L) = 0), its "
                            "mirror image the lower half")
    g.add_argument("--meridian-lower", type=meridian_value, metavar="'R; Z; L'", dest="meridian_lower",
                   help="with --closed --meridian on a substrate under a curved tip: the lower half's own meridian, "
                        "pole to equator in its mirror image (an egg: Z > 0 is below the equator)")
    g.add_argument("--dome", action="store_true", default=None,
                   help="the shell is a dome indented from outside (its convex side): --rise is the pole's height "
                        "above the rim's plane, gamma = -rise / R_L")
    tip = g.add_mutually_exclusive_group()
    kind_of, note = kind("rho")
    tip.add_argument("--rho", type=kind_of, help=f"indenter radius / rim radius (> 0){note}")
    tip.add_argument("--indenter-radius", type=quantity("length"), dest="indenter_radius",
                     help="the indenter's tip radius with its unit (with --radius): rho = it / R_L")
    tip.add_argument("--flat-tip", action="store_true", default=None, dest="flat_tip",
                     help="the indenter is a flat plate (FlatTip: no radius)")
    g.add_argument("--closed", action="store_true", default=None,
                   help="a complete spheroid (a cell, capsule or pollen grain) instead of a shell held on its rim: "
                        "--radius is its equatorial radius, --gamma (or --rise) its polar semi-axis over it "
                        "(or --meridian its upper half)")
    g.add_argument("--support", choices=("substrate", "plates"),
                   help="with --closed: resting on a rigid plane (default; under a sphere, your tip or a flat "
                        "plate) or compressed between two plates (--flat-tip, or two of the same tip)")
    kind_of, note = kind("beta")
    g.add_argument("--beta", type=kind_of, help=f"bending stiffness B/(mu R_L^2) (> 0){note}")
    g.add_argument("--thickness", type=thickness_value,
                   help="shell thickness: H/R_L in (0, 0.5], or with a unit (50um) together with --radius; "
                        "sets beta = (H/R_L)^2/3, the bending stiffness of a 3D plate")
    g.add_argument("--thickness-profile", dest="thickness_profile", metavar="FILE",
                   help="a wall whose thickness varies: a table arc_um (or angle_deg, angle_rad, S),thickness_um from "
                        "pole to rim, with --radius (docs/thickness.md); forces and mu*H refer to the pole's")
    g.add_argument("--transverse-shear", action="store_true", default=None, dest="transverse_shear",
                   help="with --thickness: add the shell's transverse shear compliance (forces at the thick "
                        "shell's depth; removes most of the model's O(H/R_L) error, see docs/accuracy.md)")
    m = g.add_mutually_exclusive_group()
    for param in material_options():  # --alpha, --gent-jm: each selects its material
        kind_of, note = kind(param.name)
        m.add_argument(param.option, dest=param.dest, type=kind_of, help=param.option_help + note)
    m.add_argument("--neo-hookean", action="store_true", help="neo-Hookean material")
    m.add_argument("--material", type=material_spec, metavar="FAMILY[:NAME=VALUE,...]",
                   help=material_help())
    g.add_argument("--xi", type=int, choices=(0, 1), help="1: full generalised tensions; 0: first approximation")
    g.add_argument("--pressure", type=pressure_value,
                   help="pressure below the shell (from the side away from the indenter; > 0 inflates a dome or "
                        "cell): p R_L/(mu H), or with a unit (0.2MPa, 50kPa) together with --radius and --muH")
    g.add_argument("--sealed", action="store_true", default=None,
                   help="volume control: the shell encloses the volume it has when inflated at --pressure (a "
                        "sealed capsule); the pressure becomes an unknown of every state")
    g.add_argument("--contact", choices=contact_models(), help="contact-line model (default smooth)")
    b = g.add_mutually_exclusive_group()
    b.add_argument("--bending", choices=bending_families(),
                   help="bending energy B in U = W + beta B: trace (the paper's, default), rotation (convex) or "
                        "koiter (Koiter's, with the Gaussian curvature's energy at Poisson ratio 1/2: walls "
                        "whose thickness varies)")
    b.add_argument("--bending-formula", dest="bending_formula",
                   help="a user bending energy B per beta in lambda_s, lambda_theta, kappa_s, kappa_theta, "
                        "kappa_s0, kappa_theta0 (the reference curvatures)")
    if not solver:  # a command that solves nothing: no solver options to ignore
        return g
    s = p.add_argument_group("solver")
    if "tol" in solver:
        s.add_argument("--tol", type=plain_number, default=1e-6, help="collocation tolerance (default 1e-6)")
    if "max_nodes" in solver:
        s.add_argument("--max-nodes", type=node_budget, default=10000, dest="max_nodes",
                       help=f"largest collocation mesh of a state (default 10000, in [{NODE_BUDGET[0]}, {NODE_BUDGET[1]}])")
    return g


def material_options() -> list:
    """The materials' parameters with an option of their own (``--alpha``, ``--gent-jm``), from
    the registry (:mod:`shellbvp.scene_parameters`)."""
    return [p for p in scene_parameters().values() if p.material and p.option]


def scene_from_args(args):
    from ..scene import Scene

    own = [p.dest for p in scene_parameters().values() if p.option and not p.material]  # --gamma, --rho, ...
    over = {k: getattr(args, k) for k in (*own, "xi", "contact", "sealed", "transverse_shear", "closed", "support")
            if getattr(args, k, None) is not None}
    if getattr(args, "flat_tip", None):
        over["tip"] = FlatTip()
    if (lower := getattr(args, "meridian_lower", None)) and not getattr(args, "meridian", None):
        raise ValueError("--meridian-lower needs --meridian (the upper half, pole to equator) and --closed")
    if getattr(args, "meridian", None):
        over["shell"] = UserShell.closed_halves(args.meridian, lower) if lower else UserShell(*args.meridian)
    chosen = [p for p in material_options() if getattr(args, p.dest, None) is not None]
    if chosen:  # its material (the options exclude each other)
        over["material"] = material_class(chosen[0].material)(**{chosen[0].name: getattr(args, chosen[0].dest)})
    elif args.neo_hookean:
        over["material"] = NeoHookean()
    elif args.material is not None:
        over["material"] = args.material
    if getattr(args, "bending", None):
        over["bending"] = bending_class(args.bending)()
    elif getattr(args, "bending_formula", None):
        over["bending"] = BendingEnergy(args.bending_formula)
    if getattr(args, "pressure", None) is not None:
        over["pressure"] = nondimensional_pressure(args)
    if getattr(args, "thickness", None) is not None:
        over["thickness"] = nondimensional_thickness(args)
    for name, length, what in (("rho", "indenter_radius", "--indenter-radius"), ("gamma", "rise", "--rise")):
        if getattr(args, length, None) is not None:
            over[name] = over_rim_radius(args, getattr(args, length), what)
    if getattr(args, "dome", None):
        over["gamma"] = -_dome_rise(args) / args.radius.si
    scene = Scene.preset(args.preset or "base", **over)
    if getattr(args, "thickness_profile", None) is not None:
        over["thickness"] = _thickness_profile(args, scene)
        scene = Scene.preset(args.preset or "base", **over)
    return scene


def _thickness_profile(args, scene):
    """``--thickness-profile FILE`` (lab units) as a ThicknessProfile of the scene's meridian."""
    from ..thickness_profile import profile_from_file

    if getattr(args, "thickness", None) is not None:
        raise ValueError("--thickness-profile gives the thickness along the wall (the pole's from its first row): "
                         "drop --thickness")
    if getattr(args, "radius", None) is None:
        raise ValueError("--thickness-profile is in lab units: it needs --radius (the rim radius R_L)")
    return profile_from_file(args.thickness_profile, args.radius.si, scene)


def _dome_rise(args):
    """``--rise`` with ``--dome``: the dome's height above its rim (m), > 0."""
    if args.rise is None:
        raise ValueError("--dome goes with --rise, the dome's height above its rim (e.g. --rise 5um --dome); "
                         "with --gamma give the sign itself (< 0: a dome)")
    if not args.rise.si > 0:
        raise ValueError(f"--rise {args.rise} with --dome: give the dome's height as a length > 0 (or drop --dome: "
                         f"a negative --rise is a dome)")
    return args.rise.si


def over_rim_radius(args, length, option):
    """A lab length of the sample over the rim radius ``--radius``: the nondimensional number."""
    radius = getattr(args, "radius", None)
    if radius is None:
        raise ValueError(f"{option} {length} is a length: it needs --radius (the rim radius R_L), or give "
                         f"the ratio itself ({'--rho' if option == '--indenter-radius' else '--gamma'})")
    return scene_parameter("rho" if option == "--indenter-radius" else "gamma").from_lab(length.si, radius.si)


def require_sample(args, bending_per_pixel=False):
    """``fit`` names its sample: a preset, or the geometry (no silent default hemisphere);
    ``bending_per_pixel``: a force map's pixel table gives the thickness (or beta)."""
    if args.preset is not None:
        return
    missing = [what for what, given in (
        ("the indenter: --indenter-radius (or --rho, or --flat-tip)",
         args.rho is not None or args.indenter_radius is not None or bool(getattr(args, "flat_tip", None))),
        ("the shell's shape: --rise (or --gamma, --meridian)",
         args.gamma is not None or args.rise is not None or getattr(args, "meridian", None) is not None),
        ("its bending stiffness: --thickness (or --beta)",
         args.thickness is not None or args.beta is not None or bending_per_pixel
         or getattr(args, "thickness_profile", None) is not None))
        if not given]
    if missing:
        raise ValueError("fit needs the sample: --preset NAME (`shellbvp presets`), or its geometry; missing "
                         + "; ".join(missing))


def nondimensional_thickness(args):
    """``--thickness`` as ``H / R_L``: a plain number as it is, a length through ``--radius``."""
    if not isinstance(args.thickness, Quantity):
        return args.thickness
    radius = getattr(args, "radius", None)
    if radius is None:
        raise ValueError(f"--thickness {args.thickness} has a unit: it needs --radius (the nondimensional "
                         f"thickness is H / R_L); or give that number itself")
    return scene_parameter("thickness").from_lab(args.thickness.si, radius.si)  # H (m) -> H / R_L


def nondimensional_pressure(args):
    """``--pressure`` as ``p R_L/(mu H)``: a plain number as it is, a pressure with a unit through
    ``--radius`` and ``--muH``."""
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
    return scene_parameter("pressure").from_lab(args.pressure.si, radius.si, mu_h.si)  # Pa -> p R_L/(mu H)


def checkpoint_seconds():
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


def progress_bar(total, unit, args):
    """A progress bar on stderr (tqdm; none when quiet, not a terminal, or tqdm absent)."""
    enabled = progress.wanted(getattr(args, "quiet", False))
    return progress.progress_bar(total, desc=args.command, unit=unit, enabled=enabled)


def curve_bars(args, leave=True):
    """``progress`` for :func:`shellbvp.fit`: one bar per model curve, over delta."""
    mode = progress.wanted(getattr(args, "quiet", False))
    if not mode:
        return None
    return lambda desc, delta_max: progress.curve_progress(delta_max, desc, enabled=mode, leave=leave)


MAX_POINTS = 100_000  # --points: each is a solve (~0.05-0.5 s); more is a typo, not a curve


def free_default_name(preset, force):
    """Without -o: ``<preset>.h5``, or (it exists, no --overwrite) the first free ``<preset>-N.h5``,
    so that running the quick start twice neither fails nor replaces the first result."""
    from pathlib import Path

    name = Path(f"{preset}.h5")
    n = 2
    while not force and (name.exists() or Path(f"{name}.partial").exists()):
        name = Path(f"{preset}-{n}.h5")
        n += 1
    return str(name)


def strict_json(value):
    """NaN and inf as null (JSON has neither; jq, JavaScript and most parsers refuse them)."""
    import numpy as np

    if isinstance(value, dict):
        return {k: strict_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict_json(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def output_dir(path, what, files, suffix, force):
    """A directory for one output per file (created if its parent exists); names checked now."""
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


def check_report_path(path, overwrite):
    if not str(path).lower().endswith((".png", ".pdf")):
        raise ValueError(f"--report must name a .png or .pdf file; got {path!r}")
    return check_output_path(path, overwrite=overwrite)


def add_overwrite_option(p, what):
    """``--overwrite`` (``--force`` too, the older name, not shown: scripts keep working)."""
    p.add_argument("--overwrite", action="store_true", dest="force", help=what)
    p.add_argument("--force", action="store_true", dest="force", help=argparse.SUPPRESS)
