"""Newton for the 3D reference (:mod:`shellbvp.fe`): the solid with its contact and rim at an
indenter position, or at a mid-surface pole displacement with the indenter's position as one
more unknown, and the steps along the path between them.

* Pole control is a bordered system: the residual's derivative in the indenter's position is
  the contact tangent applied to a rigid axial shift (the tip's distance depends on ``z - apex``
  only), so each Newton iteration solves for the field and the indenter together, and a depth
  costs one Newton solve instead of a secant on the indenter.
* The linear solves use SuperLU with the symmetric minimum-degree ordering and diagonal pivots
  (the matrix is symmetric; about 3x faster than the default column ordering with partial
  pivoting here), checked by the solve's residual and refactorised with partial pivoting where
  that is not small.
* Steps along the path grow after a solve in 10 iterations or fewer and halve after a failure,
  and the path keeps the step it learnt: a failed solve costs its full iteration budget.  (The
  iterations hardly fall with the step at eps 0.02 -- 7 or 8 even at 0.2 H, from the contact's
  edge -- so steps shrunk for fewer iterations cost more: measured 1104 against 468.)

Points are ``(z, r)``, FElupe's axisymmetric order.  Nondimensional: mu = 1, R_L = 1.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse.linalg import splu

__all__ = ["Newton", "LinearSolve", "STALL", "GROW"]

#: A Newton that can no longer reduce its residual by a line search has met rounding; below
#: this residual relative to the contact force it is converged (F to about this accuracy).
STALL = 1e-6
#: A full Newton step is taken unless it multiplies the residual's norm by more than this: the
#: predictor's error at the contact's edge is a penetration far deeper than the penalty's, and
#: a strictly monotone line search crawls through the active set's changes (measured on the
#: hemisphere at eps 0.05: 199 instead of 252 iterations, 8 instead of 18 failed solves).
GROW = 4.0


class LinearSolve:
    """LU of a sparse symmetric (indefinite) matrix, for several right-hand sides.

    Parameters
    ----------
    K : scipy.sparse matrix
        Square, symmetric in pattern and values.
    """

    def __init__(self, K):
        self.K = K.tocsc()
        try:  # the u/p/J matrix has zeros on its diagonal: SuperLU then pivots off it
            self.lu = splu(self.K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
        except RuntimeError:
            self.lu = None
        self.pivoted = False

    def solve(self, rhs):
        """``K^-1 rhs``; raises RuntimeError where K is singular."""
        if self.lu is not None:
            x = self.lu.solve(rhs)
            scale = np.linalg.norm(rhs) + 1e-300
            if np.all(np.isfinite(x)) and np.linalg.norm(self.K @ x - rhs) <= 1e-8 * scale:
                return x
        if not self.pivoted:  # a small diagonal pivot lost accuracy: partial pivoting instead
            self.lu, self.pivoted = splu(self.K), True
        return self.lu.solve(rhs)


class Newton:
    """Newton on the solid + contact, from the current state, with the converged states kept for
    the predictor.

    Parameters
    ----------
    model : object
        :func:`shellbvp.fe`'s model: ``field``, ``solid``, ``contact``, ``fixed``, ``face``,
        ``pole_mid``.
    tol : float
        Converged when the residual's norm is below ``tol`` times the contact force's.
    delta_tol : float
        Pole control: and the pole within ``delta_tol * max(delta, H)`` of its target.
    max_iterations : int
    """

    def __init__(self, model, tol, delta_tol=1e-7, max_iterations=15):
        self.m, self.tol, self.delta_tol, self.max_iterations = model, tol, delta_tol, max_iterations
        ndof = int(np.sum(model.field.fieldsizes))
        free = np.ones(ndof, bool)
        free[model.fixed] = False
        if model.face is not None:
            free[model.face.dofs] = False  # moved through the face's own unknowns
        self.free = np.flatnonzero(free)
        # delta = pole0 - w . u: the mid-surface pole's displacement (a closed shell's: the poles'
        # approach, model.delta_weights)
        self.weights = np.zeros(ndof)
        for dof, w in (getattr(model, "delta_weights", None) or {2 * model.pole_mid: 1.0}).items():
            self.weights[dof] = w
        self.supports = list(getattr(model, "supports", None) or [])  # fixed contacts, springs
        self.shift = np.zeros(ndof)  # a rigid axial shift of the displacement field
        self.shift[0:model.contact.ndof_u:2] = 1.0
        self.newton_iterations = 0
        self.pole0 = 0.0  # the pole's axial displacement that delta is measured from (the inflated state's)
        self.V0 = None    # a sealed shell's volume (held, the pressure an unknown); None: the pressure given
        self.history = [self.save()]  # converged states (values, indenter, delta) for the predictor

    # ------------------------------------------------------------ state
    def save(self):
        return [f.values.copy() for f in self.m.field.fields], self.indenter, self.delta(), self.pressure

    def restore(self, saved):
        values, self.indenter, _, self.pressure = saved
        for f, v in zip(self.m.field.fields, values):
            f.values[...] = v

    @property
    def pressure(self):
        """The pressure on the inner surface (mu), 0 without one."""
        return 0.0 if self.m.pressure is None else self.m.pressure.P

    @pressure.setter
    def pressure(self, P):
        if self.m.pressure is not None:
            self.m.pressure.P = P

    @property
    def indenter(self):
        """The indenter's displacement from first touch, positive down."""
        return self.m.contact.z0 - self.m.contact.apex

    @indenter.setter
    def indenter(self, a):
        self.m.contact.apex = self.m.contact.z0 - a

    def delta(self):
        """The mid-surface pole's displacement, positive down (a closed shell's: the approach of
        its mid-surface poles)."""
        return self.pole0 - self._weighted()

    def _weighted(self):
        u = self.m.field[0].values.ravel()
        return float(self.weights[: u.size] @ u)

    def _remember(self):
        self.history = (self.history + [self.save()])[-3:]

    def _predict(self, x, pole):
        """The secant predictor: field and indenter extrapolated from the two converged states
        nearest in the control (the indenter's position, or the pole's displacement); without it
        the tip's step lands as a deep penetration."""
        key = 2 if pole else 1
        if len(self.history) < 2:
            return
        h0, h1 = sorted(self.history, key=lambda h: abs(h[key] - x))[:2]
        if h1[key] == h0[key]:
            return
        t = (x - h1[key]) / (h1[key] - h0[key])
        for f, x0, x1 in zip(self.m.field.fields, h0[0], h1[0]):
            f.values[...] = x1 + t * (x1 - x0)
        if pole:
            self.indenter = h1[1] + t * (h1[1] - h0[1])
        if self.V0 is not None:
            self.pressure = h1[3] + t * (h1[3] - h0[3])

    # ------------------------------------------------------------ the system
    def residual(self):
        """``(r, load, K_load, F)`` at the current state (full dofs): the residual, the norm of the
        loads it is measured against (the contacts', the supports' and the pressure's), their
        tangent and the indenter's force.  The indenter's own tangent is kept (``K_tip``): a rigid
        axial shift changes its load alone, so it is the pole control's border."""
        m = self.m
        u = m.field[0].values.ravel()
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # trial states may invert
            r = np.asarray(m.solid.assemble.vector(m.field).todense()).ravel()
        rc, Kc, F, _ = m.contact.evaluate(u)
        self.K_tip = Kc
        r, load, K = r + rc, np.linalg.norm(rc), Kc
        for support in self.supports:
            rs, Ks, _, _ = support.evaluate(u)
            r, load, K = r + rs, load + np.linalg.norm(rs), K + Ks
        if m.pressure is not None:
            rp, Kp = m.pressure.evaluate(u)
            r, load, K = r + rp, load + np.linalg.norm(rp), K + Kp
        return r, load, K, F

    def system(self, r, K):
        """``(K_reduced, r_reduced, J)``: the Newton system in the unknowns the rim leaves free
        (J maps a reduced step to the full dofs; None where the unknowns are plain dofs)."""
        face = self.m.face
        if face is None:
            return (None if K is None else K[self.free][:, self.free].tocsc()), r[self.free], None
        if K is None:
            return None, np.r_[r[self.free], face.residual(r, self.m.field[0].values.ravel())], None
        return face.reduce(r, K, self.free, self.m.field[0].values.ravel())

    def advance(self, dq, scale):
        """The state moved by ``scale`` times the reduced Newton step ``dq``."""
        m = self.m
        full = np.zeros(int(np.sum(m.field.fieldsizes)))
        full[self.free] = scale * dq[: self.free.size]
        m.field += full
        if m.face is not None:
            m.face.step(m.field[0].values, dq[self.free.size:], scale)

    def _full(self, dq, J):
        if J is not None:
            return J @ dq
        full = np.zeros(int(np.sum(self.m.field.fieldsizes)))
        full[self.free] = dq
        return full

    # ------------------------------------------------------------ Newton
    def solve(self, a, delta=None):
        """Newton with the indenter at ``a`` or, given ``delta``, with the pole's displacement at
        ``delta`` and the indenter free (``a`` its first guess); from the current state.  True
        when converged (the state kept), else False (the state restored)."""
        m, saved = self.m, self.save()
        pole = delta is not None
        self.indenter = a
        self._predict(delta if pole else a, pole)
        if m.face is not None:
            m.face.project(m.field[0].values)  # the predictor extrapolates off the face's line
        r, load, K_load, F = self.residual()
        du = np.inf
        for it in range(self.max_iterations):
            rf = self.system(r, None)[1]
            norm = np.linalg.norm(rf)
            if not np.isfinite(norm):
                break
            # converged: the residual small against the contact force, or (at loads so small that
            # the residual meets rounding first) a full Newton step that moved nothing
            if it > 0 and (norm <= self.tol * load or du <= 1e-13) and self._on_target(delta):
                return self._converged(it, F)
            K, rr, J = self.system(r, m.solid.assemble.matrix(m.field) + K_load)
            try:
                lu = LinearSolve(K)
                dq = lu.solve(-rr)
                dq, da, dP = self._bordered(lu, dq, K_load, J, delta)
            except (RuntimeError, np.linalg.LinAlgError):  # singular: no equilibrium from here
                break
            full = self._full(dq, J)
            if not (np.all(np.isfinite(full)) and np.isfinite(da + dP)) or np.max(np.abs(full[: m.contact.ndof_u])) > 0.5:
                break
            # backtracking on the residual's norm (a full step may raise it): contact enters and
            # leaves the active set
            step, du = 1.0, np.inf
            base = self.save()
            for _ in range(8):
                self.advance(dq, step)
                self.indenter, self.pressure = base[1] + step * da, base[3] + step * dP
                r, load, K_load, F = self.residual()
                new = np.linalg.norm(self.system(r, None)[1])
                if np.isfinite(new) and new <= (1 - 1e-4 * step) * norm * (GROW if step == 1.0 else 1.0):
                    du = np.max(np.abs(full[: m.contact.ndof_u])) if step == 1.0 else np.inf
                    break
                self.restore(base)
                step *= 0.5
            else:
                r, load, K_load, F = self.residual()
                if norm <= STALL * load and self._on_target(delta):  # stalled at rounding
                    return self._converged(it + 1, F)
                self.advance(dq, step)  # no descent: take the short step and go on
                self.indenter, self.pressure = base[1] + step * da, base[3] + step * dP
                r, load, K_load, F = self.residual()
        self.restore(saved)
        return False

    def _bordered(self, lu, dq, K_load, J, delta):
        """``(dq, da, dP)``: the Newton step ``dq = K^-1 (-r)`` corrected for the bordered
        unknowns -- the indenter's position under pole control (the pole at ``delta``), a sealed
        shell's pressure (the volume at ``V0``) -- each with its linearised constraint (a Schur
        complement of one or two rows)."""
        cols, rows, rhs = [], [], []
        reduced = (lambda v: v[self.free]) if J is None else (lambda v: J.T @ v)  # noqa: E731
        if delta is not None:
            cols.append(reduced(self.K_tip @ self.shift))
            rows.append(reduced(self.weights))
            rhs.append(self.delta() - delta)
        if self.V0 is not None:
            u = self.m.field[0].values.ravel()
            g = reduced(self.m.pressure.gradient(u))
            cols.append(-g)
            rows.append(g)
            rhs.append(self.V0 - self.m.pressure.volume(u))
        if not cols:
            return dq, 0.0, 0.0
        X = np.column_stack([lu.solve(c) for c in cols])
        R = np.array(rows)
        y = np.linalg.solve(R @ X, R @ dq - np.array(rhs))
        return dq - X @ y, (y[0] if delta is not None else 0.0), (y[-1] if self.V0 is not None else 0.0)

    def seal(self):
        """From here on the volume below the inner surface is held (its pressure an unknown)."""
        self.V0 = self.m.pressure.volume(self.m.field[0].values.ravel())
        self.history = [self.save()]

    def _on_target(self, delta):
        volume_held = self.V0 is None or abs(self.m.pressure.volume(self.m.field[0].values.ravel()) - self.V0) <= \
            1e-10 * abs(self.V0)
        return volume_held and (delta is None or abs(self.delta() - delta) <= self._delta_tol(delta))

    def _delta_tol(self, delta):
        return self.delta_tol * max(delta, self.m.eps)

    def _converged(self, iterations, F):
        self.newton_iterations += iterations
        self.force = F
        self._remember()
        return True

    def inflate(self, first=0.25, smallest=1e-3):
        """The pressure's load factor from 0 to 1 with the indenter away (steps grow after a
        success and halve after a failure); the inflated state is then the path's start: first
        touch on its surface, delta measured from its pole.  False where it is not reached."""
        load, done, step = self.m.pressure, 0.0, first
        self.indenter = -1.0  # the tip one R_L above the surface: no contact while inflating
        while done < 1.0:
            load.scale = min(1.0, done + step)
            if self.solve(self.indenter):
                done, step = load.scale, 1.5 * step
            else:
                load.scale, step = done, 0.5 * step
                if step < smallest:
                    return False
        u = self.m.field[0].values
        self.pole0 = self._weighted()
        self.m.contact.z0 = self.m.contact.apex = self.m.contact.first_touch(u.ravel())
        self.history = [self.save()]
        return True

    def move(self, a, min_fraction=1e-3):
        """From the current state to the indenter at ``a``: steps that grow after a success and
        halve after a failure, down to ``min_fraction`` of the way."""
        start = self.indenter
        step = a - start
        while abs(a - self.indenter) > 1e-15:
            target = self.indenter + step if abs(a - self.indenter) > abs(step) else a
            if self.solve(target):
                step *= 1.5
            else:
                step *= 0.5
                if abs(step) < min_fraction * abs(a - start):
                    return False
        return True

    def march(self, target, pole, step, cap):
        """From the current state to ``target`` (the pole's displacement, or the indenter's) in
        steps of about ``step``, adapted to the Newton's iterations, at most ``cap(current)``.

        Returns ``(reached, step)``: the step to go on with.
        """
        smallest = 1e-4 * self.m.eps
        while True:
            now = self.delta() if pole else self.indenter
            rest = target - now
            if abs(rest) <= (self._delta_tol(target) if pole else 1e-15):
                return True, step
            h = rest if abs(rest) <= 1.5 * step else math.copysign(step, rest)  # no sliver before the target
            before = self.newton_iterations
            if self.solve(self.indenter, now + h) if pole else self.solve(now + h):
                it = self.newton_iterations - before
                # the step the Newton takes in a few iterations (a failed solve costs a full one)
                grow = 1.5 if it <= 10 else 1.0
                step = min(max(step, abs(h)) * grow if abs(h) >= step else step, cap(now + h))
            else:
                step = 0.5 * abs(h)
                if step < smallest:
                    return False, step
