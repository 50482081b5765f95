"""The SymPy derivation and the generated code (issue: symbolic derivation).

Checks the constitutive laws against closed forms, the generated numpy
functions against direct SymPy evaluation of the same derivation, generated
Jacobians against finite differences, specialisation (xi = 0, neo-Hookean),
determinism of the generated text and validation of user energies.
"""

import functools
import re
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

import shellbvp as sb
from symbolic import geometry as sg
from symbolic import materials as sm
from symbolic.build import generate_source, structure_from_description
from symbolic.equations import BETA, CONTACT_STATES, FREE_STATES, derive
from symbolic.version import canonical_json

LS, LT = sm.LS, sm.LT


@functools.lru_cache(maxsize=None)
def _derivation(desc_json):
    import json

    return derive(structure_from_description(json.loads(desc_json)))


def derivation(scene):
    return _derivation(canonical_json(scene.structure()))


SCENES = {
    "base": sb.Scene.preset("base"),
    "base-xi0": sb.Scene.preset("base-xi0"),
    "gent": sb.Scene.preset("gent1", material=sb.Gent(5.0)),  # Jm large enough for random stretches
    "neo-hookean": sb.Scene.preset("base", material=sb.NeoHookean()),
    "rotation-bending": sb.Scene.preset("base", bending=sb.RotationBending()),
    "rotation-bending-xi0": sb.Scene.preset("base-xi0", bending=sb.RotationBending()),
}
#: The product of two variants each checked on its own by default (rotation-bending, base-xi0): one
#: more derivation (~3 s of CPU) used by no other default test, so behind --runslow.
PRODUCTS = {"rotation-bending-xi0"}
SCENE_NAMES = [pytest.param(n, marks=pytest.mark.slow) if n in PRODUCTS else n for n in sorted(SCENES)]


# ---------------------------------------------------------------- constitutive laws
def test_moments_are_h_dU_dkappa_and_the_papers_closed_form():
    d = derivation(SCENES["base"])
    A, o = d.free_phys, d.free_phys_out
    ls, lt, ks, kt = sp.symbols("ls lt_ ks kt_")
    r, phi = sp.symbols("r phi")
    ksR, ktR = (A.expand(o[k]) for k in ("ksR", "ktR"))
    lt_e, kt_e = A.expand(o["lt"]), A.expand(o["kt"])
    m = ls**2 * ks + lt_e**2 * kt_e - ksR - ktR
    # paper eq. momentconst (nondimensional): M_s = beta ls/lt m, M_theta = beta lt/ls m
    assert sp.simplify(A.expand(o["M_s"]) - BETA * ls / lt_e * m) == 0
    assert sp.simplify(A.expand(o["M_t"]) - BETA * lt_e / ls * m) == 0
    # and independently from h dU/dkappa with h = 1/(ls lt)
    KS, KT = sp.symbols("KS KT")
    U = sm.mooney_rivlin(sp.Symbol("alpha", positive=True)) + BETA / 2 * (LS**2 * KS + LT**2 * KT - ksR - ktR) ** 2
    Ms = (sp.diff(U, KS) / (LS * LT)).subs({LS: ls, LT: lt_e, KS: ks, KT: kt_e})
    assert sp.simplify(A.expand(o["M_s"]) - Ms) == 0


def _T_closed_forms(W_name, ls, lt, par):
    i1 = ls**2 + lt**2 + 1 / (ls**2 * lt**2)
    if W_name == "mr":
        a = par
        Ts = ((1 - a) * (ls - 1 / (ls**3 * lt**2)) + a * (ls * lt**2 - 1 / ls**3)) / lt
        Tt = ((1 - a) * (lt - 1 / (lt**3 * ls**2)) + a * (lt * ls**2 - 1 / lt**3)) / ls
    else:
        Jm = par
        f = 1 / (1 - (i1 - 3) / Jm)
        Ts = f * (ls - 1 / (ls**3 * lt**2)) / lt
        Tt = f * (lt - 1 / (lt**3 * ls**2)) / ls
    return Ts, Tt


