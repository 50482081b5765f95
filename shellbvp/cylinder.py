"""Contact with the indenter's cylinder: the shell that meets the indenter's side.

A large indenter, or a deep one, brings the free shell beyond the tip's contact
edge against the indenter's cylinder ``r = rho A(omega_max)``.  As it goes deeper
the shell passes through three configurations (``shellbvp.chain``), each
following on from the one before without a jump in F:

``cap+line(cylinder)``
    the free shell touches the wall on one circle (a ring force), while the shell
    there bends away from the wall;
``cap+band(cylinder)``
    the circle has become a band of contact on the wall, with a free gap between
    it and the cap on the tip;
``cap+cylinder``
    the gap has closed: the contact runs from the tip onto the wall, passing the
    tip's end at S*, where omega = omega_max and ``[lambda_s dU/dlambda_s - U] = 0``
    (lambda_s jumps where the indenter's meridional curvature does).

Where several are valid at one depth the state of lower energy is the state
(SPEC section 7).  This module makes guesses (from a cap state or from a
neighbouring configuration), solves and diagnoses (``shellbvp.diagnosis``), and
chooses.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .chain import ChainBVP, TipEnd
from .configurations import configuration, is_single_cap, names
from .diagnosis import diagnose
from .solution import Solution, failure, finished, passed_tip_end, richardson_error, warm_mesh

__all__ = ["WALL_TOPOLOGIES", "wall_again", "cap_onto_wall", "make_wall_system", "wall_contact_suspected", "solve_chain_from", "wall_state",
           "best_wall_state", "transfer_guess"]

#: The configurations with contact on the cylinder (``shellbvp.configurations``, family
#: "wall"), in the order they follow each other as the indenter goes deeper.
WALL_TOPOLOGIES = names("wall")
#: A cap whose contact edge has reached this fraction of the tip's end, and whose free shell
#: passes through the indenter, is tried against the wall configurations.
NEAR_TIP_END = 0.7
#: The smallest node budget of a wall state's solve (see :func:`wall_state`).
WALL_MIN_NODES = 2000
#: relative half widths of the band guessed from a cap's touch point, and from a line (narrow first:
#: a band is born from its line with zero width; beta 1e-5 just past the switch at 0.8381: 1e-4,
#: and 0.02 ran away to the node budget)
_BAND_HALF_WIDTH = 0.02
_BAND_FROM_LINE_HALF_WIDTHS = (0.002, 0.02)
_CAP_SPLITS = ((0.97, 1.15), (0.9, 1.3), (0.99, 1.05))  # (S*/Sc, Sc'/Sc) of cap+cylinder guesses from a cap


def make_wall_system(scene, topology, control, value, eps):
    """The system of a wall configuration (``WALL_TOPOLOGIES``)."""
    if topology not in WALL_TOPOLOGIES:
        raise ValueError(f"topology must be one of {WALL_TOPOLOGIES}; got {topology!r}")
    return configuration(topology).system(scene, control, value, eps)


def wall_contact_suspected(cap: Solution) -> bool:
    """A converged cap that passed the tip's end, or whose free shell passes through the
    indenter with its contact edge near the tip's end."""
    if not is_single_cap(cap) or cap.system is None or cap.scene.model().OMEGA_MAX is None:
        return False
    passed = passed_tip_end(cap)
    omega_max = cap.scene.tip_omega_max
    near = bool(cap.success and cap.penetration > 0
                and omega_max - cap.tip_end_margin > NEAR_TIP_END * omega_max)  # the edge's omega
    return passed or near


# -- guesses --------------------------------------------------------------------------------------
def _fields_at(sol, S):
    """Physical fields of a solution at the points S (each from the region that holds it)."""
    sysm = sol.system
    out = None
    for k, reg in enumerate(sysm.regions):
        t = sysm.t_of(k, S, sol.p)
        inside = (t >= 0) & (t <= 1) if k < len(sysm.regions) - 1 else (t >= 0)
        if k == 0:
            inside = inside | (t < 0)
        if out is not None:
            inside = inside & ~out["set"]
        if not np.any(inside):
            continue
        prof = getattr(sysm.model, f"{reg.kind}_profile")(S[inside], sol.sol(np.clip(t[inside], 0, 1))[sysm.rows(k)],
                                                           sysm.par)
        if out is None:
            out = {key: np.full(S.shape, np.nan) for key in (*prof, "omega")}
            out["set"] = np.zeros(S.shape, bool)
        for key, v in prof.items():
            out[key][inside] = v
        if reg.kind != "free":
            out["z"][inside] = out["z"][inside] + sol.z_tip
        out["set"] |= inside
    return out


