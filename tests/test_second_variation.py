r"""The two-dimensional energy and its second variation (symbolic.second_variation; issue 44, item 1).

* restricted to axisymmetric states the 2D energy is today's ``U R Psi + p r^2 z'/2``: SymPy
  ``simplify`` of the difference is 0;
* its first variation's Euler-Lagrange expressions are today's equilibrium equations, built from
  the derivation's ``tau, M`` (``symbolic.equations``) along random meridians (not solutions):
  ``E_u = -eq1``, ``E_w = -r psi eq2`` (``w`` along ``N = -n``), numerically to 1e-20 (mpmath);
  also for a wall whose thickness varies (``t W + beta t^3 B``, issue 58), against the
  equations derived with the same t(S);
* rigid motions: translations are null vectors of the second-order energy density of any state,
  rotations of the unstressed one (pointwise, to 1e-25 of the size of the terms); the unstressed
  state's form is positive semidefinite and positive on non-rigid fields;
* a closed form: the out-of-plane block of a flat membrane under equibiaxial prestretch with
  bending, ``q_w = S/4 [T (w'^2 + n^2 w^2/S^2) + beta c^2 (w'' + w'/S - n^2 w/S^2)^2]``
  (``c = 1`` trace, ``1/lambda`` rotation): the membrane term of a plate under an isotropic
  tension T (Timoshenko & Woinowsky-Krieger, *Theory of Plates and Shells*, 2nd ed. 1959, §12,
  energy of the middle-plane forces ``T/2 |grad w|^2`` per deformed area) and Kirchhoff's
  bending energy ``D/2 (Laplacian w)^2`` with the model's bending Poisson ratio 1
  (``bending.plate_limit``).
"""

from __future__ import annotations

import functools
import random

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from symbolic import bending, geometry, materials
from symbolic import second_variation as sv
from symbolic.equations import BETA, POLE_RISE, PRESSURE, PRESSURE_LOAD, RHO, Structure, derive
from symbolic.geometry import GAMMA, S
from symbolic.materials import LS, LT

ALPHA = sp.Symbol("alpha", positive=True)
JM = sp.Symbol("Jm", positive=True)
MATERIALS = {
    "neo_hookean": (materials.neo_hookean(), ()),
    "mooney_rivlin": (materials.mooney_rivlin(ALPHA), (ALPHA,)),
    "gent": (materials.gent(JM), (JM,)),
}
BENDINGS = {"trace": None, "rotation": bending.rotation_bending(), "koiter": bending.koiter_bending()}
MATERIAL_VALUES = {ALPHA: 0.23, JM: 6.5}
#: A wall's thickness over the pole's for the profiled variants (t(0) = 1).
THICKNESS = 1 + 3 * S / 10 - S**2 / 5


@functools.lru_cache(maxsize=None)
def variation(material, family, pressurised=True, profiled=False):
    W, par = MATERIALS[material]
    return sv.second_variation(W, par, BENDINGS[family], pressurised=pressurised, profiled=profiled)


def args_of(res):
    return res.base + res.params + (sv.N_MODE,)


@functools.lru_cache(maxsize=None)
def matrix_function(material, family, module="mpmath"):
    res = variation(material, family)
    return sp.lambdify(args_of(res), res.matrix, module, cse=True)


# ---------------------------------------------------------------- total derivative on base symbols
Z = sp.Symbol("z")
DDLS, DDKS, DDPSI = sp.symbols("ddls ddks ddPsi")
_PSI = sv.LS_ * sv.PSI_R
_D1 = {sv.R_: _PSI * sp.cos(sv.PHI), Z: _PSI * sp.sin(sv.PHI), sv.PHI: _PSI * sv.KS_, sv.LS_: sv.DLS,
       sv.KS_: sv.DKS, sv.PSI_R: sv.DPSI_R, sv.DLS: DDLS, sv.DKS: DDKS, sv.DPSI_R: DDPSI}


def D(e):
    """d/dS along the base state (r' = psi cos phi, z' = psi sin phi, phi' = psi kappa_s)."""
    return sum(sp.diff(e, k) * v for k, v in _D1.items())


def mode(u, v, w):
    """The nine amplitudes of a field given as expressions in the base symbols."""
    out = []
    for f in (u, v, w):
        f = sp.sympify(f)
        out += [f, D(f), D(D(f))]
    return out


# rigid motions in (u, v, w), with t = (cos phi, sin phi), N = (-sin phi, cos phi) in (e_r, e_z)
AXIAL = (0, mode(sp.sin(sv.PHI), 0, sp.cos(sv.PHI)))                    # e_z
LATERAL = (1, mode(sp.cos(sv.PHI), -1, -sp.sin(sv.PHI)))                # e_x = cos e_r - sin e_theta
SPIN = (0, mode(0, sv.R_, 0))                                            # e_z x x0 = r e_theta
TILT = (1, mode(Z * sp.cos(sv.PHI) - sv.R_ * sp.sin(sv.PHI), -Z,         # e_y x x0
                -(Z * sp.sin(sv.PHI) + sv.R_ * sp.cos(sv.PHI))))


