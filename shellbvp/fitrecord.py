"""A fit as a record: one NeXus HDF5 file with the data, the model and the result.

Layout (format ``shellbvp-fit``, version 1; every dataset has a ``units`` attribute,
SI units, ``"1"`` nondimensional, ``""`` text)::

    /                          attrs: format, format_version, package_version, created,
                                      NX_class = "NXroot", default = "fit"
    /fit                       NXentry; attrs: default = "data", title, program_name, success,
                                      status, message
    /fit/data                  NXdata: signal = "force", axes = ["displacement"],
                               auxiliary_signals = ["model_force"]: the data as read, every row
                               in the file's (time) order
      displacement, force      (n,) m, N
      time                     (n,) s (when the file has a time column)
      used                     (n,) 1: the rows fitted
      segment                  (n,) approach / loading / hold / retraction / other
      line                     (n,) the row's line in the source file
      model_force, residual    (n,) N: the fitted model (baseline included) and model - data
      weight                   (n,) 1: the noise model's 1/sigma (largest 1; NaN where not fitted)
    /fit/model                 NXdata: signal = "force", axes = ["displacement"]: the model curve
      displacement, force      (m,) m, N: offset + R_L delta, baseline + mu_H R_L F
      delta, F                 (m,) 1: the nondimensional curve
    /fit/parameters            NXparameters: mu_H (N/m), offset (m), baseline (N),
                               baseline_slope (N/m), R_L (m), residual_rms (N), n_points (1),
                               noise_sigma (N), aic, bic, runs_p, residual_autocorrelation, model_error
                               (1: the shell model's error beside the interval; NaN: none), max_depth
                               (m: the fitting range's deepest depth; NaN: all data), max_force (N: the
                               fitting range's largest force; NaN: all data), and every
                               shape parameter and derived quantity of shellbvp.shape_parameters
                               (beta (1), alpha (1, NaN for other materials), pressure (1), pressure_Pa
                               (Pa, NaN unless fitted), ...) -- scalars; correlation (k, k); <name>_ci95
                               (2,) for each parameter fitted and its derived quantities; attrs: fitted,
                               baseline_model, weights, segment, model (shell or solid: what
                               delta is, the mid-surface pole's or the indenter's displacement),
                               model_note (why that model, with model auto), model_error_source
                               (measured: on this scene by the solid; map: the mapped scenes' bound;
                               mesh: the solid's own, by its mesh check), stability_verdict
                               (whether the fitted shell's stability was checked, and to what depth),
                               weights_check (one line: mu*H refitted with another noise model, or
                               not checked)
    /fit/warnings              (k,) the fit's warnings (text); attr codes
    /fit/sample                NXsample; attrs: scene (JSON, rebuilds the Scene), scene_<key>
    /fit/source                NXnote: file_name, sha256, columns (JSON), units (JSON), inverted
                               (JSON list: the columns whose sign was flipped), notes (JSON list: what
                               reading left out of the file and why) -- text

Written atomically (temporary file + rename); an existing file is replaced only with
``overwrite=True``.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import schema as sc
from .fit_checks import weights_check_line
from .fitting import fit_quality
from .nexus import DIMENSIONLESS, number_dataset, string_dataset
from .paths import atomic_hdf5, check_output_path, open_hdf5
from .scene import Scene
from .scene_parameters import LiveMapping
from .shape_parameters import DERIVED, SHAPE_PARAMETERS
from .version import __version__

__all__ = ["FitRecord", "write_fit", "read_fit", "is_fit_file", "FIT_FORMAT", "FIT_FORMAT_VERSION",
           "PARAMETER_UNITS"]

FIT_FORMAT = "shellbvp-fit"
FIT_FORMAT_VERSION = 1
#: The fit's own scalar parameters in ``/fit/parameters`` with their units.
_FIT_UNITS = {"mu_H": "N/m", "offset": "m", "baseline": "N", "baseline_slope": "N/m", "R_L": "m", "residual_rms": "N",
              "n_points": DIMENSIONLESS, "noise_sigma": "N", "aic": DIMENSIONLESS, "bic": DIMENSIONLESS,
              "runs_p": DIMENSIONLESS, "residual_autocorrelation": DIMENSIONLESS, "model_error": DIMENSIONLESS,
              "max_depth": "m", "max_force": "N"}
#: Units of the scalar parameters in ``/fit/parameters``: the fit's own, every shape parameter's and
#: every derived quantity's (:mod:`shellbvp.shape_parameters`).
PARAMETER_UNITS = LiveMapping(lambda: {**_FIT_UNITS, **{p.name: p.unit for p in SHAPE_PARAMETERS.values()},
                                       **{d.name: d.unit for d in DERIVED.values()}})
#: Parameters every file of format version 1 holds; the others (later additions) read as NaN when absent.
_REQUIRED_PARAMETERS = ("mu_H", "offset", "baseline", "baseline_slope", "beta", "alpha", "R_L", "residual_rms",
                        "n_points")


@dataclass
class FitRecord:
    """What a fit file holds (:func:`read_fit`), in SI units.

    Attributes
    ----------
    data : dict of ndarray
        ``displacement``, ``force``, ``time`` (or absent), ``used`` (bool), ``segment`` (str),
        ``line``, ``model_force``, ``residual``, ``weight`` -- one entry per row of the source.
    model : dict of ndarray
        The model curve: ``displacement`` (m), ``force`` (N), ``delta``, ``F`` (nondimensional).
    parameters : dict of float
        ``mu_H``, ``offset``, ``baseline``, ``baseline_slope``, ``R_L``, ``residual_rms``,
        ``n_points``, the diagnostics, and every shape parameter and derived quantity
        (``beta``, ``alpha``, ``pressure``, ``pressure_Pa``, ...; :data:`PARAMETER_UNITS`).
    intervals : dict of (float, float)
        The 95 % interval of each fitted parameter and of the fitted shape parameter's
        derived quantities.
    fitted : list of str
    settings : dict
        ``baseline_model``, ``weights``, ``segment``, ``model`` (``"shell"`` or ``"solid"``).
    warnings : list of str
    warning_codes : list of str
    scene : Scene
    source : dict
        ``file_name``, ``sha256``, ``columns``, ``units`` (the units the file was in), ``inverted``
        (the columns whose sign was flipped on reading), ``notes`` (what reading left out and why).
    success : bool
    status : int
    message : str
    version : str
        Package version that wrote the file.
    path : str
    """

    data: dict
    model: dict
    parameters: dict
    intervals: dict
    fitted: list
    settings: dict
    warnings: list
    warning_codes: list
    scene: object
    source: dict
    success: bool
    status: int
    message: str
    version: str = ""
    correlation: object = None
    path: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def quality(self) -> str:
        """``good``, ``fair`` or ``poor`` (:func:`shellbvp.fitting.fit_quality`), from what the file holds."""
        error = self.parameters.get("model_error", math.nan)
        return fit_quality(self.success, self.warning_codes, self.parameters["mu_H"],
                           self.intervals.get("mu_H", (math.nan, math.nan)), self.correlation, self.fitted,
                           error if math.isfinite(error) else None)


def write_fit(path, result, record, used, *, segment="loading", overwrite=False):
    """Write a fit and its data to ``path`` (HDF5, NeXus NXentry ``/fit``), atomically.

    Parameters
    ----------
    path : str or Path
    result : FitResult
        The fit (:func:`shellbvp.fitting.fit_record`).
    record : InstrumentRecord
        The data as read (:func:`shellbvp.instrument.read_instrument`).
    used : ndarray of bool, shape (len(record),)
        The rows fitted.
    segment : str
        The segment fitted (recorded in the settings).
    overwrite : bool
        Replace an existing file (otherwise ``FileExistsError``).
    """
    import h5py

    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (CLI: --overwrite) to replace it")
    check_output_path(path, overwrite=True)
    d, f = record.displacement, record.force
    model_force = result.model_force(d)
    weight = np.full(d.size, np.nan)
    if result.point_weights is not None and np.sum(used) == result.point_weights.size:
        weight[used] = result.point_weights
    with atomic_hdf5(path) as h:  # built in memory: a full disk is one OSError naming the file
        h.attrs.update({"format": FIT_FORMAT, "format_version": FIT_FORMAT_VERSION,
                        "package_version": __version__, "NX_class": "NXroot", "default": "fit",
                        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")})
        e = h.create_group("fit")
        e.attrs.update({"NX_class": "NXentry", "default": "data", "program_name": f"shellbvp {__version__}",
                        "title": f"fit of mu*H to {Path(record.path).name}", "success": bool(result.success),
                        "status": int(result.status), "message": result.message})
        g = e.create_group("data")
        g.attrs.update({"NX_class": "NXdata", "signal": "force",
                        "axes": np.array(["displacement"], dtype=h5py.string_dtype()),
                        "auxiliary_signals": np.array(["model_force"], dtype=h5py.string_dtype())})
        number_dataset(g, "displacement", d, "m", "indenter displacement (as read)")
        number_dataset(g, "force", f, "N", "force (as read)")
        if record.time is not None:
            number_dataset(g, "time", record.time, "s", "time")
        number_dataset(g, "used", np.asarray(used, bool), DIMENSIONLESS, "row fitted")
        string_dataset(g, "segment", [str(s) for s in record.segments], "segment of the record")
        number_dataset(g, "line", np.asarray(record.line, int), DIMENSIONLESS, "line in the source file")
        number_dataset(g, "model_force", model_force, "N", "fitted model force (baseline included)")
        number_dataset(g, "residual", model_force - f, "N", "model - data")
        number_dataset(g, "weight", weight, DIMENSIONLESS, "noise model weight 1/sigma (largest 1)")
        m = e.create_group("model")
        m.attrs.update({"NX_class": "NXdata", "signal": "force",
                        "axes": np.array(["displacement"], dtype=h5py.string_dtype())})
        c = result.curve
        delta, F = np.r_[0.0, np.asarray(c.delta, float)], np.r_[0.0, np.asarray(c.force, float)]
        x = result.offset + result.R_L * delta
        number_dataset(m, "displacement", x, "m", "displacement: offset + R_L delta")
        number_dataset(m, "force", result.model_force(x), "N", "model force: baseline + mu_H R_L F")
        number_dataset(m, "delta", delta, DIMENSIONLESS, "indenter displacement / R_L (the 3D solid's)"
                       if result.model == "solid" else "pole displacement / R_L")
        number_dataset(m, "F", F, DIMENSIONLESS, "force / (mu H R_L)")
        p = e.create_group("parameters")
        p.attrs.update({"NX_class": "NXparameters", "baseline_model": result.baseline_model,
                        "weights": result.weights, "segment": segment, "model": result.model,
                        "model_note": result.model_note, "model_error_source": _error_source(result),
                        "stability_verdict": getattr(result, "stability_verdict", "stability: not checked"),
                        "weights_check": weights_check_line(result.weights, getattr(result, "weights_check", None)),
                        "fitted": np.array(list(result.fitted), dtype=h5py.string_dtype())})
        values = {"mu_H": result.mu_H, "offset": result.offset, "baseline": result.baseline,
                  "baseline_slope": result.baseline_slope, "R_L": result.R_L,
                  "residual_rms": result.residual_rms, "n_points": result.n,
                  "model_error": math.nan if result.model_error is None else result.model_error[0],
                  "max_depth": math.nan if result.max_depth is None else result.max_depth,
                  "max_force": math.nan if getattr(result, "max_force", None) is None else result.max_force,
                  **{k: getattr(result, k) for k in ("noise_sigma", "aic", "bic", "runs_p",
                                                      "residual_autocorrelation")},
                  **{k: np.nan if getattr(result, k) is None else getattr(result, k)
                     for k in (*SHAPE_PARAMETERS, *DERIVED)}}
        for name, v in values.items():
            number_dataset(p, name, float(v), PARAMETER_UNITS[name])
        if result.correlation is not None:
            number_dataset(p, "correlation", np.asarray(result.correlation, float), DIMENSIONLESS,
                           "correlation of the fitted parameters (rows and columns in the order of fitted)")
        for name in _with_intervals(result):
            number_dataset(p, f"{name}_ci95", np.asarray(getattr(result, f"{name}_ci95"), float),
                           PARAMETER_UNITS[name], f"95 % interval of {name}")
        first = getattr(result, "first_instability", None)
        if first is not None:  # fit(stability=True) found the shell unstable within the fitted depths
            number_dataset(p, "first_instability_delta", float(first.delta), DIMENSIONLESS,
                           "where the axisymmetric shell first loses stability: pole displacement / R_L")
            number_dataset(p, "first_instability_displacement", result.offset + result.R_L * float(first.delta),
                           "m", "the same as a displacement of the data (offset + R_L delta)")
            number_dataset(p, "first_instability_mode", int(first.mode), DIMENSIONLESS,
                           "the Fourier mode n that goes unstable")
        w = string_dataset(e, "warnings", list(result.warnings), "warnings of the fit")
        w.attrs["codes"] = np.array(list(result.warning_codes), dtype=h5py.string_dtype())
        s = e.create_group("sample")
        s.attrs["NX_class"] = "NXsample"
        scene = result.scene.to_dict()
        s.attrs["scene"] = json.dumps(scene, sort_keys=True)
        for k, v in scene.items():
            if not isinstance(v, dict):
                s.attrs[f"scene_{k}"] = v
        src = e.create_group("source")
        src.attrs["NX_class"] = "NXnote"
        string_dataset(src, "file_name", str(record.path))
        string_dataset(src, "sha256", record.sha256)
        string_dataset(src, "columns", json.dumps({k: str(v) for k, v in record.columns.items()}))
        string_dataset(src, "units", json.dumps(record.units, ensure_ascii=False))
        string_dataset(src, "inverted", json.dumps(list(getattr(record, "inverted", ()))))
        string_dataset(src, "notes", json.dumps(list(getattr(record, "notes", ())), ensure_ascii=False),
                       "what reading left out of the source file and why (JSON list of text)")


def _error_source(result):
    """Where a fit's ``model_error`` comes from: measured on this scene by the solid, the map, or none."""
    if result.model_error is None:
        return ""
    if result.model == "solid":
        return "mesh"
    return "measured" if result.measured_model_error is not None else "map"


