"""The second variation's 9 x 9 form evaluated on a base state: the generated form of a
structure, the base state from a solution's regions (or a sphere), the contact's curvature terms."""

from __future__ import annotations

import functools
import json

import numpy as np

from ..chain import CONTACT_STATES, FREE_STATES
from ..model import load_stability_module


@functools.lru_cache(maxsize=16)
def _module(structure_key):
    """The generated module of ``symbolic.second_variation`` for a structure description (a
    hashable key)."""
    return load_stability_module(json.loads(structure_key))


def _key(scene):
    return json.dumps(scene.structure(), sort_keys=True)


def form_functions(scene):
    """(upper-triangle entry function of the 9 x 9 form, the entries' (i, j), its parameter
    names, the reference shell's parameter names, the reference-shell function) of the scene's
    structure."""
    mod = _module(_key(scene))
    return mod.form, list(mod.UPPER), list(mod.PARAMS), list(mod.SHELL_PARAMS), mod.reference


def wall_thickness(scene, S):
    """The wall's thickness over the pole's, t(S), at the points S from the generated module (the
    structure's own expression, as the equilibrium equations hold it); None for a uniform wall."""
    if scene.thickness_profile is None:
        return None
    mod = _module(_key(scene))
    values = scene.values()
    t = mod.thickness(S, *[values[p] for p in mod.SHELL_PARAMS])[0]
    return np.broadcast_to(np.asarray(t, float), S.shape)


def state_base(state):
    """The base state of ``state`` as a function of S: a dict of ``phi, ls, ks, dls, dks, lt``
    from the inflated state's interpolant (``dls, dks`` its S-derivatives)."""
    return functools.partial(_base_state, state)


def sphere_base(stretch: float):
    """The uniformly stretched sphere ``r = stretch sin S`` of the reference hemisphere (gamma = 1)
    as a base state (no rim layer): the membrane state of a complete sphere under pressure."""
    def base(S):
        one = np.ones_like(S)
        return {"phi": S.copy(), "ls": stretch * one, "ks": one / stretch, "dls": 0 * S, "dks": 0 * S,
                "lt": stretch * one}
    return base


def _base_state(state, S):
    """The base symbols' values at S (dict by name) from an inflated state's interpolant."""
    sysm = state.system
    a, b = sysm.ln_S(sysm.regions[0].start, None), sysm.ln_S(sysm.regions[0].end, None)
    t = (np.log(S) - a) / (b - a)
    y = state.sol(t)
    dy = state.sol.derivative()(t) / (S * (b - a))  # d/dS
    lt, phiS, ls, ks = y[0], y[1], y[2], y[3]
    return {"phi": phiS * S, "ls": ls, "ks": ks, "dls": dy[2], "dks": dy[3], "lt": lt}


def form_at(scene, base_of, S, n):
    """The 9 x 9 form at the points S (shape (9, 9, len(S))) for mode n."""
    f, upper, params, shell_params, ref = form_functions(scene)
    values = scene.values()
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(np.asarray(v, float), S.shape)
                              for v in ref(S, *[values[p] for p in shell_params]))
    base = base_of(S)
    r = base["lt"] * R
    thk = wall_thickness(scene, S)  # a profiled wall: t W + beta t^3 B at each point
    args = (r, base["phi"], base["ls"], base["ks"], base["dls"], base["dks"], R, Psi, dPsi, ks0, kt0,
            *(() if thk is None else (thk,)), *[values[p] for p in params], n)
    with np.errstate(all="ignore"):
        out = f(*args)
    A = np.empty((9, 9, S.size))
    for (i, j), e in zip(upper, out):
        A[i, j] = A[j, i] = np.broadcast_to(np.asarray(e, float), S.shape)
    if "P" in base:  # on the tip: the constraint's curvature, -P/2 II(dx_t, dx_t) per deformed area
        cu, cv = contact_coefficients(base, R, Psi)
        A[0, 0] += cu
        A[3, 3] += cv
    return A, R * Psi