def random_point(rng, res, n, stress_free=False, pressure=0.3):
    vals = {s: rng.uniform(0.3, 1.4) for s in sv.BASE + (Z, DDLS, DDKS, DDPSI)}
    vals[sv.PHI] = rng.uniform(-1.2, 1.2)
    vals[sv.DKS] = rng.uniform(-1.0, 1.0)
    vals.update({BETA: 0.3, sv.N_MODE: n, **MATERIAL_VALUES})
    if PRESSURE in res.params:
        vals[PRESSURE] = pressure
    vals = {k: mp.mpf(v) for k, v in vals.items()}
    if stress_free:  # lambda_s = lambda_theta = 1, kappa = kappa_0: no tension, no moment
        vals.update({sv.R_: vals[sv.RR], sv.LS_: mp.mpf(1), sv.DLS: mp.mpf(0), sv.KS0: vals[sv.KS_],
                     sv.KT0: mp.sin(vals[sv.PHI]) / vals[sv.RR]})
    return vals


def form_at(material, family, vals, fields):
    """(zeta^T M zeta, sum of |M_ij zeta_i zeta_j|) at a point."""
    res = variation(material, family)
    M = mp.matrix(matrix_function(material, family)(*[vals[s] for s in args_of(res)]))
    keys = list(vals)
    z = [sp.lambdify(keys, f, "mpmath")(*[vals[k] for k in keys]) for f in fields]
    terms = [M[i, j] * z[i] * z[j] for i in range(9) for j in range(9)]
    return mp.fsum(terms), mp.fsum(abs(t) for t in terms)


# ------------------------------------------------------------------------------ invariants
def test_builtin_energies_in_the_invariants():
    """The rewrite gives I1 = tr C + 1/det C, I2 = tr C/det C + det C in the paper's formulas."""
    i1 = sv.TRC + 1 / sv.DETC
    i2 = sv.TRC / sv.DETC + sv.DETC
    want = {
        "neo_hookean": (i1 - 3) / 2,
        "mooney_rivlin": ((1 - ALPHA) * (i1 - 3) + ALPHA * (i2 - 3)) / 2,
        "gent": -JM / 2 * sp.log(1 - (i1 - 3) / JM),
    }
    for name, (W, _) in MATERIALS.items():
        got = sv.invariant_form(W)
        assert not got.has(LS, LT)
        assert sp.simplify(sp.expand_log(got - want[name], force=True)) == 0, (name, got)


def test_user_energies_accepted_through_the_invariants_or_refused():
    ls, lt = LS, LT
    accepted = [
        (ls**2 + lt**2 + 1 / (ls * lt) ** 2 - 3) / 2 + (ls * lt - 1) ** 2,  # odd: sqrt(det C)
        sp.exp((ls**2 + lt**2 - 2) / 10) - 1 + sp.log(ls) + sp.log(lt),       # logs combined
        ((ls**2 + lt**2 + 1 / (ls * lt) ** 2 - 3) / 2) ** 3 / 7,               # Yeoh-like
    ]
    x, y = sp.symbols("x y", positive=True)
    for W in accepted:
        got = sv.invariant_form(W)
        assert got.free_symbols <= {sv.TRC, sv.DETC}, got
        back = got.xreplace({sv.TRC: x**2 + y**2, sv.DETC: x**2 * y**2})
        assert sp.simplify(sp.expand_log(back - W.xreplace({ls: x, lt: y}), force=True)) == 0, W
    refused = [
        (ls**3 + lt**3 + (ls * lt) ** -3 - 3) / 3,                      # Ogden, alpha = 3
        (ls**2 + 2 * lt**2 + 1 / (ls * lt) ** 2 - 4) / 2,               # not symmetric
        ls * sp.log(ls) + lt * sp.log(lt),                              # symmetric only across terms
    ]
    for W in refused:
        with pytest.raises(ValueError, match="invariants tr C"):
            sv.invariant_form(W)
    with pytest.raises(ValueError, match="user bending energy"):
        sv.second_variation(materials.neo_hookean(), (), B=(LS * bending.KS - bending.KS0) ** 2 / 2)


# ------------------------------------------------------------------------------ restriction to U
@pytest.mark.parametrize("material,family", [("mooney_rivlin", "trace"), ("gent", "rotation"),
                                             ("neo_hookean", "koiter")])
