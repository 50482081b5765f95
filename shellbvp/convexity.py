"""Where a scene's energy U = W + beta B is convex in (lambda_s, kappa_s): the Legendre condition.

The free region's equations invert d(tau_s, M_s)/d(lambda_s, kappa_s); where its determinant
(the Hessian of U in the kinematic variables (psi, phi'), ``symbolic.bending.legendre_determinant``)
is not positive they are singular, and a smooth contact edge ends (``shellbvp.corner``).  This
module evaluates that determinant symbolically derived from the scene's own W and B.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["convexity_limits", "convexity_report"]


def _determinant(scene):
    import sympy as sp

    from symbolic import bending
    from symbolic.build import structure_from_description

    st = structure_from_description(scene.structure())
    B = st.B if st.B is not None else bending.trace_bending()
    values = scene.values()
    W = st.W.xreplace({p: values[p.name] for p in st.material_params})
    k0 = float(scene.shell.pole_curvature({"gamma": scene.gamma}))
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
