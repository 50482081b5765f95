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


#: What a benchmark writes: changes there do not make the measured code "dirty"
RESULTS = ("benchmarks/results", "benchmarks/figures")


def commit_label(src=ROOT, default=None):
    """``git describe --always`` of the checkout at ``src``, with ``-dirty`` only for changes
    outside :data:`RESULTS` (a run that writes one result before measuring the next must not
    label the code it measures dirty); ``default`` where ``src`` is not a git checkout."""
    import subprocess

    def git(*args):
        return subprocess.run(["git", "-C", str(src), *args], capture_output=True, text=True)

    head = git("describe", "--always")
    if head.returncode != 0:
        return default
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".",
                  *(f":(exclude){path}" for path in RESULTS))
    return head.stdout.strip() + ("-dirty" if changed.stdout.strip() else "")


# -- where a benchmark writes (benchmarks/run.py passes ``--out-dir``) ----------------------------

HERE = ROOT / "benchmarks"


def add_output_args(ap, quick=None):
    """Add ``--out-dir DIR`` (``results/`` and ``figures/`` under DIR; default ``benchmarks/``) and, when
    ``quick`` is its help text, ``--quick`` (a smaller problem whose files carry a ``-quick`` suffix)."""
    ap.add_argument("--out-dir", type=Path, default=None,
                    help="write results/ (and figures/) under this directory (default benchmarks/)")
    if quick:
        ap.add_argument("--quick", action="store_true", help=f"{quick} (writes *-quick files)")
    return ap


def results_dir(out_dir=None) -> Path:
    """``results/`` under ``out_dir`` (default ``benchmarks/``), made if missing."""
    path = (Path(out_dir) if out_dir else HERE) / "results"
    path.mkdir(parents=True, exist_ok=True)
    return path


def figures_dir(out_dir=None) -> Path:
    """``figures/`` under ``out_dir`` (default ``benchmarks/``), made if missing."""
    path = (Path(out_dir) if out_dir else HERE) / "figures"
    path.mkdir(parents=True, exist_ok=True)
    return path


def stem(name, quick=False):
    """A result's file name without its suffix: ``name`` or ``name-quick``."""
    return f"{name}-quick" if quick else name


def write_atomic(path, text):
    """Write ``text`` to ``path`` through a temporary file beside it (no half-written result)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
    return path
