"""The solid as a fitting model (``fit(..., model="solid")``): the scene's shell as a 3D
axisymmetric solid (:func:`shellbvp.fe_curve`), indented by the instrument's own displacement.

Why: the shell model's delta is its mid-surface pole's displacement; an instrument records
the indenter's, which also compresses and thins the wall under the tip.  On thick samples
(eps = H/R_L of 0.1-0.2) that difference and the shell's own error bias a shell fit of mu*H
by 6-20 % (issue 54).  The solid has neither: its abscissa is the indenter's displacement from
first touch (at the pole or on a ring, where it really is), divided by R_L.

A closed shell (``Scene(closed=True)``, :mod:`shellbvp.fe_closed`) is fitted the same way: its
abscissa is the approach of the indenters from first touch -- the two plates' (or tips'), or
the tip's towards the fixed substrate -- which is also the closed shell model's delta (the
approach of its mid-surface poles, which press the indenters directly); the solid's poles'
approach is shorter by the wall's compression under both contacts.  Between plates the solid is
the half above the equator and each plate moves by half the approach; on a substrate the whole
wall on a second, fixed contact, its cost twice the half's elements (:func:`shellbvp.fe.fe_size`).
Open, under a pressure or sealed: the nondimensional pressure (or the held volume) is part of
the scene, so the curve still scales with mu*H.

For a material whose energy scales with mu at fixed shape parameters (neo-Hookean,
Mooney-Rivlin at a given alpha, Gent at a given Jm, ...), the solid's force is mu times one
curve: ``F_SI = mu_H R_L F(d / R_L)`` with ``F = force / (mu R_L H)``, exactly the shell
model's form.  One solid curve per scene and depth grid serves every mu*H, the contact
point and the baseline; it is kept on disk (:func:`solid_curve`) like a shell model curve.

A kept solid curve is data from disk: a JSON file in the code cache's ``solid_curves/``
folder, named by a hash of everything it depends on (scene, depths, the FE's settings, the
package's source) and carrying a SHA-256 of its own contents.  It is used only when that
checksum, its key, its depths and its finite forces all check; otherwise it is set aside with
a warning and computed again (:mod:`shellbvp.fitting.kept`, as a shell model curve).  A folder
or file another user owns or may write is not read.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import json
import logging
import math
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..config import OPTIONS
from ..fe import FE_DEFAULTS, check_fe_size, check_solid_scene, coarser, fe_curve, fe_size
from ..version import __version__
from .curves import code_fingerprint
from .kept import checksum, keep, kept_folder, read_kept

__all__ = ["SolidCurve", "solid_curve", "clear_solid_curves", "check_solid_fit", "auto_model", "shell_or_solid",
           "shell_words", "solid_words", "FIT_MODELS", "AUTO_SOLID_EPS", "MAX_KEPT_BYTES"]

log = logging.getLogger(__name__)

#: What a fit can compare with the data: the shell model's curve, the 3D solid's, or the one of
#: them this scene needs (:func:`auto_model`).
FIT_MODELS = ("auto", "shell", "solid")

#: ``model="auto"`` measures the shell against the solid from this thickness (eps = H/R_L) up:
#: thinner shells need a finer solid mesh (its cost grows like 1/eps^2: benchmarks/results/
#: thick_fits.md), and their shell model is within a few percent of the solid.  A wall whose
#: thickness varies is measured from its thickest point this thick up (the model's error line
#: names the thickest too), when its solid is within the limit of unknowns (``max_fe_dofs``).
#: The same for closed shells, whose solid on a substrate (the whole wall) has twice the elements
#: of the half between plates.
AUTO_SOLID_EPS = 0.05

#: A kept solid curve larger than this is not read (40 depths take about 4 kB).
MAX_KEPT_BYTES = 1 << 20

#: Format of a kept solid curve (a new one makes new keys).
FORMAT = 1

# the solid curves of this process (a batch or a map on one grid computes one), least recent out first
_MEMO: OrderedDict = OrderedDict()
_MEMO_SIZE = 8


@dataclass
class SolidCurve:
    """The solid's force against the indenter's displacement, nondimensional.

    Attributes
    ----------
    scene : Scene
    delta : ndarray
        The indenter's displacement from first touch / R_L at the depths reached (the fit's
        abscissa: named as the shell curve's so that a fit reads either); of a closed shell, the
        approach of the plates, or of the tip and the substrate.
    force : ndarray
        Indenter force / (mu R_L H) there.
    pole_delta : ndarray
        The mid-surface pole's displacement / R_L there (of a closed shell, the approach of its
        two mid-surface poles).
    contact_radius : ndarray
        Radius of the outermost surface point in contact / R_L.
    complete : bool
        Every requested depth reached.
    stop_reason : str
    elements : tuple
        Elements along the meridian and through the thickness.
    wall_time : float
        Seconds the FE took (0 for a kept curve read back).
    kept : bool
        Read from the code cache.
    """

    scene: object
    delta: np.ndarray
    force: np.ndarray
    pole_delta: np.ndarray
    contact_radius: np.ndarray
    complete: bool
    stop_reason: str
    elements: tuple
    wall_time: float = 0.0
    kept: bool = False
    settings: dict = field(default_factory=dict)

    def __len__(self):
        return int(self.delta.size)


def check_solid_fit(scene, free=()):
    """ValueError, in one line, where the solid cannot be this fit's model (before any work)."""
    if scene.thickness is None:
        raise ValueError("model='solid' needs the shell's thickness (thickness = H/R_L; --thickness with a unit "
                         "and --radius): the solid is meshed at that thickness")
    if free:
        raise ValueError(f"model='solid' fits mu*H, the contact point and a baseline; fitting {', '.join(free)} "
                         f"with the solid is not supported yet: fit it with model='shell'")
    if scene.transverse_shear:
        raise ValueError("transverse_shear is a correction of the shell model; the solid has its shear already: "
                         "drop --transverse-shear with --model solid")
    check_solid_scene(scene)
    check_fe_size(fe_size(scene, scene.thickness, **FE_DEFAULTS))  # before the data are read


