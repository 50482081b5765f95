r"""Contact configurations as data: a chain of regions and junctions, assembled into ONE
multipoint BVP for ``scipy.integrate.solve_bvp``.

The stacked layout (the one place it is defined)
------------------------------------------------
A configuration is an ordered list of regions ``k = 0 .. n-1`` from the pole to
the rim, each of a kind (``"free"``: 6 states ``(lt, phiS, ls, ks, rQ, z)``;
``"contact"``, the shell on the tip, and ``"cylinder"``, the shell on the
indenter's cylinder: 2 states ``(chi, ls)``, ``chi = rho omega/S`` with omega
running on past the tip's end ``omega_max`` along the cylinder; see
``symbolic.equations``) on ``[S_a, S_b]``.  Every region is mapped
geometrically onto the same ``t in [0, 1]``,

    ``S_k(t) = exp(a_k + t (b_k - a_k))``,  ``a_k = ln S_a``, ``b_k = ln S_b``,

so that ``dy/dt = (b_k - a_k) g_k(S, y)`` with ``g = S dy/dS`` from the
generated code, and tiny caps stay well conditioned.  ``y`` stacks the
regions' states in chain order (rows ``offset[k] : offset[k] + size[k]``);
``y[:, 0]`` holds every region's start and ``y[:, -1]`` every region's end.

Each end is a :class:`Point` with ``ln S = ln_offset + p[unknown]`` (or a
fixed value): a pole start ``zeta = eps * Sc`` is the point ``Sc`` shifted by
``ln eps``.  The unknown parameters ``p`` are, in this order, the
configuration's own unknowns (``ln Sc``; ``ln S1, ln S2``; ``ln S1, chi1``),
then ``lambda0`` where a contact cap reaches the pole and lambda0 is not
prescribed, then ``delta`` unless it is prescribed.

Conditions are the junctions' rows in chain order (pole, contact edges or
lines, rim), then the control's row: the force at the last contact edge
(``force``), the stretch at a lifted pole (``lambda0`` without a contact
pole), or the pseudo-arclength condition (``arclength``,
``sum_i t_i (X_i - Xhat_i)/s_i = 0`` over ``X = (delta, lambda0, F)``; its
value is the tuple ``(Xhat, t, s)``).

Volume control (a sealed shell, ``Scene.sealed``): the pressure is an unknown too
(the last), and one state ``v`` (the last row) sums the regions' volumes, which all
run on the same t: ``v' = sum_k (b_k - a_k) S dV/dS``, ``v(0) = 0``, ``v(1) = V0``
(rows after the control's).  One state, not one per region: solve_bvp's LU costs
about the cube of the states per node.  Guesses need only the regions' states and
the unknowns before the pressure: :meth:`ChainBVP.solve` completes them.

:class:`Region`, :class:`Point` and the junctions are the blocks a chain is declared with
(each configuration's chain is declared in its module of :mod:`shellbvp.configurations`,
e.g. ``cap_chain`` in ``shellbvp/configurations/cap.py``); :class:`ChainBVP`
assembles any chain into ``fun``, ``fun_jac``, ``bc``, ``bc_jac`` (analytic,
from the generated Jacobians), end values, energy and profile.

The package's modules: :mod:`shellbvp.chain.blocks` (the declarations),
:mod:`shellbvp.chain.conditions` (the junctions' rows and their Jacobians) and
:mod:`shellbvp.chain.assembler` (:class:`ChainBVP`); every name is importable from here.
"""

from .assembler import CONTROLS, ChainBVP
from .blocks import (CONTACT_KINDS, CONTACT_STATES, FREE_STATES, REGION_CODES, SIZES, Chain, ContactPole, Edge,
                     FreePole, Kink, Line, Point, PointPole, Region, Rim, Seam, TipEnd)

__all__ = ["Point", "Region", "ContactPole", "FreePole", "PointPole", "Edge", "TipEnd", "Line", "Kink", "Rim", "Seam",
           "Chain",
           "ChainBVP", "CONTROLS",
           "SIZES", "FREE_STATES", "CONTACT_STATES", "CONTACT_KINDS", "REGION_CODES"]
