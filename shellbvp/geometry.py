"""Shell and indenter-tip shapes a scene can use.

The built-in spheroid (``R = sin S, Z = -gamma cos S``) and sphere tip are
described by name; user shapes carry formulas (parsed without evaluating
code by ``symbolic.formula`` and validated by ``symbolic.geometry``), stored
as plain text, and get code generated for them.
"""

from __future__ import annotations

import math

__all__ = ["Spheroid", "SphereTip", "FlatTip", "UserShell", "UserTip"]


class Spheroid:
    """Built-in reference shell ``R = sin S``, ``Z = -gamma cos S``, ``L = pi/2``.

    gamma is a run-time parameter of the scene (``Scene.gamma``).

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene(gamma=2.0, shell=sb.Spheroid()) == sb.Scene.preset("prolate2")
    True
    """

    kind = "spheroid"

    def description(self):
        """The structural choice, as files store it."""
        return {"kind": "spheroid"}

    def pole_curvature(self, values):
        """kappa_theta^R at the pole: gamma."""
        return values["gamma"]

    def __repr__(self):
        return "Spheroid()"

    def __eq__(self, other):
        return isinstance(other, Spheroid)

    def __hash__(self):
        return hash("spheroid")


class SphereTip:
    """Built-in spherical tip ``A = sin omega``, ``B = 1 - cos omega`` (radius rho).

    It ends at omega = pi/2, where it joins the indenter's cylinder r = rho.

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.SphereTip().apex_curvature(), sb.SphereTip().omega_max
    (1.0, 1.5707963267948966)
    """

    kind = "sphere"
    omega_max = 1.5707963267948966  # pi/2: the sphere meets its cylinder

    def description(self):
        """The structural choice, as files store it."""
        return {"kind": "sphere"}

    def apex_curvature(self):
        """B''(0)/A'(0)^2 in units of 1/rho."""
        return 1.0

    def __repr__(self):
        return "SphereTip()"

    def __eq__(self, other):
        return isinstance(other, SphereTip)

    def __hash__(self):
        return hash("sphere")


class FlatTip:
    """A flat rigid plate ``A = omega``, ``B = 0``: an indenter wider than the contact, or the
    plates a closed shell is compressed between (``Scene(closed=True, support="plates")``).

    It has no radius: a scene with a flat tip holds ``rho = 1`` (the plate's length scale,
    ``r = rho omega``), and it meets a shell at the pole first only where the shell is a dome
    (a closed shell, or ``gamma < 0``).  It has no end (no wall contact); it is followed up to
    ``r = 2 pi``, six times the shell's radius.

    Examples
    --------
    >>> import shellbvp as sb
    >>> scene = sb.Scene(closed=True, gamma=1.0, tip=sb.FlatTip(), support="plates", beta=1e-4)
    >>> scene.rho, sb.FlatTip().apex_curvature()
    (1.0, 0.0)
    """

    kind = "flat"
    # a plate has no end; tabulated, like a user tip without one, up to omega = 2 pi (r = 2 pi rho)
    omega_max = 2 * math.pi

    def description(self):
        """The structural choice, as files store it."""
        return {"kind": "flat"}

    def apex_curvature(self):
        """B''(0)/A'(0)^2: 0, a plane."""
        return 0.0

    def __repr__(self):
        return "FlatTip()"

    def __eq__(self, other):
        return isinstance(other, FlatTip)

    def __hash__(self):
        return hash("flat")


