"""From a structure description (plain JSON data) to generated module text.

The description is what ``shellbvp`` hashes into the cache key, so it must
say everything the generated code depends on, and nothing else (continuous
parameters are run-time arguments).  User formulas travel as plain text
(``formula.formula_text``), read back by the whitelist parser
``formula.parse_formula``; descriptions of older versions held ``srepr`` text,
which the parser's legacy mode reads.  Strain and bending energies come from
the families registered in ``symbolic.energies``.
"""

from __future__ import annotations

from . import codegen, codegen_numba, energies, geometry
from .equations import Structure, derive
from .formula import parse_formula
from .version import canonical_json

__all__ = ["structure_from_description", "generate_source", "generate_sources"]


def _expr(text: str, name: str, *syms):
    """Rebuild an expression from its stored text (never evaluated as code)."""
    return parse_formula(text, {s.name: s for s in syms}, name=name, legacy_srepr=True)


def structure_from_description(desc: dict) -> Structure:
    W, mpar = energies.strain_energy(desc["material"])
    sh = desc["shell"]
    if sh["kind"] == "spheroid":
        shell = geometry.spheroid()
    else:
        shell = geometry.user_shell(_expr(sh["R"], "R(S)", geometry.S), _expr(sh["Z"], "Z(S)", geometry.S),
                                    _expr(sh["L"], "L"))
    tp = desc["tip"]
    if tp["kind"] == "sphere":
        tip = geometry.sphere_tip()
    elif tp["kind"] == "flat":
        tip = geometry.flat_tip()
    else:
        tip = geometry.user_tip(_expr(tp["A"], "A(omega)", geometry.OMEGA), _expr(tp["B"], "B(omega)", geometry.OMEGA))
    B = energies.bending_energy(desc.get("bending", {"family": "trace"}))
    profile = desc.get("thickness")
    thickness = geometry.thickness_profile(profile, shell) if profile is not None else None
    return Structure(W=W, material_params=mpar, shell=shell, tip=tip, xi=int(desc["xi"]), B=B,
                     pressurised=bool(desc.get("pressurised", False)), substrate=bool(desc.get("substrate", False)),
                     thickness=thickness)


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
