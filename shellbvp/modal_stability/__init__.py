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

A wall whose thickness varies (``scene.thickness_profile``, issue 58): the energy per reference
area is ``t W + beta t^3 B``, so ``A_n`` is the uniform wall's with its membrane part times
``t(S)`` and its bending part times ``t(S)^3`` (the generated form takes ``thk`` per point:
:func:`form.wall_thickness`, the structure's own t at the quadrature points).  Eigenvalues stay
in units of the pole's ``mu H0/R_L^2``; the default mesh and modes follow the thinnest wall
(:func:`fem.local_beta`).  Checks: tests/test_stability_profile.py.

States on the tip (``contact="smooth"``: the cap, the point load, lifted and split contact)
-------------------------------------------------------------------------------------------
Every chain of free regions and regions on the tip joined by contact edges and lines
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

*Friction* (``friction="sticking"``).  All of the above is the frictionless tip: ``u, v`` free on
the contact set.  The other bound is a tip to which the shell sticks, no material point in
contact slipping: ``u = v = 0`` on each region on the tip, at each line, and at a pole held at a
point (``U = u(S0) = 0`` at n = 1; n = 0 and n >= 2 hold it already).  On a region, ``u = 0`` on
the interval makes ``u' = 0`` at its interior nodes, and at its end nodes the one-sided
derivative from inside is 0 too; the elements are C^1, so ``u'`` is continuous and 0 there (an
element on which a field vanishes has all four of its dofs 0): ``u = u' = v = v' = 0`` at every
node of the region, its ends included.  The exact field need not be C^1 in ``u, v`` (the form
holds ``u''`` only times lower derivatives: ``u`` is H^1), so a mode's ``u'`` may jump where it
leaves the stuck region; as at the frictionless edge the graded mesh resolves that kink by a
layer (the base cap at delta 0.3: n = 0..4 move by < 5e-5 with twice the elements).  At a line
and a held pole only ``u = v = 0`` at the node: the material beside it is not in contact.  The
pressure's, the rings' and the pole's curvature terms are quadratic in ``u, v`` where they act
and vanish; a line keeps its rolling term ``+f w1^2/gap`` (with ``u = 0`` the gap's minimum
moves to the neighbouring material: rolling, which sticking allows).

Why these are the two bounds.  The sticking perturbations are a subspace of the frictionless
ones, with the same stiffness and Gram matrices on it, so by the min-max characterisation each
mode's k-th eigenvalue with sticking is at least the frictionless one (exactly so for the
discrete problems: the sticking basis spans a subspace of the frictionless one's;
tests/test_stability_friction.py).  A tip with any friction coefficient mu > 0 lies between:
the frictionless state carries no tangential traction, strictly inside every Coulomb cone, so a
small perturbation that does not slip needs tangential tractions of its own size, which the
cone admits -- a state unstable with a sticking tip is unstable for every mu; and friction only
dissipates on slip, so a state that minimises the energy over the larger, frictionless set is
stable for every mu.  Between the two the verdict depends on mu and on how the contact slips.
Both concern the frictionless base state: friction during loading changes the axisymmetric
state itself (tangential traction on the cap), which neither accounts for.

Cost: a state on the tip of the dome of beta 1e-5 (91 elements and the graded nodes, n = 0..33)
takes 1-2.5 s, the base scene's (beta 0.01, n = 0..8) 0.1 s (the form's derivation, 2-5 s, once per
process).

Accuracy: on the base scene at delta 0.3 (cap, Sc 0.091) the eigenvalues of n = 0..3 move by
less than 3e-4 with twice the elements or with S0 = 1e-3; the dome's first n >= 2 crossings
(benchmarks/results/stability_contact.md) move by < 3e-7 in delta with twice the elements.  At
a pole held at a point, n = 1 depends on the first element's length against S0 (the sharp tip,
rho 0.05, at delta 0.05: frictionless -1.89 and -3.19 with the ratio 15.6 and 7.8, sticking 1.54
and 1.51; benchmarks/results/stability_friction.md): its sign, not its size, is what is known.

A band on the indenter's cylinder is a region on the tip like the others (its meridian is
straight: ``kappa_s = 0``, and only the hoop term remains).

