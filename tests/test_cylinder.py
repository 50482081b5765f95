"""Contact on the indenter's cylinder (issue 12): the region's generated equations, the
tip | cylinder junction, and the cap+cylinder configuration.

The scene: the Lepidium fit preset (gamma 2.5, rho 1/3) with beta = 1e-3, whose single
cap passes through the indenter's side from delta ~1.14 and reaches the tip's end at
delta ~1.32 (issue 12).
"""

import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import shellbvp as sb
from shellbvp.cylinder import cylinder_state, cylinder_suspected

SCENE = sb.Scene.preset("fit", beta=1e-3)


@pytest.fixture(scope="module")
def state():
    return sb.solve(SCENE, delta=1.25, topology="cap+cylinder", tol=1e-8)


def test_cylinder_profile_is_the_indenter_side():
    """r = rho A(omega_max), phi = pi/2, kappa_s = 0, kappa_theta = 1/r, and z climbs the wall
    with omega at unit speed (in units of rho)."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    rho, w0 = SCENE.rho, mod.OMEGA_MAX
    assert w0 == pytest.approx(math.pi / 2, abs=1e-15)
    S = np.array([0.25, 0.3, 0.4])
    omega = w0 + np.array([0.0, 0.2, 0.5])
    y = np.vstack([rho * omega / S, np.array([1.1, 1.3, 0.9])])
    f = mod.cylinder_profile(S, y, par)
    np.testing.assert_allclose(f["r"], rho, rtol=1e-15)
    np.testing.assert_allclose(f["phi"], math.pi / 2, rtol=1e-15)
    np.testing.assert_allclose(f["kappa_s"], 0.0, atol=1e-15)
    np.testing.assert_allclose(f["kappa_theta"], 1 / rho, rtol=1e-14)
    np.testing.assert_allclose(f["z"], rho * (1 + omega - w0), rtol=1e-14)  # from the apex; sphere B(w0) = 1


def test_tension_is_constant_along_the_cylinder():
    """On a straight wall (r constant, kappa_s = 0) the tangential balance is tau_s' = 0: an
    independent check of the generic contact derivation specialised to the cylinder."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    S0, S1 = 0.2, 0.35
    y0 = [SCENE.rho * (mod.OMEGA_MAX + 0.01) / S0, 1.4]
    sol = solve_ivp(lambda S, y: mod.cylinder_rhs(np.array([S]), y[:, None], par)[:, 0] / S, (S0, S1), y0,
                    rtol=1e-11, atol=1e-13, dense_output=True)
    assert sol.success
    S = np.linspace(S0, S1, 9)
    tau = mod.cylinder_profile(S, sol.sol(S), par)["tau_s"]
    ls = sol.sol(S)[1]
    assert np.ptp(ls) > 0.05  # the stretch does change along the wall
    np.testing.assert_allclose(tau, tau[0], rtol=1e-8)


