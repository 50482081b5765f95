"""shellbvp: indentation of thin curved hyperelastic shells as one multipoint BVP.

Quick use::

    import shellbvp as sb
    scene = sb.Scene.preset("base")
    sol = sb.solve(scene, delta=0.2)           # one state
    c = sb.curve(scene, delta_max=0.5)         # force-displacement curve
    c.to_hdf5("base.h5")
    grid = sb.sweep(scene, {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}, delta_max=0.5, out="grid.h5")
"""

from .version import __version__  # noqa: F401  (sb.__version__)

# Every public name is imported on first use (PEP 562): `import shellbvp` and the command line's
# parser cost next to nothing, so bad input is refused before numpy and SciPy load and Ctrl-C
# finds the CLI's handler in place.
_LAZY = {"curve": "continuation", "iter_curve": "continuation", "CurveRun": "continuation", "SphereTip": "geometry", "FlatTip": "geometry", "Spheroid": "geometry", "UserShell": "geometry",
         "UserTip": "geometry", "Curve": "io", "read_curve": "io", "BendingEnergy": "materials", "Gent": "materials",
         "MooneyRivlin": "materials", "NeoHookean": "materials", "RotationBending": "materials", "KoiterBending": "materials",
         "StrainEnergy": "materials", "TraceBending": "materials", "PRESETS": "presets", "Scene": "scene",
         "ThicknessProfile": "thickness_profile",
         "STATUS_MESSAGES": "solution", "Solution": "solution", "delta_bounds": "bounds", "solve": "state",
         "Dimensions": "units", "beta_from_thickness": "units", "parse_quantity": "units",
         "fit": "fitting", "FitResult": "fitting", "read_force_csv": "fitting", "fit_record": "fitting",
         "read_instrument": "instrument", "fit_files": "batch", "read_fit": "fitrecord",
         "sweep": "sweeps", "read_sweep": "sweeps", "Sweep": "sweeps",
         "fit_with_geometry": "uncertainty", "GeometryFit": "uncertainty", "convexity_limits": "convexity",
         "inflate": "inflation", "enclosed_volume": "inflation", "stability": "modal_stability", "hoop_indicator": "wrinkling", "HoopIndicator": "wrinkling", "Stability": "modal_stability", "options": "config", "Options": "config", "fe_curve": "fe", "FECurve": "fe", "validate": "validation",
         "Validation": "validation", "read_validation": "validation"}


def __getattr__(name):
    import importlib

    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    # any registered material or bending energy (a module of shellbvp.materials: sb.Yeoh)
    materials = importlib.import_module(".materials", __name__)
    for value in (*materials.MATERIALS.values(), *materials.BENDINGS.values()):
        if value.__name__ == name:
            globals()[name] = value
            return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "Scene",
    "ThicknessProfile",
    "solve",
    "delta_bounds",
    "inflate",
    "enclosed_volume",
    "stability",
    "Stability",
    "hoop_indicator",
    "HoopIndicator",
    "curve",
    "iter_curve",
    "options",
    "Options",
    "CurveRun",
    "fe_curve",
    "FECurve",
    "validate",
    "Validation",
    "read_validation",
    "Curve",
    "read_curve",
    "fit",
    "FitResult",
    "read_force_csv",
    "read_instrument",
    "fit_record",
    "fit_files",
    "read_fit",
    "sweep",
    "read_sweep",
    "Sweep",
    "fit_with_geometry",
    "GeometryFit",
    "Dimensions",
    "beta_from_thickness",
    "parse_quantity",
    "Solution",
    "STATUS_MESSAGES",
    "PRESETS",
    "MooneyRivlin",
    "NeoHookean",
    "Gent",
    "StrainEnergy",
    "TraceBending",
    "RotationBending",
    "KoiterBending",
    "BendingEnergy",
    "convexity_limits",
    "Spheroid",
    "SphereTip",
    "FlatTip",
    "UserShell",
    "UserTip",
]
