r"""Shooting: the paper's own method, as an independent peer for the benchmarks.

This re-solves the indentation problem with ``lambda0`` (the pole stretch)
prescribed, the way the paper did (its section 3), and shares nothing with
``shellbvp``'s collocation machinery (``shellbvp.system`` / ``shellbvp.solve``)
except the generated equations: the right-hand sides ``g = S dy/dS`` of both
regions, their Jacobians and the pole, contact-line and rim conditions.

Method, for one lambda0
-----------------------
1. Contact region (on the tip), states ``(chi, ls)``: start at ``S = zeta =
   eps*Sc`` from the leading term of the pole series (``chi = c*lambda0``,
   ``ls = lambda0``; truncation error O(eps^2) relative) and integrate to Sc in
   ``tau = ln(S/Sc)`` (``dy/dtau = g``).
2. Contact line: the free region's start ``yf(Sc+)`` (states ``lt, phiS, ls,
   ks, rQ, z``) has one free component ``u`` -- ``rQ`` for ``contact="smooth"``
   (r, phi, z, lambda_s, kappa_s continuous; Q jumps), ``ks`` for
   ``contact="paper"`` (r, phi, z, Q continuous; lambda_s from [tau_s] = 0).
   The other five follow from the generated junction residual (5 equations),
   solved by Newton with its analytic Jacobian (linear rows converge in one
   step; the paper's [tau_s] = 0 row for ``ls_f`` starts from the contact
   value).  ``delta = 0`` there, i.e. ``z`` is measured with the tip at
   ``z_tip = Z(0)``; delta then follows from ``z(L) = 0``.
3. Free region: integrate from Sc to L in ``tau = ln(S/Sc)/ln(L/Sc)`` (so the
   interval is [0, 1] whatever Sc).
4. Newton on the two unknowns ``x = (ln Sc, u)`` for the rim conditions
   ``lambda_theta(L) = 1`` and ``M_s(L) = 0`` (``rim_res`` rows 0, 1).  The
   Jacobian is exact: the variational equations are integrated with both
   regions (dy/d ln Sc in the contact region, d/d(ln Sc, u) in the free
   region, including the moving start of the free interval), using the
   generated ``*_jac``.  Steps are damped (backtracking on the residual norm,
   ``|d ln Sc| <= 0.5``), trial states that leave the tip, blow up or fail to
   integrate are rejected.
5. ``delta = z(L)`` (the pole moved by delta) and ``F = 2 pi G`` with
   ``G = r sin(phi) tau_s - r cos(phi) Q`` at the rim (``free_profile``'s
   ``axial_force_2pi``; it is a first integral, so its drift between Sc+ and L
   is reported as an error indicator, ``force_defect``).

No exception is raised for non-convergence: ``success``, ``status`` and
``message`` say what happened.

Run as a script to validate against ``sb.solve`` and time both::

    python benchmarks/shooting.py [--out benchmarks/results/shooting.json]
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

    Parameters
    ----------
    scene : shellbvp.Scene
    rtol, atol : float
        ``solve_ivp`` tolerances (atol defaults to rtol; the states are O(1)).
    method : str
        ``solve_ivp`` method.  The problem is not stiff in ln S for moderate beta
        (eigenvalues of dg/dy are O(1..10) on the base scene), so the default is
        the explicit 'DOP853'; 'Radau', 'BDF', 'LSODA' get an (approximate, block
        diagonal) analytic Jacobian of the augmented system.
    eps : float
        Pole start ``zeta = eps*Sc``; default ``min(1e-3, 0.1 sqrt(rtol))`` (the
        leading-order start errs by O(eps^2)).
    """

    def __init__(self, scene, rtol=1e-8, atol=None, method="DOP853", eps=None, max_fev=20000):
        self.scene = scene
        self.model = mod = scene.model()
        self.par = scene.parameters(mod)
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
        self.c_pole = -mod.pole_res(0.0, 0.0, 1.0, self.par)
        self.max_fev = int(max_fev)
        self.nfev = 0
        self.implicit = method in ("Radau", "BDF", "LSODA")

    # -- region 1: the contact region --------------------------------------------------------
    def contact_end(self, lambda0, lnSc):
        """(chi, ls) at Sc and d/d ln Sc of them (pole start fixed at zeta = eps*Sc)."""
        mod, par = self.model, self.par
        Sc = math.exp(lnSc)
        y0 = np.r_[self.c_pole * lambda0, np.zeros(_NC)]

        def f(tau, w):
            S = Sc * math.exp(tau)
            y = w[:_NC]
            g = mod.contact_rhs(S, y, par)
            J, gS = mod.contact_jac(S, y, par)
            return np.r_[g, J @ w[_NC:] + gS * S]

        def jac(tau, w):
            S = Sc * math.exp(tau)
            J, _ = mod.contact_jac(S, w[:_NC], par)
            out = np.zeros((2 * _NC, 2 * _NC))
            out[:_NC, :_NC] = J
            out[_NC:, _NC:] = J
            return out

        sol = self._ivp(f, jac, (self.ln_eps, 0.0), y0, _contact_guard)
        if sol is None:
            return None
        w = sol.y[:, -1]
        return w[:_NC], w[_NC:]

    # -- the contact line --------------------------------------------------------------------
    def free_start(self, lnSc, yc, dyc, u):
        """yf(Sc+) with yf[k_u] = u, and d yf / d(ln Sc, u) (6, 2); None if unsolvable."""
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
        for _ in range(30):
            res = self.jres(Sc, yc, yf, 0.0, 0.0, par)
            if not np.all(np.isfinite(res)):
                return None
            jj = self.jjac(Sc, yc, yf, 0.0, 0.0, par)
            A = jj[:, cols]
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
        if not (np.all(np.isfinite(yf)) and np.max(np.abs(res)) < 1e-11):
            return None
        jj = self.jjac(Sc, yc, yf, 0.0, 0.0, par)
        A = jj[:, cols]
        # d res = dres/dSc * Sc dlnSc + dres/dyc dyc + dres/dyf dyf = 0
        rhs_lnSc = jj[:, 0] * Sc + jj[:, 1:3] @ dyc
        rhs_u = jj[:, 3 + self.k_u]
        D = np.zeros((_NF, 2))
        D[det, 0] = -np.linalg.solve(A, rhs_lnSc)
        D[det, 1] = -np.linalg.solve(A, rhs_u)
        D[self.k_u, 1] = 1.0
        return yf, D

    # -- region 2: the free region -----------------------------------------------------------
    def free_end(self, lnSc, yf0, D0):
        """yf(L) and d yf(L) / d(ln Sc, u), with S = Sc (L/Sc)^tau, tau in [0, 1]."""
        mod, par = self.model, self.par
        Sc = math.exp(lnSc)
        Lf = self.lnL - lnSc

        def f(tau, w):
            S = Sc * math.exp(Lf * tau)
            y = w[:_NF]
            V = w[_NF:].reshape(_NF, 2)
            g = mod.free_rhs(S, y, par)
            J, gS = mod.free_jac(S, y, par)
            dV = Lf * (J @ V)
            # explicit dependence of the mapped RHS on ln Sc (moving start of the interval)
            dV[:, 0] += -g + Lf * gS * S * (1.0 - tau)
            return np.r_[Lf * g, dV.ravel()]

        def jac(tau, w):
            S = Sc * math.exp(Lf * tau)
            J, _ = mod.free_jac(S, w[:_NF], par)
            n = _NF * 3
            out = np.zeros((n, n))
            out[:_NF, :_NF] = Lf * J
            # d(J V)/dV for V stored row-major (6, 2): column j of V is every 2nd entry
            for j in range(2):
                idx = _NF + np.arange(_NF) * 2 + j
                out[np.ix_(idx, idx)] = Lf * J
            return out

        # d yf(0)/d lnSc: only via the junction (the start itself is accounted for in f).
        sol = self._ivp(f, jac, (0.0, 1.0), np.r_[yf0, D0.ravel()], _free_guard)
        if sol is None:
            return None
        w = sol.y[:, -1]
        return w[:_NF], w[_NF:].reshape(_NF, 2)

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
        if self.implicit:
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
    def residual(self, lambda0, x, want_jac=True):
        """Rim residual (lt - 1, m) at L and its Jacobian for x = (ln Sc, u); None on failure."""
        lnSc, u = float(x[0]), float(x[1])
        if not (lnSc < self.lnL - 1e-3) or not math.isfinite(u):
            return None
        Sc = math.exp(lnSc)
        ce = self.contact_end(lambda0, lnSc)
        if ce is None:
            return None
        yc, dyc = ce
        if not (0 < Sc * yc[0] / self.rho < self.omega_max) or yc[1] <= 0:
            return None  # the cap has left the tip (or collapsed)
        fs = self.free_start(lnSc, yc, dyc, u)
        if fs is None:
            return None
        yf0, D0 = fs
        fe = self.free_end(lnSc, yf0, D0)
        if fe is None:
            return None
        yL, VL = fe
        res = self.model.rim_res(self.L, yL, self.par)[:2]
        Jr = self.model.rim_jac(self.L, yL, self.par)[:2] @ VL
        if not (np.all(np.isfinite(res)) and np.all(np.isfinite(Jr))):
            return None
        return res, Jr, dict(yc=yc, yf0=yf0, yL=yL)

    def solve(self, lambda0, guess, max_iter=30, xtol=None):
        """Damped Newton from guess = (ln Sc, u).  Returns a ShootState."""
        t0 = time.perf_counter()
        self.nfev = 0
        xtol = 10 * self.rtol if xtol is None else xtol
        x = np.asarray(guess, float).copy()
        st = ShootState(lambda0=float(lambda0), contact=self.contact, rtol=self.rtol)
        cur = self.residual(lambda0, x)
        if cur is None:
            st.status, st.message = 3, STATUS[3]
            st.wall_time = time.perf_counter() - t0
            st.nfev = self.nfev
            return st
        status = 1
        for it in range(1, max_iter + 1):
            res, Jr, info = cur
            nrm = np.max(np.abs(res))
            try:
                dx = -np.linalg.solve(Jr, res)
            except np.linalg.LinAlgError:
                status = 2
                break
            if not np.all(np.isfinite(dx)):
                status = 2
                break
            if abs(dx[0]) > 0.5:
                dx *= 0.5 / abs(dx[0])
            lam, accepted = 1.0, None
            while lam >= 1.0 / 64:
                trial = self.residual(lambda0, x + lam * dx)
                if trial is not None and np.max(np.abs(trial[0])) < (1 - 0.25 * lam) * nrm + 1e-15:
                    accepted = trial
                    break
                lam *= 0.5
            st.niter = it
            if accepted is None:
                # At the noise floor of the integrator no step can reduce the residual further.
                if nrm <= 100 * max(self.rtol, 1e-14):
                    status = 0
                else:
                    status = 2
                break
            x = x + lam * dx
            cur = accepted
            step = np.max(np.abs(lam * dx) / (1 + np.abs(x)))
            if step <= xtol and np.max(np.abs(cur[0])) <= 100 * max(self.rtol, 1e-14):
                status = 0
                break
        res, Jr, info = cur
        G0 = self.model.free_profile(np.array([math.exp(x[0])]), info["yf0"][:, None], self.par)
        GL = self.model.free_profile(np.array([self.L]), info["yL"][:, None], self.par)
        g0, gL = float(G0["axial_force_2pi"][0]), float(GL["axial_force_2pi"][0])
        st.Sc, st.u = math.exp(x[0]), float(x[1])
        st.delta = float(info["yL"][5])  # z(L) with delta = 0; z(L) - delta = 0
        st.F = 2 * math.pi * gL
        st.force_defect = 2 * math.pi * abs(gL - g0)
        st.residual = float(np.max(np.abs(res)))
        st.status = status
        st.success = status == 0
        st.message = STATUS[status]
        if st.success and st.delta < 0:
            st.message += f" (collapsed state: delta = {st.delta:.3g} < 0)"
        st.nfev = self.nfev
        st.wall_time = time.perf_counter() - t0
        return st