*Corners* (a contact edge past the convexity limit, ``contact_edge == "corner"``).  There lambda_s and kappa_s jump (SPEC 2b, ``shellbvp.corner``), and
the displacement's class changes: the perturbed surface must keep one normal across the corner,
i.e. the rotation of the normal about e_theta, ``omega = (w' + phi' u)/(lambda_s Psi)``
(phi' = d phi/dS = lambda_s Psi kappa_s), is continuous, so ``w'`` jumps with lambda_s and
kappa_s; ``u'`` and ``v'`` may jump (the energy holds them in L^2 only).  The mesh has twin nodes
at the corner (:func:`fem.corner_ties`).  With ``w'`` held continuous instead (C^1 elements
across the corner) the perturbed surface is kinked at first order and the piecewise form's
``u u''`` and ``v v''`` terms leave point terms in ``u'(Sc)`` and ``v'(Sc)`` at the corner: the
eigenvalues fell without bound as the mesh was refined (-2.5e3, -1.1e4 with 40, 80 elements on
the base scene at delta 0.65).

At second order the displacement still kinks the normal: on each side the normal turns by
``R = -omega a/(lambda_s Psi) - q c/(lambda_s Psi r)`` (plus a part common to both), with
``a = u' - phi' w``, ``c = v'``, ``q = v sin(phi) - n w`` (the theta-factors averaged).  The
state that the energy sees is ``x0 + eta xi + eta^2 zeta`` with ``zeta`` restoring one normal;
``zeta``'s first-order energy is a boundary term of the equilibrium, the moment ``r M_s`` (the
conjugate of phi') times zeta's rotation at the corner.  On the tip's side of a contact edge the
shell's normal is the tip's, so that side's total second-order rotation is fixed by the sliding;
eliminating zeta, the corner adds

.. math:: (rM_s)_+ R_+ - (rM_s)_- R_- + \big[(rM_s)_- - (rM_s)_+\big]
          \frac{\kappa_s' u^2 + \kappa_\theta' v^2}{2\lambda_s\Psi}\Big|_{\rm tip\ side}

(theta-averaged, :func:`fem.corner_energy`; ``kappa'`` the tip's curvatures' S-derivatives, zero
on a spherical tip).  The moments
differ across a contact edge (by 0.6-4 % on the base scene at delta 0.7-0.9).  Check
(tests/test_stability_corner.py): along a path that slides the shell exactly along the spherical
tip and keeps it smooth at the edge, the exact energy's second derivative equals the discrete
form's to 7e-7 and 5e-6 at delta 0.7 and 0.9; without the term it misses by 25 %, with one moment
for both sides by 0.4 %; the eigenvalues converge (n = 0..5 within 1e-4 from 40 to 160 elements)
and step smoothly where the corner is born.  Not checked by that test: the torsion's part (v; its
coefficient is the one that keeps the spectrum bounded, which the convergence shows) and the tip
curvature's slope term (no non-spherical tip in the check).

The corner itself stays at its material point: moving it through the material (its position a
function of theta) is a degree of freedom of its own, with the Eshelby condition as its first
variation, that the displacement modes do not carry.  A negative eigenvalue of a cornered state
therefore proves it unstable; a positive one is stability against the perturbations that keep
the corner where it is (``Stability.held_corners`` names them).

A closed shell (``Scene(closed=True)``): between plates (or under a flat tip) its half above the
equator is solved, and its modes are those of that half with the equator's conditions for modes
symmetric (``u = w' = 0``, and ``v = 0`` at n = 0: the spin about the axis held) and
antisymmetric (``v = w = 0``) about it.  On a substrate under a curved tip both halves are
solved, each from its own pole, and their modes are tied at the equator into one problem
(:mod:`.closed`, :func:`.contact.halves_of`).  n = 1 is left out unless asked for
(:func:`.fem.checked_modes`): the frictionless model's rigid motions (sliding and turning between
plates at no cost; on a substrate under a curved tip slipping out sideways, negative, and rolling
in place, zero).

