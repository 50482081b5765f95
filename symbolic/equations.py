r"""The shell's equations, derived from the energy, as straight-line programs.

Everything follows from the kinematics and the energy density

.. math:: U = W(\lambda_s, \lambda_\theta) + \beta B, \quad
          B = \tfrac12(\operatorname{tr}\Delta)^2,
          \quad \operatorname{tr}\Delta = \lambda_s^2\kappa_s + \lambda_\theta^2\kappa_\theta
          - \kappa_s^R - \kappa_\theta^R
          \text{ (the paper's; other bending energies B: symbolic.bending)},

with ``T_s = (1/lambda_theta) dW/dlambda_s``, ``T_theta = (1/lambda_s) dW/dlambda_theta``,
``M_alpha = h dU/dkappa_alpha`` (``h = 1/(lambda_s lambda_theta)``) and the generalised
tensions ``tau_alpha = T_alpha + xi M_alpha kappa_alpha``; the equilibrium equations are
the paper's (eq. equibshell), with ``P`` the load of a pressure ``p`` below the shell off
the indenter (:func:`pressure_load`; 0 by default).

State layout (one place; the solver and the tests import these tuples)
---------------------------------------------------------------------
Both regions are written as ``g = S dy/dS`` (the solver maps S geometrically
onto t in [0, 1], so ``dy/dt = (d ln S/dt) g``), in O(1)-scaled states:

* free region, ``Sc < S < L``  -- ``FREE_STATES``:
  ``lt = r/R``, ``phiS = phi/S``, ``ls = lambda_s``, ``ks = kappa_s``, ``rQ = r Q``, ``z``.
* contact region, ``zeta < S < Sc`` -- ``CONTACT_STATES``:
  ``chi = rho omega/S``, ``ls = lambda_s``  (omega: the tip's angle parameter).

Conditions (residuals; all O(1)-scaled):

* pole (S = zeta, leading order of the odd series of omega): 2;
* rim (S = L, simply supported): ``lt - 1``, ``tr Delta`` (``M_s = 0`` divided by
  ``beta lambda_s/lambda_theta``; for another bending energy ``dB/dkappa_s``), ``z``: 3;
* contact line, smooth (variational) model: r, phi, z, lambda_s, kappa_s continuous
  (so M_s and tau_s are; Q may jump): 5;
* contact line, paper model (eq. jumpeqns2): r, phi, z, Q and tau_s continuous
  (``[F] = r sin(phi)[tau_s]`` given the others; tau_s is the well-scaled form): 5;
* force control: ``F/(2 pi)`` of the free region minus the prescribed value: 1.
* regular pole of a free cap (lift-off topologies): isotropic stretch,
  ``phi/S = psi kappa_s``, zero axial force: 3.

Counting: 8 ODEs (2 contact + 6 free) plus k unknown parameters need 8 + k
conditions.  The pole (2) + rim (3) + contact line (5) give 10 = 8 + 2: the
unknown ``ln Sc`` plus one of ``lambda0`` (delta prescribed) or ``delta``
(lambda0 prescribed).  Force control adds the force condition and has
k = 3 unknowns (``ln Sc``, ``lambda0``, ``delta``): 11 = 8 + 3.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from . import bending
from .dag import Program
from .geometry import OMEGA, S, ShellGeometry, TipGeometry, cylinder_of, flat_tip
from .materials import LS, LT

__all__ = [
    "FREE_STATES",
    "CONTACT_STATES",
    "Structure",
    "Derivation",
    "derive",
]

FREE_STATES = ("lt", "phiS", "ls", "ks", "rQ", "z")
CONTACT_STATES = ("chi", "ls")
CONTACT_MODELS = ("smooth", "paper")

BETA, RHO = sp.symbols("beta rho", positive=True)
#: Pressure below the shell (the side away from the indenter; > 0 pushes the shell towards
#: it: a dome or cell inflated from inside), ``p R_L/(mu H)``; and the pole's rise under it
#: (the inflated pole is at ``Z(0) + pole_rise``; delta is measured from there).
PRESSURE, POLE_RISE = sp.symbols("pressure pole_rise", real=True)
SC = sp.Symbol("Sc", positive=True)
LAMBDA0, DELTA, FORCE = sp.symbols("lambda0 delta F", real=True)


@dataclass(frozen=True)
class Structure:
    """The structural choices a generated module is specialised on.

    ``W`` is the strain energy in ``materials.LS, LT`` and ``material_params``;
    shell and tip are geometries; ``xi`` in {0, 1}; ``B`` the bending energy per beta in
    ``symbolic.bending``'s symbols (None: the paper's, ``trace_bending``).
    """

    W: sp.Expr
    material_params: tuple
    shell: ShellGeometry
    tip: TipGeometry
    xi: int
    B: sp.Expr | None = None
    pressurised: bool = False
    substrate: bool = False  # a closed shell on a rigid plane: its lower half's contact ("plane")
    #: The wall's thickness relative to the pole's, t(S) (``geometry.thickness_profile``): the
    #: energy per reference area is ``t W + beta t^3 B``; None: uniform (no such terms generated).
    thickness: sp.Expr | None = None

    @property
    def params(self) -> tuple:
        """Run-time parameters, in the order the generated functions take them (the pressure
        and the inflated pole's rise only where there is a pressure)."""
        extra = (PRESSURE, POLE_RISE) if self.pressurised else ()
        return (BETA, RHO) + extra + tuple(self.shell.params) + tuple(self.material_params)

    @property
    def pressure(self):
        """The pressure, or 0 in a structure without one (its terms are then not generated)."""
        return PRESSURE if self.pressurised else sp.S.Zero

    @property
    def pole_rise(self):
        return POLE_RISE if self.pressurised else sp.S.Zero


def pressure_load():
    r"""The follower load of the pressure, from the variation of its potential ``-p V``.

    ``V = -pi Int r^2 z' dS`` is the volume between the shell and its rim's plane, signed
    so that it grows as the shell moves towards the indenter's side (up).  The force per
    reference length is ``-dPi/dx`` (Euler-Lagrange of ``Pi = -p V`` in r and z); its
    component along the normal in which the contact pressure P counts positive,
    ``(sin phi, -cos phi)``, per deformed area ``2 pi r psi``, is the load in the normal
    balance's ``P``.  The potential does not depend on z itself, so axial translation
    leaves it invariant and it adds ``dPi/dz' / (2 pi)`` to the axial first integral
    F(S)/(2 pi) (Noether; the paper's F(S), eq. Flaw, with the pressure on the cap
    inside S).  Returns ``(load, volume density, axial force / (2 pi))``: ``-p`` (a uniform
    pressure), ``-pi r^2 z'`` and ``p r^2/2``, over the symbols ``r, phi, psi``.
    """
    r, z = sp.Function("r")(S), sp.Function("z")(S)
    rr, phi, psi = sp.symbols("r phi psi")
    v = -sp.pi * r**2 * sp.diff(z, S)
    forces = [-eq.lhs for eq in sp.euler_equations(-PRESSURE * v, [r, z], S)]
    on_shell = {sp.diff(r, S): psi * sp.cos(phi), sp.diff(z, S): psi * sp.sin(phi)}
    fr, fz = (f.subs(on_shell).subs(r, rr) for f in forces)
    load = sp.simplify((fr * sp.sin(phi) - fz * sp.cos(phi)) / (2 * sp.pi * rr * psi))
    if load.free_symbols != {PRESSURE}:
        raise AssertionError(f"pressure load is not uniform: {load}")
    if sp.diff(v, z) != 0:
        raise AssertionError("the pressure's potential depends on z: no axial first integral")
    axial = sp.diff(-PRESSURE * v, sp.diff(z, S)).subs(r, rr) / (2 * sp.pi)
    return load, v.subs(on_shell).subs(r, rr), sp.simplify(axial)


PRESSURE_LOAD, _VOLUME_DENSITY, _PRESSURE_AXIAL_FORCE = pressure_load()


def volume_density(r, phi, psi):
    """``dV/dS = -pi r^2 psi sin(phi)`` (see :func:`pressure_load`)."""
    return _VOLUME_DENSITY.xreplace(dict(zip(sp.symbols("r phi psi"), (r, phi, psi))))


def pressure_axial_force(r, pressure):
    """The pressure's part of F(S)/(2 pi), ``p r^2/2`` (see :func:`pressure_load`)."""
    return _PRESSURE_AXIAL_FORCE.xreplace({sp.Symbol("r"): r, PRESSURE: pressure})


class Derivation:
    """All programs of one structure: physical sub-derivations and scaled systems.

    Attributes (each a :class:`~symbolic.dag.Program` plus named outputs):
    ``free``, ``contact``, ``pole``, ``rim``, ``junction``.
    """

    def __init__(self, st: Structure):
        if st.xi not in (0, 1):
            raise ValueError(f"xi must be 0 or 1; got {st.xi}")
        self.structure = st
        self.params = st.params
        self._build_free_physical()
        self.contact_phys, self.contact_phys_out = self._contact_physical(st.tip)
        self._build_free_scaled()
        self.contact, self.contact_states, self.contact_rhs, self.contact_profile = self._contact_scaled(
            self.contact_phys, self.contact_phys_out)
        self._build_boundaries()
        (self.junction, self.junction_inputs, self.junction_res,
         self.force_res) = self._edge(self.contact, self.contact_profile, self.contact_phys_out,
                                      pin_at=st.tip.omega_max)
        # The indenter's cylinder r = rho A(omega_max): the same contact equations on the
        # continuation of the tip past its end (kappa_s = 0), its edge to a free region, and
        # the junction where the shell passes from the tip onto it.
        self.has_cylinder = st.tip.omega_max is not None
        if self.has_cylinder:
            self.cylinder_phys, self.cylinder_phys_out = self._contact_physical(cylinder_of(st.tip))
            self.cylinder, self.cylinder_states, self.cylinder_rhs, self.cylinder_profile = self._contact_scaled(
                self.cylinder_phys, self.cylinder_phys_out)
            (self.cyl_junction, self.cyl_junction_inputs, self.cyl_junction_res,
             self.cyl_force_res) = self._edge(self.cylinder, self.cylinder_profile, self.cylinder_phys_out)
            self._build_tip_end()
        # A closed shell on a substrate: its lower half, from the lower pole, touches a rigid
        # plane (a flat tip that does not move: its edges are evaluated at delta = 0).
        self.has_plane = st.substrate
        if self.has_plane:
            self.plane_phys, self.plane_phys_out = self._contact_physical(flat_tip())
            self.plane, self.plane_states, self.plane_rhs, self.plane_profile = self._contact_scaled(
                self.plane_phys, self.plane_phys_out)
            (self.plane_junction, self.plane_junction_inputs, self.plane_junction_res,
             self.plane_force_res) = self._edge(self.plane, self.plane_profile, self.plane_phys_out)
            chi0, ls0 = self.pole_states
            dR0 = sp.diff(st.shell.R, S).subs(S, 0)
            self.plane_pole = Pp = Program([chi0, ls0, LAMBDA0, *self.params])
            self.plane_pole_res = [Pp.let("res_chi", chi0 - LAMBDA0 * dR0), Pp.let("res_ls", ls0 - LAMBDA0)]
        self._build_geometry()
        self._build_point_load()
        self._build_free_pole()
        self._build_kink()

    # ------------------------------------------------------------------ shared pieces
    def _shell_steps(self, prog: Program, Svar, tag=""):
        sh = self.structure.shell
        ksR, ktR = sh.curvatures()
        sub = {S: Svar}
        out = {
            "R": prog.let(f"R{tag}", sh.R.xreplace(sub)),
            "dR": prog.let(f"dR{tag}", sp.diff(sh.R, S).xreplace(sub)),
            "Psi": prog.let(f"Psi{tag}", sh.Psi.xreplace(sub)),
            "ksR": prog.let(f"ksR{tag}", ksR.xreplace(sub)),
            "ktR": prog.let(f"ktR{tag}", ktR.xreplace(sub)),
        }
        if self.structure.thickness is not None:
            out["thk"] = prog.let(f"thk{tag}", self.structure.thickness.xreplace(sub))
        return out

    def _constitutive(self, prog: Program, ls, lt, ks, kt, ksR, ktR, tag="", thk=None):
        """T, M, tau and U from W and the bending energy; names get suffix ``tag``.

        ``m`` is what the rim's ``M_s = 0`` sets to zero: ``tr Delta`` for the paper's bending
        energy (written through it, as the paper does), ``dB/dkappa_s`` for any other.
        ``thk``: the local thickness over the pole's (a profiled wall): the membrane energy
        scales with it, the bending stiffness with its cube (``t W + beta t^3 B``).
        """
        st = self.structure
        KS, KT = bending.KS, bending.KT
        h = 1 / (LS * LT)
        sub = {LS: ls, LT: lt, KS: ks, KT: kt}
        t = sp.S.One if thk is None else thk
        beta = BETA * t**3
        T_s = prog.let(f"T_s{tag}", (t * sp.diff(st.W, LS) / LT).xreplace(sub))
        T_t = prog.let(f"T_t{tag}", (t * sp.diff(st.W, LT) / LS).xreplace(sub))
        W = prog.let(f"W{tag}", (t * st.W).xreplace(sub))
        if st.B is None:  # the paper's (tr Delta)^2/2
            tr_delta = LS**2 * KS + LT**2 * KT - ksR - ktR
            U = t * st.W + beta / 2 * tr_delta**2
            m = prog.let(f"m{tag}", tr_delta.xreplace(sub))

            def as_m(expr):  # write moments through the named bending strain m
                return expr.xreplace(sub).subs(tr_delta.xreplace(sub), m)

            M_s = prog.let(f"M_s{tag}", as_m(h * sp.diff(U, KS)))
            M_t = prog.let(f"M_t{tag}", as_m(h * sp.diff(U, KT)))
            U_ = prog.let(f"U{tag}", W + beta / 2 * m**2)
            tau_s = prog.let(f"tau_s{tag}", T_s + st.xi * M_s * ks)
            tau_t = prog.let(f"tau_t{tag}", T_t + st.xi * M_t * kt)
        else:
            # The generalised tensions of the energy: r tau_s = R Psi dU/dpsi at fixed phi' (and
            # the hoop one from dU/dr at fixed phi), i.e. tau_a = (dU/dlambda_a - dU/dkappa_a
            # kappa_a/lambda_a)/lambda_b.  For the paper's B the bending part is M_a kappa_a (the
            # branch above); for another it is not, and M kappa would break F = dE/ddelta.
            B = st.B.xreplace({bending.KS0: ksR, bending.KT0: ktR})
            m = prog.let(f"m{tag}", sp.diff(B, KS).xreplace(sub))
            M_s = prog.let(f"M_s{tag}", (h * beta).xreplace(sub) * m)
            M_t = prog.let(f"M_t{tag}", (h * beta * sp.diff(B, KT)).xreplace(sub))
            U_ = prog.let(f"U{tag}", W + beta * B.xreplace(sub))
            bend_s = beta * (sp.diff(B, LS) - sp.diff(B, KS) * KS / LS) / LT
            bend_t = beta * (sp.diff(B, LT) - sp.diff(B, KT) * KT / LT) / LS
            tau_s = prog.let(f"tau_s{tag}", T_s + st.xi * bend_s.xreplace(sub))
            tau_t = prog.let(f"tau_t{tag}", T_t + st.xi * bend_t.xreplace(sub))
        return dict(m=m, T_s=T_s, T_t=T_t, M_s=M_s, M_t=M_t, tau_s=tau_s, tau_t=tau_t, W=W, U=U_)

    @property
    def _pressure_load(self):
        return PRESSURE_LOAD.xreplace({PRESSURE: self.structure.pressure})

    def _indenter_force(self, r, sin_phi, cos_phi, tau_s, Q):
        """F(S)/(2 pi): the shell's axial force ``r sin(phi) tau_s - r cos(phi) Q`` plus the
        pressure's axial force on the cap inside S, ``p r^2/2`` (derived: :func:`pressure_load`;
        the paper's F(S), eq. Flaw: constant over a free region; the indenter's force at a
        contact edge)."""
        return r * sin_phi * tau_s - r * cos_phi * Q + pressure_axial_force(r, self.structure.pressure)

    @staticmethod
    def _eshelby(prog: Program, U, ls):
        """``lambda_s dU/dlambda_s - U`` (at fixed kappa_s): times R Psi, the Hamiltonian of
        E = 2 pi Int U R Psi dS, continuous where S may move (an edge, the tip's end, a corner)."""
        return ls * prog.derivative(U, ls) - U

    def _tip_steps(self, prog: Program, omega, tip, tag=""):
        d = tip.derived()
        sub = {OMEGA: omega}
        return {k: prog.let(f"tip_{k}{tag}", v.xreplace(sub)) for k, v in d.items()}

    # ------------------------------------------------------------------ free region
    def _build_free_physical(self):
        """Free region over the physical variables (S, r, phi, ls, ks, Q).

        Equilibrium (paper eq. equibshell, P the pressure's normal load, ``PRESSURE_LOAD``):
        (r tau_s)' - r' tau_theta + kappa_s r Q psi = 0,
        kappa_s tau_s + kappa_theta tau_theta - (r Q)'/(r psi) = P,
        (r M_s)' - r' M_theta - r Q psi = 0.
        The first and third are linear in (lambda_s', kappa_s'): a 2x2 system
        whose coefficients are partial derivatives of tau_s and M_s.
        """
        r, phi, ls, ks, Q = sp.symbols("r phi ls ks Q")
        A = Program([S, r, phi, ls, ks, Q, *self.params])
        g = self._shell_steps(A, S)
        lt = A.let("lt", r / g["R"])
        kt = A.let("kt", sp.sin(phi) / r)
        psi = A.let("psi", ls * g["Psi"])
        c = self._constitutive(A, ls, lt, ks, kt, g["ksR"], g["ktR"], thk=g.get("thk"))
        dr = A.let("dr", psi * sp.cos(phi))
        dphi = A.let("dphi", psi * ks)

        def split(f):  # f' = f_ls ls' + f_ks ks' + rest
            rest = A.derivative(f, r) * dr + A.derivative(f, phi) * dphi + A.derivative(f, S)
            return A.derivative(f, ls), A.derivative(f, ks), rest

        ts_ls, ts_ks, ts_rest = split(c["tau_s"])
        ms_ls, ms_ks, ms_rest = split(c["M_s"])
        a11 = A.let("a11", r * ts_ls)
        a12 = A.let("a12", r * ts_ks)
        b1 = A.let("b1", -(r * ts_rest + dr * (c["tau_s"] - c["tau_t"]) + ks * r * Q * psi))
        a21 = A.let("a21", r * ms_ls)
        a22 = A.let("a22", r * ms_ks)
        b2 = A.let("b2", -(r * ms_rest + dr * (c["M_s"] - c["M_t"]) - r * Q * psi))
        det = A.let("det", a11 * a22 - a12 * a21)
        dls = A.let("dls", (b1 * a22 - a12 * b2) / det)
        dks = A.let("dks", (a11 * b2 - a21 * b1) / det)
        dQ = A.let("dQ", psi * (ks * c["tau_s"] + kt * c["tau_t"] - self._pressure_load) - dr * Q / r)
        dz = A.let("dz", psi * sp.sin(phi))
        G = A.let("G", self._indenter_force(r, sp.sin(phi), sp.cos(phi), c["tau_s"], Q))
        self.free_phys = A
        self.free_phys_vars = (r, phi, ls, ks, Q)
        self.free_phys_out = dict(c, lt=lt, kt=kt, psi=psi, dr=dr, dphi=dphi, dls=dls, dks=dks,
                                  dQ=dQ, dz=dz, G=G, **g)

    def _build_free_scaled(self):
        ys = sp.symbols(" ".join(FREE_STATES))
        lt, phiS, ls, ks, rQ, z = ys
        P = Program([S, *ys, *self.params])
        sh = self.structure.shell
        r = P.let("r", lt * sh.R, always=True)
        phi = P.let("phi", S * phiS, always=True)
        P.let("Q", rQ / r, always=True)
        P.extend(self.free_phys, skip_defined=True)
        o = self.free_phys_out
        g = [
            S * (o["dr"] - lt * o["dR"]) / o["R"],
            o["dphi"] - phiS,
            S * o["dls"],
            S * o["dks"],
            S * (o["dr"] * sp.Symbol("Q") + r * o["dQ"]),
            S * o["dz"],
        ]
        self.free = P
        self.free_states = ys
        self.free_rhs = [P.let(f"g_{n}", e) for n, e in zip(FREE_STATES, g)]
        self.free_profile = {
            "r": r, "z": z, "phi": phi, "lambda_s": ls, "lambda_theta": lt,
            "kappa_s": ks, "kappa_theta": o["kt"], "T_s": o["T_s"], "T_theta": o["T_t"],
            "M_s": o["M_s"], "M_theta": o["M_t"], "tau_s": o["tau_s"], "tau_theta": o["tau_t"],
            "Q": sp.Symbol("Q"), "P": sp.S.Zero, "axial_force_2pi": o["G"],
            "energy_density": o["U"] * o["R"] * o["Psi"],
            "volume_density": volume_density(r, phi, o["psi"]),
        }
        if "thk" in o:  # a profiled wall: its thickness over the pole's
            self.free_profile["thickness"] = o["thk"]

    # ------------------------------------------------------------------ contact region
    def _contact_physical(self, tip: TipGeometry):
        """Contact region over (S, omega, ls): r, z on the tip, omega(S) unknown.

        With Q eliminated by the moment balance, the tangential balance
        ``(r tau_s)' - r' tau_theta + kappa_s[(r M_s)' - r' M_theta] = 0`` is linear
        in lambda_s' (a second-order ODE for omega).  The normal balance then
        gives the contact pressure P.
        """
        omega, ls = sp.symbols("omega ls")
        C = Program([S, omega, ls, *self.params])
        g = self._shell_steps(C, S)
        t = self._tip_steps(C, omega, tip)
        r = C.let("r", RHO * t["A"])
        lt = C.let("lt", r / g["R"])
        ks = C.let("ks", t["rho_ks"] / RHO)
        kt = C.let("kt", t["rho_kt"] / RHO)
        psi = C.let("psi", ls * g["Psi"])
        c = self._constitutive(C, ls, lt, ks, kt, g["ksR"], g["ktR"], thk=g.get("thk"))
        domega = C.let("domega", ls * g["Psi"] / (RHO * t["G"]))
        dr = C.let("dr", psi * t["cos_phi"])

        def split(f):
            return C.derivative(f, ls), C.derivative(f, omega) * domega + C.derivative(f, S)

        ts_ls, ts_rest = split(c["tau_s"])
        ms_ls, ms_rest = split(c["M_s"])
        num = -(r * ts_rest + dr * (c["tau_s"] - c["tau_t"]) + ks * (r * ms_rest + dr * (c["M_s"] - c["M_t"])))
        dls = C.let("dls", num / (r * (ts_ls + ks * ms_ls)))
        rQ = C.let("rQ", (r * (ms_ls * dls + ms_rest) + dr * (c["M_s"] - c["M_t"])) / psi)
        Q = C.let("Q", rQ / r)
        G = C.let("G", self._indenter_force(r, t["sin_phi"], t["cos_phi"], c["tau_s"], Q))
        # The indenter's pressure from the normal balance, less the pressure's own load
        # (the indenter carries it here); (rQ)' is a total derivative along the solution.
        drQ = C.derivative(rQ, S) + C.derivative(rQ, omega) * domega + C.derivative(rQ, ls) * dls
        P = C.let("P", ks * c["tau_s"] + kt * c["tau_t"] - drQ / (r * psi) - self._pressure_load)
        return C, dict(c, **g, tip=t, r=r, dr=dr, lt=lt, ks=ks, kt=kt, psi=psi,
                       domega=domega, dls=dls, rQ=rQ, Q=Q, G=G, P=P)

    def _contact_scaled(self, phys: Program, o: dict):
        """(program, states, rhs, profile) of a contact region in the scaled states (chi, ls)."""
        ys = sp.symbols(" ".join(CONTACT_STATES))
        chi, ls = ys
        P = Program([S, *ys, *self.params])
        P.let("omega", S * chi / RHO, always=True)
        P.extend(phys, skip_defined=True)
        g = [ls * o["Psi"] / o["tip"]["G"] - chi, S * o["dls"]]
        rhs = [P.let(f"g_{n}", e) for n, e in zip(CONTACT_STATES, g)]
        t = o["tip"]
        profile = {
            "r": o["r"], "z": RHO * t["B"], "phi": t["phi"], "lambda_s": ls, "lambda_theta": o["lt"],
            "kappa_s": o["ks"], "kappa_theta": o["kt"], "T_s": o["T_s"], "T_theta": o["T_t"],
            "M_s": o["M_s"], "M_theta": o["M_t"], "tau_s": o["tau_s"], "tau_theta": o["tau_t"],
            "Q": o["Q"], "P": o["P"], "axial_force_2pi": o["G"],
            "energy_density": o["U"] * o["R"] * o["Psi"], "omega": sp.Symbol("omega"),
            "volume_density": -sp.pi * o["r"] ** 2 * o["psi"] * t["sin_phi"],
        }
        if "thk" in o:
            profile["thickness"] = o["thk"]
        # note: profile z is relative to the tip apex; the solver adds z_tip.
        return P, ys, rhs, profile

    # ------------------------------------------------------------------ conditions
    def _build_boundaries(self):
        st = self.structure
        sh = st.shell
        # Pole: omega = omega'(0) S + O(S^3), omega'(0) = lambda0 R'(0)/(rho A'(0)), and
        # lambda_s(0) = lambda_theta(0) = lambda0.
        chi0, ls0 = sp.symbols("chi ls")
        Pp = Program([chi0, ls0, LAMBDA0, *self.params])
        dR0 = sp.diff(sh.R, S).subs(S, 0)
        dA0 = sp.diff(st.tip.A, OMEGA).subs(OMEGA, 0)
        self.pole = Pp
        self.pole_states = (chi0, ls0)
        self.pole_res = [Pp.let("res_chi", chi0 - LAMBDA0 * dR0 / dA0), Pp.let("res_ls", ls0 - LAMBDA0)]

        # Rim, S = L: lambda_theta = 1, M_s = 0 (as tr Delta = 0), z = 0.
        lt, phiS, ls, ks, rQ, z = self.free_states
        F = self.free
        self.rim_res = [F.let("res_lt", lt - 1), F.let("res_m", self.free_phys_out["m"]),
                        F.let("res_z", z)]


    def _edge(self, contact: Program, contact_profile: dict, contact_out: dict, pin_at=None):
        """Contact-line programs between a contact region (tip or cylinder) and a free one.

        Returns ``(program, inputs (Sc, yc, yf), {model: residuals}, force residual)``:
        contact end (chi_c, ls_c) and free start (suffix _f) at S = Sc.  (Ring forces are
        the jumps of the axial force across an edge, from the regions' profiles:
        ``shellbvp.diagnosis``.)  With ``pin_at`` (the tip's end omega_max) also the paper's
        edge held there ("pinned").
        """
        sh = self.structure.shell
        yc = sp.symbols("chi_c ls_c")
        yf = sp.symbols(" ".join(n + "_f" for n in FREE_STATES))
        J = Program([SC, *yc, *yf, DELTA, FORCE, *self.params])
        cprog, cmap = contact.renamed("_c", {S: SC}, keep=self.params)
        fprog, fmap = self.free.renamed("_f", {S: SC}, keep=self.params)
        J.extend(cprog)
        J.extend(fprog)
        oc = {k: v.xreplace(cmap) for k, v in contact_profile.items()}
        of = {k: v.xreplace(fmap) for k, v in self.free_profile.items()}
        z_tip = sh.Z.subs(S, 0) + self.structure.pole_rise - DELTA
        lt_f, phiS_f, ls_f, ks_f, rQ_f, z_f = yf
        common = [
            J.let("res_r", lt_f - oc["lambda_theta"]),
            J.let("res_phi", phiS_f - oc["phi"] / SC),
            J.let("res_z", z_f - (z_tip + oc["z"])),
        ]
        # Weierstrass-Erdmann corner: lambda_s and kappa_s may jump.  Sliding the edge's material
        # along the indenter (whose meridional curvature kappa_s^c turns phi with it) gives
        # [tau_s] + kappa_s^c [M_s] = 0; moving the edge gives the Eshelby condition
        # [lambda_s dU/dlambda_s - U] = 0 (R Psi continuous).  Both hold at continuity too:
        # only a state with a jump is a corner (there the two rows are independent).
        U_c = contact_out["U"].xreplace(cmap)
        U_f = self.free_phys_out["U"].xreplace(fmap)
        H_c = J.let("H_c", self._eshelby(J, U_c, yc[1]))
        H_f = J.let("H_f", self._eshelby(J, U_f, ls_f))
        res = {
            "smooth": common + [J.let("res_ls", ls_f - oc["lambda_s"]),
                                J.let("res_ks", ks_f - oc["kappa_s"])],
            "paper": common + [J.let("res_Q", rQ_f - contact_out["rQ"].xreplace(cmap)),
                               J.let("res_tau", of["tau_s"] - oc["tau_s"])],
            "corner": common + [J.let("res_slide", of["tau_s"] - oc["tau_s"]
                                      + oc["kappa_s"] * (of["M_s"] - oc["M_s"])),
                                J.let("res_H", H_f - H_c)],
        }
        if pin_at is not None:
            # The paper's edge held at the tip's end, where the indenter's meridional curvature
            # jumps from the tip's to the cylinder's 0: there the indenter can push on the edge's
            # circle (Q jumps: a ring force, normal to the shell, which must push), so the
            # paper's no-ring-force condition gives way to omega = omega_max; tau_s stays
            # continuous (frictionless).
            res["pinned"] = common + [J.let("res_pin", yc[0] - RHO * pin_at / SC),
                                      J.let("res_tau_pin", of["tau_s"] - oc["tau_s"])]
        force = J.let("res_F", of["axial_force_2pi"] - FORCE / (2 * sp.pi))
        return J, (SC, *yc, *yf), res, force

    def _build_tip_end(self):
        """Where the shell passes from the tip onto the cylinder, at an unknown S = S*.

        omega reaches omega_max from both sides (2 conditions, as chi = rho omega_max/S*), and
        the Weierstrass-Erdmann (refraction) condition of E = 2 pi Int U R Psi dS across the
        line omega = omega_max, where U jumps with the indenter's kappa_s: the Hamiltonian
        ``R Psi (lambda_s dU/dlambda_s - U)`` is continuous (``[lambda_s U_ls - U] = 0``, R Psi
        being continuous); lambda_s may jump, and with it the tension (the kink of the indenter's
        curvature carries it, like the contact edge's ring force).  1 condition.
        """
        w0 = self.structure.tip.omega_max
        SS = sp.Symbol("S_end", positive=True)
        yt = sp.symbols("chi_t ls_t")
        yw = sp.symbols("chi_w ls_w")
        E = Program([SS, *yt, *yw, *self.params])
        tprog, tmap = self.contact.renamed("_t", {S: SS, self.contact_states[0]: yt[0],
                                                  self.contact_states[1]: yt[1]}, keep=self.params)
        wprog, wmap = self.cylinder.renamed("_w", {S: SS, self.cylinder_states[0]: yw[0],
                                                   self.cylinder_states[1]: yw[1]}, keep=self.params)
        E.extend(tprog)
        E.extend(wprog)

        H_t = E.let("H_t", self._eshelby(E, self.contact_phys_out["U"].xreplace(tmap), yt[1]))
        H_w = E.let("H_w", self._eshelby(E, self.cylinder_phys_out["U"].xreplace(wmap), yw[1]))
        self.tip_end = E
        self.tip_end_inputs = (SS, *yt, *yw)
        self.tip_end_res = [E.let("res_end_t", yt[0] - RHO * w0 / SS), E.let("res_end_w", yw[0] - RHO * w0 / SS),
                            E.let("res_end_H", H_t - H_w)]

    def _build_point_load(self):
        """Pole conditions of the point-load limit (cap -> 0, smooth model), at S = s0.

        Near a concentrated force the stretches tend to an isotropic lambda0, the
        moments grow like ln S (so kappa_s ~ a ln S + b) and phi ~ psi (a (S ln S - S) + b S).
        Hence, with a = S dkappa_s/dS from the free region's own equations:
        ``lambda_theta = lambda_s``, ``z = Z(0) - delta`` and
        ``phi/S = psi (kappa_s - S dkappa_s/dS)`` (this excludes the ln S deflection
        that a finite pole displacement forbids).  Truncation error O(s0^2 ln^2 s0).
        """
        lt, phiS, ls, ks, rQ, z = self.free_states
        P = Program([S, *self.free_states, DELTA, *self.params])
        P.extend(self.free, skip_defined=True)
        o = self.free_phys_out
        g_ks = sp.Symbol("g_ks")
        self.point_load = P
        self.point_load_res = [
            P.let("res_iso", lt - ls),
            P.let("res_zpole", z - (self.structure.shell.Z.subs(S, 0) + self.structure.pole_rise - DELTA)),
            P.let("res_rot", phiS - o["psi"] * (ks - g_ks)),
        ]

    def _build_free_pole(self):
        """Regular pole of a free cap (the shell lifted off the indenter there), at S = zeta.

        With no force at the pole the axial force of the cap vanishes identically
        (``G = 0`` exactly), the stretches are isotropic and ``phi/S = psi kappa_s``; the
        last two err by O(zeta^2), like the contact pole.  G is imposed as it is, a force
        like the other force conditions: as G/S^2 its Jacobian row grew as 1/zeta^2 (3e12 on
        base's line at delta 0.075, 4e15 at 0.018) and solve_bvp's absolute bc_tol asked rQ
        to 1e-23, below what Newton's linear solves resolve (it stalled with status 3).
        """
        lt, phiS, ls, ks, rQ, z = self.free_states
        o = self.free_phys_out
        F = self.free
        self.free_pole_res = [
            F.let("res_pole_iso", lt - ls),
            F.let("res_pole_rot", phiS - o["psi"] * ks),
            F.let("res_pole_G", o["G"]),
        ]

    def _build_kink(self):
        """An interior Weierstrass-Erdmann corner of the free region, at an unknown S = S_k.

        Where U is not convex in (lambda_s, kappa_s) the minimiser may jump between two states
        of equal (lambda_theta, kappa_theta) inside the free region.  r, phi, z and Q stay
        continuous (``shellbvp.chain.Kink`` equates the states lt, phiS, rQ, z); the momenta of
        E = 2 pi Int U R Psi dS conjugate to r, z and phi, i.e. the force resultants tau_s, Q and
        the moment M_s, are continuous; and so is the Hamiltonian R Psi (lambda_s dU/dlambda_s
        - U) (the Eshelby condition; R Psi continuous).  The three rows below hold at
        continuity too: only a state with a jump is a corner.  (The contact edge's corner is
        the same construction with the indenter on one side: ``_edge``.)
        """
        SK = sp.Symbol("S_k", positive=True)
        yl = sp.symbols(" ".join(n + "_l" for n in FREE_STATES))
        yr = sp.symbols(" ".join(n + "_r" for n in FREE_STATES))
        K = Program([SK, *yl, *yr, *self.params])
        sides = []
        for tag, ys in (("_l", yl), ("_r", yr)):
            prog, mapping = self.free.renamed(tag, {S: SK, **dict(zip(self.free_states, ys))}, keep=self.params)
            K.extend(prog)
            U = self.free_phys_out["U"].xreplace(mapping)
            ls = ys[FREE_STATES.index("ls")]
            sides.append(dict(tau_s=self.free_phys_out["tau_s"].xreplace(mapping),
                              M_s=self.free_phys_out["M_s"].xreplace(mapping),
                              H=K.let(f"H{tag}", self._eshelby(K, U, ls))))
        left, right = sides
        self.kink = K
        self.kink_inputs = (SK, *yl, *yr)
        self.kink_res = [K.let("res_kink_tau", right["tau_s"] - left["tau_s"]),
                         K.let("res_kink_M", right["M_s"] - left["M_s"]),
                         K.let("res_kink_H", right["H"] - left["H"])]

    def _build_geometry(self):
        """Reference shell and tip shape as plain functions (no states)."""
        sh, tip = self.structure.shell, self.structure.tip
        G = Program([S, OMEGA, *self.params])
        k_s, k_t = sh.curvatures()
        dR, dZ = sp.diff(sh.R, S), sp.diff(sh.Z, S)
        self.reference_shell = {
            "R": G.let("ref_R", sh.R), "Z": G.let("ref_Z", sh.Z), "Phi": G.let("ref_Phi", sp.atan2(dZ, dR)),
            "kappa_s": G.let("ref_ks", k_s), "kappa_theta": G.let("ref_kt", k_t),
            "volume_density": G.let("ref_vol", -sp.pi * sh.R**2 * dZ),
        }
        self.tip_shape = {"A": G.let("tip_A", tip.A), "B": G.let("tip_B", tip.B),
                          "phi": G.let("tip_phi", tip.phi), "dA": G.let("tip_dA", sp.diff(tip.A, OMEGA))}
        self.geometry_prog, self.geometry_S, self.geometry_omega = G, S, OMEGA


def derive(st: Structure) -> Derivation:
    """Derive every program of a structure (see :class:`Derivation`)."""
    return Derivation(st)