def _cold_guesses(shooter):
    """A few crude (ln Sc, u) starts: cap sizes times a few values of the free unknown."""
    if shooter.contact == "smooth":
        us = (-0.05, 0.0, -0.2)      # rQ(Sc+): about -F/(2 pi) for a shallow cap
    else:
        us = (-2.5, 0.0, 1.0 / shooter.rho)  # kappa_s(Sc+)
    for Sc in (0.05, 0.1, 0.02, 0.2):
        for u in us:
            yield math.log(Sc), u


def shoot_state(scene, lambda0, rtol=1e-8, guess=None, *, atol=None, method="DOP853", eps=None,
                max_iter=30, shooter=None):
    """One state with the pole stretch lambda0 prescribed, by shooting.

    guess : ShootState, or (Sc, u) with u = rQ(Sc+) (smooth) or kappa_s(Sc+) (paper);
        without it a few crude starts are tried in turn (``nfev``/``wall_time`` count all).
    Returns a :class:`ShootState` (never raises for non-convergence).
    """
    sh = shooter or Shooter(scene, rtol=rtol, atol=atol, method=method, eps=eps)
    if guess is not None:
        x0 = guess.x if isinstance(guess, ShootState) else np.array([math.log(guess[0]), guess[1]])
        return sh.solve(lambda0, x0, max_iter=max_iter)
    t0, nfev, first = time.perf_counter(), 0, None
    for x0 in _cold_guesses(sh):
        st = sh.solve(lambda0, x0, max_iter=max_iter)
        nfev += st.nfev
        if st.success and st.delta >= 0:
            break
        first = first or st
    else:
        st = first
        st.message = "no crude start converged (first attempt: " + st.message + ")"
    st.nfev, st.wall_time = nfev, time.perf_counter() - t0
    return st