@pytest.mark.parametrize("name,scene", [("mr", SCENES["base"]), ("gent", SCENES["gent"])])
def test_tensions_match_closed_forms(name, scene):
    d = derivation(scene)
    A, o = d.free_phys, d.free_phys_out
    ls = sp.Symbol("ls")
    lt = A.expand(o["lt"])
    par = d.params[-1]
    Ts, Tt = _T_closed_forms(name, ls, lt, par)
    rng = np.random.default_rng(1)
    for _ in range(5):
        sub = {A.inputs[0]: rng.uniform(0.2, 1.4), sp.Symbol("r"): rng.uniform(0.3, 1.2),
               ls: rng.uniform(0.7, 1.4), par: rng.uniform(0.05, 0.9) if name == "mr" else rng.uniform(3, 9)}
        for got, want in ((o["T_s"], Ts), (o["T_t"], Tt)):
            g, w = (float(sp.N(e.subs(sub), 30)) for e in (A.expand(got), want))
            assert g == pytest.approx(w, rel=1e-13)


def test_small_strain_shear_modulus_of_builtin_energies_is_one():
    a, j = sp.symbols("alpha Jm", positive=True)
    for W in (sm.mooney_rivlin(a), sm.neo_hookean(), sm.gent(j)):
        assert sp.simplify(sm.small_strain_shear_modulus(W) - 1) == 0
        # isotropy at small strain: d2W/dls dlt = 2 mu
        assert sp.simplify(sp.diff(W, LS, LT).subs({LS: 1, LT: 1}) - 2) == 0


def test_user_energy_validation():
    good = sb.StrainEnergy("(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2")
    assert good.shear_modulus == pytest.approx(1.0)
    with pytest.raises(ValueError, match="stress-free"):
        sb.StrainEnergy("lambda_s + lambda_theta - 2")
    with pytest.raises(ValueError, match="symmetric"):
        sb.StrainEnergy("(lambda_s - 1)**2 + 2*(lambda_theta - 1)**2")
    with pytest.raises(ValueError, match="vanish"):
        sb.StrainEnergy("(lambda_s - 1)**2 + (lambda_theta - 1)**2 + 1")
    with pytest.raises(ValueError, match=r"'c' \(unknown name\)"):
        sb.StrainEnergy("c*(lambda_s - 1)**2 + c*(lambda_theta - 1)**2")
    stiff = sb.StrainEnergy("lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3")
    assert stiff.shear_modulus == pytest.approx(2.0)


def test_sphere_tip_curvatures_are_one_over_rho_independent_of_omega_prime():
    d = derivation(SCENES["base"])
    C, o = d.contact_phys, d.contact_phys_out
    rho = sp.Symbol("rho", positive=True)
    for k in ("ks", "kt"):
        e = C.expand(o[k])
        assert sp.simplify(e - 1 / rho) == 0
        # no dependence on the stretch (i.e. on omega' = ls Psi/(rho G))
        assert sp.Symbol("ls") not in e.free_symbols
    tip = sg.sphere_tip().derived()
    assert sp.simplify(sp.tan(tip["phi"]) - tip["dB"] / tip["dA"]) == 0


def test_user_tip_curvatures_are_geometric():
    """A paraboloid tip B = A^2/2: kappa_s = 1/(rho (1+w^2)^{3/2}), independent of omega'."""
    tip = sg.user_tip("omega", "omega**2/2").derived()
    w = sg.OMEGA
    assert sp.simplify(tip["rho_ks"] - 1 / (1 + w**2) ** sp.Rational(3, 2)) == 0
    assert sp.simplify(tip["rho_kt"] - 1 / sp.sqrt(1 + w**2)) == 0


# ---------------------------------------------------------------- generated code
def _random_free(rng, m):
    S = rng.uniform(0.05, 1.5, m)
    y = np.vstack([rng.uniform(0.8, 1.2, m), rng.uniform(0.3, 1.5, m), rng.uniform(0.8, 1.25, m),
                   rng.uniform(0.3, 3, m), rng.uniform(-0.3, 0.3, m), rng.uniform(-1, 0, m)])
    return S, y


def _random_contact(rng, m):
    S = rng.uniform(1e-3, 0.3, m)
    y = np.vstack([rng.uniform(0.8, 1.2, m), rng.uniform(0.8, 1.25, m)])
    return S, y


