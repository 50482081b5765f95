"""The record of a curve: its accepted points, with their error estimates.

A :class:`Recorder` only records: the continuation decides which state stands at a depth
(``shellbvp.continuation``), the recorder keeps it with its order key along the branch, gives
it an error estimate (a Richardson solve where the schedule asks for one, else one
calibrated from the neighbouring Richardson points; a point whose estimate is above tol solved
again tighter), and turns the points into a :class:`~shellbvp.io.Curve`.
"""

from __future__ import annotations

import logging
import math
import time
from typing import NamedTuple

import numpy as np

from .configurations import is_point_load
from .io import POINT_FIELDS, Curve, point_record
from .config import OPTIONS
from .pointload import solve_point_load
from .solution import Solution, calibrated_error, richardson_error
from .state import solve_from
from .steps import configuration_key

__all__ = ["Recorder", "Row", "RICHARDSON_EVERY"]

log = logging.getLogger(__name__)

#: With ``estimate_error="auto"``, a Richardson estimate at least every this many points
#: (measured: benchmarks/error_estimates.py).
RICHARDSON_EVERY = 5


class Row(NamedTuple):
    """A recorded point: its order key along the branch, its file record and flags, its state,
    and kept beside it (no state holds another) the single cap it replaced and the line
    converged at its depth beside a split state, where the curve's switches are located from."""

    key: float
    record: dict
    flags: str
    state: Solution
    cap: Solution | None = None
    line: Solution | None = None


