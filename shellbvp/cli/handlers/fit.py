"""The ``fit`` command's handler: mu*H (and the contact point) from measured data; a file, a batch
or a force map (its parser: ``shellbvp/cli/fit.py``)."""

from __future__ import annotations

import itertools
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from ... import units
from ...afm import iter_afm
from ...batch import expand_inputs, fit_files, fit_map, read_record, write_table
from ...fit_checks import weights_check_line
from ...fitrecord import read_fit, write_fit
from ...fitting import diagnostics_lines, example_data_path, fit_record
from ...fitting.solid import check_solid_fit, solid_words
from ...modal_stability import check_stability_size
from ...paths import check_output_path
from ...pixel_table import read_pixel_table
from ...plotting import fit_report
from ...readers import check_options, reader_for
from ...scene_parameters import parameters_that, scene_parameter, scene_parameters
from ...shape_parameters import SHAPE_PARAMETERS
from ...sweeps import dask_executor
from ...textdata import printable
from ...thickness import model_error_line
from ...uncertainty import fit_with_geometry
from ...units import Quantity, format_in, readable_unit, split_quantity, unit_factor, unit_kind
from ..common import check_report_path, curve_bars, os_error_line, output_dir, progress_bar, say, strict_json
from ..scene_options import require_sample, scene_from_args

__all__ = ["run"]


def _split_uncertain(args):
    """``VALUE+-U`` options of ``fit``: the values go to the scene; returns {name: U}."""
    uncertainty = {}
    for param in parameters_that("uncertainty"):  # the registry's, in its order
        given = getattr(args, param.dest, None)
        if isinstance(given, tuple):
            setattr(args, param.dest, given[0])
            if given[1] is not None:
                uncertainty[param.name] = given[1]
    if (args.workers is not None or args.scheduler) and not uncertainty:
        raise ValueError("--workers and --scheduler run the fits of an uncertain geometry: give a parameter "
                         "as VALUE+-U (e.g. --rho 0.333+-0.02)")
    if args.scheduler and args.workers is not None:
        raise ValueError("--workers sets the local pool; with --scheduler the cluster has its own workers")
    return uncertainty


def _bending_per_pixel(pixel_values):
    return pixel_values is not None and "beta" in scene_parameter(pixel_values.name).sets


def _pixel_table(args, files, folder):
    """``--pixel-table``'s table read and checked (before the map is read), or None."""
    if args.pixel_table is None:
        return None
    if len(files) != 1 or folder or not reader_for(files[0]).curves:
        raise ValueError("--pixel-table is for one force map (an AFM file such as .jpk-force-map)")
    table = read_pixel_table(args.pixel_table)
    # the options that set what the table sets (the thickness sets beta too)
    sets = set(scene_parameter(table.name).sets)
    clash = [p.option for p in scene_parameters().values()
             if p.option and sets & set(p.sets) and getattr(args, p.dest, None) is not None]
    if clash:
        raise ValueError(f"{args.pixel_table} gives the {table.name} per pixel: leave out {', '.join(clash)}")
    return table


def _fit_inputs(args, pixel_values=None):
    """The scene, R_L and the reading and fitting options of ``fit``, checked before any work."""
    require_sample(args, bending_per_pixel=_bending_per_pixel(pixel_values))
    scene = scene_from_args(args)
    units = None
    if args.units:
        parts = [u.strip() for u in args.units.split(",")]
        if len(parts) not in (2, 3):
            raise ValueError(f"--units must be two units, displacement and force (and a third for time), "
                             f"e.g. mm,mN; got {args.units!r}")
        units = tuple(parts)
    columns = [c.strip() for c in args.columns.split(",")] if args.columns else None
    if columns is not None and len(columns) not in (2, 3):
        raise ValueError(f"--columns must name two columns (displacement, force) or three (and time); "
                         f"got {args.columns!r}")
    free = tuple(name for name in SHAPE_PARAMETERS if getattr(args, f"fit_{name}"))
    bounds = {}
    for name, param in SHAPE_PARAMETERS.items():
        text = getattr(args, f"{name}_range")
        if text is not None:
            bounds[name] = _search_range(param, text, args.radius.si)
            if name not in free:
                raise ValueError(f"--{name}-range needs --fit-{name}")
    if args.model == "solid":
        check_solid_fit(scene, free)
    if args.stability:
        check_stability_size(scene)
    options = {"fit_offset": not args.no_offset, "free": free, "bounds": bounds, "weights": args.weights,
               "tol": args.tol, "stability": args.stability, "model": args.model, "mesh_check": args.mesh_check,
               "max_depth": _max_depth(args.max_depth, args.radius.si),
               "max_force": None if args.max_force is None else args.max_force.si, "weights_check": args.weights_check}
    reading = {"columns": columns, "units": units, "invert": tuple(args.invert or ()), **_calibration(args)}
    return scene, args.radius.si, reading, options