def _free_states(f, S):
    return np.vstack([f["lambda_theta"], f["phi"] / S, f["lambda_s"], f["kappa_s"], f["r"] * f["Q"], f["z"]])


def _wall_omega(sysm, z, z_tip):
    """omega of the wall point at height z (the cylinder continues the tip at unit speed)."""
    mod, par = sysm.model, sysm.par
    w0 = mod.OMEGA_MAX
    z_end = z_tip + sysm.scene.rho * float(mod.tip_shape(np.array([w0]), par)["B"][0])
    return w0 + np.maximum(z - z_end, 0.0) / sysm.scene.rho


def transfer_guess(sysm: ChainBVP, source: Solution, n: int = 101, **unknowns):
    """Guess for ``sysm`` from a solution of another configuration: the target's unknowns as
    given (``ln_Sc=..., chi1=...``; lambda0 and delta from the source), the states at every
    target S from the source's fields there (free states from its profile; on the tip or the
    wall omega from the source where it is in contact, else from the shell's height)."""
    rho = sysm.scene.rho
    values = dict(unknowns, lambda0=source.lambda0, delta=source.delta)
    p = sysm.pack(**values)
    t = np.linspace(0.0, 1.0, n)
    blocks = []
    for k, reg in enumerate(sysm.regions):
        S = sysm.S(k, t, p)
        f = _fields_at(source, S)
        if reg.kind == "free":
            blocks.append(_free_states(f, S))
            continue
        omega = f["omega"]
        if reg.kind == "cylinder":
            omega = np.where(np.isfinite(omega) & (omega >= sysm.model.OMEGA_MAX), omega,
                             _wall_omega(sysm, f["z"], source.z_tip))
            omega = np.maximum.accumulate(omega)
        elif not np.all(np.isfinite(omega)):
            # where the source is free (a lifted pole coming down): the tip's point at its radius,
            # from the system's tip table (attach_tip_table)
            grid = np.linspace(0.0, sysm.scene.tip_omega_max, sysm.tip_A.size)
            omega = np.where(np.isfinite(omega), omega, np.interp(f["r"] / rho, sysm.tip_A, grid))
        if any(isinstance(j, TipEnd) and j.k == k for j in sysm.junctions):  # reach omega_max at S*
            w_end = omega[-1]
            omega = omega * (sysm.model.OMEGA_MAX / w_end) ** ((S / S[-1]) ** 2)
        blocks.append(np.vstack([rho * omega / S, f["lambda_s"]]))
    return t, np.vstack(blocks), p


def _touch_point(cap):
    """(S, omega on the wall) where a cap's free shell comes nearest the wall from inside."""
    sysm = cap.system
    t = np.linspace(0.0, 1.0, 801)
    S = sysm.S(1, t, cap.p)
    f = sysm.model.free_profile(S, cap.sol(t)[sysm.rows(1)], sysm.par)
    above = f["z"] > cap.z_tip + cap.scene.rho  # above the tip's end (sphere: B(omega_max) = 1)
    gap = np.where(above, f["r"] - cap.scene.rho * sysm.tip_A[-1], np.inf)
    i = int(np.argmin(gap))
    return float(S[i]), float(_wall_omega(sysm, f["z"][i:i + 1], cap.z_tip)[0])


def _unknowns(state):
    return dict(zip(state.system.unknowns, state.p))


def _cap_to_cylinder(sysm, cap):
    Sc = cap.Sc
    return [transfer_guess(sysm, cap, ln_Send=math.log(a * Sc), ln_Sc=math.log(b * Sc)) for a, b in _CAP_SPLITS]


