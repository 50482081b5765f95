"""The apparent modulus against depth, E(delta), as nanite and PyJibe users read it: for each
data point beyond the contact point, the mu*H (and with a thickness E = 3 mu*H / H,
incompressible) the fitted model would need to pass through that point alone, with the fitted
contact point and baseline.  Flat over depth: the model follows the data's shape; a trend: it
does not (the fitted mu*H is then a compromise over the fitted range)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ApparentModulus", "apparent_modulus", "NEAR_CONTACT"]

#: Points where the model's force is below this fraction of its largest over the data are left
#: out: near the contact point the ratio is noise over a vanishing force.
NEAR_CONTACT = 0.02


@dataclass(frozen=True)
class ApparentModulus:
    """Per data point beyond the contact point, in depth order: ``depth`` (m, from the fitted
    contact point), ``mu_H`` (N/m: data force less baseline over the model force at mu*H = 1 N/m)
    and ``E`` (Pa, ``3 mu_H / thickness``; None without a thickness)."""
    depth: np.ndarray
    mu_H: np.ndarray
    E: np.ndarray | None


def apparent_modulus(displacement, force, unit_force, *, offset, baseline=0.0, baseline_slope=0.0,
                     thickness=None) -> ApparentModulus:
    """:class:`ApparentModulus` of the data (m, N) under a fitted model.

    Parameters
    ----------
    displacement, force : array_like
        The data fitted (m, N).
    unit_force : callable
        ``unit_force(displacement)``: the model's force (N) at mu*H = 1 N/m without the baseline
        (NaN beyond the model curve).
    offset, baseline, baseline_slope : float
        The fitted contact point (m) and baseline ``baseline + baseline_slope (d - offset)`` (N, N/m).
    thickness : float, optional
        The shell's thickness H (m), given or fitted: E = 3 mu*H / H.
    """
    d = np.asarray(displacement, float)
    f = np.asarray(force, float)
    depth = d - offset
    with np.errstate(invalid="ignore"):
        u = np.asarray(unit_force(d), float)
        beyond = (depth > 0) & np.isfinite(u) & np.isfinite(f) & (u > 0)
        if beyond.any():
            beyond &= u >= NEAR_CONTACT * np.max(u[beyond])
    order = np.argsort(depth[beyond], kind="stable")
    mu_H = ((f - baseline - baseline_slope * depth)[beyond] / u[beyond])[order]
    return ApparentModulus(depth[beyond][order], mu_H, None if not thickness else 3 * mu_H / thickness)
