"""A wall whose thickness varies along the meridian (issue 58).

A :class:`ThicknessProfile` is a shape and a scale: the shape ``H(S)`` (a formula of the
reference coordinate ``S`` and the meridian's end ``L``, read by the whitelist parser of
``symbolic.formula``, or a table of rows interpolated by the natural cubic spline through them)
and the pole's thickness ``H(0)`` (in units of the rim radius, as ``Scene.thickness``).  The
generated code holds the relative profile ``t(S) = H(S)/H(0)``; the pole's thickness sets
``beta`` and the units of force, so nondimensional forces and ``mu H`` refer to the pole.
Scaling a profile (``scaled``; a fit of the thickness) changes only the pole's thickness:
the same generated code.

``S`` is the package's meridian coordinate: the arc length over ``R_L`` on a sphere (gamma 1),
the parametric angle of ``R = sin S, Z = -gamma cos S`` on other spheroids, a user meridian's
own S.  Tables may be given along the reference arc length or the angle of the normal from
the axis (:func:`positions_to_S` converts them for the scene's meridian).
"""

from __future__ import annotations

import math

import numpy as np

from symbolic.spline import natural_spline_coefficients

from .units import LENGTH_UNITS

__all__ = ["ThicknessProfile", "MAX_TABLE_ROWS", "ALONG", "positions_to_S", "read_profile_table", "settle_profile",
           "profile_from_file"]

#: The largest thickness table (rows): every row is a term of the generated expression.
MAX_TABLE_ROWS = 64
#: How a table's positions are given: the package's S, the reference arc length, the normal's angle.
ALONG = ("S", "arc", "angle")
_GRID = 2001  # points along the meridian where a profile is checked


