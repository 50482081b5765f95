"""The paper's scenes and the issues' closed shells by name (``Scene.preset(name)``;
``shellbvp presets`` lists them): the fields of each scene as data."""

from __future__ import annotations

from .geometry import FlatTip, SphereTip
from .materials import Gent, MooneyRivlin

__all__ = ["PRESETS"]

#: The paper's scenes by name: ``{name: {"doc": description, "scene": Scene fields}}``
#: (``Scene.preset(name)``; ``shellbvp presets`` lists them).  A user shell is written as its
#: ``(R, Z, L)`` formulas, parsed when the preset is used (importing shellbvp needs no SymPy).
PRESETS = {
    "base": {"doc": "paper's base case: hemisphere, rho 0.2, beta 0.01, Mooney-Rivlin 0.1, xi 1",
             "scene": dict(gamma=1.0, rho=0.2, beta=0.01, material=MooneyRivlin(0.1), xi=1)},
    "base-xi0": {"doc": "base with the first approximation xi = 0",
                 "scene": dict(gamma=1.0, rho=0.2, beta=0.01, material=MooneyRivlin(0.1), xi=0)},
    "prolate2": {"doc": "prolate spheroid gamma = 2",
                 "scene": dict(gamma=2.0, rho=0.2, beta=0.01, material=MooneyRivlin(0.1), xi=1)},
    "fit": {"doc": "Lepidium endosperm fit case: gamma 2.5, rho 1/3",
            "scene": dict(gamma=2.5, rho=1 / 3, beta=0.01, material=MooneyRivlin(0.1), xi=1)},
    "flat": {"doc": "flat plate gamma = 0",
             "scene": dict(gamma=0.0, rho=0.2, beta=0.01, material=MooneyRivlin(0.1), xi=1)},
    "gent1": {"doc": "base with Gent Jm = 1 (strain-stiffening)",
              "scene": dict(gamma=1.0, rho=0.2, beta=0.01, material=Gent(1.0), xi=1)},
    "dome": {"doc": "dome gamma = -1, indented from the convex side",
             "scene": dict(gamma=-1.0, rho=0.2, beta=0.01, material=MooneyRivlin(0.1), xi=1)},
    "balloon": {"doc": "inflated membrane patch: a spherical cap of radius 2 clamped on its rim (half-angle 30 "
                       "degrees), indented from outside, pressure 0.1 (tau = p R^2/(4 sqrt(3 beta)) = 5.8)",
                "scene": dict(shell=("2*sin(S/2)", "2*cos(S/2)", "2*asin(1/2)"), rho=0.2, beta=1e-4,
                              material=MooneyRivlin(0.1), xi=1, pressure=0.1)},
    "cell": {"doc": "walled cell with turgor: a near-complete sphere held on a ring 144 degrees from the pole "
                    "(sphere radius 1.70), colloidal probe rho 0.34, beta 1.55e-3, pressure 0.089 (yeast-like: "
                    "radius 2.5 um, wall 0.1 um: eps = H/R_L = 0.068, beta = eps^2/3; mu H 3.3 N/m, turgor 0.2 MPa)",
             "scene": dict(shell=("sin(S)", "cos(S)", "4*pi/5"), rho=0.34, beta=1.55e-3,
                           material=MooneyRivlin(0.1), xi=1, pressure=0.089)},
    "capsule": {"doc": "sealed liquid-filled capsule: the cell's near-complete sphere with no pressure before "
                       "indenting, under volume control (the pressure rises as it is indented)",
                "scene": dict(shell=("sin(S)", "cos(S)", "4*pi/5"), rho=0.34, beta=1.55e-3,
                              material=MooneyRivlin(0.1), xi=1, sealed=True)},
    "cell-glass": {"doc": "walled cell with turgor resting on glass under a colloidal probe: a complete sphere, wall "
                          "eps = H/R = 0.04 (beta 5.3e-4), probe rho 0.34, pressure 0.15 (yeast-like: radius 2.5 um, "
                          "wall 0.1 um, probe 0.85 um, mu H 3.3 N/m, turgor 0.2 MPa)",
                   "scene": dict(closed=True, support="substrate", tip=SphereTip(), gamma=1.0, rho=0.34,
                                 beta=0.04**2 / 3, material=MooneyRivlin(0.1), xi=1, pressure=0.15)},
    "pollen": {"doc": "dry pollen grain on a substrate under a colloidal probe: a complete sphere of radius 25 um, "
                      "wall 1 um (eps 0.04, beta 5.3e-4), probe radius 2 um (rho 0.08), no pressure",
               "scene": dict(closed=True, support="substrate", tip=SphereTip(), gamma=1.0, rho=0.08,
                             beta=0.04**2 / 3, material=MooneyRivlin(0.1), xi=1)},
    "capsule-plates": {"doc": "sealed liquid-filled capsule compressed between two plates: a complete sphere, wall "
                              "eps = H/R = 0.02 (beta 1.33e-4), no pressure before compressing (volume control)",
                       "scene": dict(closed=True, support="plates", tip=FlatTip(), gamma=1.0, rho=1.0,
                                     beta=0.02**2 / 3, material=MooneyRivlin(0.1), xi=1, sealed=True)},
}