def test_energy_restricted_to_axisymmetric_states_is_todays(material, family):
    """The base energy of the expansion, L(x0), is U R Psi + p r^2 z'/2 exactly (simplify to 0)
    with U = W(lambda_s, r/R) + beta B of symbolic.bending, kappa_theta = sin(phi)/r."""
    res = variation(material, family)
    W, _ = MATERIALS[material]
    B = BENDINGS[family] if BENDINGS[family] is not None else bending.trace_bending()
    lt = sv.R_ / sv.RR
    at = {LS: sv.LS_, LT: lt, bending.KS: sv.KS_, bending.KT: sp.sin(sv.PHI) / sv.R_,
          bending.KS0: sv.KS0, bending.KT0: sv.KT0}
    U = W.xreplace(at) + BETA * B.xreplace(at)
    psi = sv.LS_ * sv.PSI_R
    want = U * sv.RR * sv.PSI_R + PRESSURE * sv.R_**2 * psi * sp.sin(sv.PHI) / 2
    assert sp.simplify(sp.expand_log(res.energy - want, force=True)) == 0


# ------------------------------------------------------------------------------ first variation
def _meridian(rng):
    """A smooth meridian near the spheroid's (not a solution) and the spheroid's gamma."""
    g = sp.Rational(int(rng.uniform(-1.5, 2.0) * 100), 100)
    a = [sp.Rational(int(rng.uniform(-0.3, 0.3) * 1000), 1000) for _ in range(6)]
    r = sp.sin(S) * (1 + a[0] * S + a[1] * S**2) + a[2] * S**3
    z = -g * sp.cos(S) + a[3] * S**2 + a[4] * S**3 + a[5] * S**4
    return g, r, z


def _base_along(g, r, z):
    """The base symbols as functions of S along the meridian (r, z) over the spheroid gamma = g."""
    sh = geometry.spheroid()
    ksR, ktR = sh.curvatures()
    rp, zp = sp.diff(r, S), sp.diff(z, S)
    psi = sp.sqrt(rp**2 + zp**2)
    Psi = sh.Psi
    ls = psi / Psi
    ks = (rp * sp.diff(zp, S) - zp * sp.diff(rp, S)) / psi**3
    exprs = {sv.R_: r, sv.PHI: sp.atan2(zp, rp), sv.LS_: ls, sv.KS_: ks, sv.DLS: sp.diff(ls, S),
             sv.DKS: sp.diff(ks, S), sv.RR: sh.R, sv.PSI_R: Psi, sv.DPSI_R: sp.diff(Psi, S),
             sv.KS0: ksR, sv.KT0: ktR}
    return {k: sp.lambdify(S, v.subs(GAMMA, g), "mpmath") for k, v in exprs.items()}


@pytest.mark.parametrize("material,family,profiled", [("mooney_rivlin", "trace", False), ("gent", "rotation", False),
                                                      ("mooney_rivlin", "trace", True), ("gent", "rotation", True),
                                                      pytest.param("neo_hookean", "koiter", False, marks=pytest.mark.slow),
                                                      ("mooney_rivlin", "koiter", True)])
