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
  it vanishes, ``u = v = w = 0``; ``w'`` is free (its natural condition is ``M_s = 0``).  With
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
(:data:`SUPPORTED`) is handled alike: ``w = w' = 0`` on each region on the tip, ``w = 0`` at a
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

import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from .chain import CONTACT_KINDS, CONTACT_STATES, FREE_STATES, Edge, Line
from .geometry import Spheroid

__all__ = ["stability", "Stability", "spectrum", "state_base", "sphere_base", "mesh", "default_modes",
           "default_elements", "END_CONDITIONS", "sphere_stretch"]

#: Gauss points per element.
GAUSS = 6


@dataclass(eq=False)
class Stability:
    """The smallest eigenvalues of the second variation per Fourier mode.

    Attributes
    ----------
    modes : ndarray of int
        The mode numbers n.
    eigenvalues : ndarray, shape (len(modes), count)
        The smallest ``count`` eigenvalues of each mode, ascending (``d^2 Pi/d eta^2`` per squared
        L2 norm of the displacement over the reference surface; module docstring).
    critical_mode : int
        The n of the smallest eigenvalue.
    stable : bool
        Every eigenvalue positive.
    vectors : dict
        Per mode, the eigenvector of its smallest eigenvalue as fields ``S, u, v, w`` at the nodes.
    elements : int
        Elements of the mesh in S.
    S0 : float
        Where the mesh starts (the pole conditions are imposed there).
    wall_time : float
        Seconds (the form's derivation included on first use in a process).

    Examples
    --------
    >>> import shellbvp as sb
    >>> res = sb.stability(sb.inflate(sb.Scene(gamma=1, beta=1e-3)), modes=range(4), elements=20)
    >>> res.stable, res.critical_mode, res.eigenvalues.shape
    (True, 1, (4, 2))
    """

    modes: np.ndarray
    eigenvalues: np.ndarray
    elements: int
    S0: float
    vectors: dict = field(default_factory=dict)
    wall_time: float = math.nan

    @property
    def smallest(self) -> np.ndarray:
        """The smallest eigenvalue of each mode."""
        return self.eigenvalues[:, 0]

    @property
    def critical_mode(self) -> int:
        return int(self.modes[int(np.argmin(self.smallest))])

    @property
    def minimum(self) -> float:
        """The smallest eigenvalue over all modes."""
        return float(np.min(self.smallest))

    @property
    def stable(self) -> bool:
        return bool(self.minimum > 0)

    def __repr__(self):
        return (f"Stability(critical_mode={self.critical_mode}, minimum={self.minimum:.4g}, "
                f"stable={self.stable}, modes={self.modes[0]}..{self.modes[-1]}, elements={self.elements})")


# ------------------------------------------------------------------------------ the form, numeric
@functools.lru_cache(maxsize=16)
def _numeric_form(structure_key):
    """(upper-triangle entry function of the 9 x 9 form, the entries' (i, j), its parameter
    names, the reference shell's parameter names, the reference-shell function) for a structure
    description (a hashable key): the generated module of ``symbolic.second_variation``."""
    import json

    from .model import load_stability_module

    mod = load_stability_module(json.loads(structure_key))
    return mod.form, list(mod.UPPER), list(mod.PARAMS), list(mod.SHELL_PARAMS), mod.reference


def _form_functions(scene):
    import json

    return _numeric_form(json.dumps(scene.structure(), sort_keys=True))


def state_base(state):
    """The base state of ``state`` as a function of S: a dict of ``phi, ls, ks, dls, dks, lt``
    from the inflated state's interpolant (``dls, dks`` its S-derivatives)."""
    return functools.partial(_base_state, state)


def sphere_base(stretch: float):
    """The uniformly stretched sphere ``r = stretch sin S`` of the reference hemisphere (gamma = 1)
    as a base state (no rim layer): the membrane state of a complete sphere under pressure."""
    def base(S):
        one = np.ones_like(S)
        return {"phi": S.copy(), "ls": stretch * one, "ks": one / stretch, "dls": 0 * S, "dks": 0 * S,
                "lt": stretch * one}
    return base


