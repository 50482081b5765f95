r"""The shell's energy for a general deformation, and its second variation by Fourier mode.

What is derived
---------------
The axisymmetric model (``symbolic.equations``) is the Euler-Lagrange system (xi = 1) of

.. math:: \Pi = 2\pi\int_0^L \big[U R\Psi + \tfrac{p}{2} r^2 z'\big]\,dS,\qquad
          U = W(\lambda_s, \lambda_\theta) + \beta B,

``U`` per reference area (``R Psi dS dtheta``), ``-p V`` the pressure's potential with the volume
``V = -pi Int r^2 z' dS`` (``equations.pressure_load``).  Here the same energy is written for a
mid-surface ``x(S, theta)`` that need not be axisymmetric, per ``dS dtheta``:

.. math:: L = \big[W(\operatorname{tr}C, \det C) + \beta B\big] R\Psi
          - p\,\tfrac12 (x, y, 0)\cdot(x_{,S}\times x_{,\theta}),

* metric: ``a_ab = x_,a . x_,b``, reference ``A = diag(Psi^2, R^2)``, ``C = A^{-1} a`` (its
  eigenvalues are ``lambda_s^2, lambda_theta^2`` on an axisymmetric state; incompressible:
  ``lambda_n^2 = 1/det C``).  The built-in energies are functions of
  ``I1 = tr C + 1/det C`` and ``I2 = tr C/det C + det C``.  A user ``W(lambda_s, lambda_theta)``
  is rewritten in ``(tr C, det C)`` by :func:`invariant_form`, or refused (``ValueError``).
* curvature: unit normal ``N = x_,S x x_,theta/|...|``, ``b_ab = x_,ab . N``, ``K = A^{-1} b``
  (eigenvalues ``lambda_s^2 kappa_s, lambda_theta^2 kappa_theta`` on an axisymmetric state, with
  ``N = (-sin phi, cos phi)`` in ``(e_r, e_z)``: the normal for which ``kappa_s = phi'/psi`` and
  ``kappa_theta = sin(phi)/r`` are the package's curvatures; the paper's ``n``, in which ``P``
  counts, is ``-N``).  Bending energies (``symbolic.bending``):

  - ``trace``: ``B = (tr K - kappa_s0 - kappa_theta0)^2/2``; a function of ``K`` alone, so its
    isotropic extension from the axisymmetric states is unique.  Like the axisymmetric model
    (``bending.plate_limit``) it has bending Poisson ratio 1: on a flat unstressed region
    ``B = (Laplacian w)^2/2``, and a harmonic deflection (``w = S^n cos(n theta)``) costs no
    bending energy (a test shows it); only tension or curvature resists such modes;
  - ``rotation``: ``B = (tr(C^{-1/2} K) - kappa_s0 - kappa_theta0)^2/2`` (``C^{1/2}`` the stretch
    tensor, by Cayley-Hamilton ``(C + sqrt(det C) I)/sqrt(tr C + 2 sqrt(det C))``).  It depends on
    ``C`` and ``K`` together, and the axisymmetric states (``C`` and ``K`` coaxial) do not fix
    how it depends on the angle between their principal axes: this is the simplest extension,
    not the only one;
  - ``koiter``: ``B = (tr Delta)^2/2 - (1 - nu) det Delta`` with nu = 1/2 and ``Delta = K - K0``
    the mixed tensor of the curvature change (``K0 = diag(kappa_s0, kappa_theta0)``, the reference
    shell's ``A^{-1} b0``): ``det Delta = (b_SS/A_SS - kappa_s0)(b_thth/A_thth - kappa_theta0) -
    b_Sth^2/(A_SS A_thth)``.  A function of ``K`` alone like ``trace``, so its isotropic extension
    from the axisymmetric states (where ``det Delta = Delta_s Delta_theta``) is unique too.  On
    a flat unstressed region ``B = (Laplacian w)^2/2 - (1 - nu) (w_xx w_yy - w_xy^2)``: a
    harmonic deflection now costs bending energy (a test shows it);
  - a user bending energy is refused (same reason as ``rotation``'s caveat: its axisymmetric form
    does not fix its 2D one).
* pressure: ``(x, y, 0)/2`` has divergence 1 and no flux through a horizontal plane; on an
  axisymmetric state the term is ``p r^2 z'/2``.  For non-axisymmetric fields it is the volume up
  to terms at the rim (item 2's boundary conditions).

Perturbation (``eta`` the amplitude)
------------------------------------
``x = x0 + eta [u(S) cos(n theta) t + v(S) sin(n theta) e_theta + w(S) cos(n theta) N]`` with
``t = (cos phi, sin phi)`` and ``N`` of the axisymmetric base state ``x0``.  ``L`` is expanded to
second order in ``eta`` as truncated series of every intermediate quantity (the metric and
``x_,S x x_,theta`` are exactly quadratic; square roots, quotients and ``W`` by Taylor), with
every first- and second-order coefficient kept as a vector and a symmetric matrix over the nine
amplitudes ``(u, u', u'', v, v', v'', w, w', w'')``.  By rotational invariance it suffices to
expand at ``theta = 0``; the theta-average of ``cos^2`` and ``sin^2`` is 1/2 and of
``cos sin`` is 0, so the average is half the sum of the expansions with (cos, sin) = (1, 0) and
(0, 1).  The result, :class:`SecondVariation`, holds

* ``matrix`` (9 x 9, symmetric): the theta-averaged ``eta^2`` coefficient of ``L`` is
  ``zeta^T matrix zeta`` (``zeta`` the nine amplitudes), for n >= 1.  At n = 0 the same polynomial
  is half the ``eta^2`` coefficient of the theta-independent fields ``(u, w)`` plus half that of
  a theta-independent ``v`` (torsion; with ``v sin(0)`` it would vanish): at n = 0, ``(u, w)``
  and ``v`` decouple (their coupling terms carry a factor n);
* ``first`` (9): the ``eta`` coefficient of ``L`` for n = 0 (fields independent of theta);
  its Euler-Lagrange expressions are the equilibrium equations (tests/test_second_variation.py).

So the ``eta^2`` term of the energy is ``2 pi Int zeta^T matrix zeta dS`` for n >= 1.  The
form has no ``u''^2`` or ``v''^2`` term: ``u''`` and ``v''`` enter only multiplied by lower
derivatives (through the normal's change in ``b_SS``, ``b_S theta``), so an integration by
parts leaves a form in ``(u, u', v, v', w, w', w'')``: Euler-Lagrange equations of order 2 in
u, v and 4 in w.

Coefficients are SymPy expressions in the base state's variables as the free region stores them,
``r, phi, lambda_s, kappa_s`` and their S-derivatives ``dls = lambda_s'``, ``dks = kappa_s'`` (the
free region's ``dls, dks``), the reference shell's ``R, Psi, Psi', kappa_s0, kappa_theta0`` at
the same S, ``beta``, the pressure and the material parameters, and ``n``.  (``z`` does not
enter; ``lambda_theta = r/R``, ``kappa_theta = sin(phi)/r``, ``psi = lambda_s Psi``.)

Cost: the series arithmetic keeps every coefficient as a shared SymPy DAG; deriving a
built-in material with either bending energy takes 0.6-1.7 s, and ``sympy.cse`` reduces the 81
entries to about 1400 operations (trace) or 2800 (rotation), so no disk cache is needed here.

A wall whose thickness varies (issue 58): the energy per reference area is
``t W + beta t^3 B`` with ``t(S) = H(S)/H(0)`` a given function of the reference coordinate, so
``L`` has ``t W + beta t^3 B`` in place of ``U`` and the form is the uniform wall's with its
membrane part times t and its bending part times t^3 (the perturbation does not move S: no
derivative of t enters).  Derived with one more symbol, :data:`THK` (``profiled=True``); the
uniform wall's expressions and generated code are those without it.

Only the xi = 1 model is an energy's: with xi = 0 the equilibrium equations are not the
Euler-Lagrange equations of Pi (``tests/test_variational.py``), and this second variation is
not theirs.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import sympy as sp
from sympy.polys.polyfuncs import symmetrize

from . import bending
from .equations import BETA, PRESSURE
from .materials import LS, LT

__all__ = ["TRC", "DETC", "BASE", "FIELDS", "N_MODE", "THK", "invariant_form", "membrane_energy",
           "bending_family", "surface_energy_density", "SecondVariation", "second_variation",
           "second_variation_of", "form_module_source", "FORM_UPPER"]

#: The invariants of C = A^{-1} a: tr C and det C.
TRC, DETC = sp.symbols("trC detC", positive=True)
#: The Fourier mode number.
N_MODE = sp.Symbol("n", integer=True, nonnegative=True)

# Base state (free region's variables) and reference shell at one S.
R_, LS_, RR, PSI_R = sp.symbols("r ls R Psi", positive=True)
PHI, KS_, DLS, DKS = sp.symbols("phi ks dls dks", real=True)
DPSI_R, KS0, KT0 = sp.symbols("dPsi kappa_s0 kappa_theta0", real=True)
#: The base-state symbols the coefficients are written in (besides beta, pressure, material params, n).
BASE = (R_, PHI, LS_, KS_, DLS, DKS, RR, PSI_R, DPSI_R, KS0, KT0)
#: The wall's thickness over the pole's at the point, t(S) (a profiled wall; after BASE in the arguments).
THK = sp.Symbol("thk", positive=True)
#: The nine amplitudes (u, u', u'', v, v', v'', w, w', w'').
FIELDS = sp.symbols("u du ddu v dv ddv w dw ddw", real=True)


# ------------------------------------------------------------------------------ membrane energy
class InvariantFormError(ValueError):
    pass


def invariant_form(W, ls=LS, lt=LT, name="W"):
    r"""``W(lambda_s, lambda_theta)`` rewritten in ``TRC = tr C`` and ``DETC = det C``.

    With ``x = lambda_s^2, y = lambda_theta^2`` (the eigenvalues of C), W is taken apart into its
    rational parts in x, y and the arguments of the functions and non-integer powers around them;
    each must be a symmetric rational function, which SymPy's ``symmetrize`` writes in
    ``x + y = tr C`` and ``x y = det C``.  So polynomials and quotients of the squared stretches,
    of ``lambda_s lambda_theta = sqrt(det C)``, and functions (log, exp, powers) of such
    symmetric expressions are accepted.  Refused (``ValueError``): a W that is not symmetric, or
    whose symmetry appears only between different terms of a transcendental part, e.g. Ogden's
    ``lambda_s^a + lambda_theta^a`` with a non-even a (a function of the eigenvalues that is not a
    smooth expression in tr C and det C at equal stretches).  The result is checked against W at
    a few stretches.
    """
    W = sp.sympify(W, strict=True)
    x, y = sp.symbols("x_ y_")  # no sign assumed: sqrt(x) sqrt(y) stays sqrt(x y) once combined
    e = sp.powsimp(W.xreplace({ls: sp.sqrt(x), lt: sp.sqrt(y)}), combine="base", force=True, deep=True)

    def refuse(part):
        raise InvariantFormError(
            f"{name} cannot be written through the invariants tr C = lambda_s^2 + lambda_theta^2 and "
            f"det C = lambda_s^2 lambda_theta^2 of the surface metric: its part "
            f"{part.xreplace({x: ls**2, y: lt**2})} is not a symmetric rational function of lambda_s^2 and "
            f"lambda_theta^2 (each rational part of W, and each argument of a function or a non-integer "
            f"power in it, is rewritten on its own).  The second variation needs W "
            f"as a smooth function of the metric; write W through I1, I2 or the invariants.")

    def rational(part):
        num, den = sp.fraction(sp.cancel(sp.together(part)))
        swapped = den.xreplace({x: y, y: x})
        if sp.expand(swapped + den) == 0:  # antisymmetric denominator: multiply through by x - y
            num, den = sp.expand(num * (x - y)), sp.expand(den * (x - y))
        out = []
        for p in (num, den):
            sym, rem, defs = symmetrize(sp.expand(p), x, y, formal=True)
            if rem != 0:
                refuse(part)
            out.append(sym.xreplace({s: (TRC if v == x + y else DETC) for s, v in defs}))
        return out[0] / out[1]

    def rewrite(part):
        if not part.has(x, y):
            return part
        if part.is_rational_function(x, y):
            return rational(part)
        if part.is_Add or part.is_Mul:
            rat = [a for a in part.args if a.is_rational_function(x, y)]
            rest = [rewrite(a) for a in part.args if not a.is_rational_function(x, y)]
            head = rational(part.func(*rat)) if rat else part.func.identity
            return part.func(head, *rest)
        try:
            if part.is_Pow and not part.exp.has(x, y):
                return rewrite(part.base) ** part.exp
            if isinstance(part, sp.Function):
                return part.func(*[rewrite(a) for a in part.args])
        except InvariantFormError:
            pass
        refuse(part)  # the whole power or function: the message names what the user wrote

    try:
        out = rewrite(e)
    except InvariantFormError as first:  # log(x) + log(y) is log(x y): one more chance, logs combined
        try:
            out = rewrite(sp.powsimp(sp.logcombine(e, force=True), combine="base", force=True, deep=True))
        except InvariantFormError:
            raise first from None
    # check: at a few stretches the rewrite is W
    others = {q: sp.Float(7.3 + i, 30) for i, q in enumerate(sorted(W.free_symbols - {ls, lt}, key=str))}
    for a, b in ((1.3, 0.8), (0.7, 1.6), (1.1, 1.1), (2.1, 0.9)):
        at = {ls: sp.Float(a, 30), lt: sp.Float(b, 30), **others}
        want = complex(W.evalf(30, subs=at))
        got = complex(out.evalf(30, subs={TRC: at[ls] ** 2 + at[lt] ** 2, DETC: at[ls] ** 2 * at[lt] ** 2, **others}))
        if abs(want - got) > 1e-20 * max(1.0, abs(want)):
            refuse(W)
    return out


def membrane_energy(W):
    """The strain energy W(lambda_s, lambda_theta) as a function of (TRC, DETC) (cached by W)."""
    return _membrane_energy(sp.sympify(W, strict=True))


@functools.lru_cache(maxsize=None)
def _membrane_energy(W):
    return invariant_form(W)


def bending_family(B):
    """``"trace"``, ``"rotation"`` or ``"koiter"`` for a structure's bending energy (None: the
    paper's trace); ValueError for any other."""
    if B is None or sp.expand(B - bending.trace_bending()) == 0:
        return "trace"
    if sp.expand(B - bending.rotation_bending()) == 0:
        return "rotation"
    if sp.expand(B - bending.koiter_bending()) == 0:
        return "koiter"
    raise ValueError(
        "the two-dimensional form of a user bending energy is not determined by its axisymmetric "
        "form (it fixes B only where the stretch and curvature tensors are coaxial); the second "
        "variation is derived for the trace, rotation and koiter bending energies only")


