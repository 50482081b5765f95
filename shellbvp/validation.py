"""The shell model against the 3D solid it stands for: one scene, one thickness.

:func:`validate` computes the shell model's curve (beta from the thickness) and the 3D
finite-element reference (:func:`shellbvp.fe.fe_curve`) at the same pole displacements and
reports ``F_shell / F_FE - 1`` at each: the model's error for this scene, which is
O(eps) (``docs/accuracy.md``).  ``shellbvp validate`` is the command line of it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import schema as sc
from .continuation import curve
from .fe import fe_curve
from .io import read_curve_group, write_curve_group
from .nexus import new_file, number_dataset
from .paths import open_hdf5
from .plotting import require_matplotlib, save_figure
from .units import format_in

__all__ = ["validate", "Validation", "ValidationFile", "read_validation", "default_depths", "shell_curve", "FORMAT"]

FORMAT = "shellbvp-validation"
FORMAT_VERSION = 1
#: Depths of a validation, in units of the thickness (delta / H).
DEPTHS_PER_THICKNESS = (0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 25.0)


def default_depths(thickness: float, delta_max: float) -> np.ndarray:
    """delta / H in :data:`DEPTHS_PER_THICKNESS` up to ``delta_max``, and ``delta_max`` itself."""
    d = np.array([k * thickness for k in DEPTHS_PER_THICKNESS if k * thickness < delta_max * (1 - 1e-9)])
    return np.append(d, delta_max)


@dataclass
class Validation:
    """The shell model and the 3D solid at the same depths.

    Attributes
    ----------
    scene : Scene
        With ``thickness`` set (beta from it unless given and equal).
    shell : Curve
        The shell model's curve at ``delta``.
    fe : FECurve
        The 3D reference at ``delta``.
    R_L : float or None
        The rim radius (m) when known: its file names the sample in lab units.
    delta, force_shell, force_fe, error : ndarray
        ``error = F_shell / F_FE - 1`` (NaN where either is missing).

    Examples
    --------
    >>> import shellbvp as sb
    >>> v = sb.validate(sb.Scene.preset("base", material=sb.NeoHookean()), thickness=0.1, deltas=[0.1])
    >>> print(v.table())
        delta  delta/H     F_shell        F_FE    error  FE mesh
          0.1        1     0.10418    0.089085  +16.94%        -
    """
    scene: object
    shell: object
    fe: object
    R_L: float | None = None

    @property
    def delta(self):
        return self.fe.delta

    @property
    def force_fe(self):
        return self.fe.force

    @property
    def force_shell(self):
        if self.scene.transverse_shear:  # the thick shell's delta + shear_delta, interpolated
            return self.shell.force_at(self.delta)
        d, f = np.asarray(self.shell.points["delta"], float), np.asarray(self.shell.points["force"], float)
        ok = np.asarray(self.shell.points["status"]) == 0
        out = np.full(self.delta.size, np.nan)
        for i, x in enumerate(self.delta):
            j = np.flatnonzero(np.isclose(d, x, rtol=1e-9, atol=1e-12) & ok)
            if j.size:
                out[i] = f[j[0]]
        return out

    @property
    def error(self):
        return self.force_shell / self.force_fe - 1

    def table(self) -> str:
        """The comparison as aligned text, one depth a line."""
        return _table(self.scene.thickness, self.delta, self.force_shell, self.force_fe, self.error,
                      self.fe.mesh_error)

    def to_hdf5(self, path, *, overwrite: bool = False):
        """Both curves and the comparison in one NeXus file, written atomically.

        Layout: ``/`` (NXroot), ``/entry`` (NXentry) with ``comparison`` (NXdata: delta,
        force_shell, force_fe, error; the default plot), ``shell`` (the shell model's curve as in a
        curve file), ``fe`` (NXdata: delta, force, indenter, contact_radius, mesh_error; the FE
        settings) and ``sample`` (NXsample: the scene in words; with ``R_L``, the datasets
        ``R_L`` and ``thickness`` in m).  :func:`read_validation` reads it.
        """
        with new_file(path, FORMAT, FORMAT_VERSION, overwrite=overwrite) as f:
            f.attrs["default"] = "entry"
            entry = f.create_group("entry")
            entry.attrs["NX_class"] = "NXentry"
            entry.attrs["default"] = "comparison"
            entry.attrs["thickness"] = float(self.scene.thickness)
            cmp_ = entry.create_group("comparison")
            cmp_.attrs.update({"NX_class": "NXdata", "signal": "error", "axes": "delta"})
            number_dataset(cmp_, "delta", self.delta, "1", "mid-surface pole displacement / R_L")
            number_dataset(cmp_, "force_shell", self.force_shell, "1", "shell model's F / (mu H R_L)")
            number_dataset(cmp_, "force_fe", self.force_fe, "1", "3D solid's F / (mu H R_L)")
            number_dataset(cmp_, "error", self.error, "1", "F_shell / F_FE - 1")
            write_curve_group(entry.create_group("shell"), self.shell)
            fe = entry.create_group("fe")
            fe.attrs.update({"NX_class": "NXdata", "signal": "force", "axes": "delta",
                             "success": bool(self.fe.success), "message": self.fe.message,
                             "elements": np.asarray(self.fe.elements),
                             "settings": json.dumps(self.fe.settings, sort_keys=True),
                             "wall_time_s": float(self.fe.wall_time)})
            number_dataset(fe, "delta", self.fe.delta, "1", "mid-surface pole displacement / R_L")
            number_dataset(fe, "force", self.fe.force, "1", "indenter force F / (mu H R_L)")
            number_dataset(fe, "indenter", self.fe.indenter, "1", "indenter displacement / R_L")
            number_dataset(fe, "contact_radius", self.fe.contact_radius, "1",
                           "radius of the outermost contact point / R_L")
            number_dataset(fe, "mesh_error", self.fe.mesh_error, "1",
                           "|F - F on a mesh with 2/3 the elements| / F")
            sample = entry.create_group("sample")
            sample.attrs.update({"NX_class": "NXsample", "description": self.scene.describe(self.R_L)})
            if self.R_L is not None:
                number_dataset(sample, "R_L", float(self.R_L), "m",
                               "equatorial radius" if self.scene.closed else "rim radius")
                number_dataset(sample, "thickness", float(self.scene.thickness * self.R_L), "m",
                               "shell thickness H" if self.scene.thickness_profile is None else
                               "shell thickness H at the pole (the wall's profile: the shell's scene)")


def validate(scene, thickness=None, deltas=None, *, delta_max=0.5, mesh_check=False, progress=None,
             tol=1e-6, max_nodes=10000, max_dofs=None, R_L=None, **fe_settings) -> Validation:
    """The shell model's error for ``scene`` at thickness ``eps``: both curves at the same depths.

    Parameters
    ----------
    scene : Scene
        Its ``thickness`` is used when ``thickness`` is not given; beta comes from the thickness.
        A wall whose thickness varies (``scene.thickness_profile``) is meshed as it varies
        (:func:`shellbvp.fe.fe_curve`); forces and depths refer to the pole's thickness.
    thickness : float, optional
        eps = H / R_L in (0, 0.5]; of a profiled wall the pole's, which scales the profile.
    deltas : array_like, optional
        Mid-surface pole displacements; default :func:`default_depths` up to ``delta_max``.
    mesh_check : bool
        Also solve the 3D model on a coarser mesh (``FECurve.mesh_error``).
    progress : callable, optional
        ``progress(i, delta, F_FE)`` after each FE depth.
    tol, max_nodes : float, int
        The shell model's collocation tolerance and largest mesh of a state.
    max_dofs : int, optional
        The largest 3D solid built, in unknowns (:func:`shellbvp.fe.fe_size`; a larger one is
        refused before any work); default ``sb.options``' ``max_fe_dofs`` (50,000).
    R_L : float, optional
        The rim radius (m): kept with the result, so that its file names the sample in lab units.
    **fe_settings
        :data:`shellbvp.fe.FE_DEFAULTS` overrides.

    Returns
    -------
    Validation
        The shell model's curve, the 3D curve and ``error = F_shell / F_FE - 1``.

    Examples
    --------
    >>> import shellbvp as sb
    >>> v = sb.validate(sb.Scene.preset("base", material=sb.NeoHookean()), thickness=0.1, deltas=[0.05, 0.1])
    >>> print(f"{v.error[-1]:+.3f}")             # the shell model 17 % stiffer at delta = H, eps = 0.1
    +0.169
    """
    if thickness is not None:
        scene = scene.replace(thickness=thickness)
    if scene.thickness is None:
        raise ValueError("thickness: give the shell's thickness eps = H / R_L (or a scene with one)")
    eps = scene.thickness
    if deltas is None:
        if not (np.isfinite(delta_max) and 0 < delta_max <= 2):
            raise ValueError(f"delta_max must be in (0, 2]; got {delta_max!r}")
        deltas = default_depths(eps, delta_max)
    deltas = np.asarray(deltas, dtype=float)
    fe = fe_curve(scene, eps, deltas, mesh_check=mesh_check, progress=progress, max_dofs=max_dofs, **fe_settings)
    return Validation(scene, shell_curve(scene, deltas, tol=tol, max_nodes=max_nodes), fe,
                      R_L=None if R_L is None else float(R_L))


def shell_curve(scene, deltas, *, tol=1e-6, max_nodes=10000):
    """The shell model's curve at ``deltas``; with ``scene.transverse_shear`` also at ``deltas -
    shear_delta``, whose thick-shell depths ``delta + shear_delta`` fall next to ``deltas`` (then
    :meth:`Curve.force_at` interpolates locally)."""
    deltas = np.asarray(deltas, dtype=float)
    shell = curve(scene, deltas=deltas, tol=tol, max_nodes=max_nodes, estimate_error=False)
    if not scene.transverse_shear:
        return shell
    d, sd = np.asarray(shell.points["delta"], float), np.asarray(shell.points["shear_delta"], float)
    ok = (np.asarray(shell.points["status"]) == 0) & np.isfinite(sd)
    shifted = np.interp(deltas, d[ok], d[ok] - sd[ok]) if np.count_nonzero(ok) else np.array([])
    shifted = shifted[shifted > 0]
    if not shifted.size:
        return shell
    return curve(scene, deltas=np.unique(np.r_[deltas, shifted]), tol=tol, max_nodes=max_nodes, estimate_error=False)


def _table(eps, delta, force_shell, force_fe, error, mesh_error) -> str:
    lines = [f"{'delta':>9} {'delta/H':>8} {'F_shell':>11} {'F_FE':>11} {'error':>8} {'FE mesh':>8}"]
    for d, fs, ff, e, m in zip(delta, force_shell, force_fe, error, mesh_error):
        mesh = f"{100 * m:7.2f}%" if np.isfinite(m) else f"{'-':>8}"
        err = f"{100 * e:+7.2f}%" if np.isfinite(e) else f"{'-':>8}"
        lines.append(f"{d:9.4g} {d / eps:8.3g} {fs:11.5g} {ff:11.5g} {err} {mesh}")
    return "\n".join(lines)


@dataclass
class ValidationFile:
    """What a validation file (:meth:`Validation.to_hdf5`) holds, as :func:`read_validation` reads it.

    Attributes
    ----------
    path : str
    scene : Scene
        The shell model's scene (its thickness eps = H/R_L set).
    R_L : float or None
        The rim radius (m), when the file has it (``shellbvp validate --radius``).
    delta, force_shell, force_fe, error, mesh_error : ndarray
        The comparison (nondimensional; ``error = F_shell / F_FE - 1``).
    fe_success : bool
    fe_message : str
    """
    path: str
    scene: object
    R_L: object
    delta: np.ndarray
    force_shell: np.ndarray
    force_fe: np.ndarray
    error: np.ndarray
    mesh_error: np.ndarray
    fe_success: bool
    fe_message: str

    def table(self) -> str:
        """The comparison as aligned text, as ``shellbvp validate`` printed it."""
        return _table(self.scene.thickness, self.delta, self.force_shell, self.force_fe, self.error,
                      self.mesh_error)

    def summary_lines(self) -> list:
        """What ``shellbvp info`` prints."""
        def length(x):
            return format_in(x, "um" if x < 1e-3 else "mm", "length")

        lab = "" if self.R_L is None else f", R_L = {length(self.R_L)}, H = {length(self.scene.thickness * self.R_L)}"
        pole = "" if self.scene.thickness_profile is None else " at the pole"
        lines = [f"sample:    {self.scene.describe(self.R_L)}",
                 f"compared:  the shell model and the 3D solid (FElupe) at {self.delta.size} pole displacements; "
                 f"eps = H/R_L = {self.scene.thickness:.4g}{lab}{pole}"]
        if not self.fe_success:
            lines.append(f"FE:        {self.fe_message}")
        return lines + self.table().splitlines()

    def plot(self, out=None, dpi=150):
        """F against delta of both models and the shell's error, side by side; saved to ``out``."""
        plt = require_matplotlib()
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.2))
        a.plot(self.delta, self.force_fe, "ko", label="3D solid (FElupe)")
        a.plot(self.delta, self.force_shell, "C0.-", label="shell model")
        a.set_xlabel("pole displacement delta / R_L")
        a.set_ylabel("F / (mu H R_L)")
        a.set_xlim(left=0)
        a.set_ylim(bottom=0)
        a.legend()
        b.axhline(0, color="0.6", lw=0.8)
        b.plot(self.delta, 100 * self.error, "C3o-")
        b.set_xlabel("pole displacement delta / R_L")
        b.set_ylabel("F_shell / F_FE - 1 (%)")
        fig.suptitle(f"{Path(self.path).name}: eps = H/R_L = {self.scene.thickness:.3g}", fontsize=9)
        fig.tight_layout()
        if out is not None:
            try:
                save_figure(fig, out, dpi=dpi)
            finally:
                plt.close(fig)
        return fig


