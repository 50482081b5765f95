"""Print the derived programs as a vectorised numpy module.

One module per structure (strain-energy family, xi, shell and tip shapes);
continuous parameters are run-time arguments.  Each function evaluates only
the assignments its outputs depend on (so, e.g., ``free_rhs`` computes no
derivatives), after a common-subexpression pass over them.  Array layouts
are solve_bvp's: values ``(n, m)``, Jacobians ``(n, k, m)`` with ``[i, j, :]``
the derivative of output i by input j at each of the m nodes.

Output is deterministic: the same structure gives byte-identical text.
"""

from __future__ import annotations

import hashlib
import textwrap
from dataclasses import dataclass, field

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from .dag import Program
from .equations import CONTACT_STATES, FREE_STATES, Derivation
from .version import CODEGEN_VERSION

__all__ = ["FunctionSpec", "Printer", "module_source", "function_specs", "lower", "docstring", "header",
           "CODEGEN_VERSION"]



@dataclass
class FunctionSpec:
    """One generated function.

    ``args``: list of (argument name, tuple of symbols); a tuple of length one
    is passed as a single array/scalar, longer tuples are unpacked row-wise.
    ``outputs``: list of (name, sympy Matrix or list of expressions, or dict
    for a profile).  ``shape_of``: the argument whose shape the node axis takes.
    ``node_args``: the arguments that vary over the nodes (the rest, e.g. ``par``,
    are the same at every node); a function that has them is also printed as a
    compiled loop-over-nodes kernel (``symbolic.codegen_numba``).
    """

    name: str
    program: Program
    args: list
    outputs: list
    doc: str
    shape_of: str | None = None
    extra_doc: list = field(default_factory=list)
    node_args: tuple = ()
    lowered: tuple | None = field(default=None, repr=False, compare=False)  # cache of lower()


class Printer(NumPyPrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False})

    def _print_Pow(self, expr, rational=False):
        """Negative integer powers as quotients (``1/(x**3)``), half-integer ones through a
        square root (``numpy.sqrt(x)**3``): NumPyPrinter writes ``x**(-1.0)`` and ``x**(3/2)``,
        which numba compiles to calls of ``pow`` (a compiled right-hand side spent 40 % of its
        time in them) where integer powers become products.  NumPy's functions are about as
        fast either way (within 5 %, benchmarks/kernels.py)."""
        base, exp = expr.base, expr.exp
        if exp.is_Integer and exp < 0:
            power = base if exp == -1 else sp.Pow(base, -exp, evaluate=False)
            return f"1/({self._print(power)})"
        if exp.is_Rational and exp.q == 2 and abs(exp.p) > 1:
            root = f"{self._module_format(self._module + '.sqrt')}({self._print(base)})**{abs(exp.p)}"
            return root if exp > 0 else f"1/({root})"
        return super()._print_Pow(expr, rational=rational)


def _flatten(outputs):
    flat = []
    for _, val in outputs:
        if isinstance(val, dict):
            flat.extend(val.values())
        else:
            flat.extend(sp.Matrix(val))
    return [sp.sympify(e, strict=True) for e in flat]  # expressions, never text


def lower(spec: FunctionSpec):
    """The straight-line code of one function, printed: ``(assignments, outputs)``.

    ``assignments`` is a list of ``(name, text)`` in evaluation order (program steps and the
    common subexpressions they need); ``outputs`` the printed text of every flattened output
    entry (``_flatten`` order), ``None`` where the entry is identically zero.  Shared by the
    vectorised printer below and the loop-over-nodes one (``symbolic.codegen_numba``), so that
    both evaluate the same expressions in the same order.
    """
    if spec.lowered is not None:
        return spec.lowered
    prog = spec.program
    printer = Printer()
    flat = _flatten(spec.outputs)
    steps = prog.dependencies(flat)
    exprs = [prog.expression(s) for s in steps] + flat
    reps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_c"), order="canonical")
    rep_expr = dict(reps)
    rep_rank = {s: i for i, (s, _) in enumerate(reps)}
    emitted: set = set()
    assignments = []

    def emit_reps(expr):
        for s in sorted(expr.free_symbols & rep_expr.keys(), key=rep_rank.__getitem__):
            if s in emitted:
                continue
            emit_reps(rep_expr[s])
            assignments.append((s.name, printer.doprint(rep_expr[s])))
            emitted.add(s)

    for sym, e in zip(steps, reduced[: len(steps)]):
        emit_reps(e)
        assignments.append((sym.name, printer.doprint(e)))
    outs = reduced[len(steps):]
    for e in outs:
        emit_reps(e)
    spec.lowered = (assignments, [None if e == 0 else printer.doprint(e) for e in outs])
    return spec.lowered