def _sympy_eval(prog, expr, sub):
    return float(sp.N(prog.expand(expr).xreplace(sub), 30))


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_generated_functions_equal_direct_sympy_evaluation(name):
    scene = SCENES[name]
    mod, d = scene.model(), derivation(scene)
    par = scene.parameters(mod)
    psub = dict(zip(d.params, par))
    rng = np.random.default_rng(7)
    m = 8  # random points per region, each against SymPy at 30 digits (20 before: 2.5x the cost)
    for region, rand, prog, states, rhs, prof in (
        ("free", _random_free, d.free, d.free_states, d.free_rhs, d.free_profile),
        ("contact", _random_contact, d.contact, d.contact_states, d.contact_rhs, d.contact_profile),
    ):
        S, y = rand(rng, m)
        g = getattr(mod, f"{region}_rhs")(S, y, par)
        p = getattr(mod, f"{region}_profile")(S, y, par)
        assert g.shape == (len(states), m)
        for k in range(m):
            sub = {**psub, prog.inputs[0]: S[k], **dict(zip(states, y[:, k]))}
            want = [_sympy_eval(prog, e, sub) for e in rhs]
            np.testing.assert_allclose(g[:, k], want, rtol=1e-12, atol=1e-12 * (1 + np.max(np.abs(want))))
            if k < 3:
                for key in ("tau_s", "M_s", "Q", "P", "axial_force_2pi", "energy_density"):
                    w = _sympy_eval(prog, prof[key], sub)
                    assert p[key][k] == pytest.approx(w, rel=1e-12, abs=1e-12)
    # the interior corner's rows (two free states at one S)
    (_, yl), (_, yr) = _random_free(rng, 1), _random_free(rng, 1)
    SK, *yk = d.kink_inputs
    sub = {**psub, SK: 0.4, **dict(zip(yk, np.r_[yl[:, 0], yr[:, 0]]))}
    want = [_sympy_eval(d.kink, e, sub) for e in d.kink_res]
    np.testing.assert_allclose(mod.kink_res(0.4, yl[:, 0], yr[:, 0], par), want, rtol=1e-12,
                               atol=1e-12 * (1 + np.max(np.abs(want))))


def _fd_jacobian(f, x, h):
    cols = []
    for j in range(len(x)):
        xp, xm = x.copy(), x.copy()
        xp[j] += h * (1 + abs(x[j]))
        xm[j] -= h * (1 + abs(x[j]))
        cols.append((f(xp) - f(xm)) / (xp[j] - xm[j]))
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_generated_jacobians_equal_finite_differences(name):
    scene = SCENES[name]
    mod = scene.model()
    par = scene.parameters(mod)
    rng = np.random.default_rng(3)
    h = 1e-6

    def check(analytic, fd):
        scale = 1 + np.abs(fd)
        err = np.max(np.abs(analytic - fd) / scale)
        assert err < 1e-6, err

    for region, rand in (("free", _random_free), ("contact", _random_contact)):
        rhs, jac, jpar = (getattr(mod, f"{region}_{s}") for s in ("rhs", "jac", "jac_par"))
        S, y = rand(rng, 10)
        dy, dS = jac(S, y, par)
        dp = jpar(S, y, par)
        for k in range(10):
            check(dy[:, :, k], _fd_jacobian(lambda v: rhs(S[k:k + 1], v[:, None], par)[:, 0], y[:, k], h))
            check(dS[:, k], _fd_jacobian(lambda v: rhs(v, y[:, k:k + 1], par)[:, 0], S[k:k + 1], h)[:, 0])
            check(dp[:, :, k], _fd_jacobian(lambda v: rhs(S[k:k + 1], y[:, k:k + 1], v)[:, 0], par, h))

    # conditions: pole, rim, contact line (both models), force
    x = np.array([1.05, 0.98])
    check(mod.pole_jac(x[0], x[1], 1.02, par),
          _fd_jacobian(lambda v: mod.pole_res(v[0], v[1], v[2], par), np.r_[x, 1.02], h))
    S, y = _random_free(rng, 1)
    check(mod.rim_jac(np.pi / 2, y[:, 0], par), _fd_jacobian(lambda v: mod.rim_res(np.pi / 2, v, par), y[:, 0], h))
    yc = np.array([1.02, 1.05])
    yf = _random_free(rng, 1)[1][:, 0]
    xj = np.r_[0.15, yc, yf, 0.3]
    for model in ("smooth", "paper", "corner", "pinned"):  # pinned: the paper's edge held at the tip's end
        res = getattr(mod, f"junction_{model}_res")
        jac = getattr(mod, f"junction_{model}_jac")
        check(jac(0.15, yc, yf, 0.3, 0.0, par),
              _fd_jacobian(lambda v: res(v[0], v[1:3], v[3:9], v[9], 0.0, par), xj, h))
    check(mod.force_jac(0.15, yc, yf, 0.3, 0.7, par),
          _fd_jacobian(lambda v: mod.force_res(v[0], yc, v[1:7], 0.3, v[7], par), np.r_[0.15, yf, 0.7], h))
    # regular pole of a lifted-off free cap, d/d(y, S)
    check(mod.free_pole_jac(0.05, yf, par),
          _fd_jacobian(lambda v: mod.free_pole_res(v[6], v[:6], par), np.r_[yf, 0.05], h))
    # interior corner of the free region, d/d(S_k, yl, yr)
    yr = _random_free(rng, 1)[1][:, 0]
    check(mod.kink_jac(0.4, yf, yr, par),
          _fd_jacobian(lambda v: mod.kink_res(v[0], v[1:7], v[7:13], par), np.r_[0.4, yf, yr], h))


