"""The ``plot`` command's handler: figures of curve, sweep, fit, force-map and validation files;
one pixel of a force map or one figure per pixel (its parser: ``shellbvp/cli/plot.py``)."""

from __future__ import annotations

from pathlib import Path

from ...afm import read_map_file
from ...filekinds import file_kind
from ...fitrecord import read_fit
from ...io import read_curve
from ...map_pixels import parse_pixel
from ...paths import check_output_path
from ...plotting import plot_curves, plot_fit_record, plot_profiles, require_matplotlib, save_figure, scene_label
from ...sweeps import read_sweep
from ...textdata import printable
from ...validation import read_validation
from ..common import output_dir, plain_numbers

__all__ = ["run"]


def run(args):
    """``shellbvp plot FILE ...``: the figures written; exit 0."""
    kinds = [file_kind(f) for f in args.files]
    if args.pixel is not None or args.pixels is not None:
        return _pixel_figures(args, kinds)
    single = [k for k in kinds if k in _ONE_FIGURE_EACH]
    if single:  # fit, force-map and validation files: one figure each
        if len(set(kinds)) != 1:
            raise ValueError(f"plot files of one kind in one call: {single[0]} files, or curve and sweep files "
                             f"(got {', '.join(sorted({str(k or 'other') for k in kinds}))})")
        draw = _ONE_FIGURE_EACH[single[0]]
        for name, out in zip(args.files, _figure_paths(args.output, args.files)):
            check_output_path(out, overwrite=True)  # a figure is cheap to redraw: replaced
            draw(name, out, args.dpi)
            print(f"wrote {out}")
        return 0
    args.output = "curves.png" if args.output is None else args.output
    check_output_path(args.output, overwrite=True)  # a figure is cheap to redraw: replaced
    plt = require_matplotlib()
    curves, labels = [], []
    for name, kind in zip(args.files, kinds):
        if kind == "sweep":  # a family: one curve per finished combination, labelled by its values
            sw = read_sweep(name)
            for i, c in sorted(sw.curves.items()):
                curves.append(c)
                labels.append(" ".join(f"{p}={sw.index[p][i]:.4g}" for p in sw.parameters))
        else:
            curves.append(read_curve(name))
            labels.append(scene_label(curves[-1].scene))
    if not curves:
        raise ValueError(f"{', '.join(args.files)}: no finished curve to plot")
    deltas = plain_numbers(args.profiles, "--profiles") if args.profiles else []
    ncol = 2 if deltas else 1
    fig, axes = plt.subplots(1, ncol, figsize=(6 * ncol, 4.8), squeeze=False)
    plot_curves(curves, ax=axes[0, 0], labels=labels)
    if deltas:
        for d in deltas:
            if not d > 0:
                raise ValueError(f"--profiles depths must be > 0; got {d}")
        plot_profiles(curves[0].scene, deltas, ax=axes[0, 1])
    fig.tight_layout()
    save_figure(fig, args.output, dpi=args.dpi)
    print(f"wrote {args.output}")
    return 0


def _fit_figure(name, out, dpi):
    plt = require_matplotlib()
    ax, _ = plot_fit_record(read_fit(name))
    ax.figure.tight_layout()
    try:
        save_figure(ax.figure, out, dpi=dpi)
    finally:
        plt.close(ax.figure)


def _pixel_figures(args, kinds):
    """``--pixel IX,IY``: one pixel's figure; ``--pixels all|failed -o DIR``: one per pixel, their
    number said first and bounded by ``--max-figures``."""
    option = "--pixel" if args.pixel is not None else "--pixels"
    if len(args.files) != 1 or kinds[0] != "force-map":
        what = (f"{len(args.files)} files" if len(args.files) != 1 else f"{args.files[0]}, a {kinds[0]} file"
                if kinds[0] else f"{args.files[0]}, not a file shellbvp writes")
        raise ValueError(f"{option} is for one force-map file (`shellbvp fit MAP -o map.h5`); got {what}")
    name = args.files[0]
    if args.pixel is not None:
        ix, iy = parse_pixel(args.pixel)
        out = Path(args.output) if args.output else Path(name).with_name(f"{Path(name).stem}_pixel_{ix}_{iy}.png")
        check_output_path(out, overwrite=True)  # a figure is cheap to redraw: replaced
        try:
            read_map_file(name).plot_pixel(ix, iy, out, dpi=args.dpi)
        except ValueError as exc:
            raise ValueError(f"--pixel {ix},{iy}: {exc}") from None
        print(f"wrote {out}")
        return 0
    if args.max_figures < 1:
        raise ValueError(f"--max-figures must be >= 1; got {args.max_figures}")
    if args.output is None or (Path(args.output).exists() and not Path(args.output).is_dir()):
        raise ValueError("--pixels writes one figure per pixel: give a directory with -o DIR")
    mf = read_map_file(name)
    pixels = mf.pixels(args.pixels)
    if not mf.curves.has_data:
        raise ValueError(mf.curves.no_data_reason())
    which = "every curve's" if args.pixels == "all" else "the pixels whose fit did not succeed"
    if len(pixels) > args.max_figures:
        raise ValueError(f"--pixels {args.pixels} would write {len(pixels)} figures ({which}) into {args.output}; "
                         f"at most --max-figures {args.max_figures}: give --max-figures {len(pixels)} to write them")
    outdir = Path(args.output)
    if not outdir.exists():
        if not outdir.parent.is_dir():
            raise ValueError(f"-o {args.output}: its parent directory does not exist")
        outdir.mkdir()
    paths = {p: outdir / f"{Path(name).stem}_pixel_{p[0]}_{p[1]}.png" for p in pixels}
    for path in paths.values():
        check_output_path(path, overwrite=True)
    print(f"{name}: {len(pixels)} figures ({which}) into {outdir}")
    written = 0
    for (ix, iy), path in paths.items():
        pixel = mf.pixel(ix, iy)
        if pixel.displacement is None or pixel.displacement.size == 0:
            print(f"pixel {(ix, iy)}: no rows to draw ({pixel.status}: {printable(pixel.message)})")
            continue
        mf.plot_pixel(ix, iy, path, dpi=args.dpi)
        written += 1
    print(f"wrote {written} figures ({Path(name).stem}_pixel_IX_IY.png) into {outdir}")
    return 0


def _map_figure(name, out, dpi):
    read_map_file(name).plot(out, dpi=dpi)


def _validation_figure(name, out, dpi):
    read_validation(name).plot(out, dpi=dpi)


#: The kinds of file drawn one figure each, and how.
_ONE_FIGURE_EACH = {"fit": _fit_figure, "force-map": _map_figure, "validation": _validation_figure}


def _figure_paths(output, names):
    """One figure per file: beside each file (no ``-o``), in the directory ``-o`` names (several
    files, or a directory), or ``-o`` itself (one file)."""
    if output is None:
        return [Path(name).with_suffix(".png") for name in names]
    if len(names) > 1 or Path(output).is_dir():
        outdir = output_dir(output, "-o", names, ".png", True)
        return [outdir / (Path(name).stem + ".png") for name in names]
    return [Path(output)]
