"""Which of the package's files a path holds, and what to do with a file a command does not take.

Every HDF5 file the package writes names its kind in the root's ``format`` attribute: a curve
(``shellbvp curve``), a sweep, a fit (``shellbvp fit -o``), a force map (a JPK map's ``fit -o``)
or a validation (``shellbvp validate``).  ``info`` reads each; ``plot`` and ``report`` the ones
they can draw, and for the others :func:`wrong_kind` says which command reads them.
"""

from __future__ import annotations

from .afm import MAP_FORMAT
from .fitrecord import FIT_FORMAT
from .io import FORMAT as CURVE_FORMAT
from .sweeps.layout import FORMAT as SWEEP_FORMAT
from .validation import FORMAT as VALIDATION_FORMAT

__all__ = ["file_kind", "wrong_kind", "KINDS"]

#: The kinds of file, in the order the messages list them.
KINDS = ("curve", "sweep", "fit", "force-map", "validation")

#: What reads each kind.
_READ_BY = {
    "curve": "`shellbvp info` lists its points, `shellbvp plot` draws it",
    "sweep": "`shellbvp info` lists its curves, `shellbvp plot` draws them",
    "fit": "`shellbvp info`, `shellbvp plot` and `shellbvp report` read it",
    "force-map": "`shellbvp info` summarises it, `shellbvp plot` and `shellbvp report` draw its image of mu*H, "
                 "`shellbvp plot --pixel IX,IY` one pixel's fit",
    "validation": "`shellbvp info` prints its comparison, `shellbvp plot` and `shellbvp report` draw it",
}


def _formats() -> dict:
    return {CURVE_FORMAT: "curve", SWEEP_FORMAT: "sweep", FIT_FORMAT: "fit", MAP_FORMAT: "force-map",
            VALIDATION_FORMAT: "validation"}


def file_kind(path) -> str | None:
    """The kind of the package's file at ``path`` (one of :data:`KINDS`), by its root's ``format``
    attribute; None for anything else (missing, a directory, not HDF5, another format)."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
    except (OSError, ValueError, TypeError):
        return None
    if isinstance(fmt, bytes):
        fmt = fmt.decode("utf-8", "replace")
    return _formats().get(fmt) if isinstance(fmt, str) else None


def wrong_kind(path, kind: str, command: str, takes: str) -> ValueError:
    """The one-line error of ``shellbvp command`` given a ``kind`` file it does not take (the
    command line prints it escaped)."""
    return ValueError(f"{path} is a {kind} file; `shellbvp {command}` takes {takes}; "
                      f"{_READ_BY[kind]}")
