r"""Stability of an axisymmetric state against Fourier modes n = 0, 1, 2, ... (issue 44, item 2).

What is solved
--------------
For a state ``x0`` and a perturbation ``eta [u(S) cos(n theta) t + v(S) sin(n theta) e_theta +
w(S) cos(n theta) N]`` the energy is ``Pi0 + eta^2 * 2 pi Int zeta^T A_n(S) zeta dS`` with
``zeta = (u, u', u'', v, v', v'', w, w', w'')`` and ``A_n`` the symmetric 9 x 9 form of
:mod:`symbolic.second_variation` (its coefficients evaluated on the state).  The eigenvalues
returned are those of

.. math:: K q = \lambda M q,\qquad
          \tfrac{d^2\Pi}{d\eta^2} = \lambda \|\delta x\|^2,\quad
          \|\delta x\|^2 = \int\!\!\int |\delta x|^2\, R\Psi\, dS\, d\theta,

i.e. the second derivative of the energy per squared L2 norm of the displacement over the
reference surface (units ``mu H / R_L^2``); for n >= 1 and n = 0 alike
``lambda = 4 Int zeta^T A zeta dS / Int (u^2 + v^2 + w^2) R Psi dS``.  A state is stable
against mode n when its smallest eigenvalue is positive.

Discretisation: Rayleigh-Ritz with cubic Hermite elements (C^1) for all three of u, v, w on a
uniform mesh in S from ``S0`` to the rim.  The form holds ``u''`` and ``v''`` only multiplied
by lower derivatives; C^1 fields make it the exact energy of the discrete fields, so no
integration by parts is needed and the computed eigenvalues are upper bounds of the exact
ones (up to quadrature error, 6 Gauss points per element, and the pole's rounding floor below).  The smallest eigenvalues come from
shift-invert Lanczos (``scipy.sparse.linalg.eigsh``) about a shift that a banded Cholesky
factorisation certifies to lie below the spectrum.

Boundary conditions (the inflated/pressurised shell; states on the tip below):

* rim (``lambda_theta = 1, z = 0, M_s = 0``): the rim circle is held, so every displacement of
  it vanishes, ``u = v = w = 0``; ``w'`` is free (its natural condition is ``M_s = 0``).  A
  clamped rim (``Scene.rim = "clamped"``, the slope held) holds ``w' = 0`` too.  With
  the rim circle fixed, the surface that closes the shell at the rim stays the flat disc, across
  which ``(x, y, 0)/2`` has no flux: the pressure's term is the exact volume, no rim term is left.
  Rigid motions move the rim, so none survives at n = 1 (no tilt to remove).
* pole: the fields of a smooth displacement at the axis, per n (``U cos + V sin`` of
  ``e_x = cos(theta) e_r - sin(theta) e_theta`` at n = 1):

  ====  ==========================================  ===================================
  n     behaviour at S -> 0                          imposed at S0
  ====  ==========================================  ===================================
  0     u, v ~ S, w ~ const + S^2                   u = v = 0, w' = 0
  1     u, v ~ const with u + v -> 0, w ~ S         u + v = 0, w = S0 w'
  >= 2  u, v ~ S^(n-1), w ~ S^n                     u = v = w = 0, w' = 0
  ====  ==========================================  ===================================

  The conditions imposed are those without which the energy diverges (the coefficients carry
  up to ``1/r^3``); higher-order ones (``u' = 0`` for n >= 3, ...) follow from finite energy in
  the limit and are not imposed.  At n = 1, ``w = 0`` at S0 would hold the small circle S0 still
  against the tilt ``w = a S``, at a bending energy of order ``a^2`` whatever S0 (the
  correction of size ``a S0`` over the length S0): ``w = S0 w'`` there lets the tilt through.  The mesh starts at ``S0``: the state's own pole start
  (``inflation.EPS * L``) by default, with the conditions above imposed there; the result's
  change with ``S0`` is measured in the tests.

Accuracy and cost (measured; tests/test_stability.py, benchmarks/stability_pressure.py): the
default mesh has 24 elements per classical wavelength ``2 pi/k_c``, ``k_c = (3/beta)^(1/4)``;
doubling it moves the critical pressures by less than 1e-4 of p_c.  Near the pole the form's
coefficients (up to ``1/r^3``) are evaluated numerically from the generated expressions, and
their cancellation leaves a floor of about 1e-4 of the eigenvalues' scale at S0 = 1.5e-4 (the
rigid motions of a complete sphere come out at that level instead of 0), growing as S0 -> 0
(1e-2 at S0 = 1e-5); regularised pole expressions per n would remove it.  The form's 45 entries
are generated code (``symbolic.second_variation.form_module_source``, numpy with CSE), derived
once per structure into the code cache (``stability_<key>.py``, ~5-10 s) and imported after;
a state of beta 1e-5 (141 elements, n = 0..33) takes about 1 s.

States on the tip (``contact="smooth"``: the cap, the point load, lifted and split contact)
-------------------------------------------------------------------------------------------
Every chain of free regions and regions on the tip joined by smooth contact edges and lines
(:func:`supported`) is handled alike: ``w = w' = 0`` on each region on the tip, ``w = 0`` at a
line, and at each edge and line the ring force's term below; the single cap serves to derive it.

The tip is rigid, frictionless and fixed in space (displacement control).  Let ``g(x)`` be the
signed distance of a point from the tip's surface (``g >= 0`` outside the tip).  The constraint
is ``g(x(S, theta)) >= 0`` for every material point; its multiplier is the contact pressure,
per ``dS dtheta`` ``p^ = P r psi`` on the cap ``[0, Sc]`` (``P`` the generated profile's), and
at the edge the normal ring force ``f_c`` (for the whole circle: ``state.edge_forces``,
``-2 pi [r Q]``; the smooth model's jump of Q, SPEC 2b).  The state is stationary for the
Lagrangian

.. math:: \mathcal L = \Pi - \int\!\!\int \hat p\, g\, dS\, d\theta
          - \tfrac{f_c}{2\pi}\int g(x(S_c, \theta))\, d\theta

(on the cap N points into the tip, so ``g = -w`` to first order, and the generated equilibrium
is ``dPi/dw = -r psi P`` there, tests/test_second_variation.py).

*Admissible perturbations.*  On a valid state ``P > 0`` on the cap and ``f_c > 0``: every point
of the contact set carries a positive multiplier, the critical cone is the subspace
``dg = 0`` there, i.e. ``w = 0`` on ``[0, Sc]``; ``u, v`` are free (frictionless).  With the
bending energy the perturbations are H^2 (C^1), so ``w = 0`` on the cap implies ``w'(Sc) = 0``:
``w = w' = 0`` is imposed at the cap's nodes.  On a state flagged invalid (``P < 0`` somewhere,
a pulling ring) the same eigenproblem is that of the shell held on the tip over its contact set
(an equality constraint): what the fold of its branch needs, nothing about lifting off.

*The constraint's curvature.*  The second variation is the Lagrangian's at fixed multipliers:
``d^2 Pi - Int p^ d^2 g - f_c/(2 pi) Int d^2 g(Sc)``, with ``d^2 g = dx^T (Hess g) dx``.  For a
tangential ``dx`` at a point of the tip's surface, ``Hess g`` is the surface's second
fundamental form, positive for the convex tip seen from outside: ``d^2 g = kappa_s u^2 +
kappa_theta v^2`` with the tip's principal curvatures (meridian, parallel), which on the cap
are the shell's own ``kappa_s``, ``kappa_theta = sin(phi)/r`` (for a sphere of radius rho,
``|x + dx - c| = rho + |dx_t|^2/(2 rho) + ...``: sliding along the tip with ``w = 0`` to first
order leaves it outward at second order).  The form gains ``-P r psi (kappa_s u^2 +
kappa_theta v^2)/4`` per dS on the cap (theta-average 1/2; the same at n = 0, where v is the
torsion) and ``K`` gains ``-f_c/(2 pi) (kappa_s u^2 + kappa_theta v^2)`` at Sc: the contact
destabilises sliding, like a ball resting on a ball.  Its sign is checked by the energy along
the branch: ``d^2E/d delta^2 = dF/d delta`` equals ``d^2 Pi(x', x') - Int p^ kappa_s
dt^2 - f_c kappa_s dt(Sc)^2`` (``x'`` the branch tangent at fixed S, ``dt`` the tangential
component of ``x' + e_z``, the motion relative to the tip that moves down); measured on the base
scene at delta 0.3 and 0.6 (difference quotients over 1.25e-4 in delta) it agrees to 3e-5 and
3e-4 of dF/ddelta, with the opposite sign it misses by 0.5 % and 7 %, without the terms by 0.2 %
and 3.4 % (tests/test_stability_contact.py).

*The edge's motion.*  In the smooth model r, phi, lambda_s and kappa_s are continuous at Sc and
Q jumps, so the gap just outside the cap grows like ``c s^3`` (s = S - Sc).  A perturbation with
``w = w' = 0`` at Sc penetrates there only where ``c s^3 < eta w''(Sc) s^2/2``: over s = O(eta),
by O(eta^3), and letting the edge move changes the energy at O(eta^3).  The points outside carry
no multiplier and strict complementarity holds on the whole contact set, so the fixed active set
``[0, Sc]`` is exact to second order.  (Not for the paper's edge, where lambda_s and kappa_s
jump and which is not variational: refused.)  The branch tangent's ``u'`` jumps at Sc (lambda_s'
does, and the edge moves), and so may a mode's: the C^1 elements resolve the kink by a layer, on
a mesh graded towards Sc (:func:`mesh`; without it the eigenvalues converged like h).

*A line contact* (topology ``"line"``: the pole lifted, the shell touching the tip on the
circle S1, carrying a ring force; lambda_s and kappa_s continuous there, the shell's kappa_s
below the tip's by ``gap = -curvature_excess > 0``).  Here the contact point can roll along the
meridian, so the constraint is the smallest gap near S1.  In the frame of the contact point
(sigma the arclength along t, heights along N) the tip is ``kappa_T sigma^2/2`` and the shell
``kappa_S sigma^2/2``; displaced by ``eta (u t + w N)`` (u, w at sigma = 0 and ``w1 = dw/dsigma
= w'/psi``; the frame turns with sigma by kappa_S) the gap is ``gap sigma^2/2 + eta sigma (gap
u - w1) - eta w + eta^2 kappa_T u^2/2 + O(eta^3)`` at sigma = O(eta), whose minimum over sigma is
``-eta w + eta^2 (kappa_S u^2/2 + u w1 - w1^2/(2 gap))``.  So ``w(S1) = 0`` (first order) and the
ring's term in ``K`` is ``-f/(2 pi) (kappa_S u^2 + 2 u w1 - w1^2/gap + kappa_theta v^2)``: the
rolling term ``+f w1^2/gap`` stiffens, without bound as the line opens into an annulus
(gap -> 0, then refused).  (Check: a rigid rotation about the centre of a spherical tip,
``u = Omega/kappa_T, w1 = Omega gap/kappa_T``, gives ``Omega^2/kappa_T``: the straight-line
rotation's outward second-order motion, as it must.)  Along a line branch the line rolls with the
shell and the ring's term is small (4e-5 of dF/ddelta on the base scene at delta 0.1): the energy
check there is one of consistency (to 5e-5), it does not decide the term's sign.

*The pole.*  The mesh starts at ``S0 = max(EPS L, zeta)``; the cap's disc [0, S0] is left out.
On the tip the pole conditions above hold with ``w = w' = 0``.  For every state in contact,
n = 1 also has ``u' = v' = 0`` at S0 (the regular field is ``u = U + O(S^2)``): where the pole
carries a bending prestress (a cap held at curvature 1/rho, a lifted cap bent by its line) the
form's ``u u''`` terms are not small and without these conditions a layer at S0 lowers the
energy without bound as the first element shrinks (the states without contact keep their
conditions).  A cap or line within [0, S0] and a point load hold the pole at a point:
``w(S0) = 0`` at n = 0 (delta is prescribed); at n = 1 the pole slides by ``U = u(S0)`` and
``K`` gains ``-F kappa_apex U^2/pi`` (the limit of the cap's term); n >= 2 hold it already.

Cost: a state on the tip of the dome of beta 1e-5 (91 elements and the graded nodes, n = 0..33)
takes 1-2.5 s, the base scene's (beta 0.01, n = 0..8) 0.1 s (the form's derivation, 2-5 s, once per
process).

Accuracy: on the base scene at delta 0.3 (cap, Sc 0.091) the eigenvalues of n = 0..3 move by
less than 3e-4 with twice the elements or with S0 = 1e-3; the dome's first n >= 2 crossings
(benchmarks/results/stability_contact.md) move by < 3e-7 in delta with twice the elements.

A band on the indenter's cylinder is a region on the tip like the others (its meridian is
straight: ``kappa_s = 0``, and only the hoop term remains).

Refused (ValueError, one line): the contact running over the tip's end onto the cylinder
(``"cap+cylinder"``: the obstacle has a corner there, across which material slides; the same
issue as an edge's corner below) and interior corners (``"line+corner"``), ``contact="paper"``, a line whose gap is not positive, more than one line,
an edge inside [0, S0] of a configuration with several, a sealed shell in contact, and a contact
edge with a Weierstrass-Erdmann corner (lambda_s, kappa_s jump there: the corner can move
through the material, a degree of freedom of its own that the displacement modes do not
carry; the base scene's edges have one from delta 0.62).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..geometry import Spheroid
from ..configurations import of
from .contact import NOT_BUILT, Contact, check_supported, contact_of, supported
from .fem import END_CONDITIONS, Stability, default_elements, default_modes, mesh, spectrum
from .form import chain_base, form_functions, sphere_base, state_base

__all__ = ["stability", "Stability", "spectrum", "state_base", "sphere_base", "mesh", "default_modes",
           "default_elements", "END_CONDITIONS", "sphere_stretch", "NOT_BUILT", "supported", "Contact", "check_supported",
           "contact_of", "chain_base", "form_functions"]


def stability(state, modes=None, *, elements: int | None = None, S0: float | None = None,
              count: int = 2, vectors: bool = False) -> Stability:
    """The smallest eigenvalues of the second variation of ``state`` per Fourier mode.

    Parameters
    ----------
    state : Solution
        A converged state: :func:`shellbvp.inflate`'s (topology ``"inflated"``), or one on the
        tip with ``contact="smooth"`` (a configuration :func:`supported`; module docstring).
    modes : iterable of int, optional
        The mode numbers n (default :func:`default_modes`).
    elements : int, optional
        Cubic Hermite elements in S (default :func:`default_elements`).
    S0 : float, optional
        Where the mesh starts (default: the state's pole start); the pole conditions are imposed
        there (module docstring).
    count : int
        Eigenvalues per mode.
    vectors : bool
        Keep the eigenvector of each mode's smallest eigenvalue.

    Returns
    -------
    Stability
        ``.modes``, ``.eigenvalues`` (per mode the ``count`` smallest), ``.critical_mode``,
        ``.stable``.

    Raises
    ------
    ValueError
        One line naming what is not supported (:func:`check_supported`, :func:`contact_of`): a
        state that did not converge, the contact over the tip's end, interior corners,
        ``contact="paper"``, a cornered edge, a line without a curvature gap, a sealed shell in
        contact.

    Examples
    --------
    The hemisphere under external pressure (below the bowl) buckles, next to its held rim, at
    about 0.76 of the classical pressure ``4 sqrt(3 beta)`` (benchmarks/results/stability_pressure.md):

    >>> import shellbvp as sb
    >>> scene = sb.Scene(gamma=1, beta=1e-4, pressure=0.8 * 4 * (3e-4) ** 0.5)
    >>> res = sb.stability(sb.inflate(scene))
    >>> res.stable, res.critical_mode
    (False, 11)

    A state on the tip: the base scene's cap at delta 0.3 is stable, its softest mode n = 1 (the
    cap sliding round the tip); the paper's contact model is refused:

    >>> res = sb.stability(sb.solve(sb.Scene.preset("base"), delta=0.3), modes=range(4))
    >>> res.stable, res.critical_mode
    (True, 1)
    >>> sb.stability(sb.solve(sb.Scene.preset("base").replace(contact="paper"), delta=0.3))
    Traceback (most recent call last):
    ...
    ValueError: stability: contact='paper' is not variational ...; only contact='smooth' is supported
    """
    t0 = time.perf_counter()
    check_supported(state)
    sysm = state.system
    if of(state) is None:  # the inflated shell: no contact
        zeta = float(sysm.S_point(sysm.regions[0].start, None))
        S0 = zeta if S0 is None else max(float(S0), zeta)
        out = spectrum(state.scene, state_base(state), S0, float(sysm.L), modes, elements=elements, count=count,
                       vectors=vectors, end=state.scene.rim)
    else:
        contact = contact_of(state, S0)
        out = spectrum(state.scene, contact.base, contact.S0, float(sysm.L), modes, elements=elements,
                       count=count, vectors=vectors, contact=contact)
    out.wall_time = time.perf_counter() - t0
    return out


def sphere_stretch(scene) -> float:
    """The stretch of the complete sphere (the reference hemisphere, gamma = 1, continued
    through its equator) under the scene's pressure in the membrane state with its uniform
    bending moment: ``kappa_s tau_s + kappa_theta tau_theta = -p`` (the pressure below the bowl
    pushes on its convex side) for ``r = stretch sin S`` (from the generated ``free_profile``)."""
    from scipy.optimize import brentq

    if scene.gamma != 1 or not isinstance(scene.shell, Spheroid):
        raise ValueError("the sphere's membrane state is that of the hemisphere, gamma = 1")
    mod = scene.model()
    par = scene.parameters(mod)
    S = np.array([0.7])

    def residual(stretch):
        y = np.array([[stretch], [1.0], [stretch], [1.0 / stretch], [0.0], [-stretch * math.cos(0.7)]])
        prof = mod.free_profile(S, y, par)
        return float((prof["tau_s"][0] + prof["tau_theta"][0]) / stretch + scene.pressure)

    return brentq(residual, 0.5, 2.0, xtol=1e-14)
