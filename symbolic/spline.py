"""The natural cubic spline of a thickness table, in numpy only (no SymPy: ``shellbvp`` evaluates
profiles with it without loading the derivation; ``symbolic.geometry`` writes the same spline
as an expression)."""

from __future__ import annotations

import numpy as np

__all__ = ["natural_spline_coefficients"]


def natural_spline_coefficients(knots, values):
    """``(a, b, c)`` of the natural cubic spline ``a + b S + sum_k c_k |S - S_k|^3`` through
    ``(knots, values)`` (at least 2 strictly increasing knots; numpy floats)."""
    x = np.asarray(knots, dtype=float)
    y = np.asarray(values, dtype=float)
    n = x.size
    if n < 2 or y.shape != x.shape or not np.all(np.diff(x) > 0):
        raise ValueError("a thickness table needs at least 2 rows with strictly increasing positions")
    A = np.zeros((n + 2, n + 2))
    A[:n, :n] = np.abs(x[:, None] - x[None, :]) ** 3
    A[:n, n], A[:n, n + 1] = 1.0, x
    A[n, :n], A[n + 1, :n] = 1.0, x
    coef = np.linalg.solve(A, np.concatenate([y, [0.0, 0.0]]))
    return coef[n], coef[n + 1], coef[:n]
