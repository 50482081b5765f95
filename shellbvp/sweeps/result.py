"""What a sweep returns: :class:`Sweep`, its grid, index and finished curves, with every
curve's force interpolated onto common depths as arrays shaped like the grid."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["STATUSES", "Sweep"]

#: Status of a combination in the index.
STATUSES = ("pending", "complete", "stopped", "error")


@dataclass
class Sweep:
    """A sweep's grid and curves (from :func:`sweep` or :func:`read_sweep`).

    Attributes
    ----------
    parameters : tuple of str
        Swept names, in grid order (the axes of the gridded arrays).
    values : dict of ndarray
        Each parameter's values (an axis of the grid).
    base_scene : Scene
    delta_max : float
    settings : dict
        Curve settings of every curve.
    index : dict of ndarray
        One entry per combination (file order): each parameter's value, ``status``,
        ``stop_reason``, ``message``, ``points``, ``wall_time``.
    curves : dict
        Combination number -> :class:`Curve` (finished curves only).
    computed : int
        Curves computed by the call that returned this (0 from :func:`read_sweep`).
    lost : int
        Curves the executor failed to run in that call (a worker died): still pending.
    delta : ndarray
        The common depths ``linspace(0, delta_max, 101)`` of :attr:`force`.
    force : ndarray, shape ``(len(values[p0]), len(values[p1]), ..., delta.size)``
        Each curve's F at :attr:`delta` (monotone cubic in delta through (0, 0) and its points
        up to its first turn in delta); NaN beyond each curve's deepest point and where the
        combination has no curve.
    status, points, wall_time : ndarray, shape of the grid
        From the index ("" / -1 / NaN where the grid has no such combination).

    Examples
    --------
    >>> import shellbvp as sb
    >>> res = sb.sweep(sb.Scene.preset("base"), {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}, delta_max=0.1,
    ...                workers=1, deltas=[0.05, 0.1], estimate_error=False)
    >>> res.parameters, res.shape, res.force.shape
    (('beta', 'rho'), (2, 2), (2, 2, 101))
    >>> res.counts(), res.finished
    ({'complete': 4}, True)
    >>> bool(res.force[1, 0, -1] > res.force[0, 0, -1])       # a stiffer shell pushes back harder
    True
    """

    parameters: tuple
    values: dict
    base_scene: object
    delta_max: float
    settings: dict
    index: dict
    curves: dict = field(default_factory=dict, repr=False)
    computed: int = 0
    lost: int = 0
    delta: np.ndarray = field(default=None, repr=False)
    force: np.ndarray = field(default=None, repr=False)
    status: np.ndarray = field(default=None, repr=False)
    points: np.ndarray = field(default=None, repr=False)
    wall_time: np.ndarray = field(default=None, repr=False)

    def __post_init__(self):
        from scipy.interpolate import PchipInterpolator

        shape = tuple(len(self.values[p]) for p in self.parameters)
        self.delta = np.linspace(0.0, self.delta_max, 101)
        self.force = np.full(shape + (self.delta.size,), np.nan)
        self.status = np.full(shape, "", dtype=object)
        self.points = np.full(shape, -1, dtype=int)
        self.wall_time = np.full(shape, np.nan)
        for i in range(len(self.index["status"])):
            pos = tuple(int(np.flatnonzero(self.values[p] == self.index[p][i])[0]) for p in self.parameters)
            self.status[pos] = self.index["status"][i]
            self.points[pos] = self.index["points"][i]
            self.wall_time[pos] = self.index["wall_time"][i]
            c = self.curves.get(i)
            if c is None or len(c) < 2:
                continue
            d, F = np.asarray(c.delta, float), np.asarray(c.force, float)
            turn = np.flatnonzero(np.diff(d) <= 0)
            n = turn[0] + 1 if turn.size else d.size  # up to the first turn: F as a function of delta
            x, y = np.r_[0.0, d[:n]], np.r_[0.0, F[:n]]
            ok = np.r_[True, np.diff(x) > 0]
            self.force[pos] = PchipInterpolator(x[ok], y[ok], extrapolate=False)(self.delta)

    @property
    def shape(self):
        return self.status.shape

    def counts(self) -> dict:
        """Number of combinations by status (only the statuses present)."""
        st = list(self.index["status"])
        return {s: st.count(s) for s in STATUSES if s in st}

    @property
    def finished(self) -> bool:
        """No combination is pending."""
        return "pending" not in set(self.index["status"])
