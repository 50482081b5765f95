"""solve_bvp's collocation Jacobian, handed to SuperLU without its stored zeros.

scipy.integrate.solve_bvp assembles the Jacobian of its collocation system from
dense n x n blocks per mesh interval (COO, then CSC) and factorises it with
SuperLU.  The regions of a chain are stacked into one system and each region's
equations involve its own states only, so the blocks are block-diagonal: 40-60 %
of the entries are exact zeros, which SuperLU stores, orders and factorises as
nonzeros.  On the first solve this module replaces two private functions of
``scipy.integrate._bvp``:

* ``construct_global_jac`` by :func:`collocation_jacobian`: the same blocks by
  the same arithmetic, written straight into CSC form (columns in order, rows
  sorted) without the zeros -- the matrix scipy builds, with its zeros
  eliminated (a test compares them entry by entry);
* ``compute_jac_indices``, whose COO index arrays that needs no more.

With a structure's compiled kernels active (``shellbvp.kernels``), the assembly is their
``collocation_csc`` (:mod:`symbolic.collocation_kernel`, loops that skip the zero blocks)
instead of numpy's array operations.

A scipy whose ``_bvp`` lacks them or calls them differently keeps its own
functions: only slower.  ``ENABLED = False`` restores scipy's path at run time
(the benchmarks' ablation).
"""

from __future__ import annotations

import contextlib
import inspect
import threading

import numpy as np

__all__ = ["ENABLED", "assembling", "collocation_jacobian", "install"]

#: Assemble without the zeros (False: scipy's own assembly; benchmarks measure the gain)
ENABLED = True

_SIGNATURES = {
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
    """``scipy.integrate._bvp.construct_global_jac`` (same arguments, same values: the blocks
    of Kierzenka & Shampine's collocation formula), as a CSC matrix without stored zeros.
    ``i_jac``, ``j_jac`` are not used."""
    from scipy.integrate._bvp import stacked_matmul
    from scipy.sparse import csc_matrix

    if not ENABLED:
        return _ORIGINAL["construct_global_jac"](n, m, k, i_jac, j_jac, h, df_dy, df_dy_middle, df_dp,
                                                 df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)
    compiled = getattr(_CURRENT, "assembler", None)
    if compiled is not None:
        if k == 0:
            df_dp = df_dp_middle = np.empty((n, 0, m))
            dbc_dp = np.empty((n, 0))
        data, indices, indptr = compiled(h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)
        return csc_matrix((data, indices, indptr), shape=(n * m + k, n * m + k))
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


_CURRENT = threading.local()


@contextlib.contextmanager
def assembling(assembler):
    """Within the block, :func:`collocation_jacobian` calls ``assembler`` (a compiled
    :func:`symbolic.collocation_kernel.collocation_csc`, from a structure's kernel set) instead
    of its numpy assembly; None: numpy.  Per thread."""
    before = getattr(_CURRENT, "assembler", None)
    _CURRENT.assembler = assembler
    try:
        yield
    finally:
        _CURRENT.assembler = before


def _jac_indices(n, m, k):
    """Placeholder of ``compute_jac_indices``: :func:`collocation_jacobian` needs no COO indices."""
    if not ENABLED:
        return _ORIGINAL["compute_jac_indices"](n, m, k)
    return None, None


_ORIGINAL: dict = {}
_REPLACEMENT = {"compute_jac_indices": _jac_indices, "construct_global_jac": collocation_jacobian}


def install() -> bool:
    """Replace the two functions in ``scipy.integrate._bvp`` (once); False if that scipy does
    not have them with the expected parameters (it keeps its own)."""
    from scipy.integrate import _bvp

    if _ORIGINAL:
        return True
    found = {name: getattr(_bvp, name, None) for name in _SIGNATURES}
    for name, fn in found.items():
        try:
            if not callable(fn) or tuple(inspect.signature(fn).parameters) != _SIGNATURES[name]:
                return False
        except (TypeError, ValueError):
            return False
    _ORIGINAL.update(found)
    for name, fn in _REPLACEMENT.items():
        setattr(_bvp, name, fn)
    return True
