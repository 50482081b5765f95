"""Curves as records: the per-point schema, :class:`Curve`, and its HDF5 file (atomic writes, a documented
self-describing layout).  The continuation (``shellbvp.continuation``) fills a Curve; this module owns its shape.

Layout (format ``shellbvp-curve``, version 4, NeXus; versions 1-3 kept the same group at
``/curve``, under the root, and read as before; version 1 lacked topology, S1 and
ring_force_inner, which read as a single cap; version 2 lacked legendre_min,
contact_edge and edge_jump_ls/ks, which read as NaN and "")::

    /                       attrs: format, format_version, package_version, created (UTC ISO),
                            default = "entry"
    /entry                  NXentry; attrs: default = "curve"
    /entry/curve            NXdata group (below: /curve for short); attrs:
                              NX_class = "NXdata", signal = "force", axes = ["delta"],
                              scene (JSON: rebuilds the Scene exactly, user formulas as plain text),
                              scene_<key> (gamma, rho, beta, xi, contact, material_family, ...,
                              shell_lower_R of halves that differ: the same, readable at a glance),
                              settings (JSON: solver and continuation settings),
                              stop_reason, complete (bool), interrupted (bool),
                              energy_identity_max (max |dE/ddelta - F| over the points),
                              units: "nondimensional" or, with R_L and mu*H given,
                              R_L_m, mu_H_N_per_m (then delta_m, force_N datasets exist)
    /curve/delta            (n,) axis: pole displacement / R_L
    /curve/force            (n,) signal: indenter force / (mu H R_L)
    /curve/<field>          (n,) each of POINT_FIELDS, plus
                            energy_residual (dE/ddelta - F) and flags (strings);
                            topology (strings: shellbvp.configurations.CONFIGURATION_NAMES),
                            contact_edge (strings: smooth, corner, paper or pinned, shellbvp.edge_models);
                            error_method (strings: how force_error/delta_error were
                            made: richardson, calibrated, or empty: not estimated);
                            pressure (the pressure below the shell: the scene's, or
                            under volume control the one that holds the volume);
                            stability_min, critical_mode (curve(stability=...): the
                            smallest eigenvalue over Fourier modes and its n; NaN and -1
                            where not computed, also in files that lack them)
    /curve attrs            first_instability (JSON; with _delta, _force, _mode and, with
                            SI columns, _delta_m, _force_N beside it): where the curve
                            first loses axisymmetric stability, when it was looked for and found
    /curve/profiles/point_<i>   optional (profiles=True): S, region, r, z, ... at the
                            mesh nodes of point i (see Solution.profile)

Files are written to a temporary file in the same directory and renamed into
place, so a reader never sees a half-written file; an existing file is never
replaced unless ``overwrite=True``.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .configurations import CONFIGURATION_NAMES, is_point_load
from .edge_models import EDGE_MODELS
from .inflation import INFLATED_FIELDS, InflatedStart
from .nexus import new_file
from .paths import open_hdf5
from .scene import Scene
from .schema import MAX_DATASET_BYTES, parse_json
from .thickness import force_at

__all__ = ["Curve", "FirstInstability", "STABILITY_FIELDS", "POINT_FIELDS", "CAP_FIELD_DEFAULTS", "FORMAT",
           "point_record", "energy_residual", "write_curve", "read_curve", "write_curve_group", "read_curve_group",
           "FORMAT_VERSION"]

FORMAT = "shellbvp-curve"
FORMAT_VERSION = 4

#: Per-point fields of a curve (arrays of the Curve and datasets of its HDF5 file).
POINT_FIELDS = (
    "delta", "force", "lambda0", "Sc", "status", "valid", "max_residual", "nodes", "niter",
    "force_error", "delta_error", "energy", "ring_force", "cap_force", "pressure_min",
    "penetration", "force_defect", "edge_legendre", "wall_time", "topology", "S1", "ring_force_inner",
    "legendre_min", "contact_edge", "edge_jump_ls", "edge_jump_ks", "error_method", "pressure", "shear_delta",
)
#: Fields a single-cap state does not carry, with their cap values (also what files of
#: format version 1, which predate them, read as).
CAP_FIELD_DEFAULTS = {"topology": "cap", "S1": 0.0, "ring_force_inner": 0.0}
#: Fields that files of format version 2 predate, with what they read as (not computed then).
V2_FIELD_DEFAULTS = {"legendre_min": float("nan"), "contact_edge": "", "edge_jump_ls": float("nan"),
                     "edge_jump_ks": float("nan")}
#: Fields added within format version 3 (additive: older readers ignore them), with what
#: earlier files read as.  error_method: "richardson" | "calibrated" | "" (not estimated).
V3_FIELD_DEFAULTS = {"error_method": "", "pressure": float("nan"),  # pressure: the scene's, filled in on reading
                     "shear_delta": 0.0}
_MISSING_FIELD_DEFAULTS = {**CAP_FIELD_DEFAULTS, **V2_FIELD_DEFAULTS, **V3_FIELD_DEFAULTS}
#: Per-point stability fields (shellbvp.curve_stability), with their value where not computed
#: (also what files without them read as)
STABILITY_FIELDS = {"stability_min": math.nan, "critical_mode": -1}


@dataclass(frozen=True)
class FirstInstability:
    """The first unstable depth along a curve.

    Attributes
    ----------
    delta, force : float
        Where the smallest eigenvalue crosses zero (package units), interpolated linearly
        between the two states of the final bracket; with ``located`` False, the first unstable
        recorded point's.
    mode : int
        The Fourier mode n that goes unstable.
    located : bool
        The crossing was narrowed to ``bracket`` by states solved in between.
    bracket : (float, float)
        The last stable and the first unstable depth known.
    message : str
        How it was found, or why it was not narrowed.
    """

    delta: float
    force: float
    mode: int
    located: bool
    bracket: tuple
    message: str = ""

    def to_dict(self) -> dict:
        """As JSON can hold it: an unknown end of the bracket (NaN) as None (null)."""
        d = asdict(self)
        d["bracket"] = [float(b) if math.isfinite(b) else None for b in self.bracket]
        return d

    @classmethod
    def from_dict(cls, d) -> "FirstInstability":
        return cls(delta=float(d["delta"]), force=float(d["force"]), mode=int(d["mode"]),
                   located=bool(d["located"]), bracket=tuple(math.nan if b is None else float(b) for b in d["bracket"]),
                   message=str(d["message"]) if "message" in d else "")

    def summary(self) -> str:
        how = "" if self.located else f"; {self.message}"
        return f"loses axisymmetric stability at delta = {self.delta:.6g} (n = {self.mode}{how})"


@dataclass
class Curve:
    """A force–displacement curve: per-point arrays and how it was made.

    Attributes
    ----------
    scene : Scene
    delta, force, lambda0, Sc, ... : ndarray
        One entry per point (see ``POINT_FIELDS``), in the order computed along
        the branch (increasing delta unless the branch folds back).
    energy_residual : ndarray
        ``dE/ddelta - F`` at each point, dE/ddelta by finite differences of the
        energies along the curve (second order on the non-uniform grid): ~0 for
        the smooth contact model, finite for the paper's.
    flags : list of str
        Per point, "; "-joined validity flags ("" when valid).
    stop_reason : str
    complete : bool
        The stopping rule was reached (False: failure or interruption).
    interrupted : bool
    settings : dict
        Its :class:`~shellbvp.curve_settings.CurveSettings` as a dict, and what was learned (:meth:`learned`).
    solutions : list of Solution
        In memory only (profiles); not stored unless ``to_hdf5(profiles=True)``.

    Examples
    --------
    >>> import os, tempfile, shellbvp as sb
    >>> c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    >>> c.summary()
    '2 points, delta 0.1..0.2, F 0.1505..0.3639, 2 valid; stopped: all requested deltas computed'
    >>> path = os.path.join(tempfile.mkdtemp(), "base.h5")
    >>> c.to_hdf5(path, units={"R_L": 0.3e-3, "mu_H": 52.0})    # SI columns too
    >>> sb.read_curve(path).summary() == c.summary()
    True
    """

    scene: object
    points: dict
    flags: list
    stop_reason: str
    complete: bool
    interrupted: bool
    settings: dict
    solutions: list = field(default_factory=list, repr=False)
    version: str = ""
    units: dict = None  # {"R_L": m, "mu_H": N/m} when the file had SI columns (to_hdf5(units=...))
    #: the first unstable depth (:class:`FirstInstability`, shellbvp.curve_stability), None if none was found
    first_instability: object = None
    #: under pressure, where the curve starts (:class:`shellbvp.inflation.InflatedStart`): the
    #: continuation's first step, which the file keeps; None without pressure
    inflated: object = None

    def __getattr__(self, name):
        points = self.__dict__.get("points", {})
        if name in points:
            return points[name]
        raise AttributeError(name)

    def __len__(self):
        return len(self.points["delta"])

    @property
    def energy_residual(self):
        """``dE/ddelta - F`` at each point (see the class docstring)."""
        return energy_residual(self.points["delta"], self.points["energy"], self.points["force"])

    def force_at(self, deltas):
        """F at pole displacements ``deltas`` of the shell with its thickness: interpolated at
        ``delta + shear_delta`` (:func:`shellbvp.thickness.force_at`); NaN outside the curve."""
        return force_at(self, deltas)

    def to_hdf5(self, path, *, profiles: bool = False, overwrite: bool = False, units=None):
        """Write the curve to an HDF5 file atomically (see :func:`write_curve`); ``units`` default:
        the lab scales it was read with, if any."""
        write_curve(self, path, profiles=profiles, overwrite=overwrite, units=units or self.units)

    def learned(self, **facts):
        """Record beside the settings what a step learned (``topology_switches``, ``wall_time``, ...)."""
        self.settings.update(facts)

    def topology_summary(self) -> str:
        """Runs of contact topology along the curve, e.g. 'point x2, line x6, cap x27'."""
        runs = [f"{k} x{len(list(g))}" for k, g in itertools.groupby(self.points["topology"])]
        switches = self.settings.get("topology_switches") or []
        where = "; ".join(f"{s['from']} -> {s['to']} at delta = {s['delta']:.6g}"
                          + (f", {s['kind'].split(':')[0]}" if s.get("kind") else "") for s in switches)
        return ", ".join(runs) + (f" (switch {where})" if where else "")

    def summary(self) -> str:
        """One line: points, ranges of delta and F, valid points, why it stopped."""
        n = len(self)
        if n == 0:
            return f"0 points ({self.stop_reason})"
        d, F = self.points["delta"], self.points["force"]
        nvalid = int(np.sum(self.points["valid"]))
        unstable = f"; {self.first_instability.summary()}" if self.first_instability is not None else ""
        return (f"{n} points, delta {d.min():.4g}..{d.max():.4g}, F {F.min():.4g}..{F.max():.4g}, "
                f"{nvalid} valid; stopped: {self.stop_reason}{unstable}")


def energy_residual(delta, energy, force):
    """dE/ddelta - F along a curve (np.gradient, second order, non-uniform spacing)."""
    delta, energy, force = (np.asarray(a, float) for a in (delta, energy, force))
    if delta.size < 3 or np.any(np.diff(delta) == 0):
        return np.full(delta.shape, np.nan)
    with np.errstate(all="ignore"):  # a file's near-equal or non-finite depths: inf/NaN, not warnings
        return np.gradient(energy, delta, edge_order=2) - force


def point_record(sol) -> dict:
    """One point of a curve from a Solution: every POINT_FIELDS value."""
    row = {k: getattr(sol, k) for k in POINT_FIELDS}
    if is_point_load(sol):
        row["S1"] = 0.0
    row["valid"] = bool(sol.valid)
    return row


def _check_units(units):
    if units is None:
        return None
    try:
        R_L, mu_H = float(units["R_L"]), float(units["mu_H"])
    except (KeyError, TypeError, ValueError):
        raise ValueError("units must be a dict with R_L (m) and mu_H (N/m), both numbers") from None
    for name, v in (("R_L", R_L), ("mu_H", mu_H)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0; got {v!r}")
    return R_L, mu_H


def _flat(data: dict, prefix: str):
    """``(prefix_key[_subkey...], value)`` of nested mappings (``scene_shell_lower_R``)."""
    for k, v in data.items():
        yield from _flat(v, f"{prefix}_{k}") if isinstance(v, dict) else ((f"{prefix}_{k}", v),)


def write_curve_group(g, curve, *, profiles=False, units=None):
    """Fill the HDF5 group ``g`` with ``curve`` in the layout of the module docstring (the
    ``/curve`` group of a curve file; sweep files hold one such group per curve)."""
    import h5py

    dims = _check_units(units)
    g.attrs["NX_class"] = "NXdata"
    g.attrs["signal"] = "force"
    g.attrs["axes"] = np.array(["delta"], dtype=h5py.string_dtype())
    scene = curve.scene.to_dict()
    g.attrs["scene"] = json.dumps(scene, sort_keys=True)
    g.attrs.update(_flat(scene, "scene"))
    g.attrs["settings"] = json.dumps(curve.settings, sort_keys=True, default=float)
    g.attrs["stop_reason"] = curve.stop_reason
    g.attrs["complete"] = bool(curve.complete)
    g.attrs["interrupted"] = bool(curve.interrupted)
    res = curve.energy_residual
    g.attrs["energy_identity_max"] = float(np.nanmax(np.abs(res))) if np.any(np.isfinite(res)) else np.nan
    for k, v in curve.points.items():
        v = np.asarray(v)
        if v.dtype.kind in "UO" or k in _STRING_FIELDS:  # strings (topology; also when empty)
            g.create_dataset(k, data=np.array(v, dtype=object), dtype=h5py.string_dtype())
        else:
            g.create_dataset(k, data=v)
    g.create_dataset("energy_residual", data=res)
    g.create_dataset("flags", data=np.array(curve.flags, dtype=object), dtype=h5py.string_dtype())
    g["delta"].attrs["long_name"] = "pole displacement delta / R_L"
    g["force"].attrs["long_name"] = "indenter force F / (mu H R_L)"
    g["shear_delta"].attrs["long_name"] = "pole displacement added by transverse shear / R_L (0: not modelled)"
    for k, (units_, name) in _STABILITY_DATASETS.items():
        if k in g:
            g[k].attrs["units"], g[k].attrs["long_name"] = units_, name
    first = curve.first_instability
    if first is not None:
        g.attrs["first_instability"] = json.dumps(first.to_dict(), sort_keys=True)
        g.attrs["first_instability_delta"], g.attrs["first_instability_force"] = first.delta, first.force
        g.attrs["first_instability_mode"] = first.mode
    if dims is None:
        g.attrs["units"] = "nondimensional"
    else:
        R_L, mu_H = dims
        g.attrs["units"] = "nondimensional; SI columns delta_m, force_N"
        g.attrs["R_L_m"], g.attrs["mu_H_N_per_m"] = R_L, mu_H
        g.create_dataset("delta_m", data=R_L * np.asarray(curve.points["delta"]))
        g.create_dataset("force_N", data=mu_H * R_L * np.asarray(curve.points["force"]))
        if first is not None:
            g.attrs["first_instability_delta_m"] = R_L * first.delta
            g.attrs["first_instability_force_N"] = mu_H * R_L * first.force
    if curve.inflated is not None:
        _write_inflated(g.create_group("inflated"), curve.inflated)
    if profiles:
        pg = g.create_group("profiles")
        for i, sol in enumerate(curve.solutions):
            if sol is None or not sol.success:
                continue
            sg = pg.create_group(f"point_{i:05d}")
            for k, v in sol.profile().items():
                sg.create_dataset(k, data=v)


def _write_inflated(ig, inflated):
    """The inflated state of a pressurised scene, where its curve starts (``Curve.inflated``)."""
    ig.attrs["NX_class"] = "NXnote"
    ig.attrs["long_name"] = "the shell under its pressure before indentation: delta is measured from its pole"
    for name, units, what in INFLATED_FIELDS:
        d = ig.create_dataset(name, data=getattr(inflated, name))
        d.attrs["units"], d.attrs["long_name"] = units, what


def write_curve(curve, path, *, profiles=False, overwrite=False, units=None):
    """Write ``curve`` to ``path`` atomically (temporary file + rename).

    Parameters
    ----------
    curve : Curve
    path : str or Path
    profiles : bool
        Also store each point's fields over S.
    overwrite : bool
        Replace an existing file (otherwise ``FileExistsError``).
    units : dict, optional
        ``{"R_L": metres, "mu_H": N/m}``: also store ``delta_m`` and ``force_N``.
    """
    _check_units(units)  # bad units refused before any file is made
    with new_file(path, FORMAT, FORMAT_VERSION, overwrite=overwrite) as f:
        f.attrs["default"] = "entry"  # NeXus: root -> entry -> curve, the plottable F(delta)
        entry = f.create_group("entry")
        entry.attrs.update({"NX_class": "NXentry", "default": "curve"})
        write_curve_group(entry.create_group("curve"), curve, profiles=profiles, units=units)


def _missing_field(name, n):
    """A field added after format version 1, as an older (single-cap) file reads it."""

    value = _MISSING_FIELD_DEFAULTS[name]
    return np.full(n, value, dtype=object if isinstance(value, str) else float)


#: Per-point stability fields (shellbvp.curve_stability): units and long names; read as "not
#: computed" from files that lack them
_STABILITY_DATASETS = {
    "stability_min": ("1 (mu H / R_L^2 per squared displacement / R_L^2)",
                      "smallest eigenvalue of the second variation over Fourier modes n (NaN: not computed)"),
    "critical_mode": ("1", "the Fourier mode n of stability_min (-1: not computed)"),
}

#: Fields stored as strings; every other point field is numeric.
_STRING_FIELDS = ("topology", "flags", "contact_edge", "error_method")
#: Integer-valued fields (an empty curve stores them as float).
_INTEGER_FIELDS = ("status", "nodes", "niter", "critical_mode")


def _format_version(f):
    v = f.attrs.get("format_version")
    if v is None:
        raise ValueError("format_version attribute missing")
    a = np.asarray(v)
    if a.shape != () or a.dtype.kind not in "iu":
        raise ValueError(f"format_version must be a scalar integer; got {a.dtype} of shape {a.shape}")
    version = int(a)
    if not 1 <= version <= FORMAT_VERSION:
        raise ValueError(f"format version {version} is not one this shellbvp reads (1..{FORMAT_VERSION})")
    return version


def _text_attr(g, name):
    if name not in g.attrs:
        raise ValueError(f"attribute {name} missing")
    v = g.attrs[name]
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    if not isinstance(v, str):
        raise ValueError(f"attribute {name} must be a string; got {type(v).__name__}")
    return v


def _bool_attr(g, name):
    if name not in g.attrs:
        raise ValueError(f"attribute {name} missing")
    a = np.asarray(g.attrs[name])
    if a.shape != () or a.dtype.kind not in "biu" or int(a) not in (0, 1):
        raise ValueError(f"attribute {name} must be a boolean; got {a.dtype} {a.tolist()!r}")
    return bool(a)


def _json_attr(g, name):
    v = parse_json(_text_attr(g, name), f"attribute {name}")  # size and depth bounded before parsing
    if not isinstance(v, dict):
        raise ValueError(f"attribute {name} must be a JSON object; got {type(v).__name__}")
    return v


def _field(g, name, n):
    """Dataset ``name`` as a 1-D array of length ``n`` (strings or numbers as the field is)."""
    import h5py

    d = g[name]
    if not isinstance(d, h5py.Dataset):
        raise ValueError(f"{name} must be a dataset; got a group")
    if d.ndim != 1 or d.shape[0] != n:
        raise ValueError(f"{name} must be a 1-D array of {n} values (one per delta); got shape {d.shape}")
    if n * d.dtype.itemsize > MAX_DATASET_BYTES:  # before a compressed dataset is expanded
        raise ValueError(f"{name} would expand to {n * d.dtype.itemsize / 2**20:.0f} MiB")
    v = d[()]
    if name in _STRING_FIELDS:
        if v.dtype.kind not in "OSU" and n:  # files of empty curves stored an empty float array
            raise ValueError(f"{name} must hold strings; got {v.dtype}")
        return np.array([t.decode("utf-8", "replace") if isinstance(t, bytes) else str(t) for t in v], dtype=str)
    if v.dtype.kind not in "fiub":
        raise ValueError(f"{name} must hold numbers; got {'strings' if v.dtype.kind in 'OSU' else v.dtype}")
    if name in _INTEGER_FIELDS:
        if not np.all(np.isfinite(v)) or np.any(v != np.round(v)):
            raise ValueError(f"{name} must hold integers")
        return v.astype(int)
    if name == "valid":
        if not np.all((v == 0) | (v == 1)):
            raise ValueError("valid must hold booleans")
        return v.astype(bool)
    return v.astype(float)


def _points(g):
    """Every point field (and flags), checked; fields added after version 1 default to a cap's."""
    import h5py


    if "delta" not in g or not isinstance(g["delta"], h5py.Dataset):
        raise ValueError("dataset delta missing")
    if g["delta"].ndim != 1:
        raise ValueError(f"delta must be a 1-D array; got shape {g['delta'].shape}")
    n = g["delta"].shape[0]
    points = {}
    for k in POINT_FIELDS:
        if k in g:
            points[k] = _field(g, k, n)
        elif k in _MISSING_FIELD_DEFAULTS:
            points[k] = _missing_field(k, n)
        else:
            raise ValueError(f"dataset {k} missing")
    for k, missing in STABILITY_FIELDS.items():
        points[k] = _field(g, k, n) if k in g else np.full(n, missing, dtype=type(missing))
    points["topology"] = np.asarray(points["topology"], dtype=str)
    points["contact_edge"] = np.asarray(points["contact_edge"], dtype=str)
    if unknown := sorted(set(points["contact_edge"]) - {"", *EDGE_MODELS}):
        raise ValueError(f"contact_edge must be one of {', '.join(EDGE_MODELS)}; got {str(unknown[0])!r}")
    unknown = sorted(set(points["topology"]) - set(CONFIGURATION_NAMES))
    if unknown:
        raise ValueError(f"topology must be one of {CONFIGURATION_NAMES}; got {str(unknown[0])!r}")
    if not np.all(np.isfinite(points["delta"])):
        raise ValueError("delta must be finite")
    if "flags" not in g:
        raise ValueError("dataset flags missing")
    flags = list(_field(g, "flags", n))
    return points, flags