def read_validation(path) -> ValidationFile:
    """Read a validation file (``shellbvp validate``, :meth:`Validation.to_hdf5`), every item checked.

    Parameters
    ----------
    path : str or Path
        An HDF5 file of format ``shellbvp-validation``.

    Returns
    -------
    ValidationFile
        The comparison, the scene, the rim radius (when the file has it) and the FE outcome.

    Raises
    ------
    ValueError
        Not a validation file, or an item missing or malformed (naming it).

    Examples
    --------
    >>> import os, tempfile, shellbvp as sb
    >>> v = sb.validate(sb.Scene.preset("base", material=sb.NeoHookean()), thickness=0.1, deltas=[0.1], R_L=1e-3)
    >>> path = os.path.join(tempfile.mkdtemp(), "validate.h5")
    >>> v.to_hdf5(path)
    >>> back = sb.read_validation(path)
    >>> back.R_L                                  # the rim radius (m), as validate was given it
    0.001
    >>> print(back.table())
        delta  delta/H     F_shell        F_FE    error  FE mesh
          0.1        1     0.10418    0.089085  +16.94%        -
    """
    with open_hdf5(path, fmt=FORMAT, group="entry/comparison", kind="validation") as h:
        try:
            sc.format_version(h, FORMAT_VERSION)
            entry, fe = h["entry"], h["entry/fe"]
            delta = sc.dataset(h["entry/comparison"], "delta")
            columns = {k: sc.dataset(h["entry/comparison"], k, length=delta.size)
                       for k in ("force_shell", "force_fe", "error")}
            mesh_error = sc.dataset(fe, "mesh_error", length=delta.size)
            scene = read_curve_group(entry["shell"]).scene
            if scene.thickness is None:
                raise ValueError("the shell's scene has no thickness")
            sample = entry.get("sample")
            R_L = None
            if sample is not None and "R_L" in sample:
                R_L = sc.scalar(sample, "R_L", low=0.0)
                if not R_L > 0:
                    raise ValueError(f"R_L must be > 0; got {R_L!r}")
            success, message = sc.attr_bool(fe, "success"), sc.attr_text(fe, "message")
        except (ValueError, KeyError, TypeError, OSError) as exc:
            what = str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"
            raise ValueError(f"{path}: incomplete or corrupt validation file ({what})") from None
    return ValidationFile(path=str(path), scene=scene, R_L=R_L, delta=delta, mesh_error=mesh_error,
                          fe_success=success, fe_message=message, **columns)