# ------------------------------------------------------------------------------ truncated series
class Series:
    """``c0 + eta c1 . zeta + eta^2 zeta^T c2 zeta``: c1 a column, c2 a symmetric matrix over the
    amplitudes zeta."""

    __slots__ = ("c0", "c1", "c2")

    def __init__(self, c0, c1, c2):
        self.c0, self.c1, self.c2 = c0, c1, c2

    @staticmethod
    def const(c0, k):
        return Series(sp.sympify(c0, strict=True), sp.zeros(k, 1), sp.zeros(k, k))

    def _lift(self, other):
        return other if isinstance(other, Series) else Series.const(other, self.c1.rows)

    def __add__(self, other):
        o = self._lift(other)
        return Series(self.c0 + o.c0, self.c1 + o.c1, self.c2 + o.c2)

    __radd__ = __add__

    def __neg__(self):
        return Series(-self.c0, -self.c1, -self.c2)

    def __sub__(self, other):
        return self + (-self._lift(other))

    def __rsub__(self, other):
        return self._lift(other) - self

    def __mul__(self, other):
        if not isinstance(other, Series):
            return Series(self.c0 * other, self.c1 * other, self.c2 * other)
        outer = self.c1 * other.c1.T
        return Series(self.c0 * other.c0, self.c0 * other.c1 + other.c0 * self.c1,
                      self.c0 * other.c2 + other.c0 * self.c2 + (outer + outer.T) / 2)

    __rmul__ = __mul__

    def __truediv__(self, other):
        if not isinstance(other, Series):
            return self * (1 / sp.sympify(other, strict=True))
        return self * apply(lambda s: 1 / s, other)

    def __rtruediv__(self, other):
        return self._lift(other) / self

    def __pow__(self, k):
        if k != 2:
            raise NotImplementedError
        return self * self


