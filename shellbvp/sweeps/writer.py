"""The sweep file as one process writes it: an exclusive lock for as long as a sweep writes
the file (:class:`Lock`), every write made to a copy that then replaces the file atomically,
and the index kept in memory and written with each batch of finished curves
(:class:`Writer`)."""

from __future__ import annotations

import datetime as _dt
import glob
import json
import os
import shutil
from pathlib import Path

from ..io import write_curve_group
from ..paths import atomic_file
from ..version import __version__
from .layout import FORMAT, FORMAT_VERSION, label_units, write_index, write_overview

__all__ = ["Lock", "Writer"]


def _rewrite(path: Path, edit, *, fresh: bool = False) -> None:
    """Apply ``edit(h5file)`` to a copy of ``path`` (a new file if there is none or ``fresh``) and
    rename it into place.

    The rename is the only moment the file changes: an interruption at any point before it
    (Ctrl-C, kill -9, a full disk) leaves the previous complete file, and at most a hidden
    ``.<name>.*.tmp`` beside it (removed here on any Python-level failure).
    """
    import h5py

    with atomic_file(path) as tmp:
        copy = path.exists() and not fresh
        if copy:
            shutil.copyfile(path, tmp)
        with h5py.File(tmp, "a" if copy else "w") as f:
            edit(f)
            f.attrs["updated"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")



class Lock:
    """An exclusive lock on ``<file>.lock`` for as long as a sweep writes ``<file>``.

    Two sweeps writing one file would each replace the other's additions (every write is a
    copy of the file as that process last saw it), so a second one is refused.  ``flock`` is
    released by the kernel when the process ends, however it ends (a ``kill -9`` leaves no
    stale lock).  Where ``fcntl`` does not exist (Windows) no lock is taken.
    """

    def __init__(self, path: Path):
        self.path = path.with_name(path.name + ".lock")
        self.fh = None

    def __enter__(self):
        try:
            import fcntl
        except ImportError:
            return self
        while True:
            try:
                fh = open(self.path, "a+")  # held open for the sweep: the lock lives with it
            except OSError as exc:
                raise ValueError(f"{self.path}: cannot be the sweep's lock file ({exc.strerror}); remove it or "
                                 f"choose another output file") from None
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                fh.close()
                raise ValueError(f"{self.path.with_suffix('')} is being written by another sweep (lock "
                                 f"{self.path}); wait for it to end, or choose another output file") from None
            try:  # the file locked must still be the one at the path (another sweep may have removed it)
                same = os.stat(self.path).st_ino == os.fstat(fh.fileno()).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self.fh = fh
                return self
            fh.close()

    def __exit__(self, *exc):
        if self.fh is not None:
            self.path.unlink(missing_ok=True)  # while still locked: a waiting sweep sees it gone and retries
            self.fh.close()


class Writer:
    """The sweep file as this process writes it: the index in memory, each write atomic (_rewrite)."""

    def __init__(self, path: Path | None, names, index, meta):
        self.path, self.names, self.index, self.meta = path, names, index, meta

    def start(self, fresh: bool):
        """Write the metadata and the index (every combination pending or as found)."""
        if self.path is None:
            return
        # a killed writer's temporary files (we hold the lock); the name is escaped: run[12].h5 is
        # a name, not a pattern that matches other writers' files
        for debris in self.path.parent.glob(f".{glob.escape(self.path.name)}.*.tmp"):
            debris.unlink(missing_ok=True)

        def edit(f):
            f.attrs["NX_class"] = "NXroot"
            f.attrs["format"], f.attrs["format_version"] = FORMAT, FORMAT_VERSION
            f.attrs["package_version"] = __version__
            if "created" not in f.attrs:
                f.attrs["created"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
            f.attrs["default"] = "sweep"  # NeXus: root -> sweep (NXentry) -> overview (NXdata)
            s = f.require_group("sweep")
            s.attrs["NX_class"] = "NXentry"
            s.require_group("curves").attrs["NX_class"] = "NXcollection"
            for key in ("base_scene", "settings"):
                s.attrs[key] = json.dumps(self.meta[key], sort_keys=True)
            for key in ("parameters", "grid"):  # in grid order
                s.attrs[key] = json.dumps(self.meta[key])
            s.attrs["delta_max"] = self.meta["delta_max"]
            s.attrs["units"] = "nondimensional"
            write_index(s, self.names, self.index)
            write_overview(s, self.names, self.meta, self.index)

        _rewrite(self.path, edit, fresh=fresh)

    def add(self, records, curves):
        """Enter finished records in the index and write their curves (one atomic write)."""
        for rec in records:
            i = rec["index"]
            for key in ("status", "message", "wall_time"):
                self.index[key][i] = rec[key]
            if i in curves:
                self.index["stop_reason"][i] = rec["stop_reason"]
                self.index["points"][i] = len(rec["points"]["delta"])
                self.index["group"][i] = f"curves/curve_{i:06d}"
        if self.path is None:
            return

        def edit(f):
            s = f["sweep"]
            for rec in records:
                name = self.index["group"][rec["index"]]
                if name:
                    if name in s:  # a pending combination has no group; kept safe all the same
                        del s[name]
                    write_curve_group(s.create_group(name), curves[rec["index"]])
                    label_units(s[name])
            write_index(s, self.names, self.index)
            write_overview(s, self.names, self.meta, self.index)

        _rewrite(self.path, edit)
