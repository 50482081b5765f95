"""The shell under pressure before the indenter touches it: the start of a pressurised curve.

A pressure ``p`` below the shell (``Scene.pressure``; > 0 pushes it towards the indenter)
deforms it before any contact.  That state is itself a boundary-value problem, the
chain ``inflated``: one free region from a regular pole (``FreePole``: isotropic
stretch, ``phi/S = psi kappa_s``, and no axial force, ``F(S) = 0``) to the rim.

What is held at the rim (the paper's remark on ``lambda_theta(L)``, its section on
boundary conditions and its conclusion): the rim stays simply supported at its reference
radius and height, ``lambda_theta(L) = 1``, ``z(L) = 0``, ``M_s(L) = 0``, as without
pressure.  So the rim ring takes the pressure's reaction (a seed slotted in a hole, a
patch of membrane clamped on a ring, a cell held by a pipette's rim); a pre-stretched
rim, ``lambda_theta(L) = lambda_p > 1``, is not offered.  Consequently the inflated shape
has a boundary layer at the rim where the hoop stretch returns to 1.  ``Scene(rim="clamped")``
holds the rim's slope too, ``phi(L) = Phi(L)`` instead of ``M_s(L) = 0`` (the clamped caps of the
buckling literature); it is offered here only, not in contact.

The inflated pole rises by ``pole_rise`` above ``Z(0)``; delta is measured from there
(the generated code's ``z_tip = Z(0) + pole_rise - delta``), so every curve starts at
delta = 0 from the inflated shape, which is also what the crude guesses start from.

A closed shell is solved on the half above its equator (the rim's rows hold its tangent
vertical, no horizontal force, the equator at its height), exact where its halves are mirror
images.  One whose halves differ (``UserShell.closed_halves``, an egg) inflates as a whole: both
halves free from their poles to the equator, joined there as on the substrate (the chain's
``Seam``: the slope, the radius, the height, ``tau_s``, ``M_s`` and the shear continuous), the
equator's tangent free to tilt.  The lower pole's axial force then follows from the upper's and
the seam (both halves' axial force is the same first integral), so its row holds the rigid
translation instead: the equator at ``z = 0``.  Each pole's rise (the upper's ``pole_rise``, the
lower's ``lower_pole_rise``, in its mirror image) is where the tip, and the substrate, find it.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .chain import Chain, ChainBVP, FreePole, Point, Region, Rim, Seam
from .diagnosis import as_failure, diagnose
from .march import Steps, march
from .model import lower_structure
from .solution import Solution, attach_tip_table, state_class

__all__ = ["inflate", "InflatedState", "inflated_chain", "inflated_pole_rise", "start_shape", "system_parameters",
           "enclosed_volume", "InflatedStart", "INFLATED_FIELDS", "inflated_start", "halves_chain", "lower_pole_rise"]

#: Pole start of the inflated state, ``zeta = EPS * L`` (the free pole's truncation error
#: is O(zeta^2): 1e-8 relative, below the inflation's tolerance).
EPS = 1e-4
#: Tolerance of the inflated state: it fixes the origin of delta for every point of a curve.
TOL = 1e-8
_MAX_NODES = 50000


@state_class
class InflatedState(Solution):
    """The shell under its pressure before the indenter touches it: a :class:`Solution`
    of topology ``"inflated"`` with the numbers that fix where a curve starts."""

    pole_rise: float = math.nan
    pole_stretch: float = math.nan
    volume_change: float = math.nan
    rim_hoop_tension: float = math.nan
    #: a closed shell whose halves differ: its lower pole's rise (in its mirror image; NaN otherwise)
    lower_pole_rise: float = math.nan


#: The inflated state's numbers that a curve carries and its file keeps: (name, units, what it is)
INFLATED_FIELDS = (("pole_rise", "1 (R_L)", "height of the inflated pole above the reference pole"),
                   ("pole_stretch", "1", "stretch at the inflated pole"),
                   ("volume_change", "1 (R_L^3)", "V - V_ref, V between the shell and its rim's plane"),
                   ("rim_hoop_tension", "1 (mu H)", "tau_theta at the rim"))


@dataclass(frozen=True)
class InflatedStart:
    """Where a curve under pressure starts: the numbers of its inflated state (:func:`inflate`),
    which the curve carries (``Curve.inflated``) and its file keeps.  NaN where the state was
    not found."""

    pole_rise: float
    pole_stretch: float
    volume_change: float
    rim_hoop_tension: float


def inflated_start(scene) -> InflatedStart | None:
    """The inflated state's numbers of a scene under pressure (:func:`inflate`, solved once per
    scene), None without pressure: a step of the continuation, passed on to the curve's file."""
    if not scene.pressure:
        return None
    state = inflate(scene)
    return InflatedStart(**{name: float(getattr(state, name)) for name, _, _ in INFLATED_FIELDS})