def _clean(c0):
    """The base value before a function is applied to it (small: trig identities, roots of squares)."""
    return sp.factor(sp.trigsimp(sp.expand(c0)))


def apply(f, s):
    """f(s) for a series s and a function f of one SymPy argument (Taylor to second order)."""
    if not isinstance(s, Series):
        return f(s)
    y = sp.Dummy("y")
    fy = f(y)
    a0 = _clean(s.c0)
    f0 = fy.subs(y, a0)
    f1 = sp.diff(fy, y).subs(y, a0)
    f2 = sp.diff(fy, y, 2).subs(y, a0)
    return Series(f0, f1 * s.c1, f1 * s.c2 + f2 / 2 * (s.c1 * s.c1.T))


def apply2(F, t, d):
    """F(t, d) for series t, d and an expression F in TRC, DETC (Taylor to second order)."""
    if not isinstance(t, Series):
        return F.xreplace({TRC: t, DETC: d})
    at = {TRC: _clean(t.c0), DETC: _clean(d.c0)}
    g = [sp.diff(F, v) for v in (TRC, DETC)]
    H = [[sp.diff(gi, v) for v in (TRC, DETC)] for gi in g]
    g = [gi.xreplace(at) for gi in g]
    H = [[h.xreplace(at) for h in row] for row in H]
    s1 = (t.c1, d.c1)
    c1 = g[0] * t.c1 + g[1] * d.c1
    c2 = g[0] * t.c2 + g[1] * d.c2
    for i in range(2):
        for j in range(2):
            c2 += H[i][j] / 2 * (s1[i] * s1[j].T)
    return Series(F.xreplace(at), c1, c2)