def docstring(spec: FunctionSpec) -> list[str]:
    """The generated docstring's lines (argument rows named)."""
    doc = [spec.doc.strip(), ""]
    for a, syms in spec.args:
        if len(syms) > 1:
            doc.append(f"{a} : rows ({', '.join(s.name for s in syms)})")
        else:
            doc.append(f"{a} : {syms[0].name}")
    doc += spec.extra_doc
    return doc


def matrix_entries(val, outs, k):
    """``(dims, [(index, text)], next k)`` of a matrix output whose entries' texts start at
    ``outs[k]`` (zero entries, None, are left out: the array starts at zeros)."""
    mat = sp.Matrix(val)
    dims = (mat.rows,) if mat.cols == 1 else (mat.rows, mat.cols)
    entries = []
    for i in range(mat.rows):
        for j in range(mat.cols):
            if outs[k] is not None:
                entries.append((f"{i}" if mat.cols == 1 else f"{i}, {j}", outs[k]))
            k += 1
    return dims, entries, k


def _function_source(spec: FunctionSpec) -> str:
    lines = [f"def {spec.name}({', '.join(a for a, _ in spec.args)}):"]
    lines.append(textwrap.indent('"""' + "\n".join(docstring(spec)).rstrip() + '\n"""', "    "))
    for a, syms in spec.args:
        if len(syms) > 1:
            lines.append(f"    {', '.join(s.name for s in syms)} = {a}")
    shape = f"numpy.shape({spec.shape_of})" if spec.shape_of else "()"
    lines.append(f"    _shape = {shape}")
    assignments, outs = lower(spec)
    lines += [f"    {name} = {text}" for name, text in assignments]

    k = 0
    ret = []
    for name, val in spec.outputs:
        if isinstance(val, dict):
            lines.append(f"    {name} = {{}}")
            for key in val:
                lines.append(f"    {name}[{key!r}] = numpy.zeros(_shape) + ({outs[k] or 0})")
                k += 1
        else:
            dims, entries, k = matrix_entries(val, outs, k)
            lines.append(f"    {name} = numpy.zeros({dims!r} + _shape)")
            lines += [f"    {name}[{idx}] = {text}" for idx, text in entries]
        ret.append(name)
    lines.append(f"    return {', '.join(ret)}")
    return "\n".join(lines) + "\n"


def _condition_specs(name, prog, args, res, wrt, wrt_names, par, pressurised, doc) -> list[FunctionSpec]:
    """``<name>_res``, its Jacobian ``<name>_jac`` in ``wrt`` and, for a pressurised structure (the
    pressure an unknown under volume control), ``<name>_jac_par``."""
    n = len(res)
    specs = [FunctionSpec(f"{name}_res", prog, args, [("res", res)], f"{doc}, ({n},)."),
             FunctionSpec(f"{name}_jac", prog, args, [("dres", prog.jacobian(res, wrt))],
                          f"{doc}: d/d({wrt_names}), ({n}, {len(wrt)}).")]
    if pressurised:
        specs.append(FunctionSpec(f"{name}_jac_par", prog, args, [("dres", prog.jacobian(res, par))],
                                  f"{doc}: d/dpar ({n}, {len(par)})."))
    return specs