class ThicknessProfile:
    """The wall's thickness along the meridian, ``H(S)`` in units of the rim radius.

    Make one with :meth:`formula` or :meth:`table`, and give it as ``Scene(thickness=...)``
    (a formula's text is accepted there too).

    Examples
    --------
    >>> import shellbvp as sb
    >>> import math
    >>> wall = sb.ThicknessProfile.formula("0.05*(1 + S/L)")       # twice as thick at the rim
    >>> scene = sb.Scene.preset("base", beta=None, thickness=wall)
    >>> scene.thickness, round(scene.beta, 6)                         # the pole's
    (0.05, 0.000833)
    >>> round(float(scene.thickness_profile.at([0.0, math.pi / 4], L=math.pi / 2)[1]), 4)
    0.075
    """

    def __init__(self, kind: str, shape, pole: float | None = None):
        if kind not in ("formula", "spline"):
            raise ValueError(f"thickness profile kind must be 'formula' or 'spline'; got {kind!r}")
        self.kind = kind
        if kind == "formula":
            from symbolic.formula import evaluation_errors, formula_text, parse_formula
            import sympy as sp

            with evaluation_errors("thickness"):
                S, L = sp.Symbol("S", positive=True), sp.Symbol("L", positive=True)
                expr = parse_formula(shape, {"S": S, "L": L}, name="thickness H(S)")
            self._expr, self._symbols = expr, (S, L)
            self.shape = formula_text(expr)
            self._relative = None
        else:
            knots, values = (np.array(v, dtype=float) for v in shape)
            if knots.ndim != 1 or knots.size > MAX_TABLE_ROWS:
                raise ValueError(f"thickness table: 2 to {MAX_TABLE_ROWS} rows; got {knots.size}")
            if not (np.all(np.isfinite(knots)) and np.all(np.isfinite(values)) and np.all(values > 0)):
                raise ValueError("thickness table: positions and thicknesses must be finite, thicknesses > 0")
            self._spline = natural_spline_coefficients(knots, values)  # raises on too few or unordered rows
            self.shape = (tuple(float(x) for x in knots), tuple(float(h) for h in values))
        shape_pole = self._shape_at(np.array([0.0]), L=1.0)[0]
        if not (np.isfinite(shape_pole) and shape_pole > 0):
            raise ValueError(f"thickness profile: the thickness at the pole H(0) must be > 0; got {shape_pole:g}")
        self._shape_pole = float(shape_pole)
        self.pole = self._shape_pole if pole is None else float(pole)

    # -- constructors ------------------------------------------------------------------
    @classmethod
    def formula(cls, text: str) -> "ThicknessProfile":
        """``H(S)`` as a formula of ``S`` and ``L`` (units of the rim radius), e.g.
        ``"0.05*(1 - 0.5*S/L)"``: 0.05 at the pole, half that at the rim."""
        return cls("formula", text)

    @classmethod
    def table(cls, positions, thickness) -> "ThicknessProfile":
        """Rows ``(S, H)`` from the pole (S = 0) to the rim, units of the rim radius,
        interpolated by the natural cubic spline through them (at most ``MAX_TABLE_ROWS``);
        positions along the arc or the normal's angle: :func:`positions_to_S` first."""
        return cls("spline", (positions, thickness))

    # -- values ------------------------------------------------------------------------
    def _shape_at(self, S, L):
        S = np.asarray(S, dtype=float)
        if self.kind == "spline":
            knots = np.asarray(self.shape[0])
            a, b, c = self._spline
            return a + b * S + (c[:, None] * np.abs(S[None, :] - knots[:, None]) ** 3).sum(axis=0)
        if self._relative is None:
            import sympy as sp

            # the expression came through the whitelist parser: printing it runs nothing of the user's
            self._relative = sp.lambdify(self._symbols, self._expr, "numpy")
        return np.broadcast_to(np.asarray(self._relative(S, L), dtype=float), S.shape)

    def at(self, S, *, L: float) -> np.ndarray:
        """``H(S)`` in units of the rim radius (``L``: the meridian's end, ``Scene.shell_length``)."""
        return self.pole / self._shape_pole * self._shape_at(S, L)

    def relative(self, S, *, L: float) -> np.ndarray:
        """``t(S) = H(S)/H(0)``, what the generated code holds."""
        return self._shape_at(S, L) / self._shape_pole

    def scaled(self, pole: float) -> "ThicknessProfile":
        """The same shape with the pole's thickness ``pole`` (a fitted thickness)."""
        return ThicknessProfile(self.kind, self.shape, pole)

    def thickest(self, L: float) -> float:
        """The largest thickness from the pole to the rim (units of the rim radius)."""
        return float(np.max(self.at(np.linspace(0.0, L, _GRID), L=L)))

    def check(self, L: float, *, largest: float = 0.5) -> None:
        """Positive and at most ``largest`` (units of the rim radius) along the whole meridian."""
        H = self.at(np.linspace(0.0, L, _GRID), L=L)
        if not np.all(np.isfinite(H)) or H.min() <= 0 or H.max() > largest:
            lo, hi = (float(np.nanmin(H)), float(np.nanmax(H))) if np.any(np.isfinite(H)) else (math.nan,) * 2
            raise ValueError(f"thickness profile must stay in (0, {largest}] (H/R_L) from the pole to the rim; "
                             f"it spans [{lo:.4g}, {hi:.4g}]")
        if self.kind == "spline":
            first, last = self.shape[0][0], self.shape[0][-1]
            if abs(first) > 1e-9 * L or last < L * (1 - 1e-6):
                raise ValueError(f"thickness table must run from the pole (S = 0) to the rim (S = {L:.6g}); "
                                 f"its rows span [{first:.6g}, {last:.6g}]")

    # -- data ---------------------------------------------------------------------------
    def description(self) -> dict:
        """The shape, what the generated code depends on (the pole's thickness is run-time)."""
        if self.kind == "formula":
            return {"kind": "formula", "H": self.shape}
        return {"kind": "spline", "S": list(self.shape[0]), "H": list(self.shape[1])}

    def to_dict(self) -> dict:
        """Plain data that rebuilds this profile (files store it)."""
        return {**self.description(), "pole": self.pole}

    @classmethod
    def from_dict(cls, d: dict) -> "ThicknessProfile":
        if not isinstance(d, dict) or d.get("kind") not in ("formula", "spline"):
            raise ValueError("scene data: thickness_profile must be a mapping with kind 'formula' or 'spline'")
        pole = d.get("pole")
        if pole is not None and not (isinstance(pole, (int, float)) and not isinstance(pole, bool)):
            raise ValueError(f"scene data: thickness_profile.pole must be a number; got {pole!r}")
        if d["kind"] == "formula":
            if not isinstance(d.get("H"), str):
                raise ValueError("scene data: thickness_profile.H must be text (a formula of S and L)")
            return cls("formula", d["H"], pole)
        S, H = d.get("S"), d.get("H")
        if not (isinstance(S, list) and isinstance(H, list) and len(S) == len(H)
                and len(S) <= MAX_TABLE_ROWS
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in S + H)):
            raise ValueError(f"scene data: thickness_profile.S and .H must be lists of up to {MAX_TABLE_ROWS} "
                             "numbers of equal length")
        return cls("spline", (S, H), pole)

    def describe(self) -> str:
        """One line for summaries."""
        if self.kind == "formula":
            return f"H(S)/R_L = {self.shape}"
        return f"a table of {len(self.shape[0])} rows, natural cubic spline"

    def __eq__(self, other):
        return isinstance(other, ThicknessProfile) and self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(repr(self.to_dict()))

    def __repr__(self):
        if self.kind == "formula":
            return f"ThicknessProfile.formula({self.shape!r})"
        return f"ThicknessProfile.table({list(self.shape[0])!r}, {list(self.shape[1])!r})"


