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

    def bc_jac(self, ya, yb, p=None):
        A, B = np.zeros((N_FREE, N_FREE)), np.zeros((N_FREE, N_FREE))
        A[0:3] = self.model.point_load_jac(self.s0, ya, self.delta, self.par)[:, :N_FREE]
        B[3:6] = self.model.rim_jac(self.L, yb, self.par)
        return A, B
