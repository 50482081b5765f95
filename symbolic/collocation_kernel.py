"""solve_bvp's collocation system, factorised and solved as loops for numba.

Not derived: two functions that :mod:`symbolic.codegen_numba` prints, with their
signatures, into every structure's kernel module, so that they are compiled and
cached with the structure's kernels (under the same trust checks).  Kept here as
plain Python so that a test can run them without numba and compare them with
scipy's assembly and SuperLU.  ``shellbvp.collocation`` hands them to
solve_bvp in place of its sparse Jacobian and SuperLU when the compiled kernels
are active.

The matrix is the one ``scipy.integrate._bvp.construct_global_jac`` assembles
(Kierzenka & Shampine's collocation formula): almost block diagonal, one n x n
pair of blocks per interval, the boundary conditions coupling both ends and
the k unknowns.  SuperLU spends most of its time on its general machinery for
this small and regular structure (little fill: L + U hold 1.4 times the
matrix's entries); here the elimination walks the nodes in order and skips the
zeros of the stacked regions' block-diagonal blocks.
"""

import numpy

#: numba signatures of the helpers the kernels call (printed first, not kernels themselves)
HELPERS = {"pivot_row": "int64(float64[:, :], int64, int64)"}
#: numba signatures (the unknowns' arrays have k = 0 columns when there are none)
SIGNATURES = {
    "collocation_factor": "(float64[:], float64[:, :, :], float64[:, :, :], float64[:, :, :], float64[:, :, :], "
                          "float64[:, :], float64[:, :], float64[:, :], float64)",
    "collocation_solve": "(int64, int64[:], float64[:], int64[:], int64[:], float64[:], int64[:], int64[:], "
                         "float64[:], float64[:, :], int64[:], float64[:])",
}


def pivot_row(a, c, rows):
    """The row (c <= row < rows) of the largest |a[row, c]|, the first of equals."""
    p = c
    best = abs(a[c, c])
    for r in range(c + 1, rows):
        if abs(a[r, c]) > best:
            best = abs(a[r, c])
            p = r
    return p