def test_tip_end_condition_is_the_jump_of_lambda_s_dU_dlambda_s_minus_U():
    """tip_end_res against [ls U_ls - U] written out here from the Mooney-Rivlin energy and
    the bending energy (beta/2) m^2, m = ls^2 ks + lt^2 kt - ksR - ktR (not from the DAG)."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    rho, alpha, beta, gamma = SCENE.rho, SCENE.material.alpha, SCENE.beta, SCENE.gamma
    ls, lt, ks, kt, ksR, ktR = sp.symbols("ls lt ks kt ksR ktR")
    I1 = ls**2 + lt**2 + 1 / (ls * lt) ** 2
    I2 = 1 / ls**2 + 1 / lt**2 + ls**2 * lt**2
    U = ((1 - alpha) * (I1 - 3) + alpha * (I2 - 3)) / 2 + beta / 2 * (ls**2 * ks + lt**2 * kt - ksR - ktR) ** 2
    H = sp.lambdify((ls, lt, ks, kt, ksR, ktR), ls * sp.diff(U, ls) - U)
    rng = np.random.default_rng(3)
    for _ in range(5):
        S = rng.uniform(0.15, 0.5)
        ls_t, ls_w = rng.uniform(0.8, 2.5, 2)
        off = rho * mod.OMEGA_MAX / S + rng.uniform(-0.1, 0.1)  # omega off the end: the first two rows
        res = mod.tip_end_res(S, np.array([off, ls_t]), np.array([off, ls_w]), par)
        np.testing.assert_allclose(res[:2], off - rho * mod.OMEGA_MAX / S, rtol=1e-13)
        chi = rho * mod.OMEGA_MAX / S  # at the end: the third row
        res = mod.tip_end_res(S, np.array([chi, ls_t]), np.array([chi, ls_w]), par)
        ref = mod.reference_shell(np.array([S]), par)
        R, ksR_, ktR_ = ref["R"][0], ref["kappa_s"][0], ref["kappa_theta"][0]
        lt_ = rho / R  # at omega_max on the sphere and on the cylinder r = rho
        expect = H(ls_t, lt_, 1 / rho, 1 / rho, ksR_, ktR_) - H(ls_w, lt_, 0.0, 1 / rho, ksR_, ktR_)
        assert res[2] == pytest.approx(expect, rel=1e-12, abs=1e-13), gamma


def test_cap_passing_through_the_side_is_replaced_by_contact_on_the_cylinder(state):
    cap = sb.solve(SCENE, delta=1.25, topology="cap", tol=1e-8, estimate_error=False)
    assert cap.success and not cap.valid and cylinder_suspected(cap)
    assert any("passes through the indenter" in f for f in cap.flags)
    auto = sb.solve(SCENE, delta=1.25, tol=1e-8, estimate_error=False)
    assert auto.topology == "cap+cylinder" and auto.valid
    assert state.success and state.valid, state.flags
    assert 0 < state.S_end < state.Sc < SCENE.shell_length
    assert state.pressure_min > 0 and state.edge_forces[0] > 0
    assert state.penetration < 1e-6
    assert state.force_error < 1e-7


def test_profile_regions_and_the_refraction_at_the_tip_end(state):
    """Profile: tip (0), cylinder (2), free (1) in order; at S*, omega = omega_max from both
    sides, lambda_s jumps and R Psi (ls lt (T_s + 2 kappa_s M_s) - U) does not."""
    prof = state.profile()
    codes = prof["region"]
    assert list(dict.fromkeys(codes.tolist())) == [0, 2, 1]
    i_t = np.nonzero(codes == 0)[0][-1]
    i_w = np.nonzero(codes == 2)[0][0]
    assert prof["S"][i_t] == pytest.approx(state.S_end, rel=1e-12) == prof["S"][i_w]
    assert abs(prof["lambda_s"][i_w] - prof["lambda_s"][i_t]) > 1e-3  # a real jump

    def hamiltonian(i):  # energy_density is U R Psi: multiply the rest by R Psi
        RPsi = prof["energy_density"][i] / _U(prof, i)
        return RPsi * prof["lambda_s"][i] * prof["lambda_theta"][i] * (
            prof["T_s"][i] + 2 * prof["kappa_s"][i] * prof["M_s"][i]) - prof["energy_density"][i]

    assert hamiltonian(i_t) == pytest.approx(hamiltonian(i_w), rel=1e-8)
    np.testing.assert_allclose(prof["r"][codes == 2], SCENE.rho, rtol=1e-12)


def _U(prof, i):
    """U from the profile's stretches and curvatures (Mooney-Rivlin + bending), independently."""
    a, beta = SCENE.material.alpha, SCENE.beta
    ls, lt, ks, kt = (prof[k][i] for k in ("lambda_s", "lambda_theta", "kappa_s", "kappa_theta"))
    S = prof["S"][i]
    mod = SCENE.model()
    ref = mod.reference_shell(np.array([S]), SCENE.parameters(mod))
    I1 = ls**2 + lt**2 + 1 / (ls * lt) ** 2
    I2 = 1 / ls**2 + 1 / lt**2 + ls**2 * lt**2
    m = ls**2 * ks + lt**2 * kt - ref["kappa_s"][0] - ref["kappa_theta"][0]
    return ((1 - a) * (I1 - 3) + a * (I2 - 3)) / 2 + beta / 2 * m**2


def test_force_is_the_derivative_of_the_energy_on_the_cylinder_branch(state):
    """F = dE/ddelta (Richardson-extrapolated central differences, error O(h^4)): the refraction
    condition at S* and the edge conditions on the wall are the natural ones of E."""
    h = 2e-3
    E = {}
    for k in (-2, -1, 1, 2):
        s = sb.solve(SCENE, delta=state.delta + k * h, guess=state, tol=1e-8, estimate_error=False)
        assert s.success and s.topology == "cap+cylinder", s.message
        E[k] = s.energy
    d1, d2 = (E[1] - E[-1]) / (2 * h), (E[2] - E[-2]) / (4 * h)
    assert (4 * d1 - d2) / 3 == pytest.approx(state.force, abs=1e-7)


@pytest.mark.parametrize("control", ["force", "lambda0"])
def test_other_controls_reach_the_same_cylinder_state(state, control):
    value = state[control]
    s = cylinder_state(state, control=control, value=value, tol=1e-8)
    assert s.success and s.topology == "cap+cylinder"
    assert s.delta == pytest.approx(state.delta, abs=1e-7)
    assert s.force == pytest.approx(state.force, rel=1e-7)
