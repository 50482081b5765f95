"""Where a sweep's curves are computed: a local process pool whose workers end with the
process that started them (:func:`local_pool`, :func:`die_with_parent`), or a Dask cluster
reached at a checked address (:func:`dask_executor`)."""

from __future__ import annotations

import logging
import multiprocessing
import os
import re
import time
from concurrent.futures import ProcessPoolExecutor

__all__ = ["SCHEDULER_ADDRESS", "dask_executor", "local_pool", "die_with_parent"]

#: Scheduler addresses a sweep connects to: plain TCP (``tcp://host:port`` or ``host:port``).
#: TLS needs certificates set up in Dask's own configuration, UCX a build of its own, inproc a
#: scheduler in this process: each is refused with a line saying so.
SCHEDULER_ADDRESS = re.compile(r"^(?:tcp://)?(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):([0-9]{1,5})$")


def dask_executor(address: str, timeout: float = 10.0):
    """A ``concurrent.futures.Executor`` on the Dask cluster at ``address`` (needs ``shellbvp[dask]``).

    The address is checked before anything is imported or contacted; the connection, handshake
    included, must succeed within ``timeout`` seconds (a peer that accepts and never answers, or
    answers junk, is one line, not a hang or a traceback).
    """
    import threading

    text = str(address).strip()
    scheme = text.split("://", 1)[0] if "://" in text else "tcp"
    if not text:
        raise ValueError("--scheduler: the address is empty; give host:port or tcp://host:port")
    if scheme != "tcp":
        raise ValueError(f"--scheduler {text!r}: only tcp:// addresses are supported (host:port or "
                         f"tcp://host:port); {scheme}:// is not")
    m = SCHEDULER_ADDRESS.match(text)
    if not m or not 0 < int(m.group(1)) < 65536:
        raise ValueError(f"--scheduler {text!r}: not an address host:port or tcp://host:port (port 1-65535)")
    try:
        from dask.distributed import Client
        # a lost scheduler is reported once, as the curves it leaves pending (work.compute), not as the
        # client's multi-line tracebacks of every reconnection attempt
        for name in ("distributed.client", "distributed.core", "distributed.comm"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
    except ImportError:
        raise ValueError("a Dask scheduler needs the dask extra: pip install 'shellbvp[dask]' "
                         "(dask[distributed])") from None
    result = {}

    def connect():  # in a daemon thread: a handshake that never ends must not keep the process
        try:
            result["client"] = Client(text, timeout=f"{timeout}s")
        except BaseException as exc:  # noqa: BLE001 -- any failure of the peer is reported as one line
            result["error"] = exc

    worker = threading.Thread(target=connect, daemon=True, name="dask-connect")
    worker.start()
    worker.join(timeout + 5.0)
    if worker.is_alive():
        raise ValueError(f"the Dask scheduler at {text!r} did not answer within {timeout + 5:g} s")
    if "error" in result:
        exc = result["error"]
        raise ValueError(f"cannot use the Dask scheduler at {text!r}: {type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:200]}") from None
    return result["client"].get_executor()


def local_pool(workers=None):
    """A process pool of ``workers`` processes (default: all cores), started by spawn; each
    worker ends when the process that started it does (:func:`die_with_parent`)."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers must be an integer >= 1; got {workers!r}")
    # spawn, not fork: workers start clean whatever threads the parent runs (Dask, h5py)
    return ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1,
                               mp_context=multiprocessing.get_context("spawn"),
                               initializer=die_with_parent, initargs=(os.getpid(),))


def die_with_parent(parent_pid: int, period: float = 0.5) -> None:
    """In a worker: exit as soon as ``parent_pid`` is no longer this process's parent (the
    parent was killed, even by ``kill -9``, and the worker was handed to init), instead of
    living on with the dead parent's pipes open (a caller reading them would never see EOF).
    A daemon thread polls ``os.getppid()``; ``prctl(PR_SET_PDEATHSIG)`` is not used: it fires
    when the *thread* that started the worker ends, which a pool's thread may do early."""
    import threading

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(period)
        os._exit(1)

    if os.getppid() != parent_pid:  # the parent died before the worker got here
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()