def _base_state(state, S):
    """The base symbols' values at S (dict by name) from an inflated state's interpolant."""
    sysm = state.system
    a, b = sysm.ln_S(sysm.regions[0].start, None), sysm.ln_S(sysm.regions[0].end, None)
    t = (np.log(S) - a) / (b - a)
    y = state.sol(t)
    dy = state.sol.derivative()(t) / (S * (b - a))  # d/dS
    lt, phiS, ls, ks = y[0], y[1], y[2], y[3]
    return {"phi": phiS * S, "ls": ls, "ks": ks, "dls": dy[2], "dks": dy[3], "lt": lt}


def _form_at(scene, base_of, S, n):
    """The 9 x 9 form at the points S (shape (9, 9, len(S))) for mode n."""
    f, upper, params, shell_params, ref = _form_functions(scene)
    values = scene.values()
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(np.asarray(v, float), S.shape)
                              for v in ref(S, *[values[p] for p in shell_params]))
    base = base_of(S)
    r = base["lt"] * R
    args = (r, base["phi"], base["ls"], base["ks"], base["dls"], base["dks"], R, Psi, dPsi, ks0, kt0,
            *[values[p] for p in params], n)
    with np.errstate(all="ignore"):
        out = f(*args)
    A = np.empty((9, 9, S.size))
    for (i, j), e in zip(upper, out):
        A[i, j] = A[j, i] = np.broadcast_to(np.asarray(e, float), S.shape)
    if "P" in base:  # on the tip: the constraint's curvature, -P/2 II(dx_t, dx_t) per deformed area
        cu, cv = contact_coefficients(base, R, Psi)
        A[0, 0] += cu
        A[3, 3] += cv
    return A, R * Psi


def contact_coefficients(base, R, Psi):
    """The contact term's coefficients of ``u^2`` and ``v^2`` in the form (per dS, module
    docstring): ``-P r psi kappa_s / 4`` and ``-P r psi kappa_theta / 4`` (zero where P = 0)."""
    r = base["lt"] * R
    weight = -0.25 * base["P"] * r * base["ls"] * Psi
    with np.errstate(all="ignore"):
        kt = np.where(base["P"] != 0, np.sin(base["phi"]) / r, 0.0)
    return weight * base["ks"], weight * kt


# ------------------------------------------------------------------------------ cubic Hermite FEM
def _hermite(xi, h):
    """Values, first and second S-derivatives of the four cubic Hermite shape functions on an
    element of length h at reference points xi in [0, 1] (dofs: f(a), f'(a), f(b), f'(b))."""
    H = np.array([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                  h * (-xi**2 + xi**3)])
    dH = np.array([-6 * xi + 6 * xi**2, h * (1 - 4 * xi + 3 * xi**2), 6 * xi - 6 * xi**2,
                   h * (-2 * xi + 3 * xi**2)]) / h
    ddH = np.array([-6 + 12 * xi, h * (-4 + 6 * xi), 6 - 12 * xi, h * (-2 + 6 * xi)]) / h**2
    return H, dH, ddH


def _assemble(scene, base_of, n, nodes):
    """Stiffness K (4 x the form) and Gram M of (u, v, w) on the Hermite mesh (sparse CSR).

    Global dofs: per node ``(u, u', v, v', w, w')``, node-major; derivative dofs times the
    largest element length (so all dofs have the size of the fields)."""
    m = nodes.size
    ndof = 6 * m
    xg, wg = np.polynomial.legendre.leggauss(GAUSS)
    xg, wg = (xg + 1) / 2, wg / 2
    h = np.diff(nodes)
    S = (nodes[:-1, None] + h[:, None] * xg[None, :]).ravel()
    A, area = _form_at(scene, base_of, S, n)
    A = A.reshape(9, 9, m - 1, GAUSS)
    area = area.reshape(m - 1, GAUSS)
    hs = h.max()  # scale of the derivative dofs
    B = np.stack([_element_basis(xg, he, hs) for he in h])  # (elements, 9, 12, GAUSS)
    weights = wg[None, :] * h[:, None]
    Ke = 4 * np.einsum("eiag,ijeg,ejbg,eg->eab", B, A, B, weights, optimize=True)
    G = B[:, [0, 3, 6]]
    Me = np.einsum("eiag,eibg,eg->eab", G, G, weights * area, optimize=True)
    idx = 6 * np.arange(m - 1)[:, None] + np.arange(12)[None, :]
    rows = np.broadcast_to(idx[:, :, None], Ke.shape).ravel()
    cols = np.broadcast_to(idx[:, None, :], Ke.shape).ravel()
    K = scipy.sparse.csr_matrix((Ke.ravel(), (rows, cols)), shape=(ndof, ndof))
    M = scipy.sparse.csr_matrix((Me.ravel(), (rows, cols)), shape=(ndof, ndof))
    return K, M


