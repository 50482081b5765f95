"""The ``report`` command: a one-page summary of a fit file."""

from __future__ import annotations

from pathlib import Path

from .common import add_overwrite_option, check_report_path

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``report`` subcommand's arguments, on ``sub`` (the subparsers)."""
    rp = sub.add_parser("report", help="one-page summary (PDF or PNG) of a fit file written by `shellbvp fit -o`")
    rp.add_argument("file", help="fit file (HDF5)")
    rp.add_argument("-o", "--output", help="PDF or PNG (default: the fit file's name with .pdf)")
    add_overwrite_option(rp, "replace an existing report")
    rp.set_defaults(func=run)


def run(args):
    """``shellbvp report FIT.h5 [-o FIT.pdf]``: the one-page summary of a fit file."""
    from ..fitrecord import read_fit
    from ..plotting import fit_report, require_matplotlib

    out = args.output or str(Path(args.file).with_suffix(".pdf"))
    check_report_path(out, overwrite=args.force)
    require_matplotlib()
    fit_report(read_fit(args.file), out)
    print(f"wrote {out}")
    return 0
