r"""The branch tangent's checks of the stability tests: along a branch of states,
``d^2E/d delta^2 = dF/d delta`` equals the n = 0 second variation on the branch tangent.

One copy for tests/test_stability_contact.py (open shells on the tip, :func:`branch_check`),
tests/test_stability_closed.py (each half of a closed shell: ``regions``, ``lift`` and its own
``z_offset``), tests/test_stability_profile.py and tests/test_koiter.py (:func:`branch_check` on
other walls and energies).  The tangent is the difference quotient of the neighbours' positions
at fixed material point S.
"""

from __future__ import annotations

import math

import numpy as np

import shellbvp as sb
from shellbvp import modal_stability as st
from shellbvp.chain import CONTACT_KINDS
from shellbvp.modal_stability.form import form_at


def open_offset(kind, state):
    """The height of a region's profile's origin: the tip's apex for the regions on the tip, else 0."""
    return state.z_tip if kind in CONTACT_KINDS else 0.0


def closed_offset(kind, state):
    """A closed shell's: the tip's profile from its apex, the plane's from the unmoved pole (delta 0)."""
    return {"contact": state.z_tip, "plane": state.system.pole_height}.get(kind, 0.0)


def frame(state, S, regions=None, z_offset=open_offset):
    """Position ((r, z) rows), its first and second S-derivatives, the base fields, the tangent t
    and normal N, psi, psi' and the reference radius R of ``state`` at the points S (``regions``:
    a chain's indices, a closed shell's half in its own frame; default all)."""
    regions = list(range(len(state.system.regions))) if regions is None else list(regions)
    base = st.chain_base(state, regions)(S)
    _, _, _, shell_params, ref = st.form_functions(state.scene)
    values = state.scene.values()
    R, Psi, dPsi, _, _ = (np.broadcast_to(np.asarray(v, float), S.shape)
                          for v in ref(S, *[values[p] for p in shell_params]))
    sysm = state.system
    z = np.empty_like(S)
    edges = [float(sysm.S_point(sysm.regions[k].end, state.p)) for k in regions[:-1]]
    which = np.searchsorted(edges, S, side="right")
    for i, k in enumerate(regions):
        sel = which == i
        if np.any(sel):
            reg = sysm.regions[k]
            t = sysm.t_of(k, S[sel], state.p)
            prof = getattr(sysm.kernels.active, f"{reg.kind}_profile")(S[sel], state.sol(t)[sysm.rows(k)],
                                                                        sysm.par_at(state.p))
            z[sel] = prof["z"] + z_offset(reg.kind, state)
    phi, ls, ks = base["phi"], base["ls"], base["ks"]
    psi, dpsi = ls * Psi, base["dls"] * Psi + ls * dPsi
    t = np.array([np.cos(phi), np.sin(phi)])
    N = np.array([-np.sin(phi), np.cos(phi)])
    x = np.array([base["lt"] * R, z])
    return x, psi * t, dpsi * t + psi * psi * ks * N, base, t, N, psi, dpsi, R


def edge(state, regions=None):
    """Where the first region of the chain (``regions``' first) ends: the contact's edge or line."""
    sysm = state.system
    return float(sysm.S_point(sysm.regions[0 if regions is None else regions[0]].end, state.p))


def tangent(lo, mid, hi, S, regions=None, lift=0.0, z_offset=open_offset):
    """zeta = (u, u', u'', 0.., w, w', w'') of the branch tangent ``x' + lift e_z`` at ``mid`` from
    its neighbours, in the chain's frame, and ``mid``'s base fields, R and psi there."""
    h = hi.delta - lo.delta
    x, xS, xSS, base, t, N, psi, dpsi, R = frame(mid, S, regions, z_offset)
    (xl, xSl, xSSl), (xh, xSh, xSSh) = (frame(s, S, regions, z_offset)[:3] for s in (lo, hi))
    d, dS, dSS = (xh - xl) / h, (xSh - xSl) / h, (xSSh - xSSl) / h
    d = d + np.array([0.0, lift])[:, None]
    phS = psi * base["ks"]
    phSS = dpsi * base["ks"] + psi * base["dks"]

    def dot(a, b):
        return a[0] * b[0] + a[1] * b[1]

    u, w = dot(d, t), dot(d, N)
    zeta = np.zeros((9, S.size))
    zeta[0], zeta[6] = u, w
    zeta[1] = dot(dS, t) + phS * w
    zeta[2] = dot(dSS, t) + 2 * phS * dot(dS, N) + phSS * w - phS**2 * u
    zeta[7] = dot(dS, N) - phS * u
    zeta[8] = dot(dSS, N) - 2 * phS * dot(dS, t) - phSS * u - phS**2 * w
    return zeta, base, R, psi


def quadrature(lo, mid, hi, regions=None, S0=1e-3):
    """Gauss points and weights on [S0, L], with nodes inside the span of the moving edge (the
    tangent's u' jumps there: lambda_s' jumps at the edge, which moves with delta)."""
    L = float(mid.system.L)
    edges = [edge(s, regions) for s in (lo, mid, hi)]
    e = edges[1]
    brk = np.unique(np.concatenate([np.geomspace(S0, e, 200), np.linspace(e, L, 600),
                                    np.linspace(min(edges), max(edges), 9), np.linspace(0.98 * e, 1.02 * e, 41)]))
    brk = brk[(brk >= S0) & (brk <= L)]
    xg, wg = np.polynomial.legendre.leggauss(6)
    hb = np.diff(brk)
    S = (brk[:-1, None] + hb[:, None] * (xg + 1)[None, :] / 2).ravel()
    W = (hb[:, None] * wg[None, :] / 2).ravel()
    return S, W