def test_first_variation_gives_the_equilibrium_equations(material, family, profiled):
    """Euler-Lagrange of the eta coefficient (n = 0) against eq1, eq2 of symbolic.equations.

    ``E_f = dl/df - (dl/df')' + (dl/df'')''`` for f = u, w; eq1, eq2 from the derivation's
    ``tau_s, tau_theta, M_s, M_theta`` (Q from the moment balance, P the pressure's load):
    ``E_u = -eq1`` and ``E_w = -r psi eq2`` to 1e-20 relative, with both sides of size 1e-3 or
    more (the meridians are not solutions).  S-derivatives by mpmath at 40 digits.  ``profiled``:
    the wall's thickness t(S) = :data:`THICKNESS` in both (``thk`` of the form at each S, the
    structure's ``thickness`` in the equations).
    """
    W, par = MATERIALS[material]
    res = variation(material, family, profiled=profiled)
    st = Structure(W=W, material_params=par, shell=geometry.spheroid(), tip=geometry.sphere_tip(), xi=1,
                   B=BENDINGS[family], pressurised=True, thickness=THICKNESS if profiled else None)
    thickness = sp.lambdify(S, THICKNESS, "mpmath")
    d = derive(st)
    A, o = d.free_phys, d.free_phys_out
    r_, phi_, ls_, ks_, _ = d.free_phys_vars
    eqsyms = (S, r_, phi_, ls_, ks_, *d.params)
    parts = {k: sp.lambdify(eqsyms, A.expand(o[k]), "mpmath") for k in ("tau_s", "tau_t", "M_s", "M_t")}
    idx = {f.name: i for i, f in enumerate(sv.FIELDS)}
    first = sp.lambdify(args_of(res), list(res.first), "mpmath", cse=True)
    rng = random.Random(7 if material == "gent" else 3)
    checked = 0
    with mp.workdps(40):
        for _ in range(2):
            g, r, z = _meridian(rng)
            base = _base_along(g, r, z)
            pvals = {BETA: mp.mpf("0.21"), PRESSURE: mp.mpf("0.37"), GAMMA: mp.mpf(g.p) / g.q, RHO: mp.mpf("0.3"),
                     POLE_RISE: mp.mpf(0), **{k: mp.mpf(v) for k, v in MATERIAL_VALUES.items()}}

            def b(s):
                return {sv.THK: thickness(s), **{k: f(s) for k, f in base.items()}}

            def coeff(name):
                def f(s):
                    bv = b(s)
                    return first(*[bv[k] for k in res.base], *[pvals[p] for p in res.params], 0)[idx[name]]
                return f

            def eq(name):
                def f(s):
                    bv = b(s)
                    return parts[name](s, bv[sv.R_], bv[sv.PHI], bv[sv.LS_], bv[sv.KS_],
                                       *[pvals[p] for p in d.params])
                return f

            rf = base[sv.R_]

            def psi(s):
                bv = b(s)
                return bv[sv.LS_] * bv[sv.PSI_R]

            def rQ(s):  # moment balance: r Q psi = (r M_s)' - r' M_theta
                return (mp.diff(lambda t: rf(t) * eq("M_s")(t), s) - mp.diff(rf, s) * eq("M_t")(s)) / psi(s)

            for S0 in (mp.mpf(rng.uniform(0.3, 1.3)) for _ in range(2)):
                def el(f):
                    return (coeff(f)(S0) - mp.diff(coeff("d" + f), S0)
                            + mp.diff(coeff("dd" + f), S0, 2))
                bv = b(S0)
                Q = rQ(S0) / bv[sv.R_]
                eq1 = (mp.diff(lambda t: rf(t) * eq("tau_s")(t), S0) - mp.diff(rf, S0) * eq("tau_t")(S0)
                       + bv[sv.KS_] * bv[sv.R_] * Q * psi(S0))
                load = sp.lambdify(PRESSURE, PRESSURE_LOAD, "mpmath")(pvals[PRESSURE])
                eq2 = (bv[sv.KS_] * eq("tau_s")(S0) + mp.sin(bv[sv.PHI]) / bv[sv.R_] * eq("tau_t")(S0)
                       - mp.diff(rQ, S0) / (bv[sv.R_] * psi(S0)) - load)
                Eu, Ew = el("u"), el("w")
                assert abs(Eu) > 1e-3 and abs(Ew) > 1e-3
                assert abs(Eu + eq1) < 1e-20 * abs(Eu), (Eu, -eq1)
                want = -bv[sv.R_] * psi(S0) * eq2
                assert abs(Ew - want) < 1e-20 * abs(Ew), (Ew, want)
                checked += 1
    assert checked == 4


# ------------------------------------------------------------------------------ rigid motions
@pytest.mark.parametrize("material,family", [("mooney_rivlin", "trace"), ("gent", "rotation"),
                                             ("neo_hookean", "rotation"), ("mooney_rivlin", "koiter")])
def test_rigid_motions_are_null_vectors(material, family):
    """Translations (n = 0 axial, n = 1 lateral) leave the second-order density of any state at 0
    (also with the pressure: its density is at most linear in a translation); the rotations
    (n = 0 about the axis, n = 1 tilt) that of the unstressed state.  A stressed state's
    rotations are not null (its first variation does not vanish pointwise): a check that could fail.
    """
    res = variation(material, family)
    rng = random.Random(11)
    with mp.workdps(30):
        for _ in range(3):
            for n, fields in (AXIAL, LATERAL):
                q, size = form_at(material, family, random_point(rng, res, n), fields)
                assert size > 1e-2 and abs(q) < 1e-25 * size, (n, q, size)
            for n, fields in (SPIN, TILT):
                q, size = form_at(material, family, random_point(rng, res, n, stress_free=True, pressure=0), fields)
                assert size > 1e-3 and abs(q) < 1e-25 * size, (n, q, size)
                q, size = form_at(material, family, random_point(rng, res, n), fields)
                assert abs(q) > 1e-4 * size, (n, q, size)


