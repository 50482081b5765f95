"""The boundary conditions of a chain: each junction's rows (``bc``) and their analytic
Jacobians (``bc_jac``), then the control's row and the volume's, as
:class:`~shellbvp.chain.ChainBVP` (which inherits them) assembles them (the rows' order:
:mod:`shellbvp.chain`)."""

from __future__ import annotations

import numpy as np

from ..edge_models import edge_model
from .blocks import FREE_STATES, ContactPole, Edge, FreePole, Kink, Line, PointPole, Rim, Seam, TipEnd

__all__ = ["BoundaryConditions"]

_LS = FREE_STATES.index("ls")
# states continuous across a line contact (rQ jumps: the ring force)
_LINE_CONTINUOUS = [FREE_STATES.index(s) for s in ("lt", "phiS", "ls", "ks", "z")]
# states continuous across an interior corner (ls, ks jump)
_KINK_CONTINUOUS = [FREE_STATES.index(s) for s in ("lt", "phiS", "rQ", "z")]
_PHIS, _RQ, _Z = (FREE_STATES.index(s) for s in ("phiS", "rQ", "z"))
# a closed shell's equator (Seam): states equal across it, and states opposite in the mirror image
_SEAM_EQUAL = [FREE_STATES.index(s) for s in ("lt", "ls", "ks")]
_SEAM_OPPOSITE = [FREE_STATES.index(s) for s in ("rQ", "z")]
# the generated rim rows are (lt - 1, the moment's m, z); a clamped rim holds its slope instead
# of M_s = 0: phi/S - Phi(L)/L, linear in the states and free of the run-time parameters.  A
# closed shell's equator (the half above it solved, symmetric about it) holds its slope too (the
# tangent vertical), moves out freely (no horizontal force: r Q = 0) and moves by delta/2 towards
# the indenter (z = -delta/2), so that delta is the approach of the indenter and the support.
_RIM_CIRCLE_ROW, _RIM_MOMENT_ROW, _RIM_Z_ROW = 0, 1, 2