def _sqrt(s):
    return apply(sp.sqrt, s)


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


# ------------------------------------------------------------------------------ the 2D energy
def surface_energy_density(jets, reference, Wi, family, beta=BETA, pressure=PRESSURE, thickness=None):
    """``L`` per ``dS dtheta`` (module docstring) from the jets of the mid-surface.

    ``jets``: dict of 3-vectors (lists) ``x, xS, xT, xSS, xST, xTT`` (T for theta), entries SymPy
    expressions or :class:`Series`; ``reference``: dict ``R, Psi, kappa_s0, kappa_theta0``;
    ``Wi``: W in (TRC, DETC); ``family``: "trace", "rotation" or "koiter"; ``thickness``: the wall's
    thickness over the pole's at the point (None: uniform), ``t W + beta t^3 B``.
    """
    R, Psi = reference["R"], reference["Psi"]
    xS, xT = jets["xS"], jets["xT"]
    aSS, aST, aTT = _dot(xS, xS), _dot(xS, xT), _dot(xT, xT)
    A1, A2 = Psi**2, R**2
    trC = aSS / A1 + aTT / A2
    detC = (aSS * aTT - aST * aST) / (A1 * A2)
    m = _cross(xS, xT)
    inv_norm = apply(lambda g: 1 / sp.sqrt(g), _dot(m, m))
    bSS, bST, bTT = (_dot(jets[k], m) * inv_norm for k in ("xSS", "xST", "xTT"))
    trK = bSS / A1 + bTT / A2
    ks0, kt0 = reference["kappa_s0"], reference["kappa_theta0"]
    if family in ("trace", "koiter"):
        strain = trK
    elif family == "rotation":
        # tr(C^{-1/2} K) = (trU trK - (tr(CK) + sqrt(det C) trK)/trU)/sqrt(det C), U = C^{1/2}
        J = _sqrt(detC)
        trU = _sqrt(trC + 2 * J)
        trCK = aSS * bSS / A1**2 + 2 * aST * bST / (A1 * A2) + aTT * bTT / A2**2
        strain = (trU * trK - (trCK + J * trK) / trU) / J
    else:
        raise ValueError(f"unknown bending family {family!r}")
    bend = (strain - ks0 - kt0) ** 2 * sp.Rational(1, 2)
    if family == "koiter":  # less (1 - nu) det(K - K0), K = A^{-1} b (mixed), K0 = diag(ks0, kt0)
        det_change = (bSS / A1 - ks0) * (bTT / A2 - kt0) - bST * bST / (A1 * A2)
        bend = bend - (1 - bending.KOITER_POISSON) * det_change
    if thickness is None:
        U = apply2(Wi, trC, detC) + beta * bend
    else:
        U = thickness * apply2(Wi, trC, detC) + beta * thickness**3 * bend
    x = jets["x"]
    volume = _dot([x[0] / 2, x[1] / 2, 0], m)
    return U * (R * Psi) - pressure * volume