def elastic_form(mid, zeta, base, S, W):
    """``8 pi Int zeta^T A_0 zeta dS`` (A_0: the form without the contact terms)."""
    A, _ = form_at(mid.scene, lambda s: dict(base, P=np.zeros_like(S)), S, 0)
    return 8 * math.pi * float(np.sum(W * np.einsum("ig,ijg,jg->g", zeta, A, zeta)))


def elastic(lo, mid, hi, regions=None, lift=0.0, S0=1e-3, z_offset=open_offset):
    """The elastic second variation of a chain (a closed shell's half) on the branch tangent."""
    S, W = quadrature(lo, mid, hi, regions, S0)
    zeta, base, _, _ = tangent(lo, mid, hi, S, regions, lift, z_offset)
    return elastic_form(mid, zeta, base, S, W)


def branch_check(lo, mid, hi, S0=1e-3):
    """(dF/ddelta, the elastic second variation on the tangent, the constraint's terms) at
    ``mid`` from its neighbours ``lo``, ``hi`` on an open shell's branch (a cap or a line).

    The tangent ``x' = (x_hi - x_lo)/(delta_hi - delta_lo)`` at fixed S, in (u, w) with their
    S-derivatives; ``8 pi Int zeta^T A_0 zeta dS`` (A_0 without the contact terms) is
    ``d^2 Pi(x', x')``; relative to the tip (which moves down) the tangent is ``x' + e_z``.
    The contact edge moves with delta and lambda_s' jumps there, so the tangent's u' jumps
    inside [edge_lo, edge_hi]: the quadrature has nodes there."""
    h = hi.delta - lo.delta
    S, W = quadrature(lo, mid, hi, S0=S0)
    zeta, base, R, psi = tangent(lo, mid, hi, S)
    elastic_ = elastic_form(mid, zeta, base, S, W)
    # the tangent relative to the tip along t (the pressure's term, 2 pi Int p^ kappa_s dt^2)
    rel = zeta[0] + np.sin(base["phi"])
    pressure = -2 * math.pi * float(np.sum(W * base["P"] * base["lt"] * R * psi * base["ks"] * rel**2))
    # at the edge or line
    e = edge(mid)
    Se = np.array([e])
    xl, xh = (frame(s, Se)[0] for s in (lo, hi))
    be, te = frame(mid, np.array([e * (1 - 1e-12)]))[3:5]
    de = (xh - xl)[:, 0] / h
    ks = float(be["ks"][0])
    u0 = float(de @ te[:, 0]) + float(te[1, 0])
    f = float(mid.edge_forces[0])
    if mid.topology == "cap":
        ring = -f * ks * u0**2
    else:  # the line: kappa_S u0^2 + 2 u0 w1 - w1^2/gap, w1 = d(dt . N)/dsigma
        gap = -float(mid.curvature_excess)
        w1 = slope_at_line(lo, mid, hi)
        ring = -f * (ks * u0**2 + 2 * u0 * w1 - w1**2 / gap)
    return (hi.force - lo.force) / h, elastic_, pressure + ring


def slope_at_line(lo, mid, hi):
    """``w1 = d(dt . N)/dsigma`` of the tangent relative to the tip at the line.  The
    difference quotient is off by O(h) between the neighbours' lines (their x_SSS jumps there),
    so it is extrapolated linearly to the line from 2 and 3 such widths on each side and the
    two sides averaged (the exact tangent's slope is continuous there)."""
    h = hi.delta - lo.delta
    e = edge(mid)
    width = abs(edge(hi) - edge(lo))
    sides = []
    for sign in (-1, 1):
        S = e + sign * width * np.array([2.0, 3.0])
        (xl, xSl), (xh, xSh) = (frame(s, S)[:2] for s in (lo, hi))
        _, _, _, b, t, N, psi, _, _ = frame(mid, S)
        d, dS = (xh - xl) / h, (xSh - xSl) / h
        phS = psi * b["ks"]
        w_S = (dS * N).sum(0) - phS * ((d * t).sum(0) + np.sin(b["phi"]))
        w1 = w_S / psi
        sides.append(w1[0] - 2 * (w1[1] - w1[0]))  # linear, from 2 and 3 widths to 0
    return float(np.mean(sides))


def neighbours(scene, delta, h=5e-4, **kw):
    """The state at ``delta`` (tol 1e-8) and its neighbours ``h`` apart on the same branch."""
    mid = sb.solve(scene, delta=delta, tol=1e-8, estimate_error=False, **kw)
    lo, hi = (sb.solve(scene, delta=delta + s * h / 2, guess=mid, tol=1e-8, estimate_error=False, **kw)
              for s in (-1, 1))
    assert all(s.success and s.topology == mid.topology for s in (lo, hi)), (lo.topology, hi.topology)
    return lo, mid, hi