@pytest.mark.parametrize("family", ["trace", "rotation", "koiter"])
def test_unstressed_form_is_positive_semidefinite_and_positive_off_rigid_motions(family):
    """At unstressed points the 9x9 form has no negative eigenvalue (to 1e-12 of its largest);
    on the hemisphere (gamma = 1, beta = 1e-3) the integrated n = 2 energy of smooth fields that
    are not rigid is positive, and that of the tilt (n = 1) is 0 to 1e-10 of its terms."""
    res = variation("mooney_rivlin", family)
    rng = random.Random(5)
    with mp.workdps(30):
        for n in (0, 1, 2, 5):
            vals = random_point(rng, res, n, stress_free=True, pressure=0)
            M = mp.matrix(matrix_function("mooney_rivlin", family)(*[vals[s] for s in args_of(res)]))
            ev = mp.eigsy(M)[0]
            assert min(ev) > -1e-12 * max(abs(e) for e in ev), (n, ev)
    # integrate over the hemisphere's meridian, u, v, w smooth and zero-free at the pole as n = 2 needs
    sh = geometry.spheroid()
    ksR, ktR = sh.curvatures()
    ref = {sv.R_: sh.R, sv.PHI: sp.atan2(sp.diff(sh.Z, S), sp.diff(sh.R, S)), sv.LS_: 1, sv.KS_: ksR,
           sv.DLS: 0, sv.DKS: sp.diff(ksR, S), sv.RR: sh.R, sv.PSI_R: sh.Psi, sv.DPSI_R: sp.diff(sh.Psi, S),
           sv.KS0: ksR, sv.KT0: ktR}
    ref = {k: sp.sympify(v).subs(GAMMA, 1) for k, v in ref.items()}
    s_nodes, weights = np.polynomial.legendre.leggauss(60)
    s_nodes = (s_nodes + 1) * np.pi / 4
    weights = weights * np.pi / 4
    fM = matrix_function("mooney_rivlin", family, "numpy")
    base_fns = [sp.lambdify(S, ref[k], "numpy") for k in sv.BASE]

    def energy(n, u, v, w):
        fields = [sp.lambdify(S, sp.diff(f, S, k), "numpy") for f in (u, v, w) for k in range(3)]
        total, size = 0.0, 0.0
        for s, wt in zip(s_nodes, weights):
            M = np.array(fM(*[float(f(s)) for f in base_fns], 1e-3, 0.0, 0.23, n), dtype=float)
            z = np.array([float(f(s)) for f in fields])
            total += wt * z @ M @ z
            size += wt * np.abs(z) @ np.abs(M) @ np.abs(z)
        return total, size

    for u, v, w in ((0, 0, sp.sin(S) ** 2), (sp.sin(S) ** 2, 0, 0), (0, sp.sin(S) ** 2 * sp.cos(S), 0),
                    (sp.sin(S) ** 3, sp.sin(S) ** 2, sp.sin(2 * S) ** 2)):
        e, size = energy(2, u, v, w)
        assert e > 1e-3 * size, (u, v, w, e, size)
    # the tilt of the hemisphere (z = -cos S): u = z cos(phi) - r sin(phi) etc. with phi = S
    z = -sp.cos(S)
    e, size = energy(1, z * sp.cos(S) - sp.sin(S) * sp.sin(S), -z, -(z * sp.sin(S) + sp.sin(S) * sp.cos(S)))
    assert abs(e) < 1e-10 * size, (e, size)


# ------------------------------------------------------------------------------ closed form
@pytest.mark.parametrize("family,material", [("trace", "mooney_rivlin"), ("rotation", "gent"),
                                             ("koiter", "mooney_rivlin")])
def test_flat_membrane_under_equibiaxial_prestretch(family, material):
    """Flat disk stretched to r = lambda S (phi = 0, kappa = 0, R = S, Psi = 1): the w block of the
    form is S/4 [T (w'^2 + n^2 w^2/S^2) + beta c^2 (w'' + w'/S - n^2 w/S^2)^2], T the tension
    (1/lambda) dW/dlambda_s at (lambda, lambda), c = 1 (trace, koiter) or 1/lambda (rotation), and w does
    not couple to u, v (module docstring of the tests for the sources).  Koiter's energy adds
    ``-beta S (1 - nu) <det grad grad w>``, the theta-average of the Hessian's determinant in the
    reference polar coordinates, ``(1/2) [w'' (w'/S - n^2 w/S^2) - n^2 (w'/S - w/S^2)^2]`` (Kirchhoff's
    Gaussian-curvature term; the prestretch does not enter it, as it does not the trace's).  Checked
    symbolically in lambda, S, n, w, w', w'' at beta, pressure 0 and the material parameter fixed."""
    res = variation(material, family)
    lam, s = sp.symbols("lambda S_", positive=True)
    W, par = MATERIALS[material]
    T = (sp.diff(W, LS) / LT).subs({LS: lam, LT: lam})
    at = {sv.R_: lam * s, sv.PHI: 0, sv.LS_: lam, sv.KS_: 0, sv.DLS: 0, sv.DKS: 0, sv.RR: s, sv.PSI_R: 1,
          sv.DPSI_R: 0, sv.KS0: 0, sv.KT0: 0, PRESSURE: 0, **{p: sp.Rational(23, 100) if p == ALPHA else 6
                                                            for p in par}}
    M = res.matrix.xreplace(at)
    w_block = [6, 7, 8]
    for i in w_block:
        for j in range(6):
            assert sp.simplify(M[i, j]) == 0, (i, j, M[i, j])
    w, dw, ddw = sv.FIELDS[6:]
    n = sv.N_MODE
    c = 1 / lam if family == "rotation" else 1
    want = s / 4 * (T.subs({p: at[p] for p in par}) * (dw**2 + n**2 * w**2 / s**2)
                    + BETA * c**2 * (ddw + dw / s - n**2 * w / s**2) ** 2)
    if family == "koiter":
        det = (ddw * (dw / s - n**2 * w / s**2) - n**2 * (dw / s - w / s**2) ** 2) / 2
        want -= BETA * s * (1 - bending.KOITER_POISSON) * det
    z = sp.Matrix(sv.FIELDS[6:])
    got = (z.T * M[6:, 6:] * z)[0, 0]
    assert sp.simplify(got - want) == 0