def function_specs(d: Derivation) -> list[FunctionSpec]:
    """Every function of a structure's module."""
    from .equations import DELTA, FORCE, LAMBDA0

    par = tuple(d.params)
    specs = []
    regions = [("free", d.free, d.free_states, d.free_rhs, d.free_profile),
               ("contact", d.contact, d.contact_states, d.contact_rhs, d.contact_profile)]
    if d.has_cylinder:
        regions.append(("cylinder", d.cylinder, d.cylinder_states, d.cylinder_rhs, d.cylinder_profile))
    if d.has_plane:
        regions.append(("plane", d.plane, d.plane_states, d.plane_rhs, d.plane_profile))
    for region, prog, states, rhs, profile in regions:
        n = len(states)
        args = [("S", (sp.Symbol("S"),)), ("y", states), ("par", par)]
        # S is declared positive in geometry; find the program's own S.
        Ssym = prog.inputs[0]
        args[0] = ("S", (Ssym,))
        specs += [
            # the hot path: also compiled as loops over the nodes (node_args)
            FunctionSpec(f"{region}_rhs", prog, args, [("g", rhs)],
                         f"{region} region: g = S dy/dS, shape ({n}, m).", "S", node_args=("S", "y")),
            FunctionSpec(f"{region}_jac", prog, args,
                         [("dg_dy", prog.jacobian(rhs, states)), ("dg_dS", prog.jacobian(rhs, [Ssym]))],
                         f"{region} region: dg/dy ({n}, {n}, m) and dg/dS ({n}, m).", "S",
                         node_args=("S", "y")),
            FunctionSpec(f"{region}_jac_par", prog, args, [("dg_dpar", prog.jacobian(rhs, par))],
                         f"{region} region: dg/dpar ({n}, {len(par)}, m).", "S", node_args=("S", "y")),
            FunctionSpec(f"{region}_profile", prog, args, [("out", profile)],
                         f"{region} region: physical fields at the nodes (dict of arrays).", "S",
                         node_args=("S", "y")),  # diagnosis, at every state
            # the energy's integrand alone: the profile computes all its fields at 4 Gauss points
            # per mesh interval for one of them (a third of a state's diagnosis)
            FunctionSpec(f"{region}_energy", prog, args, [("e", [profile["energy_density"]])],
                         f"{region} region: the energy density U R Psi (profile's energy_density), (1, m).",
                         "S", node_args=("S", "y")),
        ]
        if d.structure.pressurised:  # volume control (a sealed shell): V = Int dV/dS dS
            vol = [Ssym * profile["volume_density"]]
            if any(s.name == "pressure" for s in prog.expand(vol[0]).free_symbols):
                raise AssertionError(f"the {region} region's volume density depends on the pressure")
            specs += [
                FunctionSpec(f"{region}_vol", prog, args, [("v", vol)],
                             f"{region} region: S dV/dS, (1, m).", "S"),
                FunctionSpec(f"{region}_vol_jac", prog, args,
                             [("dv_dy", prog.jacobian(vol, states)), ("dv_dS", prog.jacobian(vol, [Ssym]))],
                             f"{region} region: d(S dV/dS)/dy (1, {n}, m) and d/dS (1, m).", "S"),
            ]
    # Legendre condition of the free region: det of the (lambda_s', kappa_s') system
    r_ = sp.Symbol("r")
    legendre = [d.free.let("legendre", sp.Symbol("det") / r_**2)]
    specs.append(FunctionSpec("free_legendre", d.free, [("S", (d.free.inputs[0],)), ("y", d.free_states),
                                                        ("par", par)], [("out", legendre)],
                              "det d(tau_s, M_s)/d(lambda_s, kappa_s) over the free region, (1, m): "
                              "the ODE is singular where it vanishes (loss of convexity of U)", "S",
                              node_args=("S", "y")))  # diagnosis, at every state
    # pole
    chi, ls = d.pole_states
    pargs = [("chi", (chi,)), ("ls", (ls,)), ("lambda0", (LAMBDA0,)), ("par", par)]
    specs += [
        FunctionSpec("pole_res", d.pole, pargs, [("res", d.pole_res)], "Pole conditions (2,)."),
        FunctionSpec("pole_jac", d.pole, pargs,
                     [("dres", d.pole.jacobian(d.pole_res, [chi, ls, LAMBDA0]))],
                     "Pole conditions: d/d(chi, ls, lambda0), (2, 3)."),
    ]
    pressurised = d.structure.pressurised  # d/dpar of every condition: the pressure is an unknown under
    # volume control (the other junctions' *_jac_par exist for every structure)
    if pressurised:
        specs.append(FunctionSpec("pole_jac_par", d.pole, pargs, [("dres", d.pole.jacobian(d.pole_res, par))],
                                  f"Pole conditions: d/dpar (2, {len(par)})."))
    if d.has_plane:  # the lower pole of a closed shell on a substrate
        specs += [
            FunctionSpec("plane_pole_res", d.plane_pole, pargs, [("res", d.plane_pole_res)],
                         "Lower pole on the substrate (2,)."),
            FunctionSpec("plane_pole_jac", d.plane_pole, pargs,
                         [("dres", d.plane_pole.jacobian(d.plane_pole_res, [chi, ls, LAMBDA0]))],
                         "Lower pole on the substrate: d/d(chi, ls, lambda0), (2, 3)."),
        ]
        if pressurised:
            specs.append(FunctionSpec("plane_pole_jac_par", d.plane_pole, pargs,
                                      [("dres", d.plane_pole.jacobian(d.plane_pole_res, par))],
                                      f"Lower pole on the substrate: d/dpar (2, {len(par)})."))
    # rim (S = L)
    Ssym = d.free.inputs[0]
    rargs = [("S", (Ssym,)), ("y", d.free_states), ("par", par)]
    specs += [
        FunctionSpec("rim_res", d.free, rargs, [("res", d.rim_res)], "Rim conditions at S = L (3,)."),
        FunctionSpec("rim_jac", d.free, rargs, [("dres", d.free.jacobian(d.rim_res, d.free_states))],
                     "Rim conditions: d/dy (3, 6)."),
        FunctionSpec("rim_jac_par", d.free, rargs, [("dres", d.free.jacobian(d.rim_res, par))],
                     f"Rim conditions: d/dpar (3, {len(par)})."),
    ]
    # contact lines: tip | free and, where the tip has an end, cylinder | free (prefix cyl_)
    edges = [("", "tip", d.junction, d.junction_inputs, d.junction_res, d.force_res)]
    if d.has_cylinder:
        edges.append(("cyl_", "cylinder", d.cyl_junction, d.cyl_junction_inputs, d.cyl_junction_res,
                      d.cyl_force_res))
    if d.has_plane:
        edges.append(("plane_", "plane", d.plane_junction, d.plane_junction_inputs, d.plane_junction_res,
                      d.plane_force_res))
    for prefix, where, J, inputs, residuals, force_res in edges:
        Sc, yc, yf = inputs[0], inputs[1:3], inputs[3:]
        jargs = [("Sc", (Sc,)), ("yc", yc), ("yf", yf), ("delta", (DELTA,)), ("F", (FORCE,)), ("par", par)]
        wrt = [Sc, *yc, *yf, DELTA]
        for model, res in residuals.items():
            specs += [
                FunctionSpec(f"junction_{prefix}{model}_res", J, jargs, [("res", res)],
                             f"Contact-line conditions ({where} | free), {model} model (5,)."),
                FunctionSpec(f"junction_{prefix}{model}_jac", J, jargs, [("dres", J.jacobian(res, wrt))],
                             f"Contact-line conditions ({where} | free), {model} model: "
                             "d/d(Sc, yc, yf, delta), (5, 10)."),
                FunctionSpec(f"junction_{prefix}{model}_jac_par", J, jargs, [("dres", J.jacobian(res, par))],
                             f"Contact-line conditions ({where} | free), {model} model: d/dpar (5, {len(par)})."),
            ]
        specs += [
            FunctionSpec(f"force_{prefix}res", J, jargs, [("res", [force_res])],
                         f"Force control at a {where} edge: F/(2 pi) of the free region minus the "
                         "prescribed F/(2 pi), (1,)."),
            FunctionSpec(f"force_{prefix}jac", J, jargs, [("dres", J.jacobian([force_res], [Sc, *yf, FORCE]))],
                         f"Force control at a {where} edge: d/d(Sc, yf, F), (1, 8)."),
        ]
        if pressurised:
            specs.append(FunctionSpec(f"force_{prefix}jac_par", J, jargs, [("dres", J.jacobian([force_res], par))],
                                      f"Force control at a {where} edge: d/dpar (1, {len(par)})."))
    if d.has_cylinder:
        E, (SS, *ye) = d.tip_end, d.tip_end_inputs
        eargs = [("S_end", (SS,)), ("yt", tuple(ye[:2])), ("yw", tuple(ye[2:])), ("par", par)]
        specs += _condition_specs("tip_end", E, eargs, d.tip_end_res, [SS, *ye], "S, yt, yw", par, pressurised,
                                  "Tip | cylinder junction at S = S* (tip end state yt, cylinder start state "
                                  "yw): omega = omega_max on both sides and [lambda_s U_ls - U] = 0")
    # point-load limit: pole conditions of the free region alone
    PL = d.point_load
    plargs = [("S", (PL.inputs[0],)), ("y", d.free_states), ("delta", (DELTA,)), ("par", par)]
    specs += [
        FunctionSpec("point_load_res", PL, plargs, [("res", d.point_load_res)],
                     "Point-load pole conditions at S = s0 (3,)."),
        FunctionSpec("point_load_jac", PL, plargs,
                     [("dres", PL.jacobian(d.point_load_res, [*d.free_states, DELTA]))],
                     "Point-load pole conditions: d/d(y, delta), (3, 7)."),
    ]
    if pressurised:
        specs.append(FunctionSpec("point_load_jac_par", PL, plargs, [("dres", PL.jacobian(d.point_load_res, par))],
                                  f"Point-load pole conditions: d/dpar (3, {len(par)})."))
    # regular pole of a free cap (annular and line contact)
    fargs = [("S", (d.free.inputs[0],)), ("y", d.free_states), ("par", par)]
    specs += [
        FunctionSpec("free_pole_res", d.free, fargs, [("res", d.free_pole_res)],
                     "Regular pole of a free cap at S = zeta (3,)."),
        FunctionSpec("free_pole_jac", d.free, fargs,
                     [("dres", d.free.jacobian(d.free_pole_res, [*d.free_states, d.free.inputs[0]]))],
                     "Regular pole of a free cap: d/d(y, S), (3, 7)."),
    ]
    if pressurised:
        specs.append(FunctionSpec("free_pole_jac_par", d.free, fargs,
                                  [("dres", d.free.jacobian(d.free_pole_res, par))],
                                  f"Regular pole of a free cap: d/dpar (3, {len(par)})."))
    # interior corner of the free region (left state yl, right state yr at S = S_k)
    K, (SK, *yk) = d.kink, d.kink_inputs
    kargs = [("S_k", (SK,)), ("yl", tuple(yk[:6])), ("yr", tuple(yk[6:])), ("par", par)]
    specs += _condition_specs("kink", K, kargs, d.kink_res, [SK, *yk], "S_k, yl, yr", par, pressurised,
                              "Interior corner of the free region at S = S_k: [tau_s], [M_s] and "
                              "[lambda_s U_ls - U]")
    # geometry of the scene (guesses, plots, penetration checks)
    specs += [
        FunctionSpec("reference_shell", d.geometry_prog, [("S", (d.geometry_S,)), ("par", par)],
                     [("out", d.reference_shell)], "Reference meridian: R, Z, Phi (angle), curvatures.",
                     "S"),
        FunctionSpec("tip_shape", d.geometry_prog, [("omega", (d.geometry_omega,)), ("par", par)],
                     [("out", d.tip_shape)], "Tip profile in units of rho: A, B, phi (tangent angle).",
                     "omega"),
    ]
    return specs