def _banded(A, bandwidth):
    """The upper band of a symmetric sparse matrix in LAPACK's banded storage."""
    coo = scipy.sparse.triu(A).tocoo()
    ab = np.zeros((bandwidth + 1, A.shape[0]))
    ab[bandwidth + coo.row - coo.col, coo.col] = coo.data
    return ab


def _smallest(K, M, count):
    """The ``count`` smallest eigenvalues (and vectors) of K q = lambda M q, K symmetric, M
    positive definite, both banded sparse: shift-invert Lanczos (``eigsh``) about a shift below
    the spectrum, which a banded Cholesky factorisation of ``K - sigma M`` certifies (it
    exists only when ``K - sigma M`` is positive definite)."""
    coo = K.tocoo()
    bandwidth = int(np.max(np.abs(coo.row - coo.col)))
    Kb, Mb = _banded(K, bandwidth), _banded(M, bandwidth)

    def factor(sigma):
        try:
            return scipy.linalg.cholesky_banded(Kb - sigma * Mb)
        except np.linalg.LinAlgError:
            return None

    # bracket the smallest eigenvalue between a shift that factorises (below it) and one that
    # does not, then bisect: Lanczos about a shift just below the spectrum converges fast
    lo, hi, step = 0.0, None, 1.0
    if factor(lo) is None:
        hi = lo
        while factor(lo) is None:
            lo, step = lo - step, 4 * step
            if step > 1e30:
                raise RuntimeError("no shift below the spectrum found")
    else:
        hi = step
        while factor(hi) is not None:
            lo, hi, step = hi, hi + 4 * step, 4 * step
    for _ in range(60):
        if hi - lo <= 1e-3 * max(1.0, abs(lo)):
            break
        mid = (lo + hi) / 2
        if factor(mid) is None:
            hi = mid
        else:
            lo = mid
    sigma = lo - 1e-3 * max(1.0, abs(lo))
    chol = factor(sigma)
    op = scipy.sparse.linalg.LinearOperator(K.shape, matvec=lambda x: scipy.linalg.cho_solve_banded(
        (chol, False), x), dtype=float)
    lam, X = scipy.sparse.linalg.eigsh(K, k=count, M=M, sigma=sigma, which="LM", OPinv=op, tol=1e-12)
    order = np.argsort(lam)
    return lam[order], X[:, order]


@functools.lru_cache(maxsize=64)
def _element_basis_cached(xg_key, h, hs):
    xg = np.array(xg_key)
    H, dH, ddH = _hermite(xg, h)
    # derivative dofs d = f' * hs: the shape function of d is (shape of f') / hs
    col = np.array([1.0, 1.0 / hs, 1.0, 1.0 / hs])
    H, dH, ddH = H * col[:, None], dH * col[:, None], ddH * col[:, None]
    B = np.zeros((9, 12, xg.size))
    # local dof order: node a (u, u', v, v', w, w'), node b (same); field f in {0: u, 1: v, 2: w}
    for f in range(3):
        cols = [2 * f, 2 * f + 1, 6 + 2 * f, 6 + 2 * f + 1]
        for k, c in enumerate(cols):
            B[3 * f, c] = H[k]
            B[3 * f + 1, c] = dH[k]
            B[3 * f + 2, c] = ddH[k]
    return B


def _element_basis(xg, h, hs):
    return _element_basis_cached(tuple(xg), float(h), float(hs))


#: Dofs (of u, u', v, v', w, w') held at the end S = L: the held rim (``w'`` free: M_s = 0), or
#: the equator of a complete sphere for modes symmetric (u = 0, w' = 0; Q and the in-plane
#: shear vanish naturally) or antisymmetric (v = w = 0; w'' = 0 naturally) about it.
END_CONDITIONS = {"pinned": (0, 2, 4), "symmetric": (0, 5), "antisymmetric": (2, 4)}