def settle_profile(scene) -> None:
    """A wall's profile given as ``thickness`` (a ThicknessProfile or a formula's text) moved to
    ``thickness_profile``, ``thickness`` set to the pole's (a new pole thickness scales the profile);
    the profile checked along the whole meridian."""
    given, profile = scene.thickness, scene.thickness_profile
    if isinstance(given, str):
        given = ThicknessProfile.formula(given)
    if isinstance(given, ThicknessProfile):
        if profile is not None and profile != given:
            raise ValueError("thickness and thickness_profile disagree: give the profile once")
        profile, given = given, given.pole
    if profile is None:
        return
    if not isinstance(profile, ThicknessProfile):
        raise ValueError(f"thickness_profile must be a ThicknessProfile (formula or table); got {profile!r}")
    if given is not None:
        if isinstance(given, bool) or not isinstance(given, (int, float, np.floating)):
            raise ValueError(f"thickness must be a number H/R_L or a ThicknessProfile; got {given!r}")
        pole = float(given)
        if pole != profile.pole:
            profile = profile.scaled(pole)
    profile.check(scene.shell_length)
    object.__setattr__(scene, "thickness_profile", profile)
    object.__setattr__(scene, "thickness", profile.pole)


def profile_from_file(path, R_L: float, scene) -> ThicknessProfile:
    """A thickness file in lab units (:func:`read_profile_table`) as the profile of the scene's meridian."""
    positions, thickness, along = read_profile_table(path, R_L)
    return ThicknessProfile.table(positions_to_S(scene, positions, along), thickness)


def positions_to_S(scene, positions, along: str) -> np.ndarray:
    """The package's S of positions along the reference arc length (``"arc"``, units of the
    rim radius) or the angle of the normal from the axis (``"angle"``, radians), on the
    scene's meridian; ``"S"`` as they are.  Positions past the rim are refused."""
    if along not in ALONG:
        raise ValueError(f"along must be one of {ALONG}; got {along!r}")
    x = np.asarray(positions, dtype=float)
    if along == "S":
        return x
    L = scene.shell_length
    S = np.linspace(0.0, L, 20001)
    R, Z, dR, dZ = _meridian(scene, S)
    if along == "arc":
        coordinate = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(R), np.diff(Z)))])
    else:
        coordinate = np.abs(np.arctan2(dZ, dR))
        if np.any(np.diff(coordinate) <= 0):
            raise ValueError("along='angle' needs a meridian whose normal turns monotonically from the pole "
                             "to the rim; give the positions along the arc")
    top = coordinate[-1]
    if np.any(x < -1e-9 * top) or np.any(x > top * (1 + 1e-6)):
        unit = "rad" if along == "angle" else "R_L"
        raise ValueError(f"thickness table positions along the {along} must lie in [0, {top:.6g}] {unit} "
                         f"(pole to rim); got [{x.min():.6g}, {x.max():.6g}]")
    return np.interp(np.clip(x, 0.0, top), coordinate, S)


