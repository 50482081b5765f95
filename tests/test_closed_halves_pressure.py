"""Closed shells whose halves differ (an egg, ``UserShell.closed_halves``) under pressure and
sealed, on a substrate under a curved tip: the egg inflated as a whole before indenting (each
pole's rise where the tip, and the substrate, find it), the volume over both halves
(docs/closed.md, "Halves that differ")."""

import numpy as np
import pytest

import shellbvp as sb

#: The spheroid gamma = 0.7's upper half, and the same half at twice the pace (its own module, L)
SPHEROID = ("sin(S)", "0.7*cos(S)", "pi/2")
SPHEROID_FAST = ("sin(2*S)", "0.7*cos(2*S)", "pi/4")
#: An egg: a prolate upper half on an oblate lower half
PROLATE, OBLATE = ("sin(S)", "1.3*cos(S)", "pi/2"), ("sin(S)", "0.7*cos(S)", "pi/2")


def on_substrate(shell, **kw):
    return sb.Scene(closed=True, shell=shell, tip=sb.SphereTip(), rho=kw.pop("rho", 1.0), beta=1e-3, **kw)


def egg(**kw):
    return on_substrate(sb.UserShell.closed_halves(PROLATE, OBLATE), rho=0.5, **kw)


@pytest.mark.slow  # pressurised structures of both halves derived (~2 min on a fresh cache)
def test_equal_halves_given_apart_inflate_as_the_symmetric_closed_shell():
    # the egg's inflation (both halves joined, the equator free to tilt) of a mirror-symmetric
    # shell is the half's with its equator held vertical
    symmetric = sb.inflate(on_substrate(sb.UserShell(*SPHEROID), pressure=0.1))
    halves = sb.inflate(on_substrate(sb.UserShell.closed_halves(SPHEROID, SPHEROID_FAST), pressure=0.1))
    assert symmetric.success and halves.success
    assert halves.pole_rise == pytest.approx(symmetric.pole_rise, rel=1e-8)
    assert halves.lower_pole_rise == pytest.approx(symmetric.pole_rise, rel=1e-8)
    assert halves.volume_change == pytest.approx(2 * symmetric.volume_change, rel=1e-8)  # the whole shell's
    assert np.isnan(symmetric.lower_pole_rise)


@pytest.mark.slow  # pressurised structures of both halves derived and two-contact states (~3 min cold)
@pytest.mark.parametrize("sealed", [False, True])
@pytest.mark.parametrize("delta", [0.02, 0.2])
def test_equal_halves_given_apart_under_pressure_are_the_symmetric_closed_shell(delta, sealed):
    symmetric = sb.solve(on_substrate(sb.UserShell(*SPHEROID), pressure=0.1, sealed=sealed), delta=delta)
    halves = sb.solve(on_substrate(sb.UserShell.closed_halves(SPHEROID, SPHEROID_FAST), pressure=0.1, sealed=sealed),
                      delta=delta)
    assert symmetric.valid and halves.valid and halves.topology == symmetric.topology
    assert halves.force == pytest.approx(symmetric.force, rel=1e-8)
    assert halves.pressure == pytest.approx(symmetric.pressure, rel=1e-8)
    # open, E = E_el - p (V - V_ref), whose terms nearly cancel (E = -1.2e-4 at delta 0.2, each term
    # ~5e-3): held to 1e-8 of the terms' size
    work = symmetric.pressure * abs(symmetric.system.volume(symmetric.sol, symmetric.x, symmetric.p)
                                    - symmetric.scene.closed_volume()) if not sealed else 0.0
    assert halves.energy == pytest.approx(symmetric.energy, abs=1e-8 * (abs(symmetric.energy) + 2 * work))


@pytest.mark.slow
def test_an_inflated_egg_tilts_its_equator_and_its_pressure_is_the_derivative_of_its_energy_by_its_volume():
    scene = egg(pressure=0.1)
    s = sb.inflate(scene)
    assert s.success and s.system.regions[1].kind == "free"
    # the halves joined: the equator's radius, height and slope shared, its tangent tilted (the
    # prolate half pulled out, the oblate in), which the halves inflated apart would hold vertical
    sysm, yb = s.system, s.y[:, -1]
    (Lu, _), (Ll, _) = sysm.seam_slopes
    up, low = sysm.rows(0), sysm.rows(1)
    assert yb[up][0] == pytest.approx(yb[low][0], rel=1e-12) and yb[up][5] == 0.0 == yb[low][5]
    assert Lu * yb[up][1] + Ll * yb[low][1] == pytest.approx(-np.pi, rel=1e-10)
    assert Lu * yb[up][1] + np.pi / 2 < -0.02  # measured -0.041 rad
    # each pole's rise differs from its half's inflated alone (the seam is no mirror plane)
    alone = [sb.inflate(on_substrate(sb.UserShell(*h), rho=0.5, pressure=0.1)).pole_rise for h in (PROLATE, OBLATE)]
    assert abs(s.pole_rise - alone[0]) > 1e-3 and abs(s.lower_pole_rise - alone[1]) > 1e-3
    # an equilibrium under the pressure p makes E_el - p V stationary: along the inflated branch
    # dE_el = p dV (the energy by quadrature, the volume by its own; the ODE knows neither)
    h, elastic, volume = 1e-4, [], []
    for p in (0.1 - h, 0.1 + h):
        q = sb.inflate(scene.replace(pressure=p), start=s)
        assert q.success
        elastic.append(q.energy + p * q.volume_change)
        volume.append(q.volume_change)
    assert (elastic[1] - elastic[0]) / (volume[1] - volume[0]) == pytest.approx(0.1, rel=1e-5)
    with pytest.raises(ValueError, match="the inflated state of a closed shell on a substrate under a curved tip is not"):
        sb.stability(s)  # not built (it was an IndexError)


