r"""Reference shells and indenter tips as SymPy expressions.

Shell: meridian ``R(S), Z(S)`` on ``0 <= S <= L`` with ``R(0) = 0, Z'(0) = 0``,
scaled so that ``R(L) = 1, Z(L) = 0`` (lengths in units of the rim radius).
Tip: ``r = rho A(omega), z = z_tip + rho B(omega)`` with ``A(0) = B(0) = B'(0) = 0``.

The curvature conventions are the paper's (eq. curvatures):
``kappa_s = (R'Z'' - Z'R'')/Psi^3``, ``kappa_theta = Z'/(R Psi)``; the tip's
are its geometric curvatures (SPEC section 2 corrects the paper's division by
omega'), so they do not depend on how the shell is stretched over the tip.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .formula import parse_formula
from .spline import natural_spline_coefficients

__all__ = ["S", "OMEGA", "GAMMA", "ShellGeometry", "TipGeometry", "spheroid", "user_shell",
           "sphere_tip", "flat_tip", "user_tip"]

S = sp.Symbol("S", positive=True)
OMEGA = sp.Symbol("omega", positive=True)
GAMMA = sp.Symbol("gamma", real=True)


@dataclass(frozen=True)
class ShellGeometry:
    """Reference meridian; ``params`` are run-time symbols (e.g. gamma)."""

    R: sp.Expr
    Z: sp.Expr
    L: sp.Expr
    params: tuple = ()

    @property
    def Psi(self):
        return sp.sqrt(sp.diff(self.R, S) ** 2 + sp.diff(self.Z, S) ** 2)

    def curvatures(self, simplify: bool = True):
        """(kappa_s^R, kappa_theta^R) as expressions in S; ``simplify=False`` leaves them as
        derived (the same values, for checks that evaluate them: simplifying costs seconds)."""
        Rp, Zp = sp.diff(self.R, S), sp.diff(self.Z, S)
        Rpp, Zpp = sp.diff(Rp, S), sp.diff(Zp, S)
        Psi = self.Psi
        ks, kt = (Rp * Zpp - Zp * Rpp) / Psi**3, Zp / (self.R * Psi)
        return (sp.simplify(ks), sp.simplify(kt)) if simplify else (ks, kt)


@dataclass(frozen=True)
class TipGeometry:
    """Indenter tip profile in units of its radius rho.

    ``phi`` is the tip's tangent angle, ``tan(phi) = B'/A'``; for the sphere
    it is omega itself (checked in the tests), otherwise ``atan2(B', A')``.
    """

    A: sp.Expr
    B: sp.Expr
    phi: sp.Expr
    omega_max: sp.Expr | None = None  # where A' first vanishes: the tip meets its cylinder (None: never)

    def derived(self):
        """Dict of tip expressions in omega: A, B, dA, dB, G=|(A',B')|,
        kappa_s*rho, kappa_theta*rho, sin(phi), cos(phi)."""
        dA, dB = sp.diff(self.A, OMEGA), sp.diff(self.B, OMEGA)
        ddA, ddB = sp.diff(dA, OMEGA), sp.diff(dB, OMEGA)
        G = sp.simplify(sp.sqrt(dA**2 + dB**2))
        return {
            "A": self.A,
            "B": self.B,
            "dA": dA,
            "dB": dB,
            "G": G,
            "rho_ks": sp.simplify((dA * ddB - dB * ddA) / G**3),
            "rho_kt": sp.simplify(dB / (self.A * G)),
            "sin_phi": sp.simplify(dB / G),
            "cos_phi": sp.simplify(dA / G),
            "phi": self.phi,
        }


def spheroid() -> ShellGeometry:
    """``R = sin S``, ``Z = -gamma cos S``, ``L = pi/2`` (gamma > 0: bowl, < 0: dome)."""
    return ShellGeometry(R=sp.sin(S), Z=-GAMMA * sp.cos(S), L=sp.pi / 2, params=(GAMMA,))


def user_shell(R, Z, L, *, legacy_srepr: bool = False) -> ShellGeometry:
    """Any smooth meridian with ``R(0) = 0``, ``Z'(0) = 0``, ``R > 0`` on (0, L].

    Formulas are text (or SymPy expressions) read by ``formula.parse_formula``.
    Rescaled so that ``R(L) = 1`` and ``Z(L) = 0``.
    """
    R = parse_formula(R, {"S": S}, name="R(S)", legacy_srepr=legacy_srepr)
    Z = parse_formula(Z, {"S": S}, name="Z(S)", legacy_srepr=legacy_srepr)
    exact = isinstance(L, sp.Basic)
    L = parse_formula(L, {}, name="L", legacy_srepr=legacy_srepr)
    L = L if exact else sp.nsimplify(L)
    if not (L.is_number and L.is_extended_real and float(L) > 0):
        raise ValueError(f"L must be a positive number; got {L}")
    if sp.simplify(R.subs(S, 0)) != 0:
        raise ValueError(f"R(0) must be 0 (the pole is on the axis); got {R.subs(S, 0)}")
    if sp.simplify(sp.diff(Z, S).subs(S, 0)) != 0:
        raise ValueError("Z'(0) must be 0 (smooth pole)")
    RL = R.subs(S, L)
    if not (RL.is_number and float(RL) > 0):
        raise ValueError(f"R(L) must be positive; got {RL}")
    return ShellGeometry(R=sp.simplify(R / RL), Z=sp.simplify((Z - Z.subs(S, L)) / RL), L=L)


def sphere_tip() -> TipGeometry:
    """Sphere of radius rho: ``A = sin omega``, ``B = 1 - cos omega``, phi = omega."""
    return TipGeometry(A=sp.sin(OMEGA), B=1 - sp.cos(OMEGA), phi=OMEGA, omega_max=sp.pi / 2)


def flat_tip() -> TipGeometry:
    """A flat plate: ``A = omega``, ``B = 0``, phi = 0; it has no end (no cylinder)."""
    return TipGeometry(A=OMEGA, B=sp.S.Zero, phi=sp.S.Zero, omega_max=None)


def user_tip(A, B, *, legacy_srepr: bool = False) -> TipGeometry:
    """Any smooth tip with ``A(0) = 0``, ``B(0) = 0``, ``B'(0) = 0``, ``A'(0) > 0``."""
    A = parse_formula(A, {"omega": OMEGA}, name="A(omega)", legacy_srepr=legacy_srepr)
    B = parse_formula(B, {"omega": OMEGA}, name="B(omega)", legacy_srepr=legacy_srepr)
    if sp.simplify(A.subs(OMEGA, 0)) != 0:
        raise ValueError("A(0) must be 0 (tip on the axis)")
    if sp.simplify(B.subs(OMEGA, 0)) != 0:
        raise ValueError("B(0) must be 0 (tip height measured from its apex)")
    if sp.simplify(sp.diff(B, OMEGA).subs(OMEGA, 0)) != 0:
        raise ValueError("B'(0) must be 0 (smooth apex)")
    dA0 = sp.diff(A, OMEGA).subs(OMEGA, 0)
    if not (dA0.is_number and float(dA0) > 0):
        raise ValueError(f"A'(0) must be positive; got {dA0}")
    return TipGeometry(A=A, B=B, phi=sp.atan2(sp.diff(B, OMEGA), sp.diff(A, OMEGA)), omega_max=tip_end(A))


def tip_end(A, omega_limit=2 * sp.pi):
    """The first omega > 0 where A'(omega) = 0 (the tip meets the cylinder r = rho A there),
    exact where SymPy solves it, else to 30 digits; None if A' keeps its sign up to ``omega_limit``."""
    import numpy as np

    dA = sp.diff(A, OMEGA)
    f = sp.lambdify(OMEGA, dA, "mpmath")
    grid = np.linspace(1e-6, float(omega_limit), 20001)
    vals = np.array([float(f(w)) for w in grid[::20]])  # coarse scan, then refine the bracket
    change = np.nonzero(np.diff(np.sign(vals)) != 0)[0]
    if not change.size:
        return None
    lo, hi = grid[::20][change[0]], grid[::20][change[0] + 1]
    roots = sp.solveset(dA, OMEGA, sp.Interval(lo, hi))
    if isinstance(roots, sp.FiniteSet) and roots:
        return min(roots, key=float)
    import mpmath

    with mpmath.workdps(30):
        return sp.Float(mpmath.findroot(f, (lo, hi), solver="anderson"), 30)