def _calibration(args):
    """An AFM text export's calibration options, as :func:`shellbvp.afm.read_afm` takes them."""
    return {"spring_constant": args.spring_constant, "sensitivity": args.sensitivity}


def _max_depth(given, R_L):
    """``--max-depth`` in m: a length as it is, a plain number as a fraction of R_L; None if not given."""
    if given is None:
        return None
    depth = given.si if hasattr(given, "si") else given * R_L
    if not depth > 0:
        raise ValueError(f"--max-depth must be a depth > 0 (a length, or a fraction of R_L); got {given}")
    return depth


def _search_range(param, text, R_L):
    """``--NAME-range LOW,HIGH`` as the nondimensional bounds of the shape parameter ``param``:
    plain numbers as they are; with a unit (a parameter with a lab unit, e.g. 20um) through R_L."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        values = []
        for part in parts:
            if param.unit_kind and split_quantity(part, param.unit_kind, f"--{param.name}-range")[1]:
                values.append(Quantity.parse(part, param.unit_kind, f"--{param.name}-range").si
                              / param.report_scale(R_L))
            else:
                values.append(units.plain_number(part, f"--{param.name}-range"))
    except ValueError:
        unit = f" (plain, or with a {param.unit_kind} unit)" if param.unit_kind else ""
        raise ValueError(f"--{param.name}-range must be two numbers LOW,HIGH{unit}; got {text!r}") from None
    return tuple(values)


def run(args):
    """``shellbvp fit``: exit 0 (fit succeeded; warnings allowed), 1 (the fit ran but failed its
    checks) or 2 (bad input: a ValueError, one line on stderr).  With ``--json`` stdout holds
    exactly one JSON document in every case (errors: see :func:`main`).  Several files (or a
    directory, a pattern, or ``--table``): a batch, see :func:`_fit_batch`; an AFM force map: every
    curve into a map, see :func:`_fit_map`.  The data given is checked first, before this module
    loads (``shellbvp/cli/fit.py``: :func:`~shellbvp.cli.fit.run`)."""

    inputs = [str(example_data_path())] if args.example else args.data
    files = expand_inputs(inputs)
    uncertainty = _split_uncertain(args)
    folder = any(Path(x).is_dir() for x in inputs)
    pixel_values = _pixel_table(args, files, folder)
    map_curves = None
    if len(files) == 1 and not folder and reader_for(files[0]).curves:  # a file of curves: a force map?
        # its one-line error before the file is read
        require_sample(args, bending_per_pixel=_bending_per_pixel(pixel_values))
        curves = iter_afm(files[0], **_calibration(args))  # one at a time: a map is never all in memory
        first = list(itertools.islice(curves, 2))
        if not first:
            raise ValueError(f"{printable(files[0])}: afmformats found no force-distance curve in it")
        if len(first) > 1:  # a force map: every curve, into a map
            if uncertainty:
                raise ValueError("VALUE+-U (the geometry's uncertainty) is for one curve, not a force map")
            map_curves = itertools.chain(first, curves)
    if pixel_values is not None and map_curves is None:
        raise ValueError(f"--pixel-table is for a force map; {files[0]} holds one curve")
    if map_curves is None and (len(files) > 1 or args.table or folder):
        if uncertainty:
            raise ValueError("VALUE+-U (the geometry's uncertainty) is for one file at a time, not a batch")
        return _fit_batch(args, files)
    if args.output is not None:
        check_output_path(args.output, overwrite=args.force)
    if args.report is not None:
        check_report_path(args.report, overwrite=args.force)
    scene, R_L, reading, options = _fit_inputs(args, pixel_values)
    options["progress"] = curve_bars(args)
    if map_curves is not None:
        return _fit_map(args, files[0], map_curves, scene, R_L, reading, options, pixel_values)
    record = read_record(files[0], **reading)
    res, used = fit_record(scene, record, R_L=R_L, segment=args.segment, baseline=args.baseline, **options)
    geometry = None
    if uncertainty and res.success:
        # the same rows, baseline model and contact point as the nominal fit, at each perturbed geometry
        kw = {k: v for k, v in options.items() if k not in ("progress", "mesh_check")}
        kw["model"] = res.model  # the nominal fit's model at every perturbed geometry
        executor = dask_executor(args.scheduler) if args.scheduler else None
        geometry = fit_with_geometry(scene, record.displacement[used], record.force[used], R_L=R_L,
                                     uncertainty=uncertainty, executor=executor, workers=args.workers,
                                     baseline=res.baseline_model, contact_guess=res.offset, **kw)
    out = res.to_dict()
    out["notes"] = list(record.notes)
    ok = res.success and (geometry is None or geometry.success)
    if geometry is not None:
        out["geometry"] = geometry.to_dict()
        out["success"] = ok
    out["exit_status"] = 0 if ok else 1
    written = not (args.output or args.report) or not res.success
    if args.json and not written:  # written first: the one JSON document says whether it was
        written = _save_or_error(res, record, used, args)
        if written is not True:
            out.update(exit_status=2, write_error=written)
    if args.json:
        print(json.dumps(strict_json(out), allow_nan=False))
    else:
        _print_fit(res, record, used, args)
        if geometry is not None:
            if not geometry.success:
                print(f"fit with the geometry's uncertainty failed: {geometry.message}")
            g1, g2 = geometry.mu_H_ci95
            print(f"geometry = mu*H 95% CI [{g1:.4g}, {g2:.4g}] N/m with the geometry's uncertainty "
                  f"(u = {geometry.u_geometry:.3g} N/m; {geometry.fits_computed} fits)")
            print(geometry.table())
    if args.output or args.report:
        if not res.success:
            print(f"shellbvp: not writing {args.output or args.report}: the fit failed its checks", file=sys.stderr)
        elif written is not True:  # the result is printed; the file could not be written (a full disk)
            written = written or _save_or_error(res, record, used, args)
            if written is not True:
                print(f"shellbvp: error: {printable(written)}", file=sys.stderr)
                return 2
    return 0 if ok else 1


def _save_or_error(res, record, used, args):
    """True once the fit's record (and report) are written, else the one-line reason (a full
    disk: the partial file is removed, the fit's result stands)."""
    try:
        _save_fit(res, record, used, args.output, args.report, args.segment, args.force, args.json)
    except OSError as exc:
        return os_error_line(exc)
    return True