@pytest.mark.slow
def test_an_egg_under_pressure_starts_from_its_inflated_state_with_its_force_from_its_energy():
    scene = egg(pressure=0.1)
    # the tip finds the upper pole, the substrate the lower pole, at their inflated positions: the
    # force vanishes with delta (linear near 0; the halves' rises apart would leave 6e-3 of delta)
    F = [sb.solve(scene, delta=d).force for d in (0.002, 0.004)]
    assert F[0] > 0 and abs(2 * F[0] - F[1]) < 0.02 * F[0]
    s = sb.solve(scene, delta=0.2)
    assert s.valid and s.topology == "closed-cap-cap"
    h = 1e-4
    E = [sb.solve(scene, delta=0.2 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)  # with the pressure's work


@pytest.mark.slow
def test_a_sealed_egg_holds_its_volume_and_its_pressure_rises():
    scene = egg(pressure=0.1, sealed=True)
    V0 = sb.enclosed_volume(scene)
    assert V0 == pytest.approx(scene.closed_volume() + sb.inflate(egg(pressure=0.1)).volume_change, rel=1e-14)
    states = [sb.solve(scene, delta=d) for d in (0.1, 0.2)]
    for s in states:
        assert s.valid
        # the volume by quadrature of both halves' profiles, not the ODE's volume state
        assert s.system.at(s.p).volume(s.sol, s.x, s.p) == pytest.approx(V0, rel=1e-8)
    assert 0.1 < states[0].pressure < states[1].pressure
    h = 1e-4
    E = [sb.solve(scene, delta=0.2 + sign * h, guess=states[1]).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(states[1].force, rel=1e-5)


@pytest.mark.slow
def test_the_eggs_conditions_under_pressure_have_their_jacobians():
    from shellbvp.configurations import configuration, names
    from shellbvp.inflation import _system

    rng = np.random.default_rng(1)
    systems = [configuration(name).system(egg(pressure=0.1, sealed=True), "delta", 0.05, 1e-3)
               for name in ("closed-cap-cap", "closed-line-annulus", "closed-point-line")]
    systems.append(_system(egg(pressure=0.1), 0.1))
    assert systems[0].lower_pole_rise is not None and "closed-cap-cap" in names()
    for sysm in systems:
        assert sysm.n_conditions == sysm.n + sysm.k
        ya, yb = rng.uniform(0.5, 1.5, sysm.n), rng.uniform(0.5, 1.5, sysm.n)
        p = np.r_[np.log(rng.uniform(0.05, 0.3, sysm.k - 1)), 0.12] if sysm.k else None
        A, B, *P = sysm.bc_jac(ya, yb, p)
        h, base = 1e-7, sysm.bc(ya, yb, p)
        fd = np.column_stack([(sysm.bc(ya + h * e, yb, p) - base) / h for e in np.eye(sysm.n)])
        assert np.allclose(fd, A, atol=1e-5, rtol=1e-5), sysm.topology
        fd = np.column_stack([(sysm.bc(ya, yb + h * e, p) - base) / h for e in np.eye(sysm.n)])
        assert np.allclose(fd, B, atol=1e-5, rtol=1e-5), sysm.topology
        if sysm.k:
            fd = np.column_stack([(sysm.bc(ya, yb, p + h * e) - base) / h for e in np.eye(sysm.k)])
            assert np.allclose(fd, P[0], atol=1e-5, rtol=1e-5), sysm.topology


@pytest.mark.slow  # the egg between plates under pressure and sealed: ~80 s of CPU on a warm cache
@pytest.mark.parametrize("sealed", [False, True])
def test_an_egg_between_plates_under_pressure_has_its_force_from_its_energy(sealed):
    # between plates the upper half's contact is the plate's; the inflated egg, the volume over
    # both halves and the pressure's work are the substrate's; a flat plate on a substrate is the
    # same problem
    shell = sb.UserShell.closed_halves(PROLATE, OBLATE)
    scene = sb.Scene(closed=True, shell=shell, support="plates", tip=sb.FlatTip(), rho=1.0, beta=1e-3,
                     pressure=0.0 if sealed else 0.1, sealed=sealed)
    state = sb.solve(scene, delta=0.1, tol=1e-8)
    assert state.success and state.valid, state.message
    h = 1e-3
    energy = {d: sb.solve(scene, delta=0.1 + d, guess=state, tol=1e-8).energy for d in (-2 * h, -h, h, 2 * h)}
    d1, d2 = (energy[h] - energy[-h]) / (2 * h), (energy[2 * h] - energy[-2 * h]) / (4 * h)
    assert (4 * d1 - d2) / 3 == pytest.approx(state.force, rel=1e-5)  # Richardson: O(h^4)
    on_flat = sb.solve(scene.replace(support="substrate"), delta=0.1, tol=1e-8)
    assert on_flat.force == pytest.approx(state.force, rel=1e-10)
