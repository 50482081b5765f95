"""Shell and indenter-tip shapes a scene can use.

The built-in spheroid (``R = sin S, Z = -gamma cos S``) and sphere tip are
described by name; user shapes carry formulas (parsed without evaluating
code by ``symbolic.formula`` and validated by ``symbolic.geometry``), stored
as plain text, and get code generated for them.
"""

from __future__ import annotations

import copy
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
            ks, kt = self._curvatures = self.geometry.curvatures(simplify=False)  # checks evaluate them
            pole_kt = sp.limit(kt, sg.S, 0, "+")
        if not (pole_kt.is_real and pole_kt.is_finite):
            raise ValueError(f"shell: the pole curvature kappa_theta(0) must be finite; got {pole_kt}")
        self._pole_kt = float(pole_kt)
        self._closed_problem = ...  # not asked yet (closed_problem)
        self.lower = None  # a closed shell's lower half, where it differs (closed_halves)
        self._upper = None  # the upper half alone, where this shell carries more (closed_halves, pole_to_pole)
        self.meridian = None  # the whole meridian's (R, Z, L) as given (pole_to_pole), else None
        self.equator = None  # and where on it the equator is, S_e (pole_to_pole)

    @classmethod
    def closed_halves(cls, upper, lower, *, legacy_srepr: bool = False) -> "UserShell":
        """A closed shell whose halves differ (an egg): each half's meridian ``(R, Z, L)`` from its
        own pole to the equator, as :meth:`closed_problem` asks of an upper half (rescaled so the
        equator is ``R = 1``, ``Z = 0``): the lower half in its mirror image, ``Z > 0`` above the
        equator meaning below it.  For ``Scene(closed=True)`` on a substrate under a curved tip
        (both halves solved), or between plates (on a substrate under a flat plate: the same problem).

        >>> import shellbvp as sb
        >>> egg = sb.UserShell.closed_halves(("sin(S)", "1.3*cos(S)", "pi/2"), ("sin(S)", "0.7*cos(S)", "pi/2"))
        >>> egg.lower.pole_curvature({})
        -0.7
        """
        for name, half in (("upper", upper), ("lower", lower)):
            if not (isinstance(half, (tuple, list)) and len(half) == 3 and all(isinstance(t, str) for t in half)):
                raise ValueError(f"shell: closed_halves' {name} half must be its meridian's (R, Z, L) as three "
                                 f"texts; got {half!r}")
        shell, other = cls(*upper, legacy_srepr=legacy_srepr), cls(*lower, legacy_srepr=legacy_srepr)
        shell._upper, shell.lower = copy.copy(shell), other  # the upper half alone, before it carries the lower
        shell._upper._desc = dict(shell._desc)
        shell._desc["lower"] = {k: other._desc[k] for k in "RZL"}
        return shell

    @classmethod
    def pole_to_pole(cls, R, Z, L, *, legacy_srepr: bool = False) -> "UserShell":
        """A closed shell given by its whole meridian, from its top pole (``S = 0``) to its bottom
        pole (``S = L``): ``R(0) = R(L) = 0``, ``R > 0`` between, ``Z`` decreasing through the
        widest point.

        The meridian is split at its equator ``S_e``, the one point between the poles where
        ``R'(S) = 0`` (found to full precision; refused in one line where there is none or more
        than one, or the tangent there is not vertical), into the upper half ``(R(S), Z(S) -
        Z(S_e), S_e)`` and the lower half in its mirror image from its own pole, ``(R(L - S),
        Z(S_e) - Z(L - S), L - S_e)``, both by substitution in the formulas.  Where the halves are
        mirror images (to 1e-12 on 4001 points) it is the symmetric ``UserShell(upper)`` (plates,
        pressure and all); else :meth:`closed_halves` of the two.  Either way it keeps the
        meridian as given (``meridian``, and files store it) and its equator ``S_e``
        (``equator``).

        >>> import shellbvp as sb
        >>> sphere = sb.UserShell.pole_to_pole("sin(S)", "cos(S)", "pi")
        >>> sphere.upper_half() == sb.UserShell("sin(S)", "cos(S)", "pi/2"), sphere.lower is None
        (True, True)
        >>> egg = sb.UserShell.pole_to_pole("sin(S)", "cos(S)*(1 + 0.3*cos(S))", "pi")
        >>> egg.equator, egg.pole_curvature({}), egg.lower.pole_curvature({})
        (1.5707963267948966, -1.6, -0.4)
        """
        meridian, upper, lower, mirror, S_e = _split_at_equator(R, Z, L, legacy_srepr)
        if mirror:
            plain = cls(*upper)
            shell = copy.copy(plain)
            shell._desc, shell._upper = dict(plain._desc), plain
        else:
            shell = cls.closed_halves(upper, lower)
        shell.meridian, shell.equator = meridian, S_e
        shell._desc["pole_to_pole"] = dict(zip("RZL", meridian))
        if why := shell.closed_problem():
            raise ValueError(why.replace("the lower half (in its mirror image)", f"the lower half (S >= S_e = "
                                         f"{S_e:.6g}, in its mirror image from its pole)", 1))
        return shell

    @staticmethod
    def returns_to_axis(R, L) -> bool:
        """Whether the meridian ``R(S)`` ends on the axis, ``|R(L)| <= 1e-6 max |R|`` (a whole
        meridian, pole to pole: how the command line tells it from a half).

        >>> import shellbvp as sb
        >>> sb.UserShell.returns_to_axis("sin(S)", "pi"), sb.UserShell.returns_to_axis("sin(S)", "pi/2")
        (True, False)
        """
        import numpy as np
        import sympy as sp

        from symbolic import geometry as sg
        from symbolic.formula import evaluation_errors, parse_formula

        with evaluation_errors("shell"):
            R = parse_formula(R, {"S": sg.S}, name="R(S)")
            L = parse_formula(L, {}, name="L")
            if not (L.is_number and L.is_extended_real and float(L) > 0):
                return False
            with np.errstate(all="ignore"):
                values = np.abs(np.asarray(sp.lambdify(sg.S, R, "numpy")(np.linspace(0.0, float(L), 201)), complex))
            end = abs(complex(sp.N(R.subs(sg.S, L), 30)))
        return bool(np.isfinite(values).all() and end <= 1e-6 * values.max())

    def halves_problem(self, scene) -> str | None:
        """Why ``scene`` cannot take this shell's lower half of its own (yet), or None."""
        if self.lower is None:
            return None
        if not scene.closed:
            return "shell: a lower half of its own (UserShell.closed_halves) needs closed=True"
        if scene.support == "plates" and not isinstance(scene.tip, FlatTip):
            return ("shell: halves that differ rest on a substrate (under any tip) or lie between plates (a flat tip); "
                    "between two curved tips (support='plates' with a curved tip) the shell must be mirror-symmetric "
                    "about its equator (UserShell(R, Z, L))")
        if scene.pressure or scene.sealed:
            return "shell: halves that differ are offered without pressure only (pressure=0, sealed=False) for now"
        if scene.thickness_profile is not None:
            return "shell: halves that differ are offered with a constant thickness only (no thickness profile) for now"
        return None

    def upper_half(self) -> "UserShell":
        """This meridian without its lower half (the one its code is generated for)."""
        return self if self._upper is None else self._upper

    def description(self):
        """The formulas as plain text (what files store; a closed shell's different lower half
        under ``lower``)."""
        return {k: (dict(v) if isinstance(v, dict) else v) for k, v in self._desc.items()}

    def pole_curvature(self, values):
        """kappa_theta^R at the pole (after rescaling)."""
        return self._pole_kt

    def closed_problem(self) -> str | None:
        """Why this meridian is not the upper half of a closed shell, or None.

        A closed shell's meridian (``Scene(closed=True, shell=...)``) runs from its pole (S = 0)
        to its equator (S = L), the lower half its mirror image: it leaves the pole horizontally
        (``R'(0) > 0``), meets the equator with a vertical tangent (``R'(L) = 0``, ``Z'(L) < 0``),
        is smooth (``Psi > 0``, finite curvatures), off the axis (``R > 0``) and above the
        equator (``Z > 0``) in between, and highest at its pole (a plate meets the pole first).
        Checked on 2001 points of [0, L] and, at the ends, in 30 digits.

        >>> import shellbvp as sb
        >>> sb.UserShell("sin(S)", "0.7*cos(S)", "pi/2").closed_problem() is None
        True
        >>> sb.UserShell("sin(S)", "cos(S)", "1.5").closed_problem()[:60]
        "shell: a closed shell's meridian ends at its equator S = L w"
        """
        if self._closed_problem is ...:
            self._closed_problem = _closed_problem(self.geometry, self._curvatures)
            if self._closed_problem is None and self.lower is not None and (why := self.lower.closed_problem()):
                self._closed_problem = why.replace("shell: ", "shell: the lower half (in its mirror image): ", 1)
        return self._closed_problem

    def __repr__(self):
        if self.meridian is not None:
            return "UserShell.pole_to_pole(R={!r}, Z={!r}, L={!r})".format(*self.meridian)
        if self.lower is None:
            return f"UserShell(R={str(self.geometry.R)!r}, Z={str(self.geometry.Z)!r}, L={str(self.geometry.L)!r})"
        halves = [", ".join(repr(str(e)) for e in (g.R, g.Z, g.L)) for g in (self.geometry, self.lower.geometry)]
        return f"UserShell.closed_halves(upper=({halves[0]}), lower=({halves[1]}))"

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