def shoot_curve(scene, lambda0s, rtol=1e-8, *, guess=None, **kw):
    """States at the given lambda0 values, each warm-started from its neighbours.

    The first state starts from ``guess`` (or crude starts); later ones from a
    secant prediction in (ln Sc, u) through the last two converged states (the
    last one alone after a failure; a failed point is retried from crude starts).
    Returns a :class:`ShootCurve`.
    """
    sh = Shooter(scene, rtol=rtol, **{k: v for k, v in kw.items() if k in ("atol", "method", "eps")})
    mi = kw.get("max_iter", 30)
    out = ShootCurve()
    done = []
    for lam in lambda0s:
        if len(done) >= 2:
            (l1, s1), (l2, s2) = done[-2], done[-1]
            x0 = s2.x + (s2.x - s1.x) * (lam - l2) / (l2 - l1)
            st = sh.solve(lam, x0, max_iter=mi)
            if not st.success:  # predictor overshot: fall back to the last state
                st2 = sh.solve(lam, s2.x, max_iter=mi)
                st2.nfev += st.nfev
                st2.wall_time += st.wall_time
                st = st2
        elif done:
            st = sh.solve(lam, done[-1][1].x, max_iter=mi)
        else:
            st = shoot_state(scene, lam, rtol, guess=guess, shooter=sh, max_iter=mi)
        if not st.success and done:
            st = shoot_state(scene, lam, rtol, shooter=sh, max_iter=mi)
        out.states.append(st)
        if st.success:
            done.append((lam, st))
    return out