# ------------------------------------------------------------------------------ the perturbation
def _jets(parity):
    """Jets at theta = 0 of x0 + eta dx as Series over FIELDS, for (cos, sin) = parity.

    Base: ``x0_S = psi t``, ``x0_theta = r e_theta``; ``phi' = psi kappa_s``,
    ``psi' = lambda_s' Psi + lambda_s Psi'``, ``phi'' = psi' kappa_s + psi kappa_s'``.
    """
    S, th = sp.symbols("S_ theta_", real=True)
    phi, psi = sp.Function("phi")(S), sp.Function("psi")(S)
    er = sp.Matrix([sp.cos(th), sp.sin(th), 0])
    eth = sp.Matrix([-sp.sin(th), sp.cos(th), 0])
    ez = sp.Matrix([0, 0, 1])
    t = sp.cos(phi) * er + sp.sin(phi) * ez
    N = -sp.sin(phi) * er + sp.cos(phi) * ez
    F = {k: sp.Function(k)(S, th) for k in ("U", "V", "W")}
    dx = F["U"] * t + F["V"] * eth + F["W"] * N
    base_x = R_ * er  # z e_z does not enter L
    base_S = psi * t
    base_T = R_ * eth
    derivs = {
        "x": (base_x, dx), "xS": (base_S, dx.diff(S)), "xT": (base_T, dx.diff(th)),
        "xSS": (base_S.diff(S), dx.diff(S, 2)), "xST": (base_S.diff(th), dx.diff(S, th)),
        "xTT": (base_T.diff(th), dx.diff(th, 2)),
    }
    # amplitudes: U = u c, V = v s, W = w c with c = cos(n theta), s = sin(n theta) at theta = 0
    # after rotation, i.e. theta-derivatives bring n and swap the parities.
    c, s = parity
    n = N_MODE
    u, du, ddu, v, dv, ddv, w, dw, ddw = FIELDS
    amp = {}
    for name, (a, da, dda), (even, odd) in (("U", (u, du, ddu), (c, -s)), ("W", (w, dw, ddw), (c, -s)),
                                            ("V", (v, dv, ddv), (s, c))):
        f = F[name]
        amp[f] = even * a
        amp[f.diff(S)] = even * da
        amp[f.diff(S, 2)] = even * dda
        amp[f.diff(th)] = odd * n * a
        amp[f.diff(S, th)] = odd * n * da
        amp[f.diff(th, 2)] = -n**2 * even * a
    dpsi = DLS * PSI_R + LS_ * DPSI_R
    base_sub = {sp.Derivative(phi, (S, 2)): dpsi * KS_ + LS_ * PSI_R * DKS,
                sp.Derivative(phi, S): LS_ * PSI_R * KS_, sp.Derivative(psi, S): dpsi}
    jets = {}
    k = len(FIELDS)
    for key, (b, d) in derivs.items():
        vec = []
        for bi, di in zip(b, d):
            b0 = bi.subs(base_sub).subs({phi: PHI, psi: LS_ * PSI_R}).subs(th, 0)
            d0 = sp.expand(di.xreplace(amp).subs(base_sub).subs({phi: PHI, psi: LS_ * PSI_R}).subs(th, 0))
            lin = sp.Matrix([d0.coeff(z) for z in FIELDS])
            if sp.expand(d0 - sum(lin[i] * FIELDS[i] for i in range(k))) != 0:
                raise AssertionError(f"perturbation of {key} is not linear in the amplitudes")
            vec.append(Series(b0, lin, sp.zeros(k, k)))
        jets[key] = vec
    return jets