def test_condition_counts_close_each_control_mode():
    """8 ODEs; lambda0- or delta-control: 2 unknowns, 10 conditions; force: 3 and 11."""
    mod = SCENES["base"].model()
    par = SCENES["base"].parameters(mod)
    n = len(mod.FREE_STATES) + len(mod.CONTACT_STATES)
    assert (len(mod.FREE_STATES), len(mod.CONTACT_STATES)) == (len(FREE_STATES), len(CONTACT_STATES)) == (6, 2)
    yf = np.array([1.0, 1.0, 1.0, 1.0, 0.0, -0.5])
    pole = mod.pole_res(1.0, 1.0, 1.0, par).size
    rim = mod.rim_res(np.pi / 2, yf, par).size
    for model in ("smooth", "paper", "corner", "pinned"):
        jun = getattr(mod, f"junction_{model}_res")(0.1, np.ones(2), yf, 0.1, 0.0, par).size
        force = mod.force_res(0.1, np.ones(2), yf, 0.1, 0.5, par).size
        assert pole + rim + jun == n + 2          # unknowns: ln Sc and lambda0 (or delta)
        assert pole + rim + jun + force == n + 3  # unknowns: ln Sc, lambda0 and delta


def test_specialisation_leaves_out_unneeded_terms():
    d0 = derivation(SCENES["base-xi0"])
    # xi = 0: the generalised tensions are the plain tensions, no M*kappa term
    for prog, o in ((d0.free_phys, d0.free_phys_out), (d0.contact_phys, d0.contact_phys_out)):
        assert o["tau_s"] == o["T_s"] and o["tau_t"] == o["T_t"]
    src0 = SCENES["base-xi0"].model().__file__
    text0 = open(src0).read()
    assert not re.search(r"^\s*tau_s = .*M_s", text0, re.M)
    text1 = open(SCENES["base"].model().__file__).read()
    assert re.search(r"^\s*tau_s = .*M_s", text1, re.M)  # the check above can fail
    text_nh = open(SCENES["neo-hookean"].model().__file__).read()
    assert "alpha" not in text_nh and "alpha" in text1
    assert SCENES["neo-hookean"].model().PARAMS == ("beta", "rho", "gamma")
    # the pressure's terms only where there is a pressure
    assert "pressure" not in text1 and "pole_rise" not in text1
    inflated = SCENES["base"].replace(pressure=0.1).model()
    assert inflated.PARAMS[:4] == ("beta", "rho", "pressure", "pole_rise")
    assert re.search(r"^\s*dQ = .*pressure", open(inflated.__file__).read(), re.M)


@functools.lru_cache(maxsize=None)
def _base_source():
    """The base structure's generated source, derived once for the module."""
    return generate_source(SCENES["base"].structure())


def test_regeneration_is_byte_identical():
    desc = SCENES["base"].structure()
    a = _base_source()
    b = generate_source(desc)
    assert a == b
    assert a == open(SCENES["base"].model().__file__).read()
    assert a.startswith("# Generated by shellbvp") and "DO NOT EDIT" in a.splitlines()[0]