def _closed_problem(g, curvatures) -> str | None:
    """:meth:`UserShell.closed_problem` of the geometry ``g`` with its curvatures ``(ks, kt)``."""
    import numpy as np
    import sympy as sp

    from symbolic.geometry import S

    L = float(g.L)
    dR, dZ = sp.diff(g.R, S), sp.diff(g.Z, S)
    ends = [complex(sp.N(e.subs(S, at), 30)) for e in (dR, dZ) for at in (0, g.L)]
    if any(abs(v.imag) > 1e-12 or not np.isfinite(v.real) for v in ends):
        return f"shell: R'(S) and Z'(S) must be real and finite at the pole and the equator (S = 0, L = {L:.6g})"
    dR0, dRL, _, dZL = (v.real for v in ends)
    if not dR0 > 0:
        return f"shell: a closed shell's meridian leaves its pole horizontally, R'(0) > 0; got R'(0) = {dR0:.3g}"
    if not abs(dRL) <= 1e-9:
        return (f"shell: a closed shell's meridian ends at its equator S = L with a vertical tangent, R'(L) = 0 "
                f"(|R'(L)| <= 1e-9; give the upper half, pole to equator); got R'(L) = {dRL:.3g} at L = {L:.6g}")
    if not dZL < 0:
        return (f"shell: a closed shell's meridian runs down to its equator, Z'(L) < 0 (the pole above it); "
                f"got Z'(L) = {dZL:.3g}")
    s = np.linspace(0.0, L, 2001)[1:]
    with np.errstate(all="ignore"):
        R, Z, dRs, dZs, ks, kt = (np.broadcast_to(np.asarray(f(s), dtype=complex), s.shape) for f in
                                  (sp.lambdify(S, e, "numpy") for e in (g.R, g.Z, dR, dZ, *curvatures)))
    Z0 = float(sp.N(g.Z.subs(S, 0), 30))
    checks = (
        (np.isfinite(R) & np.isfinite(Z) & (abs(R.imag) + abs(Z.imag) <= 1e-12), "R(S), Z(S) must be real and finite"),
        (R.real > 0, "R(S) must be > 0 between the pole and the equator (off the axis)"),
        (np.hypot(abs(dRs), abs(dZs)) > 1e-9, "Psi = sqrt(R'^2 + Z'^2) must be > 0 (a smooth meridian)"),
        (np.isfinite(ks) & np.isfinite(kt) & (abs(ks.imag) + abs(kt.imag) <= 1e-12),
         "the curvatures must be real and finite (a smooth meridian)"),
        (Z.real < Z0, "the pole must be the highest point, Z(S) < Z(0) (a plate meets the pole first)"),
        (np.r_[Z.real[:-1] > 0, True], "Z(S) must be > 0 before the equator (the upper half above it)"),
    )
    for ok, what in checks:
        if not np.all(ok):
            bad = s[np.argmin(ok)]
            return f"shell: a closed shell's meridian: {what} on 0 < S <= L = {L:.6g}; not at S = {bad:.4g}"
    return None


