"""The ``report`` command: a one-page summary of a fit, force-map or validation file."""

from __future__ import annotations

from .common import add_overwrite_option

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``report`` subcommand's arguments, on ``sub`` (the subparsers)."""
    rp = sub.add_parser("report", help="one-page summary (PDF or PNG) of a fit file written by `shellbvp fit -o`, "
                                       "a force map's (its image of mu*H) or a validation's (`shellbvp validate`)")
    rp.add_argument("file", help="fit, force-map or validation file (HDF5)")
    rp.add_argument("-o", "--output", help="PDF or PNG (default: the file's name with .pdf)")
    add_overwrite_option(rp, "replace an existing report")
    rp.set_defaults(func=run)


def run(args):
    """The handler (``handlers/report.py``), imported now: the parser loads no numpy."""
    from .handlers import report

    return report.run(args)
