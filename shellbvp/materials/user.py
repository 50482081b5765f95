"""A user strain energy: its formula travels in the description as plain text."""

from __future__ import annotations

from .base import Material, register_material

__all__ = ["StrainEnergy"]


@register_material
class StrainEnergy(Material):
    """A user strain energy ``W(lambda_s, lambda_theta)``.

    Parameters
    ----------
    W : str or sympy expression
        In the symbols ``lambda_s`` and ``lambda_theta`` (shear modulus 1 in the
        nondimensionalisation), parsed without evaluating code
        (``symbolic.formula``: numbers, ``+ - * / **``, sin, exp, log, sqrt, ...).  Checked on construction: symmetric,
        ``W(1,1) = 0``, stress-free at (1,1), positive small-strain shear
        modulus (reported as ``shear_modulus``; it should be 1, or forces are in
        units of that modulus times mu).
    name : str, optional
        Label for output files.

    Raises
    ------
    ValueError
        Naming the formula and the offending piece (a name, call or construct
        outside the whitelist), or the check that failed.

    Examples
    --------
    >>> import shellbvp as sb
    >>> W = sb.StrainEnergy("(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2")
    >>> W.shear_modulus                      # the neo-Hookean energy, written out
    1.0
    >>> sb.StrainEnergy("lambda_s**2 - 1")
    Traceback (most recent call last):
    ...
    ValueError: ...
    """

    family = "user"
    label, short_label = "user strain energy", "user W"
    cli = False  # a formula is no NAME=VALUE option
    no_3d_form = "a user energy W(lambda_s, lambda_theta) of a sheet has no unique 3D form"

    def __init__(self, W, name: str = "user", *, legacy_srepr: bool = False):
        from symbolic import materials as sm
        from symbolic.formula import evaluation_errors, formula_text, parse_formula

        with evaluation_errors("W"):
            expr = parse_formula(W, {"lambda_s": sm.LS, "lambda_theta": sm.LT}, name="W", legacy_srepr=legacy_srepr)
            self.shear_modulus = float(sm.check_energy(expr, name="W"))
        self.W = expr
        self.name = str(name)
        self._text = formula_text(expr)

    def description(self):
        """The family and the formula as plain text (what files store)."""
        return {"family": "user", "W": self._text}

    def legend(self):
        return self.short_label

    @classmethod
    def from_data(cls, read):
        return cls(read("W", (str,)), legacy_srepr=True)

    @classmethod
    def strain_energy(cls, description):
        """W read back from the description's text (never evaluated as code); no parameters."""
        from symbolic import materials as sm
        from symbolic.formula import parse_formula

        return parse_formula(description["W"], {"lambda_s": sm.LS, "lambda_theta": sm.LT}, name="W",
                             legacy_srepr=True), ()

    def __repr__(self):
        return f"StrainEnergy({str(self.W)!r}, name={self.name!r})"

    def __eq__(self, other):
        return isinstance(other, StrainEnergy) and self.description() == other.description()

    def __hash__(self):
        return hash(str(self.description()))