def _check_settings(settings):
    for s in settings.get("topology_switches", []) or []:
        if not (isinstance(s, dict) and {"from", "to"} <= s.keys() and isinstance(s.get("delta"), (int, float))):
            raise ValueError("settings.topology_switches must list {delta, from, to} objects")


def read_curve_group(g, version: str = ""):
    """The Curve held by the HDF5 group ``g`` (see :func:`write_curve_group`); ``ValueError``
    naming the attribute or dataset that is missing or malformed."""
    scene_data = _json_attr(g, "scene")
    try:
        scene = Scene.from_dict(scene_data)
    except ValueError as exc:  # Scene.from_dict names the field or formula
        raise ValueError(f"attribute scene does not describe a scene: {exc}") from None
    except (KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"attribute scene does not describe a scene ({type(exc).__name__}: "
                         f"{exc})") from None
    settings = _json_attr(g, "settings")
    _check_settings(settings)
    points, flags = _points(g)
    if "pressure" not in g:  # before volume control, every point had the scene's pressure
        points["pressure"] = np.full(points["delta"].shape, float(scene.pressure))
    units = None
    if "R_L_m" in g.attrs and "mu_H_N_per_m" in g.attrs:  # the file's SI columns: its lab scales
        try:
            units = _check_units({"R_L": g.attrs["R_L_m"], "mu_H": g.attrs["mu_H_N_per_m"]})
        except ValueError as exc:
            raise ValueError(f"attributes R_L_m, mu_H_N_per_m: {exc}") from None
        units = {"R_L": units[0], "mu_H": units[1]}
    return Curve(scene=scene, points=points, flags=flags, stop_reason=_text_attr(g, "stop_reason"),
                 complete=_bool_attr(g, "complete"), interrupted=_bool_attr(g, "interrupted"),
                 settings=settings, version=version, units=units, first_instability=_first_instability(g),
                 inflated=_inflated(g["inflated"]) if "inflated" in g else None)


