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
            ks, kt = self._curvatures = self.geometry.curvatures()
            pole_kt = sp.limit(kt, sg.S, 0, "+")
        if not (pole_kt.is_real and pole_kt.is_finite):
            raise ValueError(f"shell: the pole curvature kappa_theta(0) must be finite; got {pole_kt}")
        self._pole_kt = float(pole_kt)
        self._closed_problem = ...  # not asked yet (closed_problem)
        self.lower = None  # a closed shell's lower half, where it differs (closed_halves)

    @classmethod
    def closed_halves(cls, upper, lower, *, legacy_srepr: bool = False) -> "UserShell":
        """A closed shell whose halves differ (an egg): each half's meridian ``(R, Z, L)`` from its
        own pole to the equator, as :meth:`closed_problem` asks of an upper half (rescaled so the
        equator is ``R = 1``, ``Z = 0``): the lower half in its mirror image, ``Z > 0`` above the
        equator meaning below it.  For ``Scene(closed=True)`` on a substrate under a curved tip
        (both halves solved); between plates the mirror symmetry is needed.

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
        shell._upper, shell.lower = cls(*upper, legacy_srepr=legacy_srepr), other
        shell._desc["lower"] = {k: other._desc[k] for k in "RZL"}
        return shell

    def halves_problem(self, scene) -> str | None:
        """Why ``scene`` cannot take this shell's lower half of its own (yet), or None."""
        if self.lower is None:
            return None
        if not scene.closed:
            return "shell: a lower half of its own (UserShell.closed_halves) needs closed=True"
        if not scene.two_contacts:
            return ("shell: halves that differ need support='substrate' under a curved tip; between plates (or "
                    "under a flat plate) the shell must be mirror-symmetric about its equator (UserShell(R, Z, L))")
        if scene.thickness_profile is not None:
            return "shell: halves that differ are offered with a constant thickness only (no thickness profile) for now"
        return None

    def upper_half(self) -> "UserShell":
        """This meridian without its lower half (the one its code is generated for)."""
        return self if self.lower is None else self._upper

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
