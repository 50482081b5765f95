"""The ``presets`` command's handler: the built-in scenes listed (its parser: ``shellbvp/cli/presets.py``)."""

from __future__ import annotations

from ...presets import PRESETS

__all__ = ["run"]


def run(args):
    """``shellbvp presets``: one line per built-in scene."""
    for name, p in PRESETS.items():
        sc = p["scene"]
        shape = (f"shell=R,Z,L=({', '.join(sc['shell'])})" if isinstance(sc.get("shell"), tuple)
                 else f"gamma={sc['gamma']:<5g}")
        extra = f" pressure={sc['pressure']:g}" if sc.get("pressure") else ""
        extra += " sealed" if sc.get("sealed") else ""
        print(f"{name:9s} {shape} rho={sc['rho']:<7.4g} beta={sc['beta']:<6g} "
              f"xi={sc['xi']} material={sc['material']!r}{extra}  -- {p['doc']}")
    return 0
