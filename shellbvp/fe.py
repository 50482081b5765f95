"""A 3D reference: the scene's shell as an axisymmetric, nearly incompressible solid (FElupe).

The shell model reduces a solid of thickness H to its mid-surface.  This module solves
the solid itself, so that a user sees the model's error for his own scene:

* the solid: the scene's reference meridian as the mid-surface, thickness ``eps = H/R_L``
  on either side of it by eps/2 along the normal (a wall whose thickness varies,
  ``scene.thickness_profile``: by H(S)/2, the elements' sizes following the local H); 9-node quadratic elements (FElupe's
  ``RegionBiQuadraticQuad``) with the mixed u/p/J (Hu-Washizu) formulation of
  ``ThreeFieldVariation``, bulk modulus ``bulk`` (5000 mu by default: a Poisson ratio of
  0.4999); the scene's energy on the isochoric invariants, from its material's module
  (``felupe_model``: Mooney-Rivlin, neo-Hookean, Gent, ...; user energies
  ``W(lambda_s, lambda_theta)`` have no unique 3D form: refused);
* the rim (:mod:`shellbvp.fe_rim`): the shell model's simple support as the rim face held
  plane and turning about its fixed mid-thickness point (pinning that point alone does not
  converge under refinement); a clamped rim holds the whole face;
* a closed shell (:mod:`shellbvp.fe_closed`): between plates the half above the equator on its
  symmetry plane; on a substrate the whole wall on a second, fixed frictionless contact; one
  whose halves differ (an egg) the whole wall, each half's own meridian, on a substrate and
  between plates (the bottom plate the fixed substrate); delta the approach of the
  mid-surface poles;
* the indenter: rigid and frictionless, the scene's tip on its cylinder, pressed on the
  surface that faces it (the shell model presses the mid-surface); a penalty on the
  penetration at Gauss points of that surface with the exact (consistent) tangent
  (:mod:`shellbvp.fe_contact`); first touch where it happens (the pole, or a ring where the
  surface is more curved than the tip);
* the depths: the mid-surface pole's displacement delta, as in the shell model (each reached
  by a secant iteration on the indenter's position), or the indenter's displacement from
  first touch, as an instrument records it (``at="indenter"``); both are reported;
* a pressure: a follower load on the inner surface (:mod:`shellbvp.fe_pressure`), applied
  before the indenter touches; depths from the inflated state; a sealed shell holds the
  volume below that surface with the pressure an unknown (a bordered Newton system);
* the force ``F / (mu R_L H)`` (nondimensional as in :func:`shellbvp.curve`).

Needs FElupe (``pip install 'shellbvp[fe]'``).  Nondimensional: mu = 1, R_L = 1.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .config import OPTIONS
from .fe_closed import closed_boundary, egg, mirrored, whole
from .fe_contact import PenaltyContact, TipSurface
from .fe_newton import Newton
from .fe_pressure import FollowerPressure
from .fe_rim import RIM_FACES, HingedFace
from .materials import MATERIALS
from .model import load_module, lower_structure

__all__ = ["fe_curve", "FECurve", "TipSurface", "FE_DEFAULTS", "check_solid_scene", "coarser", "FESize", "fe_size",
           "check_fe_size"]

#: Mesh, material and contact settings of :func:`fe_curve` (all nondimensional).
FE_DEFAULTS = {
    "through_thickness": 3,     # elements through H
    "element_length": 0.5,      # meridian element length / H (away from the pole)
    "pole_refinement": 2,       # elements near the pole this many times shorter (contact zone)
    "bulk": 5000.0,             # bulk modulus / mu
    "penalty": 1e4,             # contact penalty * H / mu (penetration ~ pressure H / penalty)
    "gauss_points": 4,          # per element edge of the contact surface
    "band": 1e-5,               # the penalty is smoothed over penetrations below band * H
    "tol": 1e-9,                # Newton: residual norm / contact force
    "delta_tol": 1e-7,          # pole control: |delta - target| / max(target, H)
    "rim_face": "plane",        # the rim face held plane, turning about its mid-thickness point (RIM_FACES)
}


#: The cost model of :func:`fe_size`, measured (benchmarks/results/fe_speed-new-grow.md and the
#: first touch of the hemisphere at eps 0.01, 0.004, 0.002): a curve of the hemisphere at eps 0.02
#: (167 x 3 elements, 12 depths) took 52.5 s, and the time grows like the square of the elements
#: (the Newton iterations grow with them); the peak memory was ~100 MB plus ~4.5 kB per unknown.
_REFERENCE_ELEMENTS, _REFERENCE_SECONDS = 167 * 3, 52.5
_BASE_MB, _MB_PER_DOF = 100.0, 4.5e-3


def _felupe():
    try:
        import felupe
    except ImportError as exc:  # optional extra
        raise ImportError("the 3D reference needs FElupe: pip install 'shellbvp[fe]'") from exc
    return felupe


# ---------------------------------------------------------------- the solid's mesh
def _meridian(scene, n_table=4001, lower=False):
    """Arclength-parametrised reference mid-surface: s -> (R, Z, Phi), with the total length,
    and the package's meridian coordinate S of each tabulated point (a profile's H(S)); of a
    closed shell's lower half of its own (``lower``), that half's, in its mirror image."""
    mod = load_module(lower_structure(scene)) if lower else scene.model()
    par = scene.parameters(mod, pole_rise=0.0)
    S = np.linspace(0.0, float(scene.shell.lower.geometry.L) if lower else scene.shell_length, n_table)
    ref = mod.reference_shell(S, par)
    R, Z = np.asarray(ref["R"], float), np.asarray(ref["Z"], float)
    ds = np.hypot(np.diff(R), np.diff(Z))
    s = np.concatenate([[0.0], np.cumsum(ds)])
    # chords of 4000 intervals: the arclength to ~1e-8, nodes placed by linear interpolation
    return s, R, Z, np.asarray(ref["Phi"], float), S


def _tables(scene, eps, element_length, pole_refinement):
    """The meridian table ``(s, R, Z, Phi, H, corners)`` the solid is meshed on: the upper half's,
    or a closed shell's whole wall (on a substrate, or one whose halves differ), each half's
    elements from its own pole; and the upper half's elements (the equator's corner)."""
    s, R, Z, Phi, S = _meridian(scene)
    H = _wall(scene, eps, S)
    upper = (s, R, Z, Phi, H, _corners(s, H, eps, element_length, pole_refinement))
    if not whole(scene):
        return upper, upper[-1].size - 1
    lower = None
    if egg(scene):  # its lower half's own table (a uniform wall: an egg has no profile)
        s, R, Z, Phi, S = _meridian(scene, lower=True)
        H = _wall(scene, eps, S)
        lower = (s, R, Z, Phi, H, _corners(s, H, eps, element_length, pole_refinement))
    return mirrored(upper, lower), upper[-1].size - 1


def _wall(scene, eps, S):
    """The wall's thickness H/R_L at the meridian coordinates ``S``: ``eps``, or the scene's
    profile scaled to the pole thickness ``eps`` (the package's convention, ``Scene.replace``)."""
    profile = scene.thickness_profile
    if profile is None:
        return np.full(np.shape(S), float(eps))
    return eps * profile.relative(S, L=scene.shell_length)


def _corners(s_tab, H_tab, eps, element_length, pole_refinement):
    """The element corners along the meridian (arc length): ``element_length`` times the local
    thickness, ``pole_refinement`` times shorter within 4 eps of the pole (eps: the pole's)."""
    h = element_length * eps
    local = None if np.all(H_tab == eps) else (lambda x: element_length * np.interp(x, s_tab, H_tab))
    return _node_positions(s_tab[-1], h, h / pole_refinement, 4 * eps, local)


def _node_positions(total, h, pole_h, pole_zone, local=None):
    """Meridian nodes of the element corners: length pole_h up to pole_zone, growing to h, or
    to ``local(x)`` (a profiled wall's element length at x: the shorter of its value at the
    element's start and end)."""
    s, x = [0.0], 0.0
    while x < total - 1e-12:
        cap = h
        if local is not None:
            cap = float(local(x))
            cap = min(cap, float(local(min(total, x + cap))))
        step = pole_h if x < pole_zone else min(cap, pole_h * (1 + (x - pole_zone) / max(pole_zone, h)) ** 2)
        x = min(total, x + step)
        if total - x < 0.3 * step:  # no sliver at the rim
            x = total
        s.append(x)
    return np.array(s)


@dataclass
class _Model:
    mesh: object
    region: object
    field: object
    solid: object
    contact: "PenaltyContact"
    fixed: np.ndarray      # constrained dofs of the displacement field
    pole_mid: int          # the mid-surface pole's point
    eps: float
    elements: tuple
    face: object = None    # HingedFace: the rim face's own unknowns (None: its dofs fixed or free)
    pressure: object = None  # FollowerPressure on the inner surface (None: no pressure)
    supports: list = field(default_factory=list)  # a closed shell's substrate and spring (fe_closed)
    delta_weights: dict = None  # delta = pole0 - sum w u over these dofs (None: the mid-surface pole's)
    approach: float = 1.0  # the indenter's approach per displacement of the tip (2 between plates)


def _build(scene, eps, *, through_thickness, element_length, pole_refinement, bulk, penalty, gauss_points,
           band=1e-5, rim_face="plane"):
    fem = _felupe()
    # the wall's thickness H at each tabulated point; a closed shell's whole wall pole to pole
    (s_tab, R_tab, Z_tab, Phi_tab, H_tab, corners), n_upper = _tables(scene, eps, element_length, pole_refinement)
    n_s, n_t = corners.size - 1, int(through_thickness)
    # quadratic nodes: element corners plus midpoints, along s and through t
    s_nodes = np.empty(2 * n_s + 1)
    s_nodes[0::2] = corners
    s_nodes[1::2] = 0.5 * (corners[:-1] + corners[1:])
    t_nodes = np.linspace(-0.5, 0.5, 2 * n_t + 1)  # times the local thickness
    R, Z, Phi, H = (np.interp(s_nodes, s_tab, v) for v in (R_tab, Z_tab, Phi_tab, H_tab))
    # the unit normal towards the indenter: (r, z) = (-sin Phi, cos Phi); the wall at +-H/2 along it
    nr, nz = -np.sin(Phi), np.cos(Phi)
    tt, ss = np.meshgrid(t_nodes, np.arange(s_nodes.size), indexing="ij")
    tt = tt * H[ss]
    points = np.stack([(Z[ss] + tt * nz[ss]).ravel(), (R[ss] + tt * nr[ss]).ravel()], axis=1)
    points[np.isclose(points[:, 1], 0.0, atol=1e-14), 1] = 0.0
    ncol = s_nodes.size

    def node(i, j):  # i through the thickness, j along the meridian (quadratic grid)
        return i * ncol + j

    cells = []
    for a in range(n_t):
        for b in range(n_s):
            i, j = 2 * a, 2 * b
            # FElupe's quad9: corners counter-clockwise, edge midpoints, centre
            cells.append([node(i, j), node(i, j + 2), node(i + 2, j + 2), node(i + 2, j),
                          node(i, j + 1), node(i + 1, j + 2), node(i + 2, j + 1), node(i + 1, j),
                          node(i + 1, j + 1)])
    cells = np.array(cells)
    # FElupe wants counter-clockwise cells in (z, r); (s, t) maps clockwise where the normal turns
    e = points[cells[0, 1]] - points[cells[0, 0]]
    f = points[cells[0, 3]] - points[cells[0, 0]]
    if e[0] * f[1] - e[1] * f[0] < 0:
        cells = cells[:, [0, 3, 2, 1, 7, 6, 5, 4, 8]]
    mesh = fem.Mesh(points, cells, cell_type="quad9")
    region = fem.RegionBiQuadraticQuad(mesh)
    field = fem.FieldsMixed(region, n=3, axisymmetric=True)
    solid = fem.SolidBody(fem.NearlyIncompressible(_material(scene, fem), bulk=bulk), field)
    pressure = None
    if scene.pressurised:  # p R_L/(mu H) on the shell is P = p H/R_L on the solid's inner surface (t = -eps/2)
        bottom = np.array([node(0, j) for j in range(ncol)])
        pressure = FollowerPressure(points, bottom, scene.pressure * eps, int(np.sum(field.fieldsizes)), gauss_points)
    if scene.closed:
        fixed, top, supports, weights, approach = closed_boundary(
            scene, eps, points, node, n_t, ncol, field, penalty=penalty, gauss_points=gauss_points, band=band,
            equator=2 * n_upper)
        contact = PenaltyContact(TipSurface(scene), points, top, penalty / eps, gauss_points, field, band * eps)
        return _Model(mesh, region, field, solid, contact, fixed, node(n_t, 0), eps, (n_s, n_t), None, pressure,
                      supports, weights, approach)
    # boundary: the axis (r = 0) cannot move radially; the rim's mid-thickness point is pinned and
    # its face turns about it, held plane (simple support) or held fixed (clamped)
    axis = np.flatnonzero(points[:, 1] == 0.0)
    rim_mid = node(n_t, ncol - 1)
    face_nodes = np.array([node(i, ncol - 1) for i in range(2 * n_t + 1)])
    held = face_nodes if scene.rim == "clamped" else [rim_mid]
    face = HingedFace(points, face_nodes, rim_mid) if scene.rim != "clamped" and rim_face == "plane" else None
    fixed = np.unique(np.concatenate([2 * axis + 1, 2 * np.asarray(held), 2 * np.asarray(held) + 1]))
    top = np.array([node(2 * n_t, j) for j in range(ncol)])  # t = +eps/2: faces the indenter
    contact = PenaltyContact(TipSurface(scene), points, top, penalty / eps, gauss_points, field, band * eps)
    return _Model(mesh, region, field, solid, contact, fixed, node(n_t, 0), eps, (n_s, n_t), face, pressure)


@dataclass(frozen=True)
class FESize:
    """What a solid of :func:`fe_curve` costs, estimated from the scene before it is built.

    Attributes
    ----------
    elements : tuple
        Elements along the meridian and through the thickness.
    dofs : int
        Unknowns of the mixed fields (displacement, pressure, volume ratio).
    memory_mb, seconds : float
        Peak memory and wall time of a curve, by the measured cost model (:data:`_REFERENCE_SECONDS`):
        an order of magnitude, not a promise.
    """

    elements: tuple
    dofs: int
    memory_mb: float
    seconds: float

    def describe(self) -> str:
        minutes = self.seconds / 60
        when = f"{self.seconds:.0f} s" if minutes < 2 else (f"{minutes:.0f} min" if minutes < 120
                                                            else f"{minutes / 60:.0f} h")
        return (f"{self.elements[0]}x{self.elements[1]} elements, {self.dofs:,} unknowns, "
                f"~{self.memory_mb:,.0f} MB, about {when}")


def fe_size(scene, thickness, **settings) -> FESize:
    """The mesh :func:`fe_curve` would build for ``scene`` at ``thickness`` (of a profiled wall,
    the pole's) and its estimated cost, without building it (``settings``: :data:`FE_DEFAULTS`
    overrides)."""
    opts = {**FE_DEFAULTS, **settings}
    eps = float(thickness)
    n_s = _half_elements(scene, eps, opts)
    if whole(scene):  # a closed shell's whole wall: both halves, an egg's lower its own
        n_s += _half_elements(scene, eps, opts, lower=True) if egg(scene) else n_s
    n_t = int(opts["through_thickness"])
    # quadratic displacement nodes, two components; pressure and volume ratio: 4 per element each
    dofs = 2 * (2 * n_s + 1) * (2 * n_t + 1) + 2 * 4 * n_s * n_t
    seconds = _REFERENCE_SECONDS * (n_s * n_t / _REFERENCE_ELEMENTS) ** 2
    return FESize((n_s, n_t), dofs, _BASE_MB + _MB_PER_DOF * dofs, seconds)


def _half_elements(scene, eps, opts, lower=False):
    """Elements along the upper half's meridian (``lower``: an egg's lower half's)."""
    s_tab, *_, S_tab = _meridian(scene, lower=lower)
    H_tab = _wall(scene, eps, S_tab)
    # elements of the local length element_length * H along the arc: exact count below (the loop is
    # cheap), beyond it this integral (a lower bound: the pole's refinement adds elements)
    n_s = math.ceil(np.trapezoid(1.0 / (opts["element_length"] * H_tab), s_tab))
    if n_s < 100_000:
        n_s = _corners(s_tab, H_tab, eps, opts["element_length"], opts["pole_refinement"]).size - 1
    return n_s


def check_fe_size(size: FESize, max_dofs=None) -> None:
    """ValueError, in one line, where ``size`` exceeds ``max_dofs`` (default ``sb.options``'
    ``max_fe_dofs``, 50,000: about 30 min and 330 MB, the hemisphere at eps ~ 0.0035; eps = 1e-4
    would need 1.6 million unknowns, issue 59)."""
    limit = int(OPTIONS.max_fe_dofs if max_dofs is None else max_dofs)
    if size.dofs > limit:
        raise ValueError(f"thickness: the 3D solid would need {size.describe()}, over the limit of {limit:,} "
                         f"unknowns (max_dofs, --max-fe-dofs); a thicker shell, or a larger limit if the "
                         f"machine allows it")


def _check_max_dofs(max_dofs):
    if max_dofs is not None and not (isinstance(max_dofs, (int, np.integer)) and max_dofs > 0):
        raise ValueError(f"max_dofs must be a positive integer (unknowns of the 3D solid); got {max_dofs!r}")


def coarser(settings):
    """The mesh of a mesh check: ``settings`` with 2/3 the elements each way."""
    return {**settings, "element_length": settings["element_length"] * 1.5,
            "through_thickness": max(2, round(settings["through_thickness"] * 2 / 3))}


def check_solid_scene(scene):
    """ValueError, in one line, where the scene has no solid (before any work): a material
    without a 3D form.  Every shell the solid holds -- rimmed, or closed between plates or on a
    substrate, open, under a pressure or sealed -- is also a fitting model (``fit --model
    solid``): its curve at the indenters' approach (``at="indenter"``) is what a fit reads.
    A closed shell whose halves differ (an egg) is the whole wall, on a substrate and between
    plates."""
    _check_material(scene)


def _check_profile(scene, eps):
    """ValueError, in one line, where the profile scaled to the pole thickness ``eps`` leaves (0, 0.5]."""
    profile = scene.thickness_profile
    thickest = eps * profile.thickest(scene.shell_length) / profile.pole
    if thickest > 0.5:
        raise ValueError(f"thickness: at the pole's eps = {eps:g} the wall's profile reaches H/R_L = {thickest:.4g}; "
                         f"it must stay in (0, 0.5] (a pole thickness up to {0.5 * eps / thickest:.4g})")


def _check_material(scene):
    if scene.material.felupe_model is None:
        known = [c.label for c in MATERIALS.values() if c.felupe_model is not None]
        raise ValueError(f"material: the 3D reference knows {', '.join(known[:-1])} and {known[-1]}; "
                         f"{scene.material.no_3d_form} ({scene.material!r})")


def _material(scene, fem):
    """The scene's material on the isochoric invariants (its module's ``felupe_model``)."""
    _check_material(scene)
    return scene.material.felupe_model(fem)


@dataclass
class FECurve:
    """The solid's force-displacement curve (nondimensional like :class:`shellbvp.Curve`).

    Attributes
    ----------
    scene : Scene
    thickness : float
        eps = H / R_L (of a profiled wall, the pole's).
    delta : ndarray
        Mid-surface pole displacement (the shell model's delta).
    force : ndarray
        Indenter force / (mu R_L H).
    indenter : ndarray
        The indenter's displacement from first touch.
    contact_radius : ndarray
        Radius of the outermost surface point in contact (deformed), / R_L.
    pressure : ndarray
        The pressure ``p R_L/(mu H)`` at each depth: a sealed shell's (its volume held), else
        the scene's.
    mesh_error : ndarray
        ``|F - F_coarse| / F``: the force on a mesh with 2/3 the elements each way (NaN unless
        ``mesh_check``); quadratic elements converge at least like h^2, so this bounds the
        fine mesh's error by about 1.25x itself.
    success : bool
    message : str
    elements : tuple
        Elements along the meridian and through the thickness.
    settings : dict
    wall_time : float

    Examples
    --------
    >>> import numpy as np, shellbvp as sb
    >>> c = sb.fe_curve(sb.Scene.preset("base", material=sb.NeoHookean()), thickness=0.1, deltas=[0.05, 0.1])
    >>> c.success, c.elements                     # elements along the meridian, through H
    (True, (41, 3))
    >>> print(np.round(c.indenter, 3))            # the indenter goes deeper: the wall thins under it
    [0.052 0.103]
    """

    scene: object
    thickness: float
    delta: np.ndarray
    force: np.ndarray
    indenter: np.ndarray
    contact_radius: np.ndarray
    pressure: np.ndarray
    mesh_error: np.ndarray
    success: bool
    message: str
    elements: tuple
    settings: dict = field(default_factory=dict)
    wall_time: float = 0.0

    def summary(self) -> str:
        ok = np.isfinite(self.force)
        return (f"FE, eps {self.thickness:g}: {int(ok.sum())} of {self.delta.size} depths, "
                f"{self.elements[0]}x{self.elements[1]} elements, {self.wall_time:.1f} s; {self.message}")


def fe_curve(scene, thickness, deltas, *, at="pole", mesh_check=False, progress=None, max_dofs=None,
             **settings) -> FECurve:
    """Indent the scene's shell as a 3D axisymmetric solid of thickness ``eps`` (FElupe).

    Parameters
    ----------
    scene : Scene
        Shell, indenter, material (one with a ``felupe_model``) and rim (``"pinned"``: the rim
        face held plane and turning about its mid-thickness point; ``"clamped"``: held), or a
        closed shell (:mod:`shellbvp.fe_closed`: between plates, or on a substrate); beta,
        xi, the bending energy and the contact model are the shell model's and play no part
        here.  A pressure ``p R_L/(mu H)`` acts on the inner surface as ``p H/R_L`` (a follower
        load, :mod:`shellbvp.fe_pressure`): the solid is inflated first, and its depths are
        measured from the inflated state, as the shell model's.  ``sealed``: the volume below
        the inner surface is then held, its pressure an unknown (``FECurve.pressure``).
    thickness : float
        eps = H / R_L, in (0, 0.5]; of a wall whose thickness varies (``scene.thickness_profile``)
        the pole's, which scales the profile as ``scene.replace(thickness=eps)`` does: the wall is
        ``eps * H(S)/H(0)`` (at most 0.5 everywhere), its inner and outer surfaces at half that on
        either side of the reference mid-surface, and forces ``F / (mu R_L H)`` with the pole's H,
        as the shell model's.
    deltas : array_like
        Depths, increasing, > 0: of the mid-surface pole (``at="pole"``, the shell model's delta)
        or of the indenter from first touch (``at="indenter"``, what an instrument records); of a
        closed shell, the approach of its mid-surface poles, or of the indenters (the plates, or
        the tip and the substrate).
    at : {"pole", "indenter"}
        What ``deltas`` are.  Both are reported (``delta`` and ``indenter``).
    mesh_check : bool
        Also solve on a mesh with 2/3 the elements each way and report the difference
        (``mesh_error``).
    progress : callable, optional
        Called as ``progress(i, depth, force)`` after each depth.
    max_dofs : int, optional
        Refuse (ValueError, before the mesh is built) a solid of more unknowns than this
        (:func:`fe_size`); default ``sb.options``' ``max_fe_dofs`` (50,000).
    **settings
        Override :data:`FE_DEFAULTS`.

    Returns
    -------
    FECurve
        Depths not reached are NaN, with ``success`` False and a message saying where it stopped.

    Examples
    --------
    >>> import numpy as np, shellbvp as sb
    >>> scene = sb.Scene.preset("base", material=sb.NeoHookean())
    >>> c = sb.fe_curve(scene, thickness=0.1, deltas=[0.05, 0.1])
    >>> print(np.round(c.force, 4))               # F / (mu R_L H) of the 3D solid
    [0.0356 0.0891]
    """
    t0 = time.perf_counter()
    eps = float(thickness)
    if not (math.isfinite(eps) and 0 < eps <= 0.5):
        raise ValueError(f"thickness (H / R_L) must be in (0, 0.5]; got {thickness!r}")
    deltas = np.atleast_1d(np.asarray(deltas, dtype=float))
    if deltas.size == 0 or not np.all(np.isfinite(deltas)) or np.any(deltas <= 0) or np.any(np.diff(deltas) <= 0):
        raise ValueError("deltas must be finite, > 0 and increasing")
    if at not in ("pole", "indenter"):
        raise ValueError(f"at must be 'pole' or 'indenter'; got {at!r}")
    check_solid_scene(scene)
    if scene.thickness_profile is not None:
        _check_profile(scene, eps)
    unknown = set(settings) - set(FE_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown FE setting(s) {sorted(unknown)}; known: {sorted(FE_DEFAULTS)}")
    opts = {**FE_DEFAULTS, **settings}
    if opts["rim_face"] not in RIM_FACES:
        raise ValueError(f"rim_face must be one of {RIM_FACES}; got {opts['rim_face']!r}")
    _check_max_dofs(max_dofs)
    check_fe_size(fe_size(scene, eps, **opts), max_dofs)
    path = _indenter_path if at == "indenter" else _pole_path
    out = path(scene, eps, deltas, opts, progress)
    err = np.full(deltas.size, np.nan)
    if mesh_check:
        Fc = path(scene, eps, deltas, coarser(opts), None).force
        err = np.abs(out.force - Fc) / np.abs(out.force)
    return FECurve(scene, eps, out.delta, out.force, out.indenter, out.contact_radius, out.pressure, err, out.success,
                   out.message, out.elements, settings={**opts, "at": at}, wall_time=time.perf_counter() - t0)


@dataclass
class _Path:
    delta: np.ndarray
    indenter: np.ndarray
    force: np.ndarray
    contact_radius: np.ndarray
    pressure: np.ndarray
    success: bool
    message: str
    elements: tuple


def _start(scene, eps, n, opts):
    """The model with its solver, and empty arrays for ``n`` depths."""
    model = _build(scene, eps, through_thickness=opts["through_thickness"],
                   element_length=opts["element_length"], pole_refinement=opts["pole_refinement"],
                   bulk=opts["bulk"], penalty=opts["penalty"], gauss_points=opts["gauss_points"],
                   band=opts["band"], rim_face=opts["rim_face"])
    model.contact.bind(model.mesh.points)
    return model, Newton(model, opts["tol"], opts["delta_tol"]), _Path(*(np.full(n, np.nan) for _ in range(5)), False, "",
                                                    model.elements)


def _record(out, i, model, solver):
    _, _, F_i, rc_i = model.contact.evaluate(model.field[0].values.ravel(), with_matrix=False)
    out.force[i], out.indenter[i], out.delta[i], out.contact_radius[i] = F_i / model.eps, \
        model.approach * solver.indenter, solver.delta(), rc_i
    out.pressure[i] = solver.pressure / model.eps


def _ended(out, message, success=False):
    out.success, out.message = success, message
    return out


def _indenter_path(scene, eps, targets, opts, progress):
    """The indenter moved to each target (its displacement from first touch)."""
    return _march(scene, eps, targets, opts, progress, pole=False)


def _pole_path(scene, eps, deltas, opts, progress):
    """Each mid-surface pole displacement reached with the indenter's position as an unknown."""
    return _march(scene, eps, deltas, opts, progress, pole=True)


def _march(scene, eps, targets, opts, progress, pole):
    model, solver, out = _start(scene, eps, targets.size, opts)
    if scene.pressure and not solver.inflate():
        return _ended(out, f"no inflated state at pressure {scene.pressure:g}")
    if scene.sealed:
        solver.seal()
    # a first touch under indenter control (pole control needs a contact to move the pole)
    if not solver.move(min(0.02 * eps, 0.5 * targets[0] / model.approach)):
        return _ended(out, "no equilibrium at first touch")
    step = 0.5 * eps
    cap = lambda x: 0.25 * max(x, eps) + 0.5 * eps  # noqa: E731
    for i, target in enumerate(targets):
        # the indenter's target: its approach to the substrate or the other plate (each plate moves half)
        reached, step = solver.march(target if pole else target / model.approach, pole, step, cap)
        if not reached:
            where = f"delta = {solver.delta():.4g}" if pole else \
                f"the indenter's displacement {model.approach * solver.indenter:.4g}"
            return _ended(out, f"no equilibrium beyond {where}")
        _record(out, i, model, solver)
        if pole:
            out.delta[i] = target
        if progress is not None:
            progress(i, target, out.force[i])
    return _ended(out, "all requested depths computed", True)
