"""Output paths checked before any work is done (the CLI's ``-o`` of curve, fit and plot), and
files published atomically."""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

__all__ = ["require_file", "check_output_path", "partial_path", "atomic_file", "atomic_hdf5", "open_hdf5", "read_input_bytes",
           "MAX_INPUT_BYTES"]

#: The largest input file read whole (a measured curve is kilobytes to a few megabytes).
MAX_INPUT_BYTES = 256 * 2**20


def read_input_bytes(path, max_bytes=MAX_INPUT_BYTES) -> bytes:
    """The bytes of the regular file ``path``; ValueError with one line for a FIFO, a device, a
    directory, a socket (read without blocking: a FIFO with no writer must not hang a batch) or
    a file larger than ``max_bytes``."""
    import stat

    kinds = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise ValueError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            what = next((name for test, name in kinds if test(mode)), "not a regular file")
            raise ValueError(f"{path}: is {what}, not a data file")
        size = os.fstat(fd).st_size
        if size > max_bytes:
            raise ValueError(f"{path}: {size / 2**20:.0f} MiB, more than the {max_bytes / 2**20:.0f} MiB a curve file "
                             f"may have")
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            total += len(chunk)
            if total > max_bytes:  # a file that grows while read
                raise ValueError(f"{path}: more than {max_bytes / 2**20:.0f} MiB")
            chunks.append(chunk)
        return b"".join(chunks)
    except OSError as exc:
        raise ValueError(f"{path}: cannot read ({exc.strerror})") from None
    finally:
        os.close(fd)


def require_file(path) -> None:
    """ValueError in one line unless ``path`` exists: the reading commands' first check, made
    before their handlers load numpy and h5py (``shellbvp info missing.h5`` answers at once)."""
    if not os.path.exists(path):
        raise ValueError(f"{path}: no such file")


def open_hdf5(path, *, fmt: str, group, kind: str):
    """The HDF5 file at ``path`` opened for reading (use it in ``with``), once it is known to be a
    shellbvp ``kind`` file: attribute ``format == fmt`` and a group ``group`` (or one of several
    paths, for a layout that changed between versions).  ValueError with one line naming the path
    otherwise (missing, a directory, not HDF5, another format)."""
    import h5py

    path = Path(path)
    if not path.exists():
        raise ValueError(f"{path}: no such file")
    if path.is_dir():
        raise ValueError(f"{path}: is a directory, not a {kind} file")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise ValueError(f"{path}: not a readable HDF5 file ({' '.join(str(exc).split())})") from None
    found = f.attrs.get("format")
    found = found.decode("utf-8", "replace") if isinstance(found, bytes) else found
    groups = (group,) if isinstance(group, str) else tuple(group)
    if not (isinstance(found, str) and found == fmt and any(isinstance(f.get(g), h5py.Group) for g in groups)):
        f.close()
        raise ValueError(f"{path}: not a shellbvp {kind} file (format attribute missing or different)")
    return f


@contextmanager
def atomic_file(path):
    """A temporary file beside ``path`` (yielded as a Path) that is renamed onto ``path`` when the
    block ends without error, with the usual permissions (mkstemp makes 0600), and removed on any
    error: a reader never sees a half-written file and an earlier complete one stays until then."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextmanager
def atomic_hdf5(path):
    """An HDF5 file built in memory (yielded open for writing), then written to ``path`` as
    :func:`atomic_file` does.  Why in memory: HDF5 writing into a file on a full disk (ENOSPC,
    EFBIG) fails while it flushes and closes, and h5py then prints a traceback per object
    released and the process can crash at exit; plain file writes fail with one OSError, which
    names ``path`` here.  A file of the package is kilobytes to a few megabytes."""
    import io

    import h5py

    path = Path(path)
    buffer = io.BytesIO()
    with h5py.File(buffer, "w") as f:
        yield f
    image = buffer.getbuffer()
    try:
        with atomic_file(path) as tmp, open(tmp, "wb") as out:
            out.write(image)
            out.flush()
            os.fsync(out.fileno())
    except OSError as exc:
        raise OSError(exc.errno, f"cannot write {path}: {exc.strerror or exc}") from None


def partial_path(path) -> Path:
    """The checkpoint file of ``path``: ``X.h5`` -> ``X.h5.partial`` (same directory)."""
    path = Path(path)
    return path.with_name(path.name + ".partial")


def check_output_path(path, *, overwrite: bool) -> Path:
    """Check that a file can be written at ``path``, before computing what goes in it.

    Parameters
    ----------
    path : str or Path
    overwrite : bool
        An existing file may be replaced.

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        One line naming the path and what is wrong: empty, a directory, a parent
        that does not exist or is not a directory, a directory where no file can
        be created (probed by creating and removing a temporary file there:
        ``os.access`` says yes on read-only mounts, ``/proc`` and for root),
        or an existing file without ``overwrite``.
    """
    text = os.fspath(path)
    if not text.strip():
        raise ValueError("the output path is empty")
    if text.endswith(os.sep) or os.path.isdir(text):
        raise ValueError(f"output {text} is a directory; give a file name")
    out = Path(text)
    parent = out.parent
    if not parent.exists():
        raise ValueError(f"output directory {parent} does not exist")
    if not parent.is_dir():
        raise ValueError(f"output directory {parent} is not a directory")
    if out.exists() and not overwrite:
        raise ValueError(f"output {out} exists; use --overwrite to replace it")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"output directory {parent} is not writable")
    try:
        fd, probe = tempfile.mkstemp(dir=parent, prefix=f".{out.name}.", suffix=".probe")
    except OSError as exc:
        raise ValueError(f"output directory {parent} is not writable (creating a file there: "
                         f"{exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
    return out  # files are written to a temporary file there and renamed over ``out``