class BoundaryConditions:
    """``bc`` and ``bc_jac`` of a :class:`~shellbvp.chain.ChainBVP`: its base, using its layout
    (``rows``, ``offsets``, ``S_point``, ``quantities``, ``par_at``)."""

    @staticmethod
    def _prefix(kind):
        """Generated names of cylinder edges carry ``cyl_`` (``junction_cyl_smooth_res``), of a
        closed shell's edge on its substrate ``plane_``."""
        return {"cylinder": "cyl_", "plane": "plane_"}.get(kind, "")

    def _edge_delta(self, j, q):
        """The indenter's delta at an edge: the substrate's plane does not move (0)."""
        return 0.0 if self.regions[j.kc].kind == "plane" else q["delta"]

    @staticmethod
    def _line_delta(j, q):
        """The indenter's delta at a line contact: the substrate's plane does not move (0)."""
        return 0.0 if j.on == "plane" else q["delta"]

    def _pole_function(self, j, what):
        return getattr(self.models[j.k], f"{self._prefix(self.regions[j.k].kind)}pole_{what}")

    def _edge_function(self, j, what):
        """junction_[cyl_]<model>_<what> of an edge, by its contact region's kind."""
        return j.model.function(self.models[j.kc], self._prefix(self.regions[j.kc].kind), what)

    # -- conditions -------------------------------------------------------------------------------
    def _edge_states(self, j: Edge, ya, yb):
        """(point, yc, yf, contact state at start?, free state at start?) of an edge."""
        rc, rf = self.rows(j.kc), self.rows(j.kf)
        if j.kc < j.kf:
            return self.regions[j.kc].end, yb[rc], ya[rf], False, True
        return self.regions[j.kc].start, ya[rc], yb[rf], True, False

    def _line_states(self, j: Line, ya, yb, q):
        yin = yb[self.rows(j.k)]
        return self.regions[j.k].end, np.array([q[j.chi], yin[_LS]]), yin, ya[self.rows(j.k + 1)]

    def bc(self, ya, yb, p=None):
        par_all = self.par_at(p)
        q = self.quantities(p)
        parts = []
        for j in self.junctions:
            mod = self._junction_model(j)
            par = self.half_par(par_all, self._junction_k(j))
            if isinstance(j, ContactPole):
                y0 = ya[self.rows(j.k)]
                parts.append(self._pole_function(j, "res")(y0[0], y0[1], q[j.stretch], par))
            elif isinstance(j, FreePole):
                parts.append(mod.free_pole_res(self.S_point(self.regions[j.k].start, p), ya[self.rows(j.k)], par))
            elif isinstance(j, PointPole):
                parts.append(mod.point_load_res(self.S_point(self.regions[j.k].start, p), ya[self.rows(j.k)],
                                                q["delta"] if j.moving else 0.0, par))
            elif isinstance(j, Edge):
                point, yc, yf, _, _ = self._edge_states(j, ya, yb)
                parts.append(self._edge_function(j, "res")(self.S_point(point, p), yc, yf, self._edge_delta(j, q),
                                                           q["F"], par))
            elif isinstance(j, TipEnd):
                parts.append(mod.tip_end_res(self.S_point(self.regions[j.k].end, p), yb[self.rows(j.k)],
                                             ya[self.rows(j.k + 1)], par))
            elif isinstance(j, Line):
                point, yc, yin, yout = self._line_states(j, ya, yb, q)
                on_tip = self._line_function(j, "res")(self.S_point(point, p), yc, yin, self._line_delta(j, q), q["F"],
                                                       par)[:3]
                parts += [on_tip, (yout - yin)[_LINE_CONTINUOUS]]
            elif isinstance(j, Kink):
                yl, yr = yb[self.rows(j.k)], ya[self.rows(j.k + 1)]
                parts += [mod.kink_res(self.S_point(self.regions[j.k].end, p), yl, yr, par),
                          (yr - yl)[_KINK_CONTINUOUS]]
            elif isinstance(j, Seam):
                yu, yl = yb[self.rows(j.ku)], yb[self.rows(j.kl)]
                (Lu, wu), (Ll, wl) = self.seam_slopes
                equal = (yu - yl)[_SEAM_EQUAL]
                if self.seam_references is not None:  # halves that differ: [tau_s] = [M_s] = 0
                    equal[1:] = self._seam_stress_jumps(j, yu, yl, par_all)[0]
                parts += [equal, (yu + yl)[_SEAM_OPPOSITE],
                          [(Lu * yu[_PHIS] + Ll * yl[_PHIS] - wu - wl) / (0.5 * (Lu + Ll))]]
            elif isinstance(j, Rim):
                parts.append(self._rim_res(self.S_point(self.regions[j.k].end, p), yb[self.rows(j.k)], par,
                                           q["delta"] if "delta" in q else 0.0))
        par = self.half_par(par_all, self._junction_k(self.force_at)) if self.force_at is not None else par_all
        if self.extra == "force":
            _, S, yc, yf, _, _ = self._force_args(ya, yb, p, q)
            parts.append(self._force_function("res")(S, yc, yf, q["delta"], q["F"], par))
        elif self.extra == "pole_stretch":
            parts.append([ya[self.rows(0)][_LS] - self.value])
        elif self.extra == "arclength":
            _, S, yc, yf, _, _ = self._force_args(ya, yb, p, q)
            force = 2 * np.pi * self._force_function("res")(S, yc, yf, q["delta"], 0.0, par)[0]
            X = np.array([q["delta"], q["lambda0"], force])
            parts.append([np.sum(self.arc_tangent * (X - self.arc_point) / self.arc_scale)])
        if self.volume_control:
            parts += [[ya[self.n_shell]], [yb[self.n_shell] - self.enclosed_volume]]
        return np.concatenate(parts)

    def _seam_stress_jumps(self, j, yu, yl, par, jac=False):
        """``tau_s`` and ``M_s`` of the upper half minus the lower's at the equator (each from
        its own module, as its corner's jumps from its undeformed state, where both vanish),
        and with ``jac`` their derivatives by ``yu`` and ``yl``."""
        (Lu, _), (Ll, _) = self.seam_slopes
        ru, rl = self.seam_references
        mu, ml = self.models[j.ku], self.models[j.kl]
        pu, pl = self.half_par(par, j.ku), self.half_par(par, j.kl)
        jumps = mu.kink_res(Lu, ru, yu, pu)[:2] - ml.kink_res(Ll, rl, yl, pl)[:2]
        if not jac:
            return jumps, None, None
        return jumps, mu.kink_jac(Lu, ru, yu, pu)[:2, 7:13], -ml.kink_jac(Ll, rl, yl, pl)[:2, 7:13]

    def _rim_res(self, S, y, par, delta):
        res = self.model.rim_res(S, y, par)
        if self.rim_slope is None:
            return res
        res = np.array(res, float)
        res[_RIM_MOMENT_ROW] = y[_PHIS] - self.rim_slope
        if self.scene.closed:
            res[_RIM_CIRCLE_ROW] = y[_RQ]
            res[_RIM_Z_ROW] = y[_Z] + 0.5 * delta
        return res

    def _rim_jac(self, S, y, par, what="jac"):
        """d/dy (``what="jac"``) or d/dpar (``"jac_par"``) of the rim rows."""
        dres = getattr(self.model, f"rim_{what}")(S, y, par)
        if self.rim_slope is None:
            return dres
        dres = np.array(dres, float)
        rows = [_RIM_MOMENT_ROW, _RIM_CIRCLE_ROW] if self.scene.closed else [_RIM_MOMENT_ROW]
        dres[rows] = 0.0
        if what == "jac":
            dres[_RIM_MOMENT_ROW, _PHIS] = 1.0
            if self.scene.closed:
                dres[_RIM_CIRCLE_ROW, _RQ] = 1.0
        return dres

    def _line_function(self, j, what):
        """A line's rows on the indenter: the smooth edge's (their first three are used)."""
        return edge_model("smooth").function(self.models[j.k], self._prefix(j.on), what)

    @staticmethod
    def _junction_k(j):
        """The region whose half a junction is on (its module, its parameters)."""
        return j.ku if isinstance(j, Seam) else j.kc if isinstance(j, Edge) else j.k

    def _junction_model(self, j):
        """The generated module of the half a junction is on (a closed shell's halves may differ)."""
        return self.models[self._junction_k(j)]

    def _force_function(self, what):
        """force_[cyl_]<what> at the last contact edge (F of the free region beyond it)."""
        j = self.force_at
        kind = self.regions[j.kc].kind if isinstance(j, Edge) else ""
        return getattr(self._junction_model(j), f"force_{self._prefix(kind)}{what}")

    def _force_args(self, ya, yb, p, q):
        """(point, S, yc, yf, free region, free state at its start?) of the force condition."""
        j = self.force_at
        if isinstance(j, Edge):
            point, yc, yf, _, f_at_a = self._edge_states(j, ya, yb)
            kf = j.kf
        else:
            point, yc, _, yf = self._line_states(j, ya, yb, q)
            kf, f_at_a = j.k + 1, True
        return point, self.S_point(point, p), yc, yf, kf, f_at_a

    def _add_p(self, P, rows, name, values):
        if name is not None and name in self.col:
            P[rows, self.col[name]] += values

    def _pressure_column(self, P, rows, dres_dpar):
        """Under volume control, a condition's derivative in the pressure (an unknown)."""
        if self.volume_control:
            P[rows, self.col["pressure"]] += dres_dpar[..., self._i_pressure]

    def bc_jac(self, ya, yb, p=None):
        par_all = self.par_at(p)
        q = self.quantities(p)
        m, n = self.n_conditions, self.n
        A, B = np.zeros((m, n)), np.zeros((m, n))
        P = np.zeros((m, self.k)) if self.k else None
        vc = self.volume_control
        r = 0
        for j in self.junctions:
            rows = slice(r, r + j.rows)
            mod = self._junction_model(j)
            par = self.half_par(par_all, self._junction_k(j))
            if isinstance(j, ContactPole):
                o = self.offsets[j.k]
                y0 = ya[self.rows(j.k)]
                pj = self._pole_function(j, "jac")(y0[0], y0[1], q[j.stretch], par)  # d/d(chi, ls, lambda0)
                A[rows, o:o + 2] = pj[:, :2]
                self._add_p(P, rows, j.stretch, pj[:, 2])
                if vc:
                    self._pressure_column(P, rows, self._pole_function(j, "jac_par")(y0[0], y0[1], q[j.stretch], par))
            elif isinstance(j, (FreePole, PointPole)):
                point = self.regions[j.k].start
                S = self.S_point(point, p)
                if isinstance(j, FreePole):
                    pj = mod.free_pole_jac(S, ya[self.rows(j.k)], par)  # d/d(y, S)
                    self._add_p(P, rows, point.unknown, pj[:, 6] * S)
                    if vc:
                        self._pressure_column(P, rows, mod.free_pole_jac_par(S, ya[self.rows(j.k)], par))
                else:
                    delta = q["delta"] if j.moving else 0.0
                    pj = mod.point_load_jac(S, ya[self.rows(j.k)], delta, par)  # d/d(y, delta)
                    if j.moving:
                        self._add_p(P, rows, "delta", pj[:, 6])
                    if vc:
                        self._pressure_column(P, rows, mod.point_load_jac_par(S, ya[self.rows(j.k)], delta, par))
                A[rows, self.rows(j.k)] = pj[:, :6]
            elif isinstance(j, Edge):
                point, yc, yf, c_at_a, f_at_a = self._edge_states(j, ya, yb)
                S = self.S_point(point, p)
                delta = self._edge_delta(j, q)
                jj = self._edge_function(j, "jac")(S, yc, yf, delta, q["F"], par)
                (A if c_at_a else B)[rows, self.rows(j.kc)] = jj[:, 1:3]
                (A if f_at_a else B)[rows, self.rows(j.kf)] = jj[:, 3:9]
                self._add_p(P, rows, point.unknown, jj[:, 0] * S)
                if self.regions[j.kc].kind != "plane":
                    self._add_p(P, rows, "delta", jj[:, 9])
                if vc:
                    dpar = self._edge_function(j, "jac_par")(S, yc, yf, delta, q["F"], par)
                    self._pressure_column(P, rows, dpar)
            elif isinstance(j, Line):
                point, yc, yin, yout = self._line_states(j, ya, yb, q)
                S = self.S_point(point, p)
                on = slice(r, r + 3)
                jj = self._line_function(j, "jac")(S, yc, yin, self._line_delta(j, q), q["F"], par)[:3]
                self._add_p(P, on, point.unknown, jj[:, 0] * S)
                self._add_p(P, on, j.chi, jj[:, 1])
                if j.on != "plane":
                    self._add_p(P, on, "delta", jj[:, 9])
                if vc:
                    self._pressure_column(P, on, self._line_function(j, "jac_par")(S, yc, yin, self._line_delta(j, q), q["F"],
                                                                                 par)[:3])
                i0, o0 = self.offsets[j.k], self.offsets[j.k + 1]
                B[on, i0:i0 + 6] = jj[:, 3:9]
                B[on, i0 + _LS] += jj[:, 2]  # ls of the contact state is the inner region's
                for row, c in enumerate(_LINE_CONTINUOUS, start=r + 3):
                    A[row, o0 + c] = 1.0
                    B[row, i0 + c] = -1.0
            elif isinstance(j, TipEnd):
                point = self.regions[j.k].end
                S = self.S_point(point, p)
                ej = mod.tip_end_jac(S, yb[self.rows(j.k)], ya[self.rows(j.k + 1)], par)  # d/d(S, yt, yw)
                B[rows, self.rows(j.k)] = ej[:, 1:3]
                A[rows, self.rows(j.k + 1)] = ej[:, 3:5]
                self._add_p(P, rows, point.unknown, ej[:, 0] * S)
                if vc:
                    self._pressure_column(P, rows, mod.tip_end_jac_par(S, yb[self.rows(j.k)], ya[self.rows(j.k + 1)],
                                                                       par))
            elif isinstance(j, Kink):
                point = self.regions[j.k].end
                S = self.S_point(point, p)
                yl, yr = yb[self.rows(j.k)], ya[self.rows(j.k + 1)]
                kj = mod.kink_jac(S, yl, yr, par)  # d/d(S, yl, yr)
                jump = slice(r, r + 3)
                B[jump, self.rows(j.k)] = kj[:, 1:7]
                A[jump, self.rows(j.k + 1)] = kj[:, 7:13]
                self._add_p(P, jump, point.unknown, kj[:, 0] * S)
                if vc:
                    self._pressure_column(P, jump, mod.kink_jac_par(S, yl, yr, par))
                l0, r0 = self.offsets[j.k], self.offsets[j.k + 1]
                for row, c in enumerate(_KINK_CONTINUOUS, start=r + 3):
                    A[row, r0 + c] = 1.0
                    B[row, l0 + c] = -1.0
            elif isinstance(j, Seam):
                ou, ol = self.offsets[j.ku], self.offsets[j.kl]
                for row, c in enumerate(_SEAM_EQUAL + _SEAM_OPPOSITE, start=r):
                    B[row, ou + c] = 1.0
                    B[row, ol + c] = -1.0 if c in _SEAM_EQUAL else 1.0
                (Lu, _), (Ll, _) = self.seam_slopes
                B[r + 5, ou + _PHIS], B[r + 5, ol + _PHIS] = Lu / (0.5 * (Lu + Ll)), Ll / (0.5 * (Lu + Ll))
                if self.seam_references is not None:  # halves that differ: [tau_s] = [M_s] = 0
                    _, du, dl = self._seam_stress_jumps(j, yb[self.rows(j.ku)], yb[self.rows(j.kl)], par_all, jac=True)
                    B[r + 1:r + 3, self.rows(j.ku)], B[r + 1:r + 3, self.rows(j.kl)] = du, dl
            elif isinstance(j, Rim):
                S = self.S_point(self.regions[j.k].end, p)
                B[rows, self.rows(j.k)] = self._rim_jac(S, yb[self.rows(j.k)], par)
                if self.scene.closed:
                    self._add_p(P, r + _RIM_Z_ROW, "delta", 0.5)
                if vc:
                    self._pressure_column(P, rows, self._rim_jac(S, yb[self.rows(j.k)], par, "jac_par"))
            r += j.rows
        par = self.half_par(par_all, self._junction_k(self.force_at)) if self.force_at is not None else par_all
        if self.extra in ("force", "arclength"):
            w = 1.0 if self.extra == "force" else 2 * np.pi * self.arc_tangent[2] / self.arc_scale[2]
            F = q["F"] if self.extra == "force" else 0.0
            point, S, yc, yf, kf, f_at_a = self._force_args(ya, yb, p, q)
            fj = w * self._force_function("jac")(S, yc, yf, q["delta"], F, par)  # d/d(Sc, yf, F)
            (A if f_at_a else B)[r, self.rows(kf)] = fj[0, 1:7]
            self._add_p(P, r, point.unknown, fj[0, 0] * S)
            if vc:
                self._pressure_column(P, r, w * self._force_function("jac_par")(S, yc, yf, q["delta"], F, par)[0])
            if self.extra == "arclength":
                w3 = self.arc_tangent / self.arc_scale  # weights of (delta, lambda0, F)
                self._add_p(P, r, "lambda0", w3[1])
                self._add_p(P, r, "delta", w3[0])
        elif self.extra == "pole_stretch":
            A[r, self.offsets[0] + _LS] = 1.0
        if vc:
            r += self.extra is not None
            A[r, self.n_shell] = 1.0
            B[r + 1, self.n_shell] = 1.0
        return (A, B, P) if P is not None else (A, B)
