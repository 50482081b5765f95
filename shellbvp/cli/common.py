"""What the commands share: the parser, number and unit arguments, limits, output names (the
scene's options: :mod:`.scene_options`)."""

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
from ..paths import check_output_path
from ..textdata import printable
from ..units import Quantity, parse_uncertain, split_quantity

__all__ = ["Parser", "print_json_error", "show_code_generation", "plain_number", "plain_numbers", "quantity", "uncertain_value", "pressure_value", "say", "number_or", "thickness_value", "nondimensional", "add_radius_option", "add_mu_h_option", "checkpoint_seconds", "progress_bar", "curve_bars", "MAX_POINTS", "free_default_name", "strict_json", "output_dir", "check_report_path", "add_overwrite_option", "NODE_BUDGET", "node_budget", "add_limit_options", "limits_of", "LIMIT_OPTIONS"]


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