def _split_at_equator(R, Z, L, legacy_srepr):
    """:meth:`UserShell.pole_to_pole`'s meridian split at its equator: ``(meridian, upper, lower,
    mirror, S_e)``, the meridian's three texts as parsed, each half's ``(R, Z, L)`` as text (by
    substitution), whether the halves are mirror images and the equator's S; ValueError where it
    is no closed shell's whole meridian."""
    import mpmath
    import numpy as np
    import sympy as sp

    from symbolic.formula import evaluation_errors, formula_text, parse_formula
    from symbolic.geometry import S

    def number(e, digits=30):
        v = complex(sp.N(e, digits))
        return v.real if abs(v.imag) <= 1e-12 and math.isfinite(v.real) else math.nan

    with evaluation_errors("shell"):
        R = parse_formula(R, {"S": S}, name="R(S)", legacy_srepr=legacy_srepr)
        Z = parse_formula(Z, {"S": S}, name="Z(S)", legacy_srepr=legacy_srepr)
        exact = isinstance(L, sp.Basic)
        L = parse_formula(L, {}, name="L", legacy_srepr=legacy_srepr)
        L = L if exact else sp.nsimplify(L)
        Lf = number(L) if L.is_number else math.nan
        if not Lf > 0:
            raise ValueError(f"shell: a meridian from pole to pole ends at its bottom pole S = L > 0; got L = {L}")
        dR, dZ = sp.diff(R, S), sp.diff(Z, S)
        for what, e, at in (("R(0) = 0 (the top pole on the axis)", R, 0),
                            ("R(L) = 0 (the bottom pole on the axis)", R, L),
                            ("Z'(0) = 0 (a smooth top pole)", dZ, 0), ("Z'(L) = 0 (a smooth bottom pole)", dZ, L)):
            if sp.simplify(e.subs(S, at)) != 0:
                got = number(e.subs(S, at))
                exactly = f" (give L exactly: pi, not {Lf:.5g})" if abs(got) < 1e-3 else ""
                raise ValueError(f"shell: a meridian from pole to pole has {what}; got {got:.3g} at S = "
                                 + (f"L = {Lf:.6g}{exactly}" if at is L else "0"))
        slopes = number(dR.subs(S, 0)), number(dR.subs(S, L))
        if not (slopes[0] > 0 and slopes[1] < 0):
            raise ValueError(f"shell: a meridian from pole to pole leaves both poles horizontally, R'(0) > 0 and "
                             f"R'(L) < 0; got R'(0) = {slopes[0]:.3g}, R'(L) = {slopes[1]:.3g} at L = {Lf:.6g}")
        # the equator: the one point between the poles where R' = 0 (scan, then refine)
        s = np.linspace(0.0, Lf, 20001)[1:-1]
        with np.errstate(all="ignore"):
            fn = sp.lambdify(S, dR, "numpy")
            d = np.broadcast_to(np.asarray(fn(s), dtype=complex), s.shape)
        if not (np.isfinite(d).all() and np.all(abs(d.imag) <= 1e-12)):
            bad = s[np.argmin(np.isfinite(d) & (abs(d.imag) <= 1e-12))]
            raise ValueError(f"shell: R'(S) must be real and finite between the poles; not at S = {bad:.4g}")
        d = d.real
        zeros = _zeros(lambda x: np.real(fn(x)), s, d)
        if len(zeros) != 1:
            where = ("R' keeps its sign" if not zeros else f"R'(S) = 0 at {len(zeros)} points, S = "
                     + ", ".join(f"{(lo + hi) / 2:.4g}" for lo, hi in zeros[:5]))
            raise ValueError(f"shell: a meridian from pole to pole has one widest point (its equator), where R'(S) = 0 "
                             f"between the poles; {where} on 0 < S < L = {Lf:.6g}")
        lo, hi = zeros[0]
        f = sp.lambdify(S, dR, "mpmath")
        with mpmath.workdps(40):
            root = mpmath.findroot(f, (lo, hi), solver="anderson") if lo != hi else mpmath.mpf(lo)
            S_e = sp.Float(root, 30)
            guess = sp.nsimplify(S_e, [sp.pi])  # pi/2 where it is: the halves' L exact, else 30 digits
            S_e = guess if abs(number(guess, 40) - float(S_e)) < 1e-14 and sp.simplify(dR.subs(S, guess)) == 0 else (
                sp.Rational(str(S_e)))  # a fraction: the halves' texts keep the 30 digits (text floats are doubles)
        slope = number(dZ.subs(S, S_e))
        scale = max(abs(d).max(), 1e-300)
        if not abs(slope) > 1e-9 * scale:
            raise ValueError(f"shell: the tangent at the widest point S = {float(S_e):.6g} must be vertical (R' = 0, "
                             f"Z' < 0); got Z' = {slope:.3g} there (a cusp)")
        if not slope < 0:
            raise ValueError(f"shell: Z(S) decreases through the widest point (the top pole above the bottom one); "
                             f"got Z'(S_e) = {slope:.3g} at S_e = {float(S_e):.6g}")
        Ze = Z.subs(S, S_e)
        upper = (R, Z - Ze, S_e)
        lower = (R.subs(S, L - S), Ze - Z.subs(S, L - S), L - S_e)
        mirror = _mirror_images(upper, lower)
        texts = [tuple(formula_text(e) for e in half) for half in (upper, lower)]
        return (formula_text(R), formula_text(Z), formula_text(L)), *texts, mirror, float(S_e)