def inflated_chain(L: float) -> Chain:
    """One free region on ``[EPS L, L]``: a regular free pole and the rim."""
    ln_L = math.log(L)
    return Chain("inflated", (Region("free", Point("zeta", None, ln_L + math.log(EPS)), Point("L", None, ln_L)),),
                 (FreePole(0), Rim(0)), (), EPS)


def halves_chain(L_upper: float, L_lower: float) -> Chain:
    """A closed shell whose halves differ, free: each half from a regular pole (at ``EPS`` times
    its L) to the equator, where they meet (the upper's region first)."""
    regions = tuple(Region("free", Point("zeta", None, math.log(L) + math.log(EPS)), Point(end, None, math.log(L)))
                    for L, end in ((L_upper, "L"), (L_lower, "L_b")))
    return Chain("inflated", regions, (FreePole(0), FreePole(1), Seam(0, 1)), (), EPS)


class _HalvesInflated(ChainBVP):
    """The inflated chain of a closed shell whose halves differ: the lower pole's axial-force row
    (implied by the upper's and the seam's) holds the equator's height instead, ``z = 0``."""

    _ROW = 5  # FreePole(1)'s third row, G = 0
    _Z = 5  # z in a free region's states

    def bc(self, ya, yb, p=None):
        res = super().bc(ya, yb, p)
        res[self._ROW] = yb[self.offsets[0] + self._Z]
        return res

    def bc_jac(self, ya, yb, p=None):
        A, B = super().bc_jac(ya, yb, p)
        A[self._ROW], B[self._ROW] = 0.0, 0.0
        B[self._ROW, self.offsets[0] + self._Z] = 1.0
        return A, B


def _reference_states(sysm, S, k=0):
    """The unstressed reference shell in the free region's states (lt, phiS, ls, ks, rQ, z): of
    region ``k``'s half."""
    ref = sysm.models[k].reference_shell(S, sysm.par)
    one = np.ones_like(S)
    return np.vstack([one, ref["Phi"] / S, one, ref["kappa_s"] * one, 0 * S, ref["Z"] * one])


def _halves_differ(scene) -> bool:
    """A closed shell whose halves differ, both solved (``UserShell.closed_halves``)."""
    return lower_structure(scene) is not None


def _system(scene, pressure):
    """The inflated chain of ``scene`` at ``pressure`` (a step of the continuation)."""
    scene = scene.replace(pressure=pressure)
    mod = scene.model()
    par = scene.parameters(mod, pole_rise=0.0)
    if _halves_differ(scene):
        sysm = _HalvesInflated(scene, halves_chain(scene.shell_length, float(scene.shell.lower.geometry.L)), "delta",
                               0.0, model=mod, par=par, volume_control=False)
    else:
        sysm = ChainBVP(scene, inflated_chain(scene.shell_length), "delta", 0.0, model=mod, par=par,
                        volume_control=False)
    attach_tip_table(sysm)
    return sysm


def _solve(sysm, x, y, tol, max_nodes):
    with np.errstate(all="ignore"):
        bvp = sysm.solve(x, y, None, tol=tol, bc_tol=1e-10, max_nodes=max_nodes)
        return diagnose(sysm, bvp, tol, result=InflatedState)


