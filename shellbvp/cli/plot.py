"""The ``plot`` command: figures of curve, sweep, fit, force-map and validation files; one
pixel of a force map (``--pixel IX,IY``) or one figure per pixel (``--pixels all|failed -o DIR``)."""

from __future__ import annotations

from ..paths import require_file

__all__ = ["add_parser", "run", "MAX_PIXEL_FIGURES"]

#: ``--pixels`` writes at most this many figures unless ``--max-figures`` says more
MAX_PIXEL_FIGURES = 100


def add_parser(sub):
    """The ``plot`` subcommand's arguments, on ``sub`` (the subparsers)."""
    pl = sub.add_parser("plot", help="plot curves (and profiles) from HDF5 files (needs matplotlib)")
    pl.add_argument("files", nargs="+", help="curve files (`shellbvp curve`), sweep files (`shellbvp sweep`: one "
                    "curve per finished combination), fit files (`shellbvp fit -o`: data, model and residuals in "
                    "SI units), force-map files (`shellbvp fit MAP.jpk-force-map -o`: the image of mu*H) or validation "
                    "files (`shellbvp validate`: both models' F and the shell's error)")
    pl.add_argument("-o", "--output", help="PNG or PDF (default curves.png; for fit, force-map and validation files <name>.png "
                    "next to each); for several of those a directory (one <name>.png each)")
    pl.add_argument("--profiles", help="also draw the deformed shell of the first file at these depths, e.g. 0.1,0.3")
    pl.add_argument("--dpi", type=int, default=150, help="resolution of a PNG (default 150)")
    px = pl.add_mutually_exclusive_group()
    px.add_argument("--pixel", metavar="IX,IY",
                    help="a force-map file: one pixel's fitted rows against its model, and the residuals (the grid "
                         "index as the map's warnings name pixels, e.g. 9,0; default -o <name>_pixel_IX_IY.png)")
    px.add_argument("--pixels", choices=("all", "failed"),
                    help="a force-map file: one such figure per pixel into the directory -o (every curve's, or those "
                         "whose fit failed its checks or could not run); at most --max-figures")
    pl.add_argument("--max-figures", type=int, default=MAX_PIXEL_FIGURES, metavar="N",
                    help=f"--pixels: refuse to write more than N figures (default {MAX_PIXEL_FIGURES}; say how many "
                         f"you want)")
    pl.set_defaults(func=run)


def run(args):
    """The handler (``handlers/plot.py``), imported once the file is known to exist: the parser loads no numpy."""
    for path in args.files:
        require_file(path)
    from .handlers import plot

    return plot.run(args)
