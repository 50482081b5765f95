"""The ``info`` command's handler: what a curve, sweep, fit, force-map or validation file holds
(its parser: ``shellbvp/cli/info.py``)."""

from __future__ import annotations

import json
import os

import numpy as np

from ...afm import read_map_file
from ...curve_stability import verdict
from ...filekinds import file_kind
from ...fitrecord import read_fit
from ...io import read_curve
from ...plotting import fit_summary_lines
from ...sweeps import read_sweep
from ...validation import read_validation
from ..common import say

__all__ = ["run"]


def _sweep_info(path):
    sw = read_sweep(path)
    s = sw.base_scene
    say(f"file:      {path} (shellbvp sweep)")
    say(f"base:      gamma={s.gamma:g} rho={s.rho:g} beta={s.beta:g} xi={s.xi} contact={s.contact} "
          f"material={s.material!r}")
    for name in sw.parameters:
        say(f"sweeps:    {name} = {', '.join(f'{v:g}' for v in sw.values[name])}")
    say(f"settings:  delta_max={sw.delta_max:g} {json.dumps(sw.settings, sort_keys=True)}")
    counts = ", ".join(f"{v} {k}" for k, v in sw.counts().items())
    wall = np.asarray(sw.index["wall_time"], float)
    done = np.isfinite(wall)
    say(f"curves:    {len(sw.index['status'])} combinations: {counts}")
    if np.any(done):
        say(f"time:      {np.sum(wall[done]):.1f} s of curves in workers; slowest {np.max(wall[done]):.1f} s, "
              f"median {np.median(wall[done]):.1f} s")
    head = " ".join(f"{n:>10s}" for n in sw.parameters)
    say(f"{head} {'status':>9s} {'points':>6s} {'delta_end':>9s} {'F_end':>10s} {'time(s)':>8s}  stop reason")
    for i, st in enumerate(sw.index["status"]):
        c = sw.curves.get(i)
        end = (f"{c.delta[-1]:9.4g} {c.force[-1]:10.5g}" if c is not None and len(c) else f"{'':9s} {'':10s}")
        why = sw.index["stop_reason"][i] or sw.index["message"][i]
        say(" ".join(f"{sw.index[n][i]:10.5g}" for n in sw.parameters)
              + f" {st:>9s} {int(sw.index['points'][i]):6d} {end} {float(sw.index['wall_time'][i]):8.2f}  {why}")
    return 0


def run(args):
    """``shellbvp info FILE``: what a file of shellbvp holds, printed."""
    kind = file_kind(args.file) if os.path.isfile(args.file) else None
    if kind == "fit":
        say(f"file:      {args.file} (a fit)")
        for line in fit_summary_lines(read_fit(args.file)):
            say(f"  {line}")
        return 0
    if kind == "force-map":
        say(f"file:      {args.file} (a force map fitted curve by curve)")
        for line in read_map_file(args.file).summary_lines():
            say(line)
        return 0
    if kind == "validation":
        say(f"file:      {args.file} (a validation: the shell model against the 3D solid)")
        for line in read_validation(args.file).summary_lines():
            say(line)
        return 0
    if kind == "sweep":
        return _sweep_info(args.file)
    c = read_curve(args.file)  # a curve, its checkpoint, or the one-line reason it is neither
    s = c.scene
    mat = s.material
    say(f"file:      {args.file} (shellbvp {c.version})")
    say(f"scene:     gamma={s.gamma:g} rho={s.rho:g} beta={s.beta:g} xi={s.xi} contact={s.contact} "
          f"material={mat!r} bending={s.bending!r} shell={s.shell!r} tip={s.tip!r}"
          + (f" pressure={s.pressure:g} (delta from the inflated pole)" if s.pressure else "")
          + (" sealed (volume control: the pressure is per point)" if s.sealed else ""))
    say(f"sample:    {s.describe(None if c.units is None else c.units['R_L'])}")  # bowl or dome, lab lengths
    say(f"curve:     {c.summary()}")
    say(f"complete:  {c.complete}  interrupted: {c.interrupted}")
    say(verdict(c))
    res = c.energy_residual
    if np.any(np.isfinite(res)):
        say(f"energy identity: max |dE/ddelta - F| = {np.nanmax(np.abs(res)):.3g}")
    if len(c):
        say(f"topology:  {c.topology_summary()}")
        say(f"{'delta':>10s} {'force':>12s} {'lambda0':>9s} {'S1':>10s} {'Sc':>10s} {'topology':>8s} "
              f"{'status':>6s} {'valid':>5s}" + (f" {'pressure':>10s}" if s.sealed else ""))
        for i in range(len(c)):
            say(f"{c.delta[i]:10.5f} {c.force[i]:12.6g} {c.lambda0[i]:9.5f} {c.S1[i]:10.4g} {c.Sc[i]:10.4g} "
                  f"{c.topology[i]:>8s} {int(c.status[i]):6d} {str(bool(c.valid[i])):>5s}"
                  + (f" {c.points['pressure'][i]:10.5g}" if s.sealed else ""))
    return 0
