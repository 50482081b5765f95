"""Records kept in the code cache between processes (the shell model's curves in ``curves/``,
the solid's in ``solid_curves/``): data from disk, checked before use.

A kept record is used only when its file is a regular file of this user that no one else may
write, no larger than its kind allows, readable, and sound by its kind's own check (a checksum of
its contents, its key, its depths, finite numbers).  A record that fails is reported once (a
warning naming the file and why), set aside as ``<name>.bad`` and computed again: a damaged or
edited file never changes a fit, and never fails one.  A folder that cannot hold records (not
a folder, another user's, writable by others, read-only, a full disk) turns the disk off for
that kind with one warning: fits compute their curves, as with
``sb.options(model_curve_cache=False)``.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from pathlib import Path

from ..model import cache_dir, untrusted_reason
from ..textdata import printable

__all__ = ["checksum", "kept_folder", "read_kept", "keep", "set_aside", "forget_warnings"]

log = logging.getLogger(__name__)

# what this process has warned about already (a file or a folder): each once
_told: set = set()


def forget_warnings():
    """Warn again about files and folders warned about before (tests)."""
    _told.clear()


def _warn_once(about, text):
    if about in _told:
        return
    _told.add(about)
    log.warning("%s", printable(text))


def checksum(data) -> str:
    """SHA-256 of ``data`` as canonical JSON (sorted keys): a record's fingerprint."""
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()


def kept_folder(name: str, what: str) -> Path | None:
    """The code cache's folder ``name`` where it can hold ``what`` (it need not exist yet), else
    None with one warning saying why (not a folder, another user's, writable by others)."""
    folder = cache_dir() / name
    why = None
    if os.path.lexists(folder):
        why = "it is not a folder" if not folder.is_dir() else untrusted_reason(folder)
    if why is not None:
        _warn_once(folder, f"not keeping {what} in {folder}: {why}; fits compute their own")
        return None
    return folder


def set_aside(path: Path, why: str, what: str) -> None:
    """Rename the unusable record ``path`` to ``<name>.bad`` (so it is not read again), with one
    warning naming it and why."""
    bad = path.with_name(path.name + ".bad")
    try:
        os.replace(path, bad)
        where = f"set aside as {bad.name}"
    except OSError as exc:
        where = f"left in place (renaming it: {exc.strerror or exc})"
    _warn_once(path, f"kept {what} {path} not used: {why}; {where}; computed again")


def read_kept(path: Path | None, read, check, *, what: str, max_bytes: int):
    """``read(path)`` when the kept record at ``path`` is there and sound, else None.

    ``check(record)`` says why a record read cannot be used (or None); ``read`` may raise
    ValueError or OSError for a file it cannot read.  A record that fails any check is set
    aside (:func:`set_aside`).
    """
    if path is None or not os.path.lexists(path):
        return None
    why = untrusted_reason(path)
    record = None
    try:
        if why is None and not path.is_file():
            why = "it is not a regular file"
        elif why is None and path.stat().st_size > max_bytes:
            why = f"larger than the {max_bytes} bytes such a record may have"
        if why is None:
            record = read(path)
    except (OSError, ValueError) as exc:
        why = f"unreadable ({' '.join(str(exc).split())[:200]})"
    if why is None:
        why = check(record)
    if why is None:
        return record
    set_aside(path, why, what)
    return None


def keep(path: Path | None, write, *, what: str) -> bool:
    """Write a record: ``write(tmp)`` into a temporary file beside ``path``, renamed onto it
    (mode 0644: the trust checks refuse files others may write).  Never raises: a folder that
    cannot be written (read-only, full, not a folder) is reported once and the partial file
    removed.  True when kept."""
    if path is None:
        return False
    tmp = None
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.close(fd)
        write(Path(tmp))
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
        return True
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else ' '.join(str(exc).split())
        _warn_once(("keep", path.parent), f"cannot keep {what} in {path.parent} ({reason}); fits compute their own")
        return False
    finally:
        if tmp is not None and os.path.lexists(tmp):
            try:
                os.unlink(tmp)
            except OSError:
                pass
