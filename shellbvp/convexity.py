"""Where a scene's energy U = W + beta B is convex in (lambda_s, kappa_s): the Legendre condition.

The free region's equations invert d(tau_s, M_s)/d(lambda_s, kappa_s); where its determinant
(the Hessian of U in the kinematic variables (psi, phi'), ``symbolic.bending.legendre_determinant``)
is not positive they are singular, and a smooth contact edge ends (``shellbvp.corner``).  This
module evaluates that determinant symbolically derived from the scene's own W and B.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["convexity_limits", "convexity_report", "envelope_partner", "weierstrass_gap"]


def _determinant(scene):
    import sympy as sp

    from symbolic import bending
    from symbolic.build import structure_from_description

    st = structure_from_description(scene.structure())
    B = st.B if st.B is not None else bending.trace_bending()
    values = scene.values()
    W = st.W.xreplace({p: values[p.name] for p in st.material_params})
    k0 = float(scene.shell.pole_curvature(values))  # the meridian's own (a closed shell's upper half: -gamma)
    det = bending.legendre_determinant(W, B.xreplace({bending.KS0: k0, bending.KT0: k0}),
                                       beta=sp.Float(scene.beta))
    return det, k0


def convexity_limits(scene, stretches=(0.8, 1.0, 1.2, 1.5, 2.0), kappa_max=3.0, n=61):
    """For isotropic stretch and bending near the pole (lambda_s = lambda_theta, kappa_s =
    kappa_theta = kappa, reference curvatures the shell's at the pole), the smallest kappa rho
    in [0, kappa_max] at which U stops being convex, per stretch (NaN: convex throughout).

    A cap on a sphere of radius rho imposes kappa rho = 1 on the shell: a limit at or below 1 means
    the smooth contact edge ends at some depth (where the stretch there reaches that value).

    Parameters
    ----------
    scene : Scene
    stretches : sequence of float
        The isotropic stretches lambda at which to look.
    kappa_max : float
        The largest kappa rho scanned.
    n : int
        Points of the scan in [0, kappa_max] (the limit is found to kappa_max/(n - 1)).

    Returns
    -------
    dict
        ``{lambda: kappa rho where convexity is lost, or NaN}``.

    Examples
    --------
    >>> import shellbvp as sb
    >>> lim = sb.convexity_limits(sb.Scene.preset("base"), stretches=(1.5,))
    >>> 0 < lim[1.5] < 1                 # the paper's bending energy: not convex at the tip's curvature
    True
    >>> sb.convexity_limits(sb.Scene.preset("base", bending=sb.RotationBending()), stretches=(1.2,))
    {1.2: nan}
    """
    from symbolic import bending
    from symbolic.materials import LS, LT

    det, _ = _determinant(scene)
    out = {}
    for ls in stretches:
        limit = math.nan
        for k in np.linspace(0.0, kappa_max, n):
            kappa = float(k) / scene.rho
            value = float(det.evalf(subs={LS: ls, LT: ls, bending.KS: kappa, bending.KT: kappa}))
            if not value > 0:
                limit = float(k)
                break
        out[ls] = limit
    return out


def _stretched(a, b, n, fine=0.002):
    """n points on [a, b] (a < 0 < b) spaced ~``fine`` near 0 and growing geometrically outwards."""
    u = np.linspace(-1.0, 1.0, n)
    return np.clip(fine * np.sinh(np.arcsinh(max(-a, b) / fine) * u), a, b)


def envelope_partner(sysm, S, y, *, lambda_min=0.1, kappa_rho_max=100.0, n=(161, 201)) -> dict:
    """Is a free-region state on the convex envelope of U in (lambda_s, lambda_s kappa_s), and where
    is the other phase of an interior Weierstrass-Erdmann corner from it?

    An interior corner (``chain.Kink``) joins two states of equal (lambda_theta, kappa_theta),
    equal gradient of U in the derivative variables (lambda_s, k = lambda_s kappa_s, i.e. equal
    tau_s and M_s) and equal Legendre transform (Eshelby): the ends of a segment of U's convex
    envelope at those (lambda_theta, kappa_theta).  The envelope is taken of U sampled on the box
    ``lambda_s in [lambda_min, 3]``, ``|kappa_s rho| <= kappa_rho_max`` (the state itself a sample);
    the rest of the state (S, lt, phiS, rQ, z) is held.

    Parameters
    ----------
    sysm : ChainBVP
        The state's system (its generated module and parameters).
    S, y : float, array (6,)
        A point of a free region and its state.

    Returns
    -------
    dict
        ``gap``: (U - envelope)/U at the state (0 on the envelope: the Weierstrass condition holds
        in the box); ``partner``: (lambda_s, kappa_s) of the envelope's facet vertex farthest from
        the state (the other phase, where ``gap > 0``; compare two boxes: a partner that moves out
        with the box is no state of the shell, see ``lifted_ends.pole_corner_partner``).
    """
    from scipy.spatial import ConvexHull

    mod, par, rho = sysm.model, sysm.par, sysm.scene.rho
    y = np.asarray(y, float)
    l0, k0 = float(y[2]), float(y[2] * y[3])
    k_max = kappa_rho_max / rho  # |kappa_s| <= k_max: the box in k = lambda_s kappa_s is k_max lambda_s wide
    # fine near the state (an envelope's segment may start a few per cent away), coarse far out
    ls = np.unique(np.append(l0 * np.exp(_stretched(math.log(lambda_min / l0), math.log(3.0 / l0), n[0])), l0))
    reach = 3.0 * k_max + abs(k0)
    kk = np.unique(np.append(k0 + _stretched(-reach, reach, n[1], fine=0.02 / rho), k0))
    L, K = np.meshgrid(ls, kk, indexing="ij")
    inside = np.abs(K) <= k_max * L
    L, K = L[inside], K[inside]
    states = np.repeat(y[:, None], L.size, axis=1)
    states[2], states[3] = L, K / L
    U = mod.free_profile(np.full(L.size, float(S)), states, par)["energy_density"]  # U R Psi: R Psi > 0 fixed
    pts = np.column_stack([(L - l0) / (3.0 - lambda_min), (K - k0) / k_max, U])
    hull = ConvexHull(pts)
    lower = hull.equations[:, 2] < 0
    eq, simplices = hull.equations[lower], hull.simplices[lower]
    here = int(np.flatnonzero((L == l0) & (K == k0))[0])
    below = -eq[:, 3] / eq[:, 2]  # each lower facet's plane at the state (its shifted origin)
    f = int(np.argmax(below))
    u0 = float(U[here])
    gap = max(0.0, (u0 - float(below[f])) / abs(u0)) if here not in set(np.unique(simplices)) else 0.0
    vertices = simplices[f]
    far = int(vertices[np.argmax(np.hypot(np.log(L[vertices] / l0), (K[vertices] / L[vertices] - y[3]) * rho))])
    return {"gap": gap, "partner": (float(L[far]), float(K[far] / L[far]))}


def weierstrass_gap(sol, points: int = 9, *, lambda_min=0.05, kappa_rho_max=1000.0) -> dict:
    """The Weierstrass condition over a state's free regions: the largest relative height of U
    above its convex envelope (:func:`envelope_partner`) at ``points`` equally spaced t of each
    free region.

    0 means every point sampled lies on the envelope in the box (a strong local minimum there,
    as far as the box reaches); a positive gap means a short segment in the envelope's other
    phase (a crease where the partner is extreme) would lower the energy: the state is then a
    weak local minimum only (the Legendre condition, ``legendre_min``, is what the solver
    needs).  About 0.1 s per point: a diagnosis, not part of every solve.

    Returns
    -------
    dict
        ``gap``, and where it is largest: ``region``, ``S`` and the ``partner`` (lambda_s, kappa_s).
    """
    sysm = sol.system.at(sol.p)
    worst = {"gap": 0.0, "region": None, "S": math.nan, "partner": (math.nan, math.nan)}
    for k, reg in enumerate(sysm.regions):
        if reg.kind != "free":
            continue
        for t in np.linspace(0.0, 1.0, points):
            S = float(sysm.S(k, np.array([t]), sol.p)[0])
            found = envelope_partner(sysm, S, sol.sol(np.array([t]))[sysm.rows(k), 0],
                                     lambda_min=lambda_min, kappa_rho_max=kappa_rho_max)
            if found["gap"] > worst["gap"]:
                worst = {"gap": found["gap"], "region": k, "S": S, "partner": found["partner"]}
    return worst


def convexity_report(scene) -> str:
    """A few lines for ``shellbvp convexity``: where the scene's energy is convex."""
    lim = convexity_limits(scene)
    name = type(scene.bending).__name__
    lines = [f"Legendre condition of U = W + beta B ({type(scene.material).__name__}, {name}, beta = {scene.beta:g}),"
             f" isotropic stretch lambda and curvature kappa near the pole; the tip imposes kappa rho = 1:"]
    for ls, k in lim.items():
        where = "convex for kappa rho in [0, 3]" if math.isnan(k) else f"not convex from kappa rho = {k:.2f}"
        lines.append(f"  lambda = {ls:<4g} {where}")
    if all(math.isnan(k) for k in lim.values()):
        lines.append("convex throughout: no corner at the contact edge is needed")
    else:
        lines.append("where the contact edge reaches the non-convex range the smooth edge ends and the curve "
                     "continues with a corner there (lambda_s, kappa_s jump)")
    return "\n".join(lines)
