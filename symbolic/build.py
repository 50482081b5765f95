"""From a structure description (plain JSON data) to generated module text.

The description is what ``shellbvp`` hashes into the cache key, so it must
say everything the generated code depends on, and nothing else (continuous
parameters are run-time arguments).  User formulas travel as plain text
(``formula.formula_text``), read back by the whitelist parser
``formula.parse_formula``; descriptions of older versions held ``srepr`` text,
which the parser's legacy mode reads.
"""

from __future__ import annotations

import sympy as sp

from . import bending, codegen, codegen_numba, geometry, materials
from .equations import Structure, derive
from .formula import parse_formula
from .version import canonical_json

__all__ = ["structure_from_description", "generate_source", "generate_sources"]

ALPHA = sp.Symbol("alpha", positive=True)
JM = sp.Symbol("Jm", positive=True)


def _expr(text: str, name: str, *syms):
    """Rebuild an expression from its stored text (never evaluated as code)."""
    return parse_formula(text, {s.name: s for s in syms}, name=name, legacy_srepr=True)


def structure_from_description(desc: dict) -> Structure:
    mat = desc["material"]
    family = mat["family"]
    if family == "mooney-rivlin":
        W, mpar = materials.mooney_rivlin(ALPHA), (ALPHA,)
    elif family == "neo-hookean":
        W, mpar = materials.neo_hookean(), ()
    elif family == "gent":
        W, mpar = materials.gent(JM), (JM,)
    elif family == "user":
        W, mpar = _expr(mat["W"], "W", materials.LS, materials.LT), ()
    else:
        raise ValueError(f"unknown material family {family!r}")
    sh = desc["shell"]
    if sh["kind"] == "spheroid":
        shell = geometry.spheroid()
    else:
        shell = geometry.user_shell(_expr(sh["R"], "R(S)", geometry.S), _expr(sh["Z"], "Z(S)", geometry.S),
                                    _expr(sh["L"], "L"))
    tp = desc["tip"]
    if tp["kind"] == "sphere":
        tip = geometry.sphere_tip()
    else:
        tip = geometry.user_tip(_expr(tp["A"], "A(omega)", geometry.OMEGA), _expr(tp["B"], "B(omega)", geometry.OMEGA))
    bend = desc.get("bending", {"family": "trace"})
    B = None if bend["family"] == "trace" else bending.bending_energy(
        bend["family"], _expr(bend["B"], "B", *bending.BENDING_SYMBOLS.values()) if bend["family"] == "user" else None)
    return Structure(W=W, material_params=mpar, shell=shell, tip=tip, xi=int(desc["xi"]), B=B,
                     pressurised=bool(desc.get("pressurised", False)))


def generate_source(desc: dict) -> str:
    """Derive and print the module of a description (deterministic)."""
    return codegen.module_source(derive(structure_from_description(desc)), canonical_json(desc))


def generate_sources(desc: dict) -> tuple[str, str]:
    """The numpy module and the compiled-kernel module of a description, from one derivation
    (the kernels reuse the numpy module's lowering: printing both costs little more than one)."""
    d = derive(structure_from_description(desc))
    specs = codegen.function_specs(d)
    text = canonical_json(desc)
    return codegen.module_source(d, text, specs), codegen_numba.kernel_source(d, text, specs)
