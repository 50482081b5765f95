"""The assembler: :class:`ChainBVP`, one chain's multipoint BVP (``fun``, ``fun_jac``, its
boundary conditions from :mod:`shellbvp.chain.conditions`), solved, and the values of a
solution (end values, profiles, energy, volume); the layout it stacks: :mod:`shellbvp.chain`."""

from __future__ import annotations

import numpy as np

from ..collocation import newton_on_mesh
from ..kernels import kernel_set
from ..model import load_module, lower_structure
from ..quadrature import gauss_points
from ..solution import solve_bvp
from .blocks import CONTACT_KINDS, REGION_CODES, SIZES, Chain, ContactPole, Edge, FreePole, Line, Point, Rim, Seam
from .conditions import BoundaryConditions

__all__ = ["ChainBVP", "CONTROLS"]

CONTROLS = ("delta", "lambda0", "force", "arclength")


def _call_key(t, y, p, par):
    """The cheap part of what identifies a ``fun`` call (shapes, the unknowns' and parameters'
    bytes), compared before t and y are compared by value (:func:`_same_call`)."""
    return np.shape(y), np.shape(t), None if p is None else np.asarray(p, float).tobytes(), par.tobytes()


def _same_call(key, small, t, y) -> bool:
    k_small, kt, ky = key
    return k_small == small and np.array_equal(ky, y) and np.array_equal(kt, t)


