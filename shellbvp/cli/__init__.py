"""The ``shellbvp`` command line: a thin layer over the Python API.

    shellbvp curve [--preset base] [scene options] [-o base.h5]   force-displacement curve -> HDF5
    shellbvp solve [scene options] --delta 0.2 [--profiles] [--json]   one state
    shellbvp sweep --beta 0.005,0.01 --rho 0.15:0.3:4 -o grid.h5   one curve per combination -> one file
    shellbvp fit DATA.csv --preset fit --radius 0.3mm [--json]         mu*H from measured data
    shellbvp plot A.h5 [B.h5 ...] -o fig.png [--profiles 0.1,0.3]   figures (matplotlib)
    shellbvp info FILE.h5                                            what a curve or sweep file holds
    shellbvp presets                                                 the built-in scenes
    shellbvp compile [--preset NAME]                                 compile the kernels once (numba, [fast])

Invalid input exits with status 2 and a one-line message naming the parameter.
``fit`` exits 0 when the fit succeeded (warnings allowed, printed as ``warning: ...``
lines and listed under ``warnings`` in ``--json``), 1 when the fit ran but failed its
checks (``success`` false, ``status`` one of ``shellbvp.fitting.FIT_STATUS``), 2 on bad
input (data the fit cannot use included); with ``--json`` stdout is one JSON document
in every case.
"""

from __future__ import annotations

import logging
import sys

from . import compile, convexity, curve, fit, info, plot, presets, report, solve, sweep, validate
from ..config import options
from ..textdata import printable
from ..version import __version__
from .common import Parser, limits_of, os_error_line, print_json_error, show_code_generation
from .scene_options import scene_from_args

__all__ = ["main", "build_parser", "scene_from_args"]

#: The subcommands, in the order ``shellbvp --help`` lists them; each module holds its parser
#: (``add_parser``) and a ``run`` that imports its handler, ``handlers/NAME.py``, on dispatch
COMMANDS = (curve, solve, fit, sweep, plot, report, info, convexity, validate, presets, compile)


def build_parser():
    p = Parser(prog="shellbvp", description="Indentation of thin curved hyperelastic shells.")
    p.add_argument("-v", "--verbose", action="store_true", help="log progress (INFO)")
    p.add_argument("--version", action="version", version=f"shellbvp {__version__}")
    sub = p.add_subparsers(dest="command", parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(sub)
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
    Parser.json_errors = "--json" in argv
    args = parser.parse_args(argv)
    if args.command is None:
        args = parser.parse_args(["curve", *argv])
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    show_code_generation(args)
    try:
        with options(**limits_of(args)):  # --max-fe-dofs, --max-stability-dofs
            return args.func(args)
    except (ValueError, FileExistsError, ImportError) as exc:  # ImportError: an optional part missing or refused
        if getattr(args, "json", False):
            print_json_error(exc)
        print(f"shellbvp: error: {printable(' '.join(str(exc).split()))}", file=sys.stderr)  # one line, always
        return 2
    except KeyboardInterrupt:
        print("shellbvp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `shellbvp info f.h5 | head`
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:  # a file that cannot be written (a full disk): its partial file is removed
        print(f"shellbvp: error: {printable(os_error_line(exc))}", file=sys.stderr)
        return 2
