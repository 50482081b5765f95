"""Print the hot functions of a structure as loops over the nodes, for numba.

The vectorised module of :mod:`symbolic.codegen` spends most of a call in
NumPy's per-operation overhead (a few hundred array operations on ~300
nodes).  Here the same straight-line programs (the same lowering: the same
common subexpressions, in the same order) are printed as one scalar pass per
node inside ``for _node in range(m)``, decorated with ``numba.njit`` and an
explicit signature, so that the module compiles (or loads numba's on-disk
cache) when it is imported and never again on a call.

Only the functions whose :class:`~symbolic.codegen.FunctionSpec` has
``node_args`` are printed (the regions' ``*_rhs``, ``*_jac``, ``*_jac_par`` and
``*_profile``; a profile's fields are computed as the rows of one array by
``<name>_rows`` and made the numpy module's dict by a plain ``<name>``);
boundary and junction conditions are scalar and cheap (about 1 % of a curve)
and stay in the numpy module.  The signatures take C- or otherwise-ordered
float64 arrays (layout ``A``): solve_bvp hands over both.  Arguments that are not
node arguments (``par``) are 1-D arrays unpacked once before the loop, so new
run-time parameters pass through without any change here.

The module also holds ``collocation_factor`` and ``collocation_solve``
(:mod:`symbolic.collocation_kernel`, not derived): solve_bvp's collocation system
factorised and solved, compiled and cached with the structure's kernels.

Output is deterministic: the same structure gives byte-identical text.  It is
a second module rather than a section of the numpy one so that the numpy
module imports without numba, and numba's cache (which stamps the source
file) depends on this file alone.
"""

from __future__ import annotations

import inspect
import textwrap

from . import collocation_kernel
from .codegen import (
    FunctionSpec,
    docstring,
    function_specs,
    header,
    lower,
    matrix_entries,
)
from .equations import Derivation

__all__ = ["kernel_source", "KERNEL_OPTIONS"]

#: numba options of every kernel: ``error_model="numpy"`` gives IEEE inf/nan on division by
#: zero (as NumPy does) instead of raising; no fastmath, so results match NumPy's to rounding.
KERNEL_OPTIONS = 'cache=True, nogil=True, error_model="numpy"'

_NODE = "_node"  # the loop index; program names never start with "_n" (CSE names are _c<k>)


def _arg_name(a: str) -> str:
    return f"_arg_{a}"


def _signature(spec: FunctionSpec) -> str:
    """numba signature: per-node scalars are 1-D, per-node rows 2-D, constants 1-D arrays."""
    types = []
    for a, syms in spec.args:
        if a in spec.node_args and len(syms) > 1:
            types.append("float64[:, :]")
        elif a in spec.node_args or len(syms) > 1:
            types.append("float64[:]")
        else:
            types.append("float64")
    return f"({', '.join(types)})"


