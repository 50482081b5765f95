r"""Bending energies: the part of U = W + beta B that depends on curvature.

``B(lambda_s, lambda_theta, kappa_s, kappa_theta; kappa_s0, kappa_theta0)`` per unit
reference area and per unit beta (kappa_*0: the reference shell's curvatures).  The
moments ``M = h dU/dkappa`` (h = 1/(lambda_s lambda_theta)) and every equation follow by
differentiation (``symbolic.equations``).

Built in:

* ``trace`` (the paper's): ``B = (tr Delta)^2/2``,
  ``tr Delta = lambda_s^2 kappa_s + lambda_theta^2 kappa_theta - kappa_s0 - kappa_theta0``.
  In the kinematic variables of the free region, ``psi = lambda_s Psi`` and
  ``phi' = kappa_s psi``, ``lambda_s^2 kappa_s = psi phi'/Psi^2`` is bilinear, so U is not
  convex in (psi, phi') at large bending: the Legendre condition fails (issue 13).
* ``rotation``: ``B = (lambda_s kappa_s + lambda_theta kappa_theta - kappa_s0 - kappa_theta0)^2/2``,
  the square of the change of the rotation gradients, ``lambda_s kappa_s = phi'/Psi`` and
  ``lambda_theta kappa_theta = sin(phi)/R`` per unit *reference* length: the bending strains of
  the axisymmetric shell theories built on the rotation angle (Libai & Simmonds, *The Nonlinear
  Theory of Elastic Shells*, 2nd ed. 1998, ch. 5; for a rod, Antman, *Nonlinear Problems of
  Elasticity*, 2005, ch. 4: moment proportional to the change of phi').  Independent of psi, so
  U is convex in (psi, phi') wherever W is convex in lambda_s: the Legendre condition never
  fails through bending.  Same small-strain stiffness as ``trace`` (both give d^2B/dkappa_s^2 = 1
  at the reference state).
* ``koiter``: ``B = (Delta_s + Delta_theta)^2/2 - (1 - nu) Delta_s Delta_theta`` with
  ``nu = 1/2``, ``Delta_s = lambda_s^2 kappa_s - kappa_s0``, ``Delta_theta = lambda_theta^2
  kappa_theta - kappa_theta0`` (the eigenvalues of the trace energy's curvature change):
  Koiter's bending energy ``nu (tr Delta)^2/2 + (1 - nu) tr(Delta^2)/2`` (W. T. Koiter, On the
  nonlinear theory of thin elastic shells, Proc. Kon. Ned. Akad. Wetensch. B 69, 1966, 1-54),
  ``Delta`` his bending strain ``A^{-1}(b - b_0)``, at the Poisson ratio of an incompressible
  solid.  For a flat plate it is Kirchhoff's ``(k1 + k2)^2/2 - (1 - nu) k1 k2``: the trace
  energy is the same at nu = 1, with no energy in the Gaussian curvature.  Same stiffness 1, so
  ``beta = eps^2/3`` stays; ``plate_limit`` gives ``(1, 1/2)``, the 3D plate's
  (:func:`plate_3d`).  Like ``trace``, bilinear in (psi, phi'): not convex at large bending.
"""

from __future__ import annotations

import sympy as sp

from .materials import FLOAT_ZERO, LS, LT

__all__ = ["KS", "KT", "KS0", "KT0", "BENDING_SYMBOLS", "trace_bending", "rotation_bending", "koiter_bending",
           "KOITER_POISSON", "check_bending",
           "legendre_determinant", "plate_limit", "plate_3d"]

KS, KT = sp.symbols("kappa_s kappa_theta", real=True)
KS0, KT0 = sp.symbols("kappa_s0 kappa_theta0", real=True)
#: The names a user bending energy may use.
BENDING_SYMBOLS = {"lambda_s": LS, "lambda_theta": LT, "kappa_s": KS, "kappa_theta": KT, "kappa_s0": KS0,
                   "kappa_theta0": KT0}


def trace_bending():
    return (LS**2 * KS + LT**2 * KT - KS0 - KT0) ** 2 / 2


def rotation_bending():
    return (LS * KS + LT * KT - KS0 - KT0) ** 2 / 2


#: The Poisson ratio of :func:`koiter_bending`: the 3D incompressible plate's (``plate_3d``)
KOITER_POISSON = sp.Rational(1, 2)


def koiter_bending():
    """Koiter's bending energy at Poisson ratio 1/2 (module docstring): the trace energy less
    ``(1 - nu) Delta_s Delta_theta``, the energy of the change of Gaussian curvature."""
    ds, dt = LS**2 * KS - KS0, LT**2 * KT - KT0
    return (ds + dt) ** 2 / 2 - (1 - KOITER_POISSON) * ds * dt


def _zero(e) -> bool:
    e = sp.simplify(e)
    if e == 0:
        return True
    if not e.has(sp.Float):
        return False
    for point in ((0.3, -0.2), (1.1, 0.7), (-2.0, 0.4)):
        value = complex(e.subs({KS0: point[0], KT0: point[1]}).evalf(30))
        if abs(value) > FLOAT_ZERO:
            return False
    return True