def _meridian(scene, S):
    """The reference meridian's (R, Z, R', Z') at S, without code generation."""
    if getattr(scene.shell, "kind", None) == "user":
        import sympy as sp

        from symbolic.geometry import S as s_symbol

        g = scene.shell.geometry
        exprs = (g.R, g.Z, sp.diff(g.R, s_symbol), sp.diff(g.Z, s_symbol))
        return tuple(np.broadcast_to(np.asarray(sp.lambdify(s_symbol, e, "numpy")(S), float), S.shape)
                     for e in exprs)
    gamma = -scene.gamma if scene.closed else scene.gamma
    return np.sin(S), -gamma * np.cos(S), np.cos(S), gamma * np.sin(S)


def read_profile_table(path, R_L: float):
    """Rows of a thickness file: ``(positions, thickness in units of R_L, along)``.

    A text file of two columns with a header naming them and their units:
    ``arc_um, thickness_um`` (any length unit the package reads: m, mm, um, nm), or
    ``angle_deg``/``angle_rad``, or ``S`` (the package's coordinate, no unit), then
    ``thickness_<unit>``.  At most :data:`MAX_TABLE_ROWS` rows.
    """
    text = _read_text(path)
    lines = [ln.strip() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no rows")
    header = [h.strip() for h in lines[0].replace(";", ",").replace("\t", ",").split(",")]
    if len(header) != 2:
        raise ValueError(f"{path}: the header must name 2 columns (position, thickness_<unit>); "
                         f"got {len(header)}")
    pos_name, thk_name = header

    def length_scale(name, what):
        prefix, _, unit = name.rpartition("_")
        if unit not in LENGTH_UNITS:
            raise ValueError(f"{path}: column {name!r}: {what} needs a length unit "
                             f"({', '.join(LENGTH_UNITS)}), e.g. {prefix or what}_um")
        return LENGTH_UNITS[unit] / R_L

    if pos_name == "S":
        along, pos_scale = "S", 1.0
    elif pos_name.startswith("angle_") and pos_name in ("angle_deg", "angle_rad"):
        along, pos_scale = "angle", math.pi / 180 if pos_name.endswith("deg") else 1.0
    elif pos_name.startswith("arc_"):
        along, pos_scale = "arc", length_scale(pos_name, "the arc length")
    else:
        raise ValueError(f"{path}: the first column must be arc_<unit>, angle_deg, angle_rad or S; "
                         f"got {pos_name!r}")
    if not thk_name.startswith("thickness_"):
        raise ValueError(f"{path}: the second column must be thickness_<unit>; got {thk_name!r}")
    thk_scale = length_scale(thk_name, "the thickness")
    rows = lines[1:]
    if not 2 <= len(rows) <= MAX_TABLE_ROWS:
        raise ValueError(f"{path}: a thickness table has 2 to {MAX_TABLE_ROWS} rows; got {len(rows)}")
    data = []
    for k, ln in enumerate(rows, start=2):
        cells = ln.replace(";", ",").replace("\t", ",").split(",")
        try:
            values = [float(c) for c in cells]
        except ValueError:
            raise ValueError(f"{path}: row {k}: two numbers expected; got {ln[:60]!r}") from None
        if len(values) != 2 or not all(map(math.isfinite, values)):
            raise ValueError(f"{path}: row {k}: two finite numbers expected; got {ln[:60]!r}")
        data.append(values)
    data = np.array(data)
    return data[:, 0] * pos_scale, data[:, 1] * thk_scale, along


def _read_text(path, limit=1 << 20):
    with open(path, "rb") as f:
        raw = f.read(limit + 1)
    if len(raw) > limit:
        raise ValueError(f"{path}: a thickness table is at most {limit} bytes")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not UTF-8 text") from None