def cylinder_of(tip: TipGeometry) -> TipGeometry:
    """The indenter's cylinder as the continuation of the tip past its end, in the same
    parameter: ``A = A(omega_max)``, ``B = B(omega_max) + (omega - omega_max)`` (unit speed,
    tangent vertical, kappa_s = 0, kappa_theta = 1/(rho A(omega_max)))."""
    if tip.omega_max is None:
        raise ValueError("this tip has no end where it meets a cylinder (A' never vanishes)")
    w0 = tip.omega_max
    return TipGeometry(A=sp.simplify(tip.A.subs(OMEGA, w0)) + 0 * OMEGA,
                       B=sp.simplify(tip.B.subs(OMEGA, w0)) + (OMEGA - w0), phi=sp.pi / 2 + 0 * OMEGA,
                       omega_max=None)


def thickness_profile(description: dict, shell: ShellGeometry) -> sp.Expr:
    """The wall's thickness relative to the pole's, ``t(S) = H(S)/H(0)``, from a profile's
    description: ``{"kind": "formula", "H": text}`` (a formula of S and L, read by the
    whitelist parser) or ``{"kind": "spline", "S": [...], "H": [...]}`` (knots from the pole
    to the rim).  A table is interpolated by the natural cubic spline through its rows, written
    as ``a + b S + sum_k c_k |S - S_k|^3`` (with ``sum c_k = sum c_k S_k = 0``): one smooth
    (C2) expression, so the derivation differentiates it as any formula.  Its third derivative
    never enters the equations (it would carry ``|S - S_k|^2 delta(S - S_k) = 0``:
    :meth:`symbolic.dag.Program.derivative` drops such terms).
    """
    kind = description.get("kind")
    if kind == "formula":
        L = sp.Symbol("L", positive=True)
        H = parse_formula(description["H"], {"S": S, "L": L}, name="H(S)").xreplace({L: shell.L})
    elif kind == "spline":
        H = natural_spline(description["S"], description["H"])
    else:
        raise ValueError(f"unknown thickness profile kind {kind!r} (known: formula, spline)")
    H0 = H.subs(S, 0)
    if not (H0.is_number and float(H0) > 0):
        raise ValueError(f"the thickness at the pole H(0) must be positive; got {H0}")
    return H / H0


def natural_spline(knots, values) -> sp.Expr:
    """The natural cubic spline through ``(knots, values)`` as one SymPy expression in S."""
    a, b, c = natural_spline_coefficients(knots, values)
    expr = sp.Float(a) + sp.Float(b) * S
    for ck, xk in zip(c, knots):
        if ck != 0.0:
            expr += sp.Float(ck) * sp.Abs(S - sp.Float(float(xk))) ** 3
    return expr
