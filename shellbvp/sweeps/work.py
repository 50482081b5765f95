"""A sweep's work: one curve computed in a worker and returned as a plain record
(:func:`run_curve`: arrays, strings and numbers, no module objects), a record made a
:class:`~shellbvp.io.Curve` again in the parent, and the queue of curves run through an
executor with finished records passed on in batches (:func:`compute`)."""

from __future__ import annotations

import logging
import time
from concurrent.futures import FIRST_COMPLETED, wait

import numpy as np

from ..config import OPTIONS
from ..continuation import curve
from ..io import Curve

log = logging.getLogger(__name__)

__all__ = ["run_curve", "curve_of", "compute"]


def run_curve(index: int, scene, delta_max: float, settings: dict) -> dict:
    """Compute one curve of a sweep and return it as a plain record (what a worker sends back).

    A curve that raises is recorded with status "error" and the exception's text: it is a
    result (the same inputs raise again), not a lost task.
    """
    t0 = time.perf_counter()
    try:
        c = curve(scene, delta_max, **settings)
    except Exception as exc:  # recorded in the index with its message, never hidden
        return {"index": index, "status": "error", "message": f"{type(exc).__name__}: {exc}",
                "wall_time": time.perf_counter() - t0}
    return {"index": index, "status": "complete" if c.complete else "stopped", "message": "",
            "stop_reason": c.stop_reason, "complete": c.complete, "interrupted": c.interrupted,
            "points": {k: np.asarray(v) for k, v in c.points.items()}, "flags": list(c.flags),
            "settings": c.settings, "version": c.version, "inflated": c.inflated, "wall_time": time.perf_counter() - t0}


def curve_of(record, scene) -> Curve:
    return Curve(scene=scene, points=record["points"], flags=record["flags"], stop_reason=record["stop_reason"],
                 complete=record["complete"], interrupted=record["interrupted"], settings=record["settings"],
                 version=record.get("version", ""), inflated=record.get("inflated"))


def _executor_gone(executor) -> bool:
    """A Dask executor whose client has closed (its scheduler gone, reconnection given up)."""
    status = getattr(getattr(executor, "_client", None), "status", None)
    return status is not None and status not in ("running", "connecting", "newly-created")


def compute(todo, args_of, executor, on_records):
    """Run :func:`run_curve` on ``args_of(i)`` for each i in ``todo``, through ``executor`` (None:
    in this process), passing finished records on in batches (whatever finished meanwhile).

    Returns (computed, lost): tasks the executor could not run (a worker died, or a Dask client
    closed: checked whenever ``OPTIONS.health_seconds`` pass without a finished curve) are lost,
    logged and left pending.  On an interruption, tasks not yet started are cancelled.
    """
    if executor is None:
        for i in todo:
            on_records([run_curve(*args_of(i))])
        return len(todo), 0
    computed = lost = 0
    futures = {}
    try:
        futures = {executor.submit(run_curve, *args_of(i)): i for i in todo}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, timeout=OPTIONS.health_seconds, return_when=FIRST_COMPLETED)
            if not done and _executor_gone(executor):  # a cluster that went away never finishes them
                lost += len(pending)
                log.warning("the Dask client is %s: %d curves were not computed; they stay pending",
                            executor._client.status, len(pending))
                break
            records = []
            for fut in done:
                try:
                    records.append(fut.result())
                except Exception as exc:  # the executor failed (a worker died): logged, stays pending
                    lost += 1
                    log.warning("curve %d was not computed (%s: %s); it stays pending", futures[fut],
                                type(exc).__name__, exc)
            computed += len(records)
            if records:
                on_records(records)
    finally:
        for fut in futures:  # after an interruption: what has not started never starts
            fut.cancel()
    return computed, lost