class ChainBVP(BoundaryConditions):
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
        The pressure as an unknown with the enclosed volume held at ``enclosed_volume``
        (default: ``scene.sealed``).
    enclosed_volume : float, optional
        V0, the volume a sealed shell holds; needed under volume control
        (``shellbvp.inflation.enclosed_volume``, which a configuration's system passes): the
        system solves nothing to find it.
    lower_pole_rise : float, optional
        A closed shell's lower half of its own (``UserShell.closed_halves``) under pressure: its
        pole's rise in the inflated state, where the substrate finds it (the lower half's
        ``pole_rise`` parameter, :meth:`half_par`; ``par`` carries the upper's).
    """

    def __init__(self, scene, chain: Chain, control: str, value, model=None, par=None, volume_control=None,
                 enclosed_volume=None, lower_pole_rise=None):
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
        self.lower_pole_rise = None
        if lower_pole_rise is not None and self.models[-1] is not self.model:
            self.lower_pole_rise = float(lower_pole_rise)
            self._i_rise = mod.PARAMS.index("pole_rise")
        self.sizes = [SIZES[r.kind] for r in chain.regions]
        self.offsets = np.cumsum([0, *self.sizes])[:-1].tolist()
        self.n_shell = int(sum(self.sizes))  # the regions' states; then the volume state
        self.volume_control = bool(scene.sealed if volume_control is None else volume_control)
        self.enclosed_volume = None
        self.n = self.n_shell + self.volume_control
        kinds = {type(j) for j in chain.junctions}
        self.has_contact_pole = any(isinstance(j, ContactPole) and j.stretch == "lambda0" for j in chain.junctions)
        if control == "arclength" and not self.has_contact_pole:
            raise ValueError(f"arclength control needs a contact cap at the pole; {chain.name} has none")
        if control in ("force", "arclength") and not any(isinstance(j, (Edge, Line)) for j in chain.junctions):
            raise ValueError(f"{control} control needs contact; the {chain.name} configuration has only delta")
        if control == "lambda0" and not any(isinstance(j, (ContactPole, FreePole)) for j in chain.junctions):
            raise ValueError(f"lambda0 control needs a regular pole; the {chain.name} configuration has none")
        names = list(chain.unknowns)
        if self.has_contact_pole and control != "lambda0":
            names.append("lambda0")
        # a closed shell's lower pole on its substrate has a stretch of its own
        names += [j.stretch for j in chain.junctions if isinstance(j, ContactPole) and j.stretch != "lambda0"]
        if control != "delta":
            names.append("delta")
        if self.volume_control:
            if "pressure" not in mod.PARAMS:
                raise ValueError("volume control needs a pressurised structure (Scene.sealed)")
            if enclosed_volume is None:
                raise ValueError("enclosed_volume is needed under volume control: V0 of the sealed shell "
                                 "(shellbvp.inflation.enclosed_volume; a configuration's system passes it)")
            names.append("pressure")
            self.enclosed_volume = float(enclosed_volume)
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
        self.rim_slope = self._clamped_rim_slope()
        # a closed shell's equator: each half's (L, Phi(L)), the slopes' departures opposite
        seam = next((j for j in self.junctions if isinstance(j, Seam)), None)
        self.seam_slopes = None if seam is None else tuple(
            (L, float(self.models[k].reference_shell(L, self.par)["Phi"]))
            for k in (seam.ku, seam.kl) for L in [float(self.S_point(self.regions[k].end, None))])
        # halves that differ: their reference curvatures jump at the equator, so lambda_s and
        # kappa_s do too, tau_s and M_s are continuous instead; each half's undeformed state
        # there (stress-free) is where its stresses are measured from (BoundaryConditions._seam)
        self.seam_references = None
        if seam is not None and self.models[seam.ku] is not self.models[seam.kl]:
            self.seam_references = tuple(self._undeformed(k, L) for k, (L, _) in zip((seam.ku, seam.kl),
                                                                                      self.seam_slopes))
        # a closed shell solved on the half above its equator (its mirror image the other half)
        self.mirrored = scene.closed and any(isinstance(j, Rim) for j in self.junctions)

    def _undeformed(self, k, S) -> np.ndarray:
        """The free states of region ``k``'s half undeformed at ``S`` (its reference)."""
        ref = self.models[k].reference_shell(S, self.par)
        return np.array([1.0, float(ref["Phi"]) / S, 1.0, float(ref["kappa_s"]), 0.0, float(ref["Z"])])

    def _clamped_rim_slope(self):
        """``Phi(L)/L``, the reference slope over L that a clamped rim or a closed shell's equator
        holds (``phiS`` at the rim), or None for the pinned rim.  Clamped is offered before
        contact only (a pole and a rim)."""
        if self.scene.rim == "pinned" and not self.scene.closed:
            return None
        if not self.scene.closed and any(not isinstance(j, (FreePole, Rim)) for j in self.chain.junctions):
            raise ValueError(f"rim={self.scene.rim!r} is offered for the shell under pressure before contact "
                             f"(sb.inflate) only; the {self.chain.name} configuration touches the indenter")
        L = self.L
        return float(self.model.reference_shell(L, self.par)["Phi"]) / L

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
        unbound = ("model", "kernels", "models", "region_kernels", "_vol", "_vol_jac")
        return {k: v for k, v in self.__dict__.items() if k not in unbound}

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
        return (b - a) * self._vol[k](S, y[self.rows(k)], self.half_par(self.par, k))[0]

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
        (``shellbvp.kernels``; looked up on every call, so a curve switches as soon as they are).
        A closed shell whose halves differ (``shellbvp.model.lower_structure``) has a module and kernel set
        per half: the regions after its seam's upper one are its lower half's; both modules take
        the same run-time parameters."""
        self.kernels = kernel_set(self.model, self.scene.structure)
        desc = lower_structure(self.scene)
        seam = next((j for j in self.chain.junctions if isinstance(j, Seam)), None)
        if desc is not None and seam is not None:
            lower = load_module(desc)
            if tuple(lower.PARAMS) != tuple(self.model.PARAMS):
                raise ValueError("the closed shell's halves' generated modules take different parameters")
            lower_kernels = kernel_set(lower, lambda: desc)
            self.models = [self.model if k <= seam.ku else lower for k in range(len(self.regions))]
            self.region_kernels = [self.kernels if k <= seam.ku else lower_kernels for k in range(len(self.regions))]
        else:
            self.models = [self.model] * len(self.regions)
            self.region_kernels = [self.kernels] * len(self.regions)
        self._rhs_names = [f"{r.kind}_rhs" for r in self.regions]
        self._jac_names = [f"{r.kind}_jac" for r in self.regions]
        if "pressure" in self.model.PARAMS:  # volume control's functions (pressurised structures)
            self._i_pressure = self.model.PARAMS.index("pressure")
            self._vol = [getattr(m, f"{r.kind}_vol") for m, r in zip(self.models, self.regions)]
            self._vol_jac = [getattr(m, f"{r.kind}_vol_jac") for m, r in zip(self.models, self.regions)]

    def _active(self, k):
        """Region ``k``'s kernels (its half's, of a closed shell whose halves differ)."""
        return self.region_kernels[k].active

    def _rhs(self, k):
        return getattr(self._active(k), self._rhs_names[k])

    def _jac(self, k):
        return getattr(self._active(k), self._jac_names[k])


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
            par_k = self.half_par(par, k)
            gs.append(self._rhs(k)(S, y[rows], par_k))
            f[rows] = (b - a) * gs[-1]
            if self.volume_control:
                f[self.n_shell] += (b - a) * self._vol[k](S, y[rows], par_k)[0]
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
            par_k = self.half_par(par, k)
            gy, gS = self._jac(k)(S, y[rows], par_k)
            dfdy[rows, rows] = (b - a) * gy
            if self.volume_control:
                v = self.n_shell
                vy, vS = self._vol_jac[k](S, y[rows], par_k)
                dfdy[v, rows] = (b - a) * vy[0]
                dfdp[rows, self.col["pressure"]] = (b - a) * getattr(
                    self._active(k), f"{reg.kind}_jac_par")(S, y[rows], par_k)[:, self._i_pressure]
            if dfdp is None:
                continue
            # d/da and d/db of (b - a) g(exp(a + t (b - a)), y), and of the volume rate
            g = None
            for point, dS_dln, sign in ((reg.start, 1.0 - t, -1.0), (reg.end, t, 1.0)):
                if point.unknown is None:
                    continue
                if g is None:
                    g = hit[1][k] if hit is not None else self._rhs(k)(S, y[rows], par_k)
                    if self.volume_control:
                        rate = self._vol[k](S, y[rows], par_k)[0]
                dfdp[rows, self.col[point.unknown]] += sign * g + (b - a) * gS * S * dS_dln
                if self.volume_control:
                    dfdp[v, self.col[point.unknown]] += sign * rate + (b - a) * vS[0] * S * dS_dln
        return (dfdy, dfdp) if dfdp is not None else dfdy

    # -- values of a solution -----------------------------------------------------------------------
    def end_values(self, ya, yb, p=None):
        """(F, delta): F is the axial force at the start of the region that ends at the rim
        (a first integral of a free region, so the indenter's force)."""
        seam = next((j for j in self.junctions if isinstance(j, Seam)), None)
        k = len(self.regions) - 1 if seam is None else seam.ku  # a closed shell's: its upper half's
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
            out.append((k, S, getattr(self._active(k), f"{reg.kind}_profile")(S, y[self.rows(k)],
                                                                                   self.half_par(self.par_at(p), k))))
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
                if key == "z" and self.regions[k].kind == "plane":
                    v = v + self.half_pole_height(k)  # the substrate stays where the lower pole was at delta = 0
                elif key == "z" and self.regions[k].kind in CONTACT_KINDS:
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

    def half_par(self, par, k) -> np.ndarray:
        """``par`` as region ``k``'s half takes it: a lower half of its own (``lower_pole_rise``)
        with its own pole rise; the other parameters are both halves'."""
        if self.lower_pole_rise is None or self.models[k] is self.model:
            return par
        par = par.copy()
        par[self._i_rise] = self.lower_pole_rise
        return par

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

    def half_pole_height(self, k) -> float:
        """:attr:`pole_height` of region ``k``'s half: a closed shell's lower half's pole is its own
        meridian's (in its mirror image), where the substrate finds it."""
        if self.models[k] is self.model:
            return self.pole_height
        rise = self._param("pole_rise") if self.lower_pole_rise is None else self.lower_pole_rise
        return float(self.models[k].reference_shell(0.0, self.par)["Z"]) + rise

    def energy(self, sol, x, p) -> float:
        """``E = 2 pi Int U R Psi dS - p (V - V_ref)``, twice that for a closed shell (the half
        above its equator is solved): the elastic energy over every region
        (Gauss-Legendre on each mesh interval, plus the leading term ``zeta U(zeta)/2`` of
        each pole disc ``[0, zeta]``) and the pressure's potential (``shellbvp.inflation``).
        Under volume control the pressure does no work (V is held): E is the elastic energy."""
        elastic = self._elastic_energy(sol, x, p)
        if not (self.volume_control or not self.pressure):  # V_ref: of what is solved, a half or the whole
            reference = (self.scene.closed_volume() if self.scene.two_contacts and not self.mirrored
                         else self.scene.reference_volume())
            elastic -= self.pressure * (self.volume(sol, x, p) - reference)
        return 2 * elastic if self.mirrored else elastic

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
            density = getattr(self._active(k), f"{reg.kind}_energy")(S, y[self.rows(k)], self.half_par(par, k))[0]
            total += float(np.sum(w * density * S)) * (self.ln_S(reg.end, p) - self.ln_S(reg.start, p))
        for j in self.junctions:
            if isinstance(j, (ContactPole, FreePole)):
                zeta = self.S_point(self.regions[j.k].start, p)
                energy = getattr(self._active(j.k), f"{self.regions[j.k].kind}_energy")
                density = energy(np.array([zeta]), sol(np.array([0.0]))[self.rows(j.k)], self.half_par(par, j.k))[0]
                total += 0.5 * float(density[0]) * zeta
        return 2 * np.pi * total
