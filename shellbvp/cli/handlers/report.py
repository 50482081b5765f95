"""The ``report`` command's handler: a one-page summary of a fit, force-map or validation file
(its parser: ``shellbvp/cli/report.py``)."""

from __future__ import annotations

from pathlib import Path

from ...afm import read_map_file
from ...filekinds import file_kind, wrong_kind
from ...fitrecord import read_fit
from ...plotting import fit_report, require_matplotlib
from ...validation import read_validation
from ..common import check_report_path

__all__ = ["run"]


def run(args):
    """``shellbvp report FILE.h5 [-o FILE.pdf]``: the one-page summary of a fit, force-map or
    validation file; a curve or sweep file is a one-line error that names what reads it."""
    kind = file_kind(args.file)
    if kind in ("curve", "sweep"):
        raise wrong_kind(args.file, kind, "report", "fit, force-map and validation files")
    out = args.output or str(Path(args.file).with_suffix(".pdf"))
    check_report_path(out, overwrite=args.force)
    require_matplotlib()
    if kind == "force-map":  # the map's page is its image, as `fit MAP --report` draws it
        read_map_file(args.file).plot(out)
    elif kind == "validation":
        read_validation(args.file).plot(out)
    else:
        fit_report(read_fit(args.file), out)  # a fit, or the one-line reason the file is none
    print(f"wrote {out}")
    return 0
