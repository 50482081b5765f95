"""The ``validate`` command's handler: the shell model against a 3D finite-element model (its
parser: ``shellbvp/cli/validate.py``)."""

from __future__ import annotations

import time

from ...fe import check_fe_size, check_solid_scene, fe_size
from ...paths import check_output_path
from ...validation import validate
from ..common import free_default_name, nondimensional, plain_numbers
from ..scene_options import scene_from_args

__all__ = ["run"]


def run(args):
    """``shellbvp validate``: exit 0 when the 3D model's curve converged, 1 otherwise."""
    scene = scene_from_args(args)
    args.delta_max = nondimensional(args, args.delta_max, "--delta-max")
    if scene.thickness is None:
        raise ValueError("validate needs --thickness (H/R_L, or with a unit and --radius)")
    check_solid_scene(scene)
    if not (0 < args.delta_max <= 2):
        raise ValueError(f"--delta-max must be in (0, 2]; got {args.delta_max:g}")
    deltas = None
    if args.deltas:
        deltas = plain_numbers(args.deltas, "--deltas")
        if any(not 0 < d <= 2 for d in deltas) or any(b <= a for a, b in zip(deltas, deltas[1:])):
            raise ValueError("--deltas must be increasing pole displacements in (0, 2]")
    out = check_output_path(args.output if args.output is not None
                            else free_default_name(f"{args.preset or 'base'}-validate", args.force), overwrite=args.force)
    try:
        import felupe  # noqa: F401
    except ImportError:
        raise ValueError("validate needs FElupe: pip install 'shellbvp[fe]'") from None
    size = fe_size(scene, scene.thickness)
    check_fe_size(size)  # before the shell's curve too: one line, no work
    t0 = time.perf_counter()
    shell = "with its transverse shear" if scene.transverse_shear else "Kirchhoff (no transverse shear)"
    pole = "" if scene.thickness_profile is None else " at the pole (the wall's profile in the sample line)"
    print(f"scene: {args.preset or 'base'}, eps = H/R_L = {scene.thickness:.4g}{pole}, beta = {scene.beta:.4g}; "
          f"3D model (FElupe) and shell model, {shell}, at the same pole displacements", flush=True)
    print(f"sample: {scene.describe(None if args.radius is None else args.radius.si)}", flush=True)
    print(f"3D model: {size.describe()} (estimated)", flush=True)
    result = validate(scene, deltas=deltas, delta_max=args.delta_max, mesh_check=args.mesh_check, tol=args.tol,
                      R_L=None if args.radius is None else args.radius.si, max_nodes=args.max_nodes,
                      progress=lambda i, d, f: print(f"  FE: delta = {d:.4g}, F = {f:.5g}", flush=True))
    print(result.table())
    if not result.fe.success:
        print(f"FE: {result.fe.message}")
    result.to_hdf5(out, overwrite=args.force)
    print(f"wrote {out} ({time.perf_counter() - t0:.1f} s)")
    return 0 if result.fe.success else 1
