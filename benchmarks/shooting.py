r"""Shooting: the paper's own method, as an independent peer for the benchmarks.

This re-solves the indentation problem with ``lambda0`` (the pole stretch)
prescribed, the way the paper did (its section 3), and shares nothing with
``shellbvp``'s collocation machinery (``shellbvp.chain`` / ``shellbvp.state``)
except the generated equations: the right-hand sides ``g = S dy/dS`` of both
regions, their Jacobians and the pole, contact-line and rim conditions.

Method, for one lambda0
-----------------------
1. Contact region (on the tip), states ``(chi, ls)``: start at ``S = zeta =
   eps*Sc`` from the leading term of the pole series (``chi = c*lambda0``,
   ``ls = lambda0``, ``c = -pole_res(0, 0, 1)``; truncation error O(eps^2)
   relative) and integrate to Sc in ``tau = ln(S/Sc)`` (``dy/dtau = g``).
2. Contact line: the free region's start ``yf(Sc+)`` (states ``lt, phiS, ls,
   ks, rQ, z``) has one free component ``u`` -- ``rQ`` for ``contact="smooth"``
   (r, phi, z, lambda_s, kappa_s continuous; Q jumps), ``ks`` for
   ``contact="paper"`` (r, phi, z, Q continuous; lambda_s from [tau_s] = 0).
   The other five solve the generated junction residual (5 equations) by
   Newton with its analytic Jacobian (the linear rows converge in one step;
   the paper's [tau_s] = 0 row for ``ls_f`` starts from the contact value).
   ``delta = 0`` there, i.e. ``z`` is measured with the tip at ``z_tip = Z(0)``;
   delta then follows from ``z(L) = 0``.
3. Free region: integrate from Sc to L in ``tau = ln(S/Sc)/ln(L/Sc)`` (so the
   interval is [0, 1] whatever Sc).  ``solve_ivp`` with 'DOP853' by default:
   in ln S the system is not stiff for moderate beta (eigenvalues of dg/dy are
   O(1..10) on the base scene), but it has growing, oscillating modes.
4. Newton on ``x = (ln Sc, u)`` for the rim conditions ``lambda_theta(L) = 1``,
   ``M_s(L) = 0`` (``rim_res`` rows 0, 1).  Jacobian: exact, from the
   variational equations integrated alongside (d/d(ln Sc, u, lambda0) through
   both regions and the junction, including the moving start of the free
   interval; generated ``*_jac``), or Broyden updates of it
   (``jacobian="broyden"``).  Steps are damped (backtracking,
   ``|d ln Sc| <= 0.5``); trial states that leave the tip, become singular or
   fail to integrate within a budget are rejected.
5. ``delta = z(L)`` and ``F = 2 pi G``, ``G = r sin(phi) tau_s - r cos(phi) Q``
   at the rim (``free_profile``'s ``axial_force_2pi``; a first integral, so its
   drift between Sc+ and L is reported, ``force_defect``).  States with
   delta < 0 (the spurious "collapsed" branch) are reported as failures.

Continuation in lambda0 (:func:`shoot_curve`) uses the exact tangent
``d(ln Sc, u)/d lambda0 = -J_x^{-1} J_lambda0`` as predictor.  Without a guess,
:func:`shoot_state` uses a homotopy in beta (see ``_cold_start``): crude
guesses essentially never converge (see below).

What shooting meets (measured on the base preset; benchmarks/results/shooting.md)
----------------------------------------------------------------------------------
* The shooting map is extremely sensitive: d M_s(L)/d rQ(Sc+) ~ 8600 (smooth,
  lambda0 = 1.05); Newton's basin is ~1e-3 relative in u.  Warm starts from the
  neighbour at d lambda0 = 0.01 *without* a predictor fail (smooth: 0/3; paper:
  1/3, the others end on the collapsed branch or cannot be integrated); with
  the tangent predictor all converge in 3-6 iterations.
* Poor guesses make the trajectory singular (lambda_s -> infinity where the
  2x2 system for (lambda_s', kappa_s') degenerates, or r -> 0); the step size of
  the integrator collapses -- hence a guard event and an evaluation budget.
* The growing modes amplify integration errors: delta errs by up to ~100-1000
  rtol (the rim conditions are enforced, the other outputs inherit the error).
* Small beta: ||dres/dx|| grows like exp(c/sqrt(beta)): 5e5 at beta = 3e-3,
  3e8 at 1e-3, 5e12 at 3e-4, 1e13-1e16 at 1e-4.  From beta <= 3e-4 shooting
  fails even when started at the exact (collocation) answer (the residual
  there is O(1..100) at rtol 1e-10) -- the paper's "singular perturbation".

No exception is raised for non-convergence: ``success``, ``status`` and
``message`` say what happened.

Run as a script to validate against ``sb.solve`` and time both::

    python benchmarks/shooting.py [--quick] [--out benchmarks/results/shooting.json]
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ["ShootState", "ShootCurve", "Shooter", "shoot_state", "shoot_curve"]

# Index of the free unknown ``u`` in the free state (lt, phiS, ls, ks, rQ, z).
_UNKNOWN = {"smooth": 4, "paper": 3}
_NF, _NC = 6, 2

STATUS = {
    0: "converged",
    1: "Newton did not converge in max_iter iterations",
    2: "Newton stalled: no step reduced the residual (guess too far, or a fold in lambda0)",
    3: "integration failed at the guess (singular or non-finite trajectory, or the cap left the tip)",
    4: "converged to a spurious collapsed state",
}


@dataclass
class ShootState:
    """One shooting solution (lambda0 prescribed)."""

    lambda0: float
    delta: float = math.nan
    F: float = math.nan
    Sc: float = math.nan
    u: float = math.nan           # rQ(Sc+) (smooth) or kappa_s(Sc+) (paper)
    success: bool = False
    status: int = 3
    message: str = ""
    wall_time: float = 0.0
    nfev: int = 0                 # right-hand-side evaluations (augmented systems), all regions
    niter: int = 0                # Newton iterations
    residual: float = math.nan    # max |rim residual| at the end
    force_defect: float = math.nan  # |2 pi (G(L) - G(Sc+))|
    contact: str = "smooth"
    rtol: float = math.nan

    @property
    def x(self):
        return np.array([math.log(self.Sc), self.u])

    def as_dict(self):
        return asdict(self)


@dataclass
class ShootCurve:
    """Result of :func:`shoot_curve`: arrays over the requested lambda0 values."""

    states: list = field(default_factory=list)

    def _arr(self, key):
        return np.array([getattr(s, key) for s in self.states])

    def __getattr__(self, key):
        if key in ("lambda0", "delta", "F", "Sc", "u", "success", "wall_time", "nfev", "niter",
                   "residual", "force_defect"):
            return self._arr(key)
        raise AttributeError(key)


class _Budget(Exception):
    """An integration used more right-hand-side evaluations than allowed."""


def _free_guard(tau, w):
    """> 0 while the free trajectory is plausible: stretches in (0.05, 10), states bounded.

    Poor guesses make the 2x2 system for (ls', ks') singular (ls -> infinity) or the
    deformed radius vanish within the interval; stopping there keeps failures cheap.
    """
    return min(w[0] - 0.05, w[2] - 0.05, 10.0 - w[0], 10.0 - w[2],
               1e3 - max(abs(w[1]), abs(w[3]), abs(w[4])))


def _contact_guard(tau, w):
    return min(w[1] - 0.05, 10.0 - w[1], 1e3 - abs(w[0]))


class Shooter:
    """Shooting for one scene at fixed integration tolerances.

    The shooting unknowns are ``x = (ln Sc, u, lambda0)``; Newton solves the two
    rim conditions for two of them with the third fixed (lambda0 for the
    paper's procedure; Sc in the cold start's homotopy).

    Parameters
    ----------
    scene : shellbvp.Scene
    rtol, atol : float
        ``solve_ivp`` tolerances (atol defaults to rtol; the states are O(1)).
    method : str
        ``solve_ivp`` method.  The problem is not stiff in ln S for moderate beta
        (eigenvalues of dg/dy are O(1..10) on the base scene, but with growing,
        oscillating modes), so the default is the explicit 'DOP853'; 'Radau',
        'BDF', 'LSODA' get an analytic (block-diagonal) Jacobian of the augmented
        system.
    eps : float
        Pole start ``zeta = eps*Sc``; default ``min(1e-3, 0.1 sqrt(rtol))`` (the
        leading-order start errs by O(eps^2)).
    max_fev : int
        Right-hand-side evaluations allowed per integration (a poor guess can make
        the trajectory singular; the step size then collapses).
    jacobian : {"broyden", "newton"}
        How Newton gets the shooting Jacobian (see :meth:`newton`).
    """

    def __init__(self, scene, rtol=1e-8, atol=None, method="DOP853", eps=None, max_fev=20000,
                 jacobian="newton"):
        self.scene = scene
        self.model = mod = scene.model()
        self.par = np.array(scene.parameters(mod), float)
        self.i_beta = list(mod.PARAMS).index("beta")
        self.contact = scene.contact
        self.k_u = _UNKNOWN[self.contact]
        self.det = [i for i in range(_NF) if i != self.k_u]  # components fixed by the junction
        self.jres = getattr(mod, f"junction_{self.contact}_res")
        self.jjac = getattr(mod, f"junction_{self.contact}_jac")
        self.L = float(scene.shell_length)
        self.lnL = math.log(self.L)
        self.omega_max = float(scene.tip_omega_max)
        self.rho = float(scene.rho)
        self.rtol = float(rtol)
        self.atol = float(rtol if atol is None else atol)
        self.method = method
        self.eps = min(1e-3, 0.1 * math.sqrt(rtol)) if eps is None else float(eps)
        self.ln_eps = math.log(self.eps)
        self.z_tip0 = float(mod.reference_shell(0.0, self.par)["Z"])  # z_tip at delta = 0
        self.c_pole = -mod.pole_res(0.0, 0.0, 1.0, self.par)           # y(pole) = c lambda0
        self.max_fev = int(max_fev)
        if jacobian not in ("broyden", "newton"):
            raise ValueError(f"jacobian must be 'broyden' or 'newton'; got {jacobian!r}")
        self.jacobian = jacobian
        self.nfev = 0
        self.trace = False
        self.implicit = method in ("Radau", "BDF", "LSODA")

    @property
    def beta(self):
        return float(self.par[self.i_beta])

    @beta.setter
    def beta(self, value):
        self.par[self.i_beta] = value

    # -- region 1: the contact region --------------------------------------------------------
    def contact_end(self, lnSc, lambda0, sens=True):
        """(chi, ls) at Sc and their derivatives (2, 2) by (ln Sc, lambda0) (None if not sens).

        tau = ln(S/Sc) from ln eps to 0; the start (the pole series) is fixed in tau.
        """
        mod, par = self.model, self.par
        Sc = math.exp(lnSc)
        if not sens:
            sol = self._ivp(lambda tau, y: mod.contact_rhs(Sc * math.exp(tau), y, par), None,
                            (self.ln_eps, 0.0), self.c_pole * lambda0, _contact_guard)
            return None if sol is None else (sol.y[:, -1], None)
        w0 = np.zeros(_NC * 3)
        w0[:_NC] = self.c_pole * lambda0
        w0[_NC:].reshape(_NC, 2)[:, 1] = self.c_pole

        def f(tau, w):
            S = Sc * math.exp(tau)
            y = w[:_NC]
            g = mod.contact_rhs(S, y, par)
            J, gS = mod.contact_jac(S, y, par)
            dW = J @ w[_NC:].reshape(_NC, 2)
            dW[:, 0] += gS * S
            return np.r_[g, dW.ravel()]

        def jac(tau, w):
            J, _ = mod.contact_jac(Sc * math.exp(tau), w[:_NC], par)
            return _block_jac(J, 1.0, 2)

        sol = self._ivp(f, jac, (self.ln_eps, 0.0), w0, _contact_guard)
        if sol is None:
            return None
        w = sol.y[:, -1]
        return w[:_NC], w[_NC:].reshape(_NC, 2)

    # -- the contact line --------------------------------------------------------------------
    def free_start(self, lnSc, u, yc, dyc=None):
        """yf(Sc+) with yf[k_u] = u, and d yf / d(ln Sc, u, lambda0) (6, 3); None if unsolvable.

        The five other components solve the generated junction residual (delta = 0) by
        Newton with its analytic Jacobian, from the contact side's values.
        """
        mod, par = self.model, self.par
        Sc = math.exp(lnSc)
        pc = mod.contact_profile(np.array([Sc]), yc[:, None], par)
        r, phi = float(pc["r"][0]), float(pc["phi"][0])
        R = float(mod.reference_shell(Sc, par)["R"])
        yf = np.array([r / R, phi / Sc, float(pc["lambda_s"][0]), float(pc["kappa_s"][0]),
                       r * float(pc["Q"][0]), float(pc["z"][0]) + self.z_tip0])
        yf[self.k_u] = u
        det = self.det
        cols = [3 + i for i in det]
        with np.errstate(all="ignore"):
            for _ in range(30):
                res = self.jres(Sc, yc, yf, 0.0, 0.0, par)
                if not np.all(np.isfinite(res)):
                    return None
                A = self.jjac(Sc, yc, yf, 0.0, 0.0, par)[:, cols]
                try:
                    step = np.linalg.solve(A, res)
                except np.linalg.LinAlgError:
                    return None
                yf[det] -= step
                if np.max(np.abs(step)) <= 1e-14 * (1 + np.max(np.abs(yf))):
                    break
            else:
                return None
            res = self.jres(Sc, yc, yf, 0.0, 0.0, par)
            if not (np.all(np.isfinite(yf)) and np.max(np.abs(res)) < 1e-11) or yf[2] <= 0:
                return None
            if dyc is None:
                return yf, None
            jj = self.jjac(Sc, yc, yf, 0.0, 0.0, par)
            A = jj[:, cols]
            # 0 = dres/dSc Sc dlnSc + dres/dyc dyc + dres/dyf dyf
            rhs = np.zeros((5, 3))
            rhs[:, 0] = jj[:, 0] * Sc + jj[:, 1:3] @ dyc[:, 0]
            rhs[:, 1] = jj[:, 3 + self.k_u]
            rhs[:, 2] = jj[:, 1:3] @ dyc[:, 1]
            D = np.zeros((_NF, 3))
            D[det] = -np.linalg.solve(A, rhs)
            D[self.k_u, 1] = 1.0
        return yf, D

    # -- region 2: the free region -----------------------------------------------------------
    def free_end(self, lnSc, yf0, D0):
        """yf(L) and d yf(L) / d(ln Sc, u, lambda0), with S = Sc (L/Sc)^tau, tau in [0, 1]."""
        mod, par = self.model, self.par
        Sc = math.exp(lnSc)
        Lf = self.lnL - lnSc
        if D0 is None:
            sol = self._ivp(lambda tau, y: Lf * mod.free_rhs(Sc * math.exp(Lf * tau), y, par), None,
                            (0.0, 1.0), yf0, _free_guard)
            return None if sol is None else (sol.y[:, -1], None)

        def f(tau, w):
            S = Sc * math.exp(Lf * tau)
            y = w[:_NF]
            g = mod.free_rhs(S, y, par)
            J, gS = mod.free_jac(S, y, par)
            dV = Lf * (J @ w[_NF:].reshape(_NF, 3))
            # the mapped right-hand side depends on ln Sc explicitly (the interval moves)
            dV[:, 0] += -g + Lf * gS * S * (1.0 - tau)
            return np.r_[Lf * g, dV.ravel()]

        def jac(tau, w):
            J, _ = mod.free_jac(Sc * math.exp(Lf * tau), w[:_NF], par)
            return _block_jac(J, Lf, 3)

        sol = self._ivp(f, jac, (0.0, 1.0), np.r_[yf0, D0.ravel()], _free_guard)
        if sol is None:
            return None
        w = sol.y[:, -1]
        return w[:_NF], w[_NF:].reshape(_NF, 3)

    def _ivp(self, f, jac, span, y0, guard=None):
        """solve_ivp with a budget; None if it fails, blows up or trips the guard event."""
        count = [0]
        budget = self.max_fev

        def fc(t, w):
            count[0] += 1
            if count[0] > budget:
                raise _Budget
            return f(t, w)

        kw = dict(method=self.method, rtol=self.rtol, atol=self.atol)
        if self.implicit and jac is not None:
            kw["jac"] = jac
        if guard is not None:
            guard.terminal = True
            kw["events"] = guard
        try:
            with np.errstate(all="ignore"):
                sol = solve_ivp(fc, span, y0, **kw)
        except (_Budget, ValueError, ZeroDivisionError, FloatingPointError, np.linalg.LinAlgError):
            self.nfev += count[0]
            return None
        self.nfev += count[0]
        if sol.status != 0 or not np.all(np.isfinite(sol.y[:, -1])):
            return None
        return sol

    # -- the shooting map --------------------------------------------------------------------
    def shoot(self, x, sens=True):
        """Rim residual (lt - 1, m) at L and its Jacobian (2, 3) by x = (ln Sc, u, lambda0).

        None when the trajectory cannot be computed (cap off the tip, singular or
        non-finite trajectory, junction unsolvable).  ``sens=False``: no Jacobian (J None;
        the states alone, about 4x cheaper).
        """
        lnSc, u, lambda0 = (float(v) for v in x)
        if not (lnSc < self.lnL - 1e-3 and math.isfinite(u) and lambda0 > 0):
            return None
        Sc = math.exp(lnSc)
        ce = self.contact_end(lnSc, lambda0, sens)
        if ce is None:
            return None
        yc, dyc = ce
        if not (0 < Sc * yc[0] / self.rho < self.omega_max):
            return None  # the cap has left the tip
        fs = self.free_start(lnSc, u, yc, dyc)
        if fs is None:
            return None
        yf0, D0 = fs
        fe = self.free_end(lnSc, yf0, D0)
        if fe is None:
            return None
        yL, VL = fe
        res = self.model.rim_res(self.L, yL, self.par)[:2]
        J = None if VL is None else self.model.rim_jac(self.L, yL, self.par)[:2] @ VL
        if not (np.all(np.isfinite(res)) and (J is None or np.all(np.isfinite(J)))):
            return None
        return dict(res=res, J=J, yc=yc, yf0=yf0, yL=yL, x=np.array([lnSc, u, lambda0]))

    def newton(self, x0, free=(0, 1), max_iter=30, xtol=None, J0=None):
        """Damped (quasi-)Newton on the components ``free`` of x (the third is held).

        ``self.jacobian == "newton"``: every iterate is shot with the variational
        equations (exact Jacobian, quadratic convergence).  ``"broyden"``: iterates are
        shot without them (about 4x cheaper, see ``shoot``) and the Jacobian -- ``J0``
        (e.g. the neighbouring state's) or one variational shot at x0 -- gets Broyden
        updates; it is recomputed exactly when a step fails.

        Returns (status, niter, info) with info = the last shoot() result (None if the
        guess itself could not be integrated).  Convergence: a (full) step below ``xtol``
        (default 10 rtol, relative to 1 + |x|) -- that last step is taken, with a
        states-only shoot, so the result errs by O(step^2) -- or, at the integrator's
        noise floor where exact-Jacobian steps stop shrinking, a step below 100 rtol.
        Steps smaller than 1e-4 (relative) with an exact Jacobian are taken in full; larger
        ones are damped until the residual decreases.  (The
        outputs are sensitive: on the base scene d delta / d rQ(Sc+) ~ 150, so a
        looser test on x, e.g. a step predicted from quadratic convergence, left
        delta errors of 2e-5 at rtol 1e-8.)
        """
        xtol = 10 * self.rtol if xtol is None else xtol
        free = list(free)
        broyden = self.jacobian == "broyden"
        x0 = np.asarray(x0, float)
        if broyden and J0 is not None:
            cur = self.shoot(x0, sens=False)
            if cur is not None:
                cur["J"], fresh = np.array(J0, float), False
        else:
            cur, fresh = self.shoot(x0), True
        if cur is None:
            return 3, 0, None
        it = 0
        prev_near, prev_floor = None, False
        while it < max_iter:
            it += 1
            res, J, x = cur["res"], cur["J"], cur["x"]
            nrm = np.max(np.abs(res))
            try:
                dxf = -np.linalg.solve(J[:, free], res)
            except np.linalg.LinAlgError:
                dxf = np.full(len(free), np.nan)
            if not np.all(np.isfinite(dxf)):
                if fresh:
                    return 2, it, cur
                cur, fresh = self._refresh(cur), True
                if cur is None:
                    return 3, it, None
                continue
            dx = np.zeros(3)
            dx[free] = dxf
            size = np.max(np.abs(dx) / (1 + np.abs(x)))
            if self.trace:
                print(f"  {'broyden' if broyden else 'newton'} {it}: |res| {nrm:.2e} |dx| {size:.2e} "
                      f"nfev {self.nfev}{' (fresh J)' if fresh else ''}")
            near = fresh and size <= _NEAR
            floor = near and prev_near is not None and size > 0.5 * prev_near
            if size <= xtol or (floor and size <= 100 * self.rtol):
                # last step: states only (its error is O(size^2)); at the integrator's
                # noise floor (steps no longer shrink) the residual need not decrease
                final = self.shoot(x + dx, sens=False)
                if final is not None:
                    final["J"] = J
                    return 0, it, final
                return 0, it, cur
            if floor and prev_floor:
                return 2, it, cur
            prev_near, prev_floor = (size if near else None), floor
            scale = min(1.0, 0.5 / max(abs(dx[0]), 1e-300), 0.2 / max(abs(dx[2]), 1e-300))
            dx *= scale
            lam, accepted = 1.0, None
            while lam >= (1.0 / 64 if fresh else 0.25):
                trial = self.shoot(x + lam * dx, sens=not broyden)
                # close to the solution with an exact Jacobian: full steps (the residual
                # is dominated by integration noise there, a decrease test would stall)
                if trial is not None and (near or np.max(np.abs(trial["res"])) < (1 - 0.1 * lam) * nrm):
                    accepted = trial
                    break
                lam *= 0.5
            if accepted is None:
                if not fresh:  # the quasi-Newton direction was poor: exact Jacobian, retry
                    cur, fresh = self._refresh(cur), True
                    if cur is None:
                        return 3, it, None
                    continue
                return 2, it, cur
            if broyden:
                if np.max(np.abs(accepted["res"])) > 0.5 * nrm:
                    # slow progress: the secant Jacobian has drifted; take an exact one
                    accepted, fresh = self._refresh(accepted), True
                    if accepted is None:
                        return 3, it, None
                else:
                    step = accepted["x"] - x
                    sf = step[free]
                    Jn = J.copy()
                    Jn[:, free] += np.outer(accepted["res"] - res - J @ step, sf) / (sf @ sf)
                    accepted["J"], fresh = Jn, False
            cur = accepted
        return 1, max_iter, cur

    def _refresh(self, cur):
        """Re-shoot at cur's x with the variational equations (exact Jacobian)."""
        return self.shoot(cur["x"])

    def state(self, status, niter, info, lambda0, t0, nfev):
        """A ShootState from a Newton result."""
        st = ShootState(lambda0=float(lambda0), contact=self.contact, rtol=self.rtol,
                        status=status, niter=niter, success=status == 0, message=STATUS[status],
                        nfev=nfev, wall_time=time.perf_counter() - t0)
        if info is None:
            return st
        x = info["x"]
        mod, par = self.model, self.par
        G0 = mod.free_profile(np.array([math.exp(x[0])]), info["yf0"][:, None], par)["axial_force_2pi"]
        GL = mod.free_profile(np.array([self.L]), info["yL"][:, None], par)["axial_force_2pi"]
        st.lambda0 = float(x[2])
        st.Sc, st.u = math.exp(x[0]), float(x[1])
        st.delta = float(info["yL"][5])      # z(L) with the tip at Z(0); z(L) - delta = 0
        st.F = 2 * math.pi * float(GL[0])
        st.force_defect = 2 * math.pi * abs(float(GL[0]) - float(G0[0]))
        st.residual = float(np.max(np.abs(info["res"])))
        if st.success and st.delta < 0:
            st.status, st.success = 4, False
            st.message = STATUS[4] + f": delta = {st.delta:.3g} < 0"
        return st

    def solve(self, lambda0, guess, max_iter=30):
        """One state at lambda0 from guess = (ln Sc, u)."""
        t0, self.nfev = time.perf_counter(), 0
        status, niter, info = self.newton(np.r_[guess[0], guess[1], lambda0], (0, 1), max_iter)
        return self.state(status, niter, info, lambda0, t0, self.nfev)

    # -- continuation ------------------------------------------------------------------------
    def tangent(self, info):
        """d(ln Sc, u)/d lambda0 at a converged state (from the exact Jacobian)."""
        J = info["J"]
        return -np.linalg.solve(J[:, :2], J[:, 2])

    def march(self, info, target, max_steps=200, h0=None):
        """Natural continuation in lambda0 from a converged state to ``target``.

        Tangent predictor, adaptive steps (x1.5 after an easy success, halved after a
        failure).  Returns (status, niter_total, info at the target or the last state).
        """
        lam = info["x"][2]
        h = (target - lam) if h0 is None else math.copysign(h0, target - lam)
        niter = 0
        for _ in range(max_steps):
            if lam == target:
                return 0, niter, info
            h = math.copysign(min(abs(h), abs(target - lam)), target - lam)
            nxt = lam + h
            pred = info["x"][:2] + h * self.tangent(info)
            status, it, new = self.newton(np.r_[pred, nxt], (0, 1), J0=info["J"])
            niter += it
            if status == 0 and _jumped(info, new, np.r_[pred, nxt]):
                status = 2  # left the branch (e.g. to a collapsed state): smaller step
            if status == 0:
                info, lam = new, nxt
                if it <= 3:
                    h *= 1.5
            else:
                h /= 2
                if abs(h) < 1e-6:
                    return 2, niter, info
        return 1, niter, info


def _jumped(old, new, pred):
    """Did a continuation step leave the branch?  The corrector went far from the
    predictor (|d ln Sc| > 0.2 or |d lambda0| > 0.05, or u by more than 20 %), or delta
    turned negative (the spurious "collapsed" states of SPEC section 3)."""
    d = np.abs(new["x"] - pred)
    return bool(d[0] > 0.2 or d[2] > 0.05 or d[1] > 0.2 * (abs(old["x"][1]) + 0.05)
                or new["yL"][5] < 0 <= old["yL"][5])


_NEAR = 1e-4  # relative Newton step below which exact-Jacobian steps are taken in full


def _block_jac(J, factor, ncols):
    """Block-diagonal approximation of the augmented system's Jacobian (state + ncols columns)."""
    n = J.shape[0]
    out = np.zeros((n * (1 + ncols), n * (1 + ncols)))
    out[:n, :n] = factor * J
    for j in range(ncols):
        idx = n + np.arange(n) * ncols + j
        out[np.ix_(idx, idx)] = factor * J
    return out


def _cold_start(sh, lambda0, beta_start=1.0, loose_rtol=1e-6, verbose=False):
    """Find a first state at ``lambda0`` without a guess.

    Shooting's basin of attraction is tiny for small beta (the free region has growing,
    oscillating modes: on the base scene d M_s(L)/d rQ(Sc+) ~ 1e4, so Newton needs rQ to
    ~1e-4), and crude guesses fail.  Homotopy, at the loose tolerance ``loose_rtol``: at a
    fixed cap size Sc0 = rho/2 on a stiff shell (beta = beta_start) the shooting map is
    nearly linear; solve there for (u, lambda0) from crude guesses, continue in ln beta
    down to the scene's beta at fixed Sc0, then in lambda0 to the target; finally Newton
    at the shooter's own tolerance.  Returns (status, niter, info); ``sh.nfev`` counts all.
    """
    lo = Shooter(sh.scene, rtol=max(sh.rtol, loose_rtol), method=sh.method, max_fev=5000)
    lo.par = sh.par.copy()
    beta_t = lo.beta
    lnSc0 = math.log(0.5 * lo.rho)
    niter = 0
    us = (-0.2, -0.5, 0.0, -1.0) if lo.contact == "smooth" else (0.0, -1.0, 1.0, -2.0)

    def done(status, info):
        sh.nfev += lo.nfev
        return status, niter, info

    found = None
    lo.beta = max(beta_t, beta_start)
    for lam0 in (0.8, 0.65, 1.0):
        for u in us:
            status, it, info = lo.newton(np.r_[lnSc0, u, lam0], (1, 2), max_iter=20)
            niter += it
            if status == 0:
                found = info
                break
        if found is not None:
            break
    if found is None:
        return done(3, None)
    info = found
    # continuation in ln beta at fixed Sc (secant predictor in (u, lambda0))
    lb, lb_t = math.log(lo.beta), math.log(beta_t)
    h, prev = -0.5, None
    while lb > lb_t:
        h = max(h, lb_t - lb)
        nb = lb + h
        x = info["x"].copy()
        if prev is not None:
            x[1:] += (x[1:] - prev[1][1:]) * h / (lb - prev[0])
        lo.beta = math.exp(nb)
        status, it, new = lo.newton(x, (1, 2))
        niter += it
        if status == 0 and _jumped(info, new, x):
            status = 2
        if status == 0:
            prev, info, lb = (lb, info["x"]), new, nb
            if verbose:
                print(f"beta {lo.beta:.3g} lambda0 {new['x'][2]:.4f} u {new['x'][1]:.4g}")
            if it <= 3:
                h *= 1.5
        else:
            lo.beta = math.exp(lb)
            h /= 2
            if h > -1e-3:
                return done(2, None)
    lo.beta = beta_t
    status, it, info = lo.march(info, lambda0, h0=0.02)
    niter += it
    if status != 0:
        return done(status, None)
    sh.nfev += lo.nfev
    status, it, info = sh.newton(info["x"], (0, 1))
    return status, niter + it, info


def shoot_state(scene, lambda0, rtol=1e-8, guess=None, *, atol=None, method="DOP853", eps=None,
                jacobian="newton", max_iter=30, shooter=None):
    """One state with the pole stretch lambda0 prescribed, by shooting.

    guess : ShootState, or (Sc, u) with u = rQ(Sc+) (smooth) or kappa_s(Sc+) (paper).
        Without it the state is found by a homotopy (see ``_cold_start``), much more
        expensive than a warm start: shooting needs a guess very close to the answer.
    Returns a :class:`ShootState` (never raises for non-convergence).
    """
    sh = shooter or Shooter(scene, rtol=rtol, atol=atol, method=method, eps=eps, jacobian=jacobian)
    if guess is not None:
        x0 = guess.x if isinstance(guess, ShootState) else np.array([math.log(guess[0]), guess[1]])
        return sh.solve(lambda0, x0, max_iter=max_iter)
    t0, sh.nfev = time.perf_counter(), 0
    status, niter, info = _cold_start(sh, lambda0)
    st = sh.state(status, niter, info if status == 0 else None, lambda0, t0, sh.nfev)
    if status != 0:
        st.message = "cold start failed: " + st.message
    return st


def shoot_curve(scene, lambda0s, rtol=1e-8, *, guess=None, **kw):
    """States at the given lambda0 values, each warm-started from its neighbour.

    The first state starts from ``guess`` (a ShootState or (Sc, u)) or, without one, from
    the cold-start homotopy; each later one from the previous converged state with the
    tangent predictor (exact, from the shooting Jacobian); when that fails, by
    continuation in lambda0 with smaller steps.  ``wall_time``/``nfev`` of a state count
    all the work done for it.  Returns a :class:`ShootCurve`.
    """
    sh = Shooter(scene, rtol=rtol, **kw)
    out = ShootCurve()
    info = None
    for lam in lambda0s:
        t0, sh.nfev = time.perf_counter(), 0
        if info is None:
            if guess is not None:
                x0 = guess.x if isinstance(guess, ShootState) else (math.log(guess[0]), guess[1])
                status, niter, new = sh.newton(np.r_[x0[0], x0[1], lam], (0, 1))
            else:
                status, niter, new = _cold_start(sh, lam)
        else:
            status, niter, new = sh.march(info, lam)
        if status == 0:
            st = sh.state(status, niter, new, lam, t0, sh.nfev)
            if st.success:  # not a collapsed state
                info = new
        else:  # do not report a neighbour's (or an unconverged iterate's) values
            st = sh.state(status, niter, None, lam, t0, sh.nfev)
            if info is not None:
                st.message += f" (continuation from lambda0 = {info['x'][2]:.6g})"
        out.states.append(st)
    return out


# ---------------------------------------------------------------------------------------------
# Validation against the collocation solver and timing (run as a script)
# ---------------------------------------------------------------------------------------------

def _timed(fn, repeat):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _validate(lambdas=(1.0, 1.05, 1.1), rtols=(1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
              tols=(1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8), ref_tol=1e-10, step=0.01, repeat=3,
              jacobians=("newton", "broyden"), method="DOP853", log=print):
    """Both solvers on the base preset, both contact models, against sb.solve at ref_tol.

    Each state is solved warm from its neighbour at lambda0 - step (not timed):
    collocation ``sb.solve(..., guess=neighbour, estimate_error=False)``; shooting one
    continuation step (tangent predictor from the neighbour, its Jacobian for Broyden)
    -- and, for information, plain Newton from the neighbour's (ln Sc, u) ("no predictor").
    Times are the best of ``repeat``.
    """
    import shellbvp as sb

    rows = []
    for contact in ("smooth", "paper"):
        scene = sb.Scene.preset("base", contact=contact)
        scene.model()
        refs = {l: sb.solve(scene, lambda0=l, tol=ref_tol) for l in lambdas}
        for l, r in refs.items():
            assert r.success, r.message
            rows.append(dict(contact=contact, solver="reference", tol=ref_tol, lambda0=l, F=r.force,
                             delta=r.delta, Sc=r.Sc, F_err_est=r.force_error,
                             delta_err_est=r.delta_error, time=r.wall_time))
        # cold start of the shooting (once per contact model), timed
        l_start = lambdas[0] - step
        cold = shoot_state(scene, l_start, 1e-8)
        rows.append(dict(contact=contact, solver="shooting-cold", tol=1e-8, lambda0=l_start,
                         success=bool(cold.success), time=cold.wall_time, nfev=cold.nfev,
                         niter=cold.niter, message=cold.message, F=cold.F, delta=cold.delta))
        log(f"{contact}: shooting cold start {cold.wall_time:.1f} s, {cold.nfev} fev ({cold.message})")
        if not cold.success:
            continue
        for tol in tols:
            for l in lambdas:
                nb = sb.solve(scene, lambda0=l - step, tol=tol, estimate_error=False)
                t, s = _timed(lambda: sb.solve(scene, lambda0=l, tol=tol, guess=nb,
                                               estimate_error=False), repeat)
                rows.append(dict(contact=contact, solver="collocation", tol=tol, lambda0=l,
                                 success=bool(s.success), dF=abs(s.force - refs[l].force),
                                 ddelta=abs(s.delta - refs[l].delta), time=t,
                                 nodes=int(s.nodes), niter=int(s.niter)))
            log(f"{contact}: collocation tol {tol:g} done")
        for jac in jacobians:
            for rtol in rtols:
                sh = Shooter(scene, rtol=rtol, method=method, jacobian=jac)
                status, _, info = sh.newton(np.r_[cold.x, l_start], (0, 1))
                for l in lambdas:
                    if info is not None and status == 0:
                        status, _, nb = sh.march(info, l - step)
                    if info is None or status != 0:
                        rows.append(dict(contact=contact, solver=f"shooting-{jac}", tol=rtol,
                                         lambda0=l, success=False, message="neighbour failed"))
                        break

                    def one(nb=nb, l=l):
                        t0, sh.nfev = time.perf_counter(), 0
                        stt, it, new = sh.march(nb, l, h0=step)
                        return sh.state(stt, it, new if stt == 0 else None, l, t0, sh.nfev), new

                    def plain(nb=nb, l=l):
                        return sh.solve(l, nb["x"][:2], max_iter=10)

                    t, (st, new) = _timed(one, repeat)
                    tp, stp = _timed(plain, 1)
                    for name, tt, s in ((f"shooting-{jac}", t, st),
                                        (f"shooting-{jac} no predictor", tp, stp)):
                        rows.append(dict(contact=contact, solver=name, tol=rtol, lambda0=l,
                                         success=bool(s.success), dF=abs(s.F - refs[l].force),
                                         ddelta=abs(s.delta - refs[l].delta),
                                         dSc=abs(s.Sc - refs[l].Sc), time=tt, nfev=s.nfev,
                                         niter=s.niter, force_defect=s.force_defect,
                                         message=s.message))
                    if st.success:
                        info = new
                log(f"{contact}: shooting {jac} rtol {rtol:g} done")
    return rows


def _table(rows):
    lines = ["| contact | solver | tol | lambda0 | ok | abs err F | abs err delta | s/state | work |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["solver"] in ("reference", "shooting-cold") or "dF" not in r:
            continue
        work = (f"{r['nodes']} nodes, {r['niter']} it" if r["solver"] == "collocation"
                else f"{r['niter']} it, {r['nfev']} fev")
        if not r["success"]:
            work += " FAILED: " + r.get("message", "")
        lines.append(f"| {r['contact']} | {r['solver']} | {r['tol']:.0e} | {r['lambda0']} | "
                     f"{r['success']} | {r['dF']:.1e} | {r['ddelta']:.1e} | {r['time']:.3f} | {work} |")
    return "\n".join(lines)


def _summary(rows):
    """One line per (contact, solver, tol): all converged?, max errors, median time per state."""
    groups = {}
    for r in rows:
        if "dF" in r or r["solver"].startswith("shooting-") and r["solver"] != "shooting-cold":
            groups.setdefault((r["contact"], r["solver"], r["tol"]), []).append(r)
    lines = ["| contact | solver | tol | converged | max abs err F | max abs err delta | median s/state |",
             "|---|---|---|---|---|---|---|"]
    for (contact, solver, tol), rs in groups.items():
        ok = [r for r in rs if r.get("success")]
        errF = max((r["dF"] for r in ok), default=math.nan)
        errd = max((r["ddelta"] for r in ok), default=math.nan)
        med = float(np.median([r["time"] for r in rs if "time" in r])) if rs else math.nan
        lines.append(f"| {contact} | {solver} | {tol:.0e} | {len(ok)}/{len(rs)} | {errF:.1e} | "
                     f"{errd:.1e} | {med:.3f} |")
    for r in rows:
        if r["solver"] == "shooting-cold":
            lines.append(f"\nShooting cold start ({r['contact']}, lambda0 = {r['lambda0']:g}, rtol "
                         f"{r['tol']:.0e}): {r['time']:.1f} s, {r['nfev']} RHS evaluations "
                         f"({r['message']}).")
    return "\n".join(lines)


def main(argv=None):
    import argparse
    import json
    import sys

    ap = argparse.ArgumentParser(description="Validate the shooting peer against sb.solve and time both.")
    ap.add_argument("--out", default=None, help="write the rows as JSON here (and a .md table beside)")
    ap.add_argument("--quick", action="store_true", help="fewer tolerances, one repeat")
    ap.add_argument("--method", default="DOP853", help="solve_ivp method")
    args = ap.parse_args(argv)
    kw = dict(method=args.method)
    if args.quick:
        kw.update(rtols=(1e-6, 1e-9), tols=(1e-4, 1e-7), repeat=1)
    rows = _validate(log=lambda m: print(m, file=sys.stderr, flush=True), **kw)
    table = _summary(rows) + "\n\n" + _table(rows)
    print(table)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(rows, fh, indent=1)
        with open(args.out.rsplit(".", 1)[0] + ".md", "w") as fh:
            fh.write(table + "\n")


if __name__ == "__main__":
    main()
