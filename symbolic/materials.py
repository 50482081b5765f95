r"""Strain-energy functions W(lambda_s, lambda_theta) of an incompressible sheet.

Nondimensional (shear modulus mu = 1); the thickness stretch is
``lambda_n = 1/(lambda_s lambda_theta)``.  Stresses are never typed in: the
model derives ``T_s = (1/lambda_theta) dW/dlambda_s`` and
``T_theta = (1/lambda_s) dW/dlambda_theta`` by differentiation.
"""

from __future__ import annotations

import sympy as sp

__all__ = [
    "LS",
    "LT",
    "mooney_rivlin",
    "neo_hookean",
    "gent",
    "first_invariant",
    "check_energy",
    "small_strain_shear_modulus",
]

#: Generic stretch symbols in which energies are written.
LS, LT = sp.symbols("lambda_s lambda_theta", positive=True)


def first_invariant(ls=LS, lt=LT):
    r""":math:`I_1 = \lambda_s^2 + \lambda_\theta^2 + \lambda_s^{-2}\lambda_\theta^{-2}`."""
    return ls**2 + lt**2 + 1 / (ls**2 * lt**2)


def mooney_rivlin(alpha, ls=LS, lt=LT):
    r"""Mooney–Rivlin energy (paper, section 2c).

    .. math::
        W = \tfrac12\left[(1-\alpha)(I_1 - 3) + \alpha(I_2 - 3)\right],\quad
        I_2 = \lambda_s^{-2} + \lambda_\theta^{-2} + \lambda_s^2\lambda_\theta^2 .

    ``alpha = 0`` is neo-Hookean.
    """
    i2 = 1 / ls**2 + 1 / lt**2 + ls**2 * lt**2
    return sp.Rational(1, 2) * ((1 - alpha) * (first_invariant(ls, lt) - 3) + alpha * (i2 - 3))


def neo_hookean(ls=LS, lt=LT):
    r"""Neo-Hookean energy :math:`W = \tfrac12 (I_1 - 3)`."""
    return sp.Rational(1, 2) * (first_invariant(ls, lt) - 3)


def gent(Jm, ls=LS, lt=LT):
    r"""Gent energy (Gent 1996; paper, section 2c).

    .. math:: W = -\frac{J_m}{2}\log\left(1 - \frac{I_1 - 3}{J_m}\right),

    defined while ``I_1 - 3 < J_m`` (limiting chain extensibility).
    """
    return -Jm / 2 * sp.log(1 - (first_invariant(ls, lt) - 3) / Jm)


def small_strain_shear_modulus(W, ls=LS, lt=LT):
    r"""Shear modulus of ``W`` at small strain.

    For an incompressible isotropic solid ``W ~ mu (e_1^2 + e_2^2 + e_3^2)`` with
    ``e_3 = -e_1 - e_2``, so ``d^2W/dlambda_s^2 (1,1) = 4 mu``.
    """
    return sp.simplify(sp.diff(W, ls, 2).subs({ls: 1, lt: 1}) / 4)


#: A formula with decimal numbers (e.g. Gent's Jm = 97.2 written out) is exact only to
#: rounding: such a property holds when it holds to this relative size.
FLOAT_ZERO = 1e-12


def _vanishes(e, ls, lt) -> bool:
    """``e`` is zero: exactly, or -- where it holds floating-point numbers -- to FLOAT_ZERO of
    the size of its terms at a few stretches."""
    e = sp.simplify(e)
    if e == 0:
        return True
    if not e.has(sp.Float):
        return False
    terms = sp.Add.make_args(sp.expand(e))
    for point in ((1, 1), (1.3, 0.8), (0.7, 1.6), (2.1, 1.1)):
        at = {ls: point[0], lt: point[1]}
        value = complex(e.evalf(30, subs=at))
        size = sum(abs(complex(t.evalf(30, subs=at))) for t in terms)
        if abs(value) > FLOAT_ZERO * max(size, 1.0):
            return False
    return True


def check_energy(W, ls=LS, lt=LT, name="W"):
    """Validate a user strain energy; return its small-strain shear modulus.

    Raises ``ValueError`` (naming the failed property) unless ``W`` depends
    only on the two stretches (and declared parameters are substituted),
    is symmetric in them, vanishes and is stress-free at ``(1, 1)``, and has
    a positive small-strain shear modulus.
    """
    W = sp.sympify(W, strict=True)  # an expression already: text goes through formula.parse_formula
    extra = W.free_symbols - {ls, lt}
    if extra:
        raise ValueError(
            f"{name} must be an expression in lambda_s and lambda_theta only; "
            f"it also contains {sorted(map(str, extra))}"
        )
    swapped = W.xreplace({ls: lt, lt: ls})
    if not _vanishes(W - swapped, ls, lt):
        raise ValueError(f"{name} must be symmetric in (lambda_s, lambda_theta) (isotropy); it is not")
    w0 = sp.simplify(W.subs({ls: 1, lt: 1}))
    if not _vanishes(w0, ls, lt):
        raise ValueError(f"{name} must vanish in the reference state: W(1, 1) = {w0}, expected 0")
    s0 = sp.simplify(sp.diff(W, ls).subs({ls: 1, lt: 1}))
    if not _vanishes(s0, ls, lt):
        raise ValueError(
            f"{name} must be stress-free in the reference state: dW/dlambda_s(1, 1) = {s0}, expected 0"
        )
    mu = small_strain_shear_modulus(W, ls, lt)
    if not (mu.is_number and float(mu) > 0):
        raise ValueError(f"{name} must have a positive small-strain shear modulus; got {mu}")
    return mu