def _fit_batch(args, files):
    """``shellbvp fit A B ... [--table results.csv] [-o DIR] [--report DIR]``: every file with
    the same scene and settings, one row each (status ok, failed or error), continuing past
    a file that fails; exit 0 when every file was fitted, 1 otherwise."""
    if args.table is not None:
        check_output_path(args.table, overwrite=args.force)
    outdir = output_dir(args.output, "-o", files, ".h5", args.force) if args.output else None
    repdir = output_dir(args.report, "--report", files, ".pdf", args.force) if args.report else None
    scene, R_L, reading, options = _fit_inputs(args)
    options["progress"] = curve_bars(args, leave=False)
    bar = progress_bar(len(files), "file", args)

    def step(row):
        bar.update(1)
        bar.set_postfix_str(f"{Path(row.file).name}: {row.status}")

    try:
        rows = fit_files(scene, files, R_L=R_L, segment=args.segment, baseline=args.baseline, on_file=step,
                         **reading, **options)
    finally:
        bar.close()
    for row in rows:
        if row.status == "ok" and (outdir or repdir):
            stem = Path(row.file).stem
            _save_fit(row.result, row.record, row.used, outdir / f"{stem}.h5" if outdir else None,
                      repdir / f"{stem}.pdf" if repdir else None, args.segment, args.force, True)
    if args.table is not None:
        write_table(args.table, rows, args.segment, overwrite=args.force)
    ok = all(r.status == "ok" for r in rows)
    if args.json:
        docs = [{"file": r.file, "status": r.status, "message": r.message,
                 **(r.result.to_dict() if r.result is not None else {})} for r in rows]
        print(json.dumps(strict_json({"files": docs, "success": ok, "exit_status": 0 if ok else 1}),
                         allow_nan=False))
    else:
        say(f"scene  = {scene.describe(R_L)}")  # every file's, in lab units: a batch names its sample too
        width = max(len(r.file) for r in rows)
        for r in rows:
            if r.result is not None and r.status != "error":
                lo, hi = r.result.mu_H_ci95
                text = f"mu*H = {r.result.mu_H:.4g} N/m  95% CI [{lo:.4g}, {hi:.4g}]"
                if r.result.warnings:
                    text += f"  ({len(r.result.warnings)} warning{'s' * (len(r.result.warnings) > 1)})"
            else:
                text = r.message
            say(f"{r.file:<{width}}  {r.status:<6s}  {text}")
        n_ok = sum(r.status == "ok" for r in rows)
        print(f"{n_ok} of {len(rows)} files fitted" + (f"; table: {args.table}" if args.table else ""))
    return 0 if ok else 1