def test_harmonic_deflection_of_a_flat_plate_costs_nothing():
    """A documented property, not a wish: with bending Poisson ratio 1 (the trace and rotation
    energies, ``bending.plate_limit``) the 2D bending energy is (Laplacian w)^2/2 on a flat unstressed plate,
    so w = S^n cos(n theta) (harmonic) has zero second variation, for n = 2 and 3: on a flat
    region only a tension resists such modes."""
    for family in ("trace", "rotation"):
        res = variation("mooney_rivlin", family)
        s = sp.Symbol("S_", positive=True)
        at = {sv.R_: s, sv.PHI: 0, sv.LS_: 1, sv.KS_: 0, sv.DLS: 0, sv.DKS: 0, sv.RR: s, sv.PSI_R: 1,
              sv.DPSI_R: 0, sv.KS0: 0, sv.KT0: 0, PRESSURE: 0, ALPHA: sp.Rational(23, 100)}
        for n in (2, 3):
            w = s**n
            fields = [0, 0, 0, 0, 0, 0, w, sp.diff(w, s), sp.diff(w, s, 2)]
            q = res.quadratic_form().xreplace(at).xreplace(dict(zip(sv.FIELDS, fields))).subs(sv.N_MODE, n)
            assert sp.simplify(q) == 0, (family, n, q)
            w = s**n + s ** (n + 2)  # not harmonic: positive
            fields = [0, 0, 0, 0, 0, 0, w, sp.diff(w, s), sp.diff(w, s, 2)]
            q = res.quadratic_form().xreplace(at).xreplace(dict(zip(sv.FIELDS, fields))).subs(sv.N_MODE, n)
            assert sp.simplify(q).subs(s, sp.Rational(1, 2)) > 0


def test_harmonic_deflection_costs_the_gaussian_terms_energy_with_koiters():
    """With Koiter's energy (bending Poisson ratio 1/2) the same harmonic w = S^n cos(n theta) on a
    flat unstressed plate costs ``beta S (1 - nu) |grad grad w|^2/2`` per dS dtheta, Kirchhoff's
    ``-D (1 - nu) det grad grad w`` with Laplacian w = 0 and ``|grad grad w|^2 = 2 n^2 (n - 1)^2
    S^(2n - 4)`` (w = Re z^n): ``beta n^2 (n - 1)^2 S^(2n - 3)/2``, exactly, for n = 2 and 3;
    the trace energy's is 0 (the test above)."""
    res = variation("mooney_rivlin", "koiter")
    s = sp.Symbol("S_", positive=True)
    at = {sv.R_: s, sv.PHI: 0, sv.LS_: 1, sv.KS_: 0, sv.DLS: 0, sv.DKS: 0, sv.RR: s, sv.PSI_R: 1,
          sv.DPSI_R: 0, sv.KS0: 0, sv.KT0: 0, PRESSURE: 0, ALPHA: sp.Rational(23, 100)}
    for n in (2, 3):
        w = s**n
        fields = [0, 0, 0, 0, 0, 0, w, sp.diff(w, s), sp.diff(w, s, 2)]
        q = res.quadratic_form().xreplace(at).xreplace(dict(zip(sv.FIELDS, fields))).subs(sv.N_MODE, n)
        want = BETA * n**2 * (n - 1) ** 2 * s ** (2 * n - 3) / 2
        assert sp.simplify(q - want) == 0, (n, q)
        assert sp.simplify(q) != 0


def test_modes_decouple_at_n0():
    """At n = 0 the torsion v does not couple to (u, w) (their coupling terms carry a factor n),
    while at n = 1 it does: at a random stressed point with pressure."""
    res = variation("mooney_rivlin", "trace")
    rng = random.Random(2)
    with mp.workdps(30):
        for n in (0, 1):
            vals = random_point(rng, res, n)
            M = mp.matrix(matrix_function("mooney_rivlin", "trace")(*[vals[s] for s in args_of(res)]))
            coupling = max(abs(M[i, j]) for i in (3, 4, 5) for j in (0, 1, 2, 6, 7, 8))
            size = max(abs(M[i, j]) for i in range(9) for j in range(9))
            assert (coupling < 1e-28 * size) if n == 0 else (coupling > 1e-3 * size), (n, coupling, size)