def check_bending(B, name="B"):
    """Validate a bending energy; return its bending stiffness d^2B/dkappa_s^2 at rest (1 for the built-ins).

    ValueError unless ``B`` uses only the stretches, curvatures and reference curvatures, and
    vanishes, is moment-free and has positive stiffness in the reference state
    (lambda = 1, kappa = kappa_0) for any reference curvatures.
    """
    B = sp.sympify(B, strict=True)  # an expression already: text goes through formula.parse_formula
    extra = B.free_symbols - set(BENDING_SYMBOLS.values())
    if extra:
        raise ValueError(f"{name} must be an expression in {', '.join(BENDING_SYMBOLS)}; it also contains "
                         f"{sorted(map(str, extra))}")
    if not B.has(KS):
        raise ValueError(f"{name} must depend on kappa_s")
    rest = {LS: 1, LT: 1, KS: KS0, KT: KT0}
    if not _zero(B.subs(rest)):
        raise ValueError(f"{name} must vanish in the reference state (lambda = 1, kappa = kappa_0); "
                         f"it is {sp.simplify(B.subs(rest))}")
    for k in (KS, KT):
        if not _zero(sp.diff(B, k).subs(rest)):
            raise ValueError(f"{name} must be moment-free in the reference state: d{name}/d{k} = "
                             f"{sp.simplify(sp.diff(B, k).subs(rest))} there, expected 0")
    stiffness = sp.simplify(sp.diff(B, KS, 2).subs(rest))
    probe = stiffness.subs({KS0: 0.37, KT0: -0.21}) if stiffness.free_symbols else stiffness
    if not (probe.is_number and float(probe) > 0):
        raise ValueError(f"{name} must have a positive bending stiffness d2{name}/dkappa_s2 at rest; got {stiffness}")
    return stiffness


def legendre_determinant(W, B, beta=sp.Symbol("beta", positive=True)):
    """det of the Hessian of U = W + beta B in the free region's velocities (psi, phi'), per Psi^4,
    written in (lambda_s, lambda_theta, kappa_s, kappa_theta): > 0 where U is convex in them (the
    Legendre condition; same sign as det d(tau_s, M_s)/d(lambda_s, kappa_s))."""
    psi, dphi, Psi = sp.symbols("psi dphi Psi", positive=True)
    U = (W + beta * B).xreplace({LS: psi / Psi, KS: dphi / psi})
    H = sp.hessian(U, (psi, dphi))
    det = (H[0, 0] * H[1, 1] - H[0, 1] ** 2) * Psi**4
    return sp.simplify(det.xreplace({psi: LS * Psi, dphi: KS * LS * Psi}))


def plate_3d():
    """The bending of a 3D plate of an incompressible isotropic solid, per ``mu H^3`` and with its
    Poisson ratio: ``D = E H^3 / (12 (1 - nu^2))`` with ``E = 2 (1 + nu) mu``, ``nu = 1/2``, i.e.
    ``(1/3, 1/2)``.  Its energy per area is ``D/2 (kappa_s^2 + kappa_theta^2 + 2 nu kappa_s kappa_theta)``."""
    nu, mu, H = sp.Rational(1, 2), sp.Symbol("mu", positive=True), sp.Symbol("H", positive=True)
    D = 2 * (1 + nu) * mu * H**3 / (12 * (1 - nu**2))
    return sp.simplify(D / (mu * H**3)), nu


def plate_limit(B):
    """The small-strain plate limit of a bending energy: ``(stiffness, poisson)`` with
    ``B ~ stiffness/2 (kappa_s^2 + kappa_theta^2 + 2 poisson kappa_s kappa_theta)`` at
    ``lambda = 1`` on a flat reference (``kappa_0 = 0``).

    Against :func:`plate_3d` the shell model with ``U = W + beta B`` (energy per ``mu H``) bends as
    a 3D plate of thickness ``eps = H/R_L`` when ``beta * stiffness = eps^2 * D/(mu H^3)``, i.e.
    ``beta = eps^2 / (3 stiffness)``: ``eps^2/3`` for the trace and rotation energies (both
    ``(1, 1)``: their bending Poisson ratio is 1, the plate's 1/2, which matters where the
    Gaussian curvature's energy does: at a free or simply supported edge, and where the wall's
    thickness varies) and for the koiter energy (``(1, 1/2)``, the plate's).
    """
    flat = {LS: 1, LT: 1, KS0: 0, KT0: 0}
    B = sp.sympify(B, strict=True).subs(flat)  # an expression already, never text
    at_rest = {KS: 0, KT: 0}
    ss = sp.simplify(sp.diff(B, KS, 2).subs(at_rest))
    st = sp.simplify(sp.diff(B, KS, KT).subs(at_rest))
    tt = sp.simplify(sp.diff(B, KT, 2).subs(at_rest))
    if sp.simplify(ss - tt) != 0:
        raise ValueError(f"B's plate limit is not isotropic: d2B/dkappa_s2 = {ss}, d2B/dkappa_theta2 = {tt}")
    return ss, sp.simplify(st / ss)
