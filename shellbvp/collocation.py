"""solve_bvp's collocation Jacobian: assembled without its stored zeros, and, with
compiled kernels, factorised by an elimination that knows its structure.

scipy.integrate.solve_bvp assembles the Jacobian of its collocation system from
dense n x n blocks per mesh interval (COO, then CSC) and factorises it with
SuperLU.  The regions of a chain are stacked into one system and each region's
equations involve its own states only, so the blocks are block-diagonal: 40-60 %
of the entries are exact zeros, which SuperLU would store, order and factorise
as nonzeros.  On the first solve this module replaces three private functions of
``scipy.integrate._bvp``:

* ``construct_global_jac`` by :func:`collocation_jacobian`: with numpy, the same
  blocks by the same arithmetic, written straight into CSC form without the
  zeros (:func:`assemble_csc`: scipy's matrix with its zeros eliminated, entry
  for entry, a test); with a structure's compiled kernels active
  (``shellbvp.kernels``), the blocks' arguments alone, for ``splu``;
* ``splu`` by :func:`factorise`: SuperLU for a sparse matrix; for the compiled
  case the kernels' ``collocation_factor`` and ``collocation_solve``
  (:mod:`symbolic.collocation_kernel`: Gaussian elimination with partial
  pivoting, node by node, skipping the zero blocks; 2-3x faster than SuperLU
  there).  Factors whose entries grow beyond ``OPTIONS.collocation_max_growth`` times the matrix's
  are not trusted: SuperLU factorises that matrix instead;
* ``compute_jac_indices``, whose COO index arrays nothing needs any more.

A scipy whose ``_bvp`` lacks them or calls them differently keeps its own
functions: only slower.  ``shellbvp.options(collocation=False)`` restores scipy's path at run
time (the benchmarks' ablation).

:func:`newton_on_mesh` solves the same collocation system on a mesh that stays fixed,
by Newton's method without solve_bvp's line search: Richardson estimates need no
more (see its docstring).
"""

from __future__ import annotations

import contextlib
import inspect
import logging
import threading

import numpy as np

from .config import OPTIONS

__all__ = ["CollocationBlocks", "CollocationLU", "assemble_csc",
           "collocation_jacobian", "factorise", "install", "newton_on_mesh", "solving_with"]

log = logging.getLogger(__name__)


_SIGNATURES = {
    "splu": None,  # SuperLU's: any parameters
    "compute_jac_indices": ("n", "m", "k"),
    "construct_global_jac": ("n", "m", "k", "i_jac", "j_jac", "h", "df_dy", "df_dy_middle", "df_dp",
                             "df_dp_middle", "dbc_dya", "dbc_dyb", "dbc_dp"),
}
_PATTERNS: dict = {}  # (n, m, k) -> (row indices, column pointers) of the full block pattern
_MAX_PATTERNS = 64


def _block_pattern(n: int, m: int, k: int):
    """CSC rows and column pointers of every entry solve_bvp's blocks can hold, columns in
    order: node 0 (interval 0, then the conditions), nodes 1..m-2 (intervals i-1 and i),
    node m-1 (interval m-2, then the conditions), then the k unknowns (every row)."""
    key = (n, m, k)
    if key not in _PATTERNS:
        if len(_PATTERNS) >= _MAX_PATTERNS:
            _PATTERNS.clear()
        bc = (m - 1) * n + np.arange(n + k)
        first = np.concatenate([np.arange(n), bc])
        middle = np.arange(m - 2)[:, None] * n + np.arange(2 * n)[None, :]
        last = np.concatenate([(m - 2) * n + np.arange(n), bc])
        rows = np.concatenate([np.tile(first, n), np.repeat(middle, n, axis=0).ravel(), np.tile(last, n),
                               np.tile(np.arange(m * n + k), k)]).astype(np.int32)
        lengths = np.concatenate([np.full(n, 2 * n + k), np.full((m - 2) * n, 2 * n), np.full(n, 2 * n + k),
                                  np.full(k, m * n + k)])
        pointers = np.zeros(lengths.size + 1, dtype=np.int64)
        np.cumsum(lengths, out=pointers[1:])
        _PATTERNS[key] = rows, pointers
    return _PATTERNS[key]


