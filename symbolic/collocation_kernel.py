"""solve_bvp's collocation Jacobian in CSC form, as loops for numba.

Not derived: one function that :mod:`symbolic.codegen_numba` prints, with a
signature, into every structure's kernel module, so that it is compiled and
cached with the structure's kernels (under the same trust checks).  Kept here as
plain Python so that a test can run it without numba and compare it with scipy's
assembly (``shellbvp.collocation`` uses it when the compiled kernels are active).

The values are those of ``scipy.integrate._bvp.construct_global_jac``
(Kierzenka & Shampine's collocation formula), column by column, rows sorted,
without the entries that are exactly zero: the stacked regions' blocks are
block-diagonal, so products skip the zero factors too.
"""

import numpy

#: numba signature of :func:`collocation_csc` (df_dp, df_dp_middle, dbc_dp have k = 0 columns
#: when there are no unknowns)
SIGNATURE = ("(float64[:], float64[:, :, :], float64[:, :, :], float64[:, :, :], float64[:, :, :], "
             "float64[:, :], float64[:, :], float64[:, :])")


def collocation_csc(h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp):
    """(data, indices, indptr) of the collocation Jacobian: n states, m nodes, k unknowns.

    h (m-1,); df_dy (n, n, m); df_dy_middle (n, n, m-1); df_dp (n, k, m); df_dp_middle
    (n, k, m-1); dbc_dya, dbc_dyb (n+k, n); dbc_dp (n+k, k).
    """
    n = df_dy.shape[0]
    m = df_dy.shape[2]
    k = df_dp.shape[1]
    # d(residual j)/d(y_j) and d(residual j)/d(y_j+1), as scipy forms them
    left = numpy.empty((m - 1, n, n))
    right = numpy.empty((m - 1, n, n))
    t_left = numpy.empty(n)
    t_right = numpy.empty(n)
    for j in range(m - 1):
        h6 = h[j] / 6
        h12 = h[j] ** 2 / 12
        for r in range(n):
            for c in range(n):
                unit = 1.0 if r == c else 0.0
                left[j, r, c] = -unit - h6 * (df_dy[r, c, j] + 2 * df_dy_middle[r, c, j])
                right[j, r, c] = unit - h6 * (df_dy[r, c, j + 1] + 2 * df_dy_middle[r, c, j])
                t_left[c] = 0.0
                t_right[c] = 0.0
            for q in range(n):  # row r of df_dy_middle times df_dy at both nodes, zeros skipped
                a = df_dy_middle[r, q, j]
                if a != 0.0:
                    for c in range(n):
                        t_left[c] += a * df_dy[q, c, j]
                        t_right[c] += a * df_dy[q, c, j + 1]
            for c in range(n):
                left[j, r, c] -= h12 * t_left[c]
                right[j, r, c] += h12 * t_right[c]
    bc0 = (m - 1) * n  # first row of the boundary conditions
    room = 2 * n * (2 * n + k) + (m - 2) * n * 2 * n + k * (m * n + k)
    data = numpy.empty(room)
    indices = numpy.empty(room, dtype=numpy.int32)
    indptr = numpy.empty(m * n + k + 1, dtype=numpy.int32)
    nnz = 0
    col = 0
    for i in range(m):  # the states at node i: intervals i-1 and i, and the conditions at the ends
        for c in range(n):
            indptr[col] = nnz
            if i > 0:
                for r in range(n):
                    v = right[i - 1, r, c]
                    if v != 0.0:
                        data[nnz] = v
                        indices[nnz] = (i - 1) * n + r
                        nnz += 1
            if i < m - 1:
                for r in range(n):
                    v = left[i, r, c]
                    if v != 0.0:
                        data[nnz] = v
                        indices[nnz] = i * n + r
                        nnz += 1
            if i == 0 or i == m - 1:
                dbc = dbc_dya if i == 0 else dbc_dyb
                for r in range(n + k):
                    if dbc[r, c] != 0.0:
                        data[nnz] = dbc[r, c]
                        indices[nnz] = bc0 + r
                        nnz += 1
            col += 1
    for u in range(k):  # the unknowns: every interval, then the conditions
        indptr[col] = nnz
        for j in range(m - 1):
            hj = h[j]
            for r in range(n):
                t = 0.0
                for q in range(n):
                    a = df_dy_middle[r, q, j]
                    if a != 0.0:
                        t += a * (df_dp[q, u, j] - df_dp[q, u, j + 1])
                middle = df_dp_middle[r, u, j] + 0.125 * hj * t
                v = -hj / 6 * (df_dp[r, u, j] + df_dp[r, u, j + 1] + 4 * middle)
                if v != 0.0:
                    data[nnz] = v
                    indices[nnz] = j * n + r
                    nnz += 1
        for r in range(n + k):
            if dbc_dp[r, u] != 0.0:
                data[nnz] = dbc_dp[r, u]
                indices[nnz] = bc0 + r
                nnz += 1
        col += 1
    indptr[col] = nnz
    return data[:nnz], indices[:nnz], indptr