@functools.lru_cache(maxsize=64)
def inflate(scene, tol: float = TOL, max_nodes: int = _MAX_NODES, *, start: InflatedState | None = None):
    """The scene's shell under its pressure, held at the rim, before the indenter touches it.

    Solved by continuation in the pressure from the unstressed shell (steps that halve
    where Newton fails; the first step goes to ``scene.pressure`` directly, so past a fold
    the state found may lie on another branch), or in one step from ``start``.  Cached per
    scene (and start).

    Parameters
    ----------
    scene : Scene
        ``scene.pressure`` may be 0 (then the state is the reference shell).
    tol, max_nodes : float, int
        solve_bvp's settings.
    start : InflatedState, optional
        A converged state of the same scene at another pressure: Newton starts from it, once (a
        caller's continuation along one branch, e.g. up to a fold); where Newton does not
        converge from it the state has ``success`` False.

    Returns
    -------
    InflatedState
        Topology ``"inflated"``; ``pole_rise`` (the pole's height above ``Z(0)``),
        ``pole_stretch``, ``volume_change`` (``V - V_ref``, V the volume between the shell
        and its rim's plane), ``rim_hoop_tension`` and the usual fields (``force`` is 0 to
        tolerance: no indenter).  A closed shell whose halves differ (``UserShell.closed_halves``,
        inflated as a whole): also ``lower_pole_rise`` (its lower pole's, in its mirror image,
        the equator at height 0), the whole shell's ``volume_change``, and the upper half's
        other numbers (``rim_hoop_tension`` at its equator).  ``success`` False with a message
        if the continuation stalled.

    Examples
    --------
    >>> import shellbvp as sb
    >>> state = sb.inflate(sb.Scene.preset("dome", pressure=0.05))
    >>> state.success, round(state.pole_rise, 4)
    (True, 0.0057)
    """
    target = float(scene.pressure)
    if start is not None:
        if not (isinstance(start, InflatedState) and start.success
                and start.scene.replace(pressure=target) == scene):
            raise ValueError("start must be a converged inflated state of the same scene at another pressure")
        # every other node of its mesh (keeping the ends): solve_bvp only adds nodes, so along a
        # chain of solves the mesh would only grow (a clamped cap over 60 steps of p: 900 -> 1740
        # nodes; thinned 860 -> 1510)
        keep = np.unique(np.r_[np.arange(0, start.x.size, 2), start.x.size - 1])
        return _finish(_solve(_system(scene, target), start.x[keep], start.y[:, keep], tol, max_nodes))
    sysm = _system(scene, 0.0)
    x = np.linspace(0.0, 1.0, 81)
    y = np.vstack([_reference_states(sysm, sysm.S(k, x, None), k) for k in range(len(sysm.regions))])
    if target == 0.0:
        return _finish(_solve(sysm, x, y, tol, max_nodes))
    def solve_at(p_next, states):
        return _solve(_system(scene, p_next), *((states[-1].x, states[-1].y) if states else (x, y)), tol, max_nodes)

    steps = Steps(target, advance=lambda u, s, t: t if abs(t - u) <= abs(s) else u + s,
                  too_small=lambda s, u: abs(s) < 1e-6 * max(1.0, abs(target)))
    m = march(0.0, target, solve_at, steps, arrived=lambda u: u == target)
    if not m.reached:
        out = as_failure(m.failed if m.last is None else m.last, 5,
                         f"the inflated state was not reached: continuation in the pressure stalled at "
                         f"p = {m.at:.4g} of {target:.4g} ({m.failed.message})")
        return _finish(out, failed=True)
    return _finish(m.last)


def _pole_rise(sysm, y0, k) -> float:
    """The rise of region ``k``'s pole above its half's ``Z(0)`` from its states ``y0`` at zeta."""
    zeta = sysm.S_point(sysm.regions[k].start, None)
    lt, phiS, ls, ks, rQ, z = y0
    ref = sysm.models[k].reference_shell
    # z(zeta) - z(0) = Int_0^zeta psi sin(phi) dS ~ psi phiS zeta^2/2 (phi ~ phiS S near the pole)
    return float(z - ls * ref(zeta, sysm.par)["R"] / zeta * phiS * zeta**2 / 2) - float(ref(0.0, sysm.par)["Z"])