def _inverted(src):
    """The flipped columns of a record's source (files before the option: none)."""
    if "inverted" not in src:
        return []
    inv = sc.parse_json(sc.text_dataset(src, "inverted", ndim=0), "source/inverted")
    if not (isinstance(inv, list) and all(x in ("displacement", "force") for x in inv)):
        raise ValueError("source/inverted must be a JSON list of 'displacement' and 'force'")
    return inv


def _notes(src):
    """The reading notes of a record's source (files before them: none)."""
    if "notes" not in src:
        return []
    notes = sc.parse_json(sc.text_dataset(src, "notes", ndim=0), "source/notes")
    if not (isinstance(notes, list) and all(isinstance(x, str) for x in notes)):
        raise ValueError("source/notes must be a JSON list of text")
    return notes


def _with_intervals(result):
    """The names whose 95 % intervals the file holds: the fitted parameters and the derived
    quantities of a fitted shape parameter."""
    derived = [d.name for name in result.fitted if name in SHAPE_PARAMETERS for d in SHAPE_PARAMETERS[name].derived]
    return [*result.fitted, *derived]


def is_fit_file(path) -> bool:
    """True when ``path`` is an HDF5 file of format ``shellbvp-fit``."""
    import h5py

    try:
        with h5py.File(path, "r") as h:
            fmt = h.attrs.get("format")
    except (OSError, ValueError):
        return False
    fmt = fmt.decode() if isinstance(fmt, bytes) else fmt
    return fmt == FIT_FORMAT