def _fit_map(args, path, curves, scene, R_L, reading, options, pixel_values=None):
    """``shellbvp fit MAP.jpk-force-map [-o map.h5] [--table map.csv] [--report map.png]
    [--pixel-table geometry.csv]``: every curve with the same scene (or with the table's geometry
    per pixel); exit 0 when every curve was fitted, 1 otherwise."""
    check_options(reader_for(path), path, reading)
    if args.table is not None:
        check_output_path(args.table, overwrite=args.force)
    options = dict(options, progress=curve_bars(args, leave=False))
    bar = progress_bar(None, "curve", args)

    def step(row):
        bar.update(1)
        bar.set_postfix_str(row.status)

    try:
        fm = fit_map(scene, curves, R_L=R_L, path=path, segment=args.segment, baseline=args.baseline,
                     on_curve=step, pixel_values=pixel_values, **options)
    finally:
        bar.close()
    ok = all(r.status == "ok" for r in fm.rows)
    if args.table is not None:
        write_table(args.table, fm.rows, args.segment, overwrite=args.force)
    if args.output is not None:
        fm.to_hdf5(args.output, overwrite=args.force)
    if args.report is not None:
        fm.plot(args.report)
    wrote = [w for w in (args.table, args.output, args.report) if w is not None]
    if args.json:
        docs = [{"file": r.file, "grid_index": list(c.grid), "status": r.status, "message": r.message, **r.extra,
                 **(r.result.to_dict() if r.result is not None else {})} for c, r in zip(fm.curves, fm.rows)]
        per_pixel = {} if pixel_values is None else {"per_pixel": {
            "parameter": pixel_values.name, "table": str(pixel_values.path), "unit": fm.pixel_unit(),
            "nodes": list(fm.pixel_nodes), "curves_computed": fm.curves_computed,
            "interpolation_error": fm.interpolation_error, "notes": fm.notes}}
        print(json.dumps(strict_json({"map": str(path), "shape": list(fm.shape), "curves": docs, **per_pixel,
                                      "success": ok, "exit_status": 0 if ok else 1}), allow_nan=False))
        for w in wrote:
            print(f"wrote {w}", file=sys.stderr)
    else:
        say(f"data   = {path}: a force map of {len(fm.rows)} curves; fitted the {args.segment} segment of each")
        say(f"scene  = {scene.describe(R_L)}" + ("" if pixel_values is None else
                                                 f"; in place of its {pixel_values.name}: the pixel table's"))
        say(f"map    = {fm.summary()}")
        for code, (where, text) in fm.warning_counts().items():
            cells = ", ".join(map(str, where[:8])) + (", ..." if len(where) > 8 else "")
            say(f"warning: {len(where)} curve{'s' * (len(where) > 1)} ({cells}): {text}")
        for note in fm.notes:
            say(f"note: {note}")
        for w in wrote:
            say(f"wrote {w}")
    return 0 if ok else 1


def _save_fit(res, record, used, output, report, segment, force, quiet_stdout=False):
    """The fit's record (HDF5) and its one-page report (PNG/PDF), as asked (with --json the
    'wrote' lines go to stderr: stdout holds the one JSON document)."""
    if output:
        write_fit(output, res, record, used, segment=segment, overwrite=force)
        print(f"wrote {output}", file=sys.stderr if quiet_stdout else sys.stdout)
    if report:
        if output:
            fit_report(read_fit(output), report)
        else:  # the report alone: the record goes through a temporary file
            fd, tmp = tempfile.mkstemp(suffix=".h5")
            os.close(fd)
            try:
                write_fit(tmp, res, record, used, segment=segment, overwrite=True)
                fit_report(read_fit(tmp), report)
            finally:
                os.unlink(tmp)
        print(f"wrote {report}", file=sys.stderr if quiet_stdout else sys.stdout)