class Recorder:
    """The accepted points of a curve (sorted into branch order at the end) and their error
    estimates (``estimate_error``: "auto", "full" or False).

    ``"auto"``: a Richardson estimate (one Newton solve on the halved mesh) at the first and
    last point, at every point whose configuration (topology, contact_edge) differs from its
    neighbour's, at point-load states and at every ``RICHARDSON_EVERY``-th point; in between,
    no solve: the larger Richardson ``error / max_residual`` of the two neighbouring Richardson
    points times the point's own residual (against tol-1e-10 references:
    ``benchmarks/results/error_estimates.md``).  A point whose estimate puts its relative F
    error above ``tol`` (small F, at the end of the small-delta leg) is solved again at a
    tighter tolerance (10 times, or twice the estimate's excess, up to three times) and
    estimated by Richardson (:meth:`_tightened`)."""

    def __init__(self, out: Curve, estimate_error, settings):
        self.out, self.estimate_error = out, estimate_error
        self.settings = settings
        self.tol = settings.tol
        self.rows = []  # Row: (order key, record, flags, solution, cap, line)
        self.since_richardson = None  # points added since the last Richardson estimate
        self.last_configuration = None
        self.last_accepted = None  # perf_counter() when the last point was accepted

    def estimated(self, sol: Solution) -> Solution:
        """``sol`` with its error estimate: the point to record (itself, or solved again tighter)."""
        if self.estimate_error and sol.success:
            configuration = configuration_key(sol)
            # point-load states too: their F error per unit residual scatters (flat preset at
            # 0.0065: a calibrated 5.4e-7 for a true 2.1e-6), and only a Richardson estimate
            # lets a point above tol be tightened
            if self.estimate_error == "full" or self.since_richardson is None \
                    or self.since_richardson >= RICHARDSON_EVERY - 1 or configuration != self.last_configuration \
                    or is_point_load(sol):
                sol = self._richardson(sol)
                self.since_richardson = 0
            else:
                sol = sol.with_(error_method="calibrated")  # values set by finish(), from the Richardson points
                self.since_richardson += 1
            self.last_configuration = configuration
        return sol

    def record(self, sol: Solution, key: float, cap: Solution | None = None, line: Solution | None = None):
        """Keep ``sol`` (and beside it the cap it replaced, the line converged at its depth);
        ``key`` orders points along the branch."""
        self.rows.append(Row(key, point_record(sol), "; ".join(sol.flags), sol, cap, line))
        self.last_accepted = time.perf_counter()

    def _richardson(self, sol):
        """Richardson estimate of ``sol``; returns the point to record: ``sol``, or, where the
        estimate puts its relative F error above tol, the same state solved again at a tighter
        tolerance (:meth:`_tightened`)."""
        sol = richardson_error(sol.system, sol, self.tol).with_(error_method="richardson")
        return self._tightened(sol) if self._above_tol(sol) else sol

    def _above_tol(self, sol):
        return bool(OPTIONS.tighten and sol.force_error > self.tol * abs(sol.force))

    #: solve_bvp bounds collocation residuals, not the error of F: where F is small (the
    #: end of the small-delta leg) its relative error can exceed tol (fit preset, delta 0.005:
    #: 1.4e-6 at tol 1e-6; flat, point-load limit at 0.005: 2.0e-6; the estimates saying so).
    #: Such a point is solved again, from itself, on the same system (same depth, or the same
    #: point of the arclength step), at a tolerance at least TIGHTEN times tighter, and tighter
    #: still by twice the factor its estimate exceeds tol by (the error falls about as fast as
    #: the tolerance: flat's point-load state at delta 2e-4 errs by 9.6e-5, 5.3e-6, 3.8e-7 and
    #: 4.5e-8 at tol 1e-6 to 1e-9); up to MAX_TIGHTENINGS times, never below MIN_TOL.
    TIGHTEN = 10.0
    MAX_TIGHTENINGS = 3
    MIN_TOL = 1e-12

    def _tightened(self, sol):
        tol, fine = self.tol, sol
        for _ in range(self.MAX_TIGHTENINGS):
            excess = fine.force_error / (self.tol * abs(fine.force))
            tol = max(self.MIN_TOL, tol / min(1000.0, max(self.TIGHTEN, 2.0 * excess)))
            finer = self._solved_again(fine, tol)
            if finer is None:
                break  # keep the last state that converged, with its estimate
            log.info("delta = %.6g: F error estimate %.2g relative > tol: solved again at tol %.2g (%.2g)",
                     fine.delta, fine.force_error / abs(fine.force), tol, finer.force_error / abs(finer.force))
            fine = finer
            if not self._above_tol(fine) or tol <= self.MIN_TOL:
                break
        return fine

    def _solved_again(self, sol, tol):
        """``sol`` solved again at ``tol`` from itself, with its Richardson estimate; None where that
        does not converge to a state of the same configuration and validity."""
        st = self.settings
        if is_point_load(sol):
            fine = solve_point_load(sol.scene, sol.delta, tol=tol, max_nodes=st.max_nodes, guess=sol,
                                    bc_tol=st.bc_tol)
        else:
            fine = solve_from(sol.system, (sol.x, sol.y, sol.p), tol=tol, max_nodes=st.max_nodes,
                              bc_tol=st.bc_tol)
        if not (fine.success and fine.valid == sol.valid
                and configuration_key(fine) == configuration_key(sol)):
            return None
        # with what the lift-off search attached (the states beside it stay in its row)
        return richardson_error(fine.system, fine, tol).with_(error_method="richardson", cap_state=sol.cap_state)

    def _estimate_calibrated(self, final):
        """Fill the calibrated points' estimates (in branch order, per configuration run).

        With ``final``, first add Richardson estimates where the branch order (known only
        now: switches are located last) puts a calibrated point at an end of the curve or
        next to another configuration.
        """
        rows = sorted((r for r in self.rows if r.state.error_method), key=lambda r: r.key)
        configurations = [configuration_key(r.state) for r in rows]
        if final and not self.out.interrupted:
            for i, sol in enumerate([r.state for r in rows]):
                at_edge = i in (0, len(rows) - 1) or configurations[i - 1] != configurations[i] \
                    or configurations[i + 1] != configurations[i]
                if sol.error_method == "calibrated" and at_edge:
                    rows[i] = self._replace(rows[i], self._richardson(sol))
        anchors = {}  # configuration -> [(key, force ratio, delta ratio)] of its Richardson points
        for (key, sol), conf in zip([(r.key, r.state) for r in rows], configurations):
            res = float(sol.max_residual)
            errors = (sol.force_error, sol.delta_error)
            ratios = (errors[0] / res, errors[1] / res) if res > 0 else (math.nan, math.nan)
            if sol.error_method == "richardson" and all(map(math.isfinite, ratios)):
                anchors.setdefault(conf, []).append((key,) + ratios)
        everywhere = [a for run in anchors.values() for a in run]
        calibrated = {}  # id of a row -> the row with its state's calibrated estimate (its record updated below)
        for i, (row, conf) in enumerate(zip(rows, configurations)):
            sol = row.state
            if sol.error_method == "calibrated":
                near = anchors.get(conf) or everywhere  # another configuration only while incomplete
                rows[i] = calibrated[id(row)] = row._replace(state=sol.with_(
                    force_error=calibrated_error(sol.max_residual, row.key, [(a[0], a[1]) for a in near]),
                    delta_error=calibrated_error(sol.max_residual, row.key, [(a[0], a[2]) for a in near])))
        self.rows = [calibrated.get(id(r), r) for r in self.rows]
        if final and not self.out.interrupted:  # calibrated points whose estimate is above tol, as above
            for row in [r for r in rows if r.state.error_method == "calibrated" and self._above_tol(r.state)]:
                self._replace(row, self._tightened(row.state))
        for r in self.rows:
            r.record.update(force_error=r.state.force_error, delta_error=r.state.delta_error,
                            error_method=r.state.error_method)

    def _replace(self, row, sol):
        """``row`` with ``sol`` as its point (in ``self.rows`` too; the cap and line beside it kept); the
        row itself if ``sol`` is its own."""
        if sol is row.state:
            return row
        new = row._replace(record=point_record(sol), flags="; ".join(sol.flags), state=sol)
        self.rows = [new if r is row else r for r in self.rows]
        return new

    def snapshot(self) -> Curve:
        self.finish(final=False)
        return self.out

    def finish(self, final: bool = True):
        if self.estimate_error == "auto":
            self._estimate_calibrated(final)
        rows = sorted(self.rows, key=lambda r: r.key)
        pts = {k: np.array([r.record[k] for r in rows]) for k in POINT_FIELDS}
        pts["valid"] = pts["valid"].astype(bool)
        for k in ("status", "nodes", "niter"):
            pts[k] = pts[k].astype(int) if len(rows) else pts[k]
        self.out.points = pts
        self.out.flags = [r.flags for r in rows]
        self.out.solutions = [r.state for r in rows]