REFERENCE = {"R": RR, "Psi": PSI_R, "kappa_s0": KS0, "kappa_theta0": KT0}


@dataclass(frozen=True)
class SecondVariation:
    """The quadratic form of mode n (module docstring): ``zeta^T matrix zeta`` with zeta = FIELDS.

    ``energy``: the base energy per dS dtheta (the axisymmetric L); ``first``: the eta
    coefficient for n = 0; ``params``: (beta, pressure, *material params); ``seconds``: the
    derivation's wall time; ``base``: the point's symbols the coefficients are written in,
    :data:`BASE` and, for a profiled wall, :data:`THK`.
    """

    matrix: sp.Matrix
    first: sp.Matrix
    energy: sp.Expr
    W: sp.Expr
    family: str
    params: tuple
    seconds: float
    base: tuple = BASE

    def quadratic_form(self):
        z = sp.Matrix(FIELDS)
        return (z.T * self.matrix * z)[0, 0]


def second_variation(W, material_params=(), B=None, pressurised=False, profiled=False) -> SecondVariation:
    """Derive the second variation of mode n for a strain energy W(lambda_s, lambda_theta)
    and a bending energy B (None or ``bending.trace_bending()``: trace; ``rotation_bending()``,
    ``koiter_bending()``);
    ``profiled``: a wall whose thickness varies, ``t W + beta t^3 B`` with t = :data:`THK`.
    ValueError for a W not expressible through (tr C, det C) or another B.  Cached in-process."""
    W = sp.sympify(W, strict=True)
    family = bending_family(B)
    return _second_variation(W, tuple(material_params), family, bool(pressurised), bool(profiled))


