"""The ``presets`` command: the built-in scenes."""

from __future__ import annotations

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``presets`` subcommand's arguments, on ``sub`` (the subparsers)."""
    r = sub.add_parser("presets", help="list the built-in scenes")
    r.set_defaults(func=run)


def run(args):
    """The handler (``handlers/presets.py``), imported now: the parser loads no numpy."""
    from .handlers import presets

    return presets.run(args)