def test_pressure_part_on_a_closed_sphere():
    """The pressure's part of the form (d/dp of the matrix) on the unit sphere (R = sin S,
    Z = -cos S, 0 < S < pi, N inward), for a normal field w cos(n theta): the second variation
    of the volume for a normal displacement is ``Int H w^2 dA`` (H the mean curvature; the swept
    volume of the normal segments, exact to second order), so with the package's V (negative for
    this orientation) the eta^2 term of -p V is ``p Int w^2 cos^2(n theta) dA``, i.e.
    ``Int_0^pi zeta^T dM/dp zeta dS = 1/2 Int_0^pi w^2 sin S dS`` for n >= 1.  w = sin(S)^2, n = 2
    and 3, Gauss-Legendre with 40 nodes (the integrand is a trigonometric polynomial)."""
    res = variation("mooney_rivlin", "trace")
    dM = sp.lambdify(args_of(res), sp.diff(res.matrix, PRESSURE), "numpy", cse=True)
    x, wts = np.polynomial.legendre.leggauss(40)
    x, wts = (x + 1) * np.pi / 2, wts * np.pi / 2
    w = sp.sin(S) ** 2
    fw = [sp.lambdify(S, sp.diff(w, S, k), "numpy") for k in range(3)]
    for n in (2, 3):
        total = 0.0
        for s, wt in zip(x, wts):
            base = {sv.R_: np.sin(s), sv.PHI: s, sv.LS_: 1.0, sv.KS_: 1.0, sv.DLS: 0.0, sv.DKS: 0.0,
                    sv.RR: np.sin(s), sv.PSI_R: 1.0, sv.DPSI_R: 0.0, sv.KS0: 1.0, sv.KT0: 1.0,
                    BETA: 0.1, PRESSURE: 0.0, ALPHA: 0.2, sv.N_MODE: n}
            M = np.array(dM(*[base[k] for k in args_of(res)]), dtype=float)
            z = np.zeros(9)
            z[6:] = [f(s) for f in fw]
            total += wt * z @ M @ z
        want = 0.5 * float(sp.integrate(w**2 * sp.sin(S), (S, 0, sp.pi)))
        assert abs(total - want) < 1e-12 * want, (n, total, want)


def _brute_force_second_order(material, family, n, S0, fields, meridian, gamma, params, swap=False):
    """(``swap``: u, w along sin(n theta) and v along cos(n theta).)  The theta-average of the eta^2 coefficient of L at S0 for x = x0 + eta dx written out in
    Cartesian coordinates (no series, no rotation to theta = 0, no parity trick): L through
    ``surface_energy_density`` on plain expressions, the eta^2 coefficient by mpmath's
    differentiation, the average by the trapezoidal rule (exact for the degree-2 trigonometric
    polynomial in n theta)."""
    W, _ = MATERIALS[material]
    th, eta = sp.symbols("theta_ eta_", real=True)
    r, z = meridian
    sh = geometry.spheroid()
    ksR, ktR = (k.subs(GAMMA, gamma) for k in sh.curvatures())
    rp, zp = sp.diff(r, S), sp.diff(z, S)
    psi = sp.sqrt(rp**2 + zp**2)
    t = sp.Matrix([rp / psi * sp.cos(th), rp / psi * sp.sin(th), zp / psi])
    N = sp.Matrix([-zp / psi * sp.cos(th), -zp / psi * sp.sin(th), rp / psi])
    eth = sp.Matrix([-sp.sin(th), sp.cos(th), 0])
    u, v, w = fields
    even, odd = (sp.sin(n * th), sp.cos(n * th)) if swap else (sp.cos(n * th), sp.sin(n * th))
    x = (sp.Matrix([r * sp.cos(th), r * sp.sin(th), z])
         + eta * (u * even * t + v * odd * eth + w * even * N))
    jets = {"x": list(x), "xS": list(x.diff(S)), "xT": list(x.diff(th)), "xSS": list(x.diff(S, 2)),
            "xST": list(x.diff(S, th)), "xTT": list(x.diff(th, 2))}
    ref = {"R": sh.R.subs(GAMMA, gamma), "Psi": sh.Psi.subs(GAMMA, gamma), "kappa_s0": ksR, "kappa_theta0": ktR}
    L = sv.surface_energy_density(jets, ref, sv.membrane_energy(W), family)
    f = sp.lambdify((S, th, eta, *params), L, "mpmath", cse=True)
    pv = list(params.values())
    m = 4 * n + 3
    return mp.fsum(mp.diff(lambda e: f(S0, 2 * mp.pi * k / m, e, *pv), 0, 2) / 2 for k in range(m)) / m


