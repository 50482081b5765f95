"""Gauss-Legendre quadrature on a solve_bvp mesh (energy integrals)."""

from __future__ import annotations

import numpy as np

__all__ = ["gauss_points"]

_GAUSS_T, _GAUSS_W = np.polynomial.legendre.leggauss(4)


def gauss_points(x):
    """Gauss-Legendre points (4 per mesh interval) and weights on t, for energy integrals."""
    a, b = x[:-1], x[1:]
    t = (0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * _GAUSS_T[None, :]).ravel()
    w = (0.5 * (b - a)[:, None] * _GAUSS_W[None, :]).ravel()
    return t, w
