"""The ``fit`` command: mu*H (and the contact point) from measured data; a file, a batch or a force map."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..scene_parameters import parameters_that
from ..shape_parameters import SHAPE_PARAMETERS
from .common import add_limit_options, add_overwrite_option, number_or, plain_number, quantity
from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``fit`` subcommand's arguments, on ``sub`` (the subparsers)."""
    f = sub.add_parser("fit", help="fit mu*H (and the contact point) to measured force-displacement data",
                       description="Fit mu*H (and the contact point) to measured force-displacement data. "
                       "Exit status: 0 the fit succeeded (warnings, if any, printed as 'warning: ...'); "
                       "1 the fit ran but failed its checks (e.g. an interval not finite or wider than mu*H); "
                       "2 bad input (one-line message).")
    f.add_argument("data", nargs="*", help="instrument file(s) (CSV/TSV/text: displacement and force, optionally "
                   "time); several files, a directory or a pattern fit each with the same settings (a batch)")
    f.add_argument("--table", help="batch: write one row per file (CSV: file, status, mu*H and its interval, "
                   "offset, baseline, residual, warnings, ...)")
    f.add_argument("--example", action="store_true",
                   help="use the synthetic Lepidium-like data shipped with shellbvp (README)")
    # --max-nodes is not offered: the model curves keep the solver's node budget, which is part of
    # the key of every kept model curve (issue 59)
    add_scene_options(f, uncertain=True, preset_required=True, solver=("tol",))
    f.add_argument("--workers", type=int, help="with VALUE+-U parameters: local processes for their fits "
                                               "(default: all cores)")
    f.add_argument("--scheduler", help="with VALUE+-U parameters: run their fits on this Dask scheduler")
    f.add_argument("--radius", "--rim-radius", required=True, type=quantity("length"),
                   help="rim radius R_L of the sample with its unit, e.g. 0.3mm")
    f.add_argument("--pixel-table", dest="pixel_table", metavar="CSV",
                   help="a force map: the shell's geometry per pixel, a table with the columns ix, iy and one of "
                        f"{_pixel_columns()}; each pixel fitted with its value fixed (model curves at a few values "
                        "spanning the table's range, interpolated)")
    f.add_argument("--columns", help="displacement,force columns by name or 0-based index (default 0,1)")
    f.add_argument("--units", help="units of the two columns, e.g. mm,mN (default: from the header)")
    f.add_argument("--invert", action="append", choices=("displacement", "force"),
                   help="flip the sign of a column: an AFM height that falls as the tip goes in "
                        "(displacement), compression recorded as negative (force); may be given twice")
    f.add_argument("--spring-constant", dest="spring_constant", type=positive_number, metavar="N/m",
                   help="AFM text exports (AFM Workshop CSV, NT-MDT Nova .txt): the cantilever's spring constant")
    f.add_argument("--sensitivity", type=positive_number, metavar="m/V",
                   help="AFM text exports: the deflection sensitivity (NT-MDT: m/A)")
    f.add_argument("--segment", choices=("loading", "retraction", "all"), default="loading",
                   help="rows to fit: loading (default: the approach and the loading, up to the deepest point; "
                        "segments by the direction of the displacement over time), retraction, or all "
                        "(every row, whatever its direction)")
    f.add_argument("--baseline", choices=("auto", "none", "constant", "linear"), default="auto",
                   help="force baseline fitted with the contact point: auto (default: constant when the data "
                        "have an approach before contact, else none), none, constant, linear")
    f.add_argument("--no-offset", action="store_true", dest="no_offset", help="do not fit the contact point")
    f.add_argument("--max-depth", dest="max_depth", type=number_or("length"),
                   help="fitting range: leave out rows deeper than this beyond the contact point's first guess, "
                        "a length (2um) or a plain number (a fraction of R_L, as the warnings give it)")
    f.add_argument("--force-max", dest="max_force", type=quantity("force"),
                   help="fitting range: leave out rows whose force is above this, with its unit (5nN, 2mN)")
    f.add_argument("--no-weights-check", action="store_false", dest="weights_check",
                   help="do not refit with another noise model (uniform; mixed for --weights uniform) to check "
                        "the fit: by default a fit whose two mu*H intervals do not overlap fails (status 6)")
    for name, param in SHAPE_PARAMETERS.items():  # one of them at most
        f.add_argument(f"--fit-{name}", action="store_true", dest=f"fit_{name}", help=param.fit_help)
        f.add_argument(f"--{name}-range", dest=f"{name}_range", help=param.range_help)
    f.add_argument("--weights", choices=("uniform", "relative", "mixed"),
                   help="noise model: uniform (same force noise everywhere), relative (noise proportional "
                        "to the force) or mixed (both, estimated; the default)")
    f.add_argument("--stability", action="store_true",
                   help="also look for where the fitted shell stops being axisymmetric, up to the deepest fitted "
                        "depth (a warning when the data pass it; seconds to a minute more)")
    f.add_argument("--model", choices=("auto", "shell", "solid"), default="auto",
                   help="what is compared with the data: shell (the shell model; its mid-surface pole's "
                        "displacement taken as the data's), solid (the shell as a 3D solid of the given "
                        "--thickness, indented by the indenter's displacement as the instrument records it (a "
                        "closed shell: the indenters' approach); "
                        "needs '.[fe]'; one FE curve per sample, kept in the code cache) or auto (default: with a "
                        "thickness of at least 0.05 R_L, both, and the shell where the solid measures its error "
                        "within the interval, else the solid; otherwise the shell); the summary says which and why")
    f.add_argument("--mesh-check", action="store_true", dest="mesh_check",
                   help="where the 3D solid is the model: fit again on a mesh with 2/3 the elements each way and "
                        "report the change of mu*H as the solid's error (one more, cheaper FE curve)")
    f.add_argument("--json", action="store_true", help="print the result as one JSON document (also on errors)")
    f.add_argument("-o", "--output", help="write the fit as a record (HDF5/NeXus: data, model, parameters with "
                   "intervals, weights, warnings, scene, source file and its SHA-256); a batch: a directory "
                   "(one <name>.h5 per file)")
    f.add_argument("--report", help="write a one-page summary of the fit (.png or .pdf); a batch: a directory "
                   "(one <name>.pdf per file)")
    f.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_overwrite_option(f, "replace an existing output file (record, report, table)")
    add_limit_options(f, "fe", "stability")
    f.set_defaults(func=run)


def _pixel_columns() -> str:
    """The geometry columns a pixel table may have, from the registry (in words, for --help)."""
    return ", ".join(f"{p.name} (with its unit: {p.name}_um, '{p.name} (nm)'; bare: {p.symbol})"
                     if p.lab is not None and p.lab.scale == "R_L" else p.name for p in parameters_that("per_pixel"))


def positive_number(text):
    """argparse type of ``--spring-constant``/``--sensitivity``: a finite number > 0 (SI units)."""
    value = plain_number(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a number > 0 (SI units); got {text!r}")
    return value


def run(args):
    """The data given checked, then the handler (``handlers/fit.py``) imported: a missing file is
    refused before numpy loads."""
    if args.example == bool(args.data):
        raise ValueError("give data files (or a directory) or --example (one of them)")
    if len(args.data) == 1 and not any(ch in args.data[0] for ch in "*?[") and not Path(args.data[0]).exists():
        raise ValueError(f"{args.data[0]}: no such file or directory")
    from .handlers import fit

    return fit.run(args)
