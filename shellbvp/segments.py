"""The segments of a force–displacement record: each row labelled approach, loading, hold,
retraction or other by the direction of the displacement over time (:func:`segment`), and a
first contact point from the force's baseline (:func:`estimate_contact`)."""

from __future__ import annotations

import numpy as np

__all__ = ["SEGMENTS", "FIT_SEGMENTS", "BASELINE_ROWS", "BASELINE_RISE", "BASELINE_FLAT", "BASELINE_CURVATURE_T",
           "BASELINE_SLOPE", "segment", "estimate_contact", "smoothed_slope"]

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


#: The fewest rows a baseline is read from (:func:`estimate_contact`).
BASELINE_ROWS = 5
#: The largest change of the force over the baseline's rows (its straight line's), as a fraction
#: of the force's rise over the record: more, and the record starts in contact.
BASELINE_RISE = 0.05
#: The baseline's rows are loaded rows when they both rise by more than ``BASELINE_FLAT`` times
#: their scatter about their straight line (the line's change across them) and curve up by more
#: than ``BASELINE_CURVATURE_T`` standard errors (a quadratic's curvature, Student's t).  A flat
#: baseline rises by about its noise (at most 1.9 of these units on the AFM curves of afmformats'
#: test files; beyond 5 by chance in 1.5 % of straight bases of 5 rows, fewer with more) and a
#: tilted one (drift, drag) does not curve; a record that starts in contact on a convex curve
#: (force ~ delta^2 from its first row: 7.4 of these units over 5 rows, more over more or from
#: deeper) rises by only a few per cent of the whole over its first tenth, but does both.
BASELINE_FLAT = 5.0
BASELINE_CURVATURE_T = 4.0
#: The baseline's rows are loaded rows, too, when they rise beyond their noise (as above) and their
#: straight line's slope is more than ``BASELINE_SLOPE`` times that of the rows beyond the contact
#: this baseline gives (their straight line's).  An approach is flat, or tilted by drift or drag far
#: less steeply than the loading: at most 0.012 of it on the AFM curves of afmformats' test files and
#: the shipped records, 0.046 on the tilted approach of tests/test_fit_contact.py; a noisy approach
#: of a few rows passes both tests by chance (2 in 10,000 of ``benchmarks/contact_estimate.py``'s
#: records with an approach, which then get no estimate).  A record that starts in contact on
#: a nearly straight curve (a shell under a sphere, force ~ delta) rises over its first tenth at
#: 0.15-0.9 of the slope beyond it (the 3D solid's records of ``benchmarks/thick_fits.py`` without
#: their approach), by less than :data:`BASELINE_RISE` of the whole, and does not curve up enough.
BASELINE_SLOPE = 0.1


def _base_shape(x, y):
    """``(change, scatter, t)`` of rows ``y`` at ``x`` (scaled to [-1, 1]): the change of their
    straight line across them, their standard deviation about it, and the t statistic of a
    quadratic's curvature (> 0 curving up; 0 for no curvature, inf for an exact curve)."""
    line = np.polyfit(x, y, 1)
    off = y - np.polyval(line, x)
    scatter = float(np.sqrt(off @ off / (x.size - 2)))
    A = np.column_stack([np.ones_like(x), x, x * x])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    se = float(np.sqrt(resid @ resid / (x.size - 3) * np.linalg.inv(A.T @ A)[2, 2]))
    curvature = float(coef[2])
    if not abs(curvature) > 1e-12 * (float(np.max(np.abs(y))) or 1.0):
        return 2 * float(line[0]), scatter, 0.0
    return 2 * float(line[0]), scatter, curvature / se if se > 0 else np.copysign(np.inf, curvature)


def estimate_contact(displacement, force):
    """First estimate of the contact point from the force's baseline (m), or None.

    The first 10 % of the pushing rows (at least :data:`BASELINE_ROWS`) are the baseline unless
    the force already rises there: its straight line's change across them more than
    :data:`BASELINE_RISE` (5 %) of the force's whole rise, or rising beyond the rows' noise
    (:data:`BASELINE_FLAT` times their scatter about the line) while curving up (beyond
    :data:`BASELINE_CURVATURE_T` standard errors) -- a record that starts in contact on a convex
    curve (force ~ delta^2, a sealed capsule between plates) rises by only a few per cent over its
    first rows, but does both; a flat or tilted straight baseline does not.  Nor do rows rising
    beyond their noise at more than :data:`BASELINE_SLOPE` (0.1) of the slope of the rows beyond
    the contact they would give: a shell's record without its approach rises steadily from its
    first row, by a few per cent over its first tenth, and hardly curves.  The contact is
    then the last row before the force leaves the baseline for good (its mean plus the larger
    of 5 standard deviations and 1 % of the rise; cf. nanite's "deviation from baseline").
    None when the record starts in contact or is too short to tell (fewer than twice
    :data:`BASELINE_ROWS` rows): a fit then starts its contact point at the first row and fits
    no baseline (:func:`shellbvp.fitting.fit_record`).

    Parameters
    ----------
    displacement, force : array_like, shape (n,)
        The pushing rows, in time order.

    Examples
    --------
    >>> x = np.linspace(0, 1, 60)
    >>> noise = 1e-4 * np.random.default_rng(0).standard_normal(60)
    >>> round(estimate_contact(x, np.clip(x - 0.4, 0, None) ** 2 + noise), 2)  # 1 % of the rise at 0.46
    0.46
    >>> estimate_contact(x, (x + 0.05) ** 2 + noise) is None  # loaded from the first row: no baseline
    True
    """
    d, f = np.asarray(displacement, float), np.asarray(force, float)
    order = np.argsort(d, kind="stable")
    d, f = d[order], f[order]
    n = d.size
    k = max(BASELINE_ROWS, n // 10)
    if n < 2 * k:
        return None
    rise = np.max(f) - np.median(f[:k])
    if not rise > 0:
        return None
    base = f[:k]
    thr = np.mean(base) + max(5 * np.std(base), 0.01 * rise)
    above = f > thr
    stays = np.flatnonzero(~above)  # the last row still at the baseline
    if stays.size == 0:
        return None
    last = stays[-1]
    if last >= n - 1:
        return None
    span = np.ptp(d[:k])
    if span > 0:  # scaled to [-1, 1]: well conditioned
        change, scatter, t = _base_shape(2 * (d[:k] - d[0]) / span - 1, base)
        if abs(change) > BASELINE_RISE * rise:
            return None  # the force already rises: the record starts in contact
        if change > BASELINE_FLAT * scatter:  # it rises beyond its noise: loaded rows, or a tilted baseline
            if t > BASELINE_CURVATURE_T:
                return None  # and curves up: loaded rows, no baseline
            if change / span > BASELINE_SLOPE * _loaded_slope(d[last:], f[last:]):
                return None  # as steeply as the rows beyond it rise: loaded rows, no baseline
    return float(d[last])


def _loaded_slope(d, f):
    """The slope (force per displacement) of the straight line through the rows ``d``, ``f`` beyond
    a contact estimate; inf for fewer than 2 rows or no span (no slope to compare with)."""
    span = np.ptp(d)
    if d.size < 2 or not span > 0:
        return np.inf
    return float(np.polyfit((d - d[0]) / span, f, 1)[0]) / span
