r"""The hoop-stress wrinkling indicator (shellbvp.wrinkling; issue 44, item 3).

* the local threshold's minimiser against the closed forms derived in the module docstring: the
  strip with no meridional wave (``2 sqrt(B Y)|kappa_s|`` at ``k = (Y kappa_s^2/B)^(1/4)``) and
  the flat strip under meridional tension (``2 B (k_s^2 + sqrt(k_s^4 + tau_s k_s^2/B))``);
* a sphere under external pressure p: away from the pole and the held rim the indicator reads
  ``p_c / p`` with the classical ``p_c = 4 sqrt(3 beta)`` (the local criterion is the
  classical one on a sphere) and the classical wave number ``(3/beta)^(1/4)``;
* an inflated shell without contact reads no compression;
* a thin dome indented deep: the compressed band lies outside the contact, on the inner side of
  the ridge (the dimple's edge), where Knoche & Kierfeld place the wrinkles;
* the band model's n next to the eigenvalue analysis's critical mode on a thin hemisphere.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.solution import Solution
from shellbvp.wrinkling import STRETCHING_STIFFNESS as Y
from shellbvp.wrinkling import wrinkling_threshold


@pytest.mark.parametrize("B, kappa", [(1e-4, 0.7), (1e-2, 3.0), (1e-6, -1.3)])
def test_threshold_without_meridional_wave_is_the_closed_form(B, kappa):
    closed = 2 * math.sqrt(B * Y) * abs(kappa)
    k_closed = (Y * kappa**2 / B) ** 0.25
    tau, k = wrinkling_threshold(B, Y, kappa)
    assert tau == pytest.approx(closed, rel=1e-12) and k == pytest.approx(k_closed, rel=1e-12)
    # the general minimiser (a vanishing k_s sends it there) finds the same minimum
    tau_num, k_num = wrinkling_threshold(B, Y, kappa, k_s=1e-9 * k_closed)
    assert tau_num == pytest.approx(closed, rel=1e-8)
    assert k_num == pytest.approx(k_closed, rel=1e-4)
    # a lower bound on k above the optimum: the value at the bound
    tau_b, k_b = wrinkling_threshold(B, Y, kappa, k_min=2 * k_closed)
    assert k_b == 2 * k_closed
    assert tau_b == pytest.approx(B * k_b**2 + Y * kappa**2 / k_b**2, rel=1e-12) and tau_b > closed


@pytest.mark.parametrize("B, tau_s, k_s", [(1e-4, 0.05, 5.0), (1e-3, 0.3, 2.0), (1e-5, 1e-3, 40.0)])
def test_flat_strip_under_tension_is_the_closed_form(B, tau_s, k_s):
    tau, _ = wrinkling_threshold(B, Y, 0.0, 0.0, tau_s, k_s)
    assert tau == pytest.approx(2 * B * (k_s**2 + math.sqrt(k_s**4 + tau_s * k_s**2 / B)), rel=1e-9)


def test_sphere_under_external_pressure_reads_the_classical_pressure():
    beta = 1e-4
    p_c = 4 * math.sqrt(3 * beta)
    state = sb.inflate(sb.Scene(gamma=1, beta=beta, pressure=0.5 * p_c))  # pressure on the convex side
    ind = sb.hoop_indicator(state)
    S, ratio = ind.profile["S"], ind.profile["ratio"]
    inside = (S > 0.3) & (S < 0.8)  # off the pole (k >= 2/r binds there) and the rim's bending layer
    assert inside.sum() > 50
    # p_c/p = 2, up to the stretch of the deformed radius (0.3 %) and the state's own ripple in
    # kappa_s (measured: 1.998-2.015 here; 1.992-2.028 out to S = 1)
    assert np.all(np.abs(ratio[inside] / 2.0 - 1) < 0.01), (ratio[inside].min(), ratio[inside].max())
    assert not ind.fires and ind.ratio < 1.9  # the rim's bending layer compresses more ...
    assert math.pi / 2 - ind.S < 3 * (beta / Y) ** 0.25  # ... and holds the smallest ratio


def test_inflated_shell_without_contact_reads_no_compression():
    ind = sb.hoop_indicator(sb.inflate(sb.Scene.preset("balloon")))
    assert ind.ratio == math.inf and not ind.fires and ind.compression == 0.0 and ind.profile == {}
    assert math.isnan(ind.S) and math.isnan(ind.n)


def test_thin_dome_indented_deep_is_compressed_inside_its_ridge():
    state = sb.solve(sb.Scene.preset("dome", beta=1e-4), delta=0.3)
    prof = state.profile(4)
    free = prof["region"] == 1
    ridge = prof["S"][free][np.argmin(prof["kappa_s"][free])]  # the dimple's edge: the sharpest fold
    bending_length = (1e-4 / Y) ** 0.25
    for model in ("strip", "band"):
        ind = sb.hoop_indicator(state, model=model)
        lo, hi = ind.band
        assert state.Sc < lo < hi < ridge + bending_length, (state.Sc, ind.band, ridge)
        assert ridge - hi < bending_length  # it ends at the ridge
        assert lo < ind.S < hi
    # the largest compression inside the ridge, within two bending lengths of it
    S_max = prof["S"][free][np.argmin(prof["tau_theta"][free])]
    assert 0 < ridge - S_max < 2 * bending_length


def test_band_model_predicts_the_eigen_mode_of_a_thin_hemisphere():
    # the hemisphere of the stability grid at beta 1e-4 turns unstable at delta 0.1349 in n = 7
    # (benchmarks/results/stability_modes.md); just past it:
    state = sb.solve(sb.Scene.preset("base", beta=1e-4), delta=0.14)
    eig = sb.stability(state)
    assert not eig.stable and eig.critical_mode >= 2
    band = sb.hoop_indicator(state, model="band")
    assert abs(band.n - eig.critical_mode) < 1.5, (band.n, eig.critical_mode)
    strip = sb.hoop_indicator(state)
    assert strip.fires and strip.n < 3  # the strip's minimum sits at the meridian's inflection


def test_bad_input_and_failed_states():
    state = sb.inflate(sb.Scene.preset("balloon"))
    with pytest.raises(ValueError, match="model must be one of"):
        sb.hoop_indicator(state, model="cylinder")
    failed = sb.hoop_indicator(Solution(status=1, success=False))
    assert math.isnan(failed.ratio) and not failed.fires


@pytest.mark.slow  # ~25 s: code is generated for the cap's shell
def test_pinned_shallow_cap_under_pressure_fires_before_its_n7_instability():
    """A spherical cap of radius 5 over the rim radius 1, beta 1e-5 (tests/test_stability.py):
    n = 7 goes unstable at 0.734 p_c (benchmarks/results/stability_pressure.md).  The strip
    indicator fires before: already at 0.70 p_c, where every mode is still stable."""
    beta = 1e-5
    shell = sb.UserShell("5*sin(S/5)", "-5*cos(S/5)", "5*asin(1/5)")
    p_c = 4 * math.sqrt(3 * beta) / 25
    state = sb.inflate(sb.Scene(shell=shell, beta=beta, pressure=0.70 * p_c))
    assert sb.stability(state, modes=range(2, 12)).stable
    ind = sb.hoop_indicator(state)
    assert ind.fires and ind.ratio < 0.6, ind.ratio