def _print_fit(res, record, used, args):
    """The fit in words, in the data's own units (and mu*H in N/m)."""
    du, fu = _shown_units(record)
    if not res.success:
        say(f"fit failed (status {res.status}): {res.message}")
    counts = ", ".join(f"{k} {v}" for k, v in record.counts().items())
    name = Path(record.path).name if args.example else record.path
    say(f"data   = {name}: {len(record)} rows ({counts}); fitted the {args.segment} segment, "
          f"{int(used.sum())} rows")
    for text in getattr(record, "notes", ()):
        say(f"note: {text}")
    say(f"scene  = {res.scene.describe(res.R_L)}")
    lo, hi = res.mu_H_ci95
    say(f"mu*H   = {res.mu_H:.4g} N/m (um*MPa)   95% CI [{lo:.4g}, {hi:.4g}]")
    for e in res.derived.values():
        if e.of is None:  # from a given scene value (mu of a given thickness)
            say(_estimate_line(e))
    if res.model_note:
        say(f"model  = {res.model_note}")
    if res.model == "solid":
        say(_solid_line(res.curve, res.mesh_error))
    elif res.thickness is not None and res.measured_model_error is None:
        say(model_error_line(res.scene))
    show = (lambda v, unit, kind: format_in(v, unit, kind).split(" ")[0])
    if "offset" in res.fitted:
        o1, o2 = res.offset_ci95
        say(f"offset = {format_in(res.offset, du, 'length')}   95% CI [{show(o1, du, 'length')}, "
              f"{show(o2, du, 'length')}] {du} (the contact point)")
    if res.baseline_model != "none":
        b1, b2 = res.baseline_ci95
        say(f"baseline = {format_in(res.baseline, fu, 'force')}   95% CI [{show(b1, fu, 'force')}, "
              f"{show(b2, fu, 'force')}] {fu} ({res.baseline_model})")
    if res.baseline_model == "linear":
        s1, s2 = res.baseline_slope_ci95
        say(f"baseline slope = {res.baseline_slope:.4g} N/m   95% CI [{s1:.4g}, {s2:.4g}]")
    for name, param in SHAPE_PARAMETERS.items():
        if name in res.fitted:
            v, (c1, c2) = res.shape_values[name], res.shape_ci95[name]
            if param.display_unit:
                unit = param.display_unit
                value = format_in(v, unit, param.unit_kind)
                interval = f"[{show(c1, unit, param.unit_kind)}, {show(c2, unit, param.unit_kind)}] {unit}"
            else:
                value, interval = f"{v:.4g}", f"[{c1:.4g}, {c2:.4g}]"
            say(f"{name:<6s} = {value}   95% CI {interval} (profile likelihood; {res.curves_computed} model "
                 f"curves){param.note}")
            for e in res.derived.values():
                if e.of == name:
                    say(_estimate_line(e))
    if res.max_depth is not None:
        say(f"range  = depths up to {format_in(res.max_depth, du, 'length')} beyond the contact point's first guess "
            f"(--max-depth; deeper rows left out)")
    if res.max_force is not None:
        say(f"range  = forces up to {format_in(res.max_force, fu, 'force')} (--force-max; rows above left out)")
    say(f"rms residual = {format_in(res.residual_rms, fu, 'force')} over {res.n} points; R_L = "
          f"{args.radius}; {res.weights} weights")
    say(weights_check_line(res.weights, res.weights_check))
    for line in diagnostics_lines(res.quality, res.fitted, res.correlation,
                                  {k: getattr(res, k) for k in ("noise_sigma", "aic", "bic", "runs_p",
                                                                "residual_autocorrelation")},
                                  lambda v: format_in(v, fu, "force")):
        say(line)
    for text in res.warnings:
        say(f"warning: {text}")
    if getattr(args, "stability", False):
        say(res.stability_verdict)
    if res.stability_note:
        say(f"stability not analysed where: {res.stability_note}")


def _shown_units(record):
    """The units the fit is printed in: the data's own, or for data in bare SI (AFM files, in m
    and N) the unit that suits its size (um or nm, nN or pN); files keep SI."""
    du, fu = record.units["displacement"], record.units["force"]
    if du == "m" and np.isfinite(record.displacement).any():
        du = readable_unit(np.nanmax(record.displacement) - np.nanmin(record.displacement), "length")
    if fu == "N" and np.isfinite(record.force).any():
        fu = readable_unit(np.nanmax(np.abs(record.force)), "force")
    return du, fu


def _solid_line(c, mesh_error):
    """What the solid fitted is: its mesh and its error, its displacement, where its curve came from."""
    where = "kept in the code cache" if c.kept else f"computed in {c.wall_time:.1f} s"
    error = ("--mesh-check measures its mesh's error" if mesh_error is None else
             f"mu*H {100 * mesh_error:.2g} % off on a mesh 2/3 as fine")
    held, abscissa = solid_words(c.scene)
    return (f"solid  = FElupe, {c.elements[0]}x{c.elements[1]} quadratic elements ({error}), {held}; "
            f"{abscissa} as the data's; curve {where}")


def _estimate_line(e):
    """A line of a quantity a fit reports in lab units (``FitResult.derived``)."""
    f = unit_factor(e.display_unit, unit_kind(e.display_unit))
    c1, c2 = e.ci95
    return f"{e.label:<6s} = {e.value / f:.4g} {e.display_unit}   95% CI [{c1 / f:.4g}, {c2 / f:.4g}] ({e.note})"