def second_variation_of(structure) -> SecondVariation:
    """:func:`second_variation` of an ``equations.Structure`` (its W, B and pressure); ValueError
    for xi = 0, whose equations are not the Euler-Lagrange equations of an energy."""
    if structure.xi != 1:
        raise ValueError("the second variation is that of the energy, whose equilibrium equations are the "
                         "xi = 1 model's; with xi = 0 they are not Euler-Lagrange equations of any energy here")
    return second_variation(structure.W, structure.material_params, structure.B, structure.pressurised,
                            structure.thickness is not None)


@functools.lru_cache(maxsize=None)
def _second_variation(W, material_params, family, pressurised, profiled=False):
    t0 = time.perf_counter()
    Wi = membrane_energy(W)
    p = PRESSURE if pressurised else sp.S.Zero
    out = []
    for parity in ((1, 0), (0, 1)):
        L = surface_energy_density(_jets(parity), REFERENCE, Wi, family, pressure=p,
                                   thickness=THK if profiled else None)
        out.append(L)
    Lc, Ls = out
    matrix = (Lc.c2 + Ls.c2) / 2
    first = Lc.c1.subs(N_MODE, 0)
    params = (BETA,) + ((PRESSURE,) if pressurised else ()) + material_params
    return SecondVariation(matrix=matrix, first=first, energy=Lc.c0, W=Wi, family=family, params=params,
                           seconds=time.perf_counter() - t0, base=BASE + ((THK,) if profiled else ()))