#: How the summary names the shell model: what it takes the data's displacement to be.
SHELL_WORDS = "shell model, its mid-surface pole's displacement taken as the data's"
#: ... of a closed shell, whose model presses the indenters with its mid-surface poles.
CLOSED_SHELL_WORDS = "shell model, its mid-surface poles' approach taken as the data's"


def shell_words(scene):
    """The summary's name of the shell model of ``scene`` (None: a rimmed shell's)."""
    return CLOSED_SHELL_WORDS if getattr(scene, "closed", False) else SHELL_WORDS


def solid_words(scene):
    """``(solid, abscissa)``: how the summary describes the solid of ``scene`` (its support)
    and what it takes the data's displacement to be."""
    if not scene.closed:
        return "the rim face hinged at mid-thickness", "its indenter's displacement from first touch"
    if scene.support == "plates":
        if getattr(scene.shell, "lower", None) is not None:  # an egg: no symmetry plane
            return "the whole wall, the bottom plate fixed", "the indenters' approach from first touch"
        return "the half above the equator on its symmetry plane", "the indenters' approach from first touch"
    return "the whole wall on a frictionless substrate", "the tip's approach to the substrate from first touch"


def auto_model(scene, free=(), stability=False):
    """``(choice, why)`` of ``model="auto"``: ``"shell"`` with the reason the solid is not used
    here, or ``"both"`` (fit both; :func:`shell_or_solid` keeps one)."""
    eps = scene.thickness
    if eps is not None and scene.thickness_profile is not None:
        eps = scene.thickness_profile.thickest(scene.shell_length)
    reason = None
    if eps is None:
        reason = "no thickness given: the 3D solid needs --thickness"
    elif free:
        reason = f"fitting {', '.join(free)}: the solid fits mu*H only"
    elif stability:
        reason = "the stability check is the shell model's"
    elif scene.transverse_shear:
        reason = "asked for with transverse shear"
    elif eps < AUTO_SOLID_EPS:
        thickest = " (the wall's thickest)" if scene.thickness_profile is not None else ""
        reason = (f"eps = {eps:.3g}{thickest} < {AUTO_SOLID_EPS:g}: the solid costs too much to measure the shell "
                  f"by default; --model solid uses it")
    else:
        try:
            check_solid_scene(scene)
            check_fe_size(fe_size(scene, scene.thickness, **FE_DEFAULTS))
        except ValueError as exc:
            reason = f"no 3D solid for this scene: {exc}"
    if reason is None and importlib.util.find_spec("felupe") is None:
        reason = "the 3D solid needs FElupe: pip install 'shellbvp[fe]'"
    return ("both", "") if reason is None else ("shell", f"{shell_words(scene)} ({reason})")


