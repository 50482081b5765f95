"""One diagnosis for every contact configuration: a solve_bvp result -> a :class:`Solution`.

Reads the chain's declaration (``shellbvp.chain``): the force is the axial force of the
region that ends at the rim; every contact edge (tip or cylinder) and line carries a ring
force, the jump of the axial force across it (``ring_force`` at the outermost edge,
``ring_force_inner`` at the innermost of several) and a normal ring force
``-2 pi r [Q]`` (``edge_forces``, all edges, pole to rim) that must push; every contact
region a pressure (``pressure_min``); no free region may pass through the indenter.
"""

from __future__ import annotations

import math

import numpy as np

from .chain import FREE_STATES, ContactPole, Edge, FreePole, Line, PointPole, Seam, TipEnd
from .solution import STATE_NUMBERS, Solution, penetration, run_status, wall_gap
from .thickness import shear_delta

__all__ = ["diagnose", "as_failure"]

_LS, _LT = FREE_STATES.index("ls"), FREE_STATES.index("lt")


def _edges(sysm):
    """(S point, inner region, outer region) of each contact edge and line, pole to rim (of a
    closed shell on a substrate: its upper half's, on the tip)."""
    out = []
    upper = set(_halves(sysm)[0])
    for j in sysm.junctions:
        if isinstance(j, (Edge, Line)) and (j.kc if isinstance(j, Edge) else j.k) not in upper:
            continue
        if isinstance(j, Edge):
            inner, outer = min(j.kc, j.kf), max(j.kc, j.kf)
            out.append((sysm.regions[inner].end, inner, outer))
        elif isinstance(j, Line):
            out.append((sysm.regions[j.k].end, j.k, j.k + 1))
    return out


def _at(sysm, k, kind, S, y):
    """The generated profile of a ``kind`` region at one point S with state y (the kernel set of
    region ``k``'s half)."""
    return getattr(sysm.region_kernels[k].active, f"{kind}_profile")(np.array([S], dtype=float), y[:, None],
                                                                      sysm.par)


def _shear_delta(sysm, parts, edges, ends):
    """What transverse shear adds to the pole displacement (:mod:`shellbvp.thickness`), from the
    free shell outside the outermost contact edge or ring (all of it under a point load)."""
    start = edges[-1][2] if edges else 0
    edge_r = ends[start][0]["r"] if edges else 0.0
    kinds = [(sysm.regions[k].kind, f) for k, _, f in parts]
    return shear_delta(kinds, start, edge_r, sysm.scene.thickness)


def _legendre_min(sysm, t, y, p):
    """(min, where) over every free region of the Legendre determinant det d(tau_s, M_s)/d(lambda_s,
    kappa_s), relative to its median magnitude there (scale-free; < 0: U is not convex in
    (lambda_s, kappa_s) there, the free equations are singular where it crosses 0); ``y``: the
    solution on ``t``."""
    best, where = math.inf, math.nan
    for k, reg in enumerate(sysm.regions):
        if reg.kind != "free":
            continue
        S = sysm.S(k, t, p)
        det = sysm.region_kernels[k].active.free_legendre(S, y[sysm.rows(k)], sysm.par)[0]
        scale = _median(np.abs(det))
        if not scale > 0:
            continue
        i = int(np.argmin(det))
        if det[i] / scale < best:
            best, where = float(det[i] / scale), float(S[i])
    return (best, where) if math.isfinite(best) else (math.nan, math.nan)


def _median(a) -> float:
    """np.median of a 1-D array, the same value, by one partition (np.median's generic path
    cost ~25 µs a state at ~400 points, the partition ~7 µs)."""
    if a.size == 0 or np.isnan(a).any():
        return math.nan
    m = a.size // 2
    if a.size % 2:
        return float(np.partition(a, m)[m])
    q = np.partition(a, (m - 1, m))
    return float(0.5 * (q[m - 1] + q[m]))


def _nodes_and_midpoints(x):
    """The mesh and its intervals' midpoints, sorted, without repeats (a midpoint equals a node
    where an interval is within rounding of zero width)."""
    t = np.empty(2 * x.size - 1)
    t[0::2] = x
    t[1::2] = 0.5 * (x[1:] + x[:-1])
    return t if np.all(t[1:] > t[:-1]) else np.unique(t)


def _edge_model(sysm) -> str:
    """The name ``Solution.contact_edge`` holds: the model of a contact edge that jumps (a
    Weierstrass-Erdmann corner) if there is one, else the edges' one model ("" if none or mixed)."""
    models = {j.model for j in sysm.junctions if isinstance(j, Edge)}
    shown = next((m for m in models if m.jumps), next(iter(models)) if len(models) == 1 else None)
    return "" if shown is None else shown.name