def _constraints(n, m, end="pinned", S0_over_hs=0.0, held=(), pole_held=False, lines=()):
    """The reduced basis T (sparse, ndof x nfree) that imposes the pole (node 0) and end
    (node m-1) conditions: q = T q_free.  ``S0_over_hs``: S0 over the derivative dofs' scale
    (n = 1's ``w = S0 w'`` at S0).  ``held``: nodes on the tip (``w = w' = 0``: the normal
    displacement vanishes on the contact region, module docstring); ``pole_held``: the pole
    touches the tip at a point (``w = 0`` at S0 for n = 0; the n >= 1 pole conditions hold it
    already or let it slide); ``lines``: the nodes of line contacts (``w = 0`` there)."""
    ndof = 6 * m
    fixed = {6 * (m - 1) + k for k in END_CONDITIONS[end]}
    fixed |= {6 * i + k for i in held for k in (4, 5)}
    fixed |= {6 * i + 4 for i in lines}
    tie_w = n == 1 and 0 not in held
    if n == 1 and (held or pole_held or lines):
        # u = U + O(S^2), v = -U + O(S^2) at the axis: u' = v' = 0.  Where the pole carries a
        # bending prestress (on the tip, or under a point load) the form's u u'' and v v''
        # terms are not small, and without these conditions a layer at S0 lowers the energy
        # without bound as the first element shrinks (measured: tests/test_stability_contact.py)
        fixed |= {1, 3}
    if n == 0:
        fixed |= {0, 2, 5}  # u = v = 0, w' = 0
        if pole_held:
            fixed.add(4)
    elif n == 1:
        fixed |= {2, 4}  # v(S0) = -u(S0), w(S0) = S0 w'(S0): folded into u's and w''s columns
    else:
        fixed |= {0, 2, 4, 5}
    free = np.array([i for i in range(ndof) if i not in fixed])
    rows, cols, vals = list(free), list(range(free.size)), [1.0] * free.size
    if n == 1:
        rows += [2]
        cols += [int(np.flatnonzero(free == 0)[0])]
        vals += [-1.0]
        if tie_w:
            rows += [4]
            cols += [int(np.flatnonzero(free == 5)[0])]
            vals += [S0_over_hs]
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(ndof, free.size))


#: Grading at the pole: the first uniform element is split geometrically (ratio POLE_RATIO)
#: down to a few times S0, so that the quadrature resolves the form's 1/r^k near the pole.
POLE_RATIO = 0.25


def mesh(S0: float, L: float, elements: int, edges=()) -> np.ndarray:
    """Nodes on [S0, L]: ``elements`` uniform elements, the first split towards S0 geometrically;
    at each of ``edges`` (contact edges and lines inside (S0, L)) a node and :data:`EDGE_LEVELS`
    nodes on each side at ``h/2, h/4, ...`` from it (the mode's derivatives jump there: without
    the grading the eigenvalues converged only like h)."""
    nodes = np.linspace(S0, L, elements + 1)
    h = nodes[1] - nodes[0]
    extra = []
    d = h * POLE_RATIO
    while d > 4 * S0:
        extra.append(S0 + d)
        d *= POLE_RATIO
    nodes = np.concatenate([nodes[:1], np.array(extra[::-1]), nodes[1:]])
    steps = h * 0.5 ** np.arange(1, EDGE_LEVELS + 1)
    for edge in edges:
        near = np.concatenate([edge - steps, [edge], edge + steps])
        near = near[(near > S0) & (near < L)]
        far = nodes[(np.abs(nodes - edge) >= h / 2) | np.isin(nodes, edges)]  # uniform nodes closer than h/2 give way
        nodes = np.unique(np.concatenate([far, near]))
    return nodes


#: Nodes on each side of a contact edge (:func:`mesh`).
EDGE_LEVELS = 8


def default_elements(scene) -> int:
    """Elements in S: 24 per local buckling wavelength ``2 pi / k_c``, ``k_c = (3/beta)^(1/4)``
    (the wavenumber of the sphere's classical modes, package units), at least 40."""
    kc = (3.0 / scene.beta) ** 0.25
    return max(40, int(math.ceil(24 * scene.shell_length * kc / (2 * math.pi))))


def default_modes(scene) -> np.ndarray:
    """n = 0 .. N with ``N = ceil(1.3 k_c) + 2``: the classical modes of wavenumber k_c reach
    ``n = k_c r`` on the rim circle (r = 1)."""
    kc = (3.0 / scene.beta) ** 0.25
    return np.arange(0, int(math.ceil(1.3 * kc)) + 3)


