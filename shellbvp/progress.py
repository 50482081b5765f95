"""Progress bars (tqdm, an optional extra: ``pip install 'shellbvp[progress]'``).

Bars are drawn on stderr when it is a terminal and the caller did not ask for quiet
(``-q``).  When stderr is a file or a pipe (a batch job, a log) a line is written there
instead every ``OPTIONS.progress_seconds`` (``SHELLBVP_PROGRESS_SECONDS``), none for a task shorter
than that.  Without tqdm, or when quiet, a silent stand-in with the same methods takes the
bar's place, so callers never test for it.
"""

from __future__ import annotations

import sys
import time

from .config import OPTIONS

__all__ = ["progress_bar", "curve_progress", "wanted"]


class _Silent:
    """The methods of a tqdm bar that the package uses, doing nothing."""

    def __init__(self, total=None):
        self.total, self.n = total, 0

    def update(self, n=1):
        self.n += n

    def set_postfix_str(self, text="", refresh=True):
        pass

    def set_description_str(self, text="", refresh=True):
        pass

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False




class _Lines(_Silent):
    """Progress as a line on stderr every ``OPTIONS.progress_seconds`` (for logs: no bar to redraw)."""

    def __init__(self, total=None, desc="", unit=""):
        super().__init__(total)
        self.desc, self.unit, self.postfix = desc, unit, ""
        self.start = self.last = time.monotonic()
        self.written = False

    def _write(self, note=""):
        done = f"{self.n:.4g}" + (f"/{self.total:.4g}" if self.total else "")
        extra = f", {self.postfix}" if self.postfix else ""
        what = f"{self.unit} " if self.unit else ""
        print(f"{self.desc}: {what}{done}{extra} ({time.monotonic() - self.start:.0f} s){note}", file=sys.stderr,
              flush=True)
        self.written = True

    def update(self, n=1):
        self.n += n
        now = time.monotonic()
        if now - self.last >= OPTIONS.progress_seconds:
            self.last = now
            self._write()

    def set_postfix_str(self, text="", refresh=True):
        self.postfix = text

    def close(self):
        if self.written:  # a task that reported progress reports its end too
            self._write("; done")
            self.written = False


def wanted(quiet: bool = False, stream=None):
    """How to show progress: ``"bar"`` (stderr is a terminal), ``"lines"`` (a file or a pipe:
    a line now and then) or False (quiet)."""
    stream = sys.stderr if stream is None else stream
    if quiet:
        return False
    return "bar" if hasattr(stream, "isatty") and stream.isatty() else "lines"


def progress_bar(total=None, *, desc="", unit="it", enabled=True, leave=True, **kwargs):
    """A tqdm bar on stderr, or a silent stand-in (tqdm absent or ``enabled`` false).

    Parameters
    ----------
    total : float, optional
        The end of the bar (a count, or a depth for :func:`curve_progress`).
    desc, unit : str
    enabled : bool or str
        Draw it (see :func:`wanted`): True or ``"bar"`` a tqdm bar, ``"lines"`` a line on stderr
        every ``OPTIONS.progress_seconds``, False nothing.
    leave : bool
        Keep the finished bar on screen.
    **kwargs
        Passed to ``tqdm.tqdm`` (e.g. ``bar_format``).

    Examples
    --------
    >>> with progress_bar(3, enabled=False) as bar:
    ...     bar.update(1)
    >>> bar.n
    1
    """
    if not enabled:
        return _Silent(total)
    if enabled == "lines":
        return _Lines(total, desc, unit)
    try:
        from tqdm import tqdm
    except ImportError:  # the optional extra is not installed: no bar
        return _Silent(total)
    return tqdm(total=total, desc=desc, unit=unit, leave=leave, file=sys.stderr, dynamic_ncols=True, **kwargs)


def curve_progress(delta_max, desc="curve", enabled=True, leave=True):
    """A bar over the pole displacement toward ``delta_max`` and the callback that moves it.

    Returns
    -------
    bar
        Close it when the curve is done.
    callback : callable
        ``callback(curve, sol)``, the signature of :func:`shellbvp.curve`'s ``callback``.
    """
    fmt = "{desc}: {percentage:3.0f}%|{bar}| delta {n:.3f}/{total:.3f} [{elapsed}<{remaining}{postfix}]"
    bar = progress_bar(float(delta_max), desc=desc, unit="delta", enabled=enabled, leave=leave, bar_format=fmt)

    def callback(curve, sol):
        d = float(sol.delta) if sol.delta == sol.delta else bar.n  # NaN delta: no move
        step = min(max(d, 0.0), float(delta_max)) - bar.n
        if step > 0:
            bar.update(step)
        bar.set_postfix_str(f"{len(curve)} points, F = {float(sol.force):.4g}", refresh=False)

    return bar, callback