def contact_coefficients(base, R, Psi):
    """The contact term's coefficients of ``u^2`` and ``v^2`` in the form (per dS, module
    docstring): ``-P r psi kappa_s / 4`` and ``-P r psi kappa_theta / 4`` (zero where P = 0)."""
    r = base["lt"] * R
    weight = -0.25 * base["P"] * r * base["ls"] * Psi
    with np.errstate(all="ignore"):
        kt = np.where(base["P"] != 0, np.sin(base["phi"]) / r, 0.0)
    return weight * base["ks"], weight * kt


def reference_shell(scene, S):
    """(R, Psi) of the reference shell at S."""
    f, upper, params, shell_params, ref = form_functions(scene)
    values = scene.values()
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(np.asarray(v, float), S.shape)
                              for v in ref(S, *[values[p] for p in shell_params]))
    return R, Psi


#: Step in t of the directional derivative of the profiles (:func:`chain_base`).
PROFILE_STEP = 1e-6


def chain_base(state, regions=None):
    """The base state of any chain of regions (``regions``: their indices, a closed shell's half
    running from its own pole; default all) as a function of S: ``phi, ls, ks, dls, dks, lt``,
    the contact pressure ``P`` (0 in free regions) and the meridional moment ``Ms``, from each region's generated profile
    (``*_profile``, as ``Solution.profile`` reads them) on the state's interpolant; ``dls, dks``
    are the interpolant's derivatives where they are states of the region (``ls`` always,
    ``ks`` in free regions; near the pole the form's 1/r^3 coefficients cancel, and a
    difference quotient's rounding there moves n = 1 by percents), else the derivatives of the
    profile along the interpolant (central difference of step :data:`PROFILE_STEP` in t along
    ``(S'(t), y'(t))``: the tip's kappa_s)."""
    sysm, p = state.system, state.p
    dsol = state.sol.derivative()
    kernels = sysm.kernels.active
    par = sysm.par_at(p)
    regions = list(range(len(sysm.regions))) if regions is None else list(regions)
    edges = [float(sysm.S_point(sysm.regions[k].end, p)) for k in regions[:-1]]

    def base(S):
        S = np.asarray(S, float)
        out = {k: np.empty_like(S) for k in ("phi", "ls", "ks", "dls", "dks", "lt", "P", "Ms")}
        which = np.searchsorted(edges, S, side="right")
        for i, k in enumerate(regions):
            reg = sysm.regions[k]
            sel = which == i
            if not np.any(sel):
                continue
            Sk = S[sel]
            t = sysm.t_of(k, Sk, p)
            a, b = sysm.ln_S(reg.start, p), sysm.ln_S(reg.end, p)
            y = state.sol(t)[sysm.rows(k)]
            dy = dsol(t)[sysm.rows(k)]
            dS = Sk * (b - a)
            prof = getattr(kernels, f"{reg.kind}_profile")
            h = PROFILE_STEP
            f0 = prof(Sk, y, par)
            fp = prof(Sk + h * dS, y + h * dy, par)
            fm = prof(Sk - h * dS, y - h * dy, par)
            for key, name in (("phi", "phi"), ("ls", "lambda_s"), ("ks", "kappa_s"), ("lt", "lambda_theta"),
                              ("Ms", "M_s")):
                out[key][sel] = np.broadcast_to(f0[name], Sk.shape)
            states = FREE_STATES if reg.kind == "free" else CONTACT_STATES
            for key, name, state_name in (("dls", "lambda_s", "ls"), ("dks", "kappa_s", "ks")):
                if state_name in states:  # a state of the region: its interpolant's derivative
                    out[key][sel] = dy[states.index(state_name)] / dS
                else:
                    out[key][sel] = np.broadcast_to((np.asarray(fp[name]) - np.asarray(fm[name])) / (2 * h),
                                                    Sk.shape) / dS
            out["P"][sel] = np.broadcast_to(f0["P"], Sk.shape) if reg.kind != "free" else 0.0
        return out

    return base