def _zeros(f, s, d):
    """The zeros of ``f`` on the grid ``s`` where it takes the values ``d``: brackets ``(lo, hi)``
    of its sign changes, and ``(x, x)`` where ``|f|`` has a minimum touching zero without changing
    sign (``<= 1e-10 max |d|`` at a minimum located to ~1e-12)."""
    import numpy as np
    from scipy.optimize import minimize_scalar

    nonzero = np.flatnonzero(d != 0)
    flips = np.flatnonzero(np.diff(np.sign(d[nonzero])))
    out = [(float(s[nonzero[k]]), float(s[nonzero[k + 1]])) for k in flips]
    a = abs(d)
    minima = np.flatnonzero((a[1:-1] <= a[:-2]) & (a[1:-1] <= a[2:]) & (a[1:-1] < 1e-3 * a.max())) + 1
    for i in minima:
        if any(lo <= s[i + 1] and s[i - 1] <= hi for lo, hi in out):
            continue  # a sign change
        m = minimize_scalar(lambda x: abs(float(f(x))), bounds=(s[i - 1], s[i + 1]), method="bounded",
                            options={"xatol": 1e-12})
        if m.fun <= 1e-10 * a.max():
            out.append((float(m.x), float(m.x)))
    return sorted(out)


def _mirror_images(upper, lower) -> bool:
    """Whether two halves' ``(R, Z, L)`` expressions are one meridian: equal L and R, Z equal to
    1e-12 (of the equatorial radius) on 4001 points of [0, L]."""
    import numpy as np
    import sympy as sp

    from symbolic.geometry import S

    Lu, Ll = float(upper[2]), float(lower[2])
    if abs(Lu - Ll) > 1e-12 * Lu:
        return False
    s = np.linspace(0.0, Lu, 4001)
    scale = abs(complex(sp.N(upper[0].subs(S, upper[2]), 30)))  # R at the equator
    with np.errstate(all="ignore"):
        u, v = ([np.broadcast_to(np.asarray(sp.lambdify(S, e, "numpy")(s), dtype=complex), s.shape) for e in h[:2]]
                for h in (upper, lower))
    gap = max(np.max(abs(a - b)) for a, b in zip(u, v))
    return bool(np.isfinite(gap) and gap <= 1e-12 * scale)