Refused (ValueError, one line): the contact running over the tip's end onto the cylinder
(``"cap+cylinder"``: held on both sides of a corner of the obstacle, across which material
would have to slide), an interior corner (``"line+corner"``: the package's searches find no state
of it to check the corner's terms on), ``contact="paper"``, a line whose gap is not positive, more than one line,
an edge inside [0, S0] of a configuration with several, a sealed shell in contact (a closed shell
under volume control included), and a state
whose negative eigenvalue is not resolved: it still moves on 16 times the elements (an edge next
to its convexity limit) or with the mesh starting 10 times further from the pole (the form's
1/r^3 coefficients cancelling there; :func:`stability`'s checks).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..geometry import Spheroid
from ..configurations import of
from .closed import spectrum_closed
from .contact import FRICTION, NOT_BUILT, Contact, check_friction, check_supported, contact_of, halves_of, supported
from .fem import (
    END_CONDITIONS, Stability, check_stability_size, checked_modes, default_elements, default_modes, either_side,
    mesh, spectrum, stability_size,
)
from .form import chain_base, form_functions, sphere_base, state_base

__all__ = ["stability", "Stability", "spectrum", "state_base", "sphere_base", "mesh", "default_modes", "checked_modes",
           "default_elements", "END_CONDITIONS", "sphere_stretch", "NOT_BUILT", "supported", "Contact", "check_supported",
           "contact_of", "halves_of", "spectrum_closed", "chain_base", "form_functions", "FRICTION", "stability_size", "check_stability_size"]


def stability(state, modes=None, *, elements: int | None = None, S0: float | None = None,
              count: int = 2, vectors: bool = False, friction: str = "frictionless", max_dofs=None) -> Stability:
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
    friction : {"frictionless", "sticking"}
        The tip's tangential behaviour on the contact set: free sliding (``u, v`` free there), or
        no slip (``u = v = 0`` there, the pole held at a point included).  The two bound the
        stability of the state under any friction coefficient (module docstring, "Friction");
        no effect without contact.
    max_dofs : int, optional
        Refuse (ValueError, before anything is built) an analysis of more unknowns than this,
        summed over the modes (:func:`stability_size`); default ``sb.options``'
        ``max_stability_dofs`` (300,000: about 15 s, the hemisphere at beta ~ 1e-7).

    Returns
    -------
    Stability
        ``.modes``, ``.eigenvalues`` (per mode the ``count`` smallest), ``.critical_mode``,
        ``.stable``.

    Raises
    ------
    ValueError
        One line naming what is not supported (:func:`check_supported`, :func:`contact_of`): a
        state that did not converge, the contact over the tip's end, ``contact="paper"``, a line
        without a curvature gap, a sealed shell in contact, a negative eigenvalue not resolved in
        the mesh or at the pole (module docstring).

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
    check_friction(friction)
    two = state.scene is not None and state.scene.two_contacts
    check_supported(state, halves=two)
    modes = None if modes is None else [int(n) for n in modes]
    check_stability_size(state.scene, modes, elements, max_dofs)
    sysm = state.system
    # a closed shell: n = 1 is left out (fem.checked_modes; the spin about the axis, n = 0, is held
    # at the equator)
    if modes is None and state.scene.closed:
        modes = [int(n) for n in checked_modes(state.scene)]
    if two:  # both halves, each from its own pole, tied at the equator
        def solve(modes, S0, elements=elements, **kw):
            return spectrum_closed(state.scene, halves_of(state, S0, friction), float(sysm.L), modes,
                                   elements=elements, **kw)
    elif of(state) is None:  # the inflated shell: no contact
        zeta = float(sysm.S_point(sysm.regions[0].start, None))
        S0 = zeta if S0 is None else max(float(S0), zeta)

        def solve_end(modes, S0, end, elements=elements, **kw):
            return spectrum(state.scene, state_base(state), S0, float(sysm.L), modes, elements=elements,
                            end=end, **kw)
    else:
        def solve_end(modes, S0, end, elements=elements, **kw):
            contact = contact_of(state, S0, friction)
            return spectrum(state.scene, contact.base, contact.S0, float(sysm.L), modes, elements=elements,
                            contact=contact, end=end, **kw)

    if not two:
        def solve(modes, S0, **kw):
            # a closed shell's half: the modes symmetric and antisymmetric about its equator
            ends = ("held-symmetric", "antisymmetric") if state.scene.closed else (state.scene.rim,)
            return either_side([solve_end(modes, S0, end, **kw) for end in ends])
    out = solve(modes, S0, count=count, vectors=vectors)
    _refine_negative(out, solve)
    _check_pole_floor(out, solve)
    out.wall_time = time.perf_counter() - t0
    return out


#: A negative eigenvalue is recomputed with this many times the elements (:func:`_refine_negative`).
REFINE_FACTOR = 4


def _refine_negative(out, solve):
    """Recompute each mode with a negative eigenvalue on :data:`REFINE_FACTOR` times the elements
    and keep the finer eigenvalues (``out.refined``: those modes); where the finer one is still
    negative but differs from the coarser by more than a factor 2, once more on REFINE_FACTOR
    times those: the finest is kept if it is positive or within a factor 2 of the one before, else
    a ValueError (one line): not resolved in the mesh.

    Where a contact edge is close to its convexity limit its free side has a layer whose width
    falls with the Legendre determinant there; the default mesh does not resolve it, and at a
    corner just born the corner's terms then give negative eigenvalues that are not the state's
    (the grid's gamma = 2 at delta 0.739, lambda_s jumping by 0.005: n = 1 at -1.66, 0.418, 0.933
    with 40, 160, 640 elements).  A negative verdict is worth the finer meshes."""
    negative = [int(n) for n, lam in zip(out.modes, out.smallest) if lam < 0]
    if not negative:
        return
    elements, coarse = out.elements, {int(n): float(lam) for n, lam in zip(out.modes, out.smallest)}
    for _ in range(2):
        elements *= REFINE_FACTOR
        fine = solve(negative, out.S0, elements=elements, count=out.eigenvalues.shape[1], vectors=bool(out.vectors))
        for n, values in zip(fine.modes, fine.eigenvalues):
            out.eigenvalues[list(out.modes).index(n)] = values
        out.vectors.update(fine.vectors)
        out.refined = tuple(sorted(set(out.refined) | {int(n) for n in fine.modes}))
        unsure = [int(n) for n, lam in zip(fine.modes, fine.smallest)
                  if lam < 0 and not 0.5 * coarse[int(n)] >= lam >= 2 * coarse[int(n)]]
        if not unsure:
            return
        if elements > out.elements * REFINE_FACTOR:  # still moving after the second refinement
            raise ValueError(f"stability: mode n = {unsure[0]} is not resolved in the mesh (smallest eigenvalue "
                             f"{coarse[unsure[0]]:.3g} with {elements // REFINE_FACTOR} elements, "
                             f"{float(fine.smallest[list(fine.modes).index(unsure[0])]):.3g} with {elements}); "
                             f"a contact edge next to its convexity limit has a layer thinner than the mesh")
        negative = unsure
        coarse = {int(n): float(lam) for n, lam in zip(fine.modes, fine.smallest)}


#: A negative eigenvalue is recomputed with the mesh starting this many times further from the
#: pole (:func:`_check_pole_floor`).
POLE_CHECK_FACTOR = 10.0


def _check_pole_floor(out, solve):
    """ValueError (one line) if a negative eigenvalue is the pole's rounding floor, not the state's.

    Near the pole the form's coefficients (up to 1/r^3) cancel; where the pole is strongly
    compressed and bent (a thick shell's lifted pole near its fold: lambda0 0.37, kappa_s 71 at
    beta 0.2) the rounding left is larger than the energy: n = 2 reads -1.2e6 and -1.9e4 with the
    mesh starting 10 times further out, and n = 0 changes sign (benchmarks/results/stability_contact.md).
    A genuine instability's eigenvalue hardly depends on where the mesh starts (the modes live on
    the bending length): each negative one is recomputed with S0 times :data:`POLE_CHECK_FACTOR`
    and must stay negative and within a factor 10 of itself -- or move by less than 1 % of the
    state's eigenvalues (the median over modes of their magnitudes): near a crossing the
    eigenvalue is small and moving the mesh's start moves the crossing (the deep dome of the grid,
    gamma -2, at delta 0.367: -1.96e-4 and -0.94e-4, against eigenvalues of order 1)."""
    negative = [int(n) for n, lam in zip(out.modes, out.smallest) if lam < 0]
    if not negative:
        return
    scale = float(np.median(np.abs(out.eigenvalues)))
    check = solve(negative, out.S0 * POLE_CHECK_FACTOR, count=1)
    for n, far in zip(check.modes, check.smallest):
        near = float(out.smallest[list(out.modes).index(n)])
        agrees = far < 0 and max(-far, -near) <= 10 * min(-far, -near)
        if not (agrees or abs(far - near) <= 0.01 * scale):
            raise ValueError(f"stability: mode n = {n} is not resolved at the pole (smallest eigenvalue {near:.3g} "
                             f"with the mesh from S0 = {out.S0:.3g}, {far:.3g} from {out.S0 * POLE_CHECK_FACTOR:.3g}): "
                             "the form's coefficients there cancel below double precision")


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
