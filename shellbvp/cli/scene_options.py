"""The scene's options of the commands (``--preset``, the shape, tip, wall, material, interior,
contact, bending) and the scene they describe (:func:`scene_from_args`)."""

from __future__ import annotations

import argparse

from .. import units
from ..edge_models import contact_models
from ..geometry import FlatTip, UserShell
from ..materials import BENDINGS, MATERIALS, BendingEnergy, NeoHookean, bending_class, material_class
from ..scene_parameters import scene_parameter, scene_parameters
from ..textdata import printable
from ..units import Quantity
from .common import NODE_BUDGET, node_budget, plain_number, pressure_value, quantity, thickness_value, uncertain_value

__all__ = ["meridian_value", "material_spec", "material_help", "bending_families", "add_scene_options",
           "material_options", "scene_from_args", "over_rim_radius", "require_sample", "nondimensional_thickness",
           "nondimensional_pressure"]


def meridian_value(text):
    """``--meridian 'R; Z; L'``: the three formulas' text (parsed by the scene's whitelist later)."""
    parts = [part.strip() for part in text.split(";")]
    if len(parts) != 3 or not all(parts):
        raise argparse.ArgumentTypeError(f"give three formulas 'R(S); Z(S); L' separated by ';'; got {len(parts)} "
                                         f"part{'s' if len(parts) != 1 else ''} in {printable(text)!r}")
    return tuple(parts)


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
                            "pi/2': pole to rim; with --closed the upper half, pole to equator (R'(L) = 0), its "
                            "mirror image the lower half, or the whole meridian from pole to pole when it returns to "
                            "the axis at S = L (R(L) = 0, e.g. 'sin(S); cos(S)*(1 + 0.3*cos(S)); pi': an egg), split "
                            "at its widest point (the equator, R = 1, Z = 0)")
    g.add_argument("--meridian-lower", type=meridian_value, metavar="'R; Z; L'", dest="meridian_lower",
                   help="with --closed --meridian on a substrate under a curved tip: the lower half's own meridian, "
                        "pole to equator in its mirror image (an egg: Z > 0 is below the equator); not with a --meridian "
                        "from pole to pole, which holds both halves")
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
                        "(or --meridian its upper half, or its meridian from pole to pole)")
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
    if meridian := getattr(args, "meridian", None):
        over["shell"] = _user_shell(meridian, lower)
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


def _user_shell(meridian, lower):
    """``--meridian`` (and ``--meridian-lower``) as a UserShell; its errors name the options."""
    options = "--meridian, --meridian-lower" if lower else "--meridian"
    try:
        whole = UserShell.returns_to_axis(meridian[0], meridian[2])  # R(L) = 0: pole to pole
        if whole and lower:
            raise ValueError("--meridian returns to the axis at S = L (R(L) = 0), a whole meridian from pole to pole; "
                             "give either that alone, or the upper half (pole to equator) with --meridian-lower")
        return (UserShell.pole_to_pole(*meridian) if whole else
                UserShell.closed_halves(meridian, lower) if lower else UserShell(*meridian))
    except ValueError as exc:
        raise ValueError(f"{options}: {str(exc).removeprefix('shell: ')}") from None


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
