"""The ``report`` command: a one-page summary of a fit, force-map or validation file."""

from __future__ import annotations

from .common import add_overwrite_option

from ..paths import require_file

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
    """The handler (``handlers/report.py``), imported once the file is known to exist: the parser loads no numpy."""
    require_file(args.file)
    from .handlers import report

    return report.run(args)
