"""The checkout these benchmarks belong to, for the processes they start.

A script run as ``python benchmarks/x.py`` has ``benchmarks/`` first on ``sys.path``, not the
checkout, so ``import shellbvp`` finds whatever is installed.  Processes started with
:func:`checkout_env` import this checkout's package, the one whose commit the results name.
"""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def checkout_env(**extra) -> dict:
    """``os.environ`` with ``extra`` and this checkout first on ``PYTHONPATH``."""
    env = dict(os.environ, **extra)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, (str(ROOT), os.environ.get("PYTHONPATH"))))
    return env