_EDGE_FIELDS = ("axial_force_2pi", "r", "Q", "lambda_s", "kappa_s")  # what the edges' checks read


def _pick(fields, i):
    """The edge fields of a profile (arrays over the points, or constants) at point i."""
    picked = {}
    for key in _EDGE_FIELDS:
        v = fields[key]
        picked[key] = float(v[i] if np.ndim(v) else v)
    return picked


def _edge_jumps(sysm, ends):
    """Jumps (free minus contact side) of lambda_s and kappa_s at the outermost contact edge;
    ``ends[k]``: region k's profile fields at its (start, end)."""
    edges = [j for j in sysm.junctions if isinstance(j, Edge)]
    if not edges:
        return 0.0, 0.0
    j = edges[-1]
    side = (1, 0) if j.kc < j.kf else (0, 1)  # which end of the contact and the free region meet
    on, free = ends[j.kc][side[0]], ends[j.kf][side[1]]
    return free["lambda_s"] - on["lambda_s"], free["kappa_s"] - on["kappa_s"]


def diagnose(sysm, bvp, tol, converged_note: str = "", result: type = Solution) -> Solution:
    """The Solution of a solve_bvp run of ``sysm`` (a ChainBVP) with the model's checks
    (``result``: Solution or a subclass with a configuration's own fields).

    Status 4 (inadmissible) for edges out of order, non-positive stretches, delta < 0, a
    tip contact past the tip's end or a cylinder contact below it; ``valid`` also needs
    pressures and ring forces that push and no penetration (``flags`` say what failed).
    """
    nan = float("nan")
    p = bvp.p
    sysm = sysm.at(p)  # under volume control, the parameters at the solution's pressure
    q = sysm.quantities(p) if sysm.k else sysm.quantities(None)
    ya, yb = bvp.y[:, 0], bvp.y[:, -1]
    force, delta = sysm.end_values(ya, yb, p)
    par = sysm.par
    # the upper pole (a closed shell on a substrate declares its lower half's junctions first)
    first = next((j for j in sysm.chain.junctions if isinstance(j, (ContactPole, FreePole, PointPole)) and j.k == 0),
                 sysm.chain.junctions[0])
    lambda0 = (q["lambda0"] if isinstance(first, ContactPole)
               else ya[sysm.rows(0)][_LS] if isinstance(first, FreePole) else nan)
    edges = _edges(sysm)
    S_edges = [sysm.S_point(pt, p) for pt, _, _ in edges] or [0.0]
    # the state's fields, gathered here and built into one Solution at the end
    res = dict(
        topology=sysm.topology, x=bvp.x, y=bvp.y,
        p=p if p is not None else np.empty(0), sol=bvp.sol,
        rms_residuals=bvp.rms_residuals, tol=tol, niter=int(bvp.niter), nodes=int(bvp.x.size),
        max_residual=float(np.max(bvp.rms_residuals)) if bvp.rms_residuals.size else nan,
        delta=float(delta), lambda0=float(lambda0), Sc=S_edges[-1], force=float(force), edge_S=S_edges,
        # where the contact starts from the pole's side: the pole itself, or a lifted pole's first edge
        S1=S_edges[0] if isinstance(first, FreePole) else 0.0,
        control=sysm.control, scene=sysm.scene, system=sysm,
        z_tip=sysm.pole_height - float(delta), pressure=sysm.pressure,
    )
    z_tip = res["z_tip"]
    tip_end = next((j for j in sysm.junctions if isinstance(j, TipEnd)), None)
    if tip_end is not None:
        res["S_end"] = sysm.S_point(sysm.regions[tip_end.k].end, p)
    flags = []
    finite = bool(np.all(np.isfinite(bvp.y)) and (p is None or np.all(np.isfinite(p))) and math.isfinite(force))
    if not finite:
        flags.append("non-finite state")
    elif bvp.status == 0:
        for half in _halves(sysm):  # each half of a closed shell on a substrate from its own pole
            bounds = [sysm.S_point(sysm.regions[k].start, p) for k in half]
            bounds.append(sysm.S_point(sysm.regions[half[-1]].end, p))
            if not (bounds[0] > 0 and np.all(np.diff(bounds) > 0)):
                flags.append("region boundaries not ordered inside (0, L): " + ", ".join(f"{b:.3g}" for b in bounds))
        stretches = [bvp.y[sysm.offsets[k] + (_LS if r.kind == "free" else 1)] for k, r in enumerate(sysm.regions)]
        stretches += [bvp.y[sysm.offsets[k] + _LT] for k, r in enumerate(sysm.regions) if r.kind == "free"]
        if (math.isfinite(lambda0) and lambda0 <= 0) or any(np.any(s <= 0) for s in stretches):
            flags.append("non-positive stretch")
        if delta < 0:
            flags.append(f"collapsed state with delta = {delta:.3g} < 0")
    if not finite:
        res.update(run_status(bvp, flags, converged_note), energy=nan, shear_delta=nan, pressure_min=nan,
                   penetration=nan, force_defect=nan, edge_legendre=nan, legendre_min=nan, legendre_min_S=nan,
                   edge_jump_ls=nan, edge_jump_ks=nan, contact_edge=_edge_model(sysm),
                   ring_force=nan, ring_force_inner=nan, cap_force=nan, edge_forces=[], valid=False, flags=flags)
        return _built(result, res)

    t = _nodes_and_midpoints(bvp.x)  # from 0 to 1: the regions' ends
    y_t = bvp.sol(t)
    parts = sysm.region_profiles(t, y_t, p)
    ends = {k: (_pick(f, 0), _pick(f, -1)) for k, _, f in parts}  # (start, end) of region k
    # ring forces: jumps of the axial force (2 pi G) and of r Q across each edge, outer minus inner
    axial, normal = [], []
    for _, inner, outer in edges:
        fi, fo = ends[inner][1], ends[outer][0]
        axial.append(2 * np.pi * float(fo["axial_force_2pi"] - fi["axial_force_2pi"]))
        normal.append(-2 * np.pi * float(fo["r"] * fo["Q"] - fi["r"] * fi["Q"]))
    res["ring_force"] = axial[-1] if axial else float(force)  # no edge: a point force
    res["ring_force_inner"] = axial[0] if len(axial) > 1 else 0.0
    res["edge_forces"] = normal
    res["cap_force"] = float(force) - sum(axial) if axial else 0.0
    contact = [(k, f) for k, _, f in parts if sysm.regions[k].kind != "free"]
    res["pressure_min"] = min((float(np.min(f["P"])) for _, f in contact), default=nan)
    free = [(k, f) for k, _, f in parts if sysm.regions[k].kind == "free"]
    defect = 0.0
    for k, f in free:
        G = 2 * np.pi * f["axial_force_2pi"]
        ref = 0.0 if (k == 0 and isinstance(first, FreePole)) else G[0]
        defect = max(defect, float(np.max(np.abs(G - ref))))
    res["force_defect"] = defect
    below = set(_halves(sysm)[1]) if len(_halves(sysm)) > 1 else set()  # the half on the substrate
    res["penetration"] = through = max(float(np.max(f["z"])) - sysm.half_pole_height(k) if k in below
                                       else penetration(sysm, f["r"], f["z"], z_tip) for k, f in free)
    res["wall_gap"] = min(wall_gap(sysm, f["r"], f["z"], z_tip) for k, f in free if k not in below)
    last = len(sysm.regions) - 1
    t_leg = np.array([0.0, 0.5])
    leg = sysm.region_kernels[last].active.free_legendre(sysm.S(last, t_leg, p), bvp.sol(t_leg)[sysm.rows(last)],
                                                        par)[0]
    res["edge_legendre"] = float(leg[0] / leg[1]) if leg[1] != 0 else nan
    res["legendre_min"], res["legendre_min_S"] = legendre = _legendre_min(sysm, t, y_t, p)
    res["contact_edge"] = _edge_model(sysm)
    res["edge_jump_ls"], res["edge_jump_ks"] = _edge_jumps(sysm, ends)
    res["energy"] = sysm.energy(bvp.sol, bvp.x, p)
    res["shear_delta"] = _shear_delta(sysm, parts, edges, ends) if sysm.scene.transverse_shear else 0.0

    admissible, vflags = [], []
    omega_max = sysm.scene.tip_omega_max
    on_tip = [float(np.max(f["omega"])) for k, f in contact if sysm.regions[k].kind == "contact"]
    res["tip_end_margin"] = omega_max - max(on_tip) if on_tip else float("nan")  # < 0: past the tip's end
    past_end = False
    for k, f in contact:
        lo, hi = float(np.min(f["omega"])), float(np.max(f["omega"]))
        if sysm.regions[k].kind == "contact" and hi > omega_max * (1 + 1e-9):
            admissible.append("the contact has passed the end of the tip (the indenter's cylinder)")
            past_end = True
        if sysm.regions[k].kind == "cylinder" and lo < omega_max * (1 - 1e-9):
            admissible.append("the contact on the cylinder runs back onto the tip")
    for j in sysm.junctions:
        if isinstance(j, Line):
            w = q[j.chi] * sysm.S_point(sysm.regions[j.k].end, p) / sysm.scene.rho
            if j.on == "contact" and w > omega_max * (1 + 1e-9):
                admissible.append("the contact has passed the end of the tip (the indenter's cylinder)")
                past_end = True
            if j.on == "cylinder" and w < omega_max * (1 - 1e-9):
                admissible.append("the contact line on the cylinder runs back onto the tip")
    if admissible and bvp.status == 0:
        flags = flags + admissible
        res["past_tip_end"] = past_end  # a reason of its status 4, for the callers that go on on the cylinder
    res.update(run_status(bvp, flags, converged_note))
    if isinstance(first, PointPole) and force < 0:
        vflags.append(f"negative point force ({force:.3g})")
    scale = 10 * tol * (1 + abs(force))
    for k, f in contact:
        where = {"cylinder": "the cylinder", "plane": "the substrate"}.get(sysm.regions[k].kind, "the tip")
        if float(np.min(f["P"])) < -scale:
            vflags.append(f"negative contact pressure on {where} (min P = {float(np.min(f['P'])):.3g})")
    for (pt, _, _), N in zip(edges, normal):
        if N < -scale:
            vflags.append(f"negative ring force ({N:.3g}) at the contact edge {pt.name}")
    if legendre[0] < 0:
        vflags.append(f"the energy is not convex in (lambda_s, kappa_s) in the free region (Legendre "
                      f"determinant {legendre[0]:.3g} of its median at S = {legendre[1]:.4g}): "
                      f"not an energy minimum")
    if through > 10 * tol:
        vflags.append(f"the free shell passes through the indenter (by {through:.3g})")
    for j in sysm.junctions:
        if isinstance(j, Line):
            # touching on a circle, the shell must not bend more tightly than the indenter there
            # (else it passes through it next to the line: the contact is a band)
            S = sysm.S_point(sysm.regions[j.k].end, p)
            yin = yb[sysm.rows(j.k)]
            on = _at(sysm, j.k, j.on, S, np.array([q[j.chi], yin[_LS]]))
            res["curvature_excess"] = excess = float(yin[FREE_STATES.index("ks")] - on["kappa_s"][0])
            if excess > 10 * tol * max(1.0, abs(float(on["kappa_s"][0]))):
                vflags.append(f"the shell bends more tightly than the indenter at the contact line "
                              f"(kappa_s exceeds the indenter's by {excess:.3g}): the contact is "
                              f"{'a band' if j.on == 'cylinder' else 'an annulus'}")
    res.update(flags=flags + vflags, valid=res["success"] and not vflags)
    return _built(result, res)


