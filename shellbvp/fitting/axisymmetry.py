"""The stability check of a fit (``fit(stability=True)``): the fitted scene's curve analysed for
the first loss of axisymmetric stability up to the deepest fitted depth."""

from __future__ import annotations

import numpy as np

from ..continuation import curve
from ..curve_stability import assess, verdict

__all__ = ["CHECK_DEPTHS", "check_axisymmetry"]


#: Depths of the curve :func:`check_axisymmetry` analyses
CHECK_DEPTHS = 12


def check_axisymmetry(res, deepest, tol, progress=None):
    """``res.first_instability`` and a warning where the fitted scene's curve (at
    :data:`CHECK_DEPTHS` depths to ``deepest``, stability ``"locate"``) loses axisymmetric
    stability before the deepest fitted depth ``deepest`` (delta); ``res.stability_note``: what
    was not analysed; ``res.stability_verdict``: what was found.  ``progress``: as :func:`fit`'s,
    a bar for the curve and one for the analysis of its states."""
    bar, callback = progress("stability check: curve", deepest) if progress is not None else (None, None)
    try:
        c = curve(res.scene, deltas=deepest * np.arange(1, CHECK_DEPTHS + 1) / CHECK_DEPTHS, tol=tol,
                  estimate_error=False, callback=callback)
    finally:
        if bar is not None:
            bar.close()
    bar, callback = progress("stability check: states", deepest) if progress is not None else (None, None)
    try:
        assess(c, "off" if c.interrupted else "locate", progress=None if callback is None else
               lambda delta: callback(c, c.solutions[int(np.argmin(np.abs(c.delta - delta)))]))
    finally:
        if bar is not None:
            bar.close()
    first = c.first_instability if c.first_instability is not None and c.first_instability.delta <= deepest \
        else None
    notes = [c.settings.get("stability_note", "")]
    if not c.complete:
        notes.append(f"the curve stopped at delta = {c.delta.max() if len(c) else 0:.4g} ({c.stop_reason})")
    res.first_instability, res.stability_note = first, "; ".join(filter(None, notes))
    res.stability_verdict = verdict(c)
    if first is not None:
        res.warnings.append(
            f"the fitted depths reach delta = {deepest:.4g} but the axisymmetric shell loses stability at delta = "
            f"{first.delta:.4g} (mode n = {first.mode}, displacement {res.offset + first.delta * res.R_L:.4g} m): past "
            f"it the shell is not axisymmetric and the model does not describe it; fit the data up to that depth "
            f"(--max-depth {first.delta:.4g}, a fraction of R_L; fit(max_depth={first.delta * res.R_L:.4g}) in m)")
        res.warning_codes.append("unstable_depths")