def _text(v):
    return v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v)


def read_fit(path) -> FitRecord:
    """Read a fit file written by :func:`write_fit` (``shellbvp fit -o FILE.h5``).

    Parameters
    ----------
    path : str or Path
        The fit file (HDF5, format ``shellbvp-fit``; the layout is in this module's docstring).

    Returns
    -------
    FitRecord
        The data, the model curve, the parameters and their intervals, the settings, the
        scene and the source file's name, hash and units, in SI units.

    Raises
    ------
    ValueError
        One line naming the file and what is missing or malformed.

    Examples
    --------
    >>> import os, tempfile, shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> from shellbvp.fitrecord import write_fit
    >>> rec = sb.read_instrument(example_data_path())
    >>> res, used = sb.fit_record(sb.Scene.preset("fit"), rec, R_L=0.3e-3)
    >>> path = os.path.join(tempfile.mkdtemp(), "fit.h5")
    >>> write_fit(path, res, rec, used)
    >>> fr = sb.read_fit(path)
    >>> fr.success, fr.fitted, fr.settings["segment"], fr.source["units"]
    (True, ['mu_H', 'offset'], 'loading', {'displacement': 'mm', 'force': 'mN'})
    >>> lo, hi = fr.intervals["mu_H"]
    >>> print(f"mu*H = {fr.parameters['mu_H']:.2f} N/m, 95% [{lo:.2f}, {hi:.2f}]")
    mu*H = 51.91 N/m, 95% [51.52, 52.30]
    >>> int(fr.data["used"].sum()), fr.data["model_force"].shape
    (40, (40,))
    """

    path = Path(path)
    with open_hdf5(path, fmt=FIT_FORMAT, group="fit", kind="fit") as h:
        try:
            sc.format_version(h, FIT_FORMAT_VERSION)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        try:
            e = h["fit"]
            g = e["data"]
            n = sc.dataset(g, "displacement").shape[0]
            data = {k: sc.dataset(g, k, length=n) for k in ("displacement", "force", "model_force", "residual",
                                                             "weight")}
            data["line"] = sc.dataset(g, "line", kind="int", length=n)
            data["used"] = sc.dataset(g, "used", kind="bool", length=n)
            data["segment"] = np.array(sc.text_dataset(g, "segment", length=n))
            if "time" in g:
                data["time"] = sc.dataset(g, "time", length=n)
            gm = e["model"]
            m = sc.dataset(gm, "delta").shape[0]
            model = {k: sc.dataset(gm, k, length=m) for k in ("displacement", "force", "delta", "F")}
            p = e["parameters"]
            params = {k: sc.scalar(p, k, finite=False, required=k in _REQUIRED_PARAMETERS)
                      for k in PARAMETER_UNITS}
            if not (params["R_L"] > 0 and math.isfinite(params["R_L"])):
                raise ValueError(f"parameters/R_L must be a length > 0; got {params['R_L']!r}")
            fitted = [sc.text(s, "parameters.fitted") for s in np.atleast_1d(p.attrs["fitted"])]
            unknown = sorted(set(fitted) - set(PARAMETER_UNITS))
            if unknown or "mu_H" not in fitted:
                raise ValueError(f"parameters.fitted must name mu_H and known parameters; got {fitted}")
            intervals = {k: tuple(sc.dataset(p, f"{k}_ci95", length=2)) for k in fitted}
            intervals.update({k: tuple(sc.dataset(p, f"{k}_ci95", length=2)) for k in DERIVED if f"{k}_ci95" in p})
            correlation = None
            if "correlation" in p:  # files before the diagnostics have none
                correlation = np.asarray(sc.dataset(p, "correlation", ndim=2, length=len(fitted)), float)
                if correlation.shape != (len(fitted), len(fitted)):
                    raise ValueError(f"parameters/correlation must be {len(fitted)} x {len(fitted)} (fitted); got "
                                     f"{correlation.shape}")
            settings = {k: sc.attr_text(p, k) for k in ("baseline_model", "weights", "segment")}
            settings["model"] = sc.attr_text(p, "model") if "model" in p.attrs else "shell"  # files before it: shell
            for k in ("model_note", "model_error_source", "stability_verdict", "weights_check"):
                settings[k] = sc.attr_text(p, k) if k in p.attrs else ""
            if settings["model"] not in ("shell", "solid"):
                raise ValueError(f"parameters.model must be 'shell' or 'solid'; got {settings['model']!r}")
            warnings = sc.text_dataset(e, "warnings")
            codes = [sc.text(s, "warnings.codes") for s in np.atleast_1d(e["warnings"].attrs.get("codes", []))]
            scene = Scene.from_dict(sc.parse_json(sc.attr_text(e["sample"], "scene"), "sample.scene"))
            src = e["source"]
            source = {"file_name": sc.text_dataset(src, "file_name", ndim=0),
                      "sha256": sc.text_dataset(src, "sha256", ndim=0),
                      "columns": sc.parse_json(sc.text_dataset(src, "columns", ndim=0), "source/columns"),
                      "units": sc.parse_json(sc.text_dataset(src, "units", ndim=0), "source/units"),
                      "inverted": _inverted(src), "notes": _notes(src)}
            success = sc.attr_bool(e, "success")
            status = sc.attr_int(e, "status", low=0, high=99)
            if success != (status == 0):
                raise ValueError(f"success ({success}) and status ({status}) disagree")
            if success and not (math.isfinite(params["mu_H"]) and params["mu_H"] > 0):
                raise ValueError(f"a successful fit must have mu_H > 0; got {params['mu_H']!r}")
            out = FitRecord(data=data, model=model, parameters=params, intervals=intervals, fitted=fitted,
                            settings=settings, warnings=warnings, warning_codes=codes, scene=scene, source=source,
                            success=success, status=status, message=sc.attr_text(e, "message"),
                            version=sc.attr_text(h, "package_version") if "package_version" in h.attrs else "",
                            path=str(path), correlation=correlation)
        except (ValueError, KeyError, TypeError, OSError, RecursionError) as exc:
            what = str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"
            raise ValueError(f"{path}: incomplete or corrupt fit file ({what})") from None
    return out