# ---------------------------------------------------------------------------------------------
# Validation against the collocation solver and timing (run as a script)
# ---------------------------------------------------------------------------------------------

def _validate(lambdas=(1.0, 1.05, 1.1), rtols=(1e-6, 1e-8, 1e-9, 1e-10), ref_tol=1e-10):
    import shellbvp as sb

    rows = []
    for contact in ("smooth", "paper"):
        scene = sb.Scene.preset("base", contact=contact)
        scene.model()
        refs = [sb.solve(scene, lambda0=l, tol=ref_tol) for l in lambdas]
        for r in refs:
            assert r.success, r.message
        # collocation, warm-started from the neighbour, at several tolerances
        for tol in (1e-4, 1e-6, 1e-8):
            prev = sb.solve(scene, lambda0=lambdas[0] - 0.01, tol=tol, estimate_error=False)
            for l, ref in zip(lambdas, refs):
                times = []
                for _ in range(3):
                    t0 = time.perf_counter()
                    s = sb.solve(scene, lambda0=l, tol=tol, guess=prev, estimate_error=False)
                    times.append(time.perf_counter() - t0)
                rows.append(dict(contact=contact, solver="collocation", tol=tol, lambda0=l,
                                 success=bool(s.success), dF=abs(s.force - ref.force),
                                 ddelta=abs(s.delta - ref.delta), time=min(times),
                                 nodes=int(s.nodes)))
                prev = s
        # shooting: cold (crude starts) and warm (from the neighbour at lambda0 - 0.01)
        for rtol in rtols:
            sh = Shooter(scene, rtol=rtol)
            for l, ref in zip(lambdas, refs):
                cold = shoot_state(scene, l, rtol, shooter=sh)
                nb = sh.solve(l - 0.01, cold.x) if cold.success else None
                times, st = [], None
                for _ in range(3):
                    st = sh.solve(l, nb.x if nb is not None and nb.success else cold.x)
                    times.append(st.wall_time)
                rows.append(dict(contact=contact, solver="shooting", tol=rtol, lambda0=l,
                                 success=bool(st.success), dF=abs(st.F - ref.force),
                                 ddelta=abs(st.delta - ref.delta), dSc=abs(st.Sc - ref.Sc),
                                 time=min(times), cold_time=cold.wall_time, nfev=st.nfev,
                                 niter=st.niter, force_defect=st.force_defect,
                                 message=st.message))
    return rows


def main(argv=None):
    import argparse
    import json

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=None, help="write the rows as JSON here")
    args = ap.parse_args(argv)
    rows = _validate()
    print("| contact | solver | tol | lambda0 | ok | |dF| | |d delta| | s/state | work |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        work = (f"{r['nodes']} nodes" if r["solver"] == "collocation"
                else f"{r['niter']} it, {r['nfev']} fev")
        print(f"| {r['contact']} | {r['solver']} | {r['tol']:.0e} | {r['lambda0']} | {r['success']} | "
              f"{r['dF']:.1e} | {r['ddelta']:.1e} | {r['time']:.3f} | {work} |")
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
