"""A scene: shell, indenter, material, bending stiffness and model choices.

Nondimensional (SPEC section 2): lengths by the rim radius R_L, forces and
moments by mu R_L H, ``beta = B/(mu R_L^2)`` (``eps^2/3`` for a shell of thickness
``eps = H/R_L``: :func:`shellbvp.beta_from_thickness`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from .edge_models import EdgeModel, contact_models, edge_model
from .geometry import FlatTip, SphereTip, Spheroid, UserShell, UserTip
from .materials import MATERIALS, Bending, Material, MooneyRivlin, TraceBending, bending_class, material_class
from .model import load_module, structure_description
from .presets import PRESETS
from .scene_parameters import scene_parameter, scene_parameters
from .thickness_profile import ThicknessProfile, settle_profile
from .units import beta_from_thickness, format_in

__all__ = ["Scene", "PRESETS", "CONTACT_MODELS", "RIMS", "SUPPORTS"]

#: The contact models a scene takes (:mod:`shellbvp.edge_models`, which holds what each does)
CONTACT_MODELS = contact_models()
#: What is held at the rim S = L besides its circle (lambda_theta = 1, z = 0): ``pinned``
#: leaves the rotation free (M_s = 0), ``clamped`` holds the slope at the reference's,
#: phi(L) = Phi(L).
RIMS = ("pinned", "clamped")
#: What a closed shell rests on: a rigid plane below it (``substrate``) or a second plate,
#: moving towards the first (``plates``); a shell held on its rim has support ``rim``.
SUPPORTS = ("substrate", "plates")


def _finite(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ValueError(f"{name} must be a real number; got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite; got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Scene:
    """One indentation problem.

    Parameters
    ----------
    gamma : float
        Spheroid aspect parameter (``Z = -gamma cos S``): > 0 bowl indented
        from inside, < 0 dome, 0 flat, 1 hemisphere.  Requires
        ``gamma < 1/rho`` (first contact at the pole).  Ignored for a user shell.
    rho : float
        Indenter radius / rim radius, > 0.
    beta : float
        Bending stiffness ``B/(mu R_L^2)``, > 0 (default 0.01, or from ``thickness``).
    material : Material
        ``MooneyRivlin(alpha)``, ``NeoHookean()``, ``Gent(Jm)``, ``StrainEnergy(W)`` or any other
        material of :mod:`shellbvp.materials` (one module each, found by family name).
    xi : {0, 1}
        1: generalised tensions ``T + M kappa`` (the full theory, default);
        0: the "first approximation" ``tau = T``.
    contact : {"smooth", "paper"}
        Contact-line conditions: variational (default) or the paper's eq. jumpeqns2.
    shell, tip : optional
        ``UserShell(R, Z, L)`` / ``UserTip(A, B)``; default spheroid and sphere.
    bending : Bending, optional
        The bending energy ``B`` in ``U = W + beta B``: ``TraceBending()`` (the paper's,
        default), ``RotationBending()`` (convex in stretch and curvature), ``KoiterBending()``
        (with the Gaussian curvature's energy at the solid's Poisson ratio 1/2: for walls whose
        thickness varies) or ``BendingEnergy(formula)``.
    pressure : float
        Pressure difference ``p R_L/(mu H)`` across the shell, from the side away from
        the indenter (below it): > 0 inflates a dome or a cell indented from outside.
        It acts on the deformed midsurface (a follower load); the curve starts from the
        inflated shape (:func:`shellbvp.inflate`) and delta is measured from its pole.
        Default 0.
    sealed : bool
        Volume control: the shell encloses a fixed volume of incompressible fluid (a
        sealed capsule), the volume between it and its rim's plane in the inflated
        state at ``pressure`` (then the pressure before indenting).  While indenting,
        the pressure is an unknown of every solve (``Solution.pressure``) with the
        constraint ``V = V0``.  Default False (pressure control).
    thickness : float, optional
        The shell's thickness ``eps = H/R_L`` in (0, 0.5]: sets ``beta`` to the 3D plate's
        (:func:`shellbvp.beta_from_thickness`, ``eps^2/3`` for the built-in bending energies)
        and is kept for the 3D reference (:func:`shellbvp.fe_curve`).  Give it or ``beta``:
        both only when they agree.  ``replace(beta=...)`` drops it, ``replace(thickness=...)``
        sets beta anew.  A wall whose thickness varies: a :class:`ThicknessProfile` (or a
        formula's text, H/R_L of S and L); ``thickness`` is then the pole's, which forces,
        mu*H and beta refer to (docs/thickness.md).
    transverse_shear : bool
        Add the transverse shear compliance of a shell of that ``thickness`` (Reissner-Mindlin,
        shear factor 5/6; :mod:`shellbvp.thickness`): each state's ``shear_delta``, and fits
        and :func:`shellbvp.validate` compare forces at ``delta + shear_delta``.  It removes
        most of the model's O(eps) error against 3D elasticity (``docs/accuracy.md``).
        Needs ``thickness``.  Default False.
    rim : {"pinned", "clamped"}
        What holds the rim circle (``lambda_theta = 1``, ``z = 0`` in both): ``"pinned"`` (simply
        supported, the rotation free, ``M_s = 0``; default) or ``"clamped"`` (the slope held at the
        reference's, ``phi(L) = Phi(L)``).  Clamped is offered for the shell under pressure
        before contact (:func:`shellbvp.inflate` and its :func:`shellbvp.stability`); a solve in
        contact refuses it.
    closed : bool
        A complete spheroid instead of a shell held on its rim (a cell, a capsule, a pollen
        grain): ``gamma`` is then its polar over its equatorial semi-axis (> 0) and lengths are
        in units of its equatorial radius (``R_L``).  A ``UserShell`` is then the upper half's
        meridian, pole to equator, the lower half its mirror image
        (:meth:`UserShell.closed_problem` says what it must be), or its whole meridian from pole
        to pole (:meth:`UserShell.pole_to_pole`).  Default False.
    support : {"substrate", "plates"}, optional
        What a closed shell rests on (default ``"substrate"``, a rigid frictionless plane) or
        ``"plates"`` (compressed between two parallel plates: ``tip=FlatTip()``; with a curved
        tip, between two such indenters); delta is the approach of the indenter and the
        support.  Between plates, or on a substrate under a flat plate, the half above the
        equator is solved (symmetry: the equator stays vertical, free to move out, and moves
        by delta/2); under a curved tip on a substrate both halves are, with a contact each, as
        are a shell's whose halves differ (``UserShell.closed_halves``) between plates.
    thickness_profile : ThicknessProfile, optional
        Set from ``thickness`` when that is a profile (read it here; files store it).

    Raises
    ------
    ValueError
        Naming the parameter and its valid range.

    See Also
    --------
    Scene.preset : the paper's scenes by name (:data:`PRESETS`).

    Examples
    --------
    >>> import shellbvp as sb
    >>> scene = sb.Scene(gamma=2.5, rho=1/3, beta=0.01, material=sb.MooneyRivlin(alpha=0.1))
    >>> scene == sb.Scene.preset("fit")
    True
    >>> scene.replace(contact="paper").contact
    'paper'
    >>> round(sb.Scene(thickness=0.05).beta, 6)              # beta = eps^2/3
    0.000833
    >>> sb.Scene(rho=0)
    Traceback (most recent call last):
    ...
    ValueError: rho (indenter radius / rim radius) must be > 0; got 0
    """

    gamma: float = 1.0
    rho: float = 0.2
    beta: float = None
    material: Material = field(default_factory=lambda: MooneyRivlin(0.1))
    xi: int = 1
    contact: str = "smooth"
    shell: object = field(default_factory=Spheroid)
    tip: object = field(default_factory=SphereTip)
    bending: Bending = field(default_factory=TraceBending)
    pressure: float = 0.0
    sealed: bool = False
    thickness: float = None
    transverse_shear: bool = False
    rim: str = "pinned"
    closed: bool = False
    support: str = None
    thickness_profile: ThicknessProfile = None

    def __post_init__(self):
        # the ranges and their errors are the registry's (shellbvp.scene_parameters)
        rho = _finite("rho", self.rho)
        scene_parameter("rho").check(rho, shown=self.rho)
        if not isinstance(self.bending, Bending):
            raise ValueError(f"bending must be TraceBending(), RotationBending(), KoiterBending() or BendingEnergy(...); "
                             f"got {self.bending!r}")
        beta = self.beta
        if not isinstance(self.shell, (Spheroid, UserShell)):
            raise ValueError(f"shell must be Spheroid() or UserShell(...); got {self.shell!r}")
        settle_profile(self)
        if self.thickness is not None:
            eps = _finite("thickness", self.thickness)  # H / R_L: the scene's unit (its lab form H = eps R_L)
            scene_parameter("thickness").check(eps, shown=self.thickness)

            from_eps = beta_from_thickness(eps, 1.0, self.bending)
            if beta is not None and not math.isclose(_finite("beta", beta), from_eps, rel_tol=1e-12):
                raise ValueError(f"beta = {beta!r} and thickness = {eps!r} disagree (the thickness gives beta = "
                                 f"{from_eps:.6g}): give one of them")
            beta = from_eps
            object.__setattr__(self, "thickness", eps)
        beta = _finite("beta", 0.01 if beta is None else beta)
        scene_parameter("beta").check(beta, shown=self.beta)
        gamma = _finite("gamma", self.gamma)
        if self.xi not in (0, 1) or isinstance(self.xi, bool):
            raise ValueError(f"xi must be 0 or 1; got {self.xi!r}")
        if self.contact not in CONTACT_MODELS:
            raise ValueError(f"contact must be one of {CONTACT_MODELS}; got {self.contact!r}")
        if not isinstance(self.material, Material):
            raise ValueError(f"material must be one of {', '.join(c.__name__ for c in MATERIALS.values())}; "
                             f"got {self.material!r}")
        self.material.validate()
        if not isinstance(self.tip, (SphereTip, FlatTip, UserTip)):
            raise ValueError(f"tip must be SphereTip(), FlatTip() or UserTip(...); got {self.tip!r}")
        if isinstance(self.tip, FlatTip):
            rho = 1.0  # a plate has no radius: rho is its length scale
        object.__setattr__(self, "support", _support(self, gamma))
        if isinstance(self.shell, UserShell) and (why := self.shell.halves_problem(self)):
            raise ValueError(why)
        # First contact at the pole: kappa_theta^R(0) < B''(0)/(rho A'(0)^2).
        k_shell = self.shell.pole_curvature({"gamma": -gamma if self.closed else gamma})
        k_tip = self.tip.apex_curvature() / rho
        if not k_shell < k_tip:
            what = "gamma" if isinstance(self.shell, Spheroid) else "the shell's pole curvature"
            raise ValueError(
                f"{what} = {k_shell:g} must be < {k_tip:g} (the indenter's apex curvature, 1/rho for a "
                "sphere): otherwise the indenter touches the shell away from the pole first"
            )
        object.__setattr__(self, "gamma", gamma)
        object.__setattr__(self, "rho", rho)
        object.__setattr__(self, "beta", beta)
        object.__setattr__(self, "pressure", _finite("pressure", self.pressure))
        if not isinstance(self.sealed, (bool, np.bool_)):
            raise ValueError(f"sealed must be True (volume control) or False (pressure control); "
                             f"got {self.sealed!r}")
        object.__setattr__(self, "sealed", bool(self.sealed))
        if not isinstance(self.transverse_shear, (bool, np.bool_)):
            raise ValueError(f"transverse_shear must be True or False; got {self.transverse_shear!r}")
        if self.transverse_shear and self.thickness is None:
            raise ValueError("transverse_shear needs the shell's thickness (thickness = H / R_L in (0, 0.5])")
        object.__setattr__(self, "transverse_shear", bool(self.transverse_shear))
        if not isinstance(self.rim, str) or self.rim not in RIMS:
            raise ValueError(f"rim must be one of {RIMS}; got {self.rim!r}")

    # -- presets -----------------------------------------------------------------
    @classmethod
    def preset(cls, name: str, **overrides) -> "Scene":
        """A scene of the paper by name (:data:`PRESETS`), with optional overrides.

        Parameters
        ----------
        name : str
            ``base``, ``base-xi0``, ``prolate2``, ``fit``, ``flat``, ``gent1``, ``dome``, and
            the pressurised ``balloon`` and ``cell`` (``shellbvp presets`` lists them).
        **overrides
            Any field of :class:`Scene`.

        Examples
        --------
        >>> from shellbvp import Scene, Gent
        >>> Scene.preset("dome").gamma
        -1.0
        >>> Scene.preset("base", material=Gent(Jm=97.2), contact="paper").material
        Gent(Jm=97.2)
        >>> round(Scene.preset("fit", thickness=50 / 300).beta, 5)   # 50 um on R_L = 0.3 mm
        0.00926
        """
        if name not in PRESETS:
            raise ValueError(f"unknown preset {name!r}; choose one of {sorted(PRESETS)}")
        base = dict(PRESETS[name]["scene"])
        if isinstance(base.get("shell"), tuple):
            base["shell"] = UserShell(*base["shell"])
        if overrides.get("thickness") is not None and "beta" not in overrides:
            base.pop("beta", None)  # the thickness sets it
        base.update(overrides)
        return cls(**base)

    def replace(self, **changes) -> "Scene":
        """A copy with some fields changed (validated again).

        A new ``beta`` drops the thickness (and the transverse shear that needs it); a new
        ``thickness`` (or bending energy, with a thickness) sets beta from it.  A new thickness
        (a number) of a profiled wall scales its profile to that pole thickness.
        """
        if "beta" in changes and "thickness" not in changes:
            changes["thickness"] = None
            changes.setdefault("thickness_profile", None)
            changes.setdefault("transverse_shear", False)
        elif "beta" not in changes and ("thickness" in changes or "bending" in changes and self.thickness):
            changes["beta"] = None
        return replace(self, **changes)

    # -- serialisation -------------------------------------------------------------
    def to_dict(self) -> dict:
        """Plain data that rebuilds this scene exactly (user formulas as plain text)."""
        return {
            "gamma": self.gamma, "rho": self.rho, "beta": self.beta, "xi": self.xi,
            "contact": self.contact,
            "material": {**self.material.description(), **self.material.values()},
            "shell": self.shell.description(), "tip": self.tip.description(),
            "bending": self.bending.description(),
            **({"pressure": self.pressure} if self.pressure else {}),  # files of unpressurised scenes as before
            **({"sealed": True} if self.sealed else {}),
            **({"thickness": self.thickness} if self.thickness is not None else {}),
            **({"transverse_shear": True} if self.transverse_shear else {}),
            **({"rim": self.rim} if self.rim != "pinned" else {}),
            **({"closed": True, "support": self.support} if self.closed else {}),
            **({"thickness_profile": self.thickness_profile.to_dict()} if self.thickness_profile else {}),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        """The scene of :meth:`to_dict` data (e.g. read from a file).

        Formulas are parsed by the whitelist of ``symbolic.formula`` (plain
        text, or the srepr text of files from before plain text): data from a
        file never runs as code.  Malformed data raises ``ValueError`` naming
        the field.
        """
        def field(data, key, kind, where):
            if not isinstance(data, dict) or key not in data:
                raise ValueError(f"scene data{' ' + where.rstrip('.') if where else ''} has no {key!r}")
            value = data[key]
            if not isinstance(value, kind) or isinstance(value, bool) and bool not in kind:
                raise ValueError(f"scene data: {where}{key} must be {what[kind]}; got {value!r}")
            return value

        number, text = (int, float), (str,)
        what = {number: "a number", text: "text", (dict,): "a mapping", (int,): "an integer", (bool,): "true or false"}
        def registered(data, lookup, where):  # a material or bending energy by its registered family
            try:
                kind_of = lookup(field(data, "family", text, where))
            except ValueError as exc:
                raise ValueError(f"scene data: {exc}") from None
            return kind_of.from_data(lambda key, kind: field(data, key, kind, where))

        material = registered(field(d, "material", (dict,), ""), material_class, "material.")
        sh, tp = field(d, "shell", (dict,), ""), field(d, "tip", (dict,), "")
        kind = field(sh, "kind", text, "shell.")
        if kind == "spheroid":
            shell = Spheroid()
        elif kind == "user" and "pole_to_pole" in sh:  # the meridian as given; its halves are derived from it
            shell = UserShell.pole_to_pole(*(field(field(sh, "pole_to_pole", (dict,), "shell."), k, text,
                                                   "shell.pole_to_pole.") for k in "RZL"), legacy_srepr=True)
        elif kind == "user":
            halves = [tuple(field(h, k, text, "shell.") for k in "RZL")
                      for h in [sh] + ([field(sh, "lower", (dict,), "shell.")] if "lower" in sh else [])]
            shell = UserShell.closed_halves(*halves, legacy_srepr=True) if len(halves) == 2 else UserShell(
                *halves[0], legacy_srepr=True)
        else:
            raise ValueError(f"scene data: unknown shell kind {kind!r}")
        kind = field(tp, "kind", text, "tip.")
        if kind == "sphere":
            tip = SphereTip()
        elif kind == "flat":
            tip = FlatTip()
        elif kind == "user":
            tip = UserTip(*(field(tp, k, text, "tip.") for k in "AB"), legacy_srepr=True)
        else:
            raise ValueError(f"scene data: unknown tip kind {kind!r}")
        # files from before the choice hold no bending: the paper's
        bend = registered(d.get("bending", {"family": "trace"}), bending_class, "bending.")
        return cls(gamma=field(d, "gamma", number, ""), rho=field(d, "rho", number, ""),
                   beta=field(d, "beta", number, ""), material=material, xi=field(d, "xi", (int,), ""),
                   contact=field(d, "contact", text, ""), shell=shell, tip=tip, bending=bend,
                   pressure=field(d, "pressure", number, "") if "pressure" in d else 0.0,
                   sealed=field(d, "sealed", (bool,), "") if "sealed" in d else False,
                   thickness=field(d, "thickness", number, "") if "thickness" in d else None,
                   transverse_shear=field(d, "transverse_shear", (bool,), "") if "transverse_shear" in d
                   else False,
                   rim=field(d, "rim", text, "") if "rim" in d else "pinned",
                   closed=field(d, "closed", (bool,), "") if "closed" in d else False,
                   support=field(d, "support", text, "") if "support" in d else None,
                   thickness_profile=ThicknessProfile.from_dict(d["thickness_profile"])
                   if "thickness_profile" in d else None)

    def describe(self, R_L: float | None = None) -> str:
        """The scene in words, one line; with the rim radius ``R_L`` (m) its lengths in lab units.

        >>> import shellbvp as sb
        >>> print(sb.Scene.preset("fit", thickness=0.05).describe(R_L=0.3e-3))
        preset fit with thickness; shell: spheroidal bowl (indented from inside), rise 750 um (gamma 2.5) on a rim radius of 300 um; indenter: sphere of radius 100 um (rho 0.3333); thickness 15 um (eps 0.05, beta 0.0008333); Mooney-Rivlin alpha 0.1; smooth contact
        """
        def length(x):
            return "" if R_L is None else format_in(abs(x) * R_L, "um" if abs(x) * R_L < 1e-3 else "mm", "length")

        # only presets that could be this scene are built (a user meridian's preset parses formulas):
        # equal in the scene's own parameters but those the thickness sets
        shape_and_load = [p for p in scene_parameters().values()
                          if not p.material and p.name not in scene_parameter("thickness").sets]
        candidates = [n for n, spec in PRESETS.items()
                      if isinstance(spec["scene"].get("shell"), tuple) == isinstance(self.shell, UserShell)
                      and all(math.isclose(float(spec["scene"][p.name]), p.get(self), rel_tol=1e-12)
                              for p in shape_and_load if p.name in spec["scene"])]
        named = [n for n in candidates if Scene.preset(n) == self]
        extra = [n for n in candidates if self.thickness is not None and Scene.preset(n, thickness=self.thickness) ==
                 replace(self, transverse_shear=False)]
        parts = [f"preset {named[0]}" if named else f"preset {extra[0]} with thickness" if extra else "own scene"]
        if isinstance(self.shell, Spheroid):
            rise = f"rise {length(self.gamma)} (gamma {self.gamma:.4g})" if R_L else f"gamma {self.gamma:.4g}"
            if self.closed:
                rise = (f"polar semi-axis {length(self.gamma)} (gamma {self.gamma:.4g}) on an equatorial radius of "
                        f"{length(1.0)}" if R_L else f"gamma {self.gamma:.4g} (polar / equatorial semi-axis)")
            parts.append(f"shell: {self.shell_side()}, {rise}" + (f" on a rim radius of {length(1.0)}"
                                                                   if R_L and not self.closed else ""))
        else:
            parts.append(f"shell: {self.shell_side()}" + (f" on {'an equatorial' if self.closed else 'a rim'} radius of "
                                                           f"{length(1.0)}" if R_L else ""))
        tip = "sphere" if isinstance(self.tip, SphereTip) else "user tip"
        if isinstance(self.tip, FlatTip):
            parts.append("indenter: flat plate")
        else:
            parts.append(f"indenter: {tip} of radius {length(self.rho)} (rho {self.rho:.4g})" if R_L
                         else f"indenter: {tip}, rho {self.rho:.4g}")
        if self.thickness is not None:
            at_pole = ""
            if self.thickness_profile is not None:
                thickest = self.thickness_profile.thickest(self.shell_length)
                at_pole = (f" at the pole (forces and mu*H refer to it), up to "
                           f"{length(thickest) if R_L else f'{thickest:.4g}'} along the wall: "
                           f"{self.thickness_profile.describe()}")
            parts.append(f"thickness {length(self.thickness) + ' (eps ' if R_L else 'eps '}{self.thickness:.4g}, "
                         f"beta {self.beta:.4g}{')' if R_L else ''}{at_pole}"
                         + ("; with transverse shear" if self.transverse_shear else ""))
        else:
            parts.append(f"beta {self.beta:.4g} (no thickness given)")
        parts.append(self.material.describe())
        if not isinstance(self.bending, TraceBending):
            parts.append(f"{type(self.bending).__name__}()")
        parts.append(f"{self.contact} contact" + ("" if self.xi == 1 else ", first approximation xi 0"))
        if self.pressure or self.sealed:
            parts.append(f"pressure p R_L/(mu H) {self.pressure:g}" + (", sealed" if self.sealed else ""))
        if self.rim != "pinned":
            parts.append(f"{self.rim} rim")
        return "; ".join(parts)

    def shell_side(self) -> str:
        """Which shell the indenter meets, in words: a spheroid's ``gamma > 0`` is a bowl (pole below
        the rim, indented from inside), ``gamma < 0`` a dome (indented from outside), 0 a flat disk.

        >>> import shellbvp as sb
        >>> sb.Scene.preset("fit").shell_side(), sb.Scene.preset("dome").shell_side()
        ('spheroidal bowl (indented from inside)', 'spheroidal dome (indented from outside)')
        """
        if self.closed:
            shape = "closed spheroid" if isinstance(self.shell, Spheroid) else (
                "closed shell (user meridian" + (", pole to pole" if self.shell.meridian else "") +
                (("s" if not self.shell.meridian else "") + ", halves that differ)" if self.shell.lower else ")"))
            if self.support == "plates":
                return f"{shape} between " + ("plates" if isinstance(self.tip, FlatTip) else "two indenters")
            return f"{shape} on a substrate"
        if not isinstance(self.shell, Spheroid):
            return "user meridian"
        if self.gamma == 0:
            return "flat disk"
        return f"spheroidal {'bowl (indented from inside)' if self.gamma > 0 else 'dome (indented from outside)'}"

    def to_json(self) -> str:
        """:meth:`to_dict` as a JSON string (sorted keys)."""
        import json

        return json.dumps(self.to_dict(), sort_keys=True)

    # -- generated code ------------------------------------------------------------
    def structure(self) -> dict:
        """The structural choices the generated code is specialised on."""
        profile = self.thickness_profile.description() if self.thickness_profile is not None else None
        shell = self.shell.upper_half() if isinstance(self.shell, UserShell) else self.shell
        return structure_description(self.material, self.xi, shell, self.tip, self.bending,
                                     pressurised=self.pressurised, substrate=self.two_contacts, thickness=profile)

    @property
    def halved(self) -> bool:
        """A closed shell solved on the half above its equator: between two plates (or two
        identical tips), or on a substrate under a flat plate (the same problem); not a shell
        whose halves differ (``UserShell.closed_halves``), which has no mirror symmetry."""
        return (self.closed and (self.support == "plates" or isinstance(self.tip, FlatTip))
                and getattr(self.shell, "lower", None) is None)

    @property
    def two_contacts(self) -> bool:
        """A closed shell on a substrate under a curved tip, or one whose halves differ between
        plates (on a substrate under a flat plate): both halves solved, two contacts."""
        return self.closed and not self.halved

    @property
    def pressurised(self) -> bool:
        """Whether the generated code carries the pressure (a pressure, or volume control)."""
        return self.pressure != 0 or self.sealed

    def model(self):
        """The generated module for this scene's structure (cached)."""
        return load_module(self.structure())

    def values(self) -> dict:
        """Continuous (run-time) parameters by name (a closed shell's upper half is the dome
        ``Z = gamma cos S``: its meridian's gamma is ``-gamma``)."""
        v = {p.name: p.get(self) for p in scene_parameters().values() if not p.material}
        v.update(self.material.values(), pole_rise=0.0)
        if self.closed:
            v["gamma"] = -self.gamma
        return v

    def parameters(self, model=None, *, pole_rise: float = 0.0) -> np.ndarray:
        """Run-time parameter vector in the order of the generated functions.

        ``pole_rise``: where the indenter finds the pole before indenting, above ``Z(0)``.
        Under pressure that is the inflated state's, which a system's parameters carry
        (:func:`shellbvp.inflation.system_parameters` solves it once per scene); a scene
        itself solves nothing.
        """
        model = model or self.model()
        v = self.values()
        v["pole_rise"] = float(pole_rise)
        return np.array([v[name] for name in model.PARAMS], dtype=float)

    def reference_volume(self) -> float:
        """V of the undeformed shell, ``-pi Int R^2 Z' dS``: the volume between it and its rim's
        plane (the origin of the pressure's potential ``-p (V - V_ref)``)."""
        return _reference_volume(self)

    @property
    def contact_model(self) -> EdgeModel:
        """The contact model's object (:mod:`shellbvp.edge_models`): what its edge conditions
        are and what a curve does with them."""
        return edge_model(self.contact)

    @property
    def tip_omega_max(self) -> float:
        """Where the tip joins the indenter's cylinder (A' = 0): pi/2 for the sphere."""
        return self.tip.omega_max

    @property
    def shell_length(self) -> float:
        """L, the reference meridian's length parameter."""
        if isinstance(self.shell, Spheroid):
            return math.pi / 2
        return float(self.shell.geometry.L)


def _support(scene, gamma) -> str:
    """``Scene.support`` checked: ``rim`` for a shell held on its rim, else one of SUPPORTS."""
    if not isinstance(scene.closed, (bool, np.bool_)):
        raise ValueError(f"closed must be True (a complete shell) or False (held on its rim); got {scene.closed!r}")
    object.__setattr__(scene, "closed", bool(scene.closed))
    if not scene.closed:
        if scene.support not in (None, "rim"):
            raise ValueError(f"support={scene.support!r} needs closed=True; a shell held on its rim has support 'rim'")
        if isinstance(scene.shell, UserShell) and scene.shell.meridian is not None:
            raise ValueError("shell: a meridian from pole to pole (UserShell.pole_to_pole) is a closed shell's: it needs "
                             "closed=True (--closed)")
        return "rim"
    support = "substrate" if scene.support is None else scene.support
    if support not in SUPPORTS:
        raise ValueError(f"support must be one of {SUPPORTS} for a closed shell; got {support!r}")
    if isinstance(scene.shell, UserShell) and (why := scene.shell.closed_problem()):  # its upper half
        raise ValueError(why)
    if isinstance(scene.shell, Spheroid) and not gamma > 0:
        raise ValueError(f"gamma (polar / equatorial semi-axis of a closed spheroid) must be > 0; got {gamma!r}")
    if support == "substrate" and not isinstance(scene.tip, FlatTip) and not scene.contact_model.variational:
        raise ValueError(f"contact={scene.contact!r}: a closed shell on a substrate under a curved tip has the smooth "
                         "(variational) contact model only")
    if scene.rim != "pinned":
        raise ValueError(f"rim={scene.rim!r} holds a rim; a closed shell has none")
    return support


@functools.lru_cache(maxsize=64)
def _reference_volume(scene) -> float:
    from scipy.integrate import quad

    mod = scene.model()
    par = scene.parameters(mod, pole_rise=0.0)
    value, _ = quad(lambda S: float(mod.reference_shell(S, par)["volume_density"]), 0.0, scene.shell_length,
                    epsabs=1e-13, epsrel=1e-12, limit=200)
    return value
