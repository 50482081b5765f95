"""Collocation systems to solve with symbolic.collocation_kernel's elimination and with
SuperLU (test_solve: the elimination as plain Python; test_kernels: compiled)."""

import types

import numpy as np

from symbolic import collocation_kernel

#: the elimination's functions as plain Python (what the kernel modules compile)
PLAIN = types.SimpleNamespace(collocation_factor=collocation_kernel.collocation_factor,
                              collocation_solve=collocation_kernel.collocation_solve)


def elimination_against_superlu(kernels, n, m, k, h, *blocks):
    """(max relative difference of the solutions of two right-hand sides, growth) of the
    elimination in ``kernels`` against SuperLU on scipy's own assembly of the same matrix."""
    from shellbvp import collocation

    collocation.install()
    J = collocation._ORIGINAL["construct_global_jac"](
        n, m, k, *collocation._ORIGINAL["compute_jac_indices"](n, m, k), h,
        *[None if b is None else np.array(b) for b in blocks])  # scipy updates df_dp_middle in place
    superlu = collocation._ORIGINAL["splu"](J.tocsc())
    lu = collocation.CollocationBlocks(kernels, n, m, k, h, *blocks).factorise()
    rng = np.random.default_rng(5)
    worst = 0.0
    for b in (rng.standard_normal(J.shape[0]), J @ rng.standard_normal(J.shape[0])):
        ours, theirs = lu.solve(b), superlu.solve(b)
        worst = max(worst, float(np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))))
    return worst, lu.growth


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


def switch_state_estimate():
    """(state, its F error estimate, its F error against the state solved at tol 1e-9) of the
    switch to cap+line(tip) on the base curve through the first 9 of the 40 depths
    linspace(0.0125, 0.5, 40) (delta 0.1125: one region ~1e-8 long, an ill-conditioned
    collocation Jacobian), with the kernels the environment selects."""
    import shellbvp as sb
    from shellbvp.state import solve_from

    c = sb.curve(sb.Scene.preset("base"), deltas=np.linspace(0.0125, 0.5, 40)[:9])
    s = c.solutions[-1]
    assert s.topology == "cap+line(tip)" and s.error_method == "richardson"
    ref = solve_from(s.system, (s.x, s.y, s.p), tol=1e-9, max_nodes=30000, bc_tol=1e-12)
    assert ref.success and ref.topology == s.topology
    return s, float(s.force_error), abs(ref.force - s.force)