@pytest.mark.parametrize("material,family", [("mooney_rivlin", "trace"),
                                             pytest.param("gent", "rotation", marks=pytest.mark.slow)])
def test_form_against_a_brute_force_expansion(material, family):
    """The 9x9 form at a point of a stressed meridian (not a solution; pressure on) against the
    brute-force theta-average of the eta^2 coefficient (``_brute_force_second_order``), for n = 0,
    2, 3 and fields with all three components: to 1e-25 relative (30 digits; they agree to ~30)."""
    res = variation(material, family)
    rng = random.Random(13)
    g, r, z = _meridian(rng)
    base = _base_along(g, r, z)
    fields = (sp.sin(S) * (1 + S), S**2 - S**3 / 3, sp.cos(2 * S) + S)
    params = {BETA: mp.mpf("0.2"), PRESSURE: mp.mpf("0.4"), **{k: mp.mpf(v) for k, v in MATERIAL_VALUES.items()
                                                             if k in res.params}}
    with mp.workdps(30):
        for n in (0, 2, 3):
            S0 = mp.mpf("0.83")
            bv = {k: f(S0) for k, f in base.items()}
            M = mp.matrix(matrix_function(material, family)(*[bv[k] for k in sv.BASE],
                                                            *[params[p] for p in res.params], n))
            zeta = [sp.lambdify(S, sp.diff(f, S, k), "mpmath")(S0) for f in fields for k in range(3)]
            q = mp.fsum(M[i, j] * zeta[i] * zeta[j] for i in range(9) for j in range(9))
            if n == 0:  # the polynomial at n = 0 is half the energy of theta-independent (u, w) and v
                want = (_brute_force_second_order(material, family, 0, S0, (fields[0], 0, fields[2]), (r, z), g,
                                                  params)
                                + _brute_force_second_order(material, family, 0, S0, (0, fields[1], 0), (r, z), g,
                                                    params, swap=True)) / 2
            else:
                want = _brute_force_second_order(material, family, n, S0, fields, (r, z), g, params)
            assert abs(q - want) < 1e-25 * abs(want), (n, q, want)


@pytest.mark.parametrize("material", ["mooney_rivlin", "gent"])
def test_flat_disk_in_plane_block_is_plane_stress_elasticity(material):
    """Unstressed flat disk: the (u, v) block is the linear plane-stress energy of an
    incompressible sheet (nu = 1/2, E = 3 mu, mu = 1), ``2 (e_rr^2 + e_tt^2 + e_rr e_tt) + 2 e_rt^2``
    (Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed. 1970, plane stress strain energy
    ``E/(2(1 - nu^2)) (e_rr^2 + e_tt^2 + 2 nu e_rr e_tt) + 2 mu e_rt^2``), with
    ``e_rr = u'``, ``e_tt = (u + n v)/S``, ``e_rt = (v' - v/S - n u/S)/2`` (amplitudes of cos, cos,
    sin), theta-averaged (1/2) and times the area element S; and u, v do not couple to w."""
    res = variation(material, "trace")
    s = sp.Symbol("S_", positive=True)
    at = {sv.R_: s, sv.PHI: 0, sv.LS_: 1, sv.KS_: 0, sv.DLS: 0, sv.DKS: 0, sv.RR: s, sv.PSI_R: 1,
          sv.DPSI_R: 0, sv.KS0: 0, sv.KT0: 0, PRESSURE: 0, ALPHA: sp.Rational(23, 100), JM: 6}
    M = res.matrix.xreplace(at)
    u, du, ddu, v, dv, ddv = sv.FIELDS[:6]
    n = sv.N_MODE
    err, ett, ert = du, (u + n * v) / s, (dv - v / s - n * u / s) / 2
    want = s / 2 * (2 * (err**2 + ett**2 + err * ett) + 2 * ert**2)
    z = sp.Matrix(sv.FIELDS[:6])
    assert sp.simplify((z.T * M[:6, :6] * z)[0, 0] - want) == 0
    assert all(sp.simplify(M[i, j]) == 0 for i in range(6) for j in (6, 7, 8))


def test_structures_and_xi():
    """A structure's form is that of its W, B and pressure; xi = 0 is refused."""
    W, par = MATERIALS["mooney_rivlin"]
    st = Structure(W=W, material_params=par, shell=geometry.spheroid(), tip=geometry.sphere_tip(), xi=1,
                   pressurised=True)
    assert sv.second_variation_of(st) is variation("mooney_rivlin", "trace")
    with pytest.raises(ValueError, match="xi = 0"):
        sv.second_variation_of(Structure(W=W, material_params=par, shell=geometry.spheroid(),
                                         tip=geometry.sphere_tip(), xi=0))