class UserShell:
    """Reference meridian ``R(S), Z(S)``, ``0 <= S <= L`` (formulas in S).

    Rescaled so that ``R(L) = 1``, ``Z(L) = 0``.  The formulas are parsed by a
    whitelist (numbers, ``S``, ``pi``, arithmetic, elementary functions), never
    evaluated as code.

    Parameters
    ----------
    R, Z : str
        The reference meridian, with ``R(0) = 0`` and ``Z'(0) = 0``.
    L : str
        The end of the meridian (the rim).

    Examples
    --------
    >>> import shellbvp as sb
    >>> shell = sb.UserShell("sin(S)", "-2*cos(S)", "pi/2")     # the gamma = 2 spheroid
    >>> shell.pole_curvature({})
    2.0
    >>> scene = sb.Scene.preset("base", shell=shell)            # code is generated for it
    """

    kind = "user"

    def __init__(self, R, Z, L="pi/2", *, legacy_srepr: bool = False):
        import sympy as sp

        from symbolic import geometry as sg
        from symbolic.formula import evaluation_errors, formula_text

        with evaluation_errors("shell"):
            self.geometry = sg.user_shell(R, Z, L, legacy_srepr=legacy_srepr)
            self._desc = {"kind": "user", "R": formula_text(self.geometry.R), "Z": formula_text(self.geometry.Z),
                          "L": formula_text(self.geometry.L)}
            ks, kt = self.geometry.curvatures()
            pole_kt = sp.limit(kt, sg.S, 0, "+")
        if not (pole_kt.is_real and pole_kt.is_finite):
            raise ValueError(f"shell: the pole curvature kappa_theta(0) must be finite; got {pole_kt}")
        self._pole_kt = float(pole_kt)

    def description(self):
        """The formulas as plain text (what files store)."""
        return dict(self._desc)

    def pole_curvature(self, values):
        """kappa_theta^R at the pole (after rescaling)."""
        return self._pole_kt

    def __repr__(self):
        return f"UserShell(R={str(self.geometry.R)!r}, Z={str(self.geometry.Z)!r}, L={str(self.geometry.L)!r})"

    def __eq__(self, other):
        return isinstance(other, UserShell) and self._desc == other._desc

    def __hash__(self):
        return hash(str(self._desc))


class UserTip:
    """Indenter tip ``r = rho A(omega)``, ``z = z_tip + rho B(omega)`` (formulas in omega).

    The tip ends where ``A'`` first vanishes (it joins the cylinder r = rho
    there).  Formulas are parsed by a whitelist, never evaluated as code.

    Parameters
    ----------
    A, B : str
        With ``A(0) = B(0) = B'(0) = 0`` and a convex apex (``B''(0)/A'(0)^2 > 0``).

    Examples
    --------
    >>> import shellbvp as sb
    >>> tip = sb.UserTip("omega", "omega**2/2")                 # a paraboloid
    >>> tip.apex_curvature()
    1.0
    """

    kind = "user"

    def __init__(self, A, B, *, legacy_srepr: bool = False):
        import sympy as sp

        from symbolic import geometry as sg
        from symbolic.formula import evaluation_errors, formula_text

        with evaluation_errors("tip"):
            self.geometry = sg.user_tip(A, B, legacy_srepr=legacy_srepr)
            self._desc = {"kind": "user", "A": formula_text(self.geometry.A), "B": formula_text(self.geometry.B)}
            w = sg.OMEGA
            dA0 = sp.diff(self.geometry.A, w).subs(w, 0)
            ddB0 = sp.diff(self.geometry.B, w, 2).subs(w, 0)
            apex = ddB0 / dA0**2
        if not (apex.is_real and apex.is_finite):
            raise ValueError(f"tip apex curvature B''(0)/A'(0)^2 must be a finite number; got {apex}")
        self._apex = float(apex)
        if self._apex <= 0:
            raise ValueError(f"tip apex curvature B''(0)/A'(0)^2 must be > 0 (a convex tip); got {self._apex}")
        # The tip ends where A' first vanishes (it meets the cylinder r = rho A there); a tip
        # whose A' never vanishes is followed up to omega = 2 pi.
        end = self.geometry.omega_max
        self.omega_max = float(end) if end is not None else 2 * math.pi

    def description(self):
        """The formulas as plain text (what files store)."""
        return dict(self._desc)

    def apex_curvature(self):
        """B''(0)/A'(0)^2 in units of 1/rho."""
        return self._apex

    def __repr__(self):
        return f"UserTip(A={str(self.geometry.A)!r}, B={str(self.geometry.B)!r})"

    def __eq__(self, other):
        return isinstance(other, UserTip) and self._desc == other._desc

    def __hash__(self):
        return hash(str(self._desc))
