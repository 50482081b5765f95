"""The ``presets`` command: the built-in scenes."""

from __future__ import annotations



__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``presets`` subcommand's arguments, on ``sub`` (the subparsers)."""
    r = sub.add_parser("presets", help="list the built-in scenes")
    r.set_defaults(func=run)


def run(args):
    from ..scene import PRESETS

    for name, p in PRESETS.items():
        sc = p["scene"]
        shape = (f"shell=R,Z,L=({', '.join(sc['shell'])})" if isinstance(sc.get("shell"), tuple)
                 else f"gamma={sc['gamma']:<5g}")
        extra = f" pressure={sc['pressure']:g}" if sc.get("pressure") else ""
        extra += " sealed" if sc.get("sealed") else ""
        print(f"{name:9s} {shape} rho={sc['rho']:<7.4g} beta={sc['beta']:<6g} "
              f"xi={sc['xi']} material={sc['material']!r}{extra}  -- {p['doc']}")
    return 0
