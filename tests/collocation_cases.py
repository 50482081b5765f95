"""Collocation Jacobians to compare with scipy's assembly (test_solve: the loops as plain
Python; test_kernels: compiled)."""

import numpy as np


def _scipys_collocation_jacobian(n, m, k, h, *blocks):
    """scipy's own assembly with its zeros eliminated (the reference)."""
    from shellbvp import collocation

    collocation.install()
    theirs = collocation._ORIGINAL["construct_global_jac"](
        n, m, k, *collocation._ORIGINAL["compute_jac_indices"](n, m, k), h,
        *[None if b is None else np.array(b) for b in blocks])  # scipy updates df_dp_middle in place
    theirs.eliminate_zeros()
    theirs.sort_indices()
    return theirs


def collocation_loops_against_scipy(collocation_csc, n, m, k, h, *blocks):
    """max |difference| / max |entry| of ``collocation_csc`` (the loops of
    symbolic.collocation_kernel, plain or compiled) against scipy's assembly; asserts the
    same sparsity and sorted rows without stored zeros."""
    from scipy.sparse import csc_matrix

    df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp = blocks
    if k == 0:
        df_dp = df_dp_middle = np.empty((n, 0, m))
        dbc_dp = np.empty((n, 0))
    data, indices, indptr = collocation_csc(h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp)
    ours = csc_matrix((data, indices, indptr), shape=(n * m + k, n * m + k))
    theirs = _scipys_collocation_jacobian(n, m, k, h, *blocks)
    assert ours.has_sorted_indices and np.count_nonzero(ours.data == 0) == 0
    assert np.array_equal(ours.indptr, theirs.indptr) and np.array_equal(ours.indices, theirs.indices)
    return float(np.max(np.abs(ours.data - theirs.data)) / np.max(np.abs(theirs.data)))


def random_collocation_blocks(k, n=5, m=9, seed=3):
    """(n, m, k, h, blocks) of a random system of two stacked regions (states 0-1 and 2-4:
    block-diagonal df/dy) with k unknowns and some exact zeros inside the blocks."""
    rng = np.random.default_rng(seed)
    mask = np.zeros((n, n))
    mask[:2, :2] = mask[2:, 2:] = 1
    mask[3, 4] = 0

    def jac(size):
        return rng.standard_normal((n, n, size)) * mask[:, :, None]

    h = rng.uniform(0.05, 0.2, m - 1)
    dp = rng.standard_normal((n, k, m)) if k else None
    dp_middle = rng.standard_normal((n, k, m - 1)) if k else None
    dbc_dya, dbc_dyb = rng.standard_normal((n + k, n)), rng.standard_normal((n + k, n))
    dbc_dya[:, 2:] = dbc_dyb[:, :2] = 0.0  # conditions at the ends that a chain does not couple
    return n, m, k, h, jac(m), jac(m - 1), dp, dp_middle, dbc_dya, dbc_dyb, rng.standard_normal((n + k, k)) if k else None