def collocation_jacobian(n, m, k, i_jac, j_jac, h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb,
                         dbc_dp):
    """``scipy.integrate._bvp.construct_global_jac`` (the same arguments; ``i_jac``, ``j_jac``
    are not used): :func:`assemble_csc`, or, with compiled kernels (:func:`solving_with`), a
    :class:`CollocationBlocks` for :func:`factorise`."""
    if not OPTIONS.collocation:
        return _ORIGINAL["construct_global_jac"](n, m, k, i_jac, j_jac, h, df_dy, df_dy_middle, df_dp,
                                                 df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)
    kernels = getattr(_CURRENT, "kernels", None)
    if kernels is not None and OPTIONS.compiled_elimination:
        return CollocationBlocks(kernels, n, m, k, h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb,
                                 dbc_dp)
    return assemble_csc(n, m, k, h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)


def assemble_csc(n, m, k, h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp):
    """The collocation Jacobian as ``construct_global_jac`` computes it (the blocks of
    Kierzenka & Shampine's formula, by scipy's arithmetic), as a CSC matrix without stored
    zeros, rows sorted."""
    from scipy.integrate._bvp import stacked_matmul
    from scipy.sparse import csc_matrix

    df_dy = np.transpose(df_dy, (2, 0, 1))
    df_dy_middle = np.transpose(df_dy_middle, (2, 0, 1))
    h = h[:, np.newaxis, np.newaxis]
    # the diagonal (0) and off-diagonal (1) n x n blocks of each interval, as scipy computes them
    dPhi_dy_0 = np.empty((m - 1, n, n))
    dPhi_dy_0[:] = -np.identity(n)
    dPhi_dy_0 -= h / 6 * (df_dy[:-1] + 2 * df_dy_middle)
    dPhi_dy_0 -= h ** 2 / 12 * stacked_matmul(df_dy_middle, df_dy[:-1])
    dPhi_dy_1 = np.empty((m - 1, n, n))
    dPhi_dy_1[:] = np.identity(n)
    dPhi_dy_1 -= h / 6 * (df_dy[1:] + 2 * df_dy_middle)
    dPhi_dy_1 += h ** 2 / 12 * stacked_matmul(df_dy_middle, df_dy[1:])
    columns = [np.concatenate([dPhi_dy_0[0].T, dbc_dya.T], axis=1).ravel(),
               np.concatenate([dPhi_dy_1[:-1], dPhi_dy_0[1:]], axis=1).transpose(0, 2, 1).ravel(),
               np.concatenate([dPhi_dy_1[-1].T, dbc_dyb.T], axis=1).ravel()]
    if k > 0:
        df_dp = np.transpose(df_dp, (2, 0, 1))
        df_dp_middle = np.transpose(df_dp_middle, (2, 0, 1))
        df_dp_middle = df_dp_middle + 0.125 * h * stacked_matmul(df_dy_middle, df_dp[:-1] - df_dp[1:])
        dPhi_dp = -h / 6 * (df_dp[:-1] + df_dp[1:] + 4 * df_dp_middle)
        columns.append(np.concatenate([dPhi_dp.reshape(-1, k), dbc_dp], axis=0).T.ravel())
    values = np.concatenate(columns)
    rows, pointers = _block_pattern(n, m, k)
    stored = values != 0
    kept = np.zeros_like(pointers)
    np.cumsum(np.add.reduceat(stored, pointers[:-1]), out=kept[1:])
    size = n * m + k
    return csc_matrix((values[stored], rows[stored], kept), shape=(size, size))




class CollocationBlocks:
    """solve_bvp's collocation Jacobian as the arguments of its blocks, with the compiled
    kernels that factorise it (solve_bvp hands its Jacobian to ``splu`` only)."""

    def __init__(self, kernels, n, m, k, h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp):
        self.kernels, self.n, self.m, self.k = kernels, n, m, k
        self.blocks = (h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)

    def tocsc(self):
        """The same matrix, assembled (:func:`assemble_csc`)."""
        return assemble_csc(self.n, self.m, self.k, *self.blocks)

    def factorise(self, max_growth=None):
        """:class:`CollocationLU`; RuntimeError for an exactly singular matrix (as SuperLU);
        None when the factors grew beyond ``max_growth`` (default ``OPTIONS.collocation_max_growth``)."""
        h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp = self.blocks
        if self.k == 0:  # the kernels take arrays with no columns
            df_dp = df_dp_middle = np.empty((self.n, 0, self.m))
            dbc_dp = np.empty((self.n, 0))
        *factors, growth, status = self.kernels.collocation_factor(
            h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp,
            OPTIONS.collocation_max_growth if max_growth is None else float(max_growth))
        if status == 1:
            raise RuntimeError("Factor is exactly singular")
        if status == 2:
            return None
        return CollocationLU(self.kernels.collocation_solve, self.n, factors, growth)