def _kernel_source(spec: FunctionSpec) -> str:
    if not spec.node_args or spec.shape_of not in spec.node_args:
        raise ValueError(f"{spec.name} has no node axis; only node functions are compiled")
    fields = _fields(spec)
    if fields is not None and len(spec.outputs) != 1:
        raise ValueError(f"{spec.name} returns a dict among other outputs; only a dict alone is compiled")
    assignments, outs = lower(spec)
    name = spec.name if fields is None else _rows_name(spec)
    lines = [f"@numba.njit({_signature(spec)!r}, {KERNEL_OPTIONS})",
             f"def {name}({', '.join(_arg_name(a) for a, _ in spec.args)}):"]
    doc = docstring(spec) + ["", "Compiled loop over the nodes; the same values as the numpy module's."]
    if fields is not None:
        doc = [f"Rows of {spec.name}'s fields, {_fields_name(spec)} (the dict is made by {spec.name}).", ""] + doc
    lines.append(textwrap.indent('"""' + "\n".join(doc).rstrip() + '\n"""', "    "))
    for a, syms in spec.args:  # the same at every node
        if a in spec.node_args:
            continue
        if len(syms) > 1:
            lines += [f"    {s.name} = {_arg_name(a)}[{i}]" for i, s in enumerate(syms)]
        else:
            lines.append(f"    {syms[0].name} = {_arg_name(a)}")
    lines.append(f"    _m = {_arg_name(spec.shape_of)}.shape[0]")
    stores, k, ret = [], 0, []
    for name, val in spec.outputs:
        out = f"_out_{name}"
        if fields is not None:  # a profile: one row per field, in the dict's order
            dims = (len(fields),)
            entries = [(f"{i}", outs[i]) for i in range(len(fields)) if outs[i] is not None]
        else:
            dims, entries, k = matrix_entries(val, outs, k)
        lines.append(f"    {out} = numpy.zeros(({', '.join(map(str, dims))}, _m))")
        stores += [f"        {out}[{idx}, {_NODE}] = {text}" for idx, text in entries]
        ret.append(out)
    lines.append(f"    for {_NODE} in range(_m):")
    for a, syms in spec.args:  # this node's values
        if a not in spec.node_args:
            continue
        if len(syms) > 1:
            lines += [f"        {s.name} = {_arg_name(a)}[{i}, {_NODE}]" for i, s in enumerate(syms)]
        else:
            lines.append(f"        {syms[0].name} = {_arg_name(a)}[{_NODE}]")
    lines += [f"        {name} = {text}" for name, text in assignments]
    lines += stores
    lines.append(f"    return {', '.join(ret)}")
    if fields is not None:
        lines += ["", "", f"{_fields_name(spec)} = {fields!r}", "", "",
                  f"def {spec.name}({', '.join(a for a, _ in spec.args)}):",
                  f'    """{spec.doc.strip()} Compiled ({_rows_name(spec)})."""',
                  f"    return dict(zip({_fields_name(spec)}, {_rows_name(spec)}({', '.join(a for a, _ in spec.args)})))"]
    return "\n".join(lines) + "\n"


def _fields(spec: FunctionSpec):
    """The field names of a profile (a function whose output is a dict), else None."""
    dicts = [val for _, val in spec.outputs if isinstance(val, dict)]
    return tuple(dicts[0]) if dicts else None


def _rows_name(spec: FunctionSpec) -> str:
    return f"{spec.name}_rows"


def _fields_name(spec: FunctionSpec) -> str:
    return f"{spec.name.upper()}_FIELDS"


def kernel_source(d: Derivation, description: str, specs: list[FunctionSpec] | None = None) -> str:
    """Full text of the compiled-kernel module for derivation ``d`` (see the module docstring).

    ``description`` and ``specs`` as for :func:`symbolic.codegen.module_source`; the two
    modules of a structure carry the same ``KEY``.
    """
    key, comments = header("codegen_numba.py", description)
    kernels = [s for s in (specs if specs is not None else function_specs(d)) if s.node_args]
    head = [
        *comments,
        '"""Compiled loop-over-nodes kernels of one shellbvp structure (see the header).',
        "",
        "Importing this module compiles them, or loads them from numba's cache beside it.",
        '"""',
        "import numba",
        "import numpy",
        "",
        f"KEY = {key!r}",
        f"PARAMS = {tuple(p.name for p in d.params)!r}",
        f"KERNELS = {tuple(s.name for s in kernels) + tuple(collocation_kernel.SIGNATURES)!r}",
        "",
    ]
    return "\n".join(head) + "\n" + "\n\n".join([_kernel_source(s) for s in kernels] + [_collocation_source()])


def _collocation_source() -> str:
    """The functions of :mod:`symbolic.collocation_kernel`, compiled with the structure's kernels."""
    return "\n\n".join(f"@numba.njit({signature!r}, {KERNEL_OPTIONS})\n"
                       + inspect.getsource(getattr(collocation_kernel, name))
                       for name, signature in {**collocation_kernel.HELPERS,
                                               **collocation_kernel.SIGNATURES}.items())
