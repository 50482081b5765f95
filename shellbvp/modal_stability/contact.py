"""What the indenter adds to a state's eigenproblem: which states are handled
(:func:`check_supported`), the contact regions, edges and lines of a state (:func:`contact_of`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..chain import CONTACT_KINDS, FREE_STATES, Edge, Kink, Line, PointPole, Seam, TipEnd
from ..configurations import CONFIGURATIONS, is_point_load, of
from ..edge_models import contact_models, edge_model
from ..inflation import EPS
from .form import chain_base, reference_shell


#: The tip's tangential behaviour on the contact set: free sliding, or no slip (the two bounds
#: of any friction coefficient; :mod:`shellbvp.modal_stability`).
FRICTION = ("frictionless", "sticking")

#: Junctions whose stability is not built: the contact running over the tip's end (TipEnd), where
#: the shell is held on both sides of a corner, and an interior corner (Kink: no state of
#: ``line+corner`` is found by the package's searches to check its terms on).  Every other chain --
#: free regions and regions on the tip joined by edges (smooth or cornered) and lines -- is.
NOT_BUILT = (Kink, TipEnd)

_LS, _KS = FREE_STATES.index("ls"), FREE_STATES.index("ks")


def supported(conf) -> bool:
    """Whether the stability of a registered configuration's states is built (no junction of its
    chain in :data:`NOT_BUILT`); None (the inflated shell, no contact) is."""
    if conf is None:
        return True
    return not any(isinstance(j, NOT_BUILT) for j in conf.chain(1e-3, 1.0, "smooth").junctions)


def check_supported(state, halves: bool = False):
    """ValueError (one line, naming what is not supported) unless :func:`stability` handles
    ``state``: a converged state of a configuration whose chain is :func:`supported`, with the
    smooth contact edge, under pressure (not volume) control; a closed shell on a substrate
    under a curved tip (``scene.two_contacts``) only where its two halves are asked for
    (``halves``: :func:`halves_of`)."""
    if not state.success:
        raise ValueError(f"stability: the state did not converge ({state.message})")
    conf = of(state)
    if not supported(conf):
        built = ", ".join(repr(c.name) for c in CONFIGURATIONS.values() if supported(c))
        raise ValueError(f"stability: topology {state.topology!r} is not supported (only the inflated shell and "
                         f"{built}: the contact running over the tip's end onto the indenter's cylinder and interior "
                         f"corners are not built)")
    if conf is None and state.scene is not None and state.scene.two_contacts:
        raise ValueError("stability: the inflated state of a closed shell on a substrate under a curved tip is not "
                         "built; check a state in contact (a mirror-symmetric shell's inflated state is the same "
                         "between plates, support='plates')")
    if state.scene is not None and state.scene.two_contacts and not halves:
        raise ValueError("stability: a closed shell on a substrate under a curved tip has two halves, each "
                         "from its own pole: contact_of takes one chain from one pole, halves_of the two")
    if conf is None:
        return
    scene = state.scene
    if not scene.contact_model.variational:
        supported_contacts = " or ".join(f"contact={n!r}" for n in contact_models() if edge_model(n).variational)
        raise ValueError(f"stability: contact={scene.contact!r} is not variational (its edge conditions are not "
                         f"the natural conditions of an energy); only {supported_contacts} is supported")
    if scene.sealed:
        raise ValueError("stability: a sealed shell (volume control) in contact is not supported, only "
                         "pressure control")


@dataclass(frozen=True)
class Corner:
    """A Weierstrass-Erdmann corner of a contact edge at ``S``, where
    lambda_s and kappa_s jump: ``ls``, ``dphi`` (= lambda_s Psi kappa_s, d phi/dS) and ``moment``
    (``r M_s``, the conjugate of phi') on the sides before and after S, the continuous ``Psi, r,
    phi`` there, ``tip_side`` (0 before, 1 after) and ``tip_slope``, the S-derivatives of the tip's
    curvatures (kappa_s, kappa_theta) there (module docstring, "Corners")."""

    S: float
    ls: tuple
    dphi: tuple
    moment: tuple
    Psi: float
    r: float
    phi: float
    tip_side: int
    tip_slope: tuple


def check_friction(friction):
    """ValueError (one line) unless ``friction`` is one of :data:`FRICTION`."""
    if friction not in FRICTION:
        raise ValueError(f"stability: friction must be one of {', '.join(map(repr, FRICTION))}, not {friction!r}")


@dataclass(eq=False)
class Contact:
    """What the tip adds to the eigenproblem of a state in contact (module docstring).

    ``base``: the base state as a function of S, with the contact pressure ``P`` (0 off the
    tip); ``S0``: where the mesh starts; ``held``: the S-intervals on the tip (w = w' = 0);
    ``lines``: the line contacts' S (w = 0); ``rings``: per edge or line ``(S, (a, b, c, d))``,
    its quadratic form ``a u^2 + b v^2 + 2 c u w' + d w'^2`` in the stiffness; ``pole_held``:
    the contact lies within [0, S0] or is a point load (the pole held at a point), with
    ``pole_force`` the axial force there and ``apex_curvature`` the tip's; ``friction``: one of
    :data:`FRICTION`, ``"sticking"`` also holding ``u = v = 0`` wherever the shell touches the tip.
    """

    base: object
    S0: float
    held: tuple = ()
    lines: tuple = ()
    rings: tuple = ()
    pole_held: bool = False
    pole_force: float = 0.0
    apex_curvature: float = 0.0
    corners: tuple = ()
    friction: str = "frictionless"

    @property
    def edges(self):
        """Where the contact starts or ends inside the mesh, the lines and the corners."""
        return tuple(sorted({S for S, _ in self.rings} | {S for a, b in self.held for S in (a, b) if S > self.S0}
                            | {c.S for c in self.corners}))


def _junction_points(sysm, p):
    """(S, kind (:class:`Edge` or :class:`Line`), inner region, outer region) of every contact edge
    and line, pole to rim, in the order of ``Solution.edge_forces`` (``shellbvp.diagnosis``)."""
    out = []
    for j in sysm.junctions:
        if isinstance(j, Edge):
            out.append((float(sysm.S_point(sysm.regions[min(j.kc, j.kf)].end, p)), Edge, j.kc, j.kf))
        elif isinstance(j, Line):
            out.append((float(sysm.S_point(sysm.regions[j.k].end, p)), Line, j.k, j.k + 1))
    return out


def contact_of(state, S0=None, friction: str = "frictionless") -> Contact:
    """The :class:`Contact` of a state on the tip: the base state from the regions' generated
    profiles (:func:`chain_base`), the regions on the tip, and at each contact edge and line
    its normal ring force (``state.edge_forces``, ``-2 pi [r Q]``) with the curvatures there;
    ``friction`` one of :data:`FRICTION`."""
    check_friction(friction)
    check_supported(state)
    sysm, p = state.system, state.p
    points = _junction_points(sysm, p)
    gaps = [-float(state.curvature_excess) if kind is Line else math.nan for _, kind, _, _ in points]
    regions = range(len(sysm.regions))
    apex = state.scene.tip.apex_curvature() / state.scene.rho
    contact = _contact(state, regions, S0, friction, points, list(state.edge_forces), gaps, is_point_load(state), apex)
    return replace(contact, corners=_corners(state, contact.base))


def halves_of(state, S0=None, friction: str = "frictionless") -> tuple:
    """The :class:`Contact` of each half of a closed shell on a substrate under a curved tip
    (``scene.two_contacts``), upper (on the tip) then lower (on the plane, in its mirror image
    z -> -z, as the chain solves it), each from its own pole to the equator: ring forces
    ``-2 pi [r Q]`` and line gaps from the regions' profiles, the plane's curvature 0 (its
    pressure's and rings' sliding terms vanish: kappa_s = 0, sin(phi) = 0 there)."""
    check_friction(friction)
    check_supported(state, halves=True)
    sysm, p = state.system, state.p
    seam = next(j for j in sysm.junctions if isinstance(j, Seam))
    out = []
    for regions, apex in ((range(seam.ku + 1), state.scene.tip.apex_curvature() / state.scene.rho),
                          (range(seam.ku + 1, len(sysm.regions)), 0.0)):
        points = [pt for pt in _junction_points(sysm, p) if pt[2] in regions]
        forces, gaps = _ring_forces(state, points)
        point = any(isinstance(j, PointPole) and j.k == regions[0] for j in sysm.junctions)
        out.append(_contact(state, regions, S0, friction, points, forces, gaps, point, apex))
    return tuple(out)


def _ring_forces(state, points):
    """The normal ring force ``-2 pi [r Q]`` (outer minus inner) at each of ``points``
    (:func:`_junction_points`) and, at a line, the curvature gap (the indenter's kappa_s minus the
    shell's; NaN at an edge), from the regions' profiles at their ends."""
    sysm, p = state.system, state.p
    par, q = sysm.par_at(p), sysm.quantities(p)
    kernels = sysm.kernels.active
    y0, y1 = state.sol(0.0), state.sol(1.0)  # every region runs from t = 0 to t = 1

    def end(k, at_end):
        S = np.array([float(sysm.S_point(sysm.regions[k].end if at_end else sysm.regions[k].start, p))])
        y = (y1 if at_end else y0)[sysm.rows(k)]
        return getattr(kernels, f"{sysm.regions[k].kind}_profile")(S, y[:, None], par), y

    lines = {j.k: j for j in sysm.junctions if isinstance(j, Line)}
    forces, gaps = [], []
    for S, kind, inner, outer in points:
        inner, outer = min(inner, outer), max(inner, outer)
        (fi, yin), (fo, _) = end(inner, True), end(outer, False)
        rq = [float(np.ravel(np.asarray(f["r"]) * np.asarray(f["Q"]))[0]) for f in (fi, fo)]
        forces.append(-2 * np.pi * (rq[1] - rq[0]))
        if kind is Line:
            j = lines[inner]
            on = getattr(kernels, f"{j.on}_profile")(np.array([S]), np.array([[q[j.chi]], [yin[_LS]]]), par)
            gaps.append(float(np.ravel(on["kappa_s"])[0]) - float(yin[_KS]))
        else:
            gaps.append(math.nan)
    return forces, gaps


def _contact(state, regions, S0, friction, points, forces, gaps, point, apex) -> Contact:
    """The :class:`Contact` of the chain of ``regions`` (all, or a closed shell's half) with its
    contact edges and lines ``points`` (:func:`_junction_points`), their normal ring forces and
    line gaps; ``point``: the pole held at a point (a point load); ``apex``: the indenter's
    curvature at its apex."""
    sysm, p = state.system, state.p
    regions = list(regions)
    L = float(sysm.L)
    zeta = float(sysm.S_point(sysm.regions[regions[0]].start, p))
    S0 = max(EPS * L, zeta) if S0 is None else max(float(S0), zeta)
    base = chain_base(state, regions)
    if point or (len(points) == 1 and points[0][0] <= S0 * (1 + 1e-9)):
        # the one contact (a cap or a line) lies within the pole's disc: a point contact there
        return Contact(base, S0, pole_held=True, pole_force=float(state.force), apex_curvature=apex,
                       friction=friction)
    if points[0][0] <= S0 * (1 + 1e-9):
        raise ValueError(f"stability: a contact edge at S = {points[0][0]:.3g} inside the mesh's start "
                         f"S0 = {S0:.3g} of a {state.topology!r} state is not supported")
    held = tuple((max(float(sysm.S_point(sysm.regions[k].start, p)), S0), float(sysm.S_point(sysm.regions[k].end, p)))
                 for k in regions if sysm.regions[k].kind in CONTACT_KINDS)
    lines = [S for S, kind, _, _ in points if kind is Line]
    if len(lines) > 1:
        raise ValueError("stability: more than one line contact is not supported")
    rings = []
    for (S, kind, k, other), force, gap in zip(points, forces, gaps):
        side = S * (1 - 1e-12) if k < other else S * (1 + 1e-12)  # inside region k: the tip's side of an edge
        at = base(np.array([side]))
        R, Psi = (float(v[0]) for v in reference_shell(state.scene, np.array([S])))
        kt = float(np.sin(at["phi"][0]) / (at["lt"][0] * R))
        ks = float(at["ks"][0])
        f = float(force) / (2 * np.pi)  # the normal ring force per unit length, times r
        if kind is Edge:
            rings.append((S, (-f * ks, -f * kt, 0.0, 0.0)))
            continue
        # a line: the gap's second variation with the contact point rolling along the meridian,
        # kappa_S u^2 + 2 u w'/psi - w'^2/(psi^2 gap) + kappa_theta v^2 (module docstring), with
        # gap = kappa_s(indenter) - kappa_s(shell) = -curvature_excess > 0, kappa_S the shell's
        if not gap > 0:
            raise ValueError(f"stability: the line contact's curvature gap {gap:.3g} is not positive (the shell "
                             f"bends as tightly as the indenter there: a band), not supported")
        psi = float(at["ls"][0]) * Psi
        rings.append((S, (-f * ks, -f * kt, -f / psi, f / (psi**2 * gap))))
    return Contact(base, S0, held=held, lines=tuple(lines), rings=tuple(rings), apex_curvature=apex,
                   friction=friction)


def _corners(state, base):
    """The :class:`Corner` of every cornered contact edge (an ``Edge`` whose model jumps: the corner)."""
    sysm, p = state.system, state.p
    out = []
    for j in sysm.junctions:
        if not (isinstance(j, Edge) and j.model.jumps):
            continue
        k, tip_side = min(j.kc, j.kf), int(j.kc > j.kf)
        S = float(sysm.S_point(sysm.regions[k].end, p))
        sides = base(np.array([S * (1 - 1e-12), S * (1 + 1e-12)]))
        R, Psi = (float(v[0]) for v in reference_shell(state.scene, np.array([S])))
        r, phi = float(sides["lt"][1]) * R, float(sides["phi"][1])
        ls = tuple(float(v) for v in sides["ls"])
        dphi = tuple(float(l * Psi * k) for l, k in zip(ls, sides["ks"]))
        # kappa_theta = sin(phi)/r: its S-derivative (cos(phi) phi' r - sin(phi) r')/r^2, r' = psi cos(phi)
        kt = math.sin(phi) / r
        slope = (float(sides["dks"][tip_side]), math.cos(phi) * (dphi[tip_side] - ls[tip_side] * Psi * kt) / r)
        out.append(Corner(S, ls, dphi, tuple(r * float(v) for v in sides["Ms"]), Psi, r, phi, tip_side, slope))
    return tuple(out)