def _halves(sysm) -> list:
    """The regions' indices by the pole they run from: one list, or a closed shell's two halves
    on a substrate (upper, lower; :class:`~shellbvp.chain.Seam`)."""
    seam = next((j for j in sysm.junctions if isinstance(j, Seam)), None)
    n = len(sysm.regions)
    return [list(range(n))] if seam is None else [list(range(seam.ku + 1)), list(range(seam.ku + 1, n))]


def _built(result, fields):
    """The one Solution (``result``: the class) of a diagnosis, built from its ``fields``."""
    return _without_iterate_numbers(result(**fields))


def _without_iterate_numbers(res):
    """``res``, or where its run did not converge, ``res`` with the state's numbers NaN but the
    prescribed one (as given)."""
    if res.status in (0, 4):  # converged (admissible or not)
        return res
    prescribed = res.control  # the prescribed delta, lambda0 or force is known all the same
    nan = float("nan")
    out = {key: nan for key in STATE_NUMBERS if key != prescribed}
    if prescribed in STATE_NUMBERS and res.system is not None:
        out[prescribed] = float(res.system.value)  # as given (the iterate's force is not it)
    out.update(edge_forces=[nan] * len(res.edge_forces), edge_S=[nan] * len(res.edge_S), valid=False,
               # the tip's height follows from delta: known only where delta is prescribed
               z_tip=res.z_tip if prescribed == "delta" else nan)  # per-edge lists: as many NaN as edges
    if res.system is not None and res.system.volume_control:  # the pressure was an unknown
        out["pressure"] = nan
    return res.with_(**out)


def as_failure(res, status, message):
    """``res`` (a diagnosed Solution) as a failure with ``status`` (1, 2, 3 or 5) and
    ``message``: the state's numbers NaN as for any run that did not converge (a converged
    but inadmissible state that stands for a failed search must not keep its numbers)."""
    if status in (0, 4):
        raise ValueError(f"status must be that of a failure (1, 2, 3 or 5); got {status}")
    nan = float("nan")
    return _without_iterate_numbers(res.with_(status=status, message=message, success=False, force_error=nan,
                                              delta_error=nan))