def collocation_factor(h, df_dy, df_dy_middle, df_dp, df_dp_middle, dbc_dya, dbc_dyb, dbc_dp, max_growth):
    """LU with partial pivoting of the collocation Jacobian, formed here from solve_bvp's
    blocks (the arguments of ``scipy.integrate._bvp.construct_global_jac`` without its index
    arrays; df_dp, df_dp_middle and dbc_dp have k = 0 columns when there are no unknowns).

    Gaussian elimination in the natural order, one node at a time: at node i the working
    rows are interval i's n collocation rows and the n + k rows carried from before (the
    boundary conditions, then whichever rows were not pivots), the columns y_i | y_i+1 |
    y_last | p; every row that holds a column of y_i is a pivot candidate, so this is
    partial pivoting of the whole matrix.  The pivot rows are kept compressed (u_*), and the
    multipliers (l_*); y_last and p are solved from the n + k rows left, densely.

    Returns (piv, diag, l_ptr, l_row, l_val, u_ptr, u_col, u_val, last, lpiv, growth,
    status): status 0, 1 (an exactly zero pivot: singular) or 2 (growth, the largest
    entry of the factors over the largest of the matrix, above ``max_growth``: not trusted,
    for SuperLU to do instead).
    """
    n = df_dy.shape[0]
    m = df_dy.shape[2]
    m1 = m - 1
    k = df_dp.shape[1]
    rows = 2 * n + k
    cols = 3 * n + k
    w = numpy.empty((rows, cols))  # interval i's rows, then the n+k carried rows; y_i | y_i+1 | y_last | p
    glob = numpy.empty(cols, dtype=numpy.int64)  # the global column of each of w's columns
    piv = numpy.empty(m1 * n, dtype=numpy.int64)
    diag = numpy.empty(m1 * n)
    l_ptr = numpy.empty(m1 * n + 1, dtype=numpy.int64)
    l_row = numpy.empty(m1 * n * rows, dtype=numpy.int64)
    l_val = numpy.empty(m1 * n * rows)
    u_ptr = numpy.empty(m1 * n + 1, dtype=numpy.int64)
    u_col = numpy.empty(m1 * n * cols, dtype=numpy.int64)
    u_val = numpy.empty(m1 * n * cols)
    t_left = numpy.empty(n)
    t_right = numpy.empty(n)
    t_p = numpy.empty(k)
    nonzero = numpy.empty(cols, dtype=numpy.int64)
    biggest = 0.0  # the largest entry of the matrix, and of the factors
    largest = 0.0
    size = n + k
    last = numpy.empty((size, size))
    lpiv = numpy.empty(size, dtype=numpy.int64)
    for r in range(n + k):  # the conditions start the carried rows
        for c in range(n):
            w[n + r, c] = dbc_dya[r, c]
            w[n + r, n + c] = 0.0
            w[n + r, 2 * n + c] = dbc_dyb[r, c]
        for u in range(k):
            w[n + r, 3 * n + u] = dbc_dp[r, u]
        for c in range(cols):
            biggest = max(biggest, abs(w[n + r, c]))
    nl = 0
    nu = 0
    l_ptr[0] = 0
    u_ptr[0] = 0
    for i in range(m1):
        for c in range(n):
            glob[c] = i * n + c
            glob[n + c] = (i + 1) * n + c
            glob[2 * n + c] = m1 * n + c
        for u in range(k):
            glob[3 * n + u] = m * n + u
        h6 = h[i] / 6
        h12 = h[i] ** 2 / 12
        for r in range(n):  # interval i's rows, as scipy forms them
            for c in range(n):
                unit = 1.0 if r == c else 0.0
                w[r, c] = -unit - h6 * (df_dy[r, c, i] + 2 * df_dy_middle[r, c, i])
                w[r, n + c] = unit - h6 * (df_dy[r, c, i + 1] + 2 * df_dy_middle[r, c, i])
                w[r, 2 * n + c] = 0.0
                t_left[c] = 0.0
                t_right[c] = 0.0
            for u in range(k):
                t_p[u] = 0.0
            for q in range(n):
                a = df_dy_middle[r, q, i]
                if a != 0.0:
                    for c in range(n):
                        t_left[c] += a * df_dy[q, c, i]
                        t_right[c] += a * df_dy[q, c, i + 1]
                    for u in range(k):
                        t_p[u] += a * (df_dp[q, u, i] - df_dp[q, u, i + 1])
            for c in range(n):
                w[r, c] -= h12 * t_left[c]
                w[r, n + c] += h12 * t_right[c]
            for u in range(k):
                middle = df_dp_middle[r, u, i] + 0.125 * h[i] * t_p[u]
                w[r, 3 * n + u] = -h6 * (df_dp[r, u, i] + df_dp[r, u, i + 1] + 4 * middle)
            for c in range(cols):
                biggest = max(biggest, abs(w[r, c]))
        for c in range(n):  # partial pivoting over every row that holds y_i's column c
            p = pivot_row(w, c, rows)
            best = abs(w[p, c])
            if best == 0.0:
                return piv, diag, l_ptr, l_row, l_val, u_ptr, u_col, u_val, last, lpiv, 0.0, 1
            s = i * n + c
            piv[s] = p
            if p != c:
                for q in range(c, cols):
                    w[c, q], w[p, q] = w[p, q], w[c, q]
            diag[s] = w[c, c]
            largest = max(largest, best)
            nz = 0
            for q in range(c + 1, cols):
                if w[c, q] != 0.0:
                    largest = max(largest, abs(w[c, q]))
                    nonzero[nz] = q
                    u_col[nu] = glob[q]
                    u_val[nu] = w[c, q]
                    nu += 1
                    nz += 1
            u_ptr[s + 1] = nu
            inv = 1.0 / w[c, c]
            for r in range(c + 1, rows):
                f = w[r, c]
                if f != 0.0:
                    f *= inv
                    l_row[nl] = r
                    l_val[nl] = f
                    nl += 1
                    for t in range(nz):
                        q = nonzero[t]
                        w[r, q] -= f * w[c, q]
            l_ptr[s + 1] = nl
        for r in range(n, rows):  # the rows left carry on: y_i+1 becomes their first block
            for c in range(n):
                w[r, c] = w[r, n + c]
                w[r, n + c] = 0.0
    # the last n + k unknowns (y_last and p) from the n + k rows left: dense, pivoted
    for r in range(size):
        for c in range(n):
            last[r, c] = w[n + r, c] + w[n + r, 2 * n + c]  # the same unknowns in two blocks
        for u in range(k):
            last[r, n + u] = w[n + r, 3 * n + u]
    for c in range(size):
        p = pivot_row(last, c, size)
        if last[p, c] == 0.0:
            return piv, diag, l_ptr, l_row, l_val, u_ptr, u_col, u_val, last, lpiv, 0.0, 1
        lpiv[c] = p
        if p != c:
            for q in range(c, size):
                last[c, q], last[p, q] = last[p, q], last[c, q]
        inv = 1.0 / last[c, c]
        for r in range(c + 1, size):
            f = last[r, c]
            if f != 0.0:
                f *= inv
                last[r, c] = f
                for q in range(c + 1, size):
                    last[r, q] -= f * last[c, q]
    for r in range(size):
        for c in range(r, size):
            largest = max(largest, abs(last[r, c]))
    growth = largest / biggest
    return (piv, diag, l_ptr, l_row[:nl], l_val[:nl], u_ptr, u_col[:nu], u_val[:nu], last, lpiv, growth,
            0 if growth <= max_growth else 2)


def collocation_solve(n, piv, diag, l_ptr, l_row, l_val, u_ptr, u_col, u_val, last, lpiv, b):
    """x with J x = b, from :func:`collocation_factor`'s factors (n states)."""
    steps = piv.size  # (m - 1) n
    m1 = steps // n
    size = last.shape[0]
    k = size - n
    x = numpy.empty(b.size)
    r = numpy.empty(2 * n + k)
    for q in range(size):
        r[n + q] = b[steps + q]
    for i in range(m1):
        for q in range(n):
            r[q] = b[i * n + q]
        for c in range(n):
            s = i * n + c
            p = piv[s]
            if p != c:
                r[c], r[p] = r[p], r[c]
            rc = r[c]
            if rc != 0.0:
                for t in range(l_ptr[s], l_ptr[s + 1]):
                    r[l_row[t]] -= l_val[t] * rc
        for q in range(n):
            x[i * n + q] = r[q]
    z = r[n:]
    for c in range(size):
        p = lpiv[c]
        if p != c:
            z[c], z[p] = z[p], z[c]
        for q in range(c + 1, size):
            z[q] -= last[q, c] * z[c]
    for c in range(size - 1, -1, -1):
        v = z[c]
        for q in range(c + 1, size):
            v -= last[c, q] * z[q]
        z[c] = v / last[c, c]
    for q in range(n):
        x[steps + q] = z[q]
    for u in range(k):
        x[steps + n + u] = z[n + u]
    for s in range(steps - 1, -1, -1):
        v = x[s]
        for t in range(u_ptr[s], u_ptr[s + 1]):
            v -= u_val[t] * x[u_col[t]]
        x[s] = v / diag[s]
    return x