def _finish(res, failed=False):
    """The inflated state's own numbers (from its system, ``res.system``), NaN where it failed."""
    nan = float("nan")
    if failed or not res.success:
        return res.with_(topology="inflated", pole_rise=nan, pole_stretch=nan, volume_change=nan, rim_hoop_tension=nan,
                         lower_pole_rise=nan)
    sysm = res.system
    halves = len(sysm.regions) == 2  # a closed shell whose halves differ: the upper's numbers, and its lower pole's
    rows = sysm.rows(0)
    rim = sysm.model.free_profile(np.array([sysm.S_point(sysm.regions[0].end, None)]), res.y[rows, -1:], sysm.par)
    volume = sysm.scene.closed_volume() if halves else sysm.scene.reference_volume()
    return res.with_(
        topology="inflated", pole_rise=_pole_rise(sysm, res.y[rows, 0], 0), pole_stretch=float(res.y[rows, 0][2]),
        volume_change=sysm.volume(res.sol, res.x, None) - volume, rim_hoop_tension=float(rim["tau_theta"][0]),
        lower_pole_rise=_pole_rise(sysm, res.y[sysm.rows(1), 0], 1) if halves else nan)


def system_parameters(scene, model=None):
    """The run-time parameters of a system of ``scene``: with the inflated state's pole rise
    (:func:`inflate`, solved once per scene) where the scene is under pressure."""
    return scene.parameters(model, pole_rise=inflated_pole_rise(scene) if scene.pressure else 0.0)


def lower_pole_rise(scene) -> float | None:
    """Where the substrate finds the lower pole of a closed shell whose halves differ under
    pressure (:func:`inflate`'s ``lower_pole_rise``, the lower half's ``pole_rise`` parameter),
    None for any other scene (its halves share the upper's)."""
    if not (scene.pressure and _halves_differ(scene)):
        return None
    inflated_pole_rise(scene)  # a ValueError if the inflated state was not found
    return float(inflate(scene).lower_pole_rise)


def enclosed_volume(scene) -> float:
    """V0 of a sealed scene: the volume between the shell and its rim's plane in the inflated
    state at ``scene.pressure`` (the reference volume at pressure 0).  What a sealed scene's
    systems hold the volume at.  A closed shell's: of the half above its equator; of one whose
    halves differ, the whole shell's (both halves').

    Parameters
    ----------
    scene : Scene
        Its ``sealed`` flag is not read: the volume of the open shell at its pressure.

    Returns
    -------
    float
        V0 (units R_L^3); a ValueError if the inflated state was not found.

    Examples
    --------
    >>> import shellbvp as sb
    >>> scene = sb.Scene.preset("balloon", sealed=True)
    >>> round(sb.enclosed_volume(scene) - scene.reference_volume(), 4)  # the inflated state's volume change
    0.088
    """
    reference = scene.closed_volume() if _halves_differ(scene) else scene.reference_volume()
    if not scene.pressure:
        return reference
    state = inflate(scene.replace(sealed=False))
    if not state.success:
        raise ValueError(f"the inflated state at pressure {scene.pressure:g} was not found "
                         f"({state.message}): no enclosed volume for the sealed shell")
    return reference + state.volume_change


def inflated_pole_rise(scene) -> float:
    """``inflate(scene).pole_rise``, or a ValueError if the inflated state was not found."""
    state = inflate(scene)
    if not state.success:
        raise ValueError(f"pressure = {scene.pressure:g}: {state.message}")
    return state.pole_rise


def start_shape(scene, S):
    """The shell before indentation at ``S`` as free-region states ``(lt, phiS, ls, ks, rQ, z)``:
    the reference shell, or the inflated state under pressure (guesses start from it)."""
    S = np.asarray(S, float)
    if not scene.pressure:
        return _reference_states(_system(scene, 0.0), S)
    state = inflate(scene)
    if not state.success:
        raise ValueError(f"pressure = {scene.pressure:g}: {state.message}")
    sysm = state.system
    t = np.clip(sysm.t_of(0, np.maximum(S, sysm.S_point(sysm.regions[0].start, None)), None), 0.0, 1.0)
    return state.sol(t)[sysm.rows(0)]  # (a closed shell whose halves differ: its upper half)