def _inflated(ig):
    """The curve's inflated state from its group ``inflated`` (one number each of ``INFLATED_FIELDS``)."""
    values = {name: ig.get(name) if hasattr(ig, "keys") else None for name, _, _ in INFLATED_FIELDS}
    for name, d in values.items():
        if getattr(d, "shape", None) != () or d.dtype.kind not in "fiu":
            raise ValueError(f"inflated/{name} must be one number")
    return InflatedStart(**{name: float(d[()]) for name, d in values.items()})


def _first_instability(g):
    """The curve's first unstable depth (attribute ``first_instability``), or None."""
    if "first_instability" not in g.attrs:
        return None
    d = _json_attr(g, "first_instability")
    try:
        first = FirstInstability.from_dict(d)
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"attribute first_instability must hold delta, force, mode, located and bracket "
                         f"({type(exc).__name__}: {exc})") from None
    if len(first.bracket) != 2 or not np.isfinite(first.delta):
        raise ValueError("attribute first_instability: delta must be finite and bracket two numbers")
    return first


def read_curve(path):
    """Read a curve written by :func:`write_curve` (``Curve.to_hdf5``, ``shellbvp curve``).

    Parameters
    ----------
    path : str or Path
        An HDF5 curve file (format ``shellbvp-curve``, versions 1 to 4), or a
        ``.partial`` checkpoint of a running curve.

    Returns
    -------
    Curve
        With its scene rebuilt exactly (user formulas parsed, never evaluated).

    Raises
    ------
    ValueError
        With a one-line reason for a missing, corrupt or foreign file, naming
        the attribute or dataset that is missing or malformed (every point
        field a 1-D array of one number, or string, per delta).

    Examples
    --------
    >>> import os, tempfile, shellbvp as sb
    >>> path = os.path.join(tempfile.mkdtemp(), "base.h5")
    >>> sb.curve(sb.Scene.preset("base"), deltas=[0.2], estimate_error=False).to_hdf5(path)
    >>> c = sb.read_curve(path)
    >>> c.scene == sb.Scene.preset("base"), round(float(c.force[0]), 4)
    (True, 0.3639)
    """

    import h5py

    path = Path(path)
    with open_hdf5(path, fmt=FORMAT, group=("entry/curve", "curve"), kind="curve") as f:
        try:
            version = _format_version(f)
            where = "entry/curve" if version >= 4 else "curve"  # version 4: NeXus, under an NXentry
            if not isinstance(f.get(where), h5py.Group):
                raise ValueError(f"format version {version} keeps its curve in /{where}, which is missing")
            curve = read_curve_group(f[where], str(f.attrs.get("package_version", "")))
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        except (KeyError, TypeError, OSError) as exc:  # h5py's own errors on a damaged file
            raise ValueError(f"{path}: incomplete or corrupt curve ({type(exc).__name__}: {exc})") from None
        return curve