class CollocationLU:
    """The factors of a :class:`CollocationBlocks`; ``solve(b)`` as SuperLU's."""

    def __init__(self, solve, n, factors, growth):
        self._solve, self.n, self.factors, self.growth = solve, n, factors, growth

    def solve(self, b):
        return self._solve(self.n, *self.factors, np.asarray(b, dtype=float))


def factorise(J, *args, **kwargs):
    """The ``splu`` solve_bvp calls: the compiled elimination for :class:`CollocationBlocks`
    (SuperLU if its factors grew too much), SuperLU for anything else."""
    if isinstance(J, CollocationBlocks):
        lu = J.factorise()
        if lu is not None:
            return lu
        log.debug("collocation factors grew beyond %g times the matrix: SuperLU instead", OPTIONS.collocation_max_growth)
        J = J.tocsc()
    with _c_output_discarded():
        return _ORIGINAL["splu"](J, *args, **kwargs)


_QUIET = threading.Lock()


@contextlib.contextmanager
def _c_output_discarded():
    """SuperLU reports a failed allocation by printing from C ("Not enough memory to perform
    factorization." on stdout, "malloc fails for local dworkptr[]." on stderr, no newline) before
    Python sees the error, which the solve turns into a status: that text would break ``--json``'s
    one document and the CLI's one-line error (issue 59).  File descriptors 1 and 2 point at
    /dev/null meanwhile (a few microseconds; without usable descriptors, nothing changes)."""
    import os
    import sys

    with _QUIET:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (AttributeError, OSError, ValueError):
                pass
        try:
            saved, null = (os.dup(1), os.dup(2)), os.open(os.devnull, os.O_WRONLY)
        except OSError:
            yield
            return
        try:
            os.dup2(null, 1)
            os.dup2(null, 2)
            yield
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in (*saved, null):
                os.close(fd)


_CURRENT = threading.local()


@contextlib.contextmanager
def solving_with(kernels):
    """Within the block, :func:`collocation_jacobian` leaves the Jacobian to ``kernels``'
    ``collocation_factor`` and ``collocation_solve`` (a structure's compiled kernel set,
    ``shellbvp.kernels``); None: numpy assembly and SuperLU.  Per thread."""
    before = getattr(_CURRENT, "kernels", None)
    _CURRENT.kernels = kernels
    try:
        yield
    finally:
        _CURRENT.kernels = before


def _scipy_collocation_fun():
    """``scipy.integrate._bvp.collocation_fun`` (solve_bvp's collocation residuals, the same
    arithmetic), or None where that scipy has none with the parameters expected."""
    from scipy.integrate import _bvp

    fn = getattr(_bvp, "collocation_fun", None)
    global _collocation_fun_checked
    if _collocation_fun_checked[0] is not fn:  # inspect.signature costs ~30 µs a Richardson estimate
        try:
            ok = callable(fn) and tuple(inspect.signature(fn).parameters) == ("fun", "y", "p", "x", "h")
        except (TypeError, ValueError):
            ok = False
        _collocation_fun_checked = (fn, ok)
    return fn if _collocation_fun_checked[1] else None


_collocation_fun_checked = (None, False)  # (the function last checked, whether its parameters are right)