def shell_or_solid(shell, solid):
    """The fit to report of the shell's and the solid's on the same data: the shell where its
    error on this scene, measured by the solid as the difference of their mu*H, lies within
    its 95 % interval; the solid otherwise (``model_note`` says which and why)."""
    computed = shell.curves_computed + solid.curves_computed
    words = shell_words(shell.scene)
    if not solid.success:
        return dataclasses.replace(shell, curves_computed=computed, model_note=(
            f"{words} (the 3D solid's fit failed: {solid.message}; its error is not measured)"))
    if not shell.success:
        return dataclasses.replace(solid, curves_computed=computed, model_note=(
            f"3D solid (the shell model's fit failed: {shell.message})"))
    error = shell.mu_H / solid.mu_H - 1
    half = (shell.mu_H_ci95[1] - shell.mu_H_ci95[0]) / 2 / shell.mu_H
    measured = (f"{100 * error:+.2g} % in mu*H on this scene, measured by the 3D solid (shell {shell.mu_H:.4g}, "
                f"solid {solid.mu_H:.4g} N/m)")
    if abs(error) <= half:
        return dataclasses.replace(shell, curves_computed=computed, measured_model_error=abs(error), model_note=(
            f"{words}; its error, {measured}, is within its interval (+-{100 * half:.2g} %)"))
    return dataclasses.replace(solid, curves_computed=computed, measured_model_error=abs(error), model_note=(
        f"3D solid; the shell model's error, {measured}, is beyond the shell's interval (+-{100 * half:.2g} %)"))


def solid_curve(scene, grid, tol=None, counter=None, progress=None, *, coarse=False) -> SolidCurve:
    """The solid's curve of ``scene`` at the indenter displacements ``grid`` (/ R_L): read back
    from the code cache when kept there and sound, else computed (``fe_curve(at="indenter")``)
    and kept.  ``tol`` (the shell model's) plays no part; ``counter[0]`` counts computed curves;
    ``progress(description, depth_max) -> (bar, callback)`` draws a bar; ``coarse``: on the mesh
    check's mesh (2/3 the elements each way, :func:`shellbvp.fe.coarser`)."""
    grid = np.asarray(grid, float)
    settings = coarser(FE_DEFAULTS) if coarse else dict(FE_DEFAULTS)
    memo = (scene, tuple(grid.tolist()), coarse)
    if memo in _MEMO:
        _MEMO.move_to_end(memo)
        return _MEMO[memo]
    path, key = _place(scene, grid, settings)
    c = _read_kept(path, key, scene, grid, settings)
    if c is None:
        c = _computed(scene, grid, counter, progress, settings)
        if c.complete:
            _keep(c, path, key)
    _MEMO[memo] = c
    while len(_MEMO) > _MEMO_SIZE:
        _MEMO.popitem(last=False)
    return c


def clear_solid_curves():
    """Forget the solid curves memoised in this process (the disk's stay)."""
    _MEMO.clear()


def _computed(scene, grid, counter, progress, settings):
    bar, callback = progress("solid curve", float(grid[-1])) if progress is not None else (None, None)
    try:
        fe = fe_curve(scene, scene.thickness, grid, at="indenter",
                      progress=None if callback is None else _fe_progress(callback), **settings)
    finally:
        if bar is not None:
            bar.close()
    if counter is not None:
        counter[0] += 1
    reached = int(np.argmax(~np.isfinite(fe.force))) if not np.all(np.isfinite(fe.force)) else grid.size
    return SolidCurve(scene, grid[:reached].copy(), fe.force[:reached], fe.delta[:reached],
                      fe.contact_radius[:reached], bool(fe.success), fe.message, tuple(fe.elements), fe.wall_time,
                      settings=dict(fe.settings))


