"""How a curve is computed: its settings as one frozen record.

:func:`shellbvp.iter_curve` checks its arguments and builds a :class:`CurveSettings` once; the
continuation passes it down to the legs, steps, the recorder and the switch search, which read
it and never change it.  What a step learns (the switches located, the stability found, the
time taken) is returned to the continuation, or recorded on the curve, never stored into it.

A curve's file keeps its settings as a JSON object (``Curve.settings``: these fields, with what
the run learned beside them); :meth:`CurveSettings.to_dict` and :meth:`CurveSettings.from_dict`
convert at that boundary, so files written before this record read as before.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, fields

__all__ = ["CurveSettings"]


@dataclass(frozen=True)
class CurveSettings:
    """The settings of one curve, checked by :func:`shellbvp.iter_curve` (see it for each one's
    meaning and default).

    Examples
    --------
    >>> from shellbvp.curve_settings import CurveSettings
    >>> st = CurveSettings(tol=1e-6, max_nodes=10000, delta_max=0.5, force_max=None, lambda0_max=None,
    ...                    max_steps=400, delta_start=0.05, delta_min=0.005, ds_max=0.05, estimate_error="auto",
    ...                    mode="adaptive", eps=1e-8, bc_tol=1e-10, topology="auto")
    >>> st.solver == dict(tol=1e-6, max_nodes=10000, bc_tol=1e-10)
    True
    >>> CurveSettings.from_dict({**st.to_dict(), "wall_time": 1.5}) == st  # what a run learned is left out
    True
    """

    #: solve_bvp's tolerance at every point
    tol: float
    #: solve_bvp's largest mesh at every point
    max_nodes: int
    #: the pole displacement where the curve stops
    delta_max: float
    #: the force where the curve stops (None: no such rule)
    force_max: float | None
    #: the Lagrange multiplier lambda0 where the curve stops (None: no such rule)
    lambda0_max: float | None
    #: the largest number of continuation steps
    max_steps: int
    #: the depth of an adaptive curve's first point
    delta_start: float
    #: where the small-delta leg ends
    delta_min: float
    #: the largest arclength step in (delta, lambda0, F)
    ds_max: float
    #: "auto", "full" or False: the points' error estimates
    estimate_error: str | bool
    #: "adaptive" (pseudo-arclength) or "deltas" (the requested depths only)
    mode: str
    #: the finite-difference step of the Jacobians (from ``tol``)
    eps: float
    #: solve_bvp's tolerance on the boundary conditions
    bc_tol: float
    #: "auto" (the valid configuration recorded at each depth) or "cap" (single caps only)
    topology: str

    @property
    def solver(self) -> dict:
        """The keywords of a single solve: ``tol``, ``max_nodes`` and ``bc_tol``."""
        return dict(tol=self.tol, max_nodes=self.max_nodes, bc_tol=self.bc_tol)

    def to_dict(self) -> dict:
        """The settings as the curve file's JSON object holds them (in field order)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_dict(cls, d: dict) -> CurveSettings:
        """The record of a curve file's settings (``Curve.settings``); the keys of what the run
        learned (switches, stability, times) are left out, and a field with a default that an
        older file lacks takes its default.

        Raises
        ------
        ValueError
            If a setting without a default is missing.
        """
        missing = [f.name for f in fields(cls) if f.name not in d and f.default is MISSING]
        if missing:
            raise ValueError(f"curve settings lack {', '.join(missing)}")
        return cls(**{f.name: d[f.name] for f in fields(cls) if f.name in d})