#: The upper triangle of the 9 x 9 form, in the order the generated ``form`` returns it
FORM_UPPER = tuple((i, j) for i in range(9) for j in range(i, 9))


def form_module_source(structure, description: str) -> str:
    """Text of the generated numpy module of a structure's second variation.

    It holds ``form(r, phi, ls, ks, dls, dks, R, Psi, dPsi, kappa_s0, kappa_theta0, *PARAMS, n)``,
    the 45 entries of the form's upper triangle (:data:`FORM_UPPER`) at the points given, and
    ``reference(S, *SHELL_PARAMS)``, the reference shell's ``R, Psi, Psi', kappa_s0,
    kappa_theta0``; ``description`` is hashed into the module's ``KEY`` (``codegen.header``).
    A profiled wall's module (``PROFILED = True``; a uniform wall's has no such name) takes
    ``thk`` after ``kappa_theta0`` in ``form`` and holds ``thickness(S, *SHELL_PARAMS)``, the
    structure's t(S).  Deterministic: the same structure gives the same text.
    """
    from .codegen import Printer, header
    from .geometry import S as S_SYM

    res = second_variation_of(structure)
    key, comments = header("second_variation.py", description)
    printer = Printer()
    shell = structure.shell
    ks0, kt0 = shell.curvatures()
    params = [str(p) for p in res.params]
    shell_params = [str(p) for p in shell.params]

    def function(name, args, exprs, doc):
        temps, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols("t"), optimizations="basic")
        lines = [f"def {name}({', '.join(args)}):", f'    """{doc}"""']
        lines += [f"    {t} = {printer.doprint(e)}" for t, e in temps]
        lines.append("    return [" + ", ".join(printer.doprint(e) for e in reduced) + "]")
        return "\n".join(lines)

    form = function("form", [str(b) for b in res.base] + params + [str(N_MODE)],
                    [res.matrix[i, j] for i, j in FORM_UPPER],
                    "The 45 entries of the form's upper triangle (UPPER) at the points given.")
    ref = function("reference", [str(S_SYM)] + shell_params,
                   [shell.R, shell.Psi, sp.diff(shell.Psi, S_SYM), ks0, kt0],
                   "The reference shell's R, Psi, Psi', kappa_s0, kappa_theta0 at S.")
    head = [*comments, '"""Generated second variation of one shellbvp structure (see the header)."""',
            "import numpy", "", f"KEY = {key!r}", f"PARAMS = {tuple(params)!r}",
            f"SHELL_PARAMS = {tuple(shell_params)!r}", f"UPPER = {FORM_UPPER!r}", ""]
    if structure.thickness is None:
        return "\n".join(head) + "\n" + form + "\n\n\n" + ref + "\n"
    thk = function("thickness", [str(S_SYM)] + shell_params, [structure.thickness],
                   "The wall's thickness over the pole's, t(S) (a list of one).")
    head.insert(-1, "PROFILED = True")
    return "\n".join(head) + "\n" + form + "\n\n\n" + ref + "\n\n\n" + thk + "\n"
