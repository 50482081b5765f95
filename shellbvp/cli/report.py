"""The ``report`` command: a one-page summary of a fit, force-map or validation file."""

from __future__ import annotations

from pathlib import Path

from .common import add_overwrite_option, check_report_path

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
    """``shellbvp report FILE.h5 [-o FILE.pdf]``: the one-page summary of a fit, force-map or
    validation file; a curve or sweep file is a one-line error that names what reads it."""
    from ..filekinds import file_kind, wrong_kind
    from ..fitrecord import read_fit
    from ..plotting import fit_report, require_matplotlib

    kind = file_kind(args.file)
    if kind in ("curve", "sweep"):
        raise wrong_kind(args.file, kind, "report", "fit, force-map and validation files")
    out = args.output or str(Path(args.file).with_suffix(".pdf"))
    check_report_path(out, overwrite=args.force)
    require_matplotlib()
    if kind == "force-map":  # the map's page is its image, as `fit MAP --report` draws it
        from ..afm import read_map_file

        read_map_file(args.file).plot(out)
    elif kind == "validation":
        from ..validation import read_validation

        read_validation(args.file).plot(out)
    else:
        fit_report(read_fit(args.file), out)  # a fit, or the one-line reason the file is none
    print(f"wrote {out}")
    return 0