def _cap_to_wall_line(sysm, cap):
    S1, w1 = _touch_point(cap)
    return [transfer_guess(sysm, cap, ln_Sc=math.log(cap.Sc), ln_S1=math.log(S1), chi1=cap.scene.rho * w1 / S1)]


def _cap_to_band(sysm, cap):
    S1, _ = _touch_point(cap)
    return [transfer_guess(sysm, cap, ln_Sc=math.log(cap.Sc), ln_S1=math.log(S1 * (1 - _BAND_HALF_WIDTH)),
                           ln_S2=math.log(S1 * (1 + _BAND_HALF_WIDTH)))]


def _wall_line_to_band(sysm, line):
    q = _unknowns(line)
    S1 = math.exp(q["ln_S1"])
    return [transfer_guess(sysm, line, ln_Sc=q["ln_Sc"], ln_S1=math.log(S1 * (1 - w)), ln_S2=math.log(S1 * (1 + w)))
            for w in _BAND_FROM_LINE_HALF_WIDTHS]


def _band_to_cylinder(sysm, band):
    q = _unknowns(band)
    Sc, S1, S2 = (math.exp(q[k]) for k in ("ln_Sc", "ln_S1", "ln_S2"))
    return [transfer_guess(sysm, band, ln_Send=math.log(0.5 * (Sc + S1)), ln_Sc=math.log(S2))]


def _band_to_wall_line(sysm, band):
    q = _unknowns(band)
    S1 = math.sqrt(math.exp(q["ln_S1"] + q["ln_S2"]))
    w1 = float(_fields_at(band, np.array([S1]))["omega"][0])
    return [transfer_guess(sysm, band, ln_Sc=q["ln_Sc"], ln_S1=math.log(S1), chi1=band.scene.rho * w1 / S1)]


def _cylinder_to_band(sysm, state):
    q = _unknowns(state)
    Se, Sc = math.exp(q["ln_Send"]), math.exp(q["ln_Sc"])
    return [transfer_guess(sysm, state, ln_Sc=math.log(0.98 * Se), ln_S1=math.log(1.02 * Se), ln_S2=math.log(Sc))]


#: How a wall configuration is guessed from a state of another: {(from, to): guesses}
_GUESSES = {
    ("cap", "cap+cylinder"): _cap_to_cylinder,
    ("cap", "cap+line(cylinder)"): _cap_to_wall_line,
    ("cap", "cap+band(cylinder)"): _cap_to_band,
    ("cap+line(cylinder)", "cap+band(cylinder)"): _wall_line_to_band,
    ("cap+band(cylinder)", "cap+cylinder"): _band_to_cylinder,
    ("cap+band(cylinder)", "cap+line(cylinder)"): _band_to_wall_line,
    ("cap+cylinder", "cap+band(cylinder)"): _cylinder_to_band,
}


def _guesses(sysm, start):
    """Guesses for ``sysm`` from ``start`` (a cap, or a wall state of this or a neighbouring
    configuration), best first; none where no transition is known."""
    if start.topology == sysm.topology:  # a warm start
        x = warm_mesh(start)
        q = dict(_unknowns(start), lambda0=start.lambda0, delta=start.delta)
        return [(x, start.sol(x), sysm.pack(**q))]
    guesses = _GUESSES.get((start.topology, sysm.topology))
    return [] if guesses is None else guesses(sysm, start)


# -- solving and choosing ---------------------------------------------------------------------------
def solve_chain_from(sysm, guess, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10, max_jacobians=None):
    """One solve_bvp run of ``sysm`` from ``guess = (x, y, p)``, diagnosed."""
    x, y, p = guess
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        bvp = sysm.solve(x, y, p, tol=tol, bc_tol=bc_tol, max_nodes=max_nodes, max_jacobians=max_jacobians)
        res = diagnose(sysm, bvp, tol)
    return res.with_(wall_time=time.perf_counter() - t0)


def _control_of(start, control, value):
    if control is None:
        control = start.control if start.control in ("force", "lambda0") else "delta"
        value = {"force": start.force, "lambda0": start.lambda0, "delta": start.delta}[control]
    return control, value


