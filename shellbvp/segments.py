"""The segments of a force–displacement record: each row labelled approach, loading, hold,
retraction or other by the direction of the displacement over time (:func:`segment`), and a
first contact point from the force's baseline (:func:`estimate_contact`)."""

from __future__ import annotations

import numpy as np

__all__ = ["SEGMENTS", "FIT_SEGMENTS", "segment", "estimate_contact", "smoothed_slope"]

#: Labels of the rows of a record (:func:`segment`).
SEGMENTS = ("approach", "loading", "hold", "retraction", "other")
#: What ``fit`` may use: ``loading`` (the pushing part: the approach before contact and
#: the loading after it, which together fix the baseline and the contact point),
#: ``retraction`` (the unloading branch) or ``all`` (every row, in any order).
FIT_SEGMENTS = ("loading", "retraction", "all")


def _runs(state):
    """[(value, start, stop)] of the runs of equal values."""
    edges = np.flatnonzero(np.diff(state)) + 1
    starts = np.r_[0, edges]
    stops = np.r_[edges, state.size]
    return [(int(state[a]), int(a), int(b)) for a, b in zip(starts, stops)]


def smoothed_slope(values, window: int):
    """The slope per sample of ``values`` by a least-squares quadratic over ``window`` points (odd):
    Savitzky–Golay, as ``scipy.signal.savgol_filter(values, window, 2, deriv=1)`` (mode "interp")
    computes it, without importing scipy.signal (0.37 s, for it imports scipy.stats)."""
    d = np.asarray(values, float)
    m = window // 2
    k = np.arange(-m, m + 1, dtype=float)
    rate = np.empty_like(d)
    # inside: the slope of a quadratic at the centre of a symmetric window is the straight line's
    rate[m:d.size - m] = np.correlate(d, k / np.sum(k * k), mode="valid")
    # the ends: the quadratic through the first (last) window, differentiated there
    x = np.arange(window, dtype=float)
    for rows, at in ((slice(0, window), np.arange(m)), (slice(d.size - window, d.size), np.arange(window - m, window))):
        c = np.polyfit(x, d[rows], 2)
        rate[rows][at] = np.polyval(np.polyder(c), x[at])
    return rate


def segment(displacement, time=None) -> np.ndarray:
    """Label each row of a record: approach/loading (pushing), hold, retraction, other.

    The direction of motion is the sign of the displacement's rate (a Savitzky–Golay
    derivative over about 2 % of the rows, against time when given, else against the
    row number: instruments sample at a fixed rate): moving in (rate above 10 % of the
    typical pushing rate), moving out (likewise), or still.  Runs shorter than half
    the window are noise and join their neighbour.  The main push is the pushing run
    that gains the most depth; with the runs pushing or still around it (a staircase of
    steps and pauses, a pause before the approach) up to the runs moving out, it is the
    'loading' (split into 'approach' and 'loading' at a contact point by
    :meth:`InstrumentRecord.relabel`); still rows after its last push are the 'hold'; the
    runs moving out after it (pauses between them included) up to the next push the
    'retraction'; everything else 'other' (earlier and later cycles).

    Parameters
    ----------
    displacement : array_like, shape (n,)
        In file (time) order.
    time : array_like, shape (n,), optional
        Increasing times of the rows.

    Returns
    -------
    ndarray of str, shape (n,)

    Examples
    --------
    >>> d = np.r_[np.linspace(0, 1, 20), np.ones(5), np.linspace(1, 0, 20)]
    >>> labels = segment(d)
    >>> [str(s) for s in labels[[0, 19, 22, 44]]]
    ['loading', 'loading', 'hold', 'retraction']
    """
    d = np.asarray(displacement, float)
    n = d.size
    labels = np.full(n, "other", dtype=object)
    if n < 3:
        return labels.astype(str)
    w = int(min(51, max(5, 2 * (n // 100) + 1)))
    if n >= w + 2:
        rate = smoothed_slope(d, w)
    else:
        w = 3
        rate = np.gradient(d)
    if time is not None:
        dt = np.gradient(np.asarray(time, float))
        rate = np.where(dt > 0, rate / np.where(dt > 0, dt, 1.0), 0.0)
    state = np.zeros(n, int)
    for sign in (1, -1):
        moving = sign * rate[sign * rate > 0]
        if moving.size:
            state[sign * rate > 0.1 * np.percentile(moving, 90)] = sign
    short = max(2, w // 2)
    for _ in range(n):  # merge runs shorter than `short` into the previous (or next) run
        runs = _runs(state)
        small = [k for k, (_, a, b) in enumerate(runs) if b - a < short]
        if not small or len(runs) == 1:
            break
        k = small[0]
        _, a, b = runs[k]
        state[a:b] = runs[k - 1][0] if k > 0 else runs[k + 1][0]
    runs = _runs(state)
    pushes = [(d[b - 1] - d[a], k) for k, (s, a, b) in enumerate(runs) if s == 1]
    if not pushes:
        pulls = [(d[a] - d[b - 1], k) for k, (s, a, b) in enumerate(runs) if s == -1]
        if pulls:
            _, k = max(pulls)
            labels[runs[k][1]:runs[k][2]] = "retraction"
        return labels.astype(str)
    _, k = max(pushes)
    # the loading: the main push with the pushes and pauses around it up to the runs moving out
    # (a staircase of steps and holds is one loading); still rows after its last push: the hold
    a, b = k, k
    while a > 0 and runs[a - 1][0] != -1:
        a -= 1
    while b + 1 < len(runs) and runs[b + 1][0] != -1:
        b += 1
    last_push = max(j for j in range(a, b + 1) if runs[j][0] == 1)
    labels[runs[a][1]:runs[last_push][2]] = "loading"
    if last_push < b:
        labels[runs[last_push + 1][1]:runs[b][2]] = "hold"
    # the retraction: the runs moving out after it (with pauses between them), up to the next push
    c = b + 1
    if c < len(runs):
        e = c
        while e + 1 < len(runs) and runs[e + 1][0] != 1:
            e += 1
        last_pull = max(j for j in range(c, e + 1) if runs[j][0] == -1)
        labels[runs[c][1]:runs[last_pull][2]] = "retraction"
    return labels.astype(str)


def estimate_contact(displacement, force):
    """First estimate of the contact point from the force's baseline (m), or None.

    The first 10 % of the pushing rows (at least 5) are the baseline when the force
    rises there by less than 5 % of its whole rise; the contact is then the last
    row before the force leaves the baseline for good (its mean plus the larger of
    5 standard deviations and 1 % of the rise; cf. nanite's "deviation from baseline").
    None when the record starts in contact (no baseline to read).

    Parameters
    ----------
    displacement, force : array_like, shape (n,)
        The pushing rows, in time order.
    """
    d, f = np.asarray(displacement, float), np.asarray(force, float)
    order = np.argsort(d, kind="stable")
    d, f = d[order], f[order]
    n = d.size
    k = max(5, n // 10)
    if n < 2 * k:
        return None
    rise = np.max(f) - np.median(f[:k])
    if not rise > 0:
        return None
    base = f[:k]
    span = np.ptp(d[:k])
    change = np.polyfit((d[:k] - d[0]) / span, base, 1)[0] if span > 0 else 0.0  # scaled: well conditioned
    if abs(change) > 0.05 * rise:
        return None  # the force already rises: the record starts in contact
    thr = np.mean(base) + max(5 * np.std(base), 0.01 * rise)
    above = f > thr
    stays = np.flatnonzero(~above)  # the last row still at the baseline
    if stays.size == 0:
        return None
    last = stays[-1]
    if last >= n - 1:
        return None
    return float(d[last])
