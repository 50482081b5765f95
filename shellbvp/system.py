r"""The indentation problem as ONE multipoint BVP for ``scipy.integrate.solve_bvp``.

Layout (the one place it is defined)
------------------------------------
Both regions are mapped geometrically onto ``t in [0, 1]`` (tiny caps and the
pole stay well conditioned; ``ln Sc`` is the unknown):

* contact region ``S = Sc * eps**(1 - t)``, from the pole start ``zeta = eps Sc`` to Sc;
* free region    ``S = Sc * (L/Sc)**t``, from Sc to the rim L.

``y`` has 8 rows: ``y[0:2]`` the contact states ``(chi, ls)`` and ``y[2:8]``
the free states ``(lt, phiS, ls, ks, rQ, z)`` (see ``symbolic.equations``).
At ``t = 0`` the rows hold the pole start and the free region's start (Sc+);
at ``t = 1`` the contact end (Sc-) and the rim.

Unknown parameters ``p`` by control mode (k of them):

=========  =====================================  ==========================
control    p                                      conditions (8 + k)
=========  =====================================  ==========================
delta      (ln Sc, lambda0)                       pole 2, contact line 5, rim 3
lambda0    (ln Sc, delta)                         pole 2, contact line 5, rim 3
force      (ln Sc, lambda0, delta)                the 10 above + force 1
arclength  (ln Sc, lambda0, delta)                the 10 above + arclength 1
=========  =====================================  ==========================

The residual vector is ordered ``[pole(2), contact line(5), rim(3), extra(1)?]``.
The arclength condition (pseudo-arclength continuation) is
``sum_i t_i (X_i - Xhat_i)/s_i = 0`` over ``X = (delta, lambda0, F)`` with a unit
tangent ``t``, a predicted point ``Xhat`` and scales ``s``; ``value`` is then the
tuple ``(Xhat, t, s)``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MultipointBVP", "CONTROLS"]

CONTROLS = ("delta", "lambda0", "force", "arclength")
N_CONTACT, N_FREE = 2, 6
N = N_CONTACT + N_FREE


class MultipointBVP:
    """fun, fun_jac, bc, bc_jac of one scene, control mode and prescribed value.

    Parameters
    ----------
    scene : Scene
    control : {"delta", "lambda0", "force"}
    value : float
        The prescribed delta, lambda0 or F.
    eps : float
        Pole start ``zeta = eps * Sc``.
    """

    def __init__(self, scene, control: str, value: float, eps: float):
        if control not in CONTROLS:
            raise ValueError(f"control must be one of {CONTROLS}; got {control!r}")
        self.scene = scene
        self.model = mod = scene.model()
        self.par = scene.parameters(mod)
        self.control = control
        if control == "arclength":
            xhat, tangent, scale = (np.asarray(v, float) for v in value)
            self.arc_point, self.arc_tangent, self.arc_scale = xhat, tangent, scale
            self.value = float("nan")
        else:
            self.value = float(value)
        self.eps = float(eps)
        self.ln_eps = math.log(eps)
        self.L = scene.shell_length
        self.ln_L = math.log(self.L)
        self._jres = getattr(mod, f"junction_{scene.contact}_res")
        self._jjac = getattr(mod, f"junction_{scene.contact}_jac")
        self.k = 3 if control in ("force", "arclength") else 2
        self.n_conditions = N + self.k

    # -- parameters -------------------------------------------------------------------
    def unpack(self, p):
        """(ln Sc, lambda0, delta, F) from the unknowns and the prescribed value."""
        if self.control == "delta":
            return p[0], p[1], self.value, 0.0
        if self.control == "lambda0":
            return p[0], self.value, p[1], 0.0
        if self.control == "arclength":
            return p[0], p[1], p[2], 0.0
        return p[0], p[1], p[2], self.value

    def pack(self, ln_Sc, lambda0, delta):
        if self.control == "delta":
            return np.array([ln_Sc, lambda0])
        if self.control == "lambda0":
            return np.array([ln_Sc, delta])
        return np.array([ln_Sc, lambda0, delta])

    @property
    def _i_lambda0(self):
        return {"delta": 1, "lambda0": None, "force": 1, "arclength": 1}[self.control]

    @property
    def _i_delta(self):
        return {"delta": None, "lambda0": 1, "force": 2, "arclength": 2}[self.control]

    # -- the maps -----------------------------------------------------------------------
    def S_contact(self, t, ln_Sc):
        return np.exp(ln_Sc + (1.0 - t) * self.ln_eps)

    def S_free(self, t, ln_Sc):
        return np.exp(ln_Sc + t * (self.ln_L - ln_Sc))

    # -- ODE ------------------------------------------------------------------------------
    def fun(self, t, y, p):
        mod, par, ln_Sc = self.model, self.par, p[0]
        Lf = self.ln_L - ln_Sc
        f = np.empty_like(y)
        f[:N_CONTACT] = -self.ln_eps * mod.contact_rhs(self.S_contact(t, ln_Sc), y[:N_CONTACT], par)
        f[N_CONTACT:] = Lf * mod.free_rhs(self.S_free(t, ln_Sc), y[N_CONTACT:], par)
        return f

    def fun_jac(self, t, y, p):
        mod, par, ln_Sc = self.model, self.par, p[0]
        Lc, Lf = -self.ln_eps, self.ln_L - ln_Sc
        Sc_t, Sf_t = self.S_contact(t, ln_Sc), self.S_free(t, ln_Sc)
        dfdy = np.zeros((N, N, t.size))
        dfdp = np.zeros((N, self.k, t.size))
        gc_y, gc_S = mod.contact_jac(Sc_t, y[:N_CONTACT], par)
        gf_y, gf_S = mod.free_jac(Sf_t, y[N_CONTACT:], par)
        dfdy[:N_CONTACT, :N_CONTACT] = Lc * gc_y
        dfdy[N_CONTACT:, N_CONTACT:] = Lf * gf_y
        # d/d ln Sc: contact S scales with Sc; free: both S(t) and the factor ln(L/Sc) move.
        dfdp[:N_CONTACT, 0] = Lc * gc_S * Sc_t
        gf = mod.free_rhs(Sf_t, y[N_CONTACT:], par)
        dfdp[N_CONTACT:, 0] = -gf + Lf * gf_S * Sf_t * (1.0 - t)
        return dfdy, dfdp

    # -- conditions -------------------------------------------------------------------------
    def bc(self, ya, yb, p):
        mod, par = self.model, self.par
        ln_Sc, lambda0, delta, F = self.unpack(p)
        Sc = np.exp(ln_Sc)
        parts = [
            mod.pole_res(ya[0], ya[1], lambda0, par),
            self._jres(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, F, par),
            mod.rim_res(self.L, yb[N_CONTACT:], par),
        ]
        if self.control == "force":
            parts.append(mod.force_res(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, F, par))
        elif self.control == "arclength":
            # F of the state: force_res with a prescribed F of 0 is F/(2 pi).
            force = 2 * np.pi * mod.force_res(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, 0.0, par)[0]
            X = np.array([delta, lambda0, force])
            parts.append([np.sum(self.arc_tangent * (X - self.arc_point) / self.arc_scale)])
        return np.concatenate(parts)

    def bc_jac(self, ya, yb, p):
        mod, par = self.model, self.par
        ln_Sc, lambda0, delta, F = self.unpack(p)
        Sc = np.exp(ln_Sc)
        m = self.n_conditions
        A, B, P = np.zeros((m, N)), np.zeros((m, N)), np.zeros((m, self.k))
        pj = mod.pole_jac(ya[0], ya[1], lambda0, par)  # d/d(chi, ls, lambda0)
        A[0:2, 0:2] = pj[:, :2]
        if self._i_lambda0 is not None:
            P[0:2, self._i_lambda0] = pj[:, 2]
        jj = self._jjac(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, F, par)  # d/d(Sc, yc, yf, delta)
        P[2:7, 0] = jj[:, 0] * Sc
        B[2:7, :N_CONTACT] = jj[:, 1:3]
        A[2:7, N_CONTACT:] = jj[:, 3:9]
        if self._i_delta is not None:
            P[2:7, self._i_delta] = jj[:, 9]
        B[7:10, N_CONTACT:] = mod.rim_jac(self.L, yb[N_CONTACT:], par)
        if self.control == "force":
            fj = mod.force_jac(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, F, par)  # d/d(Sc, yf, F)
            P[10, 0] = fj[0, 0] * Sc
            A[10, N_CONTACT:] = fj[0, 1:7]
        elif self.control == "arclength":
            w = self.arc_tangent / self.arc_scale  # weights of (delta, lambda0, F)
            fj = 2 * np.pi * mod.force_jac(Sc, yb[:N_CONTACT], ya[N_CONTACT:], delta, 0.0, par)
            P[10, 0] = w[2] * fj[0, 0] * Sc
            A[10, N_CONTACT:] = w[2] * fj[0, 1:7]
            P[10, 1] = w[1]
            P[10, 2] = w[0]
        return A, B, P


    def end_values(self, ya, yb, p):
        """(F, delta) of a solution given its end states and unknowns."""
        ln_Sc, _, delta, F = self.unpack(p)
        ring, cap = self.model.contact_line_forces(np.exp(ln_Sc), yb[:N_CONTACT], ya[N_CONTACT:], delta, F,
                                                   self.par)
        return float(ring[0] + cap[0]), float(delta)


class PointLoadBVP:
    """The point-load limit of the smooth model: the free region alone, delta prescribed.

    When the contact cap is exponentially small (``Sc`` below ~1e-30, which
    happens as delta -> 0) the cap's own equations leave double precision and
    the state is the point-load solution to exponential accuracy.  The free
    region is then solved on ``S = s0 (L/s0)**t`` with the point-load pole
    conditions at ``s0`` (``symbolic.equations.Derivation._build_point_load``):
    6 ODEs, 3 pole + 3 rim conditions, no unknown parameter.  ``y`` holds the
    free states only.
    """

    k = 0

    def __init__(self, scene, delta: float, s0: float = 1e-12):
        self.scene = scene
        self.model = scene.model()
        self.par = scene.parameters(self.model)
        self.control = "delta"
        self.value = self.delta = float(delta)
        self.s0 = float(s0)
        self.L = scene.shell_length
        self.ln_s0, self.ln_L = math.log(s0), math.log(self.L)
        self.n_conditions = N_FREE

    def S(self, t):
        return np.exp(self.ln_s0 + t * (self.ln_L - self.ln_s0))

    def fun(self, t, y, p=None):
        return (self.ln_L - self.ln_s0) * self.model.free_rhs(self.S(t), y, self.par)

    def fun_jac(self, t, y, p=None):
        dy, _ = self.model.free_jac(self.S(t), y, self.par)
        return (self.ln_L - self.ln_s0) * dy

    def bc(self, ya, yb, p=None):
        return np.concatenate([self.model.point_load_res(self.s0, ya, self.delta, self.par),
                               self.model.rim_res(self.L, yb, self.par)])

    def end_values(self, ya, yb, p=None):
        """(F, delta): the axial force at the pole start and the prescribed delta."""
        G = self.model.free_profile(np.array([self.s0]), ya[:, None], self.par)["axial_force_2pi"][0]
        return 2 * np.pi * float(G), self.delta

    def bc_jac(self, ya, yb, p=None):
        A, B = np.zeros((N_FREE, N_FREE)), np.zeros((N_FREE, N_FREE))
        A[0:3] = self.model.point_load_jac(self.s0, ya, self.delta, self.par)[:, :N_FREE]
        B[3:6] = self.model.rim_jac(self.L, yb, self.par)
        return A, B


class LiftOffBVP:
    """Contact that has lifted off at the pole: a free inner cap, then contact, then free.

    ``topology="annulus"``: inner free cap ``[zeta, S1]``, contact annulus
    ``[S1, S2]``, outer free region ``[S2, L]``; ``y`` has 14 rows
    (inner free 6, contact 2, outer free 6) and the unknowns are
    ``p = (ln S1, ln S2)`` (+ ``delta`` under force or lambda0 control).  Maps:
    ``S = S1 eps**(1-t)``, ``S = S1 (S2/S1)**t``, ``S = S2 (L/S2)**t``.
    Conditions (16 or 17): inner pole 3 (``free_pole_res``), smooth contact
    line at S1 5 and at S2 5, rim 3, (force or lambda0 1: the stretch at the lifted pole).

    ``topology="line"``: the shell touches the indenter on one circle S1 (a
    zero-width annulus); ``y`` has 12 rows (inner free 6, outer free 6), the
    unknowns are ``p = (ln S1, chi1)`` with ``chi1 = rho omega1/S1`` the
    indenter point touched (+ ``delta``).  Conditions (14 or 15): pole 3; at S1
    the shell lies on the indenter and is tangent to it (r, phi, z: 3), and
    ``lambda_theta, phi, lambda_s, kappa_s, z`` are continuous (5) while ``rQ``
    jumps (the ring force); rim 3; (force or lambda0 1).  Unlike the annulus, kappa_s at
    the line is free (it must not exceed the indenter's: no penetration).

    ``delta`` is the indenter's displacement (the tip apex sits at
    ``Z(0) - delta``), which is the pole displacement whenever the pole touches.
    Both edges use the variational (smooth) contact-line conditions of SPEC 2b.
    """

    def __init__(self, scene, topology: str, control: str, value: float, eps: float):
        if topology not in ("annulus", "line"):
            raise ValueError(f"topology must be 'annulus' or 'line'; got {topology!r}")
        if control not in ("delta", "force", "lambda0"):
            raise ValueError(f"control must be 'delta', 'force' or 'lambda0' for {topology} contact; "
                             f"got {control!r}")
        self.scene, self.topology, self.control = scene, topology, control
        self.model = mod = scene.model()
        self.par = scene.parameters(mod)
        self.value = float(value)
        self.eps, self.ln_eps = float(eps), math.log(eps)
        self.L = scene.shell_length
        self.ln_L = math.log(self.L)
        self.n_contact = N_CONTACT if topology == "annulus" else 0
        self.n = 2 * N_FREE + self.n_contact
        self.inner = slice(0, N_FREE)
        self.contact = slice(N_FREE, N_FREE + self.n_contact)
        self.outer = slice(N_FREE + self.n_contact, self.n)
        self.k = 2 if control == "delta" else 3
        self.n_conditions = self.n + self.k
        self._jres, self._jjac = mod.junction_smooth_res, mod.junction_smooth_jac

    # -- parameters ------------------------------------------------------------------
    def unpack(self, p):
        """(ln S1, q, delta, F) with q = ln S2 (annulus) or chi1 (line)."""
        if self.control == "delta":
            return p[0], p[1], self.value, 0.0
        return p[0], p[1], p[2], self.value if self.control == "force" else 0.0

    def pack(self, ln_S1, q, delta):
        return np.array([ln_S1, q] if self.control == "delta" else [ln_S1, q, delta])

    def ln_S2(self, p):
        return p[1] if self.topology == "annulus" else p[0]

    # -- maps -----------------------------------------------------------------------------
    def S_inner(self, t, p):
        return np.exp(p[0] + (1.0 - t) * self.ln_eps)

    def S_contact(self, t, p):
        return np.exp(p[0] + t * (self.ln_S2(p) - p[0]))

    def S_outer(self, t, p):
        b = self.ln_S2(p)
        return np.exp(b + t * (self.ln_L - b))

    # -- ODE --------------------------------------------------------------------------------
    def fun(self, t, y, p):
        mod, par = self.model, self.par
        b = self.ln_S2(p)
        f = np.empty_like(y)
        f[self.inner] = -self.ln_eps * mod.free_rhs(self.S_inner(t, p), y[self.inner], par)
        if self.n_contact:
            f[self.contact] = (b - p[0]) * mod.contact_rhs(self.S_contact(t, p), y[self.contact], par)
        f[self.outer] = (self.ln_L - b) * mod.free_rhs(self.S_outer(t, p), y[self.outer], par)
        return f

    def fun_jac(self, t, y, p):
        mod, par = self.model, self.par
        a, b = p[0], self.ln_S2(p)
        n, m = self.n, t.size
        dfdy, dfdp = np.zeros((n, n, m)), np.zeros((n, self.k, m))
        ib = 1 if self.topology == "annulus" else 0  # column of ln S2
        Si = self.S_inner(t, p)
        gy, gS = mod.free_jac(Si, y[self.inner], par)
        dfdy[self.inner, self.inner] = -self.ln_eps * gy
        dfdp[self.inner, 0] = -self.ln_eps * gS * Si
        if self.n_contact:
            Sc = self.S_contact(t, p)
            gy, gS = mod.contact_jac(Sc, y[self.contact], par)
            g = mod.contact_rhs(Sc, y[self.contact], par)
            dfdy[self.contact, self.contact] = (b - a) * gy
            dfdp[self.contact, 0] = -g + (b - a) * gS * Sc * (1.0 - t)
            dfdp[self.contact, ib] += g + (b - a) * gS * Sc * t
        So = self.S_outer(t, p)
        gy, gS = mod.free_jac(So, y[self.outer], par)
        g = mod.free_rhs(So, y[self.outer], par)
        dfdy[self.outer, self.outer] = (self.ln_L - b) * gy
        dfdp[self.outer, ib] += -g + (self.ln_L - b) * gS * So * (1.0 - t)
        return dfdy, dfdp

    # -- conditions ---------------------------------------------------------------------------
    def _line_contact_state(self, q, yb_inner):
        # the indenter point touched, as a contact state (ls is not used by r, phi, z)
        return np.array([q, yb_inner[2]])

    def bc(self, ya, yb, p):
        mod, par = self.model, self.par
        ln_S1, q, delta, F = self.unpack(p)
        S1 = np.exp(np.float64(ln_S1))
        parts = [mod.free_pole_res(self.eps * S1, ya[self.inner], par)]
        if self.topology == "annulus":
            S2 = np.exp(np.float64(q))
            parts += [self._jres(S1, ya[self.contact], yb[self.inner], delta, F, par),
                      self._jres(S2, yb[self.contact], ya[self.outer], delta, F, par)]
            yc2 = yb[self.contact]
        else:
            S2 = S1
            yc2 = self._line_contact_state(q, yb[self.inner])
            cont = ya[self.outer] - yb[self.inner]
            parts += [self._jres(S1, yc2, yb[self.inner], delta, F, par)[:3], cont[[0, 1, 2, 3, 5]]]
        parts.append(mod.rim_res(self.L, yb[self.outer], par))
        if self.control == "force":
            parts.append(mod.force_res(S2, yc2, ya[self.outer], delta, F, par))
        elif self.control == "lambda0":  # the stretch at the lifted pole
            parts.append([ya[self.inner.start + 2] - self.value])
        return np.concatenate(parts)

    def bc_jac(self, ya, yb, p):
        mod, par = self.model, self.par
        ln_S1, q, delta, F = self.unpack(p)
        S1 = np.exp(np.float64(ln_S1))
        m, n = self.n_conditions, self.n
        A, B, P = np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, self.k))
        i0 = self.inner.start
        o0 = self.outer.start
        pj = mod.free_pole_jac(self.eps * S1, ya[self.inner], par)  # d/d(y, S)
        A[0:3, i0:i0 + N_FREE] = pj[:, :N_FREE]
        P[0:3, 0] = pj[:, N_FREE] * self.eps * S1
        if self.topology == "annulus":
            c0 = self.contact.start
            S2 = np.exp(np.float64(q))
            j1 = self._jjac(S1, ya[self.contact], yb[self.inner], delta, F, par)  # d/d(Sc, yc, yf, delta)
            P[3:8, 0] = j1[:, 0] * S1
            A[3:8, c0:c0 + N_CONTACT] = j1[:, 1:3]
            B[3:8, i0:i0 + N_FREE] = j1[:, 3:9]
            j2 = self._jjac(S2, yb[self.contact], ya[self.outer], delta, F, par)
            P[8:13, 1] = j2[:, 0] * S2
            B[8:13, c0:c0 + N_CONTACT] = j2[:, 1:3]
            A[8:13, o0:o0 + N_FREE] = j2[:, 3:9]
            jd = np.r_[j1[:, 9], j2[:, 9]]
            S2_col, S2v, yc2 = 1, S2, yb[self.contact]
        else:
            yc2 = self._line_contact_state(q, yb[self.inner])
            j1 = self._jjac(S1, yc2, yb[self.inner], delta, F, par)[:3]
            P[3:6, 0] = j1[:, 0] * S1
            P[3:6, 1] = j1[:, 1]  # d/d chi1
            B[3:6, i0:i0 + N_FREE] = j1[:, 3:9]
            B[3:6, i0 + 2] += j1[:, 2]  # the placeholder ls of the contact state
            for row, col in enumerate((0, 1, 2, 3, 5), start=6):
                A[row, o0 + col] = 1.0
                B[row, i0 + col] = -1.0
            jd = np.r_[j1[:, 9], np.zeros(8)]
            S2_col, S2v = 0, S1
        r0 = 3 + (10 if self.topology == "annulus" else 8)
        B[r0:r0 + 3, o0:o0 + N_FREE] = mod.rim_jac(self.L, yb[self.outer], par)
        if self.control != "delta":
            P[3:3 + jd.size, 2] = jd
        if self.control == "force":
            fj = mod.force_jac(S2v, yc2, ya[self.outer], delta, F, par)  # d/d(Sc, yf, F)
            P[r0 + 3, S2_col] += fj[0, 0] * S2v
            A[r0 + 3, o0:o0 + N_FREE] = fj[0, 1:7]
        elif self.control == "lambda0":
            A[r0 + 3, i0 + 2] = 1.0
        return A, B, P

    def edge_values(self, ya, yb, p):
        """(F, inner ring force, outer ring force, S1, S2, delta) of a solution."""
        mod, par = self.model, self.par
        ln_S1, _, delta, _ = self.unpack(p)
        S1 = float(np.exp(np.float64(ln_S1)))
        S2 = float(np.exp(np.float64(self.ln_S2(p))))
        G_out = float(mod.free_profile(np.array([S2]), ya[self.outer, None], par)["axial_force_2pi"][0])
        G_in = float(mod.free_profile(np.array([S1]), yb[self.inner, None], par)["axial_force_2pi"][0])
        if self.topology == "annulus":
            pc1 = mod.contact_profile(np.array([S1]), ya[self.contact, None], par)["axial_force_2pi"][0]
            pc2 = mod.contact_profile(np.array([S2]), yb[self.contact, None], par)["axial_force_2pi"][0]
            ring_in, ring_out = 2 * np.pi * (pc1 - G_in), 2 * np.pi * (G_out - pc2)
        else:
            ring_in, ring_out = 0.0, 2 * np.pi * (G_out - G_in)
        return 2 * np.pi * G_out, float(ring_in), float(ring_out), S1, S2, float(delta)

    def end_values(self, ya, yb, p):
        """(F, delta) of a solution."""
        values = self.edge_values(ya, yb, p)
        return values[0], values[5]
