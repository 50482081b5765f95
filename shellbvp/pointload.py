"""The point-load limit of the smooth model: the free region alone, delta prescribed.

When the contact cap is exponentially small (``Sc`` below ~1e-30, which happens
as delta -> 0) the cap's own equations leave double precision and the state is
the point-load solution to exponential accuracy (``shellbvp.chain.point_chain``).
"""

from __future__ import annotations

import time

import numpy as np

from .chain import ChainBVP, point_chain
from .diagnosis import diagnose
from .inflation import start_shape
from .solution import (
    attach_tip_table,
    solve_bvp,
    thin_mesh,
)

__all__ = ["solve_point_load", "SC_POINT", "POINT_S0"]


#: Caps smaller than this are replaced by the point-load limit (their own equations
#: leave double precision near Sc ~ 1e-75; the difference is exponentially small).
SC_POINT = 1e-30
#: Start of the point-load state's free region (truncation error O(s0^2 ln^2 s0)).
POINT_S0 = 1e-12


def _point_guess(sysm, prev):
    """Free states for the point-load problem from a cap or point solution."""
    if prev.get("topology") == "point":
        x = thin_mesh(prev.x)
        return x, prev.sol(x)
    x = np.linspace(0.0, 1.0, 61)
    cap = prev.system
    tp = np.clip(cap.t_of(1, sysm.S(0, x, None), prev.p), 0.0, 1.0)
    return x, prev.sol(tp)[cap.rows(1)]


def _crude_point_guess(sysm):
    x = np.linspace(0.0, 1.0, 61)
    S = sysm.S(0, x, None)
    y = start_shape(sysm.scene, S)  # the reference shell, or the inflated one under pressure
    y[[0, 2]] *= 0.95
    y[4] = 0.0
    y[5] -= sysm.value * (1 - (S - S[0]) / (S[-1] - S[0]))
    return x, y


def solve_point_load(scene, delta, *, tol=1e-6, max_nodes=10000, guess=None, bc_tol=1e-10):
    """The point-load limit of the smooth model at pole displacement ``delta``.

    When the contact cap is exponentially small (``Sc`` below ~1e-30, which
    happens as delta -> 0) the cap's own equations leave double precision and
    the state is the point-load solution to exponential accuracy: the free
    region alone on ``[s0, L]`` with the point-load pole conditions
    (``shellbvp.chain.point_chain``).
    """
    t0 = time.perf_counter()
    sysm = ChainBVP(scene, point_chain(POINT_S0, scene.shell_length), "delta", delta)
    attach_tip_table(sysm)
    x, y = _point_guess(sysm, guess) if guess is not None else _crude_point_guess(sysm)
    with np.errstate(all="ignore"):
        bvp = solve_bvp(sysm.fun, sysm.bc, x, y, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=tol,
                        bc_tol=bc_tol, max_nodes=max_nodes)
        res = diagnose(sysm, bvp, tol, " (point-load limit: the contact cap is exponentially small)")
    res.wall_time = time.perf_counter() - t0
    return res
