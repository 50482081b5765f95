r"""Contact configurations as data: a chain of regions and junctions, assembled into ONE
multipoint BVP for ``scipy.integrate.solve_bvp``.

The stacked layout (the one place it is defined)
------------------------------------------------
A configuration is an ordered list of regions ``k = 0 .. n-1`` from the pole to
the rim, each of a kind (``"free"``: 6 states ``(lt, phiS, ls, ks, rQ, z)``;
``"contact"``, the shell on the tip, and ``"cylinder"``, the shell on the
indenter's cylinder: 2 states ``(chi, ls)``, ``chi = rho omega/S`` with omega
running on past the tip's end ``omega_max`` along the cylinder; see
``symbolic.equations``) on ``[S_a, S_b]``.  Every region is mapped
geometrically onto the same ``t in [0, 1]``,

    ``S_k(t) = exp(a_k + t (b_k - a_k))``,  ``a_k = ln S_a``, ``b_k = ln S_b``,

so that ``dy/dt = (b_k - a_k) g_k(S, y)`` with ``g = S dy/dS`` from the
generated code, and tiny caps stay well conditioned.  ``y`` stacks the
regions' states in chain order (rows ``offset[k] : offset[k] + size[k]``);
``y[:, 0]`` holds every region's start and ``y[:, -1]`` every region's end.

Each end is a :class:`Point` with ``ln S = ln_offset + p[unknown]`` (or a
fixed value): a pole start ``zeta = eps * Sc`` is the point ``Sc`` shifted by
``ln eps``.  The unknown parameters ``p`` are, in this order, the
configuration's own unknowns (``ln Sc``; ``ln S1, ln S2``; ``ln S1, chi1``),
then ``lambda0`` where a contact cap reaches the pole and lambda0 is not
prescribed, then ``delta`` unless it is prescribed.

Conditions are the junctions' rows in chain order (pole, contact edges or
lines, rim), then the control's row: the force at the last contact edge
(``force``), the stretch at a lifted pole (``lambda0`` without a contact
pole), or the pseudo-arclength condition (``arclength``,
``sum_i t_i (X_i - Xhat_i)/s_i = 0`` over ``X = (delta, lambda0, F)``; its
value is the tuple ``(Xhat, t, s)``).

Volume control (a sealed shell, ``Scene.sealed``): the pressure is an unknown too
(the last), and one state ``v`` (the last row) sums the regions' volumes, which all
run on the same t: ``v' = sum_k (b_k - a_k) S dV/dS``, ``v(0) = 0``, ``v(1) = V0``
(rows after the control's).  One state, not one per region: solve_bvp's LU costs
about the cube of the states per node.  Guesses need only the regions' states and
the unknowns before the pressure: :meth:`ChainBVP.solve` completes them.

:class:`Region`, :class:`Point` and the junctions are the blocks a chain is declared with
(each configuration's chain is declared in its module of :mod:`shellbvp.configurations`,
e.g. ``cap_chain`` in ``shellbvp/configurations/cap.py``); :class:`ChainBVP`
assembles any chain into ``fun``, ``fun_jac``, ``bc``, ``bc_jac`` (analytic,
from the generated Jacobians), end values, energy and profile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels import kernel_set
from .quadrature import gauss_points

__all__ = ["Point", "Region", "ContactPole", "FreePole", "PointPole", "Edge", "TipEnd", "Line", "Kink", "Rim",
           "Chain",
           "ChainBVP", "CONTROLS",
           "SIZES", "FREE_STATES", "CONTACT_STATES", "CONTACT_KINDS", "REGION_CODES"]

CONTROLS = ("delta", "lambda0", "force", "arclength")
FREE_STATES = ("lt", "phiS", "ls", "ks", "rQ", "z")
CONTACT_STATES = ("chi", "ls")
SIZES = {"free": len(FREE_STATES), "contact": len(CONTACT_STATES), "cylinder": len(CONTACT_STATES)}
CONTACT_KINDS = ("contact", "cylinder")  # the shell on the tip; on the indenter's cylinder r = rho A(omega_max)
#: ``region`` codes of profiles: 0 on the tip, 1 free, 2 on the cylinder
REGION_CODES = {"contact": 0, "free": 1, "cylinder": 2}
_LS = FREE_STATES.index("ls")
# states continuous across a line contact (rQ jumps: the ring force)
_LINE_CONTINUOUS = [FREE_STATES.index(s) for s in ("lt", "phiS", "ls", "ks", "z")]
# states continuous across an interior corner (ls, ks jump)
_KINK_CONTINUOUS = [FREE_STATES.index(s) for s in ("lt", "phiS", "rQ", "z")]


# -- declarations ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Point:
    """A point on the S axis: ``ln S = ln_offset + p[unknown]``, or ``ln S = ln_offset`` if fixed."""

    name: str
    unknown: str | None = None
    ln_offset: float = 0.0


@dataclass(frozen=True)
class Region:
    kind: str  # "free" | "contact" (on the tip) | "cylinder" (on the indenter's side)
    start: Point
    end: Point


@dataclass(frozen=True)
class ContactPole:
    """Regular pole of a contact cap (region ``k`` starts at zeta): 2 rows, uses lambda0."""

    k: int
    rows = 2


@dataclass(frozen=True)
class FreePole:
    """Regular pole of a free cap (region ``k`` starts at zeta): 3 rows."""

    k: int
    rows = 3


@dataclass(frozen=True)
class PointPole:
    """Point-load pole of the free region ``k`` at its start s0: 3 rows, uses delta."""

    k: int
    rows = 3


@dataclass(frozen=True)
class Edge:
    """Contact edge between contact region ``kc`` and free region ``kf`` (adjacent): 5 rows.

    ``model`` is ``"smooth"`` (variational) or ``"paper"``; see SPEC section 2b.
    """

    kc: int
    kf: int
    model: str = "smooth"
    rows = 5


@dataclass(frozen=True)
class TipEnd:
    """The shell passes from the tip (region ``k``) onto the cylinder (region ``k + 1``): 3 rows.

    omega = omega_max at the end of one and the start of the other, and
    ``[lambda_s dU/dlambda_s - U] = 0`` (``symbolic.equations.Derivation._build_tip_end``).
    """

    k: int
    rows = 3


@dataclass(frozen=True)
class Line:
    """Line contact between free regions ``k`` and ``k + 1`` at the indenter point ``chi1``: 8 rows.

    r, phi, z on the indenter (3 rows, the smooth junction's first three; ``on`` the tip,
    ``"contact"``, or the cylinder, ``"cylinder"``); lt, phiS, ls, ks, z continuous (5);
    rQ jumps (the ring force).
    """

    k: int
    on: str = "contact"
    rows = 8


@dataclass(frozen=True)
class Kink:
    """Interior Weierstrass-Erdmann corner between free regions ``k`` and ``k + 1``: 7 rows.

    lt, phiS, rQ, z continuous (4); lambda_s and kappa_s jump with [tau_s] = [M_s] = 0 and the
    Eshelby condition [lambda_s dU/dlambda_s - U] = 0 (3, ``kink_res``).  Where U is convex
    the jump is 0 (the rows then hold for any S_k): only a state with a jump is a corner.
    """

    k: int
    rows = 7


@dataclass(frozen=True)
class Rim:
    """Simply supported rim at the end of region ``k``: 3 rows."""

    k: int
    rows = 3


@dataclass(frozen=True)
class Chain:
    """A contact configuration: regions pole to rim, junctions, unknowns of its own."""

    name: str
    regions: tuple
    junctions: tuple
    unknowns: tuple  # configuration unknowns (before lambda0, delta)
    eps: float | None = None  # pole start zeta = eps * (first contact or lift-off edge), if a regular pole

    def layout(self) -> str:
        """A table of the stacked layout (rows, S ranges, junction rows)."""
        lines, row = [f"{self.name}: y rows, t in [0, 1]"], 0
        for k, reg in enumerate(self.regions):
            n = SIZES[reg.kind]
            states = FREE_STATES if reg.kind == "free" else CONTACT_STATES
            lines.append(f"  y[{row}:{row + n}]  region {k} {reg.kind:<7s} S in [{reg.start.name}, {reg.end.name}]"
                         f"  ({', '.join(states)})")
            row += n
        lines.append("conditions:")
        r = 0
        for j in self.junctions:
            lines.append(f"  [{r}:{r + j.rows}]  {type(j).__name__}{_fields(j)}")
            r += j.rows
        return "\n".join(lines)


def _fields(j):
    return "(" + ", ".join(f"{k}={v!r}" for k, v in j.__dict__.items()) + ")"


# -- the assembler -------------------------------------------------------------------------------
def _call_key(t, y, p, par):
    """The cheap part of what identifies a ``fun`` call (shapes, the unknowns' and parameters'
    bytes), compared before t and y are compared by value (:func:`_same_call`)."""
    return np.shape(y), np.shape(t), None if p is None else np.asarray(p, float).tobytes(), par.tobytes()


def _same_call(key, small, t, y) -> bool:
    k_small, kt, ky = key
    return k_small == small and np.array_equal(ky, y) and np.array_equal(kt, t)


class ChainBVP:
    """fun, fun_jac, bc, bc_jac of one chain, scene, control mode and prescribed value.

    Parameters
    ----------
    scene : Scene
    chain : Chain
    control : {"delta", "lambda0", "force", "arclength"}
    value : float, or (Xhat, tangent, scale) for ``"arclength"``
    model : module, optional
        The scene's generated module (loaded if not given).
    par : array, optional
        Its run-time parameters; default ``scene.parameters(model)``, without pressure only:
        under pressure they carry the inflated state's pole rise
        (``shellbvp.inflation.system_parameters``), which a configuration's system passes.
    volume_control : bool, optional
        The pressure as an unknown with the enclosed volume held at ``scene.enclosed_volume()``
        (default: ``scene.sealed``).
    """

    def __init__(self, scene, chain: Chain, control: str, value, model=None, par=None, volume_control=None):
        if control not in CONTROLS:
            raise ValueError(f"control must be one of {CONTROLS}; got {control!r}")
        self.scene, self.chain, self.control = scene, chain, control
        self.model = mod = model if model is not None else scene.model()
        if par is None and scene.pressure:
            raise ValueError("par is needed for a scene under pressure: its run-time parameters with the inflated "
                             "state's pole rise (shellbvp.inflation.system_parameters; a configuration's system "
                             "passes them)")
        self.par = scene.parameters(mod) if par is None else np.asarray(par, float)
        self.regions = chain.regions
        self._bind()
        self.sizes = [SIZES[r.kind] for r in chain.regions]
        self.offsets = np.cumsum([0, *self.sizes])[:-1].tolist()
        self.n_shell = int(sum(self.sizes))  # the regions' states; then the volume state
        self.volume_control = bool(scene.sealed if volume_control is None else volume_control)
        self.n = self.n_shell + self.volume_control
        kinds = {type(j) for j in chain.junctions}
        self.has_contact_pole = ContactPole in kinds
        if control == "arclength" and not self.has_contact_pole:
            raise ValueError(f"arclength control needs a contact cap at the pole; {chain.name} has none")
        if control in ("force", "arclength") and not any(isinstance(j, (Edge, Line)) for j in chain.junctions):
            raise ValueError(f"{control} control needs contact; the {chain.name} configuration has only delta")
        if control == "lambda0" and not any(isinstance(j, (ContactPole, FreePole)) for j in chain.junctions):
            raise ValueError(f"lambda0 control needs a regular pole; the {chain.name} configuration has none")
        names = list(chain.unknowns)
        if self.has_contact_pole and control != "lambda0":
            names.append("lambda0")
        if control != "delta":
            names.append("delta")
        if self.volume_control:
            if "pressure" not in mod.PARAMS:
                raise ValueError("volume control needs a pressurised structure (Scene.sealed)")
            names.append("pressure")
            self.enclosed_volume = scene.enclosed_volume()
        self.unknowns = tuple(names)
        self.k = len(names)
        self.col = {name: i for i, name in enumerate(names)}
        self._set_value(value)
        self.junctions = list(chain.junctions)
        self.extra = None
        if control == "force":
            self.extra = "force"
        elif control == "lambda0" and not self.has_contact_pole:
            self.extra = "pole_stretch"
        elif control == "arclength":
            self.extra = "arclength"
        self.force_at = next((j for j in reversed(self.junctions) if isinstance(j, (Edge, Line))), None)
        self.n_conditions = (sum(j.rows for j in self.junctions) + (self.extra is not None)
                             + (2 if self.volume_control else 0))

    def _set_value(self, value):
        self.value = float("nan")
        if self.control == "arclength":
            self.arc_point, self.arc_tangent, self.arc_scale = (np.asarray(v, float) for v in value)
        else:
            self.value = float(value)

    def with_value(self, value) -> "ChainBVP":
        """This system with another prescribed value (same chain, control and parameters): a
        continuation step's system without building it again (~0.15 ms a step)."""
        if self.volume_control:
            raise ValueError("with_value: a volume-controlled system's parameters follow its solution (see at)")
        other = object.__new__(type(self))
        other.__dict__.update(self.__dict__)
        other.__dict__.pop("_fun_cache", None)
        other._set_value(value)
        return other

    def __repr__(self):
        return f"ChainBVP({self.control}={self.value:g})\n{self.chain.layout()}"

    # pickling: the generated module is code, not data; it is loaded again (from the code
    # cache) by the scene on unpickling, so results can travel between processes
    def __getstate__(self):
        return {k: v for k, v in self.__dict__.items() if k not in ("model", "kernels", "_vol", "_vol_jac")}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self.model = self.scene.model()
        self._bind()

    # -- quantities -----------------------------------------------------------------------------
    def quantities(self, p) -> dict:
        """Every quantity by name: the unknowns from ``p``, the prescribed one, F (0 unless prescribed)."""
        q = {name: p[i] for i, name in enumerate(self.unknowns)}
        q.setdefault("F", self.value if self.control == "force" else 0.0)
        if self.control in ("delta", "lambda0"):
            q.setdefault(self.control, self.value)
        q.setdefault("lambda0", float("nan"))
        return q

    def pack(self, **values) -> np.ndarray:
        """``p`` from named values (extra names, e.g. a prescribed delta, are ignored; a missing
        pressure under volume control is the scene's)."""
        if self.volume_control:
            values.setdefault("pressure", self.scene.pressure)
        return np.array([values[name] for name in self.unknowns], float)

    # -- volume control ------------------------------------------------------------------------------
    def par_at(self, p) -> np.ndarray:
        """The run-time parameters at unknowns ``p``: the pressure is one of them under volume control."""
        if not self.volume_control or p is None:
            return self.par
        par = self.par.copy()
        par[self._i_pressure] = p[self.col["pressure"]]
        return par

    def at(self, p) -> "ChainBVP":
        """This system with its parameters at the solution ``p`` (the pressure under volume
        control; ``self`` otherwise): what profiles and checks of that solution evaluate."""
        if not self.volume_control or p is None:
            return self
        other = object.__new__(type(self))
        other.__dict__.update(self.__dict__)
        other.__dict__.pop("_fun_cache", None)
        other.__dict__.pop("_pole_height", None)
        other.par = self.par_at(p)
        return other

    def _volume_rates(self, t, y, p, k):
        a, b = self.ln_S(self.regions[k].start, p), self.ln_S(self.regions[k].end, p)
        S = np.exp(a + t * (b - a))
        return (b - a) * self._vol[k](S, y[self.rows(k)], self.par)[0]

    def complete(self, x, y, p):
        """``(y, p)`` for a solve from a guess of the regions' states and the unknowns before
        the pressure: under volume control the volume state (integrated from ``y`` by the
        trapezoidal rule) and the pressure (the scene's, if ``p`` has none) are added."""
        y = np.asarray(y, float)
        if not self.volume_control:
            return y, p
        p = np.empty(0) if p is None else np.asarray(p, float)
        if p.size == self.k - 1:
            p = np.append(p, self.scene.pressure)
        from scipy.integrate import cumulative_trapezoid

        rate = sum(self._volume_rates(x, y, p, k) for k in range(len(self.regions)))
        return np.vstack([y[:self.n_shell], cumulative_trapezoid(rate, x, initial=0.0)]), p

    def solve(self, x, y, p=None, **kwargs):
        """``shellbvp.solution.solve_bvp`` of this system from a guess (completed, see
        :meth:`complete`); keyword arguments go to solve_bvp."""
        from .solution import solve_bvp

        y, p = self.complete(x, y, p)
        return solve_bvp(self.fun, self.bc, x, y, p, fun_jac=self.fun_jac, bc_jac=self.bc_jac,
                         kernels=self._elimination, **kwargs)

    @property
    def _elimination(self):
        """The compiled kernels that factorise the collocation Jacobian, or None (SuperLU)."""
        active = self.kernels.active
        return active if hasattr(active, "collocation_factor") else None

    def newton_on_mesh(self, x, y, p=None, *, tol, bc_tol):
        """``shellbvp.collocation.newton_on_mesh`` of this system from a guess (completed, see
        :meth:`complete`) on the fixed mesh ``x``: ``(y, p)`` (``p`` None when there are no
        unknowns), or None where that Newton does not converge."""
        from .collocation import newton_on_mesh

        y, p = self.complete(x, y, p)
        if self.k:
            fun, fun_jac, bc, bc_jac = self.fun, self.fun_jac, self.bc, self.bc_jac
        else:  # solve_bvp's calling convention without unknowns, as newton_on_mesh takes it
            def fun(t, y, _):
                return self.fun(t, y)

            def fun_jac(t, y, _):
                return self.fun_jac(t, y), None

            def bc(ya, yb, _):
                return self.bc(ya, yb)

            def bc_jac(ya, yb, _):
                return (*self.bc_jac(ya, yb), None)
        out = newton_on_mesh(fun, bc, fun_jac, bc_jac, np.asarray(x, float), np.array(y, float),
                             np.empty(0) if p is None else np.array(p, float), tol=tol, bc_tol=bc_tol,
                             kernels=self._elimination)
        if out is None:
            return None
        return out[0], (out[1] if self.k else None)

    def ln_S(self, point: Point, p) -> float:
        return point.ln_offset + (p[self.col[point.unknown]] if point.unknown else 0.0)

    def S_point(self, point: Point, p) -> np.float64:
        # a numpy scalar, not a float: an iterate far out (S -> 0 or inf) must give inf/NaN in
        # the generated code (IEEE), not Python's OverflowError
        return np.exp(np.float64(self.ln_S(point, p)))

    def rows(self, k) -> slice:
        return slice(self.offsets[k], self.offsets[k] + self.sizes[k])

    def S(self, k, t, p):
        """S on region ``k`` at ``t``."""
        a, b = self.ln_S(self.regions[k].start, p), self.ln_S(self.regions[k].end, p)
        return np.exp(a * (1 - t) + b * t)  # exact at both ends: neighbouring regions meet, not cross

    def t_of(self, k, S, p):
        """The t at which region ``k`` reaches ``S`` (outside the region: outside [0, 1])."""
        a, b = self.ln_S(self.regions[k].start, p), self.ln_S(self.regions[k].end, p)
        return (np.log(S) - a) / (b - a)

    @property
    def topology(self) -> str:
        return self.chain.name

    @property
    def eps(self):
        return self.chain.eps

    @property
    def L(self) -> float:
        return self.S_point(self.regions[-1].end, None)

    def _bind(self):
        """The regions' right-hand sides and Jacobians (the hot path) come from the structure's
        kernel set: the generated numpy functions, or the compiled ones once they are ready
        (``shellbvp.kernels``; looked up on every call, so a curve switches as soon as they are)."""
        self.kernels = kernel_set(self.model, self.scene.structure)
        self._rhs_names = [f"{r.kind}_rhs" for r in self.regions]
        self._jac_names = [f"{r.kind}_jac" for r in self.regions]
        if "pressure" in self.model.PARAMS:  # volume control's functions (pressurised structures)
            self._i_pressure = self.model.PARAMS.index("pressure")
            self._vol = [getattr(self.model, f"{r.kind}_vol") for r in self.regions]
            self._vol_jac = [getattr(self.model, f"{r.kind}_vol_jac") for r in self.regions]

    def _rhs(self, k):
        return getattr(self.kernels.active, self._rhs_names[k])

    def _jac(self, k):
        return getattr(self.kernels.active, self._jac_names[k])

    @staticmethod
    def _prefix(kind):
        """Generated names of cylinder edges carry ``cyl_`` (``junction_cyl_smooth_res``)."""
        return "cyl_" if kind == "cylinder" else ""

    def _edge_function(self, j, what):
        """junction_[cyl_]<model>_<what> of an edge, by its contact region's kind."""
        return getattr(self.model, f"junction_{self._prefix(self.regions[j.kc].kind)}{j.model}_{what}")

    # -- ODE ------------------------------------------------------------------------------------
    #: fun's last results kept, by their arguments' values: after each Newton run solve_bvp
    #: evaluates again, at the nodes and the midpoints, the iterate its last step evaluated, and
    #: fun_jac, at the iterate fun was last called at, needs the right-hand sides too (for the
    #: derivatives by the regions' ends)
    _FUN_CACHE = 2

    def _cached(self, small, t, y):
        """(f, [g of each region]) of an earlier ``fun`` call at these arguments (``small``: their
        :func:`_call_key`), or None."""
        for key, value in self.__dict__.get("_fun_cache", ()):
            if _same_call(key, small, t, y):
                return value
        return None

    def fun(self, t, y, p=None):
        small = _call_key(t, y, p, self.par)
        hit = self._cached(small, t, y)
        if hit is not None:
            return hit[0].copy()
        f, g = self._fun(t, y, p)
        cache = self.__dict__.setdefault("_fun_cache", [])
        cache.insert(0, ((small, t.copy(), y.copy()), (f.copy(), g)))
        del cache[self._FUN_CACHE:]
        return f

    def _fun(self, t, y, p=None):
        """(f, [g_k]): the right-hand side, and each region's generated g = S dy/dS."""
        f = np.empty_like(y)
        par = self.par_at(p)
        gs = []
        if self.volume_control:
            f[self.n_shell] = 0.0
        for k, reg in enumerate(self.regions):
            a, b = self.ln_S(reg.start, p), self.ln_S(reg.end, p)
            rows = self.rows(k)
            S = np.exp(a + t * (b - a))
            gs.append(self._rhs(k)(S, y[rows], par))
            f[rows] = (b - a) * gs[-1]
            if self.volume_control:
                f[self.n_shell] += (b - a) * self._vol[k](S, y[rows], par)[0]
        return f, gs

    def fun_jac(self, t, y, p=None):
        n, m = self.n, t.size
        dfdy = np.zeros((n, n, m))
        dfdp = np.zeros((n, self.k, m)) if self.k else None
        par = self.par_at(p)
        hit = self._cached(_call_key(t, y, p, self.par), t, y) if dfdp is not None else None
        for k, reg in enumerate(self.regions):
            a, b = self.ln_S(reg.start, p), self.ln_S(reg.end, p)
            rows = self.rows(k)
            S = np.exp(a + t * (b - a))
            gy, gS = self._jac(k)(S, y[rows], par)
            dfdy[rows, rows] = (b - a) * gy
            if self.volume_control:
                v = self.n_shell
                vy, vS = self._vol_jac[k](S, y[rows], par)
                dfdy[v, rows] = (b - a) * vy[0]
                dfdp[rows, self.col["pressure"]] = (b - a) * getattr(
                    self.kernels.active, f"{reg.kind}_jac_par")(S, y[rows], par)[:, self._i_pressure]
            if dfdp is None:
                continue
            # d/da and d/db of (b - a) g(exp(a + t (b - a)), y), and of the volume rate
            g = None
            for point, dS_dln, sign in ((reg.start, 1.0 - t, -1.0), (reg.end, t, 1.0)):
                if point.unknown is None:
                    continue
                if g is None:
                    g = hit[1][k] if hit is not None else self._rhs(k)(S, y[rows], par)
                    if self.volume_control:
                        rate = self._vol[k](S, y[rows], par)[0]
                dfdp[rows, self.col[point.unknown]] += sign * g + (b - a) * gS * S * dS_dln
                if self.volume_control:
                    dfdp[v, self.col[point.unknown]] += sign * rate + (b - a) * vS[0] * S * dS_dln
        return (dfdy, dfdp) if dfdp is not None else dfdy

    # -- conditions -------------------------------------------------------------------------------
    def _edge_states(self, j: Edge, ya, yb):
        """(point, yc, yf, contact state at start?, free state at start?) of an edge."""
        rc, rf = self.rows(j.kc), self.rows(j.kf)
        if j.kc < j.kf:
            return self.regions[j.kc].end, yb[rc], ya[rf], False, True
        return self.regions[j.kc].start, ya[rc], yb[rf], True, False

    def _line_states(self, j: Line, ya, yb, q):
        yin = yb[self.rows(j.k)]
        return self.regions[j.k].end, np.array([q["chi1"], yin[_LS]]), yin, ya[self.rows(j.k + 1)]

    def bc(self, ya, yb, p=None):
        mod, par = self.model, self.par_at(p)
        q = self.quantities(p)
        parts = []
        for j in self.junctions:
            if isinstance(j, ContactPole):
                y0 = ya[self.rows(j.k)]
                parts.append(mod.pole_res(y0[0], y0[1], q["lambda0"], par))
            elif isinstance(j, FreePole):
                parts.append(mod.free_pole_res(self.S_point(self.regions[j.k].start, p), ya[self.rows(j.k)], par))
            elif isinstance(j, PointPole):
                parts.append(mod.point_load_res(self.S_point(self.regions[j.k].start, p), ya[self.rows(j.k)],
                                                q["delta"], par))
            elif isinstance(j, Edge):
                point, yc, yf, _, _ = self._edge_states(j, ya, yb)
                parts.append(self._edge_function(j, "res")(self.S_point(point, p), yc, yf, q["delta"], q["F"], par))
            elif isinstance(j, TipEnd):
                parts.append(mod.tip_end_res(self.S_point(self.regions[j.k].end, p), yb[self.rows(j.k)],
                                             ya[self.rows(j.k + 1)], par))
            elif isinstance(j, Line):
                point, yc, yin, yout = self._line_states(j, ya, yb, q)
                on_tip = self._line_function(j, "res")(self.S_point(point, p), yc, yin, q["delta"], q["F"], par)[:3]
                parts += [on_tip, (yout - yin)[_LINE_CONTINUOUS]]
            elif isinstance(j, Kink):
                yl, yr = yb[self.rows(j.k)], ya[self.rows(j.k + 1)]
                parts += [mod.kink_res(self.S_point(self.regions[j.k].end, p), yl, yr, par),
                          (yr - yl)[_KINK_CONTINUOUS]]
            elif isinstance(j, Rim):
                parts.append(mod.rim_res(self.S_point(self.regions[j.k].end, p), yb[self.rows(j.k)], par))
        if self.extra == "force":
            _, S, yc, yf, _, _ = self._force_args(ya, yb, p, q)
            parts.append(self._force_function("res")(S, yc, yf, q["delta"], q["F"], par))
        elif self.extra == "pole_stretch":
            parts.append([ya[self.rows(0)][_LS] - self.value])
        elif self.extra == "arclength":
            _, S, yc, yf, _, _ = self._force_args(ya, yb, p, q)
            force = 2 * np.pi * self._force_function("res")(S, yc, yf, q["delta"], 0.0, par)[0]
            X = np.array([q["delta"], q["lambda0"], force])
            parts.append([np.sum(self.arc_tangent * (X - self.arc_point) / self.arc_scale)])
        if self.volume_control:
            parts += [[ya[self.n_shell]], [yb[self.n_shell] - self.enclosed_volume]]
        return np.concatenate(parts)

    def _line_function(self, j, what):
        return getattr(self.model, f"junction_{self._prefix(j.on)}smooth_{what}")

    def _force_function(self, what):
        """force_[cyl_]<what> at the last contact edge (F of the free region beyond it)."""
        j = self.force_at
        return getattr(self.model, f"force_{self._prefix(self.regions[j.kc].kind if isinstance(j, Edge) else '')}"
                                   f"{what}")

    def _force_args(self, ya, yb, p, q):
        """(point, S, yc, yf, free region, free state at its start?) of the force condition."""
        j = self.force_at
        if isinstance(j, Edge):
            point, yc, yf, _, f_at_a = self._edge_states(j, ya, yb)
            kf = j.kf
        else:
            point, yc, _, yf = self._line_states(j, ya, yb, q)
            kf, f_at_a = j.k + 1, True
        return point, self.S_point(point, p), yc, yf, kf, f_at_a

    def _add_p(self, P, rows, name, values):
        if name is not None and name in self.col:
            P[rows, self.col[name]] += values

    def _pressure_column(self, P, rows, dres_dpar):
        """Under volume control, a condition's derivative in the pressure (an unknown)."""
        if self.volume_control:
            P[rows, self.col["pressure"]] += dres_dpar[..., self._i_pressure]

    def bc_jac(self, ya, yb, p=None):
        mod, par = self.model, self.par_at(p)
        q = self.quantities(p)
        m, n = self.n_conditions, self.n
        A, B = np.zeros((m, n)), np.zeros((m, n))
        P = np.zeros((m, self.k)) if self.k else None
        vc = self.volume_control
        r = 0
        for j in self.junctions:
            rows = slice(r, r + j.rows)
            if isinstance(j, ContactPole):
                o = self.offsets[j.k]
                y0 = ya[self.rows(j.k)]
                pj = mod.pole_jac(y0[0], y0[1], q["lambda0"], par)  # d/d(chi, ls, lambda0)
                A[rows, o:o + 2] = pj[:, :2]
                self._add_p(P, rows, "lambda0", pj[:, 2])
                if vc:
                    self._pressure_column(P, rows, mod.pole_jac_par(y0[0], y0[1], q["lambda0"], par))
            elif isinstance(j, (FreePole, PointPole)):
                point = self.regions[j.k].start
                S = self.S_point(point, p)
                if isinstance(j, FreePole):
                    pj = mod.free_pole_jac(S, ya[self.rows(j.k)], par)  # d/d(y, S)
                    self._add_p(P, rows, point.unknown, pj[:, 6] * S)
                    if vc:
                        self._pressure_column(P, rows, mod.free_pole_jac_par(S, ya[self.rows(j.k)], par))
                else:
                    pj = mod.point_load_jac(S, ya[self.rows(j.k)], q["delta"], par)  # d/d(y, delta)
                    self._add_p(P, rows, "delta", pj[:, 6])
                    if vc:
                        self._pressure_column(P, rows, mod.point_load_jac_par(S, ya[self.rows(j.k)], q["delta"], par))
                A[rows, self.rows(j.k)] = pj[:, :6]
            elif isinstance(j, Edge):
                point, yc, yf, c_at_a, f_at_a = self._edge_states(j, ya, yb)
                S = self.S_point(point, p)
                jj = self._edge_function(j, "jac")(S, yc, yf, q["delta"], q["F"], par)
                (A if c_at_a else B)[rows, self.rows(j.kc)] = jj[:, 1:3]
                (A if f_at_a else B)[rows, self.rows(j.kf)] = jj[:, 3:9]
                self._add_p(P, rows, point.unknown, jj[:, 0] * S)
                self._add_p(P, rows, "delta", jj[:, 9])
                if vc:
                    dpar = self._edge_function(j, "jac_par")(S, yc, yf, q["delta"], q["F"], par)
                    self._pressure_column(P, rows, dpar)
            elif isinstance(j, Line):
                point, yc, yin, yout = self._line_states(j, ya, yb, q)
                S = self.S_point(point, p)
                on = slice(r, r + 3)
                jj = self._line_function(j, "jac")(S, yc, yin, q["delta"], q["F"], par)[:3]
                self._add_p(P, on, point.unknown, jj[:, 0] * S)
                self._add_p(P, on, "chi1", jj[:, 1])
                self._add_p(P, on, "delta", jj[:, 9])
                if vc:
                    self._pressure_column(P, on, self._line_function(j, "jac_par")(S, yc, yin, q["delta"], q["F"],
                                                                                 par)[:3])
                i0, o0 = self.offsets[j.k], self.offsets[j.k + 1]
                B[on, i0:i0 + 6] = jj[:, 3:9]
                B[on, i0 + _LS] += jj[:, 2]  # ls of the contact state is the inner region's
                for row, c in enumerate(_LINE_CONTINUOUS, start=r + 3):
                    A[row, o0 + c] = 1.0
                    B[row, i0 + c] = -1.0
            elif isinstance(j, TipEnd):
                point = self.regions[j.k].end
                S = self.S_point(point, p)
                ej = mod.tip_end_jac(S, yb[self.rows(j.k)], ya[self.rows(j.k + 1)], par)  # d/d(S, yt, yw)
                B[rows, self.rows(j.k)] = ej[:, 1:3]
                A[rows, self.rows(j.k + 1)] = ej[:, 3:5]
                self._add_p(P, rows, point.unknown, ej[:, 0] * S)
                if vc:
                    self._pressure_column(P, rows, mod.tip_end_jac_par(S, yb[self.rows(j.k)], ya[self.rows(j.k + 1)],
                                                                       par))
            elif isinstance(j, Kink):
                point = self.regions[j.k].end
                S = self.S_point(point, p)
                yl, yr = yb[self.rows(j.k)], ya[self.rows(j.k + 1)]
                kj = mod.kink_jac(S, yl, yr, par)  # d/d(S, yl, yr)
                jump = slice(r, r + 3)
                B[jump, self.rows(j.k)] = kj[:, 1:7]
                A[jump, self.rows(j.k + 1)] = kj[:, 7:13]
                self._add_p(P, jump, point.unknown, kj[:, 0] * S)
                if vc:
                    self._pressure_column(P, jump, mod.kink_jac_par(S, yl, yr, par))
                l0, r0 = self.offsets[j.k], self.offsets[j.k + 1]
                for row, c in enumerate(_KINK_CONTINUOUS, start=r + 3):
                    A[row, r0 + c] = 1.0
                    B[row, l0 + c] = -1.0
            elif isinstance(j, Rim):
                S = self.S_point(self.regions[j.k].end, p)
                B[rows, self.rows(j.k)] = mod.rim_jac(S, yb[self.rows(j.k)], par)
                if vc:
                    self._pressure_column(P, rows, mod.rim_jac_par(S, yb[self.rows(j.k)], par))
            r += j.rows
        if self.extra in ("force", "arclength"):
            w = 1.0 if self.extra == "force" else 2 * np.pi * self.arc_tangent[2] / self.arc_scale[2]
            F = q["F"] if self.extra == "force" else 0.0
            point, S, yc, yf, kf, f_at_a = self._force_args(ya, yb, p, q)
            fj = w * self._force_function("jac")(S, yc, yf, q["delta"], F, par)  # d/d(Sc, yf, F)
            (A if f_at_a else B)[r, self.rows(kf)] = fj[0, 1:7]
            self._add_p(P, r, point.unknown, fj[0, 0] * S)
            if vc:
                self._pressure_column(P, r, w * self._force_function("jac_par")(S, yc, yf, q["delta"], F, par)[0])
            if self.extra == "arclength":
                w3 = self.arc_tangent / self.arc_scale  # weights of (delta, lambda0, F)
                self._add_p(P, r, "lambda0", w3[1])
                self._add_p(P, r, "delta", w3[0])
        elif self.extra == "pole_stretch":
            A[r, self.offsets[0] + _LS] = 1.0
        if vc:
            r += self.extra is not None
            A[r, self.n_shell] = 1.0
            B[r + 1, self.n_shell] = 1.0
        return (A, B, P) if P is not None else (A, B)

    # -- values of a solution -----------------------------------------------------------------------
    def end_values(self, ya, yb, p=None):
        """(F, delta): F is the axial force at the start of the region that ends at the rim
        (a first integral of a free region, so the indenter's force)."""
        k = len(self.regions) - 1
        S = self.S_point(self.regions[k].start, p)
        G = self.kernels.active.free_profile(np.array([S]), ya[self.rows(k), None],
                                             self.par_at(p))["axial_force_2pi"][0]
        return 2 * np.pi * float(G), float(self.quantities(p)["delta"])

    def region_profiles(self, t, y, p):
        """[(k, S, fields)] of every region on ``t`` (1-D): the generated ``*_profile`` dicts,
        from the kernel set (diagnosis and energy evaluate them at every state)."""
        out = []
        for k, reg in enumerate(self.regions):
            S = self.S(k, t, p)
            out.append((k, S, getattr(self.kernels.active, f"{reg.kind}_profile")(S, y[self.rows(k)],
                                                                                   self.par_at(p))))
        return out

    def profile(self, t, y, p, z_tip: float) -> dict:
        """Fields over S, pole to rim, on ``t`` for every region (see ``Solution.profile``):
        ``S``, ``region`` (0 on the indenter, 1 free) and the generated profile fields
        (``axial_force`` = 2 pi times the generated ``axial_force_2pi``)."""
        parts = self.region_profiles(t, y, p)
        out = {"S": np.concatenate([S for _, S, _ in parts]),
               "region": np.concatenate([np.full(t.size, REGION_CODES[self.regions[k].kind]) for k, _, _ in parts])}
        keys = next(fields for k, _, fields in parts if self.regions[k].kind == "free")  # contact adds omega
        for key in keys:
            vals = []
            for k, _, fields in parts:
                v = np.broadcast_to(fields[key], t.shape)
                if key == "z" and self.regions[k].kind in CONTACT_KINDS:
                    v = v + z_tip  # the generated contact z is measured from the tip's apex
                vals.append(v)
            vals = np.concatenate(vals)
            out["axial_force" if key == "axial_force_2pi" else key] = (
                2 * np.pi * vals if key == "axial_force_2pi" else vals)
        return out

    def _param(self, name) -> float:
        """A run-time parameter by name; 0 for the pressure's in a structure without them."""
        names = self.model.PARAMS
        return float(self.par[names.index(name)]) if name in names else 0.0

    @property
    def pressure(self) -> float:
        """The pressure of the parameters (under volume control: of the solution, see :meth:`at`)."""
        return self._param("pressure")

    @property
    def pole_height(self) -> float:
        """Where the indenter finds the pole at delta = 0: ``Z(0) + pole_rise`` (kept: every
        diagnosis reads it, and the parameters it depends on are fixed; :meth:`at` drops it)."""
        h = self.__dict__.get("_pole_height")
        if h is None:
            h = self._pole_height = float(self.model.reference_shell(0.0, self.par)["Z"]) + self._param("pole_rise")
        return h

    def energy(self, sol, x, p) -> float:
        """``E = 2 pi Int U R Psi dS - p (V - V_ref)``: the elastic energy over every region
        (Gauss-Legendre on each mesh interval, plus the leading term ``zeta U(zeta)/2`` of
        each pole disc ``[0, zeta]``) and the pressure's potential (``shellbvp.inflation``).
        Under volume control the pressure does no work (V is held): E is the elastic energy."""
        elastic = self._elastic_energy(sol, x, p)
        if self.volume_control or not self.pressure:
            return elastic
        return elastic - self.pressure * (self.volume(sol, x, p) - self.scene.reference_volume())

    def volume(self, sol, x, p) -> float:
        """``V = Int dV/dS dS`` over every region (Gauss-Legendre on the mesh): the volume between
        the shell and its rim's plane (``symbolic.equations.pressure_load``)."""
        t, w = gauss_points(x)
        total = 0.0
        for k, S, fields in self.region_profiles(t, sol(t), p):
            reg = self.regions[k]
            total += float(np.sum(w * fields["volume_density"] * S)) * (self.ln_S(reg.end, p) - self.ln_S(reg.start, p))
        return total

    def _elastic_energy(self, sol, x, p) -> float:
        t, w = gauss_points(x)
        y = sol(t)
        par = self.par_at(p)
        total = 0.0
        for k, reg in enumerate(self.regions):  # the generated energy density alone, not the profile
            S = self.S(k, t, p)
            density = getattr(self.kernels.active, f"{reg.kind}_energy")(S, y[self.rows(k)], par)[0]
            total += float(np.sum(w * density * S)) * (self.ln_S(reg.end, p) - self.ln_S(reg.start, p))
        for j in self.junctions:
            if isinstance(j, (ContactPole, FreePole)):
                zeta = self.S_point(self.regions[j.k].start, p)
                energy = getattr(self.kernels.active, f"{self.regions[j.k].kind}_energy")
                density = energy(np.array([zeta]), sol(np.array([0.0]))[self.rows(j.k)], par)[0]
                total += 0.5 * float(density[0]) * zeta
        return 2 * np.pi * total