def test_warm_start_does_not_import_sympy(tmp_path):
    """A second process loads the cached module without SymPy or the derivation."""
    SCENES["base"].model()  # make sure the cache holds it
    import os

    code = ("import sys, shellbvp as sb; m = sb.Scene.preset('base').model(); "
            "print(m.KEY[:8], 'sympy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ), check=True).stdout.split()
    assert out == [SCENES["base"].model().KEY[:8], "False"]


def test_corrupt_cache_file_is_regenerated(tmp_path, monkeypatch, base_derivation):
    from shellbvp import model as sbm

    scene = sb.Scene.preset("base", material=sb.MooneyRivlin(0.3))
    desc = scene.structure()
    # a cache of its own: the suite's is shared by its workers, which must not meet the garbage
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    path = sbm.module_path(desc)
    path.write_text("garbage = (\n")
    monkeypatch.setattr(sbm, "_loaded", {})
    mod = sbm.load_module(desc)
    assert mod.KEY == sbm.description_key(desc) and len(base_derivation) == 1
    assert path.read_text().startswith("# Generated by shellbvp")


def test_a_structure_another_process_derives_is_waited_for_and_read(tmp_path, monkeypatch, caplog):
    """Two test workers meeting one new structure at once each derived it (~4 s of CPU each time):
    the second now waits on the first's lock and imports its module; past ``LOCK_WAIT`` it
    derives the structure itself."""
    import logging
    import os
    import threading

    fcntl = pytest.importorskip("fcntl")
    from shellbvp import model as sbm

    path, key = tmp_path / "model_lock.py", "lock-test-" + "0" * 54
    monkeypatch.delitem(sys.modules, f"shellbvp_generated_{key[:20]}", raising=False)
    derived = []

    def generate():
        derived.append(True)
        return f"KEY = {key!r}\nBY = 'this process'\n", None

    fd = os.open(path.with_name(path.name + ".lock"), os.O_RDWR | os.O_CREAT, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)  # another process deriving it (a second open file holds its own lock)
    got = []
    worker = threading.Thread(target=lambda: got.append(sbm._cached_or_generated(path, key, generate)))
    worker.start()
    worker.join(0.5)
    assert worker.is_alive() and not derived  # waiting, not deriving
    sbm.write_atomic(path, f"KEY = {key!r}\nBY = 'the other process'\n")
    os.close(fd)
    worker.join(60)
    assert got and got[0].BY == "the other process" and not derived
    # a lock held past LOCK_WAIT: derived here too (a warning says so)
    path.unlink()
    fd = os.open(path.with_name(path.name + ".lock"), os.O_RDWR)
    fcntl.flock(fd, fcntl.LOCK_EX)
    monkeypatch.setattr(sbm, "LOCK_WAIT", 0.2)
    try:
        with caplog.at_level(logging.WARNING, logger="shellbvp.model"):
            mod = sbm._cached_or_generated(path, key, generate)
    finally:
        os.close(fd)
    assert mod.BY == "this process" and derived == [True]
    assert "deriving it here too" in caplog.text


def test_user_shell_and_tip_generate_code():
    """A user spheroid equals the built-in one; a user tip is accepted."""
    user = sb.Scene.preset("base", shell=sb.UserShell("2*sin(S)", "-2*cos(S)", "pi/2"))
    builtin = sb.Scene.preset("base")
    mu, mb = user.model(), builtin.model()
    rng = np.random.default_rng(5)
    S, y = _random_free(rng, 8)
    np.testing.assert_allclose(mu.free_rhs(S, y, user.parameters(mu)),
                               mb.free_rhs(S, y, builtin.parameters(mb)), rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="R\\(0\\)"):
        sb.UserShell("1 + S", "0", "1")
    with pytest.raises(ValueError, match="B'\\(0\\)"):
        sb.UserTip("omega", "omega")


def test_powers_are_printed_without_float_or_half_exponents():
    """numba compiles ``x**(-1.0)`` and ``x**(3/2)`` to calls of pow; the printer writes them as
    quotients and square roots (their values: test_generated_functions_equal_direct_sympy_evaluation)."""
    from symbolic.codegen import Printer

    x, y = sp.symbols("x y", positive=True)
    printer = Printer()
    expected = {1 / x: "1/(x)", x ** -3: "1/(x**3)", x ** sp.Rational(3, 2): "numpy.sqrt(x)**3",
                x ** sp.Rational(-5, 2): "1/(numpy.sqrt(x)**5)", 1 / (x + y): "1/(x + y)",
                sp.sqrt(x): "numpy.sqrt(x)", x ** 2: "x**2"}
    for expr, text in expected.items():
        assert printer.doprint(expr) == text
    source = _base_source()
    assert "numpy.sqrt(" in source
    assert not re.search(r"\*\*\(-?[0-9]+(\.[0-9]+|/2)\)", source)
