"""The ``solve`` command's handler: one state, printed (its parser: ``shellbvp/cli/solve.py``)."""

from __future__ import annotations

import json

import numpy as np

from ...state import solve
from ...units import force_unit_of, format_in
from ..common import nondimensional, strict_json
from ..scene_options import scene_from_args

__all__ = ["run"]


def run(args):
    """``shellbvp solve``: exit 0 when the state converged, 1 otherwise."""
    scene = scene_from_args(args)
    given = {k: nondimensional(args, v, f"--{k}") for k, v in (("delta", args.delta), ("lambda0", args.lambda0),
                                                                ("force", args.load)) if v is not None}
    if not given:
        given = {"delta": 0.2}
    sol = solve(scene, tol=args.tol, max_nodes=args.max_nodes, topology=args.topology, **given)
    keys = ("success", "status", "message", "topology", "delta", "force", "lambda0", "S1", "Sc", "pressure",
            "ring_force", "ring_force_inner", "cap_force",
            "pressure_min", "penetration", "valid", "flags", "energy", "force_defect", "force_error",
            "delta_error", "nodes", "niter", "max_residual", "wall_time")
    if scene.transverse_shear:  # the thick shell's pole is at delta + shear_delta
        keys = keys[:5] + ("shear_delta",) + keys[5:]
    out = {k: getattr(sol, k) for k in keys}
    out = {k: (float(v) if isinstance(v, (np.floating,)) else v) for k, v in out.items()}
    if (args.radius is None) != (args.mu_h is None):
        raise ValueError("--radius and --muH go together (rim radius, e.g. 0.3mm, and mu*H, e.g. 52N/m)")
    shown = {}
    if args.radius is not None:  # the state in the units given: displacement R_L delta, force mu_H R_L F
        out["displacement_m"] = args.radius.si * sol.delta
        out["force_N"] = args.mu_h.si * args.radius.si * sol.force
        shown = {"displacement": args.radius.show(out["displacement_m"]),
                 "force (SI)": format_in(out["force_N"], force_unit_of(args.mu_h.unit), "force")}
    if args.profiles and sol.success:
        out["profile"] = {k: np.asarray(v).tolist() for k, v in sol.profile().items()}
    if args.json:
        print(json.dumps(strict_json(out), allow_nan=False))
    else:
        for k in keys:
            print(f"{k:>16s}: {out[k]}")
        for k, v in shown.items():
            print(f"{k:>16s}: {v}")
        if args.profiles and sol.success:
            prof = sol.profile()
            cols = ("S", "region", "r", "z", "lambda_s", "lambda_theta", "kappa_s", "kappa_theta",
                    "M_s", "Q", "P")
            print(" ".join(f"{c:>13s}" for c in cols))
            for i in range(prof["S"].size):
                print(" ".join(f"{prof[c][i]:13.6g}" for c in cols))
    return 0 if sol.success else 1
