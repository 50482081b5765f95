"""The ``info`` command: what a curve, sweep, fit, force-map or validation file holds."""

from __future__ import annotations

from ..paths import require_file

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``info`` subcommand's arguments, on ``sub`` (the subparsers)."""
    i = sub.add_parser("info", help="describe a curve, sweep, fit, force-map or validation file")
    i.add_argument("file")
    i.set_defaults(func=run)


def run(args):
    """The handler (``handlers/info.py``), imported once the file is known to exist: the parser loads no numpy."""
    require_file(args.file)
    from .handlers import info

    return info.run(args)