def wall_state(start: Solution, topology: str, *, control=None, value=None, tol=1e-6, max_nodes=10000,
               bc_tol=1e-10, estimate_error=False):
    """The ``topology`` state (one of WALL_TOPOLOGIES) at ``start``'s delta (or the given control
    and value), from a cap state or a wall state; the first guess that converges.  Returns a
    Solution (check ``success`` and ``valid``), a failure if no guess can be made."""
    control, value = _control_of(start, control, value)
    t0 = time.perf_counter()
    sysm = make_wall_system(start.scene, topology, control, value, start.system.eps)
    # a node budget of a few times the start's mesh, as for every guessed configuration: valid
    # wall states need about their cap's mesh (stability grid: <= 650 nodes), and a guess whose
    # mesh runs away (a boundary layer: no such state) fails fast instead of at max_nodes
    kw = dict(tol=tol, max_nodes=int(min(max_nodes, max(WALL_MIN_NODES, 4 * start.nodes))), bc_tol=bc_tol)
    res = None
    for guess in _guesses(sysm, start):
        res = solve_chain_from(sysm, guess, **kw)
        if res.success:
            break
    if res is None:
        res = failure(5, f"no guess for {topology} from a {start.topology} state", scene=sysm.scene,
                      control=None, value=None, topology=topology)
    elif res.success and estimate_error:
        res = richardson_error(sysm, res, tol, bc_tol)
    return res.with_(wall_time=time.perf_counter() - t0)


def _neighbours(topology):
    order = list(WALL_TOPOLOGIES)
    if topology not in order:
        return order
    i = order.index(topology)
    return [order[i]] + order[i + 1:i + 2] + order[max(i - 1, 0):i]


def best_wall_state(start: Solution, *, control=None, value=None, tol=1e-6, max_nodes=10000, bc_tol=1e-10,
                    tried=None, outcomes=None):
    """The valid wall configuration of lowest energy at ``start``'s depth, or None.

    From a cap every configuration is tried; from a wall state its own configuration, the
    next deeper one and the one before.  ``tried`` (a list) collects what was tried and why
    it was not taken, ``outcomes`` (a list) the status of each attempt.
    """
    tried = [] if tried is None else tried
    outcomes = [] if outcomes is None else outcomes
    order = list(WALL_TOPOLOGIES) if is_single_cap(start) else _neighbours(start.topology)
    order = [t for t in order if configuration(t).allows(start.scene)]
    valid = []
    for topology in order:
        res = wall_state(start, topology, control=control, value=value, tol=tol, max_nodes=max_nodes,
                         bc_tol=bc_tol)
        outcomes.append(int(res.status))
        if res.success and res.valid:
            valid.append(res)
        else:
            tried.append(f"{topology}: {res.message if not res.success else '; '.join(res.flags)}")
    if not valid:
        return None
    best = min(valid, key=lambda r: r.energy)
    return best.with_(candidates={r.topology: r.energy for r in valid})


def wall_again(guess, control, value, *, topology, tol, max_nodes, eps, bc_tol, estimate_error):
    """``solve(guess=...)`` from a wall state: the valid wall configuration of lowest energy
    (auto) or the asked one; None (back to the single cap) where that does not converge."""
    t0 = time.perf_counter()
    kw = dict(control=control, value=value, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    res = best_wall_state(guess, **kw) if topology == "auto" else (
        wall_state(guess, topology, **kw) if topology in WALL_TOPOLOGIES else None)
    if res is not None and res.success:
        return finished(res, t0, estimate_error, tol, bc_tol)
    return None


def cap_onto_wall(cap, topology, kw):
    """The asked wall configuration, or (auto) the valid one of lowest energy where the cap
    passes the tip's end or its free shell passes through the indenter near it; else the
    cap, with what was tried in its flags."""
    if cap.system is None or cap.scene.model().OMEGA_MAX is None:
        return cap
    if not (cap.success or passed_tip_end(cap)):
        return cap
    if topology in WALL_TOPOLOGIES:
        return wall_state(cap, topology, **kw)
    if not wall_contact_suspected(cap):
        return cap
    tried = []
    alt = best_wall_state(cap, tried=tried, **kw)
    if alt is None:
        return cap.with_(flags=list(cap.flags) + ["no valid contact with the indenter's cylinder (" + "; ".join(tried)
                                                  + ")"])
    return alt