def stability(state, modes=None, *, elements: int | None = None, S0: float | None = None,
              count: int = 2, vectors: bool = False) -> Stability:
    """The smallest eigenvalues of the second variation of ``state`` per Fourier mode.

    Parameters
    ----------
    state : Solution
        A converged state: :func:`shellbvp.inflate`'s (topology ``"inflated"``), or one on the
        tip with ``contact="smooth"`` (a topology in :data:`SUPPORTED`; module docstring).
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
    if state.topology == "inflated":
        zeta = float(sysm.S_point(sysm.regions[0].start, None))
        S0 = zeta if S0 is None else max(float(S0), zeta)
        out = spectrum(state.scene, state_base(state), S0, float(sysm.L), modes, elements=elements, count=count,
                       vectors=vectors)
    else:
        contact = contact_of(state, S0)
        out = spectrum(state.scene, contact.base, contact.S0, float(sysm.L), modes, elements=elements,
                       count=count, vectors=vectors, contact=contact)
    out.wall_time = time.perf_counter() - t0
    return out


#: The topologies whose stability is built (``"inflated"``: no contact): every chain of free
#: regions and regions on the tip joined by smooth edges and lines.
SUPPORTED = ("inflated", "cap", "point", "line", "annulus", "cap+line(tip)", "cap+band(tip)", "cap+line(cylinder)",
             "cap+band(cylinder)")


def check_supported(state):
    """ValueError (one line, naming what is not supported) unless :func:`stability` handles
    ``state``: a converged state of a topology in :data:`SUPPORTED` with the smooth contact
    edge, under pressure (not volume) control."""
    if not state.success:
        raise ValueError(f"stability: the state did not converge ({state.message})")
    if state.topology not in SUPPORTED:
        raise ValueError(f"stability: topology {state.topology!r} is not supported (only "
                         f"{', '.join(repr(t) for t in SUPPORTED)}: the contact running over the tip's end onto the "
                         f"indenter's cylinder and interior corners are not built)")
    if state.topology == "inflated":
        return
    scene = state.scene
    if scene.contact != "smooth":
        raise ValueError(f"stability: contact={scene.contact!r} is not variational (its edge conditions are not "
                         f"the natural conditions of an energy); only contact='smooth' is supported")
    if state.contact_edge == "corner":
        raise ValueError("stability: a contact edge with a Weierstrass-Erdmann corner (contact_edge 'corner') "
                         "is not supported, only the smooth edge")
    if scene.sealed:
        raise ValueError("stability: a sealed shell (volume control) in contact is not supported, only "
                         "pressure control")


@dataclass(eq=False)
class Contact:
    """What the tip adds to the eigenproblem of a state in contact (module docstring).

    ``base``: the base state as a function of S, with the contact pressure ``P`` (0 off the
    tip); ``S0``: where the mesh starts; ``held``: the S-intervals on the tip (w = w' = 0);
    ``lines``: the line contacts' S (w = 0); ``rings``: per edge or line ``(S, (a, b, c, d))``,
    its quadratic form ``a u^2 + b v^2 + 2 c u w' + d w'^2`` in the stiffness; ``pole_held``:
    the contact lies within [0, S0] or is a point load (the pole held at a point), with
    ``pole_force`` the axial force there and ``apex_curvature`` the tip's.
    """

    base: object
    S0: float
    held: tuple = ()
    lines: tuple = ()
    rings: tuple = ()
    pole_held: bool = False
    pole_force: float = 0.0
    apex_curvature: float = 0.0

    @property
    def edges(self):
        """Where the contact starts or ends inside the mesh, and the lines."""
        return tuple(sorted({S for S, _ in self.rings} | {S for a, b in self.held for S in (a, b)
                                                          if S > self.S0}))


def _junction_points(sysm, p):
    """(S, kind, inner region, outer region) of every contact edge and line, pole to rim, in the
    order of ``Solution.edge_forces`` (``shellbvp.diagnosis``)."""
    out = []
    for j in sysm.junctions:
        if isinstance(j, Edge):
            out.append((float(sysm.S_point(sysm.regions[min(j.kc, j.kf)].end, p)), "edge", j.kc, j.kf))
        elif isinstance(j, Line):
            out.append((float(sysm.S_point(sysm.regions[j.k].end, p)), "line", j.k, j.k + 1))
    return out


def contact_of(state, S0=None) -> Contact:
    """The :class:`Contact` of a state on the tip: the base state from the regions' generated
    profiles (:func:`chain_base`), the regions on the tip, and at each contact edge and line
    its normal ring force (``state.edge_forces``, ``-2 pi [r Q]``) with the curvatures there."""
    check_supported(state)
    from .inflation import EPS

    sysm, p = state.system, state.p
    L = float(sysm.L)
    zeta = float(sysm.S_point(sysm.regions[0].start, p))
    S0 = max(EPS * L, zeta) if S0 is None else max(float(S0), zeta)
    base = chain_base(state)
    apex = state.scene.tip.apex_curvature() / state.scene.rho
    points = _junction_points(sysm, p)
    if state.topology == "point" or (state.topology in ("cap", "line") and points[0][0] <= S0 * (1 + 1e-9)):
        # the cap or line lies within the pole's disc: a point contact there
        return Contact(base, S0, pole_held=True, pole_force=float(state.force), apex_curvature=apex)
    if points[0][0] <= S0 * (1 + 1e-9):
        raise ValueError(f"stability: a contact edge at S = {points[0][0]:.3g} inside the mesh's start "
                         f"S0 = {S0:.3g} of a {state.topology!r} state is not supported")
    held = tuple((max(float(sysm.S_point(r.start, p)), S0), float(sysm.S_point(r.end, p)))
                 for r in sysm.regions if r.kind in CONTACT_KINDS)
    lines = [S for S, kind, _, _ in points if kind == "line"]
    if len(lines) > 1:
        raise ValueError("stability: more than one line contact is not supported")
    rings = []
    for (S, kind, k, other), force in zip(points, state.edge_forces):
        side = S * (1 - 1e-12) if k < other else S * (1 + 1e-12)  # inside region k: the tip's side of an edge
        at = base(np.array([side]))
        R, Psi = (float(v[0]) for v in _reference(state.scene, np.array([S])))
        kt = float(np.sin(at["phi"][0]) / (at["lt"][0] * R))
        ks = float(at["ks"][0])
        f = float(force) / (2 * np.pi)  # the normal ring force per unit length, times r
        if kind == "edge":
            rings.append((S, (-f * ks, -f * kt, 0.0, 0.0)))
            continue
        # a line: the gap's second variation with the contact point rolling along the meridian,
        # kappa_S u^2 + 2 u w'/psi - w'^2/(psi^2 gap) + kappa_theta v^2 (module docstring), with
        # gap = kappa_s(indenter) - kappa_s(shell) = -curvature_excess > 0, kappa_S the shell's
        gap = -float(state.curvature_excess)
        if not gap > 0:
            raise ValueError(f"stability: the line contact's curvature gap {gap:.3g} is not positive (the shell "
                             f"bends as tightly as the indenter there: a band), not supported")
        psi = float(at["ls"][0]) * Psi
        rings.append((S, (-f * ks, -f * kt, -f / psi, f / (psi**2 * gap))))
    return Contact(base, S0, held=held, lines=tuple(lines), rings=tuple(rings), apex_curvature=apex)


def _reference(scene, S):
    """(R, Psi) of the reference shell at S."""
    f, upper, params, shell_params, ref = _form_functions(scene)
    values = scene.values()
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(np.asarray(v, float), S.shape)
                              for v in ref(S, *[values[p] for p in shell_params]))
    return R, Psi


#: Step in t of the directional derivative of the profiles (:func:`chain_base`).
PROFILE_STEP = 1e-6


def chain_base(state):
    """The base state of any chain of regions as a function of S: ``phi, ls, ks, dls, dks, lt``
    and the contact pressure ``P`` (0 in free regions), from each region's generated profile
    (``*_profile``, as ``Solution.profile`` reads them) on the state's interpolant; ``dls, dks``
    are the interpolant's derivatives where they are states of the region (``ls`` always,
    ``ks`` in free regions; near the pole the form's 1/r^3 coefficients cancel, and a
    difference quotient's rounding there moves n = 1 by percents), else the derivatives of the
    profile along the interpolant (central difference of step :data:`PROFILE_STEP` in t along
    ``(S'(t), y'(t))``: the tip's kappa_s)."""
    sysm, p = state.system, state.p
    dsol = state.sol.derivative()
    kernels = sysm.kernels.active
    par = sysm.par_at(p)
    edges = [float(sysm.S_point(reg.end, p)) for reg in sysm.regions[:-1]]

    def base(S):
        S = np.asarray(S, float)
        out = {k: np.empty_like(S) for k in ("phi", "ls", "ks", "dls", "dks", "lt", "P")}
        which = np.searchsorted(edges, S, side="right")
        for k, reg in enumerate(sysm.regions):
            sel = which == k
            if not np.any(sel):
                continue
            Sk = S[sel]
            t = sysm.t_of(k, Sk, p)
            a, b = sysm.ln_S(reg.start, p), sysm.ln_S(reg.end, p)
            y = state.sol(t)[sysm.rows(k)]
            dy = dsol(t)[sysm.rows(k)]
            dS = Sk * (b - a)
            prof = getattr(kernels, f"{reg.kind}_profile")
            h = PROFILE_STEP
            f0 = prof(Sk, y, par)
            fp = prof(Sk + h * dS, y + h * dy, par)
            fm = prof(Sk - h * dS, y - h * dy, par)
            for key, name in (("phi", "phi"), ("ls", "lambda_s"), ("ks", "kappa_s"), ("lt", "lambda_theta")):
                out[key][sel] = np.broadcast_to(f0[name], Sk.shape)
            states = FREE_STATES if reg.kind == "free" else CONTACT_STATES
            for key, name, state_name in (("dls", "lambda_s", "ls"), ("dks", "kappa_s", "ks")):
                if state_name in states:  # a state of the region: its interpolant's derivative
                    out[key][sel] = dy[states.index(state_name)] / dS
                else:
                    out[key][sel] = np.broadcast_to((np.asarray(fp[name]) - np.asarray(fm[name])) / (2 * h),
                                                    Sk.shape) / dS
            out["P"][sel] = np.broadcast_to(f0["P"], Sk.shape) if reg.kind != "free" else 0.0
        return out

    return base


def spectrum(scene, base_of, S0, L, modes=None, *, elements=None, count=2, vectors=False, end="pinned",
             contact=None):
    """The eigenvalues of :func:`stability` for a base state given as a function of S
    (:func:`state_base`, :func:`sphere_base`) on [S0, L], with ``end`` conditions at L
    (:data:`END_CONDITIONS`) and, for a state on the tip, its :class:`Contact`."""
    t0 = time.perf_counter()
    ne = elements or default_elements(scene)
    nodes = mesh(S0, L, ne, () if contact is None else contact.edges)
    held, pole_held, lines, extra = (), False, (), {}
    if contact is not None:
        pole_held = contact.pole_held
        held = tuple(int(i) for a, b in contact.held for i in np.flatnonzero((nodes >= a) & (nodes <= b)))
        lines = tuple(int(np.flatnonzero(nodes == S)[0]) for S in contact.lines)
        hs = np.diff(nodes).max()  # the scale of the derivative dofs (_assemble)
        for S, (uu, vv, uw, ww) in contact.rings:
            i = 6 * int(np.flatnonzero(nodes == S)[0])
            for key, value in (((i, i), uu), ((i + 2, i + 2), vv), ((i, i + 5), uw / hs), ((i + 5, i), uw / hs),
                               ((i + 5, i + 5), ww / hs**2)):
                extra[key] = extra.get(key, 0.0) + value
    modes = default_modes(scene) if modes is None else np.asarray(sorted(set(int(n) for n in modes)))
    out = np.empty((modes.size, count))
    vecs = {}
    for k, n in enumerate(modes):
        K, M = _assemble(scene, base_of, int(n), nodes)
        terms = dict(extra)
        if pole_held and n == 1:  # the pole slides on the tip: -F kappa_apex U^2 / pi (U = u(S0))
            terms[0, 0] = terms.get((0, 0), 0.0) - contact.pole_force * contact.apex_curvature / np.pi
        if terms:
            rows, cols = zip(*terms)
            K = K + scipy.sparse.csr_matrix((list(terms.values()), (rows, cols)), shape=K.shape)
        T = _constraints(int(n), nodes.size, end, nodes[0] / np.diff(nodes).max(), held, pole_held, lines)
        Kr, Mr = (T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr()
        Kr = ((Kr + Kr.T) / 2).tocsr()
        lam, X = _smallest(Kr, Mr, count)
        out[k] = lam
        if vectors:
            q = (T @ X[:, 0]).reshape(-1, 6)
            vecs[int(n)] = {"S": nodes, "u": q[:, 0], "v": q[:, 2], "w": q[:, 4]}
    return Stability(modes=modes, eigenvalues=out, elements=ne, S0=S0, vectors=vecs,
                     wall_time=time.perf_counter() - t0)


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