def header(generator: str, description: str) -> tuple[str, list[str]]:
    """(key, comment lines) that open a generated module: who made it, from what, the key."""
    key = hashlib.sha256(description.encode()).hexdigest()  # == version.description_key
    return key, [
        f"# Generated by shellbvp's symbolic/{generator} -- DO NOT EDIT BY HAND.",
        "# It is regenerated from the SymPy derivation in symbolic/ (see README, 'Generated code').",
        f"# sympy {sp.__version__}, codegen version {CODEGEN_VERSION}",
        f"# key {key}",
        "# structure:",
        *("#   " + line for line in description.splitlines()),
    ]


def module_source(d: Derivation, description: str, specs: list[FunctionSpec] | None = None) -> str:
    """Full text of the generated module for derivation ``d``.

    ``description`` is the structure's canonical description (it is hashed
    into the cache key and written into the header).  ``specs``: the
    derivation's :func:`function_specs`, if already made (their lowering is
    shared with the compiled kernels' module).
    """
    key, comments = header("codegen.py", description)
    specs = specs if specs is not None else function_specs(d)
    par = [p.name for p in d.params]
    head = [
        *comments,
        '"""Generated equations of one shellbvp structure (see the header)."""',
        "import numpy",
        "",
        f"KEY = {key!r}",
        f"PARAMS = {tuple(par)!r}",
        f"FREE_STATES = {FREE_STATES!r}",
        f"CONTACT_STATES = {CONTACT_STATES!r}",
        f"OMEGA_MAX = {float(d.structure.tip.omega_max)!r}" if d.has_cylinder else "OMEGA_MAX = None",
        f"KERNELS = {tuple(s.name for s in specs if s.node_args)!r}  # also compiled: symbolic/codegen_numba.py",
        "",
    ]
    body = [_function_source(s) for s in specs]
    return "\n".join(head) + "\n" + "\n\n".join(body)
