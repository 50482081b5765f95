r"""A cheap wrinkling indicator from one axisymmetric state: compressive hoop stress against a
local threshold (issue 44, item 3).

What it computes
----------------
Where the free shell carries a compressive hoop tension ``tau_theta < 0``, the parallels may
buckle out of their circles into wrinkles ``w ~ exp(i k t)`` along the parallel (t its arclength,
``k = n / r``).  Knoche & Kierfeld (EPL 106, 24004, 2014; arXiv:1408.0946) explain the polygonal
secondary buckling of deflated shells this way and derive a critical hoop stress from the
stability equations of shallow shells; their formula is not in the material available here, so
the threshold is derived below from the same equations, with the package's stiffnesses.

*The local stability form.*  In a patch small against the radii of curvature, with principal
curvatures ``kappa_s`` (meridian) and ``kappa_theta`` (parallel), tensions ``tau_s``,
``tau_theta``, bending stiffness ``B`` and stretching stiffness ``Y``, the Donnell-Mushtari-
Vlasov equations for a normal perturbation ``w exp(i (k_s s + k t))`` give the energy per
``|w|^2/2``

.. math:: B K^4 + \tau_s k_s^2 + \tau_\theta k^2
          + Y \frac{(\kappa_s k^2 + \kappa_\theta k_s^2)^2}{K^4},\qquad K^2 = k_s^2 + k^2

(the last term: the in-plane stress that the change of Gauss curvature ``kappa_s w_tt +
kappa_theta w_ss`` forces through the Airy function).  The patch wrinkles when this is negative
for some wave vector, i.e. when ``-tau_theta`` exceeds

.. math:: \tau_c(k_s) = \min_{k} \frac{B K^4 + \tau_s k_s^2
          + Y (\kappa_s k^2 + \kappa_\theta k_s^2)^2 / K^4}{k^2}.

It is a compressed beam (the parallel) on an elastic foundation: the foundation's stiffness is
``Y kappa_s^2`` (the meridian's curvature turns the wrinkle's deflection into meridional
stretching) plus ``tau_s k_s^2`` (the meridional tension, where the wrinkle has a meridional
wavenumber ``k_s``).  Closed forms (tests/test_hoop_indicator.py checks the minimiser on them):

* ``k_s = 0`` (crests along the meridian; the cylinder under axial compression turned by
  90 degrees): ``tau_c = 2 sqrt(B Y) |kappa_s|`` at ``k = (Y kappa_s^2 / B)^(1/4)``;
* a flat strip under tension (``kappa_s = kappa_theta = 0``):
  ``tau_c = 2 B (k_s^2 + sqrt(k_s^4 + tau_s k_s^2 / B))``.

Two ways of applying it to a state (``model``):

* ``"strip"`` (default): at every point of the free shell with ``tau_theta < 0``, ``k_s = 0``:
  ``tau_c = 2 sqrt(B Y) |kappa_s|``, the wave number bounded below by ``n = 2`` (``k >= 2/r``:
  n = 0 and 1 are no wrinkles).  Local in the strict sense; where the meridian has an
  inflection (``kappa_s = 0``, which the indented shell has next to its contact edge) it reads
  a threshold near 0.
* ``"band"``: for each connected band of compression (deformed arclength ``W``), one
  Galerkin mode ``w = sin(pi (s - s_a)/W) exp(i k t)``: ``k_s = pi / W`` and the form above
  averaged over the band with weight ``sin^2``; the threshold is the ratio of the averaged
  stabilising terms to the averaged ``-tau_theta k^2``, minimised over ``k >= 2/r``.  The
  band's width and its meridional tension enter; the point of inflection no longer decides.

The indicator of a state is the smallest ratio ``threshold / |tau_theta|`` (< 1: it fires),
where (S, r), and the predicted wave number and ``n = k r``.

Stiffnesses in the package's units (``mu H``, lengths by R_L): ``B = beta`` (SPEC section 2) and
``Y = 3`` (the small-strain stretching stiffness ``E H`` of an incompressible sheet, E = 3 mu;
every built-in strain energy has small-strain shear modulus 1); on a wall whose thickness varies,
``beta t^3`` and ``3 t`` with the local ``t = H(S)/H0``.  Finite stretches change both
(the incremental moduli, the thinned wall): the indicator uses the small-strain values, an
approximation of its own beside the locality.

What it is worth (benchmarks/results/hoop_indicator.md, the curves of
benchmarks/stability_modes.py, every state's indicator beside the eigenvalues of
:func:`shellbvp.stability`): the Notes of :func:`hoop_indicator`.  It is not used in place of
the eigenvalue analysis anywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["hoop_indicator", "HoopIndicator", "wrinkling_threshold", "STRETCHING_STIFFNESS", "MODELS",
           "LOWEST_WRINKLE"]

#: ``Y = E H`` in units of ``mu H`` (incompressible: E = 3 mu)
STRETCHING_STIFFNESS = 3.0
#: The lowest mode number counted as a wrinkle (n = 0 is axisymmetric, n = 1 a tilt or a slide)
LOWEST_WRINKLE = 2
#: The ways of applying the threshold to a state (module docstring)
MODELS = ("strip", "band")
_FREE = 1  # the region code of free shell in Solution.profile


@dataclass
class HoopIndicator:
    """The wrinkling indicator of one state (module docstring).

    Attributes
    ----------
    ratio : float
        The smallest ``threshold / |tau_theta|`` over the compressed free shell; ``inf`` where
        no free shell is in hoop compression; NaN for a state that did not converge.
    fires : bool
        ``ratio < 1``: the indicator predicts wrinkles.
    S, r : float
        Where the smallest ratio lies (for ``"band"``: the band's point of largest
        compression); NaN if none.
    tau_theta, threshold : float
        The hoop tension there and its threshold.
    wavenumber, n : float
        The predicted wave number along the parallel and ``n = wavenumber * r``.
    band : tuple of float
        ``(S_start, S_end)`` of the compressed band holding the smallest ratio.
    compression : float
        The largest ``-tau_theta`` over the free shell (0 if none is compressed).
    model : str
        ``"strip"`` or ``"band"``.
    profile : dict of ndarray
        ``S`` and ``ratio`` at every profile point of the compressed free shell (``"band"``: each
        band's ratio at its points); empty if none is compressed.

    Examples
    --------
    >>> import shellbvp as sb
    >>> ind = sb.hoop_indicator(sb.inflate(sb.Scene.preset("balloon")))   # inflated: no compression
    >>> ind.ratio, ind.fires, ind.compression
    (inf, False, 0.0)
    """

    ratio: float = math.inf
    fires: bool = False
    S: float = math.nan
    r: float = math.nan
    tau_theta: float = math.nan
    threshold: float = math.nan
    wavenumber: float = math.nan
    n: float = math.nan
    band: tuple = (math.nan, math.nan)
    compression: float = 0.0
    model: str = "strip"
    profile: dict = field(default_factory=dict)


def wrinkling_threshold(B, Y, kappa_s, kappa_theta=0.0, tau_s=0.0, k_s=0.0, k_min=0.0):
    """The local critical hoop compression ``tau_c`` and its wave number along the parallel.

    ``tau_c = min over k >= k_min of [B K^4 + tau_s k_s^2 + Y (kappa_s k^2 + kappa_theta k_s^2)^2
    / K^4] / k^2`` with ``K^2 = k_s^2 + k^2`` (module docstring); arrays broadcast.

    Returns
    -------
    threshold, k : ndarray
        ``k_s = 0`` is the closed form ``2 sqrt(B Y) |kappa_s|`` at ``k = (Y kappa_s^2/B)^(1/4)``
        (or the value at ``k_min`` where that is smaller); otherwise a minimisation in ``ln k``
        (a grid of 241 points over 8 decades about the scale ``(Y/B)^(1/4) sqrt(|kappa|)``, then
        golden sections), relative accuracy about 1e-9.
    """
    B, Y, kappa_s, kappa_theta, tau_s, k_s, k_min = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (B, Y, kappa_s, kappa_theta, tau_s, k_s, k_min)))
    if np.all(k_s == 0):
        k = np.maximum((Y * kappa_s**2 / B) ** 0.25, k_min)
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.where(k > 0, B * k**2 + Y * kappa_s**2 / np.where(k > 0, k, 1.0) ** 2, 0.0)
        return tau, k

    def form(k):
        K2 = k_s**2 + k**2
        return (B * K2**2 + tau_s * k_s**2 + Y * (kappa_s * k**2 + kappa_theta * k_s**2) ** 2 / K2**2) / k**2

    scale = np.maximum.reduce([(Y / B) ** 0.25 * np.sqrt(np.abs(kappa_s) + np.abs(kappa_theta)), k_s, k_min,
                               np.full(B.shape, 1e-3)])
    lo = np.maximum(np.log(scale) - 4 * math.log(10), np.log(np.maximum(k_min, 1e-300)))
    hi = np.maximum(np.log(scale) + 4 * math.log(10), lo + 1.0)
    grid = lo[..., None] + (hi - lo)[..., None] * np.linspace(0.0, 1.0, 241)
    values = np.stack([form(np.exp(grid[..., j])) for j in range(grid.shape[-1])], axis=-1)
    j = np.argmin(values, axis=-1)
    step = (hi - lo) / 240
    a = np.take_along_axis(grid, j[..., None], -1)[..., 0] - step
    b = a + 2 * step
    a = np.maximum(a, lo)
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        c = b - g * (b - a)
        d = a + g * (b - a)
        left = form(np.exp(c)) < form(np.exp(d))
        b = np.where(left, d, b)
        a = np.where(left, a, c)
    k = np.exp(0.5 * (a + b))
    return form(k), k


def _bands(mask):
    """(start, stop) index pairs of the runs of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return list(zip(edges[::2], edges[1::2]))


def hoop_indicator(state, *, model: str = "strip", points_per_interval: int = 4) -> HoopIndicator:
    """The wrinkling indicator of an axisymmetric state: compressive hoop stress against a local
    threshold (module docstring).

    Parameters
    ----------
    state : Solution
        A converged state (on the tip or :func:`shellbvp.inflate`'s).
    model : {"strip", "band"}
        How the threshold is applied: pointwise with no meridional wave (``"strip"``), or one
        Galerkin mode over each compressed band (``"band"``).
    points_per_interval : int
        Profile points per mesh interval (``Solution.profile``).

    Returns
    -------
    HoopIndicator

    Notes
    -----
    It costs a profile evaluation (about 5-15 ms a state), against 0.1-2.5 s for
    :func:`shellbvp.stability`.  The verdict of the comparison with the eigenvalues along the
    35 curves of ``benchmarks/stability_modes.py`` (benchmarks/results/hoop_indicator.md; 9 of
    them lose stability, 1101 states analysed stable):

    * ``"strip"`` fires before every instability in modes n >= 2 (7 of 7: the thin hemispheres,
      the thin domes, the balloon; its ratio at the located crossing 0.05-0.43), and also before
      the pinned shallow cap's n = 7 under pressure (0.52 at 0.70 p_c).  It misses both n = 1
      instabilities (the pole sliding on the tip: no hoop mechanism).  It fires early, at 0.25-0.9
      of the onset depth, on 433 of the 1101 stable states and on 11 of the 23 curves that stay
      stable, and its n is mostly 2: its minimum sits where the meridian has an inflection
      (``kappa_s = 0``), where the local threshold vanishes and locality fails.
    * ``"band"`` predicts n near the eigenvalues' (6.9 for 6, 7.3 for 7, 9.9 for 8) and never fires on a
      stable state, but it fires late or never: it misses 5 of the 7 n >= 2 instabilities.

    So it is **not a substitute** for the eigenvalue analysis and is not used by
    :func:`shellbvp.curve`.  As a screen (modes n = 0, 1 only where ``"strip"`` is silent) it
    changed no first instability on the grid and halved the analysis' time (117 s against 225 s),
    but that safety rests on 8 instabilities and on the breakdown at the inflection, not on a
    bound: use it to see where and why a state is near wrinkling; only :func:`shellbvp.stability`
    certifies stability.

    Examples
    --------
    >>> import shellbvp as sb
    >>> ind = sb.hoop_indicator(sb.solve(sb.Scene.preset("base", beta=1e-4), delta=0.2))
    >>> bool(ind.fires), ind.compression > 0
    (True, True)
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}; got {model!r}")
    if state is None or not getattr(state, "success", False):
        return HoopIndicator(ratio=math.nan, model=model)
    prof = state.profile(points_per_interval)
    # a profiled wall's local stiffnesses: bending ~ H^3, stretching ~ H (t = H(S)/H0)
    t = np.asarray(prof["thickness"], float) if "thickness" in prof else np.ones(prof["S"].shape)
    B, Y = float(state.scene.beta) * t**3, STRETCHING_STIFFNESS * t
    free = prof["region"] == _FREE
    tau_t = prof["tau_theta"]
    compressed = free & (tau_t < 0)
    out = HoopIndicator(model=model, compression=float(max(0.0, -tau_t[free].min())) if free.any() else 0.0)
    if not compressed.any():
        return out
    r, S = prof["r"], prof["S"]
    s = np.r_[0.0, np.cumsum(np.hypot(np.diff(r), np.diff(prof["z"])))]  # deformed arclength
    best = None
    S_all, ratio_all = [], []
    for a, b in _bands(compressed):
        idx = np.arange(a, b)
        if model == "strip":
            thr, k = wrinkling_threshold(B[idx], Y[idx], prof["kappa_s"][idx], k_min=LOWEST_WRINKLE / r[idx])
            ratio = thr / -tau_t[idx]
            m = int(np.argmin(ratio))
            cand = (float(ratio[m]), idx[m], float(thr[m]), float(k[m]))
        else:
            cand = _band_ratio(B, Y, prof, s, idx, np.r_[max(a - 1, 0), idx, min(b, S.size - 1)])
            ratio = np.full(idx.size, cand[0])
        S_all.append(S[idx])
        ratio_all.append(ratio)
        if best is None or cand[0] < best[0]:
            best = cand + ((float(S[a]), float(S[b - 1])),)
    ratio, i, thr, k, band = best
    out.ratio, out.fires = ratio, ratio < 1.0
    out.S, out.r, out.tau_theta, out.threshold = float(S[i]), float(r[i]), float(tau_t[i]), thr
    out.wavenumber, out.n, out.band = k, k * float(r[i]), band
    out.profile = {"S": np.concatenate(S_all), "ratio": np.concatenate(ratio_all)}
    return out


def _band_ratio(B, Y, prof, s, idx, span):
    """(ratio, index of the largest compression, threshold there, k) of one compressed band: one
    Galerkin mode ``sin(pi (s - s_a)/W) exp(i k t)`` over the band ``span`` (its nodes and the two
    neighbours where tau_theta changes sign)."""
    B, Y = B[span], Y[span]  # the local stiffnesses on the band
    sa, sb = s[span[0]], s[span[-1]]
    W = max(sb - sa, 1e-12)
    k_s = math.pi / W
    ss = s[span]
    weight = np.sin(math.pi * (ss - sa) / W) ** 2
    dw = np.gradient(ss) * weight  # trapezoid-like weights on the (non-uniform) points
    kap_s, kap_t, tau_s = prof["kappa_s"][span], prof["kappa_theta"][span], prof["tau_s"][span]
    comp = np.maximum(-prof["tau_theta"][span], 0.0)
    r = prof["r"][span]
    k_min = LOWEST_WRINKLE / float(np.sum(dw * r) / np.sum(dw))

    def quotient(k):
        K2 = k_s**2 + k**2
        num = np.sum(dw * (B * K2**2 + tau_s * k_s**2 + Y * (kap_s * k**2 + kap_t * k_s**2) ** 2 / K2**2))
        return num / (k**2 * np.sum(dw * comp))

    scale = max(float(np.median(Y / B)) ** 0.25 * math.sqrt(float(np.max(np.abs(kap_s) + np.abs(kap_t)))),
                k_s, k_min)
    grid = np.exp(np.linspace(math.log(k_min), math.log(scale) + 4 * math.log(10), 400))
    vals = np.array([quotient(k) for k in grid])
    j = int(np.argmin(vals))
    a, b = math.log(grid[max(j - 1, 0)]), math.log(grid[min(j + 1, grid.size - 1)])
    g = (math.sqrt(5) - 1) / 2
    for _ in range(50):
        c, d = b - g * (b - a), a + g * (b - a)
        if quotient(math.exp(c)) < quotient(math.exp(d)):
            b = d
        else:
            a = c
    k = math.exp(0.5 * (a + b))
    ratio = float(quotient(k))
    i = int(idx[np.argmax(-prof["tau_theta"][idx])])
    # the threshold expressed at the band's largest compression: ratio * |tau_theta| there
    return ratio, i, ratio * float(-prof["tau_theta"][i]), k