def newton_on_mesh(fun, bc, fun_jac, bc_jac, x, y, p, *, tol, bc_tol, kernels=None, max_jacobians=2,
                   max_steps=6):
    """The collocation system of solve_bvp on the fixed mesh ``x``, solved by Newton's method
    from ``(y, p)`` (``p`` an array, possibly empty; ``fun(x, y, p)``, ``fun_jac`` returning
    ``(df_dy, df_dp)``, ``bc(ya, yb, p)``, ``bc_jac`` returning three blocks, as solve_bvp
    calls them once it has wrapped them).

    Full steps only, until solve_bvp's own test of convergence at ``tol`` and ``bc_tol``
    holds.  A step that reduces the largest residual is taken; the Jacobian is kept while
    steps reduce it at least twofold, else evaluated again at the new iterate; a step of a
    kept Jacobian that does not reduce it is dropped and the Jacobian evaluated again where
    it was.  At most ``max_jacobians`` Jacobians and ``max_steps`` steps.  Returns the
    converged ``(y, p)``, or None (no convergence within that, a full step of a new Jacobian
    that does not reduce the residual, a singular Jacobian, a NaN, a scipy without the
    private functions this calls: its ``collocation_fun`` and those :func:`install` replaces): the caller then has solve_bvp, with its line
    search, to fall back on.

    What this is for: a start that is already near the solution (a converged state on its
    mesh with every interval halved).  solve_bvp's line search tests each step by the norm
    of the next Newton step, which an ill-conditioned Jacobian (a state at a switch, one
    region ~1e-8 long) keeps large after the residual has reached rounding level: it then
    halves converged steps and evaluates up to four Jacobians.  And its mesh refinement
    and residual estimate after Newton are work a fixed mesh does not need.
    """
    collocation_fun = _scipy_collocation_fun()
    if collocation_fun is None or not install():  # factorise needs scipy's splu as install() finds it
        return None
    n, m = y.shape
    k = p.size
    h = np.diff(x)
    x_middle = x[:-1] + 0.5 * h
    tol_r = 2 / 3 * h * 5e-2 * tol  # solve_bvp's (solve_newton's) termination test, the same numbers

    def residuals(y, p):
        col, y_middle, _, f_middle = collocation_fun(fun, y, p, x, h)
        bc_res = bc(y[:, 0], y[:, -1], p)
        done = bool(np.all(np.abs(col) < tol_r * (1 + np.abs(f_middle))) and np.all(np.abs(bc_res) < bc_tol))
        return np.hstack((col.ravel(order="F"), bc_res)), done, y_middle

    r, done, y_middle = residuals(y, p)
    if done:
        return y, p
    size, jacobians, lu, fresh = float(np.max(np.abs(r))), 0, None, False
    if not np.isfinite(size):
        return None
    with solving_with(kernels):
        for _ in range(max_steps):
            if lu is None:
                if jacobians == max_jacobians:
                    return None
                jacobians, fresh = jacobians + 1, True
                df_dy, df_dp = fun_jac(x, y, p)
                df_dy_middle, df_dp_middle = fun_jac(x_middle, y_middle, p)
                dbc_dya, dbc_dyb, dbc_dp = bc_jac(y[:, 0], y[:, -1], p)
                blocks = (df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)
                if not all(b is None or np.all(np.isfinite(b)) for b in blocks):
                    return None
                i_jac, j_jac = (None, None) if OPTIONS.collocation else _ORIGINAL["compute_jac_indices"](n, m, k)
                try:
                    lu = factorise(collocation_jacobian(n, m, k, i_jac, j_jac, h, *blocks))
                except RuntimeError:  # exactly singular
                    return None
            step = lu.solve(r)
            y_new = y - step[:m * n].reshape((n, m), order="F")
            p_new = p - step[m * n:]
            r_new, done, y_middle_new = residuals(y_new, p_new)
            if done:
                return y_new, p_new
            size_new = float(np.max(np.abs(r_new)))
            if not size_new < size:  # worse, or NaN
                if fresh:  # a full step of a new Jacobian: this needs a line search
                    return None
                lu = None  # the kept Jacobian has gone stale: a new one, here
                continue
            if not size_new <= 0.5 * size:  # slow progress: a new Jacobian at the new iterate
                lu = None
            y, p, r, y_middle, size, fresh = y_new, p_new, r_new, y_middle_new, size_new, False
    return None


def _jac_indices(n, m, k):
    """Placeholder of ``compute_jac_indices``: :func:`collocation_jacobian` needs no COO indices."""
    if not OPTIONS.collocation:
        return _ORIGINAL["compute_jac_indices"](n, m, k)
    return None, None


_ORIGINAL: dict = {}
_REPLACEMENT = {"compute_jac_indices": _jac_indices, "construct_global_jac": collocation_jacobian,
                "splu": factorise}


def install() -> bool:
    """Replace the three functions in ``scipy.integrate._bvp`` (once); False if that scipy does
    not have them with the expected parameters (it keeps its own)."""
    from scipy.integrate import _bvp

    if _ORIGINAL:
        return True
    found = {name: getattr(_bvp, name, None) for name in _SIGNATURES}
    for name, fn in found.items():
        try:
            if not callable(fn) or (_SIGNATURES[name] is not None
                                    and tuple(inspect.signature(fn).parameters) != _SIGNATURES[name]):
                return False
        except (TypeError, ValueError):
            return False
    _ORIGINAL.update(found)
    for name, fn in _REPLACEMENT.items():
        setattr(_bvp, name, fn)
    return True
