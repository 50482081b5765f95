"""What every contact configuration shares: the result object, statuses, the guarded
solve_bvp call, error estimates and the checks against the indenter.

:class:`Solution` is built by each configuration's diagnosis (``state`` for the cap,
``pointload``, ``liftoff``); it never raises for a state that does not converge
(``success=False``, a ``status`` from :data:`STATUS_MESSAGES` and a ``message``).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import collocation
from .config import OPTIONS

__all__ = ["STATUS_MESSAGES", "STATE_NUMBERS", "Solution", "state_class", "failure", "solve_bvp", "run_status",
           "inadmissible", "cached", "thin_mesh", "warm_mesh", "secant_ratio", "richardson_error", "finished",
           "penetration", "wall_gap", "attach_tip_table", "default_eps"]


#: What each ``Solution.status`` means and what to try: ``{status: message}``.
STATUS_MESSAGES = {
    0: "converged",
    1: "the maximum number of mesh nodes was exceeded: raise max_nodes or loosen tol, or start "
       "from a neighbouring solution (guess=)",
    2: "a singular Jacobian was met: the guess is too far from a solution; start from a "
       "neighbouring solution (guess=) or use sb.curve",
    3: "solve_bvp could not satisfy the boundary conditions to bc_tol",
    4: "converged to an inadmissible state (see message): start from a neighbouring solution",
    5: "no initial guess converged (crude guesses and continuation from small delta)",
}


_NAN = float("nan")


class _NonFinite(Exception):
    """Raised inside solve_bvp by a Jacobian with NaN or inf entries (see :func:`solve_bvp`)."""


class _OverBudget(Exception):
    """Raised inside solve_bvp when a run asks for more Jacobians than ``max_jacobians``;
    carries the unknowns of the last iterate a Jacobian was evaluated at."""

    def __init__(self, p):
        super().__init__()
        self.p = p


def _finite_jacobian(jac, what, max_evaluations=None):
    """``jac`` that refuses to hand non-finite entries to solve_bvp's sparse LU (and, with
    ``max_evaluations``, stops the run after that many calls)."""
    calls = 0

    def checked(*args):
        nonlocal calls
        calls += 1
        if max_evaluations is not None and calls > max_evaluations:
            raise _OverBudget(None if len(args) < 3 or args[2] is None else np.array(args[2], float))
        out = jac(*args)
        for block in (out if isinstance(out, tuple) else (out,)):
            if block is not None and not np.all(np.isfinite(block)):
                raise _NonFinite(what)
        return out

    return checked


class _NoSolution:
    """Interpolant of a run that produced no state: NaN everywhere."""

    def __init__(self, n):
        self.n = n

    def __call__(self, t):
        t = np.asarray(t, float)
        return np.full((self.n,) + t.shape, np.nan)


def _failed_run(x, y, p, status, message):
    """A solve_bvp-like result of a run stopped before (or instead of) a LAPACK call."""
    from scipy.optimize import OptimizeResult

    x = np.asarray(x, float)
    n = np.shape(y)[0]
    p = None if p is None else np.full(np.shape(p), np.nan)
    return OptimizeResult(sol=_NoSolution(n), p=p, x=x, y=np.full((n, x.size), np.nan),
                          yp=np.full((n, x.size), np.nan), rms_residuals=np.full(max(x.size - 1, 0), np.nan),
                          niter=0, status=status, message=message, success=False)


def solve_bvp(fun, bc, x, y, p=None, *, fun_jac, bc_jac, max_jacobians=None, kernels=None, **kwargs):
    """scipy.integrate.solve_bvp, imported on first use (scipy.integrate is most of the
    import time of shellbvp, and reading files or loading a model does not need it),
    with a guard on what reaches its linear algebra.

    ``max_jacobians``: stop the run (status 3) when Newton asks for more collocation
    Jacobians than that -- for probes that have a fallback: solve_bvp restarts a Newton that
    diverges on an unchanged mesh up to 10 times, ~35 Jacobians.  The result then keeps the
    unknowns ``p`` of the last iterate (its states and numbers are NaN), for the caller to
    see where Newton was going.  ``kernels``: compiled kernels that factorise the collocation
    Jacobian (``shellbvp.collocation.solving_with``), or None (SuperLU).

    A guess with NaN/inf or a mesh that is not strictly increasing, and a Jacobian
    that overflows during Newton (a state far outside the model's domain, e.g. an
    extreme scene), end the run with status 2 instead: solve_bvp would pass such a
    matrix to SuperLU, whose BLAS calls then print ``** On entry to DGEMV parameter
    number 2 had an illegal value`` on stdout (Fortran, not Python) and return garbage.
    """
    from scipy.integrate import solve_bvp as _solve_bvp

    collocation.install()  # the collocation Jacobian without its stored zeros, or compiled
    xa = np.asarray(x, float)
    if xa.ndim != 1 or xa.size < 2 or not np.all(np.isfinite(xa)) or not np.all(np.diff(xa) > 0):
        return _failed_run(x, y, p, 2, "degenerate mesh (not strictly increasing and finite): no solve")
    if not np.all(np.isfinite(y)) or (p is not None and not np.all(np.isfinite(p))):
        return _failed_run(x, y, p, 2, "the initial guess has NaN or inf entries: no solve")
    try:
        # solve_bvp evaluates fun_jac twice per Jacobian (at the nodes and the midpoints)
        with collocation.solving_with(kernels):
            return _solve_bvp(fun, bc, x, y, p, fun_jac=_finite_jacobian(
                fun_jac, "fun_jac", None if max_jacobians is None else 2 * max_jacobians),
                bc_jac=_finite_jacobian(bc_jac, "bc_jac"), **kwargs)
    except _OverBudget as exc:
        res = _failed_run(x, y, p, 3, f"{STATUS_MESSAGES[3]}: Newton did not converge within {max_jacobians} "
                                      f"Jacobians (the budget of a probe)")
        if exc.p is not None:
            res.p = exc.p
        return res
    except _NonFinite as exc:
        return _failed_run(x, y, p, 2, f"the Jacobian ({exc}) overflowed to NaN/inf during Newton: the "
                                       f"iterate left the model's domain (no solve of the collocation system)")
    except MemoryError:  # the refined mesh's collocation system outgrew the machine: a node budget too
        return _failed_run(x, y, p, 1, f"{STATUS_MESSAGES[1]} (memory ran out on the refined mesh, from "
                                       f"{xa.size} nodes)")


def _refuse(self, name, value=None):
    raise dataclasses.FrozenInstanceError(f"cannot assign to {name!r}: a state is never written (with_() makes a new one)")


def state_class(cls):
    """``cls`` as a frozen dataclass with slots, :class:`Solution` or a subclass with a
    configuration's own fields: a field set or a name not declared raises ``FrozenInstanceError``
    (CPython < 3.12 raises TypeError for the latter: a frozen class with slots calls super())."""
    cls = dataclass(frozen=True, eq=False, repr=False, slots=True)(cls)
    cls.__setattr__ = cls.__delattr__ = _refuse
    return cls


@state_class
class Solution:
    """Result of :func:`solve`: every state of every configuration, with fixed fields.

    A field that a configuration does not have keeps its default (NaN for a number).  Built
    once (:func:`shellbvp.diagnosis.diagnose`, or :func:`failure` for a search without a state)
    and never written (``FrozenInstanceError``): what a later step adds (an error estimate, the
    wall time, a flag) makes a new state, :meth:`with_`.  No state holds another.

    Attributes
    ----------
    success : bool
        Converged to an admissible state (``status == 0``).
    status : int
        0 converged; 1 too many nodes; 2 singular Jacobian; 3 boundary conditions
        not met to ``bc_tol``; 4 inadmissible (delta < 0, cap beyond the tip, ...);
        5 no guess converged.  See ``STATUS_MESSAGES``.
    message : str
    delta, force, lambda0, Sc : float
        Pole displacement, indenter force F (> 0 pushing), pole stretch, contact circle.
    topology : str
        The contact configuration (``"cap"``, ``"point"``, ``"line"``, ``"annulus"``,
        ``"cap+line(tip)"``, ``"cap+line(cylinder)"``, ``"cap+band(cylinder)"``,
        ``"cap+cylinder"``; ``shellbvp.chain``).
    control : str
        What was prescribed: ``"delta"``, ``"force"`` or ``"lambda0"``.
    scene, system
        The :class:`~shellbvp.scene.Scene` and the solved ``ChainBVP`` (None for a failure
        without a system).
    S1, edge_S : float, list of float
        Where the contact starts (0 when it reaches the pole; a lifted pole's first edge);
        every contact edge's S, pole to rim.
    x, y, p, sol, rms_residuals, niter
        solve_bvp's mesh on t in [0, 1], stacked states (8, m) (layout in
        ``shellbvp.chain``), unknown parameters, interpolant, residuals, iterations.
    tol, nodes, max_residual : float, int, float
        The residual tolerance the state was solved to, its mesh nodes, and the largest
        relative collocation residual.
    z_tip, energy : float
        The indenter tip's height; ``E = 2 pi Int U R Psi dS`` (F = dE/ddelta for the smooth model).
    shear_delta : float
        The transverse-shear depth correction (``shellbvp.thickness``).
    ring_force, cap_force : float
        Axial force of the ring at Sc (jump of Q) and of the pressure on the cap;
        ``force = ring_force + cap_force``.  For ``contact="paper"`` the ring force is ~0.
    ring_force_inner, edge_forces : float, list of float
        The ring force at the first edge of a configuration with two (else 0); the normal ring
        force of every edge.
    pressure : float
        The pressure below the shell (``p R_L/(mu H)``): the scene's, or under volume control
        (``Scene.sealed``) the one that holds the enclosed volume.
    pressure_min : float
        Minimum contact pressure over the contact regions (< 0: the shell would pull the indenter).
    edge_legendre : float
        det d(tau_s, M_s)/d(lambda_s, kappa_s) at Sc+ relative to mid-region; it goes to 0
        where the energy loses convexity at the contact edge and the branch ends.
    legendre_min, legendre_min_S : float
        The smallest such determinant over the free shell, and where.
    contact_edge, edge_jump_ls, edge_jump_ks : str, float, float
        The edge conditions in force at Sc (``shellbvp.corner``); the jumps of lambda_s and
        kappa_s across the contact edge.
    penetration, wall_gap : float
        Largest height of the free shell above the indenter's surface (> 0: it passes through
        the indenter); smallest distance of the free shell above the tip's end from the
        indenter's cylinder (< 0: through it).
    tip_end_margin : float
        How far the last contact on the tip is from the tip's end, in the tip's angle
        (< 0: past it).
    S_end : float
        Where a contact that ends at the tip's end ends.
    curvature_excess : float
        A line contact's kappa_s beyond the indenter's (> 0: the shell would cut into it).
    pole_clearance : float
        A lifted pole's height above the tip (computed on demand by the touch-down search).
    valid, flags : bool, list of str
        pressure_min >= 0, ring_force >= 0, no penetration, contact on the tip; why the state
        is not valid (empty when valid).
    force_defect : float
        ``max abs(F(S) - F)`` over the free region (F is a first integral there).
    past_tip_end : bool
        Set on a state of status 4 whose contact has passed the end of the tip (onto the
        indenter's cylinder): :func:`passed_tip_end`.
    force_error, delta_error : float
        Error estimates (NaN if not estimated); ``error_method`` says how
        (``"richardson"``: halved mesh, ``"calibrated"``, or ``""``).
    wall_time : float
        Seconds.
    cap_state, candidates
        What a search that replaced a state attached: the numbers of the cap state it
        replaced (:meth:`summary`), the energies of the wall configurations that were
        compared (None where there was no such search).

    Notes
    -----
    A run that did not converge (status 1, 2, 3 or 5) carries NaN for every number of a
    state (force, delta, lambda0, Sc, energy, ring and edge forces, pressures, errors, ...)
    but the prescribed delta, force or lambda0, as given; ``x``, ``y``, ``p`` are its last
    iterate, for inspection, and ``niter``, ``nodes``, ``max_residual``,
    ``rms_residuals``, ``wall_time`` describe the run.

    Examples
    --------
    >>> import shellbvp as sb
    >>> sol = sb.solve(sb.Scene.preset("base"), delta=0.2)
    >>> sol.success, sol.status, sol.message, sol.topology
    (True, 0, 'converged', 'cap')
    >>> print(f"F = {sol.force:.4f}, lambda0 = {sol.lambda0:.4f}, valid: {sol.valid}")
    F = 0.3639, lambda0 = 1.0010, valid: True
    >>> sol.force_error < 1e-6                  # Richardson estimate
    True
    """

    # how the run went
    status: int = 5
    message: str = ""
    success: bool = False
    topology: str = "cap"
    control: str = "delta"
    scene: Any = None
    system: Any = None
    # solve_bvp's run
    x: np.ndarray = field(default_factory=lambda: np.empty(0))
    y: np.ndarray = field(default_factory=lambda: np.empty((8, 0)))
    p: np.ndarray = field(default_factory=lambda: np.empty(0))
    sol: Any = None
    rms_residuals: np.ndarray = field(default_factory=lambda: np.empty(0))
    tol: float = _NAN
    niter: int = 0
    nodes: int = 0
    max_residual: float = _NAN
    wall_time: float = _NAN
    # the state
    delta: float = _NAN
    force: float = _NAN
    lambda0: float = _NAN
    Sc: float = _NAN
    S1: float = 0.0
    edge_S: list = field(default_factory=list)
    z_tip: float = _NAN
    pressure: float = _NAN
    energy: float = _NAN
    shear_delta: float = 0.0
    ring_force: float = _NAN
    ring_force_inner: float = 0.0
    cap_force: float = _NAN
    edge_forces: list = field(default_factory=list)
    # checks
    pressure_min: float = _NAN
    penetration: float = _NAN
    wall_gap: float = _NAN
    tip_end_margin: float = _NAN
    S_end: float = _NAN
    force_defect: float = _NAN
    edge_legendre: float = _NAN
    legendre_min: float = _NAN
    legendre_min_S: float = _NAN
    contact_edge: str = ""
    edge_jump_ls: float = _NAN
    edge_jump_ks: float = _NAN
    curvature_excess: float = _NAN
    pole_clearance: float = _NAN
    valid: bool = False
    flags: list = field(default_factory=list)
    past_tip_end: bool = False
    # error estimates
    force_error: float = _NAN
    delta_error: float = _NAN
    error_method: str = ""
    # what a search that replaced this state attached (numbers, not states)
    cap_state: Any = None
    candidates: Any = None

    def __repr__(self):
        keys = ("success", "status", "delta", "force", "lambda0", "Sc", "nodes", "valid")
        inner = ", ".join(f"{k}={getattr(self, k)!r}" for k in keys)
        return f"{type(self).__name__}({inner})"

    def summary(self) -> dict:
        """The numbers that a replaced state leaves behind (``cap_state``)."""
        return {k: getattr(self, k) for k in ("delta", "force", "energy", "pressure_min", "Sc")}

    def with_(self, **fields) -> Solution:
        """A copy of this state with ``fields`` replaced (only declared fields)."""
        return dataclasses.replace(self, **fields)

    # -- fields over S ------------------------------------------------------------------
    def profile(self, points_per_interval: int = 1):
        """Physical fields over S, pole to rim.

        Parameters
        ----------
        points_per_interval : int
            ``> 1`` adds points between mesh nodes (from the interpolant).

        Returns
        -------
        dict of ndarray
            1-D arrays: ``S`` (increasing), ``region`` (0 on the indenter,
            1 free; a lifted pole's free cap comes first), ``r``, ``z``,
            ``phi``, ``lambda_s``, ``lambda_theta``, ``kappa_s``, ``kappa_theta``, ``T_s``,
            ``T_theta``, ``M_s``, ``M_theta``, ``tau_s``, ``tau_theta``, ``Q``, ``P``,
            ``axial_force`` (F(S), the axial force carried across the circle S), ``energy_density``.
            For a point-load state (``topology == "point"``) there is no contact region.

        Examples
        --------
        >>> import shellbvp as sb
        >>> prof = sb.solve(sb.Scene.preset("base"), delta=0.2).profile()
        >>> float(prof["S"][0]) < 1e-3 and abs(float(prof["S"][-1]) - 1.5708) < 1e-4
        True
        >>> bool(abs(prof["lambda_theta"][-1] - 1) < 1e-8)    # the rim is held: r(L) = R(L)
        True
        """
        sysm = self.system
        t = self.x
        if points_per_interval > 1:
            t = np.unique(np.concatenate([np.linspace(a, b, points_per_interval + 1)
                                          for a, b in zip(t[:-1], t[1:])]))
        return sysm.profile(t, self.sol(t), self.p, self.z_tip)


def thin_mesh(x, keep_every: int = 3):
    """Every ``keep_every``-th node plus the ends (solve_bvp only ever adds nodes)."""
    idx = np.unique(np.r_[np.arange(0, x.size, keep_every), x.size - 1])
    return x[idx]


#: A warm start's mesh aims the residual of the state it starts from at this fraction of tol
WARM_MESH_SAFETY = 0.5
#: solve_bvp's relative residual goes as h^3 (halving a converged mesh: 2^2.98-2^3.00 per interval)
RESIDUAL_ORDER = 3
_WARM_MESH_MIN_INTERVALS = 10


#: A secant predictor ``cur + a (cur - prev)`` is made only while the step is at most this many
#: times the previous one: the two states' difference holds their solver error (~tol) besides
#: the slope, and the secant multiplies it by ``a``.  Through depths a hair apart (two curves'
#: depths merged: 5e-11) ``a`` reached 3e7, the guesses needed 2-3 times the nodes, and at
#: tol 1e-5 half of the steps failed at the node budget (base-xi0: 2.8 s for 47 points, 0.33 s
#: with this bound).  Steps of a curve's own making keep ``a`` <= 1.5.
SECANT_MAX_RATIO = 4.0


def secant_ratio(delta, cur, prev):
    """``a = (delta - cur.delta) / (cur.delta - prev.delta)``, the secant's step ratio from
    ``prev`` through ``cur`` to ``delta``; None where the two depths are equal or the ratio
    exceeds ``SECANT_MAX_RATIO`` (the guess is then ``cur`` itself)."""
    if prev is None or cur.delta == prev.delta:
        return None
    a = (delta - cur.delta) / (cur.delta - prev.delta)
    return a if abs(a) <= SECANT_MAX_RATIO else None


def warm_mesh(sol, tol=None):
    """Mesh for a warm start from the converged state ``sol``: its nodes moved so that
    every interval's residual, were the new state ``sol`` itself, would be
    ``WARM_MESH_SAFETY * tol`` (default tol: the one ``sol`` was solved at).

    Interval i of width h_i and residual r_i asks for the density
    ``(r_i / (safety tol))^(1/3) / h_i``; the new nodes equidistribute it.  solve_bvp only
    adds nodes, so the converged mesh itself would grow from step to step, and a thinned
    one (every third node, :func:`thin_mesh`, the fallback when ``sol`` has no residuals)
    is refined in a second pass: about 1.6x the Newton iterations of a curve.
    """
    r = np.asarray(sol.rms_residuals, float)
    tol = sol.tol if tol is None else tol
    x = np.asarray(sol.x, float)
    if not OPTIONS.equidistribute or not math.isfinite(tol) or r.size != x.size - 1 or r.size == 0 or not np.all(np.isfinite(r)):
        return thin_mesh(x)
    h = np.diff(x)
    target = WARM_MESH_SAFETY * tol
    density = np.maximum(r / target, 1e-3) ** (1.0 / RESIDUAL_ORDER) / h
    cum = np.r_[0.0, np.cumsum(density * h)]
    m = max(int(np.ceil(cum[-1])), _WARM_MESH_MIN_INTERVALS)
    return np.interp(np.linspace(0.0, cum[-1], m + 1), cum, x)  # the ends exactly: x[0] and x[-1]


#: The numbers of a state; a run that did not converge reports them as NaN, all but the
#: prescribed one (its ``y``, ``x`` and ``p`` stay: the last iterate, for inspection).
STATE_NUMBERS = ("delta", "force", "lambda0", "Sc", "S1", "S_end", "energy", "shear_delta", "ring_force", "ring_force_inner",
                 "cap_force", "pressure_min", "penetration", "wall_gap", "force_defect", "edge_legendre",
                 "curvature_excess", "tip_end_margin", "legendre_min", "legendre_min_S", "edge_jump_ls",
                 "edge_jump_ks")


def failure(status, message, *, scene, control, value, topology="cap", **fields) -> Solution:
    """A result without any state (status 1, 2, 3 or 5): every number NaN but the
    prescribed ``control`` = ``value`` and the scene's pressure, unless that is an unknown
    (volume control).  ``fields``: what the run that failed can still tell (``nodes``,
    ``wall_time``, ...)."""
    if status in (0, 4):
        raise ValueError(f"status must be that of a failure (1, 2, 3 or 5); got {status}")
    numbers = dict.fromkeys(STATE_NUMBERS, _NAN)  # those whose default is a number (S1 = 0 ...)
    if control is not None:
        numbers[control] = float(value)
    return Solution(status=status, message=message, success=False, valid=False, topology=topology, control=control,
                    scene=scene, pressure=_NAN if scene.sealed else scene.pressure, **{**fields, **numbers})


def passed_tip_end(sol) -> bool:
    """Whether a state is inadmissible (status 4) because its contact has passed the end of the
    tip onto the indenter's cylinder (diagnosis sets ``past_tip_end``): where a curve goes on
    on the cylinder."""
    return sol.status == 4 and bool(sol.past_tip_end)


def run_status(bvp, flags, converged_note="") -> dict:
    """``status``, ``message`` and ``success`` of a diagnosed run: a converged run whose state
    breaks an admissibility check (``flags``) gets status 4."""
    status, message = int(bvp.status), bvp.message
    if bvp.status == 0 and flags:
        status, message = 4, STATUS_MESSAGES[4] + ": " + "; ".join(flags)
    elif bvp.status == 0:
        message = STATUS_MESSAGES[0] + converged_note
    elif not message:
        message = STATUS_MESSAGES.get(bvp.status, "")
    return dict(status=status, message=message, success=status == 0)


def inadmissible(res, reason) -> Solution:
    """``res`` as a converged but inadmissible state (status 4, not valid): ``reason`` says why."""
    return res.with_(status=4, success=False, valid=False, message=f"{STATUS_MESSAGES[4]}: {reason}")


def cached(sol, name, compute):
    """``sol`` with its number ``name`` computed by ``compute(sol)`` where it is NaN, kept on ``sol``:
    the one write into a built state, of what it already determines (for speed: ``pole_clearance``)."""
    if math.isnan(getattr(sol, name)):
        object.__setattr__(sol, name, compute(sol))
    return sol


def penetration(sysm, r, z, z_tip):
    """How far free-shell points reach into the indenter (tip and cylinder above it).

    For a point above the tip's surface and inside the cylinder ``r < rho A(omega_max)``,
    the depth is the smaller of its height above the tip surface and its distance from
    the cylinder wall; for points outside, the (negative) height above the tip surface.
    Returns the largest value (> 0: the shell passes through the indenter), -inf if no
    point lies inside the cylinder's radius.
    """
    A, B = sysm.tip_A, sysm.tip_B
    rho = sysm.scene.rho
    inside = r < rho * A[-1]
    if not np.any(inside):
        return -np.inf
    height = z[inside] - (z_tip + rho * np.interp(r[inside] / rho, A, B))
    depth = np.where(height > 0, np.minimum(height, rho * A[-1] - r[inside]), height)
    return float(np.max(depth))


def wall_gap(sysm, r, z, z_tip):
    """Smallest horizontal distance from the indenter's cylinder ``r = rho A(omega_max)`` of the
    free-shell points above the tip's end (negative: through the wall); inf if none is above.
    It crosses zero where the free shell first touches the indenter's side."""
    A, B = sysm.tip_A, sysm.tip_B
    rho = sysm.scene.rho
    above = z > z_tip + rho * B[-1]
    if not np.any(above):
        return float("inf")
    return float(np.min(r[above] - rho * A[-1]))


def attach_tip_table(sysm):
    """Tabulated tip profile for penetration checks (A increasing up to omega_max)."""
    shape = sysm.model.tip_shape(np.linspace(0.0, sysm.scene.tip_omega_max, 401), sysm.par)
    sysm.tip_A, sysm.tip_B = shape["A"], shape["B"]


def richardson_error(sysm, res, tol, bc_tol=1e-10) -> Solution:
    """``res`` with ``force_error`` and ``delta_error`` by Richardson extrapolation (any topology).

    The collocation solution (Lobatto IIIA, order 4) is recomputed on the
    converged mesh with every interval halved, without further refinement
    (Newton converges to tol/100 and bc_tol/100, so the coarse solve's iteration and
    boundary errors are included); the error of the coarse value is then
    ``|X_h - X_h/2| * 16/15``.  Costs one Newton solve on twice the nodes: the system's
    ``newton_on_mesh`` (full steps; usually one Jacobian), or, where that does not
    converge, solve_bvp with its line search on the pinned mesh (``max_nodes``).
    ``sysm.end_values`` gives (F, delta) of a solution.
    """
    x = res.x
    x2 = np.sort(np.r_[x, 0.5 * (x[1:] + x[:-1])])
    p = np.asarray(res.p, float)
    p = p if p.size else None
    with np.errstate(all="ignore"):
        y2 = res.sol(x2)
        fine = sysm.newton_on_mesh(x2, y2, p, tol=tol / 100, bc_tol=bc_tol / 100)
        if fine is None:
            run = sysm.solve(x2, y2, p, tol=tol / 100, bc_tol=bc_tol / 100, max_nodes=x2.size)
            if run.status == 2 or not np.all(np.isfinite(run.y)) \
                    or (run.p is not None and not np.all(np.isfinite(run.p))):
                return res.with_(force_error=_NAN, delta_error=_NAN, flags=list(res.flags) + [
                    "error estimate failed (Newton on the halved mesh did not converge)"])
            fine = run.y, run.p
        force, delta = sysm.end_values(fine[0][:, 0], fine[0][:, -1], fine[1])
    return res.with_(force_error=abs(force - res.force) * 16 / 15, delta_error=abs(delta - res.delta) * 16 / 15)


def finished(res, t0, estimate_error, tol, bc_tol):
    """``res`` with its error estimate (if asked for) and its wall time since ``t0``."""
    if estimate_error:
        res = richardson_error(res.system, res, tol, bc_tol)
    return res.with_(wall_time=time.perf_counter() - t0)

def calibrated_error(residual, key, anchors):
    """An error estimate without a solve, calibrated against Richardson estimates.

    solve_bvp refines every mesh to the same residual level, so along a branch of one
    contact configuration the error of a collocation value per unit of the largest
    residual keeps its size -- but it scatters from mesh to mesh, by 100x where the
    signed contributions of the intervals happen to cancel.  So the ratio
    ``error / max_residual`` is taken from the Richardson points ``anchors`` that
    bracket ``key``, the larger of the two (a cancelled anchor must not make its
    neighbours look exact; benchmarks/error_estimates.py compares the rules), or from
    the nearest beyond the ends, and multiplied by this point's own ``residual``.

    Parameters
    ----------
    residual : float
        The point's largest relative collocation residual (``max_residual``).
    key : float
        The point's position along the branch.
    anchors : sequence of (float, float)
        ``(key, ratio)`` of Richardson points, ratio = error / max_residual (finite).

    Returns
    -------
    float
        NaN when there is no anchor.
    """
    if not anchors or not math.isfinite(residual):
        return float("nan")
    anchors = sorted(anchors)
    below = [a for a in anchors if a[0] <= key]
    above = [a for a in anchors if a[0] >= key]
    if not below or not above:
        return (above[0] if above else below[-1])[1] * residual
    return max(below[-1][1], above[0][1]) * residual


def default_eps(tol):
    # Pole start zeta = eps*Sc: the truncated series errs by O(eps^2) relative.
    return min(1e-3, 0.1 * math.sqrt(tol))
