"""Contact that runs past the tip's end onto the indenter's cylinder (``"cap+cylinder"``).

Deep enough, or with an indenter large for the shell, the contact reaches the end
of the tip (omega_max, where the tip meets its cylinder r = rho A(omega_max)); a
single cap there either passes the tip's end or leaves a free shell that passes
through the cylinder.  The state is then the chain of
:func:`shellbvp.chain.cylinder_chain`: the shell on the tip up to S*, on the
cylinder from S* to Sc, free beyond.  At S* omega = omega_max and the
refraction condition ``[lambda_s dU/dlambda_s - U] = 0`` holds (lambda_s jumps
where the indenter's meridional curvature does); at Sc the edge conditions of
the scene's contact model.  This module makes guesses from a cap state or a
neighbouring cylinder state, solves, and diagnoses (``shellbvp.diagnosis``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from .chain import ChainBVP, cylinder_chain
from .diagnosis import diagnose
from .solution import Solution, attach_tip_table, richardson_error, solve_bvp, thin_mesh

__all__ = ["make_cylinder_system", "cylinder_guess_from_cap", "cylinder_warm_guess", "solve_cylinder_from",
           "cylinder_state", "cylinder_suspected", "TOPOLOGY"]

TOPOLOGY = "cap+cylinder"
#: A cap whose contact edge has reached this fraction of the tip's end, and whose free shell
#: passes through the indenter, is tried as contact running onto the cylinder.
NEAR_TIP_END = 0.7
#: (S*/Sc, Sc'/Sc) of the guesses made from a cap state: the tip end a little inside the cap's
#: edge, the cylinder contact reaching a little beyond it.
_GUESS_SPLITS = ((0.97, 1.15), (0.9, 1.3), (0.99, 1.05))


def make_cylinder_system(scene, control, value, eps):
    if scene.model().OMEGA_MAX is None:
        raise ValueError("this tip has no end where it meets a cylinder (A' never vanishes): no cylinder contact")
    sysm = ChainBVP(scene, cylinder_chain(eps, scene.shell_length, scene.contact), control, value)
    attach_tip_table(sysm)
    return sysm


def _cap_omega(cap):
    """omega at the cap's contact edge."""
    csys = cap.system
    return float(cap.Sc * cap.y[csys.rows(0), -1][0] / cap.scene.rho)


def cylinder_suspected(cap: Solution) -> bool:
    """A converged cap that passed the tip's end, or whose free shell passes through the
    indenter with its contact edge near the tip's end."""
    if cap.get("topology") != "cap" or not math.isfinite(cap.get("penetration", float("nan"))) \
            and cap.get("status") != 4:
        return False
    passed = cap.get("status") == 4 and "end of the tip" in cap.get("message", "")
    near = (cap.get("success") and cap.get("penetration", -1.0) > 0
            and _cap_omega(cap) > NEAR_TIP_END * cap.scene.tip_omega_max)
    return bool(passed or near)


def cylinder_guess_from_cap(sysm: ChainBVP, cap: Solution, end_fraction: float, edge_fraction: float,
                            n: int = 81):
    """Guess from a cap state: the tip contact up to ``S* = end_fraction * Sc`` (its omega
    stretched to reach omega_max there), the cylinder on ``[S*, edge_fraction * Sc]``, the free
    region of the cap beyond."""
    csys, rho, w0 = cap.system, cap.scene.rho, cap.scene.tip_omega_max
    Se, Sc = end_fraction * cap.Sc, edge_fraction * cap.Sc
    t = np.linspace(0.0, 1.0, n)
    p = sysm.pack(ln_Send=math.log(Se), ln_Sc=math.log(Sc), lambda0=cap.lambda0, delta=cap.delta)
    S0, S1, S2 = sysm.S(0, t, p), sysm.S(1, t, p), sysm.S(2, t, p)
    y0 = cap.sol(np.clip(csys.t_of(0, S0, cap.p), 0.0, 1.0))[csys.rows(0)]
    omega_end = Se * y0[0, -1] / rho
    y0[0] = y0[0] * (w0 / omega_end) ** ((S0 / Se) ** 2)  # omega -> omega_max at S*, unchanged at the pole
    ls_end = y0[1, -1]
    y1 = np.vstack([rho * (w0 + (S1 - Se) * ls_end / rho) / S1, np.full(n, ls_end)])
    y2 = cap.sol(np.clip(csys.t_of(1, S2, cap.p), 0.0, 1.0))[csys.rows(1)]
    return t, np.vstack([y0, y1, y2]), p


def cylinder_warm_guess(sysm: ChainBVP, prev: Solution):
    """A neighbouring cap+cylinder state on its thinned mesh."""
    x = thin_mesh(prev.x)
    q = dict(zip(prev.system.unknowns, prev.p), lambda0=prev.lambda0, delta=prev.delta)
    return x, prev.sol(x), sysm.pack(**q)


def solve_cylinder_from(sysm, guess, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10):
    x, y, p = guess
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        bvp = solve_bvp(sysm.fun, sysm.bc, x, y, p, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=tol,
                        bc_tol=bc_tol, max_nodes=max_nodes)
        res = diagnose(sysm, bvp, tol)
    res.wall_time = time.perf_counter() - t0
    return res


def cylinder_state(start: Solution, *, control=None, value=None, tol=1e-6, max_nodes=10000, bc_tol=1e-10,
                   estimate_error=False):
    """The cap+cylinder state at ``start``'s delta (or the given control and value), from a cap
    state (a few splits are tried) or a neighbouring cap+cylinder state (warm start).

    Returns a Solution (check ``success`` and ``valid``).
    """
    if control is None:
        control = start.control if start.control in ("force", "lambda0") else "delta"
        value = {"force": start.force, "lambda0": start.lambda0, "delta": start.delta}[control]
    t0 = time.perf_counter()
    sysm = make_cylinder_system(start.scene, control, value, start.system.eps)
    kw = dict(tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    if start.get("topology") == TOPOLOGY:
        res = solve_cylinder_from(sysm, cylinder_warm_guess(sysm, start), **kw)
    else:
        res = None
        for end, edge in _GUESS_SPLITS:
            res = solve_cylinder_from(sysm, cylinder_guess_from_cap(sysm, start, end, edge), **kw)
            if res.success:
                break
    if res.success and estimate_error:
        richardson_error(sysm, res, tol, bc_tol)
    res.wall_time = time.perf_counter() - t0
    return res