def _fe_progress(callback):
    """fe_curve's ``progress(i, depth, force)`` drawn by a curve bar's ``callback(curve, sol)``."""
    class _Point:
        def __init__(self, delta, force):
            self.delta, self.force = delta, force

    done = []

    def step(i, depth, force):
        done.append(depth)
        callback(done, _Point(float(depth), float(force)))

    return step


def _place(scene, grid, settings):
    """(path, key) of the kept curve, or (None, None) where the disk is off or not trusted."""
    if not OPTIONS.model_curve_cache:
        return None, None
    try:
        payload = json.dumps({"format": FORMAT, "scene": scene.to_dict(), "grid": [float(x) for x in grid],
                              "fe": settings, "code": code_fingerprint(), "version": __version__},
                             sort_keys=True)
    except (TypeError, ValueError, AttributeError):
        return None, None
    key = hashlib.sha256(payload.encode()).hexdigest()
    folder = kept_folder("solid_curves", KEPT_WHAT)
    if folder is None:
        return None, None
    return folder / f"solid_{key[:32]}.json", key


#: What the cache's warnings call a kept solid curve
KEPT_WHAT = "solid curves"


def _checksum(record):
    return checksum({k: v for k, v in record.items() if k != "sha256"})


def _read_json(path):
    return json.loads(path.read_bytes().decode("utf-8"))


def _read_kept(path, key, scene, grid, settings):
    """The kept curve at ``path`` when it is sound and holds ``key`` and ``grid``, else None (a
    bad one set aside with a warning)."""
    record = read_kept(path, _read_json, lambda r: _unsound(r, key, grid), what="solid curve",
                       max_bytes=MAX_KEPT_BYTES)
    if record is None:
        return None
    return SolidCurve(scene, grid.copy(), np.array(record["force"], float), np.array(record["pole_delta"], float),
                      np.array(record["contact_radius"], float), True, record["stop_reason"][:200],
                      tuple(int(e) for e in record["elements"][:2]), 0.0, True,
                      settings={**settings, "at": "indenter"})  # the settings its key holds, as computed


def _unsound(record, key, grid):
    """Why a kept record cannot be used, or None."""
    if not isinstance(record, dict):
        return "not a record"
    if record.get("sha256") != _checksum(record):
        return "its checksum does not match its contents (damaged or edited)"
    if record.get("key") != key or record.get("format") != FORMAT:
        return "made for another scene, grid or version"
    try:
        depths = np.array(record["grid"], float)
        arrays = [np.array(record[k], float) for k in ("force", "pole_delta", "contact_radius")]
        elements = record["elements"]
    except (KeyError, TypeError, ValueError):
        return "fields missing or not numbers"
    if depths.shape != grid.shape or not np.array_equal(depths, grid):
        return "its depths are not the requested ones"
    if any(a.shape != grid.shape or not np.all(np.isfinite(a)) for a in arrays):
        return "an array of the wrong length or with a non-finite value"
    if not (isinstance(elements, list) and len(elements) == 2 and all(isinstance(e, int) for e in elements)):
        return "elements are not two integers"
    if not isinstance(record.get("stop_reason"), str):
        return "no stop reason"
    return None


def _keep(c, path, key):
    """Write the complete curve ``c`` (atomically); a cache that cannot be written is skipped."""
    if path is None:
        return
    record = {"format": FORMAT, "key": key, "grid": [float(x) for x in c.delta],
              "force": [float(x) for x in c.force], "pole_delta": [float(x) for x in c.pole_delta],
              "contact_radius": [float(x) for x in c.contact_radius], "elements": [int(e) for e in c.elements],
              "stop_reason": c.stop_reason, "units": {"grid": "indenter displacement / R_L",
                                                       "force": "F / (mu R_L H)", "pole_delta": "1 (/ R_L)",
                                                       "contact_radius": "1 (/ R_L)"}}
    if not all(math.isfinite(x) for x in record["force"]):
        return
    record["sha256"] = _checksum(record)

    def write(tmp):
        tmp.write_text(json.dumps(record, sort_keys=True), encoding="utf-8")
        if (why := _unsound(_read_json(tmp), key, np.asarray(record["grid"]))) is not None:
            raise ValueError(f"the record read back is not the one written: {why}")

    keep(path, write, what=KEPT_WHAT)
